/* libFuzzer target for the visibility-field file decoder (hfvis_visfield_decode): it must never
 * crash, must fail only with FORMAT, LIMIT or OUT_OF_MEMORY (leaving the output untouched), and
 * what it accepts must be a valid field that re-encodes to the very same bytes (the format has
 * one encoding per field) and answers queries.
 * Seeds: test/fuzz/seeds/visfield. Built and run by `make fuzz`. */
#include "hfvis.h"
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    hfvis_visfield vf, pat;
    unsigned char *enc;
    size_t need, written = 0;
    hfvis_status s;
    int a;
    memset(&vf, 0xA5, sizeof vf);
    memcpy(&pat, &vf, sizeof vf);
    s = hfvis_visfield_decode(data, size, NULL, &vf);
    if (s != HFVIS_OK) {
        if (s != HFVIS_ERR_FORMAT && s != HFVIS_ERR_LIMIT && s != HFVIS_ERR_OUT_OF_MEMORY) abort();
        if (memcmp(&vf, &pat, sizeof vf) != 0) abort(); /* untouched on error */
        return 0;
    }
    if (vf.positions_n < 1 || vf.positions_n > HFVIS_VISFIELD_MAX_N || vf.dir_res < 1
        || vf.dir_res > HFVIS_VISFIELD_MAX_DIR_RES || !(vf.radius > 0.0) || !isfinite(vf.radius)
        || !(vf.avg_distance >= 0.0 && vf.avg_distance <= 1.0) || !vf.maps
        || vf.maps_size != hfvis_visfield_size(vf.positions_n, vf.dir_res, vf.format))
        abort();
    need = hfvis_visfield_encode_size(&vf);
    if (need != size) abort();
    enc = (unsigned char *)malloc(need);
    if (!enc) {
        hfvis_visfield_free(NULL, &vf);
        return 0;
    }
    if (hfvis_visfield_encode(&vf, enc, need, &written) != HFVIS_OK || written != size) abort();
    if (memcmp(enc, data, size) != 0) abort(); /* one encoding per field */
    free(enc);
    /* queries from outside and inside read only what the decoder validated */
    for (a = 0; a < 8; a++) {
        double o[3], d[3], R = vf.radius;
        hfvis_visfield_hit h;
        int k;
        for (k = 0; k < 3; k++) {
            o[k] = vf.center[k] + ((a >> k) & 1 ? 2.5 : -0.3) * R * (k == 2 ? 1.0 : 0.7);
            d[k] = vf.center[k] - o[k] + 0.1 * R * (double)(a - k);
        }
        if (d[0] == 0.0 && d[1] == 0.0 && d[2] == 0.0) d[2] = 1.0;
        if (!isfinite(o[0] + o[1] + o[2] + d[0] + d[1] + d[2])) break; /* huge centre or radius */
        if (hfvis_visfield_query(&vf, o, d, 0.02 * R, &h) != HFVIS_OK) abort();
        if (h.result != HFVIS_VISFIELD_MISS
            && !(h.position < hfvis_visfield_position_count(vf.positions_n)))
            abort();
    }
    hfvis_visfield_free(NULL, &vf);
    return 0;
}
