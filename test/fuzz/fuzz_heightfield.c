/* libFuzzer target for the height-field sweeps: the input picks a grid shape (1..48 per side,
 * thin grids included), K, the border, a cell size from 1e-140 to 1e140 and raw float heights
 * (NaN and infinities are holes, huge and tiny values allowed), then runs the horizon map, the
 * sky-view factor, sky light, the visibility count, a direction range of sums and the normals,
 * and checks each output against its documented range (hfvis.h): finite inside the range at
 * every sample that is not a hole, NaN at holes. The cell is capped so that |z|/cell stays
 * within 1e150, the range hfvis.h guarantees (the hfvis tool refuses beyond it).
 * Layout: byte 0 width-1 (mod 48), 1 height-1 (mod 48), 2 K-1 (mod 32), 3 border (mod 3),
 * 4 cell exponent (cell = 10^((b - 128) * 140 / 128)), then width*height little-endian floats
 * (missing bytes are 0). Seeds: test/fuzz/seeds/heightfield. Built and run by `make fuzz`. */
#include "hfvis.h"
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define FZ_MAX_SIDE 48
#define FZ_MAX_K 32
#define FZ_HALF_PI 1.5707963267948966
#define FZ_SKY_MAX 3.2     /* sky light of sky = albedo = 1: K terms of [P1] Eq. 5 on a near-vertical
                              receiver overshoot the hemisphere's 1 (measured 2.24 at K = 3,
                              1.06 at K = 16); each term is at most pi/K of it */
#define FZ_RELIEF 1e150    /* |z| / cell guaranteed by hfvis.h */

static float z[FZ_MAX_SIDE * FZ_MAX_SIDE], out[FZ_MAX_SIDE * FZ_MAX_SIDE * 4];
static float map[FZ_MAX_K * FZ_MAX_SIDE * FZ_MAX_SIDE];
static double sums[FZ_MAX_SIDE * FZ_MAX_SIDE];

static int W_, H_;
static int hole(int i) { return !isfinite(z[i]); }
/* A sample with a hole within two cells may receive NaN: every lattice node of an oblique
 * direction around it can touch the hole (a bilinear sample touching a hole is a hole), and the
 * gather finds no finite node within two cells (known limitation, docs/reliability.md). */
static int near_hole(int i)
{
    int x = i % W_, y = i / W_, dx, dy;
    for (dy = -2; dy <= 2; dy++)
        for (dx = -2; dx <= 2; dx++)
            if (x + dx >= 0 && x + dx < W_ && y + dy >= 0 && y + dy < H_ && hole((y + dy) * W_ + x + dx))
                return 1;
    return 0;
}
/* value v at sample i: NaN at a hole, in [lo, hi] elsewhere (or NaN next to a hole) */
static int bad(int i, double v, double lo, double hi)
{
    if (hole(i)) return !isnan(v);
    if (isnan(v)) return !near_hole(i);
    return !(v >= lo && v <= hi);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    int W, H, K, n, i;
    double cell, top = 0.0;
    hfvis_grid g;
    hfvis_sweep_options o = hfvis_sweep_options_default();
    if (size < 5) return 0;
    W = 1 + data[0] % FZ_MAX_SIDE;
    H = 1 + data[1] % FZ_MAX_SIDE;
    K = 1 + data[2] % FZ_MAX_K;
    o.border = (hfvis_border)(1 + data[3] % 3);
    cell = pow(10.0, ((double)data[4] - 128.0) * 140.0 / 128.0);
    n = W * H;
    W_ = W;
    H_ = H;
    for (i = 0; i < n; i++) {
        uint32_t u = 0;
        size_t at = 5 + 4 * (size_t)i, b;
        for (b = 0; b < 4; b++) u |= (uint32_t)(at + b < size ? data[at + b] : 0) << (8 * b);
        memcpy(&z[i], &u, 4);
        if (isfinite(z[i]) && fabs((double)z[i]) > top) top = fabs((double)z[i]);
    }
    if (top / cell > FZ_RELIEF) cell = top / FZ_RELIEF;
    g.z = z; g.width = W; g.height = H; g.stride = W; g.cell_size = cell;

    if (hfvis_horizon_map(&g, K, &o, map) != HFVIS_OK) abort();
    for (i = 0; i < K * n; i++)
        if (bad(i % n, (double)map[i], -FZ_HALF_PI - 1e-6, FZ_HALF_PI + 1e-6)) abort();
    if (hfvis_sky_view_factor(&g, K, &o, out, W) != HFVIS_OK) abort();
    for (i = 0; i < n; i++)
        if (bad(i, (double)out[i], 0.0, 1.0)) abort();
    if (hfvis_sky_light(&g, K, 1.0f, 1.0f, &o, out, W) != HFVIS_OK) abort();
    for (i = 0; i < n; i++)
        if (bad(i, (double)out[i], 0.0, FZ_SKY_MAX)) abort();
    if (hfvis_visibility_count(&g, K, &o, NULL, out, W, NULL) != HFVIS_OK) abort();
    for (i = 0; i < n; i++)
        if (bad(i, (double)out[i], 0.0, (double)K * (double)(W + H + 3))) abort();
    o.direction_begin = K / 2;
    o.direction_end = K;
    if (K > 1) {
        if (hfvis_direction_sums(&g, K, HFVIS_SUM_SKY_VIEW, NULL, NULL, &o, sums) != HFVIS_OK) abort();
        for (i = 0; i < n; i++)
            if (bad(i, sums[i], 0.0, (double)(K - K / 2))) abort();
    }
    if (hfvis_normals_compute(&g, out) != HFVIS_OK) abort();
    for (i = 0; i < n; i++) {
        double len;
        if (hole(i)) {
            if (!isnan(out[3 * i])) abort();
            continue;
        }
        len = sqrt((double)out[3 * i] * (double)out[3 * i] + (double)out[3 * i + 1] * (double)out[3 * i + 1] +
                   (double)out[3 * i + 2] * (double)out[3 * i + 2]);
        if (!(fabs(len - 1.0) <= 1e-6) || !(out[3 * i + 2] >= 0.0f)) abort();
    }
    return 0;
}
