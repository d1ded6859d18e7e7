/* test_ssao.c - tests of ssao.c: camera and depth helpers, falloffs, directions and the line
 * lattice, P3 line-sweep AO against its brute-force oracle and the closed forms of spec
 * screenspace-p3-p4 §6, HBAO, the screen-space ray-traced reference, bad arguments and
 * allocation failure at every site. */
#include "hfvis.h"
#include "test.h"

#include <float.h>
#include <stdint.h>
#include <stdlib.h>

#define PI 3.14159265358979323846

/* ---- tolerances (each with its reason) ---- */
/* double round trips through one division/multiplication chain */
#define TOL_ROUNDTRIP 1e-12
/* a float output of a double computation: half an ulp of values of order 1 */
#define TOL_FLOAT 2e-7
/* normals from float depths of a plane: float depth rounding (2^-24 relative) over a
 * one-pixel difference of a depth ~ 10 at focal length ~ 100 amplifies to ~1e-5 */
#define TOL_NORMAL 5e-5
/* lattice sample positions: the clipping tolerance of the lattice (1e-7 px) plus rounding */
#define TOL_LATTICE_PX 2e-7

/* ---- small deterministic PRNG (xorshift64*) ---- */
static uint64_t rng_state = 1;
static void rng_seed(uint64_t s) { rng_state = s * 2654435761u + 0x9E3779B97F4A7C15ull; if (!rng_state) rng_state = 1; }
static double rng_unit(void)
{
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (double)((rng_state * 2685821657736338717ull) >> 11) * (1.0 / 9007199254740992.0);
}

/* ---- counting allocator: fail_at = the 1-based allocation that fails (0 = never) ---- */
typedef struct counting {
    int allocs, frees, live, fail_at;
} counting;
static void *cnt_alloc(void *user, size_t n)
{
    counting *c = (counting *)user;
    void *p;
    c->allocs++;
    if (c->fail_at != 0 && c->allocs == c->fail_at) return NULL;
    p = malloc(n);
    if (p) c->live++;
    return p;
}
static void cnt_free(void *user, void *p)
{
    counting *c = (counting *)user;
    if (!p) return;
    c->frees++;
    c->live--;
    free(p);
}

/* ========================================================================================== */
/* 1. Camera and depth                                                                        */
/* ========================================================================================== */

TEST(camera_check)
{
    hfvis_camera c, b;
    CHECK_EQ_STATUS(hfvis_camera_perspective(&c, 64, 48, 4, 3, 1.0), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_camera_check(&c), HFVIS_OK);
    CHECK_NEAR(c.fx, 0.5 * 42.0 / tan(0.5), 1e-12, 1e-15);
    CHECK(c.fx == c.fy && c.cx == 32.0 && c.cy == 24.0 && c.stride == 0);
    CHECK_EQ_STATUS(hfvis_camera_check(NULL), HFVIS_ERR_INVALID_ARGUMENT);
    b = c; b.width = 0; CHECK_EQ_STATUS(hfvis_camera_check(&b), HFVIS_ERR_INVALID_ARGUMENT);
    b = c; b.height = -1; CHECK_EQ_STATUS(hfvis_camera_check(&b), HFVIS_ERR_INVALID_ARGUMENT);
    b = c; b.stride = 63; CHECK_EQ_STATUS(hfvis_camera_check(&b), HFVIS_ERR_INVALID_ARGUMENT);
    b = c; b.stride = -64; CHECK_EQ_STATUS(hfvis_camera_check(&b), HFVIS_ERR_INVALID_ARGUMENT);
    b = c; b.stride = 80; CHECK_EQ_STATUS(hfvis_camera_check(&b), HFVIS_OK);
    b = c; b.guard_x = 32; CHECK_EQ_STATUS(hfvis_camera_check(&b), HFVIS_ERR_INVALID_ARGUMENT);
    b = c; b.guard_x = 31; CHECK_EQ_STATUS(hfvis_camera_check(&b), HFVIS_OK);
    b = c; b.guard_y = -1; CHECK_EQ_STATUS(hfvis_camera_check(&b), HFVIS_ERR_INVALID_ARGUMENT);
    b = c; b.projection = (hfvis_camera_projection)0; CHECK_EQ_STATUS(hfvis_camera_check(&b), HFVIS_ERR_INVALID_ARGUMENT);
    b = c; b.projection = (hfvis_camera_projection)3; CHECK_EQ_STATUS(hfvis_camera_check(&b), HFVIS_ERR_INVALID_ARGUMENT);
    b = c; b.fx = 0.0; CHECK_EQ_STATUS(hfvis_camera_check(&b), HFVIS_ERR_INVALID_ARGUMENT);
    b = c; b.fy = (double)NAN; CHECK_EQ_STATUS(hfvis_camera_check(&b), HFVIS_ERR_INVALID_ARGUMENT);
    b = c; b.cx = (double)INFINITY; CHECK_EQ_STATUS(hfvis_camera_check(&b), HFVIS_ERR_INVALID_ARGUMENT);
    b = c; b.far_depth = -1.0; CHECK_EQ_STATUS(hfvis_camera_check(&b), HFVIS_ERR_INVALID_ARGUMENT);
    b = c; b.far_depth = (double)NAN; CHECK_EQ_STATUS(hfvis_camera_check(&b), HFVIS_ERR_INVALID_ARGUMENT);
    b = c; b.far_depth = (double)INFINITY; CHECK_EQ_STATUS(hfvis_camera_check(&b), HFVIS_OK);
    b = c; b.width = HFVIS_SSAO_MAX_SIZE + 1; CHECK_EQ_STATUS(hfvis_camera_check(&b), HFVIS_ERR_LIMIT);
    /* ortho reads only its scales */
    CHECK_EQ_STATUS(hfvis_camera_orthographic(&c, 10, 1, 0, 0, 0.5), HFVIS_OK);
    CHECK(c.scale_x == 0.5 && c.scale_y == 0.5 && c.projection == HFVIS_CAMERA_ORTHOGRAPHIC);
    b = c; b.scale_y = 0.0; CHECK_EQ_STATUS(hfvis_camera_check(&b), HFVIS_ERR_INVALID_ARGUMENT);
    /* constructors: bad arguments leave the output untouched */
    memset(&b, 0x5a, sizeof b);
    c = b;
    CHECK_EQ_STATUS(hfvis_camera_perspective(&c, 64, 48, 4, 3, 0.0), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_camera_perspective(&c, 64, 48, 4, 3, PI), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_camera_perspective(&c, 64, 48, 32, 3, 1.0), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_camera_perspective(NULL, 64, 48, 4, 3, 1.0), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_camera_orthographic(&c, 64, 48, 4, 3, -1.0), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_camera_orthographic(&c, 0, 48, 4, 3, 1.0), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(memcmp(&b, &c, sizeof b) == 0);
}

TEST(camera_project_roundtrip)
{
    hfvis_camera c;
    int k, m;
    double p[3], q[3], u, v, d;
    for (m = 0; m < 2; m++) {
        if (m == 0) {
            CHECK_EQ_STATUS(hfvis_camera_perspective(&c, 80, 60, 8, 6, 1.1), HFVIS_OK);
            c.fy = 1.3 * c.fx; /* non-square pixels */
            c.cx = 37.25;      /* off-centre */
        } else {
            CHECK_EQ_STATUS(hfvis_camera_orthographic(&c, 80, 60, 8, 6, 0.25), HFVIS_OK);
            c.scale_y = 0.5;
        }
        rng_seed(7 + (uint64_t)m);
        for (k = 0; k < 50; k++) {
            double uu = 80.0 * rng_unit(), vv = 60.0 * rng_unit(), z = 1.0 + 20.0 * rng_unit();
            CHECK_EQ_STATUS(hfvis_camera_unproject(&c, uu, vv, z, p), HFVIS_OK);
            CHECK(p[2] == -z);
            CHECK_EQ_STATUS(hfvis_camera_project(&c, p, &u, &v, &d), HFVIS_OK);
            CHECK_NEAR(u, uu, TOL_ROUNDTRIP, TOL_ROUNDTRIP);
            CHECK_NEAR(v, vv, TOL_ROUNDTRIP, TOL_ROUNDTRIP);
            CHECK_NEAR(d, z, 0.0, TOL_ROUNDTRIP);
        }
        /* orientation: +X right, +Y up */
        CHECK_EQ_STATUS(hfvis_camera_unproject(&c, c.cx + 1.0, c.cy - 1.0, 5.0, q), HFVIS_OK);
        CHECK(q[0] > 0.0 && q[1] > 0.0 && q[2] == -5.0);
    }
    CHECK_EQ_STATUS(hfvis_camera_unproject(&c, (double)NAN, 1.0, 1.0, p), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_camera_unproject(&c, 1.0, 1.0, 1.0, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_camera_unproject(NULL, 1.0, 1.0, 1.0, p), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_camera_perspective(&c, 80, 60, 8, 6, 1.1), HFVIS_OK);
    p[0] = 0.0; p[1] = 0.0; p[2] = 1.0;
    CHECK_EQ_STATUS(hfvis_camera_project(&c, p, &u, &v, &d), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_camera_project(&c, NULL, &u, &v, &d), HFVIS_ERR_INVALID_ARGUMENT);
}

TEST(camera_from_view)
{
    hfvis_view view;
    hfvis_camera c;
    double eye[3] = {1.0, 2.0, 3.0}, tgt[3] = {0.5, 0.0, -4.0}, up[3] = {0.0, 1.0, 0.0};
    int m, k;
    for (m = 0; m < 2; m++) {
        if (m == 0)
            CHECK_EQ_STATUS(hfvis_view_perspective(&view, eye, tgt, up, 0.9, 96, 54, 0.1, 50.0), HFVIS_OK);
        else
            CHECK_EQ_STATUS(hfvis_view_orthographic(&view, eye, tgt, up, 3.0, 96, 54, 0.1, 50.0), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_camera_from_view(&c, &view, 8, 4), HFVIS_OK);
        CHECK(c.far_depth == 50.0 && c.guard_x == 8 && c.guard_y == 4);
        /* a world point through the GL matrices lands where the camera projects its eye point */
        rng_seed(11 + (uint64_t)m);
        for (k = 0; k < 20; k++) {
            double w[4], e[4], clip[4], u, v, d, p[3];
            int i;
            w[0] = tgt[0] + 2.0 * rng_unit() - 1.0;
            w[1] = tgt[1] + 2.0 * rng_unit() - 1.0;
            w[2] = tgt[2] + 2.0 * rng_unit() - 1.0;
            w[3] = 1.0;
            for (i = 0; i < 4; i++)
                e[i] = view.view[i] * w[0] + view.view[4 + i] * w[1] + view.view[8 + i] * w[2] + view.view[12 + i];
            for (i = 0; i < 4; i++)
                clip[i] = view.proj[i] * e[0] + view.proj[4 + i] * e[1] + view.proj[8 + i] * e[2] + view.proj[12 + i] * e[3];
            p[0] = e[0]; p[1] = e[1]; p[2] = e[2];
            CHECK_EQ_STATUS(hfvis_camera_project(&c, p, &u, &v, &d), HFVIS_OK);
            CHECK_NEAR(u, 0.5 * 96.0 * (clip[0] / clip[3] + 1.0), 1e-9, 0.0);
            CHECK_NEAR(v, 0.5 * 54.0 * (1.0 - clip[1] / clip[3]), 1e-9, 0.0);
            CHECK_NEAR(d, -e[2], 1e-12, 0.0);
        }
    }
    view.proj[4] = 0.1; /* shear: not a camera */
    CHECK_EQ_STATUS(hfvis_camera_from_view(&c, &view, 8, 4), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_camera_from_view(&c, NULL, 8, 4), HFVIS_ERR_INVALID_ARGUMENT);
}

TEST(depth_linearize)
{
    const double n = 0.25, f = 40.0;
    int e, ortho, k;
    for (e = HFVIS_DEPTH_GL; e <= HFVIS_DEPTH_REVERSED_INFINITE; e++)
        for (ortho = 0; ortho < 2; ortho++) {
            int inf = e == HFVIS_DEPTH_INFINITE_FAR || e == HFVIS_DEPTH_REVERSED_INFINITE;
            if (inf && ortho) {
                CHECK(isnan(hfvis_depth_linear(0.5, (hfvis_depth_encoding)e, ortho, n, f)));
                continue;
            }
            for (k = 0; k <= 20; k++) {
                double z = n + (f - n) * (double)k / 20.0, d, z2;
                d = hfvis_depth_hardware(z, (hfvis_depth_encoding)e, ortho, n, f);
                z2 = hfvis_depth_linear(d, (hfvis_depth_encoding)e, ortho, n, f);
                CHECK_NEAR(z2, z, 1e-12, 1e-12);
            }
            /* near plane and range */
            CHECK_NEAR(hfvis_depth_linear(e == HFVIS_DEPTH_GL_NDC ? -1.0 : (e == HFVIS_DEPTH_REVERSED_Z || e == HFVIS_DEPTH_REVERSED_INFINITE ? 1.0 : 0.0),
                                          (hfvis_depth_encoding)e, ortho, n, f), n, 1e-15, 1e-14);
            CHECK(hfvis_depth_linear(1.5, (hfvis_depth_encoding)e, ortho, n, f) == (double)INFINITY);
            CHECK(hfvis_depth_linear(-1.5, (hfvis_depth_encoding)e, ortho, n, f) == (double)INFINITY);
            CHECK(hfvis_depth_linear((double)NAN, (hfvis_depth_encoding)e, ortho, n, f) == (double)INFINITY);
        }
    /* GL window depth is voxel.c's hfvis_depth_to_eye_z */
    for (k = 0; k <= 10; k++) {
        double d = (double)k / 10.0;
        CHECK_NEAR(hfvis_depth_linear(d, HFVIS_DEPTH_GL, 0, n, f), -hfvis_depth_to_eye_z(d, n, f, 0), 0.0, 1e-14);
        CHECK_NEAR(hfvis_depth_linear(d, HFVIS_DEPTH_GL, 1, n, f), -hfvis_depth_to_eye_z(d, n, f, 1), 0.0, 1e-14);
        CHECK_NEAR(hfvis_depth_linear(2.0 * d - 1.0, HFVIS_DEPTH_GL_NDC, 0, n, f), -hfvis_depth_to_eye_z(d, n, f, 0), 0.0, 1e-14);
    }
    /* the far plane of the finite encodings is f; infinite far planes are background */
    CHECK_NEAR(hfvis_depth_linear(1.0, HFVIS_DEPTH_D3D, 0, n, f), f, 0.0, 1e-14);
    CHECK(hfvis_depth_linear(1.0, HFVIS_DEPTH_INFINITE_FAR, 0, n, f) == (double)INFINITY);
    CHECK(hfvis_depth_linear(0.0, HFVIS_DEPTH_REVERSED_INFINITE, 0, n, f) == (double)INFINITY);
    CHECK_NEAR(hfvis_depth_linear(0.5, HFVIS_DEPTH_REVERSED_INFINITE, 0, n, f), 2.0 * n, 0.0, 1e-15);
    CHECK_NEAR(hfvis_depth_linear(0.5, HFVIS_DEPTH_INFINITE_FAR, 0, n, f), 2.0 * n, 0.0, 1e-15);
    /* invalid parameters */
    CHECK(isnan(hfvis_depth_linear(0.5, (hfvis_depth_encoding)0, 0, n, f)));
    CHECK(isnan(hfvis_depth_linear(0.5, (hfvis_depth_encoding)7, 0, n, f)));
    CHECK(isnan(hfvis_depth_linear(0.5, HFVIS_DEPTH_GL, 2, n, f)));
    CHECK(isnan(hfvis_depth_linear(0.5, HFVIS_DEPTH_GL, 0, f, n)));
    CHECK(isnan(hfvis_depth_linear(0.5, HFVIS_DEPTH_GL, 0, 0.0, f)));
    CHECK(!isnan(hfvis_depth_linear(0.5, HFVIS_DEPTH_GL, 1, 0.0, f)));
    CHECK(isnan(hfvis_depth_linear(0.5, HFVIS_DEPTH_INFINITE_FAR, 0, 0.0, f)));
    CHECK(isnan(hfvis_depth_hardware(-1.0, HFVIS_DEPTH_GL, 0, n, f)));
    {
        /* buffers, in place, strides, untouched on error */
        float in[3 * 5], out[3 * 6], keep[3 * 6];
        int i;
        for (i = 0; i < 15; i++) in[i] = (float)((double)i / 14.0);
        for (i = 0; i < 18; i++) out[i] = keep[i] = -7.0f;
        CHECK_EQ_STATUS(hfvis_depth_linearize(in, 4, 3, 5, HFVIS_DEPTH_REVERSED_Z, 0, n, f, out, 6), HFVIS_OK);
        for (i = 0; i < 12; i++) {
            int x = i % 4, y = i / 4;
            CHECK(out[y * 6 + x] == (float)hfvis_depth_linear((double)in[y * 5 + x], HFVIS_DEPTH_REVERSED_Z, 0, n, f));
        }
        CHECK(out[4] == -7.0f && out[5] == -7.0f);
        for (i = 0; i < 18; i++) out[i] = keep[i];
        CHECK_EQ_STATUS(hfvis_depth_linearize(in, 4, 3, 3, HFVIS_DEPTH_GL, 0, n, f, out, 6), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_depth_linearize(in, 4, 3, 5, HFVIS_DEPTH_GL, 0, n, f, out, 3), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_depth_linearize(in, 4, 3, 5, HFVIS_DEPTH_GL, 3, n, f, out, 6), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_depth_linearize(in, 4, 3, 5, HFVIS_DEPTH_GL, 0, n, n, out, 6), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_depth_linearize(NULL, 4, 3, 5, HFVIS_DEPTH_GL, 0, n, f, out, 6), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_depth_linearize(in, 0, 3, 5, HFVIS_DEPTH_GL, 0, n, f, out, 6), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK(memcmp(out, keep, sizeof out) == 0);
        for (i = 0; i < 15; i++) keep[i] = (float)hfvis_depth_linear((double)in[i], HFVIS_DEPTH_D3D, 0, n, f);
        CHECK_EQ_STATUS(hfvis_depth_linearize(in, 5, 3, 5, HFVIS_DEPTH_D3D, 0, n, f, in, 5), HFVIS_OK);
        CHECK(memcmp(in, keep, sizeof in) == 0);
    }
}

/* A tilted plane n.X = c in view space, rendered into a depth buffer through the camera. */
static void plane_depth(const hfvis_camera *c, const double nrm[3], double off, float *depth)
{
    int x, y;
    ptrdiff_t st = c->stride ? c->stride : c->width;
    for (y = 0; y < c->height; y++)
        for (x = 0; x < c->width; x++) {
            double r[3], z;
            hfvis_camera_unproject(c, x + 0.5, y + 0.5, 1.0, r);
            if (c->projection == HFVIS_CAMERA_PERSPECTIVE) {
                /* n.(z r) = off with r at depth 1 */
                z = off / (nrm[0] * r[0] + nrm[1] * r[1] + nrm[2] * r[2]);
            } else {
                /* n.(x, y, -z) = off */
                z = (nrm[0] * r[0] + nrm[1] * r[1] - off) / nrm[2];
            }
            depth[y * st + x] = (float)z;
        }
}

TEST(depth_normals)
{
    enum { W = 24, H = 18, ST = 26 };
    static float depth[ST * H], nrm[3 * ST * H];
    hfvis_camera c;
    double n0[3] = {0.3, -0.2, 0.9}, l;
    int m, x, y, bad = 0;
    l = sqrt(n0[0] * n0[0] + n0[1] * n0[1] + n0[2] * n0[2]);
    n0[0] /= l; n0[1] /= l; n0[2] /= l;
    for (m = 0; m < 2; m++) {
        if (m == 0) CHECK_EQ_STATUS(hfvis_camera_perspective(&c, W, H, 2, 2, 1.2), HFVIS_OK);
        else CHECK_EQ_STATUS(hfvis_camera_orthographic(&c, W, H, 2, 2, 0.1), HFVIS_OK);
        c.stride = ST;
        /* plane n0.X = -8 (in front of the camera, facing it) */
        plane_depth(&c, n0, m == 0 ? -8.0 : -8.0, depth);
        /* a background hole and a background column */
        depth[5 * ST + 7] = (float)INFINITY;
        for (y = 0; y < H; y++) depth[y * ST + 20] = (float)NAN;
        CHECK_EQ_STATUS(hfvis_depth_normals(&c, depth, nrm), HFVIS_OK);
        for (y = 0; y < H; y++)
            for (x = 0; x < W; x++) {
                const float *o = nrm + 3 * (y * ST + x);
                if (x == 20 || (x == 7 && y == 5)) {
                    if (o[0] != 0.0f || o[1] != 0.0f || o[2] != 0.0f) bad++;
                    continue;
                }
                if (fabs((double)o[0] - n0[0]) > TOL_NORMAL || fabs((double)o[1] - n0[1]) > TOL_NORMAL ||
                    fabs((double)o[2] - n0[2]) > TOL_NORMAL)
                    bad++;
            }
    }
    CHECK(bad == 0);
    /* a lone texel faces the eye */
    {
        float d1[3] = {(float)INFINITY, 4.0f, (float)INFINITY}, n1[9];
        CHECK_EQ_STATUS(hfvis_camera_perspective(&c, 3, 1, 0, 0, 1.0), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_depth_normals(&c, d1, n1), HFVIS_OK);
        CHECK(n1[3] == 0.0f && n1[4] == 0.0f && n1[5] == 1.0f);
        CHECK_EQ_STATUS(hfvis_depth_normals(&c, NULL, n1), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_depth_normals(&c, d1, NULL), HFVIS_ERR_INVALID_ARGUMENT);
        c.projection = (hfvis_camera_projection)9;
        CHECK_EQ_STATUS(hfvis_depth_normals(&c, d1, n1), HFVIS_ERR_INVALID_ARGUMENT);
    }
}

TEST(line_plane_isometry)
{
    hfvis_camera c;
    double e1[3], yh[3];
    int k, m;
    CHECK_EQ_STATUS(hfvis_camera_perspective(&c, 100, 80, 10, 8, 1.0), HFVIS_OK);
    c.fy = 1.2 * c.fx; /* non-square pixels: e1 must account for them */
    rng_seed(3);
    for (k = 0; k < 20; k++) {
        double u0 = 100.0 * rng_unit(), v0 = 80.0 * rng_unit(), a = 2.0 * PI * rng_unit();
        double du = cos(a), dv = sin(a), ref[3], P[4][3], q[4][2];
        CHECK_EQ_STATUS(hfvis_camera_unproject(&c, u0, v0, 3.0, ref), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_camera_line_plane(&c, ref, du, dv, e1, yh), HFVIS_OK);
        CHECK_NEAR(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2], 1.0, 1e-14, 0.0);
        CHECK_NEAR(e1[0] * yh[0] + e1[1] * yh[1] + e1[2] * yh[2], 0.0, 1e-14, 0.0);
        CHECK(yh[2] > 0.0);
        /* 4 points of the screen line at random depths: distances are preserved */
        for (m = 0; m < 4; m++) {
            double s = 40.0 * rng_unit() - 20.0;
            CHECK_EQ_STATUS(hfvis_camera_unproject(&c, u0 + s * du, v0 + s * dv, 1.0 + 30.0 * rng_unit(), P[m]), HFVIS_OK);
            q[m][0] = P[m][0] * e1[0] + P[m][1] * e1[1] + P[m][2] * e1[2];
            q[m][1] = P[m][0] * yh[0] + P[m][1] * yh[1] + P[m][2] * yh[2];
            CHECK_NEAR(q[m][1], P[m][2] / yh[2], 1e-12, 1e-12);
        }
        for (m = 1; m < 4; m++) {
            double d3 = sqrt((P[m][0] - P[0][0]) * (P[m][0] - P[0][0]) + (P[m][1] - P[0][1]) * (P[m][1] - P[0][1]) +
                             (P[m][2] - P[0][2]) * (P[m][2] - P[0][2]));
            double d2 = sqrt((q[m][0] - q[0][0]) * (q[m][0] - q[0][0]) + (q[m][1] - q[0][1]) * (q[m][1] - q[0][1]));
            CHECK_NEAR(d2, d3, 1e-11, 1e-12);
        }
        /* the line moves right on screen when du > 0: e1.x has du's sign */
        CHECK(e1[0] * du >= 0.0 && -e1[1] * dv >= 0.0);
    }
    {
        double ref[3] = {0.0, 0.0, 1.0};
        CHECK_EQ_STATUS(hfvis_camera_line_plane(&c, ref, 1.0, 0.0, e1, yh), HFVIS_ERR_INVALID_ARGUMENT);
        ref[2] = -1.0;
        CHECK_EQ_STATUS(hfvis_camera_line_plane(&c, ref, 0.0, 0.0, e1, yh), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_camera_line_plane(&c, ref, 1.0, 0.0, NULL, yh), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_camera_orthographic(&c, 10, 10, 0, 0, 1.0), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_camera_line_plane(&c, ref, 1.0, 1.0, e1, yh), HFVIS_OK);
        CHECK(yh[0] == 0.0 && yh[1] == 0.0 && yh[2] == 1.0);
        CHECK_NEAR(e1[0], sqrt(0.5), 1e-15, 0.0);
        CHECK_NEAR(e1[1], -sqrt(0.5), 1e-15, 0.0);
    }
}

/* ========================================================================================== */
/* 2. Falloff, directions, lattice                                                            */
/* ========================================================================================== */

static double custom_fall(void *user, double d)
{
    double s = *(const double *)user;
    return 2.0 - d / s; /* clamped to [0, 1] by the library */
}

TEST(falloff)
{
    hfvis_falloff f;
    double s = 2.0;
    memset(&f, 0, sizeof f);
    CHECK(hfvis_falloff_eval(&f, 123.0) == 1.0);
    CHECK(hfvis_falloff_eval(NULL, 5.0) == 1.0);
    CHECK(hfvis_falloff_support(&f) == (double)INFINITY);
    f.kind = HFVIS_FALLOFF_INV_QUADRATIC; f.param = 4.0;
    CHECK(hfvis_falloff_eval(&f, 0.0) == 1.0);
    CHECK_NEAR(hfvis_falloff_eval(&f, 2.0), 0.5, 0.0, 1e-15);
    f.kind = HFVIS_FALLOFF_HBAO; f.param = 3.0;
    CHECK(hfvis_falloff_eval(&f, 0.0) == 1.0);
    CHECK_NEAR(hfvis_falloff_support(&f), sqrt(10.0), 0.0, 1e-15);
    CHECK(hfvis_falloff_eval(&f, sqrt(10.0) * 1.0000001) == 0.0);
    CHECK_NEAR(hfvis_falloff_eval(&f, 1.0), 3.0 * 1.3 / 4.0 - 0.3, 0.0, 1e-15);
    f.hbao_c = 0.5;
    CHECK_NEAR(hfvis_falloff_support(&f), sqrt(6.0), 0.0, 1e-15);
    f.kind = HFVIS_FALLOFF_EXPONENTIAL; f.param = 2.0;
    CHECK_NEAR(hfvis_falloff_eval(&f, 2.0), exp(-1.0), 0.0, 1e-15);
    f.kind = HFVIS_FALLOFF_STEP; f.param = 2.0;
    CHECK(hfvis_falloff_eval(&f, 1.999) == 1.0 && hfvis_falloff_eval(&f, 2.0) == 0.0);
    CHECK(hfvis_falloff_support(&f) == 2.0);
    f.kind = HFVIS_FALLOFF_CUSTOM; f.fn = custom_fall; f.user = &s; f.param = 3.0;
    CHECK(hfvis_falloff_eval(&f, 1.0) == 1.0);
    CHECK_NEAR(hfvis_falloff_eval(&f, 2.5), 0.75, 0.0, 1e-15);
    CHECK(hfvis_falloff_eval(&f, 3.5) == 0.0); /* beyond the declared support: 0, fn not called */
    CHECK(hfvis_falloff_support(&f) == 3.0);
    f.param = 0.0;
    CHECK(hfvis_falloff_eval(&f, 10.0) == 0.0 && hfvis_falloff_support(&f) == (double)INFINITY);
    /* invalid */
    f.fn = NULL;
    CHECK_EQ_STATUS(hfvis_falloff_check(&f), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(isnan(hfvis_falloff_eval(&f, 1.0)) && isnan(hfvis_falloff_support(&f)));
    f.kind = HFVIS_FALLOFF_INV_QUADRATIC; f.param = 0.0;
    CHECK_EQ_STATUS(hfvis_falloff_check(&f), HFVIS_ERR_INVALID_ARGUMENT);
    f.param = (double)INFINITY;
    CHECK_EQ_STATUS(hfvis_falloff_check(&f), HFVIS_ERR_INVALID_ARGUMENT);
    f.kind = HFVIS_FALLOFF_HBAO; f.param = 1.0; f.hbao_c = -0.1;
    CHECK_EQ_STATUS(hfvis_falloff_check(&f), HFVIS_ERR_INVALID_ARGUMENT);
    f.kind = (hfvis_falloff_kind)7;
    CHECK_EQ_STATUS(hfvis_falloff_check(&f), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_falloff_check(NULL), HFVIS_ERR_INVALID_ARGUMENT);
}

TEST(directions)
{
    hfvis_ssao_direction d[32], keep[32];
    double sum, deg = 180.0 / PI;
    int k, n;
    CHECK_EQ_STATUS(hfvis_ssao_directions_uniform(4, 0.0, 1.5, 2.0, d), HFVIS_OK);
    CHECK(d[0].dx == 1.0 && d[0].dy == 0.0 && d[1].dx == 0.0 && d[1].dy == 1.0);
    CHECK(d[2].dx == -1.0 && d[2].dy == 0.0 && d[3].dx == 0.0 && d[3].dy == -1.0);
    CHECK(d[1].step_x == 0.0 && d[1].step_y == 1.5 && d[1].weight == 0.25 && d[1].spacing == 2.0);
    /* box patterns: P3 Table 2 mean step lengths and the axis rounding */
    {
        const double mean_paper[5] = {0.0, 1.41, 2.43, 3.56, 4.69}; /* P3 Table 2, 2 decimals */
        const int axis[5] = {0, 1, 2, 4, 5};
        for (n = 1; n <= 4; n++) {
            double mean = 0.0;
            int cnt = 0;
            CHECK_EQ_STATUS(hfvis_ssao_directions_box(n, 1, 1.0, d), HFVIS_OK);
            sum = 0.0;
            for (k = 0; k < 8 * n; k++) {
                sum += d[k].weight;
                CHECK(d[k].step_x == floor(d[k].step_x) && d[k].step_y == floor(d[k].step_y));
                CHECK_NEAR(d[k].dx * d[k].dx + d[k].dy * d[k].dy, 1.0, 1e-15, 0.0);
                if (d[k].step_x != 0.0 && d[k].step_y != 0.0) {
                    mean += d[k].step;
                    cnt++;
                } else {
                    CHECK(d[k].step == (double)axis[n]);
                }
                if (k > 0) CHECK(atan2(d[k].dy, d[k].dx) + (d[k].dy < 0.0 ? 2.0 * PI : 0.0) >
                                 atan2(d[k - 1].dy, d[k - 1].dx) + (d[k - 1].dy < 0.0 ? 2.0 * PI : 0.0));
            }
            CHECK_NEAR(sum, 1.0, 1e-14, 0.0);
            CHECK_NEAR(mean / cnt, mean_paper[n], 0.005, 0.0);
            CHECK(d[0].dx == 1.0 && d[0].dy == 0.0);
        }
        CHECK_EQ_STATUS(hfvis_ssao_directions_box(1, 1, 1.0, d), HFVIS_OK);
        for (k = 0; k < 8; k++) CHECK_NEAR(d[k].weight, 0.125, 1e-15, 0.0);
        /* n = 2: 26.57 deg axes, 22.5 deg (2,1)-type, 18.43 deg diagonals */
        CHECK_EQ_STATUS(hfvis_ssao_directions_box(2, 1, 1.0, d), HFVIS_OK);
        for (k = 0; k < 16; k++) {
            double w = d[k].weight * 360.0;
            if (d[k].step_x == 0.0 || d[k].step_y == 0.0) CHECK_NEAR(w, atan(0.5) * deg, 1e-9, 0.0);
            else if (fabs(d[k].step_x) == fabs(d[k].step_y)) CHECK_NEAR(w, (PI / 4.0 - atan(0.5)) * deg, 1e-9, 0.0);
            else CHECK_NEAR(w, 22.5, 1e-9, 0.0);
        }
        /* scale 2: non-axis vectors doubled, axis round(2 * 1.414) = 3 */
        CHECK_EQ_STATUS(hfvis_ssao_directions_box(1, 2, 2.12, d), HFVIS_OK);
        CHECK(d[1].step_x == 2.0 && d[1].step_y == 2.0 && d[0].step_x == 3.0 && d[2].step_y == 3.0);
    }
    memcpy(keep, d, sizeof d);
    CHECK_EQ_STATUS(hfvis_ssao_directions_uniform(0, 0.0, 1.0, 1.0, d), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_ssao_directions_uniform(4, (double)NAN, 1.0, 1.0, d), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_ssao_directions_uniform(4, 0.0, 0.001, 1.0, d), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_ssao_directions_uniform(4, 0.0, 1.0, (double)INFINITY, d), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_ssao_directions_uniform(4, 0.0, 1.0, 1.0, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_ssao_directions_box(0, 1, 1.0, d), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_ssao_directions_box(1, 0, 1.0, d), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_ssao_directions_box(1, 1, 0.0, d), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(memcmp(keep, d, sizeof d) == 0);
}

/* Every lattice sample lies in the texel-centre rectangle, lines are D_L apart, steps share
 * the origin, the sample count matches the lines, and the nearest sample of every pixel lies
 * within sqrt((D_S/2)^2 + (D_L/2)^2) (spec §2.3). */
TEST(lattice)
{
    hfvis_camera c;
    hfvis_ssao_direction dirs[40];
    int set, k, bad = 0, far_bad = 0;
    CHECK_EQ_STATUS(hfvis_camera_perspective(&c, 37, 23, 3, 2, 1.0), HFVIS_OK);
    for (set = 0; set < 4; set++) {
        int K;
        if (set == 0) { K = 7; CHECK_EQ_STATUS(hfvis_ssao_directions_uniform(K, 0.3, 1.0, 1.0, dirs), HFVIS_OK); }
        else if (set == 1) { K = 16; CHECK_EQ_STATUS(hfvis_ssao_directions_uniform(K, 0.0, 2.5, 1.7, dirs), HFVIS_OK); }
        else if (set == 2) { K = 16; CHECK_EQ_STATUS(hfvis_ssao_directions_box(2, 1, 1.64, dirs), HFVIS_OK); }
        else { K = 40; CHECK_EQ_STATUS(hfvis_ssao_directions_box(5, 2, 3.1, dirs), HFVIS_OK); }
        for (k = 0; k < K; k++) {
            hfvis_ssao_lattice L;
            hfvis_ssao_line *lines;
            size_t total = 0;
            int j, i, x, y, maxc = 0;
            double R;
            CHECK_EQ_STATUS(hfvis_ssao_lattice_init(&c, &dirs[k], &L), HFVIS_OK);
            lines = (hfvis_ssao_line *)malloc(sizeof *lines * (size_t)L.line_count);
            CHECK_EQ_STATUS(hfvis_ssao_lattice_lines(&c, &L, lines), HFVIS_OK);
            for (j = 0; j < L.line_count; j++) {
                CHECK(lines[j].offset == total);
                total += (size_t)lines[j].count;
                if (lines[j].count > maxc) maxc = lines[j].count;
                for (i = lines[j].first - 2; i < lines[j].first + lines[j].count + 2; i++) {
                    double u = lines[j].x0 + i * dirs[k].step_x, v = lines[j].y0 + i * dirs[k].step_y;
                    int in = u >= 0.5 - TOL_LATTICE_PX && u <= c.width - 0.5 + TOL_LATTICE_PX &&
                             v >= 0.5 - TOL_LATTICE_PX && v <= c.height - 0.5 + TOL_LATTICE_PX;
                    int member = i >= lines[j].first && i < lines[j].first + lines[j].count;
                    if (in != member) bad++;
                    /* on the line s_j and at along-line t_min + i D_S */
                    if (fabs(u * L.px + v * L.py - (L.s_first + j * dirs[k].spacing)) > 1e-9) bad++;
                    if (fabs(u * dirs[k].dx + v * dirs[k].dy - (L.t_min + i * dirs[k].step)) > 1e-9) bad++;
                }
            }
            CHECK(total == L.sample_count && maxc == L.max_line_samples);
            R = sqrt(0.25 * dirs[k].step * dirs[k].step + 0.25 * dirs[k].spacing * dirs[k].spacing);
            for (y = 0; y < c.height; y++)
                for (x = 0; x < c.width; x++) {
                    double u = x + 0.5, v = y + 0.5, su, sv, dd;
                    int jj, ii;
                    CHECK(hfvis_ssao_lattice_nearest(&L, lines, u, v, &jj, &ii) == 1);
                    su = lines[jj].x0 + ii * dirs[k].step_x;
                    sv = lines[jj].y0 + ii * dirs[k].step_y;
                    dd = sqrt((su - u) * (su - u) + (sv - v) * (sv - v));
                    /* interior pixels (2 R from the border) are within R */
                    if (u > 2 * R && v > 2 * R && u < c.width - 2 * R && v < c.height - 2 * R && dd > R + 1e-9) far_bad++;
                }
            free(lines);
        }
    }
    CHECK(bad == 0);
    CHECK(far_bad == 0);
    {
        hfvis_ssao_lattice L;
        hfvis_ssao_direction d = dirs[0];
        hfvis_camera c1;
        hfvis_ssao_line ln[1];
        int jj, ii;
        /* a 1 x 1 buffer has one sample per direction */
        CHECK_EQ_STATUS(hfvis_camera_orthographic(&c1, 1, 1, 0, 0, 1.0), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_ssao_directions_uniform(3, 0.2, 1.0, 1.0, dirs), HFVIS_OK);
        for (k = 0; k < 3; k++) {
            CHECK_EQ_STATUS(hfvis_ssao_lattice_init(&c1, &dirs[k], &L), HFVIS_OK);
            CHECK(L.line_count == 1 && L.sample_count == 1);
            CHECK_EQ_STATUS(hfvis_ssao_lattice_lines(&c1, &L, ln), HFVIS_OK);
            CHECK(hfvis_ssao_lattice_nearest(&L, ln, 0.5, 0.5, &jj, &ii) == 1 && jj == 0 && ii == ln[0].first);
        }
        CHECK(hfvis_ssao_lattice_nearest(&L, ln, (double)NAN, 0.5, &jj, &ii) == 0);
        d.dx = 0.9; /* not unit */
        CHECK_EQ_STATUS(hfvis_ssao_lattice_init(&c, &d, &L), HFVIS_ERR_INVALID_ARGUMENT);
        d = dirs[0];
        d.step_x += 0.01; /* step vector != step * D */
        CHECK_EQ_STATUS(hfvis_ssao_lattice_init(&c, &d, &L), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_ssao_lattice_init(&c, NULL, &L), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_ssao_lattice_init(&c, &dirs[0], NULL), HFVIS_ERR_INVALID_ARGUMENT);
    }
}

int main(int argc, char **argv)
{
    TEST_INIT(argc, argv);
    RUN(camera_check);
    RUN(camera_project_roundtrip);
    RUN(camera_from_view);
    RUN(depth_linearize);
    RUN(depth_normals);
    RUN(line_plane_isometry);
    RUN(falloff);
    RUN(directions);
    RUN(lattice);
    return TEST_DONE();
}
