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
 *   5b. conservative voxelization: per-voxel SAT reference and the certified-bounds fast path
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

#ifndef VX_CONS_SMALL_BOX
#define VX_CONS_SMALL_BOX 16 /* bounding boxes of at most this many voxels: direct SAT */
#endif

/* C99 inline for the few hot helpers of the fast path (no effect on results). */
#define VX_CONS_INLINE inline

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
 * any double but NaN (lo >= 0). Branch-free: clamp in double, truncate, correct. */
static VX_CONS_INLINE int vx_cons_ceil_in(double x, int lo, int hi)
{
    double l = (double)lo - 1.0, h = (double)hi + 1.0;
    int i;
    x = x > l ? x : l;
    x = x < h ? x : h;
    i = (int)x; /* x >= -1: truncation, then up when x had a fraction */
    i += (double)i < x;
    return i < lo ? lo : i;
}

static VX_CONS_INLINE int vx_cons_floor_in(double x, int lo, int hi)
{
    double l = (double)lo - 1.0, h = (double)hi + 1.0;
    int i;
    x = x > l ? x : l;
    x = x < h ? x : h;
    i = (int)x;
    i -= (double)i > x; /* truncation of x in (-1, 0) gives 0 */
    return i > hi ? hi : i;
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

static VX_CONS_INLINE size_t vx_cons_brick_of(const vx_cons_bricks *B, const int p[3], unsigned *bit)
{
    *bit = (unsigned)(((p[2] & 3) << 4) | ((p[1] & 3) << 2) | (p[0] & 3));
    return (size_t)(p[0] >> 2) * B->bs[0] + (size_t)(p[1] >> 2) * B->bs[1]
           + (size_t)(p[2] >> 2) * B->bs[2];
}

/* 1 when every vertex lies in the closed cube of voxel p (a one-voxel range can also come from
 * clipping a larger triangle at the grid's border). */
static int vx_cons_inside_voxel(const vx_cons_tri *T, const int p[3])
{
    int k, a;
    for (k = 0; k < 3; k++)
        for (a = 0; a < 3; a++)
            if (!(T->v[k][a] >= (double)p[a] && T->v[k][a] <= (double)p[a] + 1.0)) return 0;
    return 1;
}

/* vx_cons_bbox, exactly, without libm calls: on each axis lo = max(0, ceil(min) - 1),
 * hi = min(n - 1, floor(max)); the coordinates are clamped first (which keeps the result) so
 * the int conversions are exact. */
static VX_CONS_INLINE int vx_cons_bbox_fast(const vx_cons_tri *T, const hfvis_volume_grid *grid,
                                            int lo[3], int hi[3])
{
    int a;
    for (a = 0; a < 3; a++) {
        double mn = vx_cons_min3(T->v[0][a], T->v[1][a], T->v[2][a]);
        double mx = vx_cons_max3(T->v[0][a], T->v[1][a], T->v[2][a]);
        double top = (double)grid->dims[a] + 1.0;
        int i;
        mn = mn > -1.0 ? mn : -1.0;
        mn = mn < top ? mn : top;
        mx = mx > -1.0 ? mx : -1.0;
        mx = mx < top ? mx : top;
        i = (int)mn; /* truncation; ceil */
        i += (double)i < mn;
        lo[a] = i - 1 > 0 ? i - 1 : 0;
        i = (int)mx; /* floor (mx >= -1) */
        i -= (double)i > mx;
        hi[a] = i < grid->dims[a] - 1 ? i : grid->dims[a] - 1;
        if (lo[a] > hi[a]) return 0;
    }
    return 1;
}

/* One SAT edge axis as a bound on a linear form of two voxel-centre coordinates x, y: in exact
 * arithmetic the axis does not separate iff lo <= A x + B y <= hi (the SAT's p = Q - L.c of the
 * axis' two vertices, Q = L.v: lo = min Q - r, hi = max Q + r, r = (|A| + |B|)/2). With A != 0
 * that is x in [x1(y), x2(y)], x1,2 = c1,2 - m y (c = lo/A, hi/A in order, m = B/A), kept as
 * four linear forms c[i] - m y: the candidates (the interval widened by the margin dk = dl/|A|)
 * and the certain range (narrowed by dk); dl = eps (|A| + |B|) is the margin in value units.
 * A == 0 (the axis does not depend on x): lo, hi, dl are kept to test y. */
typedef struct vx_cons_bound {
    double c[4], m;
    double B, lo, hi, dl; /* A == 0 only */
    int flat;             /* A == 0 */
} vx_cons_bound;

/* The bound of axis (A, B) whose two vertices have coordinates (xj, yj), (xo, yo). */
static VX_CONS_INLINE void vx_cons_bound_init(vx_cons_bound *b, double A, double B, double xj,
                                              double yj, double xo, double yo, double eps)
{
    double qa = A * xj + B * yj, qb = A * xo + B * yo, r = 0.5 * (fabs(A) + fabs(B));
    double lo = (qa < qb ? qa : qb) - r, hi = (qa < qb ? qb : qa) + r, dl = 2.0 * eps * r;
    b->flat = A == 0.0;
    if (!b->flat) {
        double inv = 1.0 / A, dk = dl * fabs(inv), c1 = lo * inv, c2 = hi * inv;
        if (inv < 0.0) {
            double tmp = c1;
            c1 = c2;
            c2 = tmp;
        }
        b->m = B * inv;
        b->c[0] = c1 - dk;
        b->c[1] = c2 + dk;
        b->c[2] = c1 + dk;
        b->c[3] = c2 - dk;
    } else {
        b->B = B;
        b->lo = lo;
        b->hi = hi;
        b->dl = dl;
    }
}

/* Narrows r = {candidate lo, candidate hi, certain lo, certain hi} of x, given y, by one bound:
 * x inside the certain range passes the SAT's axis for certain, x outside the candidate range
 * fails it for certain. A flat bound: the whole line certainly fails (candidates emptied),
 * certainly passes, or is undecided (certain range emptied). */
static VX_CONS_INLINE void vx_cons_bound_apply(const vx_cons_bound *b, double y, double r[4])
{
    if (!b->flat) {
        double my = b->m * y, x;
        x = b->c[0] - my;
        r[0] = r[0] > x ? r[0] : x;
        x = b->c[1] - my;
        r[1] = r[1] < x ? r[1] : x;
        x = b->c[2] - my;
        r[2] = r[2] > x ? r[2] : x;
        x = b->c[3] - my;
        r[3] = r[3] < x ? r[3] : x;
    } else {
        double rem = b->B * y;
        if (rem < b->lo - b->dl || rem > b->hi + b->dl) r[0] = HUGE_VAL;
        else if (!(rem >= b->lo + b->dl && rem <= b->hi - b->dl)) r[2] = HUGE_VAL;
    }
}

/* Bits of layers l0..l1 (0..3) of one column inside a brick, for layer strides 1, 4, 16 bits
 * (dominant axis x, y, z), before the shift by the column's bit. */
static const uint64_t vx_cons_layer_masks[3][4][4] = {
    {{0x1, 0x3, 0x7, 0xf}, {0, 0x2, 0x6, 0xe}, {0, 0, 0x4, 0xc}, {0, 0, 0, 0x8}},
    {{0x1, 0x11, 0x111, 0x1111}, {0, 0x10, 0x110, 0x1110}, {0, 0, 0x100, 0x1100}, {0, 0, 0, 0x1000}},
    {{0x1, 0x10001, 0x100010001ull, 0x1000100010001ull},
     {0, 0x10000, 0x100010000ull, 0x1000100010000ull},
     {0, 0, 0x100000000ull, 0x1000100000000ull},
     {0, 0, 0, 0x1000000000000ull}}};

/* Voxelizes one triangle (grid-space vertices T->v, normal n != 0 with dominant axis D, U = D+1,
 * W = D+2; bounding-box voxel ranges lo..hi) into the bricks. The result is, bit for bit, the
 * set of voxels of the range on which hfvis_triangle_box_overlap returns 1, found without
 * calling it on most voxels (Schwarz & Seidel 2010's per-triangle decomposition, made exact):
 *  - the work is done in the frame (x, y, z) = (U, W, D), a cyclic permutation, in which the
 *    SAT's axes keep their form: the edge axes of projection a are e_a x f_j with in-plane axes
 *    (a+1, a+2). Each edge axis is a two-sided bound on two centre coordinates (vx_cons_bound):
 *    the three axes of projection z bound the columns x of each row y; the three of projection x
 *    bound the layers z of each row y; the three of projection y bound the layers z of each
 *    column index x; the plane axis bounds the layers of each column (x, y) to
 *    |kc - z| <= rn/|n_z| with kc linear in (x, y) (Schwarz & Seidel's plane test solved for
 *    the column); the box axes always pass inside the bounding-box range (|t| <= h there, also
 *    in floating point). So the voxels of a column form an interval computed from these bounds;
 *  - the bounds are evaluated in double with a margin eps = 2^-30 of the coordinate scale
 *    (times |A| + |B| of the axis, or in layers for the plane): the rounding of the SAT's own
 *    expressions and of these bounds is about 2^-50 of that, so a voxel inside every bound by
 *    its margin passes every axis of the SAT for certain, and one outside a bound by its margin
 *    fails it for certain. Voxels within a margin of an end (exact ties such as faces on voxel
 *    boundaries, or 1e-9-close calls) are decided with the SAT's own expressions in the
 *    original frame (vx_cons_sep_proj, vx_cons_layer_ok; set up lazily), which makes the
 *    result identical to the reference;
 *  - a voxel already set needs no decision (the result is a union): a column whose plane
 *    candidates are all set is skipped before the other projections' bounds are even set up
 *    (they are set up once per triangle, when first needed); a bounding box of at most
 *    VX_CONS_SMALL_BOX voxels is decided by calling the SAT on its voxels not yet set;
 *  - a triangle inside one voxel's closed cube (not merely clipped to one): every offset
 *    |t| <= h, and then no axis of the SAT can separate (|fl(L.t)| <= fl(h |L|) term by term,
 *    since rounding is monotone and the radii are summed in the same order): the voxel is set.
 * Returns the number of columns decided with the SAT's expressions (a statistic). */
static size_t vx_cons_fast_tri(vx_cons_tri *T, const int lo[3], const int hi[3],
                               vx_cons_bricks *B)
{
    const int D = T->D, U = T->U, W = T->W;
    const int x0 = lo[U], x1 = hi[U], y0 = lo[W], y1 = hi[W], z0 = lo[D], z1 = hi[D];
    const unsigned sh = D == 0 ? 0u : (D == 1 ? 2u : 4u);
    const size_t sD = B->bs[D], sU = B->bs[U], sW = B->bs[W];
    double P[3][3], f[3][3], nx, ny, nz, ax, ay, K0, hwid, eps, scale, t[3][3];
    vx_cons_bound bz[3], bx[3], by[3];
    size_t slow = 0;
    int ix, iy, k, j, have_sat = 0, have_xy = 0;
    if (x0 == x1 && y0 == y1 && z0 == z1 && vx_cons_inside_voxel(T, lo)) {
        unsigned bit;
        size_t wi = vx_cons_brick_of(B, lo, &bit); /* sequenced before bit is read */
        B->w[wi] |= (uint64_t)1 << bit;
        return 0;
    }
    if ((x1 - x0 + 1) * (y1 - y0 + 1) * (z1 - z0 + 1) <= VX_CONS_SMALL_BOX) {
        /* a small box: the SAT itself on the voxels not yet set (the result is a union) */
        int q[3];
        for (q[2] = lo[2]; q[2] <= hi[2]; q[2]++)
            for (q[1] = lo[1]; q[1] <= hi[1]; q[1]++)
                for (q[0] = lo[0]; q[0] <= hi[0]; q[0]++) {
                    unsigned bit;
                    uint64_t *w, m;
                    double c[3];
                    w = B->w + vx_cons_brick_of(B, q, &bit);
                    m = (uint64_t)1 << bit;
                    if (*w & m) continue;
                    c[0] = (double)q[0] + 0.5;
                    c[1] = (double)q[1] + 0.5;
                    c[2] = (double)q[2] + 0.5;
                    if (hfvis_triangle_box_overlap(c, vx_cons_half, T->v[0], T->v[1], T->v[2])) *w |= m;
                }
        return 0;
    }
    for (k = 0; k < 3; k++) {
        P[k][0] = T->v[k][U];
        P[k][1] = T->v[k][W];
        P[k][2] = T->v[k][D];
    }
    for (j = 0; j < 3; j++) {
        const int e = j == 2 ? 0 : j + 1;
        f[j][0] = P[e][0] - P[j][0];
        f[j][1] = P[e][1] - P[j][1];
        f[j][2] = P[e][2] - P[j][2];
    }
    nx = T->n[U];
    ny = T->n[W];
    nz = T->n[D];
    /* the plane slab per column: kc(x, y) = K0 - ax x - ay y (layer of the centre), |ax|, |ay|
     * <= 1, half width rn/|n_z| <= 1.5 */
    ax = nx / nz;
    ay = ny / nz;
    K0 = P[0][2] - 0.5 + (nx * (P[0][0] - 0.5) + ny * (P[0][1] - 0.5)) / nz;
    hwid = 0.5 * (fabs(nx) + fabs(ny) + fabs(nz)) / fabs(nz);
    scale = 4.0 + (double)(x1 + y1 + z1);
    for (k = 0; k < 3; k++) scale += fabs(P[k][0]) + fabs(P[k][1]) + fabs(P[k][2]);
    eps = scale * 9.313225746154785e-10; /* 2^-30 */
    /* the nine edge axes: projection z (x = cx, y = cy), x (x = cz, y = cy), y (x = cz,
     * y = cx); vertex pairs (j, o) = (0, 2), (1, 0), (2, 1). Projections x and y are only set
     * up when some candidate voxel is not set yet. */
    for (j = 0; j < 3; j++) {
        const int o = j == 0 ? 2 : j - 1;
        vx_cons_bound_init(&bz[j], -f[j][1], f[j][0], P[j][0], P[j][1], P[o][0], P[o][1], eps);
    }
    for (iy = y0; iy <= y1; iy++) {
        double cy = (double)iy + 0.5, krow = K0 - ay * (double)iy + 0.5, rc[4], rk[4];
        int ca0, ca1, cc0, cc1, p[3], have_rk = 0;
        size_t rowbase;
        unsigned rowbit;
        /* the row's columns (projection z), on centres */
        rc[0] = rc[2] = -HUGE_VAL;
        rc[1] = rc[3] = HUGE_VAL;
        for (j = 0; j < 3; j++) vx_cons_bound_apply(&bz[j], cy, rc);
        ca0 = vx_cons_ceil_in(rc[0] - 0.5, x0, x1);
        ca1 = vx_cons_floor_in(rc[1] - 0.5, x0, x1);
        if (ca0 > ca1) continue;
        /* the certain range is the candidate one unless a bound is within its margin of a
         * centre: ceil(rc[2] - .5) == ca0 iff ca0 >= rc[2] - .5 (rc[2] >= rc[0]) */
        cc0 = (double)ca0 >= rc[2] - 0.5 ? ca0 : vx_cons_ceil_in(rc[2] - 0.5, x0, x1);
        cc1 = (double)ca1 <= rc[3] - 0.5 ? ca1 : vx_cons_floor_in(rc[3] - 0.5, x0, x1);
        p[U] = 0;
        p[W] = iy;
        p[D] = 0;
        rowbase = vx_cons_brick_of(B, p, &rowbit);
        for (ix = ca0; ix <= ca1; ix++) {
            double kc = krow - ax * (double)ix, r[4];
            int ka, kb, kA, kB;
            size_t base = rowbase + (size_t)(ix >> 2) * sU;
            unsigned bit0 = rowbit | (unsigned)(ix & 3) << (U == 0 ? 0 : (U == 1 ? 2 : 4));
#define VX_CONS_WORD(kk) B->w[base + (size_t)((kk) >> 2) * sD]
#define VX_CONS_MASK(kk) ((uint64_t)1 << (bit0 | ((unsigned)((kk) & 3) << sh)))
            /* the plane's candidate layers; done if they are all set already */
            r[0] = kc - hwid - eps;
            r[1] = kc + hwid + eps;
            ka = vx_cons_ceil_in(r[0] - 0.5, z0, z1);
            kb = vx_cons_floor_in(r[1] - 0.5, z0, z1);
            if (ka > kb) continue;
            if (kb - ka <= 4) {
                /* at most two bricks: masks of the layers in each (vx_cons_layer_masks) */
                int kc3 = ka | 3, last = kb < kc3 ? kb : kc3;
                uint64_t m1 = vx_cons_layer_masks[sh >> 1][ka & 3][last & 3] << bit0, m2 = 0, w2 = 0;
                if (kb > kc3) {
                    m2 = vx_cons_layer_masks[sh >> 1][0][kb & 3] << bit0;
                    w2 = VX_CONS_WORD(kb);
                }
                if ((VX_CONS_WORD(ka) & m1) == m1 && (w2 & m2) == m2) continue;
            } else {
                for (k = ka; k <= kb && (VX_CONS_WORD(k) & VX_CONS_MASK(k)); k++) {}
                if (k > kb) continue;
            }
            /* layer bounds on the centre: plane, projection x (row), projection y (column) */
            if (!have_xy) {
                for (j = 0; j < 3; j++) {
                    const int o = j == 0 ? 2 : j - 1;
                    vx_cons_bound_init(&bx[j], f[j][1], -f[j][2], P[j][2], P[j][1], P[o][2],
                                       P[o][1], eps);
                    vx_cons_bound_init(&by[j], -f[j][0], f[j][2], P[j][2], P[j][0], P[o][2],
                                       P[o][0], eps);
                }
                have_xy = 1;
            }
            if (!have_rk) {
                rk[0] = rk[2] = -HUGE_VAL;
                rk[1] = rk[3] = HUGE_VAL;
                for (j = 0; j < 3; j++) vx_cons_bound_apply(&bx[j], cy, rk);
                have_rk = 1;
            }
            r[2] = kc - hwid + eps;
            r[3] = kc + hwid - eps;
            for (j = 0; j < 3; j++) vx_cons_bound_apply(&by[j], (double)ix + 0.5, r);
            r[0] = r[0] > rk[0] ? r[0] : rk[0];
            r[1] = r[1] < rk[1] ? r[1] : rk[1];
            r[2] = r[2] > rk[2] ? r[2] : rk[2];
            r[3] = r[3] < rk[3] ? r[3] : rk[3];
            ka = vx_cons_ceil_in(r[0] - 0.5, z0, z1);
            kb = vx_cons_floor_in(r[1] - 0.5, z0, z1);
            if (ka > kb) continue;
            kA = (double)ka >= r[2] - 0.5 ? ka : vx_cons_ceil_in(r[2] - 0.5, z0, z1);
            kB = (double)kb <= r[3] - 0.5 ? kb : vx_cons_floor_in(r[3] - 0.5, z0, z1);
            if (ka == kA && kb == kB && ix >= cc0 && ix <= cc1) {
                for (k = ka; k <= kb; k++) VX_CONS_WORD(k) |= VX_CONS_MASK(k); /* certain */
                continue;
            }
            /* within a margin of an end: the SAT's own expressions decide */
            slow++;
            if (!have_sat) {
                vx_cons_setup(T);
                have_sat = 1;
            }
            {
                double cu = (double)ix + 0.5;
                t[0][U] = T->v[0][U] - cu;
                t[1][U] = T->v[1][U] - cu;
                t[2][U] = T->v[2][U] - cu;
                t[0][W] = T->v[0][W] - cy;
                t[1][W] = T->v[1][W] - cy;
                t[2][W] = T->v[2][W] - cy;
            }
            if ((ix < cc0 || ix > cc1) && vx_cons_sep_proj(T, D, U, W, t)) continue;
            for (k = ka; k <= kb; k++)
                if ((k >= kA && k <= kB) || vx_cons_layer_ok(T, t, k)) VX_CONS_WORD(k) |= VX_CONS_MASK(k);
#undef VX_CONS_WORD
#undef VX_CONS_MASK
        }
    }
    (void)sW;
    return slow;
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
        for (k = 0; k < 3; k++) {
            const double *g = gv + 3 * (size_t)mesh->indices[3 * t + (size_t)k];
            T.v[k][0] = g[0];
            T.v[k][1] = g[1];
            T.v[k][2] = g[2];
        }
        if (!vx_cons_bbox_fast(&T, grid, lo, hi)) continue;
        {
            double f0[3], f1[3];
            for (a = 0; a < 3; a++) {
                f0[a] = T.v[1][a] - T.v[0][a];
                f1[a] = T.v[2][a] - T.v[1][a];
            }
            vx_cons_normal(f0, f1, T.n); /* the SAT's normal: degenerate iff it is zero */
        }
        if (T.n[0] == 0.0 && T.n[1] == 0.0 && T.n[2] == 0.0) continue;
        T.D = 0;
        if (fabs(T.n[1]) > fabs(T.n[T.D])) T.D = 1;
        if (fabs(T.n[2]) > fabs(T.n[T.D])) T.D = 2;
        T.U = T.D == 2 ? 0 : T.D + 1;
        T.W = T.D == 0 ? 2 : T.D - 1;
        vx_cons_fast_tri(&T, lo, hi, &B);
    }
    n = vx_cons_bricks_emit(&B, grid, occ);
    vx_free(alloc, B.w);
    vx_free(alloc, gv);
    if (count) *count = n;
    return HFVIS_OK;
}

/* ---- 5c. exact 2D orientation and the watertight pixel-centre coverage rule ------------- */

/* The rounding error of the product p = fl(a*b): a*b - p exactly (Dekker's TwoProduct with
 * Veltkamp's split; needs round-to-nearest double arithmetic without contraction, which the
 * build's -ffp-contract=off gives, and no overflow/underflow, which VX_CONS_MAX_COORD and the
 * grid-space ranges give). */
static double vx_cons_product_error(double a, double b, double p)
{
    const double split = 134217729.0; /* 2^27 + 1 */
    double ca = split * a, cb = split * b;
    double ah = ca - (ca - a), al = a - ah, bh = cb - (cb - b), bl = b - bh;
    return ((ah * bh - p) + ah * bl + al * bh) + al * bl;
}

/* Exact sign of a*b - c*d. Rounding is monotone, so fl(a*b) > fl(c*d) implies a*b > c*d; only
 * when the rounded products are equal do their exact errors decide. */
static int vx_cons_det_sign(double a, double b, double c, double d)
{
    double p = a * b, q = c * d, ep, eq;
    if (p > q) return 1;
    if (p < q) return -1;
    ep = vx_cons_product_error(a, b, p);
    eq = vx_cons_product_error(c, d, q);
    return ep > eq ? 1 : (ep < eq ? -1 : 0);
}

/* Coverage of the point (cu, cw) by a triangle projected to (pu[k], pw[k]) (spec §3.4, §3.9:
 * the pixel-centre rule with a watertight tie rule). The vertices are moved to the point first,
 * q_k = fl(p_k - c) (shared vertices give the same q in every triangle), and the three edge
 * functions E_k = q_{k+1} x q_{k+2} are evaluated with their EXACT sign (vx_cons_det_sign), so
 * the two triangles of an edge see exactly opposite signs. The point is inside when no two signs
 * are opposite and not all are zero; the triangle's orientation s is then the common non-zero
 * sign. An edge whose E is 0 passes the point on it exactly: it includes it when the point
 * moved by (eps, eps^2) (eps -> 0+) would be strictly inside, i.e. when the edge, oriented by s,
 * has direction d with d_w < 0, or d_w == 0 and d_u > 0 (a "top-left" rule). This equals exact
 * coverage of that infinitesimally moved point by the triangle of the q's, so on a closed mesh
 * every line through a point crosses the surface an even number of times, and a shared edge or
 * vertex is counted once where the surface passes through and 0 or 2 times where it folds
 * (silhouettes). Returns 1 inside, 0 outside; *e receives fl(E_k) (unnormalised barycentrics,
 * for depth interpolation). */
static int vx_cons_cover(const double pu[3], const double pw[3], double cu, double cw,
                         double e[3])
{
    double qu[3], qw[3];
    int s[3], k, pos = 0, neg = 0, orient;
    for (k = 0; k < 3; k++) {
        qu[k] = pu[k] - cu;
        qw[k] = pw[k] - cw;
    }
    for (k = 0; k < 3; k++) {
        int a = k == 2 ? 0 : k + 1, b = k == 0 ? 2 : k - 1;
        double x = qu[a] * qw[b], y = qw[a] * qu[b];
        e[k] = x - y;
        s[k] = x > y ? 1 : (x < y ? -1 : vx_cons_det_sign(qu[a], qw[b], qw[a], qu[b]));
        pos |= s[k] > 0;
        neg |= s[k] < 0;
    }
    if (pos == neg) return 0; /* opposite signs, or all zero (degenerate) */
    orient = pos ? 1 : -1;
    for (k = 0; k < 3; k++) {
        if (s[k] == 0) {
            int a = k == 2 ? 0 : k + 1, b = k == 0 ? 2 : k - 1;
            double du = qu[b] - qu[a], dw = qw[b] - qw[a];
            if (orient < 0) {
                du = -du;
                dw = -dw;
            }
            if (!(dw < 0.0 || (dw == 0.0 && du > 0.0))) return 0;
        }
    }
    return 1;
}

/* Depth (grid units along the projection axis) of the covered point from the unnormalised
 * barycentrics e and the vertex depths pz, clamped to the vertices' range. */
static double vx_cons_depth(const double e[3], const double pz[3])
{
    double sum = e[0] + e[1] + e[2];
    double lo = vx_cons_min3(pz[0], pz[1], pz[2]), hi = vx_cons_max3(pz[0], pz[1], pz[2]), z;
    if (sum == 0.0) return lo; /* rounding-dominated sliver: any depth of the triangle */
    z = (e[0] * pz[0] + e[1] * pz[1] + e[2] * pz[2]) / sum;
    return z < lo ? lo : (z > hi ? hi : z);
}

/* Column range [*lo, *hi] of the pixel centres c + 0.5 inside [mn, mx], clipped to [0, n-1];
 * 0 when empty. */
static int vx_cons_centre_range(double mn, double mx, int n, int *lo, int *hi)
{
    double l = ceil(mn - 0.5), h = floor(mx - 0.5);
    if (l < 0.0) l = 0.0;
    if (h > (double)(n - 1)) h = (double)(n - 1);
    if (l > h) return 0;
    *lo = (int)l;
    *hi = (int)h;
    return 1;
}

/* Visits every pixel centre (iu, iw) of projection a (u = a+1, w = a+2) covered by grid-space
 * triangle v under vx_cons_cover, with its depth z along a. */
typedef void (*vx_cons_pixel_fn)(void *ctx, int iu, int iw, double z);

static void vx_cons_raster(double v[3][3], int a, const int dims[3], vx_cons_pixel_fn fn,
                           void *ctx)
{
    int u = a == 2 ? 0 : a + 1, w = a == 0 ? 2 : a - 1, ul, uh, wl, wh, iu, iw;
    double pu[3], pw[3], pz[3], e[3];
    int k;
    for (k = 0; k < 3; k++) {
        pu[k] = v[k][u];
        pw[k] = v[k][w];
        pz[k] = v[k][a];
    }
    if (!vx_cons_centre_range(vx_cons_min3(pu[0], pu[1], pu[2]), vx_cons_max3(pu[0], pu[1], pu[2]),
                              dims[u], &ul, &uh)
        || !vx_cons_centre_range(vx_cons_min3(pw[0], pw[1], pw[2]),
                                 vx_cons_max3(pw[0], pw[1], pw[2]), dims[w], &wl, &wh))
        return;
    for (iw = wl; iw <= wh; iw++)
        for (iu = ul; iu <= uh; iu++)
            if (vx_cons_cover(pu, pw, (double)iu + 0.5, (double)iw + 0.5, e))
                fn(ctx, iu, iw, vx_cons_depth(e, pz));
}

/* ---- 5d. solid voxelization by parity -------------------------------------------------- */

/* Options resolved: the parity axis as 0, 1, 2; -1 for an unknown value. */
static int vx_cons_parity_axis(const hfvis_binary_voxel_options *opts)
{
    if (!opts || opts->axis == HFVIS_PARITY_AXIS_DEFAULT) return 2;
    switch (opts->axis) {
    case HFVIS_PARITY_AXIS_X: return 0;
    case HFVIS_PARITY_AXIS_Y: return 1;
    case HFVIS_PARITY_AXIS_Z: return 2;
    default: return -1;
    }
}

/* First layer k whose centre k + 0.5 lies strictly above depth z, clipped to [0, n]. */
static int vx_cons_first_above(double z, int n)
{
    double f;
    int k;
    if (!(z >= 0.5)) return 0; /* also z < 0.5 => layer 0's centre is above */
    if (z >= (double)n - 0.5) return n;
    f = floor(z - 0.5);
    k = (int)f + 1;
    /* fix the rounding of z - 0.5 with exact comparisons (k + 0.5 is exact) */
    while (k > 0 && (double)(k - 1) + 0.5 > z) k--;
    while (k < n && !((double)k + 0.5 > z)) k++;
    return k;
}

typedef struct vx_cons_solid_ctx {
    uint8_t *colpar; /* per column: parity of its crossings */
    uint8_t *occ;    /* NULL in the checking pass */
    size_t stride_u, stride_w, stride_a;
    int nu, na;
} vx_cons_solid_ctx;

static void vx_cons_solid_pixel(void *ctx, int iu, int iw, double z)
{
    vx_cons_solid_ctx *c = (vx_cons_solid_ctx *)ctx;
    c->colpar[(size_t)iw * (size_t)c->nu + (size_t)iu] ^= 1;
    if (c->occ) {
        int k0 = vx_cons_first_above(z, c->na);
        if (k0 < c->na)
            c->occ[(size_t)iu * c->stride_u + (size_t)iw * c->stride_w + (size_t)k0 * c->stride_a] ^= 1;
    }
}

/* Rasterizes every non-degenerate triangle of the mesh into projection a. */
static void vx_cons_raster_mesh(const hfvis_mesh *mesh, const hfvis_volume_grid *grid, int a,
                                vx_cons_pixel_fn fn, void *ctx)
{
    size_t t;
    for (t = 0; t < mesh->triangle_count; t++) {
        double v[3][3];
        int k;
        for (k = 0; k < 3; k++) vx_cons_gvert(mesh, grid, mesh->indices[3 * t + (size_t)k], v[k]);
        if (vx_cons_degenerate(v[0], v[1], v[2])) continue;
        vx_cons_raster(v, a, grid->dims, fn, ctx);
    }
}

HFVIS_API hfvis_status hfvis_voxelize_solid(const hfvis_mesh *mesh, const hfvis_volume_grid *grid,
                                            const hfvis_binary_voxel_options *opts, uint8_t *occ,
                                            size_t *count)
{
    const hfvis_allocator *alloc = opts ? opts->alloc : NULL;
    int a = vx_cons_parity_axis(opts), u, w, allow_open = opts && opts->allow_open;
    size_t ncol, stride[3], i, n = 0, nvox;
    vx_cons_solid_ctx c;
    hfvis_status s;
    if (a < 0) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_cons_args(mesh, grid, occ);
    if (s != HFVIS_OK) return s;
    u = a == 2 ? 0 : a + 1;
    w = a == 0 ? 2 : a - 1;
    stride[0] = 1;
    stride[1] = (size_t)grid->dims[0];
    stride[2] = stride[1] * (size_t)grid->dims[1];
    ncol = (size_t)grid->dims[u] * (size_t)grid->dims[w];
    memset(&c, 0, sizeof c);
    c.colpar = (uint8_t *)vx_alloc(alloc, ncol);
    if (!c.colpar) return HFVIS_ERR_OUT_OF_MEMORY;
    memset(c.colpar, 0, ncol);
    c.nu = grid->dims[u];
    c.na = grid->dims[a];
    c.stride_u = stride[u];
    c.stride_w = stride[w];
    c.stride_a = stride[a];
    if (!allow_open) {
        /* pass 1: every column must be crossed an even number of times (a closed surface) */
        vx_cons_raster_mesh(mesh, grid, a, vx_cons_solid_pixel, &c);
        for (i = 0; i < ncol; i++)
            if (c.colpar[i]) {
                vx_free(alloc, c.colpar);
                return HFVIS_ERR_FORMAT;
            }
    }
    /* pass 2 (Chen & Fang; Eisemann & Decoret 2008): each crossing toggles the first voxel whose
     * centre lies above it; a prefix XOR along the axis then gives the parity of the crossings
     * below every voxel centre. */
    nvox = vx_grid_voxels(grid);
    memset(occ, 0, nvox);
    c.occ = occ;
    vx_cons_raster_mesh(mesh, grid, a, vx_cons_solid_pixel, &c);
    if (a == 0) {
        size_t row, nrows = nvox / stride[1];
        for (row = 0; row < nrows; row++) {
            uint8_t *r = occ + row * stride[1], acc = 0;
            int x;
            for (x = 0; x < grid->dims[0]; x++) r[x] = acc ^= r[x];
        }
    } else {
        /* layers along a are planes (a = 2) or rows inside each z plane (a = 1) */
        size_t plane = a == 2 ? stride[2] : stride[1], blocks = a == 2 ? 1 : (size_t)grid->dims[2];
        size_t blk, layer;
        for (blk = 0; blk < blocks; blk++) {
            uint8_t *base = occ + blk * stride[2];
            for (layer = 1; layer < (size_t)grid->dims[a]; layer++) {
                uint8_t *cur = base + layer * plane;
                const uint8_t *prev = cur - plane;
                for (i = 0; i < plane; i++) cur[i] ^= prev[i];
            }
        }
    }
    if (allow_open) {
        /* columns crossed an odd number of times (an open mesh) are left empty */
        int iu, iw, k;
        for (iw = 0; iw < grid->dims[w]; iw++)
            for (iu = 0; iu < grid->dims[u]; iu++)
                if (c.colpar[(size_t)iw * (size_t)c.nu + (size_t)iu])
                    for (k = 0; k < grid->dims[a]; k++)
                        occ[(size_t)iu * stride[u] + (size_t)iw * stride[w] + (size_t)k * stride[a]] = 0;
    }
    for (i = 0; i < nvox; i++) n += occ[i];
    vx_free(alloc, c.colpar);
    if (count) *count = n;
    return HFVIS_OK;
}

/* Solid angle of triangle (a, b, c) seen from the origin, signed by orientation (Van Oosterom &
 * Strackee 1983): tan(Omega/2) = a.(b x c) / (|a||b||c| + (a.b)|c| + (a.c)|b| + (b.c)|a|). */
static double vx_cons_solid_angle(const double a[3], const double b[3], const double c[3])
{
    double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    double lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    double lc = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    double det = a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2])
                 + a[2] * (b[0] * c[1] - b[1] * c[0]);
    double ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    double ac = a[0] * c[0] + a[1] * c[1] + a[2] * c[2];
    double bc = b[0] * c[0] + b[1] * c[1] + b[2] * c[2];
    return 2.0 * atan2(det, la * lb * lc + ab * lc + ac * lb + bc * la);
}

HFVIS_API hfvis_status hfvis_voxelize_solid_reference(const hfvis_mesh *mesh,
                                                      const hfvis_volume_grid *grid,
                                                      const hfvis_binary_voxel_options *opts,
                                                      uint8_t *occ, size_t *count)
{
    size_t n = 0, t, idx = 0;
    int i, j, k;
    hfvis_status s;
    if (vx_cons_parity_axis(opts) < 0) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_cons_args(mesh, grid, occ);
    if (s != HFVIS_OK) return s;
    for (k = 0; k < grid->dims[2]; k++)
        for (j = 0; j < grid->dims[1]; j++)
            for (i = 0; i < grid->dims[0]; i++, idx++) {
                double c[3], wsum = 0.0, wn;
                c[0] = (double)i + 0.5;
                c[1] = (double)j + 0.5;
                c[2] = (double)k + 0.5;
                for (t = 0; t < mesh->triangle_count; t++) {
                    double v[3][3];
                    int q, a;
                    for (q = 0; q < 3; q++) {
                        vx_cons_gvert(mesh, grid, mesh->indices[3 * t + (size_t)q], v[q]);
                        for (a = 0; a < 3; a++) v[q][a] -= c[a];
                    }
                    wsum += vx_cons_solid_angle(v[0], v[1], v[2]);
                }
                /* generalized winding number (Jacobson et al. 2013); parity of its rounding */
                wn = floor(fabs(wsum) / (4.0 * VX_PI) + 0.5);
                occ[idx] = (uint8_t)(fmod(wn, 2.0) == 1.0);
                n += occ[idx];
            }
    if (count) *count = n;
    return HFVIS_OK;
}

/* ---- 5e. watertightness of the index structure ----------------------------------------- */

static int vx_cons_key_cmp(const void *x, const void *y)
{
    uint64_t a = *(const uint64_t *)x, b = *(const uint64_t *)y;
    return a < b ? -1 : (a > b);
}

HFVIS_API hfvis_status hfvis_mesh_is_watertight(const hfvis_mesh *mesh,
                                                const hfvis_allocator *alloc, int *result)
{
    uint64_t *keys;
    size_t t, m, i;
    int ok = 1;
    if (!result || vx_mesh_check(mesh) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    if (mesh->triangle_count == 0) {
        *result = 1;
        return HFVIS_OK;
    }
    /* every directed edge a -> b as the key a << 32 | b */
    keys = (uint64_t *)vx_alloc_array(alloc, mesh->triangle_count, 3 * sizeof(uint64_t));
    if (!keys) return HFVIS_ERR_OUT_OF_MEMORY;
    m = 3 * mesh->triangle_count;
    for (t = 0; t < mesh->triangle_count && ok; t++) {
        const uint32_t *v = mesh->indices + 3 * t;
        int k;
        for (k = 0; k < 3; k++) {
            uint32_t a = v[k], b = v[k == 2 ? 0 : k + 1];
            if (a == b) ok = 0; /* a repeated index: not a 2-manifold triangle */
            keys[3 * t + (size_t)k] = ((uint64_t)a << 32) | b;
        }
    }
    if (ok) qsort(keys, m, sizeof *keys, vx_cons_key_cmp);
    /* closed and consistently oriented <=> every directed edge occurs once and its reverse too */
    for (i = 0; ok && i < m; i++) {
        uint64_t rev = (keys[i] << 32) | (keys[i] >> 32);
        if (i + 1 < m && keys[i + 1] == keys[i]) ok = 0;
        else if (!bsearch(&rev, keys, m, sizeof *keys, vx_cons_key_cmp)) ok = 0;
    }
    vx_free(alloc, keys);
    *result = ok;
    return HFVIS_OK;
}

/* ---- 5f. bitmask voxelization (three-axis OR, slicemap layout) ------------------------- */

HFVIS_API size_t hfvis_bitmask_words(const hfvis_volume_grid *grid)
{
    if (!vx_grid_valid(grid)) return 0;
    /* <= voxels/32 + columns: no overflow for a valid grid */
    return (size_t)grid->dims[0] * (size_t)grid->dims[1] * (((size_t)grid->dims[2] + 31) / 32);
}

typedef struct vx_cons_bits_ctx {
    uint32_t *bits;
    size_t nx, words; /* words per (i, j) column */
    int a, dims[3];
} vx_cons_bits_ctx;

static void vx_cons_bits_pixel(void *ctx, int iu, int iw, double z)
{
    vx_cons_bits_ctx *c = (vx_cons_bits_ctx *)ctx;
    int p[3], k;
    if (!(z >= 0.0) || z >= (double)c->dims[c->a]) return; /* outside the grid's slabs */
    k = (int)z; /* floor: a depth on a slab boundary goes to the upper slab */
    p[c->a] = k;
    p[c->a == 2 ? 0 : c->a + 1] = iu;
    p[c->a == 0 ? 2 : c->a - 1] = iw;
    c->bits[((size_t)p[1] * c->nx + (size_t)p[0]) * c->words + (size_t)(p[2] >> 5)]
        |= (uint32_t)1 << (p[2] & 31);
}

static unsigned vx_cons_popcount32(uint32_t x)
{
    x = x - ((x >> 1) & 0x55555555u);
    x = (x & 0x33333333u) + ((x >> 2) & 0x33333333u);
    x = (x + (x >> 4)) & 0x0f0f0f0fu;
    return (unsigned)((x * 0x01010101u) >> 24);
}

HFVIS_API hfvis_status hfvis_voxelize_bitmask(const hfvis_mesh *mesh, const hfvis_volume_grid *grid,
                                              const hfvis_binary_voxel_options *opts, uint32_t *bits,
                                              size_t *count)
{
    vx_cons_bits_ctx c;
    size_t nw, i, n = 0;
    int a;
    hfvis_status s = vx_cons_args(mesh, grid, bits);
    (void)opts;
    if (s != HFVIS_OK) return s;
    nw = hfvis_bitmask_words(grid);
    memset(bits, 0, nw * sizeof *bits);
    c.bits = bits;
    c.nx = (size_t)grid->dims[0];
    c.words = ((size_t)grid->dims[2] + 31) / 32;
    for (a = 0; a < 3; a++) c.dims[a] = grid->dims[a];
    /* Eisemann & Decoret 2006 from three viewpoints: every pass rasterizes every triangle with
     * the pixel-centre rule and ORs the bit of the slab holding its depth */
    for (a = 0; a < 3; a++) {
        c.a = a;
        vx_cons_raster_mesh(mesh, grid, a, vx_cons_bits_pixel, &c);
    }
    for (i = 0; i < nw; i++) n += vx_cons_popcount32(bits[i]);
    if (count) *count = n;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_bitmask_to_occupancy(const hfvis_volume_grid *grid,
                                                  const uint32_t *bits, uint8_t *occ)
{
    size_t nx, ny, nz, words, i, j, k;
    if (!bits || !occ || !vx_grid_valid(grid)) return HFVIS_ERR_INVALID_ARGUMENT;
    nx = (size_t)grid->dims[0];
    ny = (size_t)grid->dims[1];
    nz = (size_t)grid->dims[2];
    words = (nz + 31) / 32;
    for (k = 0; k < nz; k++)
        for (j = 0; j < ny; j++)
            for (i = 0; i < nx; i++)
                occ[(k * ny + j) * nx + i]
                    = (uint8_t)((bits[(j * nx + i) * words + (k >> 5)] >> (k & 31)) & 1u);
    return HFVIS_OK;
}

/* ---- 5g. .binvox codec and the raw writer ---------------------------------------------- */
/* binvox (P. Min's voxelizer and viewvox; format by M. Kazhdan): an ASCII header
 *   "#binvox 1\n" "dim D D D\n" "translate tx ty tz\n" "scale s\n" "data\n"
 * then run-length pairs of bytes (value, count), count 1..255, over the D^3 voxels in the order
 * x slowest, then z, then y fastest (index x*D*D + z*D + y); voxel (x, y, z) spans
 * translate + scale*[x, x+1]/D (and likewise y, z). Numbers are written and read without the C
 * library (locale-independent). */

/* Decimal number parser: [+-] digits [. digits] [(e|E) [+-] digits], or [+-] . digits ...
 * Exactly rounded when at most 19 significant digits form a mantissa <= 2^53 and the decimal
 * exponent is within +-22 (Clinger's fast path: m and 10^|e| are exact doubles, one rounding);
 * otherwise within a few ulps. Advances *i; returns 0 on a malformed or non-finite number. */
static int vx_cons_parse_number(const unsigned char *p, size_t n, size_t *i, double *out)
{
    static const double pow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                     1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                     1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
    size_t j = *i;
    uint64_t m = 0;
    long e10 = 0, ex = 0;
    int neg = 0, digits = 0, sig = 0, eneg = 0;
    double v;
    if (j < n && (p[j] == '+' || p[j] == '-')) neg = p[j++] == '-';
    for (; j < n && p[j] >= '0' && p[j] <= '9'; j++, digits++) {
        if (sig < 19) {
            m = m * 10u + (unsigned)(p[j] - '0');
            sig += m != 0;
        } else if (e10 < 100000) {
            e10++;
        }
    }
    if (j < n && p[j] == '.') {
        for (j++; j < n && p[j] >= '0' && p[j] <= '9'; j++, digits++) {
            if (sig < 19) {
                m = m * 10u + (unsigned)(p[j] - '0');
                sig += m != 0;
                e10--;
            }
        }
    }
    if (digits == 0) return 0;
    if (j < n && (p[j] == 'e' || p[j] == 'E')) {
        j++;
        if (j < n && (p[j] == '+' || p[j] == '-')) eneg = p[j++] == '-';
        if (j >= n || p[j] < '0' || p[j] > '9') return 0;
        for (; j < n && p[j] >= '0' && p[j] <= '9'; j++)
            if (ex < 100000) ex = ex * 10 + (long)(p[j] - '0');
    }
    e10 += eneg ? -ex : ex;
    if (m == 0) {
        v = 0.0;
    } else if (m <= ((uint64_t)1 << 53) && e10 >= -22 && e10 <= 22) {
        v = e10 >= 0 ? (double)m * pow10[e10] : (double)m / pow10[-e10];
    } else {
        if (e10 > 400) e10 = 400;
        if (e10 < -400) e10 = -400;
        v = (double)m * pow(10.0, (double)(e10 / 2)) * pow(10.0, (double)(e10 - e10 / 2));
    }
    if (!isfinite(v)) return 0;
    *out = neg ? -v : v;
    *i = j;
    return 1;
}

/* Writes finite x in at most 25 characters (no terminator): the fewest significant digits
 * (1..15) that vx_cons_parse_number reads back as exactly x, else 17 digits (within a few
 * ulps). Plain notation for decimal exponents -5..15, else d.ddde+XX. Returns the length. */
static size_t vx_cons_format_number(double x, char *out)
{
    static const double pow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                     1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                     1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
    char dig[24], buf[40];
    size_t len = 0;
    int prec, e10, nd = 0, k;
    double ax = fabs(x);
    HFVIS_ASSERT(isfinite(x));
    if (ax == 0.0 || !isfinite(x)) {
        out[0] = '0';
        return 1;
    }
    e10 = (int)floor(log10(ax));
    for (prec = 1; prec <= 17; prec++) {
        /* q = round(ax * 10^(prec-1-e10)) (approximately), so ax ~ q * 10^(e10-prec+1) */
        int sh = prec - 1 - e10, lead;
        double m;
        uint64_t q;
        if (prec == 16) continue;
        if (sh >= 0 && sh <= 22) m = ax * pow10[sh];
        else if (sh < 0 && sh >= -22) m = ax / pow10[-sh];
        else m = ax * pow(10.0, (double)(sh / 2)) * pow(10.0, (double)(sh - sh / 2));
        m = floor(m + 0.5);
        if (m >= 1e17) { /* only when log10 misjudged the exponent: drop a digit */
            m = floor(m / 10.0 + 0.5);
            sh--;
        }
        if (m < 1.0) m = 1.0;
        q = (uint64_t)m;
        nd = 0;
        while (q) {
            dig[nd++] = (char)('0' + (int)(q % 10u));
            q /= 10u;
        }
        lead = nd - 1 - sh; /* power of ten of the leading digit dig[nd-1] */
        while (nd > 1 && dig[0] == '0') { /* trailing zeros of the digit string */
            for (k = 0; k + 1 < nd; k++) dig[k] = dig[k + 1];
            nd--;
        }
        len = 0;
        if (x < 0.0) buf[len++] = '-';
        if (lead >= -5 && lead <= 15) {
            int place;
            if (lead < 0) {
                buf[len++] = '0';
                buf[len++] = '.';
                for (place = -1; place > lead; place--) buf[len++] = '0';
            }
            for (k = 0; k < nd; k++) {
                place = lead - k;
                buf[len++] = dig[nd - 1 - k];
                if (place == 0 && k + 1 < nd) buf[len++] = '.';
            }
            for (place = lead - nd; place >= 0; place--) buf[len++] = '0';
        } else {
            int ee = lead < 0 ? -lead : lead;
            buf[len++] = dig[nd - 1];
            if (nd > 1) {
                buf[len++] = '.';
                for (k = 1; k < nd; k++) buf[len++] = dig[nd - 1 - k];
            }
            buf[len++] = 'e';
            buf[len++] = lead < 0 ? '-' : '+';
            if (ee >= 100) buf[len++] = (char)('0' + ee / 100);
            buf[len++] = (char)('0' + ee / 10 % 10);
            buf[len++] = (char)('0' + ee % 10);
        }
        if (prec <= 15) {
            size_t at = 0;
            double back;
            if (vx_cons_parse_number((const unsigned char *)buf, len, &at, &back) && at == len
                && back == x)
                break;
        }
    }
    memcpy(out, buf, len);
    return len;
}

/* The binvox header of a grid padded to the cube of side d, into out (NULL: only measure).
 * translate = origin, scale = d * max(cell): binvox has one scale, so non-cubic voxels are
 * written with the largest cell (documented). */
static size_t vx_cons_binvox_header(const hfvis_volume_grid *g, int d, char *out)
{
    char tmp[256];
    size_t len = 0, k;
    int a;
    double cell = vx_cons_max3(g->cell[0], g->cell[1], g->cell[2]);
    char num[12];
    int nn = 0, q = d;
    static const char head[] = "#binvox 1\ndim ";
    memcpy(tmp, head, sizeof head - 1);
    len = sizeof head - 1;
    do {
        num[nn++] = (char)('0' + q % 10);
        q /= 10;
    } while (q);
    for (a = 0; a < 3; a++) {
        for (k = 0; k < (size_t)nn; k++) tmp[len++] = num[nn - 1 - (int)k];
        tmp[len++] = a < 2 ? ' ' : '\n';
    }
    memcpy(tmp + len, "translate ", 10);
    len += 10;
    for (a = 0; a < 3; a++) {
        len += vx_cons_format_number(g->origin[a], tmp + len);
        tmp[len++] = a < 2 ? ' ' : '\n';
    }
    memcpy(tmp + len, "scale ", 6);
    len += 6;
    len += vx_cons_format_number((double)d * cell, tmp + len);
    memcpy(tmp + len, "\ndata\n", 6);
    len += 6;
    if (out) memcpy(out, tmp, len);
    return len;
}

/* Side of the binvox cube for a valid grid; 0 when d^3 exceeds HFVIS_VOLUME_MAX_VOXELS or the
 * scale d * max(cell) overflows a double. */
static int vx_cons_binvox_side(const hfvis_volume_grid *g)
{
    int d = g->dims[0] > g->dims[1] ? g->dims[0] : g->dims[1];
    size_t dd = 1;
    if (g->dims[2] > d) d = g->dims[2];
    if (!vx_mul_size(dd, (size_t)d, &dd) || !vx_mul_size(dd, (size_t)d, &dd)
        || !vx_mul_size(dd, (size_t)d, &dd) || dd > HFVIS_VOLUME_MAX_VOXELS
        || !isfinite((double)d * vx_cons_max3(g->cell[0], g->cell[1], g->cell[2])))
        return 0;
    return d;
}

/* Runs the binvox RLE over the padded cube; writes pairs into out when not NULL. Returns the
 * number of bytes of the pairs. */
static size_t vx_cons_binvox_rle(const hfvis_volume_grid *g, const uint8_t *occ, int d,
                                 unsigned char *out)
{
    size_t nx = (size_t)g->dims[0], ny = (size_t)g->dims[1], nz = (size_t)g->dims[2], bytes = 0;
    size_t x, y, z, D = (size_t)d;
    unsigned run = 0, cur = 0;
    for (x = 0; x < D; x++)
        for (z = 0; z < D; z++)
            for (y = 0; y < D; y++) {
                unsigned v = (x < nx && y < ny && z < nz) ? occ[(z * ny + y) * nx + x] != 0 : 0u;
                if (run > 0 && (v != cur || run == 255)) {
                    if (out) {
                        out[bytes] = (unsigned char)cur;
                        out[bytes + 1] = (unsigned char)run;
                    }
                    bytes += 2;
                    run = 0;
                }
                cur = v;
                run++;
            }
    if (out) {
        out[bytes] = (unsigned char)cur;
        out[bytes + 1] = (unsigned char)run;
    }
    return bytes + 2;
}

HFVIS_API size_t hfvis_binvox_encode_size(const hfvis_volume_grid *grid, const uint8_t *occ)
{
    int d;
    if (!occ || !vx_grid_valid(grid) || (d = vx_cons_binvox_side(grid)) == 0) return 0;
    return vx_cons_binvox_header(grid, d, NULL) + vx_cons_binvox_rle(grid, occ, d, NULL);
}

HFVIS_API hfvis_status hfvis_binvox_encode(const hfvis_volume_grid *grid, const uint8_t *occ,
                                           void *out, size_t capacity, size_t *written)
{
    size_t head, need;
    int d;
    if (!occ || !out || !written || !vx_grid_valid(grid)) return HFVIS_ERR_INVALID_ARGUMENT;
    d = vx_cons_binvox_side(grid);
    if (d == 0) return HFVIS_ERR_LIMIT;
    need = hfvis_binvox_encode_size(grid, occ);
    if (capacity < need) return HFVIS_ERR_BUFFER_TOO_SMALL;
    head = vx_cons_binvox_header(grid, d, (char *)out);
    vx_cons_binvox_rle(grid, occ, d, (unsigned char *)out + head);
    *written = need;
    return HFVIS_OK;
}

/* Skips blanks (space, tab) from p[*i]. */
static void vx_cons_skip_blank(const unsigned char *p, size_t n, size_t *i)
{
    while (*i < n && (p[*i] == ' ' || p[*i] == '\t')) (*i)++;
}

/* The end of a header line: optional blanks, optional '\r', then '\n'. */
static int vx_cons_line_end(const unsigned char *p, size_t n, size_t *i)
{
    vx_cons_skip_blank(p, n, i);
    if (*i < n && p[*i] == '\r') (*i)++;
    if (*i >= n || p[*i] != '\n') return 0;
    (*i)++;
    return 1;
}

/* A keyword at p[*i] followed by a blank or the line end. */
static int vx_cons_keyword(const unsigned char *p, size_t n, size_t *i, const char *kw)
{
    size_t len = strlen(kw);
    if (n - *i < len || memcmp(p + *i, kw, len) != 0) return 0;
    if (*i + len < n && p[*i + len] != ' ' && p[*i + len] != '\t' && p[*i + len] != '\r'
        && p[*i + len] != '\n')
        return 0;
    *i += len;
    return 1;
}

/* Unsigned decimal after blanks (at least one blank first); values above cap saturate at
 * cap + 1. */
static int vx_cons_parse_uint(const unsigned char *p, size_t n, size_t *i, unsigned long cap,
                              unsigned long *out)
{
    size_t j = *i;
    unsigned long v = 0;
    vx_cons_skip_blank(p, n, &j);
    if (j == *i || j >= n || p[j] < '0' || p[j] > '9') return 0;
    for (; j < n && p[j] >= '0' && p[j] <= '9'; j++) {
        unsigned long dg = (unsigned long)(p[j] - '0');
        v = (v > (cap - dg) / 10) ? cap + 1 : v * 10 + dg;
    }
    *i = j;
    *out = v;
    return 1;
}

/* A number after at least one blank. */
static int vx_cons_parse_field(const unsigned char *p, size_t n, size_t *i, double *out)
{
    size_t j = *i;
    vx_cons_skip_blank(p, n, &j);
    if (j == *i) return 0;
    if (!vx_cons_parse_number(p, n, &j, out)) return 0;
    if (j < n && p[j] != ' ' && p[j] != '\t' && p[j] != '\r' && p[j] != '\n') return 0;
    *i = j;
    return 1;
}

HFVIS_API hfvis_status hfvis_binvox_decode(const void *data, size_t size,
                                           const hfvis_allocator *alloc, hfvis_volume_grid *grid,
                                           uint8_t **occ)
{
    const unsigned char *p = (const unsigned char *)data;
    size_t i = 0, total, got = 0, j, D, DD;
    unsigned long version, dims[3];
    double translate[3] = {0.0, 0.0, 0.0}, scale = 1.0;
    int have_dim = 0, have_t = 0, have_s = 0, a;
    hfvis_volume_grid g;
    uint8_t *o;
    if (!data || !grid || !occ) return HFVIS_ERR_INVALID_ARGUMENT;
    if (!vx_cons_keyword(p, size, &i, "#binvox") || !vx_cons_parse_uint(p, size, &i, 9, &version)
        || (version != 1 && version != 2) || !vx_cons_line_end(p, size, &i))
        return HFVIS_ERR_FORMAT;
    for (;;) {
        if (vx_cons_keyword(p, size, &i, "data")) {
            if (!vx_cons_line_end(p, size, &i)) return HFVIS_ERR_FORMAT;
            break;
        } else if (vx_cons_keyword(p, size, &i, "dim")) {
            if (have_dim) return HFVIS_ERR_FORMAT;
            for (a = 0; a < 3; a++)
                if (!vx_cons_parse_uint(p, size, &i, (unsigned long)INT_MAX, &dims[a]) || dims[a] == 0)
                    return HFVIS_ERR_FORMAT;
            have_dim = 1;
        } else if (vx_cons_keyword(p, size, &i, "translate")) {
            if (have_t) return HFVIS_ERR_FORMAT;
            for (a = 0; a < 3; a++)
                if (!vx_cons_parse_field(p, size, &i, &translate[a])) return HFVIS_ERR_FORMAT;
            have_t = 1;
        } else if (vx_cons_keyword(p, size, &i, "scale")) {
            if (have_s || !vx_cons_parse_field(p, size, &i, &scale) || !(scale > 0.0))
                return HFVIS_ERR_FORMAT;
            have_s = 1;
        } else {
            return HFVIS_ERR_FORMAT; /* unknown line, blank line or end of data */
        }
        if (!vx_cons_line_end(p, size, &i)) return HFVIS_ERR_FORMAT;
    }
    if (!have_dim || dims[0] != dims[1] || dims[1] != dims[2]) return HFVIS_ERR_FORMAT;
    if (dims[0] > (unsigned long)INT_MAX) return HFVIS_ERR_LIMIT;
    D = (size_t)dims[0];
    if (!vx_mul_size(D, D, &DD) || !vx_mul_size(DD, D, &total) || total > HFVIS_VOLUME_MAX_VOXELS)
        return HFVIS_ERR_LIMIT;
    for (a = 0; a < 3; a++) {
        g.dims[a] = (int)D;
        g.origin[a] = translate[a];
        g.cell[a] = scale / (double)D;
    }
    if (!vx_grid_valid(&g)) return HFVIS_ERR_FORMAT; /* e.g. a scale that underflows */
    /* validate the runs before allocating: pairs, values, counts, exact total, no trailing byte */
    if ((size - i) % 2 != 0) return HFVIS_ERR_FORMAT;
    for (j = i; j < size; j += 2) {
        if ((version == 1 && p[j] > 1) || p[j + 1] == 0 || got >= total) return HFVIS_ERR_FORMAT;
        got += p[j + 1];
        if (got > total) return HFVIS_ERR_FORMAT;
    }
    if (got != total) return HFVIS_ERR_FORMAT;
    o = (uint8_t *)vx_alloc(alloc, total);
    if (!o) return HFVIS_ERR_OUT_OF_MEMORY;
    {
        size_t x = 0, y = 0, z = 0; /* binvox order: y fastest, then z, then x */
        for (j = i; j < size; j += 2) {
            unsigned c = p[j + 1];
            while (c--) {
                o[(z * D + y) * D + x] = p[j];
                if (++y == D) {
                    y = 0;
                    if (++z == D) {
                        z = 0;
                        x++;
                    }
                }
            }
        }
    }
    *grid = g;
    *occ = o;
    return HFVIS_OK;
}

#ifndef HFVIS_NO_STDIO
HFVIS_API hfvis_status hfvis_binvox_save(const char *path, const hfvis_volume_grid *grid,
                                         const uint8_t *occ)
{
    size_t need, written = 0;
    unsigned char *buf;
    hfvis_status s;
    if (!path || !occ || !vx_grid_valid(grid)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (vx_cons_binvox_side(grid) == 0) return HFVIS_ERR_LIMIT;
    need = hfvis_binvox_encode_size(grid, occ);
    buf = (unsigned char *)vx_alloc(NULL, need);
    if (!buf) return HFVIS_ERR_OUT_OF_MEMORY;
    s = hfvis_binvox_encode(grid, occ, buf, need, &written);
    if (s == HFVIS_OK) s = hfvis__write_file(path, buf, written);
    vx_free(NULL, buf);
    return s;
}

HFVIS_API hfvis_status hfvis_binvox_load(const char *path, const hfvis_allocator *alloc,
                                         hfvis_volume_grid *grid, uint8_t **occ)
{
    unsigned char *data = NULL;
    size_t size = 0;
    hfvis_status s;
    if (!path || !grid || !occ) return HFVIS_ERR_INVALID_ARGUMENT;
    s = hfvis__read_file(path, alloc, &data, &size);
    if (s != HFVIS_OK) return s;
    s = hfvis_binvox_decode(data, size, alloc, grid, occ);
    vx_free(alloc, data);
    return s;
}

HFVIS_API hfvis_status hfvis_voxels_raw_save(const char *path, const hfvis_volume_grid *grid,
                                             const uint8_t *voxels)
{
    if (!path || !voxels || !vx_grid_valid(grid)) return HFVIS_ERR_INVALID_ARGUMENT;
    return hfvis__write_file(path, voxels, vx_grid_voxels(grid));
}
#endif /* HFVIS_NO_STDIO */
