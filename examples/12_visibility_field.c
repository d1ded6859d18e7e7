/* 12_visibility_field.c - a 4D visibility field of a teapot ([G12] ch. 4): ambient occlusion on
 * the ground plane under it from the field and from direct ray casting, and their difference. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "common.h"

#define W 192          /* image side: the square [-2.4, 2.4]^2 of the ground z = 0, seen from above */
#define EXTENT 2.4
#define POS_N 32       /* octahedral frequency: K = 2(2n^2 + 2n + 1) = 4226 positional samples */
#define DIRS 32        /* 32 x 32 directions per sample (8-bit distances: 4.3 MB), the thesis' choice */

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "out";
    const size_t n = (size_t)W * W;
    hfvis_mesh teapot = { 0 };
    hfvis_bvh bvh = { 0 };
    hfvis_visfield field = { { 0.0, 0.0, 0.0 }, 0.0, POS_N, DIRS, HFVIS_DIRMAP_CONCENTRIC,
                             HFVIS_VISFIELD_U8, 0.0, NULL, 0 };
    hfvis_visfield_object obj;
    hfvis_visfield_ao_options opts = hfvis_visfield_ao_options_default(); /* 16 x 16 rays */
    float *pts = malloc(sizeof(float) * 3 * n), *nrm = malloc(sizeof(float) * 3 * n);
    float *ao = malloc(sizeof(float) * n), *ref = malloc(sizeof(float) * n);
    float *diff = malloc(sizeof(float) * n);
    double rms = 0.0, worst = 0.0, turn = 0.6;
    size_t i;
    int x, y, k, rc = 1;

    if (!pts || !nrm || !ao || !ref || !diff) { ex_error("12_visibility_field", "out of memory"); goto fail; }
    /* The teapot-like test mesh stands on z = 0 (bounds about [-1.5, 1.7] x [-1, 1] x [0, 1.4]). */
    EX_CHECK(hfvis_mesh_teapot(NULL, 4, &teapot), "hfvis_mesh_teapot");
    EX_CHECK(hfvis_bvh_build(&teapot, NULL, &bvh), "hfvis_bvh_build");

    /* Algorithm 1: K maps of D x D distances from the bounding sphere toward the object, cast
     * once, offline, in object space. The caller owns the maps (hfvis_visfield_size bytes). */
    EX_CHECK(hfvis_visfield_bounding_sphere(&teapot, field.center, &field.radius),
             "hfvis_visfield_bounding_sphere");
    field.maps_size = hfvis_visfield_size(POS_N, DIRS, HFVIS_VISFIELD_U8);
    field.maps = malloc(field.maps_size);
    if (!field.maps) { ex_error("12_visibility_field", "out of memory"); goto fail; }
    EX_CHECK(hfvis_visfield_build(&teapot, NULL, &field), "hfvis_visfield_build");

    /* One instance of the object, turned about z by a rigid transform (the field is reused as
     * is: queries run in object space). The mesh and its BVH serve the ray-cast reference. */
    obj.field = &field;
    obj.mesh = &teapot;
    obj.bvh = &bvh;
    for (k = 0; k < 16; k++) obj.object_to_world[k] = (k % 5 == 0) ? 1.0 : 0.0;
    obj.object_to_world[0] = obj.object_to_world[5] = cos(turn);
    obj.object_to_world[1] = sin(turn);
    obj.object_to_world[4] = -sin(turn);

    /* Receivers: the pixel centres of the ground plane, normal +z, row 0 at +y. */
    for (y = 0; y < W; y++)
        for (x = 0; x < W; x++) {
            i = (size_t)y * W + (size_t)x;
            pts[3 * i] = (float)(-EXTENT + 2.0 * EXTENT * (x + 0.5) / W);
            pts[3 * i + 1] = (float)(EXTENT - 2.0 * EXTENT * (y + 0.5) / W);
            pts[3 * i + 2] = 0.0f;
            nrm[3 * i] = nrm[3 * i + 1] = 0.0f;
            nrm[3 * i + 2] = 1.0f;
        }
    /* Algorithms 2/3: every AO ray that meets the sphere reads the rest of its distance from
     * the map of the nearest sample; receivers inside the sphere use the inside query with the
     * default bias (0.02 R). The reference casts the very same rays against the mesh. */
    EX_CHECK(hfvis_visfield_ambient_occlusion(&obj, 1, pts, nrm, n, &opts, ao),
             "hfvis_visfield_ambient_occlusion");
    EX_CHECK(hfvis_visfield_ambient_occlusion_reference(&obj, 1, pts, nrm, n, &opts, ref),
             "hfvis_visfield_ambient_occlusion_reference");
    for (i = 0; i < n; i++) {
        double d = (double)ao[i] - (double)ref[i];
        rms += d * d;
        if (fabs(d) > worst) worst = fabs(d);
        diff[i] = (float)fabs(d);
    }
    printf("12_visibility_field: %zu maps of %d x %d (%zu bytes) for %zu triangles; AO of %d x %d ground points, "
           "256 rays each: RMS vs ray casting %.2f on the 8-bit scale, worst %.3f\n",
           hfvis_visfield_position_count(POS_N), DIRS, DIRS, field.maps_size, teapot.triangle_count,
           W, W, 255.0 * sqrt(rms / (double)n), worst);
    /* Obscurance: 0 (black) = open sky, 1 = fully blocked; the difference is shown x 4. */
    if (ex_save_pgm_png(dir, "12_visibility_field_ao_field.pgm", ao, W, W, W, 0.0f, 1.0f)) goto fail;
    if (ex_save_pgm_png(dir, "12_visibility_field_ao_raycast.pgm", ref, W, W, W, 0.0f, 1.0f)) goto fail;
    if (ex_save_pgm_png(dir, "12_visibility_field_ao_difference.pgm", diff, W, W, W, 0.0f, 0.25f)) goto fail;
    {   /* picture: field | ray casting | difference x 4 */
        const ex_panel sheet[3] = { { ao, 0.0f, 1.0f }, { ref, 0.0f, 1.0f }, { diff, 0.0f, 0.25f } };
        if (ex_save_png_sheet(dir, "12_visibility_field_sheet.png", sheet, 3, 3, W, W, 1)) goto fail;
    }
    rc = 0;
fail:
    free(field.maps);
    hfvis_bvh_free(NULL, &bvh);
    hfvis_mesh_free(NULL, &teapot);
    free(pts); free(nrm); free(ao); free(ref); free(diff);
    return rc;
}
