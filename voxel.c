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
