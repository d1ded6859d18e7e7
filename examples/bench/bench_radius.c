/* bench_radius.c - the search radius (hfvis.h, "Search radius and tiles"): the fused sky-view
 * factor at K = 16 on fBm, unlimited and with R = 16, 64, 256, 1024 cells, in ns per
 * receiver-direction and as a ratio to the unlimited sweep (lattice at 1024^2, exact rays at
 * 512^2 to keep the run short); then a 512^2 field as 4 x 4 tiles with the halo of
 * hfvis_tile_halo (R = 64 cells), the tiles' total time beside the whole run's and the
 * bit-for-bit comparison; then the [P2] visibility index (hfvis_visibility_count, the hull tree)
 * at 512^2, unlimited and with R = 16, 64, 256 cells, with the visible samples per
 * receiver-direction. quick: everything at 256^2. */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bench.h"

#define RADIUS_BENCH_K 16

static double radius_svf(const hfvis_grid *g, const hfvis_sweep_options *o, float *out)
{
    double t0 = bench_now();
    if (hfvis_sky_view_factor(g, RADIUS_BENCH_K, o, out, g->width) != HFVIS_OK) return -1.0;
    return bench_now() - t0;
}

/* 4 x 4 tiles of the n x n grid with R: each receiver window plus its halo, copied into its
 * own buffer; returns the total time and counts receivers that differ from whole[] in bits. */
static double radius_tiles(const hfvis_grid *g, const hfvis_sweep_options *o, const float *whole,
                           size_t *differ, int *halo_out)
{
    int n = g->width, halo = hfvis_tile_halo(o->max_distance, g->cell_size, o->rays), tx, ty;
    size_t cap = (size_t)(n / 4 + 2 * halo + 1) * (size_t)(n / 4 + 2 * halo + 1);
    float *z = (float *)malloc(cap * sizeof(float)), *out = (float *)malloc(cap * sizeof(float));
    double total = 0.0;
    *differ = 0;
    *halo_out = halo;
    if (!z || !out || halo < 0) {
        free(z);
        free(out);
        return -1.0;
    }
    for (ty = 0; ty < 4; ty++)
        for (tx = 0; tx < 4; tx++) {
            int x0 = tx * n / 4, x1 = (tx + 1) * n / 4, y0 = ty * n / 4, y1 = (ty + 1) * n / 4;
            int gx0 = x0 - halo < 0 ? 0 : x0 - halo, gy0 = y0 - halo < 0 ? 0 : y0 - halo;
            int gx1 = x1 + halo > n ? n : x1 + halo, gy1 = y1 + halo > n ? n : y1 + halo, x, y;
            hfvis_grid t = *g;
            hfvis_sweep_options to = *o;
            double dt;
            t.z = z;
            t.width = gx1 - gx0;
            t.height = gy1 - gy0;
            t.stride = t.width;
            for (y = gy0; y < gy1; y++)
                memcpy(z + (size_t)(y - gy0) * (size_t)t.width, g->z + (size_t)y * (size_t)n + (size_t)gx0,
                       (size_t)t.width * sizeof(float));
            to.origin_x = gx0;
            to.origin_y = gy0;
            to.extent_width = n;
            to.extent_height = n;
            to.receiver_x = x0 - gx0;
            to.receiver_y = y0 - gy0;
            to.receiver_width = x1 - x0;
            to.receiver_height = y1 - y0;
            if ((dt = radius_svf(&t, &to, out)) < 0.0) {
                free(z);
                free(out);
                return -1.0;
            }
            total += dt;
            for (y = y0; y < y1; y++)
                for (x = x0; x < x1; x++)
                    if (memcmp(&out[(size_t)(y - gy0) * (size_t)t.width + (size_t)(x - gx0)],
                               &whole[(size_t)y * (size_t)n + (size_t)x], sizeof(float)) != 0)
                        (*differ)++;
        }
    free(z);
    free(out);
    return total;
}

void bench_radius(int quick)
{
    static const double radii[] = {16.0, 64.0, 256.0, 1024.0};
    hfvis_field f;
    hfvis_grid g;
    int nmax = quick ? 256 : 1024, mode, r, n;
    size_t cells = (size_t)nmax * (size_t)nmax;
    float *z = (float *)malloc(cells * sizeof(float)), *out = (float *)malloc(cells * sizeof(float)),
          *whole = (float *)malloc(cells * sizeof(float));
    double rd;
    if (!z || !out || !whole) {
        printf("radius: out of memory\n");
        free(z);
        free(out);
        free(whole);
        return;
    }
    memset(&f, 0, sizeof f);
    f.kind = HFVIS_FIELD_FBM;
    f.amplitude = 40.0;
    f.wavelength = 64.0;
    f.seed = 5;
    printf("\n== radius: search radius R (cells), sky-view factor K=%d (fBm), ns per receiver-direction ==\n",
           RADIUS_BENCH_K);
    printf("%-16s %10s", "mode", "unlimited");
    for (r = 0; r < 4; r++) printf("   R=%-4.0f (ratio)", radii[r]);
    printf("\n");
    for (mode = 0; mode < 2; mode++) {
        hfvis_sweep_options o = hfvis_sweep_options_default();
        double t_unl;
        n = mode && !quick ? 512 : nmax;
        hfvis_field_generate(&f, n, n, n, z);
        g.z = z; g.width = n; g.height = n; g.stride = n; g.cell_size = 1.0;
        rd = (double)n * (double)n * RADIUS_BENCH_K;
        o.rays = mode ? HFVIS_RAYS_EXACT : HFVIS_RAYS_LATTICE;
        t_unl = radius_svf(&g, &o, out);
        printf("%-7s %4dx%-4d %10.1f", mode ? "exact" : "lattice", n, n, t_unl * 1e9 / rd);
        for (r = 0; r < 4; r++) {
            double t;
            o.max_distance = radii[r];
            t = radius_svf(&g, &o, out);
            printf("   %6.1f (%4.2fx)", t * 1e9 / rd, t / t_unl);
        }
        printf("\n");
    }
    n = quick ? 256 : 512;
    hfvis_field_generate(&f, n, n, n, z);
    g.z = z; g.width = n; g.height = n; g.stride = n; g.cell_size = 1.0;
    for (mode = 0; mode < 2; mode++) {
        hfvis_sweep_options o = hfvis_sweep_options_default();
        double tw, tt;
        size_t differ;
        int halo;
        o.rays = mode ? HFVIS_RAYS_EXACT : HFVIS_RAYS_LATTICE;
        o.max_distance = 64.0;
        tw = radius_svf(&g, &o, whole);
        tt = radius_tiles(&g, &o, whole, &differ, &halo);
        printf("tiles %-7s R=64 halo %d: whole %.3f s, 4x4 tiles %.3f s (%.2fx), receivers differing "
               "in bits: %zu of %zu\n", mode ? "exact" : "lattice", halo, tw, tt, tt / tw, differ,
               (size_t)n * (size_t)n);
    }
    /* the [P2] tree: the tree is built as without R, the visible listing and count shrink */
    {
        static const double vr[] = {0.0, 16.0, 64.0, 256.0};
        printf("visibility %4dx%-4d K=%d, ns per receiver-direction (visible samples each):", n, n,
               RADIUS_BENCH_K);
        for (r = 0; r < 4; r++) {
            hfvis_sweep_options o = hfvis_sweep_options_default();
            hfvis_visibility_stats st;
            double t0, t;
            o.max_distance = vr[r];
            t0 = bench_now();
            if (hfvis_visibility_count(&g, RADIUS_BENCH_K, &o, NULL, out, n, &st) != HFVIS_OK) {
                printf(" failed\n");
                break;
            }
            t = bench_now() - t0;
            if (r == 0) printf(" unlimited");
            else printf("  R=%.0f", vr[r]);
            printf(" %.1f (%.1f)", t * 1e9 / st.receivers, st.visible / st.receivers);
        }
        printf("\n");
    }
    free(z);
    free(out);
    free(whole);
}
