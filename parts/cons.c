/* ========================================================================================== */
/* 5. Binary voxelizers: conservative (triangle-box SAT), solid (parity), bitmask; .binvox/raw */
/*    (spec voxel §3.9 baselines: T. Akenine-Moller, "Fast 3D triangle-box overlap testing",   */
/*    JGT 2001 - the 13-axis separating-axis test; M. Schwarz & H.-P. Seidel, "Fast parallel   */
/*    surface and solid voxelization on GPUs", SIGGRAPH Asia 2010 - its per-triangle setup;   */
/*    solid voxelization by parity / XOR, Chen & Fang 1998, Eisemann & Decoret 2008;          */
/*    E. Eisemann & X. Decoret, "Fast scene voxelization and applications", I3D 2006 - the    */
/*    bitmask ("slicemap") layout; the binvox format of P. Min / M. Kazhdan)                  */
/* ========================================================================================== */
/* Contents
 *   5a. grid space, ranges and the SAT predicate (hfvis_triangle_box_overlap)
 *   5b. conservative voxelization: per-voxel SAT reference and the column-interval fast path
 *   5c. exact 2D orientation signs and the watertight pixel-centre coverage rule
 *   5d. solid voxelization by parity (fast: toggles + prefix XOR; reference: winding number)
 *   5e. watertightness of the index structure
 *   5f. bitmask voxelization (three-axis OR, slicemap layout)
 *   5g. .binvox codec and the raw writer
 *
 * Everything is decided in GRID SPACE: a vertex p becomes g = (p - origin) / cell (per axis, in
 * double), so voxel (i, j, k) is the unit cube [i, i+1] x [j, j+1] x [k, k+1] and its centre is
 * (i + 0.5, j + 0.5, k + 0.5). */

/* ---- 5a. grid space, ranges and the SAT predicate --------------------------------------- */

/* Grid coordinates beyond this magnitude (in cells) make the products of the predicates below
 * lose their guarantees (overflow of the exact 2D orientation, int conversions): such meshes
 * are refused with HFVIS_ERR_LIMIT. 2^60 cells is far outside any grid. */
#define VX_CONS_MAX_COORD 1152921504606846976.0 /* 2^60 */

/* Grid-space coordinate of world coordinate x on axis a. The ONE expression every binary
 * voxelizer and its reference uses, so they see the same doubles. */
static double vx_cons_gc(const hfvis_volume_grid *g, int a, float x)
{
    return ((double)x - g->origin[a]) / g->cell[a];
}

/* Grid-space vertex vi of a mesh. */
static void vx_cons_gvert(const hfvis_mesh *m, const hfvis_volume_grid *g, uint32_t vi,
                          double out[3])
{
    const float *p = m->xyz + 3 * (size_t)vi;
    out[0] = vx_cons_gc(g, 0, p[0]);
    out[1] = vx_cons_gc(g, 1, p[1]);
    out[2] = vx_cons_gc(g, 2, p[2]);
}

/* Checks the common arguments of the binary voxelizers; HFVIS_ERR_LIMIT when a vertex lies
 * beyond VX_CONS_MAX_COORD cells. */
static hfvis_status vx_cons_args(const hfvis_mesh *mesh, const hfvis_volume_grid *grid,
                                 const void *out)
{
    size_t v;
    int a;
    if (!out || !vx_grid_valid(grid) || vx_mesh_check(mesh) != HFVIS_OK)
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (v = 0; v < mesh->vertex_count; v++)
        for (a = 0; a < 3; a++) {
            double c = vx_cons_gc(grid, a, mesh->xyz[3 * v + (size_t)a]);
            if (!(fabs(c) <= VX_CONS_MAX_COORD)) return HFVIS_ERR_LIMIT;
        }
    return HFVIS_OK;
}

/* Voxel range [*lo, *hi] along one axis of the voxels whose CLOSED extent [i, i+1] meets the
 * closed interval [mn, mx] (grid units), clipped to [0, n-1]: i from ceil(mn) - 1 to floor(mx).
 * Returns 0 when it is empty. mn, mx are within +-VX_CONS_MAX_COORD. */
static int vx_cons_range(double mn, double mx, int n, int *lo, int *hi)
{
    double l = ceil(mn) - 1.0, h = floor(mx);
    if (l < 0.0) l = 0.0;
    if (h > (double)(n - 1)) h = (double)(n - 1);
    if (l > h) return 0;
    *lo = (int)l;
    *hi = (int)h;
    return 1;
}

static double vx_cons_min3(double a, double b, double c)
{
    double m = a < b ? a : b;
    return m < c ? m : c;
}

static double vx_cons_max3(double a, double b, double c)
{
    double m = a > b ? a : b;
    return m > c ? m : c;
}

/* The triangle normal n = f0 x f1 with f0 = v1 - v0, f1 = v2 - v1 (the ONE formula both the
 * SAT and the fast path use). */
static void vx_cons_normal(const double f0[3], const double f1[3], double n[3])
{
    n[0] = f0[1] * f1[2] - f0[2] * f1[1];
    n[1] = f0[2] * f1[0] - f0[0] * f1[2];
    n[2] = f0[0] * f1[1] - f0[1] * f1[0];
}

/* One edge axis L = e_a x f_j of the SAT, in the projection along box axis a with in-plane axes
 * u = a+1, w = a+2 (mod 3): L_u = -f_w, L_w = f_u. The triangle projects to p = L_u t_u + L_w t_w
 * of its vertices t (relative to the box centre); only two vertices are needed, the start of
 * edge j (the end projects to the same value in exact arithmetic) and the opposite vertex. The
 * box projects to [-r, r], r = h_u |L_u| + h_w |L_w|. Returns 1 when the axis SEPARATES.
 * Every caller evaluates exactly these expressions in this order (see 5b). */
static int vx_cons_sep2(double Lu, double Lw, double r, double su, double sw, double ou,
                        double ow)
{
    double p = Lu * su + Lw * sw, q = Lu * ou + Lw * ow;
    double mn = p < q ? p : q, mx = p < q ? q : p;
    return mn > r || mx < -r;
}

/* Plane axis: d = n . t0 evaluated ((n_x t_x + n_y t_y) + n_z t_z), radius
 * r = (h_x |n_x| + h_y |n_y|) + h_z |n_z| with the same association. Returns 1 when it
 * separates. */
static int vx_cons_sep_plane(const double n[3], double r, const double t0[3])
{
    double d = n[0] * t0[0] + n[1] * t0[1] + n[2] * t0[2];
    return d > r || d < -r;
}

static double vx_cons_plane_radius(const double n[3], const double h[3])
{
    return h[0] * fabs(n[0]) + h[1] * fabs(n[1]) + h[2] * fabs(n[2]);
}

/* One edge axis of the SAT as a statement: returns 0 from the enclosing function when axis
 * (Lu, Lw) with radius r separates vertex offsets (su, sw) and (ou, ow) (vx_cons_sep2). */
#define VX_CONS_AXIS(Lu, Lw, hu, hw, su, sw, ou, ow)                                         \
    do {                                                                                     \
        double r_ = (hu) * fabs(Lu) + (hw) * fabs(Lw);                                       \
        if (vx_cons_sep2((Lu), (Lw), r_, (su), (sw), (ou), (ow))) return 0;                  \
    } while (0)

HFVIS_API int hfvis_triangle_box_overlap(const double center[3], const double half[3],
                                         const double v0[3], const double v1[3],
                                         const double v2[3])
{
    /* t_k = v_k - center; f_j from the untranslated vertices, so they do not depend on the box */
    const double t0x = v0[0] - center[0], t0y = v0[1] - center[1], t0z = v0[2] - center[2];
    const double t1x = v1[0] - center[0], t1y = v1[1] - center[1], t1z = v1[2] - center[2];
    const double t2x = v2[0] - center[0], t2y = v2[1] - center[1], t2z = v2[2] - center[2];
    const double hx = half[0], hy = half[1], hz = half[2];
    double f0[3], f1[3], f2[3], n[3], t0[3];
    f0[0] = v1[0] - v0[0];
    f0[1] = v1[1] - v0[1];
    f0[2] = v1[2] - v0[2];
    f1[0] = v2[0] - v1[0];
    f1[1] = v2[1] - v1[1];
    f1[2] = v2[2] - v1[2];
    f2[0] = v0[0] - v2[0];
    f2[1] = v0[1] - v2[1];
    f2[2] = v0[2] - v2[2];
    /* axes 5-13, e_a x f_j with (u, w) = (a+1, a+2): L_u = -f_j[w], L_w = f_j[u]; vertices:
     * the start of edge j and the opposite vertex j+2 (vx_cons_sep2). As Akenine-Moller, these
     * nine first: they separate most often. */
    VX_CONS_AXIS(-f0[2], f0[1], hy, hz, t0y, t0z, t2y, t2z); /* e_x x f0 */
    VX_CONS_AXIS(-f1[2], f1[1], hy, hz, t1y, t1z, t0y, t0z); /* e_x x f1 */
    VX_CONS_AXIS(-f2[2], f2[1], hy, hz, t2y, t2z, t1y, t1z); /* e_x x f2 */
    VX_CONS_AXIS(-f0[0], f0[2], hz, hx, t0z, t0x, t2z, t2x); /* e_y x f0 */
    VX_CONS_AXIS(-f1[0], f1[2], hz, hx, t1z, t1x, t0z, t0x); /* e_y x f1 */
    VX_CONS_AXIS(-f2[0], f2[2], hz, hx, t2z, t2x, t1z, t1x); /* e_y x f2 */
    VX_CONS_AXIS(-f0[1], f0[0], hx, hy, t0x, t0y, t2x, t2y); /* e_z x f0 */
    VX_CONS_AXIS(-f1[1], f1[0], hx, hy, t1x, t1y, t0x, t0y); /* e_z x f1 */
    VX_CONS_AXIS(-f2[1], f2[0], hx, hy, t2x, t2y, t1x, t1y); /* e_z x f2 */
    /* axes 1-3: the box normals (the triangle's bounding box against the box) */
    if (vx_cons_min3(t0x, t1x, t2x) > hx || vx_cons_max3(t0x, t1x, t2x) < -hx) return 0;
    if (vx_cons_min3(t0y, t1y, t2y) > hy || vx_cons_max3(t0y, t1y, t2y) < -hy) return 0;
    if (vx_cons_min3(t0z, t1z, t2z) > hz || vx_cons_max3(t0z, t1z, t2z) < -hz) return 0;
    /* axis 4: the triangle normal */
    vx_cons_normal(f0, f1, n);
    t0[0] = t0x;
    t0[1] = t0y;
    t0[2] = t0z;
    return !vx_cons_sep_plane(n, vx_cons_plane_radius(n, half), t0);
}
#undef VX_CONS_AXIS

/* ---- 5b. conservative voxelization --------------------------------------------------------- */

HFVIS_API hfvis_binary_voxel_options hfvis_binary_voxel_options_default(void)
{
    hfvis_binary_voxel_options o;
    memset(&o, 0, sizeof o);
    o.alloc = NULL;
    o.axis = HFVIS_PARITY_AXIS_Z;
    o.allow_open = 0;
    return o;
}

/* Argument checks and output clearing shared by the conservative voxelizers. */
static hfvis_status vx_cons_begin(const hfvis_mesh *mesh, const hfvis_volume_grid *grid,
                                  uint8_t *occ)
{
    hfvis_status s = vx_cons_args(mesh, grid, occ);
    if (s != HFVIS_OK) return s;
    memset(occ, 0, vx_grid_voxels(grid));
    return HFVIS_OK;
}

/* Voxel ranges of the triangle's bounding box (vx_cons_range on each axis); 0 when empty. */
static int vx_cons_bbox(const double *v0, const double *v1, const double *v2,
                        const hfvis_volume_grid *grid, int lo[3], int hi[3])
{
    int a;
    for (a = 0; a < 3; a++)
        if (!vx_cons_range(vx_cons_min3(v0[a], v1[a], v2[a]), vx_cons_max3(v0[a], v1[a], v2[a]),
                           grid->dims[a], &lo[a], &hi[a]))
            return 0;
    return 1;
}

/* 1 when the grid-space triangle has a zero normal (computed as vx_cons_normal): such triangles
 * are never voxelized (hfvis_mesh). */
static int vx_cons_degenerate(const double *v0, const double *v1, const double *v2)
{
    double f0[3], f1[3], n[3];
    int a;
    for (a = 0; a < 3; a++) {
        f0[a] = v1[a] - v0[a];
        f1[a] = v2[a] - v1[a];
    }
    vx_cons_normal(f0, f1, n);
    return n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0;
}

HFVIS_API hfvis_status hfvis_voxelize_conservative_reference(const hfvis_mesh *mesh,
                                                             const hfvis_volume_grid *grid,
                                                             const hfvis_binary_voxel_options *opts,
                                                             uint8_t *occ, size_t *count)
{
    static const double half[3] = {0.5, 0.5, 0.5};
    size_t t, n = 0, nx, nxy;
    hfvis_status s;
    (void)opts;
    s = vx_cons_begin(mesh, grid, occ);
    if (s != HFVIS_OK) return s;
    nx = (size_t)grid->dims[0];
    nxy = nx * (size_t)grid->dims[1];
    for (t = 0; t < mesh->triangle_count; t++) {
        double v[3][3], c[3];
        int lo[3], hi[3], i, j, k;
        for (k = 0; k < 3; k++) vx_cons_gvert(mesh, grid, mesh->indices[3 * t + (size_t)k], v[k]);
        if (vx_cons_degenerate(v[0], v[1], v[2]) || !vx_cons_bbox(v[0], v[1], v[2], grid, lo, hi))
            continue;
        for (k = lo[2]; k <= hi[2]; k++) {
            c[2] = (double)k + 0.5;
            for (j = lo[1]; j <= hi[1]; j++) {
                c[1] = (double)j + 0.5;
                for (i = lo[0]; i <= hi[0]; i++) {
                    uint8_t *o = occ + (size_t)k * nxy + (size_t)j * nx + (size_t)i;
                    c[0] = (double)i + 0.5;
                    if (hfvis_triangle_box_overlap(c, half, v[0], v[1], v[2]) && !*o) {
                        *o = 1;
                        n++;
                    }
                }
            }
        }
    }
    if (count) *count = n;
    return HFVIS_OK;
}

/* Per-triangle setup of the fast path (Schwarz & Seidel 2010, §3.1: the triangle's normal,
 * plane radius ("critical point" offset) and the nine 2D edge axes with their radii, computed
 * once per triangle with exactly the expressions of hfvis_triangle_box_overlap, h = 0.5). */
typedef struct vx_cons_tri {
    double v[3][3];    /* grid-space vertices */
    double n[3], rn;   /* normal f0 x f1 and its radius sum h|n_a| */
    double L[3][3][2]; /* [a][j]: edge axis e_a x f_j as (L_u, L_w) */
    double r[3][3];    /* [a][j]: its radius */
    int D, U, W;       /* dominant axis argmax |n_a| (ties to the lower axis); U = D+1, W = D+2 */
} vx_cons_tri;

static const double vx_cons_half[3] = {0.5, 0.5, 0.5};

/* Returns 0 for a degenerate triangle (zero normal). */
static int vx_cons_setup(vx_cons_tri *T)
{
    double f[3][3];
    int a, j;
    for (a = 0; a < 3; a++) {
        f[0][a] = T->v[1][a] - T->v[0][a];
        f[1][a] = T->v[2][a] - T->v[1][a];
        f[2][a] = T->v[0][a] - T->v[2][a];
    }
    vx_cons_normal(f[0], f[1], T->n);
    if (T->n[0] == 0.0 && T->n[1] == 0.0 && T->n[2] == 0.0) return 0;
    T->rn = vx_cons_plane_radius(T->n, vx_cons_half);
    for (a = 0; a < 3; a++) {
        int u = a == 2 ? 0 : a + 1, w = a == 0 ? 2 : a - 1;
        for (j = 0; j < 3; j++) {
            double Lu = -f[j][w], Lw = f[j][u];
            T->L[a][j][0] = Lu;
            T->L[a][j][1] = Lw;
            T->r[a][j] = vx_cons_half[u] * fabs(Lu) + vx_cons_half[w] * fabs(Lw);
        }
    }
    T->D = 0;
    if (fabs(T->n[1]) > fabs(T->n[T->D])) T->D = 1;
    if (fabs(T->n[2]) > fabs(T->n[T->D])) T->D = 2;
    T->U = T->D == 2 ? 0 : T->D + 1;
    T->W = T->D == 0 ? 2 : T->D - 1;
    return 1;
}

/* The three edge axes of projection a (in-plane axes u, w) at a voxel whose vertex offsets are
 * t[k][.]: exactly the expressions of hfvis_triangle_box_overlap. 1 when one separates. */
static int vx_cons_sep_proj(const vx_cons_tri *T, int a, int u, int w, double t[3][3])
{
    return vx_cons_sep2(T->L[a][0][0], T->L[a][0][1], T->r[a][0], t[0][u], t[0][w], t[2][u], t[2][w])
        || vx_cons_sep2(T->L[a][1][0], T->L[a][1][1], T->r[a][1], t[1][u], t[1][w], t[0][u], t[0][w])
        || vx_cons_sep2(T->L[a][2][0], T->L[a][2][1], T->r[a][2], t[2][u], t[2][w], t[1][u], t[1][w]);
}

/* The SAT of layer k of a column whose offsets t[.][U], t[.][W] are set and whose dominant
 * projection's axes (and, inside the bounding-box range, the box axes) do not separate: the plane
 * axis and the six edge axes of the two other projections, with the SAT's expressions.
 * Returns 1 when none separates, i.e. hfvis_triangle_box_overlap would return 1. */
static int vx_cons_layer_ok(const vx_cons_tri *T, double t[3][3], int k)
{
    int D = T->D, U = T->U, W = T->W;
    double c = (double)k + 0.5;
    t[0][D] = T->v[0][D] - c;
    t[1][D] = T->v[1][D] - c;
    t[2][D] = T->v[2][D] - c;
    return !vx_cons_sep_plane(T->n, T->rn, t[0]) && !vx_cons_sep_proj(T, U, W, D, t)
        && !vx_cons_sep_proj(T, W, D, U, t);
}

/* ceil(x) clamped to [lo, hi + 1] (hi + 1 = "empty"), floor(x) clamped to [lo - 1, hi]; x may be
 * any double but NaN (lo >= 0). */
static int vx_cons_ceil_in(double x, int lo, int hi)
{
    int i;
    if (!(x > (double)lo - 1.0)) return lo;
    if (x > (double)hi) return hi + 1;
    i = (int)x; /* x > -1: truncation, then up when x had a fraction */
    return i + ((double)i < x);
}

static int vx_cons_floor_in(double x, int lo, int hi)
{
    if (!(x < (double)hi + 1.0)) return hi;
    if (x < (double)lo) return lo - 1;
    return (int)x; /* x >= lo >= 0 */
}

/* The fast path's scratch occupancy: bits in 4x4x4 bricks, one uint64 per brick (brick
 * (bx, by, bz) at (bz*nb[1] + by)*nb[0] + bx, voxel bit (z&3)*16 + (y&3)*4 + (x&3)), so the few
 * voxels one triangle touches share a handful of words in cache; the byte output is written
 * from it at the end. */
typedef struct vx_cons_bricks {
    uint64_t *w;
    size_t nb[3];  /* bricks per axis */
    size_t bs[3];  /* brick stride per axis: 1, nb[0], nb[0]*nb[1] */
} vx_cons_bricks;

static size_t vx_cons_brick_of(const vx_cons_bricks *B, const int p[3], unsigned *bit)
{
    *bit = (unsigned)(((p[2] & 3) << 4) | ((p[1] & 3) << 2) | (p[0] & 3));
    return (size_t)(p[0] >> 2) * B->bs[0] + (size_t)(p[1] >> 2) * B->bs[1]
           + (size_t)(p[2] >> 2) * B->bs[2];
}

/* Voxelizes one set-up triangle whose bounding-box voxel ranges are lo..hi into the bricks;
 * returns the number of voxels newly set. The decisions are those of
 * hfvis_triangle_box_overlap on every voxel of the range, bit for bit, reached without calling
 * it on most voxels:
 *  - a voxel already set needs no decision (the result is a union);
 *  - per column (iU, iW) of the dominant projection D, the plane slab's layers come from the
 *    plane equation, k in kc -+ rn/|n_D| with kc linear in (iU, iW) (Schwarz & Seidel's plane
 *    test solved for the column). Layers farther than EPS outside that interval fail the SAT's
 *    plane axis for certain: EPS (2^-30 of the coordinate scale, in layers) is far above the
 *    rounding of both the SAT's expression and this estimate (about 2^-46 of the scale), so
 *    these "candidates" contain every voxel the SAT accepts;
 *  - when every candidate voxel of a column is already set the column is done; otherwise the
 *    column's three 2D axes of projection D are tested once (the SAT's expressions), and the
 *    plane + six remaining axes are tested from the two ends of the candidate interval inward
 *    (skipping set voxels) until a voxel passes: every axis value is monotone along the column
 *    in floating point (each rounding is monotone), so the layers that pass the SAT form an
 *    interval and every unset voxel between the lowest and highest passing one passes.
 * A bounding box of one voxel: the triangle lies in the voxel's closed cube, every offset
 * |t| <= h, and then no axis of the SAT can separate (|fl(L.t)| <= fl(h |L|) term by term, since
 * rounding is monotone and the radii are summed in the same order), so the voxel is set. */
static size_t vx_cons_fast_tri(vx_cons_tri *T, const int lo[3], const int hi[3],
                               vx_cons_bricks *B)
{
    const int D = T->D, U = T->U, W = T->W;
    const unsigned sh = D == 0 ? 0u : (D == 1 ? 2u : 4u);
    const size_t sD = B->bs[D];
    double t[3][3], aU, aW, K0, hwid, eps, scale;
    size_t n = 0;
    int iU, iW, k, a, p[3];
    if (lo[0] == hi[0] && lo[1] == hi[1] && lo[2] == hi[2]) {
        unsigned bit;
        uint64_t *w = B->w + vx_cons_brick_of(B, lo, &bit), m = (uint64_t)1 << bit;
        n = (*w & m) == 0;
        *w |= m;
        return n;
    }
    /* the plane slab per column: kc(iU, iW) = K0 - aU iU - aW iW, half width rn/|n_D| */
    aU = T->n[U] / T->n[D];
    aW = T->n[W] / T->n[D];
    K0 = T->v[0][D] - 0.5
         + (T->n[U] * (T->v[0][U] - 0.5) + T->n[W] * (T->v[0][W] - 0.5)) / T->n[D];
    hwid = T->rn / fabs(T->n[D]);
    scale = 4.0;
    for (a = 0; a < 3; a++) {
        double m = vx_cons_max3(fabs(T->v[0][a]), fabs(T->v[1][a]), fabs(T->v[2][a]));
        scale += m + (double)hi[a];
    }
    eps = scale * 9.313225746154785e-10; /* 2^-30 */
    for (iW = lo[W]; iW <= hi[W]; iW++) {
        double cW = (double)iW + 0.5, krow = K0 - aW * (double)iW;
        t[0][W] = T->v[0][W] - cW;
        t[1][W] = T->v[1][W] - cW;
        t[2][W] = T->v[2][W] - cW;
        p[W] = iW;
        for (iU = lo[U]; iU <= hi[U]; iU++) {
            double kc = krow - aU * (double)iU, cU;
            int ka = vx_cons_ceil_in(kc - hwid - eps, lo[D], hi[D]);
            int kb = vx_cons_floor_in(kc + hwid + eps, lo[D], hi[D]);
            int k1, k2;
            size_t base;
            unsigned bU;
            if (ka > kb) continue;
            /* bits of the column's voxels: word base + (k >> 2)*sD, bit bU | (k & 3) << sh */
            p[U] = iU;
            p[D] = 0;
            base = vx_cons_brick_of(B, p, &bU);
#define VX_CONS_WORD(kk) B->w[base + (size_t)((kk) >> 2) * sD]
#define VX_CONS_MASK(kk) ((uint64_t)1 << (bU | ((unsigned)((kk) & 3) << sh)))
            while (ka <= kb && (VX_CONS_WORD(ka) & VX_CONS_MASK(ka))) ka++;
            if (ka > kb) continue; /* every candidate already set */
            while (VX_CONS_WORD(kb) & VX_CONS_MASK(kb)) kb--;
            cU = (double)iU + 0.5;
            t[0][U] = T->v[0][U] - cU;
            t[1][U] = T->v[1][U] - cU;
            t[2][U] = T->v[2][U] - cU;
            if (vx_cons_sep_proj(T, D, U, W, t)) continue;
            /* lowest and highest unset layers that pass */
            for (k1 = ka; k1 <= kb; k1++)
                if (!(VX_CONS_WORD(k1) & VX_CONS_MASK(k1)) && vx_cons_layer_ok(T, t, k1)) break;
            if (k1 > kb) continue;
            for (k2 = kb; k2 > k1; k2--)
                if (!(VX_CONS_WORD(k2) & VX_CONS_MASK(k2)) && vx_cons_layer_ok(T, t, k2)) break;
            for (k = k1; k <= k2; k++) {
                uint64_t m = VX_CONS_MASK(k);
                n += !(VX_CONS_WORD(k) & m);
                VX_CONS_WORD(k) |= m;
            }
#undef VX_CONS_WORD
#undef VX_CONS_MASK
        }
    }
    return n;
}

/* Allocates the brick scratch (zeroed) for a valid grid; NULL on failure. */
static uint64_t *vx_cons_bricks_init(vx_cons_bricks *B, const hfvis_volume_grid *grid,
                                     const hfvis_allocator *alloc)
{
    size_t words;
    int a;
    for (a = 0; a < 3; a++) B->nb[a] = ((size_t)grid->dims[a] + 3) / 4;
    B->bs[0] = 1;
    B->bs[1] = B->nb[0];
    B->bs[2] = B->nb[0] * B->nb[1];
    words = B->bs[2] * B->nb[2]; /* about voxels / 64: no overflow for a valid grid */
    B->w = (uint64_t *)vx_alloc_array(alloc, words, sizeof(uint64_t));
    if (B->w) memset(B->w, 0, words * sizeof(uint64_t));
    return B->w;
}

/* Index of the lowest set bit of m != 0. */
static unsigned vx_cons_ctz64(uint64_t m)
{
    unsigned b = 0;
    if (!(m & 0xffffffffu)) { m >>= 32; b += 32; }
    if (!(m & 0xffffu)) { m >>= 16; b += 16; }
    if (!(m & 0xffu)) { m >>= 8; b += 8; }
    if (!(m & 0xfu)) { m >>= 4; b += 4; }
    if (!(m & 0x3u)) { m >>= 2; b += 2; }
    return b + (unsigned)!(m & 1u);
}

/* Clears occ and sets the voxels of the bricks' set bits; returns their number. */
static size_t vx_cons_bricks_emit(const vx_cons_bricks *B, const hfvis_volume_grid *grid,
                                  uint8_t *occ)
{
    size_t nx = (size_t)grid->dims[0], nxy = nx * (size_t)grid->dims[1], n = 0, b0, b1, b2;
    const uint64_t *w = B->w;
    memset(occ, 0, vx_grid_voxels(grid));
    for (b2 = 0; b2 < B->nb[2]; b2++)
        for (b1 = 0; b1 < B->nb[1]; b1++)
            for (b0 = 0; b0 < B->nb[0]; b0++) {
                uint64_t m = *w++;
                while (m) {
                    unsigned bit = vx_cons_ctz64(m);
                    m &= m - 1;
                    occ[(b2 * 4 + (bit >> 4)) * nxy + (b1 * 4 + ((bit >> 2) & 3u)) * nx + b0 * 4
                        + (bit & 3u)] = 1;
                    n++;
                }
            }
    return n;
}

HFVIS_API hfvis_status hfvis_voxelize_conservative(const hfvis_mesh *mesh,
                                                   const hfvis_volume_grid *grid,
                                                   const hfvis_binary_voxel_options *opts,
                                                   uint8_t *occ, size_t *count)
{
    const hfvis_allocator *alloc = opts ? opts->alloc : NULL;
    size_t t, v, n;
    double *gv;
    vx_cons_bricks B;
    hfvis_status s = vx_cons_args(mesh, grid, occ);
    if (s != HFVIS_OK) return s;
    /* scratch: every vertex in grid space (transformed once), and the brick bits */
    gv = (double *)vx_alloc_array(alloc, mesh->vertex_count, 3 * sizeof(double));
    if (!gv && mesh->vertex_count) return HFVIS_ERR_OUT_OF_MEMORY;
    if (!vx_cons_bricks_init(&B, grid, alloc)) {
        vx_free(alloc, gv);
        return HFVIS_ERR_OUT_OF_MEMORY;
    }
    for (v = 0; v < mesh->vertex_count; v++) vx_cons_gvert(mesh, grid, (uint32_t)v, gv + 3 * v);
    for (t = 0; t < mesh->triangle_count; t++) {
        vx_cons_tri T;
        int lo[3], hi[3], a, k;
        for (k = 0; k < 3; k++)
            for (a = 0; a < 3; a++)
                T.v[k][a] = gv[3 * (size_t)mesh->indices[3 * t + (size_t)k] + (size_t)a];
        if (!vx_cons_bbox(T.v[0], T.v[1], T.v[2], grid, lo, hi)) continue;
        if (!vx_cons_setup(&T)) continue;
        vx_cons_fast_tri(&T, lo, hi, &B);
    }
    n = vx_cons_bricks_emit(&B, grid, occ);
    vx_free(alloc, B.w);
    vx_free(alloc, gv);
    if (count) *count = n;
    return HFVIS_OK;
}
