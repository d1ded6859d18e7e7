/* 02_sky_view_factor.c - uniform-sky light ([P1] Eq. 5) and the GIS sky-view factor of a generated terrain. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "common.h"

#define W 256
#define H 256
#define K 32 /* azimuth directions; both outputs converge quickly in K on smooth terrain */

/* Mean of the finite values (holes are NaN). */
static double mean(const float *v, size_t n)
{
    double sum = 0.0;
    size_t i, count = 0;
    for (i = 0; i < n; i++)
        if (isfinite(v[i])) { sum += (double)v[i]; count++; }
    return count ? sum / (double)count : 0.0;
}

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "out";
    const hfvis_field terrain = { .kind = HFVIS_FIELD_FBM, .amplitude = 48.0, .wavelength = 128.0,
                                  .octaves = 6, .seed = 2010 };
    float *z = malloc(sizeof(float) * W * H), *sky = malloc(sizeof(float) * W * H);
    float *svf = malloc(sizeof(float) * W * H);
    hfvis_sweep_options opts = hfvis_sweep_options_default();
    hfvis_grid grid;
    int rc = 1;

    if (!z || !sky || !svf) { ex_error("02_sky_view_factor", "out of memory"); goto fail; }
    EX_CHECK(hfvis_field_generate(&terrain, W, H, W, z), "hfvis_field_generate");
    grid.z = z; grid.width = W; grid.height = H; grid.stride = W; grid.cell_size = 1.0;
    /* A DEM tile is cut out of a larger landscape: let the edge heights extend outward instead
     * of the papers' open border, so the tile's edges are not lit from below the horizon. */
    opts.border = HFVIS_BORDER_CLAMP;

    /* Sky light: radiance reflected by a Lambertian surface (albedo 1) under a uniform sky of
     * radiance 1, cosine-weighted and slope-aware; fused into the sweep, so no horizon map is
     * stored. An open flat receiver would return exactly 1. */
    EX_CHECK(hfvis_sky_light(&grid, K, 1.0f, 1.0f, &opts, sky, W), "hfvis_sky_light");
    /* Sky-view factor (Zaksek et al. 2011): 1 - mean over directions of sin(max(horizon, 0)),
     * the fraction of the sky hemisphere a horizontal receiver sees, ignoring its slope. */
    EX_CHECK(hfvis_sky_view_factor(&grid, K, &opts, svf, W), "hfvis_sky_view_factor");
    printf("02_sky_view_factor: mean sky light %.4f, mean sky-view factor %.4f\n",
           mean(sky, (size_t)W * H), mean(svf, (size_t)W * H));

    /* Both lie in [0, 1], and mostly above 0.5 on this terrain: stretch [0.5, 1] to grey. */
    if (ex_save_pgm_png(dir, "02_sky_light.pgm", sky, W, H, W, 0.5f, 1.0f)) goto fail;
    if (ex_save_pgm_png(dir, "02_sky_view_factor.pgm", svf, W, H, W, 0.5f, 1.0f)) goto fail;
    {   /* picture: both side by side */
        const ex_panel sheet[2] = { { sky, 0.5f, 1.0f }, { svf, 0.5f, 1.0f } };
        if (ex_save_png_sheet(dir, "02_sky_sheet.png", sheet, 2, 2, W, H, 1)) goto fail;
    }
    rc = 0;
fail:
    free(z); free(sky); free(svf);
    return rc;
}
