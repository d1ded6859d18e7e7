/* fields.h - test fields that break lattice horizons, and the exact bilinear maximum along a ray.
 * Shared by test/test_exact.c, examples/bench/bench_exact.c and examples/14_exact_rays.c (one copy).
 *   fields_urban     flat ground with random box buildings (a DSM), heights in world units
 *   fields_terraces  a stepped hill: flat treads and one-cell cliffs of a given angle
 *   fields_ray_max   the largest elevation over the bilinear surface along a ray, exactly
 */
#ifndef HFVIS_FIELDS_H
#define HFVIS_FIELDS_H
#include <math.h>
#include <stdint.h>
#include "hfvis.h"

static inline uint64_t fields_next(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}
static inline double fields_uniform(uint64_t *s) { return (double)(fields_next(s) >> 11) * (1.0 / 9007199254740992.0); }

/* Flat ground (height 0) with `boxes` random buildings: sides 4..24 cells, heights 5..40 world
 * units (metres on a 1 m grid), overlapping boxes take the taller height. */
static inline void fields_urban(float *z, int W, int H, int boxes, uint64_t seed)
{
    int i, x, y;
    for (i = 0; i < W * H; i++) z[i] = 0.0f;
    for (i = 0; i < boxes; i++) {
        int w = 4 + (int)(fields_uniform(&seed) * 21.0), h = 4 + (int)(fields_uniform(&seed) * 21.0);
        int x0 = (int)(fields_uniform(&seed) * (double)W), y0 = (int)(fields_uniform(&seed) * (double)H);
        float top = (float)(5.0 + 35.0 * fields_uniform(&seed));
        for (y = y0; y < y0 + h && y < H; y++)
            for (x = x0; x < x0 + w && x < W; x++)
                if (z[y * W + x] < top) z[y * W + x] = top;
    }
}

/* A stepped hill: tread level n = floor(r / tread) of the distance r from the centre, height
 * (levels - n) * rise with rise = tan(cliff_deg) * cell (a cliff one cell wide), plus a gentle
 * seeded wobble of the contours so cliffs take every orientation. Heights in world units. */
static inline void fields_terraces(float *z, int W, int H, double cell, double tread,
                                   double cliff_deg, uint64_t seed)
{
    double cx = 0.5 * (double)(W - 1), cy = 0.5 * (double)(H - 1), rise = tan(cliff_deg * 3.14159265358979323846 / 180.0) * cell;
    double ph = 6.283185307179586 * fields_uniform(&seed);
    int x, y;
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++) {
            double dx = (double)x - cx, dy = (double)y - cy, r = sqrt(dx * dx + dy * dy);
            r *= 1.0 + 0.15 * sin(3.0 * atan2(dy, dx) + ph);
            z[y * W + x] = (float)((12.0 - floor(r / tread)) * rise);
        }
}

/* The exact supremum of the elevation seen from grid point (x, y) along azimuth psi over the
 * bilinear surface (open border: until the ray leaves the grid), counting surface points at
 * distances >= min_cells only (0: all, the limit at the receiver included). Along a ray the surface is quadratic inside each cell, so the sup
 * of (h(s) - h0)/s over a piece is at its ends or at s* = sqrt((p - h0)/r) for h = p + q s + r s^2;
 * the pieces run between the ray's column and row crossings. *arg receives the distance (cells)
 * of the maximum. Returns -pi/2 when nothing qualifies, NaN at a hole. */
static inline double fields_ray_max(const hfvis_grid *g, int x, int y, double psi, double min_cells,
                                    double *arg)
{
    double cx = cos(psi), cy = sin(psi), h0 = (double)g->z[(ptrdiff_t)y * g->stride + x];
    double s = 0.0, best = -(double)INFINITY, bests = 0.0, cs = g->cell_size;
    double xmax = (double)(g->width - 1), ymax = (double)(g->height - 1);
    if (fabs(cx) < 1e-15) cx = 0.0;
    if (fabs(cy) < 1e-15) cy = 0.0;
    if (!isfinite(h0)) return (double)NAN;
    for (;;) {
        double px = (double)x + s * cx, py = (double)y + s * cy, sx = (double)INFINITY, sy = (double)INFINITY, s1;
        double cand[4], hs[1], hm, h1, hq, r, q, p;
        int n = 0, i;
        if (cx > 0.0) sx = (floor(px + 1e-12) + 1.0 - (double)x) / cx;
        else if (cx < 0.0) sx = (ceil(px - 1e-12) - 1.0 - (double)x) / cx;
        if (cy > 0.0) sy = (floor(py + 1e-12) + 1.0 - (double)y) / cy;
        else if (cy < 0.0) sy = (ceil(py - 1e-12) - 1.0 - (double)y) / cy;
        s1 = sx < sy ? sx : sy;
        px = (double)x + s1 * cx;
        py = (double)y + s1 * cy;
        if (px < -1e-9 || py < -1e-9 || px > xmax + 1e-9 || py > ymax + 1e-9) break;
        /* the quadratic of this piece from three samples */
        hs[0] = hfvis_grid_sample(g, (double)x + s * cx, (double)y + s * cy);
        hm = hfvis_grid_sample(g, (double)x + 0.5 * (s + s1) * cx, (double)y + 0.5 * (s + s1) * cy);
        h1 = hfvis_grid_sample(g, px, py);
        if (isfinite(hs[0]) && isfinite(hm) && isfinite(h1)) {
            double L = s1 - s;
            /* h(t) = hs0 + q t + r t^2, t = s' - s in [0, L] */
            r = 2.0 * (hs[0] - 2.0 * hm + h1) / (L * L);
            q = (h1 - hs[0]) / L - r * L;
            p = hs[0] - q * s + r * s * s;           /* h(s') = p + (q - 2 r s) s' + r s'^2 */
            hq = q - 2.0 * r * s;
            cand[n++] = s > min_cells ? s : (min_cells > 0.0 ? min_cells : 1e-7); /* s -> 0: the slope's limit */
            cand[n++] = s1;
            if (r != 0.0 && (p - h0) / r > 0.0) cand[n++] = sqrt((p - h0) / r);
            for (i = 0; i < n; i++) {
                double t = cand[i], e;
                if (t < s || t > s1 || t < min_cells || t <= 0.0) continue;
                e = (p + hq * t + r * t * t - h0) / (t * cs);
                if (e > best) { best = e; bests = t; }
            }
        }
        s = s1;
    }
    if (arg) *arg = bests;
    return best == -(double)INFINITY ? -1.5707963267948966 : atan(best);
}
#endif
