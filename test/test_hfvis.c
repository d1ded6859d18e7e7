/* test_hfvis.c - height-field horizon / sky-light tests against the spec
 * (heightfield-p1-p2 §3.2 lattice, §4, §5.1-5.3, §11, §12.1-12.4 closed forms). */
#include "../hfvis.h"
#include "test.h"

#include <float.h>
#include <stdint.h>
#include <stdlib.h>

/* Small local xorshift64 PRNG: deterministic across platforms. */
static uint64_t rng_state = 88172645463325252ULL;
static void rng_seed(uint64_t s) { rng_state = s ? s : 88172645463325252ULL; }
static uint64_t rng_next(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return rng_state;
}
/* uniform in [0, 1) with 53 bits */
static double rng_unit(void) { return (double)(rng_next() >> 11) * (1.0 / 9007199254740992.0); }
static int rng_int(int n) { return (int)(rng_next() % (uint64_t)n); }


/* ---------------------------------------------------------------------------------------- */
/* 1. Hull stack vs brute force (spec §4.2, §11 item 5, §12.9, §12.11)                       */
/* ---------------------------------------------------------------------------------------- */

#define LINE_MAX_N 320

static int same_double(double a, double b) { return a == b || (isnan(a) && isnan(b)); }

/* Compare hfvis_line_horizons with hfvis_line_horizons_naive on one line: tangents exactly
 * equal; casters equal, or (on exact ties) both casters attain the common tangent exactly.
 * Returns 1 if all agree; prints the first difference. */
static int line_agrees(const double *d, const double *h, int n, const char *what, int line)
{
    double tf[LINE_MAX_N], tn[LINE_MAX_N];
    int cf[LINE_MAX_N], cn[LINE_MAX_N], stack[LINE_MAX_N], i;
    if (hfvis_line_horizons(d, h, n, tf, cf, stack) != HFVIS_OK ||
        hfvis_line_horizons_naive(d, h, n, tn, cn) != HFVIS_OK) {
        fprintf(stderr, "  %s line %d: status not OK\n", what, line);
        return 0;
    }
    for (i = 0; i < n; i++) {
        int ok = same_double(tf[i], tn[i]);
        if (ok && cf[i] != cn[i]) {
            /* ties: each caster must attain the tangent exactly */
            ok = cf[i] >= 0 && cn[i] >= 0 && cf[i] < i && cn[i] < i &&
                 (h[cf[i]] - h[i]) / (d[i] - d[cf[i]]) == tf[i] &&
                 (h[cn[i]] - h[i]) / (d[i] - d[cn[i]]) == tn[i];
        }
        if (ok && cf[i] >= 0 && (h[cf[i]] - h[i]) / (d[i] - d[cf[i]]) != tf[i]) ok = 0;
        if (!ok) {
            fprintf(stderr, "  %s line %d n=%d i=%d: hull t=%.17g c=%d, naive t=%.17g c=%d\n",
                    what, line, n, i, tf[i], cf[i], tn[i], cn[i]);
            return 0;
        }
    }
    return 1;
}

enum { LINE_GENERIC, LINE_INTEGER, LINE_PLATEAU, LINE_CLIFF, LINE_MONO_UP, LINE_MONO_DOWN,
       LINE_KINDS };
static const char *const line_kind_name[LINE_KINDS] = {
    "generic", "integer", "plateau", "cliff", "monotone-up", "monotone-down" };

static void line_make(int kind, int n, double *d, double *h)
{
    int i;
    double pos = rng_unit() * 10.0 - 5.0, level = 0.0;
    for (i = 0; i < n; i++) {
        switch (kind) {
        case LINE_GENERIC:
            pos += 0.01 + rng_unit() * 3.0;
            h[i] = (rng_unit() - 0.5) * 40.0;
            break;
        case LINE_INTEGER: /* small integers: exact ties everywhere (§11 item 5) */
            pos = (i == 0) ? (double)rng_int(5) : pos + (double)(1 + rng_int(3));
            h[i] = (double)rng_int(7);
            break;
        case LINE_PLATEAU: /* runs of equal heights, integer positions */
            pos = (i == 0) ? 0.0 : pos + 1.0;
            if (rng_int(6) == 0) level = (double)rng_int(9);
            h[i] = level;
            break;
        case LINE_CLIFF: /* flat stretches with rare huge steps */
            pos += 0.5 + rng_unit();
            if (rng_int(15) == 0) level += (rng_unit() - 0.5) * 2000.0;
            h[i] = level + rng_unit() * 0.1;
            break;
        case LINE_MONO_UP:
            pos += 0.25 + rng_unit();
            level += rng_unit() * 5.0;
            h[i] = level;
            break;
        default: /* LINE_MONO_DOWN */
            pos += 0.25 + rng_unit();
            level -= rng_unit() * 5.0;
            h[i] = level;
            break;
        }
        d[i] = pos;
    }
}

TEST(line_horizons_random)
{
    /* 3600 seeded lines, 600 of each kind, n in 0..300 */
    double d[LINE_MAX_N], h[LINE_MAX_N];
    int line, bad[LINE_KINDS] = { 0 }, k;
    rng_seed(12345);
    for (line = 0; line < 3600; line++) {
        int kind = line % LINE_KINDS, n = rng_int(301);
        line_make(kind, n, d, h);
        if (!line_agrees(d, h, n, line_kind_name[kind], line)) bad[kind]++;
    }
    for (k = 0; k < LINE_KINDS; k++) CHECK(bad[k] == 0);
}

TEST(line_horizons_small_n)
{
    double d[3] = { -1.0, 0.5, 2.0 }, h[3] = { 3.0, 1.0, 7.0 }, t[3] = { 9, 9, 9 };
    int c[3] = { 9, 9, 9 }, stack[3];
    CHECK_EQ_STATUS(hfvis_line_horizons(d, h, 0, t, c, stack), HFVIS_OK);
    CHECK(t[0] == 9.0 && c[0] == 9); /* n = 0 writes nothing */
    CHECK_EQ_STATUS(hfvis_line_horizons(d, h, 1, t, c, stack), HFVIS_OK);
    CHECK(t[0] == -(double)INFINITY && c[0] == -1 && t[1] == 9.0);
    CHECK_EQ_STATUS(hfvis_line_horizons(d, h, 2, t, c, stack), HFVIS_OK);
    /* t_1 = (h0 - h1)/(d1 - d0) = 2/1.5 */
    CHECK(t[0] == -(double)INFINITY && c[0] == -1 && t[1] == 2.0 / 1.5 && c[1] == 0);
    CHECK(line_agrees(d, h, 0, "n0", 0));
    CHECK(line_agrees(d, h, 1, "n1", 0));
    CHECK(line_agrees(d, h, 2, "n2", 0));
    CHECK(line_agrees(d, h, 3, "n3", 0));
    /* caster_out may be NULL */
    CHECK_EQ_STATUS(hfvis_line_horizons(d, h, 3, t, NULL, stack), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_line_horizons_naive(d, h, 3, t, NULL), HFVIS_OK);
}

TEST(line_horizons_holes)
{
    /* Holes never occlude: the result at the finite samples equals that of the line with the
     * holes removed (casters mapped back to the original indices); holes get NaN, -1. */
    double d[LINE_MAX_N], h[LINE_MAX_N], dr[LINE_MAX_N], hr[LINE_MAX_N];
    double t[LINE_MAX_N], tr[LINE_MAX_N], tn[LINE_MAX_N];
    int c[LINE_MAX_N], cr[LINE_MAX_N], cn[LINE_MAX_N], stack[LINE_MAX_N], keep[LINE_MAX_N];
    int line, bad = 0;
    rng_seed(777);
    for (line = 0; line < 600; line++) {
        int kind = line % LINE_KINDS, n = 1 + rng_int(200), i, m = 0, ok = 1;
        line_make(kind, n, d, h);
        for (i = 0; i < n; i++) {
            int r = rng_int(8);
            if (r == 0) h[i] = (double)NAN;
            else if (r == 1 && line % 3 == 0) h[i] = (rng_int(2) ? 1.0 : -1.0) * (double)INFINITY;
            if (isfinite(h[i])) { dr[m] = d[i]; hr[m] = h[i]; keep[m] = i; m++; }
        }
        if (hfvis_line_horizons(d, h, n, t, c, stack) != HFVIS_OK ||
            hfvis_line_horizons_naive(d, h, n, tn, cn) != HFVIS_OK ||
            hfvis_line_horizons(dr, hr, m, tr, cr, stack) != HFVIS_OK) { bad++; continue; }
        for (i = 0; i < n; i++)
            if (!isfinite(h[i]) && !(isnan(t[i]) && c[i] == -1 && isnan(tn[i]) && cn[i] == -1)) ok = 0;
        for (i = 0; i < m; i++) {
            int j = keep[i];
            if (!same_double(t[j], tr[i]) || !same_double(tn[j], tr[i])) ok = 0;
            if (c[j] != (cr[i] < 0 ? -1 : keep[cr[i]])) ok = 0;
        }
        if (!ok) {
            if (!bad) fprintf(stderr, "  holes: line %d (%s) differs\n", line, line_kind_name[kind]);
            bad++;
        }
    }
    CHECK(bad == 0);
}

TEST(line_horizons_worst_shapes)
{
    /* spec §12.9 */
    double d[LINE_MAX_N], h[LINE_MAX_N], t[LINE_MAX_N];
    int c[LINE_MAX_N], stack[LINE_MAX_N], n = 300, i, ok;
    /* dome h = -(x - 150)^2: strictly concave, every receiver's caster is its neighbour,
     * t_i = h_{i-1} - h_i = 2(x - 150) - 1 at x = i */
    for (i = 0; i < n; i++) { d[i] = (double)i; h[i] = -(double)((i - 150) * (i - 150)); }
    CHECK(line_agrees(d, h, n, "dome", 0));
    CHECK_EQ_STATUS(hfvis_line_horizons(d, h, n, t, c, stack), HFVIS_OK);
    for (ok = 1, i = 1; i < n; i++) ok &= c[i] == i - 1 && t[i] == (double)(2 * (i - 150) - 1);
    CHECK(ok);
    /* convex bowl h = (x - 150)^2: from x = i the slope to j is (h_j - h_i)/(i - j) =
     * -(i + j - 300), largest at j = 0: one horizon, p_0, t_i = 300 - i */
    for (i = 0; i < n; i++) h[i] = (double)((i - 150) * (i - 150));
    CHECK(line_agrees(d, h, n, "bowl", 0));
    CHECK_EQ_STATUS(hfvis_line_horizons(d, h, n, t, c, stack), HFVIS_OK);
    for (ok = 1, i = 1; i < n; i++) ok &= c[i] == 0 && t[i] == (double)(300 - i);
    CHECK(ok);
    /* bowl with every other sample lowered (the P2 worst case) */
    for (i = 0; i < n; i++) h[i] = (double)((i - 150) * (i - 150)) - ((i & 1) ? 50.0 : 0.0);
    CHECK(line_agrees(d, h, n, "bowl-alt", 0));
}

TEST(line_horizons_bad_args)
{
    double d[4] = { 0.0, 1.0, 1.0, 2.0 }, h[4] = { 1.0, 2.0, 3.0, 4.0 }, t[4], t0[4];
    int c[4], c0[4], stack[4], i;
    for (i = 0; i < 4; i++) { t0[i] = t[i] = 123.0; c0[i] = c[i] = 77; }
    /* non-increasing distance (equal at index 2, then decreasing) */
    CHECK_EQ_STATUS(hfvis_line_horizons(d, h, 4, t, c, stack), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_line_horizons_naive(d, h, 4, t, c), HFVIS_ERR_INVALID_ARGUMENT);
    d[2] = 0.5;
    CHECK_EQ_STATUS(hfvis_line_horizons(d, h, 4, t, c, stack), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_line_horizons_naive(d, h, 4, t, c), HFVIS_ERR_INVALID_ARGUMENT);
    d[2] = 1.5;
    d[1] = (double)NAN; /* NaN distance is not increasing */
    CHECK_EQ_STATUS(hfvis_line_horizons(d, h, 4, t, c, stack), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_line_horizons_naive(d, h, 4, t, c), HFVIS_ERR_INVALID_ARGUMENT);
    d[1] = 1.0;
    CHECK_EQ_STATUS(hfvis_line_horizons(NULL, h, 4, t, c, stack), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_line_horizons(d, NULL, 4, t, c, stack), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_line_horizons(d, h, 4, NULL, c, stack), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_line_horizons(d, h, 4, t, c, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_line_horizons(d, h, -1, t, c, stack), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_line_horizons_naive(NULL, h, 4, t, c), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_line_horizons_naive(d, NULL, 4, t, c), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_line_horizons_naive(d, h, 4, NULL, c), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_line_horizons_naive(d, h, -1, t, c), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(memcmp(t, t0, sizeof t) == 0 && memcmp(c, c0, sizeof c) == 0);
}


/* ---------------------------------------------------------------------------------------- */
/* Shared grid helpers                                                                       */
/* ---------------------------------------------------------------------------------------- */

static const double PI = 3.14159265358979323846;

/* A seeded fBm field (spec §12.11-style random terrain) into a new buffer. */
static float *make_fbm(int w, int h, uint64_t seed, double amplitude, double wavelength)
{
    hfvis_field f;
    float *z = (float *)malloc(sizeof(float) * (size_t)w * (size_t)h);
    memset(&f, 0, sizeof f);
    f.kind = HFVIS_FIELD_FBM;
    f.amplitude = amplitude;
    f.wavelength = wavelength;
    f.seed = seed;
    if (z && hfvis_field_generate(&f, w, h, w, z) != HFVIS_OK) { free(z); z = NULL; }
    return z;
}

/* ---------------------------------------------------------------------------------------- */
/* 2. Sweep lattice == per-node brute force, bit for bit (spec §6 item 2)                     */
/* ---------------------------------------------------------------------------------------- */

TEST(horizon_lattice_vs_naive)
{
    /* the third grid is the first with NaN / +-Inf holes (holes never occlude, NaN nodes) */
    static const int dims[3][2] = { { 37, 23 }, { 64, 64 }, { 37, 23 } };
    static const double cells[2] = { 1.0, 2.5 };
    static const hfvis_border borders[3] = { HFVIS_BORDER_OPEN, HFVIS_BORDER_CLAMP, HFVIS_BORDER_WRAP };
    int gi, ci, bi, a, bad = 0, runs = 0;
    rng_seed(4242);
    for (gi = 0; gi < 3; gi++) {
        int w = dims[gi][0], h = dims[gi][1], i;
        float *z = make_fbm(w, h, (uint64_t)(100 + gi % 2), 5.0, 9.0);
        CHECK(z != NULL);
        if (!z) return;
        if (gi == 2)
            for (i = 0; i < w * h; i += 1 + rng_int(40))
                z[i] = i % 3 == 0 ? (float)NAN : i % 3 == 1 ? (float)INFINITY : -(float)INFINITY;
        for (ci = 0; ci < 2; ci++) {
            hfvis_grid g;
            g.z = z; g.width = w; g.height = h; g.stride = w; g.cell_size = cells[ci];
            for (a = 0; a < 30; a++) {
                /* the five special azimuths, then random ones (some negative or > 2pi) */
                static const double special[5] = { 0.0, 0.5 * PI, PI, 1.5 * PI, 0.25 * PI };
                double az = a < 5 ? special[a] : (rng_unit() * 4.0 - 1.0) * PI;
                hfvis_lattice L;
                size_t n;
                float *fast, *slow;
                CHECK_EQ_STATUS(hfvis_lattice_init(&L, w, h, az), HFVIS_OK);
                n = hfvis_lattice_size(&L);
                fast = (float *)malloc(sizeof(float) * n);
                slow = (float *)malloc(sizeof(float) * n);
                CHECK(fast && slow);
                if (!fast || !slow) { free(fast); free(slow); free(z); return; }
                for (bi = 0; bi < 3; bi++) {
                    hfvis_sweep_options o = hfvis_sweep_options_default();
                    o.border = borders[bi];
                    o.border_cells = 10;
                    memset(fast, 0x5a, sizeof(float) * n);
                    memset(slow, 0xa5, sizeof(float) * n);
                    CHECK_EQ_STATUS(hfvis_horizon_lattice(&g, az, &o, fast), HFVIS_OK);
                    CHECK_EQ_STATUS(hfvis_horizon_lattice_naive(&g, az, &o, slow), HFVIS_OK);
                    runs++;
                    if (memcmp(fast, slow, sizeof(float) * n) != 0) {
                        if (bad < 5)
                            fprintf(stderr, "  lattice %dx%d cell %g az %.17g border %d differs\n",
                                    w, h, cells[ci], az, (int)borders[bi]);
                        bad++;
                    }
                }
                free(fast);
                free(slow);
            }
        }
        free(z);
    }
    CHECK(runs == 540);
    CHECK(bad == 0);
}


/* ---------------------------------------------------------------------------------------- */
/* 3. Lattice geometry (spec §3.2)                                                           */
/* ---------------------------------------------------------------------------------------- */

/* Domain slack of spec §3.2 (eps = 1e-9): nodes on the boundary belong to the domain. */
#define LATTICE_EPS 1e-9

static int node_inside(const hfvis_lattice *L, int i, int j)
{
    double x = (double)i * L->ux + (double)j * L->vx, y = (double)i * L->uy + (double)j * L->vy;
    return x >= -LATTICE_EPS && x <= (double)(L->width - 1) + LATTICE_EPS &&
           y >= -LATTICE_EPS && y <= (double)(L->height - 1) + LATTICE_EPS;
}

/* Walks every line: in-range nodes inside, the nodes just before/after outside, lines beyond
 * [j_min, j_max] have no inside node near the buffer. Returns total in-domain nodes, sets
 * *lines to the number of non-empty lines and *ok to 0 on any violation. */
static long lattice_walk(const hfvis_lattice *L, int *lines, int *ok)
{
    long total = 0;
    int i, j;
    *lines = 0;
    for (j = L->j_min; j <= L->j_max; j++) {
        int i0 = 0, i1 = -1, cnt = hfvis_lattice_line(L, j, &i0, &i1);
        if (cnt <= 0) continue;
        (*lines)++;
        total += cnt;
        if (cnt != i1 - i0 + 1 || i0 < L->i_min || i1 > L->i_max) *ok = 0;
        for (i = i0; i <= i1; i++)
            if (!node_inside(L, i, j)) *ok = 0;
        if (node_inside(L, i0 - 1, j) || node_inside(L, i1 + 1, j)) *ok = 0;
    }
    for (i = L->i_min - 2; i <= L->i_max + 2; i++)
        if (node_inside(L, i, L->j_min - 1) || node_inside(L, i, L->j_max + 1)) *ok = 0;
    return total;
}

TEST(lattice_geometry)
{
    static const double axes[4] = { 0.0, 0.5 * PI, PI, 1.5 * PI };
    hfvis_lattice L;
    int a, lines, ok;
    long total;
    /* axis directions reproduce the grid: 64 lines of 64 nodes, a 64 x 64 buffer */
    for (a = 0; a < 4; a++) {
        int j, i0, i1, every64 = 1;
        CHECK_EQ_STATUS(hfvis_lattice_init(&L, 64, 64, axes[a]), HFVIS_OK);
        ok = 1;
        total = lattice_walk(&L, &lines, &ok);
        CHECK(ok);
        CHECK(lines == 64 && total == 64L * 64L);
        CHECK(hfvis_lattice_size(&L) == 64u * 64u);
        for (j = L.j_min; j <= L.j_max; j++) every64 &= hfvis_lattice_line(&L, j, &i0, &i1) == 64;
        CHECK(every64);
        /* snapped: exact 0 / +-1 components */
        CHECK(fabs(L.ux) + fabs(L.uy) == 1.0 && fabs(L.vx) + fabs(L.vy) == 1.0);
        CHECK(L.ux * L.vx + L.uy * L.vy == 0.0);
    }
    /* 45 degrees: 89 lines, 4050 in-domain nodes. Buffer: rows = j_max-j_min+1 = 89 (one per
     * line), cols = i_max-i_min+1 = 90; the spec's "90 x 89" lists (cols x rows). */
    CHECK_EQ_STATUS(hfvis_lattice_init(&L, 64, 64, 0.25 * PI), HFVIS_OK);
    ok = 1;
    total = lattice_walk(&L, &lines, &ok);
    CHECK(ok);
    CHECK(lines == 89);
    CHECK(total == 4050);
    CHECK(L.j_max - L.j_min + 1 == 89);
    CHECK(L.i_max - L.i_min + 1 == 90);
    CHECK(hfvis_lattice_size(&L) == 90u * 89u);
    /* random azimuths and non-square grids: the same invariants */
    rng_seed(99);
    for (a = 0, ok = 1; a < 200; a++) {
        int w = 1 + rng_int(70), h = 1 + rng_int(70);
        double az = (rng_unit() * 6.0 - 2.0) * PI;
        if (hfvis_lattice_init(&L, w, h, az) != HFVIS_OK) { ok = 0; continue; }
        total = lattice_walk(&L, &lines, &ok);
        if ((size_t)(L.j_max - L.j_min + 1) * (size_t)(L.i_max - L.i_min + 1) != hfvis_lattice_size(&L))
            ok = 0;
        /* nodes of a unit lattice in the (W-1) x (H-1) rectangle: its area, +- about half
         * the perimeter (spec §3.2 "(W-1)(H-1) + boundary") */
        if (labs(total - (long)(w - 1) * (long)(h - 1)) > (long)(w + h)) ok = 0;
    }
    CHECK(ok);
}


/* ---------------------------------------------------------------------------------------- */
/* 4. Bilinear sampling (spec §3.2 "Bilinear sampling", §11 item 11)                         */
/* ---------------------------------------------------------------------------------------- */

/* A 4-tap blend of a plane rounds a few ulps of heights <= 100: 1e-12 absolute. */
#define SAMPLE_TOL 1e-12

TEST(grid_sample)
{
    enum { W = 13, H = 9 };
    float z[W * H];
    hfvis_grid g;
    int x, y, k, ok;
    /* z = 3 + 0.5 x - 0.25 y: exact in float at integer points; bilinear reproduces a plane */
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++) z[y * W + x] = (float)(3.0 + 0.5 * x - 0.25 * y);
    g.z = z; g.width = W; g.height = H; g.stride = W; g.cell_size = 2.0;
    rng_seed(5);
    for (k = 0, ok = 1; k < 2000; k++) {
        double px = rng_unit() * (W - 1), py = rng_unit() * (H - 1);
        if (k < 4) { px = (k & 1) ? W - 1 : 0; py = (k & 2) ? H - 1 : 0; } /* corners: max edge */
        if (fabs(hfvis_grid_sample(&g, px, py) - (3.0 + 0.5 * px - 0.25 * py)) > SAMPLE_TOL) ok = 0;
    }
    CHECK(ok);
    /* clamped outside the grid: equals the value at the clamped position */
    CHECK_NEAR(hfvis_grid_sample(&g, -3.5, 2.25), 3.0 - 0.25 * 2.25, SAMPLE_TOL, 0);
    CHECK_NEAR(hfvis_grid_sample(&g, 40.0, 2.25), 3.0 + 0.5 * (W - 1) - 0.25 * 2.25, SAMPLE_TOL, 0);
    CHECK_NEAR(hfvis_grid_sample(&g, 4.5, -1e9), 3.0 + 0.5 * 4.5, SAMPLE_TOL, 0);
    CHECK_NEAR(hfvis_grid_sample(&g, 4.5, 1e9), 3.0 + 0.5 * 4.5 - 0.25 * (H - 1), SAMPLE_TOL, 0);
    CHECK_NEAR(hfvis_grid_sample(&g, 1e300, -1e300), 3.0 + 0.5 * (W - 1), SAMPLE_TOL, 0);
    /* holes: NaN when a tap with non-zero weight is a hole */
    z[5 * W + 5] = (float)NAN;
    CHECK(isnan(hfvis_grid_sample(&g, 4.5, 5.5)));
    CHECK(isnan(hfvis_grid_sample(&g, 5.0, 5.0)));
    CHECK(isnan(hfvis_grid_sample(&g, 5.25, 4.5)));
    CHECK(isnan(hfvis_grid_sample(&g, 5.9, 5.9)));
    /* ... but finite when the hole's weight is zero (x or y exactly on a neighbouring line) */
    CHECK_NEAR(hfvis_grid_sample(&g, 4.0, 4.5), 3.0 + 2.0 - 0.25 * 4.5, SAMPLE_TOL, 0);
    CHECK_NEAR(hfvis_grid_sample(&g, 6.0, 5.5), 3.0 + 3.0 - 0.25 * 5.5, SAMPLE_TOL, 0);
    CHECK_NEAR(hfvis_grid_sample(&g, 4.5, 4.0), 3.0 + 2.25 - 1.0, SAMPLE_TOL, 0);
    CHECK_NEAR(hfvis_grid_sample(&g, 5.5, 6.0), 3.0 + 2.75 - 1.5, SAMPLE_TOL, 0);
    z[5 * W + 5] = (float)INFINITY; /* +-Inf is a hole too (hfvis.h CONVENTIONS: non-finite) */
    CHECK(isnan(hfvis_grid_sample(&g, 4.5, 5.5)));
    CHECK(isnan(hfvis_grid_sample(&g, 5.0, 5.0)));
    CHECK_NEAR(hfvis_grid_sample(&g, 4.0, 4.5), 3.0 + 2.0 - 0.25 * 4.5, SAMPLE_TOL, 0);
    z[5 * W + 5] = 0.0f;
    /* a hole at the max edge (x0 = W-2, fx = 0 at x = W-2: zero weight) */
    z[3 * W + (W - 1)] = (float)NAN;
    CHECK_NEAR(hfvis_grid_sample(&g, W - 2, 3.0), 3.0 + 0.5 * (W - 2) - 0.75, SAMPLE_TOL, 0);
    CHECK(isnan(hfvis_grid_sample(&g, W - 1, 3.0)));
    CHECK(isnan(hfvis_grid_sample(&g, W + 7.0, 3.0))); /* clamped onto the hole */
    /* 1 x N and N x 1 grids: 1-D interpolation, clamped in the degenerate axis */
    {
        float col[7], row[7];
        hfvis_grid gc, gr;
        for (k = 0; k < 7; k++) col[k] = row[k] = (float)(2.0 + 0.5 * k);
        gc.z = col; gc.width = 1; gc.height = 7; gc.stride = 1; gc.cell_size = 1.0;
        gr.z = row; gr.width = 7; gr.height = 1; gr.stride = 7; gr.cell_size = 1.0;
        for (k = 0, ok = 1; k < 200; k++) {
            double t = rng_unit() * 6.0, o = (rng_unit() - 0.5) * 10.0;
            if (fabs(hfvis_grid_sample(&gc, o, t) - (2.0 + 0.5 * t)) > SAMPLE_TOL) ok = 0;
            if (fabs(hfvis_grid_sample(&gr, t, o) - (2.0 + 0.5 * t)) > SAMPLE_TOL) ok = 0;
        }
        CHECK(ok);
        CHECK_NEAR(hfvis_grid_sample(&gc, 0.0, 6.0), 5.0, SAMPLE_TOL, 0);
        CHECK_NEAR(hfvis_grid_sample(&gr, 9.0, 0.0), 5.0, SAMPLE_TOL, 0);
        CHECK_NEAR(hfvis_grid_sample(&gr, -9.0, 0.0), 2.0, SAMPLE_TOL, 0);
        gc.height = 1; /* 1 x 1 */
        CHECK_NEAR(hfvis_grid_sample(&gc, 3.0, -2.0), 2.0, SAMPLE_TOL, 0);
    }
    /* invalid grid: NaN */
    CHECK(isnan(hfvis_grid_sample(NULL, 1.0, 1.0)));
    g.cell_size = 0.0;
    CHECK(isnan(hfvis_grid_sample(&g, 1.0, 1.0)));
}


/* ---------------------------------------------------------------------------------------- */
/* 5. Normals (spec §5.1)                                                                    */
/* ---------------------------------------------------------------------------------------- */

/* Normals are stored as float: half an ulp of a unit vector component is 6e-8; 1e-6 leaves
 * room for the double normalisation before rounding. */
#define NORMAL_TOL 1e-6

TEST(normals)
{
    enum { W = 9, H = 7 };
    float z[W * H], n[3 * W * H];
    hfvis_grid g;
    int x, y, ok = 1;
    /* plane z = 1 + 0.75 x - 0.5 y (x, y in cells), cell 2: gradient per world unit
     * (0.375, -0.25), so N = (-0.375, 0.25, 1)/sqrt(0.375^2 + 0.25^2 + 1) everywhere
     * (central differences inside, one-sided at the border: both exact on a plane) */
    const double len = sqrt(0.375 * 0.375 + 0.25 * 0.25 + 1.0);
    const double nx = -0.375 / len, ny = 0.25 / len, nz = 1.0 / len;
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++) z[y * W + x] = (float)(1.0 + 0.75 * x - 0.5 * y);
    g.z = z; g.width = W; g.height = H; g.stride = W; g.cell_size = 2.0;
    CHECK_EQ_STATUS(hfvis_normals_compute(&g, n), HFVIS_OK);
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++) {
            const float *p = n + 3 * (y * W + x);
            if (fabs((double)p[0] - nx) > NORMAL_TOL || fabs((double)p[1] - ny) > NORMAL_TOL ||
                fabs((double)p[2] - nz) > NORMAL_TOL) {
                if (ok) fprintf(stderr, "  normal (%d,%d) = %g %g %g\n", x, y, (double)p[0],
                                (double)p[1], (double)p[2]);
                ok = 0;
            }
        }
    CHECK(ok);
    /* holes: NaN normal; neighbours use the one-sided difference (still exact on the plane) */
    z[3 * W + 4] = (float)NAN;
    z[0] = (float)(-INFINITY);
    CHECK_EQ_STATUS(hfvis_normals_compute(&g, n), HFVIS_OK);
    CHECK(isnan(n[3 * (3 * W + 4)]) && isnan(n[3 * (3 * W + 4) + 1]) && isnan(n[3 * (3 * W + 4) + 2]));
    CHECK(isnan(n[0]) && isnan(n[1]) && isnan(n[2]));
    for (y = 0, ok = 1; y < H; y++)
        for (x = 0; x < W; x++) {
            const float *p = n + 3 * (y * W + x);
            if ((y == 3 && x == 4) || (x == 0 && y == 0)) continue;
            if (fabs((double)p[0] - nx) > NORMAL_TOL || fabs((double)p[1] - ny) > NORMAL_TOL ||
                fabs((double)p[2] - nz) > NORMAL_TOL) ok = 0;
        }
    CHECK(ok);
    /* one-sided beside a hole on a curved row z = x^2 (cells), cell 1: at x = 5 with a hole at
     * x = 6 the slope is h(4) - h(5) = -9 (central would give (16 - 36)/2 = -10), so
     * N ~ (h(x-1) - h(x), 0, 1) = (-9, 0, 1)/sqrt(82) */
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++) z[y * W + x] = (float)(x * x);
    z[2 * W + 6] = (float)NAN;
    g.cell_size = 1.0;
    CHECK_EQ_STATUS(hfvis_normals_compute(&g, n), HFVIS_OK);
    CHECK_NEAR(n[3 * (2 * W + 5)], -9.0 / sqrt(82.0), NORMAL_TOL, 0);
    CHECK_NEAR(n[3 * (2 * W + 5) + 1], 0.0, NORMAL_TOL, 0);
    CHECK_NEAR(n[3 * (2 * W + 5) + 2], 1.0 / sqrt(82.0), NORMAL_TOL, 0);
    /* and at x = 7 the right-sided slope h(7) - h(8) = -15 */
    CHECK_NEAR(n[3 * (2 * W + 7)], -15.0 / sqrt(226.0), NORMAL_TOL, 0);
    /* interior elsewhere: central (h(x-1) - h(x+1))/2 = -2x, at x = 3 on row 2: -6 */
    CHECK_NEAR(n[3 * (2 * W + 3)], -6.0 / sqrt(37.0), NORMAL_TOL, 0);
    /* right border one-sided: h(7) - h(8) = -15 at x = 8 */
    CHECK_NEAR(n[3 * (4 * W + 8)], -15.0 / sqrt(226.0), NORMAL_TOL, 0);
}


/* ---------------------------------------------------------------------------------------- */
/* 6. Flat plane (spec §12.1)                                                                */
/* ---------------------------------------------------------------------------------------- */

/* Light outputs are float: Sum_k S_k rounded once; 1e-6 is ~8 float ulps at 1. */
#define LIGHT_TOL 1e-6

/* A grid point is "interior" for gathered directions if every lattice node its gather can
 * touch (within sqrt 2 cells) is a non-first node (first nodes lie within 1 cell of the
 * border): distance >= 3 cells from every edge (spec §3.3). */
#define INTERIOR_MARGIN 3

static int interior(int x, int y, int w, int h)
{
    return x >= INTERIOR_MARGIN && y >= INTERIOR_MARGIN && x < w - INTERIOR_MARGIN &&
           y < h - INTERIOR_MARGIN;
}

TEST(flat_plane)
{
    enum { W = 24, H = 20, K = 8 };
    static const int ks[4] = { 1, 3, 4, 16 };
    float z[W * H], out[W * H], *map;
    hfvis_grid g;
    int i, k, x, y, ok;
    for (i = 0; i < W * H; i++) z[i] = 7.0f;
    g.z = z; g.width = W; g.height = H; g.stride = W; g.cell_size = 1.5;
    /* every non-first sample has t = 0 (collinear samples pop, the caster is the previous
     * sample): the map is exactly 0 at interior grid points in all K = 8 directions */
    map = (float *)malloc(sizeof(float) * K * W * H);
    CHECK(map != NULL);
    if (!map) return;
    CHECK_EQ_STATUS(hfvis_horizon_map(&g, K, NULL, map), HFVIS_OK);
    for (k = 0, ok = 1; k < K; k++)
        for (y = 0; y < H; y++)
            for (x = 0; x < W; x++)
                if (interior(x, y, W, H) && map[(k * H + y) * W + x] != 0.0f) ok = 0;
    CHECK(ok);
    /* Eq. 5 on a flat field is exactly 1 for any K, including border points whose first
     * samples have t = -inf (the tangent clamp makes them equal to the interior, §11 item 4) */
    for (i = 0; i < 4; i++) {
        int bad = 0;
        CHECK_EQ_STATUS(hfvis_sky_light(&g, ks[i], 1.0f, 1.0f, NULL, out, W), HFVIS_OK);
        for (y = 0; y < H; y++)
            for (x = 0; x < W; x++) bad += !(fabs((double)out[y * W + x] - 1.0) <= LIGHT_TOL);
        CHECK(bad == 0);
        CHECK_EQ_STATUS(hfvis_sky_view_factor(&g, ks[i], NULL, out, W), HFVIS_OK);
        for (y = 0, bad = 0; y < H; y++)
            for (x = 0; x < W; x++) bad += !(fabs((double)out[y * W + x] - 1.0) <= LIGHT_TOL);
        CHECK(bad == 0);
    }
    /* the same from the stored map, everywhere */
    CHECK_EQ_STATUS(hfvis_sky_light_from_map(&g, K, 0.0, map, 1.0f, 1.0f, NULL, out, W), HFVIS_OK);
    for (i = 0, ok = 1; i < W * H; i++) ok &= fabs((double)out[i] - 1.0) <= LIGHT_TOL;
    CHECK(ok);
    CHECK_EQ_STATUS(hfvis_sky_view_factor_from_map(&g, K, map, out, W), HFVIS_OK);
    for (i = 0, ok = 1; i < W * H; i++) ok &= fabs((double)out[i] - 1.0) <= LIGHT_TOL;
    CHECK(ok);
    /* sky radiance and albedo scale the result */
    CHECK_EQ_STATUS(hfvis_sky_light(&g, 4, 2.0f, 0.25f, NULL, out, W), HFVIS_OK);
    CHECK_NEAR(out[5 * W + 7], 0.5, LIGHT_TOL, 0);
    free(map);
}

/* ---------------------------------------------------------------------------------------- */
/* 7. Tilted plane (spec §12.2)                                                              */
/* ---------------------------------------------------------------------------------------- */

/* The spec's table values are rounded to 6 decimals: |table - exact| <= 5e-7. */
#define TABLE_ROUND_TOL 5e-7
/* The raw lattice stores alpha as float: the spec's 1e-9 on t is invisible through a float
 * output, whose rounding (half an ulp, 2^-24 |alpha|) is the limit; allow one ulp. */
#define LATTICE_ALPHA_REL_TOL (double)FLT_EPSILON
#define LATTICE_ALPHA_ABS_TOL 1e-12
/* Wrong-sign limit: the flipped sum converges exponentially in K to 1/(1+g^2); at K = 16 the
 * discrete closed form differs from the limit by 1.5e-10 (g = 0.5) and 1.8e-4 (g = 2). */
#define SIGN_LIMIT_TOL 5e-4

static double sector_sum_plane(int K, double g, double q, double az0, int flip)
{
    /* [P1] Eq. 5 with the clamp of spec §5.2 on the plane h = g x + q y: N = (-g,-q,1)/|.|,
     * t_k = g cos psi_k + q sin psi_k (or its negative when the opposite direction's horizon
     * is fed in), clamped up to the tangent plane t >= -a_k/N_z. */
    double len = sqrt(1.0 + g * g + q * q), nx = -g / len, ny = -q / len, nz = 1.0 / len, sum = 0.0;
    int k;
    for (k = 0; k < K; k++) {
        double psi = az0 + 2.0 * PI * k / K, a = nx * cos(psi) + ny * sin(psi);
        double t = g * cos(psi) + q * sin(psi), th;
        if (flip) t = -t;
        if (t < -a / nz) t = -a / nz;
        th = 0.5 * PI - atan(t);
        sum += nz / K * sin(th) * sin(th) + sin(PI / K) / PI * a * (th - 0.5 * sin(2.0 * th));
    }
    return sum;
}

static float *make_plane(int w, int h, double g, double q)
{
    float *z = (float *)malloc(sizeof(float) * (size_t)w * (size_t)h);
    int x, y;
    if (z)
        for (y = 0; y < h; y++)
            for (x = 0; x < w; x++) z[y * w + x] = (float)(g * x + q * y); /* exact in float */
    return z;
}

TEST(tilted_plane_light)
{
    enum { W = 32, H = 28 };
    static const int ks[4] = { 4, 8, 16, 64 };
    static const double gs[2] = { 0.5, 2.0 };
    static const double table[2][4] = { { 0.978851, 0.994897, 0.998717, 0.999920 },
                                        { 0.875157, 0.976775, 0.994842, 0.999679 } };
    float out[W * H], *map = (float *)malloc(sizeof(float) * 64 * W * H);
    int gi, ki, x, y;
    CHECK(map != NULL);
    if (!map) return;
    for (gi = 0; gi < 2; gi++) {
        double g = gs[gi];
        float *z = make_plane(W, H, g, 0.0);
        hfvis_grid grid;
        CHECK(z != NULL);
        if (!z) break;
        grid.z = z; grid.width = W; grid.height = H; grid.stride = W; grid.cell_size = 1.0;
        for (ki = 0; ki < 4; ki++) {
            int K = ks[ki], bad_fused = 0, bad_map = 0;
            double exact = sector_sum_plane(K, g, 0.0, 0.0, 0);
            double worst_f = 0.0, worst_m = 0.0;
            CHECK_NEAR(exact, table[gi][ki], TABLE_ROUND_TOL, 0);
            CHECK_EQ_STATUS(hfvis_sky_light(&grid, K, 1.0f, 1.0f, NULL, out, W), HFVIS_OK);
            for (y = 0; y < H; y++)
                for (x = 0; x < W; x++)
                    if (interior(x, y, W, H)) {
                        double e = fabs((double)out[y * W + x] - table[gi][ki]);
                        if (e > worst_f) worst_f = e;
                        bad_fused += !(e <= LIGHT_TOL);
                    }
            CHECK_EQ_STATUS(hfvis_horizon_map(&grid, K, NULL, map), HFVIS_OK);
            CHECK_EQ_STATUS(hfvis_sky_light_from_map(&grid, K, 0.0, map, 1.0f, 1.0f, NULL, out, W),
                            HFVIS_OK);
            for (y = 0; y < H; y++)
                for (x = 0; x < W; x++)
                    if (interior(x, y, W, H)) {
                        double e = fabs((double)out[y * W + x] - table[gi][ki]);
                        if (e > worst_m) worst_m = e;
                        bad_map += !(e <= LIGHT_TOL);
                    }
            if (bad_fused || bad_map)
                fprintf(stderr, "  tilted g=%g K=%d: worst fused %.3g, from map %.3g\n", g, K,
                        worst_f, worst_m);
            CHECK(bad_fused == 0);
            CHECK(bad_map == 0);
        }
        /* sign/direction detector: the map of the opposite directions (azimuth0 + pi) read as
         * if it were made with azimuth0 = 0 gives t_k = -g cos psi_k, clamped to g|cos psi_k|:
         * Eq. 5 -> 1/(1+g^2) as K grows (0.8 for g = 0.5), far from the correct ~0.99 */
        {
            hfvis_sweep_options o = hfvis_sweep_options_default();
            double flipped = sector_sum_plane(16, g, 0.0, 0.0, 1), worst = 0.0;
            int bad = 0;
            o.azimuth0_rad = PI;
            CHECK_NEAR(flipped, 1.0 / (1.0 + g * g), SIGN_LIMIT_TOL, 0);
            CHECK_EQ_STATUS(hfvis_horizon_map(&grid, 16, &o, map), HFVIS_OK);
            CHECK_EQ_STATUS(hfvis_sky_light_from_map(&grid, 16, 0.0, map, 1.0f, 1.0f, NULL, out, W),
                            HFVIS_OK);
            for (y = 0; y < H; y++)
                for (x = 0; x < W; x++)
                    if (interior(x, y, W, H)) {
                        double v = (double)out[y * W + x];
                        if (fabs(v - flipped) > worst) worst = fabs(v - flipped);
                        bad += !(fabs(v - flipped) <= LIGHT_TOL) ||
                               !(fabs(v - 1.0 / (1.0 + g * g)) <= SIGN_LIMIT_TOL);
                    }
            if (bad) fprintf(stderr, "  flipped g=%g: worst |v - closed form| %.3g\n", g, worst);
            CHECK(bad == 0);
        }
        free(z);
    }
    free(map);
}

TEST(tilted_plane_lattice)
{
    /* raw lattice: every non-first node of every line has tan(alpha) = g cos psi + q sin psi
     * exactly (the samples along a line are collinear; spec §12.2), NaN outside the domain */
    enum { W = 40, H = 33 };
    static const double gq[4][2] = { { 0.5, 0.0 }, { 2.0, 0.0 }, { 0.5, 0.25 }, { -0.75, -1.25 } };
    int p, a, bad = 0, nodes = 0;
    rng_seed(31337);
    for (p = 0; p < 4; p++) {
        double g = gq[p][0], q = gq[p][1];
        float *z = make_plane(W, H, g, q), *lat;
        hfvis_grid grid;
        CHECK(z != NULL);
        if (!z) return;
        grid.z = z; grid.width = W; grid.height = H; grid.stride = W; grid.cell_size = 1.0;
        for (a = 0; a < 12; a++) {
            /* 0, pi/4, pi/2, 5pi/4, then random azimuths in [-pi, 3pi) */
            double psi = a < 4 ? 0.25 * PI * a + (a == 3 ? 0.5 * PI : 0.0)
                               : (rng_unit() * 2.0 - 0.5) * 2.0 * PI;
            double want = atan(g * cos(psi) + q * sin(psi));
            hfvis_lattice L;
            int j, i, cols;
            CHECK_EQ_STATUS(hfvis_lattice_init(&L, W, H, psi), HFVIS_OK);
            lat = (float *)malloc(sizeof(float) * hfvis_lattice_size(&L));
            CHECK(lat != NULL);
            if (!lat) { free(z); return; }
            CHECK_EQ_STATUS(hfvis_horizon_lattice(&grid, psi, NULL, lat), HFVIS_OK);
            cols = L.i_max - L.i_min + 1;
            for (j = L.j_min; j <= L.j_max; j++) {
                int i0 = 0, i1 = -1;
                hfvis_lattice_line(&L, j, &i0, &i1);
                for (i = L.i_min; i <= L.i_max; i++) {
                    double v = (double)lat[(size_t)(j - L.j_min) * (size_t)cols + (size_t)(i - L.i_min)];
                    int ok;
                    if (i < i0 || i > i1) ok = isnan(v);          /* outside the domain */
                    else if (i == i0) ok = v == -0.5 * PI || v == (double)(float)(-0.5 * PI);
                    else {
                        ok = fabs(v - want) <= LATTICE_ALPHA_ABS_TOL + LATTICE_ALPHA_REL_TOL * fabs(want);
                        nodes++;
                    }
                    if (!ok) {
                        if (bad < 3)
                            fprintf(stderr, "  lattice g=%g q=%g psi=%g node (%d,%d): %.9g want %.9g\n",
                                    g, q, psi, i, j, v, i == i0 ? -0.5 * PI : want);
                        bad++;
                    }
                }
            }
            free(lat);
        }
        free(z);
    }
    CHECK(nodes > 4 * 12 * 1000);
    CHECK(bad == 0);
}


/* ---------------------------------------------------------------------------------------- */
/* 8. V-valley (spec §12.3) and 9. L1 pyramid pit (spec §12.4), per-receiver oracle          */
/* ---------------------------------------------------------------------------------------- */

/* A float elevation <= pi/2 is within 2^-24 * pi/2 = 9.4e-8 of its double; the double march
 * arithmetic adds ~1e-15. Two float ulps. */
#define REF_ALPHA_TOL 2.4e-7
/* V from float elevations: d(cos^2 a)/da <= 1, so the error is <= REF_ALPHA_TOL; the spec's
 * values carry 6-7 significant digits (<= 5e-7 rounding). */
#define V_TOL 1e-6
/* Finite-domain pipeline (map + gather) vs the §12.3 finite-domain closed form built from
 * the per-receiver ray: the lattice line through the receiver ends up to ~1 cell from the
 * ray's exit, moving t by 2 s delta / r^2 per cell (~3e-4 rad at r ~ 80, delta = 3) in the
 * cross-valley gathered directions, weighted <= 1/K in Eq. 5 (observed 1.3e-5). */
#define FLANK_PIPELINE_TOL 1e-4

/* V = (1/K) sum_k cos^2(max(alpha_k, 0)) = (1/K) sum 1/(1+t_k^2) (spec §12 notation) */
static double v_from_alpha(const float *alpha, int K)
{
    double v = 0.0;
    int k;
    for (k = 0; k < K; k++) {
        double a = (double)alpha[k] > 0.0 ? (double)alpha[k] : 0.0;
        v += cos(a) * cos(a);
    }
    return v / K;
}

static double eq5_sum(int K, double nx, double ny, double nz, const double *t)
{
    /* [P1] Eq. 5 with the tangent clamp (spec §5.2-5.3), psi_k = 2 pi k / K */
    double sum = 0.0;
    int k;
    for (k = 0; k < K; k++) {
        double psi = 2.0 * PI * k / K, a = nx * cos(psi) + ny * sin(psi), tk = t[k], th;
        if (tk < -a / nz) tk = -a / nz;
        th = 0.5 * PI - atan(tk);
        sum += nz / K * sin(th) * sin(th) + sin(PI / K) / PI * a * (th - 0.5 * sin(2.0 * th));
    }
    return sum;
}

TEST(v_valley)
{
    enum { W = 41, H = 41, X0 = 20 };
    static const int ks[2] = { 8, 16 };
    /* §12.3, s = 1: V_K(bottom) and the flank's Eq. 5 value N_z V_K(bottom) */
    static const double v_bottom[2] = { 0.708333, 0.7071078 };
    static const double v_flank[2] = { 0.500867, 0.5000008 };
    hfvis_field f;
    float *z, *map, *out;
    hfvis_grid g;
    int ki;
    memset(&f, 0, sizeof f);
    f.kind = HFVIS_FIELD_V_VALLEY;
    f.x0 = X0;
    f.slope = 1.0;
    z = (float *)malloc(sizeof(float) * W * H);
    map = (float *)malloc(sizeof(float) * 16 * W * H);
    out = (float *)malloc(sizeof(float) * W * H);
    CHECK(z && map && out);
    if (!z || !map || !out) { free(z); free(map); free(out); return; }
    CHECK_EQ_STATUS(hfvis_field_generate(&f, W, H, W, z), HFVIS_OK);
    g.z = z; g.width = W; g.height = H; g.stride = W; g.cell_size = 1.0;
    for (ki = 0; ki < 2; ki++) {
        int K = ks[ki], k, i, bad = 0;
        float alpha[16], pts[2] = { (float)X0, 20.0f };
        double vb, nz = 1.0 / sqrt(2.0);
        /* bottom receiver: t(psi) = s |cos psi| exactly (every sample on a ray is collinear) */
        CHECK_EQ_STATUS(hfvis_horizon_reference(&g, K, NULL, NULL, pts, 1, alpha), HFVIS_OK);
        for (k = 0; k < K; k++)
            CHECK_NEAR(alpha[k], atan(fabs(cos(2.0 * PI * k / K))), REF_ALPHA_TOL, 0);
        vb = v_from_alpha(alpha, K);
        CHECK_NEAR(vb, v_bottom[ki], V_TOL, 0);
        /* flank, infinite extent: the horizon is again atan(s |cos psi|) (uphill the tangent
         * plane, across the valley the far flank at infinity), so a map holding the bottom's
         * elevations everywhere must give Eq. 5 = N_z V_K(bottom) on both flanks */
        for (k = 0; k < K; k++)
            for (i = 0; i < W * H; i++) map[k * W * H + i] = alpha[k];
        CHECK_EQ_STATUS(hfvis_sky_light_from_map(&g, K, 0.0, map, 1.0f, 1.0f, NULL, out, W), HFVIS_OK);
        for (i = 2; i < H - 2; i++) {
            bad += !(fabs((double)out[i * W + X0 + 5] - v_flank[ki]) <= V_TOL);
            bad += !(fabs((double)out[i * W + X0 - 7] - v_flank[ki]) <= V_TOL);
        }
        if (bad) fprintf(stderr, "  flank K=%d: %.9g want %.9g\n", K, (double)out[10 * W + X0 + 5], v_flank[ki]);
        CHECK(bad == 0);
        CHECK_NEAR(nz * vb, v_flank[ki], V_TOL, 0);
    }
    free(z); free(map); free(out);
}

TEST(v_valley_finite_flank)
{
    /* The finite domain (§12.3 third bullet): a flank receiver at delta cells from the bottom
     * sees, across the valley, t = max(-s c, s c - 2 s delta / t_max) with c = |cos psi| and
     * t_max the distance of the farthest sample on the ray; uphill t = s cos psi. The
     * infinite-extent value N_z V_K(bottom) is reached only as O(delta / N): on this 161^2
     * domain the flank gets ~0.5157 (K = 8) instead of 0.500867. */
    enum { N = 161, X0 = 80, YC = 80, DELTA = 3 };
    static const int ks[2] = { 8, 16 };
    hfvis_field f;
    float *z = (float *)malloc(sizeof(float) * N * N), *map = (float *)malloc(sizeof(float) * 16 * N * N);
    float *out = (float *)malloc(sizeof(float) * N * N);
    hfvis_grid g;
    int ki;
    CHECK(z && map && out);
    if (!z || !map || !out) { free(z); free(map); free(out); return; }
    memset(&f, 0, sizeof f);
    f.kind = HFVIS_FIELD_V_VALLEY;
    f.x0 = X0;
    f.slope = 1.0;
    CHECK_EQ_STATUS(hfvis_field_generate(&f, N, N, N, z), HFVIS_OK);
    g.z = z; g.width = N; g.height = N; g.stride = N; g.cell_size = 1.0;
    for (ki = 0; ki < 2; ki++) {
        int K = ks[ki], k, bad = 0;
        float alpha[16], pts[2] = { (float)(X0 + DELTA), (float)YC };
        double t[16], nz = 1.0 / sqrt(2.0), want, got;
        CHECK_EQ_STATUS(hfvis_horizon_reference(&g, K, NULL, NULL, pts, 1, alpha), HFVIS_OK);
        for (k = 0; k < K; k++) {
            double psi = 2.0 * PI * k / K, c = cos(psi), sn = sin(psi), rx = 1e300, ry = 1e300, r;
            /* farthest unit march step inside [0, N-1]^2 */
            if (c > 1e-12) rx = (N - 1 - (X0 + DELTA)) / c;
            if (c < -1e-12) rx = (X0 + DELTA) / -c;
            if (sn > 1e-12) ry = (N - 1 - YC) / sn;
            if (sn < -1e-12) ry = YC / -sn;
            r = floor((rx < ry ? rx : ry) + 1e-9);
            t[k] = c >= 0.0 ? c : fabs(c) - 2.0 * DELTA / r;
            if (t[k] < -fabs(c)) t[k] = -fabs(c);
            if (!(fabs((double)alpha[k] - atan(t[k])) <= REF_ALPHA_TOL)) {
                fprintf(stderr, "  finite flank K=%d k=%d: alpha %.9g want %.9g\n", K, k,
                        (double)alpha[k], atan(t[k]));
                bad++;
            }
        }
        CHECK(bad == 0);
        want = eq5_sum(K, -nz, 0.0, nz, t);
        CHECK_EQ_STATUS(hfvis_horizon_map(&g, K, NULL, map), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_sky_light_from_map(&g, K, 0.0, map, 1.0f, 1.0f, NULL, out, N), HFVIS_OK);
        got = (double)out[YC * N + X0 + DELTA];
        CHECK_NEAR(got, want, FLANK_PIPELINE_TOL, 0);
        CHECK_EQ_STATUS(hfvis_sky_light(&g, K, 1.0f, 1.0f, NULL, out, N), HFVIS_OK);
        CHECK_NEAR(out[YC * N + X0 + DELTA], want, FLANK_PIPELINE_TOL, 0);
        /* and it is measurably above the infinite-extent value */
        CHECK(got > (K == 8 ? 0.500867 : 0.5000008) + 0.01);
    }
    free(z); free(map); free(out);
}

TEST(l1_pit)
{
    /* apex of h = s(|x-x0| + |y-y0|), s = 1: t(psi) = s(|cos psi| + |sin psi|) exactly;
     * V_K = (1/K) sum 1/(1+t_k^2): K = 8 -> (4/2 + 4/3)/8 = 5/12 */
    enum { W = 45, H = 39 };
    static const int ks[3] = { 8, 16, 32 };
    static const double want[3] = { 5.0 / 12.0, 0.393032, 0.386943 };
    hfvis_field f;
    float z[W * H], alpha[32], pts[2] = { 22.0f, 19.0f };
    hfvis_grid g;
    int ki, k;
    memset(&f, 0, sizeof f);
    f.kind = HFVIS_FIELD_L1_PIT;
    f.x0 = 22.0;
    f.y0 = 19.0;
    f.slope = 1.0;
    CHECK_EQ_STATUS(hfvis_field_generate(&f, W, H, W, z), HFVIS_OK);
    g.z = z; g.width = W; g.height = H; g.stride = W; g.cell_size = 1.0;
    for (ki = 0; ki < 3; ki++) {
        int K = ks[ki], bad = 0;
        CHECK_EQ_STATUS(hfvis_horizon_reference(&g, K, NULL, NULL, pts, 1, alpha), HFVIS_OK);
        for (k = 0; k < K; k++) {
            double psi = 2.0 * PI * k / K;
            bad += !(fabs((double)alpha[k] - atan(fabs(cos(psi)) + fabs(sin(psi)))) <= REF_ALPHA_TOL);
        }
        CHECK(bad == 0);
        CHECK_NEAR(v_from_alpha(alpha, K), want[ki], V_TOL, 0);
    }
}


/* ---------------------------------------------------------------------------------------- */
/* 10. Golden horizon map                                                                    */
/* ---------------------------------------------------------------------------------------- */

/* Elevations go through atan/sin/cos of the C library: different libms differ at ~1e-15
 * relative, which can flip a float rounding; 1e-6 rad is far above that and far below any
 * algorithmic change. */
#define GOLDEN_TOL 1e-6
#define GOLDEN_PATH "test/golden/horizon_fbm32_k8.pfm"
#define GOLDEN_ACTUAL "build/horizon_fbm32_k8_actual.pfm"

TEST(golden_horizon_map)
{
    /* 32 x 32 fBm (seed 7, amplitude 6, wavelength 8), K = 8: the 8 planes stored as one
     * 32 x 256 grey PFM, plane k in rows 32k .. 32k+31 */
    enum { W = 32, H = 32, K = 8 };
    float *z = make_fbm(W, H, 7, 6.0, 8.0), *map = (float *)malloc(sizeof(float) * K * W * H);
    hfvis_grid g;
    CHECK(z && map);
    if (!z || !map) { free(z); free(map); return; }
    g.z = z; g.width = W; g.height = H; g.stride = W; g.cell_size = 1.0;
    CHECK_EQ_STATUS(hfvis_horizon_map(&g, K, NULL, map), HFVIS_OK);
    if (test_update_golden) {
        CHECK_EQ_STATUS(hfvis_pfm_save(GOLDEN_PATH, map, W, K * H, 1, W), HFVIS_OK);
        printf("     wrote %s\n", GOLDEN_PATH);
    } else {
        float *gold = NULL;
        hfvis_image_info info;
        hfvis_status st = hfvis_image_load(GOLDEN_PATH, NULL, &gold, &info);
        CHECK_EQ_STATUS(st, HFVIS_OK);
        if (st == HFVIS_OK) {
            int i, bad = 0;
            double worst = 0.0;
            CHECK(info.width == W && info.height == K * H && info.channels == 1);
            if (info.width == W && info.height == K * H && info.channels == 1)
                for (i = 0; i < K * W * H; i++) {
                    double d = fabs((double)map[i] - (double)gold[i]);
                    if (isnan(map[i]) != isnan(gold[i]) || d > GOLDEN_TOL) bad++;
                    if (d > worst) worst = d;
                }
            else bad = 1;
            if (bad) {
                hfvis_pfm_save(GOLDEN_ACTUAL, map, W, K * H, 1, W);
                fprintf(stderr, "  golden: %d values differ (worst %.3g rad); wrote %s; if the change is "
                        "intended, run make update-golden\n", bad, worst, GOLDEN_ACTUAL);
            }
            CHECK(bad == 0);
        } else {
            fprintf(stderr, "  golden: cannot load %s (run from the repository root); "
                    "run make update-golden\n", GOLDEN_PATH);
        }
        hfvis_free(NULL, gold);
    }
    free(z);
    free(map);
}


/* ---------------------------------------------------------------------------------------- */
/* 11. Bad arguments: HFVIS_ERR_INVALID_ARGUMENT and outputs untouched (hfvis.h Errors)      */
/* ---------------------------------------------------------------------------------------- */

#define SENT_N 4096
static float sent_buf[SENT_N];
static float sent_ref[SENT_N];

static float *sent_fill(void)
{
    memset(sent_buf, 0xA7, sizeof sent_buf);
    memcpy(sent_ref, sent_buf, sizeof sent_buf);
    return sent_buf;
}

/* status must be INVALID_ARGUMENT and the sentinel output unchanged; names the failing case */
static int bad_ok(hfvis_status st, const char *what, int idx)
{
    int ok = st == HFVIS_ERR_INVALID_ARGUMENT && memcmp(sent_buf, sent_ref, sizeof sent_buf) == 0;
    if (!ok)
        fprintf(stderr, "  bad args %s #%d: status %s, output %s\n", what, idx,
                hfvis_status_string(st),
                memcmp(sent_buf, sent_ref, sizeof sent_buf) == 0 ? "untouched" : "MODIFIED");
    return ok;
}

enum { BAD_GRIDS = 11 };

/* The bad grid variants of an 8 x 8 grid; NULL for variant 0. */
static const hfvis_grid *bad_grid(int i, hfvis_grid *store, const float *z)
{
    store->z = z; store->width = 8; store->height = 8; store->stride = 8; store->cell_size = 1.0;
    switch (i) {
    case 0: return NULL;
    case 1: store->z = NULL; break;
    case 2: store->width = 0; break;
    case 3: store->height = 0; break;
    case 4: store->width = -3; break;
    case 5: store->stride = 7; break;                   /* stride < width */
    case 6: store->cell_size = 0.0; break;
    case 7: store->cell_size = (double)NAN; break;
    case 8: store->cell_size = -1.0; break;
    case 9: store->cell_size = (double)INFINITY; break;
    default: store->height = -1; break;
    }
    return store;
}

static double bad_fn(void *user, double x, double y) { (void)user; return x + y; }

TEST(bad_arguments)
{
    float z[64], map[8 * 64], pts[2] = { 3.0f, 3.0f };
    hfvis_grid gs, good;
    hfvis_sweep_options o;
    hfvis_march_options mo;
    int i;
    const double nan = (double)NAN, inf = (double)INFINITY;
    for (i = 0; i < 64; i++) z[i] = (float)(i % 5);
    for (i = 0; i < 8 * 64; i++) map[i] = 0.1f;
    good.z = z; good.width = 8; good.height = 8; good.stride = 8; good.cell_size = 1.0;

    /* --- every grid-taking function with every bad grid */
    for (i = 0; i < BAD_GRIDS; i++) {
        const hfvis_grid *g = bad_grid(i, &gs, z);
        sent_fill(); CHECK(bad_ok(hfvis_horizon_lattice(g, 0.3, NULL, sent_buf), "lattice grid", i));
        sent_fill(); CHECK(bad_ok(hfvis_horizon_lattice_naive(g, 0.3, NULL, sent_buf), "lattice_naive grid", i));
        sent_fill(); CHECK(bad_ok(hfvis_horizon_direction(g, 8, 1, NULL, sent_buf, 8), "direction grid", i));
        sent_fill(); CHECK(bad_ok(hfvis_horizon_map(g, 8, NULL, sent_buf), "map grid", i));
        sent_fill(); CHECK(bad_ok(hfvis_horizon_reference(g, 8, NULL, NULL, pts, 1, sent_buf), "reference grid", i));
        sent_fill(); CHECK(bad_ok(hfvis_sky_light(g, 8, 1.0f, 1.0f, NULL, sent_buf, 8), "sky_light grid", i));
        sent_fill(); CHECK(bad_ok(hfvis_sky_light_from_map(g, 8, 0.0, map, 1.0f, 1.0f, NULL, sent_buf, 8), "sky_light_from_map grid", i));
        sent_fill(); CHECK(bad_ok(hfvis_sky_view_factor(g, 8, NULL, sent_buf, 8), "svf grid", i));
        sent_fill(); CHECK(bad_ok(hfvis_sky_view_factor_from_map(g, 8, map, sent_buf, 8), "svf_from_map grid", i));
        sent_fill(); CHECK(bad_ok(hfvis_sun_visibility(g, 0.5, 0.3, 0.0, NULL, sent_buf, 8), "sun grid", i));
        sent_fill(); CHECK(bad_ok(hfvis_normals_compute(g, sent_buf), "normals grid", i));
    }

    /* --- NULL outputs (and NULL map inputs) */
    CHECK_EQ_STATUS(hfvis_horizon_lattice(&good, 0.3, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_horizon_lattice_naive(&good, 0.3, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_horizon_direction(&good, 8, 1, NULL, NULL, 8), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_horizon_map(&good, 8, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_horizon_reference(&good, 8, NULL, NULL, pts, 1, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_horizon_reference_fn(bad_fn, NULL, 8, 8, 1.0, 8, NULL, NULL, pts, 1, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_sky_light(&good, 8, 1.0f, 1.0f, NULL, NULL, 8), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_sky_light_from_map(&good, 8, 0.0, map, 1.0f, 1.0f, NULL, NULL, 8), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_sky_view_factor(&good, 8, NULL, NULL, 8), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_sky_view_factor_from_map(&good, 8, map, NULL, 8), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_sun_visibility(&good, 0.5, 0.3, 0.0, NULL, NULL, 8), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_normals_compute(&good, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    sent_fill(); CHECK(bad_ok(hfvis_sky_light_from_map(&good, 8, 0.0, NULL, 1.0f, 1.0f, NULL, sent_buf, 8), "sky_light_from_map map NULL", 0));
    sent_fill(); CHECK(bad_ok(hfvis_sky_view_factor_from_map(&good, 8, NULL, sent_buf, 8), "svf_from_map map NULL", 0));
    sent_fill(); CHECK(bad_ok(hfvis_horizon_reference(&good, 8, NULL, NULL, NULL, 1, sent_buf), "reference points NULL", 0));
    sent_fill(); CHECK(bad_ok(hfvis_horizon_reference_fn(bad_fn, NULL, 8, 8, 1.0, 8, NULL, NULL, NULL, 1, sent_buf), "reference_fn points NULL", 0));

    /* --- out_stride < width */
    sent_fill(); CHECK(bad_ok(hfvis_horizon_direction(&good, 8, 1, NULL, sent_buf, 7), "direction stride", 0));
    sent_fill(); CHECK(bad_ok(hfvis_sky_light(&good, 8, 1.0f, 1.0f, NULL, sent_buf, 7), "sky_light stride", 0));
    sent_fill(); CHECK(bad_ok(hfvis_sky_light_from_map(&good, 8, 0.0, map, 1.0f, 1.0f, NULL, sent_buf, 7), "sky_light_from_map stride", 0));
    sent_fill(); CHECK(bad_ok(hfvis_sky_view_factor(&good, 8, NULL, sent_buf, 7), "svf stride", 0));
    sent_fill(); CHECK(bad_ok(hfvis_sky_view_factor_from_map(&good, 8, map, sent_buf, 7), "svf_from_map stride", 0));
    sent_fill(); CHECK(bad_ok(hfvis_sun_visibility(&good, 0.5, 0.3, 0.0, NULL, sent_buf, 7), "sun stride", 0));

    /* --- K < 1 and k out of range */
    for (i = 0; i < 2; i++) {
        int K = i ? -4 : 0;
        sent_fill(); CHECK(bad_ok(hfvis_horizon_direction(&good, K, 0, NULL, sent_buf, 8), "direction K", i));
        sent_fill(); CHECK(bad_ok(hfvis_horizon_map(&good, K, NULL, sent_buf), "map K", i));
        sent_fill(); CHECK(bad_ok(hfvis_horizon_reference(&good, K, NULL, NULL, pts, 1, sent_buf), "reference K", i));
        sent_fill(); CHECK(bad_ok(hfvis_horizon_reference_fn(bad_fn, NULL, 8, 8, 1.0, K, NULL, NULL, pts, 1, sent_buf), "reference_fn K", i));
        sent_fill(); CHECK(bad_ok(hfvis_sky_light(&good, K, 1.0f, 1.0f, NULL, sent_buf, 8), "sky_light K", i));
        sent_fill(); CHECK(bad_ok(hfvis_sky_light_from_map(&good, K, 0.0, map, 1.0f, 1.0f, NULL, sent_buf, 8), "sky_light_from_map K", i));
        sent_fill(); CHECK(bad_ok(hfvis_sky_view_factor(&good, K, NULL, sent_buf, 8), "svf K", i));
        sent_fill(); CHECK(bad_ok(hfvis_sky_view_factor_from_map(&good, K, map, sent_buf, 8), "svf_from_map K", i));
    }
    sent_fill(); CHECK(bad_ok(hfvis_horizon_direction(&good, 8, 8, NULL, sent_buf, 8), "direction k = K", 0));
    sent_fill(); CHECK(bad_ok(hfvis_horizon_direction(&good, 8, -1, NULL, sent_buf, 8), "direction k = -1", 0));
    sent_fill(); CHECK(bad_ok(hfvis_horizon_direction(&good, 6, 6, NULL, sent_buf, 8), "direction k = K (K % 4 != 0)", 0));

    /* --- non-finite azimuths and parameters */
    for (i = 0; i < 3; i++) {
        double bad = i == 0 ? nan : i == 1 ? inf : -inf;
        hfvis_lattice L;
        unsigned char lref[sizeof(hfvis_lattice)];
        o = hfvis_sweep_options_default();
        o.azimuth0_rad = bad;
        sent_fill(); CHECK(bad_ok(hfvis_horizon_lattice(&good, bad, NULL, sent_buf), "lattice azimuth", i));
        sent_fill(); CHECK(bad_ok(hfvis_horizon_lattice_naive(&good, bad, NULL, sent_buf), "lattice_naive azimuth", i));
        sent_fill(); CHECK(bad_ok(hfvis_horizon_direction(&good, 8, 1, &o, sent_buf, 8), "direction azimuth0", i));
        sent_fill(); CHECK(bad_ok(hfvis_horizon_map(&good, 8, &o, sent_buf), "map azimuth0", i));
        sent_fill(); CHECK(bad_ok(hfvis_horizon_reference(&good, 8, &o, NULL, pts, 1, sent_buf), "reference azimuth0", i));
        sent_fill(); CHECK(bad_ok(hfvis_horizon_reference_fn(bad_fn, NULL, 8, 8, 1.0, 8, &o, NULL, pts, 1, sent_buf), "reference_fn azimuth0", i));
        sent_fill(); CHECK(bad_ok(hfvis_sky_light(&good, 8, 1.0f, 1.0f, &o, sent_buf, 8), "sky_light azimuth0", i));
        sent_fill(); CHECK(bad_ok(hfvis_sky_light_from_map(&good, 8, bad, map, 1.0f, 1.0f, NULL, sent_buf, 8), "sky_light_from_map azimuth0", i));
        sent_fill(); CHECK(bad_ok(hfvis_sky_view_factor(&good, 8, &o, sent_buf, 8), "svf azimuth0", i));
        sent_fill(); CHECK(bad_ok(hfvis_sun_visibility(&good, bad, 0.3, 0.0, NULL, sent_buf, 8), "sun azimuth", i));
        sent_fill(); CHECK(bad_ok(hfvis_sun_visibility(&good, 0.5, bad, 0.0, NULL, sent_buf, 8), "sun elevation", i));
        sent_fill(); CHECK(bad_ok(hfvis_sun_visibility(&good, 0.5, 0.3, bad, NULL, sent_buf, 8), "sun radius", i));
        sent_fill(); CHECK(bad_ok(hfvis_sun_visibility(&good, 0.5, 0.3, 0.0, &o, sent_buf, 8), "sun azimuth0 opts", i));
        sent_fill(); CHECK(bad_ok(hfvis_sky_light(&good, 8, (float)bad, 1.0f, NULL, sent_buf, 8), "sky_light sky", i));
        sent_fill(); CHECK(bad_ok(hfvis_sky_light(&good, 8, 1.0f, (float)bad, NULL, sent_buf, 8), "sky_light albedo", i));
        sent_fill(); CHECK(bad_ok(hfvis_sky_light_from_map(&good, 8, 0.0, map, (float)bad, 1.0f, NULL, sent_buf, 8), "sky_light_from_map sky", i));
        memset(&L, 0x3c, sizeof L);
        memcpy(lref, &L, sizeof L);
        CHECK_EQ_STATUS(hfvis_lattice_init(&L, 8, 8, bad), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK(memcmp(&L, lref, sizeof L) == 0);
    }
    /* the sun's angular radius must not be negative */
    sent_fill(); CHECK(bad_ok(hfvis_sun_visibility(&good, 0.5, 0.3, -0.01, NULL, sent_buf, 8), "sun radius < 0", 0));

    /* --- unknown border mode, negative border_cells, bad direction ranges */
    for (i = 0; i < 2; i++) {
        o = hfvis_sweep_options_default();
        if (i == 0) o.border = (hfvis_border)99; else o.border_cells = -1;
        sent_fill(); CHECK(bad_ok(hfvis_horizon_lattice(&good, 0.3, &o, sent_buf), "lattice border", i));
        sent_fill(); CHECK(bad_ok(hfvis_horizon_lattice_naive(&good, 0.3, &o, sent_buf), "lattice_naive border", i));
        sent_fill(); CHECK(bad_ok(hfvis_horizon_direction(&good, 8, 1, &o, sent_buf, 8), "direction border", i));
        sent_fill(); CHECK(bad_ok(hfvis_horizon_map(&good, 8, &o, sent_buf), "map border", i));
        sent_fill(); CHECK(bad_ok(hfvis_horizon_reference(&good, 8, &o, NULL, pts, 1, sent_buf), "reference border", i));
        sent_fill(); CHECK(bad_ok(hfvis_sky_light(&good, 8, 1.0f, 1.0f, &o, sent_buf, 8), "sky_light border", i));
        sent_fill(); CHECK(bad_ok(hfvis_sky_view_factor(&good, 8, &o, sent_buf, 8), "svf border", i));
        sent_fill(); CHECK(bad_ok(hfvis_sun_visibility(&good, 0.5, 0.3, 0.0, &o, sent_buf, 8), "sun border", i));
    }
    for (i = 0; i < 5; i++) {
        /* begin >= end, begin < 0, end > K */
        static const int be[5][2] = { { 3, 3 }, { 5, 2 }, { -1, 4 }, { 0, 9 }, { 8, 8 } };
        o = hfvis_sweep_options_default();
        o.direction_begin = be[i][0];
        o.direction_end = be[i][1];
        sent_fill(); CHECK(bad_ok(hfvis_sky_light(&good, 8, 1.0f, 1.0f, &o, sent_buf, 8), "sky_light directions", i));
        sent_fill(); CHECK(bad_ok(hfvis_sky_view_factor(&good, 8, &o, sent_buf, 8), "svf directions", i));
    }

    /* --- march options and counts of the oracles */
    memset(&mo, 0, sizeof mo);
    for (i = 0; i < 4; i++) {
        mo.step_cells = i == 0 ? -1.0 : i == 1 ? nan : 0.0;
        mo.max_distance_cells = i == 2 ? -1.0 : i == 3 ? nan : 0.0;
        sent_fill(); CHECK(bad_ok(hfvis_horizon_reference(&good, 8, NULL, &mo, pts, 1, sent_buf), "reference march", i));
        sent_fill(); CHECK(bad_ok(hfvis_horizon_reference_fn(bad_fn, NULL, 8, 8, 1.0, 8, NULL, &mo, pts, 1, sent_buf), "reference_fn march", i));
    }
    sent_fill(); CHECK(bad_ok(hfvis_horizon_reference_fn(NULL, NULL, 8, 8, 1.0, 8, NULL, NULL, pts, 1, sent_buf), "reference_fn fn NULL", 0));
    for (i = 0; i < 6; i++) {
        int w = i == 0 ? 0 : 8, h = i == 1 ? 0 : i == 2 ? -2 : 8;
        double cs = i == 3 ? 0.0 : i == 4 ? nan : i == 5 ? -2.0 : 1.0;
        sent_fill(); CHECK(bad_ok(hfvis_horizon_reference_fn(bad_fn, NULL, w, h, cs, 8, NULL, NULL, pts, 1, sent_buf), "reference_fn size/cell", i));
    }

    /* --- hfvis_field_generate */
    {
        hfvis_field f;
        memset(&f, 0, sizeof f);
        f.kind = HFVIS_FIELD_PLANE;
        sent_fill(); CHECK(bad_ok(hfvis_field_generate(NULL, 8, 8, 8, sent_buf), "field NULL", 0));
        CHECK_EQ_STATUS(hfvis_field_generate(&f, 8, 8, 8, NULL), HFVIS_ERR_INVALID_ARGUMENT);
        sent_fill(); CHECK(bad_ok(hfvis_field_generate(&f, 0, 8, 8, sent_buf), "field width 0", 0));
        sent_fill(); CHECK(bad_ok(hfvis_field_generate(&f, 8, 0, 8, sent_buf), "field height 0", 0));
        sent_fill(); CHECK(bad_ok(hfvis_field_generate(&f, 8, 8, 7, sent_buf), "field stride", 0));
        f.kind = (hfvis_field_kind)99;
        sent_fill(); CHECK(bad_ok(hfvis_field_generate(&f, 8, 8, 8, sent_buf), "field kind 99", 0));
        f.kind = (hfvis_field_kind)0;
        sent_fill(); CHECK(bad_ok(hfvis_field_generate(&f, 8, 8, 8, sent_buf), "field kind 0", 0));
        f.kind = HFVIS_FIELD_V_VALLEY;
        f.slope = nan;
        sent_fill(); CHECK(bad_ok(hfvis_field_generate(&f, 8, 8, 8, sent_buf), "field slope NaN", 0));
        f.slope = 1.0;
        f.x0 = inf;
        sent_fill(); CHECK(bad_ok(hfvis_field_generate(&f, 8, 8, 8, sent_buf), "field x0 inf", 0));
        f.x0 = 0.0;
        f.height = nan;
        sent_fill(); CHECK(bad_ok(hfvis_field_generate(&f, 8, 8, 8, sent_buf), "field height NaN", 0));
        memset(&f, 0, sizeof f);
        f.kind = HFVIS_FIELD_FBM;
        f.amplitude = 1.0;
        f.wavelength = 0.0; /* must be > 0 */
        sent_fill(); CHECK(bad_ok(hfvis_field_generate(&f, 8, 8, 8, sent_buf), "field FBM wavelength 0", 0));
        f.wavelength = 4.0;
        f.octaves = -1;
        sent_fill(); CHECK(bad_ok(hfvis_field_generate(&f, 8, 8, 8, sent_buf), "field FBM octaves -1", 0));
        memset(&f, 0, sizeof f);
        f.kind = HFVIS_FIELD_HEMISPHERE;
        f.amplitude = 1.0;
        f.radius = 0.0; /* must be > 0 */
        sent_fill(); CHECK(bad_ok(hfvis_field_generate(&f, 8, 8, 8, sent_buf), "field HEMISPHERE radius 0", 0));
    }

    /* --- hfvis_lattice_init sizes and NULL */
    {
        hfvis_lattice L;
        unsigned char lref[sizeof(hfvis_lattice)];
        static const int wh[4][2] = { { 0, 8 }, { 8, 0 }, { -1, 8 }, { 8, -5 } };
        memset(&L, 0x3c, sizeof L);
        memcpy(lref, &L, sizeof L);
        CHECK_EQ_STATUS(hfvis_lattice_init(NULL, 8, 8, 0.3), HFVIS_ERR_INVALID_ARGUMENT);
        for (i = 0; i < 4; i++)
            CHECK_EQ_STATUS(hfvis_lattice_init(&L, wh[i][0], wh[i][1], 0.3), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK(memcmp(&L, lref, sizeof L) == 0);
    }

    /* --- a valid call right after all this still works (no hidden state) */
    CHECK_EQ_STATUS(hfvis_horizon_map(&good, 8, NULL, sent_buf), HFVIS_OK);
}

/* PART2-TESTS */

int main(int argc, char **argv)
{
    TEST_INIT(argc, argv);
    RUN(line_horizons_random);
    RUN(line_horizons_small_n);
    RUN(line_horizons_holes);
    RUN(line_horizons_worst_shapes);
    RUN(line_horizons_bad_args);
    RUN(horizon_lattice_vs_naive);
    RUN(lattice_geometry);
    RUN(grid_sample);
    RUN(normals);
    RUN(flat_plane);
    RUN(tilted_plane_light);
    RUN(tilted_plane_lattice);
    RUN(v_valley);
    RUN(v_valley_finite_flank);
    RUN(l1_pit);
    RUN(golden_horizon_map);
    RUN(bad_arguments);
    /* PART2-RUNS */
    return TEST_DONE();
}
