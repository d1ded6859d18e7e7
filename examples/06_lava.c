/* 06_lava.c - an emissive lava river in a valley under a dark night sky: the glow it casts on the valley walls ([P2] indirect light). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "common.h"

#define W 256
#define H 256
#define K 16        /* azimuth directions of the sweeps */
#define C 3         /* RGB */
#define ALBEDO 0.5f /* dark rock */
#define LEVEL 2.0   /* the lava fills each row of the valley up to this height above its lowest point */

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "out";
    /* A V-shaped valley running north-south (rising 0.6 per cell from x = 128), roughened with fBm. */
    const hfvis_field valley = { .kind = HFVIS_FIELD_V_VALLEY, .x0 = 128.0, .slope = 0.6 };
    const hfvis_field rough = { .kind = HFVIS_FIELD_FBM, .amplitude = 8.0, .wavelength = 64.0,
                                .octaves = 5, .seed = 7 };
    static const float lava[C] = { 6.0f, 1.8f, 0.3f };   /* emitted radiance, orange */
    const float sky = 0.02f;                            /* a dark night sky */
    float *z = malloc(sizeof(float) * W * H), *fbm = malloc(sizeof(float) * W * H);
    float *emit = malloc(sizeof(float) * C * W * H), *direct = malloc(sizeof(float) * C * W * H);
    float *glow = malloc(sizeof(float) * C * W * H), *lit = malloc(sizeof(float) * C * W * H);
    float *lum = malloc(sizeof(float) * W * H);
    hfvis_grid grid;
    double near = 0.0, far = 0.0, top = 0.0;
    size_t i, n_lava = 0, n_near = 0, n_far = 0;
    int x, y, c, rc = 1;

    if (!z || !fbm || !emit || !direct || !glow || !lit || !lum) { ex_error("06_lava", "out of memory"); goto fail; }
    EX_CHECK(hfvis_field_generate(&valley, W, H, W, z), "hfvis_field_generate (valley)");
    EX_CHECK(hfvis_field_generate(&rough, W, H, W, fbm), "hfvis_field_generate (fBm)");
    for (i = 0; i < (size_t)W * H; i++) z[i] += fbm[i];
    /* The river: in each row, a flat lava surface LEVEL above the row's lowest point wherever
     * the ground lies lower; it emits light. */
    for (y = 0; y < H; y++) {
        float *row = z + (size_t)y * W, surface = row[0];
        for (x = 1; x < W; x++) surface = row[x] < surface ? row[x] : surface;
        surface = (float)((double)surface + LEVEL);
        for (x = 0; x < W; x++) {
            int is_lava = row[x] <= surface;
            if (is_lava) { row[x] = surface; n_lava++; }
            for (c = 0; c < C; c++) emit[((size_t)y * W + (size_t)x) * C + (size_t)c] = is_lava ? lava[c] : 0.0f;
        }
    }
    grid.z = z; grid.width = W; grid.height = H; grid.stride = W; grid.cell_size = 1.0;

    /* The glow alone: the lava's radiance gathered over the visible terrain, no sky (sky = 0). */
    EX_CHECK(hfvis_indirect_light(&grid, K, emit, C, 0.0f, ALBEDO, NULL, NULL, glow, W),
             "hfvis_indirect_light");
    /* The whole picture: sky light plus emission, with 2 bounces between the rocks. */
    EX_CHECK(hfvis_direct_light(&grid, K, NULL, sky, NULL, C, NULL, direct), "hfvis_direct_light");
    EX_CHECK(hfvis_terrain_gi(&grid, K, direct, emit, NULL, ALBEDO, C, 2, NULL, NULL, lit),
             "hfvis_terrain_gi");

    /* Mean glow (red channel) on the rock near the river (within 12 cells of the valley axis)
     * and far from it (more than 60 cells away). */
    for (i = 0; i < (size_t)W * H; i++) {
        double dx = fabs((double)(i % W) - 128.0), g = (double)glow[i * C];
        if (emit[i * C] > 0.0f || !isfinite(g)) continue;
        if (dx < 12.0) { near += g; n_near++; }
        else if (dx > 60.0) { far += g; n_far++; }
    }
    if (n_lava == 0 || n_near == 0 || n_far == 0 || !(near / (double)n_near > far / (double)n_far)) {
        ex_error("06_lava", "the valley walls are not brighter than the plateau: unexpected result");
        goto fail;
    }
    printf("06_lava: %zu lava samples; red glow on the rock near the river %.4f, far from it %.4f\n",
           n_lava, near / (double)n_near, far / (double)n_far);

    /* Images: luminance of the glow on the rock (lava masked to 0), and of the whole scene. */
    for (i = 0; i < (size_t)W * H; i++) {
        const float *p = emit[i * C] > 0.0f ? NULL : glow + i * C;
        lum[i] = p ? (float)(0.2126 * (double)p[0] + 0.7152 * (double)p[1] + 0.0722 * (double)p[2]) : 0.0f;
        if (isfinite(lum[i]) && (double)lum[i] > top) top = (double)lum[i];
    }
    /* Range: half the brightest glow, so that its spread up the walls shows. */
    if (ex_save_pgm_png(dir, "06_lava_glow.pgm", lum, W, H, W, 0.0f, (float)(0.5 * top))) goto fail;
    for (i = 0; i < (size_t)W * H; i++) {
        const float *p = lit + i * C;
        lum[i] = (float)(0.2126 * (double)p[0] + 0.7152 * (double)p[1] + 0.0722 * (double)p[2]);
    }
    /* Range: the same, so that the lava saturates and the lit walls show. */
    if (ex_save_pgm_png(dir, "06_lava_scene.pgm", lum, W, H, W, 0.0f, (float)(0.5 * top))) goto fail;
    /* picture: the scene in colour on the same scale */
    if (ex_save_png_rgb(dir, "06_lava_scene_rgb.png", lit, W, H, W, 0.0f, (float)(0.5 * top))) goto fail;
    rc = 0;
fail:
    free(z); free(fbm); free(emit); free(direct); free(glow); free(lit); free(lum);
    return rc;
}
