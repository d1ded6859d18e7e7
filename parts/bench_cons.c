#define _POSIX_C_SOURCE 199309L
#include "hfvis.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double bench_cons_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void bench_cons(int quick)
{
    static const double c[3] = {0.0, 0.0, 0.0};
    hfvis_mesh knot;
    int res[3] = {128, 256, 512}, r;
    (void)quick;
    if (hfvis_mesh_torus_knot(NULL, c, 1.0, 2, 3, 2500, 20, &knot) != HFVIS_OK) return;
    for (r = 0; r < 3; r++) {
        hfvis_volume_grid g;
        uint8_t *a, *b;
        size_t na = 0, nb = 0, nv, i, diff = 0;
        double t0, t1, t2;
        hfvis_volume_grid_fit(&knot, res[r], 0.01, 0, &g);
        nv = (size_t)g.dims[0] * g.dims[1] * g.dims[2];
        a = malloc(nv);
        b = malloc(nv);
        {
            double best = 1e9, bestr = 1e9, x;
            int rep;
            for (rep = 0; rep < 3; rep++) {
                x = bench_cons_now();
                hfvis_voxelize_conservative(&knot, &g, NULL, a, &na);
                x = bench_cons_now() - x;
                if (x < best) best = x;
            }
            for (rep = 0; rep < 2; rep++) {
                x = bench_cons_now();
                hfvis_voxelize_conservative_reference(&knot, &g, NULL, b, &nb);
                x = bench_cons_now() - x;
                if (x < bestr) bestr = x;
            }
            t0 = 0; t1 = best; t2 = best + bestr;
        }
        for (i = 0; i < nv; i++) diff += a[i] != b[i];
        printf("%d^3 (%dx%dx%d): fast %.1f ms, ref %.1f ms, ratio %.1f, voxels %zu %zu diff %zu\n",
               res[r], g.dims[0], g.dims[1], g.dims[2], 1e3 * (t1 - t0), 1e3 * (t2 - t1),
               (t2 - t1) / (t1 - t0), na, nb, diff);
        free(a);
        free(b);
    }
    hfvis_mesh_free(NULL, &knot);
}

int main(void)
{
    bench_cons(0);
    return 0;
}
