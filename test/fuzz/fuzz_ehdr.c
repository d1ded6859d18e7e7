/* libFuzzer target for the EHdr (.hdr + raw .bil/.flt) reader of examples/raster_io.h: the
 * input is the header text, a NUL byte, then the raw data (no NUL: all header, no data); the
 * first byte's low bit picks .flt (floats by default) or .bil. Refused with a message, or every
 * band's corner windows read within the data (the layout is checked against its size).
 * Seeds: test/fuzz/seeds/ehdr. Built and run by `make fuzz`. */
#include "examples/raster_io.h"
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    ex_rio_reader r;
    float win[8 * 8];
    const uint8_t *nul = (const uint8_t *)memchr(data, 0, size);
    size_t hlen = nul ? (size_t)(nul - data) : size;
    const unsigned char *raw = nul ? nul + 1 : NULL;
    size_t rlen = nul ? size - hlen - 1 : 0;
    int b;
    if (ex_rio_open_ehdr_mem(&r, (const char *)data, hlen, raw, rlen, size > 0 && (data[0] & 1)) != 0) {
        if (r.err[0] == '\0') abort();
        ex_rio_close(&r);
        return 0;
    }
    r.nodata_to_nan = 1;
    for (b = 0; b < r.bands && b < 4; b++) {
        if (ex_rio_read(&r, b, 0, 0, 8, 8, win, 8) != 0) abort(); /* the layout fits the data */
        if (ex_rio_read(&r, b, r.width - 4, r.height - 4, 8, 8, win, 8) != 0) abort();
    }
    ex_rio_close(&r);
    return 0;
}
