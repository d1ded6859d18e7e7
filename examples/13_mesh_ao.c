/* 13_mesh_ao.c - Laine-Karras ray-cast ambient obscurance of a teapot in a room by rasterization,
 * BVH traversal and ray casting (identical images), and the table-mask error. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "common.h"

#define W 256
#define H 192
#define N 64        /* rays per pixel */
#define RADIUS 0.15 /* longest ray, in room units (the room is the unit cube) */

/* The room with a teapot (scaled by 0.18, standing at (0.42, 0.45) on the floor). */
static hfvis_status room_with_teapot(hfvis_mesh *out, float **xyz, uint32_t **idx)
{
    hfvis_mesh room, pot;
    hfvis_status s = hfvis_mesh_room(NULL, &room);
    size_t i;
    if (s != HFVIS_OK) return s;
    s = hfvis_mesh_teapot(NULL, 4, &pot);
    if (s != HFVIS_OK) { hfvis_mesh_free(NULL, &room); return s; }
    *xyz = malloc(sizeof(float) * 3 * (room.vertex_count + pot.vertex_count));
    *idx = malloc(sizeof(uint32_t) * 3 * (room.triangle_count + pot.triangle_count));
    if (!*xyz || !*idx) s = HFVIS_ERR_OUT_OF_MEMORY;
    else {
        memcpy(*xyz, room.xyz, sizeof(float) * 3 * room.vertex_count);
        memcpy(*idx, room.indices, sizeof(uint32_t) * 3 * room.triangle_count);
        for (i = 0; i < pot.vertex_count; i++) {
            float *v = *xyz + 3 * (room.vertex_count + i);
            v[0] = 0.42f + 0.18f * pot.xyz[3 * i];
            v[1] = 0.45f + 0.18f * pot.xyz[3 * i + 1];
            v[2] = 0.18f * pot.xyz[3 * i + 2];
        }
        for (i = 0; i < 3 * pot.triangle_count; i++)
            (*idx)[3 * room.triangle_count + i] = (uint32_t)room.vertex_count + pot.indices[i];
        out->xyz = *xyz;
        out->vertex_count = room.vertex_count + pot.vertex_count;
        out->indices = *idx;
        out->triangle_count = room.triangle_count + pot.triangle_count;
    }
    hfvis_mesh_free(NULL, &room);
    hfvis_mesh_free(NULL, &pot);
    return s;
}

/* Largest |a - b| over pixels with a receiver; d gets the difference image. */
static double diff_image(const float *a, const float *b, float *d)
{
    double worst = 0.0;
    int i;
    for (i = 0; i < W * H; i++) {
        d[i] = isnan(a[i]) ? 0.0f : (float)fabs((double)a[i] - (double)b[i]);
        if ((double)d[i] > worst) worst = (double)d[i];
    }
    return worst;
}

int main(int argc, char **argv)
{
    static const char *names[3] = {"raster", "bvh", "raycast"};
    static const hfvis_lk_method methods[3] = {HFVIS_LK_METHOD_RASTER, HFVIS_LK_METHOD_BVH,
                                               HFVIS_LK_METHOD_RAYCAST};
    const char *dir = argc > 1 ? argv[1] : "out";
    const double eye[3] = {0.5, -1.15, 0.5}, target[3] = {0.5, 0.5, 0.38}, up[3] = {0.0, 0.0, 1.0};
    float *xyz = NULL, *ao[4] = {NULL, NULL, NULL, NULL}, *diff = malloc(sizeof(float) * W * H);
    uint32_t *idx = NULL;
    hfvis_mesh mesh;
    hfvis_view view;
    hfvis_lk_rays rays;
    hfvis_lk_lut lut;
    hfvis_lk_options opts = hfvis_lk_options_default();
    hfvis_lk_stats st;
    char name[64];
    double worst, worst2;
    int m, rc = 1;

    memset(&rays, 0, sizeof rays);
    memset(&lut, 0, sizeof lut);
    for (m = 0; m < 4; m++) ao[m] = malloc(sizeof(float) * W * H);
    if (!diff || !ao[0] || !ao[1] || !ao[2] || !ao[3]) { ex_error("13_mesh_ao", "out of memory"); goto fail; }
    EX_CHECK(room_with_teapot(&mesh, &xyz, &idx), "room_with_teapot");
    EX_CHECK(hfvis_view_perspective(&view, eye, target, up, 55.0 * 3.14159265358979323846 / 180.0, W, H,
                                    0.05, 10.0), "hfvis_view_perspective");
    /* N cosine-distributed rays of length RADIUS (Lloyd-relaxed disc, [LK] §6), shared by all */
    EX_CHECK(hfvis_lk_rays_build(N, RADIUS, NULL, &rays), "hfvis_lk_rays_build");

    /* The three methods on the same receivers (the G-buffer of the view), exact masks */
    for (m = 0; m < 3; m++) {
        clock_t t0 = clock();
        EX_CHECK(hfvis_lk_image(methods[m], &mesh, NULL, &view, &rays, &opts, NULL, ao[m], &st),
                 "hfvis_lk_image");
        printf("13_mesh_ao: %-7s %llu receivers x %d rays, mean obscurance %.4f, %llu %s, %.2f s\n",
               names[m], (unsigned long long)st.receivers, N, (double)st.rays_blocked / (double)st.rays,
               (unsigned long long)(m == 2 ? st.fragments : st.masks),
               m == 2 ? "ray-triangle tests" : "triangle masks", (double)(clock() - t0) / CLOCKS_PER_SEC);
        snprintf(name, sizeof name, "lk_ao_%s.pgm", names[m]);
        if (ex_save_pgm_png(dir, name, ao[m], W, H, W, 0.0f, 1.0f)) goto fail;
    }
    /* Exact masks: the methods agree bit for bit, so the difference images are black */
    worst = diff_image(ao[0], ao[1], diff);
    if (ex_save_pgm_png(dir, "lk_diff_raster_bvh.pgm", diff, W, H, W, 0.0f, 0.05f)) goto fail;
    worst2 = diff_image(ao[2], ao[1], diff);
    if (ex_save_pgm_png(dir, "lk_diff_raycast_bvh.pgm", diff, W, H, W, 0.0f, 0.05f)) goto fail;
    printf("13_mesh_ao: max |raster - bvh| = %g, max |raycast - bvh| = %g\n", worst, worst2);
    if (worst != 0.0 || worst2 != 0.0) { ex_error("13_mesh_ao", "the methods disagree"); goto fail; }

    /* Table masks ([LK] §3.1, T = 64): faster for large N, quantised near planes */
    EX_CHECK(hfvis_lk_lut_build(&rays, 64, NULL, &lut), "hfvis_lk_lut_build");
    opts.mask_mode = HFVIS_LK_MASK_LUT;
    opts.lut = &lut;
    EX_CHECK(hfvis_lk_image(HFVIS_LK_METHOD_BVH, &mesh, NULL, &view, &rays, &opts, NULL, ao[3], NULL),
             "hfvis_lk_image (LUT)");
    worst = diff_image(ao[3], ao[1], diff);
    printf("13_mesh_ao: table (%.0f MiB) vs exact masks: max difference %g (%.0f of %d rays)\n",
           (double)lut.bytes / 1048576.0, worst, worst * N, N);
    if (ex_save_pgm_png(dir, "lk_diff_lut_exact.pgm", diff, W, H, W, 0.0f, 0.05f)) goto fail;
    {   /* picture: ray casting | BVH masks | table masks | |table - exact| x 20 */
        const ex_panel sheet[4] = { { ao[2], 0.0f, 1.0f }, { ao[1], 0.0f, 1.0f }, { ao[3], 0.0f, 1.0f },
                                    { diff, 0.0f, 0.05f } };
        if (ex_save_png_sheet(dir, "lk_sheet.png", sheet, 4, 4, W, H, 1)) goto fail;
    }
    rc = 0;
fail:
    hfvis_lk_lut_free(NULL, &lut);
    hfvis_lk_rays_free(NULL, &rays);
    for (m = 0; m < 4; m++) free(ao[m]);
    free(diff); free(xyz); free(idx);
    return rc;
}
