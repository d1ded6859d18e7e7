/* cli_ssaob.c - the `ssao` subcommand of examples/hfvis_cli.c (issue 5). Merge instructions:
 *
 * 1. enum: add CMD_SSAO before CMD_COUNT; cli_cmd_names: add "ssao".
 * 2. cli_args: add the fields
 *        int ssao_method, ssao_depth, ssao_has_ortho, ssao_has_near, ssao_has_far, ssao_guard;
 *        double ssao_fov, ssao_ortho, ssao_radius, ssao_near, ssao_far;
 *    (defaults set in parse_args: ssao_method = SSAO_FFAO, ssao_depth = SSAO_DEPTH_LINEAR,
 *    ssao_fov = 60, ssao_guard = -1 (= 10 % of each side), dirs stays 0 = each method's default)
 * 3. cli_flags: add (CLI_ONLY(CMD_SSAO)); --method and --dirs gain CLI_ONLY(CMD_SSAO):
 *        { "--fov-y", 1, .. }, { "--ortho", 1, .. }, { "--radius", 1, .. }, { "--guard", 1, .. },
 *        { "--depth", 1, .. }, { "--near", 1, .. }, { "--far", 1, .. }
 * 4. cli_set: call cli_set_ssao(a, f, v) first for CMD_SSAO (returns -1 when not its flag).
 * 5. main dispatch: if (a->cmd == CMD_SSAO) return cli_run_ssao(a);   (before the grid load,
 *    like voxelize: IN is a depth buffer, not a height field)
 * 6. help text: cli_cmd_help[CMD_SSAO] = cli_ssao_help; usage line:
 *        "  hfvis ssao DEPTH.pfm --method lsao|hbao|ffao|raytrace --fov-y DEG -o OUT.pgm|.pfm\n"
 */

enum { SSAO_LSAO, SSAO_HBAO, SSAO_FFAO, SSAO_RAYTRACE };
enum { SSAO_DEPTH_LINEAR, SSAO_DEPTH_GL, SSAO_DEPTH_D3D, SSAO_DEPTH_REVERSED };

static const char cli_ssao_help[] =
    "hfvis ssao DEPTH.pfm [--method lsao|hbao|ffao|raytrace] [--fov-y DEG] [--ortho SCALE]\n"
    "           [--radius R] [--dirs K] [--guard PIXELS] [--depth linear|gl|d3d|reversed]\n"
    "           [--near N --far F] -o OUT.pgm|.pfm\n"
    "  Screen-space ambient obscurance of a depth buffer (a one-channel PFM, row 0 at the top as\n"
    "  the library reads it). The output is obscurance in [0, 1] (0 = open) for the inner pixels\n"
    "  (the buffer minus the guard band on every side).\n"
    "  --method   lsao: P3 line sweep; hbao: horizon-based ray march; ffao: P4 far-field AO\n"
    "             (default); raytrace: the screen-space ray-traced reference (256 rays, slow)\n"
    "  --fov-y    vertical field of view of the inner image in degrees (default 60)\n"
    "  --ortho    orthographic camera instead, SCALE view units per pixel\n"
    "  --radius   falloff rho = r/(r + d^2) with r = R^2 (view units); default: none (rho = 1)\n"
    "  --dirs     directions K (default: lsao 16, hbao 8, ffao 8 (x2 segments), ignored by raytrace)\n"
    "  --guard    guard band in pixels per side (default 10 % of the width/height per side)\n"
    "  --depth    encoding of the values: linear view depth (default), gl / d3d window depth,\n"
    "             reversed Z; the hardware encodings need --near and --far\n";

/* 0 = handled, 1 = usage error (reported), -1 = not an ssao flag */
static int cli_set_ssao(cli_args *a, const char *f, const char *v)
{
    char *end;
    double d;
    if (strcmp(f, "--method") == 0) {
        static const char *const m[] = {"lsao", "hbao", "ffao", "raytrace"};
        int i;
        for (i = 0; i < 4; i++) if (strcmp(v, m[i]) == 0) { a->ssao_method = i; return 0; }
        cli_error(CLI_EXIT_USAGE, "--method", "expected lsao, hbao, ffao or raytrace, got '%s'", v);
        return 1;
    }
    if (strcmp(f, "--depth") == 0) {
        static const char *const m[] = {"linear", "gl", "d3d", "reversed"};
        int i;
        for (i = 0; i < 4; i++) if (strcmp(v, m[i]) == 0) { a->ssao_depth = i; return 0; }
        cli_error(CLI_EXIT_USAGE, "--depth", "expected linear, gl, d3d or reversed, got '%s'", v);
        return 1;
    }
    if (strcmp(f, "--fov-y") && strcmp(f, "--ortho") && strcmp(f, "--radius") &&
        strcmp(f, "--guard") && strcmp(f, "--near") && strcmp(f, "--far"))
        return -1;
    errno = 0;
    d = strtod(v, &end);
    if (end == v || *end || errno || !(d == d) || d - d != 0.0) {
        cli_error(CLI_EXIT_USAGE, f, "expected a number, got '%s'", v);
        return 1;
    }
    if (strcmp(f, "--fov-y") == 0) {
        if (!(d > 0.0 && d < 180.0)) { cli_error(CLI_EXIT_USAGE, f, "must be in (0, 180)"); return 1; }
        a->ssao_fov = d;
    } else if (strcmp(f, "--ortho") == 0) {
        if (!(d > 0.0)) { cli_error(CLI_EXIT_USAGE, f, "must be > 0"); return 1; }
        a->ssao_ortho = d;
        a->ssao_has_ortho = 1;
    } else if (strcmp(f, "--radius") == 0) {
        if (!(d > 0.0)) { cli_error(CLI_EXIT_USAGE, f, "must be > 0"); return 1; }
        a->ssao_radius = d;
    } else if (strcmp(f, "--guard") == 0) {
        if (!(d >= 0.0 && d <= 65536.0 && d == floor(d))) { cli_error(CLI_EXIT_USAGE, f, "must be an integer >= 0"); return 1; }
        a->ssao_guard = (int)d;
    } else if (strcmp(f, "--near") == 0) {
        a->ssao_near = d;
        a->ssao_has_near = 1;
    } else {
        a->ssao_far = d;
        a->ssao_has_far = 1;
    }
    return 0;
}

static int cli_run_ssao(const cli_args *a)
{
    float *depth = NULL, *ao = NULL;
    hfvis_image_info info;
    hfvis_camera cam;
    hfvis_falloff fo;
    hfvis_status s;
    int rc = 0, gx, gy, W, H;
    errno = 0;
    s = hfvis_image_load(a->in, NULL, &depth, &info);
    if (s != HFVIS_OK) return cli_status(a->in, s, errno);
    if (info.channels != 1) { rc = cli_error(CLI_EXIT_ERROR, a->in, "expected a one-channel depth buffer"); goto done; }
    gx = a->ssao_guard >= 0 ? a->ssao_guard : info.width / 10;
    gy = a->ssao_guard >= 0 ? a->ssao_guard : info.height / 10;
    if (2 * gx >= info.width || 2 * gy >= info.height) {
        rc = cli_error(CLI_EXIT_USAGE, "--guard", "leaves no inner pixel in a %dx%d buffer", info.width, info.height);
        goto done;
    }
    if (a->ssao_depth != SSAO_DEPTH_LINEAR) {
        static const hfvis_depth_encoding enc[] = {HFVIS_DEPTH_GL, HFVIS_DEPTH_GL, HFVIS_DEPTH_D3D, HFVIS_DEPTH_REVERSED_Z};
        if (!a->ssao_has_near || !a->ssao_has_far) {
            rc = cli_error(CLI_EXIT_USAGE, "--depth", "hardware depth needs --near and --far");
            goto done;
        }
        s = hfvis_depth_linearize(depth, info.width, info.height, info.width, enc[a->ssao_depth],
                                  a->ssao_has_ortho, a->ssao_near, a->ssao_far, depth, info.width);
        if (s != HFVIS_OK) { rc = cli_status("--near/--far", s, 0); goto done; }
    }
    s = a->ssao_has_ortho ? hfvis_camera_orthographic(&cam, info.width, info.height, gx, gy, a->ssao_ortho)
                          : hfvis_camera_perspective(&cam, info.width, info.height, gx, gy, (a->ssao_fov > 0.0 ? a->ssao_fov : 60.0) * CLI_PI / 180.0);
    if (s != HFVIS_OK) { rc = cli_status("camera", s, 0); goto done; }
    if (a->ssao_depth != SSAO_DEPTH_LINEAR) cam.far_depth = a->ssao_far; /* the far plane is background */
    memset(&fo, 0, sizeof fo);
    if (a->ssao_radius > 0.0) {
        fo.kind = HFVIS_FALLOFF_INV_QUADRATIC;
        fo.param = a->ssao_radius * a->ssao_radius;
    }
    W = info.width - 2 * gx;
    H = info.height - 2 * gy;
    ao = (float *)malloc(sizeof(float) * (size_t)W * (size_t)H);
    if (!ao) { rc = cli_status("ssao", HFVIS_ERR_OUT_OF_MEMORY, 0); goto done; }
    if (a->ssao_method == SSAO_LSAO) {
        hfvis_lsao_options o = hfvis_lsao_options_default();
        o.falloff = fo;
        o.directions = a->dirs;
        s = hfvis_lsao(&cam, depth, NULL, &o, ao, W);
    } else if (a->ssao_method == SSAO_HBAO) {
        hfvis_hbao_options o = hfvis_hbao_options_default();
        o.falloff = fo;
        o.directions = a->dirs;
        s = hfvis_hbao(&cam, depth, NULL, &o, ao, W);
    } else if (a->ssao_method == SSAO_FFAO) {
        hfvis_ffao_options o = hfvis_ffao_options_default();
        o.falloff = fo;
        o.directions = a->dirs;
        s = hfvis_ffao(&cam, depth, NULL, &o, ao, W);
    } else {
        hfvis_ssao_rt_options o = hfvis_ssao_rt_options_default();
        o.falloff = fo;
        s = hfvis_ssao_raytrace(&cam, depth, NULL, &o, ao, W);
    }
    if (s != HFVIS_OK) { rc = cli_status("ssao", s, 0); goto done; }
    rc = cli_save(a, ao, W, H, 1, 0.0, 1.0);
done:
    free(ao);
    hfvis_free(NULL, depth);
    return rc;
}

/* test/cli_test.sh lines (after the inputs block):
 *
 * # plane.pfm: 20 x 16 linear depth 5 everywhere (a fronto-parallel plane): AO 0 everywhere
 * { printf 'Pf\n20 16\n-1\n'; i=0; while [ $i -lt 320 ]; do printf '\000\000\240\100'; i=$((i + 1)); done; } > "$dir/plane.pfm"
 * for m in lsao hbao ffao raytrace; do
 *   if "$hfvis" ssao "$dir/plane.pfm" --method $m --fov-y 60 --guard 2 -o "$dir/ao_$m.pfm" 2>/dev/null &&
 *      [ "$(head -c 9 "$dir/ao_$m.pfm" | tr '\n' ' ')" = "Pf 16 12 " ]; then ok "ssao $m"; else bad "ssao $m"; fi
 * done
 * "$hfvis" ssao "$dir/plane.pfm" --method ffao --ortho 0.1 --radius 2 -o "$dir/ao.pgm" 2>/dev/null && ok "ssao ortho pgm" || bad "ssao ortho pgm"
 * "$hfvis" ssao "$dir/plane.pfm" --method nope -o "$fdir/x.pfm" 2>/dev/null; [ $? -eq 2 ] && ok "ssao bad method" || bad "ssao bad method"
 * "$hfvis" ssao "$dir/plane.pfm" --depth gl -o "$fdir/x.pfm" 2>/dev/null; [ $? -eq 2 ] && ok "ssao gl needs planes" || bad "ssao gl needs planes"
 * "$hfvis" ssao "$dir/plane.pfm" --guard 10 -o "$fdir/x.pfm" 2>/dev/null; [ $? -eq 2 ] && ok "ssao guard too big" || bad "ssao guard too big"
 * "$hfvis" ssao "$dir/garbage.pgm" -o "$fdir/x.pfm" 2>/dev/null; [ $? -eq 1 ] && ok "ssao garbage" || bad "ssao garbage"
 */
