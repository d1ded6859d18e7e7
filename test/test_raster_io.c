/* test_raster_io.c - examples/zio.h (inflate, deflate) and examples/raster_io.h (GeoTIFF, ASC,
 * EHdr): round trips for every byte order, layout, compression, predictor, sample type and
 * BigTIFF; LZW and PackBits files built here with reference encoders; window reads against the
 * whole read, and a window that never touches a corrupted tile; hand-built malformed files
 * (truncated IFDs, offsets past the end, huge tile counts, IFD loops, bad LZW/deflate streams,
 * strips claiming impossible sizes) refused with a message; a .prj's CRS as GeoKeys (EPSG code or
 * ESRI PE string) and back. Writes into a temporary folder. */
#define _POSIX_C_SOURCE 200809L /* mkdtemp, rmdir */
#include "test.h"
#include "test_dir.h"
#include "../examples/raster_io.h"
#include <fenv.h>
#include <stdint.h>
#include <unistd.h>

static char tdir[256];

static char *tpath(const char *name) { return test_dir_path(tdir, name); }

static unsigned char *slurp(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    unsigned char *b;
    long len;
    *n = 0;
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    len = ftell(f);
    fseek(f, 0, SEEK_SET);
    b = (unsigned char *)malloc((size_t)len + 1);
    if (b && fread(b, 1, (size_t)len, f) == (size_t)len) *n = (size_t)len;
    fclose(f);
    return b;
}

static void spit(const char *path, const void *p, size_t n)
{
    FILE *f = fopen(path, "wb");
    if (!f) return;
    if (fwrite(p, 1, n, f) != n) fprintf(stderr, "short write %s\n", path);
    fclose(f);
}

static uint32_t lcg(uint32_t *s)
{
    *s = *s * 1103515245u + 12345u;
    return (*s >> 16) & 0x7fffu;
}

/* A test field: integers (fit every sample type) or fractions, with one NaN hole when asked. */
static void field(float *z, int w, int h, int bands, int integral, uint32_t seed)
{
    int i, n = w * h * bands;
    for (i = 0; i < n; i++) {
        uint32_t r = lcg(&seed);
        z[i] = integral ? (float)(r % 120) : (float)((double)r / 32768.0 * 1000.0 - 200.0);
    }
}

/* ---- zio.h ------------------------------------------------------------------------------ */

/* A dynamic-Huffman zlib stream (zlib.compress, level 9) of 600 bytes from lcg seed 12345. */
static const unsigned char dyn_stream[] = {
    0x78,0xda,0x1d,0x92,0xd9,0x11,0xc3,0x50,0x08,0x03,0x6b,0x15,0x20,0x50,0xff,0x15,0x78,0x9f,0x27,0x1f,
    0x4e,0x02,0xe8,0xb4,0xbd,0x9d,0xdd,0xee,0xf5,0x5c,0x46,0xe5,0x55,0x2a,0x5a,0x9b,0xc9,0x9c,0xa6,0x3b,
    0xb9,0xa8,0xea,0x4a,0xa3,0x5d,0x57,0x55,0xee,0xfa,0xe2,0xda,0x1d,0xab,0xcb,0x9e,0x3e,0xae,0x01,0xf1,
    0xb2,0x17,0x31,0xb4,0xd3,0xb7,0x56,0xb5,0xeb,0xc0,0x99,0x33,0x2c,0x3b,0x13,0xd8,0x5a,0x7d,0x9c,0xde,
    0xcd,0x4d,0x4b,0x0b,0x72,0x9a,0xb9,0x95,0xe1,0x0e,0x50,0x16,0x57,0x7e,0x48,0xbd,0x90,0xd7,0xcd,0x82,
    0x9f,0x83,0xed,0x50,0x08,0xe5,0xd5,0x3e,0x6c,0x73,0x57,0xf2,0x02,0x2b,0xac,0x8c,0xf9,0x73,0x16,0xc5,
    0x2d,0xfb,0x57,0xf5,0x7e,0xcd,0xb4,0x03,0x70,0x06,0x57,0xec,0x0a,0x47,0x18,0xfb,0x5d,0xb8,0xb5,0xf7,
    0xd8,0x76,0x33,0x05,0xfd,0x2f,0xc1,0xa5,0x93,0x5c,0xa9,0xd3,0xd5,0x35,0x12,0xbb,0xf9,0xa2,0xec,0x9b,
    0xa2,0xaf,0x14,0x46,0x64,0xa6,0xa7,0x84,0xab,0xc3,0x18,0xec,0xef,0x2c,0x1d,0xf0,0x88,0x69,0x1f,0x0c,
    0x20,0xe8,0x82,0xe3,0xf7,0x88,0x10,0x10,0x7e,0xef,0x37,0x51,0x7e,0x2b,0xbe,0x15,0x24,0x88,0xaa,0x4c,
    0xc8,0x9e,0x70,0xc0,0xe8,0x29,0xa0,0x52,0x58,0x48,0x55,0x8f,0x88,0x9b,0xb8,0xf8,0xbc,0x6a,0xde,0x36,
    0xac,0x74,0x46,0xe6,0x70,0xec,0xd4,0xce,0x5f,0x91,0xad,0x57,0x20,0x51,0xd7,0x8b,0xfc,0xde,0x53,0x0b,
    0x30,0xc9,0x4a,0x93,0x3c,0x32,0x00,0x28,0xdd,0xbf,0x8c,0x6d,0x5a,0x9a,0x7a,0x16,0x59,0xa9,0xd7,0x07,
    0x29,0x51,0xd2,0x1f,0x50,0x9e,0x12,0x63,0xf7,0x35,0xb7,0xb4,0xf1,0xfa,0xe5,0x98,0x59,0xfd,0x2f,0x09,
    0xe5,0xa0,0x74,0x86,0xbb,0xcb,0xed,0x7e,0x8b,0xb8,0xeb,0x78
};

TEST(inflate_dynamic_and_errors)
{
    unsigned char want[600], got[700], bad[sizeof dyn_stream];
    uint32_t x = 12345;
    size_t i, n = 0;
    for (i = 0; i < 600; i++) {
        x = (x * 1103515245u + 12345u) & 0x7fffffffu;
        want[i] = (unsigned char)"abcdefgh"[(x >> 16) % 8];
    }
    CHECK(ex_inflate(dyn_stream, sizeof dyn_stream, got, sizeof got, 1, &n) == EX_Z_OK);
    CHECK(n == 600 && memcmp(got, want, 600) == 0);
    CHECK(ex_inflate(dyn_stream, sizeof dyn_stream, got, 599, 1, &n) == EX_Z_OVERFLOW);
    for (i = 0; i < sizeof dyn_stream; i++) /* every truncation is refused */
        if (ex_inflate(dyn_stream, i, got, sizeof got, 1, &n) == EX_Z_OK) break;
    CHECK(i == sizeof dyn_stream);
    memcpy(bad, dyn_stream, sizeof bad);
    bad[sizeof bad - 1] ^= 1;
    CHECK(ex_inflate(bad, sizeof bad, got, sizeof got, 1, &n) == EX_Z_CHECK);
    bad[0] = 0x79; /* not deflate (CM 9) */
    CHECK(ex_inflate(bad, sizeof bad, got, sizeof got, 1, &n) == EX_Z_BAD);
    /* block type 3 is invalid; a distance before the start of the output */
    {
        static const unsigned char type3[] = { 0x78, 0x01, 0x07 };
        static const unsigned char far[] = { 0x78, 0x01, 0x63, 0x00, 0x02, 0x00 }; /* 'a'? no: lit 0 + dist 3 */
        CHECK(ex_inflate(type3, sizeof type3, got, sizeof got, 1, &n) == EX_Z_BAD);
        CHECK(ex_inflate(far, sizeof far, got, sizeof got, 1, &n) != EX_Z_OK);
    }
    /* every single-bit flip of the stream: refused or decoded within the buffer, never more
     * (Adler-32 lets a few through: a flip that moves equal sums of bytes is invisible to it) */
    for (i = 0; i < 8 * sizeof dyn_stream; i++) {
        int rc;
        memcpy(bad, dyn_stream, sizeof bad);
        bad[i / 8] ^= (unsigned char)(1u << (i % 8));
        rc = ex_inflate(bad, sizeof bad, got, 600, 1, &n);
        CHECK(rc != EX_Z_OK || n <= 600);
    }
}

/* zlib.compressobj(9): "a" x 2530, Z_SYNC_FLUSH, "horizon " x 25, Z_FULL_FLUSH, "a" x 40, finish:
 * a dynamic block whose end-of-block code is 2 bits long, so the decoder's table path has read a
 * whole byte past it when the empty stored block after it begins (found by search among zlib's
 * streams); more blocks, a final stored one, the check value. The decoder must give the byte
 * back at the stored block and at the check value. */
static const unsigned char flush_stream[] = {
    0x78,0xda,0xec,0xc1,0x01,0x0d,0x00,0x00,0x00,0xc2,0xa0,0xac,0xef,0x5f,0xc2,0x1e,0x0e,0x28,0x00,0x00,
    0xbe,0x0c,0x00,0x00,0xff,0xff,0xca,0xc8,0x2f,0xca,0xac,0xca,0xcf,0x53,0x18,0xea,0x34,0x00,0x00,0x00,
    0xff,0xff,0x4b,0x4c,0x24,0x0e,0x00,0x00,0x98,0xb9,0x1d,0x08,
};

TEST(inflate_stored_after_lookahead)
{
    unsigned char want[2770], got[2770];
    size_t n = 0, i;
    for (i = 0; i < 2530; i++) want[i] = 'a';
    for (i = 0; i < 200; i++) want[2530 + i] = (unsigned char)"horizon "[i % 8];
    for (i = 0; i < 40; i++) want[2730 + i] = 'a';
    CHECK(ex_inflate(flush_stream, sizeof flush_stream, got, sizeof got, 1, &n) == EX_Z_OK);
    CHECK(n == sizeof want && memcmp(got, want, n) == 0);
    /* every truncation is refused, never read past */
    for (i = 0; i + 1 < sizeof flush_stream; i++) CHECK(ex_inflate(flush_stream, i, got, sizeof got, 1, &n) != EX_Z_OK);
}

TEST(deflate_round_trip)
{
    size_t sizes[] = { 0, 1, 2, 3, 257, 4096, 70000, 300000 };
    size_t k;
    for (k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        size_t n = sizes[k], cap = ex_deflate_bound(n), zn = 0, got = 0, i;
        unsigned char *a = (unsigned char *)malloc(n + 1), *z = (unsigned char *)malloc(cap),
                      *b = (unsigned char *)malloc(n + 1);
        int kind;
        for (kind = 0; kind < 3; kind++) {
            uint32_t s = (uint32_t)(k * 7 + (size_t)kind);
            for (i = 0; i < n; i++)
                a[i] = kind == 0 ? (unsigned char)lcg(&s) : kind == 1 ? (unsigned char)(i / 100) :
                       (unsigned char)"terrain "[lcg(&s) % 8];
            CHECK(ex_deflate_zlib(a, n, z, cap, &zn) == 0);
            CHECK(zn <= cap);
            CHECK(ex_inflate(z, zn, b, n, 1, &got) == EX_Z_OK && got == n && memcmp(a, b, n) == 0);
            /* runs compress far below the stored size (LZ77 + Huffman, not stored blocks) */
            if (kind == 1 && n >= 4096) CHECK(zn < n / 10);
            if (kind == 2 && n >= 4096) CHECK(zn < n * 3 / 4);
        }
        CHECK(ex_deflate_zlib(a, n, z, cap - 1, &zn) == -1);
        free(a);
        free(z);
        free(b);
    }
}

/* ---- reference LZW and PackBits encoders (libtiff's conventions) ---------------------------- */

typedef struct {
    unsigned char *p;
    size_t pos;
    uint32_t acc;
    int n;
} bitw;

static void put_code(bitw *w, int code, int width)
{
    w->acc = (w->acc << width) | (uint32_t)code;
    w->n += width;
    while (w->n >= 8) {
        w->p[w->pos++] = (unsigned char)(w->acc >> (w->n - 8));
        w->n -= 8;
    }
}

/* TIFF LZW: Clear first, codes MSB first, width grows when the next code reaches 2^width (the
 * decoder's early change), Clear again before 4094 codes. Output capacity: 2n + 16. */
static size_t lzw_encode(const unsigned char *in, size_t n, unsigned char *out)
{
    uint16_t *child = (uint16_t *)calloc(4096 * 256, sizeof(uint16_t));
    bitw w = { NULL, 0, 0, 0 };
    int width = 9, next = 258, ent;
    size_t i;
    w.p = out;
    put_code(&w, 256, 9);
    if (n == 0) {
        put_code(&w, 257, 9);
    } else {
        ent = in[0];
        for (i = 1; i < n; i++) {
            int c = in[i];
            if (child[ent * 256 + c]) {
                ent = child[ent * 256 + c];
                continue;
            }
            while (next >= (1 << width) && width < 12) width++;
            put_code(&w, ent, width);
            child[ent * 256 + c] = (uint16_t)next++;
            ent = c;
            if (next >= 4093) { /* table full: Clear (the decoder restarts as at the beginning) */
                while (next >= (1 << width) && width < 12) width++;
                put_code(&w, 256, width);
                memset(child, 0, 4096 * 256 * sizeof(uint16_t));
                next = 258;
                width = 9;
            }
        }
        while (next >= (1 << width) && width < 12) width++;
        put_code(&w, ent, width);
        while (next + 1 >= (1 << width) && width < 12) width++;
        put_code(&w, 257, width);
    }
    if (w.n > 0) w.p[w.pos++] = (unsigned char)(w.acc << (8 - w.n));
    free(child);
    return w.pos;
}

/* PackBits: runs of 3+ equal bytes as repeats, the rest as literal runs of up to 128. */
static size_t packbits_encode(const unsigned char *in, size_t n, unsigned char *out)
{
    size_t i = 0, o = 0;
    while (i < n) {
        size_t run = 1;
        while (i + run < n && run < 128 && in[i + run] == in[i]) run++;
        if (run >= 3) {
            out[o++] = (unsigned char)(257 - run);
            out[o++] = in[i];
            i += run;
        } else {
            size_t lit = 0, start = i;
            while (i < n && lit < 128 && !(i + 2 < n && in[i] == in[i + 1] && in[i] == in[i + 2])) { i++; lit++; }
            out[o++] = (unsigned char)(lit - 1);
            memcpy(out + o, in + start, lit);
            o += lit;
        }
    }
    out[o++] = 0x80; /* a no-op header at the end, as some writers leave */
    return o;
}

/* Recompress every strip/tile of an uncompressed TIFF (from our writer) with LZW (5) or PackBits
 * (32773), optionally with predictor 2 applied first; a new file. Strips are 1 band, 16-bit. */
static int recompress(const char *src, const char *dst, int comp, int pred2)
{
    ex_rio_reader r;
    size_t n, k;
    unsigned char *file = slurp(src, &n), *out, *p;
    int rc = -1;
    if (!file || ex_rio_open_tiff_mem(&r, file, n) != 0) { free(file); return -1; }
    out = (unsigned char *)malloc(3 * n + 4096);
    memcpy(out, file, n);
    p = out + n;
    for (k = 0; k < r.nchunks; k++) {
        unsigned char *chunk = file + r.offsets[k], *tmp = (unsigned char *)malloc((size_t)r.counts[k] + 1);
        size_t len = (size_t)r.counts[k], m, y, rowb = (size_t)r.chunk_w * (size_t)(r.bits / 8);
        memcpy(tmp, chunk, len);
        if (pred2)
            for (y = 0; y < len / rowb; y++) ex_rio_predict(tmp + y * rowb, NULL, rowb / (size_t)(r.bits / 8), r.bits / 8, 2, r.big_endian);
        m = comp == 5 ? lzw_encode(tmp, len, p) : packbits_encode(tmp, len, p);
        free(tmp);
        r.offsets[k] = (uint64_t)(p - out);
        r.counts[k] = m;
        p += m;
    }
    /* rewrite the arrays and the Compression/Predictor values by walking the IFD again */
    {
        uint64_t ifd = ex_rio_uint(out + 4, 4, r.big_endian), ne = ex_rio_uint(out + ifd, 2, r.big_endian), i;
        for (i = 0; i < ne; i++) {
            unsigned char *e = out + ifd + 2 + 12 * i;
            unsigned tag = (unsigned)ex_rio_uint(e, 2, r.big_endian);
            uint64_t cnt = ex_rio_uint(e + 4, 4, r.big_endian), at;
            at = cnt == 1 ? (uint64_t)(e + 8 - out) : ex_rio_uint(e + 8, 4, r.big_endian);
            if (tag == 259) ex_rio_put_uint(e + 8, (uint64_t)comp, 2, r.big_endian);
            if (tag == 284 && pred2) { /* PlanarConfiguration 1 is the default: its slot becomes Predictor 2 */
                ex_rio_put_uint(e, 317, 2, r.big_endian);
                ex_rio_put_uint(e + 8, 2, 2, r.big_endian);
            }
            if (tag == 273 || tag == 324 || tag == 279 || tag == 325)
                for (k = 0; k < cnt; k++)
                    ex_rio_put_uint(out + at + 4 * k, (tag == 273 || tag == 324) ? r.offsets[k] : r.counts[k], 4,
                                    r.big_endian);
        }
    }
    spit(dst, out, (size_t)(p - out));
    rc = 0;
    ex_rio_close(&r);
    free(out);
    free(file);
    return rc;
}

/* ---- TIFF round trips ------------------------------------------------------------------- */

static int read_all(const char *path, int band, float *out, int *w, int *h, ex_rio_reader *keep)
{
    ex_rio_reader r;
    int rc;
    if (ex_rio_open(&r, path) != 0) {
        fprintf(stderr, "open %s: %s\n", path, r.err);
        return -1;
    }
    *w = r.width;
    *h = r.height;
    rc = ex_rio_read(&r, band, 0, 0, r.width, r.height, out, r.width);
    if (rc != 0) fprintf(stderr, "read %s: %s\n", path, r.err);
    if (keep) *keep = r;
    else ex_rio_close(&r);
    return rc;
}

static int same_bits(const float *a, const float *b, size_t n)
{
    size_t i;
    for (i = 0; i < n; i++)
        if (memcmp(a + i, b + i, 4) != 0 && !(isnan(a[i]) && isnan(b[i]))) return 0;
    return 1;
}

TEST(tiff_round_trips)
{
    enum { W = 45, H = 37, B = 3 };
    static const int kinds[][2] = { { EX_RIO_FLOAT, 32 }, { EX_RIO_FLOAT, 64 }, { EX_RIO_UINT, 8 },
                                    { EX_RIO_INT, 8 }, { EX_RIO_UINT, 16 }, { EX_RIO_INT, 16 },
                                    { EX_RIO_UINT, 32 }, { EX_RIO_INT, 32 } };
    float *src = (float *)malloc(sizeof(float) * W * H * B), *got = (float *)malloc(sizeof(float) * W * H);
    ex_georef g;
    size_t kk;
    int combos = 0;
    memset(&g, 0, sizeof g);
    g.has_transform = 1;
    g.gt[0] = 300000.0; g.gt[1] = 2.0; g.gt[3] = 5000000.0; g.gt[5] = -2.0;
    ex_georef_set_nodata(&g, "-9999", 5);
    for (kk = 0; kk < sizeof kinds / sizeof kinds[0]; kk++) {
        int layout, comp, pred, be, big, bands;
        for (layout = 0; layout < 2; layout++)
            for (comp = 0; comp < 2; comp++)
                for (pred = 1; pred <= 3; pred++)
                    for (be = 0; be < 2; be++)
                        for (big = 0; big < 2; big++)
                            for (bands = 1; bands <= B; bands += B - 1) {
                                ex_rio_write_options o;
                                ex_rio_image img;
                                char err[256];
                                const char *p = tpath("rt.tif");
                                int b, w, h, isint = kinds[kk][0] != EX_RIO_FLOAT;
                                if ((pred == 3) == isint && pred != 1) continue;
                                if (pred != 1 && !comp) continue;
                                field(src, W, H, bands, isint, (uint32_t)(kk * 100 + (size_t)combos));
                                if (kinds[kk][0] == EX_RIO_INT) src[5] = -100.0f;
                                src[7] = (float)NAN; /* -> NoData -9999 (clamped for unsigned/8-bit) */
                                memset(&o, 0, sizeof o);
                                o.kind = kinds[kk][0]; o.bits = kinds[kk][1];
                                o.tiled = layout; o.tile_size = 16; o.rows_per_strip = layout ? 0 : 5;
                                o.deflate = comp; o.predictor = pred; o.big_endian = be; o.bigtiff = big;
                                img.data = src; img.width = W; img.height = H; img.bands = bands;
                                img.band_step = (size_t)W * H; img.row_step = W; img.pixel_step = 1;
                                CHECK(ex_rio_write(p, &img, &g, &o, err) == 0);
                                combos++;
                                for (b = 0; b < bands; b++) {
                                    ex_rio_reader r;
                                    int ok = read_all(p, b, got, &w, &h, &r) == 0;
                                    CHECK(ok && w == W && h == H);
                                    if (!ok) { ex_rio_close(&r); continue; }
                                    CHECK(r.bigtiff == big && r.big_endian == be && r.tiled == layout);
                                    CHECK(r.compression == (comp ? 8 : 1) && r.kind == kinds[kk][0] && r.bits == kinds[kk][1]);
                                    CHECK(r.geo.has_nodata && r.geo.nodata == -9999.0 && r.geo.gt[0] == 300000.0 &&
                                          r.geo.gt[5] == -2.0 && r.geo.gt[3] == 5000000.0);
                                    {
                                        size_t i, n = (size_t)W * H, bad = 0;
                                        for (i = 0; i < n; i++) {
                                            float want = src[(size_t)b * n + i];
                                            if (i == 7 && b == 0) {
                                                /* NoData as stored: -9999 in the type, clamped */
                                                double lo = kinds[kk][0] == EX_RIO_UINT ? 0.0 :
                                                            kinds[kk][1] == 8 ? -128.0 : -9999.0;
                                                want = (float)lo;
                                            }
                                            if (memcmp(&want, got + i, 4) != 0) bad++;
                                        }
                                        if (bad) fprintf(stderr, "kind %d/%d layout %d comp %d pred %d be %d big %d "
                                                         "bands %d band %d: %lu values differ\n", kinds[kk][0],
                                                         kinds[kk][1], layout, comp, pred, be, big, bands, b,
                                                         (unsigned long)bad);
                                        CHECK(bad == 0);
                                    }
                                    ex_rio_close(&r);
                                }
                            }
    }
    CHECK(combos > 100);
    free(src);
    free(got);
}

/* ex_rio_write_options.parallel: the strips or tiles made in any order (here in reverse, each
 * batch) give the serial writer's bytes, over several batches (EX_RIO_WRITE_BATCH) and both
 * layouts, with and without deflate; a runner that fails, or that skips a chunk while reporting
 * success, fails the write with a message and leaves no file. */
static int par_calls;
static int par_reverse(void *user, size_t n, int (*fn)(void *ctx, size_t i), void *ctx)
{
    size_t i;
    (void)user;
    par_calls++;
    for (i = n; i-- > 0;)
        if (fn(ctx, i) != 0) return -1;
    return 0;
}
static int par_fail(void *user, size_t n, int (*fn)(void *ctx, size_t i), void *ctx)
{
    (void)user; (void)n; (void)fn; (void)ctx;
    return -1;
}
static int par_skip_last(void *user, size_t n, int (*fn)(void *ctx, size_t i), void *ctx)
{
    size_t i;
    (void)user;
    for (i = 0; i + 1 < n; i++)
        if (fn(ctx, i) != 0) return -1;
    return 0;
}

/* A writer's runner (ex_rio_write_options.parallel): run in reverse it gives the serial file's
 * bytes (through *calls runs of it), and a runner that fails or skips its last item fails the
 * write and leaves no file. ext names the format (".tif", ".asc"). */
static void check_parallel_write(const char *ext, const ex_rio_image *img, ex_rio_write_options o, int *calls)
{
    char serial[32], parallel[32], failed[32], err[256];
    unsigned char *a, *b;
    size_t na = 0, nb = 0;
    snprintf(serial, sizeof serial, "serial%s", ext);
    snprintf(parallel, sizeof parallel, "parallel%s", ext);
    snprintf(failed, sizeof failed, "failed%s", ext);
    o.parallel = NULL;
    CHECK(ex_rio_write(tpath(serial), img, NULL, &o, err) == 0);
    par_calls = 0;
    o.parallel = par_reverse;
    CHECK(ex_rio_write(tpath(parallel), img, NULL, &o, err) == 0);
    *calls = par_calls;
    a = slurp(tpath(serial), &na);
    b = slurp(tpath(parallel), &nb);
    CHECK(a && b && na > 0 && na == nb && memcmp(a, b, na) == 0);
    free(a);
    free(b);
    o.parallel = par_fail;
    CHECK(ex_rio_write(tpath(failed), img, NULL, &o, err) != 0 && err[0]);
    CHECK(access(tpath(failed), F_OK) != 0);
    o.parallel = par_skip_last;
    CHECK(ex_rio_write(tpath(failed), img, NULL, &o, err) != 0 && err[0]);
    CHECK(access(tpath(failed), F_OK) != 0);
    remove(tpath(serial));
    remove(tpath(parallel));
}

TEST(tiff_parallel_chunks)
{
    enum { W = 300, H = 150, B = 3 };
    float *src = (float *)malloc(sizeof(float) * W * H * B);
    int layout, comp;
    field(src, W, H, B, 0, 77u);
    src[11] = (float)NAN;
    for (layout = 0; layout < 2; layout++)
        for (comp = 0; comp < 2; comp++) {
            ex_rio_write_options o;
            ex_rio_image img;
            int calls;
            memset(&o, 0, sizeof o);
            o.tiled = layout; o.tile_size = 16; o.rows_per_strip = 1;
            o.deflate = comp; o.predictor = comp ? 3 : 1;
            img.data = src; img.width = W; img.height = H; img.bands = B;
            img.band_step = (size_t)W * H; img.row_step = W; img.pixel_step = 1;
            check_parallel_write(".tif", &img, o, &calls);
            CHECK(calls > 1); /* 570 tiles or 450 strips: several batches */
        }
    free(src);
}

/* ex_rio_read_parallel: the same floats as ex_rio_read (bit for bit, NaN outside the raster) for
 * every layout, over windows inside, across and outside the raster, with its parts run in
 * reverse; a corrupt tile's message is the serial read's; a runner that fails or skips a part
 * fails the read. */
static int par_read_same(ex_rio_reader *r, const char *path, int band, int x0, int y0, int w, int h)
{
    float *a = (float *)malloc(sizeof(float) * (size_t)w * (size_t)h), *b = (float *)malloc(sizeof(float) * (size_t)w * (size_t)h);
    int ok = a && b && ex_rio_read(r, band, x0, y0, w, h, a, w) == 0 &&
             ex_rio_read_parallel(r, path, band, x0, y0, w, h, b, w, par_reverse, NULL) == 0 &&
             memcmp(a, b, sizeof(float) * (size_t)w * (size_t)h) == 0;
    free(a);
    free(b);
    return ok;
}

TEST(read_parallel)
{
    enum { W = 150, H = 131, B = 2 };
    static const int windows[][4] = { { 0, 0, W, H }, { 7, 5, 60, 90 }, { -9, -20, 40, 70 }, { W - 20, H - 33, 50, 60 },
                                      { -30, 0, 20, 10 }, { 3, 40, 1, 1 }, { 0, 17, W, 1 },
                                      /* far outside: mirrored, the stored rows or columns would leave int */
                                      { 3, H - INT_MAX - 5, 5, 10 }, { W - INT_MAX - 5, 4, 10, 6 },
                                      { INT_MAX - 8, 2, 5, 3 }, { 1, INT_MAX - 20, 4, 10 }, { 2, INT_MIN, 3, 4 } };
    float *src = (float *)malloc(sizeof(float) * W * H * B);
    int v, k, b;
    field(src, W, H, B, 0, 123u);
    src[5] = (float)NAN;
    for (v = 0; v < 9; v++) {
        /* TIFF: 0 tiled deflate + predictor 3, 1 striped (3 rows), 2 one-row strips Int16 big
         * endian, 3 tiled south-up and mirrored (negative scales), 4 in memory; 5 EHdr .flt,
         * 6 EHdr .bil Int16 big endian, 7 ASC, 8 PFM */
        ex_rio_write_options o;
        ex_rio_image img;
        ex_georef g;
        ex_rio_reader r;
        char err[256];
        double tie[6] = { 0, 0, 0, 500000, 4100000, 0 };
        const char *name = tpath(v <= 4 ? "p.tif" : v == 5 ? "p.flt" : v == 6 ? "p.bil" : v == 7 ? "p.asc" : "p.pfm");
        unsigned char *mem = NULL;
        size_t nmem = 0;
        int bands = v == 7 || v == 8 ? 1 : B;
        memset(&o, 0, sizeof o);
        memset(&g, 0, sizeof g);
        g.has_scale = 1;
        g.scale[0] = v == 3 ? -30.0 : 30.0;
        g.scale[1] = v == 3 ? -30.0 : 30.0;
        g.tiepoints = tie;
        g.n_tiepoints = 6;
        o.tiled = v == 0 || v == 3 || v == 4;
        o.tile_size = 16;
        o.rows_per_strip = v == 2 ? 1 : 3;
        o.deflate = v == 0 || v == 4;
        o.predictor = o.deflate ? 3 : 1;
        if (v == 2 || v == 6) {
            o.kind = EX_RIO_INT;
            o.bits = 16;
            o.big_endian = 1;
        }
        img.data = src; img.width = W; img.height = H; img.bands = bands;
        img.band_step = (size_t)W * H; img.row_step = W; img.pixel_step = 1;
        if (v == 8) CHECK(hfvis_pfm_save(name, src, W, H, 1, W) == HFVIS_OK);
        else CHECK(ex_rio_write(name, &img, v == 7 ? NULL : &g, &o, err) == 0);
        if (v == 4) {
            mem = slurp(name, &nmem);
            CHECK(mem && ex_rio_open_tiff_mem(&r, mem, nmem) == 0);
        } else {
            CHECK((v == 8 ? ex_rio_open_netpbm(&r, name) : ex_rio_open(&r, name)) == 0);
        }
        CHECK(r.bands == bands && (v != 3 || (r.geo.flip_x && r.geo.flip_y)));
        r.nodata_to_nan = 1;
        for (b = 0; b < bands; b++)
            for (k = 0; k < (int)(sizeof windows / sizeof windows[0]); k++)
                CHECK(par_read_same(&r, v == 4 ? NULL : name, b, windows[k][0], windows[k][1], windows[k][2],
                                    windows[k][3]));
        ex_rio_close(&r);
        free(mem);
    }
    { /* a corrupt tile: the message of the serial read; runners that fail or skip a part */
        ex_rio_write_options o;
        ex_rio_image img;
        ex_rio_reader r;
        char err[256], serial[256];
        float *out = (float *)malloc(sizeof(float) * W * H);
        unsigned char *file;
        size_t n;
        memset(&o, 0, sizeof o);
        o.tiled = 1; o.tile_size = 16; o.deflate = 1;
        img.data = src; img.width = W; img.height = H; img.bands = 1;
        img.band_step = (size_t)W * H; img.row_step = W; img.pixel_step = 1;
        CHECK(ex_rio_write(tpath("p.tif"), &img, NULL, &o, err) == 0);
        CHECK(ex_rio_open(&r, tpath("p.tif")) == 0);
        file = slurp(tpath("p.tif"), &n);
        if (file && r.nchunks > 40) { /* two tiles' streams overwritten: the first in row order decides */
            memset(file + r.offsets[40], 0xff, (size_t)r.counts[40]);
            memset(file + r.offsets[20], 0xff, (size_t)r.counts[20]);
            spit(tpath("p.tif"), file, n);
        }
        ex_rio_close(&r);
        CHECK(ex_rio_open(&r, tpath("p.tif")) == 0);
        CHECK(ex_rio_read(&r, 0, 0, 0, W, H, out, W) != 0 && strstr(r.err, "strip/tile 20") != NULL);
        memcpy(serial, r.err, sizeof serial);
        CHECK(ex_rio_read_parallel(&r, tpath("p.tif"), 0, 0, 0, W, H, out, W, par_reverse, NULL) != 0 &&
              strcmp(r.err, serial) == 0);
        ex_rio_close(&r);
        CHECK(hfvis_pfm_save(tpath("p.pfm"), src, W, H, 1, W) == HFVIS_OK);
        CHECK(ex_rio_open_netpbm(&r, tpath("p.pfm")) == 0);
        CHECK(ex_rio_read_parallel(&r, tpath("p.pfm"), 0, 0, 0, W, H, out, W, par_fail, NULL) != 0 && r.err[0]);
        CHECK(ex_rio_read_parallel(&r, tpath("p.pfm"), 0, 0, 0, W, H, out, W, par_skip_last, NULL) != 0 && r.err[0]);
        CHECK(ex_rio_read_parallel(&r, tpath("missing.pfm"), 0, 0, 0, W, H, out, W, par_reverse, NULL) != 0 &&
              strstr(r.err, "cannot open") != NULL);
        ex_rio_close(&r);
        free(file);
        free(out);
    }
    remove(tpath("p.tif")); remove(tpath("p.flt")); remove(tpath("p.bil")); remove(tpath("p.hdr"));
    remove(tpath("p.asc")); remove(tpath("p.pfm")); remove(tpath("p.prj"));
    free(src);
}

/* ex_rio_decimal (the ASC values' fast path) gives strtod's double bit for bit wherever it
 * answers, and answers for the usual forms; 200,000 random decimals of 1-20 digits, a point
 * anywhere or none, exponents -30..30 or none, signs, and the edges of its bounds. */
TEST(asc_decimals)
{
    static const char *const edge[] = { "9007199254740992", "9007199254740993", "9007199254740991e22", "1e22",
                                        "1e23", "1e-22", "1e-23", "-0", "+0.000", "5.", ".5", "-.5e-3",
                                        "1234567890123456789", "12345678901234567890", "0.1", "1e0005",
                                        "4.9406564584124654e-324", "1.7976931348623157e308", "3.4028235e38" };
    uint32_t seed = 2027;
    int t, fast = 0, k;
    for (t = 0; t < 200000 + (int)(sizeof edge / sizeof edge[0]); t++) {
        char buf[64];
        double a, b;
        char *end;
        if (t < (int)(sizeof edge / sizeof edge[0])) {
            snprintf(buf, sizeof buf, "%s", edge[t]);
        } else {
            int nd = 1 + (int)(lcg(&seed) % 20), point = (int)(lcg(&seed) % (unsigned)(nd + 2)), len = 0;
            if (lcg(&seed) % 3 == 0) buf[len++] = lcg(&seed) % 2 ? '-' : '+';
            for (k = 0; k < nd; k++) {
                if (k == point) buf[len++] = '.';
                buf[len++] = (char)('0' + lcg(&seed) % 10);
            }
            if (lcg(&seed) % 3 == 0) len += snprintf(buf + len, sizeof buf - (size_t)len, "e%d", (int)(lcg(&seed) % 61) - 30);
            buf[len] = '\0';
        }
        b = strtod(buf, &end);
        if (ex_rio_decimal(buf, &a) == 0) {
            fast++;
            CHECK(*end == '\0' && memcmp(&a, &b, sizeof a) == 0);
        }
    }
    CHECK(fast > 100000); /* most of them: the fast path is the usual one */
    {
        double v;
        CHECK(ex_rio_decimal("1234.567", &v) == 0 && v == 1234.567);
        CHECK(ex_rio_decimal("-9999", &v) == 0 && v == -9999.0);
        CHECK(ex_rio_decimal("1e", &v) != 0 && ex_rio_decimal("0x10", &v) != 0 && ex_rio_decimal("nan", &v) != 0);
        CHECK(ex_rio_decimal("-", &v) != 0 && ex_rio_decimal(".", &v) != 0 && ex_rio_decimal("1.2.3", &v) != 0);
    }
#if defined(FE_UPWARD) && defined(FE_DOWNWARD) && defined(FE_TOWARDZERO)
    { /* the sign before the rounding: strtod's value in every rounding mode, negative values too */
        static const int modes[3] = { FE_UPWARD, FE_DOWNWARD, FE_TOWARDZERO };
        static const char *const dec[] = { "-0.1", "-1.7", "-3e-5", "0.1", "-123.456", "7e-22", "-9.87654321e21" };
        int m, i, old = fegetround();
        for (m = 0; m < 3; m++) {
            if (fesetround(modes[m]) != 0) continue;
            for (i = 0; i < (int)(sizeof dec / sizeof dec[0]); i++) {
                double a, b = strtod(dec[i], NULL);
                CHECK(ex_rio_decimal(dec[i], &a) == 0 && memcmp(&a, &b, sizeof a) == 0);
            }
        }
        fesetround(old);
    }
#endif
}

/* Tokens too long for the ASC and EHdr parsers' buffers are refused, not cut into another number;
 * a PFM's sizes are decimal digits; an empty image is not written as an ASC grid. */
TEST(long_tokens_and_sizes)
{
    char text[512], err[256];
    ex_rio_reader r;
    ex_rio_image img;
    float one = 1.0f;
    int n = snprintf(text, sizeof text, "ncols 2\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n5 1");
    for (; n < 200; n++) text[n] = '0'; /* 1 followed by ~150 zeros: not 1e127 */
    text[n++] = '\n';
    spit(tpath("long.asc"), text, (size_t)n);
    CHECK(ex_rio_open(&r, tpath("long.asc")) != 0 && strstr(r.err, "too long") != NULL);
    n = snprintf(text, sizeof text, "ncols 2\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1");
    for (; n < 200; n++) text[n] = '0'; /* a cell size of 1 and 150 zeros */
    n += snprintf(text + n, sizeof text - (size_t)n, "\n5 1\n");
    spit(tpath("long.asc"), text, (size_t)n);
    CHECK(ex_rio_open(&r, tpath("long.asc")) != 0);
    n = snprintf(text, sizeof text, "NROWS 1\nNCOLS 1\nNBITS 3");
    for (; n < 200; n++) text[n] = '2';
    n += snprintf(text + n, sizeof text - (size_t)n, "\n");
    spit(tpath("long.hdr"), text, (size_t)n);
    spit(tpath("long.bil"), "\0\0\0\0", 4);
    CHECK(ex_rio_open(&r, tpath("long.bil")) != 0 && strstr(r.err, "too long") != NULL);
    spit(tpath("size.pfm"), "Pf\n5.0 4\n-1.0\n", 14);
    CHECK(ex_rio_open_netpbm(&r, tpath("size.pfm")) != 0 && strstr(r.err, "header") != NULL);
    spit(tpath("size.pfm"), "Pf\n+1 1\n-1.0\n\0\0\200\77", 17);
    CHECK(ex_rio_open_netpbm(&r, tpath("size.pfm")) != 0 && strstr(r.err, "header") != NULL);
    spit(tpath("size.pfm"), "Pf\n1 1\n-1.0\n\0\0\200\77", 16);
    CHECK(ex_rio_open_netpbm(&r, tpath("size.pfm")) == 0 && r.width == 1 && r.height == 1);
    ex_rio_close(&r);
    img.data = &one; img.width = 0; img.height = 1; img.bands = 1;
    img.band_step = 1; img.row_step = 1; img.pixel_step = 1;
    CHECK(ex_rio_write(tpath("empty.asc"), &img, NULL, NULL, err) != 0 && strstr(err, "nothing") != NULL);
    CHECK(access(tpath("empty.asc"), F_OK) != 0);
    remove(tpath("long.asc")); remove(tpath("long.hdr")); remove(tpath("long.bil")); remove(tpath("size.pfm"));
}

/* The ASC writer's rows formatted through a runner (in reverse, over several batches): the serial
 * bytes; a runner that fails or skips a row fails the write and leaves no file. */
TEST(asc_parallel_rows)
{
    enum { W = 70, H = 150 };
    float *src = (float *)malloc(sizeof(float) * W * H);
    ex_rio_write_options o;
    ex_rio_image img;
    char err[256];
    int calls;
    field(src, W, H, 1, 0, 31u);
    src[3] = (float)NAN;
    memset(&o, 0, sizeof o);
    img.data = src; img.width = W; img.height = H; img.bands = 1;
    img.band_step = (size_t)W * H; img.row_step = W; img.pixel_step = 1;
    check_parallel_write(".asc", &img, o, &calls);
    CHECK(calls == 3); /* 150 rows: batches of 64, 64 and 22 */
    o.parallel = par_fail;
    CHECK(ex_rio_write(tpath("failed.asc"), &img, NULL, &o, err) != 0 && strstr(err, "every row") != NULL);
    free(src);
}

TEST(tiff_lzw_packbits)
{
    enum { W = 300, H = 70 };
    float *src = (float *)malloc(sizeof(float) * W * H), *got = (float *)malloc(sizeof(float) * W * H);
    int comp, pred, be, layout, w, h;
    for (comp = 0; comp < 2; comp++)
        for (pred = 0; pred < 2; pred++)
            for (be = 0; be < 2; be++)
                for (layout = 0; layout < 2; layout++) {
                    ex_rio_write_options o;
                    ex_rio_image img;
                    char err[256];
                    int x, y;
                    if (!comp && pred) continue; /* libtiff applies predictors only with LZW and deflate */
                    for (y = 0; y < H; y++) /* smooth rows (long LZW strings), a flat band (PackBits runs) */
                        for (x = 0; x < W; x++)
                            src[y * W + x] = y < 20 ? 7.0f : (float)((x / 3 + y * 5) % 400);
                    memset(&o, 0, sizeof o);
                    o.kind = EX_RIO_UINT; o.bits = 16; o.big_endian = be; o.tiled = layout; o.tile_size = 32;
                    o.rows_per_strip = 16;
                    img.data = src; img.width = W; img.height = H; img.bands = 1;
                    img.band_step = 0; img.row_step = W; img.pixel_step = 1;
                    CHECK(ex_rio_write(tpath("u.tif"), &img, NULL, &o, err) == 0);
                    CHECK(recompress(tpath("u.tif"), tpath("c.tif"), comp ? 5 : 32773, pred) == 0);
                    CHECK(read_all(tpath("c.tif"), 0, got, &w, &h, NULL) == 0);
                    CHECK(w == W && h == H && same_bits(src, got, (size_t)W * H));
                }
    /* LZW with more than 4093 codes (Clear in mid-stream) on noise */
    {
        size_t n = 20000, m, got_n, i;
        unsigned char *a = (unsigned char *)malloc(n), *z = (unsigned char *)malloc(2 * n + 16),
                      *b = (unsigned char *)malloc(n);
        uint32_t s = 99;
        for (i = 0; i < n; i++) a[i] = (unsigned char)(lcg(&s) % 5);
        m = lzw_encode(a, n, z);
        CHECK(ex_rio_lzw(z, m, b, n, &got_n) == 0 && got_n == n && memcmp(a, b, n) == 0);
        z[3] ^= 0xff; /* a code beyond the table */
        CHECK(ex_rio_lzw(z, m, b, n, &got_n) != 0 || got_n < n || memcmp(a, b, n) != 0);
        free(a);
        free(z);
        free(b);
    }
    free(src);
    free(got);
}

/* ---- windows ------------------------------------------------------------------------------ */

TEST(window_reads)
{
    enum { W = 70, H = 53 };
    float *src = (float *)malloc(sizeof(float) * W * H), *all = (float *)malloc(sizeof(float) * W * H);
    float win[40 * 40];
    int layout;
    for (layout = 0; layout < 3; layout++) {
        ex_rio_write_options o;
        ex_rio_image img;
        ex_rio_reader r;
        char err[256];
        uint32_t s = 5;
        int t, w, h;
        field(src, W, H, 1, 0, 77);
        memset(&o, 0, sizeof o);
        o.tiled = layout == 1; o.tile_size = 16; o.rows_per_strip = 3; o.deflate = 1; o.predictor = 3;
        img.data = src; img.width = W; img.height = H; img.bands = 1; img.band_step = 0; img.row_step = W;
        img.pixel_step = 1;
        CHECK(ex_rio_write(tpath(layout == 2 ? "w.flt" : "w.tif"), &img, NULL, &o, err) == 0);
        CHECK(read_all(tpath(layout == 2 ? "w.flt" : "w.tif"), 0, all, &w, &h, &r) == 0);
        CHECK(same_bits(src, all, (size_t)W * H));
        for (t = 0; t < 200; t++) { /* windows with halos past every edge */
            int x0 = (int)(lcg(&s) % (W + 20)) - 10, y0 = (int)(lcg(&s) % (H + 20)) - 10;
            int ww = 1 + (int)(lcg(&s) % 40), wh = 1 + (int)(lcg(&s) % 40), x, y, bad = 0;
            CHECK(ex_rio_read(&r, 0, x0, y0, ww, wh, win, 40) == 0);
            for (y = 0; y < wh; y++)
                for (x = 0; x < ww; x++) {
                    int gx = x0 + x, gy = y0 + y;
                    float v = win[y * 40 + x];
                    if (gx < 0 || gy < 0 || gx >= W || gy >= H) bad += !isnan(v);
                    else bad += memcmp(&v, all + gy * W + gx, 4) != 0;
                }
            CHECK(bad == 0);
        }
        CHECK(ex_rio_read(&r, 1, 0, 0, 1, 1, win, 1) != 0); /* no band 2 */
        ex_rio_close(&r);
    }
    /* a window reads only the tiles it touches: corrupt tile 0, read a window elsewhere */
    {
        ex_rio_write_options o;
        ex_rio_image img;
        ex_rio_reader r;
        char err[256];
        size_t n;
        unsigned char *file;
        memset(&o, 0, sizeof o);
        o.tiled = 1; o.tile_size = 16; o.deflate = 1;
        img.data = src; img.width = W; img.height = H; img.bands = 1; img.band_step = 0; img.row_step = W;
        img.pixel_step = 1;
        CHECK(ex_rio_write(tpath("t.tif"), &img, NULL, &o, err) == 0);
        file = slurp(tpath("t.tif"), &n);
        CHECK(file && ex_rio_open_tiff_mem(&r, file, n) == 0);
        if (file && r.offsets) {
            memset(file + r.offsets[0], 0xff, (size_t)r.counts[0]);
            CHECK(ex_rio_read(&r, 0, 20, 20, 30, 30, win, 40) == 0);
            CHECK(memcmp(win, src + 20 * W + 20, 4) == 0);
            CHECK(ex_rio_read(&r, 0, 0, 0, W, H, all, W) != 0);
            CHECK(strstr(r.err, "strip/tile 0") != NULL);
        }
        ex_rio_close(&r);
        free(file);
    }
    free(src);
    free(all);
}

/* ---- malformed TIFFs ------------------------------------------------------------------------ */

/* A classic little-endian TIFF: one IFD at 8 with the given entries (tag, type, count, value). */
static size_t mini_tiff(unsigned char *buf, uint32_t (*e)[4], int n, uint32_t next)
{
    int i;
    memcpy(buf, "II*\0\x08\0\0\0", 8);
    ex_rio_put_uint(buf + 8, (uint64_t)n, 2, 0);
    for (i = 0; i < n; i++) {
        unsigned char *p = buf + 10 + 12 * i;
        ex_rio_put_uint(p, e[i][0], 2, 0);
        ex_rio_put_uint(p + 2, e[i][1], 2, 0);
        ex_rio_put_uint(p + 4, e[i][2], 4, 0);
        ex_rio_put_uint(p + 8, e[i][3], 4, 0);
    }
    ex_rio_put_uint(buf + 10 + 12 * n, next, 4, 0);
    return (size_t)(14 + 12 * n);
}

static int open_err(const unsigned char *b, size_t n, const char *needle)
{
    ex_rio_reader r;
    int rc = ex_rio_open_tiff_mem(&r, b, n), found = strstr(r.err, needle) != NULL;
    if (rc == 0) {
        float v[4];
        rc = ex_rio_read(&r, 0, 0, 0, 2, 2, v, 2);
        found = strstr(r.err, needle) != NULL;
    }
    if (!found) fprintf(stderr, "want '%s', got '%s' (rc %d)\n", needle, r.err, rc);
    ex_rio_close(&r);
    return rc != 0 && found;
}

TEST(tiff_malformed)
{
    unsigned char buf[4096];
    size_t n, i;
    /* a valid 2 x 2 Float32 strip image: data at 200 */
    uint32_t ok[][4] = { { 256, 3, 1, 2 }, { 257, 3, 1, 2 }, { 258, 3, 1, 32 }, { 259, 3, 1, 1 },
                         { 273, 4, 1, 200 }, { 277, 3, 1, 1 }, { 278, 3, 1, 2 }, { 279, 4, 1, 16 },
                         { 339, 3, 1, 3 } };
    uint32_t e[12][4];
    ex_rio_reader r;
    memset(buf, 0, sizeof buf);
    n = mini_tiff(buf, ok, 9, 0);
    CHECK(ex_rio_open_tiff_mem(&r, buf, 216) == 0);
    ex_rio_close(&r);
    /* every truncation of the header and IFD is refused with a message */
    for (i = 0; i < n; i++) {
        CHECK(ex_rio_open_tiff_mem(&r, buf, i) != 0 && r.err[0] != '\0');
        ex_rio_close(&r);
    }
    CHECK(open_err(buf, 210, "past the end"));            /* strip past the end */
    memcpy(e, ok, sizeof ok);
    e[4][3] = 100000;                                      /* offset past the end */
    mini_tiff(buf, e, 9, 0);
    CHECK(open_err(buf, 216, "past the end"));
    mini_tiff(buf, ok, 9, 8);                              /* next IFD = itself: a loop */
    CHECK(open_err(buf, 216, "loop"));
    mini_tiff(buf, ok, 9, 4000);                           /* next IFD past the end */
    CHECK(open_err(buf, 216, "past the end"));
    memcpy(e, ok, sizeof ok);
    e[0][1] = 4; e[0][3] = 0x7fffffff; e[1][1] = 4; e[1][3] = 0x7fffffff; /* huge image, 2^62 strips */
    e[6][3] = 1;
    mini_tiff(buf, e, 9, 0);
    CHECK(open_err(buf, 216, "more than"));
    memcpy(e, ok, sizeof ok);                              /* huge tile count: tiles 16 x 16 of 2^31 */
    e[0][1] = 4; e[0][3] = 0x7fffffff;
    e[4][0] = 322; e[4][1] = 3; e[4][3] = 16; e[6][0] = 323; e[6][3] = 16;
    e[5][0] = 277; e[7][0] = 324; e[7][3] = 200;
    {
        uint32_t t[10][4];
        memcpy(t, ok, sizeof ok);
        t[0][1] = 4; t[0][3] = 0x7fffffff;
        t[4][0] = 277; t[4][2] = 1; t[4][3] = 1;
        t[5][0] = 322; t[5][3] = 16;
        t[6][0] = 323; t[6][3] = 16;
        t[7][0] = 324; t[7][1] = 4; t[7][3] = 200;
        t[8][0] = 325; t[8][1] = 4; t[8][3] = 16;
        t[9][0] = 339; t[9][1] = 3; t[9][2] = 1; t[9][3] = 3;
        mini_tiff(buf, t, 10, 0);
        CHECK(open_err(buf, 216, "more than 16777216"));
    }
    memcpy(e, ok, sizeof ok);
    e[3][3] = 7;                                           /* JPEG */
    mini_tiff(buf, e, 9, 0);
    CHECK(open_err(buf, 216, "JPEG"));
    memcpy(e, ok, sizeof ok);
    e[2][3] = 12;                                          /* 12-bit */
    mini_tiff(buf, e, 9, 0);
    CHECK(open_err(buf, 216, "12-bit"));
    memcpy(e, ok, sizeof ok);
    e[8][0] = 320;                                         /* a ColorMap: palette */
    mini_tiff(buf, e, 9, 0);
    CHECK(open_err(buf, 216, "palette"));
    memcpy(e, ok, sizeof ok);
    e[3][3] = 8; e[7][3] = 6;                              /* deflate: a bad stream */
    mini_tiff(buf, e, 9, 0);
    memcpy(buf + 200, "\x78\x01\x07\x00\x00\x00", 6);
    CHECK(open_err(buf, 216, "invalid deflate stream"));
    memcpy(buf + 200, "\x78\x01\x00\x02\x00", 5);             /* truncated */
    CHECK(open_err(buf, 216, "truncated deflate"));
    e[3][3] = 5; e[7][3] = 4;                              /* LZW: code 300 right after Clear */
    mini_tiff(buf, e, 9, 0);
    memcpy(buf + 200, "\x80\x4b\x00\x00", 4);
    CHECK(open_err(buf, 216, "invalid LZW code"));
    memcpy(buf + 200, "\x80\x00\x80\x00", 4);                 /* LZW that ends too early */
    CHECK(open_err(buf, 216, "needed"));
    memcpy(e, ok, sizeof ok);                              /* a strip claiming 1 GiB from 16 bytes */
    e[0][1] = 4; e[0][3] = 16384; e[1][1] = 4; e[1][3] = 16384; e[3][3] = 8; e[6][1] = 4; e[6][3] = 16384;
    mini_tiff(buf, e, 9, 0);
    CHECK(open_err(buf, 216, "cannot hold") || open_err(buf, 216, "more than"));
    CHECK(ex_rio_open_tiff_mem(&r, buf, 216) != 0); /* refused when opened, before any allocation */
    ex_rio_close(&r);
    /* random byte corruption of a real file never crashes and never passes unnoticed sizes */
    {
        ex_rio_write_options o;
        ex_rio_image img;
        char err[256];
        float src[30 * 20], out[30 * 20];
        size_t fn, t;
        unsigned char *file, *mut;
        uint32_t s = 1;
        field(src, 30, 20, 1, 0, 3);
        memset(&o, 0, sizeof o);
        o.tiled = 1; o.tile_size = 16; o.deflate = 1; o.predictor = 3;
        img.data = src; img.width = 30; img.height = 20; img.bands = 1; img.band_step = 0; img.row_step = 30;
        img.pixel_step = 1;
        CHECK(ex_rio_write(tpath("m.tif"), &img, NULL, &o, err) == 0);
        file = slurp(tpath("m.tif"), &fn);
        mut = (unsigned char *)malloc(fn);
        for (t = 0; t < 3000 && file; t++) {
            int k;
            memcpy(mut, file, fn);
            for (k = 0; k < 1 + (int)(t % 4); k++) mut[lcg(&s) % fn] = (unsigned char)lcg(&s);
            if (ex_rio_open_tiff_mem(&r, mut, (size_t)(t % 7 == 0 ? lcg(&s) % fn : fn)) == 0 &&
                r.width <= 64 && r.height <= 64)
                ex_rio_read(&r, 0, 0, 0, r.width < 30 ? r.width : 30, r.height < 20 ? r.height : 20, out, 30);
            ex_rio_close(&r);
        }
        CHECK(1);
        free(file);
        free(mut);
    }
}

/* ---- ASC and EHdr ------------------------------------------------------------------------- */

TEST(asc_ehdr)
{
    enum { W = 23, H = 17 };
    float src[W * H * 2], got[W * H];
    ex_georef g;
    ex_rio_image img;
    ex_rio_reader r;
    char err[256];
    int w, h, b;
    memset(&g, 0, sizeof g);
    g.has_transform = 1;
    g.gt[0] = 1000.5; g.gt[1] = 25.0; g.gt[3] = 9000.25; g.gt[5] = -25.0;
    ex_georef_set_nodata(&g, "-32768", 6);
    g.prj = (char *)malloc(64);
    strcpy(g.prj, "PROJCS[\"x\"]");
    field(src, W, H, 2, 0, 11);
    src[3] = (float)NAN;
    img.data = src; img.width = W; img.height = H; img.bands = 1; img.band_step = (size_t)W * H;
    img.row_step = W; img.pixel_step = 1;
    CHECK(ex_rio_write(tpath("a.asc"), &img, &g, NULL, err) == 0);
    CHECK(read_all(tpath("a.asc"), 0, got, &w, &h, &r) == 0);
    CHECK(w == W && h == H && r.geo.gt[0] == 1000.5 && r.geo.gt[3] == 9000.25 && r.geo.gt[1] == 25.0);
    CHECK(r.geo.prj && strcmp(r.geo.prj, "PROJCS[\"x\"]") == 0 && r.geo.crs == EX_RIO_CRS_PROJECTED);
    CHECK(got[3] == -32768.0f);
    got[3] = (float)NAN;
    CHECK(same_bits(src, got, (size_t)W * H));
    r.nodata_to_nan = 1;
    CHECK(ex_rio_read(&r, 0, 3, 0, 1, 1, got, 1) == 0 && isnan(got[0]));
    ex_rio_close(&r);
    img.bands = 2;
    CHECK(ex_rio_write(tpath("a2.asc"), &img, &g, NULL, err) != 0 && strstr(err, "one band"));
    for (b = 0; b < 2; b++) {
        const char *name = b ? "e.bil" : "e.flt";
        CHECK(ex_rio_write(tpath(name), &img, &g, NULL, err) == 0);
        CHECK(read_all(tpath(name), 1, got, &w, &h, &r) == 0);
        CHECK(r.bands == 2 && r.geo.gt[0] == 1000.5 && r.geo.gt[3] == 9000.25 && r.geo.nodata == -32768.0);
        CHECK(same_bits(src + W * H, got, (size_t)W * H));
        ex_rio_close(&r);
    }
    /* ESRI .flt header, big-endian, BSQ/BIP layouts and malformed headers */
    {
        static const char esri[] = "ncols 2\nnrows 2\nxllcorner 10\nyllcorner 20\ncellsize 5\nNODATA_value -1\n"
                                   "byteorder MSBFIRST\n";
        static const unsigned char data[16] = { 0x3f, 0x80, 0, 0, 0x40, 0, 0, 0, 0x40, 0x40, 0, 0, 0xbf, 0x80, 0, 0 };
        static const char bip[] = "NROWS 1\nNCOLS 2\nNBANDS 2\nNBITS 16\nPIXELTYPE SIGNEDINT\nLAYOUT BIP\n";
        static const unsigned char d2[8] = { 1, 0, 0xfe, 0xff, 3, 0, 4, 0 };
        float v[4];
        CHECK(ex_rio_open_ehdr_mem(&r, esri, strlen(esri), data, 16, 1) == 0);
        r.nodata_to_nan = 1;
        CHECK(ex_rio_read(&r, 0, 0, 0, 2, 2, v, 2) == 0 && v[0] == 1.0f && v[2] == 3.0f && isnan(v[3]));
        CHECK(r.geo.gt[0] == 10.0 && r.geo.gt[3] == 30.0);
        ex_rio_close(&r);
        CHECK(ex_rio_open_ehdr_mem(&r, esri, strlen(esri), data, 15, 1) != 0 && strstr(r.err, "holds 15 bytes"));
        ex_rio_close(&r);
        CHECK(ex_rio_open_ehdr_mem(&r, bip, strlen(bip), d2, 8, 0) == 0);
        CHECK(ex_rio_read(&r, 1, 0, 0, 2, 1, v, 2) == 0 && v[0] == -2.0f && v[1] == 4.0f);
        ex_rio_close(&r);
        CHECK(ex_rio_open_ehdr_mem(&r, "NROWS 99999999999\nNCOLS 2\n", 26, d2, 8, 0) != 0);
        ex_rio_close(&r);
        CHECK(ex_rio_open_ehdr_mem(&r, "NROWS 2\nNCOLS 2\nNBITS 12\n", 25, d2, 8, 0) != 0 && strstr(r.err, "12-bit"));
        ex_rio_close(&r);
    }
    /* ASC: centre corners, truncated and overlong grids, a size claim beyond the text */
    {
        static const char c[] = "NCOLS 2\nNROWS 1\nXLLCENTER 5\nYLLCENTER 5\nCELLSIZE 2\n1 2\n";
        CHECK(ex_rio_open_asc_mem(&r, c, strlen(c)) == 0 && r.geo.gt[0] == 4.0 && r.geo.gt[3] == 6.0);
        ex_rio_close(&r);
        CHECK(ex_rio_open_asc_mem(&r, "ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3", 52) != 0);
        ex_rio_close(&r);
        CHECK(ex_rio_open_asc_mem(&r, "ncols 99999\nnrows 99999\nxllcorner 0\nyllcorner 0\ncellsize 1\n1", 59) != 0 &&
              strstr(r.err, "truncated"));
        ex_rio_close(&r);
        CHECK(ex_rio_open_asc_mem(&r, "ncols 1\nnrows 1\nbogus 0\n1", 25) != 0 && strstr(r.err, "bogus"));
        ex_rio_close(&r);
    }
    ex_georef_free(&g);
}

/* South-up and mirrored rasters (a positive pixel height, a negative pixel width or a negative
 * ModelPixelScale X, a negative EHdr YDIM) read north-up, west to east: the same cells, the
 * same geotransform, windows included; a GeoTIFF written from such an input stores the raster
 * in the input's orientation again (ModelTransformation), an ASC north-up. Each stored file is
 * built here by reversing the rows or columns of the north-up field. */
TEST(orientation)
{
    enum { W = 7, H = 5 };
    static const double gt[6] = {500000.0, 30.0, 0.0, 4100000.0, 0.0, -30.0};
    float z[W * H], stored[W * H], got[W * H], win[9];
    int v, x, y, w, h, k;
    char err[256];
    ex_rio_image img;
    ex_rio_reader r;
    field(z, W, H, 1, 0, 5);
    img.width = W; img.height = H; img.bands = 1; img.band_step = W * H; img.row_step = W; img.pixel_step = 1;
    for (v = 0; v < 4; v++) { /* 0 north-up, 1 south-up, 2 mirrored (matrix), 3 both (negative scale X) */
        int fx = v >= 2, fy = v == 1 || v == 3;
        char name[32];
        ex_georef g;
        double tie[6] = {0, 0, 0, 0, 0, 0};
        memset(&g, 0, sizeof g);
        for (y = 0; y < H; y++)
            for (x = 0; x < W; x++) stored[y * W + x] = z[(fy ? H - 1 - y : y) * W + (fx ? W - 1 - x : x)];
        if (v == 2) {
            g.has_matrix = 1;
            g.matrix[0] = -30.0; g.matrix[3] = gt[0] + 30.0 * W; g.matrix[5] = -30.0; g.matrix[7] = gt[3];
            g.matrix[10] = g.matrix[15] = 1.0;
        } else {
            g.has_scale = 1;
            g.scale[0] = fx ? -30.0 : 30.0; g.scale[1] = fy ? -30.0 : 30.0;
            tie[3] = fx ? gt[0] + 30.0 * W : gt[0];
            tie[4] = fy ? gt[3] - 30.0 * H : gt[3];
            g.tiepoints = tie; g.n_tiepoints = 6;
        }
        img.data = stored;
        snprintf(name, sizeof name, "o%d.tif", v);
        CHECK(ex_rio_write(tpath(name), &img, &g, NULL, err) == 0);
        CHECK(read_all(tpath(name), 0, got, &w, &h, &r) == 0);
        CHECK(same_bits(z, got, W * H));
        for (k = 0; k < 6; k++) CHECK(r.geo.gt[k] == gt[k]);
        CHECK(r.geo.flip_x == fx && r.geo.flip_y == fy);
        /* a window inside and one past the corner (NaN outside) */
        CHECK(ex_rio_read(&r, 0, 2, 1, 3, 3, win, 3) == 0);
        for (y = 0; y < 3; y++)
            for (x = 0; x < 3; x++) CHECK(same_bits(&win[y * 3 + x], &z[(1 + y) * W + 2 + x], 1));
        CHECK(ex_rio_read(&r, 0, -1, -1, 3, 3, win, 3) == 0);
        CHECK(isnan(win[0]) && isnan(win[2]) && isnan(win[6]) && same_bits(&win[4], &z[0], 1) &&
              same_bits(&win[8], &z[W + 1], 1));
        /* written back: in the input's orientation (GeoTIFF), north-up (ASC) */
        img.data = z;
        CHECK(ex_rio_write(tpath("back.tif"), &img, &r.geo, NULL, err) == 0);
        CHECK(ex_rio_write(tpath("back.asc"), &img, &r.geo, NULL, err) == 0);
        ex_rio_close(&r);
        CHECK(read_all(tpath("back.tif"), 0, got, &w, &h, &r) == 0);
        CHECK(same_bits(z, got, W * H) && r.geo.flip_x == fx && r.geo.flip_y == fy);
        for (k = 0; k < 6; k++) CHECK(r.geo.gt[k] == gt[k]);
        ex_rio_close(&r);
        CHECK(read_all(tpath("back.asc"), 0, got, &w, &h, &r) == 0);
        CHECK(same_bits(z, got, W * H) && !r.geo.flip_x && !r.geo.flip_y && r.geo.gt[0] == gt[0] && r.geo.gt[3] == gt[3]);
        ex_rio_close(&r);
    }
    /* EHdr: a negative YDIM is a south-up file, as GDAL reads it; XDIM/YDIM 0 and cellsize 0
     * or below are refused (never cell 1) */
    {
        static const char su[] = "NROWS 2\nNCOLS 2\nNBITS 32\nPIXELTYPE FLOAT\nULXMAP 15\nULYMAP 15\nXDIM 10\nYDIM -10\n";
        static const char *const bad[] = {
            "NROWS 2\nNCOLS 2\nNBITS 32\nPIXELTYPE FLOAT\nULXMAP 15\nULYMAP 15\nXDIM 0\nYDIM 10\n",
            "NROWS 2\nNCOLS 2\nNBITS 32\nPIXELTYPE FLOAT\nULXMAP 15\nULYMAP 15\nXDIM 10\n",
            "ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 0\n",
            "ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize -5\n"};
        static const unsigned char d[16] = {0, 0, 0x80, 0x3f, 0, 0, 0, 0x40, 0, 0, 0x40, 0x40, 0, 0, 0x80, 0x40};
        float o[4]; /* 1, 2, 3, 4 as little-endian floats */
        CHECK(ex_rio_open_ehdr_mem(&r, su, strlen(su), d, 16, 0) == 0 && r.geo.flip_y && !r.geo.flip_x);
        CHECK(r.geo.gt[0] == 10.0 && r.geo.gt[3] == 30.0 && r.geo.gt[5] == -10.0);
        CHECK(ex_rio_read(&r, 0, 0, 0, 2, 2, o, 2) == 0 && o[0] == 3.0f && o[1] == 4.0f && o[2] == 1.0f && o[3] == 2.0f);
        ex_rio_close(&r);
        for (k = 0; k < 4; k++) {
            CHECK(ex_rio_open_ehdr_mem(&r, bad[k], strlen(bad[k]), d, 16, k >= 2) != 0 && r.err[0] != '\0');
            ex_rio_close(&r);
        }
    }
}

/* ModelPixelScale with two values (X, Y) is read as GDAL reads it; with one value, or a scale
 * without a tie point, or a zero scale, the file is refused: never cell 1 in silence. */
TEST(pixel_scale_counts)
{
    unsigned char buf[4096];
    /* a 2 x 2 Float32 strip image (data at 200) with ModelPixelScale at 300, ModelTiepoint at 340 */
    uint32_t e[11][4] = { { 256, 3, 1, 2 }, { 257, 3, 1, 2 }, { 258, 3, 1, 32 }, { 259, 3, 1, 1 },
                          { 273, 4, 1, 200 }, { 277, 3, 1, 1 }, { 278, 3, 1, 2 }, { 279, 4, 1, 16 },
                          { 339, 3, 1, 3 }, { 33550, 12, 2, 300 }, { 33922, 12, 6, 340 } };
    double sc[3] = {90.0, 90.0, 0.0}, tie[6] = {0, 0, 0, 1000.0, 2000.0, 0};
    ex_rio_reader r;
    int k;
    memset(buf, 0, sizeof buf);
    for (k = 0; k < 3; k++) { uint64_t u; memcpy(&u, &sc[k], 8); ex_rio_put_uint(buf + 300 + 8 * k, u, 8, 0); }
    for (k = 0; k < 6; k++) { uint64_t u; memcpy(&u, &tie[k], 8); ex_rio_put_uint(buf + 340 + 8 * k, u, 8, 0); }
    mini_tiff(buf, e, 11, 0);
    CHECK(ex_rio_open_tiff_mem(&r, buf, 400) == 0 && r.geo.has_transform && r.geo.gt[1] == 90.0 &&
          r.geo.gt[5] == -90.0 && r.geo.gt[0] == 1000.0 && r.geo.gt[3] == 2000.0);
    ex_rio_close(&r);
    e[9][2] = 1; /* one value */
    mini_tiff(buf, e, 11, 0);
    CHECK(open_err(buf, 400, "ModelPixelScale"));
    e[9][2] = 3; /* no tie point */
    mini_tiff(buf, e, 10, 0);
    CHECK(open_err(buf, 400, "no ModelTiepoint"));
    sc[0] = (double)INFINITY; /* an infinite scale: refused (info printed "origin -nan -nan") */
    { uint64_t u; memcpy(&u, &sc[0], 8); ex_rio_put_uint(buf + 300, u, 8, 0); }
    mini_tiff(buf, e, 11, 0);
    CHECK(open_err(buf, 400, "non-finite"));
    sc[0] = 0.0; /* zero scale */
    { uint64_t u; memcpy(&u, &sc[0], 8); ex_rio_put_uint(buf + 300, u, 8, 0); }
    mini_tiff(buf, e, 11, 0);
    CHECK(open_err(buf, 400, "zero pixel size"));
}

/* Heights that are not finite as floats are holes (NaN), as hfvis.h takes every non-finite
 * height: +-Inf and a Float64 1e300 in a GeoTIFF, 1e39 in an ASC. Hexadecimal is not a number
 * (NoData "0x10", an ASC value "0x10"); a TOTALROWBYTES shorter than a row is refused. */
TEST(non_finite_and_hex)
{
    unsigned char buf[4096];
    uint32_t e[9][4] = { { 256, 3, 1, 2 }, { 257, 3, 1, 2 }, { 258, 3, 1, 64 }, { 259, 3, 1, 1 },
                         { 273, 4, 1, 200 }, { 277, 3, 1, 1 }, { 278, 3, 1, 2 }, { 279, 4, 1, 32 },
                         { 339, 3, 1, 3 } };
    double d[4];
    float v[4];
    ex_rio_reader r;
    int k;
    static const char *const refused[] = {
        "ncols 2\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value 0x10\n1 2\n",
        "ncols 2\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n0x10 2\n",
        "ncols 0x2\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2\n"};
    static const unsigned char raw[16] = {0};
    d[0] = 1e300; d[1] = (double)INFINITY; d[2] = -(double)INFINITY; d[3] = 7.5;
    memset(buf, 0, sizeof buf);
    mini_tiff(buf, e, 9, 0);
    for (k = 0; k < 4; k++) { uint64_t u; memcpy(&u, &d[k], 8); ex_rio_put_uint(buf + 200 + 8 * k, u, 8, 0); }
    CHECK(ex_rio_open_tiff_mem(&r, buf, 232) == 0 && ex_rio_read(&r, 0, 0, 0, 2, 2, v, 2) == 0);
    CHECK(isnan(v[0]) && isnan(v[1]) && isnan(v[2]) && v[3] == 7.5f);
    ex_rio_close(&r);
    {
        static const char a[] = "ncols 3\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n1e39 -1e39 5\n";
        CHECK(ex_rio_open_asc_mem(&r, a, strlen(a)) == 0 && ex_rio_read(&r, 0, 0, 0, 3, 1, v, 3) == 0);
        CHECK(isnan(v[0]) && isnan(v[1]) && v[2] == 5.0f);
        ex_rio_close(&r);
    }
    for (k = 0; k < 3; k++) {
        CHECK(ex_rio_open_asc_mem(&r, refused[k], strlen(refused[k])) != 0 && r.err[0] != '\0');
        ex_rio_close(&r);
    }
    for (k = 0; k < 3; k++) {
        static const char *const h[3] = {"NROWS 2\nNCOLS 2\nNBITS 32\nPIXELTYPE FLOAT\nNODATA 0x10\n",
                                          "NROWS 2\nNCOLS 2\nNBITS 32\nPIXELTYPE FLOAT\nTOTALROWBYTES 4\n",
                                          "NROWS 2\nNCOLS 2\nNBITS 32\nPIXELTYPE FLOAT\nTOTALROWBYTES 8\n"};
        int rc = ex_rio_open_ehdr_mem(&r, h[k], strlen(h[k]), raw, 16, 0);
        CHECK(k == 2 ? rc == 0 : rc != 0 && r.err[0] != '\0');
        CHECK(k != 1 || strstr(r.err, "shorter than a row"));
        ex_rio_close(&r);
    }
}

/* An EPSG-only CRS reaches ASC/EHdr outputs as a .prj where the WKT needs no database (UTM on
 * WGS 84 north and south, ETRS89); other codes are reported lost. Band descriptions, unit and
 * metadata items go into GDAL_METADATA (escaped), and gdalinfo shows them (SKIP without it). */
TEST(epsg_prj_and_metadata)
{
    static const struct { int epsg; const char *want; } cases[] = {
        {32633, "\"WGS 84 / UTM zone 33N\""}, {32733, "PARAMETER[\"false_northing\",10000000]"},
        {25832, "\"ETRS89 / UTM zone 32N\""}, {32601, "PARAMETER[\"central_meridian\",-177]"}, {4326, "GEOGCS[\"WGS 84\""}};
    float z[2 * 3 * 4];
    ex_rio_image img;
    ex_georef g;
    ex_rio_reader r;
    ex_rio_write_options o;
    ex_rio_meta items[2];
    const char *names[2] = {"azimuth 0.00 deg", "a<b&c \"q\""};
    char err[256];
    size_t n, k;
    unsigned char *b;
    field(z, 4, 3, 2, 0, 9);
    img.data = z; img.width = 4; img.height = 3; img.bands = 1; img.band_step = 12; img.row_step = 4; img.pixel_step = 1;
    for (k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        memset(&g, 0, sizeof g);
        g.has_transform = 1; g.gt[0] = 500000; g.gt[1] = 30; g.gt[3] = 4100000; g.gt[5] = -30;
        g.epsg = cases[k].epsg; g.crs = EX_RIO_CRS_PROJECTED;
        CHECK(!ex_rio_crs_lost(&g));
        CHECK(ex_rio_write(tpath("e.asc"), &img, &g, NULL, err) == 0);
        b = slurp(tpath("e.prj"), &n);
        CHECK(b && strstr((char *)b, cases[k].want) && ex_rio_wkt_epsg((char *)b) == cases[k].epsg);
        free(b);
        CHECK(ex_rio_open(&r, tpath("e.asc")) == 0 && r.geo.prj && ex_rio_wkt_epsg(r.geo.prj) == cases[k].epsg);
        ex_rio_close(&r);
    }
    g.epsg = 2056; /* CH1903+ / LV95: no WKT without a database, no .prj (the old one removed) */
    CHECK(ex_rio_crs_lost(&g));
    CHECK(ex_rio_write(tpath("e.asc"), &img, &g, NULL, err) == 0);
    CHECK(access(tpath("e.prj"), F_OK) != 0);
    remove(tpath("e.asc"));
    /* GDAL_METADATA */
    memset(&o, 0, sizeof o);
    o.band_names = names;
    o.unit = "degree";
    items[0].name = "convention"; items[0].value = "elevation angle"; items[0].band = 0;
    items[1].name = "azimuth"; items[1].value = "90"; items[1].band = 2;
    o.meta = items;
    o.n_meta = 2;
    img.bands = 2;
    CHECK(ex_rio_write(tpath("md.tif"), &img, NULL, &o, err) == 0);
    b = slurp(tpath("md.tif"), &n);
    CHECK(b != NULL);
    if (b) {
        static const char *const want[] = {
            "<Item name=\"convention\">elevation angle</Item>",
            "<Item name=\"DESCRIPTION\" sample=\"0\" role=\"description\">azimuth 0.00 deg</Item>",
            "<Item name=\"DESCRIPTION\" sample=\"1\" role=\"description\">a&lt;b&amp;c &quot;q&quot;</Item>",
            "<Item name=\"UNITTYPE\" sample=\"1\" role=\"unittype\">degree</Item>",
            "<Item name=\"azimuth\" sample=\"1\">90</Item>"};
        size_t i, j;
        for (i = 0; i < sizeof want / sizeof want[0]; i++) {
            size_t L = strlen(want[i]);
            int found = 0;
            for (j = 0; j + L <= n && !found; j++) found = memcmp(b + j, want[i], L) == 0;
            CHECK(found);
        }
        free(b);
    }
    CHECK(read_all(tpath("md.tif"), 1, z, &img.width, &img.height, NULL) == 0); /* still a TIFF we read */
    if (system("gdalinfo --version > /dev/null 2>&1") == 0) {
        char cmd[600], line[512];
        int desc = 0, unit = 0, conv = 0, az = 0;
        FILE *p;
        snprintf(cmd, sizeof cmd, "gdalinfo '%s' 2>&1", tpath("md.tif"));
        p = popen(cmd, "r");
        while (p && fgets(line, sizeof line, p)) {
            /* (GDAL 3.6 shows the second name cut at its '&', "a<b": its reader's, the XML is escaped) */
            desc += strstr(line, "Description = azimuth 0.00 deg") != NULL || strstr(line, "Description = a<b") != NULL;
            unit += strstr(line, "Unit Type: degree") != NULL;
            conv += strstr(line, "convention=elevation angle") != NULL;
            az += strstr(line, "azimuth=90") != NULL;
        }
        if (p) pclose(p);
        CHECK(desc == 2 && unit == 2 && conv == 1 && az == 1);
    } else {
        printf("     SKIP gdalinfo not found (GDAL_METADATA as GDAL reads it)\n");
    }
    remove(tpath("md.tif"));
}

TEST(georef_cells)
{
    ex_georef g;
    double cell = 0.0;
    char err[256];
    memset(&g, 0, sizeof g);
    CHECK(ex_georef_cell(&g, &cell, err) != 0);
    g.has_transform = 1;
    g.gt[1] = 10.0; g.gt[5] = -10.0;
    CHECK(ex_georef_cell(&g, &cell, err) == 0 && cell == 10.0);
    g.gt[5] = -12.0;
    CHECK(ex_georef_cell(&g, &cell, err) != 0 && strstr(err, "not square"));
    g.gt[5] = -10.0; g.gt[2] = 0.5;
    CHECK(ex_georef_cell(&g, &cell, err) != 0 && strstr(err, "rotated"));
    /* GeoKeys: geographic model type and EPSG 4326; PixelIsPoint moves the transform half a cell */
    {
        uint16_t keys[] = { 1, 1, 0, 3, 1024, 0, 1, 2, 1025, 0, 1, 2, 2048, 0, 1, 4326 };
        double tie[6] = { 0, 0, 0, 100.0, 50.0, 0 };
        memset(&g, 0, sizeof g);
        g.geokeys = keys; g.n_geokeys = 16; g.tiepoints = tie; g.n_tiepoints = 6;
        g.has_scale = 1; g.scale[0] = 0.5; g.scale[1] = 0.5;
        CHECK(ex_georef_keys(&g, err) == 0 && g.crs == EX_RIO_CRS_GEOGRAPHIC && g.epsg == 4326 && g.pixel_is_point);
        ex_georef_transform(&g);
        CHECK(g.has_transform && g.gt[0] == 99.75 && g.gt[3] == 50.25 && g.gt[1] == 0.5 && g.gt[5] == -0.5);
        keys[3] = 9; /* more keys than the directory holds */
        CHECK(ex_georef_keys(&g, err) != 0);
    }
}

/* A .prj's CRS as GeoKeys and back: the EPSG code is the one the WKT names at its top level
 * (never a nested datum's or base CRS's), a WKT without one becomes an ESRI PE string that the
 * reader classifies and ex_rio_pe_string returns whole; too long or neither kind: no keys. */
TEST(prj_geokeys)
{
    static const char esri[] = "PROJCS[\"UTM_33N\",GEOGCS[\"GCS_WGS_1984\",DATUM[\"D_WGS_1984\","
                               "SPHEROID[\"WGS_1984\",6378137.0,298.257223563]],PRIMEM[\"Greenwich\",0.0],"
                               "UNIT[\"Degree\",0.0174532925199433]],PROJECTION[\"Transverse_Mercator\"],"
                               "UNIT[\"Meter\",1.0]]";
    uint64_t k[16];
    char *ascii = NULL, err[256];
    size_t n_ascii = 0, len = 0, i;
    uint16_t k16[16];
    ex_georef g;
    const char *pe;
    /* the top-level code, not the nested GEOGCS's 4326 or the unit's 9001 */
    CHECK(ex_rio_wkt_epsg("PROJCS[\"x\",GEOGCS[\"y\",AUTHORITY[\"EPSG\",\"4326\"]],UNIT[\"m\",1,"
                          "AUTHORITY[\"EPSG\",\"9001\"]],AUTHORITY[\"EPSG\",\"32633\"]]") == 32633);
    CHECK(ex_rio_wkt_epsg("PROJCS[\"x\",GEOGCS[\"y\",AUTHORITY[\"EPSG\",\"4326\"]]]") == 0);
    CHECK(ex_rio_wkt_epsg("PROJCRS[\"x\",BASEGEOGCRS[\"y\",ID[\"EPSG\",4326]],ID[\"EPSG\",32633]]") == 32633);
    CHECK(ex_rio_wkt_epsg("PROJCS[\"a \"\"quoted\"\" [name\",AUTHORITY[\"EPSG\",\"3035\"]]") == 3035);
    CHECK(ex_rio_wkt_epsg("PROJCS[\"x\",AUTHORITY[\"ESRI\",\"102003\"]]") == 0);
    CHECK(ex_rio_prj_geokeys("GEOGCS[\"y\",AUTHORITY[\"EPSG\",\"4326\"]]\n", k, &ascii, &n_ascii) == 16 &&
          k[7] == EX_RIO_CRS_GEOGRAPHIC && k[12] == 2048 && k[15] == 4326 && !ascii);
    CHECK(ex_rio_prj_geokeys("LOCAL_CS[\"z\"]", k, &ascii, &n_ascii) == 0 && !ascii);
    /* no code: a PE string under a user-defined model, read back */
    CHECK(ex_rio_prj_geokeys(esri, k, &ascii, &n_ascii) == 16 && ascii && k[7] == 32767 && k[12] == 3073 &&
          k[13] == 34737 && k[14] == n_ascii - 1 && ascii[n_ascii - 2] == '|' && ascii[n_ascii - 1] == '\0');
    for (i = 0; i < 16; i++) k16[i] = (uint16_t)k[i];
    memset(&g, 0, sizeof g);
    g.geokeys = k16; g.n_geokeys = 16; g.geoascii = ascii; g.n_geoascii = n_ascii;
    CHECK(ex_georef_keys(&g, err) == 0 && g.crs == EX_RIO_CRS_UNKNOWN && g.epsg == 0);
    ex_georef_pe_crs(&g);
    CHECK(g.crs == EX_RIO_CRS_PROJECTED);
    pe = ex_rio_pe_string(&g, &len);
    CHECK(pe && len == strlen(esri) && memcmp(pe, esri, len) == 0);
    g.n_geoascii = 20; /* cut after three characters of the WKT, then inside the tag */
    CHECK(ex_rio_pe_string(&g, &len) == pe && len == 3);
    g.n_geoascii = 10;
    CHECK(ex_rio_pe_string(&g, &len) == NULL);
    free(ascii);
    {
        char *big = (char *)malloc(EX_RIO_MAX_PE_STRING + 64);
        if (big) {
            memset(big, ' ', EX_RIO_MAX_PE_STRING + 63);
            memcpy(big, "PROJCS[\"long\"", 13);
            big[EX_RIO_MAX_PE_STRING + 62] = ']';
            big[EX_RIO_MAX_PE_STRING + 63] = '\0';
            CHECK(ex_rio_prj_geokeys(big, k, &ascii, &n_ascii) == 0 && !ascii);
            free(big);
        }
    }
}

/* PFM (grey and colour, both byte orders) and binary PGM (8 and 16 bit) windows read by seeking
 * rows (ex_rio_open_netpbm) against the crop of the library's whole decode (hfvis_image_load),
 * headers with comments, a truncated file refused; ex_georef_shift moves the geotransform and the
 * verbatim tie point by whole cells. */
TEST(netpbm_windows)
{
    enum { W = 37, H = 29 };
    float *src = (float *)malloc(sizeof(float) * W * H * 3), win[20 * 20 * 3];
    int kind;
    field(src, W, H, 3, 0, 91);
    for (kind = 0; kind < 5; kind++) {
        /* 0: Pf LE (library writer), 1: PF LE, 2: Pf BE with a comment, 3: P5 8-bit, 4: P5 16-bit */
        const char *name = tpath("n.img");
        ex_rio_reader r;
        hfvis_image_info info;
        float *all = NULL;
        uint32_t s = 9;
        int t, ch = kind == 1 ? 3 : 1;
        if (kind <= 1) {
            CHECK(hfvis_pfm_save(name, src, W, H, ch, W) == HFVIS_OK);
        } else if (kind == 2) {
            size_t n = (size_t)W * H, i;
            unsigned char *buf = (unsigned char *)malloc(64 + n * 4);
            int len = sprintf((char *)buf, "Pf\n# a comment\n%d %d\n1.0\n", W, H), y, x;
            for (y = 0; y < H; y++)
                for (x = 0; x < W; x++) { /* bottom row first, big endian */
                    uint32_t u;
                    unsigned char *p = buf + len + ((size_t)(H - 1 - y) * W + (size_t)x) * 4;
                    memcpy(&u, &src[y * W + x], 4);
                    p[0] = (unsigned char)(u >> 24); p[1] = (unsigned char)(u >> 16);
                    p[2] = (unsigned char)(u >> 8); p[3] = (unsigned char)u;
                }
            spit(name, buf, (size_t)len + n * 4);
            (void)i;
            free(buf);
        } else {
            CHECK(hfvis_pgm_save(name, src, W, H, W, -200.0f, 800.0f, kind == 3 ? 255 : 65535) == HFVIS_OK);
        }
        CHECK(hfvis_image_load(name, NULL, &all, &info) == HFVIS_OK);
        CHECK(ex_rio_open_netpbm(&r, name) == 0);
        CHECK(r.width == W && r.height == H && r.bands == ch);
        for (t = 0; all && r.width == W && t < 100; t++) {
            int x0 = (int)(lcg(&s) % (W + 10)) - 5, y0 = (int)(lcg(&s) % (H + 10)) - 5;
            int ww = 1 + (int)(lcg(&s) % 20), wh = 1 + (int)(lcg(&s) % 20), x, y, b, bad = 0;
            for (b = 0; b < ch; b++) {
                CHECK(ex_rio_read(&r, b, x0, y0, ww, wh, win, 20) == 0);
                for (y = 0; y < wh; y++)
                    for (x = 0; x < ww; x++) {
                        int gx = x0 + x, gy = y0 + y;
                        float v = win[y * 20 + x];
                        if (gx < 0 || gy < 0 || gx >= W || gy >= H) bad += !isnan(v);
                        else bad += memcmp(&v, all + ((size_t)gy * W + (size_t)gx) * (size_t)ch + (size_t)b, 4) != 0;
                    }
            }
            CHECK(bad == 0);
        }
        ex_rio_close(&r);
        hfvis_free(NULL, all);
    }
    { /* truncated: one row short */
        size_t n;
        unsigned char *file;
        ex_rio_reader r;
        CHECK(hfvis_pfm_save(tpath("n.img"), src, W, H, 1, W) == HFVIS_OK);
        file = slurp(tpath("n.img"), &n);
        if (file) spit(tpath("n.img"), file, n - (size_t)W * 4);
        CHECK(ex_rio_open_netpbm(&r, tpath("n.img")) != 0 && strstr(r.err, "truncated") != NULL);
        spit(tpath("n.img"), "P2\n2 2\n9\n1 2 3 4\n", 17);
        CHECK(ex_rio_open_netpbm(&r, tpath("n.img")) != 0);
        free(file);
    }
    { /* a window's georeference: 3 columns east, 2 rows south */
        ex_georef g;
        double tie[6] = { 0, 0, 0, 500000, 4100000, 0 };
        memset(&g, 0, sizeof g);
        g.has_scale = 1; g.scale[0] = 30; g.scale[1] = 30;
        g.tiepoints = (double *)malloc(sizeof tie);
        if (g.tiepoints) memcpy(g.tiepoints, tie, sizeof tie);
        g.n_tiepoints = g.tiepoints ? 6 : 0;
        ex_georef_transform(&g);
        ex_georef_shift(&g, 3, 2);
        CHECK(g.gt[0] == 500090.0 && g.gt[3] == 4099940.0);
        CHECK(g.n_tiepoints == 6 && g.tiepoints[0] == -3.0 && g.tiepoints[1] == -2.0 && g.tiepoints[3] == 500000.0);
        ex_georef_free(&g);
    }
    unlink(tpath("n.img"));
    free(src);
}

int main(int argc, char **argv)
{
    const char *base = getenv("TMPDIR");
    TEST_INIT(argc, argv);
    snprintf(tdir, sizeof tdir, "%s/hfvis_test_raster_io_XXXXXX", base ? base : "/tmp");
    if (!mkdtemp(tdir)) {
        perror("mkdtemp");
        return 1;
    }
    RUN(inflate_dynamic_and_errors);
    RUN(inflate_stored_after_lookahead);
    RUN(deflate_round_trip);
    RUN(tiff_round_trips);
    RUN(tiff_parallel_chunks);
    RUN(read_parallel);
    RUN(asc_decimals);
    RUN(asc_parallel_rows);
    RUN(tiff_lzw_packbits);
    RUN(window_reads);
    RUN(netpbm_windows);
    RUN(long_tokens_and_sizes);
    RUN(tiff_malformed);
    RUN(asc_ehdr);
    RUN(orientation);
    RUN(pixel_scale_counts);
    RUN(non_finite_and_hex);
    RUN(epsg_prj_and_metadata);
    RUN(georef_cells);
    RUN(prj_geokeys);
    {
        const char *names[] = { "rt.tif", "u.tif", "c.tif", "w.tif", "w.flt", "w.hdr", "t.tif", "m.tif", "a.asc",
                                "a.prj", "e.flt", "e.bil", "e.hdr", "e.prj", "o0.tif", "o1.tif", "o2.tif", "o3.tif",
                                "back.tif", "back.asc" };
        size_t i;
        for (i = 0; i < sizeof names / sizeof names[0]; i++) remove(tpath(names[i]));
        CHECK(test_dir_entries(tdir) == 0); /* no temporary file left by a writer */
        rmdir(tdir);
    }
    return TEST_DONE();
}
