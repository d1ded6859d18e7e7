/* png_write.h - the smallest PNG writer the examples need (PNG spec, ISO/IEC 15948:2003; zlib
 * RFC 1950; deflate RFC 1951): 8- or 16-bit greyscale and 8-bit RGB, no interlace, every row
 * filter type 0, one IDAT chunk holding a zlib stream of STORED (uncompressed) deflate blocks.
 * The files are as large as the pixels (plus 11 bytes per 65535), which is the price of no
 * compressor. Checksums and the atomic file write come from zio.h. Header-only, every function static inline; it prints nothing (common.h reports
 * failures) and keeps no state. The library itself stays PFM/PGM: this file belongs to the
 * examples. */
#ifndef HFVIS_EXAMPLES_PNG_H
#define HFVIS_EXAMPLES_PNG_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hfvis.h"
#include "zio.h"

/* A PNG chunk length is at most 2^31 - 1 (PNG §5.3), and the whole zlib stream goes in one IDAT
 * chunk: images whose stream would be longer are refused with HFVIS_ERR_LIMIT (about 2 GB). */
#define EX_PNG_MAX_CHUNK 0x7fffffffu
/* A stored deflate block holds at most 65535 bytes (RFC 1951 §3.2.4: LEN is 16 bits). */
#define EX_PNG_MAX_STORED 65535u

/* The chunk CRC of PNG Annex D is the library's hfvis_crc32 (ISO-HDLC, reflected 0xEDB88320);
 * Adler-32 is zio.h's ex_adler32. */

/* Bytes per row of samples (no filter byte), the zlib stream length and the file size of a
 * width x height PNG with channels 1 (grey) or 3 (RGB) and depth 8 or 16 (16 only for grey).
 * HFVIS_ERR_INVALID_ARGUMENT for other values, non-positive or size_t-overflowing sizes;
 * HFVIS_ERR_LIMIT when the zlib stream exceeds one chunk. Any out-pointer may be NULL. */
static inline hfvis_status ex_png_layout(int width, int height, int channels, int depth,
                                         size_t *row_bytes, size_t *zlib_bytes, size_t *file_bytes)
{
    size_t row, raw, blocks, z;
    if (width <= 0 || height <= 0 || !((channels == 1 && (depth == 8 || depth == 16)) ||
                                       (channels == 3 && depth == 8)))
        return HFVIS_ERR_INVALID_ARGUMENT;
    row = (size_t)width;
    if (row > SIZE_MAX / (size_t)(channels * depth / 8)) return HFVIS_ERR_INVALID_ARGUMENT;
    row *= (size_t)(channels * depth / 8);
    /* raw = height * (1 + row): each row is preceded by its filter-type byte */
    if (row == SIZE_MAX || row + 1 > SIZE_MAX / (size_t)height) return HFVIS_ERR_INVALID_ARGUMENT;
    raw = (row + 1) * (size_t)height;
    blocks = raw / EX_PNG_MAX_STORED + (raw % EX_PNG_MAX_STORED != 0);
    /* zlib: 2-byte header, 5 bytes (header, LEN, NLEN) per stored block, 4-byte Adler-32 */
    if (blocks > (SIZE_MAX - 6) / 5 || raw > SIZE_MAX - 6 - 5 * blocks) return HFVIS_ERR_INVALID_ARGUMENT;
    z = 2 + 5 * blocks + raw + 4;
    if (z > EX_PNG_MAX_CHUNK) return HFVIS_ERR_LIMIT;
    if (row_bytes) *row_bytes = row;
    if (zlib_bytes) *zlib_bytes = z;
    /* signature 8, IHDR 12 + 13, IDAT 12 + z, IEND 12 (z < 2^31: no overflow) */
    if (file_bytes) *file_bytes = 8 + 25 + 12 + z + 12;
    return HFVIS_OK;
}

static inline unsigned char *ex_png__be32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)(v >> 24);
    p[1] = (unsigned char)(v >> 16);
    p[2] = (unsigned char)(v >> 8);
    p[3] = (unsigned char)v;
    return p + 4;
}

/* Chunk = length, type, data, CRC over type and data (PNG §5.3). The data is already at p + 8. */
static inline unsigned char *ex_png__chunk(unsigned char *p, const char type[4], size_t n)
{
    ex_png__be32(p, (uint32_t)n);
    memcpy(p + 4, type, 4);
    return ex_png__be32(p + 8 + n, hfvis_crc32(0, p + 4, 4 + n));
}

/* The deflate writer: copies the filtered scanlines into stored blocks of at most 65535 bytes,
 * opening a block (BFINAL on the last, BTYPE 00, LEN, NLEN) whenever the previous one is full. */
typedef struct {
    unsigned char *p;
    size_t block_left, total_left;
    uint32_t adler;
} ex_png__deflate;

static inline void ex_png__stored(ex_png__deflate *z, const unsigned char *src, size_t n)
{
    while (n > 0) {
        size_t k;
        if (z->block_left == 0) {
            size_t len = z->total_left < EX_PNG_MAX_STORED ? z->total_left : EX_PNG_MAX_STORED;
            z->p[0] = (unsigned char)(len == z->total_left); /* BFINAL in bit 0, BTYPE 00 */
            z->p[1] = (unsigned char)(len & 0xffu);
            z->p[2] = (unsigned char)(len >> 8);
            z->p[3] = (unsigned char)(~len & 0xffu);
            z->p[4] = (unsigned char)((~len >> 8) & 0xffu);
            z->p += 5;
            z->block_left = len;
        }
        k = n < z->block_left ? n : z->block_left;
        memcpy(z->p, src, k);
        z->adler = ex_adler32(z->adler, src, k);
        z->p += k;
        src += k;
        n -= k;
        z->block_left -= k;
        z->total_left -= k;
    }
}

/* Encode samples (height rows of row_bytes, see ex_png_layout; 16-bit samples big-endian, RGB
 * interleaved) as a PNG into out (capacity bytes); *written = the file size. Fails with
 * HFVIS_ERR_BUFFER_TOO_SMALL when capacity is short, and then writes nothing. */
static inline hfvis_status ex_png_encode(const unsigned char *samples, int width, int height,
                                         int channels, int depth, unsigned char *out,
                                         size_t capacity, size_t *written)
{
    static const unsigned char signature[8] = { 137, 80, 78, 71, 13, 10, 26, 10 };
    static const unsigned char filter_none = 0;
    size_t row, zbytes, total;
    ex_png__deflate z;
    unsigned char *p = out, *idat;
    int y;
    hfvis_status s = ex_png_layout(width, height, channels, depth, &row, &zbytes, &total);
    if (s != HFVIS_OK) return s;
    if (!samples || !out || !written) return HFVIS_ERR_INVALID_ARGUMENT;
    if (capacity < total) return HFVIS_ERR_BUFFER_TOO_SMALL;
    memcpy(p, signature, 8);
    p += 8;
    /* IHDR: width, height, bit depth, colour type (0 grey, 2 RGB), deflate, filter set 0, no interlace */
    ex_png__be32(p + 8, (uint32_t)width);
    ex_png__be32(p + 12, (uint32_t)height);
    p[16] = (unsigned char)depth;
    p[17] = (unsigned char)(channels == 3 ? 2 : 0);
    p[18] = p[19] = p[20] = 0;
    p = ex_png__chunk(p, "IHDR", 13);
    /* IDAT: zlib header CMF 0x78 (deflate, 32 KiB window), FLG 0x01 (no dictionary, level 0,
     * FCHECK making 0x7801 a multiple of 31), the stored blocks, then Adler-32 big-endian */
    idat = p;
    p += 8;
    p[0] = 0x78;
    p[1] = 0x01;
    z.p = p + 2;
    z.block_left = 0;
    z.total_left = (row + 1) * (size_t)height;
    z.adler = 1;
    for (y = 0; y < height; y++) {
        ex_png__stored(&z, &filter_none, 1);
        ex_png__stored(&z, samples + (size_t)y * row, row);
    }
    ex_png__be32(z.p, z.adler);
    p = ex_png__chunk(idat, "IDAT", zbytes);
    p = ex_png__chunk(p, "IEND", 0);
    *written = (size_t)(p - out);
    return HFVIS_OK;
}

/* Write n bytes to path atomically: the library's hfvis_write_file (a temporary file beside
 * path renamed onto it; on failure path is untouched and nothing is left). */
static inline hfvis_status ex_png_write_file(const char *path, const unsigned char *bytes, size_t n)
{
    return hfvis_write_file(path, bytes, n, NULL);
}

/* One sample of [lo, hi] on 0..top, as hfvis_pgm_encode maps it: values outside clamp, NaN and
 * infinities -> 0, rounded to nearest. */
static inline unsigned ex_png_quantize(float v, double lo, double range, unsigned top)
{
    double t = ((double)v - lo) / range * (double)top;
    if (!isfinite(v) || !(t > 0.0)) return 0;
    if (t >= (double)top) return top;
    return (unsigned)round(t);
}

/* Save width x height pixels (channels 1 or 3 floats each, interleaved; stride in pixels) as the
 * PNG path, mapping [lo, hi] to 0..2^depth - 1 per channel (depth 16 only with channels 1).
 * HFVIS_ERR_INVALID_ARGUMENT for bad sizes, NULL, stride < width or not lo < hi (both finite);
 * the file is written atomically (ex_png_write_file). Prints nothing. */
static inline hfvis_status ex_png_save(const char *path, const float *pixels, int width, int height,
                                       ptrdiff_t stride, int channels, int depth, float lo, float hi)
{
    size_t row, total, written = 0, x;
    unsigned char *samples, *file;
    unsigned top = depth == 16 ? 65535u : 255u;
    double range = (double)hi - (double)lo;
    hfvis_status s = ex_png_layout(width, height, channels, depth, &row, NULL, &total);
    int y;
    if (s != HFVIS_OK) return s;
    /* the last row starts (height - 1) stride channels floats in: that must be addressable */
    if (!path || !pixels || stride < width || !isfinite(lo) || !isfinite(hi) || !(lo < hi) ||
        (size_t)stride > ((size_t)PTRDIFF_MAX / (size_t)channels) / (size_t)height)
        return HFVIS_ERR_INVALID_ARGUMENT;
    samples = (unsigned char *)malloc(row * (size_t)height);
    file = (unsigned char *)malloc(total);
    if (!samples || !file) {
        free(samples);
        free(file);
        return HFVIS_ERR_OUT_OF_MEMORY;
    }
    for (y = 0; y < height; y++) {
        const float *src = pixels + (size_t)y * (size_t)stride * (size_t)channels;
        unsigned char *dst = samples + (size_t)y * row;
        for (x = 0; x < (size_t)width * (size_t)channels; x++) {
            unsigned q = ex_png_quantize(src[x], (double)lo, range, top);
            if (depth == 16) *dst++ = (unsigned char)(q >> 8);
            *dst++ = (unsigned char)(q & 0xffu);
        }
    }
    s = ex_png_encode(samples, width, height, channels, depth, file, total, &written);
    if (s == HFVIS_OK) s = ex_png_write_file(path, file, written);
    free(samples);
    free(file);
    return s;
}

#endif /* HFVIS_EXAMPLES_PNG_H */
