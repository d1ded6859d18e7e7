/* bench_mesh.c - mesh generators and the OBJ codec on the 100k-triangle torus knot;
 * the codec's own number parsing/formatting beside the C library's strtof / snprintf("%.9g"). */
#define _POSIX_C_SOURCE 199309L
#include "bench.h"
#include "hfvis.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double bench_mesh_knot(int reps, hfvis_mesh *keep)
{
    const double c[3] = {0.0, 0.0, 0.0};
    double t0 = bench_now();
    int r;
    for (r = 0; r < reps; r++) {
        hfvis_mesh m;
        if (hfvis_mesh_torus_knot(NULL, c, 1.0, 2, 3, 2500, 20, &m) != HFVIS_OK) exit(1);
        if (r == reps - 1) *keep = m;
        else hfvis_mesh_free(NULL, &m);
    }
    return (bench_now() - t0) / reps;
}

static double bench_mesh_encode(const hfvis_mesh *m, int reps, unsigned char **buf, size_t *n)
{
    size_t need = hfvis_obj_encode_size(m);
    double t0;
    int r;
    *buf = (unsigned char *)malloc(need);
    t0 = bench_now();
    for (r = 0; r < reps; r++)
        if (hfvis_obj_encode(m, *buf, need, n) != HFVIS_OK) exit(1);
    return (bench_now() - t0) / reps;
}

static double bench_mesh_decode(const unsigned char *buf, size_t n, int reps)
{
    double t0 = bench_now();
    int r;
    for (r = 0; r < reps; r++) {
        hfvis_mesh m;
        if (hfvis_obj_decode(buf, n, NULL, &m) != HFVIS_OK) exit(1);
        hfvis_mesh_free(NULL, &m);
    }
    return (bench_now() - t0) / reps;
}

/* Baseline: the same text's v lines through strtof and f lines through strtol (what a
 * strtod-based loader costs; locale-dependent, no validation of the rest). */
static double bench_mesh_decode_libc(const unsigned char *buf, size_t n, int reps, double *sink)
{
    char *text = (char *)malloc(n + 1);
    double t0, acc = 0.0;
    int r;
    memcpy(text, buf, n);
    text[n] = '\0';
    t0 = bench_now();
    for (r = 0; r < reps; r++) {
        char *p = text;
        while (*p) {
            char *e = strchr(p, '\n');
            if (p[0] == 'v') {
                char *q = p + 1;
                acc += (double)strtof(q, &q);
                acc += (double)strtof(q, &q);
                acc += (double)strtof(q, &q);
            } else if (p[0] == 'f') {
                char *q = p + 1;
                acc += (double)strtol(q, &q, 10);
                acc += (double)strtol(q, &q, 10);
                acc += (double)strtol(q, &q, 10);
            }
            p = e ? e + 1 : p + strlen(p);
        }
    }
    *sink += acc;
    free(text);
    return (bench_now() - t0) / reps;
}

static double bench_mesh_printf(const hfvis_mesh *m, int reps)
{
    char line[128];
    double t0 = bench_now();
    size_t i, total = 0;
    int r;
    for (r = 0; r < reps; r++) {
        for (i = 0; i < m->vertex_count; i++)
            total += (size_t)snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", (double)m->xyz[3 * i],
                                      (double)m->xyz[3 * i + 1], (double)m->xyz[3 * i + 2]);
        for (i = 0; i < m->triangle_count; i++)
            total += (size_t)snprintf(line, sizeof line, "f %u %u %u\n", m->indices[3 * i] + 1u,
                                      m->indices[3 * i + 1] + 1u, m->indices[3 * i + 2] + 1u);
    }
    if (total == 0) exit(1);
    return (bench_now() - t0) / reps;
}

void bench_mesh(int quick)
{
    int reps = quick ? 1 : 5;
    hfvis_mesh m;
    unsigned char *buf = NULL;
    size_t n = 0;
    double tg, te, td, tdl, tp, sink = 0.0, T;
    tg = bench_mesh_knot(reps, &m);
    T = (double)m.triangle_count;
    te = bench_mesh_encode(&m, reps, &buf, &n);
    tp = bench_mesh_printf(&m, reps);
    td = bench_mesh_decode(buf, n, reps);
    tdl = bench_mesh_decode_libc(buf, n, reps, &sink);
    printf("mesh: torus knot 2500x20 (%zu triangles, OBJ %.2f MB)\n", m.triangle_count, (double)n / 1e6);
    printf("  %-34s %10.1f ns/triangle %8.2f ms\n", "generate hfvis_mesh_torus_knot", 1e9 * tg / T, 1e3 * tg);
    printf("  %-34s %10.1f ns/triangle %8.2f ms  %6.1f MB/s\n", "hfvis_obj_encode (shortest)", 1e9 * te / T,
           1e3 * te, (double)n / te / 1e6);
    printf("  %-34s %10.1f ns/triangle %8.2f ms  ratio %.2f\n", "baseline snprintf %.9g", 1e9 * tp / T,
           1e3 * tp, te / tp);
    printf("  %-34s %10.1f ns/triangle %8.2f ms  %6.1f MB/s\n", "hfvis_obj_decode (2 passes)", 1e9 * td / T,
           1e3 * td, (double)n / td / 1e6);
    printf("  %-34s %10.1f ns/triangle %8.2f ms  ratio %.2f%s\n", "baseline strtof/strtol scan", 1e9 * tdl / T,
           1e3 * tdl, td / tdl, sink == 0.5 ? " " : "");
    free(buf);
    hfvis_mesh_free(NULL, &m);
}
