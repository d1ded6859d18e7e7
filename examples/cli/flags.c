/* flags.c - the command line: the table of flags (name, value, the commands that take it), the
 * parsing primitives (cli_real, cli_int) and cli_parse, which applies each flag and checks the
 * combinations. Owns: cli_args' contents. May call: progress.c (errors), gis.c (GIS flags), the
 * command families' flag setters and checks (sweeps.c, screen.c, meshes.c). */

#define CLI_VOLGI_FLAGS                                                                      \
    { "--room", 0, CLI_ONLY(CMD_VOLGI) }, { "--iterations", 1, CLI_ONLY(CMD_VOLGI) },        \
    { "--light", 1, CLI_ONLY(CMD_VOLGI) }, { "--eye", 1, CLI_ONLY(CMD_VOLGI) | CLI_ONLY(CMD_MESHAO) },              \
    { "--target", 1, CLI_ONLY(CMD_VOLGI) | CLI_ONLY(CMD_MESHAO) | CLI_ONLY(CMD_VIEWSHED) }, { "--up", 1, CLI_ONLY(CMD_VOLGI) | CLI_ONLY(CMD_MESHAO) },              \
    { "--fov", 1, CLI_ONLY(CMD_VOLGI) | CLI_ONLY(CMD_MESHAO) }, { "--size", 1, CLI_ONLY(CMD_VOLGI) | CLI_ONLY(CMD_VISFIELD) | CLI_ONLY(CMD_MESHAO) },               \
    { "--transfer", 1, CLI_ONLY(CMD_VOLGI) }, { "--paths", 1, CLI_ONLY(CMD_VOLGI) },         \
    { "--reflection", 1, CLI_ONLY(CMD_VOLGI) }, { "--reflectance", 1, CLI_ONLY(CMD_VOLGI) }


#define CLI_VF_FLAGS                                                                              \
    { "--positions", 1, CLI_ONLY(CMD_VISFIELD) }, { "--format", 1, CLI_ONLY(CMD_VISFIELD) },      \
    { "--mapping", 1, CLI_ONLY(CMD_VISFIELD) }, { "--ao", 0, CLI_ONLY(CMD_VISFIELD) },            \
    { "--ground", 1, CLI_ONLY(CMD_VISFIELD) }, { "--extent", 1, CLI_ONLY(CMD_VISFIELD) },         \
    { "--rays", 1, CLI_ONLY(CMD_VISFIELD) | CLI_ONLY(CMD_MESHAO) },                                                      \
    { "--bias", 1, CLI_ONLY(CMD_VISFIELD) }, { "--reference", 1, CLI_ONLY(CMD_VISFIELD) }


#define CLI_LK_FLAGS                                                                          \
    { "--falloff", 1, CLI_ONLY(CMD_MESHAO) }, { "--two-sided", 0, CLI_ONLY(CMD_MESHAO) },     \
    { "--lut", 1, CLI_ONLY(CMD_MESHAO) }, { "--seed", 1, CLI_ONLY(CMD_MESHAO) },              \
    { "--no-jitter", 0, CLI_ONLY(CMD_MESHAO) }, { "--pattern", 1, CLI_ONLY(CMD_MESHAO) }

#define CLI_GI_FLAGS                                                                         \
    { "--order", 1, CLI_ONLY(CMD_GI) }, { "--subsample", 1, CLI_ONLY(CMD_GI) },              \
    { "--specular", 1, CLI_ONLY(CMD_GI) }, { "--shininess", 1, CLI_ONLY(CMD_GI) }


#define CLI_SOLAR_FLAGS                                                                            \
    { "--day", 1, CLI_ONLY(CMD_SOLAR) }, { "--start", 1, CLI_ONLY(CMD_SOLAR) },                   \
    { "--end", 1, CLI_ONLY(CMD_SOLAR) }, { "--time", 1, CLI_ONLY(CMD_SOLAR) },                    \
    { "--step", 1, CLI_ONLY(CMD_SOLAR) }, { "--linke", 1, CLI_ONLY(CMD_SOLAR) },                  \
    { "--linke-monthly", 1, CLI_ONLY(CMD_SOLAR) }, { "--linke-map", 1, CLI_ONLY(CMD_SOLAR) },     \
    { "--latitude", 1, CLI_ONLY(CMD_SOLAR) }, { "--longitude", 1, CLI_ONLY(CMD_SOLAR) },          \
    { "--utc-offset", 1, CLI_ONLY(CMD_SOLAR) }, { "--solar-time", 0, CLI_ONLY(CMD_SOLAR) },       \
    { "--bands", 1, CLI_ONLY(CMD_SOLAR) }, { "--beam", 1, CLI_ONLY(CMD_SOLAR) },                  \
    { "--diffuse", 1, CLI_ONLY(CMD_SOLAR) }, { "--reflected", 1, CLI_ONLY(CMD_SOLAR) },           \
    { "--sun-hours", 1, CLI_ONLY(CMD_SOLAR) }

#define CLI_GIS_FLAGS                                                                             \
    { "--convention", 1, CLI_HF }, { "--radians", 0, CLI_HF }, { "--overwrite", 0, CLI_ALL },     \
    { "--progress", 0, CLI_ALL }, { "--azimuth", 1, CLI_ONLY(CMD_HORIZON) },                      \
    { "--split", 0, CLI_ONLY(CMD_HORIZON) }, { "--observer-grid", 1, CLI_ONLY(CMD_VIEWSHED) },    \
    { "--curvature", 0, CLI_ONLY(CMD_VIEWSHED) }, { "--refraction", 1, CLI_ONLY(CMD_VIEWSHED) },  \
    { "--earth-radius", 1, CLI_ONLY(CMD_VIEWSHED) }, { "--svf", 1, CLI_ONLY(CMD_SKYVIEW) },       \
    { "--blend", 1, CLI_ONLY(CMD_HILLSHADE) }, { "--no-shadows", 0, CLI_ONLY(CMD_HILLSHADE) },    \
    { "--negative", 0, CLI_ONLY(CMD_OPENNESS) }

/* A finite number with nothing else in s (no leading space, no trailing characters). */
static int cli_parse_real(const char *s, double *out)
{
    char *end;
    double v;
    if (s[0] == '\0' || isspace((unsigned char)s[0])) return 0;
    errno = 0;
    v = strtod(s, &end);
    if (*end != '\0' || !isfinite(v)) return 0;
    *out = v;
    return 1;
}

/* flag's value as a real in [lo, hi] (lo excluded when lo_open); "expect" words the rule. */
static int cli_real(const char *flag, const char *s, double lo, int lo_open, double hi,
                    const char *expect, double *out)
{
    double v;
    if (!cli_parse_real(s, &v) || v < lo || (lo_open && v == lo) || v > hi)
        return cli_error(CLI_EXIT_USAGE, flag, "expected %s, got '%s'", expect, s);
    *out = v;
    return 0;
}

static int cli_int(const char *flag, const char *s, long lo, long hi, const char *expect, int *out)
{
    char *end;
    long v;
    if (s[0] == '\0' || isspace((unsigned char)s[0]))
        return cli_error(CLI_EXIT_USAGE, flag, "expected %s, got '%s'", expect, s);
    errno = 0;
    v = strtol(s, &end, 10);
    if (*end != '\0' || errno == ERANGE || v < lo || v > hi)
        return cli_error(CLI_EXIT_USAGE, flag, "expected %s, got '%s'", expect, s);
    *out = (int)v;
    return 0;
}

/* Case-insensitive "does s end in ext". */
static int cli_ends_with(const char *s, const char *ext)
{
    size_t n = strlen(s), m = strlen(ext), i;
    if (n <= m) return 0;
    for (i = 0; i < m; i++)
        if (tolower((unsigned char)s[n - m + i]) != tolower((unsigned char)ext[i])) return 0;
    return 1;
}

typedef struct cli_flag { const char *name; int has_value; unsigned commands; } cli_flag;
static const cli_flag cli_flags[] = {
    { "-o", 1, CLI_ALL },           { "--range", 1, CLI_ALL },       { "--cell", 1, CLI_ALL },
    { "--zscale", 1, CLI_ALL },     { "--nodata", 1, CLI_ALL },      { "--dirs", 1, CLI_ALL },
    { "--azimuth0", 1, CLI_ALL },   { "--compass", 0, CLI_ALL },     { "--degrees", 0, CLI_ALL },
    { "--border", 1, CLI_ALL },     { "--border-cells", 1, CLI_ALL }, { "--quiet", 0, CLI_ALL },
    { "--band", 1, CLI_ALL },
    { "--max-memory", 1, CLI_ALL },
    { "--dir-range", 1, CLI_ONLY(CMD_HORIZON) | CLI_ONLY(CMD_SKYVIEW) | CLI_ONLY(CMD_SKY)
                        | CLI_ONLY(CMD_LIGHT) | CLI_ONLY(CMD_VISIBILITY) },
    { "--sky", 1, CLI_ONLY(CMD_SKY) | CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI) },
    { "--albedo", 1, CLI_ONLY(CMD_SKY) | CLI_ONLY(CMD_LIGHT) | CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI)
                  | CLI_ONLY(CMD_VOLGI) | CLI_ONLY(CMD_SOLAR) },
    { "--sun-azimuth", 1, CLI_SUN },              { "--sun-elevation", 1, CLI_SUN },
    { "--sun-radius", 1, CLI_SUN | CLI_ONLY(CMD_SOLAR) },               { "--math", 0, CLI_SUN },
    { "--env", 1, CLI_ONLY(CMD_LIGHT) | CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI) },
    { "--method", 1, CLI_ONLY(CMD_LIGHT) | CLI_ONLY(CMD_VOXELIZE) | CLI_ONLY(CMD_SSAO)
                     | CLI_ONLY(CMD_MESHAO) },
    { "--sun-irradiance", 1, CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI) }, { "--albedo-map", 1, CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_SOLAR) },
    { "--emission", 1, CLI_ONLY(CMD_INDIRECT) },  { "--bounces", 1, CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI) },
    { "--output", 1, CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI) | CLI_ONLY(CMD_VOLGI) },
    { "--fraction", 0, CLI_ONLY(CMD_VISIBILITY) }, { "--stats", 0, CLI_ONLY(CMD_VISIBILITY) | CLI_ONLY(CMD_MESHAO) },
    { "--observer", 1, CLI_ONLY(CMD_VIEWSHED) },  { "--observer-height", 1, CLI_ONLY(CMD_VIEWSHED) },
    { "--target-height", 1, CLI_ONLY(CMD_VIEWSHED) },
    { "--max-distance", 1, CLI_ONLY(CMD_VIEWSHED) | CLI_ONLY(CMD_VISFIELD) | CLI_SWEEP | CLI_P2
                           | CLI_ONLY(CMD_SOLAR) },
    { "--window", 1, CLI_SWEEP | CLI_ONLY(CMD_OPENNESS) },
    { "--exact", 0, CLI_ONLY(CMD_VIEWSHED) | CLI_ONLY(CMD_HORIZON) | CLI_ONLY(CMD_SKYVIEW) | CLI_ONLY(CMD_SKY)
                    | CLI_ONLY(CMD_LIGHT) | CLI_ONLY(CMD_SHADOW) },
    { "--res", 1, CLI_ONLY(CMD_VOXELIZE) | CLI_ONLY(CMD_VOLGI) },       { "--mode", 1, CLI_ONLY(CMD_VOXELIZE) },
    { "--axis", 1, CLI_ONLY(CMD_VOXELIZE) },  
    { "--max-vertices", 1, CLI_ONLY(CMD_VOXELIZE) }, { "--padding", 1, CLI_ONLY(CMD_VOXELIZE) },
    { "--open", 0, CLI_ONLY(CMD_VOXELIZE) },
    CLI_GI_FLAGS,
    CLI_VOLGI_FLAGS,
    CLI_VF_FLAGS,
    CLI_LK_FLAGS,
    { "--fov-y", 1, CLI_ONLY(CMD_SSAO) },         { "--ortho", 1, CLI_ONLY(CMD_SSAO) },
    { "--radius", 1, CLI_ONLY(CMD_SSAO) | CLI_ONLY(CMD_MESHAO) | CLI_ONLY(CMD_OPENNESS) },        { "--guard", 1, CLI_ONLY(CMD_SSAO) },
    { "--depth", 1, CLI_ONLY(CMD_SSAO) },         { "--near", 1, CLI_ONLY(CMD_SSAO) },
    { "--far", 1, CLI_ONLY(CMD_SSAO) },
    CLI_SOLAR_FLAGS,
    CLI_GIS_FLAGS
};

/* Apply one recognised flag; returns 0 or CLI_EXIT_USAGE (message printed). */
static int cli_set(cli_args *a, const char *f, const char *v)
{
    {
        int r = cli_set_gis(a, f, v);
        if (r >= 0) return r;
    }
    if (a->cmd == CMD_MESHAO) {
        int r = cli_set_lk(a, f, v);
        if (r >= 0) return r;
    }
    if (a->cmd == CMD_SOLAR) {
        int r = cli_set_solar(a, f, v);
        if (r >= 0) return r;
    }
    if (!strcmp(f, "-o") && a->cmd == CMD_VISFIELD) return cli_set_vf(a, f, v);
    if (!strcmp(f, "-o") && a->cmd == CMD_VOXELIZE) {
        if (cli_ends_with(v, ".binvox")) a->out_binvox = 1;
        else if (cli_ends_with(v, ".raw")) a->out_binvox = 0;
        else return cli_error(CLI_EXIT_USAGE, v, "unknown output type (use a .binvox or .raw name)");
        a->out = v;
        return 0;
    }
    if (!strcmp(f, "-o")) {
        a->out_pgm = a->out_partial = 0;
        if (cli_ends_with(v, ".pfm")) a->out_pgm = 0;
        else if (cli_ends_with(v, ".pgm")) a->out_pgm = 1;
        else if (cli_ends_with(v, ".hfvs")) a->out_partial = 1;
        else if (ex_rio_format_of(v)) a->out_raster = 1;
        else return cli_error(CLI_EXIT_USAGE, v, "unknown output type (use a .pfm, .pgm, .tif, .asc, .bil "
                              "or .flt name)");
        a->out = v;
        return 0;
    }
    if (!strcmp(f, "--dir-range")) { /* "A:B", checked against K in cli_parse */
        char *end;
        long b, e;
        errno = 0;
        b = strtol(v, &end, 10);
        if (end == v || !isdigit((unsigned char)v[0]) || *end != ':' || !isdigit((unsigned char)end[1]))
            return cli_error(CLI_EXIT_USAGE, f, "expected A:B (directions A..B-1), got '%s'", v);
        e = strtol(end + 1, &end, 10);
        if (*end != '\0' || errno == ERANGE || b > CLI_MAX_DIRS || e > CLI_MAX_DIRS)
            return cli_error(CLI_EXIT_USAGE, f, "expected A:B (directions A..B-1), got '%s'", v);
        a->has_dir_range = 1;
        a->dir_begin = (int)b;
        a->dir_end = (int)e;
        return 0;
    }
    if (!strcmp(f, "--range")) {
        char buf[256];
        const char *colon = strchr(v, ':');
        size_t n = colon ? (size_t)(colon - v) : 0;
        if (!colon || n >= sizeof buf)
            return cli_error(CLI_EXIT_USAGE, f, "expected LO:HI, got '%s'", v);
        memcpy(buf, v, n);
        buf[n] = '\0';
        if (!cli_parse_real(buf, &a->range_lo) || !cli_parse_real(colon + 1, &a->range_hi) ||
            fabs(a->range_lo) > CLI_FLT_MAX || fabs(a->range_hi) > CLI_FLT_MAX ||
            !((float)a->range_lo < (float)a->range_hi))
            return cli_error(CLI_EXIT_USAGE, f, "expected LO:HI with finite LO < HI, got '%s'", v);
        a->has_range = 1;
        return 0;
    }
    if (!strcmp(f, "--max-memory")) { /* BYTES with an optional K, M, G or T (powers of 1024) */
        char *end;
        double m;
        errno = 0;
        m = strtod(v, &end);
        if (end != v && *end) {
            const char *u = "KMGT", *q = strchr(u, toupper((unsigned char)*end));
            if (q && end[1] == '\0') m *= pow(1024.0, (double)(q - u + 1)), end++;
        }
        if (end == v || *end != '\0' || !(m >= 0.0) || !isfinite(m) || !isdigit((unsigned char)v[0]))
            return cli_error(CLI_EXIT_USAGE, f, "expected bytes >= 0 with an optional K, M, G or T "
                             "(0 = no limit), got '%s'", v);
        a->max_memory = m;
        return 0;
    }
    if (!strcmp(f, "--cell")) {
        a->has_cell = 1;
        return cli_real(f, v, 0.0, 1, DBL_MAX, "a number > 0", &a->cell);
    }
    if (!strcmp(f, "--band")) return cli_int(f, v, 1, EX_RIO_MAX_BANDS, "a band number 1..65535", &a->band);
    if (!strcmp(f, "--zscale")) {
        if (cli_real(f, v, -CLI_FLT_MAX, 0, CLI_FLT_MAX, "a non-zero number", &a->zscale)) return CLI_EXIT_USAGE;
        if ((float)a->zscale == 0.0f)
            return cli_error(CLI_EXIT_USAGE, f, "expected a non-zero number, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--nodata")) {
        a->has_nodata = 1;
        return cli_real(f, v, -CLI_FLT_MAX, 0, CLI_FLT_MAX, "a finite number", &a->nodata);
    }
    if (!strcmp(f, "--dirs")) a->has_dirs = 1;
    if (!strcmp(f, "--dirs")) return cli_int(f, v, 1, CLI_MAX_DIRS, "an integer 1..65536", &a->dirs);
    if (!strcmp(f, "--degrees")) { a->degrees = 1; return 0; }
    if (!strcmp(f, "--quiet")) { a->quiet = 1; return 0; }
    if (!strcmp(f, "--border")) {
        if (!strcmp(v, "open")) a->border = HFVIS_BORDER_OPEN;
        else if (!strcmp(v, "clamp")) a->border = HFVIS_BORDER_CLAMP;
        else if (!strcmp(v, "wrap")) a->border = HFVIS_BORDER_WRAP;
        else return cli_error(CLI_EXIT_USAGE, f, "expected open, clamp or wrap, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--border-cells"))
        return cli_int(f, v, 1, HFVIS_IMAGE_MAX_DIM, "an integer 1..1048576", &a->border_cells);
    if (!strcmp(f, "--sky")) {
        a->has_sky = 1;
        return cli_real(f, v, 0.0, 0, CLI_FLT_MAX, "a radiance >= 0", &a->sky);
    }
    if (!strcmp(f, "--albedo")) {
        a->has_albedo = 1;
        return cli_real(f, v, 0.0, 0, CLI_FLT_MAX, "an albedo >= 0", &a->albedo);
    }
    if (!strcmp(f, "--sun-irradiance")) {
        a->has_sun_irradiance = 1;
        return cli_real(f, v, 0.0, 0, CLI_FLT_MAX, "an irradiance >= 0", &a->sun_irradiance);
    }
    if (!strcmp(f, "--albedo-map")) { a->albedo_map = v; return 0; }
    if (!strcmp(f, "--emission")) { a->emission = v; return 0; }
    if (!strcmp(f, "--bounces")) {
        a->has_bounces = 1;
        return cli_int(f, v, 0, CLI_MAX_BOUNCES, "an integer 0..1000", &a->bounces);
    }
    if (!strcmp(f, "--output")) {
        if (!strcmp(v, "total")) a->output = OUT_TOTAL;
        else if (!strcmp(v, "direct")) a->output = OUT_DIRECT;
        else if (!strcmp(v, "indirect")) a->output = OUT_INDIRECT;
        else return cli_error(CLI_EXIT_USAGE, f, "expected total, direct or indirect, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--fraction")) { a->fraction = 1; return 0; }
    if (!strcmp(f, "--stats")) { a->stats = 1; return 0; }
    if (!strcmp(f, "--sun-azimuth")) {
        a->has_sun_azimuth = 1;
        return cli_real(f, v, -DBL_MAX, 0, DBL_MAX, "a finite angle in degrees", &a->sun_azimuth);
    }
    if (!strcmp(f, "--sun-elevation")) {
        a->has_sun_elevation = 1;
        return cli_real(f, v, -90.0, 0, 90.0, "degrees in -90..90", &a->sun_elevation);
    }
    if (!strcmp(f, "--sun-radius")) {
        a->has_sun_radius = 1;
        return cli_real(f, v, 0.0, 0, 90.0, "degrees in 0..90", &a->sun_radius);
    }
    if (!strcmp(f, "--env")) { a->env = v; return 0; }
    if (!strcmp(f, "--observer-height"))
        return cli_real(f, v, 0.0, 0, DBL_MAX, "a height >= 0", &a->observer_height);
    if (!strcmp(f, "--target-height"))
        return cli_real(f, v, 0.0, 0, DBL_MAX, "a height >= 0", &a->target_height);
    if (!strcmp(f, "--max-distance"))
        return cli_real(f, v, 0.0, 0, DBL_MAX, "a distance >= 0", &a->max_distance);
    if (!strcmp(f, "--exact")) { a->exact = 1; return 0; }
    if (!strcmp(f, "--window")) { /* X0,Y0,W,H in cells; clipped to the raster when it is read */
        long n[4];
        const char *p = v;
        char *end;
        int k;
        for (k = 0; k < 4; k++, p = end + 1) {
            errno = 0;
            n[k] = strtol(p, &end, 10);
            if (end == p || errno == ERANGE || n[k] < -(long)INT_MAX / 2 || n[k] > (long)INT_MAX / 2 ||
                (k >= 2 && n[k] < 1) || *end != (k < 3 ? ',' : '\0'))
                return cli_error(CLI_EXIT_USAGE, f, "expected X0,Y0,W,H (cells: first column and row, "
                                 "width and height >= 1), got '%s'", v);
        }
        a->has_window = 1;
        a->win_x = (int)n[0], a->win_y = (int)n[1], a->win_w = (int)n[2], a->win_h = (int)n[3];
        return 0;
    }
    if (!strcmp(f, "--res")) return cli_int(f, v, 1, CLI_MAX_RES, "an integer 1..2048", &a->res);
    if (!strcmp(f, "--max-vertices"))
        return cli_int(f, v, 1, 1000000, "an integer 1..1000000", &a->max_vertices);
    if (!strcmp(f, "--padding")) return cli_real(f, v, 0.0, 0, 1.0, "a fraction in 0..1", &a->padding);
    if (!strcmp(f, "--open")) { a->open_mesh = 1; return 0; }
    if (!strcmp(f, "--mode")) {
        if (!strcmp(v, "surface")) a->vox_mode = VOX_SURFACE;
        else if (!strcmp(v, "conservative")) a->vox_mode = VOX_CONSERVATIVE;
        else if (!strcmp(v, "solid")) a->vox_mode = VOX_SOLID;
        else return cli_error(CLI_EXIT_USAGE, f, "expected surface, conservative or solid, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--axis")) {
        static const char *const names[] = {"", "dominant", "all", "x", "y", "z"};
        int k;
        for (k = AXIS_DOMINANT; k <= AXIS_Z; k++)
            if (!strcmp(v, names[k])) { a->vox_axis = k; return 0; }
        return cli_error(CLI_EXIT_USAGE, f, "expected dominant, all, x, y or z, got '%s'", v);
    }
    if (a->cmd == CMD_VISFIELD) {
        int r = cli_set_vf(a, f, v);
        if (r >= 0) return r;
    }
    {
        int r = cli_set_volgi(a, f, v);
        if (r >= 0) return r;
    }
    {
        int r = cli_set_gi(a, f, v);
        if (r >= 0) return r;
        if (a->cmd == CMD_SSAO && (r = cli_set_ssao(a, f, v)) >= 0) return r;
    }
    if (a->cmd == CMD_VOXELIZE) { /* --method of voxelize */
        if (!strcmp(v, "pixel")) a->vox_method = HFVIS_VOXELIZE_PIXEL_RULE;
        else if (!strcmp(v, "slicing")) a->vox_method = HFVIS_VOXELIZE_GS_SLICING;
        else if (!strcmp(v, "clipping")) a->vox_method = HFVIS_VOXELIZE_FRAGMENT_CLIPPING;
        else return cli_error(CLI_EXIT_USAGE, f, "expected pixel, slicing or clipping, got '%s'", v);
        return 0;
    }
    /* --method */
    if (!strcmp(v, "prefix")) a->method = HFVIS_ENV_PREFIX;
    else if (!strcmp(v, "lp")) a->method = HFVIS_ENV_LP_TABLE;
    else return cli_error(CLI_EXIT_USAGE, f, "expected prefix or lp, got '%s'", v);
    return 0;
}

/* --window: the combinations a piece cannot honour; 0 or CLI_EXIT_USAGE (reported). */
static int cli_check_window(const cli_args *a)
{
    if (a->cmd == CMD_OPENNESS ? !(a->radius > 0.0) : !(a->max_distance > 0.0))
        return cli_error(CLI_EXIT_USAGE, "--window", "needs a finite %s: without it a receiver's "
                         "horizon depends on the whole field, so no window of it can be computed "
                         "from the window and a halo", a->cmd == CMD_OPENNESS ? "--radius R" : "--max-distance R");
    if (a->has_dir_range || a->out_partial)
        return cli_error(CLI_EXIT_USAGE, "--window", "cannot be combined with --dir-range");
    if (a->split) return cli_error(CLI_EXIT_USAGE, "--window", "cannot be combined with --split");
    if (a->out_pgm)
        return cli_error(CLI_EXIT_USAGE, a->out, "a piece keeps its values exactly: write .pfm, .tif, "
                         ".bil/.flt or .asc ('hfvis mosaic' writes the .pgm)");
    if (a->border == HFVIS_BORDER_WRAP)
        return cli_error(CLI_EXIT_USAGE, "--window", "--border wrap joins opposite edges of the whole "
                         "raster: not with a window");
    if (a->albedo_map || a->emission)
        return cli_error(CLI_EXIT_USAGE, "--window", "cannot be combined with %s (a map of the whole "
                         "raster)", a->albedo_map ? "--albedo-map" : "--emission");
    return 0;
}

/* Returns CLI_RUN, or the exit status after printing help (0) or a usage error (2). */
static int cli_parse(int argc, char **argv, cli_args *a)
{
    int i, c, positional_only = 0;
    memset(a, 0, sizeof *a);
    a->cell = 1.0; a->zscale = 1.0; a->dirs = 16; a->sky = 1.0; a->albedo = 1.0;
    a->max_memory = cli_default_max_memory();
    a->border = HFVIS_BORDER_OPEN; a->method = HFVIS_ENV_PREFIX;
    a->bounces = 1; a->sun_irradiance = CLI_PI; a->output = OUT_TOTAL;
    a->order = 4; a->subsample = 1;
    a->ssao_method = SSAO_FFAO; a->ssao_depth = SSAO_DEPTH_LINEAR; a->ssao_fov = 60.0;
    a->ssao_guard = -1;
    cli_volgi_defaults(a);
    cli_lk_defaults(a);
    if (argc < 2) return cli_error(CLI_EXIT_USAGE, "usage", "missing COMMAND (try 'hfvis --help')");
    if (!strcmp(argv[1], "-h") || !strcmp(argv[1], "--help") || !strcmp(argv[1], "help")) {
        if (argc > 2 && strcmp(argv[1], "help") == 0) {
            for (c = 0; c < CMD_COUNT; c++)
                if (!strcmp(argv[2], cli_cmd_names[c])) {
                    printf("%s%s%s", cli_cmd_help[c], cli_shared_help, cli_shared_help2);
                    return 0;
                }
            return cli_error(CLI_EXIT_USAGE, argv[2], "unknown command (try 'hfvis --help')");
        }
        printf("%s%s%s", cli_usage, cli_shared_help, cli_shared_help2);
        return 0;
    }
    for (c = 0; c < CMD_COUNT && strcmp(argv[1], cli_cmd_names[c]); c++) {}
    if (c == CMD_COUNT) return cli_error(CLI_EXIT_USAGE, argv[1], "unknown command (try 'hfvis --help')");
    a->cmd = c;
    for (i = 2; i < argc; i++) {
        const char *arg = argv[i], *value = NULL, *eq;
        char name[64];
        size_t n, k;
        if (positional_only || arg[0] != '-' || arg[1] == '\0') {
            if (a->in) return cli_error(CLI_EXIT_USAGE, arg, "unexpected argument (only one IN)");
            a->in = arg;
            continue;
        }
        if (!strcmp(arg, "--")) { positional_only = 1; continue; }
        if (!strcmp(arg, "-h") || !strcmp(arg, "--help")) {
            printf("%s%s%s", cli_cmd_help[a->cmd], cli_shared_help, cli_shared_help2);
            return 0;
        }
        eq = strchr(arg, '=');
        n = eq ? (size_t)(eq - arg) : strlen(arg);
        if (n >= sizeof name) n = sizeof name - 1;
        memcpy(name, arg, n);
        name[n] = '\0';
        for (k = 0; k < sizeof cli_flags / sizeof cli_flags[0]; k++)
            if (!strcmp(name, cli_flags[k].name)) break;
        if (k == sizeof cli_flags / sizeof cli_flags[0])
            return cli_error(CLI_EXIT_USAGE, name, "unknown option (see 'hfvis %s --help')",
                             cli_cmd_names[a->cmd]);
        if ((CLI_ONLY(a->cmd) & CLI_P2) && !strcmp(name, "--window"))
            return cli_error(CLI_EXIT_USAGE, name, "'%s' sweeps whole lattice lines with the [P2] "
                             "hull tree, which honours --max-distance but computes no windows; run "
                             "it whole (or split it with --dir-range)", cli_cmd_names[a->cmd]);
        if (!(cli_flags[k].commands & CLI_ONLY(a->cmd)))
            return cli_error(CLI_EXIT_USAGE, name, "not an option of '%s' (see 'hfvis %s --help')",
                             cli_cmd_names[a->cmd], cli_cmd_names[a->cmd]);
        if (cli_flags[k].has_value) {
            if (eq) value = eq + 1;
            else if (i + 1 < argc) value = argv[++i];
            else return cli_error(CLI_EXIT_USAGE, name, "missing value");
        } else if (eq) {
            return cli_error(CLI_EXIT_USAGE, name, "takes no value");
        }
        if (cli_set(a, name, value)) return CLI_EXIT_USAGE;
    }
    if (!a->in && !(a->cmd == CMD_VOLGI && a->room))
        return cli_error(CLI_EXIT_USAGE, cli_cmd_names[a->cmd], "missing input file IN");
    if (!a->out) return cli_error(CLI_EXIT_USAGE, cli_cmd_names[a->cmd], "missing -o OUT");
    if (a->sky * a->albedo > CLI_FLT_MAX) /* the sky light's scale: outputs would be inf */
        return cli_error(CLI_EXIT_USAGE, "--sky/--albedo", "%g x %g exceeds the float range (3.4e38)",
                         a->sky, a->albedo);
    if (a->has_range && !a->out_pgm)
        return cli_error(CLI_EXIT_USAGE, "--range", a->out_partial ? "applies to 'hfvis sum', not to "
                         "a partial result" : "applies only to .pgm output");
    if (a->out_partial && !a->has_dir_range)
        return cli_error(CLI_EXIT_USAGE, a->out, "a .hfvs partial result needs --dir-range A:B");
    if (a->has_dir_range) {
        if (!a->out_partial)
            return cli_error(CLI_EXIT_USAGE, a->out, "a --dir-range run writes a partial result: use a "
                             ".hfvs name (then 'hfvis sum')");
        if (!(a->dir_begin < a->dir_end && a->dir_end <= a->dirs))
            return cli_error(CLI_EXIT_USAGE, "--dir-range", "expected A:B with 0 <= A < B <= K = %d, got "
                             "%d:%d", a->dirs, a->dir_begin, a->dir_end);
        if (a->stats)
            return cli_error(CLI_EXIT_USAGE, "--stats", "cannot be combined with --dir-range");
    }
    if (a->cmd == CMD_SOLAR) {
        int r = cli_check_solar(a);
        if (r) return r;
    }
    if (a->cmd == CMD_SHADOW && !a->has_sun_azimuth)
        return cli_error(CLI_EXIT_USAGE, "shadow", "missing --sun-azimuth DEG");
    if (a->cmd == CMD_SHADOW && !a->has_sun_elevation)
        return cli_error(CLI_EXIT_USAGE, "shadow", "missing --sun-elevation DEG");
    if (a->cmd == CMD_VIEWSHED && !a->has_observer)
        return cli_error(CLI_EXIT_USAGE, "viewshed", "missing --observer X,Y");
    if (a->cmd == CMD_VOXELIZE) {
        const char *m = a->vox_mode == VOX_SOLID ? "solid" : "conservative";
        if (!a->res) return cli_error(CLI_EXIT_USAGE, "voxelize", "missing --res N");
        if (a->vox_mode != VOX_SURFACE && (a->vox_method != HFVIS_VOXELIZE_PIXEL_RULE || a->max_vertices))
            return cli_error(CLI_EXIT_USAGE, a->max_vertices ? "--max-vertices" : "--method",
                             "applies only to --mode surface, not %s", m);
        if (a->vox_mode == VOX_CONSERVATIVE && a->vox_axis != AXIS_DEFAULT)
            return cli_error(CLI_EXIT_USAGE, "--axis", "does not apply to --mode conservative");
        if (a->vox_mode == VOX_SOLID && (a->vox_axis == AXIS_DOMINANT || a->vox_axis == AXIS_ALL))
            return cli_error(CLI_EXIT_USAGE, "--axis", "--mode solid takes x, y or z");
        if (a->open_mesh && a->vox_mode != VOX_SOLID)
            return cli_error(CLI_EXIT_USAGE, "--open", "applies only to --mode solid");
        if (a->max_vertices && a->vox_method == HFVIS_VOXELIZE_PIXEL_RULE)
            return cli_error(CLI_EXIT_USAGE, "--max-vertices", "needs --method slicing or clipping");
    }
    if (a->cmd == CMD_LIGHT && !a->env)
        return cli_error(CLI_EXIT_USAGE, "light", "missing --env ENV.pfm");
    if (a->cmd == CMD_INDIRECT) {
        int sun = a->has_sun_azimuth || a->has_sun_elevation;
        if (a->has_sun_azimuth && !a->has_sun_elevation)
            return cli_error(CLI_EXIT_USAGE, "--sun-azimuth", "needs --sun-elevation DEG");
        if (a->has_sun_elevation && !a->has_sun_azimuth)
            return cli_error(CLI_EXIT_USAGE, "--sun-elevation", "needs --sun-azimuth DEG");
        if (!sun && (a->has_sun_radius || a->has_sun_irradiance || a->math))
            return cli_error(CLI_EXIT_USAGE, a->has_sun_radius ? "--sun-radius" :
                             a->has_sun_irradiance ? "--sun-irradiance" : "--math",
                             "needs a sun (--sun-azimuth and --sun-elevation)");
        if (a->has_albedo && a->albedo_map)
            return cli_error(CLI_EXIT_USAGE, "--albedo-map", "cannot be combined with --albedo");
        if (a->has_sky && a->env)
            return cli_error(CLI_EXIT_USAGE, "--env", "cannot be combined with --sky");
        if (a->output == OUT_DIRECT && a->has_bounces)
            return cli_error(CLI_EXIT_USAGE, "--bounces", "has no effect with --output direct");
        if (a->output == OUT_INDIRECT && a->bounces < 1)
            return cli_error(CLI_EXIT_USAGE, "--output indirect", "needs --bounces >= 1");
    }
    if (a->has_window && cli_check_window(a)) return CLI_EXIT_USAGE;
    if (a->cmd == CMD_GI && cli_check_gi(a)) return CLI_EXIT_USAGE;
    if (a->cmd == CMD_VOLGI && cli_check_volgi(a)) return CLI_EXIT_USAGE;
    if (a->cmd == CMD_VISFIELD && cli_check_vf(a)) return CLI_EXIT_USAGE;
    if (a->cmd == CMD_MESHAO && cli_check_lk(a)) return CLI_EXIT_USAGE;
    return CLI_RUN;
}
