/* gis.c - GIS conventions and georeference: angle units, azimuth conventions (compass, grass,
 * grid), the GIS flags, map coordinates, loading a GeoTIFF/ASC/EHdr raster with its georeference,
 * the integer GeoTIFF types of integral outputs, and the `info` and `azimuths` commands.
 * Owns: the georeference of the run (cli_run_state.geo). May call: progress.c, flags.c's
 * primitives, tiles.c's window plan, examples/raster_io.h. */

/* An angle flag's value in degrees (it was given in radians with --radians). */
static double cli_deg(const cli_args *a, double v)
{
    return a->radians ? v * (180.0 / CLI_PI) : v;
}

/* An azimuth in degrees, read in convention conv, as the library's psi in radians. */
static double cli_psi(int conv, double deg)
{
    if (conv == CONV_COMPASS) return (deg - 90.0) * (CLI_PI / 180.0);
    if (conv == CONV_GRASS) return -deg * (CLI_PI / 180.0);
    return deg * (CLI_PI / 180.0);
}

/* psi in radians as an azimuth of convention conv, in degrees in [0, 360). */
static double cli_from_psi(int conv, double psi)
{
    double deg = psi * (180.0 / CLI_PI), v;
    v = conv == CONV_COMPASS ? deg + 90.0 : conv == CONV_GRASS ? -deg : deg;
    v = fmod(v, 360.0);
    if (v < 0.0) v += 360.0;
    if (v >= 360.0 - 1e-9 || v == 0.0) v = 0.0; /* -0.0 and rounding just under a turn */
    return v;
}

/* The library direction that is direction k of the user's convention: GRASS's directions run
 * counter-clockwise, the library's clockwise from the same psi_0. */
static int cli_lib_direction(const cli_args *a, int k)
{
    return a->convention == CONV_GRASS ? (a->dirs - k) % a->dirs : k;
}

/* "X,Y" -> two finite reals; 0 or CLI_EXIT_USAGE (reported with what). */
static int cli_pair(const char *f, const char *v, const char *what, double *x, double *y)
{
    char buf[256];
    const char *comma = strchr(v, ',');
    size_t n = comma ? (size_t)(comma - v) : 0;
    if (!comma || n >= sizeof buf) return cli_error(CLI_EXIT_USAGE, f, "expected %s, got '%s'", what, v);
    memcpy(buf, v, n);
    buf[n] = '\0';
    if (!cli_parse_real(buf, x) || !cli_parse_real(comma + 1, y) || fabs(*x) > 1e300 || fabs(*y) > 1e300)
        return cli_error(CLI_EXIT_USAGE, f, "expected %s, got '%s'", what, v);
    return 0;
}

/* The GIS flags (conventions, map coordinates, hillshade, openness, safety, progress); -1 if f
 * is none of them. */
static int cli_set_gis(cli_args *a, const char *f, const char *v)
{
    if (!strcmp(f, "--convention")) {
        int c;
        for (c = 0; c < 3; c++)
            if (!strcmp(v, cli_conv_names[c])) {
                a->convention = c;
                a->has_convention = 1;
                return 0;
            }
        if (!strcmp(v, "math"))
            return cli_error(CLI_EXIT_USAGE, f, "'math' is ambiguous: use grass (counter-clockwise "
                             "from east) or grid (from east toward south, the old --math)");
        return cli_error(CLI_EXIT_USAGE, f, "expected compass, grass or grid, got '%s'", v);
    }
    if (!strcmp(f, "--compass")) { /* the default since 0.2; kept so old command lines run */
        if (a->has_convention && a->convention != CONV_COMPASS)
            return cli_error(CLI_EXIT_USAGE, f, "contradicts --convention %s",
                             cli_conv_names[a->convention]);
        a->convention = CONV_COMPASS;
        a->has_convention = 1;
        return 0;
    }
    if (!strcmp(f, "--math"))
        return cli_error(CLI_EXIT_USAGE, f, "removed: it read --sun-azimuth from east toward south, "
                         "now '--convention grid'; GRASS's counter-clockwise from east is "
                         "'--convention grass'");
    if (!strcmp(f, "--radians")) { a->radians = 1; return 0; }
    if (!strcmp(f, "--split")) { a->split = 1; return 0; }
    if (!strcmp(f, "--overwrite")) { a->overwrite = 1; return 0; }
    if (!strcmp(f, "--progress")) { a->progress_lines = 1; return 0; }
    if (a->cmd == CMD_VIEWSHED) {
        if (!strcmp(f, "--observer") || !strcmp(f, "--observer-grid")) {
            if (a->has_observer)
                return cli_error(CLI_EXIT_USAGE, f, "one observer: give --observer X,Y or --observer-grid "
                                 "COL,ROW, once");
            a->observer_grid = f[10] == '-';
            a->has_observer = 1;
            return cli_pair(f, v, a->observer_grid ? "COL,ROW (grid position)" : "X,Y (map "
                            "coordinates)", &a->observer_x, &a->observer_y);
        }
        if (!strcmp(f, "--target")) {
            if (a->ntargets == CLI_MAX_TARGETS)
                return cli_error(CLI_EXIT_USAGE, f, "at most %d targets", CLI_MAX_TARGETS);
            a->ntargets++;
            return cli_pair(f, v, "X,Y (map coordinates)", &a->targets[2 * a->ntargets - 2],
                            &a->targets[2 * a->ntargets - 1]);
        }
        if (!strcmp(f, "--curvature")) { a->curvature = 1; return 0; }
    }
    if (!strcmp(f, "--svf")) {
        static const char *const names[3] = { "zaksek", "saga", "visible" };
        int k;
        for (k = 0; k < 3; k++)
            if (!strcmp(v, names[k])) { a->svf = k; return 0; }
        return cli_error(CLI_EXIT_USAGE, f, "expected zaksek, saga or visible, got '%s'", v);
    }
    if (!strcmp(f, "--no-shadows")) { a->no_shadows = 1; return 0; }
    if (!strcmp(f, "--negative") || !strcmp(f, "--both")) {
        if (a->negative != 0)
            return cli_error(CLI_EXIT_USAGE, f, "give one of --negative and --both");
        a->negative = !strcmp(f, "--both") ? 2 : 1; /* hfvis_openness_options.negative */
        return 0;
    }
    if (!strcmp(f, "--lattice")) { a->lattice = 1; return 0; }
    return -1;
}

/* After parsing: read the angle flags in their unit and convention and store them as the
 * library's psi (a->azimuth0 in radians, --sun-azimuth in psi degrees with a->math set), check
 * the GIS combinations. Returns 0 or CLI_EXIT_USAGE (reported). */
static int cli_gis_finish(cli_args *a)
{
    double deg;
    if (a->cmd == CMD_HILLSHADE) { /* the cartographic default light: north-west, 45 degrees up */
        if (!a->has_sun_azimuth) a->sun_azimuth = a->radians ? 315.0 * CLI_PI / 180.0 : 315.0;
        if (!a->has_sun_elevation) a->sun_elevation = a->radians ? CLI_PI / 4.0 : 45.0;
        a->has_sun_azimuth = a->has_sun_elevation = 1;
        if (!a->blend) a->blend = 1;
    }
    if (a->has_sun_elevation) {
        a->sun_elevation = cli_deg(a, a->sun_elevation);
        if (a->sun_elevation < -90.0 || a->sun_elevation > 90.0)
            return cli_error(CLI_EXIT_USAGE, "--sun-elevation", "expected -90..90 degrees, got %g",
                             a->sun_elevation);
    }
    if (a->has_sun_radius) {
        a->sun_radius = cli_deg(a, a->sun_radius);
        if (a->sun_radius > 90.0)
            return cli_error(CLI_EXIT_USAGE, "--sun-radius", "expected 0..90 degrees, got %g",
                             a->sun_radius);
    }
    if (a->has_sun_azimuth) { /* as psi in degrees: the existing sun code reads that with math */
        a->sun_azimuth = cli_psi(a->convention, cli_deg(a, a->sun_azimuth)) * (180.0 / CLI_PI);
        a->math = 1;
    }
    if (a->has_azimuth) {
        if (a->has_dirs && a->dirs != 1)
            return cli_error(CLI_EXIT_USAGE, "--azimuth", "gives one direction: not with --dirs %d",
                             a->dirs);
        if (a->has_azimuth0)
            return cli_error(CLI_EXIT_USAGE, "--azimuth", "cannot be combined with --azimuth0");
        a->dirs = 1;
        a->azimuth0 = a->azimuth;
        a->has_azimuth0 = 1;
    }
    if (a->svf != 0 && a->has_dir_range)
        return cli_error(CLI_EXIT_USAGE, "--dir-range", "applies to --svf zaksek only");
    if (a->split && (a->out_partial || a->has_dir_range))
        return cli_error(CLI_EXIT_USAGE, "--split", "cannot be combined with --dir-range");
    if (a->convention == CONV_GRASS && a->cmd == CMD_HORIZON && a->has_dir_range)
        return cli_error(CLI_EXIT_USAGE, "--dir-range", "horizon parts keep the library's clockwise "
                         "order: use --convention compass or grid for a split horizon run");
    if ((a->has_refraction || a->has_earth_radius) && !a->curvature)
        return cli_error(CLI_EXIT_USAGE, a->has_refraction ? "--refraction" : "--earth-radius",
                         "applies with --curvature");
    if (a->cmd == CMD_OPENNESS && !a->has_dirs) a->dirs = 8; /* Yokoyama et al.'s eight */
    /* direction 0: north (compass) or east (grass, grid: r.horizon's start=0 and the old default) */
    deg = a->has_azimuth0 ? cli_deg(a, a->azimuth0) : 0.0;
    a->azimuth0 = cli_psi(a->convention, deg);
    a->compass = 0; /* a->azimuth0 is psi_0 now */
    return 0;
}

/* Open path for window reads: a GeoTIFF, ASC or EHdr raster by its extension, else a PFM or a
 * binary PGM. 0, or -1 with r->err. */
static int cli_open_raster(ex_rio_reader *r, const char *path)
{
    return ex_rio_format_of(path) ? ex_rio_open(r, path) : ex_rio_open_netpbm(r, path);
}

/* Load a GeoTIFF, ASC or EHdr IN (band --band): NoData -> NaN, the georeference kept in
 * a->run->geo, *cell from it (geographic CRS refused unless --cell), --cell overriding with a note. */
static int cli_load_raster(const cli_args *a, float **z, int *w, int *h, double *cell)
{
    ex_rio_reader r;
    float *px;
    double rc_cell = 0.0;
    char why[256];
    int gx = 0, gy = 0, gw, gh, threads;
    if (cli_open_raster(&r, a->in) != 0)
        return cli_error(CLI_EXIT_ERROR, a->in, "%s", r.err);
    if (r.format == EX_RIO_NETPBM && r.bands != 1) {
        ex_rio_close(&r);
        return cli_error(CLI_EXIT_ERROR, a->in, "a height field has one channel, this image has %d", 3);
    }
    if ((a->band ? a->band : 1) > r.bands) {
        cli_error(CLI_EXIT_ERROR, a->in, "--band %d: the raster has %d band%s", a->band, r.bands,
                  r.bands == 1 ? "" : "s");
        ex_rio_close(&r);
        return CLI_EXIT_ERROR;
    }
    if (!a->run->win.active && (r.width > HFVIS_IMAGE_MAX_DIM || r.height > HFVIS_IMAGE_MAX_DIM ||
        (size_t)r.width * (size_t)r.height > HFVIS_IMAGE_MAX_VALUES)) {
        cli_error(CLI_EXIT_ERROR, a->in, "%s: %d x %d cells exceed the limit of 2^28 values",
                  hfvis_status_string(HFVIS_ERR_LIMIT), r.width, r.height);
        ex_rio_close(&r);
        return CLI_EXIT_ERROR;
    }
    if (r.geo.has_transform) {
        if (r.geo.crs == EX_RIO_CRS_GEOGRAPHIC && !a->has_cell) {
            char crs[32] = "";
            if (r.geo.epsg) snprintf(crs, sizeof crs, ", EPSG:%d", r.geo.epsg);
            cli_error(CLI_EXIT_ERROR, a->in, "geographic coordinates (cells in degrees%s): reproject to "
                      "metres first, e.g. gdalwarp -t_srs EPSG:32633 (your UTM zone) -r bilinear IN out.tif, "
                      "or give --cell in metres", crs);
            ex_rio_close(&r);
            return CLI_EXIT_ERROR;
        }
        if (ex_georef_cell(&r.geo, &rc_cell, why) != 0) {
            cli_error(CLI_EXIT_ERROR, a->in, "%s", why);
            ex_rio_close(&r);
            return CLI_EXIT_ERROR;
        }
        if (!a->has_cell) *cell = rc_cell;
        else if (!a->quiet && a->cell != rc_cell)
            fprintf(stderr, "hfvis: note: --cell %g overrides the cell size %.10g of %s\n", a->cell, rc_cell,
                    a->in);
    } else if (!a->has_cell && !a->quiet) {
        fprintf(stderr, r.format == EX_RIO_NETPBM ? "hfvis: note: %s has no cell size: using 1 (give --cell)\n"
                : "hfvis: note: %s has no georeference: cell size 1 (give --cell)\n", a->in);
    }
    gw = r.width, gh = r.height;
    if (a->run->win.active) { /* the window and its halo only (estimate, refusal before allocating) */
        int rc = cli_window_plan(a, &r, a->in, *cell);
        if (rc != 0) {
            ex_rio_close(&r);
            return rc;
        }
        gx = a->run->win.gx0, gy = a->run->win.gy0, gw = a->run->win.gw, gh = a->run->win.gh;
    }
    px = cli_alloc((size_t)gw, (size_t)gh, 1);
    if (!px) {
        ex_rio_close(&r);
        return cli_status(a->in, HFVIS_ERR_OUT_OF_MEMORY, 0);
    }
    r.nodata_to_nan = 1;
    threads = cli_run_threads(a); /* each thread decodes its rows' chunks and first touches their pages */
    if (ex_rio_read_parallel(&r, a->in, a->band ? a->band - 1 : 0, gx, gy, gw, gh, px, gw,
                             threads > 1 ? cli_parallel_for : NULL, &threads) != 0) {
        cli_error(CLI_EXIT_ERROR, a->in, "%s", r.err);
        free(px);
        ex_rio_close(&r);
        return CLI_EXIT_ERROR;
    }
    *z = px; *w = gw; *h = gh;
    ex_georef_free(&a->run->geo);
    a->run->geo = r.geo; /* moved: the reader no longer owns it */
    memset(&r.geo, 0, sizeof r.geo);
    if (a->run->win.active) /* the piece's origin */
        ex_georef_shift(&a->run->geo, a->run->win.x0, a->run->win.y0);
    ex_rio_close(&r);
    return 0;
}

/* Integral outputs (viewshed 0/1, visibility counts) go into the smallest integer GeoTIFF type
 * holding their values and NoData: the input's NoData when it is an integer, else (holes
 * present) one past the largest value. Returns 0 (and leaves o, g alone) to keep Float32. */
static int cli_integral_type(const cli_args *a, const float *px, size_t n, ex_georef *g,
                             ex_rio_write_options *o)
{
    static const int types[4][2] = { { EX_RIO_UINT, 8 }, { EX_RIO_UINT, 16 }, { EX_RIO_INT, 16 },
                                     { EX_RIO_INT, 32 } };
    double lo = 0.0, hi = 0.0, nd = 0.0;
    int holes = 0, want_nd, k;
    size_t i;
    if (!(a->cmd == CMD_VIEWSHED || (a->cmd == CMD_VISIBILITY && !a->fraction))) return 0;
    for (i = 0; i < n; i++) {
        double v = (double)px[i];
        if (isnan(v)) { holes = 1; continue; }
        if (v != floor(v) || fabs(v) > 2147483647.0) return 0;
        if (v < lo) lo = v;
        if (v > hi) hi = v;
    }
    want_nd = holes || g->has_nodata;
    if (g->has_nodata && isfinite(g->nodata) && g->nodata == floor(g->nodata)) nd = g->nodata;
    else if (g->has_nodata && !holes) want_nd = 0; /* a NaN or fractional NoData nobody needs */
    else if (want_nd) nd = hi + 1.0;
    for (k = 0; k < 4; k++) {
        double tlo = types[k][0] == EX_RIO_UINT ? 0.0 : -ldexp(1.0, types[k][1] - 1);
        double thi = types[k][0] == EX_RIO_UINT ? ldexp(1.0, types[k][1]) - 1.0 : ldexp(1.0, types[k][1] - 1) - 1.0;
        if (lo >= tlo && hi <= thi && (!want_nd || (nd >= tlo && nd <= thi))) break;
    }
    if (k == 4) return 0;
    o->kind = types[k][0];
    o->bits = types[k][1];
    o->predictor = 2;
    g->has_nodata = want_nd;
    if (want_nd) {
        g->nodata = nd;
        snprintf(g->nodata_text, sizeof g->nodata_text, "%.0f", nd);
    }
    return 1;
}

/* The georeference as a GDAL geotransform: map X = gt[0] + P*gt[1] + L*gt[2],
 * Y = gt[3] + P*gt[4] + L*gt[5] for pixel-corner coordinates (P, L); the sample of column c, row
 * r is the centre of its pixel, (P, L) = (c + 0.5, r + 0.5). Without a georeferenced input
 * (PFM, PGM) the sample of column c, row r lies at X = c*cell, Y = r*cell (the library's world
 * frame: Y grows southward). */
static void cli_georef(const cli_args *a, double cell, double gt[6])
{
    int i;
    if (a->has_geotransform) {
        for (i = 0; i < 6; i++) gt[i] = a->geotransform[i];
        return;
    }
    if (a->run->geo.has_transform) { /* a georeferenced input (GeoTIFF, ASC, EHdr) */
        for (i = 0; i < 6; i++) gt[i] = a->run->geo.gt[i];
        return;
    }
    gt[0] = -0.5 * cell, gt[1] = cell, gt[2] = 0.0;
    gt[3] = -0.5 * cell, gt[4] = 0.0, gt[5] = cell;
}

/* Map point (X, Y) -> grid position (x, y) (column, row of sample centres); 0 if the transform
 * cannot be inverted. */
static int cli_map_to_grid(const cli_args *a, double cell, double X, double Y, double *x, double *y)
{
    double gt[6], det, dx, dy;
    cli_georef(a, cell, gt);
    det = gt[1] * gt[5] - gt[2] * gt[4];
    if (!(fabs(det) > 0.0) || !isfinite(det)) return 0;
    dx = X - gt[0], dy = Y - gt[3];
    *x = (gt[5] * dx - gt[2] * dy) / det - 0.5;
    *y = (-gt[4] * dx + gt[1] * dy) / det - 0.5;
    return isfinite(*x) && isfinite(*y);
}

/* `hfvis info RASTER`: the header of a raster (any the tool reads), one "key value" per line, for
 * scripts (examples/tiles.sh): only the header is read. */
static int cli_info(int argc, char **argv)
{
    ex_rio_reader r;
    double cell = 0.0;
    char why[256];
    static const char *const crs[4] = { "unknown", "projected", "geographic", "geocentric" };
    static const char *const fmt[5] = { "", "tiff", "asc", "ehdr", "pgm" };
    int i;
    for (i = 2; i < argc; i++) /* info takes no flag: each is refused by name */
        if (argv[i][0] == '-' && argv[i][1] != '\0') {
            if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) return cli_help(CMD_INFO);
            return cli_refuse_flag(CMD_INFO, argv[i]);
        }
    if (argc != 3) return cli_error(CLI_EXIT_USAGE, "info", "usage: hfvis info RASTER");
    if (cli_open_raster(&r, argv[2]) != 0)
        return cli_error(CLI_EXIT_ERROR, argv[2], "%s", r.err);
    printf("width %d\nheight %d\nbands %d\n", r.width, r.height, r.bands);
    if (r.geo.has_transform && ex_georef_cell(&r.geo, &cell, why) == 0) printf("cell %.17g\n", cell);
    else printf("cell none\n");
    if (r.geo.has_transform) printf("origin %.17g %.17g\n", r.geo.gt[0], r.geo.gt[3]); /* upper-left corner */
    else printf("origin none\n");
    printf("crs %s", crs[r.geo.crs >= 0 && r.geo.crs < 4 ? r.geo.crs : 0]);
    if (r.geo.epsg) printf(" EPSG:%d", r.geo.epsg);
    printf("\nnodata %s\nformat %s\n", r.geo.has_nodata ? r.geo.nodata_text : "none",
           r.format == EX_RIO_NETPBM && r.kind == EX_RIO_FLOAT ? "pfm" /* a PFM, not a PGM */
           : fmt[r.format >= 1 && r.format <= 4 ? r.format : 0]);
    ex_rio_close(&r);
    return fflush(stdout) == 0 && !ferror(stdout) ? 0 : cli_error(CLI_EXIT_ERROR, "info", "cannot write to stdout");
}

/* azimuths: --dirs is required (the run commands default to 16, but a list of "the" azimuths
 * without K would be a guess). */
static int cli_check_azimuths(const cli_args *a)
{
    return a->has_dirs ? 0 : cli_error(CLI_EXIT_USAGE, "azimuths", "needs --dirs K");
}

/* hfvis azimuths [IN]: the directions of a run (hfvis_sweep_azimuths), one per line, from the
 * flags as cli_parse and cli_gis_finish read them for the run commands (a->azimuth0 is psi_0).
 * IN, when given, is read as a run reads it (a GIS raster's header only): the directions do not
 * depend on it, but a file the run would refuse is refused here too. */
static int cli_run_azimuths(const cli_args *a)
{
    hfvis_sweep_options o = hfvis_sweep_options_default();
    const int K = a->dirs;
    double *az;
    int k;
    if (a->in && ex_rio_format_of(a->in)) { /* a GIS raster: its header */
        ex_rio_reader r;
        if (ex_rio_open(&r, a->in) != 0) return cli_error(CLI_EXIT_ERROR, a->in, "%s", r.err);
        ex_rio_close(&r);
    } else if (a->in) { /* PGM or PFM: read as the run reads it */
        hfvis_image_info info;
        float *px = NULL;
        hfvis_status s;
        errno = 0;
        s = hfvis_image_load(a->in, NULL, &px, &info);
        if (s != HFVIS_OK) return cli_status(a->in, s, errno);
        hfvis_free(NULL, px);
    }
    if (a->exact) o.rays = HFVIS_RAYS_EXACT;
    o.azimuth0_rad = a->azimuth0;
    az = (double *)malloc((size_t)K * sizeof(double));
    if (!az) return cli_status("azimuths", HFVIS_ERR_OUT_OF_MEMORY, 0);
    if (hfvis_sweep_azimuths(K, &o, az, NULL) != HFVIS_OK) {
        free(az);
        return cli_error(CLI_EXIT_USAGE, "--azimuth0", "not a usable azimuth");
    }
    for (k = 0; k < K; k++) /* GRASS's direction k is the library's (K - k) mod K */
        printf("%.17g\n", cli_from_psi(a->convention, az[a->convention == CONV_GRASS ? (K - k) % K : k]));
    free(az);
    return fflush(stdout) == 0 && !ferror(stdout) ? 0 : cli_error(CLI_EXIT_ERROR, "stdout", "write error");
}
