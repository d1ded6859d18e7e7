/* gis_products.c - the GIS products: `viewshed` (observer, targets, curvature), `hillshade`,
 * `openness` and SAGA's sky-view factor, dispatched by cli_run_gis.
 * May call: progress.c, gis.c, write.c. */


/* viewshed: the observer (map coordinates, or --observer-grid) on a sample that is not NoData,
 * optional Earth curvature and refraction as in GRASS r.viewshed (each target's height lowered by
 * (1 - k) d^2 / (2 R), d its horizontal distance from the observer), R2 or the exact oracle, and
 * the verdict at each --target on stdout. */
static int cli_run_viewshed(const cli_args *a, const hfvis_grid *grid, float *out)
{
    const int w = grid->width, h = grid->height;
    const size_t n = (size_t)w * (size_t)h;
    hfvis_viewshed_options vo;
    hfvis_grid g = *grid;
    float *zc = NULL;
    double ox = a->observer_x, oy = a->observer_y;
    hfvis_status s;
    int rc = 0, t;
    memset(&vo, 0, sizeof vo);
    vo.observer_height = a->observer_height;
    vo.target_height = a->target_height;
    vo.max_distance = a->max_distance;
    if (!a->observer_grid && !cli_map_to_grid(a, grid->cell_size, a->observer_x, a->observer_y, &ox, &oy))
        return cli_error(CLI_EXIT_ERROR, "--observer", "the georeference cannot be inverted");
    if (!(ox >= 0.0 && ox <= w - 1 && oy >= 0.0 && oy <= h - 1))
        return cli_error(CLI_EXIT_ERROR, a->observer_grid ? "--observer-grid" : "--observer",
                         "%g,%g (column %g, row %g) is outside the grid [0, %d] x [0, %d]",
                         a->observer_x, a->observer_y, ox, oy, w - 1, h - 1);
    if (isnan(hfvis_grid_sample(grid, ox, oy)))
        return cli_error(CLI_EXIT_ERROR, a->observer_grid ? "--observer-grid" : "--observer",
                         "%g,%g (column %g, row %g) is on NoData: the observer needs ground",
                         a->observer_x, a->observer_y, ox, oy);
    if (a->curvature) { /* GRASS r.viewshed -c -r: z - (1 - k) d^2/(2R), d in metres */
        const double c = (1.0 - a->refraction) / (2.0 * a->earth_radius);
        size_t i;
        zc = cli_alloc(n, 1, 1);
        if (!zc) return cli_status("viewshed", HFVIS_ERR_OUT_OF_MEMORY, 0);
        for (i = 0; i < n; i++) {
            double dx = ((double)(i % (size_t)w) - ox) * grid->cell_size;
            double dy = ((double)(i / (size_t)w) - oy) * grid->cell_size;
            zc[i] = (float)((double)grid->z[i] - c * (dx * dx + dy * dy));
        }
        g.z = zc;
        g.stride = w;
    }
    if (a->exact) s = hfvis_viewshed_reference(&g, ox, oy, &vo, 0.0, out, w);
    else s = hfvis_viewshed(&g, ox, oy, &vo, out, w);
    free(zc);
    if (s != HFVIS_OK) return cli_status("viewshed", s, 0);
    for (t = 0; t < a->ntargets; t++) { /* the verdict of the sample nearest to each target */
        double X = a->targets[2 * t], Y = a->targets[2 * t + 1], x, y;
        const char *verdict;
        long c, r;
        const int mapped = cli_map_to_grid(a, grid->cell_size, X, Y, &x, &y);
        if (!mapped || !(x > -0.5 && x < w - 0.5 && y > -0.5 && y < h - 0.5)) {
            /* where the target is, as given: not a sample's indices, which it has none of */
            if (mapped) printf("target %.10g,%.10g (column %.10g, row %.10g): outside the grid\n", X, Y, x, y);
            else printf("target %.10g,%.10g: outside the grid\n", X, Y);
            continue;
        } else {
            float v;
            c = (long)floor(x + 0.5), r = (long)floor(y + 0.5);
            v = out[(size_t)r * (size_t)w + (size_t)c];
            verdict = v == 1.0f ? "visible" : v == 0.0f ? "hidden" :
                      isnan(grid->z[(size_t)r * (size_t)grid->stride + (size_t)c]) ? "no data"
                      : "beyond --max-distance";
        }
        printf("target %.10g,%.10g (column %ld, row %ld): %s\n", X, Y, c, r, verdict);
    }
    if (a->ntargets > 0 && fflush(stdout) != 0) rc = cli_error(CLI_EXIT_ERROR, "stdout", "%s", strerror(errno));
    return rc;
}

/* hillshade: H = (1/N) sum_j max(n . l_j, 0) V_j over N suns spread evenly in azimuth from
 * --sun-azimuth (N = --blend), n the grid normal, l_j the direction of sun j's centre and V_j its
 * visibility from exact rays (hfvis_sun_visibility: 0/1, or the visible fraction of a disc of
 * --sun-radius; --lattice: the lattice sweep), V_j = 1 with --no-shadows. In [0, 1]; NaN at
 * holes. A GIS product: the shadows are those of `shadow --exact`, cell for cell. */
static int cli_run_hillshade(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts,
                             cli_progress_state *prog, float *out)
{
    const int w = grid->width, N = a->blend;
    const size_t n = (size_t)w * (size_t)grid->height;
    const double el = a->sun_elevation * (CLI_PI / 180.0), psi0 = a->sun_azimuth * (CLI_PI / 180.0);
    float *nrm = cli_alloc(n, 3, 1), *vis = cli_alloc(n, 1, 1);
    double *acc = (double *)calloc(n, sizeof(double));
    hfvis_status s = HFVIS_OK;
    size_t i;
    int j, rc = 0;
    if (!nrm || !vis || !acc) { rc = cli_status("hillshade", HFVIS_ERR_OUT_OF_MEMORY, 0); goto done; }
    s = hfvis_normals_compute(grid, nrm);
    prog->total = N;
    for (j = 0; s == HFVIS_OK && j < N; j++) {
        const double psi = psi0 + 2.0 * CLI_PI * j / N;
        const double l[3] = { cos(el) * cos(psi), cos(el) * sin(psi), sin(el) };
        if (a->no_shadows) {
            for (i = 0; i < n; i++) vis[i] = 1.0f;
            if (opts->progress) opts->progress(opts->progress_user, 1, 1);
        } else {
            s = cli_threaded_sun(grid, psi, el, a->sun_radius * (CLI_PI / 180.0), opts, cli_run_threads(a), vis, w);
        }
        for (i = 0; s == HFVIS_OK && i < n; i++) {
            double d = (double)nrm[3 * i] * l[0] + (double)nrm[3 * i + 1] * l[1] + (double)nrm[3 * i + 2] * l[2];
            acc[i] += (d > 0.0 ? d : 0.0) * (double)vis[i];
        }
    }
    if (s != HFVIS_OK) { rc = cli_status("hillshade", s, 0); goto done; }
    for (i = 0; i < n; i++) out[i] = isfinite(grid->z[(i / (size_t)w) * (size_t)grid->stride + i % (size_t)w])
                                     ? (float)(acc[i] / N) : (float)NAN;
done:
    free(acc);
    free(vis);
    free(nrm);
    return rc;
}

/* openness: hfvis_openness (Yokoyama et al. 2002), in radians or, with --degrees, degrees. */
static int cli_run_openness(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts,
                            cli_progress_state *prog, float *out)
{
    hfvis_openness_options oo;
    hfvis_status s;
    size_t i, n = (size_t)grid->width * (size_t)grid->height;
    memset(&oo, 0, sizeof oo);
    oo.radius = a->radius;
    oo.negative = a->negative;
    prog->total = a->radius > 0.0 ? grid->height : a->dirs * (a->negative == 2 ? 2 : 1);
    s = cli_threaded_openness(grid, a->dirs, &oo, opts, cli_run_threads(a), out);
    if (s != HFVIS_OK) return cli_status("openness", s, 0);
    if (a->negative == 2) n *= 2; /* --both: positive, then negative */
    if (a->degrees)
        for (i = 0; i < n; i++) out[i] = (float)((double)out[i] * (180.0 / CLI_PI));
    return 0;
}

/* skyview --svf saga|visible, SAGA's "Sky View Factor" tool (ta_lighting, after Hantzschel et al.
 * 2005), from the K horizon angles phi_k = max(alpha_k, 0) (SAGA never lets a horizon fall below
 * the horizontal) and the grid normal (n_x, n_y, n_z):
 *   saga:    (1/K) sum_k [n_z cos^2 phi_k + (n_x cos psi_k + n_y sin psi_k)(pi/2 - phi_k - sin phi_k cos phi_k)]
 *            (n_z = cos slope, n_x cos psi + n_y sin psi = sin slope cos(psi - aspect)): the
 *            cosine-weighted sky, 1 - (1/K) sum sin^2 phi_k on level ground;
 *   visible: (1/K) sum_k (1 - phi_k/(pi/2)), SAGA's "Visible Sky" as a fraction (SAGA: percent). */
static int cli_run_skyview_saga(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts,
                                cli_progress_state *prog, float *out)
{
    const int w = grid->width, K = a->dirs;
    const size_t n = (size_t)w * (size_t)grid->height;
    float *nrm = a->svf == 1 ? cli_alloc(n, 3, 1) : NULL, *plane = cli_alloc(n, 1, 1);
    double *acc = (double *)calloc(n, sizeof(double));
    hfvis_status s = HFVIS_OK;
    size_t i;
    int k, rc = 0;
    if ((a->svf == 1 && !nrm) || !plane || !acc) { rc = cli_status("skyview", HFVIS_ERR_OUT_OF_MEMORY, 0); goto done; }
    if (nrm) s = hfvis_normals_compute(grid, nrm);
    prog->total = K;
    for (k = 0; s == HFVIS_OK && k < K; k++) {
        const double psi = opts->azimuth0_rad + 2.0 * CLI_PI * k / K, c = cos(psi), sn = sin(psi);
        s = hfvis_horizon_direction(grid, K, k, opts, plane, w);
        for (i = 0; s == HFVIS_OK && i < n; i++) {
            double phi = (double)plane[i] > 0.0 ? (double)plane[i] : 0.0;
            if (isnan(plane[i])) { acc[i] = (double)NAN; continue; }
            if (nrm)
                acc[i] += (double)nrm[3 * i + 2] * cos(phi) * cos(phi) +
                          ((double)nrm[3 * i] * c + (double)nrm[3 * i + 1] * sn) *
                              (CLI_PI / 2.0 - phi - sin(phi) * cos(phi));
            else
                acc[i] += 1.0 - phi / (CLI_PI / 2.0);
        }
    }
    if (s != HFVIS_OK) { rc = cli_status("skyview", s, 0); goto done; }
    for (i = 0; i < n; i++) out[i] = (float)(acc[i] / K);
done:
    free(acc);
    free(plane);
    free(nrm);
    return rc;
}

/* The commands of this section: compute into out (W x H) and save it. */
static int cli_run_gis(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts,
                       cli_progress_state *prog)
{
    const int w = grid->width, h = grid->height;
    const int planes = a->cmd == CMD_OPENNESS && a->negative == 2 ? 2 : 1; /* openness --both */
    float *out = cli_alloc((size_t)w, (size_t)h, (size_t)planes);
    double lo = 0.0, hi = 1.0;
    int rc;
    if (!out) return cli_status(cli_commands[a->cmd].name, HFVIS_ERR_OUT_OF_MEMORY, 0);
    if (a->cmd == CMD_VIEWSHED) {
        rc = cli_run_viewshed(a, grid, out);
    } else if (a->cmd == CMD_HILLSHADE) {
        a->run->directions = a->blend;
        rc = cli_run_hillshade(a, grid, opts, prog, out);
    } else if (a->cmd == CMD_OPENNESS) {
        hi = a->degrees ? 180.0 : CLI_PI; /* 0 .. 180 degrees */
        rc = cli_run_openness(a, grid, opts, prog, out);
    } else if (a->cmd == CMD_SKYVIEW) {
        rc = cli_run_skyview_saga(a, grid, opts, prog, out);
    } else {
        rc = cli_error(CLI_EXIT_ERROR, cli_commands[a->cmd].name, "internal error: not a GIS product");
    }
    if (rc == 0) {
        cli_output o = cli_output_of(out, w, h, planes, 1, lo, hi);
        o.band_names = cli_fixed_band_names(a->cmd, planes);
        rc = cli_save(a, o);
    }
    free(out);
    return rc;
}

/* hillshade --no-shadows: the flags that only shape the cast shadows are refused, not ignored
 * (--max-distance too, unless a --window run needs it for its halo). */
static int cli_check_hillshade(const cli_args *a)
{
    const char *f = a->lattice ? "--lattice" : a->has_sun_radius ? "--sun-radius"
                    : a->max_distance > 0.0 && !a->has_window ? "--max-distance"
                    : a->has_exact_near ? "--exact-near" : NULL;
    if (a->no_shadows && f)
        return cli_error(CLI_EXIT_USAGE, f, "shapes the cast shadows, and --no-shadows casts none");
    return 0;
}

/* viewshed: the observer is required. */
static int cli_check_viewshed(const cli_args *a)
{
    return a->has_observer ? 0 : cli_error(CLI_EXIT_USAGE, "viewshed", "missing --observer X,Y");
}
