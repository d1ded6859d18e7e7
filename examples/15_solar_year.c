/* 15_solar_year.c - a year of clear-sky solar irradiation over exact horizons (hfvis.h, "solar
 * radiation"; docs/solar.md): hfvis_solar_irradiation for every day of 2026 at 15-minute steps
 * (SPA sun, r.sun's ESRA clear sky, Linke 3, albedo 0.2), shown in colour over the DEM's
 * hillshade. Without arguments after DIR a 128^2 fBm with 30 m cells at 46 N 15 E stands in;
 * with them, a PFM DEM: 15_solar_year DIR DEM.pfm CELL_M LAT_DEG LON_DEG (docs/solar.md's
 * gallery image is the Colorado SRTM tile: cell 90, 40.24, -105.53). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "common.h"
#include "fields.h"

#define SYN_N 128
#define DEG (3.14159265358979323846 / 180.0)
#define PICTURE_MAX 256 /* the picture's largest side: larger DEMs are box-filtered down */
#define CLIP 0.02       /* the colour ramp spans the 2nd to the 98th percentile */

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return x < y ? -1 : x > y;
}

/* A colour ramp over t in [0, 1]: dark blue, violet, red-orange, yellow, pale yellow. */
static void ramp(double t, double rgb[3])
{
    static const double stop[5][3] = { { 0.05, 0.10, 0.35 }, { 0.45, 0.15, 0.55 }, { 0.85, 0.30, 0.20 },
                                       { 0.98, 0.75, 0.15 }, { 1.00, 1.00, 0.75 } };
    double s = (t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t) * 4.0;
    int k = s >= 4.0 ? 3 : (int)s, c;
    for (c = 0; c < 3; c++) rgb[c] = stop[k][c] + (s - k) * (stop[k + 1][c] - stop[k][c]);
}

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "out";
    hfvis_grid grid;
    hfvis_image_info info;
    hfvis_solar_input in = hfvis_solar_input_default();
    hfvis_solar_options o = hfvis_solar_options_default();
    hfvis_solar_output out = { NULL, NULL, NULL, NULL, NULL };
    float *z = NULL, *glob = NULL, *nrm = NULL, *rgb = NULL, *sorted = NULL, *pic = NULL;
    double lat = 46.0, lon = 15.0, cell = 30.0, lo, hi, mean = 0.0;
    int w = SYN_N, h = SYN_N, rc = 1, loaded = 0, f, pw, ph, x, y;
    size_t i, n, m = 0;
    if (argc > 2) {
        if (argc != 6) { ex_error("15_solar_year", "usage: 15_solar_year DIR [DEM.pfm CELL LAT LON]"); return 1; }
        EX_CHECK(hfvis_image_load(argv[2], NULL, &z, &info), argv[2]);
        loaded = 1;
        w = info.width; h = info.height;
        cell = atof(argv[3]); lat = atof(argv[4]); lon = atof(argv[5]);
    } else {
        hfvis_field fld;
        z = malloc(sizeof(float) * SYN_N * SYN_N);
        if (!z) { ex_error("15_solar_year", "out of memory"); return 1; }
        memset(&fld, 0, sizeof fld);
        fld.kind = HFVIS_FIELD_FBM; fld.amplitude = 600.0; fld.wavelength = 60.0; fld.seed = 15;
        hfvis_field_generate(&fld, SYN_N, SYN_N, SYN_N, z);
    }
    n = (size_t)w * (size_t)h;
    glob = malloc(sizeof(float) * n);
    nrm = malloc(sizeof(float) * 3 * n);
    rgb = malloc(sizeof(float) * 3 * n);
    sorted = malloc(sizeof(float) * n);
    pic = malloc(sizeof(float) * 3 * n);
    if (!glob || !nrm || !rgb || !sorted || !pic) { ex_error("15_solar_year", "out of memory"); goto fail; }
    grid.z = z; grid.width = w; grid.height = h; grid.stride = w; grid.cell_size = cell;
    in.latitude_rad = lat * DEG;
    in.longitude_rad = lon * DEG;
    in.utc_offset_hours = floor(lon / 15.0 + 0.5);
    in.year = 2026; in.month = 1; in.day = 1; in.days = 365;
    out.global = glob;
    EX_CHECK(hfvis_solar_irradiation(&grid, &in, &o, &out), "hfvis_solar_irradiation");
    EX_CHECK(hfvis_normals_compute(&grid, nrm), "hfvis_normals_compute");
    for (i = 0; i < n; i++) /* kWh/m^2 */
        if (isfinite(glob[i])) mean += (double)(sorted[m++] = glob[i] / 1000.0f);
    if (!m) { ex_error("15_solar_year", "no finite height"); goto fail; }
    qsort(sorted, m, sizeof(float), cmp_float);
    lo = (double)sorted[(size_t)(CLIP * (double)(m - 1))];
    hi = (double)sorted[(size_t)((1.0 - CLIP) * (double)(m - 1))];
    printf("annual global irradiation of %dx%d cells (%.0f m) at %.2f, %.2f: mean %.0f kWh/m^2, "
           "%.0f to %.0f (colour ramp %.0f to %.0f)\n", w, h, cell, lat, lon, mean / (double)m,
           (double)sorted[0], (double)sorted[m - 1], lo, hi);
    for (i = 0; i < n; i++) { /* colour of the irradiation times a hillshade (sun NW, 45 deg) */
        const float *v = nrm + 3 * i;
        double l[3] = { -0.5, -0.5, 0.70710678 }, hs = (double)v[0] * l[0] + (double)v[1] * l[1] + (double)v[2] * l[2], c[3];
        int k;
        ramp(((double)glob[i] / 1000.0 - lo) / (hi > lo ? hi - lo : 1.0), c);
        hs = 0.45 + 0.55 * (hs > 0.0 ? hs : 0.0);
        for (k = 0; k < 3; k++) rgb[3 * i + (size_t)k] = isfinite(glob[i]) ? (float)(c[k] * hs) : 0.0f;
    }
    f = (w > h ? w : h) > PICTURE_MAX ? ((w > h ? w : h) + PICTURE_MAX - 1) / PICTURE_MAX : 1;
    pw = w / f; ph = h / f;
    for (y = 0; y < ph; y++) /* box filter f x f */
        for (x = 0; x < pw; x++) {
            int k, a, b;
            for (k = 0; k < 3; k++) {
                double sum = 0.0;
                for (b = 0; b < f; b++)
                    for (a = 0; a < f; a++) sum += (double)rgb[3 * ((size_t)(y * f + b) * (size_t)w + (size_t)(x * f + a)) + (size_t)k];
                pic[3 * ((size_t)y * (size_t)pw + (size_t)x) + (size_t)k] = (float)(sum / (double)(f * f));
            }
        }
    EX_CHECK(ex_save_png_rgb(dir, "15_solar_year_rgb.png", pic, pw, ph, pw, 0.0f, 1.0f), "ex_save_png_rgb");
    rc = 0;
fail:
    if (loaded) hfvis_free(NULL, z);
    else free(z);
    free(glob); free(nrm); free(rgb); free(sorted); free(pic);
    return rc;
}
