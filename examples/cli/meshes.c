/* meshes.c - the mesh commands: `meshao` (Laine & Karras), `visfield` ([G12] ch. 4), `volgi`
 * ([G12] ch. 5) and `voxelize`: their flags, checks and runs.
 * May call: progress.c, flags.c's primitives, write.c. */

/* meshao's defaults (called for every command; harmless for the others). */
static void cli_lk_defaults(cli_args *a)
{
    a->lk_method = HFVIS_LK_METHOD_BVH;
    a->lk_falloff = HFVIS_LK_FALLOFF_CONSTANT;
    a->lk_width = 512;
    a->lk_height = 384;
    a->lk_up[0] = 0.0; a->lk_up[1] = 0.0; a->lk_up[2] = 1.0;
}

/* "X,Y,Z" (--eye, --target, --up): three finite numbers; 0 or CLI_EXIT_USAGE (reported). */
static int cli_xyz(const char *f, const char *v, double out[3])
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

/* "WxH" (--size): sides 1..HFVIS_RASTER_MAX_SIZE, at most 2^26 pixels; 0 or CLI_EXIT_USAGE. */
static int cli_size(const char *f, const char *v, int *width, int *height)
{
    char *end;
    long w, h;
    errno = 0;
    w = strtol(v, &end, 10);
    if (end == v || !isdigit((unsigned char)v[0]) || (*end != 'x' && *end != 'X') || w < 1
        || w > HFVIS_RASTER_MAX_SIZE)
        return cli_error(CLI_EXIT_USAGE, f, "expected WxH, sides 1..%d, got '%s'",
                         HFVIS_RASTER_MAX_SIZE, v);
    h = strtol(end + 1, &end, 10);
    if (*end != '\0' || errno == ERANGE || h < 1 || h > HFVIS_RASTER_MAX_SIZE
        || (long long)w * h > 1LL << 26)
        return cli_error(CLI_EXIT_USAGE, f, "expected WxH, sides 1..%d, at most 2^26 pixels, got "
                         "'%s'", HFVIS_RASTER_MAX_SIZE, v);
    *width = (int)w, *height = (int)h;
    return 0;
}

/* The flags of `meshao` (called only for it, before the shared ones, because it gives --method,
 * --rays, --radius and the camera flags their own meaning); -1 if f is none of them. */
static int cli_set_lk(cli_args *a, const char *f, const char *v)
{
    if (!strcmp(f, "--method")) {
        if (!strcmp(v, "raster")) a->lk_method = HFVIS_LK_METHOD_RASTER;
        else if (!strcmp(v, "bvh")) a->lk_method = HFVIS_LK_METHOD_BVH;
        else if (!strcmp(v, "raycast")) a->lk_method = HFVIS_LK_METHOD_RAYCAST;
        else return cli_error(CLI_EXIT_USAGE, f, "expected raster, bvh or raycast, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--pattern")) {
        if (!strcmp(v, "torus")) a->lk_pattern = HFVIS_LK_PATTERN_LLOYD_TORUS;
        else if (!strcmp(v, "lloyd")) a->lk_pattern = HFVIS_LK_PATTERN_LLOYD;
        else if (!strcmp(v, "random")) a->lk_pattern = HFVIS_LK_PATTERN_RANDOM;
        else return cli_error(CLI_EXIT_USAGE, f, "expected torus, lloyd or random, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--falloff")) {
        if (!strcmp(v, "constant")) a->lk_falloff = HFVIS_LK_FALLOFF_CONSTANT;
        else if (!strcmp(v, "linear")) a->lk_falloff = HFVIS_LK_FALLOFF_LINEAR;
        else if (!strcmp(v, "quadratic")) a->lk_falloff = HFVIS_LK_FALLOFF_QUADRATIC;
        else return cli_error(CLI_EXIT_USAGE, f, "expected constant, linear or quadratic, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--eye")) { a->lk_has_eye = 1; return cli_xyz(f, v, a->lk_eye); }
    if (!strcmp(f, "--target")) { a->lk_has_target = 1; return cli_xyz(f, v, a->lk_target); }
    if (!strcmp(f, "--up")) { a->lk_has_up = 1; return cli_xyz(f, v, a->lk_up); }
    if (!strcmp(f, "--size")) return cli_size(f, v, &a->lk_width, &a->lk_height);
    if (!strcmp(f, "--two-sided")) { a->lk_two_sided = 1; return 0; }
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


/* -o and the flags only `visfield` has; -1 if f is none of them. */
static int cli_set_vf(cli_args *a, const char *f, const char *v)
{
    if (!strcmp(f, "-o")) { /* checked against the mode in cli_check_vf */
        a->out = v;
        a->out_pgm = cli_ends_with(v, ".pgm");
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
    if (!cli_ends_with(a->out, ".hfvf"))
        return cli_error(CLI_EXIT_USAGE, a->out, "unknown output type for a field (use a .hfvf name)");
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


static void cli_volgi_defaults(cli_args *a)
{
    a->vg_up[0] = 0.0, a->vg_up[1] = 0.0, a->vg_up[2] = 1.0;
    a->vg_width = 512, a->vg_height = 512;
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
            return cli_error(CLI_EXIT_USAGE, "--light", "intensity: finite values in 0..3.4e38 (float), got '%s'", v);
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
    if (!strcmp(f, "--light")) return cli_volgi_light(a, v);
    if (!strcmp(f, "--eye") || !strcmp(f, "--target") || !strcmp(f, "--up")) {
        if (f[2] == 'e') a->vg_has_eye = 1;
        if (f[2] == 't') a->vg_has_target = 1;
        return cli_xyz(f, v, f[2] == 'e' ? a->vg_eye : f[2] == 't' ? a->vg_target : a->vg_up);
    }
    if (!strcmp(f, "--size")) return cli_size(f, v, &a->vg_width, &a->vg_height);
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
    if (a->vg_up[0] == 0.0 && a->vg_up[1] == 0.0 && a->vg_up[2] == 0.0)
        return cli_error(CLI_EXIT_USAGE, "--up", "the up direction is zero");
    return 0;
}

/* Combinations `voxelize` rejects; returns 0 or CLI_EXIT_USAGE (message printed). */
static int cli_check_voxelize(const cli_args *a)
{
    const char *m = a->vox_mode == VOX_SOLID ? "solid" : "conservative";
    if (!a->res) return cli_error(CLI_EXIT_USAGE, "voxelize", "missing --res N");
    if (a->vox_mode != VOX_SURFACE && (a->vox_method != HFVIS_VOXELIZE_PIXEL_RULE || a->max_vertices))
        return cli_error(CLI_EXIT_USAGE, a->max_vertices ? "--max-vertices" : "--method",
                         "applies only to --mode surface, not %s", m);
    if (a->vox_mode == VOX_CONSERVATIVE && a->vox_axis != AXIS_DEFAULT)
        return cli_error(CLI_EXIT_USAGE, "--axis", "does not apply to --mode conservative");
    if (a->vox_mode == VOX_SOLID && (a->vox_axis == AXIS_DOMINANT || a->vox_axis == AXIS_ALL))
        return cli_error(CLI_EXIT_USAGE, "--axis", "--mode solid takes x, y or z");
    if (a->open_mesh && a->vox_mode != VOX_SOLID)
        return cli_error(CLI_EXIT_USAGE, "--open", "applies only to --mode solid");
    if (a->max_vertices && a->vox_method == HFVIS_VOXELIZE_PIXEL_RULE)
        return cli_error(CLI_EXIT_USAGE, "--max-vertices", "needs --method slicing or clipping");
    return 0;
}

/* voxelize: MESH.obj -> a cubic-voxel grid fitted to the mesh -> .binvox or .raw. */
static int cli_run_voxelize(const cli_args *a)
{
    hfvis_mesh mesh;
    hfvis_volume_grid grid;
    uint8_t *occ = NULL;
    size_t voxels, count = 0, i;
    hfvis_status s;
    int rc = 0;
    errno = 0;
    s = hfvis_mesh_load(a->in, NULL, &mesh);
    if (s != HFVIS_OK) return cli_status(a->in, s, errno);
    s = hfvis_volume_grid_fit(&mesh, a->res, a->padding, 1, &grid);
    if (s == HFVIS_ERR_INVALID_ARGUMENT && mesh.triangle_count == 0) {
        rc = cli_error(CLI_EXIT_ERROR, a->in, "the mesh has no triangles");
        goto done;
    }
    if (s != HFVIS_OK) { rc = cli_status("voxelize", s, 0); goto done; }
    voxels = (size_t)grid.dims[0] * (size_t)grid.dims[1] * (size_t)grid.dims[2];
    if (a->out_binvox) { /* binvox pads the grid to the cube of its largest side */
        size_t side = (size_t)(grid.dims[0] > grid.dims[1] ? grid.dims[0] : grid.dims[1]);
        side = side > (size_t)grid.dims[2] ? side : (size_t)grid.dims[2];
        if (side * side * side > HFVIS_VOLUME_MAX_VOXELS) {
            rc = cli_error(CLI_EXIT_ERROR, a->out, "%s: the .binvox cube of %zu^3 voxels (the grid is "
                           "%d x %d x %d) exceeds 2^31; write .raw or lower --res",
                           hfvis_status_string(HFVIS_ERR_LIMIT), side, grid.dims[0], grid.dims[1], grid.dims[2]);
            goto done;
        }
    }
    if (a->vox_mode == VOX_SURFACE) { /* one more layer on each axis: see below */
        size_t grown = (size_t)(grid.dims[0] + 1) * (size_t)(grid.dims[1] + 1) * (size_t)(grid.dims[2] + 1);
        if (grown > HFVIS_VOLUME_MAX_VOXELS) { rc = cli_status("voxelize", HFVIS_ERR_LIMIT, 0); goto done; }
        occ = (uint8_t *)malloc(grown);
    } else {
        occ = (uint8_t *)malloc(voxels);
    }
    if (!occ) { rc = cli_status("voxelize", HFVIS_ERR_OUT_OF_MEMORY, 0); goto done; }
    if (a->vox_mode == VOX_SURFACE) {
        /* The library's grid is half-open: a surface on its far side (the mesh's top with
         * --padding 0, where the grid ends: a cube's three far faces) has the depth dims[a], the
         * slab past the grid. The sweep runs on the grid grown by one layer on each axis (same
         * origin and cell, so the same fragments), and that layer is folded into the last one. */
        hfvis_volume_grid big = grid;
        const size_t n0 = (size_t)grid.dims[0], n1 = (size_t)grid.dims[1], n2 = (size_t)grid.dims[2];
        size_t ii, jj, kk;
        hfvis_voxelize_options o = hfvis_voxelize_options_default();
        static const hfvis_voxelize_axes axes[] = {HFVIS_AXES_DOMINANT, HFVIS_AXES_DOMINANT,
                                                   HFVIS_AXES_ALL, HFVIS_AXES_ONLY_X,
                                                   HFVIS_AXES_ONLY_Y, HFVIS_AXES_ONLY_Z};
        o.method = (hfvis_voxelize_method)a->vox_method;
        o.axes = axes[a->vox_axis];
        o.max_output_vertices = a->max_vertices;
        if (a->max_vertices && hfvis_gs_max_slices(a->max_vertices,
                                                   o.method == HFVIS_VOXELIZE_FRAGMENT_CLIPPING) == 0) {
            rc = cli_error(CLI_EXIT_USAGE, "--max-vertices", "%d vertices hold no slab (slicing "
                           "needs >= 7, clipping >= 3)", a->max_vertices);
            goto done;
        }
        big.dims[0]++, big.dims[1]++, big.dims[2]++;
        s = hfvis_voxelize_occupancy(&mesh, &big, &o, occ);
        /* in place: voxel (i, j, k) reads grown indices >= its own, never one written before */
        for (kk = 0; s == HFVIS_OK && kk < n2; kk++)
            for (jj = 0; jj < n1; jj++)
                for (ii = 0; ii < n0; ii++) {
                    size_t dk, dj, di;
                    uint8_t v = 0;
                    for (dk = 0; dk <= (size_t)(kk + 1 == n2); dk++)
                        for (dj = 0; dj <= (size_t)(jj + 1 == n1); dj++)
                            for (di = 0; di <= (size_t)(ii + 1 == n0); di++)
                                v |= occ[((kk + dk) * (n1 + 1) + jj + dj) * (n0 + 1) + ii + di];
                    occ[(kk * n1 + jj) * n0 + ii] = v;
                }
        for (i = 0; s == HFVIS_OK && i < voxels; i++) count += occ[i];
    } else {
        hfvis_binary_voxel_options o = hfvis_binary_voxel_options_default();
        if (a->vox_mode == VOX_CONSERVATIVE) {
            s = hfvis_voxelize_conservative(&mesh, &grid, &o, occ, &count);
        } else {
            o.axis = a->vox_axis == AXIS_X ? HFVIS_PARITY_AXIS_X
                     : a->vox_axis == AXIS_Y ? HFVIS_PARITY_AXIS_Y : HFVIS_PARITY_AXIS_Z;
            o.allow_open = a->open_mesh;
            s = hfvis_voxelize_solid(&mesh, &grid, &o, occ, &count);
            if (s == HFVIS_ERR_FORMAT) {
                rc = cli_error(CLI_EXIT_ERROR, a->in, "the mesh is not closed (a parity ray "
                               "crosses it an odd number of times); use --open or --mode surface");
                goto done;
            }
        }
    }
    if (s != HFVIS_OK) { rc = cli_status("voxelize", s, 0); goto done; }
    errno = 0;
    s = a->out_binvox ? cli_binvox_save(a->out, &grid, occ) : cli_voxels_raw_save(a->out, &grid, occ);
    if (s != HFVIS_OK) { rc = cli_status(a->out, s, errno); goto done; }
    if (!a->quiet)
        printf("voxelize: %zu triangles -> %d x %d x %d voxels of %.6g (origin %.6g %.6g %.6g), "
               "%zu set\n", mesh.triangle_count, grid.dims[0], grid.dims[1], grid.dims[2],
               grid.cell[0], grid.origin[0], grid.origin[1], grid.origin[2], count);
done:
    free(occ);
    hfvis_mesh_free(NULL, &mesh);
    return rc;
}


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
    ro.pattern = (hfvis_lk_pattern)a->lk_pattern; /* 0 = the library's default */
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
    if (a->stats) { /* before OUT: a failed print must not follow a replaced OUT */
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
        if (fflush(stdout) != 0 || ferror(stdout)) {
            rc = cli_error(CLI_EXIT_ERROR, "stdout", "%s (OUT not written)", strerror(errno));
            goto done;
        }
    }
    rc = cli_save(a, cli_output_of(out, a->lk_width, a->lk_height, 1, 1, 0.0, 1.0));
done:
    free(out);
    hfvis_lk_lut_free(NULL, &lut);
    hfvis_lk_rays_free(NULL, &rays);
    hfvis_mesh_free(NULL, &mesh);
    return rc;
}


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
    prog.label = "visfield"; prog.base = 0; prog.total = 0; prog.run = a->run;
    if (!a->quiet && cli_stderr_is_terminal()) {
        bo.progress = cli_progress;
        bo.progress_user = &prog;
    }
    s = hfvis_visfield_build(&mesh, &bo, &vf);
    if (s != HFVIS_OK) { rc = cli_status("visfield", s, 0); goto done; }
    errno = 0;
    s = cli_visfield_save(a->out, &vf);
    if (s != HFVIS_OK) { rc = cli_status(a->out, s, errno); goto done; }
    if (!a->quiet)
        printf("visfield: %zu triangles -> %zu maps of %d x %d (%s), sphere centre %.6g %.6g %.6g "
               "radius %.6g, %zu bytes\n", mesh.triangle_count,
               hfvis_visfield_position_count(vf.positions_n), vf.dir_res, vf.dir_res,
               fmt_names[vf.format], vf.center[0], vf.center[1], vf.center[2], vf.radius,
               hfvis_visfield_encode_size(&vf));
done:
    cli_progress_end(a->run, rc);
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
    rc = cli_save(a, cli_output_of(ao, W, H, 1, 1, 0.0, 1.0));
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
    rc = cli_save(a, cli_output_of(img, w, h, 1, 3, 0.0, cli_top(img, 3 * n, 1.0)));
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
