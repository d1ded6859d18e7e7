/* bench.h - the benchmark sections of `make bench` that live in examples/bench_*.c, one file per
 * library module; examples/bench/bench.c's main calls each (quick = the short `bench quick` run). */
#ifndef HFVIS_BENCH_H
#define HFVIS_BENCH_H

#include <stddef.h>
#include <stdlib.h>
#include <time.h>

#include "hfvis.h"

/* Seconds on the monotonic clock (the including file defines _POSIX_C_SOURCE first). */
static inline double bench_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

/* Seconds of this process's CPU time: for single-threaded sections on a shared machine, where
 * the wall clock also counts the time other jobs hold the core. */
static inline double bench_cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

/* qsort's comparison of doubles, ascending (percentiles of errors). */
static inline int bench_cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* An allocator (hfvis_allocator with user = a bench_tracker) that records the peak number of
 * bytes live (the library's scratch memory), and the bytes and blocks it allocated in all. */
typedef struct bench_tracker { size_t live, peak, total, count; } bench_tracker;
typedef struct bench_block { size_t size; double align; } bench_block;
static inline void *bench_track_alloc(void *user, size_t size)
{
    bench_tracker *t = (bench_tracker *)user;
    bench_block *b = (bench_block *)malloc(sizeof(bench_block) + size);
    if (!b) return NULL;
    b->size = size;
    t->live += size;
    t->total += size;
    t->count++;
    if (t->live > t->peak) t->peak = t->live;
    return b + 1;
}
static inline void bench_track_free(void *user, void *p)
{
    bench_tracker *t = (bench_tracker *)user;
    bench_block *b;
    if (!p) return;
    b = (bench_block *)p - 1;
    t->live -= b->size;
    free(b);
}
/* An allocator (user = a bench_arena) that hands out pieces of one block the caller keeps
 * across calls and never frees them: what an engine does to call the library every frame
 * without allocating. Reset used to 0 before each call. */
typedef struct bench_arena { unsigned char *base; size_t cap, used; } bench_arena;
static inline void *bench_arena_alloc(void *user, size_t size)
{
    bench_arena *a = (bench_arena *)user;
    size_t at = (a->used + 63u) & ~(size_t)63u;
    if (at > a->cap || size > a->cap - at) return NULL;
    a->used = at + size;
    return a->base + at;
}
static inline void bench_arena_free(void *user, void *p)
{
    (void)user;
    (void)p;
}
void bench_mesh(int quick);
void bench_raster(int quick);
void bench_vox(int quick);
void bench_iv(int quick);
void bench_bvh(int quick);
void bench_gi2(int quick);
void bench_cons(int quick);
void bench_ssao(int quick);
void bench_ssaob(int quick);
/* bench_ssao.c: the knot-on-ground scene (100k triangles) rendered into W0 x H0 linear depth, the
 * camera with guard band (gx, gy); 0 on failure. */
int bench_ssao_scene(int W0, int H0, int gx, int gy, float *depth, hfvis_camera *cam);
void bench_volgi(int quick);
void bench_vf(int quick);
void bench_lk(int quick);
void bench_lk_obj(int quick); /* bench_lkobj.c: the meshes of HFVIS_BENCH_MESHES */
void bench_dirs(int quick);
void bench_exact(int quick);
void bench_tiles(int quick);
/* bench_tiles.c: a child process's exit status, wall and CPU seconds and peak memory; whether
 * two files are equal byte for byte (used by the sections that run the hfvis tool) */
int bench_spawn(char *const argv[], double *seconds, long *maxrss_kib, double *cpu);
int bench_same_file(const char *a, const char *b);
void bench_threads(int quick); /* bench_threads.c: the tool's --threads 1 against 2 ($HFVIS_CLI) */
void bench_solar(int quick); /* bench_solar.c: the DEMs of $HFVIS_BENCH_DEMS (else an fBm) */ /* bench_tiles.c: the hfvis tool whole vs tiled ($HFVIS_CLI) */
void bench_radius(int quick);
void bench_solar_sites(int quick); /* bench_solar_sites.c: the per-cell sun on the Colorado tile */
float *bench_solar_standin(void); /* bench_solar.c: the 512^2 fBm standing in for the DEMs */
#endif
