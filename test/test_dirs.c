/* test_dirs.c - split runs: every per-direction computation run as direction ranges that tile
 * [0, K) adds up to the single run. Horizon planes are bit-exact; the fused sums (light,
 * sky-view, visibility index) are bit-exact per group but associate differently across a split
 * (the visibility index too: its counts are gathered bilinearly, not integers), so they
 * are held to the rounding bound of a sum of non-negative terms (Higham, "Accuracy and
 * Stability of Numerical Algorithms", §4.2: |fl(sum) - sum| <= (n-1) u sum|t_i|). Also the
 * HFVISSUM partial-sum codec: round trip, every truncation, malformed headers, allocation
 * failures. */
#include "hfvis.h"
#include "test/test.h"

#include <float.h>
#include <stdint.h>
#include <stdlib.h>

#define W 29
#define H 21
#define KMAX 16
#define PARTS 4

/* Two orders of summing the same <= K non-negative group terms each stay within (K-1) u S of
 * the exact sum (u = DBL_EPSILON/2), so they differ by at most K * DBL_EPSILON * S. */
#define SPLIT_DOUBLE_REL(K) ((double)(K) * DBL_EPSILON)
/* A float output is the exact value times (1 + d), |d| <= FLT_EPSILON/2: P float parts and the
 * float single run differ by at most (P+1) * FLT_EPSILON/2 * (sum |part| + |full|); doubled for
 * the double-level sums underneath. */
#define SPLIT_FLOAT_FACTOR ((double)(PARTS + 1) * (double)FLT_EPSILON)

static float heights[W * H];
static float full[KMAX * W * H], part[KMAX * W * H];
static double dfull[3 * W * H], dpart[3 * W * H], dacc[3 * W * H];
static double fsum[3 * W * H];

/* Four ranges that tile [0, K), uneven and crossing the quarter-turn groups. */
static void split4(int K, int b[PARTS], int e[PARTS])
{
    b[0] = 0;
    e[0] = K > 3 ? K / 4 - (K >= 8 ? 1 : 0) : 1;
    if (e[0] < 1) e[0] = 1;
    b[1] = e[0]; e[1] = b[1] + (K - b[1]) / 3; if (e[1] <= b[1]) e[1] = b[1] + 1;
    b[2] = e[1]; e[2] = b[2] + (K - b[2]) / 2; if (e[2] <= b[2]) e[2] = b[2] + 1;
    b[3] = e[2]; e[3] = K;
}

static hfvis_grid make_grid(uint64_t seed)
{
    hfvis_grid g;
    hfvis_field f;
    memset(&f, 0, sizeof f);
    f.kind = HFVIS_FIELD_FBM;
    f.amplitude = 5.0;
    f.wavelength = 7.0;
    f.seed = seed;
    hfvis_field_generate(&f, W, H, W, heights);
    heights[6 * W + 9] = (float)NAN; /* a hole: NaN out, never occludes */
    g.z = heights;
    g.width = W;
    g.height = H;
    g.stride = W;
    g.cell_size = 1.25;
    return g;
}

static int same_bits(const float *a, const float *b, size_t n)
{
    return memcmp(a, b, n * sizeof(float)) == 0;
}

/* horizon_map over four ranges: each part's planes equal the full map's, bit for bit. */
TEST(horizon_map_split_is_bit_exact)
{
    static const int Ks[] = { 16, 6, 1, 4 };
    static const hfvis_border borders[] = { HFVIS_BORDER_OPEN, HFVIS_BORDER_WRAP };
    hfvis_grid g = make_grid(3);
    const size_t plane = (size_t)W * H;
    size_t ki, bi;
    for (ki = 0; ki < sizeof Ks / sizeof Ks[0]; ki++)
        for (bi = 0; bi < 2; bi++) {
            int K = Ks[ki], b[PARTS], e[PARTS], p;
            hfvis_sweep_options o = hfvis_sweep_options_default();
            o.border = borders[bi];
            o.azimuth0_rad = 0.3;
            CHECK_EQ_STATUS(hfvis_horizon_map(&g, K, &o, full), HFVIS_OK);
            if (K < PARTS) { /* one range per direction */
                for (p = 0; p < K; p++) {
                    o.direction_begin = p;
                    o.direction_end = p + 1;
                    CHECK_EQ_STATUS(hfvis_horizon_map(&g, K, &o, part), HFVIS_OK);
                    CHECK(same_bits(part, full + (size_t)p * plane, plane));
                }
                continue;
            }
            split4(K, b, e);
            for (p = 0; p < PARTS; p++) {
                o.direction_begin = b[p];
                o.direction_end = e[p];
                CHECK_EQ_STATUS(hfvis_horizon_map(&g, K, &o, part), HFVIS_OK);
                CHECK(same_bits(part, full + (size_t)b[p] * plane, (size_t)(e[p] - b[p]) * plane));
            }
        }
}

/* The finish of the full raw sums equals the finished routine bit for bit. */
TEST(direction_sums_finish_equals_routines)
{
    hfvis_grid g = make_grid(5);
    const int K = 12;
    const float sky = 1.75f, albedo = 0.6f;
    hfvis_sweep_options o = hfvis_sweep_options_default();
    float radiance[3 * 4 * 6];
    hfvis_env env;
    size_t i, n = (size_t)W * H;
    o.azimuth0_rad = -0.2;
    for (i = 0; i < 3 * 4 * 6; i++) radiance[i] = 0.25f + 0.125f * (float)(i % 7);
    env.radiance = radiance;
    env.n_theta = 4;
    env.n_phi = 6;
    env.channels = 3;

    CHECK_EQ_STATUS(hfvis_sky_view_factor(&g, K, &o, full, W), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_direction_sums(&g, K, HFVIS_SUM_SKY_VIEW, NULL, NULL, &o, dfull), HFVIS_OK);
    for (i = 0; i < n; i++) part[i] = (float)(1.0 + (-1.0 / (double)K) * dfull[i]);
    CHECK(same_bits(part, full, n));
    CHECK(isnan(dfull[6 * W + 9]));

    CHECK_EQ_STATUS(hfvis_sky_light(&g, K, sky, albedo, &o, full, W), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_direction_sums(&g, K, HFVIS_SUM_SKY_LIGHT, NULL, NULL, &o, dfull), HFVIS_OK);
    for (i = 0; i < n; i++) part[i] = (float)(0.0 + ((double)sky * (double)albedo) * dfull[i]);
    CHECK(same_bits(part, full, n));

    CHECK_EQ_STATUS(hfvis_env_light(&g, K, &env, albedo, &o, NULL, full, W), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_direction_sums(&g, K, HFVIS_SUM_ENV_LIGHT, &env, NULL, &o, dfull), HFVIS_OK);
    for (i = 0; i < 3 * n; i++) part[i] = (float)(0.0 + (double)albedo * dfull[i]);
    CHECK(same_bits(part, full, 3 * n));

    CHECK_EQ_STATUS(hfvis_visibility_count(&g, K, &o, NULL, full, W, NULL), HFVIS_OK);
    CHECK_EQ_STATUS(hfvis_direction_sums(&g, K, HFVIS_SUM_VISIBILITY, NULL, NULL, &o, dfull), HFVIS_OK);
    for (i = 0; i < n; i++) part[i] = (float)(0.0 + 1.0 * dfull[i]);
    CHECK(same_bits(part, full, n));
}

/* Four ranges of hfvis_direction_sums, added in range order, against the full sums: within
 * SPLIT_DOUBLE_REL; the finished floats at most one ulp apart. Axis directions only (K = 4,
 * open border) gather exactly, and then the visibility counts are integers that add up exactly. */
TEST(direction_sums_split_within_double_rounding)
{
    static const hfvis_sum_kind kinds[] = { HFVIS_SUM_SKY_VIEW, HFVIS_SUM_SKY_LIGHT,
                                            HFVIS_SUM_ENV_LIGHT, HFVIS_SUM_VISIBILITY };
    static const int Ks[] = { 16, 9 };
    hfvis_grid g = make_grid(8);
    float radiance[2 * 3 * 8];
    hfvis_env env;
    size_t i, n = (size_t)W * H, ki, kk;
    for (i = 0; i < 2 * 3 * 8; i++) radiance[i] = 0.5f + 0.25f * (float)(i % 5);
    env.radiance = radiance;
    env.n_theta = 3;
    env.n_phi = 8;
    env.channels = 2;
    for (ki = 0; ki < 2; ki++)
        for (kk = 0; kk < 4; kk++) {
            int K = Ks[ki], b[PARTS], e[PARTS], p, C = kinds[kk] == HFVIS_SUM_ENV_LIGHT ? 2 : 1;
            int ulp_ok = 1, within = 1;
            hfvis_sweep_options o = hfvis_sweep_options_default();
            o.border = HFVIS_BORDER_CLAMP;
            CHECK_EQ_STATUS(hfvis_direction_sums(&g, K, kinds[kk], &env, NULL, &o, dfull), HFVIS_OK);
            split4(K, b, e);
            for (i = 0; i < n * (size_t)C; i++) dacc[i] = 0.0;
            for (p = 0; p < PARTS; p++) {
                o.direction_begin = b[p];
                o.direction_end = e[p];
                CHECK_EQ_STATUS(hfvis_direction_sums(&g, K, kinds[kk], &env, NULL, &o, dpart), HFVIS_OK);
                for (i = 0; i < n * (size_t)C; i++) dacc[i] = p == 0 ? dpart[i] : dacc[i] + dpart[i];
            }
            for (i = 0; i < n * (size_t)C; i++) {
                double a = dacc[i], f = dfull[i];
                float fa, ff;
                if (isnan(f) || isnan(a)) {
                    within &= isnan(f) && isnan(a);
                    continue;
                }
                within &= fabs(a - f) <= SPLIT_DOUBLE_REL(K) * fabs(f);
                fa = (float)(1.0 - a / K);
                ff = (float)(1.0 - f / K);
                ulp_ok &= fa == ff || nextafterf(fa, ff) == ff;
            }
            CHECK(within);
            CHECK(ulp_ok);
        }
    {   /* K = 4: the four axis directions; integer counts, any split exact */
        hfvis_sweep_options o = hfvis_sweep_options_default();
        int k, exact = 1, integral = 1;
        CHECK_EQ_STATUS(hfvis_direction_sums(&g, 4, HFVIS_SUM_VISIBILITY, NULL, NULL, &o, dfull), HFVIS_OK);
        for (i = 0; i < n; i++) dacc[i] = 0.0;
        for (k = 3; k >= 0; k--) { /* added in reverse order on purpose */
            o.direction_begin = k;
            o.direction_end = k + 1;
            CHECK_EQ_STATUS(hfvis_direction_sums(&g, 4, HFVIS_SUM_VISIBILITY, NULL, NULL, &o, dpart), HFVIS_OK);
            for (i = 0; i < n; i++) dacc[i] += dpart[i];
        }
        for (i = 0; i < n; i++) {
            if (isnan(dfull[i])) continue;
            exact &= dacc[i] == dfull[i];
            integral &= dfull[i] == floor(dfull[i]);
        }
        CHECK(exact);
        CHECK(integral);
    }
}

/* The float outputs of the routines over four ranges: the visibility index, sky-view factor
 * and sky light shares add up within SPLIT_FLOAT_FACTOR of float rounding. */
TEST(float_routines_split)
{
    hfvis_grid g = make_grid(13);
    const int K = 16;
    int b[PARTS], e[PARTS], p, within = 1, kind;
    size_t i, n = (size_t)W * H;
    split4(K, b, e);
    for (kind = 0; kind < 3; kind++) {
        hfvis_sweep_options o = hfvis_sweep_options_default();
        if (kind == 0) CHECK_EQ_STATUS(hfvis_visibility_count(&g, K, &o, NULL, full, W, NULL), HFVIS_OK);
        if (kind == 1) CHECK_EQ_STATUS(hfvis_sky_view_factor(&g, K, &o, full, W), HFVIS_OK);
        if (kind == 2) CHECK_EQ_STATUS(hfvis_sky_light(&g, K, 1.5f, 0.8f, &o, full, W), HFVIS_OK);
        for (i = 0; i < n; i++) fsum[i] = 0.0, dacc[i] = 0.0;
        for (p = 0; p < PARTS; p++) {
            o.direction_begin = b[p];
            o.direction_end = e[p];
            if (kind == 0) CHECK_EQ_STATUS(hfvis_visibility_count(&g, K, &o, NULL, part, W, NULL), HFVIS_OK);
            if (kind == 1) CHECK_EQ_STATUS(hfvis_sky_view_factor(&g, K, &o, part, W), HFVIS_OK);
            if (kind == 2) CHECK_EQ_STATUS(hfvis_sky_light(&g, K, 1.5f, 0.8f, &o, part, W), HFVIS_OK);
            for (i = 0; i < n; i++) {
                fsum[i] += (double)part[i];
                dacc[i] += fabs((double)part[i]);
            }
        }
        for (i = 0; i < n; i++) {
            if (isnan(full[i])) { within &= isnan(fsum[i]) != 0; continue; }
            within &= fabs(fsum[i] - (double)full[i]) <=
                      SPLIT_FLOAT_FACTOR * (dacc[i] + fabs((double)full[i]));
        }
        CHECK(within);
    }
}

/* Bad ranges: HFVIS_ERR_INVALID_ARGUMENT and the output untouched; 0, 0 means all K. */
TEST(bad_ranges)
{
    static const int bad[][2] = { { -1, 2 }, { 0, 9 }, { 3, 3 }, { 5, 2 }, { 0, -1 }, { 8, 9 } };
    hfvis_grid g = make_grid(2);
    const int K = 8;
    size_t r, i, n = (size_t)W * H;
    for (r = 0; r < sizeof bad / sizeof bad[0]; r++) {
        hfvis_sweep_options o = hfvis_sweep_options_default();
        o.direction_begin = bad[r][0];
        o.direction_end = bad[r][1];
        for (i = 0; i < n; i++) part[i] = 42.0f, dpart[i] = 42.0;
        CHECK_EQ_STATUS(hfvis_horizon_map(&g, K, &o, part), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_sky_view_factor(&g, K, &o, part, W), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_visibility_count(&g, K, &o, NULL, part, W, NULL), HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_direction_sums(&g, K, HFVIS_SUM_SKY_LIGHT, NULL, NULL, &o, dpart),
                        HFVIS_ERR_INVALID_ARGUMENT);
        for (i = 0; i < n; i++) CHECK(part[i] == 42.0f && dpart[i] == 42.0);
    }
    {
        hfvis_sweep_options o = hfvis_sweep_options_default();
        CHECK_EQ_STATUS(hfvis_direction_sums(NULL, K, HFVIS_SUM_SKY_VIEW, NULL, NULL, &o, dpart),
                        HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_direction_sums(&g, 0, HFVIS_SUM_SKY_VIEW, NULL, NULL, &o, dpart),
                        HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_direction_sums(&g, K, HFVIS_SUM_SKY_VIEW, NULL, NULL, &o, NULL),
                        HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_direction_sums(&g, K, (hfvis_sum_kind)0, NULL, NULL, &o, dpart),
                        HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_direction_sums(&g, K, (hfvis_sum_kind)5, NULL, NULL, &o, dpart),
                        HFVIS_ERR_INVALID_ARGUMENT);
        CHECK_EQ_STATUS(hfvis_direction_sums(&g, K, HFVIS_SUM_ENV_LIGHT, NULL, NULL, &o, dpart),
                        HFVIS_ERR_INVALID_ARGUMENT);
        /* 0, 0 = all K, and [0, K) is the same */
        CHECK_EQ_STATUS(hfvis_horizon_map(&g, K, &o, full), HFVIS_OK);
        o.direction_end = K;
        CHECK_EQ_STATUS(hfvis_horizon_map(&g, K, &o, part), HFVIS_OK);
        CHECK(same_bits(part, full, (size_t)K * n));
    }
}

/* HFVIS_DIRECTION_ORDER_SWEEP: position p is k = p/4 + (p%4)*K/4. Horizon parts come out in
 * position order, bit-identical to their planes; sum parts of exactly one quarter-turn group,
 * added in position order, repeat the single run's own order of additions (one gathered group
 * at a time into the accumulator), so they are bit-exact too. */
TEST(sweep_order_parts)
{
    static const hfvis_sum_kind kinds[] = { HFVIS_SUM_SKY_VIEW, HFVIS_SUM_SKY_LIGHT, HFVIS_SUM_VISIBILITY };
    hfvis_grid g = make_grid(21);
    const int K = 16, G = K / 4;
    const size_t plane = (size_t)W * H, n = plane;
    hfvis_sweep_options o = hfvis_sweep_options_default();
    int p, j, ok = 1;
    size_t kk, i;
    o.azimuth0_rad = 0.7;
    CHECK_EQ_STATUS(hfvis_horizon_map(&g, K, &o, full), HFVIS_OK);
    o.direction_order = HFVIS_DIRECTION_ORDER_SWEEP;
    for (p = 0; p < K; p += 4) { /* one group per part, then one odd-sized part */
        o.direction_begin = p;
        o.direction_end = p + 4;
        CHECK_EQ_STATUS(hfvis_horizon_map(&g, K, &o, part), HFVIS_OK);
        for (j = 0; j < 4; j++) {
            int pos = p + j, k = pos / 4 + (pos % 4) * G;
            ok &= same_bits(part + (size_t)j * plane, full + (size_t)k * plane, plane);
        }
    }
    o.direction_begin = 3;
    o.direction_end = 10;
    CHECK_EQ_STATUS(hfvis_horizon_map(&g, K, &o, part), HFVIS_OK);
    for (j = 0; j < 7; j++) {
        int pos = 3 + j, k = pos / 4 + (pos % 4) * G;
        ok &= same_bits(part + (size_t)j * plane, full + (size_t)k * plane, plane);
    }
    o.direction_begin = o.direction_end = 0; /* all K in sweep order */
    CHECK_EQ_STATUS(hfvis_horizon_map(&g, K, &o, part), HFVIS_OK);
    ok &= same_bits(part + 1 * plane, full + (size_t)G * plane, plane);
    CHECK(ok);
    for (kk = 0; kk < sizeof kinds / sizeof kinds[0]; kk++) {
        o.direction_begin = o.direction_end = 0;
        o.direction_order = HFVIS_DIRECTION_ORDER_INDEX;
        CHECK_EQ_STATUS(hfvis_direction_sums(&g, K, kinds[kk], NULL, NULL, &o, dfull), HFVIS_OK);
        o.direction_order = HFVIS_DIRECTION_ORDER_SWEEP;
        for (p = 0; p < K; p += 4) {
            o.direction_begin = p;
            o.direction_end = p + 4;
            CHECK_EQ_STATUS(hfvis_direction_sums(&g, K, kinds[kk], NULL, NULL, &o, dpart), HFVIS_OK);
            for (i = 0; i < n; i++) dacc[i] = p == 0 ? dpart[i] : dacc[i] + dpart[i];
        }
        CHECK(memcmp(dacc, dfull, n * sizeof(double)) == 0);
    }
    o.direction_order = (hfvis_direction_order)3;
    CHECK_EQ_STATUS(hfvis_direction_sums(&g, K, HFVIS_SUM_SKY_VIEW, NULL, NULL, &o, dpart),
                    HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_horizon_map(&g, K, &o, part), HFVIS_ERR_INVALID_ARGUMENT);
    o.direction_order = (hfvis_direction_order)-1;
    CHECK_EQ_STATUS(hfvis_sky_view_factor(&g, K, &o, part, W), HFVIS_ERR_INVALID_ARGUMENT);
}

TEST(allocation_failures)
{
    hfvis_grid g = make_grid(4);
    float radiance[8];
    hfvis_env env;
    int kind, k;
    for (k = 0; k < 8; k++) radiance[k] = 1.0f;
    env.radiance = radiance;
    env.n_theta = 2;
    env.n_phi = 4;
    env.channels = 1;
    for (kind = HFVIS_SUM_SKY_VIEW; kind <= HFVIS_SUM_VISIBILITY + 1; kind++) {
        test_counting c;
        hfvis_allocator a;
        hfvis_sweep_options o = hfvis_sweep_options_default();
        int total;
        a.alloc = test_count_alloc;
        a.free = test_count_free;
        a.user = &c;
        o.alloc = &a;
        o.direction_begin = 1;
        o.direction_end = 6;
        memset(&c, 0, sizeof c);
        c.fail_at = 0;
        if (kind > HFVIS_SUM_VISIBILITY) /* the horizon map's range path */
            CHECK_EQ_STATUS(hfvis_horizon_map(&g, 8, &o, part), HFVIS_OK);
        else
            CHECK_EQ_STATUS(hfvis_direction_sums(&g, 8, (hfvis_sum_kind)kind, &env, NULL, &o, dpart), HFVIS_OK);
        CHECK(c.live == 0);
        total = c.allocs;
        CHECK(total >= 1);
        for (k = 0; k < total; k++) {
            hfvis_status s;
            memset(&c, 0, sizeof c);
            c.fail_at = k + 1;
            if (kind > HFVIS_SUM_VISIBILITY) s = hfvis_horizon_map(&g, 8, &o, part);
            else s = hfvis_direction_sums(&g, 8, (hfvis_sum_kind)kind, &env, NULL, &o, dpart);
            CHECK_EQ_STATUS(s, HFVIS_ERR_OUT_OF_MEMORY);
            CHECK(c.live == 0);
        }
    }
}

/* ---- the HFVISSUM codec ---------------------------------------------------------------- */

static unsigned char enc[8192], enc2[8192];

static hfvis_partial sample_partial(double *sums)
{
    hfvis_partial p;
    int i;
    p.width = 3;
    p.height = 2;
    p.planes = 2;
    p.directions = 16;
    p.begin = 4;
    p.end = 9;
    p.tag = "skyview dirs=16 cell=0x1p+0 in=0123456789abcdef";
    for (i = 0; i < 12; i++) sums[i] = (double)i * 0.1 - 0.35;
    sums[3] = (double)NAN;
    sums[4] = -0.0;
    sums[5] = (double)INFINITY;
    p.sums = sums;
    return p;
}

TEST(partial_round_trip)
{
    double sums[12];
    hfvis_partial p = sample_partial(sums), q;
    size_t n = hfvis_partial_encode_size(&p), written = 0;
    static const char head[] = "HFVISSUM 2\n3 2 2 16 4 9\n";
    CHECK(n == sizeof head - 1 + strlen(p.tag) + 1 + 12 * 8 + 4); /* + the CRC-32 */
    CHECK_EQ_STATUS(hfvis_partial_encode(&p, enc, n - 1, &written), HFVIS_ERR_BUFFER_TOO_SMALL);
    CHECK_EQ_STATUS(hfvis_partial_encode(&p, enc, sizeof enc, &written), HFVIS_OK);
    CHECK(written == n);
    CHECK(memcmp(enc, head, sizeof head - 1) == 0);
    memset(&q, 0, sizeof q);
    CHECK_EQ_STATUS(hfvis_partial_decode(enc, n, NULL, &q), HFVIS_OK);
    CHECK(q.width == 3 && q.height == 2 && q.planes == 2 && q.directions == 16 && q.begin == 4 && q.end == 9);
    CHECK(strcmp(q.tag, p.tag) == 0);
    CHECK(memcmp(q.sums, sums, sizeof sums) == 0); /* bit for bit: NaN, -0, inf */
    hfvis_partial_free(NULL, &q);
    CHECK(q.sums == NULL);
    hfvis_partial_free(NULL, NULL);
}

TEST(partial_encode_rejects_invalid)
{
    double sums[12];
    hfvis_partial p = sample_partial(sums), b;
    size_t w;
    b = p; b.begin = 9; CHECK(hfvis_partial_encode_size(&b) == 0);
    b = p; b.end = 17; CHECK(hfvis_partial_encode_size(&b) == 0);
    b = p; b.begin = -1; CHECK(hfvis_partial_encode_size(&b) == 0);
    b = p; b.width = 0; CHECK(hfvis_partial_encode_size(&b) == 0);
    b = p; b.planes = HFVIS_PARTIAL_MAX_PLANES + 1; CHECK(hfvis_partial_encode_size(&b) == 0);
    b = p; b.tag = ""; CHECK(hfvis_partial_encode_size(&b) == 0);
    b = p; b.tag = "two\nlines"; CHECK(hfvis_partial_encode_size(&b) == 0);
    b = p; b.tag = NULL; CHECK(hfvis_partial_encode_size(&b) == 0);
    b = p; b.sums = NULL; CHECK(hfvis_partial_encode_size(&b) == 0);
    b = p; b.width = 1 << 20; b.height = 1 << 13; CHECK(hfvis_partial_encode_size(&b) == 0);
    CHECK(hfvis_partial_encode_size(NULL) == 0);
    b = p; b.end = 3;
    CHECK_EQ_STATUS(hfvis_partial_encode(&b, enc, sizeof enc, &w), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_partial_encode(&p, NULL, sizeof enc, &w), HFVIS_ERR_INVALID_ARGUMENT);
}

/* Every prefix of a valid file, and the file with one byte more, is HFVIS_ERR_FORMAT. */
TEST(partial_truncations)
{
    double sums[12];
    hfvis_partial p = sample_partial(sums), q;
    size_t n = 0, k;
    int all = 1;
    CHECK_EQ_STATUS(hfvis_partial_encode(&p, enc, sizeof enc, &n), HFVIS_OK);
    for (k = 0; k < n; k++) {
        memset(&q, 0, sizeof q);
        all &= hfvis_partial_decode(enc, k, NULL, &q) == HFVIS_ERR_FORMAT && q.sums == NULL;
    }
    CHECK(all);
    enc[n] = 0;
    CHECK_EQ_STATUS(hfvis_partial_decode(enc, n + 1, NULL, &q), HFVIS_ERR_FORMAT);
    CHECK_EQ_STATUS(hfvis_partial_decode(NULL, n, NULL, &q), HFVIS_ERR_INVALID_ARGUMENT);
    CHECK_EQ_STATUS(hfvis_partial_decode(enc, n, NULL, NULL), HFVIS_ERR_INVALID_ARGUMENT);
}

/* Header variations: each edit of the numbers line or the tag. */
static hfvis_status decode_with_header(const char *numbers, const char *tag, size_t data_bytes)
{
    hfvis_partial q;
    hfvis_status s;
    size_t len = (size_t)sprintf((char *)enc2, "HFVISSUM 2\n%s\n%s\n", numbers, tag), k;
    uint32_t crc;
    memset(enc2 + len, 0, data_bytes);
    crc = hfvis_crc32(0, enc2, len + data_bytes);
    for (k = 0; k < 4; k++) enc2[len + data_bytes + k] = (unsigned char)(crc >> (8 * k));
    memset(&q, 0, sizeof q);
    s = hfvis_partial_decode(enc2, len + data_bytes + 4, NULL, &q);
    if (s == HFVIS_OK) hfvis_partial_free(NULL, &q);
    return s;
}

TEST(partial_malformed_headers)
{
    char longtag[HFVIS_PARTIAL_MAX_TAG + 2];
    CHECK_EQ_STATUS(decode_with_header("3 2 1 8 0 8", "t", 48), HFVIS_OK);
    CHECK_EQ_STATUS(decode_with_header("3 2 1 8 0 8", "t", 47), HFVIS_ERR_FORMAT);
    CHECK_EQ_STATUS(decode_with_header("3 2 1 8 0 8", "t", 49), HFVIS_ERR_FORMAT);
    CHECK_EQ_STATUS(decode_with_header("3 2 1 8 8 8", "t", 48), HFVIS_ERR_FORMAT);  /* empty range */
    CHECK_EQ_STATUS(decode_with_header("3 2 1 8 0 9", "t", 48), HFVIS_ERR_FORMAT);  /* end > K */
    CHECK_EQ_STATUS(decode_with_header("3 2 1 0 0 0", "t", 48), HFVIS_ERR_FORMAT);  /* K = 0 */
    CHECK_EQ_STATUS(decode_with_header("0 2 1 8 0 8", "t", 0), HFVIS_ERR_FORMAT);
    CHECK_EQ_STATUS(decode_with_header("3 2 0 8 0 8", "t", 0), HFVIS_ERR_FORMAT);
    CHECK_EQ_STATUS(decode_with_header("03 2 1 8 0 8", "t", 48), HFVIS_ERR_FORMAT); /* leading zero */
    CHECK_EQ_STATUS(decode_with_header("+3 2 1 8 0 8", "t", 48), HFVIS_ERR_FORMAT);
    CHECK_EQ_STATUS(decode_with_header("3  2 1 8 0 8", "t", 48), HFVIS_ERR_FORMAT);
    CHECK_EQ_STATUS(decode_with_header("3 2 1 8 0 8 ", "t", 48), HFVIS_ERR_FORMAT);
    CHECK_EQ_STATUS(decode_with_header("3 2 1 8 0", "t", 48), HFVIS_ERR_FORMAT);
    CHECK_EQ_STATUS(decode_with_header("3 2 1 2147483648 0 8", "t", 48), HFVIS_ERR_FORMAT);
    CHECK_EQ_STATUS(decode_with_header("3 2 1 8 0 8", "", 48), HFVIS_ERR_FORMAT);    /* empty tag */
    CHECK_EQ_STATUS(decode_with_header("3 2 1 8 0 8", "t\tab", 48), HFVIS_ERR_FORMAT);
    CHECK_EQ_STATUS(decode_with_header("1048577 1 1 8 0 8", "t", 0), HFVIS_ERR_LIMIT);
    CHECK_EQ_STATUS(decode_with_header("65536 65537 1 8 0 8", "t", 0), HFVIS_ERR_LIMIT);
    CHECK_EQ_STATUS(decode_with_header("16384 16385 1 8 0 8", "t", 0), HFVIS_ERR_FORMAT); /* short */
    CHECK_EQ_STATUS(decode_with_header("1 1 65537 8 0 8", "t", 0), HFVIS_ERR_LIMIT);
    memset(longtag, 'x', sizeof longtag);
    longtag[HFVIS_PARTIAL_MAX_TAG] = '\0';
    CHECK_EQ_STATUS(decode_with_header("1 1 1 1 0 1", longtag, 8), HFVIS_OK);
    longtag[HFVIS_PARTIAL_MAX_TAG] = 'x';
    longtag[HFVIS_PARTIAL_MAX_TAG + 1] = '\0';
    CHECK_EQ_STATUS(decode_with_header("1 1 1 1 0 1", longtag, 8), HFVIS_ERR_FORMAT);
    {   /* a bad magic or version */
        hfvis_partial q;
        memcpy(enc2, "HFVISSUM 3\n1 1 1 1 0 1\nt\n", 25);
        CHECK_EQ_STATUS(hfvis_partial_decode(enc2, 37, NULL, &q), HFVIS_ERR_FORMAT);
    }
}

/* The CRC-32 trailer: a part written by version 1 (no trailer) is refused, and so is every
 * single-byte change of a valid file (a NaN or 1e308 planted in the body was summed before). */
TEST(partial_checksum)
{
    double sums[12];
    hfvis_partial p = sample_partial(sums), q;
    size_t n = 0, k, flips_refused = 0;
    CHECK_EQ_STATUS(hfvis_partial_encode(&p, enc, sizeof enc, &n), HFVIS_OK);
    for (k = 0; k < n; k++) { /* bit 6 of each byte in turn */
        enc[k] ^= 0x40u;
        memset(&q, 0, sizeof q);
        flips_refused += hfvis_partial_decode(enc, n, NULL, &q) == HFVIS_ERR_FORMAT && q.sums == NULL;
        enc[k] ^= 0x40u;
    }
    CHECK(flips_refused == n);
    {   /* 1e308 over sums[0] with the old trailer */
        double big = 1e308;
        size_t body = n - 4 - 12 * 8, b;
        uint64_t u;
        memcpy(&u, &big, 8);
        for (b = 0; b < 8; b++) enc[body + b] = (unsigned char)(u >> (8 * b));
        CHECK_EQ_STATUS(hfvis_partial_decode(enc, n, NULL, &q), HFVIS_ERR_FORMAT);
    }
    /* the version-1 layout: the same header and body under "HFVISSUM 1", no trailer */
    CHECK_EQ_STATUS(hfvis_partial_encode(&p, enc, sizeof enc, &n), HFVIS_OK);
    enc[9] = '1';
    CHECK_EQ_STATUS(hfvis_partial_decode(enc, n - 4, NULL, &q), HFVIS_ERR_FORMAT);
    CHECK(hfvis_crc32(0, "123456789", 9) == 0xcbf43926u);
    CHECK(hfvis_crc32(0, NULL, 0) == 0u);
}

TEST(partial_decode_allocation_failure)
{
    double sums[12];
    hfvis_partial p = sample_partial(sums), q;
    test_counting c;
    hfvis_allocator a;
    size_t n = 0;
    CHECK_EQ_STATUS(hfvis_partial_encode(&p, enc, sizeof enc, &n), HFVIS_OK);
    a.alloc = test_count_alloc;
    a.free = test_count_free;
    a.user = &c;
    memset(&c, 0, sizeof c);
    c.fail_at = 1;
    memset(&q, 0, sizeof q);
    CHECK_EQ_STATUS(hfvis_partial_decode(enc, n, &a, &q), HFVIS_ERR_OUT_OF_MEMORY);
    CHECK(q.sums == NULL && c.live == 0);
    c.fail_at = 0;
    CHECK_EQ_STATUS(hfvis_partial_decode(enc, n, &a, &q), HFVIS_OK);
    CHECK(c.live == 1);
    hfvis_partial_free(&a, &q);
    CHECK(c.live == 0);
}

int main(int argc, char **argv)
{
    TEST_INIT(argc, argv);
    RUN(horizon_map_split_is_bit_exact);
    RUN(direction_sums_finish_equals_routines);
    RUN(direction_sums_split_within_double_rounding);
    RUN(float_routines_split);
    RUN(bad_ranges);
    RUN(sweep_order_parts);
    RUN(allocation_failures);
    RUN(partial_round_trip);
    RUN(partial_encode_rejects_invalid);
    RUN(partial_truncations);
    RUN(partial_malformed_headers);
    RUN(partial_checksum);
    RUN(partial_decode_allocation_failure);
    return TEST_DONE();
}
