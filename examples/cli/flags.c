/* flags.c - the command line: the table of flags (name, value, the commands that take it), the
 * parsing primitives (cli_real, cli_int) and cli_parse, which applies each flag and checks the
 * combinations. Owns: cli_args' contents. May call: progress.c (errors), gis.c (GIS flags), the
 * command families' flag setters and checks (sweeps.c, screen.c, meshes.c). */

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

/* The flags: name, value (its placeholder in the help; NULL: the flag takes none), the commands
 * that use it, and for the shared options their --help entry (the others are described in their
 * commands' help). A command refuses by name every flag whose row does not list it; `hfvis
 * --list-flags [CMD]` prints this table, test/cli_test.sh walks it. */
typedef struct cli_flag {
    const char *name, *value;
    unsigned long commands; /* CLI_ONLY(CMD_...) bits */
    const char *help;
} cli_flag;
static const cli_flag cli_flags[] = {
    { "-o", "OUT", CLI_OUT,
      "output file, required: *.pfm writes PFM floats, *.pgm a 16-bit PGM;\n"
      "                    a PGM of a 3-channel result stacks the channels as planes, top to bottom;\n"
      "                    PGM code 0 is NoData and LO..HI map to 1..65535, recorded in the header\n"
      "                    comment \"# hfvis range LO HI nodata 0\"\n"
      "                    *.tif a GeoTIFF (tiled, DEFLATE; Float32, or the smallest integer type\n"
      "                    for viewshed and visibility counts), *.asc an ESRI ASCII grid,\n"
      "                    *.bil/*.flt raw floats + .hdr: these carry IN's georeference and NoData\n"
      "                    (planes and channels become bands)\n" },
    { "--band", "N", CLI_HF,
      "IN is a multi-band raster: use band N (1-based, default 1)\n" },
    { "--range", "LO:HI", CLI_PGM,
      ".pgm only: the values mapped to 0 and 65535 (default per command)\n" },
    { "--cell", "S", CLI_HF,
      "distance between samples, in height units (default: the cell size of a\n"
      "                    georeferenced IN (.tif, .asc, .bil/.flt), else 1 with a note)\n" },
    { "--zscale", "Z", CLI_HF,
      "multiply input values by Z, non-zero (default 1)\n" },
    { "--nodata", "V", CLI_HF,
      "input values equal to V are holes: no occlusion, output NaN (PGM code 0)\n" },
    { "--dirs", "K", CLI_DIRS | CLI_ONLY(CMD_SSAO) | CLI_ONLY(CMD_VISFIELD) | CLI_ONLY(CMD_SOLAR),
      "number of azimuth directions, 1..65536 (default 16)\n" },
    { "--convention", "C", CLI_ANGLES,
      "how azimuths are read and directions ordered (height-field commands):\n"
      "                    compass (default): bearings clockwise from north, direction k at\n"
      "                    azimuth0 + 360k/K; grass: counter-clockwise from east (r.horizon,\n"
      "                    r.sun), direction k at azimuth0 + 360k/K counter-clockwise; grid: the\n"
      "                    library's psi, from east toward south (x toward y; the old --math)\n" },
    { "--azimuth0", "A", CLI_DIRS,
      "azimuth of direction 0 in the convention (default: compass 0 = north;\n"
      "                    grass and grid 0 = east). Degrees (before 0.2: radians); see --radians\n" },
    { "--radians", NULL, CLI_ANGLES,
      "angle flags (--azimuth0, --azimuth, --sun-*) in radians, not degrees\n" },
    { "--compass", NULL, CLI_ANGLES,
      "the same as --convention compass (the default)\n" },
    { "--degrees", NULL, CLI_ONLY(CMD_HORIZON) | CLI_ONLY(CMD_OPENNESS),
      "angle outputs in degrees instead of radians\n" },
    { "--dir-range", "A:B", CLI_ONLY(CMD_HORIZON) | CLI_ONLY(CMD_SKYVIEW) | CLI_ONLY(CMD_SKY) | CLI_ONLY(CMD_LIGHT)
                      | CLI_ONLY(CMD_VISIBILITY),
      "horizon, skyview, sky, light, visibility: only the directions at\n"
      "                    positions A..B-1 of the K (0 <= A < B <= K) in sweep order (with K a\n"
      "                    multiple of 4, each 4 consecutive positions are the quarter turns\n"
      "                    k, k+K/4, k+K/2, k+3K/4 that share one lattice: give A and B as\n"
      "                    multiples of 4 and each part costs its share of the run); OUT (*.hfvs)\n"
      "                    is then a partial result, and 'hfvis sum' adds the parts of a split\n"
      "                    into the single run's OUT\n" },
    { "--border", "MODE", CLI_BORDER | CLI_ONLY(CMD_SOLAR),
      "open (nothing outside the grid, default), clamp (edge heights extend\n"
      "                    outward) or wrap (periodic field)\n" },
    { "--border-cells", "N", CLI_BORDER | CLI_ONLY(CMD_SOLAR),
      "clamp/wrap: lines start N cells outside the grid, 1..1048576\n"
      "                    (default max(width, height))\n" },
    { "--exact", NULL, CLI_ONLY(CMD_VIEWSHED) | CLI_ONLY(CMD_HORIZON) | CLI_ONLY(CMD_SKYVIEW) | CLI_ONLY(CMD_SKY)
                      | CLI_ONLY(CMD_LIGHT) | CLI_ONLY(CMD_SHADOW) | CLI_ONLY(CMD_AZIMUTHS)
                      | CLI_ONLY(CMD_HILLSHADE),
      "horizon, skyview, sky, light, shadow: exact rays (beyond [P1]): every\n"
      "                    sample gets its own ray along the nearest rational direction, no\n"
      "                    interpolation between lattice lines (right at walls, roofs, cliffs;\n"
      "                    'hfvis azimuths --exact' prints the directions used). visibility,\n"
      "                    indirect and gi keep the lattice\n" },
    { "--max-distance", "R", CLI_ONLY(CMD_VIEWSHED) | CLI_ONLY(CMD_VISFIELD) | CLI_SWEEP | CLI_P2
                           | CLI_ONLY(CMD_SOLAR),
      "horizon, skyview, sky, shadow, light, visibility, indirect, hillshade:\n"
      "                    the search radius in height units (--cell applies): occluders farther\n"
      "                    than R along the ray are ignored (GRASS maxdistance, SAGA and RVT radius,\n"
      "                    WhiteboxTools max_dist); 0 = unlimited (default). visibility and\n"
      "                    indirect: visible samples farther than R are not counted or gathered.\n"
      "                    viewshed: its range\n" },
    { "--window", "X0,Y0,W,H", CLI_SWEEP | CLI_ONLY(CMD_OPENNESS),
      "with a finite R (openness: --radius R; not visibility, indirect): only\n"
      "                    the W x H cells from\n"
      "                    column X0, row Y0 (clipped to IN), reading only them and a halo of\n"
      "                    ceil(R/cell) + 1 cells (GeoTIFF strips/tiles, .bil/.flt, PFM and binary\n"
      "                    PGM rows, by seeking); OUT (.pfm .tif .bil .flt .asc) is a piece, placed\n"
      "                    and georeferenced at the window, with its sidecar OUT.tile; 'hfvis\n"
      "                    mosaic' joins the pieces into the whole run's OUT (docs/tiles.md)\n" },
    { "--quiet", NULL, CLI_OUT,
      "no progress bar (shown on stderr only when it is a terminal) and no notes\n" },
    { "--progress", NULL, CLI_RUNS,
      "plain progress lines on stderr instead (percent, elapsed, ETA), for logs\n"
      "                    and job schedulers, and a summary line at the end (time, cells,\n"
      "                    directions); runs over 10 s end with the summary anyway (not --quiet)\n" },
    { "--overwrite", NULL, CLI_OUT,
      "allow OUT to be one of the inputs (refused otherwise: same file,\n"
      "                    through hard and symbolic links too)\n" },
    { "--max-memory", "B", CLI_RUNS,
      "refuse a run whose estimated memory exceeds B bytes (suffix K, M, G or\n"
      "                    T: powers of 1024; 0 = no limit); default half of the physical memory\n"
      "                    where the system reports it (sysconf), else no limit. The estimate and\n"
      "                    the work (lattice nodes swept, rays, voxel updates) are printed on\n"
      "                    stderr with the progress bar\n" },
    { "--threads", "N", CLI_THREADED,
      "horizon, skyview, sky, light, shadow, hillshade, openness --radius: run\n"
      "                    on N threads, 0..256 (0: the online cores; default 1); the output is\n"
      "                    the one-thread run's bit for bit (directions, bands across the sun,\n"
      "                    rows). Each thread holds its own lattice: where first-touch page faults\n"
      "                    are slow (VMs), more threads can be slower (docs/performance.md)\n" },
    { "--sky", "C", CLI_ONLY(CMD_SKY) | CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI), NULL },
    { "--albedo", "A", CLI_ONLY(CMD_SKY) | CLI_ONLY(CMD_LIGHT) | CLI_ONLY(CMD_INDIRECT)
                     | CLI_ONLY(CMD_GI) | CLI_ONLY(CMD_VOLGI) | CLI_ONLY(CMD_SOLAR), NULL },
    { "--sun-azimuth", "DEG", CLI_SUN, NULL },
    { "--sun-elevation", "DEG", CLI_SUN, NULL },
    { "--sun-radius", "DEG", CLI_SUN | CLI_ONLY(CMD_SOLAR), NULL },
    { "--math", NULL, CLI_SUN, NULL },
    { "--env", "ENV", CLI_ONLY(CMD_LIGHT) | CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI), NULL },
    { "--method", "M", CLI_ONLY(CMD_LIGHT) | CLI_ONLY(CMD_VOXELIZE) | CLI_ONLY(CMD_SSAO)
                     | CLI_ONLY(CMD_MESHAO), NULL },
    { "--sun-irradiance", "E", CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI), NULL },
    { "--albedo-map", "MAP", CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_SOLAR), NULL },
    { "--emission", "MAP", CLI_ONLY(CMD_INDIRECT), NULL },
    { "--bounces", "B", CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI), NULL },
    { "--output", "WHAT", CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI) | CLI_ONLY(CMD_VOLGI), NULL },
    { "--fraction", NULL, CLI_ONLY(CMD_VISIBILITY), NULL },
    { "--stats", NULL, CLI_ONLY(CMD_VISIBILITY) | CLI_ONLY(CMD_MESHAO), NULL },
    { "--observer", "X,Y", CLI_ONLY(CMD_VIEWSHED), NULL },
    { "--observer-height", "H", CLI_ONLY(CMD_VIEWSHED), NULL },
    { "--target-height", "H", CLI_ONLY(CMD_VIEWSHED), NULL },
    { "--res", "N", CLI_ONLY(CMD_VOXELIZE) | CLI_ONLY(CMD_VOLGI), NULL },
    { "--mode", "M", CLI_ONLY(CMD_VOXELIZE), NULL },
    { "--axis", "A", CLI_ONLY(CMD_VOXELIZE), NULL },
    { "--max-vertices", "N", CLI_ONLY(CMD_VOXELIZE), NULL },
    { "--padding", "P", CLI_ONLY(CMD_VOXELIZE), NULL },
    { "--open", NULL, CLI_ONLY(CMD_VOXELIZE), NULL },
    { "--order", "O", CLI_ONLY(CMD_GI), NULL },
    { "--subsample", "S", CLI_ONLY(CMD_GI), NULL },
    { "--specular", "S", CLI_ONLY(CMD_GI), NULL },
    { "--shininess", "N", CLI_ONLY(CMD_GI), NULL },
    { "--room", NULL, CLI_ONLY(CMD_VOLGI), NULL },
    { "--iterations", "I", CLI_ONLY(CMD_VOLGI), NULL },
    { "--light", "SPEC", CLI_ONLY(CMD_VOLGI), NULL },
    { "--eye", "X,Y,Z", CLI_ONLY(CMD_VOLGI) | CLI_ONLY(CMD_MESHAO), NULL },
    { "--target", "POINT", CLI_ONLY(CMD_VOLGI) | CLI_ONLY(CMD_MESHAO)
                     | CLI_ONLY(CMD_VIEWSHED), NULL },
    { "--up", "X,Y,Z", CLI_ONLY(CMD_VOLGI) | CLI_ONLY(CMD_MESHAO), NULL },
    { "--fov", "DEG", CLI_ONLY(CMD_VOLGI) | CLI_ONLY(CMD_MESHAO), NULL },
    { "--size", "WxH", CLI_ONLY(CMD_VOLGI) | CLI_ONLY(CMD_VISFIELD) | CLI_ONLY(CMD_MESHAO), NULL },
    { "--transfer", "T", CLI_ONLY(CMD_VOLGI), NULL },
    { "--paths", "P", CLI_ONLY(CMD_VOLGI), NULL },
    { "--reflection", "R", CLI_ONLY(CMD_VOLGI), NULL },
    { "--reflectance", "R", CLI_ONLY(CMD_VOLGI), NULL },
    { "--positions", "K", CLI_ONLY(CMD_VISFIELD), NULL },
    { "--format", "F", CLI_ONLY(CMD_VISFIELD), NULL },
    { "--mapping", "M", CLI_ONLY(CMD_VISFIELD), NULL },
    { "--ao", NULL, CLI_ONLY(CMD_VISFIELD), NULL },
    { "--ground", "Z", CLI_ONLY(CMD_VISFIELD), NULL },
    { "--extent", "E", CLI_ONLY(CMD_VISFIELD), NULL },
    { "--rays", "N", CLI_ONLY(CMD_VISFIELD) | CLI_ONLY(CMD_MESHAO), NULL },
    { "--bias", "B", CLI_ONLY(CMD_VISFIELD), NULL },
    { "--reference", "MESH", CLI_ONLY(CMD_VISFIELD), NULL },
    { "--falloff", "F", CLI_ONLY(CMD_MESHAO), NULL },
    { "--two-sided", NULL, CLI_ONLY(CMD_MESHAO), NULL },
    { "--lut", "T", CLI_ONLY(CMD_MESHAO), NULL },
    { "--seed", "S", CLI_ONLY(CMD_MESHAO), NULL },
    { "--no-jitter", NULL, CLI_ONLY(CMD_MESHAO), NULL },
    { "--pattern", "P", CLI_ONLY(CMD_MESHAO), NULL },
    { "--fov-y", "DEG", CLI_ONLY(CMD_SSAO), NULL },
    { "--ortho", "SCALE", CLI_ONLY(CMD_SSAO), NULL },
    { "--radius", "R", CLI_ONLY(CMD_SSAO) | CLI_ONLY(CMD_MESHAO) | CLI_ONLY(CMD_OPENNESS), NULL },
    { "--guard", "PIXELS", CLI_ONLY(CMD_SSAO), NULL },
    { "--depth", "ENC", CLI_ONLY(CMD_SSAO), NULL },
    { "--near", "N", CLI_ONLY(CMD_SSAO), NULL },
    { "--far", "F", CLI_ONLY(CMD_SSAO), NULL },
    { "--azimuth", "A", CLI_ONLY(CMD_HORIZON), NULL },
    { "--split", NULL, CLI_ONLY(CMD_HORIZON), NULL },
    { "--observer-grid", "C,R", CLI_ONLY(CMD_VIEWSHED), NULL },
    { "--curvature", NULL, CLI_ONLY(CMD_VIEWSHED), NULL },
    { "--refraction", "K", CLI_ONLY(CMD_VIEWSHED), NULL },
    { "--earth-radius", "R", CLI_ONLY(CMD_VIEWSHED), NULL },
    { "--svf", "D", CLI_ONLY(CMD_SKYVIEW), NULL },
    { "--blend", "N", CLI_ONLY(CMD_HILLSHADE), NULL },
    { "--no-shadows", NULL, CLI_ONLY(CMD_HILLSHADE), NULL },
    { "--negative", NULL, CLI_ONLY(CMD_OPENNESS), NULL },
    { "--both", NULL, CLI_ONLY(CMD_OPENNESS), NULL },
    { "--lattice", NULL, CLI_ONLY(CMD_HILLSHADE), NULL },
    { "--day", "DATE", CLI_ONLY(CMD_SOLAR), NULL },
    { "--start", "DATE", CLI_ONLY(CMD_SOLAR), NULL },
    { "--end", "DATE", CLI_ONLY(CMD_SOLAR), NULL },
    { "--time", "HH:MM", CLI_ONLY(CMD_SOLAR), NULL },
    { "--step", "S", CLI_ONLY(CMD_SOLAR), NULL },
    { "--linke", "L", CLI_ONLY(CMD_SOLAR), NULL },
    { "--linke-monthly", "L1,...,L12", CLI_ONLY(CMD_SOLAR), NULL },
    { "--linke-map", "MAP", CLI_ONLY(CMD_SOLAR), NULL },
    { "--latitude", "DEG", CLI_ONLY(CMD_SOLAR), NULL },
    { "--longitude", "DEG", CLI_ONLY(CMD_SOLAR), NULL },
    { "--utc-offset", "H", CLI_ONLY(CMD_SOLAR), NULL },
    { "--solar-time", NULL, CLI_ONLY(CMD_SOLAR), NULL },
    { "--bands", "day|month", CLI_ONLY(CMD_SOLAR), NULL },
    { "--beam", "OUT", CLI_ONLY(CMD_SOLAR), NULL },
    { "--diffuse", "OUT", CLI_ONLY(CMD_SOLAR), NULL },
    { "--reflected", "OUT", CLI_ONLY(CMD_SOLAR), NULL },
    { "--sun-hours", "OUT", CLI_ONLY(CMD_SOLAR), NULL },
};
#define CLI_NFLAGS (sizeof cli_flags / sizeof cli_flags[0])

/* The command named name, or -1. */
static int cli_command_of(const char *name)
{
    int c;
    for (c = 0; c < CMD_COUNT; c++)
        if (!strcmp(name, cli_commands[c].name)) return c;
    return -1;
}

/* The row of flag name in cli_flags, or CLI_NFLAGS. */
static size_t cli_flag_of(const char *name)
{
    size_t k;
    for (k = 0; k < CLI_NFLAGS; k++)
        if (!strcmp(name, cli_flags[k].name)) break;
    return k;
}

/* A flag that command cmd does not take (arg: "--name" or "--name=value"): refused by name,
 * "not used" when the table has it, else unknown. Returns CLI_EXIT_USAGE. */
static int cli_refuse_flag(int cmd, const char *arg)
{
    const char *name = cli_commands[cmd].name, *eq = strchr(arg, '=');
    char flag[64];
    size_t n = eq ? (size_t)(eq - arg) : strlen(arg);
    if (n >= sizeof flag) n = sizeof flag - 1;
    memcpy(flag, arg, n);
    flag[n] = '\0';
    if (cli_flag_of(flag) == CLI_NFLAGS)
        return cli_error(CLI_EXIT_USAGE, flag, "unknown option (see 'hfvis %s --help')", name);
    return cli_error(CLI_EXIT_USAGE, name, "%s is not used by %s (see 'hfvis %s --help')", flag, name, name);
}

/* `hfvis --help` (cmd < 0: the usage, the commands and every shared option) or `hfvis CMD
 * --help` (the command's help and the shared options it uses), from the tables; returns 0. */
static int cli_help(int cmd)
{
    size_t k;
    int c;
    if (cmd < 0) {
        printf("%s", cli_usage);
        for (c = 0; c < CMD_COUNT; c++) printf("  %-11s %s\n", cli_commands[c].name, cli_commands[c].summary);
        printf("\nshared options (each command's --help lists those it uses; it refuses the others):\n");
    } else if (cli_commands[cmd].main) { /* sum, mosaic, info: their help lists their options */
        printf("%s", cli_commands[cmd].help);
        return 0;
    } else {
        printf("%s\nshared options of %s:\n", cli_commands[cmd].help, cli_commands[cmd].name);
    }
    for (k = 0; k < CLI_NFLAGS; k++) {
        const cli_flag *f = &cli_flags[k];
        char label[64];
        if (!f->help || (cmd >= 0 && !(f->commands & CLI_ONLY(cmd)))) continue;
        snprintf(label, sizeof label, "%s%s%s", f->name, f->value ? " " : "", f->value ? f->value : "");
        printf("  %-16s  %s", label, f->help);
    }
    printf("%s", cli_help_tail);
    return 0;
}

/* `hfvis --list-commands`: the commands, one per line (for scripts and tests). */
static int cli_list_commands(int argc)
{
    int c;
    if (argc != 2) return cli_error(CLI_EXIT_USAGE, "--list-commands", "takes no argument");
    for (c = 0; c < CMD_COUNT; c++) printf("%s\n", cli_commands[c].name);
    return fflush(stdout) == 0 && !ferror(stdout) ? 0 : cli_error(CLI_EXIT_ERROR, "stdout", "write error");
}

/* `hfvis --list-flags [COMMAND]`: one flag per line, "NAME VALUE COMMANDS" separated by tabs
 * (VALUE "-" for a flag without one, COMMANDS the commands that use it, comma-separated); with
 * COMMAND, only the flags it uses. */
static int cli_list_flags(int argc, char **argv)
{
    int cmd = -1, c;
    size_t k;
    if (argc > 3) return cli_error(CLI_EXIT_USAGE, "--list-flags", "takes at most one COMMAND");
    if (argc == 3 && (cmd = cli_command_of(argv[2])) < 0)
        return cli_error(CLI_EXIT_USAGE, argv[2], "unknown command (try 'hfvis --list-commands')");
    for (k = 0; k < CLI_NFLAGS; k++) {
        const char *sep = "";
        if (cmd >= 0 && !(cli_flags[k].commands & CLI_ONLY(cmd))) continue;
        printf("%s\t%s\t", cli_flags[k].name, cli_flags[k].value ? cli_flags[k].value : "-");
        for (c = 0; c < CMD_COUNT; c++)
            if (cli_flags[k].commands & CLI_ONLY(c)) printf("%s%s", sep, cli_commands[c].name), sep = ",";
        printf("\n");
    }
    return fflush(stdout) == 0 && !ferror(stdout) ? 0 : cli_error(CLI_EXIT_ERROR, "stdout", "write error");
}

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
    if (!strcmp(f, "--threads")) {
        a->has_threads = 1;
        if (cli_int(f, v, 0, CLI_THREADS_MAX, "an integer 0..256 (0: the online cores)", &a->threads))
            return CLI_EXIT_USAGE;
        if (a->threads == 0) a->threads = cli_threads_online();
        return 0;
    }
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
    if (a->border == HFVIS_BORDER_CLAMP && a->cmd != CMD_OPENNESS) /* openness marches a plain grid */
        return cli_error(CLI_EXIT_USAGE, "--border clamp", "a sweep's clamped lines start outside the "
                         "whole raster, which a window's lines do not: not with --window (run whole, "
                         "or --border open; openness --radius windows take clamp)");
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
    a->threads = 1; /* not the online cores: see --threads' help and docs/performance.md */
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
            if ((c = cli_command_of(argv[2])) < 0)
                return cli_error(CLI_EXIT_USAGE, argv[2], "unknown command (try 'hfvis --help')");
            return cli_help(c);
        }
        return cli_help(-1);
    }
    if ((c = cli_command_of(argv[1])) < 0)
        return cli_error(CLI_EXIT_USAGE, argv[1], "unknown command (try 'hfvis --help')");
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
        if (!strcmp(arg, "-h") || !strcmp(arg, "--help")) return cli_help(a->cmd);
        eq = strchr(arg, '=');
        n = eq ? (size_t)(eq - arg) : strlen(arg);
        if (n >= sizeof name) n = sizeof name - 1;
        memcpy(name, arg, n);
        name[n] = '\0';
        if ((k = cli_flag_of(name)) == CLI_NFLAGS) return cli_refuse_flag(a->cmd, name);
        if ((CLI_ONLY(a->cmd) & CLI_P2) && !strcmp(name, "--window"))
            return cli_error(CLI_EXIT_USAGE, cli_commands[a->cmd].name, "--window is not used by %s: "
                             "it sweeps whole lattice lines with the [P2] hull tree, which honours "
                             "--max-distance but computes no windows; run it whole (or split it with "
                             "--dir-range)", cli_commands[a->cmd].name);
        if (!(cli_flags[k].commands & CLI_ONLY(a->cmd))) return cli_refuse_flag(a->cmd, name);
        if (cli_flags[k].value) {
            if (eq) value = eq + 1;
            else if (i + 1 < argc) value = argv[++i];
            else return cli_error(CLI_EXIT_USAGE, name, "missing value");
        } else if (eq) {
            return cli_error(CLI_EXIT_USAGE, name, "takes no value");
        }
        if (cli_set(a, name, value)) return CLI_EXIT_USAGE;
    }
    if (!a->in && (cli_commands[a->cmd].io & CLI_IN_NEEDED) && !(a->cmd == CMD_VOLGI && a->room))
        return cli_error(CLI_EXIT_USAGE, cli_commands[a->cmd].name, "missing input file IN");
    if (!a->out && (cli_commands[a->cmd].io & CLI_OUT_NEEDED))
        return cli_error(CLI_EXIT_USAGE, cli_commands[a->cmd].name, "missing -o OUT");
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
        if (a->has_threads && a->threads > 1)
            return cli_error(CLI_EXIT_USAGE, "--threads", "a --dir-range part runs on one thread: "
                             "split the range into more parts instead");
        a->threads = 1;
    }
    if (a->cmd == CMD_HILLSHADE) { /* a GIS product: exact shadows unless --lattice */
        if (a->lattice && a->exact)
            return cli_error(CLI_EXIT_USAGE, "--lattice", "cannot be combined with --exact");
        a->exact = !a->lattice;
    }
    if (a->has_threads && a->threads > 1 && a->cmd == CMD_OPENNESS && !(a->radius > 0.0))
        return cli_error(CLI_EXIT_USAGE, "--threads", "openness splits over threads with --radius R "
                         "only (unlimited openness runs on one thread)");
    if (cli_commands[a->cmd].check && cli_commands[a->cmd].check(a)) return CLI_EXIT_USAGE;
    if (a->has_window && cli_check_window(a)) return CLI_EXIT_USAGE;
    return CLI_RUN;
}
