/* test_volume.c - voxel.c core: views and matrices, eq. 16 depth linearisation, grid fit and the
 * Volume Buffer (voxel.c sections 2-3). */
#include "hfvis.h"
#include "test.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Products of a few O(1) doubles: a few ulps. */
#define VC_TOL_ROUND 1e-12
/* Inverse of a well-conditioned random matrix times itself vs identity. */
#define VC_TOL_INVERSE 1e-9

static double vc_rand(unsigned long long *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(*s >> 11) * (1.0 / 9007199254740992.0);
}

static void vc_apply(const double m[16], const double p[4], double out[4])
{
    int r;
    for (r = 0; r < 4; r++)
        out[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r] * p[3];
}

TEST(mat4_multiply_invert)
{
    unsigned long long seed = 7;
    int trial, i;
    for (trial = 0; trial < 200; trial++) {
        double m[16], inv[16], prod[16], alias[16];
        for (i = 0; i < 16; i++) m[i] = vc_rand(&seed) * 2.0 - 1.0;
        for (i = 0; i < 4; i++) m[i * 5] += 4.0; /* diagonally dominant: well conditioned */
        CHECK_EQ_STATUS(hfvis_mat4_invert(m, inv), HFVIS_OK);
        hfvis_mat4_multiply(m, inv, prod);
        for (i = 0; i < 16; i++) CHECK_NEAR(prod[i], (i % 5 == 0) ? 1.0 : 0.0, VC_TOL_INVERSE, 0);
        memcpy(alias, m, sizeof alias);
        hfvis_mat4_multiply(alias, inv, alias); /* out aliases a */
        for (i = 0; i < 16; i++) CHECK(alias[i] == prod[i]);
        memcpy(alias, m, sizeof alias);
        CHECK_EQ_STATUS(hfvis_mat4_invert(alias, alias), HFVIS_OK); /* out aliases m */
        for (i = 0; i < 16; i++) CHECK(alias[i] == inv[i]);
    }
    {
        double sing[16] = {0}, out[16], keep;
        sing[0] = 1.0;
        out[3] = keep = 42.0;
        CHECK_EQ_STATUS(hfvis_mat4_invert(sing, out), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK(out[3] == keep);
        sing[5] = sing[10] = sing[15] = 1.0;
        sing[7] = (double)NAN;
        CHECK_EQ_STATUS(hfvis_mat4_invert(sing, out), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_mat4_invert(NULL, out), HFVIS_ERR_INVALID_ARGUMENT);
    }
}

TEST(look_at_and_projections)
{
    const double eye[3] = {1, 2, 3}, target[3] = {4, 6, 3}, up[3] = {0, 0, 1};
    double v[16], p[4], q[4], proj[16];
    CHECK_EQ_STATUS(hfvis_mat4_look_at(eye, target, up, v), HFVIS_OK);
    p[0] = eye[0], p[1] = eye[1], p[2] = eye[2], p[3] = 1.0;
    vc_apply(v, p, q); /* the eye goes to the origin */
    CHECK_NEAR(q[0], 0, VC_TOL_ROUND, 0);
    CHECK_NEAR(q[1], 0, VC_TOL_ROUND, 0);
    CHECK_NEAR(q[2], 0, VC_TOL_ROUND, 0);
    p[0] = target[0], p[1] = target[1], p[2] = target[2];
    vc_apply(v, p, q); /* the target is 5 units down -z */
    CHECK_NEAR(q[0], 0, VC_TOL_ROUND, 0);
    CHECK_NEAR(q[1], 0, VC_TOL_ROUND, 0);
    CHECK_NEAR(q[2], -5, VC_TOL_ROUND, 0);
    p[0] = eye[0], p[1] = eye[1], p[2] = eye[2] + 1.0;
    vc_apply(v, p, q); /* world up is eye +y */
    CHECK_NEAR(q[1], 1, VC_TOL_ROUND, 0);
    CHECK_EQ_STATUS(hfvis_mat4_look_at(eye, eye, up, v), HFVIS_ERR_INVALID_ARGUMENT);
    {
        const double along[3] = {3, 4, 0};
        CHECK_EQ_STATUS(hfvis_mat4_look_at(eye, target, along, v), HFVIS_ERR_INVALID_ARGUMENT);
    }
    /* perspective: eye z = -n -> NDC z -1, z = -f -> +1; the top edge of the frustum at y/-z =
     * tan(fov/2) -> NDC y = 1 */
    CHECK_EQ_STATUS(hfvis_mat4_perspective(1.0, 2.0, 0.5, 40.0, proj), HFVIS_OK);
    p[0] = 0, p[1] = 0, p[2] = -0.5, p[3] = 1;
    vc_apply(proj, p, q);
    CHECK_NEAR(q[2] / q[3], -1.0, VC_TOL_ROUND, 0);
    p[2] = -40.0;
    vc_apply(proj, p, q);
    CHECK_NEAR(q[2] / q[3], 1.0, VC_TOL_ROUND, 0);
    p[2] = -3.0, p[1] = 3.0 * tan(0.5), p[0] = 2.0 * 3.0 * tan(0.5);
    vc_apply(proj, p, q);
    CHECK_NEAR(q[1] / q[3], 1.0, VC_TOL_ROUND, 0);
    CHECK_NEAR(q[0] / q[3], 1.0, VC_TOL_ROUND, 0);
    CHECK_EQ_STATUS(hfvis_mat4_perspective(0.0, 1, 1, 2, proj), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_mat4_perspective(1.0, 1, 0, 2, proj), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_mat4_perspective(1.0, 1, 2, 2, proj), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_mat4_perspective(1.0, (double)NAN, 1, 2, proj), HFVIS_ERR_INVALID_ARGUMENT);
    /* ortho maps its box onto [-1, 1]^3 */
    CHECK_EQ_STATUS(hfvis_mat4_ortho(-2, 6, -1, 3, 1, 9, proj), HFVIS_OK);
    p[0] = 6, p[1] = -1, p[2] = -9, p[3] = 1;
    vc_apply(proj, p, q);
    CHECK_NEAR(q[0], 1, VC_TOL_ROUND, 0);
    CHECK_NEAR(q[1], -1, VC_TOL_ROUND, 0);
    CHECK_NEAR(q[2], 1, VC_TOL_ROUND, 0);
    CHECK_EQ_STATUS(hfvis_mat4_ortho(1, 1, -1, 3, 1, 9, proj), HFVIS_ERR_INVALID_ARGUMENT);
}

TEST(views)
{
    const double eye[3] = {0, 0, 5}, target[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    hfvis_view v, keep;
    memset(&keep, 0x5a, sizeof keep);
    v = keep;
    CHECK_EQ_STATUS(hfvis_view_perspective(&v, eye, target, up, 1.0, 0, 10, 1, 10),
                    HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_view_perspective(&v, eye, target, up, 4.0, 10, 10, 1, 10),
                    HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_view_orthographic(&v, eye, target, up, 0.0, 10, 10, 1, 10),
                    HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(memcmp(&v, &keep, sizeof v) == 0);
    CHECK_EQ_STATUS(hfvis_view_perspective(&v, eye, target, up, 1.0, 64, 32, 1, 10), HFVIS_OK);
    CHECK(v.width == 64 && v.height == 32 && !v.orthographic && v.near_plane == 1.0);
    CHECK_NEAR(v.proj[0] * 2.0, v.proj[5], VC_TOL_ROUND, 0); /* aspect 2 */
    CHECK_EQ_STATUS(hfvis_view_orthographic(&v, eye, target, up, 2.0, 64, 32, 1, 10), HFVIS_OK);
    CHECK(v.orthographic == 1);
    CHECK_NEAR(v.proj[0], 0.25, VC_TOL_ROUND, 0); /* half width 4 */
    CHECK_NEAR(v.proj[5], 0.5, VC_TOL_ROUND, 0);
}

/* Eq. 16 with its sign restored (docs/errata.md E54) against the projection matrix itself. */
TEST(depth_linearisation)
{
    double proj[16], n = 0.3, f = 70.0;
    int ortho;
    for (ortho = 0; ortho < 2; ortho++) {
        int i;
        if (ortho) hfvis_mat4_ortho(-1, 1, -1, 1, n, f, proj);
        else hfvis_mat4_perspective(1.2, 1.0, n, f, proj);
        CHECK_NEAR(hfvis_depth_to_eye_z(0.0, n, f, ortho), -n, VC_TOL_ROUND, 0);
        CHECK_NEAR(hfvis_depth_to_eye_z(1.0, n, f, ortho), -f, VC_TOL_ROUND, VC_TOL_ROUND);
        for (i = 0; i <= 100; i++) {
            double ze = -(n + (f - n) * i / 100.0), p[4], q[4], zw;
            p[0] = 0.1, p[1] = -0.2, p[2] = ze, p[3] = 1;
            vc_apply(proj, p, q);
            zw = 0.5 * (q[2] / q[3] + 1.0);
            CHECK_NEAR(hfvis_eye_z_to_depth(ze, n, f, ortho), zw, VC_TOL_ROUND, 0);
            CHECK_NEAR(hfvis_depth_to_eye_z(zw, n, f, ortho), ze, 0, 1e-9);
        }
    }
}

TEST(grid_fit)
{
    /* an axis-aligned 4 x 2 x 1 box of 2 triangles per face is not needed: two triangles
     * spanning the box's corners give the same bounds */
    static const float xyz[] = {1, 1, 1, 5, 3, 2, 5, 1, 2, 1, 3, 1};
    static const uint32_t idx[] = {0, 1, 2, 0, 3, 1};
    hfvis_mesh m;
    hfvis_volume_grid g, keep;
    m.xyz = xyz, m.vertex_count = 4, m.indices = idx, m.triangle_count = 2;
    CHECK_EQ_STATUS(hfvis_volume_grid_fit(&m, 8, 0.0, 0, &g), HFVIS_OK);
    CHECK(g.dims[0] == 8 && g.dims[1] == 4 && g.dims[2] == 2);
    CHECK(g.cell[0] == 0.5 && g.cell[1] == 0.5 && g.cell[2] == 0.5);
    CHECK(g.origin[0] == 1 && g.origin[1] == 1 && g.origin[2] == 1);
    CHECK_EQ_STATUS(hfvis_volume_grid_fit(&m, 3, 0.0, 0, &g), HFVIS_OK);
    CHECK(g.dims[0] == 3 && g.dims[1] == 2 && g.dims[2] == 1); /* round(1.5)=2, round(.75)=1 */
    CHECK_NEAR(g.cell[1], 1.0, VC_TOL_ROUND, 0);
    CHECK_EQ_STATUS(hfvis_volume_grid_fit(&m, 3, 0.0, 1, &g), HFVIS_OK);
    CHECK(g.dims[0] == 3 && g.dims[1] == 2 && g.dims[2] == 1); /* ceil(1.5)=2, ceil(.75)=1 */
    CHECK_NEAR(g.cell[2], 4.0 / 3.0, VC_TOL_ROUND, 0);
    CHECK_NEAR(g.origin[1] + g.cell[1], 2.0, VC_TOL_ROUND, 0); /* centred on y = 2 */
    CHECK_EQ_STATUS(hfvis_volume_grid_fit(&m, 8, 0.25, 1, &g), HFVIS_OK);
    CHECK(g.dims[0] == 8);
    CHECK_NEAR(g.cell[0], 0.75, VC_TOL_ROUND, 0); /* padded extent 4 + 2*0.25*4 = 6 */
    CHECK(g.dims[1] == 6 && g.dims[2] == 4);       /* ceil(4/0.75), ceil(3/0.75) */
    CHECK_NEAR(g.origin[0], 0.0, VC_TOL_ROUND, 0);
    {
        static const float flat[] = {0, 0, 2, 4, 0, 2, 0, 2, 2};
        static const uint32_t t[] = {0, 1, 2};
        hfvis_mesh fm;
        fm.xyz = flat, fm.vertex_count = 3, fm.indices = t, fm.triangle_count = 1;
        CHECK_EQ_STATUS(hfvis_volume_grid_fit(&fm, 4, 0.0, 0, &g), HFVIS_OK);
        CHECK(g.dims[0] == 4 && g.dims[1] == 2 && g.dims[2] == 1);
        CHECK(g.cell[2] == 1.0 && g.origin[2] == 1.5); /* the flat axis: one voxel around z=2 */
    }
    memset(&keep, 0x33, sizeof keep);
    g = keep;
    CHECK_EQ_STATUS(hfvis_volume_grid_fit(&m, 0, 0.0, 0, &g), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volume_grid_fit(&m, 8, -0.1, 0, &g), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volume_grid_fit(&m, 8, (double)NAN, 0, &g), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volume_grid_fit(NULL, 8, 0, 0, &g), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volume_grid_fit(&m, 4096, 0, 1, &g), HFVIS_ERR_LIMIT);
    m.triangle_count = 0;
    CHECK_EQ_STATUS(hfvis_volume_grid_fit(&m, 8, 0, 0, &g), HFVIS_ERR_INVALID_ARGUMENT);
    m.triangle_count = 2;
    {
        static const uint32_t bad[] = {0, 1, 2, 0, 3, 4};
        m.indices = bad;
        CHECK_EQ_STATUS(hfvis_volume_grid_fit(&m, 8, 0, 0, &g), HFVIS_ERR_INVALID_ARGUMENT);
    }
    CHECK(memcmp(&g, &keep, sizeof g) == 0);
}

TEST(volume_buffer)
{
    hfvis_volume_grid g;
    hfvis_volume v, w;
    float store[2 * 3 * 4 * 4], other[2 * 3 * 4 * 4], vals[4];
    int c;
    memset(&g, 0, sizeof g);
    g.dims[0] = 2, g.dims[1] = 3, g.dims[2] = 4;
    g.cell[0] = g.cell[1] = g.cell[2] = 0.5;
    CHECK(hfvis_volume_floats(&g, 4) == 96);
    CHECK(hfvis_volume_floats(&g, 0) == 0 && hfvis_volume_floats(&g, 33) == 0);
    CHECK(hfvis_volume_floats(NULL, 1) == 0);
    CHECK_EQ_STATUS(hfvis_volume_init(&v, &g, 4, store, (hfvis_blend)9), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volume_init(&v, &g, 4, NULL, HFVIS_BLEND_MAX), HFVIS_ERR_INVALID_ARGUMENT);
    memset(store, 0xff, sizeof store);
    CHECK_EQ_STATUS(hfvis_volume_init(&v, &g, 4, store, HFVIS_BLEND_MAX), HFVIS_OK);
    CHECK(store[0] == 0.0f && store[95] == 0.0f);
    v.blend[1] = HFVIS_BLEND_REPLACE, v.blend[2] = HFVIS_BLEND_MIN, v.blend[3] = HFVIS_BLEND_ADD;
    for (c = 0; c < 4; c++) vals[c] = 2.0f;
    CHECK_EQ_STATUS(hfvis_volume_write(&v, 1, 2, 3, vals), HFVIS_OK);
    for (c = 0; c < 4; c++) vals[c] = (c == 2) ? -1.0f : 1.0f;
    CHECK_EQ_STATUS(hfvis_volume_write(&v, 1, 2, 3, vals), HFVIS_OK);
    {
        const float *d = store + ((3 * 3 + 2) * 2 + 1) * 4; /* x fastest, interleaved */
        CHECK(d[0] == 2.0f && d[1] == 1.0f && d[2] == -1.0f && d[3] == 3.0f);
    }
    CHECK_EQ_STATUS(hfvis_volume_write(&v, 2, 0, 0, vals), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volume_write(&v, 0, -1, 0, vals), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volume_write(&v, 0, 0, 4, vals), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_volume_write(&v, 0, 0, 0, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    /* merge with dst's blends (the MAX merge of ch. 5 Alg. 4 and the others) */
    CHECK_EQ_STATUS(hfvis_volume_init(&w, &g, 4, other, HFVIS_BLEND_MAX), HFVIS_OK);
    hfvis_volume_clear(&w, 5.0f);
    CHECK_EQ_STATUS(hfvis_volume_merge(&v, &w), HFVIS_OK);
    {
        const float *d = store + ((3 * 3 + 2) * 2 + 1) * 4;
        CHECK(d[0] == 5.0f && d[1] == 5.0f && d[2] == -1.0f && d[3] == 8.0f);
        CHECK(store[0] == 5.0f && store[1] == 5.0f && store[2] == 0.0f && store[3] == 5.0f);
    }
    w.channels = 3;
    CHECK_EQ_STATUS(hfvis_volume_merge(&v, &w), HFVIS_ERR_INVALID_ARGUMENT);
    w.channels = 4, w.grid.dims[2] = 2;
    CHECK_EQ_STATUS(hfvis_volume_merge(&v, &w), HFVIS_ERR_INVALID_ARGUMENT);
    hfvis_volume_clear(NULL, 1.0f); /* no crash */
    hfvis_mesh_free(NULL, NULL);
}

int main(int argc, char **argv)
{
    TEST_INIT(argc, argv);
    RUN(mat4_multiply_invert);
    RUN(look_at_and_projections);
    RUN(views);
    RUN(depth_linearisation);
    RUN(grid_fit);
    RUN(volume_buffer);
    return TEST_DONE();
}
