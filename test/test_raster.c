/* test_raster.c - the reference rasterizer (hfvis_rasterize) against its ray-per-pixel oracle,
 * the top-left fill rule, watertightness, clipping, depth conventions, errors, allocation. */
#include "hfvis.h"
#include "test.h"

#include <limits.h>
#include <stdlib.h>

/* A pixel centre closer than this (pixels) to a projected edge line (or the near/far line) of
 * the rasterizer's or the oracle's triangle may legitimately differ: vertices snap to 1/256 px,
 * so edges move by <= sqrt(2)/512 px = 0.0028 px; 0.01 leaves room for rounding. */
#define EDGE_EPS_PX 0.01
/* Such pixels must stay rare: fraction of covered pixels (issue: < 1%). */
#define MAX_EDGE_FRACTION 0.01
/* Linear depth: both compute -(sum b_i z_i) in double from barycentrics that agree to ~1e-12
 * relative; the float output rounds at 6e-8 relative. */
#define TOL_LIN_REL 2e-7
/* Window depth: float rounding near 1 (2^-24) plus the double difference. */
#define TOL_ZW_ABS 1.2e-7
/* Barycentrics: float rounding of values in [0, 1] plus double differences (conditioning of
 * grazing triangles). */
#define TOL_BARY_ABS 1e-6
/* Window depth vs hfvis_eye_z_to_depth(linear depth): float rounding of both outputs, amplified
 * by dzw/dz = n f/((f-n) z^2) <= 1/n for the linear depth's relative error. */
#define TOL_ZW_FROM_LIN 4e-6
/* Orthographic linear depth on a plane: second differences vanish up to float rounding of values
 * ~ 5 (2^-21 each, four terms). */
#define TOL_ORTHO_SECOND_DIFF 4e-6

/* ---- small helpers ------------------------------------------------------------------------ */

static uint64_t rs_state = 1;
static void rs_seed(uint64_t s) { rs_state = s * 6364136223846793005ull + 1442695040888963407ull; }
static double rs_unit(void) /* [0, 1) */
{
    rs_state = rs_state * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(rs_state >> 11) * (1.0 / 9007199254740992.0);
}
static double rs_range(double a, double b) { return a + (b - a) * rs_unit(); }

typedef struct planes {
    int w, h;
    float *lin, *zw, *nrm, *bary;
    uint32_t *id, *cnt;
} planes;

static void planes_alloc(planes *p, int w, int h)
{
    size_t n = (size_t)w * (size_t)h;
    p->w = w, p->h = h;
    p->lin = (float *)malloc(n * sizeof(float));
    p->zw = (float *)malloc(n * sizeof(float));
    p->nrm = (float *)malloc(3 * n * sizeof(float));
    p->bary = (float *)malloc(2 * n * sizeof(float));
    p->id = (uint32_t *)malloc(n * sizeof(uint32_t));
    p->cnt = (uint32_t *)malloc(n * sizeof(uint32_t));
}
static void planes_free(planes *p)
{
    free(p->lin), free(p->zw), free(p->nrm), free(p->bary), free(p->id), free(p->cnt);
}
static hfvis_raster_outputs planes_out(planes *p)
{
    hfvis_raster_outputs o;
    o.linear_depth = p->lin;
    o.window_depth = p->zw;
    o.normal = p->nrm;
    o.triangle_id = p->id;
    o.barycentric = p->bary;
    o.coverage_count = p->cnt;
    return o;
}

/* clip coordinates of world point v */
static void clip_of(const hfvis_view *v, const float *p, double c[4])
{
    double e[4];
    int r;
    for (r = 0; r < 4; r++)
        e[r] = v->view[r] * (double)p[0] + v->view[4 + r] * (double)p[1] + v->view[8 + r] * (double)p[2]
               + v->view[12 + r];
    for (r = 0; r < 4; r++)
        c[r] = v->proj[r] * e[0] + v->proj[4 + r] * e[1] + v->proj[8 + r] * e[2] + v->proj[12 + r] * e[3];
}

/* Smallest distance (pixels) from pixel (x, y)'s centre to the projected edge lines of triangle t
 * and to the lines where its plane meets the near and far planes (homogeneous: exact for
 * triangles crossing w = 0 too). */
static double edge_distance(const hfvis_mesh *m, const hfvis_view *v, uint32_t t, int x, int y)
{
    double H[3][3], z[3], px = x + 0.5, py = y + 0.5, best = HUGE_VAL, det, g[3], r[3][3];
    int j, k;
    for (j = 0; j < 3; j++) {
        double c[4];
        clip_of(v, m->xyz + 3 * (size_t)m->indices[3 * (size_t)t + (size_t)j], c);
        H[j][0] = (c[0] + c[3]) * 0.5 * v->width; /* homogeneous window coordinates, y down */
        H[j][1] = (c[3] - c[1]) * 0.5 * v->height;
        H[j][2] = c[3];
        z[j] = c[2];
    }
    for (j = 0; j < 3; j++) {
        const double *p = H[(j + 1) % 3], *q = H[(j + 2) % 3];
        double l[3], d;
        l[0] = p[1] * q[2] - p[2] * q[1];
        l[1] = p[2] * q[0] - p[0] * q[2];
        l[2] = p[0] * q[1] - p[1] * q[0];
        for (k = 0; k < 3; k++) r[j][k] = l[k];
        d = fabs(l[0] * px + l[1] * py + l[2]) / sqrt(l[0] * l[0] + l[1] * l[1]);
        if (d < best) best = d;
    }
    det = r[0][0] * H[0][0] + r[0][1] * H[0][1] + r[0][2] * H[0][2];
    for (k = 0; k < 3; k++) g[k] = (r[0][k] * z[0] + r[1][k] * z[1] + r[2][k] * z[2]) / det;
    {   /* z_ndc(p) = g . (px, py, 1): distance to z_ndc = -1 and z_ndc = +1 */
        double gl = sqrt(g[0] * g[0] + g[1] * g[1]), s = g[0] * px + g[1] * py + g[2];
        if (gl > 0.0) {
            if (fabs(s + 1.0) / gl < best) best = fabs(s + 1.0) / gl;
            if (fabs(s - 1.0) / gl < best) best = fabs(s - 1.0) / gl;
        }
    }
    return best;
}

/* Vertices (by position) two triangles share. */
static int shared_vertices(const hfvis_mesh *m, uint32_t s, uint32_t t)
{
    int j, k, n = 0;
    for (j = 0; j < 3; j++)
        for (k = 0; k < 3; k++)
            if (memcmp(m->xyz + 3 * (size_t)m->indices[3 * (size_t)s + (size_t)j],
                       m->xyz + 3 * (size_t)m->indices[3 * (size_t)t + (size_t)k], 3 * sizeof(float)) == 0)
                n++;
    return n;
}

typedef struct cmp_stats {
    long adjacent, silhouette; /* mismatches between triangles sharing >= 1 vertex; with nothing
                                  or a non-adjacent triangle (silhouette over a background) */
    long covered, mismatched, unexplained, depth_bad, bary_bad, normal_bad, count_bad, count_cmp;
    double max_lin_rel, max_zw, max_bary;
} cmp_stats;

/* Rasterize and run the oracle on one view; compare plane by plane (see the tolerances). */
static void compare_view(const hfvis_mesh *m, const hfvis_view *v, const hfvis_raster_options *o,
                         cmp_stats *st)
{
    planes a, b;
    hfvis_raster_outputs oa, ob;
    int x, y;
    planes_alloc(&a, v->width, v->height);
    planes_alloc(&b, v->width, v->height);
    oa = planes_out(&a);
    ob = planes_out(&b);
    CHECK_EQ_STATUS(hfvis_rasterize(m, v, o, &oa), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_rasterize_reference(m, v, o, &ob), HFVIS_OK);
    for (y = 0; y < v->height; y++)
        for (x = 0; x < v->width; x++) {
            size_t i = (size_t)y * (size_t)v->width + (size_t)x;
            if (a.id[i] != HFVIS_NO_TRIANGLE || b.id[i] != HFVIS_NO_TRIANGLE) st->covered++;
            if (a.id[i] != b.id[i]) {
                double d = HUGE_VAL;
                st->mismatched++;
                if (a.id[i] != HFVIS_NO_TRIANGLE) d = edge_distance(m, v, a.id[i], x, y);
                if (b.id[i] != HFVIS_NO_TRIANGLE) d = fmin(d, edge_distance(m, v, b.id[i], x, y));
                if (a.id[i] != HFVIS_NO_TRIANGLE && b.id[i] != HFVIS_NO_TRIANGLE
                    && shared_vertices(m, a.id[i], b.id[i]) > 0)
                    st->adjacent++;
                else
                    st->silhouette++;
                if (!(d <= EDGE_EPS_PX)) {
                    st->unexplained++;
                    if (st->unexplained < 5)
                        fprintf(stderr, "  unexplained (%d,%d): raster %u oracle %u dist %g\n", x, y,
                                (unsigned)a.id[i], (unsigned)b.id[i], d);
                }
                continue;
            }
            if (a.id[i] == HFVIS_NO_TRIANGLE) {
                if (!(isinf(a.lin[i]) && a.zw[i] == 1.0f && a.nrm[3 * i] == 0.0f && a.bary[2 * i] == 0.0f
                      && isinf(b.lin[i]) && b.zw[i] == 1.0f))
                    st->depth_bad++;
                continue;
            }
            {
                double dl = fabs((double)a.lin[i] - (double)b.lin[i]) / fabs((double)b.lin[i]);
                double dz = fabs((double)a.zw[i] - (double)b.zw[i]);
                double db = fmax(fabs((double)a.bary[2 * i] - (double)b.bary[2 * i]),
                                 fabs((double)a.bary[2 * i + 1] - (double)b.bary[2 * i + 1]));
                if (dl > st->max_lin_rel) st->max_lin_rel = dl;
                if (dz > st->max_zw) st->max_zw = dz;
                if (db > st->max_bary) st->max_bary = db;
                if (!(dl <= TOL_LIN_REL) || !(dz <= TOL_ZW_ABS)) st->depth_bad++;
                if (!(db <= TOL_BARY_ABS)) st->bary_bad++;
                if (memcmp(a.nrm + 3 * i, b.nrm + 3 * i, 3 * sizeof(float)) != 0) st->normal_bad++;
            }
        }
    /* coverage counts: equal wherever no edge line of any triangle passes within EDGE_EPS_PX */
    for (y = 0; y < v->height; y++)
        for (x = 0; x < v->width; x++) {
            size_t i = (size_t)y * (size_t)v->width + (size_t)x;
            uint32_t t;
            int near_edge = 0;
            if (a.cnt[i] == b.cnt[i]) {
                st->count_cmp++;
                continue;
            }
            for (t = 0; t < (uint32_t)m->triangle_count && !near_edge; t++)
                if (edge_distance(m, v, t, x, y) <= EDGE_EPS_PX) near_edge = 1;
            if (!near_edge) st->count_bad++;
        }
    planes_free(&a);
    planes_free(&b);
}

static void random_view(hfvis_view *v, int ortho, double dist_lo, double dist_hi, const double ctr[3],
                        double spread)
{
    double eye[3], tgt[3], up[3], th = rs_range(0.0, 6.283185307179586), ph = rs_range(-1.4, 1.4);
    double dist = rs_range(dist_lo, dist_hi);
    int w = 40 + (int)(rs_unit() * 50), h = 30 + (int)(rs_unit() * 40), k;
    eye[0] = ctr[0] + dist * cos(ph) * cos(th);
    eye[1] = ctr[1] + dist * cos(ph) * sin(th);
    eye[2] = ctr[2] + dist * sin(ph);
    for (k = 0; k < 3; k++) {
        tgt[k] = ctr[k] + rs_range(-spread, spread);
        up[k] = rs_range(-1.0, 1.0);
    }
    up[2] += 2.0;
    if (ortho)
        CHECK_EQ_STATUS(hfvis_view_orthographic(v, eye, tgt, up, rs_range(0.8, 2.0), w, h, 0.1, 20.0),
                        HFVIS_OK);
    else
        CHECK_EQ_STATUS(hfvis_view_perspective(v, eye, tgt, up, rs_range(0.5, 1.3), w, h,
                                               rs_range(0.05, 0.5), 20.0),
                        HFVIS_OK);
}

static void report(const char *name, const cmp_stats *st)
{
    printf("  %-10s covered %ld, id mismatches %ld (%.3f%%: %ld adjacent, %ld silhouette; all within "
           "%.2g px of an edge: %s), max |dlin|/lin %.2g, max |dzw| %.2g, max |dbary| %.2g\n",
           name, st->covered, st->mismatched,
           st->covered ? 100.0 * (double)st->mismatched / (double)st->covered : 0.0, st->adjacent,
           st->silhouette, EDGE_EPS_PX, st->unexplained ? "NO" : "yes", st->max_lin_rel, st->max_zw,
           st->max_bary);
    CHECK(st->unexplained == 0);
    CHECK((double)st->mismatched <= MAX_EDGE_FRACTION * (double)st->covered);
    CHECK(st->depth_bad == 0);
    CHECK(st->bary_bad == 0);
    CHECK(st->normal_bad == 0);
    CHECK(st->count_bad == 0);
}

/* ---- pixel-exact orthographic setup for hand-made cases ----------------------------------- */

/* View identity, ortho so that world (X, -Y, z) lands on window (X, Y) exactly. */
static void pixel_view(hfvis_view *v, int w, int h)
{
    int k;
    memset(v, 0, sizeof *v);
    for (k = 0; k < 4; k++) v->view[5 * k] = 1.0;
    CHECK_EQ_STATUS(hfvis_mat4_ortho(0.0, (double)w, -(double)h, 0.0, 0.5, 10.0, v->proj), HFVIS_OK);
    v->width = w, v->height = h, v->near_plane = 0.5, v->far_plane = 10.0, v->orthographic = 1;
}

/* Mesh from window-space triangles (X, Y) at eye depth 1. */
typedef struct soup {
    float xyz[3 * 96];
    uint32_t idx[96];
    hfvis_mesh m;
} soup;
static void soup_init(soup *s) { memset(s, 0, sizeof *s); s->m.xyz = s->xyz; s->m.indices = s->idx; }
static void soup_add(soup *s, double x0, double y0, double x1, double y1, double x2, double y2)
{
    double p[6];
    int k;
    p[0] = x0, p[1] = y0, p[2] = x1, p[3] = y1, p[4] = x2, p[5] = y2;
    for (k = 0; k < 3; k++) {
        size_t v = s->m.vertex_count++;
        s->xyz[3 * v] = (float)p[2 * k];
        s->xyz[3 * v + 1] = (float)-p[2 * k + 1];
        s->xyz[3 * v + 2] = -1.0f;
        s->idx[v] = (uint32_t)v;
    }
    s->m.triangle_count++;
}

static void raster_counts(const hfvis_mesh *m, const hfvis_view *v, const hfvis_raster_options *o,
                          uint32_t *cnt, uint32_t *id)
{
    hfvis_raster_outputs out;
    memset(&out, 0, sizeof out);
    out.coverage_count = cnt;
    out.triangle_id = id;
    CHECK_EQ_STATUS(hfvis_rasterize(m, v, o, &out), HFVIS_OK);
}

/* ---- tests -------------------------------------------------------------------------------- */

TEST(options_default)
{
    hfvis_raster_options o = hfvis_raster_options_default(), z;
    memset(&z, 0, sizeof z);
    CHECK(o.alloc == NULL && o.cull == HFVIS_CULL_NONE && o.normal_space == HFVIS_NORMAL_WORLD
          && o.normal_toward_viewer == 0);
    CHECK(memcmp(&o, &z, sizeof o) == 0);
}

/* A centre exactly on a horizontal edge: covered on a top edge (triangle below it), not on a
 * bottom edge; on a vertical edge: covered on a left edge, not on a right edge. */
TEST(top_left_rule)
{
    enum { W = 8, H = 8 };
    hfvis_view v;
    soup s;
    uint32_t cnt[W * H], id[W * H];
    int x, y;
    pixel_view(&v, W, H);
    /* top edge y = 2.5 from x = 1.5 to 6.5, triangle below; left edge x = 1.5 */
    soup_init(&s);
    soup_add(&s, 1.5, 2.5, 1.5, 6.5, 6.5, 2.5); /* CCW on screen (y up): front */
    raster_counts(&s.m, &v, NULL, cnt, id);
    for (x = 1; x <= 5; x++) CHECK(cnt[2 * W + x] == 1); /* on the top edge */
    CHECK(cnt[2 * W + 6] == 0);                           /* vertex also on the hypotenuse */
    for (y = 2; y <= 5; y++) CHECK(cnt[y * W + 1] == 1);  /* on the left edge */
    CHECK(cnt[6 * W + 1] == 0);                           /* bottom vertex: on the hypotenuse */
    CHECK(cnt[1 * W + 2] == 0 && cnt[2 * W + 0] == 0);
    /* bottom edge y = 6.5 with the triangle above; right edge x = 6.5 */
    soup_init(&s);
    soup_add(&s, 1.5, 6.5, 6.5, 6.5, 6.5, 2.5);
    raster_counts(&s.m, &v, NULL, cnt, id);
    for (x = 0; x < W; x++) CHECK(cnt[6 * W + x] == 0); /* the bottom edge row: nothing */
    for (y = 0; y < H; y++) CHECK(cnt[y * W + 6] == 0); /* the right edge column: nothing */
    CHECK(cnt[5 * W + 5] == 1 && cnt[3 * W + 5] == 1);  /* interior next to both */
    CHECK(cnt[4 * W + 3] == 0);                          /* (3.5, 4.5) is left of the diagonal */
    /* the same triangles with the other winding (back-facing) cover the same pixels */
    soup_init(&s);
    soup_add(&s, 1.5, 2.5, 6.5, 2.5, 1.5, 6.5);
    raster_counts(&s.m, &v, NULL, cnt, id);
    for (x = 1; x <= 5; x++) CHECK(cnt[2 * W + x] == 1);
    CHECK(cnt[2 * W + 6] == 0 && cnt[6 * W + 1] == 0);
}

/* Two triangles sharing an edge through pixel centres, and a fan around a pixel centre: every
 * pixel of the union is covered exactly once. */
TEST(shared_edges_once)
{
    enum { W = 10, H = 10 };
    hfvis_view v;
    soup s;
    uint32_t cnt[W * H], id[W * H];
    int x, y, k, bad = 0;
    pixel_view(&v, W, H);
    soup_init(&s);
    soup_add(&s, 0.5, 0.5, 6.5, 6.5, 6.5, 0.5); /* square [0.5, 6.5]^2 split on its diagonal */
    soup_add(&s, 0.5, 0.5, 0.5, 6.5, 6.5, 6.5);
    raster_counts(&s.m, &v, NULL, cnt, id);
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++)
            if (cnt[y * W + x] != (uint32_t)(x <= 5 && y <= 5)) bad++; /* left/top edges only */
    CHECK(bad == 0);
    for (k = 0; k <= 5; k++) CHECK(cnt[k * W + k] == 1); /* the diagonal, once */
    /* the diagonal is a left edge of triangle 0 (its interior lies right of it): it takes the
     * diagonal; (5, 0) lies on 0's top edge, (0, 5) on 1's left edge */
    for (k = 0; k <= 5; k++) CHECK(id[k * W + k] == 0);
    CHECK(id[0 * W + 5] == 0 && id[5 * W + 0] == 1 && id[5 * W + 4] == 1 && id[4 * W + 5] == 0);
    /* 8 triangles around the centre of pixel (4, 4), corners at pixel centres and edge midpoints */
    soup_init(&s);
    {
        static const double ring[8][2] = {{1, 0}, {1, 1}, {0, 1}, {-1, 1}, {-1, 0}, {-1, -1}, {0, -1}, {1, -1}};
        for (k = 0; k < 8; k++)
            soup_add(&s, 4.5, 4.5, 4.5 + 3 * ring[k][0], 4.5 + 3 * ring[k][1], 4.5 + 3 * ring[(k + 1) % 8][0],
                     4.5 + 3 * ring[(k + 1) % 8][1]);
    }
    raster_counts(&s.m, &v, NULL, cnt, id);
    bad = 0;
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++)
            if (cnt[y * W + x] != (uint32_t)(x >= 1 && x <= 6 && y >= 1 && y <= 6)) bad++;
    CHECK(bad == 0);
    CHECK(cnt[4 * W + 4] == 1);
}

/* Closed meshes: every pixel gets an even number of fragments without culling (a ray enters as
 * often as it leaves; the fill rule is a consistent perturbation of the sample point), exactly 2
 * over a convex sphere's disc, exactly 1 with back or front culling; counts equal the oracle's
 * away from edges (torus: depth complexity 0, 2 or 4). */
TEST(watertight_counts)
{
    const double c0[3] = {0.0, 0.0, 0.0};
    int mk, vi, odd_total = 0, pix_total = 0;
    int count2 = 0, count4 = 0;
    rs_seed(11);
    for (mk = 0; mk < 3; mk++) {
        hfvis_mesh m;
        memset(&m, 0, sizeof m);
        if (mk == 0) CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c0, 1.0, 3, &m), HFVIS_OK);
        if (mk == 1) CHECK_EQ_STATUS(hfvis_mesh_uv_sphere(NULL, c0, 1.0, 24, 12, &m), HFVIS_OK);
        if (mk == 2) CHECK_EQ_STATUS(hfvis_mesh_torus(NULL, c0, 1.0, 0.4, 32, 16, &m), HFVIS_OK);
        for (vi = 0; vi < 6; vi++) {
            hfvis_view v;
            hfvis_raster_options o = hfvis_raster_options_default();
            uint32_t *cnt, *cb, *cf, *id;
            size_t n, i;
            int odd = 0, bad_sphere = 0, bad_cull = 0;
            random_view(&v, vi % 3 == 2, 2.5, 4.0, c0, 0.3);
            if (vi == 0) { /* one larger perspective view */
                v.width = 160, v.height = 120;
                CHECK_EQ_STATUS(hfvis_mat4_perspective(0.9, 160.0 / 120.0, v.near_plane, 20.0, v.proj), HFVIS_OK);
            }
            n = (size_t)v.width * (size_t)v.height;
            cnt = (uint32_t *)malloc(n * 4), cb = (uint32_t *)malloc(n * 4), cf = (uint32_t *)malloc(n * 4);
            id = (uint32_t *)malloc(n * 4);
            raster_counts(&m, &v, NULL, cnt, id);
            o.cull = HFVIS_CULL_BACK;
            raster_counts(&m, &v, &o, cb, id);
            o.cull = HFVIS_CULL_FRONT;
            raster_counts(&m, &v, &o, cf, id);
            for (i = 0; i < n; i++) {
                if (cnt[i] & 1u) odd++;
                if (cnt[i] == 2) count2++;
                if (cnt[i] == 4) count4++;
                if (mk < 2 && cnt[i] != 0 && cnt[i] != 2) bad_sphere++;
                if (mk < 2 && (cb[i] != cnt[i] / 2 || cf[i] != cnt[i] / 2)) bad_cull++;
                if (cb[i] + cf[i] != cnt[i] || cb[i] != cf[i]) bad_cull++;
            }
            CHECK(odd == 0);
            CHECK(bad_sphere == 0);
            CHECK(bad_cull == 0);
            odd_total += odd;
            pix_total += (int)n;
            if (vi < 2) { /* against the oracle's hit counts, away from edges */
                cmp_stats st;
                memset(&st, 0, sizeof st);
                compare_view(&m, &v, NULL, &st);
                report(mk == 0 ? "icosphere" : mk == 1 ? "uv sphere" : "torus", &st);
            }
            free(cnt), free(cb), free(cf), free(id);
        }
        hfvis_mesh_free(NULL, &m);
    }
    printf("  closed meshes: %d pixels, %d with an odd fragment count; %d pixels with 2, %d with 4\n",
           pix_total, odd_total, count2, count4);
    CHECK(count4 > 0);
}

/* The rasterizer against its oracle on seeded random views of the generator meshes. */
TEST(raster_vs_reference)
{
    const double c0[3] = {0.0, 0.0, 0.0}, room_c[3] = {0.5, 0.5, 0.5};
    const double lo[3] = {-0.7, -0.5, -0.3}, hi[3] = {0.6, 0.4, 0.8};
    int mk, vi;
    cmp_stats all;
    memset(&all, 0, sizeof all);
    rs_seed(2024);
    for (mk = 0; mk < 4; mk++) {
        hfvis_mesh m;
        cmp_stats st;
        memset(&m, 0, sizeof m);
        memset(&st, 0, sizeof st);
        if (mk == 0) CHECK_EQ_STATUS(hfvis_mesh_box(NULL, lo, hi, &m), HFVIS_OK);
        if (mk == 1) CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c0, 1.0, 2, &m), HFVIS_OK);
        if (mk == 2) CHECK_EQ_STATUS(hfvis_mesh_torus(NULL, c0, 1.0, 0.35, 24, 12, &m), HFVIS_OK);
        if (mk == 3) CHECK_EQ_STATUS(hfvis_mesh_room(NULL, &m), HFVIS_OK);
        for (vi = 0; vi < 8; vi++) {
            hfvis_view v;
            hfvis_raster_options o = hfvis_raster_options_default();
            o.cull = (hfvis_cull_mode)(vi % 3);
            o.normal_space = (hfvis_normal_space)(vi % 2);
            o.normal_toward_viewer = (vi / 2) % 2;
            if (mk == 3 && vi >= 4) { /* inside the room: walls behind the eye cross the near plane */
                random_view(&v, 0, 0.05, 0.3, room_c, 0.5);
                if (vi % 2) { /* very wide, near plane close to the eye */
                    CHECK_EQ_STATUS(hfvis_mat4_perspective(1.9, (double)v.width / v.height, 0.01, 20.0, v.proj),
                                    HFVIS_OK);
                    v.near_plane = 0.01;
                }
            } else {
                random_view(&v, vi % 4 == 3, 2.2, 4.0, mk == 3 ? room_c : c0, 0.4);
            }
            compare_view(&m, &v, &o, &st);
        }
        report(mk == 0 ? "box" : mk == 1 ? "icosphere" : mk == 2 ? "torus" : "room", &st);
        all.covered += st.covered, all.mismatched += st.mismatched;
        all.adjacent += st.adjacent, all.silhouette += st.silhouette;
        hfvis_mesh_free(NULL, &m);
    }
    printf("  all: %ld covered pixels, %ld id mismatches (%.4f%%; %ld between adjacent triangles, %ld at "
           "silhouettes)\n", all.covered, all.mismatched, 100.0 * (double)all.mismatched / (double)all.covered,
           all.adjacent, all.silhouette);
}

/* Camera inside a box with a wide field of view: the side walls pass behind the eye and cross
 * the near plane; clipped (not dropped), they cover every pixel exactly once (closed box seen
 * from inside: depth complexity 1) while the near plane (0.05) is closer than any wall point in
 * the frustum (>= 0.2 here). With near 0.5 the near plane cuts holes at the image border: counts
 * stay <= 1 and the oracle sees the same holes. */
TEST(near_plane_clipping)
{
    const double lo[3] = {-1.0, -1.0, -1.0}, hi[3] = {1.0, 1.0, 1.0};
    const double eye[3] = {0.0, 0.0, 0.0}, up[3] = {0.0, 0.0, 1.0};
    hfvis_mesh m;
    int vi;
    memset(&m, 0, sizeof m);
    CHECK_EQ_STATUS(hfvis_mesh_box(NULL, lo, hi, &m), HFVIS_OK);
    rs_seed(77);
    for (vi = 0; vi < 6; vi++) {
        hfvis_view v;
        double tgt[3];
        planes p;
        size_t i, n;
        int crossing = 0, bad = 0;
        uint32_t t;
        tgt[0] = rs_range(-1, 1), tgt[1] = rs_range(-1, 1), tgt[2] = rs_range(-0.5, 0.5);
        CHECK_EQ_STATUS(hfvis_view_perspective(&v, eye, tgt, up, rs_range(1.6, 2.6), 64, 48,
                                               vi < 3 ? 0.05 : 0.5, 10.0),
                        HFVIS_OK);
        for (t = 0; t < (uint32_t)m.triangle_count; t++) { /* triangles crossing z = -w */
            int j, in = 0, outn = 0;
            for (j = 0; j < 3; j++) {
                double c[4];
                clip_of(&v, m.xyz + 3 * (size_t)m.indices[3 * t + (uint32_t)j], c);
                if (c[2] < -c[3]) outn++;
                else in++;
            }
            if (in && outn) crossing++;
        }
        CHECK(crossing > 0);
        planes_alloc(&p, 64, 48);
        {
            hfvis_raster_outputs o = planes_out(&p);
            CHECK_EQ_STATUS(hfvis_rasterize(&m, &v, NULL, &o), HFVIS_OK);
        }
        n = 64 * 48;
        if (vi < 3) {
            for (i = 0; i < n; i++)
                if (p.cnt[i] != 1 || p.id[i] == HFVIS_NO_TRIANGLE || !((double)p.lin[i] >= v.near_plane)) bad++;
        } else {
            int holes = 0;
            for (i = 0; i < n; i++) {
                if (p.cnt[i] > 1 || (p.cnt[i] == 1) != (p.id[i] != HFVIS_NO_TRIANGLE)) bad++;
                if (p.cnt[i] == 0) holes++;
            }
            if (vi == 3) printf("  near 0.5: %d of %d pixels cut away by the near plane\n", holes, (int)n);
        }
        CHECK(bad == 0);
        if (vi < 2 || vi >= 4) {
            cmp_stats st;
            memset(&st, 0, sizeof st);
            compare_view(&m, &v, NULL, &st);
            report("inside box", &st);
        }
        planes_free(&p);
    }
    hfvis_mesh_free(NULL, &m);
    /* a closed sphere cut open by the near plane: clipped triangles stay watertight (counts equal
     * the oracle's hits away from edges and the cut line: 1 inside the cut, 2 around it) */
    {
        const double c0[3] = {0.0, 0.0, 0.0}, e2[3] = {0.2, -2.2, 0.3};
        hfvis_view v;
        cmp_stats st;
        planes p;
        size_t i;
        int ones = 0, twos = 0, more = 0;
        memset(&m, 0, sizeof m);
        CHECK_EQ_STATUS(hfvis_mesh_icosphere(NULL, c0, 1.0, 3, &m), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_view_perspective(&v, e2, c0, up, 1.2, 64, 48, 1.3, 10.0), HFVIS_OK);
        planes_alloc(&p, 64, 48);
        {
            hfvis_raster_outputs o = planes_out(&p);
            CHECK_EQ_STATUS(hfvis_rasterize(&m, &v, NULL, &o), HFVIS_OK);
        }
        for (i = 0; i < 64 * 48; i++) {
            ones += p.cnt[i] == 1;
            twos += p.cnt[i] == 2;
            more += p.cnt[i] > 2;
        }
        printf("  cut sphere: %d pixels see 1 layer (inside the cut), %d see 2, %d more\n", ones, twos, more);
        CHECK(ones > 200 && twos > 200 && more == 0);
        memset(&st, 0, sizeof st);
        compare_view(&m, &v, NULL, &st);
        report("cut sphere", &st);
        planes_free(&p);
        hfvis_mesh_free(NULL, &m);
    }
}

/* Orthographic views: linear depth is affine in the pixel position on a plane, and window depth
 * is (lin - n)/(f - n) exactly as hfvis_eye_z_to_depth says. */
TEST(orthographic_depth_linear)
{
    const double eye[3] = {0.3, -0.2, 5.0}, tgt[3] = {0.3, -0.2, 0.0}, up[3] = {0.0, 1.0, 0.0};
    float xyz[12] = {-3, -3, 0, 3, -3, 1.5f, 3, 3, 2.5f, -3, 3, 1};
    uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    hfvis_mesh m;
    hfvis_view v;
    planes p;
    int x, y, W = 40, H = 30, bad = 0, badz = 0;
    double maxd = 0.0;
    m.xyz = xyz, m.vertex_count = 4, m.indices = idx, m.triangle_count = 2;
    xyz[11] = 1.0f; /* make the quad planar: z = 1 + 0.25 x + ... */
    {   /* plane z = 1 + 0.25 x + 0.25 y through the four corners */
        int k;
        for (k = 0; k < 4; k++) xyz[3 * k + 2] = (float)(1.0 + 0.25 * (double)xyz[3 * k] + 0.25 * (double)xyz[3 * k + 1]);
    }
    CHECK_EQ_STATUS(hfvis_view_orthographic(&v, eye, tgt, up, 2.0, W, H, 0.5, 10.0), HFVIS_OK);
    planes_alloc(&p, W, H);
    {
        hfvis_raster_outputs o = planes_out(&p);
        CHECK_EQ_STATUS(hfvis_rasterize(&m, &v, NULL, &o), HFVIS_OK);
    }
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++) {
            size_t i = (size_t)y * W + (size_t)x;
            /* eye at z = 5 looking down: linear depth = 5 - z(x_world, y_world) */
            double xw = 0.3 + (2.0 * (x + 0.5) / W - 1.0) * 2.0 * W / H;
            double yw = -0.2 + (1.0 - 2.0 * (y + 0.5) / H) * 2.0;
            double want = 5.0 - (1.0 + 0.25 * xw + 0.25 * yw);
            if (!(fabs((double)p.lin[i] - want) <= 1e-6 * want)) bad++;
            if (!(fabs((double)p.zw[i] - hfvis_eye_z_to_depth(-(double)p.lin[i], 0.5, 10.0, 1)) <= TOL_ZW_ABS))
                badz++;
            if (x >= 1 && x + 1 < W) {
                double d2 = (double)p.lin[i - 1] - 2.0 * (double)p.lin[i] + (double)p.lin[i + 1];
                if (fabs(d2) > maxd) maxd = fabs(d2);
            }
            if (y >= 1 && y + 1 < H) {
                double d2 = (double)p.lin[i - W] - 2.0 * (double)p.lin[i] + (double)p.lin[i + W];
                if (fabs(d2) > maxd) maxd = fabs(d2);
            }
        }
    CHECK(bad == 0);
    CHECK(badz == 0);
    CHECK(maxd <= TOL_ORTHO_SECOND_DIFF);
    printf("  ortho plane: max |second difference| of linear depth %.3g\n", maxd);
    planes_free(&p);
}

/* Perspective: linear depth and window depth are the two sides of hfvis_depth_to_eye_z. */
TEST(window_vs_linear_depth)
{
    const double c0[3] = {0.0, 0.0, 0.0};
    hfvis_mesh m;
    int vi, bad = 0, covered = 0;
    double maxd = 0.0;
    memset(&m, 0, sizeof m);
    CHECK_EQ_STATUS(hfvis_mesh_torus(NULL, c0, 1.0, 0.4, 24, 12, &m), HFVIS_OK);
    rs_seed(5);
    for (vi = 0; vi < 6; vi++) {
        hfvis_view v;
        planes p;
        size_t i, n;
        random_view(&v, vi == 5, 2.0, 5.0, c0, 0.3);
        planes_alloc(&p, v.width, v.height);
        {
            hfvis_raster_outputs o = planes_out(&p);
            CHECK_EQ_STATUS(hfvis_rasterize(&m, &v, NULL, &o), HFVIS_OK);
        }
        n = (size_t)v.width * (size_t)v.height;
        for (i = 0; i < n; i++) {
            double ze, zw, d;
            if (p.id[i] == HFVIS_NO_TRIANGLE) continue;
            covered++;
            ze = hfvis_depth_to_eye_z((double)p.zw[i], v.near_plane, v.far_plane, v.orthographic);
            zw = hfvis_eye_z_to_depth(-(double)p.lin[i], v.near_plane, v.far_plane, v.orthographic);
            d = fabs(zw - (double)p.zw[i]);
            if (d > maxd) maxd = d;
            if (!(d <= TOL_ZW_FROM_LIN)) bad++;
            if (!(fabs(-ze - (double)p.lin[i]) <= 1e-3 * (double)p.lin[i])) bad++;
        }
        planes_free(&p);
    }
    CHECK(bad == 0 && covered > 1000);
    printf("  %d pixels: max |zw - eye_z_to_depth(linear)| %.3g\n", covered, maxd);
    hfvis_mesh_free(NULL, &m);
}

/* The far plane drops fragments beyond it; a triangle crossing it is cut at zw = 1. */
TEST(far_plane)
{
    const double eye[3] = {0.0, -5.0, 0.0}, tgt[3] = {0.0, 0.0, 0.0}, up[3] = {0.0, 0.0, 1.0};
    /* a floor quad from y = -4 to y = 40 at z = -1, seen with far = 10 */
    float xyz[12] = {-20, -4, -1, 20, -4, -1, 20, 40, -1, -20, 40, -1};
    uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    hfvis_mesh m;
    hfvis_view v;
    planes p;
    int x, y, W = 48, H = 32, beyond = 0, bad = 0, inside = 0;
    cmp_stats st;
    m.xyz = xyz, m.vertex_count = 4, m.indices = idx, m.triangle_count = 2;
    CHECK_EQ_STATUS(hfvis_view_perspective(&v, eye, tgt, up, 1.0, W, H, 0.1, 10.0), HFVIS_OK);
    planes_alloc(&p, W, H);
    {
        hfvis_raster_outputs o = planes_out(&p);
        CHECK_EQ_STATUS(hfvis_rasterize(&m, &v, NULL, &o), HFVIS_OK);
    }
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++) {
            size_t i = (size_t)y * W + (size_t)x;
            /* ray through the pixel centre meets z = -1 at view depth 1/(-y_ndc tan(fov/2)) */
            double yn = 1.0 - 2.0 * (y + 0.5) / H, depth = yn < 0.0 ? -1.0 / (yn * tan(0.5)) : HUGE_VAL;
            if (depth > 10.0 * (1.0 + 1e-9)) {
                beyond++;
                if (p.id[i] != HFVIS_NO_TRIANGLE || p.cnt[i] != 0) bad++;
            } else if (depth < 10.0 * (1.0 - 1e-9)) {
                inside++;
                if (p.id[i] == HFVIS_NO_TRIANGLE || !(fabs((double)p.lin[i] - depth) <= 1e-6 * depth)) bad++;
            }
        }
    CHECK(beyond > 0 && inside > 0 && bad == 0);
    memset(&st, 0, sizeof st);
    compare_view(&m, &v, NULL, &st);
    report("far cut", &st);
    planes_free(&p);
}

/* Facing, culling and the normal options on one triangle. */
TEST(facing_and_normals)
{
    float xyz[9] = {-1, -1, 0, 1, -1, 0, 0, 1, 0}; /* normal +z */
    uint32_t idx[3] = {0, 1, 2};
    const double tgt[3] = {0.0, 0.0, 0.0}, up[3] = {0.0, 1.0, 0.0};
    const double above[3] = {0.0, 0.0, 3.0}, below[3] = {0.0, 0.0, -3.0};
    hfvis_mesh m;
    hfvis_view va, vb;
    hfvis_raster_options o = hfvis_raster_options_default();
    float nrm[3 * 16 * 16], bary[2 * 16 * 16], lin[16 * 16];
    uint32_t id[16 * 16];
    hfvis_raster_outputs out;
    size_t c = 8 * 16 + 8;
    m.xyz = xyz, m.vertex_count = 3, m.indices = idx, m.triangle_count = 1;
    CHECK_EQ_STATUS(hfvis_view_perspective(&va, above, tgt, up, 1.2, 16, 16, 0.1, 10.0), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_view_perspective(&vb, below, tgt, up, 1.2, 16, 16, 0.1, 10.0), HFVIS_OK);
    memset(&out, 0, sizeof out);
    out.normal = nrm, out.triangle_id = id, out.barycentric = bary, out.linear_depth = lin;
    CHECK_EQ_STATUS(hfvis_rasterize(&m, &va, &o, &out), HFVIS_OK); /* front from above */
    CHECK(id[c] == 0 && nrm[3 * c] == 0.0f && nrm[3 * c + 1] == 0.0f && nrm[3 * c + 2] == 1.0f);
    CHECK_NEAR(lin[c], 3.0, 1e-6, 0.0);
    /* pixel (8, 8) centre is NDC (1/16, -1/16): the point (1/16, -1/16)*3*tan(0.6) on the plane */
    {
        double s = 3.0 * tan(0.6), px = s / 16.0, py = -s / 16.0;
        /* barycentrics of (px, py) in (-1,-1), (1,-1), (0,1): b2 = (py+1)/2, b1 = (px+1 - b2)/2 */
        double b2 = (py + 1.0) / 2.0, b1 = (px + 1.0 - b2) / 2.0;
        CHECK_NEAR(bary[2 * c], b1, 1e-6, 0.0);
        CHECK_NEAR(bary[2 * c + 1], b2, 1e-6, 0.0);
    }
    o.cull = HFVIS_CULL_FRONT;
    CHECK_EQ_STATUS(hfvis_rasterize(&m, &va, &o, &out), HFVIS_OK);
    CHECK(id[c] == HFVIS_NO_TRIANGLE && nrm[3 * c + 2] == 0.0f);
    o.cull = HFVIS_CULL_BACK;
    CHECK_EQ_STATUS(hfvis_rasterize(&m, &va, &o, &out), HFVIS_OK);
    CHECK(id[c] == 0);
    CHECK_EQ_STATUS(hfvis_rasterize(&m, &vb, &o, &out), HFVIS_OK); /* back from below */
    CHECK(id[c] == HFVIS_NO_TRIANGLE);
    o.cull = HFVIS_CULL_NONE;
    CHECK_EQ_STATUS(hfvis_rasterize(&m, &vb, &o, &out), HFVIS_OK);
    CHECK(id[c] == 0 && nrm[3 * c + 2] == 1.0f); /* as-is */
    o.normal_toward_viewer = 1;
    CHECK_EQ_STATUS(hfvis_rasterize(&m, &vb, &o, &out), HFVIS_OK);
    CHECK(nrm[3 * c + 2] == -1.0f);
    CHECK_EQ_STATUS(hfvis_rasterize(&m, &va, &o, &out), HFVIS_OK);
    CHECK(nrm[3 * c + 2] == 1.0f);
    o.normal_space = HFVIS_NORMAL_EYE; /* facing the viewer in eye space: +z */
    o.normal_toward_viewer = 0;
    CHECK_EQ_STATUS(hfvis_rasterize(&m, &va, &o, &out), HFVIS_OK);
    CHECK(nrm[3 * c + 2] == 1.0f && nrm[3 * c] == 0.0f);
    CHECK_EQ_STATUS(hfvis_rasterize(&m, &vb, &o, &out), HFVIS_OK);
    CHECK(nrm[3 * c + 2] == -1.0f);
    o.normal_toward_viewer = 1;
    CHECK_EQ_STATUS(hfvis_rasterize(&m, &vb, &o, &out), HFVIS_OK);
    CHECK(nrm[3 * c + 2] == 1.0f);
}

/* A huge quad (vertices 1e6 beyond the image) goes through the guard-band clip: still exactly
 * one fragment per pixel, and the oracle agrees. Degenerate triangles are never drawn. */
TEST(guard_band_and_degenerate)
{
    float xyz[18] = {-1e6f, -1e6f, 0, 1e6f, -1e6f, 0, 1e6f, 1e6f, 0, -1e6f, 1e6f, 0,
                     0, 0, 1, 0.5f, 0.5f, 1}; /* plus a degenerate triangle (4, 5, 5) */
    uint32_t idx[9] = {0, 1, 2, 0, 2, 3, 4, 5, 5};
    const double eye[3] = {0.3, -2.0, 4.0}, tgt[3] = {0.0, 0.0, 0.0}, up[3] = {0.0, 0.0, 1.0};
    hfvis_mesh m;
    hfvis_view v;
    planes p;
    size_t i;
    int bad = 0;
    cmp_stats st;
    m.xyz = xyz, m.vertex_count = 6, m.indices = idx, m.triangle_count = 3;
    CHECK_EQ_STATUS(hfvis_view_perspective(&v, eye, tgt, up, 1.0, 50, 40, 0.1, 1e7), HFVIS_OK);
    planes_alloc(&p, 50, 40);
    {
        hfvis_raster_outputs o = planes_out(&p);
        CHECK_EQ_STATUS(hfvis_rasterize(&m, &v, NULL, &o), HFVIS_OK);
    }
    for (i = 0; i < 50 * 40; i++)
        if (p.cnt[i] != 1 || p.id[i] > 1) bad++;
    CHECK(bad == 0);
    memset(&st, 0, sizeof st);
    compare_view(&m, &v, NULL, &st);
    report("guard band", &st);
    planes_free(&p);
}

/* Each plane alone equals the same plane of an all-planes run (bit for bit), runs repeat bit for
 * bit, and coplanar duplicate triangles resolve to the lower id (equal zw: LESS keeps the
 * first drawn) in both the rasterizer and the oracle. */
TEST(planes_independent_and_ties)
{
    const double c0[3] = {0.0, 0.0, 0.0}, eye[3] = {1.0, -2.5, 1.5}, up[3] = {0.0, 0.0, 1.0};
    hfvis_mesh m, d;
    hfvis_view v;
    planes a, b;
    hfvis_raster_outputs oa, ob;
    size_t n, k;
    float *xyz;
    uint32_t *idx;
    int pl;
    memset(&m, 0, sizeof m);
    CHECK_EQ_STATUS(hfvis_mesh_torus(NULL, c0, 1.0, 0.4, 16, 10, &m), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_view_perspective(&v, eye, c0, up, 1.0, 40, 30, 0.1, 10.0), HFVIS_OK);
    n = 40 * 30;
    planes_alloc(&a, 40, 30);
    planes_alloc(&b, 40, 30);
    oa = planes_out(&a);
    CHECK_EQ_STATUS(hfvis_rasterize(&m, &v, NULL, &oa), HFVIS_OK);
    for (pl = 0; pl < 7; pl++) {
        memset(&ob, 0, sizeof ob);
        if (pl == 0) ob.linear_depth = b.lin;
        if (pl == 1) ob.window_depth = b.zw;
        if (pl == 2) ob.normal = b.nrm;
        if (pl == 3) ob.triangle_id = b.id;
        if (pl == 4) ob.barycentric = b.bary;
        if (pl == 5) ob.coverage_count = b.cnt;
        if (pl == 6) ob = planes_out(&b);
        CHECK_EQ_STATUS(hfvis_rasterize(&m, &v, NULL, &ob), HFVIS_OK);
        if (pl == 0 || pl == 6) CHECK(memcmp(a.lin, b.lin, n * 4) == 0);
        if (pl == 1 || pl == 6) CHECK(memcmp(a.zw, b.zw, n * 4) == 0);
        if (pl == 2 || pl == 6) CHECK(memcmp(a.nrm, b.nrm, 3 * n * 4) == 0);
        if (pl == 3 || pl == 6) CHECK(memcmp(a.id, b.id, n * 4) == 0);
        if (pl == 4 || pl == 6) CHECK(memcmp(a.bary, b.bary, 2 * n * 4) == 0);
        if (pl == 5 || pl == 6) CHECK(memcmp(a.cnt, b.cnt, n * 4) == 0);
    }
    /* the mesh twice (second copy's triangles have ids T..2T-1, same vertices): ids < T win */
    xyz = (float *)malloc(m.vertex_count * 3 * sizeof(float));
    idx = (uint32_t *)malloc(m.triangle_count * 6 * sizeof(uint32_t));
    memcpy(xyz, m.xyz, m.vertex_count * 3 * sizeof(float));
    memcpy(idx, m.indices, m.triangle_count * 3 * sizeof(uint32_t));
    memcpy(idx + 3 * m.triangle_count, m.indices, m.triangle_count * 3 * sizeof(uint32_t));
    d.xyz = xyz, d.vertex_count = m.vertex_count, d.indices = idx, d.triangle_count = 2 * m.triangle_count;
    ob = planes_out(&b);
    CHECK_EQ_STATUS(hfvis_rasterize(&d, &v, NULL, &ob), HFVIS_OK);
    CHECK(memcmp(a.id, b.id, n * 4) == 0 && memcmp(a.lin, b.lin, n * 4) == 0);
    for (k = 0; k < n; k++) CHECK(b.cnt[k] == 2 * a.cnt[k]);
    CHECK_EQ_STATUS(hfvis_rasterize_reference(&d, &v, NULL, &ob), HFVIS_OK);
    for (k = 0; k < n; k++) CHECK(b.id[k] == HFVIS_NO_TRIANGLE || b.id[k] < (uint32_t)m.triangle_count);
    free(xyz), free(idx);
    planes_free(&a);
    planes_free(&b);
    hfvis_mesh_free(NULL, &m);
}

static int is_untouched(const float *f, size_t n)
{
    size_t i;
    for (i = 0; i < n; i++)
        if (f[i] != 7.0f) return 0;
    return 1;
}

TEST(bad_arguments)
{
    const double c0[3] = {0.0, 0.0, 0.0}, eye[3] = {0.0, -3.0, 0.5}, up[3] = {0.0, 0.0, 1.0};
    hfvis_mesh m, bad;
    hfvis_view v, vb;
    hfvis_raster_options o;
    hfvis_raster_outputs out, none;
    float lin[64];
    uint32_t idx3[3] = {0, 1, 5};
    int k, f;
    memset(&m, 0, sizeof m);
    CHECK_EQ_STATUS(hfvis_mesh_box(NULL, (const double[3]){-1, -1, -1}, (const double[3]){1, 1, 1}, &m),
                    HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_view_perspective(&v, eye, c0, up, 1.0, 8, 8, 0.1, 10.0), HFVIS_OK);
    memset(&out, 0, sizeof out);
    memset(&none, 0, sizeof none);
    out.linear_depth = lin;
    for (f = 0; f < 2; f++) {
        hfvis_status (*fn)(const hfvis_mesh *, const hfvis_view *, const hfvis_raster_options *,
                           const hfvis_raster_outputs *) = f ? hfvis_rasterize_reference : hfvis_rasterize;
        for (k = 0; k < 64; k++) lin[k] = 7.0f;
        CHECK_EQ_STATUS(fn(NULL, &v, NULL, &out), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(fn(&m, NULL, NULL, &out), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(fn(&m, &v, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
        bad = m, bad.indices = NULL;
        CHECK_EQ_STATUS(fn(&bad, &v, NULL, &out), HFVIS_ERR_INVALID_ARGUMENT);
        bad = m, bad.indices = idx3, bad.triangle_count = 1, bad.vertex_count = 5; /* index 5 */
        CHECK_EQ_STATUS(fn(&bad, &v, NULL, &out), HFVIS_ERR_INVALID_ARGUMENT);
        {
            float nanv[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
            uint32_t i3[3] = {0, 1, 2};
            nanv[4] = (float)NAN;
            bad.xyz = nanv, bad.vertex_count = 3, bad.indices = i3, bad.triangle_count = 1;
            CHECK_EQ_STATUS(fn(&bad, &v, NULL, &out), HFVIS_ERR_INVALID_ARGUMENT);
            bad.triangle_count = (size_t)HFVIS_NO_TRIANGLE; /* ids would collide: LIMIT, unread */
            if (sizeof(size_t) > 4) CHECK_EQ_STATUS(fn(&bad, &v, NULL, &out), HFVIS_ERR_LIMIT);
        }
        vb = v, vb.width = 0;
        CHECK_EQ_STATUS(fn(&m, &vb, NULL, &out), HFVIS_ERR_INVALID_ARGUMENT);
        vb = v, vb.height = -3;
        CHECK_EQ_STATUS(fn(&m, &vb, NULL, &out), HFVIS_ERR_INVALID_ARGUMENT);
        vb = v, vb.width = HFVIS_RASTER_MAX_SIZE + 1;
        CHECK_EQ_STATUS(fn(&m, &vb, NULL, &out), HFVIS_ERR_LIMIT);
        vb = v, vb.height = INT_MAX;
        CHECK_EQ_STATUS(fn(&m, &vb, NULL, &out), HFVIS_ERR_LIMIT);
        vb = v, vb.proj[5] = HUGE_VAL;
        CHECK_EQ_STATUS(fn(&m, &vb, NULL, &out), HFVIS_ERR_INVALID_ARGUMENT);
        vb = v, vb.view[12] = (double)NAN;
        CHECK_EQ_STATUS(fn(&m, &vb, NULL, &out), HFVIS_ERR_INVALID_ARGUMENT);
        vb = v, vb.near_plane = 0.0;
        CHECK_EQ_STATUS(fn(&m, &vb, NULL, &out), HFVIS_ERR_INVALID_ARGUMENT);
        vb = v, vb.far_plane = 0.05;
        CHECK_EQ_STATUS(fn(&m, &vb, NULL, &out), HFVIS_ERR_INVALID_ARGUMENT);
        vb = v, vb.far_plane = (double)NAN;
        CHECK_EQ_STATUS(fn(&m, &vb, NULL, &out), HFVIS_ERR_INVALID_ARGUMENT);
        o = hfvis_raster_options_default(), o.cull = (hfvis_cull_mode)3;
        CHECK_EQ_STATUS(fn(&m, &v, &o, &out), HFVIS_ERR_INVALID_ARGUMENT);
        o = hfvis_raster_options_default(), o.normal_space = (hfvis_normal_space)2;
        CHECK_EQ_STATUS(fn(&m, &v, &o, &out), HFVIS_ERR_INVALID_ARGUMENT);
        o = hfvis_raster_options_default(), o.normal_toward_viewer = 2;
        CHECK_EQ_STATUS(fn(&m, &v, &o, &out), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK(is_untouched(lin, 64));
        CHECK_EQ_STATUS(fn(&m, &v, NULL, &none), HFVIS_OK); /* nothing requested */
        CHECK_EQ_STATUS(fn(&m, &v, NULL, &out), HFVIS_OK);
        CHECK(!is_untouched(lin, 64));
    }
    /* the oracle needs an invertible proj*view */
    vb = v;
    memset(vb.proj, 0, sizeof vb.proj);
    for (k = 0; k < 64; k++) lin[k] = 7.0f;
    CHECK_EQ_STATUS(hfvis_rasterize_reference(&m, &vb, NULL, &out), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(is_untouched(lin, 64));
    /* an empty mesh clears the planes */
    bad = m, bad.triangle_count = 0;
    CHECK_EQ_STATUS(hfvis_rasterize(&bad, &v, NULL, &out), HFVIS_OK);
    CHECK(isinf(lin[0]) && isinf(lin[63]));
    hfvis_mesh_free(NULL, &m);
}

TEST(alloc_failures)
{
    const double c0[3] = {0.0, 0.0, 0.0}, eye[3] = {0.5, -3.0, 1.0}, up[3] = {0.0, 0.0, 1.0};
    hfvis_mesh m;
    hfvis_view v;
    hfvis_allocator al;
    test_counting cnt;
    hfvis_raster_options o = hfvis_raster_options_default();
    planes p;
    hfvis_raster_outputs out;
    int k, n_allocs;
    memset(&m, 0, sizeof m);
    CHECK_EQ_STATUS(hfvis_mesh_torus(NULL, c0, 1.0, 0.4, 12, 8, &m), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_view_perspective(&v, eye, c0, up, 1.0, 24, 16, 0.1, 10.0), HFVIS_OK);
    planes_alloc(&p, 24, 16);
    out = planes_out(&p);
    al.alloc = test_count_alloc, al.free = test_count_free, al.user = &cnt;
    o.alloc = &al;
    memset(&cnt, 0, sizeof cnt);
    CHECK_EQ_STATUS(hfvis_rasterize(&m, &v, &o, &out), HFVIS_OK);
    n_allocs = cnt.allocs;
    CHECK(n_allocs == 1 && cnt.frees == 1);
    for (k = 1; k <= n_allocs; k++) {
        size_t i;
        int untouched = 1;
        for (i = 0; i < 24 * 16; i++) p.lin[i] = 7.0f, p.id[i] = 7u;
        memset(&cnt, 0, sizeof cnt);
        cnt.fail_at = k;
        CHECK_EQ_STATUS(hfvis_rasterize(&m, &v, &o, &out), HFVIS_ERR_OUT_OF_MEMORY);
        CHECK(cnt.allocs - 1 == cnt.frees);
        for (i = 0; i < 24 * 16; i++)
            if (p.lin[i] != 7.0f || p.id[i] != 7u) untouched = 0;
        CHECK(untouched);
    }
    memset(&cnt, 0, sizeof cnt); /* the oracle allocates nothing */
    CHECK_EQ_STATUS(hfvis_rasterize_reference(&m, &v, &o, &out), HFVIS_OK);
    CHECK(cnt.allocs == 0);
    planes_free(&p);
    hfvis_mesh_free(NULL, &m);
}

int main(int argc, char **argv)
{
    TEST_INIT(argc, argv);
    RUN(options_default);
    RUN(top_left_rule);
    RUN(shared_edges_once);
    RUN(watertight_counts);
    RUN(raster_vs_reference);
    RUN(near_plane_clipping);
    RUN(orthographic_depth_linear);
    RUN(window_vs_linear_depth);
    RUN(far_plane);
    RUN(facing_and_normals);
    RUN(guard_band_and_degenerate);
    RUN(planes_independent_and_ties);
    RUN(bad_arguments);
    RUN(alloc_failures);
    return TEST_DONE();
}
