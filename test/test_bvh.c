/* test_bvh.c - BVH, watertight ray-triangle test and ray queries (voxel.c section 6).
 * The BVH queries are held to their naive oracles with EXACT equality (t, triangle, u, v, front
 * bits; any-hit verdicts) on seeded rays over several meshes and every leaf size. */
#include "hfvis.h"
#include "test.h"

#include <float.h>
#include <stdint.h>
#include <stdlib.h>

/* Tolerances */
#define T_ANALYTIC 1e-6   /* hand-made hits: t, u, v from a few float operations (a few ulp) */
#define T_FRONT_COS 1e-3  /* front-flag check only where |cos(direction, normal)| exceeds this */

#define RAYS_PER_CASE 2600 /* per (mesh, leaf size): 6 meshes x 8 leaf sizes x 2600 = 124,800 */

/* ---- helpers ------------------------------------------------------------------------------ */

#define D(x) ((double)(x))

static double dlen(const float d[3])
{
    return sqrt(D(d[0]) * D(d[0]) + D(d[1]) * D(d[1]) + D(d[2]) * D(d[2]));
}

static uint64_t rng_s;
static void rng_seed(uint64_t s)
{
    rng_s = s * 0x9E3779B97F4A7C15ull + 0x2545F4914F6CDD1Dull;
}
static uint32_t rng_u32(void)
{
    /* xorshift64* */
    rng_s ^= rng_s >> 12;
    rng_s ^= rng_s << 25;
    rng_s ^= rng_s >> 27;
    return (uint32_t)((rng_s * 0x2545F4914F6CDD1Dull) >> 32);
}
static double rng_unit(void) /* [0, 1) */
{
    return (double)rng_u32() / 4294967296.0;
}
static double rng_range(double a, double b)
{
    return a + (b - a) * rng_unit();
}
static void rng_dir(double d[3]) /* uniform on the unit sphere */
{
    double z = rng_range(-1.0, 1.0), p = rng_range(0.0, 6.283185307179586), s = sqrt(1.0 - z * z);
    d[0] = s * cos(p);
    d[1] = s * sin(p);
    d[2] = z;
}

static hfvis_ray make_ray(double ox, double oy, double oz, double dx, double dy, double dz)
{
    hfvis_ray r;
    memset(&r, 0, sizeof r);
    r.origin[0] = (float)ox;
    r.origin[1] = (float)oy;
    r.origin[2] = (float)oz;
    r.direction[0] = (float)dx;
    r.direction[1] = (float)dy;
    r.direction[2] = (float)dz;
    r.t_min = 0.0f;
    r.t_max = INFINITY;
    r.cull = HFVIS_CULL_NONE;
    return r;
}

static int hit_equal(const hfvis_hit *a, const hfvis_hit *b)
{
    return a->t == b->t && a->triangle == b->triangle && a->u == b->u && a->v == b->v
           && a->front == b->front;
}

static const float *vert(const hfvis_mesh *m, size_t t, int k)
{
    return m->xyz + 3 * (size_t)m->indices[3 * t + (size_t)k];
}

/* A mesh whose arrays the test owns (malloc), freed with hfvis_mesh_free(NULL, .). */
static hfvis_mesh soup_alloc(size_t nv, size_t nt, float **xyz, uint32_t **idx)
{
    hfvis_mesh m;
    *xyz = (float *)malloc(sizeof(float) * 3 * (nv ? nv : 1));
    *idx = (uint32_t *)malloc(sizeof(uint32_t) * 3 * (nt ? nt : 1));
    m.xyz = *xyz;
    m.vertex_count = nv;
    m.indices = *idx;
    m.triangle_count = nt;
    return m;
}

/* Random triangle soup: n triangles of size ~0.3 in [-1, 1]^3. */
static hfvis_mesh random_soup(size_t n, uint64_t seed)
{
    float *xyz;
    uint32_t *idx;
    hfvis_mesh m = soup_alloc(3 * n, n, &xyz, &idx);
    size_t t;
    int k, a;
    rng_seed(seed);
    for (t = 0; t < n; t++) {
        double c[3];
        for (a = 0; a < 3; a++) c[a] = rng_range(-1.0, 1.0);
        for (k = 0; k < 3; k++) {
            for (a = 0; a < 3; a++) xyz[9 * t + 3 * (size_t)k + (size_t)a] = (float)(c[a] + rng_range(-0.3, 0.3));
            idx[3 * t + (size_t)k] = (uint32_t)(3 * t + (size_t)k);
        }
    }
    return m;
}

/* Degenerate-heavy soup: ordinary triangles mixed with zero-area ones (repeated index,
 * coincident vertices, exactly collinear vertices), exact duplicates (equal t: tie rule),
 * reversed duplicates, coplanar axis-aligned fans sharing vertices, huge (1e15) and tiny (1e-20)
 * triangles. */
static hfvis_mesh degenerate_soup(size_t n, uint64_t seed)
{
    float *xyz;
    uint32_t *idx;
    hfvis_mesh m = soup_alloc(3 * n, n, &xyz, &idx);
    size_t t, v = 0;
    int a, k;
    rng_seed(seed);
    for (t = 0; t < n; t++) {
        int kind = (int)(rng_u32() % 10);
        double c[3];
        float *p = xyz + 3 * v;
        for (a = 0; a < 3; a++) c[a] = rng_range(-1.0, 1.0);
        if (t > 0 && (kind == 0 || kind == 1)) {
            /* duplicate of an earlier triangle: same vertices (0) or reversed winding (1) */
            size_t s = rng_u32() % t;
            idx[3 * t] = idx[3 * s + (kind ? 2 : 0)];
            idx[3 * t + 1] = idx[3 * s + 1];
            idx[3 * t + 2] = idx[3 * s + (kind ? 0 : 2)];
            continue;
        }
        for (k = 0; k < 3; k++)
            for (a = 0; a < 3; a++) p[3 * k + a] = (float)(c[a] + rng_range(-0.4, 0.4));
        switch (kind) {
        case 2: /* repeated index */
            idx[3 * t] = (uint32_t)v;
            idx[3 * t + 1] = (uint32_t)v;
            idx[3 * t + 2] = (uint32_t)v + 2;
            v += 3;
            continue;
        case 3: /* coincident vertex coordinates */
            for (a = 0; a < 3; a++) p[6 + a] = p[a];
            break;
        case 4: /* exactly collinear: p0 + (0, 1, 2) * (1/8, 1/4, -1/2) on a dyadic grid */
            for (a = 0; a < 3; a++) p[a] = (float)(floor(c[a] * 64.0) / 64.0);
            for (k = 1; k < 3; k++) {
                p[3 * k] = p[0] + 0.125f * (float)k;
                p[3 * k + 1] = p[1] + 0.25f * (float)k;
                p[3 * k + 2] = p[2] - 0.5f * (float)k;
            }
            break;
        case 5: /* axis-aligned, on a shared plane z = 1/4 (coplanar neighbours, exact t ties) */
            for (k = 0; k < 3; k++) p[3 * k + 2] = 0.25f;
            break;
        case 6: /* huge */
            for (k = 0; k < 3; k++)
                for (a = 0; a < 3; a++) p[3 * k + a] = (float)(1e15 * rng_range(-1.0, 1.0));
            break;
        case 7: /* tiny */
            for (k = 0; k < 3; k++)
                for (a = 0; a < 3; a++) p[3 * k + a] = (float)(c[a] + 1e-20 * rng_range(-1.0, 1.0));
            break;
        default:
            break;
        }
        for (k = 0; k < 3; k++) idx[3 * t + (size_t)k] = (uint32_t)(v + (size_t)k);
        v += 3;
    }
    m.vertex_count = v ? v : 1;
    if (!v) xyz[0] = xyz[1] = xyz[2] = 0.0f;
    return m;
}

static void mesh_bounds_f(const hfvis_mesh *m, double lo[3], double hi[3])
{
    size_t i;
    int a;
    for (a = 0; a < 3; a++) {
        lo[a] = HUGE_VAL;
        hi[a] = -HUGE_VAL;
    }
    for (i = 0; i < 3 * m->triangle_count; i++) {
        const float *p = m->xyz + 3 * (size_t)m->indices[i];
        for (a = 0; a < 3; a++) {
            if ((double)p[a] < lo[a]) lo[a] = (double)p[a];
            if ((double)p[a] > hi[a]) hi[a] = (double)p[a];
        }
    }
}

/* Seeded ray of one of several kinds around a mesh whose "working" bounds are [lo, hi]. */
static hfvis_ray random_ray(const hfvis_mesh *m, const double lo[3], const double hi[3])
{
    double c[3], s = 0.0, o[3], d[3], q[3];
    int a, kind = (int)(rng_u32() % 9);
    hfvis_ray r;
    size_t t = m->triangle_count ? rng_u32() % m->triangle_count : 0;
    for (a = 0; a < 3; a++) {
        c[a] = 0.5 * (lo[a] + hi[a]);
        if (hi[a] - lo[a] > s) s = hi[a] - lo[a];
    }
    if (s == 0.0) s = 1.0;
    for (a = 0; a < 3; a++) o[a] = c[a] + rng_range(-0.75, 0.75) * s;
    rng_dir(d);
    if (m->triangle_count && kind >= 1 && kind <= 4) {
        /* aim at a vertex (1), a point on an edge (2: midpoint, 3: random), a triangle point (4) */
        const float *p0 = vert(m, t, 0), *p1 = vert(m, t, 1), *p2 = vert(m, t, 2);
        double l = kind == 2 ? 0.5 : rng_unit(), w = rng_unit() * (1.0 - l);
        for (a = 0; a < 3; a++) {
            if (kind == 1) q[a] = (double)p0[a];
            else if (kind == 4) q[a] = (1.0 - l - w) * D(p0[a]) + l * D(p1[a]) + w * D(p2[a]);
            else q[a] = (1.0 - l) * D(p0[a]) + l * D(p1[a]);
        }
        rng_dir(d);
        for (a = 0; a < 3; a++) o[a] = q[a] + d[a] * s * rng_range(0.5, 2.0);
        for (a = 0; a < 3; a++) d[a] = (double)(float)q[a] - (double)(float)o[a];
    } else if (kind == 5 || kind == 6) {
        /* axis-parallel (5) or one zero component (6); origins snapped to vertex coordinates so
         * rays run along box faces, edges and triangle planes */
        int ax = (int)(rng_u32() % 3);
        if (m->triangle_count) {
            const float *p = vert(m, t, (int)(rng_u32() % 3));
            for (a = 0; a < 3; a++)
                if (rng_u32() % 2) o[a] = (double)p[a];
        }
        if (kind == 5) {
            d[0] = d[1] = d[2] = 0.0;
            d[ax] = rng_u32() % 2 ? 1.0 : -1.0;
            if (rng_u32() % 4 == 0) d[ax] = rng_u32() % 2 ? 0.0 : -0.0; /* set below */
            if (d[ax] == 0.0) d[(ax + 1) % 3] = 1.0;
        } else {
            d[ax] = rng_u32() % 2 ? 0.0 : -0.0;
        }
    } else if (kind == 7 && m->triangle_count) {
        /* AO-style: from a surface point, short */
        const float *p0 = vert(m, t, 0), *p1 = vert(m, t, 1), *p2 = vert(m, t, 2);
        double l = rng_unit(), w = rng_unit() * (1.0 - l);
        for (a = 0; a < 3; a++) o[a] = (1.0 - l - w) * D(p0[a]) + l * D(p1[a]) + w * D(p2[a]);
    }
    r = make_ray(o[0], o[1], o[2], d[0], d[1], d[2]);
    if (r.direction[0] == 0.0f && r.direction[1] == 0.0f && r.direction[2] == 0.0f)
        r.direction[2] = 1.0f;
    /* non-unit directions */
    if (rng_u32() % 4 == 0) {
        float f = (float)pow(2.0, rng_range(-10.0, 10.0));
        for (a = 0; a < 3; a++) r.direction[a] *= f;
    }
    {
        double dl = dlen(r.direction);
        int lim = (int)(rng_u32() % 6);
        if (kind == 7) {
            r.t_min = rng_u32() % 2 ? 0.0f : (float)(1e-4 * s / dl);
            r.t_max = (float)(rng_range(0.05, 0.5) * s / dl);
        } else if (lim == 0) {
            r.t_min = (float)(rng_range(0.0, 1.0) * s / dl);
        } else if (lim == 1) {
            r.t_max = (float)(rng_range(0.0, 2.0) * s / dl);
        } else if (lim == 2) {
            r.t_min = (float)(rng_range(0.0, 1.0) * s / dl);
            r.t_max = r.t_min + (float)(rng_range(0.0, 1.0) * s / dl);
        }
    }
    a = (int)(rng_u32() % 10);
    r.cull = a < 2 ? HFVIS_CULL_BACK : a < 3 ? HFVIS_CULL_FRONT : HFVIS_CULL_NONE;
    return r;
}

/* Structure invariants: tree shape, every triangle exactly once, leaf sizes, child boxes in
 * parents, triangle boxes in leaves, depth and leaf counts. Returns the number of violations. */
static int check_structure(const hfvis_bvh *b, const hfvis_mesh *m, int max_leaf)
{
    size_t n = m->triangle_count, i, leaves = 0, visited_nodes = 0;
    unsigned char *seen = (unsigned char *)calloc(n + 1, 1), *vis;
    uint32_t *stk, *dep;
    int bad = 0, sp = 0, maxd = 0, a;
    if (n == 0) {
        free(seen);
        return b->node_count != 0 || b->depth != 0;
    }
    vis = (unsigned char *)calloc(b->node_count, 1);
    stk = (uint32_t *)malloc(sizeof(uint32_t) * (b->node_count + 1));
    dep = (uint32_t *)malloc(sizeof(uint32_t) * (b->node_count + 1));
    if (b->node_count < 1 || b->node_count > 2 * n - 1 || b->triangle_count != n) bad++;
    if (b->max_leaf_size != max_leaf || b->depth < 1 || b->depth > HFVIS_BVH_MAX_DEPTH) bad++;
    stk[0] = 0;
    dep[0] = 1;
    sp = 1;
    while (sp > 0 && !bad) {
        uint32_t ni = stk[--sp], d = dep[sp];
        const hfvis_bvh_node *nd = b->nodes + ni;
        if (vis[ni]) {
            bad++;
            break;
        }
        vis[ni] = 1;
        visited_nodes++;
        if ((int)d > maxd) maxd = (int)d;
        for (a = 0; a < 3; a++)
            if (!(nd->lo[a] <= nd->hi[a])) bad++;
        if (nd->count == 0) {
            uint32_t l = nd->left_or_first, k;
            if (l <= ni || (size_t)l + 1 >= b->node_count) {
                bad++;
                break;
            }
            for (k = l; k <= l + 1; k++) {
                const hfvis_bvh_node *c = b->nodes + k;
                for (a = 0; a < 3; a++)
                    if (c->lo[a] < nd->lo[a] || c->hi[a] > nd->hi[a]) bad++;
                stk[sp] = k;
                dep[sp++] = d + 1;
            }
        } else {
            uint32_t k;
            leaves++;
            if ((int)nd->count > max_leaf || (size_t)nd->left_or_first + nd->count > n) {
                bad++;
                break;
            }
            for (k = nd->left_or_first; k < nd->left_or_first + nd->count; k++) {
                uint32_t t = b->tri_order[k];
                int j;
                if (t >= n || seen[t]) {
                    bad++;
                    continue;
                }
                seen[t] = 1;
                for (j = 0; j < 3; j++) {
                    const float *p = vert(m, t, j);
                    for (a = 0; a < 3; a++)
                        if (!(p[a] > nd->lo[a] || (p[a] == 0.0f && nd->lo[a] == 0.0f))
                            || !(p[a] < nd->hi[a] || (p[a] == 0.0f && nd->hi[a] == 0.0f)))
                            bad++; /* strictly inside: the box is padded (but not around 0 extent 0) */
                }
            }
        }
    }
    for (i = 0; i < n; i++)
        if (!seen[i]) bad++;
    if (visited_nodes != b->node_count || leaves != b->leaf_count || maxd != b->depth) bad++;
    free(seen);
    free(vis);
    free(stk);
    free(dep);
    return bad;
}

/* Compare BVH and naive on `count` seeded rays; returns the number of mismatches. */
static int compare_rays(const hfvis_bvh *b, const hfvis_mesh *m, int count, uint64_t seed,
                        long *hits_out)
{
    double lo[3], hi[3];
    int i, bad = 0;
    long hits = 0;
    mesh_bounds_f(m, lo, hi);
    rng_seed(seed);
    for (i = 0; i < count; i++) {
        hfvis_ray r = random_ray(m, lo, hi);
        hfvis_hit hb, hn, ab, an, chk;
        hfvis_status s1 = hfvis_bvh_closest_hit(b, m, &r, &hb);
        hfvis_status s2 = hfvis_ray_closest_naive(m, &r, &hn);
        hfvis_status s3 = hfvis_bvh_any_hit(b, m, &r, &ab);
        hfvis_status s4 = hfvis_ray_any_naive(m, &r, &an);
        if (s1 != HFVIS_OK || s2 != HFVIS_OK || s3 != HFVIS_OK || s4 != HFVIS_OK) {
            bad++;
            continue;
        }
        if (!hit_equal(&hb, &hn)) {
            if (bad < 5)
                fprintf(stderr, "closest mismatch ray %d: bvh t=%.9g tri=%u  naive t=%.9g tri=%u\n", i,
                        (double)hb.t, hb.triangle, (double)hn.t, hn.triangle);
            bad++;
        }
        if ((ab.triangle == HFVIS_NO_TRIANGLE) != (an.triangle == HFVIS_NO_TRIANGLE)) {
            if (bad < 5) fprintf(stderr, "any-hit verdict mismatch ray %d\n", i);
            bad++;
        }
        if ((hn.triangle == HFVIS_NO_TRIANGLE) != (an.triangle == HFVIS_NO_TRIANGLE)) bad++;
        if (ab.triangle != HFVIS_NO_TRIANGLE) {
            /* the any-hit triangle is a genuine hit in range */
            if (hfvis_ray_triangle(&r, vert(m, ab.triangle, 0), vert(m, ab.triangle, 1),
                                   vert(m, ab.triangle, 2), &chk) != HFVIS_OK
                || chk.triangle != 0 || chk.t != ab.t || chk.u != ab.u || chk.v != ab.v
                || chk.front != ab.front)
                bad++;
        }
        if (hn.triangle != HFVIS_NO_TRIANGLE) {
            hits++;
            if (!(hn.t >= r.t_min && hn.t <= r.t_max)) bad++;
            if (r.cull == HFVIS_CULL_BACK && !hn.front) bad++;
            if (r.cull == HFVIS_CULL_FRONT && hn.front) bad++;
        } else if (!(hn.t == INFINITY && hn.u == 0.0f && hn.v == 0.0f && hn.front == 0)) {
            bad++;
        }
    }
    if (hits_out) *hits_out += hits;
    return bad;
}

static int gen_ok(hfvis_status s)
{
    return s == HFVIS_OK;
}

/* ---- tests --------------------------------------------------------------------------------- */

TEST(ray_triangle_analytic)
{
    const float a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 1, 0};
    const float l0[3] = {0, 0, 0}, l1[3] = {1, 0, 0}, l2[3] = {2, 0, 0};   /* collinear */
    const float d0[3] = {0, 0, 0}, d1[3] = {0, 0, 0}, d2[3] = {0, 1, 0};   /* coincident */
    hfvis_ray r = make_ray(0.25, 0.5, 2, 0, 0, -1);
    hfvis_hit h;
    /* interior from the front: t = 2, point (0.25, 0.5) = 0.25 v1 + 0.5 v2 */
    CHECK_EQ_STATUS(hfvis_ray_triangle(&r, a, b, c, &h), HFVIS_OK);
    CHECK(h.triangle == 0);
    CHECK_NEAR(h.t, 2.0, T_ANALYTIC, 0);
    CHECK_NEAR(h.u, 0.25, T_ANALYTIC, 0);
    CHECK_NEAR(h.v, 0.5, T_ANALYTIC, 0);
    CHECK(h.front == 1);
    /* non-unit direction: t scales */
    r.direction[2] = -4.0f;
    CHECK_EQ_STATUS(hfvis_ray_triangle(&r, a, b, c, &h), HFVIS_OK);
    CHECK_NEAR(h.t, 0.5, T_ANALYTIC, 0);
    /* from behind */
    r = make_ray(0.25, 0.5, -3, 0, 0, 1);
    CHECK_EQ_STATUS(hfvis_ray_triangle(&r, a, b, c, &h), HFVIS_OK);
    CHECK(h.triangle == 0 && h.front == 0);
    CHECK_NEAR(h.t, 3.0, T_ANALYTIC, 0);
    r.cull = HFVIS_CULL_BACK;
    CHECK_EQ_STATUS(hfvis_ray_triangle(&r, a, b, c, &h), HFVIS_OK);
    CHECK(h.triangle == HFVIS_NO_TRIANGLE && h.t == INFINITY);
    r.cull = HFVIS_CULL_FRONT;
    CHECK_EQ_STATUS(hfvis_ray_triangle(&r, a, b, c, &h), HFVIS_OK);
    CHECK(h.triangle == 0);
    r = make_ray(0.25, 0.5, 2, 0, 0, -1);
    r.cull = HFVIS_CULL_FRONT;
    CHECK_EQ_STATUS(hfvis_ray_triangle(&r, a, b, c, &h), HFVIS_OK);
    CHECK(h.triangle == HFVIS_NO_TRIANGLE);
    /* edges and vertices belong to the triangle (edge functions exactly 0: double path) */
    r = make_ray(0.5, 0.5, 1, 0, 0, -1);
    CHECK_EQ_STATUS(hfvis_ray_triangle(&r, a, b, c, &h), HFVIS_OK);
    CHECK(h.triangle == 0 && h.u == 0.5f && h.v == 0.5f);
    r = make_ray(0.5, 0, 1, 0, 0, -1);
    CHECK_EQ_STATUS(hfvis_ray_triangle(&r, a, b, c, &h), HFVIS_OK);
    CHECK(h.triangle == 0 && h.v == 0.0f);
    r = make_ray(0, 0, 1, 0, 0, -1);
    CHECK_EQ_STATUS(hfvis_ray_triangle(&r, a, b, c, &h), HFVIS_OK);
    CHECK(h.triangle == 0 && h.u == 0.0f && h.v == 0.0f);
    r = make_ray(1, 0, 1, 0, 0, -1);
    CHECK_EQ_STATUS(hfvis_ray_triangle(&r, a, b, c, &h), HFVIS_OK);
    CHECK(h.triangle == 0 && h.u == 1.0f && h.v == 0.0f);
    /* just outside the hypotenuse, and outside a vertex */
    r = make_ray(0.5, 0.5000001, 1, 0, 0, -1);
    CHECK_EQ_STATUS(hfvis_ray_triangle(&r, a, b, c, &h), HFVIS_OK);
    CHECK(h.triangle == HFVIS_NO_TRIANGLE);
    r = make_ray(-1e-7, 0, 1, 0, 0, -1);
    CHECK_EQ_STATUS(hfvis_ray_triangle(&r, a, b, c, &h), HFVIS_OK);
    CHECK(h.triangle == HFVIS_NO_TRIANGLE);
    /* edge-on (ray in the triangle's plane, through it): never a hit */
    r = make_ray(-1, 0.25, 0, 1, 0, 0);
    CHECK_EQ_STATUS(hfvis_ray_triangle(&r, a, b, c, &h), HFVIS_OK);
    CHECK(h.triangle == HFVIS_NO_TRIANGLE);
    /* zero-area triangles never hit, even when the ray passes through them */
    r = make_ray(0.5, 0, 1, 0, 0, -1);
    CHECK_EQ_STATUS(hfvis_ray_triangle(&r, l0, l1, l2, &h), HFVIS_OK);
    CHECK(h.triangle == HFVIS_NO_TRIANGLE);
    r = make_ray(0, 0.5, 1, 0, 0, -1);
    CHECK_EQ_STATUS(hfvis_ray_triangle(&r, d0, d1, d2, &h), HFVIS_OK);
    CHECK(h.triangle == HFVIS_NO_TRIANGLE);
    /* the t range is inclusive at both ends */
    r = make_ray(0.25, 0.25, 2, 0, 0, -1);
    r.t_max = 2.0f;
    CHECK_EQ_STATUS(hfvis_ray_triangle(&r, a, b, c, &h), HFVIS_OK);
    CHECK(h.triangle == 0 && h.t == 2.0f);
    r.t_min = 2.0f;
    CHECK_EQ_STATUS(hfvis_ray_triangle(&r, a, b, c, &h), HFVIS_OK);
    CHECK(h.triangle == 0);
    r.t_min = 0.0f;
    r.t_max = nextafterf(2.0f, 0.0f);
    CHECK_EQ_STATUS(hfvis_ray_triangle(&r, a, b, c, &h), HFVIS_OK);
    CHECK(h.triangle == HFVIS_NO_TRIANGLE);
    r.t_min = nextafterf(2.0f, 3.0f);
    r.t_max = INFINITY;
    CHECK_EQ_STATUS(hfvis_ray_triangle(&r, a, b, c, &h), HFVIS_OK);
    CHECK(h.triangle == HFVIS_NO_TRIANGLE);
    /* behind the origin */
    r = make_ray(0.25, 0.25, -1, 0, 0, -1);
    CHECK_EQ_STATUS(hfvis_ray_triangle(&r, a, b, c, &h), HFVIS_OK);
    CHECK(h.triangle == HFVIS_NO_TRIANGLE);
    /* huge (float products overflow: double path) and tiny (products underflow to 0) */
    {
        const float H0[3] = {-1e30f, -1e30f, 0}, H1[3] = {1e30f, -1e30f, 0}, H2[3] = {0, 1e30f, 0};
        const float S0[3] = {-1e-30f, -1e-30f, 0}, S1[3] = {1e-30f, -1e-30f, 0}, S2[3] = {0, 1e-30f, 0};
        r = make_ray(0, 0, 1, 0, 0, -1);
        CHECK_EQ_STATUS(hfvis_ray_triangle(&r, H0, H1, H2, &h), HFVIS_OK);
        CHECK(h.triangle == 0 && h.front == 1);
        CHECK_NEAR(h.t, 1.0, T_ANALYTIC, 0);
        CHECK_NEAR(h.u, 0.25, T_ANALYTIC, 0);
        CHECK_NEAR(h.v, 0.5, T_ANALYTIC, 0);
        CHECK_EQ_STATUS(hfvis_ray_triangle(&r, S0, S1, S2, &h), HFVIS_OK);
        CHECK(h.triangle == 0 && h.front == 1);
        CHECK_NEAR(h.t, 1.0, T_ANALYTIC, 0);
        CHECK_NEAR(h.u, 0.25, T_ANALYTIC, 0);
        r = make_ray(0, 2e-30, 1, 0, 0, -1);
        CHECK_EQ_STATUS(hfvis_ray_triangle(&r, S0, S1, S2, &h), HFVIS_OK);
        CHECK(h.triangle == HFVIS_NO_TRIANGLE);
    }
    /* axis-parallel ray with two zero components, the third negative; negative zeros */
    r = make_ray(0.25, 0.25, 1, -0.0, -0.0, -1);
    CHECK_EQ_STATUS(hfvis_ray_triangle(&r, a, b, c, &h), HFVIS_OK);
    CHECK(h.triangle == 0 && h.t == 1.0f);
}

/* front == (direction . n < 0) and the hit point equals the barycentric point. */
TEST(ray_triangle_front_and_point)
{
    int i, bad = 0, hits = 0, checked = 0;
    rng_seed(11);
    for (i = 0; i < 20000; i++) {
        float p[3][3];
        double d[3], o[3], e1[3], e2[3], n[3], dn, dl, nl;
        hfvis_ray r;
        hfvis_hit h;
        int k, a;
        for (k = 0; k < 3; k++)
            for (a = 0; a < 3; a++) p[k][a] = (float)rng_range(-1.0, 1.0);
        for (a = 0; a < 3; a++) o[a] = rng_range(-3.0, 3.0);
        {
            double l = rng_range(-0.2, 1.2), w = rng_range(-0.2, 1.2), q[3];
            for (a = 0; a < 3; a++) q[a] = (1 - l - w) * D(p[0][a]) + l * D(p[1][a]) + w * D(p[2][a]);
            for (a = 0; a < 3; a++) d[a] = q[a] - o[a];
        }
        r = make_ray(o[0], o[1], o[2], d[0], d[1], d[2]);
        if (hfvis_ray_triangle(&r, p[0], p[1], p[2], &h) != HFVIS_OK) bad++;
        if (h.triangle == HFVIS_NO_TRIANGLE) continue;
        hits++;
        for (a = 0; a < 3; a++) {
            e1[a] = D(p[1][a]) - D(p[0][a]);
            e2[a] = D(p[2][a]) - D(p[0][a]);
        }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        dn = n[0] * D(r.direction[0]) + n[1] * D(r.direction[1]) + n[2] * D(r.direction[2]);
        dl = dlen(r.direction);
        nl = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(h.u >= 0.0f && h.v >= 0.0f && h.u + h.v <= 1.0f + 1e-6f)) bad++;
        if (fabs(dn) > T_FRONT_COS * dl * nl) {
            checked++;
            if ((h.front == 1) != (dn < 0.0)) bad++;
            for (a = 0; a < 3; a++) {
                double x = D(r.origin[a]) + D(h.t) * D(r.direction[a]);
                double y = (1.0 - D(h.u) - D(h.v)) * D(p[0][a]) + D(h.u) * D(p[1][a]) + D(h.v) * D(p[2][a]);
                if (fabs(x - y) > 1e-4) bad++; /* 1e-4: float t, u, v of well-conditioned hits */
            }
        }
    }
    CHECK(bad == 0);
    CHECK(hits > 5000 && checked > 4000);
    printf("  random ray/triangle: %d hits, %d checked for front flag and point\n", hits, checked);
}

/* Watertightness: rays through vertices and edges of closed meshes always hit. */
TEST(watertight_vertices_edges)
{
    const double c0[3] = {0, 0, 0};
    hfvis_mesh ico, box;
    hfvis_bvh b;
    const double blo[3] = {-1, -1, -1}, bhi[3] = {1, 1, 1};
    size_t v, t;
    int k, miss = 0, rays = 0, mismatch = 0;
    CHECK(gen_ok(hfvis_mesh_icosphere(NULL, c0, 1.0, 3, &ico)));
    CHECK(gen_ok(hfvis_bvh_build(&ico, NULL, &b)));
    /* from the centre through every vertex, and from outside (origin 2^k v, direction -v: the
     * ray passes exactly through v since 2^k v is exact) */
    for (v = 0; v < ico.vertex_count; v++) {
        const float *p = ico.xyz + 3 * v;
        for (k = 0; k < 4; k++) {
            hfvis_ray r;
            hfvis_hit h, hn;
            double f = k == 0 ? 0.0 : (double)(1 << k);
            r = k == 0 ? make_ray(0, 0, 0, D(p[0]), D(p[1]), D(p[2]))
                       : make_ray(f * D(p[0]), f * D(p[1]), f * D(p[2]), -D(p[0]), -D(p[1]), -D(p[2]));
            hfvis_bvh_closest_hit(&b, &ico, &r, &h);
            hfvis_ray_closest_naive(&ico, &r, &hn);
            rays++;
            if (h.triangle == HFVIS_NO_TRIANGLE) miss++;
            if (!hit_equal(&h, &hn)) mismatch++;
        }
    }
    /* through edge points: midpoints and quarter points of every triangle edge, from the centre
     * (origin 0, direction = the point) and from outside (origin 2q, direction -q) */
    for (t = 0; t < ico.triangle_count; t++)
        for (k = 0; k < 3; k++) {
            const float *p = vert(&ico, t, k), *q = vert(&ico, t, (k + 1) % 3);
            int j, a, w;
            for (j = 1; j < 4; j++) {
                float m[3];
                for (a = 0; a < 3; a++) m[a] = (float)((4 - j) * 0.25 * D(p[a]) + j * 0.25 * D(q[a]));
                for (w = 0; w < 2; w++) {
                    hfvis_ray r = w == 0 ? make_ray(0, 0, 0, D(m[0]), D(m[1]), D(m[2]))
                                         : make_ray(2.0 * D(m[0]), 2.0 * D(m[1]), 2.0 * D(m[2]), -D(m[0]), -D(m[1]), -D(m[2]));
                    hfvis_hit h, hn;
                    hfvis_bvh_closest_hit(&b, &ico, &r, &h);
                    hfvis_ray_closest_naive(&ico, &r, &hn);
                    rays++;
                    if (h.triangle == HFVIS_NO_TRIANGLE) miss++;
                    if (!hit_equal(&h, &hn)) mismatch++;
                }
            }
        }
    CHECK(miss == 0);
    CHECK(mismatch == 0);
    printf("  icosphere s=3: %d rays through vertices and edges, %d misses\n", rays, miss);
    hfvis_bvh_free(NULL, &b);
    hfvis_mesh_free(NULL, &ico);

    /* box [-1,1]^3 from its centre through corners, edge midpoints, face centres (on the face
     * diagonals shared by two triangles) and random points of those lines; axis-parallel rays
     * run through zero direction components */
    CHECK(gen_ok(hfvis_mesh_box(NULL, blo, bhi, &box)));
    CHECK(gen_ok(hfvis_bvh_build(&box, NULL, &b)));
    miss = 0;
    rays = 0;
    {
        int x, y, z;
        for (x = -2; x <= 2; x++)
            for (y = -2; y <= 2; y++)
                for (z = -2; z <= 2; z++) {
                    hfvis_ray r;
                    hfvis_hit h, hn;
                    if (!x && !y && !z) continue;
                    r = make_ray(0, 0, 0, x, y, z);
                    hfvis_bvh_closest_hit(&b, &box, &r, &h);
                    hfvis_ray_closest_naive(&box, &r, &hn);
                    rays++;
                    if (h.triangle == HFVIS_NO_TRIANGLE) miss++;
                    if (!hit_equal(&h, &hn)) mismatch++;
                    /* from outside through the same boundary point (exact: 2 * point) */
                    {
                        double s = fabs((double)x);
                        if (fabs((double)y) > s) s = fabs((double)y);
                        if (fabs((double)z) > s) s = fabs((double)z);
                        r = make_ray(2 * x / s, 2 * y / s, 2 * z / s, -x, -y, -z);
                        hfvis_bvh_closest_hit(&b, &box, &r, &h);
                        hfvis_ray_closest_naive(&box, &r, &hn);
                        rays++;
                        if (h.triangle == HFVIS_NO_TRIANGLE) miss++;
                        if (!hit_equal(&h, &hn)) mismatch++;
                    }
                }
    }
    /* rays along the face diagonals' planes: origin on a diagonal plane, axis direction */
    rng_seed(5);
    for (k = 0; k < 4000; k++) {
        double s = rng_range(-1, 1);
        int ax = (int)(rng_u32() % 3), sg = rng_u32() % 2 ? 1 : -1;
        double o[3];
        hfvis_ray r;
        hfvis_hit h, hn;
        o[0] = s;
        o[1] = rng_u32() % 2 ? s : -s;
        o[2] = rng_u32() % 2 ? s : -s;
        o[ax] = 0.0;
        r = make_ray(o[0], o[1], o[2], ax == 0 ? sg : 0, ax == 1 ? sg : 0, ax == 2 ? sg : 0);
        hfvis_bvh_closest_hit(&b, &box, &r, &h);
        hfvis_ray_closest_naive(&box, &r, &hn);
        rays++;
        if (h.triangle == HFVIS_NO_TRIANGLE) miss++;
        if (!hit_equal(&h, &hn)) mismatch++;
    }
    CHECK(miss == 0);
    CHECK(mismatch == 0);
    printf("  box: %d rays through corners, edges and face diagonals, %d misses\n", rays, miss);
    hfvis_bvh_free(NULL, &b);
    hfvis_mesh_free(NULL, &box);
}

/* A ray from inside a closed mesh always hits it: random interior origins of the icosphere and
 * of the torus (origins on the tube's core circle). */
TEST(watertight_interior)
{
    const double c0[3] = {0.125, -0.25, 0.5};
    hfvis_mesh ico, tor;
    hfvis_bvh b1, b2;
    int i, miss = 0;
    CHECK(gen_ok(hfvis_mesh_icosphere(NULL, c0, 1.0, 2, &ico)));
    CHECK(gen_ok(hfvis_mesh_torus(NULL, c0, 1.0, 0.25, 24, 12, &tor)));
    CHECK(gen_ok(hfvis_bvh_build(&ico, NULL, &b1)));
    CHECK(gen_ok(hfvis_bvh_build(&tor, NULL, &b2)));
    rng_seed(77);
    for (i = 0; i < 20000; i++) {
        double d[3], o[3], ph = rng_range(0, 6.283185307179586);
        hfvis_ray r;
        hfvis_hit h;
        rng_dir(d);
        o[0] = c0[0] + rng_range(-0.5, 0.5);
        o[1] = c0[1] + rng_range(-0.5, 0.5);
        o[2] = c0[2] + rng_range(-0.5, 0.5);
        r = make_ray(o[0], o[1], o[2], d[0], d[1], d[2]);
        hfvis_bvh_closest_hit(&b1, &ico, &r, &h);
        if (h.triangle == HFVIS_NO_TRIANGLE || h.front) miss++; /* from inside: back faces */
        r = make_ray(c0[0] + cos(ph), c0[1] + sin(ph), c0[2], d[0], d[1], d[2]);
        hfvis_bvh_closest_hit(&b2, &tor, &r, &h);
        if (h.triangle == HFVIS_NO_TRIANGLE || h.front) miss++;
    }
    CHECK(miss == 0);
    hfvis_bvh_free(NULL, &b1);
    hfvis_bvh_free(NULL, &b2);
    hfvis_mesh_free(NULL, &ico);
    hfvis_mesh_free(NULL, &tor);
}

/* The main cross-check: BVH == naive exactly, over 6 meshes x leaf sizes 1..8. */
TEST(bvh_matches_naive)
{
    const double c0[3] = {0, 0, 0}, blo[3] = {-0.5, -1, 0.25}, bhi[3] = {1.5, 0.75, 1};
    hfvis_mesh meshes[6];
    const char *names[6] = {"box", "icosphere", "torus", "room", "soup", "degenerate"};
    int mi, leaf, total = 0, bad_total = 0;
    long hits = 0;
    CHECK(gen_ok(hfvis_mesh_box(NULL, blo, bhi, &meshes[0])));
    CHECK(gen_ok(hfvis_mesh_icosphere(NULL, c0, 1.0, 3, &meshes[1])));
    CHECK(gen_ok(hfvis_mesh_torus(NULL, c0, 1.0, 0.3, 32, 16, &meshes[2])));
    CHECK(gen_ok(hfvis_mesh_room(NULL, &meshes[3])));
    meshes[4] = random_soup(1000, 3);
    meshes[5] = degenerate_soup(1200, 4);
    for (mi = 0; mi < 6; mi++) {
        int bad_mesh = 0;
        for (leaf = 1; leaf <= HFVIS_BVH_MAX_LEAF_SIZE; leaf++) {
            hfvis_bvh_options o = hfvis_bvh_options_default();
            hfvis_bvh b;
            int bad;
            o.max_leaf_size = leaf;
            o.bins = leaf % 2 ? 16 : 7; /* default and an odd count */
            CHECK_EQ_STATUS(hfvis_bvh_build(&meshes[mi], &o, &b), HFVIS_OK);
            CHECK(check_structure(&b, &meshes[mi], leaf) == 0);
            bad = compare_rays(&b, &meshes[mi], RAYS_PER_CASE, (uint64_t)(1000 * mi + leaf), &hits);
            CHECK(bad == 0);
            bad_mesh += bad;
            total += RAYS_PER_CASE;
            hfvis_bvh_free(NULL, &b);
        }
        printf("  %-10s %6zu triangles: %d rays x 8 leaf sizes, mismatches %d\n", names[mi],
               meshes[mi].triangle_count, RAYS_PER_CASE, bad_mesh);
        bad_total += bad_mesh;
    }
    printf("  %d rays (closest + any-hit each), %ld closest hits, %d mismatches\n", total, hits,
           bad_total);
    CHECK(total >= 100000);
    for (mi = 0; mi < 6; mi++) hfvis_mesh_free(NULL, &meshes[mi]);
}

/* Huge and tiny scales, far from the origin: an icosphere scaled by 2^k (k = -100 .. 100) and
 * moved away by 2^10 radii or more (coarse float vertices, degenerate triangles). BVH == naive,
 * and rays from the centre always hit (where the scale leaves the sphere closed). */
TEST(scales)
{
    const double c0[3] = {0, 0, 0};
    const int ks[6] = {-100, -40, -10, 10, 40, 100};
    hfvis_mesh base;
    int i, j, bad = 0, miss = 0;
    CHECK(gen_ok(hfvis_mesh_icosphere(NULL, c0, 1.0, 2, &base)));
    for (i = 0; i < 6; i++)
        for (j = 0; j < 3; j++) {
            float *xyz;
            uint32_t *idx;
            hfvis_mesh m = soup_alloc(base.vertex_count, base.triangle_count, &xyz, &idx);
            double sc = ldexp(1.0, ks[i]), off = j == 0 ? 0.0 : sc * (j == 1 ? 1024.0 : 3.0e6);
            hfvis_bvh b;
            size_t v;
            int k;
            for (v = 0; v < 3 * base.vertex_count; v++) xyz[v] = (float)(D(base.xyz[v]) * sc + off);
            memcpy(idx, base.indices, sizeof(uint32_t) * 3 * base.triangle_count);
            CHECK_EQ_STATUS(hfvis_bvh_build(&m, NULL, &b), HFVIS_OK);
            CHECK(check_structure(&b, &m, 4) == 0);
            bad += compare_rays(&b, &m, 1500, (uint64_t)(500 + 10 * i + j), NULL);
            if (j < 2) /* still a closed sphere in float: rays from the centre hit */
                for (k = 0; k < 300; k++) {
                    double d[3];
                    hfvis_ray r;
                    hfvis_hit h;
                    rng_dir(d);
                    r = make_ray(off, off, off, d[0], d[1], d[2]);
                    hfvis_bvh_closest_hit(&b, &m, &r, &h);
                    if (h.triangle == HFVIS_NO_TRIANGLE) miss++;
                }
            hfvis_bvh_free(NULL, &b);
            hfvis_mesh_free(NULL, &m);
        }
    CHECK(bad == 0);
    CHECK(miss == 0);
    hfvis_mesh_free(NULL, &base);
}

/* Exactly equal t goes to the lowest triangle index, in BVH and naive alike. */
TEST(tie_lowest_index)
{
    float *xyz;
    uint32_t *idx;
    hfvis_mesh m = soup_alloc(4, 40, &xyz, &idx);
    hfvis_bvh b;
    hfvis_hit h, hn;
    hfvis_ray r;
    int t, k, bad = 0;
    /* 40 copies of one triangle (some reversed: same t, other barycentrics) in reverse order */
    const float v[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0};
    memcpy(xyz, v, sizeof v);
    for (t = 0; t < 40; t++) {
        idx[3 * t] = t % 3 == 0 ? 3u : 0u; /* vertex 3 duplicates vertex 0 */
        idx[3 * t + 1] = t % 2 ? 2u : 1u;
        idx[3 * t + 2] = t % 2 ? 1u : 2u;
    }
    for (k = 1; k <= 8; k++) {
        hfvis_bvh_options o = hfvis_bvh_options_default();
        o.max_leaf_size = k;
        CHECK_EQ_STATUS(hfvis_bvh_build(&m, &o, &b), HFVIS_OK);
        r = make_ray(0.25, 0.25, 1, 0, 0, -1);
        hfvis_bvh_closest_hit(&b, &m, &r, &h);
        hfvis_ray_closest_naive(&m, &r, &hn);
        if (h.triangle != 0 || !hit_equal(&h, &hn)) bad++;
        r.cull = HFVIS_CULL_BACK; /* odd triangles are reversed: back faces from above */
        hfvis_bvh_closest_hit(&b, &m, &r, &h);
        if (h.triangle != 0) bad++;
        r.cull = HFVIS_CULL_FRONT;
        hfvis_bvh_closest_hit(&b, &m, &r, &h);
        hfvis_ray_closest_naive(&m, &r, &hn);
        if (h.triangle != 1 || !hit_equal(&h, &hn)) bad++;
        hfvis_bvh_free(NULL, &b);
    }
    CHECK(bad == 0);
    hfvis_mesh_free(NULL, &m);
}

/* t_min / t_max honoured exactly around the closest hit. */
TEST(t_range)
{
    const double c0[3] = {0, 0, 0};
    hfvis_mesh m;
    hfvis_bvh b;
    double lo[3], hi[3];
    int i, bad = 0, n = 0;
    CHECK(gen_ok(hfvis_mesh_torus(NULL, c0, 1.0, 0.4, 24, 12, &m)));
    CHECK(gen_ok(hfvis_bvh_build(&m, NULL, &b)));
    mesh_bounds_f(&m, lo, hi);
    rng_seed(21);
    for (i = 0; i < 5000; i++) {
        hfvis_ray r = random_ray(&m, lo, hi), q;
        hfvis_hit h0, h, hn;
        r.t_min = 0.0f;
        r.t_max = INFINITY;
        r.cull = HFVIS_CULL_NONE;
        hfvis_bvh_closest_hit(&b, &m, &r, &h0);
        if (h0.triangle == HFVIS_NO_TRIANGLE) continue;
        n++;
        q = r; /* t_max just below the closest hit: nothing */
        q.t_max = nextafterf(h0.t, 0.0f);
        if (q.t_max < h0.t) {
            hfvis_bvh_closest_hit(&b, &m, &q, &h);
            if (h.triangle != HFVIS_NO_TRIANGLE) bad++;
            hfvis_bvh_any_hit(&b, &m, &q, &h);
            if (h.triangle != HFVIS_NO_TRIANGLE) bad++;
        }
        q = r; /* t_min = t_max = the hit: exactly that hit */
        q.t_min = q.t_max = h0.t;
        hfvis_bvh_closest_hit(&b, &m, &q, &h);
        if (!hit_equal(&h, &h0)) bad++;
        hfvis_bvh_any_hit(&b, &m, &q, &h);
        if (h.t != h0.t) bad++;
        q = r; /* t_min just above: a farther hit or none, as the naive one */
        q.t_min = nextafterf(h0.t, INFINITY);
        hfvis_bvh_closest_hit(&b, &m, &q, &h);
        hfvis_ray_closest_naive(&m, &q, &hn);
        if (!hit_equal(&h, &hn) || (h.triangle != HFVIS_NO_TRIANGLE && !(h.t > h0.t))) bad++;
    }
    CHECK(bad == 0);
    CHECK(n > 1000);
    hfvis_bvh_free(NULL, &b);
    hfvis_mesh_free(NULL, &m);
}

/* The candidate filter: BVH == naive with the same (pure) filter. */
static int filter_not_mod3(void *user, const hfvis_ray *ray, const hfvis_hit *c)
{
    int *calls = (int *)user;
    (void)ray;
    (*calls)++;
    return c->triangle % 3 != 0;
}
TEST(filter)
{
    const double c0[3] = {0, 0, 0};
    hfvis_mesh m;
    hfvis_bvh b;
    double lo[3], hi[3];
    int i, bad = 0, calls = 0, hits = 0;
    CHECK(gen_ok(hfvis_mesh_icosphere(NULL, c0, 1.0, 2, &m)));
    CHECK(gen_ok(hfvis_bvh_build(&m, NULL, &b)));
    mesh_bounds_f(&m, lo, hi);
    rng_seed(31);
    for (i = 0; i < 5000; i++) {
        hfvis_ray r = random_ray(&m, lo, hi);
        hfvis_hit h, hn, a, an;
        CHECK_EQ_STATUS(hfvis_bvh_intersect(&b, &m, &r, HFVIS_RAY_CLOSEST, filter_not_mod3, &calls, &h), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_ray_intersect_naive(&m, &r, HFVIS_RAY_CLOSEST, filter_not_mod3, &calls, &hn), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_bvh_intersect(&b, &m, &r, HFVIS_RAY_ANY, filter_not_mod3, &calls, &a), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_ray_intersect_naive(&m, &r, HFVIS_RAY_ANY, filter_not_mod3, &calls, &an), HFVIS_OK);
        if (!hit_equal(&h, &hn)) bad++;
        if ((a.triangle == HFVIS_NO_TRIANGLE) != (an.triangle == HFVIS_NO_TRIANGLE)) bad++;
        if (h.triangle != HFVIS_NO_TRIANGLE) {
            hits++;
            if (h.triangle % 3 == 0) bad++;
        }
        if (a.triangle != HFVIS_NO_TRIANGLE && a.triangle % 3 == 0) bad++;
    }
    CHECK(bad == 0);
    CHECK(hits > 500 && calls > hits);
    hfvis_bvh_free(NULL, &b);
    hfvis_mesh_free(NULL, &m);
}

/* Structure, determinism, leaf sizes, empty and single-triangle meshes, the depth bound. */
TEST(build_structure)
{
    const double c0[3] = {0, 0, 0};
    hfvis_mesh m;
    hfvis_bvh b1, b2;
    int leaf;
    CHECK(gen_ok(hfvis_mesh_torus_knot(NULL, c0, 1.0, 2, 3, 250, 12, &m))); /* 6000 triangles */
    for (leaf = 1; leaf <= 8; leaf++) {
        hfvis_bvh_options o = hfvis_bvh_options_default();
        o.max_leaf_size = leaf;
        CHECK_EQ_STATUS(hfvis_bvh_build(&m, &o, &b1), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_bvh_build(&m, &o, &b2), HFVIS_OK);
        CHECK(check_structure(&b1, &m, leaf) == 0);
        CHECK(b1.node_count == b2.node_count && b1.depth == b2.depth);
        CHECK(memcmp(b1.nodes, b2.nodes, b1.node_count * sizeof *b1.nodes) == 0);
        CHECK(memcmp(b1.tri_order, b2.tri_order, m.triangle_count * sizeof(uint32_t)) == 0);
        if (leaf == 1) CHECK(b1.leaf_count == m.triangle_count);
        if (leaf == 1 || leaf == 4 || leaf == 8)
            printf("  torus knot 6000 tris, leaf %d: %zu nodes, %zu leaves, depth %d\n", leaf,
                   b1.node_count, b1.leaf_count, b1.depth);
        hfvis_bvh_free(NULL, &b1);
        hfvis_bvh_free(NULL, &b2);
    }
    /* node layout: 32 bytes */
    CHECK(sizeof(hfvis_bvh_node) == 32);
    hfvis_mesh_free(NULL, &m);
    /* empty mesh: no nodes, every query misses */
    {
        hfvis_mesh e;
        hfvis_hit h;
        hfvis_ray r = make_ray(0, 0, 0, 1, 0, 0);
        memset(&e, 0, sizeof e);
        CHECK_EQ_STATUS(hfvis_bvh_build(&e, NULL, &b1), HFVIS_OK);
        CHECK(b1.node_count == 0 && b1.depth == 0 && b1.nodes == NULL);
        CHECK_EQ_STATUS(hfvis_bvh_closest_hit(&b1, &e, &r, &h), HFVIS_OK);
        CHECK(h.triangle == HFVIS_NO_TRIANGLE);
        CHECK_EQ_STATUS(hfvis_ray_any_naive(&e, &r, &h), HFVIS_OK);
        CHECK(h.triangle == HFVIS_NO_TRIANGLE);
        hfvis_bvh_free(NULL, &b1);
        hfvis_bvh_free(NULL, NULL);
    }
    /* one triangle: one leaf, depth 1 */
    {
        const float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
        const uint32_t ix[3] = {0, 1, 2};
        hfvis_mesh one;
        hfvis_hit h;
        hfvis_ray r = make_ray(0.2, 0.2, 1, 0, 0, -1);
        one.xyz = v;
        one.vertex_count = 3;
        one.indices = ix;
        one.triangle_count = 1;
        CHECK_EQ_STATUS(hfvis_bvh_build(&one, NULL, &b1), HFVIS_OK);
        CHECK(b1.node_count == 1 && b1.depth == 1 && b1.leaf_count == 1);
        CHECK(check_structure(&b1, &one, 4) == 0);
        CHECK_EQ_STATUS(hfvis_bvh_closest_hit(&b1, &one, &r, &h), HFVIS_OK);
        CHECK(h.triangle == 0);
        hfvis_bvh_free(NULL, &b1);
    }
}

/* SAH would peel one triangle per level off an exponentially spread set (with 2 bins, all
 * centroids but the largest fall into the first bin): the median fallback keeps the depth <= HFVIS_BVH_MAX_DEPTH, and
 * identical triangles (all centroids equal) are split at the median by index. */
TEST(depth_bound)
{
    float *xyz;
    uint32_t *idx;
    const int n = 400;
    hfvis_mesh m = soup_alloc(3 * (size_t)n, (size_t)n, &xyz, &idx);
    hfvis_bvh b;
    hfvis_bvh_options o = hfvis_bvh_options_default();
    double lo[3], hi[3];
    int t, k, bad;
    for (t = 0; t < n; t++) {
        float s = (float)ldexp(1.0, t / 2 - 100); /* 2^-100 .. 2^99, two per scale */
        float x = s * (float)(1 + t % 2);
        const float p[9] = {x, 0, 0, x + s, 0, 0, x, s, 0.5f};
        for (k = 0; k < 9; k++) xyz[9 * t + k] = p[k];
        for (k = 0; k < 3; k++) idx[3 * t + k] = (uint32_t)(3 * t + k);
    }
    o.bins = 2; /* each split: the largest centroid alone on one side */
    CHECK_EQ_STATUS(hfvis_bvh_build(&m, &o, &b), HFVIS_OK);
    CHECK(check_structure(&b, &m, 4) == 0);
    CHECK(b.depth > HFVIS_BVH_SAH_DEPTH && b.depth <= HFVIS_BVH_SAH_DEPTH + 10);
    printf("  exponential soup of %d triangles: depth %d (SAH limit %d)\n", n, b.depth, HFVIS_BVH_SAH_DEPTH);
    mesh_bounds_f(&m, lo, hi);
    bad = compare_rays(&b, &m, 3000, 99, NULL);
    CHECK(bad == 0);
    /* rays down onto each triangle: hit exactly that triangle */
    for (t = 0, bad = 0; t < n; t++) {
        const float *p = xyz + 9 * t;
        hfvis_ray r = make_ray(D(p[0]) + 0.25 * (D(p[3]) - D(p[0])), D(p[1]) + 0.25 * (D(p[7]) - D(p[1])), 1.0, 0, 0, -1);
        hfvis_hit h, hn;
        hfvis_bvh_closest_hit(&b, &m, &r, &h);
        hfvis_ray_closest_naive(&m, &r, &hn);
        if (h.triangle == HFVIS_NO_TRIANGLE || !hit_equal(&h, &hn)) bad++;
    }
    CHECK(bad == 0);
    hfvis_bvh_free(NULL, &b);
    /* all triangles identical: median splits by index, depth log2 */
    for (t = 0; t < n; t++)
        for (k = 0; k < 3; k++) idx[3 * t + k] = (uint32_t)k;
    CHECK_EQ_STATUS(hfvis_bvh_build(&m, NULL, &b), HFVIS_OK);
    CHECK(check_structure(&b, &m, 4) == 0);
    CHECK(b.depth <= 9);
    {
        hfvis_ray r = make_ray(1.25 * ldexp(1.0, -100), 0.25 * ldexp(1.0, -100), 1, 0, 0, -1);
        hfvis_hit h;
        hfvis_bvh_closest_hit(&b, &m, &r, &h);
        CHECK(h.triangle == 0);
    }
    hfvis_bvh_free(NULL, &b);
    hfvis_mesh_free(NULL, &m);
}

TEST(bad_arguments)
{
    const float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const uint32_t ix[3] = {0, 1, 2}, bad_ix[3] = {0, 1, 3};
    float nanv[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    hfvis_mesh m, mb;
    hfvis_bvh b, sentinel, b2;
    hfvis_bvh_options o;
    hfvis_hit h, hs;
    hfvis_ray r = make_ray(0.2, 0.2, 1, 0, 0, -1), q;
    int k;
    m.xyz = v;
    m.vertex_count = 3;
    m.indices = ix;
    m.triangle_count = 1;
    memset(&sentinel, 0x5A, sizeof sentinel);
    /* build */
    b = sentinel;
    CHECK_EQ_STATUS(hfvis_bvh_build(NULL, NULL, &b), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_bvh_build(&m, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    mb = m;
    mb.indices = bad_ix;
    CHECK_EQ_STATUS(hfvis_bvh_build(&mb, NULL, &b), HFVIS_ERR_INVALID_ARGUMENT);
    mb = m;
    nanv[4] = NAN;
    mb.xyz = nanv;
    CHECK_EQ_STATUS(hfvis_bvh_build(&mb, NULL, &b), HFVIS_ERR_INVALID_ARGUMENT);
    nanv[4] = INFINITY;
    CHECK_EQ_STATUS(hfvis_bvh_build(&mb, NULL, &b), HFVIS_ERR_INVALID_ARGUMENT);
    mb = m;
    mb.xyz = NULL;
    CHECK_EQ_STATUS(hfvis_bvh_build(&mb, NULL, &b), HFVIS_ERR_INVALID_ARGUMENT);
    o = hfvis_bvh_options_default();
    CHECK(o.max_leaf_size == 4 && o.bins == 16 && o.alloc == NULL);
    o.max_leaf_size = 9;
    CHECK_EQ_STATUS(hfvis_bvh_build(&m, &o, &b), HFVIS_ERR_INVALID_ARGUMENT);
    o.max_leaf_size = -1;
    CHECK_EQ_STATUS(hfvis_bvh_build(&m, &o, &b), HFVIS_ERR_INVALID_ARGUMENT);
    o = hfvis_bvh_options_default();
    o.bins = 1;
    CHECK_EQ_STATUS(hfvis_bvh_build(&m, &o, &b), HFVIS_ERR_INVALID_ARGUMENT);
    o.bins = HFVIS_BVH_MAX_BINS + 1;
    CHECK_EQ_STATUS(hfvis_bvh_build(&m, &o, &b), HFVIS_ERR_INVALID_ARGUMENT);
    o.bins = -3;
    CHECK_EQ_STATUS(hfvis_bvh_build(&m, &o, &b), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(memcmp(&b, &sentinel, sizeof b) == 0);
    mb = m;
    mb.triangle_count = (size_t)HFVIS_BVH_MAX_TRIANGLES + 1; /* checked before the arrays */
    CHECK_EQ_STATUS(hfvis_bvh_build(&mb, NULL, &b), HFVIS_ERR_LIMIT);
    CHECK(memcmp(&b, &sentinel, sizeof b) == 0);
    /* zero options struct = defaults */
    memset(&o, 0, sizeof o);
    CHECK_EQ_STATUS(hfvis_bvh_build(&m, &o, &b2), HFVIS_OK);
    CHECK(b2.max_leaf_size == 4);

    /* queries: invalid rays */
    hs.t = 123.0f;
    hs.triangle = 77;
    hs.u = hs.v = 0.5f;
    hs.front = 7;
    for (k = 0; k < 13; k++) {
        q = r;
        switch (k) {
        case 0: q.origin[1] = NAN; break;
        case 1: q.origin[0] = INFINITY; break;
        case 2: q.direction[2] = NAN; break;
        case 3: q.direction[0] = -INFINITY; break;
        case 4: q.direction[0] = q.direction[1] = q.direction[2] = 0.0f; break;
        case 5: q.t_min = -1e-30f; break;
        case 6: q.t_min = NAN; break;
        case 7: q.t_max = NAN; break;
        case 8: q.t_min = 2.0f; q.t_max = 1.0f; break;
        case 9: q.t_min = INFINITY; break;
        case 10: q.cull = (hfvis_cull_mode)3; break;
        case 11: q.cull = (hfvis_cull_mode)-1; break;
        default: q.direction[0] = q.direction[1] = 0.0f; q.direction[2] = -0.0f; break;
        }
        h = hs;
        CHECK_EQ_STATUS(hfvis_bvh_closest_hit(&b2, &m, &q, &h), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_bvh_any_hit(&b2, &m, &q, &h), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_ray_closest_naive(&m, &q, &h), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_ray_any_naive(&m, &q, &h), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_ray_triangle(&q, v, v + 3, v + 6, &h), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK(memcmp(&h, &hs, sizeof h) == 0);
    }
    h = hs;
    CHECK_EQ_STATUS(hfvis_bvh_closest_hit(NULL, &m, &r, &h), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_bvh_closest_hit(&b2, NULL, &r, &h), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_bvh_closest_hit(&b2, &m, NULL, &h), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_bvh_closest_hit(&b2, &m, &r, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_bvh_intersect(&b2, &m, &r, (hfvis_ray_query)2, NULL, NULL, &h), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_ray_intersect_naive(&m, &r, (hfvis_ray_query)-1, NULL, NULL, &h), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_ray_closest_naive(NULL, &r, &h), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_ray_closest_naive(&m, NULL, &h), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_ray_closest_naive(&m, &r, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_ray_triangle(NULL, v, v + 3, v + 6, &h), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_ray_triangle(&r, NULL, v + 3, v + 6, &h), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_ray_triangle(&r, v, v + 3, v + 6, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    nanv[4] = NAN;
    CHECK_EQ_STATUS(hfvis_ray_triangle(&r, nanv, nanv + 3, nanv + 6, &h), HFVIS_ERR_INVALID_ARGUMENT);
    /* mesh / bvh mismatch, out-of-range index at query time, corrupted bvh */
    mb = m;
    mb.indices = bad_ix;
    CHECK_EQ_STATUS(hfvis_bvh_closest_hit(&b2, &mb, &r, &h), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_ray_closest_naive(&mb, &r, &h), HFVIS_ERR_INVALID_ARGUMENT);
    mb = m;
    mb.triangle_count = 0;
    CHECK_EQ_STATUS(hfvis_bvh_closest_hit(&b2, &mb, &r, &h), HFVIS_ERR_INVALID_ARGUMENT);
    mb = m;
    mb.xyz = NULL;
    CHECK_EQ_STATUS(hfvis_ray_closest_naive(&mb, &r, &h), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_bvh_closest_hit(&b2, &mb, &r, &h), HFVIS_ERR_INVALID_ARGUMENT);
    b = b2;
    b.depth = HFVIS_BVH_MAX_DEPTH + 1;
    CHECK_EQ_STATUS(hfvis_bvh_closest_hit(&b, &m, &r, &h), HFVIS_ERR_INVALID_ARGUMENT);
    b = b2;
    b.nodes = NULL;
    CHECK_EQ_STATUS(hfvis_bvh_closest_hit(&b, &m, &r, &h), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(memcmp(&h, &hs, sizeof h) == 0);
    {
        /* a leaf whose range leaves tri_order */
        hfvis_bvh_node save = b2.nodes[0];
        b2.nodes[0].left_or_first = 1;
        CHECK_EQ_STATUS(hfvis_bvh_closest_hit(&b2, &m, &r, &h), HFVIS_ERR_INVALID_ARGUMENT);
        b2.nodes[0].count = 0; /* an inner node whose children lie outside the array */
        CHECK_EQ_STATUS(hfvis_bvh_closest_hit(&b2, &m, &r, &h), HFVIS_ERR_INVALID_ARGUMENT);
        b2.nodes[0] = save;
        CHECK(memcmp(&h, &hs, sizeof h) == 0);
        CHECK_EQ_STATUS(hfvis_bvh_closest_hit(&b2, &m, &r, &h), HFVIS_OK);
        CHECK(h.triangle == 0);
    }
    hfvis_bvh_free(NULL, &b2);
}

TEST(alloc_failure)
{
    const double c0[3] = {0, 0, 0};
    hfvis_mesh m;
    hfvis_bvh b, sentinel;
    hfvis_bvh_options o = hfvis_bvh_options_default();
    test_counting c;
    hfvis_allocator a = test_counting_allocator(&c, 0);
    int k, total;
    CHECK(gen_ok(hfvis_mesh_icosphere(NULL, c0, 1.0, 2, &m)));
    o.alloc = &a;
    CHECK_EQ_STATUS(hfvis_bvh_build(&m, &o, &b), HFVIS_OK);
    total = c.allocs;
    CHECK(total == 4);
    CHECK(c.live == 2);
    hfvis_bvh_free(&a, &b);
    CHECK(c.live == 0 && c.allocs == c.frees);
    memset(&sentinel, 0x5A, sizeof sentinel);
    for (k = 1; k <= total; k++) {
        a = test_counting_allocator(&c, 0);
        c.fail_at = k;
        b = sentinel;
        CHECK_EQ_STATUS(hfvis_bvh_build(&m, &o, &b), HFVIS_ERR_OUT_OF_MEMORY);
        CHECK(memcmp(&b, &sentinel, sizeof b) == 0);
        CHECK(c.live == 0 && c.allocs - 1 == c.frees);
    }
    /* queries allocate nothing */
    a = test_counting_allocator(&c, 0);
    CHECK_EQ_STATUS(hfvis_bvh_build(&m, &o, &b), HFVIS_OK);
    c.allocs = 0;
    {
        hfvis_ray r = make_ray(0, 0, 3, 0, 0, -1);
        hfvis_hit h;
        CHECK_EQ_STATUS(hfvis_bvh_closest_hit(&b, &m, &r, &h), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_bvh_any_hit(&b, &m, &r, &h), HFVIS_OK);
        CHECK(h.triangle != HFVIS_NO_TRIANGLE);
    }
    CHECK(c.allocs == 0);
    hfvis_bvh_free(&a, &b);
    CHECK(c.live == 0);
    hfvis_mesh_free(NULL, &m);
}

int main(int argc, char **argv)
{
    TEST_INIT(argc, argv);
    RUN(ray_triangle_analytic);
    RUN(ray_triangle_front_and_point);
    RUN(watertight_vertices_edges);
    RUN(watertight_interior);
    RUN(bvh_matches_naive);
    RUN(scales);
    RUN(tie_lowest_index);
    RUN(t_range);
    RUN(filter);
    RUN(build_structure);
    RUN(depth_bound);
    RUN(bad_arguments);
    RUN(alloc_failure);
    return TEST_DONE();
}
