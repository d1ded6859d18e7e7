/* 14_exact_rays.c - exact rays beside the lattice (hfvis.h, "Exact rays"): the sky-view factor of
 * an urban DSM (flat ground, box buildings 5-40 m on a 1 m grid) by the [P1] lattice and by exact
 * rays, and their difference. The lattice's gather blends "sees the wall" with "does not" next to
 * every wall and roof edge; exact rays give each grid point its own ray. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "common.h"
#include "fields.h"

#define N 256
#define K 16

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "out";
    float *z = malloc(sizeof(float) * N * N), *lat = malloc(sizeof(float) * N * N);
    float *ex = malloc(sizeof(float) * N * N), *diff = malloc(sizeof(float) * N * N);
    hfvis_sweep_options lo = hfvis_sweep_options_default(), eo = lo;
    hfvis_grid grid;
    ex_panel panels[3];
    double worst = 0.0, sum = 0.0;
    int i, rc = 1;

    if (!z || !lat || !ex || !diff) { ex_error("14_exact_rays", "out of memory"); goto fail; }
    fields_urban(z, N, N, 70, 16);
    grid.z = z; grid.width = N; grid.height = N; grid.stride = N; grid.cell_size = 1.0;
    eo.rays = HFVIS_RAYS_EXACT;
    EX_CHECK(hfvis_sky_view_factor(&grid, K, &lo, lat, N), "hfvis_sky_view_factor (lattice)");
    EX_CHECK(hfvis_sky_view_factor(&grid, K, &eo, ex, N), "hfvis_sky_view_factor (exact)");
    for (i = 0; i < N * N; i++) {
        double d = (double)lat[i] - (double)ex[i];
        diff[i] = (float)d;
        sum += fabs(d);
        if (fabs(d) > worst) worst = fabs(d);
    }
    printf("urban DSM %dx%d, K = %d: sky-view factor lattice - exact: mean |diff| %.4f, max %.3f\n", N, N,
           K, sum / (N * N), worst);
    panels[0].pixels = lat; panels[0].lo = 0.3f; panels[0].hi = 1.0f;
    panels[1].pixels = ex; panels[1].lo = 0.3f; panels[1].hi = 1.0f;
    panels[2].pixels = diff; panels[2].lo = -0.2f; panels[2].hi = 0.2f;
    EX_CHECK(ex_save_png_sheet(dir, "14_exact_sheet.png", panels, 3, 3, N, N, 1), "ex_save_png_sheet");
    EX_CHECK(ex_save_pgm_png(dir, "14_svf_exact.pgm", ex, N, N, N, 0.0f, 1.0f), "ex_save_pgm_png");
    rc = 0;
fail:
    free(z); free(lat); free(ex); free(diff);
    return rc;
}
