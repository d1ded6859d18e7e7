/* libFuzzer target for the NoData-safe PGM (hfvis.h, hfvis_pgm_range_*): the "# hfvis range LO HI
 * nodata 0" comment parser of hfvis_pgm_range_read and the mapping of hfvis_pgm_range_decode.
 * Checks: a range read succeeds only on a PGM and gives finite lo < hi; a failed read fails the
 * decode with the same status and leaves its output untouched; a one-short buffer is refused;
 * decoded values are NaN exactly where the code is 0 and lie in [lo, hi] elsewhere; re-encoding
 * them with the same range and decoding again moves no value by more than one code step.
 * Seeds: test/fuzz/seeds/pgm_range. Built and run by `make fuzz`. */
#include "hfvis.h"
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Decode only images up to this many values, so one input never costs more than a few MiB. */
#define FUZZ_MAX_VALUES ((size_t)1 << 20)
/* Float rounding of lo + (code - 1) (hi - lo)/65534 and of the encoder's division: a few ulps of
 * the larger bound, far below one code step unless the range is tiny against its bounds. */
#define FUZZ_ULPS 8.0

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Slack of a value near [lo, hi]: FUZZ_ULPS float ulps of the larger |bound|. */
static double fuzz_slack(float lo, float hi)
{
    double m = fabs((double)lo) > fabs((double)hi) ? fabs((double)lo) : fabs((double)hi);
    return FUZZ_ULPS * m * (double)FLT_EPSILON;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    hfvis_image_info info, info2;
    hfvis_status s;
    float lo = 0.0f, hi = 0.0f, sentinel = -1.0f, *v, *codes, *again;
    unsigned char *enc;
    size_t count, k, need, written;
    double step, slack;

    s = hfvis_pgm_range_read(data, size, &lo, &hi);
    if (s != HFVIS_OK) {
        if (hfvis_pgm_range_decode(data, size, &sentinel, 1, NULL) != s || sentinel != -1.0f) abort();
        return 0;
    }
    if (!isfinite(lo) || !isfinite(hi) || !(lo < hi)) abort();
    if (hfvis_image_info_read(data, size, &info) != HFVIS_OK || info.format != HFVIS_FORMAT_PGM
        || info.channels != 1)
        abort();
    count = (size_t)info.width * (size_t)info.height;
    if (count > FUZZ_MAX_VALUES) return 0;
    v = (float *)malloc(count * sizeof(float));
    codes = (float *)malloc(count * sizeof(float));
    if (!v || !codes) {
        free(v);
        free(codes);
        return 0;
    }
    if (hfvis_pgm_range_decode(data, size, v, count - 1, &info2) != HFVIS_ERR_BUFFER_TOO_SMALL) abort();
    if (hfvis_pgm_range_decode(data, size, v, count, &info2) != HFVIS_OK) abort();
    if (memcmp(&info, &info2, sizeof info) != 0) abort();
    if (hfvis_image_decode(data, size, codes, count, NULL) != HFVIS_OK) abort();
    step = ((double)hi - (double)lo) / (double)HFVIS_PGM_RANGE_CODES;
    slack = fuzz_slack(lo, hi);
    for (k = 0; k < count; k++) {
        if ((codes[k] == 0.0f) != (v[k] != v[k])) abort(); /* NaN exactly at code 0 */
        if (codes[k] != 0.0f && !((double)v[k] >= (double)lo - slack && (double)v[k] <= (double)hi + slack))
            abort();
    }
    /* Re-encode with the same range and decode: within one code step (plus rounding). */
    need = hfvis_pgm_range_encode_size(info.width, info.height, lo, hi);
    enc = need ? (unsigned char *)malloc(need) : NULL;
    again = (float *)malloc(count * sizeof(float));
    if (enc && again) {
        if (hfvis_pgm_range_encode(v, info.width, info.height, info.width, lo, hi, enc, need, &written)
                != HFVIS_OK || written != need)
            abort();
        if (hfvis_pgm_range_decode(enc, written, again, count, NULL) != HFVIS_OK) abort();
        for (k = 0; k < count; k++) {
            if ((v[k] != v[k]) != (again[k] != again[k])) abort();
            if (v[k] == v[k] && !(fabs((double)again[k] - (double)v[k]) <= step + 2.0 * slack)) abort();
        }
    }
    free(enc);
    free(again);
    free(v);
    free(codes);
    return 0;
}
