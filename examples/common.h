/* common.h - helpers shared by the examples and the hfvis tool: one-line error reports, PGM
 * output and its PNG picture twins (png_write.h). Header-only, every function static inline
 * (unused ones cost nothing and do not warn). */
#ifndef HFVIS_EXAMPLES_COMMON_H
#define HFVIS_EXAMPLES_COMMON_H

#include <limits.h>
#include <stdio.h>
#include "hfvis.h"
#include "png_write.h"

/* Print the one error line every hfvis program uses, "hfvis: <what>: <why>", on stderr. */
static inline void ex_error(const char *what, const char *why)
{
    fprintf(stderr, "hfvis: %s: %s\n", what, why);
}

/* Report a failed status; returns 1 so that `return ex_report(...)` ends main with failure. */
static inline int ex_report(const char *what, hfvis_status status)
{
    ex_error(what, hfvis_status_string(status));
    return 1;
}

/* Evaluate a hfvis call; if it fails, report it as "hfvis: <what>: <status>" and jump to the
 * enclosing function's `fail:` label (which frees what was allocated and returns non-zero). */
#define EX_CHECK(call, what) \
    do { hfvis_status ex_status_ = (call); \
         if (ex_status_ != HFVIS_OK) { ex_report((what), ex_status_); goto fail; } } while (0)

/* Write pixels (width x height, stride in pixels) as the 16-bit PGM "<dir>/<name>", mapping
 * [lo, hi] to 0..65535 (values outside clamp, NaN -> 0). Reports its own failure. */
static inline hfvis_status ex_save_pgm(const char *dir, const char *name, const float *pixels,
                                       int width, int height, ptrdiff_t stride, float lo, float hi)
{
    char path[4096];
    hfvis_status s;
    int n = snprintf(path, sizeof path, "%s/%s", dir, name);
    if (n < 0 || (size_t)n >= sizeof path) {
        ex_error(name, "output path too long");
        return HFVIS_ERR_INVALID_ARGUMENT;
    }
    s = hfvis_pgm_save(path, pixels, width, height, stride, lo, hi, 65535);
    if (s != HFVIS_OK) ex_report(path, s);
    else printf("wrote %s\n", path);
    return s;
}

/* "<dir>/<name>" into path (cap bytes); reports it and returns 0 when it does not fit. */
static inline int ex_path(char *path, size_t cap, const char *dir, const char *name)
{
    int n = snprintf(path, cap, "%s/%s", dir, name);
    if (n < 0 || (size_t)n >= cap) {
        ex_error(name, "output path too long");
        return 0;
    }
    return 1;
}

/* Report a PNG save: "wrote <path>", or the one error line "hfvis: <path>: <why>". */
static inline hfvis_status ex_png_done(const char *path, hfvis_status s)
{
    if (s != HFVIS_OK) ex_report(path, s);
    else printf("wrote %s\n", path);
    return s;
}

/* The picture twin of ex_save_pgm: the same arguments and mapping, written as the 8-bit
 * greyscale PNG "<dir>/<name>" (256 levels). Reports its own failure. */
static inline hfvis_status ex_save_png(const char *dir, const char *name, const float *pixels,
                                       int width, int height, ptrdiff_t stride, float lo, float hi)
{
    char path[4096];
    if (!ex_path(path, sizeof path, dir, name)) return HFVIS_ERR_INVALID_ARGUMENT;
    return ex_png_done(path, ex_png_save(path, pixels, width, height, stride, 1, 8, lo, hi));
}

/* The same for RGB: 3 interleaved floats per pixel (stride in pixels), each channel mapped from
 * [lo, hi] to 0..255, written as an 8-bit RGB PNG. */
static inline hfvis_status ex_save_png_rgb(const char *dir, const char *name, const float *rgb,
                                           int width, int height, ptrdiff_t stride, float lo, float hi)
{
    char path[4096];
    if (!ex_path(path, sizeof path, dir, name)) return HFVIS_ERR_INVALID_ARGUMENT;
    return ex_png_done(path, ex_png_save(path, rgb, width, height, stride, 3, 8, lo, hi));
}

/* Both: the 16-bit PGM "<dir>/<name>" (name ends in ".pgm"; the data, 65536 levels) and its PNG
 * picture twin "<dir>/<name with .png>" (256 levels), with ex_save_pgm's arguments. */
static inline hfvis_status ex_save_pgm_png(const char *dir, const char *name, const float *pixels,
                                           int width, int height, ptrdiff_t stride, float lo, float hi)
{
    char png[256];
    size_t n = strlen(name);
    hfvis_status s;
    if (n < 4 || n >= sizeof png || strcmp(name + n - 4, ".pgm") != 0) {
        ex_error(name, "not a .pgm name");
        return HFVIS_ERR_INVALID_ARGUMENT;
    }
    s = ex_save_pgm(dir, name, pixels, width, height, stride, lo, hi);
    if (s != HFVIS_OK) return s;
    memcpy(png, name, n - 4);
    memcpy(png + n - 4, ".png", 5);
    return ex_save_png(dir, png, pixels, width, height, stride, lo, hi);
}

/* One picture of a sheet: width x height pixels (stride = width), shown over [lo, hi]. */
typedef struct {
    const float *pixels; /* NULL: an empty (white) slot */
    float lo, hi;
} ex_panel;

#define EX_SHEET_GAP 4 /* white pixels between the panels of a sheet */

/* Lay count panels of width x height (channels 1 or 3 floats per pixel) out in rows of columns,
 * left to right and top to bottom, EX_SHEET_GAP white pixels apart, each mapped from its own
 * [lo, hi] as ex_save_png does, and save them as the 8-bit PNG "<dir>/<name>". */
static inline hfvis_status ex_save_png_sheet(const char *dir, const char *name, const ex_panel *panels,
                                             int count, int columns, int width, int height, int channels)
{
    char path[4096];
    size_t sw, sh, row = 0, total = 0, written = 0, x, y;
    unsigned char *samples = NULL, *file = NULL;
    hfvis_status s = HFVIS_ERR_INVALID_ARGUMENT;
    int k, rows;
    if (!ex_path(path, sizeof path, dir, name)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (!panels || count <= 0 || columns <= 0 || width <= 0 || height <= 0 || (channels != 1 && channels != 3))
        return ex_png_done(path, s);
    if (columns > count) columns = count;
    rows = count / columns + (count % columns != 0);
    sw = (size_t)columns * ((size_t)width + EX_SHEET_GAP) - EX_SHEET_GAP;
    sh = (size_t)rows * ((size_t)height + EX_SHEET_GAP) - EX_SHEET_GAP;
    if (sw > INT_MAX || sh > INT_MAX) return ex_png_done(path, HFVIS_ERR_LIMIT);
    for (k = 0; k < count; k++)
        if (panels[k].pixels && !(isfinite(panels[k].lo) && isfinite(panels[k].hi) && panels[k].lo < panels[k].hi))
            return ex_png_done(path, s);
    s = ex_png_layout((int)sw, (int)sh, channels, 8, &row, NULL, &total);
    if (s != HFVIS_OK) return ex_png_done(path, s);
    samples = (unsigned char *)malloc(row * sh);
    file = (unsigned char *)malloc(total);
    if (!samples || !file) s = HFVIS_ERR_OUT_OF_MEMORY;
    else {
        memset(samples, 255, row * sh);
        for (k = 0; k < count; k++) {
            const ex_panel *p = &panels[k];
            size_t x0 = (size_t)(k % columns) * ((size_t)width + EX_SHEET_GAP);
            size_t y0 = (size_t)(k / columns) * ((size_t)height + EX_SHEET_GAP);
            double range = (double)p->hi - (double)p->lo;
            if (!p->pixels) continue;
            for (y = 0; y < (size_t)height; y++)
                for (x = 0; x < (size_t)width * (size_t)channels; x++)
                    samples[(y0 + y) * row + x0 * (size_t)channels + x] = (unsigned char)ex_png_quantize(
                        p->pixels[y * (size_t)width * (size_t)channels + x], (double)p->lo, range, 255u);
        }
        s = ex_png_encode(samples, (int)sw, (int)sh, channels, 8, file, total, &written);
        if (s == HFVIS_OK) s = ex_png_write_file(path, file, written);
    }
    free(samples);
    free(file);
    return ex_png_done(path, s);
}

#endif /* HFVIS_EXAMPLES_COMMON_H */
