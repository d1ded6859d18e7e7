/* test_lk.c - Laine-Karras bitmask ray-cast AO (ssao.c section 12): ray sets, frames, masks, the
 * plane table, the three methods (rasterization, BVH traversal, ray caster) and their exact
 * agreement, the analytic cases of culling, LOD windows, bad arguments, failing
 * allocators. */
#include "hfvis.h"
#include "test.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

/* Tolerances (each with its reason) */
#define TOL_UNIT 1e-14        /* |u| = 1, orthonormal frames: a few double roundings */
#define TOL_MOMENT_LLOYD 0.02 /* mean u_z, u_z^2 of a Lloyd disc set, N >= 128: the rim cells'
                                 centroids lie inward (measured 0.004..0.016 over seeds) */
#define TOL_MOMENT_TORUS 0.01 /* the torus-relaxed set has no rim (measured <= 0.008) */
#define TOL_CLOSED_1024 0.02  /* continuous-limit closed forms vs W_N at N = 1024: the finite
                                 set's discrepancy (Lloyd disc: rim effect, up to ~0.016) */
#define TOL_LINEAR_FALLOFF 0.03 /* linear falloff: stratified lengths paired at random with
                                   the directions add O(1/sqrt(N)) ~ 0.03 of noise */
#define TOL_ON_PLANE 1e-12    /* G-buffer receivers lie on their triangle's plane (double) */
#define RATE_WATERTIGHT 2e-3  /* rays where the float watertight test and the double predicate
                                 may disagree: within rounding of an edge or the segment end */
#define RATE_LUT_128 0.02     /* LUT vs exact plane masks at T = 128: rays within ~1 node */

/* ---------------------------------------------------------------------------------------- */
/* helpers                                                                                   */
/* ---------------------------------------------------------------------------------------- */

static uint64_t rng = 0x9E3779B97F4A7C15ull;
static void rng_seed(uint64_t s) { rng = s * 2654435761ull + 0x632BE59BD9B4E019ull; }
static double urand(void)
{
    rng ^= rng >> 12;
    rng ^= rng << 25;
    rng ^= rng >> 27;
    return (double)((rng * 0x2545F4914F6CDD1Dull) >> 11) * (1.0 / 9007199254740992.0);
}
static double srand1(void) { return 2.0 * urand() - 1.0; }

/* A growable triangle soup. */
typedef struct tmesh {
    float *xyz;
    uint32_t *idx;
    size_t nv, nt, capv, capt;
} tmesh;

static void tm_vertex(tmesh *m, const double p[3])
{
    if (m->nv == m->capv) {
        m->capv = m->capv ? 2 * m->capv : 64;
        m->xyz = (float *)realloc(m->xyz, sizeof(float) * 3 * m->capv);
    }
    m->xyz[3 * m->nv] = (float)p[0];
    m->xyz[3 * m->nv + 1] = (float)p[1];
    m->xyz[3 * m->nv + 2] = (float)p[2];
    m->nv++;
}
static void tm_tri_idx(tmesh *m, size_t a, size_t b, size_t c)
{
    if (m->nt == m->capt) {
        m->capt = m->capt ? 2 * m->capt : 64;
        m->idx = (uint32_t *)realloc(m->idx, sizeof(uint32_t) * 3 * m->capt);
    }
    m->idx[3 * m->nt] = (uint32_t)a;
    m->idx[3 * m->nt + 1] = (uint32_t)b;
    m->idx[3 * m->nt + 2] = (uint32_t)c;
    m->nt++;
}
static void tm_tri(tmesh *m, const double a[3], const double b[3], const double c[3])
{
    size_t base = m->nv;
    tm_vertex(m, a);
    tm_vertex(m, b);
    tm_vertex(m, c);
    tm_tri_idx(m, base, base + 1, base + 2);
}
/* Quad p0 p1 p2 p3 (a convex loop) as (p0,p1,p2), (p0,p2,p3), wound so that its normal points
 * along `toward`. */
static void tm_quad(tmesh *m, const double p0[3], const double p1[3], const double p2[3],
                    const double p3[3], const double toward[3])
{
    double u[3], w[3], n[3];
    size_t base = m->nv;
    int a;
    for (a = 0; a < 3; a++) {
        u[a] = p1[a] - p0[a];
        w[a] = p2[a] - p0[a];
    }
    n[0] = u[1] * w[2] - u[2] * w[1];
    n[1] = u[2] * w[0] - u[0] * w[2];
    n[2] = u[0] * w[1] - u[1] * w[0];
    tm_vertex(m, p0);
    tm_vertex(m, p1);
    tm_vertex(m, p2);
    tm_vertex(m, p3);
    if (n[0] * toward[0] + n[1] * toward[1] + n[2] * toward[2] >= 0.0) {
        tm_tri_idx(m, base, base + 1, base + 2);
        tm_tri_idx(m, base, base + 2, base + 3);
    } else {
        tm_tri_idx(m, base, base + 2, base + 1);
        tm_tri_idx(m, base, base + 3, base + 2);
    }
}
/* Axis-aligned rectangle in the plane axis = value, extents lo..hi on the other two axes,
 * facing sign*axis. */
static void tm_rect(tmesh *m, int axis, double value, const double lo[2], const double hi[2],
                    double sign)
{
    double p[4][3], t[3] = {0.0, 0.0, 0.0};
    int u = (axis + 1) % 3, v = (axis + 2) % 3, k;
    for (k = 0; k < 4; k++) p[k][axis] = value;
    p[0][u] = lo[0]; p[0][v] = lo[1];
    p[1][u] = hi[0]; p[1][v] = lo[1];
    p[2][u] = hi[0]; p[2][v] = hi[1];
    p[3][u] = lo[0]; p[3][v] = hi[1];
    t[axis] = sign;
    tm_quad(m, p[0], p[1], p[2], p[3], t);
}
static void tm_add(tmesh *m, const hfvis_mesh *src, int flip)
{
    size_t base = m->nv, i;
    for (i = 0; i < src->vertex_count; i++) {
        double p[3];
        p[0] = (double)src->xyz[3 * i];
        p[1] = (double)src->xyz[3 * i + 1];
        p[2] = (double)src->xyz[3 * i + 2];
        tm_vertex(m, p);
    }
    for (i = 0; i < src->triangle_count; i++) {
        const uint32_t *t = src->indices + 3 * i;
        if (flip) tm_tri_idx(m, base + t[0], base + t[2], base + t[1]);
        else tm_tri_idx(m, base + t[0], base + t[1], base + t[2]);
    }
}
static hfvis_mesh tm_view(const tmesh *m)
{
    hfvis_mesh h;
    h.xyz = m->xyz;
    h.vertex_count = m->nv;
    h.indices = m->idx;
    h.triangle_count = m->nt;
    return h;
}
static void tm_free(tmesh *m)
{
    free(m->xyz);
    free(m->idx);
    memset(m, 0, sizeof *m);
}

static int count_at_least(const hfvis_lk_rays *r, int dim, double sign, double c);

static hfvis_lk_rays make_rays_pattern(int n, double r, hfvis_lk_falloff f, uint64_t seed,
                                       hfvis_lk_pattern pattern)
{
    hfvis_lk_rays rays;
    hfvis_lk_ray_options o = hfvis_lk_ray_options_default();
    o.falloff = f;
    o.seed = seed;
    o.pattern = pattern;
    memset(&rays, 0, sizeof rays);
    if (hfvis_lk_rays_build(n, r, &o, &rays) != HFVIS_OK) fprintf(stderr, "make_rays failed\n");
    return rays;
}

static hfvis_lk_rays make_rays(int n, double r, hfvis_lk_falloff f, uint64_t seed)
{
    return make_rays_pattern(n, r, f, seed, HFVIS_LK_PATTERN_DEFAULT);
}

static int count_bits(const uint32_t *m, int words)
{
    int w, b = 0;
    for (w = 0; w < words; w++) {
        uint32_t x = m[w];
        while (x) {
            b += (int)(x & 1u);
            x >>= 1;
        }
    }
    return b;
}

/* Mask of one receiver at the origin with normal +z (no jitter) by Method 2 and the ray
 * caster; both must agree exactly; returns the bit count (or -1 on error). */
static int origin_count(const hfvis_mesh *m, const hfvis_lk_rays *rays, const hfvis_lk_options *opts_in,
                        int *agree)
{
    hfvis_bvh b;
    hfvis_lk_receivers rc;
    hfvis_lk_options o = opts_in ? *opts_in : hfvis_lk_options_default();
    double p[3] = {0.0, 0.0, 0.0}, n[3] = {0.0, 0.0, 1.0};
    uint32_t m2[128], m3[128];
    int bits = -1;
    o.jitter = HFVIS_LK_JITTER_NONE;
    rc.count = 1;
    rc.position = p;
    rc.normal = n;
    rc.key = NULL;
    *agree = 0;
    if (hfvis_bvh_build(m, NULL, &b) != HFVIS_OK) return -1;
    if (hfvis_lk_bvh(m, &b, rays, &rc, &o, m2, NULL, NULL) == HFVIS_OK &&
        hfvis_lk_reference(m, &b, rays, &rc, &o, m3, NULL, NULL) == HFVIS_OK) {
        *agree = memcmp(m2, m3, sizeof(uint32_t) * (size_t)rays->words) == 0;
        bits = count_bits(m2, rays->words);
    }
    hfvis_bvh_free(NULL, &b);
    return bits;
}

/* Run the three methods on a view: Method 1 per pixel; Method 2 and the ray caster on the
 * G-buffer receivers. Returns the number of receivers whose masks differ between any two
 * (0 = identical), -1 on a failure; *nrec gets the receiver count, *blocked the set bits of
 * Method 1, st1/st2 the stats (may be NULL). */
static long three_way(const hfvis_mesh *m, const hfvis_view *v, const hfvis_lk_rays *rays,
                      const hfvis_lk_options *opts, size_t *nrec, uint64_t *blocked,
                      hfvis_lk_stats *st1, hfvis_lk_stats *st2)
{
    size_t npix = (size_t)v->width * (size_t)v->height, n = 0, k;
    size_t words = (size_t)rays->words;
    double *pos = (double *)malloc(sizeof(double) * 3 * npix), *nrm = (double *)malloc(sizeof(double) * 3 * npix);
    uint64_t *key = (uint64_t *)malloc(sizeof(uint64_t) * npix);
    uint32_t *m1 = (uint32_t *)malloc(sizeof(uint32_t) * npix * words);
    uint32_t *m2 = (uint32_t *)malloc(sizeof(uint32_t) * npix * words);
    uint32_t *m3 = (uint32_t *)malloc(sizeof(uint32_t) * npix * words);
    hfvis_bvh b;
    hfvis_lk_receivers rc;
    long bad = -1;
    memset(&b, 0, sizeof b);
    if (!pos || !nrm || !key || !m1 || !m2 || !m3) goto done;
    if (hfvis_lk_gbuffer_receivers(m, v, opts, pos, nrm, key, &n) != HFVIS_OK) goto done;
    if (hfvis_bvh_build(m, NULL, &b) != HFVIS_OK) goto done;
    rc.count = n;
    rc.position = pos;
    rc.normal = nrm;
    rc.key = key;
    if (hfvis_lk_raster(m, v, rays, opts, m1, NULL, st1) != HFVIS_OK) goto done;
    if (hfvis_lk_bvh(m, &b, rays, &rc, opts, m2, NULL, st2) != HFVIS_OK) goto done;
    if (hfvis_lk_reference(m, &b, rays, &rc, opts, m3, NULL, NULL) != HFVIS_OK) goto done;
    bad = 0;
    if (blocked) *blocked = 0;
    for (k = 0; k < n; k++) {
        const uint32_t *a = m1 + key[k] * words, *bb = m2 + k * words, *c = m3 + k * words;
        if (memcmp(a, bb, sizeof(uint32_t) * words) || memcmp(bb, c, sizeof(uint32_t) * words)) bad++;
        if (blocked) *blocked += (uint64_t)count_bits(a, (int)words);
    }
    if (nrec) *nrec = n;
done:
    hfvis_bvh_free(NULL, &b);
    free(pos); free(nrm); free(key); free(m1); free(m2); free(m3);
    return bad;
}

static hfvis_view ortho_down(double half, int W, int H, double cx, double cy)
{
    hfvis_view v;
    double eye[3], tgt[3], up[3] = {0.0, 1.0, 0.0};
    eye[0] = cx; eye[1] = cy; eye[2] = 5.0;
    tgt[0] = cx; tgt[1] = cy; tgt[2] = 0.0;
    hfvis_view_orthographic(&v, eye, tgt, up, half, W, H, 0.5, 20.0);
    return v;
}

static hfvis_view persp(const double eye[3], const double tgt[3], double fov_deg, int W, int H)
{
    hfvis_view v;
    double up[3] = {0.0, 0.0, 1.0};
    hfvis_view_perspective(&v, eye, tgt, up, fov_deg * PI / 180.0, W, H, 0.05, 50.0);
    return v;
}

/* ---------------------------------------------------------------------------------------- */
/* ray sets ([LK] §3; docs/errata.md E44)                                                    */
/* ---------------------------------------------------------------------------------------- */

TEST(rays_lloyd_set)
{
    static const int ns[] = {32, 128, 1024};
    int q;
    for (q = 0; q < 3; q++) {
        int n = ns[q], i, w, bad_unit = 0, bad_cone = 0;
        hfvis_lk_rays a = make_rays_pattern(n, 0.5, HFVIS_LK_FALLOFF_CONSTANT, 7, HFVIS_LK_PATTERN_LLOYD), b, c;
        double mz = 0.0, mz2 = 0.0, mx2 = 0.0, my2 = 0.0;
        CHECK(a.count == n && a.words == (n + 31) / 32 && a.radius == 0.5 && a.equal_lengths == 1);
        for (i = 0; i < n; i++) {
            const double *u = a.direction + 3 * i;
            double len = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
            if (fabs(len - 1.0) > TOL_UNIT || !(u[2] > 0.0) || a.length[i] != 1.0 ||
                a.point[3 * i] != u[0] || a.point[3 * i + 2] != u[2])
                bad_unit++;
            if (u[2] < sin(a.min_elevation)) bad_unit++;
            mz += u[2];
            mz2 += u[2] * u[2];
            mx2 += u[0] * u[0];
            my2 += u[1] * u[1];
        }
        CHECK(bad_unit == 0);
        for (w = 0; w < a.words; w++) { /* every direction of a word inside its cone */
            const double *cn = a.word_cone + 7 * w;
            for (i = 32 * w; i < n && i < 32 * w + 32; i++) {
                const double *u = a.direction + 3 * i;
                if (u[0] * cn[0] + u[1] * cn[1] + u[2] * cn[2] < cn[3]) bad_cone++;
            }
        }
        CHECK(bad_cone == 0);
        mz /= n; mz2 /= n; mx2 /= n; my2 /= n;
        printf("  N=%4d: mean u_z %.5f (2/3), mean u_z^2 %.5f (1/2), mean x^2 %.5f y^2 %.5f (1/4), "
               "min elevation %.4f rad\n", n, mz, mz2, mx2, my2, a.min_elevation);
        if (n >= 128) {
            CHECK_NEAR(mz, 2.0 / 3.0, TOL_MOMENT_LLOYD, 0.0);
            CHECK_NEAR(mz2, 0.5, TOL_MOMENT_LLOYD, 0.0);
            CHECK_NEAR(mx2, 0.25, TOL_MOMENT_LLOYD, 0.0);
            CHECK_NEAR(my2, 0.25, TOL_MOMENT_LLOYD, 0.0);
        } else { /* about 2/sqrt(N) */
            CHECK_NEAR(mz, 2.0 / 3.0, 2.0 / sqrt((double)n), 0.0);
            CHECK_NEAR(mz2, 0.5, 2.0 / sqrt((double)n), 0.0);
        }
        /* deterministic; another seed gives another set */
        b = make_rays_pattern(n, 0.5, HFVIS_LK_FALLOFF_CONSTANT, 7, HFVIS_LK_PATTERN_LLOYD);
        c = make_rays_pattern(n, 0.5, HFVIS_LK_FALLOFF_CONSTANT, 8, HFVIS_LK_PATTERN_LLOYD);
        CHECK(memcmp(a.direction, b.direction, sizeof(double) * 3 * (size_t)n) == 0);
        CHECK(memcmp(a.word_cone, b.word_cone, sizeof(double) * 7 * (size_t)a.words) == 0);
        CHECK(memcmp(a.direction, c.direction, sizeof(double) * 3 * (size_t)n) != 0);
        hfvis_lk_rays_free(NULL, &a);
        hfvis_lk_rays_free(NULL, &b);
        hfvis_lk_rays_free(NULL, &c);
        CHECK(a.direction == NULL && a.count == 0);
    }
    { /* odd counts: 1 ray, a partial last word; every method runs */
        static const int odd[3] = {1, 33, 95};
        int q2, agree;
        for (q2 = 0; q2 < 3; q2++) {
            hfvis_lk_ray_options o = hfvis_lk_ray_options_default();
            hfvis_lk_rays r;
            tmesh tm = {0};
            hfvis_mesh m;
            o.pattern = q2 == 1 ? HFVIS_LK_PATTERN_LLOYD_TORUS : HFVIS_LK_PATTERN_LLOYD;
            CHECK_EQ_STATUS(hfvis_lk_rays_build(odd[q2], 1.0, &o, &r), HFVIS_OK);
            CHECK(r.words == (odd[q2] + 31) / 32 && r.min_elevation > 0.0);
            tm_rect(&tm, 2, 0.5, (const double[2]){-3, -3}, (const double[2]){3, 3}, -1.0);
            m = tm_view(&tm);
            CHECK(origin_count(&m, &r, NULL, &agree) == count_at_least(&r, 2, 1.0, 0.5) && agree);
            tm_free(&tm);
            hfvis_lk_rays_free(NULL, &r);
        }
    }
    { /* LLOYD_TORUS: no rim bias */
        hfvis_lk_ray_options o = hfvis_lk_ray_options_default();
        hfvis_lk_rays r;
        double mz = 0.0, mz2 = 0.0;
        int i;
        o.pattern = HFVIS_LK_PATTERN_LLOYD_TORUS;
        CHECK_EQ_STATUS(hfvis_lk_rays_build(512, 1.0, &o, &r), HFVIS_OK);
        for (i = 0; i < 512; i++) {
            mz += r.direction[3 * i + 2];
            mz2 += r.direction[3 * i + 2] * r.direction[3 * i + 2];
        }
        printf("  torus N=512: mean u_z %.5f, mean u_z^2 %.5f\n", mz / 512.0, mz2 / 512.0);
        CHECK_NEAR(mz / 512.0, 2.0 / 3.0, TOL_MOMENT_TORUS, 0.0);
        CHECK_NEAR(mz2 / 512.0, 0.5, TOL_MOMENT_TORUS, 0.0);
        CHECK(r.min_elevation > 0.0);
        hfvis_lk_rays_free(NULL, &r);
    }
    { /* RANDOM pattern: plain i.i.d. points, looser moments */
        hfvis_lk_ray_options o = hfvis_lk_ray_options_default();
        hfvis_lk_rays r;
        double mz = 0.0;
        int i;
        o.pattern = HFVIS_LK_PATTERN_RANDOM;
        CHECK_EQ_STATUS(hfvis_lk_rays_build(1024, 1.0, &o, &r), HFVIS_OK);
        for (i = 0; i < 1024; i++) mz += r.direction[3 * i + 2];
        CHECK_NEAR(mz / 1024.0, 2.0 / 3.0, 4.0 / sqrt(1024.0), 0.0);
        hfvis_lk_rays_free(NULL, &r);
    }
}

static double falloff_linear(void *user, double x) { (void)user; return 1.0 - x; }
static double falloff_bump(void *user, double x) { (void)user; return x < 0.5 ? 0.5 + x : 1.0 - x; }
static double falloff_big(void *user, double x) { (void)user; return 2.0 - x; }
static double falloff_step(void *user, double x) { (void)user; return x < 0.25 ? 1.0 : 0.3; }

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

TEST(rays_falloff_lengths)
{
    enum { N = 256 };
    hfvis_lk_rays lin = make_rays(N, 2.0, HFVIS_LK_FALLOFF_LINEAR, 3);
    hfvis_lk_rays quad = make_rays(N, 2.0, HFVIS_LK_FALLOFF_QUADRATIC, 3);
    hfvis_lk_rays con = make_rays(N, 2.0, HFVIS_LK_FALLOFF_CONSTANT, 3);
    hfvis_lk_ray_options o = hfvis_lk_ray_options_default();
    hfvis_lk_rays cus, tmp;
    double s[N];
    int i, bad = 0;
    /* same directions for every falloff (same seed), only the lengths differ */
    CHECK(memcmp(lin.direction, con.direction, sizeof(double) * 3 * N) == 0);
    CHECK(lin.equal_lengths == 0 && con.equal_lengths == 1);
    /* linear: the lengths are exactly the strata 1 - (j + 1/2)/N, each once */
    memcpy(s, lin.length, sizeof s);
    qsort(s, N, sizeof(double), cmp_double);
    for (i = 0; i < N; i++) bad += s[i] != 1.0 - ((double)(N - 1 - i) + 0.5) / N;
    CHECK(bad == 0);
    /* quadratic: 1 - sqrt(xi) with the same permutation as linear */
    for (i = 0, bad = 0; i < N; i++) bad += quad.length[i] != 1.0 - sqrt(1.0 - lin.length[i]);
    CHECK(bad == 0);
    for (i = 0, bad = 0; i < 3 * N; i++) bad += lin.point[i] != lin.length[i / 3] * lin.direction[i];
    CHECK(bad == 0);
    /* custom (bisection) reproduces the linear inverse to 1e-15 */
    o.seed = 3;
    o.falloff = HFVIS_LK_FALLOFF_CUSTOM;
    o.falloff_fn = falloff_linear;
    CHECK_EQ_STATUS(hfvis_lk_rays_build(N, 2.0, &o, &cus), HFVIS_OK);
    for (i = 0, bad = 0; i < N; i++) bad += fabs(cus.length[i] - lin.length[i]) > 1e-15;
    CHECK(bad == 0);
    hfvis_lk_rays_free(NULL, &cus);
    /* a step falloff: lengths 1 (xi <= 0.3) or 0.25 (xi in (0.3, 1]) */
    o.falloff_fn = falloff_step;
    CHECK_EQ_STATUS(hfvis_lk_rays_build(N, 2.0, &o, &cus), HFVIS_OK);
    for (i = 0, bad = 0; i < N; i++) {
        double xi = 1.0 - lin.length[i];
        double want = xi <= 0.3 ? 1.0 : 0.25;
        bad += fabs(cus.length[i] - want) > 1e-15;
    }
    CHECK(bad == 0);
    hfvis_lk_rays_free(NULL, &cus);
    /* rejected falloffs: increasing somewhere, above 1, no function */
    o.falloff_fn = falloff_bump;
    memset(&tmp, 0x5A, sizeof tmp);
    CHECK_EQ_STATUS(hfvis_lk_rays_build(N, 2.0, &o, &tmp), HFVIS_ERR_INVALID_ARGUMENT);
    o.falloff_fn = falloff_big;
    CHECK_EQ_STATUS(hfvis_lk_rays_build(N, 2.0, &o, &tmp), HFVIS_ERR_INVALID_ARGUMENT);
    o.falloff_fn = NULL;
    CHECK_EQ_STATUS(hfvis_lk_rays_build(N, 2.0, &o, &tmp), HFVIS_ERR_INVALID_ARGUMENT);
    {
        unsigned char *raw = (unsigned char *)&tmp;
        size_t k;
        for (k = 0, bad = 0; k < sizeof tmp; k++) bad += raw[k] != 0x5A;
        CHECK(bad == 0); /* untouched */
    }
    hfvis_lk_rays_free(NULL, &lin);
    hfvis_lk_rays_free(NULL, &quad);
    hfvis_lk_rays_free(NULL, &con);
}

TEST(rays_custom_and_bad_args)
{
    double dirs[6] = {0.0, 0.0, 2.0, 1.0, 0.0, 1.0}, len[2] = {1.0, 0.5};
    hfvis_lk_rays r, tmp;
    hfvis_lk_ray_options o = hfvis_lk_ray_options_default();
    CHECK_EQ_STATUS(hfvis_lk_rays_custom(2, 3.0, dirs, len, NULL, &r), HFVIS_OK);
    CHECK(r.count == 2 && r.words == 1 && r.direction[2] == 1.0);
    CHECK_NEAR(r.direction[3], sqrt(0.5), TOL_UNIT, 0.0);
    CHECK(r.point[5] == 0.5 * r.direction[5] && r.equal_lengths == 0);
    CHECK_NEAR(r.min_elevation, PI / 4.0, TOL_UNIT, 0.0);
    hfvis_lk_rays_free(NULL, &r);
    hfvis_lk_rays_free(NULL, NULL);
    memset(&tmp, 0, sizeof tmp);
    dirs[2] = 0.0; /* direction 0 has u_z = 0 */
    CHECK_EQ_STATUS(hfvis_lk_rays_custom(2, 3.0, dirs, len, NULL, &tmp), HFVIS_ERR_INVALID_ARGUMENT);
    dirs[2] = 1.0;
    len[1] = 1.5;
    CHECK_EQ_STATUS(hfvis_lk_rays_custom(2, 3.0, dirs, len, NULL, &tmp), HFVIS_ERR_INVALID_ARGUMENT);
    len[1] = (double)NAN;
    CHECK_EQ_STATUS(hfvis_lk_rays_custom(2, 3.0, dirs, len, NULL, &tmp), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_rays_custom(2, 3.0, NULL, NULL, NULL, &tmp), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_rays_custom(0, 3.0, dirs, NULL, NULL, &tmp), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_rays_custom(2, -1.0, dirs, NULL, NULL, &tmp), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_rays_custom(2, 1.0, dirs, NULL, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    dirs[0] = (double)INFINITY;
    CHECK_EQ_STATUS(hfvis_lk_rays_custom(2, 3.0, dirs, NULL, NULL, &tmp), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(tmp.direction == NULL);
    /* build */
    CHECK_EQ_STATUS(hfvis_lk_rays_build(0, 1.0, NULL, &tmp), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_rays_build(HFVIS_LK_MAX_RAYS + 1, 1.0, NULL, &tmp), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_rays_build(32, 0.0, NULL, &tmp), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_rays_build(32, (double)INFINITY, NULL, &tmp), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_rays_build(32, 1.0, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    o.pattern = (hfvis_lk_pattern)7;
    CHECK_EQ_STATUS(hfvis_lk_rays_build(32, 1.0, &o, &tmp), HFVIS_ERR_INVALID_ARGUMENT);
    o = hfvis_lk_ray_options_default();
    o.falloff = (hfvis_lk_falloff)9;
    CHECK_EQ_STATUS(hfvis_lk_rays_build(32, 1.0, &o, &tmp), HFVIS_ERR_INVALID_ARGUMENT);
    o = hfvis_lk_ray_options_default();
    o.density_resolution = 8;
    CHECK_EQ_STATUS(hfvis_lk_rays_build(32, 1.0, &o, &tmp), HFVIS_ERR_INVALID_ARGUMENT);
    o = hfvis_lk_ray_options_default();
    o.lloyd_iterations = -1;
    CHECK_EQ_STATUS(hfvis_lk_rays_build(32, 1.0, &o, &tmp), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(tmp.direction == NULL);
    /* helpers */
    CHECK(hfvis_lk_mask_words(1) == 1 && hfvis_lk_mask_words(32) == 1 && hfvis_lk_mask_words(33) == 2);
    CHECK(hfvis_lk_mask_words(0) == 0 && hfvis_lk_mask_words(HFVIS_LK_MAX_RAYS + 1) == 0);
    {
        uint32_t m[2] = {0xFFu, 0x1u};
        CHECK(hfvis_lk_obscurance(m, 40) == 9.0 / 40.0);
        CHECK(isnan(hfvis_lk_obscurance(NULL, 40)) && isnan(hfvis_lk_obscurance(m, 0)));
    }
}

TEST(rays_alloc_failures)
{
    int k, pat;
    for (pat = 0; pat < 2; pat++)
        for (k = 1; k <= 3; k++) {
            test_counting c = {0, 0, 0, 0, 0};
            hfvis_allocator al = {test_count_alloc, test_count_free, NULL};
            hfvis_lk_ray_options o = hfvis_lk_ray_options_default();
            hfvis_lk_rays r;
            hfvis_status s;
            al.user = &c;
            c.fail_at = k;
            o.alloc = &al;
            o.pattern = pat ? HFVIS_LK_PATTERN_RANDOM : HFVIS_LK_PATTERN_LLOYD;
            memset(&r, 0x33, sizeof r);
            s = hfvis_lk_rays_build(64, 1.0, &o, &r);
            if (k <= (pat ? 1 : 2)) {
                CHECK_EQ_STATUS(s, HFVIS_ERR_OUT_OF_MEMORY);
                CHECK(r.count == 0x33333333);
            } else {
                CHECK_EQ_STATUS(s, HFVIS_OK);
                hfvis_lk_rays_free(&al, &r);
            }
            CHECK(c.allocs >= (k <= (pat ? 1 : 2) ? k : (pat ? 1 : 2)));
            CHECK(c.live == 0 && c.allocs - (k <= (pat ? 1 : 2) ? 1 : 0) == c.frees);
        }
    {
        test_counting c = {0, 0, 0, 1, 0};
        hfvis_allocator al = {test_count_alloc, test_count_free, NULL};
        double d[3] = {0.0, 0.0, 1.0};
        hfvis_lk_rays r;
        al.user = &c;
        memset(&r, 0, sizeof r);
        CHECK_EQ_STATUS(hfvis_lk_rays_custom(1, 1.0, d, NULL, &al, &r), HFVIS_ERR_OUT_OF_MEMORY);
        CHECK(c.live == 0 && r.direction == NULL);
    }
}

/* ---------------------------------------------------------------------------------------- */
/* receiver frame ([LK] §3; docs/errata.md E45)                                              */
/* ---------------------------------------------------------------------------------------- */

TEST(frame_orthonormal_and_jitter)
{
    hfvis_lk_rays rays = make_rays(256, 1.0, HFVIS_LK_FALLOFF_CONSTANT, 1);
    double F[9], G[9], n[3] = {0.0, 0.0, 1.0};
    int t, i, a, b, bad = 0, below = 0, tilt_bad = 0;
    CHECK_EQ_STATUS(hfvis_lk_frame(&rays, n, 0, 0, HFVIS_LK_JITTER_NONE, 0.0, 0.0, F), HFVIS_OK);
    for (i = 0; i < 9; i++) bad += F[i] != (i % 4 == 0 ? 1.0 : 0.0); /* identity for +z */
    CHECK(bad == 0);
    rng_seed(11);
    for (t = 0; t < 2000; t++) {
        double nn[3], len, tilt = 0.9 * rays.min_elevation;
        hfvis_lk_jitter mode = t % 3 == 0 ? HFVIS_LK_JITTER_NONE
                               : t % 3 == 1 ? HFVIS_LK_JITTER_DEFAULT : HFVIS_LK_JITTER_CUSTOM;
        for (a = 0; a < 3; a++) nn[a] = srand1();
        if (t == 1) { nn[0] = 0.0; nn[1] = 0.0; nn[2] = -3.0; } /* -z: Duff's branch */
        CHECK_EQ_STATUS(hfvis_lk_frame(&rays, nn, 99, (uint64_t)t, mode, 1.0, 0.3, F), HFVIS_OK);
        len = sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
        for (a = 0; a < 3; a++)
            for (b = 0; b < 3; b++) {
                double d = F[3 * a] * F[3 * b] + F[3 * a + 1] * F[3 * b + 1] + F[3 * a + 2] * F[3 * b + 2];
                if (fabs(d - (a == b ? 1.0 : 0.0)) > TOL_UNIT) bad++;
            }
        /* right-handed */
        if (fabs(F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) +
                 F[2] * (F[3] * F[7] - F[4] * F[6]) - 1.0) > TOL_UNIT)
            bad++;
        /* tilt of z' from n at most min(tilt_max, 0.9 min_elevation); rays above the plane */
        {
            double cz = (F[6] * nn[0] + F[7] * nn[1] + F[8] * nn[2]) / len;
            double lim = mode == HFVIS_LK_JITTER_NONE ? 0.0
                         : mode == HFVIS_LK_JITTER_DEFAULT ? (HFVIS_LK_DEFAULT_TILT < tilt ? HFVIS_LK_DEFAULT_TILT : tilt)
                         : (0.3 < tilt ? 0.3 : tilt);
            if (acos(cz > 1.0 ? 1.0 : cz) > lim + 1e-7) tilt_bad++;
        }
        for (i = 0; i < rays.count; i++) {
            const double *u = rays.direction + 3 * i;
            double wd[3];
            for (a = 0; a < 3; a++) wd[a] = F[a] * u[0] + F[3 + a] * u[1] + F[6 + a] * u[2];
            if (!((wd[0] * nn[0] + wd[1] * nn[1] + wd[2] * nn[2]) / len > 0.05 * sin(rays.min_elevation)))
                below++;
        }
        /* deterministic per key */
        CHECK_EQ_STATUS(hfvis_lk_frame(&rays, nn, 99, (uint64_t)t, mode, 1.0, 0.3, G), HFVIS_OK);
        if (memcmp(F, G, sizeof F)) bad++;
    }
    CHECK(bad == 0);
    CHECK(tilt_bad == 0);
    CHECK(below == 0);
    /* different keys differ (jitter on) */
    CHECK_EQ_STATUS(hfvis_lk_frame(&rays, n, 5, 1, HFVIS_LK_JITTER_DEFAULT, 0.0, 0.0, F), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_lk_frame(&rays, n, 5, 2, HFVIS_LK_JITTER_DEFAULT, 0.0, 0.0, G), HFVIS_OK);
    CHECK(memcmp(F, G, sizeof F) != 0);
    /* bad arguments: frame untouched */
    memset(G, 0, sizeof G);
    n[2] = 0.0;
    CHECK_EQ_STATUS(hfvis_lk_frame(&rays, n, 0, 0, HFVIS_LK_JITTER_NONE, 0.0, 0.0, G), HFVIS_ERR_INVALID_ARGUMENT);
    n[2] = (double)NAN;
    CHECK_EQ_STATUS(hfvis_lk_frame(&rays, n, 0, 0, HFVIS_LK_JITTER_NONE, 0.0, 0.0, G), HFVIS_ERR_INVALID_ARGUMENT);
    n[2] = 1.0;
    CHECK_EQ_STATUS(hfvis_lk_frame(&rays, n, 0, 0, HFVIS_LK_JITTER_CUSTOM, 4.0, 0.0, G), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_frame(&rays, n, 0, 0, HFVIS_LK_JITTER_CUSTOM, 0.0, -0.1, G), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_frame(&rays, n, 0, 0, (hfvis_lk_jitter)5, 0.0, 0.0, G), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_frame(NULL, n, 0, 0, HFVIS_LK_JITTER_NONE, 0.0, 0.0, G), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_frame(&rays, n, 0, 0, HFVIS_LK_JITTER_NONE, 0.0, 0.0, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    for (i = 0, bad = 0; i < 9; i++) bad += G[i] != 0.0;
    CHECK(bad == 0);
    hfvis_lk_rays_free(NULL, &rays);
}

/* ---------------------------------------------------------------------------------------- */
/* masks: plane mask, triangle mask vs independent ray tests, LUT ([LK] §3.1, Fig. 1)     */
/* ---------------------------------------------------------------------------------------- */

/* Independent oracle in double (Moller-Trumbore on the world segment p -> p + l w, both ends
 * included), with the one-sided, epsilon and window rules. 1 = blocked. */
static int mt_blocked(const double p[3], const double wdir[3], double len, const float *f0,
                      const float *f1, const float *f2, int two_sided, double rmin, double rmax,
                      double r, double eps)
{
    double e1[3], e2[3], pv[3], tv[3], qv[3], det, u, v, t, n[3], nl, h, lambda = len / r;
    int a;
    for (a = 0; a < 3; a++) {
        e1[a] = (double)f1[a] - (double)f0[a];
        e2[a] = (double)f2[a] - (double)f0[a];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    nl = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(nl > 0.0)) return 0;
    h = (n[0] * ((double)f0[0] - p[0]) + n[1] * ((double)f0[1] - p[1]) + n[2] * ((double)f0[2] - p[2])) / nl;
    if (fabs(h) < eps) return 0;
    if (!two_sided && h >= 0.0) return 0;
    pv[0] = wdir[1] * e2[2] - wdir[2] * e2[1];
    pv[1] = wdir[2] * e2[0] - wdir[0] * e2[2];
    pv[2] = wdir[0] * e2[1] - wdir[1] * e2[0];
    det = e1[0] * pv[0] + e1[1] * pv[1] + e1[2] * pv[2];
    if (det == 0.0) return 0;
    for (a = 0; a < 3; a++) tv[a] = p[a] - (double)f0[a];
    u = (tv[0] * pv[0] + tv[1] * pv[1] + tv[2] * pv[2]) / det;
    if (u < 0.0 || u > 1.0) return 0;
    qv[0] = tv[1] * e1[2] - tv[2] * e1[1];
    qv[1] = tv[2] * e1[0] - tv[0] * e1[2];
    qv[2] = tv[0] * e1[1] - tv[1] * e1[0];
    v = (wdir[0] * qv[0] + wdir[1] * qv[1] + wdir[2] * qv[2]) / det;
    if (v < 0.0 || u + v > 1.0) return 0;
    t = (e2[0] * qv[0] + e2[1] * qv[1] + e2[2] * qv[2]) / det; /* distance (unit wdir) */
    return t > 0.0 && t >= rmin * lambda && t <= rmax * lambda;
}

TEST(triangle_mask_vs_ray_oracle)
{
    hfvis_lk_rays rays = make_rays(128, 1.0, HFVIS_LK_FALLOFF_LINEAR, 21);
    long total = 0, mism = 0, masked = 0, setbits = 0;
    int t, i, a;
    rng_seed(5);
    for (t = 0; t < 3000; t++) {
        double p[3], n[3], F[9], rmin = 0.0, rmax = 1.0;
        float v[3][3];
        uint32_t mask[4];
        hfvis_lk_verdict vd;
        int two = t % 2;
        for (a = 0; a < 3; a++) {
            p[a] = 0.3 * srand1();
            n[a] = srand1();
        }
        for (i = 0; i < 3; i++)
            for (a = 0; a < 3; a++) v[i][a] = (float)(1.2 * srand1());
        if (t % 5 == 1) {
            rmin = 0.4 * urand();
            rmax = rmin + (1.0 - rmin) * urand();
        }
        CHECK_EQ_STATUS(hfvis_lk_frame(&rays, n, 1, (uint64_t)t, HFVIS_LK_JITTER_DEFAULT, 0.0, 0.0, F), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_lk_triangle_mask(&rays, NULL, p, F, v[0], v[1], v[2], two, rmin, rmax,
                                               1e-5, mask, &vd), HFVIS_OK);
        masked += vd == HFVIS_LK_TRI_MASKED;
        for (i = 0; i < rays.count; i++) {
            const double *u = rays.direction + 3 * i;
            double wd[3];
            int got = (int)((mask[i >> 5] >> (i & 31)) & 1u), want;
            for (a = 0; a < 3; a++) wd[a] = F[a] * u[0] + F[3 + a] * u[1] + F[6 + a] * u[2];
            want = mt_blocked(p, wd, rays.length[i], v[0], v[1], v[2], two, rmin, rmax, 1.0, 1e-5);
            mism += got != want;
            setbits += got;
            total++;
        }
    }
    printf("  %ld ray-triangle pairs (%ld masked triangles, %ld blocked rays): %ld disagree with "
           "Moller-Trumbore in double\n", total, masked, setbits, mism);
    CHECK(setbits > 1000);
    CHECK(mism <= 2); /* only rays within rounding of an edge or the segment's end */
    hfvis_lk_rays_free(NULL, &rays);
}

TEST(plane_mask_and_lut)
{
    hfvis_lk_rays rays = make_rays(128, 1.0, HFVIS_LK_FALLOFF_CONSTANT, 2);
    hfvis_lk_rays vrays = make_rays(128, 1.0, HFVIS_LK_FALLOFF_LINEAR, 2);
    hfvis_lk_lut L16, L64, L128, LV;
    uint32_t mask[4];
    double m[3] = {0.0, 0.0, 1.0};
    int ijk[3], i, T, bad;
    long mis[3] = {0, 0, 0}, tot = 0, edge_bad = 0;
    /* exact plane mask: bit i = s_z >= 0.5 */
    CHECK_EQ_STATUS(hfvis_lk_plane_mask(&rays, m, 0.5, mask), HFVIS_OK);
    for (i = 0, bad = 0; i < 128; i++)
        bad += (int)((mask[i >> 5] >> (i & 31)) & 1u) != (rays.point[3 * i + 2] >= 0.5);
    CHECK(bad == 0);
    /* node indexing ([LK] §3.1; docs/errata.md E40): T = 3, m = +x: d = 0 -> the outer shell, d = r -> centre */
    CHECK_EQ_STATUS(hfvis_lk_lut_index(3, (const double[3]){1.0, 0.0, 0.0}, 0.0, ijk), HFVIS_OK);
    CHECK(ijk[0] == 2 && ijk[1] == 1 && ijk[2] == 1);
    CHECK_EQ_STATUS(hfvis_lk_lut_index(3, (const double[3]){1.0, 0.0, 0.0}, 1.0, ijk), HFVIS_OK);
    CHECK(ijk[0] == 1 && ijk[1] == 1 && ijk[2] == 1);
    CHECK_EQ_STATUS(hfvis_lk_lut_index(128, (const double[3]){-2.0, 2.0, 1.0}, 0.0, ijk), HFVIS_OK);
    CHECK(ijk[0] == 0 && ijk[1] == 127 && ijk[2] == 95); /* q = (-1, 1, 0.5): floor(1.5*63.5+.5) */
    CHECK_EQ_STATUS(hfvis_lk_lut_index(1, m, 0.0, ijk), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_lut_index(8, (const double[3]){0.0, 0.0, 0.0}, 0.0, ijk), HFVIS_ERR_INVALID_ARGUMENT);
    /* sizes and the memory guard */
    CHECK(hfvis_lk_lut_bytes(128, 128, 0) == (size_t)128 * 128 * 128 * 16);
    CHECK(hfvis_lk_lut_bytes(128, 1024, 0) == ((size_t)1 << 28)); /* the paper's 1024-ray case */
    CHECK(hfvis_lk_lut_bytes(1, 128, 0) == 0 && hfvis_lk_lut_bytes(8, 0, 0) == 0);
    {
        hfvis_lk_rays big = make_rays(1024, 1.0, HFVIS_LK_FALLOFF_LINEAR, 2);
        memset(&LV, 0, sizeof LV);
        CHECK_EQ_STATUS(hfvis_lk_lut_build(&big, 129, NULL, &LV), HFVIS_ERR_LIMIT);
        CHECK_EQ_STATUS(hfvis_lk_lut_build(&big, 128, NULL, &LV), HFVIS_ERR_LIMIT); /* 2 tables */
        CHECK(LV.masks == NULL);
        hfvis_lk_rays_free(NULL, &big);
    }
    CHECK_EQ_STATUS(hfvis_lk_lut_build(&rays, 16, NULL, &L16), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_lk_lut_build(&rays, 64, NULL, &L64), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_lk_lut_build(&rays, 128, NULL, &L128), HFVIS_OK);
    CHECK(L128.directions == NULL && L128.bytes == hfvis_lk_lut_bytes(128, 128, 0));
    /* LUT vs exact plane masks on random planes: the mismatch rate falls with T (A.14-9), and
     * d = 0 planes agree for every ray farther than one node from the plane */
    rng_seed(8);
    for (i = 0; i < 3000; i++) {
        double mm[3], len, dr = i % 3 == 0 ? 0.0 : urand();
        uint32_t ex[4];
        const uint32_t *lu[3];
        int k, j;
        mm[0] = srand1(); mm[1] = srand1(); mm[2] = srand1();
        len = sqrt(mm[0] * mm[0] + mm[1] * mm[1] + mm[2] * mm[2]);
        for (k = 0; k < 3; k++) mm[k] /= len;
        hfvis_lk_plane_mask(&rays, mm, dr, ex);
        lu[0] = hfvis_lk_lut_fetch(&L16, 0, mm, dr);
        lu[1] = hfvis_lk_lut_fetch(&L64, 0, mm, dr);
        lu[2] = hfvis_lk_lut_fetch(&L128, 0, mm, dr);
        for (j = 0; j < 128; j++) {
            int e = (int)((ex[j >> 5] >> (j & 31)) & 1u);
            const double *s = rays.point + 3 * j;
            double sd = mm[0] * s[0] + mm[1] * s[1] + mm[2] * s[2];
            for (k = 0; k < 3; k++) mis[k] += e != (int)((lu[k][j >> 5] >> (j & 31)) & 1u);
            if (dr == 0.0 && fabs(sd) > sin(sqrt(3.0) / 127.0) + 1e-9 &&
                e != (int)((lu[2][j >> 5] >> (j & 31)) & 1u))
                edge_bad++;
            tot++;
        }
    }
    printf("  LUT vs exact plane masks: mismatch rate T=16 %.4f, T=64 %.4f, T=128 %.4f; "
           "d=0 planes, rays > 1 node away: %ld mismatches\n",
           (double)mis[0] / tot, (double)mis[1] / tot, (double)mis[2] / tot, edge_bad);
    CHECK(mis[0] > mis[1] && mis[1] > mis[2]);
    CHECK((double)mis[2] / tot < RATE_LUT_128);
    CHECK(edge_bad == 0);
    /* the LUT triangle mask is close to the exact one */
    {
        long tm = 0, tt = 0;
        for (i = 0; i < 1000; i++) {
            double p[3] = {0.0, 0.0, 0.0}, F[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
            float v[3][3];
            uint32_t ex[4], lu[4];
            int k, j;
            for (k = 0; k < 3; k++)
                for (j = 0; j < 3; j++) v[k][j] = (float)(j == 2 ? 0.2 + 0.8 * urand() : srand1());
            hfvis_lk_triangle_mask(&rays, NULL, p, F, v[0], v[1], v[2], 1, 0.0, 1.0, 1e-5, ex, NULL);
            hfvis_lk_triangle_mask(&rays, &L128, p, F, v[0], v[1], v[2], 1, 0.0, 1.0, 1e-5, lu, NULL);
            for (j = 0; j < 4; j++) {
                uint32_t x = ex[j] ^ lu[j];
                tm += count_bits(&x, 1);
            }
            tt += 128;
        }
        printf("  LUT (T=128) vs exact triangle masks: %.4f of the bits differ\n", (double)tm / tt);
        CHECK((double)tm / tt < RATE_LUT_128);
    }
    /* variable lengths: a second (direction) table */
    CHECK_EQ_STATUS(hfvis_lk_lut_build(&vrays, 16, NULL, &LV), HFVIS_OK);
    CHECK(LV.directions != NULL && LV.bytes == hfvis_lk_lut_bytes(16, 128, 1));
    CHECK(hfvis_lk_lut_fetch(&LV, 1, m, 0.5) != hfvis_lk_lut_fetch(&LV, 0, m, 0.5));
    CHECK(hfvis_lk_lut_fetch(&L16, 1, m, 0.5) == hfvis_lk_lut_fetch(&L16, 0, m, 0.5));
    CHECK(hfvis_lk_lut_fetch(NULL, 0, m, 0.5) == NULL);
    CHECK(hfvis_lk_lut_fetch(&L16, 0, (const double[3]){0.0, 0.0, 0.0}, 0.5) == NULL);
    /* OOM sweep of the build: 1 or 2 blocks */
    for (T = 1; T <= 3; T++) {
        test_counting c = {0, 0, 0, 0, 0};
        hfvis_allocator al = {test_count_alloc, test_count_free, NULL};
        hfvis_lk_lut L;
        hfvis_status s;
        al.user = &c;
        c.fail_at = T;
        memset(&L, 0, sizeof L);
        s = hfvis_lk_lut_build(&vrays, 8, &al, &L);
        CHECK_EQ_STATUS(s, T <= 2 ? HFVIS_ERR_OUT_OF_MEMORY : HFVIS_OK);
        if (s == HFVIS_OK) hfvis_lk_lut_free(&al, &L);
        CHECK(c.live == 0 && L.masks == NULL);
    }
    CHECK_EQ_STATUS(hfvis_lk_lut_build(NULL, 8, NULL, &LV), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_lut_build(&rays, 1, NULL, &LV), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_lut_build(&rays, 8, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_plane_mask(&rays, NULL, 0.5, mask), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_plane_mask(&rays, m, (double)NAN, mask), HFVIS_ERR_INVALID_ARGUMENT);
    hfvis_lk_lut_free(NULL, &L16);
    hfvis_lk_lut_free(NULL, &L64);
    hfvis_lk_lut_free(NULL, &L128);
    hfvis_lk_lut_free(NULL, &LV);
    hfvis_lk_lut_free(NULL, NULL);
    hfvis_lk_rays_free(NULL, &rays);
    hfvis_lk_rays_free(NULL, &vrays);
}

TEST(two_sided_is_or_of_flipped_pair)
{
    hfvis_lk_rays rays = make_rays(96, 1.0, HFVIS_LK_FALLOFF_QUADRATIC, 4);
    int t, a, bad = 0, nonzero = 0;
    rng_seed(77);
    for (t = 0; t < 2000; t++) {
        double p[3], n[3], F[9];
        float v[3][3];
        uint32_t two[3], one[3], flip[3];
        int w;
        for (a = 0; a < 3; a++) {
            p[a] = 0.2 * srand1();
            n[a] = srand1();
            v[0][a] = (float)srand1();
            v[1][a] = (float)srand1();
            v[2][a] = (float)srand1();
        }
        hfvis_lk_frame(&rays, n, 3, (uint64_t)t, HFVIS_LK_JITTER_DEFAULT, 0.0, 0.0, F);
        hfvis_lk_triangle_mask(&rays, NULL, p, F, v[0], v[1], v[2], 1, 0.0, 1.0, 1e-6, two, NULL);
        hfvis_lk_triangle_mask(&rays, NULL, p, F, v[0], v[1], v[2], 0, 0.0, 1.0, 1e-6, one, NULL);
        hfvis_lk_triangle_mask(&rays, NULL, p, F, v[0], v[2], v[1], 0, 0.0, 1.0, 1e-6, flip, NULL);
        for (w = 0; w < 3; w++) {
            bad += two[w] != (one[w] | flip[w]);
            bad += (one[w] & flip[w]) != 0; /* one side only */
            nonzero += two[w] != 0;
        }
    }
    CHECK(bad == 0);
    CHECK(nonzero > 100);
    hfvis_lk_rays_free(NULL, &rays);
}

TEST(triangle_mask_bad_args)
{
    hfvis_lk_rays rays = make_rays(64, 1.0, HFVIS_LK_FALLOFF_CONSTANT, 4);
    double p[3] = {0, 0, 0}, F[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    float a[3] = {0, 0, 0.5f}, b[3] = {1, 0, 0.5f}, c[3] = {0, 1, 0.5f}, bad3[3] = {0, (float)NAN, 1};
    uint32_t m[2] = {7, 7};
    hfvis_lk_verdict vd = HFVIS_LK_TRI_MASKED;
    hfvis_lk_lut L;
    CHECK_EQ_STATUS(hfvis_lk_triangle_mask(&rays, NULL, p, F, a, b, c, 0, 0.0, 1.0, 1e-5, m, &vd), HFVIS_OK);
    CHECK(vd == HFVIS_LK_TRI_FACING_AWAY && m[0] == 0 && m[1] == 0); /* normal +z, receiver below */
    CHECK_EQ_STATUS(hfvis_lk_triangle_mask(&rays, NULL, p, F, a, c, b, 0, 0.0, 1.0, 1e-5, m, &vd), HFVIS_OK);
    CHECK(vd == HFVIS_LK_TRI_MASKED && (m[0] | m[1]) != 0);
    CHECK_EQ_STATUS(hfvis_lk_triangle_mask(&rays, NULL, p, F, a, c, b, 0, 0.0, 0.4, 1e-5, m, &vd), HFVIS_OK);
    CHECK(vd == HFVIS_LK_TRI_TOO_FAR && m[0] == 0);
    CHECK_EQ_STATUS(hfvis_lk_triangle_mask(&rays, NULL, p, F, a, a, b, 0, 0.0, 1.0, 1e-5, m, &vd), HFVIS_OK);
    CHECK(vd == HFVIS_LK_TRI_DEGENERATE);
    CHECK_EQ_STATUS(hfvis_lk_triangle_mask(&rays, NULL, p, F, a, c, b, 0, 0.0, 1.0, 2.0, m, &vd), HFVIS_OK);
    CHECK(vd == HFVIS_LK_TRI_SELF);
    m[0] = m[1] = 7;
    CHECK_EQ_STATUS(hfvis_lk_triangle_mask(NULL, NULL, p, F, a, b, c, 0, 0.0, 1.0, 1e-5, m, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_triangle_mask(&rays, NULL, NULL, F, a, b, c, 0, 0.0, 1.0, 1e-5, m, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_triangle_mask(&rays, NULL, p, F, a, bad3, c, 0, 0.0, 1.0, 1e-5, m, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_triangle_mask(&rays, NULL, p, F, a, b, c, 0, 0.5, 0.4, 1e-5, m, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_triangle_mask(&rays, NULL, p, F, a, b, c, 0, 0.0, 1.5, 1e-5, m, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_triangle_mask(&rays, NULL, p, F, a, b, c, 0, 0.0, 1.0, 0.0, m, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_triangle_mask(&rays, NULL, p, F, a, b, c, 0, 0.0, 1.0, 1e-5, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    memset(&L, 0, sizeof L);
    CHECK_EQ_STATUS(hfvis_lk_triangle_mask(&rays, &L, p, F, a, b, c, 0, 0.0, 1.0, 1e-5, m, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(m[0] == 7 && m[1] == 7);
    hfvis_lk_rays_free(NULL, &rays);
}

/* ---------------------------------------------------------------------------------------- */
/* analytic cases (..6), every method                                                        */
/* ---------------------------------------------------------------------------------------- */

/* Rays of s_dim >= c (dim 0..2, sign +-1). */
static int count_at_least(const hfvis_lk_rays *r, int dim, double sign, double c)
{
    int i, n = 0;
    for (i = 0; i < r->count; i++) n += sign * r->point[3 * i + dim] >= c;
    return n;
}

/* Method 1 on a floor z = 0 seen from above (orthographic, W x W pixels over [-half, half]^2,
 * receivers' mask counts of the pixels whose centre lies within `inner` of the origin): every
 * such receiver must have exactly `want` bits. Returns the receivers checked, -1 on mismatch. */
static int m1_floor_check(const hfvis_mesh *m, const hfvis_lk_rays *rays, hfvis_lk_options o,
                          double half, double inner, int want)
{
    enum { W = 24 };
    hfvis_view v = ortho_down(half, W, W, 0.0, 0.0);
    uint32_t *masks = (uint32_t *)malloc(sizeof(uint32_t) * W * W * (size_t)rays->words);
    int x, y, checked = 0, bad = 0;
    o.jitter = HFVIS_LK_JITTER_NONE;
    o.gbuffer_cull = HFVIS_CULL_BACK; /* see the floor through the occluders' back faces */
    if (!masks || hfvis_lk_raster(m, &v, rays, &o, masks, NULL, NULL) != HFVIS_OK) {
        free(masks);
        return -1;
    }
    for (y = 0; y < W; y++)
        for (x = 0; x < W; x++) {
            double px = (2.0 * (x + 0.5) / W - 1.0) * half, py = (1.0 - 2.0 * (y + 0.5) / W) * half;
            if (fabs(px) > inner || fabs(py) > inner) continue;
            checked++;
            bad += count_bits(masks + ((size_t)y * W + (size_t)x) * (size_t)rays->words, rays->words) != want;
        }
    free(masks);
    return bad ? -1 : checked;
}

TEST(analytic_empty_and_parallel_plane)
{
    const double r = 1.0;
    static const double hs[] = {0.1, 0.3, 0.5, 0.8, 1.2};
    hfvis_lk_rays rays = make_rays(1024, r, HFVIS_LK_FALLOFF_CONSTANT, 12);
    hfvis_lk_options o = hfvis_lk_options_default();
    int q, agree;
    { /* 1. empty scene (only the floor, coplanar with the receiver): W = 0 */
        tmesh tm = {0};
        hfvis_mesh m;
        tm_rect(&tm, 2, 0.0, (const double[2]){-4, -4}, (const double[2]){4, 4}, 1.0);
        m = tm_view(&tm);
        CHECK(origin_count(&m, &rays, &o, &agree) == 0 && agree);
        CHECK(m1_floor_check(&m, &rays, o, 3.0, 2.5, 0) > 100);
        tm_free(&tm);
    }
    for (q = 0; q < 5; q++) { /* 2. plane at height h facing the receiver: W_N = #{s_z >= h/r}/N */
        double h = hs[q], w, closed = h < r ? 1.0 - (h / r) * (h / r) : 0.0;
        int want = count_at_least(&rays, 2, 1.0, h / r), got, checked;
        tmesh tm = {0};
        hfvis_mesh m;
        tm_rect(&tm, 2, 0.0, (const double[2]){-5, -5}, (const double[2]){5, 5}, 1.0);  /* floor */
        tm_rect(&tm, 2, h, (const double[2]){-3, -3}, (const double[2]){3, 3}, -1.0);   /* plane */
        m = tm_view(&tm);
        got = origin_count(&m, &rays, &o, &agree);
        CHECK(got == want && agree);
        w = (double)got / rays.count;
        CHECK_NEAR(w, closed, TOL_CLOSED_1024, 0.0);
        checked = m1_floor_check(&m, &rays, o, 2.5, 1.9, want); /* receivers >= 1 r from the edge */
        CHECK(checked > 100);
        /* facing away (normal +z): W = 0; two-sided: as facing */
        tm_free(&tm);
        tm_rect(&tm, 2, 0.0, (const double[2]){-5, -5}, (const double[2]){5, 5}, 1.0);
        tm_rect(&tm, 2, h, (const double[2]){-3, -3}, (const double[2]){3, 3}, 1.0);
        m = tm_view(&tm);
        CHECK(origin_count(&m, &rays, &o, &agree) == 0 && agree);
        o.sides = HFVIS_LK_SIDES_TWO;
        CHECK(origin_count(&m, &rays, &o, &agree) == want && agree);
        o.sides = HFVIS_LK_SIDES_ONE;
        printf("  plane h/r = %.1f: W_N = %.5f (%d/%d rays, all methods), closed form 1 - (h/r)^2 = %.5f\n",
               h / r, w, got, rays.count, closed);
        tm_free(&tm);
    }
    hfvis_lk_rays_free(NULL, &rays);
}

TEST(analytic_linear_falloff)
{
    const double r = 2.0;
    static const double hs[] = {0.2, 0.6, 1.0, 1.6};
    hfvis_lk_rays rays = make_rays(1024, r, HFVIS_LK_FALLOFF_LINEAR, 13);
    hfvis_lk_options o = hfvis_lk_options_default();
    int q, agree;
    for (q = 0; q < 4; q++) { /* 3. W = (1 - h/r)^2 */
        double h = hs[q], closed = (1.0 - h / r) * (1.0 - h / r);
        int want = count_at_least(&rays, 2, 1.0, h / r), got;
        tmesh tm = {0};
        hfvis_mesh m;
        tm_rect(&tm, 2, 0.0, (const double[2]){-9, -9}, (const double[2]){9, 9}, 1.0);
        tm_rect(&tm, 2, h, (const double[2]){-6, -6}, (const double[2]){6, 6}, -1.0);
        m = tm_view(&tm);
        got = origin_count(&m, &rays, &o, &agree);
        CHECK(got == want && agree);
        CHECK(m1_floor_check(&m, &rays, o, 5.0, 3.9, want) > 100);
        CHECK_NEAR((double)got / rays.count, closed, TOL_LINEAR_FALLOFF, 0.0);
        printf("  linear falloff h/r = %.1f: W_N = %.5f, closed form (1 - h/r)^2 = %.5f\n", h / r,
               (double)got / rays.count, closed);
        tm_free(&tm);
    }
    hfvis_lk_rays_free(NULL, &rays);
}

static double wall_closed(double c) { return (acos(c) - c * sqrt(1.0 - c * c)) / PI; }

TEST(analytic_wall_and_trench)
{
    const double r = 1.0;
    static const double as[] = {0.02, 0.25, 0.5, 0.75};
    hfvis_lk_rays rays = make_rays(1024, r, HFVIS_LK_FALLOFF_CONSTANT, 14);
    hfvis_lk_options o = hfvis_lk_options_default();
    int q, agree;
    for (q = 0; q < 4; q++) {
        double a = as[q], w;
        int want = count_at_least(&rays, 0, 1.0, a / r), got;
        int want2 = want + count_at_least(&rays, 0, -1.0, a / r);
        tmesh tm = {0};
        hfvis_mesh m;
        /* 4. wall x = a facing -x, height >= r: W = (acos c - c sqrt(1 - c^2))/pi */
        tm_rect(&tm, 2, 0.0, (const double[2]){-4, -4}, (const double[2]){4, 4}, 1.0);
        tm_rect(&tm, 0, a, (const double[2]){-4, -1}, (const double[2]){4, 3}, -1.0);
        m = tm_view(&tm);
        got = origin_count(&m, &rays, &o, &agree);
        CHECK(got == want && agree);
        w = (double)got / rays.count;
        CHECK_NEAR(w, wall_closed(a / r), TOL_CLOSED_1024, 0.0);
        /* 5. trench: second wall at -a facing +x; the floor contributes nothing */
        tm_rect(&tm, 0, -a, (const double[2]){-4, -1}, (const double[2]){4, 3}, 1.0);
        m = tm_view(&tm);
        got = origin_count(&m, &rays, &o, &agree);
        CHECK(got == want2 && agree);
        CHECK_NEAR((double)got / rays.count, 2.0 * wall_closed(a / r), 2.0 * TOL_CLOSED_1024, 0.0);
        printf("  wall a/r = %.2f: W_N = %.5f (closed %.5f); trench W_N = %.5f (closed %.5f)\n", a / r, w,
               wall_closed(a / r), (double)got / rays.count, 2.0 * wall_closed(a / r));
        tm_free(&tm);
    }
    hfvis_lk_rays_free(NULL, &rays);
}

/* Convergence of the default ray pattern against an independent cosine-sampled caster, where
 * the occlusion comes from grazing directions: receivers on the inside of a sphere (radius
 * R = 1, a 32 x 16 UV sphere turned inward). From a point on a smooth sphere the ray of
 * elevation e meets the sphere after 2R sin e, so only e < asin(r/2R) is blocked and
 * W = (r/2R)^2: a band at the rim of the disc of directions (the facets change it a little).
 * Two AO radii: r = 0.8 (band up to 0.41 rad, W ~ 0.16) and r = 0.3 (0.15 rad, W ~ 0.02).
 * The reference casts, per receiver, its own CONVERGE_REF_RAYS fresh directions (Malley's
 * method: uniform disc points from the test's PRNG, lifted) through every triangle within
 * reach with mt_blocked (Moller-Trumbore in double, the library's one-sided and epsilon rules).
 * The library runs the default ray set and options (Method 2; the frame jitter turns the set
 * per receiver). A pattern is unbiased when its mean over seeds converges to the reference:
 * the seed mean must lie within CONVERGE_SIGMAS standard errors of it (the seeds' spread /
 * sqrt(seeds), and the reference's binomial error), and the shipped seed 0 within
 * CONVERGE_SIGMAS spreads (one realization). Measured, seed mean / spread / seed 0: r = 0.8:
 * N = 128 -1.8 / 4.6 / +4.5 %, N = 1024 +0.2 / 1.6 / +2.3 %; r = 0.3 (about 3 of 128
 * directions in the band): N = 128 +4.6 / 54 / +28 %, N = 1024 +5.3 / 10 / +16 %. The [LK] §6
 * disc pattern (LLOYD, the default of 0.1.0) keeps its outermost ring half a cell inside the
 * rim, a deterministic error with little spread: seed 0 is -100 % (r = 0.3, N = 128), -93 %
 * (r = 0.3, N = 1024) and +14 % (r = 0.8, N = 128), so it fails this test. */
#define CONVERGE_REF_RAYS 1024  /* per receiver, 256 receivers */
#define CONVERGE_SEEDS_128 16   /* ray sets per count: building a 1024-ray set takes 0.3 s */
#define CONVERGE_SEEDS_1024 4
#define CONVERGE_SIGMAS 3.0     /* standard errors (seed mean) or spreads (seed 0) allowed */
#define CONVERGE_MAX_SPREAD_128 0.7  /* relative spread over seeds at N = 128: measured 0.54
                                        where the band holds 3 directions */
#define CONVERGE_MAX_SPREAD_1024 0.2 /* at N = 1024 (23 directions in the band): measured 0.10 */

/* A cosine-distributed direction about the unit normal n (Malley: a uniform disc point by
 * rejection, lifted onto the hemisphere), in an orthonormal frame (t1, t2, n). */
static void converge_cosine_dir(const double n[3], double out[3])
{
    double t1[3], t2[3], x, y, z, len;
    int a;
    if (fabs(n[0]) < 0.9) { t1[0] = 0.0; t1[1] = -n[2]; t1[2] = n[1]; }
    else { t1[0] = n[2]; t1[1] = 0.0; t1[2] = -n[0]; }
    len = sqrt(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
    for (a = 0; a < 3; a++) t1[a] /= len;
    t2[0] = n[1] * t1[2] - n[2] * t1[1];
    t2[1] = n[2] * t1[0] - n[0] * t1[2];
    t2[2] = n[0] * t1[1] - n[1] * t1[0];
    do {
        x = srand1();
        y = srand1();
    } while (x * x + y * y >= 1.0);
    z = sqrt(1.0 - x * x - y * y);
    for (a = 0; a < 3; a++) out[a] = x * t1[a] + y * t2[a] + z * n[a];
}

/* Mean obscurance of the receivers by the independent caster (see above). near: scratch of
 * one index per triangle. */
static double converge_reference(const hfvis_mesh *m, const double *pos, const double *nrm,
                                 int nrec, double r, uint32_t *near)
{
    double sum = 0.0, eps = HFVIS_LK_DEFAULT_EPSILON * r;
    int i, j, k;
    for (i = 0; i < nrec; i++) {
        size_t nn = 0, t;
        int blocked = 0;
        /* the triangles with a vertex within r + their longest edge (a triangle farther away
         * cannot meet a segment of length r from the receiver) */
        for (t = 0; t < m->triangle_count; t++) {
            const uint32_t *tri = m->indices + 3 * t;
            double dmin = 1e300, emax = 0.0;
            for (k = 0; k < 3; k++) {
                const float *v = m->xyz + 3 * tri[k], *w = m->xyz + 3 * tri[(k + 1) % 3];
                double d2 = 0.0, e2 = 0.0;
                int a;
                for (a = 0; a < 3; a++) {
                    d2 += ((double)v[a] - pos[3 * i + a]) * ((double)v[a] - pos[3 * i + a]);
                    e2 += ((double)v[a] - (double)w[a]) * ((double)v[a] - (double)w[a]);
                }
                if (d2 < dmin) dmin = d2;
                if (e2 > emax) emax = e2;
            }
            if (sqrt(dmin) <= r + sqrt(emax)) near[nn++] = (uint32_t)t;
        }
        for (j = 0; j < CONVERGE_REF_RAYS; j++) {
            double w[3];
            size_t u;
            converge_cosine_dir(nrm + 3 * i, w);
            for (u = 0; u < nn; u++) {
                const uint32_t *tri = m->indices + 3 * (size_t)near[u];
                if (mt_blocked(pos + 3 * i, w, r, m->xyz + 3 * tri[0], m->xyz + 3 * tri[1],
                               m->xyz + 3 * tri[2], 0, 0.0, r, r, eps)) {
                    blocked++;
                    break;
                }
            }
        }
        sum += (double)blocked / CONVERGE_REF_RAYS;
    }
    return sum / nrec;
}

/* Mean obscurance of the receivers by the library (Method 2, default options) with the
 * directions of `set` and radius r; NaN on failure. */
static double converge_library(const hfvis_mesh *m, const hfvis_bvh *bvh,
                               const hfvis_lk_receivers *rc, const hfvis_lk_rays *set, double r,
                               float *obs)
{
    hfvis_lk_rays rays;
    double sum = 0.0;
    size_t i;
    if (hfvis_lk_rays_custom(set->count, r, set->direction, NULL, NULL, &rays) != HFVIS_OK)
        return (double)NAN;
    if (hfvis_lk_bvh(m, bvh, &rays, rc, NULL, NULL, obs, NULL) != HFVIS_OK) sum = (double)NAN;
    hfvis_lk_rays_free(NULL, &rays);
    for (i = 0; i < rc->count; i++) sum += (double)obs[i];
    return sum / (double)rc->count;
}

TEST(default_pattern_converges_to_cosine_caster)
{
    enum { NREC = 256, NSETS = CONVERGE_SEEDS_128 + CONVERGE_SEEDS_1024 + 2 };
    static const double radii[2] = {0.8, 0.3};
    static const int counts[2] = {128, 1024}, seeds[2] = {CONVERGE_SEEDS_128, CONVERGE_SEEDS_1024};
    static const double max_spread[2] = {CONVERGE_MAX_SPREAD_128, CONVERGE_MAX_SPREAD_1024};
    const double centre[3] = {0.0, 0.0, 0.0};
    double pos[3 * NREC], nrm[3 * NREC];
    tmesh tm = {0};
    hfvis_mesh sphere, m;
    hfvis_bvh bvh;
    hfvis_lk_receivers rc;
    hfvis_lk_rays sets[NSETS]; /* per count: the default pattern's seeds, then LLOYD seed 0 */
    float obs[NREC];
    uint32_t *near = NULL;
    int i, k, q, ri, ns = 0;
    memset(sets, 0, sizeof sets);
    CHECK_EQ_STATUS(hfvis_mesh_uv_sphere(NULL, centre, 1.0, 32, 16, &sphere), HFVIS_OK);
    tm_add(&tm, &sphere, 1); /* facing inward */
    m = tm_view(&tm);
    near = (uint32_t *)malloc(sizeof(uint32_t) * m.triangle_count);
    CHECK(near != NULL);
    CHECK_EQ_STATUS(hfvis_bvh_build(&m, NULL, &bvh), HFVIS_OK);
    for (q = 0; q < 2; q++)
        for (k = 0; k <= seeds[q]; k++, ns++) {
            hfvis_lk_ray_options ro = hfvis_lk_ray_options_default();
            ro.pattern = k < seeds[q] ? HFVIS_LK_PATTERN_DEFAULT : HFVIS_LK_PATTERN_LLOYD;
            ro.seed = k < seeds[q] ? (uint64_t)k : 0;
            CHECK_EQ_STATUS(hfvis_lk_rays_build(counts[q], 1.0, &ro, &sets[ns]), HFVIS_OK);
        }
    if (!near || test_current_failed) goto done;
    rng_seed(19);
    for (i = 0; i < NREC; i++) { /* the centroids of random facets, with their (inward) normals */
        const uint32_t *tri = m.indices + 3 * (size_t)(urand() * (double)m.triangle_count);
        const float *v0 = m.xyz + 3 * tri[0], *v1 = m.xyz + 3 * tri[1], *v2 = m.xyz + 3 * tri[2];
        double e1[3], e2[3], n[3], len;
        for (k = 0; k < 3; k++) {
            e1[k] = (double)v1[k] - (double)v0[k];
            e2[k] = (double)v2[k] - (double)v0[k];
            pos[3 * i + k] = ((double)v0[k] + (double)v1[k] + (double)v2[k]) / 3.0;
        }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (k = 0; k < 3; k++) nrm[3 * i + k] = n[k] / len;
    }
    rc.count = NREC;
    rc.position = pos;
    rc.normal = nrm;
    rc.key = NULL;
    for (ri = 0; ri < 2; ri++) {
        double r = radii[ri], ref = converge_reference(&m, pos, nrm, NREC, r, near);
        double ref_se = sqrt(ref * (1.0 - ref) / ((double)CONVERGE_REF_RAYS * NREC)) / ref;
        printf("  inside a sphere, r = %.1f, %d receivers: independent caster (%d rays each) W %.4f "
               "(relative error %.1f %%; smooth sphere %.4f)\n", r, NREC, CONVERGE_REF_RAYS, ref,
               100.0 * ref_se, r * r / 4.0);
        for (q = 0, ns = 0; q < 2; ns += seeds[q] + 1, q++) {
            double mean = 0.0, var = 0.0, e0 = 0.0, spread, lloyd;
            for (k = 0; k < seeds[q]; k++) {
                double e = converge_library(&m, &bvh, &rc, &sets[ns + k], r, obs) / ref - 1.0;
                if (k == 0) e0 = e;
                mean += e / seeds[q];
                var += e * e / seeds[q];
            }
            spread = sqrt(fmax(var - mean * mean, 0.0) * seeds[q] / (seeds[q] - 1));
            lloyd = converge_library(&m, &bvh, &rc, &sets[ns + seeds[q]], r, obs) / ref - 1.0;
            printf("    N = %4d: default pattern, mean of %2d seeds %+.1f %% (spread %.1f %%), "
                   "seed 0 %+.1f %%; LLOYD seed 0 %+.1f %%\n", counts[q], seeds[q], 100.0 * mean,
                   100.0 * spread, 100.0 * e0, 100.0 * lloyd);
            CHECK(fabs(mean) <= CONVERGE_SIGMAS * (spread / sqrt((double)seeds[q]) + ref_se));
            CHECK(fabs(e0) <= CONVERGE_SIGMAS * (spread + ref_se));
            CHECK(spread <= max_spread[q]);
        }
    }
done:
    for (k = 0; k < NSETS; k++) hfvis_lk_rays_free(NULL, &sets[k]);
    hfvis_bvh_free(NULL, &bvh);
    free(near);
    hfvis_mesh_free(NULL, &sphere);
    tm_free(&tm);
}

TEST(analytic_closed_box)
{
    /* 6. receiver at the centre of the floor of the box [-1,1]^2 x [0,1] (faces inward): W = 1
     * when r >= the farthest corner (sqrt 3), W = 0 when r < the nearest wall (1) */
    const double lo[3] = {-1.0, -1.0, 0.0}, hi[3] = {1.0, 1.0, 1.0};
    hfvis_mesh box;
    tmesh tm = {0};
    hfvis_mesh m;
    int agree;
    hfvis_lk_rays far_rays = make_rays(512, 1.75, HFVIS_LK_FALLOFF_CONSTANT, 15);
    hfvis_lk_rays near_rays = make_rays(512, 0.99, HFVIS_LK_FALLOFF_CONSTANT, 15);
    CHECK_EQ_STATUS(hfvis_mesh_box(NULL, lo, hi, &box), HFVIS_OK);
    tm_add(&tm, &box, 1);
    m = tm_view(&tm);
    CHECK(origin_count(&m, &far_rays, NULL, &agree) == 512 && agree);
    CHECK(origin_count(&m, &near_rays, NULL, &agree) == 0 && agree);
    hfvis_mesh_free(NULL, &box);
    tm_free(&tm);
    hfvis_lk_rays_free(NULL, &far_rays);
    hfvis_lk_rays_free(NULL, &near_rays);
}

/* ---------------------------------------------------------------------------------------- */
/* the three methods agree bit for bit                                                       */
/* ---------------------------------------------------------------------------------------- */

static void tm_add_xf(tmesh *tm, const hfvis_mesh *src, double s, double ox, double oy, double oz)
{
    size_t base = tm->nv, i;
    for (i = 0; i < src->vertex_count; i++) {
        double p[3];
        p[0] = ox + s * (double)src->xyz[3 * i];
        p[1] = oy + s * (double)src->xyz[3 * i + 1];
        p[2] = oz + s * (double)src->xyz[3 * i + 2];
        tm_vertex(tm, p);
    }
    for (i = 0; i < src->triangle_count; i++)
        tm_tri_idx(tm, base + src->indices[3 * i], base + src->indices[3 * i + 1], base + src->indices[3 * i + 2]);
}

/* The room (unit cube, open at y = 0) with a teapot, an icosphere and a torus knot. */
static void room_scene(tmesh *tm, int detail)
{
    hfvis_mesh m;
    const double c0[3] = {0.0, 0.0, 0.0};
    if (hfvis_mesh_room(NULL, &m) == HFVIS_OK) { tm_add(tm, &m, 0); hfvis_mesh_free(NULL, &m); }
    if (hfvis_mesh_teapot(NULL, detail, &m) == HFVIS_OK) {
        tm_add_xf(tm, &m, 0.12, 0.3, 0.25, 0.0);
        hfvis_mesh_free(NULL, &m);
    }
    if (hfvis_mesh_icosphere(NULL, c0, 1.0, detail, &m) == HFVIS_OK) {
        tm_add_xf(tm, &m, 0.1, 0.72, 0.62, 0.1);
        hfvis_mesh_free(NULL, &m);
    }
    if (hfvis_mesh_torus_knot(NULL, c0, 1.0, 2, 3, 60 * detail, 8, &m) == HFVIS_OK) {
        tm_add_xf(tm, &m, 0.08, 0.5, 0.75, 0.7);
        hfvis_mesh_free(NULL, &m);
    }
}

/* Random soup above a floor: thin and fat triangles, random orientation, some large. */
static void soup_scene(tmesh *tm, int count, uint64_t seed)
{
    int t, k, a;
    rng_seed(seed);
    tm_rect(tm, 2, 0.0, (const double[2]){-2, -2}, (const double[2]){2, 2}, 1.0);
    for (t = 0; t < count; t++) {
        double c[3], v[3][3], s = t % 17 == 0 ? 0.8 : 0.05 + 0.3 * urand();
        c[0] = 1.5 * srand1();
        c[1] = 1.5 * srand1();
        c[2] = 0.02 + 1.2 * urand();
        for (k = 0; k < 3; k++)
            for (a = 0; a < 3; a++) v[k][a] = c[a] + s * srand1() * (t % 5 == 0 && a == 2 ? 0.05 : 1.0);
        tm_tri(tm, v[0], v[1], v[2]);
    }
}

TEST(three_methods_identical_on_meshes)
{
    tmesh tm = {0};
    hfvis_mesh m;
    const double eye[3] = {0.5, -1.1, 0.55}, tgt[3] = {0.5, 0.5, 0.35};
    hfvis_view v = persp(eye, tgt, 55.0, 64, 48);
    hfvis_lk_rays rays = make_rays(128, 0.15, HFVIS_LK_FALLOFF_CONSTANT, 31);
    hfvis_lk_rays rays2 = make_rays(100, 0.3, HFVIS_LK_FALLOFF_LINEAR, 32);
    hfvis_lk_options o = hfvis_lk_options_default();
    hfvis_lk_stats s1, s2;
    size_t n = 0;
    uint64_t blocked = 0;
    long bad;
    room_scene(&tm, 2);
    m = tm_view(&tm);
    bad = three_way(&m, &v, &rays, &o, &n, &blocked, &s1, &s2);
    printf("  room scene (%zu triangles), N=128 r=0.15: %zu receivers, %.3f blocked, %ld differ; "
           "M1 fragments %llu masks %llu (prisms %llu spheres %llu), M2 masks %llu nodes %llu\n",
           m.triangle_count, n, (double)blocked / ((double)n * 128), bad,
           (unsigned long long)s1.fragments, (unsigned long long)s1.masks,
           (unsigned long long)s1.prisms, (unsigned long long)s1.spheres,
           (unsigned long long)s2.masks, (unsigned long long)s2.nodes_visited);
    CHECK(bad == 0 && n > 1500 && blocked > 1000);
    CHECK(s1.receivers == n && s1.rays == n * 128 && s1.rays_blocked == blocked);
    CHECK(s1.prisms > 0 && s1.spheres > 0 && s1.fragments >= s1.masks);
    /* two-sided, linear falloff, another radius */
    o.sides = HFVIS_LK_SIDES_TWO;
    bad = three_way(&m, &v, &rays2, &o, &n, &blocked, NULL, NULL);
    printf("  room scene, two-sided, linear falloff N=100 r=0.3: %.3f blocked, %ld differ\n",
           (double)blocked / ((double)n * 100), bad);
    CHECK(bad == 0 && blocked > 1000);
    /* always prisms / always spheres, no jitter */
    o.sides = HFVIS_LK_SIDES_ONE;
    o.volume = HFVIS_LK_VOLUME_PRISM;
    o.jitter = HFVIS_LK_JITTER_NONE;
    CHECK(three_way(&m, &v, &rays, &o, NULL, NULL, NULL, NULL) == 0);
    o.volume = HFVIS_LK_VOLUME_SPHERE;
    o.jitter = HFVIS_LK_JITTER_CUSTOM;
    o.rotation_max_rad = 0.3;
    o.tilt_max_rad = 0.5;
    CHECK(three_way(&m, &v, &rays, &o, NULL, NULL, NULL, NULL) == 0);
    { /* an orthographic close-up of the torus knot alone, N = 32 */
        hfvis_mesh k;
        const double c0[3] = {0.0, 0.0, 0.0}, e2[3] = {0.3, -3.0, 2.0}, t2[3] = {0.0, 0.0, 0.0};
        const double up[3] = {0.0, 0.0, 1.0};
        hfvis_view ov;
        hfvis_lk_rays r32 = make_rays(32, 0.9, HFVIS_LK_FALLOFF_CONSTANT, 33);
        CHECK_EQ_STATUS(hfvis_mesh_torus_knot(NULL, c0, 1.0, 2, 3, 240, 10, &k), HFVIS_OK);
        hfvis_view_orthographic(&ov, e2, t2, up, 1.8, 56, 40, 0.1, 10.0);
        o = hfvis_lk_options_default();
        bad = three_way(&k, &ov, &r32, &o, &n, &blocked, NULL, NULL);
        printf("  torus knot (%zu triangles, orthographic), N=32 r=0.9: %zu receivers, "
               "%.3f blocked, %ld differ\n", k.triangle_count, n, (double)blocked / ((double)n * 32), bad);
        CHECK(bad == 0 && blocked > 100);
        hfvis_mesh_free(NULL, &k);
        hfvis_lk_rays_free(NULL, &r32);
    }
    tm_free(&tm);
    hfvis_lk_rays_free(NULL, &rays);
    hfvis_lk_rays_free(NULL, &rays2);
}

TEST(three_methods_identical_on_soups)
{
    int seed;
    for (seed = 1; seed <= 6; seed++) {
        tmesh tm = {0};
        hfvis_mesh m;
        const double eye[3] = {0.4, -3.2, 2.6}, tgt[3] = {0.0, 0.0, 0.3};
        hfvis_view v = persp(eye, tgt, 50.0, 48, 36);
        hfvis_lk_rays rays = make_rays(seed % 2 ? 64 : 96, 0.25 + 0.125 * seed,
                                       (hfvis_lk_falloff)(1 + seed % 4 % 3), (uint64_t)seed);
        hfvis_lk_options o = hfvis_lk_options_default();
        uint8_t *two;
        float *lod;
        size_t n = 0, t;
        uint64_t blocked = 0;
        long bad;
        soup_scene(&tm, 400, (uint64_t)(100 + seed));
        m = tm_view(&tm);
        two = (uint8_t *)malloc(m.triangle_count);
        lod = (float *)malloc(sizeof(float) * 2 * m.triangle_count);
        for (t = 0; t < m.triangle_count; t++) {
            double a = urand(), b = urand();
            two[t] = (uint8_t)(t % 3 == 0);
            lod[2 * t] = (float)(a < b ? a : b) * (float)rays.radius * 0.6f;
            lod[2 * t + 1] = (float)rays.radius * (float)(0.5 + 0.5 * (a < b ? b : a));
            if (t % 4 == 0) { lod[2 * t] = 0.0f; lod[2 * t + 1] = (float)rays.radius; }
        }
        if (seed >= 3) {
            o.sides = HFVIS_LK_SIDES_PER_TRIANGLE;
            o.two_sided = two;
        }
        if (seed >= 5) o.lod_range = lod;
        o.seed = (uint64_t)seed;
        bad = three_way(&m, &v, &rays, &o, &n, &blocked, NULL, NULL);
        printf("  soup %d (%zu triangles, N=%d, r=%.1f, falloff %d%s%s): %zu receivers, %.3f blocked, "
               "%ld differ\n", seed, m.triangle_count, rays.count, rays.radius, 1 + seed % 4 % 3,
               seed >= 3 ? ", per-triangle sides" : "", seed >= 5 ? ", LOD windows" : "", n,
               (double)blocked / ((double)n * rays.count), bad);
        CHECK(bad == 0 && blocked > 500);
        { /* explicit random receivers (any points, any normals): Method 2 == ray caster */
            enum { R = 300 };
            double pos[3 * R], nrm[3 * R];
            uint32_t *a2 = (uint32_t *)malloc(sizeof(uint32_t) * R * (size_t)rays.words);
            uint32_t *a3 = (uint32_t *)malloc(sizeof(uint32_t) * R * (size_t)rays.words);
            float ob[R];
            hfvis_lk_receivers rc;
            hfvis_bvh b;
            int i, j;
            for (i = 0; i < R; i++)
                for (j = 0; j < 3; j++) {
                    pos[3 * i + j] = j == 2 ? 1.4 * urand() : 1.6 * srand1();
                    nrm[3 * i + j] = srand1();
                }
            rc.count = R;
            rc.position = pos;
            rc.normal = nrm;
            rc.key = NULL;
            CHECK_EQ_STATUS(hfvis_bvh_build(&m, NULL, &b), HFVIS_OK);
            CHECK_EQ_STATUS(hfvis_lk_bvh(&m, &b, &rays, &rc, &o, a2, ob, NULL), HFVIS_OK);
            CHECK_EQ_STATUS(hfvis_lk_reference(&m, &b, &rays, &rc, &o, a3, NULL, NULL), HFVIS_OK);
            CHECK(memcmp(a2, a3, sizeof(uint32_t) * R * (size_t)rays.words) == 0);
            for (i = 0, j = 0; i < R; i++)
                j += ob[i] != (float)((double)count_bits(a2 + (size_t)i * (size_t)rays.words, rays.words) / rays.count);
            CHECK(j == 0);
            hfvis_bvh_free(NULL, &b);
            free(a2);
            free(a3);
        }
        free(two);
        free(lod);
        tm_free(&tm);
        hfvis_lk_rays_free(NULL, &rays);
    }
}

/* ---------------------------------------------------------------------------------------- */
/* culling never removes an occluder; the paper's far-depth test does ([LK] §4.2, §5; docs/errata.md E39) */
/* ---------------------------------------------------------------------------------------- */

TEST(culling_never_changes_masks)
{
    tmesh tm = {0};
    hfvis_mesh m;
    const double eye[3] = {0.5, -1.1, 0.55}, tgt[3] = {0.5, 0.5, 0.35};
    hfvis_view v = persp(eye, tgt, 55.0, 48, 36);
    hfvis_lk_rays rays = make_rays(64, 0.25, HFVIS_LK_FALLOFF_LINEAR, 41);
    size_t npix = 48 * 36, words = 2, n = 0;
    uint32_t *ref = (uint32_t *)malloc(sizeof(uint32_t) * npix * words);
    uint32_t *got = (uint32_t *)malloc(sizeof(uint32_t) * npix * words);
    uint32_t *r2 = (uint32_t *)malloc(sizeof(uint32_t) * npix * words);
    uint32_t *g2 = (uint32_t *)malloc(sizeof(uint32_t) * npix * words);
    double *pos = (double *)malloc(sizeof(double) * 3 * npix), *nrm = (double *)malloc(sizeof(double) * 3 * npix);
    static const unsigned sets[] = {
        HFVIS_LK_CULL_NONE,
        HFVIS_LK_CULL_ALL & ~HFVIS_LK_CULL_FAR_DEPTH, HFVIS_LK_CULL_ALL & ~HFVIS_LK_CULL_SPHERE,
        HFVIS_LK_CULL_ALL & ~HFVIS_LK_CULL_FACING, HFVIS_LK_CULL_ALL & ~HFVIS_LK_CULL_PLANE,
        HFVIS_LK_CULL_ALL & ~HFVIS_LK_CULL_HORIZON,
        HFVIS_LK_CULL_SET | HFVIS_LK_CULL_FAR_DEPTH, HFVIS_LK_CULL_SET | HFVIS_LK_CULL_SPHERE,
        HFVIS_LK_CULL_SET | HFVIS_LK_CULL_FACING, HFVIS_LK_CULL_SET | HFVIS_LK_CULL_PLANE,
        HFVIS_LK_CULL_SET | HFVIS_LK_CULL_HORIZON};
    hfvis_lk_options o = hfvis_lk_options_default();
    hfvis_lk_receivers rc;
    hfvis_lk_stats st, st_all;
    hfvis_bvh b;
    uint64_t masks_none = 0;
    int q;
    room_scene(&tm, 1);
    soup_scene(&tm, 60, 9); /* add a few random triangles (their floor is outside the room) */
    m = tm_view(&tm);
    CHECK_EQ_STATUS(hfvis_bvh_build(&m, NULL, &b), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_lk_raster(&m, &v, &rays, &o, ref, NULL, &st_all), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_lk_gbuffer_receivers(&m, &v, &o, pos, nrm, NULL, &n), HFVIS_OK);
    rc.count = n;
    rc.position = pos;
    rc.normal = nrm;
    rc.key = NULL;
    /* keys: NULL means the receiver index, so use the same keys in every M2 run */
    CHECK_EQ_STATUS(hfvis_lk_bvh(&m, &b, &rays, &rc, &o, r2, NULL, NULL), HFVIS_OK);
    for (q = 0; q < (int)(sizeof sets / sizeof sets[0]); q++) {
        o.cull = sets[q];
        CHECK_EQ_STATUS(hfvis_lk_raster(&m, &v, &rays, &o, got, NULL, &st), HFVIS_OK);
        CHECK(memcmp(ref, got, sizeof(uint32_t) * npix * words) == 0);
        CHECK(st.masks >= st_all.masks && st.fragments == st_all.fragments);
        if (q == 0) masks_none = st.masks;
        CHECK_EQ_STATUS(hfvis_lk_bvh(&m, &b, &rays, &rc, &o, g2, NULL, NULL), HFVIS_OK);
        CHECK(memcmp(r2, g2, sizeof(uint32_t) * n * words) == 0);
    }
    printf("  Method 1, %zu receivers: %llu fragments; masks computed with every test %llu, with "
           "none %llu (%.2fx); culled: far depth %llu, sphere %llu, facing %llu, plane %llu, "
           "horizon %llu\n", n, (unsigned long long)st_all.fragments, (unsigned long long)st_all.masks,
           (unsigned long long)masks_none, (double)masks_none / (double)st_all.masks,
           (unsigned long long)st_all.culled_far_depth, (unsigned long long)st_all.culled_sphere,
           (unsigned long long)st_all.culled_facing, (unsigned long long)st_all.culled_plane,
           (unsigned long long)st_all.culled_horizon);
    CHECK(st_all.culled_far_depth > 0 && st_all.culled_sphere > 0 && st_all.culled_facing > 0 &&
          st_all.culled_plane > 0 && st_all.culled_horizon > 0);
    /* Method 2 node masks: none / exact */
    o.cull = 0;
    o.node_mask = HFVIS_LK_NODE_NONE;
    CHECK_EQ_STATUS(hfvis_lk_bvh(&m, &b, &rays, &rc, &o, g2, NULL, &st), HFVIS_OK);
    CHECK(memcmp(r2, g2, sizeof(uint32_t) * n * words) == 0);
    o.node_mask = HFVIS_LK_NODE_EXACT;
    CHECK_EQ_STATUS(hfvis_lk_bvh(&m, &b, &rays, &rc, &o, g2, NULL, &st_all), HFVIS_OK);
    printf("  Method 2: nodes visited %llu with exact node masks, %llu with none; culled by "
           "distance %llu, horizon %llu, mask %llu\n", (unsigned long long)st_all.nodes_visited,
           (unsigned long long)st.nodes_visited, (unsigned long long)st_all.nodes_culled_distance,
           (unsigned long long)st_all.nodes_culled_horizon, (unsigned long long)st_all.nodes_culled_mask);
    CHECK(st_all.nodes_visited < st.nodes_visited && st_all.nodes_culled_mask > 0);
    /* obscurance-only calls give popcount/N */
    {
        float *ob = (float *)malloc(sizeof(float) * npix);
        size_t i, diff = 0;
        CHECK_EQ_STATUS(hfvis_lk_raster(&m, &v, &rays, NULL, NULL, ob, NULL), HFVIS_OK);
        for (i = 0; i < npix; i++) {
            int bits = count_bits(ref + i * words, 2);
            if (isnan(ob[i])) diff += bits != 0;
            else diff += ob[i] != (float)((double)bits / 64.0);
        }
        CHECK(diff == 0);
        free(ob);
    }
    hfvis_bvh_free(NULL, &b);
    free(ref); free(got); free(r2); free(g2); free(pos); free(nrm);
    tm_free(&tm);
    hfvis_lk_rays_free(NULL, &rays);
}

TEST(paper_far_depth_test_drops_occluders)
{
    /* A floor and a long wall x = 0.1 facing -x, seen at a grazing angle along the wall from
     * (0, -1, 0.5): behind a floor receiver the eye line leaves the wall's prism far beyond the
     * receiver (depth > receiver depth + r), so the paper's test 1 discards the wall although it
     * blocks the rays toward +x. The safe form (min vertex depth) keeps it. */
    tmesh tm = {0};
    hfvis_mesh m;
    const double eye[3] = {-0.05, -1.0, 0.5}, tgt[3] = {-0.05, 3.0, 0.0};
    hfvis_view v = persp(eye, tgt, 60.0, 40, 40);
    hfvis_lk_rays rays = make_rays(64, 0.3, HFVIS_LK_FALLOFF_CONSTANT, 51);
    hfvis_lk_options o = hfvis_lk_options_default();
    hfvis_lk_stats sp, ss;
    size_t npix = 40 * 40, i, lost = 0, gained = 0;
    float *safe = (float *)malloc(sizeof(float) * npix), *paper = (float *)malloc(sizeof(float) * npix);
    tm_rect(&tm, 2, 0.0, (const double[2]){-3, -1}, (const double[2]){0.1, 12}, 1.0);
    tm_rect(&tm, 0, 0.1, (const double[2]){-1, -1}, (const double[2]){10, 1}, -1.0);
    m = tm_view(&tm);
    CHECK_EQ_STATUS(hfvis_lk_raster(&m, &v, &rays, &o, NULL, safe, &ss), HFVIS_OK);
    o.cull = HFVIS_LK_CULL_ALL | HFVIS_LK_CULL_PAPER_FAR_DEPTH;
    CHECK_EQ_STATUS(hfvis_lk_raster(&m, &v, &rays, &o, NULL, paper, &sp), HFVIS_OK);
    for (i = 0; i < npix; i++) {
        if (isnan(safe[i])) continue;
        lost += paper[i] < safe[i];
        gained += paper[i] > safe[i];
    }
    printf("  grazing wall: the paper's far-depth test culls %llu fragments (safe form: %llu) and "
           "loses occlusion at %zu of the receivers\n", (unsigned long long)sp.culled_far_depth,
           (unsigned long long)ss.culled_far_depth, lost);
    CHECK(lost > 10 && gained == 0);
    free(safe);
    free(paper);
    tm_free(&tm);
    hfvis_lk_rays_free(NULL, &rays);
}

/* ---------------------------------------------------------------------------------------- */
/* LOD windows ([LK] §4.3; docs/errata.md E42)                                               */
/* ---------------------------------------------------------------------------------------- */

TEST(lod_window_identities)
{
    tmesh tm = {0}, tm2 = {0};
    hfvis_mesh m, m2;
    const double eye[3] = {0.5, -1.1, 0.55}, tgt[3] = {0.5, 0.5, 0.35};
    hfvis_view v = persp(eye, tgt, 55.0, 40, 30);
    size_t npix = 40 * 30, t, T;
    int f;
    room_scene(&tm, 1);
    m = tm_view(&tm);
    T = m.triangle_count;
    tm_add(&tm2, &m, 0);
    tm_add(&tm2, &m, 0); /* two copies */
    m2 = tm_view(&tm2);
    for (f = 1; f <= 2; f++) {
        hfvis_lk_rays rays = make_rays(64, 0.25, (hfvis_lk_falloff)f, 61);
        size_t words = 2;
        uint32_t *a = (uint32_t *)malloc(sizeof(uint32_t) * npix * words);
        uint32_t *b = (uint32_t *)malloc(sizeof(uint32_t) * npix * words);
        uint32_t *c = (uint32_t *)malloc(sizeof(uint32_t) * npix * words);
        float *lod1 = (float *)malloc(sizeof(float) * 2 * T);
        float *lod2 = (float *)malloc(sizeof(float) * 4 * T);
        hfvis_lk_options o = hfvis_lk_options_default();
        uint64_t na = 0, nc = 0;
        size_t i;
        /* window [0, r] = no window */
        for (t = 0; t < T; t++) {
            lod1[2 * t] = 0.0f;
            lod1[2 * t + 1] = 0.25f;
        }
        CHECK_EQ_STATUS(hfvis_lk_raster(&m, &v, &rays, &o, a, NULL, NULL), HFVIS_OK);
        o.lod_range = lod1;
        CHECK_EQ_STATUS(hfvis_lk_raster(&m, &v, &rays, &o, b, NULL, NULL), HFVIS_OK);
        CHECK(memcmp(a, b, sizeof(uint32_t) * npix * words) == 0);
        /* two copies with [0, 0.125] and [0.125, r] = one copy */
        for (t = 0; t < T; t++) {
            lod2[2 * t] = 0.0f;
            lod2[2 * t + 1] = 0.125f;
            lod2[2 * (T + t)] = 0.125f;
            lod2[2 * (T + t) + 1] = 0.25f;
        }
        o.lod_range = lod2;
        CHECK_EQ_STATUS(hfvis_lk_raster(&m2, &v, &rays, &o, c, NULL, NULL), HFVIS_OK);
        CHECK(memcmp(a, c, sizeof(uint32_t) * npix * words) == 0);
        /* the near copy alone blocks a subset */
        for (t = 0; t < T; t++) lod2[2 * (T + t) + 1] = 0.125f; /* far copy: empty window */
        CHECK_EQ_STATUS(hfvis_lk_raster(&m2, &v, &rays, &o, c, NULL, NULL), HFVIS_OK);
        for (i = 0; i < npix * words; i++) {
            CHECK((c[i] & ~a[i]) == 0);
            na += (uint64_t)count_bits(a + i, 1);
            nc += (uint64_t)count_bits(c + i, 1);
        }
        CHECK(nc < na && nc > 0);
        printf("  LOD (falloff %d): [0, r] == no window; [0, 0.125] + [0.125, r] copies == one copy; "
               "[0, 0.125] alone blocks %.3f of the rays the full range blocks\n", f, (double)nc / (double)na);
        free(a); free(b); free(c); free(lod1); free(lod2);
        hfvis_lk_rays_free(NULL, &rays);
    }
    tm_free(&tm);
    tm_free(&tm2);
}

/* ---------------------------------------------------------------------------------------- */
/* independent checks: the float watertight caster, LUT modes, the G-buffer, the driver      */
/* ---------------------------------------------------------------------------------------- */

TEST(watertight_caster_and_lut_modes)
{
    tmesh tm = {0};
    hfvis_mesh m;
    const double eye[3] = {0.5, -1.1, 0.55}, tgt[3] = {0.5, 0.5, 0.35};
    hfvis_view v = persp(eye, tgt, 55.0, 48, 36);
    hfvis_lk_rays rays = make_rays(128, 0.2, HFVIS_LK_FALLOFF_CONSTANT, 71);
    hfvis_lk_options o = hfvis_lk_options_default();
    hfvis_lk_lut L;
    size_t npix = 48 * 36, words = 4, n = 0, i;
    double *pos = (double *)malloc(sizeof(double) * 3 * npix), *nrm = (double *)malloc(sizeof(double) * 3 * npix);
    uint64_t *key = (uint64_t *)malloc(sizeof(uint64_t) * npix);
    uint32_t *ex = (uint32_t *)malloc(sizeof(uint32_t) * npix * words);
    uint32_t *wt = (uint32_t *)malloc(sizeof(uint32_t) * npix * words);
    uint32_t *lu = (uint32_t *)malloc(sizeof(uint32_t) * npix * words);
    uint32_t *l1 = (uint32_t *)malloc(sizeof(uint32_t) * npix * words);
    hfvis_lk_receivers rc;
    hfvis_bvh b;
    long diff = 0, dl = 0, lost = 0, total, blocked = 0;
    int sides;
    room_scene(&tm, 2);
    m = tm_view(&tm);
    CHECK_EQ_STATUS(hfvis_bvh_build(&m, NULL, &b), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_lk_gbuffer_receivers(&m, &v, &o, pos, nrm, key, &n), HFVIS_OK);
    rc.count = n;
    rc.position = pos;
    rc.normal = nrm;
    rc.key = key;
    total = (long)n * 128;
    for (sides = 1; sides <= 2; sides++) {
        o.sides = (hfvis_lk_sides)sides;
        o.raycast_test = HFVIS_LK_RAYCAST_EXACT;
        CHECK_EQ_STATUS(hfvis_lk_reference(&m, &b, &rays, &rc, &o, ex, NULL, NULL), HFVIS_OK);
        o.raycast_test = HFVIS_LK_RAYCAST_WATERTIGHT;
        CHECK_EQ_STATUS(hfvis_lk_reference(&m, &b, &rays, &rc, &o, wt, NULL, NULL), HFVIS_OK);
        for (i = 0, diff = 0, blocked = 0; i < n * words; i++) {
            uint32_t x = ex[i] ^ wt[i];
            diff += count_bits(&x, 1);
            blocked += count_bits(ex + i, 1);
        }
        printf("  %s-sided: float watertight caster vs the double predicate: %ld of %ld rays differ "
               "(%ld blocked)\n", sides == 1 ? "one" : "two", diff, total, blocked);
        CHECK((double)diff / (double)total < RATE_WATERTIGHT && blocked > 10000);
    }
    { /* a random soup with per-triangle sides (many back-face hits): explicit receivers */
        enum { R = 400 };
        tmesh sm = {0};
        hfvis_mesh smm;
        hfvis_bvh sb;
        double sp[3 * R], sn[3 * R];
        uint8_t *two;
        hfvis_lk_receivers src;
        size_t t;
        soup_scene(&sm, 500, 4242);
        smm = tm_view(&sm);
        two = (uint8_t *)malloc(smm.triangle_count);
        for (t = 0; t < smm.triangle_count; t++) two[t] = (uint8_t)(t % 2);
        for (i = 0; i < 3 * R; i++) {
            sp[i] = i % 3 == 2 ? 1.2 * urand() : 1.4 * srand1();
            sn[i] = srand1();
        }
        src.count = R;
        src.position = sp;
        src.normal = sn;
        src.key = NULL;
        o = hfvis_lk_options_default();
        o.sides = HFVIS_LK_SIDES_PER_TRIANGLE;
        o.two_sided = two;
        CHECK_EQ_STATUS(hfvis_bvh_build(&smm, NULL, &sb), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_lk_reference(&smm, &sb, &rays, &src, &o, ex, NULL, NULL), HFVIS_OK);
        o.raycast_test = HFVIS_LK_RAYCAST_WATERTIGHT;
        CHECK_EQ_STATUS(hfvis_lk_reference(&smm, &sb, &rays, &src, &o, wt, NULL, NULL), HFVIS_OK);
        for (i = 0, diff = 0, blocked = 0; i < (size_t)R * words; i++) {
            uint32_t x = ex[i] ^ wt[i];
            diff += count_bits(&x, 1);
            blocked += count_bits(ex + i, 1);
        }
        printf("  soup, per-triangle sides: float watertight caster vs the double predicate: %ld of %d "
               "rays differ (%ld blocked)\n", diff, R * 128, blocked);
        CHECK((double)diff / (R * 128.0) < RATE_WATERTIGHT && blocked > 2000);
        hfvis_bvh_free(NULL, &sb);
        free(two);
        tm_free(&sm);
        o = hfvis_lk_options_default();
    }
    /* LUT masks in Methods 1 and 2 (T = 64): close to exact, not identical */
    o = hfvis_lk_options_default();
    CHECK_EQ_STATUS(hfvis_lk_lut_build(&rays, 64, NULL, &L), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_lk_reference(&m, &b, &rays, &rc, &o, ex, NULL, NULL), HFVIS_OK);
    o.mask_mode = HFVIS_LK_MASK_LUT;
    o.lut = &L;
    CHECK_EQ_STATUS(hfvis_lk_bvh(&m, &b, &rays, &rc, &o, lu, NULL, NULL), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_lk_raster(&m, &v, &rays, &o, l1, NULL, NULL), HFVIS_OK);
    for (i = 0, diff = 0; i < n; i++) {
        int w;
        for (w = 0; w < 4; w++) {
            uint32_t x = ex[i * words + (size_t)w] ^ lu[i * words + (size_t)w];
            uint32_t y = ex[i * words + (size_t)w] ^ l1[key[i] * words + (size_t)w];
            diff += count_bits(&x, 1);
            dl += count_bits(&y, 1);
        }
    }
    printf("  LUT masks (T=64): Method 2 differs from exact in %.4f of the rays, Method 1 in %.4f\n",
           (double)diff / (double)total, (double)dl / (double)total);
    CHECK((double)diff / (double)total < 0.02 && (double)dl / (double)total < 0.02);
    /* the paper's circular node masks (table): quantised, may only lose rays */
    o.mask_mode = HFVIS_LK_MASK_EXACT;
    o.node_mask = HFVIS_LK_NODE_SPHERE_LUT;
    CHECK_EQ_STATUS(hfvis_lk_bvh(&m, &b, &rays, &rc, &o, lu, NULL, NULL), HFVIS_OK);
    for (i = 0, diff = 0; i < n * words; i++) {
        uint32_t x = lu[i] & ~ex[i], y = ex[i] & ~lu[i];
        diff += count_bits(&x, 1);
        lost += count_bits(&y, 1);
    }
    printf("  circular LUT node masks: %ld rays lost of %ld (%.5f), %ld gained\n", lost, total,
           (double)lost / (double)total, diff);
    CHECK(diff == 0 && (double)lost / (double)total < 0.01);
    hfvis_lk_lut_free(NULL, &L);
    hfvis_bvh_free(NULL, &b);
    free(pos); free(nrm); free(key); free(ex); free(wt); free(lu); free(l1);
    tm_free(&tm);
    hfvis_lk_rays_free(NULL, &rays);
}

TEST(gbuffer_receivers_and_image_driver)
{
    tmesh tm = {0};
    hfvis_mesh m;
    const double eye[3] = {0.5, -1.1, 0.55}, tgt[3] = {0.5, 0.5, 0.35};
    hfvis_view v = persp(eye, tgt, 55.0, 40, 30);
    hfvis_lk_rays rays = make_rays(64, 0.2, HFVIS_LK_FALLOFF_CONSTANT, 81);
    size_t npix = 40 * 30, n = 0, i, off = 0, facing = 0, order = 0;
    double pos[3 * 40 * 30], nrm[3 * 40 * 30];
    uint64_t key[40 * 30];
    uint32_t ids[40 * 30], m1[40 * 30 * 2], m2[40 * 30 * 2], m3[40 * 30 * 2];
    float o1[40 * 30], o2[40 * 30], o3[40 * 30];
    hfvis_raster_outputs ro;
    int meth, ok = 1;
    room_scene(&tm, 1);
    m = tm_view(&tm);
    memset(&ro, 0, sizeof ro);
    ro.triangle_id = ids;
    CHECK_EQ_STATUS(hfvis_rasterize(&m, &v, NULL, &ro), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_lk_gbuffer_receivers(&m, &v, NULL, pos, nrm, key, &n), HFVIS_OK);
    {
        size_t covered = 0, k = 0;
        for (i = 0; i < npix; i++) covered += ids[i] != HFVIS_NO_TRIANGLE;
        CHECK(covered == n);
        for (i = 0; i < npix; i++) {
            const float *a, *b, *c;
            double u[3], w[3], nn[3], len, h, to_eye;
            int j;
            if (ids[i] == HFVIS_NO_TRIANGLE) continue;
            order += key[k] != (uint64_t)i;
            a = m.xyz + 3 * m.indices[3 * ids[i]];
            b = m.xyz + 3 * m.indices[3 * ids[i] + 1];
            c = m.xyz + 3 * m.indices[3 * ids[i] + 2];
            for (j = 0; j < 3; j++) {
                u[j] = (double)b[j] - (double)a[j];
                w[j] = (double)c[j] - (double)a[j];
            }
            nn[0] = u[1] * w[2] - u[2] * w[1];
            nn[1] = u[2] * w[0] - u[0] * w[2];
            nn[2] = u[0] * w[1] - u[1] * w[0];
            len = sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
            h = 0.0;
            to_eye = 0.0;
            for (j = 0; j < 3; j++) {
                h += nn[j] / len * (pos[3 * k + j] - (double)a[j]);
                to_eye += nrm[3 * k + j] * (eye[j] - pos[3 * k + j]);
            }
            off += fabs(h) > TOL_ON_PLANE;
            facing += !(to_eye > 0.0);
            k++;
        }
    }
    CHECK(off == 0 && facing == 0 && order == 0);
    /* hfvis_lk_image: the three methods give the same per-pixel masks and obscurance */
    for (meth = 1; meth <= 3; meth++) {
        uint32_t *mm = meth == 1 ? m1 : meth == 2 ? m2 : m3;
        float *oo = meth == 1 ? o1 : meth == 2 ? o2 : o3;
        CHECK_EQ_STATUS(hfvis_lk_image((hfvis_lk_method)meth, &m, NULL, &v, &rays, NULL, mm, oo, NULL), HFVIS_OK);
    }
    CHECK(memcmp(m1, m2, sizeof m1) == 0 && memcmp(m1, m3, sizeof m1) == 0);
    for (i = 0; i < npix; i++) {
        if (ids[i] == HFVIS_NO_TRIANGLE) ok &= isnan(o1[i]) && isnan(o2[i]) && isnan(o3[i]);
        else ok &= o1[i] == o2[i] && o1[i] == o3[i] && o1[i] >= 0.0f && o1[i] <= 1.0f;
    }
    CHECK(ok);
    CHECK_EQ_STATUS(hfvis_lk_image((hfvis_lk_method)0, &m, NULL, &v, &rays, NULL, m1, o1, NULL),
                    HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_image(HFVIS_LK_METHOD_BVH, &m, NULL, &v, &rays, NULL, NULL, NULL, NULL),
                    HFVIS_ERR_INVALID_ARGUMENT);
    tm_free(&tm);
    hfvis_lk_rays_free(NULL, &rays);
}

/* ---------------------------------------------------------------------------------------- */
/* options, bad arguments, failing allocators                                                */
/* ---------------------------------------------------------------------------------------- */

TEST(options_resolve)
{
    hfvis_lk_options in = hfvis_lk_options_default(), out, zero;
    hfvis_lk_lut L;
    memset(&zero, 0, sizeof zero);
    CHECK_EQ_STATUS(hfvis_lk_options_resolve(NULL, 2.0, &out), HFVIS_OK);
    CHECK(out.mask_mode == HFVIS_LK_MASK_EXACT && out.node_mask == HFVIS_LK_NODE_EXACT &&
          out.cull == HFVIS_LK_CULL_ALL && out.sides == HFVIS_LK_SIDES_ONE &&
          out.epsilon == HFVIS_LK_DEFAULT_EPSILON * 2.0 && out.alpha == HFVIS_LK_DEFAULT_ALPHA &&
          out.rotation_max_rad == PI && out.tilt_max_rad == HFVIS_LK_DEFAULT_TILT &&
          out.volume == HFVIS_LK_VOLUME_AUTO && out.raycast_test == HFVIS_LK_RAYCAST_EXACT);
    CHECK_EQ_STATUS(hfvis_lk_options_resolve(&zero, 2.0, &out), HFVIS_OK);
    CHECK(out.cull == HFVIS_LK_CULL_ALL && out.epsilon == 2e-5);
    in.cull = HFVIS_LK_CULL_SPHERE; /* flags without HFVIS_LK_CULL_SET */
    CHECK_EQ_STATUS(hfvis_lk_options_resolve(&in, 1.0, &out), HFVIS_ERR_INVALID_ARGUMENT);
    in.cull = HFVIS_LK_CULL_SET | 0x40u;
    CHECK_EQ_STATUS(hfvis_lk_options_resolve(&in, 1.0, &out), HFVIS_ERR_INVALID_ARGUMENT);
    in = hfvis_lk_options_default();
    in.mask_mode = HFVIS_LK_MASK_LUT; /* without a table */
    CHECK_EQ_STATUS(hfvis_lk_options_resolve(&in, 1.0, &out), HFVIS_ERR_INVALID_ARGUMENT);
    memset(&L, 0, sizeof L);
    in.lut = &L;
    CHECK_EQ_STATUS(hfvis_lk_options_resolve(&in, 1.0, &out), HFVIS_ERR_INVALID_ARGUMENT);
    in = hfvis_lk_options_default();
    in.sides = HFVIS_LK_SIDES_PER_TRIANGLE;
    CHECK_EQ_STATUS(hfvis_lk_options_resolve(&in, 1.0, &out), HFVIS_ERR_INVALID_ARGUMENT);
    in = hfvis_lk_options_default();
    in.epsilon = -1.0;
    CHECK_EQ_STATUS(hfvis_lk_options_resolve(&in, 1.0, &out), HFVIS_ERR_INVALID_ARGUMENT);
    in.epsilon = (double)NAN;
    CHECK_EQ_STATUS(hfvis_lk_options_resolve(&in, 1.0, &out), HFVIS_ERR_INVALID_ARGUMENT);
    in = hfvis_lk_options_default();
    in.alpha = -0.2;
    CHECK_EQ_STATUS(hfvis_lk_options_resolve(&in, 1.0, &out), HFVIS_ERR_INVALID_ARGUMENT);
    in = hfvis_lk_options_default();
    in.node_mask = (hfvis_lk_node_mask)9;
    CHECK_EQ_STATUS(hfvis_lk_options_resolve(&in, 1.0, &out), HFVIS_ERR_INVALID_ARGUMENT);
    in = hfvis_lk_options_default();
    in.volume = (hfvis_lk_volume)9;
    CHECK_EQ_STATUS(hfvis_lk_options_resolve(&in, 1.0, &out), HFVIS_ERR_INVALID_ARGUMENT);
    in = hfvis_lk_options_default();
    in.gbuffer_cull = (hfvis_cull_mode)9;
    CHECK_EQ_STATUS(hfvis_lk_options_resolve(&in, 1.0, &out), HFVIS_ERR_INVALID_ARGUMENT);
    in = hfvis_lk_options_default();
    in.raycast_test = (hfvis_lk_raycast_test)9;
    CHECK_EQ_STATUS(hfvis_lk_options_resolve(&in, 1.0, &out), HFVIS_ERR_INVALID_ARGUMENT);
    in = hfvis_lk_options_default();
    in.jitter = HFVIS_LK_JITTER_CUSTOM;
    in.rotation_max_rad = 5.0;
    CHECK_EQ_STATUS(hfvis_lk_options_resolve(&in, 1.0, &out), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_options_resolve(NULL, 0.0, &out), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_options_resolve(NULL, 1.0, NULL), HFVIS_ERR_INVALID_ARGUMENT);
}

TEST(methods_bad_args)
{
    tmesh tm = {0};
    hfvis_mesh m, bad_mesh;
    hfvis_lk_rays rays = make_rays(32, 0.2, HFVIS_LK_FALLOFF_CONSTANT, 91), bad_rays;
    const double eye[3] = {0.5, -1.1, 0.55}, tgt[3] = {0.5, 0.5, 0.35};
    hfvis_view v = persp(eye, tgt, 55.0, 8, 6), bv;
    hfvis_bvh b, bb;
    hfvis_lk_options o = hfvis_lk_options_default();
    hfvis_lk_receivers rc;
    hfvis_lk_stats st;
    double p[6] = {0.5, 0.5, 0.0, 0.5, 0.5, 0.5}, n[6] = {0, 0, 1, 0, 0, 1};
    uint32_t masks[48], keep[48];
    float ob[48], *lod;
    size_t cnt = 77, i;
    int bad;
    room_scene(&tm, 1);
    m = tm_view(&tm);
    CHECK_EQ_STATUS(hfvis_bvh_build(&m, NULL, &b), HFVIS_OK);
    rc.count = 2;
    rc.position = p;
    rc.normal = n;
    rc.key = NULL;
    memset(masks, 0xAB, sizeof masks);
    memcpy(keep, masks, sizeof masks);
    memset(&st, 0xCD, sizeof st);
    /* NULLs and both outputs NULL */
    CHECK_EQ_STATUS(hfvis_lk_raster(NULL, &v, &rays, NULL, masks, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_raster(&m, NULL, &rays, NULL, masks, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_raster(&m, &v, NULL, NULL, masks, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_raster(&m, &v, &rays, NULL, NULL, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_bvh(NULL, &b, &rays, &rc, NULL, masks, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_bvh(&m, NULL, &rays, &rc, NULL, masks, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_bvh(&m, &b, &rays, NULL, NULL, masks, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_bvh(&m, &b, &rays, &rc, NULL, NULL, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_reference(&m, &b, NULL, &rc, NULL, masks, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_reference(&m, &b, &rays, &rc, NULL, NULL, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_gbuffer_receivers(&m, &v, NULL, NULL, n, NULL, &cnt), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_gbuffer_receivers(&m, &v, NULL, p, n, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    /* invalid ray set */
    bad_rays = rays;
    bad_rays.words = 3;
    CHECK_EQ_STATUS(hfvis_lk_bvh(&m, &b, &bad_rays, &rc, NULL, masks, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
    bad_rays = rays;
    bad_rays.radius = -1.0;
    CHECK_EQ_STATUS(hfvis_lk_raster(&m, &v, &bad_rays, NULL, masks, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
    /* invalid mesh: index out of range, non-finite vertex */
    bad_mesh = m;
    bad_mesh.vertex_count = 2;
    CHECK_EQ_STATUS(hfvis_lk_raster(&bad_mesh, &v, &rays, NULL, masks, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_bvh(&bad_mesh, &b, &rays, &rc, NULL, masks, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
    tm.xyz[4] = (float)NAN;
    CHECK_EQ_STATUS(hfvis_lk_reference(&m, &b, &rays, &rc, NULL, masks, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
    tm.xyz[4] = 0.0f;
    /* receivers: NaN position, zero normal */
    p[0] = (double)NAN;
    CHECK_EQ_STATUS(hfvis_lk_bvh(&m, &b, &rays, &rc, NULL, masks, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
    p[0] = 0.5;
    n[5] = 0.0;
    n[3] = 0.0;
    n[4] = 0.0;
    CHECK_EQ_STATUS(hfvis_lk_reference(&m, &b, &rays, &rc, NULL, masks, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
    n[5] = 1.0;
    /* view: zero size, non-finite matrix */
    bv = v;
    bv.width = 0;
    CHECK_EQ_STATUS(hfvis_lk_raster(&m, &bv, &rays, NULL, masks, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
    bv = v;
    bv.proj[5] = (double)INFINITY;
    CHECK_EQ_STATUS(hfvis_lk_raster(&m, &bv, &rays, NULL, masks, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_image(HFVIS_LK_METHOD_BVH, &m, NULL, &bv, &rays, NULL, masks, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
    bv = v;
    bv.width = HFVIS_RASTER_MAX_SIZE + 1;
    CHECK_EQ_STATUS(hfvis_lk_raster(&m, &bv, &rays, NULL, masks, NULL, &st), HFVIS_ERR_LIMIT);
    /* options: bad enum, LOD beyond the radius, negative window */
    o.mask_mode = (hfvis_lk_mask_mode)7;
    CHECK_EQ_STATUS(hfvis_lk_raster(&m, &v, &rays, &o, masks, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
    o = hfvis_lk_options_default();
    lod = (float *)malloc(sizeof(float) * 2 * m.triangle_count);
    for (i = 0; i < 2 * m.triangle_count; i++) lod[i] = i % 2 ? 0.25f : 0.0f;
    o.lod_range = lod;
    CHECK_EQ_STATUS(hfvis_lk_bvh(&m, &b, &rays, &rc, &o, masks, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
    lod[1] = 0.1f;
    lod[0] = 0.15f;
    CHECK_EQ_STATUS(hfvis_lk_raster(&m, &v, &rays, &o, masks, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
    free(lod);
    o = hfvis_lk_options_default();
    /* BVH of another mesh, corrupted BVH */
    bb = b;
    bb.triangle_count = b.triangle_count - 1;
    CHECK_EQ_STATUS(hfvis_lk_bvh(&m, &bb, &rays, &rc, NULL, masks, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
    {
        hfvis_bvh_node *nodes = (hfvis_bvh_node *)malloc(sizeof(hfvis_bvh_node) * b.node_count);
        memcpy(nodes, b.nodes, sizeof(hfvis_bvh_node) * b.node_count);
        bb = b;
        bb.nodes = nodes;
        nodes[0].left_or_first = 0; /* child not after its parent (a cycle) */
        CHECK_EQ_STATUS(hfvis_lk_reference(&m, &bb, &rays, &rc, NULL, masks, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
        memcpy(nodes, b.nodes, sizeof(hfvis_bvh_node) * b.node_count);
        for (i = 0; i < b.node_count && nodes[i].count == 0; i++) {}
        nodes[i].left_or_first = (uint32_t)b.triangle_count; /* leaf range past tri_order */
        CHECK_EQ_STATUS(hfvis_lk_bvh(&m, &bb, &rays, &rc, NULL, masks, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
        memcpy(nodes, b.nodes, sizeof(hfvis_bvh_node) * b.node_count);
        nodes[0].lo[1] = (float)NAN;
        CHECK_EQ_STATUS(hfvis_lk_bvh(&m, &bb, &rays, &rc, NULL, masks, NULL, &st), HFVIS_ERR_INVALID_ARGUMENT);
        free(nodes);
    }
    CHECK(memcmp(masks, keep, sizeof masks) == 0); /* untouched by every failed call */
    {
        unsigned char *raw = (unsigned char *)&st;
        for (i = 0, bad = 0; i < sizeof st; i++) bad += raw[i] != 0xCD;
        CHECK(bad == 0);
    }
    CHECK(cnt == 77);
    /* a mesh without triangles: nothing blocks (empty BVH) */
    {
        hfvis_mesh empty;
        hfvis_bvh eb;
        memset(&empty, 0, sizeof empty);
        CHECK_EQ_STATUS(hfvis_bvh_build(&empty, NULL, &eb), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_lk_bvh(&empty, &eb, &rays, &rc, NULL, masks, ob, NULL), HFVIS_OK);
        CHECK(masks[0] == 0 && ob[0] == 0.0f && ob[1] == 0.0f);
        CHECK_EQ_STATUS(hfvis_lk_reference(&empty, &eb, &rays, &rc, NULL, masks, ob, NULL), HFVIS_OK);
        CHECK(masks[1] == 0 && ob[1] == 0.0f);
        hfvis_bvh_free(NULL, &eb);
    }
    hfvis_bvh_free(NULL, &b);
    tm_free(&tm);
    hfvis_lk_rays_free(NULL, &rays);
}

/* Sweep: allocation k fails for k = 1.. until the call succeeds; every failure returns
 * HFVIS_ERR_OUT_OF_MEMORY with outputs untouched and nothing leaked. */
TEST(methods_alloc_failures)
{
    tmesh tm = {0};
    hfvis_mesh m;
    const double eye[3] = {0.5, -1.1, 0.55}, tgt[3] = {0.5, 0.5, 0.35};
    hfvis_view v = persp(eye, tgt, 55.0, 12, 10);
    hfvis_lk_rays rays = make_rays(40, 0.2, HFVIS_LK_FALLOFF_CONSTANT, 93);
    hfvis_bvh b;
    double pos[3 * 120], nrm[3 * 120];
    size_t cnt = 0;
    int which;
    room_scene(&tm, 1);
    m = tm_view(&tm);
    CHECK_EQ_STATUS(hfvis_bvh_build(&m, NULL, &b), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_lk_gbuffer_receivers(&m, &v, NULL, pos, nrm, NULL, &cnt), HFVIS_OK);
    for (which = 0; which < 7; which++) {
        int k, done = 0, fails = 0;
        for (k = 1; k <= 20 && !done; k++) {
            test_counting c = {0, 0, 0, 0, 0};
            hfvis_allocator al = {test_count_alloc, test_count_free, NULL};
            hfvis_lk_options o = hfvis_lk_options_default();
            hfvis_lk_receivers rc;
            uint32_t masks[120 * 2];
            float ob[120];
            size_t got = 999, i;
            double gp[3 * 120], gn[3 * 120];
            hfvis_status s;
            int touched = 0;
            al.user = &c;
            c.fail_at = k;
            o.alloc = &al;
            rc.count = cnt;
            rc.position = pos;
            rc.normal = nrm;
            rc.key = NULL;
            memset(masks, 0x5A, sizeof masks);
            memset(ob, 0x5A, sizeof ob);
            switch (which) {
            case 0: s = hfvis_lk_raster(&m, &v, &rays, &o, masks, ob, NULL); break;
            case 1: s = hfvis_lk_raster(&m, &v, &rays, &o, NULL, ob, NULL); break;
            case 2: s = hfvis_lk_bvh(&m, &b, &rays, &rc, &o, masks, ob, NULL); break;
            case 3: s = hfvis_lk_reference(&m, &b, &rays, &rc, &o, masks, ob, NULL); break;
            case 4: s = hfvis_lk_image(HFVIS_LK_METHOD_BVH, &m, NULL, &v, &rays, &o, masks, ob, NULL); break;
            case 5: s = hfvis_lk_image(HFVIS_LK_METHOD_RAYCAST, &m, &b, &v, &rays, &o, NULL, ob, NULL); break;
            default: s = hfvis_lk_gbuffer_receivers(&m, &v, &o, gp, gn, NULL, &got); break;
            }
            for (i = 0; i < sizeof masks / sizeof masks[0]; i++) touched += masks[i] != 0x5A5A5A5Au;
            if (s == HFVIS_OK) {
                done = 1;
            } else {
                fails++;
                CHECK_EQ_STATUS(s, HFVIS_ERR_OUT_OF_MEMORY);
                CHECK(touched == 0 && got == 999);
                {
                    unsigned char *raw = (unsigned char *)ob;
                    size_t j;
                    int t2 = 0;
                    for (j = 0; j < sizeof ob; j++) t2 += raw[j] != 0x5A;
                    CHECK(t2 == 0);
                }
            }
            CHECK(c.live == 0 && c.allocs >= 1);
        }
        CHECK(done && fails >= 1);
        printf("  call %d: %d allocation failures swept\n", which, fails);
    }
    hfvis_bvh_free(NULL, &b);
    tm_free(&tm);
    hfvis_lk_rays_free(NULL, &rays);
}

int main(int argc, char **argv)
{
    TEST_INIT(argc, argv);
    if (argc > 1 && !strcmp(argv[1], "bad")) { RUN(methods_bad_args); return TEST_DONE(); }
    RUN(rays_lloyd_set);
    RUN(rays_falloff_lengths);
    RUN(rays_custom_and_bad_args);
    RUN(rays_alloc_failures);
    RUN(frame_orthonormal_and_jitter);
    RUN(triangle_mask_vs_ray_oracle);
    RUN(plane_mask_and_lut);
    RUN(two_sided_is_or_of_flipped_pair);
    RUN(triangle_mask_bad_args);
    RUN(analytic_empty_and_parallel_plane);
    RUN(analytic_linear_falloff);
    RUN(analytic_wall_and_trench);
    RUN(analytic_closed_box);
    RUN(default_pattern_converges_to_cosine_caster);
    RUN(three_methods_identical_on_meshes);
    RUN(three_methods_identical_on_soups);
    RUN(culling_never_changes_masks);
    RUN(paper_far_depth_test_drops_occluders);
    RUN(lod_window_identities);
    RUN(watertight_caster_and_lut_modes);
    RUN(gbuffer_receivers_and_image_driver);
    RUN(options_resolve);
    RUN(methods_bad_args);
    RUN(methods_alloc_failures);
    return TEST_DONE();
}
