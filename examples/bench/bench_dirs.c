/* bench_dirs.c - direction ranges (README "Splitting work across processes"): the sky-view factor
 * of an fBm terrain, K = 16, as one fused run beside a 4-way split in sweep order
 * (hfvis_direction_sums on each part, then the parts added and finished as SVF = 1 - S/K): the
 * time per part, whether the split's cost adds up to the single run's, and the largest difference
 * of the finished values (0 when every part is whole quarter-turn groups). */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bench.h"

void bench_dirs(int quick)
{
    int n = quick ? 256 : 1024, K = 16, P = 4, p;
    size_t i, cells = (size_t)n * (size_t)n;
    float *z = (float *)malloc(sizeof(float) * cells), *svf = (float *)malloc(sizeof(float) * cells);
    double *part = (double *)malloc(sizeof(double) * cells), *sum = (double *)calloc(cells, sizeof(double));
    double t0, t_single, t_parts = 0.0, t_max = 0.0, maxdiff = 0.0;
    hfvis_field f;
    hfvis_grid g;
    hfvis_sweep_options o = hfvis_sweep_options_default();
    if (!z || !svf || !part || !sum) { printf("dirs: out of memory\n"); goto done; }
    memset(&f, 0, sizeof f);
    f.kind = HFVIS_FIELD_FBM;
    f.amplitude = (double)n / 8.0;
    f.wavelength = (double)n / 4.0;
    f.seed = 3;
    g.z = z; g.width = n; g.height = n; g.stride = n; g.cell_size = 1.0;
    if (hfvis_field_generate(&f, n, n, n, z) != HFVIS_OK) { printf("dirs: field failed\n"); goto done; }
    t0 = bench_now();
    if (hfvis_sky_view_factor(&g, K, &o, svf, n) != HFVIS_OK) { printf("dirs: svf failed\n"); goto done; }
    t_single = bench_now() - t0;
    o.direction_order = HFVIS_DIRECTION_ORDER_SWEEP;
    for (p = 0; p < P; p++) {
        double t;
        o.direction_begin = p * K / P;
        o.direction_end = (p + 1) * K / P;
        t0 = bench_now();
        if (hfvis_direction_sums(&g, K, HFVIS_SUM_SKY_VIEW, NULL, NULL, &o, part) != HFVIS_OK) {
            printf("dirs: direction_sums failed\n");
            goto done;
        }
        t = bench_now() - t0;
        t_parts += t;
        if (t > t_max) t_max = t;
        for (i = 0; i < cells; i++) sum[i] += part[i];
    }
    for (i = 0; i < cells; i++) {
        double d = fabs((double)(float)(1.0 - sum[i] / K) - (double)svf[i]);
        if (d > maxdiff) maxdiff = d;
    }
    printf("direction split, sky-view factor %d^2 K=%d: single run %.1f ms (%.2f ns/rd); %d parts in sweep "
           "order %.1f ms in all (%.2fx the single run), slowest part %.1f ms (%.2fx faster wall-clock with "
           "%d processes); max |split - single| %.3g\n",
           n, K, 1e3 * t_single, 1e9 * t_single / ((double)cells * K), P, 1e3 * t_parts, t_parts / t_single,
           1e3 * t_max, t_single / t_max, P, maxdiff);
done:
    free(z); free(svf); free(part); free(sum);
}
