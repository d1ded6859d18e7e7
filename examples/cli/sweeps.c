/* sweeps.c - the sweep commands' helpers and `gi`: environment and per-sample maps, the radiance
 * overflow check, gi's flags and run, and the horizon's planes per file (--split).
 * May call: progress.c, gis.c, write.c. */

/* The light flags `gi` and `indirect` share: the sun needs both angles (and its other flags a
 * sun), the sky and an environment exclude each other, --output agrees with --bounces; returns 0
 * or CLI_EXIT_USAGE (message printed). */
static int cli_check_light_flags(const cli_args *a)
{
    int sun = a->has_sun_azimuth || a->has_sun_elevation;
    if (a->has_sun_azimuth && !a->has_sun_elevation)
        return cli_error(CLI_EXIT_USAGE, "--sun-azimuth", "needs --sun-elevation DEG");
    if (a->has_sun_elevation && !a->has_sun_azimuth)
        return cli_error(CLI_EXIT_USAGE, "--sun-elevation", "needs --sun-azimuth DEG");
    if (!sun && (a->has_sun_radius || a->has_sun_irradiance || a->math))
        return cli_error(CLI_EXIT_USAGE, a->has_sun_radius ? "--sun-radius" :
                         a->has_sun_irradiance ? "--sun-irradiance" : "--math",
                         "needs a sun (--sun-azimuth and --sun-elevation)");
    if (a->has_sky && a->env)
        return cli_error(CLI_EXIT_USAGE, "--env", "cannot be combined with --sky");
    if (a->output == OUT_DIRECT && a->has_bounces)
        return cli_error(CLI_EXIT_USAGE, "--bounces", "has no effect with --output direct");
    if (a->output == OUT_INDIRECT && a->bounces < 1)
        return cli_error(CLI_EXIT_USAGE, "--output indirect", "needs --bounces >= 1");
    return 0;
}

/* Combinations `gi` rejects; returns 0 or CLI_EXIT_USAGE (message printed). */
static int cli_check_gi(const cli_args *a)
{
    if (a->has_shininess && !a->has_specular)
        return cli_error(CLI_EXIT_USAGE, "--shininess", "needs --specular S");
    if (a->has_dirs && a->dirs > HFVIS_NS_MAX_DIRECTIONS)
        return cli_error(CLI_EXIT_USAGE, "--dirs", "gi takes 1..%d azimuthal slices, got %d",
                         HFVIS_NS_MAX_DIRECTIONS, a->dirs);
    return cli_check_light_flags(a);
}



/* Load a lat-long environment map (any image the codecs read). */
static int cli_load_env(const char *path, float **px, hfvis_env *env)
{
    hfvis_image_info info;
    hfvis_status s;
    errno = 0;
    size_t i, n;
    s = hfvis_image_load(path, NULL, px, &info);
    if (s != HFVIS_OK) return cli_status(path, s, errno);
    env->radiance = *px; env->n_theta = info.height; env->n_phi = info.width;
    env->channels = info.channels;
    n = (size_t)info.width * (size_t)info.height * (size_t)info.channels;
    for (i = 0; i < n; i++) /* radiance: finite and >= 0 (a NaN or negative sky is no light) */
        if (!((*px)[i] >= 0.0f && (*px)[i] <= FLT_MAX)) {
            size_t pix = i / (size_t)info.channels;
            return cli_error(CLI_EXIT_ERROR, path, "radiance %g at (%lu, %lu): must be finite and >= 0",
                             (double)(*px)[i], (unsigned long)(pix % (size_t)info.width),
                             (unsigned long)(pix / (size_t)info.width));
        }
    return 0;
}

/* The cells of a map that the grid covers, read by rows: a --window run's grid (the window and
 * its halo) of a map of the whole raster's size, or a whole run's grid (win NULL or inactive:
 * the map of grid's size, from 0, 0). A GeoTIFF, ASC or EHdr map (by its extension, as IN is
 * read) through examples/raster_io.h, its NoData cells NaN; else a PFM or PGM. Each band's
 * samples interleaved as hfvis_image_load gives a PFM's channels, PGM samples still 0..maxval
 * (*maxval set, 0 for the others). */
static int cli_load_map_window(const char *path, const cli_window *win, const hfvis_grid *grid, float **px,
                               int *channels, double *maxval)
{
    ex_rio_reader r;
    float *m = NULL, *plane = NULL;
    const int active = win && win->active;
    const int ew = active ? win->ext_w : grid->width, eh = active ? win->ext_h : grid->height;
    const int gx = active ? win->gx0 : 0, gy = active ? win->gy0 : 0;
    const int gw = active ? win->gw : grid->width, gh = active ? win->gh : grid->height;
    size_t i, n = (size_t)gw * (size_t)gh;
    int b, rc = 0;
    if (cli_open_raster(&r, path) != 0) {
        rc = cli_error(CLI_EXIT_ERROR, path, "%s (a map is a GeoTIFF .tif, ASC .asc, EHdr .bil/.flt, PFM or "
                       "PGM)", r.err);
        ex_rio_close(&r);
        return rc;
    }
    if (r.width != ew || r.height != eh) {
        rc = cli_error(CLI_EXIT_ERROR, path, "%d x %d samples, but IN has %d x %d", r.width, r.height, ew, eh);
    } else if (!(m = (float *)malloc(n * (size_t)r.bands * sizeof(float))) ||
               (r.bands > 1 && !(plane = (float *)malloc(n * sizeof(float))))) {
        rc = cli_status(path, HFVIS_ERR_OUT_OF_MEMORY, 0);
    }
    r.nodata_to_nan = 1;
    for (b = 0; rc == 0 && b < r.bands; b++) {
        float *dst = r.bands > 1 ? plane : m;
        if (ex_rio_read(&r, b, gx, gy, gw, gh, dst, gw) != 0) {
            rc = cli_error(CLI_EXIT_ERROR, path, "%s", r.err);
            break;
        }
        if (r.bands > 1)
            for (i = 0; i < n; i++) m[i * (size_t)r.bands + (size_t)b] = plane[i];
    }
    *channels = r.bands;
    *maxval = r.maxval;
    ex_rio_close(&r);
    free(plane);
    if (rc != 0) {
        free(m);
        return rc;
    }
    *px = m;
    return 0;
}

/* Load a per-sample map of the height field's size (indirect --albedo-map, --emission, solar
 * --linke-map and --albedo-map; in a --window run the raster's size, of which the grid's cells
 * are read): a GeoTIFF, ASC or EHdr raster (NoData cells NaN), PGM values divided by the file's
 * maxval, PFM values as stored; every value finite and >= 0 wherever the height field has no
 * hole. */
static int cli_load_map(const char *path, const cli_window *win, const hfvis_grid *grid, float **px,
                        int *channels)
{
    hfvis_image_info info;
    float *m = NULL;
    size_t i, n = (size_t)grid->width * (size_t)grid->height;
    int c;
    double maxval = 0.0;
    hfvis_status s;
    if ((win && win->active) || ex_rio_format_of(path)) {
        int rc = cli_load_map_window(path, win, grid, &m, &info.channels, &maxval);
        if (rc != 0) return rc;
    } else {
        errno = 0;
        s = hfvis_image_load(path, NULL, &m, &info);
        if (s == HFVIS_ERR_FORMAT)
            return cli_error(CLI_EXIT_ERROR, path, "%s: not a PFM or PGM (a map is a GeoTIFF .tif, ASC .asc, "
                             "EHdr .bil/.flt, PFM or PGM)", hfvis_status_string(s));
        if (s != HFVIS_OK) return cli_status(path, s, errno);
        if (info.width != grid->width || info.height != grid->height) {
            hfvis_free(NULL, m);
            return cli_error(CLI_EXIT_ERROR, path, "%d x %d samples, but IN has %d x %d", info.width,
                             info.height, grid->width, grid->height);
        }
        if (info.format == HFVIS_FORMAT_PGM) maxval = (double)info.maxval;
    }
    for (i = 0; i < n; i++)
        for (c = 0; c < info.channels; c++) {
            float *v = m + i * (size_t)info.channels + (size_t)c;
            if (maxval > 0.0) *v = (float)((double)*v / maxval);
            if (isfinite(grid->z[i]) && !(isfinite(*v) && *v >= 0.0f)) {
                double bad = (double)*v;
                int ox = win && win->active ? win->gx0 : 0, oy = win && win->active ? win->gy0 : 0;
                hfvis_free(NULL, m);
                return cli_error(CLI_EXIT_ERROR, path, "value %g at column %d, row %d is not a "
                                 "finite number >= 0", bad, ox + (int)(i % (size_t)grid->width),
                                 oy + (int)(i / (size_t)grid->width));
            }
        }
    *px = m;
    *channels = info.channels;
    return 0;
}

/* Give a one-channel array of n samples `channels` channels (each a copy), replacing *px. */
static int cli_widen(float **px, size_t n, int channels)
{
    size_t i;
    int c;
    float *w = cli_alloc(n, (size_t)channels, 1);
    if (!w) return cli_status("indirect", HFVIS_ERR_OUT_OF_MEMORY, 0);
    for (i = 0; i < n; i++)
        for (c = 0; c < channels; c++) w[i * (size_t)channels + (size_t)c] = (*px)[i];
    hfvis_free(NULL, *px);
    *px = w;
    return 0;
}

/* Largest finite value of px[0..n), or fallback if none is > 0: the top of a default PGM range. */
static double cli_top(const float *px, size_t n, double fallback)
{
    size_t i;
    double top = 0.0;
    for (i = 0; i < n; i++)
        if (isfinite(px[i]) && (double)px[i] > top) top = (double)px[i];
    return (float)top > 0.0f ? top : fallback;
}

/* Radiance outputs scale with the inputs (sky, sun, environment, emission, albedo, specular),
 * each bounded by the float range alone, so their product can overflow: refuse a result that is
 * not finite where the height field has a sample, rather than write it with exit 0. */
static int cli_check_radiance(const char *cmd, const hfvis_grid *grid, const float *out, int channels)
{
    int x, y, c;
    for (y = 0; y < grid->height; y++)
        for (x = 0; x < grid->width; x++) {
            const size_t i = (size_t)y * (size_t)grid->width + (size_t)x;
            if (!isfinite(grid->z[(ptrdiff_t)y * grid->stride + x])) continue;
            for (c = 0; c < channels; c++)
                if (!isfinite(out[i * (size_t)channels + (size_t)c]))
                    return cli_error(CLI_EXIT_ERROR, cmd, "the result at column %d, row %d is %g: "
                                     "the light inputs (sky, sun, environment, emission, albedo, "
                                     "specular) overflow the float range (3.4e38); scale them down",
                                     x, y, (double)out[i * (size_t)channels + (size_t)c]);
        }
    return 0;
}


/* gi: hfvis_ns_gi with a uniform sky or a projected environment, and an optional sun. */
static int cli_run_gi(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts,
                  cli_progress_state *prog)
{
    const char *cmd = "gi";
    const int w = grid->width, h = grid->height;
    const size_t n = (size_t)w * (size_t)h;
    const int bounces = a->output == OUT_DIRECT ? 0 : a->bounces;
    float *env_px = NULL, *direct = NULL, *bounce = NULL, *out = NULL;
    double env_sh[4 * HFVIS_SH_COEFFS];
    int channels = 1, rc = 0, c, b;
    hfvis_env env;
    hfvis_sun sun;
    hfvis_ns_scene scene;
    hfvis_ns_gi_options o = hfvis_ns_gi_options_default();
    hfvis_ns_gi_outputs res;
    hfvis_status s;
    size_t i;

    memset(&env, 0, sizeof env);
    memset(&sun, 0, sizeof sun);
    memset(&scene, 0, sizeof scene);
    memset(&res, 0, sizeof res);
    memset(env_sh, 0, sizeof env_sh);
    if (a->env) {
        if ((rc = cli_load_env(a->env, &env_px, &env)) != 0) goto done;
        channels = env.channels;
        s = hfvis_sh_project_env(&env, env_sh); /* the environment as order-4 SH ([NS09] §7) */
        if (s != HFVIS_OK) { rc = cli_status(a->env, s, 0); goto done; }
    } else {
        env_sh[0] = 2.0 * sqrt(CLI_PI) * a->sky; /* a uniform sky c: Int c Y_00 = 2 sqrt(pi) c */
    }
    scene.channels = channels;
    scene.env_sh = env_sh;
    for (c = 0; c < 4; c++) scene.albedo[c] = (float)a->albedo;
    scene.specular = (float)a->specular;
    scene.shininess = (float)a->shininess; /* --shininess, default 32 */
    if (a->has_sun_azimuth) {
        double psi_deg = a->math ? a->sun_azimuth : a->sun_azimuth - 90.0;
        sun.azimuth_rad = psi_deg * (CLI_PI / 180.0);
        sun.elevation_rad = a->sun_elevation * (CLI_PI / 180.0);
        sun.radius_rad = a->sun_radius * (CLI_PI / 180.0);
        for (c = 0; c < 4; c++) sun.irradiance[c] = (float)a->sun_irradiance;
        scene.lights = &sun;
        scene.light_count = 1;
    }
    o.directions = a->has_dirs ? a->dirs : 32;
    o.sh_order = a->order;
    o.subsample = a->subsample;
    o.border = opts->border;
    o.azimuth0_rad = opts->azimuth0_rad;
    o.key_mode = HFVIS_NS_KEY_RATIO; /* a disc sun keeps its brightness (see hfvis.h) */
    o.progress = opts->progress;
    o.progress_user = opts->progress_user;
    prog->total = 0; /* the library reports receiver rows over all passes */

    direct = cli_alloc(n, (size_t)channels, 1);
    out = cli_alloc(n, (size_t)channels, 1);
    if (bounces > 0) bounce = cli_alloc(n, (size_t)channels, (size_t)bounces);
    if (!direct || !out || (bounces > 0 && !bounce)) {
        rc = cli_status(cmd, HFVIS_ERR_OUT_OF_MEMORY, 0);
        goto done;
    }
    res.bounces = bounces;
    res.direct = direct;
    res.bounce = bounce;
    s = hfvis_ns_gi(grid, &scene, &o, &res);
    if (s != HFVIS_OK) { rc = cli_status(cmd, s, 0); goto done; }
    for (i = 0; i < n * (size_t)channels; i++) {
        double v = a->output == OUT_INDIRECT ? 0.0 : (double)direct[i];
        for (b = 0; b < bounces; b++) v += (double)bounce[(size_t)b * n * (size_t)channels + i];
        out[i] = (float)v;
    }
    if ((rc = cli_check_radiance(cmd, grid, out, channels)) != 0) goto done;
    rc = cli_save(a, cli_output_of(out, w, h, 1, channels, 0.0, cli_top(out, n * (size_t)channels, 1.0)));
done:
    free(out);
    free(bounce);
    free(direct);
    hfvis_free(NULL, env_px);
    return rc;
}

/* The azimuth in the user's convention, in degrees, of the direction that plane k holds: the one
 * the run actually used (exact rays: the rational direction (a, b) nearest the nominal one,
 * hfvis_sweep_azimuths), so that names and band descriptions never claim the nominal azimuth. */
static double cli_plane_azimuth(const cli_args *a, const double *used, int k)
{
    const int K = a->dirs, kl = cli_lib_direction(a, k);
    const double nominal = a->azimuth0 + 2.0 * CLI_PI * kl / K;
    const double lib0 = a->compass ? a->azimuth0 - CLI_PI / 2.0 : a->azimuth0; /* as cli_run_heights */
    double psi = nominal;
    if (used) psi += used[kl] - (lib0 + 2.0 * CLI_PI * (double)kl / (double)K);
    return cli_from_psi(a->convention, psi);
}

static void cli_labels_free(cli_labels *L)
{
    free(L->used);
    free(L->meta);
    free(L->band);
    free(L->values);
    free(L->names);
    memset(L, 0, sizeof *L);
}

/* The labels of a horizon run with a's directions (dirs, azimuth0, convention, exact, degrees);
 * 0, or an error printed. */
static int cli_horizon_labels(const cli_args *a, cli_labels *L)
{
    const int K = a->dirs;
    int k;
    memset(L, 0, sizeof *L);
    L->unit = a->degrees ? "degree" : "radian";
    L->names = (char (*)[64])malloc((size_t)K * sizeof *L->names);
    L->values = (char (*)[32])malloc((size_t)K * sizeof *L->values);
    L->band = (const char **)malloc((size_t)K * sizeof *L->band);
    L->meta = (ex_rio_meta *)malloc(((size_t)K + 3) * sizeof *L->meta);
    if (a->exact) L->used = (double *)malloc((size_t)K * sizeof *L->used);
    if (!L->names || !L->values || !L->band || !L->meta || (a->exact && !L->used)) {
        cli_labels_free(L);
        return cli_status("horizon", HFVIS_ERR_OUT_OF_MEMORY, 0);
    }
    if (L->used) {
        hfvis_sweep_options o = hfvis_sweep_options_default();
        o.rays = HFVIS_RAYS_EXACT;
        o.azimuth0_rad = a->compass ? a->azimuth0 - CLI_PI / 2.0 : a->azimuth0;
        if (hfvis_sweep_azimuths(K, &o, L->used, NULL) != HFVIS_OK) {
            cli_labels_free(L);
            return cli_error(CLI_EXIT_ERROR, "horizon", "internal error: the exact azimuths");
        }
    }
    L->meta[0].name = "CONVENTION", L->meta[0].value = cli_conv_names[a->convention], L->meta[0].band = 0;
    L->meta[1].name = "UNIT", L->meta[1].value = L->unit, L->meta[1].band = 0;
    L->meta[2].name = "RAYS", L->meta[2].value = a->exact ? "exact" : "lattice", L->meta[2].band = 0;
    for (k = 0; k < K; k++) {
        const double deg = cli_plane_azimuth(a, L->used, k);
        snprintf(L->names[k], sizeof L->names[k], "azimuth %.3f deg %s", deg, cli_conv_names[a->convention]);
        snprintf(L->values[k], sizeof L->values[k], "%.6f", deg);
        L->band[k] = L->names[k];
        L->meta[3 + k].name = "AZIMUTH", L->meta[3 + k].value = L->values[k], L->meta[3 + k].band = k + 1;
    }
    return 0;
}

/* A horizon map's labels rebuilt from the tag of its run (a piece's sidecar for mosaic, a partial
 * result for sum): its dirs (which must be planes), azimuth0 (the library's psi_0), convention,
 * degrees and rays. Returns 0 with L zeroed (no labels: a tag of an older hfvis) when a key is
 * missing or names another count, 0 with L filled, or an error (reported). */
static int cli_horizon_labels_of_tag(const char *tag, int planes, cli_labels *L)
{
    cli_args a;
    double az0 = 0.0, deg = 0.0, conv = 0.0, dirs = 0.0;
    char rays[16] = "";
    memset(&a, 0, sizeof a);
    memset(L, 0, sizeof *L);
    if (!cli_tag_real(tag, "dirs", &dirs) || !cli_tag_real(tag, "azimuth0", &az0) ||
        !cli_tag_real(tag, "convention", &conv) || !cli_tag_real(tag, "degrees", &deg) ||
        !cli_tag_value(tag, "rays", rays, sizeof rays) || dirs != (double)planes || !(conv >= 0.0 && conv <= 2.0))
        return 0;
    a.cmd = CMD_HORIZON;
    a.dirs = planes;
    a.azimuth0 = az0; /* psi_0 itself: a.compass is 0 */
    a.convention = (int)conv;
    a.degrees = deg != 0.0;
    a.exact = !strcmp(rays, "exact");
    return cli_horizon_labels(&a, L);
}

/* horizon, after the sweep: the planes in the user's convention's order (GRASS's run
 * counter-clockwise) and, with --split, one file per direction named OUT's stem + "_" + the
 * direction's azimuth in degrees in the convention (as r.horizon names its maps: "_045", or
 * "_022_500" for 22.5; exact rays: the azimuth actually used, e.g. "_014_036"), else the stacked
 * map; a GeoTIFF carries the labels (cli_horizon_labels). */
static int cli_horizon_finish(const cli_args *a, float *map, int w, int h, double lo, double hi)
{
    const size_t n = (size_t)w * (size_t)h;
    const int K = a->dirs;
    cli_labels L;
    cli_output out;
    int k, rc = 0;
    if (a->convention == CONV_GRASS && K > 2) { /* plane k <- library plane (K - k) % K, in place */
        float *tmp = cli_alloc(n, 1, 1);
        if (!tmp) return cli_status("horizon", HFVIS_ERR_OUT_OF_MEMORY, 0);
        for (k = 1; k < K - k; k++) {
            memcpy(tmp, map + (size_t)k * n, n * sizeof(float));
            memcpy(map + (size_t)k * n, map + (size_t)(K - k) * n, n * sizeof(float));
            memcpy(map + (size_t)(K - k) * n, tmp, n * sizeof(float));
        }
        free(tmp);
    }
    if ((rc = cli_horizon_labels(a, &L)) != 0) return rc;
    if (!a->split) {
        out = cli_output_of(map, w, h, K, 1, lo, hi);
        out.band_names = L.band, out.unit = L.unit, out.meta = L.meta, out.n_meta = K + 3;
        rc = cli_save(a, out);
        cli_labels_free(&L);
        return rc;
    }
    for (k = 0; k < K && rc == 0; k++) {
        cli_args one = *a;
        char name[4096];
        const char *dot = strrchr(a->out, '.');
        double deg = cli_plane_azimuth(a, L.used, k);
        long whole = (long)floor(deg), milli = (long)floor((deg - (double)whole) * 1000.0 + 0.5);
        size_t stem = dot ? (size_t)(dot - a->out) : strlen(a->out);
        ex_rio_meta m[4]; /* the dataset's items and this direction's AZIMUTH, on band 1 */
        int len;
        if (milli == 1000) whole++, milli = 0;
        if (milli == 0)
            len = snprintf(name, sizeof name, "%.*s_%03ld%s", (int)stem, a->out, whole, a->out + stem);
        else
            len = snprintf(name, sizeof name, "%.*s_%03ld_%03ld%s", (int)stem, a->out, whole, milli,
                           a->out + stem);
        if (len < 0 || (size_t)len >= sizeof name) {
            rc = cli_error(CLI_EXIT_ERROR, a->out, "name too long");
            break;
        }
        if ((rc = cli_refuse_inputs(a, name)) != 0) break;
        one.out = name;
        memcpy(m, L.meta, 3 * sizeof *m);
        m[3] = L.meta[3 + k];
        m[3].band = 1;
        out = cli_output_of(map + (size_t)k * n, w, h, 1, 1, lo, hi);
        out.band_names = L.band + k, out.unit = L.unit, out.meta = m, out.n_meta = 4;
        rc = cli_save(&one, out);
    }
    cli_labels_free(&L);
    return rc;
}

/* shadow: the sun's position is required. */
static int cli_check_shadow(const cli_args *a)
{
    if (!a->has_sun_azimuth) return cli_error(CLI_EXIT_USAGE, "shadow", "missing --sun-azimuth DEG");
    if (!a->has_sun_elevation) return cli_error(CLI_EXIT_USAGE, "shadow", "missing --sun-elevation DEG");
    return 0;
}

/* light: the environment map is required. */
static int cli_check_light(const cli_args *a)
{
    return a->env ? 0 : cli_error(CLI_EXIT_USAGE, "light", "missing --env ENV.pfm");
}
