/* cli_vf.c - the `visfield` subcommand of examples/hfvis_cli.c (4D visibility fields, [G12] ch. 4):
 * build a field from an OBJ mesh and write it (.hfvf, the format documented in hfvis.h), or read a
 * field and write an ambient-obscurance image of a ground plane under the object.
 *
 * MERGE RECIPE (examples/hfvis_cli.c; tested by applying it to a copy, see the commands at the end):
 *  1. enum: add CMD_VISFIELD just before CMD_COUNT; cli_cmd_names: add "visfield" at the end.
 *  2. cli_usage, after the "voxelize" line:
 *       "  visfield    4D visibility field of an OBJ mesh (.hfvf), or AO images from one\n"
 *  3. cli_cmd_help: append CLI_VF_HELP (below) as the last entry.
 *  4. cli_args: add   int vf_positions, vf_format, vf_mapping, vf_ao, vf_rays, vf_has_size;
 *                     int vf_has_extent, vf_has_ground, vf_has_bias;
 *                     double vf_extent, vf_ground, vf_bias;
 *                     const char *vf_reference;
 *     (has_dirs exists (gi part; --dirs sets it); --size WxH is volgi's: vg_width, vg_height.)
 *  5. flags: "--max-distance" gains | CLI_ONLY(CMD_VISFIELD), and so does "--size" (in
 *     CLI_VOLGI_FLAGS); add CLI_VF_FLAGS as the last entries of cli_flags.
 *  6. cli_set: first statement:  if (!strcmp(f, "-o") && a->cmd == CMD_VISFIELD) return cli_set_vf(a, f, v);
 *     and just BEFORE the cli_set_volgi call:  { int r = cli_set_vf(a, f, v); if (r >= 0) return r; }
 *     (cli_set_vf notes --size and lets volgi's code parse the WxH)
 *  7. cli_parse: before "return CLI_RUN;" add
 *       if (a->cmd == CMD_VISFIELD && cli_check_vf(a)) return CLI_EXIT_USAGE;
 *  8. cli_run: after the voxelize line:  if (a->cmd == CMD_VISFIELD) return cli_run_visfield(a);
 *  9. Paste PART A (the two macros) after CLI_GI_FLAGS, PART B (cli_set_vf, cli_check_vf) after
 *     cli_check_gi, PART C (cli_run_visfield and its helpers) after cli_run_voxelize.
 *  (Applied to examples/hfvis_cli.c of commit 62e9155 and built with -Werror; every command below
 *  and the usage errors were run.)
 *  Then e.g.:
 *    hfvis visfield teapot.obj --positions 4226 --dirs 32 -o teapot.hfvf
 *    hfvis visfield --ao teapot.hfvf --ground 0 -o teapot_ao.pgm
 *    hfvis visfield --ao teapot.hfvf --ground 0 --reference teapot.obj -o teapot_ao_ref.pgm
 */

/* ---- PART A: after CLI_GI_FLAGS ------------------------------------------------------------- */

#define CLI_VF_HELP                                                                                  \
    "usage: hfvis visfield MESH.obj -o FIELD.hfvf [--positions K] [--dirs D] [--format F]\n"        \
    "                      [--mapping M]\n"                                                          \
    "       hfvis visfield --ao FIELD.hfvf -o OUT [--ground Z] [--extent E] [--size WxH] [--rays S]\n" \
    "                      [--max-distance L] [--bias B] [--reference MESH.obj]\n"                  \
    "Pre-computed 4D visibility fields ([G12] ch. 4): for K sample points on the mesh's bounding\n" \
    "sphere and D x D directions over the inward hemisphere at each, the distance to the mesh\n"    \
    "(Alg. 1). A ray that meets the sphere then finds its hit distance by one table lookup.\n"     \
    "Build mode writes the field (the .hfvf format documented in hfvis.h); K*D*D rays are cast\n"   \
    "(4226 x 32 x 32 = 4.3 M rays; about 1 us each on a 100k-triangle mesh).\n"                     \
    "  --positions K     positional samples, a count 2(2n^2+2n+1): 10, 26, 50, 82, 122, ..., 290,\n" \
    "                    1090, 4226 (default, the thesis' recommendation), 16642, ...\n"            \
    "  --dirs D          directional samples per side, 1..4096 (default 32)\n"                      \
    "  --format F        u8 (default: 1 byte per direction), f32 (float), bit (hit/miss and one\n"  \
    "                    average distance), normal (RGBA8: normal + 8-bit distance)\n"              \
    "  --mapping M       concentric (default, Shirley-Chiu + Malley), polar or rejection\n"         \
    "--ao reads FIELD and writes the ambient obscurance (0 open .. 1 blocked, cosine-weighted,\n"   \
    "[G12] Alg. 2) of the ground plane z = Z under the object, seen from above: a W x H image of\n" \
    "the rectangle of half-width E (half-height E H/W) around the sphere's centre, row 0 = +y.\n"   \
    "  --ground Z        height of the ground plane in the field's object space (default: the\n"   \
    "                    bottom of the bounding sphere, centre z - radius)\n"                       \
    "  --extent E        half-width of the rectangle, > 0 (default 1.5 x the sphere's radius)\n"    \
    "  --size WxH        image size in pixels (default 256x256)\n"                                  \
    "  --rays S          S x S concentric rays per pixel, 1..256 (default 16: 256 rays)\n"          \
    "  --max-distance L  rays blocked farther than L do not count (default: unlimited)\n"          \
    "  --bias B          inside-query bias as a fraction of the radius, >= 0 (default 0.02)\n"     \
    "  --reference M     ray-cast M (the mesh the field was built from) with the same rays instead\n" \
    "                    (the oracle: compare the two images)\n"                                    \
    "OUT is .pgm (16-bit, default range 0:1) or .pfm.\n"

#define CLI_VF_FLAGS                                                                              \
    { "--positions", 1, CLI_ONLY(CMD_VISFIELD) }, { "--format", 1, CLI_ONLY(CMD_VISFIELD) },      \
    { "--mapping", 1, CLI_ONLY(CMD_VISFIELD) }, { "--ao", 0, CLI_ONLY(CMD_VISFIELD) },            \
    { "--ground", 1, CLI_ONLY(CMD_VISFIELD) }, { "--extent", 1, CLI_ONLY(CMD_VISFIELD) },         \
    { "--rays", 1, CLI_ONLY(CMD_VISFIELD) },                                                      \
    { "--bias", 1, CLI_ONLY(CMD_VISFIELD) }, { "--reference", 1, CLI_ONLY(CMD_VISFIELD) }

/* ---- PART B: after cli_check_gi ------------------------------------------------------------- */

/* -o and the flags only `visfield` has; -1 if f is none of them. */
static int cli_set_vf(cli_args *a, const char *f, const char *v)
{
    if (!strcmp(f, "-o")) { /* checked against the mode in cli_check_vf */
        a->out = v;
        a->out_pgm = cli_ends_with(v, ".pgm");
        return 0;
    }
    if (!strcmp(f, "--positions")) {
        int k, n;
        if (cli_int(f, v, 1, INT_MAX, "a count 2(2n^2+2n+1) such as 290, 1090 or 4226", &k))
            return CLI_EXIT_USAGE;
        for (n = 1; n <= HFVIS_VISFIELD_MAX_N; n++)
            if (hfvis_visfield_position_count(n) >= (size_t)k) break;
        if (n > HFVIS_VISFIELD_MAX_N || hfvis_visfield_position_count(n) != (size_t)k) {
            if (n > HFVIS_VISFIELD_MAX_N)
                return cli_error(CLI_EXIT_USAGE, f, "at most %zu positional samples, got '%s'",
                                 hfvis_visfield_position_count(HFVIS_VISFIELD_MAX_N), v);
            return cli_error(CLI_EXIT_USAGE, f, "expected a count 2(2n^2+2n+1), got '%s' (nearest: "
                             "%zu or %zu)", v, n > 1 ? hfvis_visfield_position_count(n - 1) : 0,
                             hfvis_visfield_position_count(n));
        }
        a->vf_positions = n; /* stored as the frequency n */
        return 0;
    }
    if (!strcmp(f, "--format")) {
        if (!strcmp(v, "u8")) a->vf_format = HFVIS_VISFIELD_U8;
        else if (!strcmp(v, "f32")) a->vf_format = HFVIS_VISFIELD_F32;
        else if (!strcmp(v, "bit")) a->vf_format = HFVIS_VISFIELD_BIT;
        else if (!strcmp(v, "normal")) a->vf_format = HFVIS_VISFIELD_NORMAL;
        else return cli_error(CLI_EXIT_USAGE, f, "expected u8, f32, bit or normal, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--mapping")) {
        if (!strcmp(v, "concentric")) a->vf_mapping = HFVIS_DIRMAP_CONCENTRIC;
        else if (!strcmp(v, "polar")) a->vf_mapping = HFVIS_DIRMAP_POLAR;
        else if (!strcmp(v, "rejection")) a->vf_mapping = HFVIS_DIRMAP_REJECTION;
        else return cli_error(CLI_EXIT_USAGE, f, "expected concentric, polar or rejection, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--ao")) { a->vf_ao = 1; return 0; }
    if (!strcmp(f, "--size")) { a->vf_has_size = 1; return -1; } /* WxH parsed by volgi's code */
    if (!strcmp(f, "--ground")) {
        a->vf_has_ground = 1;
        return cli_real(f, v, -CLI_FLT_MAX, 0, CLI_FLT_MAX, "a finite height", &a->vf_ground);
    }
    if (!strcmp(f, "--extent")) {
        a->vf_has_extent = 1;
        return cli_real(f, v, 0.0, 1, CLI_FLT_MAX, "a half-size > 0", &a->vf_extent);
    }
    if (!strcmp(f, "--rays"))
        return cli_int(f, v, 1, HFVIS_VISFIELD_MAX_RAYS_SQRT, "an integer 1..256", &a->vf_rays);
    if (!strcmp(f, "--bias")) {
        a->vf_has_bias = 1;
        return cli_real(f, v, 0.0, 0, 1.0, "a fraction of the radius in 0..1", &a->vf_bias);
    }
    if (!strcmp(f, "--reference")) { a->vf_reference = v; return 0; }
    return -1;
}

/* Combinations `visfield` rejects; returns 0 or CLI_EXIT_USAGE (message printed). */
static int cli_check_vf(const cli_args *a)
{
    if (a->vf_ao) {
        if (!cli_ends_with(a->out, ".pgm") && !cli_ends_with(a->out, ".pfm"))
            return cli_error(CLI_EXIT_USAGE, a->out, "unknown output type (use a .pfm or .pgm name)");
        if (a->vf_positions || a->vf_format || a->vf_mapping || a->has_dirs)
            return cli_error(CLI_EXIT_USAGE, a->vf_positions ? "--positions" : a->vf_format ? "--format"
                             : a->vf_mapping ? "--mapping" : "--dirs", "applies only to building a field");
        return 0;
    }
    if (a->has_range) return cli_error(CLI_EXIT_USAGE, "--range", "applies only to --ao images");
    if (a->vf_has_ground || a->vf_has_extent || a->vf_has_size || a->vf_rays || a->vf_has_bias
        || a->vf_reference || a->max_distance > 0.0)
        return cli_error(CLI_EXIT_USAGE, a->vf_has_ground ? "--ground" : a->vf_has_extent ? "--extent"
                         : a->vf_has_size ? "--size" : a->vf_rays ? "--rays" : a->vf_has_bias ? "--bias"
                         : a->vf_reference ? "--reference" : "--max-distance", "applies only to --ao");
    if (a->has_dirs && (a->dirs < 1 || a->dirs > HFVIS_VISFIELD_MAX_DIR_RES))
        return cli_error(CLI_EXIT_USAGE, "--dirs", "a field takes 1..4096 directions per side, got %d",
                         a->dirs);
    return 0;
}

/* ---- PART C: after cli_run_voxelize ---------------------------------------------------------- */

/* visfield MESH.obj: build (Alg. 1) and save. */
static int cli_vf_build(const cli_args *a)
{
    static const char *const fmt_names[5] = {"u8", "u8", "f32", "bit", "normal"};
    hfvis_mesh mesh = {0};
    hfvis_visfield vf;
    hfvis_visfield_build_options bo;
    cli_progress_state prog;
    hfvis_status s;
    size_t bytes;
    int rc = 0;
    memset(&vf, 0, sizeof vf);
    memset(&bo, 0, sizeof bo);
    errno = 0;
    s = hfvis_mesh_load(a->in, NULL, &mesh);
    if (s != HFVIS_OK) return cli_status(a->in, s, errno);
    if (mesh.vertex_count == 0) {
        rc = cli_error(CLI_EXIT_ERROR, a->in, "the mesh has no vertices");
        goto done;
    }
    s = hfvis_visfield_bounding_sphere(&mesh, vf.center, &vf.radius);
    if (s != HFVIS_OK) { rc = cli_status("visfield", s, 0); goto done; }
    vf.positions_n = a->vf_positions ? a->vf_positions : 32; /* K = 4226 */
    vf.dir_res = a->has_dirs ? a->dirs : 32;
    vf.format = a->vf_format ? (hfvis_visfield_format)a->vf_format : HFVIS_VISFIELD_U8;
    vf.mapping = a->vf_mapping ? (hfvis_dirmap)a->vf_mapping : HFVIS_DIRMAP_CONCENTRIC;
    bytes = hfvis_visfield_size(vf.positions_n, vf.dir_res, vf.format);
    if (bytes == 0 || (uint64_t)bytes > HFVIS_VISFIELD_MAX_BYTES) {
        rc = cli_error(CLI_EXIT_ERROR, "visfield", "%s: %zu maps of %d x %d exceed the file limit of "
                       "4 GiB; use fewer --positions or --dirs", hfvis_status_string(HFVIS_ERR_LIMIT),
                       hfvis_visfield_position_count(vf.positions_n), vf.dir_res, vf.dir_res);
        goto done;
    }
    vf.maps = malloc(bytes);
    vf.maps_size = bytes;
    if (!vf.maps) { rc = cli_status("visfield", HFVIS_ERR_OUT_OF_MEMORY, 0); goto done; }
    prog.label = "visfield"; prog.base = 0; prog.total = 0;
    if (!a->quiet && cli_stderr_is_terminal()) {
        bo.progress = cli_progress;
        bo.progress_user = &prog;
    }
    s = hfvis_visfield_build(&mesh, &bo, &vf);
    if (s != HFVIS_OK) { rc = cli_status("visfield", s, 0); goto done; }
    errno = 0;
    s = hfvis_visfield_save(a->out, &vf);
    if (s != HFVIS_OK) { rc = cli_status(a->out, s, errno); goto done; }
    if (!a->quiet)
        printf("visfield: %zu triangles -> %zu maps of %d x %d (%s), sphere centre %.6g %.6g %.6g "
               "radius %.6g, %zu bytes\n", mesh.triangle_count,
               hfvis_visfield_position_count(vf.positions_n), vf.dir_res, vf.dir_res,
               fmt_names[vf.format], vf.center[0], vf.center[1], vf.center[2], vf.radius,
               hfvis_visfield_encode_size(&vf));
done:
    if (cli_bar_open) { fputc('\n', stderr); cli_bar_open = 0; }
    free(vf.maps);
    hfvis_mesh_free(NULL, &mesh);
    return rc;
}

/* visfield --ao FIELD: obscurance of a ground plane under the object (field or ray cast). */
static int cli_vf_ao(const cli_args *a)
{
    hfvis_visfield vf;
    hfvis_visfield_object ob;
    hfvis_visfield_ao_options o = hfvis_visfield_ao_options_default();
    hfvis_mesh mesh = {0};
    hfvis_bvh bvh;
    hfvis_status s;
    float *pts = NULL, *nrm = NULL, *ao = NULL;
    const int W = a->vf_has_size ? a->vg_width : 256, H = a->vf_has_size ? a->vg_height : 256;
    size_t n = (size_t)W * (size_t)H, p;
    double E, EY, Z;
    int rc = 0, x, y, i, have_bvh = 0;
    memset(&vf, 0, sizeof vf);
    memset(&bvh, 0, sizeof bvh);
    errno = 0;
    s = hfvis_visfield_load(a->in, NULL, &vf);
    if (s != HFVIS_OK) return cli_status(a->in, s, errno);
    E = a->vf_has_extent ? a->vf_extent : 1.5 * vf.radius;
    EY = E * (double)H / (double)W;
    Z = a->vf_has_ground ? a->vf_ground : vf.center[2] - vf.radius;
    pts = cli_alloc(n, 3, 1);
    nrm = cli_alloc(n, 3, 1);
    ao = cli_alloc(n, 1, 1);
    if (!pts || !nrm || !ao) { rc = cli_status("visfield", HFVIS_ERR_OUT_OF_MEMORY, 0); goto done; }
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++) { /* seen from above: x right, row 0 at +y */
            p = (size_t)y * (size_t)W + (size_t)x;
            pts[3 * p] = (float)(vf.center[0] - E + 2.0 * E * (x + 0.5) / W);
            pts[3 * p + 1] = (float)(vf.center[1] + EY - 2.0 * EY * (y + 0.5) / H);
            pts[3 * p + 2] = (float)Z;
            nrm[3 * p] = nrm[3 * p + 1] = 0.0f;
            nrm[3 * p + 2] = 1.0f;
        }
    ob.field = &vf;
    ob.mesh = NULL;
    ob.bvh = NULL;
    for (i = 0; i < 16; i++) ob.object_to_world[i] = (i % 5 == 0) ? 1.0 : 0.0;
    o.rays_sqrt = a->vf_rays ? a->vf_rays : 16;
    if (a->max_distance > 0.0) o.max_distance = a->max_distance;
    if (a->vf_has_bias) o.bias = a->vf_bias > 0.0 ? a->vf_bias : 1e-300; /* 0 means the default */
    if (a->vf_reference) {
        errno = 0;
        s = hfvis_mesh_load(a->vf_reference, NULL, &mesh);
        if (s != HFVIS_OK) { rc = cli_status(a->vf_reference, s, errno); goto done; }
        s = hfvis_bvh_build(&mesh, NULL, &bvh);
        if (s != HFVIS_OK) { rc = cli_status(a->vf_reference, s, 0); goto done; }
        have_bvh = 1;
        ob.mesh = &mesh;
        ob.bvh = &bvh;
        s = hfvis_visfield_ambient_occlusion_reference(&ob, 1, pts, nrm, n, &o, ao);
    } else {
        s = hfvis_visfield_ambient_occlusion(&ob, 1, pts, nrm, n, &o, ao);
    }
    if (s != HFVIS_OK) { rc = cli_status("visfield", s, 0); goto done; }
    rc = cli_save(a, ao, W, H, 1, 0.0, 1.0);
    if (rc == 0 && !a->quiet) {
        double mean = 0.0;
        for (p = 0; p < n; p++) mean += (double)ao[p];
        printf("visfield: %s obscurance of the plane z = %.6g over [%.6g, %.6g] x [%.6g, %.6g], "
               "%d x %d rays per pixel: mean %.4f\n", a->vf_reference ? "ray-cast" : "field", Z,
               vf.center[0] - E, vf.center[0] + E, vf.center[1] - EY, vf.center[1] + EY, o.rays_sqrt,
               o.rays_sqrt, mean / (double)n);
    }
done:
    if (have_bvh) hfvis_bvh_free(NULL, &bvh);
    hfvis_mesh_free(NULL, &mesh);
    free(pts);
    free(nrm);
    free(ao);
    hfvis_visfield_free(NULL, &vf);
    return rc;
}

static int cli_run_visfield(const cli_args *a)
{
    return a->vf_ao ? cli_vf_ao(a) : cli_vf_build(a);
}
