/* bench_vox.c - surface voxelizers ([G12] ch. 6 Alg. 5-6, ch. 5 Alg. 4) on
 * the 100k-triangle torus knot at 128^3, 256^3, 512^3 (longest axis), each method beside
 * its per-voxel oracle in the same run; the same voxels written into an 8x larger grid (cost
 * follows the voxels written, not the grid volume); and a coarse icosphere whose large triangles
 * show what the row search saves over testing every voxel of the bounding box. */
#define _POSIX_C_SOURCE 199309L
#include "bench.h"
#include "hfvis.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Best of `reps` voxelizations into vol (cleared before each, outside the timing), seconds;
 * *frags = fragments written. */
static double bench_vox_time(const hfvis_mesh *m, hfvis_volume *vol, const hfvis_voxelize_options *o,
                             int reference, int reps, size_t *frags)
{
    double best = 1e30;
    int r;
    for (r = 0; r < reps; r++) {
        double t0, t;
        hfvis_volume_clear(vol, 0.0f);
        t0 = bench_now();
        if (reference) hfvis_voxelize_surface_reference(m, vol, o, frags);
        else hfvis_voxelize_surface(m, vol, o, frags);
        t = bench_now() - t0;
        if (t < best) best = t;
    }
    return best;
}

static size_t bench_vox_occupied(const hfvis_volume *vol)
{
    size_t n = hfvis_volume_floats(&vol->grid, 1), i, c = 0;
    for (i = 0; i < n; i++) c += vol->data[i * (size_t)vol->channels] != 0.0f;
    return c;
}

typedef struct bench_vox_row {
    const char *name;
    hfvis_voxelize_method method;
    hfvis_voxelize_axes axes;
    int V;
    int with_ref;
} bench_vox_row;

static const bench_vox_row bench_vox_rows[6] = {
    { "pixel rule, dominant", HFVIS_VOXELIZE_PIXEL_RULE, HFVIS_AXES_DOMINANT, 0, 1 },
    { "pixel rule, all axes", HFVIS_VOXELIZE_PIXEL_RULE, HFVIS_AXES_ALL, 0, 1 },
    { "GS slicing", HFVIS_VOXELIZE_GS_SLICING, HFVIS_AXES_DOMINANT, 0, 1 },
    { "GS slicing V=15", HFVIS_VOXELIZE_GS_SLICING, HFVIS_AXES_DOMINANT, 15, 0 },
    { "fragment clipping", HFVIS_VOXELIZE_FRAGMENT_CLIPPING, HFVIS_AXES_DOMINANT, 0, 1 },
    { "fragment clip. V=9", HFVIS_VOXELIZE_FRAGMENT_CLIPPING, HFVIS_AXES_DOMINANT, 9, 0 },
};

/* One table line: the method on mesh m into vol, beside its oracle when asked. */
static void bench_vox_line(const hfvis_mesh *m, hfvis_volume *vol, const bench_vox_row *row,
                           const char *gname, int reps, int with_ref)
{
    hfvis_voxelize_options o = hfvis_voxelize_options_default();
    size_t frags = 0, rfrags = 0, occ;
    double t, tr = 0.0, T = (double)m->triangle_count;
    o.method = row->method;
    o.axes = row->axes;
    o.max_output_vertices = row->V;
    t = bench_vox_time(m, vol, &o, 0, reps, &frags);
    occ = bench_vox_occupied(vol);
    if (with_ref && row->with_ref) tr = bench_vox_time(m, vol, &o, 1, reps > 1 ? 2 : 1, &rfrags);
    printf("%-21s %-11s %8.2f %7.1f %7.2f %9zu %7.1f %6.1f %8zu | ", row->name, gname, 1e3 * t, 1e9 * t / T,
           1e-6 * T / t, frags, 1e-6 * (double)frags / t, frags ? 1e9 * t / (double)frags : 0.0, occ);
    if (tr > 0.0) printf("%9.2f %6.1fx%s\n", 1e3 * tr, tr / t, rfrags == frags ? "" : " (count differs!)");
    else printf("%9s %7s\n", "-", "-");
}

static void bench_vox_header(void)
{
    printf("%-21s %-11s %8s %7s %7s %9s %7s %6s %8s | %9s %7s\n", "method", "grid", "ms", "ns/tri",
           "Mtri/s", "fragments", "Mfrag/s", "ns/fr", "voxels", "oracle ms", "ratio");
}

void bench_vox(int quick)
{
    static const int res[3] = { 128, 256, 512 };
    const double c0[3] = { 0.0, 0.0, 0.0 };
    hfvis_mesh m;
    int ri, k, nres = quick ? 1 : 3, reps = quick ? 1 : 5;
    if (hfvis_mesh_torus_knot(NULL, c0, 1.0, 2, 3, 2500, 20, &m) != HFVIS_OK) {
        printf("bench_vox: mesh generation failed\n");
        return;
    }
    printf("\nSurface voxelization ([G12] ch. 6, Alg. 5-6), torus knot (2,3) 2500x20 = %zu triangles, "
           "1 float channel (MAX); oracle = per-voxel test of each triangle's bounding box\n", m.triangle_count);
    bench_vox_header();
    for (ri = 0; ri < nres; ri++) {
        hfvis_volume_grid g;
        hfvis_volume vol;
        float *st;
        char gname[32];
        if (hfvis_volume_grid_fit(&m, res[ri], 0.01, 0, &g) != HFVIS_OK) break;
        st = (float *)malloc(sizeof(float) * hfvis_volume_floats(&g, 1));
        if (!st || hfvis_volume_init(&vol, &g, 1, st, HFVIS_BLEND_MAX) != HFVIS_OK) {
            free(st);
            break;
        }
        sprintf(gname, "%dx%dx%d", g.dims[0], g.dims[1], g.dims[2]);
        for (k = 0; k < 6; k++) bench_vox_line(&m, &vol, &bench_vox_rows[k], gname, reps, !quick);
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
            bst = (float *)malloc(sizeof(float) * hfvis_volume_floats(&big, 1));
            if (bst && hfvis_volume_init(&bvol, &big, 1, bst, HFVIS_BLEND_MAX) == HFVIS_OK) {
                hfvis_voxelize_options o = hfvis_voxelize_options_default();
                size_t f1 = 0, f2 = 0;
                double t1 = bench_vox_time(&m, &vol, &o, 0, reps, &f1);
                double t2 = bench_vox_time(&m, &bvol, &o, 0, reps, &f2);
                sprintf(gname, "%dx%dx%d", big.dims[0], big.dims[1], big.dims[2]);
                printf("%-21s %-11s %8.2f %7.1f %7.2f %9zu %7.1f %6.1f %8s | 8x grid volume: time x%.2f, "
                       "fragments %s\n", "pixel rule, 8x grid", gname, 1e3 * t2, 1e9 * t2 / (double)m.triangle_count,
                       1e-6 * (double)m.triangle_count / t2, f2, 1e-6 * (double)f2 / t2,
                       f2 ? 1e9 * t2 / (double)f2 : 0.0, "", t2 / t1, f1 == f2 ? "equal" : "DIFFER");
            }
            free(bst);
        }
        free(st);
    }
    hfvis_mesh_free(NULL, &m);

    /* large triangles: an icosphere of 1280 triangles (about 40 voxels across at 512^3) */
    if (hfvis_mesh_icosphere(NULL, c0, 1.0, 3, &m) == HFVIS_OK) {
        hfvis_volume_grid g;
        hfvis_volume vol;
        float *st = NULL;
        char gname[32];
        int r = quick ? 128 : 512;
        if (hfvis_volume_grid_fit(&m, r, 0.01, 0, &g) == HFVIS_OK
            && (st = (float *)malloc(sizeof(float) * hfvis_volume_floats(&g, 1))) != NULL
            && hfvis_volume_init(&vol, &g, 1, st, HFVIS_BLEND_MAX) == HFVIS_OK) {
            printf("Large triangles: icosphere, %zu triangles\n", m.triangle_count);
            sprintf(gname, "%dx%dx%d", g.dims[0], g.dims[1], g.dims[2]);
            for (k = 0; k < 6; k++) bench_vox_line(&m, &vol, &bench_vox_rows[k], gname, reps, !quick);
        }
        free(st);
        hfvis_mesh_free(NULL, &m);
    }
}
