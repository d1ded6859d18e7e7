/* test_mesh.c - analytic meshes, bounds and the Wavefront OBJ codec (voxel.c section 4). */
#include "hfvis.h"
#include "test.h"

#include <float.h>
#include <stdint.h>
#include <stdlib.h>

#define PI 3.14159265358979323846
#define DNAN ((double)NAN)
#define DINF ((double)INFINITY)

/* Tolerances */
#define T_FLOAT_REL 1e-6     /* area/volume of float-rounded vertices vs double closed form */
#define T_SPHERE_S5 3e-4     /* icosphere s=5 area vs the quoted 5025.0 (rounded to 0.1) */
#define T_CONVERGE 2e-3      /* fine tessellations vs the smooth surface's area/volume */
#define T_COORD 1e-6         /* float rounding of O(1) coordinates (2^-23 = 1.2e-7 relative) */
#define T_ANGLE 1e-6         /* angle from two float-rounded O(1) points, 0.15 apart */
#define T_UNIT 1e-7          /* a unit vector's components rounded to float (half ulp 6e-8) */
#define T_TUBE_REL 1e-3      /* tube vertices sit at the tube radius up to float rounding */

/* ---- helpers ----------------------------------------------------------------------------- */

static void vtx(const hfvis_mesh *m, size_t v, double p[3])
{
    p[0] = (double)m->xyz[3 * v];
    p[1] = (double)m->xyz[3 * v + 1];
    p[2] = (double)m->xyz[3 * v + 2];
}
static void tri_normal(const hfvis_mesh *m, size_t t, double n[3], double cen[3])
{
    double a[3], b[3], c[3], e1[3], e2[3];
    int k;
    vtx(m, m->indices[3 * t], a);
    vtx(m, m->indices[3 * t + 1], b);
    vtx(m, m->indices[3 * t + 2], c);
    for (k = 0; k < 3; k++) {
        e1[k] = b[k] - a[k];
        e2[k] = c[k] - a[k];
        cen[k] = (a[k] + b[k] + c[k]) / 3.0;
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
}
static double mesh_area(const hfvis_mesh *m)
{
    double s = 0.0, n[3], c[3];
    size_t t;
    for (t = 0; t < m->triangle_count; t++) {
        tri_normal(m, t, n, c);
        s += 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    }
    return s;
}
/* Signed volume by the divergence theorem, relative to `ref` (reduces cancellation). */
static double mesh_volume(const hfvis_mesh *m, const double ref[3])
{
    double s = 0.0;
    size_t t;
    for (t = 0; t < m->triangle_count; t++) {
        double a[3], b[3], c[3];
        int k;
        vtx(m, m->indices[3 * t], a);
        vtx(m, m->indices[3 * t + 1], b);
        vtx(m, m->indices[3 * t + 2], c);
        for (k = 0; k < 3; k++) {
            a[k] -= ref[k];
            b[k] -= ref[k];
            c[k] -= ref[k];
        }
        s += a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2])
             + a[2] * (b[0] * c[1] - b[1] * c[0]);
    }
    return s / 6.0;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y ? 1 : 0;
}
/* Number of directed edges that are not matched by exactly one reverse edge, plus directed
 * edges used twice (0 = watertight and consistently oriented), and the count of boundary
 * edges (directed edges without a reverse). */
static size_t edge_defects(const hfvis_mesh *m, size_t *boundary)
{
    size_t n = 3 * m->triangle_count, i, bad = 0, bnd = 0;
    uint64_t *e = (uint64_t *)malloc(n * sizeof(uint64_t) + 1);
    for (i = 0; i < m->triangle_count; i++) {
        int k;
        for (k = 0; k < 3; k++) {
            uint64_t a = m->indices[3 * i + (size_t)k], b = m->indices[3 * i + (size_t)(k + 1) % 3];
            e[3 * i + (size_t)k] = (a << 32) | b;
        }
    }
    qsort(e, n, sizeof(uint64_t), cmp_u64);
    for (i = 0; i < n; i++) {
        uint64_t rev = (e[i] << 32) | (e[i] >> 32);
        if (i + 1 < n && e[i + 1] == e[i]) bad++;
        if (!bsearch(&rev, e, n, sizeof(uint64_t), cmp_u64)) {
            bad++;
            bnd++;
        }
    }
    free(e);
    if (boundary) *boundary = bnd;
    return bad;
}
/* Triangles whose normal points toward `centre` (for star-shaped meshes), and degenerate ones. */
static size_t inward_triangles(const hfvis_mesh *m, const double centre[3], size_t *degenerate)
{
    size_t t, bad = 0, deg = 0;
    for (t = 0; t < m->triangle_count; t++) {
        double n[3], c[3];
        tri_normal(m, t, n, c);
        if (n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0) deg++;
        if (n[0] * (c[0] - centre[0]) + n[1] * (c[1] - centre[1]) + n[2] * (c[2] - centre[2]) <= 0.0)
            bad++;
    }
    if (degenerate) *degenerate = deg;
    return bad;
}
static int mesh_valid(const hfvis_mesh *m)
{
    size_t i;
    for (i = 0; i < 3 * m->vertex_count; i++)
        if (!isfinite(m->xyz[i])) return 0;
    for (i = 0; i < 3 * m->triangle_count; i++)
        if (m->indices[i] >= m->vertex_count) return 0;
    return 1;
}
/* Vertices no triangle uses. */
static size_t unused_vertices(const hfvis_mesh *m)
{
    unsigned char *u = (unsigned char *)calloc(m->vertex_count + 1, 1);
    size_t i, n = 0;
    for (i = 0; i < 3 * m->triangle_count; i++) u[m->indices[i]] = 1;
    for (i = 0; i < m->vertex_count; i++) n += !u[i];
    free(u);
    return n;
}

/* Closed form for a surface of revolution by regular n-gons: profile (rho_i, z_i), i = 0..m.
 * Band i is a frustum of regular n-gons (planar isosceles trapezoids). */
static void revolution_forms(const double *rho, const double *z, int m, int n, double *area,
                             double *vol)
{
    int i;
    double A = 0.0, V = 0.0, k = 0.5 * (double)n * sin(2.0 * PI / (double)n);
    double cs = cos(PI / (double)n), sn = sin(PI / (double)n);
    for (i = 0; i < m; i++) {
        double r1 = rho[i], r2 = rho[i + 1], dz = z[i + 1] - z[i];
        A += (double)n * (r1 + r2) * sn * sqrt(dz * dz + cs * cs * (r1 - r2) * (r1 - r2));
        V += -dz / 3.0 * k * (r1 * r1 + r2 * r2 + r1 * r2); /* profile runs downward */
    }
    *area = A;
    *vol = V;
}

static uint64_t rng_state = 0x1234567887654321ull;
static uint64_t rng_next(void)
{
    uint64_t z = (rng_state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* ---- generators ---------------------------------------------------------------------------- */

TEST(box)
{
    const double lo[3] = {-1.0, 2.0, 0.5}, hi[3] = {3.0, 2.5, 4.0}, cen[3] = {1.0, 2.25, 2.25};
    hfvis_mesh m;
    double blo[3], bhi[3];
    size_t deg;
    CHECK_EQ_STATUS(hfvis_mesh_box(NULL, lo, hi, &m), HFVIS_OK);
    CHECK(m.vertex_count == 8 && m.triangle_count == 12 && mesh_valid(&m));
    CHECK(edge_defects(&m, NULL) == 0);
    CHECK(inward_triangles(&m, cen, &deg) == 0 && deg == 0);
    /* volume 4 * 0.5 * 3.5 = 7, area 2(4*0.5 + 4*3.5 + 0.5*3.5) = 35.5: exact in double */
    CHECK(mesh_volume(&m, cen) == 7.0);
    CHECK(mesh_area(&m) == 35.5);
    CHECK_EQ_STATUS(hfvis_mesh_bounds(&m, blo, bhi), HFVIS_OK);
    CHECK(blo[0] == -1.0 && blo[1] == 2.0 && blo[2] == 0.5 && bhi[0] == 3.0 && bhi[1] == 2.5
          && bhi[2] == 4.0);
    hfvis_mesh_free(NULL, &m);
    CHECK(m.xyz == NULL && m.indices == NULL && m.vertex_count == 0);
}

TEST(uv_sphere)
{
    static const int sl[] = {3, 4, 7, 16, 128}, st[] = {2, 3, 5, 8, 96};
    const double c[3] = {0.25, -1.5, 2.0};
    int i;
    for (i = 0; i < 5; i++) {
        hfvis_mesh m;
        double r = 1.75, rho[100], z[100], A, V;
        size_t deg;
        int k;
        CHECK_EQ_STATUS(hfvis_mesh_uv_sphere(NULL, c, r, sl[i], st[i], &m), HFVIS_OK);
        CHECK(m.vertex_count == (size_t)((st[i] - 1) * sl[i] + 2));
        CHECK(m.triangle_count == (size_t)(2 * sl[i] * (st[i] - 1)));
        CHECK(mesh_valid(&m) && edge_defects(&m, NULL) == 0 && unused_vertices(&m) == 0);
        CHECK(inward_triangles(&m, c, &deg) == 0 && deg == 0);
        for (k = 0; k <= st[i]; k++) {
            rho[k] = (k == 0 || k == st[i]) ? 0.0 : r * sin(PI * k / st[i]);
            z[k] = r * cos(PI * k / st[i]);
        }
        revolution_forms(rho, z, st[i], sl[i], &A, &V);
        CHECK_NEAR(mesh_area(&m), A, 0.0, T_FLOAT_REL);
        CHECK_NEAR(mesh_volume(&m, c), V, 0.0, T_FLOAT_REL);
        if (i == 4) {
            CHECK_NEAR(A, 4.0 * PI * r * r, 0.0, T_CONVERGE);
            CHECK_NEAR(V, 4.0 / 3.0 * PI * r * r * r, 0.0, T_CONVERGE);
        }
        hfvis_mesh_free(NULL, &m);
    }
}

TEST(icosphere)
{
    const double c[3] = {32.1, 31.7, 32.3};
    int s;
    for (s = 0; s <= 5; s++) {
        hfvis_mesh m;
        size_t deg, v4 = (size_t)1 << (2 * s);
        double V;
        CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c, 20.0, s, &m), HFVIS_OK);
        CHECK(m.vertex_count == 10 * v4 + 2 && m.triangle_count == 20 * v4);
        CHECK(mesh_valid(&m) && edge_defects(&m, NULL) == 0 && unused_vertices(&m) == 0);
        CHECK(inward_triangles(&m, c, &deg) == 0 && deg == 0);
        V = mesh_volume(&m, c);
        CHECK(V > 0.0 && V < 4.0 / 3.0 * PI * 8000.0);
        if (s == 0) {
            /* regular icosahedron of circumradius 20: edge a = r / sin(2 pi / 5),
             * area 5 sqrt3 a^2 */
            double a = 20.0 / sin(2.0 * PI / 5.0);
            CHECK_NEAR(mesh_area(&m), 5.0 * sqrt(3.0) * a * a, 0.0, T_FLOAT_REL);
            CHECK_NEAR(V, 5.0 * (3.0 + sqrt(5.0)) / 12.0 * a * a * a, 0.0, T_FLOAT_REL);
        }
        if (s == 5) {
            printf("  icosphere s=5 r=20: area %.4f (prototype 5025.0), volume %.3f\n", mesh_area(&m), V);
            CHECK_NEAR(mesh_area(&m), 5025.0, 0.0, T_SPHERE_S5);
        }
        hfvis_mesh_free(NULL, &m);
    }
}

TEST(torus)
{
    const double c[3] = {1.0, 2.0, -3.0};
    const double R = 2.0, r = 0.5;
    static const int ma[] = {3, 5, 48, 256}, mi[] = {3, 4, 24, 128};
    int i;
    for (i = 0; i < 4; i++) {
        hfvis_mesh m;
        double rho[130], z[130], A, V;
        int j;
        CHECK_EQ_STATUS(hfvis_mesh_torus(NULL, c, R, r, ma[i], mi[i], &m), HFVIS_OK);
        CHECK(m.vertex_count == (size_t)(ma[i] * mi[i]) && m.triangle_count == (size_t)(2 * ma[i] * mi[i]));
        CHECK(mesh_valid(&m) && edge_defects(&m, NULL) == 0 && unused_vertices(&m) == 0);
        /* profile: the minor circle traversed by v = 2 pi j / minor; the formula's "downward"
         * sign convention makes the enclosed volume positive for this direction */
        for (j = 0; j <= mi[i]; j++) {
            double w = 2.0 * PI * (double)j / (double)mi[i];
            rho[j] = R + r * cos(w);
            z[j] = -r * sin(w);
        }
        revolution_forms(rho, z, mi[i], ma[i], &A, &V);
        CHECK_NEAR(mesh_area(&m), A, 0.0, T_FLOAT_REL);
        CHECK_NEAR(mesh_volume(&m, c), V, 0.0, T_FLOAT_REL);
        CHECK(V > 0.0);
        if (i == 3) {
            CHECK_NEAR(A, 4.0 * PI * PI * R * r, 0.0, T_CONVERGE);
            CHECK_NEAR(V, 2.0 * PI * PI * R * r * r, 0.0, T_CONVERGE);
        }
        hfvis_mesh_free(NULL, &m);
    }
}

TEST(torus_knot)
{
    const double c[3] = {0.0, 0.0, 0.0};
    hfvis_mesh m;
    double lo[3], hi[3];
    CHECK_EQ_STATUS(hfvis_mesh_torus_knot(NULL, c, 1.0, 2, 3, 2500, 20, &m), HFVIS_OK);
    CHECK(m.triangle_count == 100000 && m.vertex_count == 50000);
    CHECK(mesh_valid(&m) && edge_defects(&m, NULL) == 0 && unused_vertices(&m) == 0);
    CHECK(mesh_volume(&m, c) > 0.0);
    CHECK_EQ_STATUS(hfvis_mesh_bounds(&m, lo, hi), HFVIS_OK);
    CHECK(hi[0] <= 1.75 + T_COORD && lo[0] >= -1.75 - T_COORD && hi[2] <= 0.75 + T_COORD);
    hfvis_mesh_free(NULL, &m);
}

TEST(from_grid)
{
    enum { W = 5, H = 4, S = 7 };
    float z[H * S];
    hfvis_grid g;
    hfvis_mesh m;
    int x, y;
    size_t t;
    for (y = 0; y < H; y++)
        for (x = 0; x < S; x++) z[y * S + x] = (float)(0.25 * x - 0.5 * y + (x * y) % 3);
    g.z = z;
    g.width = W;
    g.height = H;
    g.stride = S;
    g.cell_size = 0.5;
    CHECK_EQ_STATUS(hfvis_mesh_from_grid(NULL, &g, &m), HFVIS_OK);
    CHECK(m.vertex_count == W * H && m.triangle_count == 2 * (W - 1) * (H - 1) && mesh_valid(&m));
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++) {
            size_t v = (size_t)(y * W + x);
            CHECK(m.xyz[3 * v] == (float)(x * 0.5) && m.xyz[3 * v + 1] == (float)(y * 0.5)
                  && m.xyz[3 * v + 2] == z[y * S + x]);
        }
    for (t = 0; t < m.triangle_count; t++) {
        double n[3], cc[3];
        tri_normal(&m, t, n, cc);
        CHECK(n[2] > 0.0);
    }
    hfvis_mesh_free(NULL, &m);
}

TEST(room)
{
    hfvis_mesh m;
    double lo[3], hi[3];
    size_t bnd = 0;
    CHECK_EQ_STATUS(hfvis_mesh_room(NULL, &m), HFVIS_OK);
    CHECK(m.vertex_count == 24 && m.triangle_count == 30 && mesh_valid(&m));
    CHECK_EQ_STATUS(hfvis_mesh_bounds(&m, lo, hi), HFVIS_OK);
    CHECK(lo[0] == 0.0 && lo[1] == 0.0 && lo[2] == 0.0 && hi[0] == 1.0 && hi[1] == 1.0 && hi[2] == 1.0);
    edge_defects(&m, &bnd);
    CHECK(bnd > 0);
    hfvis_mesh_free(NULL, &m);
}

TEST(teapot)
{
    int n;
    for (n = 1; n <= 4; n++) {
        hfvis_mesh m;
        size_t nn = (size_t)n;
        CHECK_EQ_STATUS(hfvis_mesh_teapot(NULL, n, &m), HFVIS_OK);
        CHECK(m.vertex_count == 192 * nn * nn + 2);
        CHECK(m.triangle_count == 384 * nn * nn - 24 * nn);
        CHECK(mesh_valid(&m) && unused_vertices(&m) == 0);
        hfvis_mesh_free(NULL, &m);
    }
}

/* Fail allocation k = 1..n of every generator: OUT_OF_MEMORY, *out untouched, nothing leaked. */
static hfvis_status gen_call(int which, const hfvis_allocator *a, hfvis_mesh *m)
{
    static const double c[3] = {0.5, 0.25, -1.0}, lo[3] = {0, 0, 0}, hi[3] = {1, 2, 3};
    static float z[12] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11};
    hfvis_grid g;
    g = test_grid(z, 4, 3, 1.0);
    switch (which) {
    case 0: return hfvis_mesh_box(a, lo, hi, m);
    case 1: return hfvis_mesh_uv_sphere(a, c, 1.0, 8, 5, m);
    case 2: return hfvis_mesh_icosphere(a, c, 1.0, 2, m);
    case 3: return hfvis_mesh_torus(a, c, 2.0, 1.0, 6, 5, m);
    case 4: return hfvis_mesh_torus_knot(a, c, 1.0, 2, 3, 30, 5, m);
    case 5: return hfvis_mesh_from_grid(a, &g, m);
    case 6: return hfvis_mesh_room(a, m);
    default: return hfvis_mesh_teapot(a, 1, m);
    }
}

TEST(generators_alloc_failure)
{
    int which;
    for (which = 0; which < 8; which++) {
        test_counting cnt;
        hfvis_allocator a = test_counting_allocator(&cnt, 0);
        hfvis_mesh ref, m;
        int n, k;
        CHECK_EQ_STATUS(gen_call(which, &a, &ref), HFVIS_OK);
        n = cnt.allocs;
        CHECK(n >= 2);
        hfvis_mesh_free(&a, &ref);
        CHECK(cnt.live == 0);
        for (k = 1; k <= n; k++) {
            a = test_counting_allocator(&cnt, 0);
            cnt.fail_at = k;
            memset(&m, 0xAB, sizeof m);
            CHECK_EQ_STATUS(gen_call(which, &a, &m), HFVIS_ERR_OUT_OF_MEMORY);
            CHECK(cnt.live == 0 && cnt.allocs == cnt.frees + 1);
            CHECK(m.vertex_count == (size_t)0xABABABABABABABABull);
        }
    }
}


/* ---- more generator checks ------------------------------------------------------------ */

/* Kahler's base icosahedron and the first subdivision's face order (the construction the prototype
 * voxel counts were made with). */
TEST(icosphere_construction)
{
    const double c[3] = {0.0, 0.0, 0.0}, t = (1.0 + sqrt(5.0)) / 2.0;
    static const double base[12][3] = {{-1, 1, 0}, {1, 1, 0}, {-1, -1, 0}, {1, -1, 0},
                                       {0, -1, 1}, {0, 1, 1}, {0, -1, -1}, {0, 1, -1},
                                       {1, 0, -1}, {1, 0, 1}, {-1, 0, -1}, {-1, 0, 1}};
    static const uint32_t f0[12] = {0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10};
    static const uint32_t s1[12] = {0, 12, 14, 11, 13, 12, 5, 14, 13, 12, 13, 14};
    hfvis_mesh m;
    int v, k;
    CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c, 1.0, 0, &m), HFVIS_OK);
    for (v = 0; v < 12; v++) {
        double p[3], len;
        p[0] = base[v][0] * (v >= 8 ? t : 1.0);
        p[1] = base[v][1] * (v < 4 ? t : 1.0);
        p[2] = base[v][2] * (v >= 4 && v < 8 ? t : 1.0);
        len = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        for (k = 0; k < 3; k++) CHECK(m.xyz[3 * v + k] == (float)(p[k] / len));
    }
    CHECK(memcmp(m.indices, f0, sizeof f0) == 0);
    hfvis_mesh_free(NULL, &m);
    CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c, 1.0, 1, &m), HFVIS_OK);
    CHECK(memcmp(m.indices, s1, sizeof s1) == 0);
    /* vertex 12 = normalised midpoint of vertices 0 and 11 */
    {
        double a[3], b[3], mid[3], len;
        vtx(&m, 0, a);
        vtx(&m, 11, b);
        for (k = 0; k < 3; k++) mid[k] = a[k] + b[k];
        len = sqrt(mid[0] * mid[0] + mid[1] * mid[1] + mid[2] * mid[2]);
        for (k = 0; k < 3; k++) CHECK_NEAR(m.xyz[36 + k], mid[k] / len, T_UNIT, 0.0);
    }
    hfvis_mesh_free(NULL, &m);
}

/* The pixel-centre dominant-axis rule of [G12] ch. 6 (as the quoted prototype; no ties occur
 * on this mesh), counting voxels of a 64^3 unit grid: reproduces the  numbers
 * with this icosphere (dominant 4147, all three axes 4183). */
static long proto_voxel_count(const hfvis_mesh *m, int all_axes)
{
    enum { N = 64 };
    unsigned char *vol = (unsigned char *)calloc(N * N * N, 1);
    long cnt = 0;
    size_t t;
    int i;
    for (t = 0; t < m->triangle_count; t++) {
        double g[3][3], nrm[3], cc[3];
        int a, k, dom = 0;
        for (i = 0; i < 3; i++) vtx(m, m->indices[3 * t + (size_t)i], g[i]);
        tri_normal(m, t, nrm, cc);
        if (fabs(nrm[1]) > fabs(nrm[dom])) dom = 1;
        if (fabs(nrm[2]) > fabs(nrm[dom])) dom = 2;
        for (a = 0; a < 3; a++) {
            int u = (a + 1) % 3, w = (a + 2) % 3, pu, pw, u0, u1, w0, w1;
            double P[3][2], Z[3], area;
            if ((!all_axes && a != dom) || nrm[a] == 0.0) continue;
            for (i = 0; i < 3; i++) {
                P[i][0] = g[i][u];
                P[i][1] = g[i][w];
                Z[i] = g[i][a];
            }
            area = (P[1][0] - P[0][0]) * (P[2][1] - P[0][1]) - (P[1][1] - P[0][1]) * (P[2][0] - P[0][0]);
            u0 = (int)floor(fmin(P[0][0], fmin(P[1][0], P[2][0])));
            u1 = (int)floor(fmax(P[0][0], fmax(P[1][0], P[2][0])));
            w0 = (int)floor(fmin(P[0][1], fmin(P[1][1], P[2][1])));
            w1 = (int)floor(fmax(P[0][1], fmax(P[1][1], P[2][1])));
            for (pu = u0; pu <= u1; pu++)
                for (pw = w0; pw <= w1; pw++) {
                    double cu = pu + 0.5, cw = pw + 0.5, b[3], z;
                    int v[3];
                    if (pu < 0 || pw < 0 || pu >= N || pw >= N) continue;
                    for (i = 0; i < 3; i++) {
                        int j = (i + 1) % 3, l = (i + 2) % 3;
                        b[i] = ((P[l][0] - P[j][0]) * (cw - P[j][1]) - (P[l][1] - P[j][1]) * (cu - P[j][0])) / area;
                    }
                    if (b[0] < 0.0 || b[1] < 0.0 || b[2] < 0.0) continue;
                    z = b[0] * Z[0] + b[1] * Z[1] + b[2] * Z[2];
                    k = (int)floor(z);
                    if (k < 0 || k >= N) continue;
                    v[a] = k;
                    v[u] = pu;
                    v[w] = pw;
                    vol[(v[2] * N + v[1]) * N + v[0]] = 1;
                }
        }
    }
    for (i = 0; i < N * N * N; i++) cnt += vol[i];
    free(vol);
    return cnt;
}

TEST(icosphere_spec_counts)
{
    const double c[3] = {32.1, 31.7, 32.3};
    hfvis_mesh m;
    CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c, 20.0, 5, &m), HFVIS_OK);
    CHECK(m.triangle_count == 20480);
    CHECK(proto_voxel_count(&m, 0) == 4147);
    CHECK(proto_voxel_count(&m, 1) == 4183);
    hfvis_mesh_free(NULL, &m);
}

/* No vertex of the (2,3) knot tube lies closer than the tube radius (minus the polygon sag) to
 * any point of the centre line: the tube does not intersect itself. */
TEST(torus_knot_embedded)
{
    enum { SEG = 400, SIDES = 8, DENSE = 20000 };
    const double c[3] = {0.0, 0.0, 0.0}, tube = HFVIS_TORUS_KNOT_TUBE;
    static double line[DENSE][3];
    hfvis_mesh m;
    double dmin = 1e9;
    size_t v;
    int i;
    for (i = 0; i < DENSE; i++) {
        double tt = 2.0 * PI * i / DENSE, rho = 1.0 + 0.5 * cos(3.0 * tt);
        line[i][0] = rho * cos(2.0 * tt);
        line[i][1] = rho * sin(2.0 * tt);
        line[i][2] = 0.5 * sin(3.0 * tt);
    }
    CHECK_EQ_STATUS(hfvis_mesh_torus_knot(NULL, c, 1.0, 2, 3, SEG, SIDES, &m), HFVIS_OK);
    for (v = 0; v < m.vertex_count; v++) {
        double p[3];
        vtx(&m, v, p);
        for (i = 0; i < DENSE; i++) {
            double dx = p[0] - line[i][0], dy = p[1] - line[i][1], dz = p[2] - line[i][2];
            double d = sqrt(dx * dx + dy * dy + dz * dz);
            if (d < dmin) dmin = d;
        }
    }
    printf("  torus knot (2,3): closest vertex-to-centre-line distance %.6f (tube %.2f)\n", dmin, tube);
    CHECK(dmin > tube * (1.0 - T_TUBE_REL) && dmin < tube * (1.0 + T_TUBE_REL));
    CHECK(edge_defects(&m, NULL) == 0 && mesh_volume(&m, c) > 0.0);
    hfvis_mesh_free(NULL, &m);
    /* the tube's volume converges to (centre line length) * pi * tube^2 (Pappus for tubes) */
    CHECK_EQ_STATUS(hfvis_mesh_torus_knot(NULL, c, 1.0, 2, 3, 2500, 64, &m), HFVIS_OK);
    {
        double L = 0.0;
        for (i = 0; i < DENSE; i++) {
            int j = (i + 1) % DENSE;
            double dx = line[j][0] - line[i][0], dy = line[j][1] - line[i][1], dz = line[j][2] - line[i][2];
            L += sqrt(dx * dx + dy * dy + dz * dz);
        }
        CHECK_NEAR(mesh_volume(&m, c), L * PI * tube * tube, 0.0, T_CONVERGE);
        CHECK_NEAR(mesh_area(&m), L * 2.0 * PI * tube, 0.0, T_CONVERGE);
    }
    hfvis_mesh_free(NULL, &m);
}

TEST(from_grid_holes)
{
    enum { W = 6, H = 5 };
    float z[W * H];
    hfvis_grid g;
    hfvis_mesh m;
    int x, y, kept = 0;
    size_t t;
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++) z[y * W + x] = (float)(x + 10 * y);
    z[1 * W + 2] = NAN;       /* interior hole: drops its 6 triangles */
    z[4 * W + 5] = INFINITY;  /* corner hole: drops both triangles of the last cell */
    g = test_grid(z, W, H, 2.0);
    for (y = 0; y + 1 < H; y++)
        for (x = 0; x + 1 < W; x++) {
            int a = isfinite(z[y * W + x]), b = isfinite(z[y * W + x + 1]);
            int cc = isfinite(z[(y + 1) * W + x]), d = isfinite(z[(y + 1) * W + x + 1]);
            kept += (a && b && d) + (a && d && cc);
        }
    CHECK(kept == 2 * 5 * 4 - 6 - 2);
    CHECK_EQ_STATUS(hfvis_mesh_from_grid(NULL, &g, &m), HFVIS_OK);
    CHECK(m.triangle_count == (size_t)kept && mesh_valid(&m) && unused_vertices(&m) == 0);
    /* the two holes' vertices are dropped, the rest kept in row-major order */
    CHECK(m.vertex_count == W * H - 2);
    for (t = 0; t < m.vertex_count; t++) {
        double p[3];
        int sx, sy;
        vtx(&m, t, p);
        sx = (int)(p[0] / 2.0);
        sy = (int)(p[1] / 2.0);
        CHECK(p[0] == sx * 2.0 && p[1] == sy * 2.0 && p[2] == (double)z[sy * W + sx]);
    }
    for (t = 0; t < m.triangle_count; t++) {
        double n[3], cc[3];
        tri_normal(&m, t, n, cc);
        CHECK(n[2] > 0.0);
    }
    hfvis_mesh_free(NULL, &m);
    /* the split diagonal: a 2x2 grid gives (a, b, d), (a, d, c) */
    {
        static const float z4[4] = {0.0f, 1.0f, 2.0f, 5.0f};
        static const uint32_t want[6] = {0, 1, 3, 0, 3, 2};
        g.z = z4;
        g.width = g.height = 2;
        g.stride = 2;
        g.cell_size = 1.0;
        CHECK_EQ_STATUS(hfvis_mesh_from_grid(NULL, &g, &m), HFVIS_OK);
        CHECK(m.triangle_count == 2 && memcmp(m.indices, want, sizeof want) == 0);
        hfvis_mesh_free(NULL, &m);
    }
    /* 1 x N: no triangles, no vertices, no arrays */
    g.width = 1;
    g.height = 2;
    g.stride = 1;
    CHECK_EQ_STATUS(hfvis_mesh_from_grid(NULL, &g, &m), HFVIS_OK);
    CHECK(m.vertex_count == 0 && m.triangle_count == 0 && m.xyz == NULL && m.indices == NULL);
    /* all holes: empty too */
    {
        float zh[4] = {NAN, NAN, NAN, 1.0f};
        g.z = zh;
        g.width = g.height = g.stride = 2;
        CHECK_EQ_STATUS(hfvis_mesh_from_grid(NULL, &g, &m), HFVIS_OK);
        CHECK(m.vertex_count == 0 && m.triangle_count == 0);
    }
}

/* The split against hfvis.c's bilinear surface: equal along grid lines, and at a cell centre
 * bilinear - mesh = (z_b + z_c - z_a - z_d)/4 (the documented difference). */
TEST(from_grid_vs_bilinear)
{
    enum { W = 9, H = 7 };
    float z[W * H];
    hfvis_grid g;
    hfvis_mesh m;
    int x, y, bad = 0;
    for (x = 0; x < W * H; x++) z[x] = (float)(rng_next() % 1000) / 64.0f; /* exact sums */
    g = test_grid(z, W, H, 1.0);
    CHECK_EQ_STATUS(hfvis_mesh_from_grid(NULL, &g, &m), HFVIS_OK);
    for (y = 0; y + 1 < H; y++)
        for (x = 0; x + 1 < W; x++) {
            double za = (double)z[y * W + x], zb = (double)z[y * W + x + 1], zc = (double)z[(y + 1) * W + x];
            double zd = (double)z[(y + 1) * W + x + 1];
            /* the mesh at the centre lies on the a-d diagonal of triangles 2t, 2t+1 */
            size_t t = 2 * (size_t)(y * (W - 1) + x);
            double pa[3], pd[3], centre_mesh;
            vtx(&m, m.indices[3 * t], pa);
            vtx(&m, m.indices[3 * t + 2], pd);
            centre_mesh = 0.5 * (pa[2] + pd[2]);
            if (hfvis_grid_sample(&g, x + 0.5, y + 0.5) - centre_mesh != (zb + zc - za - zd) / 4.0) bad++;
            if (hfvis_grid_sample(&g, x + 0.5, y) != 0.5 * (za + zb)) bad++; /* edge a-b */
            if (hfvis_grid_sample(&g, x, y + 0.5) != 0.5 * (za + zc)) bad++; /* edge a-c */
        }
    CHECK(bad == 0);
    hfvis_mesh_free(NULL, &m);
}

TEST(room_layout)
{
    const double room_c[3] = {0.5, 0.5, 0.5};
    hfvis_mesh m;
    size_t t, bnd = 0;
    CHECK_EQ_STATUS(hfvis_mesh_room(NULL, &m), HFVIS_OK);
    for (t = 0; t < 30; t++) {
        double n[3], cc[3], ref[3], len;
        tri_normal(&m, t, n, cc);
        len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        CHECK(len > 0.0);
        if (t < 10) { /* walls look into the room: normal toward the room's centre */
            CHECK(n[0] * (room_c[0] - cc[0]) + n[1] * (room_c[1] - cc[1]) + n[2] * (room_c[2] - cc[2]) > 0.0);
        } else {     /* boxes outward: away from their vertical axis / up for the top */
            ref[0] = t < 20 ? 0.66 : 0.34;
            ref[1] = t < 20 ? 0.33 : 0.62;
            ref[2] = t < 20 ? 0.15 : 0.3;
            CHECK(n[0] * (cc[0] - ref[0]) + n[1] * (cc[1] - ref[1]) + n[2] * (cc[2] - ref[2]) > 0.0);
            CHECK(fabs(n[2]) < T_COORD * len || n[2] > 0.0); /* no bottom faces */
        }
    }
    /* boundary: the front opening (4 edges) and the two boxes' bottom rectangles (4 each) */
    edge_defects(&m, &bnd);
    CHECK(bnd == 12);
    /* the short box's first edge direction is rotated by -17 degrees, the tall box's +17 */
    {
        double a[3], b[3];
        vtx(&m, 8, a);
        vtx(&m, 9, b);
        CHECK_NEAR(atan2(b[1] - a[1], b[0] - a[0]), -17.0 * PI / 180.0, T_ANGLE, 0.0);
        vtx(&m, 16, a);
        vtx(&m, 17, b);
        CHECK_NEAR(atan2(b[1] - a[1], b[0] - a[0]), 17.0 * PI / 180.0, T_ANGLE, 0.0);
    }
    hfvis_mesh_free(NULL, &m);
}

TEST(teapot_shape)
{
    hfvis_mesh m, m2;
    double lo[3], hi[3];
    size_t bnd = 0;
    int n = 3;
    CHECK_EQ_STATUS(hfvis_mesh_teapot(NULL, n, &m), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_mesh_teapot(NULL, n, &m2), HFVIS_OK);
    CHECK(m.vertex_count == m2.vertex_count
          && memcmp(m.xyz, m2.xyz, 3 * m.vertex_count * sizeof(float)) == 0
          && memcmp(m.indices, m2.indices, 3 * m.triangle_count * sizeof(uint32_t)) == 0);
    /* body closed; the tubes' 4 end rings (6n edges each) are the only boundary */
    edge_defects(&m, &bnd);
    CHECK(bnd == (size_t)(4 * 6 * n));
    CHECK_EQ_STATUS(hfvis_mesh_bounds(&m, lo, hi), HFVIS_OK);
    CHECK(lo[2] == 0.0 && hi[2] <= 1.42 + T_COORD && hi[2] > 1.41);
    printf("  teapot n=3: %zu vertices, %zu triangles, bounds (%.3f %.3f %.3f)-(%.3f %.3f %.3f)\n",
           m.vertex_count, m.triangle_count, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
    hfvis_mesh_free(NULL, &m);
    hfvis_mesh_free(NULL, &m2);
}

TEST(generator_bad_arguments)
{
    const double c[3] = {0, 0, 0}, lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, flat[3] = {1, 0, 1};
    const double nanc[3] = {0, DNAN, 0}, big[3] = {3e38, 0, 0};
    float z[4] = {0, 0, 0, 0};
    hfvis_grid g;
    hfvis_mesh m;
    memset(&m, 0x5A, sizeof m);
#define BAD(call) CHECK_EQ_STATUS(call, HFVIS_ERR_INVALID_ARGUMENT)
    BAD(hfvis_mesh_box(NULL, lo, hi, NULL));
    BAD(hfvis_mesh_box(NULL, NULL, hi, &m));
    BAD(hfvis_mesh_box(NULL, lo, NULL, &m));
    BAD(hfvis_mesh_box(NULL, lo, flat, &m));
    BAD(hfvis_mesh_box(NULL, hi, lo, &m));
    BAD(hfvis_mesh_box(NULL, nanc, hi, &m));
    BAD(hfvis_mesh_uv_sphere(NULL, c, 1.0, 8, 4, NULL));
    BAD(hfvis_mesh_uv_sphere(NULL, NULL, 1.0, 8, 4, &m));
    BAD(hfvis_mesh_uv_sphere(NULL, c, 0.0, 8, 4, &m));
    BAD(hfvis_mesh_uv_sphere(NULL, c, -1.0, 8, 4, &m));
    BAD(hfvis_mesh_uv_sphere(NULL, c, DNAN, 8, 4, &m));
    BAD(hfvis_mesh_uv_sphere(NULL, c, DINF, 8, 4, &m));
    BAD(hfvis_mesh_uv_sphere(NULL, c, 1.0, 2, 4, &m));
    BAD(hfvis_mesh_uv_sphere(NULL, c, 1.0, 8, 1, &m));
    BAD(hfvis_mesh_uv_sphere(NULL, nanc, 1.0, 8, 4, &m));
    BAD(hfvis_mesh_uv_sphere(NULL, big, 1e38, 8, 4, &m)); /* 3e38 + 1e38 overflows float */
    BAD(hfvis_mesh_uv_sphere(NULL, c, 1e300, 8, 4, &m));
    BAD(hfvis_mesh_icosphere(NULL, c, 1.0, 1, NULL));
    BAD(hfvis_mesh_icosphere(NULL, NULL, 1.0, 1, &m));
    BAD(hfvis_mesh_icosphere(NULL, c, 0.0, 1, &m));
    BAD(hfvis_mesh_icosphere(NULL, c, 1.0, -1, &m));
    BAD(hfvis_mesh_icosphere(NULL, c, 1.0, 11, &m));
    BAD(hfvis_mesh_icosphere(NULL, big, 1e38, 0, &m));
    BAD(hfvis_mesh_torus(NULL, c, 2.0, 1.0, 8, 4, NULL));
    BAD(hfvis_mesh_torus(NULL, c, 1.0, 1.0, 8, 4, &m));
    BAD(hfvis_mesh_torus(NULL, c, 1.0, 2.0, 8, 4, &m));
    BAD(hfvis_mesh_torus(NULL, c, 2.0, 0.0, 8, 4, &m));
    BAD(hfvis_mesh_torus(NULL, c, 2.0, 1.0, 2, 4, &m));
    BAD(hfvis_mesh_torus(NULL, c, 2.0, 1.0, 8, 2, &m));
    BAD(hfvis_mesh_torus(NULL, c, DNAN, 1.0, 8, 4, &m));
    BAD(hfvis_mesh_torus_knot(NULL, c, 1.0, 2, 3, 8, 4, NULL));
    BAD(hfvis_mesh_torus_knot(NULL, NULL, 1.0, 2, 3, 8, 4, &m));
    BAD(hfvis_mesh_torus_knot(NULL, c, 0.0, 2, 3, 8, 4, &m));
    BAD(hfvis_mesh_torus_knot(NULL, c, 1.0, 2, 4, 8, 4, &m)); /* not coprime: a link */
    BAD(hfvis_mesh_torus_knot(NULL, c, 1.0, 0, 3, 8, 4, &m));
    BAD(hfvis_mesh_torus_knot(NULL, c, 1.0, 2, -3, 8, 4, &m));
    BAD(hfvis_mesh_torus_knot(NULL, c, 1.0, 2, 3, 2, 4, &m));
    BAD(hfvis_mesh_torus_knot(NULL, c, 1.0, 2, 3, 8, 2, &m));
    BAD(hfvis_mesh_torus_knot(NULL, c, DINF, 2, 3, 8, 4, &m));
    g.z = z;
    g.width = g.height = 2;
    g.stride = 2;
    g.cell_size = 1.0;
    BAD(hfvis_mesh_from_grid(NULL, &g, NULL));
    BAD(hfvis_mesh_from_grid(NULL, NULL, &m));
    g.z = NULL;
    BAD(hfvis_mesh_from_grid(NULL, &g, &m));
    g.z = z;
    g.width = 0;
    BAD(hfvis_mesh_from_grid(NULL, &g, &m));
    g.width = 2;
    g.height = -1;
    BAD(hfvis_mesh_from_grid(NULL, &g, &m));
    g.height = 2;
    g.stride = 1;
    BAD(hfvis_mesh_from_grid(NULL, &g, &m));
    g.stride = 2;
    g.cell_size = 0.0;
    BAD(hfvis_mesh_from_grid(NULL, &g, &m));
    g.cell_size = DNAN;
    BAD(hfvis_mesh_from_grid(NULL, &g, &m));
    g.cell_size = 1e300; /* x*cell overflows float */
    BAD(hfvis_mesh_from_grid(NULL, &g, &m));
    BAD(hfvis_mesh_room(NULL, NULL));
    BAD(hfvis_mesh_teapot(NULL, 1, NULL));
    BAD(hfvis_mesh_teapot(NULL, 0, &m));
    BAD(hfvis_mesh_teapot(NULL, -5, &m));
    CHECK(m.vertex_count == (size_t)0x5A5A5A5A5A5A5A5Aull);
    /* limits: counts past HFVIS_MESH_MAX_* return LIMIT before allocating anything */
    CHECK_EQ_STATUS(hfvis_mesh_torus(NULL, c, 2.0, 1.0, 65536, 8192, &m), HFVIS_ERR_LIMIT);
    CHECK_EQ_STATUS(hfvis_mesh_torus_knot(NULL, c, 1.0, 2, 3, 1 << 20, 1 << 10, &m), HFVIS_ERR_LIMIT);
    CHECK_EQ_STATUS(hfvis_mesh_uv_sphere(NULL, c, 1.0, 1 << 15, 1 << 14, &m), HFVIS_ERR_LIMIT);
    CHECK_EQ_STATUS(hfvis_mesh_teapot(NULL, 2000, &m), HFVIS_ERR_LIMIT);
    CHECK_EQ_STATUS(hfvis_mesh_teapot(NULL, 1 << 30, &m), HFVIS_ERR_LIMIT);
    g.width = 1 << 15;
    g.height = 1 << 14;
    g.stride = 1 << 15;
    g.cell_size = 1.0;
    CHECK_EQ_STATUS(hfvis_mesh_from_grid(NULL, &g, &m), HFVIS_ERR_LIMIT); /* z never read */
    CHECK(m.vertex_count == (size_t)0x5A5A5A5A5A5A5A5Aull);
    /* bounds */
    {
        hfvis_mesh e, bad;
        float xyz[3] = {0, 0, 0};
        uint32_t idx[3] = {0, 0, 1};
        double l[3] = {7, 7, 7}, h[3] = {7, 7, 7};
        memset(&e, 0, sizeof e);
        BAD(hfvis_mesh_bounds(NULL, l, h));
        BAD(hfvis_mesh_bounds(&e, l, h)); /* no vertices */
        bad.xyz = xyz;
        bad.vertex_count = 1;
        bad.indices = idx;
        bad.triangle_count = 1; /* index 1 >= vertex_count */
        BAD(hfvis_mesh_bounds(&bad, l, h));
        bad.triangle_count = 0;
        BAD(hfvis_mesh_bounds(&bad, NULL, h));
        BAD(hfvis_mesh_bounds(&bad, l, NULL));
        xyz[1] = NAN;
        BAD(hfvis_mesh_bounds(&bad, l, h));
        CHECK(l[0] == 7 && h[2] == 7);
    }
#undef BAD
}

/* ---- OBJ codec ------------------------------------------------------------------------------ */

static int same_mesh(const hfvis_mesh *a, const hfvis_mesh *b)
{
    return a->vertex_count == b->vertex_count && a->triangle_count == b->triangle_count
           && (a->vertex_count == 0 || memcmp(a->xyz, b->xyz, 3 * a->vertex_count * sizeof(float)) == 0)
           && (a->triangle_count == 0
               || memcmp(a->indices, b->indices, 3 * a->triangle_count * sizeof(uint32_t)) == 0);
}

static int round_trip(const hfvis_mesh *m)
{
    size_t need = hfvis_obj_encode_size(m), written = 0;
    unsigned char *buf = (unsigned char *)malloc(need + 1);
    hfvis_mesh back;
    int ok;
    if (need == 0 || !buf) return 0;
    ok = hfvis_obj_encode(m, buf, need, &written) == HFVIS_OK && written == need;
    ok = ok && hfvis_obj_decode(buf, written, NULL, &back) == HFVIS_OK;
    if (ok) {
        ok = same_mesh(m, &back);
        hfvis_mesh_free(NULL, &back);
    }
    /* one byte short */
    ok = ok && hfvis_obj_encode(m, buf, need - 1, &written) == HFVIS_ERR_BUFFER_TOO_SMALL;
    free(buf);
    return ok;
}

TEST(obj_round_trip_generators)
{
    int which;
    for (which = 0; which < 8; which++) {
        hfvis_mesh m;
        CHECK_EQ_STATUS(gen_call(which, NULL, &m), HFVIS_OK);
        CHECK(round_trip(&m));
        hfvis_mesh_free(NULL, &m);
    }
    {
        const double c[3] = {-12.5, 3.25e-3, 1e5};
        hfvis_mesh m;
        CHECK_EQ_STATUS(hfvis_mesh_torus_knot(NULL, c, 7.3, 2, 3, 2500, 20, &m), HFVIS_OK);
        CHECK(round_trip(&m));
        hfvis_mesh_free(NULL, &m);
        CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c, 1e-30, 3, &m), HFVIS_OK);
        CHECK(round_trip(&m));
        hfvis_mesh_free(NULL, &m);
    }
}

/* Every float class round-trips bit for bit through encode/decode, with the fewest significant
 * digits that round-trip through the C library's strtof (correctly rounded on glibc). */
TEST(obj_float_round_trip)
{
    enum { NF = 60000 };
    static float xyz[3 * NF];
    static const float special[] = {0.0f, -0.0f, 1.0f, -1.0f, 0.1f, 1e-45f, -1e-45f, 1.17549435e-38f,
                                    1.1754942e-38f, 3.40282347e38f, -3.40282347e38f, 123456789.0f,
                                    1e10f, 1e-10f, 0.3f, 2.5f, 16777216.0f, 16777215.0f, 9.999999e-5f,
                                    100000.0f, 1e8f, 0.5f, 1.5e-44f};
    hfvis_mesh m;
    size_t i, need, written, nspecial = sizeof special / sizeof special[0];
    unsigned char *buf;
    hfvis_mesh back;
    int longer = 0, shorter = 0;
    for (i = 0; i < 3 * NF; i++) {
        uint32_t bits;
        float f;
        do {
            bits = (uint32_t)rng_next();
            if (i % 3 == 1) bits = (bits & 0x807FFFFFu) | ((uint32_t)(100 + rng_next() % 54) << 23); /* ~1e-8..1e8 */
            memcpy(&f, &bits, sizeof f);
        } while (!isfinite(f));
        xyz[i] = i < nspecial ? special[i] : f;
    }
    m.xyz = xyz;
    m.vertex_count = NF;
    m.indices = NULL;
    m.triangle_count = 0;
    need = hfvis_obj_encode_size(&m);
    buf = (unsigned char *)malloc(need);
    CHECK_EQ_STATUS(hfvis_obj_encode(&m, buf, need, &written), HFVIS_OK);
    CHECK(written == need);
    CHECK_EQ_STATUS(hfvis_obj_decode(buf, written, NULL, &back), HFVIS_OK);
    CHECK(back.vertex_count == NF && memcmp(back.xyz, xyz, sizeof xyz) == 0);
    hfvis_mesh_free(NULL, &back);
    /* digit counts against the shortest %.*e that strtof reads back */
    {
        const char *p = (const char *)buf;
        size_t v = 0;
        p = strchr(p, '\n') + 1; /* header */
        for (v = 0; v < 3 * NF; v++) {
            const char *tok;
            int ours = 0, best, k;
            char tmp[64];
            if (v % 3 == 0) p += 2; /* "v " */
            tok = p;
            while (*p != ' ' && *p != '\n') p++;
            for (k = 0; tok + k < p && tok[k] != 'e'; k++)
                if (tok[k] >= '1' && tok[k] <= '9') break;
            /* significant digits: from the first non-zero digit to the last digit before 'e' */
            {
                const char *q = tok + k, *end = tok;
                while (end < p && *end != 'e') end++;
                for (; q < end; q++) if (*q >= '0' && *q <= '9') ours++;
                /* trailing zeros of an integer are not significant */
                q = end;
                while (q > tok + k && (q[-1] == '0' || q[-1] == '.')) {
                    if (q[-1] == '0') ours--;
                    q--;
                }
            }
            if (xyz[v] == 0.0f) ours = 1;
            for (best = 1; best <= 9; best++) {
                snprintf(tmp, sizeof tmp, "%.*e", best - 1, (double)xyz[v]);
                if (strtof(tmp, NULL) == xyz[v]) break;
            }
            if (ours != best && longer + shorter < 5)
                fprintf(stderr, "  %.*s (%d digits) for %.9g: strtof needs %d\n", (int)(p - tok), tok, ours,
                        (double)xyz[v], best);
            if (ours > best) longer++;
            if (ours < best) shorter++;
            p++; /* ' ' or '\n' */
        }
    }
    printf("  %d floats: %d written with more digits than the shortest, %d with fewer\n", 3 * NF,
           longer, shorter);
    CHECK(longer == 0 && shorter == 0);
    free(buf);
}

/* The decoder's number parser against strtof on random decimal strings (C locale). */
TEST(obj_number_parser)
{
    int i, mismatch = 0;
    for (i = 0; i < 200000; i++) {
        char s[96], line[128];
        int nd = 1 + (int)(rng_next() % 17), k, n = 0, e = (int)(rng_next() % 90) - 50;
        hfvis_mesh m;
        float want;
        if (rng_next() % 2) s[n++] = '-';
        for (k = 0; k < nd; k++) {
            if (k == 1) s[n++] = '.';
            s[n++] = (char)('0' + (int)(rng_next() % 10));
        }
        n += snprintf(s + n, sizeof s - (size_t)n, "e%d", e);
        want = strtof(s, NULL);
        if (!isfinite(want)) continue;
        snprintf(line, sizeof line, "v %s 0 0\n", s);
        if (hfvis_obj_decode(line, strlen(line), NULL, &m) != HFVIS_OK) {
            mismatch++;
            continue;
        }
        if (memcmp(&m.xyz[0], &want, sizeof want) != 0) {
            if (mismatch < 5) fprintf(stderr, "  %s: got %.9g want %.9g\n", s, (double)m.xyz[0], (double)want);
            mismatch++;
        }
        hfvis_mesh_free(NULL, &m);
    }
    printf("  200000 random decimals: %d differ from strtof\n", mismatch);
    CHECK(mismatch == 0);
}

TEST(obj_syntax)
{
    static const char text[] =
        "# comment line\r\n"
        "mtllib scene.mtl\n"
        "o thing\n"
        "\n"
        "   \t\n"
        "v 0 0 0\r\n"
        "v 1.5 -2 +3.25e1 1.0\n"          /* w ignored */
        "v\t.5 5. -0 0.2 0.3 0.4\n"      /* colour values ignored; tabs */
        "vt 0.5 0.5\n"
        "vn 0 0 1\n"
        "g group\n"
        "s off\n"
        "usemtl red\n"
        "v 1E2 1e-2 -1.25E+1   # trailing comment\n"
        "f 1 2 3\n"
        "f 1/1 2/1 3/1\n"
        "f 1//1 2//1 4//1\n"
        "f 1/1/1 3/1/1 4/1/1 2/1/1\n"     /* quad: fanned (1,3,4), (1,4,2) */
        "f -4 -3 -2 -1 5\n"              /* relative + forward reference to vertex 5 */
        "l 1 2\n"
        "p 3\n"
        "vp 0.1\n"
        "v 7 8 9\r"                      /* CR only line end */
        "f 5 4 3";                       /* no final newline */
    static const float want_v[15] = {0, 0, 0, 1.5f, -2, 32.5f, 0.5f, 5, -0.0f, 100, 0.01f, -12.5f, 7, 8, 9};
    static const uint32_t want_t[] = {0, 1, 2, 0, 1, 2, 0, 1, 3, 0, 2, 3, 0, 3, 1,
                                      0, 1, 2, 0, 2, 3, 0, 3, 4, 4, 3, 2};
    hfvis_mesh m;
    CHECK_EQ_STATUS(hfvis_obj_decode(text, sizeof text - 1, NULL, &m), HFVIS_OK);
    CHECK(m.vertex_count == 5 && m.triangle_count == 9);
    if (m.vertex_count == 5) CHECK(memcmp(m.xyz, want_v, sizeof want_v) == 0);
    if (m.triangle_count == 9) CHECK(memcmp(m.indices, want_t, sizeof want_t) == 0);
    CHECK(signbit(m.xyz[8]));
    hfvis_mesh_free(NULL, &m);
    /* empty input and comment-only input: an empty mesh */
    memset(&m, 0x11, sizeof m);
    CHECK_EQ_STATUS(hfvis_obj_decode(NULL, 0, NULL, &m), HFVIS_OK);
    CHECK(m.vertex_count == 0 && m.triangle_count == 0 && m.xyz == NULL && m.indices == NULL);
    CHECK_EQ_STATUS(hfvis_obj_decode("# x\nvt 1 2\n", 11, NULL, &m), HFVIS_OK);
    CHECK(m.vertex_count == 0 && m.triangle_count == 0);
    /* long mantissas and far exponents */
    {
        static const char t2[] = "v 0.000000000000000000000000000000000000000000000000123456789012345678901234e47 "
                                 "123456789012345678901234567890e-29 1e-46\n";
        CHECK_EQ_STATUS(hfvis_obj_decode(t2, sizeof t2 - 1, NULL, &m), HFVIS_OK);
        CHECK(m.xyz[0] == strtof("0.000000000000000000000000000000000000000000000000123456789012345678901234e47", NULL));
        CHECK(m.xyz[1] == 1.23456789f && m.xyz[2] == 0.0f);
        hfvis_mesh_free(NULL, &m);
    }
}

TEST(obj_errors)
{
    static const char *const bad[] = {
        "v 1 2\n", "v 1 2 x\n", "v 1 2 inf\n", "v nan 1 2\n", "v 1e39 0 0\n", "v -3.5e38 0 0\n",
        "v 0x1p3 0 0\n", "v 1 2 3e\n", "v 1 2 3e+\n", "v . 1 2\n", "v - 1 2\n", "v 1..2 0 0\n",
        "v 1 2 3 q\n", "v 1,5 2 3\n", "v 1 2 3\nf 1 2\n", "v 1 2 3\nf 0 1 1\n",
        "v 1 2 3\nf 1 1 2\n", "v 1 2 3\nf -2 1 1\n", "v 1 2 3\nf 1/ 1 1\n", "v 1 2 3\nf 1/1/ 1 1\n",
        "v 1 2 3\nf 1//1/1 1 1\n", "v 1 2 3\nf a b c\n", "v 1 2 3\nf 1/1/1/1 1 1\n",
        "v 1 2 3\nf 1 1 1x\n", "v 1 2 3\nf 1 1 99999999999999999999\n", "f 1 2 3\n",
        "v 1 2 3\nf 1 1 -99999999999999999999\n", "v 1 2 3\nf 1/0 1 1\n", "v 1 2 3\nf 1//0 1 1\n",
        "v 1 2 3\nf\n", "v 1 2 3\nf +0 1 1\n", "v 1 2 3\nf -0 1 1\n", "v 1 2 3\nf 1 // 1\n"};
    size_t i;
    for (i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        hfvis_mesh m;
        hfvis_status s;
        memset(&m, 0x33, sizeof m);
        s = hfvis_obj_decode(bad[i], strlen(bad[i]), NULL, &m);
        if (s != HFVIS_ERR_FORMAT) fprintf(stderr, "  case %u: \"%s\"\n", (unsigned)i, bad[i]);
        CHECK_EQ_STATUS(s, HFVIS_ERR_FORMAT);
        CHECK(m.vertex_count == (size_t)0x3333333333333333ull);
    }
    {
        hfvis_mesh m;
        CHECK_EQ_STATUS(hfvis_obj_decode(NULL, 5, NULL, &m), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_obj_decode("v 1 2 3\n", 8, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    }
    /* encoder arguments */
    {
        hfvis_mesh bm;
        float xyz[3] = {0, INFINITY, 0};
        unsigned char buf[64];
        size_t w = 77;
        bm.xyz = xyz;
        bm.vertex_count = 1;
        bm.indices = NULL;
        bm.triangle_count = 0;
        CHECK(hfvis_obj_encode_size(&bm) == 0);
        CHECK(hfvis_obj_encode_size(NULL) == 0);
        CHECK_EQ_STATUS(hfvis_obj_encode(&bm, buf, sizeof buf, &w), HFVIS_ERR_INVALID_ARGUMENT);
        xyz[1] = 0.0f;
        CHECK_EQ_STATUS(hfvis_obj_encode(&bm, NULL, sizeof buf, &w), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_obj_encode(&bm, buf, sizeof buf, NULL), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK(w == 77);
        CHECK_EQ_STATUS(hfvis_obj_encode(&bm, buf, sizeof buf, &w), HFVIS_OK);
        CHECK(w == hfvis_obj_encode_size(&bm) && memcmp(buf, "# hfvis mesh: 1 vertices, 0 triangles\nv 0 0 0\n", w) == 0);
        CHECK_EQ_STATUS(hfvis_mesh_save("/tmp/x.obj", NULL), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_mesh_save(NULL, &bm), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_mesh_load(NULL, NULL, &bm), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_mesh_load("/tmp/x.obj", NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    }
}

TEST(obj_alloc_failure)
{
    static const char text[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3 4\nf 1 3 2\n";
    test_counting cnt;
    hfvis_allocator a;
    hfvis_mesh m, ref;
    int k;
    CHECK_EQ_STATUS(hfvis_obj_decode(text, sizeof text - 1, NULL, &ref), HFVIS_OK);
    for (k = 1; k <= 2; k++) {
        a = test_counting_allocator(&cnt, 0);
        cnt.fail_at = k;
        memset(&m, 0x44, sizeof m);
        CHECK_EQ_STATUS(hfvis_obj_decode(text, sizeof text - 1, &a, &m), HFVIS_ERR_OUT_OF_MEMORY);
        CHECK(cnt.live == 0 && m.vertex_count == (size_t)0x4444444444444444ull);
    }
    a = test_counting_allocator(&cnt, 0);
    CHECK_EQ_STATUS(hfvis_obj_decode(text, sizeof text - 1, &a, &m), HFVIS_OK);
    CHECK(cnt.allocs == 2 && same_mesh(&m, &ref));
    hfvis_mesh_free(&a, &m);
    CHECK(cnt.live == 0);
    /* load: file buffer + 2 */
    {
        const char *path = "build/test_mesh_alloc.obj";
        FILE *f = fopen(path, "wb");
        int n;
        CHECK(f != NULL);
        if (!f) return;
        fwrite(text, 1, sizeof text - 1, f);
        fclose(f);
        a = test_counting_allocator(&cnt, 0);
        CHECK_EQ_STATUS(hfvis_mesh_load(path, &a, &m), HFVIS_OK);
        CHECK(same_mesh(&m, &ref));
        n = cnt.allocs;
        CHECK(n == 3);
        hfvis_mesh_free(&a, &m);
        CHECK(cnt.live == 0);
        for (k = 1; k <= n; k++) {
            a = test_counting_allocator(&cnt, 0);
            cnt.fail_at = k;
            memset(&m, 0x44, sizeof m);
            CHECK_EQ_STATUS(hfvis_mesh_load(path, &a, &m), HFVIS_ERR_OUT_OF_MEMORY);
            CHECK(cnt.live == 0 && m.vertex_count == (size_t)0x4444444444444444ull);
        }
        remove(path);
    }
    hfvis_mesh_free(NULL, &ref);
}

TEST(obj_files)
{
    const char *path = "build/test_mesh_file.obj";
    const double c[3] = {1, 2, 3};
    hfvis_mesh m, back;
    FILE *f;
    char first[8] = {0};
    CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c, 2.0, 2, &m), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_mesh_save(path, &m), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_mesh_load(path, NULL, &back), HFVIS_OK);
    CHECK(same_mesh(&m, &back));
    hfvis_mesh_free(NULL, &back);
    /* saving to a directory fails and leaves it alone; a failing save leaves the old file */
    CHECK_EQ_STATUS(hfvis_mesh_save("build", &m), HFVIS_ERR_IO);
    CHECK_EQ_STATUS(hfvis_mesh_save("build/no_such_dir/x.obj", &m), HFVIS_ERR_IO);
    f = fopen(path, "rb");
    CHECK(f != NULL);
    if (f) {
        CHECK(fread(first, 1, 7, f) == 7 && memcmp(first, "# hfvis", 7) == 0);
        fclose(f);
    }
    CHECK_EQ_STATUS(hfvis_mesh_load("build/no_such_file.obj", NULL, &back), HFVIS_ERR_IO);
    /* a malformed file: FORMAT, nothing leaked */
    f = fopen(path, "wb");
    if (f) {
        fputs("v 1 2 3\nf 1 2 3\n", f);
        fclose(f);
    }
    CHECK_EQ_STATUS(hfvis_mesh_load(path, NULL, &back), HFVIS_ERR_FORMAT);
    remove(path);
    hfvis_mesh_free(NULL, &m);
}

int main(int argc, char **argv)
{
    TEST_INIT(argc, argv);
    RUN(box);
    RUN(uv_sphere);
    RUN(icosphere);
    RUN(torus);
    RUN(torus_knot);
    RUN(from_grid);
    RUN(room);
    RUN(teapot);
    RUN(generators_alloc_failure);
    RUN(icosphere_construction);
    RUN(icosphere_spec_counts);
    RUN(torus_knot_embedded);
    RUN(from_grid_holes);
    RUN(from_grid_vs_bilinear);
    RUN(room_layout);
    RUN(teapot_shape);
    RUN(generator_bad_arguments);
    RUN(obj_round_trip_generators);
    RUN(obj_float_round_trip);
    RUN(obj_number_parser);
    RUN(obj_syntax);
    RUN(obj_errors);
    RUN(obj_alloc_failure);
    RUN(obj_files);
    return TEST_DONE();
}
