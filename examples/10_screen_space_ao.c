/* 10_screen_space_ao.c - screen-space obscurance of a rasterized scene by the four methods of issue 5:
 * a torus knot ("dragon-like" tangle) standing on a ground slab, rendered with hfvis_rasterize
 * (linear depth, guard band 10 % per side), then P3 LSAO, HBAO, P4 FFAO and the screen-space
 * ray-traced reference. Writes into argv[1] (default "out"):
 *   ssao_ao.pgm      the four AO images side by side (LSAO | HBAO | FFAO | ray traced),
 *                    white = open (ambient light 1 - AO)
 *   ssao_error.pgm   |method - ray traced| for LSAO | HBAO | FFAO, white = 0, black >= 20 %
 *   the same as PNG, and ssao_sheet.png with both, the errors under their methods
 * and prints e_A and e_<5% of each against the reference. LSAO and HBAO estimate solid-angle
 * obscurance (docs/errata.md C4), so their error against the cosine-weighted reference is expected to be
 * larger: the comparison that P4 makes is FFAO's. Runs in a few seconds. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "common.h"

#define W0 256
#define H0 192
#define GX 24
#define GY 18
#define IW (W0 - 2 * GX)
#define IH (H0 - 2 * GY)

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "out";
    hfvis_mesh knot, slab;
    hfvis_mesh scene;
    float *xyz = NULL, *depth = NULL, *nrm = NULL, *ao[4] = {NULL, NULL, NULL, NULL}, *sheet = NULL, *err = NULL;
    uint32_t *idx = NULL;
    hfvis_view view;
    hfvis_raster_outputs out;
    hfvis_raster_options ro = hfvis_raster_options_default();
    hfvis_camera cam;
    hfvis_falloff fo;
    char path[1024];
    double c[3] = {0.0, 0.0, 1.1}, lo[3] = {-4.0, -4.0, -0.2}, hi[3] = {4.0, 4.0, 0.0};
    double eye[3] = {3.2, -4.2, 3.0}, tgt[3] = {0.0, 0.0, 0.6}, up[3] = {0.0, 0.0, 1.0};
    static const char *names[4] = {"LSAO", "HBAO", "FFAO", "ray traced"};
    size_t i;
    int k, x, y, rc = 1;
    memset(&knot, 0, sizeof knot);
    memset(&slab, 0, sizeof slab);
    if (hfvis_mesh_torus_knot(NULL, c, 0.9, 2, 3, 600, 16, &knot) != HFVIS_OK ||
        hfvis_mesh_box(NULL, lo, hi, &slab) != HFVIS_OK) { fprintf(stderr, "ex_ssaob: mesh\n"); goto fail; }
    /* concatenate the two meshes */
    xyz = (float *)malloc(sizeof(float) * 3 * (knot.vertex_count + slab.vertex_count));
    idx = (uint32_t *)malloc(sizeof(uint32_t) * 3 * (knot.triangle_count + slab.triangle_count));
    depth = (float *)malloc(sizeof(float) * W0 * H0);
    nrm = (float *)malloc(sizeof(float) * 3 * W0 * H0);
    sheet = (float *)malloc(sizeof(float) * 8 * IW * IH); /* AO sheet above, error sheet below */
    err = (float *)malloc(sizeof(float) * IW * IH);
    for (k = 0; k < 4; k++) ao[k] = (float *)malloc(sizeof(float) * IW * IH);
    if (!xyz || !idx || !depth || !nrm || !sheet || !err || !ao[0] || !ao[1] || !ao[2] || !ao[3]) goto fail;
    memcpy(xyz, knot.xyz, sizeof(float) * 3 * knot.vertex_count);
    memcpy(xyz + 3 * knot.vertex_count, slab.xyz, sizeof(float) * 3 * slab.vertex_count);
    memcpy(idx, knot.indices, sizeof(uint32_t) * 3 * knot.triangle_count);
    for (i = 0; i < 3 * slab.triangle_count; i++) idx[3 * knot.triangle_count + i] = slab.indices[i] + (uint32_t)knot.vertex_count;
    scene.xyz = xyz;
    scene.vertex_count = knot.vertex_count + slab.vertex_count;
    scene.indices = idx;
    scene.triangle_count = knot.triangle_count + slab.triangle_count;
    if (hfvis_view_perspective(&view, eye, tgt, up, 0.9, W0, H0, 0.1, 100.0) != HFVIS_OK) goto fail;
    memset(&out, 0, sizeof out);
    out.linear_depth = depth;
    if (hfvis_rasterize(&scene, &view, &ro, &out) != HFVIS_OK) { fprintf(stderr, "ex_ssaob: rasterize\n"); goto fail; }
    if (hfvis_camera_from_view(&cam, &view, GX, GY) != HFVIS_OK) goto fail;
    if (hfvis_depth_normals(&cam, depth, nrm) != HFVIS_OK) goto fail;
    memset(&fo, 0, sizeof fo);
    fo.kind = HFVIS_FALLOFF_INV_QUADRATIC;
    fo.param = 1.0; /* r = 1: half weight at one unit (the knot is ~3.5 units across) */
    {
        hfvis_lsao_options o = hfvis_lsao_options_default();
        o.falloff = fo;
        if (hfvis_lsao(&cam, depth, nrm, &o, ao[0], IW) != HFVIS_OK) goto fail;
    }
    {
        hfvis_hbao_options o = hfvis_hbao_options_default();
        o.falloff = fo;
        o.directions = 16;
        o.max_radius_px = 64.0;
        if (hfvis_hbao(&cam, depth, nrm, &o, ao[1], IW) != HFVIS_OK) goto fail;
    }
    {
        hfvis_ffao_options o = hfvis_ffao_options_default();
        o.falloff = fo;
        if (hfvis_ffao(&cam, depth, nrm, &o, ao[2], IW) != HFVIS_OK) goto fail;
    }
    {
        hfvis_ssao_rt_options o = hfvis_ssao_rt_options_default();
        o.falloff = fo;
        o.rays = 48;
        if (hfvis_ssao_reference(&cam, depth, nrm, &o, ao[3], IW) != HFVIS_OK) goto fail;
    }
    for (k = 0; k < 4; k++)
        for (y = 0; y < IH; y++)
            for (x = 0; x < IW; x++) sheet[(size_t)y * 4 * IW + (size_t)k * IW + (size_t)x] = 1.0f - ao[k][y * IW + x];
    snprintf(path, sizeof path, "%s/ssao_ao.pgm", dir);
    if (hfvis_pgm_save(path, sheet, 4 * IW, IH, 4 * IW, 0.0f, 1.0f, 255) != HFVIS_OK) { fprintf(stderr, "ex_ssaob: cannot write %s\n", path); goto fail; }
    if (ex_save_png(dir, "ssao_ao.png", sheet, 4 * IW, IH, 4 * IW, 0.0f, 1.0f)) goto fail;
    for (i = (size_t)4 * IW * IH; i < (size_t)8 * IW * IH; i++) sheet[i] = 1.0f; /* under the reference: white */
    for (k = 0; k < 3; k++) {
        hfvis_ssao_error_stats e;
        if (hfvis_ssao_error(ao[k], IW, ao[3], IW, IW, IH, 0.05, 0, &e, err, IW) != HFVIS_OK) goto fail;
        printf("%-5s vs %s: e_A %.2f %%, e_<5%% %.1f %% of pixels, bias %+.2f %%\n", names[k], names[3],
               100.0 * e.mean, 100.0 * e.within, 100.0 * e.bias);
        for (y = 0; y < IH; y++)
            for (x = 0; x < IW; x++) sheet[(size_t)(IH + y) * 4 * IW + (size_t)k * IW + (size_t)x] = err[y * IW + x];
    }
    snprintf(path, sizeof path, "%s/ssao_error.pgm", dir);
    if (hfvis_pgm_save(path, sheet + 4 * IW * IH, 3 * IW, IH, 4 * IW, 0.0f, 1.0f, 255) != HFVIS_OK) goto fail;
    if (ex_save_png(dir, "ssao_error.png", sheet + 4 * IW * IH, 3 * IW, IH, 4 * IW, 0.0f, 1.0f)) goto fail;
    /* picture: the AO images above, the error of LSAO, HBAO and FFAO below */
    if (ex_save_png(dir, "ssao_sheet.png", sheet, 4 * IW, 2 * IH, 4 * IW, 0.0f, 1.0f)) goto fail;
    printf("wrote %s/ssao_ao.pgm and %s/ssao_error.pgm\n", dir, dir);
    rc = 0;
fail:
    for (k = 0; k < 4; k++) free(ao[k]);
    free(err);
    free(sheet);
    free(nrm);
    free(depth);
    free(idx);
    free(xyz);
    hfvis_mesh_free(NULL, &knot);
    hfvis_mesh_free(NULL, &slab);
    return rc;
}
