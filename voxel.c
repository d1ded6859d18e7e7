/* voxel.c - meshes and volumes. Part of hfvis (see hfvis.h for the conventions and the API).
 *
 * Contents
 *   1. Common: allocation, checked sizes, mesh and grid validation, file helpers
 *   2. Views: GL-convention matrices, depth linearisation (thesis eq. 16, sign restored)
 *   3. Volume grids and the Volume Buffer (thesis ch. 6 §6.3; spec voxel §3.2-3.3)
 *
 * Paper references: [G12] A. Gaitatzes, "Interactive diffuse global illumination discretization
 * methods for dynamic environments", PhD thesis, Univ. of Cyprus, 2012. "spec voxel" is the
 * project's restatement spec/voxel-visfield-volgi.md, which fixes the thesis' errata.
 */
#include "hfvis.h"

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#ifndef HFVIS_NO_STDIO
#include <stdio.h>
#endif

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

#define VX_PI 3.14159265358979323846

/* Marks internal helpers that a given build may leave unused (-Wunused-function). */
#if defined(__GNUC__)
#define VX_MAYBE_UNUSED __attribute__((unused))
#else
#define VX_MAYBE_UNUSED
#endif

/* ========================================================================================== */
/* 1. Common                                                                                  */
/* ========================================================================================== */

#ifndef HFVIS_NO_STDIO
/* Internal, defined in hfvis.c (section 2): whole-file read into a block from alloc, and an
 * atomic write (temporary file renamed onto path: the target is complete or untouched). */
hfvis_status hfvis__read_file(const char *path, const hfvis_allocator *alloc, unsigned char **data,
                             size_t *size);
hfvis_status hfvis__write_file(const char *path, const unsigned char *bytes, size_t n);
#endif

static void *vx_alloc(const hfvis_allocator *a, size_t bytes)
{
    if (bytes == 0) return NULL;
    if (a && a->alloc) return a->alloc(a->user, bytes);
    return malloc(bytes);
}

static void vx_free(const hfvis_allocator *a, void *p)
{
    if (!p) return;
    if (a && a->free) a->free(a->user, p);
    else if (!a || !a->alloc) free(p);
}

/* *out = a*b; returns 0 (and leaves *out alone) on overflow. */
static int vx_mul_size(size_t a, size_t b, size_t *out)
{
    if (a != 0 && b > SIZE_MAX / a) return 0;
    *out = a * b;
    return 1;
}

/* count*elem bytes from alloc; NULL on overflow, failure or count 0. */
VX_MAYBE_UNUSED static void *vx_alloc_array(const hfvis_allocator *a, size_t count, size_t elem)
{
    size_t bytes;
    if (!vx_mul_size(count, elem, &bytes)) return NULL;
    return vx_alloc(a, bytes);
}

/* HFVIS_OK when the mesh is usable (hfvis_mesh: indices < vertex_count, finite coordinates),
 * else HFVIS_ERR_INVALID_ARGUMENT. O(V + T). */
static hfvis_status vx_mesh_check(const hfvis_mesh *m)
{
    size_t i, n;
    if (!m) return HFVIS_ERR_INVALID_ARGUMENT;
    if ((m->vertex_count && !m->xyz) || (m->triangle_count && !m->indices))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (m->vertex_count > SIZE_MAX / 3 || m->triangle_count > SIZE_MAX / 3)
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (i = 0; i < 3 * m->vertex_count; i++)
        if (!isfinite(m->xyz[i])) return HFVIS_ERR_INVALID_ARGUMENT;
    n = 3 * m->triangle_count;
    for (i = 0; i < n; i++)
        if ((size_t)m->indices[i] >= m->vertex_count) return HFVIS_ERR_INVALID_ARGUMENT;
    return HFVIS_OK;
}

/* 1 when g is a valid grid (hfvis_volume_grid), else 0. */
static int vx_grid_valid(const hfvis_volume_grid *g)
{
    size_t n = 1;
    int a;
    if (!g) return 0;
    for (a = 0; a < 3; a++) {
        if (g->dims[a] < 1 || !isfinite(g->origin[a]) || !isfinite(g->cell[a])
            || !(g->cell[a] > 0.0))
            return 0;
        if (!vx_mul_size(n, (size_t)g->dims[a], &n)) return 0;
    }
    return n <= HFVIS_VOLUME_MAX_VOXELS;
}

/* Voxels of a valid grid. */
static size_t vx_grid_voxels(const hfvis_volume_grid *g)
{
    return (size_t)g->dims[0] * (size_t)g->dims[1] * (size_t)g->dims[2];
}

HFVIS_API void hfvis_mesh_free(const hfvis_allocator *alloc, hfvis_mesh *mesh)
{
    if (!mesh) return;
    /* The arrays are const for the mesh's users; the generators and decoders own them. */
    vx_free(alloc, (void *)(uintptr_t)mesh->xyz);
    vx_free(alloc, (void *)(uintptr_t)mesh->indices);
    memset(mesh, 0, sizeof *mesh);
}

/* ========================================================================================== */
/* 2. Views (spec voxel §0)                                                                   */
/* ========================================================================================== */

#define VX_M(m, r, c) ((m)[(c) * 4 + (r)]) /* column-major element (row r, column c) */

static int vx_all_finite(const double *v, int n)
{
    int i;
    for (i = 0; i < n; i++)
        if (!isfinite(v[i])) return 0;
    return 1;
}

/* out = m * in (homogeneous 4-vectors). out must not alias in. */
VX_MAYBE_UNUSED static void vx_mat4_apply(const double m[16], const double in[4], double out[4])
{
    int r;
    for (r = 0; r < 4; r++)
        out[r] = VX_M(m, r, 0) * in[0] + VX_M(m, r, 1) * in[1] + VX_M(m, r, 2) * in[2]
                 + VX_M(m, r, 3) * in[3];
}

HFVIS_API void hfvis_mat4_multiply(const double a[16], const double b[16], double out[16])
{
    double t[16];
    int r, c;
    for (c = 0; c < 4; c++)
        for (r = 0; r < 4; r++)
            VX_M(t, r, c) = VX_M(a, r, 0) * VX_M(b, 0, c) + VX_M(a, r, 1) * VX_M(b, 1, c)
                            + VX_M(a, r, 2) * VX_M(b, 2, c) + VX_M(a, r, 3) * VX_M(b, 3, c);
    memcpy(out, t, sizeof t);
}

HFVIS_API hfvis_status hfvis_mat4_invert(const double m[16], double out[16])
{
    double a[4][8];
    int r, c, k;
    if (!m || !out || !vx_all_finite(m, 16)) return HFVIS_ERR_INVALID_ARGUMENT;
    for (r = 0; r < 4; r++)
        for (c = 0; c < 8; c++) a[r][c] = c < 4 ? VX_M(m, r, c) : (c - 4 == r ? 1.0 : 0.0);
    for (k = 0; k < 4; k++) {
        int p = k;
        double piv;
        for (r = k + 1; r < 4; r++)
            if (fabs(a[r][k]) > fabs(a[p][k])) p = r;
        if (!(fabs(a[p][k]) >= 1e-300)) return HFVIS_ERR_INVALID_ARGUMENT;
        if (p != k)
            for (c = 0; c < 8; c++) {
                double t = a[k][c];
                a[k][c] = a[p][c];
                a[p][c] = t;
            }
        piv = a[k][k];
        for (c = 0; c < 8; c++) a[k][c] /= piv;
        for (r = 0; r < 4; r++) {
            double f = a[r][k];
            if (r == k || f == 0.0) continue;
            for (c = 0; c < 8; c++) a[r][c] -= f * a[k][c];
        }
    }
    for (r = 0; r < 4; r++)
        for (c = 0; c < 4; c++) {
            if (!isfinite(a[r][c + 4])) return HFVIS_ERR_INVALID_ARGUMENT;
        }
    for (r = 0; r < 4; r++)
        for (c = 0; c < 4; c++) VX_M(out, r, c) = a[r][c + 4];
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_mat4_look_at(const double eye[3], const double target[3],
                                          const double up[3], double out[16])
{
    double f[3], s[3], u[3], lf, ls;
    int i;
    if (!eye || !target || !up || !out || !vx_all_finite(eye, 3) || !vx_all_finite(target, 3)
        || !vx_all_finite(up, 3))
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (i = 0; i < 3; i++) f[i] = target[i] - eye[i];
    lf = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    if (!(lf > 0.0) || !isfinite(lf)) return HFVIS_ERR_INVALID_ARGUMENT;
    for (i = 0; i < 3; i++) f[i] /= lf;
    s[0] = f[1] * up[2] - f[2] * up[1]; /* s = f x up */
    s[1] = f[2] * up[0] - f[0] * up[2];
    s[2] = f[0] * up[1] - f[1] * up[0];
    ls = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    if (!(ls > 1e-12 * sqrt(up[0] * up[0] + up[1] * up[1] + up[2] * up[2])) || !isfinite(ls))
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (i = 0; i < 3; i++) s[i] /= ls;
    u[0] = s[1] * f[2] - s[2] * f[1]; /* u = s x f */
    u[1] = s[2] * f[0] - s[0] * f[2];
    u[2] = s[0] * f[1] - s[1] * f[0];
    for (i = 0; i < 3; i++) {
        VX_M(out, 0, i) = s[i];
        VX_M(out, 1, i) = u[i];
        VX_M(out, 2, i) = -f[i];
        VX_M(out, 3, i) = 0.0;
    }
    VX_M(out, 0, 3) = -(s[0] * eye[0] + s[1] * eye[1] + s[2] * eye[2]);
    VX_M(out, 1, 3) = -(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]);
    VX_M(out, 2, 3) = f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2];
    VX_M(out, 3, 3) = 1.0;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_mat4_perspective(double fov_y_rad, double aspect, double near_plane,
                                              double far_plane, double out[16])
{
    double t;
    if (!out || !(fov_y_rad > 0.0 && fov_y_rad < VX_PI) || !(aspect > 0.0) || !isfinite(aspect)
        || !(near_plane > 0.0) || !(far_plane > near_plane) || !isfinite(far_plane))
        return HFVIS_ERR_INVALID_ARGUMENT;
    t = 1.0 / tan(0.5 * fov_y_rad);
    memset(out, 0, 16 * sizeof *out);
    VX_M(out, 0, 0) = t / aspect;
    VX_M(out, 1, 1) = t;
    VX_M(out, 2, 2) = (far_plane + near_plane) / (near_plane - far_plane);
    VX_M(out, 2, 3) = 2.0 * far_plane * near_plane / (near_plane - far_plane);
    VX_M(out, 3, 2) = -1.0;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_mat4_ortho(double left, double right, double bottom, double top,
                                        double near_plane, double far_plane, double out[16])
{
    double b[6];
    b[0] = left, b[1] = right, b[2] = bottom, b[3] = top, b[4] = near_plane, b[5] = far_plane;
    if (!out || !vx_all_finite(b, 6) || !(left < right) || !(bottom < top)
        || !(near_plane < far_plane))
        return HFVIS_ERR_INVALID_ARGUMENT;
    memset(out, 0, 16 * sizeof *out);
    VX_M(out, 0, 0) = 2.0 / (right - left);
    VX_M(out, 1, 1) = 2.0 / (top - bottom);
    VX_M(out, 2, 2) = -2.0 / (far_plane - near_plane);
    VX_M(out, 0, 3) = -(right + left) / (right - left);
    VX_M(out, 1, 3) = -(top + bottom) / (top - bottom);
    VX_M(out, 2, 3) = -(far_plane + near_plane) / (far_plane - near_plane);
    VX_M(out, 3, 3) = 1.0;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_view_perspective(hfvis_view *view, const double eye[3],
                                              const double target[3], const double up[3],
                                              double fov_y_rad, int width, int height,
                                              double near_plane, double far_plane)
{
    hfvis_view v;
    hfvis_status s;
    if (!view || width < 1 || height < 1) return HFVIS_ERR_INVALID_ARGUMENT;
    memset(&v, 0, sizeof v);
    s = hfvis_mat4_look_at(eye, target, up, v.view);
    if (s == HFVIS_OK)
        s = hfvis_mat4_perspective(fov_y_rad, (double)width / (double)height, near_plane,
                                   far_plane, v.proj);
    if (s != HFVIS_OK) return s;
    v.width = width, v.height = height;
    v.near_plane = near_plane, v.far_plane = far_plane;
    v.orthographic = 0;
    *view = v;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_view_orthographic(hfvis_view *view, const double eye[3],
                                               const double target[3], const double up[3],
                                               double half_height, int width, int height,
                                               double near_plane, double far_plane)
{
    hfvis_view v;
    hfvis_status s;
    double half_width;
    if (!view || width < 1 || height < 1 || !(half_height > 0.0) || !isfinite(half_height))
        return HFVIS_ERR_INVALID_ARGUMENT;
    half_width = half_height * ((double)width / (double)height);
    memset(&v, 0, sizeof v);
    s = hfvis_mat4_look_at(eye, target, up, v.view);
    if (s == HFVIS_OK)
        s = hfvis_mat4_ortho(-half_width, half_width, -half_height, half_height, near_plane,
                             far_plane, v.proj);
    if (s != HFVIS_OK) return s;
    v.width = width, v.height = height;
    v.near_plane = near_plane, v.far_plane = far_plane;
    v.orthographic = 1;
    *view = v;
    return HFVIS_OK;
}

/* [G12] eq. 16 prints z_e = n f / (f - zw (f - n)), a positive distance for a camera looking
 * down -z; spec voxel §4.2 restores the sign of the GL eye coordinate. */
HFVIS_API double hfvis_depth_to_eye_z(double zw, double near_plane, double far_plane,
                                      int orthographic)
{
    if (orthographic) return -(near_plane + zw * (far_plane - near_plane));
    return -near_plane * far_plane / (far_plane - zw * (far_plane - near_plane));
}

HFVIS_API double hfvis_eye_z_to_depth(double z_eye, double near_plane, double far_plane,
                                      int orthographic)
{
    if (orthographic) return (-z_eye - near_plane) / (far_plane - near_plane);
    return (far_plane + near_plane * far_plane / z_eye) / (far_plane - near_plane);
}

/* ========================================================================================== */
/* 3. Volume grids and the Volume Buffer ([G12] §6.3; spec voxel §3.2-3.3)                     */
/* ========================================================================================== */

HFVIS_API hfvis_status hfvis_volume_grid_fit(const hfvis_mesh *mesh, int resolution,
                                             double padding, int cubic, hfvis_volume_grid *out)
{
    double lo[3], hi[3], ext[3], ext_max = 0.0, cell_max;
    hfvis_volume_grid g;
    size_t i, total = 1;
    int a;
    if (!out || vx_mesh_check(mesh) != HFVIS_OK || mesh->triangle_count == 0 || resolution < 1
        || !(padding >= 0.0) || !isfinite(padding))
        return HFVIS_ERR_INVALID_ARGUMENT;
    /* Bounds of the vertices the triangles use (a soup may carry unused vertices). */
    for (a = 0; a < 3; a++) lo[a] = HUGE_VAL, hi[a] = -HUGE_VAL;
    for (i = 0; i < 3 * mesh->triangle_count; i++) {
        const float *p = mesh->xyz + 3 * (size_t)mesh->indices[i];
        for (a = 0; a < 3; a++) {
            if ((double)p[a] < lo[a]) lo[a] = (double)p[a];
            if ((double)p[a] > hi[a]) hi[a] = (double)p[a];
        }
    }
    for (a = 0; a < 3; a++)
        if (hi[a] - lo[a] > ext_max) ext_max = hi[a] - lo[a];
    if (!(ext_max > 0.0)) return HFVIS_ERR_INVALID_ARGUMENT;
    for (a = 0; a < 3; a++) {
        lo[a] -= padding * ext_max;
        hi[a] += padding * ext_max;
        ext[a] = hi[a] - lo[a];
    }
    ext_max *= 1.0 + 2.0 * padding;
    for (a = 0; a < 3; a++)
        if (ext[a] > ext_max) ext_max = ext[a]; /* rounding of the padded extents */
    cell_max = ext_max / (double)resolution;
    memset(&g, 0, sizeof g);
    for (a = 0; a < 3; a++) {
        double ratio = ext[a] / ext_max, n; /* exactly 1 on the longest axis */
        if (!isfinite(ext[a])) return HFVIS_ERR_INVALID_ARGUMENT;
        if (ext[a] == 0.0) {
            g.dims[a] = 1;
            g.cell[a] = cell_max;
            g.origin[a] = lo[a] - 0.5 * cell_max;
        } else if (!cubic) {
            n = floor(ratio * (double)resolution + 0.5);
            g.dims[a] = n < 1.0 ? 1 : (int)n;
            g.cell[a] = ext[a] / (double)g.dims[a];
            g.origin[a] = lo[a];
        } else {
            n = ceil(ratio * (double)resolution);
            g.dims[a] = n < 1.0 ? 1 : (int)n;
            g.cell[a] = cell_max;
            g.origin[a] = 0.5 * (lo[a] + hi[a]) - 0.5 * (double)g.dims[a] * cell_max;
        }
        if (!(g.cell[a] > 0.0) || !isfinite(g.origin[a])) return HFVIS_ERR_INVALID_ARGUMENT;
        if (!vx_mul_size(total, (size_t)g.dims[a], &total) || total > HFVIS_VOLUME_MAX_VOXELS)
            return HFVIS_ERR_LIMIT;
    }
    *out = g;
    return HFVIS_OK;
}

HFVIS_API size_t hfvis_volume_size(const hfvis_volume_grid *grid, int channels)
{
    size_t n;
    if (!vx_grid_valid(grid) || channels < 1 || channels > HFVIS_VOLUME_MAX_CHANNELS) return 0;
    if (!vx_mul_size(vx_grid_voxels(grid), (size_t)channels, &n)) return 0;
    return n;
}

static int vx_blend_valid(hfvis_blend b)
{
    return b == HFVIS_BLEND_MAX || b == HFVIS_BLEND_REPLACE || b == HFVIS_BLEND_MIN
           || b == HFVIS_BLEND_ADD;
}

HFVIS_API hfvis_status hfvis_volume_init(hfvis_volume *vol, const hfvis_volume_grid *grid,
                                         int channels, float *storage, hfvis_blend blend)
{
    size_t n = hfvis_volume_size(grid, channels), i;
    int c;
    if (!vol || !storage || n == 0 || !vx_blend_valid(blend)) return HFVIS_ERR_INVALID_ARGUMENT;
    memset(vol, 0, sizeof *vol);
    vol->grid = *grid;
    vol->channels = channels;
    vol->data = storage;
    for (c = 0; c < HFVIS_VOLUME_MAX_CHANNELS; c++) vol->blend[c] = blend;
    for (i = 0; i < n; i++) storage[i] = 0.0f;
    return HFVIS_OK;
}

HFVIS_API void hfvis_volume_clear(hfvis_volume *vol, float value)
{
    size_t n, i;
    if (!vol || !vol->data) return;
    n = hfvis_volume_size(&vol->grid, vol->channels);
    for (i = 0; i < n; i++) vol->data[i] = value;
}

/* The blend equation of one channel ([G12] §6.3: glBlendEquation per attachment). */
static float vx_blend_apply(hfvis_blend op, float stored, float value)
{
    switch (op) {
    case HFVIS_BLEND_REPLACE: return value;
    case HFVIS_BLEND_MIN: return value < stored ? value : stored;
    case HFVIS_BLEND_ADD: return stored + value;
    case HFVIS_BLEND_MAX: break;
    }
    return value > stored ? value : stored;
}

HFVIS_API hfvis_status hfvis_volume_write(hfvis_volume *vol, int i, int j, int k,
                                          const float *values)
{
    float *d;
    int c;
    if (!vol || !vol->data || !values || !vx_grid_valid(&vol->grid) || vol->channels < 1
        || vol->channels > HFVIS_VOLUME_MAX_CHANNELS || i < 0 || j < 0 || k < 0
        || i >= vol->grid.dims[0] || j >= vol->grid.dims[1] || k >= vol->grid.dims[2])
        return HFVIS_ERR_INVALID_ARGUMENT;
    d = vol->data + (((size_t)k * (size_t)vol->grid.dims[1] + (size_t)j) * (size_t)vol->grid.dims[0]
                     + (size_t)i) * (size_t)vol->channels;
    for (c = 0; c < vol->channels; c++) d[c] = vx_blend_apply(vol->blend[c], d[c], values[c]);
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_volume_merge(hfvis_volume *dst, const hfvis_volume *src)
{
    size_t n, i;
    int c, a;
    if (!dst || !src || !dst->data || !src->data || dst->channels != src->channels)
        return HFVIS_ERR_INVALID_ARGUMENT;
    n = hfvis_volume_size(&dst->grid, dst->channels);
    if (n == 0) return HFVIS_ERR_INVALID_ARGUMENT;
    for (a = 0; a < 3; a++)
        if (dst->grid.dims[a] != src->grid.dims[a]) return HFVIS_ERR_INVALID_ARGUMENT;
    for (i = 0; i < n; i += (size_t)dst->channels)
        for (c = 0; c < dst->channels; c++)
            dst->data[i + (size_t)c] =
                vx_blend_apply(dst->blend[c], dst->data[i + (size_t)c], src->data[i + (size_t)c]);
    return HFVIS_OK;
}

/* ========================================================================================== */
/* 1. Meshes: analytic test meshes and the Wavefront OBJ codec                                */
/*    (infrastructure for Gaitatzes 2012, ch. 6-7 and spec voxel §3.13: the icosphere of test  */
/*    4, the cube of tests 1-2, the 100k-triangle benchmark torus knot of issue 4)            */
/* ========================================================================================== */
/* Contents
 *   1a. mesh builder (exact sizes, limits, overflow checks, one cleanup path)
 *   1b. generators: box, UV sphere, icosphere, torus, torus knot, height field, room, teapot
 *   1c. bounds
 *   1d. OBJ decoder (two passes: count, then fill), own locale-independent number parser
 *   1e. OBJ encoder (own shortest round-trip float formatting), file wrappers
 * Every generated triangle is counter-clockwise seen from outside: (v1 - v0) x (v2 - v0) points
 * out of the enclosed volume (into the room for the room's walls). */

#define VX_MESH_PI 3.14159265358979323846

/* ---- 1a. builder ------------------------------------------------------------------------ */

typedef struct vx_mesh_builder {
    float *xyz;
    uint32_t *idx;
    size_t nv, nt;       /* filled so far */
    size_t cap_v, cap_t; /* exact sizes requested */
} vx_mesh_builder;

/* Allocate exactly nv vertices and nt triangles. HFVIS_ERR_LIMIT past the documented limits. */
static hfvis_status vx_mesh_builder_init(vx_mesh_builder *b, const hfvis_allocator *alloc,
                                         size_t nv, size_t nt)
{
    memset(b, 0, sizeof *b);
    if (nv > HFVIS_MESH_MAX_VERTICES || nt > HFVIS_MESH_MAX_TRIANGLES) return HFVIS_ERR_LIMIT;
    if (nv > 0) {
        b->xyz = (float *)vx_alloc_array(alloc, nv, 3 * sizeof(float));
        if (!b->xyz) return HFVIS_ERR_OUT_OF_MEMORY;
    }
    if (nt > 0) {
        b->idx = (uint32_t *)vx_alloc_array(alloc, nt, 3 * sizeof(uint32_t));
        if (!b->idx) {
            vx_free(alloc, b->xyz);
            b->xyz = NULL;
            return HFVIS_ERR_OUT_OF_MEMORY;
        }
    }
    b->cap_v = nv;
    b->cap_t = nt;
    return HFVIS_OK;
}

static void vx_mesh_builder_free(vx_mesh_builder *b, const hfvis_allocator *alloc)
{
    vx_free(alloc, b->xyz);
    vx_free(alloc, b->idx);
    b->xyz = NULL;
    b->idx = NULL;
}

static uint32_t vx_mesh_v(vx_mesh_builder *b, double x, double y, double z)
{
    size_t v = b->nv++;
    HFVIS_ASSERT(v < b->cap_v);
    b->xyz[3 * v] = (float)x;
    b->xyz[3 * v + 1] = (float)y;
    b->xyz[3 * v + 2] = (float)z;
    return (uint32_t)v;
}

static void vx_mesh_t(vx_mesh_builder *b, size_t i0, size_t i1, size_t i2)
{
    size_t t = b->nt++;
    HFVIS_ASSERT(t < b->cap_t && i0 < b->cap_v && i1 < b->cap_v && i2 < b->cap_v);
    b->idx[3 * t] = (uint32_t)i0;
    b->idx[3 * t + 1] = (uint32_t)i1;
    b->idx[3 * t + 2] = (uint32_t)i2;
}

/* Hand the arrays to *out after checking that every coordinate is finite (huge parameters can
 * overflow float: HFVIS_ERR_INVALID_ARGUMENT, nothing leaked, *out untouched). */
static hfvis_status vx_mesh_builder_finish(vx_mesh_builder *b, const hfvis_allocator *alloc,
                                           hfvis_mesh *out)
{
    size_t i;
    HFVIS_ASSERT(b->nv == b->cap_v && b->nt == b->cap_t);
    for (i = 0; i < 3 * b->nv; i++) {
        if (!isfinite(b->xyz[i])) {
            vx_mesh_builder_free(b, alloc);
            return HFVIS_ERR_INVALID_ARGUMENT;
        }
    }
    out->xyz = b->xyz;
    out->vertex_count = b->nv;
    out->indices = b->idx;
    out->triangle_count = b->nt;
    b->xyz = NULL;
    b->idx = NULL;
    return HFVIS_OK;
}

/* A finite parameter whose float image is finite too (coordinates are stored as float). */
static int vx_mesh_coord_ok(double v) { return isfinite(v) && fabs(v) <= (double)FLT_MAX; }

static int vx_mesh_point_ok(const double c[3])
{
    return c && vx_mesh_coord_ok(c[0]) && vx_mesh_coord_ok(c[1]) && vx_mesh_coord_ok(c[2]);
}

/* Count products in size_t, saturating to SIZE_MAX (which every limit check rejects). */
static size_t vx_mesh_mul(size_t a, size_t b)
{
    size_t r;
    return vx_mul_size(a, b, &r) ? r : SIZE_MAX;
}
static size_t vx_mesh_add(size_t a, size_t b) { return a > SIZE_MAX - b ? SIZE_MAX : a + b; }

/* ---- 1b. generators --------------------------------------------------------------------- */

/* The 12 outward triangles of a box whose corner k is (bit0: x, bit1: y, bit2: z) hi or lo,
 * two per face in the order -x, +x, -y, +y, -z, +z. */
static const unsigned char vx_mesh_box_tris[12][3] = {
    {0, 4, 6}, {0, 6, 2}, /* -x */
    {1, 3, 7}, {1, 7, 5}, /* +x */
    {0, 1, 5}, {0, 5, 4}, /* -y */
    {2, 6, 7}, {2, 7, 3}, /* +y */
    {0, 2, 3}, {0, 3, 1}, /* -z */
    {4, 5, 7}, {4, 7, 6}  /* +z */
};

HFVIS_API hfvis_status hfvis_mesh_box(const hfvis_allocator *alloc, const double lo[3],
                                      const double hi[3], hfvis_mesh *out)
{
    vx_mesh_builder b;
    hfvis_status s;
    int k, a;
    if (!out || !vx_mesh_point_ok(lo) || !vx_mesh_point_ok(hi)) return HFVIS_ERR_INVALID_ARGUMENT;
    for (a = 0; a < 3; a++)
        if (!(lo[a] < hi[a])) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_mesh_builder_init(&b, alloc, 8, 12);
    if (s != HFVIS_OK) return s;
    for (k = 0; k < 8; k++)
        vx_mesh_v(&b, (k & 1) ? hi[0] : lo[0], (k & 2) ? hi[1] : lo[1], (k & 4) ? hi[2] : lo[2]);
    for (k = 0; k < 12; k++)
        vx_mesh_t(&b, vx_mesh_box_tris[k][0], vx_mesh_box_tris[k][1], vx_mesh_box_tris[k][2]);
    return vx_mesh_builder_finish(&b, alloc, out);
}

/* Surface of revolution about the z axis through c: profile points (rho[i], z[i]),
 * i = 0..m (m >= 2), rho[0] = rho[m] = 0 (single pole vertices), ordered from the top pole
 * down the outside, revolved into `slices` meridians at phi_j = 2 pi j / slices (j = 0 at +x,
 * counter-clockwise seen from +z). Vertices: top pole, rings i = 1..m-1 (slices each, j
 * fastest), bottom pole. Triangles: top fan, bands (a, c, d), (a, d, b) with a = (i, j),
 * b = (i, j+1), c = (i+1, j), d = (i+1, j+1), bottom fan. Outward for a profile traversed
 * top to bottom on the outside. Writes (m-1)*slices + 2 vertices, 2*slices*(m-1) triangles. */
static void vx_mesh_revolve(vx_mesh_builder *b, const double c[3], const double *rho,
                            const double *z, size_t m, size_t slices)
{
    size_t i, j, base = b->nv, top, bottom;
    top = vx_mesh_v(b, c[0], c[1], c[2] + z[0]);
    for (i = 1; i < m; i++) {
        for (j = 0; j < slices; j++) {
            double phi = 2.0 * VX_MESH_PI * (double)j / (double)slices;
            vx_mesh_v(b, c[0] + rho[i] * cos(phi), c[1] + rho[i] * sin(phi), c[2] + z[i]);
        }
    }
    bottom = vx_mesh_v(b, c[0], c[1], c[2] + z[m]);
    for (j = 0; j < slices; j++) {
        size_t j1 = (j + 1) % slices;
        vx_mesh_t(b, top, base + 1 + j, base + 1 + j1);
    }
    for (i = 1; i + 1 < m; i++) {
        size_t r0 = base + 1 + (i - 1) * slices, r1 = r0 + slices;
        for (j = 0; j < slices; j++) {
            size_t j1 = (j + 1) % slices;
            vx_mesh_t(b, r0 + j, r1 + j, r1 + j1);
            vx_mesh_t(b, r0 + j, r1 + j1, r0 + j1);
        }
    }
    {
        size_t r0 = base + 1 + (m - 2) * slices;
        for (j = 0; j < slices; j++) {
            size_t j1 = (j + 1) % slices;
            vx_mesh_t(b, r0 + j, bottom, r0 + j1);
        }
    }
}

HFVIS_API hfvis_status hfvis_mesh_uv_sphere(const hfvis_allocator *alloc, const double c[3],
                                            double r, int slices, int stacks, hfvis_mesh *out)
{
    vx_mesh_builder b;
    hfvis_status s;
    double *prof;
    size_t i, m, nv, nt;
    if (!out || !vx_mesh_point_ok(c) || !vx_mesh_coord_ok(r) || !(r > 0.0) || slices < 3
        || stacks < 2)
        return HFVIS_ERR_INVALID_ARGUMENT;
    m = (size_t)stacks;
    nv = vx_mesh_add(vx_mesh_mul(m - 1, (size_t)slices), 2);
    nt = vx_mesh_mul(vx_mesh_mul(2, (size_t)slices), m - 1);
    if (nv > HFVIS_MESH_MAX_VERTICES || nt > HFVIS_MESH_MAX_TRIANGLES) return HFVIS_ERR_LIMIT;
    prof = (double *)vx_alloc_array(alloc, m + 1, 2 * sizeof(double));
    if (!prof) return HFVIS_ERR_OUT_OF_MEMORY;
    for (i = 0; i <= m; i++) { /* theta_i = pi i / stacks from the north pole */
        double th = VX_MESH_PI * (double)i / (double)m;
        prof[i] = (i == 0 || i == m) ? 0.0 : r * sin(th);
        prof[m + 1 + i] = (i == 0) ? r : (i == m) ? -r : r * cos(th);
    }
    s = vx_mesh_builder_init(&b, alloc, nv, nt);
    if (s == HFVIS_OK) {
        vx_mesh_revolve(&b, c, prof, prof + m + 1, m, (size_t)slices);
        s = vx_mesh_builder_finish(&b, alloc, out);
    }
    vx_free(alloc, prof);
    return s;
}

/* Edge -> midpoint vertex map of the icosphere subdivision: open addressing, linear probing,
 * key (min << 32 | max) + 1 (0 = empty). */
typedef struct vx_mesh_edge_map {
    uint64_t *keys;
    uint32_t *vals;
    size_t mask;
} vx_mesh_edge_map;

static size_t vx_mesh_edge_slot(const vx_mesh_edge_map *m, uint64_t key)
{
    uint64_t h = key * 0x9E3779B97F4A7C15ull; /* Fibonacci hashing */
    size_t i = (size_t)(h ^ (h >> 29)) & m->mask;
    while (m->keys[i] != 0 && m->keys[i] != key) i = (i + 1) & m->mask;
    return i;
}

/* The midpoint vertex of edge (a, b): created (normalised onto the unit sphere) on first use. */
static uint32_t vx_mesh_midpoint(vx_mesh_edge_map *m, double *unit, size_t *nv, uint32_t a,
                                 uint32_t b)
{
    uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
    uint64_t key = (((uint64_t)lo << 32) | hi) + 1u;
    size_t slot = vx_mesh_edge_slot(m, key);
    double p[3], len;
    int k;
    if (m->keys[slot] == key) return m->vals[slot];
    for (k = 0; k < 3; k++) p[k] = 0.5 * (unit[3 * (size_t)a + k] + unit[3 * (size_t)b + k]);
    len = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    for (k = 0; k < 3; k++) unit[3 * *nv + k] = p[k] / len;
    m->keys[slot] = key;
    m->vals[slot] = (uint32_t)*nv;
    return (uint32_t)(*nv)++;
}

/* The base icosahedron (Kahler's widely copied construction, "Creating an icosphere mesh in
 * code", 2009): the 12 vertices (+-1, +-t, 0), (0, +-1, +-t), (+-t, 0, +-1), t = (1 + sqrt 5)/2,
 * in this order, normalised; the 20 faces below (outward, counter-clockwise). */
static const signed char vx_mesh_ico_v[12][3] = {
    {-1, 1, 0}, {1, 1, 0}, {-1, -1, 0}, {1, -1, 0}, /* (+-1, +-t, 0): second entry times t */
    {0, -1, 1}, {0, 1, 1}, {0, -1, -1}, {0, 1, -1}, /* (0, +-1, +-t): third entry times t */
    {1, 0, -1}, {1, 0, 1}, {-1, 0, -1}, {-1, 0, 1}  /* (+-t, 0, +-1): first entry times t */
};
static const unsigned char vx_mesh_ico_f[20][3] = {
    {0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11},
    {1, 5, 9}, {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
    {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8}, {3, 8, 9},
    {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}
};

HFVIS_API hfvis_status hfvis_mesh_icosphere(const hfvis_allocator *alloc, const double c[3],
                                            double r, int subdivisions, hfvis_mesh *out)
{
    vx_mesh_builder b;
    vx_mesh_edge_map em;
    hfvis_status s;
    double *unit;
    size_t nv, nt, ntl, v, t, cap, k;
    const double tau = (1.0 + sqrt(5.0)) / 2.0;
    int level;
    if (!out || !vx_mesh_point_ok(c) || !vx_mesh_coord_ok(r) || !(r > 0.0) || subdivisions < 0
        || subdivisions > HFVIS_MESH_ICOSPHERE_MAX_SUBDIVISIONS)
        return HFVIS_ERR_INVALID_ARGUMENT;
    nt = (size_t)20 << (2 * subdivisions);   /* 20 * 4^s */
    nv = (size_t)10 * ((size_t)1 << (2 * subdivisions)) + 2; /* Euler: V = T/2 + 2 */
    /* the largest level's edge map: E = 3T/2 edges of the previous level, load <= 1/2 */
    cap = 64;
    while (cap < 3 * nt / 4) cap *= 2; /* 2 * (3/2) * (T/4) */
    em.mask = cap - 1;
    s = vx_mesh_builder_init(&b, alloc, nv, nt);
    if (s != HFVIS_OK) return s;
    unit = (double *)vx_alloc_array(alloc, nv, 3 * sizeof(double));
    em.keys = (uint64_t *)vx_alloc_array(alloc, cap, sizeof(uint64_t));
    em.vals = (uint32_t *)vx_alloc_array(alloc, cap, sizeof(uint32_t));
    if (!unit || !em.keys || !em.vals) {
        vx_free(alloc, em.vals);
        vx_free(alloc, em.keys);
        vx_free(alloc, unit);
        vx_mesh_builder_free(&b, alloc);
        return HFVIS_ERR_OUT_OF_MEMORY;
    }
    for (v = 0; v < 12; v++) {
        double p[3], len;
        p[0] = (double)vx_mesh_ico_v[v][0] * (v >= 8 ? tau : 1.0);
        p[1] = (double)vx_mesh_ico_v[v][1] * (v < 4 ? tau : 1.0);
        p[2] = (double)vx_mesh_ico_v[v][2] * (v >= 4 && v < 8 ? tau : 1.0);
        len = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        for (k = 0; k < 3; k++) unit[3 * v + k] = p[k] / len;
    }
    for (t = 0; t < 20; t++)
        for (k = 0; k < 3; k++) b.idx[3 * t + k] = vx_mesh_ico_f[t][k];
    ntl = 20;
    v = 12;
    for (level = 0; level < subdivisions; level++) {
        /* Kahler's order: pass over the faces in order creating the midpoints of (v1,v2),
         * (v2,v3), (v3,v1) on first use, then every face (v1,v2,v3) becomes (v1,a,c),
         * (v2,b,a), (v3,c,b), (a,b,c) at 4t..4t+3 (expanded from the last face down, in place:
         * face t is read before slots 4t.. are written, and faces < t sit below 4t). */
        memset(em.keys, 0, cap * sizeof(uint64_t));
        for (t = 0; t < ntl; t++) {
            const uint32_t *f = b.idx + 3 * t;
            vx_mesh_midpoint(&em, unit, &v, f[0], f[1]);
            vx_mesh_midpoint(&em, unit, &v, f[1], f[2]);
            vx_mesh_midpoint(&em, unit, &v, f[2], f[0]);
        }
        for (t = ntl; t-- > 0;) {
            uint32_t v1 = b.idx[3 * t], v2 = b.idx[3 * t + 1], v3 = b.idx[3 * t + 2];
            uint32_t ma = vx_mesh_midpoint(&em, unit, &v, v1, v2);
            uint32_t mb = vx_mesh_midpoint(&em, unit, &v, v2, v3);
            uint32_t mc = vx_mesh_midpoint(&em, unit, &v, v3, v1);
            uint32_t *o = b.idx + 12 * t;
            o[0] = v1; o[1] = ma; o[2] = mc;
            o[3] = v2; o[4] = mb; o[5] = ma;
            o[6] = v3; o[7] = mc; o[8] = mb;
            o[9] = ma; o[10] = mb; o[11] = mc;
        }
        ntl *= 4;
    }
    HFVIS_ASSERT(v == nv && ntl == nt);
    for (v = 0; v < nv; v++)
        vx_mesh_v(&b, c[0] + r * unit[3 * v], c[1] + r * unit[3 * v + 1], c[2] + r * unit[3 * v + 2]);
    b.nt = nt;
    vx_free(alloc, em.vals);
    vx_free(alloc, em.keys);
    vx_free(alloc, unit);
    return vx_mesh_builder_finish(&b, alloc, out);
}

/* A closed tube around a periodic frame: ring i (0..n-1) at centre C_i with unit radial axes
 * N_i, B_i and radius rad_i; vertex (i, j) = C_i + rad_i (cos v_j N_i + sin v_j B_i),
 * v_j = 2 pi j / m, j fastest. Triangles (a, b, d), (a, d, c) with a = (i, j), b = (i+1, j),
 * c = (i, j+1), d = (i+1, j+1), indices mod (n, m): outward when T_i x B_i points along N_i
 * (T = direction of increasing i). The torus and the torus knot are this with periodic i. */
static void vx_mesh_tube_tris(vx_mesh_builder *b, size_t base, size_t n, size_t m, int periodic)
{
    size_t i, j;
    for (i = 0; i + (periodic ? 0u : 1u) < n; i++) {
        size_t i1 = (i + 1) % n;
        for (j = 0; j < m; j++) {
            size_t j1 = (j + 1) % m;
            vx_mesh_t(b, base + i * m + j, base + i1 * m + j, base + i1 * m + j1);
            vx_mesh_t(b, base + i * m + j, base + i1 * m + j1, base + i * m + j1);
        }
    }
}

HFVIS_API hfvis_status hfvis_mesh_torus(const hfvis_allocator *alloc, const double c[3],
                                        double R, double r, int major, int minor, hfvis_mesh *out)
{
    vx_mesh_builder b;
    hfvis_status s;
    size_t i, j, n, m, nv, nt;
    if (!out || !vx_mesh_point_ok(c) || !vx_mesh_coord_ok(R) || !vx_mesh_coord_ok(r)
        || !(r > 0.0) || !(r < R) || major < 3 || minor < 3)
        return HFVIS_ERR_INVALID_ARGUMENT;
    n = (size_t)major;
    m = (size_t)minor;
    nv = vx_mesh_mul(n, m);
    nt = vx_mesh_mul(nv, 2);
    s = vx_mesh_builder_init(&b, alloc, nv, nt);
    if (s != HFVIS_OK) return s;
    for (i = 0; i < n; i++) {
        double u = 2.0 * VX_MESH_PI * (double)i / (double)n, cu = cos(u), su = sin(u);
        for (j = 0; j < m; j++) {
            double w = 2.0 * VX_MESH_PI * (double)j / (double)m;
            double rho = R + r * cos(w);
            vx_mesh_v(&b, c[0] + rho * cu, c[1] + rho * su, c[2] + r * sin(w));
        }
    }
    /* T = +phi direction, N = radial (outward), B = +z at v = 0: T x B = N (outward). */
    vx_mesh_tube_tris(&b, 0, n, m, 1);
    return vx_mesh_builder_finish(&b, alloc, out);
}

static int vx_mesh_gcd(int a, int b)
{
    while (b != 0) {
        int t = a % b;
        a = b;
        b = t;
    }
    return a;
}

HFVIS_API hfvis_status hfvis_mesh_torus_knot(const hfvis_allocator *alloc, const double c[3],
                                             double scale, int p, int q, int segments, int sides,
                                             hfvis_mesh *out)
{
    vx_mesh_builder b;
    hfvis_status s;
    size_t i, j, n, m, nv, nt;
    const double R = scale * HFVIS_TORUS_KNOT_MAJOR, a = scale * HFVIS_TORUS_KNOT_MINOR;
    const double tube = scale * HFVIS_TORUS_KNOT_TUBE;
    if (!out || !vx_mesh_point_ok(c) || !vx_mesh_coord_ok(scale) || !(scale > 0.0) || p < 1
        || q < 1 || vx_mesh_gcd(p, q) != 1 || segments < 3 || sides < 3)
        return HFVIS_ERR_INVALID_ARGUMENT;
    n = (size_t)segments;
    m = (size_t)sides;
    nv = vx_mesh_mul(n, m);
    nt = vx_mesh_mul(nv, 2);
    s = vx_mesh_builder_init(&b, alloc, nv, nt);
    if (s != HFVIS_OK) return s;
    for (i = 0; i < n; i++) {
        /* centre line C(t) = ((R + a cos qt) cos pt, (R + a cos qt) sin pt, a sin qt) and its
         * derivative T; frame N = the part of C orthogonal to T (C is never parallel to T on
         * these knots), B = N x T (unit): T x B = N, so the ring pattern is outward. */
        double t = 2.0 * VX_MESH_PI * (double)i / (double)n;
        double cp = cos((double)p * t), sp = sin((double)p * t);
        double cq = cos((double)q * t), sq = sin((double)q * t);
        double rho = R + a * cq, C[3], T[3], N[3], B[3], len, d;
        int k;
        C[0] = rho * cp;
        C[1] = rho * sp;
        C[2] = a * sq;
        T[0] = -a * (double)q * sq * cp - rho * (double)p * sp;
        T[1] = -a * (double)q * sq * sp + rho * (double)p * cp;
        T[2] = a * (double)q * cq;
        len = sqrt(T[0] * T[0] + T[1] * T[1] + T[2] * T[2]);
        for (k = 0; k < 3; k++) T[k] /= len;
        d = C[0] * T[0] + C[1] * T[1] + C[2] * T[2];
        for (k = 0; k < 3; k++) N[k] = C[k] - d * T[k];
        len = sqrt(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]);
        for (k = 0; k < 3; k++) N[k] /= len;
        B[0] = N[1] * T[2] - N[2] * T[1];
        B[1] = N[2] * T[0] - N[0] * T[2];
        B[2] = N[0] * T[1] - N[1] * T[0];
        for (j = 0; j < m; j++) {
            double w = 2.0 * VX_MESH_PI * (double)j / (double)m, cw = cos(w), sw = sin(w);
            vx_mesh_v(&b, c[0] + C[0] + tube * (cw * N[0] + sw * B[0]),
                      c[1] + C[1] + tube * (cw * N[1] + sw * B[1]),
                      c[2] + C[2] + tube * (cw * N[2] + sw * B[2]));
        }
    }
    vx_mesh_tube_tris(&b, 0, n, m, 1);
    return vx_mesh_builder_finish(&b, alloc, out);
}

HFVIS_API hfvis_status hfvis_mesh_from_grid(const hfvis_allocator *alloc, const hfvis_grid *g,
                                            hfvis_mesh *out)
{
    vx_mesh_builder b;
    hfvis_status s;
    uint32_t *remap = NULL;
    size_t W, H, x, y, nv = 0, nt = 0, npts;
    if (!out || !g || !g->z || g->width < 1 || g->height < 1 || g->stride < g->width
        || !isfinite(g->cell_size) || !(g->cell_size > 0.0))
        return HFVIS_ERR_INVALID_ARGUMENT;
    W = (size_t)g->width;
    H = (size_t)g->height;
    if (!vx_mesh_coord_ok((double)(W - 1) * g->cell_size)
        || !vx_mesh_coord_ok((double)(H - 1) * g->cell_size)
        || !isfinite((float)((double)(W - 1) * g->cell_size))
        || !isfinite((float)((double)(H - 1) * g->cell_size)))
        return HFVIS_ERR_INVALID_ARGUMENT;
    npts = vx_mesh_mul(W, H);
    if (npts > HFVIS_MESH_MAX_VERTICES) return HFVIS_ERR_LIMIT;
    /* pass 1: triangles kept (all three corners finite) and vertices they use */
    remap = (uint32_t *)vx_alloc_array(alloc, npts, sizeof(uint32_t));
    if (!remap) return HFVIS_ERR_OUT_OF_MEMORY;
    for (x = 0; x < npts; x++) remap[x] = 0;
#define VX_MESH_Z(xx, yy) g->z[(ptrdiff_t)(yy) * g->stride + (ptrdiff_t)(xx)]
#define VX_MESH_OK(xx, yy) isfinite(VX_MESH_Z(xx, yy))
    for (y = 0; y + 1 < H; y++) {
        for (x = 0; x + 1 < W; x++) {
            /* quad a = (x, y), b = (x+1, y), c = (x, y+1), d = (x+1, y+1), split along a-d:
             * triangles (a, b, d) and (a, d, c), normal +z for a flat field */
            int a = VX_MESH_OK(x, y), bb = VX_MESH_OK(x + 1, y), cc = VX_MESH_OK(x, y + 1);
            int d = VX_MESH_OK(x + 1, y + 1);
            if (a && bb && d) {
                remap[y * W + x] = remap[y * W + x + 1] = remap[(y + 1) * W + x + 1] = 1;
                nt++;
            }
            if (a && d && cc) {
                remap[y * W + x] = remap[(y + 1) * W + x + 1] = remap[(y + 1) * W + x] = 1;
                nt++;
            }
        }
    }
    for (x = 0; x < npts; x++)
        if (remap[x]) remap[x] = (uint32_t)nv++;
        else remap[x] = UINT32_MAX;
    if (nt > HFVIS_MESH_MAX_TRIANGLES) {
        vx_free(alloc, remap);
        return HFVIS_ERR_LIMIT;
    }
    s = vx_mesh_builder_init(&b, alloc, nv, nt);
    if (s != HFVIS_OK) {
        vx_free(alloc, remap);
        return s;
    }
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++)
            if (remap[y * W + x] != UINT32_MAX)
                vx_mesh_v(&b, (double)x * g->cell_size, (double)y * g->cell_size,
                          (double)VX_MESH_Z(x, y));
    for (y = 0; y + 1 < H; y++) {
        for (x = 0; x + 1 < W; x++) {
            uint32_t a = remap[y * W + x], bb = remap[y * W + x + 1];
            uint32_t cc = remap[(y + 1) * W + x], d = remap[(y + 1) * W + x + 1];
            int fa = VX_MESH_OK(x, y), fb = VX_MESH_OK(x + 1, y), fc = VX_MESH_OK(x, y + 1);
            int fd = VX_MESH_OK(x + 1, y + 1);
            if (fa && fb && fd) vx_mesh_t(&b, a, bb, d);
            if (fa && fd && fc) vx_mesh_t(&b, a, d, cc);
        }
    }
#undef VX_MESH_OK
#undef VX_MESH_Z
    vx_free(alloc, remap);
    return vx_mesh_builder_finish(&b, alloc, out);
}

/* Box (corner k as in vx_mesh_box_tris) rotated by angle about the vertical axis through its
 * centre (cx, cy), from z0 to z1; skip_face 0..5 (-x +x -y +y -z +z) is left out, -1 none;
 * inward != 0 reverses every triangle (faces looking into the box). */
static void vx_mesh_room_box(vx_mesh_builder *b, double cx, double cy, double hx, double hy,
                             double z0, double z1, double angle, int skip_face, int inward)
{
    size_t base = b->nv;
    double ca = cos(angle), sa = sin(angle);
    int k;
    for (k = 0; k < 8; k++) {
        double lx = (k & 1) ? hx : -hx, ly = (k & 2) ? hy : -hy;
        vx_mesh_v(b, angle == 0.0 ? cx + lx : cx + ca * lx - sa * ly,
                  angle == 0.0 ? cy + ly : cy + sa * lx + ca * ly, (k & 4) ? z1 : z0);
    }
    for (k = 0; k < 12; k++) {
        if (k / 2 == skip_face) continue;
        if (inward)
            vx_mesh_t(b, base + vx_mesh_box_tris[k][0], base + vx_mesh_box_tris[k][2],
                      base + vx_mesh_box_tris[k][1]);
        else
            vx_mesh_t(b, base + vx_mesh_box_tris[k][0], base + vx_mesh_box_tris[k][1],
                      base + vx_mesh_box_tris[k][2]);
    }
}

HFVIS_API hfvis_status hfvis_mesh_room(const hfvis_allocator *alloc, hfvis_mesh *out)
{
    vx_mesh_builder b;
    hfvis_status s;
    const double deg17 = 17.0 * VX_MESH_PI / 180.0;
    if (!out) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_mesh_builder_init(&b, alloc, 24, 30);
    if (s != HFVIS_OK) return s;
    /* walls: the unit cube seen from inside, open at y = 0 (face -y) */
    vx_mesh_room_box(&b, 0.5, 0.5, 0.5, 0.5, 0.0, 1.0, 0.0, 2, 1);
    /* short box 0.3 x 0.3 x 0.3 at (0.66, 0.33), rotated -17 deg; tall box 0.3 x 0.3 x 0.6 at
     * (0.34, 0.62), rotated +17 deg; both standing on the floor, without bottom faces */
    vx_mesh_room_box(&b, 0.66, 0.33, 0.15, 0.15, 0.0, 0.3, -deg17, 4, 0);
    vx_mesh_room_box(&b, 0.34, 0.62, 0.15, 0.15, 0.0, 0.6, deg17, 4, 0);
    return vx_mesh_builder_finish(&b, alloc, out);
}

/* Uniform Catmull-Rom through pts[0..count) (2 doubles each), at parameter s in [0, count-1],
 * end tangents from the doubled end points. */
static void vx_mesh_catmull(const double (*pts)[2], int count, double s, double out[2])
{
    int i = (int)floor(s), k;
    double u, u2, u3;
    if (i > count - 2) i = count - 2;
    if (i < 0) i = 0;
    u = s - (double)i;
    u2 = u * u;
    u3 = u2 * u;
    for (k = 0; k < 2; k++) {
        double p0 = pts[i > 0 ? i - 1 : 0][k], p1 = pts[i][k], p2 = pts[i + 1][k];
        double p3 = pts[i + 2 < count ? i + 2 : count - 1][k];
        out[k] = 0.5 * (2.0 * p1 + (-p0 + p2) * u + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * u2
                        + (-p0 + 3.0 * p1 - 3.0 * p2 + p3) * u3);
    }
}

/* Teapot profile (rho, z), top pole to bottom pole, body + lid + knob in one closed surface. */
static const double vx_mesh_teapot_profile[][2] = {
    {0.00, 1.42}, {0.13, 1.40}, {0.14, 1.32}, {0.08, 1.25}, {0.20, 1.15}, {0.45, 1.09},
    {0.62, 1.03}, {0.66, 1.00}, {0.80, 0.92}, {0.95, 0.72}, {1.00, 0.48}, {0.94, 0.22},
    {0.80, 0.06}, {0.70, 0.00}, {0.35, 0.00}, {0.00, 0.00}
};
#define VX_MESH_TEAPOT_PROFILE_N ((int)(sizeof vx_mesh_teapot_profile / sizeof vx_mesh_teapot_profile[0]))

/* Point and tangent of the teapot's spout (which = 0, quadratic Bezier) or handle (1, cubic
 * Bezier) centre line in the y = 0 plane at s in [0, 1]; radius of the tube there. */
static void vx_mesh_teapot_curve(int which, double s, double P[3], double T[3], double *rad)
{
    static const double spout[3][2] = {{0.55, 0.30}, {1.45, 0.35}, {1.60, 1.05}};
    static const double handle[4][2] = {{-0.70, 0.88}, {-1.65, 1.00}, {-1.60, 0.18}, {-0.72, 0.30}};
    double u = 1.0 - s;
    int k;
    for (k = 0; k < 2; k++) {
        double pos, der;
        if (which == 0) {
            pos = u * u * spout[0][k] + 2.0 * u * s * spout[1][k] + s * s * spout[2][k];
            der = 2.0 * u * (spout[1][k] - spout[0][k]) + 2.0 * s * (spout[2][k] - spout[1][k]);
        } else {
            pos = u * u * u * handle[0][k] + 3.0 * u * u * s * handle[1][k]
                  + 3.0 * u * s * s * handle[2][k] + s * s * s * handle[3][k];
            der = 3.0 * u * u * (handle[1][k] - handle[0][k])
                  + 6.0 * u * s * (handle[2][k] - handle[1][k])
                  + 3.0 * s * s * (handle[3][k] - handle[2][k]);
        }
        P[2 * k] = pos; /* k = 0 -> x, k = 1 -> z */
        T[2 * k] = der;
    }
    P[1] = 0.0;
    T[1] = 0.0;
    *rad = which == 0 ? 0.17 - 0.09 * s : 0.075;
}

HFVIS_API hfvis_status hfvis_mesh_teapot(const hfvis_allocator *alloc, int n, hfvis_mesh *out)
{
    vx_mesh_builder b;
    hfvis_status s;
    double *prof, zero[3] = {0.0, 0.0, 0.0};
    size_t nn, slices, m, along, around, nv, nt, i, j, tube_v, tube_t;
    int which;
    if (!out || n < 1) return HFVIS_ERR_INVALID_ARGUMENT;
    if (n > 4096) return HFVIS_ERR_LIMIT; /* past the vertex limit already */
    nn = (size_t)n;
    slices = 12 * nn;
    m = 8 * nn;
    along = 8 * nn + 1; /* rings along each tube */
    around = 6 * nn;
    tube_v = vx_mesh_mul(along, around);
    tube_t = vx_mesh_mul(2 * (along - 1), around);
    nv = vx_mesh_add(vx_mesh_add(vx_mesh_mul(m - 1, slices), 2), vx_mesh_mul(2, tube_v));
    nt = vx_mesh_add(vx_mesh_mul(2 * slices, m - 1), vx_mesh_mul(2, tube_t));
    if (nv > HFVIS_MESH_MAX_VERTICES || nt > HFVIS_MESH_MAX_TRIANGLES) return HFVIS_ERR_LIMIT;
    prof = (double *)vx_alloc_array(alloc, m + 1, 2 * sizeof(double));
    if (!prof) return HFVIS_ERR_OUT_OF_MEMORY;
    for (i = 0; i <= m; i++) {
        double pt[2];
        vx_mesh_catmull(vx_mesh_teapot_profile, VX_MESH_TEAPOT_PROFILE_N,
                        (double)(VX_MESH_TEAPOT_PROFILE_N - 1) * (double)i / (double)m, pt);
        prof[i] = (i == 0 || i == m) ? 0.0 : fabs(pt[0]);
        prof[m + 1 + i] = pt[1] > 0.0 ? pt[1] : 0.0; /* the spline dips below the flat base */
    }
    s = vx_mesh_builder_init(&b, alloc, nv, nt);
    if (s != HFVIS_OK) {
        vx_free(alloc, prof);
        return s;
    }
    vx_mesh_revolve(&b, zero, prof, prof + m + 1, m, slices);
    vx_free(alloc, prof);
    for (which = 0; which < 2; which++) {
        size_t base = b.nv;
        for (i = 0; i < along; i++) {
            double P[3], T[3], N[3], rad, len;
            const double Bv[3] = {0.0, 1.0, 0.0};
            vx_mesh_teapot_curve(which, (double)i / (double)(along - 1), P, T, &rad);
            len = sqrt(T[0] * T[0] + T[2] * T[2]);
            T[0] /= len;
            T[2] /= len;
            /* N = T x B with B = +y: T x B = N (outward ring pattern) */
            N[0] = -T[2];
            N[1] = 0.0;
            N[2] = T[0];
            for (j = 0; j < around; j++) {
                double w = 2.0 * VX_MESH_PI * (double)j / (double)around, cw = cos(w), sw = sin(w);
                vx_mesh_v(&b, P[0] + rad * (cw * N[0] + sw * Bv[0]), rad * sw * Bv[1],
                          P[2] + rad * (cw * N[2] + sw * Bv[2]));
            }
        }
        vx_mesh_tube_tris(&b, base, along, around, 0);
    }
    return vx_mesh_builder_finish(&b, alloc, out);
}

/* ---- 1c. bounds ------------------------------------------------------------------------- */

HFVIS_API hfvis_status hfvis_mesh_bounds(const hfvis_mesh *mesh, double lo[3], double hi[3])
{
    double l[3], h[3];
    size_t v;
    int k;
    if (!lo || !hi || vx_mesh_check(mesh) != HFVIS_OK || mesh->vertex_count == 0)
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (k = 0; k < 3; k++) l[k] = h[k] = (double)mesh->xyz[k];
    for (v = 1; v < mesh->vertex_count; v++) {
        for (k = 0; k < 3; k++) {
            double c = (double)mesh->xyz[3 * v + (size_t)k];
            if (c < l[k]) l[k] = c;
            if (c > h[k]) h[k] = c;
        }
    }
    for (k = 0; k < 3; k++) {
        lo[k] = l[k];
        hi[k] = h[k];
    }
    return HFVIS_OK;
}

/* ---- 1d. OBJ decoder -------------------------------------------------------------------- */
/* Wavefront OBJ subset (DESIGN §4): `v x y z [w | r g b ...]` and `f` lines; every other
 * statement is ignored. Two passes over the bytes with the same parser: pass 1 validates and
 * counts, pass 2 fills arrays of exactly the counted sizes (forward vertex references are
 * range-checked there). */

/* 10^0 .. 10^22: exact in double. */
static const double vx_mesh_obj_pow10[23] = {
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11,
    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22
};

/* d * 10^e, |e| small (<= ~70 here): steps of exact powers, multiplying for e > 0 and dividing
 * for e < 0, so each step rounds once (<= 4 steps: within 2 ulp of double in all). */
static double vx_mesh_obj_scale10(double d, long e)
{
    while (e > 22) {
        d *= 1e22;
        e -= 22;
    }
    while (e < -22) {
        d /= 1e22;
        e += 22;
    }
    return e >= 0 ? d * vx_mesh_obj_pow10[e] : d / vx_mesh_obj_pow10[-e];
}

static int vx_mesh_obj_digit(unsigned char c) { return c >= '0' && c <= '9'; }

/* Parse the whole token [s, e) as a decimal number, locale-independently:
 * [+-] (digits [. digits*] | . digits) [(e|E) [+-] digits]. No inf/nan/hex. The first 19
 * significant digits are kept exactly (later ones are dropped), the value is mant * 10^exp in
 * double (within 3 ulp of double), then rounded once to float. Returns 0 for a malformed token
 * or a value outside the float range (|v| rounds to infinity); values below the smallest
 * subnormal become (signed) zero. */
static int vx_mesh_obj_parse_float(const unsigned char *s, const unsigned char *e, float *out)
{
    uint64_t mant = 0;
    long long dexp = 0, ex = 0, e10;
    int neg = 0, eneg = 0, nd = 0, any = 0;
    double d;
    float f;
    if (s < e && (*s == '+' || *s == '-')) neg = *s++ == '-';
    for (; s < e && vx_mesh_obj_digit(*s); s++) {
        any = 1;
        if (mant == 0 && *s == '0') continue; /* leading zero */
        if (nd < 19) {
            mant = mant * 10u + (uint64_t)(*s - '0');
            nd++;
        } else {
            dexp++; /* dropped integer digit */
        }
    }
    if (s < e && *s == '.') {
        for (s++; s < e && vx_mesh_obj_digit(*s); s++) {
            any = 1;
            if (mant == 0 && *s == '0') {
                dexp--;
            } else if (nd < 19) {
                mant = mant * 10u + (uint64_t)(*s - '0');
                nd++;
                dexp--;
            }
        }
    }
    if (!any) return 0;
    if (s < e && (*s == 'e' || *s == 'E')) {
        s++;
        if (s < e && (*s == '+' || *s == '-')) eneg = *s++ == '-';
        if (s >= e || !vx_mesh_obj_digit(*s)) return 0;
        for (; s < e && vx_mesh_obj_digit(*s); s++)
            if (ex < 1000000000000000LL) ex = ex * 10 + (*s - '0');
    }
    if (s != e) return 0;
    if (mant == 0) {
        *out = neg ? -0.0f : 0.0f;
        return 1;
    }
    e10 = dexp + (eneg ? -ex : ex);
    /* mant has nd digits: the value lies in [10^(e10+nd-1), 10^(e10+nd)) */
    if (e10 + nd - 1 > 38) return 0;          /* >= 1e39 > FLT_MAX */
    if (e10 + nd < -46) {                     /* < 1e-46: below half the smallest subnormal */
        *out = neg ? -0.0f : 0.0f;
        return 1;
    }
    d = vx_mesh_obj_scale10((double)mant, (long)e10);
    f = (float)d;
    if (!isfinite(f)) return 0;
    *out = neg ? -f : f;
    return 1;
}

/* One signed, non-zero OBJ index [+-]digits at *s (saturating at 2^40); advances *s. */
static int vx_mesh_obj_parse_index(const unsigned char **sp, const unsigned char *e, long long *out)
{
    const unsigned char *s = *sp;
    long long v = 0;
    int neg = 0;
    if (s < e && (*s == '+' || *s == '-')) neg = *s++ == '-';
    if (s >= e || !vx_mesh_obj_digit(*s)) return 0;
    for (; s < e && vx_mesh_obj_digit(*s); s++)
        if (v < (1LL << 40)) v = v * 10 + (*s - '0');
    if (v == 0) return 0;
    *out = neg ? -v : v;
    *sp = s;
    return 1;
}

static int vx_mesh_obj_space(unsigned char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f'; }

typedef struct vx_mesh_obj_pass {
    int fill;          /* 0: validate and count; 1: write */
    size_t nv, nt;     /* vertices / triangles so far */
    size_t total_v;    /* pass 2: the vertex count of pass 1 */
    float *xyz;
    uint32_t *idx;
} vx_mesh_obj_pass;

/* A face vertex token: i, i/t, i//n or i/t/n (t, n checked for syntax only: they are not
 * used). Resolves i to a 0-based vertex (negative = relative to the vertices read so far). */
static hfvis_status vx_mesh_obj_face_ref(const vx_mesh_obj_pass *ps, const unsigned char *s,
                                    const unsigned char *e, size_t *vout)
{
    long long i, t;
    if (!vx_mesh_obj_parse_index(&s, e, &i)) return HFVIS_ERR_FORMAT;
    if (s < e) {
        if (*s++ != '/') return HFVIS_ERR_FORMAT;
        if (s < e && *s == '/') {
            s++;
            if (!vx_mesh_obj_parse_index(&s, e, &t)) return HFVIS_ERR_FORMAT; /* i//n */
        } else {
            if (!vx_mesh_obj_parse_index(&s, e, &t)) return HFVIS_ERR_FORMAT; /* i/t */
            if (s < e) {
                if (*s++ != '/') return HFVIS_ERR_FORMAT;
                if (!vx_mesh_obj_parse_index(&s, e, &t)) return HFVIS_ERR_FORMAT; /* i/t/n */
            }
        }
        if (s != e) return HFVIS_ERR_FORMAT;
    }
    if (i < 0) {
        if ((unsigned long long)(-i) > (unsigned long long)ps->nv) return HFVIS_ERR_FORMAT;
        *vout = ps->nv - (size_t)(-i);
    } else {
        if ((unsigned long long)i > (unsigned long long)HFVIS_MESH_MAX_VERTICES)
            return HFVIS_ERR_FORMAT; /* beyond any vertex a file may hold */
        if (ps->fill && (size_t)i > ps->total_v) return HFVIS_ERR_FORMAT;
        *vout = (size_t)(i - 1);
    }
    return HFVIS_OK;
}

/* One pass over the whole buffer. Lines end at '\n' or '\r' (so CRLF and CR files work);
 * '#' starts a comment anywhere; tokens are separated by blanks and tabs. */
static hfvis_status vx_mesh_obj_run(vx_mesh_obj_pass *ps, const unsigned char *p, const unsigned char *end)
{
    while (p < end) {
        const unsigned char *le = p, *ce, *q, *ks;
        while (le < end && *le != '\n' && *le != '\r') le++;
        for (ce = p; ce < le && *ce != '#'; ce++) {}
        q = p;
        p = le < end ? le + 1 : le;
        while (q < ce && vx_mesh_obj_space(*q)) q++;
        if (q == ce) continue;
        ks = q;
        while (q < ce && !vx_mesh_obj_space(*q)) q++;
        if (q - ks == 1 && *ks == 'v') {
            float c[3];
            int n = 0;
            for (;;) {
                const unsigned char *ts;
                float f;
                while (q < ce && vx_mesh_obj_space(*q)) q++;
                if (q == ce) break;
                ts = q;
                while (q < ce && !vx_mesh_obj_space(*q)) q++;
                if (!vx_mesh_obj_parse_float(ts, q, &f)) return HFVIS_ERR_FORMAT;
                if (n < 3) c[n] = f;
                n++;
            }
            if (n < 3) return HFVIS_ERR_FORMAT;
            if (ps->nv >= HFVIS_MESH_MAX_VERTICES) return HFVIS_ERR_LIMIT;
            if (ps->fill) memcpy(ps->xyz + 3 * ps->nv, c, sizeof c);
            ps->nv++;
        } else if (q - ks == 1 && *ks == 'f') {
            size_t first = 0, prev = 0, v;
            int n = 0;
            for (;;) {
                const unsigned char *ts;
                hfvis_status s;
                while (q < ce && vx_mesh_obj_space(*q)) q++;
                if (q == ce) break;
                ts = q;
                while (q < ce && !vx_mesh_obj_space(*q)) q++;
                s = vx_mesh_obj_face_ref(ps, ts, q, &v);
                if (s != HFVIS_OK) return s;
                if (n >= 2) { /* fan: (v0, v_{k-1}, v_k) */
                    if (ps->nt >= HFVIS_MESH_MAX_TRIANGLES) return HFVIS_ERR_LIMIT;
                    if (ps->fill) {
                        ps->idx[3 * ps->nt] = (uint32_t)first;
                        ps->idx[3 * ps->nt + 1] = (uint32_t)prev;
                        ps->idx[3 * ps->nt + 2] = (uint32_t)v;
                    }
                    ps->nt++;
                }
                if (n == 0) first = v;
                prev = v;
                n++;
            }
            if (n < 3) return HFVIS_ERR_FORMAT;
        }
        /* any other statement (vt, vn, vp, o, g, s, usemtl, mtllib, l, p, ...) is ignored */
    }
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_obj_decode(const void *data, size_t size,
                                        const hfvis_allocator *alloc, hfvis_mesh *out)
{
    const unsigned char *p = (const unsigned char *)data;
    vx_mesh_obj_pass ps;
    vx_mesh_builder b;
    hfvis_status s;
    if (!out || (!data && size > 0)) return HFVIS_ERR_INVALID_ARGUMENT;
    memset(&ps, 0, sizeof ps);
    s = vx_mesh_obj_run(&ps, p, p + size);
    if (s != HFVIS_OK) return s;
    s = vx_mesh_builder_init(&b, alloc, ps.nv, ps.nt);
    if (s != HFVIS_OK) return s;
    ps.total_v = ps.nv;
    ps.nv = ps.nt = 0;
    ps.fill = 1;
    ps.xyz = b.xyz;
    ps.idx = b.idx;
    s = vx_mesh_obj_run(&ps, p, p + size);
    if (s != HFVIS_OK) {
        vx_mesh_builder_free(&b, alloc);
        return s;
    }
    HFVIS_ASSERT(ps.nv == b.cap_v && ps.nt == b.cap_t);
    b.nv = ps.nv;
    b.nt = ps.nt;
    return vx_mesh_builder_finish(&b, alloc, out);
}

/* ---- 1e. OBJ encoder, file wrappers ----------------------------------------------------- */

#define VX_MESH_OBJ_FLOAT_MAX 16 /* longest number written: "-1.23456789e-38" is 15 */

/* The decimal digits of n (>= 0) into buf; returns the count. */
static size_t vx_mesh_obj_utoa(uint64_t n, char *buf)
{
    char tmp[24];
    size_t k = 0, i;
    do {
        tmp[k++] = (char)('0' + (int)(n % 10u));
        n /= 10u;
    } while (n != 0);
    for (i = 0; i < k; i++) buf[i] = tmp[k - 1 - i];
    return k;
}

/* N (exactly p digits) * 10^(k - p + 1) as the shorter of plain and scientific notation. */
static size_t vx_mesh_obj_layout(int neg, uint64_t N, int p, int k, char *buf)
{
    char dig[12], sci[VX_MESH_OBJ_FLOAT_MAX + 8], fix[64];
    size_t ns = 0, nf = 0;
    int i;
    vx_mesh_obj_utoa(N, dig);
    /* scientific: d[.ddd]e[-]k */
    if (neg) sci[ns++] = '-';
    sci[ns++] = dig[0];
    if (p > 1) {
        sci[ns++] = '.';
        for (i = 1; i < p; i++) sci[ns++] = dig[i];
    }
    sci[ns++] = 'e';
    if (k < 0) sci[ns++] = '-';
    ns += vx_mesh_obj_utoa((uint64_t)(k < 0 ? -k : k), sci + ns);
    /* plain */
    if (neg) fix[nf++] = '-';
    if (k < 0) {
        fix[nf++] = '0';
        fix[nf++] = '.';
        for (i = 0; i < -k - 1; i++) fix[nf++] = '0';
        for (i = 0; i < p; i++) fix[nf++] = dig[i];
    } else {
        for (i = 0; i < p || i <= k; i++) {
            if (i == k + 1) fix[nf++] = '.';
            fix[nf++] = i < p ? dig[i] : '0';
        }
    }
    if (nf <= ns) {
        memcpy(buf, fix, nf);
        return nf;
    }
    memcpy(buf, sci, ns);
    return ns;
}

/* The shortest decimal (1..9 significant digits) that vx_mesh_obj_parse_float reads back as f, bit
 * for bit (9 digits always do: a 9-digit decimal is within 5e-9 relative of f, far from the
 * midpoints to the neighbouring floats, at least 3e-8 relative away). f finite.
 * With X = |f| 10^(8-k) in [10^8, 10^9) (k = the decimal exponent of f), for p = 1, 2, ...:
 * N = round(X / 10^(9-p)) (p digits), accepted when N 10^(9-p) lies inside f's rounding
 * interval [L, H] (the midpoints to the neighbouring floats, exact in double, scaled alike).
 * The test runs in double (X, L, H within 4 ulp); where it is too close to call (within
 * 1e-12 relative) the candidate is parsed back instead, so the answer is exact. */
static size_t vx_mesh_obj_format_float(float f, char *buf)
{
    float af = fabsf(f), fm = nextafterf(af, 0.0f), fp = nextafterf(af, INFINITY);
    double x = (double)af, lo = 0.5 * (x + (double)fm);
    double hi = isfinite(fp) ? 0.5 * (x + (double)fp) : x + 0.5 * (x - (double)fm);
    double X = 0.0, L, H;
    int neg = signbit(f) != 0, p, k, it;
    if (x == 0.0) {
        if (neg) {
            buf[0] = '-';
            buf[1] = '0';
            return 2;
        }
        buf[0] = '0';
        return 1;
    }
    k = (int)floor(log10(x)); /* may be one off: adjust */
    for (it = 0; it < 3; it++) {
        X = vx_mesh_obj_scale10(x, (long)(8 - k));
        if (X >= 1e9) k++;
        else if (X < 1e8) k--;
        else break;
    }
    L = vx_mesh_obj_scale10(lo, (long)(8 - k));
    H = vx_mesh_obj_scale10(hi, (long)(8 - k));
    for (p = 1; p <= 9; p++) {
        double s = vx_mesh_obj_pow10[9 - p], dN = floor(X / s + 0.5), Lp = L / s, Hp = H / s;
        double tol = 1e-12 * vx_mesh_obj_pow10[p];
        uint64_t N = (uint64_t)dN;
        int kk = k;
        size_t n;
        float back;
        if (dN < Lp - tol || dN > Hp + tol) continue; /* certainly outside */
        if (N >= (uint64_t)vx_mesh_obj_pow10[p]) { /* rounded up to 10^p: 1 0..0 one decade up */
            N /= 10u;
            kk++;
        }
        n = vx_mesh_obj_layout(neg, N, p, kk, buf);
        if (dN > Lp + tol && dN < Hp - tol) return n; /* certainly inside */
        if (vx_mesh_obj_parse_float((const unsigned char *)buf, (const unsigned char *)buf + n, &back)
            && memcmp(&back, &f, sizeof f) == 0)
            return n;
    }
    HFVIS_ASSERT(0); /* unreachable: 9 digits always round-trip */
    return vx_mesh_obj_layout(neg, 0, 1, 0, buf);
}

/* Emit (or only count, out == NULL) the encoding; returns the byte count, 0 on overflow. */
static size_t vx_mesh_obj_emit(const hfvis_mesh *m, unsigned char *out)
{
    char line[4 * 24 + 3 * VX_MESH_OBJ_FLOAT_MAX];
    size_t total = 0, i, n;
    int k;
    /* header: "# hfvis mesh: V vertices, T triangles\n" */
    n = 0;
    memcpy(line, "# hfvis mesh: ", 14);
    n = 14;
    n += vx_mesh_obj_utoa((uint64_t)m->vertex_count, line + n);
    memcpy(line + n, " vertices, ", 11);
    n += 11;
    n += vx_mesh_obj_utoa((uint64_t)m->triangle_count, line + n);
    memcpy(line + n, " triangles\n", 11);
    n += 11;
    if (out) memcpy(out, line, n);
    total = n;
    for (i = 0; i < m->vertex_count; i++) {
        line[0] = 'v';
        n = 1;
        for (k = 0; k < 3; k++) {
            line[n++] = ' ';
            n += vx_mesh_obj_format_float(m->xyz[3 * i + (size_t)k], line + n);
        }
        line[n++] = '\n';
        if (total > SIZE_MAX - n) return 0;
        if (out) memcpy(out + total, line, n);
        total += n;
    }
    for (i = 0; i < m->triangle_count; i++) {
        line[0] = 'f';
        n = 1;
        for (k = 0; k < 3; k++) {
            line[n++] = ' ';
            n += vx_mesh_obj_utoa((uint64_t)m->indices[3 * i + (size_t)k] + 1u, line + n);
        }
        line[n++] = '\n';
        if (total > SIZE_MAX - n) return 0;
        if (out) memcpy(out + total, line, n);
        total += n;
    }
    return total;
}

HFVIS_API size_t hfvis_obj_encode_size(const hfvis_mesh *mesh)
{
    if (vx_mesh_check(mesh) != HFVIS_OK) return 0;
    return vx_mesh_obj_emit(mesh, NULL);
}

HFVIS_API hfvis_status hfvis_obj_encode(const hfvis_mesh *mesh, void *out, size_t out_capacity,
                                        size_t *written)
{
    size_t need;
    if (!out || !written || vx_mesh_check(mesh) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    need = vx_mesh_obj_emit(mesh, NULL);
    if (need == 0) return HFVIS_ERR_INVALID_ARGUMENT;
    if (out_capacity < need) return HFVIS_ERR_BUFFER_TOO_SMALL;
    vx_mesh_obj_emit(mesh, (unsigned char *)out);
    *written = need;
    return HFVIS_OK;
}

#ifndef HFVIS_NO_STDIO
HFVIS_API hfvis_status hfvis_mesh_load(const char *path, const hfvis_allocator *alloc,
                                       hfvis_mesh *out)
{
    unsigned char *data = NULL;
    size_t size = 0;
    hfvis_status s;
    if (!path || !out) return HFVIS_ERR_INVALID_ARGUMENT;
    s = hfvis__read_file(path, alloc, &data, &size);
    if (s != HFVIS_OK) return s;
    s = hfvis_obj_decode(data, size, alloc, out);
    vx_free(alloc, data);
    return s;
}

HFVIS_API hfvis_status hfvis_mesh_save(const char *path, const hfvis_mesh *mesh)
{
    size_t need, written = 0;
    unsigned char *buf;
    hfvis_status s;
    if (!path || vx_mesh_check(mesh) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    need = vx_mesh_obj_emit(mesh, NULL);
    if (need == 0) return HFVIS_ERR_INVALID_ARGUMENT;
    buf = (unsigned char *)vx_alloc(NULL, need);
    if (!buf) return HFVIS_ERR_OUT_OF_MEMORY;
    written = vx_mesh_obj_emit(mesh, buf);
    s = hfvis__write_file(path, buf, written);
    vx_free(NULL, buf);
    return s;
}
#endif /* HFVIS_NO_STDIO */


/* ========================================================================================== */
/* Reference rasterizer (issue 4 "mesh infrastructure"; spec voxel §0 view conventions)       */
/* ========================================================================================== */
/* The fixed-function GPU pipeline on the CPU, as the thesis' ch. 7 camera and light views render
 * their depth and G-buffer images ([G12] §7.4.1-7.4.2; Listings 7.1-7.2 read them):
 *   vertex stage   c = proj * view * v (double), eye z kept for the linear depth;
 *   clipping       homogeneous Sutherland-Hodgman (Sutherland & Hodgman 1974) against the near
 *                  plane z = -w, and against guard-band planes only where needed;
 *   setup          snap to 1/256 pixel; orientation by the signed area;
 *   coverage       integer edge functions (Pineda 1988) at pixel centres, D3D top-left rule;
 *   interpolation  homogeneous 2D barycentrics of the unclipped triangle (Olano & Greer 1997,
 *                  "Triangle scan conversion using 2D homogeneous coordinates"):
 *                  for clip-space columns c_j = (x_j, y_j, w_j), r_j = c_{j+1} x c_{j+2},
 *                  a_j(p) = r_j . p / det with p = (x_ndc, y_ndc, 1) and det = r_0 . c_0;
 *                  b_j = a_j / sum a (perspective-correct), z_ndc = sum a_j z_j (affine in
 *                  screen space);
 *   depth test     LESS on zw = (z_ndc + 1)/2 in double, triangles in index order.
 * The oracle (hfvis_rasterize_reference) shoots a ray per pixel centre instead. */

#define VX_RASTER_SUB 256      /* 1 << HFVIS_RASTER_SUBPIXEL_BITS */
#define VX_RASTER_MAX_POLY 9   /* 3 vertices + at most one per clip plane (5 planes) */

/* Per-triangle interpolation setup shared by every fragment of the triangle. */
typedef struct vx_raster_tri {
    double r[9];        /* r_j = rows 3j..3j+2: a_j = (r_j . (px, py, 1)) / det */
    double zp[3];       /* z_ndc = zp . (px, py, 1) */
    double ze[3];       /* eye-space z of the three vertices */
    float normal[3];    /* normal output of this triangle */
    uint32_t id;
} vx_raster_tri;

/* Everything a fragment writes to. */
typedef struct vx_raster_ctx {
    const hfvis_raster_outputs *out;
    double *zbuf;         /* width*height, +INF = empty */
    const double *ndc_x;  /* NDC x of the pixel centres of each column */
    const double *ndc_y;  /* NDC y of each row */
    int width, height;
    int want_attr;        /* linear depth, normal or barycentrics requested */
} vx_raster_ctx;

/* NDC of pixel centres (hfvis_view): x_ndc = 2(x + 0.5)/width - 1, y_ndc = 1 - 2(y + 0.5)/height.
 * Shared by the rasterizer and its oracle. */
static double vx_raster_ndc_x(int x, int width)
{
    return 2.0 * ((double)x + 0.5) / (double)width - 1.0;
}
static double vx_raster_ndc_y(int y, int height)
{
    return 1.0 - 2.0 * ((double)y + 0.5) / (double)height;
}

HFVIS_API hfvis_raster_options hfvis_raster_options_default(void)
{
    hfvis_raster_options o;
    memset(&o, 0, sizeof o);
    o.alloc = NULL;
    o.cull = HFVIS_CULL_NONE;
    o.normal_space = HFVIS_NORMAL_WORLD;
    o.normal_toward_viewer = 0;
    return o;
}

/* Argument checks common to both rasterizers; *opt receives the resolved options. */
static hfvis_status vx_raster_check(const hfvis_mesh *mesh, const hfvis_view *view,
                                    const hfvis_raster_options *opts,
                                    const hfvis_raster_outputs *out, hfvis_raster_options *opt)
{
    size_t pixels;
    if (!mesh || !view || !out) return HFVIS_ERR_INVALID_ARGUMENT;
    if (mesh->triangle_count >= (size_t)HFVIS_NO_TRIANGLE) return HFVIS_ERR_LIMIT; /* ids */
    if (vx_mesh_check(mesh) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    *opt = opts ? *opts : hfvis_raster_options_default();
    if (opt->cull != HFVIS_CULL_NONE && opt->cull != HFVIS_CULL_BACK
        && opt->cull != HFVIS_CULL_FRONT)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (opt->normal_space != HFVIS_NORMAL_WORLD && opt->normal_space != HFVIS_NORMAL_EYE)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (opt->normal_toward_viewer != 0 && opt->normal_toward_viewer != 1)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (view->width < 1 || view->height < 1) return HFVIS_ERR_INVALID_ARGUMENT;
    if (!vx_all_finite(view->view, 16) || !vx_all_finite(view->proj, 16))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (!isfinite(view->near_plane) || !isfinite(view->far_plane)
        || !(view->near_plane < view->far_plane)
        || (!view->orthographic && !(view->near_plane > 0.0)))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (view->width > HFVIS_RASTER_MAX_SIZE || view->height > HFVIS_RASTER_MAX_SIZE)
        return HFVIS_ERR_LIMIT;
    if (!vx_mul_size((size_t)view->width, (size_t)view->height, &pixels))
        return HFVIS_ERR_LIMIT; /* cannot happen with the size limit; kept for the invariant */
    return HFVIS_OK;
}

/* Fill every requested plane with the empty values. */
static void vx_raster_clear(const hfvis_raster_outputs *out, size_t pixels)
{
    size_t i;
    if (out->linear_depth)
        for (i = 0; i < pixels; i++) out->linear_depth[i] = (float)HUGE_VAL;
    if (out->window_depth)
        for (i = 0; i < pixels; i++) out->window_depth[i] = 1.0f;
    if (out->triangle_id)
        for (i = 0; i < pixels; i++) out->triangle_id[i] = HFVIS_NO_TRIANGLE;
    if (out->coverage_count) memset(out->coverage_count, 0, pixels * sizeof(uint32_t));
    if (out->normal) memset(out->normal, 0, 3 * pixels * sizeof(float));
    if (out->barycentric) memset(out->barycentric, 0, 2 * pixels * sizeof(float));
}

/* The normal output of triangle (a, b, c) (world coordinates): normalize((b-a) x (c-a)) in the
 * requested frame, negated when flip. Returns 0 for a zero-area triangle. Shared by both
 * rasterizers, so their normals are bit-identical. */
static int vx_raster_normal(const float *a, const float *b, const float *c, const double view[16],
                            hfvis_normal_space space, int flip, float out[3])
{
    double e1[3], e2[3], n[3], len;
    int i;
    for (i = 0; i < 3; i++) {
        e1[i] = (double)b[i] - (double)a[i];
        e2[i] = (double)c[i] - (double)a[i];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    if (n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0) return 0;
    if (space == HFVIS_NORMAL_EYE) {
        double m[3];
        for (i = 0; i < 3; i++)
            m[i] = VX_M(view, i, 0) * n[0] + VX_M(view, i, 1) * n[1] + VX_M(view, i, 2) * n[2];
        n[0] = m[0], n[1] = m[1], n[2] = m[2];
    }
    len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0.0) || !isfinite(len)) { /* overflow of huge coordinates: rescale */
        double s = fmax(fabs(n[0]), fmax(fabs(n[1]), fabs(n[2])));
        if (!(s > 0.0) || !isfinite(s)) return 0;
        for (i = 0; i < 3; i++) n[i] /= s;
        len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    }
    if (flip) len = -len;
    for (i = 0; i < 3; i++) out[i] = (float)(n[i] / len);
    return 1;
}

/* 1 when triangle (a, b, c) has zero area in world space ((b-a) x (c-a) == 0 exactly, as
 * vx_raster_normal decides it). */
static int vx_raster_degenerate(const float *a, const float *b, const float *c)
{
    double e1[3], e2[3];
    int i;
    for (i = 0; i < 3; i++) {
        e1[i] = (double)b[i] - (double)a[i];
        e2[i] = (double)c[i] - (double)a[i];
    }
    return e1[1] * e2[2] - e1[2] * e2[1] == 0.0 && e1[2] * e2[0] - e1[0] * e2[2] == 0.0
           && e1[0] * e2[1] - e1[1] * e2[0] == 0.0;
}

/* ---- fragments ---------------------------------------------------------------------------- */

/* One covered pixel centre (x, y) of triangle t: depth range, coverage count, depth test LESS,
 * writes. */
static void vx_raster_fragment(const vx_raster_ctx *ctx, const vx_raster_tri *t, int x, int y,
                               double zrow)
{
    const hfvis_raster_outputs *o = ctx->out;
    size_t i = (size_t)y * (size_t)ctx->width + (size_t)x;
    double px = ctx->ndc_x[x];
    double zw = 0.5 * (t->zp[0] * px + zrow) + 0.5; /* zrow = zp[1] * py + zp[2] */
    if (!(zw >= 0.0 && zw <= 1.0)) return; /* beyond the far plane, or before the near plane */
    if (o->coverage_count) o->coverage_count[i]++;
    if (!(zw < ctx->zbuf[i])) return;
    ctx->zbuf[i] = zw;
    if (o->window_depth) o->window_depth[i] = (float)zw;
    if (o->triangle_id) o->triangle_id[i] = t->id;
    if (ctx->want_attr) {
        double py = ctx->ndc_y[y];
        double a0 = t->r[0] * px + t->r[1] * py + t->r[2];
        double a1 = t->r[3] * px + t->r[4] * py + t->r[5];
        double a2 = t->r[6] * px + t->r[7] * py + t->r[8];
        double s = 1.0 / (a0 + a1 + a2), b0 = a0 * s, b1 = a1 * s, b2 = a2 * s;
        if (o->linear_depth)
            o->linear_depth[i] = (float)-(b0 * t->ze[0] + b1 * t->ze[1] + b2 * t->ze[2]);
        if (o->barycentric) {
            o->barycentric[2 * i] = (float)b1;
            o->barycentric[2 * i + 1] = (float)b2;
        }
        if (o->normal) {
            o->normal[3 * i] = t->normal[0];
            o->normal[3 * i + 1] = t->normal[1];
            o->normal[3 * i + 2] = t->normal[2];
        }
    }
}

/* ---- setup and edge walking --------------------------------------------------------------- */

/* floor(a / b) for b > 0. */
static int64_t vx_raster_floordiv(int64_t a, int64_t b)
{
    int64_t q = a / b;
    if ((a % b) != 0 && (a < 0)) q--;
    return q;
}

/* Rasterize the snapped triangle (X[k], Y[k]) (fixed point, 1/256 pixel, y down) for the
 * interpolation setup t. Exact: all edge functions are int64 (|coordinates| < 2^28). */
static void vx_raster_subtriangle(const vx_raster_ctx *ctx, const vx_raster_tri *t,
                                  const int64_t X[3], const int64_t Y[3])
{
    int64_t x0 = X[0], y0 = Y[0], x1 = X[1], y1 = Y[1], x2 = X[2], y2 = Y[2];
    int64_t area = (x1 - x0) * (y2 - y0) - (y1 - y0) * (x2 - x0);
    int64_t ax[3], ay[3], dx[3], dy[3], F[3], Frow[3], minx, maxx, miny, maxy, cx, cy;
    int64_t xs, xe, ys, ye, xx, yy;
    int k;
    if (area == 0) return;
    if (area < 0) { /* orient so the interior has E > 0: swap v1, v2 */
        int64_t tx = x1, ty = y1;
        x1 = x2, y1 = y2, x2 = tx, y2 = ty;
    }
    /* edge k runs from vertex k+1 to vertex k+2 (opposite vertex k) */
    ax[0] = x1, ay[0] = y1, dx[0] = x2 - x1, dy[0] = y2 - y1;
    ax[1] = x2, ay[1] = y2, dx[1] = x0 - x2, dy[1] = y0 - y2;
    ax[2] = x0, ay[2] = y0, dx[2] = x1 - x0, dy[2] = y1 - y0;
    minx = x0 < x1 ? (x0 < x2 ? x0 : x2) : (x1 < x2 ? x1 : x2);
    maxx = x0 > x1 ? (x0 > x2 ? x0 : x2) : (x1 > x2 ? x1 : x2);
    miny = y0 < y1 ? (y0 < y2 ? y0 : y2) : (y1 < y2 ? y1 : y2);
    maxy = y0 > y1 ? (y0 > y2 ? y0 : y2) : (y1 > y2 ? y1 : y2);
    /* pixel columns whose centre 256 x + 128 lies in [minx, maxx], clamped to the image */
    xs = -vx_raster_floordiv(-(minx - VX_RASTER_SUB / 2), VX_RASTER_SUB);
    xe = vx_raster_floordiv(maxx - VX_RASTER_SUB / 2, VX_RASTER_SUB);
    ys = -vx_raster_floordiv(-(miny - VX_RASTER_SUB / 2), VX_RASTER_SUB);
    ye = vx_raster_floordiv(maxy - VX_RASTER_SUB / 2, VX_RASTER_SUB);
    if (xs < 0) xs = 0;
    if (ys < 0) ys = 0;
    if (xe > ctx->width - 1) xe = ctx->width - 1;
    if (ye > ctx->height - 1) ye = ctx->height - 1;
    if (xs > xe || ys > ye) return;
    cx = xs * VX_RASTER_SUB + VX_RASTER_SUB / 2;
    cy = ys * VX_RASTER_SUB + VX_RASTER_SUB / 2;
    for (k = 0; k < 3; k++) {
        /* E_k(p) = dx (py - ay) - dy (px - ax) > 0 inside. Top-left rule (y down): a centre on
         * edge k is inside iff the edge is left (dy < 0) or top (dy == 0, dx > 0). F = E - 1
         * + topleft, so covered <=> F >= 0 for all three edges. */
        int64_t e = dx[k] * (cy - ay[k]) - dy[k] * (cx - ax[k]);
        int topleft = dy[k] < 0 || (dy[k] == 0 && dx[k] > 0);
        Frow[k] = e - 1 + (topleft ? 1 : 0);
        dx[k] *= VX_RASTER_SUB; /* per-pixel steps */
        dy[k] *= VX_RASTER_SUB;
    }
    for (yy = ys; yy <= ye; yy++) {
        double zrow = t->zp[1] * ctx->ndc_y[yy] + t->zp[2];
        F[0] = Frow[0], F[1] = Frow[1], F[2] = Frow[2];
        for (xx = xs; xx <= xe; xx++) {
            if ((F[0] | F[1] | F[2]) >= 0) vx_raster_fragment(ctx, t, (int)xx, (int)yy, zrow);
            F[0] -= dy[0], F[1] -= dy[1], F[2] -= dy[2];
        }
        Frow[0] += dx[0], Frow[1] += dx[1], Frow[2] += dx[2];
    }
}

/* Signed distance of clip-space point c (x, y, z, w) to clip plane `plane`: >= 0 inside.
 * 0: near z >= -w; 1..4: guard band x <= gx w, x >= -gx w, y <= gy w, y >= -gy w. */
static double vx_raster_plane(const double c[4], int plane, double gx, double gy)
{
    switch (plane) {
    case 0: return c[2] + c[3];
    case 1: return gx * c[3] - c[0];
    case 2: return gx * c[3] + c[0];
    case 3: return gy * c[3] - c[1];
    default: return gy * c[3] + c[1];
    }
}

/* Clip polygon poly[0..n) against one plane (Sutherland-Hodgman) into out; returns the new
 * count. The intersection point of an edge is computed from its inside end toward its outside
 * end, so two triangles sharing the edge get bit-identical points (watertight after clipping). */
static int vx_raster_clip(double (*poly)[4], int n, int plane, double gx, double gy,
                          double (*out)[4])
{
    int i, m = 0, k;
    for (i = 0; i < n; i++) {
        const double *p = poly[i], *q = poly[(i + 1) % n];
        double dp = vx_raster_plane(p, plane, gx, gy), dq = vx_raster_plane(q, plane, gx, gy);
        if (dp >= 0.0) {
            for (k = 0; k < 4; k++) out[m][k] = p[k];
            m++;
        }
        if ((dp >= 0.0) != (dq >= 0.0)) {
            const double *in = dp >= 0.0 ? p : q, *ou = dp >= 0.0 ? q : p;
            double din = dp >= 0.0 ? dp : dq, dout = dp >= 0.0 ? dq : dp;
            double s = din / (din - dout);
            for (k = 0; k < 4; k++) out[m][k] = in[k] + s * (ou[k] - in[k]);
            m++;
        }
    }
    return m;
}

/* Snap a clip-space point to fixed-point window coordinates; 0 if w <= 0 or not finite. */
static int vx_raster_snap(const double c[4], int width, int height, int64_t *X, int64_t *Y)
{
    double fx, fy;
    if (!(c[3] > 0.0)) return 0;
    fx = (c[0] / c[3] + 1.0) * (0.5 * (double)width) * (double)VX_RASTER_SUB;
    fy = (1.0 - c[1] / c[3]) * (0.5 * (double)height) * (double)VX_RASTER_SUB;
    if (!(fabs(fx) < 4.0e8 && fabs(fy) < 4.0e8)) return 0; /* guard band keeps |.| < 2^28 */
    *X = (int64_t)floor(fx + 0.5);
    *Y = (int64_t)floor(fy + 0.5);
    return 1;
}

/* Per-vertex cache: clip x y z w, eye z, and (inside the near plane and the guard band only)
 * the snapped window coordinates as exact doubles, else NaN. */
#define VX_RASTER_VSTRIDE 7

/* One mesh triangle: trivial reject, facing and cull, interpolation setup, clipping, scan. */
static void vx_raster_triangle(const vx_raster_ctx *ctx, const hfvis_mesh *mesh,
                               const hfvis_view *view, const hfvis_raster_options *opt,
                               const double *vcache, uint32_t tid, double gx, double gy)
{
    const uint32_t *ix = mesh->indices + 3 * (size_t)tid;
    const double *c[3];
    double poly[2][VX_RASTER_MAX_POLY][4], det;
    vx_raster_tri t;
    int64_t X[VX_RASTER_MAX_POLY], Y[VX_RASTER_MAX_POLY];
    int j, k, n, cur, plane, outside = 0, facing_front, snapped = 1;
    unsigned codes_and = 0x3F;
    for (j = 0; j < 3; j++) {
        unsigned code = 0;
        c[j] = vcache + VX_RASTER_VSTRIDE * (size_t)ix[j];
        if (c[j][0] > c[j][3]) code |= 1;
        if (c[j][0] < -c[j][3]) code |= 2;
        if (c[j][1] > c[j][3]) code |= 4;
        if (c[j][1] < -c[j][3]) code |= 8;
        if (c[j][2] > c[j][3]) code |= 16;
        if (c[j][2] < -c[j][3]) code |= 32;
        codes_and &= code;
        if (!vx_all_finite(c[j], 5)) return;
        if (!(c[j][5] == c[j][5])) snapped = 0; /* NaN: needs clipping */
    }
    if (codes_and) return; /* all three outside one frustum plane */
    /* homogeneous edge vectors r_j = c_{j+1} x c_{j+2} over (x, y, w) */
    for (j = 0; j < 3; j++) {
        const double *p = c[(j + 1) % 3], *q = c[(j + 2) % 3];
        t.r[3 * j] = p[1] * q[3] - p[3] * q[1];
        t.r[3 * j + 1] = p[3] * q[0] - p[0] * q[3];
        t.r[3 * j + 2] = p[0] * q[1] - p[1] * q[0];
    }
    det = t.r[0] * c[0][0] + t.r[1] * c[0][1] + t.r[2] * c[0][3];
    if (det == 0.0 || !isfinite(det)) return; /* edge-on, or degenerate */
    facing_front = det > 0.0;
    if ((opt->cull == HFVIS_CULL_BACK && !facing_front)
        || (opt->cull == HFVIS_CULL_FRONT && facing_front))
        return;
    {
        const float *v0 = mesh->xyz + 3 * (size_t)ix[0], *v1 = mesh->xyz + 3 * (size_t)ix[1],
                    *v2 = mesh->xyz + 3 * (size_t)ix[2];
        if (ctx->out->normal) {
            if (!vx_raster_normal(v0, v1, v2, view->view, opt->normal_space,
                                  opt->normal_toward_viewer && !facing_front, t.normal))
                return; /* zero area in world space */
        } else if (vx_raster_degenerate(v0, v1, v2)) {
            return;
        }
    }
    for (k = 0; k < 3; k++) {
        t.zp[k] = (t.r[k] * c[0][2] + t.r[3 + k] * c[1][2] + t.r[6 + k] * c[2][2]) / det;
        t.ze[k] = c[k][4];
    }
    t.id = tid;
    if (snapped) { /* fast path: every vertex in front of the near plane, inside the guard band */
        for (j = 0; j < 3; j++) X[j] = (int64_t)c[j][5], Y[j] = (int64_t)c[j][6];
        vx_raster_subtriangle(ctx, &t, X, Y);
        return;
    }
    /* clipping: near plane always checked, guard-band planes only where a vertex leaves them */
    for (j = 0; j < 3; j++)
        for (k = 0; k < 4; k++) poly[0][j][k] = c[j][k];
    n = 3;
    cur = 0;
    for (plane = 0; plane < 5 && n >= 3; plane++) {
        int need = 0;
        for (j = 0; j < n; j++)
            if (!(vx_raster_plane(poly[cur][j], plane, gx, gy) >= 0.0)) need = 1;
        if (!need) continue;
        n = vx_raster_clip(poly[cur], n, plane, gx, gy, poly[1 - cur]);
        cur = 1 - cur;
    }
    if (n < 3) return;
    for (j = 0; j < n; j++)
        if (!vx_raster_snap(poly[cur][j], ctx->width, ctx->height, &X[j], &Y[j])) outside = 1;
    if (outside) return; /* w <= 0 after near clipping: not a GL view (documented) */
    for (j = 1; j + 1 < n; j++) { /* fan (0, j, j+1): inner diagonals are shared exactly */
        int64_t TX[3], TY[3];
        TX[0] = X[0], TY[0] = Y[0], TX[1] = X[j], TY[1] = Y[j], TX[2] = X[j + 1], TY[2] = Y[j + 1];
        vx_raster_subtriangle(ctx, &t, TX, TY);
    }
}

HFVIS_API hfvis_status hfvis_rasterize(const hfvis_mesh *mesh, const hfvis_view *view,
                                       const hfvis_raster_options *opts,
                                       const hfvis_raster_outputs *out)
{
    hfvis_raster_options opt;
    hfvis_status s = vx_raster_check(mesh, view, opts, out, &opt);
    size_t pixels, n_doubles, vcount, i;
    double *block, *vcache, *ndc_x, *ndc_y, gx, gy;
    vx_raster_ctx ctx;
    uint32_t tid;
    if (s != HFVIS_OK) return s;
    if (!out->linear_depth && !out->window_depth && !out->normal && !out->triangle_id
        && !out->barycentric && !out->coverage_count)
        return HFVIS_OK;
    pixels = (size_t)view->width * (size_t)view->height;
    vcount = mesh->vertex_count;
    /* one block: depth buffer, column and row NDC, the vertex cache */
    if (!vx_mul_size(vcount, VX_RASTER_VSTRIDE, &n_doubles) || n_doubles > SIZE_MAX - pixels
        || n_doubles + pixels > SIZE_MAX - (size_t)view->width - (size_t)view->height)
        return HFVIS_ERR_OUT_OF_MEMORY;
    n_doubles += pixels + (size_t)view->width + (size_t)view->height;
    block = (double *)vx_alloc_array(opt.alloc, n_doubles, sizeof(double));
    if (!block) return HFVIS_ERR_OUT_OF_MEMORY;
    ndc_x = block + pixels;
    ndc_y = ndc_x + view->width;
    vcache = ndc_y + view->height;
    /* guard band in NDC: window coordinates within HFVIS_RASTER_GUARD_PIXELS of the centre */
    gx = 2.0 * HFVIS_RASTER_GUARD_PIXELS / (double)view->width;
    gy = 2.0 * HFVIS_RASTER_GUARD_PIXELS / (double)view->height;
    for (i = 0; i < pixels; i++) block[i] = HUGE_VAL;
    for (i = 0; i < (size_t)view->width; i++) ndc_x[i] = vx_raster_ndc_x((int)i, view->width);
    for (i = 0; i < (size_t)view->height; i++) ndc_y[i] = vx_raster_ndc_y((int)i, view->height);
    for (i = 0; i < vcount; i++) {
        double p[4], e[4], *vc = vcache + VX_RASTER_VSTRIDE * i;
        int64_t X, Y;
        int plane, inside = 1;
        p[0] = (double)mesh->xyz[3 * i];
        p[1] = (double)mesh->xyz[3 * i + 1];
        p[2] = (double)mesh->xyz[3 * i + 2];
        p[3] = 1.0;
        vx_mat4_apply(view->view, p, e);
        vx_mat4_apply(view->proj, e, vc);
        vc[4] = e[2];
        for (plane = 0; plane < 5; plane++)
            if (!(vx_raster_plane(vc, plane, gx, gy) >= 0.0)) inside = 0;
        if (inside && vx_raster_snap(vc, view->width, view->height, &X, &Y)) {
            vc[5] = (double)X; /* |X|, |Y| < 2^29: exact */
            vc[6] = (double)Y;
        } else {
            vc[5] = vc[6] = (double)NAN;
        }
    }
    vx_raster_clear(out, pixels);
    ctx.out = out;
    ctx.zbuf = block;
    ctx.ndc_x = ndc_x;
    ctx.ndc_y = ndc_y;
    ctx.width = view->width;
    ctx.height = view->height;
    ctx.want_attr = out->linear_depth || out->normal || out->barycentric;
    for (tid = 0; (size_t)tid < mesh->triangle_count; tid++)
        vx_raster_triangle(&ctx, mesh, view, &opt, vcache, tid, gx, gy);
    vx_free(opt.alloc, block);
    return HFVIS_OK;
}

/* ---- the oracle: one ray per pixel centre ------------------------------------------------- */

HFVIS_API hfvis_status hfvis_rasterize_reference(const hfvis_mesh *mesh, const hfvis_view *view,
                                                 const hfvis_raster_options *opts,
                                                 const hfvis_raster_outputs *out)
{
    hfvis_raster_options opt;
    hfvis_status s = vx_raster_check(mesh, view, opts, out, &opt);
    double pv[16], inv[16];
    size_t pixels, t;
    int x, y;
    if (s != HFVIS_OK) return s;
    hfvis_mat4_multiply(view->proj, view->view, pv);
    if (hfvis_mat4_invert(pv, inv) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    pixels = (size_t)view->width * (size_t)view->height;
    vx_raster_clear(out, pixels);
    for (y = 0; y < view->height; y++) {
        for (x = 0; x < view->width; x++) {
            size_t i = (size_t)y * (size_t)view->width + (size_t)x;
            double ndc[4], hn[4], hf[4], o[3], d[3], best = HUGE_VAL, bb[3] = {0.0, 0.0, 0.0};
            double best_ze = 0.0;
            size_t best_t = (size_t)HFVIS_NO_TRIANGLE;
            int best_front = 1, k;
            uint32_t count = 0;
            ndc[0] = vx_raster_ndc_x(x, view->width);
            ndc[1] = vx_raster_ndc_y(y, view->height);
            ndc[3] = 1.0;
            ndc[2] = -1.0;
            vx_mat4_apply(inv, ndc, hn);
            ndc[2] = 1.0;
            vx_mat4_apply(inv, ndc, hf);
            if (hn[3] == 0.0 || hf[3] == 0.0) continue;
            for (k = 0; k < 3; k++) {
                o[k] = hn[k] / hn[3];
                d[k] = hf[k] / hf[3] - o[k];
            }
            if (!vx_all_finite(o, 3) || !vx_all_finite(d, 3)) continue;
            for (t = 0; t < mesh->triangle_count; t++) {
                const uint32_t *ix = mesh->indices + 3 * t;
                double e[3][3], sv[3], sum, b[3], cc[3][4], zc = 0.0, wc = 0.0, zw, ze = 0.0;
                int j, front;
                for (j = 0; j < 3; j++)
                    for (k = 0; k < 3; k++)
                        e[j][k] = (double)mesh->xyz[3 * (size_t)ix[j] + (size_t)k] - o[k];
                /* sv[j] = d . (e_{j+1} x e_{j+2}): the signed volume opposite vertex j */
                for (j = 0; j < 3; j++) {
                    const double *p = e[(j + 1) % 3], *q = e[(j + 2) % 3];
                    sv[j] = d[0] * (p[1] * q[2] - p[2] * q[1]) + d[1] * (p[2] * q[0] - p[0] * q[2])
                            + d[2] * (p[0] * q[1] - p[1] * q[0]);
                    if (j == 1 && ((sv[0] > 0.0 && sv[1] < 0.0) || (sv[0] < 0.0 && sv[1] > 0.0)))
                        break;
                }
                if (j < 3) continue;
                if (!((sv[0] >= 0.0 && sv[1] >= 0.0 && sv[2] >= 0.0)
                      || (sv[0] <= 0.0 && sv[1] <= 0.0 && sv[2] <= 0.0)))
                    continue;
                sum = sv[0] + sv[1] + sv[2]; /* = d . ((v1 - v0) x (v2 - v0)) */
                if (sum == 0.0 || !isfinite(sum)) continue; /* parallel ray or degenerate */
                front = sum < 0.0;
                if ((opt.cull == HFVIS_CULL_BACK && !front)
                    || (opt.cull == HFVIS_CULL_FRONT && front))
                    continue;
                for (j = 0; j < 3; j++) {
                    double p[4], ev[4];
                    b[j] = sv[j] / sum;
                    for (k = 0; k < 3; k++) p[k] = (double)mesh->xyz[3 * (size_t)ix[j] + (size_t)k];
                    p[3] = 1.0;
                    vx_mat4_apply(view->view, p, ev);
                    vx_mat4_apply(view->proj, ev, cc[j]);
                    zc += b[j] * cc[j][2];
                    wc += b[j] * cc[j][3];
                    ze += b[j] * ev[2];
                }
                if (!(wc > 0.0)) continue;
                zw = 0.5 * (zc / wc) + 0.5;
                if (!(zw >= 0.0 && zw <= 1.0)) continue;
                if (vx_raster_degenerate(mesh->xyz + 3 * (size_t)ix[0],
                                         mesh->xyz + 3 * (size_t)ix[1],
                                         mesh->xyz + 3 * (size_t)ix[2]))
                    continue; /* zero area in world space */
                count++;
                if (zw < best) {
                    best = zw;
                    best_t = t;
                    best_front = front;
                    best_ze = ze;
                    bb[0] = b[0], bb[1] = b[1], bb[2] = b[2];
                }
            }
            if (out->coverage_count) out->coverage_count[i] = count;
            if (best_t == (size_t)HFVIS_NO_TRIANGLE) continue;
            if (out->window_depth) out->window_depth[i] = (float)best;
            if (out->triangle_id) out->triangle_id[i] = (uint32_t)best_t;
            if (out->linear_depth) out->linear_depth[i] = (float)-best_ze;
            if (out->barycentric) {
                out->barycentric[2 * i] = (float)bb[1];
                out->barycentric[2 * i + 1] = (float)bb[2];
            }
            if (out->normal) {
                const uint32_t *ix = mesh->indices + 3 * best_t;
                vx_raster_normal(mesh->xyz + 3 * (size_t)ix[0], mesh->xyz + 3 * (size_t)ix[1],
                                 mesh->xyz + 3 * (size_t)ix[2], view->view, opt.normal_space,
                                 opt.normal_toward_viewer && !best_front, out->normal + 3 * i);
            }
        }
    }
    return HFVIS_OK;
}
