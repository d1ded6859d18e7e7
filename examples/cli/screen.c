/* screen.c - screen space: `ssao` (LSAO, HBAO, FFAO, ray traced) on a depth buffer, its flags
 * and its run. May call: progress.c, flags.c's primitives, write.c. */

/* ssao's --method and --depth (its numbers are rows of the flag table); -1 for another flag. */
static int cli_set_ssao(cli_args *a, const char *f, const char *v)
{
    if (!strcmp(f, "--method") || !strcmp(f, "--depth")) {
        static const char *const methods[] = {"lsao", "hbao", "ffao", "raytrace"};
        static const char *const encodings[] = {"linear", "gl", "d3d", "reversed"};
        int is_method = !strcmp(f, "--method"), i;
        for (i = 0; i < 4; i++)
            if (!strcmp(v, is_method ? methods[i] : encodings[i])) {
                *(is_method ? &a->ssao_method : &a->ssao_depth) = i;
                return 0;
            }
        return cli_error(CLI_EXIT_USAGE, f, is_method ? "expected lsao, hbao, ffao or raytrace, "
                         "got '%s'" : "expected linear, gl, d3d or reversed, got '%s'", v);
    }
    return -1;
}

/* The methods' direction counts (hfvis.h): the flag is named, not the library's status. LSAO's
 * default box pattern takes rings of 8 directions (hfvis_ssao_directions_box). */
static int cli_check_ssao(const cli_args *a)
{
    if (a->ssao_depth == SSAO_DEPTH_LINEAR && (a->ssao_has_near || a->ssao_has_far))
        return cli_error(CLI_EXIT_USAGE, a->ssao_has_near ? "--near" : "--far", "applies only to "
                         "--depth gl, d3d or reversed (linear depth has no planes)");
    if (a->ssao_has_near && a->ssao_has_far /* hfvis_depth_linear's planes */
        && (!(a->ssao_has_ortho ? a->ssao_near >= 0.0 : a->ssao_near > 0.0)
            || !(a->ssao_near < a->ssao_far) || !isfinite(a->ssao_far)))
        return cli_error(CLI_EXIT_USAGE, "--near", "expected finite planes %s near < far, got %g and %g",
                         a->ssao_has_ortho ? "0 <=" : "0 <", a->ssao_near, a->ssao_far);
    if (!a->has_dirs || a->ssao_method == SSAO_RAYTRACE) return 0;
    if (a->ssao_method == SSAO_LSAO && (a->dirs % 8 != 0 || a->dirs > HFVIS_SSAO_MAX_DIRECTIONS))
        return cli_error(CLI_EXIT_USAGE, "--dirs", "ssao --method lsao takes a multiple of 8 in "
                         "8..%d directions, got %d", HFVIS_SSAO_MAX_DIRECTIONS, a->dirs);
    if (a->dirs > HFVIS_SSAO_MAX_DIRECTIONS || (a->ssao_method == SSAO_FFAO && a->dirs < 3))
        return cli_error(CLI_EXIT_USAGE, "--dirs", "ssao --method %s takes %d..%d directions, got %d",
                         a->ssao_method == SSAO_HBAO ? "hbao" : "ffao", a->ssao_method == SSAO_FFAO ? 3 : 1,
                         HFVIS_SSAO_MAX_DIRECTIONS, a->dirs);
    return 0;
}

/* ssao: a depth buffer (linear, or hardware depth linearised first) -> obscurance of the inner
 * pixels by the chosen method. */
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
    if ((rc = cli_check_cost(a, info.width, info.height, 1)) != 0) goto done;
    if (info.channels != 1) {
        rc = cli_error(CLI_EXIT_ERROR, a->in, "expected a one-channel depth buffer");
        goto done;
    }
    gx = a->ssao_guard >= 0 ? a->ssao_guard : info.width / 10;
    gy = a->ssao_guard >= 0 ? a->ssao_guard : info.height / 10;
    if (2 * gx >= info.width || 2 * gy >= info.height) {
        rc = cli_error(CLI_EXIT_USAGE, "--guard", "leaves no inner pixel in a %dx%d buffer",
                       info.width, info.height);
        goto done;
    }
    if (a->ssao_depth != SSAO_DEPTH_LINEAR) {
        static const hfvis_depth_encoding enc[] = {HFVIS_DEPTH_GL, HFVIS_DEPTH_GL, HFVIS_DEPTH_D3D,
                                                   HFVIS_DEPTH_REVERSED_Z};
        if (!a->ssao_has_near || !a->ssao_has_far) {
            rc = cli_error(CLI_EXIT_USAGE, "--depth", "hardware depth needs --near and --far");
            goto done;
        }
        s = hfvis_depth_linearize(depth, info.width, info.height, info.width, enc[a->ssao_depth],
                                  a->ssao_has_ortho, a->ssao_near, a->ssao_far, depth, info.width);
        if (s != HFVIS_OK) { rc = cli_status("--near/--far", s, 0); goto done; }
    }
    if (a->ssao_has_ortho)
        s = hfvis_camera_orthographic(&cam, info.width, info.height, gx, gy, a->ssao_ortho);
    else
        s = hfvis_camera_perspective(&cam, info.width, info.height, gx, gy,
                                     a->ssao_fov * CLI_PI / 180.0);
    if (s != HFVIS_OK) { rc = cli_status("camera", s, 0); goto done; }
    if (a->ssao_depth != SSAO_DEPTH_LINEAR)
        cam.far_depth = a->ssao_far; /* the far plane is background */
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
        o.directions = a->has_dirs ? a->dirs : 0;
        s = hfvis_lsao(&cam, depth, NULL, &o, ao, W);
    } else if (a->ssao_method == SSAO_HBAO) {
        hfvis_hbao_options o = hfvis_hbao_options_default();
        o.falloff = fo;
        o.directions = a->has_dirs ? a->dirs : 0;
        s = hfvis_hbao(&cam, depth, NULL, &o, ao, W);
    } else if (a->ssao_method == SSAO_FFAO) {
        hfvis_ffao_options o = hfvis_ffao_options_default();
        o.falloff = fo;
        o.directions = a->has_dirs ? a->dirs : 0;
        s = hfvis_ffao(&cam, depth, NULL, &o, ao, W);
    } else {
        hfvis_ssao_rt_options o = hfvis_ssao_rt_options_default();
        o.falloff = fo;
        s = hfvis_ssao_reference(&cam, depth, NULL, &o, ao, W);
    }
    if (s != HFVIS_OK) { rc = cli_status("ssao", s, 0); goto done; }
    rc = cli_save(a, cli_output_of(ao, W, H, 1, 1, 0.0, 1.0));
done:
    free(ao);
    hfvis_free(NULL, depth);
    return rc;
}
