/* test_wfault.c - a failed write is an error: every writer of the library (the *_save savers,
 * hfvis_write_file, hfvis_write_begin/end) and of examples/raster_io.h (.tif, .asc + .prj,
 * .bil/.flt + .hdr + .prj) under an injected failure of each fwrite, fflush, fclose and rename
 * it makes, one call at a time. This program compiles the three library files itself with
 * HFVIS_FWRITE, HFVIS_FFLUSH, HFVIS_FCLOSE and HFVIS_RENAME (hfvis.h, hfvis_write_file) pointed
 * at counting wrappers; for the k-th call of each kind (k over every call the writer makes)
 * it asserts: an error status (HFVIS_ERR_IO, or -1 from raster_io), every target file (the
 * output and each sidecar) byte-identical to the previous output, and no other file in the
 * folder. Without injection the writer succeeds and the new files replace the old set whole.
 * POSIX (mkdtemp, opendir) is used for the scratch folder only. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>

enum { WF_WRITE, WF_FLUSH, WF_CLOSE, WF_RENAME, WF_KINDS };
static const char *const wf_kind_name[WF_KINDS] = {"fwrite", "fflush", "fclose", "rename"};
static long wf_calls[WF_KINDS], wf_fail_kind = -1, wf_fail_at;

/* 1 when this call (of kind) is the one to fail. */
static int wf_fail(int kind)
{
    wf_calls[kind]++;
    return kind == wf_fail_kind && wf_calls[kind] == wf_fail_at;
}

/* A failing fwrite writes half of what it was given (a short write, as on a full disk). */
static size_t wf_fwrite(const void *p, size_t size, size_t n, FILE *f)
{
    if (wf_fail(WF_WRITE)) return n > 1 ? fwrite(p, size, n / 2, f) : 0;
    return fwrite(p, size, n, f);
}
static int wf_fflush(FILE *f) { return wf_fail(WF_FLUSH) ? EOF : fflush(f); }
/* A failing fclose still closes the file (as a delayed write error reported by close does). */
static int wf_fclose(FILE *f)
{
    int r = fclose(f);
    return wf_fail(WF_CLOSE) ? EOF : r;
}
static int wf_rename(const char *a, const char *b) { return wf_fail(WF_RENAME) ? -1 : rename(a, b); }

#define HFVIS_FWRITE(p, s, n, f) wf_fwrite(p, s, n, f)
#define HFVIS_FFLUSH(f) wf_fflush(f)
#define HFVIS_FCLOSE(f) wf_fclose(f)
#define HFVIS_RENAME(a, b) wf_rename(a, b)
#include "../hfvis.c"
#include "../ssao.c"
#include "../voxel.c"
#include "../examples/raster_io.h"

#include "test.h"
#include "test_dir.h"
#include <unistd.h>

static char wf_dir[64];

static char *wf_path(const char *name)
{
    static char p[8][384];
    static int k;
    k = (k + 1) & 7;
    snprintf(p[k], sizeof p[k], "%s/%s", wf_dir, name);
    return p[k];
}

/* The whole file into a malloc'd block (*n bytes); NULL when absent. */
static unsigned char *wf_read(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    unsigned char *b = NULL;
    long len;
    *n = 0;
    if (!f) return NULL;
    if (fseek(f, 0, SEEK_END) == 0 && (len = ftell(f)) >= 0 && fseek(f, 0, SEEK_SET) == 0 &&
        (b = (unsigned char *)malloc((size_t)len + 1)) != NULL) {
        if (fread(b, 1, (size_t)len, f) == (size_t)len) *n = (size_t)len;
        else {
            free(b);
            b = NULL;
        }
    }
    fclose(f);
    return b;
}

/* Remove every file of the folder. */
static void wf_clear(void)
{
    DIR *d = opendir(wf_dir);
    struct dirent *e;
    if (!d) return;
    while ((e = readdir(d)) != NULL)
        if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0) remove(wf_path(e->d_name));
    closedir(d);
}

/* ---- the writers: version v (0 or 1) writes different contents to the same targets ---- */

#define WF_W 5
#define WF_H 3
static float wf_px[2][WF_W * WF_H];
static hfvis_mesh wf_box;
static hfvis_volume_grid wf_vg;
static uint8_t wf_occ[2][4 * 4 * 4];
static unsigned char wf_vf_maps[4096];
static hfvis_visfield wf_vf;
static double wf_sums[2][WF_W * WF_H];

static int wf_pfm(int v) { return hfvis_pfm_save(wf_path("o.pfm"), wf_px[v], WF_W, WF_H, 1, WF_W); }
static int wf_pgm(int v) { return hfvis_pgm_save(wf_path("o.pgm"), wf_px[v], WF_W, WF_H, WF_W, -2.0f, 2.0f, 255); }
static int wf_pgm_range(int v) { return hfvis_pgm_range_save(wf_path("o.pgm"), wf_px[v], WF_W, WF_H, WF_W, -2.0f, 2.0f); }
static int wf_binvox(int v) { return hfvis_binvox_save(wf_path("o.binvox"), &wf_vg, wf_occ[v]); }
static int wf_raw(int v) { return hfvis_voxels_raw_save(wf_path("o.raw"), &wf_vg, wf_occ[v]); }
static int wf_mesh(int v)
{
    hfvis_mesh m = wf_box;
    m.triangle_count = v ? 6 : 12; /* the first half of the box */
    return hfvis_mesh_save(wf_path("o.obj"), &m);
}
static int wf_hfvs(int v)
{
    wf_vf.radius = v ? 2.0 : 3.0;
    return hfvis_visfield_save(wf_path("o.hfvs"), &wf_vf);
}
static int wf_partial(int v)
{
    hfvis_partial p;
    p.width = WF_W; p.height = WF_H; p.planes = 1; p.directions = 4; p.begin = 1; p.end = 3;
    p.tag = "svf K=4"; p.sums = wf_sums[v];
    return hfvis_partial_save(wf_path("o.part"), &p);
}
static int wf_write_begin_end(int v)
{
    FILE *f;
    char *tmp;
    int s = hfvis_write_begin(wf_path("o.bin"), NULL, &f, &tmp), ok;
    if (s != HFVIS_OK) return s;
    ok = HFVIS_FWRITE(wf_px[v], sizeof(float), WF_W * WF_H, f) == WF_W * WF_H;
    return hfvis_write_end(wf_path("o.bin"), f, tmp, ok, NULL) == HFVIS_OK && ok ? HFVIS_OK : HFVIS_ERR_IO;
}

/* raster_io: georeferenced, with a .prj (v 0) or without one (v 1: the old .prj must go). */
static int wf_rio(const char *name, int v, int prj)
{
    ex_rio_image img;
    ex_georef g;
    char err[256];
    int rc;
    memset(&g, 0, sizeof g);
    g.has_transform = 1;
    g.gt[0] = 500000.0 + 10.0 * v; g.gt[1] = 30.0; g.gt[3] = 4100000.0; g.gt[5] = -30.0;
    g.has_nodata = 1; g.nodata = -9999.0;
    strcpy(g.nodata_text, "-9999");
    if (prj) g.prj = (char *)(v ? "PROJCS[\"b\"]" : "PROJCS[\"a\"]");
    img.data = wf_px[v]; img.width = WF_W; img.height = WF_H; img.bands = 1;
    img.band_step = WF_W * WF_H; img.row_step = WF_W; img.pixel_step = 1;
    rc = ex_rio_write(wf_path(name), &img, &g, NULL, err);
    return rc == 0 ? HFVIS_OK : HFVIS_ERR_IO;
}
static int wf_tif(int v) { return wf_rio("o.tif", v, 1); }
static int wf_asc(int v) { return wf_rio("o.asc", v, v == 0); }
static int wf_bil(int v) { return wf_rio("o.bil", v, 1); }
static int wf_flt(int v) { return wf_rio("o.flt", v, v == 0); }

typedef struct {
    const char *name;
    int (*fn)(int v);
    const char *files[3]; /* the targets it writes (file names in the folder) */
} wf_writer;
static const wf_writer wf_writers[] = {
    {"pfm_save", wf_pfm, {"o.pfm"}},
    {"pgm_save", wf_pgm, {"o.pgm"}},
    {"pgm_range_save", wf_pgm_range, {"o.pgm"}},
    {"binvox_save", wf_binvox, {"o.binvox"}},
    {"voxels_raw_save", wf_raw, {"o.raw"}},
    {"mesh_save", wf_mesh, {"o.obj"}},
    {"visfield_save", wf_hfvs, {"o.hfvs"}},
    {"partial_save", wf_partial, {"o.part"}},
    {"write_begin_end", wf_write_begin_end, {"o.bin"}},
    {"raster_io .tif", wf_tif, {"o.tif"}},
    {"raster_io .asc", wf_asc, {"o.asc", "o.prj"}},
    {"raster_io .bil", wf_bil, {"o.bil", "o.hdr", "o.prj"}},
    {"raster_io .flt", wf_flt, {"o.flt", "o.hdr", "o.prj"}},
};
#define WF_COUNT ((int)(sizeof wf_writers / sizeof wf_writers[0]))

typedef struct {
    unsigned char *b[3];
    size_t n[3];
} wf_snapshot;

static void wf_snap(const wf_writer *w, wf_snapshot *s)
{
    int i;
    for (i = 0; i < 3; i++) s->b[i] = w->files[i] ? wf_read(wf_path(w->files[i]), &s->n[i]) : NULL;
}
static void wf_snap_free(wf_snapshot *s)
{
    int i;
    for (i = 0; i < 3; i++) free(s->b[i]);
}
/* 1 when every target of w is as in s (absent where s has none). */
static int wf_same(const wf_writer *w, const wf_snapshot *s)
{
    int i, same = 1;
    for (i = 0; i < 3 && w->files[i]; i++) {
        size_t n;
        unsigned char *b = wf_read(wf_path(w->files[i]), &n);
        if ((b == NULL) != (s->b[i] == NULL) || n != s->n[i] || (b && memcmp(b, s->b[i], n) != 0)) same = 0;
        free(b);
    }
    return same;
}

static void wf_reset(void)
{
    int k;
    for (k = 0; k < WF_KINDS; k++) wf_calls[k] = 0;
    wf_fail_kind = -1;
    wf_fail_at = 0;
}

/* One writer: version 0 in place, then version 1 under every single failure, then for real. */
static void wf_one(const wf_writer *w, long *injected)
{
    long total[WF_KINDS];
    int kind, files;
    wf_snapshot old, fresh;
    wf_clear();
    wf_reset();
    CHECK_EQ_STATUS(w->fn(0), HFVIS_OK);
    wf_snap(w, &old);
    files = test_dir_entries(wf_dir);
    /* count the calls of a successful rewrite, then undo it */
    wf_reset();
    CHECK_EQ_STATUS(w->fn(1), HFVIS_OK);
    for (kind = 0; kind < WF_KINDS; kind++) total[kind] = wf_calls[kind];
    wf_snap(w, &fresh);
    CHECK(!wf_same(w, &old)); /* the two versions differ, so "untouched" means something */
    CHECK(total[WF_WRITE] > 0 && total[WF_FLUSH] > 0 && total[WF_CLOSE] > 0 && total[WF_RENAME] > 0);
    wf_reset();
    CHECK_EQ_STATUS(w->fn(0), HFVIS_OK);
    CHECK(wf_same(w, &old));
    for (kind = 0; kind < WF_KINDS; kind++) {
        long k;
        for (k = 1; k <= total[kind]; k++) {
            int s, same, left;
            wf_reset();
            wf_fail_kind = kind;
            wf_fail_at = k;
            s = w->fn(1);
            wf_fail_kind = -1;
            same = wf_same(w, &old);
            left = test_dir_entries(wf_dir);
            (*injected)++;
            CHECK_EQ_STATUS(s, HFVIS_ERR_IO);
            CHECK(same);
            CHECK(left == files);
            if (s != HFVIS_ERR_IO || !same || left != files)
                fprintf(stderr, "  (%s: failing %s call %ld of %ld; %d files, want %d)\n", w->name,
                        wf_kind_name[kind], k, total[kind], left, files);
        }
    }
    wf_reset();
    CHECK_EQ_STATUS(w->fn(1), HFVIS_OK);
    CHECK(wf_same(w, &fresh));
    wf_snap_free(&old);
    wf_snap_free(&fresh);
}

TEST(writers)
{
    int i;
    long injected = 0;
    for (i = 0; i < WF_COUNT; i++) wf_one(&wf_writers[i], &injected);
    printf("     %d writers, %ld injected failures\n", WF_COUNT, injected);
}

static void wf_setup(void)
{
    static const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    int i;
    for (i = 0; i < WF_W * WF_H; i++) {
        wf_px[0][i] = 0.25f * (float)(i % 7) - 1.0f;
        wf_px[1][i] = 0.5f - 0.125f * (float)(i % 5);
        wf_sums[0][i] = (double)i;
        wf_sums[1][i] = 0.5 * (double)i + 1.0;
    }
    for (i = 0; i < 64; i++) {
        wf_occ[0][i] = (uint8_t)(i % 3 == 0);
        wf_occ[1][i] = (uint8_t)(i % 5 == 0);
    }
    if (hfvis_mesh_box(NULL, lo, hi, &wf_box) != HFVIS_OK) exit(2);
    wf_vg.origin[0] = wf_vg.origin[1] = wf_vg.origin[2] = -0.25;
    wf_vg.cell[0] = wf_vg.cell[1] = wf_vg.cell[2] = 0.375;
    wf_vg.dims[0] = wf_vg.dims[1] = wf_vg.dims[2] = 4;
    memset(&wf_vf, 0, sizeof wf_vf);
    if (hfvis_visfield_bounding_sphere(&wf_box, wf_vf.center, &wf_vf.radius) != HFVIS_OK) exit(2);
    wf_vf.positions_n = 1; wf_vf.dir_res = 2; wf_vf.maps = wf_vf_maps; wf_vf.maps_size = sizeof wf_vf_maps;
    if (hfvis_visfield_build(&wf_box, NULL, &wf_vf) != HFVIS_OK) exit(2);
}

int main(int argc, char **argv)
{
    TEST_INIT(argc, argv);
    strcpy(wf_dir, "/tmp/hfvis_wfault_XXXXXX");
    if (!mkdtemp(wf_dir)) {
        fprintf(stderr, "cannot create a scratch folder\n");
        return 2;
    }
    wf_setup();
    RUN(writers);
    wf_clear();
    rmdir(wf_dir);
    hfvis_mesh_free(NULL, &wf_box);
    return TEST_DONE();
}
