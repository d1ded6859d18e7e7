/* test_tiles.c - the search radius and tiled runs (hfvis.h, "Search radius and tiles"): the
 * windowed sweep against its oracles with the same cut-off (lattice and exact rays) on fBm, urban
 * boxes and terraces, R shorter than a cell and longer than the field, every border; tiles with
 * the halo of hfvis_tile_halo equal to the whole run bit for bit; argument checks. */
#include "test.h"
#include "../examples/fields.h"

#include <stdint.h>

#define PI 3.14159265358979323846
/* The hull's pop and binary-search tests compare cross products where the oracles compare
 * quotients: on slopes equal to the last bits the two may keep different (equally high) casters
 * (as EXACT_HULL_TOL in test_exact.c). */
#define RADIUS_HULL_TOL 1e-12
/* Exact rays under a radius against their supremum oracle: the sweep never above it, and below it
 * on average by at most this (the pieces beyond the first are sampled; test_exact.c SUP_MEAN_DEG). */
#define RADIUS_SUP_MEAN_RAD (HFVIS_EXACT_SUP_MEAN_DEG * PI / 180.0)

#define MAXN (96 * 80)
static float zbuf[MAXN], out_a[16 * MAXN], out_b[16 * MAXN];

/* Field number f (0 fBm, 1 urban boxes, 2 terraces with 80-degree one-cell cliffs, 3 fBm with
 * holes) of W x H, seeded. */
static void make_field(int f, float *z, int W, int H, double cell, uint64_t seed)
{
    int i;
    if (f == 1) fields_urban(z, W, H, W * H / 180 + 2, seed);
    else if (f == 2) fields_terraces(z, W, H, cell, 4.0, 80.0, seed);
    else (void)test_fbm(z, W, H, 8.0 * cell, 9.0, 0, seed);
    if (f == 3) {
        uint64_t s = seed;
        for (i = 0; i < W * H / 40; i++) z[(int)(fields_uniform(&s) * (double)(W * H))] = (float)NAN;
    }
}

static const double radii_cells[] = {0.4, 1.0, 2.5, 7.0, 19.5, 1e6};

/* Lattice mode: hfvis_horizon_lattice with R against hfvis_horizon_lattice_naive with R. */
TEST(lattice_radius_equals_oracle)
{
    static const hfvis_border borders[] = {HFVIS_BORDER_OPEN, HFVIS_BORDER_CLAMP, HFVIS_BORDER_WRAP};
    int f, r, b, a;
    for (f = 0; f < 4; f++) {
        int W = 37 + 6 * f, H = 29 + 4 * f;
        double cell = f == 1 ? 1.0 : 0.5 + 0.3 * (double)f;
        hfvis_grid g = test_grid(zbuf, W, H, cell);
        make_field(f, zbuf, W, H, cell, 11u + (uint64_t)f);
        for (r = 0; r < 6; r++)
            for (b = 0; b < 3; b++)
                for (a = 0; a < 4; a++) {
                    hfvis_sweep_options o = hfvis_sweep_options_default();
                    hfvis_lattice L;
                    double az = 0.3 + 1.7 * (double)a, d;
                    size_t n, unequal;
                    o.border = borders[b];
                    o.border_cells = b == 0 ? 0 : 11;
                    o.max_distance = radii_cells[r] * cell;
                    CHECK_EQ_STATUS(hfvis_lattice_init(&L, W, H, az), HFVIS_OK);
                    n = hfvis_lattice_nodes(&L);
                    CHECK_EQ_STATUS(hfvis_horizon_lattice(&g, az, &o, out_a), HFVIS_OK);
                    CHECK_EQ_STATUS(hfvis_horizon_lattice_naive(&g, az, &o, out_b), HFVIS_OK);
                    d = test_max_diff(out_a, out_b, n, &unequal);
                    CHECK(d >= 0.0 && d <= RADIUS_HULL_TOL);
                    if (d < 0.0 || d > RADIUS_HULL_TOL)
                        printf("     field %d R %g cells border %d az %g: diff %g (%zu)\n", f,
                               radii_cells[r], b, az, d, unequal);
                }
    }
}

/* Exact rays: hfvis_horizon_map with R against hfvis_horizon_exact_naive with R (the supremum
 * within R): never above it, the same holes and "no terrain", close on average. */
TEST(exact_radius_equals_oracle)
{
    static const hfvis_border borders[] = {HFVIS_BORDER_OPEN, HFVIS_BORDER_CLAMP, HFVIS_BORDER_WRAP};
    int f, r, b;
    for (f = 0; f < 4; f++) {
        int W = 33 + 5 * f, H = 27 + 3 * f, K = 12;
        double cell = f == 1 ? 1.0 : 0.5 + 0.3 * (double)f;
        hfvis_grid g = test_grid(zbuf, W, H, cell);
        make_field(f, zbuf, W, H, cell, 21u + (uint64_t)f);
        for (r = 0; r < 6; r++)
            for (b = 0; b < 3; b++) {
                hfvis_sweep_options o = hfvis_sweep_options_default();
                double d, above, below;
                size_t unequal, i;
                o.rays = HFVIS_RAYS_EXACT;
                o.azimuth0_rad = 0.2;
                o.border = borders[b];
                o.border_cells = b == 0 ? 0 : 9;
                o.max_distance = radii_cells[r] * cell;
                CHECK_EQ_STATUS(hfvis_horizon_map(&g, K, &o, out_a), HFVIS_OK);
                CHECK_EQ_STATUS(hfvis_horizon_exact_naive(&g, K, &o, out_b), HFVIS_OK);
                d = test_max_diff(out_a, out_b, (size_t)K * (size_t)(W * H), &unequal);
                CHECK(d >= 0.0); /* the same holes */
                above = 0.0;
                below = 0.0;
                for (i = 0; i < (size_t)K * (size_t)(W * H); i++) {
                    if (isnan(out_a[i])) continue;
                    if ((double)out_a[i] - (double)out_b[i] > above) above = (double)out_a[i] - (double)out_b[i];
                    below += (double)out_b[i] - (double)out_a[i];
                    CHECK((out_a[i] == (float)(-PI / 2)) == (out_b[i] == (float)(-PI / 2)));
                }
                below /= (double)K * (double)(W * H);
                CHECK(above <= RADIUS_HULL_TOL + 1e-6); /* + the float output's rounding */
                CHECK(below <= RADIUS_SUP_MEAN_RAD);
                if (above > RADIUS_HULL_TOL + 1e-6 || below > RADIUS_SUP_MEAN_RAD)
                    printf("     field %d R %g cells border %d: above %g, below %g on average (%zu)\n", f,
                           radii_cells[r], b, above, below, unequal);
            }
    }
}

/* Outputs of one run: kind 0 sky-view factor (K = 16), 1 sky light (K = 12), 2 horizon map
 * (K = 8, all planes), 3 sun visibility, 4 direct light (sun and sky). out holds planes of
 * W x H (stride W). */
#define NKINDS 5
static const int kind_planes[NKINDS] = {1, 1, 8, 1, 1};

static hfvis_status run_kind(int kind, const hfvis_grid *g, const hfvis_sweep_options *o, float *out)
{
    switch (kind) {
    case 0: return hfvis_sky_view_factor(g, 16, o, out, g->width);
    case 1: return hfvis_sky_light(g, 12, 1.0f, 0.8f, o, out, g->width);
    case 2: return hfvis_horizon_map(g, 8, o, out);
    case 3: return hfvis_sun_visibility(g, 0.7, 0.35, 0.02, o, out, g->width);
    default: {
        hfvis_sun sun;
        memset(&sun, 0, sizeof sun);
        sun.azimuth_rad = 2.1;
        sun.elevation_rad = 0.3;
        sun.radius_rad = 0.01;
        sun.irradiance[0] = 3.0f;
        return hfvis_direct_light(g, 8, &sun, 0.5f, NULL, 1, o, out);
    }
    }
}

static int same_bits(float a, float b) { return memcmp(&a, &b, sizeof a) == 0; }

static float tile_z[MAXN], tile_out[8 * MAXN];

/* Cut a seeded field into uneven windows (the edges, 1-cell-wide rows and columns, windows
 * reaching past the field clipped to it), run each on its window plus hfvis_tile_halo, and
 * compare every receiver of the window with the whole run bit for bit. */
static void check_tiles(int field, int W, int H, double cell, double R_cells, hfvis_ray_mode rays)
{
    static const int xs[] = {0, 1, 17, 18, 40, 57, 200}, ys[] = {0, 13, 14, 31, 32, 100};
    hfvis_grid g = test_grid(zbuf, W, H, cell);
    int kind;
    make_field(field, zbuf, W, H, cell, 77u + (uint64_t)field);
    for (kind = 0; kind < NKINDS; kind++) {
        hfvis_sweep_options o = hfvis_sweep_options_default();
        size_t plane = (size_t)W * (size_t)H;
        int xi, yi, halo, bad = 0, windows = 0;
        o.rays = rays;
        o.max_distance = R_cells * cell;
        halo = hfvis_tile_halo(o.max_distance, cell, rays);
        CHECK(halo > 0);
        CHECK_EQ_STATUS(run_kind(kind, &g, &o, out_a), HFVIS_OK);
        for (yi = 0; ys[yi] < H; yi++)
            for (xi = 0; xs[xi] < W; xi++) {
                int x0 = xs[xi], y0 = ys[yi], x1 = xs[xi + 1] < W ? xs[xi + 1] : W,
                    y1 = ys[yi + 1] < H ? ys[yi + 1] : H;
                int tx0 = x0 - halo < 0 ? 0 : x0 - halo, ty0 = y0 - halo < 0 ? 0 : y0 - halo;
                int tx1 = x1 + halo > W ? W : x1 + halo, ty1 = y1 + halo > H ? H : y1 + halo;
                int tw = tx1 - tx0, th = ty1 - ty0, x, y, p;
                hfvis_grid t = test_grid(tile_z, tw, th, cell);
                hfvis_sweep_options to = o;
                for (y = 0; y < th; y++)
                    for (x = 0; x < tw; x++) tile_z[y * tw + x] = zbuf[(ty0 + y) * W + tx0 + x];
                to.origin_x = tx0;
                to.origin_y = ty0;
                to.extent_width = W;
                to.extent_height = H;
                to.receiver_x = x0 - tx0;
                to.receiver_y = y0 - ty0;
                to.receiver_width = x1 - x0;
                to.receiver_height = y1 - y0;
                CHECK_EQ_STATUS(run_kind(kind, &t, &to, tile_out), HFVIS_OK);
                windows++;
                for (p = 0; p < kind_planes[kind]; p++)
                    for (y = y0; y < y1; y++)
                        for (x = x0; x < x1; x++)
                            if (!same_bits(out_a[(size_t)p * plane + (size_t)(y * W + x)],
                                           tile_out[(size_t)p * (size_t)(tw * th) + (size_t)((y - ty0) * tw + x - tx0)])) {
                                if (bad < 3)
                                    printf("     field %d kind %d mode %d R %g: (%d, %d) plane %d: whole %.9g tile %.9g\n",
                                           field, kind, (int)rays, R_cells, x, y, p,
                                           (double)out_a[(size_t)p * plane + (size_t)(y * W + x)],
                                           (double)tile_out[(size_t)p * (size_t)(tw * th) + (size_t)((y - ty0) * tw + x - tx0)]);
                                bad++;
                            }
            }
        CHECK(windows > 12);
        CHECK(bad == 0);
    }
}

TEST(tiles_equal_whole_run_lattice)
{
    int f;
    for (f = 0; f < 4; f++) check_tiles(f, 61, 47, f == 1 ? 1.0 : 0.75, f == 2 ? 0.6 : 6.5, HFVIS_RAYS_LATTICE);
}

TEST(tiles_equal_whole_run_exact)
{
    int f;
    for (f = 0; f < 4; f++) check_tiles(f, 61, 47, f == 1 ? 1.0 : 0.75, f == 2 ? 0.6 : 6.5, HFVIS_RAYS_EXACT);
}

/* The tile of receivers [x0, x0 + w) x [y0, y0 + h) of the W x H field in zbuf with its halo for
 * o's radius (hfvis_tile_halo), copied into tile_z; *to: o with the tile's window and receiver
 * rectangle; the tile's origin and width in *tx0, *ty0, *tw. */
static hfvis_grid tile_with_halo(int W, int H, int x0, int y0, int w, int h, const hfvis_sweep_options *o,
                                 hfvis_sweep_options *to, int *tx0, int *ty0, int *tw)
{
    const int halo = hfvis_tile_halo(o->max_distance, 1.0, o->rays);
    int x, y, th;
    *tx0 = x0 - halo < 0 ? 0 : x0 - halo;
    *ty0 = y0 - halo < 0 ? 0 : y0 - halo;
    *tw = (x0 + w + halo > W ? W : x0 + w + halo) - *tx0;
    th = (y0 + h + halo > H ? H : y0 + h + halo) - *ty0;
    for (y = 0; y < th; y++)
        for (x = 0; x < *tw; x++) tile_z[y * *tw + x] = zbuf[(*ty0 + y) * W + *tx0 + x];
    *to = *o;
    to->origin_x = *tx0;
    to->origin_y = *ty0;
    to->extent_width = W;
    to->extent_height = H;
    to->receiver_x = x0 - *tx0;
    to->receiver_y = y0 - *ty0;
    to->receiver_width = w;
    to->receiver_height = h;
    return test_grid(tile_z, *tw, th, 1.0);
}

/* hfvis_direction_sums (split runs) on a tile: the raw double sums of the window equal the
 * whole run's, both modes. */
TEST(tiles_direction_sums)
{
    static double whole[MAXN], part[MAXN];
    int W = 50, H = 36, mode, x, y;
    hfvis_grid g = test_grid(zbuf, W, H, 1.0);
    make_field(1, zbuf, W, H, 1.0, 3u);
    for (mode = 0; mode < 2; mode++) {
        hfvis_sweep_options o = hfvis_sweep_options_default(), to;
        int x0 = 13, y0 = 9, w = 17, h = 11, tx0, ty0, tw, bad = 0;
        hfvis_grid t;
        o.rays = mode ? HFVIS_RAYS_EXACT : HFVIS_RAYS_LATTICE;
        o.max_distance = 7.5;
        t = tile_with_halo(W, H, x0, y0, w, h, &o, &to, &tx0, &ty0, &tw);
        CHECK_EQ_STATUS(hfvis_direction_sums(&g, 12, HFVIS_SUM_SKY_LIGHT, NULL, NULL, &o, whole), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_direction_sums(&t, 12, HFVIS_SUM_SKY_LIGHT, NULL, NULL, &to, part), HFVIS_OK);
        for (y = y0; y < y0 + h; y++)
            for (x = x0; x < x0 + w; x++)
                bad += memcmp(&whole[y * W + x], &part[(y - ty0) * tw + x - tx0], sizeof(double)) != 0;
        CHECK(bad == 0);
    }
}

/* The same with the far end of the window deciding: a short R on fBm, K not a multiple of 4
 * (directions whose cut at R falls between grid lines at offsets that are not dyadic), every
 * exact-mode kind of sums. The cut's surface point was interpolated at the receiver's grid
 * position plus the offset, so a tile (its own numbering) rounded it differently from the
 * whole raster in the last bits of the double sums. */
TEST(tiles_direction_sums_cut_at_radius)
{
    static const hfvis_sum_kind kinds[] = {HFVIS_SUM_SKY_VIEW, HFVIS_SUM_SKY_LIGHT, HFVIS_SUM_ENV_LIGHT};
    static const int Ks[] = {3, 5, 7};
    static const double radii[] = {1.0, 2.7};
    static const float env_radiance[3 * 4 * 2] = {1.0f, 0.5f, 0.8f, 0.2f, 0.6f, 0.9f, 0.3f, 0.7f,
                                                  0.4f, 1.1f, 0.2f, 0.5f, 0.9f, 0.1f, 0.6f, 0.8f,
                                                  0.7f, 0.3f, 1.2f, 0.4f, 0.5f, 0.6f, 0.2f, 0.9f};
    static double whole[2 * MAXN], part[2 * MAXN];
    const hfvis_env env = {env_radiance, 3, 4, 2};
    int W = 23, H = 17, x0 = 5, y0 = 4, w = 4, h = 4, ki, Ki, ri, x, y, c, bad = 0;
    hfvis_grid g = test_grid(zbuf, W, H, 1.0);
    make_field(0, zbuf, W, H, 1.0, 99u);
    for (ki = 0; ki < 3; ki++)
        for (Ki = 0; Ki < 3; Ki++)
            for (ri = 0; ri < 2; ri++) {
                hfvis_sweep_options o = hfvis_sweep_options_default(), to;
                int ch = kinds[ki] == HFVIS_SUM_ENV_LIGHT ? 2 : 1, tx0, ty0, tw;
                hfvis_grid t;
                o.rays = HFVIS_RAYS_EXACT;
                o.max_distance = radii[ri];
                t = tile_with_halo(W, H, x0, y0, w, h, &o, &to, &tx0, &ty0, &tw);
                CHECK_EQ_STATUS(hfvis_direction_sums(&g, Ks[Ki], kinds[ki], &env, NULL, &o, whole), HFVIS_OK);
                CHECK_EQ_STATUS(hfvis_direction_sums(&t, Ks[Ki], kinds[ki], &env, NULL, &to, part), HFVIS_OK);
                for (y = y0; y < y0 + h; y++)
                    for (x = x0; x < x0 + w; x++)
                        for (c = 0; c < ch; c++) {
                            double a = whole[(y * W + x) * ch + c], b = part[((y - ty0) * tw + x - tx0) * ch + c];
                            if (memcmp(&a, &b, sizeof a) != 0) {
                                if (bad < 3)
                                    printf("     kind %d K %d R %g: (%d, %d) channel %d: whole %.17g tile %.17g\n",
                                           (int)kinds[ki], Ks[Ki], radii[ri], x, y, c, a, b);
                                bad++;
                            }
                        }
            }
    CHECK(bad == 0);
}

/* The receiver rectangle alone (R unlimited, the default path): the same values inside, the
 * output untouched outside; R = +INFINITY is R = 0 bit for bit. */
TEST(receiver_rectangle_and_unlimited)
{
    int W = 45, H = 33, kind, mode;
    hfvis_grid g = test_grid(zbuf, W, H, 0.8);
    make_field(3, zbuf, W, H, 0.8, 5u);
    for (mode = 0; mode < 2; mode++)
        for (kind = 0; kind < NKINDS; kind++) {
            hfvis_sweep_options o = hfvis_sweep_options_default(), r;
            size_t n = (size_t)kind_planes[kind] * (size_t)(W * H), i, bad = 0, touched = 0;
            int p, x, y;
            o.rays = mode ? HFVIS_RAYS_EXACT : HFVIS_RAYS_LATTICE;
            CHECK_EQ_STATUS(run_kind(kind, &g, &o, out_a), HFVIS_OK);
            r = o;
            r.max_distance = (double)INFINITY;
            CHECK_EQ_STATUS(run_kind(kind, &g, &r, out_b), HFVIS_OK);
            for (i = 0; i < n; i++) bad += !same_bits(out_a[i], out_b[i]);
            r = o;
            r.receiver_x = 7;
            r.receiver_y = 30;
            r.receiver_width = 20;
            r.receiver_height = 3;
            for (i = 0; i < n; i++) out_b[i] = 12345.0f;
            CHECK_EQ_STATUS(run_kind(kind, &g, &r, out_b), HFVIS_OK);
            for (p = 0; p < kind_planes[kind]; p++)
                for (y = 0; y < H; y++)
                    for (x = 0; x < W; x++) {
                        size_t q = (size_t)p * (size_t)(W * H) + (size_t)(y * W + x);
                        int in = x >= 7 && x < 27 && y >= 30;
                        if (in) bad += !same_bits(out_a[q], out_b[q]);
                        else touched += out_b[q] != 12345.0f;
                    }
            CHECK(bad == 0);
            CHECK(touched == 0);
        }
}

/* R beyond the field is the unlimited horizon (to the hull tolerance); R below one cell sees no
 * lattice node (every horizon -pi/2 in lattice mode) but still the crossings nearer than a cell
 * in exact mode; a window needs a finite R and the open border; raw lattices refuse windows;
 * the routines outside the sweep refuse the options. */
TEST(radius_limits_and_arguments)
{
    int W = 40, H = 30, mode;
    hfvis_grid g = test_grid(zbuf, W, H, 1.0);
    hfvis_sweep_options o = hfvis_sweep_options_default();
    size_t n = (size_t)8 * (size_t)(W * H), i, unequal;
    double d;
    make_field(2, zbuf, W, H, 1.0, 9u);
    for (mode = 0; mode < 2; mode++) {
        o.rays = mode ? HFVIS_RAYS_EXACT : HFVIS_RAYS_LATTICE;
        o.max_distance = 0.0;
        CHECK_EQ_STATUS(hfvis_horizon_map(&g, 8, &o, out_a), HFVIS_OK);
        o.max_distance = 1000.0;
        CHECK_EQ_STATUS(hfvis_horizon_map(&g, 8, &o, out_b), HFVIS_OK);
        d = test_max_diff(out_a, out_b, n, &unequal);
        CHECK(d >= 0.0 && d <= RADIUS_HULL_TOL);
        o.max_distance = 0.9;
        CHECK_EQ_STATUS(hfvis_horizon_map(&g, 8, &o, out_b), HFVIS_OK);
        if (!mode) {
            for (i = 0; i < n; i++) CHECK(out_b[i] == (float)(-PI / 2));
        } else {
            size_t above = 0;
            for (i = 0; i < n; i++) above += out_b[i] > (float)(-PI / 2);
            CHECK(above > 0); /* the cliffs' crossings within 0.9 cell */
        }
    }
    { /* the march oracle takes R from the sweep options as its max_distance_cells */
        static float pts[2 * 20], ra[20 * 8], rb[20 * 8];
        hfvis_march_options mo;
        memset(&mo, 0, sizeof mo);
        for (i = 0; i < 20; i++) {
            pts[2 * i] = (float)(i * 2 % W);
            pts[2 * i + 1] = (float)(i * 7 % H);
        }
        o = hfvis_sweep_options_default();
        o.max_distance = 6.0;
        CHECK_EQ_STATUS(hfvis_horizon_reference(&g, 8, &o, NULL, pts, 20, ra), HFVIS_OK);
        o.max_distance = 0.0;
        mo.max_distance_cells = 6.0;
        CHECK_EQ_STATUS(hfvis_horizon_reference(&g, 8, &o, &mo, pts, 20, rb), HFVIS_OK);
        for (i = 0; i < 160; i++) CHECK(same_bits(ra[i], rb[i]));
    }
    o = hfvis_sweep_options_default();
    o.origin_x = 3;
    o.extent_width = W + 3;
    o.extent_height = H;
    CHECK_EQ_STATUS(hfvis_sky_view_factor(&g, 8, &o, out_a, W), HFVIS_ERR_INVALID_ARGUMENT);
    o.max_distance = 5.0;
    CHECK_EQ_STATUS(hfvis_sky_view_factor(&g, 8, &o, out_a, W), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_horizon_lattice(&g, 0.3, &o, out_a), HFVIS_ERR_INVALID_ARGUMENT);
    o.border = HFVIS_BORDER_CLAMP;
    CHECK_EQ_STATUS(hfvis_sky_view_factor(&g, 8, &o, out_a, W), HFVIS_ERR_INVALID_ARGUMENT);
    o.border = HFVIS_BORDER_OPEN;
    o.extent_width = W + 2; /* the grid reaches past the raster */
    CHECK_EQ_STATUS(hfvis_sky_view_factor(&g, 8, &o, out_a, W), HFVIS_ERR_INVALID_ARGUMENT);
    o = hfvis_sweep_options_default();
    o.receiver_x = 1;
    o.receiver_width = W;
    o.receiver_height = 1;
    CHECK_EQ_STATUS(hfvis_sky_view_factor(&g, 8, &o, out_a, W), HFVIS_ERR_INVALID_ARGUMENT);
    o = hfvis_sweep_options_default();
    o.max_distance = 5.0; /* the P2 tree honours R (test_hfvis.c, p2t_radius_*) but no rectangle */
    CHECK_EQ_STATUS(hfvis_visibility_count(&g, 8, &o, NULL, out_a, W, NULL), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_openness(&g, 8, NULL, &o, out_a, W), HFVIS_ERR_INVALID_ARGUMENT);
    o.receiver_width = o.receiver_height = 2;
    CHECK_EQ_STATUS(hfvis_visibility_count(&g, 8, &o, NULL, out_a, W, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    o.receiver_width = o.receiver_height = 0;
    o = hfvis_sweep_options_default();
    o.extent_width = W; /* the whole raster: no window, R may stay unlimited */
    o.extent_height = H;
    CHECK_EQ_STATUS(hfvis_sky_view_factor(&g, 8, &o, out_a, W), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_horizon_lattice(&g, 0.3, &o, out_a), HFVIS_OK);
}

int main(int argc, char **argv)
{
    TEST_INIT(argc, argv);
    RUN(lattice_radius_equals_oracle);
    RUN(exact_radius_equals_oracle);
    RUN(tiles_equal_whole_run_lattice);
    RUN(tiles_equal_whole_run_exact);
    RUN(tiles_direction_sums);
    RUN(tiles_direction_sums_cut_at_radius);
    RUN(receiver_rectangle_and_unlimited);
    RUN(radius_limits_and_arguments);
    return TEST_DONE();
}
