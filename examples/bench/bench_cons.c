/* bench_cons.c - binary voxelizers: conservative fast path beside its per-voxel SAT baseline
 * (hfvis_voxelize_conservative_reference), solid (parity) and bitmask, on the issue's
 * 100k-triangle torus knot at 128^3, 256^3, 512^3 and on a large-triangle mesh (icosphere, 2
 * subdivisions, 320 triangles) at 256^3. Grids: hfvis_volume_grid_fit(mesh, N, 0.01, cubic = 0).
 * At 256^3 also the knot in an 8x grid volume and the floors of issue 4's 20x target
 * (bench_cons_floors). Times are the best of a few runs (CLOCK_MONOTONIC); the baseline runs
 * once at 512^3. */
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

/* Grid-space coordinate of vertex coordinate x on axis a (the library's expression). */
static double bench_cons_gc(const hfvis_volume_grid *g, int a, float x)
{
    return ((double)x - g->origin[a]) / g->cell[a];
}

/* Bit index of an isolated bit times the de Bruijn constant 0x03f79d71b4cb0a89, top 6 bits. */
static const unsigned char bench_cons_debruijn[64] = {
    0,  1,  48, 2,  57, 49, 28, 3,  61, 58, 50, 42, 38, 29, 17, 4,  62, 55, 59, 36, 53, 51,
    43, 22, 45, 39, 33, 30, 24, 18, 12, 5,  63, 47, 56, 27, 60, 41, 37, 16, 54, 35, 52, 21,
    44, 32, 23, 11, 46, 26, 40, 15, 34, 20, 31, 10, 25, 14, 19, 9,  13, 8,  7,  6};

/* Floors of any exact voxelizer with this interface on this mesh (issue 4's 20x target): the
 * best time of (a) clearing the byte grid, (b) the vertices in grid space (the doubles the SAT
 * sees), (c) a pass over the triangles that loads them and computes the SAT's normal and the
 * bounding-box ranges, (d) setting every triangle's SAT voxels (from a precomputed list, so no
 * decision at all) as bits in a zeroed bit grid and then writing the bytes of the set ones. tr = baseline
 * time; the sum is compared with tr / 20. */
static void bench_cons_floors(const hfvis_mesh *m, const hfvis_volume_grid *g, double tr)
{
    static const double half[3] = {0.5, 0.5, 0.5};
    size_t nv = (size_t)g->dims[0] * (size_t)g->dims[1] * (size_t)g->dims[2], nw = (nv + 63) / 64;
    size_t nhit = 0, cap = (size_t)16 * m->triangle_count, t, i;
    uint32_t *hit = (uint32_t *)malloc(cap * sizeof(uint32_t));
    double *gv = (double *)malloc(3 * m->vertex_count * sizeof(double)), best[4], sum = 0.0;
    uint64_t *bits = (uint64_t *)malloc(nw * sizeof(uint64_t));
    uint8_t *occ = (uint8_t *)malloc(nv);
    volatile double sink = 0.0;
    int r, a, k;
    if (!hit || !gv || !bits || !occ) goto done;
    for (i = 0; i < 3 * m->vertex_count; i++) gv[i] = bench_cons_gc(g, (int)(i % 3), m->xyz[i]);
    for (t = 0; t < m->triangle_count; t++) { /* the SAT voxels of each triangle */
        const double *v[3];
        int lo[3], hi[3], q[3];
        for (k = 0; k < 3; k++) v[k] = gv + 3 * (size_t)m->indices[3 * t + (size_t)k];
        for (a = 0; a < 3; a++) {
            double mn = v[0][a], mx = v[0][a];
            for (k = 1; k < 3; k++) {
                mn = v[k][a] < mn ? v[k][a] : mn;
                mx = v[k][a] > mx ? v[k][a] : mx;
            }
            lo[a] = (int)(ceil(mn) - 1.0 > 0.0 ? ceil(mn) - 1.0 : 0.0);
            hi[a] = (int)(floor(mx) < g->dims[a] - 1.0 ? floor(mx) : g->dims[a] - 1.0);
        }
        for (q[2] = lo[2]; q[2] <= hi[2]; q[2]++)
            for (q[1] = lo[1]; q[1] <= hi[1]; q[1]++)
                for (q[0] = lo[0]; q[0] <= hi[0]; q[0]++) {
                    double c[3];
                    c[0] = q[0] + 0.5;
                    c[1] = q[1] + 0.5;
                    c[2] = q[2] + 0.5;
                    if (nhit < cap && hfvis_triangle_box_overlap(c, half, v[0], v[1], v[2]))
                        hit[nhit++] = (uint32_t)(((size_t)q[2] * (size_t)g->dims[1] + (size_t)q[1])
                                                     * (size_t)g->dims[0] + (size_t)q[0]);
                }
    }
    for (k = 0; k < 4; k++) best[k] = 1e30;
    for (r = 0; r < 3; r++) {
        double t0 = bench_now(), acc = 0.0;
        memset(occ, 0, nv);
        sink = occ[nv / 2];
        best[0] = fmin(best[0], bench_now() - t0);
        t0 = bench_now();
        for (i = 0; i < 3 * m->vertex_count; i++) gv[i] = bench_cons_gc(g, (int)(i % 3), m->xyz[i]);
        sink = gv[m->vertex_count];
        best[1] = fmin(best[1], bench_now() - t0);
        t0 = bench_now();
        for (t = 0; t < m->triangle_count; t++) {
            const double *p0 = gv + 3 * (size_t)m->indices[3 * t], *p1 = gv + 3 * (size_t)m->indices[3 * t + 1];
            const double *p2 = gv + 3 * (size_t)m->indices[3 * t + 2];
            double f0[3], f1[3], n[3];
            int lo = 0, hi = 0;
            for (a = 0; a < 3; a++) {
                double mn = p0[a] < p1[a] ? p0[a] : p1[a], mx = p0[a] > p1[a] ? p0[a] : p1[a];
                mn = p2[a] < mn ? p2[a] : mn;
                mx = p2[a] > mx ? p2[a] : mx;
                f0[a] = p1[a] - p0[a];
                f1[a] = p2[a] - p1[a];
                lo += (int)mn;
                hi += (int)mx;
            }
            n[0] = f0[1] * f1[2] - f0[2] * f1[1];
            n[1] = f0[2] * f1[0] - f0[0] * f1[2];
            n[2] = f0[0] * f1[1] - f0[1] * f1[0];
            if (n[0] != 0.0 || n[1] != 0.0 || n[2] != 0.0) acc += n[0] + n[1] + n[2] + lo + hi;
        }
        sink = acc;
        best[2] = fmin(best[2], bench_now() - t0);
        t0 = bench_now();
        memset(bits, 0, nw * sizeof(uint64_t));
        for (i = 0; i < nhit; i++) bits[hit[i] >> 6] |= (uint64_t)1 << (hit[i] & 63);
        for (i = 0; i < nw; i++) { /* occ was cleared by (a) */
            uint64_t w = bits[i];
            while (w) {
                occ[i * 64 + bench_cons_debruijn[((w & (0u - w)) * 0x03f79d71b4cb0a89ull) >> 58]] = 1;
                w &= w - 1;
            }
        }
        best[3] = fmin(best[3], bench_now() - t0);
    }
    (void)sink;
    for (k = 0; k < 4; k++) sum += best[k];
    printf("  floors: clear bytes %.2f ms, vertices %.2f ms, per-triangle load + normal + bbox %.2f ms, "
           "%.2f SAT voxels per triangle set from a list + bytes written %.2f ms; sum %.2f ms vs "
           "baseline / 20 = %.2f ms\n",
           1e3 * best[0], 1e3 * best[1], 1e3 * best[2], (double)nhit / (double)m->triangle_count,
           1e3 * best[3], 1e3 * sum, 1e3 * tr / 20.0);
done:
    free(hit);
    free(gv);
    free(bits);
    free(occ);
}

/* The fast path's own overhead when nothing is left to set: the mesh listed twice, so each
 * triangle of the second copy finds every candidate column that lies in the result already set
 * (those partly outside it are decided again). The second copy's time is the per-triangle
 * setup, rows and column checks alone, to compare with the 20x budget. */
static void bench_cons_twice(const hfvis_mesh *m, const hfvis_volume_grid *g, double tf, double tr)
{
    size_t nv = (size_t)g->dims[0] * (size_t)g->dims[1] * (size_t)g->dims[2], n2 = 0;
    uint32_t *idx = (uint32_t *)malloc(6 * m->triangle_count * sizeof(uint32_t));
    uint8_t *occ = (uint8_t *)malloc(nv);
    hfvis_mesh twice = *m;
    double t2;
    if (idx && occ) {
        memcpy(idx, m->indices, 3 * m->triangle_count * sizeof(uint32_t));
        memcpy(idx + 3 * m->triangle_count, m->indices, 3 * m->triangle_count * sizeof(uint32_t));
        twice.indices = idx;
        twice.triangle_count = 2 * m->triangle_count;
        t2 = bench_cons_time(hfvis_voxelize_conservative, &twice, g, occ, &n2, 3);
        printf("  the mesh listed twice: %.2f ms, so the second copy (all its voxels set already) "
               "costs %.2f ms = %.1f ns/triangle, vs baseline / 20 = %.2f ms\n",
               1e3 * t2, 1e3 * (t2 - tf), 1e9 * (t2 - tf) / (double)m->triangle_count, 1e3 * tr / 20.0);
    }
    free(idx);
    free(occ);
}

static void bench_cons_row(const char *what, int res, double secs, size_t tris, size_t voxels,
                           double base)
{
    printf("  %-28s %4d^3 %9.2f ms %8.2f Mtri/s %8.2f Mvox/s %8.1f ns/tri", what, res, 1e3 * secs,
           1e-6 * (double)tris / secs, 1e-6 * (double)voxels / secs, 1e9 * secs / (double)tris);
    if (base > 0.0) printf("   x%.2f", base / secs);
    printf("\n");
}

/* One mesh at one resolution: conservative fast and baseline (and, with floors, the same mesh
 * in an 8x grid volume and the floors of bench_cons_floors), solid, bitmask. */
static void bench_cons_case(const char *name, const hfvis_mesh *m, int res, int quick, int floors)
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
    if (floors) {
        /* the same voxels in a grid 2x larger per axis (8x the volume), mesh in its middle:
         * cost should follow the voxels written, not the grid */
        hfvis_volume_grid g8 = g;
        size_t nv8, n8 = 0;
        uint8_t *c8;
        int ax;
        for (ax = 0; ax < 3; ax++) {
            g8.origin[ax] -= (double)(g.dims[ax] / 2) * g.cell[ax]; /* whole cells */
            g8.dims[ax] *= 2;
        }
        nv8 = (size_t)g8.dims[0] * (size_t)g8.dims[1] * (size_t)g8.dims[2];
        c8 = (uint8_t *)malloc(nv8);
        if (c8) {
            double t8 = bench_cons_time(hfvis_voxelize_conservative, m, &g8, c8, &n8, reps);
            printf("  same knot in an 8x grid volume (%d x %d x %d): %.2f ms, time x%.2f, %zu voxels\n",
                   g8.dims[0], g8.dims[1], g8.dims[2], 1e3 * t8, t8 / tf, n8);
            free(c8);
        }
        bench_cons_floors(m, &g, tr);
        bench_cons_twice(m, &g, tf, tr);
    }
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
    for (r = 0; r < (quick ? 1 : 3); r++)
        bench_cons_case("torus knot (2,3)", &knot, res[r], quick, res[r] == 256);
    hfvis_mesh_free(NULL, &knot);
    if (hfvis_mesh_icosphere(NULL, c, 1.0, 2, &ico) != HFVIS_OK) return;
    bench_cons_case("icosphere (2 subdivisions)", &ico, quick ? 128 : 256, quick, 0);
    hfvis_mesh_free(NULL, &ico);
}
