/* bench_threads.c - `hfvis --threads` (the tool's split of one run over POSIX threads, byte for
 * byte the one-thread output): skyview, sky and horizon in both ray modes and shadow on an N x N
 * fBm PFM (and the GeoTIFF writer and reader: horizon into a .tif, the exact shadow of the same
 * fBm as a DEFLATE GeoTIFF; the ASC reader and writer: the exact shadow of it as a .asc, the
 * shadow into a .asc), each run as a child process with --threads 1 and with --threads T (the online cores,
 * at least 2): wall and CPU seconds (user + system, all threads), peak memory, the speed-up and
 * whether the two outputs are equal byte for byte; the minimum of HFVIS_BENCH_THREADS_RUNS runs
 * (default 1) of each. N = $HFVIS_BENCH_THREADS_N (default 2048; quick 512). Then, in process, the
 * lattice sky-light sums split as the tool splits them (one quarter-turn group per call) with the
 * grid's normals computed once and shared (hfvis_sweep_options.normals) against each call making
 * its own. The tool is $HFVIS_CLI (make bench sets it), else build/hfvis; files go to $TMPDIR. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "bench.h"
#include "../raster_io.h"

/* An N x N fBm (1 m cells, relief about N/8) written as a PFM at path, as a GeoTIFF at tif
 * (tiled 256, DEFLATE, predictor 3: as the tool and GDAL's usual options write one) and as an
 * ASC grid at asc; 0 on success. */
static int threads_field(const char *path, const char *tif, const char *asc, int n, float **z_out)
{
    ex_rio_write_options wo;
    ex_rio_image img;
    char err[256];
    hfvis_field f;
    float *z = (float *)malloc((size_t)n * (size_t)n * sizeof(float));
    int x, y;
    if (!z) return -1;
    memset(&f, 0, sizeof f);
    f.kind = HFVIS_FIELD_FBM;
    f.amplitude = n / 8.0;
    f.wavelength = n / 4.0;
    f.seed = 26;
    for (y = 0; y < n; y++)
        for (x = 0; x < n; x++) z[(size_t)y * (size_t)n + (size_t)x] = (float)hfvis_field_height(&f, x, y);
    memset(&wo, 0, sizeof wo);
    wo.tiled = 1;
    wo.deflate = 1;
    wo.predictor = 3;
    img.data = z, img.width = n, img.height = n, img.bands = 1;
    img.pixel_step = 1, img.row_step = (size_t)n, img.band_step = (size_t)n * (size_t)n;
    if (hfvis_pfm_save(path, z, n, n, 1, n) != HFVIS_OK || ex_rio_write(tif, &img, NULL, &wo, err) != 0 ||
        ex_rio_write(asc, &img, NULL, NULL, err) != 0) {
        free(z);
        return -1;
    }
    *z_out = z;
    return 0;
}

/* The shared normals: 4 sky-light group calls (K = 16, lattice, sweep order) into one sum, each
 * computing the normals in its scratch, against the normals computed once and passed to all. */
static void threads_normals(const float *z, int n)
{
    const int K = 16;
    hfvis_grid g;
    hfvis_sweep_options o = hfvis_sweep_options_default();
    double *a = (double *)malloc((size_t)n * (size_t)n * sizeof(double));
    double *b = (double *)malloc((size_t)n * (size_t)n * sizeof(double));
    double *part = (double *)malloc((size_t)n * (size_t)n * sizeof(double));
    float *nrm = (float *)malloc((size_t)n * (size_t)n * 3 * sizeof(float));
    double t[2], t0;
    size_t i, cells = (size_t)n * (size_t)n;
    int r, u, same = 1;
    if (!a || !b || !part || !nrm) {
        printf("  shared normals: out of memory\n");
        free(a), free(b), free(part), free(nrm);
        return;
    }
    g.z = z, g.width = n, g.height = n, g.stride = n, g.cell_size = 1.0;
    o.direction_order = HFVIS_DIRECTION_ORDER_SWEEP;
    for (r = 0; r < 2; r++) {
        double *acc = r ? b : a;
        t0 = bench_cpu_now();
        o.normals = NULL;
        if (r == 1 && hfvis_normals_compute(&g, nrm) == HFVIS_OK) o.normals = nrm;
        for (u = 0; u < K / 4; u++) { /* the tool's units, added in order */
            o.direction_begin = 4 * u, o.direction_end = 4 * u + 4;
            if (hfvis_direction_sums(&g, K, HFVIS_SUM_SKY_LIGHT, NULL, NULL, &o, u ? part : acc) != HFVIS_OK) {
                printf("  shared normals: hfvis_direction_sums failed\n");
                free(a), free(b), free(part), free(nrm);
                return;
            }
            if (u)
                for (i = 0; i < cells; i++) acc[i] += part[i];
        }
        t[r] = bench_cpu_now() - t0;
    }
    for (i = 0; i < cells; i++)
        if (a[i] != b[i] && !(a[i] != a[i] && b[i] != b[i])) same = 0;
    printf("  shared normals (sky-light sums, %d^2, K = %d, 4 group calls, CPU): own normals per call "
           "%.3f s, shared (computed once, included) %.3f s, %.2fx; sums equal bit for bit: %s\n",
           n, K, t[0], t[1], t[0] / t[1], same ? "yes" : "NO");
    free(a), free(b), free(part), free(nrm);
}

/* The exact-ray grid data (hfvis_exact_grid_compute) shared: the exact sky-view sums of K = 16
 * directions in 4 bands each, a call per band as the tool's units, each call deriving the data itself
 * against the data made once (included) and passed to all. Above HFVIS_EXACT_TWIST_PLANE_CELLS
 * the sweep reads the class alone, so that is all the tool makes (hfvis_exact_grid_rows, out
 * NULL) and all this makes. */
static void threads_exact_grid(const float *z, int n)
{
    const int K = 16;
    const size_t cells = (size_t)n * (size_t)n;
    hfvis_grid g;
    hfvis_sweep_options o = hfvis_sweep_options_default();
    double *a = (double *)calloc(cells, sizeof(double)), *b = (double *)calloc(cells, sizeof(double));
    double *data = (double *)malloc((cells + 1) * sizeof(double));
    double t[2], t0, t_data = 0.0;
    const int twists = cells <= (size_t)HFVIS_EXACT_TWIST_PLANE_CELLS;
    size_t i;
    int r, k, cls, same = 1;
    if (!a || !b || !data) {
        printf("  shared exact grid data: out of memory\n");
        free(a), free(b), free(data);
        return;
    }
    g.z = z, g.width = n, g.height = n, g.stride = n, g.cell_size = 1.0;
    o.rays = HFVIS_RAYS_EXACT;
    for (r = 0; r < 2; r++) {
        t0 = bench_cpu_now();
        o.exact_grid = NULL;
        if (r == 1) {
            hfvis_status s = twists ? hfvis_exact_grid_compute(&g, data) : hfvis_exact_grid_rows(&g, 0, n, NULL, &cls);
            if (!twists) data[cells] = (double)cls;
            t_data = bench_cpu_now() - t0;
            if (s == HFVIS_OK) o.exact_grid = data;
        }
        for (k = 0; k < K * 4; k++) { /* the tool's units: 4 bands of a direction, added in place */
            o.direction_begin = k / 4, o.direction_end = k / 4 + 1;
            o.part_index = k % 4, o.part_count = 4;
            if (hfvis_direction_sums(&g, K, HFVIS_SUM_SKY_VIEW, NULL, NULL, &o, r ? b : a) != HFVIS_OK) {
                printf("  shared exact grid data: hfvis_direction_sums failed\n");
                free(a), free(b), free(data);
                return;
            }
        }
        t[r] = bench_cpu_now() - t0;
    }
    for (i = 0; i < cells; i++)
        if (a[i] != b[i] && !(a[i] != a[i] && b[i] != b[i])) same = 0;
    printf("  shared exact grid data (exact sky-view sums, %d^2, K = %d, 4 band calls a direction, CPU): each call "
           "its own %.3f s, shared %.3f s (of which making it %.3f s = %.2f ns a cell, %s), %.2fx; sums equal "
           "bit for bit: %s\n",
           n, K, t[0], t[1], t_data, 1e9 * t_data / (double)cells,
           twists ? "twists and class" : "the class alone: above HFVIS_EXACT_TWIST_PLANE_CELLS",
           t[0] / t[1], same ? "yes" : "NO");
    free(a), free(b), free(data);
}

void bench_threads(int quick)
{
    static char *const runs[][9] = { /* name, input and output type, then the command and its flags */
        {"skyview K=64", "pfm pfm", "skyview", "--dirs", "64", NULL},
        {"skyview K=16 exact", "pfm pfm", "skyview", "--dirs", "16", "--exact", NULL},
        {"sky K=64", "pfm pfm", "sky", "--dirs", "64", NULL},
        {"sky K=16 exact", "pfm pfm", "sky", "--dirs", "16", "--exact", NULL},
        {"horizon K=16", "pfm pfm", "horizon", "--dirs", "16", NULL},
        {"horizon K=16 exact", "pfm pfm", "horizon", "--dirs", "16", "--exact", NULL},
        {"shadow 315/10", "pfm pfm", "shadow", "--sun-azimuth", "315", "--sun-elevation", "10", NULL},
        {"shadow 315/10 exact", "pfm pfm", "shadow", "--sun-azimuth", "315", "--sun-elevation", "10", "--exact"},
        /* the GeoTIFF writer's tiles over the threads, and the reader (DEFLATE, predictor 3) */
        {"horizon K=16 -> tif", "pfm tif", "horizon", "--dirs", "16", NULL},
        {"shadow exact tif->", "tif pfm", "shadow", "--sun-azimuth", "315", "--sun-elevation", "10", "--exact"},
        /* the ASC reader (decimals) and writer (rows formatted over the threads) */
        {"shadow exact asc->", "asc pfm", "shadow", "--sun-azimuth", "315", "--sun-elevation", "10", "--exact"},
        {"shadow -> asc", "pfm asc", "shadow", "--sun-azimuth", "315", "--sun-elevation", "10", NULL},
    };
    char *cli = getenv("HFVIS_CLI") ? getenv("HFVIS_CLI") : (char *)"build/hfvis";
    const char *tmp = getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp";
    const int n = getenv("HFVIS_BENCH_THREADS_N") ? atoi(getenv("HFVIS_BENCH_THREADS_N")) : quick ? 512 : 2048;
    const int reps = getenv("HFVIS_BENCH_THREADS_RUNS") ? atoi(getenv("HFVIS_BENCH_THREADS_RUNS")) : 1;
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    char dir[512], in[600], tif[600], asc[600], out[2][600], threads[2][16], *argv[24];
    float *z = NULL;
    int r, t, k, rep;
    if (n < 16 || n > 16384 || reps < 1) {
        printf("\n== threads: HFVIS_BENCH_THREADS_N must be 16..16384 and _RUNS >= 1\n");
        return;
    }
    snprintf(threads[0], sizeof threads[0], "1");
    snprintf(threads[1], sizeof threads[1], "%ld", cores >= 2 && cores <= 256 ? cores : 2L);
    snprintf(dir, sizeof dir, "%s/hfvis_bench_threads.XXXXXX", tmp);
    if (!mkdtemp(dir)) { printf("threads: cannot create a folder in %s\n", tmp); return; }
    snprintf(in, sizeof in, "%s/fbm.pfm", dir);
    printf("\n== threads: `hfvis CMD --threads 1` vs `--threads %s` on a %d x %d fBm (%s; %ld online "
           "cores; min of %d run%s; wall and CPU seconds, peak MiB)\n", threads[1], n, n, cli, cores, reps,
           reps == 1 ? "" : "s");
    snprintf(tif, sizeof tif, "%s/fbm.tif", dir);
    snprintf(asc, sizeof asc, "%s/fbm.asc", dir);
    if (threads_field(in, tif, asc, n, &z) != 0) { printf("threads: cannot write the field in %s\n", dir); rmdir(dir); return; }
    printf("  %-20s | %8s %8s %7s | %8s %8s %7s | %8s  %s\n", "run", "1: wall", "CPU", "MiB", "T: wall", "CPU",
           "MiB", "speed-up", "bytes equal");
    for (r = 0; r < (int)(sizeof runs / sizeof runs[0]); r++) {
        double wall[2] = {1e300, 1e300}, cpu[2] = {1e300, 1e300};
        long peak[2] = {0, 0};
        int failed = 0;
        for (t = 0; t < 2; t++) {
            snprintf(out[t], sizeof out[t], "%s/out%d.%s", dir, t, runs[r][1] + 4);
            for (rep = 0; rep < reps; rep++) {
                double w = 0.0, c = 0.0;
                long m = 0;
                int a = 0;
                argv[a++] = cli;
                argv[a++] = runs[r][2];
                argv[a++] = runs[r][1][0] == 't' ? tif : runs[r][1][0] == 'a' ? asc : in;
                for (k = 3; k < 9 && runs[r][k]; k++) argv[a++] = runs[r][k];
                argv[a++] = (char *)"--threads", argv[a++] = threads[t];
                argv[a++] = (char *)"--max-memory", argv[a++] = (char *)"0";
                argv[a++] = (char *)"--quiet", argv[a++] = (char *)"-o", argv[a++] = out[t];
                argv[a] = NULL;
                if (bench_spawn(argv, &w, &m, &c) != 0) failed = 1;
                if (w < wall[t]) wall[t] = w;
                if (c < cpu[t]) cpu[t] = c;
                if (m > peak[t]) peak[t] = m;
            }
        }
        printf("  %-20s | %8.2f %8.2f %7.0f | %8.2f %8.2f %7.0f | %7.2fx  %s\n", runs[r][0], wall[0], cpu[0],
               peak[0] / 1024.0, wall[1], cpu[1], peak[1] / 1024.0, wall[0] / wall[1],
               failed ? "FAILED" : bench_same_file(out[0], out[1]) ? "yes" : "NO");
        remove(out[0]), remove(out[1]);
    }
    remove(in);
    remove(tif);
    remove(asc);
    rmdir(dir);
    threads_normals(z, n);
    threads_exact_grid(z, n);
    free(z);
}
