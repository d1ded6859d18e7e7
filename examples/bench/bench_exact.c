/* bench_exact.c - exact rays beside the lattice and the per-receiver ray march (hfvis.h, "Exact
 * rays"): horizon maps at K = 16 on an urban DSM (boxes on flat ground, 1 m grid) and on fBm, the
 * time of each and its error against the supremum over the bilinear surface (fields_ray_max,
 * every pair: the near field and negative horizons included) on 1500 receivers; the fused
 * sky-view factor in both modes; and the sky-view factor of fBm 512^2 at K = 16, 64, 256 and 360
 * in both modes (ratio, ns per receiver-direction). */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bench.h"
#include "../fields.h"

#define EXACT_BENCH_K 16
#define EXACT_BENCH_PTS 1500

/* mean and p99 (degrees) of |value - exact| over the sampled receivers of K planes (or of the
 * march's count*K values when pts_layout). */
static void exact_err(const hfvis_grid *g, const float *v, int march, const int *px, const int *py,
                      const double *az, double *mean, double *p99)
{
    static double e[EXACT_BENCH_PTS * EXACT_BENCH_K];
    size_t n = 0, plane = (size_t)g->width * (size_t)g->height;
    int i, k;
    double s = 0.0;
    for (i = 0; i < EXACT_BENCH_PTS; i++)
        for (k = 0; k < EXACT_BENCH_K; k++) {
            double ref = fields_ray_max(g, px[i], py[i], az[k], 0.0, NULL), got;
            got = march ? v[(size_t)i * EXACT_BENCH_K + (size_t)k]
                        : v[(size_t)k * plane + (size_t)py[i] * (size_t)g->width + (size_t)px[i]];
            if (isnan(ref)) continue; /* holes only */
            e[n] = fabs((double)got - ref) * (180.0 / 3.14159265358979323846);
            s += e[n++];
        }
    qsort(e, n, sizeof(double), bench_cmp_double);
    *mean = n ? s / (double)n : 0.0;
    *p99 = n ? e[(size_t)(0.99 * (double)(n - 1))] : 0.0;
}

static void exact_field(const char *name, float *z, int n, float *map)
{
    hfvis_grid g;
    hfvis_sweep_options lat = hfvis_sweep_options_default(), ex = lat;
    static int px[EXACT_BENCH_PTS], py[EXACT_BENCH_PTS];
    static float pts[2 * EXACT_BENCH_PTS], march[EXACT_BENCH_PTS * EXACT_BENCH_K];
    double az_l[EXACT_BENCH_K], az_e[EXACT_BENCH_K], t0, tl, te, tm, ml, pl, me, pe, mm, pm, sl, se;
    double rd = (double)n * (double)n * EXACT_BENCH_K;
    uint64_t seed = 77;
    int i;
    g.z = z; g.width = n; g.height = n; g.stride = n; g.cell_size = 1.0;
    ex.rays = HFVIS_RAYS_EXACT;
    hfvis_sweep_azimuths(EXACT_BENCH_K, &lat, az_l, NULL);
    hfvis_sweep_azimuths(EXACT_BENCH_K, &ex, az_e, NULL);
    for (i = 0; i < EXACT_BENCH_PTS; i++) {
        px[i] = (int)(fields_uniform(&seed) * (double)n);
        py[i] = (int)(fields_uniform(&seed) * (double)n);
        pts[2 * i] = (float)px[i];
        pts[2 * i + 1] = (float)py[i];
    }
    t0 = bench_now();
    hfvis_horizon_map(&g, EXACT_BENCH_K, &lat, map);
    tl = bench_now() - t0;
    exact_err(&g, map, 0, px, py, az_l, &ml, &pl);
    t0 = bench_now();
    hfvis_horizon_map(&g, EXACT_BENCH_K, &ex, map);
    te = bench_now() - t0;
    exact_err(&g, map, 0, px, py, az_e, &me, &pe);
    t0 = bench_now();
    hfvis_horizon_reference(&g, EXACT_BENCH_K, &ex, NULL, pts, EXACT_BENCH_PTS, march);
    tm = (bench_now() - t0) / (EXACT_BENCH_PTS * (double)EXACT_BENCH_K);
    exact_err(&g, march, 1, px, py, az_e, &mm, &pm);
    t0 = bench_now();
    hfvis_sky_view_factor(&g, EXACT_BENCH_K, &lat, map, n);
    sl = bench_now() - t0;
    t0 = bench_now();
    hfvis_sky_view_factor(&g, EXACT_BENCH_K, &ex, map, n);
    se = bench_now() - t0;
    printf("exact rays, %s %d^2 K=%d: sky-view factor lattice %.1f ns/rd, exact %.1f ns/rd (%.2fx)\n", name, n,
           EXACT_BENCH_K, 1e9 * sl / rd, 1e9 * se / rd, se / sl);
    printf("exact rays, %s %d^2 K=%d: horizon map lattice %.1f ms (%.1f ns/rd, err mean %.3f p99 %.2f deg) | exact "
           "%.1f ms (%.1f ns/rd, %.2fx lattice, err mean %.3f p99 %.2f deg) | unit-step march %.0f ns/rd "
           "(%.0fx lattice, err mean %.3f p99 %.2f deg)\n",
           name, n, EXACT_BENCH_K, 1e3 * tl, 1e9 * tl / rd, ml, pl, 1e3 * te, 1e9 * te / rd, te / tl, me, pe,
           1e9 * tm, tm / (tl / rd), mm, pm);
}

/* Sky-view factor of fBm n^2 at K = 16, 64, 256, 360: lattice, exact and exact with the near and
 * far field (ray_near_cells = EXACT_BENCH_NEAR, then EXACT_BENCH_NEAR_SHORT), one call each (the
 * exact calls at large K take seconds; the lattice's at 512^2 about 0.1-1 s), and beside each the
 * horizons' error against the supremum (hfvis_horizon_exact_naive) on a small case of the same
 * field (EXACT_BENCH_ACC^2, every pair). */
#define EXACT_BENCH_NEAR 8
#define EXACT_BENCH_NEAR_SHORT 6
#define EXACT_BENCH_ACC 96

/* The bench's fBm on n^2 cells (amplitude n/8, wavelength n/4, seed 3) into z, as a grid of unit
 * cells. */
static hfvis_grid exact_fbm(float *z, int n)
{
    hfvis_field f;
    hfvis_grid g;
    memset(&f, 0, sizeof f);
    f.kind = HFVIS_FIELD_FBM;
    f.amplitude = (double)n / 8.0;
    f.wavelength = (double)n / 4.0;
    f.seed = 3;
    hfvis_field_generate(&f, n, n, n, z);
    g.z = z; g.width = n; g.height = n; g.stride = n; g.cell_size = 1.0;
    return g;
}

/* mean and p99 (degrees) of |a - b| over n values (NaN pairs, the holes, left out). */
static void exact_pair_err(const float *a, const float *b, size_t n, double *e, double *mean, double *p99)
{
    size_t i, m = 0;
    double s = 0.0;
    for (i = 0; i < n; i++) {
        if (isnan(a[i]) || isnan(b[i])) continue;
        e[m] = fabs((double)a[i] - (double)b[i]) * (180.0 / 3.14159265358979323846);
        s += e[m++];
    }
    qsort(e, m, sizeof(double), bench_cmp_double);
    *mean = m ? s / (double)m : 0.0;
    *p99 = m ? e[(size_t)(0.99 * (double)(m - 1))] : 0.0;
}

/* The error of the sweep and of the near and far field against the supremum at K on fBm of the
 * bench's parameters scaled to EXACT_BENCH_ACC^2; returns 0, or -1 when memory runs out. */
static int exact_far_accuracy(int K, double *sm, double *sp, double fm[2], double fp[2])
{
    const int n = EXACT_BENCH_ACC;
    size_t cells = (size_t)n * (size_t)n, m = cells * (size_t)K;
    float *z = (float *)malloc(sizeof(float) * cells), *sup = (float *)malloc(sizeof(float) * m);
    float *got = (float *)malloc(sizeof(float) * m);
    double *e = (double *)malloc(sizeof(double) * m);
    hfvis_sweep_options ex = hfvis_sweep_options_default();
    hfvis_grid g;
    int rc = -1;
    if (z && sup && got && e) {
        g = exact_fbm(z, n);
        ex.rays = HFVIS_RAYS_EXACT;
        if (hfvis_horizon_exact_naive(&g, K, &ex, sup) == HFVIS_OK && hfvis_horizon_map(&g, K, &ex, got) == HFVIS_OK) {
            exact_pair_err(got, sup, m, e, sm, sp);
            ex.ray_near_cells = EXACT_BENCH_NEAR;
            if (hfvis_horizon_map(&g, K, &ex, got) == HFVIS_OK) {
                exact_pair_err(got, sup, m, e, fm, fp);
                ex.ray_near_cells = EXACT_BENCH_NEAR_SHORT;
                if (hfvis_horizon_map(&g, K, &ex, got) == HFVIS_OK) {
                    exact_pair_err(got, sup, m, e, fm + 1, fp + 1);
                    rc = 0;
                }
            }
        }
    }
    free(z);
    free(sup);
    free(got);
    free(e);
    return rc;
}

static void exact_k_rows(int n)
{
    static const int Ks[] = {16, 64, 256, 360};
    size_t cells = (size_t)n * (size_t)n;
    float *z = (float *)malloc(sizeof(float) * cells), *out = (float *)malloc(sizeof(float) * cells);
    hfvis_sweep_options lat = hfvis_sweep_options_default(), ex = lat, nf, ns;
    hfvis_grid g;
    int i;
    if (!z || !out) { printf("exact: out of memory\n"); free(z); free(out); return; }
    g = exact_fbm(z, n);
    ex.rays = HFVIS_RAYS_EXACT;
    nf = ex;
    nf.ray_near_cells = EXACT_BENCH_NEAR;
    ns = ex;
    ns.ray_near_cells = EXACT_BENCH_NEAR_SHORT;
    for (i = 0; i < 4; i++) {
        double rd = (double)cells * (double)Ks[i], t0, tl, te, tf, ts, sm, sp, fm[2], fp[2];
        t0 = bench_now();
        hfvis_sky_view_factor(&g, Ks[i], &lat, out, n);
        tl = bench_now() - t0;
        t0 = bench_now();
        hfvis_sky_view_factor(&g, Ks[i], &ex, out, n);
        te = bench_now() - t0;
        t0 = bench_now();
        hfvis_sky_view_factor(&g, Ks[i], &nf, out, n);
        tf = bench_now() - t0;
        t0 = bench_now();
        hfvis_sky_view_factor(&g, Ks[i], &ns, out, n);
        ts = bench_now() - t0;
        printf("exact rays, fBm %d^2 sky-view factor K=%3d: lattice %.2f s (%.1f ns/rd), exact %.2f s (%.1f ns/rd), "
               "%.2fx; near/far D=%d %.2f s (%.1f ns/rd), %.2fx; D=%d %.2f s (%.1f ns/rd), %.2fx\n", n, Ks[i], tl,
               1e9 * tl / rd, te, 1e9 * te / rd, te / tl, EXACT_BENCH_NEAR, tf, 1e9 * tf / rd, tf / tl,
               EXACT_BENCH_NEAR_SHORT, ts, 1e9 * ts / rd, ts / tl);
        if (exact_far_accuracy(Ks[i], &sm, &sp, fm, fp) == 0)
            printf("exact rays, fBm %d^2 horizons K=%3d against the supremum (every pair, deg): exact mean %.4f p99 "
                   "%.3f; near/far D=%d mean %.4f p99 %.3f; D=%d mean %.4f p99 %.3f\n", EXACT_BENCH_ACC, Ks[i], sm, sp,
                   EXACT_BENCH_NEAR, fm[0], fp[0], EXACT_BENCH_NEAR_SHORT, fm[1], fp[1]);
        else
            printf("exact rays: accuracy at K=%d: out of memory\n", Ks[i]);
    }
    free(z);
    free(out);
}

void bench_exact(int quick)
{
    int sizes[2] = {512, 1024}, s;
    for (s = 0; s < 2; s++) {
        int n = quick ? sizes[s] / 4 : sizes[s];
        size_t cells = (size_t)n * (size_t)n;
        float *z = (float *)malloc(sizeof(float) * cells);
        float *map = (float *)malloc(sizeof(float) * cells * EXACT_BENCH_K);
        if (!z || !map) { printf("exact: out of memory\n"); free(z); free(map); return; }
        fields_urban(z, n, n, (int)(260.0 * (double)cells / (512.0 * 512.0)), 5);
        exact_field("urban", z, n, map);
        (void)exact_fbm(z, n);
        exact_field("fBm", z, n, map);
        free(z);
        free(map);
    }
    exact_k_rows(quick ? 128 : 512);
}
