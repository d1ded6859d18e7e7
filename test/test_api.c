/* test_api.c - API-level tests: status strings, the PGM/PFM codecs (round trips, every error
 * path, outputs untouched on error, files) and failing-allocator sweeps.
 * Layout: shared helpers first, then one section per API area. A new area adds its section
 * before main and its RUN lines to main, under a comment naming the section.
 * POSIX (mkdtemp, mkfifo, fork) is used only by the file tests; the library itself needs none. */
#define _POSIX_C_SOURCE 200809L
#include "hfvis.h"
#include "test.h"

#include "test_dir.h"
#include <float.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

/* ========================================================================================== */
/* Shared helpers                                                                             */
/* ========================================================================================== */

/* Byte pattern written into outputs before a call that must fail, to see they stay untouched. */
#define SENTINEL_BYTE 0xA5

static int all_bytes(const void *p, size_t n, unsigned char value)
{
    const unsigned char *b = (const unsigned char *)p;
    size_t i;
    for (i = 0; i < n; i++)
        if (b[i] != value) return 0;
    return 1;
}

/* Same bits (so NaN == NaN with the same payload, and -0 != +0). */
static int same_floats(const float *a, const float *b, size_t n)
{
    return memcmp(a, b, n * sizeof(float)) == 0;
}

/* ========================================================================================== */
/* Status strings                                                                             */
/* ========================================================================================== */

TEST(status_strings)
{
    static const char *const names[] = {
        "HFVIS_OK", "HFVIS_ERR_INVALID_ARGUMENT", "HFVIS_ERR_OUT_OF_MEMORY", "HFVIS_ERR_FORMAT",
        "HFVIS_ERR_LIMIT", "HFVIS_ERR_BUFFER_TOO_SMALL", "HFVIS_ERR_IO"};
    const int count = (int)(sizeof names / sizeof names[0]);
    const char *s[7];
    const int unknown[] = {7, 100, -1, INT_MAX};
    int i, j;
    CHECK(count == HFVIS_ERR_IO + 1);
    for (i = 0; i < count; i++) {
        size_t len = strlen(names[i]);
        s[i] = hfvis_status_string((hfvis_status)i);
        CHECK(s[i] != NULL);
        if (!s[i]) continue;
        /* The name, then an explanation that does not extend the name. */
        CHECK(strncmp(s[i], names[i], len) == 0);
        CHECK(s[i][len] != '_' && !(s[i][len] >= 'A' && s[i][len] <= 'Z'));
    }
    for (i = 0; i < count; i++)
        for (j = i + 1; j < count; j++)
            CHECK(s[i] && s[j] && strcmp(s[i], s[j]) != 0);
    for (i = 0; i < (int)(sizeof unknown / sizeof unknown[0]); i++) {
        const char *u = hfvis_status_string((hfvis_status)unknown[i]);
        CHECK(u != NULL && u[0] != '\0');
        for (j = 0; u && j < count; j++) CHECK(!s[j] || strcmp(u, s[j]) != 0);
    }
}

/* ========================================================================================== */
/* Codecs in memory: PGM (P2/P5) and PFM (Pf/PF)                                              */
/* ========================================================================================== */

/* Largest test image in values, and the largest test file in bytes. */
#define CODEC_MAX_VALUES 64
#define CODEC_MAX_BYTES 1024

/* Builds a PFM: header text as given, then values (row 0 = top) stored bottom row first
 * (pfm(5)) in the given byte order. Returns the file size. */
static size_t make_pfm(unsigned char *buf, const char *header, const float *values, int w, int h,
                       int c, int big_endian)
{
    size_t len = strlen(header), row = (size_t)w * (size_t)c, x;
    int y;
    memcpy(buf, header, len);
    for (y = h - 1; y >= 0; y--) {
        for (x = 0; x < row; x++) {
            uint32_t u;
            int k;
            memcpy(&u, &values[(size_t)y * row + x], 4);
            for (k = 0; k < 4; k++)
                buf[len++] = (unsigned char)(u >> (big_endian ? 24 - 8 * k : 8 * k));
        }
    }
    return len;
}

/* A text file (no NUL inside) as bytes. */
static size_t make_text(unsigned char *buf, const char *text)
{
    size_t len = strlen(text);
    memcpy(buf, text, len);
    return len;
}

/* Decodes data and checks info and values (exact). */
static void check_decode(const void *data, size_t size, hfvis_image_format format, int w, int h,
                         int c, int maxval, int big_endian, const float *want)
{
    hfvis_image_info info, info2;
    float out[CODEC_MAX_VALUES];
    size_t n = (size_t)w * (size_t)h * (size_t)c;
    memset(&info, SENTINEL_BYTE, sizeof info);
    CHECK_EQ_STATUS(hfvis_image_info_read(data, size, &info), HFVIS_OK);
    CHECK(info.format == format && info.width == w && info.height == h && info.channels == c);
    CHECK(info.maxval == maxval && info.big_endian == big_endian);
    memset(out, SENTINEL_BYTE, sizeof out);
    CHECK_EQ_STATUS(hfvis_image_decode(data, size, out, n, &info2), HFVIS_OK);
    CHECK(memcmp(&info, &info2, sizeof info) == 0);
    CHECK(same_floats(out, want, n));
    CHECK(all_bytes(out + n, sizeof out - n * sizeof(float), SENTINEL_BYTE));
    /* info may be NULL */
    CHECK_EQ_STATUS(hfvis_image_decode(data, size, out, n, NULL), HFVIS_OK);
}

/* Both readers must fail with want and leave info and out untouched. */
static void check_error_at(const void *data, size_t size, hfvis_status want, int line)
{
    hfvis_image_info info;
    float out[CODEC_MAX_VALUES];
    hfvis_status s1, s2;
    memset(&info, SENTINEL_BYTE, sizeof info);
    memset(out, SENTINEL_BYTE, sizeof out);
    s1 = hfvis_image_info_read(data, size, &info);
    s2 = hfvis_image_decode(data, size, out, CODEC_MAX_VALUES, &info);
    CHECK_EQ_STATUS(s1, want);
    CHECK_EQ_STATUS(s2, want);
    CHECK(all_bytes(&info, sizeof info, SENTINEL_BYTE));
    CHECK(all_bytes(out, sizeof out, SENTINEL_BYTE));
    if (s1 != want || s2 != want) fprintf(stderr, "  (case at line %d)\n", line);
}
#define CHECK_TEXT_ERROR(text, want) do { unsigned char b_[CODEC_MAX_BYTES] = {0}; \
    check_error_at(b_, make_text(b_, (text)), (want), __LINE__); } while (0)

/* Every proper prefix of a valid file is a truncated file. */
static void check_prefixes(const unsigned char *data, size_t size)
{
    hfvis_image_info info;
    size_t len;
    for (len = 0; len < size; len++) {
        /* A fresh copy of exactly len bytes, so ASan catches any read past the end. */
        unsigned char *p = (unsigned char *)malloc(len ? len : 1);
        CHECK(p != NULL);
        if (!p) return;
        memcpy(p, data, len);
        check_error_at(p, len, HFVIS_ERR_FORMAT, (int)len);
        free(p);
    }
    CHECK_EQ_STATUS(hfvis_image_info_read(data, size, &info), HFVIS_OK);
}

/* Values with every special case of float: NaN (with a payload), infinities, -0, subnormal. */
static void special_floats(float *v, size_t n)
{
    uint32_t nan_bits = 0x7fc01234u;
    size_t i;
    for (i = 0; i < n; i++) v[i] = (float)i * 0.25f - 3.0f;
    memcpy(&v[0], &nan_bits, 4);
    v[1] = INFINITY;
    v[2] = -INFINITY;
    v[3] = -0.0f;
    v[4] = FLT_MIN / 8.0f;
    v[5] = FLT_MAX;
}

TEST(pfm_encode_decode_grey_and_rgb)
{
    const int w = 3, h = 4;
    const ptrdiff_t stride = 5; /* two padding pixels per row */
    int c;
    for (c = 1; c <= 3; c += 2) {
        float img[4 * 5 * 3], want[3 * 4 * 3];
        unsigned char enc[CODEC_MAX_BYTES];
        size_t need = hfvis_pfm_encode_size(w, h, c), written = 0, i;
        int x, y, k;
        const char *head = c == 1 ? "Pf\n3 4\n-1.0\n" : "PF\n3 4\n-1.0\n";
        for (i = 0; i < sizeof img / sizeof img[0]; i++) img[i] = 1234.5f; /* padding */
        special_floats(want, (size_t)(w * h * c));
        for (y = 0; y < h; y++)
            for (x = 0; x < w; x++)
                for (k = 0; k < c; k++)
                    img[((size_t)y * (size_t)stride + (size_t)x) * (size_t)c + (size_t)k] =
                        want[((size_t)y * (size_t)w + (size_t)x) * (size_t)c + (size_t)k];
        CHECK(need == strlen(head) + (size_t)(w * h * c) * 4);
        CHECK_EQ_STATUS(hfvis_pfm_encode(img, w, h, c, stride, enc, sizeof enc, &written), HFVIS_OK);
        CHECK(written == need);
        CHECK(memcmp(enc, head, strlen(head)) == 0);
        /* Bottom row first, little-endian: the first stored value is pixel (0, h-1). */
        {
            uint32_t u;
            memcpy(&u, &want[(size_t)(h - 1) * (size_t)w * (size_t)c], 4);
            CHECK(enc[strlen(head)] == (u & 0xffu) && enc[strlen(head) + 3] == (u >> 24));
        }
        check_decode(enc, written, HFVIS_FORMAT_PFM, w, h, c, 0, 0, want);
    }
}

TEST(pfm_decode_both_byte_orders)
{
    float v[2 * 3 * 3];
    unsigned char buf[CODEC_MAX_BYTES];
    size_t n;
    special_floats(v, sizeof v / sizeof v[0]);
    /* Negative scale: little-endian; positive: big-endian. The magnitude is not applied. */
    n = make_pfm(buf, "Pf\n2 3\n-1.0\n", v, 2, 3, 1, 0);
    check_decode(buf, n, HFVIS_FORMAT_PFM, 2, 3, 1, 0, 0, v);
    n = make_pfm(buf, "Pf\n2 3\n1.0\n", v, 2, 3, 1, 1);
    check_decode(buf, n, HFVIS_FORMAT_PFM, 2, 3, 1, 0, 1, v);
    n = make_pfm(buf, "PF\n2 3\n-0.5\n", v, 2, 3, 3, 0);
    check_decode(buf, n, HFVIS_FORMAT_PFM, 2, 3, 3, 0, 0, v);
    n = make_pfm(buf, "PF\n2 3\n255\n", v, 2, 3, 3, 1);
    check_decode(buf, n, HFVIS_FORMAT_PFM, 2, 3, 3, 0, 1, v);
}

TEST(pfm_header_spellings)
{
    /* Scale spellings, comments (ImageMagick writes them) and odd whitespace; the data starts
     * right after exactly one whitespace byte, here a space or CR. */
    static const char *const le[] = {"Pf\n1 2\n-1\n", "Pf 1 2 -1.0 ", "Pf\t1\t2\t-.5\r",
                                     "Pf\n# c\n1 2 # c\n-1e-3\n", "Pf\n1\n\n2\n-3.E+2\n",
                                     "Pf\n01 0002\n-0.000001\n", "Pf\n1 2\n-1e-300\n",
                                     "Pf\n1 2\n-0.00000000000000000000123456789012345678901\n"};
    static const char *const be[] = {"Pf\n1 2\n1\n", "Pf\n1 2\n+2.5\n", "Pf\n1 2\n3.\n",
                                     "Pf\n1 2\n1E38\n", "Pf\n1 2\n0.00000000000000000000001\n",
                                     "Pf\n1 2\n123456789012345678901234567890\n"};
    float v[2] = {32.0f, -7.5f}; /* the first stored byte of 32.0f LE is 0x00, BE 0x42 */
    unsigned char buf[CODEC_MAX_BYTES];
    size_t i;
    for (i = 0; i < sizeof le / sizeof le[0]; i++)
        check_decode(buf, make_pfm(buf, le[i], v, 1, 2, 1, 0), HFVIS_FORMAT_PFM, 1, 2, 1, 0, 0, v);
    for (i = 0; i < sizeof be / sizeof be[0]; i++)
        check_decode(buf, make_pfm(buf, be[i], v, 1, 2, 1, 1), HFVIS_FORMAT_PFM, 1, 2, 1, 0, 1, v);
}

TEST(pgm_decode_ascii_and_binary)
{
    unsigned char buf[CODEC_MAX_BYTES];
    size_t n;
    {   /* P2 8-bit, comments and every kind of whitespace, last sample ends the data */
        const float want[6] = {0, 1, 2, 3, 4, 255};
        n = make_text(buf, "P2\n# a comment\n3\t2 # after width\n\v255\f0 1 2\r\n3 #c\n 4 255");
        check_decode(buf, n, HFVIS_FORMAT_PGM, 3, 2, 1, 255, 0, want);
    }
    {   /* P2 16-bit, comment glued to a sample, CR-terminated comment, leading zeros */
        const float want[4] = {65535, 0, 1000, 7};
        n = make_text(buf, "P2 2 2 65535 65535#x\r0 01000\n# y\n0007\n");
        check_decode(buf, n, HFVIS_FORMAT_PGM, 2, 2, 1, 65535, 0, want);
    }
    {   /* P2 maxval 1 */
        const float want[3] = {1, 0, 1};
        n = make_text(buf, "P2\n3 1\n1\n1 0 1\n");
        check_decode(buf, n, HFVIS_FORMAT_PGM, 3, 1, 1, 1, 0, want);
    }
    {   /* P5 8-bit; a comment before maxval; trailing bytes ignored */
        const float want[4] = {0, 127, 128, 255};
        n = make_text(buf, "P5\n2 2 # c\n255\n");
        memcpy(buf + n, "\x00\x7f\x80\xff" "tail", 8);
        check_decode(buf, n + 8, HFVIS_FORMAT_PGM, 2, 2, 1, 255, 0, want);
    }
    {   /* P5 16-bit big-endian */
        const float want[3] = {258, 65534, 0};
        n = make_text(buf, "P5 3 1 65535\n");
        memcpy(buf + n, "\x01\x02\xff\xfe\x00\x00", 6);
        check_decode(buf, n + 6, HFVIS_FORMAT_PGM, 3, 1, 1, 65535, 0, want);
    }
    {   /* P5 16-bit with maxval 1000 (> 255 means 2 bytes) */
        const float want[2] = {1000, 999};
        n = make_text(buf, "P5 2 1 1000\n");
        memcpy(buf + n, "\x03\xe8\x03\xe7", 4);
        check_decode(buf, n + 4, HFVIS_FORMAT_PGM, 2, 1, 1, 1000, 0, want);
    }
    {   /* exactly one whitespace byte after maxval: the second '\n' (10) is the sample */
        const float want[2] = {10, 32};
        n = make_text(buf, "P5\n2 1\n255\n\n ");
        check_decode(buf, n, HFVIS_FORMAT_PGM, 2, 1, 1, 255, 0, want);
    }
}

TEST(pgm_encode_mapping)
{
    /* v -> round((v - lo)/(hi - lo)*maxval) clamped; non-finite -> 0. lo = -1, hi = 1:
     * -1 -> 0, 1 -> maxval, 0 -> round(maxval/2) (127.5 rounds up), out of range clamps. */
    const float img[8] = {-1.0f, 1.0f, 0.0f, 2.0f, -5.0f, NAN, INFINITY, -INFINITY};
    const float want8[8] = {0, 255, 128, 255, 0, 0, 0, 0};
    const float want16[8] = {0, 65535, 32768, 65535, 0, 0, 0, 0};
    const float want1000[8] = {0, 1000, 500, 1000, 0, 0, 0, 0};
    unsigned char enc[CODEC_MAX_BYTES];
    size_t written = 0;
    CHECK(hfvis_pgm_encode_size(4, 2, 255) == strlen("P5\n4 2\n255\n") + 8);
    CHECK(hfvis_pgm_encode_size(4, 2, 256) == strlen("P5\n4 2\n256\n") + 16);
    CHECK_EQ_STATUS(hfvis_pgm_encode(img, 4, 2, 4, -1.0f, 1.0f, 255, enc, sizeof enc, &written),
                    HFVIS_OK);
    CHECK(written == hfvis_pgm_encode_size(4, 2, 255));
    CHECK(memcmp(enc, "P5\n4 2\n255\n", 11) == 0);
    check_decode(enc, written, HFVIS_FORMAT_PGM, 4, 2, 1, 255, 0, want8);
    CHECK_EQ_STATUS(hfvis_pgm_encode(img, 4, 2, 4, -1.0f, 1.0f, 65535, enc, sizeof enc, &written),
                    HFVIS_OK);
    CHECK(written == hfvis_pgm_encode_size(4, 2, 65535));
    check_decode(enc, written, HFVIS_FORMAT_PGM, 4, 2, 1, 65535, 0, want16);
    CHECK_EQ_STATUS(hfvis_pgm_encode(img, 4, 2, 4, -1.0f, 1.0f, 1000, enc, sizeof enc, &written),
                    HFVIS_OK);
    check_decode(enc, written, HFVIS_FORMAT_PGM, 4, 2, 1, 1000, 0, want1000);
    {   /* stride > width; maxval 1 */
        const float padded[6] = {0.9f, 0.1f, 99.0f, 0.4f, 0.6f, 99.0f};
        const float want[4] = {1, 0, 0, 1};
        CHECK_EQ_STATUS(hfvis_pgm_encode(padded, 2, 2, 3, 0.0f, 1.0f, 1, enc, sizeof enc, &written),
                        HFVIS_OK);
        check_decode(enc, written, HFVIS_FORMAT_PGM, 2, 2, 1, 1, 0, want);
    }
}

TEST(pgm_range_nodata_round_trip)
{
    /* NoData-safe PGM: code 0 = NoData, codes 1..65535 span [lo, hi], the range in the header
     * comment. Values come back within half a code step; NaN and +-Inf come back NaN. */
    const float img[8] = {-1.0f, 1.0f, 0.0f, 2.0f, -5.0f, NAN, INFINITY, -INFINITY};
    const float codes[8] = {1, 65535, 32768, 65535, 1, 0, 0, 0};
    const double step = 2.0 / HFVIS_PGM_RANGE_CODES; /* one code, (hi - lo)/65534 */
    unsigned char enc[CODEC_MAX_BYTES];
    float back[8], lo = 0.0f, hi = 0.0f;
    hfvis_image_info info;
    size_t written = 0, i;
    const char *comment = "P5\n# hfvis range -1.00000000e+00 1.00000000e+00 nodata 0\n4 2\n65535\n";
    CHECK(hfvis_pgm_range_encode_size(4, 2, -1.0f, 1.0f) == strlen(comment) + 16);
    CHECK_EQ_STATUS(hfvis_pgm_range_encode(img, 4, 2, 4, -1.0f, 1.0f, enc, sizeof enc, &written),
                    HFVIS_OK);
    CHECK(written == strlen(comment) + 16 && memcmp(enc, comment, strlen(comment)) == 0);
    check_decode(enc, written, HFVIS_FORMAT_PGM, 4, 2, 1, 65535, 0, codes); /* plain readers */
    CHECK_EQ_STATUS(hfvis_pgm_range_read(enc, written, &lo, &hi), HFVIS_OK);
    CHECK(lo == -1.0f && hi == 1.0f);
    CHECK_EQ_STATUS(hfvis_pgm_range_decode(enc, written, back, 8, &info), HFVIS_OK);
    CHECK(info.width == 4 && info.height == 2);
    CHECK_NEAR(back[0], -1.0, 0.0, 0.0);
    CHECK_NEAR(back[1], 1.0, 1e-6, 0.0);
    CHECK_NEAR(back[2], 0.0, 0.5 * step, 0.0);
    CHECK_NEAR(back[3], 1.0, 1e-6, 0.0); /* clamped */
    for (i = 5; i < 8; i++) CHECK(isnan(back[i]));
    /* seeded random values and ranges: every float range survives the 9-digit text, every value
     * comes back within half a step */
    {
        uint32_t state = 12345u;
        int r;
        for (r = 0; r < 200; r++) {
            float v[8], a, b;
            double e;
            state = state * 1664525u + 1013904223u;
            memcpy(&a, &state, 4);
            state = state * 1664525u + 1013904223u;
            memcpy(&b, &state, 4);
            if (!isfinite(a) || !isfinite(b) || a == b || fabsf(a) > 1e30f || fabsf(b) > 1e30f) continue;
            if (a > b) { float t = a; a = b; b = t; }
            for (i = 0; i < 8; i++) {
                state = state * 1664525u + 1013904223u;
                v[i] = (float)((double)a + ((double)b - (double)a) * (double)(state >> 8) / 16777216.0);
            }
            CHECK_EQ_STATUS(hfvis_pgm_range_encode(v, 8, 1, 8, a, b, enc, sizeof enc, &written), HFVIS_OK);
            CHECK_EQ_STATUS(hfvis_pgm_range_read(enc, written, &lo, &hi), HFVIS_OK);
            CHECK(lo == a && hi == b);
            CHECK_EQ_STATUS(hfvis_pgm_range_decode(enc, written, back, 8, NULL), HFVIS_OK);
            e = ((double)b - (double)a) / HFVIS_PGM_RANGE_CODES;
            for (i = 0; i < 8; i++) CHECK_NEAR(back[i], v[i], 0.5 * e + 1e-6 * fabs((double)v[i]), 0.0);
        }
    }
    /* old files (no comment), PFM, a damaged comment: HFVIS_ERR_FORMAT; bad arguments */
    CHECK_EQ_STATUS(hfvis_pgm_encode(img, 4, 2, 4, -1.0f, 1.0f, 65535, enc, sizeof enc, &written), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_pgm_range_read(enc, written, &lo, &hi), HFVIS_ERR_FORMAT);
    CHECK_EQ_STATUS(hfvis_pgm_range_decode(enc, written, back, 8, NULL), HFVIS_ERR_FORMAT);
    CHECK_EQ_STATUS(hfvis_pfm_encode(img, 4, 2, 1, 4, enc, sizeof enc, &written), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_pgm_range_read(enc, written, &lo, &hi), HFVIS_ERR_FORMAT);
    {
        char bad[128];
        size_t n = (size_t)snprintf(bad, sizeof bad, "P2\n# hfvis range 1 x nodata 0\n1 1 9\n3\n");
        CHECK_EQ_STATUS(hfvis_pgm_range_read(bad, n, &lo, &hi), HFVIS_ERR_FORMAT);
        n = (size_t)snprintf(bad, sizeof bad, "P2\n# hfvis range 2 1 nodata 0\n1 1 9\n3\n");
        CHECK_EQ_STATUS(hfvis_pgm_range_read(bad, n, &lo, &hi), HFVIS_ERR_FORMAT); /* lo > hi */
        n = (size_t)snprintf(bad, sizeof bad, "P2\n# hfvis range 1 2\n1 1 9\n3\n");
        CHECK_EQ_STATUS(hfvis_pgm_range_read(bad, n, &lo, &hi), HFVIS_ERR_FORMAT); /* no nodata */
        n = (size_t)snprintf(bad, sizeof bad, "P2 1 1 9\n# hfvis range 0 9 nodata 0\n3\n");
        CHECK_EQ_STATUS(hfvis_pgm_range_read(bad, n, &lo, &hi), HFVIS_ERR_FORMAT); /* in the data */
        n = (size_t)snprintf(bad, sizeof bad, "P2 # hfvis range 0 9 nodata 0\n1 1 9\n3\n");
        CHECK_EQ_STATUS(hfvis_pgm_range_read(bad, n, &lo, &hi), HFVIS_OK);
        CHECK(lo == 0.0f && hi == 9.0f);
        CHECK_EQ_STATUS(hfvis_pgm_range_decode(bad, n, back, 1, NULL), HFVIS_OK);
        CHECK_NEAR(back[0], 2.0 * 9.0 / HFVIS_PGM_RANGE_CODES, 1e-7, 0.0);
        CHECK_EQ_STATUS(hfvis_pgm_range_decode(bad, n, back, 0, NULL), HFVIS_ERR_BUFFER_TOO_SMALL);
    }
    CHECK(hfvis_pgm_range_encode_size(4, 2, 1.0f, 1.0f) == 0);
    CHECK(hfvis_pgm_range_encode_size(4, 2, 0.0f, INFINITY) == 0);
    CHECK(hfvis_pgm_range_encode_size(0, 2, 0.0f, 1.0f) == 0);
    CHECK_EQ_STATUS(hfvis_pgm_range_encode(img, 4, 2, 3, 0.0f, 1.0f, enc, sizeof enc, &written),
                    HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_pgm_range_encode(img, 4, 2, 4, 0.0f, 1.0f, enc, 10, &written),
                    HFVIS_ERR_BUFFER_TOO_SMALL);
    CHECK_EQ_STATUS(hfvis_pgm_range_read(NULL, 4, &lo, &hi), HFVIS_ERR_INVALID_ARGUMENT);
}

TEST(codec_round_trip_integers)
{
    /* Integers 0..maxval survive P5 encode (lo = 0, hi = maxval) -> decode exactly. */
    const int maxvals[] = {1, 2, 9, 255, 256, 4095, 65535};
    unsigned char enc[CODEC_MAX_BYTES];
    float img[CODEC_MAX_VALUES];
    size_t m, i, written;
    for (m = 0; m < sizeof maxvals / sizeof maxvals[0]; m++) {
        int mv = maxvals[m];
        for (i = 0; i < 40; i++) img[i] = (float)((i * 7919u) % (unsigned)(mv + 1));
        img[0] = 0.0f;
        img[1] = (float)mv;
        CHECK_EQ_STATUS(hfvis_pgm_encode(img, 8, 5, 8, 0.0f, (float)mv, mv, enc, sizeof enc,
                                         &written), HFVIS_OK);
        check_decode(enc, written, HFVIS_FORMAT_PGM, 8, 5, 1, mv, 0, img);
    }
}

TEST(codec_truncated_at_every_length)
{
    unsigned char buf[CODEC_MAX_BYTES];
    float v[2 * 3 * 3];
    size_t n;
    special_floats(v, sizeof v / sizeof v[0]);
    /* P2 files end with a one-digit sample and no trailing whitespace, so that no prefix is
     * itself a valid file. */
    check_prefixes(buf, make_text(buf, "P2\n# c\n12 1\n255\n1 2 3 4 5 6 7 8 9 10 11 1"));
    check_prefixes(buf, make_text(buf, "P2 2 2 65535 65535 0 1000 7"));
    n = make_text(buf, "P5\n3 2\n255\n");
    memcpy(buf + n, "\x00\x01\x02\x03\x04\x05", 6);
    check_prefixes(buf, n + 6);
    n = make_text(buf, "P5\n2 2\n65535\n");
    memcpy(buf + n, "\x00\x01\x02\x03\x04\x05\x06\x07", 8);
    check_prefixes(buf, n + 8);
    check_prefixes(buf, make_pfm(buf, "Pf\n2 3\n-1.0\n", v, 2, 3, 1, 0));
    check_prefixes(buf, make_pfm(buf, "PF\n# c\n2 3\n1.0\n", v, 2, 3, 3, 1));
}

TEST(codec_bad_magic)
{
    CHECK_TEXT_ERROR("", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P6\n1 1\n255\n\x01\x02\x03", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P3\n1 1\n255\n1 2 3", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P1\n1 1\n1", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P7\nWIDTH 1\n", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("p5\n1 1\n255\nx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("Q5\n1 1\n255\nx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR(" P5\n1 1\n255\nx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("PG\n1 1\n-1\nxxxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("Pff\n1 1\n-1\nxxxx", HFVIS_ERR_FORMAT);  /* magic glued to a letter */
    CHECK_TEXT_ERROR("P51 1\n255\nx", HFVIS_ERR_FORMAT);        /* magic glued to the width */
}

TEST(codec_bad_header)
{
    /* truncated header */
    CHECK_TEXT_ERROR("P5", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P5\n", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P5\n3 2", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P5\n3 2\n255", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P5\n# comment to the end", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("Pf\n1 1\n-1.0", HFVIS_ERR_FORMAT);
    /* the single byte after maxval / scale must be whitespace */
    CHECK_TEXT_ERROR("P5\n1 1\n255#c\nx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P5\n1 1\n255x", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("Pf\n1 1\n-1.0#\nxxxx", HFVIS_ERR_FORMAT);
    /* zero and negative dimensions */
    CHECK_TEXT_ERROR("P5\n0 2\n255\nxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P5\n2 0\n255\nxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P2\n0 0\n255\n", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("Pf\n0 1\n-1\nxxxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P5\n-2 2\n255\nxxxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("Pf\n2 -1\n-1\nxxxxxxxx", HFVIS_ERR_FORMAT);
    /* non-numeric fields */
    CHECK_TEXT_ERROR("P5\nabc 2\n255\nxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P5\n2 2x\n255\nxxxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P5\n2 2\nff\nxxxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P5\n2.0 2\n255\nxxxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P5\n+2 2\n255\nxxxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("Pf\n1 1\nabc\nxxxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("Pf\n1 1\n-\nxxxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("Pf\n1 1\n.\nxxxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("Pf\n1 1\n1e\nxxxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("Pf\n1 1\n1e+\nxxxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("Pf\n1 1\n1.0.0\nxxxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("Pf\n1 1\n0x1p0\nxxxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("Pf\n1 1\n--1\nxxxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("Pf\n1 1\n-1,0\nxxxx", HFVIS_ERR_FORMAT);
    /* overflowing numbers (above INT_MAX) are malformed, not merely over the limit */
    CHECK_TEXT_ERROR("P5\n2147483648 1\n255\nx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P5\n1 99999999999999999999999999\n255\nx", HFVIS_ERR_FORMAT);
    /* maxval outside 1..65535 */
    CHECK_TEXT_ERROR("P5\n1 1\n0\nx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P2\n1 1\n0\n0", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P5\n1 1\n65536\nxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P5\n1 1\n4294967296\nxx", HFVIS_ERR_FORMAT);
    /* PFM scale must be finite and non-zero */
    CHECK_TEXT_ERROR("Pf\n1 1\n0.0\nxxxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("Pf\n1 1\n-0\nxxxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("Pf\n1 1\n0e5\nxxxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("Pf\n1 1\nnan\nxxxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("Pf\n1 1\nNaN\nxxxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("Pf\n1 1\ninf\nxxxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("Pf\n1 1\n-inf\nxxxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("Pf\n1 1\n1e999\nxxxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("Pf\n1 1\n-1e-999\nxxxx", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("Pf\n1 1\n1000000000000000000000000000000000000000000000000000000000000000"
                     "0000000000000000000000000000000000000000000000000000000000000000000000000"
                     "0000000000000000000000000000000000000000000000000000000000000000000000000"
                     "0000000000000000000000000000000000000000000000000000000000000000000000000"
                     "0000000000000000000000000000\nxxxx", HFVIS_ERR_FORMAT); /* 1e310 */
}

TEST(codec_limits)
{
    /* A dimension over HFVIS_IMAGE_MAX_DIM, or a value count over HFVIS_IMAGE_MAX_VALUES, is
     * HFVIS_ERR_LIMIT, reported before the (missing) data is looked at. */
    CHECK(HFVIS_IMAGE_MAX_DIM == 1048576);
    CHECK_TEXT_ERROR("P5\n1048577 1\n255\n", HFVIS_ERR_LIMIT);
    CHECK_TEXT_ERROR("P2\n1 1048577\n255\n", HFVIS_ERR_LIMIT);
    CHECK_TEXT_ERROR("Pf\n2147483647 1\n-1\n", HFVIS_ERR_LIMIT);
    CHECK_TEXT_ERROR("P5\n1048576 1048576\n255\n", HFVIS_ERR_LIMIT);
    CHECK_TEXT_ERROR("P5\n16384 16385\n255\n", HFVIS_ERR_LIMIT);  /* 2^28 + 16384 values */
    /* 16384 x 8193 = 134 M values: under the limit grey (so the short data is the error)... */
    CHECK_TEXT_ERROR("Pf\n16384 8193\n-1\n", HFVIS_ERR_FORMAT);
    /* ...but three channels make 403 M values */
    CHECK_TEXT_ERROR("PF\n16384 8193\n-1\n", HFVIS_ERR_LIMIT);
    /* exactly at the limits: the data is what is missing */
    CHECK_TEXT_ERROR("P5\n1048576 1\n255\n", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P5\n16384 16384\n255\n", HFVIS_ERR_FORMAT);
}

TEST(codec_bad_samples)
{
    unsigned char buf[CODEC_MAX_BYTES];
    size_t n;
    /* P2: samples above maxval, signs, junk, missing samples */
    CHECK_TEXT_ERROR("P2\n2 1\n5\n1 6", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P2\n2 1\n65535\n1 65536", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P2\n2 1\n255\n1 99999999999999999999999", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P2\n2 1\n255\n1 -1", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P2\n2 1\n255\n1 +1", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P2\n2 1\n255\n1 2x", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P2\n2 1\n255\n1 1.5", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P2\n2 1\n255\n1 # 2", HFVIS_ERR_FORMAT);
    CHECK_TEXT_ERROR("P2\n2 1\n255\n1\n", HFVIS_ERR_FORMAT);
    /* P5: samples above a maxval that is not 2^k - 1 */
    n = make_text(buf, "P5\n2 1\n9\n");
    memcpy(buf + n, "\x09\x0a", 2);
    check_error_at(buf, n + 2, HFVIS_ERR_FORMAT, __LINE__);
    n = make_text(buf, "P5\n2 1\n1000\n");
    memcpy(buf + n, "\x03\xe8\x03\xe9", 4);
    check_error_at(buf, n + 4, HFVIS_ERR_FORMAT, __LINE__);
}

TEST(codec_buffer_too_small_and_null)
{
    float v[2 * 3 * 3], out[CODEC_MAX_VALUES];
    hfvis_image_info info;
    size_t sizes[3], counts[3] = {6, 18, 6}, k;
    unsigned char files[3][CODEC_MAX_BYTES];
    special_floats(v, sizeof v / sizeof v[0]);
    sizes[0] = make_pfm(files[0], "Pf\n2 3\n-1\n", v, 2, 3, 1, 0);
    sizes[1] = make_pfm(files[1], "PF\n2 3\n1\n", v, 2, 3, 3, 1);
    sizes[2] = make_text(files[2], "P2 2 3 9 1 2 3 4 5 6");
    for (k = 0; k < 3; k++) {
        memset(out, SENTINEL_BYTE, sizeof out);
        memset(&info, SENTINEL_BYTE, sizeof info);
        CHECK_EQ_STATUS(hfvis_image_decode(files[k], sizes[k], out, counts[k] - 1, &info),
                        HFVIS_ERR_BUFFER_TOO_SMALL);
        CHECK_EQ_STATUS(hfvis_image_decode(files[k], sizes[k], out, 0, &info),
                        HFVIS_ERR_BUFFER_TOO_SMALL);
        CHECK(all_bytes(out, sizeof out, SENTINEL_BYTE));
        CHECK(all_bytes(&info, sizeof info, SENTINEL_BYTE));
        CHECK_EQ_STATUS(hfvis_image_decode(files[k], sizes[k], out, counts[k], &info), HFVIS_OK);
        CHECK(all_bytes(out + counts[k], sizeof out - counts[k] * sizeof(float), SENTINEL_BYTE));
        /* NULL arguments */
        memset(out, SENTINEL_BYTE, sizeof out);
        memset(&info, SENTINEL_BYTE, sizeof info);
        CHECK_EQ_STATUS(hfvis_image_info_read(NULL, sizes[k], &info), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_image_info_read(files[k], sizes[k], NULL), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_image_decode(NULL, sizes[k], out, counts[k], &info),
                        HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_image_decode(files[k], sizes[k], NULL, counts[k], &info),
                        HFVIS_ERR_INVALID_ARGUMENT);
        CHECK(all_bytes(out, sizeof out, SENTINEL_BYTE));
        CHECK(all_bytes(&info, sizeof info, SENTINEL_BYTE));
    }
}

TEST(codec_encode_errors)
{
    float img[CODEC_MAX_VALUES];
    unsigned char enc[CODEC_MAX_BYTES];
    size_t written, need, i;
    for (i = 0; i < CODEC_MAX_VALUES; i++) img[i] = (float)i;
    /* size queries: 0 for invalid sizes and on overflow */
    CHECK(hfvis_pfm_encode_size(0, 1, 1) == 0);
    CHECK(hfvis_pfm_encode_size(1, 0, 1) == 0);
    CHECK(hfvis_pfm_encode_size(-1, 1, 1) == 0);
    CHECK(hfvis_pfm_encode_size(1, 1, 0) == 0);
    CHECK(hfvis_pfm_encode_size(1, 1, 2) == 0);
    CHECK(hfvis_pfm_encode_size(1, 1, 4) == 0);
    CHECK(hfvis_pfm_encode_size(1, 1, 1) == strlen("Pf\n1 1\n-1.0\n") + 4);
    CHECK(hfvis_pfm_encode_size(2147483647, 2147483647, 3) == 0
          || SIZE_MAX / 12 / 2147483647u >= 2147483647u);
    CHECK(hfvis_pgm_encode_size(1, 1, 0) == 0);
    CHECK(hfvis_pgm_encode_size(1, 1, 65536) == 0);
    CHECK(hfvis_pgm_encode_size(0, 1, 255) == 0);
    CHECK(hfvis_pgm_encode_size(1, -5, 255) == 0);
    /* PFM encode */
    need = hfvis_pfm_encode_size(4, 2, 3);
    written = 77;
    CHECK_EQ_STATUS(hfvis_pfm_encode(NULL, 4, 2, 3, 4, enc, sizeof enc, &written), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_pfm_encode(img, 4, 2, 3, 4, NULL, sizeof enc, &written), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_pfm_encode(img, 4, 2, 3, 4, enc, sizeof enc, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_pfm_encode(img, 0, 2, 3, 4, enc, sizeof enc, &written), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_pfm_encode(img, 4, 2, 2, 4, enc, sizeof enc, &written), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_pfm_encode(img, 4, 2, 3, 3, enc, sizeof enc, &written), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_pfm_encode(img, 4, 2, 3, -4, enc, sizeof enc, &written), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_pfm_encode(img, 4, 3, 3, PTRDIFF_MAX / 2, enc, sizeof enc, &written),
                    HFVIS_ERR_INVALID_ARGUMENT);
    memset(enc, SENTINEL_BYTE, sizeof enc);
    CHECK_EQ_STATUS(hfvis_pfm_encode(img, 4, 2, 3, 4, enc, need - 1, &written), HFVIS_ERR_BUFFER_TOO_SMALL);
    CHECK(written == 77 && all_bytes(enc, sizeof enc, SENTINEL_BYTE));
    CHECK_EQ_STATUS(hfvis_pfm_encode(img, 4, 2, 3, 4, enc, need, &written), HFVIS_OK);
    CHECK(written == need && all_bytes(enc + need, sizeof enc - need, SENTINEL_BYTE));
    /* one row: any stride >= width is fine, the rows after the first are never addressed */
    CHECK_EQ_STATUS(hfvis_pfm_encode(img, 4, 1, 3, PTRDIFF_MAX, enc, sizeof enc, &written), HFVIS_OK);
    /* PGM encode */
    need = hfvis_pgm_encode_size(4, 2, 300);
    written = 77;
    CHECK_EQ_STATUS(hfvis_pgm_encode(NULL, 4, 2, 4, 0.0f, 1.0f, 300, enc, sizeof enc, &written), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_pgm_encode(img, 4, 2, 4, 0.0f, 1.0f, 300, NULL, sizeof enc, &written), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_pgm_encode(img, 4, 2, 4, 0.0f, 1.0f, 300, enc, sizeof enc, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_pgm_encode(img, 4, 0, 4, 0.0f, 1.0f, 300, enc, sizeof enc, &written), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_pgm_encode(img, 4, 2, 3, 0.0f, 1.0f, 300, enc, sizeof enc, &written), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_pgm_encode(img, 4, 2, 4, 1.0f, 1.0f, 300, enc, sizeof enc, &written), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_pgm_encode(img, 4, 2, 4, 2.0f, 1.0f, 300, enc, sizeof enc, &written), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_pgm_encode(img, 4, 2, 4, NAN, 1.0f, 300, enc, sizeof enc, &written), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_pgm_encode(img, 4, 2, 4, 0.0f, INFINITY, 300, enc, sizeof enc, &written), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_pgm_encode(img, 4, 2, 4, 0.0f, 1.0f, 0, enc, sizeof enc, &written), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_pgm_encode(img, 4, 2, 4, 0.0f, 1.0f, 65536, enc, sizeof enc, &written), HFVIS_ERR_INVALID_ARGUMENT);
    memset(enc, SENTINEL_BYTE, sizeof enc);
    CHECK_EQ_STATUS(hfvis_pgm_encode(img, 4, 2, 4, 0.0f, 1.0f, 300, enc, need - 1, &written), HFVIS_ERR_BUFFER_TOO_SMALL);
    CHECK(written == 77 && all_bytes(enc, sizeof enc, SENTINEL_BYTE));
    CHECK_EQ_STATUS(hfvis_pgm_encode(img, 4, 2, 4, 0.0f, 1.0f, 300, enc, need, &written), HFVIS_OK);
    CHECK(written == need && all_bytes(enc + need, sizeof enc - need, SENTINEL_BYTE));
}

/* ========================================================================================== */
/* Codec files: load, save, I/O errors, failing allocator                                     */
/* ========================================================================================== */

static char test_dir[64]; /* created by the first file test, removed by the last */
static float sentinel_target; /* its address is the sentinel for a float ** output */

/* path = test_dir/name */
static const char *tmp_path(char *buf, size_t cap, const char *name)
{
    int n = snprintf(buf, cap, "%s/%s", test_dir, name);
    return (n > 0 && (size_t)n < cap) ? buf : "";
}

static int write_bytes(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    int ok;
    if (!f) return 0;
    ok = fwrite(data, 1, n, f) == n;
    return (fclose(f) == 0) && ok;
}

/* Whole file into buf (at most cap bytes); returns the size or (size_t)-1. */
static size_t read_bytes(const char *path, unsigned char *buf, size_t cap)
{
    FILE *f = fopen(path, "rb");
    size_t n;
    if (!f) return (size_t)-1;
    n = fread(buf, 1, cap, f);
    fclose(f);
    return n;
}

TEST(files_setup)
{
    strcpy(test_dir, "/tmp/hfvis_test_api_XXXXXX");
    CHECK(mkdtemp(test_dir) != NULL);
}

TEST(files_save_and_load)
{
    char path[128], path2[128];
    float img[4 * 3 * 3], *px = NULL, want[3 * 3 * 3];
    unsigned char enc[CODEC_MAX_BYTES], file[CODEC_MAX_BYTES];
    hfvis_image_info info;
    size_t written, i;
    int x, y, c;
    special_floats(img, sizeof img / sizeof img[0]);
    for (y = 0; y < 3; y++)
        for (x = 0; x < 3; x++)
            for (c = 0; c < 3; c++) want[(y * 3 + x) * 3 + c] = img[(y * 4 + x) * 3 + c];
    /* PFM RGB with stride 4: the file equals the in-memory encoding, and loads back exactly */
    CHECK_EQ_STATUS(hfvis_pfm_save(tmp_path(path, sizeof path, "a.pfm"), img, 3, 3, 3, 4), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_pfm_encode(img, 3, 3, 3, 4, enc, sizeof enc, &written), HFVIS_OK);
    CHECK(read_bytes(path, file, sizeof file) == written && memcmp(file, enc, written) == 0);
    CHECK_EQ_STATUS(hfvis_image_load(path, NULL, &px, &info), HFVIS_OK);
    CHECK(info.format == HFVIS_FORMAT_PFM && info.width == 3 && info.height == 3 && info.channels == 3);
    CHECK(px && same_floats(px, want, 27));
    hfvis_free(NULL, px);
    /* PGM 16-bit and 8-bit */
    for (i = 0; i < 12; i++) img[i] = (float)i / 11.0f;
    CHECK_EQ_STATUS(hfvis_pgm_save(tmp_path(path2, sizeof path2, "b.pgm"), img, 3, 4, 3, 0.0f,
                                   1.0f, 65535), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_image_load(path2, NULL, &px, &info), HFVIS_OK);
    CHECK(info.format == HFVIS_FORMAT_PGM && info.maxval == 65535 && info.width == 3 && info.height == 4);
    for (i = 0; px && i < 12; i++) CHECK(px[i] == (float)round((double)img[i] * 65535.0));
    hfvis_free(NULL, px);
    /* overwrite: the new, smaller file replaces the old one completely */
    CHECK_EQ_STATUS(hfvis_pgm_save(path2, img, 2, 1, 2, 0.0f, 1.0f, 255), HFVIS_OK);
    CHECK(read_bytes(path2, file, sizeof file) == hfvis_pgm_encode_size(2, 1, 255));
    CHECK_EQ_STATUS(hfvis_image_load(path2, NULL, &px, &info), HFVIS_OK);
    CHECK(info.maxval == 255 && info.width == 2 && info.height == 1);
    CHECK(px && px[0] == 0.0f && px[1] == (float)round(255.0 / 11.0));
    hfvis_free(NULL, px);
    /* the NoData-safe PGM with its range: the file is its encoding, and decodes back */
    img[0] = NAN;
    CHECK_EQ_STATUS(hfvis_pgm_range_save(path2, img, 3, 4, 3, 0.0f, 1.0f), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_pgm_range_encode(img, 3, 4, 3, 0.0f, 1.0f, enc, sizeof enc, &written), HFVIS_OK);
    CHECK(read_bytes(path2, file, sizeof file) == written && memcmp(file, enc, written) == 0);
    CHECK_EQ_STATUS(hfvis_image_load(path2, NULL, &px, &info), HFVIS_OK);
    CHECK(info.maxval == 65535 && px && px[0] == (float)HFVIS_PGM_NODATA_CODE && px[11] == 65535.0f);
    hfvis_free(NULL, px);
    CHECK_EQ_STATUS(hfvis_pgm_range_save(path2, img, 3, 4, 3, 1.0f, 0.0f), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_pgm_range_save(NULL, img, 3, 4, 3, 0.0f, 1.0f), HFVIS_ERR_INVALID_ARGUMENT);
    /* nothing but the two files is left behind */
    CHECK(test_dir_entries(test_dir) == 2);
    CHECK(remove(path) == 0 && remove(path2) == 0);
}

TEST(files_errors)
{
    char path[128], dir[128], sub[160];
    float img[4] = {1, 2, 3, 4}, *px;
    hfvis_image_info info;
    float *const px_sentinel = &sentinel_target;
    /* load: bad arguments, missing file, a directory, an empty and a truncated file */
    px = px_sentinel;
    memset(&info, SENTINEL_BYTE, sizeof info);
    CHECK_EQ_STATUS(hfvis_image_load(NULL, NULL, &px, &info), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_image_load(tmp_path(path, sizeof path, "x.pfm"), NULL, NULL, &info),
                    HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_image_load(path, NULL, &px, NULL), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_image_load(tmp_path(path, sizeof path, "missing.pfm"), NULL, &px, &info),
                    HFVIS_ERR_IO);
    CHECK_EQ_STATUS(hfvis_image_load(test_dir, NULL, &px, &info), HFVIS_ERR_IO);
    CHECK(write_bytes(tmp_path(path, sizeof path, "empty.pgm"), "", 0));
    CHECK_EQ_STATUS(hfvis_image_load(path, NULL, &px, &info), HFVIS_ERR_FORMAT);
    CHECK(remove(path) == 0);
    CHECK(write_bytes(tmp_path(path, sizeof path, "short.pgm"), "P5\n2 2\n255\n\x01\x02\x03", 14));
    CHECK_EQ_STATUS(hfvis_image_load(path, NULL, &px, &info), HFVIS_ERR_FORMAT);
    CHECK(remove(path) == 0);
    CHECK(px == px_sentinel && all_bytes(&info, sizeof info, SENTINEL_BYTE));
    /* save: bad arguments create nothing */
    CHECK_EQ_STATUS(hfvis_pfm_save(NULL, img, 2, 2, 1, 2), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_pfm_save(tmp_path(path, sizeof path, "s.pfm"), NULL, 2, 2, 1, 2),
                    HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_pfm_save(path, img, 2, 2, 2, 2), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_pfm_save(path, img, 2, 2, 1, 1), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_pgm_save(path, img, 2, 2, 2, 1.0f, 0.0f, 255), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_pgm_save(path, img, 2, 2, 2, 0.0f, 1.0f, 0), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK(test_dir_entries(test_dir) == 0);
    /* save into a directory that does not exist */
    CHECK_EQ_STATUS(hfvis_pfm_save(tmp_path(path, sizeof path, "no/such/dir/s.pfm"), img, 2, 2, 1, 2),
                    HFVIS_ERR_IO);
    CHECK_EQ_STATUS(hfvis_pgm_save(path, img, 2, 2, 2, 0.0f, 4.0f, 255), HFVIS_ERR_IO);
    /* save onto an existing directory: the temporary file is written, the rename fails, and the
     * temporary file is removed again */
    CHECK(mkdir(tmp_path(dir, sizeof dir, "adir"), 0700) == 0);
    CHECK_EQ_STATUS(hfvis_pfm_save(dir, img, 2, 2, 1, 2), HFVIS_ERR_IO);
    CHECK_EQ_STATUS(hfvis_pgm_save(dir, img, 2, 2, 2, 0.0f, 4.0f, 255), HFVIS_ERR_IO);
    CHECK(test_dir_entries(test_dir) == 1 && test_dir_entries(dir) == 0);
    /* save into a read-only directory (root ignores permissions, so only as another user) */
    if (geteuid() != 0) {
        int n = snprintf(sub, sizeof sub, "%s/s.pfm", dir);
        CHECK(n > 0 && (size_t)n < sizeof sub);
        CHECK(chmod(dir, 0500) == 0);
        CHECK_EQ_STATUS(hfvis_pfm_save(sub, img, 2, 2, 1, 2), HFVIS_ERR_IO);
        CHECK(chmod(dir, 0700) == 0);
        CHECK(test_dir_entries(dir) == 0);
    }
    CHECK(rmdir(dir) == 0);
    CHECK(test_dir_entries(test_dir) == 0);
}

/* A pipe cannot seek, so the loader grows its buffer as data arrives: serve the file through a
 * FIFO from a child process. Returns the load status. */
static hfvis_status load_through_fifo(const char *fifo, const unsigned char *data, size_t n,
                                      const hfvis_allocator *alloc, float **px,
                                      hfvis_image_info *info)
{
    hfvis_status s;
    pid_t pid;
    int status;
    fflush(NULL);
    pid = fork();
    if (pid < 0) return HFVIS_ERR_IO;
    if (pid == 0) {
        FILE *f;
        signal(SIGPIPE, SIG_IGN); /* the reader may stop early (failing allocator) */
        f = fopen(fifo, "wb");
        if (f) {
            (void)fwrite(data, 1, n, f);
            fclose(f);
        }
        _exit(0);
    }
    s = hfvis_image_load(fifo, alloc, px, info);
    waitpid(pid, &status, 0);
    return s;
}

/* Header first, then exactly the bytes announced (issue: `skyview /dev/zero` climbed to 2 GB,
 * 300 MB of "P5\n" on a pipe were read whole before the magic number was checked). Bytes handed
 * out by the allocator: at most the 64 KiB head for a refused header; head + announced size + 1
 * + pixels for a file with 4 MB of trailing data. */
#define READ_HEAD_BYTES ((size_t)1 << 16) /* the loader's first read (hfvis__read_file) */
TEST(files_header_first)
{
    enum { JUNK = 4 << 20 };
    static unsigned char junk[JUNK], enc[16 * 16 * 4 + 64 + JUNK];
    static float img[16 * 16];
    char path[128], fifo[128];
    size_t written, i;
    float *px = NULL;
    hfvis_image_info info;
    test_counting state;
    hfvis_allocator a;
    for (i = 0; i < JUNK; i++) junk[i] = "P5\n"[i % 3];
    CHECK(mkfifo(tmp_path(fifo, sizeof fifo, "fifo_junk"), 0600) == 0);
    a = test_counting_allocator(&state, 0);
    CHECK_EQ_STATUS(load_through_fifo(fifo, junk, JUNK, &a, &px, &info), HFVIS_ERR_FORMAT);
    CHECK(state.live == 0 && state.bytes <= READ_HEAD_BYTES);
    CHECK(write_bytes(tmp_path(path, sizeof path, "junk.pgm"), junk, JUNK));
    a = test_counting_allocator(&state, 0);
    CHECK_EQ_STATUS(hfvis_image_load(path, &a, &px, &info), HFVIS_ERR_FORMAT);
    CHECK(state.live == 0 && state.bytes <= READ_HEAD_BYTES);
    /* zeros (as /dev/zero): the magic is refused after the head */
    memset(junk, 0, sizeof junk);
    a = test_counting_allocator(&state, 0);
    CHECK_EQ_STATUS(load_through_fifo(fifo, junk, JUNK, &a, &px, &info), HFVIS_ERR_FORMAT);
    CHECK(state.live == 0 && state.bytes <= READ_HEAD_BYTES);
    /* a valid 16 x 16 PFM followed by 4 MB of trailing bytes: read to the announced end + 1 */
    for (i = 0; i < 16 * 16; i++) img[i] = (float)i;
    CHECK_EQ_STATUS(hfvis_pfm_encode(img, 16, 16, 1, 16, enc, sizeof enc, &written), HFVIS_OK);
    memset(enc + written, 'x', JUNK);
    CHECK(write_bytes(path, enc, written + JUNK));
    a = test_counting_allocator(&state, 0);
    CHECK_EQ_STATUS(hfvis_image_load(path, &a, &px, &info), HFVIS_OK);
    CHECK(state.bytes <= READ_HEAD_BYTES + written + 1 + sizeof img);
    if (state.live == 1) hfvis_free(&a, px);
    a = test_counting_allocator(&state, 0);
    CHECK_EQ_STATUS(load_through_fifo(fifo, enc, written + JUNK, &a, &px, &info), HFVIS_OK);
    CHECK(state.bytes <= READ_HEAD_BYTES + written + 1 + sizeof img);
    if (state.live == 1) hfvis_free(&a, px);
    /* a header announcing 4096 x 4096 floats over 80 kB: refused as short, never 64 MB allocated */
    memcpy(enc, "Pf\n4096 4096\n-1\n", 16);
    memset(enc + 16, 0, 80000);
    CHECK(write_bytes(path, enc, 80016));
    a = test_counting_allocator(&state, 0);
    CHECK_EQ_STATUS(hfvis_image_load(path, &a, &px, &info), HFVIS_ERR_FORMAT);
    CHECK(state.live == 0 && state.bytes <= READ_HEAD_BYTES);
    /* text formats have no size to announce: a P2 header followed by zeros, and an OBJ of zeros
     * through the FIFO (as /dev/zero), are refused at the NUL bytes of the head; both were read
     * to the end before */
    memset(junk, 0, sizeof junk);
    memcpy(junk, "P2\n4 4\n255\n", 11);
    a = test_counting_allocator(&state, 0);
    CHECK_EQ_STATUS(load_through_fifo(fifo, junk, JUNK, &a, &px, &info), HFVIS_ERR_FORMAT);
    CHECK(state.live == 0 && state.bytes <= READ_HEAD_BYTES);
    {
        hfvis_mesh m;
        char obj[128];
        memset(junk, 0, 11);
        CHECK(write_bytes(tmp_path(obj, sizeof obj, "zeros.obj"), junk, JUNK));
        a = test_counting_allocator(&state, 0);
        CHECK_EQ_STATUS(hfvis_mesh_load(obj, &a, &m), HFVIS_ERR_FORMAT);
        CHECK(state.live == 0 && state.bytes <= READ_HEAD_BYTES);
        CHECK(remove(obj) == 0);
    }
    CHECK(remove(path) == 0 && remove(fifo) == 0);
}

TEST(files_load_failing_allocator)
{
    /* 200 x 100 grey PFM = 80 kB, from a regular file and through a FIFO: 3 allocations each
     * (the 64 kB head whose header announces the size, the announced bytes, pixels). Allocation k fails
     * for every k until the load succeeds; each failure must free everything and leave the
     * outputs untouched. */
    enum { W = 200, H = 100 };
    static float img[W * H];
    static unsigned char enc[W * H * 4 + 64];
    char path[128], fifo[128];
    size_t written, i;
    int pass;
    for (i = 0; i < (size_t)(W * H); i++) img[i] = (float)i * 0.5f - 100.0f;
    CHECK_EQ_STATUS(hfvis_pfm_encode(img, W, H, 1, W, enc, sizeof enc, &written), HFVIS_OK);
    CHECK(write_bytes(tmp_path(path, sizeof path, "big.pfm"), enc, written));
    CHECK(mkfifo(tmp_path(fifo, sizeof fifo, "fifo"), 0600) == 0);
    for (pass = 0; pass < 2; pass++) {
        long k, successes = 0, failures = 0;
        for (k = 1; k < 100; k++) {
            test_counting state;
            hfvis_allocator a = test_counting_allocator(&state, k);
            float *const px_sentinel = &sentinel_target;
            float *px = px_sentinel;
            hfvis_image_info info;
            hfvis_status s;
            memset(&info, SENTINEL_BYTE, sizeof info);
            s = pass == 0 ? hfvis_image_load(path, &a, &px, &info)
                          : load_through_fifo(fifo, enc, written, &a, &px, &info);
            if (s == HFVIS_OK) {
                successes++;
                CHECK(state.live == 1 && info.width == W && info.height == H);
                CHECK(px != px_sentinel && same_floats(px, img, (size_t)(W * H)));
                hfvis_free(&a, px);
                CHECK(state.live == 0);
                CHECK(state.allocs == 3);
                break;
            }
            failures++;
            CHECK_EQ_STATUS(s, HFVIS_ERR_OUT_OF_MEMORY);
            CHECK(state.live == 0);
            CHECK(px == px_sentinel && all_bytes(&info, sizeof info, SENTINEL_BYTE));
        }
        CHECK(successes == 1 && failures == 3);
    }
    CHECK(remove(path) == 0 && remove(fifo) == 0);
}

/* hfvis_write_options: a zero struct and hfvis_write_options_default() write the same file. */
TEST(files_write_options_default)
{
    static const unsigned char bytes[5] = {1, 2, 3, 4, 5};
    unsigned char a[16], b[16];
    char pa[160], pb[160];
    hfvis_write_options z, d = hfvis_write_options_default();
    memset(&z, 0, sizeof z);
    sprintf(pa, "%s/wz.bin", test_dir);
    sprintf(pb, "%s/wd.bin", test_dir);
    CHECK_EQ_STATUS(hfvis_write_file(pa, bytes, sizeof bytes, &z), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_write_file(pb, bytes, sizeof bytes, &d), HFVIS_OK);
    CHECK(read_bytes(pa, a, sizeof a) == sizeof bytes && read_bytes(pb, b, sizeof b) == sizeof bytes);
    CHECK(memcmp(a, bytes, sizeof bytes) == 0 && memcmp(b, bytes, sizeof bytes) == 0);
    CHECK(remove(pa) == 0 && remove(pb) == 0);
}

TEST(files_teardown)
{
    CHECK(test_dir_entries(test_dir) == 0);
    CHECK(rmdir(test_dir) == 0);
}

/* ========================================================================================== */
/* main: one RUN line per test, grouped by section                                            */
/* ========================================================================================== */

/* ========================================================================================== */
/* Failing-allocator sweep over every allocating height-field routine                         */
/* ========================================================================================== */

#define SWEEP_W 23
#define SWEEP_H 17
#define SWEEP_K 8
static float sweep_z[SWEEP_W * SWEEP_H];
static float sweep_map[SWEEP_K * SWEEP_W * SWEEP_H];
static float sweep_env_radiance[4 * 8 * 3];

static hfvis_grid sweep_grid(void)
{
    hfvis_grid g;
    hfvis_field f;
    memset(&f, 0, sizeof f);
    f.kind = HFVIS_FIELD_FBM;
    f.amplitude = 4.0;
    f.wavelength = 6.0;
    f.seed = 11;
    hfvis_field_generate(&f, SWEEP_W, SWEEP_H, SWEEP_W, sweep_z);
    sweep_z[5 * SWEEP_W + 7] = (float)NAN; /* a hole, so the hole paths run too */
    g = test_grid(sweep_z, SWEEP_W, SWEEP_H, 1.5);
    return g;
}

static hfvis_env sweep_env(void)
{
    hfvis_env e;
    size_t i;
    for (i = 0; i < sizeof sweep_env_radiance / sizeof sweep_env_radiance[0]; i++)
        sweep_env_radiance[i] = 0.25f + 0.01f * (float)(i % 17);
    e.radiance = sweep_env_radiance;
    e.n_theta = 4;
    e.n_phi = 8;
    e.channels = 3;
    return e;
}

/* One allocating call: runs routine r with allocator a, writing into out (capacity floats). */
static hfvis_status sweep_call(int r, const hfvis_allocator *a, float *out)
{
    hfvis_grid g = sweep_grid();
    hfvis_env env = sweep_env();
    hfvis_sweep_options o = hfvis_sweep_options_default();
    hfvis_env_options lp = hfvis_env_options_default();
    lp.method = HFVIS_ENV_LP_TABLE;
    o.alloc = a;
    o.border = (r % 2) ? HFVIS_BORDER_CLAMP : HFVIS_BORDER_OPEN;
    switch (r) {
    case 0: return hfvis_horizon_lattice(&g, 0.7, &o, out);
    case 1: return hfvis_horizon_lattice_naive(&g, 0.7, &o, out);
    case 2: return hfvis_horizon_direction(&g, SWEEP_K, 3, &o, out, SWEEP_W);
    case 3: return hfvis_horizon_map(&g, SWEEP_K, &o, out);
    case 4: return hfvis_sky_light(&g, SWEEP_K, 1.0f, 0.5f, &o, out, SWEEP_W);
    case 5: return hfvis_sky_light_from_map(&g, SWEEP_K, 0.0, sweep_map, 1.0f, 1.0f, a, out, SWEEP_W);
    case 6: return hfvis_sky_view_factor(&g, SWEEP_K, &o, out, SWEEP_W);
    case 7: return hfvis_sun_visibility(&g, 1.0, 0.3, 0.01, &o, out, SWEEP_W);
    case 8: return hfvis_env_light(&g, SWEEP_K, &env, 1.0f, &o, NULL, out, SWEEP_W);
    case 9: return hfvis_env_light(&g, SWEEP_K, &env, 1.0f, &o, &lp, out, SWEEP_W);
    case 10: return hfvis_env_light_from_map(&g, SWEEP_K, 0.0, sweep_map, &env, 1.0f, &lp, a, out, SWEEP_W);
    default: return HFVIS_ERR_INVALID_ARGUMENT;
    }
}
#define SWEEP_ROUTINES 11
#define SWEEP_OUT_FLOATS (SWEEP_K * SWEEP_W * SWEEP_H * 4)

TEST(sweeps_failing_allocator)
{
    static float out[SWEEP_OUT_FLOATS];
    hfvis_grid g = sweep_grid();
    int r;
    CHECK_EQ_STATUS(hfvis_horizon_map(&g, SWEEP_K, NULL, sweep_map), HFVIS_OK);
    for (r = 0; r < SWEEP_ROUTINES; r++) {
        test_counting state;
        hfvis_allocator a = test_counting_allocator(&state, 0);
        long total, k;
        /* Count the allocations of a successful call; each must be released. */
        CHECK_EQ_STATUS(sweep_call(r, &a, out), HFVIS_OK);
        total = state.allocs;
        CHECK(total >= 1);
        CHECK(state.live == 0);
        /* Fail allocation k for every k: HFVIS_ERR_OUT_OF_MEMORY, nothing leaked, output untouched. */
        for (k = 1; k <= total; k++) {
            hfvis_allocator f = test_counting_allocator(&state, k);
            memset(out, SENTINEL_BYTE, sizeof out);
            CHECK_EQ_STATUS(sweep_call(r, &f, out), HFVIS_ERR_OUT_OF_MEMORY);
            CHECK(state.live == 0);
            CHECK(all_bytes(out, sizeof out, SENTINEL_BYTE));
        }
    }
}

TEST(oracles_allocate_nothing)
{
    /* The ray-march and hemisphere oracles are documented as allocation-free: an allocator that
     * fails every call must not change their result. */
    hfvis_grid g = sweep_grid();
    test_counting state;
    hfvis_allocator a = test_counting_allocator(&state, 1);
    hfvis_sweep_options o = hfvis_sweep_options_default();
    float pts[4] = {3.0f, 4.0f, 10.5f, 8.25f}, nrm[6] = {0, 0, 1, 0, 0, 1}, out[2 * SWEEP_K], ref[2 * SWEEP_K];
    o.alloc = &a;
    CHECK_EQ_STATUS(hfvis_horizon_reference(&g, SWEEP_K, &o, NULL, pts, 2, out), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_horizon_reference(&g, SWEEP_K, NULL, NULL, pts, 2, ref), HFVIS_OK);
    CHECK(memcmp(out, ref, sizeof out) == 0);
    CHECK_EQ_STATUS(hfvis_light_reference(&g, NULL, 1.0f, &o, NULL, NULL, pts, nrm, 2, out), HFVIS_OK);
    CHECK(state.allocs == 0);
}

/* The options added with 0.2.0's *_options_default(): a zero struct (the documented defaults)
 * and the filled-in defaults give bit-identical results on one call each. */
TEST(options_default_equals_zero)
{
    static float a[SWEEP_K * SWEEP_W * SWEEP_H], b[SWEEP_K * SWEEP_W * SWEEP_H];
    hfvis_grid g = sweep_grid();
    float pts[4] = {3.0f, 4.0f, 10.5f, 8.25f}, nrm[6] = {0, 0, 1, 0, 0, 1};
    hfvis_march_options mz, md = hfvis_march_options_default();
    hfvis_openness_options oz, od = hfvis_openness_options_default();
    hfvis_hemisphere_options hz, hd = hfvis_hemisphere_options_default();
    hfvis_tree_options tz, td = hfvis_tree_options_default();
    hfvis_viewshed_options vz, vd = hfvis_viewshed_options_default();
    memset(&mz, 0, sizeof mz);
    memset(&oz, 0, sizeof oz);
    memset(&hz, 0, sizeof hz);
    memset(&tz, 0, sizeof tz);
    memset(&vz, 0, sizeof vz);
    memset(a, 0, sizeof a);
    memset(b, 0xff, sizeof b);
    CHECK_EQ_STATUS(hfvis_horizon_reference(&g, SWEEP_K, NULL, &mz, pts, 2, a), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_horizon_reference(&g, SWEEP_K, NULL, &md, pts, 2, b), HFVIS_OK);
    CHECK(memcmp(a, b, 2 * SWEEP_K * sizeof(float)) == 0);
    od.radius = oz.radius = 5.0; /* the marching path, where step_cells applies */
    CHECK_EQ_STATUS(hfvis_openness(&g, SWEEP_K, &oz, NULL, a, SWEEP_W), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_openness(&g, SWEEP_K, &od, NULL, b, SWEEP_W), HFVIS_OK);
    CHECK(memcmp(a, b, SWEEP_W * SWEEP_H * sizeof(float)) == 0);
    CHECK_EQ_STATUS(hfvis_light_reference(&g, NULL, 1.0f, NULL, NULL, &hz, pts, nrm, 2, a), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_light_reference(&g, NULL, 1.0f, NULL, NULL, &hd, pts, nrm, 2, b), HFVIS_OK);
    CHECK(memcmp(a, b, 2 * sizeof(float)) == 0);
    CHECK_EQ_STATUS(hfvis_visibility_count(&g, SWEEP_K, NULL, &tz, a, SWEEP_W, NULL), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_visibility_count(&g, SWEEP_K, NULL, &td, b, SWEEP_W, NULL), HFVIS_OK);
    CHECK(memcmp(a, b, SWEEP_W * SWEEP_H * sizeof(float)) == 0);
    CHECK_EQ_STATUS(hfvis_viewshed(&g, 11.0, 8.0, &vz, a, SWEEP_W), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_viewshed(&g, 11.0, 8.0, &vd, b, SWEEP_W), HFVIS_OK);
    CHECK(memcmp(a, b, SWEEP_W * SWEEP_H * sizeof(float)) == 0);
}

/* An allocator with free but no alloc: every block came from HFVIS_MALLOC, so the library
 * frees it with HFVIS_FREE and never hands it to free (ssao.c and voxel.c once did: a mesh
 * from hfvis_mesh_box went to the caller's free). */
static long api_foreign_frees;
static void api_count_free(void *user, void *p)
{
    (void)user;
    (void)p;
    api_foreign_frees++;
}
TEST(allocator_free_without_alloc)
{
    static const double lo[3] = {0, 0, 0}, hi[3] = {1, 2, 3};
    hfvis_allocator a;
    hfvis_mesh m;
    hfvis_ffao_table t;
    hfvis_falloff q;
    hfvis_sweep_options so = hfvis_sweep_options_default();
    float z[16 * 16], out[16 * 16];
    hfvis_grid g;
    int i;
    a.alloc = NULL;
    a.free = api_count_free;
    a.user = NULL;
    api_foreign_frees = 0;
    CHECK_EQ_STATUS(hfvis_mesh_box(&a, lo, hi, &m), HFVIS_OK);
    hfvis_mesh_free(&a, &m);
    memset(&q, 0, sizeof q);
    q.kind = HFVIS_FALLOFF_INV_QUADRATIC;
    q.param = 1.0;
    CHECK_EQ_STATUS(hfvis_ffao_table_build(&q, 4, 4, 2, 3, 0.0, &a, &t), HFVIS_OK);
    hfvis_ffao_table_free(&t);
    for (i = 0; i < 16 * 16; i++) z[i] = (float)(i % 7);
    g.z = z; g.width = 16; g.height = 16; g.stride = 16; g.cell_size = 1.0;
    so.alloc = &a;
    CHECK_EQ_STATUS(hfvis_sky_view_factor(&g, 8, &so, out, 16), HFVIS_OK);
    CHECK(api_foreign_frees == 0);
}

/* The names 0.2.0 renamed still compile and call the new functions (hfvis.h, "Deprecated
 * names"). */
TEST(deprecated_names)
{
    hfvis_lattice L;
    hfvis_volume_grid vg;
    CHECK_EQ_STATUS(hfvis_lattice_init(&L, 5, 4, 0.3), HFVIS_OK);
    CHECK(hfvis_lattice_size(&L) == hfvis_lattice_nodes(&L) && hfvis_lattice_size(&L) > 0);
    CHECK(hfvis_env_table_size(NULL, 4, NULL) == 0);
    memset(&vg, 0, sizeof vg);
    vg.dims[0] = vg.dims[1] = vg.dims[2] = 2;
    vg.cell[0] = vg.cell[1] = vg.cell[2] = 1.0;
    CHECK(hfvis_volume_size(&vg, 2) == 16 && hfvis_volume_floats(&vg, 2) == 16);
    CHECK_EQ_STATUS(hfvis_ssao_raytrace(NULL, NULL, NULL, NULL, NULL, 0), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_lk_raycast(NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
}

int main(int argc, char **argv)
{
    TEST_INIT(argc, argv);
    RUN(allocator_free_without_alloc);
    /* Status strings */
    RUN(status_strings);
    /* Codecs in memory */
    RUN(pfm_encode_decode_grey_and_rgb);
    RUN(pfm_decode_both_byte_orders);
    RUN(pfm_header_spellings);
    RUN(pgm_decode_ascii_and_binary);
    RUN(pgm_encode_mapping);
    RUN(pgm_range_nodata_round_trip);
    RUN(codec_round_trip_integers);
    RUN(codec_truncated_at_every_length);
    RUN(codec_bad_magic);
    RUN(codec_bad_header);
    RUN(codec_limits);
    RUN(codec_bad_samples);
    RUN(codec_buffer_too_small_and_null);
    RUN(codec_encode_errors);
    /* Codec files */
    RUN(files_setup);
    RUN(files_save_and_load);
    RUN(files_errors);
    RUN(files_header_first);
    RUN(files_load_failing_allocator);
    RUN(files_write_options_default);
    RUN(files_teardown);
    /* Height-field routines */
    RUN(sweeps_failing_allocator);
    RUN(oracles_allocate_nothing);
    RUN(options_default_equals_zero);
    RUN(deprecated_names);
    return TEST_DONE();
}
