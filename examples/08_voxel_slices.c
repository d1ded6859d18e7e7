/* 08_voxel_slices.c - voxelize a torus and the teapot-like test mesh three ways (surface by the
 * thesis' pixel-centre rule, conservative, solid) and write horizontal slices as PGM montages:
 * each image holds 8 z-slices side by side, bottom slice left; white = occupied voxel. The PNG
 * twins show the same slices twice as large, four to a row.
 * Usage: 08_voxel_slices [OUTDIR]   (default "out") */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common.h"

#define SLICES 8

/* Montage of SLICES evenly spaced z-slices of occ (dims d) into one PGM of (SLICES*d0) x d1,
 * row 0 = largest y so the picture is seen from above with y up; and its PNG twin, the slices
 * at twice the size in rows of 4. */
static hfvis_status save_slices(const char *dir, const char *name, const unsigned char *occ,
                                const int d[3])
{
    int w = SLICES * d[0], h = d[1], s, x, y;
    size_t n = strlen(name), big = (size_t)4 * (size_t)d[0] * (size_t)d[1];
    float *img = (float *)malloc(sizeof(float) * (size_t)w * (size_t)h);
    float *zoom = (float *)malloc(sizeof(float) * SLICES * big);
    ex_panel panels[SLICES];
    char png[256];
    hfvis_status st;
    if (!img || !zoom) {
        free(img);
        free(zoom);
        ex_report(name, HFVIS_ERR_OUT_OF_MEMORY);
        return HFVIS_ERR_OUT_OF_MEMORY;
    }
    for (s = 0; s < SLICES; s++) {
        int k = (int)(((double)s + 0.5) * d[2] / SLICES);
        for (y = 0; y < h; y++)
            for (x = 0; x < d[0]; x++) {
                size_t lin = ((size_t)k * (size_t)d[1] + (size_t)(h - 1 - y)) * (size_t)d[0] + (size_t)x;
                float *z2 = zoom + (size_t)s * big + (size_t)(2 * y) * (size_t)(2 * d[0]) + (size_t)(2 * x);
                /* a dark line between slices */
                img[(size_t)y * (size_t)w + (size_t)(s * d[0] + x)] =
                    x == 0 && s > 0 ? 0.25f : (float)occ[lin];
                z2[0] = z2[1] = z2[2 * d[0]] = z2[2 * d[0] + 1] = (float)occ[lin];
            }
        panels[s].pixels = zoom + (size_t)s * big, panels[s].lo = 0.0f, panels[s].hi = 1.0f;
    }
    st = ex_save_pgm(dir, name, img, w, h, w, 0.0f, 1.0f);
    if (st == HFVIS_OK && n > 4 && n < sizeof png) {
        memcpy(png, name, n - 4);
        memcpy(png + n - 4, ".png", 5);
        st = ex_save_png_sheet(dir, png, panels, SLICES, 4, 2 * d[0], 2 * d[1], 1);
    }
    free(img);
    free(zoom);
    return st;
}

static int voxelize_three_ways(const char *dir, const char *stem, const hfvis_mesh *mesh, int res,
                               int closed)
{
    hfvis_volume_grid grid;
    unsigned char *occ = NULL;
    char name[256];
    size_t count = 0, n;
    EX_CHECK(hfvis_volume_grid_fit(mesh, res, 0.02, 1, &grid), "grid fit");
    n = (size_t)grid.dims[0] * (size_t)grid.dims[1] * (size_t)grid.dims[2];
    occ = (unsigned char *)malloc(n);
    if (!occ) return ex_report(stem, HFVIS_ERR_OUT_OF_MEMORY);
    EX_CHECK(hfvis_voxelize_occupancy(mesh, &grid, NULL, occ), "surface voxelization");
    snprintf(name, sizeof name, "08_%s_surface.pgm", stem);
    if (save_slices(dir, name, occ, grid.dims) != HFVIS_OK) goto fail;
    EX_CHECK(hfvis_voxelize_conservative(mesh, &grid, NULL, occ, &count), "conservative");
    snprintf(name, sizeof name, "08_%s_conservative.pgm", stem);
    if (save_slices(dir, name, occ, grid.dims) != HFVIS_OK) goto fail;
    printf("%s: %zu triangles, %d x %d x %d grid, %zu conservative voxels\n", stem,
           mesh->triangle_count, grid.dims[0], grid.dims[1], grid.dims[2], count);
    if (closed) {
        EX_CHECK(hfvis_voxelize_solid(mesh, &grid, NULL, occ, &count), "solid voxelization");
        snprintf(name, sizeof name, "08_%s_solid.pgm", stem);
        if (save_slices(dir, name, occ, grid.dims) != HFVIS_OK) goto fail;
        printf("%s: %zu solid voxels\n", stem, count);
    }
    free(occ);
    return 0;
fail:
    free(occ);
    return 1;
}

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "out";
    const double centre[3] = {0.0, 0.0, 0.0};
    hfvis_mesh torus, teapot;
    int rc;
    memset(&torus, 0, sizeof torus);
    memset(&teapot, 0, sizeof teapot);
    EX_CHECK(hfvis_mesh_torus(NULL, centre, 1.0, 0.4, 64, 32, &torus), "torus");
    EX_CHECK(hfvis_mesh_teapot(NULL, 16, &teapot), "teapot");
    rc = voxelize_three_ways(dir, "torus", &torus, 64, 1);
    if (rc == 0) rc = voxelize_three_ways(dir, "teapot", &teapot, 96, 0);
    hfvis_mesh_free(NULL, &torus);
    hfvis_mesh_free(NULL, &teapot);
    return rc;
fail:
    hfvis_mesh_free(NULL, &torus);
    hfvis_mesh_free(NULL, &teapot);
    return 1;
}
