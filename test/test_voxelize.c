/* test_voxelize.c - surface voxelizers and the Volume Buffer attribute path ([G12] ch. 5 Alg. 4,
 * ch. 6 Alg. 5-6). Exact analytic counts of the fast
 * routines against their per-voxel oracle bit for bit, the output-vertex holes, 6-separation of
 * the three-axis variant, blends, callbacks, bad arguments. */
#include "hfvis.h"
#include "test.h"

#include <stdint.h>
#include <stdlib.h>

/* Icosphere area, quoted to 0.1: 5025.0 */
#define VOX_ICO_AREA_TOL 0.05
/* Spec §3.13.4: "within +-2 % of 0.8312 * area" for large smooth closed surfaces */
#define VOX_AREA_PREDICTION_REL 0.02
/* GS slicing may differ from the pixel rule only where a pixel centre lies within rounding of a
 * slab plane or a triangle edge: coordinates here are < 100 voxels, double rounding ~1e-14 */
#define VOX_NEAR_TIE 1e-9
/* Fragment attributes are floats computed in double: barycentrics sum to 1 within a few ulps */
#define VOX_BARY_TOL 1e-5
/* Fragment position (float of a double) against the pixel centre it was sampled at, in voxels
 * for coordinates < 100: float ulp 8e-6 */
#define VOX_POS_TOL 3e-5
/* radiance = albedo E / pi + emission in double rounded to float once */
#define VOX_RAD_TOL 1e-6

/* ---- helpers ------------------------------------------------------------------------------ */

static uint64_t vox_rng = 1;
static void vox_seed(uint64_t s) { vox_rng = s * 0x9E3779B97F4A7C15ull + 1; }
static double vox_unit(void) /* [0, 1), splitmix64 */
{
    uint64_t z = (vox_rng += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return (double)(z >> 11) * (1.0 / 9007199254740992.0);
}

static hfvis_volume_grid vox_grid(int nx, int ny, int nz, double ox, double oy, double oz, double cx,
                                  double cy, double cz)
{
    hfvis_volume_grid g;
    g.dims[0] = nx, g.dims[1] = ny, g.dims[2] = nz;
    g.origin[0] = ox, g.origin[1] = oy, g.origin[2] = oz;
    g.cell[0] = cx, g.cell[1] = cy, g.cell[2] = cz;
    return g;
}

static hfvis_volume_grid vox_unit_grid(int n) { return vox_grid(n, n, n, 0, 0, 0, 1, 1, 1); }

/* A mesh owned by the test (malloc'd arrays). */
typedef struct vox_soup {
    float *xyz;
    uint32_t *idx;
    size_t nv, nt;
    hfvis_mesh m;
} vox_soup;

static void vox_soup_init(vox_soup *s, size_t max_tris)
{
    s->xyz = (float *)malloc(sizeof(float) * 9 * (max_tris ? max_tris : 1));
    s->idx = (uint32_t *)malloc(sizeof(uint32_t) * 3 * (max_tris ? max_tris : 1));
    s->nv = s->nt = 0;
}
static void vox_soup_tri(vox_soup *s, const double a[3], const double b[3], const double c[3])
{
    int k;
    for (k = 0; k < 3; k++) {
        s->xyz[3 * s->nv + (size_t)k] = (float)a[k];
        s->xyz[3 * s->nv + 3 + (size_t)k] = (float)b[k];
        s->xyz[3 * s->nv + 6 + (size_t)k] = (float)c[k];
        s->idx[3 * s->nt + (size_t)k] = (uint32_t)(s->nv + (size_t)k);
    }
    s->nv += 3;
    s->nt++;
}
static const hfvis_mesh *vox_soup_mesh(vox_soup *s)
{
    s->m.xyz = s->xyz;
    s->m.vertex_count = s->nv;
    s->m.indices = s->idx;
    s->m.triangle_count = s->nt;
    return &s->m;
}
static void vox_soup_free(vox_soup *s)
{
    free(s->xyz);
    free(s->idx);
}

/* Hand-made closed box [lo, hi] (12 triangles, outward). */
static void vox_box(vox_soup *s, const double lo[3], const double hi[3])
{
    static const int f[12][3] = { { 0, 2, 6 }, { 0, 6, 4 }, { 1, 5, 7 }, { 1, 7, 3 }, { 0, 4, 5 }, { 0, 5, 1 },
                                  { 2, 3, 7 }, { 2, 7, 6 }, { 0, 1, 3 }, { 0, 3, 2 }, { 4, 6, 7 }, { 4, 7, 5 } };
    double c[8][3];
    int i, a;
    for (i = 0; i < 8; i++)
        for (a = 0; a < 3; a++) c[i][a] = (i >> a) & 1 ? hi[a] : lo[a];
    for (i = 0; i < 12; i++) vox_soup_tri(s, c[f[i][0]], c[f[i][1]], c[f[i][2]]);
}

static float *vox_storage(const hfvis_volume_grid *g, int channels)
{
    size_t n = hfvis_volume_floats(g, channels);
    return (float *)malloc(sizeof(float) * (n ? n : 1));
}

static hfvis_voxelize_options vox_opts(hfvis_voxelize_method m, hfvis_voxelize_axes ax, int V)
{
    hfvis_voxelize_options o = hfvis_voxelize_options_default();
    o.method = m;
    o.axes = ax;
    o.max_output_vertices = V;
    return o;
}

/* Occupancy voxel count of the fast routine; also checks the oracle, the occupancy routine and
 * the fragment count (each voxel written once per fragment) against it. */
static size_t vox_count(const hfvis_mesh *m, const hfvis_volume_grid *g, const hfvis_voxelize_options *o,
                        uint8_t *occ_out)
{
    float *a = vox_storage(g, 1), *b = vox_storage(g, 1);
    size_t n = hfvis_volume_floats(g, 1), fa = 0, fb = 0, cnt = 0, i;
    uint8_t *occ = (uint8_t *)malloc(n);
    hfvis_volume va, vb;
    CHECK_EQ_STATUS(hfvis_volume_init(&va, g, 1, a, HFVIS_BLEND_MAX), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_volume_init(&vb, g, 1, b, HFVIS_BLEND_MAX), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_voxelize_surface(m, &va, o, &fa), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_voxelize_surface_reference(m, &vb, o, &fb), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_voxelize_occupancy(m, g, o, occ), HFVIS_OK);
    CHECK(fa == fb);
    CHECK(memcmp(a, b, n * sizeof(float)) == 0);
    for (i = 0; i < n; i++) {
        if (a[i] != 0.0f) cnt++;
        if ((a[i] != 0.0f) != (occ[i] != 0)) break;
        if (a[i] != 0.0f && a[i] != 1.0f) break;
    }
    CHECK(i == n);
    if (occ_out) memcpy(occ_out, occ, n);
    free(occ);
    free(a);
    free(b);
    return cnt;
}

static size_t vox_lin(const hfvis_volume_grid *g, int i, int j, int k)
{
    return ((size_t)k * (size_t)g->dims[1] + (size_t)j) * (size_t)g->dims[0] + (size_t)i;
}

/* ---- API basics --------------------------------------------------------------------------- */

TEST(gs_max_slices)
{
    /* [G12] ch. 6; docs/errata.md E58: GS floor((V-3)/4): 7, 11, 15, 19 -> 1..4; PS floor(V/3): 6, 9, 12, 15 -> 2..5 */
    CHECK(hfvis_gs_max_slices(7, 0) == 1 && hfvis_gs_max_slices(11, 0) == 2);
    CHECK(hfvis_gs_max_slices(15, 0) == 3 && hfvis_gs_max_slices(19, 0) == 4);
    CHECK(hfvis_gs_max_slices(10, 0) == 1 && hfvis_gs_max_slices(6, 0) == 0);
    CHECK(hfvis_gs_max_slices(3, 0) == 0 && hfvis_gs_max_slices(0, 0) == 0);
    CHECK(hfvis_gs_max_slices(-5, 0) == 0 && hfvis_gs_max_slices(-5, 1) == 0);
    CHECK(hfvis_gs_max_slices(3, 1) == 1 && hfvis_gs_max_slices(6, 1) == 2);
    CHECK(hfvis_gs_max_slices(9, 1) == 3 && hfvis_gs_max_slices(12, 1) == 4);
    CHECK(hfvis_gs_max_slices(15, 1) == 5 && hfvis_gs_max_slices(2, 1) == 0);
    CHECK(hfvis_gs_max_slices(1024, 0) == 255 && hfvis_gs_max_slices(1024, 1) == 341);
}

TEST(options_default)
{
    hfvis_voxelize_options d = hfvis_voxelize_options_default(), z;
    memset(&z, 0, sizeof z);
    CHECK(d.method == HFVIS_VOXELIZE_PIXEL_RULE && d.axes == HFVIS_AXES_DOMINANT);
    CHECK(d.max_output_vertices == 0 && d.fragment == NULL && d.user == NULL && d.alloc == NULL);
    CHECK(d.method == z.method && d.axes == z.axes);
}


/* ---- analytic counts ----------------------------------------------------------- */

static const hfvis_voxelize_method vox_methods[3] = { HFVIS_VOXELIZE_PIXEL_RULE, HFVIS_VOXELIZE_GS_SLICING,
                                                      HFVIS_VOXELIZE_FRAGMENT_CLIPPING };

/* §3.13.1: cube [2.25, 10.25]^3 in 16^3: 6*64 - 3*8 + 1 = 361, dominant = ALL_AXES, every
 * method (each face covers pixel centres 2.5..9.5, faces at slabs 2 and 10). */
TEST(cube_361)
{
    const double lo[3] = { 2.25, 2.25, 2.25 }, hi[3] = { 10.25, 10.25, 10.25 };
    hfvis_volume_grid g = vox_unit_grid(16);
    hfvis_voxelize_options o;
    vox_soup s;
    hfvis_mesh gm;
    int mi;
    vox_soup_init(&s, 12);
    vox_box(&s, lo, hi);
    for (mi = 0; mi < 3; mi++) {
        o = vox_opts(vox_methods[mi], HFVIS_AXES_DOMINANT, 0);
        CHECK(vox_count(vox_soup_mesh(&s), &g, &o, NULL) == 361);
        o.axes = HFVIS_AXES_ALL;
        CHECK(vox_count(vox_soup_mesh(&s), &g, &o, NULL) == 361);
    }
    /* the mesh part's box (other triangulation and vertex sharing) gives the same */
    CHECK_EQ_STATUS(hfvis_mesh_box(NULL, lo, hi, &gm), HFVIS_OK);
    for (mi = 0; mi < 3; mi++) {
        o = vox_opts(vox_methods[mi], HFVIS_AXES_DOMINANT, 0);
        CHECK(vox_count(&gm, &g, &o, NULL) == 361);
        o.axes = HFVIS_AXES_ALL;
        CHECK(vox_count(&gm, &g, &o, NULL) == 361);
    }
    hfvis_mesh_free(NULL, &gm);
    vox_soup_free(&s);
}

/* §3.13.2: box [2.2,3.3,4.4]-[12.7,9.6,13.1] in 16^3: dominant = ALL_AXES = 410
 * (faces 2*(63 + 99 + 77) = 478, minus 72 shared edge voxels, plus 4 corners). */
TEST(box_410)
{
    const double lo[3] = { 2.2, 3.3, 4.4 }, hi[3] = { 12.7, 9.6, 13.1 };
    hfvis_volume_grid g = vox_unit_grid(16);
    hfvis_voxelize_options o;
    vox_soup s;
    hfvis_mesh gm;
    int mi;
    vox_soup_init(&s, 12);
    vox_box(&s, lo, hi);
    CHECK_EQ_STATUS(hfvis_mesh_box(NULL, lo, hi, &gm), HFVIS_OK);
    for (mi = 0; mi < 3; mi++) {
        o = vox_opts(vox_methods[mi], HFVIS_AXES_DOMINANT, 0);
        CHECK(vox_count(vox_soup_mesh(&s), &g, &o, NULL) == 410);
        CHECK(vox_count(&gm, &g, &o, NULL) == 410);
        o.axes = HFVIS_AXES_ALL;
        CHECK(vox_count(vox_soup_mesh(&s), &g, &o, NULL) == 410);
        CHECK(vox_count(&gm, &g, &o, NULL) == 410);
    }
    hfvis_mesh_free(NULL, &gm);
    vox_soup_free(&s);
}

/* §3.13.3: triangle (0.2,0.2,0.5) (8.7,0.2,0.5) (0.2,8.7,0.5): 36 voxels, the centres with
 * i + j <= 7, all in slice 0. */
TEST(triangle_36)
{
    const double a[3] = { 0.2, 0.2, 0.5 }, b[3] = { 8.7, 0.2, 0.5 }, c[3] = { 0.2, 8.7, 0.5 };
    hfvis_volume_grid g = vox_unit_grid(16);
    hfvis_voxelize_options o;
    uint8_t occ[16 * 16 * 16];
    vox_soup s;
    int mi, ax, i, j, k, bad;
    vox_soup_init(&s, 2);
    vox_soup_tri(&s, a, b, c);
    for (mi = 0; mi < 3; mi++)
        for (ax = 0; ax < 2; ax++) {
            o = vox_opts(vox_methods[mi], ax ? HFVIS_AXES_ALL : HFVIS_AXES_DOMINANT, 0);
            CHECK(vox_count(vox_soup_mesh(&s), &g, &o, occ) == 36);
            bad = 0;
            for (k = 0; k < 16; k++)
                for (j = 0; j < 16; j++)
                    for (i = 0; i < 16; i++)
                        if ((occ[vox_lin(&g, i, j, k)] != 0) != (k == 0 && i + j <= 7)) bad++;
            CHECK(bad == 0);
        }
    /* reversed winding: same voxels */
    vox_soup_tri(&s, a, c, b);
    s.idx[0] = 3, s.idx[1] = 4, s.idx[2] = 5;
    s.nt = 1;
    o = vox_opts(HFVIS_VOXELIZE_PIXEL_RULE, HFVIS_AXES_DOMINANT, 0);
    CHECK(vox_count(vox_soup_mesh(&s), &g, &o, NULL) == 36);
    vox_soup_free(&s);
}

static double vox_mesh_area(const hfvis_mesh *m)
{
    double A = 0.0;
    size_t t;
    for (t = 0; t < m->triangle_count; t++) {
        const float *p0 = m->xyz + 3 * m->indices[3 * t], *p1 = m->xyz + 3 * m->indices[3 * t + 1],
                    *p2 = m->xyz + 3 * m->indices[3 * t + 2];
        double e1[3], e2[3], n[3];
        int a;
        for (a = 0; a < 3; a++) e1[a] = (double)p1[a] - (double)p0[a], e2[a] = (double)p2[a] - (double)p0[a];
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        A += 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    }
    return A;
}

/* §3.13.4: icosphere 20*4^5 = 20,480 triangles, radius 20 at (32.1, 31.7, 32.3) in 64^3,
 * area 5025.0: dominant 4147, ALL_AXES 4183; within 2 % of E[max |n_a|] * area =
 * 0.8311896 * 5025.0 = 4177. */
TEST(icosphere_counts)
{
    const double c[3] = { 32.1, 31.7, 32.3 };
    hfvis_volume_grid g = vox_unit_grid(64);
    hfvis_voxelize_options o;
    hfvis_mesh m;
    size_t nd[3], na[3];
    double A;
    int mi;
    CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c, 20.0, 5, &m), HFVIS_OK);
    CHECK(m.triangle_count == 20480);
    A = vox_mesh_area(&m);
    CHECK_NEAR(A, 5025.0, VOX_ICO_AREA_TOL, 0.0);
    for (mi = 0; mi < 3; mi++) {
        o = vox_opts(vox_methods[mi], HFVIS_AXES_DOMINANT, 0);
        nd[mi] = vox_count(&m, &g, &o, NULL);
        o.axes = HFVIS_AXES_ALL;
        na[mi] = vox_count(&m, &g, &o, NULL);
        CHECK_NEAR((double)nd[mi], 0.8311896 * A, 0.0, VOX_AREA_PREDICTION_REL);
        CHECK_NEAR((double)na[mi], 0.8311896 * A, 0.0, VOX_AREA_PREDICTION_REL);
    }
    printf("  icosphere r=20 (area %.2f): dominant %zu %zu %zu, all-axes %zu %zu %zu (PR GS FC), "
           "0.8312*A = %.0f\n", A, nd[0], nd[1], nd[2], na[0], na[1], na[2], 0.8311896 * A);
    CHECK(nd[0] == 4147 && na[0] == 4183);
    CHECK(nd[1] == 4147 && na[1] == 4183);
    CHECK(nd[2] == 4147 && na[2] == 4183);
    hfvis_mesh_free(NULL, &m);
}


/* ---- fast == oracle, bit for bit ---------------------------------------------------------- */

#define VOX_CB_CHANNELS 11

/* A callback whose values depend on every fragment field; channels blend with MAX, REPLACE,
 * MIN, ADD in turn, so equal volumes mean equal fragments in the same per-voxel order. */
static void vox_cb_all(const hfvis_voxel_fragment *f, float *v, void *user)
{
    size_t *calls = (size_t *)user;
    (*calls)++;
    v[0] = 1.0f;
    v[1] = (float)(f->triangle + 1u);
    v[2] = f->barycentric[0];
    v[3] = f->barycentric[1] - f->barycentric[2];
    v[4] = f->position[0];
    v[5] = f->position[1];
    v[6] = f->position[2];
    v[7] = f->normal[0] + 2.0f * f->normal[1] + 4.0f * f->normal[2];
    v[8] = (float)f->axis + 1.0f;
    v[9] = (float)(f->voxel[0] + 7 * f->voxel[1] + 49 * f->voxel[2]);
    v[10] = (float)f->triangle * 0.001f + f->barycentric[2];
    v[20] = 123.0f; /* beyond the channels: ignored, in bounds */
}

/* Runs the fast routine and the oracle with vox_cb_all into two volumes of VOX_CB_CHANNELS mixed-
 * blend channels (cleared to 0.5) and returns 1 if volumes, counts and callback calls agree. */
static int vox_same(const hfvis_mesh *m, const hfvis_volume_grid *g, const hfvis_voxelize_options *oin,
                    size_t *frags)
{
    static const hfvis_blend bl[4] = { HFVIS_BLEND_MAX, HFVIS_BLEND_REPLACE, HFVIS_BLEND_MIN, HFVIS_BLEND_ADD };
    size_t n = hfvis_volume_floats(g, VOX_CB_CHANNELS), fa = 0, fb = 0, ca = 0, cb = 0;
    float *a = vox_storage(g, VOX_CB_CHANNELS), *b = vox_storage(g, VOX_CB_CHANNELS);
    hfvis_volume va, vb;
    hfvis_voxelize_options o = *oin;
    int c, ok;
    hfvis_volume_init(&va, g, VOX_CB_CHANNELS, a, HFVIS_BLEND_MAX);
    hfvis_volume_init(&vb, g, VOX_CB_CHANNELS, b, HFVIS_BLEND_MAX);
    for (c = 0; c < VOX_CB_CHANNELS; c++) va.blend[c] = vb.blend[c] = bl[c % 4];
    hfvis_volume_clear(&va, 0.5f);
    hfvis_volume_clear(&vb, 0.5f);
    o.fragment = vox_cb_all;
    o.user = &ca;
    ok = hfvis_voxelize_surface(m, &va, &o, &fa) == HFVIS_OK;
    o.user = &cb;
    ok = ok && hfvis_voxelize_surface_reference(m, &vb, &o, &fb) == HFVIS_OK;
    ok = ok && fa == fb && ca == fa && cb == fb && memcmp(a, b, n * sizeof(float)) == 0;
    if (frags) *frags = fa;
    free(a);
    free(b);
    return ok;
}

/* Random soup: mode 0 generic float positions, sizes from 0.05 to 2x the grid, some poking out
 * of the grid; mode 1 tie-heavy (quarter-voxel coordinates on a unit grid: pixel centres on
 * edges and vertices, depths on slab boundaries); mode 2 degenerate and extreme triangles. */
static void vox_random_soup(vox_soup *s, size_t n, int mode, double N)
{
    size_t t;
    for (t = 0; t < n; t++) {
        double p[3][3], c[3], size = N * pow(2.0, -6.0 * vox_unit() + 1.0);
        int i, a;
        for (a = 0; a < 3; a++) c[a] = -0.1 * N + 1.2 * N * vox_unit();
        for (i = 0; i < 3; i++)
            for (a = 0; a < 3; a++) {
                p[i][a] = c[a] + size * (vox_unit() - 0.5);
                if (mode == 1) p[i][a] = floor(4.0 * p[i][a]) / 4.0;
            }
        if (mode == 2) {
            int kind = (int)(vox_unit() * 5.0);
            if (kind == 0) for (a = 0; a < 3; a++) p[2][a] = p[0][a] + 0.37 * (p[1][a] - p[0][a]); /* collinear-ish */
            if (kind == 1) for (a = 0; a < 3; a++) p[2][a] = p[1][a];                             /* repeated */
            if (kind == 2) for (i = 0; i < 3; i++) p[i][2] = p[0][2];                             /* axis-parallel */
            if (kind == 3) for (i = 0; i < 3; i++) p[i][0] = c[0] + 1e-3 * vox_unit();            /* near edge-on */
            if (kind == 4) for (i = 0; i < 3; i++) for (a = 0; a < 3; a++) p[i][a] = 40.0 * N * (vox_unit() - 0.5); /* huge */
        }
        vox_soup_tri(s, p[0], p[1], p[2]);
    }
}

TEST(fast_equals_reference_soups)
{
    static const hfvis_voxelize_axes axes[5] = { HFVIS_AXES_DOMINANT, HFVIS_AXES_ALL, HFVIS_AXES_ONLY_X,
                                                 HFVIS_AXES_ONLY_Y, HFVIS_AXES_ONLY_Z };
    int trial, mi, ai, bad = 0, runs = 0;
    size_t total = 0;
    for (trial = 0; trial < 12; trial++) {
        int mode = trial % 3;
        vox_soup s;
        hfvis_volume_grid g;
        double N;
        vox_seed(1000 + (uint64_t)trial);
        if (mode == 1) {
            int n = 8 + (int)(vox_unit() * 17.0);
            g = vox_unit_grid(n);
            N = (double)n;
        } else {
            g = vox_grid(5 + (int)(vox_unit() * 20.0), 5 + (int)(vox_unit() * 20.0), 5 + (int)(vox_unit() * 20.0),
                         vox_unit() - 0.5, vox_unit() - 0.5, vox_unit() - 0.5, 0.5 + vox_unit(),
                         0.5 + vox_unit(), 0.5 + vox_unit());
            N = 14.0;
        }
        vox_soup_init(&s, 60);
        vox_random_soup(&s, 60, mode, N);
        for (mi = 0; mi < 3; mi++)
            for (ai = 0; ai < 5; ai++) {
                hfvis_voxelize_options o = vox_opts(vox_methods[mi], axes[ai], 0);
                size_t f = 0;
                runs++;
                if (!vox_same(vox_soup_mesh(&s), &g, &o, &f)) bad++;
                total += f;
                if (mi > 0) { /* capped */
                    o.max_output_vertices = mi == 1 ? 7 + 4 * (trial % 3) : 3 + 3 * (trial % 3);
                    runs++;
                    if (!vox_same(vox_soup_mesh(&s), &g, &o, &f)) bad++;
                }
            }
        vox_soup_free(&s);
    }
    printf("  %d runs on 12 random soups (generic, tie-heavy, degenerate), %zu fragments: %d mismatches\n",
           runs, total, bad);
    CHECK(bad == 0);
    CHECK(total > 10000);
}

/* Generator meshes at several resolutions, fitted grids with fractional origin offsets and
 * non-cubic cells. */
TEST(fast_equals_reference_meshes)
{
    const double c0[3] = { 0.1, -0.2, 0.3 };
    hfvis_mesh ms[5];
    const char *names[5] = { "icosphere", "torus", "torus knot", "teapot", "room" };
    int mi, k, ri, bad = 0, runs = 0;
    size_t total = 0;
    CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c0, 1.0, 3, &ms[0]), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_mesh_torus(NULL, c0, 1.0, 0.35, 40, 16, &ms[1]), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_mesh_torus_knot(NULL, c0, 1.0, 2, 3, 160, 8, &ms[2]), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_mesh_teapot(NULL, 2, &ms[3]), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_mesh_room(NULL, &ms[4]), HFVIS_OK);
    vox_seed(77);
    for (k = 0; k < 5; k++)
        for (ri = 0; ri < 3; ri++) {
            static const int res[3] = { 16, 37, 64 };
            hfvis_volume_grid g;
            int a;
            CHECK_EQ_STATUS(hfvis_volume_grid_fit(&ms[k], res[ri], 0.05, ri == 1, &g), HFVIS_OK);
            for (a = 0; a < 3; a++) g.origin[a] += (vox_unit() - 0.5) * g.cell[a];
            for (mi = 0; mi < 3; mi++) {
                hfvis_voxelize_options o = vox_opts(vox_methods[mi], HFVIS_AXES_DOMINANT, 0);
                size_t f = 0;
                runs += 2;
                if (!vox_same(&ms[k], &g, &o, &f)) bad++, printf("  mismatch %s res %d method %d\n", names[k], res[ri], mi);
                total += f;
                o.axes = HFVIS_AXES_ALL;
                if (!vox_same(&ms[k], &g, &o, &f)) bad++, printf("  mismatch %s res %d method %d all\n", names[k], res[ri], mi);
                if (mi > 0) {
                    o.max_output_vertices = mi == 1 ? 7 : 3;
                    runs++;
                    if (!vox_same(&ms[k], &g, &o, &f)) bad++;
                }
            }
        }
    printf("  %d runs on 5 generator meshes x 3 resolutions, %zu fragments: %d mismatches\n", runs, total, bad);
    CHECK(bad == 0);
    for (k = 0; k < 5; k++) hfvis_mesh_free(NULL, &ms[k]);
}

/* ---- the methods against each other ------------------------------------------------------- */

/* Without a limit fragment clipping is the pixel rule exactly (same predicate per fragment). */
TEST(fragment_clipping_is_pixel_rule)
{
    const double c0[3] = { 0.0, 0.0, 0.0 };
    hfvis_mesh m;
    hfvis_volume_grid g;
    int trial, bad = 0;
    CHECK_EQ_STATUS(hfvis_mesh_torus_knot(NULL, c0, 1.0, 2, 3, 300, 10, &m), HFVIS_OK);
    for (trial = 0; trial < 4; trial++) {
        static const int res[4] = { 20, 48, 96, 150 };
        size_t n, fa, fb;
        float *a, *b;
        hfvis_volume va, vb;
        hfvis_voxelize_options o = vox_opts(HFVIS_VOXELIZE_PIXEL_RULE, trial & 1 ? HFVIS_AXES_ALL : HFVIS_AXES_DOMINANT, 0);
        hfvis_voxelize_options f = o;
        size_t ca = 0, cb = 0;
        f.method = HFVIS_VOXELIZE_FRAGMENT_CLIPPING;
        CHECK_EQ_STATUS(hfvis_volume_grid_fit(&m, res[trial], 0.02, 0, &g), HFVIS_OK);
        n = hfvis_volume_floats(&g, VOX_CB_CHANNELS);
        a = vox_storage(&g, VOX_CB_CHANNELS);
        b = vox_storage(&g, VOX_CB_CHANNELS);
        hfvis_volume_init(&va, &g, VOX_CB_CHANNELS, a, HFVIS_BLEND_ADD);
        hfvis_volume_init(&vb, &g, VOX_CB_CHANNELS, b, HFVIS_BLEND_ADD);
        o.fragment = f.fragment = vox_cb_all;
        o.user = &ca, f.user = &cb;
        CHECK_EQ_STATUS(hfvis_voxelize_surface(&m, &va, &o, &fa), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_voxelize_surface(&m, &vb, &f, &fb), HFVIS_OK);
        if (fa != fb || memcmp(a, b, n * sizeof(float)) != 0) bad++;
        free(a);
        free(b);
    }
    CHECK(bad == 0);
    hfvis_mesh_free(NULL, &m);
}

/* Distance (in voxels) from pixel centre (pu, pw) of the pass along a to the nearest projected
 * edge line of triangle p, or from its depth to the nearest slab boundary (unit grid). */
static double vox_tie_distance(const float *p0, const float *p1, const float *p2, int a, int pu, int pw)
{
    int u = (a + 1) % 3, w = (a + 2) % 3, i;
    const float *P[3];
    double cu = pu + 0.5, cw = pw + 0.5, best = 1e300, n[3], e1[3], e2[3], z;
    P[0] = p0, P[1] = p1, P[2] = p2;
    for (i = 0; i < 3; i++) {
        const float *A = P[i], *B = P[(i + 1) % 3];
        double du = (double)B[u] - (double)A[u], dw = (double)B[w] - (double)A[w];
        double len = sqrt(du * du + dw * dw);
        double d = len > 0 ? fabs(du * (cw - (double)A[w]) - dw * (cu - (double)A[u])) / len : 0.0;
        if (d < best) best = d;
    }
    for (i = 0; i < 3; i++) e1[i] = (double)p1[i] - (double)p0[i], e2[i] = (double)p2[i] - (double)p0[i];
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    z = (double)p0[a] - (n[u] * (cu - (double)p0[u]) + n[w] * (cw - (double)p0[w])) / n[a];
    if (fabs(z - floor(z + 0.5)) < best) best = fabs(z - floor(z + 0.5));
    return best;
}

/* GS slicing rasterises the Sutherland-Hodgman pieces on their own (rounded) vertices, so it
 * may differ from the pixel rule only at near ties ([G12] Fig. 65's "rasterisation details");
 * per triangle, every differing voxel must be within VOX_NEAR_TIE of a tie. */
TEST(gs_slicing_vs_pixel_rule)
{
    int trial, far = 0;
    size_t diffs = 0, voxels = 0, tris = 0;
    for (trial = 0; trial < 4; trial++) {
        int N = 24, mode = trial & 1;
        hfvis_volume_grid g = vox_unit_grid(N);
        size_t n = (size_t)N * N * N, t, i;
        uint8_t *a = (uint8_t *)malloc(n), *b = (uint8_t *)malloc(n);
        vox_soup s;
        hfvis_voxelize_options pr = vox_opts(HFVIS_VOXELIZE_PIXEL_RULE, HFVIS_AXES_DOMINANT, 0);
        hfvis_voxelize_options gs = vox_opts(HFVIS_VOXELIZE_GS_SLICING, HFVIS_AXES_DOMINANT, 0);
        vox_seed(500 + (uint64_t)trial);
        vox_soup_init(&s, 80);
        vox_random_soup(&s, 80, mode, (double)N);
        for (t = 0; t < s.nt; t++) {
            hfvis_mesh one;
            const float *p0 = s.xyz + 9 * t, *p1 = p0 + 3, *p2 = p0 + 6;
            double e1[3], e2[3], nn[3];
            int ax = 0, k;
            one.xyz = s.xyz;
            one.vertex_count = s.nv;
            one.indices = s.idx + 3 * t;
            one.triangle_count = 1;
            CHECK_EQ_STATUS(hfvis_voxelize_occupancy(&one, &g, &pr, a), HFVIS_OK);
            CHECK_EQ_STATUS(hfvis_voxelize_occupancy(&one, &g, &gs, b), HFVIS_OK);
            for (k = 0; k < 3; k++) e1[k] = (double)p1[k] - (double)p0[k], e2[k] = (double)p2[k] - (double)p0[k];
            nn[0] = e1[1] * e2[2] - e1[2] * e2[1];
            nn[1] = e1[2] * e2[0] - e1[0] * e2[2];
            nn[2] = e1[0] * e2[1] - e1[1] * e2[0];
            if (fabs(nn[1]) > fabs(nn[ax])) ax = 1;
            if (fabs(nn[2]) > fabs(nn[ax])) ax = 2;
            tris++;
            for (i = 0; i < n; i++) {
                int v[3];
                voxels += a[i];
                if (a[i] == b[i]) continue;
                diffs++;
                v[0] = (int)(i % (size_t)N), v[1] = (int)(i / (size_t)N % (size_t)N), v[2] = (int)(i / ((size_t)N * N));
                if (vox_tie_distance(p0, p1, p2, ax, v[(ax + 1) % 3], v[(ax + 2) % 3]) > VOX_NEAR_TIE) far++;
            }
        }
        vox_soup_free(&s);
        free(a);
        free(b);
    }
    printf("  GS slicing vs pixel rule: %zu triangles, %zu voxels, %zu differ (all at ties: %s)\n", tris,
           voxels, diffs, far ? "NO" : "yes");
    CHECK(far == 0);
}

/* ALL_AXES contains the dominant pass (superset) and equals Alg. 4's three per-axis volumes
 * merged with MAX (hfvis_volume_merge), with attribute values, bit for bit. */
TEST(all_axes_superset_and_max_merge)
{
    hfvis_mesh m;
    int mi, r;
    CHECK_EQ_STATUS(hfvis_mesh_teapot(NULL, 3, &m), HFVIS_OK);
    for (r = 0; r < 2; r++)
        for (mi = 0; mi < 3; mi++) {
            hfvis_volume_grid g;
            size_t n, i, sub = 0, extra = 0, calls = 0;
            float *all, *dom, *ax[3];
            hfvis_volume vall, vdom, vax[3];
            hfvis_voxelize_options o = vox_opts(vox_methods[mi], HFVIS_AXES_ALL, 0);
            int a, merged_equal;
            CHECK_EQ_STATUS(hfvis_volume_grid_fit(&m, r ? 70 : 31, 0.03, 1, &g), HFVIS_OK);
            n = hfvis_volume_floats(&g, VOX_CB_CHANNELS);
            all = vox_storage(&g, VOX_CB_CHANNELS);
            dom = vox_storage(&g, VOX_CB_CHANNELS);
            hfvis_volume_init(&vall, &g, VOX_CB_CHANNELS, all, HFVIS_BLEND_MAX);
            hfvis_volume_init(&vdom, &g, VOX_CB_CHANNELS, dom, HFVIS_BLEND_MAX);
            o.fragment = vox_cb_all;
            o.user = &calls;
            CHECK_EQ_STATUS(hfvis_voxelize_surface(&m, &vall, &o, NULL), HFVIS_OK);
            o.axes = HFVIS_AXES_DOMINANT;
            CHECK_EQ_STATUS(hfvis_voxelize_surface(&m, &vdom, &o, NULL), HFVIS_OK);
            for (i = 0; i < n; i += VOX_CB_CHANNELS) {
                if (dom[i] != 0.0f && all[i] == 0.0f) sub++;
                if (dom[i] == 0.0f && all[i] != 0.0f) extra++;
            }
            CHECK(sub == 0);
            CHECK(extra > 0);
            for (a = 0; a < 3; a++) {
                ax[a] = vox_storage(&g, VOX_CB_CHANNELS);
                hfvis_volume_init(&vax[a], &g, VOX_CB_CHANNELS, ax[a], HFVIS_BLEND_MAX);
                o.axes = (hfvis_voxelize_axes)(HFVIS_AXES_ONLY_X + a);
                CHECK_EQ_STATUS(hfvis_voxelize_surface(&m, &vax[a], &o, NULL), HFVIS_OK);
            }
            CHECK_EQ_STATUS(hfvis_volume_merge(&vax[0], &vax[1]), HFVIS_OK);
            CHECK_EQ_STATUS(hfvis_volume_merge(&vax[0], &vax[2]), HFVIS_OK);
            merged_equal = memcmp(ax[0], all, n * sizeof(float)) == 0;
            CHECK(merged_equal);
            if (r == 1 && mi == 0)
                printf("  teapot %dx%dx%d: all-axes adds %zu voxels to the dominant set; MAX merge of X, Y, Z "
                       "passes %s all-axes\n", g.dims[0], g.dims[1], g.dims[2], extra, merged_equal ? "==" : "!=");
            for (a = 0; a < 3; a++) free(ax[a]);
            free(all);
            free(dom);
        }
    hfvis_mesh_free(NULL, &m);
}

/* ---- Volume Buffer blends and attributes ------------------------------------------------- */

static void vox_cb_id(const hfvis_voxel_fragment *f, float *v, void *user)
{
    (void)user;
    v[0] = (float)(f->triangle + 1u);
    v[1] = 1.0f;
}

/* §3.13.7: two triangles writing the same voxels: MAX keeps the maximum, ADD sums, MIN the
 * minimum, REPLACE the last (triangle order). */
TEST(blend_ops)
{
    const double a[3] = { 1.2, 1.3, 3.4 }, b[3] = { 9.7, 1.1, 3.6 }, c[3] = { 1.4, 9.8, 3.5 };
    const double d[3] = { 0.9, 0.8, 3.45 }, e[3] = { 10.1, 0.7, 3.55 }, f[3] = { 0.6, 10.3, 3.5 };
    static const hfvis_blend ops[4] = { HFVIS_BLEND_MAX, HFVIS_BLEND_ADD, HFVIS_BLEND_MIN, HFVIS_BLEND_REPLACE };
    static const float want_both[4] = { 2.0f, 3.0f, 1.0f, 2.0f };
    hfvis_volume_grid g = vox_unit_grid(12);
    vox_soup s;
    int oi, mi, r;
    vox_soup_init(&s, 2);
    vox_soup_tri(&s, a, b, c); /* triangle 0 (value 1) */
    vox_soup_tri(&s, d, e, f); /* triangle 1 (value 2) covers most of it, same slab 3 */
    for (oi = 0; oi < 4; oi++)
        for (mi = 0; mi < 3; mi++)
            for (r = 0; r < 2; r++) {
                float *st = vox_storage(&g, 2);
                hfvis_volume v;
                hfvis_voxelize_options o = vox_opts(vox_methods[mi], HFVIS_AXES_DOMINANT, 0);
                size_t i, n = hfvis_volume_floats(&g, 1), both = 0, one = 0, bad = 0, frags = 0;
                hfvis_volume_init(&v, &g, 2, st, ops[oi]);
                v.blend[1] = HFVIS_BLEND_ADD; /* channel 1 counts the fragments per voxel */
                if (ops[oi] == HFVIS_BLEND_MIN)
                    for (i = 0; i < n; i++) st[2 * i] = 100.0f;
                o.fragment = vox_cb_id;
                if (r) CHECK_EQ_STATUS(hfvis_voxelize_surface_reference(vox_soup_mesh(&s), &v, &o, &frags), HFVIS_OK);
                else CHECK_EQ_STATUS(hfvis_voxelize_surface(vox_soup_mesh(&s), &v, &o, &frags), HFVIS_OK);
                for (i = 0; i < n; i++) {
                    if (st[2 * i + 1] == 2.0f) {
                        both++;
                        if (st[2 * i] != want_both[oi]) bad++;
                    } else if (st[2 * i + 1] == 1.0f) {
                        one++;
                        if (st[2 * i] != 1.0f && st[2 * i] != 2.0f) bad++; /* one triangle: its value */
                    } else if (st[2 * i + 1] != 0.0f) bad++;
                }
                CHECK(bad == 0);
                CHECK(both >= 36 && one > 0);
                CHECK(frags == 2 * both + one);
                free(st);
            }
    vox_soup_free(&s);
}

/* No pixel centre is covered twice or missed by a triangulated sheet: quads with vertices on
 * pixel centres (every centre is a vertex or on an edge: all ties) and random diagonals; an ADD
 * channel sums the fragments of each column to exactly 1 inside the footprint (top-left rule:
 * the left and top borders are inside, the right and bottom ones not). Flat and tilted sheets,
 * every method. */
TEST(watertight_shared_edges)
{
    enum { Q = 9, N = 14 };
    hfvis_volume_grid g = vox_unit_grid(N);
    int tilt, mi, i, j, k;
    vox_seed(4242);
    for (tilt = 0; tilt < 2; tilt++) {
        vox_soup s;
        vox_soup_init(&s, 2 * Q * Q);
        for (j = 0; j < Q; j++)
            for (i = 0; i < Q; i++) {
                double p[4][3];
                int c;
                for (c = 0; c < 4; c++) {
                    p[c][0] = 2.5 + i + (c & 1);
                    p[c][1] = 2.5 + j + (c >> 1);
                    p[c][2] = tilt ? 3.3 + 0.25 * p[c][0] + 0.125 * p[c][1] : 5.25;
                }
                if (vox_unit() < 0.5) {
                    vox_soup_tri(&s, p[0], p[1], p[3]);
                    vox_soup_tri(&s, p[0], p[3], p[2]);
                } else {
                    vox_soup_tri(&s, p[0], p[1], p[2]);
                    vox_soup_tri(&s, p[1], p[3], p[2]);
                }
            }
        for (mi = 0; mi < 3; mi++) {
            float *st = vox_storage(&g, 1);
            hfvis_volume v;
            hfvis_voxelize_options o = vox_opts(vox_methods[mi], HFVIS_AXES_DOMINANT, 0);
            int bad = 0;
            size_t frags = 0;
            hfvis_volume_init(&v, &g, 1, st, HFVIS_BLEND_ADD);
            CHECK_EQ_STATUS(hfvis_voxelize_surface(vox_soup_mesh(&s), &v, &o, &frags), HFVIS_OK);
            for (j = 0; j < N; j++)
                for (i = 0; i < N; i++) {
                    float sum = 0.0f, want;
                    for (k = 0; k < N; k++) sum += st[vox_lin(&g, i, j, k)];
                    /* centres x = i + 0.5 in [2.5, 2.5 + Q): left border in; y in (2.5, 2.5 + Q] */
                    want = (i >= 2 && i < 2 + Q && j >= 3 && j <= 2 + Q) ? 1.0f : 0.0f;
                    if (sum != want) bad++;
                }
            CHECK(bad == 0);
            CHECK(frags == (size_t)Q * Q);
            free(st);
        }
        vox_soup_free(&s);
    }
}

/* Fragment contents ([G12] ch. 6): barycentrics, world position at the pixel centre on the
 * triangle, unit normal, axis, triangle id, voxel; non-cubic cells and an offset origin. */
typedef struct vox_cb_check {
    const hfvis_mesh *m;
    const hfvis_volume_grid *g;
    int dominant_only, method;
    size_t calls, bad_bary, bad_pos, bad_normal, bad_axis;
} vox_cb_check;

static void vox_cb_verify(const hfvis_voxel_fragment *f, float *v, void *user)
{
    vox_cb_check *c = (vox_cb_check *)user;
    const float *P[3];
    double e1[3], e2[3], n[3], len, gpos[3], dot;
    int i, a = f->axis, u = (a + 1) % 3, w = (a + 2) % 3, dom = 0;
    c->calls++;
    for (i = 0; i < 3; i++) P[i] = c->m->xyz + 3 * c->m->indices[3 * (size_t)f->triangle + (size_t)i];
    for (i = 0; i < 3; i++) e1[i] = (double)P[1][i] - (double)P[0][i], e2[i] = (double)P[2][i] - (double)P[0][i];
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (fabs((double)f->barycentric[0] + (double)f->barycentric[1] + (double)f->barycentric[2] - 1.0) > VOX_BARY_TOL)
        c->bad_bary++;
    for (i = 0; i < 3; i++)
        if ((double)f->barycentric[i] < -VOX_BARY_TOL || (double)f->barycentric[i] > 1.0 + VOX_BARY_TOL) c->bad_bary++;
    for (i = 0; i < 3; i++) gpos[i] = ((double)f->position[i] - c->g->origin[i]) / c->g->cell[i];
    if (fabs(gpos[u] - (f->voxel[u] + 0.5)) > VOX_POS_TOL || fabs(gpos[w] - (f->voxel[w] + 0.5)) > VOX_POS_TOL)
        c->bad_pos++;
    if (c->method != HFVIS_VOXELIZE_GS_SLICING && (gpos[a] < f->voxel[a] - VOX_POS_TOL || gpos[a] > f->voxel[a] + 1 + VOX_POS_TOL))
        c->bad_pos++;
    dot = ((double)f->normal[0] * n[0] + (double)f->normal[1] * n[1] + (double)f->normal[2] * n[2]) / len;
    if (fabs(dot - 1.0) > VOX_BARY_TOL) c->bad_normal++;
    /* dominant axis of the grid-space normal n_a / (cell_u cell_w) ~ n_a * cell_a */
    for (i = 0; i < 3; i++) n[i] *= c->g->cell[i];
    if (fabs(n[1]) > fabs(n[dom])) dom = 1;
    if (fabs(n[2]) > fabs(n[dom])) dom = 2;
    if (c->dominant_only && a != dom && fabs(fabs(n[a]) - fabs(n[dom])) > 1e-9 * fabs(n[dom])) c->bad_axis++;
    for (i = 0; i < 3; i++)
        if (f->voxel[i] < 0 || f->voxel[i] >= c->g->dims[i]) c->bad_axis++;
    v[0] = 1.0f;
}

TEST(fragment_contents)
{
    hfvis_volume_grid g = vox_grid(23, 17, 29, -0.37, 0.21, -0.13, 0.83, 1.21, 0.67);
    vox_soup s;
    int mi, ai;
    vox_seed(31337);
    vox_soup_init(&s, 150);
    vox_random_soup(&s, 150, 0, 16.0);
    for (mi = 0; mi < 3; mi++)
        for (ai = 0; ai < 2; ai++) {
            vox_cb_check c;
            float *st = vox_storage(&g, 1);
            hfvis_volume v;
            hfvis_voxelize_options o = vox_opts(vox_methods[mi], ai ? HFVIS_AXES_ALL : HFVIS_AXES_DOMINANT, 0);
            size_t frags = 0;
            memset(&c, 0, sizeof c);
            c.m = vox_soup_mesh(&s);
            c.g = &g;
            c.dominant_only = !ai;
            c.method = (int)vox_methods[mi];
            o.fragment = vox_cb_verify;
            o.user = &c;
            hfvis_volume_init(&v, &g, 1, st, HFVIS_BLEND_MAX);
            CHECK_EQ_STATUS(hfvis_voxelize_surface(c.m, &v, &o, &frags), HFVIS_OK);
            CHECK(c.calls == frags && frags > 1000);
            CHECK(c.bad_bary == 0);
            CHECK(c.bad_pos == 0);
            CHECK(c.bad_normal == 0);
            CHECK(c.bad_axis == 0);
            free(st);
        }
    vox_soup_free(&s);
}

static void vox_irr(const float position[3], const float normal[3], float rgb[3], void *user)
{
    const float *k = (const float *)user;
    (void)normal;
    rgb[0] = k[0];
    rgb[1] = k[1] * position[0];
    rgb[2] = k[2];
}

/* The ready-made callbacks and the attribute packing. */
TEST(attribute_callbacks)
{
    const double a[3] = { 1.2, 1.3, 2.4 }, b[3] = { 6.7, 1.1, 2.6 }, c[3] = { 1.4, 6.8, 2.5 };
    const float albedo[3] = { 0.25f, 0.5f, 0.75f }, emission[3] = { 0.0f, 0.125f, 2.0f };
    const float irr[3] = { 3.14159265f, 2.0f, 0.0f };
    hfvis_volume_grid g = vox_unit_grid(8);
    hfvis_voxel_attributes at;
    vox_soup s;
    float *st;
    hfvis_volume v;
    hfvis_voxelize_options o = hfvis_voxelize_options_default();
    size_t i, n = hfvis_volume_floats(&g, 1), hit = 0, bad = 0, frags = 0;
    int nc, ch_occ, ch_n, ch_alb, ch_rad;
    hfvis_voxel_fragment fr;
    float vals[HFVIS_VOLUME_MAX_CHANNELS];
    /* packing */
    CHECK(hfvis_voxel_attribute_channel(0, 0) == 1);
    CHECK(hfvis_voxel_attribute_channel(0, HFVIS_VOXEL_ATTR_OCCUPANCY) == 0);
    CHECK(hfvis_voxel_attribute_channel(0, HFVIS_VOXEL_ATTR_NORMAL) == -1);
    CHECK(hfvis_voxel_attribute_channel(HFVIS_VOXEL_ATTR_NORMAL | HFVIS_VOXEL_ATTR_RADIANCE, HFVIS_VOXEL_ATTR_RADIANCE) == 3);
    CHECK(hfvis_voxel_attribute_channel(HFVIS_VOXEL_ATTR_NORMAL | HFVIS_VOXEL_ATTR_RADIANCE, 0) == 6);
    CHECK(hfvis_voxel_attribute_channel(15u, 0) == 10);
    CHECK(hfvis_voxel_attribute_channel(15u, HFVIS_VOXEL_ATTR_ALBEDO) == 4);
    /* direct calls */
    memset(&fr, 0, sizeof fr);
    fr.normal[0] = 0.6f, fr.normal[2] = 0.8f;
    memset(vals, 0, sizeof vals);
    hfvis_voxel_fragment_occupancy(&fr, vals, NULL);
    CHECK(vals[0] == 1.0f && vals[1] == 0.0f);
    hfvis_voxel_fragment_normal_occupancy(&fr, vals, NULL);
    CHECK(vals[0] == 1.0f && vals[1] == 0.6f && vals[2] == 0.0f && vals[3] == 0.8f && vals[4] == 0.0f);
    memset(&at, 0, sizeof at);
    memset(vals, 0, sizeof vals);
    hfvis_voxel_fragment_attributes(&fr, vals, &at); /* zero struct: occupancy only */
    CHECK(vals[0] == 1.0f && vals[1] == 0.0f);
    memset(vals, 0, sizeof vals);
    hfvis_voxel_fragment_attributes(&fr, vals, NULL); /* no layout: occupancy only */
    CHECK(vals[0] == 1.0f && vals[1] == 0.0f);
    /* through the voxelizer: one triangle, all four attributes */
    vox_soup_init(&s, 1);
    vox_soup_tri(&s, a, b, c);
    at.flags = HFVIS_VOXEL_ATTR_OCCUPANCY | HFVIS_VOXEL_ATTR_NORMAL | HFVIS_VOXEL_ATTR_ALBEDO | HFVIS_VOXEL_ATTR_RADIANCE;
    at.albedo = albedo;
    at.emission = emission;
    at.irradiance = vox_irr;
    at.irradiance_user = (void *)(uintptr_t)irr; /* read only */
    nc = hfvis_voxel_attribute_channel(at.flags, 0);
    ch_occ = hfvis_voxel_attribute_channel(at.flags, HFVIS_VOXEL_ATTR_OCCUPANCY);
    ch_n = hfvis_voxel_attribute_channel(at.flags, HFVIS_VOXEL_ATTR_NORMAL);
    ch_alb = hfvis_voxel_attribute_channel(at.flags, HFVIS_VOXEL_ATTR_ALBEDO);
    ch_rad = hfvis_voxel_attribute_channel(at.flags, HFVIS_VOXEL_ATTR_RADIANCE);
    CHECK(nc == 10 && ch_occ == 0 && ch_n == 1 && ch_alb == 4 && ch_rad == 7);
    st = vox_storage(&g, nc);
    hfvis_volume_init(&v, &g, nc, st, HFVIS_BLEND_REPLACE);
    o.fragment = hfvis_voxel_fragment_attributes;
    o.user = &at;
    CHECK_EQ_STATUS(hfvis_voxelize_surface(vox_soup_mesh(&s), &v, &o, &frags), HFVIS_OK);
    for (i = 0; i < n; i++) {
        const float *d = st + i * (size_t)nc;
        double x = (double)(i % 8) + 0.5, nz;
        if (d[ch_occ] == 0.0f) continue;
        hit++;
        /* normal of (a, b, c): z up, slightly tilted */
        nz = (double)d[ch_n + 2];
        if (!(nz > 0.99 && fabs((double)d[ch_n] * (double)d[ch_n] + (double)d[ch_n + 1] * (double)d[ch_n + 1] + nz * nz - 1.0)
                               < VOX_BARY_TOL))
            bad++;
        if (d[ch_alb] != 0.25f || d[ch_alb + 1] != 0.5f || d[ch_alb + 2] != 0.75f) bad++;
        /* radiance = albedo E / pi + emission with E = (pi, 2 x, 0) */
        if (fabs((double)d[ch_rad] - 0.25 * (double)irr[0] / 3.14159265358979) > VOX_RAD_TOL) bad++;
        if (fabs((double)d[ch_rad + 1] - (0.5 * 2.0 * x / 3.14159265358979 + 0.125)) > VOX_POS_TOL) bad++;
        if (d[ch_rad + 2] != 2.0f) bad++;
    }
    CHECK(hit == frags && hit > 10);
    CHECK(bad == 0);
    /* NULL callback: channel 0 = 1, the other channels untouched */
    hfvis_volume_clear(&v, 0.5f);
    CHECK_EQ_STATUS(hfvis_voxelize_surface(vox_soup_mesh(&s), &v, NULL, &frags), HFVIS_OK);
    for (i = 0, bad = 0, hit = 0; i < n; i++) {
        const float *d = st + i * (size_t)nc;
        int k;
        if (d[0] == 1.0f) hit++;
        else if (d[0] != 0.5f) bad++;
        for (k = 1; k < nc; k++)
            if (d[k] != 0.5f) bad++;
    }
    CHECK(bad == 0 && hit == frags);
    free(st);
    vox_soup_free(&s);
}


/* ---- output-vertex limit: the thesis' holes ([G12] ch. 6, Fig. 66; docs/errata.md E58) ------------ */

/* Pixels of the pass along axis a whose column holds no voxel although its centre lies in the
 * projected triangle (the PR voxelization tells which centres are covered: one voxel each). */
static size_t vox_holes(const uint8_t *full, const uint8_t *capped, const hfvis_volume_grid *g, int a)
{
    int u = (a + 1) % 3, w = (a + 2) % 3, pu, pw, k;
    size_t holes = 0;
    for (pw = 0; pw < g->dims[w]; pw++)
        for (pu = 0; pu < g->dims[u]; pu++) {
            int inf = 0, inc = 0, v[3];
            for (k = 0; k < g->dims[a]; k++) {
                size_t l;
                v[a] = k, v[u] = pu, v[w] = pw;
                l = vox_lin(g, v[0], v[1], v[2]);
                inf |= full[l], inc |= capped[l];
            }
            if (inf && !inc) holes++;
        }
    return holes;
}

/* A 45-degree triangle (plane z = x, |n_x| = |n_z|: dominant x by the tie rule) spanning the 8
 * slabs x in [1.2, 8.9]: with max_slices = 2 only the two lowest slabs 1, 2 remain; the voxel
 * count never decreases with V and equals the unlimited one once the limit covers 8 slabs;
 * unlimited output has no holes, small limits do. */
TEST(vertex_limit_steep_triangle)
{
    const double a[3] = { 1.2, 1.3, 1.2 }, b[3] = { 8.9, 1.3, 8.9 }, c[3] = { 1.2, 9.6, 1.2 };
    hfvis_volume_grid g = vox_unit_grid(12);
    size_t n = 12 * 12 * 12, full_n, i;
    uint8_t full[12 * 12 * 12], cap[12 * 12 * 12];
    vox_soup s;
    int m, S;
    vox_soup_init(&s, 1);
    vox_soup_tri(&s, a, b, c);
    {
        hfvis_voxelize_options o = vox_opts(HFVIS_VOXELIZE_PIXEL_RULE, HFVIS_AXES_DOMINANT, 0);
        full_n = vox_count(vox_soup_mesh(&s), &g, &o, full);
    }
    CHECK(vox_holes(full, full, &g, 0) == 0);
    for (m = 1; m < 3; m++) {
        size_t prev = 0, prev_holes = (size_t)-1;
        printf("  %s:", m == 1 ? "GS slicing V" : "FC V");
        for (S = 1; S <= 9; S++) {
            int V = m == 1 ? 3 + 4 * S : 3 * S, bad = 0;
            hfvis_voxelize_options o = vox_opts(vox_methods[m], HFVIS_AXES_DOMINANT, V);
            size_t cnt = vox_count(vox_soup_mesh(&s), &g, &o, cap), holes = vox_holes(full, cap, &g, 0);
            CHECK(hfvis_gs_max_slices(V, m == 2) == S);
            for (i = 0; i < n; i++) {
                int x = (int)(i % 12);
                if (cap[i] != (full[i] && x <= S)) bad++; /* the S lowest slabs 1..S */
            }
            CHECK(bad == 0);
            CHECK(cnt >= prev);
            CHECK(holes <= prev_holes);
            CHECK((cnt == full_n) == (S >= 8));
            CHECK((holes == 0) == (S >= 8));
            if (S == 2) CHECK(holes > 0);
            printf(" %d: %zu voxels %zu holes;", V, cnt, holes);
            prev = cnt, prev_holes = holes;
        }
        printf(" unlimited %zu\n", full_n);
    }
    vox_soup_free(&s);
}

/* [G12] Fig. 66 on a coarse closed mesh (icosphere of 80 triangles, r = 20 in 48^3): the voxel
 * count grows with V and reaches the complete voxelization; every capped set is a subset. */
TEST(vertex_limit_mesh_holes)
{
    const double c[3] = { 24.13, 23.71, 24.37 };
    hfvis_volume_grid g = vox_unit_grid(48);
    hfvis_mesh m;
    size_t n = 48 * 48 * 48, i, full_n;
    uint8_t *full = (uint8_t *)malloc(n), *cap = (uint8_t *)malloc(n);
    int mi, S;
    CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c, 20.0, 1, &m), HFVIS_OK);
    {
        hfvis_voxelize_options o = vox_opts(HFVIS_VOXELIZE_PIXEL_RULE, HFVIS_AXES_DOMINANT, 0);
        full_n = vox_count(&m, &g, &o, full);
    }
    for (mi = 1; mi < 3; mi++) {
        size_t prev = 0;
        int reached = 0;
        printf("  icosphere(80) 48^3 %s:", mi == 1 ? "GS V" : "FC V");
        for (S = 1; S <= 12; S++) {
            int V = mi == 1 ? 3 + 4 * S : 3 * S, sub = 1;
            hfvis_voxelize_options o = vox_opts(vox_methods[mi], HFVIS_AXES_DOMINANT, V);
            size_t cnt = vox_count(&m, &g, &o, cap);
            for (i = 0; i < n; i++)
                if (cap[i] && !full[i]) sub = 0;
            CHECK(sub);
            CHECK(cnt >= prev);
            if (S == 1) CHECK(cnt < full_n);
            if (cnt == full_n) reached = 1;
            if (S <= 4 || cnt == full_n) printf(" %d:%zu", V, cnt);
            prev = cnt;
            if (reached) break;
        }
        printf(" (complete %zu)\n", full_n);
        CHECK(reached);
    }
    hfvis_mesh_free(NULL, &m);
    free(full);
    free(cap);
}

/* ---- no holes: 6-separation of the three-axis variant ------------------------------------- */

/* inside[v] = 1 when the centre of voxel v lies inside the closed mesh (unit grid): parity of the
 * crossings of the vertical line through the column centre, below the voxel centre. */
static void vox_inside_centres(const hfvis_mesh *m, const hfvis_volume_grid *g, uint8_t *inside)
{
    int N0 = g->dims[0], N1 = g->dims[1], N2 = g->dims[2], i, j, k;
    double *zs = (double *)malloc(sizeof(double) * (m->triangle_count + 1));
    memset(inside, 0, (size_t)N0 * N1 * N2);
    for (j = 0; j < N1; j++)
        for (i = 0; i < N0; i++) {
            double x = i + 0.5, y = j + 0.5;
            size_t t, nz = 0, q;
            for (t = 0; t < m->triangle_count; t++) {
                double P[3][3], d0, d1, d2, A, z;
                int v, x2;
                for (v = 0; v < 3; v++)
                    for (x2 = 0; x2 < 3; x2++) P[v][x2] = (double)m->xyz[3 * m->indices[3 * t + (size_t)v] + (size_t)x2];
                d0 = (P[1][0] - P[0][0]) * (y - P[0][1]) - (P[1][1] - P[0][1]) * (x - P[0][0]);
                d1 = (P[2][0] - P[1][0]) * (y - P[1][1]) - (P[2][1] - P[1][1]) * (x - P[1][0]);
                d2 = (P[0][0] - P[2][0]) * (y - P[2][1]) - (P[0][1] - P[2][1]) * (x - P[2][0]);
                A = d0 + d1 + d2;
                if (!((d0 > 0 && d1 > 0 && d2 > 0) || (d0 < 0 && d1 < 0 && d2 < 0))) continue;
                z = (d1 * P[0][2] + d2 * P[1][2] + d0 * P[2][2]) / A;
                zs[nz++] = z;
            }
            for (k = 0; k < N2; k++) {
                int below = 0;
                for (q = 0; q < nz; q++)
                    if (zs[q] < k + 0.5) below++;
                inside[vox_lin(g, i, j, k)] = (uint8_t)(below & 1);
            }
        }
    free(zs);
}

/* Empty voxels 6-connected to the grid border whose centre is inside the mesh: 0 means the
 * voxelization separates inside from outside for 6-paths (no 6-tunnel). */
static size_t vox_leaks(const uint8_t *occ, const uint8_t *inside, const hfvis_volume_grid *g)
{
    int N0 = g->dims[0], N1 = g->dims[1], N2 = g->dims[2], i, j, k, d;
    size_t n = (size_t)N0 * N1 * N2, head = 0, tail = 0, leaks = 0;
    size_t *q = (size_t *)malloc(sizeof(size_t) * n);
    uint8_t *seen = (uint8_t *)calloc(n, 1);
    for (k = 0; k < N2; k++)
        for (j = 0; j < N1; j++)
            for (i = 0; i < N0; i++)
                if ((i == 0 || j == 0 || k == 0 || i == N0 - 1 || j == N1 - 1 || k == N2 - 1)
                    && !occ[vox_lin(g, i, j, k)]) {
                    seen[vox_lin(g, i, j, k)] = 1;
                    q[tail++] = vox_lin(g, i, j, k);
                }
    while (head < tail) {
        size_t l = q[head++];
        int v[3];
        v[0] = (int)(l % (size_t)N0), v[1] = (int)(l / (size_t)N0 % (size_t)N1), v[2] = (int)(l / ((size_t)N0 * N1));
        if (inside[l]) leaks++;
        for (d = 0; d < 6; d++) {
            int w[3], a = d >> 1;
            size_t nl;
            w[0] = v[0], w[1] = v[1], w[2] = v[2];
            w[a] += d & 1 ? 1 : -1;
            if (w[a] < 0 || w[a] >= g->dims[a]) continue;
            nl = vox_lin(g, w[0], w[1], w[2]);
            if (seen[nl] || occ[nl]) continue;
            seen[nl] = 1;
            q[tail++] = nl;
        }
    }
    free(q);
    free(seen);
    return leaks;
}

/* Property tested: for a closed mesh inside the grid, the three-axis variant (Alg. 4) is
 * 6-separating: no 6-connected path of empty voxels joins a voxel whose centre is outside to
 * one whose centre is inside. Reason: a 6-path step from centre c to c + e_a that crosses the
 * surface crosses it at a point p of a triangle with n_a != 0; the pass along a samples exactly
 * that pixel centre (c_u, c_w) and p_a lies in [c_a, c_a + 1], so it writes c or c + e_a.
 * The dominant-only pass lacks this guarantee (printed, not required); small vertex limits
 * break it (the thesis' holes). */
TEST(three_axes_six_separating)
{
    const double c[3] = { 24.137, 23.711, 24.373 };
    hfvis_volume_grid g = vox_unit_grid(48);
    size_t n = 48 * 48 * 48;
    uint8_t *occ = (uint8_t *)malloc(n), *inside = (uint8_t *)malloc(n);
    hfvis_mesh ms[4];
    int k, mi;
    size_t capped_leaks = 0;
    CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c, 17.3, 3, &ms[0]), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_mesh_torus(NULL, c, 14.1, 5.3, 48, 20, &ms[1]), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_mesh_torus_knot(NULL, c, 11.3, 2, 3, 240, 12, &ms[2]), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c, 21.7, 1, &ms[3]), HFVIS_OK);
    for (k = 0; k < 4; k++) {
        size_t inside_n = 0, i, ld;
        vox_inside_centres(&ms[k], &g, inside);
        for (i = 0; i < n; i++) inside_n += inside[i];
        CHECK(inside_n > 1000);
        for (mi = 0; mi < 3; mi++) {
            hfvis_voxelize_options o = vox_opts(vox_methods[mi], HFVIS_AXES_ALL, 0);
            CHECK_EQ_STATUS(hfvis_voxelize_occupancy(&ms[k], &g, &o, occ), HFVIS_OK);
            CHECK(vox_leaks(occ, inside, &g) == 0);
        }
        {
            hfvis_voxelize_options o = vox_opts(HFVIS_VOXELIZE_PIXEL_RULE, HFVIS_AXES_DOMINANT, 0);
            CHECK_EQ_STATUS(hfvis_voxelize_occupancy(&ms[k], &g, &o, occ), HFVIS_OK);
            ld = vox_leaks(occ, inside, &g);
        }
        {
            hfvis_voxelize_options o = vox_opts(HFVIS_VOXELIZE_FRAGMENT_CLIPPING, HFVIS_AXES_ALL, 3);
            size_t lc;
            CHECK_EQ_STATUS(hfvis_voxelize_occupancy(&ms[k], &g, &o, occ), HFVIS_OK);
            lc = vox_leaks(occ, inside, &g);
            capped_leaks += lc;
            printf("  closed mesh %d (%zu tris, %zu inside centres): 6-leaks all-axes 0 (PR, GS, FC), "
                   "dominant %zu, all-axes FC V=3 %zu\n", k, ms[k].triangle_count, inside_n, ld, lc);
        }
    }
    CHECK(capped_leaks > 0);
    for (k = 0; k < 4; k++) hfvis_mesh_free(NULL, &ms[k]);
    free(occ);
    free(inside);
}

/* ---- invariance, degenerate input ---------------------------------------------------------- */

/* §3.13.8: translating the mesh by whole voxels translates the voxel set (dyadic coordinates,
 * exact in float and in the grid transform). */
TEST(translation_invariance)
{
    const int sh[3] = { 3, -2, 5 };
    hfvis_volume_grid g = vox_unit_grid(32);
    size_t n = 32 * 32 * 32, t;
    uint8_t *a = (uint8_t *)malloc(n), *b = (uint8_t *)malloc(n);
    vox_soup s1, s2;
    int mi, ai, i, j, k, bad = 0;
    vox_seed(9);
    vox_soup_init(&s1, 120);
    vox_soup_init(&s2, 120);
    for (t = 0; t < 120; t++) {
        double p[3][3], q[3][3], ctr[3];
        int v, x;
        for (x = 0; x < 3; x++) ctr[x] = 5.0 + 14.0 * vox_unit();
        for (v = 0; v < 3; v++)
            for (x = 0; x < 3; x++) {
                p[v][x] = ctr[x] + floor(64.0 * 6.0 * (vox_unit() - 0.5)) / 64.0;
                q[v][x] = p[v][x] + sh[x];
            }
        vox_soup_tri(&s1, p[0], p[1], p[2]);
        vox_soup_tri(&s2, q[0], q[1], q[2]);
    }
    for (mi = 0; mi < 3; mi++)
        for (ai = 0; ai < 2; ai++) {
            hfvis_voxelize_options o = vox_opts(vox_methods[mi], ai ? HFVIS_AXES_ALL : HFVIS_AXES_DOMINANT, 0);
            size_t ca = 0, cb = 0;
            CHECK_EQ_STATUS(hfvis_voxelize_occupancy(vox_soup_mesh(&s1), &g, &o, a), HFVIS_OK);
            CHECK_EQ_STATUS(hfvis_voxelize_occupancy(vox_soup_mesh(&s2), &g, &o, b), HFVIS_OK);
            for (k = 0; k < 32; k++)
                for (j = 0; j < 32; j++)
                    for (i = 0; i < 32; i++) {
                        int i2 = i + sh[0], j2 = j + sh[1], k2 = k + sh[2];
                        ca += a[vox_lin(&g, i, j, k)];
                        cb += b[vox_lin(&g, i, j, k)];
                        if (i2 < 0 || j2 < 0 || k2 < 0 || i2 >= 32 || j2 >= 32 || k2 >= 32) continue;
                        if (a[vox_lin(&g, i, j, k)] != b[vox_lin(&g, i2, j2, k2)]) bad++;
                    }
            CHECK(ca == cb && ca > 400);
        }
    CHECK(bad == 0);
    vox_soup_free(&s1);
    vox_soup_free(&s2);
    free(a);
    free(b);
}

TEST(degenerate_and_extreme_triangles)
{
    hfvis_volume_grid g = vox_unit_grid(10);
    vox_soup s;
    hfvis_voxelize_options o = hfvis_voxelize_options_default();
    uint8_t occ[1000];
    size_t i, cnt;
    int mi;
    vox_soup_init(&s, 8);
    {
        const double a[3] = { 1, 1, 1 }, b[3] = { 5, 5, 5 }, c[3] = { 3, 3, 3 }; /* collinear */
        const double d[3] = { 2.2, 3.3, 4.4 };                                   /* a point */
        const double f[3] = { 50, 50, 50 }, gg[3] = { 60, 50, 50 }, h[3] = { 50, 60, 50 }; /* outside */
        vox_soup_tri(&s, a, b, c);
        vox_soup_tri(&s, d, d, d);
        vox_soup_tri(&s, a, a, b);
        vox_soup_tri(&s, f, gg, h);
    }
    for (mi = 0; mi < 3; mi++) {
        o = vox_opts(vox_methods[mi], HFVIS_AXES_ALL, 0);
        CHECK(vox_count(vox_soup_mesh(&s), &g, &o, NULL) == 0);
    }
    /* a huge triangle covering the grid's whole z slab 3 (coordinates 1e6 voxels away) */
    {
        const double a[3] = { -1e6, -1e6, 3.5 }, b[3] = { 3e6, -1e6, 3.5 }, c[3] = { -1e6, 3e6, 3.5 };
        vox_soup_tri(&s, a, b, c);
    }
    for (mi = 0; mi < 3; mi++) {
        o = vox_opts(vox_methods[mi], HFVIS_AXES_ALL, 0);
        cnt = vox_count(vox_soup_mesh(&s), &g, &o, occ);
        CHECK(cnt == 100);
        for (i = 0; i < 1000; i++)
            if (occ[i] != (i / 100 == 3)) break;
        CHECK(i == 1000);
    }
    /* a huge tilted triangle: every column of the dominant pass gets exactly one voxel where the
     * plane z = 0.3 x + 0.2 y + 1.1 passes inside the grid */
    s.nt = 0, s.nv = 0;
    {
        double p[3][3] = { { -1e5, -1e5, 0 }, { 3e5, -1e5, 0 }, { -1e5, 3e5, 0 } };
        int v, j, k;
        for (v = 0; v < 3; v++) p[v][2] = 0.3 * p[v][0] + 0.2 * p[v][1] + 1.1;
        vox_soup_tri(&s, p[0], p[1], p[2]);
        o = vox_opts(HFVIS_VOXELIZE_PIXEL_RULE, HFVIS_AXES_DOMINANT, 0);
        cnt = vox_count(vox_soup_mesh(&s), &g, &o, occ);
        for (j = 0, i = 0; j < 10; j++)
            for (v = 0; v < 10; v++) {
                double z = 0.3 * (v + 0.5) + 0.2 * (j + 0.5) + 1.1;
                int col = 0;
                for (k = 0; k < 10; k++) col += occ[vox_lin(&g, v, j, k)];
                if (col != (z < 10.0 ? 1 : 0)) i++;
            }
        CHECK(i == 0);
        CHECK(cnt == 100);
    }
    /* grid coordinates beyond 1e150 voxels: skipped */
    {
        hfvis_volume_grid tiny = vox_grid(4, 4, 4, 0, 0, 0, 1e-200, 1e-200, 1e-200);
        uint8_t o4[64];
        o = hfvis_voxelize_options_default();
        CHECK_EQ_STATUS(hfvis_voxelize_occupancy(vox_soup_mesh(&s), &tiny, &o, o4), HFVIS_OK);
        for (i = 0; i < 64; i++) CHECK(o4[i] == 0);
    }
    /* empty mesh */
    s.nt = 0;
    CHECK(vox_count(vox_soup_mesh(&s), &g, &o, NULL) == 0);
    vox_soup_free(&s);
}

/* Search estimates far off: a triangle 8e9 voxels wide whose depth rises by 2^-20 across it
 * (slope 1.2e-16 per voxel) and crosses the slab boundary z = 3 at x = 0, in the middle of a
 * 64-wide grid: the rounding of the depth (1 ulp of 3 = 4.4e-16) moves the crossing by pixels
 * either way, so the boundary search falls back to galloping up and down and to bisection
 * (checked with an instrumented build); it must still equal the oracle,
 * and every column holds exactly one voxel (slab 2 or 3, nondecreasing along x). A second,
 * tilted copy in y exercises the decreasing direction. */
TEST(pathological_estimates)
{
    const double d = 1.0 / 4194304.0; /* 2^-22 */
    hfvis_volume_grid g = vox_grid(64, 16, 8, -32.0, 0.0, 0.0, 1.0, 1.0, 1.0);
    vox_soup s;
    int mi, dir;
    vox_soup_init(&s, 1);
    for (dir = 0; dir < 4; dir++) {
        double A[3] = { -2e9, -2e9, 3.0 - d }, B[3] = { 6e9, -2e9, 3.0 + 3.0 * d }, C[3] = { -2e9, 6e9, 3.0 - d };
        uint8_t occ[64 * 16 * 8];
        int i, j, k, bad = 0;
        if (dir & 1) { /* depth decreasing along x */
            A[2] = 3.0 + d, B[2] = 3.0 - 3.0 * d, C[2] = 3.0 + d;
        }
        g.origin[1] = dir & 2 ? 1e6 + 0.25 : 0.0; /* other rows: other rounding */
        g.origin[0] = dir & 2 ? -31.5 : -32.0;
        s.nt = s.nv = 0;
        vox_soup_tri(&s, A, B, C);
        for (mi = 0; mi < 3; mi++) {
            hfvis_voxelize_options o = vox_opts(vox_methods[mi], HFVIS_AXES_DOMINANT, 0);
            CHECK(vox_same(vox_soup_mesh(&s), &g, &o, NULL));
            CHECK(vox_count(vox_soup_mesh(&s), &g, &o, occ) == 1024);
            o.axes = HFVIS_AXES_ALL;
            CHECK(vox_same(vox_soup_mesh(&s), &g, &o, NULL));
        }
        for (j = 0; j < 16; j++) {
            int prev = dir & 1 ? 9 : -1;
            for (i = 0; i < 64; i++) {
                int n = 0, kk = -1;
                for (k = 0; k < 8; k++)
                    if (occ[vox_lin(&g, i, j, k)]) n++, kk = k;
                if (n != 1 || (kk != 2 && kk != 3) || (dir & 1 ? kk > prev : kk < prev)) bad++;
                prev = kk;
            }
        }
        CHECK(bad == 0);
    }
    vox_soup_free(&s);
}

/* ---- bad arguments, allocator ------------------------------------------------------------- */

TEST(bad_arguments)
{
    const double a[3] = { 1.2, 1.3, 2.5 }, b[3] = { 6.7, 1.1, 2.6 }, c[3] = { 1.4, 6.8, 2.5 };
    hfvis_volume_grid g = vox_unit_grid(8), bg = g;
    vox_soup s;
    float st[8 * 8 * 8 * 2];
    uint8_t occ[512];
    hfvis_volume v;
    hfvis_mesh m, bm;
    hfvis_voxelize_options o;
    size_t frags = 777, i;
    int f, bad = 0;
    vox_soup_init(&s, 1);
    vox_soup_tri(&s, a, b, c);
    m = *vox_soup_mesh(&s);
    hfvis_volume_init(&v, &g, 2, st, HFVIS_BLEND_MAX);
    hfvis_volume_clear(&v, 0.25f);
    memset(occ, 9, sizeof occ);
    for (f = 0; f < 2; f++) {
        hfvis_status (*fn)(const hfvis_mesh *, hfvis_volume *, const hfvis_voxelize_options *, size_t *) =
            f ? hfvis_voxelize_surface_reference : hfvis_voxelize_surface;
        hfvis_volume bv = v;
        CHECK_EQ_STATUS(fn(NULL, &v, NULL, &frags), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(fn(&m, NULL, NULL, &frags), HFVIS_ERR_INVALID_ARGUMENT);
        bv.data = NULL;
        CHECK_EQ_STATUS(fn(&m, &bv, NULL, &frags), HFVIS_ERR_INVALID_ARGUMENT);
        bv = v, bv.channels = 0;
        CHECK_EQ_STATUS(fn(&m, &bv, NULL, &frags), HFVIS_ERR_INVALID_ARGUMENT);
        bv = v, bv.channels = 33;
        CHECK_EQ_STATUS(fn(&m, &bv, NULL, &frags), HFVIS_ERR_INVALID_ARGUMENT);
        bv = v, bv.blend[1] = (hfvis_blend)7;
        CHECK_EQ_STATUS(fn(&m, &bv, NULL, &frags), HFVIS_ERR_INVALID_ARGUMENT);
        bv = v, bv.blend[5] = (hfvis_blend)7; /* unused channel: fine */
        CHECK_EQ_STATUS(fn(&m, &bv, NULL, NULL), HFVIS_OK);
        hfvis_volume_clear(&v, 0.25f);
        bv = v, bv.grid.dims[2] = 0;
        CHECK_EQ_STATUS(fn(&m, &bv, NULL, &frags), HFVIS_ERR_INVALID_ARGUMENT);
        bv = v, bv.grid.cell[0] = -1.0;
        CHECK_EQ_STATUS(fn(&m, &bv, NULL, &frags), HFVIS_ERR_INVALID_ARGUMENT);
        bv = v, bv.grid.origin[1] = (double)NAN;
        CHECK_EQ_STATUS(fn(&m, &bv, NULL, &frags), HFVIS_ERR_INVALID_ARGUMENT);
        bm = m, bm.xyz = NULL;
        CHECK_EQ_STATUS(fn(&bm, &v, NULL, &frags), HFVIS_ERR_INVALID_ARGUMENT);
        bm = m, bm.indices = NULL;
        CHECK_EQ_STATUS(fn(&bm, &v, NULL, &frags), HFVIS_ERR_INVALID_ARGUMENT);
        bm = m, bm.vertex_count = 2;
        CHECK_EQ_STATUS(fn(&bm, &v, NULL, &frags), HFVIS_ERR_INVALID_ARGUMENT);
        s.xyz[4] = NAN;
        CHECK_EQ_STATUS(fn(&m, &v, NULL, &frags), HFVIS_ERR_INVALID_ARGUMENT);
        s.xyz[4] = INFINITY;
        CHECK_EQ_STATUS(fn(&m, &v, NULL, &frags), HFVIS_ERR_INVALID_ARGUMENT);
        s.xyz[4] = (float)b[1];
        o = hfvis_voxelize_options_default(), o.method = (hfvis_voxelize_method)3;
        CHECK_EQ_STATUS(fn(&m, &v, &o, &frags), HFVIS_ERR_INVALID_ARGUMENT);
        o = hfvis_voxelize_options_default(), o.method = (hfvis_voxelize_method)-1;
        CHECK_EQ_STATUS(fn(&m, &v, &o, &frags), HFVIS_ERR_INVALID_ARGUMENT);
        o = hfvis_voxelize_options_default(), o.axes = (hfvis_voxelize_axes)5;
        CHECK_EQ_STATUS(fn(&m, &v, &o, &frags), HFVIS_ERR_INVALID_ARGUMENT);
        o = vox_opts(HFVIS_VOXELIZE_GS_SLICING, HFVIS_AXES_DOMINANT, -1);
        CHECK_EQ_STATUS(fn(&m, &v, &o, &frags), HFVIS_ERR_INVALID_ARGUMENT);
        o = vox_opts(HFVIS_VOXELIZE_PIXEL_RULE, HFVIS_AXES_DOMINANT, 9);
        CHECK_EQ_STATUS(fn(&m, &v, &o, &frags), HFVIS_ERR_INVALID_ARGUMENT);
        o = vox_opts(HFVIS_VOXELIZE_GS_SLICING, HFVIS_AXES_DOMINANT, 6);
        CHECK_EQ_STATUS(fn(&m, &v, &o, &frags), HFVIS_ERR_INVALID_ARGUMENT);
        o = vox_opts(HFVIS_VOXELIZE_FRAGMENT_CLIPPING, HFVIS_AXES_DOMINANT, 2);
        CHECK_EQ_STATUS(fn(&m, &v, &o, &frags), HFVIS_ERR_INVALID_ARGUMENT);
        o = vox_opts(HFVIS_VOXELIZE_GS_SLICING, HFVIS_AXES_DOMINANT, 7);
        CHECK_EQ_STATUS(fn(&m, &v, &o, NULL), HFVIS_OK);
        hfvis_volume_clear(&v, 0.25f);
    }
    CHECK(frags == 777);
    for (i = 0; i < 8 * 8 * 8 * 2; i++)
        if (st[i] != 0.25f) bad++;
    CHECK(bad == 0);
    /* occupancy */
    o = hfvis_voxelize_options_default();
    CHECK_EQ_STATUS(hfvis_voxelize_occupancy(NULL, &g, &o, occ), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_voxelize_occupancy(&m, NULL, &o, occ), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_voxelize_occupancy(&m, &g, &o, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    bg.dims[0] = -3;
    CHECK_EQ_STATUS(hfvis_voxelize_occupancy(&m, &bg, &o, occ), HFVIS_ERR_INVALID_ARGUMENT);
    bg = g, bg.dims[0] = bg.dims[1] = bg.dims[2] = 2048; /* 2^33 voxels > HFVIS_VOLUME_MAX_VOXELS */
    CHECK_EQ_STATUS(hfvis_voxelize_occupancy(&m, &bg, &o, occ), HFVIS_ERR_INVALID_ARGUMENT);
    o.axes = (hfvis_voxelize_axes)99;
    CHECK_EQ_STATUS(hfvis_voxelize_occupancy(&m, &g, &o, occ), HFVIS_ERR_INVALID_ARGUMENT);
    o = vox_opts(HFVIS_VOXELIZE_PIXEL_RULE, HFVIS_AXES_DOMINANT, 3);
    CHECK_EQ_STATUS(hfvis_voxelize_occupancy(&m, &g, &o, occ), HFVIS_ERR_INVALID_ARGUMENT);
    for (i = 0; i < sizeof occ; i++)
        if (occ[i] != 9) bad++;
    CHECK(bad == 0);
    CHECK_EQ_STATUS(hfvis_voxelize_occupancy(&m, &g, NULL, occ), HFVIS_OK);
    vox_soup_free(&s);
}

/* The surface voxelizers allocate nothing: the options' allocator is never called (there is no
 * allocation site to fail). */
TEST(no_allocation)
{
    const double c0[3] = { 0.0, 0.0, 0.0 };
    test_counting cnt;
    hfvis_allocator al;
    hfvis_mesh m;
    hfvis_volume_grid g;
    hfvis_volume v;
    float *st;
    uint8_t *occ;
    int mi, ai;
    al = test_counting_allocator(&cnt, 0);
    CHECK_EQ_STATUS(hfvis_mesh_torus(NULL, c0, 1.0, 0.4, 24, 12, &m), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_volume_grid_fit(&m, 24, 0.05, 0, &g), HFVIS_OK);
    st = vox_storage(&g, 4);
    occ = (uint8_t *)malloc(hfvis_volume_floats(&g, 1));
    hfvis_volume_init(&v, &g, 4, st, HFVIS_BLEND_ADD);
    for (mi = 0; mi < 3; mi++)
        for (ai = 0; ai < 2; ai++) {
            hfvis_voxelize_options o = vox_opts(vox_methods[mi], ai ? HFVIS_AXES_ALL : HFVIS_AXES_DOMINANT, mi ? 9 : 0);
            o.alloc = &al;
            o.fragment = hfvis_voxel_fragment_normal_occupancy;
            CHECK_EQ_STATUS(hfvis_voxelize_surface(&m, &v, &o, NULL), HFVIS_OK);
            CHECK_EQ_STATUS(hfvis_voxelize_surface_reference(&m, &v, &o, NULL), HFVIS_OK);
            CHECK_EQ_STATUS(hfvis_voxelize_occupancy(&m, &g, &o, occ), HFVIS_OK);
        }
    CHECK(cnt.allocs == 0 && cnt.frees == 0);
    free(st);
    free(occ);
    hfvis_mesh_free(NULL, &m);
}

int main(int argc, char **argv)
{
    TEST_INIT(argc, argv);
    RUN(gs_max_slices);
    RUN(options_default);
    RUN(cube_361);
    RUN(box_410);
    RUN(triangle_36);
    RUN(icosphere_counts);
    RUN(fast_equals_reference_soups);
    RUN(fast_equals_reference_meshes);
    RUN(fragment_clipping_is_pixel_rule);
    RUN(gs_slicing_vs_pixel_rule);
    RUN(all_axes_superset_and_max_merge);
    RUN(blend_ops);
    RUN(watertight_shared_edges);
    RUN(fragment_contents);
    RUN(attribute_callbacks);
    RUN(vertex_limit_steep_triangle);
    RUN(vertex_limit_mesh_holes);
    RUN(three_axes_six_separating);
    RUN(translation_invariance);
    RUN(degenerate_and_extreme_triangles);
    RUN(pathological_estimates);
    RUN(bad_arguments);
    RUN(no_allocation);
    return TEST_DONE();
}
