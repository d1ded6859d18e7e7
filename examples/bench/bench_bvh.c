/* bench_bvh.c - BVH build and ray queries on the 100k-triangle torus knot beside the
 * naive oracle: primary rays of a 1280x720 camera and short AO rays (cosine hemisphere). */
#define _POSIX_C_SOURCE 199309L
#include "bench.h"
#include "hfvis.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static uint64_t bench_bvh_rng = 0x853C49E6748FEA9Bull;
static double bench_bvh_unit(void)
{
    bench_bvh_rng ^= bench_bvh_rng >> 12;
    bench_bvh_rng ^= bench_bvh_rng << 25;
    bench_bvh_rng ^= bench_bvh_rng >> 27;
    return (double)((bench_bvh_rng * 0x2545F4914F6CDD1Dull) >> 11) * (1.0 / 9007199254740992.0);
}

/* Primary rays of a pinhole camera: eye (0, -5, 2.5) looking at the origin, vertical fov 30
 * degrees, w x h pixels (pixel centres), unit directions. */
static void bench_bvh_primary(hfvis_ray *rays, int w, int h)
{
    const double eye[3] = {0.0, -5.0, 2.5};
    double f[3], r[3], u[3], len, tn = tan(0.5 * 30.0 * 3.14159265358979323846 / 180.0);
    int x, y, a;
    for (a = 0; a < 3; a++) f[a] = -eye[a];
    len = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (a = 0; a < 3; a++) f[a] /= len;
    r[0] = f[1];  /* f x z_up */
    r[1] = -f[0];
    r[2] = 0.0;
    len = sqrt(r[0] * r[0] + r[1] * r[1]);
    r[0] /= len;
    r[1] /= len;
    u[0] = r[1] * f[2] - r[2] * f[1];
    u[1] = r[2] * f[0] - r[0] * f[2];
    u[2] = r[0] * f[1] - r[1] * f[0];
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            hfvis_ray *ray = rays + (size_t)y * (size_t)w + (size_t)x;
            double sx = (2.0 * (x + 0.5) / w - 1.0) * tn * w / h, sy = (1.0 - 2.0 * (y + 0.5) / h) * tn, d[3];
            memset(ray, 0, sizeof *ray);
            for (a = 0; a < 3; a++) d[a] = f[a] + sx * r[a] + sy * u[a];
            len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            for (a = 0; a < 3; a++) {
                ray->origin[a] = (float)eye[a];
                ray->direction[a] = (float)(d[a] / len);
            }
            ray->t_min = 0.0f;
            ray->t_max = INFINITY;
        }
}

/* AO rays: from the closest hits of the primary rays (every `step`-th ray), `per` cosine-
 * distributed directions about the face normal facing the camera, t in [1e-4 L, 0.1 L] with L
 * the mesh's bounding-box diagonal. Returns the number of rays written (<= cap). */
static size_t bench_bvh_ao(const hfvis_bvh *b, const hfvis_mesh *m, const hfvis_ray *prim,
                           size_t nprim, size_t step, int per, double diag, hfvis_ray *out,
                           size_t cap)
{
    size_t i, n = 0;
    int k, a;
    for (i = 0; i < nprim && n + (size_t)per <= cap; i += step) {
        hfvis_hit h;
        const float *p0, *p1, *p2;
        double e1[3], e2[3], nn[3], t1[3], t2[3], len, p[3];
        if (hfvis_bvh_closest_hit(b, m, prim + i, &h) != HFVIS_OK || h.triangle == HFVIS_NO_TRIANGLE)
            continue;
        p0 = m->xyz + 3 * (size_t)m->indices[3 * (size_t)h.triangle];
        p1 = m->xyz + 3 * (size_t)m->indices[3 * (size_t)h.triangle + 1];
        p2 = m->xyz + 3 * (size_t)m->indices[3 * (size_t)h.triangle + 2];
        for (a = 0; a < 3; a++) {
            e1[a] = (double)p1[a] - (double)p0[a];
            e2[a] = (double)p2[a] - (double)p0[a];
            p[a] = (double)prim[i].origin[a] + (double)h.t * (double)prim[i].direction[a];
        }
        nn[0] = e1[1] * e2[2] - e1[2] * e2[1];
        nn[1] = e1[2] * e2[0] - e1[0] * e2[2];
        nn[2] = e1[0] * e2[1] - e1[1] * e2[0];
        len = sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
        if (!(len > 0.0)) continue;
        if (!h.front) len = -len; /* face the camera */
        for (a = 0; a < 3; a++) nn[a] /= len;
        /* tangent frame */
        if (fabs(nn[0]) < 0.9) { t1[0] = 0.0; t1[1] = nn[2]; t1[2] = -nn[1]; }
        else { t1[0] = -nn[2]; t1[1] = 0.0; t1[2] = nn[0]; }
        len = sqrt(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
        for (a = 0; a < 3; a++) t1[a] /= len;
        t2[0] = nn[1] * t1[2] - nn[2] * t1[1];
        t2[1] = nn[2] * t1[0] - nn[0] * t1[2];
        t2[2] = nn[0] * t1[1] - nn[1] * t1[0];
        for (k = 0; k < per; k++) {
            double r1 = bench_bvh_unit(), r2 = bench_bvh_unit(), s = sqrt(r1), ph = 6.283185307179586 * r2;
            double lx = s * cos(ph), ly = s * sin(ph), lz = sqrt(1.0 - r1);
            hfvis_ray *ray = out + n++;
            memset(ray, 0, sizeof *ray);
            for (a = 0; a < 3; a++) {
                ray->origin[a] = (float)p[a];
                ray->direction[a] = (float)(lx * t1[a] + ly * t2[a] + lz * nn[a]);
            }
            ray->t_min = (float)(1e-4 * diag);
            ray->t_max = (float)(0.1 * diag);
        }
    }
    return n;
}

/* Time `n` queries (closest or any) through the BVH, best of `reps` runs (the machine may be
 * shared); returns seconds, counts hits. */
static double bench_bvh_run(const hfvis_bvh *b, const hfvis_mesh *m, const hfvis_ray *rays, size_t n,
                            hfvis_ray_query q, int reps, size_t *hits)
{
    double best = 1e30;
    int r;
    for (r = 0; r < reps; r++) {
        double t0 = bench_now(), t;
        size_t i, c = 0;
        for (i = 0; i < n; i++) {
            hfvis_hit h;
            hfvis_bvh_intersect(b, m, rays + i, q, NULL, NULL, &h);
            c += h.triangle != HFVIS_NO_TRIANGLE;
        }
        *hits = c;
        t = bench_now() - t0;
        if (t < best) best = t;
    }
    return best;
}

static double bench_bvh_run_naive(const hfvis_mesh *m, const hfvis_ray *rays, size_t n, size_t stride,
                                  hfvis_ray_query q, size_t *count)
{
    double t0 = bench_now();
    size_t i, c = 0;
    for (i = 0; i < n; i += stride) {
        hfvis_hit h;
        hfvis_ray_intersect_naive(m, rays + i, q, NULL, NULL, &h);
        c++;
    }
    *count = c;
    return bench_now() - t0;
}

static void bench_bvh_line(const char *what, size_t n, double sec, size_t hits, double naive_ns)
{
    double ns = 1e9 * sec / (double)n;
    printf("  %-30s %9zu %8.1f %9.2f %7.1f%%", what, n, ns, (double)n / sec * 1e-6,
           100.0 * (double)hits / (double)n);
    if (naive_ns > 0.0) printf(" %11.0f %9.0fx", naive_ns, naive_ns / ns);
    printf("\n");
}

void bench_bvh(int quick)
{
    const double c[3] = {0.0, 0.0, 0.0};
    hfvis_mesh m;
    hfvis_bvh b;
    hfvis_ray *prim, *ao;
    int w = quick ? 320 : 1280, h = quick ? 180 : 720, leaf, per = 16;
    size_t np = (size_t)w * (size_t)h, nao, hits, cnt, ao_cap;
    double best = 1e30, t0, sec, naive_sec, diag, lo[3], hi[3], naive_closest_prim, naive_any_prim,
           naive_closest_ao, naive_any_ao;
    int rep, reps = quick ? 1 : 3;

    if (hfvis_mesh_torus_knot(NULL, c, 1.0, 2, 3, 2500, 20, &m) != HFVIS_OK) {
        printf("bvh: torus knot failed\n");
        return;
    }
    hfvis_mesh_bounds(&m, lo, hi);
    diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1])
                + (hi[2] - lo[2]) * (hi[2] - lo[2]));
    printf("BVH and ray casting: torus knot (2,3) 2500x20 = %zu triangles, diagonal %.2f\n",
           m.triangle_count, diag);
    printf("  %-30s %9s %8s %9s\n", "build (binned SAH, 16 bins)", "ms", "ns/tri", "nodes");
    for (leaf = 1; leaf <= 8; leaf *= 2) {
        hfvis_bvh_options o = hfvis_bvh_options_default();
        char name[64];
        o.max_leaf_size = leaf;
        best = 1e30;
        for (rep = 0; rep < (quick ? 1 : 3); rep++) {
            t0 = bench_now();
            if (hfvis_bvh_build(&m, &o, &b) != HFVIS_OK) return;
            sec = bench_now() - t0;
            if (sec < best) best = sec;
            if (rep + 1 < (quick ? 1 : 3)) hfvis_bvh_free(NULL, &b);
        }
        sprintf(name, "max leaf %d (depth %d, %zu leaves)", leaf, b.depth, b.leaf_count);
        printf("  %-30s %9.1f %8.0f %9zu\n", name, 1e3 * best, 1e9 * best / (double)m.triangle_count,
               b.node_count);
        hfvis_bvh_free(NULL, &b);
    }
    if (hfvis_bvh_build(&m, NULL, &b) != HFVIS_OK) return;

    prim = (hfvis_ray *)malloc(sizeof *prim * np);
    ao_cap = (size_t)(quick ? 100000 : 1000000);
    ao = (hfvis_ray *)malloc(sizeof *ao * ao_cap);
    if (!prim || !ao) {
        free(prim);
        free(ao);
        hfvis_bvh_free(NULL, &b);
        hfvis_mesh_free(NULL, &m);
        return;
    }
    bench_bvh_primary(prim, w, h);
    nao = bench_bvh_ao(&b, &m, prim, np, quick ? 7 : 13, per, diag, ao, ao_cap);

    /* naive oracle on a small subset (every k-th ray) */
    naive_sec = bench_bvh_run_naive(&m, prim, np, np / (quick ? 50 : 200), HFVIS_RAY_CLOSEST, &cnt);
    naive_closest_prim = 1e9 * naive_sec / (double)cnt;
    naive_sec = bench_bvh_run_naive(&m, prim, np, np / (quick ? 50 : 200), HFVIS_RAY_ANY, &cnt);
    naive_any_prim = 1e9 * naive_sec / (double)cnt;
    naive_sec = bench_bvh_run_naive(&m, ao, nao, nao / (quick ? 50 : 200), HFVIS_RAY_CLOSEST, &cnt);
    naive_closest_ao = 1e9 * naive_sec / (double)cnt;
    naive_sec = bench_bvh_run_naive(&m, ao, nao, nao / (quick ? 50 : 200), HFVIS_RAY_ANY, &cnt);
    naive_any_ao = 1e9 * naive_sec / (double)cnt;

    printf("  %-30s %9s %8s %9s %8s %11s %10s\n", "query (default BVH, leaf 4)", "rays", "ns/ray",
           "Mrays/s", "hits", "naive ns", "ratio");
    sec = bench_bvh_run(&b, &m, prim, np, HFVIS_RAY_CLOSEST, reps, &hits);
    bench_bvh_line("primary 1280x720 closest", np, sec, hits, naive_closest_prim);
    sec = bench_bvh_run(&b, &m, prim, np, HFVIS_RAY_ANY, reps, &hits);
    bench_bvh_line("primary 1280x720 any-hit", np, sec, hits, naive_any_prim);
    sec = bench_bvh_run(&b, &m, ao, nao, HFVIS_RAY_CLOSEST, reps, &hits);
    bench_bvh_line("AO (16/pt, t<=0.1 diag) closest", nao, sec, hits, naive_closest_ao);
    sec = bench_bvh_run(&b, &m, ao, nao, HFVIS_RAY_ANY, reps, &hits);
    bench_bvh_line("AO (16/pt, t<=0.1 diag) any-hit", nao, sec, hits, naive_any_ao);
    printf("  (single thread, best of %d runs; naive = hfvis_ray_intersect_naive on %d evenly spaced rays of each set)\n", reps, quick ? 50 : 200);

    free(prim);
    free(ao);
    hfvis_bvh_free(NULL, &b);
    hfvis_mesh_free(NULL, &m);
}
