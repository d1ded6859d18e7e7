/* test_oom.c - allocation failure where no allocator can be passed: the *_save writers (and the
 * loaders and builders called with a NULL allocator) allocate through HFVIS_MALLOC/HFVIS_FREE
 * (hfvis.h, "Memory"). This program compiles the three library files itself with those macros
 * pointed at a counting allocator that fails the n-th call, and sweeps n over every allocation
 * of each call: the call returns HFVIS_ERR_OUT_OF_MEMORY, frees everything it took, and leaves
 * the target file as it was (absent, or with its old bytes) with no temporary file beside it;
 * once n passes the call's allocations it succeeds and the file reads back.
 * POSIX (mkdtemp, opendir) is used for the scratch folder only. */
#define _POSIX_C_SOURCE 200809L
#include <stddef.h>
#include <stdlib.h>

static long oom_calls, oom_fail_at, oom_live;

static void *oom_malloc(size_t n)
{
    void *p;
    oom_calls++;
    if (oom_fail_at != 0 && oom_calls == oom_fail_at) return NULL;
    p = malloc(n);
    if (p) oom_live++;
    return p;
}

static void oom_free(void *p)
{
    if (p) oom_live--;
    free(p);
}

#define HFVIS_MALLOC(size) oom_malloc(size)
#define HFVIS_FREE(ptr) oom_free(ptr)
#include "../hfvis.c"
#include "../ssao.c"
#include "../voxel.c"

#include "test.h"

#include "test_dir.h"
#include <unistd.h>

static char oom_dir[64];

static const char *oom_path(char *buf, size_t cap, const char *name)
{
    int n = snprintf(buf, cap, "%s/%s", oom_dir, name);
    return (n > 0 && (size_t)n < cap) ? buf : "";
}

/* The whole file into a malloc'd block (*size bytes); NULL if it cannot be read. */
static unsigned char *oom_read(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    unsigned char *b = NULL;
    long n;
    if (!f) return NULL;
    if (fseek(f, 0, SEEK_END) == 0 && (n = ftell(f)) >= 0 && fseek(f, 0, SEEK_SET) == 0) {
        b = (unsigned char *)malloc((size_t)n + 1);
        if (b && fread(b, 1, (size_t)n, f) != (size_t)n) {
            free(b);
            b = NULL;
        }
        *size = (size_t)n;
    }
    fclose(f);
    return b;
}

/* One writer under the sweep. save(path) is the call; the target starts either absent or holding
 * "old" bytes, and after every failure must be exactly as it started. Returns the number of
 * allocations the successful call made (0 if it never succeeded). */
typedef hfvis_status (*oom_save_fn)(const char *path);

static long oom_sweep_save(const char *name, oom_save_fn save)
{
    static const char old[] = "old contents";
    char path[128];
    long n, made = 0, base = oom_live;
    int pre;
    oom_path(path, sizeof path, name);
    for (pre = 0; pre < 2; pre++) {
        for (n = 1; n < 64; n++) {
            hfvis_status s;
            size_t size = 0;
            unsigned char *back;
            remove(path);
            if (pre) {
                FILE *f = fopen(path, "wb");
                CHECK(f && fwrite(old, 1, sizeof old, f) == sizeof old);
                if (f) fclose(f);
            }
            oom_calls = 0;
            oom_fail_at = n;
            s = save(path);
            oom_fail_at = 0;
            CHECK(oom_live == base);
            if (s == HFVIS_OK) {
                made = oom_calls;
                CHECK(n > made); /* every allocation before succeeded */
                CHECK(test_dir_entries(oom_dir) == 1);
                break;
            }
            CHECK_EQ_STATUS(s, HFVIS_ERR_OUT_OF_MEMORY);
            CHECK(test_dir_entries(oom_dir) == pre); /* no temporary file left */
            back = oom_read(path, &size);
            if (pre) CHECK(back && size == sizeof old && memcmp(back, old, sizeof old) == 0);
            else CHECK(back == NULL);
            free(back);
        }
        CHECK(made > 0);
    }
    remove(path);
    printf("     %s: %ld allocations, each failed in turn\n", name, made);
    return made;
}

/* The objects the writers save. */
static float oom_img[6 * 5 * 3];
static hfvis_mesh oom_mesh;
static hfvis_volume_grid oom_grid;
static uint8_t oom_occ[4 * 4 * 4];
static double oom_sums[2 * 3 * 4];
static hfvis_visfield oom_vf;
static unsigned char oom_vf_maps[4096];

static hfvis_status oom_pfm(const char *p) { return hfvis_pfm_save(p, oom_img, 6, 5, 3, 6); }
static hfvis_status oom_pgm(const char *p) { return hfvis_pgm_save(p, oom_img, 6, 5, 6, 0.0f, 1.0f, 255); }
static hfvis_status oom_pgm_range(const char *p) { return hfvis_pgm_range_save(p, oom_img, 6, 5, 6, 0.0f, 1.0f); }
static hfvis_status oom_obj(const char *p) { return hfvis_mesh_save(p, &oom_mesh); }
static hfvis_status oom_binvox(const char *p) { return hfvis_binvox_save(p, &oom_grid, oom_occ); }
static hfvis_status oom_raw(const char *p) { return hfvis_voxels_raw_save(p, &oom_grid, oom_occ); }
static hfvis_status oom_vfield(const char *p) { return hfvis_visfield_save(p, &oom_vf); }
static hfvis_status oom_partial(const char *p)
{
    hfvis_partial q;
    memset(&q, 0, sizeof q);
    q.width = 4;
    q.height = 3;
    q.planes = 2;
    q.directions = 8;
    q.begin = 2;
    q.end = 5;
    q.tag = "svf";
    q.sums = oom_sums;
    return hfvis_partial_save(p, &q);
}

TEST(setup)
{
    static const double lo[3] = {-0.5, -0.5, -0.5}, hi[3] = {0.5, 0.5, 0.5};
    size_t i;
    strcpy(oom_dir, "/tmp/hfvis_test_oom_XXXXXX");
    CHECK(mkdtemp(oom_dir) != NULL);
    for (i = 0; i < sizeof oom_img / sizeof oom_img[0]; i++) oom_img[i] = (float)(i % 11) / 10.0f;
    for (i = 0; i < sizeof oom_sums / sizeof oom_sums[0]; i++) oom_sums[i] = 0.25 * (double)i;
    CHECK_EQ_STATUS(hfvis_mesh_box(NULL, lo, hi, &oom_mesh), HFVIS_OK);
    oom_grid.origin[0] = oom_grid.origin[1] = oom_grid.origin[2] = -1.0;
    oom_grid.cell[0] = oom_grid.cell[1] = oom_grid.cell[2] = 0.5;
    oom_grid.dims[0] = oom_grid.dims[1] = oom_grid.dims[2] = 4;
    CHECK_EQ_STATUS(hfvis_voxelize_conservative(&oom_mesh, &oom_grid, NULL, oom_occ, NULL), HFVIS_OK);
    CHECK(hfvis_visfield_size(1, 2, (hfvis_visfield_format)0) <= sizeof oom_vf_maps);
    CHECK_EQ_STATUS(hfvis_visfield_bounding_sphere(&oom_mesh, oom_vf.center, &oom_vf.radius), HFVIS_OK);
    oom_vf.positions_n = 1;
    oom_vf.dir_res = 2;
    oom_vf.maps = oom_vf_maps;
    oom_vf.maps_size = sizeof oom_vf_maps;
    CHECK_EQ_STATUS(hfvis_visfield_build(&oom_mesh, NULL, &oom_vf), HFVIS_OK);
    CHECK(oom_live == 1 + 1); /* the mesh's two blocks */
}

TEST(writers)
{
    /* each writer: its encode buffer, then the temporary name */
    CHECK(oom_sweep_save("a.pfm", oom_pfm) == 2);
    CHECK(oom_sweep_save("a.pgm", oom_pgm) == 2);
    CHECK(oom_sweep_save("r.pgm", oom_pgm_range) == 2);
    CHECK(oom_sweep_save("a.obj", oom_obj) == 2);
    CHECK(oom_sweep_save("a.binvox", oom_binvox) == 2);
    CHECK(oom_sweep_save("a.raw", oom_raw) == 1); /* writes the caller's bytes */
    CHECK(oom_sweep_save("a.hfvf", oom_vfield) == 2);
    CHECK(oom_sweep_save("a.hfvs", oom_partial) == 2);
}

/* Loaders with a NULL allocator: the file block and the result; every failure leaves nothing
 * allocated and the output untouched, and the read-back equals what was saved. */
TEST(loaders)
{
    char path[128];
    long n;
    int kind;
    for (kind = 0; kind < 3; kind++) {
        long made = 0;
        oom_path(path, sizeof path, kind == 0 ? "b.pfm" : kind == 1 ? "b.obj" : "b.binvox");
        CHECK_EQ_STATUS(kind == 0 ? oom_pfm(path) : kind == 1 ? oom_obj(path) : oom_binvox(path), HFVIS_OK);
        for (n = 1; n < 64 && !made; n++) {
            hfvis_status s;
            oom_calls = 0;
            oom_fail_at = n;
            if (kind == 0) {
                float *px = NULL;
                hfvis_image_info info;
                s = hfvis_image_load(path, NULL, &px, &info);
                oom_fail_at = 0;
                if (s == HFVIS_OK) {
                    CHECK(info.width == 6 && info.height == 5 && info.channels == 3);
                    CHECK(memcmp(px, oom_img, sizeof oom_img) == 0);
                    hfvis_free(NULL, px);
                } else CHECK(px == NULL);
            } else if (kind == 1) {
                hfvis_mesh m;
                memset(&m, 0, sizeof m);
                s = hfvis_mesh_load(path, NULL, &m);
                oom_fail_at = 0;
                if (s == HFVIS_OK) {
                    CHECK(m.triangle_count == oom_mesh.triangle_count);
                    hfvis_mesh_free(NULL, &m);
                } else CHECK(m.xyz == NULL && m.indices == NULL);
            } else {
                hfvis_volume_grid g;
                uint8_t *occ = NULL;
                s = hfvis_binvox_load(path, NULL, &g, &occ);
                oom_fail_at = 0;
                if (s == HFVIS_OK) {
                    CHECK(memcmp(occ, oom_occ, sizeof oom_occ) == 0);
                    hfvis_free(NULL, occ);
                } else CHECK(occ == NULL);
            }
            CHECK(oom_live == 2); /* only the mesh of setup */
            if (s == HFVIS_OK) made = oom_calls;
            else CHECK_EQ_STATUS(s, HFVIS_ERR_OUT_OF_MEMORY);
        }
        CHECK(made > 0);
        printf("     %s: %ld allocations, each failed in turn\n", path + strlen(oom_dir) + 1, made);
        remove(path);
    }
}

TEST(teardown)
{
    hfvis_mesh_free(NULL, &oom_mesh);
    CHECK(oom_live == 0);
    CHECK(test_dir_entries(oom_dir) == 0);
    CHECK(rmdir(oom_dir) == 0);
}

int main(int argc, char **argv)
{
    TEST_INIT(argc, argv);
    RUN(setup);
    RUN(writers);
    RUN(loaders);
    RUN(teardown);
    return TEST_DONE();
}
