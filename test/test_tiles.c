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

#define MAXN (96 * 80)
static float zbuf[MAXN], out_a[16 * MAXN], out_b[16 * MAXN];

static hfvis_grid grid_of(float *z, int W, int H, double cell)
{
    hfvis_grid g;
    g.z = z;
    g.width = W;
    g.height = H;
    g.stride = W;
    g.cell_size = cell;
    return g;
}

static void fbm(float *z, int W, int H, double amp, double wl, uint64_t seed)
{
    hfvis_field f;
    memset(&f, 0, sizeof f);
    f.kind = HFVIS_FIELD_FBM;
    f.amplitude = amp;
    f.wavelength = wl;
    f.seed = seed;
    hfvis_field_generate(&f, W, H, W, z);
}

/* Field number f (0 fBm, 1 urban boxes, 2 terraces with 80-degree one-cell cliffs, 3 fBm with
 * holes) of W x H, seeded. */
static void make_field(int f, float *z, int W, int H, double cell, uint64_t seed)
{
    int i;
    if (f == 1) fields_urban(z, W, H, W * H / 180 + 2, seed);
    else if (f == 2) fields_terraces(z, W, H, cell, 4.0, 80.0, seed);
    else fbm(z, W, H, 8.0 * cell, 9.0, seed);
    if (f == 3) {
        uint64_t s = seed;
        for (i = 0; i < W * H / 40; i++) z[(int)(fields_uniform(&s) * (double)(W * H))] = (float)NAN;
    }
}

/* Largest |a - b| over n values; -1 when NaNs differ. */
static double max_diff(const float *a, const float *b, size_t n, size_t *unequal)
{
    double m = 0.0;
    size_t i;
    *unequal = 0;
    for (i = 0; i < n; i++) {
        if (isnan(a[i]) || isnan(b[i])) {
            if (!(isnan(a[i]) && isnan(b[i]))) return -1.0;
            continue;
        }
        if (a[i] != b[i]) {
            (*unequal)++;
            if (fabs((double)a[i] - (double)b[i]) > m) m = fabs((double)a[i] - (double)b[i]);
        }
    }
    return m;
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
        hfvis_grid g = grid_of(zbuf, W, H, cell);
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
                    n = hfvis_lattice_size(&L);
                    CHECK_EQ_STATUS(hfvis_horizon_lattice(&g, az, &o, out_a), HFVIS_OK);
                    CHECK_EQ_STATUS(hfvis_horizon_lattice_naive(&g, az, &o, out_b), HFVIS_OK);
                    d = max_diff(out_a, out_b, n, &unequal);
                    CHECK(d >= 0.0 && d <= RADIUS_HULL_TOL);
                    if (d < 0.0 || d > RADIUS_HULL_TOL)
                        printf("     field %d R %g cells border %d az %g: diff %g (%zu)\n", f,
                               radii_cells[r], b, az, d, unequal);
                }
    }
}

/* Exact rays: hfvis_horizon_map with R against hfvis_horizon_exact_naive with R. */
TEST(exact_radius_equals_oracle)
{
    static const hfvis_border borders[] = {HFVIS_BORDER_OPEN, HFVIS_BORDER_CLAMP, HFVIS_BORDER_WRAP};
    int f, r, b;
    for (f = 0; f < 4; f++) {
        int W = 33 + 5 * f, H = 27 + 3 * f, K = 12;
        double cell = f == 1 ? 1.0 : 0.5 + 0.3 * (double)f;
        hfvis_grid g = grid_of(zbuf, W, H, cell);
        make_field(f, zbuf, W, H, cell, 21u + (uint64_t)f);
        for (r = 0; r < 6; r++)
            for (b = 0; b < 3; b++) {
                hfvis_sweep_options o = hfvis_sweep_options_default();
                double d;
                size_t unequal;
                o.rays = HFVIS_RAYS_EXACT;
                o.azimuth0_rad = 0.2;
                o.border = borders[b];
                o.border_cells = b == 0 ? 0 : 9;
                o.max_distance = radii_cells[r] * cell;
                CHECK_EQ_STATUS(hfvis_horizon_map(&g, K, &o, out_a), HFVIS_OK);
                CHECK_EQ_STATUS(hfvis_horizon_exact_naive(&g, K, &o, out_b), HFVIS_OK);
                d = max_diff(out_a, out_b, (size_t)K * (size_t)(W * H), &unequal);
                CHECK(d >= 0.0 && d <= RADIUS_HULL_TOL);
                if (d < 0.0 || d > RADIUS_HULL_TOL)
                    printf("     field %d R %g cells border %d: diff %g (%zu)\n", f, radii_cells[r], b,
                           d, unequal);
            }
    }
}

int main(int argc, char **argv)
{
    TEST_INIT(argc, argv);
    RUN(lattice_radius_equals_oracle);
    RUN(exact_radius_equals_oracle);
    return TEST_DONE();
}
