/* bench_lkobj.c - Laine-Karras mesh AO on the caller's OBJ meshes (`hfvis meshao`'s default
 * camera, radius and image): ns per ray of Method 1 (raster), Method 2 (BVH) and the reference
 * ray caster, and the bias of each disc pattern's mean obscurance against an independent
 * cosine-sampled estimate (many fresh i.i.d. Malley ray sets, one per interleaved batch of
 * receivers, so the pattern's systematic error averages out). The meshes are named by
 * HFVIS_BENCH_MESHES (paths separated by spaces); nothing is read without it:
 *   HFVIS_BENCH_MESHES="bunny.obj dragon.obj" BENCH_ARGS=lkobj make bench
 * docs/mesh-ao.md holds the figures. */
#define _POSIX_C_SOURCE 199309L
#include "bench.h"
#include "hfvis.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define BENCH_LKOBJ_BATCHES 256 /* fresh reference ray sets per ray count */
#define BENCH_LKOBJ_SEEDS 4     /* ray sets of the default pattern (its seed spread) */
#define BENCH_LKOBJ_PI 3.14159265358979323846

/* SplitMix64 as a uniform double in [0, 1). */
static double bench_lkobj_unit(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return (double)(z >> 11) * (1.0 / 9007199254740992.0);
}

/* `hfvis meshao`'s default view of a mesh (eye in front, -y, and above the bounding box, fov 45
 * degrees) and radius (0.1 x the box diagonal). */
static int bench_lkobj_view(const hfvis_mesh *m, int w, int h, hfvis_view *view, double *radius)
{
    double lo[3], hi[3], c[3], eye[3], up[3] = {0.0, 0.0, 1.0}, diag = 0.0, back, dist = 0.0;
    double fov = 45.0 * (BENCH_LKOBJ_PI / 180.0);
    int k;
    if (hfvis_mesh_bounds(m, lo, hi) != HFVIS_OK) return 0;
    for (k = 0; k < 3; k++) {
        c[k] = 0.5 * (lo[k] + hi[k]);
        diag += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    }
    diag = sqrt(diag);
    back = 0.5 * diag / tan(0.5 * fov) + 0.5 * diag;
    eye[0] = c[0] + 0.25 * back;
    eye[1] = c[1] - 0.9 * back;
    eye[2] = c[2] + 0.45 * back;
    for (k = 0; k < 3; k++) dist += (c[k] - eye[k]) * (c[k] - eye[k]);
    dist = sqrt(dist);
    *radius = 0.1 * diag;
    return hfvis_view_perspective(view, eye, c, up, fov, w, h, (dist + 2.0 * diag + 0.2 * diag) * 1e-4,
                                  dist + 2.0 * diag + 0.2 * diag) == HFVIS_OK;
}

/* Mean obscurance of the receivers by the reference caster with the rays of `pattern` and
 * `seed`, default options. */
static double bench_lkobj_mean(const hfvis_mesh *m, const hfvis_bvh *bvh,
                               const hfvis_lk_receivers *rc, int n, double radius,
                               hfvis_lk_pattern pattern, uint64_t seed, float *obs)
{
    hfvis_lk_ray_options ro = hfvis_lk_ray_options_default();
    hfvis_lk_rays rays;
    double sum = 0.0;
    size_t i;
    ro.pattern = pattern;
    ro.seed = seed;
    if (hfvis_lk_rays_build(n, radius, &ro, &rays) != HFVIS_OK) return (double)NAN;
    if (hfvis_lk_reference(m, bvh, &rays, rc, NULL, NULL, obs, NULL) != HFVIS_OK) sum = (double)NAN;
    hfvis_lk_rays_free(NULL, &rays);
    for (i = 0; i < rc->count; i++) sum += (double)obs[i];
    return sum / (double)rc->count;
}

/* The independent estimate: receiver i takes batch i % B, each batch its own N i.i.d.
 * cosine-distributed directions (Malley: uniform disc point by rejection, lifted), turned by a
 * uniform random rotation about the normal and NOT tilted (the frame's tilt jitter moves the
 * horizon and biases grazing-dominated obscurance up); *se gets the standard error from the
 * spread of the batch means. */
static double bench_lkobj_reference(const hfvis_mesh *m, const hfvis_bvh *bvh,
                                    const hfvis_lk_receivers *rc, int n, double radius,
                                    double *se)
{
    double *pos = (double *)malloc(sizeof(double) * 3 * rc->count);
    double *nrm = (double *)malloc(sizeof(double) * 3 * rc->count);
    uint64_t *key = (uint64_t *)malloc(sizeof(uint64_t) * rc->count);
    double *dir = (double *)malloc(sizeof(double) * 3 * (size_t)n);
    float *obs = (float *)malloc(sizeof(float) * rc->count);
    double bmean[BENCH_LKOBJ_BATCHES], total = 0.0, var = 0.0;
    uint64_t seed = 0x5EEDull;
    size_t cnt = 0, i;
    int b, j, ok = pos && nrm && key && dir && obs;
    for (b = 0; ok && b < BENCH_LKOBJ_BATCHES; b++) {
        hfvis_lk_receivers sub;
        hfvis_lk_rays rays;
        double s = 0.0;
        size_t q = 0;
        for (i = (size_t)b; i < rc->count; i += BENCH_LKOBJ_BATCHES, q++) {
            memcpy(pos + 3 * q, rc->position + 3 * i, 3 * sizeof(double));
            memcpy(nrm + 3 * q, rc->normal + 3 * i, 3 * sizeof(double));
            key[q] = rc->key ? rc->key[i] : (uint64_t)i;
        }
        for (j = 0; j < n; j++) {
            double x, y;
            do {
                x = 2.0 * bench_lkobj_unit(&seed) - 1.0;
                y = 2.0 * bench_lkobj_unit(&seed) - 1.0;
            } while (x * x + y * y >= 1.0 - 1e-6);
            dir[3 * j] = x;
            dir[3 * j + 1] = y;
            dir[3 * j + 2] = sqrt(1.0 - x * x - y * y);
        }
        sub.count = q;
        sub.position = pos;
        sub.normal = nrm;
        sub.key = key;
        if (q == 0 || hfvis_lk_rays_custom(n, radius, dir, NULL, NULL, &rays) != HFVIS_OK) {
            ok = 0;
            break;
        }
        {
            hfvis_lk_options o = hfvis_lk_options_default();
            o.jitter = HFVIS_LK_JITTER_CUSTOM;
            o.rotation_max_rad = BENCH_LKOBJ_PI;
            o.tilt_max_rad = 0.0;
            ok = hfvis_lk_reference(m, bvh, &rays, &sub, &o, NULL, obs, NULL) == HFVIS_OK;
        }
        hfvis_lk_rays_free(NULL, &rays);
        for (i = 0; i < q; i++) s += (double)obs[i];
        bmean[b] = s / (double)q;
        total += s;
        cnt += q;
    }
    for (b = 0; ok && b < BENCH_LKOBJ_BATCHES; b++)
        var += (bmean[b] - total / (double)cnt) * (bmean[b] - total / (double)cnt);
    *se = ok ? sqrt(var / (BENCH_LKOBJ_BATCHES - 1) / BENCH_LKOBJ_BATCHES) : (double)NAN;
    free(pos);
    free(nrm);
    free(key);
    free(dir);
    free(obs);
    return ok ? total / (double)cnt : (double)NAN;
}

static void bench_lkobj_one(const char *path, int quick)
{
    static const hfvis_lk_method methods[3] = {HFVIS_LK_METHOD_RASTER, HFVIS_LK_METHOD_BVH,
                                               HFVIS_LK_METHOD_RAYCAST};
    static const int counts[2] = {128, 1024};
    int w = quick ? 256 : 512, h = quick ? 192 : 384, k, c;
    hfvis_mesh m;
    hfvis_view view;
    hfvis_bvh bvh;
    double radius, *pos = NULL, *nrm = NULL;
    uint64_t *key = NULL;
    float *img = NULL, *obs = NULL;
    size_t cnt = 0;
    if (hfvis_mesh_load(path, NULL, &m) != HFVIS_OK) {
        printf("  %s: cannot load\n", path);
        return;
    }
    if (!bench_lkobj_view(&m, w, h, &view, &radius) || hfvis_bvh_build(&m, NULL, &bvh) != HFVIS_OK) {
        printf("  %s: setup failed\n", path);
        hfvis_mesh_free(NULL, &m);
        return;
    }
    img = (float *)malloc(sizeof(float) * (size_t)w * (size_t)h);
    /* timing: the three methods, the default pattern, N = 128 */
    printf("  %s: %zu triangles, %dx%d, r = %.4g\n", path, m.triangle_count, w, h, radius);
    for (c = 0; c < (quick ? 1 : 2) && img; c++) {
        hfvis_lk_rays rays;
        double ns[3];
        hfvis_lk_stats st;
        if (hfvis_lk_rays_build(counts[c], radius, NULL, &rays) != HFVIS_OK) break;
        for (k = 0; k < 3; k++) {
            double t0 = bench_now();
            memset(&st, 0, sizeof st);
            if (hfvis_lk_image(methods[k], &m, k ? &bvh : NULL, &view, &rays, NULL, NULL, img, &st) != HFVIS_OK) {
                ns[k] = (double)NAN;
                continue;
            }
            ns[k] = (bench_now() - t0) * 1e9 / (double)st.rays;
        }
        printf("    N = %4d: %llu receivers, ns/ray raster %.0f, bvh %.0f, raycast %.0f; mean W %.4f\n",
               counts[c], (unsigned long long)st.receivers, ns[0], ns[1], ns[2],
               st.rays ? (double)st.rays_blocked / (double)st.rays : 0.0);
        fflush(stdout);
        hfvis_lk_rays_free(NULL, &rays);
    }
    /* bias: the same receivers */
    if (bench_lkobj_view(&m, w, h, &view, &radius)) {
        size_t px = (size_t)w * (size_t)h;
        hfvis_lk_receivers rc;
        pos = (double *)malloc(sizeof(double) * 3 * px);
        nrm = (double *)malloc(sizeof(double) * 3 * px);
        key = (uint64_t *)malloc(sizeof(uint64_t) * px);
        obs = (float *)malloc(sizeof(float) * px);
        if (pos && nrm && key && obs &&
            hfvis_lk_gbuffer_receivers(&m, &view, NULL, pos, nrm, key, &cnt) == HFVIS_OK && cnt > 0) {
            rc.count = cnt;
            rc.position = pos;
            rc.normal = nrm;
            rc.key = key;
            for (c = 0; c < (quick ? 1 : 2); c++) {
                double se, ref = bench_lkobj_reference(&m, &bvh, &rc, counts[c], radius, &se);
                double lloyd = bench_lkobj_mean(&m, &bvh, &rc, counts[c], radius, HFVIS_LK_PATTERN_LLOYD, 0, obs);
                double rnd = bench_lkobj_mean(&m, &bvh, &rc, counts[c], radius, HFVIS_LK_PATTERN_RANDOM, 0, obs);
                double torus[BENCH_LKOBJ_SEEDS], tm = 0.0, tv = 0.0;
                for (k = 0; k < BENCH_LKOBJ_SEEDS; k++) {
                    torus[k] = bench_lkobj_mean(&m, &bvh, &rc, counts[c], radius, HFVIS_LK_PATTERN_LLOYD_TORUS,
                                                (uint64_t)k, obs) / ref - 1.0;
                    tm += torus[k] / BENCH_LKOBJ_SEEDS;
                }
                for (k = 0; k < BENCH_LKOBJ_SEEDS; k++) tv += (torus[k] - tm) * (torus[k] - tm) / (BENCH_LKOBJ_SEEDS - 1);
                printf("    bias N = %4d (%zu receivers): independent W %.4f (se %.1f %%); LLOYD %+.1f %%, "
                       "LLOYD_TORUS (default) %+.1f %% (seeds 0..%d: mean %+.1f %%, spread %.1f %%), RANDOM %+.1f %%\n",
                       counts[c], cnt, ref, 100.0 * se / ref, 100.0 * (lloyd / ref - 1.0), 100.0 * torus[0],
                       BENCH_LKOBJ_SEEDS - 1, 100.0 * tm, 100.0 * sqrt(tv), 100.0 * (rnd / ref - 1.0));
                fflush(stdout);
            }
        }
    }
    free(pos);
    free(nrm);
    free(key);
    free(obs);
    free(img);
    hfvis_bvh_free(NULL, &bvh);
    hfvis_mesh_free(NULL, &m);
}

void bench_lk_obj(int quick)
{
    const char *list = getenv("HFVIS_BENCH_MESHES");
    char path[4096];
    if (!list || !*list) {
        printf("\nLaine-Karras AO on OBJ meshes: set HFVIS_BENCH_MESHES=\"a.obj b.obj\" to run\n");
        return;
    }
    printf("\nLaine-Karras AO on OBJ meshes (hfvis meshao's camera and radius; ns per ray, one thread;\n"
           "bias = mean obscurance of each pattern / the independent cosine estimate - 1):\n");
    while (*list) {
        size_t n = strcspn(list, " ");
        if (n > 0 && n < sizeof path) {
            memcpy(path, list, n);
            path[n] = '\0';
            bench_lkobj_one(path, quick);
        }
        list += n;
        while (*list == ' ') list++;
    }
}
