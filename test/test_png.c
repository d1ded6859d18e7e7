/* test_png.c - the examples' PNG writer (examples/png_write.h and its common.h wrappers): the
 * CRC-32 and Adler-32 check values, the chunk and zlib layout byte by byte, stored-block
 * splitting at 65535, a bit-exact round trip through a stored-block decoder written here, the
 * float mapping, and the failure paths (bad sizes, overflow, short buffers, unwritable paths
 * leave nothing behind). */
#define _POSIX_C_SOURCE 200809L /* mkdtemp, opendir, mkdir, rmdir */
#include "examples/common.h"
#include "test.h"

#include "test_dir.h"
#include <limits.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* ---- references written from the specifications, independent of png_write.h ---- */

/* CRC-32, one bit at a time (PNG Annex D). */
static uint32_t crc_bitwise(const unsigned char *p, size_t n)
{
    uint32_t c = 0xffffffffu;
    size_t i;
    int k;
    for (i = 0; i < n; i++) {
        c ^= p[i];
        for (k = 0; k < 8; k++) c = (c & 1u) ? (c >> 1) ^ 0xedb88320u : c >> 1;
    }
    return c ^ 0xffffffffu;
}

/* Adler-32 with the modulo after every byte (RFC 1950 §8.2). */
static uint32_t adler_slow(const unsigned char *p, size_t n)
{
    uint32_t a = 1, b = 0;
    size_t i;
    for (i = 0; i < n; i++) {
        a = (a + p[i]) % 65521u;
        b = (b + a) % 65521u;
    }
    return (b << 16) | a;
}

static uint32_t rd32(const unsigned char *p)
{
    return ((uint32_t)p[0] << 24) | ((uint32_t)p[1] << 16) | ((uint32_t)p[2] << 8) | p[3];
}

#define MAX_BLOCKS 16

/* What decode() found. */
typedef struct {
    int width, height, channels, depth;
    unsigned char *samples; /* height rows of width*channels*depth/8 bytes, filter bytes removed */
    int blocks, block_len[MAX_BLOCKS], idat_chunks;
} decoded;

/* Decode a PNG whose IDAT holds only stored deflate blocks: the signature, IHDR first and IEND
 * last, every chunk CRC, the zlib header, each block's LEN/NLEN and BFINAL, the Adler-32, the
 * stream length H*(1 + row bytes) and filter type 0 on every row. Returns 0 on any violation. */
static int decode(const unsigned char *png, size_t n, decoded *d)
{
    static const unsigned char sig[8] = { 137, 80, 78, 71, 13, 10, 26, 10 };
    unsigned char *z = NULL, *raw = NULL;
    size_t zn = 0, pos = 8, rawn, row, r, zp, got = 0;
    int seen_iend = 0, ok = 0, final = 0, y;
    memset(d, 0, sizeof *d);
    if (n < 8 + 25 + 12 || memcmp(png, sig, 8) != 0) return 0;
    while (pos + 12 <= n && !seen_iend) {
        uint32_t len = rd32(png + pos);
        const unsigned char *type = png + pos + 4, *data = png + pos + 8;
        if (len > n - pos - 12) goto done;
        if (crc_bitwise(type, 4 + (size_t)len) != rd32(data + len)) goto done;
        if (pos == 8) {
            if (memcmp(type, "IHDR", 4) != 0 || len != 13) goto done;
            d->width = (int)rd32(data);
            d->height = (int)rd32(data + 4);
            d->depth = data[8];
            d->channels = data[9] == 2 ? 3 : data[9] == 0 ? 1 : 0;
            if (d->width <= 0 || d->height <= 0 || d->channels == 0 || data[10] || data[11] || data[12])
                goto done;
        } else if (memcmp(type, "IDAT", 4) == 0) {
            unsigned char *t = (unsigned char *)realloc(z, zn + len + 1);
            if (!t) goto done;
            z = t;
            memcpy(z + zn, data, len);
            zn += len;
            d->idat_chunks++;
        } else if (memcmp(type, "IEND", 4) == 0) {
            seen_iend = len == 0;
        }
        pos += 12 + (size_t)len;
    }
    if (!seen_iend || pos != n || zn < 2 + 4) goto done;
    row = (size_t)d->width * (size_t)d->channels * (size_t)d->depth / 8;
    rawn = (row + 1) * (size_t)d->height;
    raw = (unsigned char *)malloc(rawn);
    if (!raw) goto done;
    /* zlib header: deflate with a 32 KiB window, no dictionary, FCHECK */
    if (z[0] != 0x78 || (z[0] * 256u + z[1]) % 31u != 0 || (z[1] & 0x20u)) goto done;
    zp = 2;
    while (!final) {
        unsigned len, nlen;
        if (zp + 5 > zn || (z[zp] & 0xfeu) != 0) goto done; /* BTYPE 00, padding 0 */
        final = z[zp] & 1u;
        len = z[zp + 1] | (unsigned)z[zp + 2] << 8;
        nlen = z[zp + 3] | (unsigned)z[zp + 4] << 8;
        if ((len ^ 0xffffu) != nlen || zp + 5 + len > zn || got + len > rawn) goto done;
        if (d->blocks < MAX_BLOCKS) d->block_len[d->blocks] = (int)len;
        d->blocks++;
        memcpy(raw + got, z + zp + 5, len);
        got += len;
        zp += 5 + len;
    }
    if (got != rawn || zp + 4 != zn || rd32(z + zp) != adler_slow(raw, rawn)) goto done;
    d->samples = (unsigned char *)malloc(row * (size_t)d->height);
    if (!d->samples) goto done;
    for (y = 0, r = 0; y < d->height; y++, r += row + 1) {
        if (raw[r] != 0) goto done;
        memcpy(d->samples + (size_t)y * row, raw + r + 1, row);
    }
    ok = 1;
done:
    free(z);
    free(raw);
    if (!ok) {
        free(d->samples);
        d->samples = NULL;
    }
    return ok;
}

/* Encode samples and decode them again; 1 when the round trip is bit-exact. */
static int round_trip(const unsigned char *samples, int w, int h, int c, int depth, decoded *d)
{
    size_t size = 0, written = 0, row = 0;
    unsigned char *png;
    int ok;
    d->samples = NULL;
    if (ex_png_layout(w, h, c, depth, &row, NULL, &size) != HFVIS_OK) return 0;
    png = (unsigned char *)malloc(size);
    if (!png) return 0;
    ok = ex_png_encode(samples, w, h, c, depth, png, size, &written) == HFVIS_OK && written == size &&
         decode(png, size, d) && d->width == w && d->height == h && d->channels == c && d->depth == depth &&
         memcmp(d->samples, samples, row * (size_t)h) == 0;
    free(png);
    return ok;
}

/* xorshift32 bytes: deterministic test data */
static void fill(unsigned char *p, size_t n, uint32_t seed)
{
    size_t i;
    for (i = 0; i < n; i++) {
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        p[i] = (unsigned char)(seed >> 24);
    }
}

static char test_dir[64];

static const char *in_dir(char *buf, size_t cap, const char *name)
{
    int n = snprintf(buf, cap, "%s/%s", test_dir, name);
    return (n > 0 && (size_t)n < cap) ? buf : "";
}

/* Read a whole file (at most cap bytes); returns its size, 0 if it cannot be read. */
static size_t read_all(const char *path, unsigned char *buf, size_t cap)
{
    FILE *f = fopen(path, "rb");
    size_t n;
    if (!f) return 0;
    n = fread(buf, 1, cap, f);
    fclose(f);
    return n;
}

/* Decode the file at path into d. */
static int decode_file(const char *path, decoded *d)
{
    size_t cap = 1u << 20, n;
    unsigned char *buf = (unsigned char *)malloc(cap);
    int ok;
    if (!buf) return 0;
    n = read_all(path, buf, cap);
    ok = n > 0 && n < cap && decode(buf, n, d);
    free(buf);
    return ok;
}

/* ---- tests ---- */

TEST(crc32_check_values)
{
    static const unsigned char digits[] = "123456789", iend[] = "IEND";
    unsigned char data[1000];
    fill(data, sizeof data, 7);
    /* the CRC-32 check value of the catalogue of parametrised CRCs (CRC-32/ISO-HDLC) */
    CHECK(hfvis_crc32(0, digits, 9) == 0xcbf43926u);
    CHECK(hfvis_crc32(0, digits, 0) == 0u);
    /* every PNG ends with IEND's CRC AE 42 60 82 */
    CHECK(hfvis_crc32(0, iend, 4) == 0xae426082u);
    CHECK(hfvis_crc32(0, data, sizeof data) == crc_bitwise(data, sizeof data));
    /* continuing a CRC over a split equals one pass */
    CHECK(hfvis_crc32(hfvis_crc32(0, data, 333), data + 333, sizeof data - 333) == crc_bitwise(data, sizeof data));
}

TEST(adler32_check_values)
{
    static const unsigned char wiki[] = "Wikipedia";
    unsigned char *big = (unsigned char *)malloc(100000);
    CHECK(ex_adler32(1, wiki, 9) == 0x11e60398u);
    CHECK(ex_adler32(1, wiki, 0) == 1u);
    CHECK(big != NULL);
    if (!big) return;
    /* all 0xff: the sums grow fastest, so the reduction every 5552 bytes is tested hardest */
    memset(big, 0xff, 100000);
    CHECK(ex_adler32(1, big, 100000) == adler_slow(big, 100000));
    fill(big, 100000, 99);
    CHECK(ex_adler32(ex_adler32(1, big, 7000), big + 7000, 93000) == adler_slow(big, 100000));
    free(big);
}

TEST(layout_sizes)
{
    size_t row = 0, z = 0, file = 0;
    /* 3 x 2 grey 8: rows of 3, raw 2 * 4 = 8, zlib 2 + 5 + 8 + 4 = 19, file 8 + 25 + 12 + 19 + 12 */
    CHECK_EQ_STATUS(ex_png_layout(3, 2, 1, 8, &row, &z, &file), HFVIS_OK);
    CHECK(row == 3 && z == 19 && file == 76);
    CHECK_EQ_STATUS(ex_png_layout(3, 2, 1, 16, &row, NULL, NULL), HFVIS_OK);
    CHECK(row == 6);
    CHECK_EQ_STATUS(ex_png_layout(3, 2, 3, 8, &row, NULL, NULL), HFVIS_OK);
    CHECK(row == 9);
    /* bad sizes and formats; the out-pointers stay untouched */
    row = 77;
    CHECK_EQ_STATUS(ex_png_layout(0, 2, 1, 8, &row, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(ex_png_layout(3, 0, 1, 8, &row, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(ex_png_layout(-3, 2, 1, 8, &row, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(ex_png_layout(3, -2, 1, 8, &row, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(ex_png_layout(3, 2, 2, 8, &row, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(ex_png_layout(3, 2, 4, 8, &row, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(ex_png_layout(3, 2, 1, 4, &row, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(ex_png_layout(3, 2, 3, 16, &row, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(row == 77);
    /* one IDAT chunk holds at most 2^31 - 1 bytes: 46341^2 bytes of grey are just over */
    CHECK_EQ_STATUS(ex_png_layout(46341, 46341, 1, 8, &row, NULL, NULL), HFVIS_ERR_LIMIT);
    CHECK_EQ_STATUS(ex_png_layout(INT_MAX, 1, 3, 8, &row, NULL, NULL), HFVIS_ERR_LIMIT);
    CHECK(row == 77);
    /* the largest requests: (1 + 3 (2^31 - 1)) (2^31 - 1) bytes fit a 64-bit size_t and exceed the
     * chunk limit; with a 32-bit size_t the product overflows and is refused as a bad size. Either
     * way no wrapped-around small size comes back. */
    CHECK_EQ_STATUS(ex_png_layout(INT_MAX, INT_MAX, 3, 8, &row, NULL, NULL),
                    sizeof(size_t) > 4 ? HFVIS_ERR_LIMIT : HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(ex_png_layout(65536, 65536, 3, 8, &row, NULL, NULL),
                    sizeof(size_t) > 4 ? HFVIS_ERR_LIMIT : HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(row == 77);
}

TEST(encode_byte_layout)
{
    /* 3 x 2 grey: the whole file, byte by byte */
    static const unsigned char px[6] = { 0, 1, 2, 253, 254, 255 };
    unsigned char png[76];
    size_t written = 0;
    CHECK_EQ_STATUS(ex_png_encode(px, 3, 2, 1, 8, png, sizeof png, &written), HFVIS_OK);
    CHECK(written == 76);
    {
        static const unsigned char head[33] = {
            137, 80, 78, 71, 13, 10, 26, 10,                  /* signature */
            0, 0, 0, 13, 'I', 'H', 'D', 'R', 0, 0, 0, 3, 0, 0, 0, 2, 8, 0, 0, 0, 0 };
        static const unsigned char idat[8 + 15] = {
            0, 0, 0, 19, 'I', 'D', 'A', 'T', 0x78, 0x01,      /* zlib header */
            0x01, 8, 0, 0xf7, 0xff,                           /* final stored block, LEN 8, NLEN */
            0, 0, 1, 2, 0, 253, 254, 255 };                   /* filter 0 + row, twice */
        static const unsigned char iend[12] = { 0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xae, 0x42, 0x60, 0x82 };
        static const unsigned char rows[8] = { 0, 0, 1, 2, 0, 253, 254, 255 };
        CHECK(memcmp(png, head, 29) == 0);
        CHECK(rd32(png + 29) == crc_bitwise(png + 12, 17));
        CHECK(memcmp(png + 33, idat, sizeof idat) == 0);
        CHECK(rd32(png + 33 + 23) == adler_slow(rows, 8));           /* then Adler-32 */
        CHECK(rd32(png + 33 + 27) == crc_bitwise(png + 37, 4 + 19)); /* and the chunk CRC */
        CHECK(memcmp(png + 64, iend, 12) == 0);
    }
    {
        decoded d;
        CHECK(decode(png, written, &d) && d.blocks == 1 && d.idat_chunks == 1);
        free(d.samples);
    }
}

TEST(round_trip_formats)
{
    /* odd sizes, all three formats, bit-exact through the decoder above */
    static const int sizes[][2] = { { 1, 1 }, { 1, 7 }, { 7, 1 }, { 13, 11 }, { 300, 257 } };
    static const int formats[][2] = { { 1, 8 }, { 1, 16 }, { 3, 8 } };
    unsigned char *px = (unsigned char *)malloc(300 * 257 * 3);
    size_t s, f;
    CHECK(px != NULL);
    if (!px) return;
    for (s = 0; s < sizeof sizes / sizeof sizes[0]; s++)
        for (f = 0; f < sizeof formats / sizeof formats[0]; f++) {
            decoded d;
            fill(px, 300 * 257 * 3, (uint32_t)(11 + 3 * s + f));
            CHECK(round_trip(px, sizes[s][0], sizes[s][1], formats[f][0], formats[f][1], &d));
            free(d.samples);
        }
    free(px);
}

TEST(stored_blocks_split_at_65535)
{
    /* grey 8, one row of W samples: raw = W + 1 bytes; two rows: 2 (W + 1) */
    static const struct { int w, h, blocks, first, last; } cases[] = {
        { 65533, 1, 1, 65534, 65534 },   /* one byte short of a full block */
        { 65534, 1, 1, 65535, 65535 },   /* exactly one full block, no empty block after it */
        { 65535, 1, 2, 65535, 1 },       /* one byte over */
        { 65534, 2, 2, 65535, 65535 },   /* exactly two full blocks */
        { 65535, 2, 3, 65535, 2 },       /* two full blocks and 2 bytes */
        { 100, 1310, 3, 65535, 1310 * 101 - 2 * 65535 } /* a block boundary inside a row */
    };
    unsigned char *px = (unsigned char *)malloc(2 * 65535);
    size_t c;
    CHECK(px != NULL);
    if (!px) return;
    fill(px, 2 * 65535, 5);
    for (c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        decoded d;
        size_t z = 0;
        int k, ok = round_trip(px, cases[c].w, cases[c].h, 1, 8, &d);
        CHECK(ok);
        if (ok) {
            CHECK(d.blocks == cases[c].blocks);
            CHECK(d.block_len[0] == cases[c].first && d.block_len[d.blocks - 1] == cases[c].last);
            for (k = 1; k + 1 < d.blocks; k++) CHECK(d.block_len[k] == 65535);
        }
        CHECK_EQ_STATUS(ex_png_layout(cases[c].w, cases[c].h, 1, 8, NULL, &z, NULL), HFVIS_OK);
        CHECK(z == 2 + 5 * (size_t)cases[c].blocks + (size_t)cases[c].h * (size_t)(cases[c].w + 1) + 4);
        free(d.samples);
    }
    free(px);
}

TEST(encode_failures_write_nothing)
{
    unsigned char px[6] = { 1, 2, 3, 4, 5, 6 }, png[76];
    size_t written = 12345, k;
    memset(png, 0xa5, sizeof png);
    CHECK_EQ_STATUS(ex_png_encode(px, 3, 2, 1, 8, png, 75, &written), HFVIS_ERR_BUFFER_TOO_SMALL);
    CHECK_EQ_STATUS(ex_png_encode(NULL, 3, 2, 1, 8, png, 76, &written), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(ex_png_encode(px, 3, 2, 1, 8, NULL, 76, &written), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(ex_png_encode(px, 3, 2, 1, 8, png, 76, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(ex_png_encode(px, 0, 2, 1, 8, png, 76, &written), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(ex_png_encode(px, 3, 2, 3, 16, png, 76, &written), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(ex_png_encode(px, 46341, 46341, 1, 8, png, 76, &written), HFVIS_ERR_LIMIT);
    CHECK(written == 12345);
    for (k = 0; k < sizeof png; k++) CHECK(png[k] == 0xa5);
}

TEST(save_maps_floats)
{
    /* [lo, hi] = [-1, 3]: -1 -> 0, 3 -> top, outside clamps, NaN and inf -> 0, 1 -> top / 2
     * rounded; the second row follows a stride of 5 pixels. */
    const float nan = (float)NAN, inf = (float)INFINITY;
    const float px[2 * 5] = { -1.0f, 3.0f, -7.0f, 9.0f, 0.0f, nan, inf, 1.0f, 0.0f, 0.0f };
    const float rgb[2 * 3] = { -1.0f, 1.0f, 3.0f, 0.0f, 2.0f, nan };
    char path[256];
    decoded d;
    int got;
    CHECK_EQ_STATUS(ex_png_save(in_dir(path, sizeof path, "g8.png"), px, 4, 2, 5, 1, 8, -1.0f, 3.0f), HFVIS_OK);
    got = decode_file(path, &d);
    CHECK(got);
    if (got) {
        static const unsigned char want[8] = { 0, 255, 0, 255, 0, 0, 128, 64 };
        CHECK(d.width == 4 && d.height == 2 && d.channels == 1 && d.depth == 8);
        /* row 1: px[5..8] = NaN, inf, 1, 0 -> 0, 0, 128 (127.5 rounds up), 64 (63.75) */
        CHECK(memcmp(d.samples, want, 8) == 0);
        free(d.samples);
    }
    CHECK_EQ_STATUS(ex_png_save(in_dir(path, sizeof path, "g16.png"), px, 4, 2, 5, 1, 16, -1.0f, 3.0f), HFVIS_OK);
    got = decode_file(path, &d);
    CHECK(got);
    if (got) {
        /* 16-bit big-endian: 3 -> FF FF, 1 -> 32767.5 -> 32768 = 80 00, 0 -> 16383.75 -> 16384 */
        static const unsigned char want[16] = { 0, 0, 255, 255, 0, 0, 255, 255, 0, 0, 0, 0, 0x80, 0, 0x40, 0 };
        CHECK(d.depth == 16 && memcmp(d.samples, want, 16) == 0);
        free(d.samples);
    }
    CHECK_EQ_STATUS(ex_png_save(in_dir(path, sizeof path, "rgb.png"), rgb, 2, 1, 2, 3, 8, -1.0f, 3.0f), HFVIS_OK);
    got = decode_file(path, &d);
    CHECK(got);
    if (got) {
        static const unsigned char want[6] = { 0, 128, 255, 64, 191, 0 };
        CHECK(d.channels == 3 && memcmp(d.samples, want, 6) == 0);
        free(d.samples);
    }
    CHECK(remove(in_dir(path, sizeof path, "g8.png")) == 0);
    CHECK(remove(in_dir(path, sizeof path, "g16.png")) == 0);
    CHECK(remove(in_dir(path, sizeof path, "rgb.png")) == 0);
    CHECK(test_dir_entries(test_dir) == 0);
}

TEST(save_failures_leave_nothing)
{
    const float px[4] = { 0.0f, 1.0f, 2.0f, 3.0f };
    char path[256], dir[256];
    /* bad arguments create nothing */
    in_dir(path, sizeof path, "x.png");
    CHECK_EQ_STATUS(ex_png_save(NULL, px, 2, 2, 2, 1, 8, 0.0f, 1.0f), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(ex_png_save(path, NULL, 2, 2, 2, 1, 8, 0.0f, 1.0f), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(ex_png_save(path, px, 2, 2, 1, 1, 8, 0.0f, 1.0f), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(ex_png_save(path, px, 2, 2, 2, 1, 8, 1.0f, 1.0f), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(ex_png_save(path, px, 2, 2, 2, 1, 8, (float)NAN, 1.0f), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(ex_png_save(path, px, 2, 2, 2, 3, 16, 0.0f, 1.0f), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(ex_png_save(path, px, 0, 2, 2, 1, 8, 0.0f, 1.0f), HFVIS_ERR_INVALID_ARGUMENT);
    /* a stride whose last row lies beyond size_t is refused before any allocation */
    CHECK_EQ_STATUS(ex_png_save(path, px, 1, 3, PTRDIFF_MAX, 1, 8, 0.0f, 1.0f), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(ex_png_save(path, px, 46341, 46341, 46341, 1, 8, 0.0f, 1.0f), HFVIS_ERR_LIMIT);
    CHECK_EQ_STATUS(ex_png_write_file(NULL, (const unsigned char *)"x", 1), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(test_dir_entries(test_dir) == 0);
    /* into a directory that does not exist */
    CHECK_EQ_STATUS(ex_png_save(in_dir(path, sizeof path, "no/such/x.png"), px, 2, 2, 2, 1, 8, 0.0f, 1.0f),
                    HFVIS_ERR_IO);
    CHECK(test_dir_entries(test_dir) == 0);
    /* onto an existing directory: the temporary file is written, the rename fails and the
     * temporary file is removed again */
    CHECK(mkdir(in_dir(dir, sizeof dir, "adir"), 0700) == 0);
    CHECK_EQ_STATUS(ex_png_save(dir, px, 2, 2, 2, 1, 8, 0.0f, 1.0f), HFVIS_ERR_IO);
    CHECK(test_dir_entries(test_dir) == 1 && test_dir_entries(dir) == 0);
    /* the example wrappers report the failure and write nothing either */
    CHECK_EQ_STATUS(ex_save_png(test_dir, "adir", px, 2, 2, 2, 0.0f, 1.0f), HFVIS_ERR_IO);
    CHECK_EQ_STATUS(ex_save_pgm_png(test_dir, "x.pfm", px, 2, 2, 2, 0.0f, 1.0f), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(test_dir_entries(test_dir) == 1 && test_dir_entries(dir) == 0);
    CHECK(rmdir(dir) == 0);
    CHECK(test_dir_entries(test_dir) == 0);
}

TEST(example_wrappers)
{
    /* ex_save_pgm_png writes the PGM and its PNG twin; ex_save_png_sheet lays panels out with
     * white gaps, each panel on its own range, a NULL panel white. */
    const float a[2 * 2] = { 0.0f, 1.0f, 2.0f, 3.0f }, b[2 * 2] = { 10.0f, 20.0f, 30.0f, 40.0f };
    const ex_panel panels[3] = { { a, 0.0f, 3.0f }, { NULL, 0.0f, 0.0f }, { b, 10.0f, 40.0f } };
    const ex_panel bad[1] = { { a, 1.0f, 1.0f } };
    char path[256];
    decoded d;
    int got;
    CHECK_EQ_STATUS(ex_save_pgm_png(test_dir, "t.pgm", a, 2, 2, 2, 0.0f, 3.0f), HFVIS_OK);
    got = decode_file(in_dir(path, sizeof path, "t.png"), &d);
    CHECK(got);
    if (got) {
        static const unsigned char want[4] = { 0, 85, 170, 255 };
        CHECK(memcmp(d.samples, want, 4) == 0);
        free(d.samples);
    }
    CHECK(remove(in_dir(path, sizeof path, "t.png")) == 0);
    CHECK(remove(in_dir(path, sizeof path, "t.pgm")) == 0);
    /* 3 panels of 2 x 2 in rows of 2: (2 + 4 + 2) x (2 + 4 + 2) */
    CHECK_EQ_STATUS(ex_save_png_sheet(test_dir, "s.png", panels, 3, 2, 2, 2, 1), HFVIS_OK);
    got = decode_file(in_dir(path, sizeof path, "s.png"), &d);
    CHECK(got);
    if (got) {
        const unsigned char *s = d.samples;
        int x, y, white = 1;
        CHECK(d.width == 8 && d.height == 8);
        CHECK(s[0] == 0 && s[1] == 85 && s[8] == 170 && s[9] == 255);              /* a, top left */
        CHECK(s[6 * 8] == 0 && s[6 * 8 + 1] == 85 && s[7 * 8] == 170 && s[7 * 8 + 1] == 255); /* b */
        for (y = 0; y < 8; y++)
            for (x = 0; x < 8; x++)
                if (!((x < 2 && (y < 2 || y >= 6)))) white &= s[y * 8 + x] == 255;
        CHECK(white); /* the gaps and the empty slot */
        free(d.samples);
    }
    CHECK(remove(in_dir(path, sizeof path, "s.png")) == 0);
    CHECK_EQ_STATUS(ex_save_png_sheet(test_dir, "s.png", bad, 1, 1, 2, 2, 1), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(ex_save_png_sheet(test_dir, "s.png", panels, 3, 2, 2, 2, 2), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(ex_save_png_sheet(test_dir, "s.png", panels, 0, 2, 2, 2, 1), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(test_dir_entries(test_dir) == 0);
}

int main(int argc, char **argv)
{
    TEST_INIT(argc, argv);
    strcpy(test_dir, "/tmp/hfvis_test_png_XXXXXX");
    if (!mkdtemp(test_dir)) {
        fprintf(stderr, "test_png: cannot create a scratch directory\n");
        return 1;
    }
    RUN(crc32_check_values);
    RUN(adler32_check_values);
    RUN(layout_sizes);
    RUN(encode_byte_layout);
    RUN(round_trip_formats);
    RUN(stored_blocks_split_at_65535);
    RUN(encode_failures_write_nothing);
    RUN(save_maps_floats);
    RUN(save_failures_leave_nothing);
    RUN(example_wrappers);
    rmdir(test_dir);
    return TEST_DONE();
}
