/* 03_environment_light.c - a terrain lit by a lat-long environment map made in code (sky gradient and a sun-like patch). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "common.h"

#define W 256
#define H 256
#define K 32      /* azimuth directions of the sweep */
#define N_THETA 64 /* environment rows: zenith (row 0) to nadir, pi/64 each */
#define N_PHI 128  /* environment columns: azimuth from east toward south, 2 pi/128 each */
#define PI 3.14159265358979323846

/* Radiance of the made-up environment toward unit direction d (x east, y south, z up): a blue
 * sky brightening toward the horizon, a dark ground below it, and a sun 8 deg in radius. */
static void environment(const double d[3], const double sun[3], float rgb[3])
{
    static const double zenith[3] = { 0.20, 0.40, 0.90 }, horizon[3] = { 0.85, 0.90, 1.00 };
    static const double ground[3] = { 0.12, 0.10, 0.08 }, sun_rgb[3] = { 40.0, 36.0, 30.0 };
    double t = d[2] > 0.0 ? pow(d[2], 0.5) : 0.0, cos_sun = d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2];
    int c;
    for (c = 0; c < 3; c++) {
        double v = d[2] > 0.0 ? horizon[c] * (1.0 - t) + zenith[c] * t : ground[c];
        if (cos_sun > cos(8.0 * PI / 180.0)) v += sun_rgb[c];
        rgb[c] = (float)v;
    }
}

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "out";
    const hfvis_field terrain = { .kind = HFVIS_FIELD_FBM, .amplitude = 48.0, .wavelength = 128.0,
                                  .octaves = 6, .seed = 2010 };
    /* The sun in the south-east (psi = 45 deg, between east and south), 35 deg high. */
    const double sun_psi = 45.0 * PI / 180.0, sun_elev = 35.0 * PI / 180.0;
    const double sun[3] = { cos(sun_elev) * cos(sun_psi), cos(sun_elev) * sin(sun_psi), sin(sun_elev) };
    float *z = malloc(sizeof(float) * W * H), *rgb = malloc(sizeof(float) * 3 * W * H);
    float *rgb_lp = malloc(sizeof(float) * 3 * W * H), *lum = malloc(sizeof(float) * W * H);
    float *radiance = malloc(sizeof(float) * 3 * N_THETA * N_PHI);
    hfvis_env env;
    hfvis_env_options eopts = hfvis_env_options_default();
    hfvis_grid grid;
    double top = 0.0, diff = 0.0;
    size_t i;
    int t, p, rc = 1;

    if (!z || !rgb || !rgb_lp || !lum || !radiance) { ex_error("03_environment_light", "out of memory"); goto fail; }
    EX_CHECK(hfvis_field_generate(&terrain, W, H, W, z), "hfvis_field_generate");
    grid.z = z; grid.width = W; grid.height = H; grid.stride = W; grid.cell_size = 1.0;

    /* Fill the map at texel centres: row t is theta in [t, t+1) pi/N_THETA from the zenith. */
    for (t = 0; t < N_THETA; t++)
        for (p = 0; p < N_PHI; p++) {
            double theta = (t + 0.5) * PI / N_THETA, phi = (p + 0.5) * 2.0 * PI / N_PHI;
            double d[3] = { sin(theta) * cos(phi), sin(theta) * sin(phi), cos(theta) };
            environment(d, sun, radiance + ((size_t)t * N_PHI + (size_t)p) * 3);
        }
    env.radiance = radiance; env.n_theta = N_THETA; env.n_phi = N_PHI; env.channels = 3;

    /* Default method: exact prefix integrals of the map per direction ([P1] Eq. 6-7; docs/errata.md E9). */
    EX_CHECK(hfvis_env_light(&grid, K, &env, 0.8f, NULL, NULL, rgb, W), "hfvis_env_light");
    /* The paper's own method: the L_p table of [P1] Eq. 6-7, bilinear in (theta_n, theta_h). */
    eopts.method = HFVIS_ENV_LP_TABLE;
    EX_CHECK(hfvis_env_light(&grid, K, &env, 0.8f, NULL, &eopts, rgb_lp, W), "hfvis_env_light (L_p)");

    for (i = 0; i < (size_t)W * H; i++) {
        double y = 0.2126 * (double)rgb[3 * i] + 0.7152 * (double)rgb[3 * i + 1] + 0.0722 * (double)rgb[3 * i + 2];
        double y_lp = 0.2126 * (double)rgb_lp[3 * i] + 0.7152 * (double)rgb_lp[3 * i + 1] +
                      0.0722 * (double)rgb_lp[3 * i + 2];
        lum[i] = (float)y; /* Rec. 709 luminance */
        if (isfinite(y) && y > top) top = y;
        if (isfinite(y) && fabs(y - y_lp) > diff) diff = fabs(y - y_lp);
    }
    printf("03_environment_light: largest luminance %.4f, prefix vs L_p table differ by <= %.4f\n", top, diff);
    if (ex_save_pgm_png(dir, "03_environment_light.pgm", lum, W, H, W, 0.0f, (float)top)) goto fail;
    /* picture: the RGB radiance on the same scale */
    if (ex_save_png_rgb(dir, "03_environment_light_rgb.png", rgb, W, H, W, 0.0f, (float)top)) goto fail;
    rc = 0;
fail:
    free(z); free(rgb); free(rgb_lp); free(lum); free(radiance);
    return rc;
}
