/* common.h - helpers shared by the examples and the hfvis tool: one-line error reports and PGM
 * output. Header-only, every function static inline (unused ones cost nothing and do not warn). */
#ifndef HFVIS_EXAMPLES_COMMON_H
#define HFVIS_EXAMPLES_COMMON_H

#include <stdio.h>
#include "hfvis.h"

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

#endif /* HFVIS_EXAMPLES_COMMON_H */
