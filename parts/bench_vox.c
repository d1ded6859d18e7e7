/* bench_vox.c - surface voxelizers ([G12] ch. 6 Alg. 5/6, ch. 5 Alg. 4; spec voxel §3.4-3.7) on
 * the 100k-triangle torus knot at 128^3, 256^3, 512^3 (longest axis), each method beside
 * its per-voxel oracle in the same run; and the same voxels written into an 8x larger grid to
 * show that the cost follows the voxels written, not the grid volume. */
#define _POSIX_C_SOURCE 199309L
#include "hfvis.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double bench_vox_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Seconds of one voxelization into vol (cleared first, outside the timing); *frags = fragments. */
static double bench_vox_run(const hfvis_mesh *m, hfvis_volume *vol, const hfvis_voxelize_options *o,
                            int reference, size_t *frags)
{
    double t0, t1;
    hfvis_volume_clear(vol, 0.0f);
    t0 = bench_vox_now();
    if (reference) hfvis_voxelize_surface_reference(m, vol, o, frags);
    else hfvis_voxelize_surface(m, vol, o, frags);
    t1 = bench_vox_now();
    return t1 - t0;
}

/* Best of `reps` runs. */
static double bench_vox_best(const hfvis_mesh *m, hfvis_volume *vol, const hfvis_voxelize_options *o,
                             int reference, int reps, size_t *frags)
{
    double best = 1e30;
    int r;
    for (r = 0; r < reps; r++) {
        double t = bench_vox_run(m, vol, o, reference, frags);
        if (t < best) best = t;
    }
    return best;
}

static size_t bench_vox_occupied(const hfvis_volume *vol)
{
    size_t n = hfvis_volume_size(&vol->grid, 1), i, c = 0;
    for (i = 0; i < n; i++) c += vol->data[i * (size_t)vol->channels] != 0.0f;
    return c;
}

static void bench_vox(int quick)
{
    static const int res[3] = { 128, 256, 512 };
    static const struct {
        const char *name;
        hfvis_voxelize_method method;
        hfvis_voxelize_axes axes;
        int V;
        int with_ref;
    } rows[6] = {
        { "pixel rule, dominant", HFVIS_VOXELIZE_PIXEL_RULE, HFVIS_AXES_DOMINANT, 0, 1 },
        { "pixel rule, all axes", HFVIS_VOXELIZE_PIXEL_RULE, HFVIS_AXES_ALL, 0, 1 },
        { "GS slicing", HFVIS_VOXELIZE_GS_SLICING, HFVIS_AXES_DOMINANT, 0, 1 },
        { "GS slicing V=15", HFVIS_VOXELIZE_GS_SLICING, HFVIS_AXES_DOMINANT, 15, 0 },
        { "fragment clipping", HFVIS_VOXELIZE_FRAGMENT_CLIPPING, HFVIS_AXES_DOMINANT, 0, 1 },
        { "fragment clip. V=9", HFVIS_VOXELIZE_FRAGMENT_CLIPPING, HFVIS_AXES_DOMINANT, 9, 0 },
    };
    const double c0[3] = { 0.0, 0.0, 0.0 };
    hfvis_mesh m;
    int ri, k, nres = quick ? 1 : 3;
    if (hfvis_mesh_torus_knot(NULL, c0, 1.0, 2, 3, 2500, 20, &m) != HFVIS_OK) {
        printf("bench_vox: mesh generation failed\n");
        return;
    }
    printf("\nSurface voxelization (spec voxel §3.4-3.7), torus knot (2,3) 2500x20 = %zu triangles, "
           "1 float channel (MAX)\n", m.triangle_count);
    printf("%-22s %-12s %9s %8s %8s %10s %9s %9s | %10s %8s\n", "method", "grid", "ms", "ns/tri",
           "Mtri/s", "fragments", "Mfrag/s", "voxels", "oracle ms", "ratio");
    for (ri = 0; ri < nres; ri++) {
        hfvis_volume_grid g;
        hfvis_volume vol;
        float *st;
        char gname[32];
        if (hfvis_volume_grid_fit(&m, res[ri], 0.01, 0, &g) != HFVIS_OK) break;
        st = (float *)malloc(sizeof(float) * hfvis_volume_size(&g, 1));
        if (!st) break;
        hfvis_volume_init(&vol, &g, 1, st, HFVIS_BLEND_MAX);
        sprintf(gname, "%dx%dx%d", g.dims[0], g.dims[1], g.dims[2]);
        for (k = 0; k < 6; k++) {
            hfvis_voxelize_options o = hfvis_voxelize_options_default();
            size_t frags = 0, rfrags = 0, occ;
            double t, tr = 0.0;
            o.method = rows[k].method;
            o.axes = rows[k].axes;
            o.max_output_vertices = rows[k].V;
            t = bench_vox_best(&m, &vol, &o, 0, quick ? 1 : 3, &frags);
            occ = bench_vox_occupied(&vol);
            if (rows[k].with_ref && !quick) tr = bench_vox_best(&m, &vol, &o, 1, 1, &rfrags);
            printf("%-22s %-12s %9.2f %8.1f %8.2f %10zu %9.1f %9zu | ", rows[k].name, gname, 1e3 * t,
                   1e9 * t / (double)m.triangle_count, 1e-6 * (double)m.triangle_count / t, frags,
                   1e-6 * (double)frags / t, occ);
            if (tr > 0.0) printf("%10.2f %7.1fx%s\n", 1e3 * tr, tr / t, rfrags == frags ? "" : " (count differs!)");
            else printf("%10s %8s\n", "-", "-");
        }
        /* the same voxels in a grid 2x larger per axis (8x the volume): same cells, origin moved so
         * the mesh keeps its voxel positions */
        if (ri == 1 || quick) {
            hfvis_volume_grid big = g;
            hfvis_volume bvol;
            float *bst;
            int a;
            for (a = 0; a < 3; a++) {
                big.origin[a] -= (double)(g.dims[a] / 2) * g.cell[a];
                big.dims[a] = 2 * g.dims[a];
            }
            bst = (float *)malloc(sizeof(float) * hfvis_volume_size(&big, 1));
            if (bst && hfvis_volume_init(&bvol, &big, 1, bst, HFVIS_BLEND_MAX) == HFVIS_OK) {
                hfvis_voxelize_options o = hfvis_voxelize_options_default();
                size_t f1 = 0, f2 = 0;
                double t1 = bench_vox_best(&m, &vol, &o, 0, 3, &f1), t2 = bench_vox_best(&m, &bvol, &o, 0, 3, &f2);
                sprintf(gname, "%dx%dx%d", big.dims[0], big.dims[1], big.dims[2]);
                printf("%-22s %-12s %9.2f %8.1f %8.2f %10zu %9.1f %9s | grid 8x larger: time x%.2f, "
                       "fragments %s\n", "pixel rule, 8x grid", gname, 1e3 * t2, 1e9 * t2 / (double)m.triangle_count,
                       1e-6 * (double)m.triangle_count / t2, f2, 1e-6 * (double)f2 / t2, "", t2 / t1,
                       f1 == f2 ? "equal" : "DIFFER");
            }
            free(bst);
        }
        free(st);
    }
    hfvis_mesh_free(NULL, &m);
}

int main(void)
{
    bench_vox(0);
    return 0;
}
