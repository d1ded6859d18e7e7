/* 04_sun_shadows.c - cast sun shadows on a generated terrain through a day: six sun positions, one image each. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "common.h"

#define W 256
#define H 256
#define STEPS 6 /* sun positions from morning to evening */
#define PI 3.14159265358979323846

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "out";
    const hfvis_field terrain = { .kind = HFVIS_FIELD_FBM, .amplitude = 48.0, .wavelength = 128.0,
                                  .octaves = 6, .seed = 2010 };
    const double sun_radius = 0.27 * PI / 180.0; /* the real sun: soft shadow edges */
    float *z = malloc(sizeof(float) * W * H), *n = malloc(sizeof(float) * 3 * W * H);
    ex_panel sheet[STEPS];
    float *vis = malloc(sizeof(float) * W * H), *shade = malloc(sizeof(float) * STEPS * W * H);
    hfvis_grid grid;
    size_t i;
    int step, rc = 1;

    if (!z || !n || !vis || !shade) { ex_error("04_sun_shadows", "out of memory"); goto fail; }
    EX_CHECK(hfvis_field_generate(&terrain, W, H, W, z), "hfvis_field_generate");
    grid.z = z; grid.width = W; grid.height = H; grid.stride = W; grid.cell_size = 1.0;
    EX_CHECK(hfvis_normals_compute(&grid, n), "hfvis_normals_compute");

    for (step = 0; step < STEPS; step++) {
        /* A day at mid latitude, north up: the sun rises in the east (compass bearing 90 deg),
         * culminates in the south (180 deg, 50 deg high) and sets in the west (270 deg). */
        double f = (step + 0.5) / STEPS;
        double bearing = (90.0 + 180.0 * f) * PI / 180.0, elev = 50.0 * sin(PI * f) * PI / 180.0;
        double psi = bearing - PI / 2.0; /* hfvis azimuth: from east toward south */
        double l[3] = { cos(elev) * cos(psi), cos(elev) * sin(psi), sin(elev) };
        double lit = 0.0;
        char name[64];
        float *img = shade + (size_t)step * W * H;

        /* Visible fraction of the sun disc from one exact sweep toward the sun; the receiver's
         * own tangent plane is not included, so multiply by max(n.l, 0) for the light. */
        EX_CHECK(hfvis_sun_visibility(&grid, psi, elev, sun_radius, NULL, vis, W), "hfvis_sun_visibility");
        for (i = 0; i < (size_t)W * H; i++) {
            double ndotl = (double)n[3 * i] * l[0] + (double)n[3 * i + 1] * l[1] + (double)n[3 * i + 2] * l[2];
            img[i] = (float)((double)vis[i] * (ndotl > 0.0 ? ndotl : 0.0));
            lit += (double)vis[i];
        }
        printf("04_sun_shadows: bearing %5.1f deg, elevation %4.1f deg: %5.1f%% of the sun visible\n",
               bearing * 180.0 / PI, elev * 180.0 / PI, 100.0 * lit / (W * H));
        snprintf(name, sizeof name, "04_sun_%d.pgm", step);
        if (ex_save_pgm_png(dir, name, img, W, H, W, 0.0f, 1.0f)) goto fail;
        sheet[step].pixels = img, sheet[step].lo = 0.0f, sheet[step].hi = 1.0f;
    }
    /* picture: the day in two rows, morning top left */
    if (ex_save_png_sheet(dir, "04_sun_sheet.png", sheet, STEPS, 3, W, H, 1)) goto fail;
    rc = 0;
fail:
    free(z); free(n); free(vis); free(shade);
    return rc;
}
