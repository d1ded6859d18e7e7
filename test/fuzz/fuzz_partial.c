/* libFuzzer target for the partial-sum decoder (HFVISSUM, hfvis_partial_decode): a decoded file
 * must satisfy every header bound, re-encode to exactly the input bytes, and a failed decode
 * must leave the output untouched. Seeds: test/fuzz/seeds/partial. Built and run by `make fuzz`. */
#include "hfvis.h"
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    hfvis_partial p, untouched;
    unsigned char *enc;
    size_t need, written = 0, values;
    hfvis_status s;
    memset(&p, 0xA5, sizeof p);
    memcpy(&untouched, &p, sizeof p);
    s = hfvis_partial_decode(data, size, NULL, &p);
    if (s != HFVIS_OK) {
        if (memcmp(&p, &untouched, sizeof p) != 0) abort();
        return 0;
    }
    if (p.width < 1 || p.height < 1 || p.width > HFVIS_IMAGE_MAX_DIM || p.height > HFVIS_IMAGE_MAX_DIM
        || p.planes < 1 || p.planes > HFVIS_PARTIAL_MAX_PLANES || p.directions < 1 || p.begin < 0
        || p.begin >= p.end || p.end > p.directions || !p.tag || !p.sums)
        abort();
    values = (size_t)p.width * (size_t)p.height * (size_t)p.planes;
    if ((unsigned long long)values > HFVIS_PARTIAL_MAX_VALUES || strlen(p.tag) < 1 || strlen(p.tag) > HFVIS_PARTIAL_MAX_TAG)
        abort();
    need = hfvis_partial_encode_size(&p);
    if (need != size) abort(); /* the format has one spelling per content */
    enc = (unsigned char *)malloc(need);
    if (enc) {
        if (hfvis_partial_encode(&p, enc, need, &written) != HFVIS_OK || written != size
            || memcmp(enc, data, size) != 0)
            abort();
        free(enc);
    }
    hfvis_partial_free(NULL, &p);
    return 0;
}
