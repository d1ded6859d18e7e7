/* bench_gi2.c - Nowrouzezahrai-Snyder GI (hfvis_ns_gi) beside the exact P1 + P2 pipeline
 * (hfvis_direct_light + hfvis_indirect_light bounces) on the bench's seeded fBm, in the shape of
 * [NS09] Table 1: per height-field size and sub-sampling, the scratch memory, the time per frame
 * for 1, 2 and 3 indirect bounces, the exact pipeline's time for the same frames, the speed-up and
 * the RMS difference of the final radiance. Scene: a uniform sky of radiance 1 (SH), one
 * directional sun (hard shadows in both pipelines), albedo 0.5, one channel. NS uses its defaults
 * (m = 32, k = 4, o_v = o_u = 2, B-spline omega_max); the exact pipeline K = 16 directions (the
 * CLI's default; its cost is linear in K). Usage: bench_gi2 [quick]. */
#define _POSIX_C_SOURCE 199309L
#include "bench.h"
#include "hfvis.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define BENCH_GI2_K 16          /* exact pipeline directions */
#define BENCH_GI2_ALBEDO 0.5f
#define BENCH_GI2_B 3           /* bounces */

static void *bench_gi2_xmalloc(size_t n)
{
    void *p = malloc(n);
    if (!p) {
        fprintf(stderr, "bench_gi2: out of memory (%lu bytes)\n", (unsigned long)n);
        exit(1);
    }
    memset(p, 0, n);
    return p;
}

static void bench_gi2_die(const char *what, hfvis_status s)
{
    fprintf(stderr, "bench_gi2: %s: %s\n", what, hfvis_status_string(s));
    exit(1);
}

/* The time at the end of each pass of hfvis_ns_gi, from its progress callback (one call per
 * receiver row of each pass): pass p ends when done reaches (p+1) * rows. */
typedef struct {
    double t0, end[BENCH_GI2_B + 1];
    int rows;
} bench_gi2_clock;
static void bench_gi2_progress(void *user, int done, int total)
{
    bench_gi2_clock *c = (bench_gi2_clock *)user;
    (void)total;
    if (done % c->rows == 0 && done / c->rows <= BENCH_GI2_B + 1) c->end[done / c->rows - 1] = bench_now() - c->t0;
}

/* The bench terrain of examples/bench/bench.c: fBm, amplitude n/8, base wavelength n/4, seed 3. */
static void bench_gi2_terrain(float *z, int n)
{
    hfvis_field f;
    hfvis_status s;
    memset(&f, 0, sizeof f);
    f.kind = HFVIS_FIELD_FBM;
    f.amplitude = (double)n / 8.0;
    f.wavelength = (double)n / 4.0;
    f.seed = 3;
    if ((s = hfvis_field_generate(&f, n, n, n, z)) != HFVIS_OK) bench_gi2_die("field", s);
}

static hfvis_sun bench_gi2_sun(void)
{
    hfvis_sun sun;
    memset(&sun, 0, sizeof sun);
    sun.azimuth_rad = 0.7;
    sun.elevation_rad = 0.5;
    sun.irradiance[0] = 3.14159265f;
    return sun;
}

/* The exact pipeline: D = hfvis_direct_light (sky + hard sun), L_0 = rho D,
 * L_b = rho (D + I[L_(b-1)]) with I = hfvis_indirect_light (sky 0, albedo 1), as hfvis_terrain_gi.
 * L must hold (B+1) planes; t[b] = time of a frame with b bounces. */
static void bench_gi2_exact(const hfvis_grid *g, float *L, double *t, size_t *peak)
{
    const size_t cells = (size_t)g->width * (size_t)g->height;
    float *D = (float *)bench_gi2_xmalloc(sizeof(float) * cells), *I = (float *)bench_gi2_xmalloc(sizeof(float) * cells);
    hfvis_sun sun = bench_gi2_sun();
    hfvis_sweep_options so = hfvis_sweep_options_default();
    hfvis_allocator al;
    bench_tracker tr = {0, 0, 0, 0};
    hfvis_status s;
    double t0 = bench_now();
    size_t i;
    int b;
    al.alloc = bench_track_alloc;
    al.free = bench_track_free;
    al.user = &tr;
    so.alloc = &al;
    if ((s = hfvis_direct_light(g, BENCH_GI2_K, &sun, 1.0f, NULL, 1, &so, D)) != HFVIS_OK) bench_gi2_die("direct", s);
    for (i = 0; i < cells; i++) L[i] = BENCH_GI2_ALBEDO * D[i];
    t[0] = bench_now() - t0;
    for (b = 1; b <= BENCH_GI2_B; b++) {
        float *prev = L + (size_t)(b - 1) * cells, *cur = L + (size_t)b * cells;
        if ((s = hfvis_indirect_light(g, BENCH_GI2_K, prev, 1, 0.0f, 1.0f, &so, NULL, I, g->width)) != HFVIS_OK)
            bench_gi2_die("indirect", s);
        for (i = 0; i < cells; i++) cur[i] = BENCH_GI2_ALBEDO * (D[i] + I[i]);
        t[b] = bench_now() - t0;
    }
    *peak = tr.peak;
    free(D);
    free(I);
}

/* hfvis_ns_gi with `bounces` bounces, sub-sampling s: tot receives (B+1) planes, the totals after
 * 0..B bounces; t[b] the time of a frame with b bounces (end of pass b). */
static void bench_gi2_ns(const hfvis_grid *g, int s, int bounces, float *tot, double *t, size_t *peak,
                         size_t *query)
{
    const size_t cells = (size_t)g->width * (size_t)g->height;
    float *dir = tot, *bo = tot + cells;
    double env[16];
    hfvis_sun sun = bench_gi2_sun();
    hfvis_ns_scene sc;
    hfvis_ns_gi_options o;
    hfvis_ns_gi_outputs out;
    hfvis_allocator al;
    bench_tracker tr = {0, 0, 0, 0};
    bench_gi2_clock ck;
    hfvis_status st;
    size_t i;
    int b;
    memset(env, 0, sizeof env);
    env[0] = 2.0 * sqrt(3.14159265358979323846); /* uniform sky of radiance 1 */
    memset(&sc, 0, sizeof sc);
    sc.channels = 1;
    sc.env_sh = env;
    sc.lights = &sun;
    sc.light_count = 1;
    sc.albedo[0] = BENCH_GI2_ALBEDO;
    memset(&o, 0, sizeof o);
    o.subsample = s;
    al.alloc = bench_track_alloc;
    al.free = bench_track_free;
    al.user = &tr;
    o.alloc = &al;
    o.progress = bench_gi2_progress;
    o.progress_user = &ck;
    memset(&out, 0, sizeof out);
    out.bounces = bounces;
    out.direct = dir;
    out.bounce = bo;
    memset(&ck, 0, sizeof ck);
    ck.rows = (g->height + s - 1) / s;
    if ((st = hfvis_ns_gi_scratch_size(g, &sc, &o, bounces, query)) != HFVIS_OK) bench_gi2_die("ns scratch", st);
    ck.t0 = bench_now();
    if ((st = hfvis_ns_gi(g, &sc, &o, &out)) != HFVIS_OK) bench_gi2_die("ns gi", st);
    for (b = 0; b <= bounces; b++) t[b] = ck.end[b];
    /* planes 1..B become the running totals */
    for (b = 1; b <= bounces; b++) {
        float *prev = tot + (size_t)(b - 1) * cells, *cur = tot + (size_t)b * cells;
        for (i = 0; i < cells; i++) cur[i] = prev[i] + cur[i];
    }
    *peak = tr.peak;
}

static double bench_gi2_rms(const float *a, const float *b, size_t n, double *mean)
{
    double s = 0.0, m = 0.0;
    size_t i, k = 0;
    for (i = 0; i < n; i++) {
        if (!isfinite(a[i]) || !isfinite(b[i])) continue;
        s += ((double)a[i] - (double)b[i]) * ((double)a[i] - (double)b[i]);
        m += (double)b[i];
        k++;
    }
    *mean = k ? m / (double)k : 0.0;
    return k ? sqrt(s / (double)k) : 0.0;
}

/* The table. quick: 256^2 only. The full run skips bounces 2 and 3 of 1024^2 at 1x (a pass there
 * takes about half a minute on one core): their times are extrapolated from the measured per-bounce
 * time (marked ~) and their errors not measured. */
void bench_gi2(int quick)
{
    static const int sizes[3] = {256, 512, 1024}, subs[3] = {1, 2, 4};
    const int nsizes = quick ? 1 : 3;
    int si, k, b;
    printf("\nNowrouzezahrai-Snyder GI (m 32, k 4, o 2; sky + hard sun, albedo 0.5) beside the exact P1+P2 "
           "pipeline (K %d)\n", BENCH_GI2_K);
    printf("%-6s %-4s %8s | %-27s | %-27s | %-17s | %s\n", "HF", "sub", "mem MB", "NS ms/frame, 1 2 3 bounces",
           "exact ms/frame, 1 2 3", "speed-up 1 2 3", "RMS error 0 1 2 3 bounces (% of mean)");
    for (si = 0; si < nsizes; si++) {
        const int n = sizes[si];
        const size_t cells = (size_t)n * (size_t)n;
        float *z = (float *)bench_gi2_xmalloc(sizeof(float) * cells);
        float *L = (float *)bench_gi2_xmalloc(sizeof(float) * cells * (BENCH_GI2_B + 1));
        float *T = (float *)bench_gi2_xmalloc(sizeof(float) * cells * (BENCH_GI2_B + 1));
        double te[BENCH_GI2_B + 1], tn[BENCH_GI2_B + 1];
        size_t peak_e = 0, peak_n = 0, query = 0;
        hfvis_grid g;
        bench_gi2_terrain(z, n);
        g.z = z;
        g.width = n;
        g.height = n;
        g.stride = n;
        g.cell_size = 1.0;
        bench_gi2_exact(&g, L, te, &peak_e);
        for (k = 0; k < 3; k++) {
            const int s = subs[k], B = (n >= 1024 && s == 1) ? 1 : BENCH_GI2_B;
            char row[3][3][32], e0[32];
            double mean0;
            bench_gi2_ns(&g, s, B, T, tn, &peak_n, &query);
            snprintf(e0, sizeof e0, "%.2f%%", 100.0 * bench_gi2_rms(T, L, cells, &mean0) / mean0);
            for (b = 1; b <= BENCH_GI2_B; b++) {
                double mean, e, tb = b <= B ? tn[b] : tn[B] + (double)(b - B) * (tn[B] - tn[B - 1]);
                snprintf(row[0][b - 1], sizeof row[0][b - 1], "%s%.0f", b <= B ? "" : "~", tb * 1e3);
                snprintf(row[1][b - 1], sizeof row[1][b - 1], "%.1fx", te[b] / tb);
                if (b <= B) {
                    e = bench_gi2_rms(T + (size_t)b * cells, L + (size_t)b * cells, cells, &mean);
                    snprintf(row[2][b - 1], sizeof row[2][b - 1], "%.2f%%", 100.0 * e / mean);
                } else {
                    snprintf(row[2][b - 1], sizeof row[2][b - 1], "-");
                }
            }
            printf("%4d^2 %2dx  %8.1f | %8s %8s %8s    | %8.0f %8.0f %8.0f    | %5s %5s %5s | %s %s %s %s\n", n, s,
                   (double)peak_n / 1048576.0, row[0][0], row[0][1], row[0][2], te[1] * 1e3, te[2] * 1e3,
                   te[3] * 1e3, row[1][0], row[1][1], row[1][2], e0, row[2][0], row[2][1], row[2][2]);
            if (query != peak_n) printf("  (scratch query %lu != peak %lu)\n", (unsigned long)query, (unsigned long)peak_n);
            if (s == 1)
                printf("       NS direct pass %.1f ns per receiver-direction (%d + 1 sun slices), bounce "
                       "pass %.1f ns; exact: direct %.1f, bounce %.1f ns per receiver-direction (K %d); "
                       "exact scratch %.1f MB\n",
                       tn[0] * 1e9 / ((double)cells * 33.0), 32, (tn[1] - tn[0]) * 1e9 / ((double)cells * 32.0),
                       te[0] * 1e9 / ((double)cells * BENCH_GI2_K),
                       (te[1] - te[0]) * 1e9 / ((double)cells * BENCH_GI2_K), BENCH_GI2_K,
                       (double)peak_e / 1048576.0);
        }
        free(z);
        free(L);
        free(T);
    }
    printf("(mem: hfvis_ns_gi's scratch at its peak, all passes; [NS09] Table 1 counts 16-bit GPU textures "
           "incl. inputs.  ~: extrapolated from the measured bounce pass)\n");
}
