/* test_vf.c - 4D visibility fields ([G12] ch. 4, spec voxel §1): positional samples, direction
 * maps, the build against its naive oracle, the exact sphere-in-sphere maps, queries and AO /
 * shadows / reflections against ray casting, the file codec, bad arguments and failing
 * allocations. Prints the thesis-style error tables (hit/miss disagreement, mean distance error,
 * AO RMS on the 8-bit scale) at a reduced (K, D) grid; the bench prints the full grid. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hfvis.h"
#include "test.h"

#define PI 3.14159265358979323846

/* ---- tolerances (each with its reason) -------------------------------------------------- */
#define TOL_UNIT 1e-15          /* |u_k| - 1: one division by an exact integer square root */
#define TOL_FRAME 1e-14         /* orthonormality of the Duff frame: a few roundings */
#define TOL_DISK 1e-14          /* concentric map radius = max(|A|,|B|): cos/sin rounding */
#define TOL_SQUARE 1e-12        /* square -> disk -> square round trip: atan2 + division */
#define TOL_Q_SPHERE 1          /* 8-bit code vs the analytic sphere: the icosphere's faces lie up
                                   to 4e-4 R inside the sphere (0.05 LSB) plus rounding ties */
#define TOL_NORMAL_DEG 3.0      /* NORMAL-format normal of the icosphere vs the radial direction:
                                   face tilt (<= 2.3 deg at subdivision 4) + 8-bit quantisation */
#define TOL_F32_U8 1            /* u8 code vs the code of the stored float: float rounding can
                                   cross a code boundary */
#define TOL_SNAP_EXACT (1.0 / 254.0 + 1e-6) /* query exactly on a sample and texel centre: only
                                   the 8-bit step (R/127 over 2R, half of it, x2 for safety) */
#define TOL_AO_SAME_RAYS 0.035  /* VF vs ray-cast AO with the same 256 rays (sphere, K = 1090,
                                   D = 32): snapping flips ~ a few rays on the silhouette */
#define TOL_AO_ESTIMATOR 0.012  /* 64 x 64 concentric rays vs the closed-form form factor:
                                   stratified estimator error on a sphere's silhouette */
#define TOL_AO_CONVEX 0.02      /* intra-object AO on a convex sphere (no self-occlusion): rays
                                   grazing the tangent plane can be mis-snapped */
#define TOL_WALL_VF 0.1         /* VF AO next to a large wall: R x covering angle is comparable to
                                   the receiver's distance (the thesis' elongated-object limit) */

/* ---- PRNG (splitmix64) and helpers ------------------------------------------------------- */
static uint64_t rng_state = 1;
static uint64_t rng_next(void)
{
    uint64_t z = (rng_state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}
static double rng_unit(void) { return (double)(rng_next() >> 11) * (1.0 / 9007199254740992.0); }
static void rng_dir(double d[3])
{
    double z = 2.0 * rng_unit() - 1.0, ph = 2.0 * PI * rng_unit(), s = sqrt(1.0 - z * z);
    d[0] = s * cos(ph);
    d[1] = s * sin(ph);
    d[2] = z;
}
static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* Counting allocator: fail_at = the 1-based allocation that fails (0 = never). */
typedef struct counting {
    int allocs, frees, live, fail_at;
} counting;
static void *c_alloc(void *user, size_t n)
{
    counting *c = (counting *)user;
    void *p;
    c->allocs++;
    if (c->fail_at != 0 && c->allocs == c->fail_at) return NULL;
    p = malloc(n);
    if (p) c->live++;
    return p;
}
static void c_free(void *user, void *p)
{
    counting *c = (counting *)user;
    if (!p) return;
    c->frees++;
    c->live--;
    free(p);
}

/* A field with malloc'ed maps (parameters set, not built). */
static int field_init(hfvis_visfield *vf, const double c[3], double R, int n, int D,
                      hfvis_dirmap m, hfvis_visfield_format f)
{
    memset(vf, 0, sizeof *vf);
    vf->center[0] = c[0];
    vf->center[1] = c[1];
    vf->center[2] = c[2];
    vf->radius = R;
    vf->positions_n = n;
    vf->dir_res = D;
    vf->mapping = m;
    vf->format = f;
    vf->maps_size = hfvis_visfield_size(n, D, f);
    vf->maps = malloc(vf->maps_size);
    return vf->maps != NULL;
}
static void field_done(hfvis_visfield *vf)
{
    free(vf->maps);
    vf->maps = NULL;
}

static void identity(double m[16])
{
    int i;
    for (i = 0; i < 16; i++) m[i] = (i % 5 == 0) ? 1.0 : 0.0;
}

/* ========================================================================================== */
/* samples, frames, maps, sizes                                                               */
/* ========================================================================================== */

TEST(vf_counts)
{
    static const int ns[5] = {4, 8, 16, 32, 64};
    static const size_t ks[5] = {82, 290, 1090, 4226, 16642}; /* thesis: 80 (misprint), 290, ... */
    int i, n;
    for (i = 0; i < 5; i++) CHECK(hfvis_visfield_position_count(ns[i]) == ks[i]);
    CHECK(hfvis_visfield_position_count(0) == 0);
    CHECK(hfvis_visfield_position_count(-3) == 0);
    CHECK(hfvis_visfield_position_count(HFVIS_VISFIELD_MAX_N + 1) == 0);
    CHECK(hfvis_visfield_position_count(1) == 10);
    for (n = 1; n <= 20; n++) {
        size_t K = hfvis_visfield_position_count(n), k, self = 0, upper = 0, bad = 0, eq = 0;
        for (k = 0; k < K; k++) {
            double u[3], len;
            size_t back, naive;
            CHECK_EQ_STATUS(hfvis_visfield_position(n, k, u), HFVIS_OK);
            len = sqrt(dot3(u, u));
            if (fabs(len - 1.0) > TOL_UNIT) bad++;
            if ((k < K / 2) != (u[2] >= 0.0) && u[2] != 0.0) bad++;
            CHECK_EQ_STATUS(hfvis_visfield_nearest_position(n, u, &back), HFVIS_OK);
            CHECK_EQ_STATUS(hfvis_visfield_nearest_position_naive(n, u, &naive), HFVIS_OK);
            if (back != naive) bad++;
            if (back == k) self++;
            else if (k >= K / 2 && u[2] == 0.0 && back == k - K / 2) { upper++; }
            else bad++;
            if (u[2] == 0.0 && k < K / 2) eq++;
        }
        CHECK(bad == 0);
        CHECK(eq == (size_t)(4 * n));            /* equator ring: 4n points */
        CHECK(upper == (size_t)(4 * n));         /* lower equator copies map to the upper ones */
        CHECK(self + upper == K);
    }
}

TEST(vf_nearest_matches_naive)
{
    static const int ns[10] = {1, 2, 3, 4, 5, 7, 8, 12, 16, 32};
    static const int counts[10] = {100000, 100000, 100000, 100000, 100000, 100000, 100000,
                                   60000, 40000, 15000};
    int t, mism = 0, total = 0;
    rng_state = 7;
    for (t = 0; t < 10; t++) {
        int n = ns[t], c;
        double cover = 0.0;
        size_t K = hfvis_visfield_position_count(n);
        for (c = 0; c < counts[t]; c++) {
            double q[3], u[3];
            size_t a, b;
            int kind = c % 4;
            if (kind == 0) {
                rng_dir(q);
            } else if (kind == 1) { /* the midpoint of two random nearby samples (a Voronoi edge) */
                double v[3], w[3];
                size_t k1 = (size_t)(rng_next() % K), k2;
                hfvis_visfield_position(n, k1, v);
                rng_dir(w);
                q[0] = v[0] + 0.6 * w[0] / n;
                q[1] = v[1] + 0.6 * w[1] / n;
                q[2] = v[2] + 0.6 * w[2] / n;
                hfvis_visfield_nearest_position_naive(n, q, &k2);
                hfvis_visfield_position(n, k2, w);
                q[0] = v[0] + w[0];
                q[1] = v[1] + w[1];
                q[2] = v[2] + w[2];
                if (q[0] == 0.0 && q[1] == 0.0 && q[2] == 0.0) q[2] = 1.0;
            } else if (kind == 2) { /* on the equator, on the coordinate planes, +-0 z */
                double ph = 2.0 * PI * rng_unit();
                q[0] = cos(ph);
                q[1] = sin(ph);
                q[2] = (c & 8) ? -0.0 : 0.0;
                if (c & 16) q[(c >> 5) % 2] = 0.0;
                if (q[0] == 0.0 && q[1] == 0.0) q[0] = 1.0;
            } else { /* near the octahedron's edges and vertices, scaled */
                rng_dir(q);
                q[(int)(rng_next() % 3)] *= 1e-9;
                q[0] *= 1e3;
                q[1] *= 1e3;
                q[2] *= 1e3;
            }
            CHECK_EQ_STATUS(hfvis_visfield_nearest_position(n, q, &a), HFVIS_OK);
            CHECK_EQ_STATUS(hfvis_visfield_nearest_position_naive(n, q, &b), HFVIS_OK);
            if (a != b) { double ua[3], ub[3]; hfvis_visfield_position(n, a, ua); hfvis_visfield_position(n, b, ub);
                if (mism < 12) printf("MISM n=%d kind=%d q=(%.17g %.17g %.17g) fast %zu (%.5f %.5f %.5f) %.17g naive %zu (%.5f %.5f %.5f) %.17g\n", n, kind, q[0], q[1], q[2], a, ua[0], ua[1], ua[2], dot3(q, ua), b, ub[0], ub[1], ub[2], dot3(q, ub));
                mism++; }
            if (kind == 0) {
                double len = sqrt(dot3(q, q)), ang;
                hfvis_visfield_position(n, a, u);
                ang = acos(fmin(1.0, dot3(q, u) / len));
                if (ang > cover) cover = ang;
            }
            total++;
        }
        printf("  n = %2d, K = %5zu: sampled covering radius %.3f deg (%.1f deg / n)\n", n, K,
               cover * 180.0 / PI, cover * 180.0 / PI * n);
    }
    printf("  nearest sample: %d of %d directions differ from the brute force\n", mism, total);
    CHECK(mism == 0);
}

TEST(vf_frame)
{
    int c, bad = 0;
    rng_state = 11;
    for (c = 0; c < 20000; c++) {
        double w[3], t[3], b[3], x[3];
        if (c < 4) {
            w[0] = w[1] = 0.0;
            w[2] = (c & 1) ? -1.0 : 1.0;
            if (c >= 2) w[2] = (c & 1) ? -0.0 : 0.0, w[0] = 1.0;
        } else {
            rng_dir(w);
        }
        hfvis_visfield_frame(w, t, b);
        x[0] = t[1] * b[2] - t[2] * b[1];
        x[1] = t[2] * b[0] - t[0] * b[2];
        x[2] = t[0] * b[1] - t[1] * b[0];
        if (fabs(dot3(t, t) - 1.0) > TOL_FRAME || fabs(dot3(b, b) - 1.0) > TOL_FRAME
            || fabs(dot3(t, b)) > TOL_FRAME || fabs(dot3(t, w)) > TOL_FRAME
            || fabs(dot3(b, w)) > TOL_FRAME || fabs(dot3(x, w) - 1.0) > TOL_FRAME)
            bad++;
    }
    CHECK(bad == 0);
}

TEST(vf_dirmaps)
{
    static const int Ds[9] = {1, 2, 3, 5, 8, 32, 64, 255, 512};
    int t, m, bad = 0, c;
    for (m = 1; m <= 3; m++)
        for (t = 0; t < 9; t++) {
            int D = Ds[t], i, j, unused = 0;
            for (j = 0; j < D; j++)
                for (i = 0; i < D; i++) {
                    double l[3], l2[3], len;
                    int used, ii, jj, u2;
                    CHECK_EQ_STATUS(hfvis_dirmap_to_local((hfvis_dirmap)m, D, i, j, l, &used), HFVIS_OK);
                    if (!used) {
                        unused++;
                        if (m != HFVIS_DIRMAP_REJECTION) bad++;
                        continue;
                    }
                    len = sqrt(dot3(l, l));
                    if (fabs(len - 1.0) > TOL_FRAME || l[2] < 0.0) bad++;
                    if (m == HFVIS_DIRMAP_CONCENTRIC) {
                        double A = 2.0 * (i + 0.5) / D - 1.0, B = 2.0 * (j + 0.5) / D - 1.0;
                        double rho = fmax(fabs(A), fabs(B));
                        if (fabs(sqrt(l[0] * l[0] + l[1] * l[1]) - rho) > TOL_DISK) bad++;
                    }
                    CHECK_EQ_STATUS(hfvis_dirmap_from_local((hfvis_dirmap)m, D, l, &ii, &jj, &u2), HFVIS_OK);
                    if (ii != i || jj != j || !u2) bad++;
                    l2[0] = 3.5 * l[0]; /* any length */
                    l2[1] = 3.5 * l[1];
                    l2[2] = 3.5 * l[2];
                    CHECK_EQ_STATUS(hfvis_dirmap_from_local((hfvis_dirmap)m, D, l2, &ii, &jj, NULL), HFVIS_OK);
                    if (ii != i || jj != j) bad++;
                }
            if (m == HFVIS_DIRMAP_REJECTION && D == 512)
                CHECK_NEAR((double)unused / (512.0 * 512.0), 1.0 - PI / 4.0, 2.0 / 512.0, 0.0); /* 21.5 % */
        }
    CHECK(bad == 0);
    /* the default enum is the concentric map */
    {
        double l1[3], l2[3];
        int u1, u2;
        hfvis_dirmap_to_local(HFVIS_DIRMAP_DEFAULT, 7, 2, 5, l1, &u1);
        hfvis_dirmap_to_local(HFVIS_DIRMAP_CONCENTRIC, 7, 2, 5, l2, &u2);
        CHECK(memcmp(l1, l2, sizeof l1) == 0 && u1 == u2);
    }
    /* square -> disk -> square on random points; disk radius = max(|a|, |b|) */
    rng_state = 5;
    for (c = 0; c < 100000; c++) {
        double a = 2.0 * rng_unit() - 1.0, b = 2.0 * rng_unit() - 1.0, x, y, a2, b2;
        if (c % 7 == 0) b = (c & 8) ? a : -a; /* the diagonals */
        if (c % 11 == 0) a = 0.0;
        hfvis_concentric_square_to_disk(a, b, &x, &y);
        if (fabs(sqrt(x * x + y * y) - fmax(fabs(a), fabs(b))) > TOL_DISK) bad++;
        hfvis_concentric_disk_to_square(x, y, &a2, &b2);
        if (fabs(a2 - a) > TOL_SQUARE || fabs(b2 - b) > TOL_SQUARE) bad++;
    }
    CHECK(bad == 0);
}

TEST(vf_sizes)
{
    /* spec §1.2: the thesis' memory figures are K*D^2 bytes (Fig. 42, 46/47) */
    CHECK(hfvis_visfield_size(32, 64, HFVIS_VISFIELD_U8) == 17309696u);   /* "16.508 MB" */
    CHECK(hfvis_visfield_size(64, 64, HFVIS_VISFIELD_U8) == 68165632u);   /* "65.00 MB" */
    CHECK(hfvis_visfield_size(16, 32, HFVIS_VISFIELD_U8) == 1116160u);    /* "1.064 MB" */
    CHECK(hfvis_visfield_size(32, 32, HFVIS_VISFIELD_DEFAULT) == 4327424u); /* "4.127 MB" */
    CHECK(hfvis_visfield_size(16, 128, HFVIS_VISFIELD_U8) == 17858560u);  /* "17.031 MB" */
    CHECK(hfvis_visfield_size(64, 32, HFVIS_VISFIELD_U8) == 17041408u);   /* "16.252 MB" */
    CHECK(hfvis_visfield_size(32, 32, HFVIS_VISFIELD_NORMAL) == 4u * 4327424u); /* Fig. 46 "16.508 MB" */
    CHECK(hfvis_visfield_size(32, 64, HFVIS_VISFIELD_F32) == 4u * 17309696u);
    CHECK(hfvis_visfield_size(32, 64, HFVIS_VISFIELD_BIT) == 17309696u / 8u); /* -87.5 % */
    CHECK(hfvis_visfield_size(1, 1, HFVIS_VISFIELD_BIT) == 2u);           /* 10 bits */
    CHECK(hfvis_visfield_size(1, 3, HFVIS_VISFIELD_BIT) == 12u);          /* 90 bits */
    CHECK(hfvis_visfield_size(0, 32, HFVIS_VISFIELD_U8) == 0);
    CHECK(hfvis_visfield_size(8, 0, HFVIS_VISFIELD_U8) == 0);
    CHECK(hfvis_visfield_size(8, HFVIS_VISFIELD_MAX_DIR_RES + 1, HFVIS_VISFIELD_U8) == 0);
    CHECK(hfvis_visfield_size(8, 32, (hfvis_visfield_format)9) == 0);
    if (sizeof(size_t) >= 8)
        CHECK(hfvis_visfield_size(HFVIS_VISFIELD_MAX_N, HFVIS_VISFIELD_MAX_DIR_RES, HFVIS_VISFIELD_F32)
              == (size_t)4198402u * 4096u * 4096u * 4u);
}

/* ========================================================================================== */
/* build                                                                                      */
/* ========================================================================================== */

/* Analytic 8-bit code of the concentric-sphere object (spec §1.13.3): texel square coordinates
 * (A, B), rho = max(|A|, |B|) = sin(angle to the inward normal); hit iff R rho <= r; distance
 * d = R sqrt(1 - rho^2) - sqrt(r^2 - R^2 rho^2). Returns 255 for a miss. */
static int sphere_code(double A, double B, double R, double r)
{
    double rho = fmax(fabs(A), fabs(B)), d, q;
    if (R * rho > r) return 255;
    d = R * sqrt(1.0 - rho * rho) - sqrt(r * r - R * R * rho * rho);
    q = floor(254.0 * d / (2.0 * R) + 0.5);
    return q > 254.0 ? 254 : (int)q;
}

TEST(vf_sphere_in_sphere_exact)
{
    const double c[3] = {0.0, 0.0, 0.0}, R = 1.0, r = 0.5;
    hfvis_mesh ico;
    hfvis_visfield u8, f32, bit, nrm;
    size_t K, k, off_by_one = 0, bad_hit = 0, bad_q = 0, per_map_bad = 0, f32_diff = 0, nbad = 0;
    size_t bad_bit = 0, bad_nbyte = 0;
    double max_ang = 0.0;
    int D = 32, i, j;
    CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c, r, 4, &ico), HFVIS_OK);
    CHECK(field_init(&u8, c, R, 4, D, HFVIS_DIRMAP_CONCENTRIC, HFVIS_VISFIELD_U8));
    CHECK(field_init(&f32, c, R, 4, D, HFVIS_DIRMAP_CONCENTRIC, HFVIS_VISFIELD_F32));
    CHECK(field_init(&bit, c, R, 4, D, HFVIS_DIRMAP_CONCENTRIC, HFVIS_VISFIELD_BIT));
    CHECK(field_init(&nrm, c, R, 4, D, HFVIS_DIRMAP_CONCENTRIC, HFVIS_VISFIELD_NORMAL));
    CHECK_EQ_STATUS(hfvis_visfield_build(&ico, NULL, &u8), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_visfield_build(&ico, NULL, &f32), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_visfield_build(&ico, NULL, &bit), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_visfield_build(&ico, NULL, &nrm), HFVIS_OK);
    K = hfvis_visfield_position_count(4);
    for (k = 0; k < K; k++) {
        const unsigned char *m = (const unsigned char *)u8.maps + k * (size_t)D * D;
        size_t hits = 0;
        double u[3], t[3], b[3], w[3];
        hfvis_visfield_position(4, k, u);
        w[0] = -u[0]; w[1] = -u[1]; w[2] = -u[2];
        hfvis_visfield_frame(w, t, b);
        for (j = 0; j < D; j++)
            for (i = 0; i < D; i++) {
                double A = 2.0 * (i + 0.5) / D - 1.0, B = 2.0 * (j + 0.5) / D - 1.0;
                int want = sphere_code(A, B, R, r), got = m[j * D + i], h, hb;
                size_t tx = (k * (size_t)D + (size_t)j) * (size_t)D + (size_t)i;
                float fv;
                double dist, n3[3];
                hits += got != 255;
                if ((want == 255) != (got == 255)) bad_hit++;
                else if (want != 255 && abs(want - got) > TOL_Q_SPHERE) bad_q++;
                else if (want != got) off_by_one++;
                /* 1-bit consistency (spec §1.13.8): bit set <=> 8-bit code != miss */
                hb = (((const unsigned char *)bit.maps)[tx >> 3] >> (tx & 7u)) & 1u;
                if (hb != (got != 255)) bad_bit++;
                /* the float and the NORMAL variant's distance byte carry the same distance */
                memcpy(&fv, (const unsigned char *)f32.maps + 4 * tx, 4);
                if ((fv == 1.0f) != (got == 255)) f32_diff++;
                else if (got != 255 && abs((int)floor(254.0 * (double)fv + 0.5) - got) > TOL_F32_U8) f32_diff++;
                if (((const unsigned char *)nrm.maps)[4 * tx + 3] != got) bad_nbyte++;
                CHECK_EQ_STATUS(hfvis_visfield_texel(&nrm, k, i, j, &h, &dist, n3), HFVIS_OK);
                if (h && got != 255) { /* the normal at the hit point vs the radial direction */
                    double l[3], d[3], p[3], len, ang;
                    int used, a;
                    hfvis_dirmap_to_local(HFVIS_DIRMAP_CONCENTRIC, D, i, j, l, &used);
                    for (a = 0; a < 3; a++) {
                        d[a] = l[0] * t[a] + l[1] * b[a] + l[2] * w[a];
                        p[a] = R * u[a] + dist * 2.0 * R * d[a];
                    }
                    len = sqrt(dot3(p, p));
                    ang = acos(fmin(1.0, dot3(p, n3) / len)) * 180.0 / PI;
                    if (ang > max_ang) max_ang = ang;
                    if (ang > TOL_NORMAL_DEG) nbad++;
                }
            }
        if (hits != 256) per_map_bad++; /* D = 32, r/R = 1/2: the 16 x 16 central texels */
        if (m[16 * D + 16] != 64) per_map_bad++; /* texel (16, 16) stores 64 (spec §1.13.3) */
    }
    printf("  sphere-in-sphere K = %zu, D = %d: %zu hit/miss errors, %zu codes off by one of %zu, "
           "max normal error %.2f deg\n", K, D, bad_hit, off_by_one, K * (size_t)D * D, max_ang);
    CHECK(bad_hit == 0);
    CHECK(bad_q == 0);
    CHECK(per_map_bad == 0);
    CHECK(bad_bit == 0);
    CHECK(f32_diff == 0);
    CHECK(bad_nbyte == 0);
    CHECK(nbad == 0);
    /* central rays hit at R - r: avg_distance = (R - r)/(2R) within the tessellation */
    CHECK_NEAR(u8.avg_distance, 0.25, 1e-3, 0.0);
    CHECK(u8.avg_distance == bit.avg_distance);
    field_done(&u8);
    field_done(&f32);
    field_done(&bit);
    field_done(&nrm);
    hfvis_mesh_free(NULL, &ico);
}

static int progress_calls, progress_last, progress_total;
static void on_progress(void *user, int done, int total)
{
    (void)user;
    if (done != progress_last + 1) progress_calls = -1000000;
    progress_calls++;
    progress_last = done;
    progress_total = total;
}

TEST(vf_build_matches_reference)
{
    const double c0[3] = {0.0, 0.0, 0.0};
    hfvis_mesh torus, teapot;
    hfvis_bvh bvh;
    int f, m, bad = 0;
    CHECK_EQ_STATUS(hfvis_mesh_torus(NULL, c0, 1.0, 0.35, 12, 8, &torus), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_mesh_teapot(NULL, 1, &teapot), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_bvh_build(&teapot, NULL, &bvh), HFVIS_OK);
    for (f = 1; f <= 4; f++)
        for (m = 1; m <= 3; m++) {
            hfvis_visfield a, b, e;
            hfvis_visfield_build_options o;
            const hfvis_mesh *mesh = (f + m) % 2 ? &torus : &teapot;
            double c[3], R;
            int D = 5 + f + m;
            CHECK_EQ_STATUS(hfvis_visfield_bounding_sphere(mesh, c, &R), HFVIS_OK);
            CHECK(field_init(&a, c, R, 2 + (f % 2), D, (hfvis_dirmap)m, (hfvis_visfield_format)f));
            CHECK(field_init(&b, c, R, 2 + (f % 2), D, (hfvis_dirmap)m, (hfvis_visfield_format)f));
            CHECK(field_init(&e, c, R, 2 + (f % 2), D, (hfvis_dirmap)m, (hfvis_visfield_format)f));
            memset(a.maps, 0xAB, a.maps_size);
            memset(b.maps, 0x5C, b.maps_size);
            memset(e.maps, 0x11, e.maps_size);
            memset(&o, 0, sizeof o);
            o.progress = on_progress;
            progress_calls = progress_last = progress_total = 0;
            CHECK_EQ_STATUS(hfvis_visfield_build(mesh, &o, &a), HFVIS_OK);
            CHECK(progress_calls == (int)hfvis_visfield_position_count(a.positions_n));
            CHECK(progress_total == progress_calls);
            CHECK_EQ_STATUS(hfvis_visfield_build_reference(mesh, NULL, &b), HFVIS_OK);
            if (memcmp(a.maps, b.maps, a.maps_size) != 0 || a.avg_distance != b.avg_distance) bad++;
            if (mesh == &teapot) { /* with the caller's BVH */
                o.bvh = &bvh;
                CHECK_EQ_STATUS(hfvis_visfield_build(mesh, &o, &e), HFVIS_OK);
                if (memcmp(a.maps, e.maps, a.maps_size) != 0 || a.avg_distance != e.avg_distance) bad++;
            }
            field_done(&a);
            field_done(&b);
            field_done(&e);
        }
    CHECK(bad == 0);
    hfvis_bvh_free(NULL, &bvh);
    hfvis_mesh_free(NULL, &torus);
    hfvis_mesh_free(NULL, &teapot);
}
int main(int argc, char **argv)
{
    TEST_INIT(argc, argv);
    RUN(vf_counts);
    RUN(vf_nearest_matches_naive);
    RUN(vf_frame);
    RUN(vf_dirmaps);
    RUN(vf_sizes);
    RUN(vf_sphere_in_sphere_exact);
    RUN(vf_build_matches_reference);
    return TEST_DONE();
}
