/* bench_volgi.c - volume-based VPL indirect illumination ([G12] ch. 5, Table 2 on the CPU): the
 * coloured room (hfvis_mesh_room, one point light) at 32^3, 64^3 and 128^3: voxelization with
 * direct light (Alg. 4: three sweeps, a shadow ray per fragment), VPL injection, the propagation
 * step per voxel-iteration (the number: docs/errata.md E59 kernel, the void-only / normalised
 * variant, the literal reference and the energy accounting beside it), and per 1280x720 pixel
 * the final gather (eqs. 12-15) beside the direct light with one BVH shadow ray, and the whole
 * pipeline (hfvis_volgi_render). */
#define _POSIX_C_SOURCE 199309L
#include "bench.h"
#include "hfvis.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* The scene: the room with a red (x = 0) and a green (x = 1) wall, a point light. */
typedef struct bench_volgi_scene {
    hfvis_mesh mesh;
    hfvis_bvh bvh;
    float albedo[30 * 3];
    hfvis_volgi_light light;
    hfvis_volgi_scene scene;
} bench_volgi_scene;

static int bench_volgi_scene_init(bench_volgi_scene *s)
{
    size_t t;
    memset(s, 0, sizeof *s);
    if (hfvis_mesh_room(NULL, &s->mesh) != HFVIS_OK) return 0;
    if (hfvis_bvh_build(&s->mesh, NULL, &s->bvh) != HFVIS_OK) return 0;
    for (t = 0; t < 30; t++) {
        s->albedo[3 * t] = t < 2 ? 0.75f : t < 4 ? 0.15f : 0.75f;
        s->albedo[3 * t + 1] = t < 2 ? 0.15f : 0.75f;
        s->albedo[3 * t + 2] = t < 4 ? 0.15f : 0.75f;
    }
    s->light.type = HFVIS_VOLGI_LIGHT_POINT;
    s->light.position[0] = 0.5, s->light.position[1] = 0.45, s->light.position[2] = 0.9;
    s->light.intensity[0] = s->light.intensity[1] = s->light.intensity[2] = 1.0f;
    s->scene.mesh = &s->mesh;
    s->scene.albedo = s->albedo;
    s->scene.lights = &s->light;
    s->scene.light_count = 1;
    s->scene.bvh = &s->bvh;
    return 1;
}

static void bench_volgi_scene_free(bench_volgi_scene *s)
{
    hfvis_bvh_free(NULL, &s->bvh);
    hfvis_mesh_free(NULL, &s->mesh);
}

/* The volumes of one grid: geometry (occupancy, normal, albedo), radiance, P, A, P' */
typedef struct bench_volgi_vol {
    hfvis_volume_grid grid;
    size_t n;
    float *occ, *nrm, *alb, *rad, *p0, *p, *q, *a;
} bench_volgi_vol;

static void bench_volgi_vol_free(bench_volgi_vol *v)
{
    free(v->occ), free(v->nrm), free(v->alb), free(v->rad);
    free(v->p0), free(v->p), free(v->q), free(v->a);
}

static int bench_volgi_vol_init(bench_volgi_vol *v, const hfvis_mesh *m, int res)
{
    memset(v, 0, sizeof *v);
    if (hfvis_volgi_grid_fit(m, res, &v->grid) != HFVIS_OK) return 0;
    v->n = (size_t)v->grid.dims[0] * (size_t)v->grid.dims[1] * (size_t)v->grid.dims[2];
    v->occ = (float *)malloc(v->n * sizeof(float));
    v->nrm = (float *)malloc(3 * v->n * sizeof(float));
    v->alb = (float *)malloc(3 * v->n * sizeof(float));
    v->rad = (float *)malloc(3 * v->n * sizeof(float));
    v->p0 = (float *)malloc(HFVIS_VOLGI_FLOATS * v->n * sizeof(float));
    v->p = (float *)malloc(HFVIS_VOLGI_FLOATS * v->n * sizeof(float));
    v->q = (float *)malloc(HFVIS_VOLGI_FLOATS * v->n * sizeof(float));
    v->a = (float *)calloc(HFVIS_VOLGI_FLOATS * v->n, sizeof(float));
    return v->occ && v->nrm && v->alb && v->rad && v->p0 && v->p && v->q && v->a;
}

static hfvis_volgi_geometry bench_volgi_geo(const bench_volgi_vol *v)
{
    hfvis_volgi_geometry g;
    g.grid = v->grid;
    g.occupancy = v->occ;
    g.normal = v->nrm;
    g.albedo = v->alb;
    return g;
}

/* Timed work: each returns the seconds of one run (negative on failure). */
static double bench_volgi_voxelize(const hfvis_volgi_scene *sc, bench_volgi_vol *v, size_t *frags)
{
    double t0 = bench_now();
    if (hfvis_volgi_voxelize(sc, &v->grid, NULL, v->occ, v->nrm, v->alb, v->rad, frags) != HFVIS_OK)
        return -1.0;
    return bench_now() - t0;
}

static double bench_volgi_inject(bench_volgi_vol *v)
{
    hfvis_volgi_geometry g = bench_volgi_geo(v);
    double t0 = bench_now();
    if (hfvis_volgi_inject(&g, v->rad, v->p0) != HFVIS_OK) return -1.0;
    return bench_now() - t0;
}

/* `iterations` steps of the loop (one scratch allocation, inputs checked once) */
static double bench_volgi_propagate(bench_volgi_vol *v, const hfvis_volgi_options *o, int iterations)
{
    hfvis_volgi_geometry g = bench_volgi_geo(v);
    double t0;
    memcpy(v->p, v->p0, HFVIS_VOLGI_FLOATS * v->n * sizeof(float));
    memset(v->a, 0, HFVIS_VOLGI_FLOATS * v->n * sizeof(float));
    t0 = bench_now();
    if (hfvis_volgi_propagate(&g, o, iterations, v->p, v->a, NULL) != HFVIS_OK) return -1.0;
    return bench_now() - t0;
}

/* one step, fast or reference, optionally with the energy accounting (includes the O(voxels)
 * argument checks of the single-step entry points) */
static double bench_volgi_step(bench_volgi_vol *v, const hfvis_volgi_options *o, int reference,
                               int energy)
{
    hfvis_volgi_geometry g = bench_volgi_geo(v);
    hfvis_volgi_energy e;
    double t0 = bench_now();
    hfvis_status s = reference
        ? hfvis_volgi_propagate_step_reference(&g, o, v->p0, v->q, v->a, energy ? &e : NULL)
        : hfvis_volgi_propagate_step(&g, o, v->p0, v->q, v->a, energy ? &e : NULL);
    if (s != HFVIS_OK) return -1.0;
    return bench_now() - t0;
}

/* per pixel: gather (eqs. 12-15) at the G-buffer's surface points, or the direct light */
static double bench_volgi_pixels(const bench_volgi_scene *s, const bench_volgi_vol *v,
                                 const double *pts, size_t count, int direct, double *sum)
{
    hfvis_volgi_geometry g = bench_volgi_geo(v);
    double t0 = bench_now(), acc = 0.0;
    size_t i;
    for (i = 0; i < count; i++) {
        float E[3];
        hfvis_status st = direct
            ? hfvis_volgi_direct_irradiance(&s->scene, NULL, pts + 6 * i, pts + 6 * i + 3,
                                            HFVIS_NO_TRIANGLE, E)
            : hfvis_volgi_gather(&g, v->a, NULL, pts + 6 * i, pts + 6 * i + 3, E);
        if (st != HFVIS_OK) return -1.0;
        acc += (double)E[0];
    }
    *sum = acc;
    return bench_now() - t0;
}

static double bench_volgi_render(const hfvis_volgi_scene *sc, const hfvis_view *view, int res,
                                 int iterations, float *img)
{
    hfvis_volgi_options o = hfvis_volgi_options_default();
    hfvis_volgi_outputs out;
    double t0;
    o.resolution = res;
    o.iterations = iterations;
    out.direct = NULL, out.indirect = NULL, out.total = img;
    t0 = bench_now();
    if (hfvis_volgi_render(sc, NULL, view, &o, &out, NULL) != HFVIS_OK) return -1.0;
    return bench_now() - t0;
}

static void bench_volgi_row(const char *grid, const char *what, double s, double units,
                            const char *unit, const char *note)
{
    printf("%-6s %-46s %10.2f %9.2f %-16s %s\n", grid, what, 1e3 * s, 1e9 * s / units, unit,
           note ? note : "");
}

/* min over reps of a timed expression */
#define BENCH_VOLGI_MIN(var, reps, expr) \
    do { int r_; var = 1e30; for (r_ = 0; r_ < (reps); r_++) { double t_ = (expr); \
         if (t_ >= 0.0 && t_ < var) var = t_; } } while (0)

void bench_volgi(int quick)
{
    enum { W = 1280, H = 720 };
    static const int res_list[3] = { 32, 64, 128 };
    const int nres = 3, reps = quick ? 1 : 3;
    bench_volgi_scene s;
    bench_volgi_vol v;
    hfvis_view view;
    hfvis_raster_outputs ro;
    const double eye[3] = { 0.5, -1.1, 0.5 }, at[3] = { 0.5, 0.5, 0.45 }, up[3] = { 0, 0, 1 };
    float *nrm = NULL, *bary = NULL, *img = NULL;
    uint32_t *tri = NULL;
    double *pts = NULL;
    size_t npts = 0, px;
    int ri;
    memset(&v, 0, sizeof v);
    if (!bench_volgi_scene_init(&s)) {
        printf("bench_volgi: scene setup failed\n");
        return;
    }
    printf("\nVolume-based VPL indirect light ([G12] ch. 5, Table 2 analogue): the room (%zu triangles),"
           " one point light, grid from hfvis_volgi_grid_fit%s\n", s.mesh.triangle_count,
           quick ? " (quick)" : "");
    printf("%-6s %-46s %10s %9s %-16s %s\n", "grid", "step", "ms", "ns/unit", "unit", "notes");
    for (ri = 0; ri < nres; ri++) {
        const int res = res_list[ri];
        /* iterations per timing: enough for a stable time, bounded at 128^3 */
        const int iters = quick ? (res >= 128 ? 2 : 8) : (res >= 128 ? 8 : res >= 64 ? 32 : 64);
        hfvis_volgi_options o = hfvis_volgi_options_default();
        char gname[16], note[160];
        double t_vox, t_inj, t_prop, t_void, t_norm, t_step, t_ref, t_en, vi, vox;
        size_t frags = 0, occ = 0, i;
        if (!bench_volgi_vol_init(&v, &s.mesh, res)) {
            printf("bench_volgi: out of memory at %d^3\n", res);
            bench_volgi_vol_free(&v);
            break;
        }
        sprintf(gname, "%d^3", res);
        vox = (double)v.n;
        BENCH_VOLGI_MIN(t_vox, reps, bench_volgi_voxelize(&s.scene, &v, &frags));
        for (i = 0; i < v.n; i++) occ += v.occ[i] > 0.0f;
        sprintf(note, "%zu fragments, %zu occupied; %.0f ns/fragment", frags, occ,
                1e9 * t_vox / (double)(frags ? frags : 1));
        bench_volgi_row(gname, "voxelize + direct light (Alg. 4, 3 sweeps)", t_vox, vox, "voxel", note);
        BENCH_VOLGI_MIN(t_inj, reps, bench_volgi_inject(&v));
        bench_volgi_row(gname, "inject VPLs ([G12] ch. 5)", t_inj, vox, "voxel", NULL);
        vi = vox * (double)iters;
        BENCH_VOLGI_MIN(t_prop, reps, bench_volgi_propagate(&v, &o, iters));
        sprintf(note, "%d iterations; %.1f ms per 64", iters, 1e3 * t_prop * 64.0 / iters);
        bench_volgi_row(gname, "propagate, docs/errata.md E59 kernel (ALL/CONE)", t_prop, vi, "voxel-iteration", note);
        o.paths = HFVIS_VOLGI_PATHS_VOID;
        BENCH_VOLGI_MIN(t_void, reps, bench_volgi_propagate(&v, &o, iters));
        bench_volgi_row(gname, "propagate, void-only paths (VOID/CONE)", t_void, vi, "voxel-iteration", NULL);
        o.transfer = HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED;
        BENCH_VOLGI_MIN(t_norm, reps, bench_volgi_propagate(&v, &o, iters));
        bench_volgi_row(gname, "propagate, VOID/NORMALIZED (+ scale pass)", t_norm, vi, "voxel-iteration", NULL);
        o = hfvis_volgi_options_default();
        BENCH_VOLGI_MIN(t_step, reps, bench_volgi_step(&v, &o, 0, 0));
        bench_volgi_row(gname, "one step (hfvis_volgi_propagate_step)", t_step, vox, "voxel-iteration",
                        "incl. the per-call O(voxels) input checks");
        BENCH_VOLGI_MIN(t_en, reps, bench_volgi_step(&v, &o, 0, 1));
        sprintf(note, "accounting costs %.2fx", t_en / t_step);
        bench_volgi_row(gname, "one step + energy accounting", t_en, vox, "voxel-iteration", note);
        BENCH_VOLGI_MIN(t_ref, quick && res >= 128 ? 0 : 1, bench_volgi_step(&v, &o, 1, 0));
        if (t_ref < 1e29) {
            sprintf(note, "reference / fast = %.2f", t_ref / t_step);
            bench_volgi_row(gname, "one step, literal reference (oracle)", t_ref, vox, "voxel-iteration", note);
        }
        sprintf(note, "thesis GTX 285: 61 ms for 64 iterations at 32^3 = 29 ns");
        if (res == 32) bench_volgi_row(gname, "(Table 2, room: 64 iterations)", t_prop * 64.0 / iters,
                                       vox * 64.0, "voxel-iteration", note);
        /* per pixel, at 64^3 (the grid of the thesis' Fig. 49) after 64 iterations */
        if (res == 64) {
            double t_g, t_d, sum = 0.0, t_r;
            hfvis_volgi_options d = hfvis_volgi_options_default();
            (void)bench_volgi_propagate(&v, &d, 64);
            nrm = (float *)malloc(3 * (size_t)W * H * sizeof(float));
            bary = (float *)malloc(2 * (size_t)W * H * sizeof(float));
            tri = (uint32_t *)malloc((size_t)W * H * sizeof(uint32_t));
            pts = (double *)malloc(6 * (size_t)W * H * sizeof(double));
            img = (float *)malloc(3 * (size_t)W * H * sizeof(float));
            if (!nrm || !bary || !tri || !pts || !img
                || hfvis_view_perspective(&view, eye, at, up, 40.0 * 3.14159265358979323846 / 180.0, W, H,
                                          0.1, 10.0) != HFVIS_OK) {
                bench_volgi_vol_free(&v);
                break;
            }
            memset(&ro, 0, sizeof ro);
            ro.normal = nrm, ro.barycentric = bary, ro.triangle_id = tri;
            if (hfvis_rasterize(&s.mesh, &view, NULL, &ro) != HFVIS_OK) {
                bench_volgi_vol_free(&v);
                break;
            }
            for (px = 0; px < (size_t)W * H; px++) {
                const uint32_t *ix;
                double b1, b2;
                int k;
                if (tri[px] == HFVIS_NO_TRIANGLE) continue;
                ix = s.mesh.indices + 3 * (size_t)tri[px];
                b1 = (double)bary[2 * px], b2 = (double)bary[2 * px + 1];
                for (k = 0; k < 3; k++) {
                    pts[6 * npts + (size_t)k] = (1.0 - b1 - b2) * (double)s.mesh.xyz[3 * (size_t)ix[0] + (size_t)k]
                                                + b1 * (double)s.mesh.xyz[3 * (size_t)ix[1] + (size_t)k]
                                                + b2 * (double)s.mesh.xyz[3 * (size_t)ix[2] + (size_t)k];
                    pts[6 * npts + 3 + (size_t)k] = (double)nrm[3 * px + (size_t)k];
                }
                npts++;
            }
            BENCH_VOLGI_MIN(t_g, reps, bench_volgi_pixels(&s, &v, pts, npts, 0, &sum));
            BENCH_VOLGI_MIN(t_d, reps, bench_volgi_pixels(&s, &v, pts, npts, 1, &sum));
            sprintf(note, "%zu covered pixels of %dx%d; gather / shadow ray = %.2f", npts, W, H, t_g / t_d);
            bench_volgi_row(gname, "gather per pixel (eqs. 12-15, 8 voxels)", t_g, (double)npts, "pixel", note);
            bench_volgi_row(gname, "baseline: direct light, 1 BVH shadow ray", t_d, (double)npts, "pixel", NULL);
            BENCH_VOLGI_MIN(t_r, quick ? 1 : 2, bench_volgi_render(&s.scene, &view, 64, 64, img));
            sprintf(note, "G-buffer + Alg. 4 + inject + 64 iterations + shading");
            bench_volgi_row(gname, "hfvis_volgi_render 1280x720, 64 iterations", t_r, (double)W * H, "pixel", note);
        }
        bench_volgi_vol_free(&v);
        memset(&v, 0, sizeof v);
    }
    printf("thesis Table 2 (GTX 285, 32^3): room 704 triangles, 64 iterations: voxelization 3 ms, "
           "propagation 61 ms; \"higher grid sizes are prohibitive\"\n");
    free(nrm), free(bary), free(tri), free(pts), free(img);
    bench_volgi_scene_free(&s);
}
