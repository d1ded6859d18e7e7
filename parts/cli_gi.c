/* cli_gi.c - the `gi` subcommand of examples/hfvis_cli.c (Nowrouzezahrai-Snyder GI, hfvis_ns_gi).
 *
 * MERGE RECIPE (hfvis_cli.c; tested by applying it to a copy and running the commands at the end):
 *  1. enum: add CMD_GI before CMD_COUNT; cli_cmd_names: add "gi" at the end.
 *  2. cli_usage, after the "indirect" line:
 *       "  gi          multi-resolution GI (Nowrouzezahrai & Snyder): sky, sun, bounces, gloss\n"
 *  3. cli_cmd_help: append CLI_GI_HELP (below) as the last entry.
 *  4. cli_args: add   int order, subsample, has_dirs, has_specular, has_shininess;
 *                     double specular, shininess;
 *  5. flags: CLI_SUN gains CLI_ONLY(CMD_GI); "--sky", "--albedo", "--env", "--sun-irradiance",
 *     "--bounces" and "--output" gain | CLI_ONLY(CMD_GI); add the four entries of CLI_GI_FLAGS.
 *  6. cli_set: in the "--dirs" branch set a->has_dirs = 1 before parsing; add, before the final
 *     "--method" fallback:   { int r = cli_set_gi(a, f, v); if (r >= 0) return r; }
 *  7. cli_parse: after the defaults line add   a->order = 4; a->subsample = 1;
 *     and before "return CLI_RUN;" add   if (a->cmd == CMD_GI && cli_check_gi(a)) return CLI_EXIT_USAGE;
 *  8. cli_run: beside the indirect hook add
 *       if (a->cmd == CMD_GI) { rc = cmd_gi(a, &grid, &opts, &prog); goto done; }
 *  9. Paste PART A (the two macros) after the cli_args typedef, PART B (cli_set_gi, cli_check_gi)
 *     after cli_ends_with, PART C (cmd_gi) after cli_run_indirect.
 *  Then e.g.:  hfvis gi dem.pgm --bounces 3 --sun-azimuth 250 --sun-elevation 12 --sky 0.3 -o gi.pgm
 */

/* ---- PART A: after the cli_args typedef ---------------------------------------------------- */

#define CLI_GI_HELP                                                                                  \
    "usage: hfvis gi IN -o OUT [--dirs K] [--order O] [--subsample S] [--bounces B] [--albedo A]\n"  \
    "         [--specular S --shininess N] [--sun-azimuth DEG --sun-elevation DEG [--sun-radius DEG]\n" \
    "         [--sun-irradiance E]] [--sky C | --env ENV.pfm] [--output total|direct|indirect]\n"    \
    "Direct light and interreflections with the multi-resolution method of Nowrouzezahrai &\n"     \
    "Snyder 2009: per receiver, K azimuthal slices are scanned over a height pyramid with steps\n"  \
    "growing by 2^(1/4); each slice's visibility and indirect light become Legendre vectors and\n"  \
    "order-O spherical harmonics, shaded with the pixel's own normal. An approximation of\n"        \
    "'indirect' (soft: order-4 SH), faster with --subsample 2 or 4. Lambertian radiance: an open\n" \
    "flat receiver under a sky C with albedo A returns A*C. Default: sky 1, albedo 1, one bounce.\n" \
    "  --dirs K              azimuthal slices, 1..4096 (default 32, the paper's)\n"                  \
    "  --order O             SH order 1..4 (default 4)\n"                                             \
    "  --subsample S         visibility and bounces per S x S block, 1..64 (default 1; 2 is the\n"   \
    "                        paper's recommended trade-off)\n"                                        \
    "  --bounces B           interreflection bounces, 0..1000 (default 1)\n"                          \
    "  --albedo A            diffuse albedo, >= 0 (default 1)\n"                                      \
    "  --specular S          Phong specular weight, >= 0 (default 0), seen from straight above\n"     \
    "  --shininess N         Phong exponent, > 0 (default 32; with --specular)\n"                     \
    "  --sun-azimuth DEG     compass bearing of the sun, degrees clockwise from north\n"              \
    "  --math                --sun-azimuth is psi instead: degrees from east toward south\n"          \
    "  --sun-elevation DEG   sun elevation above the horizontal, -90..90 (with --sun-azimuth)\n"      \
    "  --sun-radius DEG      0 (default): a directional sun, hard shadows; 0..90: a key light\n"      \
    "                        (a disc with soft SH shadows from its own restricted visibility)\n"      \
    "  --sun-irradiance E    irradiance on a surface facing the sun, >= 0 (default pi)\n"             \
    "  --sky C               uniform sky radiance, >= 0 (default 1; 0 for the sun alone)\n"           \
    "  --env ENV.pfm         lat-long environment instead of the uniform sky (see 'light')\n"         \
    "  --output WHAT         total: direct + all bounces (default); direct: no bounce (--bounces\n"   \
    "                        not allowed); indirect: the bounces only (needs B >= 1)\n"               \
    "--azimuth0 and --compass place the slices, --border applies to the slices and the pyramid.\n"  \
    "OUT has the environment's channels (1 for --sky). NaN at holes. Default PGM range 0:the\n"     \
    "largest output value.\n"

#define CLI_GI_FLAGS                                                                         \
    { "--order", 1, CLI_ONLY(CMD_GI) }, { "--subsample", 1, CLI_ONLY(CMD_GI) },              \
    { "--specular", 1, CLI_ONLY(CMD_GI) }, { "--shininess", 1, CLI_ONLY(CMD_GI) }

/* ---- PART B: after cli_ends_with ------------------------------------------------------------ */

/* The flags only `gi` has; -1 if f is none of them. */
static int cli_set_gi(cli_args *a, const char *f, const char *v)
{
    if (!strcmp(f, "--order")) return cli_int(f, v, 1, 4, "an integer 1..4", &a->order);
    if (!strcmp(f, "--subsample"))
        return cli_int(f, v, 1, HFVIS_NS_MAX_SUBSAMPLE, "an integer 1..64", &a->subsample);
    if (!strcmp(f, "--specular")) {
        a->has_specular = 1;
        return cli_real(f, v, 0.0, 0, CLI_FLT_MAX, "a weight >= 0", &a->specular);
    }
    if (!strcmp(f, "--shininess")) {
        a->has_shininess = 1;
        return cli_real(f, v, 0.0, 1, CLI_FLT_MAX, "an exponent > 0", &a->shininess);
    }
    return -1;
}

/* Combinations `gi` rejects; returns 0 or CLI_EXIT_USAGE (message printed). */
static int cli_check_gi(const cli_args *a)
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
    if (a->has_shininess && !a->has_specular)
        return cli_error(CLI_EXIT_USAGE, "--shininess", "needs --specular S");
    if (a->has_sky && a->env)
        return cli_error(CLI_EXIT_USAGE, "--env", "cannot be combined with --sky");
    if (a->output == OUT_DIRECT && a->has_bounces)
        return cli_error(CLI_EXIT_USAGE, "--bounces", "has no effect with --output direct");
    if (a->output == OUT_INDIRECT && a->bounces < 1)
        return cli_error(CLI_EXIT_USAGE, "--output indirect", "needs --bounces >= 1");
    return 0;
}

/* ---- PART C: after cli_run_indirect --------------------------------------------------------- */

/* gi: hfvis_ns_gi with a uniform sky or a projected environment, and an optional sun. */
static int cmd_gi(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts,
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
    scene.shininess = (float)(a->has_shininess ? a->shininess : 32.0);
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
    rc = cli_save(a, out, w, h, channels, 0.0, cli_top(out, n * (size_t)channels, 1.0));
done:
    free(out);
    free(bounce);
    free(direct);
    hfvis_free(NULL, env_px);
    return rc;
}
