/* ========================================================================================== */
/* 3a. Surface voxelization into the Volume Buffer                                            */
/*     [G12] ch. 6 (§6.4.1 Alg. 5 geometry-shader triangle slicing, §6.4.2 Alg. 6 pixel-shader */
/*     fragment clipping, §6.6 output-vertex limit), ch. 5 §5.5.1 Alg. 4 (three axial passes   */
/*     merged with MAX); spec voxel §3.4-3.8, §3.12-3.13                                       */
/* ========================================================================================== */
/*
 * Everything happens in grid space g = (p - origin)/cell, where a voxel is a unit cube. A pass
 * along axis a sees the triangle projected onto the (u, w) = (a+1, a+2 mod 3) plane; its pixel
 * (pu, pw) has centre (pu + 0.5, pw + 0.5) and the voxel column of that pixel is cut into slabs
 * [k, k+1) along a (the GPU's layers).
 *
 * Exactness. The fast routines and the oracle evaluate the same predicates with the same
 * floating-point expressions:
 *   inside(c) = every edge function > 0, or == 0 on a top-left edge;
 *   slab(c)   = floor(clamp(depth(c), zlo, zhi)).
 * For a fixed row (fixed cw) every edge function, and the depth, is a composition of rounded
 * subtractions and multiplications by constants of cu, hence monotone in cu (IEEE rounding is
 * monotone). So each predicate holds on a prefix or a suffix of the row, the covered pixels of a
 * row are one interval and the slab is monotone along it: the fast path finds the interval ends
 * and the slab changes by a guessed-then-verified search (about two predicate evaluations each)
 * and writes every fragment between them without testing it again (rows narrower than
 * VX_VOX_DIRECT_WIDTH are tested pixel by pixel, and on rows steeper than VX_VOX_STEEP each
 * pixel's slab is evaluated: cheaper there, and the same expressions). The oracle tests every
 * voxel of the bounding box directly. Both therefore select exactly the same voxels, and since
 * within one triangle and pass no voxel is written twice and triangles are processed in the
 * same order, the blended values agree bit for bit too.
 */

#define VX_VOX_MAX_COORD 1e150 /* beyond: products of coordinates could overflow double */
#define VX_VOX_MAX_SLOPE 1e100 /* beyond: the triangle is edge-on to the pass (to precision) */
/* Rows whose candidate span is narrower than this are tested pixel by pixel (with the same
 * predicate): cheaper than the boundary search for the small triangles of dense meshes. */
#define VX_VOX_DIRECT_WIDTH 4
/* Rows whose depth changes by more than this per pixel (runs of constant slab shorter than
 * 1/VX_VOX_STEEP pixels) get each pixel's slab evaluated (same formula) instead of searched. */
#define VX_VOX_STEEP 0.25

/* One directed edge A -> B of a counter-clockwise polygon in the (u, w) plane. The edge function
 * is evaluated from the lexicographically smaller endpoint `l` with d = (larger - smaller) and
 * multiplied by sign = +1 (A is the smaller) or -1, so the two directions of one segment give
 * exactly opposite values (a shared edge of two triangles never covers a pixel twice or not at
 * all). E(c) > 0 left of A -> B, i.e. inside. */
typedef struct vx_vox_edge {
    double lu, lw, du, dw, sign;
    double root_du; /* du/dw (0 when dw == 0): d(root u)/d(row w), only for search estimates */
    int owned; /* top-left rule: centres exactly on the edge are inside */
    int skip;  /* zero-length edge (duplicate polygon vertex): no constraint */
} vx_vox_edge;

static void vx_vox_edge_init(vx_vox_edge *e, double au, double aw, double bu, double bw)
{
    /* (root_du is filled by vx_vox_edge_root, only for rows wide enough to be searched) */
    int a_small = au < bu || (au == bu && aw < bw);
    double su = a_small ? au : bu, sw = a_small ? aw : bw;
    double gu = a_small ? bu : au, gw = a_small ? bw : aw;
    double tu, tw;
    e->lu = su;
    e->lw = sw;
    e->du = gu - su;
    e->dw = gw - sw;
    e->sign = a_small ? 1.0 : -1.0;
    e->skip = au == bu && aw == bw;
    e->root_du = 0.0;
    /* traversal direction B - A (exact sign of the rounded difference) */
    tu = e->sign * e->du;
    tw = e->sign * e->dw;
    /* counter-clockwise with w up: a "left" edge goes down, a "top" edge goes left */
    e->owned = tw < 0.0 || (tw == 0.0 && tu < 0.0);
}

/* The search estimate's slope du/dw of an edge (rows searched, not tested pixel by pixel). */
static void vx_vox_edge_root(vx_vox_edge *e)
{
    e->root_du = e->dw != 0.0 ? e->du / e->dw : 0.0;
}

static double vx_vox_edge_value(const vx_vox_edge *e, double cu, double cw)
{
    return e->sign * (e->du * (cw - e->lw) - e->dw * (cu - e->lu));
}

static int vx_vox_edge_pass(const vx_vox_edge *e, double cu, double cw)
{
    double v;
    if (e->skip) return 1;
    v = vx_vox_edge_value(e, cu, cw);
    return v > 0.0 || (v == 0.0 && e->owned);
}

/* A triangle prepared for voxelization (grid space, double). */
typedef struct vx_vox_tri {
    uint32_t id;
    double v[3][3];  /* world vertices */
    double g[3][3];  /* grid-space vertices */
    double n[3];     /* grid-space normal (g1 - g0) x (g2 - g0) */
    float normal[3]; /* unit world normal (only filled when fragments are delivered) */
} vx_vox_tri;

/* The triangle in the pass along axis a. */
typedef struct vx_vox_pass {
    int a, u, w;
    double U[3], W[3], Z[3]; /* projected vertices (original order) and depths */
    double area2;            /* n[a]: twice the signed projected area */
    vx_vox_edge e[3];        /* counter-clockwise edges */
    int edir[3];             /* sign of d(edge function)/du: +1 inside on a row suffix, -1 prefix */
    double q[3][3];          /* counter-clockwise vertices (U, W, Z) */
    double dzdu, dzdw;       /* depth slopes of the plane */
    double dudz;             /* 1/dzdu (0 if dzdu == 0), only for search estimates */
    double zlo, zhi;         /* depth range */
    int bu0, bu1, bw0, bw1;  /* pixel bounding box of the triangle within the grid */
    int k0, k1;              /* slabs floor(zlo) .. floor(zhi) within the grid (and the cap) */
} vx_vox_pass;

/* floor / ceil of x as int, for |x| < 2^31 (callers clamp first; libm's floor is a call on
 * baseline x86-64). */
static int vx_vox_ifloor(double x)
{
    int i = (int)x;
    return (double)i > x ? i - 1 : i;
}
static int vx_vox_iceil(double x)
{
    int i = (int)x;
    return (double)i < x ? i + 1 : i;
}

/* Pixel range [*i0, *i1] whose centres i + 0.5 lie in [lo, hi], within [0, n); 0 if empty:
 * i0 = max(0, ceil(lo - 0.5)), i1 = min(n - 1, floor(hi - 0.5)). */
static int vx_vox_pixel_range(double lo, double hi, int n, int *i0, int *i1)
{
    double a = lo - 0.5, b = hi - 0.5;
    if (!(b >= 0.0) || !(a <= (double)(n - 1))) return 0;
    *i0 = a <= 0.0 ? 0 : vx_vox_iceil(a);
    *i1 = b >= (double)(n - 1) ? n - 1 : vx_vox_ifloor(b);
    return *i0 <= *i1;
}

/* Grid-space setup of triangle t; 0 if it is degenerate or out of range (skipped). */
static int vx_vox_tri_setup(vx_vox_tri *T, const hfvis_mesh *m, const hfvis_volume_grid *g,
                            size_t t, int want_normal)
{
    int i, a;
    double e1[3], e2[3];
    T->id = (uint32_t)t;
    for (i = 0; i < 3; i++) {
        const float *p = m->xyz + 3 * (size_t)m->indices[3 * t + (size_t)i];
        for (a = 0; a < 3; a++) T->g[i][a] = ((double)p[a] - g->origin[a]) / g->cell[a];
        if (want_normal)
            for (a = 0; a < 3; a++) T->v[i][a] = (double)p[a];
    }
    {
        double big = 0.0; /* largest |coordinate| (NaN-free: the mesh and grid are finite) */
        for (i = 0; i < 3; i++)
            for (a = 0; a < 3; a++) big = fabs(T->g[i][a]) > big ? fabs(T->g[i][a]) : big;
        if (!(big <= VX_VOX_MAX_COORD)) return 0;
    }
    for (a = 0; a < 3; a++) {
        e1[a] = T->g[1][a] - T->g[0][a];
        e2[a] = T->g[2][a] - T->g[0][a];
    }
    T->n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    T->n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    T->n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    if (T->n[0] == 0.0 && T->n[1] == 0.0 && T->n[2] == 0.0) return 0;
    if (want_normal) {
        double w1[3], w2[3], nw[3], len;
        for (a = 0; a < 3; a++) {
            w1[a] = T->v[1][a] - T->v[0][a];
            w2[a] = T->v[2][a] - T->v[0][a];
        }
        nw[0] = w1[1] * w2[2] - w1[2] * w2[1];
        nw[1] = w1[2] * w2[0] - w1[0] * w2[2];
        nw[2] = w1[0] * w2[1] - w1[1] * w2[0];
        len = sqrt(nw[0] * nw[0] + nw[1] * nw[1] + nw[2] * nw[2]);
        for (a = 0; a < 3; a++) T->normal[a] = len > 0.0 ? (float)(nw[a] / len) : 0.0f;
    }
    return 1;
}

/* Dominant axis of the grid-space normal (spec §3.4, §3.12: ties -> lowest index). */
static int vx_vox_dominant(const double n[3])
{
    int a = 0;
    if (fabs(n[1]) > fabs(n[a])) a = 1;
    if (fabs(n[2]) > fabs(n[a])) a = 2;
    return a;
}

/* Set up the pass of T along axis a; max_slices > 0 caps the slabs at kmin + max_slices - 1.
 * Returns 0 when the pass writes nothing (edge-on, outside the grid). */
static int vx_vox_pass_setup(vx_vox_pass *p, const vx_vox_tri *T, int a, const int dims[3],
                             int max_slices)
{
    int i, swap;
    double ulo, uhi, wlo, whi;
    p->a = a;
    p->u = a == 2 ? 0 : a + 1;
    p->w = a == 0 ? 2 : a - 1;
    p->area2 = T->n[a];
    if (p->area2 == 0.0) return 0;
    for (i = 0; i < 3; i++) {
        p->U[i] = T->g[i][p->u];
        p->W[i] = T->g[i][p->w];
        p->Z[i] = T->g[i][a];
    }
    /* cheap rejections first: most triangles of a dense mesh cover no pixel centre */
    ulo = uhi = p->U[0];
    wlo = whi = p->W[0];
    p->zlo = p->zhi = p->Z[0];
    for (i = 1; i < 3; i++) {
        ulo = p->U[i] < ulo ? p->U[i] : ulo;
        uhi = p->U[i] > uhi ? p->U[i] : uhi;
        wlo = p->W[i] < wlo ? p->W[i] : wlo;
        whi = p->W[i] > whi ? p->W[i] : whi;
        p->zlo = p->Z[i] < p->zlo ? p->Z[i] : p->zlo;
        p->zhi = p->Z[i] > p->zhi ? p->Z[i] : p->zhi;
    }
    if (!vx_vox_pixel_range(ulo, uhi, dims[p->u], &p->bu0, &p->bu1)) return 0;
    if (!vx_vox_pixel_range(wlo, whi, dims[p->w], &p->bw0, &p->bw1)) return 0;
    /* slabs floor(zlo) .. floor(zhi) within [0, dims[a]); with a cap at most max_slices from
     * floor(zlo), the geometry shader's first slab even when it lies outside the grid */
    if (!(p->zhi >= 0.0) || !(p->zlo < (double)dims[a])) return 0;
    p->k0 = p->zlo <= 0.0 ? 0 : vx_vox_ifloor(p->zlo);
    p->k1 = p->zhi >= (double)(dims[a] - 1) ? dims[a] - 1 : vx_vox_ifloor(p->zhi);
    if (max_slices > 0) {
        double kmin = floor(p->zlo), k1 = kmin + (double)(max_slices - 1);
        if (k1 < (double)p->k1) p->k1 = k1 < 0.0 ? -1 : (int)k1;
        if (p->k0 > p->k1) return 0;
    }
    p->dzdu = -T->n[p->u] / T->n[a];
    p->dzdw = -T->n[p->w] / T->n[a];
    if (!(fabs(p->dzdu) <= VX_VOX_MAX_SLOPE) || !(fabs(p->dzdw) <= VX_VOX_MAX_SLOPE)) return 0;
    p->dudz = 0.0;
    /* counter-clockwise order in the (u, w) plane */
    swap = p->area2 < 0.0;
    for (i = 0; i < 3; i++) {
        int s = swap && i ? 3 - i : i; /* 0, 2, 1 when clockwise */
        p->q[i][0] = p->U[s];
        p->q[i][1] = p->W[s];
        p->q[i][2] = p->Z[s];
    }
    for (i = 0; i < 3; i++) {
        int j = i == 2 ? 0 : i + 1;
        double slope;
        vx_vox_edge_init(&p->e[i], p->q[i][0], p->q[i][1], p->q[j][0], p->q[j][1]);
        slope = -p->e[i].sign * p->e[i].dw;
        p->edir[i] = slope > 0.0 ? 1 : slope < 0.0 ? -1 : 0;
    }
    if (p->bu1 - p->bu0 >= VX_VOX_DIRECT_WIDTH) { /* rows are searched: their estimates */
        for (i = 0; i < 3; i++) vx_vox_edge_root(&p->e[i]);
        p->dudz = p->dzdu != 0.0 ? 1.0 / p->dzdu : 0.0;
    }
    return 1;
}

/* The plane's depth at pixel centre (cu, cw), clamped to the triangle's depth range (a no-op in
 * exact arithmetic; it keeps floor(z) inside the slabs the triangle spans). Monotone in cu. */
static double vx_vox_depth(const vx_vox_pass *p, double cu, double cw)
{
    double z = (p->Z[0] + p->dzdw * (cw - p->W[0])) + p->dzdu * (cu - p->U[0]);
    if (z < p->zlo) z = p->zlo;
    if (z > p->zhi) z = p->zhi;
    return z;
}

static int vx_vox_inside(const vx_vox_edge *e, int ne, double cu, double cw)
{
    int i;
    for (i = 0; i < ne; i++)
        if (!vx_vox_edge_pass(&e[i], cu, cw)) return 0;
    return 1;
}

/* ---- GS slicing: the slab piece (Alg. 5; Sutherland-Hodgman against both slab planes) ---- */

#define VX_VOX_PIECE_MAX 8

/* Crossing of the original edge (A, B) with the plane z = c, A.z != B.z, c strictly between:
 * computed from the lower-depth endpoint, so every piece and every triangle sharing the edge
 * gets the same point. */
static void vx_vox_cross(const double *A, const double *B, double c, double out[2])
{
    const double *P = A[2] < B[2] ? A : B, *Q = A[2] < B[2] ? B : A;
    double t = (c - P[2]) / (Q[2] - P[2]);
    out[0] = P[0] + t * (Q[0] - P[0]);
    out[1] = P[1] + t * (Q[1] - P[1]);
}

/* The piece of the pass's triangle in slab [k, k+1] (closed), counter-clockwise, as (u, w)
 * points: each edge Qi -> Qj contributes Qi if it lies in the slab, then its crossings with the
 * planes k and k+1 strictly between Qi.z and Qj.z, in order along the edge. This is the
 * Sutherland-Hodgman clip of the triangle by the two planes with every crossing taken from an
 * original edge. Returns the vertex count and its edges; 0 if the piece has no area. */
static int vx_vox_piece(const vx_vox_pass *p, double k, vx_vox_edge *edges, double *bb)
{
    double pt[VX_VOX_PIECE_MAX][2], area2 = 0.0;
    int n = 0, i;
    for (i = 0; i < 3; i++) {
        const double *A = p->q[i], *B = p->q[(i + 1) % 3];
        double c0 = A[2] < B[2] ? k : k + 1.0, c1 = A[2] < B[2] ? k + 1.0 : k;
        if (A[2] >= k && A[2] <= k + 1.0) {
            pt[n][0] = A[0];
            pt[n][1] = A[1];
            n++;
        }
        if ((A[2] < c0 && c0 < B[2]) || (B[2] < c0 && c0 < A[2])) vx_vox_cross(A, B, c0, pt[n++]);
        if ((A[2] < c1 && c1 < B[2]) || (B[2] < c1 && c1 < A[2])) vx_vox_cross(A, B, c1, pt[n++]);
    }
    if (n < 3) return 0;
    for (i = 0; i < n; i++) {
        int j = (i + 1) % n;
        area2 += (pt[i][0] - pt[0][0]) * (pt[j][1] - pt[0][1])
                 - (pt[j][0] - pt[0][0]) * (pt[i][1] - pt[0][1]);
    }
    if (!(area2 > 0.0)) return 0;
    bb[0] = bb[1] = pt[0][0];
    bb[2] = bb[3] = pt[0][1];
    for (i = 0; i < n; i++) {
        int j = (i + 1) % n;
        vx_vox_edge_init(&edges[i], pt[i][0], pt[i][1], pt[j][0], pt[j][1]);
        vx_vox_edge_root(&edges[i]);
        bb[0] = pt[i][0] < bb[0] ? pt[i][0] : bb[0];
        bb[1] = pt[i][0] > bb[1] ? pt[i][0] : bb[1];
        bb[2] = pt[i][1] < bb[2] ? pt[i][1] : bb[2];
        bb[3] = pt[i][1] > bb[3] ? pt[i][1] : bb[3];
    }
    return n;
}

/* ---- the fragment sink: occupancy bytes or the Volume Buffer with its blends ------------- */

typedef struct vx_vox_sink {
    const hfvis_volume_grid *grid;
    hfvis_volume *vol;  /* or NULL */
    uint8_t *occ;       /* or NULL */
    hfvis_voxel_fragment_fn fn;
    void *user;
    size_t count;
    size_t stride[3];   /* linear-index step per axis */
    const vx_vox_tri *tri;
} vx_vox_sink;

/* The fragment of pixel centre (cu, cw) of pass p written to voxel v. */
static void vx_vox_fragment_fill(hfvis_voxel_fragment *f, const vx_vox_tri *T,
                                 const vx_vox_pass *p, const int v[3])
{
    double cu = (double)v[p->u] + 0.5, cw = (double)v[p->w] + 0.5, b[3];
    int i, a;
    for (i = 0; i < 3; i++) {
        int j = (i + 1) % 3, k = (i + 2) % 3; /* edge opposite vertex i: j -> k */
        b[i] = ((p->U[k] - p->U[j]) * (cw - p->W[j]) - (p->W[k] - p->W[j]) * (cu - p->U[j]))
               / p->area2;
    }
    for (a = 0; a < 3; a++) {
        f->voxel[a] = v[a];
        f->barycentric[a] = (float)b[a];
        f->position[a] = (float)(b[0] * T->v[0][a] + b[1] * T->v[1][a] + b[2] * T->v[2][a]);
        f->normal[a] = T->normal[a];
    }
    f->axis = p->a;
    f->triangle = T->id;
}

/* Write pixels u0..u1 of row pw into slab k. */
static void vx_vox_emit(vx_vox_sink *s, const vx_vox_pass *p, int pw, int u0, int u1, int k)
{
    int v[3], pu;
    size_t lin, step = s->stride[p->u];
    v[p->a] = k;
    v[p->w] = pw;
    v[p->u] = u0;
    lin = ((size_t)v[2] * (size_t)s->grid->dims[1] + (size_t)v[1]) * (size_t)s->grid->dims[0]
          + (size_t)v[0];
    s->count += (size_t)(u1 - u0 + 1);
    if (s->occ) {
        for (pu = u0; pu <= u1; pu++, lin += step) s->occ[lin] = 1;
    } else if (!s->fn) {
        size_t C = (size_t)s->vol->channels;
        float *d = s->vol->data;
        hfvis_blend op = s->vol->blend[0];
        for (pu = u0; pu <= u1; pu++, lin += step) d[lin * C] = vx_blend_apply(op, d[lin * C], 1.0f);
    } else {
        int C = s->vol->channels, c;
        float values[HFVIS_VOLUME_MAX_CHANNELS];
        hfvis_voxel_fragment f;
        for (pu = u0; pu <= u1; pu++, lin += step) {
            float *d = s->vol->data + lin * (size_t)C;
            v[p->u] = pu;
            vx_vox_fragment_fill(&f, s->tri, p, v);
            memset(values, 0, sizeof values);
            s->fn(&f, values, s->user);
            for (c = 0; c < C; c++) d[c] = vx_blend_apply(s->vol->blend[c], d[c], values[c]);
        }
    }
}

/* ---- rows: hoisted row constants and monotone boundary searches ------------------------- */

/* One pixel row (centre cw) of a polygon: the non-degenerate edges with the row's constant
 * part of each edge function, K = du (cw - lw), and of the depth, zrow = Z0 + dz/dw (cw - W0).
 * The per-pixel values below use the same operations in the same order as vx_vox_edge_value
 * and vx_vox_depth, so they are bit-identical to the oracle's. */
typedef struct vx_vox_row_ctx {
    const vx_vox_edge *e[VX_VOX_PIECE_MAX];
    double K[VX_VOX_PIECE_MAX];
    int ne;
    double cw, zrow;
    const vx_vox_pass *p;
} vx_vox_row_ctx;

static void vx_vox_row_init(vx_vox_row_ctx *r, const vx_vox_edge *e, int ne, const vx_vox_pass *p,
                            double cw)
{
    int i;
    r->ne = 0;
    for (i = 0; i < ne; i++)
        if (!e[i].skip) {
            r->e[r->ne] = &e[i];
            r->K[r->ne++] = e[i].du * (cw - e[i].lw);
        }
    r->cw = cw;
    r->p = p;
    r->zrow = p->Z[0] + p->dzdw * (cw - p->W[0]);
}

static int vx_vox_row_edge_pass(const vx_vox_edge *e, double K, double cu)
{
    double v = e->sign * (K - e->dw * (cu - e->lu));
    return v > 0.0 || (v == 0.0 && e->owned);
}

static int vx_vox_row_inside(const vx_vox_row_ctx *r, double cu)
{
    int i;
    for (i = 0; i < r->ne; i++)
        if (!vx_vox_row_edge_pass(r->e[i], r->K[i], cu)) return 0;
    return 1;
}

static double vx_vox_row_depth(const vx_vox_row_ctx *r, double cu)
{
    const vx_vox_pass *p = r->p;
    double z = r->zrow + p->dzdu * (cu - p->U[0]);
    if (z < p->zlo) z = p->zlo;
    if (z > p->zhi) z = p->zhi;
    return z;
}

/* Galloping search body: the first x in [lo, hi] where PRED(x) holds, PRED nondecreasing in x
 * (false ... true), hi + 1 if none, starting from the estimate `guess` (a pixel coordinate; any
 * value, NaN included, is safe). O(1) evaluations when the estimate is within a pixel, O(log)
 * otherwise. */
#define VX_VOX_GALLOP(PRED)                                                                    \
    int g, t, f, step = 1;                                                                     \
    if (lo > hi) return lo;                                                                    \
    if (!(guess > (double)lo)) g = lo;                                                         \
    else if (!(guess < (double)hi)) g = hi;                                                    \
    else g = vx_vox_iceil(guess);                                                              \
    if (PRED(g)) {                                                                             \
        for (t = g;;) {                                                                        \
            if (t - lo < step) { f = lo - 1; break; }                                          \
            f = t - step;                                                                      \
            if (!PRED(f)) break;                                                               \
            t = f;                                                                             \
            if (step < (1 << 29)) step *= 2;                                                   \
        }                                                                                      \
    } else {                                                                                   \
        for (f = g;;) {                                                                        \
            if (hi - f < step) { t = hi + 1; break; }                                          \
            t = f + step;                                                                      \
            if (PRED(t)) break;                                                                \
            f = t;                                                                             \
            if (step < (1 << 29)) step *= 2;                                                   \
        }                                                                                      \
    }                                                                                          \
    while (t - f > 1) {                                                                        \
        int mid = f + (t - f) / 2;                                                             \
        if (PRED(mid)) t = mid;                                                                \
        else f = mid;                                                                          \
    }                                                                                          \
    return t

/* First pixel in [lo, hi] where the edge test equals `want` (monotone that way). */
static int vx_vox_edge_first(const vx_vox_edge *e, double K, int want, int lo, int hi, double guess)
{
#define VX_VOX_PRED_EDGE(x) (vx_vox_row_edge_pass(e, K, (double)(x) + 0.5) == want)
    VX_VOX_GALLOP(VX_VOX_PRED_EDGE);
#undef VX_VOX_PRED_EDGE
}

/* First pixel in [lo, hi] where (depth >= thr) equals `want` (monotone that way). */
static int vx_vox_depth_first(const vx_vox_row_ctx *r, double thr, int want, int lo, int hi,
                              double guess)
{
#define VX_VOX_PRED_DEPTH(x) ((vx_vox_row_depth(r, (double)(x) + 0.5) >= thr) == want)
    VX_VOX_GALLOP(VX_VOX_PRED_DEPTH);
#undef VX_VOX_PRED_DEPTH
}

/* The pixels [*L, *R] of the row within [lo, hi] inside every edge; 0 if none. Each edge
 * function is monotone along the row, so each edge bounds the span on one side. */
static int vx_vox_row_span(const vx_vox_row_ctx *r, int lo, int hi, int *L, int *R)
{
    int i;
    for (i = 0; i < r->ne && lo <= hi; i++) {
        const vx_vox_edge *e = r->e[i];
        double slope = -e->sign * e->dw; /* dE/dcu */
        if (slope == 0.0) {              /* constant along the row */
            if (!vx_vox_row_edge_pass(e, r->K[i], (double)lo + 0.5)) return 0;
            continue;
        }
        /* estimate: the root u = lu + (du/dw)(cw - lw), as a pixel index */
        if (slope > 0.0) /* inside on a suffix */
            lo = vx_vox_edge_first(e, r->K[i], 1, lo, hi, e->lu + e->root_du * (r->cw - e->lw) - 0.5);
        else             /* inside on a prefix */
            hi = vx_vox_edge_first(e, r->K[i], 0, lo, hi, e->lu + e->root_du * (r->cw - e->lw) - 0.5) - 1;
    }
    *L = lo;
    *R = hi;
    return lo <= hi;
}

/* Pixel estimate where the depth reaches thr along the row. */
static double vx_vox_depth_guess(const vx_vox_row_ctx *r, double thr)
{
    return r->p->U[0] + (thr - r->zrow) * r->p->dudz - 0.5;
}

/* Write the pixels L..R of row pw (all inside the triangle) whose slab lies in [s0, s1], each
 * into its slab: the runs of constant slab are delimited by searching the slab boundaries. */
static void vx_vox_row_slabs(vx_vox_sink *s, const vx_vox_row_ctx *r, int pw, int L, int R, int s0,
                             int s1)
{
    const vx_vox_pass *p = r->p;
    double lo_thr = (double)s0, hi_thr = (double)s1 + 1.0;
    int cur;
    if (p->dzdu == 0.0) { /* depth constant along the row */
        double z = vx_vox_row_depth(r, (double)L + 0.5);
        if (z >= lo_thr && z < hi_thr) vx_vox_emit(s, p, pw, L, R, vx_vox_ifloor(z));
        return;
    }
    if (fabs(p->dzdu) > VX_VOX_STEEP) { /* short runs: the slab of each pixel, grouped in runs */
        int k = 0, start = -1, pu;
        for (pu = L; pu <= R; pu++) {
            double z = vx_vox_row_depth(r, (double)pu + 0.5);
            int kk = z >= lo_thr && z < hi_thr ? vx_vox_ifloor(z) : -1;
            if (start >= 0 && kk != k) {
                vx_vox_emit(s, p, pw, start, pu - 1, k);
                start = -1;
            }
            if (kk >= 0 && start < 0) start = pu, k = kk;
        }
        if (start >= 0) vx_vox_emit(s, p, pw, start, R, k);
        return;
    }
    if (p->dzdu > 0.0) { /* slab nondecreasing along the row */
        /* restrict to [s0, s1] only where the row's ends leave it (grid border, cap, slab) */
        if (!(vx_vox_row_depth(r, (double)L + 0.5) >= lo_thr))
            L = vx_vox_depth_first(r, lo_thr, 1, L, R, vx_vox_depth_guess(r, lo_thr));
        if (L <= R && !(vx_vox_row_depth(r, (double)R + 0.5) < hi_thr))
            R = vx_vox_depth_first(r, hi_thr, 1, L, R, vx_vox_depth_guess(r, hi_thr)) - 1;
        for (cur = L; cur <= R;) {
            int k = vx_vox_ifloor(vx_vox_row_depth(r, (double)cur + 0.5)), nxt;
            double thr = (double)k + 1.0;
            if (!(vx_vox_row_depth(r, (double)R + 0.5) >= thr)) nxt = R + 1; /* one run to R */
            else nxt = vx_vox_depth_first(r, thr, 1, cur + 1, R, vx_vox_depth_guess(r, thr));
            vx_vox_emit(s, p, pw, cur, nxt - 1, k);
            cur = nxt;
        }
    } else { /* slab nonincreasing along the row */
        if (!(vx_vox_row_depth(r, (double)L + 0.5) < hi_thr))
            L = vx_vox_depth_first(r, hi_thr, 0, L, R, vx_vox_depth_guess(r, hi_thr));
        if (L <= R && !(vx_vox_row_depth(r, (double)R + 0.5) >= lo_thr))
            R = vx_vox_depth_first(r, lo_thr, 0, L, R, vx_vox_depth_guess(r, lo_thr)) - 1;
        for (cur = L; cur <= R;) {
            int k = vx_vox_ifloor(vx_vox_row_depth(r, (double)cur + 0.5)), nxt;
            double thr = (double)k; /* first pixel with depth < k */
            if (vx_vox_row_depth(r, (double)R + 0.5) >= thr) nxt = R + 1; /* one run to R */
            else nxt = vx_vox_depth_first(r, thr, 0, cur + 1, R, vx_vox_depth_guess(r, thr));
            vx_vox_emit(s, p, pw, cur, nxt - 1, k);
            cur = nxt;
        }
    }
}

/* ---- the three methods, fast ------------------------------------------------------------- */

/* The first pixel of [lo, hi] where an edge monotone along the row passes (inc != 0: it passes
 * on a suffix) or fails (inc == 0: it passes on a prefix), hi + 1 if none; `est` is the root
 * estimate. Most rows are settled by two evaluations at the estimate; otherwise gallop. */
static int vx_vox_edge_threshold(const vx_vox_edge *e, double K, int inc, int lo, int hi, double est)
{
    int g;
    if (!(est > (double)lo)) g = lo;
    else if (!(est < (double)hi)) g = hi;
    else g = vx_vox_iceil(est);
    if ((vx_vox_row_edge_pass(e, K, (double)g + 0.5) == inc)
        && (g == lo || (vx_vox_row_edge_pass(e, K, (double)g - 0.5) != inc)))
        return g;
    return vx_vox_edge_first(e, K, inc, lo, hi, est);
}

/* The pixels of row pw of the pass's triangle whose slab lies in [s0, s1]. */
static void vx_vox_row(vx_vox_sink *s, const vx_vox_pass *p, int pw, int s0, int s1)
{
    vx_vox_row_ctx r;
    int i, L = p->bu0, R = p->bu1;
    r.cw = (double)pw + 0.5;
    r.p = p;
    r.ne = 3;
    for (i = 0; i < 3; i++) {
        r.e[i] = &p->e[i];
        r.K[i] = p->e[i].du * (r.cw - p->e[i].lw);
    }
    r.zrow = p->Z[0] + p->dzdw * (r.cw - p->W[0]);
    if (R - L < VX_VOX_DIRECT_WIDTH) { /* narrow: test each pixel */
        int pu;
        for (pu = L; pu <= R; pu++) {
            double cu = (double)pu + 0.5, z;
            if (!vx_vox_row_edge_pass(&p->e[0], r.K[0], cu) || !vx_vox_row_edge_pass(&p->e[1], r.K[1], cu)
                || !vx_vox_row_edge_pass(&p->e[2], r.K[2], cu))
                continue;
            z = vx_vox_row_depth(&r, cu); /* slab floor(z) in [s0, s1] */
            if (z >= (double)s0 && z < (double)s1 + 1.0) vx_vox_emit(s, p, pw, pu, pu, vx_vox_ifloor(z));
        }
        return;
    }
    for (i = 0; i < 3 && L <= R; i++) { /* a triangle's edges are never degenerate */
        const vx_vox_edge *e = &p->e[i];
        double est;
        if (p->edir[i] == 0) { /* constant along the row */
            if (!vx_vox_row_edge_pass(e, r.K[i], (double)L + 0.5)) return;
            continue;
        }
        est = e->lu + e->root_du * (r.cw - e->lw) - 0.5; /* root, as a pixel index */
        if (p->edir[i] > 0) L = vx_vox_edge_threshold(e, r.K[i], 1, L, R, est);
        else R = vx_vox_edge_threshold(e, r.K[i], 0, L, R, est) - 1;
    }
    if (L <= R) vx_vox_row_slabs(s, &r, pw, L, R, s0, s1);
}

/* Pixel rule (spec §3.4): every covered pixel of the pass into the slab of its depth. */
static void vx_vox_fast_pixel_rule(vx_vox_sink *s, const vx_vox_pass *p)
{
    int pw;
    for (pw = p->bw0; pw <= p->bw1; pw++) vx_vox_row(s, p, pw, p->k0, p->k1);
}

/* Fragment clipping ([G12] Alg. 6): for each slab (lowest first, capped), the whole triangle is
 * rasterised again and only the fragments whose depth lies in [k, k+1) are kept. */
static void vx_vox_fast_fragment_clipping(vx_vox_sink *s, const vx_vox_pass *p)
{
    int k, pw;
    for (k = p->k0; k <= p->k1; k++)
        for (pw = p->bw0; pw <= p->bw1; pw++) vx_vox_row(s, p, pw, k, k);
}

/* GS slicing ([G12] Alg. 5): the slab pieces (lowest first, capped), each rasterised into its
 * slab with the pixel-centre rule on its own edges. */
static void vx_vox_fast_gs_slicing(vx_vox_sink *s, const vx_vox_pass *p, const int dims[3])
{
    vx_vox_edge pe[VX_VOX_PIECE_MAX];
    vx_vox_row_ctx r;
    double bb[4];
    int k, n, pw, pu, u0, u1, w0, w1, L, R;
    for (k = p->k0; k <= p->k1; k++) {
        n = vx_vox_piece(p, (double)k, pe, bb);
        if (n == 0 || !vx_vox_pixel_range(bb[0], bb[1], dims[p->u], &u0, &u1)
            || !vx_vox_pixel_range(bb[2], bb[3], dims[p->w], &w0, &w1))
            continue;
        for (pw = w0; pw <= w1; pw++) {
            vx_vox_row_init(&r, pe, n, p, (double)pw + 0.5);
            if (u1 - u0 < VX_VOX_DIRECT_WIDTH) {
                for (pu = u0; pu <= u1; pu++)
                    if (vx_vox_row_inside(&r, (double)pu + 0.5)) vx_vox_emit(s, p, pw, pu, pu, k);
            } else if (vx_vox_row_span(&r, u0, u1, &L, &R))
                vx_vox_emit(s, p, pw, L, R, k);
        }
    }
}

/* ---- the oracle (per voxel of the bounding box) ------------------------------------------ */

static void vx_vox_reference_pass(vx_vox_sink *s, const vx_vox_pass *p, hfvis_voxelize_method method,
                                  const int dims[3])
{
    int k, pu, pw;
    for (k = p->k0; k <= p->k1; k++) {
        if (method == HFVIS_VOXELIZE_GS_SLICING) {
            vx_vox_edge pe[VX_VOX_PIECE_MAX];
            double bb[4];
            int n = vx_vox_piece(p, (double)k, pe, bb), u0, u1, w0, w1;
            if (n == 0 || !vx_vox_pixel_range(bb[0], bb[1], dims[p->u], &u0, &u1)
                || !vx_vox_pixel_range(bb[2], bb[3], dims[p->w], &w0, &w1))
                continue;
            for (pw = w0; pw <= w1; pw++)
                for (pu = u0; pu <= u1; pu++)
                    if (vx_vox_inside(pe, n, (double)pu + 0.5, (double)pw + 0.5))
                        vx_vox_emit(s, p, pw, pu, pu, k);
        } else {
            for (pw = p->bw0; pw <= p->bw1; pw++)
                for (pu = p->bu0; pu <= p->bu1; pu++) {
                    double cu = (double)pu + 0.5, cw = (double)pw + 0.5, z;
                    if (!vx_vox_inside(p->e, 3, cu, cw)) continue;
                    z = vx_vox_depth(p, cu, cw);
                    if ((double)k <= z && z < (double)k + 1.0) vx_vox_emit(s, p, pw, pu, pu, k);
                }
        }
    }
}

/* ---- driver ------------------------------------------------------------------------------ */

typedef struct vx_vox_cfg {
    hfvis_voxelize_method method;
    hfvis_voxelize_axes axes;
    int max_slices; /* 0 = unlimited */
    hfvis_voxel_fragment_fn fn;
    void *user;
} vx_vox_cfg;

static hfvis_status vx_vox_resolve(const hfvis_voxelize_options *o, vx_vox_cfg *c)
{
    hfvis_voxelize_options d;
    memset(&d, 0, sizeof d);
    if (!o) o = &d;
    if (o->method != HFVIS_VOXELIZE_PIXEL_RULE && o->method != HFVIS_VOXELIZE_GS_SLICING
        && o->method != HFVIS_VOXELIZE_FRAGMENT_CLIPPING)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o->axes != HFVIS_AXES_DOMINANT && o->axes != HFVIS_AXES_ALL && o->axes != HFVIS_AXES_ONLY_X
        && o->axes != HFVIS_AXES_ONLY_Y && o->axes != HFVIS_AXES_ONLY_Z)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o->max_output_vertices < 0) return HFVIS_ERR_INVALID_ARGUMENT;
    c->max_slices = 0;
    if (o->max_output_vertices > 0) {
        if (o->method == HFVIS_VOXELIZE_PIXEL_RULE) return HFVIS_ERR_INVALID_ARGUMENT;
        c->max_slices = hfvis_gs_max_slices(o->max_output_vertices,
                                            o->method == HFVIS_VOXELIZE_FRAGMENT_CLIPPING);
        if (c->max_slices < 1) return HFVIS_ERR_INVALID_ARGUMENT;
    }
    c->method = o->method;
    c->axes = o->axes;
    c->fn = o->fragment;
    c->user = o->user;
    return HFVIS_OK;
}

static void vx_vox_run(const hfvis_mesh *m, const vx_vox_cfg *c, vx_vox_sink *s, int reference)
{
    const hfvis_volume_grid *g = s->grid;
    int npass = c->axes == HFVIS_AXES_ALL ? 3 : 1, pass;
    size_t t;
    vx_vox_tri T;
    vx_vox_pass P;
    s->stride[0] = 1;
    s->stride[1] = (size_t)g->dims[0];
    s->stride[2] = (size_t)g->dims[0] * (size_t)g->dims[1];
    s->tri = &T;
    for (pass = 0; pass < npass; pass++)
        for (t = 0; t < m->triangle_count; t++) {
            int a;
            if (!vx_vox_tri_setup(&T, m, g, t, s->fn != NULL)) continue;
            switch (c->axes) {
            case HFVIS_AXES_DOMINANT: a = vx_vox_dominant(T.n); break;
            case HFVIS_AXES_ONLY_X: a = 0; break;
            case HFVIS_AXES_ONLY_Y: a = 1; break;
            case HFVIS_AXES_ONLY_Z: a = 2; break;
            case HFVIS_AXES_ALL:
            default: a = pass; break;
            }
            if (!vx_vox_pass_setup(&P, &T, a, g->dims,
                                   c->method == HFVIS_VOXELIZE_PIXEL_RULE ? 0 : c->max_slices))
                continue;
            if (reference) vx_vox_reference_pass(s, &P, c->method, g->dims);
            else if (c->method == HFVIS_VOXELIZE_GS_SLICING) vx_vox_fast_gs_slicing(s, &P, g->dims);
            else if (c->method == HFVIS_VOXELIZE_FRAGMENT_CLIPPING) vx_vox_fast_fragment_clipping(s, &P);
            else vx_vox_fast_pixel_rule(s, &P);
        }
    s->tri = NULL; /* T is local */
}

static hfvis_status vx_vox_surface(const hfvis_mesh *mesh, hfvis_volume *vol,
                                   const hfvis_voxelize_options *opts, size_t *fragments_written,
                                   int reference)
{
    vx_vox_cfg cfg;
    vx_vox_sink s;
    int c;
    hfvis_status st;
    if (vx_mesh_check(mesh) != HFVIS_OK || !vol || !vol->data || !vx_grid_valid(&vol->grid)
        || vol->channels < 1 || vol->channels > HFVIS_VOLUME_MAX_CHANNELS)
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (c = 0; c < vol->channels; c++)
        if (!vx_blend_valid(vol->blend[c])) return HFVIS_ERR_INVALID_ARGUMENT;
    st = vx_vox_resolve(opts, &cfg);
    if (st != HFVIS_OK) return st;
    memset(&s, 0, sizeof s);
    s.grid = &vol->grid;
    s.vol = vol;
    s.fn = cfg.fn;
    s.user = cfg.user;
    vx_vox_run(mesh, &cfg, &s, reference);
    if (fragments_written) *fragments_written = s.count;
    return HFVIS_OK;
}

HFVIS_API hfvis_voxelize_options hfvis_voxelize_options_default(void)
{
    hfvis_voxelize_options o;
    memset(&o, 0, sizeof o);
    o.method = HFVIS_VOXELIZE_PIXEL_RULE;
    o.axes = HFVIS_AXES_DOMINANT;
    o.max_output_vertices = 0;
    o.fragment = NULL;
    o.user = NULL;
    o.alloc = NULL;
    return o;
}

HFVIS_API int hfvis_gs_max_slices(int max_output_vertices, int pixel_clipping)
{
    int v = max_output_vertices;
    if (pixel_clipping) return v >= 3 ? v / 3 : 0;   /* 3n vertices for n slabs */
    return v >= 7 ? (v - 3) / 4 : 0;                  /* 3 + 4n vertices for n slabs */
}

HFVIS_API hfvis_status hfvis_voxelize_surface(const hfvis_mesh *mesh, hfvis_volume *vol,
                                              const hfvis_voxelize_options *opts,
                                              size_t *fragments_written)
{
    return vx_vox_surface(mesh, vol, opts, fragments_written, 0);
}

HFVIS_API hfvis_status hfvis_voxelize_surface_reference(const hfvis_mesh *mesh, hfvis_volume *vol,
                                                        const hfvis_voxelize_options *opts,
                                                        size_t *fragments_written)
{
    return vx_vox_surface(mesh, vol, opts, fragments_written, 1);
}

HFVIS_API hfvis_status hfvis_voxelize_occupancy(const hfvis_mesh *mesh,
                                                const hfvis_volume_grid *grid,
                                                const hfvis_voxelize_options *opts, uint8_t *occ)
{
    vx_vox_cfg cfg;
    vx_vox_sink s;
    hfvis_status st;
    if (vx_mesh_check(mesh) != HFVIS_OK || !vx_grid_valid(grid) || !occ)
        return HFVIS_ERR_INVALID_ARGUMENT;
    st = vx_vox_resolve(opts, &cfg);
    if (st != HFVIS_OK) return st;
    memset(occ, 0, vx_grid_voxels(grid));
    memset(&s, 0, sizeof s);
    s.grid = grid;
    s.occ = occ;
    vx_vox_run(mesh, &cfg, &s, 0);
    return HFVIS_OK;
}

/* ---- ready-made attribute callbacks ([G12] §6.5; spec §3.8) ------------------------------- */

HFVIS_API void hfvis_voxel_fragment_occupancy(const hfvis_voxel_fragment *f, float *values,
                                              void *user)
{
    (void)f;
    (void)user;
    values[0] = 1.0f;
}

HFVIS_API void hfvis_voxel_fragment_normal_occupancy(const hfvis_voxel_fragment *f, float *values,
                                                     void *user)
{
    (void)user;
    values[0] = 1.0f;
    values[1] = f->normal[0];
    values[2] = f->normal[1];
    values[3] = f->normal[2];
}

HFVIS_API int hfvis_voxel_attribute_channel(unsigned flags, unsigned attribute)
{
    static const unsigned order[4] = { HFVIS_VOXEL_ATTR_OCCUPANCY, HFVIS_VOXEL_ATTR_NORMAL,
                                       HFVIS_VOXEL_ATTR_ALBEDO, HFVIS_VOXEL_ATTR_RADIANCE };
    int c = 0, i;
    if (flags == 0) flags = HFVIS_VOXEL_ATTR_OCCUPANCY;
    for (i = 0; i < 4; i++) {
        if (!(flags & order[i])) continue;
        if (attribute == order[i]) return c;
        c += i == 0 ? 1 : 3;
    }
    return attribute == 0 ? c : -1;
}

HFVIS_API void hfvis_voxel_fragment_attributes(const hfvis_voxel_fragment *f, float *values,
                                               void *user)
{
    const hfvis_voxel_attributes *at = (const hfvis_voxel_attributes *)user;
    unsigned flags;
    float alb[3] = { 1.0f, 1.0f, 1.0f };
    int c = 0, i;
    if (!at) { /* no layout: occupancy only */
        values[0] = 1.0f;
        return;
    }
    flags = at->flags ? at->flags : HFVIS_VOXEL_ATTR_OCCUPANCY;
    if (at->albedo)
        for (i = 0; i < 3; i++) alb[i] = at->albedo[3 * (size_t)f->triangle + (size_t)i];
    if (flags & HFVIS_VOXEL_ATTR_OCCUPANCY) values[c++] = 1.0f;
    if (flags & HFVIS_VOXEL_ATTR_NORMAL)
        for (i = 0; i < 3; i++) values[c++] = f->normal[i];
    if (flags & HFVIS_VOXEL_ATTR_ALBEDO)
        for (i = 0; i < 3; i++) values[c++] = alb[i];
    if (flags & HFVIS_VOXEL_ATTR_RADIANCE) {
        float e[3] = { 0.0f, 0.0f, 0.0f };
        if (at->irradiance) at->irradiance(f->position, f->normal, e, at->irradiance_user);
        for (i = 0; i < 3; i++) {
            double L = (double)alb[i] * (double)e[i] / VX_PI;
            if (at->emission) L += (double)at->emission[3 * (size_t)f->triangle + (size_t)i];
            values[c++] = (float)L;
        }
    }
}
