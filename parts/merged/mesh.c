/* ========================================================================================== */
/* 1. Meshes: analytic test meshes and the Wavefront OBJ codec                                */
/*    (infrastructure for Gaitatzes 2012, ch. 6-7 and spec voxel §3.13: the icosphere of test  */
/*    4, the cube of tests 1-2, the 100k-triangle benchmark torus knot of issue 4)            */
/* ========================================================================================== */
/* Contents
 *   1a. mesh builder (exact sizes, limits, overflow checks, one cleanup path)
 *   1b. generators: box, UV sphere, icosphere, torus, torus knot, height field, room, teapot
 *   1c. bounds
 *   1d. OBJ decoder (two passes: count, then fill), own locale-independent number parser
 *   1e. OBJ encoder (own shortest round-trip float formatting), file wrappers
 * Every generated triangle is counter-clockwise seen from outside: (v1 - v0) x (v2 - v0) points
 * out of the enclosed volume (into the room for the room's walls). */

#define VX_MESH_PI 3.14159265358979323846

/* ---- 1a. builder ------------------------------------------------------------------------ */

typedef struct vx_mesh_builder {
    float *xyz;
    uint32_t *idx;
    size_t nv, nt;       /* filled so far */
    size_t cap_v, cap_t; /* exact sizes requested */
} vx_mesh_builder;

/* Allocate exactly nv vertices and nt triangles. HFVIS_ERR_LIMIT past the documented limits. */
static hfvis_status vx_mesh_builder_init(vx_mesh_builder *b, const hfvis_allocator *alloc,
                                         size_t nv, size_t nt)
{
    memset(b, 0, sizeof *b);
    if (nv > HFVIS_MESH_MAX_VERTICES || nt > HFVIS_MESH_MAX_TRIANGLES) return HFVIS_ERR_LIMIT;
    if (nv > 0) {
        b->xyz = (float *)vx_alloc_array(alloc, nv, 3 * sizeof(float));
        if (!b->xyz) return HFVIS_ERR_OUT_OF_MEMORY;
    }
    if (nt > 0) {
        b->idx = (uint32_t *)vx_alloc_array(alloc, nt, 3 * sizeof(uint32_t));
        if (!b->idx) {
            vx_free(alloc, b->xyz);
            b->xyz = NULL;
            return HFVIS_ERR_OUT_OF_MEMORY;
        }
    }
    b->cap_v = nv;
    b->cap_t = nt;
    return HFVIS_OK;
}

static void vx_mesh_builder_free(vx_mesh_builder *b, const hfvis_allocator *alloc)
{
    vx_free(alloc, b->xyz);
    vx_free(alloc, b->idx);
    b->xyz = NULL;
    b->idx = NULL;
}

static uint32_t vx_mesh_v(vx_mesh_builder *b, double x, double y, double z)
{
    size_t v = b->nv++;
    HFVIS_ASSERT(v < b->cap_v);
    b->xyz[3 * v] = (float)x;
    b->xyz[3 * v + 1] = (float)y;
    b->xyz[3 * v + 2] = (float)z;
    return (uint32_t)v;
}

static void vx_mesh_t(vx_mesh_builder *b, size_t i0, size_t i1, size_t i2)
{
    size_t t = b->nt++;
    HFVIS_ASSERT(t < b->cap_t && i0 < b->cap_v && i1 < b->cap_v && i2 < b->cap_v);
    b->idx[3 * t] = (uint32_t)i0;
    b->idx[3 * t + 1] = (uint32_t)i1;
    b->idx[3 * t + 2] = (uint32_t)i2;
}

/* Hand the arrays to *out after checking that every coordinate is finite (huge parameters can
 * overflow float: HFVIS_ERR_INVALID_ARGUMENT, nothing leaked, *out untouched). */
static hfvis_status vx_mesh_builder_finish(vx_mesh_builder *b, const hfvis_allocator *alloc,
                                           hfvis_mesh *out)
{
    size_t i;
    HFVIS_ASSERT(b->nv == b->cap_v && b->nt == b->cap_t);
    for (i = 0; i < 3 * b->nv; i++) {
        if (!isfinite(b->xyz[i])) {
            vx_mesh_builder_free(b, alloc);
            return HFVIS_ERR_INVALID_ARGUMENT;
        }
    }
    out->xyz = b->xyz;
    out->vertex_count = b->nv;
    out->indices = b->idx;
    out->triangle_count = b->nt;
    b->xyz = NULL;
    b->idx = NULL;
    return HFVIS_OK;
}

/* A finite parameter whose float image is finite too (coordinates are stored as float). */
static int vx_mesh_coord_ok(double v) { return isfinite(v) && fabs(v) <= (double)FLT_MAX; }

static int vx_mesh_point_ok(const double c[3])
{
    return c && vx_mesh_coord_ok(c[0]) && vx_mesh_coord_ok(c[1]) && vx_mesh_coord_ok(c[2]);
}

/* Count products in size_t, saturating to SIZE_MAX (which every limit check rejects). */
static size_t vx_mesh_mul(size_t a, size_t b)
{
    size_t r;
    return vx_mul_size(a, b, &r) ? r : SIZE_MAX;
}
static size_t vx_mesh_add(size_t a, size_t b) { return a > SIZE_MAX - b ? SIZE_MAX : a + b; }

/* ---- 1b. generators --------------------------------------------------------------------- */

/* The 12 outward triangles of a box whose corner k is (bit0: x, bit1: y, bit2: z) hi or lo,
 * two per face in the order -x, +x, -y, +y, -z, +z. */
static const unsigned char vx_mesh_box_tris[12][3] = {
    {0, 4, 6}, {0, 6, 2}, /* -x */
    {1, 3, 7}, {1, 7, 5}, /* +x */
    {0, 1, 5}, {0, 5, 4}, /* -y */
    {2, 6, 7}, {2, 7, 3}, /* +y */
    {0, 2, 3}, {0, 3, 1}, /* -z */
    {4, 5, 7}, {4, 7, 6}  /* +z */
};

HFVIS_API hfvis_status hfvis_mesh_box(const hfvis_allocator *alloc, const double lo[3],
                                      const double hi[3], hfvis_mesh *out)
{
    vx_mesh_builder b;
    hfvis_status s;
    int k, a;
    if (!out || !vx_mesh_point_ok(lo) || !vx_mesh_point_ok(hi)) return HFVIS_ERR_INVALID_ARGUMENT;
    for (a = 0; a < 3; a++)
        if (!(lo[a] < hi[a])) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_mesh_builder_init(&b, alloc, 8, 12);
    if (s != HFVIS_OK) return s;
    for (k = 0; k < 8; k++)
        vx_mesh_v(&b, (k & 1) ? hi[0] : lo[0], (k & 2) ? hi[1] : lo[1], (k & 4) ? hi[2] : lo[2]);
    for (k = 0; k < 12; k++)
        vx_mesh_t(&b, vx_mesh_box_tris[k][0], vx_mesh_box_tris[k][1], vx_mesh_box_tris[k][2]);
    return vx_mesh_builder_finish(&b, alloc, out);
}

/* Surface of revolution about the z axis through c: profile points (rho[i], z[i]),
 * i = 0..m (m >= 2), rho[0] = rho[m] = 0 (single pole vertices), ordered from the top pole
 * down the outside, revolved into `slices` meridians at phi_j = 2 pi j / slices (j = 0 at +x,
 * counter-clockwise seen from +z). Vertices: top pole, rings i = 1..m-1 (slices each, j
 * fastest), bottom pole. Triangles: top fan, bands (a, c, d), (a, d, b) with a = (i, j),
 * b = (i, j+1), c = (i+1, j), d = (i+1, j+1), bottom fan. Outward for a profile traversed
 * top to bottom on the outside. Writes (m-1)*slices + 2 vertices, 2*slices*(m-1) triangles. */
static void vx_mesh_revolve(vx_mesh_builder *b, const double c[3], const double *rho,
                            const double *z, size_t m, size_t slices)
{
    size_t i, j, base = b->nv, top, bottom;
    top = vx_mesh_v(b, c[0], c[1], c[2] + z[0]);
    for (i = 1; i < m; i++) {
        for (j = 0; j < slices; j++) {
            double phi = 2.0 * VX_MESH_PI * (double)j / (double)slices;
            vx_mesh_v(b, c[0] + rho[i] * cos(phi), c[1] + rho[i] * sin(phi), c[2] + z[i]);
        }
    }
    bottom = vx_mesh_v(b, c[0], c[1], c[2] + z[m]);
    for (j = 0; j < slices; j++) {
        size_t j1 = (j + 1) % slices;
        vx_mesh_t(b, top, base + 1 + j, base + 1 + j1);
    }
    for (i = 1; i + 1 < m; i++) {
        size_t r0 = base + 1 + (i - 1) * slices, r1 = r0 + slices;
        for (j = 0; j < slices; j++) {
            size_t j1 = (j + 1) % slices;
            vx_mesh_t(b, r0 + j, r1 + j, r1 + j1);
            vx_mesh_t(b, r0 + j, r1 + j1, r0 + j1);
        }
    }
    {
        size_t r0 = base + 1 + (m - 2) * slices;
        for (j = 0; j < slices; j++) {
            size_t j1 = (j + 1) % slices;
            vx_mesh_t(b, r0 + j, bottom, r0 + j1);
        }
    }
}

HFVIS_API hfvis_status hfvis_mesh_uv_sphere(const hfvis_allocator *alloc, const double c[3],
                                            double r, int slices, int stacks, hfvis_mesh *out)
{
    vx_mesh_builder b;
    hfvis_status s;
    double *prof;
    size_t i, m, nv, nt;
    if (!out || !vx_mesh_point_ok(c) || !vx_mesh_coord_ok(r) || !(r > 0.0) || slices < 3
        || stacks < 2)
        return HFVIS_ERR_INVALID_ARGUMENT;
    m = (size_t)stacks;
    nv = vx_mesh_add(vx_mesh_mul(m - 1, (size_t)slices), 2);
    nt = vx_mesh_mul(vx_mesh_mul(2, (size_t)slices), m - 1);
    if (nv > HFVIS_MESH_MAX_VERTICES || nt > HFVIS_MESH_MAX_TRIANGLES) return HFVIS_ERR_LIMIT;
    prof = (double *)vx_alloc_array(alloc, m + 1, 2 * sizeof(double));
    if (!prof) return HFVIS_ERR_OUT_OF_MEMORY;
    for (i = 0; i <= m; i++) { /* theta_i = pi i / stacks from the north pole */
        double th = VX_MESH_PI * (double)i / (double)m;
        prof[i] = (i == 0 || i == m) ? 0.0 : r * sin(th);
        prof[m + 1 + i] = (i == 0) ? r : (i == m) ? -r : r * cos(th);
    }
    s = vx_mesh_builder_init(&b, alloc, nv, nt);
    if (s == HFVIS_OK) {
        vx_mesh_revolve(&b, c, prof, prof + m + 1, m, (size_t)slices);
        s = vx_mesh_builder_finish(&b, alloc, out);
    }
    vx_free(alloc, prof);
    return s;
}

/* Edge -> midpoint vertex map of the icosphere subdivision: open addressing, linear probing,
 * key (min << 32 | max) + 1 (0 = empty). */
typedef struct vx_mesh_edge_map {
    uint64_t *keys;
    uint32_t *vals;
    size_t mask;
} vx_mesh_edge_map;

static size_t vx_mesh_edge_slot(const vx_mesh_edge_map *m, uint64_t key)
{
    uint64_t h = key * 0x9E3779B97F4A7C15ull; /* Fibonacci hashing */
    size_t i = (size_t)(h ^ (h >> 29)) & m->mask;
    while (m->keys[i] != 0 && m->keys[i] != key) i = (i + 1) & m->mask;
    return i;
}

/* The midpoint vertex of edge (a, b): created (normalised onto the unit sphere) on first use. */
static uint32_t vx_mesh_midpoint(vx_mesh_edge_map *m, double *unit, size_t *nv, uint32_t a,
                                 uint32_t b)
{
    uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
    uint64_t key = (((uint64_t)lo << 32) | hi) + 1u;
    size_t slot = vx_mesh_edge_slot(m, key);
    double p[3], len;
    int k;
    if (m->keys[slot] == key) return m->vals[slot];
    for (k = 0; k < 3; k++) p[k] = 0.5 * (unit[3 * (size_t)a + k] + unit[3 * (size_t)b + k]);
    len = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    for (k = 0; k < 3; k++) unit[3 * *nv + k] = p[k] / len;
    m->keys[slot] = key;
    m->vals[slot] = (uint32_t)*nv;
    return (uint32_t)(*nv)++;
}

/* The base icosahedron (Kahler's widely copied construction, "Creating an icosphere mesh in
 * code", 2009): the 12 vertices (+-1, +-t, 0), (0, +-1, +-t), (+-t, 0, +-1), t = (1 + sqrt 5)/2,
 * in this order, normalised; the 20 faces below (outward, counter-clockwise). */
static const signed char vx_mesh_ico_v[12][3] = {
    {-1, 1, 0}, {1, 1, 0}, {-1, -1, 0}, {1, -1, 0}, /* (+-1, +-t, 0): second entry times t */
    {0, -1, 1}, {0, 1, 1}, {0, -1, -1}, {0, 1, -1}, /* (0, +-1, +-t): third entry times t */
    {1, 0, -1}, {1, 0, 1}, {-1, 0, -1}, {-1, 0, 1}  /* (+-t, 0, +-1): first entry times t */
};
static const unsigned char vx_mesh_ico_f[20][3] = {
    {0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11},
    {1, 5, 9}, {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
    {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8}, {3, 8, 9},
    {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}
};

HFVIS_API hfvis_status hfvis_mesh_icosphere(const hfvis_allocator *alloc, const double c[3],
                                            double r, int subdivisions, hfvis_mesh *out)
{
    vx_mesh_builder b;
    vx_mesh_edge_map em;
    hfvis_status s;
    double *unit;
    size_t nv, nt, ntl, v, t, cap, k;
    const double tau = (1.0 + sqrt(5.0)) / 2.0;
    int level;
    if (!out || !vx_mesh_point_ok(c) || !vx_mesh_coord_ok(r) || !(r > 0.0) || subdivisions < 0
        || subdivisions > HFVIS_MESH_ICOSPHERE_MAX_SUBDIVISIONS)
        return HFVIS_ERR_INVALID_ARGUMENT;
    nt = (size_t)20 << (2 * subdivisions);   /* 20 * 4^s */
    nv = (size_t)10 * ((size_t)1 << (2 * subdivisions)) + 2; /* Euler: V = T/2 + 2 */
    /* the largest level's edge map: E = 3T/2 edges of the previous level, load <= 1/2 */
    cap = 64;
    while (cap < 3 * nt / 4) cap *= 2; /* 2 * (3/2) * (T/4) */
    em.mask = cap - 1;
    s = vx_mesh_builder_init(&b, alloc, nv, nt);
    if (s != HFVIS_OK) return s;
    unit = (double *)vx_alloc_array(alloc, nv, 3 * sizeof(double));
    em.keys = (uint64_t *)vx_alloc_array(alloc, cap, sizeof(uint64_t));
    em.vals = (uint32_t *)vx_alloc_array(alloc, cap, sizeof(uint32_t));
    if (!unit || !em.keys || !em.vals) {
        vx_free(alloc, em.vals);
        vx_free(alloc, em.keys);
        vx_free(alloc, unit);
        vx_mesh_builder_free(&b, alloc);
        return HFVIS_ERR_OUT_OF_MEMORY;
    }
    for (v = 0; v < 12; v++) {
        double p[3], len;
        p[0] = (double)vx_mesh_ico_v[v][0] * (v >= 8 ? tau : 1.0);
        p[1] = (double)vx_mesh_ico_v[v][1] * (v < 4 ? tau : 1.0);
        p[2] = (double)vx_mesh_ico_v[v][2] * (v >= 4 && v < 8 ? tau : 1.0);
        len = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        for (k = 0; k < 3; k++) unit[3 * v + k] = p[k] / len;
    }
    for (t = 0; t < 20; t++)
        for (k = 0; k < 3; k++) b.idx[3 * t + k] = vx_mesh_ico_f[t][k];
    ntl = 20;
    v = 12;
    for (level = 0; level < subdivisions; level++) {
        /* Kahler's order: pass over the faces in order creating the midpoints of (v1,v2),
         * (v2,v3), (v3,v1) on first use, then every face (v1,v2,v3) becomes (v1,a,c),
         * (v2,b,a), (v3,c,b), (a,b,c) at 4t..4t+3 (expanded from the last face down, in place:
         * face t is read before slots 4t.. are written, and faces < t sit below 4t). */
        memset(em.keys, 0, cap * sizeof(uint64_t));
        for (t = 0; t < ntl; t++) {
            const uint32_t *f = b.idx + 3 * t;
            vx_mesh_midpoint(&em, unit, &v, f[0], f[1]);
            vx_mesh_midpoint(&em, unit, &v, f[1], f[2]);
            vx_mesh_midpoint(&em, unit, &v, f[2], f[0]);
        }
        for (t = ntl; t-- > 0;) {
            uint32_t v1 = b.idx[3 * t], v2 = b.idx[3 * t + 1], v3 = b.idx[3 * t + 2];
            uint32_t ma = vx_mesh_midpoint(&em, unit, &v, v1, v2);
            uint32_t mb = vx_mesh_midpoint(&em, unit, &v, v2, v3);
            uint32_t mc = vx_mesh_midpoint(&em, unit, &v, v3, v1);
            uint32_t *o = b.idx + 12 * t;
            o[0] = v1; o[1] = ma; o[2] = mc;
            o[3] = v2; o[4] = mb; o[5] = ma;
            o[6] = v3; o[7] = mc; o[8] = mb;
            o[9] = ma; o[10] = mb; o[11] = mc;
        }
        ntl *= 4;
    }
    HFVIS_ASSERT(v == nv && ntl == nt);
    for (v = 0; v < nv; v++)
        vx_mesh_v(&b, c[0] + r * unit[3 * v], c[1] + r * unit[3 * v + 1], c[2] + r * unit[3 * v + 2]);
    b.nt = nt;
    vx_free(alloc, em.vals);
    vx_free(alloc, em.keys);
    vx_free(alloc, unit);
    return vx_mesh_builder_finish(&b, alloc, out);
}

/* A closed tube around a periodic frame: ring i (0..n-1) at centre C_i with unit radial axes
 * N_i, B_i and radius rad_i; vertex (i, j) = C_i + rad_i (cos v_j N_i + sin v_j B_i),
 * v_j = 2 pi j / m, j fastest. Triangles (a, b, d), (a, d, c) with a = (i, j), b = (i+1, j),
 * c = (i, j+1), d = (i+1, j+1), indices mod (n, m): outward when T_i x B_i points along N_i
 * (T = direction of increasing i). The torus and the torus knot are this with periodic i. */
static void vx_mesh_tube_tris(vx_mesh_builder *b, size_t base, size_t n, size_t m, int periodic)
{
    size_t i, j;
    for (i = 0; i + (periodic ? 0u : 1u) < n; i++) {
        size_t i1 = (i + 1) % n;
        for (j = 0; j < m; j++) {
            size_t j1 = (j + 1) % m;
            vx_mesh_t(b, base + i * m + j, base + i1 * m + j, base + i1 * m + j1);
            vx_mesh_t(b, base + i * m + j, base + i1 * m + j1, base + i * m + j1);
        }
    }
}

HFVIS_API hfvis_status hfvis_mesh_torus(const hfvis_allocator *alloc, const double c[3],
                                        double R, double r, int major, int minor, hfvis_mesh *out)
{
    vx_mesh_builder b;
    hfvis_status s;
    size_t i, j, n, m, nv, nt;
    if (!out || !vx_mesh_point_ok(c) || !vx_mesh_coord_ok(R) || !vx_mesh_coord_ok(r)
        || !(r > 0.0) || !(r < R) || major < 3 || minor < 3)
        return HFVIS_ERR_INVALID_ARGUMENT;
    n = (size_t)major;
    m = (size_t)minor;
    nv = vx_mesh_mul(n, m);
    nt = vx_mesh_mul(nv, 2);
    s = vx_mesh_builder_init(&b, alloc, nv, nt);
    if (s != HFVIS_OK) return s;
    for (i = 0; i < n; i++) {
        double u = 2.0 * VX_MESH_PI * (double)i / (double)n, cu = cos(u), su = sin(u);
        for (j = 0; j < m; j++) {
            double w = 2.0 * VX_MESH_PI * (double)j / (double)m;
            double rho = R + r * cos(w);
            vx_mesh_v(&b, c[0] + rho * cu, c[1] + rho * su, c[2] + r * sin(w));
        }
    }
    /* T = +phi direction, N = radial (outward), B = +z at v = 0: T x B = N (outward). */
    vx_mesh_tube_tris(&b, 0, n, m, 1);
    return vx_mesh_builder_finish(&b, alloc, out);
}

static int vx_mesh_gcd(int a, int b)
{
    while (b != 0) {
        int t = a % b;
        a = b;
        b = t;
    }
    return a;
}

HFVIS_API hfvis_status hfvis_mesh_torus_knot(const hfvis_allocator *alloc, const double c[3],
                                             double scale, int p, int q, int segments, int sides,
                                             hfvis_mesh *out)
{
    vx_mesh_builder b;
    hfvis_status s;
    size_t i, j, n, m, nv, nt;
    const double R = scale * HFVIS_TORUS_KNOT_MAJOR, a = scale * HFVIS_TORUS_KNOT_MINOR;
    const double tube = scale * HFVIS_TORUS_KNOT_TUBE;
    if (!out || !vx_mesh_point_ok(c) || !vx_mesh_coord_ok(scale) || !(scale > 0.0) || p < 1
        || q < 1 || vx_mesh_gcd(p, q) != 1 || segments < 3 || sides < 3)
        return HFVIS_ERR_INVALID_ARGUMENT;
    n = (size_t)segments;
    m = (size_t)sides;
    nv = vx_mesh_mul(n, m);
    nt = vx_mesh_mul(nv, 2);
    s = vx_mesh_builder_init(&b, alloc, nv, nt);
    if (s != HFVIS_OK) return s;
    for (i = 0; i < n; i++) {
        /* centre line C(t) = ((R + a cos qt) cos pt, (R + a cos qt) sin pt, a sin qt) and its
         * derivative T; frame N = the part of C orthogonal to T (C is never parallel to T on
         * these knots), B = N x T (unit): T x B = N, so the ring pattern is outward. */
        double t = 2.0 * VX_MESH_PI * (double)i / (double)n;
        double cp = cos((double)p * t), sp = sin((double)p * t);
        double cq = cos((double)q * t), sq = sin((double)q * t);
        double rho = R + a * cq, C[3], T[3], N[3], B[3], len, d;
        int k;
        C[0] = rho * cp;
        C[1] = rho * sp;
        C[2] = a * sq;
        T[0] = -a * (double)q * sq * cp - rho * (double)p * sp;
        T[1] = -a * (double)q * sq * sp + rho * (double)p * cp;
        T[2] = a * (double)q * cq;
        len = sqrt(T[0] * T[0] + T[1] * T[1] + T[2] * T[2]);
        for (k = 0; k < 3; k++) T[k] /= len;
        d = C[0] * T[0] + C[1] * T[1] + C[2] * T[2];
        for (k = 0; k < 3; k++) N[k] = C[k] - d * T[k];
        len = sqrt(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]);
        for (k = 0; k < 3; k++) N[k] /= len;
        B[0] = N[1] * T[2] - N[2] * T[1];
        B[1] = N[2] * T[0] - N[0] * T[2];
        B[2] = N[0] * T[1] - N[1] * T[0];
        for (j = 0; j < m; j++) {
            double w = 2.0 * VX_MESH_PI * (double)j / (double)m, cw = cos(w), sw = sin(w);
            vx_mesh_v(&b, c[0] + C[0] + tube * (cw * N[0] + sw * B[0]),
                      c[1] + C[1] + tube * (cw * N[1] + sw * B[1]),
                      c[2] + C[2] + tube * (cw * N[2] + sw * B[2]));
        }
    }
    vx_mesh_tube_tris(&b, 0, n, m, 1);
    return vx_mesh_builder_finish(&b, alloc, out);
}

HFVIS_API hfvis_status hfvis_mesh_from_grid(const hfvis_allocator *alloc, const hfvis_grid *g,
                                            hfvis_mesh *out)
{
    vx_mesh_builder b;
    hfvis_status s;
    uint32_t *remap = NULL;
    size_t W, H, x, y, nv = 0, nt = 0, npts;
    if (!out || !g || !g->z || g->width < 1 || g->height < 1 || g->stride < g->width
        || !isfinite(g->cell_size) || !(g->cell_size > 0.0))
        return HFVIS_ERR_INVALID_ARGUMENT;
    W = (size_t)g->width;
    H = (size_t)g->height;
    if (!vx_mesh_coord_ok((double)(W - 1) * g->cell_size)
        || !vx_mesh_coord_ok((double)(H - 1) * g->cell_size)
        || !isfinite((float)((double)(W - 1) * g->cell_size))
        || !isfinite((float)((double)(H - 1) * g->cell_size)))
        return HFVIS_ERR_INVALID_ARGUMENT;
    npts = vx_mesh_mul(W, H);
    if (npts > HFVIS_MESH_MAX_VERTICES) return HFVIS_ERR_LIMIT;
    /* pass 1: triangles kept (all three corners finite) and vertices they use */
    remap = (uint32_t *)vx_alloc_array(alloc, npts, sizeof(uint32_t));
    if (!remap) return HFVIS_ERR_OUT_OF_MEMORY;
    for (x = 0; x < npts; x++) remap[x] = 0;
#define VX_MESH_Z(xx, yy) g->z[(ptrdiff_t)(yy) * g->stride + (ptrdiff_t)(xx)]
#define VX_MESH_OK(xx, yy) isfinite(VX_MESH_Z(xx, yy))
    for (y = 0; y + 1 < H; y++) {
        for (x = 0; x + 1 < W; x++) {
            /* quad a = (x, y), b = (x+1, y), c = (x, y+1), d = (x+1, y+1), split along a-d:
             * triangles (a, b, d) and (a, d, c), normal +z for a flat field */
            int a = VX_MESH_OK(x, y), bb = VX_MESH_OK(x + 1, y), cc = VX_MESH_OK(x, y + 1);
            int d = VX_MESH_OK(x + 1, y + 1);
            if (a && bb && d) {
                remap[y * W + x] = remap[y * W + x + 1] = remap[(y + 1) * W + x + 1] = 1;
                nt++;
            }
            if (a && d && cc) {
                remap[y * W + x] = remap[(y + 1) * W + x + 1] = remap[(y + 1) * W + x] = 1;
                nt++;
            }
        }
    }
    for (x = 0; x < npts; x++)
        if (remap[x]) remap[x] = (uint32_t)nv++;
        else remap[x] = UINT32_MAX;
    if (nt > HFVIS_MESH_MAX_TRIANGLES) {
        vx_free(alloc, remap);
        return HFVIS_ERR_LIMIT;
    }
    s = vx_mesh_builder_init(&b, alloc, nv, nt);
    if (s != HFVIS_OK) {
        vx_free(alloc, remap);
        return s;
    }
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++)
            if (remap[y * W + x] != UINT32_MAX)
                vx_mesh_v(&b, (double)x * g->cell_size, (double)y * g->cell_size,
                          (double)VX_MESH_Z(x, y));
    for (y = 0; y + 1 < H; y++) {
        for (x = 0; x + 1 < W; x++) {
            uint32_t a = remap[y * W + x], bb = remap[y * W + x + 1];
            uint32_t cc = remap[(y + 1) * W + x], d = remap[(y + 1) * W + x + 1];
            int fa = VX_MESH_OK(x, y), fb = VX_MESH_OK(x + 1, y), fc = VX_MESH_OK(x, y + 1);
            int fd = VX_MESH_OK(x + 1, y + 1);
            if (fa && fb && fd) vx_mesh_t(&b, a, bb, d);
            if (fa && fd && fc) vx_mesh_t(&b, a, d, cc);
        }
    }
#undef VX_MESH_OK
#undef VX_MESH_Z
    vx_free(alloc, remap);
    return vx_mesh_builder_finish(&b, alloc, out);
}

/* Box (corner k as in vx_mesh_box_tris) rotated by angle about the vertical axis through its
 * centre (cx, cy), from z0 to z1; skip_face 0..5 (-x +x -y +y -z +z) is left out, -1 none;
 * inward != 0 reverses every triangle (faces looking into the box). */
static void vx_mesh_room_box(vx_mesh_builder *b, double cx, double cy, double hx, double hy,
                             double z0, double z1, double angle, int skip_face, int inward)
{
    size_t base = b->nv;
    double ca = cos(angle), sa = sin(angle);
    int k;
    for (k = 0; k < 8; k++) {
        double lx = (k & 1) ? hx : -hx, ly = (k & 2) ? hy : -hy;
        vx_mesh_v(b, angle == 0.0 ? cx + lx : cx + ca * lx - sa * ly,
                  angle == 0.0 ? cy + ly : cy + sa * lx + ca * ly, (k & 4) ? z1 : z0);
    }
    for (k = 0; k < 12; k++) {
        if (k / 2 == skip_face) continue;
        if (inward)
            vx_mesh_t(b, base + vx_mesh_box_tris[k][0], base + vx_mesh_box_tris[k][2],
                      base + vx_mesh_box_tris[k][1]);
        else
            vx_mesh_t(b, base + vx_mesh_box_tris[k][0], base + vx_mesh_box_tris[k][1],
                      base + vx_mesh_box_tris[k][2]);
    }
}

HFVIS_API hfvis_status hfvis_mesh_room(const hfvis_allocator *alloc, hfvis_mesh *out)
{
    vx_mesh_builder b;
    hfvis_status s;
    const double deg17 = 17.0 * VX_MESH_PI / 180.0;
    if (!out) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_mesh_builder_init(&b, alloc, 24, 30);
    if (s != HFVIS_OK) return s;
    /* walls: the unit cube seen from inside, open at y = 0 (face -y) */
    vx_mesh_room_box(&b, 0.5, 0.5, 0.5, 0.5, 0.0, 1.0, 0.0, 2, 1);
    /* short box 0.3 x 0.3 x 0.3 at (0.66, 0.33), rotated -17 deg; tall box 0.3 x 0.3 x 0.6 at
     * (0.34, 0.62), rotated +17 deg; both standing on the floor, without bottom faces */
    vx_mesh_room_box(&b, 0.66, 0.33, 0.15, 0.15, 0.0, 0.3, -deg17, 4, 0);
    vx_mesh_room_box(&b, 0.34, 0.62, 0.15, 0.15, 0.0, 0.6, deg17, 4, 0);
    return vx_mesh_builder_finish(&b, alloc, out);
}

/* Uniform Catmull-Rom through pts[0..count) (2 doubles each), at parameter s in [0, count-1],
 * end tangents from the doubled end points. */
static void vx_mesh_catmull(const double (*pts)[2], int count, double s, double out[2])
{
    int i = (int)floor(s), k;
    double u, u2, u3;
    if (i > count - 2) i = count - 2;
    if (i < 0) i = 0;
    u = s - (double)i;
    u2 = u * u;
    u3 = u2 * u;
    for (k = 0; k < 2; k++) {
        double p0 = pts[i > 0 ? i - 1 : 0][k], p1 = pts[i][k], p2 = pts[i + 1][k];
        double p3 = pts[i + 2 < count ? i + 2 : count - 1][k];
        out[k] = 0.5 * (2.0 * p1 + (-p0 + p2) * u + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * u2
                        + (-p0 + 3.0 * p1 - 3.0 * p2 + p3) * u3);
    }
}

/* Teapot profile (rho, z), top pole to bottom pole, body + lid + knob in one closed surface. */
static const double vx_mesh_teapot_profile[][2] = {
    {0.00, 1.42}, {0.13, 1.40}, {0.14, 1.32}, {0.08, 1.25}, {0.20, 1.15}, {0.45, 1.09},
    {0.62, 1.03}, {0.66, 1.00}, {0.80, 0.92}, {0.95, 0.72}, {1.00, 0.48}, {0.94, 0.22},
    {0.80, 0.06}, {0.70, 0.00}, {0.35, 0.00}, {0.00, 0.00}
};
#define VX_MESH_TEAPOT_PROFILE_N ((int)(sizeof vx_mesh_teapot_profile / sizeof vx_mesh_teapot_profile[0]))

/* Point and tangent of the teapot's spout (which = 0, quadratic Bezier) or handle (1, cubic
 * Bezier) centre line in the y = 0 plane at s in [0, 1]; radius of the tube there. */
static void vx_mesh_teapot_curve(int which, double s, double P[3], double T[3], double *rad)
{
    static const double spout[3][2] = {{0.55, 0.30}, {1.45, 0.35}, {1.60, 1.05}};
    static const double handle[4][2] = {{-0.70, 0.88}, {-1.65, 1.00}, {-1.60, 0.18}, {-0.72, 0.30}};
    double u = 1.0 - s;
    int k;
    for (k = 0; k < 2; k++) {
        double pos, der;
        if (which == 0) {
            pos = u * u * spout[0][k] + 2.0 * u * s * spout[1][k] + s * s * spout[2][k];
            der = 2.0 * u * (spout[1][k] - spout[0][k]) + 2.0 * s * (spout[2][k] - spout[1][k]);
        } else {
            pos = u * u * u * handle[0][k] + 3.0 * u * u * s * handle[1][k]
                  + 3.0 * u * s * s * handle[2][k] + s * s * s * handle[3][k];
            der = 3.0 * u * u * (handle[1][k] - handle[0][k])
                  + 6.0 * u * s * (handle[2][k] - handle[1][k])
                  + 3.0 * s * s * (handle[3][k] - handle[2][k]);
        }
        P[2 * k] = pos; /* k = 0 -> x, k = 1 -> z */
        T[2 * k] = der;
    }
    P[1] = 0.0;
    T[1] = 0.0;
    *rad = which == 0 ? 0.17 - 0.09 * s : 0.075;
}

HFVIS_API hfvis_status hfvis_mesh_teapot(const hfvis_allocator *alloc, int n, hfvis_mesh *out)
{
    vx_mesh_builder b;
    hfvis_status s;
    double *prof, zero[3] = {0.0, 0.0, 0.0};
    size_t nn, slices, m, along, around, nv, nt, i, j, tube_v, tube_t;
    int which;
    if (!out || n < 1) return HFVIS_ERR_INVALID_ARGUMENT;
    if (n > 4096) return HFVIS_ERR_LIMIT; /* past the vertex limit already */
    nn = (size_t)n;
    slices = 12 * nn;
    m = 8 * nn;
    along = 8 * nn + 1; /* rings along each tube */
    around = 6 * nn;
    tube_v = vx_mesh_mul(along, around);
    tube_t = vx_mesh_mul(2 * (along - 1), around);
    nv = vx_mesh_add(vx_mesh_add(vx_mesh_mul(m - 1, slices), 2), vx_mesh_mul(2, tube_v));
    nt = vx_mesh_add(vx_mesh_mul(2 * slices, m - 1), vx_mesh_mul(2, tube_t));
    if (nv > HFVIS_MESH_MAX_VERTICES || nt > HFVIS_MESH_MAX_TRIANGLES) return HFVIS_ERR_LIMIT;
    prof = (double *)vx_alloc_array(alloc, m + 1, 2 * sizeof(double));
    if (!prof) return HFVIS_ERR_OUT_OF_MEMORY;
    for (i = 0; i <= m; i++) {
        double pt[2];
        vx_mesh_catmull(vx_mesh_teapot_profile, VX_MESH_TEAPOT_PROFILE_N,
                        (double)(VX_MESH_TEAPOT_PROFILE_N - 1) * (double)i / (double)m, pt);
        prof[i] = (i == 0 || i == m) ? 0.0 : fabs(pt[0]);
        prof[m + 1 + i] = pt[1] > 0.0 ? pt[1] : 0.0; /* the spline dips below the flat base */
    }
    s = vx_mesh_builder_init(&b, alloc, nv, nt);
    if (s != HFVIS_OK) {
        vx_free(alloc, prof);
        return s;
    }
    vx_mesh_revolve(&b, zero, prof, prof + m + 1, m, slices);
    vx_free(alloc, prof);
    for (which = 0; which < 2; which++) {
        size_t base = b.nv;
        for (i = 0; i < along; i++) {
            double P[3], T[3], N[3], rad, len;
            const double Bv[3] = {0.0, 1.0, 0.0};
            vx_mesh_teapot_curve(which, (double)i / (double)(along - 1), P, T, &rad);
            len = sqrt(T[0] * T[0] + T[2] * T[2]);
            T[0] /= len;
            T[2] /= len;
            /* N = T x B with B = +y: T x B = N (outward ring pattern) */
            N[0] = -T[2];
            N[1] = 0.0;
            N[2] = T[0];
            for (j = 0; j < around; j++) {
                double w = 2.0 * VX_MESH_PI * (double)j / (double)around, cw = cos(w), sw = sin(w);
                vx_mesh_v(&b, P[0] + rad * (cw * N[0] + sw * Bv[0]), rad * sw * Bv[1],
                          P[2] + rad * (cw * N[2] + sw * Bv[2]));
            }
        }
        vx_mesh_tube_tris(&b, base, along, around, 0);
    }
    return vx_mesh_builder_finish(&b, alloc, out);
}

/* ---- 1c. bounds ------------------------------------------------------------------------- */

HFVIS_API hfvis_status hfvis_mesh_bounds(const hfvis_mesh *mesh, double lo[3], double hi[3])
{
    double l[3], h[3];
    size_t v;
    int k;
    if (!lo || !hi || vx_mesh_check(mesh) != HFVIS_OK || mesh->vertex_count == 0)
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (k = 0; k < 3; k++) l[k] = h[k] = (double)mesh->xyz[k];
    for (v = 1; v < mesh->vertex_count; v++) {
        for (k = 0; k < 3; k++) {
            double c = (double)mesh->xyz[3 * v + (size_t)k];
            if (c < l[k]) l[k] = c;
            if (c > h[k]) h[k] = c;
        }
    }
    for (k = 0; k < 3; k++) {
        lo[k] = l[k];
        hi[k] = h[k];
    }
    return HFVIS_OK;
}

/* ---- 1d. OBJ decoder -------------------------------------------------------------------- */
/* Wavefront OBJ subset (DESIGN §4): `v x y z [w | r g b ...]` and `f` lines; every other
 * statement is ignored. Two passes over the bytes with the same parser: pass 1 validates and
 * counts, pass 2 fills arrays of exactly the counted sizes (forward vertex references are
 * range-checked there). */

/* 10^0 .. 10^22: exact in double. */
static const double vx_mesh_obj_pow10[23] = {
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11,
    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22
};

/* d * 10^e, |e| small (<= ~70 here): steps of exact powers, multiplying for e > 0 and dividing
 * for e < 0, so each step rounds once (<= 4 steps: within 2 ulp of double in all). */
static double vx_mesh_obj_scale10(double d, long e)
{
    while (e > 22) {
        d *= 1e22;
        e -= 22;
    }
    while (e < -22) {
        d /= 1e22;
        e += 22;
    }
    return e >= 0 ? d * vx_mesh_obj_pow10[e] : d / vx_mesh_obj_pow10[-e];
}

static int vx_mesh_obj_digit(unsigned char c) { return c >= '0' && c <= '9'; }

/* Parse the whole token [s, e) as a decimal number, locale-independently:
 * [+-] (digits [. digits*] | . digits) [(e|E) [+-] digits]. No inf/nan/hex. The first 19
 * significant digits are kept exactly (later ones are dropped), the value is mant * 10^exp in
 * double (within 3 ulp of double), then rounded once to float. Returns 0 for a malformed token
 * or a value outside the float range (|v| rounds to infinity); values below the smallest
 * subnormal become (signed) zero. */
static int vx_mesh_obj_parse_float(const unsigned char *s, const unsigned char *e, float *out)
{
    uint64_t mant = 0;
    long long dexp = 0, ex = 0, e10;
    int neg = 0, eneg = 0, nd = 0, any = 0;
    double d;
    float f;
    if (s < e && (*s == '+' || *s == '-')) neg = *s++ == '-';
    for (; s < e && vx_mesh_obj_digit(*s); s++) {
        any = 1;
        if (mant == 0 && *s == '0') continue; /* leading zero */
        if (nd < 19) {
            mant = mant * 10u + (uint64_t)(*s - '0');
            nd++;
        } else {
            dexp++; /* dropped integer digit */
        }
    }
    if (s < e && *s == '.') {
        for (s++; s < e && vx_mesh_obj_digit(*s); s++) {
            any = 1;
            if (mant == 0 && *s == '0') {
                dexp--;
            } else if (nd < 19) {
                mant = mant * 10u + (uint64_t)(*s - '0');
                nd++;
                dexp--;
            }
        }
    }
    if (!any) return 0;
    if (s < e && (*s == 'e' || *s == 'E')) {
        s++;
        if (s < e && (*s == '+' || *s == '-')) eneg = *s++ == '-';
        if (s >= e || !vx_mesh_obj_digit(*s)) return 0;
        for (; s < e && vx_mesh_obj_digit(*s); s++)
            if (ex < 1000000000000000LL) ex = ex * 10 + (*s - '0');
    }
    if (s != e) return 0;
    if (mant == 0) {
        *out = neg ? -0.0f : 0.0f;
        return 1;
    }
    e10 = dexp + (eneg ? -ex : ex);
    /* mant has nd digits: the value lies in [10^(e10+nd-1), 10^(e10+nd)) */
    if (e10 + nd - 1 > 38) return 0;          /* >= 1e39 > FLT_MAX */
    if (e10 + nd < -46) {                     /* < 1e-46: below half the smallest subnormal */
        *out = neg ? -0.0f : 0.0f;
        return 1;
    }
    d = vx_mesh_obj_scale10((double)mant, (long)e10);
    f = (float)d;
    if (!isfinite(f)) return 0;
    *out = neg ? -f : f;
    return 1;
}

/* One signed, non-zero OBJ index [+-]digits at *s (saturating at 2^40); advances *s. */
static int vx_mesh_obj_parse_index(const unsigned char **sp, const unsigned char *e, long long *out)
{
    const unsigned char *s = *sp;
    long long v = 0;
    int neg = 0;
    if (s < e && (*s == '+' || *s == '-')) neg = *s++ == '-';
    if (s >= e || !vx_mesh_obj_digit(*s)) return 0;
    for (; s < e && vx_mesh_obj_digit(*s); s++)
        if (v < (1LL << 40)) v = v * 10 + (*s - '0');
    if (v == 0) return 0;
    *out = neg ? -v : v;
    *sp = s;
    return 1;
}

static int vx_mesh_obj_space(unsigned char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f'; }

typedef struct vx_mesh_obj_pass {
    int fill;          /* 0: validate and count; 1: write */
    size_t nv, nt;     /* vertices / triangles so far */
    size_t total_v;    /* pass 2: the vertex count of pass 1 */
    float *xyz;
    uint32_t *idx;
} vx_mesh_obj_pass;

/* A face vertex token: i, i/t, i//n or i/t/n (t, n checked for syntax only: they are not
 * used). Resolves i to a 0-based vertex (negative = relative to the vertices read so far). */
static hfvis_status vx_mesh_obj_face_ref(const vx_mesh_obj_pass *ps, const unsigned char *s,
                                    const unsigned char *e, size_t *vout)
{
    long long i, t;
    if (!vx_mesh_obj_parse_index(&s, e, &i)) return HFVIS_ERR_FORMAT;
    if (s < e) {
        if (*s++ != '/') return HFVIS_ERR_FORMAT;
        if (s < e && *s == '/') {
            s++;
            if (!vx_mesh_obj_parse_index(&s, e, &t)) return HFVIS_ERR_FORMAT; /* i//n */
        } else {
            if (!vx_mesh_obj_parse_index(&s, e, &t)) return HFVIS_ERR_FORMAT; /* i/t */
            if (s < e) {
                if (*s++ != '/') return HFVIS_ERR_FORMAT;
                if (!vx_mesh_obj_parse_index(&s, e, &t)) return HFVIS_ERR_FORMAT; /* i/t/n */
            }
        }
        if (s != e) return HFVIS_ERR_FORMAT;
    }
    if (i < 0) {
        if ((unsigned long long)(-i) > (unsigned long long)ps->nv) return HFVIS_ERR_FORMAT;
        *vout = ps->nv - (size_t)(-i);
    } else {
        if ((unsigned long long)i > (unsigned long long)HFVIS_MESH_MAX_VERTICES)
            return HFVIS_ERR_FORMAT; /* beyond any vertex a file may hold */
        if (ps->fill && (size_t)i > ps->total_v) return HFVIS_ERR_FORMAT;
        *vout = (size_t)(i - 1);
    }
    return HFVIS_OK;
}

/* One pass over the whole buffer. Lines end at '\n' or '\r' (so CRLF and CR files work);
 * '#' starts a comment anywhere; tokens are separated by blanks and tabs. */
static hfvis_status vx_mesh_obj_run(vx_mesh_obj_pass *ps, const unsigned char *p, const unsigned char *end)
{
    while (p < end) {
        const unsigned char *le = p, *ce, *q, *ks;
        while (le < end && *le != '\n' && *le != '\r') le++;
        for (ce = p; ce < le && *ce != '#'; ce++) {}
        q = p;
        p = le < end ? le + 1 : le;
        while (q < ce && vx_mesh_obj_space(*q)) q++;
        if (q == ce) continue;
        ks = q;
        while (q < ce && !vx_mesh_obj_space(*q)) q++;
        if (q - ks == 1 && *ks == 'v') {
            float c[3];
            int n = 0;
            for (;;) {
                const unsigned char *ts;
                float f;
                while (q < ce && vx_mesh_obj_space(*q)) q++;
                if (q == ce) break;
                ts = q;
                while (q < ce && !vx_mesh_obj_space(*q)) q++;
                if (!vx_mesh_obj_parse_float(ts, q, &f)) return HFVIS_ERR_FORMAT;
                if (n < 3) c[n] = f;
                n++;
            }
            if (n < 3) return HFVIS_ERR_FORMAT;
            if (ps->nv >= HFVIS_MESH_MAX_VERTICES) return HFVIS_ERR_LIMIT;
            if (ps->fill) memcpy(ps->xyz + 3 * ps->nv, c, sizeof c);
            ps->nv++;
        } else if (q - ks == 1 && *ks == 'f') {
            size_t first = 0, prev = 0, v;
            int n = 0;
            for (;;) {
                const unsigned char *ts;
                hfvis_status s;
                while (q < ce && vx_mesh_obj_space(*q)) q++;
                if (q == ce) break;
                ts = q;
                while (q < ce && !vx_mesh_obj_space(*q)) q++;
                s = vx_mesh_obj_face_ref(ps, ts, q, &v);
                if (s != HFVIS_OK) return s;
                if (n >= 2) { /* fan: (v0, v_{k-1}, v_k) */
                    if (ps->nt >= HFVIS_MESH_MAX_TRIANGLES) return HFVIS_ERR_LIMIT;
                    if (ps->fill) {
                        ps->idx[3 * ps->nt] = (uint32_t)first;
                        ps->idx[3 * ps->nt + 1] = (uint32_t)prev;
                        ps->idx[3 * ps->nt + 2] = (uint32_t)v;
                    }
                    ps->nt++;
                }
                if (n == 0) first = v;
                prev = v;
                n++;
            }
            if (n < 3) return HFVIS_ERR_FORMAT;
        }
        /* any other statement (vt, vn, vp, o, g, s, usemtl, mtllib, l, p, ...) is ignored */
    }
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_obj_decode(const void *data, size_t size,
                                        const hfvis_allocator *alloc, hfvis_mesh *out)
{
    const unsigned char *p = (const unsigned char *)data;
    vx_mesh_obj_pass ps;
    vx_mesh_builder b;
    hfvis_status s;
    if (!out || (!data && size > 0)) return HFVIS_ERR_INVALID_ARGUMENT;
    memset(&ps, 0, sizeof ps);
    s = vx_mesh_obj_run(&ps, p, p + size);
    if (s != HFVIS_OK) return s;
    s = vx_mesh_builder_init(&b, alloc, ps.nv, ps.nt);
    if (s != HFVIS_OK) return s;
    ps.total_v = ps.nv;
    ps.nv = ps.nt = 0;
    ps.fill = 1;
    ps.xyz = b.xyz;
    ps.idx = b.idx;
    s = vx_mesh_obj_run(&ps, p, p + size);
    if (s != HFVIS_OK) {
        vx_mesh_builder_free(&b, alloc);
        return s;
    }
    HFVIS_ASSERT(ps.nv == b.cap_v && ps.nt == b.cap_t);
    b.nv = ps.nv;
    b.nt = ps.nt;
    return vx_mesh_builder_finish(&b, alloc, out);
}

/* ---- 1e. OBJ encoder, file wrappers ----------------------------------------------------- */

#define VX_MESH_OBJ_FLOAT_MAX 16 /* longest number written: "-1.23456789e-38" is 15 */

/* The decimal digits of n (>= 0) into buf; returns the count. */
static size_t vx_mesh_obj_utoa(uint64_t n, char *buf)
{
    char tmp[24];
    size_t k = 0, i;
    do {
        tmp[k++] = (char)('0' + (int)(n % 10u));
        n /= 10u;
    } while (n != 0);
    for (i = 0; i < k; i++) buf[i] = tmp[k - 1 - i];
    return k;
}

/* N (exactly p digits) * 10^(k - p + 1) as the shorter of plain and scientific notation. */
static size_t vx_mesh_obj_layout(int neg, uint64_t N, int p, int k, char *buf)
{
    char dig[12], sci[VX_MESH_OBJ_FLOAT_MAX + 8], fix[64];
    size_t ns = 0, nf = 0;
    int i;
    vx_mesh_obj_utoa(N, dig);
    /* scientific: d[.ddd]e[-]k */
    if (neg) sci[ns++] = '-';
    sci[ns++] = dig[0];
    if (p > 1) {
        sci[ns++] = '.';
        for (i = 1; i < p; i++) sci[ns++] = dig[i];
    }
    sci[ns++] = 'e';
    if (k < 0) sci[ns++] = '-';
    ns += vx_mesh_obj_utoa((uint64_t)(k < 0 ? -k : k), sci + ns);
    /* plain */
    if (neg) fix[nf++] = '-';
    if (k < 0) {
        fix[nf++] = '0';
        fix[nf++] = '.';
        for (i = 0; i < -k - 1; i++) fix[nf++] = '0';
        for (i = 0; i < p; i++) fix[nf++] = dig[i];
    } else {
        for (i = 0; i < p || i <= k; i++) {
            if (i == k + 1) fix[nf++] = '.';
            fix[nf++] = i < p ? dig[i] : '0';
        }
    }
    if (nf <= ns) {
        memcpy(buf, fix, nf);
        return nf;
    }
    memcpy(buf, sci, ns);
    return ns;
}

/* The shortest decimal (1..9 significant digits) that vx_mesh_obj_parse_float reads back as f, bit
 * for bit (9 digits always do: a 9-digit decimal is within 5e-9 relative of f, far from the
 * midpoints to the neighbouring floats, at least 3e-8 relative away). f finite.
 * With X = |f| 10^(8-k) in [10^8, 10^9) (k = the decimal exponent of f), for p = 1, 2, ...:
 * N = round(X / 10^(9-p)) (p digits), accepted when N 10^(9-p) lies inside f's rounding
 * interval [L, H] (the midpoints to the neighbouring floats, exact in double, scaled alike).
 * The test runs in double (X, L, H within 4 ulp); where it is too close to call (within
 * 1e-12 relative) the candidate is parsed back instead, so the answer is exact. */
static size_t vx_mesh_obj_format_float(float f, char *buf)
{
    float af = fabsf(f), fm = nextafterf(af, 0.0f), fp = nextafterf(af, INFINITY);
    double x = (double)af, lo = 0.5 * (x + (double)fm);
    double hi = isfinite(fp) ? 0.5 * (x + (double)fp) : x + 0.5 * (x - (double)fm);
    double X = 0.0, L, H;
    int neg = signbit(f) != 0, p, k, it;
    if (x == 0.0) {
        if (neg) {
            buf[0] = '-';
            buf[1] = '0';
            return 2;
        }
        buf[0] = '0';
        return 1;
    }
    k = (int)floor(log10(x)); /* may be one off: adjust */
    for (it = 0; it < 3; it++) {
        X = vx_mesh_obj_scale10(x, (long)(8 - k));
        if (X >= 1e9) k++;
        else if (X < 1e8) k--;
        else break;
    }
    L = vx_mesh_obj_scale10(lo, (long)(8 - k));
    H = vx_mesh_obj_scale10(hi, (long)(8 - k));
    for (p = 1; p <= 9; p++) {
        double s = vx_mesh_obj_pow10[9 - p], dN = floor(X / s + 0.5), Lp = L / s, Hp = H / s;
        double tol = 1e-12 * vx_mesh_obj_pow10[p];
        uint64_t N = (uint64_t)dN;
        int kk = k;
        size_t n;
        float back;
        if (dN < Lp - tol || dN > Hp + tol) continue; /* certainly outside */
        if (N >= (uint64_t)vx_mesh_obj_pow10[p]) { /* rounded up to 10^p: 1 0..0 one decade up */
            N /= 10u;
            kk++;
        }
        n = vx_mesh_obj_layout(neg, N, p, kk, buf);
        if (dN > Lp + tol && dN < Hp - tol) return n; /* certainly inside */
        if (vx_mesh_obj_parse_float((const unsigned char *)buf, (const unsigned char *)buf + n, &back)
            && memcmp(&back, &f, sizeof f) == 0)
            return n;
    }
    HFVIS_ASSERT(0); /* unreachable: 9 digits always round-trip */
    return vx_mesh_obj_layout(neg, 0, 1, 0, buf);
}

/* Emit (or only count, out == NULL) the encoding; returns the byte count, 0 on overflow. */
static size_t vx_mesh_obj_emit(const hfvis_mesh *m, unsigned char *out)
{
    char line[4 * 24 + 3 * VX_MESH_OBJ_FLOAT_MAX];
    size_t total = 0, i, n;
    int k;
    /* header: "# hfvis mesh: V vertices, T triangles\n" */
    n = 0;
    memcpy(line, "# hfvis mesh: ", 14);
    n = 14;
    n += vx_mesh_obj_utoa((uint64_t)m->vertex_count, line + n);
    memcpy(line + n, " vertices, ", 11);
    n += 11;
    n += vx_mesh_obj_utoa((uint64_t)m->triangle_count, line + n);
    memcpy(line + n, " triangles\n", 11);
    n += 11;
    if (out) memcpy(out, line, n);
    total = n;
    for (i = 0; i < m->vertex_count; i++) {
        line[0] = 'v';
        n = 1;
        for (k = 0; k < 3; k++) {
            line[n++] = ' ';
            n += vx_mesh_obj_format_float(m->xyz[3 * i + (size_t)k], line + n);
        }
        line[n++] = '\n';
        if (total > SIZE_MAX - n) return 0;
        if (out) memcpy(out + total, line, n);
        total += n;
    }
    for (i = 0; i < m->triangle_count; i++) {
        line[0] = 'f';
        n = 1;
        for (k = 0; k < 3; k++) {
            line[n++] = ' ';
            n += vx_mesh_obj_utoa((uint64_t)m->indices[3 * i + (size_t)k] + 1u, line + n);
        }
        line[n++] = '\n';
        if (total > SIZE_MAX - n) return 0;
        if (out) memcpy(out + total, line, n);
        total += n;
    }
    return total;
}

HFVIS_API size_t hfvis_obj_encode_size(const hfvis_mesh *mesh)
{
    if (vx_mesh_check(mesh) != HFVIS_OK) return 0;
    return vx_mesh_obj_emit(mesh, NULL);
}

HFVIS_API hfvis_status hfvis_obj_encode(const hfvis_mesh *mesh, void *out, size_t out_capacity,
                                        size_t *written)
{
    size_t need;
    if (!out || !written || vx_mesh_check(mesh) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    need = vx_mesh_obj_emit(mesh, NULL);
    if (need == 0) return HFVIS_ERR_INVALID_ARGUMENT;
    if (out_capacity < need) return HFVIS_ERR_BUFFER_TOO_SMALL;
    vx_mesh_obj_emit(mesh, (unsigned char *)out);
    *written = need;
    return HFVIS_OK;
}

#ifndef HFVIS_NO_STDIO
HFVIS_API hfvis_status hfvis_mesh_load(const char *path, const hfvis_allocator *alloc,
                                       hfvis_mesh *out)
{
    unsigned char *data = NULL;
    size_t size = 0;
    hfvis_status s;
    if (!path || !out) return HFVIS_ERR_INVALID_ARGUMENT;
    s = hfvis__read_file(path, alloc, &data, &size);
    if (s != HFVIS_OK) return s;
    s = hfvis_obj_decode(data, size, alloc, out);
    vx_free(alloc, data);
    return s;
}

HFVIS_API hfvis_status hfvis_mesh_save(const char *path, const hfvis_mesh *mesh)
{
    size_t need, written = 0;
    unsigned char *buf;
    hfvis_status s;
    if (!path || vx_mesh_check(mesh) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    need = vx_mesh_obj_emit(mesh, NULL);
    if (need == 0) return HFVIS_ERR_INVALID_ARGUMENT;
    buf = (unsigned char *)vx_alloc(NULL, need);
    if (!buf) return HFVIS_ERR_OUT_OF_MEMORY;
    written = vx_mesh_obj_emit(mesh, buf);
    s = hfvis__write_file(path, buf, written);
    vx_free(NULL, buf);
    return s;
}
#endif /* HFVIS_NO_STDIO */
