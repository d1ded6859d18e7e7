/* libFuzzer target for the GeoTIFF reader of examples/raster_io.h (with zio.h's inflate): any
 * input either is refused with a message or opens; an opened image then decodes a corner window,
 * the far corner and a window hanging over the edges of every band it has (up to 4), each either
 * refused with a message or filled, NaN outside the raster. Memory stays bounded by the reader's
 * limits (EX_RIO_MAX_CHUNK per strip/tile, the codecs' ratio bounds, counts within the file); an
 * ESRI PE string found in GeoAsciiParams lies inside it. The same windows read in parts
 * (ex_rio_read_parallel, its parts run last first) give the same floats or the same refusal.
 * Seeds: test/fuzz/seeds/geotiff. Built and run by `make fuzz`. */
#include "examples/raster_io.h"
#include <stdint.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int last_first(void *user, size_t n, int (*fn)(void *ctx, size_t i), void *ctx)
{
    size_t i;
    (void)user;
    for (i = n; i-- > 0;)
        if (fn(ctx, i) != 0) return -1;
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    ex_rio_reader r;
    float win[32 * 32], part[32 * 32];
    int b, k;
    if (ex_rio_open_tiff_mem(&r, data, size) != 0) {
        if (r.err[0] == '\0') abort(); /* every refusal names its reason */
        ex_rio_close(&r);
        return 0;
    }
    if (r.width < 1 || r.height < 1 || r.bands < 1 || r.nchunks == 0 || !r.offsets || !r.counts) abort();
    { /* an ESRI PE string lies inside GeoAsciiParams */
        size_t len = 0;
        const char *pe = ex_rio_pe_string(&r.geo, &len);
        if (pe && (pe < r.geo.geoascii || len == 0 || (size_t)(pe - r.geo.geoascii) + len > r.geo.n_geoascii)) abort();
    }
    r.nodata_to_nan = (int)(size & 1);
    for (b = 0; b < r.bands && b < 4; b++) {
        int x[3] = { 0, r.width - 1, -3 }, y[3] = { 0, r.height - 1, r.height - 2 };
        for (k = 0; k < 3; k++) {
            int i, rc;
            char err[sizeof r.err];
            win[0] = 0.0f;
            rc = ex_rio_read(&r, b, x[k], y[k], 32, 32, win, 32);
            memcpy(err, r.err, sizeof err);
            if (ex_rio_read_parallel(&r, NULL, b, x[k], y[k], 32, 32, part, 32, last_first, NULL) != rc ||
                (rc == 0 && memcmp(win, part, sizeof win) != 0) || (rc != 0 && strcmp(err, r.err) != 0))
                abort();
            if (rc != 0) {
                if (r.err[0] == '\0') abort();
                continue;
            }
            /* cells outside the raster are NaN */
            for (i = 0; i < 32; i++)
                if ((long long)x[k] + i >= r.width && !isnan(win[i])) abort();
        }
    }
    ex_rio_close(&r);
    return 0;
}
