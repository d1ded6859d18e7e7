/* ssao.c - screen space. Part of hfvis (see hfvis.h for the conventions and the API).
 *
 * Contents
 *   1. Common: three-factor sizes and the per-pixel hash (allocation, checked sizes and the
 *      PRNGs are hfvis.c's hfvis__ helpers)
 *   2. Camera, hardware depth linearisation, view-space reconstruction, normals from depth
 *      ([P4] §3; docs/errata.md C7)
 *   3. Falloff functions ([P3] Eq. 2-3; docs/errata.md C4)
 *   4. The azimuthal line plane, uniform and box-pattern directions, the line lattice
 *      ([P3] §5.1-5.2, [P4] §6; docs/errata.md E20, E21, E24)
 *   5. P3 line-sweep AO: the obscurity hull along one line ([P3] §4, Alg. 1; its order tests
 *      cross-multiplied, without roots or divisions) and its brute-force oracle ([P3] Fig. 7),
 *      the sweep of one direction (in the driver clipped to the receivers near the inner image
 *      and the steps they reach within the falloff's support), the per-pixel gather ([P3]
 *      §5.1), the driver ([P3] §4-5)
 *   6. HBAO in three variants (Bavoil, Sainz, Dimitrov 2008, as the thesis describes it; [T14] §4.1, [P4] §8; docs/errata.md E25)
 *   7. The screen-space ray-traced reference ([P4] §8; docs/errata.md E36)
 *   8. Analytic depth buffers
 *   9. P4 far-field obscurance: scan kernel (Alg. 1, sign corrected), virtual points, level
 *      hierarchy, prefix sums and sector averaging, obscurity kernel (Alg. 2), slab estimator
 *      (quadrature, L(a,b,c,d) table, closed form for rho = 1), near field, sparse 3x3, blur
 *      ([P4] §3-11)
 *  10. The mipmap baseline ([P4] §5)
 *  11. Error metrics ([P4] §8; docs/errata.md E36)
 *  12. Laine-Karras bitmask ray-cast AO: ray sets, receiver frames, exact and table triangle
 *      masks, culling, Method 1 (rasterization), Method 2 (BVH traversal with exact node masks),
 *      the reference ray caster ([LK] EGSR 2010)
 *
 * Paper references: [P3] V. Timonen, "Line-Sweep Ambient Obscurance", EGSR 2013; [P4]
 * V. Timonen, "Screen-Space Far-Field Ambient Obscurance", HPG 2013 (both in Timonen's 2014
 * thesis). Errata and choices: docs/errata.md
 * E19-E38.
 */
#define HFVIS__INTERNAL /* the internal block of hfvis.h: shared helpers, not API */
#include "hfvis.h"

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* ========================================================================================== */
/* 1. Common                                                                                  */
/* ========================================================================================== */

/* a*b*c bytes, 0 on overflow (callers never ask for 0 bytes). */
static size_t ss_bytes3(size_t a, size_t b, size_t c)
{
    size_t t, u;
    if (!hfvis__mul_size(a, b, &t) || !hfvis__mul_size(t, c, &u)) return 0;
    return u;
}

/* Uniform double in [0, 1) from (a, b, c, seed). */
static double ss_hash01(uint32_t a, uint32_t b, uint32_t c, uint32_t seed)
{
    uint64_t h = hfvis__mix64(((uint64_t)seed << 32) ^ (uint64_t)a);
    h = hfvis__mix64(h ^ ((uint64_t)b << 32) ^ (uint64_t)c);
    return (double)(h >> 11) * (1.0 / 9007199254740992.0);
}

/* ========================================================================================== */
/* 2. Camera, depth, view-space reconstruction, normals ([P4] §3; docs/errata.md C7)          */
/* ========================================================================================== */

/* The validated camera in the form the inner loops use. */
typedef struct ss_cam {
    int persp;
    int W, H, gx, gy;
    ptrdiff_t stride;
    ptrdiff_t row0, row_step;  /* element of texel (x, y): row0 + y*row_step + x (bottom-up
                                  rows: row0 = (H - 1) stride, row_step = -stride) */
    double fx, fy, cx, cy, ifx, ify, sx, sy;
    double far_d;              /* +inf when the camera has no far limit */
} ss_cam;

hfvis_status hfvis_camera_check(const hfvis_camera *cam)
{
    if (!cam) return HFVIS_ERR_INVALID_ARGUMENT;
    if (cam->width < 1 || cam->height < 1) return HFVIS_ERR_INVALID_ARGUMENT;
    if (cam->stride < 0 || (cam->stride != 0 && cam->stride < cam->width))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (cam->guard_x < 0 || cam->guard_y < 0) return HFVIS_ERR_INVALID_ARGUMENT;
    if (cam->rows_bottom_up != 0 && cam->rows_bottom_up != 1) return HFVIS_ERR_INVALID_ARGUMENT;
    if (cam->guard_x >= (cam->width + 1) / 2 || cam->guard_y >= (cam->height + 1) / 2)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (cam->projection == HFVIS_CAMERA_PERSPECTIVE) {
        if (!(isfinite(cam->fx) && cam->fx > 0.0 && isfinite(cam->fy) && cam->fy > 0.0))
            return HFVIS_ERR_INVALID_ARGUMENT;
    } else if (cam->projection == HFVIS_CAMERA_ORTHOGRAPHIC) {
        if (!(isfinite(cam->scale_x) && cam->scale_x > 0.0 && isfinite(cam->scale_y) &&
              cam->scale_y > 0.0))
            return HFVIS_ERR_INVALID_ARGUMENT;
    } else {
        return HFVIS_ERR_INVALID_ARGUMENT;
    }
    if (!isfinite(cam->cx) || !isfinite(cam->cy)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (!(cam->far_depth >= 0.0)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (cam->width > HFVIS_SSAO_MAX_SIZE || cam->height > HFVIS_SSAO_MAX_SIZE)
        return HFVIS_ERR_LIMIT;
    {
        size_t st = (size_t)(cam->stride ? cam->stride : cam->width), n;
        if (!hfvis__mul_size(st, (size_t)cam->height, &n) || !hfvis__mul_size(n, 3 * sizeof(float), &n) ||
            n > (size_t)PTRDIFF_MAX)
            return HFVIS_ERR_LIMIT;
    }
    return HFVIS_OK;
}

static hfvis_status ss_cam_load(const hfvis_camera *cam, ss_cam *c)
{
    hfvis_status s = hfvis_camera_check(cam);
    if (s != HFVIS_OK) return s;
    memset(c, 0, sizeof *c);
    c->persp = cam->projection == HFVIS_CAMERA_PERSPECTIVE;
    c->W = cam->width;
    c->H = cam->height;
    c->gx = cam->guard_x;
    c->gy = cam->guard_y;
    c->stride = cam->stride ? cam->stride : cam->width;
    c->row0 = cam->rows_bottom_up ? (ptrdiff_t)(c->H - 1) * c->stride : 0;
    c->row_step = cam->rows_bottom_up ? -c->stride : c->stride;
    c->cx = cam->cx;
    c->cy = cam->cy;
    if (c->persp) {
        c->fx = cam->fx;
        c->fy = cam->fy;
        c->ifx = 1.0 / cam->fx;
        c->ify = 1.0 / cam->fy;
    } else {
        c->sx = cam->scale_x;
        c->sy = cam->scale_y;
    }
    c->far_d = cam->far_depth > 0.0 ? cam->far_depth : HFVIS__INF;
    return HFVIS_OK;
}

/* Background: not finite, <= 0 or >= far. */
static int ss_bg(const ss_cam *c, double z) { return !(z > 0.0 && z < c->far_d); }

static void ss_unproject(const ss_cam *c, double u, double v, double z, double out[3])
{
    if (c->persp) {
        out[0] = (u - c->cx) * z * c->ifx;
        out[1] = -(v - c->cy) * z * c->ify;
    } else {
        out[0] = (u - c->cx) * c->sx;
        out[1] = -(v - c->cy) * c->sy;
    }
    out[2] = -z;
}

hfvis_status hfvis_camera_perspective(hfvis_camera *cam, int width, int height, int guard_x,
                                      int guard_y, double fov_y_rad)
{
    hfvis_camera c;
    hfvis_status s;
    double f;
    if (!cam || !(fov_y_rad > 0.0 && fov_y_rad < HFVIS__PI)) return HFVIS_ERR_INVALID_ARGUMENT;
    memset(&c, 0, sizeof c);
    c.width = width;
    c.height = height;
    c.guard_x = guard_x;
    c.guard_y = guard_y;
    c.projection = HFVIS_CAMERA_PERSPECTIVE;
    c.fx = c.fy = 1.0; /* placeholder for the check */
    c.cx = 0.5 * (double)width;
    c.cy = 0.5 * (double)height;
    s = hfvis_camera_check(&c);
    if (s != HFVIS_OK) return s;
    f = 0.5 * (double)(height - 2 * guard_y) / tan(0.5 * fov_y_rad);
    if (!(isfinite(f) && f > 0.0)) return HFVIS_ERR_INVALID_ARGUMENT;
    c.fx = c.fy = f;
    *cam = c;
    return HFVIS_OK;
}

hfvis_status hfvis_camera_orthographic(hfvis_camera *cam, int width, int height, int guard_x,
                                       int guard_y, double pixel_size)
{
    hfvis_camera c;
    hfvis_status s;
    if (!cam || !(isfinite(pixel_size) && pixel_size > 0.0)) return HFVIS_ERR_INVALID_ARGUMENT;
    memset(&c, 0, sizeof c);
    c.width = width;
    c.height = height;
    c.guard_x = guard_x;
    c.guard_y = guard_y;
    c.projection = HFVIS_CAMERA_ORTHOGRAPHIC;
    c.scale_x = c.scale_y = pixel_size;
    c.cx = 0.5 * (double)width;
    c.cy = 0.5 * (double)height;
    s = hfvis_camera_check(&c);
    if (s != HFVIS_OK) return s;
    *cam = c;
    return HFVIS_OK;
}

hfvis_status hfvis_camera_from_view(hfvis_camera *cam, const struct hfvis_view *view,
                                    int guard_x, int guard_y)
{
    hfvis_camera c;
    hfvis_status s;
    const double *P;
    double W, H;
    int i;
    if (!cam || !view) return HFVIS_ERR_INVALID_ARGUMENT;
    P = view->proj;
    for (i = 0; i < 16; i++)
        if (!isfinite(P[i])) return HFVIS_ERR_INVALID_ARGUMENT;
    W = (double)view->width;
    H = (double)view->height;
    memset(&c, 0, sizeof c);
    c.width = view->width;
    c.height = view->height;
    c.guard_x = guard_x;
    c.guard_y = guard_y;
    /* GL matrices are column-major: element (row r, col c) = m[c*4 + r]. Off-diagonal terms
     * that mix x and y (shear) are not representable by a camera: reject them. */
    if (P[4] != 0.0 || P[1] != 0.0 || P[6] != 0.0 || P[2] != 0.0 || P[0] == 0.0 ||
        P[5] == 0.0)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (!view->orthographic) {
        /* x_ndc = P00 x/d - P02 (d = -z): u = W/2 (x_ndc + 1) = cx + fx x/d */
        if (P[3] != 0.0 || P[7] != 0.0 || P[11] != -1.0 || P[15] != 0.0 || P[12] != 0.0 ||
            P[13] != 0.0)
            return HFVIS_ERR_INVALID_ARGUMENT;
        c.projection = HFVIS_CAMERA_PERSPECTIVE;
        c.fx = 0.5 * W * P[0];
        c.fy = 0.5 * H * P[5];
        c.cx = 0.5 * W * (1.0 - P[8]);
        c.cy = 0.5 * H * (1.0 + P[9]); /* P12 = m[9]: y_ndc = P11 y/d - P12 */
    } else {
        if (P[3] != 0.0 || P[7] != 0.0 || P[11] != 0.0 || P[15] != 1.0 || P[8] != 0.0 ||
            P[9] != 0.0)
            return HFVIS_ERR_INVALID_ARGUMENT;
        c.projection = HFVIS_CAMERA_ORTHOGRAPHIC;
        c.scale_x = 2.0 / (W * P[0]);
        c.scale_y = 2.0 / (H * P[5]);
        /* x_ndc = P00 x + P03 -> u = W/2 (P00 x + P03 + 1) -> x = (u - W/2 (1 + P03)) sx */
        c.cx = 0.5 * W * (1.0 + P[12]);
        c.cy = 0.5 * H * (1.0 - P[13]);
    }
    c.far_depth = view->far_plane > 0.0 ? view->far_plane : 0.0;
    if (c.projection == HFVIS_CAMERA_PERSPECTIVE && (c.fx <= 0.0 || c.fy <= 0.0))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (c.projection == HFVIS_CAMERA_ORTHOGRAPHIC && (c.scale_x <= 0.0 || c.scale_y <= 0.0))
        return HFVIS_ERR_INVALID_ARGUMENT;
    s = hfvis_camera_check(&c);
    if (s != HFVIS_OK) return s;
    *cam = c;
    return HFVIS_OK;
}

/* The depth encoding of window depth d = alpha + beta/z (perspective) or alpha + beta z
 * (orthographic) as a linear function of linear depth z: which hfvis_depth_encoding it is and
 * its planes. 0 when it is none of them. */
static int ss_depth_form(int ortho, double alpha, double beta, hfvis_projection_depth *pd)
{
    double n, f;
    if (!isfinite(alpha) || !isfinite(beta) || beta == 0.0) return 0;
    if (ortho) {
        if (beta > 0.0) { /* d(n) = 0, d(f) = 1 */
            n = -alpha / beta;
            f = (1.0 - alpha) / beta;
            pd->encoding = HFVIS_DEPTH_D3D;
        } else { /* reversed: d(n) = 1, d(f) = 0 */
            n = (1.0 - alpha) / beta;
            f = -alpha / beta;
            pd->encoding = HFVIS_DEPTH_REVERSED_Z;
        }
        if (!(n >= 0.0 && f > n && isfinite(f))) return 0;
    } else if (alpha == 1.0 && beta < 0.0) { /* d = 1 - n/z */
        n = -beta;
        f = HFVIS__INF;
        pd->encoding = HFVIS_DEPTH_INFINITE_FAR;
    } else if (alpha == 0.0 && beta > 0.0) { /* d = n/z */
        n = beta;
        f = HFVIS__INF;
        pd->encoding = HFVIS_DEPTH_REVERSED_INFINITE;
    } else {
        if (beta < 0.0) { /* d = f/(f - n) - f n/((f - n) z) */
            n = -beta / alpha;
            f = beta / (1.0 - alpha);
            pd->encoding = HFVIS_DEPTH_D3D;
        } else { /* d = n f/((f - n) z) - n/(f - n) */
            n = beta / (1.0 - alpha);
            f = -beta / alpha;
            pd->encoding = HFVIS_DEPTH_REVERSED_Z;
        }
        if (!(n > 0.0 && f > n && isfinite(f))) return 0;
    }
    if (!(n > 0.0 || (ortho && n == 0.0)) || !isfinite(n)) return 0;
    pd->orthographic = ortho;
    pd->near_plane = n;
    pd->far_plane = f;
    return 1;
}

hfvis_status hfvis_camera_from_matrix(hfvis_camera *cam, const double m[16],
                                      hfvis_clip_depth clip, int width, int height,
                                      int guard_x, int guard_y, hfvis_projection_depth *depth)
{
    hfvis_camera c;
    hfvis_projection_depth pd;
    hfvis_status st;
    double A[4][4], W = (double)width, H = (double)height, alpha, beta, w;
    int r, k, ortho;
    if (!cam || !m || (clip != HFVIS_CLIP_DEPTH_GL && clip != HFVIS_CLIP_DEPTH_ZERO_TO_ONE))
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (k = 0; k < 16; k++)
        if (!isfinite(m[k])) return HFVIS_ERR_INVALID_ARGUMENT;
    for (r = 0; r < 4; r++)
        for (k = 0; k < 4; k++) A[r][k] = m[4 * k + r];
    /* clip = A v; no shear between x and y, and x, y independent of the view z offset */
    if (A[0][1] != 0.0 || A[1][0] != 0.0 || A[3][0] != 0.0 || A[3][1] != 0.0 ||
        !(A[0][0] > 0.0) || !(A[1][1] > 0.0) || A[2][0] != 0.0 || A[2][1] != 0.0)
        return HFVIS_ERR_INVALID_ARGUMENT;
    memset(&c, 0, sizeof c);
    memset(&pd, 0, sizeof pd);
    c.width = width;
    c.height = height;
    c.guard_x = guard_x;
    c.guard_y = guard_y;
    ortho = A[3][2] == 0.0;
    if (!ortho) {
        /* w = A32 Z: linear depth z = w/|A32| and the view z = sign(A32) z (RH looks down -Z) */
        double sg = A[3][2] > 0.0 ? 1.0 : -1.0;
        w = fabs(A[3][2]);
        if (A[3][3] != 0.0 || A[0][3] != 0.0 || A[1][3] != 0.0) return HFVIS_ERR_INVALID_ARGUMENT;
        c.projection = HFVIS_CAMERA_PERSPECTIVE;
        c.fx = 0.5 * W * A[0][0] / w; /* x_ndc = (A00 X)/(w z) + sg A02/w */
        c.fy = 0.5 * H * A[1][1] / w;
        c.cx = 0.5 * W * (1.0 + sg * A[0][2] / w);
        c.cy = 0.5 * H * (1.0 - sg * A[1][2] / w); /* row 0 at the top: v grows as y_ndc falls */
        alpha = sg * A[2][2] / w;                   /* z_ndc = alpha + beta / z */
        beta = A[2][3] / w;
    } else {
        if (A[3][3] == 0.0 || A[0][2] != 0.0 || A[1][2] != 0.0) return HFVIS_ERR_INVALID_ARGUMENT;
        w = A[3][3];
        c.projection = HFVIS_CAMERA_ORTHOGRAPHIC;
        c.scale_x = 2.0 * w / (W * A[0][0]);
        c.scale_y = 2.0 * w / (H * A[1][1]);
        c.cx = 0.5 * W * (1.0 + A[0][3] / w);
        c.cy = 0.5 * H * (1.0 - A[1][3] / w);
        /* z_ndc = (A22 Z + A23)/w with Z = -+z: the sense follows from the planes (below) */
        alpha = A[2][3] / w;
        beta = -fabs(A[2][2] / w);
    }
    if (clip == HFVIS_CLIP_DEPTH_GL) { /* window depth (z_ndc + 1)/2 */
        alpha = 0.5 * (alpha + 1.0);
        beta *= 0.5;
    }
    if (ortho) {
        /* standard depth grows with z (beta > 0, d(0) <= 0); reversed falls (d(0) >= 1) */
        if (alpha <= 0.0) beta = -beta;
        else if (!(alpha >= 1.0)) return HFVIS_ERR_INVALID_ARGUMENT;
    }
    if (!ss_depth_form(ortho, alpha, beta, &pd)) return HFVIS_ERR_INVALID_ARGUMENT;
    /* The far plane as a float depth buffer holds it, so a cleared pixel is background. */
    if (isfinite(pd.far_plane)) {
        double ff = (double)(float)pd.far_plane;
        c.far_depth = ff < pd.far_plane ? ff : pd.far_plane;
    }
    st = hfvis_camera_check(&c);
    if (st != HFVIS_OK) return st;
    if (c.projection == HFVIS_CAMERA_PERSPECTIVE && !(isfinite(c.fx) && isfinite(c.fy)))
        return HFVIS_ERR_INVALID_ARGUMENT;
    *cam = c;
    if (depth) *depth = pd;
    return HFVIS_OK;
}

hfvis_status hfvis_camera_unproject(const hfvis_camera *cam, double u, double v, double depth,
                                    double out[3])
{
    ss_cam c;
    hfvis_status s = ss_cam_load(cam, &c);
    if (s != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    if (!out || !isfinite(u) || !isfinite(v) || !isfinite(depth))
        return HFVIS_ERR_INVALID_ARGUMENT;
    ss_unproject(&c, u, v, depth, out);
    return HFVIS_OK;
}

hfvis_status hfvis_camera_project(const hfvis_camera *cam, const double p[3], double *u,
                                  double *v, double *depth)
{
    ss_cam c;
    double d;
    hfvis_status s = ss_cam_load(cam, &c);
    if (s != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    if (!p || !u || !v || !depth || !isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]))
        return HFVIS_ERR_INVALID_ARGUMENT;
    d = -p[2];
    if (c.persp) {
        if (!(d > 0.0)) return HFVIS_ERR_INVALID_ARGUMENT;
        *u = c.cx + c.fx * p[0] / d;
        *v = c.cy - c.fy * p[1] / d;
    } else {
        *u = c.cx + p[0] / c.sx;
        *v = c.cy - p[1] / c.sy;
    }
    *depth = d;
    return HFVIS_OK;
}

/* Validate the planes of an encoding; 1 if usable. */
static int ss_depth_params(hfvis_depth_encoding e, int ortho, double n, double f)
{
    if (ortho != 0 && ortho != 1) return 0;
    if (e < HFVIS_DEPTH_GL || e > HFVIS_DEPTH_REVERSED_INFINITE) return 0;
    if (e == HFVIS_DEPTH_INFINITE_FAR || e == HFVIS_DEPTH_REVERSED_INFINITE)
        return !ortho && isfinite(n) && n > 0.0;
    if (!isfinite(n) || !isfinite(f) || !(n < f)) return 0;
    return ortho ? n >= 0.0 : n > 0.0;
}

double hfvis_depth_linear(double d, hfvis_depth_encoding e, int ortho, double n, double f)
{
    double z;
    if (!ss_depth_params(e, ortho, n, f)) return HFVIS__NAN;
    if (!isfinite(d)) return HFVIS__INF;
    if (e == HFVIS_DEPTH_GL_NDC) {
        if (!(d >= -1.0 && d <= 1.0)) return HFVIS__INF;
        d = 0.5 * (d + 1.0);
        e = HFVIS_DEPTH_GL;
    }
    if (!(d >= 0.0 && d <= 1.0)) return HFVIS__INF;
    switch (e) {
    case HFVIS_DEPTH_GL:
    case HFVIS_DEPTH_D3D:
        z = ortho ? n + d * (f - n) : n * f / (f - d * (f - n));
        break;
    case HFVIS_DEPTH_REVERSED_Z:
        z = ortho ? f - d * (f - n) : n * f / (n + d * (f - n));
        break;
    case HFVIS_DEPTH_INFINITE_FAR:
        z = d < 1.0 ? n / (1.0 - d) : HFVIS__INF;
        break;
    default: /* HFVIS_DEPTH_REVERSED_INFINITE */
        z = d > 0.0 ? n / d : HFVIS__INF;
        break;
    }
    return isfinite(z) ? z : HFVIS__INF;
}

double hfvis_depth_hardware(double z, hfvis_depth_encoding e, int ortho, double n, double f)
{
    double d;
    if (!ss_depth_params(e, ortho, n, f) || z != z) return HFVIS__NAN;
    if (!ortho && !(z > 0.0)) return HFVIS__NAN;
    switch (e) {
    case HFVIS_DEPTH_GL:
    case HFVIS_DEPTH_GL_NDC:
    case HFVIS_DEPTH_D3D:
        d = ortho ? (z - n) / (f - n) : f * (z - n) / (z * (f - n));
        if (e == HFVIS_DEPTH_GL_NDC) d = 2.0 * d - 1.0;
        break;
    case HFVIS_DEPTH_REVERSED_Z:
        d = ortho ? (f - z) / (f - n) : n * (f - z) / (z * (f - n));
        break;
    case HFVIS_DEPTH_INFINITE_FAR:
        d = 1.0 - n / z;
        break;
    default:
        d = n / z;
        break;
    }
    return d;
}

hfvis_status hfvis_depth_linearize(const float *in, int width, int height, ptrdiff_t in_stride,
                                   hfvis_depth_encoding e, int ortho, double n, double f,
                                   float *out, ptrdiff_t out_stride)
{
    int x, y;
    if (!in || !out || width < 1 || height < 1 || in_stride < width || out_stride < width ||
        !hfvis__plane_fits(in_stride, height, 1) || !hfvis__plane_fits(out_stride, height, 1))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (!ss_depth_params(e, ortho, n, f)) return HFVIS_ERR_INVALID_ARGUMENT;
    for (y = 0; y < height; y++) {
        const float *src = in + (ptrdiff_t)y * in_stride;
        float *dst = out + (ptrdiff_t)y * out_stride;
        for (x = 0; x < width; x++) dst[x] = (float)hfvis_depth_linear((double)src[x], e, ortho, n, f);
    }
    return HFVIS_OK;
}

static double ss_dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void ss_cross3(const double a[3], const double b[3], double out[3])
{
    double r0 = a[1] * b[2] - a[2] * b[1];
    double r1 = a[2] * b[0] - a[0] * b[2];
    double r2 = a[0] * b[1] - a[1] * b[0];
    out[0] = r0;
    out[1] = r1;
    out[2] = r2;
}

static int ss_normalize3(double v[3])
{
    double l = sqrt(ss_dot3(v, v));
    if (!(l > 0.0) || !isfinite(l)) return 0;
    v[0] /= l;
    v[1] /= l;
    v[2] /= l;
    return 1;
}

/* Element index of texel (x, y) (row 0 the top of the image) in the caller's layout. */
static ptrdiff_t ss_index(const ss_cam *c, int x, int y)
{
    return c->row0 + (ptrdiff_t)y * c->row_step + x;
}

/* Depth of texel (x, y) (no bounds check). */
static double ss_tex(const ss_cam *c, const float *depth, int x, int y)
{
    return (double)depth[ss_index(c, x, y)];
}

/* Normal of texel (x, y) from depth, into n[3]; 0 for background. */
static int ss_normal_at(const ss_cam *c, const float *depth, int x, int y, double n[3])
{
    double zc = ss_tex(c, depth, x, y), P[3], Q[3], a[3], b[3];
    int have_a = 0, have_b = 0, k;
    if (ss_bg(c, zc)) {
        n[0] = n[1] = n[2] = 0.0;
        return 0;
    }
    ss_unproject(c, (double)x + 0.5, (double)y + 0.5, zc, P);
    for (k = 0; k < 2; k++) {
        /* k = 0: x axis (a = d/du), k = 1: y axis (b = d/dv) */
        int lo_ok = 0, hi_ok = 0, lx = x - (k == 0), ly = y - (k == 1), hx = x + (k == 0),
            hy = y + (k == 1);
        double zl = 0.0, zh = 0.0, *out = k == 0 ? a : b;
        if (lx >= 0 && ly >= 0) {
            zl = ss_tex(c, depth, lx, ly);
            lo_ok = !ss_bg(c, zl);
        }
        if (hx < c->W && hy < c->H) {
            zh = ss_tex(c, depth, hx, hy);
            hi_ok = !ss_bg(c, zh);
        }
        if (hi_ok && (!lo_ok || fabs(zh - zc) <= fabs(zc - zl))) {
            ss_unproject(c, (double)hx + 0.5, (double)hy + 0.5, zh, Q);
            out[0] = Q[0] - P[0];
            out[1] = Q[1] - P[1];
            out[2] = Q[2] - P[2];
        } else if (lo_ok) {
            ss_unproject(c, (double)lx + 0.5, (double)ly + 0.5, zl, Q);
            out[0] = P[0] - Q[0];
            out[1] = P[1] - Q[1];
            out[2] = P[2] - Q[2];
        } else {
            continue;
        }
        if (k == 0) have_a = 1;
        else have_b = 1;
    }
    if (have_a && have_b) {
        ss_cross3(a, b, n);
        if (ss_normalize3(n)) {
            double facing = c->persp ? -ss_dot3(n, P) : n[2];
            if (facing < 0.0) {
                n[0] = -n[0];
                n[1] = -n[1];
                n[2] = -n[2];
            }
            return 1;
        }
    }
    if (c->persp) {
        n[0] = -P[0];
        n[1] = -P[1];
        n[2] = -P[2];
        ss_normalize3(n);
    } else {
        n[0] = n[1] = 0.0;
        n[2] = 1.0;
    }
    return 1;
}

static void ss_normals_fill(const ss_cam *c, const float *depth, float *normals)
{
    int x, y;
    for (y = 0; y < c->H; y++)
        for (x = 0; x < c->W; x++) {
            double n[3];
            float *o = normals + 3 * ss_index(c, x, y);
            ss_normal_at(c, depth, x, y, n);
            o[0] = (float)n[0];
            o[1] = (float)n[1];
            o[2] = (float)n[2];
        }
}

hfvis_status hfvis_depth_normals(const hfvis_camera *cam, const float *depth, float *normals)
{
    ss_cam c;
    if (ss_cam_load(cam, &c) != HFVIS_OK || !depth || !normals) return HFVIS_ERR_INVALID_ARGUMENT;
    ss_normals_fill(&c, depth, normals);
    return HFVIS_OK;
}

/* ========================================================================================== */
/* 3. Falloff ([P3] Eq. 2-3; docs/errata.md C4)                                               */
/* ========================================================================================== */

/* The falloff in the form the inner loops use. */
typedef struct ss_fall {
    int kind;
    double a;        /* r, lambda, R, or the custom support (0 = none) */
    double r1c, c;   /* HBAO: r(1 + C), C */
    double support;  /* rho = 0 for d >= support; +inf if unbounded */
    hfvis_falloff_fn fn;
    void *user;
} ss_fall;

hfvis_status hfvis_falloff_check(const hfvis_falloff *f)
{
    if (!f) return HFVIS_ERR_INVALID_ARGUMENT;
    switch (f->kind) {
    case HFVIS_FALLOFF_DEFAULT:
    case HFVIS_FALLOFF_NONE:
        return HFVIS_OK;
    case HFVIS_FALLOFF_INV_QUADRATIC:
    case HFVIS_FALLOFF_EXPONENTIAL:
    case HFVIS_FALLOFF_STEP:
        return isfinite(f->param) && f->param > 0.0 ? HFVIS_OK : HFVIS_ERR_INVALID_ARGUMENT;
    case HFVIS_FALLOFF_HBAO:
        if (!(isfinite(f->param) && f->param > 0.0)) return HFVIS_ERR_INVALID_ARGUMENT;
        return isfinite(f->hbao_c) && f->hbao_c >= 0.0 ? HFVIS_OK : HFVIS_ERR_INVALID_ARGUMENT;
    case HFVIS_FALLOFF_CUSTOM:
        if (!f->fn) return HFVIS_ERR_INVALID_ARGUMENT;
        return isfinite(f->param) && f->param >= 0.0 ? HFVIS_OK : HFVIS_ERR_INVALID_ARGUMENT;
    }
    return HFVIS_ERR_INVALID_ARGUMENT;
}

/* f may be NULL (= NONE); returns the check's status. */
static hfvis_status ss_fall_load(const hfvis_falloff *f, ss_fall *o)
{
    hfvis_falloff none;
    hfvis_status s;
    if (!f) {
        memset(&none, 0, sizeof none);
        f = &none;
    }
    s = hfvis_falloff_check(f);
    if (s != HFVIS_OK) return s;
    memset(o, 0, sizeof *o);
    o->kind = f->kind == HFVIS_FALLOFF_DEFAULT ? HFVIS_FALLOFF_NONE : (int)f->kind;
    o->a = f->param;
    o->support = HFVIS__INF;
    switch (o->kind) {
    case HFVIS_FALLOFF_HBAO:
        o->c = f->hbao_c > 0.0 ? f->hbao_c : 0.3;
        o->r1c = f->param * (1.0 + o->c);
        o->support = sqrt(f->param / o->c);
        break;
    case HFVIS_FALLOFF_STEP:
        o->support = f->param;
        break;
    case HFVIS_FALLOFF_CUSTOM:
        o->fn = f->fn;
        o->user = f->user;
        if (f->param > 0.0) o->support = f->param;
        break;
    default:
        break;
    }
    return HFVIS_OK;
}

static double ss_rho_general(const ss_fall *f, double d);

/* rho(d): the rational falloffs inline, the rest out of line. */
static inline double ss_rho(const ss_fall *f, double d)
{
    if (f->kind == HFVIS_FALLOFF_INV_QUADRATIC) return f->a / (f->a + d * d);
    if (f->kind == HFVIS_FALLOFF_HBAO) {
        double v = f->r1c / (f->a + d * d) - f->c;
        return v > 0.0 ? v : 0.0;
    }
    if (f->kind == HFVIS_FALLOFF_NONE) return 1.0;
    return ss_rho_general(f, d);
}

static double ss_rho_general(const ss_fall *f, double d)
{
    double v;
    switch (f->kind) {
    case HFVIS_FALLOFF_INV_QUADRATIC:
        return f->a / (f->a + d * d);
    case HFVIS_FALLOFF_HBAO:
        v = f->r1c / (f->a + d * d) - f->c;
        return v > 0.0 ? v : 0.0;
    case HFVIS_FALLOFF_EXPONENTIAL:
        return exp(-d / f->a);
    case HFVIS_FALLOFF_STEP:
        return d < f->a ? 1.0 : 0.0;
    case HFVIS_FALLOFF_CUSTOM:
        if (!(d < f->support)) return 0.0;
        v = f->fn(f->user, d);
        return v > 0.0 ? (v < 1.0 ? v : 1.0) : 0.0;
    default:
        return 1.0;
    }
}

double hfvis_falloff_eval(const hfvis_falloff *f, double distance)
{
    ss_fall o;
    if (ss_fall_load(f, &o) != HFVIS_OK || distance != distance) return HFVIS__NAN;
    return ss_rho(&o, distance);
}

double hfvis_falloff_support(const hfvis_falloff *f)
{
    ss_fall o;
    if (ss_fall_load(f, &o) != HFVIS_OK) return HFVIS__NAN;
    return o.support;
}

/* ========================================================================================== */
/* 4. Line plane, directions, lattice ([P3] §5.1-5.2, [P4] §6; docs/errata.md E20, E21, E24) */
/* ========================================================================================== */

/* e1 of screen direction (du, dv) (docs/errata.md E20, E21; unit, z = 0). */
static void ss_plane_e1(const ss_cam *c, double du, double dv, double e1[3])
{
    if (c->persp) {
        e1[0] = du * c->ifx;
        e1[1] = -dv * c->ify;
    } else {
        e1[0] = du * c->sx;
        e1[1] = -dv * c->sy;
    }
    e1[2] = 0.0;
    ss_normalize3(e1);
}

/* yhat of the plane through the eye, e1 and view point ref (perspective); (0, 0, 1) ortho. */
static void ss_plane_yhat(const ss_cam *c, const double e1[3], const double ref[3], double y[3])
{
    double N[3];
    if (!c->persp) {
        y[0] = y[1] = 0.0;
        y[2] = 1.0;
        return;
    }
    ss_cross3(e1, ref, N);
    ss_normalize3(N);
    ss_cross3(N, e1, y);
    ss_normalize3(y);
    if (y[2] < 0.0) {
        y[0] = -y[0];
        y[1] = -y[1];
        y[2] = -y[2];
    }
}

hfvis_status hfvis_camera_line_plane(const hfvis_camera *cam, const double ref[3], double du,
                                     double dv, double e1[3], double yhat[3])
{
    ss_cam c;
    double a[3], b[3];
    if (ss_cam_load(cam, &c) != HFVIS_OK || !ref || !e1 || !yhat) return HFVIS_ERR_INVALID_ARGUMENT;
    if (!isfinite(ref[0]) || !isfinite(ref[1]) || !isfinite(ref[2]) || !isfinite(du) ||
        !isfinite(dv) || (du == 0.0 && dv == 0.0))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (c.persp && !(ref[2] < 0.0)) return HFVIS_ERR_INVALID_ARGUMENT;
    ss_plane_e1(&c, du, dv, a);
    if (!(a[0] * a[0] + a[1] * a[1] > 0.5)) return HFVIS_ERR_INVALID_ARGUMENT;
    ss_plane_yhat(&c, a, ref, b);
    memcpy(e1, a, sizeof a);
    memcpy(yhat, b, sizeof b);
    return HFVIS_OK;
}

#define SS_MIN_STEP (1.0 / 64.0)

static int ss_step_ok(double s) { return isfinite(s) && s >= SS_MIN_STEP && s <= (double)HFVIS_SSAO_MAX_SIZE; }

/* Snap components within 1e-15 of 0 or +-1. */
static double ss_snap_unit(double v)
{
    if (fabs(v) < 1e-15) return 0.0;
    if (fabs(v - 1.0) < 1e-15) return 1.0;
    if (fabs(v + 1.0) < 1e-15) return -1.0;
    return v;
}

hfvis_status hfvis_ssao_directions_uniform(int K, double azimuth0_rad, double step,
                                           double spacing, hfvis_ssao_direction *out)
{
    int k;
    if (!out || K < 1 || K > HFVIS_SSAO_MAX_DIRECTIONS || !isfinite(azimuth0_rad) ||
        !ss_step_ok(step) || !ss_step_ok(spacing))
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (k = 0; k < K; k++) {
        double psi = azimuth0_rad + 2.0 * HFVIS__PI * (double)k / (double)K;
        hfvis_ssao_direction *d = &out[k];
        d->dx = ss_snap_unit(cos(psi));
        d->dy = ss_snap_unit(sin(psi));
        d->step = step;
        d->step_x = step * d->dx;
        d->step_y = step * d->dy;
        d->spacing = spacing;
        d->weight = 1.0 / (double)K;
    }
    return HFVIS_OK;
}

/* Azimuth in [0, 2 pi) of integer vector (i, j) (screen, +y down). */
static double ss_azimuth(double i, double j)
{
    double a = atan2(j, i);
    return a < 0.0 ? a + 2.0 * HFVIS__PI : a;
}

hfvis_status hfvis_ssao_directions_box(int n, int scale, double spacing,
                                       hfvis_ssao_direction *out)
{
    int K, k, i, j, cnt = 0, axis;
    double mean = 0.0;
    if (!out || n < 1 || scale < 1 || n > HFVIS_SSAO_MAX_DIRECTIONS / 8 || n > 4096 / scale ||
        !ss_step_ok(spacing))
        return HFVIS_ERR_INVALID_ARGUMENT;
    K = 8 * n;
    /* the ring in azimuth order: walk the square's boundary counter-clockwise on screen from
     * (n, 0) toward +y, which is increasing azimuth */
    k = 0;
    for (j = 0; j < n; j++) out[k++].step_x = (double)n, out[k - 1].step_y = (double)j;
    for (i = n; i > -n; i--) out[k++].step_x = (double)i, out[k - 1].step_y = (double)n;
    for (j = n; j > -n; j--) out[k++].step_x = (double)-n, out[k - 1].step_y = (double)j;
    for (i = -n; i < n; i++) out[k++].step_x = (double)i, out[k - 1].step_y = (double)-n;
    for (j = -n; j < 0; j++) out[k++].step_x = (double)n, out[k - 1].step_y = (double)j;
    HFVIS_ASSERT(k == K);
    for (k = 0; k < K; k++)
        if (out[k].step_x != 0.0 && out[k].step_y != 0.0) {
            mean += sqrt(out[k].step_x * out[k].step_x + out[k].step_y * out[k].step_y);
            cnt++;
        }
    mean = cnt ? mean / (double)cnt : (double)n;
    axis = (int)floor((double)scale * mean + 0.5);
    if (axis < 1) axis = 1;
    for (k = 0; k < K; k++) {
        hfvis_ssao_direction *d = &out[k];
        double sx = d->step_x, sy = d->step_y, len;
        if (sx == 0.0 || sy == 0.0) {
            sx = sx == 0.0 ? 0.0 : (sx > 0.0 ? (double)axis : -(double)axis);
            sy = sy == 0.0 ? 0.0 : (sy > 0.0 ? (double)axis : -(double)axis);
        } else {
            sx *= (double)scale;
            sy *= (double)scale;
        }
        len = sqrt(sx * sx + sy * sy);
        d->step_x = sx;
        d->step_y = sy;
        d->step = len;
        d->dx = sx / len;
        d->dy = sy / len;
        d->spacing = spacing;
    }
    for (k = 0; k < K; k++) {
        double a0 = ss_azimuth(out[(k + K - 1) % K].step_x, out[(k + K - 1) % K].step_y);
        double a2 = ss_azimuth(out[(k + 1) % K].step_x, out[(k + 1) % K].step_y);
        double gap = a2 - a0;
        if (gap < 0.0) gap += 2.0 * HFVIS__PI;
        out[k].weight = gap / (4.0 * HFVIS__PI);
    }
    return HFVIS_OK;
}

static int ss_dir_ok(const hfvis_ssao_direction *d)
{
    double l;
    if (!d || !isfinite(d->dx) || !isfinite(d->dy) || !ss_step_ok(d->step) ||
        !ss_step_ok(d->spacing) || !isfinite(d->step_x) || !isfinite(d->step_y))
        return 0;
    l = d->dx * d->dx + d->dy * d->dy;
    if (fabs(l - 1.0) > 1e-9) return 0;
    if (fabs(d->step_x - d->step * d->dx) > 1e-9 * d->step ||
        fabs(d->step_y - d->step * d->dy) > 1e-9 * d->step)
        return 0;
    return 1;
}

/* The parameters t of the points O + t D inside the box [lo, hi] (per axis), intersected with
 * [*tlo, *thi]; 0 when an axis with D = 0 misses it. */
static int ss_box_span(const double O[2], const double D[2], const double lo[2], const double hi[2],
                       double *tlo, double *thi)
{
    int a;
    for (a = 0; a < 2; a++) {
        if (D[a] == 0.0) {
            if (O[a] < lo[a] || O[a] > hi[a]) return 0;
        } else {
            double t1 = (lo[a] - O[a]) / D[a], t2 = (hi[a] - O[a]) / D[a];
            if (t1 > t2) {
                double t = t1;
                t1 = t2;
                t2 = t;
            }
            if (t1 > *tlo) *tlo = t1;
            if (t2 < *thi) *thi = t2;
        }
    }
    return 1;
}

/* Step range [first, first + count) of line j, and its step-0 position. */
static void ss_line_range(const ss_cam *c, const hfvis_ssao_lattice *L, int j, hfvis_ssao_line *ln)
{
    const double eps = 1e-7;
    double s = L->s_first + (double)j * L->dir.spacing;
    double ox = s * L->px, oy = s * L->py, tlo = -HFVIS__INF, thi = HFVIS__INF;
    double D[2], O[2], lo[2], hi[2];
    double fa, fb;
    D[0] = L->dir.dx;
    D[1] = L->dir.dy;
    O[0] = ox;
    O[1] = oy;
    lo[0] = lo[1] = 0.5 - eps;
    hi[0] = (double)c->W - 0.5 + eps;
    hi[1] = (double)c->H - 0.5 + eps;
    ln->x0 = ox + L->t_min * L->dir.dx;
    ln->y0 = oy + L->t_min * L->dir.dy;
    ln->first = 0;
    ln->count = 0;
    ln->offset = 0;
    if (!ss_box_span(O, D, lo, hi, &tlo, &thi) || !(tlo <= thi)) return;
    fa = ceil((tlo - L->t_min) / L->dir.step - 1e-9);
    fb = floor((thi - L->t_min) / L->dir.step + 1e-9);
    if (fb < fa) return;
    ln->first = (int)fa;
    ln->count = (int)(fb - fa) + 1;
}

static hfvis_status ss_lattice_init(const ss_cam *c, const hfvis_ssao_direction *dir,
                                    hfvis_ssao_lattice *lat)
{
    hfvis_ssao_lattice L;
    double cu[4], cv[4], smin = HFVIS__INF, smax = -HFVIS__INF, tmin = HFVIS__INF, span, nl;
    size_t total = 0;
    int k, j, maxc = 0;
    memset(&L, 0, sizeof L);
    L.dir = *dir;
    L.px = -dir->dy;
    L.py = dir->dx;
    cu[0] = cu[2] = 0.5;
    cu[1] = cu[3] = (double)c->W - 0.5;
    cv[0] = cv[1] = 0.5;
    cv[2] = cv[3] = (double)c->H - 0.5;
    for (k = 0; k < 4; k++) {
        double s = cu[k] * L.px + cv[k] * L.py, t = cu[k] * dir->dx + cv[k] * dir->dy;
        if (s < smin) smin = s;
        if (s > smax) smax = s;
        if (t < tmin) tmin = t;
    }
    span = smax - smin;
    nl = floor(span / dir->spacing + 1e-9) + 1.0;
    if (nl > (double)INT_MAX) return HFVIS_ERR_LIMIT;
    L.line_count = (int)nl;
    L.s_first = smin + 0.5 * (span - (nl - 1.0) * dir->spacing);
    L.t_min = tmin;
    /* bound the sample count before walking the lines: (lines) x (longest possible line) */
    if (nl * (floor(((double)c->W + (double)c->H) / dir->step) + 2.0) > 2147483647.0 * 64.0)
        return HFVIS_ERR_LIMIT;
    for (j = 0; j < L.line_count; j++) {
        hfvis_ssao_line ln;
        ss_line_range(c, &L, j, &ln);
        total += (size_t)ln.count;
        if (ln.count > maxc) maxc = ln.count;
        if (total > (size_t)INT_MAX) return HFVIS_ERR_LIMIT;
    }
    L.max_line_samples = maxc;
    L.sample_count = total;
    *lat = L;
    return HFVIS_OK;
}

hfvis_status hfvis_ssao_lattice_init(const hfvis_camera *cam, const hfvis_ssao_direction *dir,
                                     hfvis_ssao_lattice *lat)
{
    ss_cam c;
    hfvis_status s = ss_cam_load(cam, &c);
    if (s != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    if (!lat || !ss_dir_ok(dir)) return HFVIS_ERR_INVALID_ARGUMENT;
    return ss_lattice_init(&c, dir, lat);
}

static void ss_lattice_fill(const ss_cam *c, const hfvis_ssao_lattice *lat, hfvis_ssao_line *lines)
{
    size_t off = 0;
    int j;
    for (j = 0; j < lat->line_count; j++) {
        ss_line_range(c, lat, j, &lines[j]);
        lines[j].offset = off;
        off += (size_t)lines[j].count;
    }
}

hfvis_status hfvis_ssao_lattice_lines(const hfvis_camera *cam, const hfvis_ssao_lattice *lat,
                                      hfvis_ssao_line *lines)
{
    ss_cam c;
    if (ss_cam_load(cam, &c) != HFVIS_OK || !lat || !lines || !ss_dir_ok(&lat->dir))
        return HFVIS_ERR_INVALID_ARGUMENT;
    ss_lattice_fill(&c, lat, lines);
    return HFVIS_OK;
}

/* Nearest sample ([P3] §5.1, [P4] §6); 1 if found. */
static int ss_nearest(const hfvis_ssao_lattice *L, const hfvis_ssao_line *lines, double u,
                      double v, int *jo, int *io)
{
    double jf = (u * L->px + v * L->py - L->s_first) / L->dir.spacing;
    double tf = (u * L->dir.dx + v * L->dir.dy - L->t_min) / L->dir.step;
    int j, d, i;
    if (L->line_count < 1) return 0;
    jf = floor(jf + 0.5);
    if (jf < 0.0) jf = 0.0;
    if (jf > (double)(L->line_count - 1)) jf = (double)(L->line_count - 1);
    j = (int)jf;
    for (d = 0; d < L->line_count; d++) {
        int cand[2], m;
        cand[0] = j - d;
        cand[1] = j + d;
        for (m = 0; m < (d ? 2 : 1); m++) {
            const hfvis_ssao_line *ln;
            double ti;
            if (cand[m] < 0 || cand[m] >= L->line_count) continue;
            ln = &lines[cand[m]];
            if (ln->count < 1) continue;
            ti = floor(tf + 0.5);
            if (ti < (double)ln->first) ti = (double)ln->first;
            if (ti > (double)(ln->first + ln->count - 1)) ti = (double)(ln->first + ln->count - 1);
            i = (int)ti;
            *jo = cand[m];
            *io = i;
            return 1;
        }
    }
    return 0;
}

int hfvis_ssao_lattice_nearest(const hfvis_ssao_lattice *lat, const hfvis_ssao_line *lines,
                               double u, double v, int *line, int *step)
{
    if (!lat || !lines || !line || !step || !isfinite(u) || !isfinite(v)) return 0;
    if (!(lat->dir.spacing > 0.0) || !(lat->dir.step > 0.0)) return 0;
    return ss_nearest(lat, lines, u, v, line, step);
}

/* ========================================================================================== */
/* 5. P3 line-sweep ambient obscurance ([P3] §4-5, Alg. 1)                                    */
/* ========================================================================================== */

#define SS_LSAO_DEFAULT_K 16
#define SS_DEFAULT_SIN_T (-0.85)   /* [P3] §4.1: "fix all tangents to sin(t) = -0.85" */
#define SS_DEFAULT_REJECT_DEPTH 0.03 /* docs/errata.md E23, from P4's box filter */
#define SS_DEFAULT_REJECT_NORMAL 0.5
#define SS_COINCIDENT 1e-12        /* |h| <= 1e-12 |p|: the same point (docs/errata.md E27) */

/* Resolved LSAO/HBAO parameters in the form the loops use. */
typedef struct ss_cfg {
    ss_fall fall;
    int tangent, sampling, exact, ties, gather;
    double fixed;
    double rej_z;      /* < 0: off */
    double rej_n;      /* -inf: off */
} ss_cfg;

hfvis_lsao_options hfvis_lsao_options_default(void)
{
    hfvis_lsao_options o;
    memset(&o, 0, sizeof o);
    o.directions = SS_LSAO_DEFAULT_K;
    o.pattern = HFVIS_SSAO_PATTERN_BOX;
    o.box_scale = 1;
    o.step = 1.0;
    o.spacing = 0.0; /* depends on K: hfvis_lsao_options_resolve fills it in */
    o.falloff.kind = HFVIS_FALLOFF_NONE;
    o.tangent = HFVIS_SSAO_TANGENT_FIXED;
    o.fixed_sin_t = SS_DEFAULT_SIN_T;
    o.sampling = HFVIS_SSAO_SAMPLING_NEAREST;
    o.plane = HFVIS_SSAO_PLANE_PAPER;
    o.pop = HFVIS_LSAO_POP_TIES;
    o.gather = HFVIS_SSAO_GATHER_NEAREST;
    o.reject_depth = SS_DEFAULT_REJECT_DEPTH;
    o.reject_normal = SS_DEFAULT_REJECT_NORMAL;
    return o;
}

/* Mean |step| of the non-axis box vectors of n (the paper's D_S of a box pattern). */
static double ss_box_mean(int n, int m)
{
    double s = 0.0;
    int i, cnt = 0;
    /* ring vectors (n, j) for j = 1..n-1 and (n, n), times 8 symmetric copies: the mean over one
     * octant-symmetric set equals the mean over the ring without axes */
    for (i = 1; i <= n; i++) {
        double l = sqrt((double)n * (double)n + (double)i * (double)i);
        int mult = i == n ? 4 : 8;
        s += l * (double)mult;
        cnt += mult;
    }
    return (double)m * s / (double)cnt;
}

/* The falloff of an options struct: DEFAULT -> NONE, checked, HBAO's c defaulted to 0.3. */
static hfvis_status ss_resolve_falloff(hfvis_falloff *f)
{
    if (f->kind == HFVIS_FALLOFF_DEFAULT) f->kind = HFVIS_FALLOFF_NONE;
    if (hfvis_falloff_check(f) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    if (f->kind == HFVIS_FALLOFF_HBAO && f->hbao_c == 0.0) f->hbao_c = 0.3;
    return HFVIS_OK;
}

/* The fixed tangent, the depth sampling and the receiver plane that LSAO and HBAO share; the
 * two methods differ only in the default plane. */
static hfvis_status ss_resolve_sampling(double *fixed_sin_t, hfvis_ssao_sampling *sampling,
                                        hfvis_ssao_plane *plane, hfvis_ssao_plane plane_default)
{
    if (*fixed_sin_t == 0.0) *fixed_sin_t = SS_DEFAULT_SIN_T;
    if (!(*fixed_sin_t >= -1.0 && *fixed_sin_t <= 1.0)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (*sampling == HFVIS_SSAO_SAMPLING_DEFAULT) *sampling = HFVIS_SSAO_SAMPLING_NEAREST;
    if (*sampling != HFVIS_SSAO_SAMPLING_NEAREST && *sampling != HFVIS_SSAO_SAMPLING_BILINEAR)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (*plane == HFVIS_SSAO_PLANE_DEFAULT) *plane = plane_default;
    if (*plane != HFVIS_SSAO_PLANE_PAPER && *plane != HFVIS_SSAO_PLANE_EXACT)
        return HFVIS_ERR_INVALID_ARGUMENT;
    return HFVIS_OK;
}

hfvis_status hfvis_lsao_options_resolve(const hfvis_lsao_options *in, hfvis_lsao_options *out)
{
    hfvis_lsao_options o;
    int K, k;
    if (!out) return HFVIS_ERR_INVALID_ARGUMENT;
    if (in) o = *in;
    else memset(&o, 0, sizeof o);
    K = o.directions ? o.directions : SS_LSAO_DEFAULT_K;
    if (K < 1 || K > HFVIS_SSAO_MAX_DIRECTIONS) return HFVIS_ERR_INVALID_ARGUMENT;
    o.directions = K;
    if (o.pattern == HFVIS_SSAO_PATTERN_DEFAULT) o.pattern = HFVIS_SSAO_PATTERN_BOX;
    if (o.box_scale < 0 || !isfinite(o.step) || !isfinite(o.spacing) ||
        !isfinite(o.azimuth0_rad))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.box_scale == 0) o.box_scale = 1;
    if (o.step == 0.0) o.step = 1.0;
    if (!ss_step_ok(o.step)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.spacing != 0.0 && !ss_step_ok(o.spacing)) return HFVIS_ERR_INVALID_ARGUMENT;
    switch (o.pattern) {
    case HFVIS_SSAO_PATTERN_BOX:
        if (K % 8 != 0 || o.box_scale > 4096 / (K / 8)) return HFVIS_ERR_INVALID_ARGUMENT;
        if (o.spacing == 0.0) o.spacing = (double)K / (4.0 * ss_box_mean(K / 8, o.box_scale));
        break;
    case HFVIS_SSAO_PATTERN_UNIFORM:
        if (o.spacing == 0.0) o.spacing = (double)K / (4.0 * o.step);
        break;
    case HFVIS_SSAO_PATTERN_CUSTOM: {
        double ws = 0.0;
        if (!o.custom_directions) return HFVIS_ERR_INVALID_ARGUMENT;
        for (k = 0; k < K; k++) {
            const hfvis_ssao_direction *d = &o.custom_directions[k];
            if (!ss_dir_ok(d) || !isfinite(d->weight) || d->weight < 0.0)
                return HFVIS_ERR_INVALID_ARGUMENT;
            ws += d->weight;
        }
        if (!(ws > 0.0) || !isfinite(ws)) return HFVIS_ERR_INVALID_ARGUMENT;
        break;
    }
    default:
        return HFVIS_ERR_INVALID_ARGUMENT;
    }
    if (o.spacing != 0.0 && o.spacing < SS_MIN_STEP) o.spacing = SS_MIN_STEP;
    if (ss_resolve_falloff(&o.falloff) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    /* A step falloff breaks the obscurity hull: a point popped under a farther, higher one is
     * the answer again once the farther one leaves the radius (see the header). */
    if (o.falloff.kind == HFVIS_FALLOFF_STEP) return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.tangent == HFVIS_SSAO_TANGENT_DEFAULT) o.tangent = HFVIS_SSAO_TANGENT_FIXED;
    if (o.tangent < HFVIS_SSAO_TANGENT_FIXED || o.tangent > HFVIS_SSAO_TANGENT_FIXED_HULL_REAL_EVAL)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (ss_resolve_sampling(&o.fixed_sin_t, &o.sampling, &o.plane, HFVIS_SSAO_PLANE_PAPER)
        != HFVIS_OK)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.pop == HFVIS_LSAO_POP_DEFAULT) o.pop = HFVIS_LSAO_POP_TIES;
    if (o.pop != HFVIS_LSAO_POP_TIES && o.pop != HFVIS_LSAO_POP_STRICT)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.gather == HFVIS_SSAO_GATHER_DEFAULT) o.gather = HFVIS_SSAO_GATHER_NEAREST;
    if (o.gather != HFVIS_SSAO_GATHER_NEAREST && o.gather != HFVIS_SSAO_GATHER_BILINEAR)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.reject_depth != o.reject_depth || o.reject_normal != o.reject_normal ||
        o.reject_normal > 1.0)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.reject_depth == 0.0) o.reject_depth = SS_DEFAULT_REJECT_DEPTH;
    if (o.reject_normal == 0.0) o.reject_normal = SS_DEFAULT_REJECT_NORMAL;
    *out = o;
    return HFVIS_OK;
}

/* Directions of resolved options into out[K], weights normalised. */
static void ss_lsao_dirs(const hfvis_lsao_options *o, hfvis_ssao_direction *out)
{
    int K = o->directions, k;
    double ws = 0.0;
    switch (o->pattern) {
    case HFVIS_SSAO_PATTERN_BOX:
        hfvis_ssao_directions_box(K / 8, o->box_scale, o->spacing, out);
        break;
    case HFVIS_SSAO_PATTERN_UNIFORM:
        hfvis_ssao_directions_uniform(K, o->azimuth0_rad, o->step, o->spacing, out);
        break;
    default:
        memcpy(out, o->custom_directions, sizeof *out * (size_t)K);
        break;
    }
    for (k = 0; k < K; k++) ws += out[k].weight;
    for (k = 0; k < K; k++) out[k].weight /= ws;
}

hfvis_status hfvis_lsao_directions(const hfvis_lsao_options *opts, hfvis_ssao_direction *out)
{
    hfvis_lsao_options o;
    if (!out || hfvis_lsao_options_resolve(opts, &o) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    ss_lsao_dirs(&o, out);
    return HFVIS_OK;
}

static void ss_cfg_from_lsao(const hfvis_lsao_options *o, ss_cfg *g)
{
    memset(g, 0, sizeof *g);
    ss_fall_load(&o->falloff, &g->fall);
    g->tangent = (int)o->tangent;
    g->sampling = (int)o->sampling;
    g->exact = o->plane == HFVIS_SSAO_PLANE_EXACT;
    g->ties = o->pop == HFVIS_LSAO_POP_TIES;
    g->gather = (int)o->gather;
    g->fixed = o->fixed_sin_t;
    g->rej_z = o->reject_depth;
    g->rej_n = o->reject_normal;
}

/* Occ of point (hx, hy) = occluder - receiver seen along zenith (ux, uy) with tangent st
 * ([P3] Alg. 1 l.25-29) as the paper writes it (the oracle's arithmetic); *sin_out = Sin(h)
 * (-inf for a coincident point, which casts st). */
static inline double ss_occ(const ss_fall *f, double hx, double hy, double ux, double uy, double st,
                            double tiny, double *sin_out)
{
    double len = sqrt(hx * hx + hy * hy), s;
    s = len > tiny ? (hx * ux + hy * uy) / len : -HFVIS__INF;
    *sin_out = s;
    return s > st ? st + (s - st) * ss_rho(f, len) : st;
}

/* The hull's arithmetic without square roots and divisions on its path ([P3] Alg. 1 as the
 * oracle below computes it, rearranged). For a receiver p with unnormalised zenith w (-p in
 * perspective, |w| = r; (0, 1) and r = 1 orthographic) and a candidate h = occluder - p:
 * dd = h.w = r |h| Sin(h) and q = |h|^2. Sin order: s1 < s2 iff dd1 |dd1| q2 < dd2 |dd2| q1
 * (x |x| is monotone; q > 0). Occ - st = num / den with num = max(0, dd - st r |h|) N and
 * den = r |h| D (r |h| = sqrt(r^2 q), one root), where rho = N / D (HBAO: N = r(1+C) - C D,
 * D = r + q; inverse quadratic: N = r, D = r + q; none: 1, 1; the other kinds rho(|h|), 1), so
 * Occ order is the cross-multiplied num1 den2 against num2 den1, the root is taken only inside
 * the falloff's support, and each receiver divides once, for its output
 * Occ = (st r |h| (D - N) + dd N) / den (exactly 0 for Sin = 0 without a falloff, as the
 * oracle's st + (0 - st) 1). Coordinates are scaled by a power of two per line (exact) so the
 * products, of degree six in them, neither overflow nor underflow. */
typedef struct ss_hcand {
    double dd, q;  /* h.w, |h|^2 (scaled) */
    int co;        /* coincident with the receiver: Sin = -inf, Occ = st */
} ss_hcand;

static inline ss_hcand ss_hcand_of(double hx, double hy, double wx, double wy, double tiny2)
{
    ss_hcand c;
    c.dd = hx * wx + hy * wy;
    c.q = hx * hx + hy * hy;
    c.co = !(c.q > tiny2);
    return c;
}

static inline int ss_hsin_less(const ss_hcand *a, const ss_hcand *b)
{
    if (b->co) return 0;
    if (a->co) return 1;
    return a->dd * fabs(a->dd) * b->q < b->dd * fabs(b->dd) * a->q;
}

/* Occ - st = o->num / o->den of candidate c for tangent st (r2 = r^2), num = 0 for Occ = st;
 * fs is the falloff scaled to the line's coordinates, f the caller's (for the kinds without a
 * rational form), isig 1/scale. */
typedef struct ss_hocc_t { double num, den, rl, N, D; } ss_hocc_t;

static HFVIS__ALWAYS_INLINE void ss_hocc(const ss_fall *fs, const ss_fall *f, const ss_hcand *c, double r2,
                           double st, double isig, ss_hocc_t *o)
{
    double N, D, rl, e;
    o->num = 0.0; /* rl, N, D are read only where num > 0 */
    o->den = 1.0;
    if (c->co) return;
    if (fs->kind == HFVIS_FALLOFF_HBAO) {
        D = fs->a + c->q;
        N = fs->r1c - fs->c * D;
        if (!(N > 0.0)) return; /* beyond the support: Occ = st */
    } else if (fs->kind == HFVIS_FALLOFF_INV_QUADRATIC) {
        D = fs->a + c->q;
        N = fs->a;
    } else if (fs->kind == HFVIS_FALLOFF_NONE) {
        D = N = 1.0;
    } else {
        D = 1.0;
        N = ss_rho_general(f, sqrt(c->q) * isig);
        if (!(N > 0.0)) return;
    }
    rl = sqrt(r2 * c->q);
    e = c->dd - st * rl;
    if (!(e > 0.0)) return; /* Sin <= st: Occ = st */
    o->num = e * N;
    o->den = rl * D;
    o->rl = rl;
    o->N = N;
    o->D = D;
}

/* Occ of an evaluated candidate (ss_hocc) for its tangent st. */
static inline double ss_hocc_value(const ss_hocc_t *o, const ss_hcand *c, double st)
{
    return o->num > 0.0 ? (st * o->rl * (o->D - o->N) + c->dd * o->N) / o->den : st;
}

/* The largest power of two at most 1/max|coordinate| over the line's finite samples (1 for none);
 * m >= 0: that maximum, known to the caller. */
static double ss_line_scale(const double *x, const double *y, int n, double m)
{
    int i, e;
    if (m < 0.0)
        for (m = 0.0, i = 0; i < n; i++) {
            double a = fabs(x[i]), b = fabs(y[i]);
            if (a > m && a <= DBL_MAX) m = a;
            if (b > m && b <= DBL_MAX) m = b;
        }
    if (!(m > 0.0)) return 1.0;
    (void)frexp(m, &e); /* m in [2^(e-1), 2^e) */
    return ldexp(1.0, -e);
}

/* The obscurity hull along one line ([P3] §4.2, Alg. 1): coordinates times sig as they are
 * read (1 where the caller scaled them), the falloff's lengths times fsig (the scale); kind is
 * f->kind (a constant where a caller specializes the body). */
static HFVIS__ALWAYS_INLINE void ss_hull_body(const double *x, const double *y, const double *stc,
                                              const double *ste, int n, int persp, double fixed,
                                              const ss_fall *f, int kind, int ties, double sig,
                                              double fsig, int *stack, double *out)
{
    const double isig = 1.0 / fsig;
    ss_fall fs = *f; /* in the scaled coordinates: lengths times fsig (exact) */
    ss_hocc_t o1 = {0.0, 1.0, 0.0, 0.0, 0.0}, o2;
    int top = 0, i;
    fs.kind = kind;
    fs.a *= fsig * fsig;
    fs.r1c *= fsig * fsig;
    for (i = 0; i < n; i++) {
        double px = x[i], py = y[i], wx, wy, r2, sc, se, tiny, tiny2;
        ss_hcand c1, c2;
        int have1 = 0;
        if (!isfinite(px) || !isfinite(py)) {
            out[i] = HFVIS__NAN;
            continue;
        }
        if (persp) {
            wx = -px * sig; /* l.7: towards the camera, unnormalised */
            wy = -py * sig;
            r2 = wx * wx + wy * wy;
            if (!(r2 > 0.0)) {
                out[i] = HFVIS__NAN;
                continue;
            }
        } else {
            wx = 0.0;
            wy = 1.0;
            r2 = 1.0;
        }
        tiny = SS_COINCIDENT * (fabs(px) + fabs(py)) * sig;
        tiny2 = tiny * tiny;
        sc = stc ? stc[i] : fixed;
        se = ste ? ste[i] : fixed;
        c1.co = 1;
        c1.dd = c1.q = 0.0;
        /* Occ is formed only where the Sin test (s1 < s2) leaves the pop to it */
        if (top >= 1) {
            int a = stack[top - 1];
            c1 = ss_hcand_of((x[a] - px) * sig, (y[a] - py) * sig, wx, wy, tiny2);
        }
        while (top >= 2) { /* l.12-18 */
            int b = stack[top - 2];
            c2 = ss_hcand_of((x[b] - px) * sig, (y[b] - py) * sig, wx, wy, tiny2);
            if (!ss_hsin_less(&c1, &c2)) break;
            if (!have1) ss_hocc(&fs, f, &c1, r2, sc, isig, &o1), have1 = 1;
            ss_hocc(&fs, f, &c2, r2, sc, isig, &o2);
            if (!(ties ? o1.num * o2.den <= o2.num * o1.den : o1.num * o2.den < o2.num * o1.den)) break;
            top--;
            c1 = c2;
            o1 = o2;
        }
        if (top == 0) {
            out[i] = se; /* no occluder yet: rho = 0 (docs/errata.md E27) */
        } else {
            if (!have1 || se != sc) ss_hocc(&fs, f, &c1, r2, se, isig, &o1); /* l.20 */
            out[i] = ss_hocc_value(&o1, &c1, se);
        }
        if (top == 0 || !c1.co) stack[top++] = i; /* l.21 (coincident points skipped) */
    }
}

/* The hull of a caller's line (hfvis_lsao_line): amax the largest |x|, |y| or -1 to scan. */
static void ss_hull_line(const double *x, const double *y, const double *stc, const double *ste,
                         int n, int persp, double fixed, const ss_fall *f, int ties, double amax,
                         int *stack, double *out)
{
    const double sig = ss_line_scale(x, y, n, amax);
    ss_hull_body(x, y, stc, ste, n, persp, fixed, f, f->kind, ties, sig, sig, stack, out);
}

/* The hull of the sweep's own line: x, y scaled in place first (a power of two: the same bits as
 * scaling each difference), so the hull multiplies nothing as it reads them. hfvis_lsao's usual
 * case (perspective, the fixed tangent, HBAO's falloff, ties popped) has its own copy of the
 * body with those branches folded away (the same arithmetic). */
static void ss_hull_line_scratch(double *x, double *y, const double *stc, const double *ste, int n,
                                 int persp, double fixed, const ss_fall *f, int ties, double amax,
                                 int *stack, double *out)
{
    const double sig = ss_line_scale(x, y, n, amax);
    int i;
    for (i = 0; i < n; i++) {
        x[i] *= sig;
        y[i] *= sig;
    }
    if (persp && !stc && !ste && ties && f->kind == HFVIS_FALLOFF_HBAO)
        ss_hull_body(x, y, NULL, NULL, n, 1, fixed, f, HFVIS_FALLOFF_HBAO, 1, 1.0, sig, stack, out);
    else
        ss_hull_body(x, y, stc, ste, n, persp, fixed, f, f->kind, ties, 1.0, sig, stack, out);
}

/* Brute-force oracle ([P3] Fig. 7). */
static void ss_hull_line_naive(const double *x, const double *y, const double *stc,
                               const double *ste, int n, int persp, double fixed,
                               const ss_fall *f, double *out)
{
    int i, j;
    for (i = 0; i < n; i++) {
        double px = x[i], py = y[i], r, ux, uy, sc, se, tiny, maxs = -HFVIS__INF, bo = 0.0, bs = 0.0;
        int best = -1;
        if (!isfinite(px) || !isfinite(py)) {
            out[i] = HFVIS__NAN;
            continue;
        }
        r = sqrt(px * px + py * py);
        if (persp) {
            if (!(r > 0.0)) {
                out[i] = HFVIS__NAN;
                continue;
            }
            ux = -px / r;
            uy = -py / r;
        } else {
            ux = 0.0;
            uy = 1.0;
        }
        tiny = SS_COINCIDENT * (fabs(px) + fabs(py));
        sc = stc ? stc[i] : fixed;
        se = ste ? ste[i] : fixed;
        for (j = i - 1; j >= 0; j--) {
            double s, o;
            if (!isfinite(x[j]) || !isfinite(y[j])) continue;
            if (persp && !(x[j] * x[j] + y[j] * y[j] > 0.0)) continue;
            o = ss_occ(f, x[j] - px, y[j] - py, ux, uy, sc, tiny, &s);
            if (!(s > maxs)) continue; /* hidden behind a nearer point */
            maxs = s;
            if (best < 0 || o > bo || (o == bo && s > bs)) {
                best = j;
                bo = o;
                bs = s;
            }
        }
        if (best < 0) {
            out[i] = se;
        } else if (se == sc) {
            out[i] = bo;
        } else {
            double s;
            out[i] = ss_occ(f, x[best] - px, y[best] - py, ux, uy, se, tiny, &s);
        }
    }
}

static hfvis_status ss_line_args(const double *x, const double *y, int n, int ortho,
                                 const hfvis_lsao_options *opts, hfvis_lsao_options *o)
{
    if (n < 0 || (n > 0 && (!x || !y)) || (ortho != 0 && ortho != 1))
        return HFVIS_ERR_INVALID_ARGUMENT;
    return hfvis_lsao_options_resolve(opts, o) == HFVIS_OK ? HFVIS_OK : HFVIS_ERR_INVALID_ARGUMENT;
}

hfvis_status hfvis_lsao_line(const double *x, const double *y, const double *sin_t_cull,
                             const double *sin_t_eval, int n, int orthographic,
                             const hfvis_lsao_options *opts, int *stack, double *out)
{
    hfvis_lsao_options o;
    ss_cfg g;
    if (ss_line_args(x, y, n, orthographic, opts, &o) != HFVIS_OK || (n > 0 && (!stack || !out)))
        return HFVIS_ERR_INVALID_ARGUMENT;
    ss_cfg_from_lsao(&o, &g);
    ss_hull_line(x, y, sin_t_cull, sin_t_eval, n, !orthographic, g.fixed, &g.fall, g.ties, -1.0,
                 stack, out);
    return HFVIS_OK;
}

hfvis_status hfvis_lsao_line_naive(const double *x, const double *y, const double *sin_t_cull,
                                   const double *sin_t_eval, int n, int orthographic,
                                   const hfvis_lsao_options *opts, double *out)
{
    hfvis_lsao_options o;
    ss_cfg g;
    if (ss_line_args(x, y, n, orthographic, opts, &o) != HFVIS_OK || (n > 0 && !out))
        return HFVIS_ERR_INVALID_ARGUMENT;
    ss_cfg_from_lsao(&o, &g);
    ss_hull_line_naive(x, y, sin_t_cull, sin_t_eval, n, !orthographic, g.fixed, &g.fall, out);
    return HFVIS_OK;
}

/* Depth at screen position (u, v): NEAREST reads texel (tx, ty) (already snapped by the
 * caller) and returns its centre in (*qu, *qv); BILINEAR interpolates at (u, v) (NaN if a tap
 * with non-zero weight is background). Background -> NaN. */
static double ss_sample(const ss_cam *c, const float *depth, int bilinear, double u, double v,
                        int tx, int ty, double *qu, double *qv)
{
    double z;
    if (!bilinear) {
        z = ss_tex(c, depth, tx, ty);
        *qu = (double)tx + 0.5;
        *qv = (double)ty + 0.5;
        return ss_bg(c, z) ? HFVIS__NAN : z;
    } else {
        double a = u - 0.5, b = v - 0.5, fa, fb, z00, z10, z01, z11;
        int x0, y0, x1, y1;
        if (a < 0.0) a = 0.0;
        if (b < 0.0) b = 0.0;
        if (a > (double)(c->W - 1)) a = (double)(c->W - 1);
        if (b > (double)(c->H - 1)) b = (double)(c->H - 1);
        x0 = (int)a;
        y0 = (int)b;
        if (x0 > c->W - 2) x0 = c->W > 1 ? c->W - 2 : 0;
        if (y0 > c->H - 2) y0 = c->H > 1 ? c->H - 2 : 0;
        fa = a - (double)x0;
        fb = b - (double)y0;
        x1 = c->W > 1 ? x0 + 1 : x0;
        y1 = c->H > 1 ? y0 + 1 : y0;
        z00 = ss_tex(c, depth, x0, y0);
        z10 = ss_tex(c, depth, x1, y0);
        z01 = ss_tex(c, depth, x0, y1);
        z11 = ss_tex(c, depth, x1, y1);
        *qu = u;
        *qv = v;
        if ((fa < 1.0 && fb < 1.0 && ss_bg(c, z00)) || (fa > 0.0 && fb < 1.0 && ss_bg(c, z10)) ||
            (fa < 1.0 && fb > 0.0 && ss_bg(c, z01)) || (fa > 0.0 && fb > 0.0 && ss_bg(c, z11)))
            return HFVIS__NAN;
        if (fa == 0.0) z10 = z00, z11 = z01; /* zero weights never touch a background tap */
        if (fb == 0.0) z01 = z00, z11 = z10;
        if (fa == 1.0) z00 = z10, z01 = z11;
        if (fb == 1.0) z00 = z01, z10 = z11;
        z = (1.0 - fb) * ((1.0 - fa) * z00 + fa * z10) + fb * ((1.0 - fa) * z01 + fa * z11);
        return z;
    }
}

static int ss_clampi(int v, int lo, int hi) { return v < lo ? lo : (v > hi ? hi : v); }

static int ss_texel(double p, int n)
{
    double f = floor(p);
    if (!(f >= 0.0)) return 0;
    if (f > (double)(n - 1)) return n - 1;
    return (int)f;
}

/* sin t of the real tangent of a sample ([P3] §4.1, Fig. 7): normal of texel (tx, ty)
 * projected into the plane, t = side*(-n2.y, n2.x) (side +1: toward the occluders behind, as
 * LSAO; -1: ahead, as HBAO), sin t = t.u/|t|; the fixed value without a usable normal. */
static double ss_real_sin_t(const ss_cam *c, const float *normals, int tx, int ty,
                            const double e1[3], const double yh[3], int exact, double ux,
                            double uy, double side, double fixed)
{
    const float *np = normals + 3 * ss_index(c, tx, ty);
    double n[3], n2x, n2y, tx2, ty2, l;
    n[0] = (double)np[0];
    n[1] = (double)np[1];
    n[2] = (double)np[2];
    n2x = ss_dot3(n, e1);
    n2y = exact ? ss_dot3(n, yh) : n[2];
    tx2 = -side * n2y;
    ty2 = side * n2x;
    l = sqrt(tx2 * tx2 + ty2 * ty2);
    if (!(l > 1e-12) || !isfinite(l)) return fixed;
    return (tx2 * ux + ty2 * uy) / l;
}

/* Moves a snapped texel centre (*u, *v) to the nearest point of the screen line through
 * (u0, v0) with unit direction (dx, dy). The EXACT plane is the plane of the eye and that line:
 * a texel centre off the line would leave it, and in perspective its projection onto
 * (e1, yhat) then jitters up and down with the snapping (a flat plane facing the camera got
 * obscurance 0.05-0.19 from directions between the axes). The texel's depth is kept. */
static void ss_onto_line(double u0, double v0, double dx, double dy, double *u, double *v)
{
    double t = (*u - u0) * dx + (*v - v0) * dy;
    *u = u0 + t * dx;
    *v = v0 + t * dy;
}

/* A line's plane and first texel: e1, yhat (from the line's middle), the first texel (tx0, ty0)
 * (snapped; its fraction fx0, fy0), and fast: the line takes ss_line_points' common case,
 * nearest texels of an integer box step from that texel, the fixed tangent, and the whole line
 * inside the buffer (checked at its two ends; the texels in between lie between them), so no
 * clamps. */
typedef struct ss_lgeom {
    double e1[3], yh[3], fx0, fy0;
    int tx0, ty0, fast;
} ss_lgeom;

static void ss_line_geom(const ss_cam *c, const ss_cfg *g, const hfvis_ssao_lattice *L,
                         const hfvis_ssao_line *ln, int real, ss_lgeom *G)
{
    const hfvis_ssao_direction *d = &L->dir;
    int integral = d->step_x == floor(d->step_x) && d->step_y == floor(d->step_y) &&
                   fabs(d->step_x) < 1e9 && fabs(d->step_y) < 1e9;
    double tlx, tly, ref[3];
    memset(G, 0, sizeof *G);
    ss_plane_e1(c, d->dx, d->dy, G->e1);
    if (ln->count < 1) return;
    {
        int mid = ln->first + ln->count / 2;
        ss_unproject(c, ln->x0 + (double)mid * d->step_x, ln->y0 + (double)mid * d->step_y, 1.0,
                     ref);
        ss_plane_yhat(c, G->e1, ref, G->yh);
    }
    G->tx0 = ss_texel(ln->x0 + (double)ln->first * d->step_x, c->W);
    G->ty0 = ss_texel(ln->y0 + (double)ln->first * d->step_y, c->H);
    G->fx0 = ln->x0 + (double)ln->first * d->step_x - (double)G->tx0;
    G->fy0 = ln->y0 + (double)ln->first * d->step_y - (double)G->ty0;
    if (!integral || g->sampling == HFVIS_SSAO_SAMPLING_BILINEAR || real) return;
    tlx = (double)G->tx0 + (double)(ln->count - 1) * d->step_x;
    tly = (double)G->ty0 + (double)(ln->count - 1) * d->step_y;
    G->fast = tlx >= 0.0 && tlx <= (double)(c->W - 1) && tly >= 0.0 && tly <= (double)(c->H - 1);
}

/* ss_line_points' common case (ss_lgeom.fast) written out: the line's n depths read at dp,
 * dp + dstep, ... (the depth buffer, or the line's depths already gathered, dstep 1), texel
 * (tx0, ty0) stepped by (sx, sy), the unprojection and the plane coordinates inline with the
 * same arithmetic (the same bits). Returns the largest |x|, |y|. */
static double ss_line_points_inside(const ss_cam *c, const ss_cfg *g, const float *dp,
                                    ptrdiff_t dstep, int n, int tx0, int ty0, int sx, int sy,
                                    const double e1[3], const double yh[3], double *x, double *y,
                                    float *zs)
{
    double m = 0.0;
    const double cx = c->cx, cy = c->cy, ifx = c->ifx, ify = c->ify, osx = c->sx, osy = c->sy,
                 far_d = c->far_d, e0 = e1[0], e1y = e1[1], e2 = e1[2], y0 = yh[0], y1 = yh[1],
                 y2 = yh[2];
    int k, tx = tx0, ty = ty0, persp = c->persp, exact = g->exact;
    for (k = 0; k < n; k++, dp += dstep, tx += sx, ty += sy) {
        double z = (double)*dp, u = (double)tx + 0.5, v = (double)ty + 0.5, q0, q1, q2, xk, yk;
        if (!(z > 0.0 && z < far_d)) { /* ss_bg: background */
            if (zs) zs[k] = (float)HFVIS__NAN;
            x[k] = y[k] = HFVIS__NAN;
            continue;
        }
        if (zs) zs[k] = (float)z;
        if (persp) {
            q0 = (u - cx) * z * ifx;
            q1 = -(v - cy) * z * ify;
        } else {
            q0 = (u - cx) * osx;
            q1 = -(v - cy) * osy;
        }
        q2 = -z;
        xk = x[k] = q0 * e0 + q1 * e1y + q2 * e2;
        yk = y[k] = exact ? q0 * y0 + q1 * y1 + q2 * y2 : q2;
        xk = fabs(xk);
        yk = fabs(yk);
        m = xk > m ? xk : m;
        m = yk > m ? yk : m;
    }
    return m;
}

/* The 2D samples of one lattice line (its geometry G): x, y (NaN at holes), real-tangent sines
 * (if wanted), sample depths. In the common case (G->fast) only steps k0 .. k0 + n - 1 (written
 * from x[0]), their depths read from zline[k0...] if the caller gathered them (else NULL);
 * otherwise the whole line (k0 = 0, n = count). Returns the largest |x|, |y| where the common
 * case finds it on the way, else -1 (ss_hull_line's scale). */
static double ss_line_points(const ss_cam *c, const ss_cfg *g, const float *depth,
                             const float *normals, const hfvis_ssao_lattice *L,
                             const hfvis_ssao_line *ln, const ss_lgeom *G, const float *zline,
                             int k0, int n, double *x, double *y, double *st_real, float *zs)
{
    const hfvis_ssao_direction *d = &L->dir;
    const double *e1 = G->e1, *yh = G->yh, fx0 = G->fx0, fy0 = G->fy0;
    double amax = -1.0;
    int bil = g->sampling == HFVIS_SSAO_SAMPLING_BILINEAR, k, tx0 = G->tx0, ty0 = G->ty0;
    int integral = d->step_x == floor(d->step_x) && d->step_y == floor(d->step_y) &&
                   fabs(d->step_x) < 1e9 && fabs(d->step_y) < 1e9;
    if (G->fast) {
        const int sx = (int)d->step_x, sy = (int)d->step_y;
        const float *dp = zline ? zline + k0 : depth + ss_index(c, tx0 + k0 * sx, ty0 + k0 * sy);
        ptrdiff_t dstep = zline ? 1 : (ptrdiff_t)sy * c->row_step + (ptrdiff_t)sx;
        return ss_line_points_inside(c, g, dp, dstep, n, tx0 + k0 * sx, ty0 + k0 * sy, sx, sy, e1,
                                     yh, x, y, zs);
    }
    for (k = 0; k < ln->count; k++) {
        int i = ln->first + k, tx, ty;
        double u = ln->x0 + (double)i * d->step_x, v = ln->y0 + (double)i * d->step_y, qu, qv, z,
               Q[3];
        if (integral) { /* box patterns: integer offsets from the first texel ([P3] §5.2) */
            tx = ss_clampi(tx0 + k * (int)d->step_x, 0, c->W - 1);
            ty = ss_clampi(ty0 + k * (int)d->step_y, 0, c->H - 1);
            if (bil) { /* integer part exact, the same fraction at every step */
                u = (double)(tx0 + k * (int)d->step_x) + fx0;
                v = (double)(ty0 + k * (int)d->step_y) + fy0;
            }
        } else {
            tx = ss_texel(u, c->W);
            ty = ss_texel(v, c->H);
        }
        if (bil) {
            z = ss_sample(c, depth, 1, u, v, tx, ty, &qu, &qv);
        } else { /* ss_sample's NEAREST branch, inline */
            z = ss_tex(c, depth, tx, ty);
            if (ss_bg(c, z)) z = HFVIS__NAN;
            qu = (double)tx + 0.5;
            qv = (double)ty + 0.5;
            if (g->exact && !integral) ss_onto_line(ln->x0, ln->y0, d->dx, d->dy, &qu, &qv);
        }
        if (zs) zs[k] = (float)z;
        if (z != z) {
            x[k] = y[k] = HFVIS__NAN;
            if (st_real) st_real[k] = g->fixed;
            continue;
        }
        ss_unproject(c, qu, qv, z, Q);
        x[k] = ss_dot3(Q, e1);
        y[k] = g->exact ? ss_dot3(Q, yh) : Q[2];
        if (st_real) {
            double ux = 0.0, uy = 1.0;
            if (c->persp) {
                double r = sqrt(x[k] * x[k] + y[k] * y[k]);
                ux = -x[k] / r;
                uy = -y[k] / r;
            }
            st_real[k] = ss_real_sin_t(c, normals, tx, ty, e1, yh, g->exact, ux, uy, 1.0, g->fixed);
        }
    }
    return amax;
}

#define SS_CLIP_SAFETY 1e-6 /* relative margin of ss_line_clip's bound over the rounding of the
                               hull's support test (about 1e-15 relative) */

/* Steps ka .. kb (*ka > *kb: none) of line ln whose texels lie within m pixels of the inner
 * image: the receivers hfvis_lsao's gather may read (nearest, fallback or bilinear). */
static void ss_line_inner(const ss_cam *c, const hfvis_ssao_lattice *L, const hfvis_ssao_line *ln,
                          const ss_lgeom *G, double m, int *ka, int *kb)
{
    const double S[2] = {L->dir.step_x, L->dir.step_y};
    const double P0[2] = {(double)G->tx0 + 0.5, (double)G->ty0 + 0.5};
    const double lo[2] = {(double)c->gx - m, (double)c->gy - m};
    const double hi[2] = {(double)(c->W - c->gx) + m, (double)(c->H - c->gy) + m};
    double klo = 0.0, khi = (double)(ln->count - 1);
    if (!ss_box_span(P0, S, lo, hi, &klo, &khi)) khi = -1.0;
    klo = ceil(klo);
    khi = floor(khi);
    if (khi < klo) {
        *ka = 1;
        *kb = 0;
        return;
    }
    *ka = (int)klo;
    *kb = (int)khi;
}

/* r_k = (L_k, M_k) of ss_line_clip: the ray of step k of common-case line G in its plane. */
static void ss_clip_ray(const ss_cam *c, const ss_lgeom *G, int exact, double sx, double sy, int k,
                        double *Lk, double *Mk)
{
    double u = (double)G->tx0 + (double)k * sx + 0.5 - c->cx,
           v = -((double)G->ty0 + (double)k * sy + 0.5 - c->cy);
    if (c->persp) {
        u *= c->ifx;
        v *= c->ify;
        *Lk = u * G->e1[0] + v * G->e1[1];
        *Mk = exact ? u * G->yh[0] + v * G->yh[1] - G->yh[2] : -1.0;
    } else {
        *Lk = u * c->sx * G->e1[0] + v * c->sy * G->e1[1];
        *Mk = 0.0;
    }
}

/* The first step s0 <= ka of a common-case line (G) that the receivers ka .. kb can reach within
 * the falloff's support S: every step before s0 has Occ = st for each of them ([P3] Eq. 2 with
 * rho = 0), and can hide only steps before it, so the hull's answers for ka .. kb do not change
 * without them. The bound: sample k at texel centre (u, v) is z r_k in the plane with
 * r_k = (L_k, M_k) affine in k (perspective: L = e1 . ((u - cx)/fx, -(v - cy)/fy, 0), M = -1
 * on the paper plane, yhat . (.., .., -1) on the exact one), so for a receiver i and a
 * candidate j, |h| >= dist(z_i r_i, the ray of r_j) = z_i |r_i x r_j| / |r_j|; |r_i x r_j| is
 * affine in i and in j and 0 at i = j, so for i >= ka > j it is at least |r_ka x r_j|, growing
 * as j goes back; z_i >= zlo (the receivers' least depth) and |r_j| <= rmax (the line's ends:
 * |r|^2 is convex in k). Orthographic: x = L_k whatever the depth, so |h| >= |L_ka - L_j|. */
static int ss_line_clip(const ss_cam *c, const hfvis_ssao_lattice *L, const hfvis_ssao_line *ln,
                        const ss_lgeom *G, int exact, int ka, double zlo, double S)
{
    const double sx = L->dir.step_x, sy = L->dir.step_y;
    double La, Ma, rmax = 0.0, need;
    int j, e;
    if (!(S < HFVIS__INF) || ka <= 0) return 0;
    if (!(zlo < HFVIS__INF)) return ka; /* every receiver is background: no candidate matters */
    ss_clip_ray(c, G, exact, sx, sy, ka, &La, &Ma);
    for (e = 0; e < 2 && c->persp; e++) {
        double Le, Me, r;
        ss_clip_ray(c, G, exact, sx, sy, e ? ln->count - 1 : 0, &Le, &Me);
        r = sqrt(Le * Le + Me * Me);
        if (r > rmax) rmax = r;
    }
    need = c->persp ? S * (1.0 + SS_CLIP_SAFETY) * rmax : S * (1.0 + SS_CLIP_SAFETY);
    for (j = ka - 1; j >= 0; j--) {
        double Lj, Mj, b;
        ss_clip_ray(c, G, exact, sx, sy, j, &Lj, &Mj);
        b = c->persp ? zlo * fabs(La * Mj - Lj * Ma) : fabs(La - Lj);
        if (b >= need) return j + 1;
    }
    return 0;
}

/* Sweep (or brute-force) every line of a direction into values / sample depths, sample s at
 * values[vs s] and sdepth[vs s] (hfvis_lsao interleaves them, vs = 2, so its gather reads one
 * cache line per sample). scratch: 4*M doubles (x, y, sin t, out), M more floats with vs != 1;
 * stack: M ints; zline: M floats (with clip >= 0, else unused).
 * clip >= 0 (hfvis_lsao, whose gather reads only samples near the inner image): a common-case
 * line is swept only over its receivers within clip pixels of the inner image (ss_line_inner)
 * and the steps before them that those reach within the falloff's support (ss_line_clip); its
 * other samples are NaN (value and depth). With the guard band and a short support that is a
 * quarter fewer samples; the answers of the receivers read are unchanged up to the hull's
 * rounding (test_ssao lsao_clip_short_support). */
static void ss_lsao_sweep_dir(const ss_cam *c, const ss_cfg *g, const float *depth,
                              const float *normals, const hfvis_ssao_lattice *L,
                              const hfvis_ssao_line *lines, double *scratch, int *stack,
                              float *zline, double clip, int naive, float *values, float *sdepth,
                              size_t vs)
{
    int M = L->max_line_samples, j, k;
    double *x = scratch, *y = scratch + M, *st = scratch + 2 * (size_t)M,
           *out = scratch + 3 * (size_t)M;
    float *zs = (float *)(void *)(scratch + 4 * (size_t)M); /* vs != 1: the line's depths */
    int real = g->tangent != HFVIS_SSAO_TANGENT_FIXED;
    const ptrdiff_t dstep = (ptrdiff_t)L->dir.step_y * c->row_step + (ptrdiff_t)L->dir.step_x;
    const double far_d = c->far_d;
    for (j = 0; j < L->line_count; j++) {
        const hfvis_ssao_line *ln = &lines[j];
        const double *stc, *ste;
        const float *zl = NULL;
        ss_lgeom G;
        double amax;
        int k0 = 0, n = ln->count;
        if (ln->count < 1) continue;
        ss_line_geom(c, g, L, ln, real, &G);
        if (G.fast && clip >= 0.0) {
            const float *src = depth + ss_index(c, G.tx0, G.ty0);
            double zlo = HFVIS__INF;
            int ka, kb;
            ss_line_inner(c, L, ln, &G, clip, &ka, &kb);
            n = 0;
            if (ka <= kb) { /* the receivers' depths, their least, then the steps they reach */
                for (k = ka; k <= kb; k++) {
                    float zf = src[(ptrdiff_t)k * dstep];
                    double z = (double)zf;
                    zline[k] = zf;
                    if (z > 0.0 && z < far_d && z < zlo) zlo = z;
                }
                k0 = ss_line_clip(c, L, ln, &G, g->exact, ka, zlo, g->fall.support);
                for (k = k0; k < ka; k++) zline[k] = src[(ptrdiff_t)k * dstep];
                n = kb - k0 + 1;
                zl = zline;
            }
        }
        if (n > 0) {
            amax = ss_line_points(c, g, depth, normals, L, ln, &G, zl, k0, n, x, y,
                                  real ? st : NULL,
                                  vs != 1 ? zs : sdepth ? sdepth + ln->offset + (size_t)k0 : NULL);
            stc = g->tangent == HFVIS_SSAO_TANGENT_REAL ? st : NULL;
            ste = real ? st : NULL;
            if (naive)
                ss_hull_line_naive(x, y, stc, ste, n, c->persp, g->fixed, &g->fall, out);
            else
                ss_hull_line_scratch(x, y, stc, ste, n, c->persp, g->fixed, &g->fall, g->ties, amax,
                                     stack, out);
        }
        if (vs == 1) {
            for (k = 0; k < n; k++) values[ln->offset + (size_t)(k0 + k)] = (float)out[k];
        } else {
            float *vo = values + vs * ln->offset, *zo = sdepth + vs * ln->offset;
            for (k = 0; k < k0; k++) vo[vs * (size_t)k] = zo[vs * (size_t)k] = (float)HFVIS__NAN;
            for (k = 0; k < n; k++) {
                vo[vs * (size_t)(k0 + k)] = (float)out[k];
                zo[vs * (size_t)(k0 + k)] = zs[k];
            }
            for (k = k0 + n; k < ln->count; k++)
                vo[vs * (size_t)k] = zo[vs * (size_t)k] = (float)HFVIS__NAN;
        }
    }
}

/* A caller's lattice is consistent: every line within max_line_samples and sample_count, the
 * lines stored back to back (the buffers and the scratch are sized from these counts). */
static int ss_lattice_ok(const hfvis_ssao_lattice *L, const hfvis_ssao_line *lines)
{
    size_t off = 0;
    int j;
    if (!L || !lines || !ss_dir_ok(&L->dir) || L->line_count < 0 || L->max_line_samples < 0 ||
        !isfinite(L->s_first) || !isfinite(L->t_min) || !isfinite(L->px) || !isfinite(L->py))
        return 0;
    for (j = 0; j < L->line_count; j++) {
        const hfvis_ssao_line *ln = &lines[j];
        if (ln->count < 0 || ln->count > L->max_line_samples || ln->offset != off ||
            !isfinite(ln->x0) || !isfinite(ln->y0) ||
            (ln->count > 0 && ln->first > INT_MAX - ln->count))
            return 0;
        off += (size_t)ln->count;
        if (off > L->sample_count) return 0;
    }
    return 1;
}

static hfvis_status ss_lsao_direction(const hfvis_camera *cam, const float *depth,
                                      const float *normals, const hfvis_lsao_options *opts,
                                      const hfvis_ssao_lattice *lat, const hfvis_ssao_line *lines,
                                      float *values, float *sample_depth, int naive)
{
    ss_cam c;
    ss_cfg g;
    hfvis_lsao_options o;
    size_t M, bytes, nb = 0;
    void *blk;
    float *nrm = NULL;
    if (ss_cam_load(cam, &c) != HFVIS_OK || hfvis_lsao_options_resolve(opts, &o) != HFVIS_OK ||
        !depth || !values || !ss_lattice_ok(lat, lines))
        return HFVIS_ERR_INVALID_ARGUMENT;
    ss_cfg_from_lsao(&o, &g);
    M = (size_t)lat->max_line_samples;
    if (M == 0) return HFVIS_OK;
    bytes = ss_bytes3(M, 1, 4 * sizeof(double) + sizeof(int));
    if (!bytes) return HFVIS_ERR_OUT_OF_MEMORY;
    if (g.tangent != HFVIS_SSAO_TANGENT_FIXED && !normals) {
        nb = ss_bytes3((size_t)c.stride, (size_t)c.H, 3 * sizeof(float));
        nrm = (float *)hfvis__alloc(o.alloc, nb);
        if (!nrm) return HFVIS_ERR_OUT_OF_MEMORY;
        ss_normals_fill(&c, depth, nrm);
        normals = nrm;
    }
    blk = hfvis__alloc(o.alloc, bytes);
    if (!blk) {
        hfvis__free(o.alloc, nrm);
        return HFVIS_ERR_OUT_OF_MEMORY;
    }
    ss_lsao_sweep_dir(&c, &g, depth, normals, lat, lines, (double *)blk,
                      (int *)((double *)blk + 4 * M), NULL, -1.0, naive, values, sample_depth, 1);
    hfvis__free(o.alloc, blk);
    hfvis__free(o.alloc, nrm);
    return HFVIS_OK;
}

hfvis_status hfvis_lsao_direction(const hfvis_camera *cam, const float *depth,
                                  const float *normals, const hfvis_lsao_options *opts,
                                  const hfvis_ssao_lattice *lat, const hfvis_ssao_line *lines,
                                  float *values, float *sample_depth)
{
    return ss_lsao_direction(cam, depth, normals, opts, lat, lines, values, sample_depth, 0);
}

hfvis_status hfvis_lsao_direction_naive(const hfvis_camera *cam, const float *depth,
                                        const float *normals, const hfvis_lsao_options *opts,
                                        const hfvis_ssao_lattice *lat,
                                        const hfvis_ssao_line *lines, float *values,
                                        float *sample_depth)
{
    return ss_lsao_direction(cam, depth, normals, opts, lat, lines, values, sample_depth, 1);
}

/* Is lattice sample (j, i) acceptable for receiver depth zc / normal nc? Writes its value.
 * Sample s is at values[vs s], sdepth[vs s]. */
static int ss_accept(const ss_cam *c, const ss_cfg *g, const float *normals,
                     const hfvis_ssao_lattice *L, const hfvis_ssao_line *ln, int i,
                     const float *values, const float *sdepth, size_t vs, double zc,
                     const float *nc, double *val)
{
    size_t idx;
    double v, zs;
    if (i < ln->first || i >= ln->first + ln->count) return 0;
    idx = vs * (ln->offset + (size_t)(i - ln->first));
    v = (double)values[idx];
    zs = (double)sdepth[idx];
    if (v != v || zs != zs) return 0;
    if (g->rej_z >= 0.0 && fabs(zs - zc) > g->rej_z * zc) return 0;
    if (normals && g->rej_n > -1.0) {
        int tx = ss_texel(ln->x0 + (double)i * L->dir.step_x, c->W);
        int ty = ss_texel(ln->y0 + (double)i * L->dir.step_y, c->H);
        const float *ns = normals + 3 * ss_index(c, tx, ty);
        double dot = (double)ns[0] * (double)nc[0] + (double)ns[1] * (double)nc[1] +
                     (double)ns[2] * (double)nc[2];
        if (!(dot >= g->rej_n)) return 0;
    }
    *val = v;
    return 1;
}

/* The nearest accepted sample within radius R2 (squared) of (u, v) (docs/errata.md E23). */
static int ss_fallback(const ss_cam *c, const ss_cfg *g, const float *normals,
                       const hfvis_ssao_lattice *L, const hfvis_ssao_line *lines,
                       const float *values, const float *sdepth, size_t vs, double u, double v,
                       double zc, const float *nc, double R, double *val)
{
    const hfvis_ssao_direction *d = &L->dir;
    double jf = (u * L->px + v * L->py - L->s_first) / d->spacing;
    double tf = (u * d->dx + v * d->dy - L->t_min) / d->step;
    int a = (int)ceil(R / d->spacing), b = (int)ceil(R / d->step), j0 = (int)floor(jf + 0.5),
        i0 = (int)floor(tf + 0.5), j, i, found = 0;
    double best = R * R, bv = 0.0;
    for (j = j0 - a; j <= j0 + a; j++) {
        const hfvis_ssao_line *ln;
        if (j < 0 || j >= L->line_count) continue;
        ln = &lines[j];
        for (i = i0 - b; i <= i0 + b; i++) {
            double su = ln->x0 + (double)i * d->step_x - u, sv = ln->y0 + (double)i * d->step_y - v;
            double dd = su * su + sv * sv, vv;
            if (dd > best || (found && dd == best)) continue;
            if (!ss_accept(c, g, normals, L, ln, i, values, sdepth, vs, zc, nc, &vv)) continue;
            best = dd;
            bv = vv;
            found = 1;
        }
    }
    *val = bv;
    return found;
}

#define SS_GATHER_GROUP 4 /* directions swept, then gathered in one pass (hfvis_lsao) */
#define SS_GATHER_TILE 16 /* pixels gathered in 16 x 16 tiles: four directions' samples stay in L1 */

/* One direction of the gather: its lattice, lines, values and sample depths, and the constants
 * of its pixel-to-lattice map (in locals: loaded from the lattice at every pixel, they were
 * reloaded after every store to the accumulators, which may alias them). */
typedef struct ss_gdir {
    const hfvis_ssao_lattice *L;
    const hfvis_ssao_line *lines;
    const float *values, *sdepth;
    size_t vs; /* sample s at values[vs s], sdepth[vs s] */
    double w, ids, idl, R2, px, py, s_first, ddx, ddy, t_min, jmax;
    int empty;  /* no lines */
    int all_in; /* every inner pixel's rounded line and step lie inside the lattice */
} ss_gdir;

static void ss_gdir_set(const ss_cam *c, ss_gdir *G, const hfvis_ssao_lattice *L,
                        const hfvis_ssao_line *lines, const float *values, const float *sdepth,
                        size_t vs)
{
    const hfvis_ssao_direction *d = &L->dir;
    int k;
    G->L = L;
    G->lines = lines;
    G->values = values;
    G->sdepth = sdepth;
    G->vs = vs;
    G->w = d->weight;
    G->ids = 1.0 / d->step;
    G->idl = 1.0 / d->spacing;
    G->R2 = 2.0 * sqrt(0.25 * d->step * d->step + 0.25 * d->spacing * d->spacing);
    G->px = L->px;
    G->py = L->py;
    G->s_first = L->s_first;
    G->ddx = d->dx;
    G->ddy = d->dy;
    G->t_min = L->t_min;
    G->jmax = (double)L->line_count - 0.5;
    G->empty = L->line_count < 1;
    /* the gather's range test at the inner image's four corner pixels, in its own arithmetic:
     * each step of it is monotone in u and in v, so the corners bound every pixel between */
    G->all_in = !G->empty;
    for (k = 0; k < 4; k++) {
        double u = (k & 1 ? (double)(c->W - c->gx) : (double)c->gx) + (k & 1 ? -0.5 : 0.5),
               v = (k & 2 ? (double)(c->H - c->gy) : (double)c->gy) + (k & 2 ? -0.5 : 0.5);
        double jf = (u * G->px + v * G->py - G->s_first) * G->idl,
               tf = (u * G->ddx + v * G->ddy - G->t_min) * G->ids;
        if (!(jf > -0.5 && jf < G->jmax && tf > -0.5 && tf < 2147483647.0)) G->all_in = 0;
    }
}

/* Direction G's value for the receiver at (u, v) of depth zc (normal nc or NULL): 1 and *val if a
 * sample is accepted, else 0. */
static inline int ss_gather_at(const ss_cam *c, const ss_cfg *g, const float *normals, const ss_gdir *G,
                        double u, double v, double zc, const float *nc, double *val)
{
    const hfvis_ssao_lattice *L = G->L;
    const hfvis_ssao_line *lines = G->lines;
    const float *values = G->values, *sdepth = G->sdepth;
    const size_t vstr = G->vs;
    double jf = (u * G->px + v * G->py - G->s_first) * G->idl, tf = (u * G->ddx + v * G->ddy - G->t_min) * G->ids;
    int ok = 0, nlines = L->line_count;
    *val = 0.0;
    if (g->gather == HFVIS_SSAO_GATHER_NEAREST) {
        int j, i;
        /* fast path of ss_nearest: the rounded line and step lie inside the lattice */
        if (jf > -0.5 && jf < G->jmax && tf > -0.5 && tf < 2147483647.0) {
            const hfvis_ssao_line *ln;
            j = (int)(jf + 0.5);
            i = (int)(tf + 0.5);
            ln = &lines[j];
            if (i >= ln->first && i < ln->first + ln->count) {
                size_t idx = vstr * (ln->offset + (size_t)(i - ln->first));
                double zs = (double)sdepth[idx];
                *val = (double)values[idx];
                ok = *val == *val && zs == zs && (g->rej_z < 0.0 || fabs(zs - zc) <= g->rej_z * zc);
                if (ok && nc) ok = ss_accept(c, g, normals, L, ln, i, values, sdepth, vstr, zc, nc, val);
                goto have;
            }
        }
        if (ss_nearest(L, lines, u, v, &j, &i))
            ok = ss_accept(c, g, normals, L, &lines[j], i, values, sdepth, vstr, zc, nc, val);
    } else {
        double fj = floor(jf), fi = floor(tf), aj = jf - fj, ai = tf - fi, ws = 0.0, vs = 0.0;
        int dj, di;
        for (dj = 0; dj < 2; dj++)
            for (di = 0; di < 2; di++) {
                double wt = (dj ? aj : 1.0 - aj) * (di ? ai : 1.0 - ai), vv;
                double jj = fj + (double)dj, ii = fi + (double)di;
                if (!(wt > 0.0) || jj < 0.0 || jj >= (double)nlines) continue;
                if (!ss_accept(c, g, normals, L, &lines[(int)jj], (int)ii, values, sdepth, vstr, zc, nc, &vv))
                    continue;
                ws += wt;
                vs += wt * vv;
            }
        if (ws > 0.0) {
            *val = vs / ws;
            ok = 1;
        }
    }
have:
    if (!ok) ok = ss_fallback(c, g, normals, L, lines, values, sdepth, vstr, u, v, zc, nc, G->R2, val);
    return ok;
}

/* Gather nd directions into sum / weight (inner pixels, row-major W) in one pass over the
 * pixels: each pixel's two accumulators are read once, the directions' terms added in order (the
 * same additions as one pass per direction), and written once. With a few directions per pass
 * (hfvis_lsao: SS_GATHER_GROUP), the pixel loop, the depth test and the accumulators' loads and
 * stores are shared by the group. */
static void ss_gather_dirs(const ss_cam *c, const ss_cfg *g, const float *depth,
                           const float *normals, const ss_gdir *G, int nd, double *sum, double *wsum)
{
    int W = c->W - 2 * c->gx, x, y, k, tx, ty;
    const int x_end = c->W - c->gx, y_end = c->H - c->gy;
    const double far_d = c->far_d, rej_z = g->rej_z;
    /* ss_gather_at's first case inline, with the constants in locals (its store to *val may
     * alias them): NEAREST without normals, the rounded sample inside its line and accepted by
     * the depth test; everything else (the same value where this case accepts) through it */
    const int inline_nearest = g->gather == HFVIS_SSAO_GATHER_NEAREST && !normals;
    /* pixels in tiles (each pixel's sums are its own, so the order does not matter): along a
     * row, a direction across the rows reads a new line, a new cache line, at every pixel; in a
     * tile the next row reads the neighbouring samples of the same lines while they are cached */
    for (ty = c->gy; ty < y_end; ty += SS_GATHER_TILE)
    for (tx = c->gx; tx < x_end; tx += SS_GATHER_TILE)
    for (y = ty; y < y_end && y < ty + SS_GATHER_TILE; y++) {
        double v = (double)y + 0.5;
        const float *drow = depth + ss_index(c, 0, y);
        size_t orow = (size_t)(y - c->gy) * (size_t)W - (size_t)c->gx; /* + x: pixel x's slot (mod 2^n) */
        for (x = tx; x < x_end && x < tx + SS_GATHER_TILE; x++) {
            double u = (double)x + 0.5, zc = (double)drow[x], s, ws, rz;
            const float *nc = normals ? normals + 3 * ss_index(c, x, y) : NULL;
            if (!(zc > 0.0 && zc < far_d)) continue; /* ss_bg */
            rz = rej_z < 0.0 ? HFVIS__INF : rej_z * zc; /* the depth test's bound; off: any depth */
            s = sum[orow + (size_t)x];
            ws = wsum[orow + (size_t)x];
            for (k = 0; k < nd; k++) {
                const ss_gdir *Gk = &G[k];
                double val;
                if (Gk->empty) continue;
                if (inline_nearest) {
                    double jf = (u * Gk->px + v * Gk->py - Gk->s_first) * Gk->idl,
                           tf = (u * Gk->ddx + v * Gk->ddy - Gk->t_min) * Gk->ids;
                    if (Gk->all_in || (jf > -0.5 && jf < Gk->jmax && tf > -0.5 && tf < 2147483647.0)) {
                        const hfvis_ssao_line *ln = &Gk->lines[(int)(jf + 0.5)];
                        int i = (int)(tf + 0.5);
                        if (i >= ln->first && i < ln->first + ln->count) {
                            size_t idx = Gk->vs * (ln->offset + (size_t)(i - ln->first));
                            double zs = (double)Gk->sdepth[idx];
                            val = (double)Gk->values[idx];
                            if (val == val && fabs(zs - zc) <= rz) { /* false for a NaN depth */
                                s += Gk->w * val;
                                ws += Gk->w;
                                continue;
                            }
                        }
                    }
                }
                if (!ss_gather_at(c, g, normals, Gk, u, v, zc, nc, &val)) continue;
                s += Gk->w * val;
                ws += Gk->w;
            }
            sum[orow + (size_t)x] = s;
            wsum[orow + (size_t)x] = ws;
        }
    }
}

hfvis_status hfvis_lsao_gather(const hfvis_camera *cam, const float *depth, const float *normals,
                               const hfvis_lsao_options *opts, const hfvis_ssao_lattice *lat,
                               const hfvis_ssao_line *lines, const float *values,
                               const float *sample_depth, double *sum, double *weight)
{
    ss_cam c;
    ss_cfg g;
    ss_gdir G;
    hfvis_lsao_options o;
    if (ss_cam_load(cam, &c) != HFVIS_OK || hfvis_lsao_options_resolve(opts, &o) != HFVIS_OK ||
        !depth || !values || !sample_depth || !sum || !weight || !ss_lattice_ok(lat, lines) ||
        !isfinite(lat->dir.weight))
        return HFVIS_ERR_INVALID_ARGUMENT;
    ss_cfg_from_lsao(&o, &g);
    ss_gdir_set(&c, &G, lat, lines, values, sample_depth, 1);
    ss_gather_dirs(&c, &g, depth, normals, &G, 1, sum, weight);
    return HFVIS_OK;
}

/* Final AO of accumulators into ao (inner pixels). */
static void ss_finish(const ss_cam *c, const float *depth, const double *sum, const double *wsum,
                      float *ao, ptrdiff_t ao_stride)
{
    int W = c->W - 2 * c->gx, H = c->H - 2 * c->gy, x, y;
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++) {
            size_t o = (size_t)y * (size_t)W + (size_t)x;
            double a = 0.0;
            if (!ss_bg(c, ss_tex(c, depth, x + c->gx, y + c->gy)) && wsum[o] > 0.0) {
                a = sum[o] / wsum[o];
                a = a > 0.0 ? (a < 1.0 ? a : 1.0) : 0.0;
            }
            ao[(ptrdiff_t)y * ao_stride + x] = (float)a;
        }
}

hfvis_status hfvis_lsao(const hfvis_camera *cam, const float *depth, const float *normals,
                        const hfvis_lsao_options *opts, float *ao, ptrdiff_t ao_stride)
{
    ss_cam c;
    ss_cfg g;
    hfvis_lsao_options o;
    hfvis_ssao_direction *dirs = NULL;
    hfvis_ssao_lattice lat, glat[SS_GATHER_GROUP];
    ss_gdir G[SS_GATHER_GROUP];
    hfvis_ssao_line *lines = NULL;
    float *nrm = NULL, *vals = NULL;
    double *scratch = NULL, *acc = NULL;
    size_t maxs = 0, npix, b, ms, ml;
    int K, k, k0, maxl = 0, maxm = 0, W, H;
    hfvis_status s = HFVIS_OK;
    if (ss_cam_load(cam, &c) != HFVIS_OK || hfvis_lsao_options_resolve(opts, &o) != HFVIS_OK ||
        !depth || !ao)
        return HFVIS_ERR_INVALID_ARGUMENT;
    W = c.W - 2 * c.gx;
    H = c.H - 2 * c.gy;
    if (ao_stride < W || !hfvis__plane_fits(ao_stride, H, 1)) return HFVIS_ERR_INVALID_ARGUMENT;
    ss_cfg_from_lsao(&o, &g);
    K = o.directions;
    if (!hfvis__mul_size((size_t)W, (size_t)H, &npix)) return HFVIS_ERR_LIMIT;
    dirs = (hfvis_ssao_direction *)hfvis__alloc(o.alloc, sizeof *dirs * (size_t)K);
    if (!dirs) return HFVIS_ERR_OUT_OF_MEMORY;
    ss_lsao_dirs(&o, dirs);
    for (k = 0; k < K; k++) {
        s = ss_lattice_init(&c, &dirs[k], &lat);
        if (s != HFVIS_OK) goto done;
        if (lat.line_count > maxl) maxl = lat.line_count;
        if (lat.max_line_samples > maxm) maxm = lat.max_line_samples;
        if (lat.sample_count > maxs) maxs = lat.sample_count;
    }
    s = HFVIS_ERR_OUT_OF_MEMORY;
    if (g.tangent != HFVIS_SSAO_TANGENT_FIXED && !normals) {
        b = ss_bytes3((size_t)c.stride, (size_t)c.H, 3 * sizeof(float));
        if (!b || !(nrm = (float *)hfvis__alloc(o.alloc, b))) goto done;
        ss_normals_fill(&c, depth, nrm);
    }
    ml = (size_t)(maxl > 0 ? maxl : 1);
    ms = maxs > 0 ? maxs : 1;
    b = ss_bytes3(ml, SS_GATHER_GROUP, sizeof *lines);
    if (!b || !(lines = (hfvis_ssao_line *)hfvis__alloc(o.alloc, b))) goto done;
    b = ss_bytes3(ms, 2 * SS_GATHER_GROUP, sizeof(float));
    if (!b || !(vals = (float *)hfvis__alloc(o.alloc, b))) goto done;
    b = ss_bytes3((size_t)(maxm > 0 ? maxm : 1), 1,
                  5 * sizeof(double) + sizeof(int) + sizeof(float));
    if (!b || !(scratch = (double *)hfvis__alloc(o.alloc, b))) goto done;
    b = ss_bytes3(npix, 2, sizeof(double));
    if (!b || !(acc = (double *)hfvis__alloc(o.alloc, b))) goto done;
    for (b = 0; b < 2 * npix; b++) acc[b] = 0.0;
    for (k0 = 0; k0 < K; k0 += SS_GATHER_GROUP) { /* sweep a group of directions, gather it */
        int nd = K - k0 < SS_GATHER_GROUP ? K - k0 : SS_GATHER_GROUP;
        for (k = 0; k < nd; k++) {
            hfvis_ssao_line *lk = lines + (size_t)k * ml;
            float *vk = vals + (size_t)k * 2 * ms;
            int *stk = (int *)(scratch + 5 * (size_t)(maxm > 0 ? maxm : 1));
            const double st = dirs[k0 + k].step, sp = dirs[k0 + k].spacing;
            /* the gather reads samples within its fallback radius (the cell's diagonal) of an
             * inner pixel, bilinear a cell away, and the texels lie within a pixel of the
             * lattice's points: clip to the inner image widened by all of that */
            const double clip = sqrt(st * st + sp * sp) + st + sp + 2.0;
            ss_lattice_init(&c, &dirs[k0 + k], &glat[k]);
            ss_lattice_fill(&c, &glat[k], lk);
            ss_lsao_sweep_dir(&c, &g, depth, nrm ? nrm : normals, &glat[k], lk, scratch, stk,
                              (float *)(void *)(stk + (maxm > 0 ? maxm : 1)), clip, 0, vk, vk + 1, 2);
            ss_gdir_set(&c, &G[k], &glat[k], lk, vk, vk + 1, 2);
        }
        ss_gather_dirs(&c, &g, depth, normals, G, nd, acc, acc + npix);
    }
    ss_finish(&c, depth, acc, acc + npix, ao, ao_stride);
    s = HFVIS_OK;
done:
    hfvis__free(o.alloc, acc);
    hfvis__free(o.alloc, scratch);
    hfvis__free(o.alloc, vals);
    hfvis__free(o.alloc, lines);
    hfvis__free(o.alloc, nrm);
    hfvis__free(o.alloc, dirs);
    return s;
}

/* ========================================================================================== */
/* 6. HBAO (Bavoil, Sainz, Dimitrov 2008; [T14] §4.1, [P4] §8, Fig. 8; docs/errata.md E25)      */
/* ========================================================================================== */

#define SS_HBAO_DEFAULT_K 16 /* as LSAO: no paper asks HBAO for fewer */

hfvis_hbao_options hfvis_hbao_options_default(void)
{
    hfvis_hbao_options o;
    memset(&o, 0, sizeof o);
    o.directions = SS_HBAO_DEFAULT_K;
    o.variant = HFVIS_HBAO_INCREMENTAL;
    o.step_px = 1.0;
    o.falloff.kind = HFVIS_FALLOFF_NONE;
    o.tangent = HFVIS_SSAO_TANGENT_REAL;
    o.fixed_sin_t = SS_DEFAULT_SIN_T;
    o.sampling = HFVIS_SSAO_SAMPLING_NEAREST;
    o.plane = HFVIS_SSAO_PLANE_EXACT;
    o.jitter = HFVIS_HBAO_JITTER_NONE;
    return o;
}

hfvis_status hfvis_hbao_options_resolve(const hfvis_hbao_options *in, hfvis_hbao_options *out)
{
    hfvis_hbao_options o;
    int K, k;
    if (!out) return HFVIS_ERR_INVALID_ARGUMENT;
    if (in) o = *in;
    else memset(&o, 0, sizeof o);
    K = o.directions ? o.directions : SS_HBAO_DEFAULT_K;
    if (K < 1 || K > HFVIS_SSAO_MAX_DIRECTIONS || !isfinite(o.azimuth0_rad))
        return HFVIS_ERR_INVALID_ARGUMENT;
    o.directions = K;
    if (o.custom_directions) {
        double ws = 0.0;
        for (k = 0; k < K; k++) {
            const hfvis_ssao_direction *d = &o.custom_directions[k];
            if (!ss_dir_ok(d) || !isfinite(d->weight) || d->weight < 0.0)
                return HFVIS_ERR_INVALID_ARGUMENT;
            ws += d->weight;
        }
        if (!(ws > 0.0) || !isfinite(ws)) return HFVIS_ERR_INVALID_ARGUMENT;
    }
    if (o.variant == HFVIS_HBAO_DEFAULT) o.variant = HFVIS_HBAO_INCREMENTAL;
    if (o.variant < HFVIS_HBAO_INCREMENTAL || o.variant > HFVIS_HBAO_LARGEST_OCCLUDER)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.steps < 0 || !isfinite(o.step_px) || !isfinite(o.radius) || o.radius < 0.0 ||
        !isfinite(o.max_radius_px) || o.max_radius_px < 0.0)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.step_px == 0.0) o.step_px = 1.0;
    if (!ss_step_ok(o.step_px)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (ss_resolve_falloff(&o.falloff) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.tangent == HFVIS_SSAO_TANGENT_DEFAULT) o.tangent = HFVIS_SSAO_TANGENT_REAL;
    if (o.tangent != HFVIS_SSAO_TANGENT_REAL && o.tangent != HFVIS_SSAO_TANGENT_FIXED)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (ss_resolve_sampling(&o.fixed_sin_t, &o.sampling, &o.plane, HFVIS_SSAO_PLANE_EXACT)
        != HFVIS_OK)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.jitter == HFVIS_HBAO_JITTER_DEFAULT) o.jitter = HFVIS_HBAO_JITTER_NONE;
    if (o.jitter < HFVIS_HBAO_JITTER_NONE || o.jitter > HFVIS_HBAO_JITTER_ROTATION_STEP)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.custom_directions && o.jitter != HFVIS_HBAO_JITTER_NONE)
        return HFVIS_ERR_INVALID_ARGUMENT;
    *out = o;
    return HFVIS_OK;
}

/* The default cap on HBAO's screen radius: a sixteenth of the inner image's height, at least 8
 * pixels (a 720p frame marches 45 pixels per direction, not to the buffer's edge). */
static double ss_hbao_default_radius_px(const ss_cam *c)
{
    double r = (double)(c->H - 2 * c->gy) / 16.0;
    return r > 8.0 ? r : 8.0;
}

/* One HBAO pixel ([T14] §4.1, [P4] §8; docs/errata.md E25). dirs: the custom directions or NULL; the result is
 * divided by the weight sum, which normalises custom weights. */
static double ss_hbao_pixel(const ss_cam *c, const hfvis_hbao_options *o, const ss_fall *f,
                            const hfvis_ssao_direction *dirs, const float *depth,
                            const float *normals, int x, int y, double support)
{
    int K = o->directions, k, bil = o->sampling == HFVIS_SSAO_SAMPLING_BILINEAR;
    int exact = o->plane == HFVIS_SSAO_PLANE_EXACT, custom = o->custom_directions != NULL;
    double u0 = (double)x + 0.5, v0 = (double)y + 0.5, zc = ss_tex(c, depth, x, y), P[3];
    double rot = 0.0, xi = 1.0, sum = 0.0, wsum = 0.0, maxr, diag;
    ss_unproject(c, u0, v0, zc, P);
    maxr = o->max_radius_px > 0.0 ? o->max_radius_px : ss_hbao_default_radius_px(c);
    diag = sqrt((double)c->W * (double)c->W + (double)c->H * (double)c->H);
    if (!(maxr < diag)) maxr = diag; /* no sample beyond the diagonal is inside the buffer (and
                                        ceil(R_px / step) then fits an int) */
    if (o->jitter != HFVIS_HBAO_JITTER_NONE)
        rot = 2.0 * HFVIS__PI / (double)K * ss_hash01((uint32_t)x, (uint32_t)y, 0u, o->seed);
    if (o->jitter == HFVIS_HBAO_JITTER_ROTATION_STEP)
        xi = 1.0 - ss_hash01((uint32_t)x, (uint32_t)y, 1u, o->seed); /* (0, 1] */
    for (k = 0; k < K; k++) {
        double dx, dy, sx, sy, e1[3], yh[3], px, py, r, ux, uy, st, rpx, L, w, maxs, acc = 0.0,
               best, hdist = 0.0, tiny;
        int N, s, found = 0;
        if (custom) {
            dx = dirs[k].dx;
            dy = dirs[k].dy;
            w = dirs[k].weight;
        } else {
            double psi = o->azimuth0_rad + 2.0 * HFVIS__PI * (double)k / (double)K + rot;
            dx = ss_snap_unit(cos(psi));
            dy = ss_snap_unit(sin(psi));
            w = 1.0 / (double)K;
        }
        ss_plane_e1(c, dx, dy, e1);
        ss_plane_yhat(c, e1, P, yh);
        px = ss_dot3(P, e1);
        py = exact ? ss_dot3(P, yh) : P[2];
        r = sqrt(px * px + py * py);
        if (c->persp) {
            ux = -px / r;
            uy = -py / r;
        } else {
            ux = 0.0;
            uy = 1.0;
        }
        tiny = SS_COINCIDENT * (fabs(px) + fabs(py));
        st = o->tangent == HFVIS_SSAO_TANGENT_REAL
                 ? ss_real_sin_t(c, normals, x, y, e1, yh, exact, ux, uy, -1.0, o->fixed_sin_t)
                 : o->fixed_sin_t;
        /* screen radius of the view-space radius along e1 at the receiver's depth */
        if (support < HFVIS__INF) {
            double a = c->persp ? zc * sqrt(dx * c->ifx * dx * c->ifx + dy * c->ify * dy * c->ify)
                                : sqrt(dx * c->sx * dx * c->sx + dy * c->sy * dy * c->sy);
            rpx = support / a;
            if (!(rpx < maxr)) rpx = maxr;
        } else {
            rpx = maxr;
        }
        if (custom) {
            sx = dirs[k].step_x;
            sy = dirs[k].step_y;
            N = o->steps > 0 ? o->steps : (int)ceil(rpx / dirs[k].step);
        } else {
            N = o->steps > 0 ? o->steps : (int)ceil(rpx / o->step_px);
            if (N < 1) N = 1;
            L = rpx / (double)N;
            sx = L * dx;
            sy = L * dy;
        }
        maxs = st;
        best = st;
        for (s = 1; s <= N; s++) {
            double t = custom ? (double)s : (double)s - 1.0 + xi, u = u0 + t * sx, v = v0 + t * sy;
            double qu, qv, z, Q[3], hx, hy, len, sh;
            if (!(u >= 0.0 && v >= 0.0 && u < (double)c->W && v < (double)c->H)) break;
            z = ss_sample(c, depth, bil, u, v, ss_texel(u, c->W), ss_texel(v, c->H), &qu, &qv);
            if (z != z) continue;
            if (exact && !bil) ss_onto_line(u0, v0, dx, dy, &qu, &qv);
            ss_unproject(c, qu, qv, z, Q);
            hx = ss_dot3(Q, e1) - px;
            hy = (exact ? ss_dot3(Q, yh) : Q[2]) - py;
            len = sqrt(hx * hx + hy * hy);
            if (!(len > tiny)) continue;
            sh = (hx * ux + hy * uy) / len;
            if (!(sh > maxs)) continue;
            switch (o->variant) {
            case HFVIS_HBAO_INCREMENTAL:
                acc += ss_rho(f, len) * (sh - maxs);
                break;
            case HFVIS_HBAO_SINGLE_HORIZON:
                hdist = len;
                found = 1;
                break;
            default: {
                double oc = st + (sh - st) * ss_rho(f, len);
                if (oc > best) best = oc;
                break;
            }
            }
            maxs = sh;
        }
        if (o->variant == HFVIS_HBAO_SINGLE_HORIZON) acc = found ? ss_rho(f, hdist) * (maxs - st) : 0.0;
        else if (o->variant == HFVIS_HBAO_LARGEST_OCCLUDER) acc = best;
        sum += w * acc;
        wsum += w;
    }
    return wsum > 0.0 ? sum / wsum : 0.0;
}

hfvis_status hfvis_hbao(const hfvis_camera *cam, const float *depth, const float *normals,
                        const hfvis_hbao_options *opts, float *ao, ptrdiff_t ao_stride)
{
    ss_cam c;
    ss_fall f;
    hfvis_hbao_options o;
    float *nrm = NULL;
    double support;
    int x, y, W;
    if (ss_cam_load(cam, &c) != HFVIS_OK || hfvis_hbao_options_resolve(opts, &o) != HFVIS_OK ||
        !depth || !ao)
        return HFVIS_ERR_INVALID_ARGUMENT;
    W = c.W - 2 * c.gx;
    if (ao_stride < W || !hfvis__plane_fits(ao_stride, c.H - 2 * c.gy, 1)) return HFVIS_ERR_INVALID_ARGUMENT;
    ss_fall_load(&o.falloff, &f);
    support = o.radius > 0.0 ? o.radius : f.support;
    if (o.tangent == HFVIS_SSAO_TANGENT_REAL && !normals) {
        size_t b = ss_bytes3((size_t)c.stride, (size_t)c.H, 3 * sizeof(float));
        if (!b || !(nrm = (float *)hfvis__alloc(o.alloc, b))) return HFVIS_ERR_OUT_OF_MEMORY;
        ss_normals_fill(&c, depth, nrm);
        normals = nrm;
    }
    for (y = c.gy; y < c.H - c.gy; y++)
        for (x = c.gx; x < c.W - c.gx; x++) {
            double a = 0.0;
            if (!ss_bg(&c, ss_tex(&c, depth, x, y))) {
                a = ss_hbao_pixel(&c, &o, &f, o.custom_directions, depth, normals, x, y, support);
                a = a > 0.0 ? (a < 1.0 ? a : 1.0) : 0.0;
            }
            ao[(ptrdiff_t)(y - c.gy) * ao_stride + (x - c.gx)] = (float)a;
        }
    hfvis__free(o.alloc, nrm);
    return HFVIS_OK;
}

/* ========================================================================================== */
/* 7. The screen-space ray-traced reference ([P4] §8; docs/errata.md E36)                     */
/* ========================================================================================== */

#define SS_RT_DEFAULT_RAYS 256
#define SS_RT_DEFAULT_REFINE 20
#define SS_RT_DEFAULT_BIAS 1e-5

hfvis_ssao_rt_options hfvis_ssao_rt_options_default(void)
{
    hfvis_ssao_rt_options o;
    memset(&o, 0, sizeof o);
    o.rays = SS_RT_DEFAULT_RAYS;
    o.falloff.kind = HFVIS_FALLOFF_NONE;
    o.sampling = HFVIS_SSAO_SAMPLING_DEFAULT; /* resolved from the thickness */
    o.refine_iterations = SS_RT_DEFAULT_REFINE;
    o.bias = SS_RT_DEFAULT_BIAS;
    return o;
}

hfvis_status hfvis_ssao_rt_options_resolve(const hfvis_ssao_rt_options *in,
                                           hfvis_ssao_rt_options *out)
{
    hfvis_ssao_rt_options o;
    if (!out) return HFVIS_ERR_INVALID_ARGUMENT;
    if (in) o = *in;
    else memset(&o, 0, sizeof o);
    if (o.rays < 0 || o.refine_iterations < 0 || o.refine_iterations > 64 ||
        !isfinite(o.thickness) || o.thickness < 0.0 ||
        !isfinite(o.bias) || o.bias < 0.0 || !isfinite(o.max_distance) || o.max_distance < 0.0)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.rays == 0) o.rays = SS_RT_DEFAULT_RAYS;
    if (o.refine_iterations == 0) o.refine_iterations = SS_RT_DEFAULT_REFINE;
    if (o.bias == 0.0) o.bias = SS_RT_DEFAULT_BIAS;
    if (o.sampling == HFVIS_SSAO_SAMPLING_DEFAULT)
        o.sampling = o.thickness > 0.0 ? HFVIS_SSAO_SAMPLING_NEAREST : HFVIS_SSAO_SAMPLING_BILINEAR;
    if (o.sampling != HFVIS_SSAO_SAMPLING_NEAREST && o.sampling != HFVIS_SSAO_SAMPLING_BILINEAR)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (ss_resolve_falloff(&o.falloff) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    *out = o;
    return HFVIS_OK;
}

/* Radical inverse in base 2 of r (van der Corput). */
static double ss_radical2(uint32_t r)
{
    r = (r << 16) | (r >> 16);
    r = ((r & 0x00ff00ffu) << 8) | ((r & 0xff00ff00u) >> 8);
    r = ((r & 0x0f0f0f0fu) << 4) | ((r & 0xf0f0f0f0u) >> 4);
    r = ((r & 0x33333333u) << 2) | ((r & 0xccccccccu) >> 2);
    r = ((r & 0x55555555u) << 1) | ((r & 0xaaaaaaaau) >> 1);
    return (double)r * (1.0 / 4294967296.0);
}

typedef struct ss_rt {
    const ss_cam *c;
    const float *depth;
    const hfvis_ssao_rt_options *o;
    double zmin, zmax, maxdist;
    int bil;
} ss_rt;

/* The ray parameter s >= 0 at which the screen coordinate `axis` (0: u, 1: v) of O + s w
 * equals k; +inf when the ray never gets there. */
static double ss_rt_cross(const ss_cam *c, const double O[3], const double w[3], int axis,
                          double k)
{
    double num, den, s;
    if (c->persp) { /* u = cx + fx X/d, v = cy - fy Y/d, d = d0 - s w.z */
        double d0 = -O[2];
        if (axis == 0) {
            num = (k - c->cx) * d0 - c->fx * O[0];
            den = c->fx * w[0] + (k - c->cx) * w[2];
        } else {
            num = (k - c->cy) * d0 + c->fy * O[1];
            den = -c->fy * w[1] + (k - c->cy) * w[2];
        }
    } else {
        if (axis == 0) {
            num = (k - c->cx) * c->sx - O[0];
            den = w[0];
        } else {
            num = -(k - c->cy) * c->sy - O[1];
            den = w[1];
        }
    }
    if (den == 0.0) return HFVIS__INF;
    s = num / den;
    /* the screen coordinate is monotone along the ray: a crossing behind the origin means the
     * coordinate tends to an asymptote (the vanishing point) short of k */
    return s >= 0.0 ? s : HFVIS__INF;
}

/* Screen position of O + s w. */
static void ss_rt_screen(const ss_cam *c, const double O[3], const double w[3], double s,
                         double *u, double *v)
{
    double X = O[0] + s * w[0], Y = O[1] + s * w[1], d = -(O[2] + s * w[2]);
    if (c->persp) {
        *u = c->cx + c->fx * X / d;
        *v = c->cy - c->fy * Y / d;
    } else {
        *u = c->cx + X / c->sx;
        *v = c->cy - Y / c->sy;
    }
}

/* Bilinear depth of cell (ix, iy) (centres ix+0.5 .. ix+1.5) at (u, v); NaN on background. */
static double ss_rt_bilinear(const ss_rt *t, int ix, int iy, double u, double v)
{
    const ss_cam *c = t->c;
    double a = u - ((double)ix + 0.5), b = v - ((double)iy + 0.5);
    double z00 = ss_tex(c, t->depth, ix, iy), z10 = ss_tex(c, t->depth, ix + 1, iy);
    double z01 = ss_tex(c, t->depth, ix, iy + 1), z11 = ss_tex(c, t->depth, ix + 1, iy + 1);
    if (ss_bg(c, z00) || ss_bg(c, z10) || ss_bg(c, z01) || ss_bg(c, z11)) return HFVIS__NAN;
    a = a < 0.0 ? 0.0 : (a > 1.0 ? 1.0 : a);
    b = b < 0.0 ? 0.0 : (b > 1.0 ? 1.0 : b);
    return (1.0 - b) * ((1.0 - a) * z00 + a * z10) + b * ((1.0 - a) * z01 + a * z11);
}

/* Is ray depth d inside the field of depth zb? */
static int ss_rt_in(const ss_rt *t, double d, double zb)
{
    if (zb != zb || !(d > zb)) return 0;
    return t->o->thickness > 0.0 ? d < zb + t->o->thickness : 1;
}

/* Distance to the first hit of the ray O + s w ([P4] §8; docs/errata.md E36), or -1 for a miss. The ray is
 * traversed cell by cell in screen space (a DDA whose cell boundaries are solved exactly in s):
 * texels under NEAREST, where the depth along the ray is linear and the field constant, so the
 * first inside point is exact; the cells between texel centres under BILINEAR, where each cell
 * is tested at its entry, middle and exit and a hit refined by bisection. */
static double ss_rt_ray(const ss_rt *t, const double O[3], const double w[3])
{
    const ss_cam *c = t->c;
    double off = t->bil ? 0.5 : 0.0, u, v, s = 0.0, d0 = -O[2], s_eye = HFVIS__INF;
    double thick = t->o->thickness;
    int ix, iy, su, sv, nx = t->bil ? c->W - 1 : c->W, ny = t->bil ? c->H - 1 : c->H;
    if (c->persp) {
        double du = w[0] * d0 + O[0] * w[2], dv = -(w[1] * d0 + O[1] * w[2]);
        su = du > 0.0 ? 1 : (du < 0.0 ? -1 : 0);
        sv = dv > 0.0 ? 1 : (dv < 0.0 ? -1 : 0);
        if (w[2] > 0.0) s_eye = d0 / w[2] * (1.0 - 1e-12); /* behind the eye past this */
    } else {
        su = w[0] > 0.0 ? 1 : (w[0] < 0.0 ? -1 : 0);
        sv = w[1] < 0.0 ? 1 : (w[1] > 0.0 ? -1 : 0);
    }
    ss_rt_screen(c, O, w, 0.0, &u, &v);
    if (!(u - off >= 0.0 && v - off >= 0.0)) return -1.0;
    ix = (int)floor(u - off);
    iy = (int)floor(v - off);
    if (ix >= nx || iy >= ny) return -1.0;
    for (;;) {
        double s_u = su > 0 ? ss_rt_cross(c, O, w, 0, (double)(ix + 1) + off)
                            : (su < 0 ? ss_rt_cross(c, O, w, 0, (double)ix + off) : HFVIS__INF);
        double s_v = sv > 0 ? ss_rt_cross(c, O, w, 1, (double)(iy + 1) + off)
                            : (sv < 0 ? ss_rt_cross(c, O, w, 1, (double)iy + off) : HFVIS__INF);
        double s_next = s_u < s_v ? s_u : s_v, s_end = s_next, da, db;
        int last = 0;
        if (!(s_end >= s)) s_end = s;
        if (s_end >= t->maxdist) { s_end = t->maxdist; last = 1; }
        if (s_end >= s_eye) { s_end = s_eye; last = 1; }
        if (s_end == HFVIS__INF) { /* the ray stays in this cell: the field is constant along it */
            double zb, qu, qv;
            if (w[2] >= 0.0) return -1.0;
            zb = t->bil ? ss_rt_bilinear(t, ix, iy, u, v)
                        : ss_sample(c, t->depth, 0, u, v, ix, iy, &qu, &qv);
            da = d0 - s * w[2];
            if (zb != zb) return -1.0;
            if (ss_rt_in(t, da, zb)) return s;
            if (thick > 0.0 && da >= zb + thick) return -1.0;
            da = (d0 - zb) / w[2]; /* where the descending ray reaches the depth */
            return da > s ? da : s;
        }
        da = d0 - s * w[2];
        db = d0 - s_end * w[2];
        if (!t->bil) {
            double zb = ss_tex(c, t->depth, ix, iy);
            if (!ss_bg(c, zb)) {
                if (ss_rt_in(t, da, zb)) return s;
                if (db > da && da <= zb && db > zb) { /* entering from above */
                    double sh = (d0 - zb) / w[2];
                    return sh > s ? sh : s;
                }
                if (thick > 0.0 && db < da && da >= zb + thick && db < zb + thick) {
                    double sh = (d0 - zb - thick) / w[2];
                    return sh > s ? sh : s;
                }
            }
        } else {
            double ss3[3], lo = s, hi = -1.0;
            int m, it;
            ss3[0] = s;
            ss3[1] = 0.5 * (s + s_end);
            ss3[2] = s_end;
            for (m = 0; m < 3; m++) {
                double uu, vv, zb;
                ss_rt_screen(c, O, w, ss3[m], &uu, &vv);
                zb = ss_rt_bilinear(t, ix, iy, uu, vv);
                if (ss_rt_in(t, d0 - ss3[m] * w[2], zb)) {
                    hi = ss3[m];
                    break;
                }
                lo = ss3[m];
            }
            if (hi >= 0.0) {
                if (hi == s) return s;
                for (it = 0; it < t->o->refine_iterations; it++) {
                    double mid = 0.5 * (lo + hi), uu, vv;
                    ss_rt_screen(c, O, w, mid, &uu, &vv);
                    if (ss_rt_in(t, d0 - mid * w[2], ss_rt_bilinear(t, ix, iy, uu, vv))) hi = mid;
                    else lo = mid;
                }
                return 0.5 * (lo + hi);
            }
        }
        if (last) return -1.0;
        /* rising above every depth, or sinking below every depth plus the thickness */
        if (w[2] > 0.0 && db < t->zmin) return -1.0;
        if (w[2] < 0.0 && thick > 0.0 && db > t->zmax + thick) return -1.0;
        if (s_u <= s_v) ix += su;
        if (s_v <= s_u) iy += sv;
        if (ix < 0 || iy < 0 || ix >= nx || iy >= ny) return -1.0;
        s = s_end;
        if (t->bil) ss_rt_screen(c, O, w, s, &u, &v);
    }
}

hfvis_status hfvis_ssao_reference(const hfvis_camera *cam, const float *depth, const float *normals,
                                 const hfvis_ssao_rt_options *opts, float *ao, ptrdiff_t ao_stride)
{
    ss_cam c;
    ss_fall f;
    ss_rt t;
    hfvis_ssao_rt_options o;
    float *nrm = NULL;
    int x, y, W, r;
    if (ss_cam_load(cam, &c) != HFVIS_OK || hfvis_ssao_rt_options_resolve(opts, &o) != HFVIS_OK ||
        !depth || !ao)
        return HFVIS_ERR_INVALID_ARGUMENT;
    W = c.W - 2 * c.gx;
    if (ao_stride < W || !hfvis__plane_fits(ao_stride, c.H - 2 * c.gy, 1)) return HFVIS_ERR_INVALID_ARGUMENT;
    ss_fall_load(&o.falloff, &f);
    if (!normals) {
        size_t b = ss_bytes3((size_t)c.stride, (size_t)c.H, 3 * sizeof(float));
        if (!b || !(nrm = (float *)hfvis__alloc(o.alloc, b))) return HFVIS_ERR_OUT_OF_MEMORY;
        ss_normals_fill(&c, depth, nrm);
        normals = nrm;
    }
    t.c = &c;
    t.depth = depth;
    t.o = &o;
    t.bil = o.sampling == HFVIS_SSAO_SAMPLING_BILINEAR;
    t.maxdist = o.max_distance > 0.0 ? o.max_distance : f.support;
    t.zmin = HFVIS__INF;
    t.zmax = 0.0;
    for (y = 0; y < c.H; y++)
        for (x = 0; x < c.W; x++) {
            double z = ss_tex(&c, depth, x, y);
            if (ss_bg(&c, z)) continue;
            if (z < t.zmin) t.zmin = z;
            if (z > t.zmax) t.zmax = z;
        }
    for (y = c.gy; y < c.H - c.gy; y++)
        for (x = c.gx; x < c.W - c.gx; x++) {
            double zc = ss_tex(&c, depth, x, y), acc = 0.0, a = 0.0;
            if (!ss_bg(&c, zc)) {
                const float *np = normals + 3 * ss_index(&c, x, y);
                double P[3], n[3], O[3], T[3], B[3], sg, aa, bb, xi1, xi2;
                ss_unproject(&c, (double)x + 0.5, (double)y + 0.5, zc, P);
                n[0] = (double)np[0];
                n[1] = (double)np[1];
                n[2] = (double)np[2];
                if (!ss_normalize3(n)) {
                    if (c.persp) {
                        n[0] = -P[0];
                        n[1] = -P[1];
                        n[2] = -P[2];
                        ss_normalize3(n);
                    } else {
                        n[0] = n[1] = 0.0;
                        n[2] = 1.0;
                    }
                }
                /* orthonormal basis (Duff et al. 2017) */
                sg = n[2] >= 0.0 ? 1.0 : -1.0;
                aa = -1.0 / (sg + n[2]);
                bb = n[0] * n[1] * aa;
                T[0] = 1.0 + sg * n[0] * n[0] * aa;
                T[1] = sg * bb;
                T[2] = -sg * n[0];
                B[0] = bb;
                B[1] = sg + n[1] * n[1] * aa;
                B[2] = -n[1];
                O[0] = P[0] + o.bias * zc * n[0];
                O[1] = P[1] + o.bias * zc * n[1];
                O[2] = P[2] + o.bias * zc * n[2];
                xi1 = ss_hash01((uint32_t)x, (uint32_t)y, 1u, o.seed);
                xi2 = ss_hash01((uint32_t)x, (uint32_t)y, 2u, o.seed);
                for (r = 0; r < o.rays; r++) {
                    double u1 = (double)r / (double)o.rays + xi1, u2 = ss_radical2((uint32_t)r) + xi2;
                    double rr, ph, lx, ly, lz, w[3], hit;
                    if (u1 >= 1.0) u1 -= 1.0;
                    if (u2 >= 1.0) u2 -= 1.0;
                    rr = sqrt(u1);
                    ph = 2.0 * HFVIS__PI * u2;
                    lx = rr * cos(ph);
                    ly = rr * sin(ph);
                    lz = sqrt(1.0 - u1 > 0.0 ? 1.0 - u1 : 0.0);
                    w[0] = lx * T[0] + ly * B[0] + lz * n[0];
                    w[1] = lx * T[1] + ly * B[1] + lz * n[1];
                    w[2] = lx * T[2] + ly * B[2] + lz * n[2];
                    hit = ss_rt_ray(&t, O, w);
                    if (hit >= 0.0) acc += ss_rho(&f, hit);
                }
                a = acc / (double)o.rays;
            }
            ao[(ptrdiff_t)(y - c.gy) * ao_stride + (x - c.gx)] = (float)a;
        }
    hfvis__free(o.alloc, nrm);
    return HFVIS_OK;
}

/* ========================================================================================== */
/* 8. Analytic depth buffers                                                  */
/* ========================================================================================== */

static int ss_scene_ok(const hfvis_ssao_scene *s)
{
    if (!s || !isfinite(s->base_depth) || !(s->base_depth > 0.0)) return 0;
    switch (s->kind) {
    case HFVIS_SSAO_SCENE_PLANE:
        return isfinite(s->slope_x) && isfinite(s->slope_y);
    case HFVIS_SSAO_SCENE_STEP:
        return isfinite(s->x0) && isfinite(s->height) && s->base_depth - s->height > 0.0;
    case HFVIS_SSAO_SCENE_VGROOVE:
        return isfinite(s->x0) && s->angle > 0.0 && s->angle < 0.5 * HFVIS__PI;
    case HFVIS_SSAO_SCENE_PIT:
        return isfinite(s->x0) && isfinite(s->y0) && isfinite(s->radius) && s->radius > 0.0;
    }
    return 0;
}

/* Keep candidate t if valid and smaller. */
static void ss_take(double t, int ok, double *best, int *which, int id)
{
    if (ok && t > 0.0 && isfinite(t) && t < *best) {
        *best = t;
        *which = id;
    }
}

/* First surface along the pixel ray: depth (+inf for a miss) and normal. Orthographic rays are
 * vertical through (rx, ry); perspective rays are t (rx, ry, -1). */
static double ss_scene_hit(const hfvis_ssao_scene *s, int persp, double rx, double ry, double n[3])
{
    double Z0 = s->base_depth, best = HFVIS__INF, x;
    int which = -1;
    n[0] = n[1] = 0.0;
    n[2] = 1.0;
    switch (s->kind) {
    case HFVIS_SSAO_SCENE_PLANE: {
        double a = s->slope_x, b = s->slope_y, l = sqrt(a * a + b * b + 1.0);
        if (persp) {
            double den = 1.0 + a * rx + b * ry;
            ss_take(Z0 / den, den > 0.0, &best, &which, 0);
        } else {
            ss_take(Z0 - (a * rx + b * ry), 1, &best, &which, 0);
        }
        n[0] = -a / l;
        n[1] = -b / l;
        n[2] = 1.0 / l;
        break;
    }
    case HFVIS_SSAO_SCENE_STEP: {
        double h = s->height, lo = Z0 - h < Z0 ? Z0 - h : Z0, hi = Z0 - h < Z0 ? Z0 : Z0 - h;
        if (persp) {
            ss_take(Z0, Z0 * rx < s->x0, &best, &which, 0);
            ss_take(Z0 - h, (Z0 - h) * rx >= s->x0, &best, &which, 1);
            if (rx != 0.0) {
                double t = s->x0 / rx;
                ss_take(t, t >= lo && t <= hi, &best, &which, 2);
            }
        } else {
            ss_take(rx < s->x0 ? Z0 : Z0 - h, 1, &best, &which, rx < s->x0 ? 0 : 1);
        }
        if (which == 2) {
            n[0] = h > 0.0 ? -1.0 : 1.0;
            n[2] = 0.0;
        }
        break;
    }
    case HFVIS_SSAO_SCENE_VGROOVE: {
        double tb = tan(s->angle), l = sqrt(1.0 + tb * tb);
        if (persp) {
            double d1 = 1.0 + rx * tb, d2 = 1.0 - rx * tb, t1 = (Z0 + s->x0 * tb) / d1,
                   t2 = (Z0 - s->x0 * tb) / d2;
            ss_take(t1, d1 > 0.0 && t1 * rx >= s->x0, &best, &which, 0);
            ss_take(t2, d2 > 0.0 && t2 * rx < s->x0, &best, &which, 1);
            x = best * rx;
        } else {
            x = rx;
            ss_take(Z0 - fabs(rx - s->x0) * tb, 1, &best, &which, rx >= s->x0 ? 0 : 1);
        }
        if (which >= 0 && x != s->x0) {
            n[0] = (x > s->x0 ? -tb : tb) / l;
            n[2] = 1.0 / l;
        }
        break;
    }
    default: { /* PIT */
        double R = s->radius, dx, dy, C[3], X[3];
        if (persp) {
            dx = Z0 * rx - s->x0;
            dy = Z0 * ry - s->y0;
            if (dx * dx + dy * dy >= R * R) {
                ss_take(Z0, 1, &best, &which, 0);
            } else {
                double rr = rx * rx + ry * ry + 1.0, rc = rx * s->x0 + ry * s->y0 + Z0;
                double cc = s->x0 * s->x0 + s->y0 * s->y0 + Z0 * Z0 - R * R, disc = rc * rc - rr * cc;
                if (disc < 0.0) disc = 0.0;
                ss_take((rc + sqrt(disc)) / rr, 1, &best, &which, 1);
            }
            X[0] = best * rx;
            X[1] = best * ry;
        } else {
            dx = rx - s->x0;
            dy = ry - s->y0;
            X[0] = rx;
            X[1] = ry;
            if (dx * dx + dy * dy >= R * R) ss_take(Z0, 1, &best, &which, 0);
            else ss_take(Z0 + sqrt(R * R - dx * dx - dy * dy), 1, &best, &which, 1);
        }
        if (which == 1) {
            C[0] = s->x0;
            C[1] = s->y0;
            C[2] = -Z0;
            X[2] = -best;
            n[0] = (C[0] - X[0]) / R;
            n[1] = (C[1] - X[1]) / R;
            n[2] = (C[2] - X[2]) / R;
            ss_normalize3(n);
        }
        break;
    }
    }
    if (which < 0) n[0] = n[1] = n[2] = 0.0;
    return best;
}

hfvis_status hfvis_ssao_scene_render(const hfvis_camera *cam, const hfvis_ssao_scene *scene,
                                     float *depth, float *normals)
{
    ss_cam c;
    int x, y;
    if (ss_cam_load(cam, &c) != HFVIS_OK || !ss_scene_ok(scene) || !depth)
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (y = 0; y < c.H; y++)
        for (x = 0; x < c.W; x++) {
            double P[3], n[3], z;
            ptrdiff_t o = ss_index(&c, x, y);
            ss_unproject(&c, (double)x + 0.5, (double)y + 0.5, 1.0, P);
            z = ss_scene_hit(scene, c.persp, P[0], P[1], n);
            depth[o] = (float)z;
            if (normals) {
                normals[3 * o] = (float)n[0];
                normals[3 * o + 1] = (float)n[1];
                normals[3 * o + 2] = (float)n[2];
            }
        }
    return HFVIS_OK;
}


/* ========================================================================================== */
/* 9. P4 far-field ambient obscurance ([P4] Timonen, "Screen-Space Far-Field Ambient          */
/*    Obscurance", HPG 2013; [P4]): the slab estimator L(a, b, c, d)                          */
/*    ([P4] Eq. 2-3) by quadrature, table and the closed form for rho = 1, the scan kernel    */
/*    ([P4] Alg. 1 with the sign correction of docs/errata.md E29, E30), virtual points (§5.4), the */
/*    resolution hierarchy (§5.5), prefix sums and sector averaging (§5.6), the obscurity     */
/*    kernel ([P4] Alg. 2), the near field (§5.8), jitter, sparse 3x3 evaluation               */
/*    and the bilateral blur (§5.9); 10. the mipmap baseline ([P4] §5);                        */
/*    11. error metrics ([P4] §8, docs/errata.md E36).                                         */
/* ========================================================================================== */

#define SSB_MAX_LEVELS 24
#define SSB_MAX_NODES 64
#define SSB_TABLE_MAX 4096

/* ---- 9.1 the slab integral L ([P4] §4, Eq. 2-3) ------------------------------------------------- */

/* Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n; n <= SSB_MAX_NODES). */
static void ssb_gauss(int n, double *x, double *w)
{
    int i, j, it;
    for (i = 0; i < n; i++) {
        double z = cos(HFVIS__PI * ((double)i + 0.75) / ((double)n + 0.5)), pp = 1.0;
        for (it = 0; it < 100; it++) {
            double p1 = 1.0, p2 = 0.0, z1;
            for (j = 0; j < n; j++) {
                double p3 = p2;
                p2 = p1;
                p1 = ((2.0 * (double)j + 1.0) * z * p2 - (double)j * p3) / ((double)j + 1.0);
            }
            pp = (double)n * (z * p1 - p2) / (z * z - 1.0);
            z1 = z;
            z = z1 - p1 / pp;
            if (fabs(z - z1) < 1e-15) break;
        }
        x[i] = z;
        w[i] = 2.0 / ((1.0 - z * z) * pp * pp);
    }
}

/* The integration range of L for (c, d): [lo0, hi0] = [max(d - pi/2, 0), min(c, d + pi/2, pi)]. */
static void ssb_range(double c, double d, double *lo0, double *hi0)
{
    double lo = d - 0.5 * HFVIS__PI, hi = d + 0.5 * HFVIS__PI;
    if (lo < 0.0) lo = 0.0;
    if (hi > c) hi = c;
    if (hi > HFVIS__PI) hi = HFVIS__PI;
    *lo0 = lo;
    *hi0 = hi;
}

/* Antiderivative of sin(t) cos(t - d) ([P4] §4, Eq. 2-3: F = t sin d / 2 - cos(2t - d) / 4). */
static double ssb_F(double t, double d) { return 0.5 * t * sin(d) - 0.25 * cos(2.0 * t - d); }

/* Integral of rho(b / sin(c - t)) cos(t - d) sin t over [A, B] (already clipped), by
 * Gauss-Legendre with n nodes (x, w on [-1, 1]). One sine and one cosine per node: sin(c - t) and
 * cos(t - d) come from sin t, cos t by the angle-addition formulas ([P4] Eq. 3; docs/errata.md E33). */
static double ssb_quad(const ss_fall *f, double A, double B, double b, double c, double d, int n,
                       const double *x, const double *w)
{
    double m = 0.5 * (A + B), h = 0.5 * (B - A), s = 0.0;
    double sc = sin(c), cc = cos(c), sd = sin(d), cd = cos(d);
    int i, flat = f->kind == HFVIS_FALLOFF_NONE || b == 0.0;
    if (!(B > A)) return 0.0;
    for (i = 0; i < n; i++) {
        double t = m + h * x[i], st = sin(t), ct = cos(t), sn = sc * ct - cc * st, r;
        if (flat) r = 1.0;
        else r = sn > 0.0 ? ss_rho(f, b / sn) : 0.0;
        s += w[i] * r * (ct * cd + st * sd) * st;
    }
    return s * h;
}

double hfvis_ffao_slab_rho1(double a, double theta_hi, double c, double d)
{
    double lo, hi;
    if (!isfinite(a) || theta_hi != theta_hi || !isfinite(c) || !isfinite(d)) return HFVIS__NAN;
    ssb_range(c, d, &lo, &hi);
    if (a > lo) lo = a;
    if (theta_hi < hi) hi = theta_hi;
    return hi > lo ? ssb_F(hi, d) - ssb_F(lo, d) : 0.0;
}

double hfvis_ffao_slab_integral(const hfvis_falloff *falloff, double a, double theta_hi,
                                double b, double c, double d, int nodes)
{
    ss_fall f;
    double x[SSB_MAX_NODES], w[SSB_MAX_NODES], lo, hi;
    if (ss_fall_load(falloff, &f) != HFVIS_OK || !isfinite(a) || theta_hi != theta_hi ||
        !(b >= 0.0) || !isfinite(c) || !isfinite(d) || nodes < 1 || nodes > SSB_MAX_NODES)
        return HFVIS__NAN;
    ssb_range(c, d, &lo, &hi);
    if (a > lo) lo = a;
    if (theta_hi < hi) hi = theta_hi;
    if (!(hi > lo)) return 0.0;
    ssb_gauss(nodes, x, w);
    return ssb_quad(&f, lo, hi, b, c, d, nodes, x, w);
}

/* ---- 9.2 the tabulated L (docs/errata.md E33) ------------------------------------------ */


hfvis_status hfvis_ffao_table_build(const hfvis_falloff *falloff, int na, int nb, int nc, int nd,
                                    double b_ref, const hfvis_allocator *alloc,
                                    hfvis_ffao_table *out)
{
    ss_fall f;
    size_t cells;
    float *v;
    double x[8], w[8];
    int ib, ic, id, ia;
    if (!out || ss_fall_load(falloff, &f) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    if (na == 0) na = 64;
    if (nb == 0) nb = 48;
    if (nc == 0) nc = 16;
    if (nd == 0) nd = 33;
    if (na < 2 || nb < 2 || nc < 2 || nd < 2 || na > SSB_TABLE_MAX || nb > SSB_TABLE_MAX ||
        nc > SSB_TABLE_MAX || nd > SSB_TABLE_MAX)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (b_ref == 0.0) {
        if (f.kind == HFVIS_FALLOFF_INV_QUADRATIC || f.kind == HFVIS_FALLOFF_HBAO) b_ref = sqrt(f.a);
        else if (f.kind == HFVIS_FALLOFF_NONE) b_ref = 1.0;
        else if (f.kind == HFVIS_FALLOFF_CUSTOM) b_ref = f.a > 0.0 ? f.a : 1.0;
        else b_ref = f.a;
    }
    if (!(isfinite(b_ref) && b_ref > 0.0)) return HFVIS_ERR_INVALID_ARGUMENT;
    cells = ss_bytes3((size_t)na * (size_t)nb, (size_t)nc * (size_t)nd, sizeof(float));
    if (!cells) return HFVIS_ERR_LIMIT;
    v = (float *)hfvis__alloc(alloc, cells);
    if (!v) return HFVIS_ERR_OUT_OF_MEMORY;
    ssb_gauss(8, x, w);
    for (id = 0; id < nd; id++)
        for (ic = 0; ic < nc; ic++)
            for (ib = 0; ib < nb; ib++) {
                double u = (double)ib / (double)(nb - 1), b, d, c, lo0, hi0, acc = 0.0;
                float *row = v + (((size_t)id * (size_t)nc + (size_t)ic) * (size_t)nb + (size_t)ib) *
                                     (size_t)na;
                b = u < 1.0 ? b_ref * u / (1.0 - u) : HFVIS__INF;
                c = 0.5 * HFVIS__PI + 0.5 * HFVIS__PI * (double)ic / (double)(nc - 1);
                d = -0.5 * HFVIS__PI + HFVIS__PI * (double)id / (double)(nd - 1);
                ssb_range(c, d, &lo0, &hi0);
                row[na - 1] = 0.0f;
                for (ia = na - 2; ia >= 0; ia--) {
                    double A = HFVIS__PI * (double)ia / (double)(na - 1);
                    double B = HFVIS__PI * (double)(ia + 1) / (double)(na - 1);
                    if (A < lo0) A = lo0;
                    if (B > hi0) B = hi0;
                    if (B > A) {
                        if (b < HFVIS__INF) acc += ssb_quad(&f, A, B, b, c, d, 8, x, w);
                        else if (f.kind == HFVIS_FALLOFF_NONE) acc += ssb_F(B, d) - ssb_F(A, d);
                    }
                    row[ia] = (float)acc;
                }
            }
    out->na = na;
    out->nb = nb;
    out->nc = nc;
    out->nd = nd;
    out->b_ref = b_ref;
    out->values = v;
    out->alloc = alloc;
    return HFVIS_OK;
}

void hfvis_ffao_table_free(hfvis_ffao_table *t)
{
    if (!t) return;
    hfvis__free(t->alloc, t->values);
    memset(t, 0, sizeof *t);
}

static int ssb_table_ok(const hfvis_ffao_table *t)
{
    return t && t->values && t->na >= 2 && t->nb >= 2 && t->nc >= 2 && t->nd >= 2 &&
           t->na <= SSB_TABLE_MAX && t->nb <= SSB_TABLE_MAX && t->nc <= SSB_TABLE_MAX &&
           t->nd <= SSB_TABLE_MAX && isfinite(t->b_ref) && t->b_ref > 0.0;
}

/* Cell index and fraction of v on a uniform axis [lo, hi] with n points. */
static void ssb_axis(double v, double lo, double hi, int n, int *i, double *fr)
{
    double p = (v - lo) / (hi - lo) * (double)(n - 1);
    int k;
    if (!(p > 0.0)) p = 0.0;
    if (p > (double)(n - 1)) p = (double)(n - 1);
    k = (int)p;
    if (k > n - 2) k = n - 2;
    *i = k;
    *fr = p - (double)k;
}

/* Quadrilinear lookup of L(a, b, c, d) (inputs clamped to the table's ranges). */
static double ssb_lookup(const hfvis_ffao_table *t, double a, double b, double c, double d)
{
    int ia, ib, ic, id, k;
    double fa, fb, fc, fd, u, s = 0.0;
    u = b > 0.0 ? b / (b + t->b_ref) : 0.0;
    ssb_axis(a, 0.0, HFVIS__PI, t->na, &ia, &fa);
    ssb_axis(u, 0.0, 1.0, t->nb, &ib, &fb);
    ssb_axis(c, 0.5 * HFVIS__PI, HFVIS__PI, t->nc, &ic, &fc);
    ssb_axis(d, -0.5 * HFVIS__PI, 0.5 * HFVIS__PI, t->nd, &id, &fd);
    for (k = 0; k < 8; k++) {
        int kb = k & 1, kc = (k >> 1) & 1, kd = (k >> 2) & 1;
        double wgt = (kb ? fb : 1.0 - fb) * (kc ? fc : 1.0 - fc) * (kd ? fd : 1.0 - fd);
        const float *row;
        if (wgt == 0.0) continue;
        row = t->values + (((size_t)(id + kd) * (size_t)t->nc + (size_t)(ic + kc)) * (size_t)t->nb +
                           (size_t)(ib + kb)) * (size_t)t->na;
        s += wgt * ((1.0 - fa) * (double)row[ia] + fa * (double)row[ia + 1]);
    }
    return s;
}

double hfvis_ffao_table_lookup(const hfvis_ffao_table *t, double a, double b, double c, double d)
{
    if (!ssb_table_ok(t) || a != a || b != b || c != c || d != d) return HFVIS__NAN;
    return ssb_lookup(t, a, b, c, d);
}

/* ---- 9.3 virtual points, sector weights, the slice estimator ([P4] §4, Eq. 2-3, §6) ------------- */

void hfvis_ffao_virtual_point(double m0, double m1, double slope, double zscale, double h[2])
{
    if (!h) return;
    h[0] = (m0 - m1) / slope; /* [P4] Alg. 1; docs/errata.md E29, E30: m1 = max(y - s x), so x_h = (m0 - m1)/s */
    h[1] = m0 * zscale;
}

/* e1 of screen azimuth phi (unit, z = 0). */
static void ssb_e1_phi(const ss_cam *c, double phi, double e[3])
{
    ss_plane_e1(c, cos(phi), sin(phi), e);
}

/* Angle around the zenith between boundary vectors ea, eb ([P4] §4, Eq. 2-3; docs/errata.md E32): both projected onto
 * the plane perpendicular to v (unit view ray; orthographic +Z). */
static double ssb_wedge(const double ea[3], const double eb[3], const double v[3])
{
    double pa[3], pb[3], cr[3], da = ss_dot3(ea, v), db = ss_dot3(eb, v);
    int k;
    for (k = 0; k < 3; k++) {
        pa[k] = ea[k] - da * v[k];
        pb[k] = eb[k] - db * v[k];
    }
    ss_cross3(pa, pb, cr);
    return atan2(sqrt(ss_dot3(cr, cr)), ss_dot3(pa, pb));
}

double hfvis_ffao_sector_weight(const hfvis_camera *cam, const double p[3], double phi_lo,
                                double phi_hi)
{
    ss_cam c;
    double ea[3], eb[3], v[3] = {0.0, 0.0, 1.0};
    if (ss_cam_load(cam, &c) != HFVIS_OK || !p || !isfinite(phi_lo) || !isfinite(phi_hi) ||
        !(phi_hi > phi_lo) || phi_hi - phi_lo >= HFVIS__PI)
        return HFVIS__NAN;
    if (c.persp) {
        v[0] = p[0];
        v[1] = p[1];
        v[2] = p[2];
        if (!(p[2] < 0.0) || !ss_normalize3(v)) return HFVIS__NAN;
    }
    ssb_e1_phi(&c, phi_lo, ea);
    ssb_e1_phi(&c, phi_hi, eb);
    return ssb_wedge(ea, eb, v);
}

/* The receiver in its slice ([P4] Alg. 2): 2D position, zenith, the x axis toward +D, the
 * projected normal's angle d and length. */
typedef struct ssb_rx {
    double px, py, ux, uy, xx, xy, d, nlen;
    int ortho;
} ssb_rx;

/* How L is evaluated. */
typedef struct ssb_est {
    ss_fall f;
    int mode;           /* 1 quadrature, 2 table, 3 closed form */
    int nodes;
    double x[SSB_MAX_NODES], w[SSB_MAX_NODES];
    const hfvis_ffao_table *table;
    double thickness;
} ssb_est;

static double ssb_theta(const ssb_rx *r, double wx, double wy)
{
    return atan2(wx * r->xx + wy * r->xy, wx * r->ux + wy * r->uy);
}

/* The running horizon theta_min of a slice ([P4] Eq. 3; docs/errata.md E31, E33: zenith angles, visible iff
 * a < theta_min) with the L1 pseudo-angle of the same direction (monotone in the angle on
 * (-pi, pi]; NaN when unknown). The pseudo-angle only rejects points clearly below the horizon
 * before the atan2; everything within SSB_PSEUDO_MARGIN of it takes the exact test, so the
 * result is that of the plain atan2 comparison. */
typedef struct ssb_hz {
    double th, ps;
} ssb_hz;

#define SSB_PSEUDO_MARGIN 1e-9 /* >> the few-ulp rounding of both pseudo-angles */

/* Pseudo-angle of atan2(s, c): 1 - c/(|s|+|c|) for s > 0, c/(|s|+|c|) - 1 for s < 0 (so 0 at 0,
 * +-1 at +-pi/2, +-2 at +-pi); NaN on the axis s = 0, where atan2's sign of zero decides. */
static double ssb_pseudo(double s, double c)
{
    double q;
    if (s > 0.0) q = c / (s + fabs(c));
    else if (s < 0.0) q = c / (fabs(c) - s);
    else return HFVIS__NAN;
    return s > 0.0 ? 1.0 - q : q - 1.0;
}

static ssb_hz ssb_hz_init(double th)
{
    ssb_hz h;
    h.th = th;
    if (th == HFVIS__PI) h.ps = 2.0; /* the start of every slice: nothing seen yet */
    else if (th > -HFVIS__PI && th < HFVIS__PI) h.ps = ssb_pseudo(sin(th), cos(th));
    else h.ps = th > HFVIS__PI ? HFVIS__INF : HFVIS__NAN;
    return h;
}

/* The slab of point h ([P4] Alg. 2; docs/errata.md E31): adds nothing unless h is visible
 * (a < theta_min, strict); returns the slab's integral and lowers the horizon to a. */
static double ssb_slab(const ssb_est *e, const ssb_rx *r, double hx, double hy, ssb_hz *hz)
{
    double wx = hx - r->px, wy = hy - r->py, sa = wx * r->xx + wy * r->xy, ca = wx * r->ux + wy * r->uy;
    double ps = ssb_pseudo(sa, ca), a, b, c, tl, lo, hi, s;
    if (ps > hz->ps + SSB_PSEUDO_MARGIN) return 0.0; /* clearly below the horizon */
    a = atan2(sa, ca);
    if (!(a < hz->th)) return 0.0;
    if (r->ortho) {
        b = fabs(hx - r->px);
        c = HFVIS__PI;
    } else {
        double hl = sqrt(hx * hx + hy * hy);
        b = fabs(r->px * hy - r->py * hx) / hl;
        c = ssb_theta(r, hx, hy);
        if (c < 0.0) c = -c; /* a point behind the eye's axis of the slice (degenerate) */
    }
    tl = hz->th;
    if (e->thickness > 0.0) { /* [P4] §11: the slab ends thickness below h along its view ray */
        double bx, by, tb;
        if (r->ortho) {
            bx = hx;
            by = hy - e->thickness;
        } else {
            double hl = sqrt(hx * hx + hy * hy);
            bx = hx + e->thickness * hx / hl;
            by = hy + e->thickness * hy / hl;
        }
        tb = ssb_theta(r, bx - r->px, by - r->py);
        if (tb < tl) tl = tb;
    }
    hz->th = a;
    hz->ps = ps;
    if (e->mode == 2) {
        double dd = r->d;
        s = ssb_lookup(e->table, a, b, c, dd) - (tl < c ? ssb_lookup(e->table, tl, b, c, dd) : 0.0);
        return s > 0.0 ? r->nlen * s : 0.0;
    }
    ssb_range(c, r->d, &lo, &hi);
    if (a > lo) lo = a;
    if (tl < hi) hi = tl;
    if (!(hi > lo)) return 0.0;
    if (e->mode == 3) return r->nlen * (ssb_F(hi, r->d) - ssb_F(lo, r->d));
    return r->nlen * ssb_quad(&e->f, lo, hi, b, c, r->d, e->nodes, e->x, e->w);
}

/* Receiver setup from its 2D position and projected normal. */
static void ssb_rx_init(ssb_rx *r, int ortho, double px, double py, double nx, double ny)
{
    double l;
    r->ortho = ortho;
    r->px = px;
    r->py = py;
    if (ortho) {
        r->ux = 0.0;
        r->uy = 1.0;
    } else {
        l = sqrt(px * px + py * py);
        r->ux = -px / l;
        r->uy = -py / l;
    }
    r->xx = r->uy;
    r->xy = -r->ux;
    r->nlen = sqrt(nx * nx + ny * ny);
    r->d = ssb_theta(r, nx, ny);
}

static hfvis_status ssb_est_init(ssb_est *e, const hfvis_falloff *f, hfvis_ffao_estimator m,
                                 const hfvis_ffao_table *t, int nodes, double thickness)
{
    if (ss_fall_load(f, &e->f) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    if (nodes == 0) nodes = 16;
    if (nodes < 1 || nodes > SSB_MAX_NODES) return HFVIS_ERR_INVALID_ARGUMENT;
    e->nodes = nodes;
    ssb_gauss(nodes, e->x, e->w);
    e->table = t;
    e->thickness = thickness;
    switch (m) {
    case HFVIS_FFAO_L_DEFAULT:
        e->mode = e->f.kind == HFVIS_FALLOFF_NONE ? 3 : (t ? 2 : 1);
        break;
    case HFVIS_FFAO_L_QUADRATURE: e->mode = 1; break;
    case HFVIS_FFAO_L_TABLE: e->mode = 2; break;
    case HFVIS_FFAO_L_CLOSED_FORM:
        if (e->f.kind != HFVIS_FALLOFF_NONE) return HFVIS_ERR_INVALID_ARGUMENT;
        e->mode = 3;
        break;
    default: return HFVIS_ERR_INVALID_ARGUMENT;
    }
    if (e->mode == 2 && t && !ssb_table_ok(t)) return HFVIS_ERR_INVALID_ARGUMENT;
    return HFVIS_OK;
}

hfvis_status hfvis_ffao_slice(const double p[2], const double n[2], const double *hx,
                              const double *hy, int count, int orthographic, double theta_start,
                              const hfvis_ffao_options *opts, double *obscurance,
                              double *theta_min)
{
    hfvis_ffao_options o;
    ssb_est e;
    ssb_rx r;
    double acc = 0.0;
    ssb_hz th;
    int i;
    if (hfvis_ffao_options_resolve(opts, &o) != HFVIS_OK || !p || !n || count < 0 ||
        (count > 0 && (!hx || !hy)) || (orthographic != 0 && orthographic != 1) ||
        theta_start != theta_start || !isfinite(p[0]) || !isfinite(p[1]) || !isfinite(n[0]) ||
        !isfinite(n[1]) || !obscurance)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (!orthographic && !(p[0] * p[0] + p[1] * p[1] > 0.0)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.estimator == HFVIS_FFAO_L_TABLE && !o.table) return HFVIS_ERR_INVALID_ARGUMENT;
    if (ssb_est_init(&e, &o.falloff, o.estimator, o.table, o.quad_nodes, o.thickness) != HFVIS_OK)
        return HFVIS_ERR_INVALID_ARGUMENT;
    ssb_rx_init(&r, orthographic, p[0], p[1], n[0], n[1]);
    th = ssb_hz_init(theta_start);
    for (i = 0; i < count; i++) {
        if (!isfinite(hx[i]) || !isfinite(hy[i])) continue;
        if (!orthographic && !(hx[i] * hx[i] + hy[i] * hy[i] > 0.0)) continue;
        acc += ssb_slab(&e, &r, hx[i], hy[i], &th);
    }
    *obscurance = acc;
    if (theta_min) *theta_min = th.th;
    return HFVIS_OK;
}

/* ---- 9.4 options ------------------------------------------------------------------------- */

hfvis_ffao_options hfvis_ffao_options_default(void)
{
    hfvis_ffao_options o;
    memset(&o, 0, sizeof o);
    return o;
}

hfvis_status hfvis_ffao_options_resolve(const hfvis_ffao_options *in, hfvis_ffao_options *out)
{
    hfvis_ffao_options o;
    if (!out) return HFVIS_ERR_INVALID_ARGUMENT;
    if (in) o = *in;
    else memset(&o, 0, sizeof o);
    if (o.directions == 0) o.directions = o.sparse ? 18 : 8;
    if (o.segments == 0) o.segments = 2;
    if (o.b0 == 0) o.b0 = 10;
    if (o.level_gamma == 0.0) o.level_gamma = 1.0;
    if (o.receiver_slope == 0.0) o.receiver_slope = -1.0;
    if (o.averaging == HFVIS_FFAO_AVERAGE_DEFAULT)
        o.averaging = o.thickness > 0.0 ? HFVIS_FFAO_AVERAGE_OFF : HFVIS_FFAO_AVERAGE_ON;
    if (o.sampling == HFVIS_SSAO_SAMPLING_DEFAULT)
        o.sampling = o.thickness > 0.0 ? HFVIS_SSAO_SAMPLING_NEAREST : HFVIS_SSAO_SAMPLING_BILINEAR;
    if (o.near_field == HFVIS_FFAO_NEAR_DEFAULT) o.near_field = HFVIS_FFAO_NEAR_DIRECT;
    if (o.quad_nodes == 0) o.quad_nodes = 16;
    if (o.blur_radius == 0) o.blur_radius = 2;
    if (o.blur_threshold == 0.0) o.blur_threshold = 0.07;
    if (o.mip_growth == 0.0) o.mip_growth = 1.5;
    if (o.mip_directions == 0) o.mip_directions = 16;
    if (o.directions < 3 || o.directions > HFVIS_SSAO_MAX_DIRECTIONS || o.segments < 1 ||
        o.segments > 64 || o.b0 < 1 || o.b0 > 4096 || o.levels < 0 || o.levels > SSB_MAX_LEVELS ||
        !(isfinite(o.level_gamma) && o.level_gamma > 0.0) ||
        !(isfinite(o.receiver_slope) && o.receiver_slope < 0.0) || !isfinite(o.azimuth0_rad) ||
        (o.averaging != HFVIS_FFAO_AVERAGE_ON && o.averaging != HFVIS_FFAO_AVERAGE_OFF) ||
        (o.jitter != 0 && o.jitter != 1) || (o.sparse != 0 && o.sparse != 1) ||
        (o.blur != 0 && o.blur != 1) || !(isfinite(o.thickness) && o.thickness >= 0.0) ||
        (o.sampling != HFVIS_SSAO_SAMPLING_NEAREST && o.sampling != HFVIS_SSAO_SAMPLING_BILINEAR) ||
        (o.near_field != HFVIS_FFAO_NEAR_NONE && o.near_field != HFVIS_FFAO_NEAR_DIRECT) ||
        o.quad_nodes < 1 || o.quad_nodes > SSB_MAX_NODES || o.blur_radius < 0 ||
        o.blur_radius > 64 || !(isfinite(o.blur_threshold) && o.blur_threshold >= 0.0) ||
        !(isfinite(o.mip_growth) && o.mip_growth >= 1.0 && o.mip_growth <= 16.0) ||
        o.mip_directions < 3 || o.mip_directions > HFVIS_SSAO_MAX_DIRECTIONS ||
        (int)o.estimator < 0 || (int)o.estimator > (int)HFVIS_FFAO_L_CLOSED_FORM ||
        (o.sparse && o.directions % 9 != 0) || hfvis_falloff_check(&o.falloff) != HFVIS_OK)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.table && !ssb_table_ok(o.table)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.estimator == HFVIS_FFAO_L_CLOSED_FORM && o.falloff.kind != HFVIS_FALLOFF_NONE &&
        o.falloff.kind != HFVIS_FALLOFF_DEFAULT)
        return HFVIS_ERR_INVALID_ARGUMENT;
    *out = o;
    return HFVIS_OK;
}

/* ---- 9.5 the FFAO pipeline ---------------------------------------------------------------- */

/* One scan direction's data: lattice, line ranges, and per level the prefix sums over lines of
 * (m0, m1, valid) for every interval: pre[lev][3 * (J * (nl + 1) + l)] (slot l = sum over lines
 * < l). */
typedef struct ssb_dir {
    hfvis_ssao_lattice lat;
    hfvis_ssao_line *lines;
    double e1[3], phi;
    double eb[65][3];            /* segment boundary vectors (S + 1) */
    int smax;                    /* largest step index of any line */
    int nlev, nj[SSB_MAX_LEVELS];
    double *pre[SSB_MAX_LEVELS];
} ssb_dir;

typedef struct ssb_ctx {
    ss_cam c;
    hfvis_ffao_options o;
    ssb_est e;
    const float *depth;
    int bil;
} ssb_ctx;

/* Largest step index and per-level interval counts of a direction; total doubles needed. */
static size_t ssb_dir_size(const ssb_ctx *x, ssb_dir *dd)
{
    int n, smax = 0, j;
    size_t tot = 0, nl1 = (size_t)dd->lat.line_count + 1;
    for (j = 0; j < dd->lat.line_count; j++) {
        const hfvis_ssao_line *ln = &dd->lines[j];
        if (ln->count > 0 && ln->first + ln->count - 1 > smax) smax = ln->first + ln->count - 1;
    }
    dd->smax = smax;
    dd->nlev = 0;
    for (n = 0; n < SSB_MAX_LEVELS; n++) {
        long long bn = (long long)x->o.b0 << n;
        if (n > 0 && bn > (long long)smax + 1) break;
        if (x->o.levels > 0 && n >= x->o.levels) break;
        dd->nj[n] = (int)((long long)smax / bn) + 1;
        tot += (size_t)dd->nj[n] * nl1 * 3;
        dd->nlev = n + 1;
    }
    return tot;
}

/* Scan kernel ([P4] Alg. 1, docs/errata.md E29, E30) + hierarchy (§5.5) + prefix sums (§5.6). */
static void ssb_scan(const ssb_ctx *x, ssb_dir *dd, double *mem)
{
    const ss_cam *c = &x->c;
    size_t nl1 = (size_t)dd->lat.line_count + 1, k;
    double s = x->o.receiver_slope;
    int n, j, J, l;
    for (n = 0; n < dd->nlev; n++) {
        dd->pre[n] = mem;
        for (k = 0; k < (size_t)dd->nj[n] * nl1; k++) {
            mem[3 * k] = -HFVIS__INF;
            mem[3 * k + 1] = -HFVIS__INF;
            mem[3 * k + 2] = 0.0;
        }
        mem += (size_t)dd->nj[n] * nl1 * 3;
    }
    for (j = 0; j < dd->lat.line_count; j++) {
        const hfvis_ssao_line *ln = &dd->lines[j];
        int i;
        for (i = ln->first; i < ln->first + ln->count; i++) {
            double u = ln->x0 + (double)i * dd->lat.dir.step_x, v = ln->y0 + (double)i * dd->lat.dir.step_y;
            double qu, qv, z, Q[3], xq, yq;
            double *cell;
            z = ss_sample(c, x->depth, x->bil, u, v, ss_texel(u, c->W), ss_texel(v, c->H), &qu, &qv);
            if (z != z) continue; /* background: never occludes */
            ss_unproject(c, qu, qv, z, Q);
            xq = ss_dot3(Q, dd->e1);
            yq = Q[2];
            cell = dd->pre[0] + 3 * ((size_t)(i / x->o.b0) * nl1 + (size_t)j + 1);
            if (yq > cell[0]) cell[0] = yq;                      /* m0 = max(y) */
            if (yq - s * xq > cell[1]) cell[1] = yq - s * xq;    /* m1 = max(y - s x) (§5.3 [A]) */
            cell[2] = 1.0;
        }
    }
    for (n = 1; n < dd->nlev; n++) /* B_n = 2 B_{n-1}: max over the two children */
        for (J = 0; J < dd->nj[n]; J++)
            for (l = 1; l < (int)nl1; l++) {
                double *dst = dd->pre[n] + 3 * ((size_t)J * nl1 + (size_t)l), *a, *b;
                a = dd->pre[n - 1] + 3 * ((size_t)(2 * J) * nl1 + (size_t)l);
                dst[0] = a[0];
                dst[1] = a[1];
                dst[2] = a[2];
                if (2 * J + 1 < dd->nj[n - 1]) {
                    b = a + 3 * nl1;
                    if (b[0] > dst[0]) dst[0] = b[0];
                    if (b[1] > dst[1]) dst[1] = b[1];
                    if (b[2] > dst[2]) dst[2] = b[2];
                }
            }
    for (n = 0; n < dd->nlev; n++)
        for (J = 0; J < dd->nj[n]; J++) {
            double *row = dd->pre[n] + 3 * (size_t)J * nl1, s0 = 0.0, s1 = 0.0, sc = 0.0;
            row[0] = row[1] = row[2] = 0.0;
            for (l = 1; l < (int)nl1; l++) {
                double *cl = row + 3 * l;
                if (cl[2] > 0.0) {
                    s0 += cl[0];
                    s1 += cl[1];
                    sc += 1.0;
                }
                cl[0] = s0;
                cl[1] = s1;
                cl[2] = sc;
            }
        }
}

/* Near field ([P4] §9; docs/errata.md E37): direct samples at 1, 2, ... px along +D from the receiver up to
 * (excluding) along-line distance `until`, through the slab estimator. */
static double ssb_near(const ssb_ctx *x, const ssb_dir *dd, const ssb_rx *r, double cu, double cv,
                       double zs, double until, ssb_hz *thmin)
{
    const ss_cam *c = &x->c;
    double acc = 0.0, sdist;
    for (sdist = 1.0; sdist < until - 1e-9; sdist += 1.0) {
        double u = cu + sdist * dd->lat.dir.dx, v = cv + sdist * dd->lat.dir.dy, qu, qv, z, Q[3];
        if (u < 0.5 || v < 0.5 || u > (double)c->W - 0.5 || v > (double)c->H - 0.5) break;
        z = ss_sample(c, x->depth, x->bil, u, v, ss_texel(u, c->W), ss_texel(v, c->H), &qu, &qv);
        if (z != z) continue;
        ss_unproject(c, qu, qv, z, Q);
        acc += ssb_slab(&x->e, r, ss_dot3(Q, dd->e1), Q[2] * zs, thmin);
    }
    return acc;
}

/* One receiver, one scan direction ([P4] Alg. 2 for sector k): returns in *near_sum
 * and *far_sum the w-weighted integrals (w in radians around the zenith) of the near and far
 * fields, in *wsum the sector's weight. jit in [-1, 1]: the sector rotation of §5.9. */
static void ssb_pixel_dir(const ssb_ctx *x, const ssb_dir *dd, double cu, double cv, double z,
                          const double nrm[3], double jit, int want_near, int want_far,
                          double *near_sum, double *far_sum, double *wsum)
{
    const ss_cam *c = &x->c;
    double P[3], yh[3], v[3], zs, t_pix, jx, far0, In = 0.0, wsec = 0.0, Ifar = 0.0;
    double dphi = 2.0 * HFVIS__PI / ((double)x->o.directions * (double)x->o.segments), wseg[64];
    ssb_rx r;
    ssb_hz thn = ssb_hz_init(HFVIS__PI);
    int S = x->o.segments, g, J0, b0 = x->o.b0;
    ss_unproject(c, cu, cv, z, P);
    ss_plane_yhat(c, dd->e1, P, yh);
    zs = c->persp ? 1.0 / yh[2] : 1.0;
    ssb_rx_init(&r, !c->persp, ss_dot3(P, dd->e1), P[2] * zs, ss_dot3(nrm, dd->e1), ss_dot3(nrm, yh));
    if (c->persp) {
        v[0] = P[0];
        v[1] = P[1];
        v[2] = P[2];
        ss_normalize3(v);
    } else {
        v[0] = v[1] = 0.0;
        v[2] = 1.0;
    }
    t_pix = (cu * dd->lat.dir.dx + cv * dd->lat.dir.dy - dd->lat.t_min) / dd->lat.dir.step;
    jx = (cu * dd->lat.px + cv * dd->lat.py - dd->lat.s_first) / dd->lat.dir.spacing;
    J0 = (int)ceil((t_pix + (double)b0) / (double)b0 - 1e-9);
    far0 = (double)J0 * (double)b0;
    if (x->o.near_field == HFVIS_FFAO_NEAR_DIRECT) In = ssb_near(x, dd, &r, cu, cv, zs, far0 - t_pix, &thn);
    for (g = 0; g < S; g++) {
        wseg[g] = ssb_wedge(dd->eb[g], dd->eb[g + 1], v);
        wsec += wseg[g];
    }
    *wsum = wsec;
    *near_sum = want_near ? wsec * In : 0.0;
    *far_sum = 0.0;
    if (!want_far) return;
    for (g = 0; g < S; g++) {
        double wg = wseg[g], Ig = 0.0;
        ssb_hz th = thn;
        double alo = -HFVIS__PI / (double)x->o.directions + dphi * (double)g + jit * 0.5 * dphi;
        double ahi = alo + dphi, tlo = tan(alo), thi = tan(ahi), amid = tan(0.5 * (alo + ahi));
        long long q = J0; /* the far field starts at step q * b0, a multiple of b0 */
        while (q * b0 <= dd->smax) {
            int n = dd->nlev - 1, J, lA, lB;
            long long bn;
            double rr, olo, ohi, cnt, m0, m1, hx, hy;
            const double *row;
            size_t nl1 = (size_t)dd->lat.line_count + 1;
            for (; n > 0; n--) /* the coarsest level whose block starts here and is near enough */
                if ((q & ((1LL << n) - 1)) == 0 &&
                    (double)((long long)b0 << n) <= x->o.level_gamma * ((double)(q * b0) - t_pix))
                    break;
            bn = (long long)b0 << n;
            J = (int)(q >> n);
            q += 1LL << n;
            if (J >= dd->nj[n]) break;
            rr = ((double)J + 0.5) * (double)bn - t_pix;
            if (x->o.averaging == HFVIS_FFAO_AVERAGE_ON) {
                olo = jx + rr * tlo;
                ohi = jx + rr * thi;
                lA = (int)ceil(olo - 1e-9);
                lB = (int)floor(ohi + 1e-9);
                if (lA > lB) lA = lB = (int)floor(jx + rr * amid + 0.5);
            } else {
                lA = lB = (int)floor(jx + rr * amid + 0.5);
            }
            if (lB < 0 || lA > dd->lat.line_count - 1) continue;
            if (lA < 0) lA = 0;
            if (lB > dd->lat.line_count - 1) lB = dd->lat.line_count - 1;
            row = dd->pre[n] + 3 * (size_t)J * nl1;
            cnt = row[3 * (lB + 1) + 2] - row[3 * lA + 2];
            if (!(cnt > 0.0)) continue;
            m0 = (row[3 * (lB + 1)] - row[3 * lA]) / cnt;
            m1 = (row[3 * (lB + 1) + 1] - row[3 * lA + 1]) / cnt;
            hx = (m0 - m1) / x->o.receiver_slope; /* virtual point ([P4] §6) */
            hy = m0 * zs;
            if (!r.ortho && !(hx * hx + hy * hy > 0.0)) continue;
            Ig += ssb_slab(&x->e, &r, hx, hy, &th);
        }
        Ifar += wg * Ig;
    }
    *far_sum = Ifar;
}

/* Normal of texel (x, y) in double (the given or reconstructed buffer; the eye direction when
 * it is (0,0,0)). */
static void ssb_normal(const ss_cam *c, const float *normals, int x, int y, double z, double n[3])
{
    const float *np = normals + 3 * ss_index(c, x, y);
    n[0] = (double)np[0];
    n[1] = (double)np[1];
    n[2] = (double)np[2];
    if (!ss_normalize3(n)) {
        if (c->persp) {
            ss_unproject(c, (double)x + 0.5, (double)y + 0.5, z, n);
            n[0] = -n[0];
            n[1] = -n[1];
            n[2] = -n[2];
            ss_normalize3(n);
        } else {
            n[0] = n[1] = 0.0;
            n[2] = 1.0;
        }
    }
}

/* Sparse mode box average ([P4] §10, §11.1; docs/errata.md E38): mean depth and normal over the accepted 3x3 neighbours
 * (n_c . n_i > 0.5 and |z_i - z_c| < 3 % z_c); bit (dy+1)*3 + (dx+1) of *mask marks them. */
static void ssb_box(const ss_cam *c, const float *depth, const float *normals, int x, int y,
                    double *zo, double no[3], unsigned *mask)
{
    double zc = ss_tex(c, depth, x, y), nc[3], zs = 0.0, ns[3] = {0.0, 0.0, 0.0};
    int dx, dy, k = 0;
    unsigned m = 0;
    ssb_normal(c, normals, x, y, zc, nc);
    for (dy = -1; dy <= 1; dy++)
        for (dx = -1; dx <= 1; dx++) {
            int xx = x + dx, yy = y + dy;
            double zi, ni[3];
            if (xx < c->gx || yy < c->gy || xx >= c->W - c->gx || yy >= c->H - c->gy) continue;
            zi = ss_tex(c, depth, xx, yy);
            if (ss_bg(c, zi) || !(fabs(zi - zc) < 0.03 * zc)) continue;
            ssb_normal(c, normals, xx, yy, zi, ni);
            if (!(ss_dot3(ni, nc) > 0.5)) continue;
            m |= 1u << ((dy + 1) * 3 + (dx + 1));
            zs += zi;
            ns[0] += ni[0];
            ns[1] += ni[1];
            ns[2] += ni[2];
            k++;
        }
    *zo = zs / (double)k;
    if (!ss_normalize3(ns)) memcpy(ns, nc, sizeof ns);
    memcpy(no, ns, sizeof ns);
    *mask = m;
}

static void ssb_blur(const float *in, ptrdiff_t is, int w, int h, int rad, double thr, float *out,
                     ptrdiff_t os)
{
    int x, y, dx, dy;
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            double lc = 1.0 - (double)in[(ptrdiff_t)y * is + x], s = 0.0;
            int k = 0;
            for (dy = -rad; dy <= rad; dy++)
                for (dx = -rad; dx <= rad; dx++) {
                    int xx = x + dx, yy = y + dy;
                    double li;
                    if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
                    li = 1.0 - (double)in[(ptrdiff_t)yy * is + xx];
                    if (!(fabs(li - lc) <= thr * lc) && !(dx == 0 && dy == 0)) continue;
                    s += li;
                    k++;
                }
            out[(ptrdiff_t)y * os + x] = (float)(1.0 - s / (double)k);
        }
}

hfvis_status hfvis_ssao_bilateral_blur(const float *in, ptrdiff_t in_stride, int width,
                                       int height, int radius, double threshold, float *out,
                                       ptrdiff_t out_stride)
{
    if (!in || !out || width < 1 || height < 1 || in_stride < width || out_stride < width ||
        !hfvis__plane_fits(in_stride, height, 1) || !hfvis__plane_fits(out_stride, height, 1) ||
        radius < 0 || radius > 64 || !(isfinite(threshold) && threshold >= 0.0) || in == out)
        return HFVIS_ERR_INVALID_ARGUMENT;
    ssb_blur(in, in_stride, width, height, radius, threshold, out, out_stride);
    return HFVIS_OK;
}

/* Common setup of hfvis_ffao / hfvis_ssao_mipmap: camera, options, estimator (building the
 * table when needed into *own). */
static hfvis_status ssb_setup(ssb_ctx *x, const hfvis_camera *cam, const float *depth,
                              const hfvis_ffao_options *opts, float *ao, ptrdiff_t ao_stride,
                              hfvis_ffao_table *own)
{
    hfvis_status s;
    memset(x, 0, sizeof *x);
    memset(own, 0, sizeof *own);
    if (ss_cam_load(cam, &x->c) != HFVIS_OK || hfvis_ffao_options_resolve(opts, &x->o) != HFVIS_OK ||
        !depth || !ao || ao_stride < x->c.W - 2 * x->c.gx ||
        !hfvis__plane_fits(ao_stride, x->c.H - 2 * x->c.gy, 1))
        return HFVIS_ERR_INVALID_ARGUMENT;
    x->depth = depth;
    x->bil = x->o.sampling == HFVIS_SSAO_SAMPLING_BILINEAR;
    s = ssb_est_init(&x->e, &x->o.falloff, x->o.estimator, x->o.table, x->o.quad_nodes, x->o.thickness);
    if (s != HFVIS_OK) return s;
    if (x->e.mode == 2 && !x->o.table) {
        s = hfvis_ffao_table_build(&x->o.falloff, 0, 0, 0, 0, 0.0, x->o.alloc, own);
        if (s != HFVIS_OK) return s;
        x->e.table = own;
    }
    return HFVIS_OK;
}

hfvis_status hfvis_ffao(const hfvis_camera *cam, const float *depth, const float *normals,
                        const hfvis_ffao_options *opts, float *ao, ptrdiff_t ao_stride)
{
    ssb_ctx x;
    hfvis_ffao_table own;
    hfvis_status s;
    const ss_cam *c;
    hfvis_ssao_direction *dirs = NULL;
    ssb_dir dd;
    float *nrm = NULL;
    double *pre = NULL, *acc = NULL;
    size_t maxpre = 0, npix, maxlines = 0, b;
    int K, k, W, H, px, py;
    const hfvis_allocator *al;
    s = ssb_setup(&x, cam, depth, opts, ao, ao_stride, &own);
    if (s != HFVIS_OK) return s;
    c = &x.c;
    al = x.o.alloc;
    K = x.o.directions;
    W = c->W - 2 * c->gx;
    H = c->H - 2 * c->gy;
    npix = (size_t)W * (size_t)H;
    memset(&dd, 0, sizeof dd);
    s = HFVIS_ERR_OUT_OF_MEMORY;
    if (!normals) {
        b = ss_bytes3((size_t)c->stride, (size_t)c->H, 3 * sizeof(float));
        if (!b || !(nrm = (float *)hfvis__alloc(al, b))) goto done;
        ss_normals_fill(c, depth, nrm);
        normals = nrm;
    }
    if (!(dirs = (hfvis_ssao_direction *)hfvis__alloc(al, (size_t)K * sizeof *dirs))) goto done;
    hfvis_ssao_directions_uniform(K, x.o.azimuth0_rad, 1.0, 1.0, dirs);
    for (k = 0; k < K; k++) { /* sizes: the largest direction */
        s = ss_lattice_init(c, &dirs[k], &dd.lat);
        if (s != HFVIS_OK) goto done;
        if ((size_t)dd.lat.line_count > maxlines) maxlines = (size_t)dd.lat.line_count;
    }
    s = HFVIS_ERR_OUT_OF_MEMORY;
    if (!(dd.lines = (hfvis_ssao_line *)hfvis__alloc(al, maxlines * sizeof *dd.lines))) goto done;
    for (k = 0; k < K; k++) {
        size_t t;
        ss_lattice_init(c, &dirs[k], &dd.lat);
        ss_lattice_fill(c, &dd.lat, dd.lines);
        t = ssb_dir_size(&x, &dd);
        if (t > maxpre) maxpre = t;
    }
    b = ss_bytes3(maxpre, 1, sizeof(double));
    if (!b || !(pre = (double *)hfvis__alloc(al, b))) goto done;
    /* per pixel: ao sum; sparse adds far sum, far weight and the box mask */
    b = ss_bytes3(npix, x.o.sparse ? 4 : 1, sizeof(double));
    if (!b || !(acc = (double *)hfvis__alloc(al, b))) goto done;
    memset(acc, 0, b);
    for (k = 0; k < K; k++) {
        int g;
        ss_lattice_init(c, &dirs[k], &dd.lat);
        ss_lattice_fill(c, &dd.lat, dd.lines);
        ssb_dir_size(&x, &dd);
        dd.phi = x.o.azimuth0_rad + 2.0 * HFVIS__PI * (double)k / (double)K;
        ss_plane_e1(c, dirs[k].dx, dirs[k].dy, dd.e1);
        for (g = 0; g <= x.o.segments; g++)
            ssb_e1_phi(c, dd.phi - HFVIS__PI / (double)K + 2.0 * HFVIS__PI * (double)g / ((double)K * (double)x.o.segments),
                       dd.eb[g]);
        ssb_scan(&x, &dd, pre);
        for (py = 0; py < H; py++)
            for (px = 0; px < W; px++) {
                int tx = px + c->gx, ty = py + c->gy;
                double z = ss_tex(c, depth, tx, ty), nv[3], ns, fs, ws, jit = 0.0;
                size_t o = (size_t)py * (size_t)W + (size_t)px;
                if (ss_bg(c, z)) continue;
                if (x.o.jitter) jit = 2.0 * ss_hash01((uint32_t)tx, (uint32_t)ty, 7u, x.o.seed) - 1.0;
                ssb_normal(c, normals, tx, ty, z, nv);
                if (!x.o.sparse) {
                    ssb_pixel_dir(&x, &dd, (double)tx + 0.5, (double)ty + 0.5, z, nv, jit, 1, 1, &ns, &fs, &ws);
                    acc[o] += ns + fs;
                } else {
                    int cls = (px % 3) + 3 * (py % 3);
                    ssb_pixel_dir(&x, &dd, (double)tx + 0.5, (double)ty + 0.5, z, nv, jit, 1, 0, &ns, &fs, &ws);
                    acc[o] += ns;
                    if (k % 9 == cls) {
                        double za, na[3];
                        unsigned m;
                        ssb_box(c, depth, normals, tx, ty, &za, na, &m);
                        ssb_pixel_dir(&x, &dd, (double)tx + 0.5, (double)ty + 0.5, za, na, jit, 0, 1, &ns, &fs, &ws);
                        acc[npix + o] += fs;
                        acc[2 * npix + o] += ws;
                        acc[3 * npix + o] = (double)m;
                    }
                }
            }
    }
    if (!x.o.sparse) {
        for (py = 0; py < H; py++)
            for (px = 0; px < W; px++) {
                double a = acc[(size_t)py * (size_t)W + (size_t)px] / HFVIS__PI;
                if (ss_bg(c, ss_tex(c, depth, px + c->gx, py + c->gy))) a = 0.0;
                ao[(ptrdiff_t)py * ao_stride + px] = (float)(a > 0.0 ? (a < 1.0 ? a : 1.0) : 0.0);
            }
    } else {
        /* gather ([P4] §10, §11.1; docs/errata.md E38): near field + far field averaged over the accepted 3x3 pixels,
         * renormalised by the summed sector weights; then the optional 5x5 bilateral blur */
        float *tmp = (float *)(acc + npix); /* the far sums are consumed row by row below */
        double *res = acc;                  /* reuse: result per pixel overwrites the near sum */
        for (py = 0; py < H; py++)
            for (px = 0; px < W; px++) {
                size_t o = (size_t)py * (size_t)W + (size_t)px;
                double fsum = 0.0, wsum = 0.0, a;
                unsigned m = (unsigned)acc[3 * npix + o];
                int dx, dy;
                if (ss_bg(c, ss_tex(c, depth, px + c->gx, py + c->gy))) {
                    acc[3 * npix + o] = -1.0;
                    continue;
                }
                for (dy = -1; dy <= 1; dy++)
                    for (dx = -1; dx <= 1; dx++) {
                        size_t q;
                        if (!(m & (1u << ((dy + 1) * 3 + (dx + 1))))) continue;
                        q = (size_t)(py + dy) * (size_t)W + (size_t)(px + dx);
                        fsum += acc[npix + q];
                        wsum += acc[2 * npix + q];
                    }
                a = res[o] / HFVIS__PI + (wsum > 0.0 ? 2.0 * fsum / wsum : 0.0); /* (1/pi) 2 pi fsum/wsum */
                acc[3 * npix + o] = a; /* staged: neighbours still need the far sums */
            }
        for (py = 0; py < H; py++)
            for (px = 0; px < W; px++) {
                size_t o = (size_t)py * (size_t)W + (size_t)px;
                double a = acc[3 * npix + o];
                a = a > 0.0 ? (a < 1.0 ? a : 1.0) : 0.0;
                tmp[o] = (float)a;
            }
        if (x.o.blur) ssb_blur(tmp, W, W, H, x.o.blur_radius, x.o.blur_threshold, (float *)acc, W);
        for (py = 0; py < H; py++)
            for (px = 0; px < W; px++) {
                size_t o = (size_t)py * (size_t)W + (size_t)px;
                float a = x.o.blur ? ((float *)acc)[o] : tmp[o];
                if (ss_bg(c, ss_tex(c, depth, px + c->gx, py + c->gy))) a = 0.0f;
                ao[(ptrdiff_t)py * ao_stride + px] = a;
            }
    }
    s = HFVIS_OK;
done:
    hfvis__free(al, acc);
    hfvis__free(al, pre);
    hfvis__free(al, dd.lines);
    hfvis__free(al, dirs);
    hfvis__free(al, nrm);
    if (own.values) hfvis_ffao_table_free(&own);
    return s;
}

/* ========================================================================================== */
/* 10. The mipmap baseline ([P4] §5)                                                           */
/* ========================================================================================== */

/* Pyramid level sizes: level l is ceil(W / 2^l) x ceil(H / 2^l); offsets into one block. */
static int ssb_mip_layout(const ss_cam *c, int *w, int *h, size_t *off, size_t *total)
{
    int l = 0;
    size_t t = 0;
    w[0] = c->W;
    h[0] = c->H;
    for (;;) {
        off[l] = t;
        t += (size_t)w[l] * (size_t)h[l];
        if ((w[l] == 1 && h[l] == 1) || l == 31) break;
        w[l + 1] = (w[l] + 1) / 2;
        h[l + 1] = (h[l] + 1) / 2;
        l++;
    }
    *total = t;
    return l + 1;
}

/* Depth of level l at continuous full-resolution position (u, v), bilinear over the level's
 * non-background texels (NaN when all taps are background). */
static double ssb_mip_tap(const float *m, int w, int h, int l, double u, double v)
{
    double s = (double)(1 << l), a = u / s - 0.5, b = v / s - 0.5, acc = 0.0, ws = 0.0, fa, fb;
    int x0, y0, k;
    if (a < 0.0) a = 0.0;
    if (b < 0.0) b = 0.0;
    if (a > (double)(w - 1)) a = (double)(w - 1);
    if (b > (double)(h - 1)) b = (double)(h - 1);
    x0 = (int)a;
    y0 = (int)b;
    if (x0 > w - 2) x0 = w > 1 ? w - 2 : 0;
    if (y0 > h - 2) y0 = h > 1 ? h - 2 : 0;
    fa = a - (double)x0;
    fb = b - (double)y0;
    for (k = 0; k < 4; k++) {
        int xx = x0 + (k & 1), yy = y0 + (k >> 1);
        double wt = ((k & 1) ? fa : 1.0 - fa) * ((k >> 1) ? fb : 1.0 - fb), z;
        if (wt <= 0.0 || xx >= w || yy >= h) continue;
        z = (double)m[(size_t)yy * (size_t)w + (size_t)xx];
        if (z != z) continue;
        acc += wt * z;
        ws += wt;
    }
    return ws > 0.0 ? acc / ws : HFVIS__NAN;
}

hfvis_status hfvis_ssao_mipmap(const hfvis_camera *cam, const float *depth, const float *normals,
                               const hfvis_ffao_options *opts, float *ao, ptrdiff_t ao_stride)
{
    ssb_ctx x;
    hfvis_ffao_table own;
    hfvis_status s;
    const ss_cam *c;
    float *nrm = NULL, *mip = NULL;
    int lw[33], lh[33], nl, l, K, k, W, H, px, py, i, j;
    size_t off[33], tot, b;
    const hfvis_allocator *al;
    s = ssb_setup(&x, cam, depth, opts, ao, ao_stride, &own);
    if (s != HFVIS_OK) return s;
    c = &x.c;
    al = x.o.alloc;
    K = x.o.mip_directions;
    W = c->W - 2 * c->gx;
    H = c->H - 2 * c->gy;
    s = HFVIS_ERR_OUT_OF_MEMORY;
    if (!normals) {
        b = ss_bytes3((size_t)c->stride, (size_t)c->H, 3 * sizeof(float));
        if (!b || !(nrm = (float *)hfvis__alloc(al, b))) goto done;
        ss_normals_fill(c, depth, nrm);
        normals = nrm;
    }
    nl = ssb_mip_layout(c, lw, lh, off, &tot);
    b = ss_bytes3(tot, 1, sizeof(float));
    if (!b || !(mip = (float *)hfvis__alloc(al, b))) goto done;
    for (j = 0; j < c->H; j++) /* level 0: depth, NaN for background */
        for (i = 0; i < c->W; i++) {
            double z = ss_tex(c, depth, i, j);
            mip[(size_t)j * (size_t)c->W + (size_t)i] = ss_bg(c, z) ? (float)HFVIS__NAN : (float)z;
        }
    for (l = 1; l < nl; l++) /* averaged mips (continuous) or min-depth "max" mips (thickness) */
        for (j = 0; j < lh[l]; j++)
            for (i = 0; i < lw[l]; i++) {
                double acc = 0.0, mn = HFVIS__INF;
                int q, n = 0;
                for (q = 0; q < 4; q++) {
                    int xx = 2 * i + (q & 1), yy = 2 * j + (q >> 1);
                    double z;
                    if (xx >= lw[l - 1] || yy >= lh[l - 1]) continue;
                    z = (double)mip[off[l - 1] + (size_t)yy * (size_t)lw[l - 1] + (size_t)xx];
                    if (z != z) continue;
                    acc += z;
                    if (z < mn) mn = z;
                    n++;
                }
                mip[off[l] + (size_t)j * (size_t)lw[l] + (size_t)i] =
                    n ? (float)(x.o.thickness > 0.0 ? mn : acc / (double)n) : (float)HFVIS__NAN;
            }
    for (py = 0; py < H; py++)
        for (px = 0; px < W; px++) {
            int tx = px + c->gx, ty = py + c->gy;
            double z = ss_tex(c, depth, tx, ty), nv[3], P[3], v[3], sum = 0.0, a;
            if (ss_bg(c, z)) {
                ao[(ptrdiff_t)py * ao_stride + px] = 0.0f;
                continue;
            }
            ssb_normal(c, normals, tx, ty, z, nv);
            ss_unproject(c, (double)tx + 0.5, (double)ty + 0.5, z, P);
            memcpy(v, P, sizeof v);
            if (c->persp) ss_normalize3(v);
            else v[0] = v[1] = 0.0, v[2] = 1.0;
            for (k = 0; k < K; k++) {
                double phi = x.o.azimuth0_rad + 2.0 * HFVIS__PI * (double)k / (double)K;
                double D[2], e1[3], ea[3], eb[3], yh[3], zs, I = 0.0, dist, step, tmax;
                ssb_hz th = ssb_hz_init(HFVIS__PI);
                double cu = (double)tx + 0.5, cv = (double)ty + 0.5, t1;
                ssb_rx r;
                int last = 0;
                D[0] = cos(phi);
                D[1] = sin(phi);
                ss_plane_e1(c, D[0], D[1], e1);
                ssb_e1_phi(c, phi - HFVIS__PI / (double)K, ea);
                ssb_e1_phi(c, phi + HFVIS__PI / (double)K, eb);
                ss_plane_yhat(c, e1, P, yh);
                zs = c->persp ? 1.0 / yh[2] : 1.0;
                ssb_rx_init(&r, !c->persp, ss_dot3(P, e1), P[2] * zs, ss_dot3(nv, e1), ss_dot3(nv, yh));
                /* distance to the texel-centre rectangle's edge along D */
                tmax = HFVIS__INF;
                for (i = 0; i < 2; i++) {
                    double pc = i ? cv : cu, hi = (double)(i ? c->H : c->W) - 0.5;
                    if (D[i] > 1e-12) t1 = (hi - pc) / D[i];
                    else if (D[i] < -1e-12) t1 = (0.5 - pc) / D[i];
                    else continue;
                    if (t1 < tmax) tmax = t1;
                }
                dist = 1.0;
                step = 1.0;
                while (!last) {
                    double u, vv, lam, lf, zq, z2, Q[3];
                    int l0;
                    if (dist >= tmax) { /* one extra sample at the buffer edge ([P4] §5) */
                        dist = tmax;
                        last = 1;
                        if (!(tmax > 0.0)) break;
                    }
                    u = cu + dist * D[0];
                    vv = cv + dist * D[1];
                    lam = 2.0 * dist * tan(HFVIS__PI / (double)K);
                    lam = lam > 1.0 ? log(lam) / log(2.0) : 0.0;
                    if (lam > (double)(nl - 1)) lam = (double)(nl - 1);
                    l0 = (int)lam;
                    lf = lam - (double)l0;
                    zq = ssb_mip_tap(mip + off[l0], lw[l0], lh[l0], l0, u, vv);
                    if (lf > 0.0 && l0 + 1 < nl) {
                        z2 = ssb_mip_tap(mip + off[l0 + 1], lw[l0 + 1], lh[l0 + 1], l0 + 1, u, vv);
                        if (zq != zq) zq = z2;
                        else if (z2 == z2) zq = (1.0 - lf) * zq + lf * z2;
                    }
                    if (zq == zq) {
                        ss_unproject(c, u, vv, zq, Q);
                        I += ssb_slab(&x.e, &r, ss_dot3(Q, e1), Q[2] * zs, &th);
                    }
                    step *= x.o.mip_growth;
                    dist += step;
                }
                sum += ssb_wedge(ea, eb, v) * I;
            }
            a = sum / HFVIS__PI;
            ao[(ptrdiff_t)py * ao_stride + px] = (float)(a > 0.0 ? (a < 1.0 ? a : 1.0) : 0.0);
        }
    s = HFVIS_OK;
done:
    hfvis__free(al, mip);
    hfvis__free(al, nrm);
    if (own.values) hfvis_ffao_table_free(&own);
    return s;
}

/* ========================================================================================== */
/* 11. Error metrics ([P4] §8, docs/errata.md E36)                                             */
/* ========================================================================================== */

hfvis_status hfvis_ssao_error(const float *ao, ptrdiff_t ao_stride, const float *ref,
                              ptrdiff_t ref_stride, int width, int height, double tolerance,
                              int relative, hfvis_ssao_error_stats *stats, float *error_image,
                              ptrdiff_t error_stride)
{
    double sum = 0.0, sq = 0.0, mx = 0.0, in = 0.0, sd = 0.0;
    size_t n = 0;
    int x, y;
    if (!ao || !ref || !stats || width < 1 || height < 1 || ao_stride < width ||
        ref_stride < width || (error_image && error_stride < width) ||
        !hfvis__plane_fits(ao_stride, height, 1) || !hfvis__plane_fits(ref_stride, height, 1) ||
        (error_image && !hfvis__plane_fits(error_stride, height, 1)) ||
        !(isfinite(tolerance) && tolerance >= 0.0) || (relative != 0 && relative != 1))
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (y = 0; y < height; y++)
        for (x = 0; x < width; x++) {
            double a = (double)ao[(ptrdiff_t)y * ao_stride + x];
            double r = (double)ref[(ptrdiff_t)y * ref_stride + x], e;
            if (!isfinite(a) || !isfinite(r)) {
                if (error_image) error_image[(ptrdiff_t)y * error_stride + x] = 1.0f;
                continue;
            }
            e = fabs(a - r);
            if (relative && fabs(r) > 1e-6) e /= fabs(r);
            sum += e;
            sd += a - r;
            sq += e * e;
            if (e > mx) mx = e;
            if (e <= tolerance) in += 1.0;
            n++;
            if (error_image) {
                double g = 1.0 - e / 0.2; /* white = 0, black >= 20 % ([P4] Fig. 7) */
                error_image[(ptrdiff_t)y * error_stride + x] = (float)(g > 0.0 ? g : 0.0);
            }
        }
    memset(stats, 0, sizeof *stats);
    stats->count = n;
    if (n) {
        stats->mean = sum / (double)n;
        stats->bias = sd / (double)n;
        stats->rms = sqrt(sq / (double)n);
        stats->max = mx;
        stats->within = in / (double)n;
    }
    return HFVIS_OK;
}

/* ========================================================================================== */
/* 12. Laine-Karras bitmask ray-cast ambient occlusion                                         */
/*    S. Laine, T. Karras, "Two Methods for Fast Ray-Cast Ambient Occlusion", EGSR 2010 ([LK]); */
/*    errata and choices: docs/errata.md E39-E46.                              */
/* ========================================================================================== */
/* Contents
 *   12.1 common: allocation, checked sizes, PCG32 / SplitMix64, popcount
 *   12.2 ray sets: Lloyd-relaxed disc with Voronoi jitter, Malley lifting, falloff lengths ([LK]
 *       §3, §6; [LK] §3; docs/errata.md E44), Morton order and per-word cones
 *   12.3 the receiver frame with rotation and tilt jitter ([LK] §3; docs/errata.md E45)
 *   12.4 the blocking predicate and the exact triangle mask ([LK] §3.1, Fig. 1; window [LK] §4.3), the plane
 *       look-up table with node indexing ([LK] §3.1; docs/errata.md E40)
 *   12.5 per-triangle data: minimal bounding sphere (A.5), hexagonal prism (A.6, [LK] Fig. 2)
 *   12.6 options
 *   12.7 G-buffer receivers and Method 1, rasterization ([LK] §4)
 *   12.8 Method 2, BVH traversal with exact node masks ([LK] §5)
 *   12.9 the reference ray caster ([LK] §6)
 *   12.10 the image driver
 * Why the three methods agree bit for bit: they evaluate one predicate (lk_tri_setup +
 * lk_blocks) on the same doubles, and every test that skips work (word cones, culling tests,
 * node masks, volumes, slab tests) is applied only with margins (relative 1e-9 or more) far
 * above the rounding of that predicate (about 1e-15 relative). */

#define LK_DISC_R2 (1.0 - 0x1p-20)  /* disc points have x^2 + y^2 < this, so u_z >= 2^-10 */
#define LK_CONE_PAD 1e-9            /* word cones are widened by this angle (radians) */
#define LK_MARGIN 1e-9              /* relative margin of every work-skipping test */
#define LK_SLAB_PAD 0x1p-40         /* widening of the ray caster's slab test (in t) */
#define LK_JITTER_ATTEMPTS 64       /* Voronoi jitter: rejection attempts per site */

/* ---- 12.1 common ---------------------------------------------------------------------------- */

/* Allocation, checked sizes and PCG32: hfvis__alloc, hfvis__free, hfvis__mul_size, hfvis__pcg32
 * (hfvis.c section 1). */

/* *acc += a*b rounded up to a multiple of 16 (one sub-array of a block); 0 on overflow. */
static int lk_part(size_t *acc, size_t count, size_t elem)
{
    size_t bytes;
    if (!hfvis__mul_size(count, elem, &bytes) || bytes > SIZE_MAX - 15) return 0;
    bytes = (bytes + 15) & ~(size_t)15;
    if (*acc > SIZE_MAX - bytes) return 0;
    *acc += bytes;
    return 1;
}

/* The next sub-array of a block laid out by lk_part. */
static void *lk_take(unsigned char **cursor, size_t count, size_t elem)
{
    void *p = *cursor;
    *cursor += (count * elem + 15) & ~(size_t)15;
    return p;
}

static int lk_popcount(uint32_t x)
{
    x = x - ((x >> 1) & 0x55555555u);
    x = (x & 0x33333333u) + ((x >> 2) & 0x33333333u);
    x = (x + (x >> 4)) & 0x0F0F0F0Fu;
    return (int)((x * 0x01010101u) >> 24);
}

static double lk_dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void lk_cross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static const float *lk_vertex(const hfvis_mesh *m, size_t t, int k)
{
    return m->xyz + 3 * (size_t)m->indices[3 * t + (size_t)k];
}

/* ---- 12.2 ray sets ([LK] §3; docs/errata.md E44) ---------------------------------------------------------------- */

HFVIS_API int hfvis_lk_mask_words(int count)
{
    if (count < 1 || count > HFVIS_LK_MAX_RAYS) return 0;
    return (count + 31) / 32;
}

HFVIS_API double hfvis_lk_obscurance(const uint32_t *mask, int count)
{
    int w, words = hfvis_lk_mask_words(count), bits = 0;
    if (!mask || words == 0) return (double)NAN;
    for (w = 0; w < words; w++) bits += lk_popcount(mask[w]);
    return (double)bits / (double)count;
}

/* Valid bits of word w of an N-ray mask. */
static uint32_t lk_word_bits(int count, int w)
{
    int rest = count - 32 * w;
    return rest >= 32 ? 0xFFFFFFFFu : (uint32_t)((1u << rest) - 1u);
}

static int lk_rays_valid(const hfvis_lk_rays *r)
{
    return r && r->count >= 1 && r->count <= HFVIS_LK_MAX_RAYS &&
           r->words == (r->count + 31) / 32 && r->direction && r->length && r->point &&
           r->word_cone && isfinite(r->radius) && r->radius > 0.0 &&
           isfinite(r->min_elevation) && r->min_elevation > 0.0;
}

HFVIS_API hfvis_lk_ray_options hfvis_lk_ray_options_default(void)
{
    hfvis_lk_ray_options o;
    memset(&o, 0, sizeof o);
    o.pattern = HFVIS_LK_PATTERN_LLOYD_TORUS; /* unbiased at grazing angles (hfvis.h) */
    o.lloyd_iterations = 64;
    o.final_iterations = 4;
    o.density_resolution = 0; /* adaptive */
    o.falloff = HFVIS_LK_FALLOFF_CONSTANT;
    return o;
}

/* Sites of the disc in a uniform B x B grid over [-1, 1]^2 (nearest-site queries for Lloyd). */
typedef struct lk_sites {
    int n, B;
    int wrap;            /* periodic square (torus) instead of the plane */
    double cs;           /* cell size 2/B */
    const double *xy;    /* 2n */
    int *start;          /* B*B + 1 */
    int *items;          /* n: site indices in cell order */
    double *cxy;         /* 2n: their coordinates, in the same order */
} lk_sites;

static int lk_sites_cell(const lk_sites *g, double v)
{
    double c = floor((v + 1.0) / g->cs);
    if (!(c >= 0.0)) return 0;
    if (c >= (double)g->B) return g->B - 1;
    return (int)c;
}

/* Difference a - b, on the torus [-1, 1)^2 the shortest one. */
static double lk_sites_diff(const lk_sites *g, double a, double b)
{
    double d = a - b;
    if (g->wrap) {
        if (d >= 1.0) d -= 2.0;
        else if (d < -1.0) d += 2.0;
    }
    return d;
}

/* v wrapped into [-1, 1). */
static double lk_wrap(double v)
{
    if (v >= 1.0) v -= 2.0;
    if (v < -1.0) v += 2.0;
    if (v >= 1.0 || v < -1.0) v = 0.0;
    return v;
}

static void lk_sites_build(lk_sites *g)
{
    int i, cells = g->B * g->B;
    for (i = 0; i <= cells; i++) g->start[i] = 0;
    for (i = 0; i < g->n; i++)
        g->start[lk_sites_cell(g, g->xy[2 * i + 1]) * g->B + lk_sites_cell(g, g->xy[2 * i]) + 1]++;
    for (i = 0; i < cells; i++) g->start[i + 1] += g->start[i];
    for (i = 0; i < g->n; i++) { /* fill in index order; start[] is shifted back afterwards */
        int c = lk_sites_cell(g, g->xy[2 * i + 1]) * g->B + lk_sites_cell(g, g->xy[2 * i]);
        g->cxy[2 * g->start[c]] = g->xy[2 * i];
        g->cxy[2 * g->start[c] + 1] = g->xy[2 * i + 1];
        g->items[g->start[c]++] = i;
    }
    for (i = cells; i > 0; i--) g->start[i] = g->start[i - 1];
    g->start[0] = 0;
}

/* The nearest site of (qx, qy): smallest squared distance, ties to the lowest index. Rings of
 * cells around the query's cell; after ring k every unseen site is >= k*cs away. */
static int lk_sites_nearest(const lk_sites *g, double qx, double qy)
{
    int cx = lk_sites_cell(g, qx), cy = lk_sites_cell(g, qy), ring, best_i = -1;
    double best = DBL_MAX;
    for (ring = 0; ring < g->B; ring++) {
        int j;
        for (j = cy - ring; j <= cy + ring; j++) {
            int i, step = (j == cy - ring || j == cy + ring) ? 1 : 2 * ring, jj = j;
            if (g->wrap) jj = ((j % g->B) + g->B) % g->B;
            else if (j < 0 || j >= g->B) continue;
            for (i = cx - ring; i <= cx + ring; i += step) {
                int k, c, ii = i;
                if (g->wrap) ii = ((i % g->B) + g->B) % g->B;
                else if (i < 0 || i >= g->B) continue;
                c = jj * g->B + ii;
                for (k = g->start[c]; k < g->start[c + 1]; k++) {
                    double dx = lk_sites_diff(g, g->cxy[2 * k], qx), dy = lk_sites_diff(g, g->cxy[2 * k + 1], qy);
                    double d2 = dx * dx + dy * dy;
                    if (d2 < best || (d2 == best && g->items[k] < best_i)) {
                        best = d2;
                        best_i = g->items[k];
                    }
                }
            }
        }
        if (best_i >= 0) {
            double lim = (double)ring * g->cs;
            if (best < lim * lim || (g->wrap && 2 * ring > g->B + 2)) break;
        }
    }
    return best_i;
}

/* One pass: assign every density point to its nearest site; move = 1 moves each site to the
 * mean of its points (Lloyd step), else only the assignment is kept. */
static void lk_lloyd_pass(lk_sites *g, double *xy, const double *dens, size_t nd, int *assign,
                          double *sum, int move)
{
    size_t k;
    int i;
    lk_sites_build(g);
    for (i = 0; i < g->n; i++) sum[3 * i] = sum[3 * i + 1] = sum[3 * i + 2] = 0.0;
    for (k = 0; k < nd; k++) { /* offsets from the site (shortest on the torus) */
        int s = lk_sites_nearest(g, dens[2 * k], dens[2 * k + 1]);
        assign[k] = s;
        sum[3 * s] += lk_sites_diff(g, dens[2 * k], xy[2 * s]);
        sum[3 * s + 1] += lk_sites_diff(g, dens[2 * k + 1], xy[2 * s + 1]);
        sum[3 * s + 2] += 1.0;
    }
    if (!move) return;
    for (i = 0; i < g->n; i++)
        if (sum[3 * i + 2] > 0.0) {
            xy[2 * i] += sum[3 * i] / sum[3 * i + 2];
            xy[2 * i + 1] += sum[3 * i + 1] / sum[3 * i + 2];
            if (g->wrap) {
                xy[2 * i] = lk_wrap(xy[2 * i]);
                xy[2 * i + 1] = lk_wrap(xy[2 * i + 1]);
            }
        }
}

static void lk_disc_uniform(hfvis__pcg32 *g, double *x, double *y)
{
    double r = sqrt(hfvis__pcg32_unit(g) * LK_DISC_R2), t = 2.0 * HFVIS__PI * hfvis__pcg32_unit(g);
    *x = r * cos(t);
    *y = r * sin(t);
}

/* Shirley-Chiu concentric map of the square [-1, 1]^2 onto the unit disc (area-preserving:
 * P. Shirley, K. Chiu, "A Low Distortion Map Between Disk and Square", JGT 2(3), 1997). */
static void lk_concentric(double a, double b, double *x, double *y)
{
    double r, phi;
    if (a == 0.0 && b == 0.0) {
        *x = *y = 0.0;
        return;
    }
    if (fabs(a) > fabs(b)) {
        r = a;
        phi = (HFVIS__PI / 4.0) * (b / a);
    } else {
        r = b;
        phi = HFVIS__PI / 2.0 - (HFVIS__PI / 4.0) * (a / b);
    }
    *x = r * cos(phi);
    *y = r * sin(phi);
}

/* The Lloyd / Voronoi-jitter disc of [LK] §3; docs/errata.md E44 DISC_SAMPLES, into xy (2n). torus != 0: the same
 * relaxation on the periodic square [-1, 1)^2 (no boundary, so no rim bias), then the concentric
 * map onto the disc. */
static hfvis_status lk_disc_lloyd(int n, const hfvis_lk_ray_options *o, hfvis__pcg32 *g,
                                  const hfvis_allocator *alloc, int torus, double *xy)
{
    int G = o->density_resolution, B = 1, i, it;
    size_t nd = 0, bytes = 0, k;
    unsigned char *block, *cur;
    double *dens, *sum, *box, *jit;
    int *assign;
    lk_sites sites;
    while (B * B * 2 < n) B++; /* about two sites per cell */
    if (G == 0) { /* adaptive: about 48 density points per site, at least 64 x 64 */
        G = (int)ceil(sqrt(48.0 * n * (torus ? 1.0 : 4.0 / HFVIS__PI)));
        if (G < 64) G = 64;
    }
    for (i = 0; i < G; i++) { /* density points: centres of G x G cells (inside the disc) */
        double y = -1.0 + (2.0 * i + 1.0) / G;
        for (it = 0; it < G; it++) {
            double x = -1.0 + (2.0 * it + 1.0) / G;
            if (torus || x * x + y * y < LK_DISC_R2) nd++;
        }
    }
    if (!lk_part(&bytes, nd, 2 * sizeof(double)) || !lk_part(&bytes, nd, sizeof(int)) ||
        !lk_part(&bytes, (size_t)n, 3 * sizeof(double)) ||
        !lk_part(&bytes, (size_t)n, 4 * sizeof(double)) ||
        !lk_part(&bytes, (size_t)n, 2 * sizeof(double)) ||
        !lk_part(&bytes, (size_t)B * (size_t)B + 1, sizeof(int)) ||
        !lk_part(&bytes, (size_t)n, sizeof(int)) || !lk_part(&bytes, (size_t)n, 2 * sizeof(double)))
        return HFVIS_ERR_LIMIT; /* only on 32-bit size_t */
    block = (unsigned char *)hfvis__alloc(alloc, bytes);
    if (!block) return HFVIS_ERR_OUT_OF_MEMORY;
    cur = block;
    dens = (double *)lk_take(&cur, nd, 2 * sizeof(double));
    assign = (int *)lk_take(&cur, nd, sizeof(int));
    sum = (double *)lk_take(&cur, (size_t)n, 3 * sizeof(double));
    box = (double *)lk_take(&cur, (size_t)n, 4 * sizeof(double));
    jit = (double *)lk_take(&cur, (size_t)n, 2 * sizeof(double));
    sites.start = (int *)lk_take(&cur, (size_t)B * (size_t)B + 1, sizeof(int));
    sites.items = (int *)lk_take(&cur, (size_t)n, sizeof(int));
    sites.cxy = (double *)lk_take(&cur, (size_t)n, 2 * sizeof(double));
    sites.n = n;
    sites.B = B;
    sites.wrap = torus;
    sites.cs = 2.0 / B;
    sites.xy = xy;
    k = 0;
    for (i = 0; i < G; i++) {
        double y = -1.0 + (2.0 * i + 1.0) / G;
        for (it = 0; it < G; it++) {
            double x = -1.0 + (2.0 * it + 1.0) / G;
            if (torus || x * x + y * y < LK_DISC_R2) {
                dens[2 * k] = x;
                dens[2 * k + 1] = y;
                k++;
            }
        }
    }
    for (i = 0; i < n; i++) { /* 1. random points */
        if (torus) {
            xy[2 * i] = lk_wrap(2.0 * hfvis__pcg32_unit(g) - 1.0);
            xy[2 * i + 1] = lk_wrap(2.0 * hfvis__pcg32_unit(g) - 1.0);
        } else {
            lk_disc_uniform(g, xy + 2 * i, xy + 2 * i + 1);
        }
    }
    /* 2. Lloyd relaxation */
    for (it = 0; it < o->lloyd_iterations; it++) lk_lloyd_pass(&sites, xy, dens, nd, assign, sum, 1);
    /* 3. Voronoi jitter: each site -> a uniform point of its own cell (cells of the relaxed set,
     * sampled by rejection in the box of its density points, offsets from the site) */
    lk_lloyd_pass(&sites, xy, dens, nd, assign, sum, 0);
    for (i = 0; i < n; i++) {
        box[4 * i] = box[4 * i + 1] = DBL_MAX;
        box[4 * i + 2] = box[4 * i + 3] = -DBL_MAX;
    }
    for (k = 0; k < nd; k++) {
        double *b = box + 4 * assign[k];
        double dx = lk_sites_diff(&sites, dens[2 * k], xy[2 * assign[k]]);
        double dy = lk_sites_diff(&sites, dens[2 * k + 1], xy[2 * assign[k] + 1]);
        if (dx < b[0]) b[0] = dx;
        if (dy < b[1]) b[1] = dy;
        if (dx > b[2]) b[2] = dx;
        if (dy > b[3]) b[3] = dy;
    }
    for (i = 0; i < n; i++) {
        const double *b = box + 4 * i, h = 1.0 / G;
        int a;
        jit[2 * i] = xy[2 * i];
        jit[2 * i + 1] = xy[2 * i + 1];
        if (b[0] > b[2]) continue; /* no density point: keep the site */
        for (a = 0; a < LK_JITTER_ATTEMPTS; a++) {
            double qx = xy[2 * i] + b[0] - h + (b[2] - b[0] + 2.0 * h) * hfvis__pcg32_unit(g);
            double qy = xy[2 * i + 1] + b[1] - h + (b[3] - b[1] + 2.0 * h) * hfvis__pcg32_unit(g);
            if (torus) {
                qx = lk_wrap(qx);
                qy = lk_wrap(qy);
            } else if (!(qx * qx + qy * qy < LK_DISC_R2)) {
                continue;
            }
            if (lk_sites_nearest(&sites, qx, qy) == i) {
                jit[2 * i] = qx;
                jit[2 * i + 1] = qy;
                break;
            }
        }
    }
    memcpy(xy, jit, sizeof(double) * 2 * (size_t)n);
    /* 4. a few more Lloyd steps */
    for (it = 0; it < o->final_iterations; it++) lk_lloyd_pass(&sites, xy, dens, nd, assign, sum, 1);
    if (torus) {
        const double sc = sqrt(LK_DISC_R2);
        for (i = 0; i < n; i++) {
            double x, y;
            lk_concentric(xy[2 * i], xy[2 * i + 1], &x, &y);
            xy[2 * i] = sc * x;
            xy[2 * i + 1] = sc * y;
        }
    }
    hfvis__free(alloc, block);
    return HFVIS_OK;
}

static uint32_t lk_morton16(uint32_t v)
{
    v &= 0xFFFFu;
    v = (v | (v << 8)) & 0x00FF00FFu;
    v = (v | (v << 4)) & 0x0F0F0F0Fu;
    v = (v | (v << 2)) & 0x33333333u;
    v = (v | (v << 1)) & 0x55555555u;
    return v;
}

static int lk_cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* Per-word cones (axis, cos, sin of the widened half-angle, least and largest length) and the
 * least elevation. */
static void lk_rays_finish(hfvis_lk_rays *r)
{
    int w, i;
    double emin = HFVIS__INF;
    for (i = 0; i < r->count; i++) {
        double e = asin(r->direction[3 * i + 2]);
        if (e < emin) emin = e;
    }
    r->min_elevation = emin;
    r->equal_lengths = 1;
    for (i = 0; i < r->count; i++)
        if (r->length[i] != 1.0) r->equal_lengths = 0;
    for (w = 0; w < r->words; w++) {
        int i0 = 32 * w, i1 = i0 + 32 < r->count ? i0 + 32 : r->count;
        double ax = 0.0, ay = 0.0, az = 0.0, len, cmin = 1.0, th, lmin = HFVIS__INF, lmax = 0.0;
        double *c = r->word_cone + 7 * w;
        for (i = i0; i < i1; i++) {
            ax += r->direction[3 * i];
            ay += r->direction[3 * i + 1];
            az += r->direction[3 * i + 2];
        }
        len = sqrt(ax * ax + ay * ay + az * az); /* > 0: every u_z > 0 */
        c[0] = ax / len;
        c[1] = ay / len;
        c[2] = az / len;
        for (i = i0; i < i1; i++) {
            double d = lk_dot(c, r->direction + 3 * i);
            if (d < cmin) cmin = d;
            if (r->length[i] < lmin) lmin = r->length[i];
            if (r->length[i] > lmax) lmax = r->length[i];
        }
        if (cmin > 1.0) cmin = 1.0;
        if (cmin < -1.0) cmin = -1.0;
        th = acos(cmin) + LK_CONE_PAD;
        if (th > HFVIS__PI) th = HFVIS__PI;
        c[3] = cos(th);
        c[4] = sin(th);
        c[5] = lmin;
        c[6] = lmax;
    }
}

/* Allocate a ray set's block and set its pointers (count, radius set). */
static hfvis_status lk_rays_alloc(int count, double radius, const hfvis_allocator *alloc,
                                  hfvis_lk_rays *r)
{
    int words = (count + 31) / 32;
    size_t doubles = 7 * (size_t)count + 7 * (size_t)words;
    double *block = (double *)hfvis__alloc(alloc, doubles * sizeof(double));
    if (!block) return HFVIS_ERR_OUT_OF_MEMORY;
    memset(r, 0, sizeof *r);
    r->count = count;
    r->words = words;
    r->radius = radius;
    r->direction = block;
    r->length = block + 3 * (size_t)count;
    r->point = block + 4 * (size_t)count;
    r->word_cone = block + 7 * (size_t)count;
    return HFVIS_OK;
}

/* Falloff inverse l/r = sup{x in [0, 1] : rho(x) >= xi}. */
static double lk_falloff_inverse(const hfvis_lk_ray_options *o, double xi)
{
    double lo = 0.0, hi = 1.0;
    int it;
    switch (o->falloff) {
    case HFVIS_LK_FALLOFF_LINEAR: return 1.0 - xi;
    case HFVIS_LK_FALLOFF_QUADRATIC: return 1.0 - sqrt(xi);
    case HFVIS_LK_FALLOFF_CUSTOM:
        if (o->falloff_fn(o->falloff_user, 1.0) >= xi) return 1.0;
        if (!(o->falloff_fn(o->falloff_user, 0.0) >= xi)) return 0.0;
        for (it = 0; it < 64; it++) {
            double mid = 0.5 * (lo + hi);
            if (o->falloff_fn(o->falloff_user, mid) >= xi) lo = mid;
            else hi = mid;
        }
        return lo;
    default: return 1.0;
    }
}

HFVIS_API hfvis_status hfvis_lk_rays_build(int count, double radius,
                                           const hfvis_lk_ray_options *opts, hfvis_lk_rays *out)
{
    hfvis_lk_ray_options o = hfvis_lk_ray_options_default();
    hfvis_lk_rays r;
    hfvis_status s;
    hfvis__pcg32 g;
    uint64_t *keys;
    double *xy;
    int i;
    if (!out || count < 1 || count > HFVIS_LK_MAX_RAYS || !isfinite(radius) || !(radius > 0.0))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (opts) {
        o.alloc = opts->alloc;
        o.seed = opts->seed;
        if (opts->pattern != HFVIS_LK_PATTERN_DEFAULT) o.pattern = opts->pattern;
        if (opts->lloyd_iterations) o.lloyd_iterations = opts->lloyd_iterations;
        if (opts->final_iterations) o.final_iterations = opts->final_iterations;
        if (opts->density_resolution) o.density_resolution = opts->density_resolution;
        if (opts->falloff != HFVIS_LK_FALLOFF_DEFAULT) o.falloff = opts->falloff;
        o.falloff_fn = opts->falloff_fn;
        o.falloff_user = opts->falloff_user;
    }
    if (o.pattern < HFVIS_LK_PATTERN_LLOYD || o.pattern > HFVIS_LK_PATTERN_LLOYD_TORUS ||
        o.lloyd_iterations < 1 || o.lloyd_iterations > 10000 || o.final_iterations < 1 ||
        o.final_iterations > 10000 || (o.density_resolution != 0 && o.density_resolution < 16) || o.density_resolution > 2048 ||
        o.falloff < HFVIS_LK_FALLOFF_CONSTANT || o.falloff > HFVIS_LK_FALLOFF_CUSTOM)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.falloff == HFVIS_LK_FALLOFF_CUSTOM) { /* finite, in [0, 1], non-increasing */
        double prev = 1.0;
        if (!o.falloff_fn) return HFVIS_ERR_INVALID_ARGUMENT;
        for (i = 0; i <= 1024; i++) {
            double v = o.falloff_fn(o.falloff_user, (double)i / 1024.0);
            if (!isfinite(v) || v < 0.0 || v > 1.0 || v > prev) return HFVIS_ERR_INVALID_ARGUMENT;
            prev = v;
        }
    }
    s = lk_rays_alloc(count, radius, o.alloc, &r);
    if (s != HFVIS_OK) return s;
    /* the disc points go to `point` (2n doubles), the sort keys to `length` (n, as u64) */
    xy = r.point;
    keys = (uint64_t *)(void *)r.length;
    hfvis__pcg32_seed(&g, o.seed, 0x4C4B31u);
    if (o.pattern == HFVIS_LK_PATTERN_LLOYD || o.pattern == HFVIS_LK_PATTERN_LLOYD_TORUS) {
        s = lk_disc_lloyd(count, &o, &g, o.alloc, o.pattern == HFVIS_LK_PATTERN_LLOYD_TORUS, xy);
        if (s != HFVIS_OK) {
            hfvis__free(o.alloc, r.direction);
            return s;
        }
    } else {
        for (i = 0; i < count; i++) lk_disc_uniform(&g, xy + 2 * i, xy + 2 * i + 1);
    }
    /* Morton order of the disc points: each 32-ray word covers a compact patch */
    for (i = 0; i < count; i++) {
        uint32_t qx = (uint32_t)((xy[2 * i] + 1.0) * 32767.5);
        uint32_t qy = (uint32_t)((xy[2 * i + 1] + 1.0) * 32767.5);
        keys[i] = ((uint64_t)(lk_morton16(qx) | (lk_morton16(qy) << 1)) << 32) | (uint64_t)i;
    }
    qsort(keys, (size_t)count, sizeof(uint64_t), lk_cmp_u64);
    for (i = 0; i < count; i++) { /* Malley lifting (cosine-weighted) */
        size_t j = (size_t)(keys[i] & 0xFFFFFFFFu);
        double x = xy[2 * j], y = xy[2 * j + 1], z2 = 1.0 - x * x - y * y;
        r.direction[3 * i] = x;
        r.direction[3 * i + 1] = y;
        r.direction[3 * i + 2] = sqrt(z2 > 0.0 ? z2 : 0.0);
    }
    /* lengths: xi_i = (perm(i) + 1/2)/N, perm a seeded random permutation (stream 2) */
    {
        hfvis__pcg32 g2;
        uint32_t *perm = (uint32_t *)(void *)r.point; /* point is free again */
        hfvis__pcg32_seed(&g2, o.seed, 0x4C4B32u);
        for (i = 0; i < count; i++) perm[i] = (uint32_t)i;
        for (i = count - 1; i > 0; i--) {
            uint32_t j = hfvis__pcg32_below(&g2, (uint32_t)i + 1u), t = perm[i];
            perm[i] = perm[j];
            perm[j] = t;
        }
        for (i = 0; i < count; i++) {
            double xi = ((double)perm[i] + 0.5) / (double)count;
            r.length[i] = lk_falloff_inverse(&o, xi);
        }
    }
    for (i = 0; i < 3 * count; i++) r.point[i] = r.length[i / 3] * r.direction[i];
    lk_rays_finish(&r);
    *out = r;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_lk_rays_custom(int count, double radius, const double *directions,
                                            const double *lengths, const hfvis_allocator *alloc,
                                            hfvis_lk_rays *out)
{
    hfvis_lk_rays r;
    hfvis_status s;
    int i;
    if (!out || !directions || count < 1 || count > HFVIS_LK_MAX_RAYS || !isfinite(radius) ||
        !(radius > 0.0))
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (i = 0; i < count; i++) {
        const double *d = directions + 3 * i;
        double len2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        if (!hfvis__all_finite(d, 3) || !(len2 > 0.0) || !isfinite(len2) || !(d[2] / sqrt(len2) > 0.0))
            return HFVIS_ERR_INVALID_ARGUMENT;
        if (lengths && !(lengths[i] >= 0.0 && lengths[i] <= 1.0)) return HFVIS_ERR_INVALID_ARGUMENT;
    }
    s = lk_rays_alloc(count, radius, alloc, &r);
    if (s != HFVIS_OK) return s;
    for (i = 0; i < count; i++) {
        const double *d = directions + 3 * i;
        double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        int a;
        for (a = 0; a < 3; a++) r.direction[3 * i + a] = d[a] / len;
        r.length[i] = lengths ? lengths[i] : 1.0;
    }
    for (i = 0; i < 3 * count; i++) r.point[i] = r.length[i / 3] * r.direction[i];
    lk_rays_finish(&r);
    *out = r;
    return HFVIS_OK;
}

HFVIS_API void hfvis_lk_rays_free(const hfvis_allocator *alloc, hfvis_lk_rays *rays)
{
    if (!rays) return;
    hfvis__free(alloc, rays->direction);
    memset(rays, 0, sizeof *rays);
}

/* Largest value of n.u over the unit directions u of a word cone (n unit):
 * cos(max(phi - theta, 0)), phi = angle(n, axis). */
static double lk_cone_max(const double *cone, const double n[3])
{
    double c = lk_dot(n, cone), s;
    if (c >= cone[3]) return 1.0;
    s = 1.0 - c * c;
    s = s > 0.0 ? sqrt(s) : 0.0;
    return c * cone[3] + s * cone[4];
}

/* Least value of n.u over the cone: cos(min(phi + theta, pi)). */
static double lk_cone_min(const double *cone, const double n[3])
{
    double c = lk_dot(n, cone), s;
    if (-c >= cone[3]) return -1.0;
    s = 1.0 - c * c;
    s = s > 0.0 ? sqrt(s) : 0.0;
    return c * cone[3] - s * cone[4];
}

/* ---- 12.3 receiver frame ([LK] §3; docs/errata.md E45) -------------------------------------------------------- */

/* Branchless orthonormal basis of the unit vector n: T. Duff, J. Burgess, P. Christensen et al.,
 * "Building an Orthonormal Basis, Revisited", JCGT 6(1), 2017, Listing 3. */
static void lk_onb(const double n[3], double t1[3], double t2[3])
{
    double sign = copysign(1.0, n[2]), a = -1.0 / (sign + n[2]), b = n[0] * n[1] * a;
    t1[0] = 1.0 + sign * n[0] * n[0] * a;
    t1[1] = sign * b;
    t1[2] = -sign * n[0];
    t2[0] = b;
    t2[1] = sign + n[1] * n[1] * a;
    t2[2] = -n[1];
}

/* Jitter parameters resolved once per call. */
typedef struct lk_jit {
    int none;
    double rot, tilt;  /* psi bound; delta = min(tilt_max, 0.9 min_elevation) */
    uint64_t seed;
} lk_jit;

static void lk_jit_init(lk_jit *j, const hfvis_lk_rays *r, hfvis_lk_jitter mode, double rot,
                        double tilt, uint64_t seed)
{
    j->none = mode == HFVIS_LK_JITTER_NONE;
    if (mode == HFVIS_LK_JITTER_DEFAULT) {
        rot = HFVIS__PI;
        tilt = HFVIS_LK_DEFAULT_TILT;
    }
    j->rot = rot;
    j->tilt = tilt < 0.9 * r->min_elevation ? tilt : 0.9 * r->min_elevation;
    j->seed = seed;
}

/* The frame of a non-zero finite normal (rows x', y', z'). */
static void lk_frame_make(const lk_jit *j, const double normal[3], uint64_t key, double F[9])
{
    double n[3], t1[3], t2[3], len = sqrt(lk_dot(normal, normal));
    int a;
    for (a = 0; a < 3; a++) n[a] = normal[a] / len;
    lk_onb(n, t1, t2);
    if (j->none) {
        for (a = 0; a < 3; a++) {
            F[a] = t1[a];
            F[3 + a] = t2[a];
            F[6 + a] = n[a];
        }
        return;
    }
    {
        uint64_t s = j->seed ^ (key * 0xD1B54A32D192ED03ull);
        double x1 = (double)(hfvis__splitmix64(&s) >> 11) * (1.0 / 9007199254740992.0);
        double x2 = (double)(hfvis__splitmix64(&s) >> 11) * (1.0 / 9007199254740992.0);
        double x3 = (double)(hfvis__splitmix64(&s) >> 11) * (1.0 / 9007199254740992.0);
        double dl = j->tilt * x1, ph = 2.0 * HFVIS__PI * x2, psi = j->rot * (2.0 * x3 - 1.0);
        double np[3], x0[3], y0[3], cd = cos(dl), sd = sin(dl), cp = cos(ph), sp = sin(ph);
        double cs = cos(psi), sn = sin(psi);
        for (a = 0; a < 3; a++) np[a] = cd * n[a] + sd * (cp * t1[a] + sp * t2[a]);
        len = sqrt(lk_dot(np, np));
        for (a = 0; a < 3; a++) np[a] /= len;
        lk_onb(np, x0, y0);
        for (a = 0; a < 3; a++) {
            F[a] = cs * x0[a] + sn * y0[a];
            F[3 + a] = -sn * x0[a] + cs * y0[a];
            F[6 + a] = np[a];
        }
    }
}

static int lk_jitter_valid(hfvis_lk_jitter mode, double rot, double tilt)
{
    if (mode == HFVIS_LK_JITTER_DEFAULT || mode == HFVIS_LK_JITTER_NONE) return 1;
    return mode == HFVIS_LK_JITTER_CUSTOM && rot >= 0.0 && rot <= HFVIS__PI && tilt >= 0.0 &&
           tilt <= 0.5 * HFVIS__PI;
}

HFVIS_API hfvis_status hfvis_lk_frame(const hfvis_lk_rays *rays, const double normal[3],
                                      uint64_t seed, uint64_t key, hfvis_lk_jitter jitter,
                                      double rotation_max_rad, double tilt_max_rad,
                                      double frame[9])
{
    lk_jit j;
    double len2;
    if (!lk_rays_valid(rays) || !normal || !frame || !hfvis__all_finite(normal, 3) ||
        !lk_jitter_valid(jitter, rotation_max_rad, tilt_max_rad))
        return HFVIS_ERR_INVALID_ARGUMENT;
    len2 = lk_dot(normal, normal);
    if (!(len2 > 0.0) || !isfinite(len2)) return HFVIS_ERR_INVALID_ARGUMENT;
    lk_jit_init(&j, rays, jitter, rotation_max_rad, tilt_max_rad, seed);
    lk_frame_make(&j, normal, key, frame);
    return HFVIS_OK;
}

/* ---- 12.4 the blocking predicate, triangle masks, the plane look-up table -------------------- */

/* One triangle prepared for one receiver ([LK] §3.1, Fig. 1 in the receiver's frame). The predicate of
 * ray s is lk_blocks(t, s); dr = +infinity makes it false for every ray (skipped, facing away,
 * too far), so lk_blocks is the complete predicate whatever the verdict. */
typedef struct lk_tri {
    double e[9];        /* edge planes e1, e2, e3 (inside: e.s >= 0) */
    double m[3];        /* unit plane normal toward the plane (m.a = d > 0) */
    double dr;          /* d / r_max (+inf: never blocks) */
    double drmin;       /* d / r_min when 0 < d < r_min, else +inf */
    double zmax;        /* largest local z of the vertices (horizon test) */
    hfvis_lk_verdict verdict;
} lk_tri;

/* v - p in the frame F (each row dotted with the double difference, x + y + z). */
static void lk_local(const double F[9], const double p[3], const float v[3], double out[3])
{
    double dx = (double)v[0] - p[0], dy = (double)v[1] - p[1], dz = (double)v[2] - p[2];
    out[0] = F[0] * dx + F[1] * dy + F[2] * dz;
    out[1] = F[3] * dx + F[4] * dy + F[5] * dz;
    out[2] = F[6] * dx + F[7] * dy + F[8] * dz;
}

/* World zero-area test shared by every method: (v1 - v0) x (v2 - v0) in double exactly 0. */
static int lk_world_degenerate(const float *v0, const float *v1, const float *v2)
{
    double u[3], w[3], n[3];
    int a;
    for (a = 0; a < 3; a++) {
        u[a] = (double)v1[a] - (double)v0[a];
        w[a] = (double)v2[a] - (double)v0[a];
    }
    lk_cross(u, w, n);
    return n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0;
}

/* The setup of [LK] §3.1, Fig. 1 (see hfvis.h): a, b, c local; n = (b - a) x (c - a); h = nh.a; the
 * epsilon, one-sided and far rules; m and the oriented edge planes. */
static void lk_tri_setup(lk_tri *t, const double F[9], const double p[3], const float *v0,
                         const float *v1, const float *v2, int two_sided, double r_min,
                         double r_max, double eps)
{
    double a[3], b[3], c[3], u[3], w[3], n[3], len2, len, h, d;
    int k;
    t->dr = HFVIS__INF;
    t->drmin = HFVIS__INF;
    if (lk_world_degenerate(v0, v1, v2)) {
        memset(t->e, 0, sizeof t->e);
        t->m[0] = t->m[1] = t->m[2] = 0.0;
        t->zmax = 0.0;
        t->verdict = HFVIS_LK_TRI_DEGENERATE;
        return;
    }
    lk_local(F, p, v0, a);
    lk_local(F, p, v1, b);
    lk_local(F, p, v2, c);
    t->zmax = a[2] > b[2] ? a[2] : b[2];
    if (c[2] > t->zmax) t->zmax = c[2];
    for (k = 0; k < 3; k++) {
        u[k] = b[k] - a[k];
        w[k] = c[k] - a[k];
    }
    lk_cross(u, w, n);
    len2 = lk_dot(n, n);
    lk_cross(a, b, t->e);
    lk_cross(b, c, t->e + 3);
    lk_cross(c, a, t->e + 6);
    if (!(len2 > 0.0) || !isfinite(len2)) {
        t->m[0] = t->m[1] = t->m[2] = 0.0;
        t->verdict = HFVIS_LK_TRI_DEGENERATE;
        return;
    }
    len = sqrt(len2);
    for (k = 0; k < 3; k++) n[k] /= len;
    h = lk_dot(n, a);
    if (h < 0.0) { /* orient: m toward the plane, edge planes inward */
        for (k = 0; k < 3; k++) t->m[k] = -n[k];
        for (k = 0; k < 9; k++) t->e[k] = -t->e[k];
    } else {
        for (k = 0; k < 3; k++) t->m[k] = n[k];
    }
    d = fabs(h);
    if (!(d >= eps)) {
        t->verdict = HFVIS_LK_TRI_SELF;
        return;
    }
    if (!two_sided && h >= 0.0) {
        t->verdict = HFVIS_LK_TRI_FACING_AWAY;
        return;
    }
    if (d > r_max) {
        t->verdict = HFVIS_LK_TRI_TOO_FAR;
        return;
    }
    t->verdict = HFVIS_LK_TRI_MASKED;
    t->dr = d / r_max;
    if (r_min > 0.0 && d < r_min) t->drmin = d / r_min;
}

/* The predicate: s inside the three edge planes and the segment [0, s] reaching the plane
 * within the window (see hfvis.h). The only place it is evaluated. */
static int lk_blocks(const lk_tri *t, const double *s)
{
    double ms;
    if (t->e[0] * s[0] + t->e[1] * s[1] + t->e[2] * s[2] < 0.0) return 0;
    if (t->e[3] * s[0] + t->e[4] * s[1] + t->e[5] * s[2] < 0.0) return 0;
    if (t->e[6] * s[0] + t->e[7] * s[1] + t->e[8] * s[2] < 0.0) return 0;
    ms = t->m[0] * s[0] + t->m[1] * s[1] + t->m[2] * s[2];
    return ms >= t->dr && !(ms > t->drmin);
}

/* Exact triangle mask: the predicate for every ray; a word is skipped when its cone lies
 * outside an edge plane or cannot reach the plane, by more than LK_MARGIN (so the skipped
 * rays are exactly those the per-ray loop rejects). skip (may be NULL): the caller's
 * accumulated mask; words it has full are left 0 (the OR is the same). */
static void lk_mask_exact(const hfvis_lk_rays *R, const lk_tri *t, const uint32_t *skip,
                          uint32_t *out)
{
    double eh[9], lim;
    int w, k, i;
    if (t->dr == HFVIS__INF) {
        memset(out, 0, sizeof(uint32_t) * (size_t)R->words);
        return;
    }
    for (k = 0; k < 3; k++) {
        const double *e = t->e + 3 * k;
        double len = sqrt(lk_dot(e, e));
        if (len > 0.0) {
            eh[3 * k] = e[0] / len;
            eh[3 * k + 1] = e[1] / len;
            eh[3 * k + 2] = e[2] / len;
        } else {
            eh[3 * k] = eh[3 * k + 1] = eh[3 * k + 2] = 0.0; /* never skips */
        }
    }
    lim = t->dr - LK_MARGIN * (1.0 + t->dr);
    for (w = 0; w < R->words; w++) {
        const double *cone = R->word_cone + 7 * w;
        int i0 = 32 * w, i1 = i0 + 32 < R->count ? i0 + 32 : R->count;
        uint32_t bits = 0;
        double mx;
        if (skip && (~skip[w] & lk_word_bits(R->count, w)) == 0) { /* all already blocked */
            out[w] = 0;
            continue;
        }
        mx = lk_cone_max(cone, t->m);
        if (lk_cone_max(cone, eh) < -LK_MARGIN || lk_cone_max(cone, eh + 3) < -LK_MARGIN ||
            lk_cone_max(cone, eh + 6) < -LK_MARGIN || (mx >= 0.0 ? cone[6] * mx : cone[5] * mx) < lim) {
            out[w] = 0;
            continue;
        }
        for (i = i0; i < i1; i++) { /* lk_blocks, branch-free (the same expressions) */
            const double *sp = R->point + 3 * i;
            double a = t->e[0] * sp[0] + t->e[1] * sp[1] + t->e[2] * sp[2];
            double b = t->e[3] * sp[0] + t->e[4] * sp[1] + t->e[5] * sp[2];
            double c = t->e[6] * sp[0] + t->e[7] * sp[1] + t->e[8] * sp[2];
            double ms = t->m[0] * sp[0] + t->m[1] * sp[1] + t->m[2] * sp[2];
            uint32_t hit = (uint32_t)((a >= 0.0) & (b >= 0.0) & (c >= 0.0) & (ms >= t->dr) & !(ms > t->drmin));
            bits |= hit << (i - i0);
        }
        out[w] = bits;
    }
}

/* ---- the 3-D plane table ([LK] §3.1; docs/errata.md E40, node convention) ---- */

HFVIS_API size_t hfvis_lk_lut_bytes(int resolution, int count, int two_tables)
{
    size_t n, b;
    int words = hfvis_lk_mask_words(count);
    if (resolution < HFVIS_LK_LUT_MIN_RESOLUTION || resolution > HFVIS_LK_LUT_MAX_RESOLUTION ||
        words == 0)
        return 0;
    if (!hfvis__mul_size((size_t)resolution, (size_t)resolution, &n) || !hfvis__mul_size(n, (size_t)resolution, &n) ||
        !hfvis__mul_size(n, (size_t)words * sizeof(uint32_t), &b) || !hfvis__mul_size(b, two_tables ? 2 : 1, &b))
        return 0;
    return b;
}

static void lk_lut_fill(const hfvis_lk_rays *R, int T, int dirs, uint32_t *tab)
{
    const double *pts = dirs ? R->direction : R->point;
    int kx, ky, kz, w, i;
    size_t idx = 0;
    for (kz = 0; kz < T; kz++)
        for (ky = 0; ky < T; ky++)
            for (kx = 0; kx < T; kx++, idx += (size_t)R->words) {
                double q[3], s, len, m[3], delta;
                q[0] = -1.0 + 2.0 * kx / (T - 1);
                q[1] = -1.0 + 2.0 * ky / (T - 1);
                q[2] = -1.0 + 2.0 * kz / (T - 1);
                s = fabs(q[0]);
                if (fabs(q[1]) > s) s = fabs(q[1]);
                if (fabs(q[2]) > s) s = fabs(q[2]);
                if (s < 0.125) { /* unused core (d > r) */
                    memset(tab + idx, 0, sizeof(uint32_t) * (size_t)R->words);
                    continue;
                }
                len = sqrt(lk_dot(q, q));
                m[0] = q[0] / len;
                m[1] = q[1] / len;
                m[2] = q[2] / len;
                delta = (1.0 - s) * 8.0 / 7.0;
                for (w = 0; w < R->words; w++) {
                    const double *cone = R->word_cone + 7 * w;
                    double lmax = dirs ? 1.0 : cone[6], lmin = dirs ? 1.0 : cone[5];
                    double mx = lk_cone_max(cone, m), mn = lk_cone_min(cone, m);
                    int i0 = 32 * w, i1 = i0 + 32 < R->count ? i0 + 32 : R->count;
                    uint32_t bits = 0;
                    if ((mx >= 0.0 ? lmax * mx : lmin * mx) < delta - LK_MARGIN) {
                        tab[idx + (size_t)w] = 0;
                        continue;
                    }
                    if (mn > 0.0 && lmin * mn > delta + LK_MARGIN) {
                        tab[idx + (size_t)w] = lk_word_bits(R->count, w);
                        continue;
                    }
                    for (i = i0; i < i1; i++)
                        if (lk_dot(m, pts + 3 * i) > delta) bits |= 1u << (i - i0);
                    tab[idx + (size_t)w] = bits;
                }
            }
}

HFVIS_API hfvis_status hfvis_lk_lut_build(const hfvis_lk_rays *rays, int resolution,
                                          const hfvis_allocator *alloc, hfvis_lk_lut *out)
{
    size_t one, all;
    hfvis_lk_lut L;
    if (!lk_rays_valid(rays) || !out || resolution < HFVIS_LK_LUT_MIN_RESOLUTION ||
        resolution > HFVIS_LK_LUT_MAX_RESOLUTION)
        return HFVIS_ERR_INVALID_ARGUMENT;
    one = hfvis_lk_lut_bytes(resolution, rays->count, 0);
    all = hfvis_lk_lut_bytes(resolution, rays->count, !rays->equal_lengths);
    if (one == 0 || all == 0 || all > HFVIS_LK_LUT_MAX_BYTES) return HFVIS_ERR_LIMIT;
    memset(&L, 0, sizeof L);
    L.resolution = resolution;
    L.count = rays->count;
    L.words = rays->words;
    L.bytes = all;
    L.masks = (uint32_t *)hfvis__alloc(alloc, one);
    if (!L.masks) return HFVIS_ERR_OUT_OF_MEMORY;
    if (!rays->equal_lengths) {
        L.directions = (uint32_t *)hfvis__alloc(alloc, one);
        if (!L.directions) {
            hfvis__free(alloc, L.masks);
            return HFVIS_ERR_OUT_OF_MEMORY;
        }
    }
    lk_lut_fill(rays, resolution, 0, L.masks);
    if (L.directions) lk_lut_fill(rays, resolution, 1, L.directions);
    *out = L;
    return HFVIS_OK;
}

HFVIS_API void hfvis_lk_lut_free(const hfvis_allocator *alloc, hfvis_lk_lut *lut)
{
    if (!lut) return;
    hfvis__free(alloc, lut->directions);
    hfvis__free(alloc, lut->masks);
    memset(lut, 0, sizeof *lut);
}

/* Node of (m, delta); m finite and non-zero (checked by the callers). */
static size_t lk_lut_node(int T, const double m[3], double dr)
{
    double mx = fabs(m[0]), sc;
    int k[3], a;
    if (fabs(m[1]) > mx) mx = fabs(m[1]);
    if (fabs(m[2]) > mx) mx = fabs(m[2]);
    if (!(dr > 0.0)) dr = 0.0;
    if (dr > 1.0) dr = 1.0;
    sc = (1.0 - 7.0 * dr / 8.0) / mx;
    for (a = 0; a < 3; a++) {
        double f = floor((m[a] * sc + 1.0) * (T - 1) / 2.0 + 0.5);
        k[a] = f < 0.0 ? 0 : f > (double)(T - 1) ? T - 1 : (int)f;
    }
    return ((size_t)k[2] * (size_t)T + (size_t)k[1]) * (size_t)T + (size_t)k[0];
}

HFVIS_API hfvis_status hfvis_lk_lut_index(int resolution, const double m[3], double d_over_r,
                                          int ijk[3])
{
    size_t node, T = (size_t)resolution;
    if (!m || !ijk || resolution < HFVIS_LK_LUT_MIN_RESOLUTION ||
        resolution > HFVIS_LK_LUT_MAX_RESOLUTION || !hfvis__all_finite(m, 3) || !isfinite(d_over_r) ||
        (m[0] == 0.0 && m[1] == 0.0 && m[2] == 0.0))
        return HFVIS_ERR_INVALID_ARGUMENT;
    node = lk_lut_node(resolution, m, d_over_r);
    ijk[0] = (int)(node % T);
    ijk[1] = (int)(node / T % T);
    ijk[2] = (int)(node / T / T);
    return HFVIS_OK;
}

static const uint32_t *lk_lut_get(const hfvis_lk_lut *L, int dirs, const double m[3], double dr)
{
    const uint32_t *tab = dirs && L->directions ? L->directions : L->masks;
    return tab + lk_lut_node(L->resolution, m, dr) * (size_t)L->words;
}

static int lk_lut_valid(const hfvis_lk_lut *L)
{
    return L && L->masks && L->resolution >= HFVIS_LK_LUT_MIN_RESOLUTION &&
           L->resolution <= HFVIS_LK_LUT_MAX_RESOLUTION && L->words == hfvis_lk_mask_words(L->count);
}

HFVIS_API const uint32_t *hfvis_lk_lut_fetch(const hfvis_lk_lut *lut, int directions,
                                             const double m[3], double d_over_r)
{
    if (!lk_lut_valid(lut) || !m || !hfvis__all_finite(m, 3) || !isfinite(d_over_r) ||
        (m[0] == 0.0 && m[1] == 0.0 && m[2] == 0.0))
        return NULL;
    return lk_lut_get(lut, directions, m, d_over_r);
}

/* LUT triangle mask ([LK] §3.1, §4.3): lut(e1,0) & lut(e2,0) & lut(e3,0) & lut(m, d/r_max)
 * [& ~lut(m, d/r_min)]. A zero edge vector (a vertex direction through the origin twice)
 * constrains nothing. */
static void lk_mask_lut(const hfvis_lk_lut *L, const lk_tri *t, uint32_t *out)
{
    const uint32_t *pl;
    int w, k;
    if (t->dr == HFVIS__INF || t->dr > 1.0) {
        memset(out, 0, sizeof(uint32_t) * (size_t)L->words);
        return;
    }
    pl = lk_lut_get(L, 0, t->m, t->dr);
    for (w = 0; w < L->words; w++) out[w] = pl[w];
    for (k = 0; k < 3; k++) {
        const double *e = t->e + 3 * k;
        if (e[0] == 0.0 && e[1] == 0.0 && e[2] == 0.0) continue;
        pl = lk_lut_get(L, 0, e, 0.0);
        for (w = 0; w < L->words; w++) out[w] &= pl[w];
    }
    if (t->drmin <= 1.0) {
        pl = lk_lut_get(L, 0, t->m, t->drmin);
        for (w = 0; w < L->words; w++) out[w] &= ~pl[w];
    }
}

HFVIS_API hfvis_status hfvis_lk_plane_mask(const hfvis_lk_rays *rays, const double m[3],
                                           double d_over_r, uint32_t *mask)
{
    int i;
    if (!lk_rays_valid(rays) || !m || !mask || !hfvis__all_finite(m, 3) || !isfinite(d_over_r))
        return HFVIS_ERR_INVALID_ARGUMENT;
    memset(mask, 0, sizeof(uint32_t) * (size_t)rays->words);
    for (i = 0; i < rays->count; i++)
        if (lk_dot(m, rays->point + 3 * i) >= d_over_r) mask[i >> 5] |= 1u << (i & 31);
    return HFVIS_OK;
}

static int lk_frame_valid(const double F[9])
{
    int k;
    for (k = 0; k < 9; k++)
        if (!isfinite(F[k])) return 0;
    return 1;
}

HFVIS_API hfvis_status hfvis_lk_triangle_mask(const hfvis_lk_rays *rays, const hfvis_lk_lut *lut,
                                              const double position[3], const double frame[9],
                                              const float v0[3], const float v1[3],
                                              const float v2[3], int two_sided, double r_min,
                                              double r_max, double epsilon, uint32_t *mask,
                                              hfvis_lk_verdict *verdict)
{
    lk_tri t;
    int a;
    if (!lk_rays_valid(rays) || !position || !frame || !v0 || !v1 || !v2 || !mask ||
        !hfvis__all_finite(position, 3) || !lk_frame_valid(frame) || !(r_min >= 0.0) || !(r_max >= r_min) ||
        !(r_max <= rays->radius) || !isfinite(epsilon) || !(epsilon > 0.0))
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (a = 0; a < 3; a++)
        if (!isfinite(v0[a]) || !isfinite(v1[a]) || !isfinite(v2[a])) return HFVIS_ERR_INVALID_ARGUMENT;
    if (lut && (!lk_lut_valid(lut) || lut->count != rays->count)) return HFVIS_ERR_INVALID_ARGUMENT;
    lk_tri_setup(&t, frame, position, v0, v1, v2, two_sided != 0, r_min, r_max,
                 epsilon);
    if (lut) lk_mask_lut(lut, &t, mask);
    else lk_mask_exact(rays, &t, NULL, mask);
    if (verdict) *verdict = t.verdict;
    return HFVIS_OK;
}

/* ---- 12.5 per-triangle bounds: minimal bounding sphere (A.5), hexagonal prism (A.6) -------- */

/* The minimal bounding sphere of a triangle ([LK] §4.2; docs/errata.md E46): the midpoint of the longest
 * edge when the triangle is right or obtuse, else the circumcentre; R = the largest distance
 * to a vertex, times (1 + 1e-12) (so every vertex is inside despite rounding). */
static void lk_tri_sphere(const float *v0, const float *v1, const float *v2, double c[3],
                          double *R)
{
    double A[3], B[3], C[3], ab2 = 0.0, bc2 = 0.0, ca2 = 0.0, r2 = 0.0;
    int k;
    for (k = 0; k < 3; k++) {
        A[k] = (double)v0[k];
        B[k] = (double)v1[k];
        C[k] = (double)v2[k];
        ab2 += (B[k] - A[k]) * (B[k] - A[k]);
        bc2 += (C[k] - B[k]) * (C[k] - B[k]);
        ca2 += (A[k] - C[k]) * (A[k] - C[k]);
    }
    if (ab2 >= bc2 + ca2) {
        for (k = 0; k < 3; k++) c[k] = 0.5 * (A[k] + B[k]);
    } else if (bc2 >= ca2 + ab2) {
        for (k = 0; k < 3; k++) c[k] = 0.5 * (B[k] + C[k]);
    } else if (ca2 >= ab2 + bc2) {
        for (k = 0; k < 3; k++) c[k] = 0.5 * (C[k] + A[k]);
    } else { /* acute: circumcentre C + ((|a|^2 b - |b|^2 a) x (a x b)) / (2 |a x b|^2) */
        double a[3], b[3], axb[3], q[3], t[3], den;
        for (k = 0; k < 3; k++) {
            a[k] = A[k] - C[k];
            b[k] = B[k] - C[k];
        }
        lk_cross(a, b, axb);
        den = 2.0 * lk_dot(axb, axb);
        for (k = 0; k < 3; k++) q[k] = lk_dot(a, a) * b[k] - lk_dot(b, b) * a[k];
        lk_cross(q, axb, t);
        for (k = 0; k < 3; k++) c[k] = C[k] + t[k] / den;
        if (!hfvis__all_finite(c, 3) || !(den > 0.0)) /* (nearly) degenerate: centroid */
            for (k = 0; k < 3; k++) c[k] = (A[k] + B[k] + C[k]) / 3.0;
    }
    for (k = 0; k < 3; k++) {
        const double *v = k == 0 ? A : k == 1 ? B : C;
        double d2 = (v[0] - c[0]) * (v[0] - c[0]) + (v[1] - c[1]) * (v[1] - c[1]) +
                    (v[2] - c[2]) * (v[2] - c[2]);
        if (d2 > r2) r2 = d2;
    }
    *R = sqrt(r2) * (1.0 + 1e-12);
}

/* Absolute margin of the volumes and sphere tests of a triangle: 1e-9 of (r_max + R_T) plus
 * 1e-12 of the coordinates' magnitude (covers the rounding of plane offsets). */
static double lk_margin(double r_max, double R, const float *v0, const float *v1, const float *v2)
{
    double mag = 0.0;
    int k;
    for (k = 0; k < 3; k++) {
        if (fabs((double)v0[k]) > mag) mag = fabs((double)v0[k]);
        if (fabs((double)v1[k]) > mag) mag = fabs((double)v1[k]);
        if (fabs((double)v2[k]) > mag) mag = fabs((double)v2[k]);
    }
    return LK_MARGIN * (r_max + R) + 1e-12 * mag;
}

/* The hexagonal prism of [LK] §4.1, Fig. 2-3 in half-space form, pl[j] = (n, c) meaning n.x <= c:
 * o_k.(x - v_k) <= r (the offset edge lines A, B, C of [LK] Fig. 2), u_k.(x - v_k) <= r (the
 * corner cuts P, Q, R, u_k = the bisector of o_{k-1} and o_k), n.(x - v0) <= r and
 * -n.(x - v0) <= low; and its vertices (nv <= 12): the base polygon - the enlarged triangle
 * with corners v_k + r (o_{k-1} + o_k)/(1 + o_{k-1}.o_k) clipped by the three cuts
 * (Sutherland-Hodgman in the plane: the hexagon, or fewer vertices where cuts meet) - lifted by
 * +r and -low along n. Returns 0 when ill-conditioned (a near-180-degree corner, non-finite
 * values); the sphere billboard is used then. */
typedef struct lk_prism {
    double pl[8][4];
    double vtx[16][3];
    int nv;
} lk_prism;

static int lk_prism_build(const float *f0, const float *f1, const float *f2, double r, double low,
                          lk_prism *P)
{
    double V[3][3], u[3], w[3], n[3], o[3][3], ub[3][3], len, poly[2][8][3];
    int k, a, np = 3, cur = 0;
    for (a = 0; a < 3; a++) {
        V[0][a] = (double)f0[a];
        V[1][a] = (double)f1[a];
        V[2][a] = (double)f2[a];
        u[a] = V[1][a] - V[0][a];
        w[a] = V[2][a] - V[0][a];
    }
    lk_cross(u, w, n);
    len = sqrt(lk_dot(n, n));
    if (!(len > 0.0) || !isfinite(len)) return 0;
    for (a = 0; a < 3; a++) n[a] /= len;
    for (k = 0; k < 3; k++) { /* outward edge normals (v_{k+1} - v_k) x n */
        double e[3];
        for (a = 0; a < 3; a++) e[a] = V[(k + 1) % 3][a] - V[k][a];
        lk_cross(e, n, o[k]);
        len = sqrt(lk_dot(o[k], o[k]));
        if (!(len > 0.0) || !isfinite(len)) return 0;
        for (a = 0; a < 3; a++) o[k][a] /= len;
    }
    for (k = 0; k < 3; k++) {
        const double *op = o[(k + 2) % 3];
        double den = 1.0 + lk_dot(op, o[k]);
        for (a = 0; a < 3; a++) ub[k][a] = op[a] + o[k][a];
        len = sqrt(lk_dot(ub[k], ub[k]));
        if (!(len > 1e-6) || !(den > 1e-12)) return 0; /* a near-180-degree corner */
        for (a = 0; a < 3; a++) {
            ub[k][a] /= len;
            poly[0][k][a] = V[k][a] + r * (op[a] + o[k][a]) / den; /* enlarged corner */
        }
    }
    for (k = 0; k < 3; k++) {
        for (a = 0; a < 3; a++) P->pl[k][a] = o[k][a];
        P->pl[k][3] = lk_dot(o[k], V[k]) + r;
        for (a = 0; a < 3; a++) P->pl[3 + k][a] = ub[k][a];
        P->pl[3 + k][3] = lk_dot(ub[k], V[k]) + r;
    }
    for (a = 0; a < 3; a++) {
        P->pl[6][a] = n[a];
        P->pl[7][a] = -n[a];
    }
    P->pl[6][3] = lk_dot(n, V[0]) + r;
    P->pl[7][3] = -lk_dot(n, V[0]) + low;
    for (k = 0; k < 3; k++) { /* clip by the corner cut u_k.x <= c_k */
        int i, nn = 0;
        const double *pl = P->pl[3 + k];
        for (i = 0; i < np; i++) {
            const double *p0 = poly[cur][i], *p1 = poly[cur][(i + 1) % np];
            double f0v = lk_dot(pl, p0) - pl[3], f1v = lk_dot(pl, p1) - pl[3];
            if (f0v <= 0.0) {
                for (a = 0; a < 3; a++) poly[1 - cur][nn][a] = p0[a];
                nn++;
            }
            if ((f0v < 0.0 && f1v > 0.0) || (f0v > 0.0 && f1v < 0.0)) {
                double t = f0v / (f0v - f1v);
                for (a = 0; a < 3; a++) poly[1 - cur][nn][a] = p0[a] + t * (p1[a] - p0[a]);
                nn++;
            }
        }
        cur = 1 - cur;
        np = nn;
        if (np < 3 || np > 6) return 0;
    }
    for (k = 0; k < np; k++)
        for (a = 0; a < 3; a++) {
            P->vtx[2 * k][a] = poly[cur][k][a] + r * n[a];
            P->vtx[2 * k + 1][a] = poly[cur][k][a] - low * n[a];
        }
    P->nv = 2 * np;
    for (k = 0; k < P->nv; k++)
        if (!hfvis__all_finite(P->vtx[k], 3)) return 0;
    for (k = 0; k < 8; k++)
        if (!isfinite(P->pl[k][3])) return 0;
    return 1;
}

/* Parameter interval of the line o + tD inside the prism (Cyrus-Beck); 0 if empty. */
static int lk_prism_clip(const lk_prism *P, const double o[3], const double D[3], double *t_in,
                         double *t_out)
{
    double ti = -HFVIS__INF, to = HFVIS__INF;
    int k;
    for (k = 0; k < 8; k++) {
        double num = P->pl[k][3] - lk_dot(P->pl[k], o), den = lk_dot(P->pl[k], D);
        if (den == 0.0) {
            if (num < 0.0) return 0;
        } else if (den > 0.0) {
            double t = num / den;
            if (t < to) to = t;
        } else {
            double t = num / den;
            if (t > ti) ti = t;
        }
    }
    *t_in = ti;
    *t_out = to;
    return ti <= to;
}

/* Interval of o + tD inside the ball (c, R); 0 if the line misses it. */
static int lk_ball_clip(const double c[3], double R, const double o[3], const double D[3],
                        double *t_in, double *t_out)
{
    double oc[3], A, B, C, disc, sq;
    int a;
    for (a = 0; a < 3; a++) oc[a] = o[a] - c[a];
    A = lk_dot(D, D);
    B = lk_dot(D, oc);
    C = lk_dot(oc, oc) - R * R;
    disc = B * B - A * C;
    if (!(A > 0.0) || disc < 0.0) return 0;
    sq = sqrt(disc);
    *t_in = (-B - sq) / A;
    *t_out = (-B + sq) / A;
    return 1;
}

/* ---- 12.6 options ---------------------------------------------------------------------------- */

HFVIS_API hfvis_lk_options hfvis_lk_options_default(void)
{
    hfvis_lk_options o;
    memset(&o, 0, sizeof o);
    o.mask_mode = HFVIS_LK_MASK_EXACT;
    o.node_mask = HFVIS_LK_NODE_EXACT;
    o.cull = HFVIS_LK_CULL_ALL;
    o.sides = HFVIS_LK_SIDES_ONE;
    o.jitter = HFVIS_LK_JITTER_DEFAULT;
    o.volume = HFVIS_LK_VOLUME_AUTO;
    o.alpha = HFVIS_LK_DEFAULT_ALPHA;
    o.gbuffer_cull = HFVIS_CULL_NONE;
    o.raycast_test = HFVIS_LK_RAYCAST_EXACT;
    return o;
}

HFVIS_API hfvis_status hfvis_lk_options_resolve(const hfvis_lk_options *in, double radius,
                                                hfvis_lk_options *out)
{
    hfvis_lk_options o = hfvis_lk_options_default();
    if (!out || !isfinite(radius) || !(radius > 0.0)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (in) {
        o = *in;
        if (o.mask_mode == HFVIS_LK_MASK_DEFAULT) o.mask_mode = HFVIS_LK_MASK_EXACT;
        if (o.node_mask == HFVIS_LK_NODE_DEFAULT) o.node_mask = HFVIS_LK_NODE_EXACT;
        if (o.cull == 0) o.cull = HFVIS_LK_CULL_ALL;
        if (o.sides == HFVIS_LK_SIDES_DEFAULT) o.sides = HFVIS_LK_SIDES_ONE;
        if (o.volume == HFVIS_LK_VOLUME_DEFAULT) o.volume = HFVIS_LK_VOLUME_AUTO;
        if (o.alpha == 0.0) o.alpha = HFVIS_LK_DEFAULT_ALPHA;
        if (o.raycast_test == HFVIS_LK_RAYCAST_DEFAULT) o.raycast_test = HFVIS_LK_RAYCAST_EXACT;
    }
    if (o.epsilon == 0.0) o.epsilon = HFVIS_LK_DEFAULT_EPSILON * radius;
    if (o.mask_mode != HFVIS_LK_MASK_EXACT && o.mask_mode != HFVIS_LK_MASK_LUT)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.node_mask < HFVIS_LK_NODE_EXACT || o.node_mask > HFVIS_LK_NODE_NONE)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (!(o.cull & HFVIS_LK_CULL_SET) || (o.cull & ~(HFVIS_LK_CULL_SET | 0x3Fu)))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.sides < HFVIS_LK_SIDES_ONE || o.sides > HFVIS_LK_SIDES_PER_TRIANGLE ||
        (o.sides == HFVIS_LK_SIDES_PER_TRIANGLE && !o.two_sided))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (!isfinite(o.epsilon) || !(o.epsilon > 0.0) || !isfinite(o.alpha) || !(o.alpha > 0.0))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (!lk_jitter_valid(o.jitter, o.rotation_max_rad, o.tilt_max_rad))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.jitter == HFVIS_LK_JITTER_DEFAULT) {
        o.rotation_max_rad = HFVIS__PI;
        o.tilt_max_rad = HFVIS_LK_DEFAULT_TILT;
    } else if (o.jitter == HFVIS_LK_JITTER_NONE) {
        o.rotation_max_rad = 0.0;
        o.tilt_max_rad = 0.0;
    }
    if (o.volume < HFVIS_LK_VOLUME_AUTO || o.volume > HFVIS_LK_VOLUME_SPHERE)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.gbuffer_cull != HFVIS_CULL_NONE && o.gbuffer_cull != HFVIS_CULL_BACK &&
        o.gbuffer_cull != HFVIS_CULL_FRONT)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.raycast_test != HFVIS_LK_RAYCAST_EXACT && o.raycast_test != HFVIS_LK_RAYCAST_WATERTIGHT)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if ((o.mask_mode == HFVIS_LK_MASK_LUT || o.node_mask == HFVIS_LK_NODE_SPHERE_LUT) &&
        !lk_lut_valid(o.lut))
        return HFVIS_ERR_INVALID_ARGUMENT;
    *out = o;
    return HFVIS_OK;
}

/* Everything a method needs, resolved once per call. */
typedef struct lk_ctx {
    const hfvis_lk_rays *R;
    const hfvis_mesh *mesh;
    hfvis_lk_options o;
    lk_jit jit;
    unsigned cull;
    int words;
    double r;
    const hfvis_lk_lut *lut;   /* LUT triangle masks, or NULL (exact) */
} lk_ctx;

/* Resolve options and check the parts shared by all methods (rays, mesh, windows, LUT). */
static hfvis_status lk_ctx_init(lk_ctx *c, const hfvis_mesh *mesh, const hfvis_lk_rays *R,
                                const hfvis_lk_options *opts)
{
    hfvis_status s;
    size_t t;
    if (!lk_rays_valid(R)) return HFVIS_ERR_INVALID_ARGUMENT;
    s = hfvis_lk_options_resolve(opts, R->radius, &c->o);
    if (s != HFVIS_OK) return s;
    if (c->o.lut && (c->o.mask_mode == HFVIS_LK_MASK_LUT || c->o.node_mask == HFVIS_LK_NODE_SPHERE_LUT) &&
        c->o.lut->count != R->count)
        return HFVIS_ERR_INVALID_ARGUMENT;
    s = hfvis__mesh_check(mesh);
    if (s != HFVIS_OK) return s;
    if (c->o.lod_range)
        for (t = 0; t < mesh->triangle_count; t++) {
            double lo = (double)c->o.lod_range[2 * t], hi = (double)c->o.lod_range[2 * t + 1];
            if (!(lo >= 0.0) || !(hi >= lo) || !(hi <= R->radius)) return HFVIS_ERR_INVALID_ARGUMENT;
        }
    c->R = R;
    c->mesh = mesh;
    c->cull = c->o.cull;
    c->words = R->words;
    c->r = R->radius;
    c->lut = c->o.mask_mode == HFVIS_LK_MASK_LUT ? c->o.lut : NULL;
    lk_jit_init(&c->jit, R, c->o.jitter, c->o.rotation_max_rad, c->o.tilt_max_rad, c->o.seed);
    return HFVIS_OK;
}

static int lk_two_sided(const lk_ctx *c, size_t t)
{
    if (c->o.sides == HFVIS_LK_SIDES_TWO) return 1;
    if (c->o.sides == HFVIS_LK_SIDES_PER_TRIANGLE) return c->o.two_sided[t] != 0;
    return 0;
}

static void lk_window(const lk_ctx *c, size_t t, double *r_min, double *r_max)
{
    if (c->o.lod_range) {
        *r_min = (double)c->o.lod_range[2 * t];
        *r_max = (double)c->o.lod_range[2 * t + 1];
    } else {
        *r_min = 0.0;
        *r_max = c->r;
    }
}

/* The triangle mask after the setup (exact or LUT); skip as lk_mask_exact. */
static void lk_ctx_mask(const lk_ctx *c, const lk_tri *t, const uint32_t *skip, uint32_t *out)
{
    if (c->lut) lk_mask_lut(c->lut, t, out);
    else lk_mask_exact(c->R, t, skip, out);
}

/* Receivers' validity: finite positions, finite non-zero normals. */
static int lk_receivers_valid(const hfvis_lk_receivers *rc)
{
    size_t i;
    if (!rc || (rc->count && (!rc->position || !rc->normal))) return 0;
    if (rc->count > SIZE_MAX / 3) return 0;
    for (i = 0; i < rc->count; i++) {
        const double *p = rc->position + 3 * i, *n = rc->normal + 3 * i;
        double l2 = lk_dot(n, n);
        if (!hfvis__all_finite(p, 3) || !hfvis__all_finite(n, 3) || !(l2 > 0.0) || !isfinite(l2)) return 0;
    }
    return 1;
}

/* ---- 12.7 G-buffer receivers and Method 1 (rasterization) ----------------------------------- */

/* The camera quantities Method 1 needs (hfvis_view conventions: column-major, rigid view). */
typedef struct lk_cam {
    double PV[16];     /* proj * view */
    double eye[3];     /* perspective centre */
    double fwd[3];     /* unit viewing direction (world) */
    double drow[4];    /* linear depth -z_eye = drow . (x, 1) */
    int ortho, W, H;
} lk_cam;

static hfvis_status lk_cam_init(lk_cam *c, const hfvis_view *v)
{
    const double *m = v->view;
    double len;
    int k, j;
    if (v->width < 1 || v->height < 1) return HFVIS_ERR_INVALID_ARGUMENT;
    for (k = 0; k < 16; k++)
        if (!isfinite(v->view[k]) || !isfinite(v->proj[k])) return HFVIS_ERR_INVALID_ARGUMENT;
    hfvis_mat4_multiply(v->proj, v->view, c->PV);
    for (k = 0; k < 3; k++) c->fwd[k] = -m[k * 4 + 2];
    len = sqrt(lk_dot(c->fwd, c->fwd));
    if (!(len > 0.0)) return HFVIS_ERR_INVALID_ARGUMENT;
    for (k = 0; k < 3; k++) c->fwd[k] /= len;
    for (j = 0; j < 3; j++)
        c->eye[j] = -(m[j * 4 + 0] * m[12] + m[j * 4 + 1] * m[13] + m[j * 4 + 2] * m[14]);
    c->drow[0] = -m[2];
    c->drow[1] = -m[6];
    c->drow[2] = -m[10];
    c->drow[3] = -m[14];
    c->ortho = v->orthographic != 0;
    c->W = v->width;
    c->H = v->height;
    return HFVIS_OK;
}

static double lk_depth(const lk_cam *c, const double x[3])
{
    return c->drow[0] * x[0] + c->drow[1] * x[1] + c->drow[2] * x[2] + c->drow[3];
}

/* Pixel bounding box [x0, x1] x [y0, y1] of the pixel centres covered by the projection of the
 * convex hull of pts (one pixel of margin); the whole image when a point is not in front of
 * the eye (w <= 0) or the projection is not finite. */
static void lk_screen_box(const lk_cam *c, const double (*pts)[3], int n, int box[4])
{
    double mnx = HFVIS__INF, mny = HFVIS__INF, mxx = -HFVIS__INF, mxy = -HFVIS__INF, f;
    int k;
    for (k = 0; k < n; k++) {
        const double *p = pts[k];
        double cx = c->PV[0] * p[0] + c->PV[4] * p[1] + c->PV[8] * p[2] + c->PV[12];
        double cy = c->PV[1] * p[0] + c->PV[5] * p[1] + c->PV[9] * p[2] + c->PV[13];
        double cw = c->PV[3] * p[0] + c->PV[7] * p[1] + c->PV[11] * p[2] + c->PV[15];
        double px, py;
        if (!(cw > 0.0)) goto full;
        px = (cx / cw + 1.0) * 0.5 * c->W;
        py = (1.0 - cy / cw) * 0.5 * c->H;
        if (!isfinite(px) || !isfinite(py)) goto full;
        if (px < mnx) mnx = px;
        if (px > mxx) mxx = px;
        if (py < mny) mny = py;
        if (py > mxy) mxy = py;
    }
    f = ceil(mnx - 0.5) - 1.0;
    box[0] = f < 0.0 ? 0 : f > (double)(c->W - 1) ? c->W : (int)f;
    f = floor(mxx - 0.5) + 1.0;
    box[1] = f < 0.0 ? -1 : f > (double)(c->W - 1) ? c->W - 1 : (int)f;
    f = ceil(mny - 0.5) - 1.0;
    box[2] = f < 0.0 ? 0 : f > (double)(c->H - 1) ? c->H : (int)f;
    f = floor(mxy - 0.5) + 1.0;
    box[3] = f < 0.0 ? -1 : f > (double)(c->H - 1) ? c->H - 1 : (int)f;
    return;
full:
    box[0] = 0;
    box[1] = c->W - 1;
    box[2] = 0;
    box[3] = c->H - 1;
}

/* Rasterize triangle ids and barycentrics into one block (ids first). */
static hfvis_status lk_gbuffer_run(const hfvis_mesh *mesh, const hfvis_view *view,
                                   hfvis_cull_mode cull, const hfvis_allocator *alloc,
                                   uint32_t **ids, float **bary)
{
    size_t n, bytes = 0;
    unsigned char *block, *cur;
    hfvis_raster_options ro;
    hfvis_raster_outputs out;
    hfvis_status s;
    if (view->width < 1 || view->height < 1) return HFVIS_ERR_INVALID_ARGUMENT;
    if (view->width > HFVIS_RASTER_MAX_SIZE || view->height > HFVIS_RASTER_MAX_SIZE)
        return HFVIS_ERR_LIMIT;
    n = (size_t)view->width * (size_t)view->height;
    if (!lk_part(&bytes, n, sizeof(uint32_t)) || !lk_part(&bytes, n, 2 * sizeof(float)))
        return HFVIS_ERR_LIMIT; /* only on 32-bit size_t */
    block = (unsigned char *)hfvis__alloc(alloc, bytes);
    if (!block) return HFVIS_ERR_OUT_OF_MEMORY;
    cur = block;
    memset(&ro, 0, sizeof ro);
    ro.alloc = alloc;
    ro.cull = cull;
    memset(&out, 0, sizeof out);
    out.triangle_id = (uint32_t *)lk_take(&cur, n, sizeof(uint32_t));
    out.barycentric = (float *)lk_take(&cur, n, 2 * sizeof(float));
    s = hfvis_rasterize(mesh, view, &ro, &out);
    if (s != HFVIS_OK) {
        hfvis__free(alloc, block);
        return s;
    }
    *ids = out.triangle_id;
    *bary = out.barycentric;
    return HFVIS_OK;
}

/* The receiver of a covered pixel: p = (1 - b1 - b2) v0 + b1 v1 + b2 v2 (double), the face
 * normal turned toward the viewer. */
static void lk_pixel_receiver(const hfvis_mesh *m, const lk_cam *c, uint32_t tri, const float *b,
                              double p[3], double n[3])
{
    const float *v0 = lk_vertex(m, tri, 0), *v1 = lk_vertex(m, tri, 1), *v2 = lk_vertex(m, tri, 2);
    double b1 = (double)b[0], b2 = (double)b[1], b0 = 1.0 - b1 - b2, u[3], w[3], s;
    int a;
    for (a = 0; a < 3; a++) {
        p[a] = b0 * (double)v0[a] + b1 * (double)v1[a] + b2 * (double)v2[a];
        u[a] = (double)v1[a] - (double)v0[a];
        w[a] = (double)v2[a] - (double)v0[a];
    }
    lk_cross(u, w, n);
    if (c->ortho) s = -lk_dot(n, c->fwd);
    else s = n[0] * (c->eye[0] - p[0]) + n[1] * (c->eye[1] - p[1]) + n[2] * (c->eye[2] - p[2]);
    if (s < 0.0)
        for (a = 0; a < 3; a++) n[a] = -n[a];
}

HFVIS_API hfvis_status hfvis_lk_gbuffer_receivers(const hfvis_mesh *mesh, const hfvis_view *view,
                                                  const hfvis_lk_options *opts, double *position,
                                                  double *normal, uint64_t *key, size_t *count)
{
    hfvis_lk_options o;
    lk_cam cam;
    uint32_t *ids;
    float *bary;
    size_t i, n, k = 0;
    hfvis_status s;
    if (!mesh || !view || !position || !normal || !count) return HFVIS_ERR_INVALID_ARGUMENT;
    s = hfvis_lk_options_resolve(opts, 1.0, &o);
    if (s != HFVIS_OK) return s;
    s = lk_cam_init(&cam, view);
    if (s != HFVIS_OK) return s;
    s = lk_gbuffer_run(mesh, view, o.gbuffer_cull, o.alloc, &ids, &bary);
    if (s != HFVIS_OK) return s;
    n = (size_t)view->width * (size_t)view->height;
    for (i = 0; i < n; i++) {
        if (ids[i] == HFVIS_NO_TRIANGLE) continue;
        lk_pixel_receiver(mesh, &cam, ids[i], bary + 2 * i, position + 3 * k, normal + 3 * k);
        if (key) key[k] = (uint64_t)i;
        k++;
    }
    *count = k;
    hfvis__free(o.alloc, ids);
    return HFVIS_OK;
}

/* Method 1 receiver record: p (3), frame (9), linear depth (1). */
#define LK_REC 13

HFVIS_API hfvis_status hfvis_lk_raster(const hfvis_mesh *mesh, const hfvis_view *view,
                                       const hfvis_lk_rays *rays, const hfvis_lk_options *opts,
                                       uint32_t *masks, float *obscurance, hfvis_lk_stats *stats)
{
    lk_ctx ctx;
    lk_cam cam;
    hfvis_lk_stats st;
    hfvis_status s;
    uint32_t *ids = NULL, *acc, *tmask;
    float *bary = NULL;
    int32_t *recidx;
    double *rec;
    unsigned char *block, *cur;
    size_t npix, nrec = 0, i, t, bytes = 0, maskwords;
    int words;
    if (!mesh || !view || !rays || (!masks && !obscurance)) return HFVIS_ERR_INVALID_ARGUMENT;
    s = lk_ctx_init(&ctx, mesh, rays, opts);
    if (s != HFVIS_OK) return s;
    s = lk_cam_init(&cam, view);
    if (s != HFVIS_OK) return s;
    words = ctx.words;
    if (view->width > HFVIS_RASTER_MAX_SIZE || view->height > HFVIS_RASTER_MAX_SIZE)
        return HFVIS_ERR_LIMIT;
    npix = (size_t)view->width * (size_t)view->height;
    if (!hfvis__mul_size(npix, (size_t)words, &maskwords) || maskwords > SIZE_MAX / sizeof(uint32_t))
        return HFVIS_ERR_LIMIT;
    s = lk_gbuffer_run(mesh, view, ctx.o.gbuffer_cull, ctx.o.alloc, &ids, &bary);
    if (s != HFVIS_OK) return s;
    for (i = 0; i < npix; i++) nrec += ids[i] != HFVIS_NO_TRIANGLE;
    if (!lk_part(&bytes, npix, sizeof(int32_t)) || !lk_part(&bytes, nrec, LK_REC * sizeof(double)) ||
        !lk_part(&bytes, (size_t)words, sizeof(uint32_t)) ||
        (!masks && !lk_part(&bytes, nrec, (size_t)words * sizeof(uint32_t)))) {
        hfvis__free(ctx.o.alloc, ids);
        return HFVIS_ERR_LIMIT; /* only on 32-bit size_t */
    }
    block = (unsigned char *)hfvis__alloc(ctx.o.alloc, bytes);
    if (!block) {
        hfvis__free(ctx.o.alloc, ids);
        return HFVIS_ERR_OUT_OF_MEMORY;
    }
    cur = block;
    recidx = (int32_t *)lk_take(&cur, npix, sizeof(int32_t));
    rec = (double *)lk_take(&cur, nrec, LK_REC * sizeof(double));
    tmask = (uint32_t *)lk_take(&cur, (size_t)words, sizeof(uint32_t));
    acc = masks ? masks : (uint32_t *)lk_take(&cur, nrec, (size_t)words * sizeof(uint32_t));
    /* receivers (Method 1 step 1) and frames */
    nrec = 0;
    for (i = 0; i < npix; i++) {
        double n[3], *r;
        if (ids[i] == HFVIS_NO_TRIANGLE) {
            recidx[i] = -1;
            continue;
        }
        r = rec + LK_REC * nrec;
        lk_pixel_receiver(mesh, &cam, ids[i], bary + 2 * i, r, n);
        lk_frame_make(&ctx.jit, n, (uint64_t)i, r + 3);
        r[12] = lk_depth(&cam, r);
        recidx[i] = (int32_t)nrec++;
    }
    hfvis__free(ctx.o.alloc, ids);
    /* occlusion buffers cleared (step 2); masks[pixel] or acc[receiver] */
    memset(acc, 0, sizeof(uint32_t) * (masks ? maskwords : nrec * (size_t)words));
    memset(&st, 0, sizeof st);
    for (t = 0; t < mesh->triangle_count; t++) { /* step 3, per triangle */
        const float *f0 = lk_vertex(mesh, t, 0), *f1 = lk_vertex(mesh, t, 1), *f2 = lk_vertex(mesh, t, 2);
        double rmin, rmax, c[3], R, mabs, rr, low, Rs, nw[3], dmin, dc, vd;
        int two = lk_two_sided(&ctx, t), prism, box[4], x, y, k;
        lk_prism P;
        lk_window(&ctx, t, &rmin, &rmax);
        if (lk_world_degenerate(f0, f1, f2) || !(rmax > 0.0)) continue; /* never blocks */
        lk_tri_sphere(f0, f1, f2, c, &R);
        mabs = lk_margin(rmax, R, f0, f1, f2);
        rr = rmax + mabs;
        low = two ? rr : ctx.o.epsilon + mabs;
        Rs = R + rr;
        prism = ctx.o.volume == HFVIS_LK_VOLUME_PRISM ||
                (ctx.o.volume == HFVIS_LK_VOLUME_AUTO && R / rmax > ctx.o.alpha);
        if (prism && !lk_prism_build(f0, f1, f2, rr, low, &P)) prism = 0;
        {
            double u[3], w[3], len;
            for (k = 0; k < 3; k++) {
                u[k] = (double)f1[k] - (double)f0[k];
                w[k] = (double)f2[k] - (double)f0[k];
            }
            lk_cross(u, w, nw);
            len = sqrt(lk_dot(nw, nw));
            for (k = 0; k < 3; k++) nw[k] /= len;
        }
        if (prism) {
            st.prisms++;
            lk_screen_box(&cam, (const double(*)[3])P.vtx, P.nv, box);
        } else {
            double corners[8][3];
            st.spheres++;
            for (k = 0; k < 8; k++) {
                corners[k][0] = c[0] + ((k & 1) ? Rs : -Rs);
                corners[k][1] = c[1] + ((k & 2) ? Rs : -Rs);
                corners[k][2] = c[2] + ((k & 4) ? Rs : -Rs);
            }
            lk_screen_box(&cam, (const double(*)[3])corners, 8, box);
        }
        {
            double v[3];
            for (k = 0; k < 3; k++) v[k] = (double)f0[k];
            dmin = lk_depth(&cam, v);
            for (k = 0; k < 3; k++) v[k] = (double)f1[k];
            vd = lk_depth(&cam, v);
            if (vd < dmin) dmin = vd;
            for (k = 0; k < 3; k++) v[k] = (double)f2[k];
            vd = lk_depth(&cam, v);
            if (vd < dmin) dmin = vd;
        }
        dc = lk_depth(&cam, c);
        for (y = box[2]; y <= box[3]; y++)
            for (x = box[0]; x <= box[1]; x++) {
                int32_t ri = recidx[(size_t)y * (size_t)view->width + (size_t)x];
                const double *r, *p, *F;
                double o[3], D[3], ti, to, fdepth, dp, dx, dy, dz;
                lk_tri tri;
                uint32_t *dst;
                if (ri < 0) continue;
                r = rec + LK_REC * (size_t)ri;
                p = r;
                F = r + 3;
                dp = r[12];
                for (k = 0; k < 3; k++) {
                    if (cam.ortho) {
                        o[k] = p[k] - cam.fwd[k];
                        D[k] = cam.fwd[k];
                    } else {
                        o[k] = cam.eye[k];
                        D[k] = p[k] - cam.eye[k];
                    }
                }
                /* the fragment: the eye line meets the volume, p not behind its far side */
                if (prism) {
                    if (!lk_prism_clip(&P, o, D, &ti, &to) || to < 1.0) continue;
                    fdepth = cam.ortho ? dp + (to - 1.0) : dp * to;
                } else {
                    fdepth = dc + Rs; /* the billboard sits just behind the sphere */
                    if (dp > fdepth || !lk_ball_clip(c, Rs, o, D, &ti, &to)) continue;
                    if (!two) { /* front half: -nw.(x - v0) <= low */
                        double a0 = -(nw[0] * (o[0] - (double)f0[0]) + nw[1] * (o[1] - (double)f0[1]) +
                                      nw[2] * (o[2] - (double)f0[2])) - low;
                        double b0 = -lk_dot(nw, D);
                        if (b0 == 0.0) {
                            if (a0 > 0.0) continue;
                        } else if (b0 > 0.0) {
                            if (-a0 / b0 < to) to = -a0 / b0;
                        } else if (-a0 / b0 > ti) {
                            ti = -a0 / b0;
                        }
                        if (ti > to) continue;
                    }
                }
                st.fragments++;
                /* culling tests in the order of [LK] §4.2 */
                if ((ctx.cull & HFVIS_LK_CULL_PAPER_FAR_DEPTH) && fdepth > dp + rmax) {
                    st.culled_far_depth++;
                    continue;
                }
                if ((ctx.cull & HFVIS_LK_CULL_FAR_DEPTH) && dmin > dp + rr) {
                    st.culled_far_depth++;
                    continue;
                }
                dx = p[0] - c[0];
                dy = p[1] - c[1];
                dz = p[2] - c[2];
                if ((ctx.cull & HFVIS_LK_CULL_SPHERE) && dx * dx + dy * dy + dz * dz > Rs * Rs) {
                    st.culled_sphere++;
                    continue;
                }
                lk_tri_setup(&tri, F, p, f0, f1, f2, two, rmin, rmax, ctx.o.epsilon);
                if (tri.verdict == HFVIS_LK_TRI_DEGENERATE || tri.verdict == HFVIS_LK_TRI_SELF) {
                    st.skipped++;
                    continue;
                }
                if ((ctx.cull & HFVIS_LK_CULL_FACING) && tri.verdict == HFVIS_LK_TRI_FACING_AWAY) {
                    st.culled_facing++;
                    continue;
                }
                if ((ctx.cull & HFVIS_LK_CULL_PLANE) && tri.verdict == HFVIS_LK_TRI_TOO_FAR) {
                    st.culled_plane++;
                    continue;
                }
                if ((ctx.cull & HFVIS_LK_CULL_HORIZON) && tri.zmax <= 0.0) {
                    st.culled_horizon++;
                    continue;
                }
                dst = acc + (masks ? (size_t)y * (size_t)view->width + (size_t)x : (size_t)ri) * (size_t)words;
                lk_ctx_mask(&ctx, &tri, dst, tmask);
                st.masks++;
                for (k = 0; k < words; k++) dst[k] |= tmask[k];
            }
    }
    /* step 4: W = popcount/N */
    for (i = 0; i < npix; i++) {
        int32_t ri = recidx[i];
        const uint32_t *mk;
        int bits = 0, k;
        if (ri < 0) {
            if (obscurance) obscurance[i] = (float)NAN;
            continue;
        }
        mk = acc + (masks ? i : (size_t)ri) * (size_t)words;
        for (k = 0; k < words; k++) bits += lk_popcount(mk[k]);
        st.rays_blocked += (uint64_t)bits;
        if (obscurance) obscurance[i] = (float)((double)bits / (double)rays->count);
    }
    st.receivers = nrec;
    st.rays = (uint64_t)nrec * (uint64_t)rays->count;
    if (stats) *stats = st;
    hfvis__free(ctx.o.alloc, block);
    return HFVIS_OK;
}

/* ---- 12.8 Method 2: BVH traversal ([LK] §5) ------------------------------------- */

/* Per-triangle data of Methods 2 and the ray caster: minimal bounding sphere (c, R), R < 0 for
 * a zero-area triangle. 4 doubles per triangle. */
static void lk_tri_table(const hfvis_mesh *m, double *td)
{
    size_t t;
    for (t = 0; t < m->triangle_count; t++) {
        const float *f0 = lk_vertex(m, t, 0), *f1 = lk_vertex(m, t, 1), *f2 = lk_vertex(m, t, 2);
        double *d = td + 4 * t;
        if (lk_world_degenerate(f0, f1, f2)) {
            d[0] = d[1] = d[2] = 0.0;
            d[3] = -1.0;
        } else {
            lk_tri_sphere(f0, f1, f2, d, d + 3);
        }
    }
}

/* The BVH must belong to the mesh and be well formed: children after their parent and inside
 * the node array, leaf ranges inside tri_order, triangle indices in range, finite ordered
 * boxes, depth <= HFVIS_BVH_MAX_DEPTH (so the fixed traversal stacks suffice). depth: scratch
 * of node_count bytes. */
static hfvis_status lk_bvh_check(const hfvis_bvh *b, const hfvis_mesh *m, uint8_t *depth)
{
    size_t i, j;
    if (b->triangle_count != m->triangle_count) return HFVIS_ERR_INVALID_ARGUMENT;
    if (b->node_count == 0) return m->triangle_count == 0 ? HFVIS_OK : HFVIS_ERR_INVALID_ARGUMENT;
    if (!b->nodes || !b->tri_order || b->node_count > SIZE_MAX / 2) return HFVIS_ERR_INVALID_ARGUMENT;
    memset(depth, 0, b->node_count);
    depth[0] = 1;
    for (i = 0; i < b->node_count; i++) {
        const hfvis_bvh_node *nd = b->nodes + i;
        int a;
        if (depth[i] == 0) continue; /* never reached */
        for (a = 0; a < 3; a++)
            if (!isfinite(nd->lo[a]) || !isfinite(nd->hi[a]) || !(nd->lo[a] <= nd->hi[a]))
                return HFVIS_ERR_INVALID_ARGUMENT;
        if (nd->count == 0) {
            size_t l = nd->left_or_first;
            if (l <= i || l + 1 >= b->node_count || depth[i] >= HFVIS_BVH_MAX_DEPTH)
                return HFVIS_ERR_INVALID_ARGUMENT;
            if (depth[l] < depth[i] + 1) depth[l] = (uint8_t)(depth[i] + 1);
            if (depth[l + 1] < depth[i] + 1) depth[l + 1] = (uint8_t)(depth[i] + 1);
        } else {
            size_t f = nd->left_or_first;
            if (nd->count > HFVIS_BVH_MAX_LEAF_SIZE || f > b->triangle_count ||
                nd->count > b->triangle_count - f)
                return HFVIS_ERR_INVALID_ARGUMENT;
            for (j = f; j < f + nd->count; j++)
                if (b->tri_order[j] >= b->triangle_count) return HFVIS_ERR_INVALID_ARGUMENT;
        }
    }
    return HFVIS_OK;
}

/* Shared scratch of Method 2 and the ray caster: triangle table, BVH check, stacks. */
typedef struct lk_trav {
    unsigned char *block;
    double *td;          /* 4 per triangle */
    uint32_t *stack;     /* (HFVIS_BVH_MAX_DEPTH + 2) * (1 + words) */
    uint32_t *C, *tmask; /* words each */
} lk_trav;

#define LK_STACK (HFVIS_BVH_MAX_DEPTH + 2)

static hfvis_status lk_trav_init(lk_trav *tv, const lk_ctx *c, const hfvis_bvh *bvh)
{
    size_t bytes = 0, T = c->mesh->triangle_count;
    unsigned char *cur;
    uint8_t *depth;
    hfvis_status s;
    if (!lk_part(&bytes, T, 4 * sizeof(double)) || !lk_part(&bytes, bvh->node_count, 1) ||
        !lk_part(&bytes, LK_STACK, (1 + (size_t)c->words) * sizeof(uint32_t)) ||
        !lk_part(&bytes, 2 * (size_t)c->words, sizeof(uint32_t)))
        return HFVIS_ERR_LIMIT; /* only on 32-bit size_t */
    tv->block = (unsigned char *)hfvis__alloc(c->o.alloc, bytes);
    if (!tv->block) return HFVIS_ERR_OUT_OF_MEMORY;
    cur = tv->block;
    tv->td = (double *)lk_take(&cur, T, 4 * sizeof(double));
    depth = (uint8_t *)lk_take(&cur, bvh->node_count, 1);
    tv->stack = (uint32_t *)lk_take(&cur, LK_STACK, (1 + (size_t)c->words) * sizeof(uint32_t));
    tv->C = (uint32_t *)lk_take(&cur, 2 * (size_t)c->words, sizeof(uint32_t));
    tv->tmask = tv->C + c->words;
    s = lk_bvh_check(bvh, c->mesh, depth);
    if (s != HFVIS_OK) {
        hfvis__free(c->o.alloc, tv->block);
        return s;
    }
    lk_tri_table(c->mesh, tv->td);
    return HFVIS_OK;
}

/* Common argument checks of Method 2 and the ray caster. */
static hfvis_status lk_explicit_init(lk_ctx *c, const hfvis_mesh *mesh, const hfvis_bvh *bvh,
                                     const hfvis_lk_rays *rays, const hfvis_lk_receivers *recv,
                                     const hfvis_lk_options *opts, const uint32_t *masks,
                                     const float *obscurance)
{
    hfvis_status s;
    size_t words;
    if (!mesh || !bvh || !rays || !recv || (!masks && !obscurance)) return HFVIS_ERR_INVALID_ARGUMENT;
    s = lk_ctx_init(c, mesh, rays, opts);
    if (s != HFVIS_OK) return s;
    if (!lk_receivers_valid(recv)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (!hfvis__mul_size(recv->count, (size_t)rays->words, &words) || words > SIZE_MAX / sizeof(uint32_t))
        return HFVIS_ERR_LIMIT;
    return HFVIS_OK;
}

/* Squared distance from p to a box. */
static double lk_box_dist2(const hfvis_bvh_node *nd, const double p[3])
{
    double d2 = 0.0;
    int a;
    for (a = 0; a < 3; a++) {
        double lo = (double)nd->lo[a], hi = (double)nd->hi[a], d = 0.0;
        if (p[a] < lo) d = lo - p[a];
        else if (p[a] > hi) d = p[a] - hi;
        d2 += d * d;
    }
    return d2;
}

/* Largest local z (F row 3) over the box corners. */
static double lk_box_zmax(const hfvis_bvh_node *nd, const double F[9], const double p[3])
{
    double z = 0.0;
    int a;
    for (a = 0; a < 3; a++) {
        double zl = F[6 + a] * ((double)nd->lo[a] - p[a]), zh = F[6 + a] * ((double)nd->hi[a] - p[a]);
        z += zl > zh ? zl : zh;
    }
    return z;
}

/* Node occlusion mask ([LK] §5, Fig. 4; docs/errata.md E41) of the box's bounding sphere (centre, half-diagonal).
 * EXACT: bit i = the segment [0, s_i] (units of r) meets the sphere of radius R (1 + 1e-9) +
 * 1e-9 r; words are skipped by their cones, and rays already blocked (set in C) are not
 * computed (left 0: only M & ~C is ever used, and C only grows). SPHERE_LUT: [LK] Fig. 4 -
 * equal lengths: the cone P(c, tau/dist) if tau <= r, else the separating plane
 * P(c, (r^2 + dist^2 - R^2)/(2 r dist)); variable lengths: the cone in the direction table.
 * NONE: all ones. */
static void lk_node_mask(const lk_ctx *c, const hfvis_bvh_node *nd, const double F[9],
                         const double p[3], const uint32_t *C, uint32_t *out)
{
    const hfvis_lk_rays *R = c->R;
    double w[3], cl[3], Rn, d2, dist, ch[3], half = 0.0;
    int a, k, i;
    if (c->o.node_mask == HFVIS_LK_NODE_NONE) {
        for (k = 0; k < c->words; k++) out[k] = lk_word_bits(R->count, k);
        return;
    }
    for (a = 0; a < 3; a++) {
        double lo = (double)nd->lo[a], hi = (double)nd->hi[a];
        w[a] = 0.5 * (lo + hi) - p[a];
        half += (hi - lo) * (hi - lo);
    }
    for (a = 0; a < 3; a++) cl[a] = (F[3 * a] * w[0] + F[3 * a + 1] * w[1] + F[3 * a + 2] * w[2]) / c->r;
    Rn = 0.5 * sqrt(half) / c->r;
    Rn = Rn * (1.0 + LK_MARGIN) + LK_MARGIN;
    d2 = lk_dot(cl, cl);
    if (d2 <= Rn * Rn) {
        for (k = 0; k < c->words; k++) out[k] = lk_word_bits(R->count, k);
        return;
    }
    dist = sqrt(d2);
    for (a = 0; a < 3; a++) ch[a] = cl[a] / dist;
    if (c->o.node_mask == HFVIS_LK_NODE_SPHERE_LUT) {
        double tau = sqrt(d2 - Rn * Rn), delta;
        const uint32_t *src;
        if (!R->equal_lengths) src = lk_lut_get(c->o.lut, 1, ch, tau / dist);
        else {
            delta = tau <= 1.0 ? tau / dist : (1.0 + d2 - Rn * Rn) / (2.0 * dist);
            src = lk_lut_get(c->o.lut, 0, ch, delta);
        }
        for (k = 0; k < c->words; k++) out[k] = src[k];
        return;
    }
    {
        double sb = Rn / dist, cb = sqrt(1.0 - sb * sb);
        for (k = 0; k < c->words; k++) {
            const double *cone = R->word_cone + 7 * k;
            int i0 = 32 * k, i1 = i0 + 32 < R->count ? i0 + 32 : R->count;
            double cphi = lk_dot(ch, cone), lim = cone[3] * cb - cone[4] * sb;
            uint32_t bits = 0;
            if ((~C[k] & lk_word_bits(R->count, k)) == 0) { /* every ray already blocked */
                out[k] = 0;
                continue;
            }
            /* zero when the word's cone and the sphere's cone (half-angle beta) do not meet:
             * angle(axis, c) > theta + beta (tested when theta + beta < pi: sin > 0), or
             * the sphere lies beyond the word's longest ray */
            if ((cone[4] * cb + cone[3] * sb > 0.0 && cphi < lim - LK_MARGIN) ||
                dist - Rn > cone[6] + LK_MARGIN) {
                out[k] = 0;
                continue;
            }
            /* all ones when the word's cone lies inside the sphere's (angle(axis, c) + theta <=
             * beta: cos phi >= cos(beta - theta), beta > theta) and its shortest ray reaches
             * dist (every ray inside the cone enters the sphere before distance dist) */
            if (sb * cone[3] - cb * cone[4] > 0.0 && cphi >= cb * cone[3] + sb * cone[4] + LK_MARGIN &&
                cone[5] >= dist + LK_MARGIN) {
                out[k] = lk_word_bits(R->count, k);
                continue;
            }
            for (i = i0; i < i1; i++) {
                /* the segment [0, s] meets the sphere (c, Rn), c outside: with p = c.s, the
                 * closest point is s when p >= s.s, else t s with t = p/s.s (p <= 0: the origin,
                 * outside): |c - s|^2 <= Rn^2, or d2 - p^2/s.s <= Rn^2 (multiplied out) */
                const double *s = R->point + 3 * i;
                double ss = lk_dot(s, s), pp, q[3];
                if ((C[k] >> (i - i0)) & 1u) continue; /* already blocked: bit irrelevant */
                pp = lk_dot(cl, s);
                if (!(pp > 0.0)) continue;
                if (pp >= ss) {
                    for (a = 0; a < 3; a++) q[a] = cl[a] - s[a];
                    if (lk_dot(q, q) <= Rn * Rn) bits |= 1u << (i - i0);
                } else if ((d2 - Rn * Rn) * ss <= pp * pp) {
                    bits |= 1u << (i - i0);
                }
            }
            out[k] = bits;
        }
    }
}

/* Does mask M add a ray to C? (popcount(M & ~C)) */
static int lk_estimate(const uint32_t *M, const uint32_t *C, int words)
{
    int k, e = 0;
    for (k = 0; k < words; k++) e += lk_popcount(M[k] & ~C[k]);
    return e;
}

/* Cull tests of a node; 1 = keep. */
static int lk_node_keep(const lk_ctx *c, const hfvis_bvh_node *nd, const double F[9],
                        const double p[3], hfvis_lk_stats *st)
{
    if (lk_box_dist2(nd, p) > c->r * c->r * (1.0 + 2.0 * LK_MARGIN)) {
        st->nodes_culled_distance++;
        return 0;
    }
    if ((c->cull & HFVIS_LK_CULL_HORIZON) && lk_box_zmax(nd, F, p) <= 0.0) {
        st->nodes_culled_horizon++;
        return 0;
    }
    return 1;
}

/* One receiver of Method 2: C = OR of the masks of the triangles it reaches. */
static void lk_bvh_receiver(const lk_ctx *c, const hfvis_bvh *bvh, const lk_trav *tv,
                            const double p[3], const double F[9], uint32_t *C, hfvis_lk_stats *st)
{
    const int words = c->words;
    const size_t ent = 1 + (size_t)words;
    uint32_t *stk = tv->stack, full_last = lk_word_bits(c->R->count, words - 1);
    int sp = 0, k;
    memset(C, 0, sizeof(uint32_t) * (size_t)words);
    if (bvh->node_count == 0) return;
    if (!lk_node_keep(c, bvh->nodes, F, p, st)) return;
    stk[0] = 0;
    lk_node_mask(c, bvh->nodes, F, p, C, stk + 1);
    sp = 1;
    while (sp > 0) {
        const uint32_t *top = stk + (size_t)(sp - 1) * ent;
        const hfvis_bvh_node *nd = bvh->nodes + top[0];
        sp--;
        if (lk_estimate(top + 1, C, words) == 0) { /* stale estimate re-checked (A.13-14) */
            st->nodes_culled_mask++;
            continue;
        }
        st->nodes_visited++;
        if (nd->count > 0) {
            uint32_t j;
            for (j = nd->left_or_first; j < nd->left_or_first + nd->count; j++) {
                size_t t = bvh->tri_order[j];
                const double *td = tv->td + 4 * t;
                const float *f0, *f1, *f2;
                double rmin, rmax, dx, dy, dz, mabs;
                lk_tri tri;
                int full;
                st->fragments++;
                if (td[3] < 0.0) {
                    st->skipped++;
                    continue;
                }
                f0 = lk_vertex(c->mesh, t, 0);
                f1 = lk_vertex(c->mesh, t, 1);
                f2 = lk_vertex(c->mesh, t, 2);
                lk_window(c, t, &rmin, &rmax);
                lk_tri_setup(&tri, F, p, f0, f1, f2, lk_two_sided(c, t), rmin, rmax, c->o.epsilon);
                if (tri.verdict == HFVIS_LK_TRI_DEGENERATE || tri.verdict == HFVIS_LK_TRI_SELF) {
                    st->skipped++;
                    continue;
                }
                /* culling tests in the BVH order of [LK] §5 */
                if ((c->cull & HFVIS_LK_CULL_HORIZON) && tri.zmax <= 0.0) {
                    st->culled_horizon++;
                    continue;
                }
                if ((c->cull & HFVIS_LK_CULL_FACING) && tri.verdict == HFVIS_LK_TRI_FACING_AWAY) {
                    st->culled_facing++;
                    continue;
                }
                if ((c->cull & HFVIS_LK_CULL_PLANE) && tri.verdict == HFVIS_LK_TRI_TOO_FAR) {
                    st->culled_plane++;
                    continue;
                }
                mabs = lk_margin(rmax, td[3], f0, f1, f2);
                dx = p[0] - td[0];
                dy = p[1] - td[1];
                dz = p[2] - td[2];
                if ((c->cull & HFVIS_LK_CULL_SPHERE) &&
                    dx * dx + dy * dy + dz * dz > (td[3] + rmax + mabs) * (td[3] + rmax + mabs)) {
                    st->culled_sphere++;
                    continue;
                }
                lk_ctx_mask(c, &tri, C, tv->tmask);
                st->masks++;
                full = 1;
                for (k = 0; k < words; k++) {
                    C[k] |= tv->tmask[k];
                    if (C[k] != (k == words - 1 ? full_last : 0xFFFFFFFFu)) full = 0;
                }
                if (full) return; /* every ray blocked */
            }
        } else {
            uint32_t ch[2], *mk[2];
            int e[2], keep[2], q;
            ch[0] = nd->left_or_first;
            ch[1] = nd->left_or_first + 1;
            for (q = 0; q < 2; q++) {
                const hfvis_bvh_node *cn = bvh->nodes + ch[q];
                mk[q] = stk + (size_t)(sp + q) * ent + 1;
                keep[q] = lk_node_keep(c, cn, F, p, st);
                e[q] = 0;
                if (!keep[q]) continue;
                lk_node_mask(c, cn, F, p, C, mk[q]);
                e[q] = lk_estimate(mk[q], C, words);
                if (e[q] == 0) {
                    st->nodes_culled_mask++;
                    keep[q] = 0;
                }
            }
            /* push the smaller estimate first: the larger is visited next (ties: left first) */
            if (keep[0] && keep[1]) {
                int first = e[1] <= e[0] ? 1 : 0; /* pushed first (popped last) */
                uint32_t *a0 = stk + (size_t)sp * ent, *a1 = a0 + ent;
                if (first == 0) { /* order in place: [left, right] -> right on top */
                    a0[0] = ch[0];
                    a1[0] = ch[1];
                } else { /* swap the two entries: [right, left] */
                    for (k = 0; k < words; k++) {
                        uint32_t tmp = a0[1 + k];
                        a0[1 + k] = a1[1 + k];
                        a1[1 + k] = tmp;
                    }
                    a0[0] = ch[1];
                    a1[0] = ch[0];
                }
                sp += 2;
            } else if (keep[0] || keep[1]) {
                uint32_t *a0 = stk + (size_t)sp * ent;
                if (keep[1]) memcpy(a0 + 1, mk[1], sizeof(uint32_t) * (size_t)words);
                a0[0] = keep[0] ? ch[0] : ch[1];
                sp += 1;
            }
        }
    }
}

static void lk_write_result(const lk_ctx *c, const uint32_t *C, size_t k, uint32_t *masks,
                            float *obscurance, hfvis_lk_stats *st)
{
    int bits = 0, w;
    for (w = 0; w < c->words; w++) bits += lk_popcount(C[w]);
    if (masks) memcpy(masks + k * (size_t)c->words, C, sizeof(uint32_t) * (size_t)c->words);
    if (obscurance) obscurance[k] = (float)((double)bits / (double)c->R->count);
    st->rays_blocked += (uint64_t)bits;
}

static void lk_receiver_frame(const lk_ctx *c, const hfvis_lk_receivers *recv, size_t k,
                              double F[9])
{
    lk_frame_make(&c->jit, recv->normal + 3 * k, recv->key ? recv->key[k] : (uint64_t)k, F);
}

HFVIS_API hfvis_status hfvis_lk_bvh(const hfvis_mesh *mesh, const hfvis_bvh *bvh,
                                    const hfvis_lk_rays *rays, const hfvis_lk_receivers *recv,
                                    const hfvis_lk_options *opts, uint32_t *masks,
                                    float *obscurance, hfvis_lk_stats *stats)
{
    lk_ctx c;
    lk_trav tv;
    hfvis_lk_stats st;
    hfvis_status s;
    size_t k;
    s = lk_explicit_init(&c, mesh, bvh, rays, recv, opts, masks, obscurance);
    if (s != HFVIS_OK) return s;
    s = lk_trav_init(&tv, &c, bvh);
    if (s != HFVIS_OK) return s;
    memset(&st, 0, sizeof st);
    for (k = 0; k < recv->count; k++) {
        double F[9];
        lk_receiver_frame(&c, recv, k, F);
        lk_bvh_receiver(&c, bvh, &tv, recv->position + 3 * k, F, tv.C, &st);
        lk_write_result(&c, tv.C, k, masks, obscurance, &st);
    }
    st.receivers = recv->count;
    st.rays = (uint64_t)recv->count * (uint64_t)rays->count;
    if (stats) *stats = st;
    hfvis__free(c.o.alloc, tv.block);
    return HFVIS_OK;
}

/* ---- 12.9 the reference ray caster ([LK] §6) ------------------------------------------- */

/* Slab test of the segment p + tD, t in [0, 1], against a padded node box, in double, widened
 * by LK_SLAB_PAD (relative) so it never rejects a box that the predicate's hit point lies in. */
static int lk_slab(const hfvis_bvh_node *nd, const double p[3], const double D[3],
                   const double inv[3])
{
    double tn = -HFVIS__INF, tf = HFVIS__INF;
    int a;
    for (a = 0; a < 3; a++) {
        double lo = (double)nd->lo[a], hi = (double)nd->hi[a], t0, t1;
        if (D[a] == 0.0) {
            if (p[a] < lo || p[a] > hi) return 0;
            continue;
        }
        t0 = (lo - p[a]) * inv[a];
        t1 = (hi - p[a]) * inv[a];
        if (t0 > t1) {
            double t = t0;
            t0 = t1;
            t1 = t;
        }
        if (t0 > tn) tn = t0;
        if (t1 < tf) tf = t1;
    }
    tn -= LK_SLAB_PAD * (1.0 + fabs(tn));
    tf += LK_SLAB_PAD * (1.0 + fabs(tf));
    return tn <= tf && tf >= 0.0 && tn <= 1.0;
}

/* Any-hit of ray i of one receiver with the predicate (EXACT). */
static int lk_cast_exact(const lk_ctx *c, const hfvis_bvh *bvh, const lk_trav *tv,
                         const double p[3], const double F[9], int i, hfvis_lk_stats *st)
{
    const double *s = c->R->point + 3 * i;
    double D[3], inv[3];
    uint32_t *stk = tv->stack;
    int sp = 0, a;
    if (c->R->length[i] == 0.0 || bvh->node_count == 0) return 0;
    for (a = 0; a < 3; a++) {
        D[a] = c->r * (F[a] * s[0] + F[3 + a] * s[1] + F[6 + a] * s[2]);
        inv[a] = D[a] != 0.0 ? 1.0 / D[a] : 0.0;
    }
    stk[sp++] = 0;
    while (sp > 0) {
        const hfvis_bvh_node *nd = bvh->nodes + stk[--sp];
        if (!lk_slab(nd, p, D, inv)) continue;
        st->nodes_visited++;
        if (nd->count > 0) {
            uint32_t j;
            for (j = nd->left_or_first; j < nd->left_or_first + nd->count; j++) {
                size_t t = bvh->tri_order[j];
                double rmin, rmax;
                lk_tri tri;
                if (tv->td[4 * t + 3] < 0.0) continue;
                lk_window(c, t, &rmin, &rmax);
                lk_tri_setup(&tri, F, p, lk_vertex(c->mesh, t, 0), lk_vertex(c->mesh, t, 1),
                             lk_vertex(c->mesh, t, 2), lk_two_sided(c, t), rmin, rmax, c->o.epsilon);
                st->fragments++;
                if (lk_blocks(&tri, s)) return 1;
            }
        } else {
            stk[sp++] = nd->left_or_first + 1;
            stk[sp++] = nd->left_or_first;
        }
    }
    return 0;
}

/* The WATERTIGHT test's candidate filter: the epsilon rule, one-sidedness for per-triangle
 * sides, the distance window. */
typedef struct lk_wt {
    const lk_ctx *c;
    const double *p;
    double lambda;   /* l_i / r */
} lk_wt;

static int lk_wt_filter(void *user, const hfvis_ray *ray, const hfvis_hit *cand)
{
    const lk_wt *w = (const lk_wt *)user;
    const lk_ctx *c = w->c;
    size_t t = cand->triangle;
    const float *f0 = lk_vertex(c->mesh, t, 0), *f1 = lk_vertex(c->mesh, t, 1), *f2 = lk_vertex(c->mesh, t, 2);
    double u[3], v[3], n[3], len, h, rmin, rmax, dist;
    int a;
    (void)ray;
    for (a = 0; a < 3; a++) {
        u[a] = (double)f1[a] - (double)f0[a];
        v[a] = (double)f2[a] - (double)f0[a];
    }
    lk_cross(u, v, n);
    len = sqrt(lk_dot(n, n));
    if (!(len > 0.0)) return 0;
    h = (n[0] * (w->p[0] - (double)f0[0]) + n[1] * (w->p[1] - (double)f0[1]) +
         n[2] * (w->p[2] - (double)f0[2])) / len;
    if (!(fabs(h) >= c->o.epsilon)) return 0;
    if (c->o.sides == HFVIS_LK_SIDES_PER_TRIANGLE && !c->o.two_sided[t] && !cand->front) return 0;
    lk_window(c, t, &rmin, &rmax);
    dist = (double)cand->t;
    return dist >= rmin * w->lambda && dist <= rmax * w->lambda;
}

static hfvis_status lk_cast_watertight(const lk_ctx *c, const hfvis_bvh *bvh, const double p[3],
                                       const double F[9], int i, int *blocked)
{
    const double *u = c->R->direction + 3 * i;
    hfvis_ray ray;
    hfvis_hit hit;
    lk_wt w;
    int a;
    *blocked = 0;
    if (c->R->length[i] == 0.0) return HFVIS_OK;
    memset(&ray, 0, sizeof ray);
    for (a = 0; a < 3; a++) {
        ray.origin[a] = (float)p[a];
        ray.direction[a] = (float)(F[a] * u[0] + F[3 + a] * u[1] + F[6 + a] * u[2]);
    }
    ray.t_min = FLT_MIN;
    ray.t_max = (float)(c->R->length[i] * c->r);
    ray.cull = c->o.sides == HFVIS_LK_SIDES_ONE ? HFVIS_CULL_BACK : HFVIS_CULL_NONE;
    w.c = c;
    w.p = p;
    w.lambda = c->R->length[i];
    {
        hfvis_status s = hfvis_bvh_intersect(bvh, c->mesh, &ray, HFVIS_RAY_ANY, lk_wt_filter, &w, &hit);
        if (s != HFVIS_OK) return s;
    }
    *blocked = hit.triangle != HFVIS_NO_TRIANGLE;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_lk_reference(const hfvis_mesh *mesh, const hfvis_bvh *bvh,
                                        const hfvis_lk_rays *rays,
                                        const hfvis_lk_receivers *recv,
                                        const hfvis_lk_options *opts, uint32_t *masks,
                                        float *obscurance, hfvis_lk_stats *stats)
{
    lk_ctx c;
    lk_trav tv;
    hfvis_lk_stats st;
    hfvis_status s = HFVIS_OK;
    size_t k;
    s = lk_explicit_init(&c, mesh, bvh, rays, recv, opts, masks, obscurance);
    if (s != HFVIS_OK) return s;
    s = lk_trav_init(&tv, &c, bvh);
    if (s != HFVIS_OK) return s;
    memset(&st, 0, sizeof st);
    for (k = 0; k < recv->count && s == HFVIS_OK; k++) {
        double F[9];
        const double *p = recv->position + 3 * k;
        int i;
        lk_receiver_frame(&c, recv, k, F);
        memset(tv.C, 0, sizeof(uint32_t) * (size_t)c.words);
        for (i = 0; i < rays->count; i++) {
            int blocked;
            if (c.o.raycast_test == HFVIS_LK_RAYCAST_WATERTIGHT) {
                s = lk_cast_watertight(&c, bvh, p, F, i, &blocked);
                if (s != HFVIS_OK) break;
            } else {
                blocked = lk_cast_exact(&c, bvh, &tv, p, F, i, &st);
            }
            if (blocked) tv.C[i >> 5] |= 1u << (i & 31);
        }
        if (s == HFVIS_OK) lk_write_result(&c, tv.C, k, masks, obscurance, &st);
    }
    st.receivers = recv->count;
    st.rays = (uint64_t)recv->count * (uint64_t)rays->count;
    if (s == HFVIS_OK && stats) *stats = st;
    hfvis__free(c.o.alloc, tv.block);
    return s;
}

/* ---- 12.10 the image driver ------------------------------------------------------------------ */

HFVIS_API hfvis_status hfvis_lk_image(hfvis_lk_method method, const hfvis_mesh *mesh,
                                      const hfvis_bvh *bvh, const hfvis_view *view,
                                      const hfvis_lk_rays *rays, const hfvis_lk_options *opts,
                                      uint32_t *masks, float *obscurance, hfvis_lk_stats *stats)
{
    hfvis_lk_options o;
    hfvis_lk_receivers rc;
    hfvis_bvh own;
    lk_cam cam;
    hfvis_status s;
    unsigned char *block, *cur;
    double *pos, *nrm;
    uint64_t *key;
    uint32_t *rm = NULL;
    float *ro = NULL;
    size_t npix, bytes = 0, count = 0, i, words;
    if (method == HFVIS_LK_METHOD_RASTER)
        return hfvis_lk_raster(mesh, view, rays, opts, masks, obscurance, stats);
    if ((method != HFVIS_LK_METHOD_BVH && method != HFVIS_LK_METHOD_RAYCAST) || !mesh || !view ||
        !lk_rays_valid(rays) || (!masks && !obscurance))
        return HFVIS_ERR_INVALID_ARGUMENT;
    s = hfvis_lk_options_resolve(opts, rays->radius, &o);
    if (s != HFVIS_OK) return s;
    s = hfvis__mesh_check(mesh);
    if (s != HFVIS_OK) return s;
    s = lk_cam_init(&cam, view);
    if (s != HFVIS_OK) return s;
    if (view->width > HFVIS_RASTER_MAX_SIZE || view->height > HFVIS_RASTER_MAX_SIZE)
        return HFVIS_ERR_LIMIT;
    npix = (size_t)view->width * (size_t)view->height;
    words = (size_t)rays->words;
    if (!lk_part(&bytes, npix, 6 * sizeof(double)) || !lk_part(&bytes, npix, sizeof(uint64_t)) ||
        (masks && !lk_part(&bytes, npix, words * sizeof(uint32_t))) ||
        (obscurance && !lk_part(&bytes, npix, sizeof(float))))
        return HFVIS_ERR_LIMIT;
    block = (unsigned char *)hfvis__alloc(o.alloc, bytes);
    if (!block) return HFVIS_ERR_OUT_OF_MEMORY;
    cur = block;
    pos = (double *)lk_take(&cur, npix, 3 * sizeof(double));
    nrm = (double *)lk_take(&cur, npix, 3 * sizeof(double));
    key = (uint64_t *)lk_take(&cur, npix, sizeof(uint64_t));
    if (masks) rm = (uint32_t *)lk_take(&cur, npix, words * sizeof(uint32_t));
    if (obscurance) ro = (float *)lk_take(&cur, npix, sizeof(float));
    s = hfvis_lk_gbuffer_receivers(mesh, view, &o, pos, nrm, key, &count);
    if (s != HFVIS_OK) {
        hfvis__free(o.alloc, block);
        return s;
    }
    if (!bvh) {
        hfvis_bvh_options bo = hfvis_bvh_options_default();
        bo.alloc = o.alloc;
        s = hfvis_bvh_build(mesh, &bo, &own);
        if (s != HFVIS_OK) {
            hfvis__free(o.alloc, block);
            return s;
        }
    }
    rc.count = count;
    rc.position = pos;
    rc.normal = nrm;
    rc.key = key;
    if (method == HFVIS_LK_METHOD_BVH) s = hfvis_lk_bvh(mesh, bvh ? bvh : &own, rays, &rc, &o, rm, ro, stats);
    else s = hfvis_lk_reference(mesh, bvh ? bvh : &own, rays, &rc, &o, rm, ro, stats);
    if (!bvh) hfvis_bvh_free(o.alloc, &own);
    if (s == HFVIS_OK) {
        if (masks) memset(masks, 0, sizeof(uint32_t) * npix * words);
        if (obscurance)
            for (i = 0; i < npix; i++) obscurance[i] = (float)NAN;
        for (i = 0; i < count; i++) {
            if (masks) memcpy(masks + key[i] * words, rm + i * words, sizeof(uint32_t) * words);
            if (obscurance) obscurance[key[i]] = ro[i];
        }
    }
    hfvis__free(o.alloc, block);
    return s;
}
