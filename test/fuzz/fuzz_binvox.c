/* libFuzzer target for the .binvox decoder: hfvis_binvox_decode must never crash, must accept
 * only cubes within HFVIS_VOLUME_MAX_VOXELS with a valid grid, and what it accepts must survive
 * encode -> decode (version-1 occupancy: any nonzero byte reads back as 1; same dims; origin and
 * cell within the number formatter's few ulps).
 * Seeds: test/fuzz/seeds/binvox. Built and run by `make fuzz`. */
#include "hfvis.h"
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    hfvis_volume_grid g, g2;
    uint8_t *occ = NULL, *again = NULL;
    unsigned char *enc;
    size_t n, need, written = 0, i;
    int a;
    hfvis_status s = hfvis_binvox_decode(data, size, NULL, &g, &occ);
    if (s != HFVIS_OK) {
        if (s != HFVIS_ERR_FORMAT && s != HFVIS_ERR_LIMIT && s != HFVIS_ERR_OUT_OF_MEMORY) abort();
        if (occ) abort(); /* untouched on error */
        return 0;
    }
    if (g.dims[0] < 1 || g.dims[0] != g.dims[1] || g.dims[1] != g.dims[2]) abort();
    n = (size_t)g.dims[0] * (size_t)g.dims[1] * (size_t)g.dims[2];
    if (n > HFVIS_VOLUME_MAX_VOXELS) abort();
    for (a = 0; a < 3; a++)
        if (!isfinite(g.origin[a]) || !isfinite(g.cell[a]) || !(g.cell[a] > 0.0)) abort();
    need = hfvis_binvox_encode_size(&g, occ);
    if (need == 0) { /* only when the scale D*cell would overflow on the way back */
        if (isfinite((double)g.dims[0] * g.cell[0])) abort();
        hfvis_free(NULL, occ);
        return 0;
    }
    enc = (unsigned char *)malloc(need);
    if (!enc) {
        hfvis_free(NULL, occ);
        return 0;
    }
    if (hfvis_binvox_encode(&g, occ, enc, need, &written) != HFVIS_OK || written != need) abort();
    if (hfvis_binvox_decode(enc, written, NULL, &g2, &again) != HFVIS_OK) abort();
    if (memcmp(g.dims, g2.dims, sizeof g.dims) != 0) abort();
    for (a = 0; a < 3; a++) {
        /* relative, or absolute among subnormals (whose relative precision is lower) */
        if (fabs(g2.origin[a] - g.origin[a]) > 1e-14 * fabs(g.origin[a]) + 1e-290) abort();
        if (fabs(g2.cell[a] - g.cell[a]) > 1e-14 * g.cell[a] + 1e-290) abort();
    }
    for (i = 0; i < n; i++)
        if (again[i] != (occ[i] != 0)) abort();
    hfvis_free(NULL, again);
    hfvis_free(NULL, occ);
    free(enc);
    return 0;
}
