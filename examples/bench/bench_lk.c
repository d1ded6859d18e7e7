/* bench_lk.c - Laine-Karras bitmask AO: rays per second of Method 1 (rasterization), Method 2
 * (BVH traversal) and the reference ray caster (the double predicate, and the library's float
 * watertight any-hit query) in one run, N = 128 and 1024, two radii, three scenes (a room with
 * objects, the 100k-triangle torus knot, a hairball of thin random triangles); beside the
 * paper's Table 1 ratios; the culling statistics in the shape of its Table 2; the plane
 * table's size and build time. */
#define _POSIX_C_SOURCE 199309L
#include "bench.h"
#include "hfvis.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static uint64_t bench_lk_rng = 0x853C49E6748FEA9Bull;
static double bench_lk_unit(void)
{
    bench_lk_rng ^= bench_lk_rng >> 12;
    bench_lk_rng ^= bench_lk_rng << 25;
    bench_lk_rng ^= bench_lk_rng >> 27;
    return (double)((bench_lk_rng * 0x2545F4914F6CDD1Dull) >> 11) * (1.0 / 9007199254740992.0);
}

/* A growable mesh. */
typedef struct bench_lk_mesh {
    float *xyz;
    uint32_t *idx;
    size_t nv, nt, cv, ct;
} bench_lk_mesh;

static int bench_lk_v(bench_lk_mesh *m, double x, double y, double z)
{
    if (m->nv == m->cv) {
        float *p;
        m->cv = m->cv ? 2 * m->cv : 1024;
        p = (float *)realloc(m->xyz, sizeof(float) * 3 * m->cv);
        if (!p) return 0;
        m->xyz = p;
    }
    m->xyz[3 * m->nv] = (float)x;
    m->xyz[3 * m->nv + 1] = (float)y;
    m->xyz[3 * m->nv + 2] = (float)z;
    m->nv++;
    return 1;
}

static int bench_lk_t(bench_lk_mesh *m, size_t a, size_t b, size_t c)
{
    if (m->nt == m->ct) {
        uint32_t *p;
        m->ct = m->ct ? 2 * m->ct : 1024;
        p = (uint32_t *)realloc(m->idx, sizeof(uint32_t) * 3 * m->ct);
        if (!p) return 0;
        m->idx = p;
    }
    m->idx[3 * m->nt] = (uint32_t)a;
    m->idx[3 * m->nt + 1] = (uint32_t)b;
    m->idx[3 * m->nt + 2] = (uint32_t)c;
    m->nt++;
    return 1;
}

/* Append src scaled by s and moved by (ox, oy, oz). */
static int bench_lk_add(bench_lk_mesh *m, const hfvis_mesh *src, double s, double ox, double oy,
                        double oz)
{
    size_t base = m->nv, i;
    for (i = 0; i < src->vertex_count; i++)
        if (!bench_lk_v(m, ox + s * (double)src->xyz[3 * i], oy + s * (double)src->xyz[3 * i + 1],
                        oz + s * (double)src->xyz[3 * i + 2]))
            return 0;
    for (i = 0; i < src->triangle_count; i++)
        if (!bench_lk_t(m, base + src->indices[3 * i], base + src->indices[3 * i + 1],
                        base + src->indices[3 * i + 2]))
            return 0;
    return 1;
}

static hfvis_mesh bench_lk_view_of(const bench_lk_mesh *m)
{
    hfvis_mesh h;
    h.xyz = m->xyz;
    h.vertex_count = m->nv;
    h.indices = m->idx;
    h.triangle_count = m->nt;
    return h;
}

/* The room (unit cube, open at the front) with a teapot, an icosphere and a torus knot. */
static int bench_lk_room(bench_lk_mesh *m)
{
    hfvis_mesh s;
    const double c0[3] = {0.0, 0.0, 0.0};
    int ok = 1;
    if (hfvis_mesh_room(NULL, &s) != HFVIS_OK) return 0;
    ok &= bench_lk_add(m, &s, 1.0, 0.0, 0.0, 0.0);
    hfvis_mesh_free(NULL, &s);
    if (hfvis_mesh_teapot(NULL, 8, &s) != HFVIS_OK) return 0;
    ok &= bench_lk_add(m, &s, 0.14, 0.3, 0.22, 0.0);
    hfvis_mesh_free(NULL, &s);
    if (hfvis_mesh_icosphere(NULL, c0, 1.0, 3, &s) != HFVIS_OK) return 0;
    ok &= bench_lk_add(m, &s, 0.1, 0.72, 0.6, 0.1);
    hfvis_mesh_free(NULL, &s);
    if (hfvis_mesh_torus_knot(NULL, c0, 1.0, 2, 3, 600, 12, &s) != HFVIS_OK) return 0;
    ok &= bench_lk_add(m, &s, 0.09, 0.5, 0.78, 0.75);
    hfvis_mesh_free(NULL, &s);
    return ok;
}

/* Hairball: `strands` random walks of `segs` thin triangles (length 0.03, width 0.008) inside
 * the unit ball. */
static int bench_lk_hairball(bench_lk_mesh *m, int strands, int segs)
{
    int s, k, a;
    bench_lk_rng = 0x2545F4914F6CDD1Dull;
    for (s = 0; s < strands; s++) {
        double p[3], d[3], len;
        do {
            for (a = 0; a < 3; a++) p[a] = 2.0 * bench_lk_unit() - 1.0;
        } while (p[0] * p[0] + p[1] * p[1] + p[2] * p[2] > 0.9);
        for (a = 0; a < 3; a++) d[a] = 2.0 * bench_lk_unit() - 1.0;
        for (k = 0; k < segs; k++) {
            double q[3], w[3], n;
            size_t base = m->nv;
            for (a = 0; a < 3; a++) d[a] += 0.6 * (2.0 * bench_lk_unit() - 1.0);
            if (p[0] * p[0] + p[1] * p[1] + p[2] * p[2] > 0.95)
                for (a = 0; a < 3; a++) d[a] -= 0.5 * p[a]; /* turn back inside */
            len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            for (a = 0; a < 3; a++) {
                d[a] /= len;
                q[a] = p[a] + 0.03 * d[a];
            }
            /* width direction: d x random */
            w[0] = d[1] * 0.3 - d[2] * 0.5;
            w[1] = d[2] * 0.8 - d[0] * 0.3;
            w[2] = d[0] * 0.5 - d[1] * 0.8;
            n = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
            if (!bench_lk_v(m, p[0], p[1], p[2]) || !bench_lk_v(m, q[0], q[1], q[2]) ||
                !bench_lk_v(m, p[0] + 0.008 * w[0] / n, p[1] + 0.008 * w[1] / n, p[2] + 0.008 * w[2] / n) ||
                !bench_lk_t(m, base, base + 1, base + 2))
                return 0;
            for (a = 0; a < 3; a++) p[a] = q[a];
        }
    }
    return 1;
}

/* One timed run of a method on the G-buffer receivers (every `stride`-th for Method 2 and the
 * ray casters); returns seconds, fills rays and the stats. */
typedef struct bench_lk_run {
    double sec, rays, blocked;
    hfvis_lk_stats st;
} bench_lk_run;

static int bench_lk_method(int method, const hfvis_mesh *m, const hfvis_bvh *bvh,
                           const hfvis_view *v, const hfvis_lk_rays *rays,
                           const hfvis_lk_receivers *all, size_t stride,
                           const hfvis_lk_options *opts, bench_lk_run *out)
{
    size_t n = (all->count + stride - 1) / stride, i, words = (size_t)rays->words;
    double *pos = NULL, *nrm = NULL, t0;
    uint64_t *key = NULL;
    float *ob;
    hfvis_lk_receivers rc;
    hfvis_status s;
    if (method == 0) n = (size_t)v->width * (size_t)v->height;
    ob = (float *)malloc(sizeof(float) * (n ? n : 1));
    (void)words;
    if (!ob) return 0;
    if (method != 0) {
        pos = (double *)malloc(sizeof(double) * 3 * (n ? n : 1));
        nrm = (double *)malloc(sizeof(double) * 3 * (n ? n : 1));
        key = (uint64_t *)malloc(sizeof(uint64_t) * (n ? n : 1));
        if (!pos || !nrm || !key) {
            free(ob); free(pos); free(nrm); free(key);
            return 0;
        }
        for (i = 0; i < n; i++) {
            memcpy(pos + 3 * i, all->position + 3 * i * stride, sizeof(double) * 3);
            memcpy(nrm + 3 * i, all->normal + 3 * i * stride, sizeof(double) * 3);
            key[i] = all->key[i * stride];
        }
    }
    rc.count = n;
    rc.position = pos;
    rc.normal = nrm;
    rc.key = key;
    t0 = bench_now();
    if (method == 0) s = hfvis_lk_raster(m, v, rays, opts, NULL, ob, &out->st);
    else if (method == 1) s = hfvis_lk_bvh(m, bvh, rays, &rc, opts, NULL, ob, &out->st);
    else s = hfvis_lk_reference(m, bvh, rays, &rc, opts, NULL, ob, &out->st);
    out->sec = bench_now() - t0;
    out->rays = (double)out->st.rays;
    out->blocked = (double)out->st.rays_blocked;
    free(ob); free(pos); free(nrm); free(key);
    return s == HFVIS_OK;
}

/* Table 1 of [LK] (millions of rays per second) and its BVH / ray caster ratios. */
static const double bench_lk_paper_ratio[2][6] = {
    {6.97, 2.49, 11.06, 5.33, 15.29, 5.37},   /* N = 128: Sibenik .75 2.25, City 75 225, Hairball .1 .3 */
    {7.73, 2.25, 15.32, 6.06, 30.70, 6.78}};  /* N = 1024 */

void bench_lk(int quick)
{
    const char *names[3] = {"room+objects", "torus knot 100k", "hairball"};
    const double radii[3][2] = {{0.05, 0.15}, {0.2, 0.5}, {0.04, 0.12}};
    const double eyes[3][3] = {{0.5, -1.15, 0.5}, {0.0, -5.0, 2.5}, {0.0, -3.2, 0.9}};
    const double tgts[3][3] = {{0.5, 0.5, 0.38}, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
    const double fovs[3] = {55.0, 38.0, 40.0};
    const int W = quick ? 80 : 192, H = quick ? 60 : 144;
    const int ncount = quick ? 1 : 2;
    const int Ns[2] = {128, 1024};
    double rays_budget = quick ? 1e5 : 1e6; /* rays per ray-caster / Method 2 run */
    int sc, ri, ni;
    printf("Laine-Karras bitmask AO: Mrays/s (single thread), %dx%d G-buffer receivers; Method 2 and "
           "the ray casters on every k-th receiver (about %.1fM rays per run)\n", W, H, rays_budget * 1e-6);
    printf("  %-16s %5s %5s %9s %9s %9s %9s %9s %8s %8s %8s %7s\n", "scene", "N", "r", "M1 rast",
           "M2 bvh", "M2 lut", "cast dbl", "cast f32", "M2/dbl", "M2/f32", "lut/f32", "paper");
    for (sc = 0; sc < 3; sc++) {
        bench_lk_mesh bm;
        hfvis_mesh m;
        hfvis_bvh bvh;
        hfvis_view v;
        const double up[3] = {0.0, 0.0, 1.0};
        double *pos, *nrm;
        uint64_t *key;
        size_t cnt = 0, npix = (size_t)W * (size_t)H;
        hfvis_lk_receivers all;
        int ok;
        memset(&bm, 0, sizeof bm);
        if (sc == 0) ok = bench_lk_room(&bm);
        else if (sc == 1) {
            hfvis_mesh k;
            const double c0[3] = {0.0, 0.0, 0.0};
            ok = hfvis_mesh_torus_knot(NULL, c0, 1.0, 2, 3, quick ? 500 : 2500, 20, &k) == HFVIS_OK;
            if (ok) {
                ok = bench_lk_add(&bm, &k, 1.0, 0.0, 0.0, 0.0);
                hfvis_mesh_free(NULL, &k);
            }
        } else ok = bench_lk_hairball(&bm, quick ? 500 : 1700, 60);
        m = bench_lk_view_of(&bm);
        pos = (double *)malloc(sizeof(double) * 3 * npix);
        nrm = (double *)malloc(sizeof(double) * 3 * npix);
        key = (uint64_t *)malloc(sizeof(uint64_t) * npix);
        if (!ok || !pos || !nrm || !key ||
            hfvis_view_perspective(&v, eyes[sc], tgts[sc], up, fovs[sc] * 3.14159265358979323846 / 180.0,
                                   W, H, 0.05, 50.0) != HFVIS_OK ||
            hfvis_bvh_build(&m, NULL, &bvh) != HFVIS_OK ||
            hfvis_lk_gbuffer_receivers(&m, &v, NULL, pos, nrm, key, &cnt) != HFVIS_OK) {
            printf("  %s: setup failed\n", names[sc]);
            free(pos); free(nrm); free(key); free(bm.xyz); free(bm.idx);
            continue;
        }
        all.count = cnt;
        all.position = pos;
        all.normal = nrm;
        all.key = key;
        for (ni = 0; ni < 2; ni++)
            for (ri = 0; ri < ncount; ri++) {
                hfvis_lk_rays rays;
                hfvis_lk_ray_options ro = hfvis_lk_ray_options_default();
                hfvis_lk_options o = hfvis_lk_options_default(), ow;
                bench_lk_run r1, r2, r3, r4, r5;
                hfvis_lk_lut L;
                hfvis_lk_options ol;
                size_t stride = (size_t)ceil((double)cnt * Ns[ni] / rays_budget);
                double m1, m2, m3, m4, m5 = 0.0;
                if (stride < 1) stride = 1;
                if (hfvis_lk_rays_build(Ns[ni], radii[sc][ri], &ro, &rays) != HFVIS_OK) continue;
                ow = o;
                ow.raycast_test = HFVIS_LK_RAYCAST_WATERTIGHT;
                if (!bench_lk_method(0, &m, &bvh, &v, &rays, &all, 1, &o, &r1) ||
                    !bench_lk_method(1, &m, &bvh, &v, &rays, &all, stride, &o, &r2) ||
                    !bench_lk_method(2, &m, &bvh, &v, &rays, &all, stride, &o, &r3) ||
                    !bench_lk_method(2, &m, &bvh, &v, &rays, &all, stride, &ow, &r4)) {
                    printf("  %s: run failed\n", names[sc]);
                    hfvis_lk_rays_free(NULL, &rays);
                    continue;
                }
                /* the paper's configuration: table masks and circular table node masks */
                if (hfvis_lk_lut_build(&rays, 64, NULL, &L) == HFVIS_OK) {
                    ol = o;
                    ol.lut = &L;
                    ol.mask_mode = HFVIS_LK_MASK_LUT;
                    ol.node_mask = HFVIS_LK_NODE_SPHERE_LUT;
                    if (bench_lk_method(1, &m, &bvh, &v, &rays, &all, stride, &ol, &r5))
                        m5 = r5.rays / r5.sec * 1e-6;
                    hfvis_lk_lut_free(NULL, &L);
                }
                m1 = r1.rays / r1.sec * 1e-6;
                m2 = r2.rays / r2.sec * 1e-6;
                m3 = r3.rays / r3.sec * 1e-6;
                m4 = r4.rays / r4.sec * 1e-6;
                printf("  %-16s %5d %5.2f %9.2f %9.2f %9.2f %9.2f %9.2f %7.1fx %7.1fx %7.1fx %6.1fx\n",
                       ri == 0 && ni == 0 ? names[sc] : "", Ns[ni], radii[sc][ri], m1, m2, m5, m3, m4,
                       m2 / m3, m2 / m4, m5 / m4, bench_lk_paper_ratio[ni][2 * sc + ri]);
                printf("  %-16s %17s W %.3f; M1 %.0f fragments, %.1f masks/receiver; M2 %.1f masks, "
                       "%.1f nodes/receiver; cast %.1f tests/ray\n", "", "", r1.blocked / r1.rays,
                       (double)r1.st.fragments, (double)r1.st.masks / (double)r1.st.receivers,
                       (double)r2.st.masks / (double)r2.st.receivers,
                       (double)r2.st.nodes_visited / (double)r2.st.receivers,
                       (double)r3.st.fragments / r3.rays);
                fflush(stdout);
                hfvis_lk_rays_free(NULL, &rays);
            }
        printf("  %-16s %zu triangles, %zu receivers\n", "", m.triangle_count, cnt);
        hfvis_bvh_free(NULL, &bvh);
        free(pos); free(nrm); free(key); free(bm.xyz); free(bm.idx);
    }
    printf("  (M1 rast, M2 bvh: exact masks; M2 lut: table masks + circular table node masks, T = 64, "
           "approximate; cast dbl: the exact reference caster (double predicate); cast f32: the "
           "library's float watertight any-hit query; paper = [LK] Table 1 BVH traversal / ray "
           "caster on a GTX 480 for the corresponding scene column: Sibenik, City, Hairball)\n");

    /* Table 2 shape: Method 1 mask computations and time as tests are added, relative to all */
    {
        bench_lk_mesh bm;
        hfvis_mesh m;
        hfvis_view v;
        const double up[3] = {0.0, 0.0, 1.0};
        static const char *rows[7] = {"depth test only", "+ 1. far depth (paper)", "+ 2. bounding sphere",
                                      "+ 3. triangle facing", "+ 4. plane distance",
                                      "+ 5. hemisphere facing", "all, safe far depth"};
        static const unsigned sets[7] = {
            HFVIS_LK_CULL_SET,
            HFVIS_LK_CULL_SET | HFVIS_LK_CULL_PAPER_FAR_DEPTH,
            HFVIS_LK_CULL_SET | HFVIS_LK_CULL_PAPER_FAR_DEPTH | HFVIS_LK_CULL_SPHERE,
            HFVIS_LK_CULL_SET | HFVIS_LK_CULL_PAPER_FAR_DEPTH | HFVIS_LK_CULL_SPHERE | HFVIS_LK_CULL_FACING,
            HFVIS_LK_CULL_SET | HFVIS_LK_CULL_PAPER_FAR_DEPTH | HFVIS_LK_CULL_SPHERE | HFVIS_LK_CULL_FACING |
                HFVIS_LK_CULL_PLANE,
            HFVIS_LK_CULL_SET | HFVIS_LK_CULL_PAPER_FAR_DEPTH | HFVIS_LK_CULL_SPHERE | HFVIS_LK_CULL_FACING |
                HFVIS_LK_CULL_PLANE | HFVIS_LK_CULL_HORIZON,
            HFVIS_LK_CULL_ALL};
        double frag[2][7], sec[2][7];
        int k;
        memset(&bm, 0, sizeof bm);
        if (!bench_lk_room(&bm) ||
            hfvis_view_perspective(&v, eyes[0], tgts[0], up, fovs[0] * 3.14159265358979323846 / 180.0, W, H,
                                   0.05, 50.0) != HFVIS_OK) {
            free(bm.xyz); free(bm.idx);
            return;
        }
        m = bench_lk_view_of(&bm);
        for (ri = 0; ri < 2; ri++) {
            hfvis_lk_rays rays;
            if (hfvis_lk_rays_build(128, radii[0][ri], NULL, &rays) != HFVIS_OK) continue;
            for (k = 0; k < 7; k++) {
                hfvis_lk_options o = hfvis_lk_options_default();
                hfvis_lk_stats st;
                float *ob = (float *)malloc(sizeof(float) * (size_t)W * (size_t)H);
                double t0 = bench_now(), best = 1e30;
                int rep;
                o.cull = sets[k];
                for (rep = 0; rep < (quick ? 1 : 2); rep++) {
                    t0 = bench_now();
                    if (!ob || hfvis_lk_raster(&m, &v, &rays, &o, NULL, ob, &st) != HFVIS_OK) break;
                    if (bench_now() - t0 < best) best = bench_now() - t0;
                }
                frag[ri][k] = (double)st.masks;
                sec[ri][k] = best;
                free(ob);
            }
            hfvis_lk_rays_free(NULL, &rays);
        }
        printf("Culling tests of Method 1 in the shape of [LK] Table 2 (room+objects, N = 128; #frag = "
               "masks computed, both relative to the paper's all-tests row)\n");
        printf("  %-24s %9s %7s %9s %7s   paper: %5s %5s %5s %5s\n", "culling tests", "r=0.05 #frag", "perf",
               "r=0.15 #frag", "perf", "#frag", "perf", "#frag", "perf");
        {
            static const double paper[6][4] = {{7.06, 0.30, 5.79, 0.30}, {3.78, 0.47, 3.90, 0.40},
                                               {3.22, 0.52, 3.11, 0.47}, {2.11, 0.73, 1.95, 0.70},
                                               {2.03, 0.74, 1.92, 0.70}, {1.00, 1.00, 1.00, 1.00}};
            for (k = 0; k < 7; k++) {
                printf("  %-24s %9.2f %7.2f %9.2f %7.2f", rows[k], frag[0][k] / frag[0][5], sec[0][5] / sec[0][k],
                       frag[1][k] / frag[1][5], sec[1][5] / sec[1][k]);
                if (k < 6)
                    printf("          %5.2f %5.2f %5.2f %5.2f", paper[k][0], paper[k][1], paper[k][2], paper[k][3]);
                printf("\n");
            }
        }
        free(bm.xyz);
        free(bm.idx);
    }

    /* the plane table: size and build time (paper: 128^3 at N = 128, 32 MB, a few ms on a GPU) */
    {
        static const int cfg[3][2] = {{128, 64}, {128, 128}, {1024, 64}};
        int c;
        printf("Plane look-up table (node indexing, 7/8 remap; one table, constant falloff):\n");
        for (c = 0; c < (quick ? 1 : 3); c++) {
            hfvis_lk_rays rays;
            hfvis_lk_lut L;
            double t0;
            if (hfvis_lk_rays_build(cfg[c][0], 1.0, NULL, &rays) != HFVIS_OK) continue;
            t0 = bench_now();
            if (hfvis_lk_lut_build(&rays, cfg[c][1], NULL, &L) == HFVIS_OK) {
                printf("  N = %4d, T = %3d: %6.1f MiB, built in %.3f s\n", cfg[c][0], cfg[c][1],
                       (double)L.bytes / 1048576.0, bench_now() - t0);
                hfvis_lk_lut_free(NULL, &L);
            }
            hfvis_lk_rays_free(NULL, &rays);
        }
        printf("  N = 1024, T = 128 (the paper's T): %.0f MiB for one table (the limit, "
               "HFVIS_LK_LUT_MAX_BYTES); with variable lengths two tables -> HFVIS_ERR_LIMIT\n",
               (double)hfvis_lk_lut_bytes(128, 1024, 0) / 1048576.0);
    }
}
