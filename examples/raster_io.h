/* raster_io.h - GIS rasters for the hfvis tool: GeoTIFF (classic TIFF 6.0 and BigTIFF) read and
 * write, ESRI ASCII grids (.asc + .prj) and raw EHdr grids (.bil/.flt + .hdr) read and write, with
 * the georeference and NoData carried from input to output. Header-only, every function static
 * inline, pure C99, no dependency beyond zio.h (inflate/deflate, checksums, atomic files); the
 * hfvis library itself stays PFM/PGM. Prints nothing: a failing call returns -1 with a one-line
 * reason in the reader's err[] (or the caller's err buffer for writers).
 *
 * Reading is by window: ex_rio_read(r, band, x0, y0, w, h, ...) decodes only the TIFF strips or
 * tiles (or raw rows) that the window touches, by seeking, so a caller can process a raster larger
 * than memory piece by piece with a halo; cells of the window outside the raster come back NaN.
 *
 * Supported (read):
 *   TIFF     little and big endian, classic and BigTIFF, strips or tiles, PlanarConfiguration 1
 *            (chunky) or 2 (planar), any band; compression none (1), LZW (5), DEFLATE (8, 32946),
 *            PackBits (32773); Predictor 1, 2 (horizontal) and 3 (floating point); unsigned and
 *            signed 8/16/32-bit integers, 32/64-bit floats.
 *   GeoTIFF  ModelPixelScale 33550, ModelTiepoint 33922, ModelTransformation 34264,
 *            GeoKeyDirectory 34735 + GeoDoubleParams 34736 + GeoAsciiParams 34737 (GeoTIFF 1.1,
 *            OGC 19-008r4), GDAL_NODATA 42113.
 *   ASC      ncols nrows xllcorner|xllcenter yllcorner|yllcenter cellsize (or dx dy)
 *            [NODATA_value], rows north to south; the .prj beside it as text.
 *   EHdr     .hdr with NROWS NCOLS [NBANDS NBITS PIXELTYPE BYTEORDER LAYOUT SKIPBYTES
 *            BANDROWBYTES TOTALROWBYTES BANDGAPBYTES ULXMAP ULYMAP XDIM YDIM NODATA], or the ESRI
 *            .flt header (ncols nrows xllcorner yllcorner cellsize NODATA_value byteorder).
 * Refused with a message naming the feature: JPEG and every other compression, palette and
 * YCbCr images, bit depths other than 8/16/32/64, 16-bit floats, old-style LZW, a first IFD
 * whose chain loops.
 * Written: TIFF (Float32 or an integer type, tiled or striped, uncompressed or DEFLATE with
 * optional predictor 2/3, either byte order, BigTIFF when the file would pass 4 GiB), ASC and
 * EHdr; several bands as a planar TIFF, a BIL, or (ASC) refused.
 *
 * Contents
 *   1. types and limits        ex_georef, ex_rio_reader, ex_rio_image, ex_rio_write_options
 *   2. georeference            ex_georef_free, ex_georef_cell, GeoKey parsing, a .prj's WKT as
 *                              GeoKeys (ex_rio_prj_geokeys) and an ESRI PE string as a .prj
 *   3. byte sources            memory or FILE, bounded reads
 *   4. TIFF structure          header, IFD walk, tags, layout checks
 *   5. TIFF chunk decoding     PackBits, LZW, DEFLATE, predictors, samples
 *   6. ASC and EHdr parsing
 *   7. reading                 ex_rio_open, ex_rio_open_tiff_mem, ex_rio_open_asc_mem,
 *                              ex_rio_open_ehdr_mem, ex_rio_open_netpbm(_mem), ex_rio_read,
 *                              ex_rio_read_parallel (row parts over a caller's threads),
 *                              ex_rio_close, ex_georef_shift
 *   8. writing                 ex_rio_write (by extension), ex_rio_write_tiff_file
 */
#ifndef HFVIS_EXAMPLES_RASTER_IO_H
#define HFVIS_EXAMPLES_RASTER_IO_H

#include <ctype.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "zio.h"

/* ------------------------------------------------------------------------------------------ */
/* 1. types and limits                                                                        */
/* ------------------------------------------------------------------------------------------ */

/* Decoded bytes of one strip or tile: larger ones are refused before anything is allocated. */
#define EX_RIO_MAX_CHUNK ((uint64_t)1 << 30)
/* Strips or tiles per image: 2^24 covers a 10^5 x 10^5 raster in 64 x 64 tiles. */
#define EX_RIO_MAX_CHUNKS ((uint64_t)1 << 24)
/* Rows and columns of any raster (TIFF allows 2^32 - 1; ints index the windows). */
#define EX_RIO_MAX_DIM 0x7fffffff
/* Entries of one IFD, IFDs followed along the chain (a longer chain is taken as a loop), and
 * the longest GeoKey directory, GeoDoubleParams, GeoAsciiParams or ModelTiepoint array kept. */
#define EX_RIO_MAX_ENTRIES 4096
#define EX_RIO_MAX_IFDS 4096
#define EX_RIO_MAX_GEO 65536
/* Bands of one image (SamplesPerPixel is 16 bits). */
#define EX_RIO_MAX_BANDS 65535
/* Largest decoded-to-compressed ratio each codec can reach, plus slack (a strip claiming more
 * than this cannot be valid and is refused before its buffer is allocated): deflate's longest
 * match code is 258 bytes from about 2 bits (1032:1); one 9..12-bit LZW code yields at most
 * 4096 bytes; PackBits turns 2 bytes into 128. */
#define EX_RIO_RATIO_DEFLATE 1040u
#define EX_RIO_RATIO_LZW 4100u
#define EX_RIO_RATIO_PACKBITS 64u
/* The longest header line an ASC or EHdr header may have, and header bytes read. */
#define EX_RIO_MAX_HEADER 65536

enum { EX_RIO_UINT = 1, EX_RIO_INT = 2, EX_RIO_FLOAT = 3 };           /* TIFF SampleFormat */
enum { EX_RIO_TIFF = 1, EX_RIO_ASC = 2, EX_RIO_EHDR = 3,             /* formats */
       EX_RIO_NETPBM = 4 }; /* PFM or binary PGM, opened by ex_rio_open_netpbm only */
enum { EX_RIO_CRS_UNKNOWN = 0, EX_RIO_CRS_PROJECTED = 1, EX_RIO_CRS_GEOGRAPHIC = 2,
       EX_RIO_CRS_GEOCENTRIC = 3 };

/* Where the cells are and what is missing. gt is GDAL's geotransform of the cell corners:
 * x = gt[0] + col gt[1] + row gt[2], y = gt[3] + col gt[4] + row gt[5]. The GeoTIFF tags and
 * the .prj text are kept verbatim so that a written file carries them unchanged. */
typedef struct {
    int has_transform;
    double gt[6];
    int has_nodata;
    double nodata;
    char nodata_text[64];    /* as the input spelled it (GDAL_NODATA, NODATA_value) */
    int crs;                 /* EX_RIO_CRS_* from GTModelTypeGeoKey or the .prj */
    int epsg;                /* ProjectedCSTypeGeoKey or GeographicTypeGeoKey; 0 unknown */
    int pixel_is_point;      /* GTRasterTypeGeoKey = 2 */
    /* The file's orientation: its columns run west (flip_x) or its rows north (flip_y), as a
     * negative pixel width or a positive pixel height say (a ModelTransformation, a negative
     * ModelPixelScale, a negative EHdr YDIM). gt and ex_rio_read always give the raster
     * north-up, west to east; a GeoTIFF written with these flags set stores it back in the
     * file's orientation (its ModelTransformation says so), an ASC or EHdr north-up. */
    int flip_x, flip_y;
    /* the TIFF tags, verbatim (NULL/0 when absent) */
    int has_scale, has_matrix;
    double scale[3], matrix[16];
    double *tiepoints;
    size_t n_tiepoints;
    uint16_t *geokeys;
    size_t n_geokeys;
    double *geodoubles;
    size_t n_geodoubles;
    char *geoascii;
    size_t n_geoascii;
    char *prj;               /* the WKT of a .prj file, NUL-terminated */
} ex_georef;

typedef struct {
    /* the raster */
    int format, width, height, bands, kind, bits; /* kind: EX_RIO_UINT/INT/FLOAT */
    ex_georef geo;
    int nodata_to_nan;       /* set before ex_rio_read: cells equal to the NoData value -> NaN */
    char err[256];
    /* the source */
    FILE *f;
    const unsigned char *mem;
    uint64_t size;
    /* TIFF layout */
    int big_endian, bigtiff, compression, predictor, planar, tiled, photometric;
    uint32_t chunk_w, chunk_h;
    uint64_t across, down, nchunks, *offsets, *counts;
    /* raw (EHdr) layout: byte of (band, row, col) = skip + row * row_bytes + band * band_bytes
     * + col * col_bytes */
    uint64_t skip, row_bytes, band_bytes, col_bytes;
    int rows_up;             /* raw rows stored bottom to top (PFM): file row = height - 1 - row */
    double maxval;           /* a PGM's largest sample value (ex_rio_read gives 0..maxval); 0 else */
    /* ASC: the whole grid, as parsed (NoData is matched at read time) */
    double *grid;
    /* decoding buffers and the chunk decoded last */
    unsigned char *cbuf, *dbuf;
    size_t cbuf_cap, dbuf_cap;
    uint64_t cached;         /* index + 1 of the chunk in dbuf, 0 none */
    int cached_be;           /* its samples are big-endian (after predictor 3) */
} ex_rio_reader;

/* One metadata item of a written GeoTIFF (GDAL_METADATA, TIFF tag 42112, as GDAL writes and
 * gdalinfo shows it): band 0 = the dataset's, band b >= 1 = band b's. */
typedef struct {
    const char *name, *value;
    int band;
} ex_rio_meta;

/* Write options; zero = defaults (striped, uncompressed, Float32, little endian, BigTIFF only
 * when needed, no metadata). */
typedef struct {
    int kind, bits;          /* sample type: 0/0 = Float32; EX_RIO_UINT/INT with 8/16/32 bits */
    int tiled, tile_size;    /* tile_size: a multiple of 16, default 256 */
    int rows_per_strip;      /* default: rows of about 64 KiB */
    int deflate, predictor;  /* predictor 2 (integers) or 3 (floats) with deflate */
    int big_endian, bigtiff; /* bigtiff: 1 always, 0 when the file would pass 4 GiB */
    /* GeoTIFF only, in GDAL_METADATA: band_names (NULL, or one per band, NULL entries skipped)
     * become the bands' descriptions, unit (NULL or "") every band's unit type, meta[0..n_meta)
     * dataset and band items */
    const char *const *band_names;
    const char *unit;
    const ex_rio_meta *meta;
    int n_meta;
    /* Optional: run fn(ctx, i) for every i in [0, n), in any order or at once (each call writes
     * only its own memory); 0 when every call returned 0. NULL: in order on the calling thread.
     * The writer encodes and compresses its strips or tiles through it, EX_RIO_WRITE_BATCH at a
     * time, and writes them in order: the file's bytes do not depend on it. */
    int (*parallel)(void *user, size_t n, int (*fn)(void *ctx, size_t i), void *ctx);
    void *parallel_user;
} ex_rio_write_options;

/* Cells to write: sample (band b, column x, row y) = data[b band_step + y row_step + x
 * pixel_step] (in floats), so both stacked planes and interleaved channels fit. */
typedef struct {
    const float *data;
    int width, height, bands;
    size_t band_step, row_step, pixel_step;
} ex_rio_image;

static inline int ex_rio_fail(char *err, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, 256, fmt, ap);
    va_end(ap);
    return -1;
}

/* ------------------------------------------------------------------------------------------ */
/* 2. georeference                                                                            */
/* ------------------------------------------------------------------------------------------ */

static inline void ex_georef_free(ex_georef *g)
{
    free(g->tiepoints);
    free(g->geokeys);
    free(g->geodoubles);
    free(g->geoascii);
    free(g->prj);
    memset(g, 0, sizeof *g);
}

/* The cell size of a north-up raster with square cells: 0 and *cell set; -1 with a reason when
 * there is no transform, it is rotated or sheared, or its cells are not square (relative
 * difference over 1e-9, float noise of a written decimal). */
static inline int ex_georef_cell(const ex_georef *g, double *cell, char *err)
{
    double dx, dy;
    if (!g->has_transform) return ex_rio_fail(err, "no georeference (no cell size)");
    if (g->gt[2] != 0.0 || g->gt[4] != 0.0)
        return ex_rio_fail(err, "a rotated or sheared geotransform is not supported (square, "
                           "north-up cells are needed): warp it with gdalwarp first");
    dx = g->gt[1];
    dy = -g->gt[5]; /* the readers give every raster north-up (ex_georef_orient) */
    if (!(dx > 0.0) || !(dy > 0.0) || !isfinite(dx) || !isfinite(dy))
        return ex_rio_fail(err, "invalid cell size %g x %g", g->gt[1], g->gt[5]);
    if (fabs(dx - dy) > 1e-9 * dx)
        return ex_rio_fail(err, "cells of %.10g x %.10g are not square: resample with "
                           "gdalwarp -tr S S first", dx, dy);
    *cell = dx;
    return 0;
}

/* CRS kind of a WKT: GEOGCS/GEOGCRS at the top = geographic, PROJCS/PROJCRS = projected. */
static inline int ex_rio_wkt_crs(const char *p)
{
    while (p && isspace((unsigned char)*p)) p++;
    if (!p) return EX_RIO_CRS_UNKNOWN;
    if (!strncmp(p, "PROJCS", 6) || !strncmp(p, "PROJCRS", 7)) return EX_RIO_CRS_PROJECTED;
    if (!strncmp(p, "GEOGCS", 6) || !strncmp(p, "GEOGCRS", 7) || !strncmp(p, "GEODCRS", 7))
        return EX_RIO_CRS_GEOGRAPHIC;
    return EX_RIO_CRS_UNKNOWN;
}

/* The WKT that GeoAsciiParams carries as "ESRI PE String = WKT|" (how ArcGIS, and hfvis for a
 * .prj, write a CRS that has no EPSG code into a GeoTIFF), and its length; NULL if none. */
static inline const char *ex_rio_pe_string(const ex_georef *g, size_t *len)
{
    static const char tag[] = "ESRI PE String = ";
    const char *a = g->geoascii, *p, *end;
    size_t n = g->n_geoascii;
    if (!a || n < sizeof tag) return NULL;
    for (p = a; (size_t)(p - a) + sizeof tag - 1 <= n; p++) {
        if (memcmp(p, tag, sizeof tag - 1) != 0) continue;
        p += sizeof tag - 1;
        for (end = p; (size_t)(end - a) < n && *end != '|' && *end != '\0'; end++) {}
        *len = (size_t)(end - p);
        return *len ? p : NULL;
    }
    return NULL;
}

/* The EPSG code a WKT names for itself, AUTHORITY["EPSG","n"] (WKT 1) or ID["EPSG",n] (WKT 2)
 * directly inside its outermost node (codes deeper in name its parts: datum, unit); 0 if none. */
static inline int ex_rio_wkt_epsg(const char *w)
{
    int depth = 0, quoted = 0;
    const char *p;
    for (p = w; *p; p++) {
        if (*p == '"') quoted = !quoted; /* WKT doubles a quote inside a string: toggles twice */
        if (quoted || *p == '"') continue;
        if (*p == '[' || *p == '(') depth++;
        else if (*p == ']' || *p == ')') depth--;
        else if (depth == 1 && (p == w || !isalpha((unsigned char)p[-1])) &&
                 (!strncmp(p, "AUTHORITY[", 10) || !strncmp(p, "ID[", 3))) {
            const char *q = strchr(p, '[') + 1;
            char *end;
            long v;
            while (isspace((unsigned char)*q)) q++;
            if (strncmp(q, "\"EPSG\"", 6) != 0) continue;
            for (q += 6; isspace((unsigned char)*q) || *q == ','; q++) {}
            if (*q == '"') q++;
            v = strtol(q, &end, 10);
            if (end != q && v > 0 && v < 32767) return (int)v;
        }
    }
    return 0;
}

/* The longest WKT put into a citation: GDAL reads PCSCitationGeoKey into a 2400-byte buffer. */
#define EX_RIO_MAX_PE_STRING 2300

/* GeoKeys for a GeoTIFF of a raster whose CRS is the WKT of a .prj (GeoTIFF 1.1 §7.1): the
 * model (projected or geographic) and PixelIsArea, and the EPSG code the WKT names for itself in
 * ProjectedCSTypeGeoKey or GeographicTypeGeoKey; a WKT without one goes whole into
 * PCSCitationGeoKey as "ESRI PE String = WKT" under a user-defined model (32767), the form
 * ArcGIS writes and GDAL reads. Fills keys[16] and, for the citation, *ascii (malloc'd,
 * *n_ascii bytes with the NUL); returns the number of shorts, 0 when there is nothing to write
 * (neither projected nor geographic, or too long), SIZE_MAX when out of memory. */
static inline size_t ex_rio_prj_geokeys(const char *prj, uint64_t keys[16], char **ascii, size_t *n_ascii)
{
    static const char tag[] = "ESRI PE String = ";
    int crs = ex_rio_wkt_crs(prj), epsg;
    size_t len;
    *ascii = NULL;
    *n_ascii = 0;
    if (crs != EX_RIO_CRS_PROJECTED && crs != EX_RIO_CRS_GEOGRAPHIC) return 0;
    while (isspace((unsigned char)*prj)) prj++;
    for (len = strlen(prj); len > 0 && isspace((unsigned char)prj[len - 1]); len--) {}
    keys[0] = 1, keys[1] = 1, keys[2] = 0, keys[3] = 3;       /* version 1.1.0, three keys */
    keys[4] = 1024, keys[5] = 0, keys[6] = 1;                  /* GTModelTypeGeoKey */
    keys[8] = 1025, keys[9] = 0, keys[10] = 1, keys[11] = 1;   /* GTRasterTypeGeoKey: PixelIsArea */
    epsg = ex_rio_wkt_epsg(prj);
    if (epsg > 0) {
        keys[7] = (uint64_t)crs;
        keys[12] = crs == EX_RIO_CRS_PROJECTED ? 3072 : 2048, keys[13] = 0, keys[14] = 1;
        keys[15] = (uint64_t)epsg;
        return 16;
    }
    if (len > EX_RIO_MAX_PE_STRING || memchr(prj, '|', len)) return 0;
    *ascii = (char *)malloc(sizeof tag + len + 1);
    if (!*ascii) return SIZE_MAX;
    memcpy(*ascii, tag, sizeof tag - 1);
    memcpy(*ascii + sizeof tag - 1, prj, len);
    (*ascii)[sizeof tag - 1 + len] = '|';
    (*ascii)[sizeof tag + len] = '\0';
    *n_ascii = sizeof tag + len + 1;
    keys[7] = 32767;                                           /* user-defined model */
    keys[12] = 3073, keys[13] = 34737, keys[14] = (uint64_t)(sizeof tag + len), keys[15] = 0;
    return 16;
}

/* Read GTModelType, GTRasterType and the EPSG code from the key directory (GeoTIFF 1.1 §7.1:
 * header KeyDirectoryVersion, KeyRevision, MinorRevision, NumberOfKeys; then per key KeyID,
 * TIFFTagLocation, Count, Value_Offset). -1 when the directory is malformed. */
static inline int ex_georef_keys(ex_georef *g, char *err)
{
    size_t i, n;
    const uint16_t *k = g->geokeys;
    if (g->n_geokeys < 4) return ex_rio_fail(err, "GeoKeyDirectory shorter than its header");
    n = k[3];
    if (k[0] != 1 || n > (g->n_geokeys - 4) / 4)
        return ex_rio_fail(err, "malformed GeoKeyDirectory (version %u, %u keys in %u values)",
                           (unsigned)k[0], (unsigned)n, (unsigned)g->n_geokeys);
    for (i = 0; i < n; i++) {
        const uint16_t *e = k + 4 + 4 * i;
        if (e[1] != 0) continue; /* a value in the double or ASCII params: none of ours */
        if (e[0] == 1024) g->crs = e[3] <= 3 ? e[3] : EX_RIO_CRS_UNKNOWN;
        else if (e[0] == 1025) g->pixel_is_point = e[3] == 2;
        else if (e[0] == 3072 && e[3] != 0 && e[3] != 32767) g->epsg = e[3];
        else if (e[0] == 2048 && e[3] != 0 && e[3] != 32767 && g->epsg == 0) g->epsg = e[3];
    }
    return 0;
}

/* A user-defined model whose WKT rides in an ESRI PE string: its kind from the WKT. */
static inline void ex_georef_pe_crs(ex_georef *g)
{
    size_t len;
    const char *w = g->crs == EX_RIO_CRS_UNKNOWN ? ex_rio_pe_string(g, &len) : NULL;
    if (w) {
        char head[16] = {0};
        memcpy(head, w, len < sizeof head - 1 ? len : sizeof head - 1);
        g->crs = ex_rio_wkt_crs(head);
    }
}

/* The geotransform from ModelTransformation, or from ModelPixelScale + one ModelTiepoint
 * (GeoTIFF 1.1 §7.2); PixelIsPoint moves it half a cell as GDAL does. */
static inline void ex_georef_transform(ex_georef *g)
{
    if (g->has_matrix) {
        const double *m = g->matrix;
        g->gt[0] = m[3]; g->gt[1] = m[0]; g->gt[2] = m[1];
        g->gt[3] = m[7]; g->gt[4] = m[4]; g->gt[5] = m[5];
        g->has_transform = 1;
    } else if (g->has_scale && g->n_tiepoints >= 6) {
        const double *t = g->tiepoints;
        g->gt[1] = g->scale[0]; g->gt[2] = 0.0;
        g->gt[4] = 0.0; g->gt[5] = -g->scale[1];
        g->gt[0] = t[3] - t[0] * g->gt[1];
        g->gt[3] = t[4] - t[1] * g->gt[5];
        g->has_transform = 1;
    }
    if (g->has_transform && g->pixel_is_point) {
        g->gt[0] -= 0.5 * g->gt[1] + 0.5 * g->gt[2];
        g->gt[3] -= 0.5 * g->gt[4] + 0.5 * g->gt[5];
    }
}

/* A transform with a negative pixel width or a positive pixel height (and no rotation) as the
 * north-up raster, west to east, that ex_rio_read returns: gt describes that raster and
 * flip_x / flip_y record the file's orientation (the GeoTIFF tags, in the file's orientation,
 * are dropped: a written GeoTIFF gets a ModelTransformation from gt and the flags). */
static inline void ex_georef_orient(ex_georef *g, int width, int height)
{
    if (!g->has_transform || g->gt[2] != 0.0 || g->gt[4] != 0.0) return;
    if (g->gt[1] < 0.0) {
        g->gt[0] += g->gt[1] * (double)width;
        g->gt[1] = -g->gt[1];
        g->flip_x = 1;
    }
    if (g->gt[5] > 0.0) {
        g->gt[3] += g->gt[5] * (double)height;
        g->gt[5] = -g->gt[5];
        g->flip_y = 1;
    }
    if (g->flip_x || g->flip_y) {
        free(g->tiepoints);
        g->tiepoints = NULL;
        g->n_tiepoints = 0;
        g->has_scale = g->has_matrix = 0;
    }
}

/* NoData from its text (GDAL_NODATA, NODATA_value): a number, "nan", "inf", "-inf". */
static inline int ex_georef_set_nodata(ex_georef *g, const char *text, size_t len)
{
    char buf[64], *end;
    double v;
    while (len > 0 && (text[len - 1] == '\0' || isspace((unsigned char)text[len - 1]))) len--;
    while (len > 0 && isspace((unsigned char)*text)) { text++; len--; }
    if (len == 0 || len >= sizeof buf) return -1;
    memcpy(buf, text, len);
    buf[len] = '\0';
    v = strtod(buf, &end);
    if (memchr(buf, 'x', len) || memchr(buf, 'X', len)) return -1; /* hexadecimal: not a number */
    if (end == buf || *end != '\0') {
        size_t i;
        for (i = 0; i < len; i++) buf[i] = (char)tolower((unsigned char)buf[i]);
        if (!strcmp(buf, "nan") || !strcmp(buf, "-nan")) v = (double)NAN;
        else if (!strcmp(buf, "inf") || !strcmp(buf, "+inf")) v = (double)INFINITY;
        else if (!strcmp(buf, "-inf")) v = -(double)INFINITY;
        else return -1;
        memcpy(buf, text, len);
    }
    g->has_nodata = 1;
    g->nodata = v;
    memcpy(g->nodata_text, buf, len + 1);
    return 0;
}

/* ------------------------------------------------------------------------------------------ */
/* 3. byte sources                                                                            */
/* ------------------------------------------------------------------------------------------ */

/* Copy n bytes at off into dst; -1 past the end or on a read error. */
static inline int ex_rio_fetch(ex_rio_reader *r, uint64_t off, size_t n, void *dst)
{
    if (off > r->size || n > r->size - off) return -1;
    if (n == 0) return 0;
    if (r->mem) {
        memcpy(dst, r->mem + off, n);
        return 0;
    }
    if (off > (uint64_t)LONG_MAX || fseek(r->f, (long)off, SEEK_SET) != 0) return -1;
    return fread(dst, 1, n, r->f) == n ? 0 : -1;
}

/* 1 when this machine stores a float's most significant byte first. */
static inline int ex_rio_host_big_endian(void)
{
    const float one = 1.0f; /* 0x3f800000 */
    unsigned char b[4];
    memcpy(b, &one, 4);
    return b[0] == 0x3f;
}

static inline uint64_t ex_rio_uint(const unsigned char *p, int n, int be)
{
    uint64_t v = 0;
    int i;
    if (be) for (i = 0; i < n; i++) v = v << 8 | p[i];
    else for (i = n - 1; i >= 0; i--) v = v << 8 | p[i];
    return v;
}

static inline void ex_rio_put_uint(unsigned char *p, uint64_t v, int n, int be)
{
    int i;
    for (i = 0; i < n; i++) p[be ? n - 1 - i : i] = (unsigned char)(v >> (8 * i));
}

static inline double ex_rio_bits_double(uint64_t b)
{
    double d;
    memcpy(&d, &b, sizeof d);
    return d;
}

static inline float ex_rio_bits_float(uint32_t b)
{
    float f;
    memcpy(&f, &b, sizeof f);
    return f;
}

/* ------------------------------------------------------------------------------------------ */
/* 4. TIFF structure                                                                          */
/* ------------------------------------------------------------------------------------------ */

/* One IFD entry: tag, field type, count, and where its values are (inline or at an offset). */
typedef struct {
    unsigned tag, type;
    uint64_t count, off; /* off: file offset of the values */
} ex_rio_entry;

/* Bytes per value of a TIFF field type (TIFF 6.0 §2, BigTIFF adds 16, 17, 18); 0 unknown. */
static inline int ex_rio_type_size(unsigned type)
{
    static const unsigned char size[19] = { 0, 1, 1, 2, 4, 8, 1, 1, 2, 4, 8, 4, 8, 4, 0, 0, 8, 8, 8 };
    return type < 19 ? size[type] : 0;
}

/* Values i of an entry as uint64 (integer types) or double (any numeric type); -1 past the end
 * or for a non-numeric type. */
static inline int ex_rio_entry_value(ex_rio_reader *r, const ex_rio_entry *e, uint64_t i, double *d,
                                     uint64_t *u)
{
    unsigned char b[8];
    int n = ex_rio_type_size(e->type);
    uint64_t v;
    if (n == 0 || e->type == 2 || e->type == 7 || i >= e->count) return -1;
    if (ex_rio_fetch(r, e->off + i * (uint64_t)n, (size_t)n, b) != 0) return -1;
    v = ex_rio_uint(b, n, r->big_endian);
    switch (e->type) {
    case 5: case 10: { /* RATIONAL, SRATIONAL: two 32-bit halves */
        uint64_t num = ex_rio_uint(b, 4, r->big_endian), den = ex_rio_uint(b + 4, 4, r->big_endian);
        if (e->type == 10) *d = (double)(int32_t)(uint32_t)num / (double)(int32_t)(uint32_t)den;
        else *d = (double)num / (double)den;
        *u = den ? num / den : 0;
        return 0;
    }
    case 6: *d = (double)(int8_t)(uint8_t)v; break;
    case 8: *d = (double)(int16_t)(uint16_t)v; break;
    case 9: *d = (double)(int32_t)(uint32_t)v; break;
    case 17: *d = (double)(int64_t)v; break;
    case 11: *d = (double)ex_rio_bits_float((uint32_t)v); break;
    case 12: *d = ex_rio_bits_double(v); break;
    default: *d = (double)v; break;
    }
    *u = v;
    return 0;
}

/* A one-value integer tag. */
static inline int ex_rio_entry_u(ex_rio_reader *r, const ex_rio_entry *e, uint64_t *u)
{
    double d;
    if (e->type == 11 || e->type == 12 || e->type == 5 || e->type == 10)
        return ex_rio_fail(r->err, "TIFF tag %u has a non-integer type %u", e->tag, e->type);
    if (ex_rio_entry_value(r, e, 0, &d, u) != 0)
        return ex_rio_fail(r->err, "TIFF tag %u: no value or value past the end of the file", e->tag);
    return 0;
}

/* An array tag of numbers as doubles, at most max values (allocated; NULL for count 0). */
static inline int ex_rio_entry_doubles(ex_rio_reader *r, const ex_rio_entry *e, uint64_t max,
                                       double **out, size_t *n)
{
    uint64_t i, u;
    if (e->count > max) return ex_rio_fail(r->err, "TIFF tag %u holds %llu values, more than %llu",
                                           e->tag, (unsigned long long)e->count, (unsigned long long)max);
    *n = (size_t)e->count;
    *out = (double *)malloc((*n ? *n : 1) * sizeof(double));
    if (!*out) return ex_rio_fail(r->err, "out of memory");
    for (i = 0; i < e->count; i++)
        if (ex_rio_entry_value(r, e, i, *out + i, &u) != 0)
            return ex_rio_fail(r->err, "TIFF tag %u: values past the end of the file or of a "
                               "non-numeric type", e->tag);
    return 0;
}

/* A tag of want numbers (ModelTransformation: 16) into dst; *has = 1. ModelPixelScale (want 3)
 * may hold 2 (X and Y: GDAL reads those, Z is then 0) or more (the first 3 are kept). A tag of
 * another length is refused: ignoring it would run with cell 1. */
static inline int ex_rio_entry_fixed(ex_rio_reader *r, const ex_rio_entry *e, double *dst, size_t want, int *has)
{
    size_t i, n = want;
    uint64_t u;
    if (want == 3 && e->count >= 2) n = e->count < 3 ? (size_t)e->count : 3;
    else if (e->count != want)
        return ex_rio_fail(r->err, "TIFF tag %u (%s) holds %llu values, not %u", e->tag,
                           e->tag == 33550 ? "ModelPixelScale" : "ModelTransformation",
                           (unsigned long long)e->count, (unsigned)want);
    for (i = n; i < want; i++) dst[i] = 0.0;
    for (i = 0; i < n; i++)
        if (ex_rio_entry_value(r, e, i, dst + i, &u) != 0)
            return ex_rio_fail(r->err, "TIFF tag %u: values past the end of the file or of a non-numeric type",
                               e->tag);
    *has = 1;
    return 0;
}

/* StripOffsets/TileOffsets or the byte counts: exactly want values, as uint64. */
static inline int ex_rio_entry_chunks(ex_rio_reader *r, const ex_rio_entry *e, uint64_t want,
                                      uint64_t **out)
{
    uint64_t i;
    unsigned char *raw;
    int n = ex_rio_type_size(e->type);
    if (e->type != 3 && e->type != 4 && e->type != 16)
        return ex_rio_fail(r->err, "TIFF tag %u (strip/tile offsets or sizes) has type %u, not "
                           "SHORT, LONG or LONG8", e->tag, e->type);
    if (e->count != want)
        return ex_rio_fail(r->err, "TIFF tag %u lists %llu strips/tiles, the image has %llu", e->tag,
                           (unsigned long long)e->count, (unsigned long long)want);
    if (e->off > r->size || want > (r->size - e->off) / (uint64_t)n)
        return ex_rio_fail(r->err, "TIFF tag %u: its %llu values run past the end of the file",
                           e->tag, (unsigned long long)want);
    *out = (uint64_t *)malloc((size_t)want * sizeof(uint64_t));
    raw = (unsigned char *)malloc((size_t)want * (size_t)n);
    if (!*out || !raw) {
        free(raw);
        return ex_rio_fail(r->err, "out of memory");
    }
    if (ex_rio_fetch(r, e->off, (size_t)want * (size_t)n, raw) != 0) {
        free(raw);
        return ex_rio_fail(r->err, "cannot read TIFF tag %u", e->tag);
    }
    for (i = 0; i < want; i++) (*out)[i] = ex_rio_uint(raw + i * (uint64_t)n, n, r->big_endian);
    free(raw);
    return 0;
}

static inline const char *ex_rio_compression_name(uint64_t c)
{
    switch (c) {
    case 2: return "CCITT RLE";
    case 3: return "CCITT Group 3 fax";
    case 4: return "CCITT Group 4 fax";
    case 6: return "old-style JPEG";
    case 7: return "JPEG";
    case 34661: return "JBIG";
    case 34676: case 34677: return "SGI LogLuv";
    case 34712: return "JPEG 2000";
    case 34887: return "LERC";
    case 34925: return "LZMA";
    case 50000: return "ZSTD";
    case 50001: return "WebP";
    case 50002: return "JPEG XL";
    default: return "unknown";
    }
}

static inline int ex_rio_chunk_check(ex_rio_reader *r, uint64_t k, uint64_t *rowb_out, uint64_t *need_out,
                                     uint64_t *full_out);

/* Walk the IFD chain from first (refusing loops and offsets past the end) and parse IFD 0. */
static inline int ex_rio_tiff_parse(ex_rio_reader *r)
{
    unsigned char h[16], eb[20];
    uint64_t ifd, nent, i, next, seen = 0;
    uint64_t width = 0, height = 0, spp = 1, bps = 1, fmt = EX_RIO_UINT, rps = 0, tw = 0, th = 0;
    ex_rio_entry off_e, cnt_e;
    int have_off = 0, have_cnt = 0, have_tw = 0, have_th = 0, tile_tags = 0, esz, csz;
    uint64_t v;
    r->format = EX_RIO_TIFF;
    r->compression = 1;
    r->predictor = 1;
    r->planar = 1;
    r->photometric = -1;
    memset(&off_e, 0, sizeof off_e);
    memset(&cnt_e, 0, sizeof cnt_e);
    if (ex_rio_fetch(r, 0, 8, h) != 0) return ex_rio_fail(r->err, "not a TIFF file (shorter than its header)");
    if (h[0] == 'I' && h[1] == 'I') r->big_endian = 0;
    else if (h[0] == 'M' && h[1] == 'M') r->big_endian = 1;
    else return ex_rio_fail(r->err, "not a TIFF file (no II/MM byte-order mark)");
    v = ex_rio_uint(h + 2, 2, r->big_endian);
    if (v == 42) {
        ifd = ex_rio_uint(h + 4, 4, r->big_endian);
    } else if (v == 43) {
        r->bigtiff = 1;
        if (ex_rio_fetch(r, 0, 16, h) != 0) return ex_rio_fail(r->err, "truncated BigTIFF header");
        if (ex_rio_uint(h + 4, 2, r->big_endian) != 8 || ex_rio_uint(h + 6, 2, r->big_endian) != 0)
            return ex_rio_fail(r->err, "BigTIFF header with an offset size other than 8");
        ifd = ex_rio_uint(h + 8, 8, r->big_endian);
    } else {
        return ex_rio_fail(r->err, "not a TIFF file (version %llu, not 42 or 43)", (unsigned long long)v);
    }
    esz = r->bigtiff ? 20 : 12;
    csz = r->bigtiff ? 8 : 2;
    /* the chain: each IFD must lie in the file; more than EX_RIO_MAX_IFDS is a loop */
    for (next = ifd; next != 0; seen++) {
        unsigned char c[8];
        if (seen == EX_RIO_MAX_IFDS)
            return ex_rio_fail(r->err, "TIFF IFD chain longer than %d: a loop", EX_RIO_MAX_IFDS);
        if (ex_rio_fetch(r, next, (size_t)csz, c) != 0)
            return ex_rio_fail(r->err, "TIFF IFD offset %llu is past the end of the file",
                               (unsigned long long)next);
        nent = ex_rio_uint(c, csz, r->big_endian);
        if (nent > EX_RIO_MAX_ENTRIES)
            return ex_rio_fail(r->err, "TIFF IFD claims %llu entries (limit %d)", (unsigned long long)nent,
                               EX_RIO_MAX_ENTRIES);
        if (ex_rio_fetch(r, next + (uint64_t)csz + nent * (uint64_t)esz, (size_t)(csz == 8 ? 8 : 4), c) != 0)
            return ex_rio_fail(r->err, "truncated TIFF IFD (%llu entries at %llu)",
                               (unsigned long long)nent, (unsigned long long)next);
        v = ex_rio_uint(c, csz == 8 ? 8 : 4, r->big_endian);
        if (v == ifd) return ex_rio_fail(r->err, "TIFF IFD chain loops back to its first IFD");
        next = v;
    }
    if (ifd == 0) return ex_rio_fail(r->err, "TIFF file without an image (first IFD offset 0)");
    if (ex_rio_fetch(r, ifd, (size_t)csz, eb) != 0) return ex_rio_fail(r->err, "truncated TIFF IFD");
    nent = ex_rio_uint(eb, csz, r->big_endian);
    for (i = 0; i < nent; i++) {
        ex_rio_entry e;
        int tsz;
        uint64_t bytes, pos = ifd + (uint64_t)csz + i * (uint64_t)esz;
        if (ex_rio_fetch(r, pos, (size_t)esz, eb) != 0) return ex_rio_fail(r->err, "truncated TIFF IFD entry");
        e.tag = (unsigned)ex_rio_uint(eb, 2, r->big_endian);
        e.type = (unsigned)ex_rio_uint(eb + 2, 2, r->big_endian);
        e.count = ex_rio_uint(eb + 4, r->bigtiff ? 8 : 4, r->big_endian);
        tsz = ex_rio_type_size(e.type);
        if (tsz == 0) continue; /* unknown type: skip (TIFF 6.0 §2) */
        if (e.count > UINT64_MAX / (uint64_t)tsz) return ex_rio_fail(r->err, "TIFF tag %u: count overflows", e.tag);
        bytes = e.count * (uint64_t)tsz;
        if (bytes <= (uint64_t)(r->bigtiff ? 8 : 4)) e.off = pos + 4 + (r->bigtiff ? 8 : 4);
        else e.off = ex_rio_uint(eb + (r->bigtiff ? 12 : 8), r->bigtiff ? 8 : 4, r->big_endian);
        switch (e.tag) {
        case 256: if (ex_rio_entry_u(r, &e, &width)) return -1; break;
        case 257: if (ex_rio_entry_u(r, &e, &height)) return -1; break;
        case 258: { /* BitsPerSample: one per sample, all equal */
            uint64_t k, b;
            double d;
            if (ex_rio_entry_u(r, &e, &bps)) return -1;
            for (k = 1; k < e.count && k < EX_RIO_MAX_BANDS; k++) {
                if (ex_rio_entry_value(r, &e, k, &d, &b) != 0) return ex_rio_fail(r->err, "truncated BitsPerSample");
                if (b != bps) return ex_rio_fail(r->err, "bands of different bit depths (%llu and %llu) are not supported",
                                                 (unsigned long long)bps, (unsigned long long)b);
            }
            break;
        }
        case 259: if (ex_rio_entry_u(r, &e, &v)) return -1; r->compression = (int)(v > 65535 ? 65535 : v); break;
        case 262: if (ex_rio_entry_u(r, &e, &v)) return -1; r->photometric = (int)(v > 65535 ? 65535 : v); break;
        case 273: case 324: off_e = e; have_off = 1; tile_tags |= e.tag == 324; break;
        case 279: case 325: cnt_e = e; have_cnt = 1; break;
        case 277: if (ex_rio_entry_u(r, &e, &spp)) return -1; break;
        case 278: if (ex_rio_entry_u(r, &e, &rps)) return -1; break;
        case 284: if (ex_rio_entry_u(r, &e, &v)) return -1; r->planar = (int)(v > 2 ? 3 : v); break;
        case 317: if (ex_rio_entry_u(r, &e, &v)) return -1; r->predictor = (int)(v > 3 ? 4 : v); break;
        case 320: return ex_rio_fail(r->err, "palette (ColorMap) images are not supported: heights are needed, "
                                     "not colours");
        case 322: if (ex_rio_entry_u(r, &e, &tw)) return -1; have_tw = 1; break;
        case 323: if (ex_rio_entry_u(r, &e, &th)) return -1; have_th = 1; break;
        case 339: if (ex_rio_entry_u(r, &e, &fmt)) return -1; break;
        case 33550: if (ex_rio_entry_fixed(r, &e, r->geo.scale, 3, &r->geo.has_scale)) return -1; break;
        case 33922:
            free(r->geo.tiepoints);
            r->geo.tiepoints = NULL;
            if (ex_rio_entry_doubles(r, &e, EX_RIO_MAX_GEO, &r->geo.tiepoints, &r->geo.n_tiepoints)) return -1;
            break;
        case 34264: if (ex_rio_entry_fixed(r, &e, r->geo.matrix, 16, &r->geo.has_matrix)) return -1; break;
        case 34735: {
            double *d = NULL;
            size_t n = 0, k;
            if (e.type != 3) return ex_rio_fail(r->err, "GeoKeyDirectory is not of type SHORT");
            if (ex_rio_entry_doubles(r, &e, EX_RIO_MAX_GEO, &d, &n)) { free(d); return -1; }
            free(r->geo.geokeys);
            r->geo.geokeys = (uint16_t *)malloc((n ? n : 1) * sizeof(uint16_t));
            if (!r->geo.geokeys) { free(d); return ex_rio_fail(r->err, "out of memory"); }
            for (k = 0; k < n; k++) r->geo.geokeys[k] = (uint16_t)d[k];
            r->geo.n_geokeys = n;
            free(d);
            break;
        }
        case 34736:
            if (e.type != 12) return ex_rio_fail(r->err, "GeoDoubleParams is not of type DOUBLE");
            free(r->geo.geodoubles);
            r->geo.geodoubles = NULL;
            if (ex_rio_entry_doubles(r, &e, EX_RIO_MAX_GEO, &r->geo.geodoubles, &r->geo.n_geodoubles)) return -1;
            break;
        case 34737: case 42113: {
            char *s;
            if (e.type != 2) return ex_rio_fail(r->err, "TIFF tag %u is not ASCII", e.tag);
            if (e.count > EX_RIO_MAX_GEO) return ex_rio_fail(r->err, "TIFF tag %u: text longer than %d",
                                                             e.tag, EX_RIO_MAX_GEO);
            s = (char *)malloc((size_t)e.count + 1);
            if (!s) return ex_rio_fail(r->err, "out of memory");
            if (ex_rio_fetch(r, e.off, (size_t)e.count, s) != 0) {
                free(s);
                return ex_rio_fail(r->err, "TIFF tag %u: text past the end of the file", e.tag);
            }
            s[e.count] = '\0';
            if (e.tag == 42113) {
                if (ex_georef_set_nodata(&r->geo, s, (size_t)e.count) != 0) {
                    free(s);
                    return ex_rio_fail(r->err, "GDAL_NODATA is not a number");
                }
                free(s);
            } else {
                free(r->geo.geoascii);
                r->geo.geoascii = s;
                r->geo.n_geoascii = (size_t)e.count;
            }
            break;
        }
        default: break;
        }
    }
    /* the image */
    if (width == 0 || height == 0 || width > EX_RIO_MAX_DIM || height > EX_RIO_MAX_DIM)
        return ex_rio_fail(r->err, "TIFF image of %llu x %llu cells (1..%d each)", (unsigned long long)width,
                           (unsigned long long)height, EX_RIO_MAX_DIM);
    if (spp == 0 || spp > EX_RIO_MAX_BANDS) return ex_rio_fail(r->err, "TIFF with %llu samples per pixel",
                                                               (unsigned long long)spp);
    if (r->compression != 1 && r->compression != 5 && r->compression != 8 && r->compression != 32946 &&
        r->compression != 32773)
        return ex_rio_fail(r->err, "TIFF compression %s (%d) is not supported (none, LZW, DEFLATE and PackBits "
                           "are): gdal_translate -co COMPRESS=DEFLATE converts it",
                           ex_rio_compression_name((uint64_t)r->compression), r->compression);
    if (r->photometric == 3) return ex_rio_fail(r->err, "palette images are not supported");
    if (r->photometric > 2 && r->photometric != 5)
        return ex_rio_fail(r->err, "TIFF photometric interpretation %d (%s) is not supported", r->photometric,
                           r->photometric == 6 ? "YCbCr" : "not greyscale, RGB or separated");
    if (r->planar != 1 && r->planar != 2) return ex_rio_fail(r->err, "TIFF PlanarConfiguration must be 1 or 2");
    if (fmt != EX_RIO_UINT && fmt != EX_RIO_INT && fmt != EX_RIO_FLOAT)
        return ex_rio_fail(r->err, "TIFF SampleFormat %llu (complex or undefined) is not supported",
                           (unsigned long long)fmt);
    if (fmt == EX_RIO_FLOAT ? (bps != 32 && bps != 64) : (bps != 8 && bps != 16 && bps != 32))
        return ex_rio_fail(r->err, "%llu-bit %s samples are not supported (8/16/32-bit integers, 32/64-bit floats)",
                           (unsigned long long)bps, fmt == EX_RIO_FLOAT ? "floating-point" : "integer");
    if (r->predictor < 1 || r->predictor > 3) return ex_rio_fail(r->err, "TIFF Predictor %d is not supported", r->predictor);
    if (r->predictor == 3 && fmt != EX_RIO_FLOAT)
        return ex_rio_fail(r->err, "TIFF floating-point predictor on integer samples");
    if (r->predictor != 1 && (r->compression == 1 || r->compression == 32773))
        r->predictor = 1; /* libtiff applies predictors only with LZW and deflate */
    r->width = (int)width;
    r->height = (int)height;
    r->bands = (int)spp;
    r->kind = (int)fmt;
    r->bits = (int)bps;
    r->tiled = tile_tags || have_tw || have_th;
    if (r->tiled) {
        if (!have_tw || !have_th || tw == 0 || th == 0 || tw > EX_RIO_MAX_DIM || th > EX_RIO_MAX_DIM)
            return ex_rio_fail(r->err, "TIFF tiles of %llu x %llu", (unsigned long long)tw, (unsigned long long)th);
        r->chunk_w = (uint32_t)tw;
        r->chunk_h = (uint32_t)th;
    } else {
        r->chunk_w = (uint32_t)width;
        r->chunk_h = (uint32_t)(rps == 0 || rps > height ? height : rps);
    }
    r->across = (width + r->chunk_w - 1) / r->chunk_w;
    r->down = (height + r->chunk_h - 1) / r->chunk_h;
    if (r->across > EX_RIO_MAX_CHUNKS / r->down ||
        r->across * r->down > EX_RIO_MAX_CHUNKS / (r->planar == 2 ? spp : 1))
        return ex_rio_fail(r->err, "TIFF with more than %llu strips or tiles", (unsigned long long)EX_RIO_MAX_CHUNKS);
    r->nchunks = r->across * r->down * (r->planar == 2 ? spp : 1);
    if (!have_off || !have_cnt) return ex_rio_fail(r->err, "TIFF without strip/tile offsets or byte counts");
    if (ex_rio_entry_chunks(r, &off_e, r->nchunks, &r->offsets)) return -1;
    if (ex_rio_entry_chunks(r, &cnt_e, r->nchunks, &r->counts)) return -1;
    for (v = 0; v < r->nchunks; v++) {
        uint64_t rowb, need, full;
        if (ex_rio_chunk_check(r, v, &rowb, &need, &full) != 0) return -1;
    }
    if (r->geo.n_geokeys && ex_georef_keys(&r->geo, r->err) != 0) return -1;
    if (r->geo.n_geokeys) ex_georef_pe_crs(&r->geo);
    ex_georef_transform(&r->geo);
    if (r->geo.has_scale && !r->geo.has_matrix && r->geo.n_tiepoints < 6)
        return ex_rio_fail(r->err, "GeoTIFF with a ModelPixelScale but no ModelTiepoint: no georeference");
    if (r->geo.has_transform) {
        int k;
        for (k = 0; k < 6; k++)
            if (!isfinite(r->geo.gt[k])) return ex_rio_fail(r->err, "GeoTIFF geotransform with a non-finite value");
        if (r->geo.gt[1] * r->geo.gt[5] - r->geo.gt[2] * r->geo.gt[4] == 0.0)
            return ex_rio_fail(r->err, "GeoTIFF with a zero pixel size (ModelPixelScale %g %g)", r->geo.gt[1],
                               -r->geo.gt[5]);
    }
    ex_georef_orient(&r->geo, r->width, r->height);
    return 0;
}

/* ------------------------------------------------------------------------------------------ */
/* 5. TIFF chunk decoding                                                                     */
/* ------------------------------------------------------------------------------------------ */

/* PackBits (TIFF 6.0 §9): header n in 0..127 copies n + 1 bytes, -127..-1 repeats the next byte
 * 1 - n times, -128 is a no-op. Returns the bytes produced (stops when out is full). */
static inline size_t ex_rio_packbits(const unsigned char *in, size_t n, unsigned char *out, size_t cap)
{
    size_t i = 0, o = 0;
    while (i < n && o < cap) {
        int c = (int)(signed char)in[i++];
        if (c >= 0) {
            size_t k = (size_t)c + 1;
            if (k > n - i) k = n - i;
            if (k > cap - o) k = cap - o;
            memcpy(out + o, in + i, k);
            i += k;
            o += k;
        } else if (c != -128) {
            size_t k = (size_t)(1 - c);
            if (i == n) break;
            if (k > cap - o) k = cap - o;
            memset(out + o, in[i++], k);
            o += k;
        }
    }
    return o;
}

/* TIFF LZW (TIFF 6.0 §13): codes MSB first, 9..12 bits, Clear 256, EndOfInformation 257, the
 * width growing one code early (at 511, 1023, 2047) as libtiff writes. Returns 0 and the bytes
 * produced in *produced (at most cap), or -1 for an invalid code or old-style (LSB-first) LZW. */
static inline int ex_rio_lzw(const unsigned char *in, size_t n, unsigned char *out, size_t cap,
                             size_t *produced)
{
    uint16_t prefix[4096];
    unsigned char suffix[4096], first[4096], stack[4096];
    uint16_t length[4096];
    size_t o = 0, bitpos = 0, nbits = n * 8u;
    int width = 9, next = 258, old = -1, k;
    *produced = 0;
    if (n >= 2 && in[0] == 0 && (in[1] & 1)) return -1; /* old-style LZW starts with a LSB Clear */
    for (k = 0; k < 256; k++) {
        prefix[k] = 0;
        suffix[k] = first[k] = (unsigned char)k;
        length[k] = 1;
    }
    while (o < cap && bitpos + (size_t)width <= nbits) {
        int code = 0, b;
        for (b = 0; b < width; b++, bitpos++)
            code = code << 1 | ((in[bitpos >> 3] >> (7 - (bitpos & 7))) & 1);
        if (code == 256) {
            width = 9;
            next = 258;
            old = -1;
            continue;
        }
        if (code == 257) break;
        if (old < 0) {
            if (code > 255) return -1;
            out[o++] = (unsigned char)code;
            old = code;
            continue;
        }
        if (code > next || next >= 4096) return -1;
        {
            int c = code == next ? old : code, len, j;
            unsigned char fc;
            len = length[c];
            for (j = len - 1; j >= 0; j--) {
                stack[j] = suffix[c];
                c = prefix[c];
            }
            fc = stack[0];
            if (code == next) stack[len++] = first[old];
            prefix[next] = (uint16_t)old;
            suffix[next] = code == next ? first[old] : fc;
            first[next] = first[old];
            length[next] = (uint16_t)(length[old] + 1);
            next++;
            for (j = 0; j < len && o < cap; j++) out[o++] = stack[j];
        }
        old = code;
        if (next + 1 >= (1 << width) && width < 12) width++;
    }
    *produced = o;
    return 0;
}

/* Undo predictor 2 (horizontal differencing of whole samples, TIFF 6.0 §14) in one row of nsamp
 * samples of bytes each, stride = samples per pixel. */
static inline void ex_rio_unpredict2(unsigned char *row, size_t nsamp, int bytes, size_t stride, int be)
{
    size_t i;
    uint64_t mask = bytes == 8 ? ~(uint64_t)0 : (((uint64_t)1 << (8 * bytes)) - 1u);
    for (i = stride; i < nsamp; i++) {
        uint64_t a = ex_rio_uint(row + (i - stride) * (size_t)bytes, bytes, be);
        uint64_t b = ex_rio_uint(row + i * (size_t)bytes, bytes, be);
        ex_rio_put_uint(row + i * (size_t)bytes, (a + b) & mask, bytes, be);
    }
}

/* Undo predictor 3 (Adobe Photoshop TIFF Technical Note 3, libtiff fpAcc): byte differencing
 * with stride = samples per pixel over the row, then the bytes of sample i sit at tmp[b nsamp
 * + i], most significant byte first. The row is rewritten big-endian. */
static inline void ex_rio_unpredict3(unsigned char *row, unsigned char *tmp, size_t nsamp, int bytes,
                                     size_t stride)
{
    size_t i, n = nsamp * (size_t)bytes;
    int b;
    for (i = stride; i < n; i++) row[i] = (unsigned char)(row[i] + row[i - stride]);
    memcpy(tmp, row, n);
    if (bytes == 4) /* Float32, the usual case: the same moves unrolled */
        for (i = 0; i < nsamp; i++) {
            row[4 * i] = tmp[i];
            row[4 * i + 1] = tmp[nsamp + i];
            row[4 * i + 2] = tmp[2 * nsamp + i];
            row[4 * i + 3] = tmp[3 * nsamp + i];
        }
    else
        for (i = 0; i < nsamp; i++)
            for (b = 0; b < bytes; b++) row[i * (size_t)bytes + (size_t)b] = tmp[(size_t)b * nsamp + i];
}

static inline int ex_rio_grow(unsigned char **buf, size_t *cap, size_t need)
{
    unsigned char *p;
    if (need <= *cap) return 0;
    p = (unsigned char *)realloc(*buf, need);
    if (!p) return -1;
    *buf = p;
    *cap = need;
    return 0;
}

/* The layout of chunk k: bytes per row, decoded bytes of its rows in the image (need) and of a
 * whole strip (full: the last strip may be shorter; full = need when a whole one could not come
 * from its bytes); and the checks that its bytes lie in the file and can hold need bytes (the
 * codec's largest ratio). Run for every chunk when the file is opened, so a size the file cannot
 * back is refused before anyone allocates for it. */
static inline int ex_rio_chunk_check(ex_rio_reader *r, uint64_t k, uint64_t *rowb_out, uint64_t *need_out,
                                     uint64_t *full_out)
{
    uint64_t bytes = (uint64_t)r->bits / 8u, rowb, need, full, rows = r->chunk_h;
    uint64_t cnt = r->counts[k], off = r->offsets[k], d = (k % (r->across * r->down)) / r->across;
    uint64_t spc = r->planar == 2 ? 1u : (uint64_t)r->bands;
    if (!r->tiled && d * r->chunk_h + rows > (uint64_t)r->height) rows = (uint64_t)r->height - d * r->chunk_h;
    rowb = (uint64_t)r->chunk_w * spc * bytes; /* chunk_w, spc < 2^31, 2^16: no overflow */
    if (rowb > EX_RIO_MAX_CHUNK || rows > EX_RIO_MAX_CHUNK / rowb)
        return ex_rio_fail(r->err, "TIFF strip/tile %llu decodes to more than %llu bytes", (unsigned long long)k,
                           (unsigned long long)EX_RIO_MAX_CHUNK);
    need = rowb * rows;
    full = rowb * (uint64_t)r->chunk_h;
    if (full > EX_RIO_MAX_CHUNK) full = need;
    if (off > r->size || cnt > r->size - off)
        return ex_rio_fail(r->err, "TIFF strip/tile %llu (offset %llu, %llu bytes) runs past the end of the file",
                           (unsigned long long)k, (unsigned long long)off, (unsigned long long)cnt);
    if (r->compression == 1) {
        if (cnt < need)
            return ex_rio_fail(r->err, "TIFF strip/tile %llu holds %llu bytes, %llu needed", (unsigned long long)k,
                               (unsigned long long)cnt, (unsigned long long)need);
    } else {
        uint64_t ratio = r->compression == 5 ? EX_RIO_RATIO_LZW :
                         r->compression == 32773 ? EX_RIO_RATIO_PACKBITS : EX_RIO_RATIO_DEFLATE;
        if (need / ratio > cnt)
            return ex_rio_fail(r->err, "TIFF strip/tile %llu: %llu compressed bytes cannot hold %llu bytes",
                               (unsigned long long)k, (unsigned long long)cnt, (unsigned long long)need);
        if (full / ratio > cnt) full = need;
    }
    *rowb_out = rowb;
    *need_out = need;
    *full_out = full;
    return 0;
}

/* Decode chunk index k (rows x cols cells, spc samples per cell) into r->dbuf. */
static inline int ex_rio_chunk(ex_rio_reader *r, uint64_t k, uint64_t rows, uint64_t spc)
{
    uint64_t bytes = (uint64_t)r->bits / 8u, rowb, need, full, cnt = r->counts[k], off = r->offsets[k];
    size_t got = 0, y;
    int ok;
    if (r->cached == k + 1) return 0;
    r->cached = 0;
    if (ex_rio_chunk_check(r, k, &rowb, &need, &full) != 0) return -1;
    if (r->compression == 1) cnt = need;
    if (ex_rio_grow(&r->dbuf, &r->dbuf_cap, (size_t)full + (size_t)rowb) != 0)
        return ex_rio_fail(r->err, "out of memory");
    if (r->compression == 1) {
        if (ex_rio_fetch(r, off, (size_t)need, r->dbuf) != 0)
            return ex_rio_fail(r->err, "cannot read TIFF strip/tile %llu", (unsigned long long)k);
        got = (size_t)need;
    } else {
        if (ex_rio_grow(&r->cbuf, &r->cbuf_cap, (size_t)cnt + 1) != 0) return ex_rio_fail(r->err, "out of memory");
        if (ex_rio_fetch(r, off, (size_t)cnt, r->cbuf) != 0)
            return ex_rio_fail(r->err, "cannot read TIFF strip/tile %llu", (unsigned long long)k);
        if (r->compression == 32773) {
            got = ex_rio_packbits(r->cbuf, (size_t)cnt, r->dbuf, (size_t)full);
        } else if (r->compression == 5) {
            if (ex_rio_lzw(r->cbuf, (size_t)cnt, r->dbuf, (size_t)full, &got) != 0)
                return ex_rio_fail(r->err, "TIFF strip/tile %llu: invalid LZW code (or old-style LZW, not supported)",
                                   (unsigned long long)k);
        } else {
            ok = ex_inflate(r->cbuf, (size_t)cnt, r->dbuf, (size_t)full, 1, &got);
            if (ok != EX_Z_OK)
                return ex_rio_fail(r->err, "TIFF strip/tile %llu: %s", (unsigned long long)k, ex_inflate_string(ok));
        }
    }
    if (got < need)
        return ex_rio_fail(r->err, "TIFF strip/tile %llu decodes to %llu bytes, %llu needed", (unsigned long long)k,
                           (unsigned long long)got, (unsigned long long)need);
    r->cached_be = r->big_endian;
    if (r->predictor == 2)
        for (y = 0; y < rows; y++)
            ex_rio_unpredict2(r->dbuf + y * (size_t)rowb, (size_t)(rowb / bytes), (int)bytes, (size_t)spc,
                              r->big_endian);
    if (r->predictor == 3) {
        unsigned char *tmp = r->dbuf + (size_t)full; /* the spare row after the chunk */
        for (y = 0; y < rows; y++)
            ex_rio_unpredict3(r->dbuf + y * (size_t)rowb, tmp, (size_t)(rowb / bytes), (int)bytes, (size_t)spc);
        /* libtiff writes the byte planes most significant first for a little-endian file but,
         * having swapped the samples to the file's order first, least significant first for
         * a big-endian one (GDAL ENDIANNESS=BIG); it reads them back the same way. */
        r->cached_be = !r->big_endian;
    }
    r->cached = k + 1;
    return 0;
}

/* The value of one decoded sample as a double. */
static inline double ex_rio_sample(const unsigned char *p, int kind, int bits, int be)
{
    uint64_t v = ex_rio_uint(p, bits / 8, be);
    if (kind == EX_RIO_FLOAT) return bits == 32 ? (double)ex_rio_bits_float((uint32_t)v) : ex_rio_bits_double(v);
    if (kind == EX_RIO_INT) {
        if (bits == 8) return (double)(int8_t)(uint8_t)v;
        if (bits == 16) return (double)(int16_t)(uint16_t)v;
        return (double)(int32_t)(uint32_t)v;
    }
    return (double)v;
}

/* A sample as stored into the caller's float: NoData to NaN when asked; a value that is not
 * finite as a float (+-Inf, NaN, a Float64 or decimal beyond +-FLT_MAX) is a hole, NaN, as
 * hfvis.h takes every non-finite height. */
static inline float ex_rio_cell(const ex_rio_reader *r, double v)
{
    if (r->nodata_to_nan && r->geo.has_nodata &&
        (v == r->geo.nodata || (isnan(v) && isnan(r->geo.nodata))))
        return (float)NAN;
    if (!(fabs(v) <= (double)FLT_MAX)) return (float)NAN;
    return (float)v;
}

/* ------------------------------------------------------------------------------------------ */
/* 6. ASC and EHdr parsing                                                                    */
/* ------------------------------------------------------------------------------------------ */

/* Next whitespace-separated token of text[*pos..n) into tok (cap bytes, cut to cap - 1); returns
 * its whole length, 0 at the end: a result >= cap is a token that did not fit. */
static inline size_t ex_rio_token(const char *text, size_t n, size_t *pos, char *tok, size_t cap)
{
    size_t i = *pos, len = 0;
    while (i < n && isspace((unsigned char)text[i])) i++;
    while (i < n && !isspace((unsigned char)text[i])) {
        if (len + 1 < cap) tok[len] = text[i];
        len++;
        i++;
    }
    *pos = i;
    tok[len < cap ? len : cap - 1] = '\0';
    return len;
}

static inline int ex_rio_keyeq(const char *a, const char *b)
{
    while (*a && *b && tolower((unsigned char)*a) == tolower((unsigned char)*b)) { a++; b++; }
    return *a == '\0' && *b == '\0';
}

/* strtod's value of a plain decimal, [+-]digits[.digits][(e|E)[+-]digits], whose digits make an
 * integer m <= 2^53 and whose power of ten is within 10^22: m and 10^|e| are exact doubles, so
 * the one product or quotient is the correctly rounded value, strtod's bit for bit (Clinger, "How
 * to read floating point numbers accurately", PLDI 1990: the fast path); -1 for anything else
 * (and where doubles are evaluated in a wider format, FLT_EVAL_METHOD != 0). ASC grids are
 * mostly such decimals; strtod then takes the rest. */
static inline int ex_rio_decimal(const char *s, double *v)
{
    static const double p10[23] = { 1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11,
                                    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22 };
    uint64_t m = 0;
    double d;
    int digits = 0, e = 0, x = 0, neg = 0, eneg, ed = 0;
    if (FLT_EVAL_METHOD != 0) return -1;
    if (*s == '+' || *s == '-') neg = *s++ == '-';
    for (; *s >= '0' && *s <= '9'; s++, digits++) {
        if (digits == 19) return -1; /* m < 10^19 < 2^64 */
        m = m * 10u + (uint64_t)(*s - '0');
    }
    if (*s == '.') {
        for (s++; *s >= '0' && *s <= '9'; s++, digits++, e--) {
            if (digits == 19) return -1;
            m = m * 10u + (uint64_t)(*s - '0');
        }
    }
    if (digits == 0) return -1;
    if (*s == 'e' || *s == 'E') {
        s++;
        eneg = *s == '-';
        if (*s == '+' || *s == '-') s++;
        for (; *s >= '0' && *s <= '9' && ed < 4; s++, ed++) x = x * 10 + (*s - '0');
        if (ed == 0 || ed == 4) return -1;
        e += eneg ? -x : x;
    }
    if (*s != '\0' || m > ((uint64_t)1 << 53) || e < -22 || e > 22) return -1;
    d = neg ? -(double)m : (double)m; /* the sign first: strtod's rounding in every mode */
    *v = e < 0 ? d / p10[-e] : d * p10[e];
    return 0;
}

/* A whole token as a number: decimal, or the words inf, infinity and nan (strtod's); never
 * hexadecimal ("0x10" is not a number to GDAL either). 0, or -1. */
static inline int ex_rio_number(const char *s, double *v)
{
    char *end;
    if (ex_rio_decimal(s, v) == 0) return 0;
    if (!*s || strchr(s, 'x') || strchr(s, 'X')) return -1;
    *v = strtod(s, &end);
    return *end == '\0' ? 0 : -1;
}

/* Parse an ESRI ASCII grid held in memory (the whole grid is decoded; the values must fit in
 * the text, so the allocation is bounded by the input size). */
static inline int ex_rio_parse_asc(ex_rio_reader *r, const char *text, size_t n)
{
    char key[64], val[128];
    const double unset = (double)NAN;
    double ncols = -1, nrows = -1, x = unset, y = unset, cell = unset, dx = unset, dy = unset, v;
    int xcenter = 0, ycenter = 0;
    size_t pos = 0, count, i, len;
    r->format = EX_RIO_ASC;
    for (;;) {
        size_t save = pos;
        if (ex_rio_token(text, n, &pos, key, sizeof key) == 0) break;
        if (isdigit((unsigned char)key[0]) || key[0] == '-' || key[0] == '+' || key[0] == '.') {
            pos = save;
            break;
        }
        len = ex_rio_token(text, n, &pos, val, sizeof val);
        if (len == 0 || len >= sizeof val || ex_rio_number(val, &v) != 0)
            return ex_rio_fail(r->err, "ASC header key '%s' without a number", key);
        if (ex_rio_keyeq(key, "ncols")) ncols = v;
        else if (ex_rio_keyeq(key, "nrows")) nrows = v;
        else if (ex_rio_keyeq(key, "xllcorner")) x = v;
        else if (ex_rio_keyeq(key, "yllcorner")) y = v;
        else if (ex_rio_keyeq(key, "xllcenter")) { x = v; xcenter = 1; }
        else if (ex_rio_keyeq(key, "yllcenter")) { y = v; ycenter = 1; }
        else if (ex_rio_keyeq(key, "cellsize")) cell = v;
        else if (ex_rio_keyeq(key, "dx")) dx = v;
        else if (ex_rio_keyeq(key, "dy")) dy = v;
        else if (ex_rio_keyeq(key, "nodata_value")) {
            if (ex_georef_set_nodata(&r->geo, val, strlen(val)) != 0) return ex_rio_fail(r->err, "bad NODATA_value");
        } else return ex_rio_fail(r->err, "unknown ASC header key '%s'", key);
    }
    if (!isnan(cell)) dx = dy = cell;
    if (!(ncols >= 1 && ncols <= EX_RIO_MAX_DIM && nrows >= 1 && nrows <= EX_RIO_MAX_DIM) ||
        ncols != floor(ncols) || nrows != floor(nrows))
        return ex_rio_fail(r->err, "ASC grid needs integer ncols and nrows in 1..%d", EX_RIO_MAX_DIM);
    if (isnan(x) || isnan(y) || !(dx > 0) || !(dy > 0) || !isfinite(x + y + dx + dy))
        return ex_rio_fail(r->err, "ASC grid needs xll*, yll* and a positive cellsize");
    r->width = (int)ncols;
    r->height = (int)nrows;
    /* every value takes at least 2 characters (digit and separator) */
    if ((uint64_t)r->width * (uint64_t)r->height > (uint64_t)(n / 2 + 1))
        return ex_rio_fail(r->err, "ASC grid of %d x %d values in %llu bytes: truncated", r->width, r->height,
                           (unsigned long long)n);
    count = (size_t)r->width * (size_t)r->height;
    r->bands = 1;
    r->kind = EX_RIO_FLOAT;
    r->bits = 32;
    r->geo.has_transform = 1;
    r->geo.gt[0] = x - (xcenter ? 0.5 * dx : 0.0);
    r->geo.gt[1] = dx;
    r->geo.gt[3] = y - (ycenter ? 0.5 * dy : 0.0) + dy * (double)r->height;
    r->geo.gt[5] = -dy;
    r->grid = (double *)malloc(count * sizeof(double));
    if (!r->grid) return ex_rio_fail(r->err, "out of memory");
    for (i = 0; i < count; i++) {
        if ((len = ex_rio_token(text, n, &pos, val, sizeof val)) == 0)
            return ex_rio_fail(r->err, "ASC grid ends after %llu of %llu values", (unsigned long long)i,
                               (unsigned long long)count);
        if (len >= sizeof val)
            return ex_rio_fail(r->err, "ASC value '%.24s...' is too long (%llu characters)", val, (unsigned long long)len);
        if (ex_rio_number(val, &v) != 0) return ex_rio_fail(r->err, "ASC value '%s' is not a number", val);
        r->grid[i] = v;
    }
    if (ex_rio_token(text, n, &pos, val, sizeof val) != 0)
        return ex_rio_fail(r->err, "ASC grid has more than %llu values", (unsigned long long)count);
    r->size = 0;
    return 0;
}

/* Parse an EHdr header (GDAL's upper-case keys or the ESRI .flt header); the data file size is
 * r->size. flt = the data file is a .flt (32-bit floats unless the header says otherwise). */
static inline int ex_rio_parse_hdr(ex_rio_reader *r, const char *text, size_t n, int flt)
{
    char key[64], val[128];
    double v, nrows = -1, ncols = -1, nbands = 1, nbits = flt ? 32 : 8, skip = 0, brb = -1, trb = -1, gap = 0;
    const double unset = (double)NAN;
    double ulx = unset, uly = unset, xdim = unset, ydim = unset, xll = unset, yll = unset, cell = unset;
    int layout = 0, kind = flt ? EX_RIO_FLOAT : EX_RIO_UINT, xcenter = 0, ycenter = 0; /* 0 BIL 1 BIP 2 BSQ */
    size_t pos = 0;
    uint64_t bytes, w, h, b, need;
    r->format = EX_RIO_EHDR;
    r->big_endian = 0;
    while (ex_rio_token(text, n, &pos, key, sizeof key) != 0) {
        size_t len = ex_rio_token(text, n, &pos, val, sizeof val);
        if (len == 0) return ex_rio_fail(r->err, ".hdr key '%s' without a value", key);
        if (len >= sizeof val) return ex_rio_fail(r->err, ".hdr value of '%s' is too long", key);
        if (ex_rio_keyeq(key, "byteorder")) {
            if (ex_rio_keyeq(val, "M") || ex_rio_keyeq(val, "MSBFIRST")) r->big_endian = 1;
            else if (ex_rio_keyeq(val, "I") || ex_rio_keyeq(val, "LSBFIRST")) r->big_endian = 0;
            else return ex_rio_fail(r->err, ".hdr BYTEORDER '%s' (I, M, LSBFIRST or MSBFIRST)", val);
        } else if (ex_rio_keyeq(key, "layout")) {
            if (ex_rio_keyeq(val, "BIL")) layout = 0;
            else if (ex_rio_keyeq(val, "BIP")) layout = 1;
            else if (ex_rio_keyeq(val, "BSQ")) layout = 2;
            else return ex_rio_fail(r->err, ".hdr LAYOUT '%s' (BIL, BIP or BSQ)", val);
        } else if (ex_rio_keyeq(key, "pixeltype")) {
            if (ex_rio_keyeq(val, "FLOAT")) kind = EX_RIO_FLOAT;
            else if (ex_rio_keyeq(val, "SIGNEDINT")) kind = EX_RIO_INT;
            else if (ex_rio_keyeq(val, "UNSIGNEDINT")) kind = EX_RIO_UINT;
            else return ex_rio_fail(r->err, ".hdr PIXELTYPE '%s' is not supported", val);
        } else if (ex_rio_keyeq(key, "nodata") || ex_rio_keyeq(key, "nodata_value")) {
            if (ex_georef_set_nodata(&r->geo, val, strlen(val)) != 0) return ex_rio_fail(r->err, "bad .hdr NODATA");
        } else {
            if (ex_rio_number(val, &v) != 0) {
                if (ex_rio_keyeq(key, "projection") || ex_rio_keyeq(key, "datum") || ex_rio_keyeq(key, "units") ||
                    ex_rio_keyeq(key, "spheroid"))
                    continue;
                return ex_rio_fail(r->err, ".hdr key '%s' has a non-numeric value '%s'", key, val);
            }
            if (ex_rio_keyeq(key, "nrows")) nrows = v;
            else if (ex_rio_keyeq(key, "ncols")) ncols = v;
            else if (ex_rio_keyeq(key, "nbands")) nbands = v;
            else if (ex_rio_keyeq(key, "nbits")) nbits = v;
            else if (ex_rio_keyeq(key, "skipbytes")) skip = v;
            else if (ex_rio_keyeq(key, "bandrowbytes")) brb = v;
            else if (ex_rio_keyeq(key, "totalrowbytes")) trb = v;
            else if (ex_rio_keyeq(key, "bandgapbytes")) gap = v;
            else if (ex_rio_keyeq(key, "ulxmap")) ulx = v;
            else if (ex_rio_keyeq(key, "ulymap")) uly = v;
            else if (ex_rio_keyeq(key, "xdim")) xdim = v;
            else if (ex_rio_keyeq(key, "ydim")) ydim = v;
            else if (ex_rio_keyeq(key, "xllcorner")) xll = v;
            else if (ex_rio_keyeq(key, "yllcorner")) yll = v;
            else if (ex_rio_keyeq(key, "xllcenter")) { xll = v; xcenter = 1; }
            else if (ex_rio_keyeq(key, "yllcenter")) { yll = v; ycenter = 1; }
            else if (ex_rio_keyeq(key, "cellsize")) cell = v;
            /* other keys (e.g. BANDGAPBYTES of BSQ, statistics) are ignored */
        }
    }
    if (!(nrows >= 1 && nrows <= EX_RIO_MAX_DIM && ncols >= 1 && ncols <= EX_RIO_MAX_DIM && nbands >= 1 &&
          nbands <= EX_RIO_MAX_BANDS) || nrows != floor(nrows) || ncols != floor(ncols) || nbands != floor(nbands))
        return ex_rio_fail(r->err, ".hdr needs integer NROWS, NCOLS in 1..%d and NBANDS in 1..%d", EX_RIO_MAX_DIM,
                           EX_RIO_MAX_BANDS);
    if (kind == EX_RIO_FLOAT ? (nbits != 32 && nbits != 64) : (nbits != 8 && nbits != 16 && nbits != 32))
        return ex_rio_fail(r->err, "%g-bit %s .hdr samples are not supported", nbits,
                           kind == EX_RIO_FLOAT ? "float" : "integer");
    if (!(skip >= 0 && skip < 9e15 && gap >= 0 && gap < 9e15) || (brb != -1 && !(brb >= 0 && brb < 9e15)) ||
        (trb != -1 && !(trb >= 0 && trb < 9e15)))
        return ex_rio_fail(r->err, ".hdr with invalid SKIPBYTES, BANDROWBYTES, TOTALROWBYTES or BANDGAPBYTES");
    r->width = (int)ncols;
    r->height = (int)nrows;
    r->bands = (int)nbands;
    r->kind = kind;
    r->bits = (int)nbits;
    w = (uint64_t)r->width;
    h = (uint64_t)r->height;
    b = (uint64_t)r->bands;
    bytes = (uint64_t)r->bits / 8u;
    r->skip = (uint64_t)skip;
    /* BANDROWBYTES and TOTALROWBYTES may pad rows, never cut them (rows would overlap) */
    if ((layout != 1 && brb >= 0 && (uint64_t)brb < w * bytes) ||
        (layout != 2 && trb >= 0 && (uint64_t)trb < (layout == 0 && brb >= 0 ? (uint64_t)brb * (b - 1) + w * bytes
                                                                              : w * bytes * b)))
        return ex_rio_fail(r->err, ".hdr BANDROWBYTES %g or TOTALROWBYTES %g is shorter than a row of %llu bytes",
                           brb, trb, (unsigned long long)(w * bytes * (layout == 2 ? 1 : b)));
    if (layout == 0) { /* BIL: row of band 0, row of band 1, ... */
        r->col_bytes = bytes;
        r->band_bytes = brb >= 0 ? (uint64_t)brb : w * bytes;
        r->row_bytes = trb >= 0 ? (uint64_t)trb : r->band_bytes * b;
    } else if (layout == 1) { /* BIP: samples interleaved */
        r->col_bytes = bytes * b;
        r->band_bytes = bytes;
        r->row_bytes = trb >= 0 ? (uint64_t)trb : w * bytes * b;
    } else { /* BSQ: whole bands */
        r->col_bytes = bytes;
        r->row_bytes = brb >= 0 ? (uint64_t)brb : w * bytes;
        r->band_bytes = r->row_bytes * h + (uint64_t)gap;
    }
    /* the last sample must lie in the data file (all products < 2^31 * 2^31 * 2^16 fit 2^64?
     * not always: check each step) */
    if (h - 1 > (UINT64_MAX / 2) / (r->row_bytes + 1) || b - 1 > (UINT64_MAX / 4) / (r->band_bytes + 1) ||
        w - 1 > (UINT64_MAX / 8) / (r->col_bytes + 1))
        return ex_rio_fail(r->err, ".hdr layout overflows");
    need = r->skip + (h - 1) * r->row_bytes + (b - 1) * r->band_bytes + (w - 1) * r->col_bytes + bytes;
    if (need < r->skip || need > r->size)
        return ex_rio_fail(r->err, "raw data file holds %llu bytes, the .hdr describes %llu", (unsigned long long)r->size,
                           (unsigned long long)need);
    /* A cell size that is given must be usable (not silently cell 1): XDIM and YDIM nonzero and
     * finite (a negative YDIM is a raster stored south-up and a negative XDIM one stored east to
     * west, as GDAL reads them: ex_georef_orient), cellsize positive. */
    if ((!isnan(xdim) || !isnan(ydim)) && !(isfinite(xdim) && isfinite(ydim) && xdim != 0.0 && ydim != 0.0))
        return ex_rio_fail(r->err, ".hdr XDIM %g YDIM %g: both must be given and nonzero", xdim, ydim);
    if (!isnan(cell) && !(cell > 0.0 && isfinite(cell)))
        return ex_rio_fail(r->err, ".hdr cellsize %g: must be positive", cell);
    if (!isnan(ulx) && !isnan(uly) && !isnan(xdim)) {
        r->geo.has_transform = 1;
        r->geo.gt[0] = ulx - 0.5 * xdim; /* ULXMAP/ULYMAP name the centre of the first cell */
        r->geo.gt[1] = xdim;
        r->geo.gt[3] = uly + 0.5 * ydim;
        r->geo.gt[5] = -ydim;
        ex_georef_orient(&r->geo, r->width, r->height);
    } else if (!isnan(xll) && !isnan(yll) && cell > 0) {
        r->geo.has_transform = 1;
        r->geo.gt[0] = xll - (xcenter ? 0.5 * cell : 0.0);
        r->geo.gt[1] = cell;
        r->geo.gt[3] = yll - (ycenter ? 0.5 * cell : 0.0) + cell * (double)r->height;
        r->geo.gt[5] = -cell;
    }
    return 0;
}

/* CRS kind from .prj WKT. */
static inline void ex_rio_prj_crs(ex_georef *g)
{
    int crs = ex_rio_wkt_crs(g->prj);
    if (crs != EX_RIO_CRS_UNKNOWN) g->crs = crs;
}

/* ------------------------------------------------------------------------------------------ */
/* 7. reading                                                                                 */
/* ------------------------------------------------------------------------------------------ */

static inline void ex_rio_close(ex_rio_reader *r)
{
    if (r->f) fclose(r->f);
    free(r->offsets);
    free(r->counts);
    free(r->grid);
    free(r->cbuf);
    free(r->dbuf);
    ex_georef_free(&r->geo);
    memset(r, 0, sizeof *r);
}

/* Close a reader whose opening failed, keeping its error message. */
static inline void ex_rio_close_failed(ex_rio_reader *r)
{
    char keep[256];
    memcpy(keep, r->err, sizeof keep);
    ex_rio_close(r);
    memcpy(r->err, keep, sizeof keep);
}

static inline int ex_rio_ext(const char *path, const char *ext)
{
    size_t n = strlen(path), e = strlen(ext);
    return n >= e && ex_rio_keyeq(path + n - e, ext);
}

/* The format a path names by its extension: EX_RIO_TIFF (.tif .tiff), EX_RIO_ASC (.asc),
 * EX_RIO_EHDR (.bil .flt .bip .bsq), else 0. */
static inline int ex_rio_format_of(const char *path)
{
    if (ex_rio_ext(path, ".tif") || ex_rio_ext(path, ".tiff")) return EX_RIO_TIFF;
    if (ex_rio_ext(path, ".asc")) return EX_RIO_ASC;
    if (ex_rio_ext(path, ".bil") || ex_rio_ext(path, ".flt") || ex_rio_ext(path, ".bip") || ex_rio_ext(path, ".bsq"))
        return EX_RIO_EHDR;
    return 0;
}

/* A sidecar path: path with its extension replaced by ext (allocated). */
static inline char *ex_rio_sidecar(const char *path, const char *ext)
{
    const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
    size_t base = dot && (!slash || dot > slash) ? (size_t)(dot - path) : strlen(path);
    char *s = (char *)malloc(base + strlen(ext) + 1);
    if (!s) return NULL;
    memcpy(s, path, base);
    strcpy(s + base, ext);
    return s;
}

/* Read a whole small text file (at most EX_RIO_MAX_HEADER or, for ASC, any size); NULL and
 * *n = 0 when absent. */
static inline char *ex_rio_slurp(const char *path, size_t max, size_t *n)
{
    FILE *f = fopen(path, "rb");
    char *s = NULL;
    long len;
    *n = 0;
    if (!f) return NULL;
    if (fseek(f, 0, SEEK_END) == 0 && (len = ftell(f)) >= 0 && (unsigned long)len <= max &&
        fseek(f, 0, SEEK_SET) == 0 && (s = (char *)malloc((size_t)len + 1)) != NULL) {
        if (fread(s, 1, (size_t)len, f) == (size_t)len) {
            s[len] = '\0';
            *n = (size_t)len;
        } else {
            free(s);
            s = NULL;
        }
    }
    fclose(f);
    return s;
}

/* Open a TIFF held in memory (data must outlive the reader). */
static inline int ex_rio_open_tiff_mem(ex_rio_reader *r, const unsigned char *data, size_t size)
{
    memset(r, 0, sizeof *r);
    r->mem = data;
    r->size = size;
    return ex_rio_tiff_parse(r);
}

/* Parse an ASC grid held in memory. */
static inline int ex_rio_open_asc_mem(ex_rio_reader *r, const char *text, size_t size)
{
    memset(r, 0, sizeof *r);
    return ex_rio_parse_asc(r, text, size);
}

/* Open an EHdr raster from its header text and the data bytes in memory. */
static inline int ex_rio_open_ehdr_mem(ex_rio_reader *r, const char *hdr, size_t hdr_len,
                                       const unsigned char *data, size_t size, int flt)
{
    memset(r, 0, sizeof *r);
    r->mem = data ? data : (const unsigned char *)"";
    r->size = size;
    return ex_rio_parse_hdr(r, hdr, hdr_len, flt);
}

/* Open path by its extension (.tif/.tiff, .asc + .prj, .bil/.flt/.bip/.bsq + .hdr [+ .prj]).
 * 0, or -1 with r->err (the reader is then closed already). */
static inline int ex_rio_open(ex_rio_reader *r, const char *path)
{
    int fmt = ex_rio_format_of(path), rc = -1;
    char *side = NULL, *text = NULL;
    size_t n = 0;
    long len;
    memset(r, 0, sizeof *r);
    if (!fmt) return ex_rio_fail(r->err, "not a raster extension (.tif .tiff .asc .bil .flt)");
    if (fmt == EX_RIO_ASC) {
        FILE *f = fopen(path, "rb");
        if (!f) return ex_rio_fail(r->err, "cannot open");
        if (fseek(f, 0, SEEK_END) != 0 || (len = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) {
            fclose(f);
            return ex_rio_fail(r->err, "cannot read");
        }
        text = (char *)malloc((size_t)len + 1);
        if (!text || fread(text, 1, (size_t)len, f) != (size_t)len) {
            fclose(f);
            free(text);
            return ex_rio_fail(r->err, text ? "cannot read" : "out of memory");
        }
        fclose(f);
        rc = ex_rio_parse_asc(r, text, (size_t)len);
        free(text);
    } else {
        r->f = fopen(path, "rb");
        if (!r->f) return ex_rio_fail(r->err, "cannot open");
        if (fseek(r->f, 0, SEEK_END) != 0 || (len = ftell(r->f)) < 0) {
            ex_rio_close(r);
            return ex_rio_fail(r->err, "cannot read");
        }
        r->size = (uint64_t)len;
        if (fmt == EX_RIO_TIFF) {
            rc = ex_rio_tiff_parse(r);
        } else {
            side = ex_rio_sidecar(path, ".hdr");
            text = side ? ex_rio_slurp(side, EX_RIO_MAX_HEADER, &n) : NULL;
            if (!text) rc = ex_rio_fail(r->err, "cannot read its header %s", side ? side : ".hdr");
            else rc = ex_rio_parse_hdr(r, text, n, ex_rio_ext(path, ".flt"));
            free(side);
            free(text);
        }
    }
    if (rc == 0 && fmt != EX_RIO_TIFF) {
        side = ex_rio_sidecar(path, ".prj");
        if (side) r->geo.prj = ex_rio_slurp(side, EX_RIO_MAX_HEADER, &n);
        free(side);
        ex_rio_prj_crs(&r->geo);
    }
    if (rc != 0) ex_rio_close_failed(r);
    return rc;
}

/* Parse a PFM (Pf grey, PF colour: 3 bands) or binary PGM (P5) header from head[0..n) (the
 * file's first bytes; r->size, r->f or r->mem set): magic, width, height, scale or maxval, '#'
 * comments as netpbm allows, one whitespace byte before the samples. ex_rio_read then seeks to
 * the rows a window needs (PFM rows are stored bottom to top). Values as hfvis_image_decode
 * gives them: PFM samples as stored, PGM samples as the integers 0..maxval. No georeference. */
static inline int ex_rio_netpbm_parse(ex_rio_reader *r, const unsigned char *head, size_t n)
{
    size_t i = 2;
    double v[3];
    int k, pfm = n >= 2 && head[0] == 'P' && (head[1] == 'f' || head[1] == 'F');
    if (n < 2 || head[0] != 'P' || !(pfm || head[1] == '5'))
        return ex_rio_fail(r->err, "not a PFM or binary (P5) PGM: windows are read from those, GeoTIFF or EHdr");
    for (k = 0; k < 3; k++) { /* width, height, then the scale (PFM) or maxval (PGM) */
        char tok[64];
        size_t t = 0;
        while (i < n && (isspace(head[i]) || head[i] == '#')) {
            if (head[i] == '#') while (i < n && head[i] != '\n' && head[i] != '\r') i++;
            else i++;
        }
        while (i < n && !isspace(head[i]) && head[i] != '#' && t + 1 < sizeof tok) tok[t++] = (char)head[i++];
        tok[t] = '\0';
        if (k < 2 && strspn(tok, "0123456789") != t) t = 0; /* the sizes: decimal digits only */
        if (!t || ex_rio_number(tok, &v[k]) != 0 || (k < 2 && !(v[k] >= 1.0 && v[k] <= EX_RIO_MAX_DIM && v[k] == floor(v[k]))))
            return ex_rio_fail(r->err, "bad or truncated header");
    }
    if (i >= n || !isspace(head[i]) || (pfm ? !(v[2] != 0.0 && isfinite(v[2])) : !(v[2] >= 1.0 && v[2] <= 65535.0)))
        return ex_rio_fail(r->err, "bad or truncated header");
    r->format = EX_RIO_NETPBM;
    r->width = (int)v[0];
    r->height = (int)v[1];
    r->bands = pfm && head[1] == 'F' ? 3 : 1;
    r->kind = pfm ? EX_RIO_FLOAT : EX_RIO_UINT;
    r->bits = pfm ? 32 : v[2] < 256.0 ? 8 : 16;
    r->big_endian = pfm ? v[2] > 0.0 : 1;
    r->rows_up = pfm;
    r->maxval = pfm ? 0.0 : v[2];
    r->skip = (uint64_t)i + 1;
    r->band_bytes = (uint64_t)(r->bits / 8);
    r->col_bytes = r->band_bytes * (uint64_t)r->bands;
    r->row_bytes = r->col_bytes * (uint64_t)r->width;
    if (r->size < r->skip || (r->size - r->skip) / r->row_bytes < (uint64_t)r->height)
        return ex_rio_fail(r->err, "truncated: the header announces %d x %d samples", r->width, r->height);
    return 0;
}

/* Open a PFM or binary PGM held in memory for window reads (data must outlive the reader). */
static inline int ex_rio_open_netpbm_mem(ex_rio_reader *r, const unsigned char *data, size_t size)
{
    int rc;
    memset(r, 0, sizeof *r);
    r->mem = data ? data : (const unsigned char *)"";
    r->size = data ? size : 0;
    rc = ex_rio_netpbm_parse(r, r->mem, (size_t)r->size < 4096 ? (size_t)r->size : 4096);
    if (rc != 0) ex_rio_close_failed(r);
    return rc;
}

/* Open a PFM or binary PGM file for window reads: its first 4 KiB are parsed, nothing else read. */
static inline int ex_rio_open_netpbm(ex_rio_reader *r, const char *path)
{
    unsigned char head[4096];
    size_t n;
    long len;
    int rc;
    memset(r, 0, sizeof *r);
    r->f = fopen(path, "rb");
    if (!r->f) return ex_rio_fail(r->err, "cannot open");
    n = fread(head, 1, sizeof head, r->f);
    if (fseek(r->f, 0, SEEK_END) != 0 || (len = ftell(r->f)) < 0) {
        ex_rio_close(r);
        return ex_rio_fail(r->err, "cannot read");
    }
    r->size = (uint64_t)len;
    rc = ex_rio_netpbm_parse(r, head, n);
    if (rc != 0) ex_rio_close_failed(r);
    return rc;
}

/* Move the georeference to the window whose first cell is (dx, dy) of the raster: the
 * geotransform, and the GeoTIFF tags written verbatim (tie points name raster cells, shifted by
 * whole cells; a ModelTransformation's translation), so a window written as a piece lands where
 * its cells lay in the whole raster. */
static inline void ex_georef_shift(ex_georef *g, int dx, int dy)
{
    size_t k;
    if (!g->has_transform) return;
    g->gt[0] += (double)dx * g->gt[1] + (double)dy * g->gt[2];
    g->gt[3] += (double)dx * g->gt[4] + (double)dy * g->gt[5];
    for (k = 0; k + 6 <= g->n_tiepoints; k += 6) {
        g->tiepoints[k] -= (double)dx;
        g->tiepoints[k + 1] -= (double)dy;
    }
    if (g->has_matrix) {
        g->matrix[3] += (double)dx * g->matrix[0] + (double)dy * g->matrix[1];
        g->matrix[7] += (double)dx * g->matrix[4] + (double)dy * g->matrix[5];
    }
}

/* The band exists and the window is not empty; 0, or -1 with r->err. */
static inline int ex_rio_window_check(ex_rio_reader *r, int band, int w, int h, ptrdiff_t stride)
{
    if (band < 0 || band >= r->bands) return ex_rio_fail(r->err, "band %d does not exist (the raster has %d)",
                                                         band + 1, r->bands);
    if (w < 1 || h < 1 || stride < w) return ex_rio_fail(r->err, "empty window");
    return 0;
}

/* Decode band (0-based) of the window [x0, x0 + w) x [y0, y0 + h) into out (row stride in
 * floats); cells outside the raster are NaN. Only the strips/tiles (or raw rows) the window
 * touches are read. 0, or -1 with r->err. */
static inline int ex_rio_read_stored(ex_rio_reader *r, int band, int x0, int y0, int w, int h, float *out,
                                     ptrdiff_t stride)
{
    long long yy, xx;
    int bytes = r->bits / 8;
    if (ex_rio_window_check(r, band, w, h, stride) != 0) return -1;
    for (yy = 0; yy < h; yy++) {
        float *o = out + (ptrdiff_t)yy * stride;
        for (xx = 0; xx < w; xx++) o[xx] = (float)NAN;
    }
    {
        long long cx0 = x0 < 0 ? 0 : x0, cy0 = y0 < 0 ? 0 : y0;
        long long cx1 = (long long)x0 + w > r->width ? r->width : (long long)x0 + w;
        long long cy1 = (long long)y0 + h > r->height ? r->height : (long long)y0 + h;
        if (cx0 >= cx1 || cy0 >= cy1) return 0;
        if (r->format == EX_RIO_ASC) {
            for (yy = cy0; yy < cy1; yy++)
                for (xx = cx0; xx < cx1; xx++)
                    out[(ptrdiff_t)(yy - y0) * stride + (ptrdiff_t)(xx - x0)] =
                        ex_rio_cell(r, r->grid[(size_t)yy * (size_t)r->width + (size_t)xx]);
            return 0;
        }
        if (r->format == EX_RIO_EHDR || r->format == EX_RIO_NETPBM) {
            size_t n = (size_t)(cx1 - cx0), need = (size_t)((n - 1) * r->col_bytes + (uint64_t)bytes);
            const int direct = r->kind == EX_RIO_FLOAT && bytes == 4 && r->col_bytes == 4 &&
                               r->big_endian == ex_rio_host_big_endian();
            if (!direct && ex_rio_grow(&r->dbuf, &r->dbuf_cap, need) != 0) return ex_rio_fail(r->err, "out of memory");
            for (yy = cy0; yy < cy1; yy++) {
                uint64_t fy = r->rows_up ? (uint64_t)(r->height - 1 - yy) : (uint64_t)yy;
                uint64_t off = r->skip + fy * r->row_bytes + (uint64_t)band * r->band_bytes +
                               (uint64_t)cx0 * r->col_bytes;
                if (direct) { /* PFM, .flt: the bytes are the floats, fetched into place */
                    float *o = out + (ptrdiff_t)(yy - y0) * stride + (ptrdiff_t)(cx0 - x0);
                    if (ex_rio_fetch(r, off, need, o) != 0) return ex_rio_fail(r->err, "cannot read row %lld", yy);
                    for (xx = 0; xx < cx1 - cx0; xx++) o[xx] = ex_rio_cell(r, (double)o[xx]);
                    continue;
                }
                if (ex_rio_fetch(r, off, need, r->dbuf) != 0) return ex_rio_fail(r->err, "cannot read row %lld", yy);
                for (xx = cx0; xx < cx1; xx++)
                    out[(ptrdiff_t)(yy - y0) * stride + (ptrdiff_t)(xx - x0)] = ex_rio_cell(
                        r, ex_rio_sample(r->dbuf + (size_t)(xx - cx0) * (size_t)r->col_bytes, r->kind, r->bits,
                                         r->big_endian));
            }
            return 0;
        }
        {
            uint64_t spc = r->planar == 2 ? 1 : (uint64_t)r->bands, a, d;
            uint64_t plane = r->planar == 2 ? (uint64_t)band * r->across * r->down : 0;
            size_t sel = r->planar == 2 ? 0 : (size_t)band;
            for (d = (uint64_t)cy0 / r->chunk_h; d <= (uint64_t)(cy1 - 1) / r->chunk_h; d++) {
                long long ry0 = (long long)(d * r->chunk_h), rows = r->chunk_h;
                if (!r->tiled && ry0 + rows > r->height) rows = r->height - ry0;
                for (a = (uint64_t)cx0 / r->chunk_w; a <= (uint64_t)(cx1 - 1) / r->chunk_w; a++) {
                    long long rx0 = (long long)(a * r->chunk_w);
                    long long ya = ry0 > cy0 ? ry0 : cy0, yb = ry0 + rows < cy1 ? ry0 + rows : cy1;
                    long long xa = rx0 > cx0 ? rx0 : cx0, xb = rx0 + (long long)r->chunk_w < cx1 ? rx0 + r->chunk_w : cx1;
                    size_t rowb = (size_t)r->chunk_w * (size_t)spc * (size_t)bytes;
                    if (ex_rio_chunk(r, plane + d * r->across + a, (uint64_t)rows, spc) != 0) return -1;
                    for (yy = ya; yy < yb; yy++) {
                        const unsigned char *src = r->dbuf + (size_t)(yy - ry0) * rowb;
                        float *o = out + (ptrdiff_t)(yy - y0) * stride;
                        if (r->kind == EX_RIO_FLOAT && r->bits == 32) /* the usual DEM: ex_rio_sample's
                                                                           value, its branches hoisted */
                            for (xx = xa; xx < xb; xx++) {
                                const unsigned char *p = src + ((size_t)(xx - rx0) * (size_t)spc + sel) * 4u;
                                o[xx - x0] = ex_rio_cell(r, (double)ex_rio_bits_float((uint32_t)ex_rio_uint(p, 4, r->cached_be)));
                            }
                        else
                            for (xx = xa; xx < xb; xx++)
                                o[xx - x0] = ex_rio_cell(
                                    r, ex_rio_sample(src + ((size_t)(xx - rx0) * (size_t)spc + sel) * (size_t)bytes,
                                                     r->kind, r->bits, r->cached_be));
                    }
                }
            }
        }
    }
    return 0;
}

/* A window read in the file's orientation put north-up, west to east (ex_georef_orient): its
 * rows and columns reversed in place as the file's flags say. */
static inline void ex_rio_unflip(const ex_rio_reader *r, int w, int h, float *out, ptrdiff_t stride)
{
    int fx = r->geo.flip_x, fy = r->geo.flip_y, y, x;
    if (fy && w >= 1 && stride >= w)
        for (y = 0; y < h / 2; y++) {
            float *a = out + (ptrdiff_t)y * stride, *b = out + (ptrdiff_t)(h - 1 - y) * stride;
            for (x = 0; x < w; x++) {
                float t = a[x];
                a[x] = b[x];
                b[x] = t;
            }
        }
    if (fx && w >= 1 && stride >= w)
        for (y = 0; y < h; y++) {
            float *a = out + (ptrdiff_t)y * stride;
            for (x = 0; x < w / 2; x++) {
                float t = a[x];
                a[x] = a[w - 1 - x];
                a[w - 1 - x] = t;
            }
        }
}

/* The origin in the file's orientation of the north-up window at (x0, y0), w x h: mirrored as
 * the file's flags say, in long long (far outside the raster it may leave int). */
static inline void ex_rio_stored_origin(const ex_rio_reader *r, int x0, int y0, int w, int h, long long *sx,
                                        long long *sy)
{
    *sx = r->geo.flip_x ? (long long)r->width - x0 - w : x0;
    *sy = r->geo.flip_y ? (long long)r->height - y0 - h : y0;
}

/* ex_rio_read: the window of the north-up raster (ex_georef_orient) from the file's orientation:
 * the mirrored window, then its rows and columns reversed in place. */
static inline int ex_rio_read(ex_rio_reader *r, int band, int x0, int y0, int w, int h, float *out,
                              ptrdiff_t stride)
{
    long long sx, sy;
    ex_rio_stored_origin(r, x0, y0, w, h, &sx, &sy);
    if (ex_rio_read_stored(r, band, (int)sx, (int)sy, w, h, out, stride) != 0) return -1;
    ex_rio_unflip(r, w, h, out, stride);
    return 0;
}

/* Parts of one ex_rio_read_parallel: a few for each thread of a large machine. */
#define EX_RIO_READ_PARTS 64

typedef struct {
    const ex_rio_reader *r;  /* the opened reader: its layout, georeference and ASC grid shared */
    const char *path;        /* reopened by each part that reads a file */
    ex_rio_reader *part;     /* per part: the shared layout, its own file, buffers and message */
    int *rows;               /* part i reads stored rows [rows[i], rows[i + 1]) */
    int *rc;                 /* per part: 1 not run, 0 read, -1 failed (its message in part[i].err) */
    int band, x0, y0, w;
    float *out;
    ptrdiff_t stride;
} ex_rio_read_job;

static inline int ex_rio_read_part(void *ctx, size_t i)
{
    ex_rio_read_job *j = (ex_rio_read_job *)ctx;
    ex_rio_reader *p = &j->part[i];
    int y0 = j->rows[i], n = j->rows[i + 1] - y0;
    if (n < 1) return j->rc[i] = 0;
    *p = *j->r;
    p->f = NULL;
    p->cbuf = p->dbuf = NULL;
    p->cbuf_cap = p->dbuf_cap = 0;
    p->cached = 0;
    p->err[0] = '\0';
    if (j->r->f && !(p->f = fopen(j->path, "rb"))) {
        j->rc[i] = ex_rio_fail(p->err, "cannot open");
    } else {
        j->rc[i] = ex_rio_read_stored(p, j->band, j->x0, y0, j->w, n, j->out + (ptrdiff_t)(y0 - j->y0) * j->stride,
                                      j->stride);
        if (p->f) fclose(p->f);
    }
    free(p->cbuf);
    free(p->dbuf);
    return 0; /* every part runs: the message is then the first failing part's, whatever the order */
}

/* ex_rio_read with the rows cut into parts that parallel(user, n, fn, ctx) runs, in any order or
 * at once (the writer's runner, ex_rio_write_options.parallel): each part reads its rows through
 * its own copy of the reader (a file reader's part reopens path, which must be the file r was
 * opened from), so a part's pages are first touched and its chunks decoded by the thread that runs
 * it. A TIFF's parts end at strip or tile rows (each chunk decoded once). The same floats as
 * ex_rio_read; on failure r->err holds the first failing part's message. parallel NULL:
 * ex_rio_read. */
static inline int ex_rio_read_parallel(ex_rio_reader *r, const char *path, int band, int x0, int y0, int w, int h,
                                       float *out, ptrdiff_t stride,
                                       int (*parallel)(void *user, size_t n, int (*fn)(void *ctx, size_t i),
                                                       void *ctx),
                                       void *user)
{
    ex_rio_read_job j;
    long long unit = r->format == EX_RIO_TIFF ? (long long)r->chunk_h : 1, sy0, cut;
    long long sx, sy;
    int n = EX_RIO_READ_PARTS, i, rc = 0, ran;
    ex_rio_stored_origin(r, x0, y0, w, h, &sx, &sy);
    if (!parallel || (r->f && !path) || sx < INT_MIN || sx + w > INT_MAX || sy < INT_MIN || sy + h > INT_MAX)
        return ex_rio_read(r, band, x0, y0, w, h, out, stride); /* part rows must stay ints */
    if (ex_rio_window_check(r, band, w, h, stride) != 0) return -1;
    x0 = (int)sx;
    y0 = (int)sy;
    if (n > h) n = h;
    memset(&j, 0, sizeof j);
    j.part = (ex_rio_reader *)calloc((size_t)n, sizeof *j.part);
    j.rows = (int *)malloc(((size_t)n + 1) * sizeof *j.rows);
    j.rc = (int *)malloc((size_t)n * sizeof *j.rc);
    if (!j.part || !j.rows || !j.rc) {
        free(j.part);
        free(j.rows);
        free(j.rc);
        return ex_rio_fail(r->err, "out of memory");
    }
    j.rows[0] = y0;
    for (i = 1; i < n; i++) { /* an even share of the rows, moved up to the next chunk row */
        sy0 = (long long)y0 + (long long)h * i / n;
        cut = sy0 >= 0 ? (sy0 + unit - 1) / unit * unit : sy0;
        if (cut > (long long)y0 + h) cut = (long long)y0 + h;
        j.rows[i] = cut > j.rows[i - 1] ? (int)cut : j.rows[i - 1];
    }
    j.rows[n] = y0 + h;
    for (i = 0; i < n; i++) j.rc[i] = 1;
    j.r = r;
    j.path = path;
    j.band = band, j.x0 = x0, j.y0 = y0, j.w = w;
    j.out = out;
    j.stride = stride;
    ran = parallel(user, (size_t)n, ex_rio_read_part, &j);
    for (i = 0; i < n && rc == 0; i++)
        if (j.rc[i] < 0) rc = ex_rio_fail(r->err, "%s", j.part[i].err);
    for (i = 0; i < n && rc == 0; i++) /* a part the runner did not run (out of memory) */
        if (j.rc[i] != 0 || ran != 0) rc = ex_rio_fail(r->err, "the parallel read did not run every part");
    free(j.part);
    free(j.rows);
    free(j.rc);
    if (rc == 0) ex_rio_unflip(r, w, h, out, stride);
    return rc;
}

/* ------------------------------------------------------------------------------------------ */
/* 8. writing                                                                                 */
/* ------------------------------------------------------------------------------------------ */

/* One output sample: a float stored as the file's type. NaN (and, for integers, values outside
 * the type) become the NoData value when there is one; integers round to nearest. */
static inline void ex_rio_encode_sample(unsigned char *p, float v, int kind, int bits, int be, const ex_georef *g)
{
    uint64_t u;
    if (isnan(v) && g && g->has_nodata) {
        double nd = g->nodata;
        if (kind == EX_RIO_FLOAT) {
            if (bits == 32) { float f = (float)nd; uint32_t b; memcpy(&b, &f, 4); u = b; }
            else memcpy(&u, &nd, 8);
            ex_rio_put_uint(p, u, bits / 8, be);
            return;
        }
        v = (float)nd;
    }
    if (kind == EX_RIO_FLOAT) {
        if (bits == 32) { uint32_t b; memcpy(&b, &v, 4); u = b; }
        else { double d = (double)v; memcpy(&u, &d, 8); }
    } else {
        double lo = kind == EX_RIO_UINT ? 0.0 : -ldexp(1.0, bits - 1);
        double hi = kind == EX_RIO_UINT ? ldexp(1.0, bits) - 1.0 : ldexp(1.0, bits - 1) - 1.0;
        double d = isnan(v) ? 0.0 : floor((double)v + 0.5);
        if (d < lo) d = lo;
        if (d > hi) d = hi;
        u = (uint64_t)(int64_t)d;
    }
    ex_rio_put_uint(p, u, bits / 8, be);
}

/* Apply predictor 2 or 3 to one encoded row (the inverse of ex_rio_unpredict2/3). */
static inline void ex_rio_predict(unsigned char *row, unsigned char *tmp, size_t nsamp, int bytes, int pred, int be)
{
    size_t i, n = nsamp * (size_t)bytes;
    int b;
    if (pred == 2) {
        uint64_t mask = bytes == 8 ? ~(uint64_t)0 : (((uint64_t)1 << (8 * bytes)) - 1u);
        for (i = nsamp; i-- > 1;) {
            uint64_t a = ex_rio_uint(row + (i - 1) * (size_t)bytes, bytes, be);
            uint64_t c = ex_rio_uint(row + i * (size_t)bytes, bytes, be);
            ex_rio_put_uint(row + i * (size_t)bytes, (c - a) & mask, bytes, be);
        }
    } else if (pred == 3) {
        /* byte planes, then byte differences (libtiff fpDiff): most significant byte first in
         * a little-endian file, least significant first in a big-endian one (see ex_rio_chunk) */
        (void)be;
        for (i = 0; i < nsamp; i++)
            for (b = 0; b < bytes; b++)
                tmp[(size_t)b * nsamp + i] = row[i * (size_t)bytes + (size_t)(bytes - 1 - b)];
        memcpy(row, tmp, n);
        for (i = n; i-- > 1;) row[i] = (unsigned char)(row[i] - row[i - 1]);
    }
}

typedef struct {
    FILE *f;
    int be, big, ok;
    uint64_t pos;
} ex_rio_out;

static inline void ex_rio_emit(ex_rio_out *o, const void *p, size_t n)
{
    if (o->ok && n && HFVIS_FWRITE(p, 1, n, o->f) != n) o->ok = 0;
    o->pos += n;
}

static inline void ex_rio_emit_uint(ex_rio_out *o, uint64_t v, int n)
{
    unsigned char b[8];
    ex_rio_put_uint(b, v, n, o->be);
    ex_rio_emit(o, b, (size_t)n);
}

/* One IFD entry to write: inline values or an array stored after the IFD. */
typedef struct {
    unsigned tag, type;
    uint64_t count;
    const void *data; /* uint64_t[] for integer types, double[] for DOUBLE, char[] for ASCII */
} ex_rio_tag;

/* Bytes of one tag's values in the file. */
static inline uint64_t ex_rio_tag_bytes(const ex_rio_tag *t)
{
    return t->count * (uint64_t)ex_rio_type_size(t->type);
}

static inline void ex_rio_emit_values(ex_rio_out *o, const ex_rio_tag *t)
{
    uint64_t i;
    int n = ex_rio_type_size(t->type);
    for (i = 0; i < t->count; i++) {
        if (t->type == 2) ex_rio_emit(o, (const char *)t->data + i, 1);
        else if (t->type == 12) {
            uint64_t u;
            memcpy(&u, (const double *)t->data + i, 8);
            ex_rio_emit_uint(o, u, 8);
        } else ex_rio_emit_uint(o, ((const uint64_t *)t->data)[i], n);
    }
}

/* Append s to the growing text *buf (*len bytes used of *cap), XML-escaped when esc; 0, or -1
 * out of memory. */
static inline int ex_rio_cat(char **buf, size_t *len, size_t *cap, const char *s, int esc)
{
    for (; *s; s++) {
        const char *piece = NULL;
        char one[2];
        size_t n;
        if (esc && *s == '&') piece = "&amp;";
        else if (esc && *s == '<') piece = "&lt;";
        else if (esc && *s == '>') piece = "&gt;";
        else if (esc && *s == '"') piece = "&quot;";
        else {
            one[0] = *s;
            one[1] = '\0';
            piece = one;
        }
        n = strlen(piece);
        if (*len + n + 1 > *cap) {
            size_t nc = *cap ? *cap * 2 : 256;
            char *nb;
            while (nc < *len + n + 1) nc *= 2;
            nb = (char *)realloc(*buf, nc);
            if (!nb) return -1;
            *buf = nb;
            *cap = nc;
        }
        memcpy(*buf + *len, piece, n + 1);
        *len += n;
    }
    return 0;
}

/* One <Item name="NAME" [sample="S"] [role="ROLE"]>VALUE</Item> (sample 0-based, -1 none). */
static inline int ex_rio_xml_item(char **buf, size_t *len, size_t *cap, const char *name, int sample,
                                  const char *role, const char *value)
{
    char num[32];
    int bad = ex_rio_cat(buf, len, cap, "  <Item name=\"", 0) || ex_rio_cat(buf, len, cap, name, 1) ||
              ex_rio_cat(buf, len, cap, "\"", 0);
    if (!bad && sample >= 0) {
        snprintf(num, sizeof num, " sample=\"%d\"", sample);
        bad = ex_rio_cat(buf, len, cap, num, 0);
    }
    if (!bad && role)
        bad = ex_rio_cat(buf, len, cap, " role=\"", 0) || ex_rio_cat(buf, len, cap, role, 0) ||
              ex_rio_cat(buf, len, cap, "\"", 0);
    return bad || ex_rio_cat(buf, len, cap, ">", 0) || ex_rio_cat(buf, len, cap, value, 1) ||
           ex_rio_cat(buf, len, cap, "</Item>\n", 0) ? -1 : 0;
}

/* The GDAL_METADATA XML of the options' band names, unit and items for bands bands; *xml NULL
 * when there is none. 0, or -1 out of memory. */
static inline int ex_rio_gdal_metadata(const ex_rio_write_options *o, int bands, char **xml)
{
    size_t len = 0, cap = 0;
    int b, i, bad = 0, any = 0;
    *xml = NULL;
    bad = ex_rio_cat(xml, &len, &cap, "<GDALMetadata>\n", 0);
    for (i = 0; !bad && i < o->n_meta; i++)
        if (o->meta[i].band == 0 && o->meta[i].name && o->meta[i].value) {
            bad = ex_rio_xml_item(xml, &len, &cap, o->meta[i].name, -1, NULL, o->meta[i].value);
            any = 1;
        }
    for (b = 0; !bad && b < bands; b++) {
        if (o->band_names && o->band_names[b]) {
            bad = ex_rio_xml_item(xml, &len, &cap, "DESCRIPTION", b, "description", o->band_names[b]);
            any = 1;
        }
        if (!bad && o->unit && o->unit[0]) {
            bad = ex_rio_xml_item(xml, &len, &cap, "UNITTYPE", b, "unittype", o->unit);
            any = 1;
        }
        for (i = 0; !bad && i < o->n_meta; i++)
            if (o->meta[i].band == b + 1 && o->meta[i].name && o->meta[i].value) {
                bad = ex_rio_xml_item(xml, &len, &cap, o->meta[i].name, b, NULL, o->meta[i].value);
                any = 1;
            }
    }
    if (!bad) bad = ex_rio_cat(xml, &len, &cap, "</GDALMetadata>", 0);
    if (bad || !any) {
        free(*xml);
        *xml = NULL;
    }
    return bad ? -1 : 0;
}

/* The strips or tiles of one TIFF being written: chunk idx (band-major) encoded, predicted and
 * compressed into a buffer of its own, so that chunks can be made in any order or at once
 * (ex_rio_write_options.parallel). */
#define EX_RIO_WRITE_BATCH 64 /* chunks made before they are written: 16 MiB of 256^2 Float32 tiles */
typedef struct {
    const ex_rio_image *img;
    const ex_georef *geo;
    const ex_rio_write_options *opt;
    uint64_t cw, ch, across, per_plane, rowb, chunkb, first;
    int kind, bits, bytes, be, fx, fy;
    unsigned char *buf[EX_RIO_WRITE_BATCH];
    size_t len[EX_RIO_WRITE_BATCH];
} ex_rio_chunks;

static inline int ex_rio_chunk_make(void *ctx, size_t j)
{
    ex_rio_chunks *c = (ex_rio_chunks *)ctx;
    const ex_rio_image *img = c->img;
    uint64_t idx = c->first + j, b = idx / c->per_plane, k = idx % c->per_plane;
    uint64_t a = k % c->across, d = k / c->across, y, x, n = c->chunkb;
    unsigned char *chunk = (unsigned char *)malloc((size_t)c->chunkb), *tmp = NULL, *z = NULL;
    size_t zcap = 0, zn = 0;
    c->buf[j] = NULL;
    if (c->opt->deflate) {
        zcap = ex_deflate_bound((size_t)c->chunkb);
        tmp = (unsigned char *)malloc((size_t)c->rowb);
        z = (unsigned char *)malloc(zcap);
    }
    if (!chunk || (c->opt->deflate && (!tmp || !z))) {
        free(chunk); free(tmp); free(z);
        return -1;
    }
    for (y = 0; y < c->ch; y++) {
        unsigned char *row = chunk + y * c->rowb;
        uint64_t gy = d * c->ch + y;
        for (x = 0; x < c->cw; x++) {
            uint64_t gx = a * c->cw + x;
            float v = 0.0f;
            if (gx < (uint64_t)img->width && gy < (uint64_t)img->height) {
                uint64_t sx = c->fx ? (uint64_t)img->width - 1 - gx : gx;
                uint64_t sy = c->fy ? (uint64_t)img->height - 1 - gy : gy;
                v = img->data[(size_t)b * img->band_step + (size_t)sy * img->row_step + (size_t)sx * img->pixel_step];
            }
            ex_rio_encode_sample(row + x * (uint64_t)c->bytes, v, c->kind, c->bits, c->be, c->geo);
        }
        if (c->opt->deflate && c->opt->predictor >= 2)
            ex_rio_predict(row, tmp, (size_t)c->cw, c->bytes, c->opt->predictor, c->be);
    }
    if (!c->opt->tiled && (d + 1) * c->ch > (uint64_t)img->height) n = ((uint64_t)img->height - d * c->ch) * c->rowb;
    if (c->opt->deflate) {
        int rc = ex_deflate_zlib(chunk, (size_t)n, z, zcap, &zn);
        free(chunk);
        free(tmp);
        if (rc != 0) {
            free(z);
            return -1;
        }
        c->buf[j] = z;
        c->len[j] = zn;
    } else {
        c->buf[j] = chunk;
        c->len[j] = (size_t)n;
    }
    return 0;
}

/* Write img as a TIFF at path (atomically) with the georeference of geo (may be NULL). */
static inline int ex_rio_write_tiff_file(const char *path, const ex_rio_image *img, const ex_georef *geo,
                                         const ex_rio_write_options *opt_in, char *err)
{
    ex_rio_write_options opt;
    ex_rio_out o;
    ex_rio_tag tags[32];
    int nt = 0, bytes, i, kind, bits, spp = img->bands;
    uint64_t cw, ch, across, down, per_plane, nchunks, rowb, chunkb, raw_total, bound;
    uint64_t *offsets = NULL, *counts = NULL, u_w, u_h, u_bps[1], u_comp, u_photo = 1, u_spp, u_rps, u_cw, u_ch;
    uint64_t u_planar = spp > 1 ? 2 : 1, u_fmt, u_pred, *u_extra = NULL, *u_bpsv = NULL, *u_fmtv = NULL, *u_keys = NULL;
    uint64_t prj_keys[16];
    char *prj_ascii = NULL;
    size_t n_prj_keys = 0, n_prj_ascii = 0;
    char *tmpname = NULL, *xml = NULL;
    double tie[6], scale[3], mt[16];
    int fx = geo && geo->has_transform && geo->flip_x, fy = geo && geo->has_transform && geo->flip_y;
    int placed = geo && (geo->has_transform || geo->has_scale || geo->has_matrix);
    char nodata[64];
    uint64_t ifd_pos, data_end;
    int rc = -1;
    memset(&opt, 0, sizeof opt);
    if (opt_in) opt = *opt_in;
    kind = opt.kind ? opt.kind : EX_RIO_FLOAT;
    bits = opt.bits ? opt.bits : 32;
    if (kind == EX_RIO_FLOAT ? (bits != 32 && bits != 64) : (bits != 8 && bits != 16 && bits != 32))
        return ex_rio_fail(err, "cannot write %d-bit samples of kind %d", bits, kind);
    if (img->width < 1 || img->height < 1 || spp < 1 || spp > EX_RIO_MAX_BANDS || !img->data)
        return ex_rio_fail(err, "nothing to write");
    if (opt.predictor == 3 && kind != EX_RIO_FLOAT) return ex_rio_fail(err, "predictor 3 needs float samples");
    bytes = bits / 8;
    if (opt.tiled) {
        cw = ch = (uint64_t)(opt.tile_size > 0 ? opt.tile_size : 256);
        if (cw % 16 != 0) return ex_rio_fail(err, "tile size %llu is not a multiple of 16", (unsigned long long)cw);
    } else {
        cw = (uint64_t)img->width;
        ch = opt.rows_per_strip > 0 ? (uint64_t)opt.rows_per_strip : 65536u / ((uint64_t)img->width * (uint64_t)bytes) + 1;
        if (ch > (uint64_t)img->height) ch = (uint64_t)img->height;
    }
    across = ((uint64_t)img->width + cw - 1) / cw;
    down = ((uint64_t)img->height + ch - 1) / ch;
    per_plane = across * down;
    nchunks = per_plane * (uint64_t)spp;
    rowb = cw * (uint64_t)bytes;
    if (nchunks > EX_RIO_MAX_CHUNKS || rowb * ch > EX_RIO_MAX_CHUNK)
        return ex_rio_fail(err, "too many or too large strips/tiles");
    chunkb = rowb * ch;
    raw_total = chunkb * nchunks;
    if (ex_rio_gdal_metadata(&opt, spp, &xml) != 0) return ex_rio_fail(err, "out of memory");
    if (geo && !geo->n_geokeys && geo->prj) { /* a .prj's CRS as GeoKeys (ex_rio_prj_geokeys) */
        n_prj_keys = ex_rio_prj_geokeys(geo->prj, prj_keys, &prj_ascii, &n_prj_ascii);
        if (n_prj_keys == SIZE_MAX) {
            free(xml);
            return ex_rio_fail(err, "out of memory");
        }
    }
    /* the file size bound: header, data (deflate never exceeds ex_deflate_bound), IFD and arrays */
    bound = 16 + (opt.deflate ? ex_deflate_bound((size_t)chunkb) : chunkb) * nchunks + 16 * nchunks + 8192 +
            (geo ? 8 * (geo->n_tiepoints + geo->n_geodoubles) + 2 * geo->n_geokeys + geo->n_geoascii : 0) +
            2 * n_prj_keys + n_prj_ascii + (xml ? strlen(xml) + 2 : 0);
    (void)raw_total;
    memset(&o, 0, sizeof o);
    o.be = opt.big_endian;
    o.big = opt.bigtiff || bound > 0xffffffffu;
    offsets = (uint64_t *)malloc((size_t)nchunks * sizeof(uint64_t));
    counts = (uint64_t *)malloc((size_t)nchunks * sizeof(uint64_t));
    u_bpsv = (uint64_t *)malloc((size_t)spp * sizeof(uint64_t));
    u_fmtv = (uint64_t *)malloc((size_t)spp * sizeof(uint64_t));
    u_extra = (uint64_t *)calloc((size_t)spp, sizeof(uint64_t));
    if (!offsets || !counts || !u_bpsv || !u_fmtv || !u_extra) {
        ex_rio_fail(err, "out of memory");
        goto done;
    }
    o.f = ex_atomic_open(path, &tmpname);
    if (!o.f) {
        ex_rio_fail(err, "cannot create the file");
        goto done;
    }
    o.ok = 1;
    /* header (the IFD offset is patched at the end) */
    ex_rio_emit(&o, o.be ? "MM" : "II", 2);
    if (o.big) {
        ex_rio_emit_uint(&o, 43, 2);
        ex_rio_emit_uint(&o, 8, 2);
        ex_rio_emit_uint(&o, 0, 2);
        ex_rio_emit_uint(&o, 0, 8);
    } else {
        ex_rio_emit_uint(&o, 42, 2);
        ex_rio_emit_uint(&o, 0, 4);
    }
    /* the chunks, band by band (PlanarConfiguration 2), made a batch at a time (in parallel when
     * the options say how) and written in order */
    {
        ex_rio_chunks cs;
        uint64_t first;
        memset(&cs, 0, sizeof cs);
        cs.img = img; cs.geo = geo; cs.opt = &opt;
        cs.cw = cw; cs.ch = ch; cs.across = across; cs.per_plane = per_plane; cs.rowb = rowb; cs.chunkb = chunkb;
        cs.kind = kind; cs.bits = bits; cs.bytes = bytes; cs.be = o.be; cs.fx = fx; cs.fy = fy;
        for (first = 0; first < nchunks; first += EX_RIO_WRITE_BATCH) {
            size_t nb = nchunks - first < EX_RIO_WRITE_BATCH ? (size_t)(nchunks - first) : EX_RIO_WRITE_BATCH, j;
            int bad = 0;
            cs.first = first;
            if (opt.parallel) bad = opt.parallel(opt.parallel_user, nb, ex_rio_chunk_make, &cs) != 0;
            else
                for (j = 0; j < nb && !bad; j++) bad = ex_rio_chunk_make(&cs, j) != 0;
            for (j = 0; j < nb; j++) {
                if (!bad && !cs.buf[j]) bad = 1; /* a call that did not run or failed */
                if (!bad) {
                    offsets[first + j] = o.pos;
                    counts[first + j] = cs.len[j];
                    ex_rio_emit(&o, cs.buf[j], cs.len[j]);
                }
                free(cs.buf[j]);
                cs.buf[j] = NULL;
            }
            if (bad) {
                ex_rio_fail(err, "out of memory");
                goto fail;
            }
        }
    }
    if (o.pos & 1) ex_rio_emit(&o, "", 1); /* IFDs start on a word boundary */
    if (!o.big && o.pos > 0xffffffffu - 65536u) {
        ex_rio_fail(err, "file would exceed 4 GiB: write BigTIFF");
        goto fail;
    }
    /* the tags, in ascending order */
    u_w = (uint64_t)img->width;
    u_h = (uint64_t)img->height;
    u_bps[0] = (uint64_t)bits;
    for (i = 0; i < spp; i++) { u_bpsv[i] = (uint64_t)bits; u_fmtv[i] = (uint64_t)kind; }
    u_comp = opt.deflate ? 8 : 1;
    u_spp = (uint64_t)spp;
    u_rps = ch;
    u_cw = cw;
    u_ch = ch;
    u_fmt = (uint64_t)kind;
    u_pred = opt.deflate && opt.predictor >= 2 ? (uint64_t)opt.predictor : 1;
    (void)u_bps;
    (void)u_fmt;
#define EX_RIO_TAG(t, ty, c, d) do { tags[nt].tag = (t); tags[nt].type = (ty); tags[nt].count = (c); \
                                     tags[nt].data = (d); nt++; } while (0)
    EX_RIO_TAG(256, 4, 1, &u_w);
    EX_RIO_TAG(257, 4, 1, &u_h);
    EX_RIO_TAG(258, 3, (uint64_t)spp, u_bpsv);
    EX_RIO_TAG(259, 3, 1, &u_comp);
    EX_RIO_TAG(262, 3, 1, &u_photo);
    if (!opt.tiled) EX_RIO_TAG(273, o.big ? 16 : 4, nchunks, offsets);
    EX_RIO_TAG(277, 3, 1, &u_spp);
    if (!opt.tiled) {
        EX_RIO_TAG(278, 4, 1, &u_rps);
        EX_RIO_TAG(279, o.big ? 16 : 4, nchunks, counts);
    }
    EX_RIO_TAG(284, 3, 1, &u_planar);
    if (u_pred != 1) EX_RIO_TAG(317, 3, 1, &u_pred);
    if (opt.tiled) {
        EX_RIO_TAG(322, 4, 1, &u_cw);
        EX_RIO_TAG(323, 4, 1, &u_ch);
        EX_RIO_TAG(324, o.big ? 16 : 4, nchunks, offsets);
        EX_RIO_TAG(325, o.big ? 16 : 4, nchunks, counts);
    }
    if (spp > 1) EX_RIO_TAG(338, 3, (uint64_t)spp - 1, u_extra); /* ExtraSamples: unspecified */
    EX_RIO_TAG(339, 3, (uint64_t)spp, u_fmtv);
    if (geo && (geo->has_scale || geo->has_matrix || geo->n_tiepoints)) {
        if (geo->has_scale) EX_RIO_TAG(33550, 12, 3, geo->scale);
        if (geo->n_tiepoints) EX_RIO_TAG(33922, 12, geo->n_tiepoints, geo->tiepoints);
        if (geo->has_matrix) EX_RIO_TAG(34264, 12, 16, geo->matrix);
    } else if (geo && geo->has_transform && (fx || fy || geo->gt[2] != 0.0 || geo->gt[4] != 0.0)) {
        /* a ModelTransformation: rotated, or in the file's orientation (ex_georef_orient) */
        memset(mt, 0, sizeof mt);
        mt[0] = fx ? -geo->gt[1] : geo->gt[1];
        mt[1] = geo->gt[2];
        mt[4] = geo->gt[4];
        mt[5] = fy ? -geo->gt[5] : geo->gt[5];
        mt[3] = geo->gt[0] + (fx ? geo->gt[1] * (double)img->width : 0.0);
        mt[7] = geo->gt[3] + (fy ? geo->gt[5] * (double)img->height : 0.0);
        if (geo->pixel_is_point && geo->n_geokeys) { /* the GeoKeys say PixelIsPoint: a cell centre */
            mt[3] += 0.5 * mt[0];
            mt[7] += 0.5 * mt[5];
        }
        mt[10] = mt[15] = 1.0;
        EX_RIO_TAG(34264, 12, 16, mt);
    } else if (geo && geo->has_transform) {
        scale[0] = geo->gt[1]; scale[1] = -geo->gt[5]; scale[2] = 0.0;
        tie[0] = tie[1] = tie[2] = tie[5] = 0.0; tie[3] = geo->gt[0]; tie[4] = geo->gt[3];
        EX_RIO_TAG(33550, 12, 3, scale);
        EX_RIO_TAG(33922, 12, 6, tie);
    }
    /* a CRS only with a georeference (a GeoTIFF with a CRS but no geotransform places nothing) */
    if (geo && geo->n_geokeys && placed) {
        size_t q;
        u_keys = (uint64_t *)malloc(geo->n_geokeys * sizeof(uint64_t));
        if (!u_keys) { ex_rio_fail(err, "out of memory"); goto fail; }
        for (q = 0; q < geo->n_geokeys; q++) u_keys[q] = geo->geokeys[q];
        EX_RIO_TAG(34735, 3, geo->n_geokeys, u_keys);
        if (geo->n_geodoubles) EX_RIO_TAG(34736, 12, geo->n_geodoubles, geo->geodoubles);
        if (geo->n_geoascii) EX_RIO_TAG(34737, 2, geo->n_geoascii, geo->geoascii);
    } else if (n_prj_keys && placed) {
        EX_RIO_TAG(34735, 3, n_prj_keys, prj_keys);
        if (n_prj_ascii) EX_RIO_TAG(34737, 2, n_prj_ascii, prj_ascii);
    }
    if (xml) EX_RIO_TAG(42112, 2, strlen(xml) + 1, xml); /* GDAL_METADATA */
    if (geo && geo->has_nodata) {
        size_t L = strlen(geo->nodata_text);
        memcpy(nodata, geo->nodata_text, L + 1);
        EX_RIO_TAG(42113, 2, L + 1, nodata);
    }
#undef EX_RIO_TAG
    /* the IFD, then its out-of-line arrays */
    ifd_pos = o.pos;
    {
        int esz = o.big ? 20 : 12, inl = o.big ? 8 : 4;
        uint64_t arrays = ifd_pos + (o.big ? 8 : 2) + (uint64_t)nt * (uint64_t)esz + (uint64_t)inl;
        ex_rio_emit_uint(&o, (uint64_t)nt, o.big ? 8 : 2);
        for (i = 0; i < nt; i++) {
            uint64_t tb = ex_rio_tag_bytes(&tags[i]);
            ex_rio_emit_uint(&o, tags[i].tag, 2);
            ex_rio_emit_uint(&o, tags[i].type, 2);
            ex_rio_emit_uint(&o, tags[i].count, inl);
            if (tb <= (uint64_t)inl) {
                uint64_t start = o.pos;
                ex_rio_emit_values(&o, &tags[i]);
                while (o.pos < start + (uint64_t)inl) ex_rio_emit(&o, "", 1);
            } else {
                ex_rio_emit_uint(&o, arrays, inl);
                arrays += tb + (tb & 1);
            }
        }
        ex_rio_emit_uint(&o, 0, inl); /* no next IFD */
        for (i = 0; i < nt; i++) {
            uint64_t tb = ex_rio_tag_bytes(&tags[i]);
            if (tb > (uint64_t)inl) {
                ex_rio_emit_values(&o, &tags[i]);
                if (tb & 1) ex_rio_emit(&o, "", 1);
            }
        }
    }
    data_end = o.pos;
    if (!o.big && data_end > 0xffffffffu) {
        ex_rio_fail(err, "file would exceed 4 GiB: write BigTIFF");
        goto fail;
    }
    /* patch the first IFD offset */
    if (o.ok && fseek(o.f, o.big ? 8 : 4, SEEK_SET) != 0) o.ok = 0;
    ex_rio_emit_uint(&o, ifd_pos, o.big ? 8 : 4);
    if (!o.ok) {
        ex_rio_fail(err, "write error");
        goto fail;
    }
    rc = 0;
fail:
    if (!ex_atomic_close(o.f, tmpname, path, rc == 0) && rc == 0) rc = ex_rio_fail(err, "cannot write the file");
done:
    free(offsets);
    free(counts);
    free(u_bpsv);
    free(u_fmtv);
    free(u_extra);
    free(u_keys);
    free(prj_ascii);
    free(xml);
    return rc;
}

/* A number as the shortest decimal that reads back to the same float ("%.9g") or double. */
static inline void ex_rio_fmt(char *buf, size_t cap, double v, int is_float)
{
    if (isnan(v)) snprintf(buf, cap, "nan");
    else snprintf(buf, cap, is_float ? "%.9g" : "%.17g", v);
}

/* The WKT (1, with its EPSG authority, as GDAL writes it) of the CRS of an EPSG code that needs
 * no database: WGS 84 (4326), WGS 84 / UTM zones 1-60 north (32601-32660) and south
 * (32701-32760), ETRS89 / UTM zones 28-38 north (25828-25838). Into buf (cap bytes); 0 when
 * the code is not one of these (or buf is too small). */
static inline size_t ex_rio_epsg_wkt(int epsg, char *buf, size_t cap)
{
    static const char wgs84[] =
        "GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,298.257223563,AUTHORITY[\"EPSG\",\"7030\"]],"
        "AUTHORITY[\"EPSG\",\"6326\"]],PRIMEM[\"Greenwich\",0,AUTHORITY[\"EPSG\",\"8901\"]],"
        "UNIT[\"degree\",0.0174532925199433,AUTHORITY[\"EPSG\",\"9122\"]],AUTHORITY[\"EPSG\",\"4326\"]]";
    static const char etrs89[] =
        "GEOGCS[\"ETRS89\",DATUM[\"European_Terrestrial_Reference_System_1989\",SPHEROID[\"GRS 1980\",6378137,"
        "298.257222101,AUTHORITY[\"EPSG\",\"7019\"]],TOWGS84[0,0,0,0,0,0,0],AUTHORITY[\"EPSG\",\"6258\"]],"
        "PRIMEM[\"Greenwich\",0,AUTHORITY[\"EPSG\",\"8901\"]],UNIT[\"degree\",0.0174532925199433,"
        "AUTHORITY[\"EPSG\",\"9122\"]],AUTHORITY[\"EPSG\",\"4258\"]]";
    int zone, south = 0, n;
    const char *geog, *name;
    if (epsg == 4326) n = snprintf(buf, cap, "%s", wgs84);
    else {
        if (epsg >= 32601 && epsg <= 32660) zone = epsg - 32600, geog = wgs84, name = "WGS 84";
        else if (epsg >= 32701 && epsg <= 32760) zone = epsg - 32700, geog = wgs84, name = "WGS 84", south = 1;
        else if (epsg >= 25828 && epsg <= 25838) zone = epsg - 25800, geog = etrs89, name = "ETRS89";
        else return 0;
        n = snprintf(buf, cap,
                     "PROJCS[\"%s / UTM zone %d%c\",%s,PROJECTION[\"Transverse_Mercator\"],"
                     "PARAMETER[\"latitude_of_origin\",0],PARAMETER[\"central_meridian\",%d],"
                     "PARAMETER[\"scale_factor\",0.9996],PARAMETER[\"false_easting\",500000],"
                     "PARAMETER[\"false_northing\",%d],UNIT[\"metre\",1,AUTHORITY[\"EPSG\",\"9001\"]],"
                     "AXIS[\"Easting\",EAST],AXIS[\"Northing\",NORTH],AUTHORITY[\"EPSG\",\"%d\"]]",
                     name, zone, south ? 'S' : 'N', geog, 6 * zone - 183, south ? 10000000 : 0, epsg);
    }
    return n > 0 && (size_t)n < cap ? (size_t)n : 0;
}

/* 1 when an ASC or EHdr output of geo would carry no CRS although geo has one: no .prj text, no
 * ESRI PE string, and an EPSG code ex_rio_epsg_wkt cannot describe (the caller says so). */
static inline int ex_rio_crs_lost(const ex_georef *geo)
{
    char wkt[1024];
    size_t len;
    return geo && !geo->prj && !ex_rio_pe_string(geo, &len) && geo->epsg > 0 &&
           ex_rio_epsg_wkt(geo->epsg, wkt, sizeof wkt) == 0;
}

/* printf into the output (a line of a text header). */
static inline void ex_rio_emitf(ex_rio_out *o, const char *fmt, ...)
{
    char line[512];
    int n;
    va_list ap;
    va_start(ap, fmt);
    n = vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    if (n < 0 || (size_t)n >= sizeof line) o->ok = 0;
    else ex_rio_emit(o, line, (size_t)n);
}

/* Add the .prj of geo beside path to the set p: its .prj, the WKT of a GeoTIFF's ESRI PE
 * string, or that of its EPSG code (ex_rio_epsg_wkt); without any, a .prj left beside path by an
 * earlier output is removed with the set (ex_rio_crs_lost tells the caller). *prj_out is the
 * name (free it after ex_publish_end). Returns 0, or -1 (out of memory). */
static inline int ex_rio_publish_prj(ex_publish *p, const char *path, const ex_georef *geo, char **prj_out,
                                     char *err)
{
    const char *wkt = geo ? geo->prj : NULL;
    char epsg_wkt[1024];
    size_t len = 0;
    ex_rio_out o;
    if (geo && !wkt) wkt = ex_rio_pe_string(geo, &len);
    else if (wkt) len = strlen(wkt);
    if (geo && !wkt && geo->epsg > 0 && (len = ex_rio_epsg_wkt(geo->epsg, epsg_wkt, sizeof epsg_wkt)) > 0)
        wkt = epsg_wkt;
    *prj_out = ex_rio_sidecar(path, ".prj");
    if (!*prj_out) return ex_rio_fail(err, "out of memory");
    if (!wkt) {
        ex_publish_absent(p, *prj_out);
        return 0;
    }
    memset(&o, 0, sizeof o);
    o.f = ex_publish_open(p, *prj_out);
    o.ok = o.f != NULL;
    ex_rio_emit(&o, wkt, len);
    if (!geo->prj) ex_rio_emit(&o, "\n", 1);
    ex_publish_close(p, o.f, o.ok);
    return 0;
}

/* Publish the set p; its names are freed. Returns 0, or -1 with "cannot write the file". */
static inline int ex_rio_publish(ex_publish *p, char **names, int n, char *err)
{
    int ok = ex_publish_end(p), i;
    for (i = 0; i < n; i++) free(names[i]);
    return ok ? 0 : ex_rio_fail(err, "cannot write the file");
}

/* Rows of an ASC grid formatted at once: a batch of rows, each into its own slot of cap bytes. */
#define EX_RIO_ASC_BATCH_BYTES ((size_t)16 << 20) /* at most 64 rows, and about this many bytes */
typedef struct {
    const ex_rio_image *img;
    const char *ndt;         /* the NoData text, ndl bytes */
    size_t ndl, cap;
    char *buf;               /* row i of the batch at buf + i cap, len[i] bytes ((size_t)-1: not made) */
    size_t *len;
    int y0;
} ex_rio_asc_rows;

static inline int ex_rio_asc_row(void *ctx, size_t i)
{
    ex_rio_asc_rows *j = (ex_rio_asc_rows *)ctx;
    const ex_rio_image *img = j->img;
    char num[64], *line = j->buf + i * j->cap;
    const size_t y = (size_t)j->y0 + i;
    size_t n = 0;
    int x;
    for (x = 0; x < img->width; x++) {
        float v = img->data[y * img->row_step + (size_t)x * img->pixel_step];
        size_t k;
        if (isnan(v)) {
            memcpy(line + n, j->ndt, j->ndl);
            k = j->ndl;
        } else {
            ex_rio_fmt(num, sizeof num, (double)v, 1);
            k = strlen(num);
            memcpy(line + n, num, k);
        }
        n += k;
        line[n++] = x + 1 < img->width ? ' ' : '\n';
    }
    j->len[i] = n;
    return 0;
}

/* Write band 0 of img as an ESRI ASCII grid (+ the .prj of geo when it has one), published
 * together (ex_publish): values as %.9g, NaN cells as the NoData value (geo's, else -9999). The
 * rows are formatted a batch at a time, through opt->parallel when given (any order, each row
 * into its own buffer), and written in order: the file's bytes do not depend on it; a runner that
 * fails or skips a row fails the write and leaves no file. */
static inline int ex_rio_write_asc(const char *path, const ex_rio_image *img, const ex_georef *geo,
                                   const ex_rio_write_options *opt, char *err)
{
    char *names[1] = {NULL};
    ex_publish pub;
    ex_rio_out o;
    ex_rio_asc_rows j;
    int y0, rows, ran = 1;
    double cell = 1.0, nd = geo && geo->has_nodata ? geo->nodata : -9999.0;
    const char *ndt = geo && geo->has_nodata ? geo->nodata_text : "-9999";
    size_t ndl = strlen(ndt), i, batch;
    if (img->width < 1 || img->height < 1 || !img->data) return ex_rio_fail(err, "nothing to write");
    if (img->bands != 1) return ex_rio_fail(err, "an ASCII grid holds one band; this output has %d (write .tif or .bil)",
                                            img->bands);
    if (geo && geo->has_transform) {
        if (ex_georef_cell(geo, &cell, err) != 0) return -1;
    }
    if (isnan(nd)) return ex_rio_fail(err, "an ASCII grid cannot have NoData NaN");
    memset(&j, 0, sizeof j);
    j.img = img;
    j.ndt = ndt;
    j.ndl = ndl;
    /* one row of text: each cell at most max(16, strlen(NoData)) characters and a separator */
    j.cap = ((ndl > 16 ? ndl : 16) + 1) * (size_t)img->width;
    batch = EX_RIO_ASC_BATCH_BYTES / j.cap;
    batch = batch < 1 ? 1 : batch > 64 ? 64 : batch;
    if ((size_t)img->width < SIZE_MAX / 128) {
        j.buf = (char *)malloc(batch * j.cap);
        j.len = (size_t *)malloc(batch * sizeof *j.len);
    }
    if (!j.buf || !j.len) {
        free(j.buf);
        free(j.len);
        return ex_rio_fail(err, "out of memory");
    }
    ex_publish_init(&pub);
    memset(&o, 0, sizeof o);
    o.f = ex_publish_open(&pub, path);
    if (!o.f) {
        free(j.buf);
        free(j.len);
        ex_publish_end(&pub);
        return ex_rio_fail(err, "cannot create the file");
    }
    o.ok = 1;
    ex_rio_emitf(&o, "ncols %d\nnrows %d\n", img->width, img->height);
    if (geo && geo->has_transform)
        ex_rio_emitf(&o, "xllcorner %.17g\nyllcorner %.17g\ncellsize %.17g\n", geo->gt[0],
                     geo->gt[3] + geo->gt[5] * (double)img->height, cell);
    else
        ex_rio_emitf(&o, "xllcorner 0\nyllcorner 0\ncellsize 1\n");
    ex_rio_emitf(&o, "NODATA_value %s\n", ndt);
    for (y0 = 0; y0 < img->height && o.ok; y0 += rows) {
        rows = img->height - y0 < (int)batch ? img->height - y0 : (int)batch;
        j.y0 = y0;
        for (i = 0; i < (size_t)rows; i++) j.len[i] = (size_t)-1;
        if (opt && opt->parallel && rows > 1) {
            if (opt->parallel(opt->parallel_user, (size_t)rows, ex_rio_asc_row, &j) != 0) o.ok = 0, ran = 0;
        } else {
            for (i = 0; i < (size_t)rows; i++) (void)ex_rio_asc_row(&j, i);
        }
        for (i = 0; i < (size_t)rows && o.ok; i++) {
            if (j.len[i] == (size_t)-1) o.ok = 0, ran = 0; /* a row the runner did not make */
            else ex_rio_emit(&o, j.buf + i * j.cap, j.len[i]);
        }
    }
    free(j.buf);
    free(j.len);
    ex_publish_close(&pub, o.f, o.ok);
    if (!ran) {
        ex_publish_end(&pub); /* nothing published: the temporary file removed */
        return ex_rio_fail(err, "the rows' formatting did not run every row");
    }
    if (ex_rio_publish_prj(&pub, path, geo, &names[0], err) != 0) {
        ex_publish_end(&pub);
        return -1;
    }
    return ex_rio_publish(&pub, names, 1, err);
}

/* Write img as EHdr (.bil/.flt data + .hdr [+ .prj]): 32-bit floats, BIL, little endian; the
 * files are published together (ex_publish). */
static inline int ex_rio_write_ehdr(const char *path, const ex_rio_image *img, const ex_georef *geo, char *err)
{
    char *names[2] = {NULL, NULL};
    ex_publish pub;
    ex_rio_out o;
    int x, y, b;
    unsigned char *row;
    size_t rb = (size_t)img->width * 4u;
    row = (unsigned char *)malloc(rb);
    if (!row) return ex_rio_fail(err, "out of memory");
    ex_publish_init(&pub);
    memset(&o, 0, sizeof o);
    o.f = ex_publish_open(&pub, path);
    if (!o.f) {
        free(row);
        ex_publish_end(&pub);
        return ex_rio_fail(err, "cannot create the file");
    }
    o.ok = 1;
    for (y = 0; y < img->height && o.ok; y++)
        for (b = 0; b < img->bands && o.ok; b++) {
            for (x = 0; x < img->width; x++)
                ex_rio_encode_sample(row + (size_t)x * 4u,
                                     img->data[(size_t)b * img->band_step + (size_t)y * img->row_step +
                                               (size_t)x * img->pixel_step],
                                     EX_RIO_FLOAT, 32, 0, geo);
            ex_rio_emit(&o, row, rb);
        }
    free(row);
    ex_publish_close(&pub, o.f, o.ok);
    names[0] = ex_rio_sidecar(path, ".hdr");
    if (!names[0]) {
        ex_publish_end(&pub);
        return ex_rio_fail(err, "out of memory");
    }
    memset(&o, 0, sizeof o);
    o.f = ex_publish_open(&pub, names[0]);
    o.ok = o.f != NULL;
    ex_rio_emitf(&o, "BYTEORDER I\nLAYOUT BIL\nNROWS %d\nNCOLS %d\nNBANDS %d\nNBITS 32\nBANDROWBYTES %lu\n"
                     "TOTALROWBYTES %lu\nPIXELTYPE FLOAT\n",
                 img->height, img->width, img->bands, (unsigned long)rb, (unsigned long)(rb * (size_t)img->bands));
    if (geo && geo->has_transform)
        ex_rio_emitf(&o, "ULXMAP %.17g\nULYMAP %.17g\nXDIM %.17g\nYDIM %.17g\n", geo->gt[0] + 0.5 * geo->gt[1],
                     geo->gt[3] + 0.5 * geo->gt[5], geo->gt[1], -geo->gt[5]);
    if (geo && geo->has_nodata) ex_rio_emitf(&o, "NODATA %s\n", geo->nodata_text);
    ex_publish_close(&pub, o.f, o.ok);
    if (ex_rio_publish_prj(&pub, path, geo, &names[1], err) != 0) {
        ex_publish_end(&pub);
        free(names[0]);
        return -1;
    }
    return ex_rio_publish(&pub, names, 2, err);
}

/* Write img by the extension of path (.tif/.tiff with opt, .asc, .bil/.flt). */
static inline int ex_rio_write(const char *path, const ex_rio_image *img, const ex_georef *geo,
                               const ex_rio_write_options *opt, char *err)
{
    switch (ex_rio_format_of(path)) {
    case EX_RIO_TIFF: return ex_rio_write_tiff_file(path, img, geo, opt, err);
    case EX_RIO_ASC: return ex_rio_write_asc(path, img, geo, opt, err);
    case EX_RIO_EHDR: return ex_rio_write_ehdr(path, img, geo, err);
    default: return ex_rio_fail(err, "not a raster extension (.tif .tiff .asc .bil .flt)");
    }
}

#endif /* HFVIS_EXAMPLES_RASTER_IO_H */
