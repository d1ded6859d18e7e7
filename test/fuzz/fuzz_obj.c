/* fuzz_obj.c - libFuzzer target for hfvis_obj_decode: it must never crash, leak or read out of
 * bounds, and whatever decodes must be a valid mesh that re-encodes and decodes to the same bits.
 * Seeds: test/fuzz/seeds/obj. Built and run by `make fuzz` (clang -fsanitize=fuzzer,address,undefined). */
#include "hfvis.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    hfvis_mesh m, back;
    size_t i, need, written = 0;
    unsigned char *buf;
    if (hfvis_obj_decode(data, size, NULL, &m) != HFVIS_OK) return 0;
    for (i = 0; i < 3 * m.vertex_count; i++)
        if (!isfinite(m.xyz[i])) abort();
    for (i = 0; i < 3 * m.triangle_count; i++)
        if (m.indices[i] >= m.vertex_count) abort();
    need = hfvis_obj_encode_size(&m);
    if (need == 0) abort();
    buf = (unsigned char *)malloc(need);
    if (!buf) abort();
    if (hfvis_obj_encode(&m, buf, need, &written) != HFVIS_OK || written != need) abort();
    if (hfvis_obj_decode(buf, written, NULL, &back) != HFVIS_OK) abort();
    if (back.vertex_count != m.vertex_count || back.triangle_count != m.triangle_count) abort();
    if (m.vertex_count && memcmp(back.xyz, m.xyz, 3 * m.vertex_count * sizeof(float)) != 0) abort();
    if (m.triangle_count
        && memcmp(back.indices, m.indices, 3 * m.triangle_count * sizeof(uint32_t)) != 0)
        abort();
    hfvis_mesh_free(NULL, &back);
    hfvis_mesh_free(NULL, &m);
    free(buf);
    return 0;
}
