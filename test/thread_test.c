/* thread_test.c - the library's calls run concurrently on shared inputs, as the hfvis tool's
 * --threads runs them (hfvis.h, "Threads"), and the split results equal one call's bit for bit:
 * one sun's bands writing one output, the per-direction sums of quarter-turn groups (lattice) and
 * single directions (exact) added in order and finished as the single run finishes them, the
 * exact sums by bands of one direction at a time added in place, the grid normals given once
 * and shared, the horizon map's plane ranges writing one map, and the exact-ray grid data made
 * by row ranges into one array. Built with -pthread; make sanitize also builds it
 * under ThreadSanitizer, which reports any data race among these calls. */
#define _POSIX_C_SOURCE 200809L
#include <pthread.h>

#include "test.h"

enum { TW = 97, TH = 83, TN = TW * TH, THREADS = 4, TK = 16 };

static float g_z[TN];
static hfvis_grid g_grid;

typedef struct job {
    int id;            /* thread index */
    int mode;          /* HFVIS_RAYS_LATTICE or HFVIS_RAYS_EXACT */
    int parts;         /* work units of the run (bands, groups, directions, plane ranges) */
    int next;          /* the next unit to take (under lock) */
    pthread_mutex_t lock;
    float *out;        /* shared output (bands, horizon map) */
    double *unit_sums; /* per unit sums (sums: unit u at unit_sums + u*TN; bands: shared) */
    hfvis_sweep_options opts; /* bands: the direction and mode */
    hfvis_sum_kind kind;      /* bands */
    hfvis_status status[64];
    int cls[64];              /* exact grid rows: each range's class of heights */
} job;

static int job_take(job *j)
{
    int u;
    pthread_mutex_lock(&j->lock);
    u = j->next < j->parts ? j->next++ : -1;
    pthread_mutex_unlock(&j->lock);
    return u;
}

static void *sun_worker(void *p)
{
    job *j = (job *)p;
    int u;
    while ((u = job_take(j)) >= 0) {
        hfvis_sweep_options o = hfvis_sweep_options_default();
        o.rays = (hfvis_ray_mode)j->mode;
        o.part_index = u;
        o.part_count = j->parts;
        j->status[u] = hfvis_sun_visibility(&g_grid, 5.49, 0.2, 0.005, &o, j->out, TW);
    }
    return NULL;
}

/* A unit of the sums: one quarter-turn group (lattice, sweep order) or one direction (exact). */
static void *sums_worker(void *p)
{
    job *j = (job *)p;
    int u;
    while ((u = job_take(j)) >= 0) {
        hfvis_sweep_options o = hfvis_sweep_options_default();
        o.rays = (hfvis_ray_mode)j->mode;
        o.azimuth0_rad = 0.3;
        o.normals = j->opts.normals; /* shared by every unit (sky light) */
        if (j->mode == HFVIS_RAYS_LATTICE) {
            o.direction_order = HFVIS_DIRECTION_ORDER_SWEEP;
            o.direction_begin = 4 * u;
            o.direction_end = 4 * u + 4;
        } else {
            o.direction_begin = u;
            o.direction_end = u + 1;
        }
        j->status[u] = hfvis_direction_sums(&g_grid, TK, j->kind, NULL, NULL, &o,
                                            j->unit_sums + (size_t)u * TN);
    }
    return NULL;
}

/* A band of one direction of exact-mode sums, added in place to the shared running sums. */
static void *band_sums_worker(void *p)
{
    job *j = (job *)p;
    int u;
    while ((u = job_take(j)) >= 0) {
        hfvis_sweep_options o = j->opts;
        o.part_index = u;
        o.part_count = j->parts;
        j->status[u] = hfvis_direction_sums(&g_grid, TK, j->kind, NULL, NULL, &o, j->unit_sums);
    }
    return NULL;
}

static void *map_worker(void *p)
{
    job *j = (job *)p;
    int u;
    while ((u = job_take(j)) >= 0) {
        hfvis_sweep_options o = hfvis_sweep_options_default();
        o.rays = (hfvis_ray_mode)j->mode;
        o.direction_order = HFVIS_DIRECTION_ORDER_SWEEP;
        o.direction_begin = 4 * u;
        o.direction_end = 4 * u + 4;
        j->status[u] = hfvis_horizon_map(&g_grid, TK, &o, j->out + (size_t)4 * (size_t)u * TN);
    }
    return NULL;
}

/* A row range of the exact-ray grid data (hfvis_exact_grid_rows), into the shared unit_sums. */
static void *grid_rows_worker(void *p)
{
    job *j = (job *)p;
    int u;
    while ((u = job_take(j)) >= 0)
        j->status[u] = hfvis_exact_grid_rows(&g_grid, u * TH / j->parts, (u + 1) * TH / j->parts, j->unit_sums,
                                             &j->cls[u]);
    return NULL;
}

static void run_threads(job *j, void *(*fn)(void *))
{
    pthread_t t[THREADS];
    int i, started = 0;
    j->next = 0;
    for (i = 0; i < 64; i++) j->status[i] = HFVIS_OK;
    for (i = 0; i < THREADS; i++) started += pthread_create(&t[i], NULL, fn, j) == 0;
    CHECK(started == THREADS);
    for (i = 0; i < started; i++) pthread_join(t[i], NULL);
}

static int same(const float *a, const float *b, size_t n)
{
    size_t i;
    for (i = 0; i < n; i++)
        if (!(a[i] == b[i] || (isnan(a[i]) && isnan(b[i])))) return 0;
    return 1;
}

static void field_init(void)
{
    hfvis_field f;
    size_t i;
    memset(&f, 0, sizeof f);
    f.kind = HFVIS_FIELD_FBM;
    f.amplitude = 30.0;
    f.seed = 17;
    (void)hfvis_field_generate(&f, TW, TH, TW, g_z);
    for (i = 0; i < TN; i += 53) g_z[i] = NAN; /* holes */
    for (i = 0; i < TN; i++)
        if (i % TW == 40) g_z[i] += 25.0f; /* a one-cell wall */
    g_grid.z = g_z;
    g_grid.width = TW;
    g_grid.height = TH;
    g_grid.stride = TW;
    g_grid.cell_size = 1.0;
}

TEST(sun_bands_concurrently)
{
    static float whole[TN], shared[TN];
    job j;
    int mode, u;
    memset(&j, 0, sizeof j);
    pthread_mutex_init(&j.lock, NULL);
    for (mode = HFVIS_RAYS_LATTICE; mode <= HFVIS_RAYS_EXACT; mode++) {
        hfvis_sweep_options o = hfvis_sweep_options_default();
        o.rays = (hfvis_ray_mode)mode;
        CHECK_EQ_STATUS(hfvis_sun_visibility(&g_grid, 5.49, 0.2, 0.005, &o, whole, TW), HFVIS_OK);
        j.mode = mode;
        j.parts = 7;
        j.out = shared;
        run_threads(&j, sun_worker);
        for (u = 0; u < j.parts; u++) CHECK_EQ_STATUS(j.status[u], HFVIS_OK);
        CHECK(same(whole, shared, TN));
    }
    pthread_mutex_destroy(&j.lock);
}

/* The units of j run concurrently into unit (TN each), then added in unit order into acc. */
static void sums_in_order(job *j, double *unit, double *acc)
{
    size_t i;
    int u;
    j->unit_sums = unit;
    run_threads(j, sums_worker);
    for (u = 0; u < j->parts; u++) CHECK_EQ_STATUS(j->status[u], HFVIS_OK);
    for (i = 0; i < TN; i++) acc[i] = unit[i];
    for (u = 1; u < j->parts; u++)
        for (i = 0; i < TN; i++) acc[i] += unit[(size_t)u * TN + i];
}

TEST(direction_sums_concurrently)
{
    static double unit[TK * TN], acc[TN];
    static float whole[TN], split[TN];
    job j;
    int mode;
    size_t i;
    memset(&j, 0, sizeof j);
    pthread_mutex_init(&j.lock, NULL);
    j.kind = HFVIS_SUM_SKY_VIEW;
    for (mode = HFVIS_RAYS_LATTICE; mode <= HFVIS_RAYS_EXACT; mode++) {
        hfvis_sweep_options o = hfvis_sweep_options_default();
        o.rays = (hfvis_ray_mode)mode;
        o.azimuth0_rad = 0.3;
        CHECK_EQ_STATUS(hfvis_sky_view_factor(&g_grid, TK, &o, whole, TW), HFVIS_OK);
        j.mode = mode;
        j.parts = mode == HFVIS_RAYS_LATTICE ? TK / 4 : TK;
        sums_in_order(&j, unit, acc); /* then the single run's finish (hfvis.h, split runs) */
        for (i = 0; i < TN; i++) split[i] = (float)(1.0 + (-1.0 / (double)TK) * acc[i]);
        CHECK(same(whole, split, TN));
    }
    pthread_mutex_destroy(&j.lock);
}

static int same_sums(const double *a, const double *b, size_t n)
{
    size_t i;
    for (i = 0; i < n; i++)
        if (!(a[i] == b[i] || (isnan(a[i]) && isnan(b[i])))) return 0;
    return 1;
}

/* The grid normals given once (sweep options normals, hfvis_normals_compute's) and shared by
 * concurrent calls: the sky light equals the calls that make their own, whole (both modes) and
 * split by quarter-turn groups added in order (lattice). A normal off by one float would show. */
TEST(given_normals_shared)
{
    static float nrm[TN * 3], whole[TN], given[TN];
    static double unit[TK * TN], acc[TN], sums[TN];
    job j;
    int mode;
    memset(&j, 0, sizeof j);
    pthread_mutex_init(&j.lock, NULL);
    CHECK_EQ_STATUS(hfvis_normals_compute(&g_grid, nrm), HFVIS_OK);
    for (mode = HFVIS_RAYS_LATTICE; mode <= HFVIS_RAYS_EXACT; mode++) {
        hfvis_sweep_options o = hfvis_sweep_options_default();
        o.rays = (hfvis_ray_mode)mode;
        o.azimuth0_rad = 0.3;
        CHECK_EQ_STATUS(hfvis_sky_light(&g_grid, TK, 1.5f, 0.7f, &o, whole, TW), HFVIS_OK);
        CHECK_EQ_STATUS(hfvis_direction_sums(&g_grid, TK, HFVIS_SUM_SKY_LIGHT, NULL, NULL, &o, sums), HFVIS_OK);
        o.normals = nrm;
        CHECK_EQ_STATUS(hfvis_sky_light(&g_grid, TK, 1.5f, 0.7f, &o, given, TW), HFVIS_OK);
        CHECK(same(whole, given, TN));
        if (mode != HFVIS_RAYS_LATTICE) continue;
        j.mode = mode;
        j.kind = HFVIS_SUM_SKY_LIGHT;
        j.opts.normals = nrm;
        j.parts = TK / 4;
        sums_in_order(&j, unit, acc);
        CHECK(same_sums(sums, acc, TN));
    }
    pthread_mutex_destroy(&j.lock);
}

/* Exact-mode sums by bands of one direction at a time (7 bands over 4 threads, then the next
 * direction), added in place to one array zeroed once: the whole call's S bit for bit, for the
 * sky-view factor and the sky light, over the grid and over a receiver rectangle (whose outside
 * stays untouched). A band that lost or doubled a line would change S. */
TEST(exact_band_sums_concurrently)
{
    static double whole[TN], banded[TN];
    static float nrm[TN * 3];
    job j;
    int kind, rect, k, u;
    size_t i;
    memset(&j, 0, sizeof j);
    pthread_mutex_init(&j.lock, NULL);
    CHECK_EQ_STATUS(hfvis_normals_compute(&g_grid, nrm), HFVIS_OK);
    for (kind = HFVIS_SUM_SKY_VIEW; kind <= HFVIS_SUM_SKY_LIGHT; kind++)
        for (rect = 0; rect < 2; rect++) {
            hfvis_sweep_options o = hfvis_sweep_options_default();
            o.rays = HFVIS_RAYS_EXACT;
            o.azimuth0_rad = 0.3;
            if (rect) {
                o.receiver_x = 11;
                o.receiver_y = 7;
                o.receiver_width = 50;
                o.receiver_height = 61;
            }
            for (i = 0; i < TN; i++) whole[i] = banded[i] = -7.0; /* the outside stays -7 */
            CHECK_EQ_STATUS(hfvis_direction_sums(&g_grid, TK, (hfvis_sum_kind)kind, NULL, NULL, &o, whole), HFVIS_OK);
            for (i = 0; i < TN; i++) {
                int x = (int)(i % TW), y = (int)(i / TW);
                if (!rect || (x >= 11 && x < 61 && y >= 7 && y < 68)) banded[i] = 0.0;
            }
            j.kind = (hfvis_sum_kind)kind;
            j.parts = 7;
            j.unit_sums = banded;
            for (k = 0; k < TK; k++) { /* one direction at a time, its bands concurrently */
                j.opts = o;
                j.opts.normals = rect ? nrm : NULL; /* given (shared) or each band's own */
                j.opts.direction_begin = k;
                j.opts.direction_end = k + 1;
                run_threads(&j, band_sums_worker);
                for (u = 0; u < j.parts; u++) CHECK_EQ_STATUS(j.status[u], HFVIS_OK);
            }
            CHECK(same_sums(whole, banded, TN));
        }
    pthread_mutex_destroy(&j.lock);
}

TEST(horizon_map_planes_concurrently)
{
    static float whole[TK * TN], shared[TK * TN];
    job j;
    int mode, u;
    memset(&j, 0, sizeof j);
    pthread_mutex_init(&j.lock, NULL);
    for (mode = HFVIS_RAYS_LATTICE; mode <= HFVIS_RAYS_EXACT; mode++) {
        hfvis_sweep_options o = hfvis_sweep_options_default();
        o.rays = (hfvis_ray_mode)mode;
        o.direction_order = HFVIS_DIRECTION_ORDER_SWEEP;
        CHECK_EQ_STATUS(hfvis_horizon_map(&g_grid, TK, &o, whole), HFVIS_OK);
        j.mode = mode;
        j.parts = TK / 4;
        j.out = shared;
        run_threads(&j, map_worker); /* range u writes its 4 planes, 4u.. of the map */
        for (u = 0; u < j.parts; u++) CHECK_EQ_STATUS(j.status[u], HFVIS_OK);
        CHECK(same(whole, shared, (size_t)TK * TN));
    }
    pthread_mutex_destroy(&j.lock);
}

/* The exact-ray grid data made by 9 row ranges on 4 threads (one array, disjoint rows), the class
 * the largest of the ranges': the one call's doubles, and the sweep that shares it the sweep
 * that makes its own (a wrong row of twists would move a horizon). */
TEST(exact_grid_rows_concurrently)
{
    static double whole[TN + 1], rows[TN + 1];
    static float own[TN], shared[TN];
    hfvis_sweep_options o = hfvis_sweep_options_default();
    job j;
    int u, cls = 0;
    memset(&j, 0, sizeof j);
    pthread_mutex_init(&j.lock, NULL);
    CHECK_EQ_STATUS(hfvis_exact_grid_compute(&g_grid, whole), HFVIS_OK);
    j.parts = 9;
    j.unit_sums = rows;
    run_threads(&j, grid_rows_worker);
    for (u = 0; u < j.parts; u++) {
        CHECK_EQ_STATUS(j.status[u], HFVIS_OK);
        cls = j.cls[u] > cls ? j.cls[u] : cls;
    }
    rows[TN] = (double)cls;
    CHECK(memcmp(whole, rows, sizeof whole) == 0);
    o.rays = HFVIS_RAYS_EXACT;
    CHECK_EQ_STATUS(hfvis_sky_view_factor(&g_grid, TK, &o, own, TW), HFVIS_OK);
    o.exact_grid = rows;
    CHECK_EQ_STATUS(hfvis_sky_view_factor(&g_grid, TK, &o, shared, TW), HFVIS_OK);
    CHECK(same(own, shared, TN));
    pthread_mutex_destroy(&j.lock);
}

int main(int argc, char **argv)
{
    TEST_INIT(argc, argv);
    field_init();
    RUN(sun_bands_concurrently);
    RUN(direction_sums_concurrently);
    RUN(exact_band_sums_concurrently);
    RUN(given_normals_shared);
    RUN(horizon_map_planes_concurrently);
    RUN(exact_grid_rows_concurrently);
    return TEST_DONE();
}
