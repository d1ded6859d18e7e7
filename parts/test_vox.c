/* test_vox.c - surface voxelizers and the Volume Buffer attribute path ([G12] ch. 5 Alg. 4,
 * ch. 6 Alg. 5/6; spec voxel §3.4-3.8, §3.13). Exact analytic counts of spec §3.13, the fast
 * routines against their per-voxel oracle bit for bit, the output-vertex holes, 6-separation of
 * the three-axis variant, blends, callbacks, bad arguments. */
#include "hfvis.h"
#include "test.h"

#include <stdint.h>
#include <stdlib.h>

/* Icosphere area of spec §3.13.4 is quoted to 0.1: 5025.0 */
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
    size_t n = hfvis_volume_size(g, channels);
    return (float *)malloc(sizeof(float) * (n ? n : 1));
}

static size_t vox_count_ch0(const hfvis_volume *v)
{
    size_t n = hfvis_volume_size(&v->grid, 1), i, c = 0;
    for (i = 0; i < n; i++)
        if (v->data[i * (size_t)v->channels] != 0.0f) c++;
    return c;
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
    size_t n = hfvis_volume_size(g, 1), fa = 0, fb = 0, cnt = 0, i;
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
    /* spec §3.7: GS floor((V-3)/4): 7, 11, 15, 19 -> 1..4; PS floor(V/3): 6, 9, 12, 15 -> 2..5 */
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


/* ---- spec §3.13 analytic counts ----------------------------------------------------------- */

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

int main(int argc, char **argv)
{
    TEST_INIT(argc, argv);
    RUN(gs_max_slices);
    RUN(options_default);
    RUN(cube_361);
    RUN(box_410);
    RUN(triangle_36);
    RUN(icosphere_counts);
    return TEST_DONE();
}
