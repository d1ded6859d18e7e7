/* test.h - the whole test harness: CHECK macros, TEST registration, a summary line.
 * Each test program defines tests with TEST(name) { ... } and lists them in main via RUN(name).
 * The last line a program prints is "RESULT tests=N failed=M checks=C" (read by test/run.sh). */
#ifndef HFVIS_TEST_H
#define HFVIS_TEST_H
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../hfvis.h"

static int test_checks, test_check_failures, test_failed_tests, test_run_tests;
static int test_current_failed;
static int test_update_golden;

#define CHECK(cond) do { test_checks++; if (!(cond)) { test_check_failures++; test_current_failed = 1; \
    fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); } } while (0)
#define CHECK_EQ_STATUS(got, want) do { int g_ = (int)(got), w_ = (int)(want); test_checks++; \
    if (g_ != w_) { test_check_failures++; test_current_failed = 1; \
    fprintf(stderr, "%s:%d: status %d (%s), want %d (%s)\n", __FILE__, __LINE__, g_, \
            hfvis_status_string((hfvis_status)g_), w_, hfvis_status_string((hfvis_status)w_)); } } while (0)
/* |got - want| <= abs_tol + rel_tol*|want|; NaN never passes unless both are NaN. */
#define CHECK_NEAR(got, want, abs_tol, rel_tol) do { double g_ = (double)(got), w_ = (double)(want); \
    test_checks++; if (!((isnan(g_) && isnan(w_)) || fabs(g_ - w_) <= (abs_tol) + (rel_tol) * fabs(w_))) { \
    test_check_failures++; test_current_failed = 1; \
    fprintf(stderr, "%s:%d: %s = %.17g, want %.17g (diff %.3g, tol %.3g + %.3g rel)\n", __FILE__, __LINE__, \
            #got, g_, w_, g_ - w_, (double)(abs_tol), (double)(rel_tol)); } } while (0)

#define TEST(name) static void test_##name(void)
#define RUN(name) do { test_current_failed = 0; test_run_tests++; test_##name(); \
    if (test_current_failed) { test_failed_tests++; fprintf(stderr, "FAIL %s\n", #name); } \
    else { printf("ok   %s\n", #name); } \
    fflush(stdout); } while (0)
#define TEST_INIT(argc, argv) do { int a_; for (a_ = 1; a_ < (argc); a_++) \
    if (strcmp((argv)[a_], "--update-golden") == 0) test_update_golden = 1; } while (0)
#define TEST_DONE() (printf("DONE: %d checks, %d failed\nRESULT tests=%d failed=%d checks=%d\n", \
    test_checks, test_check_failures, test_run_tests, test_failed_tests, test_checks), \
    test_failed_tests ? 1 : 0)

/* A counting allocator for the failing-allocator sweeps: the fail_at-th allocation (1-based;
 * 0 = never) returns NULL; live = blocks allocated and not yet freed; bytes = total handed out. */
typedef struct test_counting {
    long allocs, frees, live, fail_at;
    size_t bytes;
} test_counting;
static inline void *test_count_alloc(void *user, size_t n)
{
    test_counting *c = (test_counting *)user;
    void *p;
    c->allocs++;
    if (c->fail_at != 0 && c->allocs == c->fail_at) return NULL;
    p = malloc(n);
    if (p) {
        c->live++;
        c->bytes += n;
    }
    return p;
}
static inline void test_count_free(void *user, void *p)
{
    test_counting *c = (test_counting *)user;
    if (!p) return;
    c->frees++;
    c->live--;
    free(p);
}
/* Zeroes *c, sets its fail_at and returns the allocator that counts into it. */
static inline hfvis_allocator test_counting_allocator(test_counting *c, long fail_at)
{
    hfvis_allocator a;
    memset(c, 0, sizeof *c);
    c->fail_at = fail_at;
    a.alloc = test_count_alloc;
    a.free = test_count_free;
    a.user = c;
    return a;
}

/* A height grid over z with stride W. */
static inline hfvis_grid test_grid(const float *z, int W, int H, double cell)
{
    hfvis_grid g;
    g.z = z;
    g.width = W;
    g.height = H;
    g.stride = W;
    g.cell_size = cell;
    return g;
}

/* Largest |a - b| over n values, counting the unequal ones in *unequal; -1 when a NaN of one
 * side meets a number of the other. */
/* A seeded fBm field from the library's analytic generator (octaves 0: the library's default). */
static inline hfvis_status test_fbm(float *z, int w, int h, double amplitude, double wavelength, int octaves,
                                    uint64_t seed)
{
    hfvis_field f;
    memset(&f, 0, sizeof f);
    f.kind = HFVIS_FIELD_FBM;
    f.amplitude = amplitude;
    f.wavelength = wavelength;
    f.octaves = octaves;
    f.seed = seed;
    return hfvis_field_generate(&f, w, h, w, z);
}

static inline double test_max_diff(const float *a, const float *b, size_t n, size_t *unequal)
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

/* The golden check every test program uses: img (w x h floats) against test/golden/NAME.pfm
 * (the programs run from the repository root). A value differs when it is NaN where the golden
 * is not (or the reverse) or farther than tol from it. With --update-golden the file is
 * rewritten instead. On a failure the check writes NAME.failed.pfm, expected | actual |
 * |actual - expected| side by side in one 3w x h PFM, into $HFVIS_TEST_OUT (default: the
 * current directory), and says where. */
static inline void test_golden(const char *name, const float *img, int w, int h, double tol)
{
    char path[512], out[1024];
    const char *dir = getenv("HFVIS_TEST_OUT");
    float *gold = NULL, *panel;
    hfvis_image_info info;
    hfvis_status st;
    int i, bad = 0;
    double worst = 0.0;
    snprintf(path, sizeof path, "test/golden/%s.pfm", name);
    if (test_update_golden) {
        CHECK_EQ_STATUS(hfvis_pfm_save(path, img, w, h, 1, w), HFVIS_OK);
        printf("     wrote %s\n", path);
        return;
    }
    st = hfvis_image_load(path, NULL, &gold, &info);
    CHECK_EQ_STATUS(st, HFVIS_OK);
    if (st != HFVIS_OK) {
        fprintf(stderr, "  golden: cannot load %s (run from the repository root; "
                "make update-golden writes it)\n", path);
        return;
    }
    if (info.width != w || info.height != h || info.channels != 1) {
        fprintf(stderr, "  golden %s: %d x %d x %d, want %d x %d x 1\n", path, info.width,
                info.height, info.channels, w, h);
        CHECK(0);
        hfvis_free(NULL, gold);
        return;
    }
    for (i = 0; i < w * h; i++) {
        double d = fabs((double)img[i] - (double)gold[i]);
        if (isnan(img[i]) != isnan(gold[i]) || d > tol) bad++;
        if (d > worst) worst = d;
    }
    CHECK(bad == 0);
    if (bad && (panel = (float *)malloc(sizeof(float) * 3 * (size_t)w * (size_t)h)) != NULL) {
        int x, y;
        for (y = 0; y < h; y++)
            for (x = 0; x < w; x++) {
                float e = gold[y * w + x], a = img[y * w + x];
                panel[(size_t)y * 3 * w + x] = e;
                panel[(size_t)y * 3 * w + w + x] = a;
                panel[(size_t)y * 3 * w + 2 * w + x] = (float)fabs((double)a - (double)e);
            }
        snprintf(out, sizeof out, "%s%s%s.failed.pfm", dir ? dir : "", dir ? "/" : "", name);
        if (hfvis_pfm_save(out, panel, 3 * w, h, 1, 3 * w) == HFVIS_OK)
            fprintf(stderr, "  golden %s: %d values differ (worst %.3g); wrote %s (expected | "
                    "actual | difference); if intended, run make update-golden\n", path, bad,
                    worst, out);
        else
            fprintf(stderr, "  golden %s: %d values differ (worst %.3g); if intended, run make "
                    "update-golden\n", path, bad, worst);
        free(panel);
    }
    hfvis_free(NULL, gold);
}
#endif
