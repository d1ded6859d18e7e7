/* ssao.c - screen space. Part of hfvis (see hfvis.h for the conventions and the API).
 *
 * Contents
 *   1. Common: allocation, checked sizes, the hash PRNG
 *   2. Camera, hardware depth linearisation, view-space reconstruction, normals from depth
 *      (spec screenspace-p3-p4 §2.1)
 *   3. Falloff functions ([P3] Eq. 2-3; spec §1.1)
 *   4. The azimuthal line plane, uniform and box-pattern directions, the line lattice
 *      ([P3] §5.1-5.2, [P4] §6; spec §2.2-2.3, §3.5)
 *   5. P3 line-sweep AO: the obscurity hull along one line ([P3] §4, Alg. 1) and its brute-force
 *      oracle (spec §4.2), the sweep of one direction, the per-pixel gather ([P3] §5.1), the
 *      driver (spec §3)
 *   6. HBAO in three variants (Bavoil, Sainz, Dimitrov 2008, as the thesis describes it; spec §4.1)
 *   7. The screen-space ray-traced reference ([P4] §8; spec §5.11)
 *   8. Analytic depth buffers (spec §6 T1-T7)
 * Later issues add: P4 far-field AO and the mipmap baseline; Laine-Karras bitmask ray-cast AO.
 *
 * Paper references: [P3] V. Timonen, "Line-Sweep Ambient Obscurance", EGSR 2013; [P4]
 * V. Timonen, "Screen-Space Far-Field Ambient Obscurance", HPG 2013 (both in Timonen's 2014
 * thesis). "spec" is the project's restatement spec/screenspace-p3-p4.md, which fixes the
 * papers' errata and marks each open choice.
 */
#include "hfvis.h"

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#endif

#ifndef HFVIS_ASSERT
#ifdef HFVIS_ENABLE_ASSERTS
#include <assert.h>
#define HFVIS_ASSERT(x) assert(x)
#else
#define HFVIS_ASSERT(x) ((void)0)
#endif
#endif

#define SS_PI 3.14159265358979323846
#define SS_INF ((double)INFINITY)
#define SS_NAN ((double)NAN)

/* ========================================================================================== */
/* 1. Common                                                                                  */
/* ========================================================================================== */

static void *ss_alloc(const hfvis_allocator *a, size_t bytes)
{
    if (bytes == 0) return NULL;
    if (a && a->alloc) return a->alloc(a->user, bytes);
    return malloc(bytes);
}

static void ss_free(const hfvis_allocator *a, void *p)
{
    if (!p) return;
    if (a && a->free) a->free(a->user, p);
    else if (!(a && a->alloc)) free(p);
}

/* a*b into *out; 1 if it does not overflow. */
static int ss_mul(size_t a, size_t b, size_t *out)
{
    if (a != 0 && b > SIZE_MAX / a) return 0;
    *out = a * b;
    return 1;
}

/* a*b*c bytes, 0 on overflow (callers never ask for 0 bytes). */
static size_t ss_bytes3(size_t a, size_t b, size_t c)
{
    size_t t, u;
    if (!ss_mul(a, b, &t) || !ss_mul(t, c, &u)) return 0;
    return u;
}

static int ss_finite(double v) { return v == v && v - v == 0.0; }

/* SplitMix64 finaliser: the library's stateless hash PRNG (no global state). */
static uint64_t ss_mix(uint64_t z)
{
    z += 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Uniform double in [0, 1) from (a, b, c, seed). */
static double ss_hash01(uint32_t a, uint32_t b, uint32_t c, uint32_t seed)
{
    uint64_t h = ss_mix(((uint64_t)seed << 32) ^ (uint64_t)a);
    h = ss_mix(h ^ ((uint64_t)b << 32) ^ (uint64_t)c);
    return (double)(h >> 11) * (1.0 / 9007199254740992.0);
}

/* ========================================================================================== */
/* 2. Camera, depth, view-space reconstruction, normals (spec §2.1)                           */
/* ========================================================================================== */

/* The validated camera in the form the inner loops use. */
typedef struct ss_cam {
    int persp;
    int W, H, gx, gy;
    ptrdiff_t stride;
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
    if (cam->guard_x >= (cam->width + 1) / 2 || cam->guard_y >= (cam->height + 1) / 2)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (cam->projection == HFVIS_CAMERA_PERSPECTIVE) {
        if (!(ss_finite(cam->fx) && cam->fx > 0.0 && ss_finite(cam->fy) && cam->fy > 0.0))
            return HFVIS_ERR_INVALID_ARGUMENT;
    } else if (cam->projection == HFVIS_CAMERA_ORTHOGRAPHIC) {
        if (!(ss_finite(cam->scale_x) && cam->scale_x > 0.0 && ss_finite(cam->scale_y) &&
              cam->scale_y > 0.0))
            return HFVIS_ERR_INVALID_ARGUMENT;
    } else {
        return HFVIS_ERR_INVALID_ARGUMENT;
    }
    if (!ss_finite(cam->cx) || !ss_finite(cam->cy)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (!(cam->far_depth >= 0.0)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (cam->width > HFVIS_SSAO_MAX_SIZE || cam->height > HFVIS_SSAO_MAX_SIZE)
        return HFVIS_ERR_LIMIT;
    {
        size_t st = (size_t)(cam->stride ? cam->stride : cam->width), n;
        if (!ss_mul(st, (size_t)cam->height, &n) || !ss_mul(n, 3 * sizeof(float), &n) ||
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
    c->far_d = cam->far_depth > 0.0 ? cam->far_depth : SS_INF;
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
    if (!cam || !(fov_y_rad > 0.0 && fov_y_rad < SS_PI)) return HFVIS_ERR_INVALID_ARGUMENT;
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
    if (!(ss_finite(f) && f > 0.0)) return HFVIS_ERR_INVALID_ARGUMENT;
    c.fx = c.fy = f;
    *cam = c;
    return HFVIS_OK;
}

hfvis_status hfvis_camera_orthographic(hfvis_camera *cam, int width, int height, int guard_x,
                                       int guard_y, double pixel_size)
{
    hfvis_camera c;
    hfvis_status s;
    if (!cam || !(ss_finite(pixel_size) && pixel_size > 0.0)) return HFVIS_ERR_INVALID_ARGUMENT;
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
        if (!ss_finite(P[i])) return HFVIS_ERR_INVALID_ARGUMENT;
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

hfvis_status hfvis_camera_unproject(const hfvis_camera *cam, double u, double v, double depth,
                                    double out[3])
{
    ss_cam c;
    hfvis_status s = ss_cam_load(cam, &c);
    if (s != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    if (!out || !ss_finite(u) || !ss_finite(v) || !ss_finite(depth))
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
    if (!p || !u || !v || !depth || !ss_finite(p[0]) || !ss_finite(p[1]) || !ss_finite(p[2]))
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
        return !ortho && ss_finite(n) && n > 0.0;
    if (!ss_finite(n) || !ss_finite(f) || !(n < f)) return 0;
    return ortho ? n >= 0.0 : n > 0.0;
}

double hfvis_depth_linear(double d, hfvis_depth_encoding e, int ortho, double n, double f)
{
    double z;
    if (!ss_depth_params(e, ortho, n, f)) return SS_NAN;
    if (!ss_finite(d)) return SS_INF;
    if (e == HFVIS_DEPTH_GL_NDC) {
        if (!(d >= -1.0 && d <= 1.0)) return SS_INF;
        d = 0.5 * (d + 1.0);
        e = HFVIS_DEPTH_GL;
    }
    if (!(d >= 0.0 && d <= 1.0)) return SS_INF;
    switch (e) {
    case HFVIS_DEPTH_GL:
    case HFVIS_DEPTH_D3D:
        z = ortho ? n + d * (f - n) : n * f / (f - d * (f - n));
        break;
    case HFVIS_DEPTH_REVERSED_Z:
        z = ortho ? f - d * (f - n) : n * f / (n + d * (f - n));
        break;
    case HFVIS_DEPTH_INFINITE_FAR:
        z = d < 1.0 ? n / (1.0 - d) : SS_INF;
        break;
    default: /* HFVIS_DEPTH_REVERSED_INFINITE */
        z = d > 0.0 ? n / d : SS_INF;
        break;
    }
    return ss_finite(z) ? z : SS_INF;
}

double hfvis_depth_hardware(double z, hfvis_depth_encoding e, int ortho, double n, double f)
{
    double d;
    if (!ss_depth_params(e, ortho, n, f) || z != z) return SS_NAN;
    if (!ortho && !(z > 0.0)) return SS_NAN;
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
    if (!in || !out || width < 1 || height < 1 || in_stride < width || out_stride < width)
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
    if (!(l > 0.0) || !ss_finite(l)) return 0;
    v[0] /= l;
    v[1] /= l;
    v[2] /= l;
    return 1;
}

/* Depth of texel (x, y) (no bounds check). */
static double ss_tex(const ss_cam *c, const float *depth, int x, int y)
{
    return (double)depth[(ptrdiff_t)y * c->stride + x];
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
            float *o = normals + 3 * ((ptrdiff_t)y * c->stride + x);
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
/* 3. Falloff ([P3] Eq. 2-3; spec §1.1)                                                       */
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
        return ss_finite(f->param) && f->param > 0.0 ? HFVIS_OK : HFVIS_ERR_INVALID_ARGUMENT;
    case HFVIS_FALLOFF_HBAO:
        if (!(ss_finite(f->param) && f->param > 0.0)) return HFVIS_ERR_INVALID_ARGUMENT;
        return ss_finite(f->hbao_c) && f->hbao_c >= 0.0 ? HFVIS_OK : HFVIS_ERR_INVALID_ARGUMENT;
    case HFVIS_FALLOFF_CUSTOM:
        if (!f->fn) return HFVIS_ERR_INVALID_ARGUMENT;
        return ss_finite(f->param) && f->param >= 0.0 ? HFVIS_OK : HFVIS_ERR_INVALID_ARGUMENT;
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
    o->support = SS_INF;
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

static double ss_rho(const ss_fall *f, double d)
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
    if (ss_fall_load(f, &o) != HFVIS_OK || distance != distance) return SS_NAN;
    return ss_rho(&o, distance);
}

double hfvis_falloff_support(const hfvis_falloff *f)
{
    ss_fall o;
    if (ss_fall_load(f, &o) != HFVIS_OK) return SS_NAN;
    return o.support;
}

/* ========================================================================================== */
/* 4. Line plane, directions, lattice ([P3] §5.1-5.2, [P4] §6; spec §2.2-2.3, §3.5)           */
/* ========================================================================================== */

/* e1 of screen direction (du, dv) (spec §2.2; unit, z = 0). */
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
    if (!ss_finite(ref[0]) || !ss_finite(ref[1]) || !ss_finite(ref[2]) || !ss_finite(du) ||
        !ss_finite(dv) || (du == 0.0 && dv == 0.0))
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

static int ss_step_ok(double s) { return ss_finite(s) && s >= SS_MIN_STEP && s <= (double)HFVIS_SSAO_MAX_SIZE; }

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
    if (!out || K < 1 || K > HFVIS_SSAO_MAX_DIRECTIONS || !ss_finite(azimuth0_rad) ||
        !ss_step_ok(step) || !ss_step_ok(spacing))
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (k = 0; k < K; k++) {
        double psi = azimuth0_rad + 2.0 * SS_PI * (double)k / (double)K;
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
    return a < 0.0 ? a + 2.0 * SS_PI : a;
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
        if (gap < 0.0) gap += 2.0 * SS_PI;
        out[k].weight = gap / (4.0 * SS_PI);
    }
    return HFVIS_OK;
}

static int ss_dir_ok(const hfvis_ssao_direction *d)
{
    double l;
    if (!d || !ss_finite(d->dx) || !ss_finite(d->dy) || !ss_step_ok(d->step) ||
        !ss_step_ok(d->spacing) || !ss_finite(d->step_x) || !ss_finite(d->step_y))
        return 0;
    l = d->dx * d->dx + d->dy * d->dy;
    if (fabs(l - 1.0) > 1e-9) return 0;
    if (fabs(d->step_x - d->step * d->dx) > 1e-9 * d->step ||
        fabs(d->step_y - d->step * d->dy) > 1e-9 * d->step)
        return 0;
    return 1;
}

/* Step range [first, first + count) of line j, and its step-0 position. */
static void ss_line_range(const ss_cam *c, const hfvis_ssao_lattice *L, int j, hfvis_ssao_line *ln)
{
    const double eps = 1e-7;
    double s = L->s_first + (double)j * L->dir.spacing;
    double ox = s * L->px, oy = s * L->py, tlo = -SS_INF, thi = SS_INF;
    double D[2], O[2], lo[2], hi[2];
    double fa, fb;
    int a;
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
    for (a = 0; a < 2; a++) {
        if (D[a] == 0.0) {
            if (O[a] < lo[a] || O[a] > hi[a]) return;
        } else {
            double t1 = (lo[a] - O[a]) / D[a], t2 = (hi[a] - O[a]) / D[a];
            if (t1 > t2) {
                double t = t1;
                t1 = t2;
                t2 = t;
            }
            if (t1 > tlo) tlo = t1;
            if (t2 < thi) thi = t2;
        }
    }
    if (!(tlo <= thi)) return;
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
    double cu[4], cv[4], smin = SS_INF, smax = -SS_INF, tmin = SS_INF, span, nl;
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

/* Nearest sample (spec §2.3); 1 if found. */
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
    if (!lat || !lines || !line || !step || !ss_finite(u) || !ss_finite(v)) return 0;
    if (!(lat->dir.spacing > 0.0) || !(lat->dir.step > 0.0)) return 0;
    return ss_nearest(lat, lines, u, v, line, step);
}
