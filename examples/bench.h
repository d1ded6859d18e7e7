/* bench.h - the benchmark sections of `make bench` that live in examples/bench_*.c, one file per
 * library module; examples/bench.c's main calls each (quick = the short `bench quick` run). */
#ifndef HFVIS_BENCH_H
#define HFVIS_BENCH_H
void bench_mesh(int quick);
void bench_raster(int quick);
void bench_vox(int quick);
void bench_iv(int quick);
void bench_bvh(int quick);
void bench_gi2(int quick);
void bench_cons(int quick);
void bench_ssao(int quick);
void bench_ssaob(int quick);
void bench_volgi(int quick);
void bench_vf(int quick);
void bench_lk(int quick);
#endif
