/* voxel.c - meshes and volumes. Part of hfvis (see hfvis.h for the conventions and the API).
 *
 * Contents
 *   1. Common: mesh and grid validation (allocation, checked sizes, the PRNGs and file reading
 *      are hfvis.c's hfvis__ helpers)
 *   2. Views: GL-convention matrices, depth linearisation (thesis eq. 16, sign restored)
 *   3. Volume grids and the Volume Buffer ([G12] §6.3)
 *   4. Meshes: analytic test meshes (box, spheres, torus, torus knot, height field, room,
 *      teapot) and the Wavefront OBJ codec
 *   5. Reference rasterizer: fixed-point top-left coverage, near clipping, ray-per-pixel oracle
 *   6. BVH and ray casting: binned SAH, watertight ray-triangle test (Woop, Benthin & Wald
 *      2013), closest/any hit, naive oracles
 *   7. Surface voxelization into the Volume Buffer ([G12] ch. 6 Alg. 5-6, ch. 5 Alg. 4)
 *   8. Binary voxelizers: conservative (Akenine-Moller SAT; Schwarz & Seidel 2010), solid
 *      (parity), bitmask (Eisemann & Decoret); .binvox and raw
 *   9. Incremental image-based voxelization ([G12] ch. 7 Alg. 7, eq. 16-17, Table 9)
 *  10. 4D visibility fields: positional and directional samples, build by ray casting, queries,
 *      AO, soft shadows and reflections for several objects, the .hfvf codec ([G12] ch. 4)
 *  11. Volume-based VPL indirect light: 2-band SH, injection, occlusion-aware propagation,
 *      gather, direct light, the whole pipeline for a view ([G12] ch. 5)
 *
 * Paper references: [G12] A. Gaitatzes, "Interactive diffuse global illumination discretization
 * methods for dynamic environments", PhD thesis, Univ. of Cyprus, 2012. Errata and choices:
 * docs/errata.md E54-E66.
 */
#define HFVIS__INTERNAL /* the internal block of hfvis.h: shared helpers, not API */
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

/* Marks internal helpers that a given build may leave unused (-Wunused-function). */
#if defined(__GNUC__)
#define VX_MAYBE_UNUSED __attribute__((unused))
#else
#define VX_MAYBE_UNUSED
#endif

/* ========================================================================================== */
/* 1. Common                                                                                  */
/* ========================================================================================== */

/* HFVIS_OK when the mesh is usable (hfvis_mesh: indices < vertex_count, finite coordinates),
 * else HFVIS_ERR_INVALID_ARGUMENT. O(V + T). */
hfvis_status hfvis__mesh_check(const hfvis_mesh *m)
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
        if (!hfvis__mul_size(n, (size_t)g->dims[a], &n)) return 0;
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
    hfvis__free(alloc, (void *)(uintptr_t)mesh->xyz);
    hfvis__free(alloc, (void *)(uintptr_t)mesh->indices);
    memset(mesh, 0, sizeof *mesh);
}

/* ========================================================================================== */
/* 2. Views (docs/errata.md C7)                                                               */
/* ========================================================================================== */

#define VX_M(m, r, c) ((m)[(c) * 4 + (r)]) /* column-major element (row r, column c) */

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
    if (!m || !out || !hfvis__all_finite(m, 16)) return HFVIS_ERR_INVALID_ARGUMENT;
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
    if (!eye || !target || !up || !out || !hfvis__all_finite(eye, 3) || !hfvis__all_finite(target, 3)
        || !hfvis__all_finite(up, 3))
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
    if (!out || !(fov_y_rad > 0.0 && fov_y_rad < HFVIS__PI) || !(aspect > 0.0) || !isfinite(aspect)
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
    if (!out || !hfvis__all_finite(b, 6) || !(left < right) || !(bottom < top)
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
 * down -z; docs/errata.md E54 restores the sign of the GL eye coordinate. */
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
/* 3. Volume grids and the Volume Buffer ([G12] §6.3)                                         */
/* ========================================================================================== */

/* Bounds of the vertices the triangles of a valid mesh use (a soup may carry unused vertices);
 * returns the longest extent. */
static double vx_used_bounds(const hfvis_mesh *mesh, double lo[3], double hi[3])
{
    double ext_max = 0.0;
    size_t i;
    int a;
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
    return ext_max;
}

HFVIS_API hfvis_status hfvis_volume_grid_fit(const hfvis_mesh *mesh, int resolution,
                                             double padding, int cubic, hfvis_volume_grid *out)
{
    double lo[3], hi[3], ext[3], ext_max = 0.0, cell_max;
    hfvis_volume_grid g;
    size_t total = 1;
    int a;
    if (!out || hfvis__mesh_check(mesh) != HFVIS_OK || mesh->triangle_count == 0 || resolution < 1
        || !(padding >= 0.0) || !isfinite(padding))
        return HFVIS_ERR_INVALID_ARGUMENT;
    ext_max = vx_used_bounds(mesh, lo, hi);
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
        if (!hfvis__mul_size(total, (size_t)g.dims[a], &total) || total > HFVIS_VOLUME_MAX_VOXELS)
            return HFVIS_ERR_LIMIT;
    }
    *out = g;
    return HFVIS_OK;
}

HFVIS_API size_t hfvis_volume_floats(const hfvis_volume_grid *grid, int channels)
{
    size_t n;
    if (!vx_grid_valid(grid) || channels < 1 || channels > HFVIS_VOLUME_MAX_CHANNELS) return 0;
    if (!hfvis__mul_size(vx_grid_voxels(grid), (size_t)channels, &n)) return 0;
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
    size_t n = hfvis_volume_floats(grid, channels), i;
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
    n = hfvis_volume_floats(&vol->grid, vol->channels);
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
    for (c = 0; c < vol->channels; c++)
        if (!vx_blend_valid(vol->blend[c])) return HFVIS_ERR_INVALID_ARGUMENT;
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
    n = hfvis_volume_floats(&dst->grid, dst->channels);
    if (n == 0) return HFVIS_ERR_INVALID_ARGUMENT;
    for (a = 0; a < 3; a++)
        if (dst->grid.dims[a] != src->grid.dims[a]) return HFVIS_ERR_INVALID_ARGUMENT;
    for (c = 0; c < dst->channels; c++)
        if (!vx_blend_valid(dst->blend[c])) return HFVIS_ERR_INVALID_ARGUMENT;
    for (i = 0; i < n; i += (size_t)dst->channels)
        for (c = 0; c < dst->channels; c++)
            dst->data[i + (size_t)c] =
                vx_blend_apply(dst->blend[c], dst->data[i + (size_t)c], src->data[i + (size_t)c]);
    return HFVIS_OK;
}

/* ========================================================================================== */
/* 4. Meshes: analytic test meshes and the Wavefront OBJ codec                                */
/*    (infrastructure for Gaitatzes 2012, ch. 6-7 and the icosphere of test                    */
/*    4, the cube of tests 1-2, the 100k-triangle benchmark torus knot of issue 4)            */
/* ========================================================================================== */
/* Contents
 *   4a. mesh builder (exact sizes, limits, overflow checks, one cleanup path)
 *   4b. generators: box, UV sphere, icosphere, torus, torus knot, height field, room, teapot
 *   4c. bounds
 *   4d. OBJ decoder (two passes: count, then fill), own locale-independent number parser
 *   4e. OBJ encoder (own shortest round-trip float formatting), file wrappers
 * Every generated triangle is counter-clockwise seen from outside: (v1 - v0) x (v2 - v0) points
 * out of the enclosed volume (into the room for the room's walls). */

/* ---- 4a. builder ------------------------------------------------------------------------ */

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
        b->xyz = (float *)hfvis__alloc_array(alloc, nv, 3 * sizeof(float));
        if (!b->xyz) return HFVIS_ERR_OUT_OF_MEMORY;
    }
    if (nt > 0) {
        b->idx = (uint32_t *)hfvis__alloc_array(alloc, nt, 3 * sizeof(uint32_t));
        if (!b->idx) {
            hfvis__free(alloc, b->xyz);
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
    hfvis__free(alloc, b->xyz);
    hfvis__free(alloc, b->idx);
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
    return hfvis__mul_size(a, b, &r) ? r : SIZE_MAX;
}
static size_t vx_mesh_add(size_t a, size_t b) { return a > SIZE_MAX - b ? SIZE_MAX : a + b; }

/* ---- 4b. generators --------------------------------------------------------------------- */

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
            double phi = 2.0 * HFVIS__PI * (double)j / (double)slices;
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
    prof = (double *)hfvis__alloc_array(alloc, m + 1, 2 * sizeof(double));
    if (!prof) return HFVIS_ERR_OUT_OF_MEMORY;
    for (i = 0; i <= m; i++) { /* theta_i = pi i / stacks from the north pole */
        double th = HFVIS__PI * (double)i / (double)m;
        prof[i] = (i == 0 || i == m) ? 0.0 : r * sin(th);
        prof[m + 1 + i] = (i == 0) ? r : (i == m) ? -r : r * cos(th);
    }
    s = vx_mesh_builder_init(&b, alloc, nv, nt);
    if (s == HFVIS_OK) {
        vx_mesh_revolve(&b, c, prof, prof + m + 1, m, (size_t)slices);
        s = vx_mesh_builder_finish(&b, alloc, out);
    }
    hfvis__free(alloc, prof);
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
    unit = (double *)hfvis__alloc_array(alloc, nv, 3 * sizeof(double));
    em.keys = (uint64_t *)hfvis__alloc_array(alloc, cap, sizeof(uint64_t));
    em.vals = (uint32_t *)hfvis__alloc_array(alloc, cap, sizeof(uint32_t));
    if (!unit || !em.keys || !em.vals) {
        hfvis__free(alloc, em.vals);
        hfvis__free(alloc, em.keys);
        hfvis__free(alloc, unit);
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
    hfvis__free(alloc, em.vals);
    hfvis__free(alloc, em.keys);
    hfvis__free(alloc, unit);
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
        double u = 2.0 * HFVIS__PI * (double)i / (double)n, cu = cos(u), su = sin(u);
        for (j = 0; j < m; j++) {
            double w = 2.0 * HFVIS__PI * (double)j / (double)m;
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
        double t = 2.0 * HFVIS__PI * (double)i / (double)n;
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
            double w = 2.0 * HFVIS__PI * (double)j / (double)m, cw = cos(w), sw = sin(w);
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
        || (size_t)g->height > (size_t)PTRDIFF_MAX / sizeof(float) / (size_t)g->stride
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
    remap = (uint32_t *)hfvis__alloc_array(alloc, npts, sizeof(uint32_t));
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
        hfvis__free(alloc, remap);
        return HFVIS_ERR_LIMIT;
    }
    s = vx_mesh_builder_init(&b, alloc, nv, nt);
    if (s != HFVIS_OK) {
        hfvis__free(alloc, remap);
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
    hfvis__free(alloc, remap);
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
    const double deg17 = 17.0 * HFVIS__PI / 180.0;
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
    prof = (double *)hfvis__alloc_array(alloc, m + 1, 2 * sizeof(double));
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
        hfvis__free(alloc, prof);
        return s;
    }
    vx_mesh_revolve(&b, zero, prof, prof + m + 1, m, slices);
    hfvis__free(alloc, prof);
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
                double w = 2.0 * HFVIS__PI * (double)j / (double)around, cw = cos(w), sw = sin(w);
                vx_mesh_v(&b, P[0] + rad * (cw * N[0] + sw * Bv[0]), rad * sw * Bv[1],
                          P[2] + rad * (cw * N[2] + sw * Bv[2]));
            }
        }
        vx_mesh_tube_tris(&b, base, along, around, 0);
    }
    return vx_mesh_builder_finish(&b, alloc, out);
}

/* ---- 4c. bounds ------------------------------------------------------------------------- */

HFVIS_API hfvis_status hfvis_mesh_bounds(const hfvis_mesh *mesh, double lo[3], double hi[3])
{
    double l[3], h[3];
    size_t v;
    int k;
    if (!lo || !hi || hfvis__mesh_check(mesh) != HFVIS_OK || mesh->vertex_count == 0)
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

/* ---- 4d. OBJ decoder -------------------------------------------------------------------- */
/* Wavefront OBJ subset (README.md, CLI): `v x y z [w | r g b ...]` and `f` lines; every other
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
    /* An empty input may be NULL; point at a literal so p + size is defined (C99 6.5.6p8). */
    const unsigned char *p = (const unsigned char *)(data ? data : "");
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

/* ---- 4e. OBJ encoder, file wrappers ----------------------------------------------------- */

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
    if (hfvis__mesh_check(mesh) != HFVIS_OK) return 0;
    return vx_mesh_obj_emit(mesh, NULL);
}

HFVIS_API hfvis_status hfvis_obj_encode(const hfvis_mesh *mesh, void *out, size_t out_capacity,
                                        size_t *written)
{
    size_t need;
    if (!out || !written || hfvis__mesh_check(mesh) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    need = vx_mesh_obj_emit(mesh, NULL);
    if (need == 0) return HFVIS_ERR_INVALID_ARGUMENT;
    if (out_capacity < need) return HFVIS_ERR_BUFFER_TOO_SMALL;
    vx_mesh_obj_emit(mesh, (unsigned char *)out);
    *written = need;
    return HFVIS_OK;
}

#ifndef HFVIS_NO_STDIO
/* OBJ is text without a size: read to the end, unless the first 64 KiB hold a NUL byte, which no
 * OBJ file has (/dev/zero or a binary file is refused before it is read further). */
static hfvis_status vx_obj_sizer(const unsigned char *head, size_t n, size_t *total)
{
    (void)total;
    return memchr(head, 0, n) ? HFVIS_ERR_FORMAT : HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_mesh_load(const char *path, const hfvis_allocator *alloc,
                                       hfvis_mesh *out)
{
    unsigned char *data = NULL;
    size_t size = 0;
    hfvis_status s;
    if (!path || !out) return HFVIS_ERR_INVALID_ARGUMENT;
    s = hfvis__read_file(path, alloc, vx_obj_sizer, &data, &size);
    if (s != HFVIS_OK) return s;
    s = hfvis_obj_decode(data, size, alloc, out);
    hfvis__free(alloc, data);
    return s;
}

HFVIS_API hfvis_status hfvis_mesh_save(const char *path, const hfvis_mesh *mesh)
{
    size_t need, written = 0;
    unsigned char *buf;
    hfvis_status s;
    if (!path || hfvis__mesh_check(mesh) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    need = vx_mesh_obj_emit(mesh, NULL);
    if (need == 0) return HFVIS_ERR_INVALID_ARGUMENT;
    buf = (unsigned char *)hfvis__alloc(NULL, need);
    if (!buf) return HFVIS_ERR_OUT_OF_MEMORY;
    written = vx_mesh_obj_emit(mesh, buf);
    s = hfvis_write_file(path, buf, written, NULL);
    hfvis__free(NULL, buf);
    return s;
}
#endif /* HFVIS_NO_STDIO */


/* ========================================================================================== */
/* 5. Reference rasterizer (docs/errata.md C7 view conventions)                               */
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
    if (hfvis__mesh_check(mesh) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    *opt = opts ? *opts : hfvis_raster_options_default();
    if (opt->cull != HFVIS_CULL_NONE && opt->cull != HFVIS_CULL_BACK
        && opt->cull != HFVIS_CULL_FRONT)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (opt->normal_space != HFVIS_NORMAL_WORLD && opt->normal_space != HFVIS_NORMAL_EYE)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (opt->normal_toward_viewer != 0 && opt->normal_toward_viewer != 1)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (view->width < 1 || view->height < 1) return HFVIS_ERR_INVALID_ARGUMENT;
    if (!hfvis__all_finite(view->view, 16) || !hfvis__all_finite(view->proj, 16))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (!isfinite(view->near_plane) || !isfinite(view->far_plane)
        || !(view->near_plane < view->far_plane)
        || (!view->orthographic && !(view->near_plane > 0.0)))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (view->width > HFVIS_RASTER_MAX_SIZE || view->height > HFVIS_RASTER_MAX_SIZE)
        return HFVIS_ERR_LIMIT;
    if (!hfvis__mul_size((size_t)view->width, (size_t)view->height, &pixels))
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
        if (!hfvis__all_finite(c[j], 5)) return;
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
    if (!hfvis__mul_size(vcount, VX_RASTER_VSTRIDE, &n_doubles) || n_doubles > SIZE_MAX - pixels
        || n_doubles + pixels > SIZE_MAX - (size_t)view->width - (size_t)view->height)
        return HFVIS_ERR_OUT_OF_MEMORY;
    n_doubles += pixels + (size_t)view->width + (size_t)view->height;
    block = (double *)hfvis__alloc_array(opt.alloc, n_doubles, sizeof(double));
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
    hfvis__free(opt.alloc, block);
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
            if (!hfvis__all_finite(o, 3) || !hfvis__all_finite(d, 3)) continue;
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

/* ========================================================================================== */
/* 6. BVH and ray casting (the scene-space caster of [LK] §5-6)               */
/*     Watertight test: S. Woop, C. Benthin, I. Wald, "Watertight Ray/Triangle Intersection",  */
/*     JCGT 2(1), 2013: its pseudo-code listing (ray setup, shear, edge functions U V W, the   */
/*     double-precision recomputation of zero edge functions), quoted line by line below.     */
/*     Slab test: T. Ize, "Robust BVH Ray Traversal", JCGT 2(2), 2013 (t_far * (1 + 2 gamma_3)).*/
/*     SAH: MacDonald & Booth 1990, binned as I. Wald, IEEE RT 2007.                           */
/* ========================================================================================== */
/* Contents
 *   6.1 rays: validation and the per-ray setup of Woop et al.
 *   6.2 the watertight ray-triangle test and the exact zero-area test
 *   6.3 naive oracle (every triangle in index order)
 *   6.4 binned SAH build (explicit stack, median fallback, padded boxes)
 *   6.5 traversal (robust slab test, nearer child first, explicit stack) */

/* Far-distance and best-distance widening of the slab test: Ize's 1 + 2 gamma_3 (3.6e-7) covers
 * the slab arithmetic; 2^-16 also covers the rounding of the triangle's own t (relative, a few
 * ulp times the conditioning of the hit), so a hit the naive loop finds is never pruned. */
#define VX_BVH_SLACK (1.0f + 1.0f / 65536.0f)
/* Node boxes are padded by 2^-18 of their largest coordinate magnitude or extent: covers the
 * off-plane rounding of a computed hit point (about gamma * box size) near box faces. */
#define VX_BVH_PAD 0x1p-18
/* The two inner-loop tests are forced inline (GCC/Clang), else left to the compiler. */
#define VX_BVH_INLINE HFVIS__ALWAYS_INLINE
/* SAH constants ([LK] §6; docs/errata.md E46: C_trav = C_tri = 1). */
#define VX_BVH_C_TRAV 1.0
#define VX_BVH_C_TRI 1.0

/* ---- 6.1 rays ------------------------------------------------------------------------------ */

/* A ray prepared once per query (Woop et al.: "calculate dimension where the ray direction is
 * maximal", "swap kx and ky dimension to preserve winding direction of triangles", "calculate
 * shear constants"). */
typedef struct vx_bvh_ray {
    float org[3], dir[3];
    float inv[3];      /* 1/dir; a zero component gives +-infinity with the zero's sign */
    int neg[3];        /* sign bit of dir: the slab's near plane is hi when set */
    int kx, ky, kz;    /* kz = axis of the largest |dir|; kx, ky swapped if dir[kz] < 0 */
    float sx, sy, sz;  /* shear constants: dir[kx]/dir[kz], dir[ky]/dir[kz], 1/dir[kz] */
    float t_min, t_max;
    int cull;
} vx_bvh_ray;

static int vx_bvh_ray_valid(const hfvis_ray *r)
{
    int a;
    if (!r) return 0;
    for (a = 0; a < 3; a++)
        if (!isfinite(r->origin[a]) || !isfinite(r->direction[a])) return 0;
    if (r->direction[0] == 0.0f && r->direction[1] == 0.0f && r->direction[2] == 0.0f) return 0;
    if (!(r->t_min >= 0.0f) || !isfinite(r->t_min)) return 0; /* NaN fails the first test */
    if (!(r->t_max >= r->t_min)) return 0;                    /* NaN fails; +inf allowed */
    if (r->cull != HFVIS_CULL_NONE && r->cull != HFVIS_CULL_BACK
        && r->cull != HFVIS_CULL_FRONT)
        return 0;
    return 1;
}

/* kz = dimension of the largest |direction| component (first on ties), kx and ky the
 * next two cyclically, swapped when dir[kz] < 0 to keep the winding; shear constants. */
static void vx_bvh_ray_setup(const hfvis_ray *r, vx_bvh_ray *p)
{
    int a, kz = 0, t;
    float m = fabsf(r->direction[0]);
    for (a = 0; a < 3; a++) {
        float d = r->direction[a];
        p->org[a] = r->origin[a];
        p->dir[a] = d;
        p->neg[a] = signbit(d) ? 1 : 0;
        p->inv[a] = d == 0.0f ? copysignf(INFINITY, d) : 1.0f / d;
        if (fabsf(d) > m) {
            m = fabsf(d);
            kz = a;
        }
    }
    p->kz = kz;
    p->kx = kz == 2 ? 0 : kz + 1;
    p->ky = p->kx == 2 ? 0 : p->kx + 1;
    if (r->direction[kz] < 0.0f) {
        t = p->kx;
        p->kx = p->ky;
        p->ky = t;
    }
    p->sx = r->direction[p->kx] / r->direction[kz];
    p->sy = r->direction[p->ky] / r->direction[kz];
    p->sz = 1.0f / r->direction[kz];
    p->t_min = r->t_min;
    p->t_max = r->t_max;
    p->cull = (int)r->cull;
}

static void vx_bvh_miss(hfvis_hit *h)
{
    h->t = INFINITY;
    h->triangle = HFVIS_NO_TRIANGLE;
    h->u = 0.0f;
    h->v = 0.0f;
    h->front = 0;
}

/* ---- 6.2 watertight ray-triangle test ----------------------------------------------------- */

/* Exact test: is p[0] + ... + p[5] == 0? The p are exact products of two floats (double). A
 * floating-point filter (the rounded sum's error is below 5 u sum|p| < 2^-50 sum|p|) decides
 * almost always; otherwise Shewchuk's GROW-EXPANSION with Knuth's TWO-SUM and zero
 * elimination ("Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric
 * Predicates", 1997): the sum is zero
 * iff no component survives. */
static int vx_bvh_sum6_is_zero(const double p[6])
{
    double s = 0.0, m = 0.0, e[7];
    int i, j, n = 0;
    for (i = 0; i < 6; i++) {
        s += p[i];
        m += fabs(p[i]);
    }
    if (m == 0.0) return 1;
    if (fabs(s) > m * 0x1p-50) return 0;
    for (i = 0; i < 6; i++) {
        double q = p[i];
        int k = 0;
        for (j = 0; j < n; j++) {
            double x = q + e[j], bv = x - q, av = x - bv;
            double err = (q - av) + (e[j] - bv);
            q = x;
            if (err != 0.0) e[k++] = err;
        }
        if (q != 0.0) e[k++] = q;
        n = k;
    }
    return n == 0;
}

/* 1 when (b - a) x (c - a) is exactly the zero vector (coincident or collinear vertices). Its
 * component (i, j) is a_i b_j - a_j b_i + b_i c_j - b_j c_i + c_i a_j - c_j a_i, each product
 * of two floats exact in double. */
static int vx_bvh_zero_area(const float *a, const float *b, const float *c)
{
    static const int ci[3] = {1, 2, 0}, cj[3] = {2, 0, 1};
    int k;
    for (k = 0; k < 3; k++) {
        int i = ci[k], j = cj[k];
        double p[6];
        p[0] = (double)a[i] * (double)b[j];
        p[1] = -((double)a[j] * (double)b[i]);
        p[2] = (double)b[i] * (double)c[j];
        p[3] = -((double)b[j] * (double)c[i]);
        p[4] = (double)c[i] * (double)a[j];
        p[5] = -((double)c[j] * (double)a[i]);
        if (!vx_bvh_sum6_is_zero(p)) return 0;
    }
    return 1;
}

/* Woop et al.'s listing for one triangle, hits accepted with t in [t_min, t_hi] (t_hi <= t_max:
 * callers pass their current best). Returns 1 and fills h (all but triangle) on a hit. */
static VX_BVH_INLINE int vx_bvh_tri(const vx_bvh_ray *r, const float *p0, const float *p1,
                                     const float *p2, float t_hi, hfvis_hit *h)
{
    const int kx = r->kx, ky = r->ky, kz = r->kz;
    float ax, ay, az, bx, by, bz, cx, cy, cz, Ax, Ay, Bx, By, Cx, Cy, U, V, W, det, T, t;
    /* "calculate vertices relative to ray origin": A = tri.A - org, ... */
    ax = p0[kx] - r->org[kx];
    ay = p0[ky] - r->org[ky];
    az = p0[kz] - r->org[kz];
    bx = p1[kx] - r->org[kx];
    by = p1[ky] - r->org[ky];
    bz = p1[kz] - r->org[kz];
    cx = p2[kx] - r->org[kx];
    cy = p2[ky] - r->org[ky];
    cz = p2[kz] - r->org[kz];
    /* shear: the ray becomes the +z axis ("Ax = A[kx] - Sx*A[kz]" ...) */
    Ax = ax - r->sx * az;
    Ay = ay - r->sy * az;
    Bx = bx - r->sx * bz;
    By = by - r->sy * bz;
    Cx = cx - r->sx * cz;
    Cy = cy - r->sy * cz;
    /* scaled barycentric coordinates = 2D edge functions ("U = Cx*By - Cy*Bx" ...) */
    U = Cx * By - Cy * Bx;
    V = Ax * Cy - Ay * Cx;
    W = Bx * Ay - By * Ax;
    /* "fallback to test against edges using double precision": an edge function that is exactly
     * 0 is recomputed in double, where the products of two floats are exact and the difference
     * is correctly rounded, so its sign is exact. (The float value's sign, when nonzero, is
     * already exact: rounding is monotonic.) */
    if (U == 0.0f || V == 0.0f || W == 0.0f) goto exact_path;
    /* inside iff U, V, W share a sign ("if ((U<0 || V<0 || W<0) && (U>0 || V>0 || W>0))
     * return"); a NaN (two overflowed products) passes here and is resolved below */
    if ((U < 0.0f || V < 0.0f || W < 0.0f) && (U > 0.0f || V > 0.0f || W > 0.0f)) return 0;
    det = U + V + W;
    if (!(fabsf(det) <= FLT_MAX)) goto exact_path; /* overflow or NaN: redo in double */
    if (r->cull == HFVIS_CULL_BACK && det < 0.0f) return 0;
    if (r->cull == HFVIS_CULL_FRONT && det > 0.0f) return 0;
    /* scaled hit distance ("Az = Sz*A[kz]" ..., "T = U*Az + V*Bz + W*Cz") and t = T/det */
    T = U * (r->sz * az) + V * (r->sz * bz) + W * (r->sz * cz);
    t = T / det;
    if (!(fabsf(t) <= FLT_MAX)) goto exact_path;
    if (!(t >= r->t_min) || !(t <= t_hi)) return 0;
    if (vx_bvh_zero_area(p0, p1, p2)) return 0;
    h->t = t;
    h->u = V / det;
    h->v = W / det;
    h->front = det > 0.0f;
    return 1;
exact_path: {
        double Ud = (double)Cx * (double)By - (double)Cy * (double)Bx;
        double Vd = (double)Ax * (double)Cy - (double)Ay * (double)Cx;
        double Wd = (double)Bx * (double)Ay - (double)By * (double)Ax;
        double dd, Td, td;
        if ((Ud < 0.0 || Vd < 0.0 || Wd < 0.0) && (Ud > 0.0 || Vd > 0.0 || Wd > 0.0)) return 0;
        dd = Ud + Vd + Wd;
        if (dd == 0.0 || !(fabs(dd) <= DBL_MAX)) return 0; /* edge-on (or not finite) */
        if (r->cull == HFVIS_CULL_BACK && dd < 0.0) return 0;
        if (r->cull == HFVIS_CULL_FRONT && dd > 0.0) return 0;
        Td = Ud * ((double)r->sz * (double)az) + Vd * ((double)r->sz * (double)bz)
             + Wd * ((double)r->sz * (double)cz);
        td = Td / dd;
        if (!(fabs(td) <= (double)FLT_MAX)) return 0;
        t = (float)td;
        if (!(t >= r->t_min) || !(t <= t_hi)) return 0;
        if (vx_bvh_zero_area(p0, p1, p2)) return 0;
        h->t = t;
        h->u = (float)(Vd / dd);
        h->v = (float)(Wd / dd);
        h->front = dd > 0.0;
        return 1;
    }
}

HFVIS_API hfvis_status hfvis_ray_triangle(const hfvis_ray *ray, const float v0[3],
                                          const float v1[3], const float v2[3], hfvis_hit *hit)
{
    vx_bvh_ray r;
    hfvis_hit h;
    int a;
    if (!vx_bvh_ray_valid(ray) || !v0 || !v1 || !v2 || !hit) return HFVIS_ERR_INVALID_ARGUMENT;
    for (a = 0; a < 3; a++)
        if (!isfinite(v0[a]) || !isfinite(v1[a]) || !isfinite(v2[a]))
            return HFVIS_ERR_INVALID_ARGUMENT;
    vx_bvh_ray_setup(ray, &r);
    if (vx_bvh_tri(&r, v0, v1, v2, r.t_max, &h)) {
        h.triangle = 0;
        *hit = h;
    } else {
        vx_bvh_miss(hit);
    }
    return HFVIS_OK;
}

/* ---- 6.3 naive oracle ---------------------------------------------------------------------- */

static int vx_bvh_query_valid(hfvis_ray_query q)
{
    return q == HFVIS_RAY_CLOSEST || q == HFVIS_RAY_ANY;
}

HFVIS_API hfvis_status hfvis_ray_intersect_naive(const hfvis_mesh *mesh, const hfvis_ray *ray,
                                                 hfvis_ray_query query, hfvis_hit_filter filter,
                                                 void *user, hfvis_hit *hit)
{
    vx_bvh_ray r;
    hfvis_hit best, h;
    size_t t, nv;
    if (!mesh || !hit || !vx_bvh_ray_valid(ray) || !vx_bvh_query_valid(query))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if ((mesh->vertex_count && !mesh->xyz) || (mesh->triangle_count && !mesh->indices))
        return HFVIS_ERR_INVALID_ARGUMENT;
    vx_bvh_ray_setup(ray, &r);
    vx_bvh_miss(&best);
    best.t = r.t_max;
    nv = mesh->vertex_count;
    for (t = 0; t < mesh->triangle_count; t++) {
        const uint32_t *ix = mesh->indices + 3 * t;
        if (ix[0] >= nv || ix[1] >= nv || ix[2] >= nv) return HFVIS_ERR_INVALID_ARGUMENT;
        /* in index order, "t < best" is the closest-hit order (ties keep the lower index) */
        if (!vx_bvh_tri(&r, mesh->xyz + 3 * (size_t)ix[0], mesh->xyz + 3 * (size_t)ix[1],
                        mesh->xyz + 3 * (size_t)ix[2], best.t, &h))
            continue;
        if (best.triangle != HFVIS_NO_TRIANGLE && !(h.t < best.t)) continue;
        h.triangle = (uint32_t)t;
        if (filter && !filter(user, ray, &h)) continue;
        best = h;
        if (query == HFVIS_RAY_ANY) break;
    }
    if (best.triangle == HFVIS_NO_TRIANGLE) vx_bvh_miss(&best);
    *hit = best;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_ray_closest_naive(const hfvis_mesh *mesh, const hfvis_ray *ray,
                                               hfvis_hit *hit)
{
    return hfvis_ray_intersect_naive(mesh, ray, HFVIS_RAY_CLOSEST, NULL, NULL, hit);
}

HFVIS_API hfvis_status hfvis_ray_any_naive(const hfvis_mesh *mesh, const hfvis_ray *ray,
                                           hfvis_hit *hit)
{
    return hfvis_ray_intersect_naive(mesh, ray, HFVIS_RAY_ANY, NULL, NULL, hit);
}

/* ---- 6.4 binned SAH build ----------------------------------------------------------------- */

HFVIS_API hfvis_bvh_options hfvis_bvh_options_default(void)
{
    hfvis_bvh_options o;
    memset(&o, 0, sizeof o);
    o.max_leaf_size = HFVIS_BVH_DEFAULT_LEAF_SIZE;
    o.bins = HFVIS_BVH_DEFAULT_BINS;
    return o;
}

typedef struct vx_bvh_prim {
    float lo[3], hi[3]; /* float bounding box of the triangle (exact: min/max of its vertices) */
} vx_bvh_prim;

typedef struct vx_bvh_task {
    uint32_t node, begin, end;
    int depth;
} vx_bvh_task;

typedef struct vx_bvh_bin {
    float lo[3], hi[3];
    uint32_t count;
} vx_bvh_bin;

/* Centroid of a triangle's box on axis a, doubled (lo + hi, in double: no overflow). */
static double vx_bvh_cen(const vx_bvh_prim *p, int a)
{
    return (double)p->lo[a] + (double)p->hi[a];
}

static double vx_bvh_area(const float lo[3], const float hi[3])
{
    double dx = (double)hi[0] - (double)lo[0], dy = (double)hi[1] - (double)lo[1],
           dz = (double)hi[2] - (double)lo[2];
    return 2.0 * (dx * dy + dy * dz + dz * dx);
}

static void vx_bvh_grow(float lo[3], float hi[3], const float plo[3], const float phi[3])
{
    int a;
    for (a = 0; a < 3; a++) {
        if (plo[a] < lo[a]) lo[a] = plo[a];
        if (phi[a] > hi[a]) hi[a] = phi[a];
    }
}

/* Bin of a (doubled) centroid c on an axis with bounds [cmin, cmax], cmax > cmin. */
static int vx_bvh_bin_of(double c, double cmin, double scale, int bins)
{
    int b = (int)((c - cmin) * scale);
    if (b < 0) b = 0;
    if (b > bins - 1) b = bins - 1;
    return b;
}

/* Key order of the median split: centroid on axis a, then triangle index. */
static int vx_bvh_less(const vx_bvh_prim *prims, uint32_t x, uint32_t y, int a)
{
    double cx = vx_bvh_cen(prims + x, a), cy = vx_bvh_cen(prims + y, a);
    return cx < cy || (cx == cy && x < y);
}

/* Swap *x and *y unless *x comes first. */
static void vx_bvh_order2(const vx_bvh_prim *prims, uint32_t *x, uint32_t *y, int a)
{
    if (vx_bvh_less(prims, *y, *x, a)) {
        uint32_t t = *x;
        *x = *y;
        *y = t;
    }
}

/* Rearrange idx[0..n) so that idx[k] holds the k-th smallest key and smaller keys come before
 * it (deterministic quickselect, median-of-three pivot, Lomuto partition). */
static void vx_bvh_select(const vx_bvh_prim *prims, uint32_t *idx, size_t n, size_t k, int a)
{
    size_t lo = 0, hi = n - 1;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2, i, store;
        uint32_t tmp, piv;
        /* median of three into position hi */
        vx_bvh_order2(prims, idx + lo, idx + mid, a);
        vx_bvh_order2(prims, idx + lo, idx + hi, a);
        vx_bvh_order2(prims, idx + hi, idx + mid, a); /* lo <= hi <= mid: pivot idx[hi] */
        piv = idx[hi];
        store = lo;
        for (i = lo; i < hi; i++)
            if (vx_bvh_less(prims, idx[i], piv, a)) {
                tmp = idx[i];
                idx[i] = idx[store];
                idx[store] = tmp;
                store++;
            }
        idx[hi] = idx[store];
        idx[store] = piv;
        if (store == k) return;
        if (k < store) hi = store - 1;
        else lo = store + 1;
    }
}

/* Pad a finished node box outward (see hfvis_bvh_node). */
static void vx_bvh_pad(hfvis_bvh_node *n)
{
    double m = 0.0, pad;
    int a;
    for (a = 0; a < 3; a++) {
        double l = fabs((double)n->lo[a]), h = fabs((double)n->hi[a]);
        double e = (double)n->hi[a] - (double)n->lo[a];
        if (l > m) m = l;
        if (h > m) m = h;
        if (e > m) m = e;
    }
    pad = m * VX_BVH_PAD;
    for (a = 0; a < 3; a++) {
        double l = (double)n->lo[a] - pad, h = (double)n->hi[a] + pad;
        /* rounded to float away from the box (the double values are within float range unless
         * the box reaches FLT_MAX, which gives +-infinity) */
        float lf = l < -(double)FLT_MAX ? -INFINITY : (float)l;
        float hf = h > (double)FLT_MAX ? INFINITY : (float)h;
        if ((double)lf > l) lf = nextafterf(lf, -INFINITY);
        if ((double)hf < h) hf = nextafterf(hf, INFINITY);
        n->lo[a] = lf;
        n->hi[a] = hf;
    }
}

HFVIS_API hfvis_status hfvis_bvh_build(const hfvis_mesh *mesh, const hfvis_bvh_options *opts,
                                       hfvis_bvh *out)
{
    const hfvis_allocator *alloc = opts ? opts->alloc : NULL;
    int max_leaf = opts && opts->max_leaf_size ? opts->max_leaf_size : HFVIS_BVH_DEFAULT_LEAF_SIZE;
    int bins = opts && opts->bins ? opts->bins : HFVIS_BVH_DEFAULT_BINS;
    size_t n, i, max_nodes, next, leaves = 0;
    uint32_t *order = NULL;
    vx_bvh_prim *prims = NULL;
    hfvis_bvh_node *tmp = NULL, *nodes = NULL;
    vx_bvh_task stack[HFVIS_BVH_MAX_DEPTH + 2];
    int sp = 0, max_depth = 0;
    hfvis_status st;

    if (!out || max_leaf < 1 || max_leaf > HFVIS_BVH_MAX_LEAF_SIZE || bins < 2
        || bins > HFVIS_BVH_MAX_BINS)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (!mesh) return HFVIS_ERR_INVALID_ARGUMENT;
    n = mesh->triangle_count;
    if (n > HFVIS_BVH_MAX_TRIANGLES) return HFVIS_ERR_LIMIT; /* before reading the arrays */
    st = hfvis__mesh_check(mesh);
    if (st != HFVIS_OK) return st;
    if (n == 0) {
        memset(out, 0, sizeof *out);
        out->max_leaf_size = max_leaf;
        return HFVIS_OK;
    }
    max_nodes = 2 * n - 1;
    order = (uint32_t *)hfvis__alloc_array(alloc, n, sizeof *order);
    if (!order) goto oom;
    prims = (vx_bvh_prim *)hfvis__alloc_array(alloc, n, sizeof *prims);
    if (!prims) goto oom;
    tmp = (hfvis_bvh_node *)hfvis__alloc_array(alloc, max_nodes, sizeof *tmp);
    if (!tmp) goto oom;

    for (i = 0; i < n; i++) {
        const uint32_t *ix = mesh->indices + 3 * i;
        const float *p0 = mesh->xyz + 3 * (size_t)ix[0], *p1 = mesh->xyz + 3 * (size_t)ix[1],
                    *p2 = mesh->xyz + 3 * (size_t)ix[2];
        int a;
        for (a = 0; a < 3; a++) {
            float lo = p0[a], hi = p0[a];
            if (p1[a] < lo) lo = p1[a];
            if (p1[a] > hi) hi = p1[a];
            if (p2[a] < lo) lo = p2[a];
            if (p2[a] > hi) hi = p2[a];
            prims[i].lo[a] = lo;
            prims[i].hi[a] = hi;
        }
        order[i] = (uint32_t)i;
    }

    next = 1;
    stack[0].node = 0;
    stack[0].begin = 0;
    stack[0].end = (uint32_t)n;
    stack[0].depth = 1;
    sp = 1;
    while (sp > 0) {
        vx_bvh_task task = stack[--sp];
        hfvis_bvh_node *node = tmp + task.node;
        size_t count = task.end - task.begin, mid = 0;
        double cmin[3], cmax[3], area;
        int a, split = 0, median = 0;
        uint32_t *idx = order + task.begin;
        /* node box and centroid bounds: O(count) */
        for (a = 0; a < 3; a++) {
            node->lo[a] = prims[idx[0]].lo[a];
            node->hi[a] = prims[idx[0]].hi[a];
            cmin[a] = cmax[a] = vx_bvh_cen(prims + idx[0], a);
        }
        for (i = 1; i < count; i++) {
            const vx_bvh_prim *p = prims + idx[i];
            vx_bvh_grow(node->lo, node->hi, p->lo, p->hi);
            for (a = 0; a < 3; a++) {
                double c = vx_bvh_cen(p, a);
                if (c < cmin[a]) cmin[a] = c;
                if (c > cmax[a]) cmax[a] = c;
            }
        }
        if (task.depth > max_depth) max_depth = task.depth;
        area = vx_bvh_area(node->lo, node->hi);
        if (count > 1) {
            int degenerate = (cmax[0] == cmin[0] && cmax[1] == cmin[1] && cmax[2] == cmin[2])
                             || !(area > 0.0) || !(area <= DBL_MAX);
            if (task.depth >= HFVIS_BVH_SAH_DEPTH || degenerate) {
                /* deep or degenerate nodes: leaf if small enough, else median split */
                median = count > (size_t)max_leaf;
            } else {
                /* binned SAH over every axis with a centroid extent (Wald 2007) */
                vx_bvh_bin bin[HFVIS_BVH_MAX_BINS];
                double right_area[HFVIS_BVH_MAX_BINS];
                uint32_t right_count[HFVIS_BVH_MAX_BINS];
                double best = HUGE_VAL, scale_best = 0.0;
                int best_axis = -1, best_bin = -1, b;
                for (a = 0; a < 3; a++) {
                    double scale;
                    float llo[3], lhi[3];
                    uint32_t lc = 0;
                    if (!(cmax[a] > cmin[a])) continue;
                    scale = (double)bins * (1.0 - 0x1p-40) / (cmax[a] - cmin[a]);
                    for (b = 0; b < bins; b++) {
                        bin[b].count = 0;
                        bin[b].lo[0] = bin[b].lo[1] = bin[b].lo[2] = INFINITY;
                        bin[b].hi[0] = bin[b].hi[1] = bin[b].hi[2] = -INFINITY;
                    }
                    for (i = 0; i < count; i++) {
                        const vx_bvh_prim *p = prims + idx[i];
                        b = vx_bvh_bin_of(vx_bvh_cen(p, a), cmin[a], scale, bins);
                        bin[b].count++;
                        vx_bvh_grow(bin[b].lo, bin[b].hi, p->lo, p->hi);
                    }
                    /* sweep from the right: boxes and counts of bins b+1..bins-1 */
                    {
                        float rlo[3] = {INFINITY, INFINITY, INFINITY},
                              rhi[3] = {-INFINITY, -INFINITY, -INFINITY};
                        uint32_t rc = 0;
                        for (b = bins - 1; b > 0; b--) {
                            if (bin[b].count) vx_bvh_grow(rlo, rhi, bin[b].lo, bin[b].hi);
                            rc += bin[b].count;
                            right_count[b - 1] = rc;
                            right_area[b - 1] = rc ? vx_bvh_area(rlo, rhi) : 0.0;
                        }
                    }
                    llo[0] = llo[1] = llo[2] = INFINITY;
                    lhi[0] = lhi[1] = lhi[2] = -INFINITY;
                    for (b = 0; b < bins - 1; b++) {
                        double cost;
                        if (bin[b].count) vx_bvh_grow(llo, lhi, bin[b].lo, bin[b].hi);
                        lc += bin[b].count;
                        if (lc == 0 || right_count[b] == 0) continue;
                        cost = vx_bvh_area(llo, lhi) * (double)lc
                               + right_area[b] * (double)right_count[b];
                        if (cost < best) {
                            best = cost;
                            best_axis = a;
                            best_bin = b;
                            scale_best = scale;
                        }
                    }
                }
                if (best_axis < 0) {
                    median = count > (size_t)max_leaf; /* unreachable: some extent is > 0 */
                } else {
                    double split_cost = VX_BVH_C_TRAV + VX_BVH_C_TRI * best / area;
                    if (count > (size_t)max_leaf || !(VX_BVH_C_TRI * (double)count <= split_cost)) {
                        /* partition by bin: bins <= best_bin go left */
                        size_t lo = 0, hi = count;
                        a = best_axis;
                        while (lo < hi) {
                            if (vx_bvh_bin_of(vx_bvh_cen(prims + idx[lo], a), cmin[a], scale_best,
                                              bins) <= best_bin) {
                                lo++;
                            } else {
                                uint32_t t = idx[lo];
                                idx[lo] = idx[--hi];
                                idx[hi] = t;
                            }
                        }
                        mid = lo;
                        split = 1;
                        HFVIS_ASSERT(mid > 0 && mid < count);
                    }
                }
            }
            if (median) {
                int ax = 0;
                for (a = 1; a < 3; a++)
                    if (cmax[a] - cmin[a] > cmax[ax] - cmin[ax]) ax = a;
                mid = count / 2;
                vx_bvh_select(prims, idx, count, mid, ax);
                split = 1;
            }
        }
        if (!split) {
            node->left_or_first = task.begin;
            node->count = (uint32_t)count;
            leaves++;
            continue;
        }
        HFVIS_ASSERT(next + 2 <= max_nodes && sp + 2 <= HFVIS_BVH_MAX_DEPTH + 2);
        node->left_or_first = (uint32_t)next;
        node->count = 0;
        /* right first on the stack, so the left subtree is built (and numbered) first */
        stack[sp].node = (uint32_t)(next + 1);
        stack[sp].begin = task.begin + (uint32_t)mid;
        stack[sp].end = task.end;
        stack[sp].depth = task.depth + 1;
        stack[sp + 1].node = (uint32_t)next;
        stack[sp + 1].begin = task.begin;
        stack[sp + 1].end = task.begin + (uint32_t)mid;
        stack[sp + 1].depth = task.depth + 1;
        sp += 2;
        next += 2;
    }
    HFVIS_ASSERT(max_depth <= HFVIS_BVH_MAX_DEPTH);

    nodes = (hfvis_bvh_node *)hfvis__alloc_array(alloc, next, sizeof *nodes);
    if (!nodes) goto oom;
    for (i = 0; i < next; i++) {
        nodes[i] = tmp[i];
        vx_bvh_pad(nodes + i);
    }
    hfvis__free(alloc, tmp);
    hfvis__free(alloc, prims);
    out->nodes = nodes;
    out->node_count = next;
    out->tri_order = order;
    out->triangle_count = n;
    out->leaf_count = leaves;
    out->depth = max_depth;
    out->max_leaf_size = max_leaf;
    return HFVIS_OK;
oom:
    hfvis__free(alloc, tmp);
    hfvis__free(alloc, prims);
    hfvis__free(alloc, order);
    return HFVIS_ERR_OUT_OF_MEMORY;
}

HFVIS_API void hfvis_bvh_free(const hfvis_allocator *alloc, hfvis_bvh *bvh)
{
    if (!bvh) return;
    hfvis__free(alloc, bvh->nodes);
    hfvis__free(alloc, bvh->tri_order);
    memset(bvh, 0, sizeof *bvh);
}

/* ---- 6.5 traversal ------------------------------------------------------------------------- */

/* Robust slab test (Ize 2013): entry distance max(t_min, near planes), exit distance
 * min(far planes) * VX_BVH_SLACK; a NaN from 0 * infinity (ray in a slab's plane, zero
 * direction component) is ignored by the comparisons, which is the right answer for a ray on
 * the (closed) slab boundary. Hit when entry <= exit and entry <= t_hi (the widened best). */
static VX_BVH_INLINE int vx_bvh_box(const hfvis_bvh_node *n, const vx_bvh_ray *r, float t_hi,
                                     float *entry)
{
    float tn = r->t_min, tf = INFINITY, t0, t1;
    t0 = ((r->neg[0] ? n->hi[0] : n->lo[0]) - r->org[0]) * r->inv[0];
    t1 = ((r->neg[0] ? n->lo[0] : n->hi[0]) - r->org[0]) * r->inv[0];
    tn = t0 > tn ? t0 : tn;
    tf = t1 < tf ? t1 : tf;
    t0 = ((r->neg[1] ? n->hi[1] : n->lo[1]) - r->org[1]) * r->inv[1];
    t1 = ((r->neg[1] ? n->lo[1] : n->hi[1]) - r->org[1]) * r->inv[1];
    tn = t0 > tn ? t0 : tn;
    tf = t1 < tf ? t1 : tf;
    t0 = ((r->neg[2] ? n->hi[2] : n->lo[2]) - r->org[2]) * r->inv[2];
    t1 = ((r->neg[2] ? n->lo[2] : n->hi[2]) - r->org[2]) * r->inv[2];
    tn = t0 > tn ? t0 : tn;
    tf = t1 < tf ? t1 : tf;
    tf *= VX_BVH_SLACK;
    *entry = tn;
    return tn <= tf && tn <= t_hi;
}

HFVIS_API hfvis_status hfvis_bvh_intersect(const hfvis_bvh *bvh, const hfvis_mesh *mesh,
                                           const hfvis_ray *ray, hfvis_ray_query query,
                                           hfvis_hit_filter filter, void *user, hfvis_hit *hit)
{
    vx_bvh_ray r;
    hfvis_hit best, h;
    uint32_t stack_node[HFVIS_BVH_MAX_DEPTH + 1];
    float stack_t[HFVIS_BVH_MAX_DEPTH + 1];
    int sp = 0;
    const hfvis_bvh_node *nodes;
    const uint32_t *order, *indices;
    const float *xyz;
    size_t nv, ntri;
    uint32_t ni = 0;
    float t_hi, entry;
    const int any = query == HFVIS_RAY_ANY;

    if (!bvh || !mesh || !hit || !vx_bvh_ray_valid(ray) || !vx_bvh_query_valid(query))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (bvh->triangle_count != mesh->triangle_count || bvh->depth < 0
        || bvh->depth > HFVIS_BVH_MAX_DEPTH || (bvh->node_count && (!bvh->nodes || !bvh->tri_order))
        || (mesh->vertex_count && !mesh->xyz) || (mesh->triangle_count && !mesh->indices))
        return HFVIS_ERR_INVALID_ARGUMENT;
    vx_bvh_ray_setup(ray, &r);
    vx_bvh_miss(&best);
    best.t = r.t_max;
    t_hi = r.t_max * VX_BVH_SLACK;
    nodes = bvh->nodes;
    order = bvh->tri_order;
    indices = mesh->indices;
    xyz = mesh->xyz;
    nv = mesh->vertex_count;
    ntri = bvh->triangle_count;
    if (bvh->node_count == 0 || !vx_bvh_box(nodes, &r, t_hi, &entry)) goto done;
    for (;;) {
        const hfvis_bvh_node *n = nodes + ni;
        if (n->count) {
            uint32_t k, first = n->left_or_first, end = first + n->count;
            if (end < first || end > ntri) return HFVIS_ERR_INVALID_ARGUMENT; /* corrupt bvh */
            for (k = first; k < end; k++) {
                uint32_t tri = order[k];
                const uint32_t *ix = indices + 3 * (size_t)tri;
                if (tri >= ntri || ix[0] >= nv || ix[1] >= nv || ix[2] >= nv)
                    return HFVIS_ERR_INVALID_ARGUMENT;
                if (!vx_bvh_tri(&r, xyz + 3 * (size_t)ix[0], xyz + 3 * (size_t)ix[1],
                                xyz + 3 * (size_t)ix[2], best.t, &h))
                    continue;
                /* closest-hit order: smaller t, equal t -> lower index (as the naive loop) */
                if (best.triangle != HFVIS_NO_TRIANGLE && !(h.t < best.t || tri < best.triangle))
                    continue;
                h.triangle = tri;
                if (filter && !filter(user, ray, &h)) continue;
                best = h;
                if (any) goto done;
                t_hi = best.t * VX_BVH_SLACK;
            }
        } else {
            uint32_t left = n->left_or_first;
            float e0, e1;
            int h0, h1;
            /* children follow their parent (so every path ends) and lie inside the array */
            if (left <= ni || (size_t)left + 1 >= bvh->node_count)
                return HFVIS_ERR_INVALID_ARGUMENT;
            h0 = vx_bvh_box(nodes + left, &r, t_hi, &e0);
            h1 = vx_bvh_box(nodes + left + 1, &r, t_hi, &e1);
            if (h0 && h1) {
                if (sp >= HFVIS_BVH_MAX_DEPTH) return HFVIS_ERR_INVALID_ARGUMENT; /* corrupt bvh */
                if (e1 < e0) {
                    stack_node[sp] = left;
                    stack_t[sp++] = e0;
                    ni = left + 1;
                } else {
                    stack_node[sp] = left + 1;
                    stack_t[sp++] = e1;
                    ni = left;
                }
                continue;
            }
            if (h0) {
                ni = left;
                continue;
            }
            if (h1) {
                ni = left + 1;
                continue;
            }
        }
        /* pop the next pushed node that can still hold a hit no farther than the best */
        for (;;) {
            if (sp == 0) goto done;
            --sp;
            if (stack_t[sp] <= t_hi) break;
        }
        ni = stack_node[sp];
    }
done:
    if (best.triangle == HFVIS_NO_TRIANGLE) vx_bvh_miss(&best);
    *hit = best;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_bvh_closest_hit(const hfvis_bvh *bvh, const hfvis_mesh *mesh,
                                             const hfvis_ray *ray, hfvis_hit *hit)
{
    return hfvis_bvh_intersect(bvh, mesh, ray, HFVIS_RAY_CLOSEST, NULL, NULL, hit);
}

HFVIS_API hfvis_status hfvis_bvh_any_hit(const hfvis_bvh *bvh, const hfvis_mesh *mesh,
                                         const hfvis_ray *ray, hfvis_hit *hit)
{
    return hfvis_bvh_intersect(bvh, mesh, ray, HFVIS_RAY_ANY, NULL, NULL, hit);
}

/* ========================================================================================== */
/* 7. Surface voxelization into the Volume Buffer                                             */
/*     [G12] ch. 6 (§6.4.1 Alg. 5 geometry-shader triangle slicing, §6.4.2 Alg. 6 pixel-shader */
/*     fragment clipping, §6.6 output-vertex limit), ch. 5 §5.5.1 Alg. 4 (three axial passes   */
/*     merged with MAX)                                                                        */
/* ========================================================================================== */
/*
 * Everything happens in grid space g = (p - origin)/cell, where a voxel is a unit cube. A pass
 * along axis a sees the triangle projected onto the (u, w) = (a+1, a+2 mod 3) plane; its pixel
 * (pu, pw) has centre (pu + 0.5, pw + 0.5) and the voxel column of that pixel is cut into slabs
 * [k, k+1) along a (the GPU's layers).
 *
 * Exactness. The fast routines and the oracle evaluate the same predicates with the same
 * floating-point expressions:
 *   inside(c) = every edge function > 0, or == 0 on a top-left edge;
 *   slab(c)   = floor(clamp(depth(c), zlo, zhi)).
 * For a fixed row (fixed cw) every edge function, and the depth, is a composition of rounded
 * subtractions and multiplications by constants of cu, hence monotone in cu (IEEE rounding is
 * monotone). So each predicate holds on a prefix or a suffix of the row, the covered pixels of a
 * row are one interval and the slab is monotone along it: the fast path finds the interval ends
 * and the slab changes by a guessed-then-verified search (about two predicate evaluations each)
 * and writes every fragment between them without testing it again (rows narrower than
 * VX_VOX_DIRECT_WIDTH are tested pixel by pixel, and on rows steeper than VX_VOX_STEEP each
 * pixel's slab is evaluated: cheaper there, and the same expressions). The oracle tests every
 * voxel of the bounding box directly. Both therefore select exactly the same voxels, and since
 * within one triangle and pass no voxel is written twice and triangles are processed in the
 * same order, the blended values agree bit for bit too.
 */

#define VX_VOX_MAX_COORD 1e150 /* beyond: products of coordinates could overflow double */
#define VX_VOX_MAX_SLOPE 1e100 /* beyond: the triangle is edge-on to the pass (to precision) */
/* Rows whose candidate span is narrower than this are tested pixel by pixel (with the same
 * predicate): cheaper than the boundary search for the small triangles of dense meshes. */
#define VX_VOX_DIRECT_WIDTH 4
/* Rows whose depth changes by more than this per pixel (runs of constant slab shorter than
 * 1/VX_VOX_STEEP pixels) get each pixel's slab evaluated (same formula) instead of searched. */
#define VX_VOX_STEEP 0.25

/* One directed edge A -> B of a counter-clockwise polygon in the (u, w) plane. The edge function
 * is evaluated from the lexicographically smaller endpoint `l` with d = (larger - smaller) and
 * multiplied by sign = +1 (A is the smaller) or -1, so the two directions of one segment give
 * exactly opposite values (a shared edge of two triangles never covers a pixel twice or not at
 * all). E(c) > 0 left of A -> B, i.e. inside. */
typedef struct vx_vox_edge {
    double lu, lw, du, dw, sign;
    double root_du; /* du/dw (0 when dw == 0): d(root u)/d(row w), only for search estimates */
    int owned; /* top-left rule: centres exactly on the edge are inside */
    int skip;  /* zero-length edge (duplicate polygon vertex): no constraint */
} vx_vox_edge;

static void vx_vox_edge_init(vx_vox_edge *e, double au, double aw, double bu, double bw)
{
    /* (root_du is filled by vx_vox_edge_root, only for rows wide enough to be searched) */
    int a_small = au < bu || (au == bu && aw < bw);
    double su = a_small ? au : bu, sw = a_small ? aw : bw;
    double gu = a_small ? bu : au, gw = a_small ? bw : aw;
    double tu, tw;
    e->lu = su;
    e->lw = sw;
    e->du = gu - su;
    e->dw = gw - sw;
    e->sign = a_small ? 1.0 : -1.0;
    e->skip = au == bu && aw == bw;
    e->root_du = 0.0;
    /* traversal direction B - A (exact sign of the rounded difference) */
    tu = e->sign * e->du;
    tw = e->sign * e->dw;
    /* counter-clockwise with w up: a "left" edge goes down, a "top" edge goes left */
    e->owned = tw < 0.0 || (tw == 0.0 && tu < 0.0);
}

/* The search estimate's slope du/dw of an edge (rows searched, not tested pixel by pixel). */
static void vx_vox_edge_root(vx_vox_edge *e)
{
    e->root_du = e->dw != 0.0 ? e->du / e->dw : 0.0;
}

static double vx_vox_edge_value(const vx_vox_edge *e, double cu, double cw)
{
    return e->sign * (e->du * (cw - e->lw) - e->dw * (cu - e->lu));
}

static int vx_vox_edge_pass(const vx_vox_edge *e, double cu, double cw)
{
    double v;
    if (e->skip) return 1;
    v = vx_vox_edge_value(e, cu, cw);
    return v > 0.0 || (v == 0.0 && e->owned);
}

/* A triangle prepared for voxelization (grid space, double). */
typedef struct vx_vox_tri {
    uint32_t id;
    double v[3][3];  /* world vertices */
    double g[3][3];  /* grid-space vertices */
    double n[3];     /* grid-space normal (g1 - g0) x (g2 - g0) */
    float normal[3]; /* unit world normal (only filled when fragments are delivered) */
} vx_vox_tri;

/* The triangle in the pass along axis a. */
typedef struct vx_vox_pass {
    int a, u, w;
    double U[3], W[3], Z[3]; /* projected vertices (original order) and depths */
    double area2;            /* n[a]: twice the signed projected area */
    vx_vox_edge e[3];        /* counter-clockwise edges */
    int edir[3];             /* sign of d(edge function)/du: +1 inside on a row suffix, -1 prefix */
    double q[3][3];          /* counter-clockwise vertices (U, W, Z) */
    double dzdu, dzdw;       /* depth slopes of the plane */
    double dudz;             /* 1/dzdu (0 if dzdu == 0), only for search estimates */
    double zlo, zhi;         /* depth range */
    int bu0, bu1, bw0, bw1;  /* pixel bounding box of the triangle within the grid */
    int k0, k1;              /* slabs floor(zlo) .. floor(zhi) within the grid (and the cap) */
} vx_vox_pass;

/* floor / ceil of x as int, for |x| < 2^31 (callers clamp first; libm's floor is a call on
 * baseline x86-64). */
static int vx_vox_ifloor(double x)
{
    int i = (int)x;
    return (double)i > x ? i - 1 : i;
}
static int vx_vox_iceil(double x)
{
    int i = (int)x;
    return (double)i < x ? i + 1 : i;
}

/* Pixel range [*i0, *i1] whose centres i + 0.5 lie in [lo, hi], within [0, n); 0 if empty:
 * i0 = max(0, ceil(lo - 0.5)), i1 = min(n - 1, floor(hi - 0.5)). */
static int vx_vox_pixel_range(double lo, double hi, int n, int *i0, int *i1)
{
    double a = lo - 0.5, b = hi - 0.5;
    if (!(b >= 0.0) || !(a <= (double)(n - 1))) return 0;
    *i0 = a <= 0.0 ? 0 : vx_vox_iceil(a);
    *i1 = b >= (double)(n - 1) ? n - 1 : vx_vox_ifloor(b);
    return *i0 <= *i1;
}

/* Grid-space setup of triangle t; 0 if it is degenerate or out of range (skipped). */
static int vx_vox_tri_setup(vx_vox_tri *T, const hfvis_mesh *m, const hfvis_volume_grid *g,
                            size_t t, int want_normal)
{
    int i, a;
    double e1[3], e2[3];
    T->id = (uint32_t)t;
    for (i = 0; i < 3; i++) {
        const float *p = m->xyz + 3 * (size_t)m->indices[3 * t + (size_t)i];
        for (a = 0; a < 3; a++) T->g[i][a] = ((double)p[a] - g->origin[a]) / g->cell[a];
        if (want_normal)
            for (a = 0; a < 3; a++) T->v[i][a] = (double)p[a];
    }
    {
        double big = 0.0; /* largest |coordinate| (NaN-free: the mesh and grid are finite) */
        for (i = 0; i < 3; i++)
            for (a = 0; a < 3; a++) big = fabs(T->g[i][a]) > big ? fabs(T->g[i][a]) : big;
        if (!(big <= VX_VOX_MAX_COORD)) return 0;
    }
    for (a = 0; a < 3; a++) {
        e1[a] = T->g[1][a] - T->g[0][a];
        e2[a] = T->g[2][a] - T->g[0][a];
    }
    T->n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    T->n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    T->n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    if (T->n[0] == 0.0 && T->n[1] == 0.0 && T->n[2] == 0.0) return 0;
    if (want_normal) {
        double w1[3], w2[3], nw[3], len;
        for (a = 0; a < 3; a++) {
            w1[a] = T->v[1][a] - T->v[0][a];
            w2[a] = T->v[2][a] - T->v[0][a];
        }
        nw[0] = w1[1] * w2[2] - w1[2] * w2[1];
        nw[1] = w1[2] * w2[0] - w1[0] * w2[2];
        nw[2] = w1[0] * w2[1] - w1[1] * w2[0];
        len = sqrt(nw[0] * nw[0] + nw[1] * nw[1] + nw[2] * nw[2]);
        for (a = 0; a < 3; a++) T->normal[a] = len > 0.0 ? (float)(nw[a] / len) : 0.0f;
    }
    return 1;
}

/* Dominant axis of the grid-space normal ([G12] ch. 6: ties -> lowest index). */
static int vx_vox_dominant(const double n[3])
{
    int a = 0;
    if (fabs(n[1]) > fabs(n[a])) a = 1;
    if (fabs(n[2]) > fabs(n[a])) a = 2;
    return a;
}

/* Set up the pass of T along axis a; max_slices > 0 caps the slabs at kmin + max_slices - 1.
 * Returns 0 when the pass writes nothing (edge-on, outside the grid). */
static int vx_vox_pass_setup(vx_vox_pass *p, const vx_vox_tri *T, int a, const int dims[3],
                             int max_slices)
{
    int i, swap;
    double ulo, uhi, wlo, whi;
    p->a = a;
    p->u = a == 2 ? 0 : a + 1;
    p->w = a == 0 ? 2 : a - 1;
    p->area2 = T->n[a];
    if (p->area2 == 0.0) return 0;
    for (i = 0; i < 3; i++) {
        p->U[i] = T->g[i][p->u];
        p->W[i] = T->g[i][p->w];
        p->Z[i] = T->g[i][a];
    }
    /* cheap rejections first: most triangles of a dense mesh cover no pixel centre */
    ulo = uhi = p->U[0];
    wlo = whi = p->W[0];
    p->zlo = p->zhi = p->Z[0];
    for (i = 1; i < 3; i++) {
        ulo = p->U[i] < ulo ? p->U[i] : ulo;
        uhi = p->U[i] > uhi ? p->U[i] : uhi;
        wlo = p->W[i] < wlo ? p->W[i] : wlo;
        whi = p->W[i] > whi ? p->W[i] : whi;
        p->zlo = p->Z[i] < p->zlo ? p->Z[i] : p->zlo;
        p->zhi = p->Z[i] > p->zhi ? p->Z[i] : p->zhi;
    }
    if (!vx_vox_pixel_range(ulo, uhi, dims[p->u], &p->bu0, &p->bu1)) return 0;
    if (!vx_vox_pixel_range(wlo, whi, dims[p->w], &p->bw0, &p->bw1)) return 0;
    /* slabs floor(zlo) .. floor(zhi) within [0, dims[a]); with a cap at most max_slices from
     * floor(zlo), the geometry shader's first slab even when it lies outside the grid */
    if (!(p->zhi >= 0.0) || !(p->zlo < (double)dims[a])) return 0;
    p->k0 = p->zlo <= 0.0 ? 0 : vx_vox_ifloor(p->zlo);
    p->k1 = p->zhi >= (double)(dims[a] - 1) ? dims[a] - 1 : vx_vox_ifloor(p->zhi);
    if (max_slices > 0) {
        double kmin = floor(p->zlo), k1 = kmin + (double)(max_slices - 1);
        if (k1 < (double)p->k1) p->k1 = k1 < 0.0 ? -1 : (int)k1;
        if (p->k0 > p->k1) return 0;
    }
    p->dzdu = -T->n[p->u] / T->n[a];
    p->dzdw = -T->n[p->w] / T->n[a];
    if (!(fabs(p->dzdu) <= VX_VOX_MAX_SLOPE) || !(fabs(p->dzdw) <= VX_VOX_MAX_SLOPE)) return 0;
    p->dudz = 0.0;
    /* counter-clockwise order in the (u, w) plane */
    swap = p->area2 < 0.0;
    for (i = 0; i < 3; i++) {
        int s = swap && i ? 3 - i : i; /* 0, 2, 1 when clockwise */
        p->q[i][0] = p->U[s];
        p->q[i][1] = p->W[s];
        p->q[i][2] = p->Z[s];
    }
    for (i = 0; i < 3; i++) {
        int j = i == 2 ? 0 : i + 1;
        double slope;
        vx_vox_edge_init(&p->e[i], p->q[i][0], p->q[i][1], p->q[j][0], p->q[j][1]);
        slope = -p->e[i].sign * p->e[i].dw;
        p->edir[i] = slope > 0.0 ? 1 : slope < 0.0 ? -1 : 0;
    }
    if (p->bu1 - p->bu0 >= VX_VOX_DIRECT_WIDTH) { /* rows are searched: their estimates */
        for (i = 0; i < 3; i++) vx_vox_edge_root(&p->e[i]);
        p->dudz = p->dzdu != 0.0 ? 1.0 / p->dzdu : 0.0;
    }
    return 1;
}

/* The plane's depth at pixel centre (cu, cw), clamped to the triangle's depth range (a no-op in
 * exact arithmetic; it keeps floor(z) inside the slabs the triangle spans). Monotone in cu. */
static double vx_vox_depth(const vx_vox_pass *p, double cu, double cw)
{
    double z = (p->Z[0] + p->dzdw * (cw - p->W[0])) + p->dzdu * (cu - p->U[0]);
    if (z < p->zlo) z = p->zlo;
    if (z > p->zhi) z = p->zhi;
    return z;
}

static int vx_vox_inside(const vx_vox_edge *e, int ne, double cu, double cw)
{
    int i;
    for (i = 0; i < ne; i++)
        if (!vx_vox_edge_pass(&e[i], cu, cw)) return 0;
    return 1;
}

/* ---- GS slicing: the slab piece (Alg. 5; Sutherland-Hodgman against both slab planes) ---- */

#define VX_VOX_PIECE_MAX 8

/* Crossing of the original edge (A, B) with the plane z = c, A.z != B.z, c strictly between:
 * computed from the lower-depth endpoint, so every piece and every triangle sharing the edge
 * gets the same point. */
static void vx_vox_cross(const double *A, const double *B, double c, double out[2])
{
    const double *P = A[2] < B[2] ? A : B, *Q = A[2] < B[2] ? B : A;
    double t = (c - P[2]) / (Q[2] - P[2]);
    out[0] = P[0] + t * (Q[0] - P[0]);
    out[1] = P[1] + t * (Q[1] - P[1]);
}

/* The piece of the pass's triangle in slab [k, k+1] (closed), counter-clockwise, as (u, w)
 * points: each edge Qi -> Qj contributes Qi if it lies in the slab, then its crossings with the
 * planes k and k+1 strictly between Qi.z and Qj.z, in order along the edge. This is the
 * Sutherland-Hodgman clip of the triangle by the two planes with every crossing taken from an
 * original edge. Returns the vertex count and its edges; 0 if the piece has no area. */
static int vx_vox_piece(const vx_vox_pass *p, double k, vx_vox_edge *edges, double *bb)
{
    double pt[VX_VOX_PIECE_MAX][2], area2 = 0.0;
    int n = 0, i;
    for (i = 0; i < 3; i++) {
        const double *A = p->q[i], *B = p->q[(i + 1) % 3];
        double c0 = A[2] < B[2] ? k : k + 1.0, c1 = A[2] < B[2] ? k + 1.0 : k;
        if (A[2] >= k && A[2] <= k + 1.0) {
            pt[n][0] = A[0];
            pt[n][1] = A[1];
            n++;
        }
        if ((A[2] < c0 && c0 < B[2]) || (B[2] < c0 && c0 < A[2])) vx_vox_cross(A, B, c0, pt[n++]);
        if ((A[2] < c1 && c1 < B[2]) || (B[2] < c1 && c1 < A[2])) vx_vox_cross(A, B, c1, pt[n++]);
    }
    if (n < 3) return 0;
    for (i = 0; i < n; i++) {
        int j = (i + 1) % n;
        area2 += (pt[i][0] - pt[0][0]) * (pt[j][1] - pt[0][1])
                 - (pt[j][0] - pt[0][0]) * (pt[i][1] - pt[0][1]);
    }
    if (!(area2 > 0.0)) return 0;
    bb[0] = bb[1] = pt[0][0];
    bb[2] = bb[3] = pt[0][1];
    for (i = 0; i < n; i++) {
        int j = (i + 1) % n;
        vx_vox_edge_init(&edges[i], pt[i][0], pt[i][1], pt[j][0], pt[j][1]);
        vx_vox_edge_root(&edges[i]);
        bb[0] = pt[i][0] < bb[0] ? pt[i][0] : bb[0];
        bb[1] = pt[i][0] > bb[1] ? pt[i][0] : bb[1];
        bb[2] = pt[i][1] < bb[2] ? pt[i][1] : bb[2];
        bb[3] = pt[i][1] > bb[3] ? pt[i][1] : bb[3];
    }
    return n;
}

/* ---- the fragment sink: occupancy bytes or the Volume Buffer with its blends ------------- */

typedef struct vx_vox_sink {
    const hfvis_volume_grid *grid;
    hfvis_volume *vol;  /* or NULL */
    uint8_t *occ;       /* or NULL */
    hfvis_voxel_fragment_fn fn;
    void *user;
    size_t count;
    size_t stride[3];   /* linear-index step per axis */
    const vx_vox_tri *tri;
} vx_vox_sink;

/* The fragment of pixel centre (cu, cw) of pass p written to voxel v. */
static void vx_vox_fragment_fill(hfvis_voxel_fragment *f, const vx_vox_tri *T,
                                 const vx_vox_pass *p, const int v[3])
{
    double cu = (double)v[p->u] + 0.5, cw = (double)v[p->w] + 0.5, b[3];
    int i, a;
    for (i = 0; i < 3; i++) {
        int j = (i + 1) % 3, k = (i + 2) % 3; /* edge opposite vertex i: j -> k */
        b[i] = ((p->U[k] - p->U[j]) * (cw - p->W[j]) - (p->W[k] - p->W[j]) * (cu - p->U[j]))
               / p->area2;
    }
    for (a = 0; a < 3; a++) {
        f->voxel[a] = v[a];
        f->barycentric[a] = (float)b[a];
        f->position[a] = (float)(b[0] * T->v[0][a] + b[1] * T->v[1][a] + b[2] * T->v[2][a]);
        f->normal[a] = T->normal[a];
    }
    f->axis = p->a;
    f->triangle = T->id;
}

/* Write pixels u0..u1 of row pw into slab k. */
static void vx_vox_emit(vx_vox_sink *s, const vx_vox_pass *p, int pw, int u0, int u1, int k)
{
    int v[3], pu;
    size_t lin, step = s->stride[p->u];
    v[p->a] = k;
    v[p->w] = pw;
    v[p->u] = u0;
    lin = ((size_t)v[2] * (size_t)s->grid->dims[1] + (size_t)v[1]) * (size_t)s->grid->dims[0]
          + (size_t)v[0];
    s->count += (size_t)(u1 - u0 + 1);
    if (s->occ) {
        for (pu = u0; pu <= u1; pu++, lin += step) s->occ[lin] = 1;
    } else if (!s->fn) {
        size_t C = (size_t)s->vol->channels;
        float *d = s->vol->data;
        hfvis_blend op = s->vol->blend[0];
        for (pu = u0; pu <= u1; pu++, lin += step) d[lin * C] = vx_blend_apply(op, d[lin * C], 1.0f);
    } else {
        int C = s->vol->channels, c;
        float values[HFVIS_VOLUME_MAX_CHANNELS];
        hfvis_voxel_fragment f;
        for (pu = u0; pu <= u1; pu++, lin += step) {
            float *d = s->vol->data + lin * (size_t)C;
            v[p->u] = pu;
            vx_vox_fragment_fill(&f, s->tri, p, v);
            memset(values, 0, sizeof values);
            s->fn(&f, values, s->user);
            for (c = 0; c < C; c++) d[c] = vx_blend_apply(s->vol->blend[c], d[c], values[c]);
        }
    }
}

/* ---- rows: hoisted row constants and monotone boundary searches ------------------------- */

/* One pixel row (centre cw) of a polygon: the non-degenerate edges with the row's constant
 * part of each edge function, K = du (cw - lw), and of the depth, zrow = Z0 + dz/dw (cw - W0).
 * The per-pixel values below use the same operations in the same order as vx_vox_edge_value
 * and vx_vox_depth, so they are bit-identical to the oracle's. */
typedef struct vx_vox_row_ctx {
    const vx_vox_edge *e[VX_VOX_PIECE_MAX];
    double K[VX_VOX_PIECE_MAX];
    int ne;
    double cw, zrow;
    const vx_vox_pass *p;
} vx_vox_row_ctx;

static void vx_vox_row_init(vx_vox_row_ctx *r, const vx_vox_edge *e, int ne, const vx_vox_pass *p,
                            double cw)
{
    int i;
    r->ne = 0;
    for (i = 0; i < ne; i++)
        if (!e[i].skip) {
            r->e[r->ne] = &e[i];
            r->K[r->ne++] = e[i].du * (cw - e[i].lw);
        }
    r->cw = cw;
    r->p = p;
    r->zrow = p->Z[0] + p->dzdw * (cw - p->W[0]);
}

static int vx_vox_row_edge_pass(const vx_vox_edge *e, double K, double cu)
{
    double v = e->sign * (K - e->dw * (cu - e->lu));
    return v > 0.0 || (v == 0.0 && e->owned);
}

static int vx_vox_row_inside(const vx_vox_row_ctx *r, double cu)
{
    int i;
    for (i = 0; i < r->ne; i++)
        if (!vx_vox_row_edge_pass(r->e[i], r->K[i], cu)) return 0;
    return 1;
}

static double vx_vox_row_depth(const vx_vox_row_ctx *r, double cu)
{
    const vx_vox_pass *p = r->p;
    double z = r->zrow + p->dzdu * (cu - p->U[0]);
    if (z < p->zlo) z = p->zlo;
    if (z > p->zhi) z = p->zhi;
    return z;
}

/* Galloping search body: the first x in [lo, hi] where PRED(x) holds, PRED nondecreasing in x
 * (false ... true), hi + 1 if none, starting from the estimate `guess` (a pixel coordinate; any
 * value, NaN included, is safe). O(1) evaluations when the estimate is within a pixel, O(log)
 * otherwise. */
#define VX_VOX_GALLOP(PRED)                                                                    \
    int g, t, f, step = 1;                                                                     \
    if (lo > hi) return lo;                                                                    \
    if (!(guess > (double)lo)) g = lo;                                                         \
    else if (!(guess < (double)hi)) g = hi;                                                    \
    else g = vx_vox_iceil(guess);                                                              \
    if (PRED(g)) {                                                                             \
        for (t = g;;) {                                                                        \
            if (t - lo < step) { f = lo - 1; break; }                                          \
            f = t - step;                                                                      \
            if (!PRED(f)) break;                                                               \
            t = f;                                                                             \
            if (step < (1 << 29)) step *= 2;                                                   \
        }                                                                                      \
    } else {                                                                                   \
        for (f = g;;) {                                                                        \
            if (hi - f < step) { t = hi + 1; break; }                                          \
            t = f + step;                                                                      \
            if (PRED(t)) break;                                                                \
            f = t;                                                                             \
            if (step < (1 << 29)) step *= 2;                                                   \
        }                                                                                      \
    }                                                                                          \
    while (t - f > 1) {                                                                        \
        int mid = f + (t - f) / 2;                                                             \
        if (PRED(mid)) t = mid;                                                                \
        else f = mid;                                                                          \
    }                                                                                          \
    return t

/* First pixel in [lo, hi] where the edge test equals `want` (monotone that way). */
static int vx_vox_edge_first(const vx_vox_edge *e, double K, int want, int lo, int hi, double guess)
{
#define VX_VOX_PRED_EDGE(x) (vx_vox_row_edge_pass(e, K, (double)(x) + 0.5) == want)
    VX_VOX_GALLOP(VX_VOX_PRED_EDGE);
#undef VX_VOX_PRED_EDGE
}

/* First pixel in [lo, hi] where (depth >= thr) equals `want` (monotone that way). */
static int vx_vox_depth_first(const vx_vox_row_ctx *r, double thr, int want, int lo, int hi,
                              double guess)
{
#define VX_VOX_PRED_DEPTH(x) ((vx_vox_row_depth(r, (double)(x) + 0.5) >= thr) == want)
    VX_VOX_GALLOP(VX_VOX_PRED_DEPTH);
#undef VX_VOX_PRED_DEPTH
}

/* The pixels [*L, *R] of the row within [lo, hi] inside every edge; 0 if none. Each edge
 * function is monotone along the row, so each edge bounds the span on one side. */
static int vx_vox_row_span(const vx_vox_row_ctx *r, int lo, int hi, int *L, int *R)
{
    int i;
    for (i = 0; i < r->ne && lo <= hi; i++) {
        const vx_vox_edge *e = r->e[i];
        double slope = -e->sign * e->dw; /* dE/dcu */
        if (slope == 0.0) {              /* constant along the row */
            if (!vx_vox_row_edge_pass(e, r->K[i], (double)lo + 0.5)) return 0;
            continue;
        }
        /* estimate: the root u = lu + (du/dw)(cw - lw), as a pixel index */
        if (slope > 0.0) /* inside on a suffix */
            lo = vx_vox_edge_first(e, r->K[i], 1, lo, hi, e->lu + e->root_du * (r->cw - e->lw) - 0.5);
        else             /* inside on a prefix */
            hi = vx_vox_edge_first(e, r->K[i], 0, lo, hi, e->lu + e->root_du * (r->cw - e->lw) - 0.5) - 1;
    }
    *L = lo;
    *R = hi;
    return lo <= hi;
}

/* Pixel estimate where the depth reaches thr along the row. */
static double vx_vox_depth_guess(const vx_vox_row_ctx *r, double thr)
{
    return r->p->U[0] + (thr - r->zrow) * r->p->dudz - 0.5;
}

/* Write the pixels L..R of row pw (all inside the triangle) whose slab lies in [s0, s1], each
 * into its slab: the runs of constant slab are delimited by searching the slab boundaries. */
static void vx_vox_row_slabs(vx_vox_sink *s, const vx_vox_row_ctx *r, int pw, int L, int R, int s0,
                             int s1)
{
    const vx_vox_pass *p = r->p;
    double lo_thr = (double)s0, hi_thr = (double)s1 + 1.0;
    int cur;
    if (p->dzdu == 0.0) { /* depth constant along the row */
        double z = vx_vox_row_depth(r, (double)L + 0.5);
        if (z >= lo_thr && z < hi_thr) vx_vox_emit(s, p, pw, L, R, vx_vox_ifloor(z));
        return;
    }
    if (fabs(p->dzdu) > VX_VOX_STEEP) { /* short runs: the slab of each pixel, grouped in runs */
        int k = 0, start = -1, pu;
        for (pu = L; pu <= R; pu++) {
            double z = vx_vox_row_depth(r, (double)pu + 0.5);
            int kk = z >= lo_thr && z < hi_thr ? vx_vox_ifloor(z) : -1;
            if (start >= 0 && kk != k) {
                vx_vox_emit(s, p, pw, start, pu - 1, k);
                start = -1;
            }
            if (kk >= 0 && start < 0) start = pu, k = kk;
        }
        if (start >= 0) vx_vox_emit(s, p, pw, start, R, k);
        return;
    }
    if (p->dzdu > 0.0) { /* slab nondecreasing along the row */
        /* restrict to [s0, s1] only where the row's ends leave it (grid border, cap, slab) */
        if (!(vx_vox_row_depth(r, (double)L + 0.5) >= lo_thr))
            L = vx_vox_depth_first(r, lo_thr, 1, L, R, vx_vox_depth_guess(r, lo_thr));
        if (L <= R && !(vx_vox_row_depth(r, (double)R + 0.5) < hi_thr))
            R = vx_vox_depth_first(r, hi_thr, 1, L, R, vx_vox_depth_guess(r, hi_thr)) - 1;
        for (cur = L; cur <= R;) {
            int k = vx_vox_ifloor(vx_vox_row_depth(r, (double)cur + 0.5)), nxt;
            double thr = (double)k + 1.0;
            if (!(vx_vox_row_depth(r, (double)R + 0.5) >= thr)) nxt = R + 1; /* one run to R */
            else nxt = vx_vox_depth_first(r, thr, 1, cur + 1, R, vx_vox_depth_guess(r, thr));
            vx_vox_emit(s, p, pw, cur, nxt - 1, k);
            cur = nxt;
        }
    } else { /* slab nonincreasing along the row */
        if (!(vx_vox_row_depth(r, (double)L + 0.5) < hi_thr))
            L = vx_vox_depth_first(r, hi_thr, 0, L, R, vx_vox_depth_guess(r, hi_thr));
        if (L <= R && !(vx_vox_row_depth(r, (double)R + 0.5) >= lo_thr))
            R = vx_vox_depth_first(r, lo_thr, 0, L, R, vx_vox_depth_guess(r, lo_thr)) - 1;
        for (cur = L; cur <= R;) {
            int k = vx_vox_ifloor(vx_vox_row_depth(r, (double)cur + 0.5)), nxt;
            double thr = (double)k; /* first pixel with depth < k */
            if (vx_vox_row_depth(r, (double)R + 0.5) >= thr) nxt = R + 1; /* one run to R */
            else nxt = vx_vox_depth_first(r, thr, 0, cur + 1, R, vx_vox_depth_guess(r, thr));
            vx_vox_emit(s, p, pw, cur, nxt - 1, k);
            cur = nxt;
        }
    }
}

/* ---- the three methods, fast ------------------------------------------------------------- */

/* The first pixel of [lo, hi] where an edge monotone along the row passes (inc != 0: it passes
 * on a suffix) or fails (inc == 0: it passes on a prefix), hi + 1 if none; `est` is the root
 * estimate. Most rows are settled by two evaluations at the estimate; otherwise gallop. */
static int vx_vox_edge_threshold(const vx_vox_edge *e, double K, int inc, int lo, int hi, double est)
{
    int g;
    if (!(est > (double)lo)) g = lo;
    else if (!(est < (double)hi)) g = hi;
    else g = vx_vox_iceil(est);
    if ((vx_vox_row_edge_pass(e, K, (double)g + 0.5) == inc)
        && (g == lo || (vx_vox_row_edge_pass(e, K, (double)g - 0.5) != inc)))
        return g;
    return vx_vox_edge_first(e, K, inc, lo, hi, est);
}

/* The pixels of row pw of the pass's triangle whose slab lies in [s0, s1]. */
static void vx_vox_row(vx_vox_sink *s, const vx_vox_pass *p, int pw, int s0, int s1)
{
    vx_vox_row_ctx r;
    int i, L = p->bu0, R = p->bu1;
    r.cw = (double)pw + 0.5;
    r.p = p;
    r.ne = 3;
    for (i = 0; i < 3; i++) {
        r.e[i] = &p->e[i];
        r.K[i] = p->e[i].du * (r.cw - p->e[i].lw);
    }
    r.zrow = p->Z[0] + p->dzdw * (r.cw - p->W[0]);
    if (R - L < VX_VOX_DIRECT_WIDTH) { /* narrow: test each pixel */
        int pu;
        for (pu = L; pu <= R; pu++) {
            double cu = (double)pu + 0.5, z;
            if (!vx_vox_row_edge_pass(&p->e[0], r.K[0], cu) || !vx_vox_row_edge_pass(&p->e[1], r.K[1], cu)
                || !vx_vox_row_edge_pass(&p->e[2], r.K[2], cu))
                continue;
            z = vx_vox_row_depth(&r, cu); /* slab floor(z) in [s0, s1] */
            if (z >= (double)s0 && z < (double)s1 + 1.0) vx_vox_emit(s, p, pw, pu, pu, vx_vox_ifloor(z));
        }
        return;
    }
    for (i = 0; i < 3 && L <= R; i++) { /* a triangle's edges are never degenerate */
        const vx_vox_edge *e = &p->e[i];
        double est;
        if (p->edir[i] == 0) { /* constant along the row */
            if (!vx_vox_row_edge_pass(e, r.K[i], (double)L + 0.5)) return;
            continue;
        }
        est = e->lu + e->root_du * (r.cw - e->lw) - 0.5; /* root, as a pixel index */
        if (p->edir[i] > 0) L = vx_vox_edge_threshold(e, r.K[i], 1, L, R, est);
        else R = vx_vox_edge_threshold(e, r.K[i], 0, L, R, est) - 1;
    }
    if (L <= R) vx_vox_row_slabs(s, &r, pw, L, R, s0, s1);
}

/* Pixel rule ([G12] ch. 6): every covered pixel of the pass into the slab of its depth. */
static void vx_vox_fast_pixel_rule(vx_vox_sink *s, const vx_vox_pass *p)
{
    int pw;
    for (pw = p->bw0; pw <= p->bw1; pw++) vx_vox_row(s, p, pw, p->k0, p->k1);
}

/* Fragment clipping ([G12] Alg. 6): for each slab (lowest first, capped), the whole triangle is
 * rasterised again and only the fragments whose depth lies in [k, k+1) are kept. */
static void vx_vox_fast_fragment_clipping(vx_vox_sink *s, const vx_vox_pass *p)
{
    int k, pw;
    for (k = p->k0; k <= p->k1; k++)
        for (pw = p->bw0; pw <= p->bw1; pw++) vx_vox_row(s, p, pw, k, k);
}

/* GS slicing ([G12] Alg. 5): the slab pieces (lowest first, capped), each rasterised into its
 * slab with the pixel-centre rule on its own edges. */
static void vx_vox_fast_gs_slicing(vx_vox_sink *s, const vx_vox_pass *p, const int dims[3])
{
    vx_vox_edge pe[VX_VOX_PIECE_MAX];
    vx_vox_row_ctx r;
    double bb[4];
    int k, n, pw, pu, u0, u1, w0, w1, L, R;
    for (k = p->k0; k <= p->k1; k++) {
        n = vx_vox_piece(p, (double)k, pe, bb);
        if (n == 0 || !vx_vox_pixel_range(bb[0], bb[1], dims[p->u], &u0, &u1)
            || !vx_vox_pixel_range(bb[2], bb[3], dims[p->w], &w0, &w1))
            continue;
        for (pw = w0; pw <= w1; pw++) {
            vx_vox_row_init(&r, pe, n, p, (double)pw + 0.5);
            if (u1 - u0 < VX_VOX_DIRECT_WIDTH) {
                for (pu = u0; pu <= u1; pu++)
                    if (vx_vox_row_inside(&r, (double)pu + 0.5)) vx_vox_emit(s, p, pw, pu, pu, k);
            } else if (vx_vox_row_span(&r, u0, u1, &L, &R))
                vx_vox_emit(s, p, pw, L, R, k);
        }
    }
}

/* ---- the oracle (per voxel of the bounding box) ------------------------------------------ */

static void vx_vox_reference_pass(vx_vox_sink *s, const vx_vox_pass *p, hfvis_voxelize_method method,
                                  const int dims[3])
{
    int k, pu, pw;
    for (k = p->k0; k <= p->k1; k++) {
        if (method == HFVIS_VOXELIZE_GS_SLICING) {
            vx_vox_edge pe[VX_VOX_PIECE_MAX];
            double bb[4];
            int n = vx_vox_piece(p, (double)k, pe, bb), u0, u1, w0, w1;
            if (n == 0 || !vx_vox_pixel_range(bb[0], bb[1], dims[p->u], &u0, &u1)
                || !vx_vox_pixel_range(bb[2], bb[3], dims[p->w], &w0, &w1))
                continue;
            for (pw = w0; pw <= w1; pw++)
                for (pu = u0; pu <= u1; pu++)
                    if (vx_vox_inside(pe, n, (double)pu + 0.5, (double)pw + 0.5))
                        vx_vox_emit(s, p, pw, pu, pu, k);
        } else {
            for (pw = p->bw0; pw <= p->bw1; pw++)
                for (pu = p->bu0; pu <= p->bu1; pu++) {
                    double cu = (double)pu + 0.5, cw = (double)pw + 0.5, z;
                    if (!vx_vox_inside(p->e, 3, cu, cw)) continue;
                    z = vx_vox_depth(p, cu, cw);
                    if ((double)k <= z && z < (double)k + 1.0) vx_vox_emit(s, p, pw, pu, pu, k);
                }
        }
    }
}

/* ---- driver ------------------------------------------------------------------------------ */

typedef struct vx_vox_cfg {
    hfvis_voxelize_method method;
    hfvis_voxelize_axes axes;
    int max_slices; /* 0 = unlimited */
    hfvis_voxel_fragment_fn fn;
    void *user;
} vx_vox_cfg;

static hfvis_status vx_vox_resolve(const hfvis_voxelize_options *o, vx_vox_cfg *c)
{
    hfvis_voxelize_options d;
    memset(&d, 0, sizeof d);
    if (!o) o = &d;
    if (o->method != HFVIS_VOXELIZE_PIXEL_RULE && o->method != HFVIS_VOXELIZE_GS_SLICING
        && o->method != HFVIS_VOXELIZE_FRAGMENT_CLIPPING)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o->axes != HFVIS_AXES_DOMINANT && o->axes != HFVIS_AXES_ALL && o->axes != HFVIS_AXES_ONLY_X
        && o->axes != HFVIS_AXES_ONLY_Y && o->axes != HFVIS_AXES_ONLY_Z)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o->max_output_vertices < 0) return HFVIS_ERR_INVALID_ARGUMENT;
    c->max_slices = 0;
    if (o->max_output_vertices > 0) {
        if (o->method == HFVIS_VOXELIZE_PIXEL_RULE) return HFVIS_ERR_INVALID_ARGUMENT;
        c->max_slices = hfvis_gs_max_slices(o->max_output_vertices,
                                            o->method == HFVIS_VOXELIZE_FRAGMENT_CLIPPING);
        if (c->max_slices < 1) return HFVIS_ERR_INVALID_ARGUMENT;
    }
    c->method = o->method;
    c->axes = o->axes;
    c->fn = o->fragment;
    c->user = o->user;
    return HFVIS_OK;
}

static void vx_vox_run(const hfvis_mesh *m, const vx_vox_cfg *c, vx_vox_sink *s, int reference)
{
    const hfvis_volume_grid *g = s->grid;
    int npass = c->axes == HFVIS_AXES_ALL ? 3 : 1, pass;
    size_t t;
    vx_vox_tri T;
    vx_vox_pass P;
    s->stride[0] = 1;
    s->stride[1] = (size_t)g->dims[0];
    s->stride[2] = (size_t)g->dims[0] * (size_t)g->dims[1];
    s->tri = &T;
    for (pass = 0; pass < npass; pass++)
        for (t = 0; t < m->triangle_count; t++) {
            int a;
            if (!vx_vox_tri_setup(&T, m, g, t, s->fn != NULL)) continue;
            switch (c->axes) {
            case HFVIS_AXES_DOMINANT: a = vx_vox_dominant(T.n); break;
            case HFVIS_AXES_ONLY_X: a = 0; break;
            case HFVIS_AXES_ONLY_Y: a = 1; break;
            case HFVIS_AXES_ONLY_Z: a = 2; break;
            case HFVIS_AXES_ALL:
            default: a = pass; break;
            }
            if (!vx_vox_pass_setup(&P, &T, a, g->dims,
                                   c->method == HFVIS_VOXELIZE_PIXEL_RULE ? 0 : c->max_slices))
                continue;
            if (reference) vx_vox_reference_pass(s, &P, c->method, g->dims);
            else if (c->method == HFVIS_VOXELIZE_GS_SLICING) vx_vox_fast_gs_slicing(s, &P, g->dims);
            else if (c->method == HFVIS_VOXELIZE_FRAGMENT_CLIPPING) vx_vox_fast_fragment_clipping(s, &P);
            else vx_vox_fast_pixel_rule(s, &P);
        }
    s->tri = NULL; /* T is local */
}

static hfvis_status vx_vox_surface(const hfvis_mesh *mesh, hfvis_volume *vol,
                                   const hfvis_voxelize_options *opts, size_t *fragments_written,
                                   int reference)
{
    vx_vox_cfg cfg;
    vx_vox_sink s;
    int c;
    hfvis_status st;
    if (hfvis__mesh_check(mesh) != HFVIS_OK || !vol || !vol->data || !vx_grid_valid(&vol->grid)
        || vol->channels < 1 || vol->channels > HFVIS_VOLUME_MAX_CHANNELS)
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (c = 0; c < vol->channels; c++)
        if (!vx_blend_valid(vol->blend[c])) return HFVIS_ERR_INVALID_ARGUMENT;
    st = vx_vox_resolve(opts, &cfg);
    if (st != HFVIS_OK) return st;
    memset(&s, 0, sizeof s);
    s.grid = &vol->grid;
    s.vol = vol;
    s.fn = cfg.fn;
    s.user = cfg.user;
    vx_vox_run(mesh, &cfg, &s, reference);
    if (fragments_written) *fragments_written = s.count;
    return HFVIS_OK;
}

HFVIS_API hfvis_voxelize_options hfvis_voxelize_options_default(void)
{
    hfvis_voxelize_options o;
    memset(&o, 0, sizeof o);
    o.method = HFVIS_VOXELIZE_PIXEL_RULE;
    o.axes = HFVIS_AXES_DOMINANT;
    o.max_output_vertices = 0;
    o.fragment = NULL;
    o.user = NULL;
    o.alloc = NULL;
    return o;
}

HFVIS_API int hfvis_gs_max_slices(int max_output_vertices, int pixel_clipping)
{
    int v = max_output_vertices;
    if (pixel_clipping) return v >= 3 ? v / 3 : 0;   /* 3n vertices for n slabs */
    return v >= 7 ? (v - 3) / 4 : 0;                  /* 3 + 4n vertices for n slabs */
}

HFVIS_API hfvis_status hfvis_voxelize_surface(const hfvis_mesh *mesh, hfvis_volume *vol,
                                              const hfvis_voxelize_options *opts,
                                              size_t *fragments_written)
{
    return vx_vox_surface(mesh, vol, opts, fragments_written, 0);
}

HFVIS_API hfvis_status hfvis_voxelize_surface_reference(const hfvis_mesh *mesh, hfvis_volume *vol,
                                                        const hfvis_voxelize_options *opts,
                                                        size_t *fragments_written)
{
    return vx_vox_surface(mesh, vol, opts, fragments_written, 1);
}

HFVIS_API hfvis_status hfvis_voxelize_occupancy(const hfvis_mesh *mesh,
                                                const hfvis_volume_grid *grid,
                                                const hfvis_voxelize_options *opts, uint8_t *occ)
{
    vx_vox_cfg cfg;
    vx_vox_sink s;
    hfvis_status st;
    if (hfvis__mesh_check(mesh) != HFVIS_OK || !vx_grid_valid(grid) || !occ)
        return HFVIS_ERR_INVALID_ARGUMENT;
    st = vx_vox_resolve(opts, &cfg);
    if (st != HFVIS_OK) return st;
    memset(occ, 0, vx_grid_voxels(grid));
    memset(&s, 0, sizeof s);
    s.grid = grid;
    s.occ = occ;
    vx_vox_run(mesh, &cfg, &s, 0);
    return HFVIS_OK;
}

/* ---- ready-made attribute callbacks ([G12] §6.5) ----------------------------------------- */

HFVIS_API void hfvis_voxel_fragment_occupancy(const hfvis_voxel_fragment *f, float *values,
                                              void *user)
{
    (void)f;
    (void)user;
    values[0] = 1.0f;
}

HFVIS_API void hfvis_voxel_fragment_normal_occupancy(const hfvis_voxel_fragment *f, float *values,
                                                     void *user)
{
    (void)user;
    values[0] = 1.0f;
    values[1] = f->normal[0];
    values[2] = f->normal[1];
    values[3] = f->normal[2];
}

HFVIS_API int hfvis_voxel_attribute_channel(unsigned flags, unsigned attribute)
{
    static const unsigned order[4] = { HFVIS_VOXEL_ATTR_OCCUPANCY, HFVIS_VOXEL_ATTR_NORMAL,
                                       HFVIS_VOXEL_ATTR_ALBEDO, HFVIS_VOXEL_ATTR_RADIANCE };
    int c = 0, i;
    if (flags == 0) flags = HFVIS_VOXEL_ATTR_OCCUPANCY;
    for (i = 0; i < 4; i++) {
        if (!(flags & order[i])) continue;
        if (attribute == order[i]) return c;
        c += i == 0 ? 1 : 3;
    }
    return attribute == 0 ? c : -1;
}

HFVIS_API void hfvis_voxel_fragment_attributes(const hfvis_voxel_fragment *f, float *values,
                                               void *user)
{
    const hfvis_voxel_attributes *at = (const hfvis_voxel_attributes *)user;
    unsigned flags;
    float alb[3] = { 1.0f, 1.0f, 1.0f };
    int c = 0, i;
    if (!at) { /* no layout: occupancy only */
        values[0] = 1.0f;
        return;
    }
    flags = at->flags ? at->flags : HFVIS_VOXEL_ATTR_OCCUPANCY;
    if (at->albedo)
        for (i = 0; i < 3; i++) alb[i] = at->albedo[3 * (size_t)f->triangle + (size_t)i];
    if (flags & HFVIS_VOXEL_ATTR_OCCUPANCY) values[c++] = 1.0f;
    if (flags & HFVIS_VOXEL_ATTR_NORMAL)
        for (i = 0; i < 3; i++) values[c++] = f->normal[i];
    if (flags & HFVIS_VOXEL_ATTR_ALBEDO)
        for (i = 0; i < 3; i++) values[c++] = alb[i];
    if (flags & HFVIS_VOXEL_ATTR_RADIANCE) {
        float e[3] = { 0.0f, 0.0f, 0.0f };
        if (at->irradiance) at->irradiance(f->position, f->normal, e, at->irradiance_user);
        for (i = 0; i < 3; i++) {
            double L = (double)alb[i] * (double)e[i] / HFVIS__PI;
            if (at->emission) L += (double)at->emission[3 * (size_t)f->triangle + (size_t)i];
            values[c++] = (float)L;
        }
    }
}

/* ========================================================================================== */
/* 8. Binary voxelizers: conservative (triangle-box SAT), solid (parity), bitmask; .binvox/raw */
/*    ([G12] ch. 6 baselines: T. Akenine-Moller, "Fast 3D triangle-box overlap testing",       */
/*    JGT 2001 - the 13-axis separating-axis test; M. Schwarz & H.-P. Seidel, "Fast parallel   */
/*    surface and solid voxelization on GPUs", SIGGRAPH Asia 2010 - its per-triangle setup;   */
/*    solid voxelization by parity / XOR, Chen & Fang 1998, Eisemann & Decoret 2008;          */
/*    E. Eisemann & X. Decoret, "Fast scene voxelization and applications", I3D 2006 - the    */
/*    bitmask ("slicemap") layout; the binvox format of P. Min / M. Kazhdan)                  */
/* ========================================================================================== */
/* Contents
 *   8a. grid space, ranges and the SAT predicate (hfvis_triangle_box_overlap)
 *   8b. conservative voxelization: per-voxel SAT reference and the certified-bounds fast path
 *   8c. exact 2D orientation signs and the watertight pixel-centre coverage rule
 *   8d. solid voxelization by parity (fast: toggles + prefix XOR; reference: winding number)
 *   8e. watertightness of the index structure
 *   8f. bitmask voxelization (three-axis OR, slicemap layout)
 *   8g. .binvox codec and the raw writer
 *
 * Everything is decided in GRID SPACE: a vertex p becomes g = (p - origin) / cell (per axis, in
 * double), so voxel (i, j, k) is the unit cube [i, i+1] x [j, j+1] x [k, k+1] and its centre is
 * (i + 0.5, j + 0.5, k + 0.5). */

/* ---- 8a. grid space, ranges and the SAT predicate --------------------------------------- */

/* Grid coordinates beyond this magnitude (in cells) make the products of the predicates below
 * lose their guarantees (overflow of the exact 2D orientation, int conversions): such meshes
 * are refused with HFVIS_ERR_LIMIT. 2^60 cells is far outside any grid. */
#define VX_CONS_MAX_COORD 1152921504606846976.0 /* 2^60 */

#ifndef VX_CONS_SMALL_BOX
#define VX_CONS_SMALL_BOX 16 /* bounding boxes of at most this many voxels: direct SAT */
#endif

/* C99 inline for the few hot helpers of the fast path (no effect on results). */
#define VX_CONS_INLINE inline

/* Grid-space coordinate of world coordinate x on axis a. The ONE expression every binary
 * voxelizer and its reference uses, so they see the same doubles. */
static double vx_cons_gc(const hfvis_volume_grid *g, int a, float x)
{
    return ((double)x - g->origin[a]) / g->cell[a];
}

/* Grid-space vertex vi of a mesh. */
static void vx_cons_gvert(const hfvis_mesh *m, const hfvis_volume_grid *g, uint32_t vi,
                          double out[3])
{
    const float *p = m->xyz + 3 * (size_t)vi;
    out[0] = vx_cons_gc(g, 0, p[0]);
    out[1] = vx_cons_gc(g, 1, p[1]);
    out[2] = vx_cons_gc(g, 2, p[2]);
}

/* Checks the common arguments of the binary voxelizers; HFVIS_ERR_LIMIT when a vertex lies
 * beyond VX_CONS_MAX_COORD cells. */
static hfvis_status vx_cons_args(const hfvis_mesh *mesh, const hfvis_volume_grid *grid,
                                 const void *out)
{
    size_t v;
    int a;
    if (!out || !vx_grid_valid(grid) || hfvis__mesh_check(mesh) != HFVIS_OK)
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (v = 0; v < mesh->vertex_count; v++)
        for (a = 0; a < 3; a++) {
            double c = vx_cons_gc(grid, a, mesh->xyz[3 * v + (size_t)a]);
            if (!(fabs(c) <= VX_CONS_MAX_COORD)) return HFVIS_ERR_LIMIT;
        }
    return HFVIS_OK;
}

/* Voxel range [*lo, *hi] along one axis of the voxels whose CLOSED extent [i, i+1] meets the
 * closed interval [mn, mx] (grid units), clipped to [0, n-1]: i from ceil(mn) - 1 to floor(mx).
 * Returns 0 when it is empty. mn, mx are within +-VX_CONS_MAX_COORD. */
static int vx_cons_range(double mn, double mx, int n, int *lo, int *hi)
{
    double l = ceil(mn) - 1.0, h = floor(mx);
    if (l < 0.0) l = 0.0;
    if (h > (double)(n - 1)) h = (double)(n - 1);
    if (l > h) return 0;
    *lo = (int)l;
    *hi = (int)h;
    return 1;
}

static double vx_cons_min3(double a, double b, double c)
{
    double m = a < b ? a : b;
    return m < c ? m : c;
}

static double vx_cons_max3(double a, double b, double c)
{
    double m = a > b ? a : b;
    return m > c ? m : c;
}

/* The triangle normal n = f0 x f1 with f0 = v1 - v0, f1 = v2 - v1 (the ONE formula both the
 * SAT and the fast path use). */
static void vx_cons_normal(const double f0[3], const double f1[3], double n[3])
{
    n[0] = f0[1] * f1[2] - f0[2] * f1[1];
    n[1] = f0[2] * f1[0] - f0[0] * f1[2];
    n[2] = f0[0] * f1[1] - f0[1] * f1[0];
}

/* One edge axis L = e_a x f_j of the SAT, in the projection along box axis a with in-plane axes
 * u = a+1, w = a+2 (mod 3): L_u = -f_w, L_w = f_u. The triangle projects to p = L_u t_u + L_w t_w
 * of its vertices t (relative to the box centre); only two vertices are needed, the start of
 * edge j (the end projects to the same value in exact arithmetic) and the opposite vertex. The
 * box projects to [-r, r], r = h_u |L_u| + h_w |L_w|. Returns 1 when the axis SEPARATES.
 * Every caller evaluates exactly these expressions in this order (see 5b). */
static int vx_cons_sep2(double Lu, double Lw, double r, double su, double sw, double ou,
                        double ow)
{
    double p = Lu * su + Lw * sw, q = Lu * ou + Lw * ow;
    double mn = p < q ? p : q, mx = p < q ? q : p;
    return mn > r || mx < -r;
}

/* Plane axis: d = n . t0 evaluated ((n_x t_x + n_y t_y) + n_z t_z), radius
 * r = (h_x |n_x| + h_y |n_y|) + h_z |n_z| with the same association. Returns 1 when it
 * separates. */
static int vx_cons_sep_plane(const double n[3], double r, const double t0[3])
{
    double d = n[0] * t0[0] + n[1] * t0[1] + n[2] * t0[2];
    return d > r || d < -r;
}

static double vx_cons_plane_radius(const double n[3], const double h[3])
{
    return h[0] * fabs(n[0]) + h[1] * fabs(n[1]) + h[2] * fabs(n[2]);
}

/* One edge axis of the SAT as a statement: returns 0 from the enclosing function when axis
 * (Lu, Lw) with radius r separates vertex offsets (su, sw) and (ou, ow) (vx_cons_sep2). */
#define VX_CONS_AXIS(Lu, Lw, hu, hw, su, sw, ou, ow)                                         \
    do {                                                                                     \
        double r_ = (hu) * fabs(Lu) + (hw) * fabs(Lw);                                       \
        if (vx_cons_sep2((Lu), (Lw), r_, (su), (sw), (ou), (ow))) return 0;                  \
    } while (0)

HFVIS_API int hfvis_triangle_box_overlap(const double center[3], const double half[3],
                                         const double v0[3], const double v1[3],
                                         const double v2[3])
{
    /* t_k = v_k - center; f_j from the untranslated vertices, so they do not depend on the box */
    const double t0x = v0[0] - center[0], t0y = v0[1] - center[1], t0z = v0[2] - center[2];
    const double t1x = v1[0] - center[0], t1y = v1[1] - center[1], t1z = v1[2] - center[2];
    const double t2x = v2[0] - center[0], t2y = v2[1] - center[1], t2z = v2[2] - center[2];
    const double hx = half[0], hy = half[1], hz = half[2];
    double f0[3], f1[3], f2[3], n[3], t0[3];
    f0[0] = v1[0] - v0[0];
    f0[1] = v1[1] - v0[1];
    f0[2] = v1[2] - v0[2];
    f1[0] = v2[0] - v1[0];
    f1[1] = v2[1] - v1[1];
    f1[2] = v2[2] - v1[2];
    f2[0] = v0[0] - v2[0];
    f2[1] = v0[1] - v2[1];
    f2[2] = v0[2] - v2[2];
    /* axes 5-13, e_a x f_j with (u, w) = (a+1, a+2): L_u = -f_j[w], L_w = f_j[u]; vertices:
     * the start of edge j and the opposite vertex j+2 (vx_cons_sep2). As Akenine-Moller, these
     * nine first: they separate most often. */
    VX_CONS_AXIS(-f0[2], f0[1], hy, hz, t0y, t0z, t2y, t2z); /* e_x x f0 */
    VX_CONS_AXIS(-f1[2], f1[1], hy, hz, t1y, t1z, t0y, t0z); /* e_x x f1 */
    VX_CONS_AXIS(-f2[2], f2[1], hy, hz, t2y, t2z, t1y, t1z); /* e_x x f2 */
    VX_CONS_AXIS(-f0[0], f0[2], hz, hx, t0z, t0x, t2z, t2x); /* e_y x f0 */
    VX_CONS_AXIS(-f1[0], f1[2], hz, hx, t1z, t1x, t0z, t0x); /* e_y x f1 */
    VX_CONS_AXIS(-f2[0], f2[2], hz, hx, t2z, t2x, t1z, t1x); /* e_y x f2 */
    VX_CONS_AXIS(-f0[1], f0[0], hx, hy, t0x, t0y, t2x, t2y); /* e_z x f0 */
    VX_CONS_AXIS(-f1[1], f1[0], hx, hy, t1x, t1y, t0x, t0y); /* e_z x f1 */
    VX_CONS_AXIS(-f2[1], f2[0], hx, hy, t2x, t2y, t1x, t1y); /* e_z x f2 */
    /* axes 1-3: the box normals (the triangle's bounding box against the box) */
    if (vx_cons_min3(t0x, t1x, t2x) > hx || vx_cons_max3(t0x, t1x, t2x) < -hx) return 0;
    if (vx_cons_min3(t0y, t1y, t2y) > hy || vx_cons_max3(t0y, t1y, t2y) < -hy) return 0;
    if (vx_cons_min3(t0z, t1z, t2z) > hz || vx_cons_max3(t0z, t1z, t2z) < -hz) return 0;
    /* axis 4: the triangle normal */
    vx_cons_normal(f0, f1, n);
    t0[0] = t0x;
    t0[1] = t0y;
    t0[2] = t0z;
    return !vx_cons_sep_plane(n, vx_cons_plane_radius(n, half), t0);
}
#undef VX_CONS_AXIS

/* ---- 8b. conservative voxelization --------------------------------------------------------- */

HFVIS_API hfvis_binary_voxel_options hfvis_binary_voxel_options_default(void)
{
    hfvis_binary_voxel_options o;
    memset(&o, 0, sizeof o);
    o.alloc = NULL;
    o.axis = HFVIS_PARITY_AXIS_Z;
    o.allow_open = 0;
    return o;
}

/* Argument checks and output clearing shared by the conservative voxelizers. */
static hfvis_status vx_cons_begin(const hfvis_mesh *mesh, const hfvis_volume_grid *grid,
                                  uint8_t *occ)
{
    hfvis_status s = vx_cons_args(mesh, grid, occ);
    if (s != HFVIS_OK) return s;
    memset(occ, 0, vx_grid_voxels(grid));
    return HFVIS_OK;
}

/* Voxel ranges of the triangle's bounding box (vx_cons_range on each axis); 0 when empty. */
static int vx_cons_bbox(const double *v0, const double *v1, const double *v2,
                        const hfvis_volume_grid *grid, int lo[3], int hi[3])
{
    int a;
    for (a = 0; a < 3; a++)
        if (!vx_cons_range(vx_cons_min3(v0[a], v1[a], v2[a]), vx_cons_max3(v0[a], v1[a], v2[a]),
                           grid->dims[a], &lo[a], &hi[a]))
            return 0;
    return 1;
}

/* 1 when the grid-space triangle has a zero normal (computed as vx_cons_normal): such triangles
 * are never voxelized (hfvis_mesh). */
static int vx_cons_degenerate(const double *v0, const double *v1, const double *v2)
{
    double f0[3], f1[3], n[3];
    int a;
    for (a = 0; a < 3; a++) {
        f0[a] = v1[a] - v0[a];
        f1[a] = v2[a] - v1[a];
    }
    vx_cons_normal(f0, f1, n);
    return n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0;
}

HFVIS_API hfvis_status hfvis_voxelize_conservative_reference(const hfvis_mesh *mesh,
                                                             const hfvis_volume_grid *grid,
                                                             const hfvis_binary_voxel_options *opts,
                                                             uint8_t *occ, size_t *count)
{
    static const double half[3] = {0.5, 0.5, 0.5};
    size_t t, n = 0, nx, nxy;
    hfvis_status s;
    (void)opts;
    s = vx_cons_begin(mesh, grid, occ);
    if (s != HFVIS_OK) return s;
    nx = (size_t)grid->dims[0];
    nxy = nx * (size_t)grid->dims[1];
    for (t = 0; t < mesh->triangle_count; t++) {
        double v[3][3], c[3];
        int lo[3], hi[3], i, j, k;
        for (k = 0; k < 3; k++) vx_cons_gvert(mesh, grid, mesh->indices[3 * t + (size_t)k], v[k]);
        if (vx_cons_degenerate(v[0], v[1], v[2]) || !vx_cons_bbox(v[0], v[1], v[2], grid, lo, hi))
            continue;
        for (k = lo[2]; k <= hi[2]; k++) {
            c[2] = (double)k + 0.5;
            for (j = lo[1]; j <= hi[1]; j++) {
                c[1] = (double)j + 0.5;
                for (i = lo[0]; i <= hi[0]; i++) {
                    uint8_t *o = occ + (size_t)k * nxy + (size_t)j * nx + (size_t)i;
                    c[0] = (double)i + 0.5;
                    if (hfvis_triangle_box_overlap(c, half, v[0], v[1], v[2]) && !*o) {
                        *o = 1;
                        n++;
                    }
                }
            }
        }
    }
    if (count) *count = n;
    return HFVIS_OK;
}

/* Per-triangle setup of the fast path (Schwarz & Seidel 2010, §3.1: the triangle's normal,
 * plane radius ("critical point" offset) and the nine 2D edge axes with their radii, computed
 * once per triangle with exactly the expressions of hfvis_triangle_box_overlap, h = 0.5). */
typedef struct vx_cons_tri {
    double v[3][3];    /* grid-space vertices */
    double n[3], rn;   /* normal f0 x f1 and its radius sum h|n_a| */
    double L[3][3][2]; /* [a][j]: edge axis e_a x f_j as (L_u, L_w) */
    double r[3][3];    /* [a][j]: its radius */
    int D, U, W;       /* dominant axis argmax |n_a| (ties to the lower axis); U = D+1, W = D+2 */
} vx_cons_tri;

static const double vx_cons_half[3] = {0.5, 0.5, 0.5};

/* Returns 0 for a degenerate triangle (zero normal). */
static int vx_cons_setup(vx_cons_tri *T)
{
    double f[3][3];
    int a, j;
    for (a = 0; a < 3; a++) {
        f[0][a] = T->v[1][a] - T->v[0][a];
        f[1][a] = T->v[2][a] - T->v[1][a];
        f[2][a] = T->v[0][a] - T->v[2][a];
    }
    vx_cons_normal(f[0], f[1], T->n);
    if (T->n[0] == 0.0 && T->n[1] == 0.0 && T->n[2] == 0.0) return 0;
    T->rn = vx_cons_plane_radius(T->n, vx_cons_half);
    for (a = 0; a < 3; a++) {
        int u = a == 2 ? 0 : a + 1, w = a == 0 ? 2 : a - 1;
        for (j = 0; j < 3; j++) {
            double Lu = -f[j][w], Lw = f[j][u];
            T->L[a][j][0] = Lu;
            T->L[a][j][1] = Lw;
            T->r[a][j] = vx_cons_half[u] * fabs(Lu) + vx_cons_half[w] * fabs(Lw);
        }
    }
    T->D = 0;
    if (fabs(T->n[1]) > fabs(T->n[T->D])) T->D = 1;
    if (fabs(T->n[2]) > fabs(T->n[T->D])) T->D = 2;
    T->U = T->D == 2 ? 0 : T->D + 1;
    T->W = T->D == 0 ? 2 : T->D - 1;
    return 1;
}

/* The three edge axes of projection a (in-plane axes u, w) at a voxel whose vertex offsets are
 * t[k][.]: exactly the expressions of hfvis_triangle_box_overlap. 1 when one separates. */
static int vx_cons_sep_proj(const vx_cons_tri *T, int a, int u, int w, double t[3][3])
{
    return vx_cons_sep2(T->L[a][0][0], T->L[a][0][1], T->r[a][0], t[0][u], t[0][w], t[2][u], t[2][w])
        || vx_cons_sep2(T->L[a][1][0], T->L[a][1][1], T->r[a][1], t[1][u], t[1][w], t[0][u], t[0][w])
        || vx_cons_sep2(T->L[a][2][0], T->L[a][2][1], T->r[a][2], t[2][u], t[2][w], t[1][u], t[1][w]);
}

/* The SAT of layer k of a column whose offsets t[.][U], t[.][W] are set and whose dominant
 * projection's axes (and, inside the bounding-box range, the box axes) do not separate: the plane
 * axis and the six edge axes of the two other projections, with the SAT's expressions.
 * Returns 1 when none separates, i.e. hfvis_triangle_box_overlap would return 1. */
static int vx_cons_layer_ok(const vx_cons_tri *T, double t[3][3], int k)
{
    int D = T->D, U = T->U, W = T->W;
    double c = (double)k + 0.5;
    t[0][D] = T->v[0][D] - c;
    t[1][D] = T->v[1][D] - c;
    t[2][D] = T->v[2][D] - c;
    return !vx_cons_sep_plane(T->n, T->rn, t[0]) && !vx_cons_sep_proj(T, U, W, D, t)
        && !vx_cons_sep_proj(T, W, D, U, t);
}

/* The fast path's per-vertex data, computed once per vertex (about six triangles share one):
 * the grid-space coordinates, their magnitude |g0| + |g1| + |g2| (for the margin) and, per axis,
 * the voxel range of the vertex' closed extent, ceil(g) - 1 and floor(g), clamped to [-1, n]
 * (so a triangle's bounding-box range is the min and max of its vertices', clipped). */
typedef struct vx_cons_vert {
    double g[3];
    double mag;
    int lo[3], hi[3];
} vx_cons_vert;

/* x clamped to [0, top] (a NaN becomes 0), then truncated: floor(x) for x >= 0. Local indices
 * are int64_t so lo + 1 cannot overflow for a range of INT_MAX voxels. */
static VX_CONS_INLINE int64_t vx_cons_floor_local(double x, double top)
{
    x = x > 0.0 ? x : 0.0;
    x = x < top ? x : top;
    return (int64_t)x;
}

/* The fast path's scratch occupancy: bits in 4x4x4 bricks, one uint64 per brick (brick
 * (bx, by, bz) at (bz*nb[1] + by)*nb[0] + bx, voxel bit (z&3)*16 + (y&3)*4 + (x&3)), so the few
 * voxels one triangle touches share a handful of words in cache; the byte output is written
 * from it at the end. */
typedef struct vx_cons_bricks {
    uint64_t *w;
    size_t nb[3];  /* bricks per axis */
    size_t bs[3];  /* brick stride per axis: 1, nb[0], nb[0]*nb[1] */
} vx_cons_bricks;

static VX_CONS_INLINE size_t vx_cons_brick_of(const vx_cons_bricks *B, const int p[3], unsigned *bit)
{
    *bit = (unsigned)(((p[2] & 3) << 4) | ((p[1] & 3) << 2) | (p[0] & 3));
    return (size_t)(p[0] >> 2) * B->bs[0] + (size_t)(p[1] >> 2) * B->bs[1]
           + (size_t)(p[2] >> 2) * B->bs[2];
}

/* 1 when every vertex lies in the closed cube of voxel p (a one-voxel range can also come from
 * clipping a larger triangle at the grid's border). */
static int vx_cons_inside_voxel(const vx_cons_tri *T, const int p[3])
{
    int k, a;
    for (k = 0; k < 3; k++)
        for (a = 0; a < 3; a++)
            if (!(T->v[k][a] >= (double)p[a] && T->v[k][a] <= (double)p[a] + 1.0)) return 0;
    return 1;
}

/* One SAT edge axis as a bound on a linear form of two voxel-centre coordinates x, y: in exact
 * arithmetic the axis does not separate iff lo <= A x + B y <= hi (the SAT's p = Q - L.c of the
 * axis' two vertices, Q = L.v: lo = min Q - r, hi = max Q + r, r = (|A| + |B|)/2). With A != 0
 * that is x in [x1(y), x2(y)], x1,2 = c1,2 - m y (c = lo/A, hi/A in order, m = B/A), kept as
 * four linear forms c[i] - m y: the candidates (the interval widened by the margin dk = dl/|A|)
 * and the certain range (narrowed by dk); dl = eps (|A| + |B|) is the margin in value units.
 * A == 0 (the axis does not depend on x): lo, hi, dl are kept to test y. */
typedef struct vx_cons_bound {
    double c[4], m;
    double B, lo, hi, dl; /* A == 0 only */
    int flat;             /* A == 0 */
} vx_cons_bound;

/* The bound of axis (A, B) whose two vertices have coordinates (xj, yj), (xo, yo); inv = 1/A
 * (any value when A == 0), shared by the axes with the same A up to sign. */
static VX_CONS_INLINE void vx_cons_bound_init(vx_cons_bound *b, double A, double B, double inv,
                                              double xj, double yj, double xo, double yo,
                                              double eps)
{
    /* min/max as separate selections (branch-free minsd/maxsd): the signs are data */
    double qa = A * xj + B * yj, qb = A * xo + B * yo, r = 0.5 * (fabs(A) + fabs(B));
    double qmin = qa < qb ? qa : qb, qmax = qa > qb ? qa : qb;
    double lo = qmin - r, hi = qmax + r, dl = 2.0 * eps * r;
    b->flat = A == 0.0;
    if (!b->flat) {
        double dk = dl * fabs(inv), p1 = lo * inv, p2 = hi * inv;
        double c1 = p1 < p2 ? p1 : p2, c2 = p1 > p2 ? p1 : p2; /* swapped when inv < 0 */
        b->m = B * inv;
        b->c[0] = c1 - dk;
        b->c[1] = c2 + dk;
        b->c[2] = c1 + dk;
        b->c[3] = c2 - dk;
    } else {
        b->B = B;
        b->lo = lo;
        b->hi = hi;
        b->dl = dl;
    }
}

/* Narrows r = {candidate lo, candidate hi, certain lo, certain hi} of x, given y, by one bound:
 * x inside the certain range passes the SAT's axis for certain, x outside the candidate range
 * fails it for certain. A flat bound: the whole line certainly fails (candidates emptied),
 * certainly passes, or is undecided (certain range emptied). */
static VX_CONS_INLINE void vx_cons_bound_apply(const vx_cons_bound *b, double y, double r[4])
{
    if (!b->flat) {
        double my = b->m * y, x;
        x = b->c[0] - my;
        r[0] = r[0] > x ? r[0] : x;
        x = b->c[1] - my;
        r[1] = r[1] < x ? r[1] : x;
        x = b->c[2] - my;
        r[2] = r[2] > x ? r[2] : x;
        x = b->c[3] - my;
        r[3] = r[3] < x ? r[3] : x;
    } else {
        double rem = b->B * y;
        if (rem < b->lo - b->dl || rem > b->hi + b->dl) r[0] = HUGE_VAL;
        else if (!(rem >= b->lo + b->dl && rem <= b->hi - b->dl)) r[2] = HUGE_VAL;
    }
}

/* Bits of layers l0..l1 (0..3) of one column inside a brick, for layer strides 1, 4, 16 bits
 * (dominant axis x, y, z), before the shift by the column's bit. */
static const uint64_t vx_cons_layer_masks[3][4][4] = {
    {{0x1, 0x3, 0x7, 0xf}, {0, 0x2, 0x6, 0xe}, {0, 0, 0x4, 0xc}, {0, 0, 0, 0x8}},
    {{0x1, 0x11, 0x111, 0x1111}, {0, 0x10, 0x110, 0x1110}, {0, 0, 0x100, 0x1100}, {0, 0, 0, 0x1000}},
    {{0x1, 0x10001, 0x100010001ull, 0x1000100010001ull},
     {0, 0x10000, 0x100010000ull, 0x1000100010000ull},
     {0, 0, 0x100000000ull, 0x1000100000000ull},
     {0, 0, 0, 0x1000000000000ull}}};

/* Voxelizes one triangle (grid-space vertices T->v, normal n != 0 with dominant axis D, U = D+1,
 * W = D+2; bounding-box voxel ranges lo..hi) into the bricks. The result is, bit for bit, the
 * set of voxels of the range on which hfvis_triangle_box_overlap returns 1, found without
 * calling it on most voxels (Schwarz & Seidel 2010's per-triangle decomposition, made exact):
 *  - the work is done in the frame (x, y, z) = (U, W, D), a cyclic permutation, in which the
 *    SAT's axes keep their form: the edge axes of projection a are e_a x f_j with in-plane axes
 *    (a+1, a+2); or in (W, U, D) when the bounding box is shorter along U (fewer rows, each
 *    with its own setup): that odd permutation negates every axis, which leaves each two-sided
 *    bound as it is. Each edge axis is a two-sided bound on two centre coordinates (vx_cons_bound):
 *    the three axes of projection z bound the columns x of each row y; the three of projection x
 *    bound the layers z of each row y; the three of projection y bound the layers z of each
 *    column index x; the plane axis bounds the layers of each column (x, y) to
 *    |kc - z| <= rn/|n_z| with kc linear in (x, y) (Schwarz & Seidel's plane test solved for
 *    the column); the box axes always pass inside the bounding-box range (|t| <= h there, also
 *    in floating point). So the voxels of a column form an interval computed from these bounds;
 *  - the bounds are evaluated in double with a margin eps = 2^-30 of the coordinate scale
 *    (times |A| + |B| of the axis, or in layers for the plane): the rounding of the SAT's own
 *    expressions and of these bounds is about 2^-50 of that, so a voxel inside every bound by
 *    its margin passes every axis of the SAT for certain, and one outside a bound by its margin
 *    fails it for certain. Voxels within a margin of an end (exact ties such as faces on voxel
 *    boundaries, or 1e-9-close calls) are decided with the SAT's own expressions in the
 *    original frame (vx_cons_sep_proj, vx_cons_layer_ok; set up lazily), which makes the
 *    result identical to the reference. scale (from the caller) is 4 + the bounding box's high
 *    indices + the vertices' coordinate magnitudes. The bounds are evaluated in a local frame
 *    (index minus lo - 1 per axis, so ranges are 1..n and every range end is one clamp and one
 *    truncation, vx_cons_floor_local); a ceiling is taken as floor + 1, which differs only when
 *    the bound is an integer, i.e. for a centre exactly a margin away: outside a candidate
 *    range (certainly out) or outside a certain one (decided by the SAT's expressions);
 *  - a voxel already set needs no decision (the result is a union): a column whose plane
 *    candidates are all set is skipped before the other projections' bounds are even set up
 *    (they are set up once per triangle, when first needed); a bounding box of at most
 *    VX_CONS_SMALL_BOX voxels is decided by calling the SAT on its voxels not yet set;
 *  - a triangle inside one voxel's closed cube (not merely clipped to one): every offset
 *    |t| <= h, and then no axis of the SAT can separate (|fl(L.t)| <= fl(h |L|) term by term,
 *    since rounding is monotone and the radii are summed in the same order): the voxel is set.
 * Returns the number of columns decided with the SAT's expressions (a statistic). */
static size_t vx_cons_fast_tri(vx_cons_tri *T, const int lo[3], const int hi[3], double scale,
                               vx_cons_bricks *B)
{
    const int D = T->D, U = T->U, W = T->W;
    const int X = hi[U] - lo[U] < hi[W] - lo[W] ? W : U, Y = X == U ? W : U;
    const unsigned sh = 2u * (unsigned)D, shX = 2u * (unsigned)X, shY = 2u * (unsigned)Y;
    const size_t sD = B->bs[D], sX = B->bs[X], sY = B->bs[Y];
    const uint64_t(*lmask)[4] = vx_cons_layer_masks[D];
    /* the local frame: index i - o with o = lo - 1 per axis, so the range is 1..n */
    const int ox = lo[X] - 1, oy = lo[Y] - 1, oz = lo[D] - 1;
    const int64_t rows = (int64_t)hi[Y] - oy;
    const double topx = (double)((int64_t)hi[X] - ox) + 0.5, topz = (double)((int64_t)hi[D] - oz) + 0.5;
    double P[3][3], f[3][3], invy[3], invx[3], nx, ny, nz, inz, ax, ay, K0, hwid, eps, plo, phi;
    double t[3][3];
    vx_cons_bound bz[3], bx[3], by[3];
    size_t slow = 0;
    int64_t ix, iy, k;
    int j, have_sat = 0, have_xy = 0;
    if (lo[0] == hi[0] && lo[1] == hi[1] && lo[2] == hi[2] && vx_cons_inside_voxel(T, lo)) {
        unsigned bit;
        size_t wi = vx_cons_brick_of(B, lo, &bit); /* sequenced before bit is read */
        B->w[wi] |= (uint64_t)1 << bit;
        return 0;
    }
    if ((hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1) * (hi[2] - lo[2] + 1) <= VX_CONS_SMALL_BOX) {
        /* a small box: the SAT itself on the voxels not yet set (the result is a union) */
        int q[3];
        for (q[2] = lo[2]; q[2] <= hi[2]; q[2]++)
            for (q[1] = lo[1]; q[1] <= hi[1]; q[1]++)
                for (q[0] = lo[0]; q[0] <= hi[0]; q[0]++) {
                    unsigned bit;
                    uint64_t *w, m;
                    double c[3];
                    w = B->w + vx_cons_brick_of(B, q, &bit);
                    m = (uint64_t)1 << bit;
                    if (*w & m) continue;
                    c[0] = (double)q[0] + 0.5;
                    c[1] = (double)q[1] + 0.5;
                    c[2] = (double)q[2] + 0.5;
                    if (hfvis_triangle_box_overlap(c, vx_cons_half, T->v[0], T->v[1], T->v[2])) *w |= m;
                }
        return 0;
    }
    for (k = 0; k < 3; k++) {
        P[k][0] = T->v[k][X] - (double)ox;
        P[k][1] = T->v[k][Y] - (double)oy;
        P[k][2] = T->v[k][D] - (double)oz;
    }
    for (j = 0; j < 3; j++) {
        const int e = j == 2 ? 0 : j + 1;
        f[j][0] = P[e][0] - P[j][0];
        f[j][1] = P[e][1] - P[j][1];
        f[j][2] = P[e][2] - P[j][2];
        invy[j] = f[j][1] != 0.0 ? 1.0 / f[j][1] : 0.0; /* projections z and x */
    }
    nx = T->n[X];
    ny = T->n[Y];
    nz = T->n[D];
    /* the plane slab per column: kc(x, y) = K0 - ax x - ay y + 0.5 (the plane's height at the
     * column's centre), |ax|, |ay| <= 1, half width rn/|n_z| <= 1.5 */
    inz = 1.0 / nz;
    ax = nx * inz;
    ay = ny * inz;
    K0 = P[0][2] - 0.5 + (nx * (P[0][0] - 0.5) + ny * (P[0][1] - 0.5)) * inz;
    hwid = 0.5 * (fabs(nx) + fabs(ny) + fabs(nz)) * fabs(inz);
    eps = scale * 9.313225746154785e-10; /* 2^-30 */
    plo = hwid + eps + 0.5; /* the plane's candidate layers: ceil(kc - plo) .. floor(kc + phi) */
    phi = hwid + eps - 0.5;
    /* the nine edge axes: projection z (x = cx, y = cy), x (x = cz, y = cy), y (x = cz,
     * y = cx); vertex pairs (j, o) = (0, 2), (1, 0), (2, 1). Projections x and y are only set
     * up when some candidate voxel is not set yet. */
    for (j = 0; j < 3; j++) {
        const int o = j == 0 ? 2 : j - 1;
        vx_cons_bound_init(&bz[j], -f[j][1], f[j][0], -invy[j], P[j][0], P[j][1], P[o][0],
                           P[o][1], eps);
    }
    for (iy = 1; iy <= rows; iy++) {
        const double cy = (double)iy + 0.5, krow = K0 - ay * (double)iy + 0.5;
        const int gy = (int)(iy + oy);
        const size_t rowbase = (size_t)(gy >> 2) * sY;
        const unsigned rowbit = (unsigned)(gy & 3) << shY;
        double rc[4], rk[4];
        int64_t ca0, ca1, cc0, cc1;
        int have_rk = 0;
        /* the row's columns (projection z), on centres: candidates ca0..ca1, certain cc0..cc1
         * (ceil as floor + 1: it differs only on an integer, a centre exactly a margin away) */
        rc[0] = rc[2] = -HUGE_VAL;
        rc[1] = rc[3] = HUGE_VAL;
        for (j = 0; j < 3; j++) vx_cons_bound_apply(&bz[j], cy, rc);
        ca0 = vx_cons_floor_local(rc[0] - 0.5, topx) + 1;
        ca1 = vx_cons_floor_local(rc[1] - 0.5, topx);
        if (ca0 > ca1) continue;
        cc0 = vx_cons_floor_local(rc[2] - 0.5, topx) + 1;
        cc1 = vx_cons_floor_local(rc[3] - 0.5, topx);
        for (ix = ca0; ix <= ca1; ix++) {
            const double kc = krow - ax * (double)ix;
            const int gx = (int)(ix + ox);
            const size_t base = rowbase + (size_t)(gx >> 2) * sX;
            const unsigned bit0 = rowbit | (unsigned)(gx & 3) << shX;
            double r[4];
            int64_t ka = vx_cons_floor_local(kc - plo, topz) + 1, kb, kA, kB;
            int ga, gb;
#define VX_CONS_WORD(kk) B->w[base + (size_t)((kk) >> 2) * sD]
#define VX_CONS_MASK(kk) ((uint64_t)1 << (bit0 | ((unsigned)((kk) & 3) << sh)))
            /* the plane's candidate layers; done if they are all set already */
            kb = vx_cons_floor_local(kc + phi, topz);
            if (ka > kb) continue;
            ga = (int)(ka + oz);
            gb = (int)(kb + oz);
            if (gb - ga <= 4) {
                /* at most two bricks: masks of the layers in each (vx_cons_layer_masks) */
                int g3 = ga | 3, last = gb < g3 ? gb : g3;
                uint64_t m1 = lmask[ga & 3][last & 3] << bit0;
                uint64_t m2 = (lmask[0][gb & 3] & ((uint64_t)0 - (uint64_t)(gb > g3))) << bit0;
                /* m2 = 0 when gb is in ga's brick; masks without branches (the data decide) */
                if ((VX_CONS_WORD(ga) & m1) == m1 && (VX_CONS_WORD(gb) & m2) == m2) continue;
            } else {
                int g;
                for (g = ga; g <= gb && (VX_CONS_WORD(g) & VX_CONS_MASK(g)); g++) {}
                if (g > gb) continue;
            }
            /* layer bounds on the centre: plane, projection x (row), projection y (column) */
            if (!have_xy) {
                for (j = 0; j < 3; j++) {
                    const int o = j == 0 ? 2 : j - 1;
                    invx[j] = f[j][0] != 0.0 ? 1.0 / f[j][0] : 0.0;
                    vx_cons_bound_init(&bx[j], f[j][1], -f[j][2], invy[j], P[j][2], P[j][1],
                                       P[o][2], P[o][1], eps);
                    vx_cons_bound_init(&by[j], -f[j][0], f[j][2], -invx[j], P[j][2], P[j][0],
                                       P[o][2], P[o][0], eps);
                }
                have_xy = 1;
            }
            if (!have_rk) {
                rk[0] = rk[2] = -HUGE_VAL;
                rk[1] = rk[3] = HUGE_VAL;
                for (j = 0; j < 3; j++) vx_cons_bound_apply(&bx[j], cy, rk);
                have_rk = 1;
            }
            r[0] = kc - hwid - eps;
            r[1] = kc + hwid + eps;
            r[2] = kc - hwid + eps;
            r[3] = kc + hwid - eps;
            for (j = 0; j < 3; j++) vx_cons_bound_apply(&by[j], (double)ix + 0.5, r);
            r[0] = r[0] > rk[0] ? r[0] : rk[0];
            r[1] = r[1] < rk[1] ? r[1] : rk[1];
            r[2] = r[2] > rk[2] ? r[2] : rk[2];
            r[3] = r[3] < rk[3] ? r[3] : rk[3];
            ka = vx_cons_floor_local(r[0] - 0.5, topz) + 1;
            kb = vx_cons_floor_local(r[1] - 0.5, topz);
            if (ka > kb) continue;
            kA = vx_cons_floor_local(r[2] - 0.5, topz) + 1;
            kB = vx_cons_floor_local(r[3] - 0.5, topz);
            if (ka == kA && kb == kB && ix >= cc0 && ix <= cc1) {
                for (k = ka + oz; k <= kb + oz; k++) VX_CONS_WORD(k) |= VX_CONS_MASK(k); /* certain */
                continue;
            }
            /* within a margin of an end: the SAT's own expressions decide */
            slow++;
            if (!have_sat) {
                vx_cons_setup(T);
                have_sat = 1;
            }
            {
                const double gcx = (double)gx + 0.5, gcy = (double)gy + 0.5;
                t[0][X] = T->v[0][X] - gcx;
                t[1][X] = T->v[1][X] - gcx;
                t[2][X] = T->v[2][X] - gcx;
                t[0][Y] = T->v[0][Y] - gcy;
                t[1][Y] = T->v[1][Y] - gcy;
                t[2][Y] = T->v[2][Y] - gcy;
            }
            if ((ix < cc0 || ix > cc1) && vx_cons_sep_proj(T, D, U, W, t)) continue;
            for (k = ka; k <= kb; k++) {
                const int g = (int)(k + oz);
                if ((k >= kA && k <= kB) || vx_cons_layer_ok(T, t, g)) VX_CONS_WORD(g) |= VX_CONS_MASK(g);
            }
#undef VX_CONS_WORD
#undef VX_CONS_MASK
        }
    }
    return slow;
}

/* Allocates the brick scratch (zeroed) for a valid grid; NULL on failure. */
static uint64_t *vx_cons_bricks_init(vx_cons_bricks *B, const hfvis_volume_grid *grid,
                                     const hfvis_allocator *alloc)
{
    size_t words;
    int a;
    for (a = 0; a < 3; a++) B->nb[a] = ((size_t)grid->dims[a] + 3) / 4;
    B->bs[0] = 1;
    B->bs[1] = B->nb[0];
    B->bs[2] = B->nb[0] * B->nb[1];
    words = B->bs[2] * B->nb[2]; /* about voxels / 64: no overflow for a valid grid */
    B->w = (uint64_t *)hfvis__alloc_array(alloc, words, sizeof(uint64_t));
    if (B->w) memset(B->w, 0, words * sizeof(uint64_t));
    return B->w;
}

/* Index of the lowest set bit of m != 0, branch-free: the isolated bit times a de Bruijn
 * sequence B(2, 6) has a distinct top 6 bits per bit position (Leiserson, Prokop & Randall,
 * "Using de Bruijn sequences to index a 1 in a computer word", 1998). */
static unsigned vx_cons_ctz64(uint64_t m)
{
    static const unsigned char pos[64] = {
        0,  1,  48, 2,  57, 49, 28, 3,  61, 58, 50, 42, 38, 29, 17, 4,
        62, 55, 59, 36, 53, 51, 43, 22, 45, 39, 33, 30, 24, 18, 12, 5,
        63, 47, 56, 27, 60, 41, 37, 16, 54, 35, 52, 21, 44, 32, 23, 11,
        46, 26, 40, 15, 34, 20, 31, 10, 25, 14, 19, 9,  13, 8,  7,  6};
    return pos[((m & (0u - m)) * 0x03f79d71b4cb0a89ull) >> 58];
}

/* Clears occ and sets the voxels of the bricks' set bits; returns their number. */
static size_t vx_cons_bricks_emit(const vx_cons_bricks *B, const hfvis_volume_grid *grid,
                                  uint8_t *occ)
{
    size_t nx = (size_t)grid->dims[0], nxy = nx * (size_t)grid->dims[1], n = 0, b0, b1, b2;
    const uint64_t *w = B->w;
    memset(occ, 0, vx_grid_voxels(grid));
    for (b2 = 0; b2 < B->nb[2]; b2++)
        for (b1 = 0; b1 < B->nb[1]; b1++)
            for (b0 = 0; b0 < B->nb[0]; b0++) {
                uint64_t m = *w++;
                while (m) {
                    unsigned bit = vx_cons_ctz64(m);
                    m &= m - 1;
                    occ[(b2 * 4 + (bit >> 4)) * nxy + (b1 * 4 + ((bit >> 2) & 3u)) * nx + b0 * 4
                        + (bit & 3u)] = 1;
                    n++;
                }
            }
    return n;
}

HFVIS_API hfvis_status hfvis_voxelize_conservative(const hfvis_mesh *mesh,
                                                   const hfvis_volume_grid *grid,
                                                   const hfvis_binary_voxel_options *opts,
                                                   uint8_t *occ, size_t *count)
{
    const hfvis_allocator *alloc = opts ? opts->alloc : NULL;
    size_t t, v, n;
    vx_cons_vert *vert;
    vx_cons_bricks B;
    if (!occ || !vx_grid_valid(grid) || hfvis__mesh_check(mesh) != HFVIS_OK)
        return HFVIS_ERR_INVALID_ARGUMENT;
    /* scratch: every vertex in grid space with its ranges (transformed once, and checked against
     * VX_CONS_MAX_COORD as vx_cons_args does), and the brick bits */
    vert = (vx_cons_vert *)hfvis__alloc_array(alloc, mesh->vertex_count, sizeof(vx_cons_vert));
    if (!vert && mesh->vertex_count) return HFVIS_ERR_OUT_OF_MEMORY;
    for (v = 0; v < mesh->vertex_count; v++) {
        vx_cons_vert *p = vert + v;
        int a;
        p->mag = 0.0;
        for (a = 0; a < 3; a++) {
            double g = vx_cons_gc(grid, a, mesh->xyz[3 * v + (size_t)a]), l, h;
            const double top = (double)grid->dims[a];
            if (!(fabs(g) <= VX_CONS_MAX_COORD)) {
                hfvis__free(alloc, vert);
                return HFVIS_ERR_LIMIT;
            }
            p->g[a] = g;
            p->mag += fabs(g);
            l = ceil(g) - 1.0; /* vx_cons_range before clipping, kept within [-1, n] */
            h = floor(g);
            p->lo[a] = (int)(l < -1.0 ? -1.0 : l > top ? top : l);
            p->hi[a] = (int)(h < -1.0 ? -1.0 : h > top ? top : h);
        }
    }
    if (!vx_cons_bricks_init(&B, grid, alloc)) {
        hfvis__free(alloc, vert);
        return HFVIS_ERR_OUT_OF_MEMORY;
    }
    for (t = 0; t < mesh->triangle_count; t++) {
        const vx_cons_vert *p[3];
        vx_cons_tri T;
        double f0[3], f1[3];
        int lo[3], hi[3], a, k, empty = 0;
        for (k = 0; k < 3; k++) p[k] = vert + mesh->indices[3 * t + (size_t)k];
        for (a = 0; a < 3; a++) { /* vx_cons_bbox: the min and max of the vertices' ranges */
            int l = p[0]->lo[a], h = p[0]->hi[a];
            l = p[1]->lo[a] < l ? p[1]->lo[a] : l;
            l = p[2]->lo[a] < l ? p[2]->lo[a] : l;
            h = p[1]->hi[a] > h ? p[1]->hi[a] : h;
            h = p[2]->hi[a] > h ? p[2]->hi[a] : h;
            lo[a] = l > 0 ? l : 0;
            hi[a] = h < grid->dims[a] - 1 ? h : grid->dims[a] - 1;
            empty |= lo[a] > hi[a];
        }
        if (empty) continue;
        for (k = 0; k < 3; k++) {
            T.v[k][0] = p[k]->g[0];
            T.v[k][1] = p[k]->g[1];
            T.v[k][2] = p[k]->g[2];
        }
        for (a = 0; a < 3; a++) {
            f0[a] = T.v[1][a] - T.v[0][a];
            f1[a] = T.v[2][a] - T.v[1][a];
        }
        vx_cons_normal(f0, f1, T.n); /* the SAT's normal: degenerate iff it is zero */
        if (T.n[0] == 0.0 && T.n[1] == 0.0 && T.n[2] == 0.0) continue;
        T.D = 0;
        if (fabs(T.n[1]) > fabs(T.n[T.D])) T.D = 1;
        if (fabs(T.n[2]) > fabs(T.n[T.D])) T.D = 2;
        T.U = T.D == 2 ? 0 : T.D + 1;
        T.W = T.D == 0 ? 2 : T.D - 1;
        /* the margin's coordinate scale (vx_cons_fast_tri) */
        vx_cons_fast_tri(&T, lo, hi,
                         4.0 + (double)hi[0] + (double)hi[1] + (double)hi[2] + p[0]->mag + p[1]->mag + p[2]->mag,
                         &B);
    }
    n = vx_cons_bricks_emit(&B, grid, occ);
    hfvis__free(alloc, B.w);
    hfvis__free(alloc, vert);
    if (count) *count = n;
    return HFVIS_OK;
}

/* ---- 8c. exact 2D orientation and the watertight pixel-centre coverage rule ------------- */

/* The rounding error of the product p = fl(a*b): a*b - p exactly (Dekker's TwoProduct with
 * Veltkamp's split; needs round-to-nearest double arithmetic without contraction, which the
 * build's -ffp-contract=off gives, and no overflow/underflow, which VX_CONS_MAX_COORD and the
 * grid-space ranges give). */
static double vx_cons_product_error(double a, double b, double p)
{
    const double split = 134217729.0; /* 2^27 + 1 */
    double ca = split * a, cb = split * b;
    double ah = ca - (ca - a), al = a - ah, bh = cb - (cb - b), bl = b - bh;
    return ((ah * bh - p) + ah * bl + al * bh) + al * bl;
}

/* Exact sign of a*b - c*d. Rounding is monotone, so fl(a*b) > fl(c*d) implies a*b > c*d; only
 * when the rounded products are equal do their exact errors decide. */
static int vx_cons_det_sign(double a, double b, double c, double d)
{
    double p = a * b, q = c * d, ep, eq;
    if (p > q) return 1;
    if (p < q) return -1;
    ep = vx_cons_product_error(a, b, p);
    eq = vx_cons_product_error(c, d, q);
    return ep > eq ? 1 : (ep < eq ? -1 : 0);
}

/* Coverage of the point (cu, cw) by a triangle projected to (pu[k], pw[k]) ([G12] ch. 6:
 * the pixel-centre rule with a watertight tie rule). The vertices are moved to the point first,
 * q_k = fl(p_k - c) (shared vertices give the same q in every triangle), and the three edge
 * functions E_k = q_{k+1} x q_{k+2} are evaluated with their EXACT sign (vx_cons_det_sign), so
 * the two triangles of an edge see exactly opposite signs. The point is inside when no two signs
 * are opposite and not all are zero; the triangle's orientation s is then the common non-zero
 * sign. An edge whose E is 0 passes the point on it exactly: it includes it when the point
 * moved by (eps, eps^2) (eps -> 0+) would be strictly inside, i.e. when the edge, oriented by s,
 * has direction d with d_w < 0, or d_w == 0 and d_u > 0 (a "top-left" rule). This equals exact
 * coverage of that infinitesimally moved point by the triangle of the q's, so on a closed mesh
 * every line through a point crosses the surface an even number of times, and a shared edge or
 * vertex is counted once where the surface passes through and 0 or 2 times where it folds
 * (silhouettes). Returns 1 inside, 0 outside; *e receives fl(E_k) (unnormalised barycentrics,
 * for depth interpolation). */
static int vx_cons_cover(const double pu[3], const double pw[3], double cu, double cw,
                         double e[3])
{
    double qu[3], qw[3];
    int s[3], k, pos = 0, neg = 0, orient;
    for (k = 0; k < 3; k++) {
        qu[k] = pu[k] - cu;
        qw[k] = pw[k] - cw;
    }
    for (k = 0; k < 3; k++) {
        int a = k == 2 ? 0 : k + 1, b = k == 0 ? 2 : k - 1;
        double x = qu[a] * qw[b], y = qw[a] * qu[b];
        e[k] = x - y;
        s[k] = x > y ? 1 : (x < y ? -1 : vx_cons_det_sign(qu[a], qw[b], qw[a], qu[b]));
        pos |= s[k] > 0;
        neg |= s[k] < 0;
    }
    if (pos == neg) return 0; /* opposite signs, or all zero (degenerate) */
    orient = pos ? 1 : -1;
    for (k = 0; k < 3; k++) {
        if (s[k] == 0) {
            int a = k == 2 ? 0 : k + 1, b = k == 0 ? 2 : k - 1;
            double du = qu[b] - qu[a], dw = qw[b] - qw[a];
            if (orient < 0) {
                du = -du;
                dw = -dw;
            }
            if (!(dw < 0.0 || (dw == 0.0 && du > 0.0))) return 0;
        }
    }
    return 1;
}

/* Depth (grid units along the projection axis) of the covered point from the unnormalised
 * barycentrics e and the vertex depths pz, clamped to the vertices' range. */
static double vx_cons_depth(const double e[3], const double pz[3])
{
    double sum = e[0] + e[1] + e[2];
    double lo = vx_cons_min3(pz[0], pz[1], pz[2]), hi = vx_cons_max3(pz[0], pz[1], pz[2]), z;
    if (sum == 0.0) return lo; /* rounding-dominated sliver: any depth of the triangle */
    z = (e[0] * pz[0] + e[1] * pz[1] + e[2] * pz[2]) / sum;
    return z < lo ? lo : (z > hi ? hi : z);
}

/* Column range [*lo, *hi] of the pixel centres c + 0.5 inside [mn, mx], clipped to [0, n-1];
 * 0 when empty. */
static int vx_cons_centre_range(double mn, double mx, int n, int *lo, int *hi)
{
    double l = ceil(mn - 0.5), h = floor(mx - 0.5);
    if (l < 0.0) l = 0.0;
    if (h > (double)(n - 1)) h = (double)(n - 1);
    if (l > h) return 0;
    *lo = (int)l;
    *hi = (int)h;
    return 1;
}

/* Visits every pixel centre (iu, iw) of projection a (u = a+1, w = a+2) covered by grid-space
 * triangle v under vx_cons_cover, with its depth z along a. */
typedef void (*vx_cons_pixel_fn)(void *ctx, int iu, int iw, double z);

static void vx_cons_raster(double v[3][3], int a, const int dims[3], vx_cons_pixel_fn fn,
                           void *ctx)
{
    int u = a == 2 ? 0 : a + 1, w = a == 0 ? 2 : a - 1, ul, uh, wl, wh, iu, iw;
    double pu[3], pw[3], pz[3], e[3];
    int k;
    for (k = 0; k < 3; k++) {
        pu[k] = v[k][u];
        pw[k] = v[k][w];
        pz[k] = v[k][a];
    }
    if (!vx_cons_centre_range(vx_cons_min3(pu[0], pu[1], pu[2]), vx_cons_max3(pu[0], pu[1], pu[2]),
                              dims[u], &ul, &uh)
        || !vx_cons_centre_range(vx_cons_min3(pw[0], pw[1], pw[2]),
                                 vx_cons_max3(pw[0], pw[1], pw[2]), dims[w], &wl, &wh))
        return;
    for (iw = wl; iw <= wh; iw++)
        for (iu = ul; iu <= uh; iu++)
            if (vx_cons_cover(pu, pw, (double)iu + 0.5, (double)iw + 0.5, e))
                fn(ctx, iu, iw, vx_cons_depth(e, pz));
}

/* ---- 8d. solid voxelization by parity -------------------------------------------------- */

/* Options resolved: the parity axis as 0, 1, 2; -1 for an unknown value. */
static int vx_cons_parity_axis(const hfvis_binary_voxel_options *opts)
{
    if (!opts || opts->axis == HFVIS_PARITY_AXIS_DEFAULT) return 2;
    switch (opts->axis) {
    case HFVIS_PARITY_AXIS_X: return 0;
    case HFVIS_PARITY_AXIS_Y: return 1;
    case HFVIS_PARITY_AXIS_Z: return 2;
    default: return -1;
    }
}

/* First layer k whose centre k + 0.5 lies strictly above depth z, clipped to [0, n]. */
static int vx_cons_first_above(double z, int n)
{
    double f;
    int k;
    if (!(z >= 0.5)) return 0; /* also z < 0.5 => layer 0's centre is above */
    if (z >= (double)n - 0.5) return n;
    f = floor(z - 0.5);
    k = (int)f + 1;
    /* fix the rounding of z - 0.5 with exact comparisons (k + 0.5 is exact) */
    while (k > 0 && (double)(k - 1) + 0.5 > z) k--;
    while (k < n && !((double)k + 0.5 > z)) k++;
    return k;
}

typedef struct vx_cons_solid_ctx {
    uint8_t *colpar; /* per column: parity of its crossings */
    uint8_t *occ;    /* NULL in the checking pass */
    size_t stride_u, stride_w, stride_a;
    int nu, na;
} vx_cons_solid_ctx;

static void vx_cons_solid_pixel(void *ctx, int iu, int iw, double z)
{
    vx_cons_solid_ctx *c = (vx_cons_solid_ctx *)ctx;
    c->colpar[(size_t)iw * (size_t)c->nu + (size_t)iu] ^= 1;
    if (c->occ) {
        int k0 = vx_cons_first_above(z, c->na);
        if (k0 < c->na)
            c->occ[(size_t)iu * c->stride_u + (size_t)iw * c->stride_w + (size_t)k0 * c->stride_a] ^= 1;
    }
}

/* Rasterizes every non-degenerate triangle of the mesh into projection a. */
static void vx_cons_raster_mesh(const hfvis_mesh *mesh, const hfvis_volume_grid *grid, int a,
                                vx_cons_pixel_fn fn, void *ctx)
{
    size_t t;
    for (t = 0; t < mesh->triangle_count; t++) {
        double v[3][3];
        int k;
        for (k = 0; k < 3; k++) vx_cons_gvert(mesh, grid, mesh->indices[3 * t + (size_t)k], v[k]);
        if (vx_cons_degenerate(v[0], v[1], v[2])) continue;
        vx_cons_raster(v, a, grid->dims, fn, ctx);
    }
}

HFVIS_API hfvis_status hfvis_voxelize_solid(const hfvis_mesh *mesh, const hfvis_volume_grid *grid,
                                            const hfvis_binary_voxel_options *opts, uint8_t *occ,
                                            size_t *count)
{
    const hfvis_allocator *alloc = opts ? opts->alloc : NULL;
    int a = vx_cons_parity_axis(opts), u, w, allow_open = opts && opts->allow_open;
    size_t ncol, stride[3], i, n = 0, nvox;
    vx_cons_solid_ctx c;
    hfvis_status s;
    if (a < 0) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_cons_args(mesh, grid, occ);
    if (s != HFVIS_OK) return s;
    u = a == 2 ? 0 : a + 1;
    w = a == 0 ? 2 : a - 1;
    stride[0] = 1;
    stride[1] = (size_t)grid->dims[0];
    stride[2] = stride[1] * (size_t)grid->dims[1];
    /* the column-parity block is sized for the largest projection (the checking pass uses all
     * three) */
    ncol = (size_t)grid->dims[0] * (size_t)grid->dims[1];
    if ((size_t)grid->dims[1] * (size_t)grid->dims[2] > ncol)
        ncol = (size_t)grid->dims[1] * (size_t)grid->dims[2];
    if ((size_t)grid->dims[0] * (size_t)grid->dims[2] > ncol)
        ncol = (size_t)grid->dims[0] * (size_t)grid->dims[2];
    memset(&c, 0, sizeof c);
    c.colpar = (uint8_t *)hfvis__alloc(alloc, ncol);
    if (!c.colpar) return HFVIS_ERR_OUT_OF_MEMORY;
    if (!allow_open) {
        /* pass 1: along EACH of the three axes every column must be crossed an even number of
         * times (a closed surface), so the status does not depend on opts->axis: a hole whose
         * plane is parallel to the parity axis is found by another axis */
        int b;
        for (b = 0; b < 3; b++) {
            int bu = b == 2 ? 0 : b + 1, bw = b == 0 ? 2 : b - 1;
            size_t nb = (size_t)grid->dims[bu] * (size_t)grid->dims[bw];
            memset(c.colpar, 0, nb);
            c.nu = grid->dims[bu];
            vx_cons_raster_mesh(mesh, grid, b, vx_cons_solid_pixel, &c);
            for (i = 0; i < nb; i++)
                if (c.colpar[i]) {
                    hfvis__free(alloc, c.colpar);
                    return HFVIS_ERR_FORMAT;
                }
        }
    }
    memset(c.colpar, 0, ncol);
    c.nu = grid->dims[u];
    c.na = grid->dims[a];
    c.stride_u = stride[u];
    c.stride_w = stride[w];
    c.stride_a = stride[a];
    /* pass 2 (Chen & Fang; Eisemann & Decoret 2008): each crossing toggles the first voxel whose
     * centre lies above it; a prefix XOR along the axis then gives the parity of the crossings
     * below every voxel centre. */
    nvox = vx_grid_voxels(grid);
    memset(occ, 0, nvox);
    c.occ = occ;
    vx_cons_raster_mesh(mesh, grid, a, vx_cons_solid_pixel, &c);
    if (a == 0) {
        size_t row, nrows = nvox / stride[1];
        for (row = 0; row < nrows; row++) {
            uint8_t *r = occ + row * stride[1], acc = 0;
            int x;
            for (x = 0; x < grid->dims[0]; x++) r[x] = acc ^= r[x];
        }
    } else {
        /* layers along a are planes (a = 2) or rows inside each z plane (a = 1) */
        size_t plane = a == 2 ? stride[2] : stride[1], blocks = a == 2 ? 1 : (size_t)grid->dims[2];
        size_t blk, layer;
        for (blk = 0; blk < blocks; blk++) {
            uint8_t *base = occ + blk * stride[2];
            for (layer = 1; layer < (size_t)grid->dims[a]; layer++) {
                uint8_t *cur = base + layer * plane;
                const uint8_t *prev = cur - plane;
                for (i = 0; i < plane; i++) cur[i] ^= prev[i];
            }
        }
    }
    if (allow_open) {
        /* columns crossed an odd number of times (an open mesh) are left empty */
        int iu, iw, k;
        for (iw = 0; iw < grid->dims[w]; iw++)
            for (iu = 0; iu < grid->dims[u]; iu++)
                if (c.colpar[(size_t)iw * (size_t)c.nu + (size_t)iu])
                    for (k = 0; k < grid->dims[a]; k++)
                        occ[(size_t)iu * stride[u] + (size_t)iw * stride[w] + (size_t)k * stride[a]] = 0;
    }
    for (i = 0; i < nvox; i++) n += occ[i];
    hfvis__free(alloc, c.colpar);
    if (count) *count = n;
    return HFVIS_OK;
}

/* Solid angle of triangle (a, b, c) seen from the origin, signed by orientation (Van Oosterom &
 * Strackee 1983): tan(Omega/2) = a.(b x c) / (|a||b||c| + (a.b)|c| + (a.c)|b| + (b.c)|a|). */
static double vx_cons_solid_angle(const double a[3], const double b[3], const double c[3])
{
    double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    double lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    double lc = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    double det = a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2])
                 + a[2] * (b[0] * c[1] - b[1] * c[0]);
    double ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    double ac = a[0] * c[0] + a[1] * c[1] + a[2] * c[2];
    double bc = b[0] * c[0] + b[1] * c[1] + b[2] * c[2];
    return 2.0 * atan2(det, la * lb * lc + ab * lc + ac * lb + bc * la);
}

HFVIS_API hfvis_status hfvis_voxelize_solid_reference(const hfvis_mesh *mesh,
                                                      const hfvis_volume_grid *grid,
                                                      const hfvis_binary_voxel_options *opts,
                                                      uint8_t *occ, size_t *count)
{
    size_t n = 0, t, idx = 0;
    int i, j, k;
    hfvis_status s;
    if (vx_cons_parity_axis(opts) < 0) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_cons_args(mesh, grid, occ);
    if (s != HFVIS_OK) return s;
    for (k = 0; k < grid->dims[2]; k++)
        for (j = 0; j < grid->dims[1]; j++)
            for (i = 0; i < grid->dims[0]; i++, idx++) {
                double c[3], wsum = 0.0, wn;
                c[0] = (double)i + 0.5;
                c[1] = (double)j + 0.5;
                c[2] = (double)k + 0.5;
                for (t = 0; t < mesh->triangle_count; t++) {
                    double v[3][3];
                    int q, a;
                    for (q = 0; q < 3; q++) {
                        vx_cons_gvert(mesh, grid, mesh->indices[3 * t + (size_t)q], v[q]);
                        for (a = 0; a < 3; a++) v[q][a] -= c[a];
                    }
                    wsum += vx_cons_solid_angle(v[0], v[1], v[2]);
                }
                /* generalized winding number (Jacobson et al. 2013); parity of its rounding */
                wn = floor(fabs(wsum) / (4.0 * HFVIS__PI) + 0.5);
                occ[idx] = (uint8_t)(fmod(wn, 2.0) == 1.0);
                n += occ[idx];
            }
    if (count) *count = n;
    return HFVIS_OK;
}

/* ---- 8e. watertightness of the index structure ----------------------------------------- */

static int vx_cons_key_cmp(const void *x, const void *y)
{
    uint64_t a = *(const uint64_t *)x, b = *(const uint64_t *)y;
    return a < b ? -1 : (a > b);
}

HFVIS_API hfvis_status hfvis_mesh_is_watertight(const hfvis_mesh *mesh,
                                                const hfvis_allocator *alloc, int *result)
{
    uint64_t *keys;
    size_t t, m, i;
    int ok = 1;
    if (!result || hfvis__mesh_check(mesh) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    if (mesh->triangle_count == 0) {
        *result = 1;
        return HFVIS_OK;
    }
    /* every directed edge a -> b as the key a << 32 | b */
    keys = (uint64_t *)hfvis__alloc_array(alloc, mesh->triangle_count, 3 * sizeof(uint64_t));
    if (!keys) return HFVIS_ERR_OUT_OF_MEMORY;
    m = 3 * mesh->triangle_count;
    for (t = 0; t < mesh->triangle_count && ok; t++) {
        const uint32_t *v = mesh->indices + 3 * t;
        int k;
        for (k = 0; k < 3; k++) {
            uint32_t a = v[k], b = v[k == 2 ? 0 : k + 1];
            if (a == b) ok = 0; /* a repeated index: not a 2-manifold triangle */
            keys[3 * t + (size_t)k] = ((uint64_t)a << 32) | b;
        }
    }
    if (ok) qsort(keys, m, sizeof *keys, vx_cons_key_cmp);
    /* closed and consistently oriented <=> every directed edge occurs once and its reverse too */
    for (i = 0; ok && i < m; i++) {
        uint64_t rev = (keys[i] << 32) | (keys[i] >> 32);
        if (i + 1 < m && keys[i + 1] == keys[i]) ok = 0;
        else if (!bsearch(&rev, keys, m, sizeof *keys, vx_cons_key_cmp)) ok = 0;
    }
    hfvis__free(alloc, keys);
    *result = ok;
    return HFVIS_OK;
}

/* ---- 8f. bitmask voxelization (three-axis OR, slicemap layout) ------------------------- */

HFVIS_API size_t hfvis_bitmask_words(const hfvis_volume_grid *grid)
{
    if (!vx_grid_valid(grid)) return 0;
    /* <= voxels/32 + columns: no overflow for a valid grid */
    return (size_t)grid->dims[0] * (size_t)grid->dims[1] * (((size_t)grid->dims[2] + 31) / 32);
}

typedef struct vx_cons_bits_ctx {
    uint32_t *bits;
    size_t nx, words; /* words per (i, j) column */
    int a, dims[3];
} vx_cons_bits_ctx;

static void vx_cons_bits_pixel(void *ctx, int iu, int iw, double z)
{
    vx_cons_bits_ctx *c = (vx_cons_bits_ctx *)ctx;
    int p[3], k;
    if (!(z >= 0.0) || z >= (double)c->dims[c->a]) return; /* outside the grid's slabs */
    k = (int)z; /* floor: a depth on a slab boundary goes to the upper slab */
    p[c->a] = k;
    p[c->a == 2 ? 0 : c->a + 1] = iu;
    p[c->a == 0 ? 2 : c->a - 1] = iw;
    c->bits[((size_t)p[1] * c->nx + (size_t)p[0]) * c->words + (size_t)(p[2] >> 5)]
        |= (uint32_t)1 << (p[2] & 31);
}

static unsigned vx_cons_popcount32(uint32_t x)
{
    x = x - ((x >> 1) & 0x55555555u);
    x = (x & 0x33333333u) + ((x >> 2) & 0x33333333u);
    x = (x + (x >> 4)) & 0x0f0f0f0fu;
    return (unsigned)((x * 0x01010101u) >> 24);
}

HFVIS_API hfvis_status hfvis_voxelize_bitmask(const hfvis_mesh *mesh, const hfvis_volume_grid *grid,
                                              const hfvis_binary_voxel_options *opts, uint32_t *bits,
                                              size_t *count)
{
    vx_cons_bits_ctx c;
    size_t nw, i, n = 0;
    int a;
    hfvis_status s = vx_cons_args(mesh, grid, bits);
    (void)opts;
    if (s != HFVIS_OK) return s;
    nw = hfvis_bitmask_words(grid);
    memset(bits, 0, nw * sizeof *bits);
    c.bits = bits;
    c.nx = (size_t)grid->dims[0];
    c.words = ((size_t)grid->dims[2] + 31) / 32;
    for (a = 0; a < 3; a++) c.dims[a] = grid->dims[a];
    /* Eisemann & Decoret 2006 from three viewpoints: every pass rasterizes every triangle with
     * the pixel-centre rule and ORs the bit of the slab holding its depth */
    for (a = 0; a < 3; a++) {
        c.a = a;
        vx_cons_raster_mesh(mesh, grid, a, vx_cons_bits_pixel, &c);
    }
    for (i = 0; i < nw; i++) n += vx_cons_popcount32(bits[i]);
    if (count) *count = n;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_bitmask_to_occupancy(const hfvis_volume_grid *grid,
                                                  const uint32_t *bits, uint8_t *occ)
{
    size_t nx, ny, nz, words, i, j, k;
    if (!bits || !occ || !vx_grid_valid(grid)) return HFVIS_ERR_INVALID_ARGUMENT;
    nx = (size_t)grid->dims[0];
    ny = (size_t)grid->dims[1];
    nz = (size_t)grid->dims[2];
    words = (nz + 31) / 32;
    for (k = 0; k < nz; k++)
        for (j = 0; j < ny; j++)
            for (i = 0; i < nx; i++)
                occ[(k * ny + j) * nx + i]
                    = (uint8_t)((bits[(j * nx + i) * words + (k >> 5)] >> (k & 31)) & 1u);
    return HFVIS_OK;
}

/* ---- 8g. .binvox codec and the raw writer ---------------------------------------------- */
/* binvox (P. Min's voxelizer and viewvox; format by M. Kazhdan): an ASCII header
 *   "#binvox 1\n" "dim D D D\n" "translate tx ty tz\n" "scale s\n" "data\n"
 * then run-length pairs of bytes (value, count), count 1..255, over the D^3 voxels in the order
 * x slowest, then z, then y fastest (index x*D*D + z*D + y); voxel (x, y, z) spans
 * translate + scale*[x, x+1]/D (and likewise y, z). Numbers are written and read without the C
 * library (locale-independent). */

/* Decimal number parser: [+-] digits [. digits] [(e|E) [+-] digits], or [+-] . digits ...
 * Exactly rounded when at most 19 significant digits form a mantissa <= 2^53 and the decimal
 * exponent is within +-22 (Clinger's fast path: m and 10^|e| are exact doubles, one rounding);
 * otherwise within a few ulps. Advances *i; returns 0 on a malformed or non-finite number. */
static int vx_cons_parse_number(const unsigned char *p, size_t n, size_t *i, double *out)
{
    static const double pow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                     1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                     1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
    size_t j = *i;
    uint64_t m = 0;
    long e10 = 0, ex = 0;
    int neg = 0, digits = 0, sig = 0, eneg = 0;
    double v;
    if (j < n && (p[j] == '+' || p[j] == '-')) neg = p[j++] == '-';
    for (; j < n && p[j] >= '0' && p[j] <= '9'; j++, digits++) {
        if (sig < 19) {
            m = m * 10u + (unsigned)(p[j] - '0');
            sig += m != 0;
        } else if (e10 < 100000) {
            e10++;
        }
    }
    if (j < n && p[j] == '.') {
        for (j++; j < n && p[j] >= '0' && p[j] <= '9'; j++, digits++) {
            if (sig < 19) {
                m = m * 10u + (unsigned)(p[j] - '0');
                sig += m != 0;
                e10--;
            }
        }
    }
    if (digits == 0) return 0;
    if (j < n && (p[j] == 'e' || p[j] == 'E')) {
        j++;
        if (j < n && (p[j] == '+' || p[j] == '-')) eneg = p[j++] == '-';
        if (j >= n || p[j] < '0' || p[j] > '9') return 0;
        for (; j < n && p[j] >= '0' && p[j] <= '9'; j++)
            if (ex < 100000) ex = ex * 10 + (long)(p[j] - '0');
    }
    e10 += eneg ? -ex : ex;
    if (m == 0) {
        v = 0.0;
    } else if (m <= ((uint64_t)1 << 53) && e10 >= -22 && e10 <= 22) {
        v = e10 >= 0 ? (double)m * pow10[e10] : (double)m / pow10[-e10];
    } else {
        if (e10 > 400) e10 = 400;
        if (e10 < -400) e10 = -400;
        v = (double)m * pow(10.0, (double)(e10 / 2)) * pow(10.0, (double)(e10 - e10 / 2));
    }
    if (!isfinite(v)) return 0;
    *out = neg ? -v : v;
    *i = j;
    return 1;
}

/* Writes finite x in at most 25 characters (no terminator): the fewest significant digits
 * (1..15) that vx_cons_parse_number reads back as exactly x, else 17 digits (within a few
 * ulps). Plain notation for decimal exponents -5..15, else d.ddde+XX. Returns the length. */
static size_t vx_cons_format_number(double x, char *out)
{
    static const double pow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                     1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                     1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
    char dig[24], buf[40];
    size_t len = 0;
    int prec, e10, nd = 0, k;
    double ax = fabs(x);
    HFVIS_ASSERT(isfinite(x));
    if (ax == 0.0 || !isfinite(x)) {
        out[0] = '0';
        return 1;
    }
    e10 = (int)floor(log10(ax));
    for (prec = 1; prec <= 17; prec++) {
        /* q = round(ax * 10^(prec-1-e10)) (approximately), so ax ~ q * 10^(e10-prec+1) */
        int sh = prec - 1 - e10, lead;
        double m;
        uint64_t q;
        if (prec == 16) continue;
        if (sh >= 0 && sh <= 22) m = ax * pow10[sh];
        else if (sh < 0 && sh >= -22) m = ax / pow10[-sh];
        else m = ax * pow(10.0, (double)(sh / 2)) * pow(10.0, (double)(sh - sh / 2));
        m = floor(m + 0.5);
        if (m >= 1e17) { /* only when log10 misjudged the exponent: drop a digit */
            m = floor(m / 10.0 + 0.5);
            sh--;
        }
        if (m < 1.0) m = 1.0;
        q = (uint64_t)m;
        nd = 0;
        while (q) {
            dig[nd++] = (char)('0' + (int)(q % 10u));
            q /= 10u;
        }
        lead = nd - 1 - sh; /* power of ten of the leading digit dig[nd-1] */
        while (nd > 1 && dig[0] == '0') { /* trailing zeros of the digit string */
            for (k = 0; k + 1 < nd; k++) dig[k] = dig[k + 1];
            nd--;
        }
        len = 0;
        if (x < 0.0) buf[len++] = '-';
        if (lead >= -5 && lead <= 15) {
            int place;
            if (lead < 0) {
                buf[len++] = '0';
                buf[len++] = '.';
                for (place = -1; place > lead; place--) buf[len++] = '0';
            }
            for (k = 0; k < nd; k++) {
                place = lead - k;
                buf[len++] = dig[nd - 1 - k];
                if (place == 0 && k + 1 < nd) buf[len++] = '.';
            }
            for (place = lead - nd; place >= 0; place--) buf[len++] = '0';
        } else {
            int ee = lead < 0 ? -lead : lead;
            buf[len++] = dig[nd - 1];
            if (nd > 1) {
                buf[len++] = '.';
                for (k = 1; k < nd; k++) buf[len++] = dig[nd - 1 - k];
            }
            buf[len++] = 'e';
            buf[len++] = lead < 0 ? '-' : '+';
            if (ee >= 100) buf[len++] = (char)('0' + ee / 100);
            buf[len++] = (char)('0' + ee / 10 % 10);
            buf[len++] = (char)('0' + ee % 10);
        }
        if (prec <= 15) {
            size_t at = 0;
            double back;
            if (vx_cons_parse_number((const unsigned char *)buf, len, &at, &back) && at == len
                && back == x)
                break;
        }
    }
    memcpy(out, buf, len);
    return len;
}

/* The binvox header of a grid padded to the cube of side d, into out (NULL: only measure).
 * translate = origin, scale = d * max(cell): binvox has one scale, so non-cubic voxels are
 * written with the largest cell (documented). */
static size_t vx_cons_binvox_header(const hfvis_volume_grid *g, int d, char *out)
{
    char tmp[256];
    size_t len = 0, k;
    int a;
    double cell = vx_cons_max3(g->cell[0], g->cell[1], g->cell[2]);
    char num[12];
    int nn = 0, q = d;
    static const char head[] = "#binvox 1\ndim ";
    memcpy(tmp, head, sizeof head - 1);
    len = sizeof head - 1;
    do {
        num[nn++] = (char)('0' + q % 10);
        q /= 10;
    } while (q);
    for (a = 0; a < 3; a++) {
        for (k = 0; k < (size_t)nn; k++) tmp[len++] = num[nn - 1 - (int)k];
        tmp[len++] = a < 2 ? ' ' : '\n';
    }
    memcpy(tmp + len, "translate ", 10);
    len += 10;
    for (a = 0; a < 3; a++) {
        len += vx_cons_format_number(g->origin[a], tmp + len);
        tmp[len++] = a < 2 ? ' ' : '\n';
    }
    memcpy(tmp + len, "scale ", 6);
    len += 6;
    len += vx_cons_format_number((double)d * cell, tmp + len);
    memcpy(tmp + len, "\ndata\n", 6);
    len += 6;
    if (out) memcpy(out, tmp, len);
    return len;
}

/* Side of the binvox cube for a valid grid; 0 when d^3 exceeds HFVIS_VOLUME_MAX_VOXELS or the
 * scale d * max(cell) overflows a double. */
static int vx_cons_binvox_side(const hfvis_volume_grid *g)
{
    int d = g->dims[0] > g->dims[1] ? g->dims[0] : g->dims[1];
    size_t dd = 1;
    if (g->dims[2] > d) d = g->dims[2];
    if (!hfvis__mul_size(dd, (size_t)d, &dd) || !hfvis__mul_size(dd, (size_t)d, &dd)
        || !hfvis__mul_size(dd, (size_t)d, &dd) || dd > HFVIS_VOLUME_MAX_VOXELS
        || !isfinite((double)d * vx_cons_max3(g->cell[0], g->cell[1], g->cell[2])))
        return 0;
    return d;
}

/* Runs the binvox RLE over the padded cube; writes pairs into out when not NULL. Returns the
 * number of bytes of the pairs. */
static size_t vx_cons_binvox_rle(const hfvis_volume_grid *g, const uint8_t *occ, int d,
                                 unsigned char *out)
{
    size_t nx = (size_t)g->dims[0], ny = (size_t)g->dims[1], nz = (size_t)g->dims[2], bytes = 0;
    size_t x, y, z, D = (size_t)d;
    unsigned run = 0, cur = 0;
    for (x = 0; x < D; x++)
        for (z = 0; z < D; z++)
            for (y = 0; y < D; y++) {
                unsigned v = (x < nx && y < ny && z < nz) ? occ[(z * ny + y) * nx + x] != 0 : 0u;
                if (run > 0 && (v != cur || run == 255)) {
                    if (out) {
                        out[bytes] = (unsigned char)cur;
                        out[bytes + 1] = (unsigned char)run;
                    }
                    bytes += 2;
                    run = 0;
                }
                cur = v;
                run++;
            }
    if (out) {
        out[bytes] = (unsigned char)cur;
        out[bytes + 1] = (unsigned char)run;
    }
    return bytes + 2;
}

HFVIS_API size_t hfvis_binvox_encode_size(const hfvis_volume_grid *grid, const uint8_t *occ)
{
    int d;
    if (!occ || !vx_grid_valid(grid) || (d = vx_cons_binvox_side(grid)) == 0) return 0;
    return vx_cons_binvox_header(grid, d, NULL) + vx_cons_binvox_rle(grid, occ, d, NULL);
}

HFVIS_API hfvis_status hfvis_binvox_encode(const hfvis_volume_grid *grid, const uint8_t *occ,
                                           void *out, size_t capacity, size_t *written)
{
    size_t head, need;
    int d;
    if (!occ || !out || !written || !vx_grid_valid(grid)) return HFVIS_ERR_INVALID_ARGUMENT;
    d = vx_cons_binvox_side(grid);
    if (d == 0) return HFVIS_ERR_LIMIT;
    need = hfvis_binvox_encode_size(grid, occ);
    if (capacity < need) return HFVIS_ERR_BUFFER_TOO_SMALL;
    head = vx_cons_binvox_header(grid, d, (char *)out);
    vx_cons_binvox_rle(grid, occ, d, (unsigned char *)out + head);
    *written = need;
    return HFVIS_OK;
}

/* Skips blanks (space, tab) from p[*i]. */
static void vx_cons_skip_blank(const unsigned char *p, size_t n, size_t *i)
{
    while (*i < n && (p[*i] == ' ' || p[*i] == '\t')) (*i)++;
}

/* The end of a header line: optional blanks, optional '\r', then '\n'. */
static int vx_cons_line_end(const unsigned char *p, size_t n, size_t *i)
{
    vx_cons_skip_blank(p, n, i);
    if (*i < n && p[*i] == '\r') (*i)++;
    if (*i >= n || p[*i] != '\n') return 0;
    (*i)++;
    return 1;
}

/* A keyword at p[*i] followed by a blank or the line end. */
static int vx_cons_keyword(const unsigned char *p, size_t n, size_t *i, const char *kw)
{
    size_t len = strlen(kw);
    if (n - *i < len || memcmp(p + *i, kw, len) != 0) return 0;
    if (*i + len < n && p[*i + len] != ' ' && p[*i + len] != '\t' && p[*i + len] != '\r'
        && p[*i + len] != '\n')
        return 0;
    *i += len;
    return 1;
}

/* Unsigned decimal after blanks (at least one blank first); values above cap saturate at
 * cap + 1. */
static int vx_cons_parse_uint(const unsigned char *p, size_t n, size_t *i, unsigned long cap,
                              unsigned long *out)
{
    size_t j = *i;
    unsigned long v = 0;
    vx_cons_skip_blank(p, n, &j);
    if (j == *i || j >= n || p[j] < '0' || p[j] > '9') return 0;
    for (; j < n && p[j] >= '0' && p[j] <= '9'; j++) {
        unsigned long dg = (unsigned long)(p[j] - '0');
        v = (v > (cap - dg) / 10) ? cap + 1 : v * 10 + dg;
    }
    *i = j;
    *out = v;
    return 1;
}

/* A number after at least one blank. */
static int vx_cons_parse_field(const unsigned char *p, size_t n, size_t *i, double *out)
{
    size_t j = *i;
    vx_cons_skip_blank(p, n, &j);
    if (j == *i) return 0;
    if (!vx_cons_parse_number(p, n, &j, out)) return 0;
    if (j < n && p[j] != ' ' && p[j] != '\t' && p[j] != '\r' && p[j] != '\n') return 0;
    *i = j;
    return 1;
}

HFVIS_API hfvis_status hfvis_binvox_decode(const void *data, size_t size,
                                           const hfvis_allocator *alloc, hfvis_volume_grid *grid,
                                           uint8_t **occ)
{
    const unsigned char *p = (const unsigned char *)data;
    size_t i = 0, total, got = 0, j, D, DD;
    unsigned long version, dims[3];
    double translate[3] = {0.0, 0.0, 0.0}, scale = 1.0;
    int have_dim = 0, have_t = 0, have_s = 0, a;
    hfvis_volume_grid g;
    uint8_t *o;
    if (!data || !grid || !occ) return HFVIS_ERR_INVALID_ARGUMENT;
    if (!vx_cons_keyword(p, size, &i, "#binvox") || !vx_cons_parse_uint(p, size, &i, 9, &version)
        || (version != 1 && version != 2) || !vx_cons_line_end(p, size, &i))
        return HFVIS_ERR_FORMAT;
    for (;;) {
        if (vx_cons_keyword(p, size, &i, "data")) {
            if (!vx_cons_line_end(p, size, &i)) return HFVIS_ERR_FORMAT;
            break;
        } else if (vx_cons_keyword(p, size, &i, "dim")) {
            if (have_dim) return HFVIS_ERR_FORMAT;
            for (a = 0; a < 3; a++)
                if (!vx_cons_parse_uint(p, size, &i, (unsigned long)INT_MAX, &dims[a]) || dims[a] == 0)
                    return HFVIS_ERR_FORMAT;
            have_dim = 1;
        } else if (vx_cons_keyword(p, size, &i, "translate")) {
            if (have_t) return HFVIS_ERR_FORMAT;
            for (a = 0; a < 3; a++)
                if (!vx_cons_parse_field(p, size, &i, &translate[a])) return HFVIS_ERR_FORMAT;
            have_t = 1;
        } else if (vx_cons_keyword(p, size, &i, "scale")) {
            if (have_s || !vx_cons_parse_field(p, size, &i, &scale) || !(scale > 0.0))
                return HFVIS_ERR_FORMAT;
            have_s = 1;
        } else {
            return HFVIS_ERR_FORMAT; /* unknown line, blank line or end of data */
        }
        if (!vx_cons_line_end(p, size, &i)) return HFVIS_ERR_FORMAT;
    }
    if (!have_dim || dims[0] != dims[1] || dims[1] != dims[2]) return HFVIS_ERR_FORMAT;
    if (dims[0] > (unsigned long)INT_MAX) return HFVIS_ERR_LIMIT;
    D = (size_t)dims[0];
    if (!hfvis__mul_size(D, D, &DD) || !hfvis__mul_size(DD, D, &total) || total > HFVIS_VOLUME_MAX_VOXELS)
        return HFVIS_ERR_LIMIT;
    for (a = 0; a < 3; a++) {
        g.dims[a] = (int)D;
        g.origin[a] = translate[a];
        g.cell[a] = scale / (double)D;
    }
    if (!vx_grid_valid(&g)) return HFVIS_ERR_FORMAT; /* e.g. a scale that underflows */
    /* validate the runs before allocating: pairs, values, counts, exact total, no trailing byte */
    if ((size - i) % 2 != 0) return HFVIS_ERR_FORMAT;
    for (j = i; j < size; j += 2) {
        if ((version == 1 && p[j] > 1) || p[j + 1] == 0 || got >= total) return HFVIS_ERR_FORMAT;
        got += p[j + 1];
        if (got > total) return HFVIS_ERR_FORMAT;
    }
    if (got != total) return HFVIS_ERR_FORMAT;
    o = (uint8_t *)hfvis__alloc(alloc, total);
    if (!o) return HFVIS_ERR_OUT_OF_MEMORY;
    {
        size_t x = 0, y = 0, z = 0; /* binvox order: y fastest, then z, then x */
        for (j = i; j < size; j += 2) {
            unsigned c = p[j + 1];
            while (c--) {
                o[(z * D + y) * D + x] = p[j];
                if (++y == D) {
                    y = 0;
                    if (++z == D) {
                        z = 0;
                        x++;
                    }
                }
            }
        }
    }
    *grid = g;
    *occ = o;
    return HFVIS_OK;
}

#ifndef HFVIS_NO_STDIO
HFVIS_API hfvis_status hfvis_binvox_save(const char *path, const hfvis_volume_grid *grid,
                                         const uint8_t *occ)
{
    size_t need, written = 0;
    unsigned char *buf;
    hfvis_status s;
    if (!path || !occ || !vx_grid_valid(grid)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (vx_cons_binvox_side(grid) == 0) return HFVIS_ERR_LIMIT;
    need = hfvis_binvox_encode_size(grid, occ);
    buf = (unsigned char *)hfvis__alloc(NULL, need);
    if (!buf) return HFVIS_ERR_OUT_OF_MEMORY;
    s = hfvis_binvox_encode(grid, occ, buf, need, &written);
    if (s == HFVIS_OK) s = hfvis_write_file(path, buf, written, NULL);
    hfvis__free(NULL, buf);
    return s;
}

/* The binvox sizer (hfvis__read_file): the magic first; the run-length body has no announced
 * size, so the rest is read whole. */
static hfvis_status vx_binvox_sizer(const unsigned char *head, size_t n, size_t *total)
{
    size_t i = 0;
    (void)total;
    return vx_cons_keyword(head, n, &i, "#binvox") ? HFVIS_OK : HFVIS_ERR_FORMAT;
}

HFVIS_API hfvis_status hfvis_binvox_load(const char *path, const hfvis_allocator *alloc,
                                         hfvis_volume_grid *grid, uint8_t **occ)
{
    unsigned char *data = NULL;
    size_t size = 0;
    hfvis_status s;
    if (!path || !grid || !occ) return HFVIS_ERR_INVALID_ARGUMENT;
    s = hfvis__read_file(path, alloc, vx_binvox_sizer, &data, &size);
    if (s != HFVIS_OK) return s;
    s = hfvis_binvox_decode(data, size, alloc, grid, occ);
    hfvis__free(alloc, data);
    return s;
}

HFVIS_API hfvis_status hfvis_voxels_raw_save(const char *path, const hfvis_volume_grid *grid,
                                             const uint8_t *voxels)
{
    if (!path || !voxels || !vx_grid_valid(grid)) return HFVIS_ERR_INVALID_ARGUMENT;
    return hfvis_write_file(path, voxels, vx_grid_voxels(grid), NULL);
}
#endif /* HFVIS_NO_STDIO */

/* ========================================================================================== */
/* 9. Incremental image-based multi-valued voxelization ([G12] ch. 7)                         */
/*   9.1 depth images, options, channel maps                                                 */
/*   9.2 classification of a voxel centre: eq. 16 (sign restored), eq. 17 with the bias b,   */
/*        Fig. 70's three zones; the conservative footprint and its min-depth pyramid         */
/*   9.3 cleanup (Alg. 7 "Cleanup", Listing 7.1) and single-pass IV (§7.4.3)                 */
/*   9.4 injection (Listing 7.2), Alg. 7 as one frame, the lighting variant (§7.5)           */
/*   9.5 Table 9 distance metric: exact point-triangle distance, two BVHs, seeded sampling   */
/* ========================================================================================== */

/* ---- 9.1 depth images, options, channel maps ------------------------------------------- */

#define VX_IV_STACK 256 /* BVH traversal stack (median splits: depth <= 33 for 2^32 items) */

/* Everything a pass needs of one image: the rows of view and proj*view that the classification
 * evaluates, as ((r[3] + r[2] z) + r[1] y) + r[0] x (the order the hoisted loops use). */
typedef struct vx_iv_img {
    double ez[4];             /* row 2 of view: eye-space z */
    double cx[4], cy[4], cw[4]; /* rows 0, 1, 3 of proj*view: clip x, y, w */
    double n, f;
    int ortho, w, h;
    const float *depth;
    const float *attr;
    int nattr;
    const float *pyr;         /* conservative footprint: min-depth pyramid levels 1.. or NULL */
    int levels;
    size_t lev_off[40];
    int lev_w[40], lev_h[40];
} vx_iv_img;

/* Resolved options. */
typedef struct vx_iv_opt {
    double bias;
    int conservative;
    int occ;                  /* occupancy channel or -1 */
    int gw, gh;
    const int *map;           /* explicit attribute map or NULL */
    const hfvis_allocator *alloc;
} vx_iv_opt;

HFVIS_API hfvis_iv_options hfvis_iv_options_default(void)
{
    hfvis_iv_options o;
    memset(&o, 0, sizeof o);
    o.bias_rule = HFVIS_IV_BIAS_HALF_DIAGONAL;
    o.bias = 0.0;
    o.footprint = HFVIS_IV_FOOTPRINT_CENTER;
    o.occupancy_channel = 0;
    o.attribute_channels = NULL;
    o.grid_width = 0;
    o.grid_height = 0;
    o.alloc = NULL;
    return o;
}

HFVIS_API double hfvis_iv_bias_half_diagonal(const hfvis_volume_grid *grid)
{
    if (!vx_grid_valid(grid)) return (double)NAN;
    return 0.5 * sqrt(grid->cell[0] * grid->cell[0] + grid->cell[1] * grid->cell[1]
                      + grid->cell[2] * grid->cell[2]);
}

HFVIS_API hfvis_status hfvis_iv_bias(const hfvis_volume_grid *grid, const hfvis_iv_options *opts,
                                     double *out)
{
    double b;
    hfvis_iv_bias_rule rule = opts ? opts->bias_rule : HFVIS_IV_BIAS_HALF_DIAGONAL;
    if (!out || !vx_grid_valid(grid)) return HFVIS_ERR_INVALID_ARGUMENT;
    switch (rule) {
    case HFVIS_IV_BIAS_HALF_DIAGONAL: b = hfvis_iv_bias_half_diagonal(grid); break;
    case HFVIS_IV_BIAS_FULL_DIAGONAL: b = 2.0 * hfvis_iv_bias_half_diagonal(grid); break;
    case HFVIS_IV_BIAS_EXPLICIT:
        b = opts->bias;
        if (!isfinite(b) || !(b >= 0.0)) return HFVIS_ERR_INVALID_ARGUMENT;
        break;
    default: return HFVIS_ERR_INVALID_ARGUMENT;
    }
    if (!isfinite(b)) return HFVIS_ERR_INVALID_ARGUMENT;
    *out = b;
    return HFVIS_OK;
}

/* 1 when vol is a usable Volume Buffer. */
static int vx_iv_volume_ok(const hfvis_volume *vol)
{
    return vol && vol->data && vol->channels >= 1 && vol->channels <= HFVIS_VOLUME_MAX_CHANNELS
           && hfvis_volume_floats(&vol->grid, vol->channels) != 0;
}

static int vx_iv_same_grid(const hfvis_volume_grid *a, const hfvis_volume_grid *b)
{
    int i;
    for (i = 0; i < 3; i++)
        if (a->dims[i] != b->dims[i] || a->origin[i] != b->origin[i] || a->cell[i] != b->cell[i])
            return 0;
    return 1;
}

/* Options against a volume of `channels` channels (channels 0: no volume, e.g. classify); the
 * bias is resolved for grid. */
static hfvis_status vx_iv_resolve(const hfvis_iv_options *opts, const hfvis_volume_grid *grid,
                                  int channels, vx_iv_opt *o)
{
    hfvis_iv_options d = hfvis_iv_options_default();
    hfvis_status s;
    if (!opts) opts = &d;
    if (opts->footprint != HFVIS_IV_FOOTPRINT_CENTER
        && opts->footprint != HFVIS_IV_FOOTPRINT_CONSERVATIVE)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (opts->grid_width < 0 || opts->grid_height < 0) return HFVIS_ERR_INVALID_ARGUMENT;
    if (opts->occupancy_channel < HFVIS_IV_NO_CHANNEL
        || (channels > 0 && opts->occupancy_channel >= channels))
        return HFVIS_ERR_INVALID_ARGUMENT;
    s = hfvis_iv_bias(grid, opts, &o->bias);
    if (s != HFVIS_OK) return s;
    o->conservative = opts->footprint == HFVIS_IV_FOOTPRINT_CONSERVATIVE;
    o->occ = opts->occupancy_channel;
    o->gw = opts->grid_width;
    o->gh = opts->grid_height;
    o->map = opts->attribute_channels;
    o->alloc = opts->alloc;
    return HFVIS_OK;
}

/* Channel of attribute a (< nattr) for a volume of `channels` channels, written to map[a]
 * (-1 = dropped). HFVIS_ERR_INVALID_ARGUMENT when the map is bad (see hfvis_iv_options). */
static hfvis_status vx_iv_channel_map(const vx_iv_opt *o, int nattr, int channels, int *map)
{
    int a, b, c = 0;
    for (a = 0; a < nattr; a++) {
        if (o->map) {
            map[a] = o->map[a];
            if (map[a] < HFVIS_IV_NO_CHANNEL || map[a] >= channels
                || (map[a] >= 0 && map[a] == o->occ))
                return HFVIS_ERR_INVALID_ARGUMENT;
            for (b = 0; b < a; b++)
                if (map[a] >= 0 && map[b] == map[a]) return HFVIS_ERR_INVALID_ARGUMENT;
        } else {
            if (c == o->occ) c++;
            if (c >= channels) return HFVIS_ERR_INVALID_ARGUMENT;
            map[a] = c++;
        }
    }
    return HFVIS_OK;
}

/* Validate one depth image and fill the per-image rows. */
static hfvis_status vx_iv_image(const hfvis_depth_image *im, vx_iv_img *out)
{
    const hfvis_view *v;
    double m[16];
    size_t px, na;
    int r;
    if (!im || !im->depth) return HFVIS_ERR_INVALID_ARGUMENT;
    v = &im->view;
    if (v->width < 1 || v->height < 1 || !hfvis__all_finite(v->view, 16) || !hfvis__all_finite(v->proj, 16)
        || !isfinite(v->near_plane) || !isfinite(v->far_plane)
        || !(v->near_plane < v->far_plane) || (!v->orthographic && !(v->near_plane > 0.0)))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (im->attribute_count < 0 || im->attribute_count > HFVIS_VOLUME_MAX_CHANNELS
        || (im->attribute_count > 0 && !im->attributes))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (!hfvis__mul_size((size_t)v->width, (size_t)v->height, &px)
        || !hfvis__mul_size(px, (size_t)(im->attribute_count > 0 ? im->attribute_count : 1), &na))
        return HFVIS_ERR_INVALID_ARGUMENT;
    hfvis_mat4_multiply(v->proj, v->view, m);
    if (!hfvis__all_finite(m, 16)) return HFVIS_ERR_INVALID_ARGUMENT;
    memset(out, 0, sizeof *out);
    for (r = 0; r < 4; r++) {
        out->ez[r] = VX_M(v->view, 2, r);
        out->cx[r] = VX_M(m, 0, r);
        out->cy[r] = VX_M(m, 1, r);
        out->cw[r] = VX_M(m, 3, r);
    }
    out->n = v->near_plane;
    out->f = v->far_plane;
    out->ortho = v->orthographic ? 1 : 0;
    out->w = v->width;
    out->h = v->height;
    out->depth = im->depth;
    out->attr = im->attribute_count > 0 ? im->attributes : NULL;
    out->nattr = im->attribute_count;
    return HFVIS_OK;
}

/* The affine row in the fixed evaluation order ((r3 + r2 z) + r1 y) + r0 x. */
static double vx_iv_row(const double r[4], double x, double y, double z)
{
    return ((r[3] + r[2] * z) + r[1] * y) + r[0] * x;
}

/* ---- 9.2 classification ---------------------------------------------------------------- */

/* A depth texel usable as information: zw in [0, 1] (NaN and out-of-range values are no-data). */
static int vx_iv_texel_ok(float zw)
{
    return zw >= 0.0f && zw <= 1.0f;
}

/* Eq. 17 against one valid texel zw, for a point of eye z ez: CLEARED if ez > z_e + b, else
 * KEPT for a background texel (zw = 1) or ez < z_e - b, else BAND; z_e by eq. 16 (sign restored,
 * hfvis_depth_to_eye_z) in double. The decision is that literal comparison; for perspective views
 * it is usually reached without the division of eq. 16: with D = f - zw (f - n) > 0,
 * ez - b - z_e = ((ez - b) D + n f) / D, so the sign of P = (ez - b) D + n f decides unless |P| is
 * within t = 1e-12 ((|ez| + b) D + 2 n f) - about 10^4 times the rounding of both forms - and
 * likewise Q = (ez + b) D + n f for the band; inside t the literal form is evaluated. */
static hfvis_iv_class vx_iv_zone(const vx_iv_img *im, double b, double ez, float zw)
{
    double ze;
    if (!im->ortho) {
        double D = im->f - (double)zw * (im->f - im->n), nf = im->n * im->f;
        double P = (ez - b) * D + nf, Q = (ez + b) * D + nf;
        double t = 1e-12 * ((fabs(ez) + b) * D + 2.0 * nf);
        if (P > t) return HFVIS_IV_CLEARED;
        if (P < -t) {
            if (zw == 1.0f || Q < -t) return HFVIS_IV_KEPT;
            if (Q > t) return HFVIS_IV_BAND;
        }
    }
    ze = hfvis_depth_to_eye_z((double)zw, im->n, im->f, im->ortho); /* eq. 16, sign restored */
    if (ez > ze + b) return HFVIS_IV_CLEARED; /* eq. 17: in front of the recorded surface (v1) */
    if (zw == 1.0f) return HFVIS_IV_KEPT;     /* background: nothing to update */
    if (ez < ze - b) return HFVIS_IV_KEPT;    /* behind the surface (v3) */
    return HFVIS_IV_BAND;                     /* surface band (v2) */
}

/* The classification of a point with eye z `ez` and clip (X, Y, W) ([G12] ch. 7, Alg. 7, eq. 17; docs/errata.md E55): UNSEEN
 * without information, else the zone of its texel. Writes the texel read (or -1, -1). */
static hfvis_iv_class vx_iv_decide(const vx_iv_img *im, double b, double ez, double X, double Y,
                                   double W, int *opx, int *opy)
{
    double inv, nx, ny, sx, sy;
    int px, py;
    float zw;
    *opx = -1;
    *opy = -1;
    /* behind the camera, or nearer than the near plane (NDC z < -1; no information) [C] */
    if (!(W > 0.0) || !(ez <= -im->n)) return HFVIS_IV_UNSEEN;
    inv = 1.0 / W;
    nx = X * inv;
    ny = Y * inv;
    if (!(nx >= -1.0 && nx <= 1.0 && ny >= -1.0 && ny <= 1.0)) return HFVIS_IV_UNSEEN;
    /* nearest texel, row 0 at the top: (floor((ndc_x+1)/2 W), floor((1-ndc_y)/2 H)), clamped */
    sx = (nx + 1.0) * 0.5 * (double)im->w;
    sy = (1.0 - ny) * 0.5 * (double)im->h;
    px = (int)sx; /* sx >= 0: truncation is floor */
    py = (int)sy;
    if (px > im->w - 1) px = im->w - 1;
    if (py > im->h - 1) py = im->h - 1;
    *opx = px;
    *opy = py;
    zw = im->depth[(size_t)py * (size_t)im->w + (size_t)px];
    if (!vx_iv_texel_ok(zw)) return HFVIS_IV_UNSEEN;
    return vx_iv_zone(im, b, ez, zw);
}

/* Offsets of the 8 corners of a voxel about its centre in one row: +-(r[0] hx), ... */
typedef struct vx_iv_corner_rows {
    double a[4][3]; /* [row: ez, X, Y, W][axis] = r[axis] * half_cell[axis] */
} vx_iv_corner_rows;

static void vx_iv_corner_setup(const vx_iv_img *im, const hfvis_volume_grid *g,
                               vx_iv_corner_rows *cr)
{
    int a;
    for (a = 0; a < 3; a++) {
        double h = 0.5 * g->cell[a];
        cr->a[0][a] = im->ez[a] * h;
        cr->a[1][a] = im->cx[a] * h;
        cr->a[2][a] = im->cy[a] * h;
        cr->a[3][a] = im->cw[a] * h;
    }
}

/* Minimum over a clipped pixel rectangle of the min-depth pyramid (sentinel -1 = no-data). */
static float vx_iv_pyr_min(const vx_iv_img *im, int x0, int x1, int y0, int y1)
{
    int L = 1, x, y;
    float m = 2.0f;
    while (L < im->levels && (((x1 >> L) - (x0 >> L)) > 1 || ((y1 >> L) - (y0 >> L)) > 1)) L++;
    HFVIS_ASSERT(L < im->levels); /* the top level is 1 x 1 */
    {
        const float *lev = im->pyr + im->lev_off[L];
        int lw = im->lev_w[L];
        for (y = y0 >> L; y <= (y1 >> L); y++)
            for (x = x0 >> L; x <= (x1 >> L); x++) {
                float v = lev[(size_t)y * (size_t)lw + (size_t)x];
                if (v < m) m = v;
            }
    }
    return m;
}

/* Conservative footprint (docs/errata.md E63): 1 if the clear of a voxel whose centre test
 * cleared is vetoed: a corner before the near plane or behind the camera, or a pixel whose
 * centre lies in the bounding box of the projected corners that is no-data or does not clear
 * (p'_z > z_e + b fails). With a pyramid, a rectangle whose minimum depth clears is accepted
 * without a scan: z_e(zw) falls as zw grows (every step of eq. 16 is monotone), so the minimum
 * clearing implies every texel clears (vx_iv_zone decides exactly as the literal form, whose
 * every step is monotone in zw), and the answer is the scan's bit for bit. */
static int vx_iv_veto(const vx_iv_img *im, const vx_iv_corner_rows *cr, double b, double ez,
                      double X, double Y, double W)
{
    double nx0 = HUGE_VAL, nx1 = -HUGE_VAL, ny0 = HUGE_VAL, ny1 = -HUGE_VAL;
    double fx0, fx1, fy0, fy1;
    int c, x0, x1, y0, y1, x, y;
    for (c = 0; c < 8; c++) {
        double sx = (c & 1) ? 1.0 : -1.0, sy = (c & 2) ? 1.0 : -1.0, sz = (c & 4) ? 1.0 : -1.0;
        double cez = ((ez + sx * cr->a[0][0]) + sy * cr->a[0][1]) + sz * cr->a[0][2];
        double cX = ((X + sx * cr->a[1][0]) + sy * cr->a[1][1]) + sz * cr->a[1][2];
        double cY = ((Y + sx * cr->a[2][0]) + sy * cr->a[2][1]) + sz * cr->a[2][2];
        double cW = ((W + sx * cr->a[3][0]) + sy * cr->a[3][1]) + sz * cr->a[3][2];
        double nx, ny;
        if (!(cW > 0.0) || !(cez <= -im->n)) return 1;
        nx = cX / cW;
        ny = cY / cW;
        if (nx < nx0) nx0 = nx;
        if (nx > nx1) nx1 = nx;
        if (ny < ny0) ny0 = ny;
        if (ny > ny1) ny1 = ny;
    }
    /* pixel x has its centre at window x + 0.5: centres in [sx0, sx1] are ceil(sx0 - 0.5) ..
     * floor(sx1 - 0.5); rows count from the top */
    fx0 = ceil((nx0 + 1.0) * 0.5 * (double)im->w - 0.5);
    fx1 = floor((nx1 + 1.0) * 0.5 * (double)im->w - 0.5);
    fy0 = ceil((1.0 - ny1) * 0.5 * (double)im->h - 0.5);
    fy1 = floor((1.0 - ny0) * 0.5 * (double)im->h - 0.5);
    if (!(fx0 >= 0.0)) fx0 = 0.0;
    if (!(fy0 >= 0.0)) fy0 = 0.0;
    if (!(fx1 <= (double)(im->w - 1))) fx1 = (double)(im->w - 1);
    if (!(fy1 <= (double)(im->h - 1))) fy1 = (double)(im->h - 1);
    if (fx0 > fx1 || fy0 > fy1) return 0; /* no pixel centre inside: the centre texel decided */
    x0 = (int)fx0;
    x1 = (int)fx1;
    y0 = (int)fy0;
    y1 = (int)fy1;
    if (im->pyr && (x1 - x0 > 1 || y1 - y0 > 1)) {
        float m = vx_iv_pyr_min(im, x0, x1, y0, y1);
        if (m >= 0.0f && vx_iv_zone(im, b, ez, m) == HFVIS_IV_CLEARED) return 0;
    }
    for (y = y0; y <= y1; y++) {
        const float *row = im->depth + (size_t)y * (size_t)im->w;
        for (x = x0; x <= x1; x++) {
            float zw = row[x];
            if (!vx_iv_texel_ok(zw)) return 1;
            if (vx_iv_zone(im, b, ez, zw) != HFVIS_IV_CLEARED) return 1;
        }
    }
    return 0;
}

/* Pyramid sizes of a w x h image (levels 1.. until 1 x 1); returns the float count, 0 on
 * overflow (never for valid images). */
static size_t vx_iv_pyr_layout(vx_iv_img *im)
{
    size_t total = 0, n;
    int L = 0, w = im->w, h = im->h;
    im->lev_w[0] = w;
    im->lev_h[0] = h;
    im->lev_off[0] = 0;
    while (w > 1 || h > 1) {
        w = (w + 1) / 2;
        h = (h + 1) / 2;
        L++;
        im->lev_w[L] = w;
        im->lev_h[L] = h;
        im->lev_off[L] = total;
        if (!hfvis__mul_size((size_t)w, (size_t)h, &n) || total > SIZE_MAX - n) return 0;
        total += n;
    }
    im->levels = L + 1;
    return total;
}

/* Fill the pyramid (min of each 2 x 2 block; level 0 is the image, no-data -> -1). */
static void vx_iv_pyr_build(vx_iv_img *im, float *store)
{
    int L, x, y;
    im->pyr = store;
    for (L = 1; L < im->levels; L++) {
        int pw = im->lev_w[L - 1], ph = im->lev_h[L - 1], w = im->lev_w[L], h = im->lev_h[L];
        const float *src = L == 1 ? im->depth : store + im->lev_off[L - 1];
        float *dst = store + im->lev_off[L];
        for (y = 0; y < h; y++)
            for (x = 0; x < w; x++) {
                float m = 2.0f;
                int dx, dy;
                for (dy = 0; dy < 2; dy++)
                    for (dx = 0; dx < 2; dx++) {
                        int sx = 2 * x + dx, sy = 2 * y + dy;
                        float v;
                        if (sx >= pw || sy >= ph) continue;
                        v = src[(size_t)sy * (size_t)pw + (size_t)sx];
                        if (L == 1 && !vx_iv_texel_ok(v)) v = -1.0f;
                        if (v < m) m = v;
                    }
                dst[(size_t)y * (size_t)w + (size_t)x] = m;
            }
    }
}

static void vx_iv_sample_set(const vx_iv_img *im, hfvis_iv_sample *out, hfvis_iv_class cls, int px,
                             int py, double ez)
{
    double ze = (double)NAN;
    if (px >= 0) {
        float zw = im->depth[(size_t)py * (size_t)im->w + (size_t)px];
        if (vx_iv_texel_ok(zw)) ze = hfvis_depth_to_eye_z((double)zw, im->n, im->f, im->ortho);
    }
    out->cls = cls;
    out->pixel_x = px;
    out->pixel_y = py;
    out->eye_z = ez;
    out->depth_eye_z = ze;
}

HFVIS_API hfvis_status hfvis_iv_classify(const hfvis_depth_image *image, const double point[3],
                                         double bias, hfvis_iv_sample *out)
{
    vx_iv_img im;
    double ez, X, Y, W;
    int px, py;
    hfvis_iv_class cls;
    if (!out || !point || !hfvis__all_finite(point, 3) || !isfinite(bias) || !(bias >= 0.0))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (vx_iv_image(image, &im) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    ez = vx_iv_row(im.ez, point[0], point[1], point[2]);
    X = vx_iv_row(im.cx, point[0], point[1], point[2]);
    Y = vx_iv_row(im.cy, point[0], point[1], point[2]);
    W = vx_iv_row(im.cw, point[0], point[1], point[2]);
    cls = vx_iv_decide(&im, bias, ez, X, Y, W, &px, &py);
    vx_iv_sample_set(&im, out, cls, px, py, ez);
    return HFVIS_OK;
}

/* Voxel centre coordinate along axis a (the one expression every path uses). */
static double vx_iv_centre(const hfvis_volume_grid *g, int a, int idx)
{
    return g->origin[a] + g->cell[a] * ((double)idx + 0.5);
}

HFVIS_API hfvis_status hfvis_iv_classify_voxel(const hfvis_depth_image *image,
                                               const hfvis_volume_grid *grid, int i, int j, int k,
                                               const hfvis_iv_options *opts,
                                               hfvis_iv_sample *out)
{
    vx_iv_img im;
    vx_iv_opt o;
    double x, y, z, ez, X, Y, W;
    int px, py;
    hfvis_iv_class cls;
    if (!out || !vx_grid_valid(grid) || i < 0 || j < 0 || k < 0 || i >= grid->dims[0]
        || j >= grid->dims[1] || k >= grid->dims[2])
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (vx_iv_resolve(opts, grid, 0, &o) != HFVIS_OK || vx_iv_image(image, &im) != HFVIS_OK)
        return HFVIS_ERR_INVALID_ARGUMENT;
    x = vx_iv_centre(grid, 0, i);
    y = vx_iv_centre(grid, 1, j);
    z = vx_iv_centre(grid, 2, k);
    ez = vx_iv_row(im.ez, x, y, z);
    X = vx_iv_row(im.cx, x, y, z);
    Y = vx_iv_row(im.cy, x, y, z);
    W = vx_iv_row(im.cw, x, y, z);
    cls = vx_iv_decide(&im, o.bias, ez, X, Y, W, &px, &py);
    if (cls == HFVIS_IV_CLEARED && o.conservative) {
        vx_iv_corner_rows cr;
        vx_iv_corner_setup(&im, grid, &cr);
        if (vx_iv_veto(&im, &cr, o.bias, ez, X, Y, W)) cls = HFVIS_IV_KEPT;
    }
    vx_iv_sample_set(&im, out, cls, px, py, ez);
    return HFVIS_OK;
}

/* ---- 9.3 cleanup and single pass --------------------------------------------------------- */

static int vx_iv_empty(const float *v, int channels)
{
    int c;
    for (c = 0; c < channels; c++)
        if (v[c] != 0.0f) return 0;
    return 1;
}

/* First index in [i, n) of a non-empty voxel of the row (C channels per voxel), or n: the first
 * non-zero float from voxel i on, tested in branch-free blocks of 8 floats (a cleanup pass over a
 * surface volume spends most of its time here). */
static int vx_iv_next_nonempty(const float *row, int i, int n, int C)
{
    size_t f = (size_t)i * (size_t)C, end = (size_t)n * (size_t)C;
    while (f + 8 <= end) {
        const float *v = row + f;
        int z = (v[0] == 0.0f) & (v[1] == 0.0f) & (v[2] == 0.0f) & (v[3] == 0.0f)
                & (v[4] == 0.0f) & (v[5] == 0.0f) & (v[6] == 0.0f) & (v[7] == 0.0f);
        if (!z) break;
        f += 8;
    }
    while (f < end && row[f] == 0.0f) f++;
    return (int)(f / (size_t)C);
}

/* Per-call counters. */
typedef struct vx_iv_count {
    size_t cls[4];
    size_t off, on, inj, bg, outside;
} vx_iv_count;

/* One image over the whole volume: src -> dst (src == dst in place). single: turn on the band
 * (§7.4.3), else cleanup only (Alg. 7 Cleanup). map: attribute -> channel for the band. Row by
 * row: the row is copied once (ping-pong), then only voxels that can change are visited (cleanup:
 * the non-empty ones; an empty voxel stays empty). The affine rows are hoisted per slab and row in
 * the order of vx_iv_row, so every voxel sees exactly hfvis_iv_classify_voxel's numbers. */
static void vx_iv_pass(const float *src, float *dst, const hfvis_volume_grid *g, int C,
                       const vx_iv_img *im, const vx_iv_opt *o, int single, const int *map,
                       vx_iv_count *cnt)
{
    const int nx = g->dims[0], ny = g->dims[1], nz = g->dims[2];
    const size_t cs = (size_t)C, row = (size_t)nx * cs;
    vx_iv_corner_rows cr;
    int i, j, k, c;
    size_t lin = 0;
    vx_iv_corner_setup(im, g, &cr);
    for (k = 0; k < nz; k++) {
        double z = vx_iv_centre(g, 2, k);
        double kez = im->ez[3] + im->ez[2] * z, kX = im->cx[3] + im->cx[2] * z;
        double kY = im->cy[3] + im->cy[2] * z, kW = im->cw[3] + im->cw[2] * z;
        for (j = 0; j < ny; j++, lin += (size_t)nx) {
            double y = vx_iv_centre(g, 1, j);
            double jez = kez + im->ez[1] * y, jX = kX + im->cx[1] * y;
            double jY = kY + im->cy[1] * y, jW = kW + im->cw[1] * y;
            const float *srow = src + lin * cs;
            float *drow = dst + lin * cs;
            if (drow != srow) memcpy(drow, srow, row * sizeof(float));
            for (i = 0; i < nx; i++) {
                float *d;
                double x, ez, X, Y, W;
                int px, py, empty;
                hfvis_iv_class cls;
                if (!single) { /* cleanup: an empty voxel stays empty */
                    i = vx_iv_next_nonempty(drow, i, nx, C);
                    if (i >= nx) break;
                }
                d = drow + (size_t)i * cs; /* holds the source values now */
                empty = single ? vx_iv_empty(d, C) : 0;
                x = vx_iv_centre(g, 0, i);
                ez = jez + im->ez[0] * x;
                X = jX + im->cx[0] * x;
                Y = jY + im->cy[0] * x;
                W = jW + im->cw[0] * x;
                cls = vx_iv_decide(im, o->bias, ez, X, Y, W, &px, &py);
                if (cls == HFVIS_IV_CLEARED && o->conservative
                    && vx_iv_veto(im, &cr, o->bias, ez, X, Y, W))
                    cls = HFVIS_IV_KEPT;
                cnt->cls[cls]++;
                if (cls == HFVIS_IV_CLEARED) {
                    if (!empty) {
                        for (c = 0; c < C; c++) d[c] = 0.0f;
                        cnt->off++;
                    }
                } else if (cls == HFVIS_IV_BAND && single) {
                    /* turn on / update with the centre texel's attributes (replace) */
                    int t;
                    if (im->nattr > 0) {
                        const float *a = im->attr + ((size_t)py * (size_t)im->w + (size_t)px)
                                                        * (size_t)im->nattr;
                        for (t = 0; t < im->nattr; t++)
                            if (map[t] >= 0) d[map[t]] = a[t];
                    }
                    if (o->occ >= 0) d[o->occ] = 1.0f;
                    if (empty && !vx_iv_empty(d, C)) cnt->on++;
                }
            }
        }
    }
}

/* Validates the arguments of cleanup / single pass and resolves everything. */
static hfvis_status vx_iv_pass_args(const hfvis_volume *prev, const hfvis_volume *curr,
                                    const hfvis_depth_image *images, size_t count,
                                    const hfvis_iv_options *opts, vx_iv_opt *o, int single)
{
    size_t t;
    /* an image array of count entries must be addressable */
    if (!vx_iv_volume_ok(prev) || !vx_iv_volume_ok(curr) || (count > 0 && !images)
        || count > SIZE_MAX / sizeof(hfvis_depth_image))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (prev->channels != curr->channels || !vx_iv_same_grid(&prev->grid, &curr->grid))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (vx_iv_resolve(opts, &prev->grid, prev->channels, o) != HFVIS_OK)
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (t = 0; t < count; t++) {
        vx_iv_img im;
        int map[HFVIS_VOLUME_MAX_CHANNELS];
        if (vx_iv_image(&images[t], &im) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
        if (single && vx_iv_channel_map(o, im.nattr, prev->channels, map) != HFVIS_OK)
            return HFVIS_ERR_INVALID_ARGUMENT;
    }
    return HFVIS_OK;
}

static void vx_iv_stats_out(const vx_iv_count *c, hfvis_iv_stats *stats)
{
    if (!stats) return;
    memset(stats, 0, sizeof *stats);
    stats->unseen = c->cls[HFVIS_IV_UNSEEN];
    stats->cleared = c->cls[HFVIS_IV_CLEARED];
    stats->band = c->cls[HFVIS_IV_BAND];
    stats->kept = c->cls[HFVIS_IV_KEPT];
    stats->turned_off = c->off;
    stats->turned_on = c->on;
    stats->points_injected = c->inj;
    stats->points_background = c->bg;
    stats->points_outside = c->outside;
}

/* Cleanup or single pass after validation: the pyramids (one block for all images), then the
 * images in order, the first reading prev and the others curr in place. */
static hfvis_status vx_iv_run(const hfvis_volume *prev, hfvis_volume *curr,
                              const hfvis_depth_image *images, size_t count, const vx_iv_opt *o,
                              int single, vx_iv_count *cnt)
{
    float *pyr = NULL;
    size_t t, total = 0, n = hfvis_volume_floats(&prev->grid, prev->channels);
    if (o->conservative && count > 0) {
        for (t = 0; t < count; t++) {
            vx_iv_img im;
            size_t s;
            (void)vx_iv_image(&images[t], &im);
            s = vx_iv_pyr_layout(&im);
            if (s == 0 && (im.w > 1 || im.h > 1)) return HFVIS_ERR_INVALID_ARGUMENT;
            if (total > SIZE_MAX - s) return HFVIS_ERR_INVALID_ARGUMENT;
            total += s;
        }
        if (total > 0) {
            pyr = (float *)hfvis__alloc_array(o->alloc, total, sizeof(float));
            if (!pyr) return HFVIS_ERR_OUT_OF_MEMORY;
        }
    }
    if (count == 0 && curr->data != prev->data)
        for (t = 0; t < n; t++) curr->data[t] = prev->data[t];
    total = 0;
    for (t = 0; t < count; t++) {
        vx_iv_img im;
        int map[HFVIS_VOLUME_MAX_CHANNELS] = {0};
        (void)vx_iv_image(&images[t], &im);
        if (single) (void)vx_iv_channel_map(o, im.nattr, prev->channels, map);
        if (pyr) {
            size_t s = vx_iv_pyr_layout(&im);
            vx_iv_pyr_build(&im, pyr + total);
            total += s;
        }
        vx_iv_pass(t == 0 ? prev->data : curr->data, curr->data, &prev->grid, prev->channels, &im,
                   o, single, map, cnt);
    }
    hfvis__free(o->alloc, pyr);
    return HFVIS_OK;
}

/* hfvis_iv_cleanup (single = 0) and hfvis_iv_single_pass (single = 1). */
static hfvis_status vx_iv_entry(const hfvis_volume *prev, hfvis_volume *curr,
                                const hfvis_depth_image *images, size_t image_count,
                                const hfvis_iv_options *opts, hfvis_iv_stats *stats, int single)
{
    vx_iv_opt o;
    vx_iv_count cnt;
    hfvis_status s = vx_iv_pass_args(prev, curr, images, image_count, opts, &o, single);
    if (s != HFVIS_OK) return s;
    memset(&cnt, 0, sizeof cnt);
    s = vx_iv_run(prev, curr, images, image_count, &o, single, &cnt);
    if (s != HFVIS_OK) return s;
    vx_iv_stats_out(&cnt, stats);
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_iv_cleanup(const hfvis_volume *prev, hfvis_volume *curr,
                                        const hfvis_depth_image *images, size_t image_count,
                                        const hfvis_iv_options *opts, hfvis_iv_stats *stats)
{
    return vx_iv_entry(prev, curr, images, image_count, opts, stats, 0);
}

HFVIS_API hfvis_status hfvis_iv_single_pass(const hfvis_volume *prev, hfvis_volume *curr,
                                            const hfvis_depth_image *images, size_t image_count,
                                            const hfvis_iv_options *opts, hfvis_iv_stats *stats)
{
    return vx_iv_entry(prev, curr, images, image_count, opts, stats, 1);
}

/* ---- 9.4 injection, one frame, lighting ---------------------------------------------------- */

/* Validate the injection arguments (everything that can fail). */
static hfvis_status vx_iv_inject_args(const hfvis_volume *vol, const hfvis_depth_image *images,
                                      size_t count, const vx_iv_opt *o)
{
    size_t t;
    int c, map[HFVIS_VOLUME_MAX_CHANNELS];
    if (!vx_iv_volume_ok(vol) || (count > 0 && !images)
        || count > SIZE_MAX / sizeof(hfvis_depth_image))
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (c = 0; c < vol->channels; c++)
        if (!vx_blend_valid(vol->blend[c])) return HFVIS_ERR_INVALID_ARGUMENT;
    for (t = 0; t < count; t++) {
        vx_iv_img im;
        double m[16], inv[16];
        if (vx_iv_image(&images[t], &im) != HFVIS_OK
            || vx_iv_channel_map(o, im.nattr, vol->channels, map) != HFVIS_OK)
            return HFVIS_ERR_INVALID_ARGUMENT;
        hfvis_mat4_multiply(images[t].view.proj, images[t].view.view, m);
        if (hfvis_mat4_invert(m, inv) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    }
    return HFVIS_OK;
}

/* Listing 7.2 for validated arguments. */
static void vx_iv_inject_run(hfvis_volume *vol, const hfvis_depth_image *images, size_t count,
                             const vx_iv_opt *o, vx_iv_count *cnt)
{
    const hfvis_volume_grid *g = &vol->grid;
    const size_t cs = (size_t)vol->channels;
    size_t t;
    for (t = 0; t < count; t++) {
        vx_iv_img im;
        double m[16], inv[16];
        int map[HFVIS_VOLUME_MAX_CHANNELS], gx, gy, gw, gh;
        (void)vx_iv_image(&images[t], &im);
        (void)vx_iv_channel_map(o, im.nattr, vol->channels, map);
        hfvis_mat4_multiply(images[t].view.proj, images[t].view.view, m);
        (void)hfvis_mat4_invert(m, inv);
        gw = o->gw > 0 ? o->gw : im.w;
        gh = o->gh > 0 ? o->gh : im.h;
        for (gy = 0; gy < gh; gy++) {
            double v = ((double)gy + 0.5) / (double)gh;
            int py = (int)(v * (double)im.h);
            if (py > im.h - 1) py = im.h - 1;
            for (gx = 0; gx < gw; gx++) {
                double u = ((double)gx + 0.5) / (double)gw, ndc[4], hp[4], p[3];
                int px = (int)(u * (double)im.w), idx[3], a, ok = 1;
                size_t pix;
                float zw, *d;
                if (px > im.w - 1) px = im.w - 1;
                pix = (size_t)py * (size_t)im.w + (size_t)px;
                zw = im.depth[pix];
                if (!(zw >= 0.0f && zw < 1.0f)) { /* background or no-data: no sample */
                    cnt->bg++;
                    continue;
                }
                /* canonical screen space -> world (PointCSS2WCS: inverse view-projection) */
                ndc[0] = 2.0 * u - 1.0;
                ndc[1] = 1.0 - 2.0 * v;
                ndc[2] = 2.0 * (double)zw - 1.0;
                ndc[3] = 1.0;
                vx_mat4_apply(inv, ndc, hp);
                if (!(hp[3] != 0.0)) {
                    cnt->outside++;
                    continue;
                }
                for (a = 0; a < 3; a++) {
                    double q;
                    p[a] = hp[a] / hp[3];
                    q = (p[a] - g->origin[a]) / g->cell[a];
                    if (!(q >= 0.0 && q < (double)g->dims[a])) {
                        ok = 0;
                        break;
                    }
                    idx[a] = (int)q;
                    if (idx[a] > g->dims[a] - 1) idx[a] = g->dims[a] - 1;
                }
                if (!ok) {
                    cnt->outside++;
                    continue;
                }
                d = vol->data + (((size_t)idx[2] * (size_t)g->dims[1] + (size_t)idx[1])
                                     * (size_t)g->dims[0]
                                 + (size_t)idx[0])
                                    * cs;
                if (im.nattr > 0) {
                    const float *at = im.attr + pix * (size_t)im.nattr;
                    for (a = 0; a < im.nattr; a++)
                        if (map[a] >= 0) d[map[a]] = vx_blend_apply(vol->blend[map[a]], d[map[a]], at[a]);
                }
                if (o->occ >= 0) d[o->occ] = vx_blend_apply(vol->blend[o->occ], d[o->occ], 1.0f);
                cnt->inj++;
            }
        }
    }
}

HFVIS_API hfvis_status hfvis_iv_inject(hfvis_volume *vol, const hfvis_depth_image *images,
                                       size_t image_count, const hfvis_iv_options *opts,
                                       hfvis_iv_stats *stats)
{
    vx_iv_opt o;
    vx_iv_count cnt;
    if (!vx_iv_volume_ok(vol) || vx_iv_resolve(opts, &vol->grid, vol->channels, &o) != HFVIS_OK
        || vx_iv_inject_args(vol, images, image_count, &o) != HFVIS_OK)
        return HFVIS_ERR_INVALID_ARGUMENT;
    memset(&cnt, 0, sizeof cnt);
    vx_iv_inject_run(vol, images, image_count, &o, &cnt);
    vx_iv_stats_out(&cnt, stats);
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_iv_update(const hfvis_volume *prev, hfvis_volume *curr,
                                       const hfvis_depth_image *images, size_t image_count,
                                       const hfvis_iv_options *opts, hfvis_iv_stats *stats)
{
    vx_iv_opt o;
    vx_iv_count cnt;
    hfvis_status s = vx_iv_pass_args(prev, curr, images, image_count, opts, &o, 0);
    if (s != HFVIS_OK) return s;
    if (vx_iv_inject_args(curr, images, image_count, &o) != HFVIS_OK)
        return HFVIS_ERR_INVALID_ARGUMENT;
    memset(&cnt, 0, sizeof cnt);
    s = vx_iv_run(prev, curr, images, image_count, &o, 0, &cnt); /* all cleanups (Alg. 7) */
    if (s != HFVIS_OK) return s;
    vx_iv_inject_run(curr, images, image_count, &o, &cnt);       /* then all injections */
    vx_iv_stats_out(&cnt, stats);
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_iv_replace_nonempty(hfvis_volume *curr,
                                                 const hfvis_volume *injection,
                                                 const int *channels, int channel_count,
                                                 const hfvis_iv_options *opts, size_t *replaced)
{
    int list[HFVIS_VOLUME_MAX_CHANNELS], n, a, b, occ, C;
    size_t v, nv, count = 0;
    if (!vx_iv_volume_ok(curr) || !vx_iv_volume_ok(injection)
        || curr->channels != injection->channels || !vx_iv_same_grid(&curr->grid, &injection->grid))
        return HFVIS_ERR_INVALID_ARGUMENT;
    C = curr->channels;
    occ = opts ? opts->occupancy_channel : 0;
    if (occ < HFVIS_IV_NO_CHANNEL || occ >= C) return HFVIS_ERR_INVALID_ARGUMENT;
    if (channels) {
        if (channel_count < 1 || channel_count > C) return HFVIS_ERR_INVALID_ARGUMENT;
        for (a = 0; a < channel_count; a++) {
            if (channels[a] < 0 || channels[a] >= C) return HFVIS_ERR_INVALID_ARGUMENT;
            for (b = 0; b < a; b++)
                if (channels[b] == channels[a]) return HFVIS_ERR_INVALID_ARGUMENT;
            list[a] = channels[a];
        }
        n = channel_count;
    } else {
        for (a = 0; a < C; a++) list[a] = a;
        n = C;
    }
    nv = vx_grid_voxels(&curr->grid);
    for (v = 0; v < nv; v++) {
        const float *s = injection->data + v * (size_t)C;
        float *d = curr->data + v * (size_t)C;
        if (occ >= 0 ? s[occ] == 0.0f : vx_iv_empty(s, C)) continue;
        for (a = 0; a < n; a++) d[list[a]] = s[list[a]];
        count++;
    }
    if (replaced) *replaced = count;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_iv_occupancy(const hfvis_volume *vol, int channel, uint8_t *out,
                                          size_t *count)
{
    size_t v, nv, n = 0;
    if (!vx_iv_volume_ok(vol) || !out || channel < HFVIS_IV_NO_CHANNEL || channel >= vol->channels)
        return HFVIS_ERR_INVALID_ARGUMENT;
    nv = vx_grid_voxels(&vol->grid);
    for (v = 0; v < nv; v++) {
        const float *s = vol->data + v * (size_t)vol->channels;
        int on = channel >= 0 ? s[channel] != 0.0f : !vx_iv_empty(s, vol->channels);
        out[v] = (uint8_t)(on ? 1 : 0);
        n += (size_t)on;
    }
    if (count) *count = n;
    return HFVIS_OK;
}

/* ---- 9.5 Table 9 distance metric --------------------------------------------------------- */

/* Squared distance from p to triangle (a, b, c): the closest point by Voronoi regions
 * (Ericson, Real-Time Collision Detection §5.1.5), in double. A degenerate triangle (zero
 * cross product) is the union of its edges. */
static double vx_iv_seg_d2(const double p[3], const double a[3], const double b[3])
{
    double ab[3], ap[3], t, l2, q, d2 = 0.0;
    int i;
    for (i = 0; i < 3; i++) ab[i] = b[i] - a[i], ap[i] = p[i] - a[i];
    l2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
    t = l2 > 0.0 ? (ab[0] * ap[0] + ab[1] * ap[1] + ab[2] * ap[2]) / l2 : 0.0;
    if (!(t > 0.0)) t = 0.0;
    if (t > 1.0) t = 1.0;
    for (i = 0; i < 3; i++) {
        q = p[i] - (a[i] + t * ab[i]);
        d2 += q * q;
    }
    return d2;
}

static double vx_iv_tri_d2(const double p[3], const double a[3], const double b[3],
                           const double c[3])
{
    double ab[3], ac[3], ap[3], bp[3], cp[3], q[3], n[3];
    double d1, d2, d3, d4, d5, d6, va, vb, vc, v, w, den, r = 0.0;
    int i;
    for (i = 0; i < 3; i++) {
        ab[i] = b[i] - a[i];
        ac[i] = c[i] - a[i];
        ap[i] = p[i] - a[i];
        bp[i] = p[i] - b[i];
        cp[i] = p[i] - c[i];
    }
    n[0] = ab[1] * ac[2] - ab[2] * ac[1];
    n[1] = ab[2] * ac[0] - ab[0] * ac[2];
    n[2] = ab[0] * ac[1] - ab[1] * ac[0];
    if (n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0) {
        double s0 = vx_iv_seg_d2(p, a, b), s1 = vx_iv_seg_d2(p, b, c), s2 = vx_iv_seg_d2(p, c, a);
        if (s1 < s0) s0 = s1;
        return s2 < s0 ? s2 : s0;
    }
    d1 = ab[0] * ap[0] + ab[1] * ap[1] + ab[2] * ap[2];
    d2 = ac[0] * ap[0] + ac[1] * ap[1] + ac[2] * ap[2];
    d3 = ab[0] * bp[0] + ab[1] * bp[1] + ab[2] * bp[2];
    d4 = ac[0] * bp[0] + ac[1] * bp[1] + ac[2] * bp[2];
    d5 = ab[0] * cp[0] + ab[1] * cp[1] + ab[2] * cp[2];
    d6 = ac[0] * cp[0] + ac[1] * cp[1] + ac[2] * cp[2];
    vc = d1 * d4 - d3 * d2;
    vb = d5 * d2 - d1 * d6;
    va = d3 * d6 - d5 * d4;
    if (d1 <= 0.0 && d2 <= 0.0) { /* vertex region a */
        for (i = 0; i < 3; i++) q[i] = a[i];
    } else if (d3 >= 0.0 && d4 <= d3) { /* vertex region b */
        for (i = 0; i < 3; i++) q[i] = b[i];
    } else if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) { /* edge ab */
        v = d1 / (d1 - d3);
        for (i = 0; i < 3; i++) q[i] = a[i] + v * ab[i];
    } else if (d6 >= 0.0 && d5 <= d6) { /* vertex region c */
        for (i = 0; i < 3; i++) q[i] = c[i];
    } else if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) { /* edge ac */
        w = d2 / (d2 - d6);
        for (i = 0; i < 3; i++) q[i] = a[i] + w * ac[i];
    } else if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) { /* edge bc */
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        for (i = 0; i < 3; i++) q[i] = b[i] + w * (c[i] - b[i]);
    } else { /* face: barycentric (1 - v - w, v, w) */
        den = va + vb + vc;
        if (!(den > 0.0)) { /* rounding on a sliver: fall back to the edges */
            double s0 = vx_iv_seg_d2(p, a, b), s1 = vx_iv_seg_d2(p, b, c), s2 = vx_iv_seg_d2(p, c, a);
            if (s1 < s0) s0 = s1;
            return s2 < s0 ? s2 : s0;
        }
        v = vb / den;
        w = vc / den;
        for (i = 0; i < 3; i++) q[i] = a[i] + ab[i] * v + ac[i] * w;
    }
    for (i = 0; i < 3; i++) r += (p[i] - q[i]) * (p[i] - q[i]);
    return r;
}

HFVIS_API double hfvis_point_triangle_distance(const double p[3], const double a[3],
                                               const double b[3], const double c[3])
{
    if (!p || !a || !b || !c) return (double)NAN;
    return sqrt(vx_iv_tri_d2(p, a, b, c));
}

/* Shared set-up of the metric: the positive-area triangles, their area prefix sums, the voxel
 * centres, the bounding-box diagonal and a coordinate scale for the pruning margin. */
typedef struct vx_iv_metric {
    const hfvis_mesh *mesh;
    uint32_t *tris;  /* ids of positive-area triangles */
    double *cdf;     /* inclusive prefix sums of their areas */
    size_t nt;
    double *pts;     /* voxel centres, 3 per point */
    size_t np;
    double diag, scale2;
    size_t samples;
    uint64_t seed;
    const hfvis_allocator *alloc;
} vx_iv_metric;

static void vx_iv_tri_vertices(const hfvis_mesh *m, size_t t, double v[3][3])
{
    int c, a;
    for (c = 0; c < 3; c++) {
        const float *p = m->xyz + 3 * (size_t)m->indices[3 * t + (size_t)c];
        for (a = 0; a < 3; a++) v[c][a] = (double)p[a];
    }
}

static void vx_iv_metric_free(vx_iv_metric *M)
{
    hfvis__free(M->alloc, M->pts);
    hfvis__free(M->alloc, M->cdf);
    hfvis__free(M->alloc, M->tris);
    M->pts = NULL;
    M->cdf = NULL;
    M->tris = NULL;
}

/* Area-uniform samples of the mesh for d(X, Y) when the options give 0 (hfvis_distance_options). */
#define VX_IV_DEFAULT_METRIC_SAMPLES 100000

/* Validates and builds the set-up (3 blocks: triangle ids, prefix sums, centres). */
static hfvis_status vx_iv_metric_init(vx_iv_metric *M, const hfvis_mesh *mesh,
                                      const hfvis_volume_grid *grid, const uint8_t *occ,
                                      const hfvis_distance_options *opts)
{
    size_t t, nv, v, nt = 0, np = 0;
    double lo[3], hi[3], sum = 0.0, s = 0.0, e[3];
    int a;
    memset(M, 0, sizeof *M);
    if (!occ || !vx_grid_valid(grid) || hfvis__mesh_check(mesh) != HFVIS_OK)
        return HFVIS_ERR_INVALID_ARGUMENT;
    M->mesh = mesh;
    M->samples = opts && opts->sample_count ? opts->sample_count : VX_IV_DEFAULT_METRIC_SAMPLES;
    M->seed = opts ? opts->seed : 0u;
    M->alloc = opts ? opts->alloc : NULL;
    if (mesh->triangle_count > (size_t)UINT32_MAX / 2) return HFVIS_ERR_LIMIT;
    for (a = 0; a < 3; a++) lo[a] = HUGE_VAL, hi[a] = -HUGE_VAL;
    for (t = 0; t < mesh->triangle_count; t++) {
        double p[3][3], u[3], w[3], n[3];
        int c;
        vx_iv_tri_vertices(mesh, t, p);
        for (c = 0; c < 3; c++)
            for (a = 0; a < 3; a++) {
                if (p[c][a] < lo[a]) lo[a] = p[c][a];
                if (p[c][a] > hi[a]) hi[a] = p[c][a];
            }
        for (a = 0; a < 3; a++) u[a] = p[1][a] - p[0][a], w[a] = p[2][a] - p[0][a];
        n[0] = u[1] * w[2] - u[2] * w[1];
        n[1] = u[2] * w[0] - u[0] * w[2];
        n[2] = u[0] * w[1] - u[1] * w[0];
        if (n[0] != 0.0 || n[1] != 0.0 || n[2] != 0.0) nt++;
    }
    nv = vx_grid_voxels(grid);
    for (v = 0; v < nv; v++) np += occ[v] != 0;
    if (nt == 0 || np == 0) return HFVIS_ERR_INVALID_ARGUMENT;
    if (np > (size_t)UINT32_MAX / 2 || np > SIZE_MAX / 6 || nt > SIZE_MAX / 6) return HFVIS_ERR_LIMIT;
    for (a = 0; a < 3; a++) {
        double m1 = fabs(lo[a]) > fabs(hi[a]) ? fabs(lo[a]) : fabs(hi[a]);
        double g0 = fabs(grid->origin[a]), g1 = fabs(grid->origin[a] + grid->cell[a] * (double)grid->dims[a]);
        if (g0 > m1) m1 = g0;
        if (g1 > m1) m1 = g1;
        s += m1 * m1;
        e[a] = hi[a] - lo[a];
    }
    M->diag = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
    M->scale2 = s;
    M->tris = (uint32_t *)hfvis__alloc_array(M->alloc, nt, sizeof(uint32_t));
    if (!M->tris) return HFVIS_ERR_OUT_OF_MEMORY;
    M->cdf = (double *)hfvis__alloc_array(M->alloc, nt, sizeof(double));
    M->pts = (double *)hfvis__alloc_array(M->alloc, 3 * np, sizeof(double));
    if (!M->cdf || !M->pts) {
        vx_iv_metric_free(M);
        return HFVIS_ERR_OUT_OF_MEMORY;
    }
    M->nt = 0;
    for (t = 0; t < mesh->triangle_count; t++) {
        double p[3][3], u[3], w[3], n[3], area;
        vx_iv_tri_vertices(mesh, t, p);
        for (a = 0; a < 3; a++) u[a] = p[1][a] - p[0][a], w[a] = p[2][a] - p[0][a];
        n[0] = u[1] * w[2] - u[2] * w[1];
        n[1] = u[2] * w[0] - u[0] * w[2];
        n[2] = u[0] * w[1] - u[1] * w[0];
        if (n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0) continue;
        area = 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        sum += area;
        M->tris[M->nt] = (uint32_t)t;
        M->cdf[M->nt] = sum;
        M->nt++;
    }
    if (!(sum > 0.0) || !isfinite(sum)) {
        vx_iv_metric_free(M);
        return HFVIS_ERR_INVALID_ARGUMENT;
    }
    M->np = 0;
    {
        int i, j, k;
        size_t lin = 0;
        for (k = 0; k < grid->dims[2]; k++)
            for (j = 0; j < grid->dims[1]; j++)
                for (i = 0; i < grid->dims[0]; i++, lin++) {
                    if (!occ[lin]) continue;
                    M->pts[3 * M->np + 0] = vx_iv_centre(grid, 0, i);
                    M->pts[3 * M->np + 1] = vx_iv_centre(grid, 1, j);
                    M->pts[3 * M->np + 2] = vx_iv_centre(grid, 2, k);
                    M->np++;
                }
    }
    return HFVIS_OK;
}

/* Sample s of the mesh (the same sequence for the fast path and the oracle). */
static void vx_iv_metric_sample(const vx_iv_metric *M, hfvis__pcg32 *r, double out[3])
{
    double u = hfvis__pcg32_unit(r) * M->cdf[M->nt - 1], r2 = hfvis__pcg32_unit(r), r3 = hfvis__pcg32_unit(r);
    double v[3][3], su = sqrt(r2), w0 = 1.0 - su, w1 = su * (1.0 - r3), w2 = su * r3;
    size_t lo = 0, hi = M->nt - 1;
    int a;
    while (lo < hi) { /* first prefix sum > u */
        size_t mid = lo + (hi - lo) / 2;
        if (M->cdf[mid] > u) hi = mid;
        else lo = mid + 1;
    }
    vx_iv_tri_vertices(M->mesh, (size_t)M->tris[lo], v);
    for (a = 0; a < 3; a++) out[a] = (w0 * v[0][a] + w1 * v[1][a]) + w2 * v[2][a];
}

static double vx_iv_pt_d2(const double p[3], const double q[3])
{
    double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
    return (dx * dx + dy * dy) + dz * dz;
}

/* A bounding-volume hierarchy over items with boxes (median split of the centroids along the
 * longest axis, up to 4 items per leaf). Inner node: count 0, children first and first + 1. */
typedef struct vx_iv_node {
    double lo[3], hi[3];
    uint32_t first, count;
} vx_iv_node;

typedef struct vx_iv_bvh {
    vx_iv_node *nodes;
    uint32_t *items;
    void *block;
} vx_iv_bvh;

/* Reorders items[first..first+count) so that position first+mid holds the element of rank mid by
 * key (lo + hi on axis a), smaller before, larger after (Hoare quickselect, median of three). */
static void vx_iv_select(uint32_t *it, size_t first, size_t count, size_t mid, const double *lo,
                         const double *hi, int a)
{
    size_t l = first, r = first + count - 1, want = first + mid;
    while (r > l) {
        size_t i = l, j = r, m = l + (r - l) / 2;
        double k0 = lo[3 * (size_t)it[l] + (size_t)a] + hi[3 * (size_t)it[l] + (size_t)a];
        double k1 = lo[3 * (size_t)it[m] + (size_t)a] + hi[3 * (size_t)it[m] + (size_t)a];
        double k2 = lo[3 * (size_t)it[r] + (size_t)a] + hi[3 * (size_t)it[r] + (size_t)a];
        double piv = k0 < k1 ? (k1 < k2 ? k1 : (k0 < k2 ? k2 : k0)) : (k0 < k2 ? k0 : (k1 < k2 ? k2 : k1));
        for (;;) {
            uint32_t tmp;
            while (lo[3 * (size_t)it[i] + (size_t)a] + hi[3 * (size_t)it[i] + (size_t)a] < piv) i++;
            while (lo[3 * (size_t)it[j] + (size_t)a] + hi[3 * (size_t)it[j] + (size_t)a] > piv) j--;
            if (i >= j) break;
            tmp = it[i];
            it[i] = it[j];
            it[j] = tmp;
            i++;
            j--;
        }
        /* now [l, j] <= piv <= [j+1, r] */
        if (want <= j) r = j;
        else l = j + 1;
    }
}

/* Builds over n >= 1 items with boxes lo/hi (3 doubles each). One block. */
static hfvis_status vx_iv_bvh_build(vx_iv_bvh *b, size_t n, const double *lo, const double *hi,
                                    const hfvis_allocator *alloc)
{
    size_t nn = 2 * n, bytes_nodes, bytes_items, used = 1, sp = 0, i;
    uint32_t stack[VX_IV_STACK];
    memset(b, 0, sizeof *b);
    if (n > (size_t)UINT32_MAX / 2) return HFVIS_ERR_LIMIT;
    if (!hfvis__mul_size(nn, sizeof(vx_iv_node), &bytes_nodes)
        || !hfvis__mul_size(n, sizeof(uint32_t), &bytes_items) || bytes_nodes > SIZE_MAX - bytes_items)
        return HFVIS_ERR_LIMIT;
    b->block = hfvis__alloc(alloc, bytes_nodes + bytes_items);
    if (!b->block) return HFVIS_ERR_OUT_OF_MEMORY;
    b->nodes = (vx_iv_node *)b->block;
    b->items = (uint32_t *)(void *)((unsigned char *)b->block + bytes_nodes);
    for (i = 0; i < n; i++) b->items[i] = (uint32_t)i;
    b->nodes[0].first = 0;
    b->nodes[0].count = (uint32_t)n;
    stack[sp++] = 0;
    while (sp > 0) {
        vx_iv_node *nd = &b->nodes[stack[--sp]];
        size_t first = nd->first, count = nd->count, mid;
        double clo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, chi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
        int a, axis = 0;
        for (a = 0; a < 3; a++) nd->lo[a] = HUGE_VAL, nd->hi[a] = -HUGE_VAL;
        for (i = first; i < first + count; i++) {
            size_t it = (size_t)b->items[i];
            for (a = 0; a < 3; a++) {
                double c = lo[3 * it + (size_t)a] + hi[3 * it + (size_t)a];
                if (lo[3 * it + (size_t)a] < nd->lo[a]) nd->lo[a] = lo[3 * it + (size_t)a];
                if (hi[3 * it + (size_t)a] > nd->hi[a]) nd->hi[a] = hi[3 * it + (size_t)a];
                if (c < clo[a]) clo[a] = c;
                if (c > chi[a]) chi[a] = c;
            }
        }
        if (count <= 4) continue; /* leaf */
        for (a = 1; a < 3; a++)
            if (chi[a] - clo[a] > chi[axis] - clo[axis]) axis = a;
        mid = count / 2;
        vx_iv_select(b->items, first, count, mid, lo, hi, axis);
        HFVIS_ASSERT(used + 2 <= nn && sp + 2 <= VX_IV_STACK);
        nd->first = (uint32_t)used;
        nd->count = 0;
        b->nodes[used].first = (uint32_t)first;
        b->nodes[used].count = (uint32_t)mid;
        b->nodes[used + 1].first = (uint32_t)(first + mid);
        b->nodes[used + 1].count = (uint32_t)(count - mid);
        stack[sp++] = (uint32_t)used;
        stack[sp++] = (uint32_t)(used + 1);
        used += 2;
    }
    return HFVIS_OK;
}

static double vx_iv_box_d2(const vx_iv_node *nd, const double p[3])
{
    double d2 = 0.0;
    int a;
    for (a = 0; a < 3; a++) {
        double g = 0.0;
        if (p[a] < nd->lo[a]) g = nd->lo[a] - p[a];
        else if (p[a] > nd->hi[a]) g = p[a] - nd->hi[a];
        d2 += g * g;
    }
    return d2;
}

/* Smallest squared distance from p to an item (tri: triangles of M, else voxel centres). A node
 * is skipped only when its box is farther than the best so far plus a margin far above the
 * rounding of the distances (1e-9 of best + coordinate scale^2), so the minimum is exactly the
 * brute-force minimum of the same per-item values. */
static double vx_iv_bvh_nearest(const vx_iv_bvh *b, const vx_iv_metric *M, int tri,
                                const double p[3])
{
    uint32_t stack[VX_IV_STACK];
    size_t sp = 0;
    double best = HUGE_VAL;
    stack[sp++] = 0;
    while (sp > 0) {
        const vx_iv_node *nd = &b->nodes[stack[--sp]];
        if (vx_iv_box_d2(nd, p) > best + 1e-9 * (best + M->scale2)) continue;
        if (nd->count > 0) {
            uint32_t i;
            for (i = nd->first; i < nd->first + nd->count; i++) {
                size_t it = (size_t)b->items[i];
                double d2;
                if (tri) {
                    double v[3][3];
                    vx_iv_tri_vertices(M->mesh, (size_t)M->tris[it], v);
                    d2 = vx_iv_tri_d2(p, v[0], v[1], v[2]);
                } else {
                    d2 = vx_iv_pt_d2(p, M->pts + 3 * it);
                }
                if (d2 < best) best = d2;
            }
        } else {
            double d0 = vx_iv_box_d2(&b->nodes[nd->first], p);
            double d1 = vx_iv_box_d2(&b->nodes[nd->first + 1], p);
            HFVIS_ASSERT(sp + 2 <= VX_IV_STACK);
            if (d0 <= d1) { /* nearer child popped first */
                stack[sp++] = nd->first + 1;
                stack[sp++] = nd->first;
            } else {
                stack[sp++] = nd->first;
                stack[sp++] = nd->first + 1;
            }
        }
    }
    return best;
}

static void vx_iv_metric_out(const vx_iv_metric *M, double sum_p, double max_p, double sum_s,
                             double max_s, hfvis_distance_metrics *out)
{
    hfvis_distance_metrics r;
    double mp = sum_p / (double)M->np, ms = sum_s / (double)M->samples;
    memset(&r, 0, sizeof r);
    r.mean_voxel_to_mesh = mp;
    r.max_voxel_to_mesh = max_p;
    r.mean_mesh_to_voxel = ms;
    r.max_mesh_to_voxel = max_s;
    r.hausdorff = max_p > max_s ? max_p : max_s;
    r.diagonal = M->diag;
    r.table9_percent = M->diag > 0.0 ? 100.0 * (mp > ms ? mp : ms) / M->diag : (double)NAN;
    r.voxel_count = M->np;
    r.sample_count = M->samples;
    *out = r;
}

HFVIS_API hfvis_distance_options hfvis_distance_options_default(void)
{
    hfvis_distance_options o;
    memset(&o, 0, sizeof o);
    o.sample_count = VX_IV_DEFAULT_METRIC_SAMPLES;
    o.seed = 0;
    o.alloc = NULL;
    return o;
}

HFVIS_API hfvis_status hfvis_voxel_distance_metrics(const hfvis_mesh *mesh,
                                                    const hfvis_volume_grid *grid,
                                                    const uint8_t *occupancy,
                                                    const hfvis_distance_options *opts,
                                                    hfvis_distance_metrics *out)
{
    vx_iv_metric M;
    vx_iv_bvh tb, pb;
    hfvis__pcg32 rng;
    double *box = NULL, sum_p = 0.0, max_p = 0.0, sum_s = 0.0, max_s = 0.0;
    size_t t, s;
    hfvis_status st;
    if (!out) return HFVIS_ERR_INVALID_ARGUMENT;
    st = vx_iv_metric_init(&M, mesh, grid, occupancy, opts);
    if (st != HFVIS_OK) return st;
    /* triangle boxes (lo: first 3 nt doubles, hi: next 3 nt) */
    box = (double *)hfvis__alloc_array(M.alloc, 6 * M.nt, sizeof(double));
    if (!box) {
        vx_iv_metric_free(&M);
        return HFVIS_ERR_OUT_OF_MEMORY;
    }
    for (t = 0; t < M.nt; t++) {
        double v[3][3];
        int a, c;
        vx_iv_tri_vertices(mesh, (size_t)M.tris[t], v);
        for (a = 0; a < 3; a++) {
            double l = v[0][a], h = v[0][a];
            for (c = 1; c < 3; c++) {
                if (v[c][a] < l) l = v[c][a];
                if (v[c][a] > h) h = v[c][a];
            }
            box[3 * t + (size_t)a] = l;
            box[3 * M.nt + 3 * t + (size_t)a] = h;
        }
    }
    st = vx_iv_bvh_build(&tb, M.nt, box, box + 3 * M.nt, M.alloc);
    if (st != HFVIS_OK) {
        hfvis__free(M.alloc, box);
        vx_iv_metric_free(&M);
        return st;
    }
    st = vx_iv_bvh_build(&pb, M.np, M.pts, M.pts, M.alloc);
    if (st != HFVIS_OK) {
        hfvis__free(M.alloc, tb.block);
        hfvis__free(M.alloc, box);
        vx_iv_metric_free(&M);
        return st;
    }
    /* Y -> X: every voxel centre to the mesh, exactly */
    for (s = 0; s < M.np; s++) {
        double d = sqrt(vx_iv_bvh_nearest(&tb, &M, 1, M.pts + 3 * s));
        sum_p += d;
        if (d > max_p) max_p = d;
    }
    /* X -> Y: area-uniform samples of the mesh to the nearest voxel centre */
    hfvis__pcg32_seed(&rng, (M.seed) ^ 0x853c49e6748fea9bull, 0xda3e39cb94b95bdbull);
    for (s = 0; s < M.samples; s++) {
        double q[3], d;
        vx_iv_metric_sample(&M, &rng, q);
        d = sqrt(vx_iv_bvh_nearest(&pb, &M, 0, q));
        sum_s += d;
        if (d > max_s) max_s = d;
    }
    vx_iv_metric_out(&M, sum_p, max_p, sum_s, max_s, out);
    hfvis__free(M.alloc, pb.block);
    hfvis__free(M.alloc, tb.block);
    hfvis__free(M.alloc, box);
    vx_iv_metric_free(&M);
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_voxel_distance_metrics_naive(const hfvis_mesh *mesh,
                                                          const hfvis_volume_grid *grid,
                                                          const uint8_t *occupancy,
                                                          const hfvis_distance_options *opts,
                                                          hfvis_distance_metrics *out)
{
    vx_iv_metric M;
    hfvis__pcg32 rng;
    double sum_p = 0.0, max_p = 0.0, sum_s = 0.0, max_s = 0.0;
    size_t t, s;
    hfvis_status st;
    if (!out) return HFVIS_ERR_INVALID_ARGUMENT;
    st = vx_iv_metric_init(&M, mesh, grid, occupancy, opts);
    if (st != HFVIS_OK) return st;
    for (s = 0; s < M.np; s++) {
        double best = HUGE_VAL, d;
        for (t = 0; t < M.nt; t++) {
            double v[3][3], d2;
            vx_iv_tri_vertices(mesh, (size_t)M.tris[t], v);
            d2 = vx_iv_tri_d2(M.pts + 3 * s, v[0], v[1], v[2]);
            if (d2 < best) best = d2;
        }
        d = sqrt(best);
        sum_p += d;
        if (d > max_p) max_p = d;
    }
    hfvis__pcg32_seed(&rng, (M.seed) ^ 0x853c49e6748fea9bull, 0xda3e39cb94b95bdbull);
    for (s = 0; s < M.samples; s++) {
        double q[3], best = HUGE_VAL, d;
        size_t p;
        vx_iv_metric_sample(&M, &rng, q);
        for (p = 0; p < M.np; p++) {
            double d2 = vx_iv_pt_d2(q, M.pts + 3 * p);
            if (d2 < best) best = d2;
        }
        d = sqrt(best);
        sum_s += d;
        if (d > max_s) max_s = d;
    }
    vx_iv_metric_out(&M, sum_p, max_p, sum_s, max_s, out);
    vx_iv_metric_free(&M);
    return HFVIS_OK;
}


/* ========================================================================================== */
/* 10. 4D visibility fields ([G12] ch. 4: Alg. 1 build, Alg. 2/3 queries, Figs. 29/31;        */
/*     [G12] ch. 4; A. Gaitatzes et al., "Presampled visibility for ambient occlusion",      */
/*     WSCG 2008, and "Fast approximate visibility on the GPU using pre-computed 4D          */
/*     visibility fields", WSCG 2010)                                                        */
/* ========================================================================================== */
/* Contents
 *   vf-a. positional samples on the bounding sphere (octahedral subdivision, [G12] ch. 4; docs/errata.md E56) and
 *         the constant-time nearest-sample lookup
 *   vf-b. tangent frame (Duff et al. 2017) and the three hemisphere direction maps (§1.4)
 *   vf-c. sizes, validation, texel encoding (§1.2, §1.5-1.6)
 *   vf-d. build (Alg. 1) with the BVH, and its naive-caster oracle
 *   vf-e. queries from outside (Fig. 29) and inside (Fig. 31), and the ray-cast oracle (§1.7)
 *   vf-f. scenes of rigid instances: ambient occlusion (Alg. 2/3), soft shadows, tracing and
 *         reflections (§1.7(c)-(d)), each with its ray-cast oracle
 *   vf-g. the field file: encoder, strict decoder, file wrappers */

#define VX_VF_RIGID_TOL 1e-6          /* |Q^T Q - I| tolerance of an object transform */
#define VX_VF_INSIDE_TOL 1e-6         /* vertices may exceed the radius by this fraction */
#define VX_VF_DEFAULT_RAYS_SQRT 16    /* AO: 16 x 16 = 256 rays (the thesis' CPU count) */
#define VX_VF_DEFAULT_SHADOW_SAMPLES 20 /* thesis: 20 shadow rays per pixel */
#define VX_VF_DEFAULT_REFLECT_RAYS 4  /* thesis: 4 rays per reflective pixel */
#define VX_VF_F32_MAX_HIT 0.99999994f /* 1 - 2^-24: the largest float below 1 */

/* ---- vf-a. positional samples ------------------------------------------------------------ */

/* Samples per hemisphere, H = 2n^2 + 2n + 1 = n^2 + (n+1)^2. */
static size_t vx_vf_hemi(int n)
{
    return 2u * (size_t)n * (size_t)n + 2u * (size_t)n + 1u;
}

static int vx_vf_n_valid(int n) { return n >= 1 && n <= HFVIS_VISFIELD_MAX_N; }
static int vx_vf_d_valid(int d) { return d >= 1 && d <= HFVIS_VISFIELD_MAX_DIR_RES; }

/* Largest s with s*s <= r (r < 2^42 here, so the double estimate is off by at most one). */
static size_t vx_vf_isqrt(size_t r)
{
    size_t s = (size_t)sqrt((double)r);
    while (s > 0 && s * s > r) s--;
    while ((s + 1) * (s + 1) <= r) s++;
    return s;
}

/* Unit direction of lattice point (a, b) of hemisphere h: (a, b, +-c)/sqrt(a^2 + b^2 + c^2),
 * c = n - |a| - |b| (the octahedron point (a/n, b/n, c/n) projected radially; the squared
 * length is an exact integer in double). */
static void vx_vf_oct_dir(int n, int a, int b, int h, double out[3])
{
    int c = n - abs(a) - abs(b);
    double len2 = (double)((long long)a * a + (long long)b * b + (long long)c * c);
    double inv = 1.0 / sqrt(len2);
    out[0] = (double)a * inv;
    out[1] = (double)b * inv;
    out[2] = (h ? -(double)c : (double)c) * inv;
}

/* (h, a, b) of sample k < K. Rows m = b + n: row m <= n holds 2m + 1 points and starts at m^2;
 * the rows above n are counted from the end (the last (2n - m + 1)^2 points are rows m..2n). */
static void vx_vf_decode_index(int n, size_t k, int *h, int *a, int *b)
{
    size_t H = vx_vf_hemi(n), r = k % H;
    *h = (int)(k / H);
    if (r < (size_t)(n + 1) * (size_t)(n + 1)) {
        size_t m = vx_vf_isqrt(r);
        *b = (int)m - n;
        *a = (int)(r - m * m) - (int)m;       /* w = n - |b| = m points each side */
    } else {
        size_t rr = H - 1 - r, mp = vx_vf_isqrt(rr); /* mp = 2n - m = the row's half width */
        *b = n - (int)mp;
        *a = (int)mp - (int)(rr - mp * mp);
    }
}

/* Index of (h, a, b), |a| + |b| <= n. */
static size_t vx_vf_encode_index(int n, int h, int a, int b)
{
    size_t H = vx_vf_hemi(n), m = (size_t)(b + n), off;
    int w = n - abs(b);
    if (m <= (size_t)n) off = m * m;
    else off = H - (2u * (size_t)n - m + 1u) * (2u * (size_t)n - m + 1u);
    return (size_t)h * H + off + (size_t)(a + w);
}

HFVIS_API size_t hfvis_visfield_position_count(int positions_n)
{
    if (!vx_vf_n_valid(positions_n)) return 0;
    return 2u * vx_vf_hemi(positions_n);
}

HFVIS_API hfvis_status hfvis_visfield_position(int positions_n, size_t k, double dir[3])
{
    int h, a, b;
    if (!vx_vf_n_valid(positions_n) || !dir || k >= 2u * vx_vf_hemi(positions_n))
        return HFVIS_ERR_INVALID_ARGUMENT;
    vx_vf_decode_index(positions_n, k, &h, &a, &b);
    vx_vf_oct_dir(positions_n, a, b, h, dir);
    return HFVIS_OK;
}

/* The key every nearest-sample search ranks lattice point (a, b, cs) by, cs = +-(n - |a| - |b|)
 * (the sign of its hemisphere): with d = q . (a, b, cs) and L = a^2 + b^2 + cs^2 (exact), the key
 * d |d| / L = |q|^2 cos|cos| is monotone in the cosine of the angle between q and the sample, so
 * its maximum is the nearest sample, and it needs no square root. One expression for the fast
 * search and the oracle, so that they agree bit for bit. */
static double vx_vf_key(const double q[3], int a, int b, int cs)
{
    double L = (double)((long long)a * a + (long long)b * b + (long long)cs * cs);
    double d = q[0] * (double)a + q[1] * (double)b + q[2] * (double)cs;
    return d * fabs(d) / L;
}

/* q itself, or q divided by its largest |component| when that lies outside [1e-100, 1e100], so
 * that the keys neither overflow nor underflow. Applied by the fast search and the oracle alike. */
static void vx_vf_safe_q(const double q[3], double out[3])
{
    double m = fabs(q[0]);
    if (fabs(q[1]) > m) m = fabs(q[1]);
    if (fabs(q[2]) > m) m = fabs(q[2]);
    if (m >= 1e-100 && m <= 1e100) {
        out[0] = q[0];
        out[1] = q[1];
        out[2] = q[2];
    } else {
        out[0] = q[0] / m;
        out[1] = q[1] / m;
        out[2] = q[2] / m;
    }
}

/* Nearest sample to q (finite, not zero): radial projection onto the octahedron face of q's
 * hemisphere, the (up to) 9 lattice points of the 3 x 3 window around it, ranked by vx_vf_key;
 * equal keys go to the lower index, where an equator point counts with its upper copy's index
 * (same point, same key, lower index): the oracle's rule exactly. Returns the index and the
 * winner's lattice point (*h, *a, *b), the equator in the upper hemisphere. */
static size_t vx_vf_nearest_abh(int n, const double q0[3], int *ph, int *pa, int *pb)
{
    double q[3];
    int h = q0[2] < 0.0, ra, rb, a, b, m = 0, i, best = 0;
    int ca[9], cb[9], cc[9];
    double key[9], qz, s, fx, fy;
    size_t best_k = 0;
    vx_vf_safe_q(q0, q);
    qz = fabs(q[2]);
    s = fabs(q[0]) + fabs(q[1]) + qz;
    fx = floor(q[0] / s * (double)n + 0.5);
    fy = floor(q[1] / s * (double)n + 0.5);
    ra = fx >= -(double)n && fx <= (double)n ? (int)fx : 0;
    rb = fy >= -(double)n && fy <= (double)n ? (int)fy : 0;
    for (b = rb - 1; b <= rb + 1; b++)
        for (a = ra - 1; a <= ra + 1; a++) {
            int c = n - abs(a) - abs(b);
            if (b < -n || b > n || c < 0) continue;
            ca[m] = a;
            cb[m] = b;
            cc[m] = h ? -c : c;
            m++;
        }
    HFVIS_ASSERT(m > 0);
    for (i = 0; i < m; i++) key[i] = vx_vf_key(q, ca[i], cb[i], cc[i]); /* independent: pipelined */
    for (i = 1; i < m; i++) {
        if (key[i] < key[best]) continue;
        if (key[i] == key[best]) { /* a tie: the lower index wins */
            size_t ki = vx_vf_encode_index(n, cc[i] == 0 ? 0 : h, ca[i], cb[i]);
            best_k = vx_vf_encode_index(n, cc[best] == 0 ? 0 : h, ca[best], cb[best]);
            if (ki >= best_k) continue;
        }
        best = i;
    }
    *ph = cc[best] == 0 ? 0 : h;
    *pa = ca[best];
    *pb = cb[best];
    best_k = vx_vf_encode_index(n, *ph, *pa, *pb);
    return best_k;
}

static size_t vx_vf_nearest(int n, const double q[3])
{
    int h, a, b;
    return vx_vf_nearest_abh(n, q, &h, &a, &b);
}

static int vx_vf_vec_ok(const double v[3])
{
    return v && isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2])
           && (v[0] != 0.0 || v[1] != 0.0 || v[2] != 0.0);
}

HFVIS_API hfvis_status hfvis_visfield_nearest_position(int positions_n, const double q[3],
                                                       size_t *k)
{
    if (!vx_vf_n_valid(positions_n) || !vx_vf_vec_ok(q) || !k) return HFVIS_ERR_INVALID_ARGUMENT;
    *k = vx_vf_nearest(positions_n, q);
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_visfield_nearest_position_naive(int positions_n, const double q0[3],
                                                             size_t *k)
{
    size_t K, i, best_i = 0;
    double best = -HUGE_VAL, q[3];
    if (!vx_vf_n_valid(positions_n) || !vx_vf_vec_ok(q0) || !k) return HFVIS_ERR_INVALID_ARGUMENT;
    K = 2u * vx_vf_hemi(positions_n);
    vx_vf_safe_q(q0, q);
    for (i = 0; i < K; i++) {
        double dd;
        int h, a, b, c;
        vx_vf_decode_index(positions_n, i, &h, &a, &b);
        c = positions_n - abs(a) - abs(b);
        dd = vx_vf_key(q, a, b, h ? -c : c);
        if (i == 0 || dd > best) {
            best = dd;
            best_i = i;
        }
    }
    *k = best_i;
    return HFVIS_OK;
}

/* ---- vf-b. frame and direction maps ------------------------------------------------------ */

HFVIS_API void hfvis_visfield_frame(const double w[3], double t[3], double b[3])
{
    double s = w[2] < 0.0 ? -1.0 : 1.0; /* copysign(1, w.z) without C99 copysign's -0 case */
    double a = -1.0 / (s + w[2]), e = w[0] * w[1] * a;
    t[0] = 1.0 + s * w[0] * w[0] * a;
    t[1] = s * e;
    t[2] = -s * w[0];
    b[0] = e;
    b[1] = s + w[1] * w[1] * a;
    b[2] = -w[1];
}

#define VX_VF_QPI (HFVIS__PI / 4.0)

HFVIS_API void hfvis_concentric_square_to_disk(double a, double b, double *x, double *y)
{
    double r, phi;
    if (a == 0.0 && b == 0.0) {
        *x = 0.0;
        *y = 0.0;
        return;
    }
    if (a > -b) {
        if (a > b) { r = a; phi = VX_VF_QPI * (b / a); }
        else { r = b; phi = VX_VF_QPI * (2.0 - a / b); }
    } else {
        if (a < b) { r = -a; phi = VX_VF_QPI * (4.0 + b / a); }
        else { r = -b; phi = b != 0.0 ? VX_VF_QPI * (6.0 - a / b) : 0.0; }
    }
    *x = r * cos(phi);
    *y = r * sin(phi);
}

HFVIS_API void hfvis_concentric_disk_to_square(double x, double y, double *a, double *b)
{
    double r = sqrt(x * x + y * y), phi;
    if (r == 0.0) {
        *a = 0.0;
        *b = 0.0;
        return;
    }
    phi = atan2(y, x);
    if (phi < -VX_VF_QPI) phi += 2.0 * HFVIS__PI;
    if (phi < VX_VF_QPI) { *a = r; *b = r * (phi / VX_VF_QPI); }
    else if (phi < 3.0 * VX_VF_QPI) { *b = r; *a = r * (2.0 - phi / VX_VF_QPI); }
    else if (phi < 5.0 * VX_VF_QPI) { *a = -r; *b = -r * (phi / VX_VF_QPI - 4.0); }
    else { *b = -r; *a = -r * (6.0 - phi / VX_VF_QPI); }
}

static hfvis_dirmap vx_vf_mapping(hfvis_dirmap m)
{
    return m == HFVIS_DIRMAP_DEFAULT ? HFVIS_DIRMAP_CONCENTRIC : m;
}

static int vx_vf_mapping_valid(hfvis_dirmap m)
{
    return m == HFVIS_DIRMAP_DEFAULT || m == HFVIS_DIRMAP_POLAR || m == HFVIS_DIRMAP_REJECTION
           || m == HFVIS_DIRMAP_CONCENTRIC;
}

/* Square coordinate of texel index i (centre). */
static double vx_vf_sq(int i, int D)
{
    return 2.0 * ((double)i + 0.5) / (double)D - 1.0;
}

/* Texel index of square coordinate A, clamped to 0..D-1. */
static int vx_vf_texel_of(double A, int D)
{
    double f = floor((A + 1.0) * 0.5 * (double)D);
    if (!(f >= 0.0)) return 0;
    if (f > (double)(D - 1)) return D - 1;
    return (int)f;
}

/* Local direction of texel (i, j); returns 0 for an unused rejection texel. m resolved. */
static int vx_vf_to_local(hfvis_dirmap m, int D, int i, int j, double l[3])
{
    if (m == HFVIS_DIRMAP_POLAR) {
        double th = ((double)i + 0.5) / (double)D * (HFVIS__PI / 2.0);
        double ph = ((double)j + 0.5) / (double)D * (2.0 * HFVIS__PI);
        l[0] = sin(th) * cos(ph);
        l[1] = sin(th) * sin(ph);
        l[2] = cos(th);
        return 1;
    } else {
        double A = vx_vf_sq(i, D), B = vx_vf_sq(j, D), x, y, r2;
        if (m == HFVIS_DIRMAP_REJECTION) {
            x = A;
            y = B;
            r2 = x * x + y * y;
            if (r2 > 1.0) {
                l[0] = x;
                l[1] = y;
                l[2] = 0.0;
                return 0;
            }
        } else {
            hfvis_concentric_square_to_disk(A, B, &x, &y);
            r2 = x * x + y * y;
        }
        l[0] = x;
        l[1] = y;
        l[2] = sqrt(r2 < 1.0 ? 1.0 - r2 : 0.0);
        return 1;
    }
}

/* Texel of a unit local direction l (lz >= 0); returns whether it is used. m resolved. */
static int vx_vf_from_local(hfvis_dirmap m, int D, const double l[3], int *i, int *j)
{
    if (m == HFVIS_DIRMAP_POLAR) {
        double lz = l[2] > 1.0 ? 1.0 : l[2], th = acos(lz), ph = atan2(l[1], l[0]);
        double fi, fj;
        if (ph < 0.0) ph += 2.0 * HFVIS__PI;
        fi = floor(th / (HFVIS__PI / 2.0) * (double)D);
        fj = floor(ph / (2.0 * HFVIS__PI) * (double)D);
        *i = fi >= (double)D ? D - 1 : (fi < 0.0 ? 0 : (int)fi);
        *j = fj >= (double)D ? D - 1 : (fj < 0.0 ? 0 : (int)fj);
        return 1;
    } else if (m == HFVIS_DIRMAP_REJECTION) {
        double A, B;
        *i = vx_vf_texel_of(l[0], D);
        *j = vx_vf_texel_of(l[1], D);
        A = vx_vf_sq(*i, D);
        B = vx_vf_sq(*j, D);
        return A * A + B * B <= 1.0;
    } else {
        double A, B;
        hfvis_concentric_disk_to_square(l[0], l[1], &A, &B);
        *i = vx_vf_texel_of(A, D);
        *j = vx_vf_texel_of(B, D);
        return 1;
    }
}

HFVIS_API hfvis_status hfvis_dirmap_to_local(hfvis_dirmap mapping, int dir_res, int i, int j,
                                             double l[3], int *used)
{
    double tmp[3];
    int u;
    if (!vx_vf_mapping_valid(mapping) || !vx_vf_d_valid(dir_res) || i < 0 || j < 0
        || i >= dir_res || j >= dir_res || !l || !used)
        return HFVIS_ERR_INVALID_ARGUMENT;
    u = vx_vf_to_local(vx_vf_mapping(mapping), dir_res, i, j, tmp);
    l[0] = tmp[0];
    l[1] = tmp[1];
    l[2] = tmp[2];
    *used = u;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_dirmap_from_local(hfvis_dirmap mapping, int dir_res,
                                               const double l[3], int *i, int *j, int *used)
{
    double len, u[3];
    int ii, jj, us;
    if (!vx_vf_mapping_valid(mapping) || !vx_vf_d_valid(dir_res) || !vx_vf_vec_ok(l) || !i || !j
        || l[2] < 0.0)
        return HFVIS_ERR_INVALID_ARGUMENT;
    len = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
    if (!(len > 0.0) || !isfinite(len)) return HFVIS_ERR_INVALID_ARGUMENT;
    u[0] = l[0] / len;
    u[1] = l[1] / len;
    u[2] = l[2] / len;
    us = vx_vf_from_local(vx_vf_mapping(mapping), dir_res, u, &ii, &jj);
    *i = ii;
    *j = jj;
    if (used) *used = us;
    return HFVIS_OK;
}

/* ---- vf-c. sizes, validation, texel encoding --------------------------------------------- */

static hfvis_visfield_format vx_vf_format(hfvis_visfield_format f)
{
    return f == HFVIS_VISFIELD_DEFAULT ? HFVIS_VISFIELD_U8 : f;
}

static int vx_vf_format_valid(hfvis_visfield_format f)
{
    return f == HFVIS_VISFIELD_DEFAULT || f == HFVIS_VISFIELD_U8 || f == HFVIS_VISFIELD_F32
           || f == HFVIS_VISFIELD_BIT || f == HFVIS_VISFIELD_NORMAL;
}

/* Maps bytes in 64 bits (never overflows for valid n, D: K*D^2*4 < 2^49). */
static uint64_t vx_vf_size64(int n, int D, hfvis_visfield_format f)
{
    uint64_t texels = (uint64_t)(2u * vx_vf_hemi(n)) * (uint64_t)D * (uint64_t)D;
    switch (vx_vf_format(f)) {
    case HFVIS_VISFIELD_F32:
    case HFVIS_VISFIELD_NORMAL: return texels * 4u;
    case HFVIS_VISFIELD_BIT: return (texels + 7u) / 8u;
    default: return texels;
    }
}

HFVIS_API size_t hfvis_visfield_size(int positions_n, int dir_res, hfvis_visfield_format format)
{
    uint64_t s;
    if (!vx_vf_n_valid(positions_n) || !vx_vf_d_valid(dir_res) || !vx_vf_format_valid(format))
        return 0;
    s = vx_vf_size64(positions_n, dir_res, format);
    if (s > (uint64_t)SIZE_MAX) return 0;
    return (size_t)s;
}

/* Parameters valid (maps not looked at). */
static int vx_vf_params_ok(const hfvis_visfield *vf)
{
    return vf && isfinite(vf->center[0]) && isfinite(vf->center[1]) && isfinite(vf->center[2])
           && isfinite(vf->radius) && vf->radius > 0.0 && vx_vf_n_valid(vf->positions_n)
           && vx_vf_d_valid(vf->dir_res) && vx_vf_mapping_valid(vf->mapping)
           && vx_vf_format_valid(vf->format) && isfinite(vf->avg_distance)
           && vf->avg_distance >= 0.0 && vf->avg_distance <= 1.0;
}

/* Parameters valid and maps present with enough bytes. */
static int vx_vf_valid(const hfvis_visfield *vf)
{
    size_t need;
    if (!vx_vf_params_ok(vf) || !vf->maps) return 0;
    need = hfvis_visfield_size(vf->positions_n, vf->dir_res, vf->format);
    return need != 0 && vf->maps_size >= need;
}

/* 8-bit distance code of a normalised hit distance v in [0, 1] ([G12] ch. 4, Alg. 1; docs/errata.md E64). */
static unsigned char vx_vf_code8(double v)
{
    double q = floor((double)HFVIS_VISFIELD_U8_SCALE * v + 0.5);
    if (!(q >= 0.0)) q = 0.0;
    if (q > (double)HFVIS_VISFIELD_U8_SCALE) q = (double)HFVIS_VISFIELD_U8_SCALE;
    return (unsigned char)q;
}

static unsigned char vx_vf_code_normal(double c)
{
    double q = floor(127.5 * c + 128.0);
    if (!(q >= 0.0)) q = 0.0;
    if (q > 255.0) q = 255.0;
    return (unsigned char)q;
}

/* Write texel t (linear index over all maps) of format f: hit (v = th/(2R)) or miss. */
static void vx_vf_store(unsigned char *maps, hfvis_visfield_format f, size_t t, int hit, double v,
                        const double nrm[3])
{
    switch (f) {
    case HFVIS_VISFIELD_F32: {
        float x = 1.0f;
        if (hit) {
            x = (float)v;
            if (!(x >= 0.0f)) x = 0.0f;
            if (x > VX_VF_F32_MAX_HIT) x = VX_VF_F32_MAX_HIT;
        }
        memcpy(maps + 4 * t, &x, 4);
        break;
    }
    case HFVIS_VISFIELD_BIT:
        if (hit) maps[t >> 3] = (unsigned char)(maps[t >> 3] | (1u << (t & 7u)));
        else maps[t >> 3] = (unsigned char)(maps[t >> 3] & ~(1u << (t & 7u)));
        break;
    case HFVIS_VISFIELD_NORMAL:
        if (hit) {
            maps[4 * t] = vx_vf_code_normal(nrm[0]);
            maps[4 * t + 1] = vx_vf_code_normal(nrm[1]);
            maps[4 * t + 2] = vx_vf_code_normal(nrm[2]);
            maps[4 * t + 3] = vx_vf_code8(v);
        } else {
            maps[4 * t] = maps[4 * t + 1] = maps[4 * t + 2] = 0;
            maps[4 * t + 3] = HFVIS_VISFIELD_U8_MISS;
        }
        break;
    default:
        maps[t] = hit ? vx_vf_code8(v) : (unsigned char)HFVIS_VISFIELD_U8_MISS;
        break;
    }
}

/* Read texel t: returns 1 for a hit with *v = th/(2R) (and the normal for NORMAL), 0 for a miss. */
static int vx_vf_load(const hfvis_visfield *vf, hfvis_visfield_format f, size_t t, double *v,
                      double nrm[3])
{
    const unsigned char *maps = (const unsigned char *)vf->maps;
    switch (f) {
    case HFVIS_VISFIELD_F32: {
        float x;
        memcpy(&x, maps + 4 * t, 4);
        if (!(x < 1.0f)) return 0;
        *v = (double)x;
        return 1;
    }
    case HFVIS_VISFIELD_BIT:
        if (!((maps[t >> 3] >> (t & 7u)) & 1u)) return 0;
        *v = vf->avg_distance;
        return 1;
    case HFVIS_VISFIELD_NORMAL: {
        const unsigned char *p = maps + 4 * t;
        if (p[3] == HFVIS_VISFIELD_U8_MISS) return 0;
        *v = (double)p[3] / (double)HFVIS_VISFIELD_U8_SCALE;
        if (nrm) {
            double x = ((double)p[0] - 127.5) / 127.5, y = ((double)p[1] - 127.5) / 127.5;
            double z = ((double)p[2] - 127.5) / 127.5, len = sqrt(x * x + y * y + z * z);
            nrm[0] = x / len;
            nrm[1] = y / len;
            nrm[2] = z / len;
        }
        return 1;
    }
    default:
        if (maps[t] == HFVIS_VISFIELD_U8_MISS) return 0;
        *v = (double)maps[t] / (double)HFVIS_VISFIELD_U8_SCALE;
        return 1;
    }
}

HFVIS_API hfvis_status hfvis_visfield_texel(const hfvis_visfield *vf, size_t k, int i, int j,
                                            int *hit, double *distance, double normal[3])
{
    double v = 1.0, nrm[3] = {0.0, 0.0, 0.0};
    size_t D;
    hfvis_visfield_format f;
    int h;
    if (!vx_vf_valid(vf) || !hit || !distance || k >= 2u * vx_vf_hemi(vf->positions_n) || i < 0
        || j < 0 || i >= vf->dir_res || j >= vf->dir_res)
        return HFVIS_ERR_INVALID_ARGUMENT;
    D = (size_t)vf->dir_res;
    f = vx_vf_format(vf->format);
    h = vx_vf_load(vf, f, (k * D + (size_t)j) * D + (size_t)i, &v, nrm);
    if (!h) v = 1.0;
    if (!h || f != HFVIS_VISFIELD_NORMAL) nrm[0] = nrm[1] = nrm[2] = 0.0;
    *hit = h;
    *distance = v;
    if (normal) {
        normal[0] = nrm[0];
        normal[1] = nrm[1];
        normal[2] = nrm[2];
    }
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_visfield_bounding_sphere(const hfvis_mesh *mesh, double center[3],
                                                      double *radius)
{
    double lo[3], hi[3], c[3], r2 = 0.0, r;
    size_t v;
    int a;
    if (!mesh || !center || !radius || hfvis__mesh_check(mesh) != HFVIS_OK || mesh->vertex_count == 0)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (hfvis_mesh_bounds(mesh, lo, hi) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    for (a = 0; a < 3; a++) c[a] = 0.5 * lo[a] + 0.5 * hi[a];
    for (v = 0; v < mesh->vertex_count; v++) {
        const float *p = mesh->xyz + 3 * v;
        double dx = (double)p[0] - c[0], dy = (double)p[1] - c[1], dz = (double)p[2] - c[2];
        double d2 = dx * dx + dy * dy + dz * dz;
        if (d2 > r2) r2 = d2;
    }
    r = sqrt(r2) * (1.0 + 1e-4);
    if (r < 1e-30) r = 1e-30;
    for (a = 0; a < 3; a++) center[a] = c[a];
    *radius = r;
    return HFVIS_OK;
}

/* ---- vf-d. build (Algorithm 1) ----------------------------------------------------------- */

/* Unit geometric normal (v1 - v0) x (v2 - v0) of triangle tri, in double. */
static void vx_vf_tri_normal(const hfvis_mesh *m, uint32_t tri, double n[3])
{
    const uint32_t *ix = m->indices + 3 * (size_t)tri;
    const float *p0 = m->xyz + 3 * (size_t)ix[0], *p1 = m->xyz + 3 * (size_t)ix[1];
    const float *p2 = m->xyz + 3 * (size_t)ix[2];
    double e1[3], e2[3], len;
    int a;
    for (a = 0; a < 3; a++) {
        e1[a] = (double)p1[a] - (double)p0[a];
        e2[a] = (double)p2[a] - (double)p0[a];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (len > 0.0) {
        n[0] /= len;
        n[1] /= len;
        n[2] /= len;
    }
}

/* Closest hit of a float ray from o along d (t_min = 0, t_max = +inf), through bvh or naively
 * (bvh NULL). *th = t * |direction| (distance along the unit direction); *tri the triangle. */
static hfvis_status vx_vf_cast(const hfvis_mesh *mesh, const hfvis_bvh *bvh, const double o[3],
                               const double d[3], int *hit, double *th, uint32_t *tri)
{
    hfvis_ray ray;
    hfvis_hit h;
    hfvis_status s;
    double len;
    int a;
    for (a = 0; a < 3; a++) {
        ray.origin[a] = (float)o[a];
        ray.direction[a] = (float)d[a];
    }
    ray.t_min = 0.0f;
    ray.t_max = INFINITY;
    ray.cull = HFVIS_CULL_NONE;
    s = bvh ? hfvis_bvh_closest_hit(bvh, mesh, &ray, &h) : hfvis_ray_closest_naive(mesh, &ray, &h);
    if (s != HFVIS_OK) return s;
    *hit = h.triangle != HFVIS_NO_TRIANGLE;
    if (*hit) {
        len = sqrt((double)ray.direction[0] * (double)ray.direction[0]
                   + (double)ray.direction[1] * (double)ray.direction[1]
                   + (double)ray.direction[2] * (double)ray.direction[2]);
        *th = (double)h.t * len;
        *tri = h.triangle;
    }
    return HFVIS_OK;
}

/* Arguments of both builds: a valid mesh inside the sphere, valid parameters and storage. */
static hfvis_status vx_vf_build_check(const hfvis_mesh *mesh, const hfvis_visfield *vf)
{
    size_t need, v;
    double lim;
    if (!mesh || !vf || hfvis__mesh_check(mesh) != HFVIS_OK || !vf->maps)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (!isfinite(vf->center[0]) || !isfinite(vf->center[1]) || !isfinite(vf->center[2])
        || !isfinite(vf->radius) || !(vf->radius > 0.0) || !vx_vf_n_valid(vf->positions_n)
        || !vx_vf_d_valid(vf->dir_res) || !vx_vf_mapping_valid(vf->mapping)
        || !vx_vf_format_valid(vf->format))
        return HFVIS_ERR_INVALID_ARGUMENT;
    need = hfvis_visfield_size(vf->positions_n, vf->dir_res, vf->format);
    if (need == 0) return HFVIS_ERR_LIMIT; /* does not fit size_t (32-bit hosts) */
    lim = vf->radius * (1.0 + VX_VF_INSIDE_TOL);
    lim *= lim;
    for (v = 0; v < mesh->vertex_count; v++) {
        const float *p = mesh->xyz + 3 * v;
        double dx = (double)p[0] - vf->center[0], dy = (double)p[1] - vf->center[1];
        double dz = (double)p[2] - vf->center[2];
        if (!(dx * dx + dy * dy + dz * dz <= lim)) return HFVIS_ERR_INVALID_ARGUMENT;
    }
    if (vf->maps_size < need) return HFVIS_ERR_BUFFER_TOO_SMALL;
    return HFVIS_OK;
}

/* Algorithm 1 over all samples and texels; bvh NULL = the naive caster. */
static hfvis_status vx_vf_build_run(const hfvis_mesh *mesh, const hfvis_bvh *bvh,
                                    const hfvis_visfield_build_options *opts, hfvis_visfield *vf)
{
    const int n = vf->positions_n, D = vf->dir_res;
    const size_t K = 2u * vx_vf_hemi(n), DD = (size_t)D * (size_t)D;
    const hfvis_dirmap m = vx_vf_mapping(vf->mapping);
    const hfvis_visfield_format f = vx_vf_format(vf->format);
    const double R = vf->radius, inv2R = 1.0 / (2.0 * R);
    unsigned char *maps = (unsigned char *)vf->maps;
    double sum = 0.0, nrm[3] = {0.0, 0.0, 0.0};
    size_t k, central = 0;
    hfvis_status s;

    if (f == HFVIS_VISFIELD_BIT) memset(maps, 0, (size_t)vx_vf_size64(n, D, f));
    for (k = 0; k < K; k++) {
        double u[3], w[3], t[3], b[3], p[3], th = 0.0;
        uint32_t tri = 0;
        int i, j, hit = 0, a;
        s = hfvis_visfield_position(n, k, u);
        HFVIS_ASSERT(s == HFVIS_OK);
        for (a = 0; a < 3; a++) {
            w[a] = -u[a];
            p[a] = vf->center[a] + R * u[a];
        }
        hfvis_visfield_frame(w, t, b);
        /* the central ray (along the inward normal) for avg_distance ([G12] §4.6.1.3) */
        s = vx_vf_cast(mesh, bvh, p, w, &hit, &th, &tri);
        if (s != HFVIS_OK) return s;
        if (hit) {
            sum += th * inv2R;
            central++;
        }
        for (j = 0; j < D; j++)
            for (i = 0; i < D; i++) {
                double l[3], d[3];
                size_t texel = k * DD + (size_t)j * (size_t)D + (size_t)i;
                hit = 0;
                if (vx_vf_to_local(m, D, i, j, l)) {
                    for (a = 0; a < 3; a++) d[a] = l[0] * t[a] + l[1] * b[a] + l[2] * w[a];
                    s = vx_vf_cast(mesh, bvh, p, d, &hit, &th, &tri);
                    if (s != HFVIS_OK) return s;
                }
                if (hit && f == HFVIS_VISFIELD_NORMAL) vx_vf_tri_normal(mesh, tri, nrm);
                vx_vf_store(maps, f, texel, hit, hit ? th * inv2R : 1.0, nrm);
            }
        if (opts && opts->progress) opts->progress(opts->progress_user, (int)(k + 1), (int)K);
    }
    vf->avg_distance = central ? sum / (double)central : 0.5;
    if (vf->avg_distance > 1.0) vf->avg_distance = 1.0;
    return HFVIS_OK;
}

HFVIS_API hfvis_visfield_build_options hfvis_visfield_build_options_default(void)
{
    hfvis_visfield_build_options o;
    memset(&o, 0, sizeof o); /* no allocator, a BVH built inside, no progress callback */
    return o;
}

HFVIS_API hfvis_status hfvis_visfield_build(const hfvis_mesh *mesh,
                                            const hfvis_visfield_build_options *opts,
                                            hfvis_visfield *vf)
{
    hfvis_bvh own;
    const hfvis_bvh *bvh;
    hfvis_status s = vx_vf_build_check(mesh, vf);
    if (s != HFVIS_OK) return s;
    if (opts && opts->bvh) {
        if (opts->bvh->triangle_count != mesh->triangle_count) return HFVIS_ERR_INVALID_ARGUMENT;
        return vx_vf_build_run(mesh, opts->bvh, opts, vf);
    }
    {
        hfvis_bvh_options bo = hfvis_bvh_options_default();
        bo.alloc = opts ? opts->alloc : NULL;
        s = hfvis_bvh_build(mesh, &bo, &own);
        if (s != HFVIS_OK) return s;
    }
    bvh = &own;
    s = vx_vf_build_run(mesh, bvh, opts, vf);
    hfvis_bvh_free(opts ? opts->alloc : NULL, &own);
    return s;
}

HFVIS_API hfvis_status hfvis_visfield_build_reference(const hfvis_mesh *mesh,
                                                      const hfvis_visfield_build_options *opts,
                                                      hfvis_visfield *vf)
{
    hfvis_status s = vx_vf_build_check(mesh, vf);
    if (s != HFVIS_OK) return s;
    return vx_vf_build_run(mesh, NULL, opts, vf);
}

/* ---- vf-e. queries ----------------------------------------------------------------------- */

static void vx_vf_hit_miss(hfvis_visfield_hit *h)
{
    h->result = HFVIS_VISFIELD_MISS;
    h->distance = HUGE_VAL;
    h->normal[0] = h->normal[1] = h->normal[2] = 0.0;
    h->sphere_t = HUGE_VAL;
    h->position = HFVIS_VISFIELD_NONE;
    h->texel_i = h->texel_j = -1;
}

/* The sphere part of both queries: returns 0 (miss: the ray does not meet the sphere), 1
 * (outside: *t = entry t0, rel = entry - c) or 2 (inside: *t = exit t1, rel = exit - c). */
static int vx_vf_sphere(const hfvis_visfield *vf, const double o[3], const double d[3], double *t,
                        double rel[3])
{
    double oc[3], beta, gamma, delta, sq, t0, t1, R = vf->radius;
    int a;
    for (a = 0; a < 3; a++) oc[a] = o[a] - vf->center[a];
    beta = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
    gamma = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - R * R;
    delta = beta * beta - gamma;
    /* fields or rays so far out that the squares overflow: no answer rather than a NaN index */
    if (!isfinite(beta) || !isfinite(gamma) || !isfinite(delta)) return 0;
    if (gamma >= 0.0) {
        if (!(delta > 0.0)) return 0;
        sq = sqrt(delta);
        t1 = -beta + sq;
        if (!(t1 > 0.0)) return 0;
        t0 = -beta - sq;
        if (t0 < 0.0) t0 = 0.0;
        *t = t0;
        for (a = 0; a < 3; a++) rel[a] = oc[a] + t0 * d[a];
        if (rel[0] == 0.0 && rel[1] == 0.0 && rel[2] == 0.0) /* underflow: a central ray */
            for (a = 0; a < 3; a++) rel[a] = -d[a];
        return isfinite(t0) && isfinite(rel[0]) && isfinite(rel[1]) && isfinite(rel[2]) ? 1 : 0;
    }
    sq = sqrt(delta);
    t1 = -beta + sq;
    *t = t1;
    for (a = 0; a < 3; a++) rel[a] = oc[a] + t1 * d[a];
    if (rel[0] == 0.0 && rel[1] == 0.0 && rel[2] == 0.0)
        for (a = 0; a < 3; a++) rel[a] = d[a];
    return isfinite(t1) && isfinite(rel[0]) && isfinite(rel[1]) && isfinite(rel[2]) ? 2 : 0;
}

/* The map lookup of both cases: direction e (unit) toward the object at the sample nearest rel.
 * Returns 1 with *v (and nrm) on a stored hit. */
static int vx_vf_lookup(const hfvis_visfield *vf, const double rel[3], const double e[3],
                        hfvis_visfield_hit *out, double *v, double nrm[3])
{
    const int n = vf->positions_n, D = vf->dir_res;
    const hfvis_visfield_format f = vx_vf_format(vf->format);
    double u[3], w[3], t[3], b[3], l[3];
    int h, aa, bb, i, j;
    size_t k = vx_vf_nearest_abh(n, rel, &h, &aa, &bb);
    vx_vf_oct_dir(n, aa, bb, h, u);
    w[0] = -u[0];
    w[1] = -u[1];
    w[2] = -u[2];
    hfvis_visfield_frame(w, t, b);
    out->position = k;
    l[0] = e[0] * t[0] + e[1] * t[1] + e[2] * t[2];
    l[1] = e[0] * b[0] + e[1] * b[1] + e[2] * b[2];
    l[2] = e[0] * w[0] + e[1] * w[1] + e[2] * w[2];
    if (!(l[2] > 0.0)) return 0; /* grazing: outside the sample's hemisphere (docs/errata.md E64) */
    if (!vx_vf_from_local(vx_vf_mapping(vf->mapping), D, l, &i, &j)) {
        out->texel_i = i;
        out->texel_j = j;
        return 0; /* unused rejection texel */
    }
    out->texel_i = i;
    out->texel_j = j;
    return vx_vf_load(vf, f, (k * (size_t)D + (size_t)j) * (size_t)D + (size_t)i, v,
                      f == HFVIS_VISFIELD_NORMAL ? nrm : NULL);
}

/* Algorithms 2/3 for one ray, d unit, object space. */
static void vx_vf_query_core(const hfvis_visfield *vf, const double o[3], const double d[3],
                             double bias, hfvis_visfield_hit *out)
{
    double t, rel[3], v = 0.0, nrm[3] = {0.0, 0.0, 0.0}, e[3], twoR = 2.0 * vf->radius;
    int c;
    vx_vf_hit_miss(out);
    c = vx_vf_sphere(vf, o, d, &t, rel);
    if (c == 0) return;
    out->sphere_t = t;
    if (c == 1) {
        if (!vx_vf_lookup(vf, rel, d, out, &v, nrm)) return;
        out->result = HFVIS_VISFIELD_HIT;
        out->distance = t + v * twoR;
    } else {
        double d2;
        e[0] = -d[0];
        e[1] = -d[1];
        e[2] = -d[2];
        if (!vx_vf_lookup(vf, rel, e, out, &v, nrm)) return;
        d2 = v * twoR;
        if (!(d2 < t - bias)) return;
        out->result = HFVIS_VISFIELD_OCCLUDED;
        out->distance = t - d2;
    }
    out->normal[0] = nrm[0];
    out->normal[1] = nrm[1];
    out->normal[2] = nrm[2];
}

/* The same with exact ray casting from the entry / exit point. */
static hfvis_status vx_vf_query_ref_core(const hfvis_visfield *vf, const hfvis_mesh *mesh,
                                         const hfvis_bvh *bvh, const double o[3],
                                         const double d[3], double bias, hfvis_visfield_hit *out)
{
    double t, rel[3], p[3], e[3], th = 0.0;
    uint32_t tri = 0;
    hfvis_status s;
    int c, a, hit = 0;
    vx_vf_hit_miss(out);
    c = vx_vf_sphere(vf, o, d, &t, rel);
    if (c == 0) return HFVIS_OK;
    out->sphere_t = t;
    for (a = 0; a < 3; a++) {
        p[a] = o[a] + t * d[a];
        e[a] = c == 1 ? d[a] : -d[a];
    }
    s = vx_vf_cast(mesh, bvh, p, e, &hit, &th, &tri);
    if (s != HFVIS_OK) return s;
    if (!hit) return HFVIS_OK;
    if (c == 1) {
        out->result = HFVIS_VISFIELD_HIT;
        out->distance = t + th;
    } else {
        if (!(th < t - bias)) return HFVIS_OK;
        out->result = HFVIS_VISFIELD_OCCLUDED;
        out->distance = t - th;
    }
    vx_vf_tri_normal(mesh, tri, out->normal);
    return HFVIS_OK;
}

/* Unit copy of a valid direction. */
static int vx_vf_unit(const double d[3], double u[3])
{
    double len;
    if (!vx_vf_vec_ok(d)) return 0;
    len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(len > 0.0) || !isfinite(len)) { /* over/underflow: rescale first */
        double m = fabs(d[0]);
        if (fabs(d[1]) > m) m = fabs(d[1]);
        if (fabs(d[2]) > m) m = fabs(d[2]);
        u[0] = d[0] / m;
        u[1] = d[1] / m;
        u[2] = d[2] / m;
        len = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
        u[0] /= len;
        u[1] /= len;
        u[2] /= len;
        return 1;
    }
    u[0] = d[0] / len;
    u[1] = d[1] / len;
    u[2] = d[2] / len;
    return 1;
}

static int vx_vf_point_ok(const double p[3])
{
    return p && isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]);
}

HFVIS_API hfvis_status hfvis_visfield_query(const hfvis_visfield *vf, const double origin[3],
                                            const double direction[3], double bias,
                                            hfvis_visfield_hit *out)
{
    double d[3];
    hfvis_visfield_hit h;
    if (!vx_vf_valid(vf) || !vx_vf_point_ok(origin) || !vx_vf_unit(direction, d) || !out
        || !isfinite(bias) || bias < 0.0)
        return HFVIS_ERR_INVALID_ARGUMENT;
    vx_vf_query_core(vf, origin, d, bias, &h);
    *out = h;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_visfield_query_reference(const hfvis_visfield *vf,
                                                      const hfvis_mesh *mesh,
                                                      const hfvis_bvh *bvh,
                                                      const double origin[3],
                                                      const double direction[3], double bias,
                                                      hfvis_visfield_hit *out)
{
    double d[3];
    hfvis_visfield_hit h;
    hfvis_status s;
    if (!vx_vf_params_ok(vf) || !mesh || !vx_vf_point_ok(origin) || !vx_vf_unit(direction, d)
        || !out || !isfinite(bias) || bias < 0.0)
        return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_vf_query_ref_core(vf, mesh, bvh, origin, d, bias, &h);
    if (s != HFVIS_OK) return s;
    *out = h;
    return HFVIS_OK;
}

/* ---- vf-f. scenes: AO, soft shadows, tracing, reflections -------------------------------- */

/* One object prepared for queries: object -> world M = [s Q | T]. */
typedef struct vx_vf_inst {
    const hfvis_visfield *vf;
    const hfvis_mesh *mesh;
    const hfvis_bvh *bvh;
    double q[9];     /* columns of Q: q[3c + r] */
    double T[3];
    double s, inv_s;
    double bias;     /* object units */
} vx_vf_inst;

/* Rigid-with-uniform-scale check of a column-major matrix; fills inst's transform. */
static int vx_vf_transform(const double m[16], vx_vf_inst *in)
{
    double s2;
    int a, b, r;
    for (a = 0; a < 16; a++)
        if (!isfinite(m[a])) return 0;
    if (m[3] != 0.0 || m[7] != 0.0 || m[11] != 0.0 || m[15] != 1.0) return 0;
    s2 = m[0] * m[0] + m[1] * m[1] + m[2] * m[2];
    if (!(s2 > 0.0) || !isfinite(s2)) return 0;
    for (a = 0; a < 3; a++)
        for (b = a; b < 3; b++) {
            double dd = m[4 * a] * m[4 * b] + m[4 * a + 1] * m[4 * b + 1]
                        + m[4 * a + 2] * m[4 * b + 2];
            if (!(fabs(dd - (a == b ? s2 : 0.0)) <= VX_VF_RIGID_TOL * s2)) return 0;
        }
    in->s = sqrt(s2);
    in->inv_s = 1.0 / in->s;
    for (a = 0; a < 3; a++) {
        for (r = 0; r < 3; r++) in->q[3 * a + r] = m[4 * a + r] * in->inv_s;
        in->T[a] = m[12 + a];
    }
    return 1;
}

/* Validate the objects of a scene (reference: also meshes and BVHs, O(V + T) each). */
static hfvis_status vx_vf_objects_check(const hfvis_visfield_object *objects, size_t count,
                                        int reference)
{
    size_t i;
    vx_vf_inst tmp;
    /* the object array (and the per-object scratch sized from count) must be addressable */
    if ((count && !objects) || count > SIZE_MAX / sizeof(hfvis_visfield_object))
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (i = 0; i < count; i++) {
        const hfvis_visfield_object *o = objects + i;
        if (!vx_vf_transform(o->object_to_world, &tmp)) return HFVIS_ERR_INVALID_ARGUMENT;
        if (reference) {
            if (!vx_vf_params_ok(o->field) || hfvis__mesh_check(o->mesh) != HFVIS_OK)
                return HFVIS_ERR_INVALID_ARGUMENT;
            if (o->bvh && o->bvh->triangle_count != o->mesh->triangle_count)
                return HFVIS_ERR_INVALID_ARGUMENT;
        } else if (!vx_vf_valid(o->field)) {
            return HFVIS_ERR_INVALID_ARGUMENT;
        }
    }
    return HFVIS_OK;
}

/* Prepare a validated object; bias_frac * R is its object-space bias. */
static void vx_vf_inst_make(const hfvis_visfield_object *o, double bias_frac, vx_vf_inst *in)
{
    int ok = vx_vf_transform(o->object_to_world, in);
    HFVIS_ASSERT(ok);
    (void)ok;
    in->vf = o->field;
    in->mesh = o->mesh;
    in->bvh = o->bvh;
    in->bias = bias_frac * o->field->radius;
}

/* World ray (o, d unit) -> object space (o2, d2 unit). */
static void vx_vf_to_object(const vx_vf_inst *in, const double o[3], const double d[3],
                            double o2[3], double d2[3])
{
    double r[3];
    int c;
    for (c = 0; c < 3; c++) r[c] = o[c] - in->T[c];
    for (c = 0; c < 3; c++) {
        const double *qc = in->q + 3 * c;
        o2[c] = (qc[0] * r[0] + qc[1] * r[1] + qc[2] * r[2]) * in->inv_s;
        d2[c] = qc[0] * d[0] + qc[1] * d[1] + qc[2] * d[2];
    }
}

/* Query one object with a world ray; world distance in *dist. Returns the result. */
static hfvis_status vx_vf_inst_query(const vx_vf_inst *in, int reference, const double o[3],
                                     const double d[3], hfvis_visfield_hit *h)
{
    double o2[3], d2[3];
    vx_vf_to_object(in, o, d, o2, d2);
    if (reference) return vx_vf_query_ref_core(in->vf, in->mesh, in->bvh, o2, d2, in->bias, h);
    vx_vf_query_core(in->vf, o2, d2, in->bias, h);
    return HFVIS_OK;
}

HFVIS_API hfvis_visfield_ao_options hfvis_visfield_ao_options_default(void)
{
    hfvis_visfield_ao_options o;
    memset(&o, 0, sizeof o);
    o.rays_sqrt = VX_VF_DEFAULT_RAYS_SQRT;
    o.max_distance = HUGE_VAL;
    o.falloff = HFVIS_VISFIELD_FALLOFF_BINARY;
    o.combine = HFVIS_VISFIELD_COMBINE_ANY;
    o.bias = HFVIS_VISFIELD_DEFAULT_BIAS;
    o.offset = 0.0;
    o.alloc = NULL;
    return o;
}

/* Bias fraction of the options (0 = default); -1 if invalid. */
static double vx_vf_bias_frac(double b)
{
    if (!isfinite(b) || b < 0.0) return -1.0;
    return b == 0.0 ? HFVIS_VISFIELD_DEFAULT_BIAS : b;
}

/* Points (and normals) finite, normals not zero. */
static int vx_vf_points_ok(const float *pts, const float *nrm, size_t count)
{
    size_t i;
    if (count > SIZE_MAX / 3) return 0;
    for (i = 0; i < 3 * count; i++)
        if (!isfinite(pts[i]) || (nrm && !isfinite(nrm[i]))) return 0;
    if (nrm)
        for (i = 0; i < count; i++)
            if (nrm[3 * i] == 0.0f && nrm[3 * i + 1] == 0.0f && nrm[3 * i + 2] == 0.0f) return 0;
    return 1;
}

/* The instances of a validated scene in one block (NULL and OK for count 0). */
static hfvis_status vx_vf_insts(const hfvis_visfield_object *objects, size_t count,
                                double bias_frac, const hfvis_allocator *alloc, vx_vf_inst **out)
{
    size_t i;
    vx_vf_inst *in;
    *out = NULL;
    if (count == 0) return HFVIS_OK;
    in = (vx_vf_inst *)hfvis__alloc_array(alloc, count, sizeof *in);
    if (!in) return HFVIS_ERR_OUT_OF_MEMORY;
    for (i = 0; i < count; i++) vx_vf_inst_make(objects + i, bias_frac, in + i);
    *out = in;
    return HFVIS_OK;
}

/* Ambient occlusion driver (fast or reference). */
static hfvis_status vx_vf_ao_run(const hfvis_visfield_object *objects, size_t count,
                                 const float *points, const float *normals, size_t pc,
                                 const hfvis_visfield_ao_options *opts, float *out, int reference)
{
    hfvis_visfield_ao_options o = hfvis_visfield_ao_options_default();
    const hfvis_allocator *alloc;
    vx_vf_inst *in = NULL;
    double *rays = NULL, maxd, bias_frac;
    float *res = NULL;
    size_t S, nr, p, r, m;
    hfvis_status s;
    int i, j;

    if (opts) {
        o = *opts;
        if (o.rays_sqrt == 0) o.rays_sqrt = VX_VF_DEFAULT_RAYS_SQRT;
        if (o.max_distance == 0.0) o.max_distance = HUGE_VAL;
        if (o.falloff == HFVIS_VISFIELD_FALLOFF_DEFAULT) o.falloff = HFVIS_VISFIELD_FALLOFF_BINARY;
        if (o.combine == HFVIS_VISFIELD_COMBINE_DEFAULT) o.combine = HFVIS_VISFIELD_COMBINE_ANY;
    }
    bias_frac = vx_vf_bias_frac(o.bias);
    maxd = o.max_distance;
    if (o.rays_sqrt < 1 || o.rays_sqrt > HFVIS_VISFIELD_MAX_RAYS_SQRT || !(maxd > 0.0)
        || bias_frac < 0.0 || !isfinite(o.offset) || o.offset < 0.0
        || (o.falloff != HFVIS_VISFIELD_FALLOFF_BINARY
            && o.falloff != HFVIS_VISFIELD_FALLOFF_LINEAR)
        || (o.combine != HFVIS_VISFIELD_COMBINE_ANY
            && o.combine != HFVIS_VISFIELD_COMBINE_SUBTRACTIVE)
        || (o.falloff == HFVIS_VISFIELD_FALLOFF_LINEAR && !isfinite(maxd)))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (pc && (!points || !normals || !out)) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_vf_objects_check(objects, count, reference);
    if (s != HFVIS_OK) return s;
    if (pc && !vx_vf_points_ok(points, normals, pc)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (pc == 0) return HFVIS_OK;
    alloc = o.alloc;
    S = (size_t)o.rays_sqrt;
    nr = S * S;
    /* the pre-generated hemisphere ray set ([G12] §4.5.1): concentric grid + Malley */
    rays = (double *)hfvis__alloc_array(alloc, nr, 3 * sizeof(double));
    if (!rays) return HFVIS_ERR_OUT_OF_MEMORY;
    for (j = 0; j < o.rays_sqrt; j++)
        for (i = 0; i < o.rays_sqrt; i++) {
            double x, y, r2, *l = rays + 3 * ((size_t)j * S + (size_t)i);
            hfvis_concentric_square_to_disk(vx_vf_sq(i, o.rays_sqrt), vx_vf_sq(j, o.rays_sqrt),
                                            &x, &y);
            r2 = x * x + y * y;
            l[0] = x;
            l[1] = y;
            l[2] = sqrt(r2 < 1.0 ? 1.0 - r2 : 0.0);
        }
    s = vx_vf_insts(objects, count, bias_frac, alloc, &in);
    if (s != HFVIS_OK) goto done;
    if (reference) {
        res = (float *)hfvis__alloc_array(alloc, pc, sizeof(float));
        if (!res) { s = HFVIS_ERR_OUT_OF_MEMORY; goto done; }
    }
    for (p = 0; p < pc; p++) {
        double x[3], nn[3], n0[3], t[3], b[3], total = 0.0;
        int a;
        for (a = 0; a < 3; a++) n0[a] = (double)normals[3 * p + a];
        vx_vf_unit(n0, nn);
        hfvis_visfield_frame(nn, t, b);
        for (a = 0; a < 3; a++) x[a] = (double)points[3 * p + a] + o.offset * nn[a];
        for (r = 0; r < nr && count; r++) {
            const double *l = rays + 3 * r;
            double d[3], occ = 0.0;
            for (a = 0; a < 3; a++) d[a] = l[0] * t[a] + l[1] * b[a] + l[2] * nn[a];
            for (m = 0; m < count; m++) {
                hfvis_visfield_hit h;
                double dw, wgt;
                s = vx_vf_inst_query(in + m, reference, x, d, &h);
                if (s != HFVIS_OK) goto done;
                if (h.result == HFVIS_VISFIELD_MISS) continue;
                dw = in[m].s * h.distance;
                if (!(dw <= maxd)) continue;
                wgt = o.falloff == HFVIS_VISFIELD_FALLOFF_BINARY ? 1.0 : 1.0 - dw / maxd;
                if (wgt < 0.0) wgt = 0.0;
                if (o.combine == HFVIS_VISFIELD_COMBINE_SUBTRACTIVE) {
                    occ += wgt;
                } else if (wgt > occ) {
                    occ = wgt;
                    if (occ >= 1.0) break; /* any object blocks fully */
                }
            }
            total += occ;
        }
        total /= (double)nr;
        if (total > 1.0) total = 1.0;
        if (reference) res[p] = (float)total;
        else out[p] = (float)total;
    }
    if (reference) memcpy(out, res, pc * sizeof(float));
    s = HFVIS_OK;
done:
    hfvis__free(alloc, res);
    hfvis__free(alloc, in);
    hfvis__free(alloc, rays);
    return s;
}

HFVIS_API hfvis_status hfvis_visfield_ambient_occlusion(const hfvis_visfield_object *objects,
                                                        size_t object_count, const float *points,
                                                        const float *normals, size_t point_count,
                                                        const hfvis_visfield_ao_options *opts,
                                                        float *out)
{
    return vx_vf_ao_run(objects, object_count, points, normals, point_count, opts, out, 0);
}

HFVIS_API hfvis_status hfvis_visfield_ambient_occlusion_reference(
    const hfvis_visfield_object *objects, size_t object_count, const float *points,
    const float *normals, size_t point_count, const hfvis_visfield_ao_options *opts, float *out)
{
    return vx_vf_ao_run(objects, object_count, points, normals, point_count, opts, out, 1);
}

/* Van der Corput radical inverse of i in base 2, in [0, 1). */
static double vx_vf_radical2(uint32_t i)
{
    i = (i << 16) | (i >> 16);
    i = ((i & 0x00ff00ffu) << 8) | ((i & 0xff00ff00u) >> 8);
    i = ((i & 0x0f0f0f0fu) << 4) | ((i & 0xf0f0f0f0u) >> 4);
    i = ((i & 0x33333333u) << 2) | ((i & 0xccccccccu) >> 2);
    i = ((i & 0x55555555u) << 1) | ((i & 0xaaaaaaaau) >> 1);
    return (double)i * (1.0 / 4294967296.0);
}

/* Soft-shadow driver (fast or reference). */
static hfvis_status vx_vf_shadow_run(const hfvis_visfield_object *objects, size_t count,
                                     const float *points, size_t pc, const double lc[3],
                                     double lr, const hfvis_visfield_shadow_options *opts,
                                     float *out, int reference)
{
    const hfvis_allocator *alloc = opts ? opts->alloc : NULL;
    int N = opts && opts->samples ? opts->samples : VX_VF_DEFAULT_SHADOW_SAMPLES;
    double bias_frac = vx_vf_bias_frac(opts ? opts->bias : 0.0), *disk = NULL;
    vx_vf_inst *in = NULL;
    float *res = NULL;
    size_t p, m;
    hfvis_status s;
    int i;

    if (N < 1 || N > HFVIS_VISFIELD_MAX_SAMPLES || bias_frac < 0.0 || !vx_vf_point_ok(lc)
        || !isfinite(lr) || lr < 0.0)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (pc && (!points || !out)) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_vf_objects_check(objects, count, reference);
    if (s != HFVIS_OK) return s;
    if (pc && !vx_vf_points_ok(points, NULL, pc)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (pc == 0) return HFVIS_OK;
    disk = (double *)hfvis__alloc_array(alloc, (size_t)N, 2 * sizeof(double));
    if (!disk) return HFVIS_ERR_OUT_OF_MEMORY;
    for (i = 0; i < N; i++) /* Hammersley points on the light's disc */
        hfvis_concentric_square_to_disk(2.0 * (((double)i + 0.5) / (double)N) - 1.0,
                                        2.0 * vx_vf_radical2((uint32_t)i) - 1.0, disk + 2 * i,
                                        disk + 2 * i + 1);
    s = vx_vf_insts(objects, count, bias_frac, alloc, &in);
    if (s != HFVIS_OK) goto done;
    if (reference) {
        res = (float *)hfvis__alloc_array(alloc, pc, sizeof(float));
        if (!res) { s = HFVIS_ERR_OUT_OF_MEMORY; goto done; }
    }
    for (p = 0; p < pc; p++) {
        double x[3], v[3], w[3] = {0.0, 0.0, 1.0}, e1[3], e2[3], len;
        int a, lit = 0;
        for (a = 0; a < 3; a++) {
            x[a] = (double)points[3 * p + a];
            v[a] = lc[a] - x[a];
        }
        len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (len > 0.0 && isfinite(len))
            for (a = 0; a < 3; a++) w[a] = v[a] / len;
        hfvis_visfield_frame(w, e1, e2);
        for (i = 0; i < N; i++) {
            double y[3], d[3], L;
            int blocked = 0;
            for (a = 0; a < 3; a++)
                y[a] = lc[a] + lr * (disk[2 * i] * e1[a] + disk[2 * i + 1] * e2[a]);
            for (a = 0; a < 3; a++) d[a] = y[a] - x[a];
            L = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            if (!(L > 0.0) || !isfinite(L)) {
                lit++;
                continue;
            }
            for (a = 0; a < 3; a++) d[a] /= L;
            for (m = 0; m < count && !blocked; m++) {
                hfvis_visfield_hit h;
                s = vx_vf_inst_query(in + m, reference, x, d, &h);
                if (s != HFVIS_OK) goto done;
                blocked = h.result != HFVIS_VISFIELD_MISS && in[m].s * h.distance < L;
            }
            lit += !blocked;
        }
        if (reference) res[p] = (float)((double)lit / (double)N);
        else out[p] = (float)((double)lit / (double)N);
    }
    if (reference) memcpy(out, res, pc * sizeof(float));
    s = HFVIS_OK;
done:
    hfvis__free(alloc, res);
    hfvis__free(alloc, in);
    hfvis__free(alloc, disk);
    return s;
}

HFVIS_API hfvis_visfield_shadow_options hfvis_visfield_shadow_options_default(void)
{
    hfvis_visfield_shadow_options o;
    memset(&o, 0, sizeof o);
    o.samples = VX_VF_DEFAULT_SHADOW_SAMPLES;
    o.bias = HFVIS_VISFIELD_DEFAULT_BIAS;
    o.alloc = NULL;
    return o;
}

HFVIS_API hfvis_status hfvis_visfield_soft_shadow(const hfvis_visfield_object *objects,
                                                  size_t object_count, const float *points,
                                                  size_t point_count,
                                                  const double light_center[3],
                                                  double light_radius,
                                                  const hfvis_visfield_shadow_options *opts,
                                                  float *out)
{
    return vx_vf_shadow_run(objects, object_count, points, point_count, light_center,
                            light_radius, opts, out, 0);
}

HFVIS_API hfvis_status hfvis_visfield_soft_shadow_reference(
    const hfvis_visfield_object *objects, size_t object_count, const float *points,
    size_t point_count, const double light_center[3], double light_radius,
    const hfvis_visfield_shadow_options *opts, float *out)
{
    return vx_vf_shadow_run(objects, object_count, points, point_count, light_center,
                            light_radius, opts, out, 1);
}

/* Nearest object along a world ray (o, d unit) of a validated scene. */
static hfvis_status vx_vf_trace_core(const hfvis_visfield_object *objects, size_t count,
                                     const double o[3], const double d[3], double bias_frac,
                                     int reference, hfvis_visfield_trace_hit *out)
{
    size_t m;
    int a;
    out->object = HFVIS_VISFIELD_NONE;
    out->result = HFVIS_VISFIELD_MISS;
    out->distance = HUGE_VAL;
    for (a = 0; a < 3; a++) out->point[a] = out->normal[a] = 0.0;
    for (m = 0; m < count; m++) {
        vx_vf_inst in;
        hfvis_visfield_hit h;
        double dw;
        hfvis_status s;
        vx_vf_inst_make(objects + m, bias_frac, &in);
        s = vx_vf_inst_query(&in, reference, o, d, &h);
        if (s != HFVIS_OK) return s;
        if (h.result == HFVIS_VISFIELD_MISS) continue;
        dw = in.s * h.distance;
        if (!(dw < out->distance)) continue;
        out->object = m;
        out->result = h.result;
        out->distance = dw;
        for (a = 0; a < 3; a++) {
            out->point[a] = o[a] + dw * d[a];
            out->normal[a] = in.q[a] * h.normal[0] + in.q[3 + a] * h.normal[1]
                             + in.q[6 + a] * h.normal[2];
        }
    }
    return HFVIS_OK;
}

static hfvis_status vx_vf_trace_run(const hfvis_visfield_object *objects, size_t count,
                                    const double origin[3], const double direction[3],
                                    double bias_fraction, hfvis_visfield_trace_hit *hit,
                                    int reference)
{
    double d[3], bf = vx_vf_bias_frac(bias_fraction);
    hfvis_visfield_trace_hit h;
    hfvis_status s;
    if (!vx_vf_point_ok(origin) || !vx_vf_unit(direction, d) || !hit || bf < 0.0)
        return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_vf_objects_check(objects, count, reference);
    if (s != HFVIS_OK) return s;
    s = vx_vf_trace_core(objects, count, origin, d, bf, reference, &h);
    if (s != HFVIS_OK) return s;
    *hit = h;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_visfield_trace(const hfvis_visfield_object *objects,
                                            size_t object_count, const double origin[3],
                                            const double direction[3], double bias_fraction,
                                            hfvis_visfield_trace_hit *hit)
{
    return vx_vf_trace_run(objects, object_count, origin, direction, bias_fraction, hit, 0);
}

HFVIS_API hfvis_status hfvis_visfield_trace_reference(const hfvis_visfield_object *objects,
                                                      size_t object_count,
                                                      const double origin[3],
                                                      const double direction[3],
                                                      double bias_fraction,
                                                      hfvis_visfield_trace_hit *hit)
{
    return vx_vf_trace_run(objects, object_count, origin, direction, bias_fraction, hit, 1);
}

/* Direction of reflection ray i of N about the mirror direction r (frame t, b). */
static void vx_vf_lobe_dir(int i, int N, double shin, const double r[3], const double t[3],
                           const double b[3], double d[3])
{
    int a;
    if (shin > 0.0) {
        double c = pow(((double)i + 0.5) / (double)N, 1.0 / (shin + 1.0));
        double sn = sqrt(c < 1.0 ? 1.0 - c * c : 0.0);
        double ph = 2.0 * HFVIS__PI * vx_vf_radical2((uint32_t)i);
        for (a = 0; a < 3; a++) d[a] = sn * cos(ph) * t[a] + sn * sin(ph) * b[a] + c * r[a];
    } else {
        for (a = 0; a < 3; a++) d[a] = r[a];
    }
}

static hfvis_status vx_vf_reflect_run(const hfvis_visfield_object *objects, size_t count,
                                      const double point[3], const double normal[3],
                                      const double incoming[3],
                                      const hfvis_visfield_reflect_options *opts,
                                      hfvis_visfield_trace_hit *hits, int reference)
{
    int N = opts && opts->rays ? opts->rays : VX_VF_DEFAULT_REFLECT_RAYS, i, a, pass;
    double shin = opts ? opts->shininess : 0.0, off = opts ? opts->offset : 0.0;
    double bf = vx_vf_bias_frac(opts ? opts->bias : 0.0), n[3], v[3], r[3], t[3], b[3], x[3], vn;
    hfvis_status s;
    if (N < 1 || N > HFVIS_VISFIELD_MAX_SAMPLES || !isfinite(shin) || shin < 0.0 || bf < 0.0
        || !isfinite(off) || off < 0.0 || !vx_vf_point_ok(point) || !vx_vf_unit(normal, n)
        || !vx_vf_unit(incoming, v) || !hits)
        return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_vf_objects_check(objects, count, reference);
    if (s != HFVIS_OK) return s;
    vn = v[0] * n[0] + v[1] * n[1] + v[2] * n[2];
    for (a = 0; a < 3; a++) {
        r[a] = v[a] - 2.0 * vn * n[a];
        x[a] = point[a] + off * n[a];
    }
    if (!vx_vf_unit(r, r)) return HFVIS_ERR_INVALID_ARGUMENT;
    hfvis_visfield_frame(r, t, b);
    /* The reference's ray queries can fail (a corrupt bvh): it traces every ray once before
     * writing anything, so that hits stay untouched on error. */
    for (pass = reference ? 0 : 1; pass < 2; pass++)
        for (i = 0; i < N; i++) {
            double d[3];
            hfvis_visfield_trace_hit h;
            vx_vf_lobe_dir(i, N, shin, r, t, b, d);
            if (!(d[0] * n[0] + d[1] * n[1] + d[2] * n[2] > 0.0)) { /* below the surface */
                h.object = HFVIS_VISFIELD_NONE;
                h.result = HFVIS_VISFIELD_MISS;
                h.distance = HUGE_VAL;
                for (a = 0; a < 3; a++) h.point[a] = h.normal[a] = 0.0;
            } else {
                s = vx_vf_trace_core(objects, count, x, d, bf, reference, &h);
                if (s != HFVIS_OK) return s;
            }
            if (pass == 1) hits[i] = h;
        }
    return HFVIS_OK;
}

HFVIS_API hfvis_visfield_reflect_options hfvis_visfield_reflect_options_default(void)
{
    hfvis_visfield_reflect_options o;
    memset(&o, 0, sizeof o);
    o.rays = VX_VF_DEFAULT_REFLECT_RAYS;
    o.shininess = 0.0; /* a perfect mirror */
    o.bias = HFVIS_VISFIELD_DEFAULT_BIAS;
    o.offset = 0.0;
    return o;
}

HFVIS_API hfvis_status hfvis_visfield_reflect(const hfvis_visfield_object *objects,
                                              size_t object_count, const double point[3],
                                              const double normal[3], const double incoming[3],
                                              const hfvis_visfield_reflect_options *opts,
                                              hfvis_visfield_trace_hit *hits)
{
    return vx_vf_reflect_run(objects, object_count, point, normal, incoming, opts, hits, 0);
}

HFVIS_API hfvis_status hfvis_visfield_reflect_reference(const hfvis_visfield_object *objects,
                                                        size_t object_count,
                                                        const double point[3],
                                                        const double normal[3],
                                                        const double incoming[3],
                                                        const hfvis_visfield_reflect_options *opts,
                                                        hfvis_visfield_trace_hit *hits)
{
    return vx_vf_reflect_run(objects, object_count, point, normal, incoming, opts, hits, 1);
}

/* ---- vf-g. the field file ---------------------------------------------------------------- */

static const unsigned char vx_vf_magic[8] = {'H', 'F', 'V', 'F', 'I', 'E', 'L', 'D'};

static void vx_vf_put32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)(v & 0xffu);
    p[1] = (unsigned char)((v >> 8) & 0xffu);
    p[2] = (unsigned char)((v >> 16) & 0xffu);
    p[3] = (unsigned char)((v >> 24) & 0xffu);
}

static void vx_vf_put64(unsigned char *p, uint64_t v)
{
    vx_vf_put32(p, (uint32_t)(v & 0xffffffffu));
    vx_vf_put32(p + 4, (uint32_t)(v >> 32));
}

static void vx_vf_putf64(unsigned char *p, double d)
{
    uint64_t v;
    memcpy(&v, &d, 8);
    vx_vf_put64(p, v);
}

static uint32_t vx_vf_get32(const unsigned char *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

static uint64_t vx_vf_get64(const unsigned char *p)
{
    return (uint64_t)vx_vf_get32(p) | ((uint64_t)vx_vf_get32(p + 4) << 32);
}

static double vx_vf_getf64(const unsigned char *p)
{
    uint64_t v = vx_vf_get64(p);
    double d;
    memcpy(&d, &v, 8);
    return d;
}

HFVIS_API size_t hfvis_visfield_encode_size(const hfvis_visfield *vf)
{
    size_t need;
    if (!vx_vf_valid(vf)) return 0;
    need = hfvis_visfield_size(vf->positions_n, vf->dir_res, vf->format);
    if (need > SIZE_MAX - HFVIS_VISFIELD_FILE_HEADER) return 0;
    return need + HFVIS_VISFIELD_FILE_HEADER;
}

HFVIS_API hfvis_status hfvis_visfield_encode(const hfvis_visfield *vf, void *out,
                                             size_t out_capacity, size_t *written)
{
    unsigned char *p = (unsigned char *)out;
    const unsigned char *src;
    size_t total = hfvis_visfield_encode_size(vf), payload, i;
    hfvis_visfield_format f;
    if (!vf || !out || total == 0) return HFVIS_ERR_INVALID_ARGUMENT;
    if (out_capacity < total) return HFVIS_ERR_BUFFER_TOO_SMALL;
    payload = total - HFVIS_VISFIELD_FILE_HEADER;
    f = vx_vf_format(vf->format);
    memcpy(p, vx_vf_magic, 8);
    vx_vf_put32(p + 8, 1u);
    vx_vf_put32(p + 12, (uint32_t)f);
    vx_vf_put32(p + 16, (uint32_t)vx_vf_mapping(vf->mapping));
    vx_vf_put32(p + 20, (uint32_t)vf->positions_n);
    vx_vf_put32(p + 24, (uint32_t)vf->dir_res);
    vx_vf_put32(p + 28, 0u);
    vx_vf_putf64(p + 32, vf->center[0]);
    vx_vf_putf64(p + 40, vf->center[1]);
    vx_vf_putf64(p + 48, vf->center[2]);
    vx_vf_putf64(p + 56, vf->radius);
    vx_vf_putf64(p + 64, vf->avg_distance);
    vx_vf_put64(p + 72, (uint64_t)payload);
    p += HFVIS_VISFIELD_FILE_HEADER;
    src = (const unsigned char *)vf->maps;
    if (f == HFVIS_VISFIELD_F32) {
        for (i = 0; i < payload; i += 4) {
            uint32_t v;
            memcpy(&v, src + i, 4);
            vx_vf_put32(p + i, v);
        }
    } else {
        memcpy(p, src, payload);
    }
    if (written) *written = total;
    return HFVIS_OK;
}

/* Payload contents a build can produce (file byte order for F32). */
static int vx_vf_payload_ok(const unsigned char *pl, hfvis_visfield_format f, hfvis_dirmap m,
                            int n, int D, size_t bytes)
{
    const size_t K = 2u * vx_vf_hemi(n), DD = (size_t)D * (size_t)D, texels = K * DD;
    size_t t, k;
    int i, j;
    if (f == HFVIS_VISFIELD_F32) {
        for (t = 0; t < texels; t++) {
            uint32_t v = vx_vf_get32(pl + 4 * t);
            float x;
            memcpy(&x, &v, 4);
            if (!(x >= 0.0f && x <= 1.0f)) return 0; /* NaN, negative, > 1 */
        }
    } else if (f == HFVIS_VISFIELD_NORMAL) {
        for (t = 0; t < texels; t++) {
            const unsigned char *q = pl + 4 * t;
            if (q[3] == HFVIS_VISFIELD_U8_MISS && (q[0] | q[1] | q[2]) != 0) return 0;
        }
    } else if (f == HFVIS_VISFIELD_BIT && (texels & 7u) != 0) {
        if (pl[bytes - 1] >> (texels & 7u)) return 0; /* padding bits */
    }
    if (m != HFVIS_DIRMAP_REJECTION) return 1;
    for (j = 0; j < D; j++)
        for (i = 0; i < D; i++) {
            double A = vx_vf_sq(i, D), B = vx_vf_sq(j, D);
            if (A * A + B * B <= 1.0) continue;
            for (k = 0; k < K; k++) {
                size_t tt = k * DD + (size_t)j * (size_t)D + (size_t)i;
                int miss;
                switch (f) {
                case HFVIS_VISFIELD_F32: miss = vx_vf_get32(pl + 4 * tt) == 0x3f800000u; break;
                case HFVIS_VISFIELD_BIT: miss = !((pl[tt >> 3] >> (tt & 7u)) & 1u); break;
                case HFVIS_VISFIELD_NORMAL: miss = pl[4 * tt + 3] == HFVIS_VISFIELD_U8_MISS; break;
                default: miss = pl[tt] == HFVIS_VISFIELD_U8_MISS; break;
                }
                if (!miss) return 0;
            }
        }
    return 1;
}

HFVIS_API hfvis_status hfvis_visfield_decode(const void *data, size_t size,
                                             const hfvis_allocator *alloc, hfvis_visfield *out)
{
    const unsigned char *p = (const unsigned char *)data;
    uint32_t version, fmt, map, n, D;
    uint64_t payload, want;
    hfvis_visfield vf;
    unsigned char *maps;
    size_t i;
    if (!out || (!data && size > 0)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (size < HFVIS_VISFIELD_FILE_HEADER || memcmp(p, vx_vf_magic, 8) != 0)
        return HFVIS_ERR_FORMAT;
    version = vx_vf_get32(p + 8);
    fmt = vx_vf_get32(p + 12);
    map = vx_vf_get32(p + 16);
    n = vx_vf_get32(p + 20);
    D = vx_vf_get32(p + 24);
    if (version != 1u || vx_vf_get32(p + 28) != 0u || fmt < 1u || fmt > 4u || map < 1u || map > 3u
        || n == 0u || D == 0u)
        return HFVIS_ERR_FORMAT;
    if (n > (uint32_t)HFVIS_VISFIELD_MAX_N || D > (uint32_t)HFVIS_VISFIELD_MAX_DIR_RES)
        return HFVIS_ERR_LIMIT;
    want = vx_vf_size64((int)n, (int)D, (hfvis_visfield_format)fmt);
    if (want > HFVIS_VISFIELD_MAX_BYTES || want > (uint64_t)SIZE_MAX - HFVIS_VISFIELD_FILE_HEADER)
        return HFVIS_ERR_LIMIT;
    payload = vx_vf_get64(p + 72);
    if (payload != want || (uint64_t)(size - HFVIS_VISFIELD_FILE_HEADER) != want)
        return HFVIS_ERR_FORMAT;
    memset(&vf, 0, sizeof vf);
    vf.center[0] = vx_vf_getf64(p + 32);
    vf.center[1] = vx_vf_getf64(p + 40);
    vf.center[2] = vx_vf_getf64(p + 48);
    vf.radius = vx_vf_getf64(p + 56);
    vf.avg_distance = vx_vf_getf64(p + 64);
    vf.positions_n = (int)n;
    vf.dir_res = (int)D;
    vf.format = (hfvis_visfield_format)fmt;
    vf.mapping = (hfvis_dirmap)map;
    if (!vx_vf_params_ok(&vf)) return HFVIS_ERR_FORMAT;
    p += HFVIS_VISFIELD_FILE_HEADER;
    if (!vx_vf_payload_ok(p, vf.format, vf.mapping, vf.positions_n, vf.dir_res, (size_t)want))
        return HFVIS_ERR_FORMAT;
    maps = (unsigned char *)hfvis__alloc(alloc, (size_t)want);
    if (!maps) return HFVIS_ERR_OUT_OF_MEMORY;
    if (vf.format == HFVIS_VISFIELD_F32) {
        for (i = 0; i < (size_t)want; i += 4) {
            uint32_t v = vx_vf_get32(p + i);
            memcpy(maps + i, &v, 4);
        }
    } else {
        memcpy(maps, p, (size_t)want);
    }
    vf.maps = maps;
    vf.maps_size = (size_t)want;
    *out = vf;
    return HFVIS_OK;
}

HFVIS_API void hfvis_visfield_free(const hfvis_allocator *alloc, hfvis_visfield *vf)
{
    if (!vf) return;
    hfvis__free(alloc, vf->maps);
    memset(vf, 0, sizeof *vf);
}

#ifndef HFVIS_NO_STDIO
HFVIS_API hfvis_status hfvis_visfield_save(const char *path, const hfvis_visfield *vf)
{
    size_t need = hfvis_visfield_encode_size(vf), written = 0;
    unsigned char *buf;
    hfvis_status s;
    if (!path || need == 0) return HFVIS_ERR_INVALID_ARGUMENT;
    buf = (unsigned char *)hfvis__alloc(NULL, need);
    if (!buf) return HFVIS_ERR_OUT_OF_MEMORY;
    s = hfvis_visfield_encode(vf, buf, need, &written);
    if (s == HFVIS_OK) s = hfvis_write_file(path, buf, written, NULL);
    hfvis__free(NULL, buf);
    return s;
}

/* The field file's sizer (hfvis__read_file): the 80-byte header's magic and payload size. */
static hfvis_status vx_vf_sizer(const unsigned char *head, size_t n, size_t *total)
{
    uint64_t payload;
    if (n < HFVIS_VISFIELD_FILE_HEADER || memcmp(head, vx_vf_magic, 8) != 0) return HFVIS_ERR_FORMAT;
    payload = vx_vf_get64(head + 72);
    if (payload > HFVIS_VISFIELD_MAX_BYTES || payload > (uint64_t)SIZE_MAX - HFVIS_VISFIELD_FILE_HEADER)
        return HFVIS_ERR_LIMIT;
    *total = HFVIS_VISFIELD_FILE_HEADER + (size_t)payload;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_visfield_load(const char *path, const hfvis_allocator *alloc,
                                           hfvis_visfield *out)
{
    unsigned char *data = NULL;
    size_t size = 0;
    hfvis_status s;
    if (!path || !out) return HFVIS_ERR_INVALID_ARGUMENT;
    s = hfvis__read_file(path, alloc, vx_vf_sizer, &data, &size);
    if (s != HFVIS_OK) return s;
    s = hfvis_visfield_decode(data, size, alloc, out);
    hfvis__free(alloc, data);
    return s;
}
#endif

/* ========================================================================================== */
/* 11. Volume-based VPL indirect illumination ([G12] ch. 5, "Interactive Volume-based         */
/* Indirect Illumination of Dynamic Scenes": Alg. 4, eqs. 7, 11-15; [G12] ch. 5)              */
/*   GI.1 2-band SH: basis, clamped cosine, cone ([G12] ch. 5)                                */
/*   GI.2 options, transport constants, validation                                           */
/*   GI.3 VPL injection ([G12] §5.5.1)                                                        */
/*   GI.4 one propagation step (eq. 11 with the reference kernel of [G12] ch. 5, eq. 11; docs/errata.md E59): the fast */
/*        gathering kernel, the literal reference, the energy accounting                     */
/*   GI.5 the propagation loop (multiple bounces, §5.5.2 / §5.6)                               */
/*   GI.6 final gather (eqs. 12-15, [G12] ch. 5, eq. 12-15; docs/errata.md E60)               */
/*   GI.7 lights and direct irradiance with BVH shadow rays                                   */
/*   GI.8 voxelization with direct light (Alg. 4) and the room grid                           */
/*   GI.9 the whole pipeline for a view                                                       */
/* Every choice the thesis leaves open is marked [C] and listed in hfvis.h.                   */
/* ========================================================================================== */

#define VX_GI_F 12 /* HFVIS_VOLGI_FLOATS */

/* The per-voxel tail of the fast kernel is forced inline: called out of line, its vector loads
 * of the just-stored accumulators miss store-to-load forwarding (a 2x slowdown measured). */
#define VX_GI_INLINE static HFVIS__ALWAYS_INLINE

/* ---- GI.1 2-band SH (hfvis.h conventions: real, orthonormal, no Condon-Shortley phase, index l(l+1)+m:
 *      0 = Y00, 1 = y, 2 = z, 3 = x) ------------------------------------------------------ */

/* u = d/|d| (scaled first, so no intermediate overflows); 0 for NULL, non-finite or zero d. */
static int vx_gi_unit(const double *d, double u[3])
{
    double m, x, y, z, l;
    if (!d || !isfinite(d[0]) || !isfinite(d[1]) || !isfinite(d[2])) return 0;
    m = fabs(d[0]);
    if (fabs(d[1]) > m) m = fabs(d[1]);
    if (fabs(d[2]) > m) m = fabs(d[2]);
    if (!(m > 0.0)) return 0;
    x = d[0] / m, y = d[1] / m, z = d[2] / m;
    l = sqrt(x * x + y * y + z * z);
    u[0] = x / l, u[1] = y / l, u[2] = z / l;
    return 1;
}

/* The band-1 coefficient of axis a (x -> 3, y -> 1, z -> 2). */
static const int vx_gi_band1[3] = { 3, 1, 2 };

HFVIS_API hfvis_status hfvis_volgi_sh_basis(const double dir[3], double out[4])
{
    double u[3], k;
    if (!out || !vx_gi_unit(dir, u)) return HFVIS_ERR_INVALID_ARGUMENT;
    k = sqrt(3.0 / (4.0 * HFVIS__PI));
    out[0] = 0.5 / sqrt(HFVIS__PI);
    out[1] = k * u[1], out[2] = k * u[2], out[3] = k * u[0];
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_volgi_sh_clamped_cosine(const double normal[3], double out[4])
{
    double u[3], k;
    if (!out || !vx_gi_unit(normal, u)) return HFVIS_ERR_INVALID_ARGUMENT;
    /* Int max(0, n.w) Y00 = pi/(2 sqrt pi); Int max(0, n.w) 0.4886 (n.w) = 0.4886 * 2 pi/3 */
    k = sqrt(HFVIS__PI / 3.0);
    out[0] = 0.5 * sqrt(HFVIS__PI);
    out[1] = k * u[1], out[2] = k * u[2], out[3] = k * u[0];
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_volgi_sh_cone(const double axis[3], double half_angle_rad,
                                           double out[4])
{
    double u[3], k, s;
    if (!out || !vx_gi_unit(axis, u) || !isfinite(half_angle_rad) || !(half_angle_rad > 0.0)
        || half_angle_rad > HFVIS__PI)
        return HFVIS_ERR_INVALID_ARGUMENT;
    /* Int_cone Y00 = 2 pi (1 - cos a)/(2 sqrt pi); Int_cone 0.4886 cos t = 0.4886 pi sin^2 a */
    s = sin(half_angle_rad);
    k = 0.5 * sqrt(3.0 * HFVIS__PI) * (s * s);
    out[0] = sqrt(HFVIS__PI) * (1.0 - cos(half_angle_rad));
    out[1] = k * u[1], out[2] = k * u[2], out[3] = k * u[0];
    return HFVIS_OK;
}

/* ---- GI.2 options, constants, validation ------------------------------------------------ */

HFVIS_API hfvis_volgi_options hfvis_volgi_options_default(void)
{
    hfvis_volgi_options o;
    memset(&o, 0, sizeof o);
    o.iterations = HFVIS_VOLGI_DEFAULT_ITERATIONS;
    o.resolution = HFVIS_VOLGI_DEFAULT_RESOLUTION;
    o.transfer = HFVIS_VOLGI_TRANSFER_CONE;
    o.reflection = HFVIS_VOLGI_REFLECT_MIRROR;
    o.paths = HFVIS_VOLGI_PATHS_ALL;
    o.reflectance_source = HFVIS_VOLGI_REFLECTANCE_THESIS;
    o.reflectance = (float)HFVIS_VOLGI_DEFAULT_REFLECTANCE;
    o.gather_scale = HFVIS_VOLGI_DEFAULT_GATHER_SCALE;
    o.shadow_bias = 0.0;
    return o;
}

/* Resolved options. */
typedef struct vx_gi_cfg {
    const hfvis_allocator *alloc;
    int iterations, resolution;
    hfvis_volgi_transfer transfer;
    hfvis_volgi_reflection reflection;
    hfvis_volgi_reflectance rsrc;
    hfvis_volgi_paths paths;
    double rho;           /* the constant reflectance (THESIS or CONSTANT) */
    double gather_scale;
    double shadow_bias;   /* 0: relative to the scene */
} vx_gi_cfg;

static hfvis_status vx_gi_resolve(const hfvis_volgi_options *o, vx_gi_cfg *c)
{
    hfvis_volgi_options d = hfvis_volgi_options_default();
    if (!o) o = &d;
    memset(c, 0, sizeof *c);
    c->alloc = o->alloc;
    c->iterations = o->iterations == 0 ? HFVIS_VOLGI_DEFAULT_ITERATIONS : o->iterations;
    c->resolution = o->resolution == 0 ? HFVIS_VOLGI_DEFAULT_RESOLUTION : o->resolution;
    if (c->iterations < 1 || c->iterations > HFVIS_VOLGI_MAX_ITERATIONS || c->resolution < 2
        || c->resolution > HFVIS_VOLGI_MAX_RESOLUTION)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o->transfer != HFVIS_VOLGI_TRANSFER_CONE && o->transfer != HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o->reflection != HFVIS_VOLGI_REFLECT_MIRROR && o->reflection != HFVIS_VOLGI_REFLECT_DIFFUSE)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o->paths != HFVIS_VOLGI_PATHS_ALL && o->paths != HFVIS_VOLGI_PATHS_VOID)
        return HFVIS_ERR_INVALID_ARGUMENT;
    c->transfer = o->transfer;
    c->reflection = o->reflection;
    c->paths = o->paths;
    c->rsrc = o->reflectance_source;
    switch (o->reflectance_source) {
    case HFVIS_VOLGI_REFLECTANCE_THESIS: c->rho = HFVIS_VOLGI_DEFAULT_REFLECTANCE; break;
    case HFVIS_VOLGI_REFLECTANCE_CONSTANT:
        if (!(o->reflectance >= 0.0f && o->reflectance <= 1.0f)) return HFVIS_ERR_INVALID_ARGUMENT;
        c->rho = (double)o->reflectance;
        break;
    case HFVIS_VOLGI_REFLECTANCE_ALBEDO: c->rho = 0.0; break;
    default: return HFVIS_ERR_INVALID_ARGUMENT;
    }
    if (!isfinite(o->gather_scale) || o->gather_scale < 0.0) return HFVIS_ERR_INVALID_ARGUMENT;
    c->gather_scale = o->gather_scale == 0.0 ? HFVIS_VOLGI_DEFAULT_GATHER_SCALE : o->gather_scale;
    if (!isfinite(o->shadow_bias) || o->shadow_bias < 0.0) return HFVIS_ERR_INVALID_ARGUMENT;
    c->shadow_bias = o->shadow_bias;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_volgi_options_resolve(const hfvis_volgi_options *opts,
                                                   hfvis_volgi_options *out)
{
    vx_gi_cfg c;
    hfvis_volgi_options r;
    hfvis_status s;
    if (!out) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_gi_resolve(opts, &c);
    if (s != HFVIS_OK) return s;
    memset(&r, 0, sizeof r);
    r.alloc = c.alloc;
    r.iterations = c.iterations;
    r.resolution = c.resolution;
    r.transfer = c.transfer;
    r.reflection = c.reflection;
    r.reflectance_source = c.rsrc;
    r.paths = c.paths;
    r.reflectance = c.rsrc == HFVIS_VOLGI_REFLECTANCE_ALBEDO ? (opts ? opts->reflectance : 0.0f) : (float)c.rho;
    r.gather_scale = c.gather_scale;
    r.shadow_bias = c.shadow_bias;
    *out = r;
    return HFVIS_OK;
}

/* The transport constants, for the six travel directions o in the order +x, -x, +y, -y, +z, -z:
 * Cone45(o) and CC(o) as 4-vectors (from the public helpers, so that the fast kernel and the
 * reference use the same bits), and the sparse form the fast kernel uses. */
typedef struct vx_gi_consts {
    double cone[6][4], cc[6][4];
    double a;             /* cone[d][0], sqrt(pi)(1 - cos 45) */
    double sb[6], sc[6];  /* cone[d][band1 of d's axis], cc[d][same]: +-b, +-sqrt(pi/3) */
    double c0;            /* cc[d][0], sqrt(pi)/2 */
    double ccpi[6][4];    /* cc[d][k]/pi: S_in += F ccpi[o] is eq. 11's re-expansion (F/pi) CC(o) */
    double k0, k1[6];     /* ccpi[d][0], ccpi[d][band1 of d's axis] */
    double lobe;          /* c1/c0 of a cosine lobe: 2/sqrt 3 */
    double flux;          /* 2 sqrt(pi): flux of a band = flux * c_0 */
} vx_gi_consts;

static void vx_gi_consts_init(vx_gi_consts *k)
{
    int d;
    for (d = 0; d < 6; d++) {
        double e[3] = { 0.0, 0.0, 0.0 };
        int ax = d / 2;
        e[ax] = (d & 1) ? -1.0 : 1.0;
        (void)hfvis_volgi_sh_cone(e, 0.25 * HFVIS__PI, k->cone[d]);
        (void)hfvis_volgi_sh_clamped_cosine(e, k->cc[d]);
        k->sb[d] = k->cone[d][vx_gi_band1[ax]];
        k->sc[d] = k->cc[d][vx_gi_band1[ax]];
    }
    for (d = 0; d < 6; d++) {
        int q;
        for (q = 0; q < 4; q++) k->ccpi[d][q] = k->cc[d][q] / HFVIS__PI;
        k->k1[d] = k->ccpi[d][vx_gi_band1[d / 2]];
    }
    k->a = k->cone[0][0];
    k->c0 = k->cc[0][0];
    k->k0 = k->ccpi[0][0];
    k->lobe = k->cc[0][3] / k->cc[0][0];
    k->flux = 2.0 * sqrt(HFVIS__PI);
}

/* Voxel count of a valid grid, or 0 when an SH volume of it would overflow size_t. */
static size_t vx_gi_voxels(const hfvis_volume_grid *g)
{
    size_t n = vx_grid_voxels(g), bytes;
    if (!hfvis__mul_size(n, (size_t)VX_GI_F * sizeof(double), &bytes)) return 0;
    return n;
}

/* Validate a geometry volume (O(voxels)); *n receives the voxel count. */
static hfvis_status vx_gi_geometry_check(const hfvis_volgi_geometry *g, size_t *n)
{
    size_t i, m;
    if (!g || !g->occupancy || !g->normal || !vx_grid_valid(&g->grid)) return HFVIS_ERR_INVALID_ARGUMENT;
    m = vx_gi_voxels(&g->grid);
    if (m == 0) return HFVIS_ERR_LIMIT;
    for (i = 0; i < m; i++) {
        float a = g->occupancy[i];
        if (!(a >= 0.0f && a <= 1.0f)) return HFVIS_ERR_INVALID_ARGUMENT;
    }
    for (i = 0; i < 3 * m; i++)
        if (!isfinite(g->normal[i])) return HFVIS_ERR_INVALID_ARGUMENT;
    if (g->albedo)
        for (i = 0; i < 3 * m; i++)
            if (!(g->albedo[i] >= 0.0f && g->albedo[i] <= 1.0f)) return HFVIS_ERR_INVALID_ARGUMENT;
    *n = m;
    return HFVIS_OK;
}

/* Every value finite with |v| <= HFVIS_VOLGI_MAX_VALUE. */
static int vx_gi_values_ok(const float *v, size_t count)
{
    size_t i;
    for (i = 0; i < count; i++)
        if (!(fabsf(v[i]) <= HFVIS_VOLGI_MAX_VALUE)) return 0;
    return 1;
}

/* ---- GI.3 VPL injection ----------------------------------------------------------------- */

/* Dominant axis of a vector (largest |component|, ties to the lower axis); -1 when it is 0. */
static int vx_gi_dominant(double x, double y, double z)
{
    double ax = fabs(x), ay = fabs(y), az = fabs(z);
    if (ax == 0.0 && ay == 0.0 && az == 0.0) return -1;
    if (ax >= ay && ax >= az) return 0;
    return ay >= az ? 1 : 2;
}

/* Area of the grid face perpendicular to axis a (s^2 for cubic voxels). */
static double vx_gi_face(const hfvis_volume_grid *g, int a)
{
    return g->cell[(a + 1) % 3] * g->cell[(a + 2) % 3];
}

HFVIS_API hfvis_status hfvis_volgi_inject(const hfvis_volgi_geometry *geometry,
                                          const float *radiance, float *prop)
{
    vx_gi_consts K;
    size_t n, v;
    hfvis_status s;
    if (!geometry || !radiance || !prop) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_gi_geometry_check(geometry, &n);
    if (s != HFVIS_OK) return s;
    for (v = 0; v < 3 * n; v++)
        if (!(radiance[v] >= 0.0f && radiance[v] <= HFVIS_VOLGI_MAX_VALUE))
            return HFVIS_ERR_INVALID_ARGUMENT;
    vx_gi_consts_init(&K);
    for (v = 0; v < n; v++) {
        float *p = prop + v * VX_GI_F;
        const float *nv = geometry->normal + 3 * v;
        double u[3], cc[4] = { 0.0, 0.0, 0.0, 0.0 }, area;
        int b, k, ax;
        for (k = 0; k < VX_GI_F; k++) p[k] = 0.0f;
        if (!(geometry->occupancy[v] > 0.0f)) continue;
        ax = vx_gi_dominant((double)nv[0], (double)nv[1], (double)nv[2]);
        if (ax >= 0) {
            double nd[3];
            nd[0] = (double)nv[0], nd[1] = (double)nv[1], nd[2] = (double)nv[2];
            (void)vx_gi_unit(nd, u);
            (void)hfvis_volgi_sh_clamped_cosine(u, cc);
            area = vx_gi_face(&geometry->grid, ax);
        } else { /* no normal: the isotropic lobe of the same flux, c_0 = CC's c_0 [C] */
            cc[0] = K.c0;
            area = pow(geometry->grid.cell[0] * geometry->grid.cell[1] * geometry->grid.cell[2],
                       2.0 / 3.0);
        }
        /* P0 = (Phi/pi) CC(n), Phi = pi L s^2 ([G12] ch. 5; docs/errata.md E60) */
        for (b = 0; b < 3; b++) {
            double q = (double)radiance[3 * v + (size_t)b] * area;
            for (k = 0; k < 4; k++) p[4 * b + k] = (float)(q * cc[k]);
        }
    }
    return HFVIS_OK;
}

/* ---- GI.4 one propagation step ---------------------------------------------------------- */

typedef struct vx_gi_step {
    const hfvis_volgi_geometry *g;
    vx_gi_cfg cfg;
    vx_gi_consts K;
    const float *pin;
    float *pout, *acc;
    const double *scale;          /* normalised transfer: Phi_j / sum_o F_o(j) per voxel and band */
    hfvis_volgi_energy *en;       /* NULL: no accounting */
    int dims[3];
    size_t stride[3];             /* voxel strides along x, y, z */
} vx_gi_step;

/* The clamped cone flux of band b of the SH voxel q toward direction d (sparse form: the zero
 * coefficients of Cone(o) are left out; equal to the full 4-term product whenever it is > 0). */
static double vx_gi_cone_flux(const vx_gi_consts *K, const float *q, int d)
{
    double F = K->a * (double)q[0] + K->sb[d] * (double)q[vx_gi_band1[d / 2]];
    return F > 0.0 ? F : 0.0;
}

/* 1 when the neighbour of voxel ijk in (travel) direction d exists. */
static int vx_gi_has(const int dims[3], const int ijk[3], int d)
{
    int ax = d / 2;
    return (d & 1) ? ijk[ax] > 0 : ijk[ax] + 1 < dims[ax];
}

/* Linear index of the (existing) neighbour of voxel v in direction d. */
static size_t vx_gi_nb(const vx_gi_step *c, size_t v, int d)
{
    return (d & 1) ? v - c->stride[d / 2] : v + c->stride[d / 2];
}

/* Path weight of a transfer from voxel jl to its face neighbour il: 1 (HFVIS_VOLGI_PATHS_ALL),
 * or 1 - alpha_j alpha_i (HFVIS_VOLGI_PATHS_VOID: no light between two occupied voxels). */
static double vx_gi_path(const vx_gi_step *c, size_t jl, size_t il)
{
    if (c->cfg.paths == HFVIS_VOLGI_PATHS_ALL) return 1.0;
    return 1.0 - (double)c->g->occupancy[jl] * (double)c->g->occupancy[il];
}

/* Normalised transfer: Phi / sum_o F_o w_o for band b of voxel v at ijk (clamped cone fluxes
 * times path weights, summed in the order o = 0..5; leaving the grid has weight 1), or 0 when
 * either is <= 0. */
static double vx_gi_norm_scale(const vx_gi_step *c, size_t v, const int ijk[3], int b)
{
    const float *q = c->pin + v * VX_GI_F + 4 * b;
    double sum = 0.0, phi = c->K.flux * (double)q[0];
    int d;
    for (d = 0; d < 6; d++) {
        double F = vx_gi_cone_flux(&c->K, q, d);
        if (vx_gi_has(c->dims, ijk, d)) F *= vx_gi_path(c, v, vx_gi_nb(c, v, d));
        sum += F;
    }
    return phi > 0.0 && sum > 0.0 ? phi / sum : 0.0;
}

/* The table of vx_gi_norm_scale for every voxel and band (the fast step's normalisation); the
 * same products and sums, with the six path weights computed once per voxel. */
static void vx_gi_scale_pass(const vx_gi_step *c, double *scale)
{
    int ijk[3], b, d;
    size_t v = 0;
    for (ijk[2] = 0; ijk[2] < c->dims[2]; ijk[2]++)
        for (ijk[1] = 0; ijk[1] < c->dims[1]; ijk[1]++)
            for (ijk[0] = 0; ijk[0] < c->dims[0]; ijk[0]++, v++) {
                double w[6];
                for (d = 0; d < 6; d++)
                    w[d] = vx_gi_has(c->dims, ijk, d) ? vx_gi_path(c, v, vx_gi_nb(c, v, d)) : 1.0;
                for (b = 0; b < 3; b++) {
                    const float *q = c->pin + v * VX_GI_F + 4 * b;
                    double sum = 0.0, phi = c->K.flux * (double)q[0];
                    for (d = 0; d < 6; d++) sum += vx_gi_cone_flux(&c->K, q, d) * w[d];
                    scale[3 * v + (size_t)b] = phi > 0.0 && sum > 0.0 ? phi / sum : 0.0;
                }
            }
}

/* The source side of the energy accounting (start, escaped, blocked, uncovered, created), shared
 * by the fast step and the reference: per voxel and band what it sends, what leaves the grid and
 * what the path weights hold back. */
static void vx_gi_energy_sources(const vx_gi_step *c)
{
    hfvis_volgi_energy *e = c->en;
    const int norm = c->cfg.transfer == HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED;
    int ijk[3], b, d;
    size_t v = 0;
    for (ijk[2] = 0; ijk[2] < c->dims[2]; ijk[2]++)
        for (ijk[1] = 0; ijk[1] < c->dims[1]; ijk[1]++)
            for (ijk[0] = 0; ijk[0] < c->dims[0]; ijk[0]++, v++)
                for (b = 0; b < 3; b++) {
                    const float *q = c->pin + v * VX_GI_F + 4 * b;
                    double phi = c->K.flux * (double)q[0], sent = 0.0, esc = 0.0, blk = 0.0;
                    double sc = norm ? vx_gi_norm_scale(c, v, ijk, b) : 1.0;
                    for (d = 0; d < 6; d++) {
                        double F = vx_gi_cone_flux(&c->K, q, d) * sc, w = 1.0;
                        if (vx_gi_has(c->dims, ijk, d)) w = vx_gi_path(c, v, vx_gi_nb(c, v, d));
                        else esc += F;
                        sent += F * w;
                        blk += F * (1.0 - w);
                    }
                    if (norm && phi > 0.0) { /* exact in real arithmetic: all or nothing */
                        if (sc > 0.0) sent = phi, blk = 0.0;
                        else sent = 0.0, blk = phi, esc = 0.0;
                    }
                    e->start[b] += phi;
                    e->escaped[b] += esc;
                    e->blocked[b] += blk;
                    if (phi > sent + blk) e->uncovered[b] += phi - sent - blk;
                    else e->created[b] += sent + blk - phi;
                }
}

/* R(S_in) of one band (the thesis' T_r, or the diffuse alternative), into r. */
VX_GI_INLINE void vx_gi_reflect(const vx_gi_step *c, const float *nv, const double *s, double r[4])
{
    int k, ax = vx_gi_dominant((double)nv[0], (double)nv[1], (double)nv[2]);
    if (c->cfg.reflection == HFVIS_VOLGI_REFLECT_MIRROR) {
        for (k = 0; k < 4; k++) r[k] = s[k];
        if (ax >= 0) {
            r[vx_gi_band1[ax]] = -s[vx_gi_band1[ax]]; /* mirror on the plane perpendicular to ax */
        } else {
            r[1] = -s[1], r[2] = -s[2], r[3] = -s[3]; /* no normal: back where it came from [C] */
        }
        return;
    }
    /* diffuse: c_0 kept (the flux), the band-1 part (2/sqrt 3) c_0 along +-n [C] */
    r[0] = s[0];
    r[1] = r[2] = r[3] = 0.0;
    if (ax >= 0) {
        double nd[3], u[3], side, g;
        nd[0] = (double)nv[0], nd[1] = (double)nv[1], nd[2] = (double)nv[2];
        (void)vx_gi_unit(nd, u);
        side = s[3] * u[0] + s[1] * u[1] + s[2] * u[2]; /* > 0: travelling along +n, from behind */
        g = (side > 0.0 ? -1.0 : 1.0) * (s[0] * c->K.lobe);
        r[1] = g * u[1], r[2] = g * u[2], r[3] = g * u[0];
    }
}

/* The receiving side of voxel lin, shared by the fast step and the reference: record and
 * reflect at occupied voxels (T_r), transmit through empty ones; energy end/absorbed/deposited. */
VX_GI_INLINE void vx_gi_finish(const vx_gi_step *c, size_t lin, const double s[VX_GI_F])
{
    float *po = c->pout + lin * VX_GI_F;
    double alpha = (double)c->g->occupancy[lin];
    int b, k;
    if (alpha == 0.0) { /* void: T_r = 1 */
        for (k = 0; k < VX_GI_F; k++) po[k] = (float)s[k];
    } else {
        float *pa = c->acc + lin * VX_GI_F;
        const float *nv = c->g->normal + 3 * lin;
        for (k = 0; k < VX_GI_F; k++) pa[k] = (float)((double)pa[k] + alpha * s[k]);
        for (b = 0; b < 3; b++) {
            double r[4], rho = c->cfg.rsrc == HFVIS_VOLGI_REFLECTANCE_ALBEDO
                                   ? (double)c->g->albedo[3 * lin + (size_t)b] : c->cfg.rho;
            vx_gi_reflect(c, nv, s + 4 * b, r);
            for (k = 0; k < 4; k++)
                po[4 * b + k] = (float)((1.0 - alpha) * s[4 * b + k] + alpha * (rho * r[k]));
            if (c->en) {
                double phi = c->K.flux * s[4 * b];
                c->en->absorbed[b] += alpha * (1.0 - rho) * phi;
                c->en->deposited[b] += alpha * phi;
            }
        }
    }
    if (c->en)
        for (b = 0; b < 3; b++) c->en->end[b] += c->K.flux * (double)po[4 * b];
}

/* One neighbour of the fast kernel: direction D (travel), its band-1 coefficient M (a constant,
 * so that the accumulators stay in registers), source voxel JL. Per band: F = max(0, a c_0 +
 * (+-b) c_M) (the sparse form of P_j . Cone(o)), times the path weight and the normalisation;
 * S_in += F ccpi[o] on the two non-zero coefficients of (F/pi) CC(o). The branch-free clamp adds
 * exact zeros for F = 0, so the sums equal the reference's bit for bit. */
#define VX_GI_TAKE(D, M, JL)                                                                   \
    do {                                                                                       \
        const size_t jl_ = (JL);                                                               \
        const float *q_ = pin + jl_ * VX_GI_F;                                                 \
        const double sb_ = K->sb[D], k1_ = K->k1[D];                                           \
        double w_ = 1.0, F0_, F1_, F2_;                                                        \
        if (void_only) w_ = 1.0 - (double)occ[jl_] * ai;                                        \
        if (w_ > 0.0) {                                                                        \
            F0_ = a * (double)q_[0] + sb_ * (double)q_[M];                                     \
            F1_ = a * (double)q_[4] + sb_ * (double)q_[4 + M];                                 \
            F2_ = a * (double)q_[8] + sb_ * (double)q_[8 + M];                                 \
            F0_ = (F0_ > 0.0 ? F0_ : 0.0) * w_;                                                \
            F1_ = (F1_ > 0.0 ? F1_ : 0.0) * w_;                                                \
            F2_ = (F2_ > 0.0 ? F2_ : 0.0) * w_;                                                \
            if (scale) {                                                                       \
                F0_ *= scale[3 * jl_], F1_ *= scale[3 * jl_ + 1], F2_ *= scale[3 * jl_ + 2];   \
            }                                                                                  \
            s0 += F0_ * k0, s4 += F1_ * k0, s8 += F2_ * k0;                                    \
            s[M] += F0_ * k1_, s[4 + M] += F1_ * k1_, s[8 + M] += F2_ * k1_;                   \
        }                                                                                      \
    } while (0)

/* Fast step: gathering at every voxel from its six face neighbours ([G12] Fig. 51), in the
 * order +x, -x, +y, -y, +z, -z of the reference. */
static void vx_gi_step_fast(const vx_gi_step *c)
{
    const int nx = c->dims[0], ny = c->dims[1], nz = c->dims[2];
    const int void_only = c->cfg.paths == HFVIS_VOLGI_PATHS_VOID;
    const size_t sy = c->stride[1], sz = c->stride[2];
    const vx_gi_consts *K = &c->K;
    const double a = K->a, k0 = K->k0;
    const float *occ = c->g->occupancy, *pin = c->pin;
    const double *scale = c->scale;
    int i, j, k;
    for (k = 0; k < nz; k++)
        for (j = 0; j < ny; j++) {
            const size_t row = (size_t)k * sz + (size_t)j * sy;
            for (i = 0; i < nx; i++) {
                const size_t lin = row + (size_t)i;
                const double ai = void_only ? (double)occ[lin] : 0.0;
                double s[VX_GI_F] = { 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0 };
                double s0 = 0.0, s4 = 0.0, s8 = 0.0;
                /* o = +x comes from i - 1, o = -x from i + 1, ... (j = i - o) */
                if (i > 0) VX_GI_TAKE(0, 3, lin - 1);
                if (i + 1 < nx) VX_GI_TAKE(1, 3, lin + 1);
                if (j > 0) VX_GI_TAKE(2, 1, lin - sy);
                if (j + 1 < ny) VX_GI_TAKE(3, 1, lin + sy);
                if (k > 0) VX_GI_TAKE(4, 2, lin - sz);
                if (k + 1 < nz) VX_GI_TAKE(5, 2, lin + sz);
                s[0] = s0, s[4] = s4, s[8] = s8;
                vx_gi_finish(c, lin, s);
            }
        }
}
#undef VX_GI_TAKE

/* Linear index of voxel v of grid dims. */
static size_t vx_gi_lin(const int dims[3], const int v[3])
{
    return ((size_t)v[2] * (size_t)dims[1] + (size_t)v[1]) * (size_t)dims[0] + (size_t)v[0];
}

/* Reference step: the kernel of docs/errata.md E59 literally, full 4-coefficient products, every path
 * weight and normalisation recomputed per (i, o). */
static void vx_gi_step_reference(const vx_gi_step *c)
{
    const int void_only = c->cfg.paths == HFVIS_VOLGI_PATHS_VOID;
    int ijk[3], d, b, k, e;
    size_t lin = 0;
    for (ijk[2] = 0; ijk[2] < c->dims[2]; ijk[2]++)
        for (ijk[1] = 0; ijk[1] < c->dims[1]; ijk[1]++)
            for (ijk[0] = 0; ijk[0] < c->dims[0]; ijk[0]++, lin++) {
                double s[VX_GI_F];
                for (k = 0; k < VX_GI_F; k++) s[k] = 0.0;
                for (d = 0; d < 6; d++) {             /* o = travel direction j -> i */
                    int jj[3];
                    size_t jlin;
                    const float *P;
                    double w;
                    jj[0] = ijk[0], jj[1] = ijk[1], jj[2] = ijk[2];
                    jj[d / 2] += (d & 1) ? 1 : -1;    /* j = i - o */
                    if (jj[d / 2] < 0 || jj[d / 2] >= c->dims[d / 2]) continue;
                    jlin = vx_gi_lin(c->dims, jj);
                    P = c->pin + jlin * VX_GI_F;
                    w = void_only ? 1.0 - (double)c->g->occupancy[jlin] * (double)c->g->occupancy[lin] : 1.0;
                    for (b = 0; b < 3; b++) {
                        double F = 0.0;
                        for (k = 0; k < 4; k++) F += (double)P[4 * b + k] * c->K.cone[d][k];
                        F = F > 0.0 ? F : 0.0;
                        F *= w;
                        if (c->cfg.transfer == HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED) {
                            /* all six weighted cone fluxes of j, recomputed */
                            double sum = 0.0, phi = c->K.flux * (double)P[4 * b];
                            for (e = 0; e < 6; e++) {
                                double G = 0.0;
                                int nn[3];
                                for (k = 0; k < 4; k++) G += (double)P[4 * b + k] * c->K.cone[e][k];
                                G = G > 0.0 ? G : 0.0;
                                nn[0] = jj[0], nn[1] = jj[1], nn[2] = jj[2];
                                nn[e / 2] += (e & 1) ? -1 : 1; /* j + o_e */
                                if (void_only && nn[e / 2] >= 0 && nn[e / 2] < c->dims[e / 2])
                                    G *= 1.0 - (double)c->g->occupancy[jlin]
                                                   * (double)c->g->occupancy[vx_gi_lin(c->dims, nn)];
                                sum += G;
                            }
                            F *= phi > 0.0 && sum > 0.0 ? phi / sum : 0.0;
                        }
                        for (k = 0; k < 4; k++) s[4 * b + k] += F * c->K.ccpi[d][k]; /* (F/pi) CC(o) */
                    }
                }
                vx_gi_finish(c, lin, s);
            }
}

/* Set up a step context (inputs validated by the caller). */
static void vx_gi_step_init(vx_gi_step *c, const hfvis_volgi_geometry *g, const vx_gi_cfg *cfg,
                            const float *pin, float *pout, float *acc, const double *scale,
                            hfvis_volgi_energy *en)
{
    memset(c, 0, sizeof *c);
    c->g = g;
    c->cfg = *cfg;
    vx_gi_consts_init(&c->K);
    c->pin = pin, c->pout = pout, c->acc = acc, c->scale = scale, c->en = en;
    c->dims[0] = g->grid.dims[0], c->dims[1] = g->grid.dims[1], c->dims[2] = g->grid.dims[2];
    c->stride[0] = 1;
    c->stride[1] = (size_t)c->dims[0];
    c->stride[2] = (size_t)c->dims[0] * (size_t)c->dims[1];
}

/* Validation shared by the step entry points and the loop. */
static hfvis_status vx_gi_transport_check(const hfvis_volgi_geometry *g, const hfvis_volgi_options *o,
                                          const float *pin, const float *acc, vx_gi_cfg *cfg,
                                          size_t *n)
{
    hfvis_status s;
    if (!g || !pin || !acc) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_gi_resolve(o, cfg);
    if (s != HFVIS_OK) return s;
    if (cfg->rsrc == HFVIS_VOLGI_REFLECTANCE_ALBEDO && !g->albedo) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_gi_geometry_check(g, n);
    if (s != HFVIS_OK) return s;
    if (!vx_gi_values_ok(pin, *n * VX_GI_F) || !vx_gi_values_ok(acc, *n * VX_GI_F))
        return HFVIS_ERR_INVALID_ARGUMENT;
    return HFVIS_OK;
}

static hfvis_status vx_gi_step_entry(const hfvis_volgi_geometry *g, const hfvis_volgi_options *o,
                                     const float *pin, float *pout, float *acc,
                                     hfvis_volgi_energy *energy, int reference)
{
    vx_gi_cfg cfg;
    vx_gi_step c;
    hfvis_volgi_energy en;
    double *scale = NULL;
    size_t n;
    hfvis_status s;
    if (!pout) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_gi_transport_check(g, o, pin, acc, &cfg, &n);
    if (s != HFVIS_OK) return s;
    if (cfg.transfer == HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED && !reference) {
        scale = (double *)hfvis__alloc_array(cfg.alloc, n, 3 * sizeof(double));
        if (!scale) return HFVIS_ERR_OUT_OF_MEMORY;
    }
    memset(&en, 0, sizeof en);
    vx_gi_step_init(&c, g, &cfg, pin, pout, acc, NULL, energy ? &en : NULL);
    if (scale) {
        vx_gi_scale_pass(&c, scale);
        c.scale = scale;
    }
    if (energy) vx_gi_energy_sources(&c);
    if (reference) vx_gi_step_reference(&c);
    else vx_gi_step_fast(&c);
    hfvis__free(cfg.alloc, scale);
    if (energy) *energy = en;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_volgi_propagate_step(const hfvis_volgi_geometry *geometry,
                                                  const hfvis_volgi_options *opts,
                                                  const float *prop_in, float *prop_out,
                                                  float *accum, hfvis_volgi_energy *energy)
{
    return vx_gi_step_entry(geometry, opts, prop_in, prop_out, accum, energy, 0);
}

HFVIS_API hfvis_status hfvis_volgi_propagate_step_reference(const hfvis_volgi_geometry *geometry,
                                                            const hfvis_volgi_options *opts,
                                                            const float *prop_in, float *prop_out,
                                                            float *accum,
                                                            hfvis_volgi_energy *energy)
{
    return vx_gi_step_entry(geometry, opts, prop_in, prop_out, accum, energy, 1);
}

/* ---- GI.5 the propagation loop ---------------------------------------------------------- */

/* The loop on validated inputs; scratch: n*12 floats, then n*3 doubles for the normalised
 * transfer (one block). */
static void vx_gi_propagate_run(const hfvis_volgi_geometry *g, const vx_gi_cfg *cfg, int iterations,
                                float *prop, float *accum, hfvis_volgi_energy *energy, float *tmp,
                                double *scale, size_t n)
{
    float *cur = prop, *nxt = tmp;
    int t;
    for (t = 0; t < iterations; t++) {
        vx_gi_step c;
        float *sw;
        if (energy) memset(&energy[t], 0, sizeof energy[t]);
        vx_gi_step_init(&c, g, cfg, cur, nxt, accum, NULL, energy ? &energy[t] : NULL);
        if (scale) {
            vx_gi_scale_pass(&c, scale);
            c.scale = scale;
        }
        if (energy) vx_gi_energy_sources(&c);
        vx_gi_step_fast(&c);
        sw = cur, cur = nxt, nxt = sw;
    }
    if (cur != prop) memcpy(prop, cur, n * VX_GI_F * sizeof(float));
}

/* Scratch bytes of the loop: 12 floats per voxel (+ 3 doubles, normalised). 0 on overflow. */
static size_t vx_gi_loop_scratch(const vx_gi_cfg *cfg, size_t n, size_t *scale_off)
{
    size_t a, b = 0;
    if (!hfvis__mul_size(n, VX_GI_F * sizeof(float), &a)) return 0;
    a = (a + sizeof(double) - 1) / sizeof(double) * sizeof(double);
    *scale_off = a;
    if (cfg->transfer == HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED
        && (!hfvis__mul_size(n, 3 * sizeof(double), &b) || b > SIZE_MAX - a))
        return 0;
    return a + b;
}

HFVIS_API hfvis_status hfvis_volgi_propagate(const hfvis_volgi_geometry *geometry,
                                             const hfvis_volgi_options *opts, int iterations,
                                             float *prop, float *accum,
                                             hfvis_volgi_energy *energy)
{
    vx_gi_cfg cfg;
    size_t n, bytes, off;
    unsigned char *block;
    hfvis_status s;
    if (!prop || iterations < 0 || iterations > HFVIS_VOLGI_MAX_ITERATIONS)
        return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_gi_transport_check(geometry, opts, prop, accum, &cfg, &n);
    if (s != HFVIS_OK) return s;
    if (iterations == 0) return HFVIS_OK;
    bytes = vx_gi_loop_scratch(&cfg, n, &off);
    if (bytes == 0) return HFVIS_ERR_LIMIT;
    block = (unsigned char *)hfvis__alloc(cfg.alloc, bytes);
    if (!block) return HFVIS_ERR_OUT_OF_MEMORY;
    vx_gi_propagate_run(geometry, &cfg, iterations, prop, accum, energy, (float *)(void *)block,
                        cfg.transfer == HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED
                            ? (double *)(void *)(block + off) : NULL, n);
    hfvis__free(cfg.alloc, block);
    return HFVIS_OK;
}

/* ---- GI.6 final gather ------------------------------------------------------------------ */

/* Eqs. 12-15 on validated inputs ([G12] ch. 5, eq. 12-15; docs/errata.md E60); n need not be unit (a zero n gives 0). */
static void vx_gi_gather_point(const hfvis_volgi_geometry *g, const float *accum, double kappa,
                               const double p[3], const double n[3], double E[3])
{
    double gg[3], f[3], L[VX_GI_F], wsum = 0.0, u[3], m[3], cc[4], area;
    int b0[3], c, a, k, b, ax;
    E[0] = E[1] = E[2] = 0.0;
    ax = vx_gi_dominant(n[0], n[1], n[2]);
    if (ax < 0 || !vx_gi_unit(n, u)) return;
    for (a = 0; a < 3; a++) {
        gg[a] = (p[a] - g->grid.origin[a]) / g->grid.cell[a] - 0.5;
        if (!(gg[a] > -2.0 && gg[a] < (double)g->grid.dims[a] + 1.0)) return; /* no voxel near */
        b0[a] = (int)floor(gg[a]);
        f[a] = gg[a] - (double)b0[a];
    }
    for (k = 0; k < VX_GI_F; k++) L[k] = 0.0;
    for (c = 0; c < 8; c++) {
        int v[3];
        double w = 1.0;
        size_t lin;
        for (a = 0; a < 3; a++) {
            int bit = (c >> a) & 1;
            v[a] = b0[a] + bit;
            w *= bit ? f[a] : 1.0 - f[a];
        }
        if (v[0] < 0 || v[1] < 0 || v[2] < 0 || v[0] >= g->grid.dims[0] || v[1] >= g->grid.dims[1]
            || v[2] >= g->grid.dims[2])
            continue;
        lin = ((size_t)v[2] * (size_t)g->grid.dims[1] + (size_t)v[1]) * (size_t)g->grid.dims[0]
              + (size_t)v[0];
        if (!(g->occupancy[lin] > 0.0f)) continue; /* only occupied voxels ([G12] §5.5.3) */
        for (k = 0; k < VX_GI_F; k++) L[k] += w * (double)accum[lin * VX_GI_F + (size_t)k];
        wsum += w;
    }
    if (!(wsum > 0.0)) return;
    /* A is indexed by travel direction: light reaching the surface travels along -n */
    m[0] = -u[0], m[1] = -u[1], m[2] = -u[2];
    (void)hfvis_volgi_sh_clamped_cosine(m, cc);
    area = vx_gi_face(&g->grid, ax);
    for (b = 0; b < 3; b++) {
        double d = 0.0;
        for (k = 0; k < 4; k++) d += (L[4 * b + k] / wsum) * cc[k]; /* eq. 7: a dot product */
        E[b] = d > 0.0 ? kappa * d / area : 0.0;
    }
}

HFVIS_API hfvis_status hfvis_volgi_gather(const hfvis_volgi_geometry *geometry,
                                          const float *accum, const hfvis_volgi_options *opts,
                                          const double point[3], const double normal[3],
                                          float irradiance[3])
{
    vx_gi_cfg cfg;
    double u[3], E[3];
    hfvis_status s;
    if (!geometry || !accum || !point || !normal || !irradiance || !geometry->occupancy
        || !geometry->normal || !vx_grid_valid(&geometry->grid) || !vx_gi_unit(normal, u)
        || !isfinite(point[0]) || !isfinite(point[1]) || !isfinite(point[2]))
        return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_gi_resolve(opts, &cfg);
    if (s != HFVIS_OK) return s;
    vx_gi_gather_point(geometry, accum, cfg.gather_scale, point, u, E);
    irradiance[0] = (float)E[0], irradiance[1] = (float)E[1], irradiance[2] = (float)E[2];
    return HFVIS_OK;
}

/* ---- GI.7 lights and direct irradiance ------------------------------------------------- */

#define VX_GI_MAX_COORD 1e30 /* light positions and receivers: far inside float range */

static int vx_gi_vec_ok(const double *v, int nonzero)
{
    int a;
    for (a = 0; a < 3; a++)
        if (!(fabs(v[a]) <= VX_GI_MAX_COORD)) return 0;
    return !nonzero || v[0] != 0.0 || v[1] != 0.0 || v[2] != 0.0;
}

static int vx_gi_light_ok(const hfvis_volgi_light *L)
{
    int b;
    for (b = 0; b < 3; b++)
        if (!(L->intensity[b] >= 0.0f && L->intensity[b] <= FLT_MAX)) return 0;
    switch (L->type) {
    case HFVIS_VOLGI_LIGHT_POINT: return vx_gi_vec_ok(L->position, 0);
    case HFVIS_VOLGI_LIGHT_SPOT:
        return vx_gi_vec_ok(L->position, 0) && vx_gi_vec_ok(L->direction, 1)
               && L->spot_inner_rad >= 0.0 && L->spot_inner_rad <= L->spot_outer_rad
               && L->spot_outer_rad > 0.0 && L->spot_outer_rad <= HFVIS__PI;
    case HFVIS_VOLGI_LIGHT_DIRECTIONAL: return vx_gi_vec_ok(L->direction, 1);
    }
    return 0;
}

/* Shadow rays ignore the receiver's own triangle. */
static int vx_gi_skip_filter(void *user, const hfvis_ray *ray, const hfvis_hit *candidate)
{
    (void)ray;
    return candidate->triangle != *(const uint32_t *)user;
}

/* The default shadow bias: 1e-5 times the diagonal of the BVH's root box (0 without nodes). */
static double vx_gi_bias(const vx_gi_cfg *cfg, const hfvis_bvh *bvh)
{
    double d2 = 0.0;
    int a;
    if (cfg->shadow_bias > 0.0) return cfg->shadow_bias;
    if (bvh->node_count == 0) return 0.0;
    for (a = 0; a < 3; a++) {
        double e = (double)bvh->nodes[0].hi[a] - (double)bvh->nodes[0].lo[a];
        d2 += e * e;
    }
    return 1e-5 * sqrt(d2);
}

/* Direct irradiance on validated inputs (n unit). */
static void vx_gi_direct(const hfvis_volgi_scene *sc, const hfvis_bvh *bvh, double bias,
                         const double p[3], const double n[3], uint32_t skip, double E[3])
{
    int l, b;
    E[0] = E[1] = E[2] = 0.0;
    for (l = 0; l < sc->light_count; l++) {
        const hfvis_volgi_light *L = &sc->lights[l];
        double dir[3], w = 1.0, cosn;
        hfvis_ray ray;
        hfvis_hit hit;
        int a;
        if (L->type == HFVIS_VOLGI_LIGHT_DIRECTIONAL) {
            double u[3];
            (void)vx_gi_unit(L->direction, u);
            dir[0] = -u[0], dir[1] = -u[1], dir[2] = -u[2];
            cosn = n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2];
            if (!(cosn > 0.0)) continue;
            for (a = 0; a < 3; a++) ray.direction[a] = (float)dir[a];
            ray.t_min = (float)bias;
            ray.t_max = (float)INFINITY;
        } else {
            double d[3], dist;
            for (a = 0; a < 3; a++) d[a] = L->position[a] - p[a];
            dist = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            if (!(dist > 2.0 * bias) || !(dist > 0.0)) continue; /* receiver at the light */
            for (a = 0; a < 3; a++) dir[a] = d[a] / dist;
            cosn = n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2];
            if (!(cosn > 0.0)) continue;
            if (L->type == HFVIS_VOLGI_LIGHT_SPOT) {
                double u[3], ct, ci = cos(L->spot_inner_rad), co = cos(L->spot_outer_rad);
                (void)vx_gi_unit(L->direction, u);
                ct = -(dir[0] * u[0] + dir[1] * u[1] + dir[2] * u[2]); /* cos(axis, light->p) */
                if (ct >= ci) w = 1.0;
                else if (ct <= co || ci == co) w = 0.0;
                else w = (ct - co) / (ci - co);
                if (!(w > 0.0)) continue;
            }
            w /= dist * dist;
            for (a = 0; a < 3; a++) ray.direction[a] = (float)d[a];
            ray.t_min = (float)(bias / dist);
            ray.t_max = (float)(1.0 - bias / dist);
        }
        if (bvh->node_count > 0) {
            uint32_t skip_tri = skip;
            hfvis_status st;
            for (a = 0; a < 3; a++) ray.origin[a] = (float)p[a];
            ray.cull = HFVIS_CULL_NONE;
            st = hfvis_bvh_intersect(bvh, sc->mesh, &ray, HFVIS_RAY_ANY, vx_gi_skip_filter,
                                     &skip_tri, &hit);
            HFVIS_ASSERT(st == HFVIS_OK);
            if (st == HFVIS_OK && hit.triangle != HFVIS_NO_TRIANGLE) continue; /* in shadow */
        }
        for (b = 0; b < 3; b++) E[b] += (double)L->intensity[b] * w * cosn;
    }
}

/* Scene checks: mesh, materials, lights, the BVH's triangle count. */
static hfvis_status vx_gi_scene_check(const hfvis_volgi_scene *sc)
{
    size_t i, t3;
    int l;
    if (!sc || !sc->mesh) return HFVIS_ERR_INVALID_ARGUMENT;
    if (sc->mesh->triangle_count > HFVIS_BVH_MAX_TRIANGLES) return HFVIS_ERR_LIMIT;
    if (hfvis__mesh_check(sc->mesh) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    if (sc->light_count < 0 || sc->light_count > HFVIS_VOLGI_MAX_LIGHTS
        || (sc->light_count > 0 && !sc->lights))
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (l = 0; l < sc->light_count; l++)
        if (!vx_gi_light_ok(&sc->lights[l])) return HFVIS_ERR_INVALID_ARGUMENT;
    t3 = 3 * sc->mesh->triangle_count;
    if (sc->albedo)
        for (i = 0; i < t3; i++)
            if (!(sc->albedo[i] >= 0.0f && sc->albedo[i] <= 1.0f)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (sc->emission)
        for (i = 0; i < t3; i++)
            if (!(sc->emission[i] >= 0.0f && sc->emission[i] <= HFVIS_VOLGI_MAX_VALUE))
                return HFVIS_ERR_INVALID_ARGUMENT;
    if (sc->bvh && sc->bvh->triangle_count != sc->mesh->triangle_count) return HFVIS_ERR_INVALID_ARGUMENT;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_volgi_direct_irradiance(const hfvis_volgi_scene *scene,
                                                     const hfvis_volgi_options *opts,
                                                     const double point[3],
                                                     const double normal[3],
                                                     uint32_t skip_triangle, float irradiance[3])
{
    vx_gi_cfg cfg;
    double u[3], E[3];
    int l;
    hfvis_status s;
    if (!scene || !scene->mesh || !scene->bvh || !point || !normal || !irradiance
        || !vx_gi_vec_ok(point, 0) || !vx_gi_unit(normal, u)
        || scene->bvh->triangle_count != scene->mesh->triangle_count
        || (scene->bvh->node_count > 0 && !scene->bvh->nodes)
        || scene->light_count < 0 || scene->light_count > HFVIS_VOLGI_MAX_LIGHTS
        || (scene->light_count > 0 && !scene->lights))
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (l = 0; l < scene->light_count; l++)
        if (!vx_gi_light_ok(&scene->lights[l])) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_gi_resolve(opts, &cfg);
    if (s != HFVIS_OK) return s;
    vx_gi_direct(scene, scene->bvh, vx_gi_bias(&cfg, scene->bvh), point, u, skip_triangle, E);
    irradiance[0] = (float)E[0], irradiance[1] = (float)E[1], irradiance[2] = (float)E[2];
    return HFVIS_OK;
}

/* ---- GI.8 voxelization with direct light (Alg. 4) and the room grid --------------------- */

HFVIS_API hfvis_status hfvis_volgi_grid_fit(const hfvis_mesh *mesh, int resolution,
                                            hfvis_volume_grid *out)
{
    double lo[3], hi[3], ext_max = 0.0, s;
    hfvis_volume_grid g;
    size_t total = 1;
    int a;
    if (!out || hfvis__mesh_check(mesh) != HFVIS_OK || mesh->triangle_count == 0 || resolution < 2
        || resolution > HFVIS_VOLGI_MAX_RESOLUTION)
        return HFVIS_ERR_INVALID_ARGUMENT;
    ext_max = vx_used_bounds(mesh, lo, hi);
    if (!(ext_max > 0.0) || !isfinite(ext_max)) return HFVIS_ERR_INVALID_ARGUMENT;
    s = ext_max / (double)(resolution - 1);
    memset(&g, 0, sizeof g);
    for (a = 0; a < 3; a++) {
        double nn = floor((hi[a] - lo[a]) / s + 0.5) + 1.0;
        g.dims[a] = (int)nn; /* <= resolution */
        g.cell[a] = s;
        g.origin[a] = 0.5 * (lo[a] + hi[a]) - 0.5 * nn * s;
        if (!(s > 0.0) || !isfinite(g.origin[a])) return HFVIS_ERR_INVALID_ARGUMENT;
        if (!hfvis__mul_size(total, (size_t)g.dims[a], &total) || total > HFVIS_VOLUME_MAX_VOXELS)
            return HFVIS_ERR_LIMIT;
    }
    *out = g;
    return HFVIS_OK;
}

/* The Volume Buffer layout of the voxelization: fragment count, normal sum, albedo sum (ADD:
 * averages [C]) and radiance (MAX: [G12] Alg. 4). */
#define VX_GI_VCH 10

typedef struct vx_gi_frag_user {
    const hfvis_volgi_scene *sc;
    const hfvis_bvh *bvh;
    double bias;
} vx_gi_frag_user;

static void vx_gi_fragment(const hfvis_voxel_fragment *f, float *values, void *user)
{
    const vx_gi_frag_user *u = (const vx_gi_frag_user *)user;
    const size_t t = (size_t)f->triangle;
    double p[3], n[3], E[3];
    int b;
    values[0] = 1.0f;
    for (b = 0; b < 3; b++) {
        p[b] = (double)f->position[b];
        n[b] = (double)f->normal[b];
        values[1 + b] = f->normal[b];
        values[4 + b] = u->sc->albedo ? u->sc->albedo[3 * t + (size_t)b] : 1.0f;
    }
    /* radiosity from direct light with shadows, plus emission ([G12] §5.5.1), as radiance */
    vx_gi_direct(u->sc, u->bvh, u->bias, p, n, f->triangle, E);
    for (b = 0; b < 3; b++) {
        double L = (double)values[4 + b] * E[b] / HFVIS__PI;
        if (u->sc->emission) L += (double)u->sc->emission[3 * t + (size_t)b];
        values[7 + b] = (float)L;
    }
}

/* Alg. 4 on validated inputs into the caller's arrays (albedo may be NULL). One block. */
static hfvis_status vx_gi_voxelize(const hfvis_volgi_scene *sc, const hfvis_bvh *bvh,
                                   const hfvis_volume_grid *grid, const vx_gi_cfg *cfg, float *occ,
                                   float *nrm, float *alb, float *rad, size_t *fragments)
{
    size_t n = vx_grid_voxels(grid), v, count = 0;
    float *block = (float *)hfvis__alloc_array(cfg->alloc, n, VX_GI_VCH * sizeof(float));
    hfvis_volume vol;
    hfvis_voxelize_options vo = hfvis_voxelize_options_default();
    vx_gi_frag_user fu;
    hfvis_status s;
    int b;
    if (!block) return HFVIS_ERR_OUT_OF_MEMORY;
    s = hfvis_volume_init(&vol, grid, VX_GI_VCH, block, HFVIS_BLEND_ADD);
    HFVIS_ASSERT(s == HFVIS_OK);
    for (b = 7; b < VX_GI_VCH; b++) vol.blend[b] = HFVIS_BLEND_MAX;
    fu.sc = sc, fu.bvh = bvh, fu.bias = vx_gi_bias(cfg, bvh);
    vo.axes = HFVIS_AXES_ALL;        /* the x, y and z slicing passes of Alg. 4 */
    vo.fragment = vx_gi_fragment;
    vo.user = &fu;
    s = hfvis_voxelize_surface(sc->mesh, &vol, &vo, &count);
    HFVIS_ASSERT(s == HFVIS_OK);
    for (v = 0; v < n; v++) {
        const float *q = block + v * VX_GI_VCH;
        double cnt = (double)q[0], len;
        occ[v] = cnt > 0.0 ? 1.0f : 0.0f;
        len = sqrt((double)q[1] * (double)q[1] + (double)q[2] * (double)q[2] + (double)q[3] * (double)q[3]);
        for (b = 0; b < 3; b++) {
            /* average normal; 0 when the fragments' normals cancel (a two-sided sheet) */
            nrm[3 * v + (size_t)b] = cnt > 0.0 && len > 1e-6 * cnt ? (float)((double)q[1 + b] / len) : 0.0f;
            if (alb) {
                double al = cnt > 0.0 ? (double)q[4 + b] / cnt : 0.0;
                alb[3 * v + (size_t)b] = (float)(al > 1.0 ? 1.0 : al);
            }
            rad[3 * v + (size_t)b] = q[7 + b];
        }
    }
    hfvis__free(cfg->alloc, block);
    if (fragments) *fragments = count;
    return s;
}

/* The scene's BVH, or one built into *own with cfg->alloc. */
static hfvis_status vx_gi_bvh(const hfvis_volgi_scene *sc, const vx_gi_cfg *cfg, hfvis_bvh *own,
                              const hfvis_bvh **bvh)
{
    hfvis_bvh_options bo = hfvis_bvh_options_default();
    hfvis_status s;
    memset(own, 0, sizeof *own);
    if (sc->bvh) {
        *bvh = sc->bvh;
        return HFVIS_OK;
    }
    bo.alloc = cfg->alloc;
    s = hfvis_bvh_build(sc->mesh, &bo, own);
    if (s == HFVIS_OK) *bvh = own;
    return s;
}

HFVIS_API hfvis_status hfvis_volgi_voxelize(const hfvis_volgi_scene *scene,
                                            const hfvis_volume_grid *grid,
                                            const hfvis_volgi_options *opts, float *occupancy,
                                            float *normal, float *albedo, float *radiance,
                                            size_t *fragments)
{
    vx_gi_cfg cfg;
    hfvis_bvh own;
    const hfvis_bvh *bvh = NULL;
    hfvis_status s;
    if (!grid || !occupancy || !normal || !radiance || !vx_grid_valid(grid))
        return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_gi_resolve(opts, &cfg);
    if (s != HFVIS_OK) return s;
    s = vx_gi_scene_check(scene);
    if (s != HFVIS_OK) return s;
    s = vx_gi_bvh(scene, &cfg, &own, &bvh);
    if (s != HFVIS_OK) return s;
    s = vx_gi_voxelize(scene, bvh, grid, &cfg, occupancy, normal, albedo, radiance, fragments);
    hfvis_bvh_free(cfg.alloc, &own);
    return s;
}

/* ---- GI.9 the whole pipeline ------------------------------------------------------------ */

/* Flux of one band summed over an SH volume. */
static void vx_gi_flux_sum(const float *sh, size_t n, double out[3])
{
    const double k = 2.0 * sqrt(HFVIS__PI);
    size_t v;
    int b;
    out[0] = out[1] = out[2] = 0.0;
    for (v = 0; v < n; v++)
        for (b = 0; b < 3; b++) out[b] += k * (double)sh[v * VX_GI_F + 4 * (size_t)b];
}

HFVIS_API hfvis_status hfvis_volgi_render(const hfvis_volgi_scene *scene,
                                          const hfvis_volume_grid *grid, const hfvis_view *view,
                                          const hfvis_volgi_options *opts,
                                          const hfvis_volgi_outputs *outputs,
                                          hfvis_volgi_render_info *info)
{
    vx_gi_cfg cfg;
    hfvis_volume_grid G;
    hfvis_bvh own;
    const hfvis_bvh *bvh = NULL;
    hfvis_raster_options ro = hfvis_raster_options_default();
    hfvis_raster_outputs rout;
    hfvis_volgi_geometry geo;
    hfvis_volgi_render_info inf;
    hfvis_volgi_options po;
    float *gbuf = NULL, *gvol = NULL, *sh = NULL;
    uint32_t *tri;
    size_t n, pixels, px, frags = 0, v;
    hfvis_status s;
    double bias;

    memset(&own, 0, sizeof own);
    memset(&inf, 0, sizeof inf);
    if (!scene || !view || !outputs) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_gi_resolve(opts, &cfg);
    if (s != HFVIS_OK) return s;
    s = vx_gi_scene_check(scene);
    if (s != HFVIS_OK) return s;
    if (grid) {
        if (!vx_grid_valid(grid)) return HFVIS_ERR_INVALID_ARGUMENT;
        G = *grid;
    } else {
        s = hfvis_volgi_grid_fit(scene->mesh, cfg.resolution, &G);
        if (s != HFVIS_OK) return s;
    }
    n = vx_gi_voxels(&G);
    if (n == 0) return HFVIS_ERR_LIMIT;
    if (view->width < 1 || view->height < 1) return HFVIS_ERR_INVALID_ARGUMENT;
    if (view->width > HFVIS_RASTER_MAX_SIZE || view->height > HFVIS_RASTER_MAX_SIZE)
        return HFVIS_ERR_LIMIT;
    pixels = (size_t)view->width * (size_t)view->height;

    /* G-buffer: normal (3), barycentrics (2), triangle id (1) per pixel, one block */
    gbuf = (float *)hfvis__alloc_array(cfg.alloc, pixels, 5 * sizeof(float) + sizeof(uint32_t));
    if (!gbuf) return HFVIS_ERR_OUT_OF_MEMORY;
    tri = (uint32_t *)(void *)(gbuf + 5 * pixels);
    memset(&rout, 0, sizeof rout);
    rout.normal = gbuf;
    rout.barycentric = gbuf + 3 * pixels;
    rout.triangle_id = tri;
    ro.alloc = cfg.alloc;
    s = hfvis_rasterize(scene->mesh, view, &ro, &rout);
    if (s != HFVIS_OK) goto done;
    s = vx_gi_bvh(scene, &cfg, &own, &bvh);
    if (s != HFVIS_OK) goto done;

    /* geometry volume: occupancy, normal, albedo, radiance (10 floats per voxel) */
    gvol = (float *)hfvis__alloc_array(cfg.alloc, n, 10 * sizeof(float));
    if (!gvol) { s = HFVIS_ERR_OUT_OF_MEMORY; goto done; }
    s = vx_gi_voxelize(scene, bvh, &G, &cfg, gvol, gvol + n, gvol + 4 * n, gvol + 7 * n, &frags);
    if (s != HFVIS_OK) goto done;
    geo.grid = G;
    geo.occupancy = gvol;
    geo.normal = gvol + n;
    geo.albedo = gvol + 4 * n;

    /* SH volumes: P (propagation) and A (accumulation) */
    sh = (float *)hfvis__alloc_array(cfg.alloc, n, 2 * VX_GI_F * sizeof(float));
    if (!sh) { s = HFVIS_ERR_OUT_OF_MEMORY; goto done; }
    s = hfvis_volgi_inject(&geo, gvol + 7 * n, sh);
    if (s != HFVIS_OK) goto done;
    vx_gi_flux_sum(sh, n, inf.injected);
    memset(sh + n * VX_GI_F, 0, n * VX_GI_F * sizeof(float));
    po = opts ? *opts : hfvis_volgi_options_default();
    s = hfvis_volgi_propagate(&geo, &po, cfg.iterations, sh, sh + n * VX_GI_F, NULL);
    if (s != HFVIS_OK) goto done;
    vx_gi_flux_sum(sh, n, inf.remaining);
    vx_gi_flux_sum(sh + n * VX_GI_F, n, inf.deposited);

    /* shading: per pixel at the exact surface point */
    bias = vx_gi_bias(&cfg, bvh);
    for (px = 0; px < pixels; px++) {
        float d[3] = { 0.0f, 0.0f, 0.0f }, id[3] = { 0.0f, 0.0f, 0.0f };
        int b;
        if (tri[px] != HFVIS_NO_TRIANGLE) {
            const size_t t = (size_t)tri[px];
            const uint32_t *ix = scene->mesh->indices + 3 * t;
            const float *v0 = scene->mesh->xyz + 3 * (size_t)ix[0];
            const float *v1 = scene->mesh->xyz + 3 * (size_t)ix[1];
            const float *v2 = scene->mesh->xyz + 3 * (size_t)ix[2];
            double b1 = (double)rout.barycentric[2 * px], b2 = (double)rout.barycentric[2 * px + 1];
            double p[3], nn[3], Ed[3], Ei[3];
            for (b = 0; b < 3; b++) {
                p[b] = (1.0 - b1 - b2) * (double)v0[b] + b1 * (double)v1[b] + b2 * (double)v2[b];
                nn[b] = (double)rout.normal[3 * px + (size_t)b];
            }
            vx_gi_direct(scene, bvh, bias, p, nn, tri[px], Ed);
            vx_gi_gather_point(&geo, sh + n * VX_GI_F, cfg.gather_scale, p, nn, Ei);
            for (b = 0; b < 3; b++) {
                double al = scene->albedo ? (double)scene->albedo[3 * t + (size_t)b] : 1.0;
                double em = scene->emission ? (double)scene->emission[3 * t + (size_t)b] : 0.0;
                d[b] = (float)(em + al * Ed[b] / HFVIS__PI);
                id[b] = (float)(al * Ei[b] / HFVIS__PI);
            }
            inf.covered_pixels++;
        }
        for (b = 0; b < 3; b++) {
            if (outputs->direct) outputs->direct[3 * px + (size_t)b] = d[b];
            if (outputs->indirect) outputs->indirect[3 * px + (size_t)b] = id[b];
            if (outputs->total) outputs->total[3 * px + (size_t)b] = (float)((double)d[b] + (double)id[b]);
        }
    }
    inf.grid = G;
    inf.fragments = frags;
    for (v = 0; v < n; v++) inf.occupied += gvol[v] > 0.0f;
    if (info) *info = inf;
done:
    hfvis__free(cfg.alloc, sh);
    hfvis__free(cfg.alloc, gvol);
    hfvis_bvh_free(cfg.alloc, &own);
    hfvis__free(cfg.alloc, gbuf);
    return s;
}
