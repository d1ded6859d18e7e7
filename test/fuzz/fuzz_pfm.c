/* libFuzzer target for the PFM decoder (and, through the shared header parser, PGM):
 * hfvis_image_info_read must agree with hfvis_image_decode, a one-short buffer must be refused,
 * and encode -> decode must reproduce every value bit for bit (NaN payloads included).
 * Seeds: test/fuzz/seeds/pfm. Built and run by `make fuzz`. */
#include "hfvis.h"
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Decode only images up to this many values, so one input never costs more than a few MiB. */
#define FUZZ_MAX_VALUES ((size_t)1 << 20)

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    hfvis_image_info info, info2;
    hfvis_status s;
    float sentinel = -1.0f, *px, *again;
    unsigned char *enc;
    size_t count, need, written;

    s = hfvis_image_info_read(data, size, &info);
    if (s != HFVIS_OK) {
        /* Every header or data error is found before the buffer size is looked at. */
        if (hfvis_image_decode(data, size, &sentinel, 1, NULL) != s || sentinel != -1.0f) abort();
        return 0;
    }
    if (info.width < 1 || info.height < 1 || info.width > HFVIS_IMAGE_MAX_DIM
        || info.height > HFVIS_IMAGE_MAX_DIM || (info.channels != 1 && info.channels != 3))
        abort();
    count = (size_t)info.width * (size_t)info.height * (size_t)info.channels;
    if (count > HFVIS_IMAGE_MAX_VALUES) abort();
    if (count > FUZZ_MAX_VALUES) return 0;
    px = (float *)malloc(count * sizeof(float));
    if (!px) return 0;
    if (hfvis_image_decode(data, size, px, count - 1, &info2) != HFVIS_ERR_BUFFER_TOO_SMALL) abort();
    if (hfvis_image_decode(data, size, px, count, &info2) != HFVIS_OK) abort();
    if (memcmp(&info, &info2, sizeof info) != 0) abort();
    if (info.format == HFVIS_FORMAT_PFM) {
        if (info.maxval != 0) abort();
        need = hfvis_pfm_encode_size(info.width, info.height, info.channels);
        enc = (unsigned char *)malloc(need);
        again = (float *)malloc(count * sizeof(float));
        if (enc && again) {
            if (hfvis_pfm_encode(px, info.width, info.height, info.channels, info.width, enc, need,
                                 &written) != HFVIS_OK || written != need)
                abort();
            if (hfvis_image_decode(enc, written, again, count, &info2) != HFVIS_OK) abort();
            if (info2.big_endian != 0 || info2.width != info.width || info2.height != info.height
                || info2.channels != info.channels
                || memcmp(px, again, count * sizeof(float)) != 0)
                abort();
        }
        free(enc);
        free(again);
    }
    free(px);
    return 0;
}
