/* 11_volume_gi.c - volume-based VPL indirect light ([G12] ch. 5): a Cornell-like room with a red
 * and a green wall; direct, indirect and total light. Usage: 11_volume_gi [OUTDIR] (default "out") */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "common.h"

#define W 256
#define H 256
#define RES 32        /* the thesis' grid (Table 2) */
#define ITERATIONS 64 /* the thesis' room: 64 steps = 2 bounces on 32^3 */
#define PI 3.14159265358979323846

/* R | G | B of an RGB image side by side, so that a grey PGM shows the colours apart. */
static void panels(const float *rgb, float *out)
{
    int x, y, c;
    for (y = 0; y < H; y++)
        for (c = 0; c < 3; c++)
            for (x = 0; x < W; x++) out[(size_t)y * 3 * W + (size_t)(c * W + x)] = rgb[3 * ((size_t)y * W + (size_t)x) + (size_t)c];
}

/* Mean red/green ratio of the bottom rows (the floor) over a band of columns. */
static double red_green(const float *rgb, int x0, int x1)
{
    double r = 0.0, g = 0.0;
    int x, y;
    for (y = H - H / 8; y < H; y++)
        for (x = x0; x < x1; x++) r += (double)rgb[3 * ((size_t)y * W + (size_t)x)], g += (double)rgb[3 * ((size_t)y * W + (size_t)x) + 1];
    return g > 0.0 ? r / g : 0.0;
}

static int by_value(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return x < y ? -1 : x > y;
}

/* The 99th percentile of px (the ceiling right above the light would set the range otherwise). */
static float top_of(const float *px, size_t n, float *tmp)
{
    memcpy(tmp, px, n * sizeof(float));
    qsort(tmp, n, sizeof(float), by_value);
    return tmp[n - n / 100 - 1] > 0.0f ? tmp[n - n / 100 - 1] : 1.0f;
}

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "out";
    const double eye[3] = { 0.5, -1.1, 0.5 }, target[3] = { 0.5, 0.5, 0.45 }, up[3] = { 0, 0, 1 };
    const size_t n = (size_t)W * H * 3;
    float albedo[30 * 3], *direct = malloc(n * sizeof(float)), *indirect = malloc(n * sizeof(float));
    float *total = malloc(n * sizeof(float)), *indirect_void = malloc(n * sizeof(float));
    float *pan = malloc(n * sizeof(float)), top, itop;
    hfvis_mesh room;
    hfvis_volgi_light light;
    hfvis_volgi_scene scene;
    hfvis_volgi_options opts = hfvis_volgi_options_default();
    hfvis_volgi_outputs out;
    hfvis_volgi_render_info info;
    hfvis_view view;
    double left, right;
    int t, rc = 1;

    memset(&room, 0, sizeof room);
    if (!direct || !indirect || !total || !indirect_void || !pan) { ex_error("11_volume_gi", "out of memory"); goto fail; }
    EX_CHECK(hfvis_mesh_room(NULL, &room), "hfvis_mesh_room");
    /* walls 0-1: x = 0 (red), 2-3: x = 1 (green); back, floor, ceiling and both boxes white */
    for (t = 0; t < 30; t++) {
        albedo[3 * t] = t < 2 ? 0.75f : t < 4 ? 0.15f : 0.75f;
        albedo[3 * t + 1] = t < 2 ? 0.15f : 0.75f;
        albedo[3 * t + 2] = t < 4 ? 0.15f : 0.75f;
    }
    memset(&light, 0, sizeof light);
    light.type = HFVIS_VOLGI_LIGHT_POINT; /* under the ceiling, 1 W/sr */
    light.position[0] = 0.5, light.position[1] = 0.45, light.position[2] = 0.9;
    light.intensity[0] = light.intensity[1] = light.intensity[2] = 1.0f;
    memset(&scene, 0, sizeof scene);
    scene.mesh = &room;
    scene.albedo = albedo;
    scene.lights = &light;
    scene.light_count = 1;
    EX_CHECK(hfvis_view_perspective(&view, eye, target, up, 40.0 * PI / 180.0, W, H, 0.1, 10.0), "view");

    /* The thesis' method: Alg. 4 voxelization with direct light, VPLs, 64 steps of the [G12] ch. 5, eq. 11; docs/errata.md E59
     * kernel, per-pixel gather. */
    opts.resolution = RES;
    opts.iterations = ITERATIONS;
    out.direct = direct, out.indirect = indirect, out.total = total;
    EX_CHECK(hfvis_volgi_render(&scene, NULL, &view, &opts, &out, &info), "hfvis_volgi_render");
    /* The energy-conserving variant: light only through empty voxels, nothing lost between cones. */
    opts.paths = HFVIS_VOLGI_PATHS_VOID;
    opts.transfer = HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED;
    out.direct = NULL, out.indirect = indirect_void, out.total = NULL;
    EX_CHECK(hfvis_volgi_render(&scene, NULL, &view, &opts, &out, NULL), "hfvis_volgi_render (void paths)");

    left = red_green(indirect, 0, W / 6), right = red_green(indirect, W - W / 6, W);
    printf("11_volume_gi: %dx%dx%d grid, %zu occupied voxels, %d iterations; surfaces received %.2f x the VPL "
           "flux; indirect floor light red/green %.2f beside the red wall, %.2f beside the green wall\n",
           info.grid.dims[0], info.grid.dims[1], info.grid.dims[2], info.occupied, ITERATIONS,
           info.deposited[0] / info.injected[0], left, right);
    if (!(left > 1.0 && right < 1.0)) { ex_error("11_volume_gi", "no colour bleeding: unexpected result"); goto fail; }

    /* One range for direct and total (so they compare), one for each indirect image (99th
     * percentiles). Each PGM holds the R, G and B channels side by side. */
    top = top_of(total, n, pan);
    panels(direct, pan);
    if (ex_save_pgm_png(dir, "volgi_direct.pgm", pan, 3 * W, H, 3 * W, 0.0f, top)) goto fail;
    panels(total, pan);
    if (ex_save_pgm_png(dir, "volgi_total.pgm", pan, 3 * W, H, 3 * W, 0.0f, top)) goto fail;
    itop = top_of(indirect, n, pan);
    panels(indirect, pan);
    if (ex_save_pgm_png(dir, "volgi_indirect.pgm", pan, 3 * W, H, 3 * W, 0.0f, itop)) goto fail;
    itop = top_of(indirect_void, n, pan);
    panels(indirect_void, pan);
    if (ex_save_pgm_png(dir, "volgi_indirect_void.pgm", pan, 3 * W, H, 3 * W, 0.0f, itop)) goto fail;
    {   /* picture in colour: direct | indirect (own scale) | total */
        const ex_panel sheet[3] = { { direct, 0.0f, top }, { indirect, 0.0f, top_of(indirect, n, pan) },
                                    { total, 0.0f, top } };
        if (ex_save_png_sheet(dir, "volgi_sheet.png", sheet, 3, 3, W, H, 3)) goto fail;
    }
    rc = 0;
fail:
    free(direct), free(indirect), free(total), free(indirect_void), free(pan);
    hfvis_mesh_free(NULL, &room);
    return rc;
}
