/* bench_ssaob.c - P4 far-field AO: time per pixel at 1280(+256)x720(+144) (quick: 320(+64)x
 * 180(+36)), and error against the screen-space ray-traced reference beside the mipmap baseline's
 * error at the same sample count ([P4] §8-10), on the knot-on-ground scene of the
 * LSAO bench (100k triangles, rasterized). The reference is noisy: it is run twice with
 * independent seeds, e_A is taken against their mean, and the RMS error is corrected for the
 * reference's own variance (E[(m - r1)^2] - E[(r1 - r2)^2]/2 is unbiased for E[(m - truth)^2]). */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "bench.h"

/* The scene and its reference, at one size. */
typedef struct ffb_scene {
    int W, H, W0, H0;
    hfvis_camera cam;
    float *depth, *r1, *r2, *rm, *a;
} ffb_scene;

static void ffb_free(ffb_scene *s)
{
    free(s->depth); free(s->r1); free(s->r2); free(s->rm); free(s->a);
    memset(s, 0, sizeof *s);
}

static int ffb_init(ffb_scene *s, int W, int H)
{
    int gx = W / 10, gy = H / 10;
    size_t n = (size_t)W * (size_t)H;
    memset(s, 0, sizeof *s);
    s->W = W; s->H = H; s->W0 = W + 2 * gx; s->H0 = H + 2 * gy;
    s->depth = (float *)malloc(sizeof(float) * (size_t)s->W0 * (size_t)s->H0);
    s->r1 = (float *)malloc(sizeof(float) * n);
    s->r2 = (float *)malloc(sizeof(float) * n);
    s->rm = (float *)malloc(sizeof(float) * n);
    s->a = (float *)malloc(sizeof(float) * n);
    if (!s->depth || !s->r1 || !s->r2 || !s->rm || !s->a ||
        !bench_ssao_scene(s->W0, s->H0, gx, gy, s->depth, &s->cam)) {
        ffb_free(s);
        return 0;
    }
    return 1;
}

/* e_A and e_<5% against the mean reference, noise-corrected RMS against the two runs. */
static void ffb_error(const ffb_scene *s, const float *m, double *ea, double *within, double *rms)
{
    hfvis_ssao_error_stats st;
    double e1 = 0.0, e12 = 0.0;
    size_t i, n = (size_t)s->W * (size_t)s->H;
    hfvis_ssao_error(m, s->W, s->rm, s->W, s->W, s->H, 0.05, 0, &st, NULL, 0);
    for (i = 0; i < n; i++) {
        double d1 = (double)m[i] - (double)s->r1[i], d12 = (double)s->r1[i] - (double)s->r2[i];
        e1 += d1 * d1;
        e12 += d12 * d12;
    }
    e1 = e1 / (double)n - 0.5 * e12 / (double)n;
    *ea = st.mean;
    *within = st.within;
    *rms = e1 > 0.0 ? sqrt(e1) : 0.0;
}

void bench_ssaob(int quick)
{
    static const struct { hfvis_falloff_kind kind; double param; const char *name; } fall[2] = {
        {HFVIS_FALLOFF_INV_QUADRATIC, 1.0, "inverse quadratic r = 1"},
        {HFVIS_FALLOFF_EXPONENTIAL, 1.0, "exponential, scale 1"}};
    int Wt = quick ? 320 : 1280, Ht = quick ? 180 : 720, We = quick ? 120 : 240, He = quick ? 68 : 135;
    int rays = quick ? 64 : 512, f, K;
    ffb_scene s;
    printf("P4 far-field AO, knot on a ground slab (the LSAO scene), 10 %% guard band per side\n");
    /* time per pixel at the paper's size */
    if (!ffb_init(&s, Wt, Ht)) { printf("  scene setup failed\n"); return; }
    printf("  time at %dx%d (+%d,+%d), inverse quadratic r = 1, normals from depth:\n", Wt, Ht,
           s.W0 - Wt, s.H0 - Ht);
    for (K = 8; K <= 18; K += K == 8 ? 8 : 2) {
        hfvis_ffao_options o = hfvis_ffao_options_default();
        double t0, t;
        o.falloff.kind = HFVIS_FALLOFF_INV_QUADRATIC;
        o.falloff.param = 1.0;
        o.directions = K;
        o.sparse = o.blur = K == 18;
        t0 = bench_now();
        if (hfvis_ffao(&s.cam, s.depth, NULL, &o, s.a, Wt) != HFVIS_OK) printf("  FFAO failed\n");
        t = bench_now() - t0;
        printf("    FFAO %2dx2%-20s %9.1f ns/px  %8.1f ms\n", K, K == 18 ? " sparse 3x3 + blur" : "",
               1e9 * t / ((double)Wt * Ht), 1e3 * t);
        if (K == 16) {
            o.sparse = o.blur = 0;
            t0 = bench_now();
            if (hfvis_ssao_mipmap(&s.cam, s.depth, NULL, &o, s.a, Wt) != HFVIS_OK) printf("  mipmap failed\n");
            t = bench_now() - t0;
            printf("    mipmap K=16%-19s %9.1f ns/px  %8.1f ms\n", "", 1e9 * t / ((double)Wt * Ht), 1e3 * t);
        }
    }
    ffb_free(&s);
    /* accuracy against the reference, smaller so that the reference can have many rays */
    if (!ffb_init(&s, We, He)) { printf("  scene setup failed\n"); return; }
    for (f = 0; f < 2; f++) {
        hfvis_ssao_rt_options ro = hfvis_ssao_rt_options_default();
        hfvis_ffao_options o = hfvis_ffao_options_default();
        double ea, wi, rms, noise = 0.0, mean = 0.0, t0;
        size_t i, n = (size_t)We * (size_t)He;
        ro.falloff.kind = fall[f].kind;
        ro.falloff.param = fall[f].param;
        ro.rays = rays;
        t0 = bench_now();
        ro.seed = 1;
        hfvis_ssao_reference(&s.cam, s.depth, NULL, &ro, s.r1, We);
        ro.seed = 2;
        hfvis_ssao_reference(&s.cam, s.depth, NULL, &ro, s.r2, We);
        for (i = 0; i < n; i++) {
            double d = (double)s.r1[i] - (double)s.r2[i];
            s.rm[i] = 0.5f * (s.r1[i] + s.r2[i]);
            noise += d * d;
            mean += (double)s.rm[i];
        }
        printf("  error at %dx%d (+%d,+%d), %s: reference 2 x %d rays (%.1f s), mean AO %.3f, "
               "reference noise (RMS of the mean) %.4f\n", We, He, s.W0 - We, s.H0 - He, fall[f].name, rays,
               bench_now() - t0, mean / (double)n, sqrt(noise / (double)n) / 2.0);
        o.falloff = ro.falloff;
        for (K = 8; K <= 16; K += 8) {
            double fea, fwi, frms;
            o.directions = K;
            o.mip_directions = 16;
            hfvis_ffao(&s.cam, s.depth, NULL, &o, s.a, We);
            ffb_error(&s, s.a, &fea, &fwi, &frms);
            hfvis_ssao_mipmap(&s.cam, s.depth, NULL, &o, s.a, We);
            ffb_error(&s, s.a, &ea, &wi, &rms);
            printf("    FFAO %2dx2: e_A %.2f %%  e_<5%% %5.1f %%  RMS %.2f %% | mipmap K=16: e_A %.2f %%  "
                   "e_<5%% %5.1f %%  RMS %.2f %% | mipmap/FFAO RMS %.1fx\n", K, 100 * fea, 100 * fwi, 100 * frms,
                   100 * ea, 100 * wi, 100 * rms, frms > 0.0 ? rms / frms : 0.0);
        }
    }
    ffb_free(&s);
}
