/* cli_lk.c - the `meshao` subcommand of examples/hfvis_cli.c: Laine-Karras bitmask ray-cast
 * ambient obscurance of an OBJ mesh seen by a camera (hfvis_lk_image), by rasterization (Method 1),
 * BVH traversal (Method 2) or the reference ray caster.
 *
 * MERGE RECIPE (examples/hfvis_cli.c as of commit ebaca8c; tested by applying it to a copy and
 * running the commands at the end and the cli_test.sh lines of PART D):
 *  1. enum: add CMD_MESHAO before CMD_COUNT; cli_cmd_names: add "meshao" at the end.
 *  2. cli_usage, after the last mesh command's line (move the closing ';' to the new line):
 *       "  meshao      ray-cast ambient obscurance of an OBJ mesh (Laine & Karras bit masks)\n"
 *  3. cli_cmd_help: append CLI_LK_HELP (PART A) as the last entry.
 *  4. cli_args: add   int lk_method, lk_rays, lk_falloff, lk_width, lk_height, lk_two_sided,
 *                         lk_lut, lk_no_jitter, lk_has_eye, lk_has_target, lk_has_up,
 *                         lk_has_radius;
 *                     double lk_radius, lk_fov, lk_seed, lk_eye[3], lk_target[3], lk_up[3];
 *  5. cli_flags: add the entries of CLI_LK_FLAGS (PART A) after the last *_FLAGS macro; and for
 *     each of the shared names  --method --stats --rays --size --radius --eye --target --up --fov
 *     OR | CLI_ONLY(CMD_MESHAO) into its entry when cli_flags already has one (--method and
 *     --stats are always there; the others come with the vf, volgi and ssaob parts), else add
 *     that entry from CLI_LK_SHARED_FLAGS.
 *  6. cli_set: make this the FIRST statement (it takes -o and the shared names for meshao only):
 *       if (a->cmd == CMD_MESHAO) { int r = cli_set_lk(a, f, v); if (r >= 0) return r; }
 *  7. cli_parse: after the defaults line add   cli_lk_defaults(a);
 *     and before "return CLI_RUN;" add   if (a->cmd == CMD_MESHAO && cli_check_lk(a)) return CLI_EXIT_USAGE;
 *  8. cli_run: beside the voxelize hook add   if (a->cmd == CMD_MESHAO) return cli_run_meshao(a);
 *  9. Paste PART B (cli_lk_defaults, cli_lk_reals, cli_set_lk, cli_check_lk) after cli_check_gi
 *     (it needs cli_error, cli_parse_real, cli_int, cli_real, cli_ends_with), PART C
 *     (cli_run_meshao) after cli_run_voxelize (it needs cli_save, cli_status, cli_error).
 * 10. test/cli_test.sh: add "meshao" to the --help loop and the lines of PART D.
 *  Then e.g.:  hfvis meshao teapot.obj -o teapot_ao.pgm
 *              hfvis meshao room.obj --method raster --rays 256 --radius 0.2 --falloff linear \
 *                    --eye 0.5,-1.2,0.5 --target 0.5,0.5,0.4 --fov 50 --size 640x480 --stats -o ao.pfm
 */

/* ---- PART A: after CLI_GI_FLAGS (or the last *_FLAGS macro) --------------------------------- */

#define CLI_LK_HELP                                                                                  \
    "usage: hfvis meshao MESH.obj -o OUT [--method raster|bvh|raycast] [--rays N] [--radius R]\n"  \
    "         [--falloff constant|linear|quadratic] [--eye X,Y,Z] [--target X,Y,Z] [--up X,Y,Z]\n"  \
    "         [--fov DEG] [--size WxH] [--two-sided] [--lut T] [--seed S] [--no-jitter] [--stats]\n" \
    "Ray-cast ambient obscurance of a triangle mesh seen by a pinhole camera, with the bit masks of\n" \
    "Laine & Karras 2010: each visible point (pixel) casts N cosine-distributed shadow rays of\n"   \
    "length up to R; W = blocked rays / N (0 open .. 1 blocked). All N rays of a point are decided\n" \
    "together: each nearby triangle sets the bits of the rays it blocks (three edge planes and its\n" \
    "own plane). The three methods give the same image bit for bit:\n"                              \
    "  --method M        bvh (default): BVH traversal per point with node masks (Method 2);\n"      \
    "                    raster: each triangle's region of influence projected over the pixels\n"   \
    "                    (Method 1); raycast: every ray through the BVH (the reference)\n"          \
    "  --rays N          rays per point, 1..4096 (default 128)\n"                                  \
    "  --radius R        longest ray, > 0 (default 0.1 x the mesh's bounding-box diagonal)\n"      \
    "  --falloff F       constant (default: every ray has length R), linear (rho = 1 - d/R) or\n"   \
    "                    quadratic (rho = (1 - d/R)^2): ray lengths distributed by the falloff\n"   \
    "  --eye X,Y,Z       camera position (default: in front of the bounding box, from -y, above)\n" \
    "  --target X,Y,Z    point looked at (default: the bounding-box centre)\n"                     \
    "  --up X,Y,Z        up direction (default 0,0,1; 0,1,0 when looking along z)\n"              \
    "  --fov DEG         vertical field of view, 1..179 (default 45)\n"                            \
    "  --size WxH        image size in pixels, 1..8192 each (default 512x384)\n"                  \
    "  --two-sided       every triangle occludes from both sides (default: only from the side its\n" \
    "                    normal, counter-clockwise winding, points to)\n"                         \
    "  --lut T           plane look-up table masks of T^3 nodes, 2..1024 (faster for many rays;\n"  \
    "                    approximate: rays within about one node of a plane may flip)\n"          \
    "  --seed S          seed of the ray pattern and the per-pixel jitter, 0..2^53 (default 0)\n"  \
    "  --no-jitter       no per-pixel rotation of the pattern (banding on flat areas)\n"          \
    "  --stats           print the counts of the run (receivers, rays, culling) to stdout\n"       \
    "OUT is .pgm (16-bit, range 0:1; pixels without geometry 0) or .pfm (NaN there).\n"

#define CLI_LK_FLAGS                                                                          \
    { "--falloff", 1, CLI_ONLY(CMD_MESHAO) }, { "--two-sided", 0, CLI_ONLY(CMD_MESHAO) },     \
    { "--lut", 1, CLI_ONLY(CMD_MESHAO) }, { "--seed", 1, CLI_ONLY(CMD_MESHAO) },              \
    { "--no-jitter", 0, CLI_ONLY(CMD_MESHAO) }

/* Only those of these names that cli_flags does not have yet (see step 5). */
#define CLI_LK_SHARED_FLAGS                                                                   \
    { "--rays", 1, CLI_ONLY(CMD_MESHAO) }, { "--size", 1, CLI_ONLY(CMD_MESHAO) },             \
    { "--radius", 1, CLI_ONLY(CMD_MESHAO) }, { "--eye", 1, CLI_ONLY(CMD_MESHAO) },            \
    { "--target", 1, CLI_ONLY(CMD_MESHAO) }, { "--up", 1, CLI_ONLY(CMD_MESHAO) },             \
    { "--fov", 1, CLI_ONLY(CMD_MESHAO) }

/* ---- PART B: after cli_check_gi --------------------------------------------------------------- */

/* meshao's defaults (called for every command; harmless for the others). */
static void cli_lk_defaults(cli_args *a)
{
    a->lk_method = HFVIS_LK_METHOD_BVH;
    a->lk_rays = 128;
    a->lk_falloff = HFVIS_LK_FALLOFF_CONSTANT;
    a->lk_width = 512;
    a->lk_height = 384;
    a->lk_fov = 45.0;
    a->lk_up[0] = 0.0; a->lk_up[1] = 0.0; a->lk_up[2] = 1.0;
}

/* "X,Y,Z": three finite numbers. */
static int cli_lk_reals(const char *f, const char *v, double out[3])
{
    char buf[256];
    const char *p = v;
    int k;
    for (k = 0; k < 3; k++) {
        const char *e = k < 2 ? strchr(p, ',') : p + strlen(p);
        size_t n = e ? (size_t)(e - p) : 0;
        if (!e || n == 0 || n >= sizeof buf) break;
        memcpy(buf, p, n);
        buf[n] = '\0';
        if (!cli_parse_real(buf, &out[k]) || fabs(out[k]) > CLI_FLT_MAX) break;
        p = e + 1;
    }
    if (k < 3) return cli_error(CLI_EXIT_USAGE, f, "expected X,Y,Z (three finite numbers), got '%s'", v);
    return 0;
}

/* -o and the flags of `meshao` (called only for it); -1 if f is none of them. */
static int cli_set_lk(cli_args *a, const char *f, const char *v)
{
    if (!strcmp(f, "-o")) {
        if (cli_ends_with(v, ".pfm")) a->out_pgm = 0;
        else if (cli_ends_with(v, ".pgm")) a->out_pgm = 1;
        else return cli_error(CLI_EXIT_USAGE, v, "unknown output type (use a .pfm or .pgm name)");
        a->out = v;
        return 0;
    }
    if (!strcmp(f, "--method")) {
        if (!strcmp(v, "raster")) a->lk_method = HFVIS_LK_METHOD_RASTER;
        else if (!strcmp(v, "bvh")) a->lk_method = HFVIS_LK_METHOD_BVH;
        else if (!strcmp(v, "raycast")) a->lk_method = HFVIS_LK_METHOD_RAYCAST;
        else return cli_error(CLI_EXIT_USAGE, f, "expected raster, bvh or raycast, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--rays"))
        return cli_int(f, v, 1, HFVIS_LK_MAX_RAYS, "an integer 1..4096", &a->lk_rays);
    if (!strcmp(f, "--radius")) {
        a->lk_has_radius = 1;
        return cli_real(f, v, 0.0, 1, CLI_FLT_MAX, "a radius > 0", &a->lk_radius);
    }
    if (!strcmp(f, "--falloff")) {
        if (!strcmp(v, "constant")) a->lk_falloff = HFVIS_LK_FALLOFF_CONSTANT;
        else if (!strcmp(v, "linear")) a->lk_falloff = HFVIS_LK_FALLOFF_LINEAR;
        else if (!strcmp(v, "quadratic")) a->lk_falloff = HFVIS_LK_FALLOFF_QUADRATIC;
        else return cli_error(CLI_EXIT_USAGE, f, "expected constant, linear or quadratic, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--eye")) { a->lk_has_eye = 1; return cli_lk_reals(f, v, a->lk_eye); }
    if (!strcmp(f, "--target")) { a->lk_has_target = 1; return cli_lk_reals(f, v, a->lk_target); }
    if (!strcmp(f, "--up")) { a->lk_has_up = 1; return cli_lk_reals(f, v, a->lk_up); }
    if (!strcmp(f, "--fov")) return cli_real(f, v, 1.0, 0, 179.0, "degrees in 1..179", &a->lk_fov);
    if (!strcmp(f, "--size")) {
        char *x = NULL;
        long w, h;
        errno = 0;
        w = strtol(v, &x, 10);
        if (x == v || !x || (*x != 'x' && *x != 'X') || errno == ERANGE)
            return cli_error(CLI_EXIT_USAGE, f, "expected WxH (e.g. 640x480), got '%s'", v);
        h = strtol(x + 1, &x, 10);
        if (*x != '\0' || errno == ERANGE || w < 1 || h < 1 || w > 8192 || h > 8192 ||
            !isdigit((unsigned char)v[0]))
            return cli_error(CLI_EXIT_USAGE, f, "expected WxH with W, H in 1..8192, got '%s'", v);
        a->lk_width = (int)w;
        a->lk_height = (int)h;
        return 0;
    }
    if (!strcmp(f, "--two-sided")) { a->lk_two_sided = 1; return 0; }
    if (!strcmp(f, "--lut"))
        return cli_int(f, v, HFVIS_LK_LUT_MIN_RESOLUTION, HFVIS_LK_LUT_MAX_RESOLUTION,
                       "a table resolution 2..1024", &a->lk_lut);
    if (!strcmp(f, "--seed"))
        return cli_real(f, v, 0.0, 0, 9007199254740992.0, "an integer 0..2^53", &a->lk_seed);
    if (!strcmp(f, "--no-jitter")) { a->lk_no_jitter = 1; return 0; }
    return -1;
}

/* Combinations `meshao` rejects; returns 0 or CLI_EXIT_USAGE (message printed). */
static int cli_check_lk(const cli_args *a)
{
    if (a->lk_seed != floor(a->lk_seed))
        return cli_error(CLI_EXIT_USAGE, "--seed", "expected an integer, got %g", a->lk_seed);
    if (a->lk_has_eye && a->lk_has_target && a->lk_eye[0] == a->lk_target[0] &&
        a->lk_eye[1] == a->lk_target[1] && a->lk_eye[2] == a->lk_target[2])
        return cli_error(CLI_EXIT_USAGE, "--eye", "the eye and the target coincide");
    if (a->lk_has_up && a->lk_up[0] == 0.0 && a->lk_up[1] == 0.0 && a->lk_up[2] == 0.0)
        return cli_error(CLI_EXIT_USAGE, "--up", "the up direction is zero");
    return 0;
}

/* ---- PART C: after cli_run_voxelize ----------------------------------------------------------- */

/* meshao: MESH.obj -> camera -> hfvis_lk_image -> OUT. */
static int cli_run_meshao(const cli_args *a)
{
    const char *cmd = "meshao";
    hfvis_mesh mesh;
    hfvis_lk_rays rays;
    hfvis_lk_ray_options ro = hfvis_lk_ray_options_default();
    hfvis_lk_options o = hfvis_lk_options_default();
    hfvis_lk_lut lut;
    hfvis_lk_stats st;
    hfvis_view view;
    hfvis_status s;
    double lo[3], hi[3], c[3], eye[3], tgt[3], up[3], d[3], diag, dist, radius, nearp, farp, len;
    float *out = NULL;
    int rc = 0, k;
    memset(&rays, 0, sizeof rays);
    memset(&lut, 0, sizeof lut);
    errno = 0;
    s = hfvis_mesh_load(a->in, NULL, &mesh);
    if (s != HFVIS_OK) return cli_status(a->in, s, errno);
    if (mesh.triangle_count == 0) {
        rc = cli_error(CLI_EXIT_ERROR, a->in, "the mesh has no triangles");
        goto done;
    }
    s = hfvis_mesh_bounds(&mesh, lo, hi);
    if (s != HFVIS_OK) { rc = cli_status(cmd, s, 0); goto done; }
    for (k = 0; k < 3; k++) c[k] = 0.5 * (lo[k] + hi[k]);
    diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                (hi[2] - lo[2]) * (hi[2] - lo[2]));
    if (!(diag > 0.0)) diag = 1.0;
    radius = a->lk_has_radius ? a->lk_radius : 0.1 * diag;
    /* camera: default eye in front (-y) and above the box, framing it */
    for (k = 0; k < 3; k++) tgt[k] = a->lk_has_target ? a->lk_target[k] : c[k];
    if (a->lk_has_eye) {
        for (k = 0; k < 3; k++) eye[k] = a->lk_eye[k];
    } else {
        double back = 0.5 * diag / tan(0.5 * a->lk_fov * (CLI_PI / 180.0)) + 0.5 * diag;
        eye[0] = tgt[0] + 0.25 * back;
        eye[1] = tgt[1] - 0.9 * back;
        eye[2] = tgt[2] + 0.45 * back;
    }
    for (k = 0; k < 3; k++) {
        d[k] = tgt[k] - eye[k];
        up[k] = a->lk_up[k];
    }
    dist = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(dist > 0.0)) { rc = cli_error(CLI_EXIT_ERROR, "--eye", "the eye is at the target"); goto done; }
    len = fabs(d[0] * up[0] + d[1] * up[1] + d[2] * up[2]) /
          (dist * sqrt(up[0] * up[0] + up[1] * up[1] + up[2] * up[2]));
    if (!a->lk_has_up && len > 0.999) { up[0] = 0.0; up[1] = 1.0; up[2] = 0.0; }
    farp = dist + 2.0 * diag + 2.0 * radius;
    nearp = farp * 1e-4;
    s = hfvis_view_perspective(&view, eye, tgt, up, a->lk_fov * (CLI_PI / 180.0), a->lk_width,
                               a->lk_height, nearp, farp);
    if (s != HFVIS_OK) {
        rc = cli_error(CLI_EXIT_ERROR, cmd, "%s (is --up parallel to the viewing direction?)",
                       hfvis_status_string(s));
        goto done;
    }
    /* rays, options, optional table */
    ro.falloff = (hfvis_lk_falloff)a->lk_falloff;
    ro.seed = (uint64_t)a->lk_seed;
    s = hfvis_lk_rays_build(a->lk_rays, radius, &ro, &rays);
    if (s != HFVIS_OK) { rc = cli_status(cmd, s, 0); goto done; }
    o.seed = (uint64_t)a->lk_seed;
    o.sides = a->lk_two_sided ? HFVIS_LK_SIDES_TWO : HFVIS_LK_SIDES_ONE;
    if (a->lk_no_jitter) o.jitter = HFVIS_LK_JITTER_NONE;
    if (a->lk_lut) {
        s = hfvis_lk_lut_build(&rays, a->lk_lut, NULL, &lut);
        if (s == HFVIS_ERR_LIMIT) {
            rc = cli_error(CLI_EXIT_ERROR, "--lut", "%s: a %d^3 table for %d rays needs %.0f MiB (limit "
                           "%.0f MiB); use a smaller T or exact masks", hfvis_status_string(s), a->lk_lut,
                           a->lk_rays, (double)hfvis_lk_lut_bytes(a->lk_lut, a->lk_rays, !rays.equal_lengths) / 1048576.0,
                           (double)HFVIS_LK_LUT_MAX_BYTES / 1048576.0);
            goto done;
        }
        if (s != HFVIS_OK) { rc = cli_status(cmd, s, 0); goto done; }
        o.lut = &lut;
        o.mask_mode = HFVIS_LK_MASK_LUT;
    }
    out = cli_alloc((size_t)a->lk_width, (size_t)a->lk_height, 1);
    if (!out) { rc = cli_status(cmd, HFVIS_ERR_OUT_OF_MEMORY, 0); goto done; }
    s = hfvis_lk_image((hfvis_lk_method)a->lk_method, &mesh, NULL, &view, &rays, &o, NULL, out, &st);
    if (s != HFVIS_OK) { rc = cli_status(cmd, s, 0); goto done; }
    rc = cli_save(a, out, a->lk_width, a->lk_height, 1, 0.0, 1.0);
    if (rc == 0 && a->stats) {
        printf("receivers: %llu\nrays: %llu\nblocked: %llu (mean obscurance %.6f)\n",
               (unsigned long long)st.receivers, (unsigned long long)st.rays,
               (unsigned long long)st.rays_blocked,
               st.rays ? (double)st.rays_blocked / (double)st.rays : 0.0);
        printf("candidates: %llu\nmasks computed: %llu\nculled: far depth %llu, sphere %llu, facing %llu, "
               "plane %llu, horizon %llu\nskipped (self plane, zero area): %llu\n",
               (unsigned long long)st.fragments, (unsigned long long)st.masks,
               (unsigned long long)st.culled_far_depth, (unsigned long long)st.culled_sphere,
               (unsigned long long)st.culled_facing, (unsigned long long)st.culled_plane,
               (unsigned long long)st.culled_horizon, (unsigned long long)st.skipped);
        if (a->lk_method == HFVIS_LK_METHOD_RASTER)
            printf("volumes: %llu prisms, %llu spheres\n", (unsigned long long)st.prisms,
                   (unsigned long long)st.spheres);
        else
            printf("nodes visited: %llu (culled: distance %llu, horizon %llu, mask %llu)\n",
                   (unsigned long long)st.nodes_visited, (unsigned long long)st.nodes_culled_distance,
                   (unsigned long long)st.nodes_culled_horizon, (unsigned long long)st.nodes_culled_mask);
        if (fflush(stdout) != 0) rc = cli_error(CLI_EXIT_ERROR, "stdout", "%s", strerror(errno));
    }
done:
    free(out);
    hfvis_lk_lut_free(NULL, &lut);
    hfvis_lk_rays_free(NULL, &rays);
    hfvis_mesh_free(NULL, &mesh);
    return rc;
}

/* ---- PART D: test/cli_test.sh ------------------------------------------------------------------
 * D1, after the voxelize expect_ok lines ($dir/cube.obj exists: the unit cube, outward faces):
 *
 * # meshao: the cube seen from outside: every method writes the same image
 * expect_ok "meshao bvh" "$dir/ao_b.pfm" meshao "$dir/cube.obj" --rays 64 --radius 0.5 --size 24x18 -o "$dir/ao_b.pfm"
 * expect_ok "meshao raster" "$dir/ao_r.pfm" meshao "$dir/cube.obj" --method raster --rays 64 --radius 0.5 --size 24x18 -o "$dir/ao_r.pfm"
 * expect_ok "meshao raycast" "$dir/ao_c.pfm" meshao "$dir/cube.obj" --method raycast --rays 64 --radius 0.5 --size 24x18 -o "$dir/ao_c.pfm"
 * cmp -s "$dir/ao_b.pfm" "$dir/ao_r.pfm" && cmp -s "$dir/ao_b.pfm" "$dir/ao_c.pfm" && ok "meshao: three methods, same bytes" || bad "meshao: methods differ"
 * expect_ok "meshao inside the cube, two-sided, linear, lut, stats" "$dir/ao_i.pgm" meshao "$dir/cube.obj" --two-sided --falloff linear --lut 16 --rays 96 --radius 2 --eye 0.5,0.5,0.5 --target 0.5,1,0.5 --fov 90 --size 16x16 --seed 3 --no-jitter --stats -o "$dir/ao_i.pgm"
 * grep -q '^receivers: 256$' "$dir/stdout" && ok "meshao inside: 256 receivers" || bad "meshao stats: $(cat "$dir/stdout")"
 *
 * D2, after the voxelize expect_fail lines ($o is set):
 *
 * expect_fail "meshao --method" 2 meshao "$dir/cube.obj" --method lsao -o "$o"
 * expect_fail "meshao --rays 0" 2 meshao "$dir/cube.obj" --rays 0 -o "$o"
 * expect_fail "meshao --size" 2 meshao "$dir/cube.obj" --size 10 -o "$o"
 * expect_fail "meshao --eye" 2 meshao "$dir/cube.obj" --eye 1,2 -o "$o"
 * expect_fail "meshao --lut too big" 1 meshao "$dir/cube.obj" --rays 1024 --falloff linear --lut 128 -o "$o"
 * expect_fail "meshao empty mesh" 1 meshao "$dir/garbage.pgm" -o "$o"
 */
