/* bench_cons.c - binary voxelizers: conservative fast path beside its per-voxel SAT baseline
 * (hfvis_voxelize_conservative_reference), solid (parity) and bitmask, on the issue's
 * 100k-triangle torus knot at 128^3, 256^3, 512^3 and on a large-triangle mesh (icosphere, 2
 * subdivisions, 320 triangles) at 256^3. Grids: hfvis_volume_grid_fit(mesh, N, 0.01, cubic = 0).
 * Times are the best of a few runs (CLOCK_MONOTONIC); the baseline runs once at 512^3. */
#define _POSIX_C_SOURCE 199309L
#include "bench.h"
#include "hfvis.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef hfvis_status (*bench_cons_fn)(const hfvis_mesh *, const hfvis_volume_grid *,
                                      const hfvis_binary_voxel_options *, uint8_t *, size_t *);

static hfvis_status bench_cons_bitmask(const hfvis_mesh *m, const hfvis_volume_grid *g,
                                       const hfvis_binary_voxel_options *o, uint8_t *out,
                                       size_t *n)
{
    return hfvis_voxelize_bitmask(m, g, o, (uint32_t *)(void *)out, n);
}

/* Best time (s) of reps runs of fn; *count = voxels set. */
static double bench_cons_time(bench_cons_fn fn, const hfvis_mesh *m, const hfvis_volume_grid *g,
                              uint8_t *out, size_t *count, int reps)
{
    double best = 1e30;
    int r;
    for (r = 0; r < reps; r++) {
        double t = bench_now();
        if (fn(m, g, NULL, out, count) != HFVIS_OK) return -1.0;
        t = bench_now() - t;
        if (t < best) best = t;
    }
    return best;
}

/* Candidate voxels of the baseline: the sum over triangles of their bounding-box ranges
 * (i from ceil(min) - 1 to floor(max), clipped to the grid), i.e. its SAT calls. */
static double bench_cons_bbox_voxels(const hfvis_mesh *m, const hfvis_volume_grid *g)
{
    double sum = 0.0;
    size_t t;
    for (t = 0; t < m->triangle_count; t++) {
        double vol = 1.0;
        int a, k;
        for (a = 0; a < 3; a++) {
            double mn = 1e300, mx = -1e300, lo, hi;
            for (k = 0; k < 3; k++) {
                double c = ((double)m->xyz[3 * m->indices[3 * t + (size_t)k] + (size_t)a] - g->origin[a]) / g->cell[a];
                mn = c < mn ? c : mn;
                mx = c > mx ? c : mx;
            }
            lo = ceil(mn) - 1.0;
            hi = floor(mx);
            if (lo < 0.0) lo = 0.0;
            if (hi > g->dims[a] - 1.0) hi = g->dims[a] - 1.0;
            vol *= hi >= lo ? hi - lo + 1.0 : 0.0;
        }
        sum += vol;
    }
    return sum;
}

static void bench_cons_row(const char *what, int res, double secs, size_t tris, size_t voxels,
                           double base)
{
    printf("  %-28s %4d^3 %9.2f ms %8.2f Mtri/s %8.2f Mvox/s %8.1f ns/tri", what, res, 1e3 * secs,
           1e-6 * (double)tris / secs, 1e-6 * (double)voxels / secs, 1e9 * secs / (double)tris);
    if (base > 0.0) printf("   x%.2f", base / secs);
    printf("\n");
}

/* One mesh at one resolution: conservative fast and baseline, solid, bitmask. */
static void bench_cons_case(const char *name, const hfvis_mesh *m, int res, int quick)
{
    hfvis_volume_grid g;
    size_t nv, nf = 0, nr = 0, ns = 0, nb = 0, words;
    uint8_t *a, *b;
    double tf, tr, ts, tb, bbox;
    int reps = quick ? 1 : 3;
    if (hfvis_volume_grid_fit(m, res, 0.01, 0, &g) != HFVIS_OK) return;
    nv = (size_t)g.dims[0] * (size_t)g.dims[1] * (size_t)g.dims[2];
    words = hfvis_bitmask_words(&g) * sizeof(uint32_t);
    a = (uint8_t *)malloc(nv > words ? nv : words);
    b = (uint8_t *)malloc(nv);
    if (!a || !b) {
        free(a);
        free(b);
        return;
    }
    bbox = bench_cons_bbox_voxels(m, &g);
    tf = bench_cons_time(hfvis_voxelize_conservative, m, &g, a, &nf, reps);
    tr = bench_cons_time(hfvis_voxelize_conservative_reference, m, &g, b, &nr,
                         (quick || res >= 512) ? 1 : 2);
    printf("%s, %zu triangles, grid %d x %d x %d: %.1f baseline SAT calls per triangle, "
           "%zu conservative voxels, fast %s baseline\n",
           name, m->triangle_count, g.dims[0], g.dims[1], g.dims[2], bbox / (double)m->triangle_count,
           nf, (nf == nr && memcmp(a, b, nv) == 0) ? "==" : "!=");
    bench_cons_row("conservative (fast)", res, tf, m->triangle_count, nf, tr);
    bench_cons_row("conservative baseline (SAT)", res, tr, m->triangle_count, nr, 0.0);
    ts = bench_cons_time(hfvis_voxelize_solid, m, &g, a, &ns, reps);
    if (ts > 0.0) bench_cons_row("solid (parity)", res, ts, m->triangle_count, ns, 0.0);
    tb = bench_cons_time(bench_cons_bitmask, m, &g, a, &nb, reps);
    bench_cons_row("bitmask (3 axes)", res, tb, m->triangle_count, nb, 0.0);
    free(a);
    free(b);
}

void bench_cons(int quick)
{
    static const double c[3] = {0.0, 0.0, 0.0};
    static const int res[3] = {128, 256, 512};
    hfvis_mesh knot, ico;
    int r;
    printf("binary voxelizers (ratio = baseline time / fast time; fast == baseline voxel for voxel)\n");
    if (hfvis_mesh_torus_knot(NULL, c, 1.0, 2, 3, 2500, 20, &knot) != HFVIS_OK) return;
    for (r = 0; r < (quick ? 1 : 3); r++) bench_cons_case("torus knot (2,3)", &knot, res[r], quick);
    hfvis_mesh_free(NULL, &knot);
    if (hfvis_mesh_icosphere(NULL, c, 1.0, 2, &ico) != HFVIS_OK) return;
    bench_cons_case("icosphere (2 subdivisions)", &ico, quick ? 128 : 256, quick);
    hfvis_mesh_free(NULL, &ico);
}
