/* p2.c - the [P2] hull-tree commands: `indirect` (direct light, then interreflections) and
 * `visibility` (the visibility index). May call: progress.c, sweeps.c's maps, write.c. */

/* Combinations `indirect` rejects; returns 0 or CLI_EXIT_USAGE (message printed). */
static int cli_check_indirect(const cli_args *a)
{
    if (a->has_albedo && a->albedo_map)
        return cli_error(CLI_EXIT_USAGE, "--albedo-map", "cannot be combined with --albedo");
    return cli_check_light_flags(a);
}

/* indirect: direct light (hfvis_direct_light), then hfvis_terrain_gi. */
static int cli_run_indirect(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts,
                            cli_progress_state *prog)
{
    const char *cmd = "indirect";
    const int w = grid->width, h = grid->height, K = a->dirs;
    const size_t n = (size_t)w * (size_t)h;
    const int has_sun = a->has_sun_azimuth;
    const int bounces = a->output == OUT_DIRECT ? 0 : a->bounces;
    float *env_px = NULL, *albedo = NULL, *emit = NULL, *direct = NULL, *out = NULL, *base = NULL;
    int env_ch = 1, albedo_ch = 1, emit_ch = 1, channels, direct_ch, rc = 0, c;
    hfvis_env env;
    hfvis_sun sun;
    hfvis_status s;
    size_t i;

    memset(&env, 0, sizeof env);
    memset(&sun, 0, sizeof sun);
    if (a->env) {
        if ((rc = cli_load_env(a->env, &env_px, &env)) != 0) goto done;
        env_ch = env.channels;
    }
    if (a->albedo_map && (rc = cli_load_map(a->albedo_map, &a->run->win, grid, &albedo, &albedo_ch)) != 0) goto done;
    if (a->emission && (rc = cli_load_map(a->emission, &a->run->win, grid, &emit, &emit_ch)) != 0) goto done;
    /* Output channels: the most of any input; one-channel inputs apply to every channel. */
    channels = env_ch > albedo_ch ? env_ch : albedo_ch;
    if (emit_ch > channels) channels = emit_ch;
    {
        const char *names[3] = { a->env, a->albedo_map, a->emission };
        const int counts[3] = { env_ch, albedo_ch, emit_ch };
        for (c = 0; c < 3; c++)
            if (names[c] && counts[c] != 1 && counts[c] != channels) {
                rc = cli_error(CLI_EXIT_ERROR, names[c], "%d channels, but another input has %d "
                               "(inputs need 1 channel or the same count)", counts[c], channels);
                goto done;
            }
    }
    if (albedo && albedo_ch < channels && (rc = cli_widen(&albedo, n, channels)) != 0) goto done;
    if (emit && emit_ch < channels && (rc = cli_widen(&emit, n, channels)) != 0) goto done;
    direct = cli_alloc(n, (size_t)channels, 1);
    out = cli_alloc(n, (size_t)channels, 1);
    if (a->output == OUT_INDIRECT) base = cli_alloc(n, (size_t)channels, 1);
    if (!direct || !out || (a->output == OUT_INDIRECT && !base)) {
        rc = cli_status(cmd, HFVIS_ERR_OUT_OF_MEMORY, 0);
        goto done;
    }
    if (has_sun) {
        double psi_deg = a->math ? a->sun_azimuth : a->sun_azimuth - 90.0;
        sun.azimuth_rad = psi_deg * (CLI_PI / 180.0);
        sun.elevation_rad = a->sun_elevation * (CLI_PI / 180.0);
        sun.radius_rad = a->sun_radius * (CLI_PI / 180.0);
        for (c = 0; c < 4; c++) sun.irradiance[c] = (float)a->sun_irradiance;
    }
    /* one bar: the sky or environment sweep (K), the sun sweep (1), K per bounce */
    prog->total = (long long)K * (1 + bounces) + (has_sun ? 1 : 0);

    /* D: the sky part has the environment's channels (1 for the uniform sky) */
    direct_ch = a->env ? env_ch : 1;
    s = hfvis_direct_light(grid, K, has_sun ? &sun : NULL, (float)a->sky, a->env ? &env : NULL,
                           direct_ch, opts, direct);
    if (s != HFVIS_OK) { rc = cli_status(cmd, s, 0); goto done; }
    if (direct_ch < channels) /* spread the one channel, back to front (in place) */
        for (i = n; i-- > 0;)
            for (c = channels - 1; c >= 0; c--) direct[i * (size_t)channels + (size_t)c] = direct[i];

    s = hfvis_terrain_gi(grid, K, direct, emit, albedo, (float)a->albedo, channels, bounces, opts,
                         NULL, out);
    if (s == HFVIS_OK && a->output == OUT_INDIRECT) { /* L_B - L_0 */
        s = hfvis_terrain_gi(grid, K, direct, emit, albedo, (float)a->albedo, channels, 0, opts,
                             NULL, base);
        for (i = 0; s == HFVIS_OK && i < n * (size_t)channels; i++)
            out[i] = (float)((double)out[i] - (double)base[i]);
    }
    if (s != HFVIS_OK) { rc = cli_status(cmd, s, 0); goto done; }
    if ((rc = cli_check_radiance(cmd, grid, out, channels)) != 0) goto done;
    rc = cli_save(a, cli_output_of(out, w, h, 1, channels, 0.0, cli_top(out, n * (size_t)channels, 1.0)));
done:
    free(base);
    free(out);
    free(direct);
    hfvis_free(NULL, emit);
    hfvis_free(NULL, albedo);
    hfvis_free(NULL, env_px);
    return rc;
}


/* visibility: hfvis_visibility_count; --fraction divides by the count on a flat field with the
 * same holes (where every sample is visible); --stats prints the counters before OUT is written
 * (a print that fails leaves OUT untouched). */
static int cli_run_visibility(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts,
                              cli_progress_state *prog)
{
    const char *cmd = "visibility";
    const int w = grid->width, h = grid->height, K = a->dirs;
    const size_t n = (size_t)w * (size_t)h;
    float *out = cli_alloc(n, 1, 1), *flat_z = NULL, *tested = NULL;
    hfvis_visibility_stats st, flat_st;
    hfvis_status s;
    size_t i;
    int rc;

    memset(&flat_st, 0, sizeof flat_st);
    if (!out) return cli_status(cmd, HFVIS_ERR_OUT_OF_MEMORY, 0);
    prog->total = (long long)K * (a->fraction ? 2 : 1);
    s = hfvis_visibility_count(grid, K, opts, NULL, out, w, &st);
    if (s == HFVIS_OK && a->fraction) {
        hfvis_grid flat = *grid;
        flat_z = cli_alloc(n, 1, 1);
        tested = cli_alloc(n, 1, 1);
        if (!flat_z || !tested) s = HFVIS_ERR_OUT_OF_MEMORY;
        else {
            for (i = 0; i < n; i++) flat_z[i] = isfinite(grid->z[i]) ? 0.0f : (float)NAN;
            flat.z = flat_z;
            s = hfvis_visibility_count(&flat, K, opts, NULL, tested, w, &flat_st);
        }
        for (i = 0; s == HFVIS_OK && i < n; i++)
            if (!isnan(out[i])) out[i] = tested[i] > 0.0f ? (float)((double)out[i] / (double)tested[i]) : 0.0f;
    }
    rc = s != HFVIS_OK ? cli_status(cmd, s, 0) : 0;
    if (rc == 0 && a->stats) { /* before OUT: a failed print must not follow a replaced OUT */
        double r = st.receivers > 0.0 ? st.receivers : 1.0; /* 0 receivers: print zeros */
        printf("receiver-directions: %.0f\n", st.receivers);
        printf("visible per receiver-direction: %.6g\n", st.visible / r);
        printf("horizons per receiver-direction (m_a): %.6g\n", st.horizons / r);
        printf("iterations per receiver-direction (t_a): %.6g\n", st.iterations / r);
        if (a->fraction) {
            double t = flat_st.visible > 0.0 ? flat_st.visible : 1.0;
            printf("tested per receiver-direction: %.6g\n", flat_st.visible / r);
            printf("visible/tested: %.6g\n", st.visible / t);
            printf("t_a/tested: %.6g\n", st.iterations / t);
        }
        if (fflush(stdout) != 0 || ferror(stdout))
            rc = cli_error(CLI_EXIT_ERROR, "stdout", "%s (OUT not written)", strerror(errno));
    }
    if (rc == 0) rc = cli_save(a, cli_output_of(out, w, h, 1, 1, 0.0, a->fraction ? 1.0 : cli_top(out, n, 1.0)));
    free(tested);
    free(flat_z);
    free(out);
    return rc;
}
