/* 01_horizon_map.c - the horizon map of a generated terrain, and a hillshade with cast shadows read from it. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "common.h"

#define W 256
#define H 256
#define K 8 /* directions psi_k = 2 pi k / K from east toward south: 0 E, 2 S, 4 W, 6 N */
#define PI 3.14159265358979323846

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "out";
    /* fBm terrain: 6 octaves of value noise, base wavelength 128 cells, heights within +-48. */
    const hfvis_field terrain = { .kind = HFVIS_FIELD_FBM, .amplitude = 48.0, .wavelength = 128.0,
                                  .octaves = 6, .seed = 2010 };
    /* The sun of the hillshade stands in direction k = 5 (psi = 225 deg: north-west, GIS's
     * default bearing 315 deg), 25 deg above the horizontal. */
    const int sun_k = 5;
    const double sun_psi = 2.0 * PI * sun_k / K, sun_elev = 25.0 * PI / 180.0;
    const double l[3] = { cos(sun_elev) * cos(sun_psi), cos(sun_elev) * sin(sun_psi), sin(sun_elev) };
    static const char *const names[4] = { "01_horizon_east.pgm", "01_horizon_south.pgm",
                                          "01_horizon_west.pgm", "01_horizon_north.pgm" };
    float *z = malloc(sizeof(float) * W * H), *map = malloc(sizeof(float) * K * W * H);
    float *n = malloc(sizeof(float) * 3 * W * H), *shade = malloc(sizeof(float) * W * H);
    size_t i, shadowed = 0;
    int k, rc = 1;
    hfvis_grid grid;

    if (!z || !map || !n || !shade) { ex_error("01_horizon_map", "out of memory"); goto fail; }
    EX_CHECK(hfvis_field_generate(&terrain, W, H, W, z), "hfvis_field_generate");
    grid.z = z; grid.width = W; grid.height = H; grid.stride = W; grid.cell_size = 1.0;

    /* K planes of horizon elevation angles; plane k = map[k*W*H + y*W + x]. NULL options: open
     * border (nothing outside the grid), psi_0 = 0. */
    EX_CHECK(hfvis_horizon_map(&grid, K, NULL, map), "hfvis_horizon_map");
    for (k = 0; k < K; k += 2)  /* east, south, west, north; 0 and 45 degrees map to black, white */
        if (ex_save_pgm_png(dir, names[k / 2], map + (size_t)k * W * H, W, H, W, 0.0f, (float)(PI / 4.0)))
            goto fail;

    /* Hillshade: Lambert max(n.l, 0), and black where the horizon toward the sun is higher than
     * the sun, i.e. where terrain (or the receiver's own slope) hides the sun's centre. */
    EX_CHECK(hfvis_normals_compute(&grid, n), "hfvis_normals_compute");
    for (i = 0; i < (size_t)W * H; i++) {
        double ndotl = (double)n[3 * i] * l[0] + (double)n[3 * i + 1] * l[1] + (double)n[3 * i + 2] * l[2];
        int lit = (double)map[(size_t)sun_k * W * H + i] < sun_elev;
        shade[i] = lit && ndotl > 0.0 ? (float)ndotl : 0.0f;
        shadowed += !lit;
    }
    printf("01_horizon_map: %.1f%% of the terrain is in cast shadow\n", 100.0 * (double)shadowed / (W * H));
    if (ex_save_pgm_png(dir, "01_hillshade.pgm", shade, W, H, W, 0.0f, 1.0f)) goto fail;
    {   /* picture: the horizon toward the sun (0 to 45 deg) beside the hillshade read from it */
        const ex_panel sheet[2] = { { map + (size_t)sun_k * W * H, 0.0f, (float)(PI / 4.0) }, { shade, 0.0f, 1.0f } };
        if (ex_save_png_sheet(dir, "01_horizon_sheet.png", sheet, 2, 2, W, H, 1)) goto fail;
    }
    rc = 0;
fail:
    free(z); free(map); free(n); free(shade);
    return rc;
}
