/* ========================================================================================== */
/* 2a. BVH and ray casting (issue 4; the scene-space caster of spec raycast A.9.2 / A.10)      */
/*     Watertight test: S. Woop, C. Benthin, I. Wald, "Watertight Ray/Triangle Intersection",  */
/*     JCGT 2(1), 2013: its pseudo-code listing (ray setup, shear, edge functions U V W, the   */
/*     double-precision recomputation of zero edge functions), quoted line by line below.     */
/*     Slab test: T. Ize, "Robust BVH Ray Traversal", JCGT 2(2), 2013 (t_far * (1 + 2 gamma_3)).*/
/*     SAH: MacDonald & Booth 1990, binned as I. Wald, IEEE RT 2007.                           */
/* ========================================================================================== */
/* Contents
 *   2a.1 rays: validation and the per-ray setup of Woop et al.
 *   2a.2 the watertight ray-triangle test and the exact zero-area test
 *   2a.3 naive oracle (every triangle in index order)
 *   2a.4 binned SAH build (explicit stack, median fallback, padded boxes)
 *   2a.5 traversal (robust slab test, nearer child first, explicit stack) */

/* Far-distance and best-distance widening of the slab test: Ize's 1 + 2 gamma_3 (3.6e-7) covers
 * the slab arithmetic; 2^-16 also covers the rounding of the triangle's own t (relative, a few
 * ulp times the conditioning of the hit), so a hit the naive loop finds is never pruned. */
#define VX_BVH_SLACK (1.0f + 1.0f / 65536.0f)
/* Node boxes are padded by 2^-18 of their largest coordinate magnitude or extent: covers the
 * off-plane rounding of a computed hit point (about gamma * box size) near box faces. */
#define VX_BVH_PAD 0x1p-18
/* The two inner-loop tests are forced inline (GCC/Clang), else left to the compiler. */
#if defined(__GNUC__)
#define VX_BVH_INLINE inline __attribute__((always_inline))
#else
#define VX_BVH_INLINE inline
#endif
/* SAH constants (spec raycast A.9.2: C_trav = C_tri = 1). */
#define VX_BVH_C_TRAV 1.0
#define VX_BVH_C_TRI 1.0

/* ---- 2a.1 rays ------------------------------------------------------------------------------ */

/* A ray prepared once per query (Woop et al.: "calculate dimension where the ray direction is
 * maximal", "swap kx and ky dimension to preserve winding direction of triangles", "calculate
 * shear constants"). */
typedef struct vx_bvh_ray {
    float org[3], dir[3];
    float inv[3];      /* 1/dir; a zero component gives +-infinity with the zero's sign */
    int neg[3];        /* sign bit of dir: the slab's near plane is hi when set */
    int kx, ky, kz;    /* kz = axis of the largest |dir|; kx, ky swapped if dir[kz] < 0 */
    float sx, sy, sz;  /* shear constants: dir[kx]/dir[kz], dir[ky]/dir[kz], 1/dir[kz] */
    float t_min, t_max;
    int cull;
} vx_bvh_ray;

static int vx_bvh_ray_valid(const hfvis_ray *r)
{
    int a;
    if (!r) return 0;
    for (a = 0; a < 3; a++)
        if (!isfinite(r->origin[a]) || !isfinite(r->direction[a])) return 0;
    if (r->direction[0] == 0.0f && r->direction[1] == 0.0f && r->direction[2] == 0.0f) return 0;
    if (!(r->t_min >= 0.0f) || !isfinite(r->t_min)) return 0; /* NaN fails the first test */
    if (!(r->t_max >= r->t_min)) return 0;                    /* NaN fails; +inf allowed */
    if (r->cull != HFVIS_CULL_NONE && r->cull != HFVIS_CULL_BACK
        && r->cull != HFVIS_CULL_FRONT)
        return 0;
    return 1;
}

/* kz = dimension of the largest |direction| component (first on ties), kx and ky the
 * next two cyclically, swapped when dir[kz] < 0 to keep the winding; shear constants. */
static void vx_bvh_ray_setup(const hfvis_ray *r, vx_bvh_ray *p)
{
    int a, kz = 0, t;
    float m = fabsf(r->direction[0]);
    for (a = 0; a < 3; a++) {
        float d = r->direction[a];
        p->org[a] = r->origin[a];
        p->dir[a] = d;
        p->neg[a] = signbit(d) ? 1 : 0;
        p->inv[a] = d == 0.0f ? copysignf(INFINITY, d) : 1.0f / d;
        if (fabsf(d) > m) {
            m = fabsf(d);
            kz = a;
        }
    }
    p->kz = kz;
    p->kx = kz == 2 ? 0 : kz + 1;
    p->ky = p->kx == 2 ? 0 : p->kx + 1;
    if (r->direction[kz] < 0.0f) {
        t = p->kx;
        p->kx = p->ky;
        p->ky = t;
    }
    p->sx = r->direction[p->kx] / r->direction[kz];
    p->sy = r->direction[p->ky] / r->direction[kz];
    p->sz = 1.0f / r->direction[kz];
    p->t_min = r->t_min;
    p->t_max = r->t_max;
    p->cull = (int)r->cull;
}

static void vx_bvh_miss(hfvis_hit *h)
{
    h->t = INFINITY;
    h->triangle = HFVIS_NO_TRIANGLE;
    h->u = 0.0f;
    h->v = 0.0f;
    h->front = 0;
}

/* ---- 2a.2 watertight ray-triangle test ----------------------------------------------------- */

/* Exact test: is p[0] + ... + p[5] == 0? The p are exact products of two floats (double). A
 * floating-point filter (the rounded sum's error is below 5 u sum|p| < 2^-50 sum|p|) decides
 * almost always; otherwise Shewchuk's GROW-EXPANSION with Knuth's TWO-SUM and zero
 * elimination ("Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric
 * Predicates", 1997): the sum is zero
 * iff no component survives. */
static int vx_bvh_sum6_is_zero(const double p[6])
{
    double s = 0.0, m = 0.0, e[7];
    int i, j, n = 0;
    for (i = 0; i < 6; i++) {
        s += p[i];
        m += fabs(p[i]);
    }
    if (m == 0.0) return 1;
    if (fabs(s) > m * 0x1p-50) return 0;
    for (i = 0; i < 6; i++) {
        double q = p[i];
        int k = 0;
        for (j = 0; j < n; j++) {
            double x = q + e[j], bv = x - q, av = x - bv;
            double err = (q - av) + (e[j] - bv);
            q = x;
            if (err != 0.0) e[k++] = err;
        }
        if (q != 0.0) e[k++] = q;
        n = k;
    }
    return n == 0;
}

/* 1 when (b - a) x (c - a) is exactly the zero vector (coincident or collinear vertices). Its
 * component (i, j) is a_i b_j - a_j b_i + b_i c_j - b_j c_i + c_i a_j - c_j a_i, each product
 * of two floats exact in double. */
static int vx_bvh_zero_area(const float *a, const float *b, const float *c)
{
    static const int ci[3] = {1, 2, 0}, cj[3] = {2, 0, 1};
    int k;
    for (k = 0; k < 3; k++) {
        int i = ci[k], j = cj[k];
        double p[6];
        p[0] = (double)a[i] * (double)b[j];
        p[1] = -((double)a[j] * (double)b[i]);
        p[2] = (double)b[i] * (double)c[j];
        p[3] = -((double)b[j] * (double)c[i]);
        p[4] = (double)c[i] * (double)a[j];
        p[5] = -((double)c[j] * (double)a[i]);
        if (!vx_bvh_sum6_is_zero(p)) return 0;
    }
    return 1;
}

/* Woop et al.'s listing for one triangle, hits accepted with t in [t_min, t_hi] (t_hi <= t_max:
 * callers pass their current best). Returns 1 and fills h (all but triangle) on a hit. */
static VX_BVH_INLINE int vx_bvh_tri(const vx_bvh_ray *r, const float *p0, const float *p1,
                                     const float *p2, float t_hi, hfvis_hit *h)
{
    const int kx = r->kx, ky = r->ky, kz = r->kz;
    float ax, ay, az, bx, by, bz, cx, cy, cz, Ax, Ay, Bx, By, Cx, Cy, U, V, W, det, T, t;
    /* "calculate vertices relative to ray origin": A = tri.A - org, ... */
    ax = p0[kx] - r->org[kx];
    ay = p0[ky] - r->org[ky];
    az = p0[kz] - r->org[kz];
    bx = p1[kx] - r->org[kx];
    by = p1[ky] - r->org[ky];
    bz = p1[kz] - r->org[kz];
    cx = p2[kx] - r->org[kx];
    cy = p2[ky] - r->org[ky];
    cz = p2[kz] - r->org[kz];
    /* shear: the ray becomes the +z axis ("Ax = A[kx] - Sx*A[kz]" ...) */
    Ax = ax - r->sx * az;
    Ay = ay - r->sy * az;
    Bx = bx - r->sx * bz;
    By = by - r->sy * bz;
    Cx = cx - r->sx * cz;
    Cy = cy - r->sy * cz;
    /* scaled barycentric coordinates = 2D edge functions ("U = Cx*By - Cy*Bx" ...) */
    U = Cx * By - Cy * Bx;
    V = Ax * Cy - Ay * Cx;
    W = Bx * Ay - By * Ax;
    /* "fallback to test against edges using double precision": an edge function that is exactly
     * 0 is recomputed in double, where the products of two floats are exact and the difference
     * is correctly rounded, so its sign is exact. (The float value's sign, when nonzero, is
     * already exact: rounding is monotonic.) */
    if (U == 0.0f || V == 0.0f || W == 0.0f) goto exact_path;
    /* inside iff U, V, W share a sign ("if ((U<0 || V<0 || W<0) && (U>0 || V>0 || W>0))
     * return"); a NaN (two overflowed products) passes here and is resolved below */
    if ((U < 0.0f || V < 0.0f || W < 0.0f) && (U > 0.0f || V > 0.0f || W > 0.0f)) return 0;
    det = U + V + W;
    if (!(fabsf(det) <= FLT_MAX)) goto exact_path; /* overflow or NaN: redo in double */
    if (r->cull == HFVIS_CULL_BACK && det < 0.0f) return 0;
    if (r->cull == HFVIS_CULL_FRONT && det > 0.0f) return 0;
    /* scaled hit distance ("Az = Sz*A[kz]" ..., "T = U*Az + V*Bz + W*Cz") and t = T/det */
    T = U * (r->sz * az) + V * (r->sz * bz) + W * (r->sz * cz);
    t = T / det;
    if (!(fabsf(t) <= FLT_MAX)) goto exact_path;
    if (!(t >= r->t_min) || !(t <= t_hi)) return 0;
    if (vx_bvh_zero_area(p0, p1, p2)) return 0;
    h->t = t;
    h->u = V / det;
    h->v = W / det;
    h->front = det > 0.0f;
    return 1;
exact_path: {
        double Ud = (double)Cx * (double)By - (double)Cy * (double)Bx;
        double Vd = (double)Ax * (double)Cy - (double)Ay * (double)Cx;
        double Wd = (double)Bx * (double)Ay - (double)By * (double)Ax;
        double dd, Td, td;
        if ((Ud < 0.0 || Vd < 0.0 || Wd < 0.0) && (Ud > 0.0 || Vd > 0.0 || Wd > 0.0)) return 0;
        dd = Ud + Vd + Wd;
        if (dd == 0.0 || !(fabs(dd) <= DBL_MAX)) return 0; /* edge-on (or not finite) */
        if (r->cull == HFVIS_CULL_BACK && dd < 0.0) return 0;
        if (r->cull == HFVIS_CULL_FRONT && dd > 0.0) return 0;
        Td = Ud * ((double)r->sz * (double)az) + Vd * ((double)r->sz * (double)bz)
             + Wd * ((double)r->sz * (double)cz);
        td = Td / dd;
        if (!(fabs(td) <= (double)FLT_MAX)) return 0;
        t = (float)td;
        if (!(t >= r->t_min) || !(t <= t_hi)) return 0;
        if (vx_bvh_zero_area(p0, p1, p2)) return 0;
        h->t = t;
        h->u = (float)(Vd / dd);
        h->v = (float)(Wd / dd);
        h->front = dd > 0.0;
        return 1;
    }
}

HFVIS_API hfvis_status hfvis_ray_triangle(const hfvis_ray *ray, const float v0[3],
                                          const float v1[3], const float v2[3], hfvis_hit *hit)
{
    vx_bvh_ray r;
    hfvis_hit h;
    int a;
    if (!vx_bvh_ray_valid(ray) || !v0 || !v1 || !v2 || !hit) return HFVIS_ERR_INVALID_ARGUMENT;
    for (a = 0; a < 3; a++)
        if (!isfinite(v0[a]) || !isfinite(v1[a]) || !isfinite(v2[a]))
            return HFVIS_ERR_INVALID_ARGUMENT;
    vx_bvh_ray_setup(ray, &r);
    if (vx_bvh_tri(&r, v0, v1, v2, r.t_max, &h)) {
        h.triangle = 0;
        *hit = h;
    } else {
        vx_bvh_miss(hit);
    }
    return HFVIS_OK;
}

/* ---- 2a.3 naive oracle ---------------------------------------------------------------------- */

static int vx_bvh_query_valid(hfvis_ray_query q)
{
    return q == HFVIS_RAY_CLOSEST || q == HFVIS_RAY_ANY;
}

HFVIS_API hfvis_status hfvis_ray_intersect_naive(const hfvis_mesh *mesh, const hfvis_ray *ray,
                                                 hfvis_ray_query query, hfvis_hit_filter filter,
                                                 void *user, hfvis_hit *hit)
{
    vx_bvh_ray r;
    hfvis_hit best, h;
    size_t t, nv;
    if (!mesh || !hit || !vx_bvh_ray_valid(ray) || !vx_bvh_query_valid(query))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if ((mesh->vertex_count && !mesh->xyz) || (mesh->triangle_count && !mesh->indices))
        return HFVIS_ERR_INVALID_ARGUMENT;
    vx_bvh_ray_setup(ray, &r);
    vx_bvh_miss(&best);
    best.t = r.t_max;
    nv = mesh->vertex_count;
    for (t = 0; t < mesh->triangle_count; t++) {
        const uint32_t *ix = mesh->indices + 3 * t;
        if (ix[0] >= nv || ix[1] >= nv || ix[2] >= nv) return HFVIS_ERR_INVALID_ARGUMENT;
        /* in index order, "t < best" is the closest-hit order (ties keep the lower index) */
        if (!vx_bvh_tri(&r, mesh->xyz + 3 * (size_t)ix[0], mesh->xyz + 3 * (size_t)ix[1],
                        mesh->xyz + 3 * (size_t)ix[2], best.t, &h))
            continue;
        if (best.triangle != HFVIS_NO_TRIANGLE && !(h.t < best.t)) continue;
        h.triangle = (uint32_t)t;
        if (filter && !filter(user, ray, &h)) continue;
        best = h;
        if (query == HFVIS_RAY_ANY) break;
    }
    if (best.triangle == HFVIS_NO_TRIANGLE) vx_bvh_miss(&best);
    *hit = best;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_ray_closest_naive(const hfvis_mesh *mesh, const hfvis_ray *ray,
                                               hfvis_hit *hit)
{
    return hfvis_ray_intersect_naive(mesh, ray, HFVIS_RAY_CLOSEST, NULL, NULL, hit);
}

HFVIS_API hfvis_status hfvis_ray_any_naive(const hfvis_mesh *mesh, const hfvis_ray *ray,
                                           hfvis_hit *hit)
{
    return hfvis_ray_intersect_naive(mesh, ray, HFVIS_RAY_ANY, NULL, NULL, hit);
}

/* ---- 2a.4 binned SAH build ----------------------------------------------------------------- */

HFVIS_API hfvis_bvh_options hfvis_bvh_options_default(void)
{
    hfvis_bvh_options o;
    memset(&o, 0, sizeof o);
    o.max_leaf_size = HFVIS_BVH_DEFAULT_LEAF_SIZE;
    o.bins = HFVIS_BVH_DEFAULT_BINS;
    return o;
}

typedef struct vx_bvh_prim {
    float lo[3], hi[3]; /* float bounding box of the triangle (exact: min/max of its vertices) */
} vx_bvh_prim;

typedef struct vx_bvh_task {
    uint32_t node, begin, end;
    int depth;
} vx_bvh_task;

typedef struct vx_bvh_bin {
    float lo[3], hi[3];
    uint32_t count;
} vx_bvh_bin;

/* Centroid of a triangle's box on axis a, doubled (lo + hi, in double: no overflow). */
static double vx_bvh_cen(const vx_bvh_prim *p, int a)
{
    return (double)p->lo[a] + (double)p->hi[a];
}

static double vx_bvh_area(const float lo[3], const float hi[3])
{
    double dx = (double)hi[0] - (double)lo[0], dy = (double)hi[1] - (double)lo[1],
           dz = (double)hi[2] - (double)lo[2];
    return 2.0 * (dx * dy + dy * dz + dz * dx);
}

static void vx_bvh_grow(float lo[3], float hi[3], const float plo[3], const float phi[3])
{
    int a;
    for (a = 0; a < 3; a++) {
        if (plo[a] < lo[a]) lo[a] = plo[a];
        if (phi[a] > hi[a]) hi[a] = phi[a];
    }
}

/* Bin of a (doubled) centroid c on an axis with bounds [cmin, cmax], cmax > cmin. */
static int vx_bvh_bin_of(double c, double cmin, double scale, int bins)
{
    int b = (int)((c - cmin) * scale);
    if (b < 0) b = 0;
    if (b > bins - 1) b = bins - 1;
    return b;
}

/* Key order of the median split: centroid on axis a, then triangle index. */
static int vx_bvh_less(const vx_bvh_prim *prims, uint32_t x, uint32_t y, int a)
{
    double cx = vx_bvh_cen(prims + x, a), cy = vx_bvh_cen(prims + y, a);
    return cx < cy || (cx == cy && x < y);
}

/* Swap *x and *y unless *x comes first. */
static void vx_bvh_order2(const vx_bvh_prim *prims, uint32_t *x, uint32_t *y, int a)
{
    if (vx_bvh_less(prims, *y, *x, a)) {
        uint32_t t = *x;
        *x = *y;
        *y = t;
    }
}

/* Rearrange idx[0..n) so that idx[k] holds the k-th smallest key and smaller keys come before
 * it (deterministic quickselect, median-of-three pivot, Lomuto partition). */
static void vx_bvh_select(const vx_bvh_prim *prims, uint32_t *idx, size_t n, size_t k, int a)
{
    size_t lo = 0, hi = n - 1;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2, i, store;
        uint32_t tmp, piv;
        /* median of three into position hi */
        vx_bvh_order2(prims, idx + lo, idx + mid, a);
        vx_bvh_order2(prims, idx + lo, idx + hi, a);
        vx_bvh_order2(prims, idx + hi, idx + mid, a); /* lo <= hi <= mid: pivot idx[hi] */
        piv = idx[hi];
        store = lo;
        for (i = lo; i < hi; i++)
            if (vx_bvh_less(prims, idx[i], piv, a)) {
                tmp = idx[i];
                idx[i] = idx[store];
                idx[store] = tmp;
                store++;
            }
        idx[hi] = idx[store];
        idx[store] = piv;
        if (store == k) return;
        if (k < store) hi = store - 1;
        else lo = store + 1;
    }
}

/* Pad a finished node box outward (see hfvis_bvh_node). */
static void vx_bvh_pad(hfvis_bvh_node *n)
{
    double m = 0.0, pad;
    int a;
    for (a = 0; a < 3; a++) {
        double l = fabs((double)n->lo[a]), h = fabs((double)n->hi[a]);
        double e = (double)n->hi[a] - (double)n->lo[a];
        if (l > m) m = l;
        if (h > m) m = h;
        if (e > m) m = e;
    }
    pad = m * VX_BVH_PAD;
    for (a = 0; a < 3; a++) {
        double l = (double)n->lo[a] - pad, h = (double)n->hi[a] + pad;
        /* rounded to float away from the box (the double values are within float range unless
         * the box reaches FLT_MAX, which gives +-infinity) */
        float lf = l < -(double)FLT_MAX ? -INFINITY : (float)l;
        float hf = h > (double)FLT_MAX ? INFINITY : (float)h;
        if ((double)lf > l) lf = nextafterf(lf, -INFINITY);
        if ((double)hf < h) hf = nextafterf(hf, INFINITY);
        n->lo[a] = lf;
        n->hi[a] = hf;
    }
}

HFVIS_API hfvis_status hfvis_bvh_build(const hfvis_mesh *mesh, const hfvis_bvh_options *opts,
                                       hfvis_bvh *out)
{
    const hfvis_allocator *alloc = opts ? opts->alloc : NULL;
    int max_leaf = opts && opts->max_leaf_size ? opts->max_leaf_size : HFVIS_BVH_DEFAULT_LEAF_SIZE;
    int bins = opts && opts->bins ? opts->bins : HFVIS_BVH_DEFAULT_BINS;
    size_t n, i, max_nodes, next, leaves = 0;
    uint32_t *order = NULL;
    vx_bvh_prim *prims = NULL;
    hfvis_bvh_node *tmp = NULL, *nodes = NULL;
    vx_bvh_task stack[HFVIS_BVH_MAX_DEPTH + 2];
    int sp = 0, max_depth = 0;
    hfvis_status st;

    if (!out || max_leaf < 1 || max_leaf > HFVIS_BVH_MAX_LEAF_SIZE || bins < 2
        || bins > HFVIS_BVH_MAX_BINS)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (!mesh) return HFVIS_ERR_INVALID_ARGUMENT;
    n = mesh->triangle_count;
    if (n > HFVIS_BVH_MAX_TRIANGLES) return HFVIS_ERR_LIMIT; /* before reading the arrays */
    st = vx_mesh_check(mesh);
    if (st != HFVIS_OK) return st;
    if (n == 0) {
        memset(out, 0, sizeof *out);
        out->max_leaf_size = max_leaf;
        return HFVIS_OK;
    }
    max_nodes = 2 * n - 1;
    order = (uint32_t *)vx_alloc_array(alloc, n, sizeof *order);
    if (!order) goto oom;
    prims = (vx_bvh_prim *)vx_alloc_array(alloc, n, sizeof *prims);
    if (!prims) goto oom;
    tmp = (hfvis_bvh_node *)vx_alloc_array(alloc, max_nodes, sizeof *tmp);
    if (!tmp) goto oom;

    for (i = 0; i < n; i++) {
        const uint32_t *ix = mesh->indices + 3 * i;
        const float *p0 = mesh->xyz + 3 * (size_t)ix[0], *p1 = mesh->xyz + 3 * (size_t)ix[1],
                    *p2 = mesh->xyz + 3 * (size_t)ix[2];
        int a;
        for (a = 0; a < 3; a++) {
            float lo = p0[a], hi = p0[a];
            if (p1[a] < lo) lo = p1[a];
            if (p1[a] > hi) hi = p1[a];
            if (p2[a] < lo) lo = p2[a];
            if (p2[a] > hi) hi = p2[a];
            prims[i].lo[a] = lo;
            prims[i].hi[a] = hi;
        }
        order[i] = (uint32_t)i;
    }

    next = 1;
    stack[0].node = 0;
    stack[0].begin = 0;
    stack[0].end = (uint32_t)n;
    stack[0].depth = 1;
    sp = 1;
    while (sp > 0) {
        vx_bvh_task task = stack[--sp];
        hfvis_bvh_node *node = tmp + task.node;
        size_t count = task.end - task.begin, mid = 0;
        double cmin[3], cmax[3], area;
        int a, split = 0, median = 0;
        uint32_t *idx = order + task.begin;
        /* node box and centroid bounds: O(count) */
        for (a = 0; a < 3; a++) {
            node->lo[a] = prims[idx[0]].lo[a];
            node->hi[a] = prims[idx[0]].hi[a];
            cmin[a] = cmax[a] = vx_bvh_cen(prims + idx[0], a);
        }
        for (i = 1; i < count; i++) {
            const vx_bvh_prim *p = prims + idx[i];
            vx_bvh_grow(node->lo, node->hi, p->lo, p->hi);
            for (a = 0; a < 3; a++) {
                double c = vx_bvh_cen(p, a);
                if (c < cmin[a]) cmin[a] = c;
                if (c > cmax[a]) cmax[a] = c;
            }
        }
        if (task.depth > max_depth) max_depth = task.depth;
        area = vx_bvh_area(node->lo, node->hi);
        if (count > 1) {
            int degenerate = (cmax[0] == cmin[0] && cmax[1] == cmin[1] && cmax[2] == cmin[2])
                             || !(area > 0.0) || !(area <= DBL_MAX);
            if (task.depth >= HFVIS_BVH_SAH_DEPTH || degenerate) {
                /* deep or degenerate nodes: leaf if small enough, else median split */
                median = count > (size_t)max_leaf;
            } else {
                /* binned SAH over every axis with a centroid extent (Wald 2007) */
                vx_bvh_bin bin[HFVIS_BVH_MAX_BINS];
                double right_area[HFVIS_BVH_MAX_BINS];
                uint32_t right_count[HFVIS_BVH_MAX_BINS];
                double best = HUGE_VAL, scale_best = 0.0;
                int best_axis = -1, best_bin = -1, b;
                for (a = 0; a < 3; a++) {
                    double scale;
                    float llo[3], lhi[3];
                    uint32_t lc = 0;
                    if (!(cmax[a] > cmin[a])) continue;
                    scale = (double)bins * (1.0 - 0x1p-40) / (cmax[a] - cmin[a]);
                    for (b = 0; b < bins; b++) {
                        bin[b].count = 0;
                        bin[b].lo[0] = bin[b].lo[1] = bin[b].lo[2] = INFINITY;
                        bin[b].hi[0] = bin[b].hi[1] = bin[b].hi[2] = -INFINITY;
                    }
                    for (i = 0; i < count; i++) {
                        const vx_bvh_prim *p = prims + idx[i];
                        b = vx_bvh_bin_of(vx_bvh_cen(p, a), cmin[a], scale, bins);
                        bin[b].count++;
                        vx_bvh_grow(bin[b].lo, bin[b].hi, p->lo, p->hi);
                    }
                    /* sweep from the right: boxes and counts of bins b+1..bins-1 */
                    {
                        float rlo[3] = {INFINITY, INFINITY, INFINITY},
                              rhi[3] = {-INFINITY, -INFINITY, -INFINITY};
                        uint32_t rc = 0;
                        for (b = bins - 1; b > 0; b--) {
                            if (bin[b].count) vx_bvh_grow(rlo, rhi, bin[b].lo, bin[b].hi);
                            rc += bin[b].count;
                            right_count[b - 1] = rc;
                            right_area[b - 1] = rc ? vx_bvh_area(rlo, rhi) : 0.0;
                        }
                    }
                    llo[0] = llo[1] = llo[2] = INFINITY;
                    lhi[0] = lhi[1] = lhi[2] = -INFINITY;
                    for (b = 0; b < bins - 1; b++) {
                        double cost;
                        if (bin[b].count) vx_bvh_grow(llo, lhi, bin[b].lo, bin[b].hi);
                        lc += bin[b].count;
                        if (lc == 0 || right_count[b] == 0) continue;
                        cost = vx_bvh_area(llo, lhi) * (double)lc
                               + right_area[b] * (double)right_count[b];
                        if (cost < best) {
                            best = cost;
                            best_axis = a;
                            best_bin = b;
                            scale_best = scale;
                        }
                    }
                }
                if (best_axis < 0) {
                    median = count > (size_t)max_leaf; /* unreachable: some extent is > 0 */
                } else {
                    double split_cost = VX_BVH_C_TRAV + VX_BVH_C_TRI * best / area;
                    if (count > (size_t)max_leaf || !(VX_BVH_C_TRI * (double)count <= split_cost)) {
                        /* partition by bin: bins <= best_bin go left */
                        size_t lo = 0, hi = count;
                        a = best_axis;
                        while (lo < hi) {
                            if (vx_bvh_bin_of(vx_bvh_cen(prims + idx[lo], a), cmin[a], scale_best,
                                              bins) <= best_bin) {
                                lo++;
                            } else {
                                uint32_t t = idx[lo];
                                idx[lo] = idx[--hi];
                                idx[hi] = t;
                            }
                        }
                        mid = lo;
                        split = 1;
                        HFVIS_ASSERT(mid > 0 && mid < count);
                    }
                }
            }
            if (median) {
                int ax = 0;
                for (a = 1; a < 3; a++)
                    if (cmax[a] - cmin[a] > cmax[ax] - cmin[ax]) ax = a;
                mid = count / 2;
                vx_bvh_select(prims, idx, count, mid, ax);
                split = 1;
            }
        }
        if (!split) {
            node->left_or_first = task.begin;
            node->count = (uint32_t)count;
            leaves++;
            continue;
        }
        HFVIS_ASSERT(next + 2 <= max_nodes && sp + 2 <= HFVIS_BVH_MAX_DEPTH + 2);
        node->left_or_first = (uint32_t)next;
        node->count = 0;
        /* right first on the stack, so the left subtree is built (and numbered) first */
        stack[sp].node = (uint32_t)(next + 1);
        stack[sp].begin = task.begin + (uint32_t)mid;
        stack[sp].end = task.end;
        stack[sp].depth = task.depth + 1;
        stack[sp + 1].node = (uint32_t)next;
        stack[sp + 1].begin = task.begin;
        stack[sp + 1].end = task.begin + (uint32_t)mid;
        stack[sp + 1].depth = task.depth + 1;
        sp += 2;
        next += 2;
    }
    HFVIS_ASSERT(max_depth <= HFVIS_BVH_MAX_DEPTH);

    nodes = (hfvis_bvh_node *)vx_alloc_array(alloc, next, sizeof *nodes);
    if (!nodes) goto oom;
    for (i = 0; i < next; i++) {
        nodes[i] = tmp[i];
        vx_bvh_pad(nodes + i);
    }
    vx_free(alloc, tmp);
    vx_free(alloc, prims);
    out->nodes = nodes;
    out->node_count = next;
    out->tri_order = order;
    out->triangle_count = n;
    out->leaf_count = leaves;
    out->depth = max_depth;
    out->max_leaf_size = max_leaf;
    return HFVIS_OK;
oom:
    vx_free(alloc, tmp);
    vx_free(alloc, prims);
    vx_free(alloc, order);
    return HFVIS_ERR_OUT_OF_MEMORY;
}

HFVIS_API void hfvis_bvh_free(const hfvis_allocator *alloc, hfvis_bvh *bvh)
{
    if (!bvh) return;
    vx_free(alloc, bvh->nodes);
    vx_free(alloc, bvh->tri_order);
    memset(bvh, 0, sizeof *bvh);
}

/* ---- 2a.5 traversal ------------------------------------------------------------------------- */

/* Robust slab test (Ize 2013): entry distance max(t_min, near planes), exit distance
 * min(far planes) * VX_BVH_SLACK; a NaN from 0 * infinity (ray in a slab's plane, zero
 * direction component) is ignored by the comparisons, which is the right answer for a ray on
 * the (closed) slab boundary. Hit when entry <= exit and entry <= t_hi (the widened best). */
static VX_BVH_INLINE int vx_bvh_box(const hfvis_bvh_node *n, const vx_bvh_ray *r, float t_hi,
                                     float *entry)
{
    float tn = r->t_min, tf = INFINITY, t0, t1;
    t0 = ((r->neg[0] ? n->hi[0] : n->lo[0]) - r->org[0]) * r->inv[0];
    t1 = ((r->neg[0] ? n->lo[0] : n->hi[0]) - r->org[0]) * r->inv[0];
    tn = t0 > tn ? t0 : tn;
    tf = t1 < tf ? t1 : tf;
    t0 = ((r->neg[1] ? n->hi[1] : n->lo[1]) - r->org[1]) * r->inv[1];
    t1 = ((r->neg[1] ? n->lo[1] : n->hi[1]) - r->org[1]) * r->inv[1];
    tn = t0 > tn ? t0 : tn;
    tf = t1 < tf ? t1 : tf;
    t0 = ((r->neg[2] ? n->hi[2] : n->lo[2]) - r->org[2]) * r->inv[2];
    t1 = ((r->neg[2] ? n->lo[2] : n->hi[2]) - r->org[2]) * r->inv[2];
    tn = t0 > tn ? t0 : tn;
    tf = t1 < tf ? t1 : tf;
    tf *= VX_BVH_SLACK;
    *entry = tn;
    return tn <= tf && tn <= t_hi;
}

HFVIS_API hfvis_status hfvis_bvh_intersect(const hfvis_bvh *bvh, const hfvis_mesh *mesh,
                                           const hfvis_ray *ray, hfvis_ray_query query,
                                           hfvis_hit_filter filter, void *user, hfvis_hit *hit)
{
    vx_bvh_ray r;
    hfvis_hit best, h;
    uint32_t stack_node[HFVIS_BVH_MAX_DEPTH + 1];
    float stack_t[HFVIS_BVH_MAX_DEPTH + 1];
    int sp = 0;
    const hfvis_bvh_node *nodes;
    const uint32_t *order, *indices;
    const float *xyz;
    size_t nv, ntri;
    uint32_t ni = 0;
    float t_hi, entry;
    const int any = query == HFVIS_RAY_ANY;

    if (!bvh || !mesh || !hit || !vx_bvh_ray_valid(ray) || !vx_bvh_query_valid(query))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (bvh->triangle_count != mesh->triangle_count || bvh->depth < 0
        || bvh->depth > HFVIS_BVH_MAX_DEPTH || (bvh->node_count && (!bvh->nodes || !bvh->tri_order))
        || (mesh->vertex_count && !mesh->xyz) || (mesh->triangle_count && !mesh->indices))
        return HFVIS_ERR_INVALID_ARGUMENT;
    vx_bvh_ray_setup(ray, &r);
    vx_bvh_miss(&best);
    best.t = r.t_max;
    t_hi = r.t_max * VX_BVH_SLACK;
    nodes = bvh->nodes;
    order = bvh->tri_order;
    indices = mesh->indices;
    xyz = mesh->xyz;
    nv = mesh->vertex_count;
    ntri = bvh->triangle_count;
    if (bvh->node_count == 0 || !vx_bvh_box(nodes, &r, t_hi, &entry)) goto done;
    for (;;) {
        const hfvis_bvh_node *n = nodes + ni;
        if (n->count) {
            uint32_t k, first = n->left_or_first, end = first + n->count;
            if (end < first || end > ntri) return HFVIS_ERR_INVALID_ARGUMENT; /* corrupt bvh */
            for (k = first; k < end; k++) {
                uint32_t tri = order[k];
                const uint32_t *ix = indices + 3 * (size_t)tri;
                if (tri >= ntri || ix[0] >= nv || ix[1] >= nv || ix[2] >= nv)
                    return HFVIS_ERR_INVALID_ARGUMENT;
                if (!vx_bvh_tri(&r, xyz + 3 * (size_t)ix[0], xyz + 3 * (size_t)ix[1],
                                xyz + 3 * (size_t)ix[2], best.t, &h))
                    continue;
                /* closest-hit order: smaller t, equal t -> lower index (as the naive loop) */
                if (best.triangle != HFVIS_NO_TRIANGLE && !(h.t < best.t || tri < best.triangle))
                    continue;
                h.triangle = tri;
                if (filter && !filter(user, ray, &h)) continue;
                best = h;
                if (any) goto done;
                t_hi = best.t * VX_BVH_SLACK;
            }
        } else {
            uint32_t left = n->left_or_first;
            float e0, e1;
            int h0, h1;
            /* children follow their parent (so every path ends) and lie inside the array */
            if (left <= ni || (size_t)left + 1 >= bvh->node_count)
                return HFVIS_ERR_INVALID_ARGUMENT;
            h0 = vx_bvh_box(nodes + left, &r, t_hi, &e0);
            h1 = vx_bvh_box(nodes + left + 1, &r, t_hi, &e1);
            if (h0 && h1) {
                if (sp >= HFVIS_BVH_MAX_DEPTH) return HFVIS_ERR_INVALID_ARGUMENT; /* corrupt bvh */
                if (e1 < e0) {
                    stack_node[sp] = left;
                    stack_t[sp++] = e0;
                    ni = left + 1;
                } else {
                    stack_node[sp] = left + 1;
                    stack_t[sp++] = e1;
                    ni = left;
                }
                continue;
            }
            if (h0) {
                ni = left;
                continue;
            }
            if (h1) {
                ni = left + 1;
                continue;
            }
        }
        /* pop the next pushed node that can still hold a hit no farther than the best */
        for (;;) {
            if (sp == 0) goto done;
            --sp;
            if (stack_t[sp] <= t_hi) break;
        }
        ni = stack_node[sp];
    }
done:
    if (best.triangle == HFVIS_NO_TRIANGLE) vx_bvh_miss(&best);
    *hit = best;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_bvh_closest_hit(const hfvis_bvh *bvh, const hfvis_mesh *mesh,
                                             const hfvis_ray *ray, hfvis_hit *hit)
{
    return hfvis_bvh_intersect(bvh, mesh, ray, HFVIS_RAY_CLOSEST, NULL, NULL, hit);
}

HFVIS_API hfvis_status hfvis_bvh_any_hit(const hfvis_bvh *bvh, const hfvis_mesh *mesh,
                                         const hfvis_ray *ray, hfvis_hit *hit)
{
    return hfvis_bvh_intersect(bvh, mesh, ray, HFVIS_RAY_ANY, NULL, NULL, hit);
}
