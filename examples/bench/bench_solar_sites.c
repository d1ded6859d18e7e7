/* bench_solar_sites.c - the per-cell sun of hfvis_solar_irradiation (hfvis_solar_input
 * latitude_map/longitude_map, hfvis_solar_options site_tolerance_rad) beside the one site of the
 * grid's centre: one day (172) and one year (2026), 15-minute steps, on the Colorado SRTM tile
 * (colorado_srtm_512_90m.pfm of HFVIS_BENCH_DEMS; without it a 512^2 fBm with 90 m cells at the
 * same site). Both runs read one exact horizon map made once (hfvis_solar_options.horizon_map, bit
 * for bit the routine's own), so the times are the integration after the map, which is what the
 * sites change: the blocks' own sun, steps, sunrise and sunset and their own sector sums.
 * The sites are the cells' on a spherical transverse Mercator grid of UTM zone 13's central
 * meridian centred at 40.24 N 105.53 W, as the tile lies in UTM 13N (the tool maps a UTM raster's
 * cells by the ellipsoid's inverse projection; the sphere moves the sites by far less than the
 * tolerance). CPU time of this process (one thread); the day the minimum of 5 runs of each,
 * alternating.
 *   HFVIS_BENCH_DEMS=/path/to/dems BENCH_ARGS=solar-sites make bench */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bench.h"

#define SITES_K 64 /* the default directions of the exact horizon map */
#define SITES_PI 3.14159265358979323846

/* One run after the map; CPU seconds, or -1 on failure. */
static double sites_run(const hfvis_grid *g, const hfvis_solar_input *in, const hfvis_solar_options *o,
                        float *global)
{
    hfvis_solar_output out;
    double t0 = bench_cpu_now();
    memset(&out, 0, sizeof out);
    out.global = global;
    if (hfvis_solar_irradiation(g, in, o, &out) != HFVIS_OK) return -1.0;
    return bench_cpu_now() - t0;
}

static void sites_dem(const char *name, float *z, int w, int h, double cell, int quick)
{
    const double lat0 = 40.24, lon0 = -105.53, deg = SITES_PI / 180.0, R = 6371000.0, lonc = -105.0;
    size_t n = (size_t)w * (size_t)h, i;
    double *lats = (double *)malloc(2 * n * sizeof(double));
    float *map = (float *)malloc(n * SITES_K * sizeof(float)), *g1 = (float *)malloc(n * sizeof(float));
    float *g2 = (float *)malloc(n * sizeof(float));
    hfvis_grid g;
    hfvis_solar_input in = hfvis_solar_input_default();
    hfvis_solar_options o = hfvis_solar_options_default();
    hfvis_sweep_options sw = hfvis_sweep_options_default();
    double t_map, t[2][2], diff = 0.0, xc, yc;
    int per, site, rep, reps;
    if (!lats || !map || !g1 || !g2) {
        printf("  %s: out of memory\n", name);
        free(lats); free(map); free(g1); free(g2);
        return;
    }
    g.z = z; g.width = w; g.height = h; g.stride = w; g.cell_size = cell;
    /* the cells' sites by the spherical transverse Mercator of UTM zone 13's central meridian
     * (Snyder 1987, USGS PP 1395, §8: the sphere's forward formulas for the centre, the inverse
     * phi = asin(sin D / cosh x), lambda = lambda0 + atan2(sinh x, cos D) per cell): north up on the grid,
     * true north turned by the projection's convergence, as on the tile's own UTM grid */
    xc = atanh(cos(lat0 * deg) * sin((lon0 - lonc) * deg));
    yc = atan(tan(lat0 * deg) / cos((lon0 - lonc) * deg));
    for (i = 0; i < n; i++) {
        double x = xc + ((double)(i % (size_t)w) + 0.5 - (double)w * 0.5) * cell / R;
        double d = yc + ((double)h * 0.5 - (double)(i / (size_t)w) - 0.5) * cell / R;
        lats[i] = asin(sin(d) / cosh(x));
        lats[n + i] = lonc * deg + atan2(sinh(x), cos(d));
    }
    sw.rays = HFVIS_RAYS_EXACT;
    t_map = bench_cpu_now();
    if (hfvis_horizon_map(&g, SITES_K, &sw, map) != HFVIS_OK) {
        printf("  %s: the horizon map failed\n", name);
        free(lats); free(map); free(g1); free(g2);
        return;
    }
    t_map = bench_cpu_now() - t_map;
    o.horizon_map = map;
    in.latitude_rad = lat0 * deg;
    in.longitude_rad = lon0 * deg;
    in.utc_offset_hours = -7.0;
    for (per = 0; per < 2; per++) { /* a day, a year */
        in.year = 2026;
        in.month = per ? 1 : 6;
        in.day = per ? 1 : 21;
        in.days = per ? 365 : 1;
        reps = quick || per ? 1 : 5;
        t[per][0] = t[per][1] = 1e30;
        for (rep = 0; rep < reps; rep++) /* alternating, so that both see the same load */
            for (site = 0; site < 2; site++) { /* one site, per-cell sites */
                double s;
                in.latitude_map = site ? lats : NULL;
                in.longitude_map = site ? lats + n : NULL;
                if ((s = sites_run(&g, &in, &o, site ? g2 : g1)) < 0.0) {
                    printf("  %s: hfvis_solar_irradiation failed\n", name);
                    free(lats); free(map); free(g1); free(g2);
                    return;
                }
                if (s < t[per][site]) t[per][site] = s;
            }
        if (per) /* the year: how far the centre's sun is from each cell's (mean |g1 - g2| / g2) */
            for (i = 0; i < n; i++) diff += fabs((double)g1[i] - (double)g2[i]) / ((double)g2[i] > 1.0 ? (double)g2[i] : 1.0);
    }
    printf("  %-30s %d x %d, horizon map K = %d made once: %.2f s; then, one site | per-cell sites "
           "(default tolerance 0.05 deg):\n", name, w, h, SITES_K, t_map);
    printf("  %-30s day 172:  %6.2f s | %6.2f s (x%.2f, %+.0f ns per cell); with the map %.2f | %.2f s (%+.1f %%)\n", "",
           t[0][0], t[0][1], t[0][1] / t[0][0], (t[0][1] - t[0][0]) * 1e9 / (double)n, t_map + t[0][0],
           t_map + t[0][1], 100.0 * (t[0][1] - t[0][0]) / (t_map + t[0][0]));
    printf("  %-30s year 2026: %6.2f s | %6.2f s (x%.2f, %+.0f ns per cell); with the map %.2f | %.2f s (%+.1f %%)\n", "",
           t[1][0], t[1][1], t[1][1] / t[1][0], (t[1][1] - t[1][0]) * 1e9 / (double)n, t_map + t[1][0],
           t_map + t[1][1], 100.0 * (t[1][1] - t[1][0]) / (t_map + t[1][0]));
    printf("  %-30s the year's global, one site against per-cell sites: mean |difference| %.4f %%; "
           "memory +16 bytes per cell (the two maps)\n", "", 100.0 * diff / (double)n);
    free(lats); free(map); free(g1); free(g2);
}

void bench_solar_sites(int quick)
{
    const char *dir = getenv("HFVIS_BENCH_DEMS");
    char path[4096];
    float *z = NULL;
    hfvis_image_info info;
    printf("\nSolar irradiation, the sun per cell (latitude_map/longitude_map) beside one site; CPU time, one thread:\n");
    snprintf(path, sizeof path, "%s/colorado_srtm_512_90m.pfm", dir && *dir ? dir : ".");
    if (dir && *dir && hfvis_image_load(path, NULL, &z, &info) == HFVIS_OK) {
        sites_dem("Colorado SRTM (90 m)", z, info.width, info.height, 90.0, quick);
        hfvis_free(NULL, z);
    } else {
        float *zf = bench_solar_standin();
        if (!zf) return;
        printf("  (HFVIS_BENCH_DEMS unset or without the tile: a synthetic field)\n");
        sites_dem("fBm 512^2 (90 m cells)", zf, 512, 512, 90.0, quick);
        free(zf);
    }
}
