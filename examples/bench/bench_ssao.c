/* bench_ssao.c - P3 line-sweep AO against HBAO on a rendered scene (a torus knot on a ground
 * slab, the rasterizer of voxel.c) at 800x600, 1280x720 and 1920x1080 with P3's "20 % guard
 * band" (10 % per side: 1280(+256) x 720(+144)), K = 8 and 16, falloff radii from a few pixels to
 * the whole screen. HBAO runs at matching quality: the same box directions and integer steps
 * as LSAO (every texel of the direction's pattern up to the falloff's support, the brute force
 * LSAO's hull replaces, [P3] Fig. 7; its screen-radius cap lifted to the buffer diagonal), so the two differ only by the gather and the hull's
 * degenerate cases (mean |d| printed). Its step count grows with the radius, as [P3] Table 1.
 * For large radii HBAO is timed on a band of rows through the image centre (its cost per pixel
 * there is printed; the band is where the knot is, so it is not cheaper than the average).
 * Times are process CPU time (single-threaded; the machine may be shared). */
#define _POSIX_C_SOURCE 199309L
#include "bench.h"
#include "hfvis.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Render the knot-on-ground scene into W0 x H0 linear depth; camera with guard (gx, gy). */
int bench_ssao_scene(int W0, int H0, int gx, int gy, float *depth, hfvis_camera *cam)
{
    hfvis_mesh knot, ground, m;
    hfvis_view view;
    hfvis_raster_outputs out;
    double c[3] = {0.0, 0.0, 0.95}, lo[3] = {-6.0, -6.0, -0.3}, hi[3] = {6.0, 6.0, 0.0};
    double eye[3] = {0.3, -5.0, 3.2}, tgt[3] = {0.0, 0.0, 0.4}, up[3] = {0.0, 0.0, 1.0};
    float *xyz;
    uint32_t *idx;
    size_t i;
    int ok = 1;
    /* the visible image spans 0.9 rad vertically; the guard band widens the buffer's field */
    double fov = 2.0 * atan(tan(0.45) * (double)H0 / (double)(H0 - 2 * gy));
    if (hfvis_mesh_torus_knot(NULL, c, 1.0, 2, 3, 2500, 20, &knot) != HFVIS_OK) return 0;
    if (hfvis_mesh_box(NULL, lo, hi, &ground) != HFVIS_OK) return 0;
    xyz = (float *)malloc(sizeof(float) * 3 * (knot.vertex_count + ground.vertex_count));
    idx = (uint32_t *)malloc(sizeof(uint32_t) * 3 * (knot.triangle_count + ground.triangle_count));
    if (!xyz || !idx) return 0;
    memcpy(xyz, knot.xyz, sizeof(float) * 3 * knot.vertex_count);
    memcpy(xyz + 3 * knot.vertex_count, ground.xyz, sizeof(float) * 3 * ground.vertex_count);
    memcpy(idx, knot.indices, sizeof(uint32_t) * 3 * knot.triangle_count);
    for (i = 0; i < 3 * ground.triangle_count; i++)
        idx[3 * knot.triangle_count + i] = ground.indices[i] + (uint32_t)knot.vertex_count;
    m.xyz = xyz;
    m.vertex_count = knot.vertex_count + ground.vertex_count;
    m.indices = idx;
    m.triangle_count = knot.triangle_count + ground.triangle_count;
    ok &= hfvis_view_perspective(&view, eye, tgt, up, fov, W0, H0, 0.05, 500.0) == HFVIS_OK;
    memset(&out, 0, sizeof out);
    out.linear_depth = depth;
    ok &= hfvis_rasterize(&m, &view, NULL, &out) == HFVIS_OK;
    ok &= hfvis_camera_from_view(cam, &view, gx, gy) == HFVIS_OK;
    free(xyz);
    free(idx);
    hfvis_mesh_free(NULL, &knot);
    hfvis_mesh_free(NULL, &ground);
    return ok;
}

/* LSAO over the whole image; returns seconds (best of reps). */
static double bench_ssao_lsao(const hfvis_camera *cam, const float *depth,
                              const hfvis_lsao_options *o, float *ao, int reps)
{
    double best = 1e30;
    int r;
    for (r = 0; r < reps; r++) {
        double t0 = bench_cpu_now(), t;
        if (hfvis_lsao(cam, depth, NULL, o, ao, cam->width - 2 * cam->guard_x) != HFVIS_OK) return -1.0;
        t = bench_cpu_now() - t0;
        if (t < best) best = t;
    }
    return best;
}

/* HBAO over a band of `rows` inner rows through the centre (rows = all: the whole image);
 * writes the band into ao at its image position. Returns seconds. */
static double bench_ssao_hbao(const hfvis_camera *cam, const float *depth,
                              const hfvis_hbao_options *o, float *ao, int rows)
{
    hfvis_camera band = *cam;
    int IH = cam->height - 2 * cam->guard_y, IW = cam->width - 2 * cam->guard_x, skip;
    double t0, t;
    if (rows > IH) rows = IH;
    skip = (IH - rows) / 2;
    band.guard_y = cam->guard_y + skip;
    rows = cam->height - 2 * band.guard_y;
    t0 = bench_cpu_now();
    if (hfvis_hbao(&band, depth, NULL, o, ao + (size_t)skip * (size_t)IW, IW) != HFVIS_OK) return -1.0;
    t = bench_cpu_now() - t0;
    return t * (double)IH / (double)rows; /* per whole image */
}

/* The [P3] Table 2 breakdown: sweep and gather seconds of one LSAO run. */
static void bench_ssao_breakdown(const hfvis_camera *cam, const float *depth,
                                 const hfvis_lsao_options *o, double *t_sweep, double *t_gather)
{
    hfvis_ssao_direction dirs[64];
    hfvis_ssao_lattice L;
    hfvis_ssao_line *lines;
    float *vals;
    double *acc;
    size_t n = (size_t)(cam->width - 2 * cam->guard_x) * (size_t)(cam->height - 2 * cam->guard_y);
    int k;
    *t_sweep = *t_gather = 0.0;
    if (hfvis_lsao_directions(o, dirs) != HFVIS_OK) return;
    acc = (double *)calloc(2 * n, sizeof(double));
    for (k = 0; k < o->directions; k++) {
        double t0;
        if (hfvis_ssao_lattice_init(cam, &dirs[k], &L) != HFVIS_OK) break;
        lines = (hfvis_ssao_line *)malloc(sizeof *lines * (size_t)L.line_count);
        vals = (float *)malloc(sizeof(float) * 2 * L.sample_count);
        hfvis_ssao_lattice_lines(cam, &L, lines);
        t0 = bench_cpu_now();
        hfvis_lsao_direction(cam, depth, NULL, o, &L, lines, vals, vals + L.sample_count);
        *t_sweep += bench_cpu_now() - t0;
        t0 = bench_cpu_now();
        hfvis_lsao_gather(cam, depth, NULL, o, &L, lines, vals, vals + L.sample_count, acc, acc + n);
        *t_gather += bench_cpu_now() - t0;
        free(vals);
        free(lines);
    }
    free(acc);
}

void bench_ssao(int quick)
{
    static const int res[3][2] = {{800, 600}, {1280, 720}, {1920, 1080}};
    /* falloff supports in view units (the knot is ~6 units away: at 1280x720, 1 unit ~ 125 px
     * there); 40 units covers the whole screen from every pixel */
    static const double radii[5] = {0.1, 0.25, 1.0, 4.0, 40.0};
    int ri, ki, ri2;
    printf("P3 line-sweep AO vs HBAO (matching quality: same box directions and texel steps, "
           "brute-force largest occluder)\n");
    printf("scene: torus knot (100k triangles) on a ground slab; falloff HBAO rho0 (C = 0.3) with "
           "support R; 20%% guard band\n");
    printf("%-10s %3s %6s | %9s %9s | %9s %9s %5s | %7s %9s\n", "size", "K", "R", "LSAO ms",
           "ns/px", "HBAO ms", "ns/px", "rows", "ratio", "mean|d|");
    for (ri = quick ? 1 : 0; ri < (quick ? 2 : 3); ri++) {
        int W = res[ri][0], H = res[ri][1], gx = W / 10, gy = H / 10, W0 = W + 2 * gx,
            H0 = H + 2 * gy;
        float *depth = (float *)malloc(sizeof(float) * (size_t)W0 * (size_t)H0);
        float *a1 = (float *)malloc(sizeof(float) * (size_t)W * (size_t)H);
        float *a2 = (float *)malloc(sizeof(float) * (size_t)W * (size_t)H);
        hfvis_camera cam;
        if (!depth || !a1 || !a2 || !bench_ssao_scene(W0, H0, gx, gy, depth, &cam)) {
            printf("scene setup failed\n");
            free(depth);
            free(a1);
            free(a2);
            return;
        }
        for (ki = 0; ki < 2; ki++) {
            int K = ki ? 16 : 8, rep;
            double lsao_t[5];
            /* LSAO at every radius, round-robin, best of the rounds: the machine is shared, and
             * interleaving keeps a slow spell from biasing one radius */
            for (ri2 = 0; ri2 < 5; ri2++) lsao_t[ri2] = 1e30;
            for (rep = 0; rep < (quick ? 1 : 5); rep++)
                for (ri2 = 0; ri2 < 5; ri2++) {
                    hfvis_lsao_options lo = hfvis_lsao_options_default();
                    double t;
                    lo.directions = K;
                    lo.falloff.kind = HFVIS_FALLOFF_HBAO;
                    lo.falloff.param = 0.3 * radii[ri2] * radii[ri2];
                    t = bench_ssao_lsao(&cam, depth, &lo, a1, 1);
                    if (t < lsao_t[ri2]) lsao_t[ri2] = t;
                }
            for (ri2 = 0; ri2 < 5; ri2++) {
                hfvis_lsao_options lo = hfvis_lsao_options_default();
                hfvis_hbao_options ho = hfvis_hbao_options_default();
                hfvis_ssao_direction dirs[16];
                double R = radii[ri2], tl, th, mean = 0.0, cost;
                int rows, IH = H, i, cnt = 0, skip;
                lo.directions = K;
                lo.falloff.kind = HFVIS_FALLOFF_HBAO;
                lo.falloff.param = 0.3 * R * R; /* support sqrt(r/C) = R */
                bench_ssao_lsao(&cam, depth, &lo, a1, 1); /* the image for the comparison */
                tl = lsao_t[ri2];
                hfvis_lsao_directions(&lo, dirs);
                ho.directions = K;
                ho.custom_directions = dirs;
                ho.variant = HFVIS_HBAO_LARGEST_OCCLUDER;
                ho.tangent = HFVIS_SSAO_TANGENT_FIXED;
                ho.plane = HFVIS_SSAO_PLANE_PAPER;
                ho.falloff = lo.falloff;
                /* march to the falloff's support at every radius (the default screen-radius cap
                 * would stop HBAO short of it at R >= 1 and compare unequal quality): the cap is
                 * the buffer diagonal, which hfvis_hbao takes as "no cap" */
                ho.max_radius_px = sqrt((double)W0 * (double)W0 + (double)H0 * (double)H0);
                /* a band small enough for ~1-2 s: cost ~ K (R_px / 2.4 px) samples per pixel */
                cost = (double)K * (R * 125.0 * (double)W / 1280.0 / 2.4 + 1.0);
                if (cost > 2.0 * (double)W) cost = 2.0 * (double)W; /* capped by the buffer */
                rows = (int)(1.5e8 / (cost * 4.0 * (double)W));
                if (quick) rows /= 4;
                if (rows < 8) rows = 8;
                if (rows > IH) rows = IH;
                th = bench_ssao_hbao(&cam, depth, &ho, a2, rows);
                skip = (IH - rows) / 2;
                for (i = skip * W; i < (skip + rows) * W; i++) {
                    mean += fabs((double)a1[i] - (double)a2[i]);
                    cnt++;
                }
                printf("%4dx%-5d %3d %6.2f | %9.2f %9.1f | %9.1f %9.1f %5d | %7.1f %9.5f\n", W, H, K,
                       R, 1e3 * tl, 1e9 * tl / ((double)W * H), 1e3 * th, 1e9 * th / ((double)W * H),
                       rows, th / tl, mean / (cnt ? cnt : 1));
                fflush(stdout);
            }
            {
                double lo_t = lsao_t[0], hi_t = lsao_t[0];
                for (ri2 = 1; ri2 < 5; ri2++) {
                    if (lsao_t[ri2] < lo_t) lo_t = lsao_t[ri2];
                    if (lsao_t[ri2] > hi_t) hi_t = lsao_t[ri2];
                }
                printf("%4dx%-5d %3d  LSAO time spread over the radii: %.1f %% (max/min - 1)\n", W, H,
                       K, 100.0 * (hi_t / lo_t - 1.0));
            }
        }
        if (res[ri][0] == 1280) {
            /* [P3] Table 2: K / (D_S D_L) = 4, stage breakdown */
            int Ks[4] = {8, 16, 24, 32}, j;
            printf("P3 Table 2 breakdown at 1280(+256)x720(+144), 4 evaluations per pixel:\n");
            for (j = 0; j < (quick ? 2 : 4); j++) {
                hfvis_lsao_options lo = hfvis_lsao_options_default(), rs;
                double ts, tg;
                lo.directions = Ks[j];
                lo.falloff.kind = HFVIS_FALLOFF_HBAO;
                lo.falloff.param = 0.3;
                hfvis_lsao_options_resolve(&lo, &rs);
                bench_ssao_breakdown(&cam, depth, &lo, &ts, &tg);
                printf("  K=%2d D_L=%.2f: line sweep %7.2f ms, gather %7.2f ms\n", Ks[j], rs.spacing,
                       1e3 * ts, 1e3 * tg);
            }
        }
        free(depth);
        free(a1);
        free(a2);
    }
}
