/* test_volgi.c - volume-based VPL indirect illumination ([G12] ch. 5): the SH
 * constants, the closed-form first-step fluxes, the mirror and closed-box cases, fast step ==
 * literal reference bit for bit, energy accounting per iteration, gather, direct light, Alg. 4,
 * the coloured room (colour bleeding, convergence), the pipeline, bad arguments, allocation
 * failures. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "hfvis.h"
#include "test.h"

#define PI 3.14159265358979323846
#define SQRT2 1.41421356237309504880

/* Tolerances */
#define TOL_EXACT 1e-12       /* double closed forms of the SH helpers (a few roundings) */
#define TOL_SPEC7 6e-8        /* constants quoted with 7 decimals */
#define TOL_QUAD_CC 2e-4      /* 1000 x 2000 midpoint quadrature of a clamped cosine (kink) */
#define TOL_QUAD_CONE 3e-3    /* the same quadrature of a cone indicator (discontinuous) */
#define TOL_FLOAT 2e-6        /* values stored in float, a few roundings (relative) */
#define TOL_ENERGY 2e-5       /* energy identity over a whole volume of float values (relative) */
#define TOL_CONVERGED 1e-4    /* room, CONE transfer: relative change from 256 to 512 steps (the
                                 cone gap loses >= 1.8 % per step: converged after ~100 steps) */
#define TOL_CONVERGED_NORM 3e-2 /* the same with the energy-conserving transfer: light is lost only
                                   at surfaces (rho = 0.5) and through the open front, so it
                                   decays much more slowly (0.8-2.7 % gained from 256 to 512) */
#define TOL_REMAINING 1e-3    /* flux still travelling after 512 steps, relative to the injected */

/* ---- helpers ---------------------------------------------------------------------------- */

static uint64_t rng_state;
static uint64_t rng_next(void)
{
    uint64_t z = (rng_state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}
static double rng_unit(void) { return (double)(rng_next() >> 11) * (1.0 / 9007199254740992.0); }

/* A geometry volume with owned arrays. */
typedef struct tg {
    hfvis_volume_grid grid;
    float *occ, *nrm, *alb;
    size_t n;
} tg;

static void tg_init(tg *t, int nx, int ny, int nz, double cx, double cy, double cz)
{
    memset(t, 0, sizeof *t);
    t->grid.dims[0] = nx, t->grid.dims[1] = ny, t->grid.dims[2] = nz;
    t->grid.cell[0] = cx, t->grid.cell[1] = cy, t->grid.cell[2] = cz;
    t->n = (size_t)nx * (size_t)ny * (size_t)nz;
    t->occ = (float *)calloc(t->n, sizeof(float));
    t->nrm = (float *)calloc(3 * t->n, sizeof(float));
    t->alb = (float *)calloc(3 * t->n, sizeof(float));
}
static void tg_free(tg *t)
{
    free(t->occ);
    free(t->nrm);
    free(t->alb);
}
static hfvis_volgi_geometry tg_geo(const tg *t, int with_albedo)
{
    hfvis_volgi_geometry g;
    g.grid = t->grid;
    g.occupancy = t->occ;
    g.normal = t->nrm;
    g.albedo = with_albedo ? t->alb : NULL;
    return g;
}
static size_t lin3(const hfvis_volume_grid *g, int i, int j, int k)
{
    return ((size_t)k * (size_t)g->dims[1] + (size_t)j) * (size_t)g->dims[0] + (size_t)i;
}
static void tg_set(tg *t, int i, int j, int k, float occ, double nx, double ny, double nz)
{
    size_t v = lin3(&t->grid, i, j, k);
    t->occ[v] = occ;
    t->nrm[3 * v] = (float)nx, t->nrm[3 * v + 1] = (float)ny, t->nrm[3 * v + 2] = (float)nz;
}

/* p[0..11] = (flux_b/pi) CC(n) per band */
static void set_lobe(float *p, double nx, double ny, double nz, const double flux[3])
{
    double n[3], cc[4];
    int b, k;
    n[0] = nx, n[1] = ny, n[2] = nz;
    hfvis_volgi_sh_clamped_cosine(n, cc);
    for (b = 0; b < 3; b++)
        for (k = 0; k < 4; k++) p[4 * b + k] = (float)(flux[b] / PI * cc[k]);
}
static double flux_of(const float *p, int b) { return 2.0 * sqrt(PI) * (double)p[4 * b]; }

static float *sh_alloc(size_t n) { return (float *)calloc(n * HFVIS_VOLGI_FLOATS, sizeof(float)); }

/* The coloured room: hfvis_mesh_room with a red wall at x = 0 (triangles 0, 1), a green wall at
 * x = 1 (2, 3), everything else white 0.75; a point light under the ceiling. */
typedef struct room {
    hfvis_mesh mesh;
    float albedo[30 * 3];
    hfvis_volgi_light light;
    hfvis_volgi_scene scene;
    hfvis_bvh bvh;
} room;

static void room_init(room *r)
{
    size_t t;
    memset(r, 0, sizeof *r);
    CHECK_EQ_STATUS(hfvis_mesh_room(NULL, &r->mesh), HFVIS_OK);
    for (t = 0; t < 30; t++) {
        float c[3] = { 0.75f, 0.75f, 0.75f };
        if (t < 2) c[0] = 0.75f, c[1] = 0.15f, c[2] = 0.15f;
        else if (t < 4) c[0] = 0.15f, c[1] = 0.75f, c[2] = 0.15f;
        memcpy(r->albedo + 3 * t, c, sizeof c);
    }
    r->light.type = HFVIS_VOLGI_LIGHT_POINT;
    r->light.position[0] = 0.5, r->light.position[1] = 0.45, r->light.position[2] = 0.9;
    r->light.intensity[0] = r->light.intensity[1] = r->light.intensity[2] = 1.0f;
    CHECK_EQ_STATUS(hfvis_bvh_build(&r->mesh, NULL, &r->bvh), HFVIS_OK);
    r->scene.mesh = &r->mesh;
    r->scene.albedo = r->albedo;
    r->scene.lights = &r->light;
    r->scene.light_count = 1;
    r->scene.bvh = &r->bvh;
}
static void room_free(room *r)
{
    hfvis_bvh_free(NULL, &r->bvh);
    hfvis_mesh_free(NULL, &r->mesh);
}

/* Voxelize the room into t (grid from hfvis_volgi_grid_fit) and inject into *prop (allocated). */
static void room_volume(room *r, int res, tg *t, float **prop, float **rad)
{
    hfvis_volume_grid g;
    hfvis_volgi_geometry geo;
    CHECK_EQ_STATUS(hfvis_volgi_grid_fit(&r->mesh, res, &g), HFVIS_OK);
    tg_init(t, g.dims[0], g.dims[1], g.dims[2], g.cell[0], g.cell[1], g.cell[2]);
    t->grid = g;
    *rad = (float *)calloc(3 * t->n, sizeof(float));
    *prop = sh_alloc(t->n);
    CHECK_EQ_STATUS(hfvis_volgi_voxelize(&r->scene, &g, NULL, t->occ, t->nrm, t->alb, *rad, NULL),
                    HFVIS_OK);
    geo = tg_geo(t, 1);
    CHECK_EQ_STATUS(hfvis_volgi_inject(&geo, *rad, *prop), HFVIS_OK);
}

/* ---- GI.1 SH constants ----------------------------------------------------------------- */

TEST(volgi_sh_constants)
{
    const double z[3] = { 0, 0, 1 }, x[3] = { 1, 0, 0 }, z2[3] = { 0, 0, 5 };
    double cc[4], cz[4], cx[4], b[4], Y[16], d = 0.0, d2 = 0.0, self = 0.0;
    int k, t;
    CHECK_EQ_STATUS(hfvis_volgi_sh_clamped_cosine(z2, cc), HFVIS_OK);
    CHECK_NEAR(cc[0], 0.8862269254527580, TOL_EXACT, 0);   /* sqrt(pi)/2 */
    CHECK_NEAR(cc[2], 1.0233267079464885, TOL_EXACT, 0);   /* sqrt(pi/3) */
    CHECK(cc[1] == 0.0 && cc[3] == 0.0);
    CHECK_NEAR(2.0 * sqrt(PI) * cc[0], PI, TOL_EXACT, 0);   /* Int CC = pi */
    for (k = 0; k < 4; k++) self += cc[k] * cc[k];
    CHECK_NEAR(self, 7.0 * PI / 12.0, TOL_EXACT, 0);       /* 0.583 pi instead of 2 pi/3 */
    CHECK_EQ_STATUS(hfvis_volgi_sh_cone(z, 0.25 * PI, cz), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_volgi_sh_cone(x, 0.25 * PI, cx), HFVIS_OK);
    CHECK_NEAR(cz[0], 0.5191397, TOL_SPEC7, 0);
    CHECK_NEAR(cz[2], 0.7674950, TOL_SPEC7, 0);
    CHECK_NEAR(cx[3], 0.7674950, TOL_SPEC7, 0);
    CHECK_NEAR(cz[0], sqrt(PI) * (1.0 - sqrt(0.5)), TOL_EXACT, 0);
    CHECK_NEAR(cz[2], sqrt(3.0 * PI) / 4.0, TOL_EXACT, 0);
    for (k = 0; k < 4; k++) d += cc[k] * cz[k], d2 += cc[k] * cx[k];
    CHECK_NEAR(d, 1.2454738, TOL_SPEC7, 0);
    CHECK_NEAR(d2, 0.4600756, TOL_SPEC7, 0);
    /* the whole sphere: sqrt(pi)*2 = 2 sqrt(pi) Y00-integral, band 1 vanishes */
    CHECK_EQ_STATUS(hfvis_volgi_sh_cone(z, PI, cz), HFVIS_OK);
    CHECK_NEAR(cz[0], 2.0 * sqrt(PI), TOL_EXACT, 0);
    CHECK_NEAR(cz[2], 0.0, TOL_EXACT, 0);
    /* the basis is the first four values of hfvis_sh_eval (the hfvis.h convention) */
    rng_state = 11;
    for (t = 0; t < 20; t++) {
        double dir[3];
        dir[0] = rng_unit() - 0.5, dir[1] = rng_unit() - 0.5, dir[2] = rng_unit() - 0.5;
        CHECK_EQ_STATUS(hfvis_volgi_sh_basis(dir, b), HFVIS_OK);
        {
            double l = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]), u[3];
            u[0] = dir[0] / l, u[1] = dir[1] / l, u[2] = dir[2] / l;
            CHECK_EQ_STATUS(hfvis_sh_eval(u, Y), HFVIS_OK);
        }
        for (k = 0; k < 4; k++) CHECK_NEAR(b[k], Y[k], TOL_EXACT, 0);
    }
    /* Y_1,-1 = +0.4886 y: the +y direction has a positive coefficient 1 */
    {
        const double y[3] = { 0, 1, 0 };
        hfvis_volgi_sh_basis(y, b);
        CHECK_NEAR(b[1], 0.4886025119029199, TOL_EXACT, 0);
        CHECK(b[2] == 0.0 && b[3] == 0.0);
    }
}

/* The projections against numerical quadrature over the sphere (midpoint rule in theta, phi). */
TEST(volgi_sh_projection_quadrature)
{
    enum { NT = 1000, NP = 2000 };
    double n[3], cc[4], cone[4], qcc[4] = { 0, 0, 0, 0 }, qcone[4] = { 0, 0, 0, 0 }, half, cosa;
    int i, j, k;
    n[0] = 0.3, n[1] = -0.5, n[2] = 0.81;
    half = 0.7;
    hfvis_volgi_sh_clamped_cosine(n, cc);
    hfvis_volgi_sh_cone(n, half, cone);
    {
        double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        n[0] /= l, n[1] /= l, n[2] /= l;
    }
    cosa = cos(half);
    for (i = 0; i < NT; i++) {
        double th = (i + 0.5) * PI / NT, st = sin(th), ct = cos(th);
        double dw = st * (PI / NT) * (2.0 * PI / NP);
        for (j = 0; j < NP; j++) {
            double ph = (j + 0.5) * 2.0 * PI / NP, w[3], Y[4], c;
            w[0] = st * cos(ph), w[1] = st * sin(ph), w[2] = ct;
            hfvis_volgi_sh_basis(w, Y);
            c = n[0] * w[0] + n[1] * w[1] + n[2] * w[2];
            for (k = 0; k < 4; k++) {
                if (c > 0.0) qcc[k] += c * Y[k] * dw;
                if (c >= cosa) qcone[k] += Y[k] * dw;
            }
        }
    }
    for (k = 0; k < 4; k++) {
        CHECK_NEAR(cc[k], qcc[k], TOL_QUAD_CC, 0);
        CHECK_NEAR(cone[k], qcone[k], TOL_QUAD_CONE, 0);
    }
}

/* ---- GI.3 injection ------------------------------------------------------------------ */

/* The 2-band helpers are bands 0-1 of the order-4 SH API (hfvis.h, "2-band SH helpers"). */
#define VOLGI_SH_AGREE 1e-14 /* two evaluation orders of the same closed forms, a few ulps apart */
TEST(volgi_sh_is_bands_0_1)
{
    const double dirs[4][3] = {{0.3, -0.5, 0.8}, {0.0, 0.0, -2.0}, {-1.0, 4.0, 0.5}, {7.0, 0.1, 0.0}};
    const double angles[3] = {0.2, 0.25 * PI, 2.5};
    double Y[16], S[16], Ahat[4], v[4];
    int d, a, i;
    for (d = 0; d < 4; d++) {
        double len = sqrt(dirs[d][0] * dirs[d][0] + dirs[d][1] * dirs[d][1] + dirs[d][2] * dirs[d][2]);
        double u[3];
        for (i = 0; i < 3; i++) u[i] = dirs[d][i] / len;
        CHECK_EQ_STATUS(hfvis_sh_eval(u, Y), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_volgi_sh_basis(dirs[d], v), HFVIS_OK);
        for (i = 0; i < 4; i++) CHECK_NEAR(v[i], Y[i], VOLGI_SH_AGREE, VOLGI_SH_AGREE);
        CHECK_EQ_STATUS(hfvis_zh_diffuse(Ahat), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_sh_from_zh(Ahat, dirs[d], S), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_volgi_sh_clamped_cosine(dirs[d], v), HFVIS_OK);
        for (i = 0; i < 4; i++) CHECK_NEAR(v[i], S[i], VOLGI_SH_AGREE, VOLGI_SH_AGREE);
        for (a = 0; a < 3; a++) {
            CHECK_EQ_STATUS(hfvis_zh_cap(angles[a], Ahat), HFVIS_OK);
            CHECK_EQ_STATUS(hfvis_sh_from_zh(Ahat, dirs[d], S), HFVIS_OK);
            CHECK_EQ_STATUS(hfvis_volgi_sh_cone(dirs[d], angles[a], v), HFVIS_OK);
            for (i = 0; i < 4; i++) CHECK_NEAR(v[i], S[i], VOLGI_SH_AGREE, VOLGI_SH_AGREE);
        }
    }
}

TEST(volgi_inject)
{
    tg t;
    hfvis_volgi_geometry geo;
    float *p, *rad;
    double cc[4];
    const double up[3] = { 0, 0, 1 }, px[3] = { 1, 0, 0 };
    size_t v, c, w;
    int b, k;
    tg_init(&t, 3, 3, 3, 0.5, 0.5, 0.5);
    p = sh_alloc(t.n);
    rad = (float *)calloc(3 * t.n, sizeof(float));
    for (v = 0; v < 12 * t.n; v++) p[v] = 7.0f; /* every value is written */
    c = lin3(&t.grid, 1, 1, 1);
    w = lin3(&t.grid, 0, 2, 1);
    tg_set(&t, 1, 1, 1, 1.0f, 0, 0, 2);  /* a non-unit normal */
    tg_set(&t, 0, 2, 1, 0.5f, 0, 0, 0);  /* no normal: isotropic */
    rad[3 * c] = 1.0f, rad[3 * c + 1] = 2.0f, rad[3 * c + 2] = 3.0f;
    rad[3 * w] = rad[3 * w + 1] = rad[3 * w + 2] = 1.0f;
    rad[3 * lin3(&t.grid, 2, 2, 2)] = 5.0f; /* unoccupied: no VPL */
    geo = tg_geo(&t, 0);
    CHECK_EQ_STATUS(hfvis_volgi_inject(&geo, rad, p), HFVIS_OK);
    hfvis_volgi_sh_clamped_cosine(up, cc);
    for (b = 0; b < 3; b++) {
        for (k = 0; k < 4; k++)
            CHECK_NEAR(p[12 * c + 4 * (size_t)b + (size_t)k], (b + 1) * 0.25 * cc[k], 0, TOL_FLOAT);
        CHECK_NEAR(flux_of(p + 12 * c, b), PI * (b + 1) * 0.25, 0, TOL_FLOAT); /* pi L s^2 */
        CHECK_NEAR(flux_of(p + 12 * w, b), PI * 0.25, 0, TOL_FLOAT);
        CHECK(p[12 * w + 4 * (size_t)b + 1] == 0.0f && p[12 * w + 4 * (size_t)b + 2] == 0.0f
              && p[12 * w + 4 * (size_t)b + 3] == 0.0f);
    }
    for (v = 0; v < t.n; v++)
        if (v != c && v != w)
            for (k = 0; k < 12; k++) CHECK(p[12 * v + (size_t)k] == 0.0f);
    tg_free(&t);
    /* anisotropic voxels: the face perpendicular to the normal's dominant axis */
    tg_init(&t, 2, 1, 1, 0.5, 1.0, 2.0);
    tg_set(&t, 0, 0, 0, 1.0f, 1, 0.2, 0);
    hfvis_volgi_sh_clamped_cosine(px, cc);
    rad[0] = rad[1] = rad[2] = 1.0f;
    geo = tg_geo(&t, 0);
    CHECK_EQ_STATUS(hfvis_volgi_inject(&geo, rad, p), HFVIS_OK);
    CHECK_NEAR(flux_of(p, 0), PI * 2.0, 0, TOL_FLOAT);
    tg_free(&t);
    free(p);
    free(rad);
}

/* ---- GI.4 closed-form first step ([G12] ch. 5, eq. 11; docs/errata.md E59) --------------------------------- */

static void first_step(hfvis_volgi_transfer tr)
{
    const double flux[3] = { 1.0, 2.0, 0.5 };
    const double fwd = (3.0 - SQRT2) / 4.0, side = (2.0 - SQRT2) / 4.0, tot = (11.0 - 5.0 * SQRT2) / 4.0;
    const double norm = tr == HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED ? 1.0 / tot : 1.0;
    tg t;
    hfvis_volgi_geometry geo;
    hfvis_volgi_options o = hfvis_volgi_options_default();
    hfvis_volgi_energy e;
    float *p, *q, *a;
    size_t v;
    int b, d;
    tg_init(&t, 5, 5, 5, 1, 1, 1);
    p = sh_alloc(t.n), q = sh_alloc(t.n), a = sh_alloc(t.n);
    set_lobe(p + 12 * lin3(&t.grid, 2, 2, 2), 0, 0, 1, flux);
    geo = tg_geo(&t, 0);
    o.transfer = tr;
    CHECK_EQ_STATUS(hfvis_volgi_propagate_step(&geo, &o, p, q, a, &e), HFVIS_OK);
    for (b = 0; b < 3; b++) {
        double sum = 0.0;
        const int nb[6][3] = { { 3, 2, 2 }, { 1, 2, 2 }, { 2, 3, 2 }, { 2, 1, 2 }, { 2, 2, 3 }, { 2, 2, 1 } };
        for (d = 0; d < 6; d++) {
            const float *s = q + 12 * lin3(&t.grid, nb[d][0], nb[d][1], nb[d][2]) + 4 * b;
            double want = d == 4 ? fwd : d == 5 ? 0.0 : side, F = flux_of(s - 4 * b, b);
            static const int idx[3] = { 3, 1, 2 };
            CHECK_NEAR(F, want * flux[b] * norm, 1e-12, TOL_FLOAT);
            /* the arriving lobe is (F/pi) CC(o): band 1 along the travel direction o */
            CHECK_NEAR((double)s[idx[d / 2]], ((d & 1) ? -1.0 : 1.0) * F / PI * sqrt(PI / 3.0), 1e-12,
                       TOL_FLOAT);
        }
        for (v = 0; v < t.n; v++) sum += flux_of(q + 12 * v, b);
        CHECK_NEAR(sum, tot * flux[b] * norm, 0, TOL_FLOAT);
        CHECK_NEAR(e.start[b], flux[b], 0, TOL_FLOAT);
        CHECK_NEAR(e.end[b], tot * flux[b] * norm, 0, TOL_FLOAT);
        CHECK_NEAR(e.uncovered[b], tr == HFVIS_VOLGI_TRANSFER_CONE ? (1.0 - tot) * flux[b] : 0.0, 1e-12,
                   TOL_FLOAT);
        CHECK(e.created[b] == 0.0 && e.escaped[b] == 0.0 && e.absorbed[b] == 0.0 && e.deposited[b] == 0.0);
    }
    for (v = 0; v < 12 * t.n; v++) CHECK(a[v] == 0.0f); /* nothing occupied: A stays 0 */
    CHECK(flux_of(q + 12 * lin3(&t.grid, 2, 2, 2), 0) == 0.0);
    tg_free(&t);
    free(p), free(q), free(a);
}

TEST(volgi_first_step_fluxes)
{
    first_step(HFVIS_VOLGI_TRANSFER_CONE);
    first_step(HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED);
}

/* A VPL on the border: what would cross the border is reported as escaped. */
TEST(volgi_border_escape)
{
    const double flux[3] = { 1.0, 1.0, 1.0 };
    tg t;
    hfvis_volgi_geometry geo;
    hfvis_volgi_energy e;
    float *p, *q, *a;
    int b;
    tg_init(&t, 3, 3, 3, 1, 1, 1);
    p = sh_alloc(t.n), q = sh_alloc(t.n), a = sh_alloc(t.n);
    set_lobe(p + 12 * lin3(&t.grid, 1, 1, 2), 0, 0, 1, flux); /* top layer, pointing up */
    geo = tg_geo(&t, 0);
    CHECK_EQ_STATUS(hfvis_volgi_propagate_step(&geo, NULL, p, q, a, &e), HFVIS_OK);
    for (b = 0; b < 3; b++) {
        CHECK_NEAR(e.escaped[b], (3.0 - SQRT2) / 4.0, 0, TOL_FLOAT);
        CHECK_NEAR(e.end[b], 4.0 * (2.0 - SQRT2) / 4.0, 0, TOL_FLOAT);
        CHECK_NEAR(e.start[b], e.end[b] + e.escaped[b] + e.uncovered[b] + e.absorbed[b], 0, TOL_FLOAT);
    }
    tg_free(&t);
    free(p), free(q), free(a);
}

/* ---- mirror test ---------------------------------------------------------- */

static void mirror_case(double nz, hfvis_volgi_reflection refl, hfvis_volgi_reflectance src, float rho)
{
    const double flux[3] = { 1.0, 3.0, 0.25 };
    const double F1 = (3.0 - SQRT2) / 4.0;
    tg t;
    hfvis_volgi_geometry geo;
    hfvis_volgi_options o = hfvis_volgi_options_default();
    hfvis_volgi_energy e;
    float *p, *q, *a;
    size_t hit;
    int i, j, b;
    tg_init(&t, 3, 3, 3, 1, 1, 1);
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++) tg_set(&t, i, j, 2, 1.0f, 0, 0, nz); /* a full occupied layer */
    for (i = 0; i < (int)(3 * t.n); i++) t.alb[i] = rho;
    p = sh_alloc(t.n), q = sh_alloc(t.n), a = sh_alloc(t.n);
    set_lobe(p + 12 * lin3(&t.grid, 1, 1, 1), 0, 0, 1, flux);
    geo = tg_geo(&t, 1);
    o.reflection = refl;
    o.reflectance_source = src;
    o.reflectance = rho;
    CHECK_EQ_STATUS(hfvis_volgi_propagate_step(&geo, &o, p, q, a, &e), HFVIS_OK);
    hit = lin3(&t.grid, 1, 1, 2);
    for (b = 0; b < 3; b++) {
        double F = F1 * flux[b], r = src == HFVIS_VOLGI_REFLECTANCE_THESIS ? 0.5 : (double)rho;
        const float *A = a + 12 * hit + 4 * b, *P = q + 12 * hit + 4 * b;
        /* S_in = F CC(+z)/pi recorded; P_next = rho F CC(-z)/pi */
        CHECK_NEAR(A[0], F / PI * sqrt(PI) / 2.0, 0, TOL_FLOAT);
        CHECK_NEAR(A[2], F / PI * sqrt(PI / 3.0), 0, TOL_FLOAT);
        CHECK(A[1] == 0.0f && A[3] == 0.0f);
        CHECK_NEAR(P[0], r * F / PI * sqrt(PI) / 2.0, 1e-30, TOL_FLOAT);
        CHECK_NEAR(P[2], -r * F / PI * sqrt(PI / 3.0), 1e-30, TOL_FLOAT);
        CHECK(P[1] == 0.0f && P[3] == 0.0f);
        CHECK_NEAR(e.deposited[b], F, 0, TOL_FLOAT);
        CHECK_NEAR(e.absorbed[b], (1.0 - r) * F, 1e-12, TOL_FLOAT);
    }
    /* the other layer voxels are not face neighbours of the source */
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++)
            if (i != 1 || j != 1) CHECK(a[12 * lin3(&t.grid, i, j, 2)] == 0.0f);
    tg_free(&t);
    free(p), free(q), free(a);
}

TEST(volgi_mirror_layer)
{
    mirror_case(-1.0, HFVIS_VOLGI_REFLECT_MIRROR, HFVIS_VOLGI_REFLECTANCE_THESIS, 0.5f);
    mirror_case(1.0, HFVIS_VOLGI_REFLECT_MIRROR, HFVIS_VOLGI_REFLECTANCE_THESIS, 0.5f);
    mirror_case(-1.0, HFVIS_VOLGI_REFLECT_MIRROR, HFVIS_VOLGI_REFLECTANCE_CONSTANT, 0.25f);
    mirror_case(-1.0, HFVIS_VOLGI_REFLECT_MIRROR, HFVIS_VOLGI_REFLECTANCE_ALBEDO, 0.8f);
    /* diffuse re-emission about the normal on the side the light came from: the same lobe */
    mirror_case(-1.0, HFVIS_VOLGI_REFLECT_DIFFUSE, HFVIS_VOLGI_REFLECTANCE_THESIS, 0.5f);
    mirror_case(1.0, HFVIS_VOLGI_REFLECT_DIFFUSE, HFVIS_VOLGI_REFLECTANCE_THESIS, 0.5f);
    mirror_case(-1.0, HFVIS_VOLGI_REFLECT_MIRROR, HFVIS_VOLGI_REFLECTANCE_CONSTANT, 0.0f);
}

/* An occupied voxel with a lateral normal: the mirror (axis x) passes a +z lobe on; the diffuse
 * reflection turns it toward the normal; a voxel without a normal sends it back. */
TEST(volgi_reflection_variants)
{
    const double flux[3] = { 1.0, 1.0, 1.0 };
    const double F = (3.0 - SQRT2) / 4.0;
    tg t;
    hfvis_volgi_geometry geo;
    hfvis_volgi_options o = hfvis_volgi_options_default();
    float *p, *q, *a;
    size_t hit;
    int refl;
    for (refl = 0; refl < 3; refl++) {
        tg_init(&t, 3, 3, 3, 1, 1, 1);
        if (refl < 2) tg_set(&t, 1, 1, 2, 1.0f, 1, 0, 0);
        else tg_set(&t, 1, 1, 2, 1.0f, 0, 0, 0);
        p = sh_alloc(t.n), q = sh_alloc(t.n), a = sh_alloc(t.n);
        set_lobe(p + 12 * lin3(&t.grid, 1, 1, 1), 0, 0, 1, flux);
        geo = tg_geo(&t, 0);
        o.reflection = refl == 1 ? HFVIS_VOLGI_REFLECT_DIFFUSE : HFVIS_VOLGI_REFLECT_MIRROR;
        CHECK_EQ_STATUS(hfvis_volgi_propagate_step(&geo, &o, p, q, a, NULL), HFVIS_OK);
        hit = 12 * lin3(&t.grid, 1, 1, 2);
        CHECK_NEAR(q[hit], 0.5 * F / PI * sqrt(PI) / 2.0, 0, TOL_FLOAT); /* c_0: rho times */
        if (refl == 0) { /* mirror on x: the z lobe goes on upward */
            CHECK_NEAR(q[hit + 2], 0.5 * F / PI * sqrt(PI / 3.0), 0, TOL_FLOAT);
            CHECK(q[hit + 3] == 0.0f);
        } else if (refl == 1) { /* re-emitted about +x */
            CHECK_NEAR(q[hit + 3], 0.5 * F / PI * sqrt(PI / 3.0), 0, TOL_FLOAT);
            CHECK(q[hit + 2] == 0.0f);
        } else { /* no normal: back down */
            CHECK_NEAR(q[hit + 2], -0.5 * F / PI * sqrt(PI / 3.0), 0, TOL_FLOAT);
        }
        tg_free(&t);
        free(p), free(q), free(a);
    }
}

/* ---- fast == reference, bit for bit ---------------------------------------------------- */

static void random_geometry(tg *t)
{
    size_t v;
    int a;
    for (v = 0; v < t->n; v++) {
        double r = rng_unit();
        t->occ[v] = r < 0.5 ? 0.0f : r < 0.8 ? 1.0f : (float)rng_unit();
        r = rng_unit();
        for (a = 0; a < 3; a++) {
            double c = r < 0.1 ? 0.0 : rng_unit() * 2.0 - 1.0;
            if (r > 0.9) c = a == 2 ? 0.0 : 0.7; /* ties between axes */
            t->nrm[3 * v + (size_t)a] = (float)c;
            t->alb[3 * v + (size_t)a] = (float)rng_unit();
        }
    }
}

/* physical: sums of cosine lobes with positive flux; otherwise arbitrary values */
static void random_prop(float *p, size_t n, int physical)
{
    size_t v;
    int k;
    for (v = 0; v < n; v++) {
        if (physical) {
            double flux[3];
            int m, l;
            for (k = 0; k < 12; k++) p[12 * v + (size_t)k] = 0.0f;
            if (rng_unit() < 0.3) continue;
            m = 1 + (int)(rng_unit() * 3.0);
            for (l = 0; l < m; l++) {
                float tmp[12];
                double d[3];
                d[0] = rng_unit() - 0.5, d[1] = rng_unit() - 0.5, d[2] = rng_unit() - 0.5;
                flux[0] = rng_unit(), flux[1] = rng_unit(), flux[2] = rng_unit();
                set_lobe(tmp, d[0], d[1], d[2], flux);
                for (k = 0; k < 12; k++) p[12 * v + (size_t)k] += tmp[k];
            }
        } else {
            for (k = 0; k < 12; k++) p[12 * v + (size_t)k] = (float)(rng_unit() * 2.0 - 1.0);
        }
    }
}

TEST(volgi_fast_equals_reference)
{
    tg t;
    hfvis_volgi_geometry geo;
    float *p, *q1, *q2, *a0, *a1, *a2;
    int combo, phys, it;
    rng_state = 2012;
    tg_init(&t, 7, 5, 6, 0.5, 0.5, 0.5);
    random_geometry(&t);
    p = sh_alloc(t.n), q1 = sh_alloc(t.n), q2 = sh_alloc(t.n);
    a0 = sh_alloc(t.n), a1 = sh_alloc(t.n), a2 = sh_alloc(t.n);
    geo = tg_geo(&t, 1);
    for (phys = 0; phys < 2; phys++)
        for (combo = 0; combo < 24; combo++) {
            hfvis_volgi_options o = hfvis_volgi_options_default();
            hfvis_volgi_energy e1, e2;
            size_t v;
            o.transfer = (hfvis_volgi_transfer)(combo & 1);
            o.reflection = (hfvis_volgi_reflection)((combo >> 1) & 1);
            o.paths = (hfvis_volgi_paths)((combo >> 2) & 1);
            o.reflectance_source = (hfvis_volgi_reflectance)(combo >> 3);
            o.reflectance = 0.3f;
            random_prop(p, t.n, phys);
            for (v = 0; v < 12 * t.n; v++) a0[v] = (float)rng_unit();
            memcpy(a1, a0, 12 * t.n * sizeof(float));
            memcpy(a2, a0, 12 * t.n * sizeof(float));
            CHECK_EQ_STATUS(hfvis_volgi_propagate_step(&geo, &o, p, q1, a1, &e1), HFVIS_OK);
            CHECK_EQ_STATUS(hfvis_volgi_propagate_step_reference(&geo, &o, p, q2, a2, &e2), HFVIS_OK);
            CHECK(memcmp(q1, q2, 12 * t.n * sizeof(float)) == 0);
            CHECK(memcmp(a1, a2, 12 * t.n * sizeof(float)) == 0);
            CHECK(memcmp(&e1, &e2, sizeof e1) == 0);
            if (phys) { /* physical input: nothing created, identity holds */
                int b;
                for (b = 0; b < 3; b++) {
                    CHECK(e1.created[b] == 0.0);
                    CHECK_NEAR(e1.start[b], e1.end[b] + e1.absorbed[b] + e1.escaped[b] + e1.blocked[b]
                               + e1.uncovered[b], 0, TOL_ENERGY);
                }
            }
            /* the loop: three steps equal three reference steps (ping-pong) */
            {
                hfvis_volgi_energy E3[3];
                float *r = sh_alloc(t.n), *s = sh_alloc(t.n);
                memcpy(r, p, 12 * t.n * sizeof(float));
                memcpy(a1, a0, 12 * t.n * sizeof(float));
                memcpy(a2, a0, 12 * t.n * sizeof(float));
                CHECK_EQ_STATUS(hfvis_volgi_propagate(&geo, &o, 3, r, a1, E3), HFVIS_OK);
                memcpy(q2, p, 12 * t.n * sizeof(float));
                for (it = 0; it < 3; it++) {
                    CHECK_EQ_STATUS(hfvis_volgi_propagate_step_reference(&geo, &o, q2, s, a2, &e2), HFVIS_OK);
                    CHECK(memcmp(&E3[it], &e2, sizeof e2) == 0);
                    memcpy(q2, s, 12 * t.n * sizeof(float));
                }
                CHECK(memcmp(r, q2, 12 * t.n * sizeof(float)) == 0);
                CHECK(memcmp(a1, a2, 12 * t.n * sizeof(float)) == 0);
                free(r), free(s);
            }
        }
    tg_free(&t);
    free(p), free(q1), free(q2), free(a0), free(a1), free(a2);
}

/* ---- energy accounting per iteration (the room) ---------------------------------------- */

TEST(volgi_energy_accounting)
{
    room r;
    tg t;
    float *p0, *rad, *p, *q, *a;
    int combo, it, b;
    room_init(&r);
    room_volume(&r, 24, &t, &p0, &rad);
    p = sh_alloc(t.n), q = sh_alloc(t.n), a = sh_alloc(t.n);
    for (combo = 0; combo < 8; combo++) {
        hfvis_volgi_options o = hfvis_volgi_options_default();
        hfvis_volgi_geometry geo = tg_geo(&t, 1);
        double prev_end[3] = { 0, 0, 0 }, dep[3] = { 0, 0, 0 };
        int created = 0, monotone = 1, identity = 1, signs = 1;
        o.transfer = (hfvis_volgi_transfer)(combo & 1);
        o.reflection = (hfvis_volgi_reflection)((combo >> 1) & 1);
        o.paths = (hfvis_volgi_paths)(combo >> 2);
        if ((combo & 3) == 3) o.reflectance_source = HFVIS_VOLGI_REFLECTANCE_ALBEDO;
        memcpy(p, p0, 12 * t.n * sizeof(float));
        memset(a, 0, 12 * t.n * sizeof(float));
        for (it = 0; it < 60; it++) {
            hfvis_volgi_energy e;
            float *sw;
            CHECK_EQ_STATUS(hfvis_volgi_propagate_step(&geo, &o, p, q, a, &e), HFVIS_OK);
            for (b = 0; b < 3; b++) {
                double lost = e.absorbed[b] + e.escaped[b] + e.blocked[b] + e.uncovered[b];
                if (e.created[b] != 0.0) created = 1;
                if (it > 0 && e.start[b] != prev_end[b]) monotone = 0; /* same floats, same order */
                if (e.end[b] > e.start[b]) monotone = 0;                /* nothing created */
                if (fabs(e.start[b] - e.end[b] - lost) > TOL_ENERGY * e.start[b]) identity = 0;
                if (e.absorbed[b] < 0.0 || e.escaped[b] < 0.0 || e.uncovered[b] < 0.0 || e.deposited[b] < 0.0
                    || e.blocked[b] < 0.0)
                    signs = 0;
                /* normalised: lost only by absorption, leaving the grid (and fully blocked voxels) */
                if (o.transfer == HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED && e.uncovered[b] != 0.0) signs = 0;
                if (o.paths == HFVIS_VOLGI_PATHS_ALL && e.blocked[b] != 0.0) signs = 0;
                prev_end[b] = e.end[b];
                dep[b] += e.deposited[b];
            }
            sw = p, p = q, q = sw;
        }
        CHECK(!created);
        CHECK(monotone);
        CHECK(identity);
        CHECK(signs);
        /* the accumulation volume's flux is the sum of the deposits */
        for (b = 0; b < 3; b++) {
            double sum = 0.0;
            size_t v;
            for (v = 0; v < t.n; v++) sum += flux_of(a + 12 * v, b);
            CHECK_NEAR(sum, dep[b], 0, TOL_ENERGY);
        }
    }
    tg_free(&t);
    free(p0), free(rad), free(p), free(q), free(a);
    room_free(&r);
}

/* ---- a closed box with rho = 0 keeps everything inside --------------------- */

TEST(volgi_closed_box_absorbs)
{
    tg t;
    hfvis_volgi_geometry geo;
    hfvis_volgi_options o = hfvis_volgi_options_default();
    float *p, *q, *a;
    int i, j, k, it, outside_lit = 0;
    double escaped = 0.0;
    tg_init(&t, 12, 12, 12, 1, 1, 1);
    for (k = 2; k <= 9; k++)
        for (j = 2; j <= 9; j++)
            for (i = 2; i <= 9; i++)
                if (i == 2 || i == 9 || j == 2 || j == 9 || k == 2 || k == 9)
                    tg_set(&t, i, j, k, 1.0f, i == 2 ? 1 : i == 9 ? -1 : 0, j == 2 ? 1 : j == 9 ? -1 : 0,
                           k == 2 ? 1 : k == 9 ? -1 : 0);
    p = sh_alloc(t.n), q = sh_alloc(t.n), a = sh_alloc(t.n);
    {
        const double f1[3] = { 1, 1, 1 }, f2[3] = { 2, 0.5, 1 };
        set_lobe(p + 12 * lin3(&t.grid, 5, 5, 5), 0.3, -0.2, 1, f1);
        set_lobe(p + 12 * lin3(&t.grid, 4, 7, 3), -1, 0, 0, f2);
    }
    geo = tg_geo(&t, 0);
    o.reflectance_source = HFVIS_VOLGI_REFLECTANCE_CONSTANT;
    o.reflectance = 0.0f;
    for (it = 0; it < 20; it++) {
        hfvis_volgi_energy e;
        float *sw;
        CHECK_EQ_STATUS(hfvis_volgi_propagate_step(&geo, &o, p, q, a, &e), HFVIS_OK);
        escaped += e.escaped[0] + e.escaped[1] + e.escaped[2];
        for (k = 0; k < 12; k++)
            for (j = 0; j < 12; j++)
                for (i = 0; i < 12; i++) {
                    size_t v = lin3(&t.grid, i, j, k);
                    int c;
                    if (i >= 2 && i <= 9 && j >= 2 && j <= 9 && k >= 2 && k <= 9) continue;
                    for (c = 0; c < 12; c++)
                        if (q[12 * v + (size_t)c] != 0.0f || a[12 * v + (size_t)c] != 0.0f) outside_lit = 1;
                }
        sw = p, p = q, q = sw;
    }
    CHECK(!outside_lit);
    CHECK(escaped == 0.0);
    tg_free(&t);
    free(p), free(q), free(a);
}

/* ---- linearity -------------------------------------------------------------- */

TEST(volgi_linearity)
{
    tg t;
    hfvis_volgi_geometry geo;
    float *p1, *p2, *p12, *a1, *a2, *a12, *pd, *ad;
    const double f1[3] = { 1, 0.5, 0.25 }, f2[3] = { 0.3, 2, 1 };
    size_t v;
    int ok = 1;
    rng_state = 5;
    tg_init(&t, 20, 5, 5, 1, 1, 1);
    random_geometry(&t);
    /* keep the two sources' voxels and their 3-step neighbourhoods apart: x <= 6 and x >= 13 */
    p1 = sh_alloc(t.n), p2 = sh_alloc(t.n), p12 = sh_alloc(t.n);
    a1 = sh_alloc(t.n), a2 = sh_alloc(t.n), a12 = sh_alloc(t.n);
    pd = sh_alloc(t.n), ad = sh_alloc(t.n);
    set_lobe(p1 + 12 * lin3(&t.grid, 3, 2, 2), 0.2, 0.1, 1, f1);
    set_lobe(p2 + 12 * lin3(&t.grid, 16, 2, 2), -1, 0.3, 0.2, f2);
    for (v = 0; v < 12 * t.n; v++) p12[v] = p1[v] + p2[v], pd[v] = 2.0f * p1[v];
    geo = tg_geo(&t, 0);
    CHECK_EQ_STATUS(hfvis_volgi_propagate(&geo, NULL, 3, p1, a1, NULL), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_volgi_propagate(&geo, NULL, 3, p2, a2, NULL), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_volgi_propagate(&geo, NULL, 3, p12, a12, NULL), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_volgi_propagate(&geo, NULL, 3, pd, ad, NULL), HFVIS_OK);
    for (v = 0; v < 12 * t.n; v++) {
        if (a12[v] != a1[v] + a2[v] || p12[v] != p1[v] + p2[v]) ok = 0; /* superposition */
        if (ad[v] != 2.0f * a1[v] || pd[v] != 2.0f * p1[v]) ok = 0;      /* doubling is exact */
    }
    CHECK(ok);
    tg_free(&t);
    free(p1), free(p2), free(p12), free(a1), free(a2), free(a12), free(pd), free(ad);
}

/* ---- gather ---------------------------------------------------------------- */

TEST(volgi_gather)
{
    tg t;
    hfvis_volgi_geometry geo;
    hfvis_volgi_options o = hfvis_volgi_options_default();
    float *A;
    float E[3], E2[3];
    double cc[4];
    const double up[3] = { 0, 0, 1 }, down[3] = { 0, 0, -1 };
    const double kap[3] = { 1.0, 2.0, 0.5 };
    size_t v;
    int k, b, trial;
    tg_init(&t, 4, 4, 4, 0.5, 0.5, 0.5);
    A = sh_alloc(t.n);
    for (v = 0; v < t.n; v++) t.occ[v] = 1.0f;
    /* A = kappa_b CC(-n) for a receiver with n = +z: light travelling down onto it */
    hfvis_volgi_sh_clamped_cosine(down, cc);
    for (v = 0; v < t.n; v++)
        for (b = 0; b < 3; b++)
            for (k = 0; k < 4; k++) A[12 * v + 4 * (size_t)b + (size_t)k] = (float)(kap[b] * cc[k]);
    geo = tg_geo(&t, 0);
    rng_state = 77;
    for (trial = 0; trial < 20; trial++) {
        double p[3];
        p[0] = 0.3 + 1.4 * rng_unit(), p[1] = 0.3 + 1.4 * rng_unit(), p[2] = 0.3 + 1.4 * rng_unit();
        /* some corners empty: the weights renormalise, E unchanged */
        if (trial >= 10) t.occ[lin3(&t.grid, (int)(p[0] / 0.5 - 0.5), (int)(p[1] / 0.5 - 0.5), 1)] = 0.0f;
        CHECK_EQ_STATUS(hfvis_volgi_gather(&geo, A, NULL, p, up, E), HFVIS_OK);
        for (b = 0; b < 3; b++) /* (12/7) kappa (7 pi/12) / s^2 = kappa pi / s^2 */
            CHECK_NEAR(E[b], kap[b] * PI / 0.25, 0, TOL_FLOAT);
        /* light from behind: max(0, .) */
        CHECK_EQ_STATUS(hfvis_volgi_gather(&geo, A, NULL, p, down, E), HFVIS_OK);
        CHECK(E[0] == 0.0f && E[1] == 0.0f && E[2] == 0.0f);
    }
    /* the gather scale multiplies */
    {
        const double p[3] = { 1.0, 1.0, 1.0 };
        o.gather_scale = 2.0 * HFVIS_VOLGI_DEFAULT_GATHER_SCALE;
        CHECK_EQ_STATUS(hfvis_volgi_gather(&geo, A, NULL, p, up, E), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_volgi_gather(&geo, A, &o, p, up, E2), HFVIS_OK);
        for (b = 0; b < 3; b++) CHECK_NEAR(E2[b], 2.0 * (double)E[b], 0, TOL_FLOAT);
    }
    /* a flux F arriving head on as (F/pi) CC(-n) gives F/s^2 */
    {
        const double p[3] = { 0.75, 0.75, 0.75 }, F = 3.0;
        for (v = 0; v < t.n; v++)
            for (b = 0; b < 3; b++)
                for (k = 0; k < 4; k++) A[12 * v + 4 * (size_t)b + (size_t)k] = (float)(F / PI * cc[k]);
        CHECK_EQ_STATUS(hfvis_volgi_gather(&geo, A, NULL, p, up, E), HFVIS_OK);
        CHECK_NEAR(E[0], F / 0.25, 0, TOL_FLOAT);
    }
    /* no occupied voxel near, or far outside the grid: 0 */
    {
        const double p[3] = { 1.0, 1.0, 1.0 }, far[3] = { 50.0, 1.0, 1.0 };
        for (v = 0; v < t.n; v++) t.occ[v] = 0.0f;
        CHECK_EQ_STATUS(hfvis_volgi_gather(&geo, A, NULL, p, up, E), HFVIS_OK);
        CHECK(E[0] == 0.0f && E[1] == 0.0f && E[2] == 0.0f);
        for (v = 0; v < t.n; v++) t.occ[v] = 1.0f;
        CHECK_EQ_STATUS(hfvis_volgi_gather(&geo, A, NULL, far, up, E), HFVIS_OK);
        CHECK(E[0] == 0.0f);
    }
    tg_free(&t);
    free(A);
}

/* ---- direct light --------------------------------------------------------------------- */

/* A floor quad [-1,1]^2 at z = 0 (triangles 0, 1, facing up) and a small blocker quad at z = 0.5
 * over x in [-0.6, -0.4] (triangles 2, 3, facing down). */
static void plane_scene(hfvis_mesh *m, float *xyz, uint32_t *idx)
{
    static const float v[24] = { -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0,
                                 -0.6f, -0.2f, 0.5f, -0.4f, -0.2f, 0.5f, -0.4f, 0.2f, 0.5f, -0.6f, 0.2f, 0.5f };
    static const uint32_t f[12] = { 0, 1, 2, 0, 2, 3, 4, 6, 5, 4, 7, 6 };
    memcpy(xyz, v, sizeof v);
    memcpy(idx, f, sizeof f);
    m->xyz = xyz, m->vertex_count = 8, m->indices = idx, m->triangle_count = 4;
}

TEST(volgi_direct_light)
{
    hfvis_mesh m;
    float xyz[24];
    uint32_t idx[12];
    hfvis_bvh bvh;
    hfvis_volgi_light L;
    hfvis_volgi_scene sc;
    float E[3];
    const double up[3] = { 0, 0, 1 }, down[3] = { 0, 0, -1 };
    double p[3] = { 0.5, 0.0, 0.0 };
    plane_scene(&m, xyz, idx);
    CHECK_EQ_STATUS(hfvis_bvh_build(&m, NULL, &bvh), HFVIS_OK);
    memset(&L, 0, sizeof L);
    memset(&sc, 0, sizeof sc);
    L.type = HFVIS_VOLGI_LIGHT_POINT;
    L.position[2] = 1.0;
    L.intensity[0] = 1.0f, L.intensity[1] = 2.0f, L.intensity[2] = 3.0f;
    sc.mesh = &m, sc.lights = &L, sc.light_count = 1, sc.bvh = &bvh;
    /* E = I cos / d^2 = I / 1.25^1.5 */
    CHECK_EQ_STATUS(hfvis_volgi_direct_irradiance(&sc, NULL, p, up, 0, E), HFVIS_OK);
    CHECK_NEAR(E[0], 1.0 / pow(1.25, 1.5), 0, TOL_FLOAT);
    CHECK_NEAR(E[2], 3.0 / pow(1.25, 1.5), 0, TOL_FLOAT);
    /* the back side is not lit */
    CHECK_EQ_STATUS(hfvis_volgi_direct_irradiance(&sc, NULL, p, down, 0, E), HFVIS_OK);
    CHECK(E[0] == 0.0f);
    /* shadowed by the blocker: the ray to (0,0,1) crosses z = 0.5 at x = -0.5 */
    p[0] = -1.0;
    CHECK_EQ_STATUS(hfvis_volgi_direct_irradiance(&sc, NULL, p, up, 0, E), HFVIS_OK);
    CHECK(E[0] == 0.0f && E[1] == 0.0f);
    /* a receiver on the blocker's underside skips its own triangle; facing down, unlit */
    {
        const double q[3] = { -0.5, 0.0, 0.5 };
        CHECK_EQ_STATUS(hfvis_volgi_direct_irradiance(&sc, NULL, q, up, 2, E), HFVIS_OK);
        CHECK_NEAR(E[0], sqrt(0.5) / 0.5, 0, TOL_FLOAT); /* cos 45 / d^2, d^2 = 0.5 */
    }
    /* spot: axis down, inner 30, outer 45 degrees */
    L.type = HFVIS_VOLGI_LIGHT_SPOT;
    L.direction[2] = -1.0;
    L.spot_inner_rad = PI / 6.0, L.spot_outer_rad = PI / 4.0;
    {
        const double ang[3] = { 20.0, 40.0, 50.0 };
        int i;
        for (i = 0; i < 3; i++) {
            double th = ang[i] * PI / 180.0, want, ct = cos(th);
            double q[3];
            q[0] = tan(th), q[1] = 0.0, q[2] = 0.0;
            want = ct * ct * ct; /* cos / d^2 with d = 1/cos */
            if (i == 1) want *= (ct - cos(PI / 4.0)) / (cos(PI / 6.0) - cos(PI / 4.0));
            if (i == 2) want = 0.0;
            CHECK_EQ_STATUS(hfvis_volgi_direct_irradiance(&sc, NULL, q, up, 0, E), HFVIS_OK);
            CHECK_NEAR(E[0], want, 1e-12, TOL_FLOAT);
        }
        /* a hard edge */
        L.spot_inner_rad = L.spot_outer_rad = PI / 4.0;
        p[0] = tan(40.0 * PI / 180.0);
        CHECK_EQ_STATUS(hfvis_volgi_direct_irradiance(&sc, NULL, p, up, 0, E), HFVIS_OK);
        CHECK(E[0] > 0.0f);
        p[0] = tan(46.0 * PI / 180.0);
        CHECK_EQ_STATUS(hfvis_volgi_direct_irradiance(&sc, NULL, p, up, 0, E), HFVIS_OK);
        CHECK(E[0] == 0.0f);
    }
    /* directional, straight down, irradiance 2 */
    L.type = HFVIS_VOLGI_LIGHT_DIRECTIONAL;
    L.intensity[0] = 2.0f;
    p[0] = 0.5;
    CHECK_EQ_STATUS(hfvis_volgi_direct_irradiance(&sc, NULL, p, up, 0, E), HFVIS_OK);
    CHECK_NEAR(E[0], 2.0, 0, TOL_FLOAT);
    p[0] = -0.5; /* under the blocker */
    CHECK_EQ_STATUS(hfvis_volgi_direct_irradiance(&sc, NULL, p, up, 0, E), HFVIS_OK);
    CHECK(E[0] == 0.0f);
    /* two lights add */
    {
        hfvis_volgi_light two[2];
        two[0] = L, two[1] = L;
        sc.lights = two, sc.light_count = 2;
        p[0] = 0.5;
        CHECK_EQ_STATUS(hfvis_volgi_direct_irradiance(&sc, NULL, p, up, 0, E), HFVIS_OK);
        CHECK_NEAR(E[0], 4.0, 0, TOL_FLOAT);
    }
    hfvis_bvh_free(NULL, &bvh);
}

/* ---- Alg. 4: voxelization with direct light --------------------------------------------- */

TEST(volgi_voxelize_plane)
{
    hfvis_mesh m;
    float xyz[24], alb[12] = { 0.5f, 0.25f, 1.0f, 0.5f, 0.25f, 1.0f, 0, 0, 0, 0, 0, 0 };
    float em[12] = { 0, 0, 0.1f, 0, 0, 0.1f, 0, 0, 0, 0, 0, 0 };
    uint32_t idx[12];
    hfvis_volgi_light L;
    hfvis_volgi_scene sc;
    hfvis_volume_grid g;
    hfvis_voxelize_options vo = hfvis_voxelize_options_default();
    float *occ, *nrm, *al, *rad;
    uint8_t *ref;
    size_t n, v, frags = 0, count = 0;
    int ok = 1, b;
    plane_scene(&m, xyz, idx);
    m.triangle_count = 2; /* the floor only */
    memset(&L, 0, sizeof L);
    memset(&sc, 0, sizeof sc);
    L.type = HFVIS_VOLGI_LIGHT_DIRECTIONAL;
    L.direction[2] = -1.0;
    L.intensity[0] = L.intensity[1] = L.intensity[2] = 2.0f;
    sc.mesh = &m, sc.lights = &L, sc.light_count = 1, sc.albedo = alb, sc.emission = em;
    memset(&g, 0, sizeof g);
    g.dims[0] = g.dims[1] = 8, g.dims[2] = 3;
    g.cell[0] = g.cell[1] = g.cell[2] = 0.25;
    g.origin[0] = g.origin[1] = -1.0, g.origin[2] = -0.3;
    n = 8 * 8 * 3;
    occ = (float *)malloc(n * sizeof(float)), nrm = (float *)malloc(3 * n * sizeof(float));
    al = (float *)malloc(3 * n * sizeof(float)), rad = (float *)malloc(3 * n * sizeof(float));
    ref = (uint8_t *)malloc(n);
    CHECK_EQ_STATUS(hfvis_volgi_voxelize(&sc, &g, NULL, occ, nrm, al, rad, &frags), HFVIS_OK);
    vo.axes = HFVIS_AXES_ALL;
    CHECK_EQ_STATUS(hfvis_voxelize_occupancy(&m, &g, &vo, ref), HFVIS_OK);
    for (v = 0; v < n; v++) {
        if ((occ[v] == 1.0f) != (ref[v] == 1)) ok = 0;
        if (occ[v] != 0.0f && occ[v] != 1.0f) ok = 0;
        if (!ref[v]) continue;
        count++;
        if (nrm[3 * v] != 0.0f || nrm[3 * v + 1] != 0.0f || nrm[3 * v + 2] != 1.0f) ok = 0;
        for (b = 0; b < 3; b++) {
            float want = (float)((double)alb[b] * 2.0 / PI + (double)em[b]);
            if (al[3 * v + (size_t)b] != alb[b] || rad[3 * v + (size_t)b] != want) ok = 0;
        }
    }
    CHECK(ok);
    CHECK(count == 64);      /* the plane z = 0 lies inside one layer: 8 x 8 voxels */
    CHECK(frags >= count);
    free(occ), free(nrm), free(al), free(rad), free(ref);
}

/* Alg. 4 literally: three per-axis volumes (hfvis_voxel_fragment_attributes with the direct
 * irradiance callback) merged with MAX give the radiance hfvis_volgi_voxelize writes. */
typedef struct irr_user {
    const hfvis_volgi_scene *sc;
} irr_user;
static void irr_cb(const float position[3], const float normal[3], float rgb[3], void *user)
{
    const irr_user *u = (const irr_user *)user;
    double p[3], n[3];
    int a;
    for (a = 0; a < 3; a++) p[a] = (double)position[a], n[a] = (double)normal[a];
    /* the receiver's triangle is not known here: no skip; the default bias keeps it off */
    hfvis_volgi_direct_irradiance(u->sc, NULL, p, n, HFVIS_NO_TRIANGLE, rgb);
}

TEST(volgi_alg4_three_axes_max)
{
    room r;
    hfvis_volume_grid g;
    hfvis_volume vol[3];
    hfvis_voxel_attributes at;
    hfvis_voxelize_options vo = hfvis_voxelize_options_default();
    irr_user iu;
    float *data[3], *occ, *nrm, *rad;
    size_t n, v;
    int a, b, same = 1, lit = 0;
    room_init(&r);
    CHECK_EQ_STATUS(hfvis_volgi_grid_fit(&r.mesh, 20, &g), HFVIS_OK);
    n = (size_t)g.dims[0] * (size_t)g.dims[1] * (size_t)g.dims[2];
    occ = (float *)malloc(n * sizeof(float)), nrm = (float *)malloc(3 * n * sizeof(float));
    rad = (float *)malloc(3 * n * sizeof(float));
    CHECK_EQ_STATUS(hfvis_volgi_voxelize(&r.scene, &g, NULL, occ, nrm, NULL, rad, NULL), HFVIS_OK);
    memset(&at, 0, sizeof at);
    at.flags = HFVIS_VOXEL_ATTR_RADIANCE;
    at.albedo = r.albedo;
    at.irradiance = irr_cb;
    iu.sc = &r.scene;
    at.irradiance_user = &iu;
    vo.fragment = hfvis_voxel_fragment_attributes;
    vo.user = &at;
    for (a = 0; a < 3; a++) {
        data[a] = (float *)malloc(3 * n * sizeof(float));
        CHECK_EQ_STATUS(hfvis_volume_init(&vol[a], &g, 3, data[a], HFVIS_BLEND_MAX), HFVIS_OK);
        vo.axes = (hfvis_voxelize_axes)(HFVIS_AXES_ONLY_X + a);
        CHECK_EQ_STATUS(hfvis_voxelize_surface(&r.mesh, &vol[a], &vo, NULL), HFVIS_OK);
    }
    CHECK_EQ_STATUS(hfvis_volume_merge(&vol[0], &vol[1]), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_volume_merge(&vol[0], &vol[2]), HFVIS_OK);
    for (v = 0; v < n; v++)
        for (b = 0; b < 3; b++) {
            /* the generic callback rounds E to float before albedo E/pi: within TOL_FLOAT; the
             * skip rule (own triangle vs none) changes nothing here (the bias keeps rays off) */
            double x = (double)data[0][3 * v + (size_t)b], y = (double)rad[3 * v + (size_t)b];
            if (fabs(x - y) > TOL_FLOAT * fabs(y)) same = 0;
            if (rad[3 * v + (size_t)b] > 0.0f) lit++;
        }
    CHECK(same);
    CHECK(lit > 0);
    for (a = 0; a < 3; a++) free(data[a]);
    free(occ), free(nrm), free(rad);
    room_free(&r);
}

/* ---- the grid ----------------------------------------------------------------------------- */

TEST(volgi_grid_fit)
{
    room r;
    hfvis_volume_grid g;
    hfvis_mesh quad;
    float xyz[24];
    uint32_t idx[12];
    int a;
    room_init(&r);
    CHECK_EQ_STATUS(hfvis_volgi_grid_fit(&r.mesh, 32, &g), HFVIS_OK);
    for (a = 0; a < 3; a++) {
        CHECK(g.dims[a] == 32);
        CHECK_NEAR(g.cell[a], 1.0 / 31.0, 1e-15, 0);
        CHECK_NEAR(g.origin[a] + 0.5 * g.cell[a], 0.0, 1e-15, 0);   /* wall 0 at a voxel centre */
        CHECK_NEAR(g.origin[a] + 31.5 * g.cell[a], 1.0, 1e-14, 0);  /* wall 1 at a voxel centre */
    }
    plane_scene(&quad, xyz, idx);
    quad.triangle_count = 2;
    CHECK_EQ_STATUS(hfvis_volgi_grid_fit(&quad, 9, &g), HFVIS_OK);
    CHECK(g.dims[0] == 9 && g.dims[1] == 9 && g.dims[2] == 1);
    CHECK_NEAR(g.origin[2] + 0.5 * g.cell[2], 0.0, 1e-15, 0);
    CHECK_EQ_STATUS(hfvis_volgi_grid_fit(&r.mesh, 1, &g), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_grid_fit(&r.mesh, HFVIS_VOLGI_MAX_RESOLUTION + 1, &g), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_grid_fit(&r.mesh, HFVIS_VOLGI_MAX_RESOLUTION, &g), HFVIS_ERR_LIMIT);
    CHECK_EQ_STATUS(hfvis_volgi_grid_fit(NULL, 32, &g), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_grid_fit(&r.mesh, 32, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    quad.triangle_count = 0;
    CHECK_EQ_STATUS(hfvis_volgi_grid_fit(&quad, 32, &g), HFVIS_ERR_INVALID_ARGUMENT);
    room_free(&r);
}

/* ---- the coloured room: colour bleeding and convergence ---------------------------------- */

TEST(volgi_room_colour_bleeding)
{
    /* floor points beside the red (x = 0) and the green (x = 1) wall, in two mirrored pairs */
    const double pts[4][3] = { { 0.05, 0.5, 0.0 }, { 0.95, 0.5, 0.0 }, { 0.1, 0.3, 0.0 }, { 0.9, 0.3, 0.0 } };
    const double up[3] = { 0, 0, 1 };
    room r;
    tg t;
    hfvis_volgi_geometry geo;
    float *p0, *p, *rad, *a;
    double hist[6][4][3];
    int mode, step, s, i, b;
    room_init(&r);
    room_volume(&r, 32, &t, &p0, &rad);
    p = sh_alloc(t.n), a = sh_alloc(t.n);
    geo = tg_geo(&t, 1);
    for (mode = 0; mode < 4; mode++) {
        hfvis_volgi_options o = hfvis_volgi_options_default();
        o.paths = (hfvis_volgi_paths)(mode & 1);
        o.transfer = (hfvis_volgi_transfer)(mode >> 1);
        memcpy(p, p0, 12 * t.n * sizeof(float));
        memset(a, 0, 12 * t.n * sizeof(float));
        /* 16, 32, 64, 128, 256, 512 steps (cumulative: propagate continues P and adds to A) */
        for (step = 16, s = 0; s < 6; step *= 2, s++) {
            CHECK_EQ_STATUS(hfvis_volgi_propagate(&geo, &o, s == 0 ? 16 : step / 2, p, a, NULL), HFVIS_OK);
            for (i = 0; i < 4; i++) {
                float E[3];
                CHECK_EQ_STATUS(hfvis_volgi_gather(&geo, a, &o, pts[i], up, E), HFVIS_OK);
                for (b = 0; b < 3; b++) hist[s][i][b] = (double)E[b];
            }
        }
        /* at 64 steps (the thesis' room count): beside the red wall the floor's indirect light is
         * red-tinted (R > G), beside the green wall green-tinted, and the red/green ratio is much
         * larger on the red side */
        for (i = 0; i < 4; i += 2) {
            const double *L = hist[2][i], *R = hist[2][i + 1];
            CHECK(L[0] > L[1]);
            CHECK(R[1] > R[0]);
            CHECK(L[0] / L[1] > 1.4 * (R[0] / R[1]));
        }
        /* converges: from 128 steps on each doubling adds less than the one before, the last one
         * changes the light by less than TOL_CONVERGED(_NORM), and almost no light is left */
        {
            double inj = 0.0, left = 0.0;
            size_t v;
            for (v = 0; v < t.n; v++) inj += flux_of(p0 + 12 * v, 0), left += flux_of(p + 12 * v, 0);
            CHECK(left >= 0.0 && left <= TOL_REMAINING * inj);
        }
        for (i = 0; i < 4; i++)
            for (b = 0; b < 3; b++) {
                for (s = 4; s < 6; s++)
                    CHECK(fabs(hist[s][i][b] - hist[s - 1][i][b]) <= fabs(hist[s - 1][i][b] - hist[s - 2][i][b]));
                CHECK(hist[5][i][b] > 0.0);
                CHECK(fabs(hist[5][i][b] - hist[4][i][b])
                      <= (mode >> 1 ? TOL_CONVERGED_NORM : TOL_CONVERGED) * hist[5][i][b]);
            }
        printf("     %s/%s, 64 steps: floor R/G beside the red wall %.2f, %.2f; beside the green wall "
               "%.2f, %.2f; change 256 -> 512 steps %.1e\n", mode & 1 ? "VOID" : "ALL",
               mode >> 1 ? "NORMALIZED" : "CONE", hist[2][0][0] / hist[2][0][1], hist[2][2][0] / hist[2][2][1],
               hist[2][1][0] / hist[2][1][1], hist[2][3][0] / hist[2][3][1],
               fabs(hist[5][0][0] - hist[4][0][0]) / hist[5][0][0]);
    }
    tg_free(&t);
    free(p0), free(p), free(rad), free(a);
    room_free(&r);
}

/* ---- the pipeline ------------------------------------------------------------------------ */

static void room_view(hfvis_view *v, int w, int h)
{
    const double eye[3] = { 0.5, -1.1, 0.5 }, at[3] = { 0.5, 0.5, 0.45 }, up[3] = { 0, 0, 1 };
    CHECK_EQ_STATUS(hfvis_view_perspective(v, eye, at, up, 40.0 * PI / 180.0, w, h, 0.1, 10.0), HFVIS_OK);
}

TEST(volgi_render_matches_parts)
{
    enum { W = 40, H = 32, ITER = 24 };
    room r;
    tg t;
    hfvis_view view;
    hfvis_volgi_outputs out;
    hfvis_volgi_render_info info;
    hfvis_volgi_options o = hfvis_volgi_options_default();
    hfvis_volgi_geometry geo;
    hfvis_raster_outputs ro;
    float *dir = (float *)malloc(3 * W * H * sizeof(float)), *ind = (float *)malloc(3 * W * H * sizeof(float));
    float *tot = (float *)malloc(3 * W * H * sizeof(float)), *p, *rad, *a;
    float nrm[3 * W * H], bary[2 * W * H];
    uint32_t tri[W * H];
    size_t px, covered = 0;
    int b, okd = 1, oki = 1, okt = 1, left_red = 0, right_green = 0;
    double inj[3] = { 0, 0, 0 };
    room_init(&r);
    room_view(&view, W, H);
    out.direct = dir, out.indirect = ind, out.total = tot;
    o.iterations = ITER;
    o.resolution = 24;
    CHECK_EQ_STATUS(hfvis_volgi_render(&r.scene, NULL, &view, &o, &out, &info), HFVIS_OK);
    /* the same steps one by one */
    room_volume(&r, 24, &t, &p, &rad);
    for (px = 0; px < t.n; px++)
        for (b = 0; b < 3; b++) inj[b] += flux_of(p + 12 * px, b);
    a = sh_alloc(t.n);
    geo = tg_geo(&t, 1);
    CHECK_EQ_STATUS(hfvis_volgi_propagate(&geo, NULL, ITER, p, a, NULL), HFVIS_OK);
    memset(&ro, 0, sizeof ro);
    ro.normal = nrm, ro.barycentric = bary, ro.triangle_id = tri;
    CHECK_EQ_STATUS(hfvis_rasterize(&r.mesh, &view, NULL, &ro), HFVIS_OK);
    for (px = 0; px < (size_t)W * H; px++) {
        float Ed[3] = { 0, 0, 0 }, Ei[3] = { 0, 0, 0 };
        if (tri[px] != HFVIS_NO_TRIANGLE) {
            const uint32_t *ix = r.mesh.indices + 3 * (size_t)tri[px];
            double p3[3], n3[3];
            double b1 = (double)bary[2 * px], b2 = (double)bary[2 * px + 1];
            int k;
            covered++;
            for (k = 0; k < 3; k++) {
                p3[k] = (1.0 - b1 - b2) * (double)r.mesh.xyz[3 * (size_t)ix[0] + (size_t)k]
                        + b1 * (double)r.mesh.xyz[3 * (size_t)ix[1] + (size_t)k]
                        + b2 * (double)r.mesh.xyz[3 * (size_t)ix[2] + (size_t)k];
                n3[k] = (double)nrm[3 * px + (size_t)k];
            }
            CHECK_EQ_STATUS(hfvis_volgi_direct_irradiance(&r.scene, NULL, p3, n3, tri[px], Ed), HFVIS_OK);
            CHECK_EQ_STATUS(hfvis_volgi_gather(&geo, a, NULL, p3, n3, Ei), HFVIS_OK);
            for (k = 0; k < 3; k++) {
                double al = (double)r.albedo[3 * (size_t)tri[px] + (size_t)k];
                Ed[k] = (float)(al * (double)Ed[k] / PI);
                Ei[k] = (float)(al * (double)Ei[k] / PI);
            }
            /* floor pixels: the side near the red wall redder in the indirect light */
            if (tri[px] == 6 || tri[px] == 7) {
                double x = p3[0];
                if (x < 0.15 && ind[3 * px] > 1.2f * ind[3 * px + 1]) left_red++;
                if (x > 0.85 && ind[3 * px + 1] > 1.2f * ind[3 * px]) right_green++;
            }
        }
        for (b = 0; b < 3; b++) {
            /* the public calls round E to float before albedo E/pi */
            if (fabs((double)dir[3 * px + (size_t)b] - (double)Ed[b]) > TOL_FLOAT * (double)Ed[b]) okd = 0;
            if (fabs((double)ind[3 * px + (size_t)b] - (double)Ei[b]) > TOL_FLOAT * (double)Ei[b]) oki = 0;
            if (tot[3 * px + (size_t)b] != (float)((double)dir[3 * px + (size_t)b] + (double)ind[3 * px + (size_t)b]))
                okt = 0;
        }
    }
    CHECK(okd);
    CHECK(oki);
    CHECK(okt);
    CHECK(info.covered_pixels == covered);
    CHECK(info.grid.dims[0] == 24);
    CHECK(left_red > 0 && right_green > 0);
    for (b = 0; b < 3; b++) {
        CHECK_NEAR(info.injected[b], inj[b], 0, 1e-12);
        CHECK(info.deposited[b] > 0.0 && info.remaining[b] >= 0.0);
        CHECK(info.deposited[b] + info.remaining[b] < 2.0 * info.injected[b] / (1.0 - 0.5));
    }
    free(dir), free(ind), free(tot), free(p), free(rad), free(a);
    tg_free(&t);
    room_free(&r);
}

/* Emissive voxels: no lights, an emissive panel under the ceiling lights the room indirectly. */
TEST(volgi_emissive_voxels)
{
    enum { W = 24, H = 24 };
    hfvis_mesh room_mesh, m;
    float *xyz, em[32 * 3];
    uint32_t *idx;
    hfvis_volgi_scene sc;
    hfvis_view view;
    hfvis_volgi_outputs out;
    hfvis_volgi_options o = hfvis_volgi_options_default();
    float dir[3 * W * H], ind[3 * W * H];
    size_t px;
    int lit = 0, glow = 0;
    CHECK_EQ_STATUS(hfvis_mesh_room(NULL, &room_mesh), HFVIS_OK);
    /* the room plus a panel [0.4, 0.6]^2 at z = 0.9 facing down (triangles 30, 31) */
    xyz = (float *)malloc((room_mesh.vertex_count + 4) * 3 * sizeof(float));
    idx = (uint32_t *)malloc(32 * 3 * sizeof(uint32_t));
    memcpy(xyz, room_mesh.xyz, room_mesh.vertex_count * 3 * sizeof(float));
    memcpy(idx, room_mesh.indices, 30 * 3 * sizeof(uint32_t));
    {
        const float pv[12] = { 0.4f, 0.4f, 0.9f, 0.6f, 0.4f, 0.9f, 0.6f, 0.6f, 0.9f, 0.4f, 0.6f, 0.9f };
        const uint32_t base = (uint32_t)room_mesh.vertex_count;
        const uint32_t pf[6] = { base, base + 2, base + 1, base, base + 3, base + 2 };
        memcpy(xyz + 3 * room_mesh.vertex_count, pv, sizeof pv);
        memcpy(idx + 90, pf, sizeof pf);
    }
    m.xyz = xyz, m.vertex_count = room_mesh.vertex_count + 4, m.indices = idx, m.triangle_count = 32;
    memset(em, 0, sizeof em);
    em[90] = em[91] = em[92] = em[93] = em[94] = em[95] = 5.0f;
    memset(&sc, 0, sizeof sc);
    sc.mesh = &m, sc.emission = em;
    room_view(&view, W, H);
    out.direct = dir, out.indirect = ind, out.total = NULL;
    o.iterations = 32;
    o.resolution = 24;
    CHECK_EQ_STATUS(hfvis_volgi_render(&sc, NULL, &view, &o, &out, NULL), HFVIS_OK);
    for (px = 0; px < (size_t)W * H; px++) {
        if (ind[3 * px] > 0.0f) lit++;
        if (dir[3 * px] == 5.0f) glow++;                      /* the panel seen from below */
        CHECK(dir[3 * px] == 0.0f || dir[3 * px] == 5.0f);    /* no lights: emission only */
    }
    CHECK(lit > W * H / 3);
    CHECK(glow > 0);
    free(xyz), free(idx);
    hfvis_mesh_free(NULL, &room_mesh);
}

/* Absolute scale: two parallel plates (emitter radiance L, absorbing receiver at distance h),
 * the normalised transfer. The exact irradiance at the receiver's centre is (view factor of the
 * emitter) pi L; report the ratio, and bound it loosely (the SH diffusion is an approximation). */
TEST(volgi_parallel_plates_scale)
{
    enum { N = 41, Z = 12 };
    tg t;
    hfvis_volgi_geometry geo;
    hfvis_volgi_options o = hfvis_volgi_options_default();
    float *p, *a, *rad, E[3];
    int i, j, tr;
    double A = 20.5 / 9.0, F, ratio[4];
    const double down[3] = { 0, 0, -1 };
    /* point under the centre of a square of half-side a at height h: 4 corner rectangles */
    F = 4.0 / (2.0 * PI) * 2.0 * (A / sqrt(1.0 + A * A) * atan(A / sqrt(1.0 + A * A)));
    tg_init(&t, N, N, Z, 1, 1, 1);
    rad = (float *)calloc(3 * t.n, sizeof(float));
    for (j = 0; j < N; j++)
        for (i = 0; i < N; i++) {
            size_t e = lin3(&t.grid, i, j, 1);
            tg_set(&t, i, j, 1, 1.0f, 0, 0, 1);
            tg_set(&t, i, j, 10, 1.0f, 0, 0, -1);
            rad[3 * e] = rad[3 * e + 1] = rad[3 * e + 2] = 1.0f;
        }
    p = sh_alloc(t.n), a = sh_alloc(t.n);
    geo = tg_geo(&t, 0);
    o.reflectance_source = HFVIS_VOLGI_REFLECTANCE_CONSTANT;
    o.reflectance = 0.0f;
    for (tr = 0; tr < 4; tr++) {
        const double c[3] = { 20.5, 20.5, 10.5 };
        o.transfer = (hfvis_volgi_transfer)(tr & 1);
        o.paths = (hfvis_volgi_paths)(tr >> 1);
        CHECK_EQ_STATUS(hfvis_volgi_inject(&geo, rad, p), HFVIS_OK);
        memset(a, 0, 12 * t.n * sizeof(float));
        CHECK_EQ_STATUS(hfvis_volgi_propagate(&geo, &o, 60, p, a, NULL), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_volgi_gather(&geo, a, &o, c, down, E), HFVIS_OK);
        ratio[tr] = (double)E[0] / (F * PI);
    }
    printf("     parallel plates (h = 9 voxels): E / exact = %.4f (ALL/CONE), %.4f (ALL/NORMALIZED), "
           "%.4f (VOID/CONE), %.4f (VOID/NORMALIZED)\n", ratio[0], ratio[1], ratio[2], ratio[3]);
    tg_free(&t);
    free(p), free(a), free(rad);
}

/* ---- bad arguments ------------------------------------------------------------------------ */

TEST(volgi_bad_arguments)
{
    tg t;
    hfvis_volgi_geometry geo, bad;
    hfvis_volgi_options o;
    hfvis_volgi_energy e, e0;
    float *p, *q, *a, *q0, rad[3 * 27], E[3] = { 9, 9, 9 };
    const double pt[3] = { 0.5, 0.5, 0.5 }, up[3] = { 0, 0, 1 }, zero[3] = { 0, 0, 0 };
    double out4[4] = { 9, 9, 9, 9 }, nanv[3];
    size_t v;
    int i;
    nanv[0] = 0.0, nanv[1] = (double)NAN, nanv[2] = 1.0;
    tg_init(&t, 3, 3, 3, 1, 1, 1);
    p = sh_alloc(t.n), q = sh_alloc(t.n), a = sh_alloc(t.n), q0 = sh_alloc(t.n);
    for (v = 0; v < 27 * 3; v++) rad[v] = 1.0f;
    for (v = 0; v < 12 * t.n; v++) q[v] = q0[v] = 3.0f;
    geo = tg_geo(&t, 0);
    memset(&e0, 0x5a, sizeof e0);
    e = e0;
    /* SH helpers */
    CHECK_EQ_STATUS(hfvis_volgi_sh_basis(NULL, out4), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_sh_basis(up, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_sh_basis(zero, out4), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_sh_clamped_cosine(nanv, out4), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_sh_cone(up, 0.0, out4), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_sh_cone(up, 3.2, out4), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_sh_cone(up, (double)NAN, out4), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(out4[0] == 9.0 && out4[3] == 9.0);
    /* geometry */
    bad = geo, bad.occupancy = NULL;
    CHECK_EQ_STATUS(hfvis_volgi_inject(&bad, rad, p), HFVIS_ERR_INVALID_ARGUMENT);
    bad = geo, bad.normal = NULL;
    CHECK_EQ_STATUS(hfvis_volgi_propagate_step(&bad, NULL, p, q, a, &e), HFVIS_ERR_INVALID_ARGUMENT);
    bad = geo, bad.grid.dims[1] = 0;
    CHECK_EQ_STATUS(hfvis_volgi_propagate(&bad, NULL, 2, p, a, &e), HFVIS_ERR_INVALID_ARGUMENT);
    bad = geo, bad.grid.cell[0] = -1.0;
    CHECK_EQ_STATUS(hfvis_volgi_gather(&bad, a, NULL, pt, up, E), HFVIS_ERR_INVALID_ARGUMENT);
    t.occ[4] = 1.5f;
    CHECK_EQ_STATUS(hfvis_volgi_propagate_step(&geo, NULL, p, q, a, &e), HFVIS_ERR_INVALID_ARGUMENT);
    t.occ[4] = NAN;
    CHECK_EQ_STATUS(hfvis_volgi_inject(&geo, rad, p), HFVIS_ERR_INVALID_ARGUMENT);
    t.occ[4] = 0.0f;
    t.nrm[5] = INFINITY;
    CHECK_EQ_STATUS(hfvis_volgi_propagate_step_reference(&geo, NULL, p, q, a, &e), HFVIS_ERR_INVALID_ARGUMENT);
    t.nrm[5] = 0.0f;
    geo.albedo = t.alb;
    t.alb[2] = 1.5f;
    CHECK_EQ_STATUS(hfvis_volgi_propagate_step(&geo, NULL, p, q, a, &e), HFVIS_ERR_INVALID_ARGUMENT);
    t.alb[2] = 0.0f;
    geo.albedo = NULL;
    /* values */
    rad[7] = -1.0f;
    CHECK_EQ_STATUS(hfvis_volgi_inject(&geo, rad, p), HFVIS_ERR_INVALID_ARGUMENT);
    rad[7] = NAN;
    CHECK_EQ_STATUS(hfvis_volgi_inject(&geo, rad, p), HFVIS_ERR_INVALID_ARGUMENT);
    rad[7] = 1.0f;
    CHECK_EQ_STATUS(hfvis_volgi_inject(NULL, rad, p), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_inject(&geo, NULL, p), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_inject(&geo, rad, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    p[17] = NAN;
    CHECK_EQ_STATUS(hfvis_volgi_propagate_step(&geo, NULL, p, q, a, &e), HFVIS_ERR_INVALID_ARGUMENT);
    p[17] = 2e20f;
    CHECK_EQ_STATUS(hfvis_volgi_propagate(&geo, NULL, 1, p, a, &e), HFVIS_ERR_INVALID_ARGUMENT);
    p[17] = 0.0f;
    a[3] = -INFINITY;
    CHECK_EQ_STATUS(hfvis_volgi_propagate_step(&geo, NULL, p, q, a, &e), HFVIS_ERR_INVALID_ARGUMENT);
    a[3] = 0.0f;
    CHECK_EQ_STATUS(hfvis_volgi_propagate_step(&geo, NULL, NULL, q, a, &e), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_propagate_step(&geo, NULL, p, NULL, a, &e), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_propagate_step(&geo, NULL, p, q, NULL, &e), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_propagate(&geo, NULL, -1, p, a, &e), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_propagate(&geo, NULL, HFVIS_VOLGI_MAX_ITERATIONS + 1, p, a, &e),
                    HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_propagate(&geo, NULL, 0, p, a, &e), HFVIS_OK);
    /* options */
    for (i = 0; i < 11; i++) {
        o = hfvis_volgi_options_default();
        switch (i) {
        case 9: o.paths = (hfvis_volgi_paths)2; break;
        case 10: o.resolution = HFVIS_VOLGI_MAX_RESOLUTION + 1; break;
        case 0: o.transfer = (hfvis_volgi_transfer)7; break;
        case 1: o.reflection = (hfvis_volgi_reflection)-1; break;
        case 2: o.reflectance_source = (hfvis_volgi_reflectance)3; break;
        case 3: o.reflectance_source = HFVIS_VOLGI_REFLECTANCE_CONSTANT, o.reflectance = 1.5f; break;
        case 4: o.reflectance_source = HFVIS_VOLGI_REFLECTANCE_CONSTANT, o.reflectance = NAN; break;
        case 5: o.gather_scale = -1.0; break;
        case 6: o.shadow_bias = (double)INFINITY; break;
        case 7: o.iterations = -3; break;
        default: o.reflectance_source = HFVIS_VOLGI_REFLECTANCE_ALBEDO; break; /* albedo NULL */
        }
        CHECK_EQ_STATUS(hfvis_volgi_propagate_step(&geo, &o, p, q, a, &e), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_volgi_propagate(&geo, &o, 1, p, a, &e), HFVIS_ERR_INVALID_ARGUMENT);
        if (i != 8) CHECK_EQ_STATUS(hfvis_volgi_gather(&geo, a, &o, pt, up, E), HFVIS_ERR_INVALID_ARGUMENT);
    }
    CHECK(memcmp(q, q0, 12 * t.n * sizeof(float)) == 0);
    CHECK(memcmp(&e, &e0, sizeof e) == 0);
    /* resolve: the defaults filled in, the same rejections */
    {
        hfvis_volgi_options r, z;
        memset(&z, 0, sizeof z);
        CHECK_EQ_STATUS(hfvis_volgi_options_resolve(&z, &r), HFVIS_OK);
        CHECK(r.iterations == 64 && r.resolution == 32 && r.reflectance == 0.5f
              && r.gather_scale == 12.0 / 7.0 && r.paths == HFVIS_VOLGI_PATHS_ALL && r.shadow_bias == 0.0);
        CHECK_EQ_STATUS(hfvis_volgi_options_resolve(NULL, &r), HFVIS_OK);
        CHECK(r.iterations == 64);
        z.reflectance_source = HFVIS_VOLGI_REFLECTANCE_CONSTANT, z.reflectance = 0.25f;
        CHECK_EQ_STATUS(hfvis_volgi_options_resolve(&z, &r), HFVIS_OK);
        CHECK(r.reflectance == 0.25f);
        z.paths = (hfvis_volgi_paths)2;
        r.iterations = -7;
        CHECK_EQ_STATUS(hfvis_volgi_options_resolve(&z, &r), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK(r.iterations == -7);
        CHECK_EQ_STATUS(hfvis_volgi_options_resolve(NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
        z = hfvis_volgi_options_default();
        z.resolution = 1;
        CHECK_EQ_STATUS(hfvis_volgi_options_resolve(&z, &r), HFVIS_ERR_INVALID_ARGUMENT);
    }
    /* gather */
    CHECK_EQ_STATUS(hfvis_volgi_gather(&geo, a, NULL, pt, zero, E), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_gather(&geo, a, NULL, nanv, up, E), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_gather(&geo, NULL, NULL, pt, up, E), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_gather(&geo, a, NULL, pt, up, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(E[0] == 9.0f);
    tg_free(&t);
    free(p), free(q), free(a), free(q0);
}

TEST(volgi_bad_scene_arguments)
{
    room r;
    hfvis_volume_grid g, badg;
    hfvis_volgi_scene sc;
    hfvis_volgi_light L;
    hfvis_view view;
    hfvis_volgi_outputs out;
    hfvis_bvh wrong;
    float occ[8], nrm[24], rad[24], E[3] = { 7, 7, 7 }, px[3 * 16];
    const double pt[3] = { 0.5, 0.5, 0.0 }, up[3] = { 0, 0, 1 };
    int i;
    room_init(&r);
    memset(&g, 0, sizeof g);
    g.dims[0] = g.dims[1] = g.dims[2] = 2;
    g.cell[0] = g.cell[1] = g.cell[2] = 0.5;
    for (i = 0; i < 8; i++) occ[i] = 5.0f;
    room_view(&view, 4, 4);
    for (i = 0; i < 48; i++) px[i] = 5.0f;
    out.direct = px, out.indirect = NULL, out.total = NULL;
    /* lights */
    for (i = 0; i < 10; i++) {
        sc = r.scene;
        L = r.light;
        sc.lights = &L;
        switch (i) {
        case 0: L.type = (hfvis_volgi_light_type)9; break;
        case 1: L.intensity[1] = -1.0f; break;
        case 2: L.position[0] = (double)NAN; break;
        case 3: L.type = HFVIS_VOLGI_LIGHT_DIRECTIONAL; break; /* zero direction */
        case 4: L.type = HFVIS_VOLGI_LIGHT_SPOT, L.direction[2] = -1, L.spot_outer_rad = 0.0; break;
        case 5: L.type = HFVIS_VOLGI_LIGHT_SPOT, L.direction[2] = -1, L.spot_inner_rad = 0.5,
                L.spot_outer_rad = 0.4; break;
        case 6: L.type = HFVIS_VOLGI_LIGHT_SPOT, L.direction[2] = -1, L.spot_outer_rad = 4.0; break;
        case 7: sc.light_count = -1; break;
        case 8: sc.lights = NULL; break;
        default: L.intensity[0] = INFINITY; break;
        }
        CHECK_EQ_STATUS(hfvis_volgi_direct_irradiance(&sc, NULL, pt, up, 0, E), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_volgi_voxelize(&sc, &g, NULL, occ, nrm, NULL, rad, NULL), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_volgi_render(&sc, NULL, &view, NULL, &out, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    }
    CHECK(E[0] == 7.0f && occ[0] == 5.0f && px[0] == 5.0f);
    /* materials and the BVH */
    sc = r.scene;
    r.albedo[5] = 1.5f;
    CHECK_EQ_STATUS(hfvis_volgi_voxelize(&sc, &g, NULL, occ, nrm, NULL, rad, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    r.albedo[5] = 0.5f;
    {
        float em[90];
        memset(em, 0, sizeof em);
        em[3] = NAN;
        sc.emission = em;
        CHECK_EQ_STATUS(hfvis_volgi_render(&sc, NULL, &view, NULL, &out, NULL), HFVIS_ERR_INVALID_ARGUMENT);
        sc.emission = NULL;
    }
    wrong = r.bvh;
    wrong.triangle_count = 3;
    sc.bvh = &wrong;
    CHECK_EQ_STATUS(hfvis_volgi_voxelize(&sc, &g, NULL, occ, nrm, NULL, rad, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_direct_irradiance(&sc, NULL, pt, up, 0, E), HFVIS_ERR_INVALID_ARGUMENT);
    sc.bvh = NULL;
    CHECK_EQ_STATUS(hfvis_volgi_direct_irradiance(&sc, NULL, pt, up, 0, E), HFVIS_ERR_INVALID_ARGUMENT);
    sc = r.scene;
    CHECK_EQ_STATUS(hfvis_volgi_direct_irradiance(&sc, NULL, pt, NULL, 0, E), HFVIS_ERR_INVALID_ARGUMENT);
    {
        const double big[3] = { 1e31, 0, 0 };
        CHECK_EQ_STATUS(hfvis_volgi_direct_irradiance(&sc, NULL, big, up, 0, E), HFVIS_ERR_INVALID_ARGUMENT);
    }
    /* grids and outputs */
    badg = g, badg.dims[0] = 0;
    CHECK_EQ_STATUS(hfvis_volgi_voxelize(&sc, &badg, NULL, occ, nrm, NULL, rad, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_render(&sc, &badg, &view, NULL, &out, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_voxelize(&sc, &g, NULL, NULL, nrm, NULL, rad, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_voxelize(&sc, &g, NULL, occ, NULL, NULL, rad, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_voxelize(&sc, &g, NULL, occ, nrm, NULL, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_voxelize(NULL, &g, NULL, occ, nrm, NULL, rad, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_render(NULL, NULL, &view, NULL, &out, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_render(&sc, NULL, NULL, NULL, &out, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volgi_render(&sc, NULL, &view, NULL, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    {
        hfvis_volgi_options o = hfvis_volgi_options_default();
        hfvis_view v2 = view;
        o.resolution = 1;
        CHECK_EQ_STATUS(hfvis_volgi_render(&sc, NULL, &view, &o, &out, NULL), HFVIS_ERR_INVALID_ARGUMENT);
        o = hfvis_volgi_options_default();
        o.iterations = HFVIS_VOLGI_MAX_ITERATIONS + 1;
        CHECK_EQ_STATUS(hfvis_volgi_render(&sc, NULL, &view, &o, &out, NULL), HFVIS_ERR_INVALID_ARGUMENT);
        v2.width = 0;
        CHECK_EQ_STATUS(hfvis_volgi_render(&sc, NULL, &v2, NULL, &out, NULL), HFVIS_ERR_INVALID_ARGUMENT);
        v2 = view;
        v2.proj[0] = (double)NAN;
        CHECK_EQ_STATUS(hfvis_volgi_render(&sc, NULL, &v2, NULL, &out, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    }
    {
        hfvis_mesh bm = r.mesh;
        bm.xyz = NULL;
        sc.mesh = &bm;
        sc.bvh = NULL;
        CHECK_EQ_STATUS(hfvis_volgi_render(&sc, NULL, &view, NULL, &out, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    }
    CHECK(occ[0] == 5.0f && px[0] == 5.0f);
    room_free(&r);
}

/* ---- allocation failures at every site ---------------------------------------------------- */

TEST(volgi_alloc_failures)
{
    room r;
    tg t;
    hfvis_volgi_geometry geo;
    hfvis_volgi_options o = hfvis_volgi_options_default();
    hfvis_allocator al;
    test_counting c;
    float *p0, *rad, *p, *a, *p_keep;
    int k, n, fn;
    room_init(&r);
    room_volume(&r, 10, &t, &p0, &rad);
    geo = tg_geo(&t, 1);
    p = sh_alloc(t.n), a = sh_alloc(t.n), p_keep = sh_alloc(t.n);
    al.alloc = test_count_alloc, al.free = test_count_free, al.user = &c;
    o.alloc = &al;
    /* the loop (one block) and the normalised step (one block), both transfers */
    for (fn = 0; fn < 3; fn++) {
        o.transfer = fn == 0 ? HFVIS_VOLGI_TRANSFER_CONE : HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED;
        memcpy(p, p0, 12 * t.n * sizeof(float));
        memset(&c, 0, sizeof c);
        if (fn < 2) CHECK_EQ_STATUS(hfvis_volgi_propagate(&geo, &o, 3, p, a, NULL), HFVIS_OK);
        else CHECK_EQ_STATUS(hfvis_volgi_propagate_step(&geo, &o, p0, p, a, NULL), HFVIS_OK);
        n = c.allocs;
        CHECK(n == 1 && c.live == 0);
        for (k = 1; k <= n; k++) {
            memset(&c, 0, sizeof c);
            c.fail_at = k;
            memcpy(p, p0, 12 * t.n * sizeof(float));
            memcpy(p_keep, p, 12 * t.n * sizeof(float));
            memset(a, 0, 12 * t.n * sizeof(float));
            if (fn < 2) CHECK_EQ_STATUS(hfvis_volgi_propagate(&geo, &o, 3, p, a, NULL), HFVIS_ERR_OUT_OF_MEMORY);
            else CHECK_EQ_STATUS(hfvis_volgi_propagate_step(&geo, &o, p0, p, a, NULL), HFVIS_ERR_OUT_OF_MEMORY);
            CHECK(c.live == 0 && c.allocs == k && c.frees == k - 1);
            CHECK(memcmp(p, p_keep, 12 * t.n * sizeof(float)) == 0);
            {
                size_t v;
                int touched = 0;
                for (v = 0; v < 12 * t.n; v++) touched |= a[v] != 0.0f;
                CHECK(!touched);
            }
        }
    }
    /* the reference and the default step allocate nothing */
    o.transfer = HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED;
    memset(&c, 0, sizeof c);
    CHECK_EQ_STATUS(hfvis_volgi_propagate_step_reference(&geo, &o, p0, p, a, NULL), HFVIS_OK);
    o.transfer = HFVIS_VOLGI_TRANSFER_CONE;
    CHECK_EQ_STATUS(hfvis_volgi_propagate_step(&geo, &o, p0, p, a, NULL), HFVIS_OK);
    CHECK(c.allocs == 0);
    /* voxelize: its scratch, plus the BVH's blocks without scene->bvh */
    for (fn = 0; fn < 2; fn++) {
        hfvis_volgi_scene sc = r.scene;
        float *occ = (float *)malloc(t.n * sizeof(float)), *nrm = (float *)malloc(3 * t.n * sizeof(float));
        float *rd = (float *)malloc(3 * t.n * sizeof(float));
        if (fn == 1) sc.bvh = NULL;
        memset(&c, 0, sizeof c);
        CHECK_EQ_STATUS(hfvis_volgi_voxelize(&sc, &t.grid, &o, occ, nrm, NULL, rd, NULL), HFVIS_OK);
        n = c.allocs;
        CHECK(n == (fn == 0 ? 1 : 5) && c.live == 0);
        for (k = 1; k <= n; k++) {
            size_t v;
            int touched = 0;
            memset(&c, 0, sizeof c);
            c.fail_at = k;
            for (v = 0; v < t.n; v++) occ[v] = -1.0f;
            CHECK_EQ_STATUS(hfvis_volgi_voxelize(&sc, &t.grid, &o, occ, nrm, NULL, rd, NULL),
                            HFVIS_ERR_OUT_OF_MEMORY);
            CHECK(c.live == 0 && c.allocs == k && c.frees == k - 1);
            for (v = 0; v < t.n; v++) touched |= occ[v] != -1.0f;
            CHECK(!touched);
        }
        free(occ), free(nrm), free(rd);
    }
    /* render: every site (G-buffer, rasterizer scratch, BVH, geometry, voxelizer scratch, SH
     * volumes, propagation scratch) */
    for (fn = 0; fn < 2; fn++) {
        enum { W = 12, H = 10 };
        hfvis_volgi_scene sc = r.scene;
        hfvis_view view;
        hfvis_volgi_outputs out;
        hfvis_volgi_render_info info, info0;
        float img[3 * W * H];
        if (fn == 1) sc.bvh = NULL;
        room_view(&view, W, H);
        out.direct = NULL, out.indirect = NULL, out.total = img;
        o.resolution = 10;
        o.iterations = 4;
        memset(&c, 0, sizeof c);
        CHECK_EQ_STATUS(hfvis_volgi_render(&sc, NULL, &view, &o, &out, &info), HFVIS_OK);
        n = c.allocs;
        CHECK(n == (fn == 0 ? 6 : 10) && c.live == 0);
        for (k = 1; k <= n; k++) {
            int i, touched = 0;
            memset(&c, 0, sizeof c);
            c.fail_at = k;
            for (i = 0; i < 3 * W * H; i++) img[i] = -2.0f;
            memset(&info0, 0x5a, sizeof info0);
            info = info0;
            CHECK_EQ_STATUS(hfvis_volgi_render(&sc, NULL, &view, &o, &out, &info), HFVIS_ERR_OUT_OF_MEMORY);
            CHECK(c.live == 0 && c.allocs == k && c.frees == k - 1);
            for (i = 0; i < 3 * W * H; i++) touched |= img[i] != -2.0f;
            CHECK(!touched);
            CHECK(memcmp(&info, &info0, sizeof info) == 0);
        }
    }
    tg_free(&t);
    free(p0), free(rad), free(p), free(a), free(p_keep);
    room_free(&r);
}

int main(int argc, char **argv)
{
    TEST_INIT(argc, argv);
    RUN(volgi_sh_constants);
    RUN(volgi_sh_projection_quadrature);
    RUN(volgi_sh_is_bands_0_1);
    RUN(volgi_inject);
    RUN(volgi_first_step_fluxes);
    RUN(volgi_border_escape);
    RUN(volgi_mirror_layer);
    RUN(volgi_reflection_variants);
    RUN(volgi_fast_equals_reference);
    RUN(volgi_energy_accounting);
    RUN(volgi_closed_box_absorbs);
    RUN(volgi_linearity);
    RUN(volgi_gather);
    RUN(volgi_direct_light);
    RUN(volgi_voxelize_plane);
    RUN(volgi_alg4_three_axes_max);
    RUN(volgi_grid_fit);
    RUN(volgi_room_colour_bleeding);
    RUN(volgi_render_matches_parts);
    RUN(volgi_emissive_voxels);
    RUN(volgi_parallel_plates_scale);
    RUN(volgi_bad_arguments);
    RUN(volgi_bad_scene_arguments);
    RUN(volgi_alloc_failures);
    return TEST_DONE();
}
