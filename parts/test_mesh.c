/* test_mesh.c - analytic meshes, bounds and the Wavefront OBJ codec (voxel.c section 1). */
#include "hfvis.h"
#include "test.h"

#include <float.h>
#include <stdint.h>
#include <stdlib.h>

#define PI 3.14159265358979323846

/* Tolerances */
#define T_FLOAT_REL 1e-6     /* area/volume of float-rounded vertices vs double closed form */
#define T_SPHERE_S5 3e-4     /* icosphere s=5 area vs the spec's 5025.0 (rounded to 0.1) */
#define T_CONVERGE 2e-3      /* fine tessellations vs the smooth surface's area/volume */

/* ---- helpers ----------------------------------------------------------------------------- */

typedef struct counting {
    int allocs, frees, live, fail_at;
} counting;
static void *c_alloc(void *user, size_t n)
{
    counting *c = (counting *)user;
    void *p;
    c->allocs++;
    if (c->fail_at != 0 && c->allocs == c->fail_at) return NULL;
    p = malloc(n);
    if (p) c->live++;
    return p;
}
static void c_free(void *user, void *p)
{
    counting *c = (counting *)user;
    if (!p) return;
    c->frees++;
    c->live--;
    free(p);
}
static hfvis_allocator counting_allocator(counting *c)
{
    hfvis_allocator a;
    memset(c, 0, sizeof *c);
    a.alloc = c_alloc;
    a.free = c_free;
    a.user = c;
    return a;
}

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
            printf("  icosphere s=5 r=20: area %.4f (spec 5025.0), volume %.3f\n", mesh_area(&m), V);
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
    CHECK(hi[0] <= 1.75 + 1e-6 && lo[0] >= -1.75 - 1e-6 && hi[2] <= 0.75 + 1e-6);
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
        CHECK(m.vertex_count == (8 * nn - 1) * 12 * nn + 2 + 2 * (8 * nn + 1) * 6 * nn);
        CHECK(m.triangle_count == 2 * 12 * nn * (8 * nn - 1) + 4 * 8 * nn * 6 * nn);
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
    g.z = z;
    g.width = 4;
    g.height = 3;
    g.stride = 4;
    g.cell_size = 1.0;
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
        counting cnt;
        hfvis_allocator a = counting_allocator(&cnt);
        hfvis_mesh ref, m;
        int n, k;
        CHECK_EQ_STATUS(gen_call(which, &a, &ref), HFVIS_OK);
        n = cnt.allocs;
        CHECK(n >= 2);
        hfvis_mesh_free(&a, &ref);
        CHECK(cnt.live == 0);
        for (k = 1; k <= n; k++) {
            a = counting_allocator(&cnt);
            cnt.fail_at = k;
            memset(&m, 0xAB, sizeof m);
            CHECK_EQ_STATUS(gen_call(which, &a, &m), HFVIS_ERR_OUT_OF_MEMORY);
            CHECK(cnt.live == 0 && cnt.allocs == cnt.frees + 1);
            CHECK(m.vertex_count == (size_t)0xABABABABABABABABull);
        }
    }
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
    return TEST_DONE();
}
