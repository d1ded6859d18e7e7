/* libFuzzer target for the ESRI ASCII grid reader of examples/raster_io.h: refused with a
 * message, or a grid whose every value reads back (NoData as NaN when asked) and whose georef
 * has a positive cell size. The grid's allocation is bounded by the text's length.
 * Seeds: test/fuzz/seeds/asc. Built and run by `make fuzz`. */
#include "examples/raster_io.h"
#include <stdint.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    ex_rio_reader r;
    float win[16 * 16];
    if (ex_rio_open_asc_mem(&r, (const char *)data, size) != 0) {
        if (r.err[0] == '\0') abort();
        ex_rio_close(&r);
        return 0;
    }
    if (r.width < 1 || r.height < 1 || !r.grid || !r.geo.has_transform || !(r.geo.gt[1] > 0.0) ||
        (uint64_t)r.width * (uint64_t)r.height > size / 2 + 1)
        abort();
    r.nodata_to_nan = 1;
    if (ex_rio_read(&r, 0, r.width - 8, r.height - 8, 16, 16, win, 16) != 0) abort();
    if (ex_rio_read(&r, 1, 0, 0, 1, 1, win, 1) == 0) abort(); /* one band only */
    ex_rio_close(&r);
    return 0;
}
