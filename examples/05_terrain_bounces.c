/* 05_terrain_bounces.c - light reflected between terrain points ([P2]): a low sun and a sky, direct light alone vs direct + 2 bounces. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "common.h"

#define W 256
#define H 256
#define K 16       /* azimuth directions of the sweeps */
#define BOUNCES 2  /* interreflection bounces */
#define ALBEDO 0.6f
#define PI 3.14159265358979323846

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "out";
    const hfvis_field terrain = { .kind = HFVIS_FIELD_FBM, .amplitude = 48.0, .wavelength = 128.0,
                                  .octaves = 6, .seed = 2010 };
    /* A low evening sun in the west-south-west (compass bearing 250 deg, psi = bearing - 90 deg),
     * 12 deg high, irradiance 3 on a surface facing it, over a uniform sky of radiance 0.3. */
    hfvis_sun sun = { (250.0 - 90.0) * PI / 180.0, 12.0 * PI / 180.0, 0.27 * PI / 180.0,
                      { 3.0f, 3.0f, 3.0f, 3.0f } };
    const float sky = 0.3f;
    float *z = malloc(sizeof(float) * W * H), *direct = malloc(sizeof(float) * W * H);
    float *l0 = malloc(sizeof(float) * W * H), *lb = malloc(sizeof(float) * W * H);
    float *diff = malloc(sizeof(float) * W * H);
    hfvis_grid grid;
    double top = 0.0, dtop = 0.0, fraction = 0.0;
    size_t i, counted = 0;
    int rc = 1;

    if (!z || !direct || !l0 || !lb || !diff) { ex_error("05_terrain_bounces", "out of memory"); goto fail; }
    EX_CHECK(hfvis_field_generate(&terrain, W, H, W, z), "hfvis_field_generate");
    grid.z = z; grid.width = W; grid.height = H; grid.stride = W; grid.cell_size = 1.0;

    /* D: the sun's Lambert term times its visibility plus the sky of [P1] Eq. 5, as reflected
     * radiance for albedo 1. */
    EX_CHECK(hfvis_direct_light(&grid, K, &sun, sky, NULL, 1, NULL, direct), "hfvis_direct_light");
    /* L_0 = albedo * D (no bounce), L_2 = albedo * (D + I[L_1]): each bounce gathers the exit
     * radiance of the samples every point sees (hull-tree intervisibility, [P2] §10.1). */
    EX_CHECK(hfvis_terrain_gi(&grid, K, direct, NULL, NULL, ALBEDO, 1, 0, NULL, NULL, l0),
             "hfvis_terrain_gi (direct only)");
    EX_CHECK(hfvis_terrain_gi(&grid, K, direct, NULL, NULL, ALBEDO, 1, BOUNCES, NULL, NULL, lb),
             "hfvis_terrain_gi (2 bounces)");

    for (i = 0; i < (size_t)W * H; i++) {
        double d = (double)lb[i] - (double)l0[i]; /* the light that came from other terrain */
        diff[i] = (float)d;
        if (!isfinite(d)) continue;
        if ((double)lb[i] > top) top = (double)lb[i];
        if (d > dtop) dtop = d;
        if (lb[i] > 0.0f) { fraction += d / (double)lb[i]; counted++; }
    }
    if (counted == 0 || !(top > 0.0) || !(dtop > 0.0)) {
        ex_error("05_terrain_bounces", "no light: unexpected result");
        goto fail;
    }
    printf("05_terrain_bounces: %d bounces, albedo %.1f: on average %.1f%% of the light comes from "
           "other terrain (largest indirect %.4f, largest total %.4f)\n",
           BOUNCES, (double)ALBEDO, 100.0 * fraction / (double)counted, dtop, top);
    /* One range for both light images, so that they compare; the difference has its own. */
    if (ex_save_pgm_png(dir, "05_direct.pgm", l0, W, H, W, 0.0f, (float)top)) goto fail;
    if (ex_save_pgm_png(dir, "05_bounces.pgm", lb, W, H, W, 0.0f, (float)top)) goto fail;
    if (ex_save_pgm_png(dir, "05_indirect.pgm", diff, W, H, W, 0.0f, (float)dtop)) goto fail;
    {   /* picture: direct | after two bounces | the bounced light alone (own scale) */
        const ex_panel sheet[3] = { { l0, 0.0f, (float)top }, { lb, 0.0f, (float)top }, { diff, 0.0f, (float)dtop } };
        if (ex_save_png_sheet(dir, "05_sheet.png", sheet, 3, 3, W, H, 1)) goto fail;
    }
    rc = 0;
fail:
    free(z); free(direct); free(l0); free(lb); free(diff);
    return rc;
}
