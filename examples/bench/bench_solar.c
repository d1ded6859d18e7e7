/* bench_solar.c - hfvis_solar_irradiation beside its oracle (hfvis.h, "solar radiation"): one
 * day (day 172, 15-minute steps, Linke 3, albedo 0.2) on a DEM for each horizon mode (exact,
 * near-far, lattice), the directions of the map it made, its ratio to GRASS; the integration
 * alone over a given map, the day path beside the step loop it replaced (ns per receiver-step);
 * the cost of Horn's normals (a day without shading, central and horn); on the Colorado tile (or
 * the stand-in) the tool's row split, `hfvis solar --threads 1` and `--threads 2`, bytes compared,
 * and its tiles (`--max-distance --window`, four windows joined by `hfvis mosaic`);
 * then each mode and the oracle on a crop, their ratio and the mode's agreement (mean
 * |fast - oracle| / oracle of the daily global and beam); last the map's directions (--dirs 16,
 * 32, 64 of the exact mode): the whole day's time and the crop's agreement in summer and winter.
 * The DEMs come from HFVIS_BENCH_DEMS, a directory holding colorado_srtm_512_90m.pfm (SRTM,
 * 90 m, 40.2 N 105.6 W) and slovenia_lidar_1000_1m.pfm (lidar DTM, 1 m, 46.5 N 15.8 E); without
 * it a 512^2 fBm with 90 m cells stands in:
 *   HFVIS_BENCH_DEMS=/path/to/dems BENCH_ARGS=solar make bench
 * On the Colorado tile, GRASS r.sun is timed in the same run (examples/bench/solar_grass.sh, named
 * by HFVIS_BENCH_GRASS, which make bench sets: r.sun with its own shadowing, and r.horizon at 5 deg
 * + r.sun), or SKIP is printed where GRASS is absent. docs/solar.md holds the figures. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "bench.h"
#include "../fields.h"

#define SOLAR_CROP 96 /* the oracle's crop: it costs O(steps * W * H * max(W, H)) */
#define SOLAR_DEG (3.14159265358979323846 / 180.0)

typedef struct solar_site { const char *file, *name; double cell, lat, lon; int days, utm_zone; } solar_site;

static int solar_run(const hfvis_grid *g, const hfvis_solar_input *in, const hfvis_solar_options *o,
                     int oracle, float *beam, float *global, double *seconds)
{
    hfvis_solar_output out;
    double t0;
    hfvis_status st;
    memset(&out, 0, sizeof out);
    out.beam = beam;
    out.global = global;
    t0 = bench_now();
    st = oracle ? hfvis_solar_irradiation_reference(g, in, o, &out) : hfvis_solar_irradiation(g, in, o, &out);
    *seconds = bench_now() - t0;
    return st == HFVIS_OK;
}

/* GRASS's times for the DEM (solar_grass.sh through popen): the DEM as an ESRI ASCII grid placed
 * in UTM zone `zone` north around (lat, lon) (the meridian arc and the parallel's scale: within
 * metres, enough for r.sun's site), then the script's lines. */
static void solar_grass(const solar_site *s, const float *z, int w, int h, int zone, double *t_rsun,
                        double *t_rhor)
{
    const char *script = getenv("HFVIS_BENCH_GRASS"), *tmp = getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp";
    char dir[512], asc[600], cmd[2048], line[256];
    double la = s->lat * SOLAR_DEG, dl = (s->lon - (-183.0 + 6.0 * zone)) * SOLAR_DEG;
    double E = 500000.0 + 0.9996 * 6378137.0 * cos(la) * dl;
    double N = 0.9996 * (111132.954 * s->lat - 16038.509 * sin(2.0 * la) + 16.833 * sin(4.0 * la));
    double t_sh = -1.0, t_hor = -1.0, t_rh = -1.0, mean = 0.0;
    FILE *f;
    int x, y;
    if (!script || !*script) { printf("  r.sun: SKIP (HFVIS_BENCH_GRASS unset: run through make bench)\n"); return; }
    snprintf(dir, sizeof dir, "%s/hfvis_bench_solar.XXXXXX", tmp);
    if (!mkdtemp(dir)) { printf("  r.sun: SKIP (cannot create a folder in %s)\n", tmp); return; }
    snprintf(asc, sizeof asc, "%s/dem.asc", dir);
    if (!(f = fopen(asc, "w"))) { printf("  r.sun: SKIP (cannot write %s)\n", asc); return; }
    fprintf(f, "ncols %d\nnrows %d\nxllcorner %.3f\nyllcorner %.3f\ncellsize %g\nNODATA_value -9999\n", w, h,
            E - 0.5 * w * s->cell, N - 0.5 * h * s->cell, s->cell);
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            float v = z[(size_t)y * (size_t)w + (size_t)x];
            fprintf(f, x + 1 < w ? "%.3f " : "%.3f\n", isfinite(v) ? (double)v : -9999.0);
        }
    if (fclose(f) != 0) { printf("  r.sun: SKIP (cannot write %s)\n", asc); remove(asc); remove(dir); return; }
    snprintf(cmd, sizeof cmd, "sh '%s' '%s' %d '%s'", script, asc, 32600 + zone, dir);
    if ((f = popen(cmd, "r")) != NULL) {
        while (fgets(line, sizeof line, f)) {
            if (!strncmp(line, "SKIP", 4)) printf("  r.sun: %s", line);
            sscanf(line, "rsun_shadow %lf", &t_sh);
            sscanf(line, "rhorizon %lf", &t_hor);
            sscanf(line, "rsun_horizon %lf", &t_rh);
            sscanf(line, "rsun_mean %lf", &mean);
        }
        pclose(f);
    }
    remove(asc);
    remove(dir);
    if (t_sh < 0.0 || t_hor < 0.0 || t_rh < 0.0) { printf("  r.sun: no timing (GRASS absent or failed)\n"); return; }
    printf("  GRASS r.sun, same DEM and day (nprocs=1): own shadowing %.2f s; r.horizon 5 deg %.2f s + "
           "r.sun %.2f s = %.2f s; r.sun mean global %.0f Wh/m^2\n", t_sh, t_hor, t_rh, t_hor + t_rh, mean);
    *t_rsun = t_sh;
    *t_rhor = t_hor + t_rh;
}

static int solar_dirs_made;
static void solar_count(void *user, int done, int total)
{
    (void)user; (void)done; (void)total;
    solar_dirs_made++;
}

static const char *const solar_mode_name[4] = { "", "exact", "near-far", "lattice" };

/* A day of `hfvis solar` as a child process: the DEM written as a PFM into a fresh folder, and
 * the arguments every run shares (the site as solar_dem's, day 172, --max-memory 0 --quiet). */
typedef struct solar_tool {
    char *cli;
    char dir[512], in[600], cell[32], lat[32], lon[32], off[32];
} solar_tool;

static int solar_tool_open(solar_tool *t, const solar_site *s, const float *z, int w, int h, const char *what)
{
    const char *tmp = getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp";
    t->cli = getenv("HFVIS_CLI") ? getenv("HFVIS_CLI") : (char *)"build/hfvis";
    snprintf(t->dir, sizeof t->dir, "%s/hfvis_bench_solar.XXXXXX", tmp);
    if (!mkdtemp(t->dir)) {
        printf("  solar %s: cannot create a folder in %s\n", what, tmp);
        return 0;
    }
    snprintf(t->in, sizeof t->in, "%s/dem.pfm", t->dir);
    if (hfvis_pfm_save(t->in, z, w, h, 1, w) != HFVIS_OK) {
        printf("  solar %s: cannot write %s\n", what, t->in);
        rmdir(t->dir);
        return 0;
    }
    snprintf(t->cell, sizeof t->cell, "%.17g", s->cell);
    snprintf(t->lat, sizeof t->lat, "%.17g", s->lat);
    snprintf(t->lon, sizeof t->lon, "%.17g", s->lon);
    snprintf(t->off, sizeof t->off, "%g", s->lon / 15.0 > 0 ? 1.0 : -7.0); /* as solar_dem's */
    return 1;
}

/* The shared arguments into argv; returns their count. */
static int solar_tool_args(solar_tool *t, char **argv)
{
    int a = 0;
    argv[a++] = t->cli, argv[a++] = (char *)"solar", argv[a++] = t->in;
    argv[a++] = (char *)"--cell", argv[a++] = t->cell, argv[a++] = (char *)"--latitude", argv[a++] = t->lat;
    argv[a++] = (char *)"--longitude", argv[a++] = t->lon, argv[a++] = (char *)"--utc-offset", argv[a++] = t->off;
    argv[a++] = (char *)"--day", argv[a++] = (char *)"2026-06-21";
    argv[a++] = (char *)"--max-memory", argv[a++] = (char *)"0", argv[a++] = (char *)"--quiet";
    return a;
}

static void solar_tool_close(solar_tool *t)
{
    remove(t->in);
    rmdir(t->dir);
}

/* The tool's row split of the day (`hfvis solar --threads 1` and `--threads 2`: the map made by
 * directions over the threads, then the library's row_begin/end per thread), as child processes
 * on the DEM written as a PFM: wall and CPU seconds, the speed-up, the outputs equal byte for byte. */
static void solar_threads(const solar_site *s, const float *z, int w, int h, int quick)
{
    static const char *const modes[2] = { "exact", "lattice" };
    solar_tool tool;
    char out[2][700], mode[16], *argv[32];
    int m, t, rep, a;
    if (!solar_tool_open(&tool, s, z, w, h, "--threads")) return;
    for (m = 0; m < 2; m++) {
        double wall[2] = {1e300, 1e300}, cpu[2] = {1e300, 1e300};
        int failed = 0;
        snprintf(mode, sizeof mode, "%s", modes[m]);
        for (t = 0; t < 2; t++) {
            snprintf(out[t], sizeof out[t], "%s/out%d.pfm", tool.dir, t);
            for (rep = 0; rep < (quick ? 1 : 2); rep++) {
                double wl = 0.0, c = 0.0;
                long mem = 0;
                a = solar_tool_args(&tool, argv);
                argv[a++] = (char *)"--horizons", argv[a++] = mode;
                argv[a++] = (char *)"--threads", argv[a++] = (char *)(t ? "2" : "1");
                argv[a++] = (char *)"-o", argv[a++] = out[t];
                argv[a] = NULL;
                if (bench_spawn(argv, &wl, &mem, &c) != 0) failed = 1;
                if (wl < wall[t]) wall[t] = wl;
                if (c < cpu[t]) cpu[t] = c;
            }
        }
        printf("  %-34s tool, --horizons %-8s --threads 1 %.2f s (CPU %.2f), --threads 2 %.2f s (CPU %.2f): %.2fx; "
               "bytes equal: %s\n", "", modes[m], wall[0], cpu[0], wall[1], cpu[1], wall[0] / wall[1],
               failed ? "FAILED" : bench_same_file(out[0], out[1]) ? "yes" : "NO");
        remove(out[0]), remove(out[1]);
    }
    solar_tool_close(&tool);
}

/* `hfvis solar --max-distance R --window` (tiles): the day with R = 100 cells as one run and as
 * four windows (2 x 2) joined by `hfvis mosaic`, child processes on the DEM as a PFM, one thread
 * each: wall and CPU seconds of the whole run and of the windows together (each window computes
 * its halo too), and the mosaic equal to the whole run byte for byte. */
static void solar_windows(const solar_site *s, const float *z, int w, int h)
{
    solar_tool tool;
    char whole[700], piece[4][700], side[720], mosaic[700], win[4][64], radius[32], range[64], *argv[40];
    float lo = HUGE_VALF, hi = -HUGE_VALF;
    int i, a, v;
    size_t c;
    if (!solar_tool_open(&tool, s, z, w, h, "--window")) return;
    for (c = 0; c < (size_t)w * (size_t)h; c++) /* the raster's height range, for --height-range */
        if (isfinite(z[c])) {
            lo = z[c] < lo ? z[c] : lo;
            hi = z[c] > hi ? z[c] : hi;
        }
    snprintf(range, sizeof range, "%.9g,%.9g", (double)lo, (double)hi);
    snprintf(radius, sizeof radius, "%.17g", 100.0 * s->cell);
    snprintf(whole, sizeof whole, "%s/whole.pfm", tool.dir);
    snprintf(mosaic, sizeof mosaic, "%s/mosaic.pfm", tool.dir);
    for (i = 0; i < 4; i++) snprintf(piece[i], sizeof piece[i], "%s/piece%d.pfm", tool.dir, i);
    for (v = 0; v < 2; v++) { /* the windows reading IN's height range, then given it (--height-range) */
        double wall[2] = {0.0, 0.0}, cpu[2] = {0.0, 0.0};
        int failed = 0;
        for (i = v; i < 5 && !failed; i++) { /* i = 0: the whole run (once); 1..4: the windows */
            double wl = 0.0, cp = 0.0;
            long mem = 0;
            a = solar_tool_args(&tool, argv);
            argv[a++] = (char *)"--max-distance", argv[a++] = radius, argv[a++] = (char *)"--threads", argv[a++] = (char *)"1";
            if (i > 0) {
                const int x0 = (i - 1) % 2 ? w / 2 : 0, y0 = (i - 1) / 2 ? h / 2 : 0;
                snprintf(win[i - 1], sizeof win[i - 1], "%d,%d,%d,%d", x0, y0, x0 ? w - w / 2 : w / 2, y0 ? h - h / 2 : h / 2);
                argv[a++] = (char *)"--window", argv[a++] = win[i - 1];
            }
            if (v) argv[a++] = (char *)"--height-range", argv[a++] = range;
            argv[a++] = (char *)"-o", argv[a++] = i ? piece[i - 1] : whole;
            argv[a] = NULL;
            if (bench_spawn(argv, &wl, &mem, &cp) != 0) failed = 1;
            wall[i > 0] += wl;
            cpu[i > 0] += cp;
        }
        if (!failed) {
            double wl = 0.0, cp = 0.0;
            long mem = 0;
            a = 0;
            argv[a++] = tool.cli, argv[a++] = (char *)"mosaic";
            for (i = 0; i < 4; i++) argv[a++] = piece[i];
            argv[a++] = (char *)"--quiet", argv[a++] = (char *)"-o", argv[a++] = mosaic;
            argv[a] = NULL;
            if (bench_spawn(argv, &wl, &mem, &cp) != 0) failed = 1;
        }
        if (!v)
            printf("  %-34s tool, --max-distance %s --window (4 windows, 1 thread): whole %.2f s (CPU %.2f), windows "
                   "%.2f s (CPU %.2f, x%.2f the whole: the halos); mosaic equal to the whole run: %s\n",
                   "", radius, wall[0], cpu[0], wall[1], cpu[1], cpu[1] / cpu[0],
                   failed ? "FAILED" : bench_same_file(whole, mosaic) ? "yes" : "NO");
        else
            printf("  %-34s the same 4 windows with --height-range %s (no pass over IN): %.2f s (CPU %.2f); "
                   "mosaic equal to the whole run: %s\n", "", range, wall[1], cpu[1],
                   failed ? "FAILED" : bench_same_file(whole, mosaic) ? "yes" : "NO");
        for (i = 0; i < 4; i++) {
            remove(piece[i]);
            snprintf(side, sizeof side, "%.700s.tile", piece[i]);
            remove(side);
        }
        remove(mosaic);
    }
    remove(whole);
    solar_tool_close(&tool);
}

/* The mean over the crop of |fast - oracle| / oracle: *eg of the daily global (each cell's oracle
 * floored at 1 Wh/m^2), *eb of the beam where the oracle's exceeds 1 Wh/m^2; *pg the 99th
 * percentile of the global's (the tail a mean hides: narrow valleys in winter). */
static void solar_crop_error(const float *fb, const float *fg, const float *ob, const float *og, double *eg,
                             double *eb, double *pg)
{
    static double rel[SOLAR_CROP * SOLAR_CROP];
    double sum_g = 0.0, sum_b = 0.0;
    int nb = 0;
    size_t i, n = (size_t)SOLAR_CROP * SOLAR_CROP;
    for (i = 0; i < n; i++) {
        rel[i] = fabs((double)fg[i] - (double)og[i]) / ((double)og[i] > 1.0 ? (double)og[i] : 1.0);
        sum_g += rel[i];
        if (ob[i] > 1.0f) {
            sum_b += fabs((double)fb[i] - (double)ob[i]) / (double)ob[i];
            nb++;
        }
    }
    *eg = sum_g / (double)n;
    *eb = nb ? sum_b / nb : 0.0;
    qsort(rel, n, sizeof(double), bench_cmp_double);
    *pg = rel[(size_t)(0.99 * (double)(n - 1))];
}

/* The map's directions against speed and accuracy (exact horizons, the default mode): the whole
 * DEM's day at K = 16 and 32 beside the default 64 (t64, measured above), each K's ratio to r.sun
 * (t_rsun > 0), and on the crop cz each K's mean error against the oracle on day 172 and on day
 * 355 (the low winter sun: the longest shadows, where the map's azimuth interpolation between
 * directions 360/K deg apart errs most). */
static void solar_directions(const solar_site *s, const float *z, int w, int h, const float *cz, double t64,
                             double t_rsun, int quick)
{
    static const int ks[3] = { 16, 32, 64 };
    static float fb[SOLAR_CROP * SOLAR_CROP], fg[SOLAR_CROP * SOLAR_CROP];
    static float ob[2][SOLAR_CROP * SOLAR_CROP], og[2][SOLAR_CROP * SOLAR_CROP];
    hfvis_grid g, c;
    hfvis_solar_input in = hfvis_solar_input_default();
    hfvis_solar_options o = hfvis_solar_options_default();
    float *b1 = (float *)malloc((size_t)w * (size_t)h * sizeof(float));
    float *g1 = (float *)malloc((size_t)w * (size_t)h * sizeof(float));
    double t, e[2][3];
    int k, d, rep;
    if (!b1 || !g1) {
        free(b1); free(g1);
        return;
    }
    g.z = z; g.width = w; g.height = h; g.stride = w; g.cell_size = s->cell;
    c = g;
    c.z = cz; c.width = c.height = c.stride = SOLAR_CROP;
    in.latitude_rad = s->lat * SOLAR_DEG;
    in.longitude_rad = s->lon * SOLAR_DEG;
    in.utc_offset_hours = s->lon / 15.0 > 0 ? 1.0 : -7.0;
    in.days = 1;
    for (d = 0; d < 2; d++) { /* the oracle: day 172, then day 355 */
        in.month = d ? 12 : 6;
        in.day = 21;
        if (!solar_run(&c, &in, &o, 1, ob[d], og[d], &t)) {
            printf("  %s: the oracle failed\n", s->name);
            free(b1); free(g1);
            return;
        }
    }
    printf("  %-34s directions of the exact map: whole day 172, ratio to r.sun; the crop's mean |fast - oracle| /\n"
           "  %-34s oracle of the global and the beam, day 172 and day 355:\n", "", "");
    for (k = 0; k < 3; k++) {
        double best = k == 2 ? t64 : 1e30;
        o.directions = ks[k];
        in.month = 6;
        for (rep = 0; k < 2 && rep < (quick ? 1 : 2); rep++)
            if (solar_run(&g, &in, &o, 0, b1, g1, &t) && t < best) best = t;
        for (d = 0; d < 2; d++) {
            in.month = d ? 12 : 6;
            if (!solar_run(&c, &in, &o, 0, fb, fg, &t)) break;
            solar_crop_error(fb, fg, ob[d], og[d], &e[d][0], &e[d][1], &e[d][2]);
        }
        printf("  %-34s   --dirs %2d  %5.2f s", "", ks[k], best);
        if (t_rsun > 0.0) printf(" (%4.1fx r.sun)", t_rsun / best);
        printf("; day 172 global %.4f %% (p99 %.2f %%), beam %.4f %%; day 355 global %.4f %% (p99 %.2f %%), beam %.4f %%\n",
               100.0 * e[0][0], 100.0 * e[0][2], 100.0 * e[0][1], 100.0 * e[1][0], 100.0 * e[1][2], 100.0 * e[1][1]);
    }
    free(b1); free(g1);
}

static void solar_dem(const solar_site *s, float *z, int w, int h, int quick)
{
    hfvis_grid g;
    hfvis_solar_input in = hfvis_solar_input_default();
    hfvis_solar_options o = hfvis_solar_options_default();
    hfvis_sweep_options sw = hfvis_sweep_options_default(), cnt = hfvis_sweep_options_default();
    size_t n = (size_t)w * (size_t)h, i;
    float *b1 = (float *)malloc(n * sizeof(float)), *g1 = (float *)malloc(n * sizeof(float));
    float *map = (float *)malloc(n * (size_t)64 * sizeof(float)), *ones = (float *)malloc(n * sizeof(float));
    float *cz = (float *)malloc((size_t)SOLAR_CROP * SOLAR_CROP * sizeof(float));
    static float cb[2][SOLAR_CROP * SOLAR_CROP], cg[2][SOLAR_CROP * SOLAR_CROP];
    double t_mode[4] = { 0, 1e30, 1e30, 1e30 }, t_map = 1e30, t_day = 1e30, t_loop = 1e30, t, t_or, t_cf;
    double t_rsun = -1.0, t_rhor = -1.0, steps, mean = 0.0;
    int rep, x, y, m, dirs[4] = { 0, 0, 0, 0 };
    if (!b1 || !g1 || !map || !ones || !cz) {
        printf("  %s: out of memory\n", s->name);
        free(b1); free(g1); free(map); free(ones); free(cz);
        return;
    }
    for (i = 0; i < n; i++) ones[i] = 1.0f;
    g.z = z; g.width = w; g.height = h; g.stride = w; g.cell_size = s->cell;
    in.latitude_rad = s->lat * SOLAR_DEG;
    in.longitude_rad = s->lon * SOLAR_DEG;
    in.utc_offset_hours = s->lon / 15.0 > 0 ? 1.0 : -7.0;
    in.days = s->days;
    cnt.progress = solar_count;
    for (rep = 0; rep < (quick ? 1 : 2); rep++) { /* the minimum of the runs: a shared machine */
        for (m = HFVIS_SOLAR_HORIZONS_EXACT; m <= HFVIS_SOLAR_HORIZONS_LATTICE; m++) {
            hfvis_solar_options mo = o;
            mo.horizons = (hfvis_solar_horizons)m;
            mo.sweep = &cnt;
            solar_dirs_made = 0;
            if (!solar_run(&g, &in, &mo, 0, b1, g1, &t)) { printf("  %s: failed\n", s->name); break; }
            if (t < t_mode[m]) t_mode[m] = t;
            dirs[m] = solar_dirs_made;
            if (m == HFVIS_SOLAR_HORIZONS_EXACT && rep == 0)
                for (i = 0; i < n; i++) mean += (double)g1[i];
        }
        sw.rays = HFVIS_RAYS_EXACT; /* the whole exact map alone */
        t = bench_now();
        hfvis_horizon_map(&g, 64, &sw, map);
        t = bench_now() - t;
        if (t < t_map) t_map = t;
        { /* the integration alone over that map: the day path, and the step loop it replaced (a
             coefficient raster of ones takes the loop, term for term the same model) */
            hfvis_solar_options io = o;
            io.horizon_map = map;
            if (solar_run(&g, &in, &io, 0, b1, g1, &t) && t < t_day) t_day = t;
            io.coeff_bh = ones;
            if (solar_run(&g, &in, &io, 0, b1, g1, &t) && t < t_loop) t_loop = t;
        }
    }
    { /* the sunlit steps of the day at the site */
        hfvis_grid one;
        hfvis_solar_options fo = o;
        hfvis_solar_output so;
        float z0 = 0.0f, hours = 0.0f;
        one.z = &z0; one.width = one.height = one.stride = 1; one.cell_size = s->cell;
        fo.no_shading = 1;
        memset(&so, 0, sizeof so);
        so.sun_hours = &hours;
        hfvis_solar_irradiation(&one, &in, &fo, &so);
        steps = ceil((double)hours / 0.25) + 1.0;
    }
    printf("  %-34s %4d x %-4d %3d day(s), mean global %.0f Wh/m^2; the whole exact map K = 64 alone %.2f s\n",
           s->name, w, h, s->days, mean / (double)n, t_map);
    printf("  %-34s integration after the map (%.0f sunlit steps): day path %.3f s = %.1f ns per receiver-step; "
           "step loop %.3f s = %.1f ns (%.1fx)\n", "", steps, t_day, t_day * 1e9 / ((double)n * steps), t_loop,
           t_loop * 1e9 / ((double)n * steps), t_loop / t_day);
    if (s->utm_zone) solar_grass(s, z, w, h, s->utm_zone, &t_rsun, &t_rhor);
    for (m = HFVIS_SOLAR_HORIZONS_EXACT; m <= HFVIS_SOLAR_HORIZONS_LATTICE; m++) {
        printf("  %-34s --horizons %-8s %6.2f s, %2d of 64 directions, %.2f us/receiver", "", solar_mode_name[m],
               t_mode[m], dirs[m], t_mode[m] * 1e6 / (double)n);
        if (t_rsun > 0.0)
            printf("; %.1fx r.sun (target 20x), %.1fx r.horizon + r.sun (target 50x)", t_rsun / t_mode[m],
                   t_rhor / t_mode[m]);
        printf("\n");
    }
    { /* Horn's normals (--normals horn): their cost, all at set-up (a 3x3 stencil per receiver),
         timed on a day without shading (no map) */
        hfvis_solar_options no = o;
        double tc = 1e30, th = 1e30;
        no.no_shading = 1;
        for (rep = 0; rep < (quick ? 1 : 3); rep++) {
            no.normals = HFVIS_SOLAR_NORMALS_CENTRAL;
            if (solar_run(&g, &in, &no, 0, b1, g1, &t) && t < tc) tc = t;
            no.normals = HFVIS_SOLAR_NORMALS_HORN;
            if (solar_run(&g, &in, &no, 0, b1, g1, &t) && t < th) th = t;
        }
        printf("  %-34s normals, a day without shading: central %.3f s, horn %.3f s: %+.1f ns per receiver\n", "",
               tc, th, (th - tc) * 1e9 / (double)n);
    }
    if (s->utm_zone || !s->file[0]) solar_threads(s, z, w, h, quick);
    if (s->utm_zone || !s->file[0]) solar_windows(s, z, w, h);
    printf("  %-34s memory: 4 bytes per receiver and direction made (the map: the counts above; K = 64 and a\n"
           "  %-34s sample-major copy, 256 + 256, for long periods and the step loop) + 120 + 32 per band\n", "", "");
    /* fast (each mode) and oracle on the central crop */
    for (y = 0; y < SOLAR_CROP; y++)
        for (x = 0; x < SOLAR_CROP; x++)
            cz[y * SOLAR_CROP + x] = z[(size_t)(h / 2 - SOLAR_CROP / 2 + y) * (size_t)w + (size_t)(w / 2 - SOLAR_CROP / 2 + x)];
    g.z = cz; g.width = g.height = SOLAR_CROP; g.stride = SOLAR_CROP;
    in.days = 1;
    if (!solar_run(&g, &in, &o, 1, cb[1], cg[1], &t_or)) {
        printf("  %s crop: failed\n", s->name);
        m = HFVIS_SOLAR_HORIZONS_LATTICE + 1;
    } else {
        m = HFVIS_SOLAR_HORIZONS_EXACT;
    }
    for (; m <= HFVIS_SOLAR_HORIZONS_LATTICE; m++) {
        hfvis_solar_options mo = o;
        double eg, eb, pg;
        mo.horizons = (hfvis_solar_horizons)m;
        if (!solar_run(&g, &in, &mo, 0, cb[0], cg[0], &t_cf)) {
            printf("  %s crop: failed\n", s->name);
            break;
        }
        solar_crop_error(cb[0], cg[0], cb[1], cg[1], &eg, &eb, &pg);
        printf("  %-34s crop %d^2, 1 day, --horizons %-8s fast %.3f s, oracle %.2f s (%.0fx); mean |fast - oracle| / "
               "oracle: global %.4f %% (p99 %.2f %%), beam %.4f %%\n", s->name, SOLAR_CROP, solar_mode_name[m], t_cf,
               t_or, t_or / t_cf, 100.0 * eg, 100.0 * pg, 100.0 * eb);
    }
    solar_directions(s, z, w, h, cz, t_mode[HFVIS_SOLAR_HORIZONS_EXACT], t_rsun, quick);
    free(b1); free(g1); free(map); free(ones); free(cz);
}

/* The solar sections' stand-in for the DEMs: a 512^2 fBm with 1500 of relief (metres with 90 m
 * cells), malloc'd; NULL when out of memory. */
float *bench_solar_standin(void)
{
    hfvis_field f;
    float *z = (float *)malloc((size_t)512 * 512 * sizeof(float));
    if (!z) return NULL;
    memset(&f, 0, sizeof f);
    f.kind = HFVIS_FIELD_FBM;
    f.amplitude = 1500.0;
    f.wavelength = 200.0;
    f.seed = 5;
    hfvis_field_generate(&f, 512, 512, 512, z);
    return z;
}

void bench_solar(int quick)
{
    static const solar_site sites[2] = {
        {"colorado_srtm_512_90m.pfm", "Colorado SRTM (90 m), day 172", 90.0, 40.24, -105.53, 1, 13},
        {"slovenia_lidar_1000_1m.pfm", "Slovenia lidar DTM (1 m), day 172", 1.0, 46.47, 15.83, 1, 0},
    };
    const char *dir = getenv("HFVIS_BENCH_DEMS");
    int k, ran = 0;
    printf("\nSolar irradiation (hfvis_solar_irradiation, SPA sun, 15-minute steps, K = 64 horizon map of each\n"
           "--horizons mode; one thread, everything included; times are the minimum of %d runs):\n", quick ? 1 : 2);
    for (k = 0; dir && *dir && k < 2; k++) {
        char path[4096];
        float *z = NULL;
        hfvis_image_info info;
        snprintf(path, sizeof path, "%s/%s", dir, sites[k].file);
        if (hfvis_image_load(path, NULL, &z, &info) != HFVIS_OK) {
            printf("  %s: cannot load\n", path);
            continue;
        }
        solar_dem(&sites[k], z, info.width, info.height, quick);
        hfvis_free(NULL, z);
        ran++;
    }
    if (!ran) {
        static const solar_site fbm = {"", "fBm 512^2 (90 m cells), day 172", 90.0, 40.24, -105.53, 1, 0};
        float *z = bench_solar_standin();
        if (!z) return;
        printf("  (HFVIS_BENCH_DEMS unset: a synthetic field)\n");
        solar_dem(&fbm, z, 512, 512, quick);
        free(z);
    }
}
