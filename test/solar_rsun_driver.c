/* solar_rsun_driver.c - hfvis's side of test/solar_rsun.sh: the daily irradiation of the centre of
 * a plane (31 x 31 samples, 10 m cells, height 0 at the centre) tilted `slope` degrees toward
 * `facing` (E, N, W, S; any for slope 0) at latitude `lat` on day of year `day`, with r.sun's
 * solar geometry (HFVIS_SUN_RSUN: local solar time, r.sun's steps), step 0.25 h, Linke 3,
 * albedo 0.2, terrain shading on. Prints "beam diffuse reflected global" in Wh/m^2.
 * usage: solar_rsun_driver LAT DAY SLOPE FACING */
#include "../hfvis.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define N 31
#define CELL 10.0
#define PI 3.14159265358979323846

int main(int argc, char **argv)
{
    static float z[N * N];
    float b, d, r, gl;
    hfvis_grid g;
    hfvis_solar_input in = hfvis_solar_input_default();
    hfvis_solar_options o = hfvis_solar_options_default();
    hfvis_solar_output out;
    double lat, slope, psi, t;
    int day, x, y, m = 1;
    static const int mdays[12] = { 31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31 };
    if (argc != 5) {
        fprintf(stderr, "usage: solar_rsun_driver LAT DAY SLOPE FACING(E|N|W|S)\n");
        return 2;
    }
    lat = atof(argv[1]);
    day = atoi(argv[2]);
    slope = atof(argv[3]);
    psi = argv[4][0] == 'E' ? 0.0 : argv[4][0] == 'S' ? PI / 2 : argv[4][0] == 'W' ? PI : 1.5 * PI;
    if (day < 1 || day > 365) return 2;
    t = tan(slope * PI / 180.0);
    for (y = 0; y < N; y++)
        for (x = 0; x < N; x++) /* descends toward psi, 0 at the centre */
            z[y * N + x] = (float)(-t * CELL * ((x - N / 2) * cos(psi) + (y - N / 2) * sin(psi)));
    g.z = z;
    g.width = g.height = N;
    g.stride = N;
    g.cell_size = CELL;
    in.latitude_rad = lat * PI / 180.0;
    in.year = 2026; /* not a leap year: day of year -> date */
    while (day > mdays[m - 1]) day -= mdays[m++ - 1];
    in.month = m;
    in.day = day;
    o.model = HFVIS_SUN_RSUN;
    memset(&out, 0, sizeof out);
    out.beam = (float *)malloc(sizeof(float) * N * N);
    out.diffuse = (float *)malloc(sizeof(float) * N * N);
    out.reflected = (float *)malloc(sizeof(float) * N * N);
    out.global = (float *)malloc(sizeof(float) * N * N);
    if (!out.beam || !out.diffuse || !out.reflected || !out.global ||
        hfvis_solar_irradiation(&g, &in, &o, &out) != HFVIS_OK) {
        fprintf(stderr, "solar_rsun_driver: hfvis_solar_irradiation failed\n");
        return 1;
    }
    x = (N / 2) * N + N / 2;
    b = out.beam[x];
    d = out.diffuse[x];
    r = out.reflected[x];
    gl = out.global[x];
    printf("%.4f %.4f %.4f %.4f\n", (double)b, (double)d, (double)r, (double)gl);
    free(out.beam);
    free(out.diffuse);
    free(out.reflected);
    free(out.global);
    return 0;
}
