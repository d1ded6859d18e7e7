/* bench_ssaob.c - P4 far-field AO: time per pixel at 1280(+256)x720(+144) (quick: 320(+64)x
 * 180(+36)) and error against the ray-traced reference beside the mipmap baseline's error. The
 * scene is the analytic perspective pit + step family of ssao.c (a rasterized scene is in the
 * example); the reference runs on a 1/4-size crop budget of rays to stay bounded. */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "bench.h"
#include "hfvis.h"

static void bench_ssaob_size(int W, int H, int rays)
{
    int gx = W / 10, gy = H / 10, W0 = W + 2 * gx, H0 = H + 2 * gy;
    hfvis_camera cam;
    hfvis_ssao_scene sc;
    float *d = (float *)malloc(sizeof(float) * (size_t)W0 * H0), *n = (float *)malloc(12 * (size_t)W0 * H0);
    float *a = (float *)malloc(sizeof(float) * (size_t)W * H), *m = (float *)malloc(sizeof(float) * (size_t)W * H);
    float *r = (float *)malloc(sizeof(float) * (size_t)W * H);
    hfvis_ffao_options o = hfvis_ffao_options_default();
    hfvis_ssao_rt_options ro = hfvis_ssao_rt_options_default();
    hfvis_ssao_error_stats ef, em;
    double t0, tf, tm, ts;
    int K;
    if (!d || !n || !a || !m || !r) { printf("out of memory\n"); goto done; }
    hfvis_camera_perspective(&cam, W0, H0, gx, gy, 1.0);
    memset(&sc, 0, sizeof sc);
    sc.kind = HFVIS_SSAO_SCENE_PIT;
    sc.base_depth = 10.0;
    sc.radius = 3.0;
    hfvis_ssao_scene_render(&cam, &sc, d, n);
    o.falloff.kind = HFVIS_FALLOFF_INV_QUADRATIC;
    o.falloff.param = 1.0;
    ro.falloff = o.falloff;
    ro.rays = rays;
    t0 = bench_now();
    hfvis_ssao_raytrace(&cam, d, n, &ro, r, W);
    printf("  %dx%d (+%d,+%d): ray-traced reference %d rays: %.1f ms\n", W, H, 2 * gx, 2 * gy, rays,
           1e3 * (bench_now() - t0));
    for (K = 8; K <= 16; K += 8) {
        o.directions = K;
        o.sparse = 0;
        t0 = bench_now();
        hfvis_ffao(&cam, d, n, &o, a, W);
        tf = bench_now() - t0;
        o.mip_directions = 16;
        t0 = bench_now();
        hfvis_ssao_mipmap(&cam, d, n, &o, m, W);
        tm = bench_now() - t0;
        hfvis_ssao_error(a, W, r, W, W, H, 0.05, 0, &ef, NULL, 0);
        hfvis_ssao_error(m, W, r, W, W, H, 0.05, 0, &em, NULL, 0);
        printf("    FFAO %2dx2: %8.1f ns/px  e_A %.3f %%  e_<5%% %.1f %% | mipmap K=16: %8.1f ns/px  e_A %.3f %%  e_<5%% %.1f %%  (error ratio %.1fx)\n",
               K, 1e9 * tf / ((double)W * H), 100 * ef.mean, 100 * ef.within, 1e9 * tm / ((double)W * H),
               100 * em.mean, 100 * em.within, ef.mean > 0 ? em.mean / ef.mean : 0.0);
    }
    o.directions = 18;
    o.sparse = 1;
    o.blur = 1;
    t0 = bench_now();
    hfvis_ffao(&cam, d, n, &o, a, W);
    ts = bench_now() - t0;
    hfvis_ssao_error(a, W, r, W, W, H, 0.05, 0, &ef, NULL, 0);
    printf("    FFAO 18x2 sparse 3x3 + blur: %8.1f ns/px  e_A %.3f %%\n", 1e9 * ts / ((double)W * H), 100 * ef.mean);
done:
    free(d); free(n); free(a); free(m); free(r);
}

void bench_ssaob(int quick)
{
    printf("P4 far-field AO (inverse-quadratic falloff r = 1, perspective pit scene):\n");
    if (quick) bench_ssaob_size(320, 180, 32);
    else bench_ssaob_size(1280, 720, 16);
}
