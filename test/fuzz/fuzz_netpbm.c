/* libFuzzer target for the PFM / binary PGM window reader of examples/raster_io.h
 * (ex_rio_open_netpbm_mem: the header parsed, rows read by seeking, PFM rows bottom to top):
 * refused with a message, or every band's corner windows read within the data (the header's
 * size is checked against the data). Seeds: test/fuzz/seeds/netpbm. Built and run by `make fuzz`. */
#include "examples/raster_io.h"
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    ex_rio_reader r;
    float win[8 * 8];
    int b;
    if (ex_rio_open_netpbm_mem(&r, data, size) != 0) {
        if (r.err[0] == '\0') abort();
        ex_rio_close(&r);
        return 0;
    }
    for (b = 0; b < r.bands; b++) {
        if (ex_rio_read(&r, b, -3, -3, 8, 8, win, 8) != 0) abort(); /* the rows fit the data */
        if (ex_rio_read(&r, b, r.width - 4, r.height - 4, 8, 8, win, 8) != 0) abort();
    }
    ex_rio_close(&r);
    return 0;
}
