/* test_visfield.c - 4D visibility fields ([G12] ch. 4): positional samples, direction
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
#define TOL_AO_CONVEX 0.01      /* intra-object AO on a convex sphere (no self-occlusion) when the
                                   bias exceeds the snapping offset: a few grazing rays */
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
    static const int counts[10] = {50000, 50000, 50000, 50000, 50000, 50000, 50000,
                                   30000, 20000, 8000};
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
            } else { /* near the octahedron's edges and vertices, scaled (also to 1e+-250) */
                static const double scale[4] = {1e3, 1e250, 1e-250, 1.0};
                double sc = scale[(c >> 2) & 3];
                rng_dir(q);
                q[(int)(rng_next() % 3)] *= 1e-9;
                q[0] *= sc;
                q[1] *= sc;
                q[2] *= sc;
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
    /* [G12] ch. 4, Fig. 42: the thesis' memory figures are K*D^2 bytes (Fig. 42, 46/47) */
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

/* Analytic 8-bit code of the concentric-sphere object: texel square coordinates
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
                /* 1-bit consistency: bit set <=> 8-bit code != miss */
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
        if (m[16 * D + 16] != 64) per_map_bad++; /* texel (16, 16) stores 64 */
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
/* ========================================================================================== */
/* queries                                                                                    */
/* ========================================================================================== */

/* Exact ray / sphere (centre s, radius r): smallest t >= 0, or INFINITY. */
static double ray_sphere(const double o[3], const double d[3], const double s[3], double r)
{
    double oc[3] = {o[0] - s[0], o[1] - s[1], o[2] - s[2]}, b = dot3(oc, d), g = dot3(oc, oc) - r * r;
    double disc = b * b - g, sq, t;
    if (disc < 0.0) return HUGE_VAL;
    sq = sqrt(disc);
    t = -b - sq;
    if (t < 0.0) t = -b + sq;
    return t >= 0.0 ? t : HUGE_VAL;
}

/* A query that starts exactly on the stored ray of (k, i, j) reads exactly that texel: the result
 * equals the stored distance plus the offset (outside) or the offset minus it (inside). */
TEST(vf_query_on_stored_rays)
{
    const double c0[3] = {0.0, 0.0, 0.0};
    hfvis_mesh mesh;
    hfvis_visfield vf;
    double c[3], R;
    size_t K, k, bad_pos = 0, bad_d = 0, n_in = 0, n_out = 0;
    int D = 16, m;
    CHECK_EQ_STATUS(hfvis_mesh_teapot(NULL, 2, &mesh), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_visfield_bounding_sphere(&mesh, c, &R), HFVIS_OK);
    (void)c0;
    for (m = 1; m <= 3; m++) {
        CHECK(field_init(&vf, c, R, 3, D, (hfvis_dirmap)m, HFVIS_VISFIELD_U8));
        CHECK_EQ_STATUS(hfvis_visfield_build(&mesh, NULL, &vf), HFVIS_OK);
        K = hfvis_visfield_position_count(3);
        for (k = 0; k < K; k++) {
            double u[3], w[3], t[3], b[3];
            int i, j, a;
            hfvis_visfield_position(3, k, u);
            if (fabs(u[2]) < 1e-12 && k >= K / 2) continue; /* lower equator copies answer as upper */
            for (a = 0; a < 3; a++) w[a] = -u[a];
            hfvis_visfield_frame(w, t, b);
            for (j = 0; j < D; j++)
                for (i = 0; i < D; i++) {
                    double l[3], d[3], p[3], o[3], nd[3], stored, s = 0.3 * R;
                    int used, hit;
                    hfvis_visfield_hit h;
                    hfvis_dirmap_to_local((hfvis_dirmap)m, D, i, j, l, &used);
                    if (!used || l[2] < 0.05) continue; /* grazing texels: the entry point is ill-conditioned */
                    for (a = 0; a < 3; a++) {
                        d[a] = l[0] * t[a] + l[1] * b[a] + l[2] * w[a];
                        p[a] = c[a] + R * u[a];
                        o[a] = p[a] - s * d[a]; /* outside, on the stored ray */
                    }
                    hfvis_visfield_texel(&vf, k, i, j, &hit, &stored, NULL);
                    CHECK_EQ_STATUS(hfvis_visfield_query(&vf, o, d, 0.0, &h), HFVIS_OK);
                    n_out++;
                    if (h.position != k || h.texel_i != i || h.texel_j != j) bad_pos++;
                    else if (hit != (h.result == HFVIS_VISFIELD_HIT)) bad_d++;
                    else if (hit && fabs(h.distance - (s + stored * 2.0 * R)) > 1e-9 * R) bad_d++;
                    /* inside: origin on the stored ray at distance s2 from p_k, looking back at p_k */
                    {
                        double s2 = 0.5 * 2.0 * R * l[2];
                        for (a = 0; a < 3; a++) {
                            o[a] = p[a] + s2 * d[a];
                            nd[a] = -d[a];
                        }
                        CHECK_EQ_STATUS(hfvis_visfield_query(&vf, o, nd, 0.0, &h), HFVIS_OK);
                        n_in++;
                        if (h.position != k || h.texel_i != i || h.texel_j != j) bad_pos++;
                        else if ((hit && stored * 2.0 * R < s2 - 1e-9 * R) != (h.result == HFVIS_VISFIELD_OCCLUDED)
                                 && fabs(stored * 2.0 * R - s2) > 1e-9 * R)
                            bad_d++;
                        else if (h.result == HFVIS_VISFIELD_OCCLUDED
                                 && fabs(h.distance - (s2 - stored * 2.0 * R)) > 1e-9 * R)
                            bad_d++;
                    }
                }
        }
        field_done(&vf);
    }
    printf("  %zu outside and %zu inside queries on stored rays: %zu wrong texels, %zu wrong values\n",
           n_out, n_in, bad_pos, bad_d);
    CHECK(bad_pos == 0);
    CHECK(bad_d == 0);
    hfvis_mesh_free(NULL, &mesh);
}

/* Error statistics of outside rays against an off-centre sphere. */
typedef struct ray_stats {
    double mismatch;   /* fraction of rays whose hit/miss differs from the oracle */
    double mean_err;   /* mean |d_vf - d_exact| / R over rays both call hits */
    double max_err;
} ray_stats;

static void outside_ray_stats(const hfvis_visfield *vf, const double s[3], double r, int rays,
                              uint64_t seed, ray_stats *st)
{
    int q, mism = 0, both = 0;
    double sum = 0.0, mx = 0.0, R = vf->radius;
    rng_state = seed;
    for (q = 0; q < rays; q++) {
        double o[3], tg[3], d[3], e[3], len, te;
        hfvis_visfield_hit h;
        int a;
        rng_dir(e);
        for (a = 0; a < 3; a++) o[a] = vf->center[a] + 3.0 * R * e[a];
        rng_dir(e);
        len = 1.3 * r * cbrt(rng_unit());
        for (a = 0; a < 3; a++) {
            tg[a] = s[a] + len * e[a];
            d[a] = tg[a] - o[a];
        }
        len = sqrt(dot3(d, d));
        for (a = 0; a < 3; a++) d[a] /= len;
        te = ray_sphere(o, d, s, r);
        hfvis_visfield_query(vf, o, d, 0.0, &h);
        if ((h.result == HFVIS_VISFIELD_HIT) != isfinite(te)) mism++;
        else if (isfinite(te)) {
            double err = fabs(h.distance - te) / R;
            sum += err;
            if (err > mx) mx = err;
            both++;
        }
    }
    st->mismatch = (double)mism / rays;
    st->mean_err = both ? sum / both : 0.0;
    st->max_err = mx;
}

/* The sphere-in-sphere table: rows K, columns D, cells "mismatch % / mean |dd|/R". Analytic
 * oracle (the exact sphere); the object is a subdivision-5 icosphere (faces within 1e-4 r). */
TEST(vf_table_sphere)
{
    static const int ns[3] = {4, 8, 16}, Ds[3] = {16, 32, 64};
    const double s[3] = {0.15, -0.1, 0.12}, r = 0.45, c0[3] = {0.0, 0.0, 0.0};
    ray_stats st[3][3];
    hfvis_mesh ico;
    hfvis_bvh bvh;
    hfvis_visfield_build_options o;
    int a, b;
    CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, s, r, 5, &ico), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_bvh_build(&ico, NULL, &bvh), HFVIS_OK);
    memset(&o, 0, sizeof o);
    o.bvh = &bvh;
    printf("  off-centre sphere (r = 0.45 R, centre 0.23 R from c), 20000 outside rays per cell:\n"
           "  hit/miss disagreement %% / mean |d - d_exact| / R\n  %6s", "K \\ D");
    for (b = 0; b < 3; b++) printf("   %9d x %-3d", Ds[b], Ds[b]);
    printf("\n");
    for (a = 0; a < 3; a++) {
        printf("  %6zu", hfvis_visfield_position_count(ns[a]));
        for (b = 0; b < 3; b++) {
            hfvis_visfield vf;
            CHECK(field_init(&vf, c0, 1.0, ns[a], Ds[b], HFVIS_DIRMAP_CONCENTRIC, HFVIS_VISFIELD_U8));
            CHECK_EQ_STATUS(hfvis_visfield_build(&ico, &o, &vf), HFVIS_OK);
            outside_ray_stats(&vf, s, r, 20000, 99, &st[a][b]);
            printf("   %5.2f%% / %.4f", 100.0 * st[a][b].mismatch, st[a][b].mean_err);
            field_done(&vf);
        }
        printf("\n");
    }
    /* the error must shrink with K at every D (positional snapping dominates, [G12] ch. 4) */
    for (b = 0; b < 3; b++)
        for (a = 1; a < 3; a++) {
            CHECK(st[a][b].mismatch < st[a - 1][b].mismatch);
            CHECK(st[a][b].mean_err < st[a - 1][b].mean_err);
        }
    /* regression bounds at K = 1090, D = 32 (a prototype with another ray set: 4.6 %, 0.023) */
    CHECK(st[2][1].mismatch < 0.08); /* this ray set aims at 1.3 r: silhouette-heavy */
    CHECK(st[2][1].mean_err < 0.025);
    hfvis_bvh_free(NULL, &bvh);
    hfvis_mesh_free(NULL, &ico);
}

/* ========================================================================================== */
/* ambient occlusion, shadows, reflections                                                    */
/* ========================================================================================== */

/* An object at the identity transform. */
static hfvis_visfield_object make_object(const hfvis_visfield *vf, const hfvis_mesh *mesh,
                                         const hfvis_bvh *bvh)
{
    hfvis_visfield_object o;
    o.field = vf;
    o.mesh = mesh;
    o.bvh = bvh;
    identity(o.object_to_world);
    return o;
}

/* AO under a sphere: receiver at the origin, normal +z, occluder sphere of radius
 * r whose centre is at distance h in the direction at angle th from the normal, fully above the
 * horizon: exact obscurance cos(th) (r/h)^2 (the sphere's form factor). */
TEST(vf_ao_form_factor)
{
    const double r = 0.45, hh = 1.5, c0[3] = {0.0, 0.0, 0.0};
    static const double ths[3] = {0.0, 0.5, 0.9};
    const float pt[3] = {0.0f, 0.0f, 0.0f}, nz[3] = {0.0f, 0.0f, 1.0f};
    hfvis_mesh ico;
    hfvis_bvh bvh;
    hfvis_visfield vf;
    hfvis_visfield_ao_options o = hfvis_visfield_ao_options_default();
    int t;
    CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c0, r, 5, &ico), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_bvh_build(&ico, NULL, &bvh), HFVIS_OK);
    CHECK(field_init(&vf, c0, 1.0, 16, 32, HFVIS_DIRMAP_CONCENTRIC, HFVIS_VISFIELD_U8));
    CHECK_EQ_STATUS(hfvis_visfield_build(&ico, NULL, &vf), HFVIS_OK);
    for (t = 0; t < 3; t++) {
        hfvis_visfield_object ob = make_object(&vf, &ico, &bvh);
        double exact = cos(ths[t]) * (r / hh) * (r / hh);
        float fast, ref, ref64;
        ob.object_to_world[12] = hh * sin(ths[t]);
        ob.object_to_world[14] = hh * cos(ths[t]);
        o.rays_sqrt = 16;
        CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion(&ob, 1, pt, nz, 1, &o, &fast), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion_reference(&ob, 1, pt, nz, 1, &o, &ref), HFVIS_OK);
        o.rays_sqrt = 64;
        CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion_reference(&ob, 1, pt, nz, 1, &o, &ref64), HFVIS_OK);
        printf("  sphere at %.2f rad: exact obscurance %.4f, ray cast 16x16 %.4f, 64x64 %.4f, "
               "VF (K = 1090, D = 32) %.4f\n", ths[t], exact, (double)ref, (double)ref64, (double)fast);
        CHECK_NEAR(fast, ref, TOL_AO_SAME_RAYS, 0.0);
        CHECK_NEAR(ref64, exact, TOL_AO_ESTIMATOR, 0.0);
    }
    field_done(&vf);
    hfvis_bvh_free(NULL, &bvh);
    hfvis_mesh_free(NULL, &ico);
}

/* A convex object does not occlude itself: receivers on the sphere, rays in their
 * outward hemisphere, inside queries. The reversed stored ray starts at the snapped sample, up to
 * R x covering angle (~79 deg / n) beside the true exit point, so rays near the tangent plane
 * meet the sphere early unless the bias exceeds that offset: the thesis' "intra-object AO needs
 * more maps". Measured here: n = 16 needs a bias of 0.1 R, n = 32 works with the default. */
TEST(vf_ao_convex_no_self_occlusion)
{
    const double c0[3] = {0.0, 0.0, 0.0};
    static const int ns[2] = {16, 32};
    static const double bias[2] = {0.02, 0.1};
    enum { P = 200 };
    static float pts[3 * P], nrm[3 * P], fast[P], ref[P];
    hfvis_mesh ico;
    hfvis_bvh bvh;
    hfvis_visfield vf;
    hfvis_visfield_object ob;
    hfvis_visfield_ao_options o = hfvis_visfield_ao_options_default();
    double mean[2][2];
    int p, a, b;
    CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c0, 0.5, 3, &ico), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_bvh_build(&ico, NULL, &bvh), HFVIS_OK);
    rng_state = 3;
    for (p = 0; p < P; p++) { /* vertices of the mesh: exactly on its surface */
        size_t v = (size_t)(rng_next() % ico.vertex_count);
        for (a = 0; a < 3; a++) {
            pts[3 * p + a] = ico.xyz[3 * v + a];
            nrm[3 * p + a] = ico.xyz[3 * v + a];
        }
    }
    printf("  convex sphere (r = R/2), %d receivers, mean VF self-obscurance (reference 0):\n", P);
    for (a = 0; a < 2; a++) {
        CHECK(field_init(&vf, c0, 1.0, ns[a], 32, HFVIS_DIRMAP_CONCENTRIC, HFVIS_VISFIELD_U8));
        CHECK_EQ_STATUS(hfvis_visfield_build(&ico, NULL, &vf), HFVIS_OK);
        ob = make_object(&vf, &ico, &bvh);
        for (b = 0; b < 2; b++) {
            o.bias = bias[b];
            CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion(&ob, 1, pts, nrm, P, &o, fast), HFVIS_OK);
            CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion_reference(&ob, 1, pts, nrm, P, &o, ref), HFVIS_OK);
            mean[a][b] = 0.0;
            for (p = 0; p < P; p++) {
                mean[a][b] += (double)fast[p];
                CHECK(ref[p] == 0.0f);
            }
            mean[a][b] /= P;
            printf("    K = %4zu, D = 32, bias %.2f R: %.4f\n", hfvis_visfield_position_count(ns[a]),
                   bias[b], mean[a][b]);
        }
        field_done(&vf);
    }
    CHECK(mean[1][0] <= TOL_AO_CONVEX); /* K = 4226, default bias */
    CHECK(mean[0][1] <= TOL_AO_CONVEX); /* K = 1090, bias 0.1 R */
    CHECK(mean[0][0] > mean[1][0]);     /* fewer maps, more self-occlusion */
    hfvis_bvh_free(NULL, &bvh);
    hfvis_mesh_free(NULL, &ico);
}

/* A large wall beside a floor receiver: exactly half of the cosine-weighted
 * hemisphere is blocked. The ray-cast estimator is exactly 1/2 (the 16 x 16 set is symmetric
 * about every axis); the field is approximate (R x covering angle vs the receiver distance). */
TEST(vf_ao_wall)
{
    const double lo[3] = {1.0, -40.0, -40.0}, hi[3] = {1.5, 40.0, 40.0};
    const float pt[3] = {0.0f, 0.0f, 0.0f}, nz[3] = {0.0f, 0.0f, 1.0f};
    hfvis_mesh box;
    hfvis_visfield vf;
    hfvis_visfield_object ob;
    hfvis_visfield_ao_options o = hfvis_visfield_ao_options_default();
    double c[3], R;
    float fast, ref;
    CHECK_EQ_STATUS(hfvis_mesh_box(NULL, lo, hi, &box), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_visfield_bounding_sphere(&box, c, &R), HFVIS_OK);
    CHECK(field_init(&vf, c, R, 32, 32, HFVIS_DIRMAP_CONCENTRIC, HFVIS_VISFIELD_F32));
    CHECK_EQ_STATUS(hfvis_visfield_build(&box, NULL, &vf), HFVIS_OK);
    ob = make_object(&vf, &box, NULL);
    o.bias = 1e-4; /* the receiver is 1 unit from a wall of radius 57: a tiny relative bias */
    CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion_reference(&ob, 1, pt, nz, 1, &o, &ref), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion(&ob, 1, pt, nz, 1, &o, &fast), HFVIS_OK);
    printf("  wall: ray cast %.4f (exactly 1/2), VF (K = 4226, D = 32, float) %.4f\n", (double)ref,
           (double)fast);
    CHECK(ref == 0.5f);
    CHECK_NEAR(fast, 0.5, TOL_WALL_VF, 0.0);
    field_done(&vf);
    hfvis_mesh_free(NULL, &box);
}

/* Rotation about axis (unit) by angle, scaled by s, translated by T: object -> world. */
static void rigid(double m[16], const double axis[3], double ang, double s, const double T[3])
{
    double c = cos(ang), sn = sin(ang), x = axis[0], y = axis[1], z = axis[2], C = 1.0 - c;
    double q[9] = {c + x * x * C, y * x * C + z * sn, z * x * C - y * sn,
                   x * y * C - z * sn, c + y * y * C, z * y * C + x * sn,
                   x * z * C + y * sn, y * z * C - x * sn, c + z * z * C};
    int a, r;
    identity(m);
    for (a = 0; a < 3; a++) {
        for (r = 0; r < 3; r++) m[4 * a + r] = s * q[3 * a + r];
        m[12 + a] = T[a];
    }
}

/* Several objects with rigid transforms: the any-object rule, the thesis' subtractive sum, and
 * the instance transform against a pre-transformed mesh. */
TEST(vf_multi_object)
{
    const double c0[3] = {0.0, 0.0, 0.0}, axis[3] = {0.48, 0.6, 0.64};
    enum { G = 12, P = G * G };
    static float pts[3 * P], nrm[3 * P], any1[P], sub1[P], any2[P], sub2[P], ref2[P], refm[P], vfm[P];
    hfvis_mesh knot, moved;
    hfvis_bvh bvh, bvh_moved;
    hfvis_visfield vf;
    hfvis_visfield_object obs[2], mob;
    hfvis_visfield_ao_options o = hfvis_visfield_ao_options_default();
    double c[3], R, T1[3] = {0.2, -0.3, 1.6}, T2[3] = {1.9, 0.8, 1.4}, m16[16];
    double rms = 0.0, maxd = 0.0;
    float *xyz;
    int p, sub_ge = 1, eq_twice = 1, a;
    size_t v;
    CHECK_EQ_STATUS(hfvis_mesh_torus_knot(NULL, c0, 0.5, 2, 3, 120, 10, &knot), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_bvh_build(&knot, NULL, &bvh), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_visfield_bounding_sphere(&knot, c, &R), HFVIS_OK);
    CHECK(field_init(&vf, c, R, 16, 32, HFVIS_DIRMAP_CONCENTRIC, HFVIS_VISFIELD_U8));
    CHECK_EQ_STATUS(hfvis_visfield_build(&knot, NULL, &vf), HFVIS_OK);
    for (p = 0; p < P; p++) { /* a floor of receivers under the objects */
        pts[3 * p] = (float)(-1.0 + 4.0 * (p % G) / (G - 1));
        pts[3 * p + 1] = (float)(-1.5 + 3.0 * (p / G) / (G - 1));
        pts[3 * p + 2] = 0.0f;
        nrm[3 * p] = nrm[3 * p + 1] = 0.0f;
        nrm[3 * p + 2] = 1.0f;
    }
    obs[0] = make_object(&vf, &knot, &bvh);
    obs[1] = obs[0];
    rigid(obs[0].object_to_world, axis, 0.7, 1.3, T1);
    /* two identical instances: any = one instance; subtractive = twice it, capped at 1 */
    obs[1] = obs[0];
    CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion(obs, 1, pts, nrm, P, &o, any1), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion(obs, 2, pts, nrm, P, &o, any2), HFVIS_OK);
    o.combine = HFVIS_VISFIELD_COMBINE_SUBTRACTIVE;
    CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion(obs, 1, pts, nrm, P, &o, sub1), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion(obs, 2, pts, nrm, P, &o, sub2), HFVIS_OK);
    for (p = 0; p < P; p++) {
        if (any2[p] != any1[p] || sub1[p] != any1[p]) eq_twice = 0;
        if (sub2[p] != (float)fmin(1.0, 2.0 * (double)any1[p])) eq_twice = 0;
    }
    CHECK(eq_twice);
    /* two different instances: subtractive >= any, both within [0, 1] */
    rigid(obs[1].object_to_world, axis, -1.9, 0.8, T2);
    o.combine = HFVIS_VISFIELD_COMBINE_ANY;
    CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion(obs, 2, pts, nrm, P, &o, any2), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion_reference(obs, 2, pts, nrm, P, &o, ref2), HFVIS_OK);
    o.combine = HFVIS_VISFIELD_COMBINE_SUBTRACTIVE;
    CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion(obs, 2, pts, nrm, P, &o, sub2), HFVIS_OK);
    for (p = 0; p < P; p++) {
        double d = (double)any2[p] - (double)ref2[p];
        if (sub2[p] < any2[p] || any2[p] < 0.0f || sub2[p] > 1.0f) sub_ge = 0;
        rms += d * d;
        if (fabs(d) > maxd) maxd = fabs(d);
    }
    rms = sqrt(rms / P);
    printf("  two rotated, scaled knot instances over a floor: VF vs ray cast RMS %.4f (%.2f on the "
           "8-bit scale), max %.4f\n", rms, 255.0 * rms, maxd);
    CHECK(sub_ge);
    CHECK(rms < 0.03);
    /* the instance transform equals transforming the mesh (ray cast): same rays, same answers up
     * to rays grazing a triangle (float rounding of the moved vertices) */
    moved = knot;
    xyz = (float *)malloc(sizeof(float) * 3 * knot.vertex_count);
    CHECK(xyz != NULL);
    if (xyz) {
        double d = 0.0;
        for (v = 0; v < knot.vertex_count; v++) {
            double pin[4] = {(double)knot.xyz[3 * v], (double)knot.xyz[3 * v + 1], (double)knot.xyz[3 * v + 2], 1.0};
            for (a = 0; a < 3; a++)
                xyz[3 * v + a] = (float)(obs[0].object_to_world[a] * pin[0] + obs[0].object_to_world[4 + a] * pin[1]
                                         + obs[0].object_to_world[8 + a] * pin[2] + obs[0].object_to_world[12 + a]);
        }
        moved.xyz = xyz;
        CHECK_EQ_STATUS(hfvis_bvh_build(&moved, NULL, &bvh_moved), HFVIS_OK);
        mob = obs[0];
        mob.mesh = &moved;
        mob.bvh = &bvh_moved;
        identity(m16);
        memcpy(mob.object_to_world, m16, sizeof m16);
        /* the same sphere, moved (the sphere decides inside / outside) */
        {
            hfvis_visfield vm = vf;
            for (a = 0; a < 3; a++)
                vm.center[a] = obs[0].object_to_world[a] * c[0] + obs[0].object_to_world[4 + a] * c[1]
                               + obs[0].object_to_world[8 + a] * c[2] + obs[0].object_to_world[12 + a];
            vm.radius = R * 1.3;
            mob.field = &vm;
            o.combine = HFVIS_VISFIELD_COMBINE_ANY;
            o.bias = 0.02 / 1.3 * 1.3;
            CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion_reference(&mob, 1, pts, nrm, P, &o, refm), HFVIS_OK);
            CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion_reference(obs, 1, pts, nrm, P, &o, vfm), HFVIS_OK);
        }
        for (p = 0; p < P; p++) d = fmax(d, fabs((double)refm[p] - (double)vfm[p]));
        CHECK(d <= 1.0 / 256.0 + 1e-7); /* at most one grazing ray of 256 */
        hfvis_bvh_free(NULL, &bvh_moved);
        free(xyz);
    }
    field_done(&vf);
    hfvis_bvh_free(NULL, &bvh);
    hfvis_mesh_free(NULL, &knot);
}
/* Hard and soft shadows of a sphere over a floor under a spherical light ([G12] §4.5.2): inside
 * the umbra of a point light the reference is 0, outside the shadow 1 (closed-form cone), and the
 * field agrees with ray casting on most points. */
TEST(vf_shadows)
{
    const double c0[3] = {0.0, 0.0, 0.0}, light[3] = {0.0, 0.0, 6.0}, h = 2.0, r = 0.5;
    enum { G = 41, P = G * G };
    static float pts[3 * P], hard[P], hard_ref[P], soft[P], soft_ref[P];
    hfvis_mesh ico;
    hfvis_bvh bvh;
    hfvis_visfield vf;
    hfvis_visfield_object ob;
    hfvis_visfield_shadow_options o;
    /* umbra of a point light at height L over a sphere at height h: a disc of radius
     * L tan(asin(r/(L - h))) on the floor */
    double L = light[2], rad = L * tan(asin(r / (L - h))), diff = 0.0, agree = 0.0;
    int p, inside_ok = 1, outside_ok = 1, ordered = 1;
    CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c0, r, 4, &ico), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_bvh_build(&ico, NULL, &bvh), HFVIS_OK);
    CHECK(field_init(&vf, c0, 0.8, 16, 32, HFVIS_DIRMAP_CONCENTRIC, HFVIS_VISFIELD_U8));
    CHECK_EQ_STATUS(hfvis_visfield_build(&ico, NULL, &vf), HFVIS_OK);
    ob = make_object(&vf, &ico, &bvh);
    ob.object_to_world[14] = h;
    for (p = 0; p < P; p++) {
        pts[3 * p] = (float)(-2.0 + 4.0 * (p % G) / (G - 1));
        pts[3 * p + 1] = (float)(-2.0 + 4.0 * (p / G) / (G - 1));
        pts[3 * p + 2] = 0.0f;
    }
    memset(&o, 0, sizeof o);
    o.samples = 1;
    CHECK_EQ_STATUS(hfvis_visfield_soft_shadow(&ob, 1, pts, P, light, 0.0, &o, hard), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_visfield_soft_shadow_reference(&ob, 1, pts, P, light, 0.0, &o, hard_ref), HFVIS_OK);
    o.samples = 0; /* 20 */
    CHECK_EQ_STATUS(hfvis_visfield_soft_shadow(&ob, 1, pts, P, light, 1.0, &o, soft), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_visfield_soft_shadow_reference(&ob, 1, pts, P, light, 1.0, &o, soft_ref), HFVIS_OK);
    for (p = 0; p < P; p++) {
        double x = (double)pts[3 * p], y = (double)pts[3 * p + 1], rr = sqrt(x * x + y * y);
        if (rr < 0.9 * rad && (hard_ref[p] != 0.0f || hard[p] != 0.0f)) inside_ok = 0;
        if (rr > 1.1 * rad && (hard_ref[p] != 1.0f || hard[p] != 1.0f)) outside_ok = 0;
        agree += hard[p] == hard_ref[p];
        diff += fabs((double)soft[p] - (double)soft_ref[p]);
        if (rr < 0.5 * rad && soft_ref[p] > 0.5f) ordered = 0;   /* the soft shadow's core */
        if (rr > 2.5 * rad && soft_ref[p] != 1.0f) ordered = 0;  /* fully lit far away */
    }
    printf("  point light: umbra radius %.3f; VF agrees with ray casting on %.1f %% of %d floor points;\n"
           "  light of radius 1, 20 rays: mean |VF - ray cast| %.4f\n", rad, 100.0 * agree / P, P, diff / P);
    CHECK(inside_ok);
    CHECK(outside_ok);
    CHECK(ordered);
    CHECK(agree / P > 0.97);
    CHECK(diff / P < 0.02);
    field_done(&vf);
    hfvis_bvh_free(NULL, &bvh);
    hfvis_mesh_free(NULL, &ico);
}

/* Tracing and reflections with the normal-carrying variant ([G12] §4.5.2): hit points, distances
 * and normals against ray casting; the mirror and glossy reflection ray sets. */
TEST(vf_trace_reflect)
{
    const double c0[3] = {0.0, 0.0, 0.0};
    hfvis_mesh knot;
    hfvis_bvh bvh;
    hfvis_visfield vf;
    hfvis_visfield_object ob;
    double c[3], R, T[3] = {0.0, 0.0, 1.5}, axis[3] = {0.0, 0.6, 0.8};
    double sum_d = 0.0, sum_a = 0.0;
    int q, both = 0, mism = 0, N = 4000, bad_refl = 0, lobe_ok = 1;
    CHECK_EQ_STATUS(hfvis_mesh_torus_knot(NULL, c0, 0.5, 2, 3, 160, 12, &knot), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_bvh_build(&knot, NULL, &bvh), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_visfield_bounding_sphere(&knot, c, &R), HFVIS_OK);
    CHECK(field_init(&vf, c, R, 16, 64, HFVIS_DIRMAP_CONCENTRIC, HFVIS_VISFIELD_NORMAL));
    CHECK_EQ_STATUS(hfvis_visfield_build(&knot, NULL, &vf), HFVIS_OK);
    ob = make_object(&vf, &knot, &bvh);
    rigid(ob.object_to_world, axis, 0.4, 1.0, T);
    rng_state = 21;
    for (q = 0; q < N; q++) { /* rays from the floor toward random points near the object */
        double o[3], d[3], tg[3], len;
        hfvis_visfield_trace_hit a, b;
        int k;
        o[0] = 4.0 * rng_unit() - 2.0;
        o[1] = 4.0 * rng_unit() - 2.0;
        o[2] = 0.0;
        for (k = 0; k < 3; k++) tg[k] = T[k] + (2.0 * rng_unit() - 1.0) * R * 0.8;
        for (k = 0; k < 3; k++) d[k] = tg[k] - o[k];
        len = sqrt(dot3(d, d));
        for (k = 0; k < 3; k++) d[k] /= len;
        CHECK_EQ_STATUS(hfvis_visfield_trace(&ob, 1, o, d, 0.0, &a), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_visfield_trace_reference(&ob, 1, o, d, 0.0, &b), HFVIS_OK);
        if ((a.object == HFVIS_VISFIELD_NONE) != (b.object == HFVIS_VISFIELD_NONE)) {
            mism++;
        } else if (a.object == 0) {
            double e = fabs(a.point[0] - (o[0] + a.distance * d[0]));
            both++;
            sum_d += fabs(a.distance - b.distance) / R;
            sum_a += acos(fmin(1.0, dot3(a.normal, b.normal))) * 180.0 / PI;
            if (e > 1e-12 || fabs(sqrt(dot3(a.normal, a.normal)) - 1.0) > 1e-9) mism += 1000000;
        }
        /* the mirror reflection off the floor of the ray going down: the same ray upward */
        if (q % 8 == 0) {
            double inc[3] = {d[0], d[1], -d[2]}, up[3] = {0.0, 0.0, 1.0}, o2[3];
            hfvis_visfield_trace_hit r1[4], r2[4];
            hfvis_visfield_reflect_options ro;
            int i;
            memset(&ro, 0, sizeof ro);
            CHECK_EQ_STATUS(hfvis_visfield_reflect(&ob, 1, o, up, inc, &ro, r1), HFVIS_OK);
            if (r1[0].object != a.object || fabs(r1[0].distance - a.distance) > 1e-9 || r1[3].distance != r1[0].distance)
                bad_refl++;
            CHECK_EQ_STATUS(hfvis_visfield_reflect_reference(&ob, 1, o, up, inc, &ro, r2), HFVIS_OK);
            if (r2[0].object != b.object || fabs(r2[0].distance - b.distance) > 1e-6) bad_refl++;
            /* glossy: 16 rays within the Phong lobe, all above the floor or misses */
            ro.rays = 16;
            ro.shininess = 50.0;
            {
                hfvis_visfield_trace_hit g[16];
                CHECK_EQ_STATUS(hfvis_visfield_reflect(&ob, 1, o, up, inc, &ro, g), HFVIS_OK);
                for (i = 0; i < 16; i++)
                    if (g[i].object == 0) {
                        for (k = 0; k < 3; k++) o2[k] = g[i].point[k] - o[k];
                        len = sqrt(dot3(o2, o2));
                        /* Phong 50: the lobe ray i has cos >= ((0.5)/16)^(1/51) ~ 0.934 */
                        if (dot3(o2, d) / len < 0.93 || o2[2] <= 0.0) lobe_ok = 0;
                    }
            }
        }
    }
    printf("  knot (NORMAL format, K = 1090, D = 64), %d rays: hit/miss disagreement %.2f %%, "
           "mean |dd|/R %.4f, mean normal error %.1f deg\n", N, 100.0 * mism / N, sum_d / both,
           sum_a / both);
    CHECK(mism < N / 10);
    CHECK(sum_d / both < 0.07);  /* regression bound (measured 0.056) */
    CHECK(sum_a / both < 25.0);  /* regression bound (measured 17.7 deg) */
    CHECK(bad_refl == 0);
    CHECK(lobe_ok);
    field_done(&vf);
    hfvis_bvh_free(NULL, &bvh);
    hfvis_mesh_free(NULL, &knot);
}
/* The thesis' Fig. 35 setting: a tessellated corner (floor and two walls, 3 x 33 x 33 receiver
 * vertices, 256 concentric rays each) around an occluder; RMS of the obscurance against ray casting
 * with the same rays, on the 8-bit scale (x 255), per (K, D). Plus outside-ray statistics against
 * the mesh (hit/miss disagreement, mean |d - d_exact|/R) for rays from 3R toward the mesh's box. */
#define CORNER_N 33
static void corner_points(double L, float *pts, float *nrm)
{
    int f, i, j;
    size_t p = 0;
    for (f = 0; f < 3; f++)
        for (j = 0; j < CORNER_N; j++)
            for (i = 0; i < CORNER_N; i++, p++) {
                double u = L * i / (CORNER_N - 1), v = L * j / (CORNER_N - 1);
                double x[3], n[3] = {0.0, 0.0, 0.0};
                int a;
                if (f == 0) { x[0] = u; x[1] = v; x[2] = 0.0; n[2] = 1.0; }      /* floor */
                else if (f == 1) { x[0] = 0.0; x[1] = u; x[2] = v; n[0] = 1.0; } /* wall x = 0 */
                else { x[0] = u; x[1] = 0.0; x[2] = v; n[1] = 1.0; }             /* wall y = 0 */
                for (a = 0; a < 3; a++) {
                    pts[3 * p + a] = (float)x[a];
                    nrm[3 * p + a] = (float)n[a];
                }
            }
}

typedef struct mesh_table_cell {
    double mismatch, mean_err, ao_rms, build_s;
} mesh_table_cell;

/* One table: rows ns[], columns Ds[]; returns the cells (rows x cols). */
static void mesh_table(const char *name, const hfvis_mesh *mesh, const double T[3], double L,
                       const int *ns, int rows, const int *Ds, int cols, int rays,
                       mesh_table_cell *cells)
{
    enum { P = 3 * CORNER_N * CORNER_N };
    static float pts[3 * P], nrm[3 * P], ref[P], fast[P];
    hfvis_bvh bvh;
    hfvis_visfield vf0;
    hfvis_visfield_object ob;
    hfvis_visfield_build_options bo;
    hfvis_visfield_hit *exact;
    double c[3], R, lo[3], hi[3];
    double (*org)[3], (*dir)[3];
    int a, b, q, k;
    exact = (hfvis_visfield_hit *)malloc(sizeof *exact * (size_t)rays);
    org = (double (*)[3])malloc(sizeof *org * (size_t)rays);
    dir = (double (*)[3])malloc(sizeof *dir * (size_t)rays);
    CHECK(exact && org && dir);
    if (!exact || !org || !dir) goto out;
    CHECK_EQ_STATUS(hfvis_bvh_build(mesh, NULL, &bvh), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_visfield_bounding_sphere(mesh, c, &R), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_mesh_bounds(mesh, lo, hi), HFVIS_OK);
    memset(&vf0, 0, sizeof vf0);
    for (k = 0; k < 3; k++) vf0.center[k] = c[k];
    vf0.radius = R;
    vf0.positions_n = 1;
    vf0.dir_res = 1;
    ob = make_object(&vf0, mesh, &bvh);
    for (k = 0; k < 3; k++) ob.object_to_world[12 + k] = T[k];
    corner_points(L, pts, nrm);
    CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion_reference(&ob, 1, pts, nrm, P, NULL, ref), HFVIS_OK);
    rng_state = 4242;
    for (q = 0; q < rays; q++) {
        double e[3], len;
        rng_dir(e);
        for (k = 0; k < 3; k++) {
            org[q][k] = c[k] + 3.0 * R * e[k];
            dir[q][k] = lo[k] + (hi[k] - lo[k]) * rng_unit() - org[q][k];
        }
        len = sqrt(dot3(dir[q], dir[q]));
        for (k = 0; k < 3; k++) dir[q][k] /= len;
        CHECK_EQ_STATUS(hfvis_visfield_query_reference(&vf0, mesh, &bvh, org[q], dir[q], 0.0, &exact[q]),
                        HFVIS_OK);
    }
    printf("  %s (%zu triangles) in a corner, %d receivers x 256 rays; %d outside rays:\n"
           "  hit/miss disagreement %% / mean |d - d_exact|/R / AO RMS x 255\n  %6s", name,
           mesh->triangle_count, P, rays, "K \\ D");
    for (b = 0; b < cols; b++) printf("   %16d x %-4d", Ds[b], Ds[b]);
    printf("\n");
    for (a = 0; a < rows; a++) {
        printf("  %6zu", hfvis_visfield_position_count(ns[a]));
        for (b = 0; b < cols; b++) {
            mesh_table_cell *cell = cells + a * cols + b;
            hfvis_visfield vf;
            int mism = 0, both = 0;
            size_t p;
            double sum = 0.0, rms = 0.0;
            CHECK(field_init(&vf, c, R, ns[a], Ds[b], HFVIS_DIRMAP_CONCENTRIC, HFVIS_VISFIELD_U8));
            memset(&bo, 0, sizeof bo);
            bo.bvh = &bvh;
            CHECK_EQ_STATUS(hfvis_visfield_build(mesh, &bo, &vf), HFVIS_OK);
            for (q = 0; q < rays; q++) {
                hfvis_visfield_hit h;
                hfvis_visfield_query(&vf, org[q], dir[q], 0.0, &h);
                if ((h.result == HFVIS_VISFIELD_HIT) != (exact[q].result == HFVIS_VISFIELD_HIT)) mism++;
                else if (h.result == HFVIS_VISFIELD_HIT) {
                    sum += fabs(h.distance - exact[q].distance) / R;
                    both++;
                }
            }
            ob.field = &vf;
            CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion(&ob, 1, pts, nrm, P, NULL, fast), HFVIS_OK);
            for (p = 0; p < P; p++) {
                double d = 255.0 * ((double)fast[p] - (double)ref[p]);
                rms += d * d;
            }
            cell->mismatch = (double)mism / rays;
            cell->mean_err = both ? sum / both : 0.0;
            cell->ao_rms = sqrt(rms / P);
            printf("   %5.2f%% / %.4f / %5.2f", 100.0 * cell->mismatch, cell->mean_err, cell->ao_rms);
            field_done(&vf);
        }
        printf("\n");
    }
    hfvis_bvh_free(NULL, &bvh);
out:
    free(exact);
    free(org);
    free(dir);
}

TEST(vf_table_meshes)
{
    static const int ns[3] = {4, 8, 16}, Ds[2] = {16, 32};
    const double c0[3] = {0.0, 0.0, 0.0}, Tt[3] = {1.9, 1.6, 0.0}, Tr[3] = {1.6, 1.6, 0.35};
    mesh_table_cell cells[6];
    hfvis_mesh teapot, torus;
    int b;
    CHECK_EQ_STATUS(hfvis_mesh_teapot(NULL, 2, &teapot), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_mesh_torus(NULL, c0, 1.0, 0.35, 48, 24, &torus), HFVIS_OK);
    mesh_table("teapot", &teapot, Tt, 3.6, ns, 3, Ds, 2, 10000, cells);
    for (b = 0; b < 2; b++) { /* positional samples dominate the error (Fig. 35) */
        CHECK(cells[4 + b].ao_rms < cells[b].ao_rms);
        CHECK(cells[4 + b].mismatch < cells[b].mismatch);
    }
    CHECK(cells[5].ao_rms < 8.0); /* regression bound at K = 1090, D = 32 */
    mesh_table("torus", &torus, Tr, 3.2, ns, 3, Ds, 2, 10000, cells);
    for (b = 0; b < 2; b++) {
        CHECK(cells[4 + b].ao_rms < cells[b].ao_rms);
        CHECK(cells[4 + b].mismatch < cells[b].mismatch);
    }
    CHECK(cells[5].ao_rms < 8.0);
    hfvis_mesh_free(NULL, &teapot);
    hfvis_mesh_free(NULL, &torus);
}
/* ========================================================================================== */
/* file codec                                                                                 */
/* ========================================================================================== */

static void put32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)v;
    p[1] = (unsigned char)(v >> 8);
    p[2] = (unsigned char)(v >> 16);
    p[3] = (unsigned char)(v >> 24);
}
static void put64(unsigned char *p, uint64_t v)
{
    put32(p, (uint32_t)v);
    put32(p + 4, (uint32_t)(v >> 32));
}
static void putf64(unsigned char *p, double d)
{
    uint64_t v;
    memcpy(&v, &d, 8);
    put64(p, v);
}

/* Decode must fail with `want` and leave out untouched. */
static int decode_fails(const unsigned char *data, size_t size, hfvis_status want)
{
    hfvis_visfield out;
    hfvis_status s;
    memset(&out, 0x5A, sizeof out);
    s = hfvis_visfield_decode(data, size, NULL, &out);
    if (s == HFVIS_OK) hfvis_visfield_free(NULL, &out);
    {
        unsigned char pat[sizeof out];
        memset(pat, 0x5A, sizeof pat);
        if (s != HFVIS_OK && memcmp(&out, pat, sizeof out) != 0) return 0;
    }
    return s == want;
}

TEST(vf_codec)
{
    const double c0[3] = {0.0, 0.0, 0.0};
    hfvis_mesh torus;
    int f, m, bad = 0;
    size_t cut;
    CHECK_EQ_STATUS(hfvis_mesh_torus(NULL, c0, 1.0, 0.4, 10, 6, &torus), HFVIS_OK);
    for (f = 0; f <= 4; f++)
        for (m = 0; m <= 3; m++) {
            hfvis_visfield vf, back;
            double c[3], R;
            unsigned char *buf, *bad_buf;
            size_t need, written = 0, K, t, texels;
            CHECK_EQ_STATUS(hfvis_visfield_bounding_sphere(&torus, c, &R), HFVIS_OK);
            CHECK(field_init(&vf, c, R, 1 + (f + m) % 3, 3 + m, (hfvis_dirmap)m, (hfvis_visfield_format)f));
            CHECK_EQ_STATUS(hfvis_visfield_build(&torus, NULL, &vf), HFVIS_OK);
            need = hfvis_visfield_encode_size(&vf);
            CHECK(need == HFVIS_VISFIELD_FILE_HEADER + vf.maps_size);
            buf = (unsigned char *)malloc(need + 1);
            bad_buf = (unsigned char *)malloc(need + 1);
            CHECK(buf && bad_buf);
            if (!buf || !bad_buf) { free(buf); free(bad_buf); field_done(&vf); continue; }
            memset(buf, 0x77, need + 1);
            CHECK_EQ_STATUS(hfvis_visfield_encode(&vf, buf, need - 1, &written), HFVIS_ERR_BUFFER_TOO_SMALL);
            CHECK(buf[0] == 0x77 && written == 0);
            CHECK_EQ_STATUS(hfvis_visfield_encode(&vf, buf, need, &written), HFVIS_OK);
            CHECK(written == need && buf[need] == 0x77);
            CHECK(memcmp(buf, "HFVFIELD", 8) == 0);
            CHECK(buf[12] == (f ? f : 1) && buf[16] == (m ? m : 3)); /* explicit enums */
            CHECK_EQ_STATUS(hfvis_visfield_decode(buf, need, NULL, &back), HFVIS_OK);
            if (back.maps_size != vf.maps_size || memcmp(back.maps, vf.maps, vf.maps_size) != 0
                || back.radius != vf.radius || back.avg_distance != vf.avg_distance
                || memcmp(back.center, vf.center, sizeof vf.center) != 0
                || back.positions_n != vf.positions_n || back.dir_res != vf.dir_res)
                bad++;
            hfvis_visfield_free(NULL, &back);
            CHECK(back.maps == NULL);
            /* every truncation and one trailing byte: FORMAT */
            for (cut = 0; cut < need; cut++)
                if (!decode_fails(buf, cut, HFVIS_ERR_FORMAT)) bad++;
            if (!decode_fails(buf, need + 1, HFVIS_ERR_FORMAT)) bad++;
            /* header fields */
#define MUTATE(stmt, want) do { memcpy(bad_buf, buf, need); stmt; \
        if (!decode_fails(bad_buf, need, want)) { bad++; printf("  mutation failed: %s\n", #stmt); } } while (0)
            MUTATE(bad_buf[0] = 'X', HFVIS_ERR_FORMAT);
            MUTATE(put32(bad_buf + 8, 2), HFVIS_ERR_FORMAT);
            MUTATE(put32(bad_buf + 12, 0), HFVIS_ERR_FORMAT);
            MUTATE(put32(bad_buf + 12, 5), HFVIS_ERR_FORMAT);
            MUTATE(put32(bad_buf + 16, 0), HFVIS_ERR_FORMAT);
            MUTATE(put32(bad_buf + 16, 4), HFVIS_ERR_FORMAT);
            MUTATE(put32(bad_buf + 20, 0), HFVIS_ERR_FORMAT);
            MUTATE(put32(bad_buf + 24, 0), HFVIS_ERR_FORMAT);
            MUTATE(put32(bad_buf + 28, 1), HFVIS_ERR_FORMAT);
            MUTATE(put32(bad_buf + 20, HFVIS_VISFIELD_MAX_N + 1), HFVIS_ERR_LIMIT);
            MUTATE(put32(bad_buf + 24, HFVIS_VISFIELD_MAX_DIR_RES + 1), HFVIS_ERR_LIMIT);
            MUTATE(put32(bad_buf + 20, 0xFFFFFFFFu), HFVIS_ERR_LIMIT);
            MUTATE((put32(bad_buf + 20, 1024), put32(bad_buf + 24, 4096)), HFVIS_ERR_LIMIT); /* 70 TB */
            MUTATE(put32(bad_buf + 24, (uint32_t)vf.dir_res + 2u), HFVIS_ERR_FORMAT); /* sizes disagree */
            MUTATE(putf64(bad_buf + 32, (double)NAN), HFVIS_ERR_FORMAT);
            MUTATE(putf64(bad_buf + 48, (double)INFINITY), HFVIS_ERR_FORMAT);
            MUTATE(putf64(bad_buf + 56, 0.0), HFVIS_ERR_FORMAT);
            MUTATE(putf64(bad_buf + 56, -1.0), HFVIS_ERR_FORMAT);
            MUTATE(putf64(bad_buf + 64, 1.5), HFVIS_ERR_FORMAT);
            MUTATE(putf64(bad_buf + 64, -0.1), HFVIS_ERR_FORMAT);
            MUTATE(put64(bad_buf + 72, (uint64_t)vf.maps_size + 1), HFVIS_ERR_FORMAT);
            MUTATE(put64(bad_buf + 72, ~(uint64_t)0), HFVIS_ERR_FORMAT);
            /* payload contents a build cannot produce */
            K = hfvis_visfield_position_count(vf.positions_n);
            texels = K * (size_t)vf.dir_res * (size_t)vf.dir_res;
            if (f == 2) {
                MUTATE(memcpy(bad_buf + 80, "\0\0\xc0\x7f", 4), HFVIS_ERR_FORMAT); /* NaN */
                MUTATE(memcpy(bad_buf + 80, "\0\0\0\xbf", 4), HFVIS_ERR_FORMAT);   /* -0.5 */
                MUTATE(memcpy(bad_buf + 80, "\0\0\0\x40", 4), HFVIS_ERR_FORMAT);   /* 2 */
            }
            if (f == 4) { /* a miss with a normal */
                for (t = 0; t < texels && buf[80 + 4 * t + 3] != 255; t++) {}
                if (t < texels) MUTATE(bad_buf[80 + 4 * t] = 1, HFVIS_ERR_FORMAT);
            }
            if (f == 3 && (texels & 7u)) MUTATE(bad_buf[need - 1] |= 0x80, HFVIS_ERR_FORMAT);
            if (m == 2) { /* an unused rejection texel (corner (0, 0) of map 0) holding a hit */
                if (f == 2) MUTATE(memcpy(bad_buf + 80, "\0\0\0\x3f", 4), HFVIS_ERR_FORMAT);
                else if (f == 3) MUTATE(bad_buf[80] |= 1, HFVIS_ERR_FORMAT);
                else if (f == 4) MUTATE((bad_buf[80] = 0, bad_buf[83] = 3), HFVIS_ERR_FORMAT);
                else MUTATE(bad_buf[80] = 3, HFVIS_ERR_FORMAT);
            }
#undef MUTATE
            /* file round trip */
            {
                const char *path = "/tmp/hfvis_test_vf.hfvf";
                CHECK_EQ_STATUS(hfvis_visfield_save(path, &vf), HFVIS_OK);
                CHECK_EQ_STATUS(hfvis_visfield_load(path, NULL, &back), HFVIS_OK);
                if (memcmp(back.maps, vf.maps, vf.maps_size) != 0) bad++;
                hfvis_visfield_free(NULL, &back);
                remove(path);
                CHECK_EQ_STATUS(hfvis_visfield_load(path, NULL, &back), HFVIS_ERR_IO);
                CHECK_EQ_STATUS(hfvis_visfield_save("/tmp", &vf), HFVIS_ERR_IO);
            }
            free(buf);
            free(bad_buf);
            field_done(&vf);
        }
    CHECK(bad == 0);
    CHECK_EQ_STATUS(hfvis_visfield_decode(NULL, 0, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    {
        hfvis_visfield out;
        CHECK_EQ_STATUS(hfvis_visfield_decode(NULL, 5, NULL, &out), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_visfield_decode(NULL, 0, NULL, &out), HFVIS_ERR_FORMAT);
        /* a header that claims a huge field: LIMIT from the header alone */
        {
            unsigned char h[80];
            memset(h, 0, sizeof h);
            memcpy(h, "HFVFIELD", 8);
            put32(h + 8, 1);
            put32(h + 12, 2);
            put32(h + 16, 3);
            put32(h + 20, 1000);
            put32(h + 24, 1000);
            putf64(h + 56, 1.0);
            CHECK(decode_fails(h, sizeof h, HFVIS_ERR_LIMIT));
        }
    }
    hfvis_visfield_free(NULL, NULL);
    hfvis_mesh_free(NULL, &torus);
}
/* ========================================================================================== */
/* bad arguments and failing allocations                                                      */
/* ========================================================================================== */

TEST(vf_bad_arguments)
{
    const double c0[3] = {0.0, 0.0, 0.0}, z3[3] = {0.0, 0.0, 0.0}, up[3] = {0.0, 0.0, 1.0};
    const double nan3[3] = {(double)NAN, 0.0, 1.0}, inf3[3] = {0.0, (double)INFINITY, 1.0}, down[3] = {0.0, 0.0, -1.0};
    const float pt[3] = {0.0f, 0.0f, -2.0f}, nz[3] = {0.0f, 0.0f, 1.0f}, nzero[3] = {0.0f, 0.0f, 0.0f};
    const float pnan[3] = {0.0f, NAN, 0.0f};
    hfvis_mesh ico, badmesh;
    hfvis_visfield vf, v2;
    hfvis_visfield_object ob, ob2;
    hfvis_visfield_hit hit, hit0;
    hfvis_visfield_trace_hit th[4], th0[4];
    hfvis_visfield_ao_options ao;
    hfvis_visfield_shadow_options so;
    hfvis_visfield_reflect_options ro;
    double d3[3] = {7.0, 7.0, 7.0}, r = 7.0, c[3];
    size_t k = 77;
    int i = 77, j = 77, used = 77, h = 77;
    float out = 7.0f;
    unsigned char buf[256];

    CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c0, 0.5, 1, &ico), HFVIS_OK);
    CHECK(field_init(&vf, c0, 1.0, 2, 4, HFVIS_DIRMAP_DEFAULT, HFVIS_VISFIELD_DEFAULT));
    CHECK_EQ_STATUS(hfvis_visfield_build(&ico, NULL, &vf), HFVIS_OK);

    /* samples and maps */
    CHECK_EQ_STATUS(hfvis_visfield_position(0, 0, d3), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_position(2, 26, d3), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_position(2, 0, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(d3[0] == 7.0);
    CHECK_EQ_STATUS(hfvis_visfield_nearest_position(2, z3, &k), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_nearest_position(2, nan3, &k), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_nearest_position(2, inf3, &k), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_nearest_position(0, up, &k), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_nearest_position(2, NULL, &k), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_nearest_position(2, up, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_nearest_position_naive(2, z3, &k), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_nearest_position_naive(HFVIS_VISFIELD_MAX_N + 1, up, &k), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(k == 77);
    CHECK_EQ_STATUS(hfvis_dirmap_to_local((hfvis_dirmap)4, 8, 0, 0, d3, &used), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_dirmap_to_local((hfvis_dirmap)-1, 8, 0, 0, d3, &used), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_dirmap_to_local(HFVIS_DIRMAP_POLAR, 0, 0, 0, d3, &used), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_dirmap_to_local(HFVIS_DIRMAP_POLAR, 8, 8, 0, d3, &used), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_dirmap_to_local(HFVIS_DIRMAP_POLAR, 8, 0, -1, d3, &used), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_dirmap_to_local(HFVIS_DIRMAP_POLAR, 8, 0, 0, NULL, &used), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_dirmap_to_local(HFVIS_DIRMAP_POLAR, 8, 0, 0, d3, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_dirmap_from_local(HFVIS_DIRMAP_POLAR, 8, down, &i, &j, &used), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_dirmap_from_local(HFVIS_DIRMAP_POLAR, 8, z3, &i, &j, &used), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_dirmap_from_local(HFVIS_DIRMAP_POLAR, 8, nan3, &i, &j, &used), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_dirmap_from_local(HFVIS_DIRMAP_POLAR, 8, up, NULL, &j, &used), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_dirmap_from_local(HFVIS_DIRMAP_POLAR, 8, up, &i, NULL, &used), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_dirmap_from_local((hfvis_dirmap)7, 8, up, &i, &j, &used), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_dirmap_from_local(HFVIS_DIRMAP_POLAR, HFVIS_VISFIELD_MAX_DIR_RES + 1, up, &i, &j, &used),
                    HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(d3[0] == 7.0 && i == 77 && j == 77 && used == 77);

    /* build */
    CHECK_EQ_STATUS(hfvis_visfield_bounding_sphere(NULL, c, &r), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_bounding_sphere(&ico, NULL, &r), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_bounding_sphere(&ico, c, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    badmesh = ico;
    badmesh.vertex_count = 0;
    CHECK_EQ_STATUS(hfvis_visfield_bounding_sphere(&badmesh, c, &r), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(r == 7.0);
    v2 = vf;
    v2.maps = malloc(vf.maps_size);
    CHECK(v2.maps != NULL);
    memset(v2.maps, 0x33, v2.maps_size);
#define BUILD_BAD(stmt, want) do { hfvis_visfield bw_ = v2; unsigned char chk_ = 0x33; size_t q_; int ok_ = 1; stmt; \
        CHECK_EQ_STATUS(hfvis_visfield_build(&ico, NULL, &bw_), want); \
        CHECK_EQ_STATUS(hfvis_visfield_build_reference(&ico, NULL, &bw_), want); \
        for (q_ = 0; q_ < v2.maps_size; q_++) ok_ &= ((unsigned char *)v2.maps)[q_] == chk_; \
        CHECK(ok_ && bw_.avg_distance == v2.avg_distance); } while (0)
    BUILD_BAD(bw_.radius = 0.0, HFVIS_ERR_INVALID_ARGUMENT);
    BUILD_BAD(bw_.radius = (double)NAN, HFVIS_ERR_INVALID_ARGUMENT);
    BUILD_BAD(bw_.radius = 0.4, HFVIS_ERR_INVALID_ARGUMENT);      /* the mesh is not inside */
    BUILD_BAD(bw_.center[0] = 0.6, HFVIS_ERR_INVALID_ARGUMENT);
    BUILD_BAD(bw_.center[1] = (double)INFINITY, HFVIS_ERR_INVALID_ARGUMENT);
    BUILD_BAD(bw_.positions_n = 0, HFVIS_ERR_INVALID_ARGUMENT);
    BUILD_BAD(bw_.positions_n = HFVIS_VISFIELD_MAX_N + 1, HFVIS_ERR_INVALID_ARGUMENT);
    BUILD_BAD(bw_.dir_res = -1, HFVIS_ERR_INVALID_ARGUMENT);
    BUILD_BAD(bw_.mapping = (hfvis_dirmap)9, HFVIS_ERR_INVALID_ARGUMENT);
    BUILD_BAD(bw_.format = (hfvis_visfield_format)5, HFVIS_ERR_INVALID_ARGUMENT);
    BUILD_BAD(bw_.maps_size = v2.maps_size - 1, HFVIS_ERR_BUFFER_TOO_SMALL);
    BUILD_BAD(bw_.dir_res = 5, HFVIS_ERR_BUFFER_TOO_SMALL);
    BUILD_BAD(bw_.format = HFVIS_VISFIELD_F32, HFVIS_ERR_BUFFER_TOO_SMALL);
#undef BUILD_BAD
    {
        hfvis_visfield w = v2;
        hfvis_visfield_build_options bo;
        hfvis_bvh other;
        hfvis_mesh tor;
        w.maps = NULL;
        CHECK_EQ_STATUS(hfvis_visfield_build(&ico, NULL, &w), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_visfield_build(NULL, NULL, &v2), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_visfield_build(&ico, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_visfield_build_reference(NULL, NULL, &v2), HFVIS_ERR_INVALID_ARGUMENT);
        badmesh = ico;
        badmesh.indices = NULL;
        CHECK_EQ_STATUS(hfvis_visfield_build(&badmesh, NULL, &v2), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_mesh_torus(NULL, c0, 0.3, 0.1, 5, 3, &tor), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_bvh_build(&tor, NULL, &other), HFVIS_OK);
        memset(&bo, 0, sizeof bo);
        bo.bvh = &other; /* a BVH of another mesh */
        CHECK_EQ_STATUS(hfvis_visfield_build(&ico, &bo, &v2), HFVIS_ERR_INVALID_ARGUMENT);
        hfvis_bvh_free(NULL, &other);
        hfvis_mesh_free(NULL, &tor);
    }
    free(v2.maps);
    CHECK_EQ_STATUS(hfvis_visfield_texel(&vf, 26, 0, 0, &h, &r, d3), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_texel(&vf, 0, 4, 0, &h, &r, d3), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_texel(&vf, 0, 0, -1, &h, &r, d3), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_texel(&vf, 0, 0, 0, NULL, &r, d3), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_texel(&vf, 0, 0, 0, &h, NULL, d3), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_texel(NULL, 0, 0, 0, &h, &r, d3), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(h == 77 && r == 7.0 && d3[0] == 7.0);

    /* queries */
    memset(&hit0, 0x44, sizeof hit0);
    hit = hit0;
    CHECK_EQ_STATUS(hfvis_visfield_query(NULL, c0, up, 0.0, &hit), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_query(&vf, NULL, up, 0.0, &hit), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_query(&vf, nan3, up, 0.0, &hit), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_query(&vf, c0, z3, 0.0, &hit), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_query(&vf, c0, inf3, 0.0, &hit), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_query(&vf, c0, up, -1.0, &hit), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_query(&vf, c0, up, (double)NAN, &hit), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_query(&vf, c0, up, 0.0, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    v2 = vf;
    v2.avg_distance = 2.0;
    CHECK_EQ_STATUS(hfvis_visfield_query(&v2, c0, up, 0.0, &hit), HFVIS_ERR_INVALID_ARGUMENT);
    v2 = vf;
    v2.maps_size--;
    CHECK_EQ_STATUS(hfvis_visfield_query(&v2, c0, up, 0.0, &hit), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_query_reference(&vf, NULL, NULL, c0, up, 0.0, &hit), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_query_reference(&vf, &ico, NULL, c0, z3, 0.0, &hit), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(memcmp(&hit, &hit0, sizeof hit) == 0);
    /* the reference needs only the sphere: maps may be NULL */
    v2 = vf;
    v2.maps = NULL;
    CHECK_EQ_STATUS(hfvis_visfield_query_reference(&v2, &ico, NULL, c0, up, 0.0, &hit), HFVIS_OK);

    /* scenes */
    ob = make_object(&vf, &ico, NULL);
    ao = hfvis_visfield_ao_options_default();
#define AO_BAD(stmt) do { hfvis_visfield_ao_options o_ = ao; hfvis_visfield_object b_ = ob; float r_ = 7.0f; stmt; \
        CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion(&b_, 1, pt, nz, 1, &o_, &r_), HFVIS_ERR_INVALID_ARGUMENT); \
        CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion_reference(&b_, 1, pt, nz, 1, &o_, &r_), HFVIS_ERR_INVALID_ARGUMENT); \
        CHECK(r_ == 7.0f); } while (0)
    AO_BAD(o_.rays_sqrt = -1);
    AO_BAD(o_.rays_sqrt = HFVIS_VISFIELD_MAX_RAYS_SQRT + 1);
    AO_BAD(o_.max_distance = -1.0);
    AO_BAD(o_.max_distance = (double)NAN);
    AO_BAD(o_.falloff = (hfvis_visfield_falloff)3);
    AO_BAD(o_.combine = (hfvis_visfield_combine)3);
    AO_BAD(o_.falloff = HFVIS_VISFIELD_FALLOFF_LINEAR); /* without a finite max_distance */
    AO_BAD(o_.bias = -0.1);
    AO_BAD(o_.bias = (double)INFINITY);
    AO_BAD(o_.offset = -0.1);
    AO_BAD(o_.offset = (double)NAN);
    AO_BAD(b_.object_to_world[0] = 2.0);              /* non-uniform scale */
    AO_BAD(b_.object_to_world[4] = 0.5);              /* shear */
    AO_BAD(b_.object_to_world[3] = 0.1);              /* projective row */
    AO_BAD(b_.object_to_world[15] = 2.0);
    AO_BAD(b_.object_to_world[13] = (double)NAN);
    AO_BAD(memset(b_.object_to_world, 0, sizeof b_.object_to_world); b_.object_to_world[15] = 1.0);
    AO_BAD(b_.field = NULL);
#undef AO_BAD
    ob2 = ob;
    ob2.field = &v2; /* maps NULL: the fast path needs them, the reference only the sphere */
    CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion(&ob2, 1, pt, nz, 1, NULL, &out), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(out == 7.0f);
    CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion_reference(&ob2, 1, pt, nz, 1, NULL, &out), HFVIS_OK);
    out = 7.0f;
    /* the reference needs meshes; the fast path does not */
    ob2 = ob;
    ob2.mesh = NULL;
    CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion(&ob2, 1, pt, nz, 1, NULL, &out), HFVIS_OK);
    out = 7.0f;
    CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion_reference(&ob2, 1, pt, nz, 1, NULL, &out), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion(NULL, 1, pt, nz, 1, NULL, &out), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion(&ob, 1, NULL, nz, 1, NULL, &out), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion(&ob, 1, pt, NULL, 1, NULL, &out), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion(&ob, 1, pt, nz, 1, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion(&ob, 1, pnan, nz, 1, NULL, &out), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion(&ob, 1, pt, nzero, 1, NULL, &out), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(out == 7.0f);
    CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion(NULL, 0, NULL, NULL, 0, NULL, NULL), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion(NULL, 0, pt, nz, 1, NULL, &out), HFVIS_OK);
    CHECK(out == 0.0f); /* no objects: nothing blocks */
    /* a mirror-image transform (det < 0) is rigid too */
    ob2 = ob;
    ob2.object_to_world[0] = -1.0;
    CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion(&ob2, 1, pt, nz, 1, NULL, &out), HFVIS_OK);

    memset(&so, 0, sizeof so);
    out = 7.0f;
    CHECK_EQ_STATUS(hfvis_visfield_soft_shadow(&ob, 1, pt, 1, NULL, 0.0, &so, &out), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_soft_shadow(&ob, 1, pt, 1, nan3, 0.0, &so, &out), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_soft_shadow(&ob, 1, pt, 1, up, -1.0, &so, &out), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_soft_shadow(&ob, 1, pt, 1, up, (double)INFINITY, &so, &out), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_soft_shadow(&ob, 1, pnan, 1, up, 0.0, &so, &out), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_soft_shadow(&ob, 1, NULL, 1, up, 0.0, &so, &out), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_soft_shadow(&ob, 1, pt, 1, up, 0.0, &so, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    so.samples = HFVIS_VISFIELD_MAX_SAMPLES + 1;
    CHECK_EQ_STATUS(hfvis_visfield_soft_shadow(&ob, 1, pt, 1, up, 0.0, &so, &out), HFVIS_ERR_INVALID_ARGUMENT);
    so.samples = -2;
    CHECK_EQ_STATUS(hfvis_visfield_soft_shadow_reference(&ob, 1, pt, 1, up, 0.0, &so, &out), HFVIS_ERR_INVALID_ARGUMENT);
    so.samples = 0;
    so.bias = -1.0;
    CHECK_EQ_STATUS(hfvis_visfield_soft_shadow(&ob, 1, pt, 1, up, 0.0, &so, &out), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(out == 7.0f);

    memset(th0, 0x22, sizeof th0);
    memcpy(th, th0, sizeof th);
    CHECK_EQ_STATUS(hfvis_visfield_trace(&ob, 1, NULL, up, 0.0, th), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_trace(&ob, 1, c0, z3, 0.0, th), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_trace(&ob, 1, c0, up, -0.5, th), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_trace(&ob, 1, c0, up, 0.0, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_trace(NULL, 1, c0, up, 0.0, th), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_trace_reference(&ob2, 1, c0, up, 0.0, th), HFVIS_OK);
    memcpy(th, th0, sizeof th);
    ob2.mesh = NULL;
    CHECK_EQ_STATUS(hfvis_visfield_trace_reference(&ob2, 1, c0, up, 0.0, th), HFVIS_ERR_INVALID_ARGUMENT);
    memset(&ro, 0, sizeof ro);
#define RF_BAD(stmt) do { hfvis_visfield_reflect_options o_ = ro; stmt; \
        CHECK_EQ_STATUS(hfvis_visfield_reflect(&ob, 1, c0, up, down, &o_, th), HFVIS_ERR_INVALID_ARGUMENT); \
        CHECK_EQ_STATUS(hfvis_visfield_reflect_reference(&ob, 1, c0, up, down, &o_, th), HFVIS_ERR_INVALID_ARGUMENT); \
        } while (0)
    RF_BAD(o_.rays = -1);
    RF_BAD(o_.rays = HFVIS_VISFIELD_MAX_SAMPLES + 1);
    RF_BAD(o_.shininess = -1.0);
    RF_BAD(o_.shininess = (double)NAN);
    RF_BAD(o_.bias = (double)NAN);
    RF_BAD(o_.offset = -1.0);
#undef RF_BAD
    CHECK_EQ_STATUS(hfvis_visfield_reflect(&ob, 1, c0, z3, down, NULL, th), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_reflect(&ob, 1, c0, up, z3, NULL, th), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_reflect(&ob, 1, nan3, up, down, NULL, th), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_reflect(&ob, 1, c0, up, down, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(memcmp(th, th0, sizeof th) == 0);

    /* codec */
    CHECK(hfvis_visfield_encode_size(NULL) == 0);
    CHECK(hfvis_visfield_encode_size(&v2) == 0); /* maps NULL */
    CHECK_EQ_STATUS(hfvis_visfield_encode(&vf, NULL, 256, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_encode(NULL, buf, sizeof buf, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_save(NULL, &vf), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_save("/tmp/x.hfvf", NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_load(NULL, NULL, &v2), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_visfield_load("/tmp/x.hfvf", NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    field_done(&vf);
    hfvis_mesh_free(NULL, &ico);
}

/* Every allocation of every allocating routine fails in turn: OUT_OF_MEMORY, outputs untouched,
 * nothing leaked. */
TEST(vf_out_of_memory)
{
    const double c0[3] = {0.0, 0.0, 0.0}, light[3] = {0.0, 0.0, 3.0};
    enum { P = 5 };
    float pts[3 * P], nrm[3 * P], out[P], want[P];
    hfvis_mesh ico;
    hfvis_visfield vf, ref, back;
    hfvis_visfield_object ob;
    hfvis_allocator al;
    test_counting cnt;
    unsigned char *file;
    size_t need;
    int routine, k, p;
    CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c0, 0.5, 2, &ico), HFVIS_OK);
    CHECK(field_init(&vf, c0, 1.0, 3, 6, HFVIS_DIRMAP_CONCENTRIC, HFVIS_VISFIELD_U8));
    CHECK(field_init(&ref, c0, 1.0, 3, 6, HFVIS_DIRMAP_CONCENTRIC, HFVIS_VISFIELD_U8));
    CHECK_EQ_STATUS(hfvis_visfield_build_reference(&ico, NULL, &ref), HFVIS_OK);
    need = hfvis_visfield_encode_size(&ref);
    file = (unsigned char *)malloc(need);
    CHECK(file != NULL);
    if (!file) return;
    CHECK_EQ_STATUS(hfvis_visfield_encode(&ref, file, need, NULL), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_visfield_save("/tmp/hfvis_test_vf_oom.hfvf", &ref), HFVIS_OK);
    for (p = 0; p < P; p++) {
        pts[3 * p] = (float)(0.3 * p - 0.6);
        pts[3 * p + 1] = 0.2f;
        pts[3 * p + 2] = -1.2f;
        nrm[3 * p] = nrm[3 * p + 1] = 0.0f;
        nrm[3 * p + 2] = 1.0f;
    }
    ob = make_object(&ref, &ico, NULL);
    al.alloc = test_count_alloc;
    al.free = test_count_free;
    al.user = &cnt;
    for (routine = 0; routine < 7; routine++) {
        int succeeded = 0, sites = 0;
        for (k = 1; k < 64 && !succeeded; k++) {
            hfvis_status s = HFVIS_OK;
            memset(&cnt, 0, sizeof cnt);
            cnt.fail_at = k;
            for (p = 0; p < P; p++) out[p] = 7.0f;
            memset(vf.maps, 0x66, vf.maps_size);
            vf.avg_distance = 0.0;
            memset(&back, 0x5A, sizeof back);
            switch (routine) {
            case 0: {
                hfvis_visfield_build_options bo;
                memset(&bo, 0, sizeof bo);
                bo.alloc = &al;
                s = hfvis_visfield_build(&ico, &bo, &vf);
                if (s == HFVIS_OK) CHECK(memcmp(vf.maps, ref.maps, ref.maps_size) == 0);
                else CHECK(((unsigned char *)vf.maps)[0] == 0x66 && vf.avg_distance == 0.0);
                break;
            }
            case 1:
            case 2: {
                hfvis_visfield_ao_options o = hfvis_visfield_ao_options_default();
                o.alloc = &al;
                s = routine == 1 ? hfvis_visfield_ambient_occlusion(&ob, 1, pts, nrm, P, &o, out)
                                 : hfvis_visfield_ambient_occlusion_reference(&ob, 1, pts, nrm, P, &o, out);
                if (s == HFVIS_OK) {
                    if (routine == 1) hfvis_visfield_ambient_occlusion(&ob, 1, pts, nrm, P, NULL, want);
                    else hfvis_visfield_ambient_occlusion_reference(&ob, 1, pts, nrm, P, NULL, want);
                    CHECK(memcmp(out, want, sizeof out) == 0);
                }
                break;
            }
            case 3:
            case 4: {
                hfvis_visfield_shadow_options o;
                memset(&o, 0, sizeof o);
                o.alloc = &al;
                s = routine == 3 ? hfvis_visfield_soft_shadow(&ob, 1, pts, P, light, 0.5, &o, out)
                                 : hfvis_visfield_soft_shadow_reference(&ob, 1, pts, P, light, 0.5, &o, out);
                break;
            }
            case 5:
                s = hfvis_visfield_decode(file, need, &al, &back);
                if (s == HFVIS_OK) {
                    CHECK(memcmp(back.maps, ref.maps, ref.maps_size) == 0);
                    hfvis_visfield_free(&al, &back);
                }
                break;
            default:
                s = hfvis_visfield_load("/tmp/hfvis_test_vf_oom.hfvf", &al, &back);
                if (s == HFVIS_OK) hfvis_visfield_free(&al, &back);
                break;
            }
            if (s == HFVIS_OK) {
                succeeded = 1;
            } else {
                unsigned char pat[sizeof back];
                memset(pat, 0x5A, sizeof pat);
                sites++;
                CHECK_EQ_STATUS(s, HFVIS_ERR_OUT_OF_MEMORY);
                if (routine >= 1 && routine <= 4) CHECK(out[0] == 7.0f && out[P - 1] == 7.0f);
                if (routine >= 5) CHECK(memcmp(&back, pat, sizeof back) == 0);
            }
            CHECK(cnt.live == 0 && cnt.allocs - (cnt.fail_at <= cnt.allocs) == cnt.frees);
        }
        CHECK(succeeded);
        printf("  routine %d: %d allocation sites failed cleanly\n", routine, sites);
        CHECK(sites >= (routine == 0 ? 4 : routine == 2 || routine == 4 ? 3 : routine >= 5 ? 1 : 2));
    }
    remove("/tmp/hfvis_test_vf_oom.hfvf");
    free(file);
    field_done(&vf);
    field_done(&ref);
    hfvis_mesh_free(NULL, &ico);
}
/* Regression (fuzzer find): a field whose radius squares to infinity made the sphere test produce
 * NaN entry points and a wild map index. Such spheres now give misses, never a read. */
TEST(vf_regression_huge_radius_query)
{
    const double c0[3] = {0.0, 0.0, 0.0}, up[3] = {0.0, 0.0, 1.0};
    static const double radii[3] = {1.8e184, 1e300, 1e-300};
    const float pt[3] = {0.0f, 0.0f, 0.0f}, nz[3] = {0.0f, 0.0f, 1.0f};
    hfvis_mesh ico;
    hfvis_visfield vf;
    hfvis_visfield_object ob;
    int r, q;
    float out = 7.0f;
    CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c0, 0.5, 0, &ico), HFVIS_OK);
    CHECK(field_init(&vf, c0, 1.0, 2, 4, HFVIS_DIRMAP_POLAR, HFVIS_VISFIELD_U8));
    CHECK_EQ_STATUS(hfvis_visfield_build(&ico, NULL, &vf), HFVIS_OK);
    for (r = 0; r < 3; r++) {
        vf.radius = radii[r];
        for (q = 0; q < 4; q++) {
            double o[3] = {0.3 * q, -1e200 * (q & 1), q == 3 ? 1e-310 : 2.0}, d[3] = {0.1, 0.2, -1.0};
            hfvis_visfield_hit h;
            CHECK_EQ_STATUS(hfvis_visfield_query(&vf, o, d, 0.0, &h), HFVIS_OK);
            CHECK(h.result == HFVIS_VISFIELD_MISS || h.position < hfvis_visfield_position_count(2));
            CHECK_EQ_STATUS(hfvis_visfield_query(&vf, c0, up, 0.0, &h), HFVIS_OK);
        }
        ob = make_object(&vf, &ico, NULL);
        CHECK_EQ_STATUS(hfvis_visfield_ambient_occlusion(&ob, 1, pt, nz, 1, NULL, &out), HFVIS_OK);
        CHECK(out >= 0.0f && out <= 1.0f);
    }
    field_done(&vf);
    hfvis_mesh_free(NULL, &ico);
}

/* The options added with 0.2.0's *_options_default(): a zero struct and the filled-in defaults
 * give bit-identical fields, shadows and reflections. */
TEST(vf_options_default_equals_zero)
{
    const double c0[3] = {0.0, 0.0, 0.0}, light[3] = {0.3, 0.2, 4.0};
    const double p[3] = {0.1, -0.2, -1.5}, up[3] = {0.0, 0.0, 1.0}, inc[3] = {0.3, 0.1, -1.0};
    float pts[3 * 4] = {0.0f, 0.0f, -1.5f, 0.4f, 0.1f, -1.2f, -0.9f, 0.3f, -2.0f, 2.0f, 2.0f, -1.0f};
    float sz[4], sd[4];
    hfvis_visfield_trace_hit rz[4], rd[4];
    hfvis_mesh ico;
    hfvis_bvh bvh;
    hfvis_visfield a, b;
    hfvis_visfield_object ob;
    hfvis_visfield_build_options bz, bd = hfvis_visfield_build_options_default();
    hfvis_visfield_shadow_options shz, shd = hfvis_visfield_shadow_options_default();
    hfvis_visfield_reflect_options rfz, rfd = hfvis_visfield_reflect_options_default();
    memset(&bz, 0, sizeof bz);
    memset(&shz, 0, sizeof shz);
    memset(&rfz, 0, sizeof rfz);
    CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c0, 0.5, 2, &ico), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_bvh_build(&ico, NULL, &bvh), HFVIS_OK);
    CHECK(field_init(&a, c0, 0.8, 4, 8, HFVIS_DIRMAP_CONCENTRIC, HFVIS_VISFIELD_U8));
    CHECK(field_init(&b, c0, 0.8, 4, 8, HFVIS_DIRMAP_CONCENTRIC, HFVIS_VISFIELD_U8));
    CHECK_EQ_STATUS(hfvis_visfield_build(&ico, &bz, &a), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_visfield_build(&ico, &bd, &b), HFVIS_OK);
    CHECK(a.maps_size == b.maps_size && memcmp(a.maps, b.maps, a.maps_size) == 0);
    ob = make_object(&a, &ico, &bvh);
    CHECK_EQ_STATUS(hfvis_visfield_soft_shadow(&ob, 1, pts, 4, light, 1.0, &shz, sz), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_visfield_soft_shadow(&ob, 1, pts, 4, light, 1.0, &shd, sd), HFVIS_OK);
    CHECK(memcmp(sz, sd, sizeof sz) == 0);
    memset(rz, 0, sizeof rz);
    memset(rd, 0, sizeof rd);
    CHECK_EQ_STATUS(hfvis_visfield_reflect(&ob, 1, p, up, inc, &rfz, rz), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_visfield_reflect(&ob, 1, p, up, inc, &rfd, rd), HFVIS_OK);
    CHECK(memcmp(rz, rd, sizeof rz) == 0);
    field_done(&a);
    field_done(&b);
    hfvis_bvh_free(NULL, &bvh);
    hfvis_mesh_free(NULL, &ico);
}

int main(int argc, char **argv)
{
    const char *only = argc > 1 && argv[1][0] != '-' ? argv[1] : NULL;
    TEST_INIT(argc, argv);
#define RUN_IF(name) do { if (!only || strstr(#name, only)) RUN(name); } while (0)
    RUN_IF(vf_counts);
    RUN_IF(vf_nearest_matches_naive);
    RUN_IF(vf_frame);
    RUN_IF(vf_dirmaps);
    RUN_IF(vf_sizes);
    RUN_IF(vf_sphere_in_sphere_exact);
    RUN_IF(vf_build_matches_reference);
    RUN_IF(vf_query_on_stored_rays);
    RUN_IF(vf_table_sphere);
    RUN_IF(vf_ao_form_factor);
    RUN_IF(vf_ao_convex_no_self_occlusion);
    RUN_IF(vf_ao_wall);
    RUN_IF(vf_multi_object);
    RUN_IF(vf_shadows);
    RUN_IF(vf_trace_reflect);
    RUN_IF(vf_options_default_equals_zero);
    RUN_IF(vf_table_meshes);
    RUN_IF(vf_codec);
    RUN_IF(vf_bad_arguments);
    RUN_IF(vf_out_of_memory);
    RUN_IF(vf_regression_huge_radius_query);
    return TEST_DONE();
}
