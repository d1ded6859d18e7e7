/* 09_ns_gi.c - multi-resolution height-field GI ([NS09] Nowrouzezahrai & Snyder): direct light,
 * one bounce and three bounces side by side. Usage: 09_ns_gi [OUTDIR]   (default "out") */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "common.h"

#define W 256
#define H 256
#define BOUNCES 3   /* interreflection bounces */
#define GAP 4       /* pixels between the panels of the side-by-side image */
#define ALBEDO 0.6f
#define PI 3.14159265358979323846

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "out";
    const hfvis_field terrain = { .kind = HFVIS_FIELD_FBM, .amplitude = 48.0, .wavelength = 128.0,
                                  .octaves = 6, .seed = 2010 };
    /* A low evening sun in the west-south-west (compass bearing 250 deg, psi = bearing - 90 deg),
     * 12 deg high, irradiance 3 on a surface facing it, and a uniform sky of radiance 0.3 given
     * as spherical harmonics (a constant c is 2 sqrt(pi) c in the first coefficient). */
    hfvis_sun sun = { (250.0 - 90.0) * PI / 180.0, 12.0 * PI / 180.0, 0.0, { 3.0f, 3.0f, 3.0f, 3.0f } };
    double sky[16] = { 2.0 * 1.7724538509055159 * 0.3 };
    const size_t n = (size_t)W * H;
    const int PW = 3 * W + 2 * GAP;
    float *z = malloc(sizeof(float) * n), *direct = malloc(sizeof(float) * n);
    float *bounce = malloc(sizeof(float) * n * BOUNCES), *one = malloc(sizeof(float) * n);
    float *three = malloc(sizeof(float) * n), *panels = malloc(sizeof(float) * (size_t)PW * H);
    hfvis_ns_scene scene = { 0 };
    hfvis_ns_gi_options opts = hfvis_ns_gi_options_default();
    hfvis_ns_gi_outputs out = { 0 };
    hfvis_grid grid;
    double top = 0.0, share = 0.0;
    size_t i, counted = 0;
    int x, y, rc = 1;

    if (!z || !direct || !bounce || !one || !three || !panels) { ex_error("09_ns_gi", "out of memory"); goto fail; }
    EX_CHECK(hfvis_field_generate(&terrain, W, H, W, z), "hfvis_field_generate");
    grid.z = z; grid.width = W; grid.height = H; grid.stride = W; grid.cell_size = 1.0;

    scene.channels = 1;
    scene.env_sh = sky;
    scene.lights = &sun;        /* radius 0: a directional light, hard shadow from one more slice */
    scene.light_count = 1;
    scene.albedo[0] = ALBEDO;
    opts.subsample = 2;         /* visibility and bounces per 2x2 block, shading per pixel ([NS09] §7) */
    /* One call: the direct light and the radiance each of the three bounces adds. */
    out.bounces = BOUNCES;
    out.direct = direct;
    out.bounce = bounce;
    EX_CHECK(hfvis_ns_gi(&grid, &scene, &opts, &out), "hfvis_ns_gi");

    for (i = 0; i < n; i++) {
        one[i] = direct[i] + bounce[i];
        three[i] = one[i] + bounce[n + i] + bounce[2 * n + i];
        if (!isfinite(three[i])) continue;
        if ((double)three[i] > top) top = (double)three[i];
        if (three[i] > 0.0f) { share += (double)(three[i] - direct[i]) / (double)three[i]; counted++; }
    }
    if (counted == 0 || !(top > 0.0)) { ex_error("09_ns_gi", "no light: unexpected result"); goto fail; }
    printf("09_ns_gi: %d bounces, albedo %.1f: on average %.1f%% of the light comes from other terrain "
           "(largest radiance %.4f)\n", BOUNCES, (double)ALBEDO, 100.0 * share / (double)counted, top);
    /* Side by side, on one scale: direct | one bounce | three bounces. */
    for (y = 0; y < H; y++)
        for (x = 0; x < PW; x++) {
            int panel = x / (W + GAP), px = x % (W + GAP);
            const float *src = panel == 0 ? direct : panel == 1 ? one : three;
            panels[(size_t)y * PW + (size_t)x] = px < W ? src[(size_t)y * W + (size_t)px] : (float)top;
        }
    if (ex_save_pgm_png(dir, "gi_direct.pgm", direct, W, H, W, 0.0f, (float)top)) goto fail;
    if (ex_save_pgm_png(dir, "gi_1bounce.pgm", one, W, H, W, 0.0f, (float)top)) goto fail;
    if (ex_save_pgm_png(dir, "gi_3bounces.pgm", three, W, H, W, 0.0f, (float)top)) goto fail;
    if (ex_save_pgm_png(dir, "gi_side_by_side.pgm", panels, PW, H, PW, 0.0f, (float)top)) goto fail;
    rc = 0;
fail:
    free(z); free(direct); free(bounce); free(one); free(three); free(panels);
    return rc;
}
