/* bench_tiles.c - rasters larger than memory through the hfvis tool (docs/tiles.md): an N x N
 * fBm field at 1 m cells written as .flt, `hfvis skyview --max-distance 1000` over it whole and
 * as 16 windows (4 x 4, halo hfvis_tile_halo: 1005 cells) joined by `hfvis mosaic`, each a child process: wall
 * time and peak memory (ru_maxrss from wait4) of each, and whether the mosaic equals the whole
 * run bit for bit; then the peak memory per grid cell of each tiled command, whole, on a
 * 1024 x 1024 field (the README's figures). N = 8192 (quick: 1024, R = 100 m). The tool is
 * $HFVIS_CLI (make bench sets it), else build/hfvis; files go to $TMPDIR (else /tmp). */
#define _DEFAULT_SOURCE /* wait4 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>
#include "bench.h"

#define TILES_SIDE 4 /* 4 x 4 = 16 windows */

/* Run argv (NULL-terminated) with stdout and stderr to /dev/null; its exit status, seconds and
 * peak resident memory in KiB (Linux: ru_maxrss is in KiB), and, when cpu is not NULL, its CPU
 * seconds (user + system, all threads). Shared with bench_threads.c (bench.h). */
int bench_spawn(char *const argv[], double *seconds, long *maxrss_kib, double *cpu)
{
    struct rusage ru;
    int status = 0;
    double t0;
    pid_t pid;
    fflush(stdout); /* the child must not flush a copy of our buffer */
    t0 = bench_now();
    pid = fork();
    if (pid < 0) return -1;
    if (pid == 0) {
        if (!freopen("/dev/null", "w", stdout) || !freopen("/dev/null", "w", stderr)) _exit(126);
        execv(argv[0], argv);
        _exit(127);
    }
    memset(&ru, 0, sizeof ru);
    while (wait4(pid, &status, 0, &ru) < 0)
        if (errno != EINTR) return -1;
    *seconds = bench_now() - t0;
    *maxrss_kib = ru.ru_maxrss;
    if (cpu)
        *cpu = (double)ru.ru_utime.tv_sec + (double)ru.ru_utime.tv_usec * 1e-6 + (double)ru.ru_stime.tv_sec +
               (double)ru.ru_stime.tv_usec * 1e-6;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* Whether two files hold the same bytes (bench.h). */
int bench_same_file(const char *a, const char *b)
{
    FILE *fa = fopen(a, "rb"), *fb = fopen(b, "rb");
    int same = fa && fb, ca, cb;
    while (same) {
        ca = getc(fa), cb = getc(fb);
        if (ca != cb) same = 0;
        if (ca == EOF) break;
    }
    if (fa) fclose(fa);
    if (fb) fclose(fb);
    return same;
}

/* An N x N fBm (1 m cells, 0..~600 m relief) as dir/name.flt + .hdr; 0 on success. */
static int tiles_field(const char *dir, const char *name, int n)
{
    hfvis_field f;
    char path[1024];
    float *z = (float *)malloc((size_t)n * 1024u * sizeof(float));
    FILE *out;
    int y0, ok = z != NULL;
    memset(&f, 0, sizeof f);
    f.kind = HFVIS_FIELD_FBM;
    f.amplitude = 300.0;
    f.wavelength = 2048.0;
    f.seed = 18;
    snprintf(path, sizeof path, "%s/%s.flt", dir, name);
    out = fopen(path, "wb");
    ok = ok && out;
    for (y0 = 0; ok && y0 < n; y0 += 1024) { /* 1024 rows at a time */
        int rows = n - y0 < 1024 ? n - y0 : 1024, y;
        for (y = 0; ok && y < rows; y++) { /* the field at rows y0.. (generate takes no origin) */
            int x;
            for (x = 0; x < n; x++) z[(size_t)y * (size_t)n + (size_t)x] = (float)hfvis_field_height(&f, x, y0 + y);
        }
        ok = fwrite(z, sizeof(float), (size_t)rows * (size_t)n, out) == (size_t)rows * (size_t)n;
    }
    if (out && fclose(out) != 0) ok = 0;
    free(z);
    snprintf(path, sizeof path, "%s/%s.hdr", dir, name);
    out = ok ? fopen(path, "w") : NULL;
    if (!out) return -1;
    fprintf(out, "ncols %d\nnrows %d\nxllcorner 400000\nyllcorner 5000000\ncellsize 1\nbyteorder LSBFIRST\n", n, n);
    return fclose(out) == 0 ? 0 : -1;
}

void bench_tiles(int quick)
{
    const char *cli_env = getenv("HFVIS_CLI") ? getenv("HFVIS_CLI") : "build/hfvis";
    const char *tmp = getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp";
    const int n = quick ? 1024 : 8192, side = n / TILES_SIDE;
    char R[16], cli[512], cmd[32];
    static const char *const cmds[] = { "skyview", "sky", "shadow", "horizon", "light", "visibility",
                                        "hillshade", "openness" };
    char dir[512], in[600], whole[600], out[1300], mosaic[600], win[64], env[600];
    char *argv[40], *pieces[TILES_SIDE * TILES_SIDE + 8];
    char names[TILES_SIDE * TILES_SIDE][600];
    double t, tiles_t = 0.0, tmax = 0.0;
    long rss, rss_max = 0, rss_whole = 0;
    int i, rc, c;
    snprintf(R, sizeof R, "%s", quick ? "100" : "1000");
    snprintf(cli, sizeof cli, "%s", cli_env);
    snprintf(dir, sizeof dir, "%s/hfvis_bench_tiles.XXXXXX", tmp);
    if (!mkdtemp(dir)) { printf("tiles: cannot create a folder in %s\n", tmp); return; }
    printf("\n== tiles: %d x %d fBm at 1 m, skyview K = 16, R = %s m (halo %d cells), whole vs 16 "
           "windows + mosaic (%s)\n", n, n, R, hfvis_tile_halo(atof(R), 1.0, HFVIS_RAYS_LATTICE), cli);
    if (tiles_field(dir, "dem", n) != 0) { printf("tiles: cannot write the field in %s\n", dir); return; }
    snprintf(in, sizeof in, "%s/dem.flt", dir);
    snprintf(whole, sizeof whole, "%s/whole.tif", dir);
    argv[0] = cli, argv[1] = (char *)"skyview", argv[2] = in, argv[3] = (char *)"--max-distance";
    argv[4] = R, argv[5] = (char *)"--quiet", argv[6] = (char *)"--max-memory", argv[7] = (char *)"0";
    argv[8] = (char *)"-o", argv[9] = whole, argv[10] = NULL;
    rc = bench_spawn(argv, &t, &rss_whole, NULL);
    printf("  whole      %8.1f s  peak %8.1f MiB  (%.1f bytes/cell)%s\n", t, rss_whole / 1024.0,
           rss_whole * 1024.0 / ((double)n * n), rc ? "  FAILED" : "");
    for (i = 0; i < TILES_SIDE * TILES_SIDE; i++) {
        snprintf(win, sizeof win, "%d,%d,%d,%d", (i % TILES_SIDE) * side, (i / TILES_SIDE) * side, side, side);
        snprintf(names[i], sizeof names[i], "%s/piece%02d.tif", dir, i);
        argv[9] = names[i], argv[10] = (char *)"--window", argv[11] = win, argv[12] = NULL;
        rc = bench_spawn(argv, &t, &rss, NULL);
        tiles_t += t;
        if (t > tmax) tmax = t;
        if (rss > rss_max) rss_max = rss;
        if (rc) printf("  window %s FAILED (exit %d)\n", win, rc);
        pieces[3 + i] = names[i];
    }
    printf("  16 windows %8.1f s  peak %8.1f MiB per window (largest; %.1f bytes per grid cell of "
           "%d^2), slowest %.1f s\n", tiles_t, rss_max / 1024.0,
           rss_max * 1024.0 / ((double)(side + 2 * (atoi(R) + 1)) * (side + 2 * (atoi(R) + 1))),
           side + 2 * (atoi(R) + 1), tmax);
    snprintf(mosaic, sizeof mosaic, "%s/mosaic.tif", dir);
    pieces[0] = cli, pieces[1] = (char *)"mosaic", pieces[2] = (char *)"--quiet";
    pieces[3 + 16] = (char *)"-o", pieces[3 + 17] = mosaic, pieces[3 + 18] = NULL;
    rc = bench_spawn(pieces, &t, &rss, NULL);
    printf("  mosaic     %8.1f s  peak %8.1f MiB%s\n", t, rss / 1024.0, rc ? "  FAILED" : "");
    printf("  mosaic = whole run bit for bit: %s\n", bench_same_file(whole, mosaic) ? "yes" :
           "NO (expected until the library honours max_distance, origin, extent and receivers)");
    for (i = 0; i < 16; i++) {
        remove(names[i]);
        snprintf(out, sizeof out, "%.1200s.tile", names[i]);
        remove(out);
    }
    remove(whole), remove(mosaic), remove(in);
    snprintf(out, sizeof out, "%s/dem.hdr", dir);
    remove(out);

    /* peak memory per cell of each command, whole, on 1024 x 1024 (--dirs 16) */
    {
        FILE *e;
        printf("  peak memory per cell, whole runs on 1024 x 1024, K = 16 (visibility 4) (ru_maxrss / cells):\n");
        if (tiles_field(dir, "small", 1024) != 0) return;
        snprintf(in, sizeof in, "%s/small.flt", dir);
        snprintf(out, sizeof out, "%s/out.tif", dir);
        snprintf(env, sizeof env, "%s/env.pfm", dir);
        e = fopen(env, "wb");
        if (e) { /* a 16 x 8 grey sky, radiance 1 */
            float one[16 * 8];
            for (i = 0; i < 16 * 8; i++) one[i] = 1.0f;
            fprintf(e, "Pf\n16 8\n-1.0\n");
            fwrite(one, sizeof one, 1, e);
            fclose(e);
        }
        for (c = 0; c < (int)(sizeof cmds / sizeof cmds[0]); c++) {
            int k = 0;
            snprintf(cmd, sizeof cmd, "%s", cmds[c]);
            argv[k++] = cli, argv[k++] = cmd, argv[k++] = in;
            argv[k++] = (char *)"--quiet", argv[k++] = (char *)"-o", argv[k++] = out;
            if (!strcmp(cmds[c], "shadow") || !strcmp(cmds[c], "hillshade"))
                argv[k++] = (char *)"--sun-azimuth", argv[k++] = (char *)"200", argv[k++] = (char *)"--sun-elevation", argv[k++] = (char *)"20";
            if (!strcmp(cmds[c], "light")) argv[k++] = (char *)"--env", argv[k++] = env;
            if (!strcmp(cmds[c], "openness")) argv[k++] = (char *)"--radius", argv[k++] = (char *)"16";
            if (!strcmp(cmds[c], "visibility")) argv[k++] = (char *)"--dirs", argv[k++] = (char *)"4";
            argv[k] = NULL;
            rc = bench_spawn(argv, &t, &rss, NULL);
            printf("    %-10s %6.1f bytes/cell  (%.1f MiB, %.1f s)%s\n", cmds[c], rss * 1024.0 / (1024.0 * 1024.0),
                   rss / 1024.0, t, rc ? "  FAILED" : "");
        }
        remove(out), remove(in), remove(env);
        snprintf(out, sizeof out, "%s/small.hdr", dir);
        remove(out);
    }
    rmdir(dir);
}
