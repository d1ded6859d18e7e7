/* test_binary_voxel.c - binary voxelizers (voxel.c section 8): the triangle-box SAT, conservative
 * voxelization (fast path == per-voxel SAT reference, bit for bit), solid voxelization by parity
 * (== generalized winding number reference; box and sphere counts), watertightness, the bitmask
 * voxelizer, the .binvox codec and the raw writer. Spec voxel §3.9, §3.13. */
#include "hfvis.h"
#include "test.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The sphere's tessellated volume lies between its inscribed and circumscribed spheres; voxel
 * centres are compared with exact lattice counts of those, so no tolerance is needed there.
 * Relative tolerance of a torus' voxel count vs its mesh volume at tube radius 5 voxels: lattice
 * noise of about 3700 centres near a 1600-voxel^2 surface, ~1%. */
#define TC_TORUS_VOLUME_REL 0.02
/* The 32x16-facet torus' own volume vs the smooth torus: faceting loses ~3.2%. */
#define TC_TORUS_FACET_REL 0.04
/* Round trip of a 17-digit number through the binvox header: a few ulps of the parser. */
#define TC_NUMBER_REL 4e-15

/* ---- helpers ------------------------------------------------------------------------------ */

static uint64_t tc_state;
static void tc_seed(uint64_t s) { tc_state = s * 2862933555777941757ull + 3037000493ull; }
static double tc_unit(void) /* [0, 1) */
{
    tc_state = tc_state * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(tc_state >> 11) * (1.0 / 9007199254740992.0);
}
static int tc_int(int n) { return (int)(tc_unit() * (double)n); }

static hfvis_volume_grid tc_grid(int nx, int ny, int nz)
{
    hfvis_volume_grid g;
    g.origin[0] = g.origin[1] = g.origin[2] = 0.0;
    g.cell[0] = g.cell[1] = g.cell[2] = 1.0;
    g.dims[0] = nx;
    g.dims[1] = ny;
    g.dims[2] = nz;
    return g;
}

static size_t tc_voxels(const hfvis_volume_grid *g)
{
    return (size_t)g->dims[0] * (size_t)g->dims[1] * (size_t)g->dims[2];
}

/* A soup mesh owned by the test. */
typedef struct tc_soup {
    float *xyz;
    uint32_t *idx;
    hfvis_mesh m;
} tc_soup;

static void tc_soup_alloc(tc_soup *s, size_t ntri)
{
    size_t i;
    s->xyz = (float *)malloc(ntri * 9 * sizeof(float));
    s->idx = (uint32_t *)malloc(ntri * 3 * sizeof(uint32_t));
    for (i = 0; i < 3 * ntri; i++) s->idx[i] = (uint32_t)i;
    s->m.xyz = s->xyz;
    s->m.vertex_count = 3 * ntri;
    s->m.indices = s->idx;
    s->m.triangle_count = ntri;
}

static void tc_soup_free(tc_soup *s)
{
    free(s->xyz);
    free(s->idx);
}

/* Conservative fast vs reference: same voxels, same count. Returns the count. */
static size_t tc_cons_check(const hfvis_mesh *m, const hfvis_volume_grid *g, int *mismatch)
{
    size_t n = tc_voxels(g), na = 0, nb = 0, i, diff = 0;
    uint8_t *a = (uint8_t *)malloc(n), *b = (uint8_t *)malloc(n);
    CHECK_EQ_STATUS(hfvis_voxelize_conservative(m, g, NULL, a, &na), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_voxelize_conservative_reference(m, g, NULL, b, &nb), HFVIS_OK);
    for (i = 0; i < n; i++) diff += a[i] != b[i];
    if (diff || na != nb) {
        (*mismatch)++;
        fprintf(stderr, "  conservative mismatch: %zu voxels differ, counts %zu vs %zu\n", diff, na,
                nb);
#ifdef TC_DEBUG
        {
            size_t t;
            for (t = 0; t < m->triangle_count; t++) {
                hfvis_mesh one = *m;
                size_t n1 = 0, n2 = 0;
                one.indices = m->indices + 3 * t;
                one.triangle_count = 1;
                hfvis_voxelize_conservative(&one, g, NULL, a, &n1);
                hfvis_voxelize_conservative_reference(&one, g, NULL, b, &n2);
                if (n1 != n2 || memcmp(a, b, n)) {
                    int k;
                    fprintf(stderr, "  triangle %zu: grid o %a %a %a c %a %a %a d %d %d %d\n", t,
                            g->origin[0], g->origin[1], g->origin[2], g->cell[0], g->cell[1], g->cell[2],
                            g->dims[0], g->dims[1], g->dims[2]);
                    for (k = 0; k < 3; k++) {
                        const float *v = m->xyz + 3 * m->indices[3 * t + (size_t)k];
                        fprintf(stderr, "    %a %a %a\n", (double)v[0], (double)v[1], (double)v[2]);
                    }
                    for (i = 0; i < n; i++) if (a[i] != b[i]) fprintf(stderr, "    voxel %zu fast %d ref %d\n", i, a[i], b[i]);
                    break;
                }
            }
        }
#endif
    }
    free(a);
    free(b);
    return na;
}

/* ---- SAT ---------------------------------------------------------------------------------- */

TEST(sat_cases)
{
    static const double c[3] = {0.5, 0.5, 0.5}, h[3] = {0.5, 0.5, 0.5};
    double a[3], b[3], d[3];
    /* inside */
    a[0] = 0.2; a[1] = 0.2; a[2] = 0.5;
    b[0] = 0.8; b[1] = 0.2; b[2] = 0.5;
    d[0] = 0.2; d[1] = 0.8; d[2] = 0.5;
    CHECK(hfvis_triangle_box_overlap(c, h, a, b, d) == 1);
    /* far away along x: a box axis separates */
    a[0] += 3.0; b[0] += 3.0; d[0] += 3.0;
    CHECK(hfvis_triangle_box_overlap(c, h, a, b, d) == 0);
    /* touching the face x = 1 with a vertex: closed sets overlap */
    a[0] = 1.0; a[1] = 0.5; a[2] = 0.5;
    b[0] = 2.0; b[1] = 0.0; b[2] = 0.5;
    d[0] = 2.0; d[1] = 1.0; d[2] = 0.5;
    CHECK(hfvis_triangle_box_overlap(c, h, a, b, d) == 1);
    a[0] = 1.0 + 1e-12;
    CHECK(hfvis_triangle_box_overlap(c, h, a, b, d) == 0);
    /* a triangle in the plane z = 1 (the shared face of two voxels) overlaps both */
    a[0] = 0.2; a[1] = 0.2; a[2] = 1.0;
    b[0] = 0.8; b[1] = 0.2; b[2] = 1.0;
    d[0] = 0.2; d[1] = 0.8; d[2] = 1.0;
    CHECK(hfvis_triangle_box_overlap(c, h, a, b, d) == 1);
    {
        double c2[3] = {0.5, 0.5, 1.5};
        CHECK(hfvis_triangle_box_overlap(c2, h, a, b, d) == 1);
    }
    /* the plane separates: a big triangle passing beside the corner (x + y + z = 3.2 > 3) */
    a[0] = 3.2; a[1] = 0.0; a[2] = 0.0;
    b[0] = 0.0; b[1] = 3.2; b[2] = 0.0;
    d[0] = 0.0; d[1] = 0.0; d[2] = 3.2;
    CHECK(hfvis_triangle_box_overlap(c, h, a, b, d) == 0);
    a[0] = b[1] = d[2] = 2.9; /* x + y + z = 2.9 cuts the corner region */
    CHECK(hfvis_triangle_box_overlap(c, h, a, b, d) == 1);
    /* an edge axis separates: the triangle's bounding box and plane slab meet the box, but the
     * triangle passes beside the corner (1,1,z): vertices far in x and in y, not both */
    a[0] = 1.6; a[1] = -3.0; a[2] = 0.5;
    b[0] = 1.6; b[1] = 3.0; b[2] = 0.5;
    d[0] = -3.0; d[1] = 1.6; d[2] = 0.5;
    /* in the plane z = 0.5 it is the half plane x <= 1.6, y <= 1.6 cut by the line through
     * (1.6, 3) and (-3, 1.6): x - 3.2857 (y - 1.6) ... it contains (1, 1): overlap */
    CHECK(hfvis_triangle_box_overlap(c, h, a, b, d) == 1);
    a[0] = 4.0; a[1] = 1.05; a[2] = 0.5;
    b[0] = 1.05; b[1] = 4.0; b[2] = 0.5;
    d[0] = 4.0; d[1] = 4.0; d[2] = 0.5;
    /* x + y >= 5.05 on the triangle, x + y <= 2 on the box: the axis e_z x (b - a) separates
     * while the bounding boxes [1.05, 4]^2 and [0, 1]^2 still... do not: nudge it */
    CHECK(hfvis_triangle_box_overlap(c, h, a, b, d) == 0);
    a[1] = 0.9;
    b[0] = 0.9;
    /* now the bounding boxes overlap ([0.9, 4]^2 meets [0, 1]^2) but x + y >= 4.9: the edge
     * axis e_z x f separates */
    CHECK(hfvis_triangle_box_overlap(c, h, a, b, d) == 0);
    /* degenerate triangles are tested as the segment or point they are */
    a[0] = 0.5; a[1] = 0.5; a[2] = 0.5;
    CHECK(hfvis_triangle_box_overlap(c, h, a, a, a) == 1);
    b[0] = 5.0; b[1] = 5.0; b[2] = 5.0;
    CHECK(hfvis_triangle_box_overlap(c, h, b, b, b) == 0);
    CHECK(hfvis_triangle_box_overlap(c, h, a, b, b) == 1);
}

/* ---- conservative: analytic counts ------------------------------------------- */

TEST(conservative_spec_counts)
{
    hfvis_volume_grid g = tc_grid(16, 16, 16);
    hfvis_mesh m;
    int bad = 0;
    size_t n;
    {
        /* 1. cube [2.25, 10.25]^3: the shell of the 9^3 block i, j, k in 2..10: 9^3 - 7^3 */
        double lo[3] = {2.25, 2.25, 2.25}, hi[3] = {10.25, 10.25, 10.25};
        CHECK_EQ_STATUS(hfvis_mesh_box(NULL, lo, hi, &m), HFVIS_OK);
        n = tc_cons_check(&m, &g, &bad);
        CHECK(n == 386);
        hfvis_mesh_free(NULL, &m);
    }
    {
        /* 2. box [2.2,3.3,4.4]-[12.7,9.6,13.1]: 11*7*10 - 9*5*8 */
        double lo[3] = {2.2, 3.3, 4.4}, hi[3] = {12.7, 9.6, 13.1};
        CHECK_EQ_STATUS(hfvis_mesh_box(NULL, lo, hi, &m), HFVIS_OK);
        n = tc_cons_check(&m, &g, &bad);
        CHECK(n == 410);
        hfvis_mesh_free(NULL, &m);
    }
    {
        /* 3. the triangle (0.2,0.2,0.5) (8.7,0.2,0.5) (0.2,8.7,0.5): i + j <= 8, slice 0 */
        static const float xyz[9] = {0.2f, 0.2f, 0.5f, 8.7f, 0.2f, 0.5f, 0.2f, 8.7f, 0.5f};
        static const uint32_t idx[3] = {0, 1, 2};
        hfvis_mesh t;
        uint8_t occ[16 * 16 * 16];
        int i, j, k, ok = 1;
        t.xyz = xyz;
        t.vertex_count = 3;
        t.indices = idx;
        t.triangle_count = 1;
        n = tc_cons_check(&t, &g, &bad);
        CHECK(n == 45);
        CHECK_EQ_STATUS(hfvis_voxelize_conservative(&t, &g, NULL, occ, NULL), HFVIS_OK);
        for (k = 0; k < 16; k++)
            for (j = 0; j < 16; j++)
                for (i = 0; i < 16; i++)
                    ok &= occ[(k * 16 + j) * 16 + i] == (k == 0 && i + j <= 8);
        CHECK(ok);
    }
    {
        /* 4. icosphere (5 subdivisions, 20480 triangles) r = 20 at (32.1, 31.7, 32.3) in 64^3 */
        double c[3] = {32.1, 31.7, 32.3};
        hfvis_volume_grid g64 = tc_grid(64, 64, 64);
        CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c, 20.0, 5, &m), HFVIS_OK);
        CHECK(m.triangle_count == 20480);
        n = tc_cons_check(&m, &g64, &bad);
        CHECK(n == 7542);
        printf("  icosphere r=20 in 64^3: conservative %zu voxels (prototype count 7542)\n", n);
        hfvis_mesh_free(NULL, &m);
    }
    CHECK(bad == 0);
}

/* ---- conservative: fast == reference ---------------------------------------------------- */

/* Random soup of ntri triangles in a grid of side n: sizes from sub-voxel to half the grid,
 * some partly outside. */
static void tc_random_soup(tc_soup *s, size_t ntri, double n, double maxsize)
{
    size_t t;
    int k, a;
    tc_soup_alloc(s, ntri);
    for (t = 0; t < ntri; t++) {
        double c[3], size = maxsize * pow(tc_unit(), 3.0);
        for (a = 0; a < 3; a++) c[a] = -2.0 + (n + 4.0) * tc_unit();
        for (k = 0; k < 3; k++)
            for (a = 0; a < 3; a++)
                s->xyz[9 * t + 3 * (size_t)k + (size_t)a] = (float)(c[a] + size * (tc_unit() - 0.5));
    }
}

/* Adversarial soup: vertices on the voxel lattice (integers, half-integers) or one float ulp
 * off them, axis-aligned triangles (two or three equal coordinates), triangles in voxel faces,
 * along voxel edges and through voxel corners. */
static float tc_lattice_coord(int n)
{
    float v = (float)tc_int(2 * n + 1) * 0.5f;
    int r = tc_int(6);
    if (r == 0) v = nextafterf(v, 1e9f);
    else if (r == 1) v = nextafterf(v, -1e9f);
    else if (r == 2) v += 0.25f;
    return v;
}

static void tc_adversarial_soup(tc_soup *s, size_t ntri, int n)
{
    size_t t;
    int k, a;
    tc_soup_alloc(s, ntri);
    for (t = 0; t < ntri; t++) {
        float *v = s->xyz + 9 * t;
        int mode = tc_int(4), flat = tc_int(3);
        for (k = 0; k < 3; k++)
            for (a = 0; a < 3; a++) v[3 * k + a] = tc_lattice_coord(n);
        if (mode >= 1) { /* axis-aligned: one coordinate shared by the three vertices */
            v[3 + flat] = v[flat];
            v[6 + flat] = v[flat];
        }
        if (mode == 2) { /* and a second one shared by two vertices: an edge along an axis */
            int b = (flat + 1) % 3;
            v[3 + b] = v[b];
        }
        if (mode == 3) { /* small: within a voxel or two */
            for (k = 1; k < 3; k++)
                for (a = 0; a < 3; a++) v[3 * k + a] = v[a] + (float)(tc_int(5) - 2) * 0.5f;
        }
    }
}

TEST(conservative_fast_equals_reference)
{
    int bad = 0, trial;
    tc_seed(11);
    for (trial = 0; trial < 24; trial++) {
        int n = 8 + tc_int(40);
        hfvis_volume_grid g = tc_grid(n, 6 + tc_int(40), 5 + tc_int(40));
        tc_soup s;
        if (trial % 3 == 1) { /* non-unit, anisotropic cells and an offset origin */
            int a;
            for (a = 0; a < 3; a++) {
                g.origin[a] = -1.3 + 2.6 * tc_unit();
                g.cell[a] = 0.7 + 0.6 * tc_unit();
            }
        }
        tc_random_soup(&s, 150, (double)n, trial % 2 ? 3.0 : 0.5 * (double)n);
        tc_cons_check(&s.m, &g, &bad);
        tc_soup_free(&s);
        tc_adversarial_soup(&s, 200, n / 2);
        g.origin[0] = g.origin[1] = g.origin[2] = 0.0;
        g.cell[0] = g.cell[1] = g.cell[2] = 1.0;
        tc_cons_check(&s.m, &g, &bad);
        tc_soup_free(&s);
    }
    {
        /* generator meshes at several resolutions and sub-voxel offsets */
        static const int res[3] = {17, 32, 45};
        hfvis_mesh meshes[5];
        double c[3] = {0.0, 0.0, 0.0}, lo[3] = {-1.0, -0.5, -0.75}, hi[3] = {1.0, 0.5, 0.75};
        int mi, r;
        CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c, 1.0, 3, &meshes[0]), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_mesh_uv_sphere(NULL, c, 1.0, 24, 12, &meshes[1]), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_mesh_torus(NULL, c, 1.0, 0.35, 32, 12, &meshes[2]), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_mesh_torus_knot(NULL, c, 1.0, 2, 3, 200, 8, &meshes[3]), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_mesh_box(NULL, lo, hi, &meshes[4]), HFVIS_OK);
        for (mi = 0; mi < 5; mi++)
            for (r = 0; r < 3; r++) {
                hfvis_volume_grid g;
                CHECK_EQ_STATUS(hfvis_volume_grid_fit(&meshes[mi], res[r], 0.05, r == 1, &g), HFVIS_OK);
                tc_cons_check(&meshes[mi], &g, &bad);
                g.origin[0] += 0.37 * g.cell[0]; /* sub-voxel offsets */
                g.origin[2] -= 0.5 * g.cell[2];
                tc_cons_check(&meshes[mi], &g, &bad);
                g.origin[1] -= 0.5 * g.cell[1]; /* box faces exactly on voxel faces, r = 1 */
                tc_cons_check(&meshes[mi], &g, &bad);
            }
        for (mi = 0; mi < 5; mi++) hfvis_mesh_free(NULL, &meshes[mi]);
    }
    {
        /* giant triangles (vertices up to 1e12 cells away) crossing a small grid: the fast
         * path's margins grow with the coordinates and its candidate ranges get long */
        hfvis_volume_grid g = tc_grid(20, 18, 22);
        tc_soup s;
        size_t t;
        int a;
        tc_seed(77);
        tc_soup_alloc(&s, 40);
        for (t = 0; t < 40; t++) {
            /* centroid c inside the grid: v0 = c + big d0, v1 = c + big d1, v2 = c - big (d0 + d1) */
            double big = pow(10.0, 2.0 + 10.0 * tc_unit()), c[3], d0[3], d1[3];
            for (a = 0; a < 3; a++) {
                c[a] = 2.0 + 16.0 * tc_unit();
                d0[a] = 2.0 * tc_unit() - 1.0;
                d1[a] = 2.0 * tc_unit() - 1.0;
            }
            for (a = 0; a < 3; a++) {
                s.xyz[9 * t + (size_t)a] = (float)(c[a] + big * d0[a]);
                s.xyz[9 * t + 3 + (size_t)a] = (float)(c[a] + big * d1[a]);
                s.xyz[9 * t + 6 + (size_t)a] = (float)(c[a] - big * (d0[a] + d1[a]));
            }
        }
        tc_cons_check(&s.m, &g, &bad);
        tc_soup_free(&s);
    }
    {
        /* a box whose faces lie exactly on voxel faces: every face voxel layer on both sides */
        double lo[3] = {2.0, 3.0, 4.0}, hi[3] = {9.0, 8.0, 10.0};
        hfvis_volume_grid g = tc_grid(14, 13, 15);
        hfvis_mesh m;
        size_t n;
        CHECK_EQ_STATUS(hfvis_mesh_box(NULL, lo, hi, &m), HFVIS_OK);
        n = tc_cons_check(&m, &g, &bad);
        /* closed cubes touching the box's boundary: i in 1..9 (9), j in 2..8 (7), k in 3..10 (8),
         * minus the interior block that does not touch it: i 3..7, j 4..6, k 5..8 */
        CHECK(n == (size_t)(9 * 7 * 8 - 5 * 3 * 4));
        hfvis_mesh_free(NULL, &m);
    }
    CHECK(bad == 0);
}

/* Slivers (the 100k knot's triangles are about 0.5 x 6 voxels): long thin triangles in every
 * orientation, near-collinear ones, slivers snapped to the half-voxel lattice or lying in a
 * lattice plane, and long strips of slivers sharing vertices (so most candidate voxels are set
 * already when a triangle is reached), with both bounding-box orientations of the fast path's
 * row/column frame; fast == reference on each soup. */
static void tc_sliver_soup(tc_soup *s, size_t ntri, double n, double maxlen)
{
    size_t t;
    int k, a;
    tc_soup_alloc(s, ntri);
    for (t = 0; t < ntri; t++) {
        float *v = s->xyz + 9 * t;
        double c[3], d[3], e[3], len = maxlen * (0.05 + tc_unit()), nd = 0.0;
        double width = len * pow(10.0, -5.0 * tc_unit()); /* aspect 1 to 1e5 */
        int mode = tc_int(5);
        for (a = 0; a < 3; a++) {
            c[a] = -1.0 + (n + 2.0) * tc_unit();
            d[a] = tc_unit() - 0.5;
            e[a] = tc_unit() - 0.5;
            nd += d[a] * d[a];
        }
        nd = sqrt(nd) + 1e-300;
        for (a = 0; a < 3; a++) {
            v[a] = (float)c[a];
            v[3 + a] = (float)(c[a] + len * d[a] / nd);
            v[6 + a] = (float)(c[a] + (0.1 + 0.8 * tc_unit()) * len * d[a] / nd + width * e[a]);
        }
        if (mode == 1) /* on the half-voxel lattice */
            for (k = 0; k < 9; k++) v[k] = floorf(v[k] * 2.0f) * 0.5f;
        if (mode == 2) { /* in a lattice plane */
            int f = tc_int(3);
            v[f] = v[3 + f] = v[6 + f] = floorf(v[f]);
        }
        if (mode == 3) /* collinear in exact arithmetic before rounding to float */
            for (a = 0; a < 3; a++) v[6 + a] = (float)(c[a] + 0.375 * len * d[a] / nd);
    }
}

/* A strip of 2 * segs slivers along a helix-like curve, sharing vertices: ring i has vertices
 * 2i (inner) and 2i + 1 (outer), width w cells. */
static void tc_strip(float *xyz, uint32_t *idx, int segs, double n, double w, double phase)
{
    int i;
    for (i = 0; i <= segs; i++) {
        double u = phase + 6.0 * (double)i / (double)segs, r = 0.35 * n;
        double x = 0.5 * n + r * cos(u), y = 0.5 * n + r * sin(u), z = 0.5 * n + 0.3 * n * sin(0.7 * u);
        xyz[6 * i + 0] = (float)x;
        xyz[6 * i + 1] = (float)y;
        xyz[6 * i + 2] = (float)z;
        xyz[6 * i + 3] = (float)(x + w * cos(u));
        xyz[6 * i + 4] = (float)(y + w * sin(u));
        xyz[6 * i + 5] = (float)(z + w * 0.3);
        if (i < segs) {
            uint32_t a = (uint32_t)(2 * i), *q = idx + 6 * i;
            q[0] = a;
            q[1] = a + 1;
            q[2] = a + 2;
            q[3] = a + 1;
            q[4] = a + 3;
            q[5] = a + 2;
        }
    }
}

TEST(conservative_fast_equals_reference_slivers)
{
    int bad = 0, trial;
    tc_seed(2010);
    for (trial = 0; trial < 40; trial++) {
        int n = 10 + tc_int(40);
        hfvis_volume_grid g = tc_grid(n, 8 + tc_int(40), 8 + tc_int(40));
        tc_soup s;
        if (trial % 2) {
            int a;
            for (a = 0; a < 3; a++) {
                g.origin[a] = -0.5 + tc_unit();
                g.cell[a] = 0.6 + 0.8 * tc_unit();
            }
        }
        tc_sliver_soup(&s, 200, (double)n, trial % 4 == 3 ? 4.0 * (double)n : 1.0 + 12.0 * tc_unit());
        tc_cons_check(&s.m, &g, &bad);
        tc_soup_free(&s);
    }
    {
        enum { SEGS = 600 };
        static float xyz[6 * (SEGS + 1)];
        static uint32_t idx[6 * SEGS];
        hfvis_volume_grid g = tc_grid(40, 40, 40);
        hfvis_mesh m;
        int w;
        m.xyz = xyz;
        m.vertex_count = 2 * (SEGS + 1);
        m.indices = idx;
        m.triangle_count = 2 * SEGS;
        for (w = 0; w < 4; w++) {
            tc_strip(xyz, idx, SEGS, 40.0, 0.25 + 0.75 * (double)w, 0.3 * (double)w);
            tc_cons_check(&m, &g, &bad);
        }
    }
    CHECK(bad == 0);
}

/* Translating a mesh by whole voxels translates the conservative voxel set. */
TEST(conservative_translation)
{
    tc_soup s;
    hfvis_volume_grid g = tc_grid(30, 30, 30);
    uint8_t *a = (uint8_t *)malloc(27000), *b = (uint8_t *)malloc(27000);
    size_t i, na, nb;
    int ok = 1, x, y, z;
    tc_seed(5);
    tc_random_soup(&s, 60, 20.0, 6.0);
    /* on a 1/1024 lattice: the shift below is exact, and so is every SAT expression */
    for (i = 0; i < 3 * s.m.vertex_count; i++) s.xyz[i] = floorf(s.xyz[i] * 1024.0f) / 1024.0f;
    CHECK_EQ_STATUS(hfvis_voxelize_conservative(&s.m, &g, NULL, a, &na), HFVIS_OK);
    for (i = 0; i < 3 * s.m.vertex_count; i++) s.xyz[i] += (i % 3 == 0) ? 3.0f : (i % 3 == 1 ? 2.0f : 1.0f);
    CHECK_EQ_STATUS(hfvis_voxelize_conservative(&s.m, &g, NULL, b, &nb), HFVIS_OK);
    /* the soup lies in [-2, 22]+-3: the shifted set, clipped at the grid's far sides */
    for (z = 0; z < 29; z++)
        for (y = 0; y < 28; y++)
            for (x = 0; x < 27; x++)
                ok &= a[(z * 30 + y) * 30 + x] == b[((z + 1) * 30 + y + 2) * 30 + x + 3];
    CHECK(ok);
    free(a);
    free(b);
    tc_soup_free(&s);
}

/* ---- solid ------------------------------------------------------------------------------ */

/* Solid fast vs reference; returns the fast count. */
static size_t tc_solid_check(const hfvis_mesh *m, const hfvis_volume_grid *g,
                             hfvis_parity_axis axis, int *mismatch)
{
    size_t n = tc_voxels(g), na = 0, nb = 0, i, diff = 0;
    uint8_t *a = (uint8_t *)malloc(n), *b = (uint8_t *)malloc(n);
    hfvis_binary_voxel_options o = hfvis_binary_voxel_options_default();
    o.axis = axis;
    CHECK_EQ_STATUS(hfvis_voxelize_solid(m, g, &o, a, &na), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_voxelize_solid_reference(m, g, &o, b, &nb), HFVIS_OK);
    for (i = 0; i < n; i++) diff += a[i] != b[i];
    if (diff || na != nb) {
        (*mismatch)++;
        fprintf(stderr, "  solid mismatch (axis %d): %zu voxels differ, counts %zu vs %zu\n",
                (int)axis, diff, na, nb);
    }
    free(a);
    free(b);
    return na;
}

/* Voxel centres of a 'grid' inside the sphere (c, r): an exact lattice count. */
static size_t tc_lattice_sphere(const hfvis_volume_grid *g, const double c[3], double r, int strict)
{
    size_t n = 0;
    int i, j, k;
    for (k = 0; k < g->dims[2]; k++)
        for (j = 0; j < g->dims[1]; j++)
            for (i = 0; i < g->dims[0]; i++) {
                double dx = i + 0.5 - c[0], dy = j + 0.5 - c[1], dz = k + 0.5 - c[2];
                double d2 = dx * dx + dy * dy + dz * dz;
                n += strict ? d2 < r * r : d2 <= r * r;
            }
    return n;
}

TEST(solid_box_exact)
{
    /* box [2.2,3.3,4.4]-[12.7,9.6,13.1]: centres i+.5 in (2.2, 12.7) -> 11, (3.3, 9.6) -> 7,
     * (4.4, 13.1) -> 9: 693 voxels, along every axis */
    double lo[3] = {2.2, 3.3, 4.4}, hi[3] = {12.7, 9.6, 13.1};
    hfvis_volume_grid g = tc_grid(16, 16, 16);
    hfvis_mesh m;
    int bad = 0;
    CHECK_EQ_STATUS(hfvis_mesh_box(NULL, lo, hi, &m), HFVIS_OK);
    CHECK(tc_solid_check(&m, &g, HFVIS_PARITY_AXIS_DEFAULT, &bad) == 693);
    CHECK(tc_solid_check(&m, &g, HFVIS_PARITY_AXIS_X, &bad) == 693);
    CHECK(tc_solid_check(&m, &g, HFVIS_PARITY_AXIS_Y, &bad) == 693);
    hfvis_mesh_free(NULL, &m);
    {
        /* faces through voxel centres and edges through column centres: ties of the rule.
         * Box [2.5, 9.5] x [3.5, 7.5] x [1.5, 6.5]: centres strictly above a crossing count
         * as inside, so along z the voxels k = 2..6 of the columns i = 3..9 (the column on
         * the x = 2.5 face passes exactly through the edges: counted on one side only),
         * j = 4..7 (likewise) -> exactly (7)(4)(5) = 140 with each axis' own tie side */
        double lo2[3] = {2.5, 3.5, 1.5}, hi2[3] = {9.5, 7.5, 6.5};
        hfvis_volume_grid g2 = tc_grid(12, 10, 9);
        uint8_t occ[12 * 10 * 9];
        size_t n;
        int a;
        CHECK_EQ_STATUS(hfvis_mesh_box(NULL, lo2, hi2, &m), HFVIS_OK);
        for (a = 1; a <= 3; a++) {
            hfvis_binary_voxel_options o = hfvis_binary_voxel_options_default();
            o.axis = (hfvis_parity_axis)a;
            CHECK_EQ_STATUS(hfvis_voxelize_solid(&m, &g2, &o, occ, &n), HFVIS_OK);
            CHECK(n == 140);
        }
        hfvis_mesh_free(NULL, &m);
    }
    CHECK(bad == 0);
}

TEST(solid_spheres)
{
    int bad = 0, trial;
    tc_seed(17);
    for (trial = 0; trial < 4; trial++) {
        hfvis_volume_grid g = tc_grid(22, 22, 22);
        double c[3], r = 6.0 + 3.0 * tc_unit(), rin;
        size_t n, outer, inner;
        hfvis_mesh m;
        int a;
        for (a = 0; a < 3; a++) c[a] = 10.5 + tc_unit();
        if (trial < 2) {
            /* icosphere, 3 subdivisions: edges subtend at most ~0.105 rad; the faces lie at least
             * r cos(0.11) from the centre (a safe inscribed radius) */
            CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c, r, 3, &m), HFVIS_OK);
            rin = r * cos(0.11);
        } else {
            /* UV sphere 32 x 16: every face is within r cos(pi/16) cos(pi/32) of the centre */
            CHECK_EQ_STATUS(hfvis_mesh_uv_sphere(NULL, c, r, 32, 16, &m), HFVIS_OK);
            rin = r * cos(3.14159265358979 / 16.0) * cos(3.14159265358979 / 32.0);
        }
        n = tc_solid_check(&m, &g, (hfvis_parity_axis)(1 + trial % 3), &bad);
        outer = tc_lattice_sphere(&g, c, r, 0);
        inner = tc_lattice_sphere(&g, c, rin, 1);
        CHECK(n <= outer && n >= inner);
        printf("  sphere r=%.3f: solid %zu voxels, lattice bounds [%zu, %zu], 4/3 pi r^3 = %.1f\n",
               r, n, inner, outer, 4.0 / 3.0 * 3.14159265358979 * r * r * r);
        hfvis_mesh_free(NULL, &m);
    }
    CHECK(bad == 0);
}

/* Volume enclosed by a closed, outward-oriented mesh: (1/6) sum v0 . (v1 x v2) (grid units). */
static double tc_mesh_volume(const hfvis_mesh *m)
{
    double vol = 0.0;
    size_t t;
    int k, a;
    for (t = 0; t < m->triangle_count; t++) {
        double v[3][3];
        for (k = 0; k < 3; k++)
            for (a = 0; a < 3; a++) v[k][a] = (double)m->xyz[3 * m->indices[3 * t + (size_t)k] + (size_t)a];
        vol += v[0][0] * (v[1][1] * v[2][2] - v[1][2] * v[2][1])
               + v[0][1] * (v[1][2] * v[2][0] - v[1][0] * v[2][2])
               + v[0][2] * (v[1][0] * v[2][1] - v[1][1] * v[2][0]);
    }
    return vol / 6.0;
}

TEST(solid_torus_and_axes)
{
    double c[3] = {14.3, 13.6, 7.9};
    hfvis_volume_grid g = tc_grid(29, 28, 16);
    hfvis_mesh m;
    int bad = 0;
    size_t nz, nx, ny;
    double vol = 2.0 * 3.14159265358979 * 3.14159265358979 * 8.0 * 25.0, mvol;
    CHECK_EQ_STATUS(hfvis_mesh_torus(NULL, c, 8.0, 5.0, 32, 16, &m), HFVIS_OK);
    mvol = tc_mesh_volume(&m);
    nz = tc_solid_check(&m, &g, HFVIS_PARITY_AXIS_Z, &bad);
    nx = tc_solid_check(&m, &g, HFVIS_PARITY_AXIS_X, &bad);
    ny = tc_solid_check(&m, &g, HFVIS_PARITY_AXIS_Y, &bad);
    CHECK(nz == nx && nx == ny);
    CHECK_NEAR((double)nz, mvol, 0.0, TC_TORUS_VOLUME_REL);
    CHECK_NEAR(mvol, vol, 0.0, TC_TORUS_FACET_REL);
    printf("  torus R=8 r=5 (32x16 facets): solid %zu voxels, mesh volume %.1f, 2 pi^2 R r^2 = %.1f\n",
           nz, mvol, vol);
    hfvis_mesh_free(NULL, &m);
    CHECK(bad == 0);
}

/* The box's 12 triangles without triangles first .. first+count-1 (indices into idx, which
 * holds 36 entries). */
static hfvis_mesh tc_box_open(const hfvis_mesh *box, size_t first, size_t count, uint32_t *idx)
{
    hfvis_mesh open = *box;
    size_t t, q = 0;
    for (t = 0; t < 12; t++)
        if (t < first || t >= first + count) {
            memcpy(idx + 3 * q, box->indices + 3 * t, 3 * sizeof(uint32_t));
            q++;
        }
    open.indices = idx;
    open.triangle_count = q;
    return open;
}

/* hfvis_voxelize_solid along `axis` (allow_open 0) must reject the mesh and leave occ (4096
 * bytes) and the count untouched. */
static void tc_solid_rejects(const hfvis_mesh *m, const hfvis_volume_grid *g, int axis,
                             uint8_t *occ)
{
    hfvis_binary_voxel_options o = hfvis_binary_voxel_options_default();
    size_t n = 12345;
    o.axis = (hfvis_parity_axis)axis;
    memset(occ, 0x5a, 4096);
    CHECK_EQ_STATUS(hfvis_voxelize_solid(m, g, &o, occ, &n), HFVIS_ERR_FORMAT);
    CHECK(n == 12345 && occ[0] == 0x5a && occ[4095] == 0x5a);
}

TEST(solid_open_mesh)
{
    double lo[3] = {2.2, 3.3, 4.4}, hi[3] = {12.7, 9.6, 13.1};
    hfvis_volume_grid g = tc_grid(16, 16, 16);
    hfvis_mesh m, open;
    uint8_t occ[4096], ref[4096];
    hfvis_binary_voxel_options o = hfvis_binary_voxel_options_default();
    size_t n = 12345, i, nclosed;
    int a;
    CHECK_EQ_STATUS(hfvis_mesh_box(NULL, lo, hi, &m), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_voxelize_solid(&m, &g, NULL, ref, &nclosed), HFVIS_OK);
    for (a = 1; a <= 3; a++) {
        uint32_t idx[36];
        /* drop the second triangle of the -face of axis a (faces -x +x -y +y -z +z, two each) */
        open = tc_box_open(&m, (size_t)(4 * (a - 1) + 1), 1, idx);
        tc_solid_rejects(&open, &g, a, occ);
        o.axis = (hfvis_parity_axis)a;
        o.allow_open = 1;
        CHECK_EQ_STATUS(hfvis_voxelize_solid(&open, &g, &o, occ, &n), HFVIS_OK);
        /* a subset of the closed result: the columns through the missing triangle are empty */
        for (i = 0; i < 4096; i++) CHECK(occ[i] <= ref[i]);
        CHECK(n < nclosed && n > 0);
        /* the other axes' columns do not cross the hole (its plane is parallel to them), yet
         * the status is the same on every axis: the check looks along all three */
        tc_solid_rejects(&open, &g, a % 3 + 1, occ);
        o.axis = (hfvis_parity_axis)(a % 3 + 1);
        o.allow_open = 1; /* along that axis nothing falls out */
        CHECK_EQ_STATUS(hfvis_voxelize_solid(&open, &g, &o, occ, &n), HFVIS_OK);
        CHECK(n == nclosed);
    }
    hfvis_mesh_free(NULL, &m);
}

/* An open mesh gives the same status along every parity axis: a box with one whole face
 * missing (for each of the six faces) and the generated teapot (open spout and handle tubes,
 * like the Utah teapot's open rims), at several resolutions. Before the check looked along all
 * three axes, the box without its -x face passed along y and z and the teapot along some axes
 * (the shipped teapot.obj: 197,225 voxels along z, HFVIS_ERR_FORMAT along x and y). */
TEST(solid_open_mesh_every_axis)
{
    double lo[3] = {2.2, 3.3, 4.4}, hi[3] = {12.7, 9.6, 13.1};
    static const int res[3] = {16, 37, 64}; /* at 8 no column centre meets a tube's rim */
    hfvis_volume_grid g = tc_grid(16, 16, 16);
    hfvis_binary_voxel_options o = hfvis_binary_voxel_options_default();
    hfvis_mesh m, open;
    uint8_t occ[4096];
    size_t n;
    int face, a, q;
    CHECK_EQ_STATUS(hfvis_mesh_box(NULL, lo, hi, &m), HFVIS_OK);
    for (face = 0; face < 6; face++) {
        uint32_t idx[36];
        open = tc_box_open(&m, (size_t)(2 * face), 2, idx);
        for (a = 0; a <= 3; a++) tc_solid_rejects(&open, &g, a, occ); /* DEFAULT, X, Y, Z */
    }
    hfvis_mesh_free(NULL, &m);
    CHECK_EQ_STATUS(hfvis_mesh_teapot(NULL, 2, &m), HFVIS_OK);
    for (q = 0; q < 3; q++) {
        hfvis_volume_grid tg;
        uint8_t *buf;
        int status[4];
        CHECK_EQ_STATUS(hfvis_volume_grid_fit(&m, res[q], 0.05, 1, &tg), HFVIS_OK);
        buf = (uint8_t *)malloc((size_t)tg.dims[0] * (size_t)tg.dims[1] * (size_t)tg.dims[2]);
        CHECK(buf != NULL);
        if (!buf) break;
        for (a = 0; a <= 3; a++) {
            o.axis = (hfvis_parity_axis)a;
            o.allow_open = 0;
            status[a] = (int)hfvis_voxelize_solid(&m, &tg, &o, buf, &n);
            CHECK_EQ_STATUS((hfvis_status)status[a], HFVIS_ERR_FORMAT);
            o.allow_open = 1;
            CHECK_EQ_STATUS(hfvis_voxelize_solid(&m, &tg, &o, buf, &n), HFVIS_OK);
        }
        printf("  teapot n=2 at %dx%dx%d: solid status x %s, y %s, z %s\n", tg.dims[0], tg.dims[1],
               tg.dims[2], hfvis_status_string((hfvis_status)status[1]),
               hfvis_status_string((hfvis_status)status[2]),
               hfvis_status_string((hfvis_status)status[3]));
        free(buf);
    }
    hfvis_mesh_free(NULL, &m);
}

/* ---- watertightness ---------------------------------------------------------------------- */

TEST(watertight)
{
    double c[3] = {0.0, 0.0, 0.0}, lo[3] = {0, 0, 0}, hi[3] = {1, 2, 3};
    hfvis_mesh m, e;
    int r = -1;
    uint32_t *idx;
    CHECK_EQ_STATUS(hfvis_mesh_box(NULL, lo, hi, &m), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_mesh_is_watertight(&m, NULL, &r), HFVIS_OK);
    CHECK(r == 1);
    e = m;
    e.triangle_count = 11;
    CHECK_EQ_STATUS(hfvis_mesh_is_watertight(&e, NULL, &r), HFVIS_OK);
    CHECK(r == 0);
    /* one triangle flipped: its edges run the same way as their neighbours' */
    idx = (uint32_t *)malloc(36 * sizeof(uint32_t));
    memcpy(idx, m.indices, 36 * sizeof(uint32_t));
    idx[4] = m.indices[5];
    idx[5] = m.indices[4];
    e.indices = idx;
    e.triangle_count = 12;
    CHECK_EQ_STATUS(hfvis_mesh_is_watertight(&e, NULL, &r), HFVIS_OK);
    CHECK(r == 0);
    idx[5] = idx[4]; /* a repeated index */
    CHECK_EQ_STATUS(hfvis_mesh_is_watertight(&e, NULL, &r), HFVIS_OK);
    CHECK(r == 0);
    free(idx);
    e.triangle_count = 0;
    CHECK_EQ_STATUS(hfvis_mesh_is_watertight(&e, NULL, &r), HFVIS_OK);
    CHECK(r == 1);
    hfvis_mesh_free(NULL, &m);
    CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c, 1.0, 2, &m), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_mesh_is_watertight(&m, NULL, &r), HFVIS_OK);
    CHECK(r == 1);
    hfvis_mesh_free(NULL, &m);
    CHECK_EQ_STATUS(hfvis_mesh_torus(NULL, c, 1.0, 0.3, 12, 8, &m), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_mesh_is_watertight(&m, NULL, &r), HFVIS_OK);
    CHECK(r == 1);
    hfvis_mesh_free(NULL, &m);
    CHECK_EQ_STATUS(hfvis_mesh_teapot(NULL, 1, &m), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_mesh_is_watertight(&m, NULL, &r), HFVIS_OK);
    CHECK(r == 0);
    hfvis_mesh_free(NULL, &m);
    {
        /* a closed soup (no shared vertices): not watertight by indices, yet solid works */
        double lo2[3] = {1.2, 1.3, 1.4}, hi2[3] = {5.7, 4.6, 6.1};
        hfvis_volume_grid g = tc_grid(8, 8, 8);
        tc_soup s;
        size_t t, n1, n2;
        uint8_t occ[512];
        int k, a;
        CHECK_EQ_STATUS(hfvis_mesh_box(NULL, lo2, hi2, &m), HFVIS_OK);
        tc_soup_alloc(&s, 12);
        for (t = 0; t < 12; t++)
            for (k = 0; k < 3; k++)
                for (a = 0; a < 3; a++)
                    s.xyz[9 * t + 3 * (size_t)k + (size_t)a] = m.xyz[3 * m.indices[3 * t + (size_t)k] + (size_t)a];
        CHECK_EQ_STATUS(hfvis_mesh_is_watertight(&s.m, NULL, &r), HFVIS_OK);
        CHECK(r == 0);
        CHECK_EQ_STATUS(hfvis_voxelize_solid(&s.m, &g, NULL, occ, &n1), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_voxelize_solid(&m, &g, NULL, occ, &n2), HFVIS_OK);
        CHECK(n1 == n2 && n1 == (size_t)(5 * 4 * 5));
        tc_soup_free(&s);
        hfvis_mesh_free(NULL, &m);
    }
}

/* ---- bitmask ------------------------------------------------------------------------------ */

/* Bitmask count, checking the layout against the unpacked occupancy and subset of conservative. */
static size_t tc_bitmask_check(const hfvis_mesh *m, const hfvis_volume_grid *g, int *bad)
{
    size_t nw = hfvis_bitmask_words(g), n = 0, nc = 0, v = tc_voxels(g), i;
    uint32_t *bits = (uint32_t *)malloc(nw * sizeof(uint32_t));
    uint8_t *occ = (uint8_t *)malloc(v), *cons = (uint8_t *)malloc(v);
    int x, y, z, W = (g->dims[2] + 31) / 32;
    size_t set = 0;
    CHECK_EQ_STATUS(hfvis_voxelize_bitmask(m, g, NULL, bits, &n), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_bitmask_to_occupancy(g, bits, occ), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_voxelize_conservative(m, g, NULL, cons, &nc), HFVIS_OK);
    for (z = 0; z < g->dims[2]; z++)
        for (y = 0; y < g->dims[1]; y++)
            for (x = 0; x < g->dims[0]; x++) {
                size_t lin = ((size_t)z * (size_t)g->dims[1] + (size_t)y) * (size_t)g->dims[0] + (size_t)x;
                int bit = (int)((bits[((size_t)y * (size_t)g->dims[0] + (size_t)x) * (size_t)W + (size_t)(z >> 5)] >> (z & 31)) & 1u);
                if (bit != occ[lin]) (*bad)++;
                if (occ[lin] && !cons[lin]) (*bad)++; /* a subset of the conservative set */
                set += occ[lin];
            }
    if (set != n) (*bad)++;
    for (i = 0; i < nw; i++) /* padding bits above dims[2] stay 0 */
        if (g->dims[2] % 32 && (i % (size_t)W) == (size_t)W - 1 && (bits[i] >> (g->dims[2] % 32)))
            (*bad)++;
#ifdef HFVIS_VOXEL_ATTR_OCCUPANCY
    {
        /* the thesis' three-axis pixel-rule voxelization (vox part) gives the same set on inputs
         * without exact ties */
        hfvis_voxelize_options o = hfvis_voxelize_options_default();
        size_t diff = 0;
        o.axes = HFVIS_AXES_ALL;
        CHECK_EQ_STATUS(hfvis_voxelize_occupancy(m, g, &o, cons), HFVIS_OK);
        for (i = 0; i < v; i++) diff += cons[i] != occ[i];
        if (diff) {
            fprintf(stderr, "  bitmask vs three-axis occupancy: %zu voxels differ\n", diff);
            (*bad)++;
        }
    }
#endif
    free(bits);
    free(occ);
    free(cons);
    return n;
}

TEST(bitmask)
{
    hfvis_volume_grid g = tc_grid(16, 16, 16);
    hfvis_mesh m;
    int bad = 0, trial;
    size_t n;
    {
        /* ALL_AXES on the cube [2.25, 10.25]^3: 6*64 - 3*8 + 1 = 361 */
        double lo[3] = {2.25, 2.25, 2.25}, hi[3] = {10.25, 10.25, 10.25};
        CHECK_EQ_STATUS(hfvis_mesh_box(NULL, lo, hi, &m), HFVIS_OK);
        n = tc_bitmask_check(&m, &g, &bad);
        CHECK(n == 361);
        hfvis_mesh_free(NULL, &m);
    }
    {
        /* §3.13.2: 410 */
        double lo[3] = {2.2, 3.3, 4.4}, hi[3] = {12.7, 9.6, 13.1};
        CHECK_EQ_STATUS(hfvis_mesh_box(NULL, lo, hi, &m), HFVIS_OK);
        n = tc_bitmask_check(&m, &g, &bad);
        CHECK(n == 410);
        hfvis_mesh_free(NULL, &m);
    }
    {
        /* §3.13.3: the pixel-centre rule covers i + j <= 7: 36 */
        static const float xyz[9] = {0.2f, 0.2f, 0.5f, 8.7f, 0.2f, 0.5f, 0.2f, 8.7f, 0.5f};
        static const uint32_t idx[3] = {0, 1, 2};
        hfvis_mesh t;
        t.xyz = xyz;
        t.vertex_count = 3;
        t.indices = idx;
        t.triangle_count = 1;
        n = tc_bitmask_check(&t, &g, &bad);
        CHECK(n == 36);
    }
    {
        /* §3.13.4: icosphere r = 20 in 64^3, ALL_AXES = 4183 */
        double c[3] = {32.1, 31.7, 32.3};
        hfvis_volume_grid g64 = tc_grid(64, 64, 64);
        CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c, 20.0, 5, &m), HFVIS_OK);
        n = tc_bitmask_check(&m, &g64, &bad);
        CHECK(n == 4183);
        printf("  icosphere r=20 in 64^3: bitmask %zu voxels (prototype ALL_AXES 4183)\n", n);
        hfvis_mesh_free(NULL, &m);
    }
    tc_seed(23);
    for (trial = 0; trial < 6; trial++) {
        hfvis_volume_grid gr = tc_grid(10 + tc_int(30), 10 + tc_int(30), 20 + tc_int(60));
        tc_soup s;
        tc_random_soup(&s, 120, 20.0, 15.0);
        tc_bitmask_check(&s.m, &gr, &bad);
        tc_soup_free(&s);
    }
    CHECK(bad == 0);
}

/* ---- binvox and raw ------------------------------------------------------------------------ */

TEST(binvox_known_bytes)
{
    /* 2 x 1 x 1 grid padded to 2^3; voxel (1, 0, 0) set: binvox index 1*4 + 0 + 0 = 4 ->
     * runs (0,4) (1,1) (0,3) */
    hfvis_volume_grid g = tc_grid(2, 1, 1);
    uint8_t occ[2] = {0, 7};
    unsigned char buf[256];
    size_t w = 0, need;
    static const char head[] = "#binvox 1\ndim 2 2 2\ntranslate 0.5 -1.25 3\nscale 1\ndata\n";
    static const unsigned char runs[6] = {0, 4, 1, 1, 0, 3};
    g.origin[0] = 0.5;
    g.origin[1] = -1.25;
    g.origin[2] = 3.0;
    g.cell[0] = g.cell[1] = 0.5;
    g.cell[2] = 0.25; /* non-cubic: scale uses the largest cell: 2 * 0.5 */
    need = hfvis_binvox_encode_size(&g, occ);
    CHECK(need == sizeof head - 1 + 6);
    CHECK_EQ_STATUS(hfvis_binvox_encode(&g, occ, buf, need - 1, &w), HFVIS_ERR_BUFFER_TOO_SMALL);
    CHECK_EQ_STATUS(hfvis_binvox_encode(&g, occ, buf, sizeof buf, &w), HFVIS_OK);
    CHECK(w == need);
    CHECK(memcmp(buf, head, sizeof head - 1) == 0);
    CHECK(memcmp(buf + sizeof head - 1, runs, 6) == 0);
}

TEST(binvox_round_trip)
{
    int trial;
    tc_seed(31);
    for (trial = 0; trial < 12; trial++) {
        hfvis_volume_grid g = tc_grid(1 + tc_int(40), 1 + tc_int(40), 1 + tc_int(40)), d;
        size_t n = tc_voxels(&g), need, w = 0, i;
        uint8_t *occ = (uint8_t *)malloc(n), *back = NULL;
        unsigned char *buf;
        int a, D = g.dims[0], x, y, z, ok = 1;
        double density = trial % 3 == 0 ? 0.02 : (trial % 3 == 1 ? 0.5 : 0.97);
        static const double origins[6] = {0.1, -3.25, 1e-7, 12345.678, -2.5e20, 0.0};
        if (g.dims[1] > D) D = g.dims[1];
        if (g.dims[2] > D) D = g.dims[2];
        for (i = 0; i < n; i++) occ[i] = tc_unit() < density;
        for (a = 0; a < 3; a++) g.origin[a] = origins[(trial + a) % 6];
        g.cell[0] = g.cell[1] = g.cell[2] = trial % 2 ? 0.125 : 0.1 + tc_unit();
        need = hfvis_binvox_encode_size(&g, occ);
        buf = (unsigned char *)malloc(need);
        CHECK_EQ_STATUS(hfvis_binvox_encode(&g, occ, buf, need, &w), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_binvox_decode(buf, w, NULL, &d, &back), HFVIS_OK);
        for (a = 0; a < 3; a++) {
            CHECK(d.dims[a] == D);
            CHECK(d.origin[a] == g.origin[a] || fabs(d.origin[a] - g.origin[a]) <= TC_NUMBER_REL * fabs(g.origin[a]));
            CHECK_NEAR(d.cell[a], g.cell[0], 0.0, TC_NUMBER_REL);
        }
        if (trial % 2) CHECK(d.cell[0] == 0.125); /* short numbers read back exactly */
        CHECK(d.origin[0] == g.origin[0] || trial % 6 == 3); /* 0.1, -3.25, 1e-7, ... exact */
        for (z = 0; z < D && ok; z++)
            for (y = 0; y < D; y++)
                for (x = 0; x < D; x++) {
                    uint8_t want = (x < g.dims[0] && y < g.dims[1] && z < g.dims[2])
                                       ? occ[((size_t)z * (size_t)g.dims[1] + (size_t)y) * (size_t)g.dims[0] + (size_t)x]
                                       : 0;
                    if (back[((size_t)z * (size_t)D + (size_t)y) * (size_t)D + (size_t)x] != want) ok = 0;
                }
        CHECK(ok);
        hfvis_free(NULL, back);
        free(buf);
        free(occ);
    }
}

/* Decodes a string (with explicit length); returns the status, freeing any output. */
static hfvis_status tc_decode(const char *s, size_t len)
{
    hfvis_volume_grid g;
    uint8_t *o = NULL;
    hfvis_status st = hfvis_binvox_decode(s, len, NULL, &g, &o);
    if (st == HFVIS_OK) hfvis_free(NULL, o);
    return st;
}

TEST(binvox_decode_errors)
{
    /* a valid 2^3 file: "data\n" then (1, 8) */
#define TC_OK_HEAD "#binvox 1\ndim 2 2 2\ntranslate 0 0 0\nscale 1\ndata\n"
#define TC_CASE(str, w) {str, sizeof(str) - 1, w}
    static const char ok8[] = TC_OK_HEAD "\001\010";
    static const struct { const char *s; size_t len; hfvis_status want; } cases[] = {
        TC_CASE(TC_OK_HEAD "\001\010", HFVIS_OK),
        TC_CASE("#binvox 1\r\ndim 2 2 2\r\ndata\r\n\000\010", HFVIS_OK), /* CRLF, defaults */
        TC_CASE("#binvox 2\ndim 1 1 1\ndata\n\007\001", HFVIS_OK),         /* version 2: any value */
        TC_CASE("#binvox 1\ndim 1 1 1\ndata\n\007\001", HFVIS_ERR_FORMAT),  /* value > 1 in v1 */
        TC_CASE(TC_OK_HEAD "\001\007", HFVIS_ERR_FORMAT),          /* short */
        TC_CASE(TC_OK_HEAD "\001\011", HFVIS_ERR_FORMAT),          /* long */
        TC_CASE(TC_OK_HEAD "\001\004\000\000\001\004", HFVIS_ERR_FORMAT), /* count 0 */
        TC_CASE(TC_OK_HEAD "\001\010\000", HFVIS_ERR_FORMAT),      /* odd byte */
        TC_CASE(TC_OK_HEAD "\001\010\000\001", HFVIS_ERR_FORMAT),  /* trailing */
        TC_CASE(TC_OK_HEAD, HFVIS_ERR_FORMAT),                     /* no data */
        TC_CASE("#binvox 3\ndim 2 2 2\ndata\n\001\010", HFVIS_ERR_FORMAT),
        TC_CASE("#binvo 1\ndim 2 2 2\ndata\n\001\010", HFVIS_ERR_FORMAT),
        TC_CASE("#binvox 1\ndim 2 2 3\ndata\n\001\014", HFVIS_ERR_FORMAT), /* not cubic */
        TC_CASE("#binvox 1\ndim 2 2\ndata\n\001\010", HFVIS_ERR_FORMAT),
        TC_CASE("#binvox 1\ndim 0 0 0\ndata\n", HFVIS_ERR_FORMAT),
        TC_CASE("#binvox 1\ndim 2 2 2\ndim 2 2 2\ndata\n\001\010", HFVIS_ERR_FORMAT),
        TC_CASE("#binvox 1\ndata\n", HFVIS_ERR_FORMAT), /* no dim */
        TC_CASE("#binvox 1\ndim 2 2 2\nscale 0\ndata\n\001\010", HFVIS_ERR_FORMAT),
        TC_CASE("#binvox 1\ndim 2 2 2\nscale -1\ndata\n\001\010", HFVIS_ERR_FORMAT),
        TC_CASE("#binvox 1\ndim 2 2 2\nscale 1e999\ndata\n\001\010", HFVIS_ERR_FORMAT),
        TC_CASE("#binvox 1\ndim 2 2 2\nscale nan\ndata\n\001\010", HFVIS_ERR_FORMAT),
        TC_CASE("#binvox 1\ndim 2 2 2\ntranslate 1 2\ndata\n\001\010", HFVIS_ERR_FORMAT),
        TC_CASE("#binvox 1\ndim 2 2 2\ntranslate 1 2 3x\ndata\n\001\010", HFVIS_ERR_FORMAT),
        TC_CASE("#binvox 1\ndim 2 2 2\nfoo 1\ndata\n\001\010", HFVIS_ERR_FORMAT),
        TC_CASE("#binvox 1\ndim 2 2 2\n\ndata\n\001\010", HFVIS_ERR_FORMAT), /* blank line */
        TC_CASE("#binvox 1\ndim 2 2 2\ndatax\n\001\010", HFVIS_ERR_FORMAT),
        TC_CASE("#binvox 1\ndim 2 2 2 7\ndata\n\001\010", HFVIS_ERR_FORMAT),
        TC_CASE("#binvox 1\ndim 2000 2000 2000\ndata\n", HFVIS_ERR_LIMIT),
        TC_CASE("#binvox 1\ndim 99999999999 99999999999 99999999999\ndata\n", HFVIS_ERR_LIMIT),
        TC_CASE("", HFVIS_ERR_FORMAT),
    };
    size_t i;
    hfvis_volume_grid g, keep;
    uint8_t *o = (uint8_t *)&keep;
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        hfvis_status st = tc_decode(cases[i].s, cases[i].len);
        if (st != cases[i].want) fprintf(stderr, "  binvox case %zu\n", i);
        CHECK_EQ_STATUS(st, cases[i].want);
    }
    /* every truncation of a valid file fails cleanly */
    for (i = 0; i + 1 < sizeof ok8 - 1; i++) CHECK_EQ_STATUS(tc_decode(ok8, i), HFVIS_ERR_FORMAT);
    /* outputs untouched on error; bad arguments */
    memset(&g, 0x33, sizeof g);
    keep = g;
    CHECK_EQ_STATUS(hfvis_binvox_decode("#binvox 1\n", 10, NULL, &g, &o), HFVIS_ERR_FORMAT);
    CHECK(memcmp(&g, &keep, sizeof g) == 0 && o == (uint8_t *)&keep);
    CHECK_EQ_STATUS(hfvis_binvox_decode(NULL, 10, NULL, &g, &o), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_binvox_decode(ok8, sizeof ok8 - 1, NULL, NULL, &o), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_binvox_decode(ok8, sizeof ok8 - 1, NULL, &g, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    {
        /* the decoded default grid */
        static const char crlf[] = "#binvox 1\r\ndim 2 2 2\r\ndata\r\n\000\010";
        CHECK_EQ_STATUS(hfvis_binvox_decode(crlf, sizeof crlf - 1, NULL, &g, &o), HFVIS_OK);
        CHECK(g.dims[0] == 2 && g.cell[1] == 0.5 && g.origin[2] == 0.0 && o[7] == 0);
        hfvis_free(NULL, o);
    }
#undef TC_OK_HEAD
#undef TC_CASE
}

TEST(binvox_raw_files)
{
    hfvis_volume_grid g = tc_grid(5, 3, 4), d;
    uint8_t occ[60], *back = NULL;
    unsigned char raw[64];
    const char *pb = "build/test_cons_tmp.binvox", *pr = "build/test_cons_tmp.raw";
    FILE *f;
    size_t i;
    for (i = 0; i < 60; i++) occ[i] = (uint8_t)(i % 7 == 0 ? 2 : i % 3 == 0);
    CHECK_EQ_STATUS(hfvis_binvox_save(pb, &g, occ), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_binvox_load(pb, NULL, &d, &back), HFVIS_OK);
    CHECK(d.dims[0] == 5 && d.dims[1] == 5 && d.dims[2] == 5);
    for (i = 0; i < 60; i++) {
        size_t x = i % 5, y = i / 5 % 3, z = i / 15;
        CHECK(back[(z * 5 + y) * 5 + x] == (occ[i] != 0));
    }
    hfvis_free(NULL, back);
    CHECK_EQ_STATUS(hfvis_voxels_raw_save(pr, &g, occ), HFVIS_OK);
    f = fopen(pr, "rb");
    CHECK(f != NULL);
    if (f) {
        CHECK(fread(raw, 1, sizeof raw, f) == 60);
        fclose(f);
        CHECK(memcmp(raw, occ, 60) == 0);
    }
    remove(pb);
    remove(pr);
    CHECK_EQ_STATUS(hfvis_binvox_load("build/no/such/file.binvox", NULL, &d, &back), HFVIS_ERR_IO);
    CHECK_EQ_STATUS(hfvis_binvox_save("build/no/such/dir/x.binvox", &g, occ), HFVIS_ERR_IO);
    CHECK_EQ_STATUS(hfvis_voxels_raw_save("build/no/such/dir/x.raw", &g, occ), HFVIS_ERR_IO);
    CHECK_EQ_STATUS(hfvis_binvox_save(NULL, &g, occ), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_voxels_raw_save(pr, NULL, occ), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_voxels_raw_save(pr, &g, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    {
        hfvis_volume_grid big = tc_grid(2000, 2000, 1); /* valid grid, but a 2000^3 cube */
        size_t w;
        CHECK(hfvis_binvox_encode_size(&big, occ) == 0);
        CHECK_EQ_STATUS(hfvis_binvox_encode(&big, occ, raw, sizeof raw, &w), HFVIS_ERR_LIMIT);
        CHECK_EQ_STATUS(hfvis_binvox_save(pb, &big, occ), HFVIS_ERR_LIMIT);
        big = tc_grid(4, 4, 4); /* scale 4 * 1e308 overflows */
        big.cell[1] = 1e308;
        CHECK(hfvis_binvox_encode_size(&big, occ) == 0);
        CHECK_EQ_STATUS(hfvis_binvox_encode(&big, occ, raw, sizeof raw, &w), HFVIS_ERR_LIMIT);
    }
}

/* ---- arguments, limits, allocation failures ------------------------------------------------ */

typedef hfvis_status (*tc_vox_fn)(const hfvis_mesh *, const hfvis_volume_grid *,
                                  const hfvis_binary_voxel_options *, uint8_t *, size_t *);

static hfvis_status tc_bitmask_as_u8(const hfvis_mesh *m, const hfvis_volume_grid *g,
                                     const hfvis_binary_voxel_options *o, uint8_t *out, size_t *n)
{
    return hfvis_voxelize_bitmask(m, g, o, (uint32_t *)(void *)out, n);
}

TEST(bad_arguments)
{
    static const tc_vox_fn fns[5] = {hfvis_voxelize_conservative, hfvis_voxelize_conservative_reference,
                                     hfvis_voxelize_solid, hfvis_voxelize_solid_reference,
                                     tc_bitmask_as_u8};
    double lo[3] = {1, 1, 1}, hi[3] = {3, 3, 3};
    hfvis_mesh m, bad;
    hfvis_volume_grid g = tc_grid(4, 4, 4), gb;
    uint32_t outw[64];
    uint8_t *out = (uint8_t *)(void *)outw;
    hfvis_binary_voxel_options o = hfvis_binary_voxel_options_default();
    size_t n;
    float far[24];
    int f, i;
    CHECK(o.axis == HFVIS_PARITY_AXIS_Z && o.alloc == NULL && o.allow_open == 0);
    CHECK_EQ_STATUS(hfvis_mesh_box(NULL, lo, hi, &m), HFVIS_OK);
    for (f = 0; f < 5; f++) {
        memset(outw, 0x77, sizeof outw);
        n = 999;
        CHECK_EQ_STATUS(fns[f](NULL, &g, NULL, out, &n), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(fns[f](&m, NULL, NULL, out, &n), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(fns[f](&m, &g, NULL, NULL, &n), HFVIS_ERR_INVALID_ARGUMENT);
        gb = g;
        gb.dims[1] = 0;
        CHECK_EQ_STATUS(fns[f](&m, &gb, NULL, out, &n), HFVIS_ERR_INVALID_ARGUMENT);
        gb = g;
        gb.cell[2] = -1.0;
        CHECK_EQ_STATUS(fns[f](&m, &gb, NULL, out, &n), HFVIS_ERR_INVALID_ARGUMENT);
        gb = g;
        gb.origin[0] = (double)NAN;
        CHECK_EQ_STATUS(fns[f](&m, &gb, NULL, out, &n), HFVIS_ERR_INVALID_ARGUMENT);
        bad = m;
        bad.indices = NULL;
        CHECK_EQ_STATUS(fns[f](&bad, &g, NULL, out, &n), HFVIS_ERR_INVALID_ARGUMENT);
        /* a vertex 2^61 cells away */
        memcpy(far, m.xyz, sizeof far);
        far[4] = 3e18f;
        bad = m;
        bad.xyz = far;
        CHECK_EQ_STATUS(fns[f](&bad, &g, NULL, out, &n), HFVIS_ERR_LIMIT);
        CHECK(n == 999);
        for (i = 0; i < 64; i++) CHECK(outw[i] == 0x77777777u);
    }
    o.axis = (hfvis_parity_axis)7;
    CHECK_EQ_STATUS(hfvis_voxelize_solid(&m, &g, &o, out, &n), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_voxelize_solid_reference(&m, &g, &o, out, &n), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(hfvis_bitmask_words(NULL) == 0);
    CHECK(hfvis_bitmask_words(&g) == 16);
    CHECK_EQ_STATUS(hfvis_bitmask_to_occupancy(&g, NULL, out), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_mesh_is_watertight(&m, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_mesh_is_watertight(NULL, NULL, &i), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(hfvis_binvox_encode_size(NULL, out) == 0 && hfvis_binvox_encode_size(&g, NULL) == 0);
    CHECK_EQ_STATUS(hfvis_binvox_encode(&g, out, NULL, 10, &n), HFVIS_ERR_INVALID_ARGUMENT);
    /* count may be NULL; an empty mesh gives nothing */
    bad = m;
    bad.triangle_count = 0;
    for (f = 0; f < 5; f++) {
        CHECK_EQ_STATUS(fns[f](&m, &g, NULL, out, NULL), HFVIS_OK);
        CHECK_EQ_STATUS(fns[f](&bad, &g, NULL, out, &n), HFVIS_OK);
        CHECK(n == 0);
    }
    hfvis_mesh_free(NULL, &m);
}

TEST(allocation_failures)
{
    double lo[3] = {1.2, 1.3, 1.4}, hi[3] = {5.7, 4.6, 6.1};
    hfvis_mesh m;
    hfvis_volume_grid g = tc_grid(8, 8, 8), d;
    uint8_t occ[512], *o = NULL;
    unsigned char enc[1024];
    size_t w = 0, n;
    int fn, k;
    const char *path = "build/test_cons_alloc.binvox";
    CHECK_EQ_STATUS(hfvis_mesh_box(NULL, lo, hi, &m), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_voxelize_conservative(&m, &g, NULL, occ, &n), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_binvox_encode(&g, occ, enc, sizeof enc, &w), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_binvox_save(path, &g, occ), HFVIS_OK);
    for (fn = 0; fn < 5; fn++) {
        int total = 0;
        test_counting c;
        hfvis_allocator a;
        hfvis_binary_voxel_options opt = hfvis_binary_voxel_options_default();
        hfvis_status s;
        int r = -7;
        a.alloc = test_count_alloc;
        a.free = test_count_free;
        a.user = &c;
        opt.alloc = &a;
        /* count the allocations of a successful run, then fail each in turn */
        for (k = 0;; k++) {
            memset(&c, 0, sizeof c);
            c.fail_at = k;
            memset(occ, 0x44, sizeof occ);
            n = 777;
            o = NULL;
            r = -7;
            memset(&d, 0x22, sizeof d);
            switch (fn) {
            case 0: s = hfvis_voxelize_conservative(&m, &g, &opt, occ, &n); break;
            case 1: s = hfvis_voxelize_solid(&m, &g, &opt, occ, &n); break;
            case 2: s = hfvis_mesh_is_watertight(&m, &a, &r); break;
            case 3: s = hfvis_binvox_decode(enc, w, &a, &d, &o); break;
            default: s = hfvis_binvox_load(path, &a, &d, &o); break;
            }
            if (k == 0) {
                CHECK_EQ_STATUS(s, HFVIS_OK);
                total = c.allocs;
                if (o) test_count_free(&c, o);
                CHECK(c.allocs == c.frees);
                CHECK(total >= 1);
                continue;
            }
            CHECK_EQ_STATUS(s, HFVIS_ERR_OUT_OF_MEMORY);
            CHECK(c.allocs == k && c.allocs - 1 == c.frees);
            if (!(n == 777 && occ[0] == 0x44 && occ[511] == 0x44 && r == -7 && o == NULL))
                fprintf(stderr, "  allocation failure %d of call %d touched an output\n", k, fn);
            CHECK(n == 777 && occ[0] == 0x44 && occ[511] == 0x44 && r == -7 && o == NULL);
            CHECK(d.dims[0] == 0x22222222);
            if (k >= total) break;
        }
    }
    remove(path);
    hfvis_mesh_free(NULL, &m);
}

int main(int argc, char **argv)
{
    TEST_INIT(argc, argv);
    RUN(sat_cases);
    RUN(conservative_spec_counts);
    RUN(conservative_fast_equals_reference);
    RUN(conservative_fast_equals_reference_slivers);
    RUN(conservative_translation);
    RUN(solid_box_exact);
    RUN(solid_spheres);
    RUN(solid_torus_and_axes);
    RUN(solid_open_mesh);
    RUN(solid_open_mesh_every_axis);
    RUN(watertight);
    RUN(bitmask);
    RUN(binvox_known_bytes);
    RUN(binvox_round_trip);
    RUN(binvox_decode_errors);
    RUN(binvox_raw_files);
    RUN(bad_arguments);
    RUN(allocation_failures);
    return TEST_DONE();
}
