/* cli_volgi.c - the `volgi` subcommand of examples/hfvis_cli.c (issue 7: volume-based VPL indirect
 * light, [G12] ch. 5, hfvis_volgi_render).
 *
 * MERGE RECIPE (examples/hfvis_cli.c as of commit ad4e531; tested by applying it to a copy and
 * running the commands at the end and the cli_test.sh lines below):
 *  1. enum: add CMD_VOLGI before CMD_COUNT; cli_cmd_names: add "volgi" at the end.
 *  2. cli_usage, after the "voxelize" line (which ends the string: move its ';' to the new line):
 *       "  volgi       direct + indirect light of an OBJ mesh or the test room ([G12] ch. 5)\n"
 *  3. cli_cmd_help: append CLI_VOLGI_HELP (PART A) as the last entry.
 *  4. cli_args: add   int room, iterations, vg_nlights, vg_has_eye, vg_has_target, vg_width,
 *                         vg_height, vg_transfer, vg_paths, vg_reflection, vg_rho_albedo,
 *                         vg_has_rho;
 *                     double vg_eye[3], vg_target[3], vg_up[3], vg_fov, vg_rho;
 *                     hfvis_volgi_light vg_lights[CLI_VOLGI_MAX_LIGHTS];
 *     (paste PART A before the cli_args typedef: it defines CLI_VOLGI_MAX_LIGHTS.)
 *  5. cli_flags: "--res", "--albedo" and "--output" gain | CLI_ONLY(CMD_VOLGI); add the entries
 *     of CLI_VOLGI_FLAGS after CLI_GI_FLAGS.
 *  6. cli_set: before the block that calls cli_set_gi add
 *       { int r = cli_set_volgi(a, f, v); if (r >= 0) return r; }
 *  7. cli_parse: after the defaults line add   cli_volgi_defaults(a);
 *     replace  if (!a->in) return cli_error(...missing input file IN);  by
 *       if (!a->in && !(a->cmd == CMD_VOLGI && a->room))
 *           return cli_error(CLI_EXIT_USAGE, cli_cmd_names[a->cmd], "missing input file IN");
 *     and before "return CLI_RUN;" add   if (a->cmd == CMD_VOLGI && cli_check_volgi(a)) return CLI_EXIT_USAGE;
 *  8. cli_run: beside the voxelize hook add   if (a->cmd == CMD_VOLGI) return cli_run_volgi(a);
 *  9. Paste PART B (cli_volgi_defaults, cli_volgi_reals, cli_set_volgi, cli_check_volgi) after
 *     cli_check_gi (it needs cli_error, cli_parse_real, cli_int, cli_real), PART C (cli_run_volgi)
 *     after cli_run_voxelize (it needs cli_save, cli_top, cli_status).
 * 10. test/cli_test.sh: add "volgi" to the --help loop (line "for c in horizon ... gi") and the
 *     lines of PART D.
 *  Then e.g.:  hfvis volgi --room -o room.pfm
 *              hfvis volgi --room --res 64 --iterations 128 --paths void --transfer normalized \
 *                    --light spot:0.5,0.5,0.95:0,0,-1:50 --output indirect -o ind.pgm
 *              hfvis volgi teapot.obj --albedo 0.6 --light dir:-1,1,-2:3 -o teapot.pgm
 */

/* ---- PART A: before the cli_args typedef ---------------------------------------------------- */

#define CLI_VOLGI_MAX_LIGHTS 8

#define CLI_VOLGI_HELP                                                                              \
    "usage: hfvis volgi MESH.obj|--room -o OUT.pfm|OUT.pgm [--res N] [--iterations I]\n"           \
    "         [--light SPEC]... [--eye X,Y,Z] [--target X,Y,Z] [--up X,Y,Z] [--fov DEG]\n"          \
    "         [--size WxH] [--albedo A] [--output total|direct|indirect] [--transfer cone|normalized]\n" \
    "         [--paths all|void] [--reflection mirror|diffuse] [--reflectance R|albedo]\n"          \
    "Direct and indirect light of a triangle mesh with the volume-based VPL method of Gaitatzes\n" \
    "2012, ch. 5: the mesh is voxelized along x, y and z with its direct light (shadow rays), every\n" \
    "lit voxel becomes a virtual point light (a cosine lobe in 2-band spherical harmonics), the\n"  \
    "light is propagated I steps from voxel to voxel (reflected where it meets occupied voxels)\n"  \
    "and each pixel gathers it from the occupied voxels around its surface point. OUT holds RGB\n"  \
    "radiance toward the camera (Lambertian; a .pgm stacks R, G, B as planes top to bottom).\n"     \
    "  --room            the test room instead of MESH: the unit cube open at y = 0 with a red wall\n" \
    "                    at x = 0, a green wall at x = 1, two white boxes (albedo 0.75)\n"         \
    "  --res N           voxels along the longest side, 2..2048 (default 32, the thesis'); the\n"   \
    "                    outermost planes of the mesh lie on voxel centres\n"                     \
    "  --iterations I    propagation steps, 1..1048576 (default 64: 2 bounces on 32^3)\n"          \
    "  --light SPEC      up to 8 lights (default: one point light, see below), SPEC one of\n"       \
    "                      point:X,Y,Z[:I]            radiant intensity I (W/sr)\n"                 \
    "                      spot:X,Y,Z:DX,DY,DZ:OUTER[,INNER][:I]  cone half-angles in degrees\n"    \
    "                                                  (INNER default 0.8 OUTER)\n"                \
    "                      dir:DX,DY,DZ[:E]           travelling along D, irradiance E\n"           \
    "                    I and E: one value (grey) or R,G,B; default 1 for the room; for a mesh\n" \
    "                    the default light sits above and in front of it, at about 2 sizes\n"      \
    "  --eye, --target   camera position and aim (default: in front of the open side of the room;\n" \
    "                    for a mesh: 2.2 sizes in front (-y) and a little above its centre)\n"     \
    "  --up X,Y,Z        camera up direction (default 0,0,1)\n"                                   \
    "  --fov DEG         vertical field of view, 1..179 (default 40)\n"                           \
    "  --size WxH        image size (default 512x512)\n"                                          \
    "  --albedo A        grey albedo of MESH, 0..1 (default 0.75; not with --room)\n"             \
    "  --output WHAT     total: direct + indirect (default); direct: the direct light with\n"   \
    "                    shadows (shadow rays); indirect: the propagated light only\n"           \
    "  --transfer T      cone: the thesis kernel, clamped 45-degree cone fluxes (default);\n"     \
    "                    normalized: the same proportions, nothing lost between the cones\n"       \
    "  --paths P         all: every face neighbour exchanges light (default, the spec kernel);\n"  \
    "                    void: no light between two occupied voxels (\"only in void space\")\n"   \
    "  --reflection R    mirror: on the dominant axis of the voxel normal (default, the thesis);\n" \
    "                    diffuse: re-emitted as a cosine lobe about the normal\n"                  \
    "  --reflectance R   reflectance of occupied voxels during the propagation, 0..1 (default\n"   \
    "                    0.5, the thesis), or 'albedo' for the voxels' own colour\n"               \
    "Prints the grid, the voxel counts and the light budget unless --quiet. Default PGM range\n"   \
    "0:the largest output value. Only -o, --range and --quiet of the shared options apply.\n"

#define CLI_VOLGI_FLAGS                                                                      \
    { "--room", 0, CLI_ONLY(CMD_VOLGI) }, { "--iterations", 1, CLI_ONLY(CMD_VOLGI) },        \
    { "--light", 1, CLI_ONLY(CMD_VOLGI) }, { "--eye", 1, CLI_ONLY(CMD_VOLGI) },              \
    { "--target", 1, CLI_ONLY(CMD_VOLGI) }, { "--up", 1, CLI_ONLY(CMD_VOLGI) },              \
    { "--fov", 1, CLI_ONLY(CMD_VOLGI) }, { "--size", 1, CLI_ONLY(CMD_VOLGI) },               \
    { "--transfer", 1, CLI_ONLY(CMD_VOLGI) }, { "--paths", 1, CLI_ONLY(CMD_VOLGI) },         \
    { "--reflection", 1, CLI_ONLY(CMD_VOLGI) }, { "--reflectance", 1, CLI_ONLY(CMD_VOLGI) }

/* ---- PART B: after cli_check_gi ------------------------------------------------------------- */

static void cli_volgi_defaults(cli_args *a)
{
    a->vg_up[0] = 0.0, a->vg_up[1] = 0.0, a->vg_up[2] = 1.0;
    a->vg_fov = 40.0;
    a->vg_width = 512, a->vg_height = 512;
    a->iterations = HFVIS_VOLGI_DEFAULT_ITERATIONS;
}

/* Parse "r1,r2,...": between min and max finite reals (s[0..len)); returns the count or -1. */
static int cli_volgi_reals(const char *s, size_t len, double *out, int min, int max)
{
    char buf[256];
    const char *p;
    int n = 0;
    if (len >= sizeof buf) return -1;
    memcpy(buf, s, len);
    buf[len] = '\0';
    p = buf;
    for (;;) {
        char *comma = strchr(p, ',');
        if (n == max) return -1;
        if (comma) *comma = '\0';
        if (!cli_parse_real(p, &out[n])) return -1;
        n++;
        if (!comma) break;
        p = comma + 1;
    }
    return n >= min ? n : -1;
}

/* --light SPEC (see CLI_VOLGI_HELP); returns 0 or CLI_EXIT_USAGE. */
static int cli_volgi_light(cli_args *a, const char *v)
{
    static const char *const kinds[3] = { "point:", "spot:", "dir:" };
    const char *bad = "expected point:X,Y,Z[:I], spot:X,Y,Z:DX,DY,DZ:OUTER[,INNER][:I] or "
                      "dir:DX,DY,DZ[:E], got '%s'";
    hfvis_volgi_light L;
    const char *p, *parts[4];
    size_t lens[4];
    double vals[3];
    int kind, np = 0, need, c, n;
    memset(&L, 0, sizeof L);
    if (a->vg_nlights == CLI_VOLGI_MAX_LIGHTS)
        return cli_error(CLI_EXIT_USAGE, "--light", "at most %d lights", CLI_VOLGI_MAX_LIGHTS);
    for (kind = 0; kind < 3 && strncmp(v, kinds[kind], strlen(kinds[kind])); kind++) {}
    if (kind == 3) return cli_error(CLI_EXIT_USAGE, "--light", bad, v);
    p = v + strlen(kinds[kind]);
    while (np < 4) { /* split at ':' */
        const char *colon = strchr(p, ':');
        parts[np] = p;
        lens[np] = colon ? (size_t)(colon - p) : strlen(p);
        np++;
        if (!colon) break;
        p = colon + 1;
        if (np == 4) return cli_error(CLI_EXIT_USAGE, "--light", bad, v);
    }
    need = kind == 1 ? 3 : 1; /* parts before the optional intensity */
    if (np != need && np != need + 1) return cli_error(CLI_EXIT_USAGE, "--light", bad, v);
    L.type = kind == 0 ? HFVIS_VOLGI_LIGHT_POINT : kind == 1 ? HFVIS_VOLGI_LIGHT_SPOT
                                                           : HFVIS_VOLGI_LIGHT_DIRECTIONAL;
    if (cli_volgi_reals(parts[0], lens[0], kind == 2 ? L.direction : L.position, 3, 3) != 3)
        return cli_error(CLI_EXIT_USAGE, "--light", bad, v);
    if (kind == 1) {
        double ang[2];
        if (cli_volgi_reals(parts[1], lens[1], L.direction, 3, 3) != 3)
            return cli_error(CLI_EXIT_USAGE, "--light", bad, v);
        n = cli_volgi_reals(parts[2], lens[2], ang, 1, 2);
        if (n < 0 || !(ang[0] > 0.0 && ang[0] <= 180.0) || (n == 2 && !(ang[1] >= 0.0 && ang[1] <= ang[0])))
            return cli_error(CLI_EXIT_USAGE, "--light", "spot angles: OUTER in (0, 180], 0 <= INNER <= "
                             "OUTER degrees, got '%s'", v);
        L.spot_outer_rad = ang[0] * (CLI_PI / 180.0);
        L.spot_inner_rad = (n == 2 ? ang[1] : 0.8 * ang[0]) * (CLI_PI / 180.0);
    }
    if ((kind == 1 || kind == 2) && L.direction[0] == 0.0 && L.direction[1] == 0.0 && L.direction[2] == 0.0)
        return cli_error(CLI_EXIT_USAGE, "--light", "the direction must not be 0,0,0, got '%s'", v);
    vals[0] = vals[1] = vals[2] = 1.0;
    if (np == need + 1) {
        n = cli_volgi_reals(parts[need], lens[need], vals, 1, 3);
        if (n == 2 || n < 0) return cli_error(CLI_EXIT_USAGE, "--light", "intensity: one value or R,G,B, got '%s'", v);
        if (n == 1) vals[1] = vals[2] = vals[0];
    }
    for (c = 0; c < 3; c++) {
        if (!(vals[c] >= 0.0 && vals[c] <= CLI_FLT_MAX))
            return cli_error(CLI_EXIT_USAGE, "--light", "intensity must be >= 0, got '%s'", v);
        L.intensity[c] = (float)vals[c];
    }
    for (c = 0; c < 3; c++)
        if (fabs(L.position[c]) > 1e30)
            return cli_error(CLI_EXIT_USAGE, "--light", "position beyond 1e30, got '%s'", v);
    a->vg_lights[a->vg_nlights++] = L;
    return 0;
}

/* The flags only `volgi` has; -1 if f is none of them. */
static int cli_set_volgi(cli_args *a, const char *f, const char *v)
{
    if (!strcmp(f, "--room")) { a->room = 1; return 0; }
    if (!strcmp(f, "--iterations"))
        return cli_int(f, v, 1, HFVIS_VOLGI_MAX_ITERATIONS, "an integer 1..1048576", &a->iterations);
    if (!strcmp(f, "--light")) return cli_volgi_light(a, v);
    if (!strcmp(f, "--eye") || !strcmp(f, "--target") || !strcmp(f, "--up")) {
        double *dst = f[2] == 'e' ? a->vg_eye : f[2] == 't' ? a->vg_target : a->vg_up;
        if (cli_volgi_reals(v, strlen(v), dst, 3, 3) != 3 || fabs(dst[0]) > 1e30 || fabs(dst[1]) > 1e30
            || fabs(dst[2]) > 1e30)
            return cli_error(CLI_EXIT_USAGE, f, "expected X,Y,Z (finite, below 1e30), got '%s'", v);
        if (f[2] == 'e') a->vg_has_eye = 1;
        if (f[2] == 't') a->vg_has_target = 1;
        return 0;
    }
    if (!strcmp(f, "--fov")) return cli_real(f, v, 1.0, 0, 179.0, "degrees in 1..179", &a->vg_fov);
    if (!strcmp(f, "--size")) {
        char *end;
        long w, h;
        errno = 0;
        w = strtol(v, &end, 10);
        if (end == v || (*end != 'x' && *end != 'X') || w < 1 || w > HFVIS_RASTER_MAX_SIZE)
            return cli_error(CLI_EXIT_USAGE, f, "expected WxH, sides 1..%d, got '%s'", HFVIS_RASTER_MAX_SIZE, v);
        h = strtol(end + 1, &end, 10);
        if (*end != '\0' || errno == ERANGE || h < 1 || h > HFVIS_RASTER_MAX_SIZE || (long long)w * h > 1LL << 26)
            return cli_error(CLI_EXIT_USAGE, f, "expected WxH, sides 1..%d, at most 2^26 pixels, got '%s'",
                             HFVIS_RASTER_MAX_SIZE, v);
        a->vg_width = (int)w, a->vg_height = (int)h;
        return 0;
    }
    if (!strcmp(f, "--transfer")) {
        if (!strcmp(v, "cone")) a->vg_transfer = HFVIS_VOLGI_TRANSFER_CONE;
        else if (!strcmp(v, "normalized")) a->vg_transfer = HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED;
        else return cli_error(CLI_EXIT_USAGE, f, "expected cone or normalized, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--paths")) {
        if (!strcmp(v, "all")) a->vg_paths = HFVIS_VOLGI_PATHS_ALL;
        else if (!strcmp(v, "void")) a->vg_paths = HFVIS_VOLGI_PATHS_VOID;
        else return cli_error(CLI_EXIT_USAGE, f, "expected all or void, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--reflection")) {
        if (!strcmp(v, "mirror")) a->vg_reflection = HFVIS_VOLGI_REFLECT_MIRROR;
        else if (!strcmp(v, "diffuse")) a->vg_reflection = HFVIS_VOLGI_REFLECT_DIFFUSE;
        else return cli_error(CLI_EXIT_USAGE, f, "expected mirror or diffuse, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--reflectance")) {
        a->vg_has_rho = 1;
        if (!strcmp(v, "albedo")) { a->vg_rho_albedo = 1; return 0; }
        a->vg_rho_albedo = 0;
        return cli_real(f, v, 0.0, 0, 1.0, "a reflectance in 0..1 or 'albedo'", &a->vg_rho);
    }
    return -1;
}

/* Combinations `volgi` rejects; returns 0 or CLI_EXIT_USAGE (message printed). */
static int cli_check_volgi(const cli_args *a)
{
    if (a->room && a->in) return cli_error(CLI_EXIT_USAGE, a->in, "--room renders the test room: no MESH");
    if (a->room && a->has_albedo)
        return cli_error(CLI_EXIT_USAGE, "--albedo", "applies to a MESH (the room has its own colours)");
    if (a->has_albedo && a->albedo > 1.0)
        return cli_error(CLI_EXIT_USAGE, "--albedo", "expected an albedo in 0..1, got %g", a->albedo);
    if (a->res == 1) return cli_error(CLI_EXIT_USAGE, "--res", "volgi needs at least 2 voxels");
    return 0;
}

/* ---- PART C: after cli_run_voxelize ---------------------------------------------------------- */

/* volgi: MESH.obj or the room -> hfvis_volgi_render -> the chosen RGB plane as PFM or PGM. */
static int cli_run_volgi(const cli_args *a)
{
    const char *cmd = "volgi";
    const int w = a->vg_width, h = a->vg_height;
    const size_t n = (size_t)w * (size_t)h;
    hfvis_mesh mesh;
    hfvis_volgi_scene sc;
    hfvis_volgi_light def;
    hfvis_volgi_options o = hfvis_volgi_options_default();
    hfvis_volgi_outputs out;
    hfvis_volgi_render_info info;
    hfvis_view view;
    double lo[3], hi[3], c[3], e = 0.0, eye[3], target[3], d;
    float *albedo = NULL, *img = NULL;
    hfvis_status s;
    size_t t;
    int k, rc = 0;

    memset(&mesh, 0, sizeof mesh);
    errno = 0;
    s = a->room ? hfvis_mesh_room(NULL, &mesh) : hfvis_mesh_load(a->in, NULL, &mesh);
    if (s != HFVIS_OK) return cli_status(a->room ? cmd : a->in, s, errno);
    if (mesh.triangle_count == 0 || hfvis_mesh_bounds(&mesh, lo, hi) != HFVIS_OK) {
        rc = cli_error(CLI_EXIT_ERROR, a->in, "the mesh has no triangles");
        goto done;
    }
    for (k = 0; k < 3; k++) {
        c[k] = 0.5 * (lo[k] + hi[k]);
        if (hi[k] - lo[k] > e) e = hi[k] - lo[k];
    }
    if (!(e > 0.0)) { rc = cli_error(CLI_EXIT_ERROR, a->in, "the mesh has no extent"); goto done; }
    albedo = cli_alloc(mesh.triangle_count, 3, 1);
    img = cli_alloc(n, 3, 1);
    if (!albedo || !img) { rc = cli_status(cmd, HFVIS_ERR_OUT_OF_MEMORY, 0); goto done; }
    for (t = 0; t < mesh.triangle_count; t++) { /* room: walls 0-1 red (x = 0), 2-3 green (x = 1) */
        float grey = a->has_albedo ? (float)a->albedo : 0.75f;
        albedo[3 * t] = a->room && t >= 2 && t < 4 ? 0.15f : grey;
        albedo[3 * t + 1] = a->room && t < 2 ? 0.15f : grey;
        albedo[3 * t + 2] = a->room && t < 4 ? 0.15f : grey;
    }
    /* camera and default light */
    memset(&def, 0, sizeof def);
    def.type = HFVIS_VOLGI_LIGHT_POINT;
    if (a->room) {
        eye[0] = 0.5, eye[1] = -1.1, eye[2] = 0.5, target[0] = 0.5, target[1] = 0.5, target[2] = 0.45;
        def.position[0] = 0.5, def.position[1] = 0.45, def.position[2] = 0.9;
        def.intensity[0] = def.intensity[1] = def.intensity[2] = 1.0f;
    } else {
        eye[0] = c[0], eye[1] = c[1] - 2.2 * e, eye[2] = c[2] + 0.6 * e;
        target[0] = c[0], target[1] = c[1], target[2] = c[2];
        def.position[0] = c[0] + 0.6 * e, def.position[1] = c[1] - 1.2 * e, def.position[2] = c[2] + 1.5 * e;
        def.intensity[0] = def.intensity[1] = def.intensity[2] = (float)(4.0 * e * e);
    }
    for (k = 0; k < 3; k++) {
        if (a->vg_has_eye) eye[k] = a->vg_eye[k];
        if (a->vg_has_target) target[k] = a->vg_target[k];
    }
    d = sqrt((eye[0] - target[0]) * (eye[0] - target[0]) + (eye[1] - target[1]) * (eye[1] - target[1])
             + (eye[2] - target[2]) * (eye[2] - target[2]));
    s = hfvis_view_perspective(&view, eye, target, a->vg_up, a->vg_fov * (CLI_PI / 180.0), w, h,
                               1e-3 * (d + e), 100.0 * (d + e));
    if (s != HFVIS_OK) {
        rc = cli_error(CLI_EXIT_USAGE, "--eye", "camera: eye and target must differ and the view "
                       "direction must not be parallel to --up");
        goto done;
    }
    memset(&sc, 0, sizeof sc);
    sc.mesh = &mesh;
    sc.albedo = albedo;
    sc.lights = a->vg_nlights ? a->vg_lights : &def;
    sc.light_count = a->vg_nlights ? a->vg_nlights : 1;
    o.resolution = a->res ? a->res : HFVIS_VOLGI_DEFAULT_RESOLUTION;
    o.iterations = a->iterations;
    o.transfer = (hfvis_volgi_transfer)a->vg_transfer;
    o.paths = (hfvis_volgi_paths)a->vg_paths;
    o.reflection = (hfvis_volgi_reflection)a->vg_reflection;
    if (a->vg_has_rho) {
        o.reflectance_source = a->vg_rho_albedo ? HFVIS_VOLGI_REFLECTANCE_ALBEDO : HFVIS_VOLGI_REFLECTANCE_CONSTANT;
        o.reflectance = (float)a->vg_rho;
    }
    memset(&out, 0, sizeof out);
    if (a->output == OUT_DIRECT) out.direct = img;
    else if (a->output == OUT_INDIRECT) out.indirect = img;
    else out.total = img;
    s = hfvis_volgi_render(&sc, NULL, &view, &o, &out, &info);
    if (s == HFVIS_ERR_LIMIT) {
        rc = cli_error(CLI_EXIT_ERROR, "--res", "%s: the grid would exceed 2^31 voxels", hfvis_status_string(s));
        goto done;
    }
    if (s != HFVIS_OK) { rc = cli_status(cmd, s, 0); goto done; }
    rc = cli_save(a, img, w, h, 3, 0.0, cli_top(img, 3 * n, 1.0));
    if (rc == 0 && !a->quiet)
        printf("volgi: %zu triangles, %d x %d x %d voxels of %.6g, %zu occupied (%zu fragments), %d "
               "iterations; VPL flux %.6g, recorded at surfaces %.6g, still travelling %.6g (red band); "
               "%zu of %zu pixels covered\n", mesh.triangle_count, info.grid.dims[0], info.grid.dims[1],
               info.grid.dims[2], info.grid.cell[0], info.occupied, info.fragments, a->iterations,
               info.injected[0], info.deposited[0], info.remaining[0], info.covered_pixels, n);
done:
    free(img);
    free(albedo);
    hfvis_mesh_free(NULL, &mesh);
    return rc;
}

/* ---- PART D: test/cli_test.sh --------------------------------------------------------------
 * D1, after the line  expect_ok "voxelize solid --axis x --open" ...  ($dir/cube.obj exists):
 *
 * # volgi: the room and a mesh with two lights render; every output choice and option parses.
 * expect_ok "volgi room" "$dir/vg.pfm" volgi --room --res 16 --iterations 16 --size 32x24 -o "$dir/vg.pfm"
 * grep -q '16 x 16 x 16 voxels' "$dir/stdout" && ok "volgi room grid" || bad "volgi room: $(cat "$dir/stdout")"
 * expect_ok "volgi room indirect, void paths, pgm" "$dir/vgi.pgm" volgi --room --res 16 --iterations 24 --paths void --transfer normalized --reflectance albedo --reflection diffuse --output indirect --size 32x24 -o "$dir/vgi.pgm"
 * expect_ok "volgi mesh, two lights, camera" "$dir/vgc.pfm" volgi "$dir/cube.obj" --res 8 --iterations 8 --albedo 0.5 --light point:2,-3,4:10 --light spot:0.5,0.5,3:0,0,-1:40,20:1,0.5,0.25 --eye 3,-4,2 --target 0.5,0.5,0.5 --fov 30 --size 16x16 --output direct -o "$dir/vgc.pfm"
 *
 * D2, after the line  expect_fail "voxelize --max-vertices with the pixel rule" ...  ($o is set):
 *
 * expect_fail "volgi without MESH or --room" 2 volgi -o "$o"
 * expect_fail "volgi --room with MESH" 2 volgi "$dir/cube.obj" --room -o "$o"
 * expect_fail "volgi --light bogus" 2 volgi --room --light lamp:1,2,3 -o "$o"
 * expect_fail "volgi --light spot without angle" 2 volgi --room --light spot:0,0,1:0,0,-1 -o "$o"
 * expect_fail "volgi --light dir 0,0,0" 2 volgi --room --light dir:0,0,0 -o "$o"
 * expect_fail "volgi --res 1" 2 volgi --room --res 1 -o "$o"
 * expect_fail "volgi --albedo with --room" 2 volgi --room --albedo 0.5 -o "$o"
 * expect_fail "volgi --size 0x4" 2 volgi --room --size 0x4 -o "$o"
 * expect_fail "volgi --reflectance 2" 2 volgi --room --reflectance 2 -o "$o"
 * expect_fail "volgi eye = target" 2 volgi --room --eye 0.5,0.5,0.5 --target 0.5,0.5,0.5 -o "$o"
 * expect_fail "volgi missing mesh file" 1 volgi "$dir/nope.obj" -o "$o"
 */
