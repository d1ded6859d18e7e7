/* bench_vf.c - 4D visibility fields ([G12] ch. 4): build time per (position x direction) sample
 * (BVH caster and the naive oracle), and the query cost per ray against BVH ray casting of the
 * same rays in the same run (the point of a field is a cheaper query). Full mode adds the
 * thesis-grid error tables (Fig. 35 form) for the exact sphere and the teapot.
 * Usage: bench_vf [quick]   (quick: a few seconds; full: under about two minutes) */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench.h"
#include "hfvis.h"

static uint64_t bench_vf_rng = 12345;
static double bench_vf_unit(void)
{
    uint64_t z = (bench_vf_rng += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return (double)(z >> 11) * (1.0 / 9007199254740992.0);
}

/* A field over mesh with malloc'ed maps (bounding sphere of the mesh). */
static int bench_vf_field(const hfvis_mesh *mesh, int n, int D, hfvis_visfield_format f,
                          hfvis_visfield *vf)
{
    memset(vf, 0, sizeof *vf);
    if (hfvis_visfield_bounding_sphere(mesh, vf->center, &vf->radius) != HFVIS_OK) return 0;
    vf->positions_n = n;
    vf->dir_res = D;
    vf->format = f;
    vf->mapping = HFVIS_DIRMAP_CONCENTRIC;
    vf->maps_size = hfvis_visfield_size(n, D, f);
    vf->maps = malloc(vf->maps_size);
    return vf->maps != NULL;
}

/* Build time per sample (seconds per position x direction ray), BVH build included. */
static double bench_vf_build(const hfvis_mesh *mesh, int n, int D, int reference, double *total_s)
{
    hfvis_visfield vf;
    double t0, dt;
    hfvis_status s;
    if (!bench_vf_field(mesh, n, D, HFVIS_VISFIELD_U8, &vf)) return (double)NAN;
    t0 = bench_now();
    s = reference ? hfvis_visfield_build_reference(mesh, NULL, &vf) : hfvis_visfield_build(mesh, NULL, &vf);
    dt = bench_now() - t0;
    free(vf.maps);
    if (s != HFVIS_OK) return (double)NAN;
    if (total_s) *total_s = dt;
    return dt / ((double)hfvis_visfield_position_count(n) * (double)D * (double)D);
}

/* AO rays of the thesis' setting: receivers on a floor under the object (normal +z), 16 x 16
 * concentric rays each, as world-space rays; count = receivers * 256. */
static void bench_vf_rays(const hfvis_visfield *vf, int receivers, double *org, double *dir)
{
    int p, i, j, a;
    for (p = 0; p < receivers; p++) {
        double x[3], t[3], b[3], nz[3] = {0.0, 0.0, 1.0};
        x[0] = vf->center[0] + (bench_vf_unit() * 2.0 - 1.0) * 1.5 * vf->radius;
        x[1] = vf->center[1] + (bench_vf_unit() * 2.0 - 1.0) * 1.5 * vf->radius;
        x[2] = vf->center[2] - 0.75 * vf->radius;
        hfvis_visfield_frame(nz, t, b);
        for (j = 0; j < 16; j++)
            for (i = 0; i < 16; i++) {
                double l[3], r2, *o = org + 3 * ((size_t)p * 256 + (size_t)j * 16 + (size_t)i);
                double *d = dir + 3 * ((size_t)p * 256 + (size_t)j * 16 + (size_t)i);
                hfvis_concentric_square_to_disk((2 * i + 1) / 16.0 - 1.0, (2 * j + 1) / 16.0 - 1.0, &l[0], &l[1]);
                r2 = l[0] * l[0] + l[1] * l[1];
                l[2] = sqrt(r2 < 1.0 ? 1.0 - r2 : 0.0);
                for (a = 0; a < 3; a++) {
                    o[a] = x[a];
                    d[a] = l[0] * t[a] + l[1] * b[a] + l[2] * nz[a];
                }
            }
    }
}

/* The machine may be shared: every timing below is the minimum over BENCH_VF_REPS interleaved
 * repetitions. */
#define BENCH_VF_REPS 5

/* ns per ray: visibility-field query, BVH closest hit and BVH any hit of the same rays; the hit
 * rate of the field and of the BVH. */
static void bench_vf_query(const hfvis_mesh *mesh, const hfvis_bvh *bvh, const hfvis_visfield *vf,
                           int receivers, double out[5])
{
    size_t nr = (size_t)receivers * 256, q;
    double *org = (double *)malloc(sizeof(double) * 3 * nr), *dir = (double *)malloc(sizeof(double) * 3 * nr);
    double t0, dt, hits_vf = 0.0, hits_bvh = 0.0, sink = 0.0;
    int a, rep, m;
    out[0] = out[1] = out[2] = out[3] = out[4] = (double)NAN;
    if (!org || !dir) {
        free(org);
        free(dir);
        return;
    }
    bench_vf_rays(vf, receivers, org, dir);
    out[0] = out[1] = out[2] = HUGE_VAL;
    for (rep = 0; rep < BENCH_VF_REPS; rep++)
        for (m = 0; m < 3; m++) {
            hits_vf = hits_bvh = 0.0;
            t0 = bench_now();
            for (q = 0; q < nr; q++) {
                if (m == 0) {
                    hfvis_visfield_hit h;
                    hfvis_visfield_query(vf, org + 3 * q, dir + 3 * q, 0.02 * vf->radius, &h);
                    hits_vf += h.result != HFVIS_VISFIELD_MISS;
                    sink += h.distance < 1e300 ? h.distance : 0.0;
                } else {
                    hfvis_ray r;
                    hfvis_hit h;
                    for (a = 0; a < 3; a++) {
                        r.origin[a] = (float)org[3 * q + a];
                        r.direction[a] = (float)dir[3 * q + a];
                    }
                    r.t_min = 1e-4f;
                    r.t_max = INFINITY;
                    r.cull = HFVIS_CULL_NONE;
                    if (m == 1) hfvis_bvh_closest_hit(bvh, mesh, &r, &h);
                    else hfvis_bvh_any_hit(bvh, mesh, &r, &h);
                    hits_bvh += h.triangle != HFVIS_NO_TRIANGLE;
                    sink += (double)h.u;
                }
            }
            dt = (bench_now() - t0) / (double)nr;
            if (dt < out[m]) out[m] = dt;
            if (m == 0) out[3] = hits_vf / (double)nr;
            if (m == 1) out[4] = hits_bvh / (double)nr;
        }
    if (sink == 1.2345) printf(" ");
    free(org);
    free(dir);
}

/* ns per ray of the whole AO routine (fast vs reference through the BVH), receivers x 256 rays. */
static void bench_vf_ao(const hfvis_mesh *mesh, const hfvis_bvh *bvh, const hfvis_visfield *vf,
                        int receivers, double out[2])
{
    float *pts = (float *)malloc(sizeof(float) * 3 * (size_t)receivers);
    float *nrm = (float *)malloc(sizeof(float) * 3 * (size_t)receivers);
    float *ao = (float *)malloc(sizeof(float) * (size_t)receivers);
    hfvis_visfield_object ob;
    double t0, dt;
    int p, i, rep;
    out[0] = out[1] = (double)NAN;
    if (!pts || !nrm || !ao) goto done;
    for (p = 0; p < receivers; p++) {
        pts[3 * p] = (float)(vf->center[0] + (bench_vf_unit() * 2.0 - 1.0) * 1.5 * vf->radius);
        pts[3 * p + 1] = (float)(vf->center[1] + (bench_vf_unit() * 2.0 - 1.0) * 1.5 * vf->radius);
        pts[3 * p + 2] = (float)(vf->center[2] - 0.75 * vf->radius);
        nrm[3 * p] = nrm[3 * p + 1] = 0.0f;
        nrm[3 * p + 2] = 1.0f;
    }
    ob.field = vf;
    ob.mesh = mesh;
    ob.bvh = bvh;
    for (i = 0; i < 16; i++) ob.object_to_world[i] = (i % 5 == 0) ? 1.0 : 0.0;
    out[0] = out[1] = HUGE_VAL;
    for (rep = 0; rep < BENCH_VF_REPS; rep++) {
        t0 = bench_now();
        if (hfvis_visfield_ambient_occlusion(&ob, 1, pts, nrm, (size_t)receivers, NULL, ao) != HFVIS_OK)
            goto done;
        dt = (bench_now() - t0) / ((double)receivers * 256.0);
        if (dt < out[0]) out[0] = dt;
        t0 = bench_now();
        if (hfvis_visfield_ambient_occlusion_reference(&ob, 1, pts, nrm, (size_t)receivers, NULL, ao)
            != HFVIS_OK)
            goto done;
        dt = (bench_now() - t0) / ((double)receivers * 256.0);
        if (dt < out[1]) out[1] = dt;
    }
done:
    free(pts);
    free(nrm);
    free(ao);
}

/* Outside-ray statistics against an exact oracle (query_reference) and AO RMS (x 255) on the
 * thesis' corner (3 x 33 x 33 receivers, 256 rays) against ray casting with the same rays. */
static void bench_vf_errors(const hfvis_mesh *mesh, const hfvis_bvh *bvh, const hfvis_visfield *vf,
                            const double T[3], double L, double out[3])
{
    enum { NC = 33, P = 3 * NC * NC, RAYS = 20000 };
    static float pts[3 * P], nrm[3 * P], fast[P], ref[P];
    hfvis_visfield_object ob;
    double lo[3], hi[3], sum = 0.0, rms = 0.0;
    int f, i, j, q, a, mism = 0, both = 0;
    size_t p = 0;
    for (f = 0; f < 3; f++)
        for (j = 0; j < NC; j++)
            for (i = 0; i < NC; i++, p++) {
                double u = L * i / (NC - 1), v = L * j / (NC - 1);
                float x[3], n[3] = {0.0f, 0.0f, 0.0f};
                if (f == 0) { x[0] = (float)u; x[1] = (float)v; x[2] = 0.0f; n[2] = 1.0f; }
                else if (f == 1) { x[0] = 0.0f; x[1] = (float)u; x[2] = (float)v; n[0] = 1.0f; }
                else { x[0] = (float)u; x[1] = 0.0f; x[2] = (float)v; n[1] = 1.0f; }
                for (a = 0; a < 3; a++) {
                    pts[3 * p + a] = x[a];
                    nrm[3 * p + a] = n[a];
                }
            }
    ob.field = vf;
    ob.mesh = mesh;
    ob.bvh = bvh;
    for (i = 0; i < 16; i++) ob.object_to_world[i] = (i % 5 == 0) ? 1.0 : 0.0;
    for (a = 0; a < 3; a++) ob.object_to_world[12 + a] = T[a];
    hfvis_visfield_ambient_occlusion(&ob, 1, pts, nrm, P, NULL, fast);
    hfvis_visfield_ambient_occlusion_reference(&ob, 1, pts, nrm, P, NULL, ref);
    for (p = 0; p < P; p++) {
        double d = 255.0 * ((double)fast[p] - (double)ref[p]);
        rms += d * d;
    }
    hfvis_mesh_bounds(mesh, lo, hi);
    bench_vf_rng = 777;
    for (q = 0; q < RAYS; q++) {
        double o[3], d[3], e[3], len, z = 2.0 * bench_vf_unit() - 1.0, ph = 6.283185307179586 * bench_vf_unit();
        hfvis_visfield_hit h, x;
        e[0] = sqrt(1.0 - z * z) * cos(ph);
        e[1] = sqrt(1.0 - z * z) * sin(ph);
        e[2] = z;
        for (a = 0; a < 3; a++) {
            o[a] = vf->center[a] + 3.0 * vf->radius * e[a];
            d[a] = lo[a] + (hi[a] - lo[a]) * bench_vf_unit() - o[a];
        }
        len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (a = 0; a < 3; a++) d[a] /= len;
        hfvis_visfield_query(vf, o, d, 0.0, &h);
        hfvis_visfield_query_reference(vf, mesh, bvh, o, d, 0.0, &x);
        if ((h.result == HFVIS_VISFIELD_HIT) != (x.result == HFVIS_VISFIELD_HIT)) mism++;
        else if (h.result == HFVIS_VISFIELD_HIT) {
            sum += fabs(h.distance - x.distance) / vf->radius;
            both++;
        }
    }
    out[0] = (double)mism / RAYS;
    out[1] = both ? sum / both : 0.0;
    out[2] = sqrt(rms / P);
}

/* The thesis' Fig. 35 grid: build seconds / hit-miss disagreement % / mean |dd|/R / AO RMS x 255. */
static void bench_vf_table(const char *name, const hfvis_mesh *mesh, const double T[3], double L,
                           const double *center, double radius)
{
    static const int ns[4] = {4, 8, 16, 32}, Ds[4] = {32, 64, 128, 256};
    hfvis_bvh bvh;
    int a, b;
    if (hfvis_bvh_build(mesh, NULL, &bvh) != HFVIS_OK) return;
    printf("\n%s (%zu triangles) in a corner, 3 x 33 x 33 receivers x 256 rays; 20000 outside rays\n"
           "cell: build s / hit-miss disagreement %% / mean |d - d_exact|/R / AO RMS x 255\n%6s",
           name, mesh->triangle_count, "K \\ D");
    for (b = 0; b < 4; b++) printf("  %21d x %-5d", Ds[b], Ds[b]);
    printf("\n");
    for (a = 0; a < 4; a++) {
        printf("%6zu", hfvis_visfield_position_count(ns[a]));
        for (b = 0; b < 4; b++) {
            hfvis_visfield vf;
            hfvis_visfield_build_options bo;
            double t0, dt, e[3];
            double rays = (double)hfvis_visfield_position_count(ns[a]) * Ds[b] * Ds[b];
            if (rays > 3e7) { printf("  %29s", "(skipped: > 30 M rays)"); continue; }
            if (!bench_vf_field(mesh, ns[a], Ds[b], HFVIS_VISFIELD_U8, &vf)) continue;
            if (center) {
                memcpy(vf.center, center, sizeof vf.center);
                vf.radius = radius;
            }
            memset(&bo, 0, sizeof bo);
            bo.bvh = &bvh;
            t0 = bench_now();
            hfvis_visfield_build(mesh, &bo, &vf);
            dt = bench_now() - t0;
            bench_vf_errors(mesh, &bvh, &vf, T, L, e);
            printf("  %6.2f / %5.2f%% / %.4f / %5.2f", dt, 100.0 * e[0], e[1], e[2]);
            fflush(stdout);
            free(vf.maps);
        }
        printf("\n");
    }
    hfvis_bvh_free(NULL, &bvh);
}

/* The thesis' Fig. 33/34/36 comparisons: direction mapping and storage format at one (K, D),
 * AO RMS x 255 on the corner and outside-ray errors. */
static void bench_vf_variants(const hfvis_mesh *mesh, const double T[3], double L, int n, int D)
{
    static const char *const mname[4] = {"", "polar", "rejection", "concentric"};
    static const char *const fname[5] = {"", "u8", "f32", "bit", "normal"};
    hfvis_bvh bvh;
    int m, f;
    if (hfvis_bvh_build(mesh, NULL, &bvh) != HFVIS_OK) return;
    printf("\nteapot, K = %zu, D = %d: mapping x format, cell: hit-miss %% / mean |dd|/R / AO RMS x 255\n%11s",
           hfvis_visfield_position_count(n), D, "");
    for (f = 1; f <= 4; f++) printf("  %24s", fname[f]);
    printf("\n");
    for (m = 1; m <= 3; m++) {
        printf("%11s", mname[m]);
        for (f = 1; f <= 4; f++) {
            hfvis_visfield vf;
            hfvis_visfield_build_options bo;
            double e[3];
            if (!bench_vf_field(mesh, n, D, (hfvis_visfield_format)f, &vf)) continue;
            vf.mapping = (hfvis_dirmap)m;
            memset(&bo, 0, sizeof bo);
            bo.bvh = &bvh;
            hfvis_visfield_build(mesh, &bo, &vf);
            bench_vf_errors(mesh, &bvh, &vf, T, L, e);
            printf("  %5.2f%% / %.4f / %6.2f", 100.0 * e[0], e[1], e[2]);
            fflush(stdout);
            free(vf.maps);
        }
        printf("\n");
    }
    hfvis_bvh_free(NULL, &bvh);
}

void bench_vf(int quick)
{
    const double c0[3] = {0.0, 0.0, 0.0};
    hfvis_mesh knot, teapot;
    hfvis_bvh bvh;
    hfvis_visfield vf;
    double per_bvh, per_naive, tot, q[5], ao[2];
    int n = quick ? 8 : 32, D = 32, receivers = quick ? 200 : 1000;
    printf("visibility fields ([G12] ch. 4): torus knot (2,3) 2500 x 20 = 100,000 triangles\n");
    if (hfvis_mesh_torus_knot(NULL, c0, 1.0, 2, 3, 2500, 20, &knot) != HFVIS_OK) return;
    if (hfvis_bvh_build(&knot, NULL, &bvh) != HFVIS_OK) return;
    per_bvh = bench_vf_build(&knot, n, D, 0, &tot);
    per_naive = bench_vf_build(&knot, 1, 2, 1, NULL); /* the naive caster: 40 rays x 100k tris */
    printf("build (Alg. 1), K = %zu, D = %d: %.2f s; per (position x direction) sample: BVH %.0f ns, "
           "naive oracle %.0f ns (ratio %.0f)\n", hfvis_visfield_position_count(n), D, tot,
           1e9 * per_bvh, 1e9 * per_naive, per_naive / per_bvh);
    if (!bench_vf_field(&knot, n, D, HFVIS_VISFIELD_U8, &vf)) return;
    hfvis_visfield_build(&knot, NULL, &vf);
    bench_vf_query(&knot, &bvh, &vf, receivers, q);
    printf("query (min of %d runs), %d floor receivers x 256 AO rays: field %.0f ns/ray, BVH closest hit %.0f ns/ray "
           "(ratio %.1f), BVH any hit %.0f ns/ray (ratio %.1f); hit rate field %.3f, BVH %.3f\n",
           BENCH_VF_REPS, receivers, 1e9 * q[0], 1e9 * q[1], q[1] / q[0], 1e9 * q[2], q[2] / q[0], q[3], q[4]);
    bench_vf_ao(&knot, &bvh, &vf, receivers, ao);
    printf("AO routine (256 rays per point): field %.0f ns/ray, ray-cast reference (BVH) %.0f ns/ray "
           "(ratio %.1f)\n", 1e9 * ao[0], 1e9 * ao[1], ao[1] / ao[0]);
    free(vf.maps);
    hfvis_bvh_free(NULL, &bvh);
    hfvis_mesh_free(NULL, &knot);
    if (quick) return;
    /* the error tables at the thesis' grid (Fig. 35 form) */
    if (hfvis_mesh_teapot(NULL, 4, &teapot) == HFVIS_OK) {
        const double T[3] = {1.9, 1.6, 0.0};
        bench_vf_variants(&teapot, T, 3.6, 16, 32);
        bench_vf_table("teapot", &teapot, T, 3.6, NULL, 0.0);
        hfvis_mesh_free(NULL, &teapot);
    }
    {
        const double s[3] = {0.15, -0.1, 0.12}, T[3] = {1.6, 1.6, 0.6};
        hfvis_mesh ico;
        if (hfvis_mesh_icosphere(NULL, s, 0.45, 5, &ico) == HFVIS_OK) {
            bench_vf_table("sphere (r = 0.45, centre 0.23 from c) in a field of radius 1", &ico, T, 3.2, c0, 1.0);
            hfvis_mesh_free(NULL, &ico);
        }
    }
}
