/* imgdiff - compares two PGM/PFM images value by value through the library's decoder (used by
 * test/determinism.sh to hold the gcc and clang builds against each other).
 * usage: imgdiff A B [ABS_TOL REL_TOL]
 * Prints "values=N differing=D max_abs=X max_rel=Y nan_mismatch=M". Exit 0 if the images have
 * the same format, size and channels, NaN at the same places, and (when tolerances are given)
 * every pair satisfies |a - b| <= ABS_TOL + REL_TOL*|b|; 1 otherwise; 2 on a usage or I/O error. */
#include "hfvis.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

int main(int argc, char **argv)
{
    float *a = NULL, *b = NULL;
    hfvis_image_info ia, ib;
    hfvis_status s;
    double abs_tol = HUGE_VAL, rel_tol = 0.0, max_abs = 0.0, max_rel = 0.0;
    size_t n, k, differing = 0, nan_mismatch = 0, over = 0;
    int rc = 2;

    if (argc != 3 && argc != 5) {
        fprintf(stderr, "usage: imgdiff A B [ABS_TOL REL_TOL]\n");
        return 2;
    }
    if (argc == 5) {
        abs_tol = strtod(argv[3], NULL);
        rel_tol = strtod(argv[4], NULL);
    }
    if ((s = hfvis_image_load(argv[1], NULL, &a, &ia)) != HFVIS_OK
        || (s = hfvis_image_load(argv[2], NULL, &b, &ib)) != HFVIS_OK) {
        fprintf(stderr, "imgdiff: %s: %s\n", a ? argv[2] : argv[1], hfvis_status_string(s));
        goto done;
    }
    rc = 1;
    if (ia.format != ib.format || ia.width != ib.width || ia.height != ib.height
        || ia.channels != ib.channels || ia.maxval != ib.maxval) {
        printf("shape differs: %dx%dx%d vs %dx%dx%d\n", ia.width, ia.height, ia.channels, ib.width,
               ib.height, ib.channels);
        goto done;
    }
    n = (size_t)ia.width * (size_t)ia.height * (size_t)ia.channels;
    for (k = 0; k < n; k++) {
        double x = (double)a[k], y = (double)b[k], d, m;
        if (isnan(x) || isnan(y)) {
            if (!(isnan(x) && isnan(y))) nan_mismatch++;
            continue;
        }
        if (x == y) continue;
        differing++;
        d = fabs(x - y);
        m = fmax(fabs(x), fabs(y));
        if (!(d <= abs_tol + rel_tol * fabs(y))) over++;
        if (d > max_abs || isnan(d)) max_abs = d;
        if (d / m > max_rel || isnan(d / m)) max_rel = d / m;
    }
    printf("values=%zu differing=%zu max_abs=%.3g max_rel=%.3g nan_mismatch=%zu\n", n, differing,
           max_abs, max_rel, nan_mismatch);
    rc = (nan_mismatch == 0 && over == 0) ? 0 : 1;
done:
    hfvis_free(NULL, a);
    hfvis_free(NULL, b);
    return rc;
}
