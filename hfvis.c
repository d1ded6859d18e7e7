/* hfvis.c - height fields. Part of hfvis (see hfvis.h for the conventions and the API).
 *
 * Contents
 *   1. Common: status strings; the library's one copy of the allocation, checked-size and PRNG
 *      helpers (hfvis__*, declared in hfvis.h's internal block, used by ssao.c and voxel.c too)
 *   2. Codecs: PGM (P2/P5) and PFM (Pf/PF) in memory, file wrappers; the NoData-safe PGM with
 *      its range comment
 *   3. Analytic test fields
 *   4. Bilinear sampling and normals ([P1] §4, §7 "quad sum"; docs/errata.md E5, E10)
 *   5. The sweep lattice ([P1] §4, Fig. 2; docs/errata.md E5)
 *   6. The P1 hull stack along one line ([P1] §5 Alg. 1, App. A.1)
 *   7. The sweep driver: sampled lattice, four-way symmetry, borders, gather ([P1] §4, §7; docs/errata.md E5, E7, E8);
 *      the search radius (blocks of R, prefix and undoable suffix hulls) and tiles in raster
 *      coordinates (docs/search-radius.md)
 *   8. Horizon outputs and the ray-march oracles ([P1] §2, [P2] §1); topographic openness (Yokoyama 2002)
 *   9. Light: uniform sky ([P1] Eq. 4-5), sky-view factor, sun visibility
 *  10. Environment light: prefix integrals and the L_p table ([P1] Eq. 6-7; docs/errata.md E9),
 *      the hemisphere-integration oracle
 *  11. P2: the convex-hull tree ([P2] §4-7, Alg. 1-3, App. A.2), visible sets ([P2] §10.1),
 *      intervisibility sweeps, visibility index, indirect light and bounces (docs/errata.md E17)
 *  12. Viewshed of one observer (Franklin & Ray 1994, R2) and its exact line-of-sight oracle
 *  13. Nowrouzezahrai-Snyder GI, math layer: real SH of order 4, zonal lobes, environment
 *      projection, normalized Legendre polynomials, Appendix-A wedge matrices ([NS09])
 *  14. Nowrouzezahrai-Snyder GI pipeline: slice scanning over the height pyramid, casting sets,
 *      wedges to SH visibility, environment, directional and key lights, diffuse and glossy
 *      bounces through the radiance pyramid, sub-sampling ([NS09] §3-9)
 *  15. Split runs: raw per-receiver direction sums in double and the partial-sum file
 *  16. Exact rays (beyond [P1]): rational directions, every grid-line crossing and the split
 *      bulging pieces swept with the [P1] §5 hull, the near and far field (a per-receiver
 *      stencil and shared far lines with hull trees), the per-receiver oracle, actual azimuths
 *      and their quadrature, the exact-mode light paths
 *  17. Solar radiation: NREL SPA (Reda & Andreas 2004/2008), r.sun's solar geometry and its ESRA
 *      clear sky (Suri & Hofierka 2004; Rigollier et al. 2000), time steps with sunrise and
 *      sunset inside the step, per-sample sites by blocks of one sun, irradiation over the
 *      horizon map (exact, near/far or lattice; only the directions the steps read): the step
 *      loop, the sector sums of long periods, the vectorized day path; and its oracle
 *      (docs/solar.md)
 *
 * Paper references: [P1] Timonen & Westerholm, "Scalable Height Field Self-Shadowing",
 * CGF 29(2), 2010 (thesis appendix A.1). Errata and choices: docs/errata.md E1-E18.
 */
#define HFVIS__INTERNAL /* the internal block of hfvis.h: shared helpers, not API */
#include "hfvis.h"

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#ifndef HFVIS_NO_STDIO
#include <stdio.h>
#endif

/* The allocation behind a NULL allocator (hfvis.h, "Memory"): define both to replace it. */
#if defined(HFVIS_MALLOC) != defined(HFVIS_FREE)
#error "define both HFVIS_MALLOC and HFVIS_FREE, or neither"
#endif
#ifndef HFVIS_MALLOC
#define HFVIS_MALLOC(size) malloc(size)
#define HFVIS_FREE(ptr) free(ptr)
#endif

/* Exact rays (section 16), called from the public routines of sections 8, 9, 10 and 15. */
/* One exact-ray direction: look vector (a, b), gcd 1, and its azimuth, unwrapped to within pi of
 * the requested one. */
typedef struct hf_ray {
    int a, b;
    double azimuth;
} hf_ray;
static int hf_exact_bound(const hfvis_sweep_options *o, int K);
static hf_ray hf_ray_nearest(double psi, int N);
static hfvis_status hf_exact_horizon_map(const hfvis_grid *g, int K, const hfvis_sweep_options *o,
                                         int begin, int end, float *out);
static hfvis_status hf_exact_horizon_direction(const hfvis_grid *g, int K, int k,
                                               const hfvis_sweep_options *o, float *out,
                                               ptrdiff_t out_stride);
static hfvis_status hf_exact_light(const hfvis_grid *g, int K, hfvis_sum_kind kind,
                                   const hfvis_env *env, const hfvis_env_options *eopts,
                                   const hfvis_sweep_options *o, double scale, float *out,
                                   ptrdiff_t out_stride);
static hfvis_status hf_exact_sun(const hfvis_grid *g, double azimuth, double elevation,
                                 double radius, const hfvis_sweep_options *o, float *out,
                                 ptrdiff_t out_stride);
static hfvis_status hf_exact_direction_sums(const hfvis_grid *g, int K, hfvis_sum_kind kind,
                                            const hfvis_env *env, const hfvis_env_options *eopts,
                                            const hfvis_sweep_options *o, int begin, int end,
                                            double *sums);

/* ========================================================================================== */
/* 1. Common                                                                                  */
/* ========================================================================================== */

const char *hfvis_status_string(hfvis_status status)
{
    switch (status) {
    case HFVIS_OK: return "HFVIS_OK: success";
    case HFVIS_ERR_INVALID_ARGUMENT: return "HFVIS_ERR_INVALID_ARGUMENT: invalid argument";
    case HFVIS_ERR_OUT_OF_MEMORY: return "HFVIS_ERR_OUT_OF_MEMORY: out of memory";
    case HFVIS_ERR_FORMAT: return "HFVIS_ERR_FORMAT: malformed data";
    case HFVIS_ERR_LIMIT: return "HFVIS_ERR_LIMIT: size exceeds a documented limit";
    case HFVIS_ERR_BUFFER_TOO_SMALL: return "HFVIS_ERR_BUFFER_TOO_SMALL: output buffer too small";
    case HFVIS_ERR_IO: return "HFVIS_ERR_IO: file could not be read or written";
    }
    return "HFVIS_ERR_UNKNOWN: unknown status code";
}

void hfvis_free(const hfvis_allocator *alloc, void *ptr) { hfvis__free(alloc, ptr); }

/* Four bits per step from a 16-entry table (entry i = the CRC register after shifting the
 * nibble i out), reflected polynomial 0xEDB88320. */
uint32_t hfvis_crc32(uint32_t crc, const void *data, size_t n)
{
    static const uint32_t t[16] = {
        0x00000000u, 0x1db71064u, 0x3b6e20c8u, 0x26d930acu, 0x76dc4190u, 0x6b6b51f4u,
        0x4db26158u, 0x5005713cu, 0xedb88320u, 0xf00f9344u, 0xd6d6a3e8u, 0xcb61b38cu,
        0x9b64c2b0u, 0x86d3d2d4u, 0xa00ae278u, 0xbdbdf21cu
    };
    const unsigned char *p = (const unsigned char *)data;
    size_t i;
    crc = ~crc;
    for (i = 0; i < n; i++) {
        crc ^= p[i];
        crc = (crc >> 4) ^ t[crc & 15u];
        crc = (crc >> 4) ^ t[crc & 15u];
    }
    return ~crc;
}

/* The library's one copy of the allocation, checked-size and PRNG helpers (declared in the
 * internal block of hfvis.h, used by all three .c files). */
void *hfvis__alloc(const hfvis_allocator *a, size_t bytes)
{
    if (bytes == 0) return NULL;
    if (a && a->alloc) return a->alloc(a->user, bytes);
    return HFVIS_MALLOC(bytes);
}

void hfvis__free(const hfvis_allocator *a, void *p)
{
    if (!p) return;
    if (a && a->alloc) {
        if (a->free) a->free(a->user, p);
        return;
    }
    HFVIS_FREE(p);
}

int hfvis__mul_size(size_t a, size_t b, size_t *out)
{
    if (a != 0 && b > SIZE_MAX / a) return 0;
    *out = a * b;
    return 1;
}

void *hfvis__alloc_array(const hfvis_allocator *a, size_t count, size_t elem)
{
    size_t bytes;
    if (!hfvis__mul_size(count, elem, &bytes)) return NULL;
    return hfvis__alloc(a, bytes);
}

int hfvis__plane_fits(ptrdiff_t stride, int height, int floats_per_pixel)
{
    return stride >= 1 && floats_per_pixel >= 1 &&
           (size_t)height <= (size_t)PTRDIFF_MAX / ((size_t)floats_per_pixel * sizeof(float)) / (size_t)stride;
}

int hfvis__all_finite(const double *v, int n)
{
    int i;
    for (i = 0; i < n; i++)
        if (!isfinite(v[i])) return 0;
    return 1;
}

uint64_t hfvis__mix64(uint64_t x)
{
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

uint64_t hfvis__splitmix64(uint64_t *state)
{
    uint64_t z = hfvis__mix64(*state);
    *state += 0x9E3779B97F4A7C15ull;
    return z;
}

uint32_t hfvis__pcg32_next(hfvis__pcg32 *g)
{
    uint64_t old = g->state;
    uint32_t xs, rot;
    g->state = old * 6364136223846793005ull + g->inc;
    xs = (uint32_t)(((old >> 18) ^ old) >> 27);
    rot = (uint32_t)(old >> 59);
    return (xs >> rot) | (xs << ((32u - rot) & 31u));
}

/* pcg32_srandom_r: stream selects the increment, seed the start. */
void hfvis__pcg32_seed(hfvis__pcg32 *g, uint64_t seed, uint64_t stream)
{
    g->state = 0;
    g->inc = (stream << 1) | 1u;
    (void)hfvis__pcg32_next(g);
    g->state += seed;
    (void)hfvis__pcg32_next(g);
}

double hfvis__pcg32_unit(hfvis__pcg32 *g)
{
    uint64_t hi = hfvis__pcg32_next(g) >> 5, lo = hfvis__pcg32_next(g) >> 6;
    return ((double)hi * 67108864.0 + (double)lo) * (1.0 / 9007199254740992.0);
}

/* Rejection below 2^32 mod n keeps every residue equally likely. */
uint32_t hfvis__pcg32_below(hfvis__pcg32 *g, uint32_t n)
{
    uint32_t limit = (uint32_t)(0u - n) % n, x;
    do x = hfvis__pcg32_next(g); while (x < limit);
    return x % n;
}

static int hf_grid_valid(const hfvis_grid *g)
{
    return g && g->z && g->width >= 1 && g->height >= 1 && g->stride >= g->width &&
           isfinite(g->cell_size) && g->cell_size > 0.0 &&
           (size_t)g->height <= SIZE_MAX / (size_t)g->stride;
}

/* width*height as size_t (valid grids only). */
static size_t hf_grid_count(const hfvis_grid *g) { return (size_t)g->width * (size_t)g->height; }

static int hf_border_valid(hfvis_border b) { return b >= HFVIS_BORDER_DEFAULT && b <= HFVIS_BORDER_WRAP; }

/* ========================================================================================== */
/* 2. Codecs: PGM (netpbm pgm(5), P2/P5) and PFM (netpbm pfm(5), Pf/PF), in memory and files */
/* ========================================================================================== */
/* Header syntax shared by both formats (pgm(5)): tokens are separated by whitespace (space, \t,
 * \n, \v, \f, \r) and '#' comments, which run to the next CR or LF; numbers are unsigned
 * decimal and end at whitespace, '#' or the end of the data; binary data starts right after
 * exactly one whitespace byte following the last header token. PFM writers never emit comments,
 * but accepting them costs nothing. P2 samples may be separated by comments too, as libnetpbm
 * reads them.
 *
 * hf_img_parse validates everything a decode depends on (header, limits, data length, and every
 * sample of a P2 file or of a P5 file whose maxval is not 255 or 65535) before anything is
 * written, so hfvis_image_info_read succeeds exactly when hfvis_image_decode succeeds with a
 * large enough buffer, and a failed call leaves its outputs untouched. */

#if FLT_RADIX != 2 || FLT_MANT_DIG != 24 || FLT_MAX_EXP != 128
#error "hfvis: the PFM codec needs IEEE-754 binary32 float"
#endif
typedef char hf_img_float_is_4_bytes[sizeof(float) == 4 ? 1 : -1];

typedef struct hf_img_header {
    hfvis_image_info info;
    int ascii;            /* P2 */
    size_t data_offset;   /* first byte of the pixel data (P2: first byte after maxval) */
    size_t values;        /* width*height*channels */
} hf_img_header;

static int hf_img_is_space(unsigned char c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\v' || c == '\f' || c == '\r';
}

static int hf_img_is_digit(unsigned char c)
{
    return c >= '0' && c <= '9';
}

/* First index at or after i that is neither whitespace nor inside a comment. */
static size_t hf_img_skip(const unsigned char *p, size_t n, size_t i)
{
    while (i < n) {
        if (p[i] == '#') {
            while (i < n && p[i] != '\n' && p[i] != '\r') i++;
        } else if (hf_img_is_space(p[i])) {
            i++;
        } else {
            break;
        }
    }
    return i;
}

/* Reads the unsigned decimal that follows p[*i] after at least one separator byte. Values above
 * cap saturate at cap + 1 so the caller can reject them. Returns 0 on a missing separator or
 * digit (including the end of the data) or a number glued to another character ("12x"). */
static int hf_img_number(const unsigned char *p, size_t n, size_t *i, unsigned long cap,
                         unsigned long *value)
{
    size_t j = hf_img_skip(p, n, *i);
    unsigned long v = 0;
    if (j == *i || j >= n || !hf_img_is_digit(p[j])) return 0;
    for (; j < n && hf_img_is_digit(p[j]); j++) {
        unsigned long d = (unsigned long)(p[j] - '0');
        v = (v > cap || d > cap || v > (cap - d) / 10) ? cap + 1 : v * 10 + d;
    }
    if (j < n && !hf_img_is_space(p[j]) && p[j] != '#') return 0;
    *i = j;
    *value = v;
    return 1;
}

/* Reads the PFM scale after at least one separator byte: [+-] digits [. digits] (or . digits),
 * optional e[+-]digits, converted from its first 17 significant digits, which is enough to tell
 * its sign and whether it is zero or overflows a double. Locale-independent (no strtod). */
static int hf_img_scale(const unsigned char *p, size_t n, size_t *i, double *scale)
{
    size_t j = hf_img_skip(p, n, *i);
    double m = 0.0;
    long exp10 = 0, e = 0;
    int negative = 0, e_negative = 0, digits = 0, significant = 0;
    if (j == *i || j >= n) return 0;
    if (p[j] == '+' || p[j] == '-') negative = p[j++] == '-';
    for (; j < n && hf_img_is_digit(p[j]); j++, digits++) {
        if (significant < 17) {
            m = m * 10.0 + (double)(p[j] - '0');
            significant += m != 0.0;
        } else if (exp10 < 100000) {
            exp10++;
        }
    }
    if (j < n && p[j] == '.') {
        for (j++; j < n && hf_img_is_digit(p[j]); j++, digits++) {
            if (significant < 17 && exp10 > -100000) {
                m = m * 10.0 + (double)(p[j] - '0');
                significant += m != 0.0;
                exp10--;
            }
        }
    }
    if (digits == 0) return 0;
    if (j < n && (p[j] == 'e' || p[j] == 'E')) {
        j++;
        if (j < n && (p[j] == '+' || p[j] == '-')) e_negative = p[j++] == '-';
        if (j >= n || !hf_img_is_digit(p[j])) return 0;
        for (; j < n && hf_img_is_digit(p[j]); j++)
            if (e < 100000) e = e * 10 + (long)(p[j] - '0');
    }
    exp10 += e_negative ? -e : e;
    if (exp10 > 400) exp10 = 400;
    if (exp10 < -400) exp10 = -400;
    /* Two half-size powers: 10^exp10 alone could overflow or underflow where m*10^exp10 does not. */
    m = m * pow(10.0, (double)(exp10 / 2)) * pow(10.0, (double)(exp10 - exp10 / 2));
    *i = j;
    *scale = negative ? -m : m;
    return 1;
}

/* P2 samples from p[i]: checks count numbers <= maxval and stores them when out != NULL. */
static int hf_img_p2_samples(const unsigned char *p, size_t n, size_t i, size_t count,
                             unsigned long maxval, float *out)
{
    size_t k;
    unsigned long v;
    for (k = 0; k < count; k++) {
        if (!hf_img_number(p, n, &i, maxval, &v) || v > maxval) return 0;
        if (out) out[k] = (float)v;
    }
    return 1;
}

/* P5 samples at p (1 byte each if maxval < 256, else 2 bytes big-endian): checks them against
 * maxval and stores them when out != NULL. */
static int hf_img_p5_samples(const unsigned char *p, size_t count, unsigned maxval, float *out)
{
    size_t k;
    for (k = 0; k < count; k++) {
        unsigned v = maxval < 256 ? p[k] : ((unsigned)p[2 * k] << 8) | p[2 * k + 1];
        if (v > maxval) return 0;
        if (out) out[k] = (float)v;
    }
    return 1;
}

/* PFM rows: the file stores the bottom row first (pfm(5)); row 0 of out is the top. */
static void hf_img_pfm_rows(const unsigned char *p, const hf_img_header *h, float *out)
{
    size_t row = (size_t)h->info.width * (size_t)h->info.channels, x;
    int y;
    for (y = 0; y < h->info.height; y++) {
        const unsigned char *src = p + (size_t)(h->info.height - 1 - y) * row * 4;
        float *dst = out + (size_t)y * row;
        for (x = 0; x < row; x++, src += 4) {
            uint32_t u = h->info.big_endian
                ? ((uint32_t)src[0] << 24) | ((uint32_t)src[1] << 16) | ((uint32_t)src[2] << 8) | src[3]
                : ((uint32_t)src[3] << 24) | ((uint32_t)src[2] << 16) | ((uint32_t)src[1] << 8) | src[0];
            memcpy(&dst[x], &u, 4);
        }
    }
}

/* Parses the header of a PGM/PFM held in p[0..n) (n may end anywhere after it): info, values
 * and data_offset; the samples are not looked at. */
static hfvis_status hf_img_header_parse(const unsigned char *p, size_t n, hf_img_header *out)
{
    hf_img_header h;
    unsigned long w, ht, maxval = 0;
    size_t i = 2;
    memset(&h, 0, sizeof h);
    if (n < 2 || p[0] != 'P') return HFVIS_ERR_FORMAT;
    if (p[1] == '2' || p[1] == '5') {
        h.info.format = HFVIS_FORMAT_PGM;
        h.info.channels = 1;
        h.ascii = p[1] == '2';
    } else if (p[1] == 'f' || p[1] == 'F') {
        h.info.format = HFVIS_FORMAT_PFM;
        h.info.channels = p[1] == 'F' ? 3 : 1;
    } else {
        return HFVIS_ERR_FORMAT;
    }
    if (!hf_img_number(p, n, &i, INT_MAX, &w) || !hf_img_number(p, n, &i, INT_MAX, &ht))
        return HFVIS_ERR_FORMAT;
    if (w > INT_MAX || ht > INT_MAX || w == 0 || ht == 0) return HFVIS_ERR_FORMAT;
    if (h.info.format == HFVIS_FORMAT_PGM) {
        if (!hf_img_number(p, n, &i, 65535, &maxval) || maxval < 1 || maxval > 65535)
            return HFVIS_ERR_FORMAT;
        h.info.maxval = (int)maxval;
    } else {
        double scale;
        if (!hf_img_scale(p, n, &i, &scale) || !isfinite(scale) || scale == 0.0)
            return HFVIS_ERR_FORMAT;
        h.info.big_endian = scale > 0.0;
    }
    if (!h.ascii) {
        if (i >= n || !hf_img_is_space(p[i])) return HFVIS_ERR_FORMAT;
        i++;
    }
    if (w > HFVIS_IMAGE_MAX_DIM || ht > HFVIS_IMAGE_MAX_DIM) return HFVIS_ERR_LIMIT;
    h.info.width = (int)w;
    h.info.height = (int)ht;
    if (!hfvis__mul_size((size_t)w, (size_t)ht, &h.values)
        || !hfvis__mul_size(h.values, (size_t)h.info.channels, &h.values)
        || h.values > HFVIS_IMAGE_MAX_VALUES)
        return HFVIS_ERR_LIMIT;
    h.data_offset = i;
    *out = h;
    return HFVIS_OK;
}

/* Bytes of the binary samples (P5, PFM) of a parsed header. */
static int hf_img_data_bytes(const hf_img_header *h, size_t *bytes)
{
    size_t bytes_per_value = h->info.format == HFVIS_FORMAT_PFM ? 4 : h->info.maxval < 256 ? 1 : 2;
    return hfvis__mul_size(h->values, bytes_per_value, bytes);
}

/* Parses and validates a whole PGM/PFM held in p[0..n); see the section comment. */
static hfvis_status hf_img_parse(const unsigned char *p, size_t n, hf_img_header *out)
{
    hf_img_header h;
    size_t i, bytes;
    unsigned long maxval;
    hfvis_status s = hf_img_header_parse(p, n, &h);
    if (s != HFVIS_OK) return s;
    i = h.data_offset;
    maxval = (unsigned long)h.info.maxval;
    if (h.ascii) {
        if (!hf_img_p2_samples(p, n, i, h.values, maxval, NULL)) return HFVIS_ERR_FORMAT;
    } else {
        if (!hf_img_data_bytes(&h, &bytes) || n - i < bytes) return HFVIS_ERR_FORMAT;
        if (h.info.format == HFVIS_FORMAT_PGM && maxval != 255 && maxval != 65535
            && !hf_img_p5_samples(p + i, h.values, (unsigned)maxval, NULL))
            return HFVIS_ERR_FORMAT;
    }
    *out = h;
    return HFVIS_OK;
}

/* Writes the pixels of a file that hf_img_parse accepted. */
static void hf_img_write_pixels(const unsigned char *p, size_t n, const hf_img_header *h,
                                float *out)
{
    if (h->info.format == HFVIS_FORMAT_PFM)
        hf_img_pfm_rows(p + h->data_offset, h, out);
    else if (h->ascii)
        (void)hf_img_p2_samples(p, n, h->data_offset, h->values, (unsigned long)h->info.maxval, out);
    else
        (void)hf_img_p5_samples(p + h->data_offset, h->values, (unsigned)h->info.maxval, out);
}

HFVIS_API hfvis_status hfvis_image_info_read(const void *data, size_t size, hfvis_image_info *info)
{
    hf_img_header h;
    hfvis_status s;
    if (!data || !info) return HFVIS_ERR_INVALID_ARGUMENT;
    s = hf_img_parse((const unsigned char *)data, size, &h);
    if (s != HFVIS_OK) return s;
    *info = h.info;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_image_decode(const void *data, size_t size, float *out,
                                          size_t out_count, hfvis_image_info *info)
{
    hf_img_header h;
    hfvis_status s;
    if (!data || !out) return HFVIS_ERR_INVALID_ARGUMENT;
    s = hf_img_parse((const unsigned char *)data, size, &h);
    if (s != HFVIS_OK) return s;
    if (out_count < h.values) return HFVIS_ERR_BUFFER_TOO_SMALL;
    hf_img_write_pixels((const unsigned char *)data, size, &h, out);
    if (info) *info = h.info;
    return HFVIS_OK;
}

/* Header "P5\n<w> <h>\n<maxval>\n" (maxval > 0) or "Pf\n<w> <h>\n-1.0\n" / "PF..." (maxval 0,
 * channels 1 or 3), into buf; returns its length, at most HF_IMG_HEADER_MAX bytes. */
#define HF_IMG_HEADER_MAX 31 /* "P5\n" + 10 digits + ' ' + 10 digits + '\n' + "65535\n" */
static size_t hf_img_header_text(unsigned char *buf, int width, int height, int channels,
                                 int maxval)
{
    unsigned long fields[3];
    size_t len = 0, f;
    fields[0] = (unsigned long)width;
    fields[1] = (unsigned long)height;
    fields[2] = (unsigned long)maxval;
    buf[len++] = 'P';
    buf[len++] = (unsigned char)(maxval > 0 ? '5' : channels == 3 ? 'F' : 'f');
    buf[len++] = '\n';
    for (f = 0; f < (maxval > 0 ? 3u : 2u); f++) {
        unsigned char digits[12];
        size_t nd = 0;
        unsigned long v = fields[f];
        do {
            digits[nd++] = (unsigned char)('0' + v % 10);
            v /= 10;
        } while (v != 0);
        while (nd > 0) buf[len++] = digits[--nd];
        buf[len++] = (unsigned char)(f == 0 ? ' ' : '\n');
    }
    if (maxval == 0) {
        memcpy(buf + len, "-1.0\n", 5);
        len += 5;
    }
    return len;
}

/* Header plus bytes_per_value*width*height*channels, or 0 if invalid or overflowing. */
static size_t hf_img_encode_size(int width, int height, int channels, int maxval,
                                 size_t bytes_per_value)
{
    unsigned char header[HF_IMG_HEADER_MAX];
    size_t values, bytes, head;
    if (width < 1 || height < 1) return 0;
    head = hf_img_header_text(header, width, height, channels, maxval);
    if (!hfvis__mul_size((size_t)width, (size_t)height, &values)
        || !hfvis__mul_size(values, (size_t)channels, &values)
        || !hfvis__mul_size(values, bytes_per_value, &bytes) || bytes > SIZE_MAX - head)
        return 0;
    return head + bytes;
}

HFVIS_API size_t hfvis_pfm_encode_size(int width, int height, int channels)
{
    if (channels != 1 && channels != 3) return 0;
    return hf_img_encode_size(width, height, channels, 0, 4);
}

HFVIS_API size_t hfvis_pgm_encode_size(int width, int height, int maxval)
{
    if (maxval < 1 || maxval > 65535) return 0;
    return hf_img_encode_size(width, height, 1, maxval, maxval < 256 ? 1 : 2);
}

/* Row y of the caller's image starts at pixels + y*stride*channels: stride >= width, and the
 * offset of the last row must fit a ptrdiff_t (otherwise no such array can exist). */
static int hf_img_stride_ok(int width, int height, int channels, ptrdiff_t stride)
{
    size_t last;
    if (stride < width) return 0;
    return hfvis__mul_size((size_t)(height - 1), (size_t)stride, &last)
        && hfvis__mul_size(last, (size_t)channels, &last) && last <= (size_t)PTRDIFF_MAX;
}

HFVIS_API hfvis_status hfvis_pfm_encode(const float *pixels, int width, int height, int channels,
                                        ptrdiff_t stride, void *out, size_t out_capacity,
                                        size_t *written)
{
    unsigned char *dst = (unsigned char *)out;
    size_t need = hfvis_pfm_encode_size(width, height, channels), row, x;
    int y;
    if (!pixels || !out || !written || need == 0
        || !hf_img_stride_ok(width, height, channels, stride))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (out_capacity < need) return HFVIS_ERR_BUFFER_TOO_SMALL;
    dst += hf_img_header_text(dst, width, height, channels, 0);
    row = (size_t)width * (size_t)channels;
    /* Little-endian (scale -1), bottom row first (pfm(5)). */
    for (y = height - 1; y >= 0; y--) {
        const float *src = pixels + (ptrdiff_t)y * stride * channels;
        for (x = 0; x < row; x++) {
            uint32_t u;
            memcpy(&u, &src[x], 4);
            *dst++ = (unsigned char)(u & 0xffu);
            *dst++ = (unsigned char)((u >> 8) & 0xffu);
            *dst++ = (unsigned char)((u >> 16) & 0xffu);
            *dst++ = (unsigned char)(u >> 24);
        }
    }
    *written = need;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_pgm_encode(const float *pixels, int width, int height,
                                        ptrdiff_t stride, float lo, float hi, int maxval,
                                        void *out, size_t out_capacity, size_t *written)
{
    unsigned char *dst = (unsigned char *)out;
    size_t need = hfvis_pgm_encode_size(width, height, maxval);
    double dlo = (double)lo, range = (double)hi - (double)lo, top = (double)maxval;
    int x, y;
    if (!pixels || !out || !written || need == 0 || !isfinite(lo) || !isfinite(hi) || !(lo < hi)
        || !hf_img_stride_ok(width, height, 1, stride))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (out_capacity < need) return HFVIS_ERR_BUFFER_TOO_SMALL;
    dst += hf_img_header_text(dst, width, height, 1, maxval);
    for (y = 0; y < height; y++) {
        const float *src = pixels + (ptrdiff_t)y * stride;
        for (x = 0; x < width; x++) {
            double t = ((double)src[x] - dlo) / range * top;
            unsigned q;
            if (!isfinite(src[x]) || !(t > 0.0)) q = 0;
            else if (t >= top) q = (unsigned)maxval;
            else q = (unsigned)round(t);
            if (maxval > 255) *dst++ = (unsigned char)(q >> 8);
            *dst++ = (unsigned char)(q & 0xffu);
        }
    }
    *written = need;
    return HFVIS_OK;
}

/* NoData-safe PGM with its range (hfvis.h): a 16-bit P5 whose code 0 is NoData and whose codes
 * 1..65535 map [lo, hi], with the comment "# hfvis range LO HI nodata 0" after the magic. LO and HI
 * are written with 9 significant digits, which any float survives (2^-24 relative spacing against
 * a quantum of 1e-8), without stdio (the codecs work under HFVIS_NO_STDIO). */
#define HF_PGM_RANGE_TEXT_MAX 64 /* "# hfvis range " + 2 x 15 + " nodata 0\n" */

/* "d.dddddddde+xx" of a finite float into buf; returns the length (at most 15). */
static size_t hf_img_float_text(float f, unsigned char *buf)
{
    double v = (double)f, m;
    unsigned long digits;
    size_t len = 0;
    int e, k;
    if (v < 0.0) buf[len++] = '-', v = -v;
    if (v == 0.0) {
        e = 0, digits = 0;
    } else {
        e = (int)floor(log10(v));
        m = v / pow(10.0, (double)e); /* [1, 10) up to the rounding of log10 and pow */
        digits = (unsigned long)floor(m * 1e8 + 0.5);
        if (digits >= 1000000000ul) digits = (digits + 5) / 10, e++;
        if (digits < 100000000ul) digits = (unsigned long)floor(v / pow(10.0, (double)(e - 1)) * 1e8 + 0.5), e--;
    }
    for (k = 8; k >= 0; k--) { /* nine digits, a point after the first */
        unsigned long p = 1;
        int q;
        for (q = 0; q < k; q++) p *= 10;
        buf[len++] = (unsigned char)('0' + (digits / p) % 10);
        if (k == 8) buf[len++] = '.';
    }
    buf[len++] = 'e';
    buf[len++] = (unsigned char)(e < 0 ? '-' : '+');
    if (e < 0) e = -e;
    buf[len++] = (unsigned char)('0' + e / 10);
    buf[len++] = (unsigned char)('0' + e % 10);
    return len;
}

/* The comment line for [lo, hi]; returns its length. */
static size_t hf_pgm_range_text(float lo, float hi, unsigned char *buf)
{
    size_t len = 14;
    memcpy(buf, "# hfvis range ", 14);
    len += hf_img_float_text(lo, buf + len);
    buf[len++] = ' ';
    len += hf_img_float_text(hi, buf + len);
    memcpy(buf + len, " nodata 0\n", 10);
    return len + 10;
}

HFVIS_API size_t hfvis_pgm_range_encode_size(int width, int height, float lo, float hi)
{
    unsigned char text[HF_PGM_RANGE_TEXT_MAX];
    size_t base = hfvis_pgm_encode_size(width, height, 65535);
    size_t extra = isfinite(lo) && isfinite(hi) && lo < hi ? hf_pgm_range_text(lo, hi, text) : 0;
    if (base == 0 || extra == 0 || base > SIZE_MAX - extra) return 0;
    return base + extra;
}

HFVIS_API hfvis_status hfvis_pgm_range_encode(const float *pixels, int width, int height,
                                              ptrdiff_t stride, float lo, float hi, void *out,
                                              size_t out_capacity, size_t *written)
{
    unsigned char text[HF_PGM_RANGE_TEXT_MAX], *dst = (unsigned char *)out;
    size_t need = hfvis_pgm_range_encode_size(width, height, lo, hi), tlen;
    double dlo = (double)lo, range = (double)hi - (double)lo;
    int x, y;
    if (!pixels || !out || !written || need == 0 || !hf_img_stride_ok(width, height, 1, stride))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (out_capacity < need) return HFVIS_ERR_BUFFER_TOO_SMALL;
    tlen = hf_pgm_range_text(lo, hi, text);
    memcpy(dst, "P5\n", 3);
    memcpy(dst + 3, text, tlen);
    dst += 3 + tlen;
    {
        unsigned char head[HF_IMG_HEADER_MAX];
        size_t hl = hf_img_header_text(head, width, height, 1, 65535);
        memcpy(dst, head + 3, hl - 3); /* without its "P5\n" */
        dst += hl - 3;
    }
    for (y = 0; y < height; y++) {
        const float *src = pixels + (ptrdiff_t)y * stride;
        for (x = 0; x < width; x++) {
            double t = ((double)src[x] - dlo) / range * (double)HFVIS_PGM_RANGE_CODES;
            unsigned q;
            if (!isfinite(src[x])) q = HFVIS_PGM_NODATA_CODE;
            else if (!(t > 0.0)) q = 1;
            else if (t >= (double)HFVIS_PGM_RANGE_CODES) q = 65535;
            else q = 1u + (unsigned)floor(t + 0.5);
            *dst++ = (unsigned char)(q >> 8);
            *dst++ = (unsigned char)(q & 0xffu);
        }
    }
    *written = need;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_pgm_range_read(const void *data, size_t size, float *lo, float *hi)
{
    const unsigned char *p = (const unsigned char *)data;
    hf_img_header h;
    size_t i = 2;
    hfvis_status s;
    if (!data || !lo || !hi) return HFVIS_ERR_INVALID_ARGUMENT;
    s = hf_img_parse(p, size, &h);
    if (s != HFVIS_OK) return s;
    if (h.info.format != HFVIS_FORMAT_PGM) return HFVIS_ERR_FORMAT;
    while (i < h.data_offset) { /* each comment of the header */
        size_t end = i, j;
        double a, b;
        if (p[i] != '#') { i++; continue; }
        while (end < h.data_offset && p[end] != '\n' && p[end] != '\r') end++;
        j = i + 13;
        if (end - i > 14 && !memcmp(p + i, "# hfvis range", 13) && hf_img_scale(p, end, &j, &a) &&
            hf_img_scale(p, end, &j, &b) && end - j >= 9 && !memcmp(p + j, " nodata 0", 9) &&
            isfinite(a) && isfinite(b) && fabs(a) <= (double)FLT_MAX && fabs(b) <= (double)FLT_MAX &&
            (float)a < (float)b) {
            *lo = (float)a;
            *hi = (float)b;
            return HFVIS_OK;
        }
        i = end;
    }
    return HFVIS_ERR_FORMAT;
}

HFVIS_API hfvis_status hfvis_pgm_range_decode(const void *data, size_t size, float *out,
                                              size_t out_count, hfvis_image_info *info)
{
    hfvis_image_info inf;
    float lo, hi;
    size_t i, n;
    hfvis_status s = hfvis_pgm_range_read(data, size, &lo, &hi);
    if (s != HFVIS_OK) return s;
    if (!out) return HFVIS_ERR_INVALID_ARGUMENT;
    s = hfvis_image_decode(data, size, out, out_count, &inf);
    if (s != HFVIS_OK) return s;
    n = (size_t)inf.width * (size_t)inf.height;
    for (i = 0; i < n; i++) {
        double code = (double)out[i];
        out[i] = code == (double)HFVIS_PGM_NODATA_CODE ? (float)HFVIS__NAN
                 : (float)((double)lo + (code - 1.0) * ((double)hi - (double)lo) /
                                           (double)HFVIS_PGM_RANGE_CODES);
    }
    if (info) *info = inf;
    return HFVIS_OK;
}

#ifndef HFVIS_NO_STDIO
/* Reads a file into a block from alloc: the head first; when the sizer announces a size, exactly
 * that many bytes and one more (so that trailing data reaches the decoder, which refuses it or
 * ignores it as its format says), and a file shorter than announced is HFVIS_ERR_FORMAT without
 * reading further; else (no sizer, HFVIS__READ_ALL) the whole file. */
hfvis_status hfvis__read_file(const char *path, const hfvis_allocator *alloc, hfvis__sizer sizer,
                             unsigned char **data, size_t *size)
{
    FILE *f = fopen(path, "rb");
    unsigned char *buf;
    size_t cap = HFVIS__READ_HEAD, len, total;
    hfvis_status s;
    if (!f) return HFVIS_ERR_IO;
    buf = (unsigned char *)hfvis__alloc(alloc, cap);
    if (!buf) {
        fclose(f);
        return HFVIS_ERR_OUT_OF_MEMORY;
    }
    len = fread(buf, 1, cap, f);
    if (ferror(f)) {
        hfvis__free(alloc, buf);
        fclose(f);
        return HFVIS_ERR_IO;
    }
    total = HFVIS__READ_ALL;
    s = sizer ? sizer(buf, len, &total) : HFVIS_OK;
    if (s == HFVIS_OK && total != HFVIS__READ_ALL && len < cap && len < total)
        s = HFVIS_ERR_FORMAT; /* shorter than its header says */
    if (s != HFVIS_OK) {
        hfvis__free(alloc, buf);
        fclose(f);
        return s;
    }
    if (total != HFVIS__READ_ALL) {
        if (total >= SIZE_MAX - 1u) {
            hfvis__free(alloc, buf);
            fclose(f);
            return HFVIS_ERR_LIMIT;
        }
        if (len > total) len = total + 1u; /* one byte past the announced end is enough */
        else if (len == cap) {
            unsigned char *all;
            long end; /* a regular file shorter than announced is refused before allocating */
            if (fseek(f, 0, SEEK_END) == 0 && (end = ftell(f)) >= 0 &&
                ((unsigned long)end < total && (unsigned long)end >= len)) {
                hfvis__free(alloc, buf);
                fclose(f);
                return HFVIS_ERR_FORMAT;
            }
            if (fseek(f, (long)len, SEEK_SET) != 0) clearerr(f); /* a pipe: still at len */
            all = (unsigned char *)hfvis__alloc(alloc, total + 1u);
            if (!all) {
                hfvis__free(alloc, buf);
                fclose(f);
                return HFVIS_ERR_OUT_OF_MEMORY;
            }
            memcpy(all, buf, len);
            hfvis__free(alloc, buf);
            buf = all;
            len += fread(buf + len, 1, total + 1u - len, f);
            if (ferror(f) || len < total) {
                s = ferror(f) ? HFVIS_ERR_IO : HFVIS_ERR_FORMAT;
                hfvis__free(alloc, buf);
                fclose(f);
                return s;
            }
        }
        fclose(f);
        *data = buf;
        *size = len;
        return HFVIS_OK;
    }
    while (len == cap) { /* read to the end, doubling */
        unsigned char *bigger = cap > SIZE_MAX / 2 ? NULL : (unsigned char *)hfvis__alloc(alloc, cap * 2);
        if (!bigger) {
            hfvis__free(alloc, buf);
            fclose(f);
            return HFVIS_ERR_OUT_OF_MEMORY;
        }
        memcpy(bigger, buf, len);
        hfvis__free(alloc, buf);
        buf = bigger;
        cap *= 2;
        len += fread(buf + len, 1, cap - len, f);
        if (ferror(f)) {
            hfvis__free(alloc, buf);
            fclose(f);
            return HFVIS_ERR_IO;
        }
    }
    fclose(f);
    *data = buf;
    *size = len;
    return HFVIS_OK;
}

/* The sizer of PGM/PFM: the header, then exactly the binary samples; P2 reads to the end. */
static hfvis_status hf_img_sizer(const unsigned char *head, size_t n, size_t *total)
{
    hf_img_header h;
    size_t bytes;
    hfvis_status s = hf_img_header_parse(head, n, &h);
    if (s != HFVIS_OK) return s;
    if (h.ascii) /* *total stays HFVIS__READ_ALL; text holds no NUL byte (/dev/zero, junk) */
        return h.data_offset < n && memchr(head + h.data_offset, 0, n - h.data_offset)
                   ? HFVIS_ERR_FORMAT : HFVIS_OK;
    if (!hf_img_data_bytes(&h, &bytes) || bytes > SIZE_MAX - h.data_offset) return HFVIS_ERR_LIMIT;
    *total = h.data_offset + bytes;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_image_load(const char *path, const hfvis_allocator *alloc,
                                        float **pixels, hfvis_image_info *info)
{
    unsigned char *data;
    size_t size, bytes;
    float *px;
    hf_img_header h;
    hfvis_status s;
    if (!path || !pixels || !info) return HFVIS_ERR_INVALID_ARGUMENT;
    s = hfvis__read_file(path, alloc, hf_img_sizer, &data, &size);
    if (s != HFVIS_OK) return s;
    s = hf_img_parse(data, size, &h);
    if (s == HFVIS_OK) {
        px = hfvis__mul_size(h.values, sizeof(float), &bytes) ? (float *)hfvis__alloc(alloc, bytes) : NULL;
        if (px) {
            hf_img_write_pixels(data, size, &h, px);
            *pixels = px;
            *info = h.info;
        } else {
            s = HFVIS_ERR_OUT_OF_MEMORY;
        }
    }
    hfvis__free(alloc, data);
    return s;
}

hfvis_write_options hfvis_write_options_default(void)
{
    hfvis_write_options o;
    memset(&o, 0, sizeof o);
    return o;
}

/* The temporary name: "<path>.tmp<8 hex digits>" beside path; when the last component would
 * then exceed HF_NAME_MAX bytes, that component is cut to leave room for the suffix (same
 * directory, same file system, so the rename stays atomic). The suffix hashes the address of a
 * local of the caller (key), which differs between concurrent calls in one process (and usually
 * between processes); a name already taken is skipped. */
#define HF_NAME_MAX 255    /* bytes of a file name on common file systems (POSIX NAME_MAX) */
#define HF_TMP_SUFFIX 12u  /* ".tmp" and 8 hex digits */
hfvis_status hfvis_write_begin(const char *path, const hfvis_write_options *opts, FILE **file,
                               char **temp_path)
{
    static const char hex[] = "0123456789abcdef";
    size_t len, base = 0, keep, k;
    const void *addrs[2];
    unsigned char raw[sizeof addrs];
    uint32_t tag = 2166136261u; /* FNV-1a */
    char *tmp;
    FILE *f = NULL;
    int attempt;
    if (file) *file = NULL;
    if (temp_path) *temp_path = NULL;
    if (!path || !file || !temp_path || path[0] == '\0') return HFVIS_ERR_INVALID_ARGUMENT;
    len = strlen(path);
    if (len > SIZE_MAX - HF_TMP_SUFFIX - 1u) return HFVIS_ERR_IO;
    for (k = 0; k < len; k++)
        if (path[k] == '/' || path[k] == '\\') base = k + 1;
    keep = len; /* bytes of path kept before the suffix */
    if (len - base + HF_TMP_SUFFIX > HF_NAME_MAX) keep = base + (HF_NAME_MAX - HF_TMP_SUFFIX);
    tmp = (char *)hfvis__alloc(NULL, keep + HF_TMP_SUFFIX + 1u);
    if (!tmp) return HFVIS_ERR_OUT_OF_MEMORY;
    addrs[0] = file;
    addrs[1] = &len;
    memcpy(raw, addrs, sizeof raw);
    for (k = 0; k < sizeof raw; k++) tag = (uint32_t)((tag ^ raw[k]) * 16777619u);
    memcpy(tmp, path, keep);
    memcpy(tmp + keep, ".tmp", 4);
    tmp[keep + HF_TMP_SUFFIX] = '\0';
    for (attempt = 0; attempt < 16; attempt++, tag += 0x9e3779b9u) {
        FILE *existing;
        for (k = 0; k < 8; k++) tmp[keep + 4 + k] = hex[(tag >> (28 - 4 * k)) & 15u];
        existing = fopen(tmp, "rb");
        if (!existing) break;
        fclose(existing);
    }
    if (attempt < 16) {
        if (opts && opts->on_temp) opts->on_temp(opts->user, tmp); /* before it exists */
        f = fopen(tmp, "wb");
    }
    if (!f) {
        if (attempt < 16 && opts && opts->on_temp) opts->on_temp(opts->user, NULL);
        hfvis__free(NULL, tmp);
        return HFVIS_ERR_IO;
    }
    *file = f;
    *temp_path = tmp;
    return HFVIS_OK;
}
#undef HF_NAME_MAX
#undef HF_TMP_SUFFIX

hfvis_status hfvis_write_end(const char *path, FILE *file, char *temp_path, int commit,
                             const hfvis_write_options *opts)
{
    int ok;
    if (!file || !temp_path) { /* nothing was opened: release what there is */
        if (file) HFVIS_FCLOSE(file);
        hfvis__free(NULL, temp_path);
        return HFVIS_ERR_INVALID_ARGUMENT;
    }
    ok = (HFVIS_FFLUSH(file) == 0) && !ferror(file);
    ok = (HFVIS_FCLOSE(file) == 0) && ok; /* closed even when the flush failed */
    if (ok && commit && (!path || HFVIS_RENAME(temp_path, path) != 0)) {
#if defined(_WIN32)
        /* Windows' rename does not replace an existing file: replace non-atomically. */
        ok = path && remove(path) == 0 && HFVIS_RENAME(temp_path, path) == 0;
#else
        ok = 0;
#endif
    }
    if (!ok || !commit) remove(temp_path);
    if (opts && opts->on_temp) opts->on_temp(opts->user, NULL); /* renamed or removed */
    hfvis__free(NULL, temp_path);
    if (!path) return HFVIS_ERR_INVALID_ARGUMENT;
    return !commit || ok ? HFVIS_OK : HFVIS_ERR_IO;
}

hfvis_status hfvis_write_file(const char *path, const void *bytes, size_t n,
                              const hfvis_write_options *opts)
{
    FILE *f;
    char *tmp;
    hfvis_status s;
    if (!path || (!bytes && n > 0) || path[0] == '\0') return HFVIS_ERR_INVALID_ARGUMENT;
    s = hfvis_write_begin(path, opts, &f, &tmp);
    if (s != HFVIS_OK) return s;
    if (n > 0 && HFVIS_FWRITE(bytes, 1, n, f) != n) { /* short write (disk full, size limit) */
        hfvis_write_end(path, f, tmp, 0, opts);
        return HFVIS_ERR_IO;
    }
    return hfvis_write_end(path, f, tmp, 1, opts);
}

HFVIS_API hfvis_status hfvis_pfm_save(const char *path, const float *pixels, int width,
                                      int height, int channels, ptrdiff_t stride)
{
    size_t need = hfvis_pfm_encode_size(width, height, channels), written = 0;
    unsigned char *buf;
    hfvis_status s;
    if (!path || !pixels || need == 0 || !hf_img_stride_ok(width, height, channels, stride))
        return HFVIS_ERR_INVALID_ARGUMENT;
    buf = (unsigned char *)hfvis__alloc(NULL, need);
    if (!buf) return HFVIS_ERR_OUT_OF_MEMORY;
    s = hfvis_pfm_encode(pixels, width, height, channels, stride, buf, need, &written);
    if (s == HFVIS_OK) s = hfvis_write_file(path, buf, written, NULL);
    hfvis__free(NULL, buf);
    return s;
}

HFVIS_API hfvis_status hfvis_pgm_save(const char *path, const float *pixels, int width,
                                      int height, ptrdiff_t stride, float lo, float hi,
                                      int maxval)
{
    size_t need = hfvis_pgm_encode_size(width, height, maxval), written = 0;
    unsigned char *buf;
    hfvis_status s;
    if (!path || !pixels || need == 0 || !isfinite(lo) || !isfinite(hi) || !(lo < hi)
        || !hf_img_stride_ok(width, height, 1, stride))
        return HFVIS_ERR_INVALID_ARGUMENT;
    buf = (unsigned char *)hfvis__alloc(NULL, need);
    if (!buf) return HFVIS_ERR_OUT_OF_MEMORY;
    s = hfvis_pgm_encode(pixels, width, height, stride, lo, hi, maxval, buf, need, &written);
    if (s == HFVIS_OK) s = hfvis_write_file(path, buf, written, NULL);
    hfvis__free(NULL, buf);
    return s;
}
HFVIS_API hfvis_status hfvis_pgm_range_save(const char *path, const float *pixels, int width,
                                            int height, ptrdiff_t stride, float lo, float hi)
{
    size_t need = hfvis_pgm_range_encode_size(width, height, lo, hi), written = 0;
    unsigned char *buf;
    hfvis_status s;
    if (!path || !pixels || need == 0 || !hf_img_stride_ok(width, height, 1, stride))
        return HFVIS_ERR_INVALID_ARGUMENT;
    buf = (unsigned char *)hfvis__alloc(NULL, need);
    if (!buf) return HFVIS_ERR_OUT_OF_MEMORY;
    s = hfvis_pgm_range_encode(pixels, width, height, stride, lo, hi, buf, need, &written);
    if (s == HFVIS_OK) s = hfvis_write_file(path, buf, written, NULL);
    hfvis__free(NULL, buf);
    return s;
}
#endif /* HFVIS_NO_STDIO */

/* ========================================================================================== */
/* 3. Analytic test fields                                                                    */
/* ========================================================================================== */

/* Value noise in [-1, 1] at (x, y) for one octave: hashed lattice values with the quintic fade,
 * so the surface is C2 and any bilinear grid sampling of it is a fair test terrain. */
static double hf_value_noise(uint64_t seed, double x, double y)
{
    double fx0 = floor(x), fy0 = floor(y);
    double fx = x - fx0, fy = y - fy0;
    int64_t ix = (int64_t)fx0, iy = (int64_t)fy0;
    double v[4];
    int c;
    for (c = 0; c < 4; c++) {
        uint64_t hx = (uint64_t)(ix + (c & 1)), hy = (uint64_t)(iy + (c >> 1));
        uint64_t h = hfvis__mix64(seed ^ hfvis__mix64(hx * 0x9E3779B97F4A7C15ull ^ hfvis__mix64(hy)));
        v[c] = (double)(h >> 11) * (2.0 / 9007199254740992.0) - 1.0;
    }
    fx = fx * fx * fx * (fx * (fx * 6.0 - 15.0) + 10.0);
    fy = fy * fy * fy * (fy * (fy * 6.0 - 15.0) + 10.0);
    return (v[0] * (1.0 - fx) + v[1] * fx) * (1.0 - fy) + (v[2] * (1.0 - fx) + v[3] * fx) * fy;
}

static int hf_field_valid(const hfvis_field *f)
{
    if (!f) return 0;
    if (!(isfinite(f->x0) && isfinite(f->y0) && isfinite(f->height) && isfinite(f->slope) &&
          isfinite(f->slope_x) && isfinite(f->slope_y) && isfinite(f->radius) &&
          isfinite(f->amplitude) && isfinite(f->wavelength) && isfinite(f->persistence)))
        return 0;
    switch (f->kind) {
    case HFVIS_FIELD_PLANE: case HFVIS_FIELD_TILTED_PLANE: case HFVIS_FIELD_V_VALLEY:
    case HFVIS_FIELD_L1_PIT: case HFVIS_FIELD_LINF_PIT: case HFVIS_FIELD_CONE:
    case HFVIS_FIELD_STEP:
        return 1;
    case HFVIS_FIELD_HEMISPHERE: return f->radius > 0.0;
    case HFVIS_FIELD_SINUSOID: return f->wavelength > 0.0;
    case HFVIS_FIELD_FBM:
        return f->wavelength > 0.0 && f->octaves >= 0 && f->octaves <= 30 && f->persistence >= 0.0;
    case HFVIS_FIELD_BRICKS: return f->wavelength > 0.0 && f->radius >= 0.0;
    }
    return 0;
}

double hfvis_field_height(void *field, double x, double y)
{
    const hfvis_field *f = (const hfvis_field *)field;
    double dx, dy, r;
    if (!hf_field_valid(f) || !isfinite(x) || !isfinite(y)) return HFVIS__NAN;
    dx = x - f->x0;
    dy = y - f->y0;
    switch (f->kind) {
    case HFVIS_FIELD_PLANE: return f->height;
    case HFVIS_FIELD_TILTED_PLANE: return f->height + f->slope_x * dx + f->slope_y * dy;
    case HFVIS_FIELD_V_VALLEY: return f->height + f->slope * fabs(dx);
    case HFVIS_FIELD_L1_PIT: return f->height + f->slope * (fabs(dx) + fabs(dy));
    case HFVIS_FIELD_LINF_PIT: return f->height + f->slope * fmax(fabs(dx), fabs(dy));
    case HFVIS_FIELD_CONE: return f->height + f->slope * sqrt(dx * dx + dy * dy);
    case HFVIS_FIELD_HEMISPHERE:
        r = sqrt(dx * dx + dy * dy) / f->radius;
        return r < 1.0 ? f->height + f->amplitude * sqrt(1.0 - r * r) : f->height;
    case HFVIS_FIELD_STEP: return dx >= 0.0 ? f->height + f->amplitude : f->height;
    case HFVIS_FIELD_SINUSOID:
        return f->height + f->amplitude * sin(2.0 * HFVIS__PI * x / f->wavelength) *
                               sin(2.0 * HFVIS__PI * y / f->wavelength);
    case HFVIS_FIELD_FBM: {
        int octaves = f->octaves ? f->octaves : 8, o;
        double gain = f->persistence > 0.0 ? f->persistence : 0.5;
        double amp = 1.0, freq = 1.0 / f->wavelength, sum = 0.0, norm = 0.0;
        for (o = 0; o < octaves; o++) {
            sum += amp * hf_value_noise(f->seed + (uint64_t)o * 0x632BE59BD9B4E019ull, x * freq, y * freq);
            norm += amp;
            amp *= gain;
            freq *= 2.0;
        }
        return f->height + f->amplitude * (norm > 0.0 ? sum / norm : 0.0);
    }
    case HFVIS_FIELD_BRICKS: {
        double bw = f->wavelength, bh = 0.5 * f->wavelength, mortar = f->radius > 0.0 ? f->radius : 1.0;
        double row = floor(dy / bh), shift = fmod(row, 2.0) != 0.0 ? 0.5 * bw : 0.0;
        double col = floor((dx + shift) / bw);
        double u = dx + shift - col * bw, v = dy - row * bh;
        uint64_t id = hfvis__mix64(f->seed ^ hfvis__mix64((uint64_t)(int64_t)col * 0x9E3779B97F4A7C15ull ^
                                                  (uint64_t)(int64_t)row));
        double jitter = ((double)(id >> 11) * (1.0 / 9007199254740992.0) - 0.5) * 0.1;
        if (u < mortar || v < mortar) return f->height - f->amplitude;
        return f->height + f->amplitude * jitter;
    }
    }
    return HFVIS__NAN;
}

hfvis_status hfvis_field_generate(const hfvis_field *field, int width, int height,
                                  ptrdiff_t stride, float *out)
{
    int x, y;
    if (!hf_field_valid(field) || !out || width < 1 || height < 1 || stride < width ||
        (size_t)height > SIZE_MAX / (size_t)stride)
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (y = 0; y < height; y++)
        for (x = 0; x < width; x++)
            out[(ptrdiff_t)y * stride + x] =
                (float)hfvis_field_height((void *)(uintptr_t)field, (double)x, (double)y);
    return HFVIS_OK;
}

/* ========================================================================================== */
/* 4. Bilinear sampling and normals                                                           */
/* ========================================================================================== */

/* Bilinear height at (x, y) inside [0, W-1] x [0, H-1] (docs/errata.md E5: x0 = min(floor x, W-2),
 * 1-D for W or H = 1). A tap with zero weight is never read into the sum, so a hole beside an
 * exact sample position does not leak into it. */
/* The bilinear value from the taps at p (cell origin) with fractions fx, fy in [0, 1]; taps of
 * zero weight are not read, so a hole next to an exact sample position does not leak. */
static inline double hf_bilerp_taps(const float *p, ptrdiff_t stride, double fx, double fy)
{
    double r0, r1;
    if (fx == 0.0) {
        r0 = (double)p[0];
        r1 = fy != 0.0 ? (double)p[stride] : 0.0;
    } else if (fx == 1.0) {
        r0 = (double)p[1];
        r1 = fy != 0.0 ? (double)p[stride + 1] : 0.0;
    } else {
        r0 = (double)p[0] * (1.0 - fx) + (double)p[1] * fx;
        r1 = fy != 0.0 ? (double)p[stride] * (1.0 - fx) + (double)p[stride + 1] * fx : 0.0;
    }
    if (fy == 0.0) r1 = r0;
    else if (fy != 1.0) r1 = r0 * (1.0 - fy) + r1 * fy;
    return isfinite(r1) ? r1 : HFVIS__NAN; /* a +-Inf tap is a hole too */
}

static inline double hf_bilerp(const float *z, ptrdiff_t stride, int W, int H, double x, double y)
{
    int x0, y0;
    double fx, fy;
    if (W > 1) {
        double f = floor(x);
        x0 = f >= (double)(W - 2) ? W - 2 : (int)f;
        fx = x - (double)x0;
    } else {
        x0 = 0;
        fx = 0.0;
    }
    if (H > 1) {
        double f = floor(y);
        y0 = f >= (double)(H - 2) ? H - 2 : (int)f;
        fy = y - (double)y0;
    } else {
        y0 = 0;
        fy = 0.0;
    }
    return hf_bilerp_taps(z + (ptrdiff_t)y0 * stride + x0, stride, fx, fy);
}

static double hf_clampd(double v, double lo, double hi) { return v < lo ? lo : v > hi ? hi : v; }

double hfvis_grid_sample(const hfvis_grid *grid, double x, double y)
{
    if (!hf_grid_valid(grid) || isnan(x) || isnan(y)) return HFVIS__NAN;
    return hf_bilerp(grid->z, grid->stride, grid->width, grid->height,
                     hf_clampd(x, 0.0, (double)(grid->width - 1)),
                     hf_clampd(y, 0.0, (double)(grid->height - 1)));
}

/* One gradient component along an axis: central difference in the interior, one-sided at the
 * border or beside a hole, 0 if both neighbours are missing. [P1] §7 sums the unnormalised
 * normals of the four quads around the sample; that sum equals this central difference
 * ([P1] §7; docs/errata.md E10), and at the border it is exactly the one-sided difference. */
static double hf_slope_1d(double hm, double h0, double hp, int has_m, int has_p)
{
    has_m = has_m && isfinite(hm);
    has_p = has_p && isfinite(hp);
    if (has_m && has_p) return (hm - hp) * 0.5;
    if (has_p) return h0 - hp;
    if (has_m) return hm - h0;
    return 0.0;
}

#define HF_SLOPE_SQUARE_MAX 1e150 /* a slope whose square stays far from DBL_MAX (1.8e308) */
/* The unit normal (gx, gy, cell)/|.| of the height drops gx, gy per cell along +x, +y. */
static void hf_normal_of(double gx, double gy, const hfvis_grid *g, double n[3])
{
    double len;
    if (fabs(gx) / g->cell_size < HF_SLOPE_SQUARE_MAX && fabs(gy) / g->cell_size < HF_SLOPE_SQUARE_MAX) {
        gx /= g->cell_size;
        gy /= g->cell_size;
        len = sqrt(gx * gx + gy * gy + 1.0);
        n[0] = gx / len;
        n[1] = gy / len;
        n[2] = 1.0 / len;
    } else { /* (gx, gy, cell) scaled by its largest part first: no overflow for tiny cells */
        double m = fmax(fmax(fabs(gx), fabs(gy)), g->cell_size), c = g->cell_size / m;
        gx /= m;
        gy /= m;
        len = sqrt(gx * gx + gy * gy + c * c);
        n[0] = gx / len;
        n[1] = gy / len;
        n[2] = c / len;
    }
}

static void hf_normal_at(const hfvis_grid *g, int x, int y, double n[3])
{
    const float *p = g->z + (ptrdiff_t)y * g->stride + x;
    double h0 = (double)*p, gx, gy;
    if (!isfinite(h0)) {
        n[0] = n[1] = n[2] = HFVIS__NAN;
        return;
    }
    gx = hf_slope_1d(x > 0 ? (double)p[-1] : 0.0, h0, x + 1 < g->width ? (double)p[1] : 0.0,
                     x > 0, x + 1 < g->width);
    gy = hf_slope_1d(y > 0 ? (double)p[-g->stride] : 0.0, h0,
                     y + 1 < g->height ? (double)p[g->stride] : 0.0, y > 0, y + 1 < g->height);
    hf_normal_of(gx, gy, g, n);
}

/* Horn 1981's normal: each drop the (1, 2, 1)-weighted mean of the three central differences
 * across the 3x3 window (r.slope.aspect's and gdaldem's stencil); hf_normal_at where a cell of
 * the window is outside the grid or a hole (r.slope.aspect -e and gdaldem -compute_edges put the
 * centre's height there instead; without them those cells have no value). */
static void hf_normal_horn_at(const hfvis_grid *g, int x, int y, double n[3])
{
    const float *p = g->z + (ptrdiff_t)y * g->stride + x;
    ptrdiff_t s = g->stride;
    double a, b, c, d, f, gg, h, i;
    if (x < 1 || y < 1 || x + 1 >= g->width || y + 1 >= g->height) {
        hf_normal_at(g, x, y, n);
        return;
    }
    a = (double)p[-s - 1]; b = (double)p[-s]; c = (double)p[-s + 1];
    d = (double)p[-1]; f = (double)p[1];
    gg = (double)p[s - 1]; h = (double)p[s]; i = (double)p[s + 1];
    if (!isfinite((double)*p) || !isfinite(a + b + c + d + f + gg + h + i)) {
        hf_normal_at(g, x, y, n);
        return;
    }
    hf_normal_of(((a + 2.0 * d + gg) - (c + 2.0 * f + i)) * 0.125,
                 ((a + 2.0 * b + c) - (gg + 2.0 * h + i)) * 0.125, g, n);
}

hfvis_status hfvis_normals_compute(const hfvis_grid *grid, float *out)
{
    int x, y;
    if (!hf_grid_valid(grid) || !out || hf_grid_count(grid) > SIZE_MAX / 3)
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (y = 0; y < grid->height; y++)
        for (x = 0; x < grid->width; x++) {
            double n[3];
            float *o = out + ((size_t)y * (size_t)grid->width + (size_t)x) * 3;
            hf_normal_at(grid, x, y, n);
            o[0] = (float)n[0];
            o[1] = (float)n[1];
            o[2] = (float)n[2];
        }
    return HFVIS_OK;
}

/* ========================================================================================== */
/* 5. The sweep lattice                                                                       */
/* ========================================================================================== */

#define HF_LATTICE_EPS 1e-9 /* docs/errata.md E5: nodes within 1e-9 cell of the border are inside */
/* Half-width of the domain across an axis of one sample: a grid 1 sample wide (or tall) is
 * swept as a strip one cell wide, heights constant across it. A line of zero width would hold a
 * lattice node only where a node happens to land on it, and the gather would find none. */
#define HF_STRIP_HALF 0.5

/* The domain along one axis of n samples: [-pad, n - 1 + pad]. */
static double hf_domain_pad(int n) { return n == 1 ? HF_STRIP_HALF : HF_LATTICE_EPS; }

/* Fill the lattice for a given sweep vector u (unit; v = (-u.y, u.x)). Directions are stored
 * as look azimuth psi with u = -(cos psi, sin psi) (docs/errata.md E4: a sweep along u yields the horizon
 * toward -u). */
static hfvis_status hf_lattice_from_u(hfvis_lattice *L, int W, int H, double ux, double uy,
                                      double ox, double oy)
{
    double cx[4], cy[4], umin = DBL_MAX, umax = -DBL_MAX, vmin = DBL_MAX, vmax = -DBL_MAX;
    double rows, cols, px, py;
    int c;
    L->ux = ux;
    L->uy = uy;
    L->vx = -uy;
    L->vy = ux;
    L->width = W;
    L->height = H;
    L->origin_x = ox;
    L->origin_y = oy;
    L->azimuth_rad = atan2(-uy, -ux);
    px = W == 1 ? HF_STRIP_HALF : 0.0; /* a thin axis: the strip's corners */
    py = H == 1 ? HF_STRIP_HALF : 0.0;
    cx[0] = -px; cy[0] = -py;
    cx[1] = (double)(W - 1) + px; cy[1] = -py;
    cx[2] = -px; cy[2] = (double)(H - 1) + py;
    cx[3] = (double)(W - 1) + px; cy[3] = (double)(H - 1) + py;
    for (c = 0; c < 4; c++) { /* the corners in raster coordinates (tiles) */
        double a = (cx[c] + ox) * L->ux + (cy[c] + oy) * L->uy, b = (cx[c] + ox) * L->vx + (cy[c] + oy) * L->vy;
        umin = fmin(umin, a);
        umax = fmax(umax, a);
        vmin = fmin(vmin, b);
        vmax = fmax(vmax, b);
    }
    umin = ceil(umin - HF_LATTICE_EPS);
    umax = floor(umax + HF_LATTICE_EPS);
    vmin = ceil(vmin - HF_LATTICE_EPS);
    vmax = floor(vmax + HF_LATTICE_EPS);
    rows = vmax - vmin + 1.0;
    cols = umax - umin + 1.0;
    /* over 2^31 nodes (0 lies in both ranges, so within the limit the indices fit an int) */
    if (rows * cols > 2147483647.0) return HFVIS_ERR_LIMIT;
    L->i_min = (int)umin;
    L->i_max = (int)umax;
    L->j_min = (int)vmin;
    L->j_max = (int)vmax;
    return HFVIS_OK;
}

/* Unit sweep vector of look azimuth psi, snapped on the axes (docs/errata.md E5). */
static void hf_sweep_vector(double psi, double *ux, double *uy)
{
    double x = -cos(psi), y = -sin(psi);
    if (fabs(x) < 1e-12) { x = 0.0; y = y > 0.0 ? 1.0 : -1.0; }
    if (fabs(y) < 1e-12) { y = 0.0; x = x > 0.0 ? 1.0 : -1.0; }
    *ux = x;
    *uy = y;
}

hfvis_status hfvis_lattice_init(hfvis_lattice *lattice, int width, int height, double azimuth_rad)
{
    hfvis_lattice L;
    double ux, uy;
    hfvis_status s;
    if (!lattice || width < 1 || height < 1 || !isfinite(azimuth_rad))
        return HFVIS_ERR_INVALID_ARGUMENT;
    hf_sweep_vector(azimuth_rad, &ux, &uy);
    s = hf_lattice_from_u(&L, width, height, ux, uy, 0.0, 0.0);
    if (s != HFVIS_OK) return s;
    L.azimuth_rad = azimuth_rad;
    *lattice = L;
    return HFVIS_OK;
}

size_t hfvis_lattice_nodes(const hfvis_lattice *L)
{
    if (!L || L->j_max < L->j_min || L->i_max < L->i_min) return 0;
    return ((size_t)(L->j_max - L->j_min) + 1) * ((size_t)(L->i_max - L->i_min) + 1);
}

/* Position of node (i, j). Written as i*u + j*v with the two products summed, so a lattice
 * turned by a quarter turn (u' = v, v' = -u) yields bit-identical positions ([P1] §7); in a tile
 * that raster position minus the origin, exact (an integer taken from a double no smaller), so a
 * tile and the whole raster sample the same surface point bit for bit. */
static void hf_node_pos(const hfvis_lattice *L, int i, int j, double *x, double *y)
{
    *x = ((double)i * L->ux + (double)j * L->vx) - L->origin_x;
    *y = ((double)i * L->uy + (double)j * L->vy) - L->origin_y;
}

static int hf_node_inside(const hfvis_lattice *L, int i, int j)
{
    double x, y;
    double px = hf_domain_pad(L->width), py = hf_domain_pad(L->height);
    hf_node_pos(L, i, j, &x, &y);
    return x >= -px && x <= (double)(L->width - 1) + px && y >= -py && y <= (double)(L->height - 1) + py;
}

int hfvis_lattice_line(const hfvis_lattice *L, int j, int *i_first, int *i_last)
{
    double lo = -DBL_MAX, hi = DBL_MAX;
    double u[2], v[2], len[2], pad[2], org[2];
    int a, first, last;
    if (!L || j < L->j_min || j > L->j_max) return 0;
    org[0] = L->origin_x;
    org[1] = L->origin_y;
    u[0] = L->ux; u[1] = L->uy;
    v[0] = L->vx; v[1] = L->vy;
    len[0] = (double)(L->width - 1);
    len[1] = (double)(L->height - 1);
    pad[0] = hf_domain_pad(L->width);
    pad[1] = hf_domain_pad(L->height);
    /* Slab test per axis (docs/errata.md E5) gives the range to within rounding ... */
    for (a = 0; a < 2; a++) {
        double off = (double)j * v[a] - org[a], lo_a = pad[a] > HF_LATTICE_EPS ? -pad[a] : 0.0;
        if (u[a] != 0.0) {
            double t0 = (lo_a - off) / u[a], t1 = (len[a] - lo_a - off) / u[a];
            lo = fmax(lo, fmin(t0, t1));
            hi = fmin(hi, fmax(t0, t1));
        } else if (off < -pad[a] || off > len[a] + pad[a]) {
            return 0;
        }
    }
    lo = fmax(lo, (double)L->i_min - 1.0);
    hi = fmin(hi, (double)L->i_max + 1.0);
    if (lo > hi + 2.0) return 0;
    first = (int)ceil(lo - HF_LATTICE_EPS);
    last = (int)floor(hi + HF_LATTICE_EPS);
    /* ... and the per-node position test decides exactly, so every lattice and its quarter
     * turns agree on which nodes exist (docs/errata.md E5). The in-domain set of a line is an
     * interval (a line meets a rectangle in a segment). */
    if (first < L->i_min) first = L->i_min;
    if (last > L->i_max) last = L->i_max;
    while (first > L->i_min && hf_node_inside(L, first - 1, j)) first--;
    while (first <= last && !hf_node_inside(L, first, j)) first++;
    while (last < L->i_max && hf_node_inside(L, last + 1, j)) last++;
    while (last >= first && !hf_node_inside(L, last, j)) last--;
    if (first > last) return 0;
    if (i_first) *i_first = first;
    if (i_last) *i_last = last;
    return last - first + 1;
}

/* ========================================================================================== */
/* 6. The P1 hull stack along one line                                                        */
/* ========================================================================================== */

/* [P1] Alg. 1 / App. A.1 (docs/errata.md E1, E2). The caster of the highest horizon of p_i is the vertex
 * before p_i on the upper hull of p_0..p_i ([P1] Eq. 2). Pop while the second entry b is seen at
 * least as high as the top a: (h_b - h)(d - d_a) >= (h_a - h)(d - d_b), P1's
 * h(v2) d(v1) >= h(v1) d(v2) ("ties pop", so on a plane the caster is the previous sample).
 * The A.1 erratum (the second point's horizon read after pushing it) cannot occur here: every
 * sample reads the stack top before it is pushed. */
hfvis_status hfvis_line_horizons(const double *distance, const double *height, int n,
                                 double *tan_out, int *caster_out, int *stack)
{
    int i, top = 0;
    if (!distance || !height || !tan_out || !stack || n < 0) return HFVIS_ERR_INVALID_ARGUMENT;
    for (i = 1; i < n; i++)
        if (!(distance[i] > distance[i - 1])) return HFVIS_ERR_INVALID_ARGUMENT;
    for (i = 0; i < n; i++) {
        double d = distance[i], h = height[i];
        if (!isfinite(h)) { /* a hole never occludes and receives no value */
            tan_out[i] = HFVIS__NAN;
            if (caster_out) caster_out[i] = -1;
            continue;
        }
        while (top >= 2) {
            int a = stack[top - 1], b = stack[top - 2];
            if ((height[b] - h) * (d - distance[a]) >= (height[a] - h) * (d - distance[b])) top--;
            else break;
        }
        if (top == 0) {
            tan_out[i] = -HFVIS__INF;
            if (caster_out) caster_out[i] = -1;
        } else {
            int a = stack[top - 1];
            tan_out[i] = (height[a] - h) / (d - distance[a]);
            if (caster_out) caster_out[i] = a;
        }
        stack[top++] = i;
    }
    return HFVIS_OK;
}

hfvis_status hfvis_line_horizons_naive(const double *distance, const double *height, int n,
                                       double *tan_out, int *caster_out)
{
    int i, j;
    if (!distance || !height || !tan_out || n < 0) return HFVIS_ERR_INVALID_ARGUMENT;
    for (i = 1; i < n; i++)
        if (!(distance[i] > distance[i - 1])) return HFVIS_ERR_INVALID_ARGUMENT;
    for (i = 0; i < n; i++) {
        double best = -HFVIS__INF;
        int caster = -1;
        if (!isfinite(height[i])) {
            tan_out[i] = HFVIS__NAN;
            if (caster_out) caster_out[i] = -1;
            continue;
        }
        for (j = 0; j < i; j++) {
            double t;
            if (!isfinite(height[j])) continue;
            t = (height[j] - height[i]) / (distance[i] - distance[j]);
            if (t >= best) { /* >=: the nearest of equal casters, as the hull's ties pop */
                best = t;
                caster = j;
            }
        }
        tan_out[i] = best;
        if (caster_out) caster_out[i] = caster;
    }
    return HFVIS_OK;
}

/* ========================================================================================== */
/* 7. The sweep driver                                                                        */
/* ========================================================================================== */

/* The search radius (hfvis.h, "Search radius and tiles"; docs/search-radius.md). The hull above
 * answers "the highest over everything behind"; a window of length R along the line needs more.
 * Every line is cut into blocks of Rw position units anchored at global position 0 (so a tile and
 * the whole raster cut a line at the same places). A sample i of block b sees the samples j < i
 * with pos[i] - pos[j] <= Rw, which are (i) those of block b before it: the [P1] §5 hull
 * restarted at the block start, and (ii) the suffix of block b - 1 from the first sample within
 * reach: the upper hull of that suffix is built once per block right to left with an undo log
 * (insertion k records the stack height and the slot it overwrote) and undone one insertion at a
 * time as the window start advances; sample i reads its tangent by binary search. O(1) amortised
 * per sample plus O(log R) per query; the answer is the larger of the two tangents. */
typedef struct hf_win {
    double *d, *h, *t;      /* one line: distances (hull arithmetic), heights (NaN holes), out */
    double *sm;             /* the previous block's suffix maxima of height */
    int64_t *pos;           /* global positions (integers; units of the caller) */
    double *ph, *pd;        /* prefix hull stack (heights, distances) */
    double *sh, *sd;        /* suffix hull (heights, distances; [0] rightmost) */
    double *log_h, *log_d;  /* undo log: the slot each insertion overwrote ... */
    int *log_top;           /* ... and the stack height before it */
} hf_win;

/* Bytes of the hf_win of lines of n >= 2 samples (ten doubles a sample, and the two NaN slots
 * below the prefix stack that hf_hull_step reads, within an eleventh). */
#define HF_WIN_BYTES_PER_SAMPLE (11u * sizeof(double) + sizeof(int64_t) + sizeof(int))

static void hf_win_carve(hf_win *w, unsigned char *b, size_t n)
{
    HFVIS_ASSERT(n >= 2);
    w->d = (double *)(void *)b;
    w->h = w->d + n;
    w->t = w->h + n;
    w->t[n] = w->t[n + 1] = HFVIS__NAN; /* ph[-2], ph[-1] */
    w->ph = w->t + n + 2;
    w->pd = w->ph + n;
    w->sm = w->pd + n;
    w->sh = w->sm + n;
    w->sd = w->sh + n;
    w->log_h = w->sd + n;
    w->log_d = w->log_h + n;
    w->pos = (int64_t *)(void *)(w->log_d + n);
    w->log_top = (int *)(void *)(w->pos + n);
}

static int64_t hf_floor_div64(int64_t num, int64_t den) /* den > 0 */
{
    int64_t q = num / den;
    return (num % den != 0 && num < 0) ? q - 1 : q;
}


/* Scratch for all the sweeps of one call, carved out of a single allocation (one block per
 * call, freed before return). The base lattice of a direction group is sampled once; its four
 * quarter turns psi + m pi/2 visit the same nodes ([P1] §7) and are traversed as
 *   m = 0: rows, increasing i      m = 1: columns, increasing j
 *   m = 2: rows, decreasing i      m = 3: columns, decreasing j
 * (turning u by +pi/2 gives u' = v, v' = -u, so node (i', j') of psi + pi/2 is node (-j', i')). */
typedef struct hf_sweep {
    const hfvis_grid *g;
    hfvis_border border;
    int preroll;                /* cells of CLAMP/WRAP pre-roll before each line (docs/errata.md E8) */
    int want_normals;
    int nrm_finite;             /* every grid normal finite (want_normals): the sampling's
                                   four-tap sum needs no hole test */
    int channels;               /* of the lattice accumulator */
    hfvis_lattice L;            /* base lattice of the current group */
    int rows, cols;
    size_t nodes_cap;           /* rows*cols of any direction fits (hf_lattice_nodes_bound) */
    int *row_first, *row_last;  /* per row: in-domain column range (buffer indices) */
    int *col_first, *col_last;  /* per column: in-domain row range */
    double *h;                  /* rows*cols heights in cell units, NaN outside or at holes */
    float *nrm;                 /* rows*cols*3 node normals (want_normals) */
    double *lat;                /* rows*cols*channels output / accumulator */
    double *lh, *lt;            /* one line: stack heights (or the oracle's copy), tangents */
    double *sd;                 /* hull stack distances (heights in lh) */
    const float *grid_nrm;      /* width*height*3 grid normals (want_normals): the scratch's,
                                   or the caller's (sweep options normals) */
    double *gacc;               /* width*height*channels grid accumulator (fused light) */
    unsigned char *extra;       /* extra_size bytes for the caller (the P2 tree and line data) */
    size_t extra_size;
    int64_t win_rw;             /* search radius in whole node steps; -1 = unlimited */
    double radius_cells;        /* the search radius in cells, 0 = unlimited (hf_stranded_tan) */
    double ox, oy;              /* tile origin in the raster (hfvis.h, "Search radius and tiles") */
    double ext_w, ext_h;        /* the raster's size */
    int rx0, ry0, rx1, ry1;     /* receiver rectangle [rx0, rx1) x [ry0, ry1) */
    int rect;                   /* 1: a proper sub-rectangle (nodes far from it are skipped) */
    int parts, part;            /* bands across the direction (hfvis_sun_visibility), 0 = off */
    double part_b0, part_span;  /* the receivers' lattice b range: its start and length */
    int band_j0, band_j1;       /* the lattice rows near the band (all rows without bands) */
    hf_win win;                 /* its line scratch (win_rw >= 0) */
    void *block;
    const hfvis_allocator *alloc;
} hf_sweep;

static size_t hf_align_add(size_t *total, size_t count, size_t elem, int *ok)
{
    size_t bytes, off = (*total + 15u) & ~(size_t)15u;
    if (off < *total || !hfvis__mul_size(count, elem, &bytes) || bytes > SIZE_MAX - off) {
        *ok = 0;
        return 0;
    }
    *total = off + bytes;
    return off;
}

/* Is the search radius finite (hfvis.h: 0 and +INFINITY are unlimited)? */
static int hf_radius_on(const hfvis_sweep_options *o)
{
    return o->max_distance > 0.0 && o->max_distance < HFVIS__INF;
}

/* floor(r) as a window length, r >= 0, clamped to 2^52 (beyond any line) */
static int64_t hf_radius_units(double r)
{
    r = floor(r);
    return r > 4503599627370496.0 ? (int64_t)4503599627370496 : (int64_t)r;
}

/* Tile fields on their own (hfvis.h, "Search radius and tiles"); with the grid: hf_tile_fits. */
static int hf_tile_opts_valid(const hfvis_sweep_options *o)
{
    int whole = o->extent_width == 0 && o->extent_height == 0;
    if (o->origin_x < 0 || o->origin_y < 0 || o->extent_width < 0 || o->extent_height < 0 ||
        o->receiver_x < 0 || o->receiver_y < 0 || o->receiver_width < 0 || o->receiver_height < 0)
        return 0;
    if ((o->extent_width == 0) != (o->extent_height == 0)) return 0;
    if ((o->receiver_width == 0) != (o->receiver_height == 0)) return 0;
    if (whole && (o->origin_x != 0 || o->origin_y != 0)) return 0;
    return 1;
}

/* A grid that is a proper window of a larger raster (not the whole of it). */
static int hf_tile_window(const hfvis_grid *g, const hfvis_sweep_options *o)
{
    return o->extent_width != 0 &&
           (o->origin_x != 0 || o->origin_y != 0 || o->extent_width != g->width ||
            o->extent_height != g->height);
}

/* The tile fields against the grid: the window inside the raster (and then a finite radius and
 * the open border: nothing beyond the window is known), the receiver rectangle inside the grid. */
static int hf_tile_fits(const hfvis_grid *g, const hfvis_sweep_options *o)
{
    if (o->extent_width != 0 && ((double)o->origin_x + (double)g->width > (double)o->extent_width ||
                                 (double)o->origin_y + (double)g->height > (double)o->extent_height))
        return 0;
    if (hf_tile_window(g, o) &&
        (!hf_radius_on(o) || (o->border != HFVIS_BORDER_OPEN && o->border != HFVIS_BORDER_DEFAULT)))
        return 0;
    if (o->receiver_width != 0 &&
        ((double)o->receiver_x + (double)o->receiver_width > (double)g->width ||
         (double)o->receiver_y + (double)o->receiver_height > (double)g->height))
        return 0;
    return 1;
}

/* The receiver rectangle of o as [x0, x1) x [y0, y1) (the whole grid by default). */
static void hf_receiver_rect(const hfvis_grid *g, const hfvis_sweep_options *o, int *x0, int *y0,
                             int *x1, int *y1)
{
    if (o->receiver_width == 0) {
        *x0 = *y0 = 0;
        *x1 = g->width;
        *y1 = g->height;
        return;
    }
    *x0 = o->receiver_x;
    *y0 = o->receiver_y;
    *x1 = o->receiver_x + o->receiver_width;
    *y1 = o->receiver_y + o->receiver_height;
}

/* A window or a receiver rectangle: the P2 hull-tree routines of section 11 refuse them (they
 * honour the radius). */
static int hf_p2_opts_limited(const hfvis_sweep_options *o)
{
    return o && (o->extent_width != 0 || o->receiver_width != 0);
}

/* part_index/part_count: 0, 0 or 0 <= index < count <= HF_PARTS_MAX (hfvis_sun_visibility). */
#define HF_PARTS_MAX 65536
static int hf_parts_valid(const hfvis_sweep_options *o)
{
    return (o->part_index == 0 && o->part_count == 0) ||
           (o->part_count >= 1 && o->part_count <= HF_PARTS_MAX && o->part_index >= 0 &&
            o->part_index < o->part_count);
}

static int hf_opts_valid(const hfvis_sweep_options *o)
{
    return !o || (hf_border_valid(o->border) && o->border_cells >= 0 && isfinite(o->azimuth0_rad) &&
                  o->max_distance >= 0.0 && hf_tile_opts_valid(o) &&
                  o->direction_begin >= 0 && o->direction_end >= 0 &&
                  o->direction_order >= HFVIS_DIRECTION_ORDER_DEFAULT &&
                  o->direction_order <= HFVIS_DIRECTION_ORDER_SWEEP &&
                  (o->rays == HFVIS_RAYS_LATTICE || o->rays == HFVIS_RAYS_EXACT) &&
                  o->ray_denominator >= 0 && o->ray_denominator <= HFVIS_RAY_DENOMINATOR_MAX &&
                  o->ray_near_cells >= 0 && o->ray_near_cells <= HFVIS_RAY_NEAR_CELLS_MAX &&
                  hf_parts_valid(o) && o->part_count <= 1); /* bands: hfvis_sun_visibility's own */
}

/* Resolved options (NULL or zero fields = defaults). */
static hfvis_sweep_options hf_opts_resolve(const hfvis_grid *g, const hfvis_sweep_options *o)
{
    hfvis_sweep_options r = hfvis_sweep_options_default();
    if (o) r = *o;
    if (r.border == HFVIS_BORDER_DEFAULT) r.border = HFVIS_BORDER_OPEN;
    if (r.border_cells == 0) r.border_cells = g->width > g->height ? g->width : g->height;
    return r;
}

int hfvis_tile_halo(double max_distance, double cell_size, hfvis_ray_mode rays)
{
    double c;
    if (!(max_distance > 0.0) || !(max_distance < HFVIS__INF) || !(cell_size > 0.0) ||
        !(cell_size < HFVIS__INF) || (rays != HFVIS_RAYS_LATTICE && rays != HFVIS_RAYS_EXACT))
        return -1;
    c = ceil(max_distance / cell_size) +
        (rays == HFVIS_RAYS_EXACT ? HFVIS_TILE_HALO_EXACT : HFVIS_TILE_HALO_LATTICE);
    return c <= (double)INT_MAX ? (int)c : -1;
}

hfvis_sweep_options hfvis_sweep_options_default(void)
{
    hfvis_sweep_options o;
    memset(&o, 0, sizeof o);
    o.border = HFVIS_BORDER_OPEN;
    return o;
}

/* Lattice extent bound over all directions: the grid diagonal plus slack. */
static int hf_lattice_bound(const hfvis_grid *g)
{
    double d = sqrt((double)(g->width - 1) * (double)(g->width - 1) +
                    (double)(g->height - 1) * (double)(g->height - 1));
    return (int)d + 3;
}

/* Nodes of the largest lattice buffer over all directions: rows x cols of a direction at angle
 * theta is at most (a|s| + b|c| + 1)(a|c| + b|s| + 1) with a, b the (padded) grid extents, at
 * most (a + b)^2/2 + 1.5(a + b) + 2: half the D x D square for a thin grid (a line at 45 degrees
 * needs an (N/sqrt 2)^2 buffer, not N^2), and D x D otherwise. */
static size_t hf_lattice_nodes_bound(const hfvis_grid *g, int D)
{
    double a = (double)(g->width - 1) + (g->width == 1 ? 2.0 * HF_STRIP_HALF : 0.0);
    double b = (double)(g->height - 1) + (g->height == 1 ? 2.0 * HF_STRIP_HALF : 0.0);
    double thin = (a + b) * (a + b) / 2.0 + 1.5 * (a + b) + 2.0, square = (double)D * (double)D;
    return (size_t)(thin < square ? thin : square);
}

static hfvis_status hf_sweep_alloc_extra(hf_sweep *sw, const hfvis_grid *g,
                                         const hfvis_sweep_options *o, int want_normals,
                                         int channels, int want_gacc, size_t extra_size)
{
    size_t total = 0, off_x = 0, nodes, gridn, off_rf, off_rl, off_cf, off_cl, off_h, off_n = 0, off_lat,
           off_lh, off_lt, off_stk, off_gn = 0, off_ga = 0, off_w = 0, linelen;
    int ok = 1, D = hf_lattice_bound(g);
    unsigned char *b;
    memset(sw, 0, sizeof *sw);
    sw->g = g;
    sw->border = o->border;
    sw->preroll = o->border == HFVIS_BORDER_OPEN ? 0 : o->border_cells;
    sw->want_normals = want_normals;
    sw->channels = channels;
    sw->alloc = o->alloc;
    if ((double)D * (double)D > 2147483647.0 || (double)D + (double)sw->preroll > 2147483647.0)
        return HFVIS_ERR_LIMIT;
    nodes = hf_lattice_nodes_bound(g, D);
    sw->nodes_cap = nodes;
    gridn = hf_grid_count(g);
    linelen = (size_t)D + (size_t)sw->preroll;
    off_rf = hf_align_add(&total, (size_t)D, sizeof(int), &ok);
    off_rl = hf_align_add(&total, (size_t)D, sizeof(int), &ok);
    off_cf = hf_align_add(&total, (size_t)D, sizeof(int), &ok);
    off_cl = hf_align_add(&total, (size_t)D, sizeof(int), &ok);
    off_h = hf_align_add(&total, nodes, sizeof(double), &ok);
    if (want_normals) off_n = hf_align_add(&total, nodes, 3 * sizeof(float), &ok);
    off_lat = hf_align_add(&total, nodes, (size_t)channels * sizeof(double), &ok);
    off_lh = hf_align_add(&total, linelen + 2, sizeof(double), &ok); /* + the hull's NaN slots */
    off_lt = hf_align_add(&total, linelen, sizeof(double), &ok);
    off_stk = hf_align_add(&total, linelen + 2, sizeof(double), &ok);
    if (want_normals && !o->normals) off_gn = hf_align_add(&total, gridn, 3 * sizeof(float), &ok);
    if (want_gacc) off_ga = hf_align_add(&total, gridn, (size_t)channels * sizeof(double), &ok);
    if (extra_size) off_x = hf_align_add(&total, extra_size, 1, &ok);
    sw->win_rw = hf_radius_on(o) ? hf_radius_units(o->max_distance / g->cell_size) : -1;
    sw->radius_cells = hf_radius_on(o) ? o->max_distance / g->cell_size : 0.0;
    if (sw->win_rw >= 0) off_w = hf_align_add(&total, linelen, HF_WIN_BYTES_PER_SAMPLE, &ok);
    if (!ok) return HFVIS_ERR_LIMIT;
    b = (unsigned char *)hfvis__alloc(o->alloc, total);
    if (!b) return HFVIS_ERR_OUT_OF_MEMORY;
    sw->block = b;
    sw->row_first = (int *)(void *)(b + off_rf);
    sw->row_last = (int *)(void *)(b + off_rl);
    sw->col_first = (int *)(void *)(b + off_cf);
    sw->col_last = (int *)(void *)(b + off_cl);
    sw->h = (double *)(void *)(b + off_h);
    sw->nrm = want_normals ? (float *)(void *)(b + off_n) : NULL;
    sw->lat = (double *)(void *)(b + off_lat);
    sw->lh = (double *)(void *)(b + off_lh) + 2;
    sw->lh[-2] = sw->lh[-1] = HFVIS__NAN; /* below the hull stack (hf_hull_step) */
    sw->lt = (double *)(void *)(b + off_lt);
    sw->sd = (double *)(void *)(b + off_stk) + 2;
    sw->sd[-2] = sw->sd[-1] = HFVIS__NAN;
    sw->grid_nrm = !want_normals ? NULL : o->normals ? o->normals : (const float *)(const void *)(b + off_gn);
    sw->gacc = want_gacc ? (double *)(void *)(b + off_ga) : NULL;
    sw->extra = extra_size ? b + off_x : NULL;
    sw->extra_size = extra_size;
    sw->ox = (double)o->origin_x;
    sw->oy = (double)o->origin_y;
    sw->ext_w = (double)(o->extent_width ? o->extent_width : g->width);
    sw->ext_h = (double)(o->extent_height ? o->extent_height : g->height);
    hf_receiver_rect(g, o, &sw->rx0, &sw->ry0, &sw->rx1, &sw->ry1);
    sw->rect = sw->rx0 > 0 || sw->ry0 > 0 || sw->rx1 < g->width || sw->ry1 < g->height;
    if (sw->win_rw >= 0) hf_win_carve(&sw->win, b + off_w, linelen);
    if (want_normals) { /* made here (hfvis_normals_compute's bits) unless the caller gave them */
        int x, y, fin = 1;
        float *own = o->normals ? NULL : (float *)(void *)(b + off_gn);
        for (y = 0; y < g->height; y++)
            for (x = 0; x < g->width; x++) {
                const size_t i = ((size_t)y * (size_t)g->width + (size_t)x) * 3;
                if (own) {
                    double n[3];
                    hf_normal_at(g, x, y, n);
                    own[i] = (float)n[0];
                    own[i + 1] = (float)n[1];
                    own[i + 2] = (float)n[2];
                }
                fin &= isfinite(sw->grid_nrm[i]) && isfinite(sw->grid_nrm[i + 1]) && isfinite(sw->grid_nrm[i + 2]);
            }
        sw->nrm_finite = fin;
    }
    if (want_gacc) memset(sw->gacc, 0, gridn * (size_t)channels * sizeof(double));
    return HFVIS_OK;
}

static hfvis_status hf_sweep_alloc(hf_sweep *sw, const hfvis_grid *g, const hfvis_sweep_options *o,
                                   int want_normals, int channels, int want_gacc)
{
    return hf_sweep_alloc_extra(sw, g, o, want_normals, channels, want_gacc, 0);
}

static void hf_sweep_free(hf_sweep *sw) { hfvis__free(sw->alloc, sw->block); }

/* Height (world units) at any position under the border rule: CLAMP clamps to the grid,
 * WRAP treats the field as periodic with period width x height (docs/errata.md E8). */
static double hf_sample_border(const hfvis_grid *g, hfvis_border border, double x, double y)
{
    if (border == HFVIS_BORDER_WRAP) {
        double W = (double)g->width, H = (double)g->height, fx, fy, r0, r1;
        int x0, y0, x1, y1;
        const float *z = g->z;
        ptrdiff_t s = g->stride;
        x = x - W * floor(x / W);
        y = y - H * floor(y / H);
        x0 = (int)floor(x);
        y0 = (int)floor(y);
        if (x0 >= g->width) x0 = g->width - 1;
        if (y0 >= g->height) y0 = g->height - 1;
        fx = x - (double)x0;
        fy = y - (double)y0;
        x1 = x0 + 1 == g->width ? 0 : x0 + 1;
        y1 = y0 + 1 == g->height ? 0 : y0 + 1;
        r0 = fx == 0.0 ? (double)z[y0 * s + x0]
                       : (double)z[y0 * s + x0] * (1.0 - fx) + (double)z[y0 * s + x1] * fx;
        if (fy != 0.0) {
            r1 = fx == 0.0 ? (double)z[y1 * s + x0]
                           : (double)z[y1 * s + x0] * (1.0 - fx) + (double)z[y1 * s + x1] * fx;
            r0 = r0 * (1.0 - fy) + r1 * fy;
        }
        return isfinite(r0) ? r0 : HFVIS__NAN;
    }
    return hf_bilerp(g->z, g->stride, g->width, g->height,
                     hf_clampd(x, 0.0, (double)(g->width - 1)),
                     hf_clampd(y, 0.0, (double)(g->height - 1)));
}

/* Set up the base lattice of sweep vector u for the current group: line ranges per row and
 * column, and the heights (cell units) at every in-domain node. */
#define HF_TILE 32 /* lattice and grid loops run in tiles so both sides stay in cache */

#define HF_RECT_MARGIN 4.0 /* cells around a receiver rectangle (band) whose nodes a gather reads */

/* Bands across the direction (hfvis_sweep_options part_index/part_count): the receivers'
 * lattice coordinate b (across the lines) over the receiver rectangle, cut into parts equal
 * lengths; each receiver is in the band of its own b, computed by the same expression in every
 * call, so the bands of separate calls tile the receivers. Lines far from the band are skipped
 * (hf_line_rect), which is what lets threads share one direction's lines. */
static void hf_sweep_parts(hf_sweep *sw, const hfvis_sweep_options *o)
{
    sw->parts = o->part_count > 1 ? o->part_count : 0;
    sw->part = o->part_index;
    if (sw->parts) sw->rect = 1; /* hf_line_rect skips the lines far from the band */
}

/* The band's geometry, once the direction's lattice is set (hf_sweep_group): the receivers' b
 * range over the rectangle, and the lattice rows [band_j0, band_j1] whose lines lie within
 * HF_RECT_MARGIN of the band (b grows by one per row: v is a unit vector). Rows outside are
 * neither sampled nor filled nor read. */
static void hf_sweep_band(hf_sweep *sw)
{
    const hfvis_lattice *L = &sw->L;
    double lo = HFVIS__INF, hi = -HFVIS__INF, px, py, b0, b1, q0, q1, j0, j1;
    int c;
    for (c = 0; c < 4; c++) {
        double x = (double)(c & 1 ? sw->rx1 - 1 : sw->rx0) + sw->ox;
        double y = (double)(c & 2 ? sw->ry1 - 1 : sw->ry0) + sw->oy;
        double b = x * L->vx + y * L->vy;
        lo = b < lo ? b : lo;
        hi = b > hi ? b : hi;
    }
    sw->part_b0 = lo;
    sw->part_span = hi - lo;
    hf_node_pos(L, L->i_min, L->j_min, &px, &py);
    b0 = (px + sw->ox) * L->vx + (py + sw->oy) * L->vy;
    hf_node_pos(L, L->i_min, L->j_min + 1, &px, &py);
    b1 = (px + sw->ox) * L->vx + (py + sw->oy) * L->vy - b0;
    q0 = lo + (hi - lo) * (double)sw->part / (double)sw->parts - HF_RECT_MARGIN;
    q1 = lo + (hi - lo) * (double)(sw->part + 1) / (double)sw->parts + HF_RECT_MARGIN;
    j0 = (q0 - b0) / b1;
    j1 = (q1 - b0) / b1;
    if (j0 > j1) {
        double t = j0;
        j0 = j1;
        j1 = t;
    }
    j0 = floor(j0) - 1.0;
    j1 = ceil(j1) + 1.0;
    sw->band_j0 = j0 < 0.0 ? 0 : j0 > (double)sw->rows ? sw->rows : (int)j0;
    sw->band_j1 = j1 < 0.0 ? -1 : j1 > (double)(sw->rows - 1) ? sw->rows - 1 : (int)j1;
}

/* The band of lattice coordinate b, 0..parts-1. */
static int hf_band_of(double b, double b0, double span, int parts)
{
    double q = span > 0.0 ? (b - b0) / span * (double)parts : 0.0;
    return q <= 0.0 ? 0 : q >= (double)(parts - 1) ? parts - 1 : (int)q;
}

/* The band of receiver (x, y) (sw->parts > 0). */
static int hf_sweep_band_at(const hf_sweep *sw, int x, int y)
{
    const hfvis_lattice *L = &sw->L;
    return hf_band_of(((double)x + sw->ox) * L->vx + ((double)y + sw->oy) * L->vy, sw->part_b0,
                      sw->part_span, sw->parts);
}

/* The first x in [rx0, rx1] of row y whose band is at or past t in the row's order (band
 * non-decreasing in x when inc, else non-increasing); rx1 if none. */
static int hf_sweep_first(const hf_sweep *sw, int y, int inc, int t)
{
    int lo = sw->rx0, hi = sw->rx1;
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2, b = hf_sweep_band_at(sw, mid, y);
        if (inc ? b >= t : b <= t) hi = mid;
        else lo = mid + 1;
    }
    return lo;
}

/* This call's receivers in row y of the receiver rectangle: [*x0, *x1). Along a row every
 * rounding step of a receiver's b (x + ox, times vx, plus a constant, minus b0, over the span,
 * times parts) is monotone in x, so its band is, and the band's receivers are one run, found by
 * bisection with the very test of hf_sweep_band_at: a band costs its share, not a scan. */
static void hf_sweep_span(const hf_sweep *sw, int y, int *x0, int *x1)
{
    const int inc = sw->L.vx >= 0.0;
    if (!sw->parts) {
        *x0 = sw->rx0;
        *x1 = sw->rx1;
        return;
    }
    *x0 = hf_sweep_first(sw, y, inc, sw->part);
    *x1 = hf_sweep_first(sw, y, inc, inc ? sw->part + 1 : sw->part - 1);
    if (*x1 < *x0) *x1 = *x0;
}

static void hf_sweep_group(hf_sweep *sw, double ux, double uy)
{
    const hfvis_grid *g = sw->g;
    hfvis_lattice *L = &sw->L;
    int j, i, c, tj, ti;
    double inv_cs = 1.0 / g->cell_size;
    hf_lattice_from_u(L, g->width, g->height, ux, uy, sw->ox, sw->oy); /* within the bound */
    sw->rows = L->j_max - L->j_min + 1;
    sw->cols = L->i_max - L->i_min + 1;
    HFVIS_ASSERT(sw->rows <= hf_lattice_bound(g) && sw->cols <= hf_lattice_bound(g));
    HFVIS_ASSERT((size_t)sw->rows * (size_t)sw->cols <= sw->nodes_cap);
    sw->band_j0 = 0;
    sw->band_j1 = sw->rows - 1;
    if (sw->parts) hf_sweep_band(sw);
    for (c = 0; c < sw->cols; c++) {
        sw->col_first[c] = INT_MAX;
        sw->col_last[c] = -1;
    }
    for (j = 0; j < sw->rows; j++) {
        int first, last;
        double *hr = sw->h + (size_t)j * (size_t)sw->cols;
        if (j < sw->band_j0 || j > sw->band_j1) { /* another band's line: left untouched */
            sw->row_first[j] = 1;
            sw->row_last[j] = 0;
            continue;
        }
        if (!hfvis_lattice_line(L, j + L->j_min, &first, &last)) {
            sw->row_first[j] = 1;
            sw->row_last[j] = 0;
            for (i = 0; i < sw->cols; i++) hr[i] = HFVIS__NAN;
            continue;
        }
        sw->row_first[j] = first - L->i_min;
        sw->row_last[j] = last - L->i_min;
        /* NaN outside the row's span; the span itself is sampled below */
        for (i = 0; i < sw->row_first[j]; i++) hr[i] = HFVIS__NAN;
        for (i = sw->row_last[j] + 1; i < sw->cols; i++) hr[i] = HFVIS__NAN;
        for (i = sw->row_first[j]; i <= sw->row_last[j]; i++) {
            if (j < sw->col_first[i]) sw->col_first[i] = j;
            if (j > sw->col_last[i]) sw->col_last[i] = j;
        }
    }
    {
    /* Per-group and per-row invariants in locals: the stores to hr and no (double, float) could
     * alias the lattice's and the grid's double fields, so the compiler reloaded them at every
     * node. Node positions as hf_node_pos (the same expressions, so the same bits). */
    const double ux_ = L->ux, uy_ = L->uy, vx_ = L->vx, vy_ = L->vy;
    const double ox_ = L->origin_x, oy_ = L->origin_y;
    const double xmax = (double)(g->width - 1), ymax = (double)(g->height - 1);
    const int W = g->width, H = g->height, i_min = L->i_min, j_min = L->j_min;
    const int cols = sw->cols, rows = sw->rows, want_normals = sw->want_normals;
    const ptrdiff_t stride = g->stride;
    const float *z = g->z, *grid_nrm = sw->grid_nrm;
    float *nrm = sw->nrm;
    const int four_taps = W > 1 && H > 1, nrm_finite = want_normals && sw->nrm_finite;
    for (tj = 0; tj < rows; tj += HF_TILE)
        for (ti = 0; ti < cols; ti += HF_TILE)
    for (j = tj; j < rows && j < tj + HF_TILE; j++) {
        double *hr = sw->h + (size_t)j * (size_t)cols;
        const double jd = (double)(j + j_min), jvx = jd * vx_, jvy = jd * vy_;
        int first = sw->row_first[j] > ti ? sw->row_first[j] : ti;
        int last = sw->row_last[j] < ti + HF_TILE - 1 ? sw->row_last[j] : ti + HF_TILE - 1;
        for (i = first; i <= last; i++) {
            const double id = (double)(i + i_min);
            double x = (id * ux_ + jvx) - ox_, y = (id * uy_ + jvy) - oy_;
            double fx = 0.0, fy = 0.0, w[4];
            int x0 = 0, y0 = 0, q;
            x = hf_clampd(x, 0.0, xmax);
            y = hf_clampd(y, 0.0, ymax);
            /* Bilinear taps (docs/errata.md E5), shared by the height and, for lighting, the normal
             * ([P1] §7: normals bilinearly filtered, then renormalised). Zero-weight taps are
             * never read, so holes do not leak into exact sample positions. */
            /* the cell of hf_bilerp: x >= 0 after the clamp, so (int)x is floor(x) */
            if (W > 1) {
                x0 = (int)x < W - 2 ? (int)x : W - 2;
                fx = x - (double)x0;
            }
            if (H > 1) {
                y0 = (int)y < H - 2 ? (int)y : H - 2;
                fy = y - (double)y0;
            }
            hr[i] = hf_bilerp_taps(z + (ptrdiff_t)y0 * stride + x0, stride, fx, fy) * inv_cs;
            if (want_normals) {
                double n0 = 0.0, n1 = 0.0, n2 = 0.0, inv;
                float *no = nrm + ((size_t)j * (size_t)cols + (size_t)i) * 3;
                const float *np = grid_nrm + ((size_t)y0 * (size_t)W + (size_t)x0) * 3;
                w[0] = (1.0 - fx) * (1.0 - fy);
                w[1] = fx * (1.0 - fy);
                w[2] = (1.0 - fx) * fy;
                w[3] = fx * fy;
                if (four_taps) {
                    /* all four taps in the grid: summed without the zero-weight test, which is
                     * bit-identical while they are finite (w*n of w == 0 is a +-0); the hole
                     * test only when some grid normal is not finite */
                    const float *r = np + (ptrdiff_t)W * 3;
                    n0 = 0.0 + w[0] * (double)np[0] + w[1] * (double)np[3] + w[2] * (double)r[0] + w[3] * (double)r[3];
                    n1 = 0.0 + w[0] * (double)np[1] + w[1] * (double)np[4] + w[2] * (double)r[1] + w[3] * (double)r[4];
                    n2 = 0.0 + w[0] * (double)np[2] + w[1] * (double)np[5] + w[2] * (double)r[2] + w[3] * (double)r[5];
                    q = 4;
                    if (!nrm_finite && !isfinite(n0 + n1 + n2)) { /* a hole's NaN normal: tap by tap */
                        n0 = n1 = n2 = 0.0;
                        q = 0;
                    }
                } else {
                    q = 0;
                }
                for (; q < 4; q++) {
                    const float *t3;
                    if (w[q] == 0.0) continue;
                    t3 = np + ((q >> 1) * (ptrdiff_t)W + (q & 1)) * 3;
                    n0 += w[q] * (double)t3[0];
                    n1 += w[q] * (double)t3[1];
                    n2 += w[q] * (double)t3[2];
                }
                inv = 1.0 / sqrt(n0 * n0 + n1 * n1 + n2 * n2);
                no[0] = (float)(n0 * inv);
                no[1] = (float)(n1 * inv);
                no[2] = (float)(n2 * inv);
            }
        }
    }
    }
}

/* The traversal of orientation m (see hf_sweep): line number `line` (a row for even m, a
 * column for odd m). Returns the node count n, the first node's buffer index and the index step;
 * and the lattice coordinates (i, j) of the first node with the lattice step (di, dj) per node. */
static int hf_line_span(const hf_sweep *sw, int m, int line, ptrdiff_t *node0, ptrdiff_t *step,
                        int *i0, int *j0, int *di, int *dj)
{
    int first, last;
    if ((m & 1) == 0) {
        first = sw->row_first[line];
        last = sw->row_last[line];
        if (first > last) return 0;
        *dj = 0;
        *j0 = line;
        if (m == 0) { *i0 = first; *di = 1; *step = 1; }
        else { *i0 = last; *di = -1; *step = -1; }
        *node0 = (ptrdiff_t)line * sw->cols + *i0;
    } else {
        first = sw->col_first[line];
        last = sw->col_last[line];
        if (first > last) return 0;
        *di = 0;
        *i0 = line;
        if (m == 1) { *j0 = first; *dj = 1; *step = sw->cols; }
        else { *j0 = last; *dj = -1; *step = -(ptrdiff_t)sw->cols; }
        *node0 = (ptrdiff_t)*j0 * sw->cols + line;
    }
    return last - first + 1;
}

/* The brute-force maximum on unit-spaced samples (docs/errata.md E5): the oracle twin of the
 * hull in hf_sweep_orientation. */
static void hf_brute_unit(const double *h, int n, double *t, int64_t rw)
{
    int i, j;
    for (i = 0; i < n; i++) {
        double best = -HFVIS__INF;
        if (isnan(h[i])) {
            t[i] = HFVIS__NAN;
            continue;
        }
        for (j = rw >= 0 && rw < i ? i - (int)rw : 0; j < i; j++) { /* within the radius */
            double s;
            if (isnan(h[j])) continue;
            s = (h[j] - h[i]) / (double)(i - j);
            if (s > best) best = s;
        }
        t[i] = best;
    }
}

/* Per-line consumer: receives the tangents t[0..n-1] of the in-domain nodes of one line of
 * orientation m, starting at buffer index node0 with index step `step`. */
typedef void (*hf_line_fn)(hf_sweep *sw, void *ctx, int m, ptrdiff_t node0, ptrdiff_t step,
                           int n, const double *t);

/* One step of the hull stack (sh, sd, top) for the sample (d, h) ([P1] Alg. 1; docs/errata.md E1, E2, the arithmetic of
 * hfvis_line_horizons with distance = node index): pop while the second entry is seen at least as
 * high, then return the tangent to the top and push. (Pop decisions taken without branches
 * measured slower: they chain every step on the previous one's loads.) (a1, b1) are the top's
 * differences (sh[top-1] - h, d - sd[top-1]); the stack is not empty (hf_hull_step answers -inf
 * for an empty one). sh[-2] and sh[-1] are NaN and sd[-2], sd[-1] readable: with one entry the
 * test reads a NaN and fails, as top >= 2 would (h is not NaN), one compare and branch less a
 * test. Two tests a round, the top's differences alternating between (a1, b1) and (a2, b2). */
static inline double hf_hull_push(double *sh, double *sd, ptrdiff_t *top_io, double h, double d,
                                  double a1, double b1)
{
    ptrdiff_t k = *top_io;
    double t, a2, b2;
    for (;;) {
        a2 = sh[k - 2] - h;
        b2 = d - sd[k - 2];
        if (!(a2 * b1 >= a1 * b2)) {
            t = a1 / b1;
            break;
        }
        k--;
        a1 = sh[k - 2] - h;
        b1 = d - sd[k - 2];
        if (!(a1 * b2 >= a2 * b1)) {
            t = a2 / b2;
            break;
        }
        k--;
    }
    sd[k] = d;
    sh[k] = h;
    *top_io = k + 1;
    return t;
}

/* The step with the top's differences read from the stack. hf_hull_push takes them from the
 * caller: when the top is the line's previous node (the step before pushed it, one unit back),
 * they are (h_prev - h, 1.0) exactly, and the compiler drops the product by b1 and, when nothing
 * pops, the division. */
static inline double hf_hull_step(double *sh, double *sd, ptrdiff_t *top_io, double h, double d)
{
    const ptrdiff_t k = *top_io;
    const double t = hf_hull_push(sh, sd, top_io, h, d, sh[k - 1] - h, d - sd[k - 1]);
    return k ? t : -HFVIS__INF; /* an empty stack: nothing behind */
}

/* Tangents t[i] = max over j < i with pos[i] - pos[j] <= Rw of (h[j] - h[i])/(d[i] - d[j])
 * (-inf for none, NaN at holes), for n samples of w with increasing d and pos, Rw >= 0; samples
 * before qfrom, and with ask (increasing sample indices, ending past n) those not in it, are
 * only occluders (t NaN). */
static void hf_window_line(const hf_win *w, int n, int64_t Rw, int qfrom, const int *ask)
{
    const double *d = w->d, *h = w->h;
    const int64_t *pos = w->pos;
    double *t = w->t, *ph = w->ph, *pd = w->pd, *sm = w->sm, dend = 0.0;
    double *sh = w->sh, *sd = w->sd, *lh = w->log_h, *ld = w->log_d;
    int *lt = w->log_top;
    int i, stop = 0, nlog = 0, cstart = 0, have = 0, wi = 0, wend = 0;
    ptrdiff_t ptop = 0;
    int64_t cb = 0, next = 0; /* the current block and the start of the next one */
    for (i = 0; i < n; i++) {
        double hi = h[i], di = d[i], tp;
        int64_t b;
        int asked = i >= qfrom && (!ask || i == *ask);
        if (ask && i == *ask) ask++;
        if (isnan(hi)) {
            t[i] = HFVIS__NAN;
            continue;
        }
        if (Rw <= 0) { /* nothing is within reach */
            t[i] = -HFVIS__INF;
            continue;
        }
        if (!have || pos[i] >= next) { /* a new block; the previous one is [cstart, i) */
            int j, hw = 0; /* hw: slots below it hold data (a later insertion may overwrite a
                              slot an earlier one popped, so every insertion saves its slot) */
            b = hf_floor_div64(pos[i], Rw);
            stop = nlog = 0;
            wi = wend = i;
            if (have && b == cb + 1) {
                double mx = -HFVIS__INF;
                dend = d[i - 1];
                for (j = i - 1; j >= cstart; j--) { /* its upper hull, right to left */
                    double hj = h[j], dj = d[j];
                    int old = stop;
                    if (isnan(hj)) {
                        sm[j] = mx;
                        continue;
                    }
                    sm[j] = mx = hj > mx ? hj : mx;
                    while (stop >= 2 && (sh[stop - 1] - hj) * (sd[stop - 2] - dj) <=
                                            (sh[stop - 2] - hj) * (sd[stop - 1] - dj))
                        stop--;
                    lt[nlog] = old;
                    lh[nlog] = stop < hw ? sh[stop] : 0.0;
                    ld[nlog++] = stop < hw ? sd[stop] : 0.0;
                    sh[stop] = hj;
                    sd[stop++] = dj;
                    if (stop > hw) hw = stop;
                }
                wi = cstart;
            }
            cstart = i;
            cb = b;
            next = (b + 1) * Rw;
            have = 1;
            ptop = 0;
        }
        /* advance the window start: undo the insertions of the samples now out of reach */
        for (; wi < wend && pos[i] - pos[wi] > Rw; wi++) {
            if (isnan(h[wi])) continue;
            nlog--;
            sh[stop - 1] = lh[nlog];
            sd[stop - 1] = ld[nlog];
            stop = lt[nlog];
        }
        tp = hf_hull_step(ph, pd, &ptop, hi, di);
        if (!asked) { /* pushed, not asked */
            t[i] = HFVIS__NAN;
            continue;
        }
        if (stop > 0) {
            /* the vertex of greatest slope: from the right end, the left neighbour is seen at
               least as high up to it and lower after it (ties go farther, as the hull pops);
               skipped when the suffix's highest sample at its nearest (numerator >= 0) or
               farthest (< 0) distance cannot beat the prefix: rounding is monotone, so the
               bound holds for the computed quotients too */
            int lo = 0, hi2 = stop - 1;
            double ts, num = sm[wi] - hi;
            if (num / (di - (num >= 0.0 ? dend : d[wi])) <= tp) {
                t[i] = tp;
                continue;
            }
            while (lo < hi2) {
                int mid = (lo + hi2) / 2;
                if ((sh[mid + 1] - hi) * (di - sd[mid]) >= (sh[mid] - hi) * (di - sd[mid + 1])) lo = mid + 1;
                else hi2 = mid;
            }
            ts = (sh[lo] - hi) / (di - sd[lo]);
            if (ts > tp) tp = ts;
        }
        t[i] = tp;
    }
}

/* Pre-roll (docs/errata.md E8): R lattice nodes before the first in-domain node (i0, j0) of a line with
 * lattice step (di, dj), sampled with the border rule, at distances -R..-1; they occlude but
 * receive nothing. Returns the stack height. */
static ptrdiff_t hf_preroll(const hf_sweep *sw, int i0, int j0, int di, int dj, double *sh, double *sd)
{
    const hfvis_lattice *L = &sw->L;
    const int R = sw->preroll;
    const double inv_cs = 1.0 / sw->g->cell_size;
    int r;
    ptrdiff_t top = 0;
    for (r = 0; r < R; r++) {
        double x, y, h;
        hf_node_pos(L, i0 - (R - r) * di + L->i_min, j0 - (R - r) * dj + L->j_min, &x, &y);
        h = hf_sample_border(sw->g, sw->border, x, y) * inv_cs;
        if (isnan(h)) continue;
        (void)hf_hull_step(sh, sd, &top, h, (double)(r - R));
    }
    return top;
}

/* One line under a finite search radius: the pre-roll within reach (its length is returned)
 * and the nodes into the window scratch at unit distances, positioned by their lattice
 * coordinate along the sweep (the same for a tile and the whole raster), and through
 * hf_window_line. */
static int hf_sweep_line_window(hf_sweep *sw, int m, int i0, int j0, int di, int dj,
                                ptrdiff_t node0, ptrdiff_t step, int n, int sfrom)
{
    const hfvis_lattice *L = &sw->L;
    const int R = sw->preroll < sw->win_rw ? sw->preroll : (int)sw->win_rw; /* pre-roll in reach */
    const double inv_cs = 1.0 / sw->g->cell_size;
    hf_win *w = &sw->win;
    int64_t c0 = (m & 1) ? (int64_t)j0 + sw->L.j_min : (int64_t)i0 + sw->L.i_min;
    ptrdiff_t p;
    int r, s;
    if (m >= 2) c0 = -c0;
    c0 -= R;
    for (r = 0; r < R; r++) {
        double x, y;
        hf_node_pos(L, i0 - (R - r) * di + L->i_min, j0 - (R - r) * dj + L->j_min, &x, &y);
        w->h[r] = hf_sample_border(sw->g, sw->border, x, y) * inv_cs;
    }
    for (s = 0, p = node0; s < n; s++, p += step) w->h[R + s] = sw->h[p];
    for (r = 0; r < R + n; r++) {
        w->d[r] = (double)r;
        w->pos[r] = c0 + r;
    }
    hf_window_line(w, R + n, sw->win_rw, R + sfrom, NULL);
    return R;
}

/* The nodes s in [*slo, *shi] of a line (first node (i0, j0), lattice step (di, dj), n nodes)
 * that lie within HF_RECT_MARGIN cells of the receiver rectangle: the only ones a gather of its
 * receivers reads (the taps within two lattice steps, under 3 cells). 0 if none. */
static int hf_line_rect(const hf_sweep *sw, int i0, int j0, int di, int dj, int n, int *slo, int *shi)
{
    const hfvis_lattice *L = &sw->L;
    double p[2], c[2], lo = -DBL_MAX, hi = DBL_MAX, blo[2], bhi[2];
    int a;
    hf_node_pos(L, i0 + L->i_min, j0 + L->j_min, &p[0], &p[1]);
    if (sw->parts) { /* the band's b range, widened like the rectangle */
        double bl = (p[0] + sw->ox) * L->vx + (p[1] + sw->oy) * L->vy;
        double q0 = sw->part_b0 + sw->part_span * (double)sw->part / (double)sw->parts;
        double q1 = sw->part_b0 + sw->part_span * (double)(sw->part + 1) / (double)sw->parts;
        if (bl < q0 - HF_RECT_MARGIN || bl > q1 + HF_RECT_MARGIN) return 0;
    }
    c[0] = (double)di * L->ux + (double)dj * L->vx;
    c[1] = (double)di * L->uy + (double)dj * L->vy;
    blo[0] = (double)sw->rx0 - HF_RECT_MARGIN;
    bhi[0] = (double)(sw->rx1 - 1) + HF_RECT_MARGIN;
    blo[1] = (double)sw->ry0 - HF_RECT_MARGIN;
    bhi[1] = (double)(sw->ry1 - 1) + HF_RECT_MARGIN;
    for (a = 0; a < 2; a++) {
        if (fabs(c[a]) > 1e-12) {
            double t0 = (blo[a] - p[a]) / c[a], t1 = (bhi[a] - p[a]) / c[a];
            lo = fmax(lo, fmin(t0, t1));
            hi = fmin(hi, fmax(t0, t1));
        } else if (p[a] < blo[a] || p[a] > bhi[a]) {
            return 0;
        }
    }
    lo = fmax(floor(lo) - 1.0, 0.0);
    hi = fmin(ceil(hi) + 1.0, (double)(n - 1));
    if (lo > hi) return 0;
    *slo = (int)lo;
    *shi = (int)hi;
    return 1;
}

static inline double hf_svf_term(double t);
static inline double hf_sky_term(double t, double nz, double a, double inv_k, double lobe);

/* What is done with each tangent t at node p (s-th of a line): stored for the line's consumer,
 * or the sky-view or sky term added to the accumulator there (the sums' one copy: hf_svf_line
 * and hf_sky_line call it too). The kind is a constant at each call of hf_walk_line, so the
 * compiler writes one walk per kind, and the sums' tangents are never stored and read back.
 * sky: look direction (x, y), 1/K, the lobe factor. */
enum { HF_WALK_STORE, HF_WALK_SVF, HF_WALK_SKY };

static HFVIS__ALWAYS_INLINE void hf_walk_emit(int kind, double *lat, const float *nrm, const double sky[4],
                                double *t, int s, ptrdiff_t p, double tan)
{
    if (kind == HF_WALK_STORE) {
        t[s] = tan;
    } else if (kind == HF_WALK_SVF) {
        lat[p] += hf_svf_term(tan); /* a NaN tan (overflowing heights) adds +0: no change */
    } else if (!isnan(tan)) {
        const float *nr = nrm + p * 3;
        double a = (double)nr[0] * sky[0] + (double)nr[1] * sky[1];
        lat[p] += hf_sky_term(tan, (double)nr[2], a, sky[2], sky[3]);
    }
}

/* The unlimited hull walk along one line (hull stack sh, sd of height top after the pre-roll):
 * nodes s < slo only occlude (their t is NaN), nodes slo..shi receive. The line is walked in runs
 * of nodes without holes; inside a run the hull's top is the previous node one unit back, so
 * hf_hull_push gets its differences as (h_prev - h, 1.0) and, with no pop, the division by 1.0
 * drops out (the same bits as hf_hull_step). */
static HFVIS__ALWAYS_INLINE void hf_walk_line(hf_sweep *sw, int kind, const double sky[4], ptrdiff_t node0,
                                ptrdiff_t step, int slo, int shi, ptrdiff_t top, double *t)
{
    double *sd = sw->sd, *sh = sw->lh, *lat = sw->lat, ds = 0.0; /* ds == s (integers, exact) */
    const double *hv = sw->h;
    const float *nrm = sw->nrm;
    ptrdiff_t p = node0;
    int s;
    for (s = 0; s < slo; s++, p += step, ds += 1.0) { /* occluders only */
        if (!isnan(hv[p])) (void)hf_hull_step(sh, sd, &top, hv[p], ds);
        if (kind == HF_WALK_STORE) t[s] = HFVIS__NAN; /* far from every receiver */
    }
    while (s <= shi) { /* a run of nodes without holes: the inner loop */
        double h = hv[p], hp;
        if (isnan(h)) {
            if (kind == HF_WALK_STORE) t[s] = HFVIS__NAN;
            s++, p += step, ds += 1.0;
            continue;
        }
        hf_walk_emit(kind, lat, nrm, sky, t, s, p, hf_hull_step(sh, sd, &top, h, ds));
        for (hp = h, s++, p += step, ds += 1.0; s <= shi; s++, p += step, ds += 1.0) {
            h = hv[p];
            if (isnan(h)) break;
            hf_walk_emit(kind, lat, nrm, sky, t, s, p, hf_hull_push(sh, sd, &top, h, ds, hp - h, 1.0));
            hp = h;
        }
    }
}

/* Run orientation m of the current group: copy each line (with its pre-roll) out of the
 * sampled lattice, find the horizons, hand them to fn. brute = 1 uses the oracle. walk
 * (HF_WALK_SVF, HF_WALK_SKY with its constants sky) adds that sum inside the unlimited walk
 * instead; fn, its same sum, still serves the windowed and oracle paths. (Sweeping
 * columns several side by side, so each row step reads whole cache lines, measured no faster:
 * docs/performance.md.) */
static void hf_sweep_orientation(hf_sweep *sw, int m, int brute, hf_line_fn fn, void *ctx, int walk,
                                 const double sky[4])
{
    int nlines = (m & 1) ? sw->cols : sw->rows, line;
    const hfvis_lattice *L = &sw->L;
    const int R = sw->preroll;
    const double inv_cs = 1.0 / sw->g->cell_size;
    double *sd = sw->sd, *sh = sw->lh, *t = sw->lt;
    for (line = 0; line < nlines; line++) {
        ptrdiff_t node0, step, p, top = 0;
        int i0, j0, di, dj, n, s, r;
        int slo = 0, shi;
        n = hf_line_span(sw, m, line, &node0, &step, &i0, &j0, &di, &dj);
        if (n == 0) continue;
        shi = n - 1;
        if (!brute && sw->rect && !hf_line_rect(sw, i0, j0, di, dj, n, &slo, &shi)) continue;
        if (brute) {
            /* Oracle: copy the line (pre-roll first) and scan it (docs/errata.md E5). */
            for (r = 0; r < R; r++) {
                double x, y;
                hf_node_pos(L, i0 - (R - r) * di + L->i_min, j0 - (R - r) * dj + L->j_min, &x, &y);
                sh[r] = hf_sample_border(sw->g, sw->border, x, y) * inv_cs;
            }
            for (s = 0, p = node0; s < n; s++, p += step) sh[R + s] = sw->h[p];
            hf_brute_unit(sh, R + n, t, sw->win_rw);
            fn(sw, ctx, m, node0, step, n, t + R);
            continue;
        }
        if (sw->win_rw >= 0) { /* a finite search radius */
            r = hf_sweep_line_window(sw, m, i0, j0, di, dj, node0, step, shi + 1, slo);
            fn(sw, ctx, m, node0, step, shi + 1, sw->win.t + r);
            continue;
        }
        if (R > 0) top = hf_preroll(sw, i0, j0, di, dj, sh, sd);
        if (walk == HF_WALK_SVF) {
            hf_walk_line(sw, HF_WALK_SVF, NULL, node0, step, slo, shi, top, t);
        } else if (walk == HF_WALK_SKY) {
            hf_walk_line(sw, HF_WALK_SKY, sky, node0, step, slo, shi, top, t);
        } else {
            hf_walk_line(sw, HF_WALK_STORE, NULL, node0, step, slo, shi, top, t);
            fn(sw, ctx, m, node0, step, shi + 1, t);
        }
    }
}

/* Look direction of orientation m of the current group: l = -u_m, u_0 = u, u_1 = v,
 * u_2 = -u, u_3 = -v (exact sign/swap operations). */
static void hf_look_dir(const hf_sweep *sw, int m, double *lx, double *ly)
{
    const hfvis_lattice *L = &sw->L;
    switch (m & 3) {
    case 0: *lx = -L->ux; *ly = -L->uy; break;
    case 1: *lx = -L->vx; *ly = -L->vy; break;
    case 2: *lx = L->ux; *ly = L->uy; break;
    default: *lx = L->vx; *ly = L->vy; break;
    }
}

/* Direction k of K -> the sweep vector of its group's base lattice and its quarter turn m
 * ([P1] §7: with K % 4 == 0, psi_{k + m K/4} is psi_k turned by m quarter turns). */
static void hf_direction_base(int K, int k, double azimuth0, double *ux, double *uy, int *m)
{
    int base = k;
    *m = 0;
    if (K % 4 == 0) {
        base = k % (K / 4);
        *m = k / (K / 4);
    }
    hf_sweep_vector(azimuth0 + 2.0 * HFVIS__PI * (double)base / (double)K, ux, uy);
}

/* Gather (docs/errata.md E7): the value at grid point (x, y) from a lattice buffer, bilinear over the
 * four surrounding nodes using only finite ones, renormalised; if none is finite, the nearest
 * finite node within two cells; else NaN. Exact for axis directions (integer coordinates).
 * The weights are set up once per grid point and applied to every channel; all channels of a
 * node share its finiteness (they are NaN exactly where the lattice height is). */
typedef struct hf_gather {
    ptrdiff_t node[4];      /* buffer node of each tap, -1 if unused (zero weight or outside) */
    double w[4];
    double wa, wb;
    int ia, jb;
} hf_gather;

static void hf_gather_setup(const hf_sweep *sw, int x, int y, hf_gather *G)
{
    const hfvis_lattice *L = &sw->L;
    double gx = (double)x + sw->ox, gy = (double)y + sw->oy; /* raster coordinates (tiles) */
    double a = gx * L->ux + gy * L->uy, b = gx * L->vx + gy * L->vy;
    double fa = floor(a), fb = floor(b);
    int q;
    G->wa = a - fa;
    G->wb = b - fb;
    G->ia = (int)fa - L->i_min;
    G->jb = (int)fb - L->j_min;
    for (q = 0; q < 4; q++) {
        int dx = q & 1, dy = q >> 1, i = G->ia + dx, j = G->jb + dy;
        double w = (dx ? G->wa : 1.0 - G->wa) * (dy ? G->wb : 1.0 - G->wb);
        G->w[q] = w;
        G->node[q] = (w == 0.0 || i < 0 || j < 0 || i >= sw->cols || j >= sw->rows)
                         ? -1 : (ptrdiff_t)j * sw->cols + i;
    }
}

static void hf_gather_apply(const hf_sweep *sw, const double *buf, int ch, const hf_gather *G,
                            double *out)
{
    double wsum = 0.0;
    int q, c, dx, dy;
    for (c = 0; c < ch; c++) out[c] = 0.0;
    for (q = 0; q < 4; q++) {
        const double *p;
        if (G->node[q] < 0) continue;
        p = buf + G->node[q] * ch;
        if (!isfinite(p[0])) continue;
        for (c = 0; c < ch; c++) out[c] += G->w[q] * p[c];
        wsum += G->w[q];
    }
    if (wsum > 0.0) {
        if (wsum != 1.0)
            for (c = 0; c < ch; c++) out[c] /= wsum;
        return;
    }
    {
        double best = DBL_MAX;
        const double *bp = NULL;
        for (dy = -1; dy <= 2; dy++)
            for (dx = -1; dx <= 2; dx++) {
                int i = G->ia + dx, j = G->jb + dy;
                double ex = (double)dx - G->wa, ey = (double)dy - G->wb, d2 = ex * ex + ey * ey;
                const double *p;
                if (i < 0 || j < 0 || i >= sw->cols || j >= sw->rows) continue;
                p = buf + ((size_t)j * (size_t)sw->cols + (size_t)i) * (size_t)ch;
                if (isfinite(p[0]) && d2 < best) {
                    best = d2;
                    bp = p;
                }
            }
        for (c = 0; c < ch; c++) out[c] = bp ? bp[c] : HFVIS__NAN;
    }
}

static int hf_is_hole(const hfvis_grid *g, int x, int y)
{
    return !isfinite(g->z[(ptrdiff_t)y * g->stride + x]);
}

/* A stranded receiver: a grid point with a finite height whose lattice neighbourhood (the
 * gather's 4 x 4 nodes) holds no finite node, as between holes, where every node's bilinear
 * sample touches a hole. Its horizon is still defined (holes never occlude), so it is not
 * left NaN: hf_stranded_tan takes the tangent toward the look direction (lx, ly) from the
 * per-receiver march of the oracle (hf_march_tan: unit steps, bilinear, holes skipped, the
 * sweep's border and search radius), the value hfvis_horizon_reference gives there. */
static double hf_stranded_tan(const hf_sweep *sw, int x, int y, double lx, double ly);
static double hf_tan_to_elevation(double t);

/* Gather of elevation angles. Channel by channel, nodes without a caster (alpha = -pi/2: the
 * first node of each line, which sees nothing) take part only when no neighbouring node has a
 * caster: a receiver between a line start and its successor lies inside the grid and does see
 * terrain ahead, and averaging -pi/2 into its angle is the border artefact docs/errata.md E7 warns of.
 * Otherwise as hf_gather_apply. */
static void hf_gather_elevations(const hf_sweep *sw, int ch, const hf_gather *G, double *out)
{
    const double *buf = sw->lat;
    int q, c;
    for (c = 0; c < ch; c++) {
        double sum = 0.0, wsum = 0.0, v;
        int any = 0;
        for (q = 0; q < 4; q++) {
            if (G->node[q] < 0) continue;
            v = buf[G->node[q] * ch + c];
            if (!isfinite(v)) continue;
            any = 1;
            if (v <= -HFVIS__HALF_PI) continue;
            sum += G->w[q] * v;
            wsum += G->w[q];
        }
        if (wsum > 0.0) out[c] = wsum != 1.0 ? sum / wsum : sum;
        else if (any) {
            /* Only line starts around: the nearest node with a caster within two cells (near
             * corners), else -pi/2. */
            double best = DBL_MAX;
            int dx, dy;
            out[c] = -HFVIS__HALF_PI;
            for (dy = -1; dy <= 2; dy++)
                for (dx = -1; dx <= 2; dx++) {
                    int i = G->ia + dx, j = G->jb + dy;
                    double ex = (double)dx - G->wa, ey = (double)dy - G->wb, d2 = ex * ex + ey * ey;
                    if (i < 0 || j < 0 || i >= sw->cols || j >= sw->rows) continue;
                    v = buf[((ptrdiff_t)j * sw->cols + i) * ch + c];
                    if (isfinite(v) && v > -HFVIS__HALF_PI && d2 < best) {
                        best = d2;
                        out[c] = v;
                    }
                }
        } else {
            double nv[4];
            hf_gather_apply(sw, buf, ch, G, nv); /* the nearest-node fallback */
            out[c] = nv[c];
        }
    }
}

/* The floor of the lattice coordinates (a, b) of a grid point (within the int range,
 * hf_lattice_from_u), as buffer indices (ia, jb), and the fractions; 0 when the four taps are
 * not all inside the lattice. */
static inline int hf_gather_cell(double a, double b, int i_min, int j_min, int cols, int rows,
                                 int *ia_out, int *jb_out, double *wa, double *wb)
{
    int ia = (int)a, jb = (int)b;
    double fa = (double)ia, fb = (double)jb;
    if (fa > a) { /* truncated up (a < 0): one less; fa - 1.0 is exact */
        ia--;
        fa -= 1.0;
    }
    if (fb > b) {
        jb--;
        fb -= 1.0;
    }
    *wa = a - fa;
    *wb = b - fb;
    ia -= i_min;
    jb -= j_min;
    *ia_out = ia;
    *jb_out = jb;
    return ia >= 0 && jb >= 0 && ia + 1 < cols && jb + 1 < rows;
}

/* hf_gather_elevations' common case written out (as in hf_gather_accumulate): all four taps
 * inside the lattice and every channel's four values finite and above -pi/2. A tap of weight 0
 * then adds a +-0 where the general routine skips it, which leaves the sums bit-identical (they
 * start at +0.0). Returns 0, with out untouched, when the general routine must decide. */
static HFVIS__ALWAYS_INLINE int hf_gather_elevations_inside(const hf_sweep *sw, int ch, int x, int y, double *out)
{
    const hfvis_lattice *L = &sw->L;
    double gx = (double)x + sw->ox, gy = (double)y + sw->oy; /* raster coordinates (tiles) */
    double a = gx * L->ux + gy * L->uy, b = gx * L->vx + gy * L->vy;
    double wa, wb, w0, w1, w2, w3, wsum;
    const double *p;
    ptrdiff_t cols = sw->cols;
    int ia, jb, c;
    if (!hf_gather_cell(a, b, L->i_min, L->j_min, sw->cols, sw->rows, &ia, &jb, &wa, &wb)) return 0;
    p = sw->lat + ((ptrdiff_t)jb * cols + ia) * ch;
    for (c = 0; c < ch; c++) {
        double t0 = p[c], t1 = p[ch + c], t2 = p[cols * ch + c], t3 = p[(cols + 1) * ch + c];
        /* finite and > -pi/2 (NaN and -inf fail the comparisons, +inf the sum) */
        if (!(t0 > -HFVIS__HALF_PI && t1 > -HFVIS__HALF_PI && t2 > -HFVIS__HALF_PI && t3 > -HFVIS__HALF_PI &&
              isfinite(t0 + t1 + t2 + t3)))
            return 0;
    }
    w0 = (1.0 - wa) * (1.0 - wb);
    w1 = wa * (1.0 - wb);
    w2 = (1.0 - wa) * wb;
    w3 = wa * wb;
    wsum = 0.0 + w0 + w1 + w2 + w3;
    for (c = 0; c < ch; c++) {
        double sum = 0.0 + w0 * p[c] + w1 * p[ch + c] + w2 * p[cols * ch + c] + w3 * p[(cols + 1) * ch + c];
        out[c] = wsum != 1.0 ? sum / wsum : sum;
    }
    return 1;
}

/* Gather the ch-channel lattice elevations into ch float planes (holes NaN): channel c holds
 * quarter turn ms[c] and goes to plane outs[c], row stride out_stride. Each channel's value is
 * the same whatever the other channels hold or how many there are. With the open border a
 * receiver whose first unit step toward the look direction leaves the grid sees no terrain:
 * -pi/2, exactly as the per-receiver march decides it ([P2] §1). */
static HFVIS__ALWAYS_INLINE void hf_gather_planes_ch(const hf_sweep *sw, int ch, const int *ms,
                                                     float *const *outs, ptrdiff_t out_stride)
{
    const hfvis_grid *g = sw->g;
    int x, y, c, tx, ty;
    double v[4], lx[4], ly[4];
    double xmax = (sw->ext_w - 1.0) + HF_LATTICE_EPS, ymax = (sw->ext_h - 1.0) + HF_LATTICE_EPS;
    hf_gather G;
    /* The open border's test can fire only within one cell of the raster's edge: a point at
     * least one cell inside (raster column in [1, ext_w - 2], row likewise) plus a look
     * direction of components in [-1, 1] stays inside (the rounding of the sum is monotone). */
    const int open = sw->border == HFVIS_BORDER_OPEN;
    const double in_x0 = 1.0 - sw->ox, in_x1 = (sw->ext_w - 2.0) - sw->ox; /* exact integers */
    const double in_y0 = 1.0 - sw->oy, in_y1 = (sw->ext_h - 2.0) - sw->oy;
    const int tile_w = sw->parts ? sw->rx1 - sw->rx0 : HF_TILE; /* a band: whole rows, its span */
    for (c = 0; c < ch; c++) hf_look_dir(sw, ms[c], &lx[c], &ly[c]);
    for (ty = sw->ry0; ty < sw->ry1; ty += HF_TILE)
        for (tx = sw->rx0; tx < sw->rx1; tx += tile_w)
    for (y = ty; y < sw->ry1 && y < ty + HF_TILE; y++) {
        const int edge_row = open && !((double)y >= in_y0 && (double)y <= in_y1);
        int xs, xe;
        hf_sweep_span(sw, y, &xs, &xe); /* this band's receivers of the row (all without bands) */
        if (xs < tx) xs = tx;
        if (xe > tx + tile_w) xe = tx + tile_w;
        for (x = xs; x < xe; x++) {
            ptrdiff_t o = (ptrdiff_t)y * out_stride + x;
            if (hf_is_hole(g, x, y)) {
                for (c = 0; c < ch; c++) outs[c][o] = (float)HFVIS__NAN;
                continue;
            }
            if (!hf_gather_elevations_inside(sw, ch, x, y, v)) {
                hf_gather_setup(sw, x, y, &G);
                hf_gather_elevations(sw, ch, &G, v);
                for (c = 0; c < ch; c++) /* a stranded receiver */
                    if (isnan(v[c])) v[c] = hf_tan_to_elevation(hf_stranded_tan(sw, x, y, lx[c], ly[c]));
            }
            if (edge_row || (open && !((double)x >= in_x0 && (double)x <= in_x1)))
                for (c = 0; c < ch; c++) { /* the raster's border (tiles) */
                    double nx = ((double)x + sw->ox) + lx[c], ny = ((double)y + sw->oy) + ly[c];
                    if (nx < -HF_LATTICE_EPS || ny < -HF_LATTICE_EPS || nx > xmax || ny > ymax)
                        v[c] = -HFVIS__HALF_PI;
                }
            for (c = 0; c < ch; c++) outs[c][o] = (float)v[c]; /* unrolled: ch a constant */
        }
    }
}

/* hf_gather_planes_ch with the channel count a constant in each copy (its loops unrolled). */
static void hf_gather_planes(const hf_sweep *sw, int ch, const int *ms, float *const *outs,
                             ptrdiff_t out_stride)
{
    switch (ch) {
    case 1: hf_gather_planes_ch(sw, 1, ms, outs, out_stride); break;
    case 2: hf_gather_planes_ch(sw, 2, ms, outs, out_stride); break;
    case 3: hf_gather_planes_ch(sw, 3, ms, outs, out_stride); break;
    default: hf_gather_planes_ch(sw, 4, ms, outs, out_stride); break;
    }
}

/* One grid point (x, y) at lattice coordinates (a, b), any channel count, added to acc. The
 * common case, all four taps inside the lattice with some finite weight, is hf_gather_setup +
 * hf_gather_apply written out without the tap table: a tap with zero weight or a non-finite
 * value adds +0.0 instead of being skipped, which leaves every sum bit-identical (a sum started
 * at +0.0 is never -0.0, and x + 0.0 == x otherwise); everything else takes the general routine.
 * Kept out of line: inlined into the grid loop (as gcc 12 -O2 chose once its callers changed),
 * the loop spills its invariants again, 26.8 -> 30.2 instructions per rd (docs/performance.md). */
static HFVIS__NOINLINE void hf_gather_point(const hf_sweep *sw, int x, int y, double a, double b, double *acc)
{
    const double *lat = sw->lat;
    const ptrdiff_t cols = sw->cols;
    const int ch = sw->channels;
    double wa, wb, w[4], wq[4], wsum, sum, v[4];
    const double *tp[4], *p;
    int ia, jb, q, c;
    if (!hf_gather_cell(a, b, sw->L.i_min, sw->L.j_min, sw->cols, sw->rows, &ia, &jb, &wa, &wb)) {
        hf_gather G;
        hf_gather_setup(sw, x, y, &G);
        hf_gather_apply(sw, lat, ch, &G, v);
        for (c = 0; c < ch; c++) acc[c] += v[c];
        return;
    }
    w[0] = (1.0 - wa) * (1.0 - wb);
    w[1] = wa * (1.0 - wb);
    w[2] = (1.0 - wa) * wb;
    w[3] = wa * wb;
    p = lat + ((ptrdiff_t)jb * cols + ia) * ch;
    tp[0] = p;
    tp[1] = p + ch;
    tp[2] = p + cols * ch;
    tp[3] = p + (cols + 1) * ch;
    wsum = 0.0;
    for (q = 0; q < 4; q++) {
        wq[q] = w[q] != 0.0 && isfinite(tp[q][0]) ? w[q] : 0.0;
        wsum += wq[q];
    }
    if (!(wsum > 0.0)) {
        hf_gather G;
        hf_gather_setup(sw, x, y, &G);
        hf_gather_apply(sw, lat, ch, &G, v);
        for (c = 0; c < ch; c++) acc[c] += v[c];
        return;
    }
    for (c = 0; c < ch; c++) {
        sum = 0.0;
        for (q = 0; q < 4; q++) sum += wq[q] != 0.0 ? wq[q] * tp[q][c] : 0.0;
        acc[c] += wsum != 1.0 ? sum / wsum : sum;
    }
}

/* Gather the lattice accumulator into the grid accumulator. One channel with its four taps
 * inside and finite is summed here, everything else goes through hf_gather_point (out of line,
 * so this loop keeps its invariants in registers). */
static void hf_gather_accumulate(hf_sweep *sw)
{
    const hfvis_grid *g = sw->g;
    const hfvis_lattice *L = &sw->L;
    const double *lat = sw->lat;
    const ptrdiff_t cols = sw->cols;
    const int ch = sw->channels;
    const double ox = sw->ox, oy = sw->oy, ux = L->ux, uy = L->uy, vx = L->vx, vy = L->vy;
    const int i_min = L->i_min, j_min = L->j_min, icols = sw->cols, rows = sw->rows;
    const int rx0 = sw->rx0, rx1 = sw->rx1, ry0 = sw->ry0, ry1 = sw->ry1;
    const float *z = g->z;
    const ptrdiff_t zstride = g->stride;
    double *gacc = sw->gacc;
    const size_t gw = (size_t)g->width;
    int x, y, tx, ty;
    for (ty = ry0; ty < ry1; ty += HF_TILE)
        for (tx = rx0; tx < rx1; tx += HF_TILE)
    for (y = ty; y < ry1 && y < ty + HF_TILE; y++) {
        const float *zr = z + (ptrdiff_t)y * zstride;
        double *accr = gacc + (size_t)y * gw * (size_t)ch;
        const double ya = ((double)y + oy) * uy, yb = ((double)y + oy) * vy;
        const int xe = rx1 < tx + HF_TILE ? rx1 : tx + HF_TILE;
        for (x = tx; x < xe; x++) {
            double *acc = accr + (size_t)x * (size_t)ch;
            double a, b, wa, wb, t0, t1, t2, t3, w0, w1, w2, w3;
            const double *p;
            int ia, jb;
            if (!isfinite(zr[x])) continue;
            a = ((double)x + ox) * ux + ya;
            b = ((double)x + ox) * vx + yb;
            if (ch == 1 && hf_gather_cell(a, b, i_min, j_min, icols, rows, &ia, &jb, &wa, &wb)) {
                p = lat + (ptrdiff_t)jb * cols + ia;
                t0 = p[0];
                t1 = p[1];
                t2 = p[cols];
                t3 = p[cols + 1];
                if (isfinite(t0 + t1 + t2 + t3)) { /* all finite: w*t of w == 0 is a +-0 too */
                    double wsum, sum;
                    w0 = (1.0 - wa) * (1.0 - wb);
                    w1 = wa * (1.0 - wb);
                    w2 = (1.0 - wa) * wb;
                    w3 = wa * wb;
                    wsum = 0.0 + w0 + w1 + w2 + w3;
                    sum = 0.0 + w0 * t0 + w1 * t1 + w2 * t2 + w3 * t3;
                    acc[0] += wsum != 1.0 ? sum / wsum : sum;
                    continue;
                }
            }
            hf_gather_point(sw, x, y, a, b, acc);
        }
    }
}

static void hf_lattice_fill(hf_sweep *sw, double value)
{
    const size_t row = (size_t)sw->cols * (size_t)sw->channels;
    size_t i, n = sw->band_j1 < sw->band_j0 ? 0 : (size_t)(sw->band_j1 - sw->band_j0 + 1) * row;
    double *lat = sw->lat + (size_t)sw->band_j0 * row; /* the band's rows (every row without) */
    for (i = 0; i < n; i++) lat[i] = value;
}

/* hf_lattice_fill outside the rows' spans only, for a lattice whose every in-span node the
 * sweeps then write (each quarter turn's line walk stores every node of its lines; not so with
 * a receiver rectangle, which cuts lines short). */
static void hf_lattice_fill_outside(hf_sweep *sw, double value)
{
    const size_t ch = (size_t)sw->channels;
    int j;
    for (j = 0; j < sw->rows; j++) {
        double *lr = sw->lat + (size_t)j * (size_t)sw->cols * ch;
        const int first = sw->row_first[j] <= sw->row_last[j] ? sw->row_first[j] : sw->cols;
        size_t i, a = (size_t)first * ch, b = (size_t)(sw->row_last[j] + 1) * ch, n = (size_t)sw->cols * ch;
        if (first == sw->cols) b = n;
        for (i = 0; i < a; i++) lr[i] = value;
        for (i = b; i < n; i++) lr[i] = value;
    }
}

/* The fused accumulator of the current group: 0 at every in-domain node with a height, else NaN;
 * one pass, row by row (outside the row's span NaN, inside it by the height). */
static void hf_lattice_zero(hf_sweep *sw)
{
    const int cols = sw->cols, rows = sw->rows, ch = sw->channels;
    const double *h = sw->h;
    double *lat = sw->lat;
    int j, i, c;
    for (j = 0; j < rows; j++) {
        const double *hr = h + (size_t)j * (size_t)cols;
        double *lr = lat + (size_t)j * (size_t)cols * (size_t)ch;
        const int first = sw->row_first[j], last = sw->row_last[j];
        if (ch == 1) {
            for (i = 0; i < first && i < cols; i++) lr[i] = HFVIS__NAN;
            for (i = first; i <= last; i++) lr[i] = isnan(hr[i]) ? HFVIS__NAN : 0.0;
            for (i = last + 1 > first ? last + 1 : first; i < cols; i++) lr[i] = HFVIS__NAN;
            continue;
        }
        for (i = 0; i < cols; i++) {
            const double v = i >= first && i <= last && !isnan(hr[i]) ? 0.0 : HFVIS__NAN;
            for (c = 0; c < ch; c++) lr[(size_t)i * (size_t)ch + (size_t)c] = v;
        }
    }
}

/* ========================================================================================== */
/* 8. Horizon outputs and the ray-march oracles                                               */
/* ========================================================================================== */

/* atan for the per-receiver-direction light terms (sky light, environment light, both modes) and
 * the lattice's node elevations: glibc's correctly rounded atan costs about 9 ns a call, half the
 * sweep's budget per receiver-direction. Range reduction atan t = pi/2 - atan(1/t) for |t| > 1,
 * then an odd polynomial x P(x^2) of degree 17 on [0, 1], minimax for the absolute error (Remez
 * exchange), P evaluated by Estrin's scheme. The oracles and the exact rays' angles keep libm's
 * atan. -inf gives -pi/2 and NaN NaN, as hf_tan_to_elevation. */
#define HF_ATAN_MAX_ERR 6e-9 /* rad, |hfvis__atan - atan| (Remez bound 5.76e-9): 1/20 of a float ulp at pi/2 */
static HFVIS__ALWAYS_INLINE double hf_atan_poly(double x)
{
    double s = x * x, s2 = s * s, s4 = s2 * s2;
    return x * (((0.9999998863830964 + -0.3333259702893892 * s) + s2 * (0.19985906780335758 + -0.1416122929275394 * s)) +
                s4 * ((0.1049894642938515 + -0.07234858062458693 * s) +
                      s2 * (0.03978123126172938 + -0.014401362402942217 * s)) +
                (s4 * s4) * 0.0024567256561116523);
}

static inline double hf_atan(double t)
{
    double x = fabs(t), y;
    int big = x > 1.0; /* false for NaN, which then runs through as NaN */
    if (big) x = 1.0 / x;
    y = hf_atan_poly(x);
    if (big) y = HFVIS__HALF_PI - y;
    return copysign(y, t);
}

/* hf_atan over a block of HF_ATAN_BLOCK values, the same bits, in loops the compiler vectorizes
 * under the default floating-point rules (which keep a branch around a division or a subtraction
 * a branch, and thread two tests of one value into branches): first |t| capped at 1e300 (its
 * atan rounds to pi/2 as inf's does; NaN passes), then the reduction's choices as products with
 * m and q = 1 - m in {0, 1}, each exact (1 a + 0 b = a for finite b), so the one division is
 * always made and x / 1 is x. */
#define HF_ATAN_BLOCK 32
static void hf_atan_block(const double *restrict t, double *restrict e)
{
    double a[HF_ATAN_BLOCK];
    int i;
    for (i = 0; i < HF_ATAN_BLOCK; i++) {
        double x = fabs(t[i]);
        a[i] = x > 1e300 ? 1e300 : x;
    }
    for (i = 0; i < HF_ATAN_BLOCK; i++) {
        double x = a[i], m = x > 1.0 ? 1.0 : 0.0, q = 1.0 - m;
        double y = hf_atan_poly((m + q * x) / (m * x + q));
        e[i] = copysign(m * HFVIS__HALF_PI + (q - m) * y, t[i]);
    }
}

/* hf_atan and hf_atan_block for the tests (test_hfvis atan_approximation, atan_block_bits). */
double hfvis__atan(double t);
double hfvis__atan(double t) { return hf_atan(t); }
int hfvis__atan_block(const double *t, double *e);
int hfvis__atan_block(const double *t, double *e)
{
    hf_atan_block(t, e);
    return HF_ATAN_BLOCK;
}

static double hf_tan_to_elevation(double t)
{
    if (isnan(t)) return HFVIS__NAN;
    if (t == -HFVIS__INF) return -HFVIS__HALF_PI;
    return atan(t);
}

/* Consumer: elevation angle at each node of the line, into channel *(const int *)ctx when ctx
 * is given (hf_horizon_planes), else channel m of a 4-channel lattice (the four quarter turns of
 * hfvis_horizon_map) or the only channel. The angle is hf_atan's (within HF_ATAN_MAX_ERR of
 * libm's, far inside the [P1] lattice's own error; the gather interpolates these angles), in
 * blocks the compiler vectorizes, the tail one by one (the same bits). */
static void hf_store_elevation(hf_sweep *sw, void *ctx, int m, ptrdiff_t node0, ptrdiff_t step,
                               int n, const double *t)
{
    int s = 0, i, ch = sw->channels;
    double *lat = sw->lat + (ctx ? *(const int *)ctx : ch == 1 ? 0 : m), e[HF_ATAN_BLOCK];
    for (; s + HF_ATAN_BLOCK <= n; s += HF_ATAN_BLOCK) {
        hf_atan_block(t + s, e);
        for (i = 0; i < HF_ATAN_BLOCK; i++, node0 += step) lat[node0 * ch] = e[i];
    }
    for (; s < n; s++, node0 += step) lat[node0 * ch] = hf_atan(t[s]);
}

static hfvis_status hf_check_common(const hfvis_grid *grid, const hfvis_sweep_options *opts)
{
    if (!hf_grid_valid(grid) || !hf_opts_valid(opts) || (opts && !hf_tile_fits(grid, opts)))
        return HFVIS_ERR_INVALID_ARGUMENT;
    return HFVIS_OK;
}

static hfvis_status hf_horizon_lattice_impl(const hfvis_grid *grid, double azimuth_rad,
                                            const hfvis_sweep_options *opts, float *out, int brute)
{
    hfvis_sweep_options o;
    hf_sweep sw;
    hfvis_status s;
    double ux, uy;
    size_t i, n;
    if (hf_check_common(grid, opts) != HFVIS_OK || !out || !isfinite(azimuth_rad) ||
        (opts && hf_tile_window(grid, opts))) /* its nodes are those of hfvis_lattice_init */
        return HFVIS_ERR_INVALID_ARGUMENT;
    o = hf_opts_resolve(grid, opts);
    if ((s = hf_sweep_alloc(&sw, grid, &o, 0, 1, 0)) != HFVIS_OK) return s;
    sw.rect = 0; /* every node: the lattice has no receivers */
    hf_sweep_vector(azimuth_rad, &ux, &uy);
    hf_sweep_group(&sw, ux, uy);
    hf_lattice_fill(&sw, HFVIS__NAN);
    hf_sweep_orientation(&sw, 0, brute, hf_store_elevation, NULL, HF_WALK_STORE, NULL);
    n = (size_t)sw.rows * (size_t)sw.cols;
    for (i = 0; i < n; i++) out[i] = (float)sw.lat[i];
    hf_sweep_free(&sw);
    return HFVIS_OK;
}

hfvis_status hfvis_horizon_lattice(const hfvis_grid *grid, double azimuth_rad,
                                   const hfvis_sweep_options *opts, float *out)
{
    return hf_horizon_lattice_impl(grid, azimuth_rad, opts, out, 0);
}

hfvis_status hfvis_horizon_lattice_naive(const hfvis_grid *grid, double azimuth_rad,
                                         const hfvis_sweep_options *opts, float *out)
{
    return hf_horizon_lattice_impl(grid, azimuth_rad, opts, out, 1);
}

static void hf_progress(const hfvis_sweep_options *o, int done, int total)
{
    if (o->progress) o->progress(o->progress_user, done, total);
}

hfvis_status hfvis_horizon_direction(const hfvis_grid *grid, int K, int k,
                                     const hfvis_sweep_options *opts, float *out,
                                     ptrdiff_t out_stride)
{
    hfvis_sweep_options o;
    hf_sweep sw;
    hfvis_status s;
    double ux, uy;
    int m;
    if (hf_check_common(grid, opts) != HFVIS_OK || !out || K < 1 || k < 0 || k >= K ||
        out_stride < grid->width || !hfvis__plane_fits(out_stride, grid->height, 4))
        return HFVIS_ERR_INVALID_ARGUMENT;
    o = hf_opts_resolve(grid, opts);
    if (o.rays == HFVIS_RAYS_EXACT) return hf_exact_horizon_direction(grid, K, k, &o, out, out_stride);
    if ((s = hf_sweep_alloc(&sw, grid, &o, 0, 1, 0)) != HFVIS_OK) return s;
    hf_direction_base(K, k, o.azimuth0_rad, &ux, &uy, &m);
    hf_sweep_group(&sw, ux, uy);
    hf_lattice_fill(&sw, HFVIS__NAN);
    hf_sweep_orientation(&sw, m, 0, hf_store_elevation, NULL, HF_WALK_STORE, NULL);
    hf_gather_planes(&sw, 1, &m, &out, out_stride);
    hf_sweep_free(&sw);
    hf_progress(&o, 1, 1);
    return HFVIS_OK;
}

static hfvis_status hf_direction_range(const hfvis_sweep_options *o, int K, int *begin, int *end);

/* Position of direction k in the order of o->direction_order (hfvis.h). */
static int hf_direction_position(const hfvis_sweep_options *o, int K, int k)
{
    if (o->direction_order != HFVIS_DIRECTION_ORDER_SWEEP || K % 4 != 0) return k;
    return (k % (K / 4)) * 4 + k / (K / 4);
}

/* The planes of the positions [begin, end) (direction_order) of the map: each direction exactly
 * as hfvis_horizon_direction does it (its group's lattice sampled once, one orientation at a
 * time), so the plane of position p, out + (p - begin)*plane, is bit-identical to its plane k of
 * the full map. */
static hfvis_status hf_horizon_map_range(const hfvis_grid *grid, int K, const hfvis_sweep_options *o,
                                         int begin, int end, float *out)
{
    hf_sweep sw;
    hfvis_status s;
    size_t plane = hf_grid_count(grid);
    int per = K % 4 == 0 ? 4 : 1, groups = K / per, gidx, m, done = 0;
    if ((s = hf_sweep_alloc(&sw, grid, o, 0, 1, 0)) != HFVIS_OK) return s;
    for (gidx = 0; gidx < groups; gidx++) {
        double ux, uy;
        int m0, sampled = 0;
        for (m = 0; m < per; m++) {
            int k = gidx + m * groups, pos = hf_direction_position(o, K, k);
            if (pos < begin || pos >= end) continue;
            if (!sampled) {
                hf_direction_base(K, gidx, o->azimuth0_rad, &ux, &uy, &m0);
                hf_sweep_group(&sw, ux, uy);
                sampled = 1;
            }
            hf_lattice_fill(&sw, HFVIS__NAN);
            float *dst = out + (size_t)(pos - begin) * plane;
            hf_sweep_orientation(&sw, m, 0, hf_store_elevation, NULL, HF_WALK_STORE, NULL);
            hf_gather_planes(&sw, 1, &m, &dst, grid->width);
            hf_progress(o, ++done, end - begin);
        }
    }
    hf_sweep_free(&sw);
    return HFVIS_OK;
}

hfvis_status hfvis_horizon_map(const hfvis_grid *grid, int K, const hfvis_sweep_options *opts,
                               float *out)
{
    hfvis_sweep_options o;
    hf_sweep sw;
    hfvis_status s;
    size_t plane = 0, total;
    int groups, per, gidx, m, done = 0, ms[4];
    int begin, end;
    float *outs[4];
    if (hf_check_common(grid, opts) != HFVIS_OK || !out || K < 1) return HFVIS_ERR_INVALID_ARGUMENT;
    plane = hf_grid_count(grid);
    if (!hfvis__mul_size(plane, (size_t)K, &total)) return HFVIS_ERR_INVALID_ARGUMENT;
    o = hf_opts_resolve(grid, opts);
    if (hf_direction_range(&o, K, &begin, &end) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.rays == HFVIS_RAYS_EXACT) return hf_exact_horizon_map(grid, K, &o, begin, end, out);
    per = K % 4 == 0 ? 4 : 1;
    groups = K / per;
    if (end - begin < K || hf_direction_position(&o, K, 1) != 1) /* a part, or planes in sweep order */
        return hf_horizon_map_range(grid, K, &o, begin, end, out);
    if ((s = hf_sweep_alloc(&sw, grid, &o, 0, per, 0)) != HFVIS_OK) return s;
    for (gidx = 0; gidx < groups; gidx++) {
        double ux, uy;
        int m0;
        hf_direction_base(K, gidx, o.azimuth0_rad, &ux, &uy, &m0);
        hf_sweep_group(&sw, ux, uy);
        if (sw.rect) hf_lattice_fill(&sw, HFVIS__NAN);
        else hf_lattice_fill_outside(&sw, HFVIS__NAN);
        for (m = 0; m < per; m++) {
            hf_sweep_orientation(&sw, m, 0, hf_store_elevation, NULL, HF_WALK_STORE, NULL);
            hf_progress(&o, ++done, K);
        }
        /* plane k = gidx + m*groups: channel m lands m*groups planes further on */
        for (m = 0; m < per; m++) {
            ms[m] = m;
            outs[m] = out + (size_t)(gidx + m * groups) * plane;
        }
        hf_gather_planes(&sw, per, ms, outs, grid->width);
    }
    hf_sweep_free(&sw);
    return HFVIS_OK;
}

/* The planes of the directions k with need[k] set into planes[k] (row stride the width; the other
 * planes neither read nor written), each bit-identical to plane k of hfvis_horizon_map(grid, K,
 * opts) in index order. Exact rays: each run of needed directions whose planes follow each other
 * in memory is one hfvis_horizon_map call. Lattice: a quarter-turn group's lattice is sampled
 * once, only its needed orientations are swept, each into its own channel (no zero or NaN fill
 * of the others), and one gather writes them all (hf_gather_planes: a channel's value does not
 * depend on the others). */
static hfvis_status hf_horizon_planes(const hfvis_grid *grid, int K, const hfvis_sweep_options *opts,
                                      const unsigned char *need, float *const *planes)
{
    hfvis_sweep_options o;
    hf_sweep sw;
    hfvis_status s = HFVIS_OK;
    size_t plane;
    int per, groups, gidx, k, e, m, done = 0, total = 0;
    if (hf_check_common(grid, opts) != HFVIS_OK || K < 1) return HFVIS_ERR_INVALID_ARGUMENT;
    o = hf_opts_resolve(grid, opts);
    o.direction_begin = o.direction_end = 0;
    o.direction_order = HFVIS_DIRECTION_ORDER_DEFAULT;
    plane = hf_grid_count(grid);
    if (o.rays == HFVIS_RAYS_EXACT) {
        for (k = 0; k < K && s == HFVIS_OK; k = e) {
            hfvis_sweep_options r = *opts; /* as the caller's (resolved again inside) */
            for (e = k + 1; e < K && need[e] == need[k] && (!need[k] || planes[e] == planes[e - 1] + plane); e++) {}
            if (!need[k]) continue;
            r.direction_order = HFVIS_DIRECTION_ORDER_DEFAULT;
            r.direction_begin = r.direction_end = 0;
            if (k > 0 || e < K) {
                r.direction_begin = k;
                r.direction_end = e;
            }
            s = hfvis_horizon_map(grid, K, &r, planes[k]);
        }
        return s;
    }
    per = K % 4 == 0 ? 4 : 1;
    groups = K / per;
    for (k = 0; k < K; k++) total += need[k] != 0;
    if ((s = hf_sweep_alloc(&sw, grid, &o, 0, per, 0)) != HFVIS_OK) return s;
    for (gidx = 0; gidx < groups; gidx++) {
        double ux, uy;
        int m0, ms[4], ch = 0, c;
        float *outs[4];
        for (m = 0; m < per; m++)
            if (need[gidx + m * groups]) {
                ms[ch] = m;
                outs[ch++] = planes[gidx + m * groups];
            }
        if (!ch) continue;
        hf_direction_base(K, gidx, o.azimuth0_rad, &ux, &uy, &m0);
        sw.channels = ch; /* the buffer holds per channels */
        hf_sweep_group(&sw, ux, uy);
        if (sw.rect) hf_lattice_fill(&sw, HFVIS__NAN);
        else hf_lattice_fill_outside(&sw, HFVIS__NAN);
        for (c = 0; c < ch; c++) {
            hf_sweep_orientation(&sw, ms[c], 0, hf_store_elevation, &c, HF_WALK_STORE, NULL);
            hf_progress(&o, ++done, total);
        }
        hf_gather_planes(&sw, ch, ms, outs, grid->width);
    }
    hf_sweep_free(&sw);
    return HFVIS_OK;
}

static int hf_march_valid(const hfvis_march_options *m)
{
    return !m || (isfinite(m->step_cells) && m->step_cells >= 0.0 &&
                  isfinite(m->max_distance_cells) && m->max_distance_cells >= 0.0);
}

/* The surface an oracle marches over: a grid (with its border rule) or an analytic function. */
typedef struct hf_surface {
    const hfvis_grid *g;       /* or NULL for fn */
    hfvis_height_fn fn;
    void *user;
    int width, height;
    double cell_size;
    hfvis_border border;
    double reach;              /* how far beyond the grid the march continues (cells) */
} hf_surface;

static inline double hf_surface_height(const hf_surface *S, double x, double y)
{
    if (S->fn) return S->fn(S->user, x, y);
    if (x >= 0.0 && y >= 0.0 && x <= (double)(S->width - 1) && y <= (double)(S->height - 1))
        return hf_bilerp(S->g->z, S->g->stride, S->width, S->height, x, y);
    return hf_sample_border(S->g, S->border, x, y);
}

/* Per-receiver march ([P2] §1; P2's "naive method"): samples at p + s*step*l,
 * s = 1, 2, ..., while inside the grid (plus the border reach), keeping the largest slope.
 * which = 1: best[0] = the largest (h - h0)/d (the terrain); which = 2: best[1] = the largest
 * (h0 - h)/d (the inverted surface -z, negative openness); which = 3: both over the same walk,
 * each equal to its own march bit for bit ((h0 - h) is -(h - h0) exactly). */
static void hf_march_slopes(const hf_surface *S, double px, double py, double h0, double lx,
                            double ly, double step, double max_dist, int which, double best[2])
{
    double xmin = -S->reach - HF_LATTICE_EPS, ymin = xmin;
    double xmax = (double)(S->width - 1) + S->reach + HF_LATTICE_EPS;
    double ymax = (double)(S->height - 1) + S->reach + HF_LATTICE_EPS;
    double inv = 1.0 / S->cell_size, up = -HFVIS__INF, low = HFVIS__INF;
    long s;
    for (s = 1;; s++) {
        double d = (double)s * step, x = px + d * lx, y = py + d * ly, h, t;
        if (max_dist > 0.0 && d > max_dist + HF_LATTICE_EPS) break;
        if (x < xmin || y < ymin || x > xmax || y > ymax) break;
        x = x < 0.0 && x > -HF_LATTICE_EPS ? 0.0 : x;
        y = y < 0.0 && y > -HF_LATTICE_EPS ? 0.0 : y;
        h = hf_surface_height(S, x, y);
        if (!isfinite(h)) continue;
        t = (h - h0) * inv / d; /* (h0 - h) * inv / d is exactly -t */
        up = t > up ? t : up;
        low = t < low ? t : low;
    }
    best[0] = which & 1 ? up : -HFVIS__INF;
    best[1] = which & 2 ? -low : -HFVIS__INF;
}

/* The march's largest slope of the terrain (sign > 0) or of -z (sign < 0). */
static double hf_march_tan(const hf_surface *S, double px, double py, double h0, double lx,
                           double ly, double step, double max_dist, double sign)
{
    double best[2];
    hf_march_slopes(S, px, py, h0, lx, ly, step, max_dist, sign > 0.0 ? 1 : 2, best);
    return sign > 0.0 ? best[0] : best[1];
}

static double hf_stranded_tan(const hf_sweep *sw, int x, int y, double lx, double ly)
{
    hf_surface S;
    memset(&S, 0, sizeof S);
    S.g = sw->g;
    S.width = sw->g->width;
    S.height = sw->g->height;
    S.cell_size = sw->g->cell_size;
    S.border = sw->border;
    S.reach = (double)sw->preroll;
    return hf_march_tan(&S, (double)x, (double)y, (double)sw->g->z[(ptrdiff_t)y * sw->g->stride + x], lx, ly,
                        1.0, sw->radius_cells, 1.0);
}

static hfvis_status hf_reference_run(const hf_surface *S, int K, double azimuth0, int exact_bound,
                                     const hfvis_march_options *march, const float *points,
                                     size_t count, float *out, double radius)
{
    double step = march && march->step_cells > 0.0 ? march->step_cells : 1.0;
    double maxd = march ? march->max_distance_cells : 0.0;
    if (radius > 0.0 && radius < HFVIS__INF) { /* the sweep options' search radius, in cells */
        double rc = radius / S->cell_size;
        maxd = maxd > 0.0 && maxd < rc ? maxd : rc;
    }
    size_t i;
    int k;
    for (i = 0; i < count; i++) {
        double px = (double)points[2 * i], py = (double)points[2 * i + 1], h0;
        h0 = isfinite(px) && isfinite(py) ? hf_surface_height(S, px, py) : HFVIS__NAN;
        for (k = 0; k < K; k++) {
            double ux, uy, t;
            if (!isfinite(h0)) {
                out[i * (size_t)K + (size_t)k] = HFVIS__NAN;
                continue;
            }
            if (exact_bound != 0) { /* exact mode: along the actual direction (a, b) */
                hf_ray r = hf_ray_nearest(azimuth0 + 2.0 * HFVIS__PI * (double)k / (double)K, exact_bound);
                double len = sqrt((double)r.a * (double)r.a + (double)r.b * (double)r.b);
                ux = -(double)r.a / len;
                uy = -(double)r.b / len;
            } else {
                hf_sweep_vector(azimuth0 + 2.0 * HFVIS__PI * (double)k / (double)K, &ux, &uy);
            }
            t = hf_march_tan(S, px, py, h0, -ux, -uy, step, maxd, 1.0);
            out[i * (size_t)K + (size_t)k] = (float)hf_tan_to_elevation(t);
        }
    }
    return HFVIS_OK;
}

static int hf_points_valid(const float *points, size_t count, int K, const float *out)
{
    return (count == 0 || (points && out)) && K >= 1 && count <= SIZE_MAX / (size_t)K;
}

hfvis_march_options hfvis_march_options_default(void)
{
    hfvis_march_options o;
    memset(&o, 0, sizeof o);
    o.step_cells = 1.0;
    o.max_distance_cells = 0.0; /* until the ray leaves the grid */
    return o;
}

hfvis_status hfvis_horizon_reference(const hfvis_grid *grid, int K,
                                     const hfvis_sweep_options *opts,
                                     const hfvis_march_options *march, const float *points,
                                     size_t count, float *out)
{
    hfvis_sweep_options o;
    hf_surface S;
    if (hf_check_common(grid, opts) != HFVIS_OK || !hf_march_valid(march) ||
        !hf_points_valid(points, count, K, out))
        return HFVIS_ERR_INVALID_ARGUMENT;
    o = hf_opts_resolve(grid, opts);
    memset(&S, 0, sizeof S);
    S.g = grid;
    S.width = grid->width;
    S.height = grid->height;
    S.cell_size = grid->cell_size;
    S.border = o.border;
    S.reach = o.border == HFVIS_BORDER_OPEN ? 0.0 : (double)o.border_cells;
    return hf_reference_run(&S, K, o.azimuth0_rad, o.rays == HFVIS_RAYS_EXACT ? hf_exact_bound(&o, K) : 0,
                            march, points, count, out, o.max_distance);
}

hfvis_status hfvis_horizon_reference_fn(hfvis_height_fn fn, void *user, int width, int height,
                                        double cell_size, int K, const hfvis_sweep_options *opts,
                                        const hfvis_march_options *march, const float *points,
                                        size_t count, float *out)
{
    hf_surface S;
    if (!fn || width < 1 || height < 1 || !isfinite(cell_size) || cell_size <= 0.0 ||
        !hf_opts_valid(opts) || !hf_march_valid(march) || !hf_points_valid(points, count, K, out) ||
        (opts && opts->border != HFVIS_BORDER_DEFAULT && opts->border != HFVIS_BORDER_OPEN))
        return HFVIS_ERR_INVALID_ARGUMENT;
    memset(&S, 0, sizeof S);
    S.fn = fn;
    S.user = user;
    S.width = width;
    S.height = height;
    S.cell_size = cell_size;
    S.border = HFVIS_BORDER_OPEN;
    return hf_reference_run(&S, K, opts ? opts->azimuth0_rad : 0.0,
                            opts && opts->rays == HFVIS_RAYS_EXACT ? hf_exact_bound(opts, K) : 0, march,
                            points, count, out, opts ? opts->max_distance : 0.0);
}

hfvis_openness_options hfvis_openness_options_default(void)
{
    hfvis_openness_options o;
    memset(&o, 0, sizeof o);
    o.radius = 0.0; /* unlimited */
    o.negative = 0;
    o.step_cells = 1.0;
    return o;
}

/* Topographic openness (Yokoyama, Shirasawa & Pike 2002): the mean zenith angle pi/2 - beta_k
 * of the K skylines. Radius-limited: every receiver marches each direction out to the radius
 * (hf_march_tan, the oracle's march; sign -1 marches the inverted surface for negative
 * openness). Unlimited: the exact sweep, one direction at a time (hfvis_horizon_direction), of
 * the surface or of its negated copy. Both take the angles with hf_atan, as the lattice does. */
hfvis_status hfvis_openness(const hfvis_grid *grid, int K, const hfvis_openness_options *oo,
                            const hfvis_sweep_options *opts, float *out, ptrdiff_t out_stride)
{
    const int W = grid ? grid->width : 0, H = grid ? grid->height : 0;
    double radius = oo ? oo->radius : 0.0, step = oo && oo->step_cells > 0.0 ? oo->step_cells : 1.0;
    int negative = oo ? oo->negative : 0, x, y, k;
    const ptrdiff_t second = (ptrdiff_t)H * out_stride; /* negative == 2: the negative plane */
    hfvis_sweep_options o;
    if (hf_check_common(grid, opts) != HFVIS_OK || K < 1 || !out || out_stride < W ||
        !hfvis__plane_fits(out_stride, negative == 2 && H <= INT_MAX / 2 ? 2 * H : H, 4) ||
        !isfinite(radius) || radius < 0.0 || !isfinite(step) || (oo && !(oo->step_cells >= 0.0)) ||
        (negative != 0 && negative != 1 && negative != 2) || (negative == 2 && H > INT_MAX / 2))
        return HFVIS_ERR_INVALID_ARGUMENT;
    /* a radius honours a receiver rectangle (each receiver's march is its own); a search radius
     * or a window is not honoured here, nor a rectangle without a radius */
    if (opts && (hf_radius_on(opts) || opts->extent_width != 0 || (radius == 0.0 && opts->receiver_width != 0)))
        return HFVIS_ERR_INVALID_ARGUMENT;
    o = hf_opts_resolve(grid, opts);
    if (radius > 0.0) { /* the march: no allocation; both signs from one walk when negative == 2 */
        int rx0, ry0, rx1, ry1;
        hf_surface S;
        const double maxd = radius / grid->cell_size;
        const int which = negative == 2 ? 3 : negative ? 2 : 1;
        memset(&S, 0, sizeof S);
        S.g = grid;
        S.width = W;
        S.height = H;
        S.cell_size = grid->cell_size;
        S.border = o.border;
        S.reach = o.border == HFVIS_BORDER_OPEN ? 0.0 : (double)o.border_cells;
        hf_receiver_rect(grid, &o, &rx0, &ry0, &rx1, &ry1);
        for (y = ry0; y < ry1; y++) {
            for (x = rx0; x < rx1; x++) {
                const ptrdiff_t i = (ptrdiff_t)y * out_stride + x;
                double h0 = (double)grid->z[(ptrdiff_t)y * grid->stride + x], sum[2] = {0.0, 0.0};
                if (!isfinite(h0)) {
                    out[i] = (float)HFVIS__NAN;
                    if (negative == 2) out[second + i] = (float)HFVIS__NAN;
                    continue;
                }
                for (k = 0; k < K; k++) {
                    double ux, uy, best[2];
                    hf_sweep_vector(o.azimuth0_rad + 2.0 * HFVIS__PI * (double)k / (double)K, &ux, &uy);
                    hf_march_slopes(&S, (double)x, (double)y, h0, -ux, -uy, step, maxd, which, best);
                    /* each angle as a float, as the horizon outputs (and the sweep path) hold it */
                    if (which & 1) sum[0] += HFVIS__HALF_PI - (double)(float)hf_atan(best[0]);
                    if (which & 2) sum[1] += HFVIS__HALF_PI - (double)(float)hf_atan(best[1]);
                }
                if (negative == 2) {
                    out[i] = (float)(sum[0] / (double)K);
                    out[second + i] = (float)(sum[1] / (double)K);
                } else
                    out[i] = (float)(sum[negative] / (double)K);
            }
            hf_progress(&o, y - ry0 + 1, ry1 - ry0);
        }
    } else if (negative == 2) { /* the sweep: the positive plane, then the negative one */
        hfvis_openness_options one = *oo;
        hfvis_status s;
        /* the positive plane waits in scratch until the negative run has succeeded: an error in
           that run leaves out untouched */
        float *pos = (float *)hfvis__alloc_array(o.alloc, hf_grid_count(grid), sizeof(float));
        if (!pos) return HFVIS_ERR_OUT_OF_MEMORY;
        one.negative = 0;
        s = hfvis_openness(grid, K, &one, opts, pos, W);
        one.negative = 1;
        if (s == HFVIS_OK) s = hfvis_openness(grid, K, &one, opts, out + second, out_stride);
        for (y = 0; s == HFVIS_OK && y < H; y++)
            for (x = 0; x < W; x++) out[(ptrdiff_t)y * out_stride + x] = pos[(size_t)y * (size_t)W + (size_t)x];
        hfvis__free(o.alloc, pos);
        return s;
    } else { /* the sweep: a plane, its sums and (negative) the inverted surface */
        const size_t n = hf_grid_count(grid);
        float *plane = (float *)hfvis__alloc_array(o.alloc, n, sizeof(float));
        double *sum = (double *)hfvis__alloc_array(o.alloc, n, sizeof(double));
        float *inv = negative ? (float *)hfvis__alloc_array(o.alloc, n, sizeof(float)) : NULL;
        hfvis_sweep_options quiet = o;
        hfvis_grid g = *grid;
        hfvis_status s = HFVIS_OK;
        size_t i;
        if (!plane || !sum || (negative && !inv)) {
            hfvis__free(o.alloc, inv);
            hfvis__free(o.alloc, sum);
            hfvis__free(o.alloc, plane);
            return HFVIS_ERR_OUT_OF_MEMORY;
        }
        if (negative) {
            for (y = 0; y < H; y++)
                for (x = 0; x < W; x++)
                    inv[(size_t)y * (size_t)W + (size_t)x] = -grid->z[(ptrdiff_t)y * grid->stride + x];
            g.z = inv;
            g.stride = W;
        }
        quiet.progress = NULL; /* reported here, once per direction */
        for (i = 0; i < n; i++) sum[i] = 0.0;
        for (k = 0; k < K && s == HFVIS_OK; k++) {
            s = hfvis_horizon_direction(&g, K, k, &quiet, plane, W);
            for (i = 0; s == HFVIS_OK && i < n; i++) sum[i] += HFVIS__HALF_PI - (double)plane[i];
            if (s == HFVIS_OK) hf_progress(&o, k + 1, K);
        }
        if (s == HFVIS_OK)
            for (y = 0; y < H; y++)
                for (x = 0; x < W; x++)
                    out[(ptrdiff_t)y * out_stride + x] = (float)(sum[(size_t)y * (size_t)W + (size_t)x] / (double)K);
        hfvis__free(o.alloc, inv);
        hfvis__free(o.alloc, sum);
        hfvis__free(o.alloc, plane);
        return s;
    }
    return HFVIS_OK;
}

/* ========================================================================================== */
/* 9. Light: uniform sky, sky-view factor, sun visibility                                     */
/* ========================================================================================== */

/* [P1] Eq. 5 re-derived: the phi-integral of the cosine term over the sector
 * [psi_k - pi/K, psi_k + pi/K] is exact (2 sin(pi/K)); the b_k term integrates to zero. */
double hfvis_sector_weight(int K, double nz, double a, double theta)
{
    if (K < 1) return HFVIS__NAN;
    return nz / (double)K * sin(theta) * sin(theta) +
           sin(HFVIS__PI / (double)K) / HFVIS__PI * a * (theta - 0.5 * sin(2.0 * theta));
}

/* S_k from the horizon tangent t, in slope space (docs/errata.md E3): the tangent-plane clamp
 * theta_k = min(theta_h, pi/2 + atan2(a, Nz)) is t' = max(t, -a/Nz) (Nz > 0 for height
 * fields), then sin^2 theta = 1/(1+t'^2), sin 2theta = 2t'/(1+t'^2), theta = pi/2 - atan t'. */
static inline double hf_sky_term(double t, double nz, double a, double inv_k, double lobe)
{
    double tc, q, theta, r;
    /* nz = 0: a vertical receiver, or a float normal whose z underflowed (tiny cells): the
     * limits of tc = -a/nz; facing away (a <= 0), the direction lies below the tangent plane */
    if (nz > 0.0) tc = -a / nz;
    else if (a > 0.0) tc = -HFVIS__INF;
    else return 0.0;
    if (t > tc) tc = t;
    if (isinf(tc)) { /* tc = -inf: q = 0, tc q -> 0, theta = pi */
        return tc > 0.0 ? 0.0 : lobe * a * HFVIS__PI;
    }
    q = 1.0 / (1.0 + tc * tc);
    theta = HFVIS__HALF_PI - hf_atan(tc);
    /* The term integrates a cosine over the visible arc, so it is >= 0; for a steep horizon
     * (large tc) theta - tc q cancels to about 2/(3 tc^3) and rounding can dip below 0. */
    r = nz * inv_k * q + lobe * a * (theta - tc * q);
    return r > 0.0 ? r : 0.0;
}

/* The common head of every fused consumer's context. */
typedef struct hf_fused {
    int K, k;
    double lx, ly;          /* look direction of direction k */
    int walk;               /* HF_WALK_SVF, HF_WALK_SKY: fn's sum added inside the line walk */
    double inv_k, lobe;     /* the sky term's 1/K and lobe factor (hf_sky_setup) */
    size_t extra_size;      /* extra scratch bytes the consumer needs (sw->extra) */
    double *gacc_out;       /* NULL, or the caller's array to use as the grid accumulator
                               (hfvis_direction_sums' sums): zeroed over the receiver rectangle */
    /* optional hooks: after a group's lattice is sampled, and instead of the P1 line walk */
    void (*group)(hf_sweep *sw, struct hf_fused *ctx);
    void (*orient)(hf_sweep *sw, int m, struct hf_fused *ctx);
} hf_fused;

static hfvis_status hf_direction_range(const hfvis_sweep_options *o, int K, int *begin, int *end)
{
    if (o->direction_begin == 0 && o->direction_end == 0) {
        *begin = 0;
        *end = K;
        return HFVIS_OK;
    }
    if (o->direction_begin >= o->direction_end || o->direction_end > K) return HFVIS_ERR_INVALID_ARGUMENT;
    *begin = o->direction_begin;
    *end = o->direction_end;
    return HFVIS_OK;
}

#define HF_STRANDED_MAX_CH 16 /* channels of a consumer the stranded pass serves (env maps: 1-4) */

/* The fused consumers' stranded receivers (hf_stranded_tan): a grid point whose gather found no
 * finite node holds NaN in sw->gacc. Its sum over the directions [begin, end) is made again
 * from the march, direction by direction, through the consumer's own line function on a
 * one-node lattice whose normal is the grid normal (one-sided beside holes). A consumer
 * without a line function (its own orientation hook) keeps NaN there. */
static void hf_fused_stranded(hf_sweep *sw, int K, const hfvis_sweep_options *o, int begin, int end,
                              hf_line_fn fn, hf_fused *ctx)
{
    const hfvis_grid *g = sw->g;
    const int ch = sw->channels;
    double *lat = sw->lat, one[HF_STRANDED_MAX_CH];
    float *nrm = sw->nrm, n1[3];
    int x, y, c, k;
    if (!fn || ch > HF_STRANDED_MAX_CH) return;
    for (y = sw->ry0; y < sw->ry1; y++)
        for (x = sw->rx0; x < sw->rx1; x++) {
            double *acc = sw->gacc + ((size_t)y * (size_t)g->width + (size_t)x) * (size_t)ch, nd[3];
            int stranded = 0;
            for (c = 0; c < ch; c++) stranded |= isnan(acc[c]);
            if (!stranded || hf_is_hole(g, x, y)) continue; /* the NaN test first: it rules out most */
            hf_normal_at(g, x, y, nd);
            n1[0] = (float)nd[0];
            n1[1] = (float)nd[1];
            n1[2] = (float)nd[2];
            for (c = 0; c < ch; c++) one[c] = 0.0;
            sw->lat = one;
            sw->nrm = n1;
            for (k = 0; k < K; k++) {
                int pos = hf_direction_position(o, K, k);
                double ux, uy, t;
                if (pos < begin || pos >= end) continue;
                hf_sweep_vector(o->azimuth0_rad + 2.0 * HFVIS__PI * (double)k / (double)K, &ux, &uy);
                ctx->K = K;
                ctx->k = k;
                ctx->lx = -ux;
                ctx->ly = -uy;
                t = hf_stranded_tan(sw, x, y, -ux, -uy);
                fn(sw, ctx, 0, 0, 1, 1, &t);
            }
            sw->lat = lat;
            sw->nrm = nrm;
            for (c = 0; c < ch; c++) acc[c] = one[c];
        }
}

/* The fused pipeline of [P1] §7 ("lighting computed in lattice space ... fused"): for each
 * group, sample the lattice once, run the quarter turns in [begin, end), accumulate the
 * consumer's per-node term in the lattice accumulator, gather it once into sw->gacc.
 * On HFVIS_OK the caller reads sw->gacc and calls hf_sweep_free. */
static hfvis_status hf_fused_run(hf_sweep *sw, const hfvis_grid *grid, int K,
                                 const hfvis_sweep_options *o, int channels, int want_normals,
                                 hf_line_fn fn, hf_fused *ctx)
{
    hfvis_status s;
    int begin, end, per, groups, gidx, m, done = 0;
    if ((s = hf_direction_range(o, K, &begin, &end)) != HFVIS_OK) return s;
    if ((s = hf_sweep_alloc_extra(sw, grid, o, want_normals, channels, !ctx->gacc_out, ctx->extra_size)) != HFVIS_OK)
        return s;
    if (ctx->gacc_out) { /* the caller's array: the receiver rectangle's values start at 0 */
        int y;
        sw->gacc = ctx->gacc_out;
        for (y = sw->ry0; y < sw->ry1; y++)
            memset(sw->gacc + ((size_t)y * (size_t)grid->width + (size_t)sw->rx0) * (size_t)channels, 0,
                   (size_t)(sw->rx1 - sw->rx0) * (size_t)channels * sizeof(double));
    }
    per = K % 4 == 0 ? 4 : 1;
    groups = K / per;
    for (gidx = 0; gidx < groups; gidx++) {
        double ux, uy;
        int m0, any = 0;
        for (m = 0; m < per; m++) {
            int pos = hf_direction_position(o, K, gidx + m * groups);
            any |= pos >= begin && pos < end;
        }
        if (!any) continue;
        hf_direction_base(K, gidx, o->azimuth0_rad, &ux, &uy, &m0);
        hf_sweep_group(sw, ux, uy);
        hf_lattice_zero(sw);
        if (ctx->group) ctx->group(sw, ctx);
        for (m = 0; m < per; m++) {
            int k = gidx + m * groups, pos = hf_direction_position(o, K, k);
            if (pos < begin || pos >= end) continue;
            ctx->K = K;
            ctx->k = k;
            hf_look_dir(sw, m, &ctx->lx, &ctx->ly);
            if (ctx->orient) ctx->orient(sw, m, ctx);
            else {
                const double sky[4] = {ctx->lx, ctx->ly, ctx->inv_k, ctx->lobe};
                hf_sweep_orientation(sw, m, 0, fn, ctx, ctx->walk, sky);
            }
            hf_progress(o, ++done, end - begin);
        }
        hf_gather_accumulate(sw);
    }
    hf_fused_stranded(sw, K, o, begin, end, fn, ctx);
    return HFVIS_OK;
}

/* Write the grid accumulator times scale to out (holes NaN). */
static void hf_fused_output(const hf_sweep *sw, double scale, double offset, float *out,
                            ptrdiff_t out_stride, int channels)
{
    const hfvis_grid *g = sw->g;
    int x, y, c;
    for (y = sw->ry0; y < sw->ry1; y++) /* the receiver rectangle; the rest is left unwritten */
        for (x = sw->rx0; x < sw->rx1; x++) {
            const double *a = sw->gacc + ((size_t)y * (size_t)g->width + (size_t)x) * (size_t)channels;
            float *o = out + ((ptrdiff_t)y * out_stride + x) * channels;
            int hole = hf_is_hole(g, x, y);
            for (c = 0; c < channels; c++) o[c] = (float)(hole ? HFVIS__NAN : offset + scale * a[c]);
        }
}

/* The fused sky light's consumer: [P1] Eq. 5 per direction (hf_sky_term), inside the line
 * walk; hf_sky_line is the same sum over a line's stored tangents (windowed and oracle paths). */
static void hf_sky_setup(hf_fused *f, int K)
{
    f->walk = HF_WALK_SKY;
    f->inv_k = 1.0 / (double)K;
    f->lobe = sin(HFVIS__PI / (double)K) / HFVIS__PI;
}

static void hf_sky_line(hf_sweep *sw, void *vctx, int m, ptrdiff_t node0, ptrdiff_t step, int n,
                        const double *t)
{
    const hf_fused *c = (const hf_fused *)vctx;
    /* in locals: the store to lat could alias the context, so gcc reloaded them at every node */
    const double sky[4] = {c->lx, c->ly, c->inv_k, c->lobe};
    const float *nrm = sw->nrm;
    double *lat = sw->lat;
    int s;
    (void)m;
    for (s = 0; s < n; s++, node0 += step)
        if (!isnan(t[s])) hf_walk_emit(HF_WALK_SKY, lat, nrm, sky, NULL, s, node0, t[s]);
}

static int hf_light_args_valid(const hfvis_grid *grid, int K, const hfvis_sweep_options *opts,
                               const void *out, ptrdiff_t out_stride)
{
    return hf_check_common(grid, opts) == HFVIS_OK && out && K >= 1 && out_stride >= grid->width &&
           hfvis__plane_fits(out_stride, grid->height, 4);
}

hfvis_status hfvis_sky_light(const hfvis_grid *grid, int K, float sky, float albedo,
                             const hfvis_sweep_options *opts, float *out, ptrdiff_t out_stride)
{
    hfvis_sweep_options o;
    hf_sweep sw;
    hf_fused ctx;
    hfvis_status s;
    if (!hf_light_args_valid(grid, K, opts, out, out_stride) || !isfinite(sky) || !isfinite(albedo))
        return HFVIS_ERR_INVALID_ARGUMENT;
    o = hf_opts_resolve(grid, opts);
    if (o.rays == HFVIS_RAYS_EXACT)
        return hf_exact_light(grid, K, HFVIS_SUM_SKY_LIGHT, NULL, NULL, &o,
                              (double)sky * (double)albedo, out, out_stride);
    memset(&ctx, 0, sizeof ctx);
    hf_sky_setup(&ctx, K);
    if ((s = hf_fused_run(&sw, grid, K, &o, 1, 1, hf_sky_line, &ctx)) != HFVIS_OK) return s;
    hf_fused_output(&sw, (double)sky * (double)albedo, 0.0, out, out_stride, 1);
    hf_sweep_free(&sw);
    return HFVIS_OK;
}

static int hf_map_args_valid(const hfvis_grid *grid, int K, const float *map, const void *out,
                             ptrdiff_t out_stride)
{
    size_t total;
    return hf_grid_valid(grid) && K >= 1 && map && out && out_stride >= grid->width &&
           hfvis__plane_fits(out_stride, grid->height, 4) && hfvis__mul_size(hf_grid_count(grid), (size_t)K, &total);
}

/* tan of a stored elevation; -pi/2 (or below) means no occluder. */
static double hf_elevation_to_tan(double alpha)
{
    if (isnan(alpha)) return HFVIS__NAN;
    if (alpha <= -HFVIS__HALF_PI) return -HFVIS__INF;
    if (alpha >= HFVIS__HALF_PI) return HFVIS__INF;
    return tan(alpha);
}

hfvis_status hfvis_sky_light_from_map(const hfvis_grid *grid, int K, double map_azimuth0_rad,
                                      const float *map, float sky, float albedo,
                                      const hfvis_allocator *alloc, float *out,
                                      ptrdiff_t out_stride)
{
    double *dirs, inv_k, lobe;
    size_t plane;
    int x, y, k;
    if (!hf_map_args_valid(grid, K, map, out, out_stride) || !isfinite(map_azimuth0_rad) ||
        !isfinite(sky) || !isfinite(albedo))
        return HFVIS_ERR_INVALID_ARGUMENT;
    dirs = (double *)hfvis__alloc_array(alloc, (size_t)K, 2 * sizeof(double));
    if (!dirs) return HFVIS_ERR_OUT_OF_MEMORY;
    for (k = 0; k < K; k++) {
        double psi = map_azimuth0_rad + 2.0 * HFVIS__PI * (double)k / (double)K;
        dirs[2 * k] = cos(psi);
        dirs[2 * k + 1] = sin(psi);
    }
    plane = hf_grid_count(grid);
    inv_k = 1.0 / (double)K;
    lobe = sin(HFVIS__PI / (double)K) / HFVIS__PI;
    for (y = 0; y < grid->height; y++)
        for (x = 0; x < grid->width; x++) {
            size_t idx = (size_t)y * (size_t)grid->width + (size_t)x;
            double n[3], sum = 0.0;
            hf_normal_at(grid, x, y, n);
            for (k = 0; k < K && !isnan(sum); k++) {
                double t = hf_elevation_to_tan((double)map[(size_t)k * plane + idx]);
                sum += hf_sky_term(t, n[2], n[0] * dirs[2 * k] + n[1] * dirs[2 * k + 1], inv_k, lobe);
            }
            out[(ptrdiff_t)y * out_stride + x] = (float)((double)sky * (double)albedo * sum);
        }
    hfvis__free(alloc, dirs);
    return HFVIS_OK;
}

/* sin(atan(t)) for t >= 0 (or NaN) without overflow: t/sqrt(1 + t^2), or past the square's range
 * (heights over tiny cells) 1/sqrt(1 + (1/t)^2). */
static inline double hf_tan_sine_nonneg(double t)
{
    if (t > HF_SLOPE_SQUARE_MAX) {
        double r = 1.0 / t;
        return 1.0 / sqrt(1.0 + r * r);
    }
    return t / sqrt(1.0 + t * t);
}

/* sin(atan(t)) of any sign: odd, and both forms are exact under negation (the same bits as
 * computing with t's own sign). */
static inline double hf_tan_sine(double t)
{
    return t < 0.0 ? -hf_tan_sine_nonneg(-t) : hf_tan_sine_nonneg(t);
}

/* Sky-view factor term per direction: sin(max(alpha, 0)) = hf_tan_sine(t) for t > 0, else 0
 * (the sweeps' hot loops call it: no sign handling). */
static inline double hf_svf_term(double t)
{
    if (!(t > 0.0)) return 0.0;
    return hf_tan_sine_nonneg(t);
}

static void hf_svf_line(hf_sweep *sw, void *vctx, int m, ptrdiff_t node0, ptrdiff_t step, int n,
                        const double *t)
{
    int s;
    (void)vctx;
    (void)m;
    for (s = 0; s < n; s++, node0 += step)
        if (!isnan(t[s])) hf_walk_emit(HF_WALK_SVF, sw->lat, NULL, NULL, NULL, s, node0, t[s]);
}

hfvis_status hfvis_sky_view_factor(const hfvis_grid *grid, int K, const hfvis_sweep_options *opts,
                                   float *out, ptrdiff_t out_stride)
{
    hfvis_sweep_options o;
    hf_sweep sw;
    hf_fused ctx;
    hfvis_status s;
    int begin, end;
    if (!hf_light_args_valid(grid, K, opts, out, out_stride)) return HFVIS_ERR_INVALID_ARGUMENT;
    o = hf_opts_resolve(grid, opts);
    if (o.rays == HFVIS_RAYS_EXACT)
        return hf_exact_light(grid, K, HFVIS_SUM_SKY_VIEW, NULL, NULL, &o, -1.0 / (double)K, out,
                              out_stride);
    memset(&ctx, 0, sizeof ctx);
    ctx.walk = HF_WALK_SVF;
    if ((s = hf_direction_range(&o, K, &begin, &end)) != HFVIS_OK) return s;
    if ((s = hf_fused_run(&sw, grid, K, &o, 1, 0, hf_svf_line, &ctx)) != HFVIS_OK) return s;
    /* A partial range returns its share of 1 - (1/K) sum, so partial results add up to SVF. */
    hf_fused_output(&sw, -1.0 / (double)K, (double)(end - begin) / (double)K, out, out_stride, 1);
    hf_sweep_free(&sw);
    return HFVIS_OK;
}

hfvis_status hfvis_sky_view_factor_from_map(const hfvis_grid *grid, int K, const float *map,
                                            float *out, ptrdiff_t out_stride)
{
    size_t plane;
    int x, y, k;
    if (!hf_map_args_valid(grid, K, map, out, out_stride)) return HFVIS_ERR_INVALID_ARGUMENT;
    plane = hf_grid_count(grid);
    for (y = 0; y < grid->height; y++)
        for (x = 0; x < grid->width; x++) {
            size_t idx = (size_t)y * (size_t)grid->width + (size_t)x;
            double sum = 0.0;
            if (hf_is_hole(grid, x, y)) sum = HFVIS__NAN;
            for (k = 0; k < K; k++) {
                double a = (double)map[(size_t)k * plane + idx];
                sum += a > 0.0 ? sin(a) : (isnan(a) ? HFVIS__NAN : 0.0);
            }
            out[(ptrdiff_t)y * out_stride + x] = (float)(1.0 - sum / (double)K);
        }
    return HFVIS_OK;
}

/* Visible fraction of a sun disc of angular radius r centred at elevation e above a horizon
 * line at elevation alpha: the circular-segment area, 1 - (acos d - d sqrt(1 - d^2))/pi,
 * d = (e - alpha)/r clamped to [-1, 1] (the horizon is taken straight across the small disc). */
static double hf_sun_fraction(double e, double r, double alpha)
{
    double d;
    if (isnan(alpha)) return HFVIS__NAN;
    if (r <= 0.0) return e > alpha ? 1.0 : 0.0;
    d = hf_clampd((e - alpha) / r, -1.0, 1.0);
    return 1.0 - (acos(d) - d * sqrt(1.0 - d * d)) / HFVIS__PI;
}

hfvis_status hfvis_sun_visibility(const hfvis_grid *grid, double sun_azimuth_rad,
                                  double sun_elevation_rad, double sun_radius_rad,
                                  const hfvis_sweep_options *opts, float *out, ptrdiff_t out_stride)
{
    hfvis_sweep_options o, whole;
    hf_sweep sw;
    hfvis_status s;
    double ux, uy;
    int x, y, m0 = 0;
    if (opts) { /* the bands are this call's own: checked here, refused elsewhere */
        whole = *opts;
        if (!hf_parts_valid(opts)) return HFVIS_ERR_INVALID_ARGUMENT;
        whole.part_index = whole.part_count = 0;
    }
    if (hf_check_common(grid, opts ? &whole : NULL) != HFVIS_OK || !out || out_stride < grid->width ||
        !hfvis__plane_fits(out_stride, grid->height, 4) || !isfinite(sun_azimuth_rad) || !isfinite(sun_elevation_rad) || !isfinite(sun_radius_rad) ||
        sun_radius_rad < 0.0 || sun_elevation_rad < -HFVIS__HALF_PI || sun_elevation_rad > HFVIS__HALF_PI)
        return HFVIS_ERR_INVALID_ARGUMENT;
    o = hf_opts_resolve(grid, opts);
    if (o.rays == HFVIS_RAYS_EXACT)
        return hf_exact_sun(grid, sun_azimuth_rad, sun_elevation_rad, sun_radius_rad, &o, out,
                            out_stride);
    if ((s = hf_sweep_alloc(&sw, grid, &o, 0, 1, 0)) != HFVIS_OK) return s;
    hf_sweep_vector(sun_azimuth_rad, &ux, &uy);
    hf_sweep_parts(&sw, &o);
    hf_sweep_group(&sw, ux, uy);
    hf_lattice_fill(&sw, HFVIS__NAN);
    hf_sweep_orientation(&sw, 0, 0, hf_store_elevation, NULL, HF_WALK_STORE, NULL);
    hf_gather_planes(&sw, 1, &m0, &out, out_stride);
    for (y = sw.ry0; y < sw.ry1; y++) {
        int x0, x1;
        hf_sweep_span(&sw, y, &x0, &x1); /* the band's receivers of the row */
        for (x = x0; x < x1; x++) {
            float *p = out + (ptrdiff_t)y * out_stride + x;
            *p = (float)hf_sun_fraction(sun_elevation_rad, sun_radius_rad, (double)*p);
        }
    }
    hf_sweep_free(&sw);
    hf_progress(&o, 1, 1);
    return HFVIS_OK;
}

/* ==========================================================================================
 * 10. Environment light tables and evaluation, the hemisphere-integration oracle
 * [P1] §6 Eq. 3-7; docs/errata.md E3, E9.

 *
 * Contents
 *   1. constants, argument resolution
 *   2. sector phi-integrals of the lat-long texels, band theta-weights
 *   3. table layouts and hfvis_env_table_floats / hfvis_env_table_build
 *   4. hf_env_eval: per node and direction evaluation (the fused sweep calls this)
 *   5. hfvis_env_light_from_map
 *   6. hfvis_light_reference (hemisphere-integration oracle)
 *
 * Table layouts (floats; C = env->channels, T = env->n_theta, K directions):
 *   HFVIS_ENV_PREFIX: 6*K*(T+1)*C floats. Record (k, b), b = 0..T, is 6*C floats at
 *     table[((k*(T+1) + b)*6 + q)*C + c], q = 0..5:
 *       q = 0,1,2: A_k, B_k, C_k of [P1] Eq. 6-7; docs/errata.md E9 at the band edge theta_b = b*pi/T (prefix over
 *                  bands 0..b-1; record 0 is zero, record T is the whole sphere);
 *       q = 3,4,5: the sector phi-integrals of band b, Int_sector L dphi,
 *                  Int_sector L cos(phi-psi_k) dphi, Int_sector L sin(phi-psi_k) dphi
 *                  (zero in record T), so that inside band b
 *                  A_k(theta) = A_k(theta_b) + [q3] * (sin^2 theta - sin^2 theta_b)/2,
 *                  B_k(theta) = B_k(theta_b) + [q4] * (G(theta) - G(theta_b)), G = (theta - sin 2theta/2)/2,
 *                  C_k likewise with [q5].
 *     Everything is accumulated in double and rounded to float once at the store (relative
 *     error ~6e-8 per entry; the prefix is not split into hi/lo floats: the sums stay O(1) per
 *     sector and the evaluator's double arithmetic adds no further error of that size).
 *   HFVIS_ENV_LP_TABLE: K*M*Th*C floats, M = lp_normal_res (odd), Th = lp_horizon_res,
 *     table[((k*M + i)*Th + j)*C + c] = L_p^k(theta_n_i, theta_h_j),
 *     theta_n_i = pi*(i/(M-1) - 1/2) in [-pi/2, pi/2] (i = (M-1)/2 is exactly 0),
 *     theta_h_j = pi*j/(Th-1) in [0, pi] (docs/errata.md E9). Already includes 1/pi.
 * ========================================================================================== */

/* ---------------------------------------------------------------- 1. constants, resolution */


/* Defaults of hfvis_env_options ([P1] §6.2: theta_n resolution 16 is "safe", odd counts make
 * N = up exact; theta_h resolution = the paper's theta_N = 256). */
#define HF_ENV_DEFAULT_LP_NORMAL_RES 15
#define HF_ENV_DEFAULT_LP_HORIZON_RES 257
/* Hemisphere oracle defaults (header). */
#define HF_ENV_DEFAULT_AZIMUTH_SAMPLES 256
#define HF_ENV_DEFAULT_ZENITH_SAMPLES 512
/* Floats per (sector, band edge) record of the prefix table. */
#define HF_ENV_PREFIX_RECORD 6

hfvis_env_options hfvis_env_options_default(void)
{
    hfvis_env_options o;
    o.method = HFVIS_ENV_PREFIX;
    o.lp_normal_res = HF_ENV_DEFAULT_LP_NORMAL_RES;
    o.lp_horizon_res = HF_ENV_DEFAULT_LP_HORIZON_RES;
    return o;
}

/* Resolved options and the table size. */
typedef struct hf_env_resolved {
    hfvis_env_method method;
    int lp_normal_res, lp_horizon_res;
    size_t table_floats;
} hf_env_resolved;

/* Checks the environment's shape (not its radiance pointer: hfvis_env_table_floats can be asked
 * before the map is loaded), K and the options; resolves defaults and the table size.
 * lp_normal_res must be odd and >= 3 (M = 1 leaves no theta_n interval to interpolate). */
/* The radiance array (n_theta*n_phi*channels floats) must be addressable: a size that
 * overflows size_t describes no array (env fields already checked >= 1). */
static int hf_env_size_ok(const hfvis_env *env)
{
    size_t n, bytes;
    return hfvis__mul_size((size_t)env->n_theta, (size_t)env->n_phi, &n) &&
           hfvis__mul_size(n, (size_t)env->channels, &n) && hfvis__mul_size(n, sizeof(float), &bytes);
}

static hfvis_status hf_env_resolve(const hfvis_env *env, int K, const hfvis_env_options *eopts,
                                   hf_env_resolved *r)
{
    hfvis_env_options o;
    size_t n, bytes;
    if (env == NULL || K < 1 || env->n_theta < 1 || env->n_phi < 1 || env->channels < 1 ||
        env->channels > 4 || !hf_env_size_ok(env))
        return HFVIS_ERR_INVALID_ARGUMENT;
    o = hfvis_env_options_default();
    if (eopts != NULL) {
        if (eopts->method != HFVIS_ENV_DEFAULT) o.method = eopts->method;
        if (eopts->lp_normal_res != 0) o.lp_normal_res = eopts->lp_normal_res;
        if (eopts->lp_horizon_res != 0) o.lp_horizon_res = eopts->lp_horizon_res;
    }
    if (o.method != HFVIS_ENV_PREFIX && o.method != HFVIS_ENV_LP_TABLE)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.method == HFVIS_ENV_LP_TABLE) {
        /* the L_p resolutions are validated only when the L_p table is used */
        if (o.lp_normal_res < 3 || o.lp_normal_res % 2 == 0 || o.lp_horizon_res < 2)
            return HFVIS_ERR_INVALID_ARGUMENT;
        if (!hfvis__mul_size((size_t)K, (size_t)o.lp_normal_res, &n) ||
            !hfvis__mul_size(n, (size_t)o.lp_horizon_res, &n) ||
            !hfvis__mul_size(n, (size_t)env->channels, &n))
            return HFVIS_ERR_INVALID_ARGUMENT;
    } else {
        if (!hfvis__mul_size((size_t)K, (size_t)env->n_theta + 1u, &n) ||
            !hfvis__mul_size(n, (size_t)HF_ENV_PREFIX_RECORD * (size_t)env->channels, &n))
            return HFVIS_ERR_INVALID_ARGUMENT;
    }
    /* every table index is later formed in size_t; bytes must be representable too */
    if (!hfvis__mul_size(n, sizeof(float), &bytes)) return HFVIS_ERR_INVALID_ARGUMENT;
    r->method = o.method;
    r->lp_normal_res = o.lp_normal_res;
    r->lp_horizon_res = o.lp_horizon_res;
    r->table_floats = n;
    return HFVIS_OK;
}

size_t hfvis_env_table_floats(const hfvis_env *env, int K, const hfvis_env_options *eopts)
{
    hf_env_resolved r;
    if (hf_env_resolve(env, K, eopts, &r) != HFVIS_OK) return 0;
    return r.table_floats;
}

/* ------------------------------------ 2. sector phi-integrals, band theta-weights ([P1] Eq. 6-7; docs/errata.md E9) */

/* The sector [psi_k - pi/K, psi_k + pi/K] as an unwrapped interval [start, start + width]
 * with start reduced to [0, 2pi); the centre start + pi/K is psi_k modulo 2pi. */
typedef struct hf_env_sector {
    double start, width, centre;
} hf_env_sector;

static hf_env_sector hf_env_sector_of(int K, double azimuth0_rad, int k)
{
    hf_env_sector s;
    double psi = azimuth0_rad + (2.0 * HFVIS__PI) * (double)k / (double)K;
    double st = fmod(psi - HFVIS__PI / (double)K, (2.0 * HFVIS__PI));
    if (st < 0.0) st += (2.0 * HFVIS__PI);
    if (st >= (2.0 * HFVIS__PI)) st = 0.0; /* -tiny + 2pi may round up to 2pi */
    s.start = st;
    s.width = (2.0 * HFVIS__PI) / (double)K;
    s.centre = st + HFVIS__PI / (double)K;
    return s;
}

/* Sector phi-integrals of texel row t ([P1] Eq. 6-7; docs/errata.md E9 "inner phi-integrals ... closed-form"):
 * a0[c] = Int L dphi, a1[c] = Int L cos(phi - psi) dphi, a2[c] = Int L sin(phi - psi) dphi
 * over the sector, the texels being constant. Columns are visited as unwrapped intervals
 * [2pi p'/P, 2pi (p'+1)/P) with p' from just below the sector start up to 2P, column p' mod P,
 * so a sector that wraps past 2pi, or is narrower or wider than a column, is covered exactly.
 * a2 may be NULL (the L_p table drops the C term, [P1] Eq. 6-7; docs/errata.md E9). */
static void hf_env_band_sector(const hfvis_env *env, int t, const hf_env_sector *s, double *a0,
                               double *a1, double *a2)
{
    const int P = env->n_phi, C = env->channels;
    const double end = s->start + s->width;
    const float *row = env->radiance + (size_t)t * (size_t)P * (size_t)C;
    int p = (int)floor(s->start * (double)P / (2.0 * HFVIS__PI)) - 1, c;
    for (c = 0; c < C; c++) {
        a0[c] = 0.0;
        a1[c] = 0.0;
        if (a2 != NULL) a2[c] = 0.0;
    }
    for (;; p++) {
        double lo = (2.0 * HFVIS__PI) * (double)p / (double)P;
        double hi = (2.0 * HFVIS__PI) * (double)(p + 1) / (double)P;
        double f1, f2, len, wc, ws;
        const float *px;
        if (lo >= end) break;
        f1 = lo > s->start ? lo : s->start;
        f2 = hi < end ? hi : end;
        if (!(f2 > f1)) continue;
        len = f2 - f1;
        /* Int cos(phi - psi) = sin(u2) - sin(u1), Int sin(phi - psi) = cos(u1) - cos(u2),
         * u relative to the sector centre so |u| <= pi/K */
        wc = sin(f2 - s->centre) - sin(f1 - s->centre);
        ws = cos(f1 - s->centre) - cos(f2 - s->centre);
        px = row + (size_t)(((p % P) + P) % P) * (size_t)C;
        for (c = 0; c < C; c++) {
            double L = (double)px[c];
            a0[c] += L * len;
            a1[c] += L * wc;
            if (a2 != NULL) a2[c] += L * ws;
        }
    }
}

/* Theta-weights between theta0 and theta (docs/errata.md E3 antiderivatives):
 * *wa = Int sin cos = (sin^2 theta - sin^2 theta0)/2 = sin(d) sin(s)/2,
 * *wb = Int sin^2   = (d - (sin 2theta - sin 2theta0)/2)/2 = (d - cos(s) sin(d))/2,
 * d = theta - theta0, s = theta + theta0 (difference forms: no cancellation inside a band). */
static void hf_env_theta_weights(double theta, double theta0, double *wa, double *wb)
{
    double d = theta - theta0, s = theta + theta0, sd = sin(d);
    *wa = 0.5 * sd * sin(s);
    *wb = 0.5 * (d - cos(s) * sd);
}

/* Band edge theta_b = b*pi/T; the build and the evaluator must use this same expression. */
static double hf_env_band_edge(int b, int T)
{
    return HFVIS__PI * (double)b / (double)T;
}

/* ---------------------------------------------------------- 3. hfvis_env_table_build */

/* Running prefix A_k, B_k (and C_k) over the bands, for the L_p build: evaluated at
 * non-decreasing cutoffs theta in [0, pi] ([P1] Eq. 6-7; docs/errata.md E9 prefix form, band-partial exact). */
typedef struct hf_env_prefix_walk {
    const hfvis_env *env;
    hf_env_sector sector;
    int band;                 /* current band t */
    double pa[4], pb[4];      /* A_k, B_k at theta_t */
    double a0[4], a1[4];      /* phi-integrals of band t */
} hf_env_prefix_walk;

static void hf_env_walk_start(hf_env_prefix_walk *w, const hfvis_env *env,
                              const hf_env_sector *s)
{
    int c;
    w->env = env;
    w->sector = *s;
    w->band = 0;
    for (c = 0; c < 4; c++) w->pa[c] = w->pb[c] = 0.0;
    hf_env_band_sector(env, 0, s, w->a0, w->a1, NULL);
}

/* A_k(theta), B_k(theta) into A[c], B[c]; theta must not decrease between calls. */
static void hf_env_walk_eval(hf_env_prefix_walk *w, double theta, double *A, double *B)
{
    const int T = w->env->n_theta, C = w->env->channels;
    double wa, wb;
    int c;
    while (w->band < T - 1 && theta >= hf_env_band_edge(w->band + 1, T)) {
        hf_env_theta_weights(hf_env_band_edge(w->band + 1, T), hf_env_band_edge(w->band, T),
                             &wa, &wb);
        for (c = 0; c < C; c++) {
            w->pa[c] += w->a0[c] * wa;
            w->pb[c] += w->a1[c] * wb;
        }
        w->band++;
        hf_env_band_sector(w->env, w->band, &w->sector, w->a0, w->a1, NULL);
    }
    hf_env_theta_weights(theta, hf_env_band_edge(w->band, T), &wa, &wb);
    for (c = 0; c < C; c++) {
        A[c] = w->pa[c] + w->a0[c] * wa;
        B[c] = w->pb[c] + w->a1[c] * wb;
    }
}

/* L_p axes (docs/errata.md E9); the build and the evaluator use these expressions. */
static double hf_env_lp_normal_angle(int i, int M)
{
    return HFVIS__PI * ((double)i / (double)(M - 1) - 0.5);
}
static double hf_env_lp_horizon_angle(int j, int Th)
{
    return HFVIS__PI * (double)j / (double)(Th - 1);
}
/* Eq. 7 upper limit theta_n + pi/2, clamped to [0, pi] against rounding at i = 0 and M-1. */
static double hf_env_lp_cutoff(int i, int M)
{
    double c = hf_env_lp_normal_angle(i, M) + HFVIS__HALF_PI;
    return c < 0.0 ? 0.0 : (c > HFVIS__PI ? HFVIS__PI : c);
}

/* L_p table of one direction ([P1] Eq. 6-7, Eq. 7 in its Eq. 5-consistent form; docs/errata.md E9):
 * L_p(theta_n, theta_h) = (1/pi)[cos theta_n A_k(c) + sin theta_n B_k(c)],
 * c = min(theta_h, theta_n + pi/2). Entries with theta_h_j < theta_n_i + pi/2 need A, B at
 * theta_h_j (shared by all i): one walk over j. The others need A, B at theta_n_i + pi/2
 * (shared by all j): a second walk over i. Both walks are O(T * columns + Th + M). */
static void hf_env_build_lp_direction(const hfvis_env *env, const hf_env_sector *s, int M,
                                      int Th, float *tab)
{
    const int C = env->channels;
    hf_env_prefix_walk w;
    double A[4], B[4];
    int i, j, c;
    hf_env_walk_start(&w, env, s);
    for (j = 0; j < Th; j++) {
        double th = hf_env_lp_horizon_angle(j, Th);
        hf_env_walk_eval(&w, th, A, B);
        for (i = 0; i < M; i++) {
            double tn = hf_env_lp_normal_angle(i, M), cn = cos(tn), sn = sin(tn);
            float *e;
            if (!(th < hf_env_lp_cutoff(i, M))) continue; /* second walk */
            e = tab + ((size_t)i * (size_t)Th + (size_t)j) * (size_t)C;
            for (c = 0; c < C; c++) e[c] = (float)((cn * A[c] + sn * B[c]) / HFVIS__PI);
        }
    }
    hf_env_walk_start(&w, env, s);
    for (i = 0; i < M; i++) {
        double tn = hf_env_lp_normal_angle(i, M), cn = cos(tn), sn = sin(tn);
        double cut = hf_env_lp_cutoff(i, M);
        hf_env_walk_eval(&w, cut, A, B);
        for (j = 0; j < Th; j++) {
            float *e;
            if (hf_env_lp_horizon_angle(j, Th) < cut) continue; /* first walk */
            e = tab + ((size_t)i * (size_t)Th + (size_t)j) * (size_t)C;
            for (c = 0; c < C; c++) e[c] = (float)((cn * A[c] + sn * B[c]) / HFVIS__PI);
        }
    }
}

/* Prefix records of one direction (layout at the top of this fragment). */
static void hf_env_build_prefix_direction(const hfvis_env *env, const hf_env_sector *s,
                                          float *tab)
{
    const int T = env->n_theta, C = env->channels;
    double pa[4] = {0.0, 0.0, 0.0, 0.0}, pb[4] = {0.0, 0.0, 0.0, 0.0},
           pc[4] = {0.0, 0.0, 0.0, 0.0};
    double a0[4], a1[4], a2[4], wa, wb;
    int t, c;
    for (t = 0; t <= T; t++) {
        float *rec = tab + (size_t)t * HF_ENV_PREFIX_RECORD * (size_t)C;
        if (t < T) {
            hf_env_band_sector(env, t, s, a0, a1, a2);
        } else {
            for (c = 0; c < C; c++) a0[c] = a1[c] = a2[c] = 0.0;
        }
        for (c = 0; c < C; c++) {
            rec[0 * C + c] = (float)pa[c];
            rec[1 * C + c] = (float)pb[c];
            rec[2 * C + c] = (float)pc[c];
            rec[3 * C + c] = (float)a0[c];
            rec[4 * C + c] = (float)a1[c];
            rec[5 * C + c] = (float)a2[c];
        }
        if (t == T) break;
        /* the prefix runs in double; only the stored copy is rounded */
        hf_env_theta_weights(hf_env_band_edge(t + 1, T), hf_env_band_edge(t, T), &wa, &wb);
        for (c = 0; c < C; c++) {
            pa[c] += a0[c] * wa;
            pb[c] += a1[c] * wb;
            pc[c] += a2[c] * wb;
        }
    }
}

/* Radiance values are not validated: a non-finite texel propagates into the sectors it
 * overlaps. Cost: prefix O(K*T*(P/K + 2)*C); L_p O(K*(T*(P/K + 2) + M*Th)*C), i.e. cheaper
 * than the header's O(K*M*Th*P) since A_k, B_k at the Th + M sorted cutoffs come from two
 * monotone walks over the bands. No allocation. */
hfvis_status hfvis_env_table_build(const hfvis_env *env, int K, double azimuth0_rad,
                                             const hfvis_env_options *eopts, float *table)
{
    hf_env_resolved r;
    hfvis_status st = hf_env_resolve(env, K, eopts, &r);
    int k;
    if (st != HFVIS_OK) return st;
    if (env->radiance == NULL || table == NULL || !isfinite(azimuth0_rad))
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (k = 0; k < K; k++) {
        hf_env_sector s = hf_env_sector_of(K, azimuth0_rad, k);
        if (r.method == HFVIS_ENV_LP_TABLE) {
            size_t per = (size_t)r.lp_normal_res * (size_t)r.lp_horizon_res *
                         (size_t)env->channels;
            hf_env_build_lp_direction(env, &s, r.lp_normal_res, r.lp_horizon_res,
                                      table + (size_t)k * per);
        } else {
            size_t per = ((size_t)env->n_theta + 1u) * HF_ENV_PREFIX_RECORD *
                         (size_t)env->channels;
            hf_env_build_prefix_direction(env, &s, table + (size_t)k * per);
        }
    }
    return HFVIS_OK;
}

/* ------------------------------------------------------------ 4. per-node evaluation */

typedef struct hf_env_eval {
    const hfvis_env *env;
    hfvis_env_method method;
    int K;
    int channels;
    int lp_normal_res, lp_horizon_res;
    const float *table;
} hf_env_eval;

/* Validate and resolve defaults; table must have been built by hfvis_env_table_build with
 * the same env, K and eopts. env->radiance is not read by the evaluator. */
static hfvis_status hf_env_eval_init(hf_env_eval *e, const hfvis_env *env, int K,
                                     const hfvis_env_options *eopts, const float *table)
{
    hf_env_resolved r;
    hfvis_status st;
    if (e == NULL || table == NULL) return HFVIS_ERR_INVALID_ARGUMENT;
    st = hf_env_resolve(env, K, eopts, &r);
    if (st != HFVIS_OK) return st;
    e->env = env;
    e->method = r.method;
    e->K = K;
    e->channels = env->channels;
    e->lp_normal_res = r.lp_normal_res;
    e->lp_horizon_res = r.lp_horizon_res;
    e->table = table;
    return HFVIS_OK;
}

/* Adds direction k's contribution (including 1/pi, excluding albedo) to acc[0..channels-1].
 * (cos_psi, sin_psi): look direction psi_k; (nx, ny, nz): unit normal, z up; tan_h: tangent
 * of the horizon elevation, -INFINITY = no occluder, +INFINITY = zenith blocked. A NaN tan_h
 * or normal adds NaN.
 * PREFIX ([P1] Eq. 4 with the clamp of docs/errata.md E3, §5.4 prefix form):
 *   theta = min(theta_h, pi/2 + atan2(a, nz)) clamped to [0, pi], theta_h = pi/2 - atan(tan_h),
 *   acc += (1/pi)[nz A_k(theta) + a B_k(theta) + b C_k(theta)],
 *   a = nx cos psi + ny sin psi, b = -nx sin psi + ny cos psi.
 * LP_TABLE ([P1] Eq. 6): acc += |N_p| L_p^k(theta_n, theta_h), |N_p| = sqrt(a^2 + nz^2),
 *   theta_n = atan2(a, nz) clamped to [-pi/2, pi/2] (height-field normals have nz > 0),
 *   bilinear in (theta_n, theta_h). Because L_p is constant in theta_h beyond theta_n + pi/2
 *   (Eq. 7's upper limit; docs/errata.md E9), a lookup with theta_h >= theta_n + pi/2 is made
 *   at theta_h = pi, an exact table column: an open horizon then carries only the theta_n
 *   interpolation error, and N = up with theta_h >= pi/2 is exact (docs/errata.md E9). */
static void hf_env_accumulate(const hf_env_eval *e, int k, double cos_psi, double sin_psi,
                              double nx, double ny, double nz, double tan_h, double *acc)
{
    const int C = e->channels;
    const double a = nx * cos_psi + ny * sin_psi;
    double theta_h = HFVIS__HALF_PI - hf_atan(tan_h);
    int c;
    if (isnan(theta_h) || isnan(a) || isnan(nz)) {
        for (c = 0; c < C; c++) acc[c] += HFVIS__NAN;
        return;
    }
    if (theta_h < 0.0) theta_h = 0.0;
    if (theta_h > HFVIS__PI) theta_h = HFVIS__PI;
    if (e->method == HFVIS_ENV_LP_TABLE) {
        const int M = e->lp_normal_res, Th = e->lp_horizon_res;
        double np = sqrt(a * a + nz * nz), tn = nz > 0.0 ? hf_atan(a / nz) : atan2(a, nz), fi, fj, u, v;
        int i0, j0;
        const float *t00, *t01, *t10, *t11;
        if (tn < -HFVIS__HALF_PI) tn = -HFVIS__HALF_PI;
        if (tn > HFVIS__HALF_PI) tn = HFVIS__HALF_PI;
        fi = (tn / HFVIS__PI + 0.5) * (double)(M - 1); /* (M-1)/2 exactly for tn = 0 */
        fj = theta_h / HFVIS__PI * (double)(Th - 1);
        i0 = (int)fi;
        if (i0 > M - 2) i0 = M - 2;
        if (i0 < 0) i0 = 0;
        j0 = (int)fj;
        if (j0 > Th - 2) j0 = Th - 2;
        if (j0 < 0) j0 = 0;
        u = fi - (double)i0;
        v = fj - (double)j0;
        t00 = e->table + (((size_t)k * (size_t)M + (size_t)i0) * (size_t)Th + (size_t)j0) *
                             (size_t)C;
        t01 = t00 + C;                        /* (i0, j0+1) */
        t10 = t00 + (size_t)Th * (size_t)C;   /* (i0+1, j0) */
        t11 = t10 + C;
        for (c = 0; c < C; c++) {
            double lo = (1.0 - v) * (double)t00[c] + v * (double)t01[c];
            double hi = (1.0 - v) * (double)t10[c] + v * (double)t11[c];
            acc[c] += np * ((1.0 - u) * lo + u * hi);
        }
    } else {
        const int T = e->env->n_theta;
        const double b = -nx * sin_psi + ny * cos_psi;
        double theta = theta_h, tc = HFVIS__HALF_PI + (nz > 0.0 ? hf_atan(a / nz) : atan2(a, nz)), wa, wb;
        const float *rec;
        int band;
        if (tc < theta) theta = tc;
        if (theta <= 0.0) return; /* every prefix integral is 0 at theta = 0 */
        band = (int)(theta * (double)T / HFVIS__PI);
        if (band > T - 1) band = T - 1;
        hf_env_theta_weights(theta, hf_env_band_edge(band, T), &wa, &wb);
        rec = e->table + ((size_t)k * ((size_t)T + 1u) + (size_t)band) * HF_ENV_PREFIX_RECORD *
                             (size_t)C;
        for (c = 0; c < C; c++) {
            double A = (double)rec[0 * C + c] + (double)rec[3 * C + c] * wa;
            double B = (double)rec[1 * C + c] + (double)rec[4 * C + c] * wb;
            double Cs = (double)rec[2 * C + c] + (double)rec[5 * C + c] * wb;
            acc[c] += (nz * A + a * B + b * Cs) / HFVIS__PI;
        }
    }
}

/* Allocate (1 block from alloc), build and bind the tables of one call; *table receives the
 * block for hfvis__free. For the lead's hfvis_env_light. */
static hfvis_status hf_env_tables_create(const hfvis_env *env, int K, double azimuth0_rad,
                                         const hfvis_env_options *eopts,
                                         const hfvis_allocator *alloc, float **table,
                                         hf_env_eval *e)
{
    hf_env_resolved r;
    hfvis_status st = hf_env_resolve(env, K, eopts, &r);
    float *t;
    if (st != HFVIS_OK) return st;
    if (env->radiance == NULL || !isfinite(azimuth0_rad)) return HFVIS_ERR_INVALID_ARGUMENT;
    t = (float *)hfvis__alloc(alloc, r.table_floats * sizeof(float));
    if (t == NULL) return HFVIS_ERR_OUT_OF_MEMORY;
    st = hfvis_env_table_build(env, K, azimuth0_rad, eopts, t);
    if (st == HFVIS_OK) st = hf_env_eval_init(e, env, K, eopts, t);
    if (st != HFVIS_OK) {
        hfvis__free(alloc, t);
        return st;
    }
    *table = t;
    return HFVIS_OK;
}

/* ------------------------------------------------------------ 5. from a stored horizon map */

/* Full environment check for the routines that read radiance. */
static int hf_env_valid(const hfvis_env *env)
{
    return env != NULL && env->radiance != NULL && env->n_theta >= 1 && env->n_phi >= 1 &&
           env->channels >= 1 && env->channels <= 4 && hf_env_size_ok(env);
}

hfvis_status hfvis_env_light_from_map(const hfvis_grid *grid, int K,
                                                double map_azimuth0_rad, const float *map,
                                                const hfvis_env *env, float albedo,
                                                const hfvis_env_options *eopts,
                                                const hfvis_allocator *alloc, float *out,
                                                ptrdiff_t out_stride)
{
    size_t plane, last, mapn, n3;
    float *normals, *table;
    hf_env_eval e;
    hf_env_resolved r;
    hfvis_status st;
    int x, y, k, c, C;
    if (!hf_grid_valid(grid) || K < 1 || !isfinite(map_azimuth0_rad) || map == NULL ||
        !hf_env_valid(env) || !isfinite(albedo) || out == NULL ||
        out_stride < (ptrdiff_t)grid->width || !hfvis__plane_fits(out_stride, grid->height, 4))
        return HFVIS_ERR_INVALID_ARGUMENT;
    st = hf_env_resolve(env, K, eopts, &r);
    if (st != HFVIS_OK) return st;
    C = env->channels;
    /* map holds K planes of W*H; out's last index and the normal buffer must be addressable */
    if (!hfvis__mul_size((size_t)grid->width, (size_t)grid->height, &plane) ||
        !hfvis__mul_size(plane, (size_t)K, &mapn) || !hfvis__mul_size(plane, 3u * sizeof(float), &n3) ||
        !hfvis__mul_size((size_t)out_stride, (size_t)grid->height, &last) ||
        !hfvis__mul_size(last, (size_t)C, &last))
        return HFVIS_ERR_INVALID_ARGUMENT;
    normals = (float *)hfvis__alloc(alloc, n3);
    if (normals == NULL) return HFVIS_ERR_OUT_OF_MEMORY;
    st = hf_env_tables_create(env, K, map_azimuth0_rad, eopts, alloc, &table, &e);
    if (st != HFVIS_OK) {
        hfvis__free(alloc, normals);
        return st;
    }
    st = hfvis_normals_compute(grid, normals);
    if (st != HFVIS_OK) {
        hfvis__free(alloc, table);
        hfvis__free(alloc, normals);
        return st;
    }
    for (y = 0; y < grid->height; y++) {
        for (x = 0; x < grid->width; x++) {
            size_t g = (size_t)y * (size_t)grid->width + (size_t)x;
            float *o = out + ((size_t)y * (size_t)out_stride + (size_t)x) * (size_t)C;
            const float *n = normals + 3u * g;
            double acc[4] = {0.0, 0.0, 0.0, 0.0};
            int hole = !isfinite(grid->z[(size_t)y * (size_t)grid->stride + (size_t)x]);
            for (k = 0; k < K && !hole; k++) {
                double alpha = (double)map[(size_t)k * plane + g];
                double psi = map_azimuth0_rad + (2.0 * HFVIS__PI) * (double)k / (double)K;
                if (!isfinite(alpha)) {
                    hole = 1;
                    break;
                }
                hf_env_accumulate(&e, k, cos(psi), sin(psi), (double)n[0], (double)n[1],
                                  (double)n[2], hf_elevation_to_tan(alpha), acc);
            }
            for (c = 0; c < C; c++)
                o[c] = (float)(hole ? HFVIS__NAN : (double)albedo * acc[c]);
        }
    }
    hfvis__free(alloc, table);
    hfvis__free(alloc, normals);
    return HFVIS_OK;
}

/* ------------------------------------------------ 6. hemisphere-integration oracle */

hfvis_hemisphere_options hfvis_hemisphere_options_default(void)
{
    hfvis_hemisphere_options o;
    memset(&o, 0, sizeof o);
    o.azimuth_samples = HF_ENV_DEFAULT_AZIMUTH_SAMPLES;
    o.zenith_samples = HF_ENV_DEFAULT_ZENITH_SAMPLES;
    return o;
}

/* L_o = albedo/pi Int L_i V max(n.w, 0) dw ([P1] Eq. 3, the header's Lambertian convention)
 * by the midpoint rule: azimuths phi_m = 2pi (m + 1/2)/A, zenith angles
 * theta_j = pi (j + 1/2)/Z over the whole sphere [0, pi] (horizons may lie below the
 * horizontal, docs/errata.md E9), dw = sin theta dtheta dphi. V = 1 iff the elevation
 * pi/2 - theta_j exceeds the exact horizon alpha(phi_m) of hfvis_horizon_reference.
 * Each azimuth is one call with K = 1 and azimuth0 = phi_m, so no scratch and no limit on A
 * (the header promises "no allocation"); opts->azimuth0_rad is therefore not used, and
 * opts->progress is not called. L_i is the texel containing (theta, phi) (nearest, as
 * piecewise-constant texels are defined). The normal is used as given. A receiver whose
 * bilinear height is a hole, whose normal is not finite or whose horizon is NaN gets NaN. */
hfvis_status hfvis_light_reference(const hfvis_grid *grid, const hfvis_env *env,
                                             float albedo, const hfvis_sweep_options *opts,
                                             const hfvis_march_options *march,
                                             const hfvis_hemisphere_options *hopts,
                                             const float *points, const float *normals,
                                             size_t count, float *out)
{
    static const float one = 1.0f;
    hfvis_env uniform;
    hfvis_sweep_options so;
    int A = HF_ENV_DEFAULT_AZIMUTH_SAMPLES, Z = HF_ENV_DEFAULT_ZENITH_SAMPLES, C, T, P;
    size_t i, tmp;
    double scale;
    if (!hf_grid_valid(grid) || !isfinite(albedo) || (env != NULL && !hf_env_valid(env)))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (opts != NULL && ((int)opts->border < (int)HFVIS_BORDER_DEFAULT ||
                         (int)opts->border > (int)HFVIS_BORDER_WRAP || opts->border_cells < 0))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (march != NULL &&
        (!isfinite(march->step_cells) || march->step_cells < 0.0 ||
         !isfinite(march->max_distance_cells) || march->max_distance_cells < 0.0))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (hopts != NULL) {
        if (hopts->azimuth_samples < 0 || hopts->zenith_samples < 0)
            return HFVIS_ERR_INVALID_ARGUMENT;
        if (hopts->azimuth_samples != 0) A = hopts->azimuth_samples;
        if (hopts->zenith_samples != 0) Z = hopts->zenith_samples;
    }
    if (env == NULL) {
        uniform.radiance = &one;
        uniform.n_theta = uniform.n_phi = uniform.channels = 1;
        env = &uniform;
    }
    C = env->channels;
    T = env->n_theta;
    P = env->n_phi;
    if (count == 0) return HFVIS_OK;
    if (points == NULL || normals == NULL || out == NULL || !hfvis__mul_size(count, 3u, &tmp) ||
        !hfvis__mul_size(count, (size_t)C, &tmp))
        return HFVIS_ERR_INVALID_ARGUMENT;
    /* validated up front so that the per-receiver march cannot fail half-way */
    for (i = 0; i < 2u * count; i++)
        if (!isfinite(points[i])) return HFVIS_ERR_INVALID_ARGUMENT;
    so = opts != NULL ? *opts : hfvis_sweep_options_default();
    so.progress = NULL;
    so.progress_user = NULL;
    scale = ((2.0 * HFVIS__PI) / (double)A) * (HFVIS__PI / (double)Z) * (double)albedo / HFVIS__PI;
    for (i = 0; i < count; i++) {
        const double nx = (double)normals[3u * i], ny = (double)normals[3u * i + 1u],
                     nz = (double)normals[3u * i + 2u];
        double acc[4] = {0.0, 0.0, 0.0, 0.0};
        int m, j, c, bad = !isfinite(nx) || !isfinite(ny) || !isfinite(nz) ||
                           isnan(hfvis_grid_sample(grid, (double)points[2u * i],
                                                   (double)points[2u * i + 1u]));
        for (m = 0; m < A && !bad; m++) {
            double phi = (2.0 * HFVIS__PI) * ((double)m + 0.5) / (double)A;
            double cp = cos(phi), sp = sin(phi), limit;
            int col = (int)(phi * (double)P / (2.0 * HFVIS__PI));
            float alpha;
            hfvis_status st;
            if (col > P - 1) col = P - 1;
            so.azimuth0_rad = phi;
            st = hfvis_horizon_reference(grid, 1, &so, march, points + 2u * i, 1, &alpha);
            if (st != HFVIS_OK) return st;
            if (isnan(alpha)) {
                bad = 1;
                break;
            }
            /* visible iff pi/2 - theta > alpha, i.e. theta < pi/2 - alpha */
            limit = HFVIS__HALF_PI - (double)alpha;
            for (j = 0; j < Z; j++) {
                double theta = HFVIS__PI * ((double)j + 0.5) / (double)Z;
                double st_ = sin(theta), cosine;
                const float *L;
                int row;
                if (!(theta < limit)) break;
                cosine = st_ * (nx * cp + ny * sp) + nz * cos(theta);
                if (!(cosine > 0.0)) continue;
                row = (int)(theta * (double)T / HFVIS__PI);
                if (row > T - 1) row = T - 1;
                L = env->radiance + ((size_t)row * (size_t)P + (size_t)col) * (size_t)C;
                for (c = 0; c < C; c++) acc[c] += (double)L[c] * cosine * st_;
            }
        }
        for (c = 0; c < C; c++)
            out[i * (size_t)C + (size_t)c] = (float)(bad ? HFVIS__NAN : acc[c] * scale);
    }
    return HFVIS_OK;
}

/* Environment light fused into the sweep ([P1] §7 "packing and lighting": the per-direction
 * light is evaluated in lattice space with bilinearly filtered normals and gathered). */
typedef struct hf_env_ctx {
    hf_fused f;
    const hf_env_eval *e;
} hf_env_ctx;

static void hf_env_line(hf_sweep *sw, void *vctx, int m, ptrdiff_t node0, ptrdiff_t step, int n,
                        const double *t)
{
    const hf_env_ctx *c = (const hf_env_ctx *)vctx;
    int s, ch = sw->channels;
    (void)m;
    for (s = 0; s < n; s++, node0 += step) {
        const float *nr = sw->nrm + node0 * 3;
        if (isnan(t[s])) continue;
        hf_env_accumulate(c->e, c->f.k, c->f.lx, c->f.ly, (double)nr[0], (double)nr[1],
                          (double)nr[2], t[s], sw->lat + node0 * ch);
    }
}

hfvis_status hfvis_env_light(const hfvis_grid *grid, int K, const hfvis_env *env, float albedo,
                             const hfvis_sweep_options *opts, const hfvis_env_options *eopts,
                             float *out, ptrdiff_t out_stride)
{
    hfvis_sweep_options o;
    hf_sweep sw;
    hf_env_ctx ctx;
    hf_env_eval eval;
    float *table = NULL;
    hfvis_status s;
    if (!hf_light_args_valid(grid, K, opts, out, out_stride) || !hf_env_valid(env) ||
        !isfinite(albedo))
        return HFVIS_ERR_INVALID_ARGUMENT;
    o = hf_opts_resolve(grid, opts);
    if (o.rays == HFVIS_RAYS_EXACT)
        return hf_exact_light(grid, K, HFVIS_SUM_ENV_LIGHT, env, eopts, &o, (double)albedo, out,
                              out_stride);
    s = hf_env_tables_create(env, K, o.azimuth0_rad, eopts, o.alloc, &table, &eval);
    if (s != HFVIS_OK) return s;
    memset(&ctx, 0, sizeof ctx);
    ctx.e = &eval;
    s = hf_fused_run(&sw, grid, K, &o, env->channels, 1, hf_env_line, &ctx.f);
    if (s == HFVIS_OK) {
        hf_fused_output(&sw, (double)albedo, 0.0, out, out_stride, env->channels);
        hf_sweep_free(&sw);
    }
    hfvis__free(o.alloc, table);
    return s;
}

/* ========================================================================================== */
/* 11. P2: the convex-hull tree, intervisibility, indirect light                              */
/* ========================================================================================== */
/* [P2] Timonen, "Low-Complexity Intervisibility in Height Fields", CGF 31(8), 2012 (thesis
 * appendix A.2); [P2] §4-7, §10.1. Terms: samples p_0..p_n pushed in order of increasing distance,
 * R = p_n the receiver; "convex" = a cap (p_i above the chord of its neighbours, [P2] Eq. 1);
 * a segment starts where a convex section follows a concave one. The tree is the union of the
 * upper hulls S_j from every segment start j to R ([P2] Eq. 2); the root is R and its children,
 * farthest first, are the horizons. */

struct hfvis_hull_tree {
    int cap, n;                 /* capacity and samples pushed */
    hfvis_tree_order order;
    int safe_zone, zone_steps;
    long long iterations;
    double *d, *h;              /* the samples */
    int *fc, *ns, *ps;          /* first child, next and previous sibling (docs/errata.md E16) */
    signed char *seg, *cls;     /* segment-start flag; convexity class +1 cap, -1 cup */
    int *pc, *pp;               /* pending (child, parent) tests: stack or ring queue */
    /* SafeZoneUpdate state ([P2] Alg. 3): a chord below every root child's line gc -> c */
    int zone_valid;
    double zone_b1, zone_b2, zone_h1, zone_h2, zone_scale;
};


static size_t hf_tree_header(void) { return (sizeof(struct hfvis_hull_tree) + 15u) & ~(size_t)15u; }

size_t hfvis_hull_tree_size(int max_samples)
{
    size_t n, per, total;
    if (max_samples < 1) return 0;
    n = (size_t)max_samples;
    per = 2 * sizeof(double) + 5 * sizeof(int) + 2 * sizeof(signed char);
    if (!hfvis__mul_size(n, per, &total) || total > SIZE_MAX - hf_tree_header() - 64) return 0;
    return hf_tree_header() + total + 64; /* + alignment slack between the arrays */
}

/* SafeZoneUpdate window b2 - b1 when the options give 0 ([P2] Alg. 3; docs/errata.md E15). */
#define HF_TREE_DEFAULT_ZONE_STEPS 4

hfvis_tree_options hfvis_tree_options_default(void)
{
    hfvis_tree_options o;
    memset(&o, 0, sizeof o);
    o.order = HFVIS_TREE_DEPTH_FIRST;
    o.safe_zone = 0;
    o.safe_zone_steps = HF_TREE_DEFAULT_ZONE_STEPS;
    return o;
}

hfvis_status hfvis_hull_tree_init(void *mem, size_t mem_size, int max_samples,
                                  const hfvis_tree_options *opts, hfvis_hull_tree **tree)
{
    struct hfvis_hull_tree *t;
    unsigned char *p;
    size_t need = hfvis_hull_tree_size(max_samples), n;
    if (!mem || !tree || need == 0 || ((uintptr_t)mem & 7u) != 0) return HFVIS_ERR_INVALID_ARGUMENT;
    if (opts && (opts->order < HFVIS_TREE_DEFAULT || opts->order > HFVIS_TREE_BREADTH_FIRST ||
                 opts->safe_zone < 0 || opts->safe_zone > 1 || opts->safe_zone_steps < 0))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (mem_size < need) return HFVIS_ERR_BUFFER_TOO_SMALL;
    n = (size_t)max_samples;
    t = (struct hfvis_hull_tree *)mem;
    memset(t, 0, sizeof *t);
    t->cap = max_samples;
    t->order = opts && opts->order ? opts->order : HFVIS_TREE_DEPTH_FIRST;
    t->safe_zone = opts ? opts->safe_zone : 0;
    t->zone_steps = opts && opts->safe_zone_steps ? opts->safe_zone_steps : HF_TREE_DEFAULT_ZONE_STEPS;
    p = (unsigned char *)mem + hf_tree_header();
    t->d = (double *)(void *)p;
    t->h = t->d + n;
    t->fc = (int *)(void *)(t->h + n);
    t->ns = t->fc + n;
    t->ps = t->ns + n;
    t->pc = t->ps + n;
    t->pp = t->pc + n;
    t->seg = (signed char *)(void *)(t->pp + n);
    t->cls = t->seg + n;
    *tree = t;
    return HFVIS_OK;
}

void hfvis_hull_tree_reset(hfvis_hull_tree *tree)
{
    if (!tree) return;
    tree->n = 0;
    tree->iterations = 0;
    tree->zone_valid = 0;
}

int hfvis_hull_tree_count(const hfvis_hull_tree *tree) { return tree ? tree->n : 0; }

int64_t hfvis_hull_tree_iterations(const hfvis_hull_tree *tree) { return tree ? tree->iterations : 0; }

/* convex(c -> p -> r): p strictly above the chord c-r ([P2] Alg. 1; strict, so collinear points
 * are not kept: the tree then matches the naive rule with >=, docs/errata.md E14). */
static int hf_tree_convex(const hfvis_hull_tree *t, int c, int p, int r)
{
    return (t->h[p] - t->h[c]) * (t->d[r] - t->d[c]) > (t->h[r] - t->h[c]) * (t->d[p] - t->d[c]);
}

/* Unlink node x from the root list of root r. */
static void hf_tree_unlink(hfvis_hull_tree *t, int x, int r)
{
    if (t->ps[x] >= 0) t->ns[t->ps[x]] = t->ns[x];
    else t->fc[r] = t->ns[x];
    if (t->ns[x] >= 0) t->ps[t->ns[x]] = t->ps[x];
}

/* SafeZoneUpdate ([P2] Alg. 3; docs/errata.md E15): over the window [b1, b2] starting at the current
 * distance, the lowest of the lines gc -> c (c a root child, gc its first child) at both ends;
 * the chord between them lies below all those lines on the window (a minimum of lines is
 * concave). */
static void hf_tree_zone_refresh(hfvis_hull_tree *t, int r)
{
    double step = r > 0 ? t->d[r] - t->d[r - 1] : 1.0, h1 = HFVIS__INF, h2 = HFVIS__INF, scale = 0.0;
    int c;
    t->zone_b1 = t->d[r];
    t->zone_b2 = t->d[r] + step * (double)t->zone_steps;
    for (c = t->fc[r]; c >= 0; c = t->ns[c]) {
        int gc = t->fc[c];
        double slope;
        if (gc < 0) continue;
        slope = (t->h[c] - t->h[gc]) / (t->d[c] - t->d[gc]);
        h1 = fmin(h1, t->h[c] + slope * (t->zone_b1 - t->d[c]));
        h2 = fmin(h2, t->h[c] + slope * (t->zone_b2 - t->d[c]));
        scale = fmax(scale, fabs(t->h[c]) + fabs(slope * (t->zone_b2 - t->d[c])));
    }
    t->zone_scale = scale;
    t->zone_h1 = h1;
    t->zone_h2 = h2;
    t->zone_valid = 1;
}

/* The shortcut applies when the new sample r only replaces the old root o: the last child of o
 * fails its test (so every child fails, [P2] Alg. 1), and r lies strictly below every line
 * gc -> c (so every first grandchild passes). Never when o is a segment start: its leaf would be
 * lost ([P2] Alg. 3; docs/errata.md E15). */
static int hf_tree_zone_applies(hfvis_hull_tree *t, int o, int r)
{
    int last = t->fc[o], chord_ok;
    double x = t->d[r];
    if (!t->zone_valid || t->seg[o] || last < 0) return 0;
    if (x < t->zone_b1 || x > t->zone_b2) return 0;
    if (isinf(t->zone_h1) || isinf(t->zone_h2)) chord_ok = 1; /* no grandchild anywhere */
    else {
        double w = t->zone_b2 > t->zone_b1 ? (x - t->zone_b1) / (t->zone_b2 - t->zone_b1) : 0.0;
        double chord = t->zone_h1 + (t->zone_h2 - t->zone_h1) * w;
        /* The chord is built from rounded slopes: keep a margin far above their rounding error
         * (~1e-15 of the largest term), so a sample on or near a line (a tie, which the exact
         * test would not call convex) never takes the shortcut. */
        chord_ok = t->h[r] < chord - 1e-9 * (t->zone_scale + fabs(t->h[r]) + 1.0);
    }
    if (!chord_ok) return 0;
    while (t->ns[last] >= 0) last = t->ns[last];
    t->iterations++;
    return !hf_tree_convex(t, last, o, r);
}

/* Queue the test of parent p's first child: on the stack (depth first) or at the tail of the
 * ring queue (breadth first). */
static void hf_tree_pend(hfvis_hull_tree *t, int p, int *top, int *tail)
{
    int at = t->order == HFVIS_TREE_BREADTH_FIRST ? (*tail)++ : (*top)++;
    if (*tail == t->cap) *tail = 0;
    t->pc[at] = t->fc[p];
    t->pp[at] = p;
}

hfvis_status hfvis_hull_tree_push(hfvis_hull_tree *t, double distance, double height,
                                  int *horizon_count)
{
    int k, o, r, i, top = 0, head = 0, tail = 0;
    if (!t || !isfinite(distance) || !isfinite(height)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (t->n > 0 && !(distance > t->d[t->n - 1])) return HFVIS_ERR_INVALID_ARGUMENT;
    if (t->n >= t->cap) return HFVIS_ERR_LIMIT;
    k = t->n++;
    t->d[k] = distance;
    t->h[k] = height;
    t->fc[k] = t->ns[k] = t->ps[k] = -1;
    t->seg[k] = 0;
    t->cls[k] = 1;
    if (k == 0) { /* p_0 is a segment start, a permanent leaf */
        t->seg[0] = 1;
        if (horizon_count) *horizon_count = 0;
        return HFVIS_OK;
    }
    o = k - 1;
    r = k;
    if (k >= 2) {
        /* [P2] Eq. 1 for p_i, i = k-1, now that p_{i+1} is known (non-uniform spacing form of
         * [P2] Eq. 1); collinear inherits the previous class. */
        double lhs, rhs;
        i = k - 1;
        lhs = (t->h[i] - t->h[i - 1]) * (t->d[i + 1] - t->d[i - 1]);
        rhs = (t->h[i + 1] - t->h[i - 1]) * (t->d[i] - t->d[i - 1]);
        t->cls[i] = lhs > rhs ? 1 : lhs < rhs ? -1 : t->cls[i - 1];
        /* docs/errata.md E13: mark the segment start before RecConvexity, so the leaf stays in the
         * root list when orphaned and is among this step's horizons */
        if (t->cls[i] == 1 && t->cls[i - 1] == -1) t->seg[i] = 1;
    }
    if (t->safe_zone && hf_tree_zone_applies(t, o, r)) {
        /* The new root adopts the old root's children; nothing deeper changes. */
        t->fc[r] = t->fc[o];
        t->fc[o] = -1;
    } else {
        t->fc[r] = o;
        t->ns[o] = t->ps[o] = -1;
        if (t->fc[o] >= 0) hf_tree_pend(t, o, &top, &tail);
        /* RecConvexity ([P2] Alg. 1) with an explicit stack (LIFO) or queue (FIFO, Alg. 2's
         * breadth-first order); at most one pending test per root child, so cap entries do. */
        while (t->order == HFVIS_TREE_BREADTH_FIRST ? head != tail : top > 0) {
            int c, p, next;
            if (t->order == HFVIS_TREE_BREADTH_FIRST) {
                c = t->pc[head];
                p = t->pp[head];
                head = head + 1 == t->cap ? 0 : head + 1;
            } else {
                top--;
                c = t->pc[top];
                p = t->pp[top];
            }
            t->iterations++;
            if (hf_tree_convex(t, c, p, r)) continue;
            /* detach c, p's first child (the sibling is saved first: A.2 erratum, docs/errata.md E12) */
            next = t->ns[c];
            t->fc[p] = next;
            if (next >= 0) t->ps[next] = -1;
            /* insert c into the root list just before p */
            t->ps[c] = t->ps[p];
            t->ns[c] = p;
            if (t->ps[p] >= 0) t->ns[t->ps[p]] = c;
            else t->fc[r] = c;
            t->ps[p] = c;
            if (t->fc[p] >= 0) hf_tree_pend(t, p, &top, &tail); /* step wider */
            else if (!t->seg[p]) hf_tree_unlink(t, p, r); /* delete the orphan; segment starts stay */
            if (t->fc[c] >= 0) hf_tree_pend(t, c, &top, &tail); /* step deeper */
        }
        if (t->safe_zone) hf_tree_zone_refresh(t, r);
    }
    if (t->safe_zone && t->zone_valid && t->d[r] > t->zone_b2) hf_tree_zone_refresh(t, r);
    if (horizon_count) {
        int m = 0, c;
        for (c = t->fc[r]; c >= 0; c = t->ns[c]) m++;
        *horizon_count = m;
    }
    return HFVIS_OK;
}

/* Elevation slope of sample q seen from receiver s. */
static double hf_slope_from(const double *d, const double *h, int s, int q)
{
    return (h[q] - h[s]) / (d[s] - d[q]);
}

int hfvis_hull_tree_horizons(const hfvis_hull_tree *tree, int minimal, int *out, int cap)
{
    int r, c, m = 0;
    if (!tree || (cap > 0 && !out) || cap < 0) return -1;
    if (tree->n < 2) return 0;
    r = tree->n - 1;
    for (c = tree->fc[r]; c >= 0; c = tree->ns[c]) {
        /* docs/errata.md E14: a root child whose predecessor is visible too is a segment start seen from
         * above, not a tangent point; the filter keeps c = 0 or a hidden predecessor */
        if (minimal && c > 0 &&
            !(hf_slope_from(tree->d, tree->h, r, c - 1) < hf_slope_from(tree->d, tree->h, r, c)))
            continue;
        if (m < cap) out[m] = c;
        m++;
    }
    return m;
}

/* Enumerate the visible samples from a horizon list ([P2] §10.1), farthest first, skipping holes.
 * The q < next guard keeps runs of spurious horizons from overlapping. Only samples q >= qmin
 * are listed (the search radius; 0 = all): each run of visible samples starts at its horizon and
 * is cut, not changed, by the radius, so a run that ends before qmin is skipped unwalked and
 * the others are walked as without it. */
static int hf_visible_from_horizons(const double *d, const double *h, int s, const int *H, int m,
                                    int qmin, int *out, int cap)
{
    int r, count = 0;
    for (r = 0; r < m; r++) {
        int next = r + 1 < m ? H[r + 1] : s, q = H[r];
        double lim;
        if (next <= qmin) continue;
        lim = r + 1 < m ? hf_slope_from(d, h, s, H[r + 1]) : -HFVIS__INF;
        for (; q < next; q++) {
            if (!isfinite(h[q])) continue;
            if (q != H[r] && !(hf_slope_from(d, h, s, q) >= lim)) break;
            if (q < qmin) continue;
            if (count < cap) out[count] = q;
            count++;
        }
    }
    return count;
}

static int hf_line_args_ok(const double *distance, const double *height, int receiver, int cap,
                           const int *out)
{
    return distance && height && receiver >= 0 && cap >= 0 && (cap == 0 || out);
}

int hfvis_line_visible_from_horizons(const double *distance, const double *height, int receiver,
                                     const int *horizons, int m, int *out, int cap)
{
    int r;
    if (!hf_line_args_ok(distance, height, receiver, cap, out) || m < 0 || (m > 0 && !horizons))
        return -1;
    for (r = 0; r < m; r++)
        if (horizons[r] < 0 || horizons[r] >= receiver || (r > 0 && horizons[r] <= horizons[r - 1]))
            return -1;
    return hf_visible_from_horizons(distance, height, receiver, horizons, m, 0, out, cap);
}

/* The naive visible set ([P2] §10.1): walking outward from the receiver, a sample is visible when
 * its slope is >= the running maximum. Counted near to far, then written farthest first. The
 * walk stops at the first sample more than win behind the receiver (the search radius in the
 * line's distance units; negative = the whole line): a sample's visibility depends only on the
 * nearer ones. */
static int hf_visible_naive(const double *d, const double *h, int s, double win, int *out, int cap)
{
    double best = -HFVIS__INF;
    int q, count = 0, i;
    for (q = s - 1; q >= 0 && !(win >= 0.0 && d[s] - d[q] > win); q--) {
        double t;
        if (!isfinite(h[q])) continue;
        t = hf_slope_from(d, h, s, q);
        if (t >= best) {
            best = t;
            count++;
        }
    }
    /* second pass writes farthest first without scratch */
    i = count;
    best = -HFVIS__INF;
    for (q = s - 1; q >= 0 && !(win >= 0.0 && d[s] - d[q] > win); q--) {
        double t;
        if (!isfinite(h[q])) continue;
        t = hf_slope_from(d, h, s, q);
        if (t >= best) {
            best = t;
            i--;
            if (i < cap) out[i] = q;
        }
    }
    return count;
}

int hfvis_line_visible_naive(const double *distance, const double *height, int receiver, int *out,
                             int cap)
{
    if (!hf_line_args_ok(distance, height, receiver, cap, out)) return -1;
    return hf_visible_naive(distance, height, receiver, -1.0, out, cap);
}

int hfvis_line_local_horizons_naive(const double *distance, const double *height, int receiver,
                                    int *out, int cap)
{
    double best = -HFVIS__INF;
    int q, count = 0, prev_visible = 0, i;
    if (!hf_line_args_ok(distance, height, receiver, cap, out)) return -1;
    /* visible flags near to far; a horizon is a visible sample whose farther neighbour (the next
     * finite sample outward) is not visible, or the farthest finite sample if visible */
    for (i = 0; i < 2; i++) {
        int k = count;
        best = -HFVIS__INF;
        prev_visible = 0;
        count = 0;
        for (q = receiver - 1; q >= -1; q--) {
            int vis = 0;
            if (q >= 0) {
                double t;
                if (!isfinite(height[q])) continue;
                t = hf_slope_from(distance, height, receiver, q);
                if (t >= best) {
                    best = t;
                    vis = 1;
                }
            }
            if (prev_visible && !vis) {
                /* the previous visible sample (nearer to the receiver) was a horizon */
                if (i == 1) {
                    k--;
                    if (k < cap) out[k] = prev_visible - 1;
                }
                count++;
            }
            prev_visible = vis ? q + 1 : 0;
        }
    }
    return count;
}

/* ---- The field sweep with the tree ([P2] §3: the same lattice and gather as P1) ---------- */

typedef struct hf_p2_ctx hf_p2_ctx;
/* Per-receiver consumer: node = lattice buffer index of the receiver, s = its index in the
 * line arrays, vis[0..nv-1] its visible samples farthest first. */
typedef void (*hf_p2_fn)(hf_sweep *sw, hf_p2_ctx *c, ptrdiff_t node, int s, const int *vis, int nv,
                         const int *hz, int nh);

struct hf_p2_ctx {
    hf_fused f;
    int naive;                  /* 1 = naive visible sets (the oracle) */
    const hfvis_tree_options *tree_opts;
    hf_p2_fn fn;
    /* line data, carved out of sw->extra */
    int len;                    /* capacity: longest line + pre-roll */
    hfvis_hull_tree *tree;
    double *ld, *lh;            /* pushed samples: distance (cells), height (cells) */
    double *wd, *wh;            /* the same in world units (callback events) */
    double *le;                 /* exit radiance of the pushed samples, channels each */
    int *vis, *hz;
    double *lat_exit;           /* per group: exit radiance at the lattice nodes */
    int npre;                   /* pre-roll samples pushed on the current line */
    double win;                 /* search radius in node steps, floor(R / cell); -1 = unlimited */
    int qmin;                   /* the current receiver's farthest sample within win */
    /* consumers */
    const float *exit;          /* grid exit radiance, channels interleaved (indirect) */
    int channels;
    double sky, inv_k, lobe;
    hfvis_visibility_fn user_fn;
    void *user;
    hfvis_visibility_stats st;
};

static size_t hf_p2_extra_size(const hfvis_grid *g, const hfvis_sweep_options *o, int channels,
                               int *len_out, int *ok)
{
    size_t total = 0, D = (size_t)hf_lattice_bound(g), len, tree;
    len = D + (size_t)(o->border == HFVIS_BORDER_OPEN ? 0 : o->border_cells);
    if (len > (size_t)INT_MAX / 2 || D * D / D != D) {
        *ok = 0;
        return 0;
    }
    tree = hfvis_hull_tree_size((int)len);
    if (tree == 0) *ok = 0;
    hf_align_add(&total, tree, 1, ok);
    hf_align_add(&total, len, 4 * sizeof(double), ok);
    hf_align_add(&total, len, (size_t)channels * sizeof(double), ok);
    hf_align_add(&total, len, 2 * sizeof(int), ok);
    if (channels) hf_align_add(&total, hf_lattice_nodes_bound(g, (int)D), (size_t)channels * sizeof(double), ok);
    *len_out = (int)len;
    return total;
}

static void hf_p2_carve(hf_sweep *sw, hf_p2_ctx *c)
{
    size_t total = 0, o_tree, o_line, o_exit, o_int, o_lat = 0, len = (size_t)c->len;
    size_t D = (size_t)hf_lattice_bound(sw->g);
    int ok = 1;
    size_t tree = hfvis_hull_tree_size(c->len);
    o_tree = hf_align_add(&total, tree, 1, &ok);
    o_line = hf_align_add(&total, len, 4 * sizeof(double), &ok);
    o_exit = hf_align_add(&total, len, (size_t)c->channels * sizeof(double), &ok);
    o_int = hf_align_add(&total, len, 2 * sizeof(int), &ok);
    if (c->channels)
        o_lat = hf_align_add(&total, hf_lattice_nodes_bound(sw->g, (int)D), (size_t)c->channels * sizeof(double), &ok);
    HFVIS_ASSERT(ok && total <= sw->extra_size);
    hfvis_hull_tree_init(sw->extra + o_tree, tree, c->len, c->tree_opts, &c->tree);
    c->ld = (double *)(void *)(sw->extra + o_line);
    c->lh = c->ld + len;
    c->wd = c->lh + len;
    c->wh = c->wd + len;
    c->le = (double *)(void *)(sw->extra + o_exit);
    c->vis = (int *)(void *)(sw->extra + o_int);
    c->hz = c->vis + len;
    c->lat_exit = c->channels ? (double *)(void *)(sw->extra + o_lat) : NULL;
}

/* Bilinear sample of a channels-interleaved grid array at an in-domain position (or under the
 * border rule outside), like the heights. */
static void hf_sample_channels(const hfvis_grid *g, hfvis_border border, const float *a, int ch,
                               double x, double y, double *out)
{
    int c;
    double fx, fy, w[4];
    int xi[2], yi[2], q;
    double W = (double)g->width, H = (double)g->height;
    if (border == HFVIS_BORDER_WRAP) {
        x = x - W * floor(x / W);
        y = y - H * floor(y / H);
        xi[0] = (int)floor(x);
        yi[0] = (int)floor(y);
        if (xi[0] >= g->width) xi[0] = g->width - 1;
        if (yi[0] >= g->height) yi[0] = g->height - 1;
        fx = x - (double)xi[0];
        fy = y - (double)yi[0];
        xi[1] = xi[0] + 1 == g->width ? 0 : xi[0] + 1;
        yi[1] = yi[0] + 1 == g->height ? 0 : yi[0] + 1;
    } else {
        x = hf_clampd(x, 0.0, W - 1.0);
        y = hf_clampd(y, 0.0, H - 1.0);
        xi[0] = g->width > 1 ? (int)floor(x) : 0;
        yi[0] = g->height > 1 ? (int)floor(y) : 0;
        if (xi[0] > g->width - 2) xi[0] = g->width > 1 ? g->width - 2 : 0;
        if (yi[0] > g->height - 2) yi[0] = g->height > 1 ? g->height - 2 : 0;
        fx = g->width > 1 ? x - (double)xi[0] : 0.0;
        fy = g->height > 1 ? y - (double)yi[0] : 0.0;
        xi[1] = g->width > 1 ? xi[0] + 1 : 0;
        yi[1] = g->height > 1 ? yi[0] + 1 : 0;
    }
    w[0] = (1.0 - fx) * (1.0 - fy);
    w[1] = fx * (1.0 - fy);
    w[2] = (1.0 - fx) * fy;
    w[3] = fx * fy;
    for (c = 0; c < ch; c++) out[c] = 0.0;
    for (q = 0; q < 4; q++) {
        const float *p;
        if (w[q] == 0.0) continue;
        p = a + ((size_t)yi[q >> 1] * (size_t)g->width + (size_t)xi[q & 1]) * (size_t)ch;
        for (c = 0; c < ch; c++) out[c] += w[q] * (double)p[c];
    }
}

/* Group hook: exit radiance at the lattice nodes (bilinear, as the heights). */
static void hf_p2_group(hf_sweep *sw, hf_fused *f)
{
    hf_p2_ctx *c = (hf_p2_ctx *)(void *)f;
    const hfvis_lattice *L = &sw->L;
    int j, i;
    if (!c->tree) hf_p2_carve(sw, c);
    if (!c->channels) return;
    for (j = 0; j < sw->rows; j++)
        for (i = sw->row_first[j]; i <= sw->row_last[j]; i++) {
            double x, y;
            hf_node_pos(L, i + L->i_min, j + L->j_min, &x, &y);
            hf_sample_channels(sw->g, HFVIS_BORDER_CLAMP, c->exit, c->channels, x, y,
                               c->lat_exit + ((size_t)j * (size_t)sw->cols + (size_t)i) * (size_t)c->channels);
        }
}

/* Orientation hook: walk each line of quarter turn m, push its samples into the tree (or keep
 * them for the naive scan) and hand every receiver's visible set to the consumer. */
static void hf_p2_orient(hf_sweep *sw, int m, hf_fused *f)
{
    hf_p2_ctx *c = (hf_p2_ctx *)(void *)f;
    const hfvis_lattice *L = &sw->L;
    const int R = sw->preroll, ch = c->channels;
    const double cs = sw->g->cell_size, inv_cs = 1.0 / cs;
    int nlines = (m & 1) ? sw->cols : sw->rows, line;
    for (line = 0; line < nlines; line++) {
        ptrdiff_t node0, step, p;
        int i0, j0, di, dj, n, s, r, k = 0, q;
        int qmin = 0; /* the farthest pushed sample within the radius of the current receiver */
        n = hf_line_span(sw, m, line, &node0, &step, &i0, &j0, &di, &dj);
        if (n == 0) continue;
        hfvis_hull_tree_reset(c->tree);
        /* every pre-roll node is pushed, with R too: the event's minimal-horizon filter reads a
         * horizon's farther neighbour (hf_p2_event), which may lie beyond R */
        for (r = 0; r < R; r++) {
            double x, y, h;
            hf_node_pos(L, i0 - (R - r) * di + L->i_min, j0 - (R - r) * dj + L->j_min, &x, &y);
            h = hf_sample_border(sw->g, sw->border, x, y) * inv_cs;
            if (isnan(h)) continue;
            c->ld[k] = (double)(r - R);
            c->lh[k] = h;
            c->wd[k] = c->ld[k] * cs;
            c->wh[k] = h * cs;
            if (ch) hf_sample_channels(sw->g, sw->border, c->exit, ch, x, y, c->le + (size_t)k * (size_t)ch);
            k++;
        }
        c->npre = k;
        if (!c->naive)
            for (q = 0; q < k; q++) hfvis_hull_tree_push(c->tree, c->ld[q], c->lh[q], NULL);
        for (s = 0, p = node0; s < n; s++, p += step) {
            int nh = 0, nv;
            double h = sw->h[p];
            if (isnan(h)) continue;
            c->ld[k] = (double)s;
            c->lh[k] = h;
            c->wd[k] = c->ld[k] * cs;
            c->wh[k] = h * cs;
            if (ch) memcpy(c->le + (size_t)k * (size_t)ch, c->lat_exit + (size_t)p * (size_t)ch, sizeof(double) * (size_t)ch);
            if (c->naive) {
                nv = hf_visible_naive(c->ld, c->lh, k, c->win, c->vis, c->len);
                c->st.iterations += (double)k;
            } else {
                long long before = c->tree->iterations;
                hfvis_hull_tree_push(c->tree, c->ld[k], c->lh[k], &nh);
                c->st.iterations += (double)(c->tree->iterations - before);
                c->st.horizons += (double)nh;
                nh = hfvis_hull_tree_horizons(c->tree, 0, c->hz, c->len);
                if (c->win >= 0.0)
                    while (c->ld[k] - c->ld[qmin] > c->win) qmin++;
                c->qmin = qmin;
                nv = hf_visible_from_horizons(c->ld, c->lh, k, c->hz, nh, qmin, c->vis, c->len);
            }
            c->st.receivers += 1.0;
            c->fn(sw, c, p, k, c->vis, nv, c->hz, nh);
            k++;
        }
    }
}

/* The P2 consumers' stranded receivers (hf_stranded_tan's rule, for visible sets): a grid point
 * with a finite height whose gather found no finite node holds NaN in sw->gacc. Its line toward
 * each direction of [begin, end) is made by the oracle's march instead of the lattice: unit
 * steps from the receiver along the look direction, bilinear heights and exit radiance, holes
 * skipped, out of the grid and then the sweep's pre-roll steps under the border rule (so at
 * most the lattice line's length: c->len). hf_visible_naive finds the visible set (the search
 * radius c->win included) and the consumer adds its term to a one-node lattice whose normal is
 * the grid normal (one-sided beside holes). The statistics stay the lattice sweep's. */
static void hf_p2_stranded(hf_sweep *sw, int K, const hfvis_sweep_options *o, hf_p2_ctx *c)
{
    const hfvis_grid *g = sw->g;
    const int ch = sw->channels, cc = c->channels;
    const double inv_cs = 1.0 / g->cell_size, xmax = (double)(g->width - 1) + HF_LATTICE_EPS,
                 ymax = (double)(g->height - 1) + HF_LATTICE_EPS;
    double *lat = sw->lat, one[4];
    float *nrm = sw->nrm, n1[3];
    hfvis_visibility_stats st = c->st;
    int x, y, q, k, begin, end;
    if (!c->ld || ch > 4 || hf_direction_range(o, K, &begin, &end) != HFVIS_OK) return;
    for (y = sw->ry0; y < sw->ry1; y++)
        for (x = sw->rx0; x < sw->rx1; x++) {
            double *acc = sw->gacc + ((size_t)y * (size_t)g->width + (size_t)x) * (size_t)ch, nd[3];
            int stranded = 0;
            if (hf_is_hole(g, x, y)) continue;
            for (q = 0; q < ch; q++) stranded |= isnan(acc[q]);
            if (!stranded) continue;
            if (sw->nrm) {
                hf_normal_at(g, x, y, nd);
                n1[0] = (float)nd[0];
                n1[1] = (float)nd[1];
                n1[2] = (float)nd[2];
                sw->nrm = n1;
            }
            for (q = 0; q < ch; q++) one[q] = 0.0;
            sw->lat = one;
            for (k = 0; k < K; k++) {
                int pos = hf_direction_position(o, K, k), n = 0, out = 0, i, nv;
                double ux, uy, d;
                if (pos < begin || pos >= end) continue;
                hf_sweep_vector(o->azimuth0_rad + 2.0 * HFVIS__PI * (double)k / (double)K, &ux, &uy);
                c->f.K = K;
                c->f.k = k;
                c->f.lx = -ux;
                c->f.ly = -uy;
                /* near to far: in-grid steps, then the pre-roll; reversed below (far first) */
                for (d = 1.0; n + 1 < c->len; d += 1.0) {
                    double px = (double)x - d * ux, py = (double)y - d * uy, h;
                    if (px < -HF_LATTICE_EPS || py < -HF_LATTICE_EPS || px > xmax || py > ymax) {
                        if (out == sw->preroll) break;
                        out++;
                    }
                    px = px < 0.0 && px > -HF_LATTICE_EPS ? 0.0 : px; /* as hf_march_slopes */
                    py = py < 0.0 && py > -HF_LATTICE_EPS ? 0.0 : py;
                    h = hf_sample_border(g, sw->border, px, py) * inv_cs;
                    if (isnan(h)) continue;
                    c->ld[n] = -d;
                    c->lh[n] = h;
                    if (cc) hf_sample_channels(g, sw->border, c->exit, cc, px, py, c->le + (size_t)n * (size_t)cc);
                    c->vis[n] = out > 0; /* outside the grid: a pre-roll sample */
                    n++;
                }
                c->npre = 0;
                for (i = 0; i < n / 2; i++) { /* far first, as a lattice line */
                    int j = n - 1 - i, t, e;
                    double v = c->ld[i];
                    c->ld[i] = c->ld[j];
                    c->ld[j] = v;
                    v = c->lh[i];
                    c->lh[i] = c->lh[j];
                    c->lh[j] = v;
                    t = c->vis[i];
                    c->vis[i] = c->vis[j];
                    c->vis[j] = t;
                    for (e = 0; e < cc; e++) {
                        v = c->le[(size_t)i * (size_t)cc + (size_t)e];
                        c->le[(size_t)i * (size_t)cc + (size_t)e] = c->le[(size_t)j * (size_t)cc + (size_t)e];
                        c->le[(size_t)j * (size_t)cc + (size_t)e] = v;
                    }
                }
                for (i = 0; i < n; i++) c->npre += c->vis[i];
                c->ld[n] = 0.0;
                c->lh[n] = (double)g->z[(ptrdiff_t)y * g->stride + x] * inv_cs;
                for (i = 0; i <= n; i++) {
                    c->wd[i] = c->ld[i] * g->cell_size;
                    c->wh[i] = c->lh[i] * g->cell_size;
                }
                nv = hf_visible_naive(c->ld, c->lh, n, c->win, c->vis, c->len);
                c->fn(sw, c, 0, n, c->vis, nv, c->hz, 0);
            }
            sw->lat = lat;
            sw->nrm = nrm;
            for (q = 0; q < ch; q++) acc[q] = one[q];
        }
    c->st = st;
}

static hfvis_status hf_p2_run(hf_sweep *sw, const hfvis_grid *grid, int K, hfvis_sweep_options *o,
                              int out_channels, int want_normals, hf_p2_ctx *c)
{
    hfvis_status s;
    int ok = 1;
    if (o->rays == HFVIS_RAYS_EXACT) return HFVIS_ERR_INVALID_ARGUMENT; /* lattices only (hfvis.h) */
    if (hf_p2_opts_limited(o)) return HFVIS_ERR_INVALID_ARGUMENT;
    /* The radius is the tree consumers' (hf_p2_orient: floor(R / cell) node steps, as the
     * lattice sweep's window); the shared driver then runs exactly as without it. */
    c->win = hf_radius_on(o) ? (double)hf_radius_units(o->max_distance / grid->cell_size) : -1.0;
    o->max_distance = 0.0;
    if (c->tree_opts && (c->tree_opts->order < HFVIS_TREE_DEFAULT ||
                         c->tree_opts->order > HFVIS_TREE_BREADTH_FIRST || c->tree_opts->safe_zone < 0 ||
                         c->tree_opts->safe_zone > 1 || c->tree_opts->safe_zone_steps < 0))
        return HFVIS_ERR_INVALID_ARGUMENT;
    c->f.extra_size = hf_p2_extra_size(grid, o, c->channels, &c->len, &ok);
    if (!ok) return HFVIS_ERR_LIMIT;
    c->f.group = hf_p2_group;
    c->f.orient = hf_p2_orient;
    if ((s = hf_fused_run(sw, grid, K, o, out_channels, want_normals, NULL, &c->f)) != HFVIS_OK) return s;
    if (!c->user_fn) hf_p2_stranded(sw, K, o, c); /* the gathered outputs (not the events) */
    return HFVIS_OK;
}

/* Consumer: visible in-grid samples per receiver (the visibility index). */
static void hf_p2_count(hf_sweep *sw, hf_p2_ctx *c, ptrdiff_t node, int s, const int *vis, int nv,
                        const int *hz, int nh)
{
    int i, n = 0;
    (void)s;
    (void)hz;
    (void)nh;
    for (i = 0; i < nv; i++) n += vis[i] >= c->npre;
    c->st.visible += (double)nv;
    sw->lat[node] += (double)n;
}

/* Consumer: the user's callback with the receiver's minimal horizons and visible samples. */
static void hf_p2_event(hf_sweep *sw, hf_p2_ctx *c, ptrdiff_t node, int s, const int *vis, int nv,
                        const int *hz, int nh)
{
    hfvis_visibility_event e;
    int i, m = 0;
    const int cols = sw->cols;
    c->st.visible += (double)nv;
    for (i = 0; i < nh; i++) /* within the radius; the minimal filter of docs/errata.md E14 */
        if (hz[i] >= c->qmin && (hz[i] == 0 || hf_slope_from(c->ld, c->lh, s, hz[i] - 1) < hf_slope_from(c->ld, c->lh, s, hz[i])))
            c->hz[m++] = hz[i];
    e.k = c->f.k;
    hf_node_pos(&sw->L, (int)(node % cols) + sw->L.i_min, (int)(node / cols) + sw->L.j_min, &e.x, &e.y);
    e.distance = c->wd;
    e.height = c->wh;
    e.receiver = s;
    e.horizons = c->hz;
    e.horizon_count = m;
    e.visible = vis;
    e.visible_count = nv;
    c->user_fn(c->user, &e);
}

/* Consumer: indirect light by the band rule of docs/errata.md E17. With W(t) the tangent-clamped [P1]
 * Eq. 5 sector integral up to the zenith angle of slope t (hf_sky_term), the visible samples
 * s_1..s_M (far to near, slopes non-increasing) own the bands [W(t_j), W(t_{j+1})], the last up
 * to the tangent plane W(-inf); the sky owns [0, W(t_1)]. The sum telescopes: uniform radiance c
 * everywhere gives c W(-inf) = c S_k(c_k), the furnace identity (docs/errata.md E17). */
static void hf_p2_indirect(hf_sweep *sw, hf_p2_ctx *c, ptrdiff_t node, int s, const int *vis,
                           int nv, const int *hz, int nh)
{
    const float *nr = sw->nrm + node * 3;
    double nz = (double)nr[2], a = (double)nr[0] * c->f.lx + (double)nr[1] * c->f.ly;
    double w_prev, acc[4] = {0.0, 0.0, 0.0, 0.0};
    int j, ch = c->channels, q;
    (void)hz;
    (void)nh;
    c->st.visible += (double)nv;
    if (isnan(nz)) {
        for (q = 0; q < ch; q++) sw->lat[node * ch + q] += HFVIS__NAN;
        return;
    }
    w_prev = nv ? hf_sky_term(hf_slope_from(c->ld, c->lh, s, vis[0]), nz, a, c->inv_k, c->lobe)
                : hf_sky_term(-HFVIS__INF, nz, a, c->inv_k, c->lobe);
    for (q = 0; q < ch; q++) acc[q] = c->sky * w_prev;
    for (j = 0; j < nv; j++) {
        double w_next = j + 1 < nv
                            ? hf_sky_term(hf_slope_from(c->ld, c->lh, s, vis[j + 1]), nz, a, c->inv_k, c->lobe)
                            : hf_sky_term(-HFVIS__INF, nz, a, c->inv_k, c->lobe);
        const double *L = c->le + (size_t)vis[j] * (size_t)ch;
        for (q = 0; q < ch; q++) acc[q] += L[q] * (w_next - w_prev);
        w_prev = w_next;
    }
    for (q = 0; q < ch; q++) sw->lat[node * ch + q] += acc[q];
}

static int hf_tree_opts_valid(const hfvis_tree_options *t)
{
    return !t || (t->order >= HFVIS_TREE_DEFAULT && t->order <= HFVIS_TREE_BREADTH_FIRST &&
                  t->safe_zone >= 0 && t->safe_zone <= 1 && t->safe_zone_steps >= 0);
}

hfvis_status hfvis_intervisibility(const hfvis_grid *grid, int K, const hfvis_sweep_options *opts,
                                   const hfvis_tree_options *tree_opts, hfvis_visibility_fn fn,
                                   void *user, hfvis_visibility_stats *stats)
{
    hfvis_sweep_options o;
    hf_sweep sw;
    hf_p2_ctx c;
    hfvis_status s;
    if (hf_check_common(grid, opts) != HFVIS_OK || K < 1 || !fn || !hf_tree_opts_valid(tree_opts))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (hf_p2_opts_limited(opts)) return HFVIS_ERR_INVALID_ARGUMENT; /* no windows here */
    o = hf_opts_resolve(grid, opts);
    memset(&c, 0, sizeof c);
    c.tree_opts = tree_opts;
    c.fn = hf_p2_event;
    c.user_fn = fn;
    c.user = user;
    if ((s = hf_p2_run(&sw, grid, K, &o, 1, 0, &c)) != HFVIS_OK) return s;
    hf_sweep_free(&sw);
    if (stats) *stats = c.st;
    return HFVIS_OK;
}

static hfvis_status hf_visibility_count(const hfvis_grid *grid, int K, const hfvis_sweep_options *opts,
                                        const hfvis_tree_options *tree_opts, int naive, float *out,
                                        ptrdiff_t out_stride, hfvis_visibility_stats *stats)
{
    hfvis_sweep_options o;
    hf_sweep sw;
    hf_p2_ctx c;
    hfvis_status s;
    if (!hf_light_args_valid(grid, K, opts, out, out_stride) || !hf_tree_opts_valid(tree_opts))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (hf_p2_opts_limited(opts)) return HFVIS_ERR_INVALID_ARGUMENT; /* no windows here */
    o = hf_opts_resolve(grid, opts);
    memset(&c, 0, sizeof c);
    c.tree_opts = tree_opts;
    c.naive = naive;
    c.fn = hf_p2_count;
    if ((s = hf_p2_run(&sw, grid, K, &o, 1, 0, &c)) != HFVIS_OK) return s;
    hf_fused_output(&sw, 1.0, 0.0, out, out_stride, 1);
    hf_sweep_free(&sw);
    if (stats) *stats = c.st;
    return HFVIS_OK;
}

hfvis_status hfvis_visibility_count(const hfvis_grid *grid, int K, const hfvis_sweep_options *opts,
                                    const hfvis_tree_options *tree_opts, float *out,
                                    ptrdiff_t out_stride, hfvis_visibility_stats *stats)
{
    return hf_visibility_count(grid, K, opts, tree_opts, 0, out, out_stride, stats);
}

hfvis_status hfvis_visibility_count_naive(const hfvis_grid *grid, int K,
                                          const hfvis_sweep_options *opts, float *out,
                                          ptrdiff_t out_stride, hfvis_visibility_stats *stats)
{
    return hf_visibility_count(grid, K, opts, NULL, 1, out, out_stride, stats);
}

static hfvis_status hf_indirect(const hfvis_grid *grid, int K, const float *exit_radiance,
                                int channels, float sky, float albedo, const hfvis_sweep_options *opts,
                                const hfvis_tree_options *tree_opts, int naive, float *out,
                                ptrdiff_t out_stride)
{
    hfvis_sweep_options o;
    hf_sweep sw;
    hf_p2_ctx c;
    hfvis_status s;
    if (!hf_light_args_valid(grid, K, opts, out, out_stride) || !hf_tree_opts_valid(tree_opts) ||
        !exit_radiance || channels < 1 || channels > 4 || !isfinite(sky) || !isfinite(albedo))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (hf_p2_opts_limited(opts)) return HFVIS_ERR_INVALID_ARGUMENT; /* no windows here */
    o = hf_opts_resolve(grid, opts);
    memset(&c, 0, sizeof c);
    c.tree_opts = tree_opts;
    c.naive = naive;
    c.fn = hf_p2_indirect;
    c.exit = exit_radiance;
    c.channels = channels;
    c.sky = (double)sky;
    c.inv_k = 1.0 / (double)K;
    c.lobe = sin(HFVIS__PI / (double)K) / HFVIS__PI;
    if ((s = hf_p2_run(&sw, grid, K, &o, channels, 1, &c)) != HFVIS_OK) return s;
    hf_fused_output(&sw, (double)albedo, 0.0, out, out_stride, channels);
    hf_sweep_free(&sw);
    return HFVIS_OK;
}

hfvis_status hfvis_indirect_light(const hfvis_grid *grid, int K, const float *exit_radiance,
                                  int channels, float sky, float albedo,
                                  const hfvis_sweep_options *opts,
                                  const hfvis_tree_options *tree_opts, float *out,
                                  ptrdiff_t out_stride)
{
    return hf_indirect(grid, K, exit_radiance, channels, sky, albedo, opts, tree_opts, 0, out, out_stride);
}

hfvis_status hfvis_indirect_light_naive(const hfvis_grid *grid, int K, const float *exit_radiance,
                                        int channels, float sky, float albedo,
                                        const hfvis_sweep_options *opts, float *out,
                                        ptrdiff_t out_stride)
{
    return hf_indirect(grid, K, exit_radiance, channels, sky, albedo, opts, NULL, 1, out, out_stride);
}

hfvis_status hfvis_terrain_gi(const hfvis_grid *grid, int K, const float *direct,
                              const float *emission, const float *albedo_map, float albedo_value,
                              int channels, int bounces, const hfvis_sweep_options *opts,
                              const hfvis_tree_options *tree_opts, float *out)
{
    size_t n, i, total;
    float *exit_b, *ind;
    const hfvis_allocator *alloc = opts ? opts->alloc : NULL;
    int b, c;
    hfvis_status s = HFVIS_OK;
    if (!hf_grid_valid(grid) || !direct || !out || channels < 1 || channels > 4 || bounces < 0 ||
        K < 1 || !isfinite(albedo_value) || !hf_opts_valid(opts) || !hf_tree_opts_valid(tree_opts))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (hf_p2_opts_limited(opts)) return HFVIS_ERR_INVALID_ARGUMENT; /* no windows here */
    if (!hfvis__mul_size(hf_grid_count(grid), (size_t)channels, &total)) return HFVIS_ERR_INVALID_ARGUMENT;
    n = hf_grid_count(grid);
    exit_b = (float *)hfvis__alloc_array(alloc, total, sizeof(float));
    ind = (float *)hfvis__alloc_array(alloc, total, sizeof(float));
    if (!exit_b || !ind) {
        hfvis__free(alloc, ind);
        hfvis__free(alloc, exit_b);
        return HFVIS_ERR_OUT_OF_MEMORY;
    }
    /* L_0 = emission + albedo * direct */
    for (i = 0; i < n; i++)
        for (c = 0; c < channels; c++) {
            size_t q = i * (size_t)channels + (size_t)c;
            double rho = albedo_map ? (double)albedo_map[q] : (double)albedo_value;
            exit_b[q] = (float)((emission ? (double)emission[q] : 0.0) + rho * (double)direct[q]);
        }
    /* L_{b+1} = emission + albedo * (direct + I[L_b]) ([P2] §10.1: repeat the indirect pass
     * with the previous output as the surface radiance) */
    for (b = 0; b < bounces && s == HFVIS_OK; b++) {
        s = hf_indirect(grid, K, exit_b, channels, 0.0f, 1.0f, opts, tree_opts, 0, ind, grid->width);
        if (s != HFVIS_OK) break;
        for (i = 0; i < n; i++)
            for (c = 0; c < channels; c++) {
                size_t q = i * (size_t)channels + (size_t)c;
                double rho = albedo_map ? (double)albedo_map[q] : (double)albedo_value;
                double e = emission ? (double)emission[q] : 0.0;
                exit_b[q] = (float)(e + rho * ((double)direct[q] + (double)ind[q]));
            }
    }
    if (s == HFVIS_OK) memcpy(out, exit_b, total * sizeof(float));
    hfvis__free(alloc, ind);
    hfvis__free(alloc, exit_b);
    return s;
}

/* Direct light (see hfvis.h): the sun's Lambert term times its visibility, plus the sky. */
hfvis_status hfvis_direct_light(const hfvis_grid *grid, int K, const hfvis_sun *sun, float sky,
                                const hfvis_env *env, int channels, const hfvis_sweep_options *opts,
                                float *out)
{
    const hfvis_allocator *alloc = opts ? opts->alloc : NULL;
    size_t n, i, total;
    float *plane;
    hfvis_status s;
    int c, rx0 = 0, ry0 = 0, rx1 = 0, ry1 = 0, x, y;
    if (!hf_grid_valid(grid) || K < 1 || !out || channels < 1 || channels > 4 || !isfinite(sky) ||
        !hf_opts_valid(opts) || (opts && !hf_tile_fits(grid, opts)) ||
        (env && (!hf_env_valid(env) || env->channels != channels)))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (opts) hf_receiver_rect(grid, opts, &rx0, &ry0, &rx1, &ry1);
    else {
        rx1 = grid->width;
        ry1 = grid->height;
    }
    if (sun) {
        if (!isfinite(sun->azimuth_rad) || !isfinite(sun->elevation_rad) || !isfinite(sun->radius_rad) ||
            sun->radius_rad < 0.0 || fabs(sun->elevation_rad) > HFVIS__HALF_PI)
            return HFVIS_ERR_INVALID_ARGUMENT;
        for (c = 0; c < channels; c++)
            if (!isfinite(sun->irradiance[c])) return HFVIS_ERR_INVALID_ARGUMENT;
    }
    n = hf_grid_count(grid);
    if (!hfvis__mul_size(n, (size_t)channels, &total)) return HFVIS_ERR_INVALID_ARGUMENT;
    plane = (float *)hfvis__alloc_array(alloc, total, sizeof(float));
    if (!plane) return HFVIS_ERR_OUT_OF_MEMORY;
    /* sky part, written to plane first so that out stays untouched on failure */
    if (env) s = hfvis_env_light(grid, K, env, 1.0f, opts, NULL, plane, grid->width);
    else {
        s = hfvis_sky_light(grid, K, sky, 1.0f, opts, plane, grid->width);
        for (y = ry1; s == HFVIS_OK && y-- > ry0;) /* spread the one channel, back to front */
            for (x = rx1; x-- > rx0;) {
                i = (size_t)y * (size_t)grid->width + (size_t)x;
                for (c = channels - 1; c >= 0; c--) plane[i * (size_t)channels + (size_t)c] = plane[i];
            }
    }
    if (s == HFVIS_OK && sun) {
        float *vis = (float *)hfvis__alloc_array(alloc, n, sizeof(float));
        if (!vis) s = HFVIS_ERR_OUT_OF_MEMORY;
        else {
            s = hfvis_sun_visibility(grid, sun->azimuth_rad, sun->elevation_rad, sun->radius_rad, opts,
                                     vis, grid->width);
            if (s == HFVIS_OK) {
                double lx = cos(sun->elevation_rad) * cos(sun->azimuth_rad);
                double ly = cos(sun->elevation_rad) * sin(sun->azimuth_rad), lz = sin(sun->elevation_rad);
                for (y = ry0; y < ry1; y++) /* the receiver rectangle */
                    for (x = rx0; x < rx1; x++) {
                        double nrm[3], cosl;
                        size_t q = (size_t)y * (size_t)grid->width + (size_t)x;
                        hf_normal_at(grid, x, y, nrm);
                        cosl = nrm[0] * lx + nrm[1] * ly + nrm[2] * lz;
                        if (cosl < 0.0) cosl = 0.0;
                        for (c = 0; c < channels; c++)
                            plane[q * (size_t)channels + (size_t)c] +=
                                (float)((double)sun->irradiance[c] / HFVIS__PI * cosl * (double)vis[q]);
                    }
            }
            hfvis__free(alloc, vis);
        }
    }
    if (s == HFVIS_OK) /* the receiver rectangle; the rest of out is left as it was */
        for (y = ry0; y < ry1; y++) {
            size_t q = ((size_t)y * (size_t)grid->width + (size_t)rx0) * (size_t)channels;
            memcpy(out + q, plane + q, (size_t)(rx1 - rx0) * (size_t)channels * sizeof(float));
        }
    hfvis__free(alloc, plane);
    return s;
}

/* ========================================================================================== */
/* 12. Viewshed: one observer, R2 ray casting (Franklin & Ray 1994) and the exact-LOS oracle  */
/* ========================================================================================== */
/* [FR94] W. R. Franklin and C. K. Ray, "Higher isn't necessarily better: visibility algorithms
 * and experiments", 6th Int. Symposium on Spatial Data Handling, 1994, algorithm R2: instead of
 * one line of sight per target, cast one ray to each cell of the perimeter and decide every cell
 * the ray crosses on the way with the running maximum of the slopes seen so far.
 *
 * Geometry shared by both routines (hfvis conventions: samples at integer grid positions,
 * bilinear surface in between, holes never occlude). The eye is E = (ox, oy, surface(ox, oy) +
 * observer_height); the target of grid point (x, y) is (x, y, z(x, y) + target_height). A point
 * of height h at horizontal distance d from the observer is seen under the slope (h - h_eye)/d.
 * Distances stay in cells: multiplying every horizontal distance by cell_size divides every
 * slope by cell_size and changes no comparison, so cell_size only converts max_distance.
 * Tie rule: grazing is visible, as hfvis_line_visible_naive, and "grazing" includes rounding:
 * every occluder is lowered by tol = HF_VS_GRAZE_ULPS * DBL_EPSILON * scale (scale the largest
 * height involved, |h_eye| or max |z| + target_height), so a sight line lying on a plane
 * (flat or tilted, eye on the surface) stays visible whatever the bilinear rounding. The bound:
 * a bilinear height is off by <= 4 eps*max|z|, the slope's subtraction and division by about
 * 2 eps*scale/d more, the target's slope alike; 32 eps*scale/d covers them with room (the
 * plane tests need 4; 0 fails them).
 * Range: a grid point is in range iff its squared distance to the observer (cells) is
 * <= (max_distance/cell_size)^2; the same test in both routines. */

#define HF_VS_STEP_DEFAULT 0.5  /* the oracle's default march step, cells (half the R2 step) */
#define HF_VS_GRAZE_ULPS 32.0   /* see the tie rule above */
#define HF_VS_END_EPS 1e-9      /* oracle samples closer than this (cells) to the target are the
                                   target itself, not an occluder (HF_LATTICE_EPS's scale) */
/* R2 keeps its per-cell bookkeeping in out itself, so it needs no scratch: while the rays run,
 * a decided cell holds +-(2 + offset), the sign the decision (+ visible) and offset in [0, 0.5]
 * the distance (cells, along the cell's row or column) from the cell centre to the sample that
 * decided it; |v| - 2 recovers the offset exactly (Sterbenz). Undecided cells hold
 * HF_VS_UNSET and cells that take no value (holes, out of range) NaN. */
#define HF_VS_BASE 2.0f
#define HF_VS_UNSET 8.0f

/* The options with their defaults (NULL = zero struct); 1 if they are valid. */
static int hf_vs_options(const hfvis_viewshed_options *opts, double cell_size, double *obs_h,
                         double *tgt_h, double *range2)
{
    hfvis_viewshed_options o;
    double r;
    if (opts) o = *opts;
    else memset(&o, 0, sizeof o);
    if (!isfinite(o.observer_height) || o.observer_height < 0.0 || !isfinite(o.target_height) ||
        o.target_height < 0.0 || !isfinite(o.max_distance) || o.max_distance < 0.0)
        return 0;
    *obs_h = o.observer_height;
    *tgt_h = o.target_height;
    r = o.max_distance / cell_size; /* may overflow to +inf: unlimited in effect */
    *range2 = o.max_distance > 0.0 ? r * r : HFVIS__INF;
    return 1;
}

static int hf_vs_args_valid(const hfvis_grid *grid, double ox, double oy, const float *out,
                            ptrdiff_t out_stride)
{
    return hf_grid_valid(grid) && out && out_stride >= grid->width &&
           (size_t)grid->height <= SIZE_MAX / (size_t)out_stride && isfinite(ox) && isfinite(oy) &&
           ox >= 0.0 && oy >= 0.0 && ox <= (double)(grid->width - 1) &&
           oy <= (double)(grid->height - 1);
}

/* Bilinear surface height (world units) at a position inside the grid; NaN on a hole. */
static double hf_vs_height(const hfvis_grid *g, double x, double y)
{
    return hf_bilerp(g->z, g->stride, g->width, g->height, hf_clampd(x, 0.0, (double)(g->width - 1)),
                     hf_clampd(y, 0.0, (double)(g->height - 1)));
}

/* Exact line of sight from the eye (ox, oy, h_eye) to the target (x, y, target_z): the bilinear
 * surface is sampled at horizontal distances d = k*step, k = 1, 2, ... while d < D (the target's
 * distance), and the target is hidden iff some sample's slope (its height lowered by the graze
 * tolerance tol) exceeds the target's. 1 = visible.
 * The observer's own position (D = 0) is visible. Cost O(D/step). */
static int hf_vs_los(const hfvis_grid *g, double ox, double oy, double h_eye, double tol, double x,
                     double y, double target_z, double step)
{
    double dx = x - ox, dy = y - oy, D = sqrt(dx * dx + dy * dy), t_slope, k;
    if (D == 0.0) return 1;
    t_slope = (target_z - h_eye) / D;
    for (k = 1.0;; k += 1.0) {
        double d = k * step, f, h;
        if (d >= D - HF_VS_END_EPS) break;
        f = d / D;
        h = hf_vs_height(g, ox + f * dx, oy + f * dy);
        if (isfinite(h) && (h - tol - h_eye) / d > t_slope) return 0; /* holes never occlude */
    }
    return 1;
}

/* First pass of both routines: NaN at holes, out of range and everywhere when the eye stands on a
 * hole; `fill` elsewhere. Returns max |z| over the finite heights (0 if none). */
static double hf_vs_prepare(const hfvis_grid *g, double ox, double oy, double range2, int eye_ok,
                          float fill, float *out, ptrdiff_t os)
{
    int x, y;
    float zmax = 0.0f;
    for (y = 0; y < g->height; y++) {
        const float *zr = g->z + (ptrdiff_t)y * g->stride;
        float *o = out + (ptrdiff_t)y * os;
        double dy = (double)y - oy;
        for (x = 0; x < g->width; x++) {
            double dx = (double)x - ox;
            int finite = isfinite(zr[x]);
            int keep = eye_ok && finite && dx * dx + dy * dy <= range2;
            if (finite && fabsf(zr[x]) > zmax) zmax = fabsf(zr[x]);
            o[x] = keep ? fill : (float)HFVIS__NAN;
        }
    }
    return (double)zmax;
}

/* The graze tolerance (tie rule above) for an eye at h_eye. */
static double hf_vs_tolerance(double zmax, double tgt_h, double h_eye)
{
    double scale = zmax + tgt_h > fabs(h_eye) ? zmax + tgt_h : fabs(h_eye);
    return HF_VS_GRAZE_ULPS * DBL_EPSILON * scale;
}

/* One R2 ray from the observer to the perimeter cell (tx, ty) ([FR94] R2). The ray is walked one
 * cell at a time along its major axis (x when |dx| >= |dy|): sample m lies where the ray crosses
 * grid line x = m (or y = m), so the bilinear surface there is the linear interpolation of the
 * two grid points on that line, and the sample is at most half a cell (along the line) from the
 * nearest grid point. For each sample, in order of increasing distance d:
 *   target slope = (h + target_height - h_eye)/d is compared with run = the largest terrain slope
 *   (h_j - tol - h_eye)/d_j of the earlier samples j (-inf for the first; tol the graze
 *   tolerance of the tie rule): visible iff >= run; then run = max(run, (h - tol - h_eye)/d).
 * The decision goes to the grid point nearest the sample on its grid line if no sample nearer
 * to that grid point has decided it yet (strictly nearer: ties keep the earlier ray in the fixed
 * perimeter order). A sample touching a hole decides nothing and does not occlude.
 * The walk stops at the perimeter cell, or once d > d_stop (max_distance + 1 cell: a sample can
 * decide an in-range cell only if d < max_distance + 1/2). */
static void hf_vs_ray(const hfvis_grid *g, double ox, double oy, double h_eye, double tgt_h,
                      double tol, double d_stop, int tx, int ty, float *out, ptrdiff_t os)
{
    double dx = (double)tx - ox, dy = (double)ty - oy;
    int xmajor = fabs(dx) >= fabs(dy);
    double maj0 = xmajor ? ox : oy, min0 = xmajor ? oy : ox;
    double dmaj = xmajor ? dx : dy, dmin = xmajor ? dy : dx;
    int end = xmajor ? tx : ty, minor_max = xmajor ? g->height - 1 : g->width - 1;
    double rate, per_unit, run = -HFVIS__INF;
    int sgn, m;
    if (dmaj == 0.0) return; /* the perimeter cell is the observer itself */
    rate = dmin / dmaj;                   /* minor advance per major cell */
    per_unit = sqrt(1.0 + rate * rate);   /* horizontal distance per major cell */
    sgn = dmaj > 0.0 ? 1 : -1;
    m = sgn > 0 ? (int)floor(maj0) + 1 : (int)ceil(maj0) - 1;
    for (; sgn > 0 ? m <= end : m >= end; m += sgn) {
        double t = (double)m - maj0, d = fabs(t) * per_unit, s, h, x, y;
        float *cell, v, off;
        int c;
        if (d > d_stop) break;
        s = hf_clampd(min0 + t * rate, 0.0, (double)minor_max);
        x = xmajor ? (double)m : s;
        y = xmajor ? s : (double)m;
        h = hf_bilerp(g->z, g->stride, g->width, g->height, x, y);
        if (!isfinite(h)) continue;
        c = (int)floor(s + 0.5);
        if (c > minor_max) c = minor_max;
        cell = xmajor ? out + (ptrdiff_t)c * os + m : out + (ptrdiff_t)m * os + c;
        v = *cell;
        off = (float)fabs(s - (double)c) + HF_VS_BASE; /* quantised like the stored value */
        if (!isnan(v) && (v == HF_VS_UNSET || off < fabsf(v)))
            *cell = (h + tgt_h - h_eye) / d >= run ? off : -off;
        if ((h - tol - h_eye) / d > run) run = (h - tol - h_eye) / d;
    }
}

hfvis_viewshed_options hfvis_viewshed_options_default(void)
{
    hfvis_viewshed_options o;
    memset(&o, 0, sizeof o); /* eye and targets on the surface, unlimited range */
    return o;
}

hfvis_status hfvis_viewshed(const hfvis_grid *grid, double observer_x, double observer_y,
                            const hfvis_viewshed_options *opts, float *out, ptrdiff_t out_stride)
{
    double obs_h, tgt_h, range2, h_eye, tol, d_stop = HFVIS__INF;
    int x0 = 0, y0 = 0, x1, y1, x, y, ix, iy;
    if (!hf_vs_args_valid(grid, observer_x, observer_y, out, out_stride) ||
        !hf_vs_options(opts, grid ? grid->cell_size : 1.0, &obs_h, &tgt_h, &range2))
        return HFVIS_ERR_INVALID_ARGUMENT;
    h_eye = hf_vs_height(grid, observer_x, observer_y) + obs_h;
    tol = hf_vs_tolerance(hf_vs_prepare(grid, observer_x, observer_y, range2, isfinite(h_eye),
                                        HF_VS_UNSET, out, out_stride), tgt_h, h_eye);
    if (!isfinite(h_eye)) return HFVIS_OK; /* the eye stands on a hole: no value anywhere */
    x1 = grid->width - 1;
    y1 = grid->height - 1;
    if (range2 < HFVIS__INF) {
        /* rays to the border of the bounding square of the range circle, clipped to the grid */
        double r = sqrt(range2), a;
        d_stop = r + 1.0;
        a = floor(observer_x - r);
        x0 = a < 0.0 ? 0 : (int)a;
        a = floor(observer_y - r);
        y0 = a < 0.0 ? 0 : (int)a;
        a = ceil(observer_x + r);
        if (a < (double)x1) x1 = (int)a;
        a = ceil(observer_y + r);
        if (a < (double)y1) y1 = (int)a;
    }
    /* "The observer itself is visible": the grid point under an observer standing exactly on one */
    ix = (int)observer_x;
    iy = (int)observer_y;
    if ((double)ix == observer_x && (double)iy == observer_y)
        out[(ptrdiff_t)iy * out_stride + ix] = HF_VS_BASE;
    /* the perimeter, each cell once, in a fixed order (rows y0, y1, then columns x0, x1) */
    for (x = x0; x <= x1; x++) {
        hf_vs_ray(grid, observer_x, observer_y, h_eye, tgt_h, tol, d_stop, x, y0, out, out_stride);
        if (y1 != y0)
            hf_vs_ray(grid, observer_x, observer_y, h_eye, tgt_h, tol, d_stop, x, y1, out, out_stride);
    }
    for (y = y0 + 1; y < y1; y++) {
        hf_vs_ray(grid, observer_x, observer_y, h_eye, tgt_h, tol, d_stop, x0, y, out, out_stride);
        if (x1 != x0)
            hf_vs_ray(grid, observer_x, observer_y, h_eye, tgt_h, tol, d_stop, x1, y, out, out_stride);
    }
    /* Resolve. A cell no sample decided takes the oracle's exact line of sight (default step),
     * so every cell gets a value. Beside holes this is common (the samples touching a hole
     * decide nothing); elsewhere the rays' coverage is not proven complete near the diagonals,
     * where x-major and y-major rays meet, but on 300 random grids (1..90 cells a side, random
     * observers and ranges) no cell away from holes was left undecided. */
    for (y = 0; y < grid->height; y++) {
        float *o = out + (ptrdiff_t)y * out_stride;
        const float *zr = grid->z + (ptrdiff_t)y * grid->stride;
        for (x = 0; x < grid->width; x++) {
            float v = o[x];
            if (isnan(v)) continue;
            if (v == HF_VS_UNSET)
                v = hf_vs_los(grid, observer_x, observer_y, h_eye, tol, (double)x, (double)y,
                              (double)zr[x] + tgt_h, HF_VS_STEP_DEFAULT) ? 1.0f : -1.0f;
            o[x] = v > 0.0f ? 1.0f : 0.0f;
        }
    }
    return HFVIS_OK;
}

hfvis_status hfvis_viewshed_reference(const hfvis_grid *grid, double observer_x, double observer_y,
                                      const hfvis_viewshed_options *opts, double step_cells,
                                      float *out, ptrdiff_t out_stride)
{
    double obs_h, tgt_h, range2, h_eye, tol, step;
    int x, y;
    if (!hf_vs_args_valid(grid, observer_x, observer_y, out, out_stride) ||
        !hf_vs_options(opts, grid ? grid->cell_size : 1.0, &obs_h, &tgt_h, &range2) ||
        !isfinite(step_cells) || step_cells < 0.0)
        return HFVIS_ERR_INVALID_ARGUMENT;
    step = step_cells > 0.0 ? step_cells : HF_VS_STEP_DEFAULT;
    h_eye = hf_vs_height(grid, observer_x, observer_y) + obs_h;
    tol = hf_vs_tolerance(hf_vs_prepare(grid, observer_x, observer_y, range2, isfinite(h_eye), 1.0f,
                                        out, out_stride), tgt_h, h_eye);
    if (!isfinite(h_eye)) return HFVIS_OK;
    for (y = 0; y < grid->height; y++) {
        float *o = out + (ptrdiff_t)y * out_stride;
        const float *zr = grid->z + (ptrdiff_t)y * grid->stride;
        for (x = 0; x < grid->width; x++)
            if (!isnan(o[x]))
                o[x] = hf_vs_los(grid, observer_x, observer_y, h_eye, tol, (double)x, (double)y,
                                 (double)zr[x] + tgt_h, step) ? 1.0f : 0.0f;
    }
    return HFVIS_OK;
}

/* ========================================================================================== */
/* 13. Nowrouzezahrai-Snyder GI: SH, Legendre, wedge matrices                                 */
/* ========================================================================================== */
/* The math layer of [NS09] D. Nowrouzezahrai, J. Snyder, "Fast Global Illumination on Dynamic
 * Height Fields", CGF 28(4), 2009: real SH of order 4 (§7), normalized Legendre polynomials and
 * the closed-form 1-D projections of visibility and indirect radiance (§4, Eq. 9-13), the
 * Appendix-A wedge matrices and the Z-rotation that turn per-azimuth NLP vectors into SH
 * (§6, Eq. 18-24), the BRDF / light ZH lobes (§7, [NS09] §6-7) and the tangent-plane minimum
 * blocking angle (§3). Errata: docs/errata.md E47-E53.
 *
 * Contents
 *   1. Real SH basis: Cartesian evaluation and the separable form K * P_l^mu(z) * Phi_m(phi)
 *   2. Exact polynomial / trigonometric integrals shared by the projections
 *   3. SH operations: Z-rotation, dot, triple-product tensor and product, ZH lobes
 *   4. Projection of a lat-long environment (exact per-texel integrals)
 *   5. Normalized Legendre polynomials and the 1-D projections (Eq. 10-13)
 *   6. Appendix-A wedge matrices and the accumulation of Eq. 21
 *   7. The tangent-plane minimum blocking angle (§3, docs/errata.md E47)
 *
 * SH convention (hfvis.h, Conventions): real, orthonormal, no Condon-Shortley phase, index l(l+1)+m,
 *   Y_lm = K_l^|m| * Pt_l^|m|(cos theta) * Phi_m(phi),  K_l^mu = sqrt((2l+1)/(4 pi) (l-mu)!/(l+mu)!),
 *   Pt_l^mu(z) = (1-z^2)^(mu/2) d^mu P_l/dz^mu (no (-1)^mu),
 *   Phi_m = sqrt2 cos(m phi) (m > 0), 1 (m = 0), sqrt2 sin(|m| phi) (m < 0),
 * with theta from +z and phi measured like psi (from +x toward +y). Compared with the quoted
 * tables (written with the Condon-Shortley phase) every value with odd |m| changes sign
 * ([NS09] §7 "library-wide alignment"); shaded values do not.
 *
 * Errata of [NS09] applied here ([NS09] §3-7): the P^_2, P^_3 constants (sqrt10/4, sqrt14/4);
 * the limits of Eq. 10 (z from -1 to sin sigma) and of Eq. 12 (z over [-1, 1]); Eq. 12's
 * "u(t_(i+1)) = 0 when i+1 >= |T|"; the canonical wedge alpha = phi/dphi of Eq. 18; m wedges on a
 * full circle (Eq. 21); M_bspl is 16x16, not 16x32; the Phong vector is a set of multipliers
 * Ahat; omega_min in the exact atan2 form by default. */

#define NS_SH_N 16          /* order-4 SH coefficients */
#define NS_NLP_N 4          /* order-4 NLP coefficients */
#define NS_SQRT2 1.41421356237309504880
#define NS_TWO_PI 6.28318530717958647692

/* ------------------------------------------------------------------------ 1. the SH basis */

/* Cartesian constants of the basis (K_l^|m| times sqrt2 for m != 0 and the polynomial's
 * leading factor), [NS09] §7 table without the Condon-Shortley signs. */
#define NS_C00 0.28209479177387814   /* 1/(2 sqrt(pi)) */
#define NS_C1 0.4886025119029199     /* sqrt(3/(4 pi)) */
#define NS_C2A 1.0925484305920792    /* sqrt(15/pi)/2: xy, yz, xz */
#define NS_C20 0.31539156525252005   /* sqrt(5/pi)/4: 3z^2 - 1 */
#define NS_C22 0.5462742152960396    /* sqrt(15/pi)/4: x^2 - y^2 */
#define NS_C33 0.5900435899266435    /* sqrt(35/(2 pi))/4: y(3x^2 - y^2), x(x^2 - 3y^2) */
#define NS_C3M2 2.890611442640554    /* sqrt(105/pi)/2: xyz */
#define NS_C31 0.4570457994644658    /* sqrt(21/(2 pi))/4: y(5z^2 - 1), x(5z^2 - 1) */
#define NS_C30 0.3731763325901154    /* sqrt(7/pi)/4: z(5z^2 - 3) */
#define NS_C32 1.445305721320277     /* sqrt(105/pi)/4: z(x^2 - y^2) */

/* Y at a unit direction (x, y, z). */
static void ns_sh_eval_unit(double x, double y, double z, double *Y)
{
    double x2 = x * x, y2 = y * y, z2 = z * z;
    Y[0] = NS_C00;
    Y[1] = NS_C1 * y;
    Y[2] = NS_C1 * z;
    Y[3] = NS_C1 * x;
    Y[4] = NS_C2A * x * y;
    Y[5] = NS_C2A * y * z;
    Y[6] = NS_C20 * (3.0 * z2 - 1.0);
    Y[7] = NS_C2A * x * z;
    Y[8] = NS_C22 * (x2 - y2);
    Y[9] = NS_C33 * y * (3.0 * x2 - y2);
    Y[10] = NS_C3M2 * x * y * z;
    Y[11] = NS_C31 * y * (5.0 * z2 - 1.0);
    Y[12] = NS_C30 * z * (5.0 * z2 - 3.0);
    Y[13] = NS_C31 * x * (5.0 * z2 - 1.0);
    Y[14] = NS_C32 * z * (x2 - y2);
    Y[15] = NS_C33 * x * (x2 - 3.0 * y2);
}

/* Normalises a finite non-zero 3-vector; 0 if it is not one. */
static int ns_unit(const double *v, double *u)
{
    double n;
    if (!isfinite(v[0]) || !isfinite(v[1]) || !isfinite(v[2])) return 0;
    n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(n > 0.0) || !isfinite(n)) return 0;
    u[0] = v[0] / n;
    u[1] = v[1] / n;
    u[2] = v[2] / n;
    return 1;
}

hfvis_status hfvis_sh_eval(const double dir[3], double Y[16])
{
    double u[3];
    if (dir == NULL || Y == NULL || !ns_unit(dir, u)) return HFVIS_ERR_INVALID_ARGUMENT;
    ns_sh_eval_unit(u[0], u[1], u[2], Y);
    return HFVIS_OK;
}

/* Ascending coefficients of d^mu P_l / dz^mu (degree l - mu <= 3), Legendre P_0..P_3. */
static void ns_legendre_deriv(int l, int mu, double q[4])
{
    static const double P[4][4] = {
        {1.0, 0.0, 0.0, 0.0}, {0.0, 1.0, 0.0, 0.0}, {-0.5, 0.0, 1.5, 0.0}, {0.0, -1.5, 0.0, 2.5}};
    int i, d;
    for (i = 0; i < 4; i++) q[i] = P[l][i];
    for (d = 0; d < mu; d++) {
        for (i = 0; i < 3; i++) q[i] = (double)(i + 1) * q[i + 1];
        q[3] = 0.0;
    }
}

/* K_l^mu of the separable form (without the sqrt2 of Phi_m). */
static double ns_sh_norm(int l, int mu)
{
    double r = 1.0;
    int i;
    for (i = l - mu + 1; i <= l + mu; i++) r /= (double)i;   /* (l-mu)!/(l+mu)! */
    return sqrt((double)(2 * l + 1) / (4.0 * HFVIS__PI) * r);
}

/* ------------------------------------------- 2. exact polynomial and trigonometric integrals */

/* Product of ascending polynomials a (degree da) and b (degree db) into r (degree da + db <= 8). */
static int ns_poly_mul(const double *a, int da, const double *b, int db, double *r)
{
    int i, j;
    for (i = 0; i <= da + db; i++) r[i] = 0.0;
    for (i = 0; i <= da; i++)
        for (j = 0; j <= db; j++) r[i + j] += a[i] * b[j];
    return da + db;
}

/* (1 - z^2)^e * q for e = 0, 1 (q of degree <= 3), into r; returns the degree. */
static int ns_poly_one_minus_z2(int e, const double *q, int dq, double *r)
{
    static const double w[3] = {1.0, 0.0, -1.0};
    int i;
    if (e == 0) {
        for (i = 0; i <= dq; i++) r[i] = q[i];
        return dq;
    }
    return ns_poly_mul(w, 2, q, dq, r);
}

/* C_k(theta) = Int_0^theta cos^k t dt for k = 0..kmax (kmax <= 9), by the reduction formula
 * C_k = cos^(k-1) sin / k + (k-1)/k C_(k-2). */
static void ns_cos_power_integrals(double theta, int kmax, double *C)
{
    double c = cos(theta), s = sin(theta), ck1 = 1.0;   /* cos^(k-1) */
    int k;
    C[0] = theta;
    if (kmax >= 1) C[1] = s;
    for (k = 2; k <= kmax; k++) {
        ck1 *= c;
        C[k] = ck1 * s / (double)k + (double)(k - 1) / (double)k * C[k - 2];
    }
}

/* Int_{theta0}^{theta1} Pt_l^mu(cos t) * p(cos t) * sin t dt for a polynomial p of degree dp
 * (p = 1 for the SH projection, p = NLP P^_k for the wedge matrices), exactly:
 *   mu even: the integrand is a polynomial in z = cos t: Int_{cos theta1}^{cos theta0} dz;
 *   mu odd:  it is sin^2 t * R(cos t) with R polynomial, and Int cos^k sin^2 = C_k - C_(k+2). */
static double ns_alp_band_integral(int l, int mu, const double *p, int dp, double theta0,
                                   double theta1)
{
    double q[4], a[9], r[9], C0[12], C1[12], sum = 0.0;
    int dq = l - mu, da, dr, k;
    ns_legendre_deriv(l, mu, q);
    da = ns_poly_one_minus_z2(mu / 2, q, dq, a);   /* (1-z^2)^floor(mu/2) d^mu P_l */
    dr = ns_poly_mul(a, da, p, dp, r);
    if (mu % 2 == 0) {
        double z0 = cos(theta0), z1 = cos(theta1), p0 = z0, p1 = z1;
        for (k = 0; k <= dr; k++) {
            sum += r[k] * (p0 - p1) / (double)(k + 1);
            p0 *= z0;
            p1 *= z1;
        }
        return sum;
    }
    ns_cos_power_integrals(theta0, dr + 2, C0);
    ns_cos_power_integrals(theta1, dr + 2, C1);
    for (k = 0; k <= dr; k++) sum += r[k] * ((C1[k] - C1[k + 2]) - (C0[k] - C0[k + 2]));
    return sum;
}

/* mc[p] = Int_0^1 a^p cos(c a) da and ms[p] = Int_0^1 a^p sin(c a) da, p = 0..3, c >= 0: the
 * power series for c <= 2 (the by-parts recurrence divides by c^p and would lose digits there),
 * the recurrence above (its error growth p!/c^p is below 1). */
static void ns_trig_moments(double c, double *mc, double *ms)
{
    int p;
    if (c <= 2.0) {
        for (p = 0; p < 4; p++) {
            double term = 1.0, sc = 0.0, ss = 0.0;   /* term = c^n / n! */
            int n;
            for (n = 0; n < 40; n++) {
                double t = term / (double)(n + p + 1);
                switch (n % 4) {
                case 0: sc += t; break;
                case 1: ss += t; break;
                case 2: sc -= t; break;
                default: ss -= t; break;
                }
                term *= c / (double)(n + 1);
            }
            mc[p] = sc;
            ms[p] = ss;
        }
        return;
    }
    mc[0] = sin(c) / c;
    ms[0] = (1.0 - cos(c)) / c;
    for (p = 1; p < 4; p++) {
        mc[p] = sin(c) / c - (double)p / c * ms[p - 1];
        ms[p] = -cos(c) / c + (double)p / c * mc[p - 1];
    }
}

/* ------------------------------------------------------------------------ 3. SH operations */

hfvis_status hfvis_sh_rotate_z(const double in[16], double angle_rad, double out[16])
{
    double t[NS_SH_N];
    int l, m, i;
    if (in == NULL || out == NULL || !isfinite(angle_rad)) return HFVIS_ERR_INVALID_ARGUMENT;
    for (i = 0; i < NS_SH_N; i++) t[i] = in[i];
    /* [NS09] §6, App. A; docs/errata.md E51: active rotation f'(phi) = f(phi - a); the (m, -m) pair turns by m a */
    for (m = 1; m <= 3; m++) {
        double c = cos((double)m * angle_rad), s = sin((double)m * angle_rad);
        for (l = m; l <= 3; l++) {
            int ip = l * (l + 1) + m, im = l * (l + 1) - m;
            double cp = t[ip], cm = t[im];
            t[ip] = cp * c - cm * s;
            t[im] = cp * s + cm * c;
        }
    }
    for (i = 0; i < NS_SH_N; i++) out[i] = t[i];
    return HFVIS_OK;
}

hfvis_status hfvis_sh_dot(const double a[16], const double b[16], double *out)
{
    double s = 0.0;
    int i;
    if (a == NULL || b == NULL || out == NULL) return HFVIS_ERR_INVALID_ARGUMENT;
    for (i = 0; i < NS_SH_N; i++) s += a[i] * b[i];
    *out = s;
    return HFVIS_OK;
}

/* Gauss-Legendre nodes and weights on [-1, 1], 8 points (exact to degree 15). */
static const double ns_gl8_x[8] = {
    -0.96028985649753623168, -0.79666647741362673959, -0.52553240991632898582,
    -0.18343464249564980494, 0.18343464249564980494, 0.52553240991632898582,
    0.79666647741362673959, 0.96028985649753623168};
static const double ns_gl8_w[8] = {
    0.10122853629037625915, 0.22238103445337447054, 0.31370664587788728734,
    0.36268378337836198297, 0.36268378337836198297, 0.31370664587788728734,
    0.22238103445337447054, 0.10122853629037625915};

/* Smallest |Gamma| kept (the non-zero entries are >= 0.058; the quadrature's rounding noise on
 * the zero ones is ~1e-17). */
#define NS_GAMMA_ZERO 1e-12

hfvis_status hfvis_sh_product_tensor(double *gamma)
{
    /* [NS09] §7: Gamma_ijk = Int Y_i Y_j Y_k. The integrand is a trigonometric polynomial of
     * degree <= 9 in phi (uniform 16-point rule exact) and, once phi is integrated, a
     * polynomial of degree <= 9 in z (8-point Gauss-Legendre exact to degree 15). */
    int a, b, i, j, k;
    if (gamma == NULL) return HFVIS_ERR_INVALID_ARGUMENT;
    for (i = 0; i < NS_SH_N * NS_SH_N * NS_SH_N; i++) gamma[i] = 0.0;
    /* accumulate i <= j <= k only, then copy to the 6 permutations: exactly symmetric */
    for (a = 0; a < 8; a++) {
        double z = ns_gl8_x[a], s = sqrt(1.0 - z * z);
        for (b = 0; b < 16; b++) {
            double phi = NS_TWO_PI * (double)b / 16.0, Y[NS_SH_N];
            double w = ns_gl8_w[a] * NS_TWO_PI / 16.0;
            ns_sh_eval_unit(s * cos(phi), s * sin(phi), z, Y);
            for (i = 0; i < NS_SH_N; i++)
                for (j = i; j < NS_SH_N; j++) {
                    double wij = w * Y[i] * Y[j];
                    for (k = j; k < NS_SH_N; k++) gamma[(i * NS_SH_N + j) * NS_SH_N + k] += wij * Y[k];
                }
        }
    }
    for (i = 0; i < NS_SH_N; i++)
        for (j = i; j < NS_SH_N; j++)
            for (k = j; k < NS_SH_N; k++) {
                double g = gamma[(i * NS_SH_N + j) * NS_SH_N + k];
                if (fabs(g) < NS_GAMMA_ZERO) g = 0.0;
                gamma[(i * NS_SH_N + j) * NS_SH_N + k] = g;
                gamma[(i * NS_SH_N + k) * NS_SH_N + j] = g;
                gamma[(j * NS_SH_N + i) * NS_SH_N + k] = g;
                gamma[(j * NS_SH_N + k) * NS_SH_N + i] = g;
                gamma[(k * NS_SH_N + i) * NS_SH_N + j] = g;
                gamma[(k * NS_SH_N + j) * NS_SH_N + i] = g;
            }
    return HFVIS_OK;
}

hfvis_status hfvis_sh_product(const double *gamma, const double a[16], const double b[16],
                              double out[16])
{
    double t[NS_SH_N];
    int i, j, k;
    if (gamma == NULL || a == NULL || b == NULL || out == NULL) return HFVIS_ERR_INVALID_ARGUMENT;
    for (k = 0; k < NS_SH_N; k++) t[k] = 0.0;
    for (i = 0; i < NS_SH_N; i++) {
        if (a[i] == 0.0) continue;
        for (j = 0; j < NS_SH_N; j++) {
            const double *g = gamma + (i * NS_SH_N + j) * NS_SH_N;
            double ab = a[i] * b[j];
            for (k = 0; k < NS_SH_N; k++)
                if (g[k] != 0.0) t[k] += g[k] * ab;
        }
    }
    for (k = 0; k < NS_SH_N; k++) out[k] = t[k];
    return HFVIS_OK;
}

static int ns_ahat_valid(const double *Ahat)
{
    int l;
    for (l = 0; l < NS_NLP_N; l++)
        if (!isfinite(Ahat[l])) return 0;
    return 1;
}

hfvis_status hfvis_sh_convolve_zh(const double in[16], const double Ahat[4], double out[16])
{
    int l, i;
    if (in == NULL || Ahat == NULL || out == NULL || !ns_ahat_valid(Ahat))
        return HFVIS_ERR_INVALID_ARGUMENT;
    /* Funk-Hecke: a circularly symmetric kernel scales band l by Ahat_l ([NS09] §7) */
    for (l = 0; l < 4; l++)
        for (i = l * l; i < (l + 1) * (l + 1); i++) out[i] = Ahat[l] * in[i];
    return HFVIS_OK;
}

hfvis_status hfvis_sh_from_zh(const double Ahat[4], const double axis[3], double out[16])
{
    double u[3], Y[NS_SH_N];
    int l, i;
    if (Ahat == NULL || axis == NULL || out == NULL || !ns_ahat_valid(Ahat) || !ns_unit(axis, u))
        return HFVIS_ERR_INVALID_ARGUMENT;
    /* [NS09] §7: F_lm = Ahat_l Y_lm(a) = sqrt(4 pi/(2l+1)) z_l Y_lm(a) ([NS09] §7, [SLS05]) */
    ns_sh_eval_unit(u[0], u[1], u[2], Y);
    for (l = 0; l < 4; l++)
        for (i = l * l; i < (l + 1) * (l + 1); i++) out[i] = Ahat[l] * Y[i];
    return HFVIS_OK;
}

hfvis_status hfvis_sh_shade_zh(const double Ahat[4], const double axis[3], const double I[16],
                               double *out)
{
    double F[NS_SH_N], s = 0.0;
    int i;
    if (I == NULL || out == NULL) return HFVIS_ERR_INVALID_ARGUMENT;
    if (hfvis_sh_from_zh(Ahat, axis, F) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    for (i = 0; i < NS_SH_N; i++) s += F[i] * I[i];
    *out = s;
    return HFVIS_OK;
}

hfvis_status hfvis_zh_diffuse(double Ahat[4])
{
    if (Ahat == NULL) return HFVIS_ERR_INVALID_ARGUMENT;
    /* 2 pi Int_0^1 z P_l(z) dz: the clamped cosine's raw ZH (sqrt(pi)/2, sqrt(pi/3),
     * sqrt(5 pi)/8, 0) of [NS09] §7 times sqrt(4 pi/(2l+1)) */
    Ahat[0] = HFVIS__PI;
    Ahat[1] = 2.0 * HFVIS__PI / 3.0;
    Ahat[2] = HFVIS__PI / 4.0;
    Ahat[3] = 0.0;
    return HFVIS_OK;
}

hfvis_status hfvis_zh_phong(double S, double Ahat[4])
{
    int l;
    if (Ahat == NULL || !isfinite(S) || !(S > 0.0)) return HFVIS_ERR_INVALID_ARGUMENT;
    /* [NS09] §7 citing [RH02]: e^(-l^2/(2S)); docs/errata.md E52: these are multipliers Ahat */
    for (l = 0; l < 4; l++) Ahat[l] = exp(-(double)(l * l) / (2.0 * S));
    return HFVIS_OK;
}

hfvis_status hfvis_zh_cap(double half_angle_rad, double Ahat[4])
{
    double c, P[5];
    int l;
    if (Ahat == NULL || !isfinite(half_angle_rad) || half_angle_rad < 0.0 || half_angle_rad > HFVIS__PI)
        return HFVIS_ERR_INVALID_ARGUMENT;
    /* [NS09] §6: Ahat_l = 2 pi Int_c^1 P_l = 2 pi (P_(l-1)(c) - P_(l+1)(c))/(2l+1), P_-1 := 1 */
    c = cos(half_angle_rad);
    P[0] = 1.0;
    P[1] = c;
    P[2] = (3.0 * c * c - 1.0) / 2.0;
    P[3] = (5.0 * c * c - 3.0) * c / 2.0;
    P[4] = ((35.0 * c * c - 30.0) * c * c + 3.0) / 8.0;
    Ahat[0] = NS_TWO_PI * (1.0 - c);
    for (l = 1; l < 4; l++) Ahat[l] = NS_TWO_PI * (P[l - 1] - P[l + 1]) / (double)(2 * l + 1);
    return HFVIS_OK;
}

/* ------------------------------------------------- 4. lat-long environment projection (B.8) */

/* Columns whose phi-integrals are held at once (a block of 64 x 7 doubles on the stack): the
 * trigonometric calls then cost O(n_phi) per map and the theta-integrals O(n_theta) per block. */
#define NS_ENV_BLOCK 64

/* Phi-integrals of Phi_m over the columns p0 .. p0+nb-1 of a map with P columns (column p is
 * [2 pi p/P, 2 pi (p+1)/P]): F[b][m + 3], m = -3..3. Each edge's sines and cosines are taken once
 * and shared by the two columns that meet there. */
static void ns_env_phi_block(int p0, int nb, int P, double (*F)[7])
{
    double sl[3], cl[3], sr[3], cr[3], phl, phr;
    int b, m;
    phl = NS_TWO_PI * (double)p0 / (double)P;
    for (m = 1; m <= 3; m++) {
        sl[m - 1] = sin((double)m * phl);
        cl[m - 1] = cos((double)m * phl);
    }
    for (b = 0; b < nb; b++) {
        phr = NS_TWO_PI * (double)(p0 + b + 1) / (double)P;
        F[b][3] = phr - phl;
        for (m = 1; m <= 3; m++) {
            sr[m - 1] = sin((double)m * phr);
            cr[m - 1] = cos((double)m * phr);
            F[b][3 + m] = NS_SQRT2 * (sr[m - 1] - sl[m - 1]) / (double)m;
            F[b][3 - m] = NS_SQRT2 * (cl[m - 1] - cr[m - 1]) / (double)m;
            sl[m - 1] = sr[m - 1];
            cl[m - 1] = cr[m - 1];
        }
        phl = phr;
    }
}

hfvis_status hfvis_sh_project_env(const hfvis_env *env, double *out)
{
    static const double one[1] = {1.0};
    double acc[4][NS_SH_N], F[NS_ENV_BLOCK][7];
    size_t n;
    int T, P, C, t, p0, nb, b, c, l, m, i;
    if (env == NULL || out == NULL || env->radiance == NULL || env->n_theta < 1 ||
        env->n_phi < 1 || env->channels < 1 || env->channels > 4 ||
        !hfvis__mul_size((size_t)env->n_theta, (size_t)env->n_phi, &n) ||
        !hfvis__mul_size(n, (size_t)env->channels, &n) || !hf_env_size_ok(env))
        return HFVIS_ERR_INVALID_ARGUMENT;
    T = env->n_theta;
    P = env->n_phi;
    C = env->channels;
    for (c = 0; c < C; c++)
        for (i = 0; i < NS_SH_N; i++) acc[c][i] = 0.0;
    /* Int_texel Y_lm = K_l^|m| [Int Pt_l^|m|(cos t) sin t dt] [Int Phi_m dphi], both exact */
    for (p0 = 0; p0 < P; p0 += NS_ENV_BLOCK) {
        nb = P - p0 < NS_ENV_BLOCK ? P - p0 : NS_ENV_BLOCK;
        ns_env_phi_block(p0, nb, P, F);
        for (t = 0; t < T; t++) {
            double th0 = HFVIS__PI * (double)t / (double)T, th1 = HFVIS__PI * (double)(t + 1) / (double)T;
            double row[4][7], band[4][4];
            const float *L = env->radiance + ((size_t)t * (size_t)P + (size_t)p0) * (size_t)C;
            for (c = 0; c < C; c++)
                for (m = 0; m < 7; m++) row[c][m] = 0.0;
            for (b = 0; b < nb; b++)
                for (c = 0; c < C; c++) {
                    double v = (double)L[(size_t)b * (size_t)C + (size_t)c];
                    for (m = 0; m < 7; m++) row[c][m] += v * F[b][m];
                }
            for (l = 0; l < 4; l++)
                for (m = 0; m <= l; m++)
                    band[l][m] = ns_sh_norm(l, m) * ns_alp_band_integral(l, m, one, 0, th0, th1);
            for (c = 0; c < C; c++)
                for (l = 0; l < 4; l++)
                    for (m = -l; m <= l; m++)
                        acc[c][l * (l + 1) + m] += band[l][m < 0 ? -m : m] * row[c][m + 3];
        }
    }
    for (c = 0; c < C; c++)
        for (i = 0; i < NS_SH_N; i++) out[c * NS_SH_N + i] = acc[c][i];
    return HFVIS_OK;
}

/* ------------------------------------------------------- 5. normalized Legendre polynomials */

/* sqrt((2l+1)/2), the NLP normalisation ([NS09] §4, Eq. 9-13; docs/errata.md E48, E49). */
#define NS_NLP0 0.70710678118654752440   /* sqrt(1/2) */
#define NS_NLP1 1.22474487139158904910   /* sqrt(3/2) */
#define NS_NLP2 1.58113883008418966600   /* sqrt(5/2) */
#define NS_NLP3 1.87082869338697069279   /* sqrt(7/2) */

/* Ascending coefficients of P^_k (degree k), docs/errata.md E48, E49 (sqrt10/4, sqrt14/4). */
static void ns_nlp_poly(int k, double q[4])
{
    static const double norm[4] = {NS_NLP0, NS_NLP1, NS_NLP2, NS_NLP3};
    int i;
    ns_legendre_deriv(k, 0, q);
    for (i = 0; i < 4; i++) q[i] *= norm[k];
}

hfvis_status hfvis_nlp_eval(double z, double P[4])
{
    if (P == NULL || !isfinite(z) || z < -1.0 || z > 1.0) return HFVIS_ERR_INVALID_ARGUMENT;
    P[0] = NS_NLP0;
    P[1] = NS_NLP1 * z;
    P[2] = NS_NLP2 * (3.0 * z * z - 1.0) / 2.0;
    P[3] = NS_NLP3 * (5.0 * z * z - 3.0) * z / 2.0;
    return HFVIS_OK;
}

/* vbar(sigma) = Int_{-1}^{sin sigma} P^(z) dz ([NS09] Eq. 10 with the limits of §4, Eq. 9-13; docs/errata.md E48, E49),
 * from Int_{-1}^s P_l = (P_(l+1)(s) - P_(l-1)(s))/(2l+1); sigma is clamped to [-pi/2, pi/2]. */
static void ns_vbar(double sigma, double *v)
{
    double s, s2;
    if (sigma <= -HFVIS__HALF_PI) s = -1.0;
    else if (sigma >= HFVIS__HALF_PI) s = 1.0;
    else s = sin(sigma);
    s2 = s * s;
    v[0] = NS_NLP0 * (s + 1.0);
    v[1] = NS_NLP1 * (s2 - 1.0) / 2.0;
    v[2] = NS_NLP2 * (s2 - 1.0) * s / 2.0;
    v[3] = NS_NLP3 * (5.0 * s2 - 1.0) * (s2 - 1.0) / 8.0;
}

hfvis_status hfvis_nlp_occlusion(double sigma_rad, double out[4])
{
    if (out == NULL || !isfinite(sigma_rad)) return HFVIS_ERR_INVALID_ARGUMENT;
    ns_vbar(sigma_rad, out);
    return HFVIS_OK;
}

hfvis_status hfvis_nlp_visibility(double omega_lo_rad, double omega_hi_rad, double out[4])
{
    double lo, hi, a[4], b[4];
    int k;
    if (out == NULL || !isfinite(omega_lo_rad) || !isfinite(omega_hi_rad))
        return HFVIS_ERR_INVALID_ARGUMENT;
    lo = omega_lo_rad < -HFVIS__HALF_PI ? -HFVIS__HALF_PI : omega_lo_rad;
    hi = omega_hi_rad > HFVIS__HALF_PI ? HFVIS__HALF_PI : omega_hi_rad;
    if (!(hi > lo)) {
        for (k = 0; k < 4; k++) out[k] = 0.0;
        return HFVIS_OK;
    }
    /* [NS09] Eq. 11, and §6's restriction to [l_min, l_max] */
    ns_vbar(hi, b);
    ns_vbar(lo, a);
    for (k = 0; k < 4; k++) out[k] = b[k] - a[k];
    return HFVIS_OK;
}

hfvis_status hfvis_nlp_radiance(int K, const double *omega_rad, const double *u,
                                double omega_min_rad, double out[4])
{
    double c[4], v[4];
    int i, k;
    if (out == NULL || K < 0 || !isfinite(omega_min_rad) ||
        (K > 0 && (omega_rad == NULL || u == NULL)))
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (i = 0; i < K; i++)
        if (!isfinite(omega_rad[i]) || !isfinite(u[i]) ||
            omega_rad[i] < (i == 0 ? omega_min_rad : omega_rad[i - 1]))
            return HFVIS_ERR_INVALID_ARGUMENT;
    for (k = 0; k < 4; k++) c[k] = 0.0;
    /* [NS09] Eq. 12 with the limits of §4, Eq. 9-13 (docs/errata.md E48, E49): the integral covers z in [-1, 1] and
     * u(t_(i+1)) = 0 once i + 1 >= |T| */
    for (i = 0; i < K; i++) {
        double du = u[i] - (i + 1 < K ? u[i + 1] : 0.0);
        ns_vbar(omega_rad[i], v);
        for (k = 0; k < 4; k++) c[k] += du * v[k];
    }
    if (K > 0) {
        ns_vbar(omega_min_rad, v);
        for (k = 0; k < 4; k++) c[k] -= u[0] * v[k];
    }
    for (k = 0; k < 4; k++) out[k] = c[k];
    return HFVIS_OK;
}

hfvis_status hfvis_nlp_reconstruct(const double c[4], double omega_rad, double *out)
{
    double P[4];
    if (c == NULL || out == NULL || !isfinite(omega_rad)) return HFVIS_ERR_INVALID_ARGUMENT;
    /* [NS09] Eq. 13 with z = cos theta = sin omega */
    (void)hfvis_nlp_eval(sin(omega_rad), P);
    *out = c[0] * P[0] + c[1] * P[1] + c[2] * P[2] + c[3] * P[3];
    return HFVIS_OK;
}

/* -------------------------------------------------------- 6. Appendix-A wedge matrices (B.6) */

/* Ascending coefficients in alpha of the interpolation kernels beta_s ([NS09] §6, App. A; docs/errata.md E51). */
static const double ns_beta_lin[2][4] = {{1.0, -1.0, 0.0, 0.0}, {0.0, 1.0, 0.0, 0.0}};
static const double ns_beta_bspl[4][4] = {
    {1.0 / 6.0, -3.0 / 6.0, 3.0 / 6.0, -1.0 / 6.0},   /* (1-a)^3/6 */
    {4.0 / 6.0, 0.0, -6.0 / 6.0, 3.0 / 6.0},          /* (3a^3 - 6a^2 + 4)/6 */
    {1.0 / 6.0, 3.0 / 6.0, 3.0 / 6.0, -3.0 / 6.0},    /* (-3a^3 + 3a^2 + 3a + 1)/6 */
    {0.0, 0.0, 0.0, 1.0 / 6.0}};                      /* a^3/6 */

int hfvis_ns_wedge_columns(hfvis_ns_interp interp)
{
    if (interp == HFVIS_NS_INTERP_DEFAULT || interp == HFVIS_NS_INTERP_LINEAR) return 8;
    if (interp == HFVIS_NS_INTERP_BSPLINE) return 16;
    return 0;
}

hfvis_status hfvis_ns_wedge_matrix(hfvis_ns_interp interp, double dphi_rad, double *M)
{
    /* [NS09] §6, App. A; docs/errata.md E51 separable closed form: M[(l,m); (s,k)] = K_l^|m| A_(l,|m|,k) B_(m,s)(D) with
     * A = Int_{-1}^{1} Pt_l^|m| P^_k dz (exact, section 2) and
     * B = Int_0^D beta_s(phi/D) Phi_m(phi) dphi = D Sum_p beta_(s,p) Int_0^1 a^p Phi_m(D a) da. */
    const double (*beta)[4];
    double A[4][4][4], Bm[7][4], q[4];
    int ns, cols, l, mu, k, m, s, p;
    cols = hfvis_ns_wedge_columns(interp);
    if (M == NULL || cols == 0 || !isfinite(dphi_rad) || !(dphi_rad > 0.0) ||
        dphi_rad > NS_TWO_PI)
        return HFVIS_ERR_INVALID_ARGUMENT;
    ns = cols / 4;
    beta = ns == 2 ? ns_beta_lin : ns_beta_bspl;
    for (l = 0; l < 4; l++)
        for (mu = 0; mu <= l; mu++)
            for (k = 0; k < 4; k++) {
                ns_nlp_poly(k, q);
                A[l][mu][k] = ns_alp_band_integral(l, mu, q, k, 0.0, HFVIS__PI);
            }
    for (m = -3; m <= 3; m++) {
        double mc[4], ms[4], mom[4];
        int mu_ = m < 0 ? -m : m;
        if (m == 0) {
            for (p = 0; p < 4; p++) mom[p] = 1.0 / (double)(p + 1);
        } else {
            ns_trig_moments((double)mu_ * dphi_rad, mc, ms);
            for (p = 0; p < 4; p++) mom[p] = NS_SQRT2 * (m > 0 ? mc[p] : ms[p]);
        }
        for (s = 0; s < ns; s++) {
            double b = 0.0;
            for (p = 0; p < 4; p++) b += beta[s][p] * mom[p];
            Bm[m + 3][s] = dphi_rad * b;
        }
    }
    for (l = 0; l < 4; l++)
        for (m = -l; m <= l; m++) {
            int r = l * (l + 1) + m, mu_ = m < 0 ? -m : m;
            double K = ns_sh_norm(l, mu_);
            for (s = 0; s < ns; s++)
                for (k = 0; k < 4; k++) M[r * cols + s * 4 + k] = K * A[l][mu_][k] * Bm[m + 3][s];
        }
    return HFVIS_OK;
}

static hfvis_status ns_wedges_init(hfvis_ns_wedges *set, hfvis_ns_interp interp, int m,
                                   int full_circle, double phi0_rad, double dphi_rad)
{
    hfvis_ns_wedges w;
    if (hfvis_ns_wedge_matrix(interp, dphi_rad, w.matrix) != HFVIS_OK)
        return HFVIS_ERR_INVALID_ARGUMENT;
    w.interp = interp == HFVIS_NS_INTERP_DEFAULT ? HFVIS_NS_INTERP_LINEAR : interp;
    w.samples = m;
    w.full_circle = full_circle;
    w.phi0_rad = phi0_rad;
    w.dphi_rad = dphi_rad;
    *set = w;
    return HFVIS_OK;
}

hfvis_status hfvis_ns_wedges_full(hfvis_ns_wedges *set, hfvis_ns_interp interp, int m,
                                  double phi0_rad)
{
    if (set == NULL || m < 1 || !isfinite(phi0_rad)) return HFVIS_ERR_INVALID_ARGUMENT;
    /* docs/errata.md E51 on Eq. 21: a full circle has m wedges, the last one wrapping to sample 0 */
    return ns_wedges_init(set, interp, m, 1, phi0_rad, NS_TWO_PI / (double)m);
}

hfvis_status hfvis_ns_wedges_partial(hfvis_ns_wedges *set, hfvis_ns_interp interp, int m,
                                     double phi_a_rad, double phi_b_rad)
{
    if (set == NULL || m < 2 || !isfinite(phi_a_rad) || !isfinite(phi_b_rad) ||
        !(phi_b_rad > phi_a_rad) || phi_b_rad - phi_a_rad > NS_TWO_PI)
        return HFVIS_ERR_INVALID_ARGUMENT;
    return ns_wedges_init(set, interp, m, 0, phi_a_rad, (phi_b_rad - phi_a_rad) / (double)(m - 1));
}

hfvis_status hfvis_ns_wedges_to_sh(const hfvis_ns_wedges *set, const double *w, double out[16])
{
    double acc[NS_SH_N];
    int cols, ns, nw, m, j, s, r, i;
    if (set == NULL || w == NULL || out == NULL) return HFVIS_ERR_INVALID_ARGUMENT;
    cols = hfvis_ns_wedge_columns(set->interp);
    m = set->samples;
    if (cols == 0 || m < (set->full_circle ? 1 : 2) ||
        !isfinite(set->phi0_rad) || !isfinite(set->dphi_rad))
        return HFVIS_ERR_INVALID_ARGUMENT;
    ns = cols / 4;
    nw = set->full_circle ? m : m - 1;
    for (i = 0; i < NS_SH_N; i++) acc[i] = 0.0;
    for (j = 0; j < nw; j++) {
        /* [NS09] Eq. 20 (linear: w_j, w_(j+1)) or the B-spline form (w_(j-1) .. w_(j+2)), indices
         * wrapped on a full circle and clamped to the end samples otherwise ([NS09] §6, App. A; docs/errata.md E51) */
        double x[16], Wj[NS_SH_N], R[NS_SH_N];
        for (s = 0; s < ns; s++) {
            int idx = j + s - (ns == 4 ? 1 : 0);
            const double *src;
            if (set->full_circle) idx = ((idx % m) + m) % m;
            else idx = idx < 0 ? 0 : (idx > m - 1 ? m - 1 : idx);
            src = w + (size_t)idx * 4u;
            for (i = 0; i < 4; i++) x[s * 4 + i] = src[i];
        }
        for (r = 0; r < NS_SH_N; r++) {
            double v = 0.0;
            for (i = 0; i < cols; i++) v += set->matrix[r * cols + i] * x[i];
            Wj[r] = v;
        }
        /* Eq. 21: rotate the canonical wedge [0, D] to [phi_j, phi_j + D] */
        (void)hfvis_sh_rotate_z(Wj, set->phi0_rad + (double)j * set->dphi_rad, R);
        for (r = 0; r < NS_SH_N; r++) acc[r] += R[r];
    }
    for (r = 0; r < NS_SH_N; r++) out[r] = acc[r];
    return HFVIS_OK;
}

/* ------------------------------------------------- 7. tangent-plane minimum blocking angle */

hfvis_status hfvis_ns_min_blocking_angle(const double normal[3], double phi_rad,
                                         hfvis_ns_omega_min form, double *out)
{
    double n[3], d;
    if (normal == NULL || out == NULL || !isfinite(phi_rad) || !ns_unit(normal, n) ||
        (form != HFVIS_NS_OMEGA_MIN_DEFAULT && form != HFVIS_NS_OMEGA_MIN_EXACT &&
         form != HFVIS_NS_OMEGA_MIN_PAPER))
        return HFVIS_ERR_INVALID_ARGUMENT;
    d = n[0] * cos(phi_rad) + n[1] * sin(phi_rad);
    if (form == HFVIS_NS_OMEGA_MIN_PAPER) {
        /* [NS09] §3 as printed: exact only when N lies in the slice's vertical plane */
        if (d > 1.0) d = 1.0;
        if (d < -1.0) d = -1.0;
        *out = -asin(d);
    } else {
        /* docs/errata.md E47: the tangent plane's horizon in azimuth phi */
        *out = atan2(-d, n[2]);
    }
    return HFVIS_OK;
}

/* ========================================================================================== */
/* 14. Nowrouzezahrai-Snyder GI: slices, pyramid, lights, bounces                             */
/* ========================================================================================== */
/* The pipeline of [NS09] D. Nowrouzezahrai, J. Snyder, "Fast Global Illumination on Dynamic
 * Height Fields", CGF 28(4), 2009, on top of the math layer of section 13: the multi-resolution
 * height pyramid and the exponential step schedule (§5.2, Eq. 14-15), the maximum blocking angle
 * as a B-spline maximum and the casting set (Eq. 16-17), the visibility and indirect-radiance
 * NLP vectors (Eq. 11-12), the per-sample form of the wedge accumulation (Eq. 20-21), key and
 * directional lights (§6-7), shading with diffuse and Phong lobes (§7), the radiance pyramids of
 * the bounces (§5.3) and sub-sampling with full-resolution normals (§7, Fig. 6-7). Errata and choices:
 * docs/errata.md E47-E53.
 *
 * Contents
 *   1. Limits, small helpers, the B-spline maximum (Eq. 16) and per-sample wedge matrices
 *   2. The multi-resolution pyramid ([NS09] §5.2, Eq. 14-17 CPU proposal, B.5)
 *   3. Options, scene validation and the memory plan
 *   4. The slice scan: blocking angles, omega_max, casting set (Eq. 14-17)
 *   5. Receiver records: visibility, key and directional lights (Eq. 11, §6, [NS09] §6)
 *   6. Receiver records: indirect radiance of a bounce (Eq. 12, §5.3, [NS09] §5.3)
 *   7. Shading (§7) and the sliding two-row upsampling of sub-sampled receivers ([NS09] §9, Fig. 6)
 *   8. The driver ([NS09] §9, Fig. 6 RENDER)
 *
 * Everything is computed in double; the pyramids, the glossy incident-radiance buffer and the
 * outputs are float. Comparisons of blocking angles are made on tangents (atan is monotone), and
 * the NLP projections only need sin(omega) = t / sqrt(1 + t^2), so atan is evaluated only where
 * the B-spline maximum needs angles. */

#define HF_NS_CAST_TOL 1e-12          /* [NS09] §5.2, Eq. 14-17: omega_i > run + 1e-12 enters the casting set */
#define HF_NS_SNAP 1e-15              /* |cos|, |sin| below this are axis directions: exactly 0 */
#define HF_NS_MAXCH 64                /* channels of a pyramid: 16 SH x 4 colour channels */
#define HF_NS_KTAPS 7                 /* blur kernel taps (offsets -3..3) */

/* ------------------------------------------------------ 1. helpers, Eq. 16, sample matrices */

/* vbar(sigma) of Eq. 10 from s = sin(sigma) ([NS09] §4, Eq. 9-13; docs/errata.md E48, E49 closed form; same as ns_vbar). */
static void hf_ns_vbar(double s, double *v)
{
    double s2 = s * s;
    v[0] = NS_NLP0 * (s + 1.0);
    v[1] = NS_NLP1 * (s2 - 1.0) / 2.0;
    v[2] = NS_NLP2 * (s2 - 1.0) * s / 2.0;
    v[3] = NS_NLP3 * (5.0 * s2 - 1.0) * (s2 - 1.0) / 8.0;
}

/* Eq. 11: v = vbar(hi) - vbar(lo) for sines lo < hi, else 0. */
static void hf_ns_vis(double s_lo, double s_hi, double *v)
{
    double a[4], b[4];
    int q;
    if (!(s_hi > s_lo)) {
        v[0] = v[1] = v[2] = v[3] = 0.0;
        return;
    }
    hf_ns_vbar(s_hi, b);
    hf_ns_vbar(s_lo, a);
    for (q = 0; q < 4; q++) v[q] = b[q] - a[q];
}

/* Band of SH index i. */
static int hf_ns_band(int i) { return i < 1 ? 0 : i < 4 ? 1 : i < 9 ? 2 : 3; }

/* The zonal lobe Ahat rotated to axis a (unit): F_i = Ahat_l Y_i(a). */
static void hf_ns_lobe(const double *Ahat, const double *a, double *F)
{
    int i;
    ns_sh_eval_unit(a[0], a[1], a[2], F);
    for (i = 0; i < NS_SH_N; i++) F[i] *= Ahat[hf_ns_band(i)];
}


/* acc (16) += G (16x4, row-major) * w (4). */
static void hf_ns_acc(double *acc, const double *G, const double *w)
{
    int r;
    for (r = 0; r < NS_SH_N; r++, G += 4) acc[r] += G[0] * w[0] + G[1] * w[1] + G[2] * w[2] + G[3] * w[3];
}

static double hf_ns_dot16(const double *a, const double *b)
{
    double s = 0.0;
    int i;
    for (i = 0; i < NS_SH_N; i++) s += a[i] * b[i];
    return s;
}

/* out (16) += T (16x16, out index major) * v (16). */
static void hf_ns_matvec_add(const double *T, const double *v, double *out)
{
    int r, i;
    for (r = 0; r < NS_SH_N; r++, T += NS_SH_N) {
        double s = 0.0;
        for (i = 0; i < NS_SH_N; i++) s += T[i] * v[i];
        out[r] += s;
    }
}

static double hf_ns_bs_knot(const double *w, int n, int j)
{
    int a = j > 0 ? j - 1 : 0, b = j + 1 < n ? j + 1 : n - 1;
    return (w[a] + 4.0 * w[j] + w[b]) / 6.0;
}

static double hf_ns_bs_mid(const double *w, int n, int j)
{
    int a = j > 0 ? j - 1 : 0, d = j + 2 < n ? j + 2 : n - 1;
    return (w[a] + 23.0 * w[j] + 23.0 * w[j + 1] + w[d]) / 48.0;
}

hfvis_status hfvis_ns_bspline_max(int n, const double *omega_rad, double *out)
{
    double best;
    int j;
    if (out == NULL || n < 0 || (n > 0 && omega_rad == NULL)) return HFVIS_ERR_INVALID_ARGUMENT;
    for (j = 0; j < n; j++)
        if (!isfinite(omega_rad[j])) return HFVIS_ERR_INVALID_ARGUMENT;
    if (n == 0) {
        *out = -HFVIS__HALF_PI;
        return HFVIS_OK;
    }
    /* Eq. 16: knots S(j) and midpoints S(j + 1/2) of the uniform cubic B-spline, ends replicated */
    best = hf_ns_bs_knot(omega_rad, n, 0);
    for (j = 0; j < n; j++) {
        double v = hf_ns_bs_knot(omega_rad, n, j);
        if (v > best) best = v;
        if (j + 1 < n) {
            v = hf_ns_bs_mid(omega_rad, n, j);
            if (v > best) best = v;
        }
    }
    *out = best;
    return HFVIS_OK;
}

/* The angle of sample i, atan(t_i), computed once (w[i] = 3 marks "not yet"). */
static double hf_ns_ang(const double *t, double *w, int i)
{
    if (w[i] > 2.0) w[i] = atan(t[i]);
    return w[i];
}

/* A cheap atan with |error| <= 1.51e-3 rad (Rajan et al. 2006 on [-1, 1], reflected outside),
 * used only to find which B-spline windows can hold the maximum. */
#define HF_NS_FATAN_ERR 1.6e-3
static inline double hf_ns_fatan(double t)
{
    double a = fabs(t), r;
    if (a <= 1.0) return 0.78539816339744831 * t - t * (a - 1.0) * (0.2447 + 0.0663 * a);
    r = 1.0 / t;
    a = fabs(r);
    return (t > 0.0 ? HFVIS__HALF_PI : -HFVIS__HALF_PI) - (0.78539816339744831 * r - r * (a - 1.0) * (0.2447 + 0.0663 * a));
}

/* Eq. 16 on the tangents t[0..n-1] (n >= 1): the value hfvis_ns_bspline_max gives for their
 * angles. A knot or midpoint value is a convex combination of its window's angles, so with the
 * cheap atan every window's value is known to within HF_NS_FATAN_ERR; only the windows that can
 * still hold the maximum are evaluated with atan. w: n doubles of scratch, ap: 3n. */
static double hf_ns_omax_bspline(const double *t, int n, double *w, double *ap)
{
    double amax = -HFVIS__INF, best = -HFVIS__INF, thr, *sk = ap + n;
    int i, j;
    for (i = 0; i < n; i++) {
        w[i] = 3.0;
        ap[i] = hf_ns_fatan(t[i]);
    }
    /* sk[2j] = approximate knot value, sk[2j+1] = approximate midpoint value (the constants'
     * rounding is far inside the bound) */
    for (j = 0; j < n; j++) {
        const double p = ap[j > 0 ? j - 1 : 0], c0 = ap[j], nx = ap[j + 1 < n ? j + 1 : n - 1];
        double v = (p + 4.0 * c0 + nx) * (1.0 / 6.0);
        sk[2 * j] = v;
        if (v > amax) amax = v;
        if (j + 1 < n) {
            v = (p + 23.0 * (c0 + nx) + ap[j + 2 < n ? j + 2 : n - 1]) * (1.0 / 48.0);
            sk[2 * j + 1] = v;
            if (v > amax) amax = v;
        }
    }
    thr = amax - 2.0 * HF_NS_FATAN_ERR - 1e-12;
    for (j = 0; j < n; j++) {
        int a = j > 0 ? j - 1 : 0, b = j + 1 < n ? j + 1 : n - 1, d = j + 2 < n ? j + 2 : n - 1;
        if (sk[2 * j] >= thr) {
            double v = (hf_ns_ang(t, w, a) + 4.0 * hf_ns_ang(t, w, j) + hf_ns_ang(t, w, b)) / 6.0;
            if (v > best) best = v;
        }
        if (j + 1 < n && sk[2 * j + 1] >= thr) {
            double v = (hf_ns_ang(t, w, a) + 23.0 * hf_ns_ang(t, w, j) + 23.0 * hf_ns_ang(t, w, b) +
                        hf_ns_ang(t, w, d)) / 48.0;
            if (v > best) best = v;
        }
    }
#ifdef HFVIS_ENABLE_ASSERTS
    {
        double full;
        for (i = 0; i < n; i++) (void)hf_ns_ang(t, w, i);
        (void)hfvis_ns_bspline_max(n, w, &full);
        HFVIS_ASSERT(full == best);
    }
#endif
    return best;
}

hfvis_status hfvis_ns_sample_matrices(const hfvis_ns_wedges *set, double *G)
{
    int cols, ns, nw, m, j, s, k, r;
    size_t i, total;
    if (set == NULL || G == NULL) return HFVIS_ERR_INVALID_ARGUMENT;
    cols = hfvis_ns_wedge_columns(set->interp);
    m = set->samples;
    if (cols == 0 || m < (set->full_circle ? 1 : 2) || !isfinite(set->phi0_rad) ||
        !isfinite(set->dphi_rad))
        return HFVIS_ERR_INVALID_ARGUMENT;
    ns = cols / 4;
    nw = set->full_circle ? m : m - 1;
    total = (size_t)m * 64u;
    for (i = 0; i < total; i++) G[i] = 0.0;
    /* Eq. 21 as Sum_j Rot_z(M [w_j; w_(j+1)], phi_j) = Sum_i (Sum_(j,s -> i) Rot_z(M_s, phi_j)) w_i:
     * the sample index of each block as in hfvis_ns_wedges_to_sh (wrapped or clamped) */
    for (j = 0; j < nw; j++) {
        double ang = set->phi0_rad + (double)j * set->dphi_rad;
        for (s = 0; s < ns; s++) {
            int idx = j + s - (ns == 4 ? 1 : 0);
            if (set->full_circle) idx = ((idx % m) + m) % m;
            else idx = idx < 0 ? 0 : (idx > m - 1 ? m - 1 : idx);
            for (k = 0; k < 4; k++) {
                double col[NS_SH_N], rot[NS_SH_N];
                for (r = 0; r < NS_SH_N; r++) col[r] = set->matrix[r * cols + s * 4 + k];
                (void)hfvis_sh_rotate_z(col, ang, rot);
                for (r = 0; r < NS_SH_N; r++) G[((size_t)idx * 16u + (size_t)r) * 4u + (size_t)k] += rot[r];
            }
        }
    }
    return HFVIS_OK;
}

/* ---------------------------------------------------------------------- 2. the pyramid */

/* One level: a float image of w x h texels x channels, sampled at grid position x as the octave
 * coordinate u = x*a + b (texel centres of octave o sit at grid positions 2^o (i + 1/2) - 1/2,
 * times the base scale of a sub-sampled base). */
typedef struct hf_ns_level {
    float *img;
    int w, h;
    double a, b;
} hf_ns_level;

static void hf_ns_oct_dims(int bw, int bh, int o, int *w, int *h)
{
    int i;
    *w = bw;
    *h = bh;
    for (i = 0; i < o; i++) {
        *w = (*w + 1) / 2;
        *h = (*h + 1) / 2;
    }
}

/* Index of filter tap i in [0, n) under the border rule, or -1 (OPEN: no texel there). */
static int hf_ns_tap(int i, int n, int border)
{
    if (i >= 0 && i < n) return i;
    if (border == HFVIS_BORDER_WRAP) return ((i % n) + n) % n;
    if (border == HFVIS_BORDER_CLAMP) return i < 0 ? 0 : n - 1;
    return -1;
}

/* dst (dw x dh) = separable filter of src (sw x sh), C channels: output texel X reads source
 * texels step*X + first + t, t = 0..nt-1, with weight w[t] per axis. Taps outside the image
 * follow the border; hole taps (channel 0 not finite) are dropped; the 2-D weights are
 * renormalised, which the two passes do exactly by carrying the weight sum beside the values.
 * row: sw*(C+1) doubles. */
static void hf_ns_filter(const float *src, int sw, int sh, float *dst, int dw, int dh, int C,
                         const double *w, int nt, int first, int step, int border, double *row)
{
    int X, Y, t, c, x;
    const int C1 = C + 1;
    for (Y = 0; Y < dh; Y++) {
        for (x = 0; x < sw * C1; x++) row[x] = 0.0;
        for (t = 0; t < nt; t++) {
            int yy = hf_ns_tap(Y * step + first + t, sh, border);
            const float *sr;
            if (yy < 0 || w[t] == 0.0) continue;
            sr = src + (size_t)yy * (size_t)sw * (size_t)C;
            for (x = 0; x < sw; x++) {
                const float *p = sr + (size_t)x * (size_t)C;
                double *r = row + (size_t)x * (size_t)C1;
                if (!isfinite(p[0])) continue;
                for (c = 0; c < C; c++) r[c] += w[t] * (double)p[c];
                r[C] += w[t];
            }
        }
        for (X = 0; X < dw; X++) {
            double acc[HF_NS_MAXCH], den = 0.0;
            float *o = dst + ((size_t)Y * (size_t)dw + (size_t)X) * (size_t)C;
            for (c = 0; c < C; c++) acc[c] = 0.0;
            for (t = 0; t < nt; t++) {
                int xx = hf_ns_tap(X * step + first + t, sw, border);
                const double *r;
                if (xx < 0 || w[t] == 0.0) continue;
                r = row + (size_t)xx * (size_t)C1;
                if (r[C] == 0.0) continue;
                for (c = 0; c < C; c++) acc[c] += w[t] * r[c];
                den += w[t] * r[C];
            }
            for (c = 0; c < C; c++) o[c] = den > 0.0 ? (float)(acc[c] / den) : (float)HFVIS__NAN;
        }
    }
}

/* Cubic B-spline B3(u), support |u| < 2. */
static double hf_ns_b3(double u)
{
    u = fabs(u);
    if (u >= 2.0) return 0.0;
    if (u >= 1.0) return (2.0 - u) * (2.0 - u) * (2.0 - u) / 6.0;
    return (4.0 - 6.0 * u * u + 3.0 * u * u * u) / 6.0;
}

/* Variance of the sampled, normalised B3(x/s) kernel on x = -3..3 (weights into w if non-NULL). */
static double hf_ns_b3_variance(double s, double *w)
{
    double sum = 0.0, m2 = 0.0, t[HF_NS_KTAPS];
    int x;
    for (x = -3; x <= 3; x++) {
        t[x + 3] = hf_ns_b3((double)x / s);
        sum += t[x + 3];
        m2 += (double)(x * x) * t[x + 3];
    }
    if (w)
        for (x = 0; x < HF_NS_KTAPS; x++) w[x] = t[x] / sum;
    return m2 / sum;
}

/* The blur kernel of level j of an octave ([NS09] §5.2, Eq. 14-17: "a normalized, sampled cubic B-spline kernel
 * of scale 2^(j/k)"): its scale is chosen (bisection) so that its variance is (4^(j/k) - 1)/4 G_o
 * texels^2: the variance of a level then grows like 4^(l/k) across the whole pyramid, G_(o+1)
 * adding the 3/4 of the [1,3,3,1]/8 decimation. j = 0 is the identity. */
static void hf_ns_blur_kernel(int k, int j, double *w)
{
    double target = (pow(4.0, (double)j / (double)k) - 1.0) / 4.0, lo = 0.5, hi = 2.0;
    int it;
    if (j == 0) {
        for (it = 0; it < HF_NS_KTAPS; it++) w[it] = it == 3 ? 1.0 : 0.0;
        return;
    }
    for (it = 0; it < 100; it++) {
        double mid = 0.5 * (lo + hi);
        if (hf_ns_b3_variance(mid, NULL) < target) lo = mid;
        else hi = mid;
    }
    (void)hf_ns_b3_variance(0.5 * (lo + hi), w);
}

/* Build levels 1..L-1 (level 0 filled by the caller). kern: k kernels of HF_NS_KTAPS taps. */
static void hf_ns_pyr_build(hf_ns_level *lv, int L, int k, int C, int border, const double *kern,
                            double *row)
{
    static const double dec[4] = {1.0 / 8.0, 3.0 / 8.0, 3.0 / 8.0, 1.0 / 8.0};
    int l;
    for (l = 1; l < L; l++) {
        int o = l / k, j = l % k;
        if (j == 0) {
            const hf_ns_level *s = &lv[k * (o - 1)];
            hf_ns_filter(s->img, s->w, s->h, lv[l].img, lv[l].w, lv[l].h, C, dec, 4, -1, 2, border, row);
        } else {
            const hf_ns_level *s = &lv[k * o];
            hf_ns_filter(s->img, s->w, s->h, lv[l].img, lv[l].w, lv[l].h, C, kern + j * HF_NS_KTAPS,
                         HF_NS_KTAPS, -3, 1, border, row);
        }
    }
}

/* Bilinear taps of coordinate u on n texels: clamped (OPEN, CLAMP) or periodic (WRAP). */
static void hf_ns_axis(double u, int n, int wrap, int *i0, int *i1, double *f)
{
    double fl;
    if (n == 1) {
        *i0 = *i1 = 0;
        *f = 0.0;
        return;
    }
    if (wrap) {
        u -= floor(u / (double)n) * (double)n;
        fl = floor(u);
        *i0 = (int)fl;
        if (*i0 >= n || *i0 < 0) {
            *i0 = 0;
            fl = 0.0;
            u = 0.0;
        }
        *i1 = *i0 + 1 == n ? 0 : *i0 + 1;
        *f = u - fl;
        return;
    }
    if (u < 0.0) u = 0.0;
    else if (u > (double)(n - 1)) u = (double)(n - 1);
    fl = floor(u);
    if (fl > (double)(n - 2)) fl = (double)(n - 2);
    *i0 = (int)fl;
    *i1 = *i0 + 1;
    *f = u - fl;
}

/* Clamped bilinear tap of coordinate u on n texels (OPEN, CLAMP): (int) truncation is floor for
 * u > 0, and u beyond the last texel gives weight 1 on it. */
static inline void hf_ns_axis_clamped(double u, int n, int *i0, double *f)
{
    int i;
    if (n == 1 || u <= 0.0) {
        *i0 = 0;
        *f = 0.0;
        return;
    }
    i = (int)u;
    if (i > n - 2) i = n - 2;
    *i0 = i;
    *f = u - (double)i;
    if (*f > 1.0) *f = 1.0;
}

/* The four bilinear taps of grid position (x, y) on level L: columns x0, x1, rows y0, y1 and the
 * weights fx, fy (wrapped, or clamped to the level). */
static inline void hf_ns_taps(const hf_ns_level *L, int wrap, double x, double y, int *x0, int *x1,
                              int *y0, int *y1, double *fx, double *fy)
{
    if (wrap) {
        hf_ns_axis(x * L->a + L->b, L->w, 1, x0, x1, fx);
        hf_ns_axis(y * L->a + L->b, L->h, 1, y0, y1, fy);
    } else {
        hf_ns_axis_clamped(x * L->a + L->b, L->w, x0, fx);
        hf_ns_axis_clamped(y * L->a + L->b, L->h, y0, fy);
        *x1 = L->w > 1 ? *x0 + 1 : *x0;
        *y1 = L->h > 1 ? *y0 + 1 : *y0;
    }
}

/* One channel (heights): bilinear at grid position (x, y); a tap with zero weight is never read
 * (as hf_bilerp), so a hole beside an exact sample position does not leak in. NaN = hole. */
static inline double hf_ns_sample1(const hf_ns_level *L, int wrap, int holes, double x, double y)
{
    int x0, x1, y0, y1;
    double fx, fy, r0 = 0.0, r1;
    const float *p0, *p1;
    hf_ns_taps(L, wrap, x, y, &x0, &x1, &y0, &y1, &fx, &fy);
    p0 = L->img + (size_t)y0 * (size_t)L->w;
    p1 = L->img + (size_t)y1 * (size_t)L->w;
    if (!holes) /* every tap finite: the plain form gives the same value */
        return ((double)p0[x0] * (1.0 - fx) + (double)p0[x1] * fx) * (1.0 - fy) +
               ((double)p1[x0] * (1.0 - fx) + (double)p1[x1] * fx) * fy;
    if (fy != 1.0) {
        r0 = fx == 0.0 ? (double)p0[x0] : fx == 1.0 ? (double)p0[x1]
                                                    : (double)p0[x0] * (1.0 - fx) + (double)p0[x1] * fx;
        if (fy == 0.0) return r0;
    }
    r1 = fx == 0.0 ? (double)p1[x0] : fx == 1.0 ? (double)p1[x1]
                                                : (double)p1[x0] * (1.0 - fx) + (double)p1[x1] * fx;
    if (fy == 1.0) return r1;
    return r0 * (1.0 - fy) + r1 * fy;
}

/* C channels at grid position (x, y) into out; 0 if the sample is a hole. holes = 0 promises that
 * no texel is one (then the plain weighted sum, same value). */
static int hf_ns_sampleC(const hf_ns_level *L, int C, int wrap, int holes, double x, double y, double *out)
{
    int x0, x1, y0, y1, c, q;
    double fx, fy, wt[4];
    const float *tp[4];
    hf_ns_taps(L, wrap, x, y, &x0, &x1, &y0, &y1, &fx, &fy);
    wt[0] = (1.0 - fx) * (1.0 - fy);
    wt[1] = fx * (1.0 - fy);
    wt[2] = (1.0 - fx) * fy;
    wt[3] = fx * fy;
    tp[0] = L->img + ((size_t)y0 * (size_t)L->w + (size_t)x0) * (size_t)C;
    tp[1] = L->img + ((size_t)y0 * (size_t)L->w + (size_t)x1) * (size_t)C;
    tp[2] = L->img + ((size_t)y1 * (size_t)L->w + (size_t)x0) * (size_t)C;
    tp[3] = L->img + ((size_t)y1 * (size_t)L->w + (size_t)x1) * (size_t)C;
    if (!holes) { /* every texel finite */
        for (c = 0; c < C; c++)
            out[c] = wt[0] * (double)tp[0][c] + wt[1] * (double)tp[1][c] + wt[2] * (double)tp[2][c] +
                     wt[3] * (double)tp[3][c];
        return 1;
    }
    for (c = 0; c < C; c++) out[c] = 0.0;
    for (q = 0; q < 4; q++) {
        if (wt[q] == 0.0) continue;
        if (!isfinite(tp[q][0])) return 0;
        for (c = 0; c < C; c++) out[c] += wt[q] * (double)tp[q][c];
    }
    return 1;
}

/* ------------------------------------------------------- 3. options, validation, memory plan */

typedef struct hf_ns_cast {
    int i;              /* step index */
    double t;           /* tan(omega_i) */
    double x, y;        /* grid position of the step (after the border rule) */
    double dz;          /* height difference at level l_v(i), world units */
} hf_ns_cast;

typedef struct hf_ns_key {
    int full;                  /* 1: the cap holds the zenith: full circle, the environment slices */
    double sin_lmin, sin_lmax; /* elevation range [l_min, l_max] as sines */
    double *cph, *sph;         /* key_directions azimuths (partial extent) */
    double *G;                 /* 64*key_directions sample matrices (partial extent) */
    double *T;                 /* C*256: the product matrix of L_key */
    double Ls[NS_SH_N];        /* L_key per unit irradiance (RATIO) */
    double E0[4];              /* irradiance per channel (RATIO) */
    double box;                /* Ls . V_box: the unoccluded restricted visibility's (RATIO) */
} hf_ns_key;

typedef struct hf_ns_dir {
    double d[3], cph, sph, sin_e;
    double E0[4];
    double Yd[NS_SH_N];        /* Y(d), bands >= order zeroed */
} hf_ns_dir;

typedef struct hf_ns_recv {
    double x, y, n[3];
    double *hl;                /* receiver height at each level of the height pyramid */
} hf_ns_recv;

typedef struct hf_ns_ctx {
    const hfvis_grid *g;
    const hfvis_ns_scene *sc;
    hfvis_ns_gi_options o;     /* resolved */
    int W, H, C, m, mk, k, n, ov, ou, order, s, Rw, Rh, B;
    int border, wrap, open, holes;
    int Lv, Lu;                /* levels built: heights, radiance */
    int nkey, ndir;            /* separate key lights, directional lights */
    int env, env_scan;         /* an environment (T_env) exists; the m environment slices run */
    int gloss, gvec, need_normals, want_vis;
    int cwords, cfilled;       /* casting-set cache: words per slice, filled by a pass */
    int rec_d, rec_b, rec_max, Cmax;
    double cell, rho_s, S, Ad[4], Ap[4], view[3];
    /* tables (block 1) */
    double *gamma, *tau, *inv_dist, *ecos, *esin, *G_env, *T_env, *kern, *row;
    int *lv_i, *lu_i;
    hf_ns_key *keys;
    hf_ns_dir *dirs;
    hf_ns_level *hp, *dp, *ip;
    double *tv, *wc, *wa, *smax, *hl, *ub, *vb, *Iq, *rtmp, *vtmp;
    hf_ns_cast *cast;
    /* block 2: height pyramid and normals; block 3: two receiver rows; block 4: bounces */
    float *normals;
    double *win;
    float *exitbuf, *ibuf;
    uint64_t *cmask;           /* casting-set cache: Rw*Rh*m*cwords words, or NULL */
} hf_ns_ctx;

hfvis_ns_gi_options hfvis_ns_gi_options_default(void)
{
    hfvis_ns_gi_options o;
    memset(&o, 0, sizeof o);
    o.directions = 32;
    o.key_directions = 3;
    o.levels_per_octave = 4;
    o.levels = 0;
    o.level_offset_v = 2;
    o.level_offset_u = 2;
    o.sh_order = 4;
    o.subsample = 1;
    o.interp = HFVIS_NS_INTERP_LINEAR;
    o.omega_min = HFVIS_NS_OMEGA_MIN_EXACT;
    o.omega_max = HFVIS_NS_OMEGA_MAX_BSPLINE;
    o.clamp_to_tangent = 0;
    o.directional = HFVIS_NS_DIRECTIONAL_HARD;
    o.key_mode = HFVIS_NS_KEY_SEPARATE;
    o.glossy = HFVIS_NS_GLOSSY_VECTOR;
    o.cast_cache = HFVIS_NS_CACHE_ON;
    o.view_dir[0] = 0.0;
    o.view_dir[1] = 0.0;
    o.view_dir[2] = 1.0;
    o.border = HFVIS_BORDER_OPEN;
    return o;
}

static int hf_ns_range(int v, int lo, int hi) { return v >= lo && v <= hi; }

hfvis_status hfvis_ns_gi_options_resolve(const hfvis_grid *grid, const hfvis_ns_gi_options *in,
                                         hfvis_ns_gi_options *out)
{
    hfvis_ns_gi_options o, d = hfvis_ns_gi_options_default();
    double vn;
    if (!hf_grid_valid(grid) || out == NULL) return HFVIS_ERR_INVALID_ARGUMENT;
    if (in) o = *in;
    else memset(&o, 0, sizeof o);
    if (!hf_ns_range(o.directions, 0, HFVIS_NS_MAX_DIRECTIONS) ||
        !(o.key_directions == 0 || hf_ns_range(o.key_directions, 2, HFVIS_NS_MAX_KEY_DIRECTIONS)) ||
        !hf_ns_range(o.levels_per_octave, 0, HFVIS_NS_MAX_LEVELS_PER_OCTAVE) ||
        !hf_ns_range(o.levels, 0, HFVIS_NS_MAX_LEVELS) ||
        !hf_ns_range(o.level_offset_v, HFVIS_NS_NO_OFFSET, HFVIS_NS_MAX_LEVEL_OFFSET) ||
        !hf_ns_range(o.level_offset_u, HFVIS_NS_NO_OFFSET, HFVIS_NS_MAX_LEVEL_OFFSET) ||
        !hf_ns_range(o.sh_order, 0, 4) || !hf_ns_range(o.subsample, 0, HFVIS_NS_MAX_SUBSAMPLE) ||
        hfvis_ns_wedge_columns(o.interp) == 0 ||
        !hf_ns_range((int)o.omega_min, 0, 2) || !hf_ns_range((int)o.omega_max, 0, 2) ||
        !hf_ns_range(o.clamp_to_tangent, 0, 1) || !hf_ns_range((int)o.directional, 0, 3) ||
        !hf_ns_range((int)o.key_mode, 0, 3) || !hf_ns_range((int)o.glossy, 0, 2) ||
        !hf_ns_range((int)o.cast_cache, 0, 2) ||
        !isfinite(o.view_dir[0]) || !isfinite(o.view_dir[1]) || !isfinite(o.view_dir[2]) ||
        !hf_border_valid(o.border) || !isfinite(o.azimuth0_rad))
        return HFVIS_ERR_INVALID_ARGUMENT;
    vn = sqrt(o.view_dir[0] * o.view_dir[0] + o.view_dir[1] * o.view_dir[1] +
              o.view_dir[2] * o.view_dir[2]);
    if (vn == 0.0) {
        o.view_dir[0] = d.view_dir[0];
        o.view_dir[1] = d.view_dir[1];
        o.view_dir[2] = d.view_dir[2];
    } else if (!isfinite(vn)) {
        return HFVIS_ERR_INVALID_ARGUMENT;
    } else {
        o.view_dir[0] /= vn;
        o.view_dir[1] /= vn;
        o.view_dir[2] /= vn;
    }
    if (o.directions == 0) o.directions = d.directions;
    if (o.key_directions == 0) o.key_directions = d.key_directions;
    if (o.levels_per_octave == 0) o.levels_per_octave = d.levels_per_octave;
    if (o.level_offset_v == 0) o.level_offset_v = d.level_offset_v;
    if (o.level_offset_u == 0) o.level_offset_u = d.level_offset_u;
    if (o.sh_order == 0) o.sh_order = d.sh_order;
    if (o.subsample == 0) o.subsample = d.subsample;
    if (o.interp == HFVIS_NS_INTERP_DEFAULT) o.interp = d.interp;
    if (o.omega_min == HFVIS_NS_OMEGA_MIN_DEFAULT) o.omega_min = d.omega_min;
    if (o.omega_max == HFVIS_NS_OMEGA_MAX_DEFAULT) o.omega_max = d.omega_max;
    if (o.directional == HFVIS_NS_DIRECTIONAL_DEFAULT) o.directional = d.directional;
    if (o.key_mode == HFVIS_NS_KEY_DEFAULT) o.key_mode = d.key_mode;
    if (o.glossy == HFVIS_NS_GLOSSY_DEFAULT) o.glossy = d.glossy;
    if (o.cast_cache == HFVIS_NS_CACHE_DEFAULT) o.cast_cache = d.cast_cache;
    if (o.border == HFVIS_BORDER_DEFAULT) o.border = d.border;
    if (o.levels == 0) {
        /* the last step tau_(n-1) = 2^((n-1)/k) reaches the grid's diagonal ([NS09] §5.2, Eq. 14-17: the natural
         * choice 1 + k log2 R, for any aspect) */
        double D = hypot((double)(grid->width - 1), (double)(grid->height - 1)), e;
        if (D < 1.0) D = 1.0;
        e = ceil((double)o.levels_per_octave * log2(D) - 1e-9);
        if (e < 0.0) e = 0.0;
        o.levels = 1 + (int)e;
        if (o.levels > HFVIS_NS_MAX_LEVELS) o.levels = HFVIS_NS_MAX_LEVELS;
    }
    *out = o;
    return HFVIS_OK;
}

static int hf_ns_offset(int v) { return v == HFVIS_NS_NO_OFFSET ? 0 : v; }

/* A non-hole sample of the grid with a non-finite map value makes the map invalid. */
static int hf_ns_map_valid(const hfvis_grid *g, const float *map, int C)
{
    int x, y, c;
    if (!map) return 1;
    for (y = 0; y < g->height; y++)
        for (x = 0; x < g->width; x++) {
            const float *p = map + ((size_t)y * (size_t)g->width + (size_t)x) * (size_t)C;
            if (!isfinite(g->z[(ptrdiff_t)y * g->stride + x])) continue;
            for (c = 0; c < C; c++)
                if (!isfinite(p[c])) return 0;
        }
    return 1;
}

/* Validate and resolve everything that decides sizes (no allocation, no tables). */
static hfvis_status hf_ns_setup(hf_ns_ctx *c, const hfvis_grid *grid, const hfvis_ns_scene *sc,
                                const hfvis_ns_gi_options *opts, int bounces, int want_vis)
{
    int i, ch;
    size_t t;
    memset(c, 0, sizeof *c);
    if (!hf_grid_valid(grid) || sc == NULL || bounces < 0) return HFVIS_ERR_INVALID_ARGUMENT;
    if (hfvis_ns_gi_options_resolve(grid, opts, &c->o) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    if (sc->channels < 1 || sc->channels > 4 || sc->light_count < 0 ||
        sc->light_count > HFVIS_NS_MAX_LIGHTS || (sc->light_count > 0 && sc->lights == NULL) ||
        !isfinite(sc->specular) || sc->specular < 0.0f ||
        (sc->specular > 0.0f && (!isfinite(sc->shininess) || !(sc->shininess > 0.0f))))
        return HFVIS_ERR_INVALID_ARGUMENT;
    c->C = sc->channels;
    for (ch = 0; ch < c->C; ch++)
        if (!isfinite(sc->albedo[ch])) return HFVIS_ERR_INVALID_ARGUMENT;
    if (sc->env_sh)
        for (i = 0; i < NS_SH_N * c->C; i++)
            if (!isfinite(sc->env_sh[i])) return HFVIS_ERR_INVALID_ARGUMENT;
    if (!hfvis__mul_size(hf_grid_count(grid), (size_t)c->C * 16u, &t) ||
        !hfvis__mul_size(t, (size_t)bounces + 1u, &t) || !hfvis__mul_size(t, sizeof(double), &t))
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (i = 0; i < sc->light_count; i++) {
        const hfvis_sun *L = &sc->lights[i];
        if (!isfinite(L->azimuth_rad) || !isfinite(L->elevation_rad) || !isfinite(L->radius_rad) ||
            fabs(L->elevation_rad) > HFVIS__HALF_PI || L->radius_rad < 0.0 || L->radius_rad > HFVIS__HALF_PI)
            return HFVIS_ERR_INVALID_ARGUMENT;
        for (ch = 0; ch < c->C; ch++)
            if (!isfinite(L->irradiance[ch])) return HFVIS_ERR_INVALID_ARGUMENT;
        if (L->radius_rad == 0.0) c->ndir++;
        else if (c->o.key_mode != HFVIS_NS_KEY_ENVIRONMENT) c->nkey++;
    }
    if (!hf_ns_map_valid(grid, sc->albedo_map, c->C) || !hf_ns_map_valid(grid, sc->emission, c->C))
        return HFVIS_ERR_INVALID_ARGUMENT;
    c->g = grid;
    c->sc = sc;
    c->W = grid->width;
    c->H = grid->height;
    c->m = c->o.directions;
    c->mk = c->o.key_directions;
    c->k = c->o.levels_per_octave;
    c->n = c->o.levels;
    c->ov = hf_ns_offset(c->o.level_offset_v);
    c->ou = hf_ns_offset(c->o.level_offset_u);
    c->order = c->o.sh_order;
    c->s = c->o.subsample;
    c->Rw = (c->W + c->s - 1) / c->s;
    c->Rh = (c->H + c->s - 1) / c->s;
    c->B = bounces;
    c->border = (int)c->o.border;
    c->wrap = c->o.border == HFVIS_BORDER_WRAP;
    c->open = c->o.border == HFVIS_BORDER_OPEN;
    c->cell = grid->cell_size;
    /* levels actually read: l_v(n-1) and l_u(n-1) */
    c->Lv = c->n - 1 - c->k * c->ov;
    c->Lv = (c->Lv < 0 ? 0 : c->Lv) + 1;
    c->Lu = c->n - 1 - c->k * c->ou;
    c->Lu = (c->Lu < 0 ? 0 : c->Lu) + 1;
    c->gloss = sc->specular > 0.0f;
    c->gvec = c->gloss && bounces > 0 && c->o.glossy == HFVIS_NS_GLOSSY_VECTOR;
    c->need_normals = c->s > 1 || c->gvec;
    c->want_vis = want_vis;
    c->env = sc->env_sh != NULL || (sc->light_count > c->ndir && c->o.key_mode == HFVIS_NS_KEY_ENVIRONMENT);
    c->env_scan = c->env || want_vis;
    for (i = 0; i < sc->light_count; i++) {
        const hfvis_sun *L = &sc->lights[i];
        if (L->radius_rad > 0.0 && c->o.key_mode != HFVIS_NS_KEY_ENVIRONMENT &&
            !(L->radius_rad < HFVIS__HALF_PI - fabs(L->elevation_rad)))
            c->env_scan = 1; /* a cap holding the zenith uses the environment slices */
    }
    c->rec_d = NS_SH_N * (1 + c->nkey) + c->ndir;
    c->rec_b = NS_SH_N * c->C;
    c->rec_max = c->rec_d > c->rec_b ? c->rec_d : c->rec_b;
    c->Cmax = c->gvec ? NS_SH_N * c->C : c->C;
    c->cwords = bounces > 0 && c->o.cast_cache == HFVIS_NS_CACHE_ON ? (c->n + 63) / 64 : 0;
    c->rho_s = (double)sc->specular;
    c->S = (double)sc->shininess;
    return HFVIS_OK;
}

typedef struct hf_ns_arena {
    unsigned char *base;
    size_t used;
    int overflow;
} hf_ns_arena;

/* Carve count*elem bytes (16-byte aligned) from the arena; with base NULL only measures. */
static void *hf_ns_take(hf_ns_arena *a, size_t count, size_t elem)
{
    size_t bytes, start;
    if (!hfvis__mul_size(count, elem, &bytes) || a->used > SIZE_MAX - 15u) {
        a->overflow = 1;
        return NULL;
    }
    start = (a->used + 15u) & ~(size_t)15u;
    if (bytes > SIZE_MAX - start) {
        a->overflow = 1;
        return NULL;
    }
    a->used = start + bytes;
    return a->base ? (void *)(a->base + start) : NULL;
}

/* Carve the images of a pyramid of L levels over a bw x bh base scaled by bscale grid units. */
static void hf_ns_pyr_carve(hf_ns_arena *a, hf_ns_level *lv, int L, int k, int bw, int bh,
                            double bscale, int C)
{
    int l;
    for (l = 0; l < L; l++) {
        int w, h, o = l / k;
        float *img;
        double sc = bscale * ldexp(1.0, o);
        hf_ns_oct_dims(bw, bh, o, &w, &h);
        img = (float *)hf_ns_take(a, (size_t)w * (size_t)h, sizeof(float) * (size_t)C);
        if (lv) {
            lv[l].img = img;
            lv[l].w = w;
            lv[l].h = h;
            lv[l].a = 1.0 / sc;
            lv[l].b = sc == 1.0 ? 0.0 : 0.5 / sc - 0.5;
        }
    }
}

/* Lay out the four blocks: tables, heights, window, bounces (pointers only when bases are set). */
static void hf_ns_carve(hf_ns_ctx *c, hf_ns_arena *A)
{
    const size_t n = (size_t)c->n, m = (size_t)c->m, C = (size_t)c->C;
    size_t mw = (size_t)(c->W > c->Rw ? c->W : c->Rw);
    hf_ns_arena *t = &A[0];
    c->keys = (hf_ns_key *)hf_ns_take(t, (size_t)c->nkey, sizeof(hf_ns_key));
    c->dirs = (hf_ns_dir *)hf_ns_take(t, (size_t)c->ndir, sizeof(hf_ns_dir));
    c->hp = (hf_ns_level *)hf_ns_take(t, (size_t)c->Lv, sizeof(hf_ns_level));
    c->dp = (hf_ns_level *)hf_ns_take(t, c->B > 0 ? (size_t)c->Lu : 0u, sizeof(hf_ns_level));
    c->ip = (hf_ns_level *)hf_ns_take(t, c->gvec ? (size_t)c->Lu : 0u, sizeof(hf_ns_level));
    c->cast = (hf_ns_cast *)hf_ns_take(t, n, sizeof(hf_ns_cast));
    c->gamma = (double *)hf_ns_take(t, 4096u, sizeof(double));
    c->tau = (double *)hf_ns_take(t, n, sizeof(double));
    c->inv_dist = (double *)hf_ns_take(t, n, sizeof(double));
    c->ecos = (double *)hf_ns_take(t, m, sizeof(double));
    c->esin = (double *)hf_ns_take(t, m, sizeof(double));
    c->G_env = (double *)hf_ns_take(t, m, 64u * sizeof(double));
    c->T_env = (double *)hf_ns_take(t, C, 256u * sizeof(double));
    c->kern = (double *)hf_ns_take(t, (size_t)c->k, HF_NS_KTAPS * sizeof(double));
    c->row = (double *)hf_ns_take(t, mw, ((size_t)c->Cmax + 1u) * sizeof(double));
    c->tv = (double *)hf_ns_take(t, n, sizeof(double));
    c->wc = (double *)hf_ns_take(t, n, sizeof(double));
    c->wa = (double *)hf_ns_take(t, n, 3u * sizeof(double));
    c->smax = (double *)hf_ns_take(t, m, sizeof(double));
    c->hl = (double *)hf_ns_take(t, (size_t)c->Lv, sizeof(double));
    c->ub = (double *)hf_ns_take(t, n, C * sizeof(double));
    c->vb = (double *)hf_ns_take(t, n, 4u * sizeof(double));
    c->Iq = (double *)hf_ns_take(t, C, NS_SH_N * sizeof(double));
    c->rtmp = (double *)hf_ns_take(t, (size_t)c->rec_max, sizeof(double));
    c->vtmp = (double *)hf_ns_take(t, C, NS_SH_N * sizeof(double));
    c->lv_i = (int *)hf_ns_take(t, n, sizeof(int));
    c->lu_i = (int *)hf_ns_take(t, n, sizeof(int));
    {
        int q;
        for (q = 0; q < c->nkey; q++) {
            double *cp = (double *)hf_ns_take(t, (size_t)c->mk, sizeof(double));
            double *sp = (double *)hf_ns_take(t, (size_t)c->mk, sizeof(double));
            double *G = (double *)hf_ns_take(t, (size_t)c->mk, 64u * sizeof(double));
            double *T = (double *)hf_ns_take(t, C, 256u * sizeof(double));
            if (c->keys) {
                c->keys[q].cph = cp;
                c->keys[q].sph = sp;
                c->keys[q].G = G;
                c->keys[q].T = T;
            }
        }
    }
    /* block 2: the height pyramid (1 channel) and the normals */
    hf_ns_pyr_carve(&A[1], c->hp, c->Lv, c->k, c->W, c->H, 1.0, 1);
    c->normals = (float *)hf_ns_take(&A[1], c->need_normals ? hf_grid_count(c->g) : 0u, 3u * sizeof(float));
    /* block 3: two receiver rows */
    c->win = (double *)hf_ns_take(&A[2], 2u * (size_t)c->Rw, (size_t)c->rec_max * sizeof(double));
    /* block 4: the bounces' buffers and pyramids */
    if (c->B > 0) {
        size_t words = 0;
        if (c->cwords > 0 && (!hfvis__mul_size((size_t)c->Rw * (size_t)c->Rh, m, &words) ||
                              !hfvis__mul_size(words, (size_t)c->cwords, &words)))
            A[3].overflow = 1;
        c->cmask = c->cwords > 0 ? (uint64_t *)hf_ns_take(&A[3], words, sizeof(uint64_t)) : NULL;
        c->exitbuf = (float *)hf_ns_take(&A[3], hf_grid_count(c->g), C * sizeof(float));
        hf_ns_pyr_carve(&A[3], c->dp, c->Lu, c->k, c->W, c->H, 1.0, c->C);
        if (c->gvec) {
            c->ibuf = (float *)hf_ns_take(&A[3], (size_t)c->Rw * (size_t)c->Rh,
                                          C * NS_SH_N * sizeof(float));
            hf_ns_pyr_carve(&A[3], c->ip, c->Lu, c->k, c->Rw, c->Rh, (double)c->s, c->C * NS_SH_N);
        }
    }
}

/* Measure the four blocks. 0 if a size overflows. */
static int hf_ns_measure(hf_ns_ctx *c, size_t bytes[4])
{
    hf_ns_arena A[4];
    int q;
    memset(A, 0, sizeof A);
    hf_ns_carve(c, A);
    for (q = 0; q < 4; q++) {
        if (A[q].overflow) return 0;
        bytes[q] = A[q].used;
    }
    return 1;
}

hfvis_status hfvis_ns_gi_scratch_size(const hfvis_grid *grid, const hfvis_ns_scene *scene,
                                      const hfvis_ns_gi_options *opts, int bounces, size_t *bytes)
{
    hf_ns_ctx c;
    size_t b[4], total = 0;
    int q;
    hfvis_status s;
    if (bytes == NULL) return HFVIS_ERR_INVALID_ARGUMENT;
    if ((s = hf_ns_setup(&c, grid, scene, opts, bounces, 0)) != HFVIS_OK) return s;
    if (!hf_ns_measure(&c, b)) return HFVIS_ERR_INVALID_ARGUMENT;
    for (q = 0; q < 4; q++) {
        if (b[q] > SIZE_MAX - total) return HFVIS_ERR_INVALID_ARGUMENT;
        total += b[q];
    }
    *bytes = total;
    return HFVIS_OK;
}

/* ------------------------------------------------------------------- 4. the slice scan */

/* Apply the border rule to a grid position; 0 if it lies outside an OPEN grid. */
static int hf_ns_place(const hf_ns_ctx *c, double *x, double *y)
{
    const double W = (double)c->W, H = (double)c->H;
    if (c->wrap) {
        *x -= floor(*x / W) * W;
        *y -= floor(*y / H) * H;
        if (!(*x < W)) *x = 0.0;
        if (!(*y < H)) *y = 0.0;
        return 1;
    }
    if (*x < 0.0 || *x > W - 1.0 || *y < 0.0 || *y > H - 1.0) {
        if (c->open) return 0;
        *x = hf_clampd(*x, 0.0, W - 1.0);
        *y = hf_clampd(*y, 0.0, H - 1.0);
    }
    return 1;
}

/* [NS09] Eq. 14-15, 17 along the slice (cph, sph) from receiver r: the tangents of the valid
 * steps into tv (if not NULL; returns their count) and, if cast is not NULL, the casting set
 * seeded with tan(omega_min) = t_seed into cast (*ncast elements, strictly increasing omega), and
 * their step indices as bits into bits (zeroed by the caller) if it is not NULL. */
static int hf_ns_scan(const hf_ns_ctx *c, const hf_ns_recv *r, double cph, double sph, double t_seed,
                      double *tv, hf_ns_cast *cast, int *ncast, uint64_t *bits)
{
    const double W1 = (double)(c->W - 1), H1 = (double)(c->H - 1);
    double run = t_seed;
    int i, nv = 0, K = 0;
    for (i = 0; i < c->n; i++) {
        const int l = c->lv_i[i];
        double x = r->x + c->tau[i] * cph, y = r->y + c->tau[i] * sph, hp = r->hl[l], hq, t;
        if (x < 0.0 || x > W1 || y < 0.0 || y > H1) {
            if (!hf_ns_place(c, &x, &y)) break; /* OPEN: the ray has left the grid for good */
        }
        if (isnan(hp)) continue;
        hq = hf_ns_sample1(&c->hp[l], c->wrap, c->holes, x, y);
        if (isnan(hq)) continue; /* a hole never occludes and never casts */
        t = (hq - hp) * c->inv_dist[i];
        if (tv) tv[nv] = t;
        nv++;
        /* Eq. 17 ([NS09] §5.2, Eq. 14-17): omega_i above the running maximum, which starts at omega_min */
        if (cast && t > run + HF_NS_CAST_TOL * (1.0 + run * run)) {
            cast[K].i = i;
            cast[K].t = t;
            cast[K].x = x;
            cast[K].y = y;
            cast[K].dz = hq - hp;
            K++;
            run = t;
            if (bits) bits[i >> 6] |= (uint64_t)1 << (i & 63);
        }
    }
    if (ncast) *ncast = K;
    return nv;
}

/* sin(omega_max) of a slice (Eq. 16 or the raw maximum); -1 if no step was valid. */
static double hf_ns_smax(hf_ns_ctx *c, int nv)
{
    int i;
    if (nv == 0) return -1.0;
    if (c->o.omega_max == HFVIS_NS_OMEGA_MAX_RAW) {
        double t = c->tv[0];
        for (i = 1; i < nv; i++)
            if (c->tv[i] > t) t = c->tv[i];
        return hf_tan_sine(t);
    }
    return sin(hf_ns_omax_bspline(c->tv, nv, c->wc, c->wa));
}

/* omega_min of the receiver normal N toward (cph, sph) as tangent and sine ([NS09] §3 with the
 * docs/errata.md E47; N_z > 0 for every normal the library makes). */
static void hf_ns_omega_min(const hf_ns_ctx *c, const double *N, double cph, double sph,
                            double *t_min, double *s_min)
{
    double d = N[0] * cph + N[1] * sph;
    if (c->o.omega_min == HFVIS_NS_OMEGA_MIN_PAPER) {
        if (d > 1.0) d = 1.0;
        if (d < -1.0) d = -1.0;
        *s_min = -d;                       /* sin(-asin d) */
        *t_min = fabs(d) < 1.0 ? -d / sqrt(1.0 - d * d) : (d > 0.0 ? -HFVIS__INF : HFVIS__INF);
    } else {
        *s_min = -d / sqrt(d * d + N[2] * N[2]); /* sin(atan2(-d, N_z)) */
        *t_min = -d / N[2];
    }
}

/* Set up receiver r at grid position (X, Y) with unit normal N: its height at every level of the
 * height pyramid. 0 if it is a hole (level 0 not finite) or N is not usable. */
static int hf_ns_recv_at(hf_ns_ctx *c, double X, double Y, const double *N, hf_ns_recv *r)
{
    int l;
    if (!isfinite(N[0]) || !isfinite(N[1]) || !(N[2] > 0.0)) return 0;
    r->x = X;
    r->y = Y;
    r->n[0] = N[0];
    r->n[1] = N[1];
    r->n[2] = N[2];
    r->hl = c->hl;
    for (l = 0; l < c->Lv; l++) r->hl[l] = hf_ns_sample1(&c->hp[l], c->wrap, c->holes, X, Y);
    return !isnan(r->hl[0]);
}

/* ------------------------------------- 5. receiver records: visibility and the direct lights */

/* Record of the direct pass at (X, Y): V_env (16), V_key (16 per separate key light), the shadow
 * factor of each directional light; rec[0] = NaN for a hole. */
static void hf_ns_direct_rec(hf_ns_ctx *c, double X, double Y, const double *N, double *rec, uint64_t *mask)
{
    hf_ns_recv r;
    double *V = rec, *Vk = rec + NS_SH_N, *dv = rec + NS_SH_N * (1 + c->nkey);
    int j, q, nv;
    for (q = 0; q < c->rec_d; q++) rec[q] = 0.0;
    if (!hf_ns_recv_at(c, X, Y, N, &r)) {
        rec[0] = HFVIS__NAN;
        return;
    }
    if (c->env_scan)
        for (j = 0; j < c->m; j++) {
            double sm, v[4], tmin = 0.0, smin = -1.0;
            uint64_t *bits = mask ? mask + (size_t)j * (size_t)c->cwords : NULL;
            int K;
            if (bits || c->o.clamp_to_tangent) hf_ns_omega_min(c, N, c->ecos[j], c->esin[j], &tmin, &smin);
            for (q = 0; bits && q < c->cwords; q++) bits[q] = 0;
            /* the casting set for the bounces comes with the visibility scan ([NS09] §9) */
            nv = hf_ns_scan(c, &r, c->ecos[j], c->esin[j], tmin, c->tv, bits ? c->cast : NULL, &K, bits);
            sm = hf_ns_smax(c, nv);
            c->smax[j] = sm;
            if (c->o.clamp_to_tangent && smin > sm) sm = smin;
            hf_ns_vis(sm, 1.0, v); /* Eq. 11: v = vbar(pi/2) - vbar(omega_max) */
            hf_ns_acc(V, c->G_env + (size_t)j * 64u, v);
        }
    for (q = 0; q < c->nkey; q++) {
        const hf_ns_key *K = &c->keys[q];
        double *VK = Vk + NS_SH_N * q;
        const int mm = K->full ? c->m : c->mk;
        for (j = 0; j < mm; j++) {
            double sm, v[4], tmin, smin, cp = K->full ? c->ecos[j] : K->cph[j];
            double sp = K->full ? c->esin[j] : K->sph[j];
            if (K->full) sm = c->smax[j];
            else {
                nv = hf_ns_scan(c, &r, cp, sp, 0.0, c->tv, NULL, NULL, NULL);
                sm = hf_ns_smax(c, nv);
            }
            /* [NS09] §6: the intersection of [omega_max, pi/2] and [l_min, l_max] */
            if (K->sin_lmin > sm) sm = K->sin_lmin;
            if (c->o.clamp_to_tangent) {
                hf_ns_omega_min(c, N, cp, sp, &tmin, &smin);
                if (smin > sm) sm = smin;
            }
            hf_ns_vis(sm, K->sin_lmax, v);
            hf_ns_acc(VK, (K->full ? c->G_env : K->G) + (size_t)j * 64u, v);
        }
    }
    for (q = 0; q < c->ndir; q++) {
        const hf_ns_dir *D = &c->dirs[q];
        double sm;
        nv = hf_ns_scan(c, &r, D->cph, D->sph, 0.0, c->tv, NULL, NULL, NULL);
        sm = hf_ns_smax(c, nv);
        if (c->o.directional == HFVIS_NS_DIRECTIONAL_SOFT) {
            /* [NS09] §6 soft: clamp(v(phi_L) . P^(sin omega_L), 0, 1) */
            double v[4], P[4], val;
            hf_ns_vis(sm, 1.0, v);
            (void)hfvis_nlp_eval(D->sin_e, P);
            val = v[0] * P[0] + v[1] * P[1] + v[2] * P[2] + v[3] * P[3];
            dv[q] = val < 0.0 ? 0.0 : val > 1.0 ? 1.0 : val;
        } else {
            dv[q] = D->sin_e > sm ? 1.0 : 0.0; /* [omega_L > omega_max(phi_L)] */
        }
    }
}

/* The SH incident radiance of a direct record, channel ch: L_env * V + Sum L_key * V_key, plus
 * the directional lights as SH deltas when sh_dirs ([NS09] §6-7). */
static void hf_ns_incident(const hf_ns_ctx *c, const double *rec, int ch, int sh_dirs, double *I)
{
    int q, i;
    for (i = 0; i < NS_SH_N; i++) I[i] = 0.0;
    if (c->env) hf_ns_matvec_add(c->T_env + (size_t)ch * 256u, rec, I);
    for (q = 0; q < c->nkey; q++) {
        const hf_ns_key *K = &c->keys[q];
        if (c->o.key_mode == HFVIS_NS_KEY_RATIO) {
            /* the visible share of the light's SH energy, Int L V_key / Int L V_box, times L */
            double f = K->box > 0.0 ? hf_ns_dot16(K->Ls, rec + NS_SH_N * (1 + q)) / K->box : 0.0;
            f = f < 0.0 ? 0.0 : f > 1.0 ? 1.0 : f;
            for (i = 0; i < NS_SH_N; i++) I[i] += f * K->E0[ch] * K->Ls[i];
        } else {
            hf_ns_matvec_add(K->T + (size_t)ch * 256u, rec + NS_SH_N * (1 + q), I);
        }
    }
    if (sh_dirs)
        for (q = 0; q < c->ndir; q++) {
            const double f = c->dirs[q].E0[ch] * rec[NS_SH_N * (1 + c->nkey) + q];
            for (i = 0; i < NS_SH_N; i++) I[i] += f * c->dirs[q].Yd[i];
        }
}

/* ------------------------------------------- 6. receiver records: the indirect radiance */

/* Normal at a fractional grid position: bilinear over the full-resolution normals (renormalised
 * over the finite ones), normalised. 0 if none is finite. */
static int hf_ns_normal_interp(const hf_ns_ctx *c, double x, double y, double *N)
{
    int x0, x1, y0, y1, q, i;
    double fx, fy, wt[4], len, tot = 0.0;
    const float *tp[4];
    hf_ns_axis(x, c->W, c->wrap, &x0, &x1, &fx);
    hf_ns_axis(y, c->H, c->wrap, &y0, &y1, &fy);
    wt[0] = (1.0 - fx) * (1.0 - fy);
    wt[1] = fx * (1.0 - fy);
    wt[2] = (1.0 - fx) * fy;
    wt[3] = fx * fy;
    tp[0] = c->normals + ((size_t)y0 * (size_t)c->W + (size_t)x0) * 3u;
    tp[1] = c->normals + ((size_t)y0 * (size_t)c->W + (size_t)x1) * 3u;
    tp[2] = c->normals + ((size_t)y1 * (size_t)c->W + (size_t)x0) * 3u;
    tp[3] = c->normals + ((size_t)y1 * (size_t)c->W + (size_t)x1) * 3u;
    N[0] = N[1] = N[2] = 0.0;
    for (q = 0; q < 4; q++) {
        if (wt[q] == 0.0 || !isfinite(tp[q][0])) continue;
        for (i = 0; i < 3; i++) N[i] += wt[q] * (double)tp[q][i];
        tot += wt[q];
    }
    len = sqrt(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]);
    if (!(tot > 0.0) || !(len > 0.0)) return 0;
    for (i = 0; i < 3; i++) N[i] /= len;
    return 1;
}

/* The casting set of a slice from its cached step indices: the same steps, heights and tangents as
 * hf_ns_scan found them, without scanning the others. */
static int hf_ns_cast_cached(hf_ns_ctx *c, const hf_ns_recv *r, double cph, double sph, const uint64_t *bits)
{
    int w, K = 0;
    for (w = 0; w < c->cwords; w++) {
        uint64_t b = bits[w];
        while (b) {
            int bit = 0, i, l;
            double x, y, hq;
            while (!((b >> bit) & 1u)) bit++;
            b &= b - 1u;
            i = w * 64 + bit;
            l = c->lv_i[i];
            x = r->x + c->tau[i] * cph;
            y = r->y + c->tau[i] * sph;
            if (x < 0.0 || x > (double)(c->W - 1) || y < 0.0 || y > (double)(c->H - 1))
                (void)hf_ns_place(c, &x, &y);
            hq = hf_ns_sample1(&c->hp[l], c->wrap, c->holes, x, y);
            c->cast[K].i = i;
            c->cast[K].t = (hq - r->hl[l]) * c->inv_dist[i];
            c->cast[K].x = x;
            c->cast[K].y = y;
            c->cast[K].dz = hq - r->hl[l];
            K++;
        }
    }
    return K;
}

/* Record of bounce pass at (X, Y): U (16 per channel) from the casting sets (Eq. 12) and the
 * exit radiance of the previous bounce; rec[0] = NaN for a hole. */
static void hf_ns_bounce_rec(hf_ns_ctx *c, double X, double Y, const double *N, double *rec, uint64_t *mask)
{
    hf_ns_recv r;
    const int C = c->C;
    int j, q, ch, K, i;
    for (q = 0; q < c->rec_b; q++) rec[q] = 0.0;
    if (!hf_ns_recv_at(c, X, Y, N, &r)) {
        rec[0] = HFVIS__NAN;
        return;
    }
    for (j = 0; j < c->m; j++) {
        const double cph = c->ecos[j], sph = c->esin[j];
        double tmin, smin, vm[4];
        hf_ns_omega_min(c, N, cph, sph, &tmin, &smin);
        if (mask && c->cfilled) {
            K = hf_ns_cast_cached(c, &r, cph, sph, mask + (size_t)j * (size_t)c->cwords);
        } else {
            uint64_t *bits = mask ? mask + (size_t)j * (size_t)c->cwords : NULL;
            for (i = 0; bits && i < c->cwords; i++) bits[i] = 0;
            (void)hf_ns_scan(c, &r, cph, sph, tmin, NULL, c->cast, &K, bits);
        }
        if (K == 0) continue; /* [NS09] §4, Eq. 9-13; docs/errata.md E48, E49: an empty casting set gives u = 0 */
        for (q = 0; q < K; q++) {
            const hf_ns_cast *e = &c->cast[q];
            const int lu = c->lu_i[e->i];
            double *u = c->ub + (size_t)q * (size_t)C;
            /* [NS09] §5.3: u(tau) from the radiance pyramid at level l_u(i) */
            if (!hf_ns_sampleC(&c->dp[lu], C, c->wrap, c->holes, e->x, e->y, u))
                for (ch = 0; ch < C; ch++) u[ch] = 0.0;
            if (c->gvec) {
                /* glossy: u += specular F_q(s) . I_(b-1)(q), s from q toward the receiver */
                double s3[3], Nq[3], len, ns, R[3], F[NS_SH_N];
                s3[0] = -c->tau[e->i] * c->cell * cph;
                s3[1] = -c->tau[e->i] * c->cell * sph;
                s3[2] = -e->dz;
                len = sqrt(s3[0] * s3[0] + s3[1] * s3[1] + s3[2] * s3[2]);
                if (len > 0.0 && hf_ns_normal_interp(c, e->x, e->y, Nq) &&
                    hf_ns_sampleC(&c->ip[lu], NS_SH_N * C, c->wrap, c->holes, e->x, e->y, c->Iq)) {
                    for (i = 0; i < 3; i++) s3[i] /= len;
                    ns = Nq[0] * s3[0] + Nq[1] * s3[1] + Nq[2] * s3[2];
                    if (ns > 0.0) { /* the receiver is above q's tangent plane */
                        for (i = 0; i < 3; i++) R[i] = 2.0 * ns * Nq[i] - s3[i];
                        hf_ns_lobe(c->Ap, R, F);
                        for (ch = 0; ch < C; ch++) {
                            double g = hf_ns_dot16(F, c->Iq + (size_t)ch * NS_SH_N);
                            if (g > 0.0) u[ch] += c->rho_s * g;
                        }
                    }
                }
            }
            hf_ns_vbar(hf_tan_sine(e->t), c->vb + (size_t)q * 4u);
        }
        hf_ns_vbar(smin, vm);
        /* Eq. 12 (docs/errata.md E48, E49): Sum_k (u_k - u_(k+1)) vbar(omega_k) - u_0 vbar(omega_min) */
        for (ch = 0; ch < C; ch++) {
            double w[4] = {0.0, 0.0, 0.0, 0.0};
            const double u0 = c->ub[ch];
            for (q = 0; q < K; q++) {
                const double du = c->ub[(size_t)q * (size_t)C + (size_t)ch] -
                                  (q + 1 < K ? c->ub[(size_t)(q + 1) * (size_t)C + (size_t)ch] : 0.0);
                const double *vb = c->vb + (size_t)q * 4u;
                w[0] += du * vb[0];
                w[1] += du * vb[1];
                w[2] += du * vb[2];
                w[3] += du * vb[3];
            }
            for (i = 0; i < 4; i++) w[i] -= u0 * vm[i];
            hf_ns_acc(rec + (size_t)ch * NS_SH_N, c->G_env + (size_t)j * 64u, w);
        }
    }
}

/* -------------------------------------------------- 7. shading and the upsampling window */

/* Normalised Phong lobe (S+1)/(2 pi) max(cos, 0)^S: the exact response to a directional light. */
static double hf_ns_phong(double S, double cosv)
{
    return cosv > 0.0 ? (S + 1.0) / NS_TWO_PI * pow(cosv, S) : 0.0;
}

/* Receiver (i, j): position (block centre, clamped to the grid) and normal. 0 if no normal. */
static int hf_ns_recv_pos(const hf_ns_ctx *c, int i, int j, double *X, double *Y, double *N)
{
    if (c->s == 1) {
        *X = (double)i;
        *Y = (double)j;
        hf_normal_at(c->g, i, j, N);
        return isfinite(N[0]);
    }
    *X = hf_clampd((double)(c->s * i) + 0.5 * (double)(c->s - 1), 0.0, (double)(c->W - 1));
    *Y = hf_clampd((double)(c->s * j) + 0.5 * (double)(c->s - 1), 0.0, (double)(c->H - 1));
    return hf_ns_normal_interp(c, *X, *Y, N);
}

/* Coarse rows (r0, r1) and weight f of full-resolution row or column y over R receivers. */
static void hf_ns_coarse(const hf_ns_ctx *c, int y, int R, int *r0, int *r1, double *f)
{
    double v = ((double)y - 0.5 * (double)(c->s - 1)) / (double)c->s, fl = floor(v);
    if (fl < 0.0) {
        *r0 = 0;
        *f = 0.0;
    } else if (fl >= (double)(R - 1)) {
        *r0 = R - 1;
        *f = 0.0;
    } else {
        *r0 = (int)fl;
        *f = v - fl;
    }
    *r1 = *r0 + 1 < R ? *r0 + 1 : R - 1;
}

/* The record of texel (x, y) from the two window rows: bilinear over the valid receivers
 * (renormalised), or NULL if none has weight (the caller then computes the texel itself). */
static const double *hf_ns_upsample(hf_ns_ctx *c, int x, int y, int rec, double *out)
{
    int i0, i1, j0, j1, q, r, wq;
    double fx, fy, wt[4], tot = 0.0;
    const double *rp[4];
    if (c->s == 1) {
        const double *p = c->win + ((size_t)(y & 1) * (size_t)c->Rw + (size_t)x) * (size_t)rec;
        return isnan(p[0]) ? NULL : p;
    }
    hf_ns_coarse(c, x, c->Rw, &i0, &i1, &fx);
    hf_ns_coarse(c, y, c->Rh, &j0, &j1, &fy);
    wt[0] = (1.0 - fx) * (1.0 - fy);
    wt[1] = fx * (1.0 - fy);
    wt[2] = (1.0 - fx) * fy;
    wt[3] = fx * fy;
    rp[0] = c->win + ((size_t)(j0 & 1) * (size_t)c->Rw + (size_t)i0) * (size_t)rec;
    rp[1] = c->win + ((size_t)(j0 & 1) * (size_t)c->Rw + (size_t)i1) * (size_t)rec;
    rp[2] = c->win + ((size_t)(j1 & 1) * (size_t)c->Rw + (size_t)i0) * (size_t)rec;
    rp[3] = c->win + ((size_t)(j1 & 1) * (size_t)c->Rw + (size_t)i1) * (size_t)rec;
    for (r = 0; r < rec; r++) out[r] = 0.0;
    wq = 0;
    for (q = 0; q < 4; q++) {
        if (wt[q] == 0.0 || isnan(rp[q][0])) continue;
        for (r = 0; r < rec; r++) out[r] += wt[q] * rp[q][r];
        tot += wt[q];
        wq++;
    }
    if (wq == 0) return NULL;
    if (tot != 1.0)
        for (r = 0; r < rec; r++) out[r] /= tot;
    return out;
}

/* Shade row y of pass b (0 = direct): outputs, and the exit radiance the next bounce gathers. */
static void hf_ns_shade_row(hf_ns_ctx *c, int b, int y, const hfvis_ns_gi_outputs *out)
{
    const int C = c->C, rec = b == 0 ? c->rec_d : c->rec_b;
    const hfvis_ns_scene *sc = c->sc;
    const size_t plane = hf_grid_count(c->g) * (size_t)C;
    float *bo = (b > 0 && out->bounce) ? out->bounce + (size_t)(b - 1) * plane : NULL;
    int x, ch, q;
    for (x = 0; x < c->W; x++) {
        const size_t px = (size_t)y * (size_t)c->W + (size_t)x, o0 = px * (size_t)C;
        const double *r;
        double N[3], FN[NS_SH_N], FR[NS_SH_N], R[3], nv = 0.0;
        if (!isfinite(c->g->z[(ptrdiff_t)y * c->g->stride + x])) {
            for (ch = 0; ch < C; ch++) {
                if (b == 0 && out->direct) out->direct[o0 + (size_t)ch] = (float)HFVIS__NAN;
                if (bo) bo[o0 + (size_t)ch] = (float)HFVIS__NAN;
                if (out->total) out->total[o0 + (size_t)ch] = (float)HFVIS__NAN;
                if (c->exitbuf && b < c->B) c->exitbuf[o0 + (size_t)ch] = (float)HFVIS__NAN;
            }
            continue;
        }
        hf_normal_at(c->g, x, y, N);
        r = hf_ns_upsample(c, x, y, rec, c->rtmp);
        if (r == NULL) { /* no receiver around: this texel is a receiver of its own */
            if (b == 0) hf_ns_direct_rec(c, (double)x, (double)y, N, c->rtmp, NULL);
            else hf_ns_bounce_rec(c, (double)x, (double)y, N, c->rtmp, NULL);
            r = c->rtmp;
        }
        /* [NS09] §7: F(w_o) = the lobe rotated to N (diffuse) or to R = reflect(view, N) (Phong) */
        hf_ns_lobe(c->Ad, N, FN);
        if (c->gloss) {
            nv = N[0] * c->view[0] + N[1] * c->view[1] + N[2] * c->view[2];
            for (q = 0; q < 3; q++) R[q] = 2.0 * nv * N[q] - c->view[q];
            hf_ns_lobe(c->Ap, R, FR);
        }
        for (ch = 0; ch < C; ch++) {
            const size_t oi = o0 + (size_t)ch;
            const double rho = sc->albedo_map ? (double)sc->albedo_map[oi] : (double)sc->albedo[ch];
            double E, Gl = 0.0, val, ex;
            if (isnan(r[0])) {
                val = ex = HFVIS__NAN;
            } else if (b == 0) {
                const double emis = sc->emission ? (double)sc->emission[oi] : 0.0;
                const int sh_dirs = c->o.directional == HFVIS_NS_DIRECTIONAL_SH;
                double *I = c->vtmp;
                hf_ns_incident(c, r, ch, sh_dirs, I);
                E = hf_ns_dot16(FN, I);
                if (c->gloss) Gl = hf_ns_dot16(FR, I);
                if (!sh_dirs)
                    for (q = 0; q < c->ndir; q++) {
                        const hf_ns_dir *D = &c->dirs[q];
                        const double vis = r[NS_SH_N * (1 + c->nkey) + q];
                        const double cl = N[0] * D->d[0] + N[1] * D->d[1] + N[2] * D->d[2];
                        if (vis == 0.0) continue;
                        if (cl > 0.0) E += D->E0[ch] * cl * vis;
                        if (c->gloss)
                            Gl += D->E0[ch] * vis *
                                  hf_ns_phong(c->S, R[0] * D->d[0] + R[1] * D->d[1] + R[2] * D->d[2]);
                    }
                ex = emis + rho / HFVIS__PI * E;
                val = ex + c->rho_s * Gl;
            } else {
                const double *U = r + (size_t)ch * NS_SH_N;
                E = hf_ns_dot16(FN, U);
                if (c->gloss) Gl = hf_ns_dot16(FR, U);
                ex = rho / HFVIS__PI * E;
                val = ex + c->rho_s * Gl;
            }
            if (c->o.glossy == HFVIS_NS_GLOSSY_SCALAR) ex = val;
            if (b == 0) {
                if (out->direct) out->direct[oi] = (float)val;
                if (out->total) out->total[oi] = (float)val;
            } else {
                if (bo) bo[oi] = (float)val;
                if (out->total) out->total[oi] = (float)((double)out->total[oi] + val);
            }
            if (c->exitbuf && b < c->B) c->exitbuf[oi] = (float)ex;
        }
    }
}

/* One pass over the receivers (b = 0: visibility and direct light; b >= 1: bounce b), two
 * receiver rows at a time; each full-resolution row is shaded as soon as the receiver rows around
 * it exist. */
static void hf_ns_pass(hf_ns_ctx *c, int b, const hfvis_ns_gi_outputs *out, int *done, int total)
{
    const int rec = b == 0 ? c->rec_d : c->rec_b;
    int i, j, y = 0, ch, q;
    for (j = 0; j < c->Rh; j++) {
        double *row = c->win + (size_t)(j & 1) * (size_t)c->Rw * (size_t)rec;
        for (i = 0; i < c->Rw; i++) {
            double X, Y, N[3], *r = row + (size_t)i * (size_t)rec;
            const size_t ri = (size_t)j * (size_t)c->Rw + (size_t)i;
            if (hf_ns_recv_pos(c, i, j, &X, &Y, N)) {
                uint64_t *mask = c->cmask ? c->cmask + ri * (size_t)c->m * (size_t)c->cwords : NULL;
                if (b == 0) hf_ns_direct_rec(c, X, Y, N, r, c->env_scan ? mask : NULL);
                else hf_ns_bounce_rec(c, X, Y, N, r, mask);
            } else {
                for (q = 0; q < rec; q++) r[q] = 0.0;
                r[0] = HFVIS__NAN;
            }
            if (b == 0 && c->want_vis && out->visibility)
                for (q = 0; q < NS_SH_N; q++)
                    out->visibility[ri * NS_SH_N + (size_t)q] = isnan(r[0]) ? (float)HFVIS__NAN : (float)r[q];
            if (c->gvec && b < c->B) {
                /* the glossy pyramid's input: I_0 = L * V (+ the directional lights as SH deltas), or
                 * I_b = U_b ([NS09] §5.3) */
                float *Ib = c->ibuf + ri * (size_t)c->C * NS_SH_N;
                for (ch = 0; ch < c->C; ch++) {
                    double *I = c->vtmp;
                    if (b == 0) hf_ns_incident(c, r, ch, 1, I);
                    else
                        for (q = 0; q < NS_SH_N; q++) I[q] = r[(size_t)ch * NS_SH_N + (size_t)q];
                    for (q = 0; q < NS_SH_N; q++)
                        Ib[(size_t)ch * NS_SH_N + (size_t)q] = isnan(r[0]) ? (float)HFVIS__NAN : (float)I[q];
                }
            }
        }
        for (; y < c->H; y++) {
            int r0, r1;
            double f;
            hf_ns_coarse(c, y, c->Rh, &r0, &r1, &f);
            if (r1 > j) break;
            hf_ns_shade_row(c, b, y, out);
        }
        ++*done;
        if (c->o.progress) c->o.progress(c->o.progress_user, *done, total);
    }
}

/* ------------------------------------------------------------------------ 8. the driver */

/* Fill the tables: steps, directions, wedge sample matrices, light products, lobes, kernels. */
static void hf_ns_tables(hf_ns_ctx *c)
{
    const hfvis_ns_scene *sc = c->sc;
    const int C = c->C, nb = c->order * c->order;
    hfvis_ns_wedges ws;
    double Lenv[4 * NS_SH_N];
    int i, j, q, ch, kk, dq = 0;
    memset(&ws, 0, sizeof ws);
    (void)hfvis_sh_product_tensor(c->gamma);
    for (i = 0; i < c->n; i++) {
        /* Eq. 14 in cell units ([NS09] §5.2, Eq. 14-17): tau_i = 2^(i/k); l_v(i) = max(0, i - k o_v) */
        c->tau[i] = pow(2.0, (double)i / (double)c->k);
        c->inv_dist[i] = 1.0 / (c->tau[i] * c->cell);
        c->lv_i[i] = i - c->k * c->ov < 0 ? 0 : i - c->k * c->ov;
        c->lu_i[i] = i - c->k * c->ou < 0 ? 0 : i - c->k * c->ou;
    }
    for (j = 0; j < c->m; j++) {
        double phi = c->o.azimuth0_rad + NS_TWO_PI * (double)j / (double)c->m;
        c->ecos[j] = fabs(cos(phi)) < HF_NS_SNAP ? 0.0 : cos(phi);
        c->esin[j] = fabs(sin(phi)) < HF_NS_SNAP ? 0.0 : sin(phi);
    }
    /* full circle: m wedges with the wrap-around one (docs/errata.md E51 on Eq. 21) */
    (void)hfvis_ns_wedges_full(&ws, c->o.interp, c->m, c->o.azimuth0_rad);
    (void)hfvis_ns_sample_matrices(&ws, c->G_env);
    for (j = 0; j < c->m; j++)
        for (i = nb * 4; i < 64; i++) c->G_env[(size_t)j * 64u + (size_t)i] = 0.0;
    /* lights */
    for (i = 0; i < 4 * NS_SH_N; i++) Lenv[i] = 0.0;
    if (sc->env_sh)
        for (ch = 0; ch < C; ch++)
            for (i = 0; i < nb; i++) Lenv[ch * NS_SH_N + i] = sc->env_sh[ch * NS_SH_N + i];
    kk = 0;
    for (q = 0; q < sc->light_count; q++) {
        const hfvis_sun *L = &sc->lights[q];
        const double e = L->elevation_rad, ce = cos(e), se = sin(e), psi = L->azimuth_rad;
        double a[3], cph = cos(psi), sph = sin(psi);
        cph = fabs(cph) < HF_NS_SNAP ? 0.0 : cph;
        sph = fabs(sph) < HF_NS_SNAP ? 0.0 : sph;
        a[0] = ce * cph;
        a[1] = ce * sph;
        a[2] = se;
        if (L->radius_rad == 0.0) {
            hf_ns_dir *D = &c->dirs[dq++];
            D->d[0] = a[0];
            D->d[1] = a[1];
            D->d[2] = a[2];
            D->cph = cph;
            D->sph = sph;
            D->sin_e = se;
            for (ch = 0; ch < 4; ch++) D->E0[ch] = ch < C ? (double)L->irradiance[ch] : 0.0;
            ns_sh_eval_unit(a[0], a[1], a[2], D->Yd);
            for (i = nb; i < NS_SH_N; i++) D->Yd[i] = 0.0;
        } else {
            /* [NS09] §6: a uniform cap of angular radius alpha about a, L0 = E0 / (pi sin^2 alpha)
             * (its irradiance on a facing surface is L0 pi sin^2 alpha), L_lm = L0 Ahat_l Y_lm(a) */
            double Ah[4], F[NS_SH_N], sa = sin(L->radius_rad);
            double *dst;
            (void)hfvis_zh_cap(L->radius_rad, Ah);
            (void)hfvis_sh_from_zh(Ah, a, F);
            if (c->o.key_mode != HFVIS_NS_KEY_ENVIRONMENT) {
                hf_ns_key *K = &c->keys[kk++];
                double vb[4], Vbox[NS_SH_N];
                double lmin = e - L->radius_rad, lmax = e + L->radius_rad, Lk[4 * NS_SH_N];
                if (lmin < -HFVIS__HALF_PI) lmin = -HFVIS__HALF_PI;
                if (lmax > HFVIS__HALF_PI) lmax = HFVIS__HALF_PI;
                K->sin_lmin = sin(lmin);
                K->sin_lmax = sin(lmax);
                K->full = !(L->radius_rad < HFVIS__HALF_PI - fabs(e));
                if (!K->full) {
                    /* azimuth extent phi_c +- asin(sin alpha / cos e), key_directions samples */
                    double half = asin(sa / ce), pa = psi - half, pb = psi + half;
                    (void)hfvis_ns_wedges_partial(&ws, c->o.interp, c->mk, pa, pb);
                    (void)hfvis_ns_sample_matrices(&ws, K->G);
                    for (j = 0; j < c->mk; j++) {
                        double ph = pa + (double)j * ws.dphi_rad;
                        K->cph[j] = fabs(cos(ph)) < HF_NS_SNAP ? 0.0 : cos(ph);
                        K->sph[j] = fabs(sin(ph)) < HF_NS_SNAP ? 0.0 : sin(ph);
                        for (i = nb * 4; i < 64; i++) K->G[(size_t)j * 64u + (size_t)i] = 0.0;
                    }
                }
                /* RATIO: L per unit irradiance and its overlap with the unoccluded box */
                for (i = 0; i < NS_SH_N; i++) {
                    K->Ls[i] = i < nb ? F[i] / (HFVIS__PI * sa * sa) : 0.0;
                    Vbox[i] = 0.0;
                }
                for (ch = 0; ch < 4; ch++) K->E0[ch] = ch < C ? (double)L->irradiance[ch] : 0.0;
                hf_ns_vis(K->sin_lmin, K->sin_lmax, vb);
                for (j = 0; j < (K->full ? c->m : c->mk); j++)
                    hf_ns_acc(Vbox, (K->full ? c->G_env : K->G) + (size_t)j * 64u, vb);
                K->box = hf_ns_dot16(K->Ls, Vbox);
                dst = Lk;
                for (ch = 0; ch < C; ch++)
                    for (i = 0; i < NS_SH_N; i++)
                        dst[ch * NS_SH_N + i] = i < nb ? (double)L->irradiance[ch] / (HFVIS__PI * sa * sa) * F[i] : 0.0;
                /* T[ch][r][j] = Sum_i Gamma_ijr L_i: the SH product L * V as a matrix on V */
                for (ch = 0; ch < C; ch++)
                    for (i = 0; i < NS_SH_N; i++)
                        for (j = 0; j < NS_SH_N; j++) {
                            double s = 0.0;
                            int r2;
                            for (r2 = 0; r2 < NS_SH_N; r2++)
                                s += c->gamma[(r2 * NS_SH_N + j) * NS_SH_N + i] * Lk[ch * NS_SH_N + r2];
                            K->T[(size_t)ch * 256u + (size_t)(i * NS_SH_N + j)] = i < nb ? s : 0.0;
                        }
            } else {
                for (ch = 0; ch < C; ch++)
                    for (i = 0; i < nb; i++)
                        Lenv[ch * NS_SH_N + i] += (double)L->irradiance[ch] / (HFVIS__PI * sa * sa) * F[i];
            }
        }
    }
    for (ch = 0; ch < C; ch++)
        for (i = 0; i < NS_SH_N; i++)
            for (j = 0; j < NS_SH_N; j++) {
                double s = 0.0;
                int r2;
                for (r2 = 0; r2 < NS_SH_N; r2++)
                    s += c->gamma[(r2 * NS_SH_N + j) * NS_SH_N + i] * Lenv[ch * NS_SH_N + r2];
                c->T_env[(size_t)ch * 256u + (size_t)(i * NS_SH_N + j)] = i < nb ? s : 0.0;
            }
    /* lobes (Ahat multipliers), bands >= order dropped */
    (void)hfvis_zh_diffuse(c->Ad);
    if (c->gloss) (void)hfvis_zh_phong(c->S, c->Ap);
    for (i = c->order; i < 4; i++) c->Ad[i] = c->Ap[i] = 0.0;
    c->view[0] = c->o.view_dir[0];
    c->view[1] = c->o.view_dir[1];
    c->view[2] = c->o.view_dir[2];
    for (j = 0; j < c->k; j++) hf_ns_blur_kernel(c->k, j, c->kern + (size_t)j * HF_NS_KTAPS);
}

hfvis_status hfvis_ns_gi(const hfvis_grid *grid, const hfvis_ns_scene *scene,
                         const hfvis_ns_gi_options *opts, const hfvis_ns_gi_outputs *out)
{
    hf_ns_ctx c;
    hf_ns_arena A[4];
    size_t bytes[4], plane, t;
    const hfvis_allocator *alloc;
    void *blk[4] = {NULL, NULL, NULL, NULL};
    int q, b, x, y, done = 0, total;
    hfvis_status s;
    if (out == NULL) return HFVIS_ERR_INVALID_ARGUMENT;
    if ((s = hf_ns_setup(&c, grid, scene, opts, out->bounces, out->visibility != NULL)) != HFVIS_OK)
        return s;
    plane = hf_grid_count(grid) * (size_t)c.C; /* checked by hf_ns_setup */
    if (!hfvis__mul_size(plane, (size_t)c.B, &t) ||
        !hfvis__mul_size((size_t)c.Rw * (size_t)c.Rh, NS_SH_N, &t) || !hf_ns_measure(&c, bytes))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (!out->direct && !out->bounce && !out->total && !out->visibility) return HFVIS_OK;
    alloc = c.o.alloc;
    for (q = 0; q < 4; q++) {
        if (bytes[q] == 0) continue;
        blk[q] = hfvis__alloc(alloc, bytes[q]);
        if (blk[q] == NULL) {
            while (q-- > 0) hfvis__free(alloc, blk[q]);
            return HFVIS_ERR_OUT_OF_MEMORY;
        }
    }
    memset(A, 0, sizeof A);
    for (q = 0; q < 4; q++) A[q].base = (unsigned char *)blk[q];
    hf_ns_carve(&c, A);
    hf_ns_tables(&c);
    /* the height pyramid (level 0 = the heights, holes as NaN) and the normals */
    for (y = 0; y < c.H; y++)
        for (x = 0; x < c.W; x++) {
            float z = grid->z[(ptrdiff_t)y * grid->stride + x];
            c.hp[0].img[(size_t)y * (size_t)c.W + (size_t)x] = isfinite(z) ? z : (float)HFVIS__NAN;
            if (!isfinite(z)) c.holes = 1;
        }
    hf_ns_pyr_build(c.hp, c.Lv, c.k, 1, c.border, c.kern, c.row);
    if (c.need_normals) (void)hfvis_normals_compute(grid, c.normals);
    total = c.Rh * (1 + c.B);
    hf_ns_pass(&c, 0, out, &done, total);
    c.cfilled = c.env_scan; /* the direct pass scanned the casting sets with the visibility */
    for (b = 1; b <= c.B; b++) {
        /* [NS09] §5.3: the radiance pyramid of bounce b-1 (and the glossy SH pyramid) */
        memcpy(c.dp[0].img, c.exitbuf, plane * sizeof(float));
        hf_ns_pyr_build(c.dp, c.Lu, c.k, c.C, c.border, c.kern, c.row);
        if (c.gvec) {
            memcpy(c.ip[0].img, c.ibuf, (size_t)c.Rw * (size_t)c.Rh * (size_t)c.C * NS_SH_N * sizeof(float));
            hf_ns_pyr_build(c.ip, c.Lu, c.k, c.C * NS_SH_N, c.border, c.kern, c.row);
        }
        hf_ns_pass(&c, b, out, &done, total);
        c.cfilled = 1;
    }
    for (q = 3; q >= 0; q--) hfvis__free(alloc, blk[q]);
    return HFVIS_OK;
}

/* ========================================================================================== */
/* 15. Split runs: raw direction sums and the partial-sum file                                */
/* ========================================================================================== */
/* Every fused output is a finish of a per-receiver sum over directions (hfvis.h, "split runs"):
 * Zaksek et al. 2011 (SVF), [P1] Eq. 5-6 (sky, environment), [P2] §10.1 (visibility index).
 * hfvis_direction_sums runs the same fused consumer as the finished routine over the options'
 * direction range and returns the grid accumulator itself, in double. */

hfvis_status hfvis_direction_sums(const hfvis_grid *grid, int K, hfvis_sum_kind kind,
                                  const hfvis_env *env, const hfvis_env_options *eopts,
                                  const hfvis_sweep_options *opts, double *sums)
{
    hfvis_sweep_options o;
    hf_sweep sw;
    hf_fused sky;
    hf_env_ctx ec;
    hf_env_eval eval;
    hf_p2_ctx p2;
    float *table = NULL;
    hfvis_status s;
    int channels = 1, begin, end, x, y, c;
    if (opts) { /* bands: exact rays only (below), the rest checked as for one call */
        o = *opts;
        if (!hf_parts_valid(opts)) return HFVIS_ERR_INVALID_ARGUMENT;
        o.part_index = o.part_count = 0;
    }
    if (hf_check_common(grid, opts ? &o : NULL) != HFVIS_OK || !sums || K < 1 || kind < HFVIS_SUM_SKY_VIEW ||
        kind > HFVIS_SUM_VISIBILITY || (kind == HFVIS_SUM_ENV_LIGHT && !hf_env_valid(env)) ||
        (opts && opts->part_count > 1 && (opts->rays != HFVIS_RAYS_EXACT || kind == HFVIS_SUM_VISIBILITY)))
        return HFVIS_ERR_INVALID_ARGUMENT;
    o = hf_opts_resolve(grid, opts);
    if (hf_direction_range(&o, K, &begin, &end) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    if (kind == HFVIS_SUM_VISIBILITY && hf_p2_opts_limited(&o)) /* the P2 tree: no windows */
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.rays == HFVIS_RAYS_EXACT && kind != HFVIS_SUM_VISIBILITY)
        return hf_exact_direction_sums(grid, K, kind, env, eopts, &o, begin, end, sums);
    memset(&sky, 0, sizeof sky);
    sky.gacc_out = sums; /* the grid accumulator is sums itself: no copy */
    switch (kind) {
    case HFVIS_SUM_SKY_VIEW:
        sky.walk = HF_WALK_SVF;
        s = hf_fused_run(&sw, grid, K, &o, 1, 0, hf_svf_line, &sky);
        break;
    case HFVIS_SUM_SKY_LIGHT:
        hf_sky_setup(&sky, K);
        s = hf_fused_run(&sw, grid, K, &o, 1, 1, hf_sky_line, &sky);
        break;
    case HFVIS_SUM_ENV_LIGHT:
        channels = env->channels;
        s = hf_env_tables_create(env, K, o.azimuth0_rad, eopts, o.alloc, &table, &eval);
        if (s != HFVIS_OK) return s;
        memset(&ec, 0, sizeof ec);
        ec.e = &eval;
        ec.f.gacc_out = sums;
        s = hf_fused_run(&sw, grid, K, &o, channels, 1, hf_env_line, &ec.f);
        break;
    default: /* HFVIS_SUM_VISIBILITY */
        memset(&p2, 0, sizeof p2);
        p2.fn = hf_p2_count;
        s = hf_p2_run(&sw, grid, K, &o, 1, 0, &p2);
        break;
    }
    if (s == HFVIS_OK) {
        for (y = sw.ry0; y < sw.ry1; y++) /* the receiver rectangle (in place but for P2's) */
            for (x = sw.rx0; x < sw.rx1; x++) {
                size_t i = ((size_t)y * (size_t)grid->width + (size_t)x) * (size_t)channels;
                if (hf_is_hole(grid, x, y))
                    for (c = 0; c < channels; c++) sums[i + (size_t)c] = HFVIS__NAN;
                else if (sw.gacc != sums)
                    for (c = 0; c < channels; c++) sums[i + (size_t)c] = sw.gacc[i + (size_t)c];
            }
        hf_sweep_free(&sw);
    }
    hfvis__free(o.alloc, table);
    return s;
}

#define HF_PARTIAL_MAGIC "HFVISSUM 2\n"
#define HF_PARTIAL_MAGIC_LEN 11u
#define HF_PARTIAL_CRC_LEN 4u /* the trailing hfvis_crc32 of everything before it */
#define HF_PARTIAL_NUMBERS 6

/* The six header numbers of p, or 0 if p is invalid; *values receives planes*width*height. */
static int hf_partial_valid(const hfvis_partial *p, size_t *values, size_t *tag_len)
{
    size_t n, t;
    if (!p || !p->tag || !p->sums || p->width < 1 || p->height < 1 ||
        p->width > HFVIS_IMAGE_MAX_DIM || p->height > HFVIS_IMAGE_MAX_DIM || p->planes < 1 ||
        p->planes > HFVIS_PARTIAL_MAX_PLANES || p->directions < 1 || p->begin < 0 ||
        p->begin >= p->end || p->end > p->directions)
        return 0;
    n = (size_t)p->width * (size_t)p->height;
    if (!hfvis__mul_size(n, (size_t)p->planes, &n) || (unsigned long long)n > HFVIS_PARTIAL_MAX_VALUES ||
        n > SIZE_MAX / 8u)
        return 0;
    for (t = 0; t <= HFVIS_PARTIAL_MAX_TAG && p->tag[t] != '\0'; t++)
        if ((unsigned char)p->tag[t] < 32u || (unsigned char)p->tag[t] > 126u) return 0;
    if (t == 0 || t > HFVIS_PARTIAL_MAX_TAG) return 0;
    *values = n;
    *tag_len = t;
    return 1;
}

/* Decimal digits of v (>= 0) into buf, returns the count. */
static size_t hf_partial_digits(unsigned char *buf, int v)
{
    unsigned char d[12];
    size_t nd = 0, i;
    unsigned u = (unsigned)v;
    do {
        d[nd++] = (unsigned char)('0' + u % 10u);
        u /= 10u;
    } while (u != 0);
    for (i = 0; i < nd; i++) buf[i] = d[nd - 1 - i];
    return nd;
}

/* The header line of numbers, at most 6*11 bytes. */
static size_t hf_partial_numbers(const hfvis_partial *p, unsigned char *buf)
{
    const int v[HF_PARTIAL_NUMBERS] = { p->width, p->height, p->planes, p->directions, p->begin, p->end };
    size_t len = 0;
    int i;
    for (i = 0; i < HF_PARTIAL_NUMBERS; i++) {
        len += hf_partial_digits(buf + len, v[i]);
        buf[len++] = (unsigned char)(i + 1 < HF_PARTIAL_NUMBERS ? ' ' : '\n');
    }
    return len;
}

size_t hfvis_partial_encode_size(const hfvis_partial *p)
{
    unsigned char line[6 * 12];
    size_t values, tag_len, head, bytes;
    if (!hf_partial_valid(p, &values, &tag_len)) return 0;
    head = HF_PARTIAL_MAGIC_LEN + hf_partial_numbers(p, line) + tag_len + 1u + HF_PARTIAL_CRC_LEN;
    if (!hfvis__mul_size(values, 8u, &bytes) || bytes > SIZE_MAX - head) return 0;
    return head + bytes;
}

hfvis_status hfvis_partial_encode(const hfvis_partial *p, void *out, size_t out_capacity,
                                  size_t *written)
{
    unsigned char *dst = (unsigned char *)out;
    size_t need = hfvis_partial_encode_size(p), values, tag_len, i;
    uint32_t crc;
    int b;
    if (!out || !written || need == 0 || !hf_partial_valid(p, &values, &tag_len))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (out_capacity < need) return HFVIS_ERR_BUFFER_TOO_SMALL;
    memcpy(dst, HF_PARTIAL_MAGIC, HF_PARTIAL_MAGIC_LEN);
    dst += HF_PARTIAL_MAGIC_LEN;
    dst += hf_partial_numbers(p, dst);
    memcpy(dst, p->tag, tag_len);
    dst += tag_len;
    *dst++ = '\n';
    for (i = 0; i < values; i++) {
        uint64_t u;
        memcpy(&u, &p->sums[i], 8);
        for (b = 0; b < 8; b++) *dst++ = (unsigned char)((u >> (8 * b)) & 0xffu);
    }
    crc = hfvis_crc32(0, out, need - HF_PARTIAL_CRC_LEN);
    for (b = 0; b < 4; b++) *dst++ = (unsigned char)((crc >> (8 * b)) & 0xffu);
    *written = need;
    return HFVIS_OK;
}

/* One decimal number 0..INT_MAX at data[*pos], no sign, no leading zero, then the byte end. */
static int hf_partial_number(const unsigned char *data, size_t size, size_t *pos, unsigned char end,
                             int *out)
{
    size_t i = *pos;
    long long v = 0;
    if (i >= size || data[i] < '0' || data[i] > '9') return 0;
    if (data[i] == '0' && i + 1 < size && data[i + 1] >= '0' && data[i + 1] <= '9') return 0;
    while (i < size && data[i] >= '0' && data[i] <= '9') {
        v = v * 10 + (data[i] - '0');
        if (v > INT_MAX) return 0;
        i++;
    }
    if (i >= size || data[i] != end) return 0;
    *pos = i + 1;
    *out = (int)v;
    return 1;
}

/* The header of a partial-sum file in d[0..size) (size may end anywhere after it): the numbers
 * into r, the tag's offset and length, the body's offset and its value count. */
static hfvis_status hf_partial_header(const unsigned char *d, size_t size, hfvis_partial *r,
                                      size_t *tag_at, size_t *tag_bytes, size_t *body, size_t *count)
{
    int v[HF_PARTIAL_NUMBERS], i;
    size_t pos = HF_PARTIAL_MAGIC_LEN, tag0, tag_len, values;
    if (size < HF_PARTIAL_MAGIC_LEN || memcmp(d, HF_PARTIAL_MAGIC, HF_PARTIAL_MAGIC_LEN) != 0)
        return HFVIS_ERR_FORMAT;
    for (i = 0; i < HF_PARTIAL_NUMBERS; i++)
        if (!hf_partial_number(d, size, &pos, (unsigned char)(i + 1 < HF_PARTIAL_NUMBERS ? ' ' : '\n'), &v[i]))
            return HFVIS_ERR_FORMAT;
    tag0 = pos;
    while (pos < size && pos - tag0 <= HFVIS_PARTIAL_MAX_TAG && d[pos] != '\n') {
        if (d[pos] < 32u || d[pos] > 126u) return HFVIS_ERR_FORMAT;
        pos++;
    }
    tag_len = pos - tag0;
    if (pos >= size || d[pos] != '\n' || tag_len == 0 || tag_len > HFVIS_PARTIAL_MAX_TAG)
        return HFVIS_ERR_FORMAT;
    pos++;
    memset(r, 0, sizeof *r);
    r->width = v[0], r->height = v[1], r->planes = v[2], r->directions = v[3], r->begin = v[4], r->end = v[5];
    if (r->width < 1 || r->height < 1 || r->planes < 1 || r->directions < 1 || r->begin >= r->end ||
        r->end > r->directions)
        return HFVIS_ERR_FORMAT;
    if (r->width > HFVIS_IMAGE_MAX_DIM || r->height > HFVIS_IMAGE_MAX_DIM || r->planes > HFVIS_PARTIAL_MAX_PLANES)
        return HFVIS_ERR_LIMIT;
    values = (size_t)r->width * (size_t)r->height;
    if (!hfvis__mul_size(values, (size_t)r->planes, &values) ||
        (unsigned long long)values > HFVIS_PARTIAL_MAX_VALUES || values > SIZE_MAX / 8u)
        return HFVIS_ERR_LIMIT;
    *tag_at = tag0;
    *tag_bytes = tag_len;
    *body = pos;
    *count = values;
    return HFVIS_OK;
}

#ifndef HFVIS_NO_STDIO
/* The partial-sum file's sizer (hfvis__read_file): header, body, checksum. */
static hfvis_status hf_partial_sizer(const unsigned char *head, size_t n, size_t *total)
{
    hfvis_partial r;
    size_t tag0, tag_len, pos, values;
    hfvis_status s = hf_partial_header(head, n, &r, &tag0, &tag_len, &pos, &values);
    if (s != HFVIS_OK) return s;
    if (values > (SIZE_MAX - pos - HF_PARTIAL_CRC_LEN) / 8u) return HFVIS_ERR_LIMIT;
    *total = pos + values * 8u + HF_PARTIAL_CRC_LEN;
    return HFVIS_OK;
}
#endif

hfvis_status hfvis_partial_decode(const void *data, size_t size, const hfvis_allocator *alloc,
                                  hfvis_partial *p)
{
    const unsigned char *d = (const unsigned char *)data;
    hfvis_partial r;
    size_t pos, tag0, tag_len, values, bytes, block, k;
    uint32_t crc;
    unsigned char *mem;
    hfvis_status s;
    if (!data || !p) return HFVIS_ERR_INVALID_ARGUMENT;
    s = hf_partial_header(d, size, &r, &tag0, &tag_len, &pos, &values);
    if (s != HFVIS_OK) return s;
    bytes = values * 8u;
    if (bytes > SIZE_MAX - tag_len - 1u - HF_PARTIAL_CRC_LEN) return HFVIS_ERR_LIMIT;
    if (size - pos != bytes + HF_PARTIAL_CRC_LEN) return HFVIS_ERR_FORMAT;
    for (k = 0, crc = 0; k < HF_PARTIAL_CRC_LEN; k++)
        crc |= (uint32_t)d[size - HF_PARTIAL_CRC_LEN + k] << (8u * k);
    if (hfvis_crc32(0, d, size - HF_PARTIAL_CRC_LEN) != crc) return HFVIS_ERR_FORMAT;
    block = bytes + tag_len + 1u;
    mem = (unsigned char *)hfvis__alloc(alloc, block);
    if (!mem) return HFVIS_ERR_OUT_OF_MEMORY;
    r.sums = (double *)(void *)mem;
    for (k = 0; k < values; k++) {
        const unsigned char *b = d + pos + 8u * k;
        uint64_t u = 0;
        int q;
        for (q = 7; q >= 0; q--) u = (u << 8) | b[q];
        memcpy(&r.sums[k], &u, 8);
    }
    memcpy(mem + bytes, d + tag0, tag_len);
    mem[bytes + tag_len] = '\0';
    r.tag = (const char *)(mem + bytes);
    *p = r;
    return HFVIS_OK;
}

void hfvis_partial_free(const hfvis_allocator *alloc, hfvis_partial *p)
{
    if (!p) return;
    hfvis__free(alloc, p->sums);
    p->sums = NULL;
    p->tag = NULL;
}

#ifndef HFVIS_NO_STDIO
hfvis_status hfvis_partial_save(const char *path, const hfvis_partial *p)
{
    size_t need = hfvis_partial_encode_size(p), written = 0;
    unsigned char *buf;
    hfvis_status s;
    if (!path || need == 0) return HFVIS_ERR_INVALID_ARGUMENT;
    buf = (unsigned char *)hfvis__alloc(NULL, need);
    if (!buf) return HFVIS_ERR_OUT_OF_MEMORY;
    s = hfvis_partial_encode(p, buf, need, &written);
    if (s == HFVIS_OK) s = hfvis_write_file(path, buf, written, NULL);
    hfvis__free(NULL, buf);
    return s;
}

hfvis_status hfvis_partial_load(const char *path, const hfvis_allocator *alloc, hfvis_partial *p)
{
    unsigned char *data;
    size_t size;
    hfvis_status s;
    if (!path || !p) return HFVIS_ERR_INVALID_ARGUMENT;
    s = hfvis__read_file(path, alloc, hf_partial_sizer, &data, &size);
    if (s != HFVIS_OK) return s;
    s = hfvis_partial_decode(data, size, alloc, p);
    hfvis__free(alloc, data);
    return s;
}
#endif /* HFVIS_NO_STDIO */

/* ========================================================================================== */
/* 16. Exact rays (beyond [P1])                                                               */
/* ========================================================================================== */
/* The lattice of [P1] §4 gives each receiver the horizon of the lattice lines beside it, blended
 * by the gather; where the horizon itself jumps (walls, roofs, cliffs) the blend is wrong by tens
 * of degrees. Exact rays give every grid point its own ray instead. A look direction with integer
 * components (a, b), gcd 1, is shared by the receivers it joins: the line through grid point g
 * also passes through g + (a, b). Between two such grid points the line crosses |a| - 1 columns
 * and |b| - 1 rows; at each crossing the bilinear surface is a linear interpolation along one grid
 * line, an exact point of the surface. Every line is swept from its far end with the hull stack
 * of [P1] §5 (Alg. 1) over all its crossings, and each grid point on it reads the tangent of the
 * hull at its turn: the maximum over every crossing of its own ray, no interpolation between
 * lines. Distances are integers in units of 1/(|a||b|) of the step |(a, b)|. Each receiver also
 * takes the near-field limit t -> 0+ of its first cell (and under a radius the window's end),
 * where the supremum is often no sample at all; the per-receiver oracle
 * (hfvis_horizon_exact_naive) is the supremum over t > 0, every piece maximized in closed form.
 * Directions are the nearest representable ones (hfvis.h, "Exact rays"); the light integrals weight
 * each by its share of the circle. */

#define HF_EXACT_MIN_DENOMINATOR 5  /* the default bound never goes below this (K = 16: 0.7 deg) */
#define HF_EXACT_SUN_DENOMINATOR 64 /* default for one direction (the sun): deviation <= 0.45 deg */
#define HF_EXACT_QUANTUM 1099511627776.0 /* 2^40: sector edges are multiples of 2^-40 turn, so the
                                            weights are exact and add up to exactly 1 */

static int hf_gcd(int a, int b)
{
    while (b != 0) {
        int t = a % b;
        a = b;
        b = t;
    }
    return a;
}

static int hf_floor_div(int num, int den) /* den > 0 */
{
    int q = num / den;
    return (num % den != 0 && num < 0) ? q - 1 : q;
}

/* The default rule for K > 32 (hfvis.h, "Exact rays"): the cheapest direction (smallest
 * |a| + |b|: a line's sweep costs |a| + |b| - 1 crossings per receiver) within tau_K of psi_k,
 * a quarter of the sector 2 pi/K but at most HF_EXACT_TAU = 0.25 deg (the two agree at K = 360),
 * searched up to the denominator hf_exact_cheap_bound(K), which always holds one: for any slope
 * some p/q with q <= Q lies within 1/Q of it (Dirichlet), and 1/Q < tau_K (K <= 360: Q = 256,
 * 1/256 rad < 0.25 deg; K > 360: Q > 2K/pi). The nearest direction with N = ceil(K/4) costs
 * |a| + |b| ~ 0.8 N on average (K = 256: 51.5, K = 360: 73, K = 1024: 222); the cheapest
 * within a quarter sector 12-21 up to K = 360, 33 at K = 1024, 76 at K = 4096 (docs/exact-rays.md,
 * "Directions"). A quarter sector keeps the chosen azimuths in order. */
#define HF_EXACT_TAU (0.25 * HFVIS__PI / 180.0)
#define HF_EXACT_CHEAP_N 256
#define HF_EXACT_CHEAP_KMAX 360

/* The cheap rule of K directions: its search bound Q and tolerance tau (above). */
static int hf_exact_cheap_bound(int K)
{
    double q = ceil(2.0 * (double)K / HFVIS__PI) + 1.0;
    if (K <= HF_EXACT_CHEAP_KMAX) return HF_EXACT_CHEAP_N;
    return q < (double)HFVIS_RAY_DENOMINATOR_MAX ? (int)q : HFVIS_RAY_DENOMINATOR_MAX;
}
static double hf_exact_cheap_tau(int K)
{
    return K <= HF_EXACT_CHEAP_KMAX ? HF_EXACT_TAU : 0.5 * HFVIS__PI / (double)K;
}

/* The largest |a|, |b| of rule N (hf_exact_bound). */
static int hf_exact_rule_max(int N)
{
    return N > 0 ? N : hf_exact_cheap_bound(-N);
}

/* The resolved direction rule of a run of K directions (hfvis.h): N > 0, the nearest direction
 * with max(|a|, |b|) <= N; N = -K, the cheapest within a quarter sector (above). K beyond
 * 4 HFVIS_RAY_DENOMINATOR_MAX keeps ceil(K/4), which the callers refuse. */
static int hf_exact_bound(const hfvis_sweep_options *o, int K)
{
    if (o->ray_denominator > 0) return o->ray_denominator;
    if (K == 1) return HF_EXACT_SUN_DENOMINATOR;
    if (K > 32 && K <= 4 * HFVIS_RAY_DENOMINATOR_MAX) return -K;
    return (K + 3) / 4 > HF_EXACT_MIN_DENOMINATOR ? (K + 3) / 4 : HF_EXACT_MIN_DENOMINATOR;
}

/* The direction of rule N (hf_exact_bound) for azimuth psi. N > 0: the nearest (a, b), gcd 1,
 * max(|a|, |b|) <= N; ties go to the smaller |a| + |b| (the cheaper sweep). N = -K: the smallest
 * |a| + |b| with max(|a|, |b|) <= hf_exact_cheap_bound(K) within hf_exact_cheap_tau(K) of psi;
 * ties go to the nearer. Searched in the first octant: for each a, the two b beside a tan(theta). */
static hf_ray hf_ray_nearest(double psi, int N)
{
    hf_ray r;
    double t = psi - 2.0 * HFVIS__PI * floor(psi / (2.0 * HFVIS__PI)), rr, th, tn, best;
    int q, mirror, a, c, ba = 1, bb = 0, x, y, turn;
    q = (int)floor(t / HFVIS__HALF_PI);
    if (q > 3) q = 3;
    if (q < 0) q = 0;
    rr = t - (double)q * HFVIS__HALF_PI;
    if (rr < 0.0) rr = 0.0;
    mirror = rr > 0.25 * HFVIS__PI;
    th = mirror ? HFVIS__HALF_PI - rr : rr;
    tn = tan(th);
    best = th; /* (1, 0) */
    if (N < 0) { /* the cheapest within tau; a + b only grows with a */
        const int Q = hf_exact_cheap_bound(-N);
        const double tau = hf_exact_cheap_tau(-N);
        int cost = INT_MAX;
        for (a = 1; a <= Q && a < cost; a++) {
            double bf = floor((double)a * tn);
            for (c = 0; c < 2; c++) {
                int b = (int)bf + c;
                double dev;
                if (b < 0 || b > a || hf_gcd(a, b) != 1) continue;
                dev = fabs(atan2((double)b, (double)a) - th);
                if (dev <= tau && (a + b < cost || (a + b == cost && dev < best))) {
                    cost = a + b;
                    best = dev;
                    ba = a;
                    bb = b;
                }
            }
        }
        N = cost == INT_MAX ? Q : 0; /* none (only where Q is capped at 4096): the nearest */
    }
    for (a = 1; a <= N; a++) {
        double bf = floor((double)a * tn);
        for (c = 0; c < 2; c++) {
            int b = (int)bf + c;
            double dev;
            if (b < 0 || b > a || hf_gcd(a, b) != 1) continue;
            dev = fabs(atan2((double)b, (double)a) - th);
            if (dev < best || (dev == best && a + b < ba + bb)) {
                best = dev;
                ba = a;
                bb = b;
            }
        }
    }
    x = mirror ? bb : ba;
    y = mirror ? ba : bb;
    for (turn = 0; turn < q; turn++) { /* (x, y) turned by +pi/2 */
        int nx = -y;
        y = x;
        x = nx;
    }
    r.a = x;
    r.b = y;
    r.azimuth = psi + remainder(atan2((double)y, (double)x) - psi, 2.0 * HFVIS__PI);
    return r;
}

/* The K directions of a run and their quadrature (hfvis.h, "Exact rays"): sector k runs between
 * the midpoints to its neighbours, its edges rounded to multiples of 2^-40 turn relative to
 * azimuth0; w[k] is its share of the circle, (lc[k], ls[k]) = (1/2pi) Int (cos phi, sin phi) dphi
 * over it ([P1] Eq. 5's lobe term for an uncentred sector), lo/hi its edges (radians). */
typedef struct hf_exact_dirs {
    int K;
    hf_ray *ray;
    double *w, *lc, *ls, *lo, *hi;
} hf_exact_dirs;

static void hf_exact_dirs_fill(hf_exact_dirs *d, int K, double azimuth0, int N)
{
    int k;
    double prev, *Q = d->lo; /* edges in quanta relative to azimuth0, first */
    for (k = 0; k < K; k++)
        d->ray[k] = hf_ray_nearest(azimuth0 + 2.0 * HFVIS__PI * (double)k / (double)K, N);
    d->K = K;
    prev = d->ray[K - 1].azimuth - 2.0 * HFVIS__PI - azimuth0;
    for (k = 0; k < K; k++) {
        double cur = d->ray[k].azimuth - azimuth0;
        Q[k] = floor(0.5 * (prev + cur) / (2.0 * HFVIS__PI) * HF_EXACT_QUANTUM + 0.5);
        if (k > 0 && Q[k] < Q[k - 1]) Q[k] = Q[k - 1]; /* rounding never makes a sector negative */
        prev = cur;
    }
    for (k = 0; k < K; k++) {
        double qhi = k + 1 < K ? Q[k + 1] : Q[0] + HF_EXACT_QUANTUM;
        d->hi[k] = qhi;
        d->w[k] = qhi > Q[k] ? (qhi - Q[k]) / HF_EXACT_QUANTUM : 0.0;
    }
    for (k = 0; k < K; k++) {
        double lo = azimuth0 + Q[k] * (2.0 * HFVIS__PI / HF_EXACT_QUANTUM);
        double hi = azimuth0 + d->hi[k] * (2.0 * HFVIS__PI / HF_EXACT_QUANTUM);
        double mid = 0.5 * (lo + hi), sh = sin(HFVIS__PI * d->w[k]) / HFVIS__PI;
        d->lo[k] = lo;
        d->hi[k] = hi;
        d->lc[k] = cos(mid) * sh; /* (sin hi - sin lo)/2pi in difference form */
        d->ls[k] = sin(mid) * sh; /* (cos lo - cos hi)/2pi */
    }
}

/* One crossing of a period: offset e of the P crossings between grid point g (e = 0) and
 * g + (a, b), in sweep order of increasing u. kind 0: the grid point; 1: a column crossing, the
 * surface between taps (X, Y) and (X, Y+1) at fraction f; 2: a row crossing, between (X, Y) and
 * (X+1, Y). u: its distance from g in sub-steps of 1/L of the step (an integer). */
typedef struct hf_cross {
    int ox, oy, kind;
    double f, u;
    ptrdiff_t zoff, zstep; /* its first tap from g in the grid's heights, and its second from that */
    ptrdiff_t coff;        /* the tap (0, 0) of its piece's cell from g in the grid's heights */
    ptrdiff_t toff;        /* that cell from g in the twist plane (hf_exact.twist, row stride width) */
    double mfx, mfy, mu;   /* the piece's midpoint: cell coordinates, distance from g (sub-steps) */
    /* the piece from this crossing to the next (or to g + (a, b)): inside cell (cx, cy) (offsets
       from g), from (fx0, fy0) to (fx1, fy1) in cell coordinates, du sub-steps long */
    int cx, cy;
    double fx0, fy0, fx1, fy1, du, q; /* q = -(fx1 - fx0)(fy1 - fy0)/4: bulge = q * twist */
} hf_cross;

/* Subdivision of concave pieces (beyond the crossing set): along a ray the bilinear surface is a
 * quadratic inside each cell; where it bulges above its chord (a saddle: box corners, the corners
 * of stair-stepped cliffs) the tangent from a receiver can touch between two crossings. Such a
 * piece gets m - 1 interior samples, m the power of two (<= HF_EXACT_MAX_SPLIT) that brings the
 * bulge r/4 below HF_EXACT_BULGE cells of height; powers of two keep every distance exact.
 * 1/16 since the near-field term (before: 1/64, which the lidar target needed while the errors
 * next to the receiver were still there): 19-21 % less time on rough fBm (K = 16 and 64), horizons
 * within 0.008 deg mean / 0.20 deg p99 of the supremum on fBm 512^2, every pair; lidar SVF p99
 * 0.0006 (docs/exact-rays.md). */
#define HF_EXACT_BULGE (1.0 / 16.0)
#define HF_EXACT_MAX_SPLIT 16

typedef struct hf_exact {
    const hfvis_grid *g;
    hfvis_border border;
    int R;                  /* reach beyond the grid in cells (CLAMP/WRAP: border_cells) */
    int N;                  /* denominator bound */
    hf_exact_dirs d;
    hf_cross *cross;        /* the current direction's crossings, up to 2N - 1 */
    double *sd, *sh;        /* one line's samples, then its hull stack: distances (sub-steps),
                               heights (world units) */
    double *tan;            /* width*height tangents of the current direction, NaN at holes */
    const float *nrm;       /* width*height*3 grid normals (lighting): the scratch's or the
                               caller's (sweep options normals), else NULL */
    float *nrm_own;         /* the scratch's normals, NULL when given */
    double *acc;            /* width*height*channels sums, else NULL */
    int channels;
    double radius;          /* a finite search radius (world units), else 0 */
    int64_t win_rw;         /* the current direction's window, 1/16 sub-steps; -1 = unlimited */
    hf_win win;             /* one line's samples under the radius */
    int *rec;               /* one line's receivers: their sample indices, then INT_MAX */
    int eager;              /* the next line's pieces eager (HF_EXACT_EAGER_SHARE) */
    int ox, oy;             /* the tile's origin in the raster (hfvis.h, "Search radius and tiles") */
    int rx0, ry0, rx1, ry1; /* the receiver rectangle, [rx0, rx1) x [ry0, ry1) */
    int rect;               /* 1: a proper sub-rectangle */
    int parts, part;        /* bands across the direction (part_index/part_count), 0 = off */
    int64_t c0, cspan;      /* the receivers' line index c = x*b - y*a: its least value, count */
    int64_t clo, chi;       /* this band's lines: clo <= c <= chi */
    int near;               /* ray_near_cells: D > 0, the near and far field (hf_far_field) */
    int ray_a, ray_b;       /* the direction being swept */
    int inf;                /* the grid holds an infinite height (hf_near_field) */
    int *fpar;              /* a far line's hull tree (hf_far_hull): parents, running maxima */
    double *fmax;
    struct hf_near_off *noff; /* the near stencil (hf_near_offsets) */
    struct hf_far_line *flines; /* one far band's exact lines */
    const double *twist;    /* width*height: each cell's twist (hf_cell_twist) at its (x, y), for
                               the sweep's and the near field's bulge tests (the caller's
                               hfvis_sweep_options.exact_grid, or made in the scratch); NULL
                               on grids above HFVIS_EXACT_TWIST_PLANE_CELLS without the near
                               field: the sweep then takes each twist from the heights */
    int finite;             /* every height of the grid is finite (hf_exact_inner) */
    double *stk;            /* hf_exact_fused's hull stack: (height, distance) pairs, two NaN pairs
                               first */
    double *row;            /* one row of near tangents */
    void *block;
    const hfvis_allocator *alloc;
} hf_exact;

/* Bands across an exact direction (a, b) (hfvis_sweep_options part_index/part_count): the
 * receivers of a line share c = x*b - y*a, an integer, so the bands are ranges of c over the
 * receiver rectangle and a line is swept by exactly one call. */
static void hf_exact_parts(hf_exact *E, const hfvis_sweep_options *o, hf_ray r)
{
    int64_t lo = INT64_MAX, hi = INT64_MIN;
    int c;
    E->parts = o->part_count > 1 ? o->part_count : 0;
    E->part = o->part_index;
    for (c = 0; c < 4; c++) {
        int64_t x = c & 1 ? E->rx1 - 1 : E->rx0, y = c & 2 ? E->ry1 - 1 : E->ry0;
        int64_t v = x * (int64_t)r.b - y * (int64_t)r.a;
        lo = v < lo ? v : lo;
        hi = v > hi ? v : hi;
    }
    E->c0 = lo;
    E->cspan = hi - lo + 1;
    /* band p holds the c with floor((c - c0) parts / cspan) == p, i.e. the c - c0 from
       ceil(p cspan / parts) to ceil((p + 1) cspan / parts) - 1 */
    E->clo = lo + ((int64_t)E->part * E->cspan + E->parts - 1) / (E->parts ? E->parts : 1);
    E->chi = lo + ((int64_t)(E->part + 1) * E->cspan + E->parts - 1) / (E->parts ? E->parts : 1) - 1;
}

/* 1 if the line through receiver (x, y) along (a, b) is one of this call's. */
static int hf_exact_mine(const hf_exact *E, int x, int y, hf_ray r)
{
    int64_t v = (int64_t)x * (int64_t)r.b - (int64_t)y * (int64_t)r.a;
    return !E->parts || (v >= E->clo && v <= E->chi);
}

/* This call's receivers in row y of the receiver rectangle: [*x0, *x1), the x whose line
 * (hf_exact_mine) is its own; c = x*b - y*a is monotone in x, so they are one run. */
static void hf_exact_span(const hf_exact *E, int y, hf_ray r, int *x0, int *x1)
{
    int64_t lo = E->rx0, hi = (int64_t)E->rx1 - 1, ya = (int64_t)y * (int64_t)r.a, b = r.b;
    if (E->parts && b == 0) { /* c = -y*a along the whole row */
        if (-ya < E->clo || -ya > E->chi) hi = lo - 1;
    } else if (E->parts) { /* clo <= x b - y a <= chi */
        int64_t p = E->clo + ya, q = E->chi + ya, t;
        if (b < 0) { /* x|b| between -q and -p */
            t = p;
            p = -q;
            q = -t;
            b = -b;
        }
        t = -hf_floor_div64(-p, b); /* ceil(p / b) */
        if (t > lo) lo = t;
        t = hf_floor_div64(q, b);
        if (t < hi) hi = t;
    }
    if (hi < lo) hi = lo - 1;
    *x0 = (int)lo;
    *x1 = (int)(hi + 1);
}

/* The piece after each crossing e (to crossing e + 1, the last one to the next grid point at
 * u = L): its cell, found from its midpoint, and its ends in that cell's coordinates. */
static void hf_exact_pieces(hf_cross *cross, int n, int a, int b, double L)
{
    int e;
    for (e = 0; e < n; e++) {
        double u0 = cross[e].u, u1 = e + 1 < n ? cross[e + 1].u : L, um = 0.5 * (u0 + u1);
        double mx = um * (double)a / L, my = um * (double)b / L;
        hf_cross *c = cross + e;
        c->cx = (int)floor(mx);
        c->cy = (int)floor(my);
        c->fx0 = u0 * (double)a / L - (double)c->cx;
        c->fy0 = u0 * (double)b / L - (double)c->cy;
        c->fx1 = u1 * (double)a / L - (double)c->cx;
        c->fy1 = u1 * (double)b / L - (double)c->cy;
        c->du = u1 - u0;
        c->q = -0.25 * (c->fx1 - c->fx0) * (c->fy1 - c->fy0);
    }
}

/* Crossings of direction (a, b) into cross[]; returns P = |a| + |b| - 1 (1 for the axes),
 * *L the sub-steps per step and *scale the factor from height per sub-step to tangent. */
static int hf_exact_geometry(hf_cross *cross, const hfvis_grid *g, int a, int b, double *L,
                             double *scale)
{
    int A = a < 0 ? -a : a, B = b < 0 ? -b : b, ja = 0, jb = 1, n = 0;
    double len = sqrt((double)a * (double)a + (double)b * (double)b);
    if (A == 0 || B == 0) {
        memset(cross, 0, sizeof *cross); /* along a grid line the surface is linear: no pieces */
        *L = 1.0;
        *scale = 1.0 / (len * g->cell_size);
        return 1;
    }
    while (ja < A || jb < B) {
        hf_cross *c = cross + n++;
        if (jb >= B || (ja < A && ja * B < jb * A)) {
            int num = ja * b;
            c->kind = ja == 0 ? 0 : 1;
            c->ox = a < 0 ? -ja : ja;
            c->oy = hf_floor_div(num, A);
            c->f = (double)(num - c->oy * A) / (double)A;
            c->u = (double)(ja * B);
            ja++;
        } else {
            int num = jb * a;
            c->kind = 2;
            c->oy = b < 0 ? -jb : jb;
            c->ox = hf_floor_div(num, B);
            c->f = (double)(num - c->ox * B) / (double)B;
            c->u = (double)(jb * A);
            jb++;
        }
    }
    *L = (double)A * (double)B;
    *scale = *L / (len * g->cell_size);
    hf_exact_pieces(cross, n, a, b, *L);
    for (ja = 0; ja < n; ja++) {
        hf_cross *c = cross + ja;
        c->zoff = (ptrdiff_t)c->oy * g->stride + c->ox;
        c->zstep = c->kind == 1 ? g->stride : 1;
        c->coff = (ptrdiff_t)c->cy * g->stride + c->cx;
        c->toff = (ptrdiff_t)c->cy * g->width + c->cx;
        c->mfx = c->fx0 + 0.5 * (c->fx1 - c->fx0); /* hf_piece_fill's sample at t = 1/2, bit for bit */
        c->mfy = c->fy0 + 0.5 * (c->fy1 - c->fy0);
        c->mu = c->u + c->du * 0.5;
    }
    return n;
}

/* Is crossing c at base tap (X, Y) inside the grid grown by R cells? */
static int hf_cross_inside(const hfvis_grid *g, int R, int X, int Y, const hf_cross *c)
{
    return X >= -R && Y >= -R && X + (c->kind == 2) <= g->width - 1 + R &&
           Y + (c->kind == 1) <= g->height - 1 + R;
}

/* The surface height (world units) at crossing c with base tap (X, Y): the linear interpolation
 * along its grid line inside the grid, the border rule outside; NaN at holes. */
static double hf_cross_height(const hfvis_grid *g, hfvis_border border, int X, int Y,
                              const hf_cross *c)
{
    double h;
    if (X >= 0 && Y >= 0 && X + (c->kind == 2) < g->width && Y + (c->kind == 1) < g->height) {
        const float *p = g->z + (ptrdiff_t)Y * g->stride + X;
        h = (double)p[0];
        if (c->kind != 0) h += ((double)p[c->kind == 1 ? g->stride : 1] - h) * c->f; /* exact on flats */
        return isfinite(h) ? h : HFVIS__NAN;
    }
    return hf_sample_border(g, border, (double)X + (c->kind == 2 ? c->f : 0.0),
                            (double)Y + (c->kind == 1 ? c->f : 0.0));
}

/* The twist z00 - z10 - z01 + z11 of the cell at p. */
static inline double hf_cell_twist(const float *p, ptrdiff_t stride)
{
    return (double)p[0] - (double)p[1] - (double)p[stride] + (double)p[stride + 1];
}

/* Whether one of the n heights at zr is a hole or infinite: the IEEE-754 binary32 exponent
 * field all ones, tested four at a time (every call of a split run scans the grid; 0.1-0.2 ns a
 * height this way, against 0.7 with isfinite one by one). */
static int hf_row_nonfinite(const float *zr, int n)
{
    uint32_t m0 = 0, m1 = 0, m2 = 0, m3 = 0, b[4];
    int x = 0;
    for (; x + 4 <= n; x += 4) { /* exponent all ones + 1 carries into bit 31 */
        memcpy(b, zr + x, sizeof b);
        m0 |= (b[0] & 0x7f800000u) + 0x00800000u;
        m1 |= (b[1] & 0x7f800000u) + 0x00800000u;
        m2 |= (b[2] & 0x7f800000u) + 0x00800000u;
        m3 |= (b[3] & 0x7f800000u) + 0x00800000u;
    }
    for (; x < n; x++) {
        memcpy(b, zr + x, sizeof b[0]);
        m0 |= (b[0] & 0x7f800000u) + 0x00800000u;
    }
    return ((m0 | m1 | m2 | m3) & 0x80000000u) != 0;
}

/* Cell (x, y)'s twist in row y of the twist plane: hf_cell_twist, 0 in the last row and column. */
static void hf_twist_row(const hfvis_grid *g, int y, double *tw)
{
    const float *zr = g->z + (ptrdiff_t)y * g->stride;
    int x;
    for (x = 0; x < g->width; x++)
        tw[x] = x + 1 < g->width && y + 1 < g->height ? hf_cell_twist(zr + x, g->stride) : 0.0;
}

/* The class of the heights of rows [y0, y1): 0 all finite, 1 holes and no infinite height, 2 an
 * infinite height (exact rays: hf_exact.finite, hf_exact.inf). A grid's class is the largest of
 * its row ranges' classes. */
static int hf_height_class(const hfvis_grid *g, int y0, int y1)
{
    int y, x, nonfinite = 0;
    for (y = y0; y < y1; y++) nonfinite |= hf_row_nonfinite(g->z + (ptrdiff_t)y * g->stride, g->width);
    if (!nonfinite) return 0;
    for (y = y0; y < y1; y++)
        for (x = 0; x < g->width; x++)
            if (isinf(g->z[(ptrdiff_t)y * g->stride + x])) return 2;
    return 1;
}

hfvis_status hfvis_exact_grid_rows(const hfvis_grid *grid, int row_begin, int row_end, double *out, int *height_class)
{
    int y;
    if (!hf_grid_valid(grid) || !height_class || row_begin < 0 || row_begin >= row_end ||
        row_end > grid->height)
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (y = row_begin; out && y < row_end; y++) hf_twist_row(grid, y, out + (size_t)y * (size_t)grid->width);
    *height_class = hf_height_class(grid, row_begin, row_end);
    return HFVIS_OK;
}

hfvis_status hfvis_exact_grid_compute(const hfvis_grid *grid, double *out)
{
    int cls;
    hfvis_status s;
    if (!hf_grid_valid(grid) || !out) return HFVIS_ERR_INVALID_ARGUMENT;
    s = hfvis_exact_grid_rows(grid, 0, grid->height, out, &cls);
    if (s == HFVIS_OK) out[hf_grid_count(grid)] = (double)cls;
    return s;
}

/* The four taps of cell (cx, cy) under the border rule into z (z00, z10, z01, z11: a 2 x 2 cell
 * of row stride 2): inside the grid, or for CLAMP/WRAP within the reach R beyond it (clamped or
 * wrapped taps, the cells of hf_sample_border's surface); 0 outside that or when a tap is a hole. */
static int hf_exact_cell_taps(const hfvis_grid *g, hfvis_border border, int R, int cx, int cy, float *z)
{
    int j;
    if (cx >= 0 && cy >= 0 && cx + 1 < g->width && cy + 1 < g->height) {
        const float *p = g->z + (ptrdiff_t)cy * g->stride + cx;
        z[0] = p[0];
        z[1] = p[1];
        z[2] = p[g->stride];
        z[3] = p[g->stride + 1];
    } else {
        if (border == HFVIS_BORDER_OPEN || cx < -R || cy < -R || cx + 1 > g->width - 1 + R ||
            cy + 1 > g->height - 1 + R)
            return 0;
        for (j = 0; j < 4; j++) {
            int X = cx + (j & 1), Y = cy + (j >> 1);
            if (border == HFVIS_BORDER_WRAP) {
                X = (X % g->width + g->width) % g->width;
                Y = (Y % g->height + g->height) % g->height;
            } else {
                X = X < 0 ? 0 : (X > g->width - 1 ? g->width - 1 : X);
                Y = Y < 0 ? 0 : (Y > g->height - 1 ? g->height - 1 : Y);
            }
            z[j] = g->z[(ptrdiff_t)Y * g->stride + X];
        }
    }
    return isfinite(z[0]) && isfinite(z[1]) && isfinite(z[2]) && isfinite(z[3]);
}

/* The interior samples of a piece in the cell whose tap (0, 0) is p (row stride `stride`), its
 * bulge above lim (hf_piece_samples). */
static int hf_piece_fill(const float *p, ptrdiff_t stride, const hf_cross *c, double bulge, double lim,
                         double *h, double *du)
{
    double z00 = (double)p[0], z10 = (double)p[1], z01 = (double)p[stride], z11 = (double)p[stride + 1];
    double dfx = c->fx1 - c->fx0, dfy = c->fy1 - c->fy0, inv_m;
    int m = 1, j;
    while (m < HF_EXACT_MAX_SPLIT && bulge > lim * (double)m * (double)m) m *= 2;
    inv_m = 1.0 / (double)m; /* a power of two: j * inv_m == j / m exactly */
    for (j = 1; j < m; j++) {
        double t = (double)j * inv_m, fx = c->fx0 + t * dfx, fy = c->fy0 + t * dfy;
        double r0 = z00 + (z10 - z00) * fx, r1 = z01 + (z11 - z01) * fx;
        h[j - 1] = r0 + (r1 - r0) * fy;
        du[j - 1] = c->du * t;
    }
    return m - 1;
}

/* Interior samples of piece c after base grid point (X, Y) (see HF_EXACT_BULGE), its cell's taps
 * under the border rule (hf_exact_cell_taps): writes up to HF_EXACT_MAX_SPLIT - 1 heights h[j]
 * at sub-step offsets du[j] from the piece's start, in increasing order, and returns the count;
 * 0 for a piece that is not concave enough, out of reach or touching a hole. */
static int hf_piece_samples(const hfvis_grid *g, hfvis_border border, int R, int X, int Y,
                            const hf_cross *c, double *h, double *du)
{
    float z[4];
    double bulge, lim = HF_EXACT_BULGE * g->cell_size;
    if (c->du == 0.0 || !hf_exact_cell_taps(g, border, R, X + c->cx, Y + c->cy, z)) return 0;
    bulge = c->q * hf_cell_twist(z, 2);
    if (!(bulge > lim) || !isfinite(bulge)) return 0;
    return hf_piece_fill(z, 2, c, bulge, lim, h, du);
}

/* Whole periods k >= 0 of the ray from grid point (x, y) along (a, b) that can hold a crossing
 * inside the grid grown by R cells. */
static int hf_exact_periods(const hfvis_grid *g, int R, int x, int y, int a, int b)
{
    int k = INT_MAX;
    if (a > 0) k = (g->width - 1 + R - x) / a;
    else if (a < 0) k = (x + R) / -a;
    if (b > 0 && (g->height - 1 + R - y) / b < k) k = (g->height - 1 + R - y) / b;
    else if (b < 0 && (y + R) / -b < k) k = (y + R) / -b;
    return k;
}

/* The last grid point q (hx - q a, hy - q b) of a line in the receiver rectangle (the line
 * stops there); 0 if none is. */
static int hf_exact_rect_span(const hf_exact *E, int hx, int hy, int a, int b, int *qhi)
{
    int lo = 0, hi = INT_MAX, ax;
    for (ax = 0; ax < 2; ax++) {
        int c = ax ? b : a, h = ax ? hy : hx, r0 = ax ? E->ry0 : E->rx0, r1 = (ax ? E->ry1 : E->rx1) - 1;
        int l, u;
        if (c == 0) {
            if (h < r0 || h > r1) return 0;
            continue;
        }
        if (c > 0) { /* h - q c in [r0, r1] */
            l = -hf_floor_div(r1 - h, c);
            u = hf_floor_div(h - r0, c);
        } else {
            l = -hf_floor_div(h - r0, -c);
            u = hf_floor_div(r1 - h, -c);
        }
        if (l > lo) lo = l;
        if (u < hi) hi = u;
    }
    if (lo > hi) return 0;
    *qhi = hi;
    return 1;
}

/* Pieces that split, as a share of those tested, above which a line computes every piece's
 * midpoint and keeps it without a branch (hf_exact_piece, eager): on rough terrain a quarter of
 * the pieces split at random and the branch mispredicts (fBm 512^2: eager 8 ns/rd faster); on
 * flat roofs and ground almost none split and the branch is free (urban 512^2: 7 ns/rd slower
 * eager). Decided per line from the line before; the output is the same either way. */
#define HF_EXACT_EAGER_SHARE (1.0 / 16.0)

/* The interior samples of piece c of the inner part of a line (between two grid points inside
 * the grid, so its cell is inside too), zn at the nearer grid point's height, appended to
 * (sd, sh) from index n far end first at distances base - offset; returns the new count and
 * counts a split in *splits. hf_piece_samples' test and samples, bit for bit; the twist from the
 * plane of the cells' twists (hf_exact.twist; tn: the nearer grid point's cell there), so a piece
 * that does not bulge costs a load and a compare and its taps are read only for its samples.
 * eager: the midpoint of a piece split in two (most splits) is written for every piece and kept
 * by the test's outcome, without a branch. */
static HFVIS__ALWAYS_INLINE int hf_exact_piece_tw(const hfvis_grid *g, const hf_cross *c, const float *zn,
                                                  double twist, double base, double lim, double *sd,
                                                  double *sh, int n, int eager, int *splits)
{
    const double bulge = c->q * twist; /* q hf_cell_twist */
    if (eager || bulge > lim) { /* not eager: most pieces end at the one test (NaN at holes) */
        const float *p = zn + c->coff;
        double z00 = (double)p[0], z10 = (double)p[1], z01 = (double)p[g->stride], z11 = (double)p[g->stride + 1];
        int split = (bulge > lim) & (bulge < HFVIS__INF);
        *splits += split;
        if (bulge > 4.0 * lim && bulge < HFVIS__INF) { /* split into 4 or more (hf_piece_fill's m >= 4): rare */
            double ph[HF_EXACT_MAX_SPLIT], pu[HF_EXACT_MAX_SPLIT];
            int j = hf_piece_fill(p, g->stride, c, bulge, lim, ph, pu);
            while (j-- > 0) { /* far end first */
                sd[n] = base - (c->u + pu[j]);
                sh[n++] = ph[j];
            }
        } else { /* split in two (a kept one has four finite taps: a finite height), or eager */
            double r0 = z00 + (z10 - z00) * c->mfx, r1 = z01 + (z11 - z01) * c->mfx;
            sd[n] = base - c->mu;
            sh[n] = r0 + (r1 - r0) * c->mfy;
            n += split;
        }
    }
    return n;
}

/* hf_exact_piece_tw with the twist from the plane (tn: the nearer grid point's cell there). */
static HFVIS__ALWAYS_INLINE int hf_exact_piece(const hfvis_grid *g, const hf_cross *c, const float *zn,
                                               const double *tn, double base, double lim, double *sd,
                                               double *sh, int n, int eager, int *splits)
{
    return hf_exact_piece_tw(g, c, zn, tn[c->toff], base, lim, sd, sh, n, eager, splits);
}

/* The inner part of a line for hf_exact_samples: grid points q = 0..qn from z0 (heights) and
 * tn (twists, at point 1), each with the crossings and piece samples behind it, appended from
 * index n; returns the new count. finite (a constant at each call, so the compiler writes one
 * loop for each): every height of the grid is finite (hf_exact.finite), so every grid point and
 * crossing is a finite sample and no hole test is made (the same samples). */
static HFVIS__ALWAYS_INLINE int hf_exact_inner(const hf_exact *E, int finite, int plane, ptrdiff_t z0,
                                               ptrdiff_t zstep, const double *tn, ptrdiff_t tstep, int pieces,
                                               int P, double L, int qn, double *sd, double *sh, int *rec, int n,
                                               int eager, int *splits)
{
    const hfvis_grid *g = E->g;
    const hf_cross *cr = E->cross;
    const double lim = HF_EXACT_BULGE * g->cell_size;
    double bq = 0.0; /* q L, exact (integers below 2^53) */
    int q, e;
    for (q = 0;; q++) {
        const ptrdiff_t zq = z0 - (ptrdiff_t)q * zstep;
        const float *zn;
        double h = (double)g->z[zq], base;
        sd[n] = bq;
        sh[n] = finite || isfinite(h) ? h : HFVIS__NAN;
        rec[q] = n++;
        if (q == qn) break;
        /* between grid points q and q + 1, both inside the grid, so are the crossings and cells */
        zn = g->z + (zq - zstep);
        if (plane) tn -= tstep;
        base = bq + L;
        bq = base;
        if (!pieces) continue; /* an axis: grid point q + 1 is the next sample */
        for (e = P - 1; e > 0; e--) { /* the piece after crossing e, then crossing e */
            const hf_cross *c = cr + e;
            n = plane ? hf_exact_piece(g, c, zn, tn, base, lim, sd, sh, n, eager, splits)
                      : hf_exact_piece_tw(g, c, zn, hf_cell_twist(zn + c->coff, g->stride), base, lim, sd, sh, n,
                                          eager, splits);
            h = (double)zn[c->zoff];
            h += ((double)zn[c->zoff + c->zstep] - h) * c->f; /* as hf_cross_height */
            sd[n] = base - c->u;
            sh[n] = h;
            n += finite || isfinite(h) ? 1 : 0; /* a hole: overwritten by the next sample */
        }
        n = plane ? hf_exact_piece(g, cr, zn, tn, base, lim, sd, sh, n, eager, splits) /* crossing 0: point q + 1 */
                  : hf_exact_piece_tw(g, cr, zn, hf_cell_twist(zn + cr->coff, g->stride), base, lim, sd, sh, n,
                                      eager, splits);
    }
    return n;
}

/* The head of a line for hf_exact_samples: the samples beyond grid point q = 0 (hx, hy), in
 * sweep order into (sd, sh); returns their count. */
static int hf_exact_head(const hf_exact *E, int hx, int hy, int a, int b, int P, double L, double *sd,
                         double *sh)
{
    const hfvis_grid *g = E->g;
    const hf_cross *cr = E->cross;
    const double lim = HF_EXACT_BULGE * g->cell_size;
    double ph[HF_EXACT_MAX_SPLIT], pu[HF_EXACT_MAX_SPLIT];
    int n = 0, k, e, j;
    for (k = hf_exact_periods(g, E->R, hx, hy, a, b); k >= 0; k--) {
        int bx = hx + k * a, by = hy + k * b;
        for (e = P - 1; e >= 0; e--) {
            int X = bx + cr[e].ox, Y = by + cr[e].oy, CX = bx + cr[e].cx, CY = by + cr[e].cy;
            double h;
            j = 0;
            if (CX >= 0 && CY >= 0 && CX + 1 < g->width && CY + 1 < g->height) {
                /* a cell inside the grid: hf_piece_samples' bulge test on the taps in place */
                double bulge = cr[e].q * hf_cell_twist(g->z + (ptrdiff_t)CY * g->stride + CX, g->stride);
                if (bulge > lim) j = hf_piece_samples(g, E->border, E->R, bx, by, cr + e, ph, pu);
            } else if (E->border != HFVIS_BORDER_OPEN) { /* OPEN: no cell outside the grid */
                j = hf_piece_samples(g, E->border, E->R, bx, by, cr + e, ph, pu);
            }
            while (j-- > 0) { /* the piece after crossing e, far end first */
                if (isnan(ph[j])) continue;
                sd[n] = -((double)k * L + (cr[e].u + pu[j]));
                sh[n++] = ph[j];
            }
            if ((k == 0 && e == 0) || !hf_cross_inside(g, E->R, X, Y, cr + e)) continue;
            h = hf_cross_height(g, E->border, X, Y, cr + e);
            if (isnan(h)) continue;
            sd[n] = -((double)k * L + cr[e].u);
            sh[n++] = h;
        }
    }
    return n;
}

/* The samples of one line of direction (a, b) from its head (hx, hy), the grid point whose
 * successor (hx + a, hy + b) lies outside the grid, to its grid point qn, in sweep order of
 * increasing distance (sub-steps from the head) into (sd, sh): the crossings beyond the head (the
 * CLAMP/WRAP pre-roll, or the part of a step still inside the grid), then each grid point q (a
 * receiver, rec[q] its sample; a hole keeps height NaN) and the crossings and piece samples
 * behind it. Crossings at holes are left out. Returns the count (the arrays hold one more).
 * *eager_io: this line's pieces eager (hf_exact_piece); set for the next from this one's splits. */
static int hf_exact_samples(const hf_exact *E, int hx, int hy, int a, int b, int P, double L, int qn,
                            double *sd, double *sh, int *rec, int *eager_io)
{
    const hfvis_grid *g = E->g;
    const ptrdiff_t z0 = (ptrdiff_t)hy * g->stride + hx, zstep = (ptrdiff_t)b * g->stride + a;
    const ptrdiff_t tstep = (ptrdiff_t)b * g->width + a;
    const double *tn = E->twist ? E->twist + ((ptrdiff_t)hy * g->width + hx) : NULL; /* twists at point q + 1 */
    const int pieces = a != 0 && b != 0; /* along a grid line the surface is linear */
    int n = hf_exact_head(E, hx, hy, a, b, P, L, sd, sh), splits = 0, eager = *eager_io;
    if (tn) /* the twists from the plane, or from the heights (HFVIS_EXACT_TWIST_PLANE_CELLS) */
        n = E->finite ? hf_exact_inner(E, 1, 1, z0, zstep, tn, tstep, pieces, P, L, qn, sd, sh, rec, n, eager, &splits)
                      : hf_exact_inner(E, 0, 1, z0, zstep, tn, tstep, pieces, P, L, qn, sd, sh, rec, n, eager, &splits);
    else
        n = E->finite ? hf_exact_inner(E, 1, 0, z0, zstep, tn, tstep, pieces, P, L, qn, sd, sh, rec, n, eager, &splits)
                      : hf_exact_inner(E, 0, 0, z0, zstep, tn, tstep, pieces, P, L, qn, sd, sh, rec, n, eager, &splits);
    if (pieces && qn > 0) *eager_io = (double)splits > HF_EXACT_EAGER_SHARE * (double)qn * (double)P;
    return n;
}

/* The hull pass over the samples of hf_exact_samples, in place (the stack never outgrows the
 * samples read; two NaN slots below it, as hf_hull_step needs): the [P1] §5 hull stack (Alg. 1,
 * ties pop, as hfvis_line_horizons) steps over every sample, and receiver r (sample rec[r])
 * writes tan[t0 - r tstep] = the tangent of the hull at its turn times scale (-INFINITY: nothing
 * before it, NaN: a hole). The top is always the sample pushed last, so its differences come
 * from registers (hf_hull_push) rather than from the stack just stored. */
static void hf_exact_hull(double *sd, double *sh, const int *rec, int nrec, double scale, double *tan,
                          ptrdiff_t t0, ptrdiff_t tstep)
{
    ptrdiff_t top = 0;
    double dt = 0.0, ht = HFVIS__NAN; /* the stack's top, sample last pushed (none: NaN) */
    int i = 0, r;
    for (r = 0; r < nrec; r++) {
        double d, h, t;
        for (; i < rec[r]; i++) {
            d = sd[i];
            h = sh[i];
            (void)hf_hull_push(sh, sd, &top, h, d, ht - h, d - dt);
            dt = d;
            ht = h;
        }
        d = sd[i];
        h = sh[i++];
        if (isnan(h)) {
            tan[t0 - (ptrdiff_t)r * tstep] = HFVIS__NAN;
            continue;
        }
        t = hf_hull_push(sh, sd, &top, h, d, ht - h, d - dt);
        tan[t0 - (ptrdiff_t)r * tstep] = (isnan(ht) ? -HFVIS__INF : t) * scale; /* scale > 0 */
        dt = d;
        ht = h;
    }
}

/* hf_hull_push on a stack of (height, distance) pairs (hf_exact.stk): the same tests, the same
 * arithmetic in the same order, so the same pops and tangents; one pointer p to the next free
 * pair, two NaN pairs below the first. */
static inline double hf_exact_push(double **top_io, double h, double d, double a1, double b1)
{
    double *p = *top_io, t, a2, b2;
    for (;;) {
        a2 = p[-4] - h;
        b2 = d - p[-3];
        if (!(a2 * b1 >= a1 * b2)) {
            t = a1 / b1;
            break;
        }
        p -= 2;
        a1 = p[-4] - h;
        b1 = d - p[-3];
        if (!(a1 * b2 >= a2 * b1)) {
            t = a2 / b2;
            break;
        }
        p -= 2;
    }
    p[0] = h;
    p[1] = d;
    *top_io = p + 2;
    return t;
}

/* hf_exact_samples and hf_exact_hull in one pass, for a line on a grid without holes or infinite
 * heights (hf_exact.finite): the head's samples go through the hull as there, then each sample
 * of the inner part is pushed as it is made (its crossing's height, a split piece's samples
 * through hf_exact_piece into a few slots of their own), so the samples are not stored and read
 * back and each grid point's tangent is taken where it is made, without a loop over the samples
 * before it. The same samples in the same order through the same hull steps: the same tangents,
 * bit for bit. A piece is split under a branch here (no eager midpoints, HF_EXACT_EAGER_SHARE):
 * the two-pass form moves that branch's randomness into the hull's loop over a receiver's
 * samples, whose exit then depends on the splits as much. */
static HFVIS__ALWAYS_INLINE void hf_exact_fused(hf_exact *E, int plane, int hx, int hy, int a, int b, int P,
                                                double L, int qn, double scale, ptrdiff_t t0)
{
    const hfvis_grid *g = E->g;
    const hf_cross *cr = E->cross;
    const ptrdiff_t zstep = (ptrdiff_t)b * g->stride + a, wstep = (ptrdiff_t)b * g->width + a;
    const double lim = HF_EXACT_BULGE * g->cell_size;
    const int pieces = a != 0 && b != 0; /* along a grid line the surface is linear */
    const float *zq = g->z + ((ptrdiff_t)hy * g->stride + hx);
    const double *tn = plane ? E->twist + ((ptrdiff_t)hy * g->width + hx) : NULL; /* twists at point q + 1 */
    double *sd = E->sd, *sh = E->sh, *tan = E->tan + t0, *top = E->stk + 4;
    /* the top before the first push: -inf at a finite distance below every sample's, so that the
       first push (its pop test fails on the NaN pair, as hf_exact_hull's on its NaN top) returns
       -inf / (d - dt) = -inf, the tangent of "nothing before", without a test at every receiver */
    double dt = -DBL_MAX, ht = -HFVIS__INF, bq = 0.0, pd[HF_EXACT_MAX_SPLIT], ph[HF_EXACT_MAX_SPLIT];
    int n = hf_exact_head(E, hx, hy, a, b, P, L, sd, sh), i, q, e, j, splits = 0;
    for (i = 0; i < n; i++) { /* the head: as hf_exact_hull before receiver 0 */
        const double d = sd[i], h = sh[i];
        (void)hf_exact_push(&top, h, d, ht - h, d - dt);
        dt = d;
        ht = h;
    }
    for (q = 0;; q++) {
        double h = (double)*zq, d = bq, t = hf_exact_push(&top, h, d, ht - h, d - dt), base;
        tan[-(ptrdiff_t)q * wstep] = t * scale; /* scale > 0 */
        dt = d;
        ht = h;
        if (q == qn) break;
        zq -= zstep; /* grid point q + 1 */
        if (plane) tn -= wstep;
        base = bq + L;
        bq = base;
        if (!pieces) continue; /* an axis: grid point q + 1 is the next sample */
        for (e = P - 1;; e--) { /* the piece after crossing e, then crossing e (0: point q + 1) */
            const hf_cross *c = cr + e;
            const double tw = plane ? tn[c->toff] : hf_cell_twist(zq + c->coff, g->stride);
            if (c->q * tw > lim) { /* split (rare): hf_exact_piece's samples, pushed */
                j = hf_exact_piece_tw(g, c, zq, tw, base, lim, pd, ph, 0, 0, &splits);
                for (i = 0; i < j; i++) {
                    (void)hf_exact_push(&top, ph[i], pd[i], ht - ph[i], pd[i] - dt);
                    dt = pd[i];
                    ht = ph[i];
                }
            }
            if (e == 0) break;
            h = (double)zq[c->zoff];
            h += ((double)zq[c->zoff + c->zstep] - h) * c->f; /* as hf_cross_height */
            d = base - c->u;
            (void)hf_exact_push(&top, h, d, ht - h, d - dt);
            dt = d;
            ht = h;
        }
    }
}

/* hf_exact_fused with the cells' twists read from the plane (hf_exact.twist), or computed from
 * the four heights of each piece's cell (the same doubles) on a grid too large for the plane to
 * pay (HFVIS_EXACT_TWIST_PLANE_CELLS). */
static void hf_exact_fused_plane(hf_exact *E, int hx, int hy, int a, int b, int P, double L, int qn, double scale,
                                 ptrdiff_t t0)
{
    hf_exact_fused(E, 1, hx, hy, a, b, P, L, qn, scale, t0);
}

static void hf_exact_fused_taps(hf_exact *E, int hx, int hy, int a, int b, int P, double L, int qn, double scale,
                                ptrdiff_t t0)
{
    hf_exact_fused(E, 0, hx, hy, a, b, P, L, qn, scale, t0);
}

/* One line of direction (a, b) from its head (hx, hy) (hf_exact_samples): the tangents of its
 * grid points up to the last one in the receiver rectangle, by the hull (in one pass with the
 * samples where hf_exact_fused applies) or, under a finite radius, by hf_window_line. */
static void hf_exact_line(hf_exact *E, int hx, int hy, int a, int b, int P, double L, double scale)
{
    const hfvis_grid *g = E->g;
    const ptrdiff_t t0 = (ptrdiff_t)hy * g->width + hx, tstep = (ptrdiff_t)b * g->width + a;
    int qn = hf_exact_periods(g, 0, hx, hy, -a, -b), qhi, n, q; /* the last grid point */
    if (E->rect) {
        if (!hf_exact_rect_span(E, hx, hy, a, b, &qhi)) return; /* no receiver wanted */
        if (qhi < qn) qn = qhi;
    }
    if (E->win_rw < 0 && E->finite) {
        if (E->twist)
            hf_exact_fused_plane(E, hx, hy, a, b, P, L, qn, scale, t0);
        else
            hf_exact_fused_taps(E, hx, hy, a, b, P, L, qn, scale, t0);
    } else if (E->win_rw < 0) {
        hf_exact_samples(E, hx, hy, a, b, P, L, qn, E->sd, E->sh, E->rec, &E->eager);
        hf_exact_hull(E->sd, E->sh, E->rec, qn + 1, scale, E->tan, t0, tstep);
    } else {
        /* positions: 16 x the sub-step along the raster's line, counted from its grid point
           q = 0 = -floor((X a + Y b)/(a^2 + b^2)) (X, Y in the raster): a tile and the whole
           raster put every sample at the same integer */
        hf_win *W = &E->win;
        int64_t n2 = (int64_t)a * a + (int64_t)b * b;
        int64_t dot = ((int64_t)hx + E->ox) * a + ((int64_t)hy + E->oy) * b;
        double base = -(double)hf_floor_div64(dot, n2) * L;
        int i;
        n = hf_exact_samples(E, hx, hy, a, b, P, L, qn, W->d, W->h, E->rec, &E->eager);
        for (i = 0; i < n; i++) W->pos[i] = (int64_t)(16.0 * (base + W->d[i]));
        E->rec[qn + 1] = INT_MAX; /* the list's end */
        hf_window_line(W, n, E->win_rw, 0, E->rec);
        for (q = 0; q <= qn; q++) E->tan[t0 - (ptrdiff_t)q * tstep] = W->t[E->rec[q]] * scale;
    }
}

/* The window of a finite radius R (world units) in 1/16 sub-steps: scale is the tangent factor
 * L/(|(a, b)| cell) of hf_exact_geometry, so R scale sub-steps span R; every sample distance is
 * a multiple of 1/16 sub-step (a crossing: whole sub-steps; a piece sample: j/m of a piece,
 * m <= HF_EXACT_MAX_SPLIT), so "16 distance <= floor(16 R scale)" is exact. */
static int64_t hf_exact_window(double radius, double scale)
{
    return hf_radius_units(16.0 * (radius * scale));
}

/* The near-field term of a receiver at grid point (x, y), height hr: the t -> 0+ limit of the
 * elevation tangent along (a, b), the slope of the bilinear cell the ray leaves by at its corner
 * (x, y), (dz/dx |a| + dz/dy |b|) / (|(a, b)| cell) with the corner's two edge differences
 * (the twist is second order). -INFINITY on the axes (the surface along a grid line is linear,
 * so the limit is the first grid point's own tangent) and where that cell is out of reach or
 * touches a hole. inv_den = hf_exact_inv_den. The sweep (its inner cells inline, the same
 * expression) and hfvis_horizon_exact_naive both compute it so: the same bits. */
static double hf_exact_first_slope(const hfvis_grid *g, hfvis_border border, int R, int x, int y,
                                   int a, int b, double hr, double inv_den)
{
    int cx = a < 0 ? x - 1 : x, cy = b < 0 ? y - 1 : y, A = a < 0 ? -a : a, B = b < 0 ? -b : b;
    float z[4];
    double zx, zy;
    if (A == 0 || B == 0 || !hf_exact_cell_taps(g, border, R, cx, cy, z)) return -HFVIS__INF;
    zx = (double)z[(cy == y ? 0 : 2) + (cx == x ? 1 : 0)]; /* the tap (x + sign a, y) */
    zy = (double)z[(cy == y ? 2 : 0) + (cx == x ? 0 : 1)]; /* the tap (x, y + sign b) */
    return ((zx - hr) * (double)A + (zy - hr) * (double)B) * inv_den;
}

/* 1 / (|(a, b)| cell), the first slope's factor (one expression for the sweep and the oracle). */
static double hf_exact_inv_den(const hfvis_grid *g, int a, int b)
{
    return 1.0 / (sqrt((double)a * (double)a + (double)b * (double)b) * g->cell_size);
}

/* The far end of a receiver's window: under a radius, the surface point at exactly ucut
 * sub-steps (hf_exact_window / 16) along its ray (a, b) from grid point (x, y), height hr, as a
 * tangent per sub-step (the supremum within R can lie there, between two samples). Its cell is the
 * one the ray is in just before the cut (along an axis, the cell beside the line, the next one
 * where that is out of reach); -INFINITY where no such cell is in reach with four finite taps. */
static double hf_exact_cut(const hfvis_grid *g, hfvis_border border, int R, int x, int y, int a, int b,
                           double L, double ucut, double hr)
{
    /* the cell and the fractions from the offset (dx, dy) alone, not from x + dx: a tile and the
       whole raster number the receiver differently, and x + dx would round differently */
    double dx = ucut * (double)a / L, dy = ucut * (double)b / L, ix, iy, fx, fy;
    float z[4];
    int cx, cy;
    if (!(ucut > 0.0) || fabs(dx) > (double)INT_MAX / 4.0 || fabs(dy) > (double)INT_MAX / 4.0) return -HFVIS__INF;
    ix = a > 0 ? ceil(dx) - 1.0 : floor(dx);
    iy = b > 0 ? ceil(dy) - 1.0 : floor(dy);
    if (fabs((double)x + ix) > (double)INT_MAX / 2.0 || fabs((double)y + iy) > (double)INT_MAX / 2.0) return -HFVIS__INF;
    cx = x + (int)ix;
    cy = y + (int)iy;
    fx = dx - ix; /* exact: dx less an integer within 1 of it */
    fy = dy - iy;
    if (!hf_exact_cell_taps(g, border, R, cx, cy, z)) {
        if (a == 0 && hf_exact_cell_taps(g, border, R, cx - 1, cy, z)) {
            cx--;
            fx += 1.0;
        } else if (b == 0 && hf_exact_cell_taps(g, border, R, cx, cy - 1, z)) {
            cy--;
            fy += 1.0;
        } else {
            return -HFVIS__INF;
        }
    }
    {
        double z0 = (double)z[0], z1 = (double)z[1], z2 = (double)z[2], z3 = (double)z[3];
        double r0 = z0 + (z1 - z0) * fx, r1 = z2 + (z3 - z2) * fx;
        return (r0 + (r1 - r0) * fy - hr) / ucut;
    }
}

/* The per-receiver terms over the receiver rectangle: each tangent becomes the largest of the
 * hull's, the first piece's t -> 0+ limit (hf_exact_first_slope) and, under a radius, the
 * window's far end (hf_exact_cut); holes stay NaN. Receivers on another part's lines
 * (hf_exact_mine) are left alone: their tangents were not swept. */
static void hf_exact_near(hf_exact *E, hf_ray r, double L, double scale)
{
    const int a = r.a, b = r.b;
    const hfvis_grid *g = E->g;
    const double inv_den = hf_exact_inv_den(g, a, b), ucut = (double)E->win_rw / 16.0;
    const double Ad = (double)(a < 0 ? -a : a), Bd = (double)(b < 0 ? -b : b);
    const int diag = a != 0 && b != 0;
    int x, y, part;
    for (y = E->ry0; y < E->ry1; y++) {
        double *t = E->tan + (size_t)y * (size_t)g->width;
        const float *z = g->z + (ptrdiff_t)y * g->stride;
        /* the first cells inside the grid: its taps read directly (hf_exact_first_slope's bits) */
        const int cy = b < 0 ? y - 1 : y, sx = a < 0 ? -1 : 1;
        const ptrdiff_t sy = b < 0 ? -g->stride : g->stride;
        const int in_row = cy >= 0 && cy + 1 < g->height;
        int x0, x1, xa, xb;
        hf_exact_span(E, y, r, &x0, &x1); /* this call's lines: the others' were not swept */
        xa = xb = x1; /* receivers whose first cell is inside the grid, in pairs: [xa, xb) */
        if (diag && in_row && E->win_rw < 0) {
            xa = a < 0 && x0 < 1 ? 1 : x0;
            xb = a > 0 && x1 > g->width - 1 ? g->width - 1 : x1;
            xb = xb > xa ? xa + ((xb - xa) & ~1) : xa;
        }
        /* there without a branch, two receivers a step (C99 the compiler can pack into vectors
           at -O2): a NaN tangent (a hole) stays NaN, and a limit that is not finite (a tap not
           finite, as below) is -INFINITY, which never wins */
        for (x = xa; x < xb; x += 2) {
            double h0 = (double)z[x], h1 = (double)z[x + 1], t0 = t[x], t1 = t[x + 1];
            double s0 = (((double)z[x + sx] - h0) * Ad + ((double)z[x + sy] - h0) * Bd) * inv_den;
            double s1 = (((double)z[x + 1 + sx] - h1) * Ad + ((double)z[x + 1 + sy] - h1) * Bd) * inv_den;
            double d0 = (double)z[x + sx + sy], d1 = (double)z[x + 1 + sx + sy];
            s0 = (fabs(s0) <= DBL_MAX) & (fabs(d0) <= DBL_MAX) ? s0 : -HFVIS__INF;
            s1 = (fabs(s1) <= DBL_MAX) & (fabs(d1) <= DBL_MAX) ? s1 : -HFVIS__INF;
            t[x] = s0 > t0 ? s0 : t0;
            t[x + 1] = s1 > t1 ? s1 : t1;
        }
        for (part = 0; part < 2; part++) /* the rest, [x0, xa) and [xb, x1), one by one */
            for (x = part ? xb : x0; x < (part ? x1 : xa); x++) {
                double s;
                if (isnan(t[x])) continue;
                if (diag) {
                    int cx = a < 0 ? x - 1 : x;
                    if (in_row && cx >= 0 && cx + 1 < g->width) {
                        /* finite s: finite zx and zy (|s| <= 2^128 4096 / den); then zd decides */
                        double hr = (double)z[x], zx = (double)z[x + sx], zy = (double)z[x + sy];
                        s = ((zx - hr) * Ad + (zy - hr) * Bd) * inv_den;
                        if (!isfinite(s) || !isfinite(z[x + sx + sy])) s = -HFVIS__INF;
                    } else {
                        s = hf_exact_first_slope(g, E->border, E->R, x, y, a, b, (double)z[x], inv_den);
                    }
                    if (s > t[x]) t[x] = s;
                }
                if (E->win_rw >= 0) {
                    s = hf_exact_cut(g, E->border, E->R, x, y, a, b, L, ucut, (double)z[x]) * scale;
                    if (s > t[x]) t[x] = s;
                }
            }
    }
}

/* Near and far field (hfvis_sweep_options.ray_near_cells = D > 0; hfvis.h "Exact rays"). A line
 * of direction (a, b) carries one receiver per |(a, b)| cells and costs |a| + |b| - 1 crossings
 * per receiver, so fine directions are expensive whatever the constant per sample. Split each
 * receiver's ray at D cells instead:
 *   - near field, u < D cells: every crossing of the receiver's own ray and the interior
 *     samples of the pieces that bulge (HF_EXACT_BULGE, the sweep's rule; the cells' twists
 *     computed once per call), a stencil of fixed offsets run over the receivers of a row, no
 *     hull; the t -> 0+ limit (hf_exact_near's expression). About 1.4 D crossings per
 *     receiver-direction whatever (a, b).
 *   - far field, u >= D cells: lines of direction (a, b) spaced M = floor(|(a, b)|) exact lines
 *     apart (about one cell), anchored at multiples of M of the raster's line index c = x b - y a.
 *     Each far line is sampled like an exact line (every crossing and the split pieces) and its
 *     upper hull built from its far end, recording each sample's parent in the hull ([P1] §5
 *     Alg. 1's stack kept as a tree: the hull of the samples up to i is the path from i through
 *     the parents). The receivers of the M exact lines nearest the far line (within half a cell
 *     of it), visited in order along (a, b), find with one pointer the last sample at least D
 *     cells ahead and walk the path while the tangent from their own point grows (the hull is
 *     concave, so the tangent is unimodal along it). Every far sample lies within half a cell of
 *     the receiver's ray and at least D cells away: within atan(1/(2D)) of its azimuth
 *     (HFVIS_EXACT_FAR_*_DEG bound the effect on the horizon).
 *   - edges: the far line and the receivers' rays end at different distances. The far line is
 *     cut where the first of its exact lines leaves the reach, so no far sample lies beyond the
 *     end of a receiver's own ray; an exact line that runs on more than a cell beyond that cut
 *     takes its own samples from the cut to its end (its tail) into a hull of its own, queried
 *     by its receivers as the far line is (one tail per line, not one march per receiver).
 * Cost: the near stencil plus about 1.3 far samples and one query per receiver-direction. The
 * value of a receiver depends on its own position only (the far line is fixed by the raster's
 * line index), so receiver rectangles and bands give the whole run's bits. */

/* One offset of the near stencil: crossing e of period k of the receiver's ray and the piece
 * after it. */
struct hf_near_off {
    const hf_cross *c;
    int cross;             /* the crossing itself is a near sample (not the receiver) */
    ptrdiff_t zoff, coff;  /* the crossing's first tap and the piece's cell from the receiver */
    ptrdiff_t toff;        /* the piece's cell in the twist plane (hf_exact.twist) */
    int dx, dy;            /* the period's base offset k (a, b) */
    double u, ic;          /* the crossing's distance (sub-steps); scale / u */
    double icm;            /* scale / the piece's midpoint distance (a piece split in two) */
    double thr;            /* the piece bulges where (sign q) twist > thr (hf_bulge_threshold) */
};
typedef struct hf_near_off hf_near_off;

/* s, t with s a + t b = 1 for gcd(a, b) = 1 (extended Euclid). */
static void hf_ext_gcd(int a, int b, int64_t *s, int64_t *t)
{
    int64_t r0 = a, r1 = b, s0 = 1, s1 = 0, t0 = 0, t1 = 1;
    while (r1 != 0) {
        const int64_t q = r0 / r1, r2 = r0 - q * r1, s2 = s0 - q * s1, t2 = t0 - q * t1;
        r0 = r1;
        r1 = r2;
        s0 = s1;
        s1 = s2;
        t0 = t1;
        t1 = t2;
    }
    if (r0 < 0) {
        s0 = -s0;
        t0 = -t0;
    }
    *s = s0;
    *t = t0;
}

/* The grid point of exact line c (x b - y a = c, grid coordinates) whose position along (a, b),
 * x a + y b, lies in [0, a^2 + b^2); (X1, Y1) is a point of line 1. */
static void hf_line_point(int64_t c, int64_t X1, int64_t Y1, int a, int b, int64_t *px, int64_t *py)
{
    int64_t x = c * X1, y = c * Y1, n2 = (int64_t)a * a + (int64_t)b * b;
    int64_t j = hf_floor_div64(x * a + y * b, n2);
    *px = x - j * a;
    *py = y - j * b;
}

/* The steps j with lo <= p + j c <= hi (c != 0): [*jlo, *jhi]. */
static inline void hf_step_range(int64_t p, int c, int64_t lo, int64_t hi, int64_t *jlo, int64_t *jhi)
{
    if (c > 0) {
        *jlo = -hf_floor_div64(p - lo, c);
        *jhi = hf_floor_div64(hi - p, c);
    } else {
        *jlo = -hf_floor_div64(hi - p, -c);
        *jhi = hf_floor_div64(p - lo, -c);
    }
}

/* The largest t with |q| t <= lim in double (q != 0, lim > 0): |q| t, rounded, grows with t, so
 * the piece's test q twist > lim (HF_EXACT_BULGE, as rounded) holds exactly where (sign q) twist
 * > t, and the near stencil tests the twists without the multiply. A few steps of one ulp from
 * lim / |q|. */
static double hf_bulge_threshold(double q, double lim)
{
    double t;
    q = fabs(q);
    t = lim / q;
    while (q * t > lim) t = nextafter(t, -HFVIS__INF);
    while (t < HFVIS__INF && q * nextafter(t, HFVIS__INF) <= lim) t = nextafter(t, HFVIS__INF);
    return t;
}

/* The near-field offsets of direction (a, b): crossings and pieces starting nearer than ucut
 * sub-steps; returns their count and the offsets' bounding box (taps included). */
static int hf_near_offsets(const hf_exact *E, const hf_cross *cr, int P, int a, int b, double L,
                           double scale, double ucut, hf_near_off *o, int box[4])
{
    const hfvis_grid *g = E->g;
    int n = 0, k, e, j;
    box[0] = box[1] = box[2] = box[3] = 0;
    for (k = 0; (double)k * L < ucut; k++)
        for (e = 0; e < P; e++) {
            const hf_cross *c = cr + e;
            double u = (double)k * L + c->u;
            int x0, y0;
            if (u >= ucut) break;
            o[n].c = c;
            o[n].cross = k > 0 || e > 0;
            o[n].dx = k * a;
            o[n].dy = k * b;
            o[n].zoff = (ptrdiff_t)(k * b + c->oy) * g->stride + (k * a + c->ox);
            o[n].coff = (ptrdiff_t)(k * b + c->cy) * g->stride + (k * a + c->cx);
            o[n].toff = (ptrdiff_t)(k * b + c->cy) * g->width + (k * a + c->cx);
            o[n].u = u;
            o[n].ic = u > 0.0 ? scale / u : 0.0;
            o[n].icm = scale / (u + c->du * 0.5); /* hf_near_fill's sample j = 1 of 2, bit for bit */
            o[n].thr = c->q != 0.0 ? hf_bulge_threshold(c->q, HF_EXACT_BULGE * g->cell_size) : HFVIS__INF;
            for (j = 0; j < 2; j++) { /* the crossing's taps, then the piece's cell */
                x0 = k * a + (j ? c->cx : c->ox);
                y0 = k * b + (j ? c->cy : c->oy);
                if (x0 < box[0]) box[0] = x0;
                if (y0 < box[1]) box[1] = y0;
                if (x0 + 1 > box[2]) box[2] = x0 + 1;
                if (y0 + 1 > box[3]) box[3] = y0 + 1;
            }
            n++;
        }
    return n;
}

/* The interior samples of a piece split in 4 or more (hf_piece_fill) as tangents from hr: the
 * largest, or best. p: the cell's tap (0, 0), u0 the piece's start (sub-steps). */
static double hf_near_fill(const float *p, ptrdiff_t stride, const hf_cross *c, double bulge,
                           double lim, double u0, double hr, double scale, double best)
{
    double ph[HF_EXACT_MAX_SPLIT], pu[HF_EXACT_MAX_SPLIT];
    int j = hf_piece_fill(p, stride, c, bulge, lim, ph, pu);
    while (j-- > 0) {
        double t = (ph[j] - hr) * (scale / (u0 + pu[j]));
        if (t > best) best = t;
    }
    return best;
}

/* Receiver x of a row (heights zr, tangents row) whose piece of offset o (cell tap (0, 0) at
 * zp + x) bulges (bulge > lim): split in two (bulge <= 4 lim: most splits), its midpoint here
 * (hf_near_fill's sample, the same bits); finer splits through hf_near_fill. */
static void hf_near_split(double *row, const float *zp, const float *zr, ptrdiff_t S, const hf_cross *c,
                          const hf_near_off *o, ptrdiff_t x, double bulge, double lim, double scale)
{
    const float *p = zp + x;
    double z00 = (double)p[0], z10 = (double)p[1], z01 = (double)p[S], z11 = (double)p[S + 1];
    double r0 = z00 + (z10 - z00) * c->mfx, r1 = z01 + (z11 - z01) * c->mfx, hr = (double)zr[x], best = row[x];
    double tt = (r0 + (r1 - r0) * c->mfy - hr) * o->icm;
    if (bulge > 4.0 * lim) tt = hf_near_fill(p, S, c, bulge, lim, o->u, hr, scale, best);
    row[x] = tt > best ? tt : best;
}

/* The receivers [xa, xb) of a row whose piece of offset o bulges: twist tp[x] > thr (up) or
 * < thr (not up), hf_bulge_threshold's test, take its interior samples (hf_near_split). */
static inline void hf_near_bulges(double *row, const double *tp, const float *zp, const float *zr, ptrdiff_t S,
                                  const hf_cross *c, const hf_near_off *o, int up, double thr, double lim,
                                  double scale, int xa, int xb)
{
    const double *p = tp + xa, *e = tp + xb;
    int k, g4;
    /* four twists a step: one pointer, a compare each (NaN at holes: never); the rare hits
       then one by one, and the last up to three */
    for (g4 = (xb - xa) / 4; g4 > 0; g4--, p += 4) {
        if (up ? !(p[0] > thr || p[1] > thr || p[2] > thr || p[3] > thr)
               : !(p[0] < thr || p[1] < thr || p[2] < thr || p[3] < thr))
            continue;
        for (k = 0; k < 4; k++)
            if (up ? p[k] > thr : p[k] < thr) hf_near_split(row, zp, zr, S, c, o, p + k - tp, c->q * p[k], lim, scale);
    }
    for (; p < e; p++)
        if (up ? *p > thr : *p < thr) hf_near_split(row, zp, zr, S, c, o, p - tp, c->q * *p, lim, scale);
}

/* The near field of one receiver at (x, y) anywhere (the border rule outside the grid): its
 * largest tangent over the stencil, from best. */
static double hf_near_one(const hf_exact *E, const hf_near_off *o, int n, int x, int y, double hr,
                          double scale, double best)
{
    const hfvis_grid *g = E->g;
    const double lim = HF_EXACT_BULGE * g->cell_size;
    int i;
    for (i = 0; i < n; i++) {
        const hf_cross *c = o[i].c;
        int X = x + o[i].dx, Y = y + o[i].dy;
        const int CX = X + c->cx, CY = Y + c->cy, open = E->border == HFVIS_BORDER_OPEN;
        float z[4];
        if (o[i].cross) {
            const int KX = X + c->ox, KY = Y + c->oy;
            double h = HFVIS__NAN, t;
            if (KX >= 0 && KY >= 0 && KX + (c->kind == 2) < g->width && KY + (c->kind == 1) < g->height) {
                const float *p = g->z + (ptrdiff_t)KY * g->stride + KX; /* hf_cross_height inside the grid */
                h = (double)p[0];
                if (c->kind != 0) h += ((double)p[c->kind == 1 ? g->stride : 1] - h) * c->f;
                if (!isfinite(h)) h = HFVIS__NAN;
            } else if (!open && hf_cross_inside(g, E->R, KX, KY, c)) {
                h = hf_cross_height(g, E->border, KX, KY, c);
            }
            t = (h - hr) * o[i].ic;
            if (t > best) best = t; /* NaN (a hole, out of reach) never is */
        }
        if (!(c->du > 0.0)) continue;
        if (CX >= 0 && CY >= 0 && CX + 1 < g->width && CY + 1 < g->height) {
            const float *p = g->z + (ptrdiff_t)CY * g->stride + CX; /* the cell's taps in place */
            double bulge = c->q * hf_cell_twist(p, g->stride);
            if (bulge > lim && bulge < HFVIS__INF) best = hf_near_fill(p, g->stride, c, bulge, lim, o[i].u, hr, scale, best);
        } else if (!open && hf_exact_cell_taps(g, E->border, E->R, CX, CY, z)) {
            double bulge = c->q * hf_cell_twist(z, 2);
            if (bulge > lim && bulge < HFVIS__INF) best = hf_near_fill(z, 2, c, bulge, lim, o[i].u, hr, scale, best);
        }
    }
    return best;
}

/* The near field over the receiver rectangle into E->tan, with the t -> 0+ limit
 * (hf_exact_near's expression): -INFINITY (nothing near), NaN at holes. Rows and columns whose
 * whole stencil lies inside the grid run offset by offset over the row (no border tests; NaN taps
 * drop out of the maxima by themselves, infinite ones would not: a grid with an infinite height,
 * E->inf, takes the other path everywhere), a piece's interior samples only where its cell's
 * twist (E->twist) makes it bulge by more than HF_EXACT_BULGE; the rest receiver by receiver
 * (hf_near_one, the same samples). */
static void hf_near_field(hf_exact *E, const hf_near_off *o, int n, const int box[4], double scale,
                          double *row)
{
    const hfvis_grid *g = E->g;
    const double lim = HF_EXACT_BULGE * g->cell_size;
    const ptrdiff_t S = g->stride;
    const int a = E->ray_a, b = E->ray_b, sx = a < 0 ? -1 : 1;
    const ptrdiff_t sy = b < 0 ? -S : S;
    const double inv_den = hf_exact_inv_den(g, a, b), Ad = (double)(a < 0 ? -a : a), Bd = (double)(b < 0 ? -b : b);
    int x, y, i;
    for (y = E->ry0; y < E->ry1; y++) {
        double *t = E->tan + (size_t)y * (size_t)g->width;
        const float *zr = g->z + (ptrdiff_t)y * S;
        const double *tw = E->twist + (ptrdiff_t)y * g->width;
        int xa = E->rx0, xb = E->rx1; /* the interior columns [xa, xb) */
        if (y + box[1] < 0 || y + box[3] > g->height - 1 || E->inf) xa = xb = E->rx1;
        else {
            if (xa < -box[0]) xa = -box[0];
            if (xb > g->width - 1 - box[2] + 1) xb = g->width - box[2];
            if (xb < xa) xa = xb = E->rx1;
        }
        /* the t -> 0+ limit (its cell is the first piece's, inside), two receivers a step
           without a branch (packed into vectors at -O2, as hf_exact_near's), then the odd one */
        for (x = xa; x + 1 < xb; x += 2) {
            double h0 = (double)zr[x], h1 = (double)zr[x + 1];
            double s0 = (((double)zr[x + sx] - h0) * Ad + ((double)zr[x + sy] - h0) * Bd) * inv_den;
            double s1 = (((double)zr[x + 1 + sx] - h1) * Ad + ((double)zr[x + 1 + sy] - h1) * Bd) * inv_den;
            double d0 = (double)zr[x + sx + sy], d1 = (double)zr[x + 1 + sx + sy];
            row[x] = (fabs(s0) <= DBL_MAX) & (fabs(d0) <= DBL_MAX) ? s0 : -HFVIS__INF;
            row[x + 1] = (fabs(s1) <= DBL_MAX) & (fabs(d1) <= DBL_MAX) ? s1 : -HFVIS__INF;
        }
        if (x < xb) {
            double h0 = (double)zr[x], s0 = (((double)zr[x + sx] - h0) * Ad + ((double)zr[x + sy] - h0) * Bd) * inv_den;
            row[x] = isfinite(s0) && isfinite(zr[x + sx + sy]) ? s0 : -HFVIS__INF;
        }
        for (i = 0; i < n && xa < xb; i++) {
            const hf_cross *c = o[i].c;
            const float *zc = zr + o[i].zoff, *zp = zr + o[i].coff;
            const double *tp = tw + o[i].toff, q = c->q;
            const double ic = o[i].ic, f = c->f;
            const ptrdiff_t st = c->zstep;
            if (o[i].cross && c->kind == 0)
                for (x = xa; x < xb; x++) {
                    double tt = ((double)zc[x] - (double)zr[x]) * ic, rx = row[x];
                    row[x] = tt > rx ? tt : rx; /* NaN (a hole) never is */
                }
            else if (o[i].cross) {
                /* four receivers a step, written out (C99 the compiler can pack into vectors at
                   -O2), then the last up to three */
                for (x = xa; x + 3 < xb; x += 4) {
                    double h0 = (double)zc[x], h1 = (double)zc[x + 1], t0, t1, r0 = row[x], r1 = row[x + 1];
                    double h2 = (double)zc[x + 2], h3 = (double)zc[x + 3], t2, t3, r2 = row[x + 2], r3 = row[x + 3];
                    h0 += ((double)zc[x + st] - h0) * f;
                    h1 += ((double)zc[x + 1 + st] - h1) * f;
                    h2 += ((double)zc[x + 2 + st] - h2) * f;
                    h3 += ((double)zc[x + 3 + st] - h3) * f;
                    t0 = (h0 - (double)zr[x]) * ic;
                    t1 = (h1 - (double)zr[x + 1]) * ic;
                    t2 = (h2 - (double)zr[x + 2]) * ic;
                    t3 = (h3 - (double)zr[x + 3]) * ic;
                    row[x] = t0 > r0 ? t0 : r0;
                    row[x + 1] = t1 > r1 ? t1 : r1;
                    row[x + 2] = t2 > r2 ? t2 : r2;
                    row[x + 3] = t3 > r3 ? t3 : r3;
                }
                for (; x < xb; x++) {
                    double h = (double)zc[x], tt, rx = row[x];
                    h += ((double)zc[x + st] - h) * f;
                    tt = (h - (double)zr[x]) * ic;
                    row[x] = tt > rx ? tt : rx;
                }
            }
            if (c->du > 0.0) {
                /* the bulge q hf_cell_twist > lim tested on the twist alone (hf_bulge_threshold;
                   few pieces bulge: hf_near_split) */
                if (q > 0.0) hf_near_bulges(row, tp, zp, zr, S, c, o + i, 1, o[i].thr, lim, scale, xa, xb);
                else if (q < 0.0) hf_near_bulges(row, tp, zp, zr, S, c, o + i, 0, -o[i].thr, lim, scale, xa, xb);
            }
        }
        for (x = xa; x + 1 < xb; x += 2) { /* NaN at holes, without a branch, two a step */
            const double h0 = (double)zr[x], h1 = (double)zr[x + 1];
            t[x] = fabs(h0) <= DBL_MAX ? row[x] : HFVIS__NAN;
            t[x + 1] = fabs(h1) <= DBL_MAX ? row[x + 1] : HFVIS__NAN;
        }
        if (x < xb) t[x] = isfinite(zr[x]) ? row[x] : HFVIS__NAN;
        for (i = 0; i < 2; i++) /* the rest, [rx0, xa) and [xb, rx1) (xa = xb = rx1: all) */
            for (x = i ? xb : E->rx0; x < (i ? E->rx1 : xa); x++) {
                const double hr = (double)zr[x];
                if (!isfinite(hr)) t[x] = HFVIS__NAN;
                else
                    t[x] = hf_near_one(E, o, n, x, y, hr, scale,
                                       hf_exact_first_slope(g, E->border, E->R, x, y, a, b, hr, inv_den));
            }
    }
}

/* The samples of the far line through grid point (px, py) (grid coordinates, possibly outside)
 * over the periods k = kmax down to kmin, in sweep order (increasing distance d, sub-steps,
 * d = (kmax - k) L at p + k (a, b)): every crossing and split piece within reach (the samples
 * hf_exact_samples takes; periods with both ends inside the grid read the heights directly, the
 * others under the border rule). Returns the count. A tail (start finite) stops once a sample
 * lies beyond the far line's end, shift + sd n2 > start (the caller drops those: the far line
 * serves them), the partly outside periods, the costly ones, at the crossing. */
static int hf_far_samples(hf_exact *E, int64_t px, int64_t py, int a, int b, int P, double L,
                          int64_t kmin, int64_t kmax, double *sd, double *sh, double shift, double n2,
                          double start)
{
    const hfvis_grid *g = E->g;
    const hf_cross *cr = E->cross;
    const double lim = HF_EXACT_BULGE * g->cell_size;
    double ph[HF_EXACT_MAX_SPLIT], pu[HF_EXACT_MAX_SPLIT];
    int n = 0, e, j, splits = 0, eager = E->eager;
    int64_t k, inner = 0;
    double ulo, uhi;
    const int tail = start < HFVIS__INF;
    for (k = kmax; k >= kmin; k--) {
        int64_t X0 = px + k * a, Y0 = py + k * b, X1 = X0 + a, Y1 = Y0 + b;
        double base = (double)(kmax - k) * L;
        if (tail && n > 0 && shift + sd[n - 1] * n2 > start) break; /* samples grow along the line */
        if (X0 >= 0 && X1 >= 0 && X0 < g->width && X1 < g->width && Y0 >= 0 && Y1 >= 0 &&
            Y0 < g->height && Y1 < g->height) {
            const float *zn = g->z + (ptrdiff_t)Y0 * g->stride + (ptrdiff_t)X0;
            const double *tn = E->twist + ((ptrdiff_t)Y0 * g->width + (ptrdiff_t)X0);
            double h;
            for (e = P - 1; e > 0; e--) { /* as hf_exact_samples between two grid points */
                const hf_cross *c = cr + e;
                n = hf_exact_piece(g, c, zn, tn, base, lim, sd, sh, n, eager, &splits);
                h = (double)zn[c->zoff];
                h += ((double)zn[c->zoff + c->zstep] - h) * c->f;
                sd[n] = base - c->u;
                sh[n] = h;
                n += isfinite(h) ? 1 : 0;
            }
            n = hf_exact_piece(g, cr, zn, tn, base, lim, sd, sh, n, eager, &splits);
            h = (double)zn[0];
            sd[n] = base;
            sh[n] = h;
            n += isfinite(h) ? 1 : 0;
            inner++;
            continue;
        }
        /* the whole period out of reach: its crossings and piece midpoints lie between its grid
           points, so beyond -R or (size - 1 + R) on an axis so do their taps and cells */
        if ((X0 > X1 ? X0 : X1) < -E->R || (X0 < X1 ? X0 : X1) > g->width - 1 + E->R ||
            (Y0 > Y1 ? Y0 : Y1) < -E->R || (Y0 < Y1 ? Y0 : Y1) > g->height - 1 + E->R)
            continue;
        /* the crossings within two cells of the reach on both axes, u in [ulo, uhi] (whole
           numbers: a cell along x is |b| sub-steps, along y |a|); a piece lies in one cell, so
           beyond that neither it nor its crossing has a sample */
        {
            const int64_t Ai = a < 0 ? -a : a, Bi = b < 0 ? -b : b, R = E->R;
            const int64_t xl = (a > 0 ? -R - 2 - X0 : X0 - g->width - R - 1) * Bi;
            const int64_t xh = (a > 0 ? g->width + R + 1 - X0 : X0 + R + 2) * Bi;
            const int64_t yl = (b > 0 ? -R - 2 - Y0 : Y0 - g->height - R - 1) * Ai;
            const int64_t yh = (b > 0 ? g->height + R + 1 - Y0 : Y0 + R + 2) * Ai;
            ulo = (double)(xl > yl ? xl : yl);
            uhi = (double)(xh < yh ? xh : yh);
        }
        for (e = P - 1; e >= 0; e--) { /* as hf_exact_samples' pre-roll */
            const hf_cross *c = cr + e;
            const int X = (int)X0 + c->ox, Y = (int)Y0 + c->oy, CX = (int)X0 + c->cx, CY = (int)Y0 + c->cy;
            double h;
            if (c->u > uhi) continue;
            if (c->u < ulo) break;
            if (tail && n > 0 && shift + sd[n - 1] * n2 > start) break; /* and the periods after */
            if (CX >= 0 && CY >= 0 && CX + 1 < g->width && CY + 1 < g->height) {
                /* the cell inside the grid: hf_piece_samples' test and samples, its taps read in
                   place (a tap that is a hole or infinite makes the bulge fail the test) */
                const float *p = g->z + (ptrdiff_t)CY * g->stride + CX;
                double bulge = c->q * hf_cell_twist(p, g->stride);
                j = c->du > 0.0 && bulge > lim && bulge < HFVIS__INF ? hf_piece_fill(p, g->stride, c, bulge, lim, ph, pu) : 0;
            } else {
                j = E->border == HFVIS_BORDER_OPEN ? 0 : hf_piece_samples(g, E->border, E->R, (int)X0, (int)Y0, c, ph, pu);
            }
            while (j-- > 0) {
                if (isnan(ph[j])) continue;
                sd[n] = base - (c->u + pu[j]);
                sh[n++] = ph[j];
            }
            if (X >= 0 && Y >= 0 && X + (c->kind == 2) < g->width && Y + (c->kind == 1) < g->height) {
                const float *p = g->z + (ptrdiff_t)Y * g->stride + X; /* hf_cross_height inside the grid */
                h = (double)p[0];
                if (c->kind != 0) h += ((double)p[c->kind == 1 ? g->stride : 1] - h) * c->f;
                if (!isfinite(h)) continue;
            } else {
                if (E->border == HFVIS_BORDER_OPEN || !hf_cross_inside(g, E->R, X, Y, c)) continue;
                h = hf_cross_height(g, E->border, X, Y, c);
                if (isnan(h)) continue;
            }
            sd[n] = base - c->u;
            sh[n++] = h;
        }
    }
    if (inner > 0) E->eager = (double)splits > HF_EXACT_EAGER_SHARE * (double)inner * (double)P;
    return n;
}

/* The upper hull of samples (sd, sh) in sweep order as a tree: par[i] the sample below i on the
 * stack when i was pushed ([P1] §5 Alg. 1's pops; -1: none), so the hull of samples 0..i is the
 * path from i through the parents; hmax[i] the highest of samples 0..i. stack: n ints. */
static void hf_far_hull(const double *sd, const double *sh, int n, int *stack, int *par, double *hmax)
{
    int top = -1, i;
    double m = -HFVIS__INF, dB = 0.0, hB = 0.0; /* the top sample's distance and height */
    for (i = 0; i < n; i++) {
        const double d = sd[i], h = sh[i];
        while (top >= 1) {
            const int A = stack[top - 1];
            const double dA = sd[A], hA = sh[A];
            /* the top B leaves when it is not above the chord from A to the new sample */
            if (!((dB - dA) * (h - hA) >= (hB - hA) * (d - dA))) break;
            top--;
            dB = dA;
            hB = hA;
        }
        par[i] = top >= 0 ? stack[top] : -1;
        stack[++top] = i;
        dB = d;
        hB = h;
        if (h > m) m = h;
        hmax[i] = m;
    }
}

/* The far field of a receiver at distance dr (sub-steps times n2, in the far line's sweep
 * coordinate) with height hr, whose far samples are 0..i (those at least D cells ahead): the
 * largest tangent (times fscale) over them if larger than best, else best. The walk follows the
 * hull from i while the tangent grows. */
static inline double hf_far_query(const double *sd, const double *sh, const int *par, const double *hmax,
                           int i, double n2, double dr, double hr, double fscale, double best,
                           double *vdist)
{
    double dist = dr - sd[i] * n2, bound = hmax[i] - hr;
    /* an exact bound: no sample up to i can beat best */
    bound = bound >= 0.0 ? bound / dist : bound / (dr - sd[0] * n2);
    if (!(bound * fscale > best)) return best;
    for (;;) {
        int p = par[i];
        double dp;
        if (p < 0) break;
        dp = dr - sd[p] * n2;
        if (!((sh[p] - hr) * dist > (sh[i] - hr) * dp)) break;
        i = p;
        dist = dp;
    }
    *vdist = dist;
    dist = (sh[i] - hr) / dist * fscale;
    return dist > best ? dist : best;
}

/* One exact line of a far band: its grid point q with position t = q . (a, b) in [0, a^2 + b^2)
 * and the steps j of its receivers q + j (a, b) in the receiver rectangle. */
struct hf_far_line {
    int64_t t, qx, qy, jlo, jhi;
    int64_t i0, z0, d0; /* receiver q + j (a, b): tangent i0 + j istep, height z0 + j zstep, and
                           distance (d0 - j n2) L from the far line's end (its frame) */
    double end; /* where its receivers' rays leave the reach, in the far line's frame (n2 units) */
};
typedef struct hf_far_line hf_far_line;

/* The periods k of the line through (px, py) along (a, b) whose grid point p + k (a, b) lies
 * within the grid grown by R + 1 cells, with one period of margin either side: [*kmin, *kmax];
 * 0 if none. */
static int hf_far_periods(const hfvis_grid *g, int R, int64_t px, int64_t py, int a, int b, int64_t *kmin,
                          int64_t *kmax)
{
    double s0 = -HFVIS__INF, s1 = HFVIS__INF;
    int ax;
    for (ax = 0; ax < 2; ax++) {
        double p0 = (double)(ax ? py : px), d = (double)(ax ? b : a);
        double e0 = -(double)R - 1.0, e1 = (double)(ax ? g->height : g->width) + (double)R;
        double ta = (e0 - p0) / d, tb = (e1 - p0) / d;
        /* fmin and fmax without the calls (d != 0: no NaN) */
        if (ta > tb) {
            const double tt = ta;
            ta = tb;
            tb = tt;
        }
        s0 = ta > s0 ? ta : s0;
        s1 = tb < s1 ? tb : s1;
    }
    if (!(s0 <= s1)) return 0;
    *kmin = (int64_t)floor(s0) - 1;
    *kmax = (int64_t)ceil(s1) + 1;
    return 1;
}

/* The far field of direction (a, b) over the receiver rectangle (this call's lines), into
 * E->tan (hf_near_field first). Frames: a far line's samples are at distance sd (sub-steps) from
 * its far end (period kmax); a receiver at along-line position pos = x a + y b lies at
 * dr = (kmax n2 + pos(p) - pos) L from it, in units of sub-steps times n2. */
static void hf_far_field(hf_exact *E, hf_ray r, int P, double L, double scale, double ucut)
{
    const hfvis_grid *g = E->g;
    const int a = r.a, b = r.b;
    hf_far_line *lines = E->flines;
    const int64_t n2i = (int64_t)a * a + (int64_t)b * b;
    const double n2 = (double)n2i, len = sqrt(n2), fscale = n2 * scale, dn = ucut * n2;
    const double Ad = (double)(a < 0 ? -a : a), Bd = (double)(b < 0 ? -b : b), cell = L / len * n2;
    const int M = (int)floor(len), hM = M / 2, R = E->R;
    const int64_t cshift = (int64_t)E->ox * b - (int64_t)E->oy * a; /* raster c - grid c */
    const int64_t istep = (int64_t)b * g->width + a, zstep = (int64_t)b * g->stride + a;
    int64_t X1, Y1, lo = INT64_MAX, hi = INT64_MIN, m, mlo, mhi;
    int corner;
    hf_ext_gcd(b, a, &X1, &Y1); /* X1 b + Y1 a = 1: (X1, -Y1) is on line 1 */
    Y1 = -Y1;
    for (corner = 0; corner < 4; corner++) {
        int64_t x = corner & 1 ? E->rx1 - 1 : E->rx0, y = corner & 2 ? E->ry1 - 1 : E->ry0;
        int64_t v = x * b - y * a + cshift;
        lo = v < lo ? v : lo;
        hi = v > hi ? v : hi;
    }
    mlo = hf_floor_div64(lo + hM, M);
    mhi = hf_floor_div64(hi + hM, M);
    for (m = mlo; m <= mhi; m++) {
        int64_t cf = m * M - cshift, px, py, kmin = 0, kmax = 0, c, clo, chi, j, jl, jh;
        int64_t jmin = 0, jmax = -1;
        double cut = -HFVIS__INF, start, *sd = E->sd, *sh = E->sh, *fm = E->fmax;
        int n = 0, nl, ptr, w, f0 = 0, *par = E->fpar;
        hf_line_point(cf, X1, Y1, a, b, &px, &py);
        if (hf_far_periods(g, R, px, py, a, b, &kmin, &kmax))
            n = hf_far_samples(E, px, py, a, b, P, L, kmin, kmax, E->sd, E->sh, 0.0, n2, HFVIS__INF);
        /* the band's exact lines (all of them, so that the cut does not depend on the receiver
           rectangle): where each one's rays leave the reach; the far line is cut at the nearest
           such end, so no far sample lies beyond the end of a receiver's own ray */
        clo = m * M - hM - cshift;
        chi = clo + M - 1;
        nl = 0;
        for (c = clo; c <= chi; c++) {
            hf_far_line l;
            int64_t jl2, jh2;
            double ex, ey;
            hf_line_point(c, X1, Y1, a, b, &l.qx, &l.qy);
            hf_step_range(l.qx, a, 0, g->width - 1, &jl, &jh);
            hf_step_range(l.qy, b, 0, g->height - 1, &jl2, &jh2);
            if (jl2 > jl) jl = jl2;
            if (jh2 < jh) jh = jh2;
            if (jl > jh) continue; /* no grid point inside the grid */
            ex = (double)(a > 0 ? g->width - 1 + R - l.qx : l.qx + R) * Bd;
            ey = (double)(b > 0 ? g->height - 1 + R - l.qy : l.qy + R) * Ad;
            l.end = ((double)kmax * L) * n2 - (double)((l.qx - px) * a + (l.qy - py) * b) * L - (ex < ey ? ex : ey) * n2;
            if (l.end > cut) cut = l.end;
            if (c + cshift < lo || c + cshift > hi) continue; /* outside the receiver rectangle */
            hf_step_range(l.qx, a, E->rx0, E->rx1 - 1, &l.jlo, &l.jhi);
            hf_step_range(l.qy, b, E->ry0, E->ry1 - 1, &jl2, &jh2);
            if (jl2 > l.jlo) l.jlo = jl2;
            if (jh2 < l.jhi) l.jhi = jh2;
            if (l.jlo > l.jhi) continue;
            l.t = l.qx * a + l.qy * b;
            l.i0 = l.qy * g->width + l.qx;
            l.z0 = l.qy * g->stride + l.qx;
            l.d0 = kmax * n2i - ((l.qx - px) * a + (l.qy - py) * b);
            for (w = nl++; w > 0 && lines[w - 1].t < l.t; w--) lines[w] = lines[w - 1];
            lines[w] = l;
            if (l.jlo < jmin || nl == 1) jmin = l.jlo;
            if (l.jhi > jmax || nl == 1) jmax = l.jhi;
        }
        if (nl == 0) continue;
        while (f0 < n && sd[f0] * n2 < cut) f0++;
        sd += f0;
        sh += f0;
        n -= f0;
        hf_far_hull(sd, sh, n, E->rec, par, fm);
        sd[n] = HFVIS__INF; /* the pointers' sentinel: never within reach */
        start = n > 0 ? sd[0] * n2 : HFVIS__INF; /* the far line's end after the cut */
        /* receivers by t = t_q + j n2 descending, so their thresholds grow: one pointer */
        for (ptr = -1, j = jmax; j >= jmin; j--) {
            for (w = 0; w < nl; w++) {
                const hf_far_line *l = lines + w;
                double *ti, dr, vd;
                if (j < l->jlo || j > l->jhi) continue;
                ti = E->tan + (l->i0 + j * istep);
                if (isnan(*ti) || (E->parts && !hf_exact_mine(E, (int)(l->qx + j * a), (int)(l->qy + j * b), r)))
                    continue;
                dr = (double)(l->d0 - j * n2i) * L; /* an integer times L: exact, as every distance here */
                while (sd[ptr + 1] * n2 <= dr - dn) ptr++;
                if (ptr >= 0) *ti = hf_far_query(sd, sh, par, fm, ptr, n2, dr, (double)g->z[l->z0 + j * zstep], fscale, *ti, &vd);
            }
        }
        /* Tails: an exact line whose rays run on more than a cell beyond the far line's end
           takes its own samples from its end to there (a hull per line, queried by its
           receivers as the far line is). */
        for (w = 0; w < nl; w++) {
            const hf_far_line *l = lines + w;
            int64_t tmin, tmax, k0;
            double shift;
            if (!(l->end + cell < start)) continue;
            if (!hf_far_periods(g, R, l->qx, l->qy, a, b, &tmin, &tmax)) continue;
            /* the tail frame's origin (period tmax of this line) in the far line's frame */
            shift = ((double)(kmax - tmax) * n2 + (double)((px - l->qx) * a + (py - l->qy) * b)) * L;
            k0 = l->jlo - 1; /* nothing behind the first receiver is ahead of any */
            if (start < HFVIS__INF) { /* the periods up to the far line's end */
                double kc = floor((double)tmax - (start - shift) / (n2 * L));
                if (kc > (double)k0) k0 = (int64_t)kc;
            }
            if (k0 > tmax) continue;
            if (k0 > tmin) tmin = k0;
            sd = E->sd;
            sh = E->sh;
            n = hf_far_samples(E, l->qx, l->qy, a, b, P, L, tmin, tmax, sd, sh, shift, n2, start);
            while (n > 0 && shift + sd[n - 1] * n2 > start) n--; /* the far line serves those */
            hf_far_hull(sd, sh, n, E->rec, par, fm);
            sd[n] = HFVIS__INF;
            for (ptr = -1, j = l->jhi; j >= l->jlo; j--) {
                double *ti = E->tan + (l->i0 + j * istep), dr = (double)(tmax - j) * L * n2, vd;
                if (isnan(*ti) || (E->parts && !hf_exact_mine(E, (int)(l->qx + j * a), (int)(l->qy + j * b), r)))
                    continue;
                while (sd[ptr + 1] * n2 <= dr - dn) ptr++;
                if (ptr >= 0) *ti = hf_far_query(sd, sh, par, fm, ptr, n2, dr, (double)g->z[l->z0 + j * zstep], fscale, *ti, &vd);
            }
        }
    }
}

/* The near and far field applies to direction r (hf_far_field): D > 0, no radius, off the axes
 * and diagonals, a line longer than D between grid points (else its sweep is the cheaper), and
 * far positions (sub-steps times a^2 + b^2, sixteenths) exact in double. */
static int hf_far_applies(const hf_exact *E, hf_ray r, double L)
{
    const hfvis_grid *g = E->g;
    double n2 = (double)r.a * (double)r.a + (double)r.b * (double)r.b;
    return E->near > 0 && E->win_rw < 0 && r.a != 0 && r.b != 0 && n2 > (double)E->near * (double)E->near &&
           16.0 * ((double)g->width + (double)g->height + 4.0 * (double)E->R + 16.0) * L * n2 < 4503599627370496.0;
}

/* Tangents of every grid point toward ray r into E->tan (-INFINITY: no terrain, NaN: hole).
 * Heads are enumerated row by row, so consecutive lines are neighbours. */
static void hf_exact_sweep(hf_exact *E, hf_ray r)
{
    const hfvis_grid *g = E->g;
    double L, scale;
    int P = hf_exact_geometry(E->cross, g, r.a, r.b, &L, &scale), x, y;
    E->win_rw = E->radius > 0.0 ? hf_exact_window(E->radius, scale) : -1;
    E->eager = 0;
    E->ray_a = r.a;
    E->ray_b = r.b;
    if (hf_far_applies(E, r, L)) {
        double n2 = (double)r.a * (double)r.a + (double)r.b * (double)r.b;
        double ucut = ceil((double)E->near * L / sqrt(n2)); /* D cells in sub-steps */
        int box[4], n = hf_near_offsets(E, E->cross, P, r.a, r.b, L, scale, ucut, E->noff, box);
        hf_near_field(E, E->noff, n, box, scale, E->row);
        hf_far_field(E, r, P, L, scale, ucut); /* the t -> 0+ limit is the near field's */
        return;
    }
    for (y = 0; y < g->height; y++) {
        int xlo, xhi;
        if (y + r.b < 0 || y + r.b >= g->height) {
            xlo = 0;
            xhi = g->width - 1;
        } else if (r.a > 0) {
            xlo = g->width - r.a;
            xhi = g->width - 1;
        } else if (r.a < 0) {
            xlo = 0;
            xhi = -r.a - 1;
        } else {
            continue;
        }
        if (xlo < 0) xlo = 0;
        if (xhi > g->width - 1) xhi = g->width - 1;
        for (x = xlo; x <= xhi; x++)
            if (hf_exact_mine(E, x, y, r)) hf_exact_line(E, x, y, r.a, r.b, P, L, scale);
    }
    if ((r.a != 0 && r.b != 0) || E->win_rw >= 0) hf_exact_near(E, r, L, scale);
}

/* The supremum of (h(u) - hr)/u (height per sub-step) over the interior of piece c (cell taps z,
 * hf_exact_cell_taps) starting u0 > 0 sub-steps from the receiver and cut at umax: along the
 * piece h(t) = H0 + H1 t + H2 t^2, t in [0, 1], u = u0 + t du; its stationary points solve
 * H2 du t^2 + 2 H2 u0 t + H1 u0 - (H0 - hr) du = 0. Candidates: the roots inside (0, 1) and
 * before the cut (the crossings at the ends and the cut are points of their own); none in the
 * first piece (u0 = 0, where the tangent is linear in t: hf_exact_first_slope). -INFINITY if none. */
static double hf_exact_piece_sup(const float *zf, const hf_cross *c, double u0, double hr, double umax)
{
    double z[4], w, dfx = c->fx1 - c->fx0, dfy = c->fy1 - c->fy0, H0, H1, H2, al, be, ga;
    double t1 = 1.0, best = -HFVIS__INF, root[2], disc;
    int n = 0, i;
    z[0] = (double)zf[0];
    z[1] = (double)zf[1];
    z[2] = (double)zf[2];
    z[3] = (double)zf[3];
    w = z[0] - z[1] - z[2] + z[3];
    H0 = z[0] + (z[1] - z[0]) * c->fx0 + (z[2] - z[0]) * c->fy0 + w * c->fx0 * c->fy0;
    H1 = (z[1] - z[0]) * dfx + (z[2] - z[0]) * dfy + w * (c->fx0 * dfy + c->fy0 * dfx);
    H2 = w * dfx * dfy;
    al = H2 * c->du;
    be = 2.0 * H2 * u0;
    ga = H1 * u0 - (H0 - hr) * c->du;
    if (u0 + c->du > umax) { /* the cut (its own point: hf_exact_cut) */
        t1 = (umax - u0) / c->du;
        if (!(t1 > 0.0)) return best;
    }
    disc = be * be - 4.0 * al * ga;
    if (u0 > 0.0 && al != 0.0 && disc >= 0.0) { /* u0 = 0 (the first piece): linear in t */
        double q = -0.5 * (be + (be < 0.0 ? -sqrt(disc) : sqrt(disc)));
        if (q != 0.0) {
            root[n++] = q / al;
            root[n++] = ga / q;
        }
    }
    for (i = 0; i < n; i++) {
        double t = root[i], s;
        if (!(t > 0.0 && t <= t1)) continue;
        s = (H0 + (H1 + H2 * t) * t - hr) / (u0 + t * c->du);
        if (s > best) best = s;
    }
    return best;
}

/* Oracle of the exact mode for one receiver: the supremum over t > 0 of the elevation tangent
 * along its own ray over the bilinear surface, within the window rw (1/16 sub-steps,
 * hf_exact_window; -1 = unlimited): every crossing (hf_cross_height, the sweep's heights), every
 * piece's interior in closed form (hf_exact_piece_sup), the window's far end (hf_exact_cut) and
 * the first piece's t -> 0+ limit (hf_exact_first_slope); the largest kept. */
static double hf_exact_march(const hfvis_grid *g, hfvis_border border, int R, const hf_cross *cr,
                             int P, double L, double scale, int a, int b, int x, int y, int64_t rw)
{
    double hr = (double)g->z[(ptrdiff_t)y * g->stride + x], best = -HFVIS__INF, s;
    double umax = rw >= 0 ? (double)rw / 16.0 : HFVIS__INF;
    int k, e, kmax = hf_exact_periods(g, R, x, y, a, b);
    if (!isfinite(hr)) return HFVIS__NAN;
    for (k = 0; k <= kmax; k++)
        for (e = 0; e < P; e++) {
            int X = x + k * a + cr[e].ox, Y = y + k * b + cr[e].oy;
            double h, u = (double)k * L + cr[e].u;
            float z[4];
            if (cr[e].du > 0.0 && u < umax &&
                hf_exact_cell_taps(g, border, R, x + k * a + cr[e].cx, y + k * b + cr[e].cy, z)) {
                s = hf_exact_piece_sup(z, cr + e, u, hr, umax) * scale;
                if (s > best) best = s;
            }
            if ((k == 0 && e == 0) || !hf_cross_inside(g, R, X, Y, cr + e)) continue;
            if (rw >= 0 && 16.0 * u > (double)rw) continue;
            h = hf_cross_height(g, border, X, Y, cr + e);
            if (isnan(h)) continue;
            s = (h - hr) / u * scale;
            if (s > best) best = s;
        }
    if (rw >= 0) {
        s = hf_exact_cut(g, border, R, x, y, a, b, L, umax, hr) * scale;
        if (s > best) best = s;
    }
    hr = hf_exact_first_slope(g, border, R, x, y, a, b, hr, hf_exact_inv_den(g, a, b));
    return hr > best ? hr : best;
}

/* Scratch of one exact-mode call, one block: the K directions and their quadrature, the
 * crossings, one line's samples and receivers (the hull stack in place), the tangent plane, and
 * optionally grid normals (want_normals 1; 2: room for them, filled by the caller) and a
 * channels-deep accumulator. */
static hfvis_status hf_exact_init(hf_exact *E, const hfvis_grid *g, int K,
                                  const hfvis_sweep_options *o, int want_tan, int want_normals,
                                  int channels)
{
    size_t total = 0, off_ray, off_d, off_c, off_s, off_t = 0, off_n = 0, off_a = 0, gridn, cap;
    size_t off_win = 0, off_r, off_fp = 0, off_fm = 0, off_no = 0, off_row = 0, off_fl = 0, off_tw = 0;
    size_t off_stk = 0;
    int ok = 1, k, maxp = 1, side = g->width > g->height ? g->width : g->height, plane = 0;
    double cls = 0.0;
    unsigned char *blk;
    memset(E, 0, sizeof *E);
    E->g = g;
    E->border = o->border;
    E->R = o->border == HFVIS_BORDER_OPEN ? 0 : o->border_cells;
    E->N = hf_exact_bound(o, K);
    E->channels = channels;
    E->alloc = o->alloc;
    if (E->N > HFVIS_RAY_DENOMINATOR_MAX) return HFVIS_ERR_INVALID_ARGUMENT;
    if ((double)side + 2.0 * (double)E->R + 3.0 > (double)INT_MAX / 2.0) return HFVIS_ERR_LIMIT;
    /* a radius: sample positions (16 x sub-steps along the raster's lines) must stay exact */
    if (hf_radius_on(o) &&
        16.0 * (2.0 * ((double)o->origin_x + (double)o->origin_y + (double)o->extent_width +
                       (double)o->extent_height + 2.0 * (double)side + 4.0 * (double)E->R) + 4.0) *
                (double)hf_exact_rule_max(E->N) * (double)hf_exact_rule_max(E->N) > 4503599627370496.0)
        return HFVIS_ERR_LIMIT;
    for (k = 0; k < K; k++) {
        hf_ray r = hf_ray_nearest(o->azimuth0_rad + 2.0 * HFVIS__PI * (double)k / (double)K, E->N);
        int p = (r.a < 0 ? -r.a : r.a) + (r.b < 0 ? -r.b : r.b) - 1;
        if (p > maxp) maxp = p;
    }
    gridn = hf_grid_count(g);
    /* a line crosses each grid line once (W + H + 4R of them within reach) and has at most
       W + H + 4R + 2 pieces within reach, each split at most HF_EXACT_MAX_SPLIT - 1 times */
    cap = (size_t)g->width + (size_t)g->height + 4u * (size_t)E->R + 8u +
          ((size_t)g->width + (size_t)g->height + 4u * (size_t)E->R + 2u) * (HF_EXACT_MAX_SPLIT - 1);
    off_ray = hf_align_add(&total, (size_t)K, sizeof(hf_ray), &ok);
    off_d = hf_align_add(&total, (size_t)K * 5u, sizeof(double), &ok);
    off_c = hf_align_add(&total, (size_t)maxp, sizeof(hf_cross), &ok);
    off_s = hf_align_add(&total, cap + 3u, 2u * sizeof(double), &ok); /* + the hull's NaN slots, a sentinel */
    if (want_tan) off_t = hf_align_add(&total, gridn, sizeof(double), &ok);
    if (want_normals && !o->normals) off_n = hf_align_add(&total, gridn, 3u * sizeof(float), &ok);
    if (channels) off_a = hf_align_add(&total, gridn, (size_t)channels * sizeof(double), &ok);
    E->radius = hf_radius_on(o) ? o->max_distance : 0.0;
    E->win_rw = -1;
    E->ox = o->origin_x;
    E->oy = o->origin_y;
    hf_receiver_rect(g, o, &E->rx0, &E->ry0, &E->rx1, &E->ry1);
    E->rect = E->rx0 > 0 || E->ry0 > 0 || E->rx1 < g->width || E->ry1 < g->height;
    if (E->radius > 0.0) off_win = hf_align_add(&total, cap, HF_WIN_BYTES_PER_SAMPLE, &ok);
    off_r = hf_align_add(&total, cap + 1, sizeof(int), &ok);
    E->near = want_tan ? o->ray_near_cells : 0;
    if (E->near > 0) {
        off_fp = hf_align_add(&total, cap + 1, sizeof(int), &ok);
        off_fm = hf_align_add(&total, cap + 1, sizeof(double), &ok);
        off_no = hf_align_add(&total, 2u * (size_t)E->near + 2u * (size_t)maxp + 4u, sizeof(hf_near_off), &ok);
        off_row = hf_align_add(&total, (size_t)g->width, sizeof(double), &ok);
        off_fl = hf_align_add(&total, (size_t)maxp + 2u, sizeof(hf_far_line), &ok);
    }
    if (want_tan) { /* the class of the heights, and whether a plane of twists is read */
        cls = o->exact_grid ? o->exact_grid[gridn] : (double)hf_height_class(g, 0, g->height);
        plane = E->near > 0 || gridn <= (size_t)HFVIS_EXACT_TWIST_PLANE_CELLS;
    }
    if (plane && !o->exact_grid) off_tw = hf_align_add(&total, gridn, sizeof(double), &ok);
    if (want_tan) off_stk = hf_align_add(&total, cap + 2u, 2u * sizeof(double), &ok);
    if (!ok) return HFVIS_ERR_LIMIT;
    blk = (unsigned char *)hfvis__alloc(o->alloc, total);
    if (!blk) return HFVIS_ERR_OUT_OF_MEMORY;
    E->block = blk;
    E->d.ray = (hf_ray *)(void *)(blk + off_ray);
    E->d.w = (double *)(void *)(blk + off_d);
    E->d.lc = E->d.w + K;
    E->d.ls = E->d.lc + K;
    E->d.lo = E->d.ls + K;
    E->d.hi = E->d.lo + K;
    E->cross = (hf_cross *)(void *)(blk + off_c);
    E->sd = (double *)(void *)(blk + off_s) + 2;
    E->sh = E->sd + cap + 3; /* sd[cap]: hf_far_field's sentinel */
    E->sd[-2] = E->sd[-1] = E->sh[-2] = E->sh[-1] = HFVIS__NAN; /* below the stack: hf_hull_step */
    E->tan = want_tan ? (double *)(void *)(blk + off_t) : NULL;
    E->nrm_own = want_normals && !o->normals ? (float *)(void *)(blk + off_n) : NULL;
    E->nrm = want_normals && o->normals ? o->normals : E->nrm_own;
    E->acc = channels ? (double *)(void *)(blk + off_a) : NULL;
    if (E->radius > 0.0) hf_win_carve(&E->win, blk + off_win, cap);
    E->rec = (int *)(void *)(blk + off_r);
    if (E->near > 0) {
        E->fpar = (int *)(void *)(blk + off_fp);
        E->fmax = (double *)(void *)(blk + off_fm);
        E->noff = (hf_near_off *)(void *)(blk + off_no);
        E->row = (double *)(void *)(blk + off_row);
        E->flines = (hf_far_line *)(void *)(blk + off_fl);
    }
    if (want_tan) {
        double *own = plane && !o->exact_grid ? (double *)(void *)(blk + off_tw) : NULL;
        E->twist = !plane ? NULL : o->exact_grid ? o->exact_grid : own; /* NULL: from the heights */
        E->stk = (double *)(void *)(blk + off_stk);
        E->stk[0] = E->stk[1] = E->stk[2] = E->stk[3] = HFVIS__NAN; /* below the stack */
        for (k = 0; own && k < g->height; k++) hf_twist_row(g, k, own + (ptrdiff_t)k * g->width);
        E->finite = cls == 0.0;
        E->inf |= cls == 2.0;
    }
    hf_exact_dirs_fill(&E->d, K, o->azimuth0_rad, E->N);
    if (want_normals == 1 && E->nrm_own) (void)hfvis_normals_compute(g, E->nrm_own); /* as floats */
    if (channels) memset(E->acc, 0, gridn * (size_t)channels * sizeof(double));
    return HFVIS_OK;
}

static void hf_exact_free(hf_exact *E) { hfvis__free(E->alloc, E->block); }

/* The horizon planes of positions [begin, end) (direction_order), as hfvis_horizon_map. */
static hfvis_status hf_exact_horizon_map(const hfvis_grid *g, int K, const hfvis_sweep_options *o,
                                         int begin, int end, float *out)
{
    hf_exact E;
    hfvis_status s;
    size_t plane = hf_grid_count(g), i;
    int k, done = 0, x, y;
    if ((s = hf_exact_init(&E, g, K, o, 1, 0, 0)) != HFVIS_OK) return s;
    for (k = 0; k < K; k++) {
        int pos = hf_direction_position(o, K, k);
        float *p;
        if (pos < begin || pos >= end) continue;
        hf_exact_sweep(&E, E.d.ray[k]);
        p = out + (size_t)(pos - begin) * plane;
        for (y = E.ry0; y < E.ry1; y++)
            for (x = E.rx0; x < E.rx1; x++) {
                i = (size_t)y * (size_t)g->width + (size_t)x;
                p[i] = (float)hf_tan_to_elevation(E.tan[i]);
            }
        hf_progress(o, ++done, end - begin);
    }
    hf_exact_free(&E);
    return HFVIS_OK;
}

static hfvis_status hf_exact_horizon_direction(const hfvis_grid *g, int K, int k,
                                               const hfvis_sweep_options *o, float *out,
                                               ptrdiff_t out_stride)
{
    hf_exact E;
    hfvis_status s;
    int x, y;
    if ((s = hf_exact_init(&E, g, K, o, 1, 0, 0)) != HFVIS_OK) return s;
    hf_exact_sweep(&E, E.d.ray[k]);
    for (y = E.ry0; y < E.ry1; y++)
        for (x = E.rx0; x < E.rx1; x++)
            out[(ptrdiff_t)y * out_stride + x] =
                (float)hf_tan_to_elevation(E.tan[(size_t)y * (size_t)g->width + (size_t)x]);
    hf_exact_free(&E);
    hf_progress(o, 1, 1);
    return HFVIS_OK;
}

/* [P1] Eq. 5 for the uncentred sector of direction k (hf_exact_dirs): nz w sin^2 theta +
 * (nx lc + ny ls)(theta - sin 2theta/2), with the tangent-plane clamp of hf_sky_term taken
 * along the direction itself, (cp, sp) = (cos, sin) of its azimuth. */
static double hf_exact_sky_term(const hf_exact_dirs *d, int k, double cp, double sp, const float *n,
                                double t)
{
    double nx = (double)n[0], ny = (double)n[1], nz = (double)n[2];
    double tc = -(nx * cp + ny * sp) / nz, q, theta;
    if (t > tc) tc = t;
    q = 1.0 / (1.0 + tc * tc);
    theta = HFVIS__HALF_PI - hf_atan(tc);
    return nz * d->w[k] * q + (nx * d->lc[k] + ny * d->ls[k]) * (theta - tc * q);
}

/* Environment tables over the exact sectors (the layouts of hfvis_env_table_build, sector k
 * = [lo_k, hi_k] around the actual azimuth). One block from alloc. */
static hfvis_status hf_exact_env_tables(const hf_exact_dirs *d, const hfvis_env *env,
                                        const hfvis_env_options *eopts,
                                        const hfvis_allocator *alloc, float **table, hf_env_eval *e)
{
    hf_env_resolved r;
    hfvis_status st = hf_env_resolve(env, d->K, eopts, &r);
    float *t;
    int k;
    if (st != HFVIS_OK) return st;
    t = (float *)hfvis__alloc(alloc, r.table_floats * sizeof(float));
    if (t == NULL) return HFVIS_ERR_OUT_OF_MEMORY;
    for (k = 0; k < d->K; k++) {
        hf_env_sector s;
        double st0 = fmod(d->lo[k], 2.0 * HFVIS__PI);
        if (st0 < 0.0) st0 += 2.0 * HFVIS__PI;
        if (st0 >= 2.0 * HFVIS__PI) st0 = 0.0;
        s.start = st0;
        s.width = d->hi[k] - d->lo[k];
        s.centre = st0 + (d->ray[k].azimuth - d->lo[k]);
        if (r.method == HFVIS_ENV_LP_TABLE) {
            size_t per = (size_t)r.lp_normal_res * (size_t)r.lp_horizon_res * (size_t)env->channels;
            hf_env_build_lp_direction(env, &s, r.lp_normal_res, r.lp_horizon_res, t + (size_t)k * per);
        } else {
            size_t per = ((size_t)env->n_theta + 1u) * HF_ENV_PREFIX_RECORD * (size_t)env->channels;
            hf_env_build_prefix_direction(env, &s, t + (size_t)k * per);
        }
    }
    st = hf_env_eval_init(e, env, d->K, eopts, t);
    if (st != HFVIS_OK) {
        hfvis__free(alloc, t);
        return st;
    }
    *table = t;
    return HFVIS_OK;
}

/* The per-receiver direction sums S of hfvis_direction_sums for kind (SKY_VIEW, SKY_LIGHT or
 * ENV_LIGHT) over positions [begin, end), in exact mode: T_k = K w_k sin(max(alpha_k, 0)) for the
 * sky-view factor (so the finish 1 - S/K is unchanged), hf_exact_sky_term for the sky, the
 * environment tables of the exact sectors. On HFVIS_OK E->acc holds S (the caller frees E).
 * With bands (o->part_count > 1) each direction's terms go only to the receivers on its band's
 * lines (hf_exact_span) and are added to the caller's running sums `add` instead (holes NaN);
 * the normals are then made per receiver and direction, as the grid's would be, not for the
 * whole grid. */
static hfvis_status hf_exact_sums(hf_exact *E, const hfvis_grid *g, int K, hfvis_sum_kind kind,
                                  const hfvis_env *env, const hfvis_env_options *eopts,
                                  const hfvis_sweep_options *o, int begin, int end, double *add)
{
    hfvis_status s;
    hf_env_eval eval;
    float *table = NULL;
    int channels = kind == HFVIS_SUM_ENV_LIGHT ? env->channels : 1, k, done = 0, x, y, x0, x1, c;
    const int banded = o->part_count > 1;
    if ((s = hf_exact_init(E, g, K, o, 1, kind == HFVIS_SUM_SKY_VIEW ? 0 : banded ? 2 : 1,
                           banded ? 0 : channels)) != HFVIS_OK)
        return s;
    E->channels = channels;
    if (kind == HFVIS_SUM_ENV_LIGHT &&
        (s = hf_exact_env_tables(&E->d, env, eopts, o->alloc, &table, &eval)) != HFVIS_OK) {
        hf_exact_free(E);
        return s;
    }
    for (k = 0; k < K; k++) {
        int pos = hf_direction_position(o, K, k);
        double wk = (double)K * E->d.w[k];
        double cp = cos(E->d.ray[k].azimuth), sp = sin(E->d.ray[k].azimuth);
        if (pos < begin || pos >= end) continue;
        hf_exact_parts(E, o, E->d.ray[k]);
        hf_exact_sweep(E, E->d.ray[k]);
        for (y = E->ry0; y < E->ry1; y++) { /* the receiver rectangle (band), one loop per kind */
            size_t r = (size_t)y * (size_t)g->width, i;
            const double *tr = E->tan + r;
            double *acc = banded ? add : E->acc, *ar = acc + r * (size_t)channels;
            hf_exact_span(E, y, E->d.ray[k], &x0, &x1);
            for (x = x0; E->nrm_own && banded && x < x1; x++) /* a band's normals, unless given */
                if (!isnan(tr[x])) { /* hfvis_normals_compute's bits */
                    double n[3];
                    float *nr = E->nrm_own + (r + (size_t)x) * 3;
                    hf_normal_at(g, x, y, n);
                    nr[0] = (float)n[0];
                    nr[1] = (float)n[1];
                    nr[2] = (float)n[2];
                }
            /* holes: the sweep's tangent is NaN there (hf_exact_sweep), so a band marks them
               only where the tangent is NaN, in the terms' own loop */
            if (kind == HFVIS_SUM_SKY_VIEW) {
                for (x = x0; x < x1; x++)
                    if (!isnan(tr[x])) ar[x] += wk * hf_svf_term(tr[x]);
                    else if (banded && hf_is_hole(g, x, y)) ar[x] = HFVIS__NAN;
            } else if (kind == HFVIS_SUM_SKY_LIGHT) {
                for (x = x0; x < x1; x++)
                    if (!isnan(tr[x]))
                        ar[x] += hf_exact_sky_term(&E->d, k, cp, sp, E->nrm + (r + (size_t)x) * 3, tr[x]);
                    else if (banded && hf_is_hole(g, x, y)) ar[x] = HFVIS__NAN;
            } else {
                for (x = x0; x < x1; x++) {
                    const float *nr = E->nrm + (r + (size_t)x) * 3;
                    i = r + (size_t)x;
                    if (!isnan(tr[x]))
                        hf_env_accumulate(&eval, k, cp, sp, (double)nr[0], (double)nr[1], (double)nr[2], tr[x],
                                          acc + i * (size_t)channels);
                    else if (banded && hf_is_hole(g, x, y))
                        for (c = 0; c < channels; c++) acc[i * (size_t)channels + (size_t)c] = HFVIS__NAN;
                }
            }
        }
        hf_progress(o, ++done, end - begin);
    }
    hfvis__free(o->alloc, table);
    return HFVIS_OK;
}

/* Finish of the exact sums into out (holes NaN): offset + scale * S per channel. */
static void hf_exact_output(const hf_exact *E, double scale, double offset, float *out,
                            ptrdiff_t out_stride)
{
    const hfvis_grid *g = E->g;
    int x, y, c, ch = E->channels;
    for (y = E->ry0; y < E->ry1; y++)
        for (x = E->rx0; x < E->rx1; x++) {
            const double *a = E->acc + ((size_t)y * (size_t)g->width + (size_t)x) * (size_t)ch;
            float *p = out + ((ptrdiff_t)y * out_stride + x) * ch;
            int hole = hf_is_hole(g, x, y);
            for (c = 0; c < ch; c++) p[c] = (float)(hole ? HFVIS__NAN : offset + scale * a[c]);
        }
}

/* hfvis_sky_light, hfvis_sky_view_factor, hfvis_env_light in exact mode (arguments checked). */
static hfvis_status hf_exact_light(const hfvis_grid *g, int K, hfvis_sum_kind kind,
                                   const hfvis_env *env, const hfvis_env_options *eopts,
                                   const hfvis_sweep_options *o, double scale, float *out,
                                   ptrdiff_t out_stride)
{
    hf_exact E;
    hfvis_status s;
    int begin, end, k;
    double offset = 0.0;
    if ((s = hf_direction_range(o, K, &begin, &end)) != HFVIS_OK) return s;
    if ((s = hf_exact_sums(&E, g, K, kind, env, eopts, o, begin, end, NULL)) != HFVIS_OK) return s;
    if (kind == HFVIS_SUM_SKY_VIEW) /* the range's share of 1 - S/K: its weights, exact */
        for (k = 0; k < K; k++) {
            int pos = hf_direction_position(o, K, k);
            if (pos >= begin && pos < end) offset += E.d.w[k];
        }
    hf_exact_output(&E, scale, offset, out, out_stride);
    hf_exact_free(&E);
    return HFVIS_OK;
}

/* hfvis_sun_visibility in exact mode: one direction, the sun's nearest representable one. A hard
 * sun (radius 0) decides lit (elevation > atan t) without the atan wherever the tangent lies
 * outside [tan(elevation - HF_SUN_TAN_GUARD), tan(elevation + HF_SUN_TAN_GUARD)]: there the
 * angles differ by more than the guard, far beyond atan's and tan's rounding, so the decision is
 * the atan's; inside, the atan decides as before (the same bits). */
#define HF_SUN_TAN_GUARD 1e-9 /* rad: 10^6 ulps of pi/2 */
static hfvis_status hf_exact_sun(const hfvis_grid *g, double azimuth, double elevation,
                                 double radius, const hfvis_sweep_options *o, float *out,
                                 ptrdiff_t out_stride)
{
    hfvis_sweep_options o1 = *o;
    hf_exact E;
    hfvis_status s;
    int x, y, x0, x1;
    const int hard = radius <= 0.0;
    const double t_lo = hard && elevation - HF_SUN_TAN_GUARD > -HFVIS__HALF_PI ? tan(elevation - HF_SUN_TAN_GUARD) : -HFVIS__INF;
    const double t_hi = hard && elevation + HF_SUN_TAN_GUARD < HFVIS__HALF_PI ? tan(elevation + HF_SUN_TAN_GUARD) : HFVIS__INF;
    o1.azimuth0_rad = azimuth;
    if ((s = hf_exact_init(&E, g, 1, &o1, 1, 0, 0)) != HFVIS_OK) return s;
    hf_exact_parts(&E, o, E.d.ray[0]);
    hf_exact_sweep(&E, E.d.ray[0]);
    for (y = E.ry0; y < E.ry1; y++) {
        hf_exact_span(&E, y, E.d.ray[0], &x0, &x1); /* the band's receivers of the row */
        for (x = x0; x < x1; x++) {
            double t = E.tan[(size_t)y * (size_t)g->width + (size_t)x];
            out[(ptrdiff_t)y * out_stride + x] = t < t_lo ? 1.0f : t > t_hi ? 0.0f : /* NaN: the atan */
                (float)hf_sun_fraction(elevation, radius, hf_tan_to_elevation(t));
        }
    }
    hf_exact_free(&E);
    hf_progress(o, 1, 1);
    return HFVIS_OK;
}

hfvis_status hfvis_sweep_azimuths(int K, const hfvis_sweep_options *opts, double *azimuths,
                                  double *weights)
{
    hfvis_sweep_options o = hfvis_sweep_options_default();
    hf_exact_dirs d;
    int k, N;
    if (K < 1 || (!azimuths && !weights) || !hf_opts_valid(opts)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (opts) o = *opts;
    if (o.rays != HFVIS_RAYS_EXACT) {
        for (k = 0; k < K; k++) {
            if (azimuths) azimuths[k] = o.azimuth0_rad + 2.0 * HFVIS__PI * (double)k / (double)K;
            if (weights) weights[k] = 1.0 / (double)K;
        }
        return HFVIS_OK;
    }
    N = hf_exact_bound(&o, K);
    if (N > HFVIS_RAY_DENOMINATOR_MAX) return HFVIS_ERR_INVALID_ARGUMENT;
    if (!weights) { /* no scratch needed */
        for (k = 0; k < K; k++) azimuths[k] = hf_ray_nearest(o.azimuth0_rad + 2.0 * HFVIS__PI * (double)k / (double)K, N).azimuth;
        return HFVIS_OK;
    }
    memset(&d, 0, sizeof d);
    d.ray = (hf_ray *)hfvis__alloc_array(o.alloc, (size_t)K, sizeof(hf_ray) + 5u * sizeof(double));
    if (!d.ray) return HFVIS_ERR_OUT_OF_MEMORY;
    d.w = (double *)(void *)(d.ray + K);
    d.lc = d.w + K;
    d.ls = d.lc + K;
    d.lo = d.ls + K;
    d.hi = d.lo + K;
    hf_exact_dirs_fill(&d, K, o.azimuth0_rad, N);
    for (k = 0; k < K; k++) {
        if (azimuths) azimuths[k] = d.ray[k].azimuth;
        weights[k] = d.w[k];
    }
    hfvis__free(o.alloc, d.ray);
    return HFVIS_OK;
}

hfvis_status hfvis_horizon_exact_naive(const hfvis_grid *grid, int K,
                                       const hfvis_sweep_options *opts, float *out)
{
    hfvis_sweep_options o;
    hf_cross *cr;
    size_t plane, total;
    int N, k, begin, end, x, y, maxp = 1, R, done = 0;
    if (hf_check_common(grid, opts) != HFVIS_OK || !out || K < 1) return HFVIS_ERR_INVALID_ARGUMENT;
    plane = hf_grid_count(grid);
    if (!hfvis__mul_size(plane, (size_t)K, &total)) return HFVIS_ERR_INVALID_ARGUMENT;
    o = hf_opts_resolve(grid, opts);
    if (hf_direction_range(&o, K, &begin, &end) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    N = hf_exact_bound(&o, K);
    R = o.border == HFVIS_BORDER_OPEN ? 0 : o.border_cells;
    if (N > HFVIS_RAY_DENOMINATOR_MAX) return HFVIS_ERR_INVALID_ARGUMENT;
    if ((double)(grid->width > grid->height ? grid->width : grid->height) + 2.0 * (double)R + 3.0 >
        (double)INT_MAX / 2.0)
        return HFVIS_ERR_LIMIT;
    for (k = 0; k < K; k++) {
        hf_ray r = hf_ray_nearest(o.azimuth0_rad + 2.0 * HFVIS__PI * (double)k / (double)K, N);
        int p = (r.a < 0 ? -r.a : r.a) + (r.b < 0 ? -r.b : r.b) - 1;
        if (p > maxp) maxp = p;
    }
    cr = (hf_cross *)hfvis__alloc_array(o.alloc, (size_t)maxp, sizeof(hf_cross));
    if (!cr) return HFVIS_ERR_OUT_OF_MEMORY;
    for (k = 0; k < K; k++) {
        int pos = hf_direction_position(&o, K, k), P;
        hf_ray r = hf_ray_nearest(o.azimuth0_rad + 2.0 * HFVIS__PI * (double)k / (double)K, N);
        double L, scale;
        float *p;
        if (pos < begin || pos >= end) continue;
        P = hf_exact_geometry(cr, grid, r.a, r.b, &L, &scale);
        p = out + (size_t)(pos - begin) * plane;
        for (y = 0; y < grid->height; y++)
            for (x = 0; x < grid->width; x++)
                p[(size_t)y * (size_t)grid->width + (size_t)x] = (float)hf_tan_to_elevation(
                    hf_exact_march(grid, o.border, R, cr, P, L, scale, r.a, r.b, x, y,
                                   hf_radius_on(&o) ? hf_exact_window(o.max_distance, scale) : -1));
        hf_progress(&o, ++done, end - begin);
    }
    hfvis__free(o.alloc, cr);
    return HFVIS_OK;
}

static hfvis_status hf_exact_direction_sums(const hfvis_grid *g, int K, hfvis_sum_kind kind,
                                            const hfvis_env *env, const hfvis_env_options *eopts,
                                            const hfvis_sweep_options *o, int begin, int end,
                                            double *sums)
{
    hf_exact E;
    hfvis_status s;
    int x, y, c;
    if ((s = hf_exact_sums(&E, g, K, kind, env, eopts, o, begin, end, sums)) != HFVIS_OK) return s;
    for (y = E.ry0; o->part_count <= 1 && y < E.ry1; y++) /* bands added to sums in place */
        for (x = E.rx0; x < E.rx1; x++) {
            size_t i = ((size_t)y * (size_t)g->width + (size_t)x) * (size_t)E.channels;
            int hole = hf_is_hole(g, x, y);
            for (c = 0; c < E.channels; c++) sums[i + (size_t)c] = hole ? HFVIS__NAN : E.acc[i + (size_t)c];
        }
    hf_exact_free(&E);
    return HFVIS_OK;
}

/* ========================================================================================== */
/* 17. Solar radiation                                                                        */
/* ========================================================================================== */
/* NREL's SPA (Reda & Andreas 2004/2008), r.sun's solar geometry and its ESRA clear sky
 * (Suri & Hofierka 2004; Rigollier et al. 2000), integrated over time over the exact-ray
 * horizon map of section 16, and its oracle. Errata and choices: docs/solar.md. */

/* ------------------------------------------------- 1. SPA: periodic terms (Tables A4.2-A4.3) */
/* Earth periodic terms A_i cos(B_i + C_i JME) of VSOP87 as SPA truncates them (Table A4.2), the
 * series L0..L5, B0..B1, R0..R4 one after another. */
static const double hf_spa_terms[][3] = {
    {175347046.0, 0, 0}, {3341656.0, 4.6692568, 6283.07585}, {34894.0, 4.6261, 12566.1517},
    {3497.0, 2.7441, 5753.3849}, {3418.0, 2.8289, 3.5231}, {3136.0, 3.6277, 77713.7715},
    {2676.0, 4.4181, 7860.4194}, {2343.0, 6.1352, 3930.2097}, {1324.0, 0.7425, 11506.7698},
    {1273.0, 2.0371, 529.691}, {1199.0, 1.1096, 1577.3435}, {990, 5.233, 5884.927},
    {902, 2.045, 26.298}, {857, 3.508, 398.149}, {780, 1.179, 5223.694}, {753, 2.533, 5507.553},
    {505, 4.583, 18849.228}, {492, 4.205, 775.523}, {357, 2.92, 0.067}, {317, 5.849, 11790.629},
    {284, 1.899, 796.298}, {271, 0.315, 10977.079}, {243, 0.345, 5486.778}, {206, 4.806, 2544.314},
    {205, 1.869, 5573.143}, {202, 2.458, 6069.777}, {156, 0.833, 213.299}, {132, 3.411, 2942.463},
    {126, 1.083, 20.775}, {115, 0.645, 0.98}, {103, 0.636, 4694.003}, {102, 0.976, 15720.839},
    {102, 4.267, 7.114}, {99, 6.21, 2146.17}, {98, 0.68, 155.42}, {86, 5.98, 161000.69},
    {85, 1.3, 6275.96}, {85, 3.67, 71430.7}, {80, 1.81, 17260.15}, {79, 3.04, 12036.46},
    {75, 1.76, 5088.63}, {74, 3.5, 3154.69}, {74, 4.68, 801.82}, {70, 0.83, 9437.76},
    {62, 3.98, 8827.39}, {61, 1.82, 7084.9}, {57, 2.78, 6286.6}, {56, 4.39, 14143.5},
    {56, 3.47, 6279.55}, {52, 0.19, 12139.55}, {52, 1.33, 1748.02}, {51, 0.28, 5856.48},
    {49, 0.49, 1194.45}, {41, 5.37, 8429.24}, {41, 2.4, 19651.05}, {39, 6.17, 10447.39},
    {37, 6.04, 10213.29}, {37, 2.57, 1059.38}, {36, 1.71, 2352.87}, {36, 1.78, 6812.77},
    {33, 0.59, 17789.85}, {30, 0.44, 83996.85}, {30, 2.74, 1349.87}, {25, 3.16, 4690.48},
    {628331966747.0, 0, 0}, {206059.0, 2.678235, 6283.07585}, {4303.0, 2.6351, 12566.1517},
    {425.0, 1.59, 3.523}, {119.0, 5.796, 26.298}, {109.0, 2.966, 1577.344}, {93, 2.59, 18849.23},
    {72, 1.14, 529.69}, {68, 1.87, 398.15}, {67, 4.41, 5507.55}, {59, 2.89, 5223.69},
    {56, 2.17, 155.42}, {45, 0.4, 796.3}, {36, 0.47, 775.52}, {29, 2.65, 7.11}, {21, 5.34, 0.98},
    {19, 1.85, 5486.78}, {19, 4.97, 213.3}, {17, 2.99, 6275.96}, {16, 0.03, 2544.31},
    {16, 1.43, 2146.17}, {15, 1.21, 10977.08}, {12, 2.83, 1748.02}, {12, 3.26, 5088.63},
    {12, 5.27, 1194.45}, {12, 2.08, 4694}, {11, 0.77, 553.57}, {10, 1.3, 6286.6},
    {10, 4.24, 1349.87}, {9, 2.7, 242.73}, {9, 5.64, 951.72}, {8, 5.3, 2352.87},
    {6, 2.65, 9437.76}, {6, 4.67, 4690.48}, {52919.0, 0, 0}, {8720.0, 1.0721, 6283.0758},
    {309.0, 0.867, 12566.152}, {27, 0.05, 3.52}, {16, 5.19, 26.3}, {16, 3.68, 155.42},
    {10, 0.76, 18849.23}, {9, 2.06, 77713.77}, {7, 0.83, 775.52}, {5, 4.66, 1577.34},
    {4, 1.03, 7.11}, {4, 3.44, 5573.14}, {3, 5.14, 796.3}, {3, 6.05, 5507.55}, {3, 1.19, 242.73},
    {3, 6.12, 529.69}, {3, 0.31, 398.15}, {3, 2.28, 553.57}, {2, 4.38, 5223.69}, {2, 3.75, 0.98},
    {289.0, 5.844, 6283.076}, {35, 0, 0}, {17, 5.49, 12566.15}, {3, 5.2, 155.42}, {1, 4.72, 3.52},
    {1, 5.3, 18849.23}, {1, 5.97, 242.73}, {114.0, 3.142, 0}, {8, 4.13, 6283.08},
    {1, 3.84, 12566.15}, {1, 3.14, 0}, {280.0, 3.199, 84334.662}, {102.0, 5.422, 5507.553},
    {80, 3.88, 5223.69}, {44, 3.7, 2352.87}, {32, 4, 1577.34}, {9, 3.9, 5507.55},
    {6, 1.73, 5223.69}, {100013989.0, 0, 0}, {1670700.0, 3.0984635, 6283.07585},
    {13956.0, 3.05525, 12566.1517}, {3084.0, 5.1985, 77713.7715}, {1628.0, 1.1739, 5753.3849},
    {1576.0, 2.8469, 7860.4194}, {925.0, 5.453, 11506.77}, {542.0, 4.564, 3930.21},
    {472.0, 3.661, 5884.927}, {346.0, 0.964, 5507.553}, {329.0, 5.9, 5223.694},
    {307.0, 0.299, 5573.143}, {243.0, 4.273, 11790.629}, {212.0, 5.847, 1577.344},
    {186.0, 5.022, 10977.079}, {175.0, 3.012, 18849.228}, {110.0, 5.055, 5486.778},
    {98, 0.89, 6069.78}, {86, 5.69, 15720.84}, {86, 1.27, 161000.69}, {65, 0.27, 17260.15},
    {63, 0.92, 529.69}, {57, 2.01, 83996.85}, {56, 5.24, 71430.7}, {49, 3.25, 2544.31},
    {47, 2.58, 775.52}, {45, 5.54, 9437.76}, {43, 6.01, 6275.96}, {39, 5.36, 4694},
    {38, 2.39, 8827.39}, {37, 0.83, 19651.05}, {37, 4.9, 12139.55}, {36, 1.67, 12036.46},
    {35, 1.84, 2942.46}, {33, 0.24, 7084.9}, {32, 0.18, 5088.63}, {32, 1.78, 398.15},
    {28, 1.21, 6286.6}, {28, 1.9, 6279.55}, {26, 4.59, 10447.39}, {103019.0, 1.10749, 6283.07585},
    {1721.0, 1.0644, 12566.1517}, {702.0, 3.142, 0}, {32, 1.02, 18849.23}, {31, 2.84, 5507.55},
    {25, 1.32, 5223.69}, {18, 1.42, 1577.34}, {10, 5.91, 10977.08}, {9, 1.42, 6275.96},
    {9, 0.27, 5486.78}, {4359.0, 5.7846, 6283.0758}, {124.0, 5.579, 12566.152}, {12, 3.14, 0},
    {9, 3.63, 77713.77}, {6, 1.87, 5573.14}, {3, 5.47, 18849.23}, {145.0, 4.273, 6283.076},
    {7, 3.92, 12566.15}, {4, 2.56, 6283.08}
};
/* rows of L0..L5, B0..B1, R0..R4 in hf_spa_terms */
static const short hf_spa_series[14] = {0, 64, 98, 118, 125, 128, 129, 134, 136, 176, 186, 192, 194, 195};
static const double hf_spa_nutation[63][9] = {
    {0, 0, 0, 0, 1, -171996, -174.2, 92025, 8.9}, {-2, 0, 0, 2, 2, -13187, -1.6, 5736, -3.1},
    {0, 0, 0, 2, 2, -2274, -0.2, 977, -0.5}, {0, 0, 0, 0, 2, 2062, 0.2, -895, 0.5},
    {0, 1, 0, 0, 0, 1426, -3.4, 54, -0.1}, {0, 0, 1, 0, 0, 712, 0.1, -7, 0},
    {-2, 1, 0, 2, 2, -517, 1.2, 224, -0.6}, {0, 0, 0, 2, 1, -386, -0.4, 200, 0},
    {0, 0, 1, 2, 2, -301, 0, 129, -0.1}, {-2, -1, 0, 2, 2, 217, -0.5, -95, 0.3},
    {-2, 0, 1, 0, 0, -158, 0, 0, 0}, {-2, 0, 0, 2, 1, 129, 0.1, -70, 0},
    {0, 0, -1, 2, 2, 123, 0, -53, 0}, {2, 0, 0, 0, 0, 63, 0, 0, 0},
    {0, 0, 1, 0, 1, 63, 0.1, -33, 0}, {2, 0, -1, 2, 2, -59, 0, 26, 0},
    {0, 0, -1, 0, 1, -58, -0.1, 32, 0}, {0, 0, 1, 2, 1, -51, 0, 27, 0},
    {-2, 0, 2, 0, 0, 48, 0, 0, 0}, {0, 0, -2, 2, 1, 46, 0, -24, 0}, {2, 0, 0, 2, 2, -38, 0, 16, 0},
    {0, 0, 2, 2, 2, -31, 0, 13, 0}, {0, 0, 2, 0, 0, 29, 0, 0, 0}, {-2, 0, 1, 2, 2, 29, 0, -12, 0},
    {0, 0, 0, 2, 0, 26, 0, 0, 0}, {-2, 0, 0, 2, 0, -22, 0, 0, 0}, {0, 0, -1, 2, 1, 21, 0, -10, 0},
    {0, 2, 0, 0, 0, 17, -0.1, 0, 0}, {2, 0, -1, 0, 1, 16, 0, -8, 0},
    {-2, 2, 0, 2, 2, -16, 0.1, 7, 0}, {0, 1, 0, 0, 1, -15, 0, 9, 0},
    {-2, 0, 1, 0, 1, -13, 0, 7, 0}, {0, -1, 0, 0, 1, -12, 0, 6, 0}, {0, 0, 2, -2, 0, 11, 0, 0, 0},
    {2, 0, -1, 2, 1, -10, 0, 5, 0}, {2, 0, 1, 2, 2, -8, 0, 3, 0}, {0, 1, 0, 2, 2, 7, 0, -3, 0},
    {-2, 1, 1, 0, 0, -7, 0, 0, 0}, {0, -1, 0, 2, 2, -7, 0, 3, 0}, {2, 0, 0, 2, 1, -7, 0, 3, 0},
    {2, 0, 1, 0, 0, 6, 0, 0, 0}, {-2, 0, 2, 2, 2, 6, 0, -3, 0}, {-2, 0, 1, 2, 1, 6, 0, -3, 0},
    {2, 0, -2, 0, 1, -6, 0, 3, 0}, {2, 0, 0, 0, 1, -6, 0, 3, 0}, {0, -1, 1, 0, 0, 5, 0, 0, 0},
    {-2, -1, 0, 2, 1, -5, 0, 3, 0}, {-2, 0, 0, 0, 1, -5, 0, 3, 0}, {0, 0, 2, 2, 1, -5, 0, 3, 0},
    {-2, 0, 2, 0, 1, 4, 0, 0, 0}, {-2, 1, 0, 2, 1, 4, 0, 0, 0}, {0, 0, 1, -2, 0, 4, 0, 0, 0},
    {-1, 0, 1, 0, 0, -4, 0, 0, 0}, {-2, 1, 0, 0, 0, -4, 0, 0, 0}, {1, 0, 0, 0, 0, -4, 0, 0, 0},
    {0, 0, 1, 2, 0, 3, 0, 0, 0}, {0, 0, -2, 2, 2, -3, 0, 0, 0}, {-1, -1, 1, 0, 0, -3, 0, 0, 0},
    {0, 1, 1, 0, 0, -3, 0, 0, 0}, {0, -1, 1, 2, 2, -3, 0, 0, 0}, {2, -1, -1, 2, 2, -3, 0, 0, 0},
    {0, 0, 3, 2, 2, -3, 0, 0, 0}, {2, -1, 0, 2, 2, -3, 0, 0, 0}
};

/* ---------------------------------------------------------------------- 2. SPA: the steps */
#define HF_DEG (HFVIS__PI / 180.0)

/* x mod 360 in [0, 360). */
static double hf_deg360(double x)
{
    double r = fmod(x, 360.0);
    return r < 0.0 ? r + 360.0 : r;
}

/* Sum of series s of the terms (Eq. 9): sum_i A_i cos(B_i + C_i jme). */
static double hf_spa_series_sum(int s, double jme)
{
    double sum = 0.0;
    int i;
    for (i = hf_spa_series[s]; i < hf_spa_series[s + 1]; i++)
        sum += hf_spa_terms[i][0] * cos(hf_spa_terms[i][1] + hf_spa_terms[i][2] * jme);
    return sum;
}

/* One of L, B, R (Eq. 10-11): (X0 + X1 jme + X2 jme^2 + ...)/1e8 over series [first, first+n). */
static double hf_spa_poly(int first, int n, double jme)
{
    double sum = 0.0;
    int i;
    for (i = n - 1; i >= 0; i--) sum = sum * jme + hf_spa_series_sum(first + i, jme);
    return sum / 1e8;
}

/* Days in a month of the proleptic calendar SPA uses (Julian before 1582-10-15). */
static int hf_month_days(int year, int month)
{
    static const int d[12] = { 31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31 };
    int leap;
    if (month == 2) {
        leap = year > 1582 ? ((year % 4 == 0 && year % 100 != 0) || year % 400 == 0) : (year % 4 == 0);
        return 28 + leap;
    }
    return d[month - 1];
}

/* The Julian day of a calendar date and a day fraction (SPA Eq. 4, Meeus 1998 Eq. 7.1). */
static double hf_julian_day(int year, int month, double day)
{
    double y = (double)year, m = (double)month, b = 0.0, jd;
    if (month < 3) {
        y -= 1.0;
        m += 12.0;
    }
    jd = floor(365.25 * (y + 4716.0)) + floor(30.6001 * (m + 1.0)) + day - 1524.5;
    if (jd > 2299160.0) {
        double a = floor(y / 100.0);
        b = 2.0 - a + floor(a / 4.0);
    }
    return jd + b;
}

/* The instant's part of SPA (everything before the observer's place): Eq. 4-31 and the
 * equatorial horizontal parallax (Eq. 33). Angles in degrees here, as the paper's equations. */
typedef struct hf_spa_sun {
    double jd, jde, L, B, R, dpsi, deps, eps, lambda, nu, alpha, delta, xi;
} hf_spa_sun;

static void hf_spa_instant(double jd, double delta_t, hf_spa_sun *s)
{
    double jc, jce, jme, x[5], theta, beta, u, eps0, nu0, lr, er, br;
    int i, j;
    s->jd = jd;
    s->jde = jd + delta_t / 86400.0;
    jc = (jd - 2451545.0) / 36525.0;
    jce = (s->jde - 2451545.0) / 36525.0;
    jme = jce / 10.0;
    s->L = hf_deg360(hf_spa_poly(0, 6, jme) / HF_DEG);
    s->B = hf_spa_poly(6, 2, jme) / HF_DEG;
    s->R = hf_spa_poly(8, 5, jme);
    theta = hf_deg360(s->L + 180.0);                         /* Eq. 13-14 */
    beta = -s->B;
    /* Nutation (Eq. 15-23): mean elongation of the moon, anomalies, argument of latitude and
     * the longitude of the ascending node, each a cubic in JCE. */
    x[0] = 297.85036 + jce * (445267.111480 + jce * (-0.0019142 + jce / 189474.0));
    x[1] = 357.52772 + jce * (35999.050340 + jce * (-0.0001603 - jce / 300000.0));
    x[2] = 134.96298 + jce * (477198.867398 + jce * (0.0086972 + jce / 56250.0));
    x[3] = 93.27191 + jce * (483202.017538 + jce * (-0.0036825 + jce / 327270.0));
    x[4] = 125.04452 + jce * (-1934.136261 + jce * (0.0020708 + jce / 450000.0));
    s->dpsi = 0.0;
    s->deps = 0.0;
    for (i = 0; i < 63; i++) {
        const double *t = hf_spa_nutation[i];
        double arg = 0.0;
        for (j = 0; j < 5; j++) arg += x[j] * t[j];
        arg *= HF_DEG;
        s->dpsi += (t[5] + t[6] * jce) * sin(arg);
        s->deps += (t[7] + t[8] * jce) * cos(arg);
    }
    s->dpsi /= 36000000.0;
    s->deps /= 36000000.0;
    u = jme / 10.0;                                          /* Eq. 24, arc seconds */
    eps0 = 84381.448 + u * (-4680.93 + u * (-1.55 + u * (1999.25 + u * (-51.38 + u * (-249.67 +
           u * (-39.05 + u * (7.12 + u * (27.87 + u * (5.79 + u * 2.45)))))))));
    s->eps = eps0 / 3600.0 + s->deps;                        /* Eq. 25 */
    s->lambda = theta + s->dpsi - 20.4898 / (3600.0 * s->R); /* Eq. 26-27 */
    nu0 = hf_deg360(280.46061837 + 360.98564736629 * (jd - 2451545.0) +
                    jc * jc * (0.000387933 - jc / 38710000.0));  /* Eq. 28 */
    er = s->eps * HF_DEG;
    s->nu = nu0 + s->dpsi * cos(er);                         /* Eq. 29 */
    lr = s->lambda * HF_DEG;
    br = beta * HF_DEG;
    s->alpha = hf_deg360(atan2(sin(lr) * cos(er) - tan(br) * sin(er), cos(lr)) / HF_DEG); /* Eq. 30 */
    s->delta = asin(sin(br) * cos(er) + cos(br) * sin(er) * sin(lr)) / HF_DEG;              /* Eq. 31 */
    s->xi = 8.794 / (3600.0 * s->R);                         /* Eq. 33 */
}

/* The observer's part (Eq. 32-46): topocentric position, optional refraction. lat, lon in
 * degrees, elevation in metres. */
typedef struct hf_spa_place {
    double H, delta_p, H_p, e0, e, zenith, azimuth;
} hf_spa_place;

static void hf_spa_at(const hf_spa_sun *s, double lat, double lon, double elev, int refraction,
                      double pressure, double temperature, double atmos_refract,
                      hf_spa_place *p)
{
    double H, phi = lat * HF_DEG, u, x, y, xi = s->xi * HF_DEG, d = s->delta * HF_DEG, hr, da,
           dp, hp, e0, gamma;
    H = hf_deg360(s->nu + lon - s->alpha);                  /* Eq. 32 */
    hr = H * HF_DEG;
    u = atan(0.99664719 * tan(phi));                         /* Eq. 34-36 */
    x = cos(u) + elev / 6378140.0 * cos(phi);
    y = 0.99664719 * sin(u) + elev / 6378140.0 * sin(phi);
    da = atan2(-x * sin(xi) * sin(hr), cos(d) - x * sin(xi) * cos(hr));        /* Eq. 37 */
    dp = atan2((sin(d) - y * sin(xi)) * cos(da), cos(d) - x * sin(xi) * cos(hr)); /* Eq. 38 */
    hp = hr - da;                                            /* Eq. 40 */
    e0 = asin(sin(phi) * sin(dp) + cos(phi) * cos(dp) * cos(hp)) / HF_DEG;     /* Eq. 41 */
    p->H = H;
    p->delta_p = dp / HF_DEG;
    p->H_p = hp / HF_DEG;
    p->e0 = e0;
    p->e = e0;
    if (refraction && e0 >= -(0.26667 + atmos_refract))    /* Eq. 42-43 */
        p->e = e0 + pressure / 1010.0 * 283.0 / (273.0 + temperature) * 1.02 /
                        (60.0 * tan((e0 + 10.3 / (e0 + 5.11)) * HF_DEG));
    p->zenith = 90.0 - p->e;                                 /* Eq. 44 */
    gamma = atan2(sin(hp), cos(hp) * sin(phi) - tan(dp) * cos(phi)) / HF_DEG;   /* Eq. 45 */
    p->azimuth = hf_deg360(gamma + 180.0);                   /* Eq. 46 */
}

static int hf_in(double v, double lo, double hi) { return v >= lo && v <= hi; }

static int hf_date_valid(int year, int month, int day)
{
    if (year < -2000 || year > 6000 || month < 1 || month > 12 || day < 1) return 0;
    if (year == 1582 && month == 10 && day > 4 && day < 15) return 0; /* the calendar reform */
    return day <= hf_month_days(year, month);
}

hfvis_status hfvis_spa(const hfvis_spa_input *in, hfvis_spa_result *out)
{
    hf_spa_sun s;
    hf_spa_place p;
    double jd;
    if (!in || !out || !hf_date_valid(in->year, in->month, in->day) || in->hour < 0 ||
        in->hour > 24 || in->minute < 0 || in->minute > 59 || !hf_in(in->second, 0.0, 60.0) ||
        (in->hour == 24 && (in->minute != 0 || in->second != 0.0)) ||
        !(fabs(in->delta_ut1) < 1.0) || !hf_in(in->delta_t, -8000.0, 8000.0) ||
        !hf_in(in->latitude_rad, -HFVIS__HALF_PI, HFVIS__HALF_PI) ||
        !hf_in(in->longitude_rad, -HFVIS__PI, HFVIS__PI) || !(in->elevation_m >= -6500000.0) ||
        !isfinite(in->elevation_m) || (in->refraction != 0 && in->refraction != 1) ||
        (in->refraction && (!(in->pressure_mbar > 0.0 && in->pressure_mbar <= 5000.0) ||
                            !(in->temperature_c > -273.0 && in->temperature_c <= 6000.0) ||
                            !hf_in(in->atmos_refract_rad, 0.0, 0.1))))
        return HFVIS_ERR_INVALID_ARGUMENT;
    jd = hf_julian_day(in->year, in->month,
                       (double)in->day + ((double)in->hour + ((double)in->minute +
                       (in->second + in->delta_ut1) / 60.0) / 60.0) / 24.0);
    hf_spa_instant(jd, in->delta_t, &s);
    hf_spa_at(&s, in->latitude_rad / HF_DEG, in->longitude_rad / HF_DEG, in->elevation_m,
              in->refraction, in->pressure_mbar, in->temperature_c, in->atmos_refract_rad / HF_DEG,
              &p);
    out->jd = s.jd;
    out->jde = s.jde;
    out->helio_longitude = s.L * HF_DEG;
    out->helio_latitude = s.B * HF_DEG;
    out->radius_au = s.R;
    out->nutation_longitude = s.dpsi * HF_DEG;
    out->nutation_obliquity = s.deps * HF_DEG;
    out->obliquity = s.eps * HF_DEG;
    out->apparent_longitude = hf_deg360(s.lambda) * HF_DEG;
    out->sidereal_time = hf_deg360(s.nu) * HF_DEG;
    out->right_ascension = s.alpha * HF_DEG;
    out->declination = s.delta * HF_DEG;
    out->hour_angle = p.H * HF_DEG;
    out->topo_declination = p.delta_p * HF_DEG;
    out->topo_hour_angle = p.H_p * HF_DEG;
    out->elevation = p.e * HF_DEG;
    out->zenith = p.zenith * HF_DEG;
    out->azimuth = p.azimuth * HF_DEG;
    return HFVIS_OK;
}

/* ------------------------------------------------- 3. r.sun's solar geometry and ESRA sky */
static double hf_rsun_day_angle(int day) { return 2.0 * HFVIS__PI * (double)day / 365.25; }

hfvis_status hfvis_rsun_sun_position(int day, double solar_hour, double latitude_rad,
                                     hfvis_rsun_sun *out)
{
    double d, dec, w, sl, cl, sd, cd, sh, east, north, c;
    if (!out || day < 1 || day > 366 || !isfinite(solar_hour) ||
        !hf_in(latitude_rad, -HFVIS__HALF_PI, HFVIS__HALF_PI))
        return HFVIS_ERR_INVALID_ARGUMENT;
    d = hf_rsun_day_angle(day);
    dec = asin(0.3978 * sin(d - 1.4 + 0.0355 * sin(d - 0.0489)));
    w = (solar_hour - 12.0) * (HFVIS__PI / 12.0);
    sl = sin(latitude_rad);
    cl = cos(latitude_rad);
    sd = sin(dec);
    cd = cos(dec);
    sh = cl * cd * cos(w) + sl * sd;
    east = -cd * sin(w);
    north = cl * sd - sl * cd * cos(w);
    out->declination = dec;
    out->hour_angle = w;
    out->elevation = asin(sh > 1.0 ? 1.0 : sh < -1.0 ? -1.0 : sh);
    out->azimuth = atan2(east, north);
    if (out->azimuth < 0.0) out->azimuth += 2.0 * HFVIS__PI;
    out->extraterrestrial = 1367.0 * (1.0 + 0.03344 * cos(d - 0.048869));
    /* cos(w0) = -tan(lat) tan(dec) at sunrise (true elevation 0), r.sun's com_par_const */
    c = cl * cd > 1e-12 ? -(sl * sd) / (cl * cd) : (sl * sd > 0.0 ? -2.0 : 2.0);
    if (c < -1.0) {
        out->sunrise_hour = 0.0;
        out->sunset_hour = 24.0;
    } else if (c > 1.0) {
        out->sunrise_hour = 12.0;
        out->sunset_hour = 12.0;
    } else {
        double h = acos(c) * 12.0 / HFVIS__PI;
        out->sunrise_hour = 12.0 - h;
        out->sunset_hour = 12.0 + h;
    }
    return HFVIS_OK;
}

/* ESRA relative optical air mass at true elevation h (rad) and pressure ratio p: the elevation
 * refracted by ESRA's fit, then Kasten & Young 1989 (Rigollier et al. 2000 Eq. 3-5). */
static double hf_esra_air_mass(double h, double p)
{
    double dr = 0.061359 * (0.1594 + h * (1.123 + 0.065656 * h)) / (1.0 + h * (28.9344 + 277.3971 * h));
    double hr = h + dr;
    return p / (sin(hr) + 0.50572 * pow(hr / HF_DEG + 6.07995, -1.6364));
}

/* Rayleigh optical thickness at air mass m (Kasten 1996 as ESRA fits it, Eq. 6-7). */
static double hf_esra_rayleigh(double m)
{
    if (m <= 20.0)
        return 1.0 / (6.6296 + m * (1.7513 + m * (-0.1202 + m * (0.0065 - m * 0.00013))));
    return 1.0 / (10.4 + 0.718 * m);
}

/* Beam normal transmittance exp(-0.8662 TL m dR(m)) at air mass m (Eq. 2). */
static double hf_esra_beam_trans_m(double m, double linke)
{
    return exp(-0.8662 * linke * m * hf_esra_rayleigh(m));
}

/* The same at true elevation h and pressure ratio p. */
static double hf_esra_beam_trans(double h, double p, double linke)
{
    return hf_esra_beam_trans_m(hf_esra_air_mass(h, p), linke);
}

/* Muneer's model (r.sun's drad): the sky-brightness part of the background diffuse per unit F_g,
 * (0.00263 - 0.712 kb - 0.6883 kb^2)(1 - kb), and the low-sun circumsolar divisor. */
static double hf_muneer_fg_part(double kb) { return (0.00263 - kb * (0.712 + 0.6883 * kb)) * (1.0 - kb); }
static double hf_muneer_low_sun(double h) { return 0.1 - 0.008 * h; }

/* Diffuse transmission Tn(TL) times the angular function Fd(h) (Eq. 10-14): dh = G0 Tn Fd. */
static double hf_esra_diffuse_factor(double sinh, double linke)
{
    double tn = -0.015843 + linke * (0.030543 + 0.0003797 * linke);
    double a1 = 0.26463 + linke * (-0.061581 + 0.0031408 * linke);
    double a2 = 2.04020 + linke * (0.018945 - 0.011161 * linke);
    double a3 = -1.3025 + linke * (0.039231 + 0.0085079 * linke);
    if (a1 * tn < 0.0022) a1 = 0.0022 / tn;
    return tn * (a1 + a2 * sinh + a3 * sinh * sinh);
}

/* Pressure ratio of a height (ESRA's scale height 8434.5 m). */
static double hf_esra_pressure(double height_m) { return exp(-height_m / 8434.5); }

hfvis_status hfvis_esra_clear_sky(double g0, double elevation_rad, double height_m, double linke,
                                  double out[3])
{
    double sh;
    if (!out || !(g0 >= 0.0) || !isfinite(g0) || !hf_in(elevation_rad, -HFVIS__HALF_PI, HFVIS__HALF_PI) ||
        !isfinite(height_m) || !(linke > 0.0 && linke <= 10.0))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (!(elevation_rad > 0.0)) {
        out[0] = out[1] = out[2] = 0.0;
        return HFVIS_OK;
    }
    sh = sin(elevation_rad);
    out[0] = g0 * hf_esra_beam_trans(elevation_rad, hf_esra_pressure(height_m), linke);
    out[1] = out[0] * sh;
    out[2] = g0 * hf_esra_diffuse_factor(sh, linke);
    return HFVIS_OK;
}

/* ------------------------------------------------------------- 4. inputs, options, steps */
#define HF_SOLAR_STEP_DEFAULT 0.25    /* hours: 15 minutes */
#define HF_SOLAR_K_DEFAULT 64         /* directions of the horizon map */
#define HF_SOLAR_KR_DEFAULT 16        /* directions of the TERRAIN gather */
#define HF_SOLAR_DELTA_T_DEFAULT 69.0 /* s, TT - UT1 around 2020-2030 */
#define HF_SOLAR_DAYS_MAX 36600       /* a century of days */
#define HF_SOLAR_K_MAX 4096
#define HF_SOLAR_BISECTIONS 40        /* sunrise to 24 h / 2^40: far below a second */
#define HF_SOLAR_SLOPE_FLAT 1e-9      /* rad: below this a receiver is horizontal (r.sun's
                                         slope != 0 test, robust to float normals) */
#define HF_SOLAR_REFRACT_P 1013.25    /* mbar and deg C of the refraction option: the */
#define HF_SOLAR_REFRACT_T 10.0       /* standard atmosphere SPA's example assumes */
#define HF_SOLAR_REFRACT_SUNRISE 0.5667 /* deg */
#define HF_SOLAR_SITE_TOL_DEFAULT (0.05 * HF_DEG) /* rad: per-sample sites share the sun of a
                                         block centre within this rotation of their frames */

hfvis_solar_input hfvis_solar_input_default(void)
{
    hfvis_solar_input in;
    memset(&in, 0, sizeof in);
    in.year = 2026;
    in.month = 6;
    in.day = 21;
    in.days = 1;
    in.linke = 3.0;
    in.albedo = 0.2;
    return in;
}

hfvis_solar_options hfvis_solar_options_default(void)
{
    hfvis_solar_options o;
    memset(&o, 0, sizeof o);
    o.model = HFVIS_SUN_SPA;
    o.step_hours = HF_SOLAR_STEP_DEFAULT;
    o.directions = HF_SOLAR_K_DEFAULT;
    o.delta_t = HF_SOLAR_DELTA_T_DEFAULT;
    o.reflected_directions = HF_SOLAR_KR_DEFAULT;
    o.site_tolerance_rad = HF_SOLAR_SITE_TOL_DEFAULT;
    return o;
}

/* The date n days after (y, m, d). */
static void hf_date_add(int *y, int *m, int *d, int n)
{
    while (n-- > 0) {
        if (++*d > hf_month_days(*y, *m)) {
            *d = 1;
            if (++*m > 12) {
                *m = 1;
                ++*y;
            }
        }
    }
}

static int hf_day_of_year(int y, int m, int d)
{
    int k, n = d;
    for (k = 1; k < m; k++) n += hf_month_days(y, k);
    return n;
}

static int hf_solar_input_valid(const hfvis_solar_input *in)
{
    return in && hf_in(in->latitude_rad, -HFVIS__HALF_PI, HFVIS__HALF_PI) &&
           hf_in(in->longitude_rad, -HFVIS__PI, HFVIS__PI) && isfinite(in->height_m) &&
           in->height_m >= -6500000.0 && hf_date_valid(in->year, in->month, in->day) &&
           (in->instant == 0 || in->instant == 1) &&
           (in->instant ? hf_in(in->hour, 0.0, 24.0) : (in->days >= 1 && in->days <= HF_SOLAR_DAYS_MAX)) &&
           hf_in(in->utc_offset_hours, -14.0, 14.0) && in->linke > 0.0 && in->linke <= 10.0 &&
           hf_in(in->albedo, 0.0, 1.0) && (in->latitude_map != NULL) == (in->longitude_map != NULL) &&
           !(in->site && in->latitude_map);
}

/* Each sample its own site (the maps or the site function), not one site for the grid. */
static int hf_solar_per_sample(const hfvis_solar_input *in)
{
    return in->latitude_map != NULL || in->site != NULL;
}

static int hf_solar_opts_valid(const hfvis_solar_options *o)
{
    int k;
    const hfvis_sweep_options *s;
    if (!o) return 1;
    s = o->sweep;
    if (o->model < HFVIS_SUN_MODEL_DEFAULT || o->model > HFVIS_SUN_RSUN || !(o->step_hours >= 0.0) ||
        o->step_hours > 24.0 || o->directions < 0 || o->directions > HF_SOLAR_K_MAX ||
        (o->no_shading != 0 && o->no_shading != 1) || !hf_in(o->sun_radius_rad, 0.0, 0.1) ||
        (o->refraction != 0 && o->refraction != 1) || !hf_in(o->delta_t, -8000.0, 8000.0) ||
        o->diffuse < HFVIS_SOLAR_DIFFUSE_DEFAULT || o->diffuse > HFVIS_SOLAR_DIFFUSE_HORIZON ||
        o->reflected < HFVIS_SOLAR_REFLECTED_DEFAULT || o->reflected > HFVIS_SOLAR_REFLECTED_TERRAIN ||
        o->reflected_directions < 0 || o->reflected_directions > HF_SOLAR_K_MAX ||
        o->bands < HFVIS_SOLAR_BANDS_DEFAULT || o->bands > HFVIS_SOLAR_BANDS_MONTH ||
        !hf_in(o->site_tolerance_rad, 0.0, 0.1) || o->horizons < HFVIS_SOLAR_HORIZONS_DEFAULT ||
        o->horizons > HFVIS_SOLAR_HORIZONS_LATTICE || o->row_begin < 0 || o->row_end < 0 ||
        ((o->row_begin || o->row_end) && (o->row_begin >= o->row_end || o->reflected == HFVIS_SOLAR_REFLECTED_TERRAIN)) ||
        o->normals < HFVIS_SOLAR_NORMALS_DEFAULT || o->normals > HFVIS_SOLAR_NORMALS_HORN ||
        !isfinite(o->height_min) || !isfinite(o->height_max) || o->height_min > o->height_max)
        return 0;
    if (s && (!hf_opts_valid(s) || ((s->extent_width != 0 || s->receiver_width != 0) &&
                                     o->reflected == HFVIS_SOLAR_REFLECTED_TERRAIN)))
        return 0; /* TERRAIN gathers over the whole grid */
    if (o->linke_monthly)
        for (k = 0; k < 12; k++)
            if (!(o->linke_monthly[k] > 0.0f && o->linke_monthly[k] <= 10.0f)) return 0;
    return 1;
}

int hfvis_solar_band_count(const hfvis_solar_input *input, const hfvis_solar_options *opts)
{
    int y, m, d, n;
    if (!hf_solar_input_valid(input) || !hf_solar_opts_valid(opts)) return -1;
    if (input->instant || !opts || opts->bands == HFVIS_SOLAR_BANDS_TOTAL) return 1;
    if (opts->bands == HFVIS_SOLAR_BANDS_DAY) return input->days;
    y = input->year;
    m = input->month;
    d = input->day;
    hf_date_add(&y, &m, &d, input->days - 1);
    n = (y - input->year) * 12 + (m - input->month) + 1;
    return n;
}

/* One time step: the sun (true elevation h for the atmosphere, the direction for shading and
 * incidence), the extraterrestrial irradiance, the step's weight in hours (1 for an instant) and
 * its band and month. */
typedef struct hf_solar_step {
    double h, sinh, g0, sx, sy, sz, psi, elev, weight;
    double linke;       /* the month's Linke factor (or input->linke) */
    double m0;          /* ESRA air mass at sea level (pressure ratio 1) */
    double fd;          /* ESRA diffuse factor Tn*Fd for this step's Linke factor */
    int band, month;
} hf_solar_step;

/* SPA's instant part (hf_spa_sun's alpha, delta, nu, xi, R) on the hours 0..24 of each day of
 * the period, shared by the blocks of a run with per-sample sites (section 17.6). nu is stored
 * less Earth's sidereal rate, alpha unwrapped along the day, so both interpolate linearly. */
#define HF_SOLAR_EPH_PER_DAY 25
#define HF_SOLAR_SIDEREAL_RATE 360.98564736629 /* deg per day (SPA Eq. 28) */
typedef struct hf_spa_eph {
    double alpha, delta, nu, xi, R;
} hf_spa_eph;

typedef struct hf_solar_ctx {
    hfvis_solar_input in;
    hfvis_solar_options o;
    int bands;
    double lat, lon;         /* the current site, radians */
    double gamma;            /* the true azimuth of the grid's up direction there */
    const hf_spa_eph *eph;   /* NULL: full SPA per instant; else the hourly instant table */
    int rb, re;              /* the rows computed and written */
    int cb, ce;              /* the columns computed and written (the receiver rectangle's) */
    int ox, oy, ew, eh;      /* the grid's (0, 0) is raster cell (ox, oy) of an ew x eh raster */
} hf_solar_ctx;

/* The Julian day of local civil hour t of day (y, m, d). */
static double hf_solar_jd(const hf_solar_ctx *c, int y, int m, int d, double t)
{
    return hf_julian_day(y, m, (double)d + (t - c->in.utc_offset_hours) / 24.0);
}

static double hf_wrap180(double x) { return x - 360.0 * floor((x + 180.0) / 360.0); }

/* Fill the hourly table of `days` days from the first (HF_SOLAR_EPH_PER_DAY rows per day). */
static void hf_solar_eph_fill(const hf_solar_ctx *c, int days, hf_spa_eph *e)
{
    int y = c->in.year, m = c->in.month, d = c->in.day, day, k;
    for (day = 0; day < days; day++, hf_date_add(&y, &m, &d, 1)) {
        hf_spa_eph *row = e + (size_t)day * HF_SOLAR_EPH_PER_DAY;
        for (k = 0; k < HF_SOLAR_EPH_PER_DAY; k++) {
            hf_spa_sun s;
            hf_spa_instant(hf_solar_jd(c, y, m, d, (double)k), c->o.delta_t, &s);
            row[k].alpha = k ? row[k - 1].alpha + hf_wrap180(s.alpha - row[k - 1].alpha) : s.alpha;
            row[k].nu = s.nu - HF_SOLAR_SIDEREAL_RATE * (double)k / 24.0;
            if (k) row[k].nu = row[k - 1].nu + hf_wrap180(row[k].nu - row[k - 1].nu);
            row[k].delta = s.delta;
            row[k].xi = s.xi;
            row[k].R = s.R;
        }
    }
}

/* Sun of the SPA model at local civil hour t of day (y, m, d), the period's day `day`: true and
 * shading elevation, compass azimuth in the grid (the true azimuth less gamma) and G0. With the
 * hourly table the instant part is interpolated linearly between its two hours: within
 * 2e-6 deg of the full SPA (the declination's curvature, at most 0.007 deg/day^2, times
 * (1/24 day)^2/8; test_solar.c's per-sample tests compare against the oracle's full SPA). */
static void hf_solar_spa_sun(const hf_solar_ctx *c, int y, int m, int d, int day, double t,
                             double *h_true, double *elev, double *azimuth, double *g0, double *hour)
{
    hf_spa_sun s;
    hf_spa_place p;
    if (c->eph) {
        int k = t >= 24.0 ? 23 : t <= 0.0 ? 0 : (int)t;
        const hf_spa_eph *e0 = c->eph + (size_t)day * HF_SOLAR_EPH_PER_DAY + k, *e1 = e0 + 1;
        double f = t - (double)k;
        s.alpha = e0->alpha + f * (e1->alpha - e0->alpha);
        s.delta = e0->delta + f * (e1->delta - e0->delta);
        s.nu = e0->nu + f * (e1->nu - e0->nu) + HF_SOLAR_SIDEREAL_RATE * t / 24.0;
        s.xi = e0->xi + f * (e1->xi - e0->xi);
        s.R = e0->R + f * (e1->R - e0->R);
    } else {
        hf_spa_instant(hf_solar_jd(c, y, m, d, t), c->o.delta_t, &s);
    }
    hf_spa_at(&s, c->lat / HF_DEG, c->lon / HF_DEG, c->in.height_m, c->o.refraction,
              HF_SOLAR_REFRACT_P, HF_SOLAR_REFRACT_T, HF_SOLAR_REFRACT_SUNRISE, &p);
    *h_true = p.e0 * HF_DEG;
    *elev = p.e * HF_DEG;
    *azimuth = p.azimuth * HF_DEG;
    *g0 = 1367.0 / (s.R * s.R);
    if (hour) *hour = p.H_p; /* topocentric hour angle, deg (Eq. 40) */
}

/* The sun's true elevation at hour t (and, hour not NULL, its topocentric hour angle in deg). */
static double hf_solar_spa_h(const hf_solar_ctx *c, int y, int m, int d, int day, double t, double *hour)
{
    double h, e, a, g;
    hf_solar_spa_sun(c, y, m, d, day, t, &h, &e, &a, &g, hour);
    return h;
}

/* The sun's zero of true elevation between lo and hi, where it rises (up: h(lo) <= 0 < h(hi);
 * returns the first lit hour) or sets (h(lo) > 0 >= h(hi); the last lit hour), by bisection. */
static double hf_solar_zero(const hf_solar_ctx *c, int y, int m, int d, int day, double lo, double hi, int up)
{
    int it;
    for (it = 0; it < HF_SOLAR_BISECTIONS; it++) {
        double mid = 0.5 * (lo + hi), hm = hf_solar_spa_h(c, y, m, d, day, mid, NULL);
        if ((hm > 0.0) == up) hi = mid;
        else lo = mid;
    }
    return up ? hi : lo;
}

/* Where the sun turns inside the step (t0, t1] of hour angles H0, H1: the hour at which its
 * topocentric hour angle, growing about 15 deg an hour, passes target (0: the transit, where the
 * elevation is highest; 180: lowest), by bisection; 0 when it does not pass it. A step of more
 * than 12 h is halved first, so that each half turns the angle by less than 360 deg. */
static int hf_solar_turn(const hf_solar_ctx *c, int y, int m, int d, int day, double t0, double H0, double t1,
                         double H1, double target, double *t)
{
    double need, lo = t0, hi = t1;
    int it;
    if (t1 - t0 > 12.0) {
        double tm = 0.5 * (t0 + t1), Hm;
        hf_solar_spa_h(c, y, m, d, day, tm, &Hm);
        return hf_solar_turn(c, y, m, d, day, t0, H0, tm, Hm, target, t) ||
               hf_solar_turn(c, y, m, d, day, tm, Hm, t1, H1, target, t);
    }
    need = fmod(target - H0 + 720.0, 360.0); /* the angle still to turn, [0, 360) */
    if (!(need > 0.0 && need <= fmod(H1 - H0 + 720.0, 360.0))) return 0;
    for (it = 0; it < HF_SOLAR_BISECTIONS; it++) {
        double mid = 0.5 * (lo + hi), Hm;
        hf_solar_spa_h(c, y, m, d, day, mid, &Hm);
        if (fmod(Hm - H0 + 720.0, 360.0) < need) lo = mid;
        else hi = mid;
    }
    *t = hi;
    return 1;
}

/* Fill a step from the sun's true elevation h, shading elevation elev and compass azimuth. */
static void hf_solar_step_set(const hf_solar_ctx *c, hf_solar_step *st, double h, double elev,
                              double azimuth, double g0, double weight, int band, int month)
{
    double ce = cos(elev);
    azimuth -= c->gamma; /* true north to the grid's up direction */
    st->h = h;
    st->sinh = sin(h);
    st->elev = elev;
    st->g0 = g0;
    st->sx = ce * sin(azimuth);   /* east = +x */
    st->sy = -ce * cos(azimuth);  /* south = +y */
    st->sz = sin(elev);
    st->psi = azimuth - HFVIS__HALF_PI;
    while (st->psi < 0.0) st->psi += 2.0 * HFVIS__PI;
    while (st->psi >= 2.0 * HFVIS__PI) st->psi -= 2.0 * HFVIS__PI;
    st->weight = weight;
    st->band = band;
    st->month = month;
    st->linke = c->o.linke_monthly ? (double)c->o.linke_monthly[month - 1] : c->in.linke;
    st->m0 = hf_esra_air_mass(h, 1.0);
    st->fd = hf_esra_diffuse_factor(st->sinh, st->linke);
}

/* The steps of the period, sun above the horizon only, in time order. steps NULL: count only. */
static size_t hf_solar_steps(const hf_solar_ctx *c, hf_solar_step *steps)
{
    size_t n = 0;
    int y = c->in.year, m = c->in.month, d = c->in.day, day, days = c->in.instant ? 1 : c->in.days;
    int band_month0 = c->in.year * 12 + c->in.month;
    double step = c->o.step_hours;
    for (day = 0; day < days; day++, hf_date_add(&y, &m, &d, 1)) {
        int band = c->o.bands == HFVIS_SOLAR_BANDS_DAY ? day
                 : c->o.bands == HFVIS_SOLAR_BANDS_MONTH ? y * 12 + m - band_month0 : 0;
        if (c->o.model == HFVIS_SUN_RSUN) {
            int doy = hf_day_of_year(y, m, d);
            hfvis_rsun_sun r;
            double ang, last, dang = step * (HFVIS__PI / 12.0), first;
            int k;
            if (c->in.instant) {
                hfvis_rsun_sun_position(doy, c->in.hour, c->lat, &r);
                if (r.elevation > 0.0) {
                    if (steps) hf_solar_step_set(c, steps + n, r.elevation, r.elevation, r.azimuth,
                                                 r.extraterrestrial, 1.0, band, m);
                    n++;
                }
                continue;
            }
            hfvis_rsun_sun_position(doy, 12.0, c->lat, &r);
            /* r.sun's schedule (joules2): the first step half a step after the start of the
             * step that holds sunrise, or one and a half when sunrise lies in its second half;
             * then every step while the hour angle has not passed sunset's */
            k = (int)(r.sunrise_hour / step);
            first = (r.sunrise_hour - (double)k * step > 0.5 * step) ? ((double)k + 1.5) * step
                                                                      : ((double)k + 0.5) * step;
            ang = (first - 12.0) * (HFVIS__PI / 12.0);
            last = (r.sunset_hour - 12.0) * (HFVIS__PI / 12.0);
            for (;;) {
                hfvis_rsun_sun q;
                hfvis_rsun_sun_position(doy, 12.0 + ang * (12.0 / HFVIS__PI), c->lat, &q);
                if (q.elevation > 0.0) {
                    if (steps) hf_solar_step_set(c, steps + n, q.elevation, q.elevation, q.azimuth,
                                                 q.extraterrestrial, step, band, m);
                    n++;
                }
                ang += dang;
                if (ang > last) break;
            }
        } else if (c->in.instant) {
            double h, e, a, g;
            hf_solar_spa_sun(c, y, m, d, day, c->in.hour, &h, &e, &a, &g, NULL);
            if (h > 0.0) {
                if (steps) hf_solar_step_set(c, steps + n, h, e, a, g, 1.0, band, m);
                n++;
            }
        } else {
            /* Each step's lit parts, one sample at the middle of each, weighted by its length.
             * Ends on either side of the horizon: sunrise or sunset inside, bisected. Both ends
             * below: lit only if the sun rises and sets inside (a short polar day, or a long
             * step), which its transit inside the step tells; both above: unlit in the middle
             * if it sets and rises inside (a short night), which its lowest point tells. */
            double H0, H1, t0 = 0.0, h0 = hf_solar_spa_h(c, y, m, d, day, 0.0, &H0);
            while (t0 < 24.0) {
                double t1 = t0 + step > 24.0 ? 24.0 : t0 + step, h1 = hf_solar_spa_h(c, y, m, d, day, t1, &H1);
                double part[4], tt;
                int np = 0, k;
                if (!(h0 > 0.0) && !(h1 > 0.0)) {
                    if (hf_solar_turn(c, y, m, d, day, t0, H0, t1, H1, 0.0, &tt) &&
                        hf_solar_spa_h(c, y, m, d, day, tt, NULL) > 0.0) {
                        part[0] = hf_solar_zero(c, y, m, d, day, t0, tt, 1);
                        part[1] = hf_solar_zero(c, y, m, d, day, tt, t1, 0);
                        np = 1;
                    }
                } else if (h0 > 0.0 && h1 > 0.0) {
                    part[0] = t0;
                    part[3] = t1;
                    if (hf_solar_turn(c, y, m, d, day, t0, H0, t1, H1, 180.0, &tt) &&
                        !(hf_solar_spa_h(c, y, m, d, day, tt, NULL) > 0.0)) {
                        part[1] = hf_solar_zero(c, y, m, d, day, t0, tt, 0);
                        part[2] = hf_solar_zero(c, y, m, d, day, tt, t1, 1);
                        np = 2;
                    } else {
                        part[1] = t1;
                        np = 1;
                    }
                } else { /* sunrise or sunset inside the step */
                    part[0] = h1 > 0.0 ? hf_solar_zero(c, y, m, d, day, t0, t1, 1) : t0;
                    part[1] = h1 > 0.0 ? t1 : hf_solar_zero(c, y, m, d, day, t0, t1, 0);
                    np = 1;
                }
                for (k = 0; k < np; k++) {
                    double a = part[2 * k], b = part[2 * k + 1], h, e, az, g;
                    if (!(b > a)) continue;
                    hf_solar_spa_sun(c, y, m, d, day, 0.5 * (a + b), &h, &e, &az, &g, NULL);
                    if (h > 0.0) {
                        if (steps) hf_solar_step_set(c, steps + n, h, e, az, g, b - a, band, m);
                        n++;
                    }
                }
                t0 = t1;
                h0 = h1;
                H0 = H1;
            }
        }
    }
    return n;
}

/* ------------------------------------------------------------- 5. the atmosphere per point */
/* Per-sample constants: pressure ratio of its height, normal, slope terms of Muneer's model,
 * Linke factor (map), albedo, real-sky coefficients and the visible-sky ratio of HORIZON. */
typedef struct hf_solar_point {
    double p, nx, ny, nz, sin_slope, r_sky, fg, albedo, cbh, cdh, sky_ratio, linke;
    int tilted, linke_map;
} hf_solar_point;

static void hf_solar_point_init(const hf_solar_ctx *c, const hfvis_grid *g, int x, int y,
                                hf_solar_point *pt)
{
    size_t i = (size_t)y * (size_t)g->width + (size_t)x;
    double n[3], slope;
    if (c->o.normals == HFVIS_SOLAR_NORMALS_HORN) hf_normal_horn_at(g, x, y, n);
    else hf_normal_at(g, x, y, n);
    pt->p = hf_esra_pressure((double)g->z[(ptrdiff_t)y * g->stride + x]);
    pt->nx = n[0];
    pt->ny = n[1];
    pt->nz = n[2];
    slope = acos(n[2] > 1.0 ? 1.0 : n[2]);
    pt->tilted = slope > HF_SOLAR_SLOPE_FLAT;
    pt->sin_slope = sin(slope);
    pt->r_sky = 0.5 * (1.0 + cos(slope));
    /* Muneer's sky-brightness function of the slope (r.sun's fg) */
    pt->fg = sin(slope) - slope * cos(slope) - HFVIS__PI * sin(0.5 * slope) * sin(0.5 * slope);
    pt->albedo = c->o.albedo_map ? (double)c->o.albedo_map[i] : c->in.albedo;
    pt->cbh = c->o.coeff_bh ? (double)c->o.coeff_bh[i] : 1.0;
    pt->cdh = c->o.coeff_dh ? (double)c->o.coeff_dh[i] : 1.0;
    pt->linke_map = c->o.linke_map != NULL;
    pt->linke = c->o.linke_map ? (double)c->o.linke_map[i] : 0.0;
    pt->sky_ratio = 1.0;
}

/* The cosine-weighted visible sky of point i over the K horizons hor[k*n + i] at azimuths az[k],
 * each raised to the point's tangent plane ([P1] Eq. 5 per sector); NaN at a hole. */
static double hf_solar_sky_seen(const hf_solar_point *pt, int K, const double *az, const float *hor,
                                size_t n, size_t i)
{
    double v = 0.0;
    int k;
    if (isnan(pt->nz)) return HFVIS__NAN;
    for (k = 0; k < K; k++) {
        double a = pt->nx * cos(az[k]) + pt->ny * sin(az[k]);
        double t = tan((double)hor[(size_t)k * n + i]), tc = -a / pt->nz;
        if (isnan(t) || t < tc) t = tc;
        v += hfvis_sector_weight(K, pt->nz, a, HFVIS__HALF_PI - atan(t));
    }
    return v;
}

/* Visible fraction of the sun at elevation elev over horizon elevation hor: the centre's test,
 * or the disc's segment above the horizon line (hfvis_sun_visibility's formula). */
static double hf_solar_visible(double elev, double hor, double radius)
{
    double d;
    if (isnan(hor)) return HFVIS__NAN;
    if (radius <= 0.0) return elev > hor ? 1.0 : 0.0;
    d = (elev - hor) / radius;
    if (d >= 1.0) return 1.0;
    if (d <= -1.0) return 0.0;
    return 1.0 - (acos(d) - d * sqrt(1.0 - d * d)) / HFVIS__PI;
}

/* One step at one point (r.sun's brad and drad, Suri & Hofierka 2004 Eq. 1-21 with ESRA):
 * adds weight * (beam, diffuse, reflected on the flat-ground model, sunshine) to acc.
 * vis: the visible fraction of the sun (1 without shading). horizon: HORIZON diffuse. */
static void hf_solar_point_step(const hf_solar_step *st, const hf_solar_point *pt, double vis,
                                int horizon, double acc[4])
{
    double linke = pt->linke_map ? pt->linke : st->linke, m, bh, sh, beam = 0.0, dh, fx, diff, gh;
    double bg, cs, kb, w = st->weight;
    int lit;
    sh = pt->nx * st->sx + pt->ny * st->sy + pt->nz * st->sz; /* cos of the incidence angle */
    m = pt->p * st->m0;
    lit = vis > 0.0 && sh > 0.0;
    if (lit) {
        bh = pt->cbh * st->g0 * st->sinh * hf_esra_beam_trans_m(m, linke);
        beam = (pt->tilted ? bh * sh / st->sinh : bh) * vis;
        acc[3] += w * vis;
    } else {
        bh = 0.0; /* r.sun: no beam in shadow, and so no beam part in kb or the reflection */
    }
    dh = pt->cdh * st->g0 * (pt->linke_map ? hf_esra_diffuse_factor(st->sinh, linke) : st->fd);
    gh = bh * (vis > 0.0 ? vis : 0.0) + dh;
    if (pt->tilted || horizon) {
        kb = bh / (st->g0 * st->sinh);
        if (!lit) { /* shadow, or the sun behind the receiver's plane */
            bg = pt->r_sky + pt->fg * 0.252271;
            cs = 0.0;
        } else {
            bg = hf_muneer_fg_part(kb) * pt->fg + pt->r_sky * (1.0 - kb);
            if (st->h >= 0.1 || !pt->tilted)
                cs = kb * sh / st->sinh;
            else /* low sun: Muneer's form with the horizontal direction (r.sun) */
                cs = kb * (pt->nx * st->sx + pt->ny * st->sy) / cos(st->elev) /
                     hf_muneer_low_sun(st->h);
            cs *= vis;
        }
        fx = bg * pt->sky_ratio + cs;
        diff = dh * fx;
    } else {
        diff = dh;
    }
    acc[0] += w * beam;
    acc[1] += w * diff;
    acc[2] += w * (pt->tilted ? pt->albedo * gh * (1.0 - pt->nz) * 0.5 : 0.0);
}

/* ------------------------------------------------------------ 6. driver, fast and oracle */
/* Validate, resolve the options, count the steps and bands. */
static hfvis_status hf_solar_setup(const hfvis_grid *g, const hfvis_solar_input *in,
                                   const hfvis_solar_options *opts, const hfvis_solar_output *out,
                                   hf_solar_ctx *c)
{
    size_t i, n;
    if (!hf_grid_valid(g) || !out || !hf_solar_input_valid(in) || !hf_solar_opts_valid(opts) ||
        (!out->beam && !out->diffuse && !out->reflected && !out->global && !out->sun_hours))
        return HFVIS_ERR_INVALID_ARGUMENT;
    c->in = *in;
    c->lat = in->latitude_rad;
    c->lon = in->longitude_rad;
    c->gamma = 0.0;
    c->eph = NULL;
    c->o = hfvis_solar_options_default();
    if (opts) {
        c->o = *opts;
        if (c->o.model == HFVIS_SUN_MODEL_DEFAULT) c->o.model = HFVIS_SUN_SPA;
        if (c->o.step_hours == 0.0) c->o.step_hours = HF_SOLAR_STEP_DEFAULT;
        if (c->o.directions == 0) c->o.directions = HF_SOLAR_K_DEFAULT;
        if (c->o.delta_t == 0.0) c->o.delta_t = HF_SOLAR_DELTA_T_DEFAULT;
        if (c->o.reflected_directions == 0) c->o.reflected_directions = HF_SOLAR_KR_DEFAULT;
        if (c->o.site_tolerance_rad == 0.0) c->o.site_tolerance_rad = HF_SOLAR_SITE_TOL_DEFAULT;
    }
    c->bands = hfvis_solar_band_count(in, opts);
    c->rb = c->o.row_end ? c->o.row_begin : 0;
    c->re = c->o.row_end ? c->o.row_end : g->height;
    if (c->re > g->height) return HFVIS_ERR_INVALID_ARGUMENT;
    c->cb = c->ox = c->oy = 0;
    c->ce = c->ew = g->width;
    c->eh = g->height;
    if (c->o.sweep) { /* the window and the receiver rectangle (hfvis.h "Search radius and tiles") */
        const hfvis_sweep_options *s = c->o.sweep;
        int rx0, ry0, rx1, ry1;
        if (!hf_tile_fits(g, s) || (in->latitude_map && hf_tile_window(g, s))) return HFVIS_ERR_INVALID_ARGUMENT;
        if (s->extent_width != 0) {
            c->ox = s->origin_x;
            c->oy = s->origin_y;
            c->ew = s->extent_width;
            c->eh = s->extent_height;
        }
        hf_receiver_rect(g, s, &rx0, &ry0, &rx1, &ry1);
        c->cb = rx0;
        c->ce = rx1;
        if (c->rb < ry0) c->rb = ry0;
        if (c->re > ry1) c->re = ry1;
        if (c->re < c->rb) c->re = c->rb; /* no row of the band in the rectangle */
    }
    n = hf_grid_count(g);
    if (n > SIZE_MAX / sizeof(double) / 8 || (size_t)c->bands > SIZE_MAX / sizeof(float) / 8 / n)
        return HFVIS_ERR_LIMIT;
    for (i = 0; i < n; i++) { /* the per-sample maps: NaN only at holes */
        size_t zi = (i / (size_t)g->width) * (size_t)g->stride + i % (size_t)g->width;
        if (!isfinite(g->z[zi])) continue;
        if ((c->o.linke_map && !(c->o.linke_map[i] > 0.0f && c->o.linke_map[i] <= 10.0f)) ||
            (c->o.albedo_map && !(c->o.albedo_map[i] >= 0.0f && c->o.albedo_map[i] <= 1.0f)) ||
            (c->o.coeff_bh && !(c->o.coeff_bh[i] >= 0.0f && c->o.coeff_bh[i] <= 1e6f)) ||
            (c->o.coeff_dh && !(c->o.coeff_dh[i] >= 0.0f && c->o.coeff_dh[i] <= 1e6f)))
            return HFVIS_ERR_INVALID_ARGUMENT;
    }
    for (i = 0; in->latitude_map && i < n; i++) /* the sites: everywhere (holes too: differences) */
        if (!hf_in(in->latitude_map[i], -HFVIS__HALF_PI, HFVIS__HALF_PI) ||
            !hf_in(in->longitude_map[i], -HFVIS__PI, HFVIS__PI))
            return HFVIS_ERR_INVALID_ARGUMENT;
    return HFVIS_OK;
}

/* The sweep options of the horizon map (exact rays) and of the TERRAIN gather (lattice). */
static hfvis_sweep_options hf_solar_sweep(const hf_solar_ctx *c, hfvis_ray_mode rays)
{
    hfvis_sweep_options s = c->o.sweep ? *c->o.sweep : hfvis_sweep_options_default();
    s.rays = rays;
    s.ray_denominator = 0;
    s.azimuth0_rad = 0.0;
    s.direction_begin = s.direction_end = 0;
    s.direction_order = HFVIS_DIRECTION_ORDER_DEFAULT;
    return s;
}

/* The sweep options of the fast routine's horizon map and visible sky: o->horizons' rays. */
static hfvis_sweep_options hf_solar_map_sweep(const hf_solar_ctx *c)
{
    hfvis_sweep_options s = hf_solar_sweep(c, c->o.horizons == HFVIS_SOLAR_HORIZONS_LATTICE ? HFVIS_RAYS_LATTICE
                                                                                          : HFVIS_RAYS_EXACT);
    if (c->o.horizons == HFVIS_SOLAR_HORIZONS_NEAR_FAR) s.ray_near_cells = HFVIS_SOLAR_NEAR_CELLS;
    if (c->o.horizons == HFVIS_SOLAR_HORIZONS_LATTICE) s.ray_near_cells = 0;
    return s;
}

hfvis_sweep_options hfvis_solar_map_options(const hfvis_solar_options *opts)
{
    hf_solar_ctx c;
    c.o = opts ? *opts : hfvis_solar_options_default();
    return hf_solar_map_sweep(&c);
}

/* Write the accumulated sums acc[(band*n + i)*4 + q] (beam, diffuse, reflected, sunshine) to the
 * outputs; terrain: the TERRAIN reflected term per band (replaces q = 2). */
static void hf_solar_store(const hfvis_grid *g, const hf_solar_ctx *c, const double *acc,
                           const float *terrain, const hfvis_solar_output *out)
{
    size_t n = hf_grid_count(g), i;
    int b;
    for (b = 0; b < c->bands; b++)
        for (i = (size_t)c->rb * (size_t)g->width; i < (size_t)c->re * (size_t)g->width; i++) {
            size_t j = (size_t)b * n + i;
            const double *a = acc + j * 4;
            int hole = !isfinite(g->z[(i / (size_t)g->width) * (size_t)g->stride + i % (size_t)g->width]);
            double r = terrain ? (double)terrain[j] : a[2];
            if ((int)(i % (size_t)g->width) < c->cb || (int)(i % (size_t)g->width) >= c->ce) continue;
            if (out->beam) out->beam[j] = hole ? (float)HFVIS__NAN : (float)a[0];
            if (out->diffuse) out->diffuse[j] = hole ? (float)HFVIS__NAN : (float)a[1];
            if (out->reflected) out->reflected[j] = hole ? (float)HFVIS__NAN : (float)r;
            if (out->global) out->global[j] = hole ? (float)HFVIS__NAN : (float)(a[0] + a[1] + r);
            if (out->sun_hours) out->sun_hours[j] = hole ? (float)HFVIS__NAN : (float)a[3];
        }
}

/* TERRAIN: per band, the [P2] gather of exit irradiance albedo * (beam + diffuse). */
static hfvis_status hf_solar_terrain(const hfvis_grid *g, const hf_solar_ctx *c, const double *acc,
                                     int naive, float **terrain_out)
{
    size_t n = hf_grid_count(g), i;
    float *exit_r, *terr;
    hfvis_sweep_options s = hf_solar_sweep(c, HFVIS_RAYS_LATTICE);
    const hfvis_allocator *al = s.alloc;
    hfvis_status st = HFVIS_OK;
    int b;
    exit_r = (float *)hfvis__alloc_array(al, n, sizeof(float));
    terr = (float *)hfvis__alloc_array(al, n * (size_t)c->bands, sizeof(float));
    if (!exit_r || !terr) {
        hfvis__free(al, exit_r);
        hfvis__free(al, terr);
        return HFVIS_ERR_OUT_OF_MEMORY;
    }
    for (b = 0; b < c->bands && st == HFVIS_OK; b++) {
        for (i = 0; i < n; i++) {
            const double *a = acc + ((size_t)b * n + i) * 4;
            double alb = c->o.albedo_map ? (double)c->o.albedo_map[i] : c->in.albedo;
            exit_r[i] = (float)(alb * (a[0] + a[1]));
            if (!isfinite(exit_r[i])) exit_r[i] = 0.0f; /* holes reflect nothing */
        }
        st = naive ? hfvis_indirect_light_naive(g, c->o.reflected_directions, exit_r, 1, 0.0f, 1.0f,
                                                &s, terr + (size_t)b * n, g->width)
                   : hfvis_indirect_light(g, c->o.reflected_directions, exit_r, 1, 0.0f, 1.0f, &s,
                                          NULL, terr + (size_t)b * n, g->width);
    }
    hfvis__free(al, exit_r);
    if (st != HFVIS_OK) {
        hfvis__free(al, terr);
        return st;
    }
    *terrain_out = terr;
    return HFVIS_OK;
}

/* Locate azimuth psi among the map's actual azimuths az[0..K) (increasing, spanning one turn):
 * the two neighbours k0, k1 and the weight of k1. */
static void hf_solar_bracket(const double *az, int K, double psi, int *k0, int *k1, double *w)
{
    double turn = 2.0 * HFVIS__PI, a0 = az[0], span, lo, hi;
    int k;
    psi = fmod(psi - a0, turn);
    if (psi < 0.0) psi += turn;
    psi += a0;
    for (k = 0; k + 1 < K && az[k + 1] <= psi; k++) {}
    lo = az[k];
    hi = k + 1 < K ? az[k + 1] : a0 + turn;
    span = hi - lo;
    *k0 = k;
    *k1 = k + 1 < K ? k + 1 : 0;
    *w = span > 0.0 ? (psi - lo) / span : 0.0;
}

/* Per-sample sites (the input's site function or its latitude and longitude maps): frames,
 * blocks. */
static double hf_wrap_pi(double x) { return x - 2.0 * HFVIS__PI * floor((x + HFVIS__PI) / (2.0 * HFVIS__PI)); }

/* Raster cell (x, y)'s latitude and longitude: the input's site function, or its maps (whose
 * grid is the raster, section 6 checks). 0 for a value out of range. */
static int hf_solar_site_at(const hf_solar_ctx *c, int x, int y, double *lat, double *lon)
{
    if (c->in.site) {
        c->in.site(c->in.site_user, x, y, lat, lon);
        return hf_in(*lat, -HFVIS__HALF_PI, HFVIS__HALF_PI) && hf_in(*lon, -HFVIS__PI, HFVIS__PI);
    }
    *lat = c->in.latitude_map[(size_t)y * (size_t)c->ew + (size_t)x];
    *lon = c->in.longitude_map[(size_t)y * (size_t)c->ew + (size_t)x];
    return 1; /* checked by hf_solar_setup */
}

/* Raster cell (x, y)'s site: latitude, longitude, and gamma, the true azimuth of the grid's up
 * direction (-y): from the sites' central differences along y (one-sided at the raster's edge),
 * along x on a one-row raster (the azimuth of +x less 90 deg), 0 where they do not change.
 * 0 for a site out of range. */
static int hf_solar_site_of(const hf_solar_ctx *c, int x, int y, double *lat, double *lon, double *gamma)
{
    double dn, de, turn = 0.0, la, lo, lb, lob;
    int ax = x, ay = y, bx = x, by = y;
    if (!hf_solar_site_at(c, x, y, lat, lon)) return 0;
    if (c->eh > 1) { /* a: the row above (up), b: the row below */
        ay = y > 0 ? y - 1 : y;
        by = y + 1 < c->eh ? y + 1 : y;
    } else { /* a: east, b: west */
        ax = x + 1 < c->ew ? x + 1 : x;
        bx = x > 0 ? x - 1 : x;
        turn = HFVIS__HALF_PI;
    }
    if (!hf_solar_site_at(c, ax, ay, &la, &lo) || !hf_solar_site_at(c, bx, by, &lb, &lob)) return 0;
    dn = la - lb;
    de = hf_wrap_pi(lo - lob) * cos(*lat);
    *gamma = dn == 0.0 && de == 0.0 ? 0.0 : hf_wrap_pi(atan2(de, dn) - turn);
    return 1;
}

/* A site's local frame in Earth-fixed axes, rows: the grid's +x (east turned by gamma), its up
 * direction (north turned by gamma), the zenith (the geodetic normal). */
static void hf_solar_frame(double lat, double lon, double gamma, double f[9])
{
    double sp = sin(lat), cp = cos(lat), sl = sin(lon), cl = cos(lon), sg = sin(gamma), cg = cos(gamma);
    double E[3], N[3];
    int k;
    E[0] = -sl; E[1] = cl; E[2] = 0.0;
    N[0] = -sp * cl; N[1] = -sp * sl; N[2] = cp;
    for (k = 0; k < 3; k++) {
        f[k] = cg * E[k] - sg * N[k];
        f[3 + k] = cg * N[k] + sg * E[k];
    }
    f[6] = cp * cl; f[7] = cp * sl; f[8] = sp;
}

/* The angle of the rotation between two frames: acos((trace(A B^T) - 1) / 2). */
static double hf_solar_frame_angle(const double a[9], const double b[9])
{
    double t = 0.0;
    int k;
    for (k = 0; k < 9; k++) t += a[k] * b[k];
    t = 0.5 * (t - 1.0);
    return acos(t > 1.0 ? 1.0 : t < -1.0 ? -1.0 : t);
}

/* A block of samples sharing the sun of its centre sample's site, in grid cells. */
typedef struct hf_solar_block {
    int x0, y0, x1, y1;   /* the block's cells within the grid */
    int r0, r1;           /* the rows computed, within [y0, y1) (the options' rows) */
    int c0, c1;           /* the columns computed, within [x0, x1) (the receiver rectangle's) */
    double lat, lon, gamma;
} hf_solar_block;

typedef struct hf_solar_blocks {
    hf_solar_block *b;
    size_t n, cap;
    int split;            /* the raster was cut into more than one block */
    const hfvis_allocator *al;
} hf_solar_blocks;

/* Append block [x0, x1) x [y0, y1) of the grid (clipped to it), its computed rows and columns
 * and its site. */
static hfvis_status hf_solar_block_add(const hfvis_grid *g, const hf_solar_ctx *c, int x0, int y0,
                                       int x1, int y1, double lat, double lon, double gamma,
                                       hf_solar_blocks *B)
{
    hf_solar_block *k;
    if (B->n == B->cap) { /* grow by doubling */
        size_t cap = B->cap ? 2 * B->cap : 16;
        hf_solar_block *nb = (hf_solar_block *)hfvis__alloc_array(B->al, cap, sizeof(hf_solar_block));
        if (!nb) return HFVIS_ERR_OUT_OF_MEMORY;
        if (B->n) memcpy(nb, B->b, B->n * sizeof(hf_solar_block));
        hfvis__free(B->al, B->b);
        B->b = nb;
        B->cap = cap;
    }
    k = B->b + B->n++;
    k->x0 = x0 > 0 ? x0 : 0;
    k->y0 = y0 > 0 ? y0 : 0;
    k->x1 = x1 < g->width ? x1 : g->width;
    k->y1 = y1 < g->height ? y1 : g->height;
    k->c0 = k->x0 > c->cb ? k->x0 : c->cb;
    k->c1 = k->x1 < c->ce ? k->x1 : c->ce;
    k->r0 = k->y0 > c->rb ? k->y0 : c->rb;
    k->r1 = k->y1 < c->re ? k->y1 : c->re;
    k->lat = lat;
    k->lon = lon;
    k->gamma = gamma;
    return HFVIS_OK;
}

/* Split raster cells [x0, x1) x [y0, y1) in halves (both axes) until every cell's frame is
 * within tol of the centre cell's; append the blocks that meet the receiver rectangle (the
 * others are neither checked nor kept). Every sun direction seen in a frame turns by at most
 * that angle, so the block's sun is within tol of each sample's own. The cuts depend on the
 * raster alone, so a window gets the whole raster's blocks. */
static hfvis_status hf_solar_split(const hfvis_grid *g, const hf_solar_ctx *c, double tol,
                                   int x0, int y0, int x1, int y1, hf_solar_blocks *B)
{
    int cx = x0 + (x1 - x0 - 1) / 2, cy = y0 + (y1 - y0 - 1) / 2, x, y, ok = 1;
    double fc[9], f[9], lat, lon, gam, la, lo, ga;
    hfvis_status st;
    if (x1 - c->ox <= c->cb || x0 - c->ox >= c->ce || y1 - c->oy <= 0 || y0 - c->oy >= g->height)
        return HFVIS_OK; /* outside the receiver rectangle's columns or the grid's rows */
    if (!hf_solar_site_of(c, cx, cy, &lat, &lon, &gam)) return HFVIS_ERR_INVALID_ARGUMENT;
    hf_solar_frame(lat, lon, gam, fc);
    for (y = y0; y < y1 && ok; y++)
        for (x = x0; x < x1 && ok; x++) {
            if (!hf_solar_site_of(c, x, y, &la, &lo, &ga)) return HFVIS_ERR_INVALID_ARGUMENT;
            hf_solar_frame(la, lo, ga, f);
            ok = hf_solar_frame_angle(f, fc) <= tol;
        }
    if (!ok && (x1 - x0 > 1 || y1 - y0 > 1)) {
        int xm = x1 - x0 > 1 ? x0 + (x1 - x0) / 2 : x1, ym = y1 - y0 > 1 ? y0 + (y1 - y0) / 2 : y1;
        B->split = 1;
        if ((st = hf_solar_split(g, c, tol, x0, y0, xm, ym, B)) != HFVIS_OK) return st;
        if (xm < x1 && (st = hf_solar_split(g, c, tol, xm, y0, x1, ym, B)) != HFVIS_OK) return st;
        if (ym < y1 && (st = hf_solar_split(g, c, tol, x0, ym, xm, y1, B)) != HFVIS_OK) return st;
        if (xm < x1 && ym < y1) return hf_solar_split(g, c, tol, xm, ym, x1, y1, B);
        return HFVIS_OK;
    }
    return hf_solar_block_add(g, c, x0 - c->ox, y0 - c->oy, x1 - c->ox, y1 - c->oy, lat, lon, gam, B);
}

/* Shared by the fast routine and the oracle: setup, steps, per-sample state. */
typedef struct hf_solar_run {
    hf_solar_ctx c;
    hf_solar_step *steps;
    size_t nsteps, cap;
    hf_solar_point *pts;
    double *acc;
    const hfvis_allocator *al;
} hf_solar_run;

static void hf_solar_run_free(hf_solar_run *r)
{
    hfvis__free(r->al, r->steps);
    hfvis__free(r->al, r->pts);
    hfvis__free(r->al, r->acc);
}

/* The steps of the current site (r->c's), in r->steps (grown as needed). */
static hfvis_status hf_solar_run_steps(hf_solar_run *r)
{
    r->nsteps = hf_solar_steps(&r->c, NULL);
    if (!r->steps || r->nsteps + 1 > r->cap) {
        hfvis__free(r->al, r->steps);
        r->cap = r->nsteps + 1;
        r->steps = (hf_solar_step *)hfvis__alloc_array(r->al, r->cap, sizeof(hf_solar_step));
        if (!r->steps) return HFVIS_ERR_OUT_OF_MEMORY;
    }
    hf_solar_steps(&r->c, r->steps);
    return HFVIS_OK;
}

/* The run's setup, steps and per-sample state. Only the rows [c.rb, c.re) of the per-sample
 * arrays are set (every row with all_rows, the oracle's), and only they are ever read: a row
 * band's call touches no other row's memory. */
static hfvis_status hf_solar_run_init(const hfvis_grid *g, const hfvis_solar_input *in,
                                      const hfvis_solar_options *opts,
                                      const hfvis_solar_output *out, int all_rows, hf_solar_run *r)
{
    hfvis_status st;
    size_t n, i, i0, i1, w;
    int b;
    memset(r, 0, sizeof *r);
    if ((st = hf_solar_setup(g, in, opts, out, &r->c)) != HFVIS_OK) return st;
    if (all_rows) { /* and every column */
        r->c.rb = r->c.cb = 0;
        r->c.re = g->height;
        r->c.ce = g->width;
    }
    r->al = r->c.o.sweep ? r->c.o.sweep->alloc : NULL;
    n = hf_grid_count(g);
    w = (size_t)g->width;
    i0 = (size_t)r->c.rb * w;
    i1 = (size_t)r->c.re * w;
    r->pts = (hf_solar_point *)hfvis__alloc_array(r->al, n, sizeof(hf_solar_point));
    r->acc = (double *)hfvis__alloc_array(r->al, n * (size_t)r->c.bands, 4 * sizeof(double));
    if (!r->pts || !r->acc || hf_solar_run_steps(r) != HFVIS_OK) {
        hf_solar_run_free(r);
        return HFVIS_ERR_OUT_OF_MEMORY;
    }
    for (b = 0; b < r->c.bands; b++)
        for (i = ((size_t)b * n + i0) * 4; i < ((size_t)b * n + i1) * 4; i++) r->acc[i] = 0.0;
    for (i = i0; i < i1; i++) hf_solar_point_init(&r->c, g, (int)(i % w), (int)(i / w), r->pts + i);
    return HFVIS_OK;
}

static hfvis_status hf_solar_finish(const hfvis_grid *g, hf_solar_run *r, int naive,
                                    const hfvis_solar_output *out)
{
    float *terr = NULL;
    hfvis_status st = HFVIS_OK;
    if (r->c.o.reflected == HFVIS_SOLAR_REFLECTED_TERRAIN &&
        (st = hf_solar_terrain(g, &r->c, r->acc, naive, &terr)) != HFVIS_OK) {
        hf_solar_run_free(r);
        return st;
    }
    hf_solar_store(g, &r->c, r->acc, terr, out);
    hfvis__free(r->al, terr);
    hf_solar_run_free(r);
    return HFVIS_OK;
}

/* ---------------------------------------------- 7. the sector sums (fast path of a period) */
/* With one Linke factor per step, no coefficient rasters and a hard sun, every term of section 5
 * is linear in per-sample constants (the normal, r_sky, F_g, the sky ratio, the albedo) once a
 * step is known to be lit or not, and the pressure ratio p enters only through B0c(p). So the
 * steps are binned by azimuth (HF_SOLAR_BINS_PER_DIR bins per map direction), sorted by tan(e)
 * in each bin and summed from the top; a sample reads, per bin, the suffix above its threshold
 * max(the tangent of its horizon interpolated linearly from the map's two directions to the
 * bin's centre, its tangent plane toward the centre) by binary search. p enters by quadratic
 * Lagrange interpolation over three pressure nodes spanning the block's heights (one block of
 * hf_solar_run_blocks per call). Cost O(bands * bins * (log S + 3 HF_SOLAR_Q)) per sample
 * instead of O(S): taken when the steps outnumber HF_SOLAR_SECTOR_MIN per bin. docs/solar.md. */
#define HF_SOLAR_BINS_PER_DIR 4
#define HF_SOLAR_SECTOR_MIN 4
#define HF_SOLAR_NODES 3
#define HF_SOLAR_NODES_ANCHORED 5 /* over height_min..height_max (a raster's relief, not a block's):
                                     quartic, as the day path's; 3 nodes gave 3e-3 over 6.8 km */
#define HF_SOLAR_P_LINEAR 0.02 /* below this range of p, B0c(p) is linear to 4e-6 of itself */
enum { /* the per-entry sums (times the step weight and the interpolation share) */
    HF_SQ_BX, HF_SQ_BY, HF_SQ_BZ, /* B0c s: beam = n . this */
    HF_SQ_BH,                     /* B0c sin h: the reflected term's beam */
    HF_SQ_FG, HF_SQ_RS,           /* Dh P1(kb) and Dh (1 - kb): the background diffuse */
    HF_SQ_AX, HF_SQ_AY, HF_SQ_AZ, /* Dh kb s / sin h: circumsolar, horizontal receivers */
    HF_SQ_TX, HF_SQ_TY, HF_SQ_TZ, /* the same for tilted ones (Muneer's low-sun form below 0.1) */
    HF_SQ_DH,                     /* Dh while lit */
    HF_SQ_HOURS,                  /* the weight: sunshine */
    HF_SOLAR_Q
};

typedef struct hf_solar_entry {
    double t;    /* tan of the shading elevation */
    size_t step;
} hf_solar_entry;

static int hf_solar_entry_cmp(const void *a, const void *b)
{
    double x = ((const hf_solar_entry *)a)->t, y = ((const hf_solar_entry *)b)->t;
    return x < y ? -1 : x > y;
}

/* The sector path is exact for the model of section 5 up to the lit test at each direction's
 * own azimuth and the pressure interpolation; it needs per-step constants. */
static int hf_solar_sectors_apply(const hf_solar_ctx *c, size_t nsteps)
{
    return !c->o.linke_map && !c->o.coeff_bh && !c->o.coeff_dh && c->o.sun_radius_rad == 0.0 &&
           !c->o.no_shading && !c->in.instant &&
           nsteps / (size_t)c->bands > (size_t)HF_SOLAR_SECTOR_MIN * HF_SOLAR_BINS_PER_DIR * (size_t)c->o.directions;
}

/* One entry's sums at pressure ratio p into q[HF_SOLAR_Q]. */
static void hf_solar_entry_sums(const hf_solar_step *st, double p, double *q)
{
    double w = st->weight, m = p * st->m0;
    double b = st->g0 * hf_esra_beam_trans_m(m, st->linke);
    double kb = b / st->g0, dh = st->g0 * st->fd, lo;
    q[HF_SQ_BX] = w * b * st->sx;
    q[HF_SQ_BY] = w * b * st->sy;
    q[HF_SQ_BZ] = w * b * st->sz;
    q[HF_SQ_BH] = w * b * st->sinh;
    q[HF_SQ_FG] = w * dh * hf_muneer_fg_part(kb);
    q[HF_SQ_RS] = w * dh * (1.0 - kb);
    q[HF_SQ_AX] = w * dh * kb * st->sx / st->sinh;
    q[HF_SQ_AY] = w * dh * kb * st->sy / st->sinh;
    q[HF_SQ_AZ] = w * dh * kb * st->sz / st->sinh;
    if (st->h >= 0.1) {
        q[HF_SQ_TX] = q[HF_SQ_AX];
        q[HF_SQ_TY] = q[HF_SQ_AY];
        q[HF_SQ_TZ] = q[HF_SQ_AZ];
    } else {
        lo = w * dh * kb / (cos(st->elev) * hf_muneer_low_sun(st->h));
        q[HF_SQ_TX] = lo * st->sx;
        q[HF_SQ_TY] = lo * st->sy;
        q[HF_SQ_TZ] = 0.0;
    }
    q[HF_SQ_DH] = w * dh;
    q[HF_SQ_HOURS] = w;
}

/* The pressure nodes span the options' height_min..height_max, not each block's heights. */
static int hf_solar_anchored(const hf_solar_ctx *c)
{
    return c->o.height_min != 0.0 || c->o.height_max != 0.0;
}

/* The pressure nodes pn[0..nn) of a block of samples, over which the sums of a step are
 * interpolated in the pressure ratio p: one node on a flat block, two (linear) over a small
 * range of p, else maxn (the sector sums: 3, quadratic, or HF_SOLAR_NODES_ANCHORED when
 * anchored; HF_SOLAR_DAY_NODES for the day path), at heights spread evenly over the block's
 * finite heights, or over the options' height_min..height_max when they are set (then the same
 * for every grid of the raster). Returns nn. The one place that chooses them (both fast paths
 * call it). */
static int hf_solar_block_nodes(const hfvis_grid *g, const hf_solar_ctx *c, const hf_solar_block *blk,
                                int maxn, double *pn)
{
    double zmin = HFVIS__INF, zmax = -HFVIS__INF;
    int nn, j, x, y, anchored = hf_solar_anchored(c);
    if (anchored) { /* the caller's span */
        zmin = c->o.height_min;
        zmax = c->o.height_max;
    } else
        for (y = blk->y0; y < blk->y1; y++)
            for (x = blk->x0; x < blk->x1; x++) {
                double z = (double)g->z[(ptrdiff_t)y * g->stride + x];
                if (!isfinite(z)) continue;
                if (z < zmin) zmin = z;
                if (z > zmax) zmax = z;
            }
    if (!(zmin <= zmax)) zmin = zmax = 0.0; /* no finite height */
    nn = zmin == zmax ? 1 : hf_esra_pressure(zmin) - hf_esra_pressure(zmax) < HF_SOLAR_P_LINEAR ? 2 : maxn;
    for (j = 0; j < nn; j++)
        pn[j] = hf_esra_pressure(nn == 1 ? zmin : zmax + (zmin - zmax) * (double)j / (double)(nn - 1));
    return nn;
}

/* The Lagrange weights L[0..nn) of pressure ratio p over the nodes pn. */
static void hf_solar_lagrange(int nn, const double *pn, double p, double *L)
{
    int j, m;
    for (j = 0; j < nn; j++) {
        L[j] = 1.0;
        for (m = 0; m < nn; m++)
            if (m != j) L[j] *= (p - pn[m]) / (pn[j] - pn[m]);
    }
}

static hfvis_status hf_solar_sectors(const hfvis_grid *g, hf_solar_run *r, int K, const double *az,
                                     const float *cellmap, const float *sky, const hf_solar_block *blk)
{
    int NB = HF_SOLAR_BINS_PER_DIR * K, j, b, nn, x, y;
    int maxn = hf_solar_anchored(&r->c) ? HF_SOLAR_NODES_ANCHORED : HF_SOLAR_NODES;
    size_t n = hf_grid_count(g), ngroups = (size_t)r->c.bands * (size_t)NB, q, i, e;
    size_t *start = NULL, *fill = NULL;
    hf_solar_entry *ent = NULL;
    int *bk = NULL, *nonempty = NULL, *nne = NULL;
    double *sums = NULL, *tdh = NULL, *bw = NULL, *bdir = NULL, *th = NULL, pn[HF_SOLAR_NODES_ANCHORED],
           turn = 2.0 * HFVIS__PI;
    start = (size_t *)hfvis__alloc_array(r->al, ngroups + 1, sizeof(size_t));
    fill = (size_t *)hfvis__alloc_array(r->al, ngroups + 1, sizeof(size_t));
    ent = (hf_solar_entry *)hfvis__alloc_array(r->al, r->nsteps + 1, sizeof(hf_solar_entry));
    sums = (double *)hfvis__alloc_array(r->al, r->nsteps + 1, sizeof(double) * (size_t)maxn * HF_SOLAR_Q);
    tdh = (double *)hfvis__alloc_array(r->al, (size_t)r->c.bands, sizeof(double));
    bk = (int *)hfvis__alloc_array(r->al, (size_t)NB, 2 * sizeof(int));
    bw = (double *)hfvis__alloc_array(r->al, (size_t)NB, sizeof(double));
    bdir = (double *)hfvis__alloc_array(r->al, (size_t)NB, 2 * sizeof(double));
    nonempty = (int *)hfvis__alloc_array(r->al, ngroups, sizeof(int));
    nne = (int *)hfvis__alloc_array(r->al, (size_t)r->c.bands, sizeof(int));
    th = (double *)hfvis__alloc_array(r->al, (size_t)K, sizeof(double));
    if (!start || !fill || !ent || !sums || !tdh || !bk || !bw || !bdir || !nonempty || !nne || !th) {
        hfvis__free(r->al, start); hfvis__free(r->al, fill); hfvis__free(r->al, ent);
        hfvis__free(r->al, sums); hfvis__free(r->al, tdh); hfvis__free(r->al, bk);
        hfvis__free(r->al, bw); hfvis__free(r->al, bdir); hfvis__free(r->al, nonempty);
        hfvis__free(r->al, nne); hfvis__free(r->al, th);
        return HFVIS_ERR_OUT_OF_MEMORY;
    }
    /* the bins: centre psi_b = 2 pi b / NB, its two map directions and weight, its look vector */
    for (b = 0; b < NB; b++) {
        double psi = turn * (double)b / (double)NB;
        hf_solar_bracket(az, K, psi, bk + 2 * b, bk + 2 * b + 1, bw + b);
        bdir[2 * b] = cos(psi);
        bdir[2 * b + 1] = sin(psi);
    }
    /* group the steps by (band, bin), each group sorted by tan e */
    for (i = 0; i <= ngroups; i++) start[i] = 0;
    for (b = 0; b < r->c.bands; b++) tdh[b] = 0.0;
    for (q = 0; q < r->nsteps; q++) {
        const hf_solar_step *st = r->steps + q;
        int bin = (int)floor(st->psi / turn * (double)NB + 0.5) % NB;
        tdh[st->band] += st->weight * st->g0 * st->fd;
        start[(size_t)st->band * (size_t)NB + (size_t)bin + 1]++;
    }
    for (i = 0; i < ngroups; i++) start[i + 1] += start[i];
    for (i = 0; i <= ngroups; i++) fill[i] = start[i];
    for (q = 0; q < r->nsteps; q++) {
        const hf_solar_step *st = r->steps + q;
        int bin = (int)floor(st->psi / turn * (double)NB + 0.5) % NB;
        hf_solar_entry *en = ent + fill[(size_t)st->band * (size_t)NB + (size_t)bin]++;
        en->t = tan(st->elev);
        en->step = q;
    }
    for (b = 0; b < r->c.bands; b++) {
        nne[b] = 0;
        for (j = 0; j < NB; j++) {
            size_t gi = (size_t)b * (size_t)NB + (size_t)j;
            if (start[gi + 1] == start[gi]) continue;
            nonempty[(size_t)b * (size_t)NB + (size_t)nne[b]++] = j;
            if (start[gi + 1] - start[gi] > 1)
                qsort(ent + start[gi], start[gi + 1] - start[gi], sizeof(hf_solar_entry), hf_solar_entry_cmp);
        }
    }
    /* pressure nodes over the block's heights, and each group's sums from the top */
    nn = hf_solar_block_nodes(g, &r->c, blk, maxn, pn);
    for (i = 0; i < ngroups; i++) {
        double acc[HF_SOLAR_NODES_ANCHORED * HF_SOLAR_Q];
        int a;
        for (a = 0; a < nn * HF_SOLAR_Q; a++) acc[a] = 0.0;
        for (e = start[i + 1]; e-- > start[i];) {
            double *s = sums + e * (size_t)nn * HF_SOLAR_Q;
            for (j = 0; j < nn; j++) {
                hf_solar_entry_sums(r->steps + ent[e].step, pn[j], s + j * HF_SOLAR_Q);
                for (a = 0; a < HF_SOLAR_Q; a++) s[j * HF_SOLAR_Q + a] = acc[j * HF_SOLAR_Q + a] += s[j * HF_SOLAR_Q + a];
            }
        }
    }
    /* per sample: the suffix of each bin above its threshold */
    for (y = blk->r0; y < blk->r1; y++)
        for (x = blk->c0; x < blk->c1; x++) {
            hf_solar_point *pt = r->pts + (i = (size_t)y * (size_t)g->width + (size_t)x);
            const float *hz = cellmap + i * (size_t)K;
            double L[HF_SOLAR_NODES_ANCHORED];
            int horizon = r->c.o.diffuse == HFVIS_SOLAR_DIFFUSE_HORIZON;
            if (!isfinite(pt->p) || isnan(pt->nz)) continue;
            if (sky) pt->sky_ratio = (double)sky[i] / pt->r_sky;
            for (j = 0; j < K; j++) th[j] = tan((double)hz[j]);
            hf_solar_lagrange(nn, pn, pt->p, L);
            for (b = 0; b < r->c.bands; b++) {
                double S[HF_SOLAR_NODES_ANCHORED * HF_SOLAR_Q], T[HF_SOLAR_Q], *a = r->acc + ((size_t)b * n + i) * 4;
                int t, u;
                for (t = 0; t < nn * HF_SOLAR_Q; t++) S[t] = 0.0;
                for (u = 0; u < nne[b]; u++) {
                    int bin = nonempty[(size_t)b * (size_t)NB + (size_t)u];
                    size_t gi = (size_t)b * (size_t)NB + (size_t)bin, lo = start[gi], hi = start[gi + 1];
                    double thr = (1.0 - bw[bin]) * th[bk[2 * bin]] + bw[bin] * th[bk[2 * bin + 1]], tc;
                    const double *s;
                    tc = pt->nz > 0.0 ? -(pt->nx * bdir[2 * bin] + pt->ny * bdir[2 * bin + 1]) / pt->nz : HFVIS__INF;
                    if (!(thr >= tc)) thr = tc; /* the receiver's own tangent plane (and NaN) */
                    if (!(ent[hi - 1].t > thr)) continue;
                    while (lo < hi) { /* the first entry above the threshold */
                        size_t mid = lo + (hi - lo) / 2;
                        if (ent[mid].t > thr) hi = mid;
                        else lo = mid + 1;
                    }
                    s = sums + lo * (size_t)nn * HF_SOLAR_Q;
                    for (t = 0; t < nn * HF_SOLAR_Q; t++) S[t] += s[t];
                }
                for (t = 0; t < HF_SOLAR_Q; t++) {
                    T[t] = 0.0;
                    for (j = 0; j < nn; j++) T[t] += L[j] * S[j * HF_SOLAR_Q + t];
                }
                a[0] = pt->nx * T[HF_SQ_BX] + pt->ny * T[HF_SQ_BY] + pt->nz * T[HF_SQ_BZ];
                if (pt->tilted || horizon) {
                    double bg = (pt->fg * T[HF_SQ_FG] + pt->r_sky * T[HF_SQ_RS]) * pt->sky_ratio;
                    double shade = (tdh[b] - T[HF_SQ_DH]) * (pt->r_sky + pt->fg * 0.252271) * pt->sky_ratio;
                    a[1] = bg + shade + (pt->tilted ? pt->nx * T[HF_SQ_TX] + pt->ny * T[HF_SQ_TY] + pt->nz * T[HF_SQ_TZ]
                                                    : pt->nx * T[HF_SQ_AX] + pt->ny * T[HF_SQ_AY] + pt->nz * T[HF_SQ_AZ]);
                } else {
                    a[1] = tdh[b];
                }
                a[2] = pt->tilted ? pt->albedo * (T[HF_SQ_BH] + tdh[b]) * (1.0 - pt->nz) * 0.5 : 0.0;
                a[3] = T[HF_SQ_HOURS];
            }
        }
    hfvis__free(r->al, start); hfvis__free(r->al, fill); hfvis__free(r->al, ent);
    hfvis__free(r->al, sums); hfvis__free(r->al, tdh); hfvis__free(r->al, bk);
    hfvis__free(r->al, bw); hfvis__free(r->al, bdir); hfvis__free(r->al, nonempty);
    hfvis__free(r->al, nne); hfvis__free(r->al, th);
    return HFVIS_OK;
}

/* The step loop over one block's samples (the fast path when the sector sums do not apply). */
static void hf_solar_loop(const hfvis_grid *g, hf_solar_run *r, int K, const float *cellmap,
                          const float *sky, const int *kk, const double *kw, const hf_solar_block *blk)
{
    size_t n = hf_grid_count(g), q;
    int horizon = r->c.o.diffuse == HFVIS_SOLAR_DIFFUSE_HORIZON, x, y;
    for (y = blk->r0; y < blk->r1; y++)
        for (x = blk->c0; x < blk->c1; x++) {
            size_t i = (size_t)y * (size_t)g->width + (size_t)x;
            hf_solar_point *pt = r->pts + i;
            const float *hz = cellmap ? cellmap + i * (size_t)K : NULL;
            double acc[4] = { 0.0, 0.0, 0.0, 0.0 }, *a;
            int band = r->nsteps ? r->steps[0].band : 0;
            if (!isfinite(pt->p) || isnan(pt->nz)) continue;
            if (sky) pt->sky_ratio = (double)sky[i] / pt->r_sky;
            for (q = 0; q < r->nsteps; q++) {
                const hf_solar_step *stp = r->steps + q;
                double vis = 1.0;
                if (stp->band != band) {
                    a = r->acc + ((size_t)band * n + i) * 4;
                    a[0] = acc[0]; a[1] = acc[1]; a[2] = acc[2]; a[3] = acc[3];
                    acc[0] = acc[1] = acc[2] = acc[3] = 0.0;
                    band = stp->band;
                }
                if (!r->c.o.no_shading) {
                    double hor = (1.0 - kw[q]) * (double)hz[kk[2 * q]] + kw[q] * (double)hz[kk[2 * q + 1]];
                    vis = hf_solar_visible(stp->elev, hor, r->c.o.sun_radius_rad);
                }
                hf_solar_point_step(stp, pt, vis, horizon, acc);
            }
            a = r->acc + ((size_t)band * n + i) * 4;
            a[0] = acc[0]; a[1] = acc[1]; a[2] = acc[2]; a[3] = acc[3];
        }
}

/* ------------------------------------------------ 7b. the day path (short periods, per step) */
/* With one Linke factor per step and no coefficient rasters (a hard sun or a disc), a step's
 * terms at a sample are its lit flag u (sun above the horizon interpolated from the map exactly
 * as hf_solar_loop does, and in front of the tangent plane), its visible fraction v (u for a hard
 * sun), the normal n and one function of the pressure ratio p, w B0c(p), interpolated over the
 * block's pressure nodes (hf_solar_block_nodes, HF_SOLAR_DAY_NODES of them); kb and Muneer's
 * sky brightness P1(kb) follow from it. So each step's constants are made once per block, and
 * per sample and step the loop adds eight products: the samples run in chunks of HF_SOLAR_CHUNK
 * as structures of arrays, the step outside, so the compiler vectorizes the inner loop (its
 * iteration count a constant multiple of every vector width). Agrees with hf_solar_loop within
 * the interpolation of p (test_solar.c day_path_equals_step_loop). */
#define HF_SOLAR_CHUNK 64
#define HF_SOLAR_DAY_NODES 5 /* quartic in p: the outputs within 3e-6 of the step loop's over
                                the Colorado tile's 2.8 km of relief, 1.5e-5 over 6 km */
typedef struct hf_solar_dstep {
    const float *hz0, *hz1;                  /* the step's two map planes */
    double c0, c1, elev, sx, sy, sz;         /* horizon weights (1 - kw, kw), the shading sun */
    double bw[HF_SOLAR_DAY_NODES];           /* w B0c at the nodes (0 for unused nodes) */
    double w, dhw, ikb, sinh, fd, ca, cb, cf; /* weight, w Dh, 1/(w G0), sin h, Tn Fd, circumsolar */
} hf_solar_dstep;

/* The day path applies (cheaper than hf_solar_loop whenever the map is read). */
static int hf_solar_day_apply(const hf_solar_ctx *c)
{
    return !c->o.linke_map && !c->o.coeff_bh && !c->o.coeff_dh && !c->o.no_shading;
}

/* A step's constants over the nodes pn[0..nn) (the map planes pl[k0], pl[k1]). */
static void hf_solar_dstep_set(const hf_solar_step *st, const float *const *pl, int k0, int k1,
                               double kw, int nn, const double *pn, hf_solar_dstep *d)
{
    int j;
    d->hz0 = pl[k0];
    d->hz1 = pl[k1];
    d->c0 = 1.0 - kw;
    d->c1 = kw;
    d->elev = st->elev;
    d->sx = st->sx;
    d->sy = st->sy;
    d->sz = st->sz;
    for (j = 0; j < HF_SOLAR_DAY_NODES; j++)
        d->bw[j] = j < nn ? st->weight * st->g0 * hf_esra_beam_trans_m(pn[j] * st->m0, st->linke) : 0.0;
    d->w = st->weight;
    d->dhw = st->weight * st->g0 * st->fd;
    d->ikb = 1.0 / (st->weight * st->g0);
    d->sinh = st->sinh;
    d->fd = st->fd;
    d->cf = st->fd / st->sinh; /* horizontal receivers and high sun: kb s / sin h */
    if (st->h >= 0.1) {
        d->ca = d->cf;
        d->cb = 0.0;
    } else { /* low sun on a tilted receiver: Muneer's form with the horizontal direction */
        d->ca = 0.0;
        d->cb = st->fd / (cos(st->elev) * hf_muneer_low_sun(st->h));
    }
}

/* The per-chunk arrays: normal, Lagrange weights, visible fraction, the eight sums. */
enum { HF_DC_NX, HF_DC_NY, HF_DC_NZ, HF_DC_L0, HF_DC_VF = HF_DC_L0 + HF_SOLAR_DAY_NODES,
       HF_DC_B, HF_DC_BH, HF_DC_H, HF_DC_FG, HF_DC_DL, HF_DC_KB, HF_DC_CT, HF_DC_CF, HF_DC_N };
#define HF_DC(c, k) ((c) + (k) * HF_SOLAR_CHUNK)

/* One step over a chunk: the sums of the lit samples (c: HF_DC_N arrays of HF_SOLAR_CHUNK). */
static void hf_solar_day_step(const hf_solar_dstep *d, double *c)
{
    const double *restrict nx = HF_DC(c, HF_DC_NX), *restrict ny = HF_DC(c, HF_DC_NY);
    const double *restrict nz = HF_DC(c, HF_DC_NZ), *restrict vf = HF_DC(c, HF_DC_VF);
    const double *restrict l0 = HF_DC(c, HF_DC_L0), *restrict l1 = HF_DC(c, HF_DC_L0 + 1);
    const double *restrict l2 = HF_DC(c, HF_DC_L0 + 2), *restrict l3 = HF_DC(c, HF_DC_L0 + 3);
    const double *restrict l4 = HF_DC(c, HF_DC_L0 + 4);
    double *restrict ab = HF_DC(c, HF_DC_B), *restrict abh = HF_DC(c, HF_DC_BH);
    double *restrict ah = HF_DC(c, HF_DC_H), *restrict afg = HF_DC(c, HF_DC_FG);
    double *restrict adl = HF_DC(c, HF_DC_DL), *restrict akb = HF_DC(c, HF_DC_KB);
    double *restrict act = HF_DC(c, HF_DC_CT), *restrict acf = HF_DC(c, HF_DC_CF);
    const double sx = d->sx, sy = d->sy, sz = d->sz, b0 = d->bw[0], b1 = d->bw[1], b2 = d->bw[2];
    const double b3 = d->bw[3], b4 = d->bw[4], w = d->w, dhw = d->dhw, ikb = d->ikb;
    const double sinh_ = d->sinh, fd = d->fd, ca = d->ca, cb = d->cb, cf = d->cf;
    int i;
    for (i = 0; i < HF_SOLAR_CHUNK; i++) {
        double shh = nx[i] * sx + ny[i] * sy, sh = shh + nz[i] * sz;
        double u = vf[i] > 0.0 ? 1.0 : 0.0, v = vf[i], bw, kb, vb; /* vf: never NaN */
        u = sh > 0.0 ? u : 0.0;
        v = sh > 0.0 ? v : 0.0;
        bw = l0[i] * b0 + l1[i] * b1 + l2[i] * b2 + l3[i] * b3 + l4[i] * b4;
        kb = bw * ikb;
        vb = v * bw;
        ab[i] += vb * sh;
        abh[i] += vb * sinh_;
        ah[i] += v * w;
        afg[i] += u * dhw * hf_muneer_fg_part(kb);
        adl[i] += u * dhw;
        akb[i] += u * bw * fd;
        act[i] += vb * (ca * sh + cb * shh);
        acf[i] += vb * (cf * sh);
    }
}

/* The hard sun's lit test over a whole chunk (hf_solar_loop's: the horizon interpolated in
 * azimuth, NaN never below the sun), vectorized. */
static void hf_solar_day_lit(const hf_solar_dstep *d, const float *restrict h0, const float *restrict h1,
                             double *restrict vf)
{
    const double c0 = d->c0, c1 = d->c1, e = d->elev;
    int j;
    for (j = 0; j < HF_SOLAR_CHUNK; j++) {
        double hor = c0 * (double)h0[j] + c1 * (double)h1[j];
        vf[j] = e > hor ? 1.0 : 0.0;
    }
}

/* The day path over one block's samples: steps [0, nsteps) of r, direction k's plane pl[k]. */
static hfvis_status hf_solar_day(const hfvis_grid *g, hf_solar_run *r, const float *const *pl,
                                 const float *sky, const int *kk, const double *kw,
                                 const hf_solar_block *blk)
{
    size_t n = hf_grid_count(g), q, q0, q1;
    double pn[HF_SOLAR_DAY_NODES], *c;
    hf_solar_dstep *ds;
    int nn = hf_solar_block_nodes(g, &r->c, blk, HF_SOLAR_DAY_NODES, pn);
    int horizon = r->c.o.diffuse == HFVIS_SOLAR_DIFFUSE_HORIZON, x0, y, j, k;
    double radius = r->c.o.sun_radius_rad;
    ds = (hf_solar_dstep *)hfvis__alloc_array(r->al, r->nsteps + 1, sizeof(hf_solar_dstep));
    c = (double *)hfvis__alloc_array(r->al, HF_DC_N * HF_SOLAR_CHUNK, sizeof(double));
    if (!ds || !c) {
        hfvis__free(r->al, ds);
        hfvis__free(r->al, c);
        return HFVIS_ERR_OUT_OF_MEMORY;
    }
    for (q = 0; q < r->nsteps; q++)
        hf_solar_dstep_set(r->steps + q, pl, kk[2 * q], kk[2 * q + 1], kw[q], nn, pn, ds + q);
    for (y = blk->r0; y < blk->r1; y++)
        for (x0 = blk->c0; x0 < blk->c1; x0 += HF_SOLAR_CHUNK) {
            int cnt = blk->c1 - x0 < HF_SOLAR_CHUNK ? blk->c1 - x0 : HF_SOLAR_CHUNK;
            size_t row = (size_t)y * (size_t)g->width + (size_t)x0;
            for (k = 0; k < HF_DC_N * HF_SOLAR_CHUNK; k++) c[k] = 0.0; /* padding: never lit */
            for (j = 0; j < cnt; j++) {
                const hf_solar_point *pt = r->pts + row + (size_t)j;
                double L[HF_SOLAR_DAY_NODES];
                if (!isfinite(pt->p) || isnan(pt->nz)) continue; /* holes: never lit, not stored */
                hf_solar_lagrange(nn, pn, pt->p, L);
                HF_DC(c, HF_DC_NX)[j] = pt->nx;
                HF_DC(c, HF_DC_NY)[j] = pt->ny;
                HF_DC(c, HF_DC_NZ)[j] = pt->nz;
                for (k = 0; k < nn; k++) HF_DC(c, HF_DC_L0 + k)[j] = L[k];
            }
            for (q0 = 0; q0 < r->nsteps; q0 = q1) { /* one band's steps at a time */
                int band = r->steps[q0].band;
                double tdh = 0.0;
                for (k = HF_DC_B * HF_SOLAR_CHUNK; k < HF_DC_N * HF_SOLAR_CHUNK; k++) c[k] = 0.0;
                for (q1 = q0; q1 < r->nsteps && r->steps[q1].band == band; q1++) {
                    const hf_solar_dstep *d = ds + q1;
                    const float *h0 = d->hz0 + row, *h1 = d->hz1 + row;
                    double *vf = HF_DC(c, HF_DC_VF);
                    tdh += d->dhw;
                    if (radius == 0.0 && cnt == HF_SOLAR_CHUNK)
                        hf_solar_day_lit(d, h0, h1, vf);
                    else
                        for (j = 0; j < cnt; j++) { /* the lit test as hf_solar_loop's */
                            double hor = d->c0 * (double)h0[j] + d->c1 * (double)h1[j];
                            double vis = radius > 0.0 ? hf_solar_visible(d->elev, hor, radius) : d->elev > hor ? 1.0 : 0.0;
                            vf[j] = vis > 0.0 ? vis : 0.0; /* NaN (no horizon): shadow, as the loop */
                        }
                    hf_solar_day_step(d, c);
                }
                for (j = 0; j < cnt; j++) { /* the sums to the band's irradiation (as section 7) */
                    size_t i = row + (size_t)j;
                    hf_solar_point *pt = r->pts + i;
                    double *a = r->acc + ((size_t)band * n + i) * 4;
                    double bh = HF_DC(c, HF_DC_BH)[j], dl = HF_DC(c, HF_DC_DL)[j];
                    if (!isfinite(pt->p) || isnan(pt->nz)) continue;
                    if (sky) pt->sky_ratio = (double)sky[i] / pt->r_sky;
                    a[0] = pt->tilted ? HF_DC(c, HF_DC_B)[j] : bh;
                    if (pt->tilted || horizon) {
                        double bg = (pt->fg * HF_DC(c, HF_DC_FG)[j] + pt->r_sky * (dl - HF_DC(c, HF_DC_KB)[j])) * pt->sky_ratio;
                        double shade = (tdh - dl) * (pt->r_sky + pt->fg * 0.252271) * pt->sky_ratio;
                        a[1] = bg + shade + HF_DC(c, pt->tilted ? HF_DC_CT : HF_DC_CF)[j];
                    } else {
                        a[1] = tdh;
                    }
                    a[2] = pt->tilted ? pt->albedo * (bh + tdh) * (1.0 - pt->nz) * 0.5 : 0.0;
                    a[3] = HF_DC(c, HF_DC_H)[j];
                }
            }
        }
    hfvis__free(r->al, ds);
    hfvis__free(r->al, c);
    return HFVIS_OK;
}

/* The blocks of the run: the whole grid at the input's site, or hf_solar_split of the raster's
 * sites (then SPA's instant part from the hourly table when the raster has more than one block:
 * a window's blocks take it exactly when the whole raster's do). */
static hfvis_status hf_solar_run_blocks(const hfvis_grid *g, hf_solar_run *r, hf_solar_blocks *B,
                                        hf_spa_eph **eph)
{
    hfvis_status st;
    int days = r->c.in.instant ? 1 : r->c.in.days;
    memset(B, 0, sizeof *B);
    B->al = r->al;
    *eph = NULL;
    if (!hf_solar_per_sample(&r->c.in))
        return hf_solar_block_add(g, &r->c, 0, 0, g->width, g->height, r->c.lat, r->c.lon, 0.0, B);
    st = hf_solar_split(g, &r->c, r->c.o.site_tolerance_rad, 0, 0, r->c.ew, r->c.eh, B);
    if (st == HFVIS_OK && B->split && r->c.o.model != HFVIS_SUN_RSUN) {
        *eph = (hf_spa_eph *)hfvis__alloc_array(r->al, (size_t)days * HF_SOLAR_EPH_PER_DAY, sizeof(hf_spa_eph));
        if (!*eph) st = HFVIS_ERR_OUT_OF_MEMORY;
        else hf_solar_eph_fill(&r->c, days, *eph);
    }
    if (st != HFVIS_OK) {
        hfvis__free(r->al, B->b);
        B->b = NULL;
    }
    return st;
}

/* Set the run's site to a block's (its steps anew when the grid has more than one site). */
static hfvis_status hf_solar_run_site(hf_solar_run *r, const hf_solar_block *blk)
{
    if (!hf_solar_per_sample(&r->c.in)) return HFVIS_OK;
    r->c.lat = blk->lat;
    r->c.lon = blk->lon;
    r->c.gamma = blk->gamma;
    return hf_solar_run_steps(r);
}

/* ------------------------------------------------ 7c. the map's directions the period reads */
#define HF_SOLAR_MARK_BLOCK_DAYS 366 /* blocks x days up to which the steps of every block are
                                        made twice (to find the directions, then to integrate);
                                        beyond, every direction is made */

/* Mark in need[K] the map directions the steps of r read: the two around each step's azimuth
 * (hf_solar_loop, the day path) and the two around the centre of its azimuth bin (the sector
 * sums). */
static void hf_solar_mark(const hf_solar_run *r, int K, const double *az, unsigned char *need)
{
    int NB = HF_SOLAR_BINS_PER_DIR * K, k0, k1, bin;
    double w, turn = 2.0 * HFVIS__PI;
    size_t q;
    for (q = 0; q < r->nsteps; q++) {
        double psi = r->steps[q].psi;
        hf_solar_bracket(az, K, psi, &k0, &k1, &w);
        need[k0] = need[k1] = 1;
        bin = (int)floor(psi / turn * (double)NB + 0.5) % NB;
        hf_solar_bracket(az, K, turn * (double)bin / (double)NB, &k0, &k1, &w);
        need[k0] = need[k1] = 1;
    }
}

/* need[K]: the directions the period's steps read over every block (hf_solar_mark; every one
 * beyond HF_SOLAR_MARK_BLOCK_DAYS blocks x days, or for HORIZON over Horn's planes, which reads
 * the whole map; none without shading otherwise). r's steps are left those of the last block. */
static hfvis_status hf_solar_need(hf_solar_run *r, const hf_solar_blocks *B, int K, const double *az,
                                  unsigned char *need)
{
    int days = r->c.in.instant ? 1 : r->c.in.days, k;
    int all = r->c.o.diffuse == HFVIS_SOLAR_DIFFUSE_HORIZON && r->c.o.normals == HFVIS_SOLAR_NORMALS_HORN;
    hfvis_status st = HFVIS_OK;
    size_t bi;
    for (k = 0; k < K; k++) need[k] = (unsigned char)all;
    if (all || r->c.o.no_shading) return HFVIS_OK;
    if (B->n == 1 || (double)B->n * (double)days <= HF_SOLAR_MARK_BLOCK_DAYS) {
        for (bi = 0; bi < B->n && st == HFVIS_OK; bi++)
            if ((st = hf_solar_run_site(r, B->b + bi)) == HFVIS_OK) hf_solar_mark(r, K, az, need);
    } else {
        for (k = 0; k < K; k++) need[k] = 1;
    }
    return st;
}

/* The horizon planes of need: *map holds them (direction order, compact), pl[k] points to
 * direction k's plane or is NULL (never read). Made by hf_horizon_planes, each plane
 * bit-identical to the whole map's. */
static hfvis_status hf_solar_map(const hfvis_grid *g, const hfvis_allocator *al, int K, const unsigned char *need,
                                 const hfvis_sweep_options *s, float **map, const float **pl)
{
    size_t n = hf_grid_count(g), used = 0;
    float **wp = (float **)hfvis__alloc_array(al, (size_t)K, sizeof(float *));
    hfvis_status st = wp ? HFVIS_OK : HFVIS_ERR_OUT_OF_MEMORY;
    int k;
    *map = NULL;
    for (k = 0; k < K; k++) used += need[k];
    if (st == HFVIS_OK && used) {
        *map = (float *)hfvis__alloc_array(al, n * used, sizeof(float)); /* n K fits */
        if (!*map) st = HFVIS_ERR_OUT_OF_MEMORY;
    }
    for (k = 0, used = 0; k < K && st == HFVIS_OK; k++) {
        wp[k] = need[k] ? *map + n * used++ : NULL;
        pl[k] = wp[k];
    }
    if (st == HFVIS_OK && used) st = hf_horizon_planes(g, K, s, need, wp);
    hfvis__free(al, wp);
    return st;
}

/* -------------------------------------------------------------------- 8. the public routines */
hfvis_status hfvis_solar_irradiation(const hfvis_grid *g, const hfvis_solar_input *in,
                                     const hfvis_solar_options *opts, const hfvis_solar_output *out)
{
    hf_solar_run r;
    hf_solar_blocks B;
    hf_spa_eph *eph = NULL;
    hfvis_status st;
    hfvis_sweep_options s;
    float *map = NULL, *cellmap = NULL, *sky = NULL;
    const float *src = NULL; /* the whole direction-major map (the caller's or map), when there is one */
    const float **pl = NULL; /* direction k's plane, NULL where never read; NULL: no shading */
    unsigned char *need = NULL; /* the directions read (hf_solar_need) */
    double *az = NULL;
    int K, horn_sky, k;
    size_t n, i, bi;
    if ((st = hf_solar_run_init(g, in, opts, out, 0, &r)) != HFVIS_OK) return st;
    n = hf_grid_count(g);
    K = r.c.o.directions;
    s = hf_solar_map_sweep(&r.c);
    B.b = NULL;
    B.n = 0;
    st = hf_solar_run_blocks(g, &r, &B, &eph);
    r.c.eph = eph;
    /* HORIZON's visible sky over Horn's tangent planes is read from the whole map (every
     * direction); else the map holds only the directions the steps read (hf_solar_map) */
    horn_sky = r.c.o.diffuse == HFVIS_SOLAR_DIFFUSE_HORIZON && r.c.o.normals == HFVIS_SOLAR_NORMALS_HORN;
    if (st == HFVIS_OK && (!r.c.o.no_shading || horn_sky)) {
        if (n > SIZE_MAX / sizeof(float) / (size_t)K) st = HFVIS_ERR_LIMIT;
        if (st == HFVIS_OK) {
            az = (double *)hfvis__alloc_array(r.al, (size_t)K, sizeof(double));
            pl = (const float **)hfvis__alloc_array(r.al, (size_t)K, sizeof(const float *));
            need = (unsigned char *)hfvis__alloc_array(r.al, (size_t)K, 1);
            map = r.c.o.horizon_map || !horn_sky ? NULL : (float *)hfvis__alloc_array(r.al, n * (size_t)K, sizeof(float));
            if (!az || !pl || !need || (!map && horn_sky && !r.c.o.horizon_map)) st = HFVIS_ERR_OUT_OF_MEMORY;
            if (st == HFVIS_OK) st = hfvis_sweep_azimuths(K, &s, az, NULL);
            if (st == HFVIS_OK) st = hf_solar_need(&r, &B, K, az, need);
            if (st == HFVIS_OK && map) st = hfvis_horizon_map(g, K, &s, map);
            else if (st == HFVIS_OK && !r.c.o.horizon_map) st = hf_solar_map(g, r.al, K, need, &s, &map, pl);
            if (r.c.o.horizon_map || horn_sky) { /* a whole map: its planes (only need's are read) */
                src = r.c.o.horizon_map ? r.c.o.horizon_map : map;
                for (k = 0; k < K && src; k++) pl[k] = need[k] ? src + (size_t)k * n : NULL;
            }
        }
    }
    if (st == HFVIS_OK && r.c.o.diffuse == HFVIS_SOLAR_DIFFUSE_HORIZON) {
        sky = (float *)hfvis__alloc_array(r.al, n, sizeof(float));
        if (!sky) st = HFVIS_ERR_OUT_OF_MEMORY;
        else if (horn_sky) {
            for (i = (size_t)r.c.rb * (size_t)g->width; i < (size_t)r.c.re * (size_t)g->width; i++) /* the samples read */
                if ((int)(i % (size_t)g->width) >= r.c.cb && (int)(i % (size_t)g->width) < r.c.ce)
                    sky[i] = (float)hf_solar_sky_seen(r.pts + i, K, az, src, n, i);
        } else st = hfvis_sky_light(g, K, 1.0f, 1.0f, &s, sky, g->width);
    }
    if (r.c.o.no_shading) { /* no map read by the steps */
        hfvis__free(r.al, pl);
        pl = NULL;
    }
    for (bi = 0; bi < B.n && st == HFVIS_OK; bi++) {
        hf_solar_block part = B.b[bi], *blk = &part;
        int *kk = NULL;
        double *kw = NULL;
        size_t q;
        int sectors, day;
        if (part.r0 >= part.r1 || part.c0 >= part.c1) continue; /* none of its samples computed */
        if ((st = hf_solar_run_site(&r, blk)) != HFVIS_OK) break;
        sectors = pl && hf_solar_sectors_apply(&r.c, r.nsteps);
        day = pl && !sectors && hf_solar_day_apply(&r.c);
        if (pl && !day && !cellmap) { /* sample-major: each sample's K horizons side by side */
            cellmap = (float *)hfvis__alloc_array(r.al, n * (size_t)K, sizeof(float));
            if (!cellmap) {
                st = HFVIS_ERR_OUT_OF_MEMORY;
                break;
            }
            for (k = 0; k < K; k++) /* the planes never read: 0 */
                for (i = 0; i < n; i++) cellmap[i * (size_t)K + (size_t)k] = pl[k] ? pl[k][i] : 0.0f;
        }
        if (sectors) {
            st = hf_solar_sectors(g, &r, K, az, cellmap, sky, blk);
            continue;
        }
        if (pl) { /* each step's two map directions and weight */
            kk = (int *)hfvis__alloc_array(r.al, r.nsteps + 1, 2 * sizeof(int));
            kw = (double *)hfvis__alloc_array(r.al, r.nsteps + 1, sizeof(double));
            if (!kk || !kw) st = HFVIS_ERR_OUT_OF_MEMORY;
            for (q = 0; q < r.nsteps && st == HFVIS_OK; q++)
                hf_solar_bracket(az, K, r.steps[q].psi, kk + 2 * q, kk + 2 * q + 1, kw + q);
        }
        if (st == HFVIS_OK && day) st = hf_solar_day(g, &r, pl, sky, kk, kw, blk);
        else if (st == HFVIS_OK) hf_solar_loop(g, &r, K, cellmap, sky, kk, kw, blk);
        hfvis__free(r.al, kk);
        hfvis__free(r.al, kw);
    }
    hfvis__free(r.al, B.b);
    hfvis__free(r.al, eph);
    hfvis__free(r.al, az);
    hfvis__free(r.al, cellmap);
    hfvis__free(r.al, map);
    hfvis__free(r.al, pl);
    hfvis__free(r.al, need);
    hfvis__free(r.al, sky);
    if (st != HFVIS_OK) {
        hf_solar_run_free(&r);
        return st;
    }
    return hf_solar_finish(g, &r, 0, out);
}

hfvis_status hfvis_solar_map_directions(const hfvis_grid *g, const hfvis_solar_input *in,
                                        const hfvis_solar_options *opts, unsigned char *need)
{
    hf_solar_run r;
    hf_solar_blocks B;
    hf_spa_eph *eph = NULL;
    hfvis_solar_output any;
    hfvis_sweep_options s;
    double *az = NULL;
    float probe = 0.0f;
    hfvis_status st;
    memset(&r, 0, sizeof r);
    memset(&any, 0, sizeof any);
    any.global = &probe; /* only checked, never written */
    if (!need) return HFVIS_ERR_INVALID_ARGUMENT;
    if ((st = hf_solar_setup(g, in, opts, &any, &r.c)) != HFVIS_OK) return st;
    r.al = r.c.o.sweep ? r.c.o.sweep->alloc : NULL;
    s = hf_solar_map_sweep(&r.c);
    B.b = NULL;
    if ((st = hf_solar_run_steps(&r)) == HFVIS_OK) st = hf_solar_run_blocks(g, &r, &B, &eph);
    r.c.eph = eph;
    if (st == HFVIS_OK) {
        az = (double *)hfvis__alloc_array(r.al, (size_t)r.c.o.directions, sizeof(double));
        st = az ? hfvis_sweep_azimuths(r.c.o.directions, &s, az, NULL) : HFVIS_ERR_OUT_OF_MEMORY;
    }
    if (st == HFVIS_OK) st = hf_solar_need(&r, &B, r.c.o.directions, az, need);
    hfvis__free(r.al, az);
    hfvis__free(r.al, B.b);
    hfvis__free(r.al, eph);
    hf_solar_run_free(&r);
    return st;
}

#define HF_SOLAR_REF_DENOM 1024 /* the oracle's ray toward the sun: within 0.002 deg of it */
#define HF_SOLAR_REF_DIRS 4      /* the oracle integrates the visible sky over 4K directions */

/* The oracle with per-sample sites: sample (x, y)'s own exact ray toward grid azimuth psi (as
 * hfvis_horizon_exact_naive's, denominator HF_SOLAR_REF_DENOM); o resolved, cr of
 * 2 HF_SOLAR_REF_DENOM entries. */
static double hf_solar_ray(const hfvis_grid *g, const hfvis_sweep_options *o, hf_cross *cr,
                           double psi, int x, int y)
{
    hf_ray ray = hf_ray_nearest(psi, HF_SOLAR_REF_DENOM);
    double L, scale;
    int P = hf_exact_geometry(cr, g, ray.a, ray.b, &L, &scale);
    return hf_tan_to_elevation(hf_exact_march(g, o->border, o->border == HFVIS_BORDER_OPEN ? 0 : o->border_cells,
                                              cr, P, L, scale, ray.a, ray.b, x, y,
                                              hf_radius_on(o) ? hf_exact_window(o->max_distance, scale) : -1));
}

/* The oracle's steps with per-sample sites: each sample's own site and steps (full SPA at every
 * instant, sunrise and sunset bisected there) and its own ray toward each step's sun. */
static hfvis_status hf_solar_reference_sites(const hfvis_grid *g, hf_solar_run *r,
                                             const hfvis_sweep_options *s)
{
    hfvis_sweep_options o = hf_opts_resolve(g, s);
    hf_cross *cr = (hf_cross *)hfvis__alloc_array(r->al, 2 * HF_SOLAR_REF_DENOM + 2, sizeof(hf_cross));
    hfvis_status st = cr ? HFVIS_OK : HFVIS_ERR_OUT_OF_MEMORY;
    size_t n = hf_grid_count(g), q;
    int x, y;
    for (y = 0; y < g->height && st == HFVIS_OK; y++)
        for (x = 0; x < g->width && st == HFVIS_OK; x++) {
            size_t i = (size_t)y * (size_t)g->width + (size_t)x;
            hf_solar_point *pt = r->pts + i;
            if (!isfinite(pt->p) || isnan(pt->nz)) continue;
            if (!hf_solar_site_of(&r->c, r->c.ox + x, r->c.oy + y, &r->c.lat, &r->c.lon, &r->c.gamma)) {
                st = HFVIS_ERR_INVALID_ARGUMENT;
                break;
            }
            if ((st = hf_solar_run_steps(r)) != HFVIS_OK) break;
            for (q = 0; q < r->nsteps; q++) {
                const hf_solar_step *stp = r->steps + q;
                double vis = r->c.o.no_shading ? 1.0
                           : hf_solar_visible(stp->elev, hf_solar_ray(g, &o, cr, stp->psi, x, y), r->c.o.sun_radius_rad);
                if (isnan(vis)) continue;
                hf_solar_point_step(stp, pt, vis, r->c.o.diffuse == HFVIS_SOLAR_DIFFUSE_HORIZON,
                                    r->acc + ((size_t)stp->band * n + i) * 4);
            }
        }
    hfvis__free(r->al, cr);
    return st;
}

hfvis_status hfvis_solar_irradiation_reference(const hfvis_grid *g, const hfvis_solar_input *in,
                                               const hfvis_solar_options *opts,
                                               const hfvis_solar_output *out)
{
    hf_solar_run r;
    hfvis_status st;
    hfvis_sweep_options s;
    float *hor = NULL;
    double *az = NULL;
    size_t n, i, q;
    int KR;
    if ((st = hf_solar_run_init(g, in, opts, out, 1, &r)) != HFVIS_OK) return st; /* every row */
    n = hf_grid_count(g);
    s = hf_solar_sweep(&r.c, HFVIS_RAYS_EXACT);
    s.receiver_x = s.receiver_y = s.receiver_width = s.receiver_height = 0; /* every receiver */
    KR = HF_SOLAR_REF_DIRS * r.c.o.directions;
    hor = (float *)hfvis__alloc_array(r.al, n * (size_t)HF_SOLAR_REF_DIRS, (size_t)r.c.o.directions * sizeof(float));
    az = (double *)hfvis__alloc_array(r.al, (size_t)KR, sizeof(double));
    if (!hor || !az) st = HFVIS_ERR_OUT_OF_MEMORY;
    if (st == HFVIS_OK && r.c.o.diffuse == HFVIS_SOLAR_DIFFUSE_HORIZON) {
        /* the visible sky: [P1] Eq. 5 per sector over the exact horizons of 4K directions, each
         * receiver's own rays (hfvis_horizon_exact_naive) along their actual azimuths */
        st = hfvis_sweep_azimuths(KR, &s, az, NULL);
        if (st == HFVIS_OK) st = hfvis_horizon_exact_naive(g, KR, &s, hor);
        for (i = 0; i < n && st == HFVIS_OK; i++)
            r.pts[i].sky_ratio = hf_solar_sky_seen(r.pts + i, KR, az, hor, n, i) / r.pts[i].r_sky;
    }
    s.ray_denominator = HF_SOLAR_REF_DENOM;
    if (st == HFVIS_OK && hf_solar_per_sample(&r.c.in)) st = hf_solar_reference_sites(g, &r, &s);
    for (q = 0; q < r.nsteps && st == HFVIS_OK && !hf_solar_per_sample(&r.c.in); q++) {
        const hf_solar_step *stp = r.steps + q;
        if (!r.c.o.no_shading) { /* each receiver's own exact ray toward the sun */
            s.azimuth0_rad = stp->psi;
            st = hfvis_horizon_exact_naive(g, 1, &s, hor);
        }
        for (i = 0; i < n && st == HFVIS_OK; i++) {
            hf_solar_point *pt = r.pts + i;
            double vis = r.c.o.no_shading ? 1.0 : hf_solar_visible(stp->elev, (double)hor[i], r.c.o.sun_radius_rad);
            if (!isfinite(pt->p) || isnan(pt->nz) || isnan(vis)) continue;
            hf_solar_point_step(stp, pt, vis, r.c.o.diffuse == HFVIS_SOLAR_DIFFUSE_HORIZON,
                                r.acc + ((size_t)stp->band * n + i) * 4);
        }
    }
    hfvis__free(r.al, hor);
    hfvis__free(r.al, az);
    if (st != HFVIS_OK) {
        hf_solar_run_free(&r);
        return st;
    }
    return hf_solar_finish(g, &r, 1, out);
}
