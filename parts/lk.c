/* ========================================================================================== */
/* 5. Laine-Karras bitmask ray-cast ambient occlusion                                          */
/*    S. Laine, T. Karras, "Two Methods for Fast Ray-Cast Ambient Occlusion", EGSR 2010 ([LK]); */
/*    spec raycast-ao-and-hf-gi.md part A (A.1-A.14), whose errata and choices are followed.  */
/* ========================================================================================== */
/* Contents
 *   5.1 common: allocation, checked sizes, PCG32 / SplitMix64, popcount
 *   5.2 ray sets: Lloyd-relaxed disc with Voronoi jitter, Malley lifting, falloff lengths ([LK]
 *       §3, §6; spec A.2), Morton order and per-word cones
 *   5.3 the receiver frame with rotation and tilt jitter ([LK] §3; spec A.3)
 *   5.4 the blocking predicate and the exact triangle mask (spec A.4.1, window A.4.3), the plane
 *       look-up table with node indexing ([LK] §3.1; spec A.4.2)
 *   5.5 per-triangle data: minimal bounding sphere (A.5), hexagonal prism (A.6, [LK] Fig. 2)
 *   5.6 options
 *   5.7 G-buffer receivers and Method 1, rasterization ([LK] §4; spec A.6-A.8)
 *   5.8 Method 2, BVH traversal with exact node masks ([LK] §5; spec A.9)
 *   5.9 the reference ray caster (spec A.10)
 *   5.10 the image driver
 * Why the three methods agree bit for bit: they evaluate one predicate (lk_tri_setup +
 * lk_blocks) on the same doubles, and every test that skips work (word cones, culling tests,
 * node masks, volumes, slab tests) is applied only with margins (relative 1e-9 or more) far
 * above the rounding of that predicate (about 1e-15 relative). */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#endif

#define LK_PI 3.14159265358979323846
#define LK_INF ((double)INFINITY)
#define LK_DISC_R2 (1.0 - 0x1p-20)  /* disc points have x^2 + y^2 < this, so u_z >= 2^-10 */
#define LK_CONE_PAD 1e-9            /* word cones are widened by this angle (radians) */
#define LK_MARGIN 1e-9              /* relative margin of every work-skipping test */
#define LK_SLAB_PAD 0x1p-40         /* widening of the ray caster's slab test (in t) */
#define LK_JITTER_ATTEMPTS 64       /* Voronoi jitter: rejection attempts per site */

/* ---- 5.1 common ---------------------------------------------------------------------------- */

static void *lk_alloc(const hfvis_allocator *a, size_t bytes)
{
    if (bytes == 0) return NULL;
    if (a && a->alloc) return a->alloc(a->user, bytes);
    return malloc(bytes);
}

static void lk_free(const hfvis_allocator *a, void *p)
{
    if (!p) return;
    if (a && a->free) a->free(a->user, p);
    else if (!a || !a->alloc) free(p);
}

/* *out = a*b; 0 on overflow. */
static int lk_mul(size_t a, size_t b, size_t *out)
{
    if (a != 0 && b > SIZE_MAX / a) return 0;
    *out = a * b;
    return 1;
}

/* *acc += a*b rounded up to a multiple of 16 (one sub-array of a block); 0 on overflow. */
static int lk_part(size_t *acc, size_t count, size_t elem)
{
    size_t bytes;
    if (!lk_mul(count, elem, &bytes) || bytes > SIZE_MAX - 15) return 0;
    bytes = (bytes + 15) & ~(size_t)15;
    if (*acc > SIZE_MAX - bytes) return 0;
    *acc += bytes;
    return 1;
}

/* The next sub-array of a block laid out by lk_part. */
static void *lk_take(unsigned char **cursor, size_t count, size_t elem)
{
    void *p = *cursor;
    *cursor += (count * elem + 15) & ~(size_t)15;
    return p;
}

static int lk_popcount(uint32_t x)
{
    x = x - ((x >> 1) & 0x55555555u);
    x = (x & 0x33333333u) + ((x >> 2) & 0x33333333u);
    x = (x + (x >> 4)) & 0x0F0F0F0Fu;
    return (int)((x * 0x01010101u) >> 24);
}

/* PCG32 (M. O'Neill, pcg-random.org, XSH-RR), seeded with (seed, stream). */
typedef struct lk_pcg {
    uint64_t state, inc;
} lk_pcg;

static uint32_t lk_pcg_next(lk_pcg *g)
{
    uint64_t old = g->state;
    uint32_t xs, rot;
    g->state = old * 6364136223846793005ull + g->inc;
    xs = (uint32_t)(((old >> 18) ^ old) >> 27);
    rot = (uint32_t)(old >> 59);
    return (xs >> rot) | (xs << ((32u - rot) & 31u));
}

static void lk_pcg_seed(lk_pcg *g, uint64_t seed, uint64_t stream)
{
    g->state = 0;
    g->inc = (stream << 1) | 1u;
    (void)lk_pcg_next(g);
    g->state += seed;
    (void)lk_pcg_next(g);
}

/* Uniform in [0, 1) with 53 bits. */
static double lk_pcg_unit(lk_pcg *g)
{
    uint64_t hi = lk_pcg_next(g) >> 5, lo = lk_pcg_next(g) >> 6;
    return ((double)hi * 67108864.0 + (double)lo) * (1.0 / 9007199254740992.0);
}

/* Uniform integer in [0, n), n >= 1 (Lemire-free rejection: unbiased). */
static uint32_t lk_pcg_below(lk_pcg *g, uint32_t n)
{
    uint32_t limit = (uint32_t)(0u - n) % n, x;
    do x = lk_pcg_next(g); while (x < limit);
    return x % n;
}

/* SplitMix64 (Steele, Lea, Flood 2014). */
static uint64_t lk_splitmix(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static double lk_dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void lk_cross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static int lk_finite3(const double v[3])
{
    return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

/* Mesh check (as voxel.c's): arrays present, indices in range, finite coordinates. O(V + T). */
static hfvis_status lk_mesh_check(const hfvis_mesh *m)
{
    size_t i;
    if (!m) return HFVIS_ERR_INVALID_ARGUMENT;
    if ((m->vertex_count && !m->xyz) || (m->triangle_count && !m->indices))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (m->vertex_count > SIZE_MAX / 3 || m->triangle_count > SIZE_MAX / 3)
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (i = 0; i < 3 * m->vertex_count; i++)
        if (!isfinite(m->xyz[i])) return HFVIS_ERR_INVALID_ARGUMENT;
    for (i = 0; i < 3 * m->triangle_count; i++)
        if ((size_t)m->indices[i] >= m->vertex_count) return HFVIS_ERR_INVALID_ARGUMENT;
    return HFVIS_OK;
}

static const float *lk_vertex(const hfvis_mesh *m, size_t t, int k)
{
    return m->xyz + 3 * (size_t)m->indices[3 * t + (size_t)k];
}

/* ---- 5.2 ray sets (spec A.2) ---------------------------------------------------------------- */

HFVIS_API int hfvis_lk_mask_words(int count)
{
    if (count < 1 || count > HFVIS_LK_MAX_RAYS) return 0;
    return (count + 31) / 32;
}

HFVIS_API double hfvis_lk_obscurance(const uint32_t *mask, int count)
{
    int w, words = hfvis_lk_mask_words(count), bits = 0;
    if (!mask || words == 0) return (double)NAN;
    for (w = 0; w < words; w++) bits += lk_popcount(mask[w]);
    return (double)bits / (double)count;
}

/* Valid bits of word w of an N-ray mask. */
static uint32_t lk_word_bits(int count, int w)
{
    int rest = count - 32 * w;
    return rest >= 32 ? 0xFFFFFFFFu : (uint32_t)((1u << rest) - 1u);
}

static int lk_rays_valid(const hfvis_lk_rays *r)
{
    return r && r->count >= 1 && r->count <= HFVIS_LK_MAX_RAYS &&
           r->words == (r->count + 31) / 32 && r->direction && r->length && r->point &&
           r->word_cone && isfinite(r->radius) && r->radius > 0.0 &&
           isfinite(r->min_elevation) && r->min_elevation > 0.0;
}

HFVIS_API hfvis_lk_ray_options hfvis_lk_ray_options_default(void)
{
    hfvis_lk_ray_options o;
    memset(&o, 0, sizeof o);
    o.pattern = HFVIS_LK_PATTERN_LLOYD;
    o.lloyd_iterations = 64;
    o.final_iterations = 4;
    o.density_resolution = 0; /* adaptive */
    o.falloff = HFVIS_LK_FALLOFF_CONSTANT;
    return o;
}

/* Sites of the disc in a uniform B x B grid over [-1, 1]^2 (nearest-site queries for Lloyd). */
typedef struct lk_sites {
    int n, B;
    int wrap;            /* periodic square (torus) instead of the plane */
    double cs;           /* cell size 2/B */
    const double *xy;    /* 2n */
    int *start;          /* B*B + 1 */
    int *items;          /* n: site indices in cell order */
    double *cxy;         /* 2n: their coordinates, in the same order */
} lk_sites;

static int lk_sites_cell(const lk_sites *g, double v)
{
    double c = floor((v + 1.0) / g->cs);
    if (!(c >= 0.0)) return 0;
    if (c >= (double)g->B) return g->B - 1;
    return (int)c;
}

/* Difference a - b, on the torus [-1, 1)^2 the shortest one. */
static double lk_sites_diff(const lk_sites *g, double a, double b)
{
    double d = a - b;
    if (g->wrap) {
        if (d >= 1.0) d -= 2.0;
        else if (d < -1.0) d += 2.0;
    }
    return d;
}

/* v wrapped into [-1, 1). */
static double lk_wrap(double v)
{
    if (v >= 1.0) v -= 2.0;
    if (v < -1.0) v += 2.0;
    if (v >= 1.0 || v < -1.0) v = 0.0;
    return v;
}

static void lk_sites_build(lk_sites *g)
{
    int i, cells = g->B * g->B;
    for (i = 0; i <= cells; i++) g->start[i] = 0;
    for (i = 0; i < g->n; i++)
        g->start[lk_sites_cell(g, g->xy[2 * i + 1]) * g->B + lk_sites_cell(g, g->xy[2 * i]) + 1]++;
    for (i = 0; i < cells; i++) g->start[i + 1] += g->start[i];
    for (i = 0; i < g->n; i++) { /* fill in index order; start[] is shifted back afterwards */
        int c = lk_sites_cell(g, g->xy[2 * i + 1]) * g->B + lk_sites_cell(g, g->xy[2 * i]);
        g->cxy[2 * g->start[c]] = g->xy[2 * i];
        g->cxy[2 * g->start[c] + 1] = g->xy[2 * i + 1];
        g->items[g->start[c]++] = i;
    }
    for (i = cells; i > 0; i--) g->start[i] = g->start[i - 1];
    g->start[0] = 0;
}

/* The nearest site of (qx, qy): smallest squared distance, ties to the lowest index. Rings of
 * cells around the query's cell; after ring k every unseen site is >= k*cs away. */
static int lk_sites_nearest(const lk_sites *g, double qx, double qy)
{
    int cx = lk_sites_cell(g, qx), cy = lk_sites_cell(g, qy), ring, best_i = -1;
    double best = DBL_MAX;
    for (ring = 0; ring < g->B; ring++) {
        int j;
        for (j = cy - ring; j <= cy + ring; j++) {
            int i, step = (j == cy - ring || j == cy + ring) ? 1 : 2 * ring, jj = j;
            if (g->wrap) jj = ((j % g->B) + g->B) % g->B;
            else if (j < 0 || j >= g->B) continue;
            for (i = cx - ring; i <= cx + ring; i += step) {
                int k, c, ii = i;
                if (g->wrap) ii = ((i % g->B) + g->B) % g->B;
                else if (i < 0 || i >= g->B) continue;
                c = jj * g->B + ii;
                for (k = g->start[c]; k < g->start[c + 1]; k++) {
                    double dx = lk_sites_diff(g, g->cxy[2 * k], qx), dy = lk_sites_diff(g, g->cxy[2 * k + 1], qy);
                    double d2 = dx * dx + dy * dy;
                    if (d2 < best || (d2 == best && g->items[k] < best_i)) {
                        best = d2;
                        best_i = g->items[k];
                    }
                }
            }
        }
        if (best_i >= 0) {
            double lim = (double)ring * g->cs;
            if (best < lim * lim || (g->wrap && 2 * ring > g->B + 2)) break;
        }
    }
    return best_i;
}

/* One pass: assign every density point to its nearest site; move = 1 moves each site to the
 * mean of its points (Lloyd step), else only the assignment is kept. */
static void lk_lloyd_pass(lk_sites *g, double *xy, const double *dens, size_t nd, int *assign,
                          double *sum, int move)
{
    size_t k;
    int i;
    lk_sites_build(g);
    for (i = 0; i < g->n; i++) sum[3 * i] = sum[3 * i + 1] = sum[3 * i + 2] = 0.0;
    for (k = 0; k < nd; k++) { /* offsets from the site (shortest on the torus) */
        int s = lk_sites_nearest(g, dens[2 * k], dens[2 * k + 1]);
        assign[k] = s;
        sum[3 * s] += lk_sites_diff(g, dens[2 * k], xy[2 * s]);
        sum[3 * s + 1] += lk_sites_diff(g, dens[2 * k + 1], xy[2 * s + 1]);
        sum[3 * s + 2] += 1.0;
    }
    if (!move) return;
    for (i = 0; i < g->n; i++)
        if (sum[3 * i + 2] > 0.0) {
            xy[2 * i] += sum[3 * i] / sum[3 * i + 2];
            xy[2 * i + 1] += sum[3 * i + 1] / sum[3 * i + 2];
            if (g->wrap) {
                xy[2 * i] = lk_wrap(xy[2 * i]);
                xy[2 * i + 1] = lk_wrap(xy[2 * i + 1]);
            }
        }
}

static void lk_disc_uniform(lk_pcg *g, double *x, double *y)
{
    double r = sqrt(lk_pcg_unit(g) * LK_DISC_R2), t = 2.0 * LK_PI * lk_pcg_unit(g);
    *x = r * cos(t);
    *y = r * sin(t);
}

/* Shirley-Chiu concentric map of the square [-1, 1]^2 onto the unit disc (area-preserving:
 * P. Shirley, K. Chiu, "A Low Distortion Map Between Disk and Square", JGT 2(3), 1997). */
static void lk_concentric(double a, double b, double *x, double *y)
{
    double r, phi;
    if (a == 0.0 && b == 0.0) {
        *x = *y = 0.0;
        return;
    }
    if (fabs(a) > fabs(b)) {
        r = a;
        phi = (LK_PI / 4.0) * (b / a);
    } else {
        r = b;
        phi = LK_PI / 2.0 - (LK_PI / 4.0) * (a / b);
    }
    *x = r * cos(phi);
    *y = r * sin(phi);
}

/* The Lloyd / Voronoi-jitter disc of spec A.2 DISC_SAMPLES, into xy (2n). torus != 0: the same
 * relaxation on the periodic square [-1, 1)^2 (no boundary, so no rim bias), then the concentric
 * map onto the disc. */
static hfvis_status lk_disc_lloyd(int n, const hfvis_lk_ray_options *o, lk_pcg *g,
                                  const hfvis_allocator *alloc, int torus, double *xy)
{
    int G = o->density_resolution, B = 1, i, it;
    size_t nd = 0, bytes = 0, k;
    unsigned char *block, *cur;
    double *dens, *sum, *box, *jit;
    int *assign;
    lk_sites sites;
    while (B * B * 2 < n) B++; /* about two sites per cell */
    if (G == 0) { /* adaptive: about 48 density points per site, at least 64 x 64 */
        G = (int)ceil(sqrt(48.0 * n * (torus ? 1.0 : 4.0 / LK_PI)));
        if (G < 64) G = 64;
    }
    for (i = 0; i < G; i++) { /* density points: centres of G x G cells (inside the disc) */
        double y = -1.0 + (2.0 * i + 1.0) / G;
        for (it = 0; it < G; it++) {
            double x = -1.0 + (2.0 * it + 1.0) / G;
            if (torus || x * x + y * y < LK_DISC_R2) nd++;
        }
    }
    if (!lk_part(&bytes, nd, 2 * sizeof(double)) || !lk_part(&bytes, nd, sizeof(int)) ||
        !lk_part(&bytes, (size_t)n, 3 * sizeof(double)) ||
        !lk_part(&bytes, (size_t)n, 4 * sizeof(double)) ||
        !lk_part(&bytes, (size_t)n, 2 * sizeof(double)) ||
        !lk_part(&bytes, (size_t)B * (size_t)B + 1, sizeof(int)) ||
        !lk_part(&bytes, (size_t)n, sizeof(int)) || !lk_part(&bytes, (size_t)n, 2 * sizeof(double)))
        return HFVIS_ERR_LIMIT; /* only on 32-bit size_t */
    block = (unsigned char *)lk_alloc(alloc, bytes);
    if (!block) return HFVIS_ERR_OUT_OF_MEMORY;
    cur = block;
    dens = (double *)lk_take(&cur, nd, 2 * sizeof(double));
    assign = (int *)lk_take(&cur, nd, sizeof(int));
    sum = (double *)lk_take(&cur, (size_t)n, 3 * sizeof(double));
    box = (double *)lk_take(&cur, (size_t)n, 4 * sizeof(double));
    jit = (double *)lk_take(&cur, (size_t)n, 2 * sizeof(double));
    sites.start = (int *)lk_take(&cur, (size_t)B * (size_t)B + 1, sizeof(int));
    sites.items = (int *)lk_take(&cur, (size_t)n, sizeof(int));
    sites.cxy = (double *)lk_take(&cur, (size_t)n, 2 * sizeof(double));
    sites.n = n;
    sites.B = B;
    sites.wrap = torus;
    sites.cs = 2.0 / B;
    sites.xy = xy;
    k = 0;
    for (i = 0; i < G; i++) {
        double y = -1.0 + (2.0 * i + 1.0) / G;
        for (it = 0; it < G; it++) {
            double x = -1.0 + (2.0 * it + 1.0) / G;
            if (torus || x * x + y * y < LK_DISC_R2) {
                dens[2 * k] = x;
                dens[2 * k + 1] = y;
                k++;
            }
        }
    }
    for (i = 0; i < n; i++) { /* 1. random points */
        if (torus) {
            xy[2 * i] = lk_wrap(2.0 * lk_pcg_unit(g) - 1.0);
            xy[2 * i + 1] = lk_wrap(2.0 * lk_pcg_unit(g) - 1.0);
        } else {
            lk_disc_uniform(g, xy + 2 * i, xy + 2 * i + 1);
        }
    }
    /* 2. Lloyd relaxation */
    for (it = 0; it < o->lloyd_iterations; it++) lk_lloyd_pass(&sites, xy, dens, nd, assign, sum, 1);
    /* 3. Voronoi jitter: each site -> a uniform point of its own cell (cells of the relaxed set,
     * sampled by rejection in the box of its density points, offsets from the site) */
    lk_lloyd_pass(&sites, xy, dens, nd, assign, sum, 0);
    for (i = 0; i < n; i++) {
        box[4 * i] = box[4 * i + 1] = DBL_MAX;
        box[4 * i + 2] = box[4 * i + 3] = -DBL_MAX;
    }
    for (k = 0; k < nd; k++) {
        double *b = box + 4 * assign[k];
        double dx = lk_sites_diff(&sites, dens[2 * k], xy[2 * assign[k]]);
        double dy = lk_sites_diff(&sites, dens[2 * k + 1], xy[2 * assign[k] + 1]);
        if (dx < b[0]) b[0] = dx;
        if (dy < b[1]) b[1] = dy;
        if (dx > b[2]) b[2] = dx;
        if (dy > b[3]) b[3] = dy;
    }
    for (i = 0; i < n; i++) {
        const double *b = box + 4 * i, h = 1.0 / G;
        int a;
        jit[2 * i] = xy[2 * i];
        jit[2 * i + 1] = xy[2 * i + 1];
        if (b[0] > b[2]) continue; /* no density point: keep the site */
        for (a = 0; a < LK_JITTER_ATTEMPTS; a++) {
            double qx = xy[2 * i] + b[0] - h + (b[2] - b[0] + 2.0 * h) * lk_pcg_unit(g);
            double qy = xy[2 * i + 1] + b[1] - h + (b[3] - b[1] + 2.0 * h) * lk_pcg_unit(g);
            if (torus) {
                qx = lk_wrap(qx);
                qy = lk_wrap(qy);
            } else if (!(qx * qx + qy * qy < LK_DISC_R2)) {
                continue;
            }
            if (lk_sites_nearest(&sites, qx, qy) == i) {
                jit[2 * i] = qx;
                jit[2 * i + 1] = qy;
                break;
            }
        }
    }
    memcpy(xy, jit, sizeof(double) * 2 * (size_t)n);
    /* 4. a few more Lloyd steps */
    for (it = 0; it < o->final_iterations; it++) lk_lloyd_pass(&sites, xy, dens, nd, assign, sum, 1);
    if (torus) {
        const double sc = sqrt(LK_DISC_R2);
        for (i = 0; i < n; i++) {
            double x, y;
            lk_concentric(xy[2 * i], xy[2 * i + 1], &x, &y);
            xy[2 * i] = sc * x;
            xy[2 * i + 1] = sc * y;
        }
    }
    lk_free(alloc, block);
    return HFVIS_OK;
}

static uint32_t lk_morton16(uint32_t v)
{
    v &= 0xFFFFu;
    v = (v | (v << 8)) & 0x00FF00FFu;
    v = (v | (v << 4)) & 0x0F0F0F0Fu;
    v = (v | (v << 2)) & 0x33333333u;
    v = (v | (v << 1)) & 0x55555555u;
    return v;
}

static int lk_cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* Per-word cones (axis, cos, sin of the widened half-angle, least and largest length) and the
 * least elevation. */
static void lk_rays_finish(hfvis_lk_rays *r)
{
    int w, i;
    double emin = LK_INF;
    for (i = 0; i < r->count; i++) {
        double e = asin(r->direction[3 * i + 2]);
        if (e < emin) emin = e;
    }
    r->min_elevation = emin;
    r->equal_lengths = 1;
    for (i = 0; i < r->count; i++)
        if (r->length[i] != 1.0) r->equal_lengths = 0;
    for (w = 0; w < r->words; w++) {
        int i0 = 32 * w, i1 = i0 + 32 < r->count ? i0 + 32 : r->count;
        double ax = 0.0, ay = 0.0, az = 0.0, len, cmin = 1.0, th, lmin = LK_INF, lmax = 0.0;
        double *c = r->word_cone + 7 * w;
        for (i = i0; i < i1; i++) {
            ax += r->direction[3 * i];
            ay += r->direction[3 * i + 1];
            az += r->direction[3 * i + 2];
        }
        len = sqrt(ax * ax + ay * ay + az * az); /* > 0: every u_z > 0 */
        c[0] = ax / len;
        c[1] = ay / len;
        c[2] = az / len;
        for (i = i0; i < i1; i++) {
            double d = lk_dot(c, r->direction + 3 * i);
            if (d < cmin) cmin = d;
            if (r->length[i] < lmin) lmin = r->length[i];
            if (r->length[i] > lmax) lmax = r->length[i];
        }
        if (cmin > 1.0) cmin = 1.0;
        if (cmin < -1.0) cmin = -1.0;
        th = acos(cmin) + LK_CONE_PAD;
        if (th > LK_PI) th = LK_PI;
        c[3] = cos(th);
        c[4] = sin(th);
        c[5] = lmin;
        c[6] = lmax;
    }
}

/* Allocate a ray set's block and set its pointers (count, radius set). */
static hfvis_status lk_rays_alloc(int count, double radius, const hfvis_allocator *alloc,
                                  hfvis_lk_rays *r)
{
    int words = (count + 31) / 32;
    size_t doubles = 7 * (size_t)count + 7 * (size_t)words;
    double *block = (double *)lk_alloc(alloc, doubles * sizeof(double));
    if (!block) return HFVIS_ERR_OUT_OF_MEMORY;
    memset(r, 0, sizeof *r);
    r->count = count;
    r->words = words;
    r->radius = radius;
    r->direction = block;
    r->length = block + 3 * (size_t)count;
    r->point = block + 4 * (size_t)count;
    r->word_cone = block + 7 * (size_t)count;
    return HFVIS_OK;
}

/* Falloff inverse l/r = sup{x in [0, 1] : rho(x) >= xi}. */
static double lk_falloff_inverse(const hfvis_lk_ray_options *o, double xi)
{
    double lo = 0.0, hi = 1.0;
    int it;
    switch (o->falloff) {
    case HFVIS_LK_FALLOFF_LINEAR: return 1.0 - xi;
    case HFVIS_LK_FALLOFF_QUADRATIC: return 1.0 - sqrt(xi);
    case HFVIS_LK_FALLOFF_CUSTOM:
        if (o->falloff_fn(o->falloff_user, 1.0) >= xi) return 1.0;
        if (!(o->falloff_fn(o->falloff_user, 0.0) >= xi)) return 0.0;
        for (it = 0; it < 64; it++) {
            double mid = 0.5 * (lo + hi);
            if (o->falloff_fn(o->falloff_user, mid) >= xi) lo = mid;
            else hi = mid;
        }
        return lo;
    default: return 1.0;
    }
}

HFVIS_API hfvis_status hfvis_lk_rays_build(int count, double radius,
                                           const hfvis_lk_ray_options *opts, hfvis_lk_rays *out)
{
    hfvis_lk_ray_options o = hfvis_lk_ray_options_default();
    hfvis_lk_rays r;
    hfvis_status s;
    lk_pcg g;
    uint64_t *keys;
    double *xy;
    int i;
    if (!out || count < 1 || count > HFVIS_LK_MAX_RAYS || !isfinite(radius) || !(radius > 0.0))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (opts) {
        o.alloc = opts->alloc;
        o.seed = opts->seed;
        if (opts->pattern != HFVIS_LK_PATTERN_DEFAULT) o.pattern = opts->pattern;
        if (opts->lloyd_iterations) o.lloyd_iterations = opts->lloyd_iterations;
        if (opts->final_iterations) o.final_iterations = opts->final_iterations;
        if (opts->density_resolution) o.density_resolution = opts->density_resolution;
        if (opts->falloff != HFVIS_LK_FALLOFF_DEFAULT) o.falloff = opts->falloff;
        o.falloff_fn = opts->falloff_fn;
        o.falloff_user = opts->falloff_user;
    }
    if (o.pattern < HFVIS_LK_PATTERN_LLOYD || o.pattern > HFVIS_LK_PATTERN_LLOYD_TORUS ||
        o.lloyd_iterations < 1 || o.lloyd_iterations > 10000 || o.final_iterations < 1 ||
        o.final_iterations > 10000 || (o.density_resolution != 0 && o.density_resolution < 16) || o.density_resolution > 2048 ||
        o.falloff < HFVIS_LK_FALLOFF_CONSTANT || o.falloff > HFVIS_LK_FALLOFF_CUSTOM)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.falloff == HFVIS_LK_FALLOFF_CUSTOM) { /* finite, in [0, 1], non-increasing */
        double prev = 1.0;
        if (!o.falloff_fn) return HFVIS_ERR_INVALID_ARGUMENT;
        for (i = 0; i <= 1024; i++) {
            double v = o.falloff_fn(o.falloff_user, (double)i / 1024.0);
            if (!isfinite(v) || v < 0.0 || v > 1.0 || v > prev) return HFVIS_ERR_INVALID_ARGUMENT;
            prev = v;
        }
    }
    s = lk_rays_alloc(count, radius, o.alloc, &r);
    if (s != HFVIS_OK) return s;
    /* the disc points go to `point` (2n doubles), the sort keys to `length` (n, as u64) */
    xy = r.point;
    keys = (uint64_t *)(void *)r.length;
    lk_pcg_seed(&g, o.seed, 0x4C4B31u);
    if (o.pattern == HFVIS_LK_PATTERN_LLOYD || o.pattern == HFVIS_LK_PATTERN_LLOYD_TORUS) {
        s = lk_disc_lloyd(count, &o, &g, o.alloc, o.pattern == HFVIS_LK_PATTERN_LLOYD_TORUS, xy);
        if (s != HFVIS_OK) {
            lk_free(o.alloc, r.direction);
            return s;
        }
    } else {
        for (i = 0; i < count; i++) lk_disc_uniform(&g, xy + 2 * i, xy + 2 * i + 1);
    }
    /* Morton order of the disc points: each 32-ray word covers a compact patch */
    for (i = 0; i < count; i++) {
        uint32_t qx = (uint32_t)((xy[2 * i] + 1.0) * 32767.5);
        uint32_t qy = (uint32_t)((xy[2 * i + 1] + 1.0) * 32767.5);
        keys[i] = ((uint64_t)(lk_morton16(qx) | (lk_morton16(qy) << 1)) << 32) | (uint64_t)i;
    }
    qsort(keys, (size_t)count, sizeof(uint64_t), lk_cmp_u64);
    for (i = 0; i < count; i++) { /* Malley lifting (cosine-weighted) */
        size_t j = (size_t)(keys[i] & 0xFFFFFFFFu);
        double x = xy[2 * j], y = xy[2 * j + 1], z2 = 1.0 - x * x - y * y;
        r.direction[3 * i] = x;
        r.direction[3 * i + 1] = y;
        r.direction[3 * i + 2] = sqrt(z2 > 0.0 ? z2 : 0.0);
    }
    /* lengths: xi_i = (perm(i) + 1/2)/N, perm a seeded random permutation (stream 2) */
    {
        lk_pcg g2;
        uint32_t *perm = (uint32_t *)(void *)r.point; /* point is free again */
        lk_pcg_seed(&g2, o.seed, 0x4C4B32u);
        for (i = 0; i < count; i++) perm[i] = (uint32_t)i;
        for (i = count - 1; i > 0; i--) {
            uint32_t j = lk_pcg_below(&g2, (uint32_t)i + 1u), t = perm[i];
            perm[i] = perm[j];
            perm[j] = t;
        }
        for (i = 0; i < count; i++) {
            double xi = ((double)perm[i] + 0.5) / (double)count;
            r.length[i] = lk_falloff_inverse(&o, xi);
        }
    }
    for (i = 0; i < 3 * count; i++) r.point[i] = r.length[i / 3] * r.direction[i];
    lk_rays_finish(&r);
    *out = r;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_lk_rays_custom(int count, double radius, const double *directions,
                                            const double *lengths, const hfvis_allocator *alloc,
                                            hfvis_lk_rays *out)
{
    hfvis_lk_rays r;
    hfvis_status s;
    int i;
    if (!out || !directions || count < 1 || count > HFVIS_LK_MAX_RAYS || !isfinite(radius) ||
        !(radius > 0.0))
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (i = 0; i < count; i++) {
        const double *d = directions + 3 * i;
        double len2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        if (!lk_finite3(d) || !(len2 > 0.0) || !isfinite(len2) || !(d[2] / sqrt(len2) > 0.0))
            return HFVIS_ERR_INVALID_ARGUMENT;
        if (lengths && !(lengths[i] >= 0.0 && lengths[i] <= 1.0)) return HFVIS_ERR_INVALID_ARGUMENT;
    }
    s = lk_rays_alloc(count, radius, alloc, &r);
    if (s != HFVIS_OK) return s;
    for (i = 0; i < count; i++) {
        const double *d = directions + 3 * i;
        double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        int a;
        for (a = 0; a < 3; a++) r.direction[3 * i + a] = d[a] / len;
        r.length[i] = lengths ? lengths[i] : 1.0;
    }
    for (i = 0; i < 3 * count; i++) r.point[i] = r.length[i / 3] * r.direction[i];
    lk_rays_finish(&r);
    *out = r;
    return HFVIS_OK;
}

HFVIS_API void hfvis_lk_rays_free(const hfvis_allocator *alloc, hfvis_lk_rays *rays)
{
    if (!rays) return;
    lk_free(alloc, rays->direction);
    memset(rays, 0, sizeof *rays);
}

/* Largest value of n.u over the unit directions u of a word cone (n unit):
 * cos(max(phi - theta, 0)), phi = angle(n, axis). */
static double lk_cone_max(const double *cone, const double n[3])
{
    double c = lk_dot(n, cone), s;
    if (c >= cone[3]) return 1.0;
    s = 1.0 - c * c;
    s = s > 0.0 ? sqrt(s) : 0.0;
    return c * cone[3] + s * cone[4];
}

/* Least value of n.u over the cone: cos(min(phi + theta, pi)). */
static double lk_cone_min(const double *cone, const double n[3])
{
    double c = lk_dot(n, cone), s;
    if (-c >= cone[3]) return -1.0;
    s = 1.0 - c * c;
    s = s > 0.0 ? sqrt(s) : 0.0;
    return c * cone[3] - s * cone[4];
}

/* ---- 5.3 receiver frame (spec A.3) -------------------------------------------------------- */

/* Branchless orthonormal basis of the unit vector n: T. Duff, J. Burgess, P. Christensen et al.,
 * "Building an Orthonormal Basis, Revisited", JCGT 6(1), 2017, Listing 3. */
static void lk_onb(const double n[3], double t1[3], double t2[3])
{
    double sign = copysign(1.0, n[2]), a = -1.0 / (sign + n[2]), b = n[0] * n[1] * a;
    t1[0] = 1.0 + sign * n[0] * n[0] * a;
    t1[1] = sign * b;
    t1[2] = -sign * n[0];
    t2[0] = b;
    t2[1] = sign + n[1] * n[1] * a;
    t2[2] = -n[1];
}

/* Jitter parameters resolved once per call. */
typedef struct lk_jit {
    int none;
    double rot, tilt;  /* psi bound; delta = min(tilt_max, 0.9 min_elevation) */
    uint64_t seed;
} lk_jit;

static void lk_jit_init(lk_jit *j, const hfvis_lk_rays *r, hfvis_lk_jitter mode, double rot,
                        double tilt, uint64_t seed)
{
    j->none = mode == HFVIS_LK_JITTER_NONE;
    if (mode == HFVIS_LK_JITTER_DEFAULT) {
        rot = LK_PI;
        tilt = HFVIS_LK_DEFAULT_TILT;
    }
    j->rot = rot;
    j->tilt = tilt < 0.9 * r->min_elevation ? tilt : 0.9 * r->min_elevation;
    j->seed = seed;
}

/* The frame of a non-zero finite normal (rows x', y', z'). */
static void lk_frame_make(const lk_jit *j, const double normal[3], uint64_t key, double F[9])
{
    double n[3], t1[3], t2[3], len = sqrt(lk_dot(normal, normal));
    int a;
    for (a = 0; a < 3; a++) n[a] = normal[a] / len;
    lk_onb(n, t1, t2);
    if (j->none) {
        for (a = 0; a < 3; a++) {
            F[a] = t1[a];
            F[3 + a] = t2[a];
            F[6 + a] = n[a];
        }
        return;
    }
    {
        uint64_t s = j->seed ^ (key * 0xD1B54A32D192ED03ull);
        double x1 = (double)(lk_splitmix(&s) >> 11) * (1.0 / 9007199254740992.0);
        double x2 = (double)(lk_splitmix(&s) >> 11) * (1.0 / 9007199254740992.0);
        double x3 = (double)(lk_splitmix(&s) >> 11) * (1.0 / 9007199254740992.0);
        double dl = j->tilt * x1, ph = 2.0 * LK_PI * x2, psi = j->rot * (2.0 * x3 - 1.0);
        double np[3], x0[3], y0[3], cd = cos(dl), sd = sin(dl), cp = cos(ph), sp = sin(ph);
        double cs = cos(psi), sn = sin(psi);
        for (a = 0; a < 3; a++) np[a] = cd * n[a] + sd * (cp * t1[a] + sp * t2[a]);
        len = sqrt(lk_dot(np, np));
        for (a = 0; a < 3; a++) np[a] /= len;
        lk_onb(np, x0, y0);
        for (a = 0; a < 3; a++) {
            F[a] = cs * x0[a] + sn * y0[a];
            F[3 + a] = -sn * x0[a] + cs * y0[a];
            F[6 + a] = np[a];
        }
    }
}

static int lk_jitter_valid(hfvis_lk_jitter mode, double rot, double tilt)
{
    if (mode == HFVIS_LK_JITTER_DEFAULT || mode == HFVIS_LK_JITTER_NONE) return 1;
    return mode == HFVIS_LK_JITTER_CUSTOM && rot >= 0.0 && rot <= LK_PI && tilt >= 0.0 &&
           tilt <= 0.5 * LK_PI;
}

HFVIS_API hfvis_status hfvis_lk_frame(const hfvis_lk_rays *rays, const double normal[3],
                                      uint64_t seed, uint64_t key, hfvis_lk_jitter jitter,
                                      double rotation_max_rad, double tilt_max_rad,
                                      double frame[9])
{
    lk_jit j;
    double len2;
    if (!lk_rays_valid(rays) || !normal || !frame || !lk_finite3(normal) ||
        !lk_jitter_valid(jitter, rotation_max_rad, tilt_max_rad))
        return HFVIS_ERR_INVALID_ARGUMENT;
    len2 = lk_dot(normal, normal);
    if (!(len2 > 0.0) || !isfinite(len2)) return HFVIS_ERR_INVALID_ARGUMENT;
    lk_jit_init(&j, rays, jitter, rotation_max_rad, tilt_max_rad, seed);
    lk_frame_make(&j, normal, key, frame);
    return HFVIS_OK;
}

/* ---- 5.4 the blocking predicate, triangle masks, the plane look-up table -------------------- */

/* One triangle prepared for one receiver (spec A.4.1 in the receiver's frame). The predicate of
 * ray s is lk_blocks(t, s); dr = +infinity makes it false for every ray (skipped, facing away,
 * too far), so lk_blocks is the complete predicate whatever the verdict. */
typedef struct lk_tri {
    double e[9];        /* edge planes e1, e2, e3 (inside: e.s >= 0) */
    double m[3];        /* unit plane normal toward the plane (m.a = d > 0) */
    double dr;          /* d / r_max (+inf: never blocks) */
    double drmin;       /* d / r_min when 0 < d < r_min, else +inf */
    double zmax;        /* largest local z of the vertices (horizon test) */
    hfvis_lk_verdict verdict;
} lk_tri;

/* v - p in the frame F (each row dotted with the double difference, x + y + z). */
static void lk_local(const double F[9], const double p[3], const float v[3], double out[3])
{
    double dx = (double)v[0] - p[0], dy = (double)v[1] - p[1], dz = (double)v[2] - p[2];
    out[0] = F[0] * dx + F[1] * dy + F[2] * dz;
    out[1] = F[3] * dx + F[4] * dy + F[5] * dz;
    out[2] = F[6] * dx + F[7] * dy + F[8] * dz;
}

/* World zero-area test shared by every method: (v1 - v0) x (v2 - v0) in double exactly 0. */
static int lk_world_degenerate(const float *v0, const float *v1, const float *v2)
{
    double u[3], w[3], n[3];
    int a;
    for (a = 0; a < 3; a++) {
        u[a] = (double)v1[a] - (double)v0[a];
        w[a] = (double)v2[a] - (double)v0[a];
    }
    lk_cross(u, w, n);
    return n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0;
}

/* The setup of spec A.4.1 (see hfvis.h): a, b, c local; n = (b - a) x (c - a); h = nh.a; the
 * epsilon, one-sided and far rules; m and the oriented edge planes. */
static void lk_tri_setup(lk_tri *t, const double F[9], const double p[3], const float *v0,
                         const float *v1, const float *v2, int two_sided, double r_min,
                         double r_max, double eps)
{
    double a[3], b[3], c[3], u[3], w[3], n[3], len2, len, h, d;
    int k;
    t->dr = LK_INF;
    t->drmin = LK_INF;
    if (lk_world_degenerate(v0, v1, v2)) {
        memset(t->e, 0, sizeof t->e);
        t->m[0] = t->m[1] = t->m[2] = 0.0;
        t->zmax = 0.0;
        t->verdict = HFVIS_LK_TRI_DEGENERATE;
        return;
    }
    lk_local(F, p, v0, a);
    lk_local(F, p, v1, b);
    lk_local(F, p, v2, c);
    t->zmax = a[2] > b[2] ? a[2] : b[2];
    if (c[2] > t->zmax) t->zmax = c[2];
    for (k = 0; k < 3; k++) {
        u[k] = b[k] - a[k];
        w[k] = c[k] - a[k];
    }
    lk_cross(u, w, n);
    len2 = lk_dot(n, n);
    lk_cross(a, b, t->e);
    lk_cross(b, c, t->e + 3);
    lk_cross(c, a, t->e + 6);
    if (!(len2 > 0.0) || !isfinite(len2)) {
        t->m[0] = t->m[1] = t->m[2] = 0.0;
        t->verdict = HFVIS_LK_TRI_DEGENERATE;
        return;
    }
    len = sqrt(len2);
    for (k = 0; k < 3; k++) n[k] /= len;
    h = lk_dot(n, a);
    if (h < 0.0) { /* orient: m toward the plane, edge planes inward */
        for (k = 0; k < 3; k++) t->m[k] = -n[k];
        for (k = 0; k < 9; k++) t->e[k] = -t->e[k];
    } else {
        for (k = 0; k < 3; k++) t->m[k] = n[k];
    }
    d = fabs(h);
    if (!(d >= eps)) {
        t->verdict = HFVIS_LK_TRI_SELF;
        return;
    }
    if (!two_sided && h >= 0.0) {
        t->verdict = HFVIS_LK_TRI_FACING_AWAY;
        return;
    }
    if (d > r_max) {
        t->verdict = HFVIS_LK_TRI_TOO_FAR;
        return;
    }
    t->verdict = HFVIS_LK_TRI_MASKED;
    t->dr = d / r_max;
    if (r_min > 0.0 && d < r_min) t->drmin = d / r_min;
}

/* The predicate: s inside the three edge planes and the segment [0, s] reaching the plane
 * within the window (see hfvis.h). The only place it is evaluated. */
static int lk_blocks(const lk_tri *t, const double *s)
{
    double ms;
    if (t->e[0] * s[0] + t->e[1] * s[1] + t->e[2] * s[2] < 0.0) return 0;
    if (t->e[3] * s[0] + t->e[4] * s[1] + t->e[5] * s[2] < 0.0) return 0;
    if (t->e[6] * s[0] + t->e[7] * s[1] + t->e[8] * s[2] < 0.0) return 0;
    ms = t->m[0] * s[0] + t->m[1] * s[1] + t->m[2] * s[2];
    return ms >= t->dr && !(ms > t->drmin);
}

/* Exact triangle mask: the predicate for every ray; a word is skipped when its cone lies
 * outside an edge plane or cannot reach the plane, by more than LK_MARGIN (so the skipped
 * rays are exactly those the per-ray loop rejects). skip (may be NULL): the caller's
 * accumulated mask; words it has full are left 0 (the OR is the same). */
static void lk_mask_exact(const hfvis_lk_rays *R, const lk_tri *t, const uint32_t *skip,
                          uint32_t *out)
{
    double eh[9], lim;
    int w, k, i;
    if (t->dr == LK_INF) {
        memset(out, 0, sizeof(uint32_t) * (size_t)R->words);
        return;
    }
    for (k = 0; k < 3; k++) {
        const double *e = t->e + 3 * k;
        double len = sqrt(lk_dot(e, e));
        if (len > 0.0) {
            eh[3 * k] = e[0] / len;
            eh[3 * k + 1] = e[1] / len;
            eh[3 * k + 2] = e[2] / len;
        } else {
            eh[3 * k] = eh[3 * k + 1] = eh[3 * k + 2] = 0.0; /* never skips */
        }
    }
    lim = t->dr - LK_MARGIN * (1.0 + t->dr);
    for (w = 0; w < R->words; w++) {
        const double *cone = R->word_cone + 7 * w;
        int i0 = 32 * w, i1 = i0 + 32 < R->count ? i0 + 32 : R->count;
        uint32_t bits = 0;
        double mx;
        if (skip && (~skip[w] & lk_word_bits(R->count, w)) == 0) { /* all already blocked */
            out[w] = 0;
            continue;
        }
        mx = lk_cone_max(cone, t->m);
        if (lk_cone_max(cone, eh) < -LK_MARGIN || lk_cone_max(cone, eh + 3) < -LK_MARGIN ||
            lk_cone_max(cone, eh + 6) < -LK_MARGIN || (mx >= 0.0 ? cone[6] * mx : cone[5] * mx) < lim) {
            out[w] = 0;
            continue;
        }
        for (i = i0; i < i1; i++) { /* lk_blocks, branch-free (the same expressions) */
            const double *sp = R->point + 3 * i;
            double a = t->e[0] * sp[0] + t->e[1] * sp[1] + t->e[2] * sp[2];
            double b = t->e[3] * sp[0] + t->e[4] * sp[1] + t->e[5] * sp[2];
            double c = t->e[6] * sp[0] + t->e[7] * sp[1] + t->e[8] * sp[2];
            double ms = t->m[0] * sp[0] + t->m[1] * sp[1] + t->m[2] * sp[2];
            uint32_t hit = (uint32_t)((a >= 0.0) & (b >= 0.0) & (c >= 0.0) & (ms >= t->dr) & !(ms > t->drmin));
            bits |= hit << (i - i0);
        }
        out[w] = bits;
    }
}

/* ---- the 3-D plane table (spec A.4.2, node convention) ---- */

HFVIS_API size_t hfvis_lk_lut_bytes(int resolution, int count, int two_tables)
{
    size_t n, b;
    int words = hfvis_lk_mask_words(count);
    if (resolution < HFVIS_LK_LUT_MIN_RESOLUTION || resolution > HFVIS_LK_LUT_MAX_RESOLUTION ||
        words == 0)
        return 0;
    if (!lk_mul((size_t)resolution, (size_t)resolution, &n) || !lk_mul(n, (size_t)resolution, &n) ||
        !lk_mul(n, (size_t)words * sizeof(uint32_t), &b) || !lk_mul(b, two_tables ? 2 : 1, &b))
        return 0;
    return b;
}

static void lk_lut_fill(const hfvis_lk_rays *R, int T, int dirs, uint32_t *tab)
{
    const double *pts = dirs ? R->direction : R->point;
    int kx, ky, kz, w, i;
    size_t idx = 0;
    for (kz = 0; kz < T; kz++)
        for (ky = 0; ky < T; ky++)
            for (kx = 0; kx < T; kx++, idx += (size_t)R->words) {
                double q[3], s, len, m[3], delta;
                q[0] = -1.0 + 2.0 * kx / (T - 1);
                q[1] = -1.0 + 2.0 * ky / (T - 1);
                q[2] = -1.0 + 2.0 * kz / (T - 1);
                s = fabs(q[0]);
                if (fabs(q[1]) > s) s = fabs(q[1]);
                if (fabs(q[2]) > s) s = fabs(q[2]);
                if (s < 0.125) { /* unused core (d > r) */
                    memset(tab + idx, 0, sizeof(uint32_t) * (size_t)R->words);
                    continue;
                }
                len = sqrt(lk_dot(q, q));
                m[0] = q[0] / len;
                m[1] = q[1] / len;
                m[2] = q[2] / len;
                delta = (1.0 - s) * 8.0 / 7.0;
                for (w = 0; w < R->words; w++) {
                    const double *cone = R->word_cone + 7 * w;
                    double lmax = dirs ? 1.0 : cone[6], lmin = dirs ? 1.0 : cone[5];
                    double mx = lk_cone_max(cone, m), mn = lk_cone_min(cone, m);
                    int i0 = 32 * w, i1 = i0 + 32 < R->count ? i0 + 32 : R->count;
                    uint32_t bits = 0;
                    if ((mx >= 0.0 ? lmax * mx : lmin * mx) < delta - LK_MARGIN) {
                        tab[idx + (size_t)w] = 0;
                        continue;
                    }
                    if (mn > 0.0 && lmin * mn > delta + LK_MARGIN) {
                        tab[idx + (size_t)w] = lk_word_bits(R->count, w);
                        continue;
                    }
                    for (i = i0; i < i1; i++)
                        if (lk_dot(m, pts + 3 * i) > delta) bits |= 1u << (i - i0);
                    tab[idx + (size_t)w] = bits;
                }
            }
}

HFVIS_API hfvis_status hfvis_lk_lut_build(const hfvis_lk_rays *rays, int resolution,
                                          const hfvis_allocator *alloc, hfvis_lk_lut *out)
{
    size_t one, all;
    hfvis_lk_lut L;
    if (!lk_rays_valid(rays) || !out || resolution < HFVIS_LK_LUT_MIN_RESOLUTION ||
        resolution > HFVIS_LK_LUT_MAX_RESOLUTION)
        return HFVIS_ERR_INVALID_ARGUMENT;
    one = hfvis_lk_lut_bytes(resolution, rays->count, 0);
    all = hfvis_lk_lut_bytes(resolution, rays->count, !rays->equal_lengths);
    if (one == 0 || all == 0 || all > HFVIS_LK_LUT_MAX_BYTES) return HFVIS_ERR_LIMIT;
    memset(&L, 0, sizeof L);
    L.resolution = resolution;
    L.count = rays->count;
    L.words = rays->words;
    L.bytes = all;
    L.masks = (uint32_t *)lk_alloc(alloc, one);
    if (!L.masks) return HFVIS_ERR_OUT_OF_MEMORY;
    if (!rays->equal_lengths) {
        L.directions = (uint32_t *)lk_alloc(alloc, one);
        if (!L.directions) {
            lk_free(alloc, L.masks);
            return HFVIS_ERR_OUT_OF_MEMORY;
        }
    }
    lk_lut_fill(rays, resolution, 0, L.masks);
    if (L.directions) lk_lut_fill(rays, resolution, 1, L.directions);
    *out = L;
    return HFVIS_OK;
}

HFVIS_API void hfvis_lk_lut_free(const hfvis_allocator *alloc, hfvis_lk_lut *lut)
{
    if (!lut) return;
    lk_free(alloc, lut->directions);
    lk_free(alloc, lut->masks);
    memset(lut, 0, sizeof *lut);
}

/* Node of (m, delta); m finite and non-zero (checked by the callers). */
static size_t lk_lut_node(int T, const double m[3], double dr)
{
    double mx = fabs(m[0]), sc;
    int k[3], a;
    if (fabs(m[1]) > mx) mx = fabs(m[1]);
    if (fabs(m[2]) > mx) mx = fabs(m[2]);
    if (!(dr > 0.0)) dr = 0.0;
    if (dr > 1.0) dr = 1.0;
    sc = (1.0 - 7.0 * dr / 8.0) / mx;
    for (a = 0; a < 3; a++) {
        double f = floor((m[a] * sc + 1.0) * (T - 1) / 2.0 + 0.5);
        k[a] = f < 0.0 ? 0 : f > (double)(T - 1) ? T - 1 : (int)f;
    }
    return ((size_t)k[2] * (size_t)T + (size_t)k[1]) * (size_t)T + (size_t)k[0];
}

HFVIS_API hfvis_status hfvis_lk_lut_index(int resolution, const double m[3], double d_over_r,
                                          int ijk[3])
{
    size_t node, T = (size_t)resolution;
    if (!m || !ijk || resolution < HFVIS_LK_LUT_MIN_RESOLUTION ||
        resolution > HFVIS_LK_LUT_MAX_RESOLUTION || !lk_finite3(m) || !isfinite(d_over_r) ||
        (m[0] == 0.0 && m[1] == 0.0 && m[2] == 0.0))
        return HFVIS_ERR_INVALID_ARGUMENT;
    node = lk_lut_node(resolution, m, d_over_r);
    ijk[0] = (int)(node % T);
    ijk[1] = (int)(node / T % T);
    ijk[2] = (int)(node / T / T);
    return HFVIS_OK;
}

static const uint32_t *lk_lut_get(const hfvis_lk_lut *L, int dirs, const double m[3], double dr)
{
    const uint32_t *tab = dirs && L->directions ? L->directions : L->masks;
    return tab + lk_lut_node(L->resolution, m, dr) * (size_t)L->words;
}

static int lk_lut_valid(const hfvis_lk_lut *L)
{
    return L && L->masks && L->resolution >= HFVIS_LK_LUT_MIN_RESOLUTION &&
           L->resolution <= HFVIS_LK_LUT_MAX_RESOLUTION && L->words == hfvis_lk_mask_words(L->count);
}

HFVIS_API const uint32_t *hfvis_lk_lut_fetch(const hfvis_lk_lut *lut, int directions,
                                             const double m[3], double d_over_r)
{
    if (!lk_lut_valid(lut) || !m || !lk_finite3(m) || !isfinite(d_over_r) ||
        (m[0] == 0.0 && m[1] == 0.0 && m[2] == 0.0))
        return NULL;
    return lk_lut_get(lut, directions, m, d_over_r);
}

/* LUT triangle mask (spec A.4.2-A.4.3): lut(e1,0) & lut(e2,0) & lut(e3,0) & lut(m, d/r_max)
 * [& ~lut(m, d/r_min)]. A zero edge vector (a vertex direction through the origin twice)
 * constrains nothing. */
static void lk_mask_lut(const hfvis_lk_lut *L, const lk_tri *t, uint32_t *out)
{
    const uint32_t *pl;
    int w, k;
    if (t->dr == LK_INF || t->dr > 1.0) {
        memset(out, 0, sizeof(uint32_t) * (size_t)L->words);
        return;
    }
    pl = lk_lut_get(L, 0, t->m, t->dr);
    for (w = 0; w < L->words; w++) out[w] = pl[w];
    for (k = 0; k < 3; k++) {
        const double *e = t->e + 3 * k;
        if (e[0] == 0.0 && e[1] == 0.0 && e[2] == 0.0) continue;
        pl = lk_lut_get(L, 0, e, 0.0);
        for (w = 0; w < L->words; w++) out[w] &= pl[w];
    }
    if (t->drmin <= 1.0) {
        pl = lk_lut_get(L, 0, t->m, t->drmin);
        for (w = 0; w < L->words; w++) out[w] &= ~pl[w];
    }
}

HFVIS_API hfvis_status hfvis_lk_plane_mask(const hfvis_lk_rays *rays, const double m[3],
                                           double d_over_r, uint32_t *mask)
{
    int i;
    if (!lk_rays_valid(rays) || !m || !mask || !lk_finite3(m) || !isfinite(d_over_r))
        return HFVIS_ERR_INVALID_ARGUMENT;
    memset(mask, 0, sizeof(uint32_t) * (size_t)rays->words);
    for (i = 0; i < rays->count; i++)
        if (lk_dot(m, rays->point + 3 * i) >= d_over_r) mask[i >> 5] |= 1u << (i & 31);
    return HFVIS_OK;
}

static int lk_frame_valid(const double F[9])
{
    int k;
    for (k = 0; k < 9; k++)
        if (!isfinite(F[k])) return 0;
    return 1;
}

HFVIS_API hfvis_status hfvis_lk_triangle_mask(const hfvis_lk_rays *rays, const hfvis_lk_lut *lut,
                                              const double position[3], const double frame[9],
                                              const float v0[3], const float v1[3],
                                              const float v2[3], int two_sided, double r_min,
                                              double r_max, double epsilon, uint32_t *mask,
                                              hfvis_lk_verdict *verdict)
{
    lk_tri t;
    int a;
    if (!lk_rays_valid(rays) || !position || !frame || !v0 || !v1 || !v2 || !mask ||
        !lk_finite3(position) || !lk_frame_valid(frame) || !(r_min >= 0.0) || !(r_max >= r_min) ||
        !(r_max <= rays->radius) || !isfinite(epsilon) || !(epsilon > 0.0))
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (a = 0; a < 3; a++)
        if (!isfinite(v0[a]) || !isfinite(v1[a]) || !isfinite(v2[a])) return HFVIS_ERR_INVALID_ARGUMENT;
    if (lut && (!lk_lut_valid(lut) || lut->count != rays->count)) return HFVIS_ERR_INVALID_ARGUMENT;
    lk_tri_setup(&t, frame, position, v0, v1, v2, two_sided != 0, r_min, r_max,
                 epsilon);
    if (lut) lk_mask_lut(lut, &t, mask);
    else lk_mask_exact(rays, &t, NULL, mask);
    if (verdict) *verdict = t.verdict;
    return HFVIS_OK;
}

/* ---- 5.5 per-triangle bounds: minimal bounding sphere (A.5), hexagonal prism (A.6) -------- */

/* The minimal bounding sphere of a triangle (spec A.5 [choice]): the midpoint of the longest
 * edge when the triangle is right or obtuse, else the circumcentre; R = the largest distance
 * to a vertex, times (1 + 1e-12) (so every vertex is inside despite rounding). */
static void lk_tri_sphere(const float *v0, const float *v1, const float *v2, double c[3],
                          double *R)
{
    double A[3], B[3], C[3], ab2 = 0.0, bc2 = 0.0, ca2 = 0.0, r2 = 0.0;
    int k;
    for (k = 0; k < 3; k++) {
        A[k] = (double)v0[k];
        B[k] = (double)v1[k];
        C[k] = (double)v2[k];
        ab2 += (B[k] - A[k]) * (B[k] - A[k]);
        bc2 += (C[k] - B[k]) * (C[k] - B[k]);
        ca2 += (A[k] - C[k]) * (A[k] - C[k]);
    }
    if (ab2 >= bc2 + ca2) {
        for (k = 0; k < 3; k++) c[k] = 0.5 * (A[k] + B[k]);
    } else if (bc2 >= ca2 + ab2) {
        for (k = 0; k < 3; k++) c[k] = 0.5 * (B[k] + C[k]);
    } else if (ca2 >= ab2 + bc2) {
        for (k = 0; k < 3; k++) c[k] = 0.5 * (C[k] + A[k]);
    } else { /* acute: circumcentre C + ((|a|^2 b - |b|^2 a) x (a x b)) / (2 |a x b|^2) */
        double a[3], b[3], axb[3], q[3], t[3], den;
        for (k = 0; k < 3; k++) {
            a[k] = A[k] - C[k];
            b[k] = B[k] - C[k];
        }
        lk_cross(a, b, axb);
        den = 2.0 * lk_dot(axb, axb);
        for (k = 0; k < 3; k++) q[k] = lk_dot(a, a) * b[k] - lk_dot(b, b) * a[k];
        lk_cross(q, axb, t);
        for (k = 0; k < 3; k++) c[k] = C[k] + t[k] / den;
        if (!lk_finite3(c) || !(den > 0.0)) /* (nearly) degenerate: centroid */
            for (k = 0; k < 3; k++) c[k] = (A[k] + B[k] + C[k]) / 3.0;
    }
    for (k = 0; k < 3; k++) {
        const double *v = k == 0 ? A : k == 1 ? B : C;
        double d2 = (v[0] - c[0]) * (v[0] - c[0]) + (v[1] - c[1]) * (v[1] - c[1]) +
                    (v[2] - c[2]) * (v[2] - c[2]);
        if (d2 > r2) r2 = d2;
    }
    *R = sqrt(r2) * (1.0 + 1e-12);
}

/* Absolute margin of the volumes and sphere tests of a triangle: 1e-9 of (r_max + R_T) plus
 * 1e-12 of the coordinates' magnitude (covers the rounding of plane offsets). */
static double lk_margin(double r_max, double R, const float *v0, const float *v1, const float *v2)
{
    double mag = 0.0;
    int k;
    for (k = 0; k < 3; k++) {
        if (fabs((double)v0[k]) > mag) mag = fabs((double)v0[k]);
        if (fabs((double)v1[k]) > mag) mag = fabs((double)v1[k]);
        if (fabs((double)v2[k]) > mag) mag = fabs((double)v2[k]);
    }
    return LK_MARGIN * (r_max + R) + 1e-12 * mag;
}

/* The hexagonal prism of spec A.6 in half-space form, pl[j] = (n, c) meaning n.x <= c:
 * o_k.(x - v_k) <= r (the offset edge lines A, B, C of [LK] Fig. 2), u_k.(x - v_k) <= r (the
 * corner cuts P, Q, R, u_k = the bisector of o_{k-1} and o_k), n.(x - v0) <= r and
 * -n.(x - v0) <= low; and its vertices (nv <= 12): the base polygon - the enlarged triangle
 * with corners v_k + r (o_{k-1} + o_k)/(1 + o_{k-1}.o_k) clipped by the three cuts
 * (Sutherland-Hodgman in the plane: the hexagon, or fewer vertices where cuts meet) - lifted by
 * +r and -low along n. Returns 0 when ill-conditioned (a near-180-degree corner, non-finite
 * values); the sphere billboard is used then. */
typedef struct lk_prism {
    double pl[8][4];
    double vtx[16][3];
    int nv;
} lk_prism;

static int lk_prism_build(const float *f0, const float *f1, const float *f2, double r, double low,
                          lk_prism *P)
{
    double V[3][3], u[3], w[3], n[3], o[3][3], ub[3][3], len, poly[2][8][3];
    int k, a, np = 3, cur = 0;
    for (a = 0; a < 3; a++) {
        V[0][a] = (double)f0[a];
        V[1][a] = (double)f1[a];
        V[2][a] = (double)f2[a];
        u[a] = V[1][a] - V[0][a];
        w[a] = V[2][a] - V[0][a];
    }
    lk_cross(u, w, n);
    len = sqrt(lk_dot(n, n));
    if (!(len > 0.0) || !isfinite(len)) return 0;
    for (a = 0; a < 3; a++) n[a] /= len;
    for (k = 0; k < 3; k++) { /* outward edge normals (v_{k+1} - v_k) x n */
        double e[3];
        for (a = 0; a < 3; a++) e[a] = V[(k + 1) % 3][a] - V[k][a];
        lk_cross(e, n, o[k]);
        len = sqrt(lk_dot(o[k], o[k]));
        if (!(len > 0.0) || !isfinite(len)) return 0;
        for (a = 0; a < 3; a++) o[k][a] /= len;
    }
    for (k = 0; k < 3; k++) {
        const double *op = o[(k + 2) % 3];
        double den = 1.0 + lk_dot(op, o[k]);
        for (a = 0; a < 3; a++) ub[k][a] = op[a] + o[k][a];
        len = sqrt(lk_dot(ub[k], ub[k]));
        if (!(len > 1e-6) || !(den > 1e-12)) return 0; /* a near-180-degree corner */
        for (a = 0; a < 3; a++) {
            ub[k][a] /= len;
            poly[0][k][a] = V[k][a] + r * (op[a] + o[k][a]) / den; /* enlarged corner */
        }
    }
    for (k = 0; k < 3; k++) {
        for (a = 0; a < 3; a++) P->pl[k][a] = o[k][a];
        P->pl[k][3] = lk_dot(o[k], V[k]) + r;
        for (a = 0; a < 3; a++) P->pl[3 + k][a] = ub[k][a];
        P->pl[3 + k][3] = lk_dot(ub[k], V[k]) + r;
    }
    for (a = 0; a < 3; a++) {
        P->pl[6][a] = n[a];
        P->pl[7][a] = -n[a];
    }
    P->pl[6][3] = lk_dot(n, V[0]) + r;
    P->pl[7][3] = -lk_dot(n, V[0]) + low;
    for (k = 0; k < 3; k++) { /* clip by the corner cut u_k.x <= c_k */
        int i, nn = 0;
        const double *pl = P->pl[3 + k];
        for (i = 0; i < np; i++) {
            const double *p0 = poly[cur][i], *p1 = poly[cur][(i + 1) % np];
            double f0v = lk_dot(pl, p0) - pl[3], f1v = lk_dot(pl, p1) - pl[3];
            if (f0v <= 0.0) {
                for (a = 0; a < 3; a++) poly[1 - cur][nn][a] = p0[a];
                nn++;
            }
            if ((f0v < 0.0 && f1v > 0.0) || (f0v > 0.0 && f1v < 0.0)) {
                double t = f0v / (f0v - f1v);
                for (a = 0; a < 3; a++) poly[1 - cur][nn][a] = p0[a] + t * (p1[a] - p0[a]);
                nn++;
            }
        }
        cur = 1 - cur;
        np = nn;
        if (np < 3 || np > 6) return 0;
    }
    for (k = 0; k < np; k++)
        for (a = 0; a < 3; a++) {
            P->vtx[2 * k][a] = poly[cur][k][a] + r * n[a];
            P->vtx[2 * k + 1][a] = poly[cur][k][a] - low * n[a];
        }
    P->nv = 2 * np;
    for (k = 0; k < P->nv; k++)
        if (!lk_finite3(P->vtx[k])) return 0;
    for (k = 0; k < 8; k++)
        if (!isfinite(P->pl[k][3])) return 0;
    return 1;
}

/* Parameter interval of the line o + tD inside the prism (Cyrus-Beck); 0 if empty. */
static int lk_prism_clip(const lk_prism *P, const double o[3], const double D[3], double *t_in,
                         double *t_out)
{
    double ti = -LK_INF, to = LK_INF;
    int k;
    for (k = 0; k < 8; k++) {
        double num = P->pl[k][3] - lk_dot(P->pl[k], o), den = lk_dot(P->pl[k], D);
        if (den == 0.0) {
            if (num < 0.0) return 0;
        } else if (den > 0.0) {
            double t = num / den;
            if (t < to) to = t;
        } else {
            double t = num / den;
            if (t > ti) ti = t;
        }
    }
    *t_in = ti;
    *t_out = to;
    return ti <= to;
}

/* Interval of o + tD inside the ball (c, R); 0 if the line misses it. */
static int lk_ball_clip(const double c[3], double R, const double o[3], const double D[3],
                        double *t_in, double *t_out)
{
    double oc[3], A, B, C, disc, sq;
    int a;
    for (a = 0; a < 3; a++) oc[a] = o[a] - c[a];
    A = lk_dot(D, D);
    B = lk_dot(D, oc);
    C = lk_dot(oc, oc) - R * R;
    disc = B * B - A * C;
    if (!(A > 0.0) || disc < 0.0) return 0;
    sq = sqrt(disc);
    *t_in = (-B - sq) / A;
    *t_out = (-B + sq) / A;
    return 1;
}

/* ---- 5.6 options ---------------------------------------------------------------------------- */

HFVIS_API hfvis_lk_options hfvis_lk_options_default(void)
{
    hfvis_lk_options o;
    memset(&o, 0, sizeof o);
    o.mask_mode = HFVIS_LK_MASK_EXACT;
    o.node_mask = HFVIS_LK_NODE_EXACT;
    o.cull = HFVIS_LK_CULL_ALL;
    o.sides = HFVIS_LK_SIDES_ONE;
    o.jitter = HFVIS_LK_JITTER_DEFAULT;
    o.volume = HFVIS_LK_VOLUME_AUTO;
    o.alpha = HFVIS_LK_DEFAULT_ALPHA;
    o.gbuffer_cull = HFVIS_CULL_NONE;
    o.raycast_test = HFVIS_LK_RAYCAST_EXACT;
    return o;
}

HFVIS_API hfvis_status hfvis_lk_options_resolve(const hfvis_lk_options *in, double radius,
                                                hfvis_lk_options *out)
{
    hfvis_lk_options o = hfvis_lk_options_default();
    if (!out || !isfinite(radius) || !(radius > 0.0)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (in) {
        o = *in;
        if (o.mask_mode == HFVIS_LK_MASK_DEFAULT) o.mask_mode = HFVIS_LK_MASK_EXACT;
        if (o.node_mask == HFVIS_LK_NODE_DEFAULT) o.node_mask = HFVIS_LK_NODE_EXACT;
        if (o.cull == 0) o.cull = HFVIS_LK_CULL_ALL;
        if (o.sides == HFVIS_LK_SIDES_DEFAULT) o.sides = HFVIS_LK_SIDES_ONE;
        if (o.volume == HFVIS_LK_VOLUME_DEFAULT) o.volume = HFVIS_LK_VOLUME_AUTO;
        if (o.alpha == 0.0) o.alpha = HFVIS_LK_DEFAULT_ALPHA;
        if (o.raycast_test == HFVIS_LK_RAYCAST_DEFAULT) o.raycast_test = HFVIS_LK_RAYCAST_EXACT;
    }
    if (o.epsilon == 0.0) o.epsilon = HFVIS_LK_DEFAULT_EPSILON * radius;
    if (o.mask_mode != HFVIS_LK_MASK_EXACT && o.mask_mode != HFVIS_LK_MASK_LUT)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.node_mask < HFVIS_LK_NODE_EXACT || o.node_mask > HFVIS_LK_NODE_NONE)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (!(o.cull & HFVIS_LK_CULL_SET) || (o.cull & ~(HFVIS_LK_CULL_SET | 0x3Fu)))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.sides < HFVIS_LK_SIDES_ONE || o.sides > HFVIS_LK_SIDES_PER_TRIANGLE ||
        (o.sides == HFVIS_LK_SIDES_PER_TRIANGLE && !o.two_sided))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (!isfinite(o.epsilon) || !(o.epsilon > 0.0) || !isfinite(o.alpha) || !(o.alpha > 0.0))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (!lk_jitter_valid(o.jitter, o.rotation_max_rad, o.tilt_max_rad))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.jitter == HFVIS_LK_JITTER_DEFAULT) {
        o.rotation_max_rad = LK_PI;
        o.tilt_max_rad = HFVIS_LK_DEFAULT_TILT;
    } else if (o.jitter == HFVIS_LK_JITTER_NONE) {
        o.rotation_max_rad = 0.0;
        o.tilt_max_rad = 0.0;
    }
    if (o.volume < HFVIS_LK_VOLUME_AUTO || o.volume > HFVIS_LK_VOLUME_SPHERE)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.gbuffer_cull != HFVIS_CULL_NONE && o.gbuffer_cull != HFVIS_CULL_BACK &&
        o.gbuffer_cull != HFVIS_CULL_FRONT)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.raycast_test != HFVIS_LK_RAYCAST_EXACT && o.raycast_test != HFVIS_LK_RAYCAST_WATERTIGHT)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if ((o.mask_mode == HFVIS_LK_MASK_LUT || o.node_mask == HFVIS_LK_NODE_SPHERE_LUT) &&
        !lk_lut_valid(o.lut))
        return HFVIS_ERR_INVALID_ARGUMENT;
    *out = o;
    return HFVIS_OK;
}

/* Everything a method needs, resolved once per call. */
typedef struct lk_ctx {
    const hfvis_lk_rays *R;
    const hfvis_mesh *mesh;
    hfvis_lk_options o;
    lk_jit jit;
    unsigned cull;
    int words;
    double r;
    const hfvis_lk_lut *lut;   /* LUT triangle masks, or NULL (exact) */
} lk_ctx;

/* Resolve options and check the parts shared by all methods (rays, mesh, windows, LUT). */
static hfvis_status lk_ctx_init(lk_ctx *c, const hfvis_mesh *mesh, const hfvis_lk_rays *R,
                                const hfvis_lk_options *opts)
{
    hfvis_status s;
    size_t t;
    if (!lk_rays_valid(R)) return HFVIS_ERR_INVALID_ARGUMENT;
    s = hfvis_lk_options_resolve(opts, R->radius, &c->o);
    if (s != HFVIS_OK) return s;
    if (c->o.lut && (c->o.mask_mode == HFVIS_LK_MASK_LUT || c->o.node_mask == HFVIS_LK_NODE_SPHERE_LUT) &&
        c->o.lut->count != R->count)
        return HFVIS_ERR_INVALID_ARGUMENT;
    s = lk_mesh_check(mesh);
    if (s != HFVIS_OK) return s;
    if (c->o.lod_range)
        for (t = 0; t < mesh->triangle_count; t++) {
            double lo = (double)c->o.lod_range[2 * t], hi = (double)c->o.lod_range[2 * t + 1];
            if (!(lo >= 0.0) || !(hi >= lo) || !(hi <= R->radius)) return HFVIS_ERR_INVALID_ARGUMENT;
        }
    c->R = R;
    c->mesh = mesh;
    c->cull = c->o.cull;
    c->words = R->words;
    c->r = R->radius;
    c->lut = c->o.mask_mode == HFVIS_LK_MASK_LUT ? c->o.lut : NULL;
    lk_jit_init(&c->jit, R, c->o.jitter, c->o.rotation_max_rad, c->o.tilt_max_rad, c->o.seed);
    return HFVIS_OK;
}

static int lk_two_sided(const lk_ctx *c, size_t t)
{
    if (c->o.sides == HFVIS_LK_SIDES_TWO) return 1;
    if (c->o.sides == HFVIS_LK_SIDES_PER_TRIANGLE) return c->o.two_sided[t] != 0;
    return 0;
}

static void lk_window(const lk_ctx *c, size_t t, double *r_min, double *r_max)
{
    if (c->o.lod_range) {
        *r_min = (double)c->o.lod_range[2 * t];
        *r_max = (double)c->o.lod_range[2 * t + 1];
    } else {
        *r_min = 0.0;
        *r_max = c->r;
    }
}

/* The triangle mask after the setup (exact or LUT); skip as lk_mask_exact. */
static void lk_ctx_mask(const lk_ctx *c, const lk_tri *t, const uint32_t *skip, uint32_t *out)
{
    if (c->lut) lk_mask_lut(c->lut, t, out);
    else lk_mask_exact(c->R, t, skip, out);
}

/* Receivers' validity: finite positions, finite non-zero normals. */
static int lk_receivers_valid(const hfvis_lk_receivers *rc)
{
    size_t i;
    if (!rc || (rc->count && (!rc->position || !rc->normal))) return 0;
    if (rc->count > SIZE_MAX / 3) return 0;
    for (i = 0; i < rc->count; i++) {
        const double *p = rc->position + 3 * i, *n = rc->normal + 3 * i;
        double l2 = lk_dot(n, n);
        if (!lk_finite3(p) || !lk_finite3(n) || !(l2 > 0.0) || !isfinite(l2)) return 0;
    }
    return 1;
}

/* ---- 5.7 G-buffer receivers and Method 1 (rasterization) ----------------------------------- */

/* The camera quantities Method 1 needs (hfvis_view conventions: column-major, rigid view). */
typedef struct lk_cam {
    double PV[16];     /* proj * view */
    double eye[3];     /* perspective centre */
    double fwd[3];     /* unit viewing direction (world) */
    double drow[4];    /* linear depth -z_eye = drow . (x, 1) */
    int ortho, W, H;
} lk_cam;

static hfvis_status lk_cam_init(lk_cam *c, const hfvis_view *v)
{
    const double *m = v->view;
    double len;
    int k, j;
    if (v->width < 1 || v->height < 1) return HFVIS_ERR_INVALID_ARGUMENT;
    for (k = 0; k < 16; k++)
        if (!isfinite(v->view[k]) || !isfinite(v->proj[k])) return HFVIS_ERR_INVALID_ARGUMENT;
    hfvis_mat4_multiply(v->proj, v->view, c->PV);
    for (k = 0; k < 3; k++) c->fwd[k] = -m[k * 4 + 2];
    len = sqrt(lk_dot(c->fwd, c->fwd));
    if (!(len > 0.0)) return HFVIS_ERR_INVALID_ARGUMENT;
    for (k = 0; k < 3; k++) c->fwd[k] /= len;
    for (j = 0; j < 3; j++)
        c->eye[j] = -(m[j * 4 + 0] * m[12] + m[j * 4 + 1] * m[13] + m[j * 4 + 2] * m[14]);
    c->drow[0] = -m[2];
    c->drow[1] = -m[6];
    c->drow[2] = -m[10];
    c->drow[3] = -m[14];
    c->ortho = v->orthographic != 0;
    c->W = v->width;
    c->H = v->height;
    return HFVIS_OK;
}

static double lk_depth(const lk_cam *c, const double x[3])
{
    return c->drow[0] * x[0] + c->drow[1] * x[1] + c->drow[2] * x[2] + c->drow[3];
}

/* Pixel bounding box [x0, x1] x [y0, y1] of the pixel centres covered by the projection of the
 * convex hull of pts (one pixel of margin); the whole image when a point is not in front of
 * the eye (w <= 0) or the projection is not finite. */
static void lk_screen_box(const lk_cam *c, const double (*pts)[3], int n, int box[4])
{
    double mnx = LK_INF, mny = LK_INF, mxx = -LK_INF, mxy = -LK_INF, f;
    int k;
    for (k = 0; k < n; k++) {
        const double *p = pts[k];
        double cx = c->PV[0] * p[0] + c->PV[4] * p[1] + c->PV[8] * p[2] + c->PV[12];
        double cy = c->PV[1] * p[0] + c->PV[5] * p[1] + c->PV[9] * p[2] + c->PV[13];
        double cw = c->PV[3] * p[0] + c->PV[7] * p[1] + c->PV[11] * p[2] + c->PV[15];
        double px, py;
        if (!(cw > 0.0)) goto full;
        px = (cx / cw + 1.0) * 0.5 * c->W;
        py = (1.0 - cy / cw) * 0.5 * c->H;
        if (!isfinite(px) || !isfinite(py)) goto full;
        if (px < mnx) mnx = px;
        if (px > mxx) mxx = px;
        if (py < mny) mny = py;
        if (py > mxy) mxy = py;
    }
    f = ceil(mnx - 0.5) - 1.0;
    box[0] = f < 0.0 ? 0 : f > (double)(c->W - 1) ? c->W : (int)f;
    f = floor(mxx - 0.5) + 1.0;
    box[1] = f < 0.0 ? -1 : f > (double)(c->W - 1) ? c->W - 1 : (int)f;
    f = ceil(mny - 0.5) - 1.0;
    box[2] = f < 0.0 ? 0 : f > (double)(c->H - 1) ? c->H : (int)f;
    f = floor(mxy - 0.5) + 1.0;
    box[3] = f < 0.0 ? -1 : f > (double)(c->H - 1) ? c->H - 1 : (int)f;
    return;
full:
    box[0] = 0;
    box[1] = c->W - 1;
    box[2] = 0;
    box[3] = c->H - 1;
}

/* Rasterize triangle ids and barycentrics into one block (ids first). */
static hfvis_status lk_gbuffer_run(const hfvis_mesh *mesh, const hfvis_view *view,
                                   hfvis_cull_mode cull, const hfvis_allocator *alloc,
                                   uint32_t **ids, float **bary)
{
    size_t n, bytes = 0;
    unsigned char *block, *cur;
    hfvis_raster_options ro;
    hfvis_raster_outputs out;
    hfvis_status s;
    if (view->width < 1 || view->height < 1) return HFVIS_ERR_INVALID_ARGUMENT;
    if (view->width > HFVIS_RASTER_MAX_SIZE || view->height > HFVIS_RASTER_MAX_SIZE)
        return HFVIS_ERR_LIMIT;
    n = (size_t)view->width * (size_t)view->height;
    if (!lk_part(&bytes, n, sizeof(uint32_t)) || !lk_part(&bytes, n, 2 * sizeof(float)))
        return HFVIS_ERR_LIMIT; /* only on 32-bit size_t */
    block = (unsigned char *)lk_alloc(alloc, bytes);
    if (!block) return HFVIS_ERR_OUT_OF_MEMORY;
    cur = block;
    memset(&ro, 0, sizeof ro);
    ro.alloc = alloc;
    ro.cull = cull;
    memset(&out, 0, sizeof out);
    out.triangle_id = (uint32_t *)lk_take(&cur, n, sizeof(uint32_t));
    out.barycentric = (float *)lk_take(&cur, n, 2 * sizeof(float));
    s = hfvis_rasterize(mesh, view, &ro, &out);
    if (s != HFVIS_OK) {
        lk_free(alloc, block);
        return s;
    }
    *ids = out.triangle_id;
    *bary = out.barycentric;
    return HFVIS_OK;
}

/* The receiver of a covered pixel: p = (1 - b1 - b2) v0 + b1 v1 + b2 v2 (double), the face
 * normal turned toward the viewer. */
static void lk_pixel_receiver(const hfvis_mesh *m, const lk_cam *c, uint32_t tri, const float *b,
                              double p[3], double n[3])
{
    const float *v0 = lk_vertex(m, tri, 0), *v1 = lk_vertex(m, tri, 1), *v2 = lk_vertex(m, tri, 2);
    double b1 = (double)b[0], b2 = (double)b[1], b0 = 1.0 - b1 - b2, u[3], w[3], s;
    int a;
    for (a = 0; a < 3; a++) {
        p[a] = b0 * (double)v0[a] + b1 * (double)v1[a] + b2 * (double)v2[a];
        u[a] = (double)v1[a] - (double)v0[a];
        w[a] = (double)v2[a] - (double)v0[a];
    }
    lk_cross(u, w, n);
    if (c->ortho) s = -lk_dot(n, c->fwd);
    else s = n[0] * (c->eye[0] - p[0]) + n[1] * (c->eye[1] - p[1]) + n[2] * (c->eye[2] - p[2]);
    if (s < 0.0)
        for (a = 0; a < 3; a++) n[a] = -n[a];
}

HFVIS_API hfvis_status hfvis_lk_gbuffer_receivers(const hfvis_mesh *mesh, const hfvis_view *view,
                                                  const hfvis_lk_options *opts, double *position,
                                                  double *normal, uint64_t *key, size_t *count)
{
    hfvis_lk_options o;
    lk_cam cam;
    uint32_t *ids;
    float *bary;
    size_t i, n, k = 0;
    hfvis_status s;
    if (!mesh || !view || !position || !normal || !count) return HFVIS_ERR_INVALID_ARGUMENT;
    s = hfvis_lk_options_resolve(opts, 1.0, &o);
    if (s != HFVIS_OK) return s;
    s = lk_cam_init(&cam, view);
    if (s != HFVIS_OK) return s;
    s = lk_gbuffer_run(mesh, view, o.gbuffer_cull, o.alloc, &ids, &bary);
    if (s != HFVIS_OK) return s;
    n = (size_t)view->width * (size_t)view->height;
    for (i = 0; i < n; i++) {
        if (ids[i] == HFVIS_NO_TRIANGLE) continue;
        lk_pixel_receiver(mesh, &cam, ids[i], bary + 2 * i, position + 3 * k, normal + 3 * k);
        if (key) key[k] = (uint64_t)i;
        k++;
    }
    *count = k;
    lk_free(o.alloc, ids);
    return HFVIS_OK;
}

/* Method 1 receiver record: p (3), frame (9), linear depth (1). */
#define LK_REC 13

HFVIS_API hfvis_status hfvis_lk_raster(const hfvis_mesh *mesh, const hfvis_view *view,
                                       const hfvis_lk_rays *rays, const hfvis_lk_options *opts,
                                       uint32_t *masks, float *obscurance, hfvis_lk_stats *stats)
{
    lk_ctx ctx;
    lk_cam cam;
    hfvis_lk_stats st;
    hfvis_status s;
    uint32_t *ids = NULL, *acc, *tmask;
    float *bary = NULL;
    int32_t *recidx;
    double *rec;
    unsigned char *block, *cur;
    size_t npix, nrec = 0, i, t, bytes = 0, maskwords;
    int words;
    if (!mesh || !view || !rays || (!masks && !obscurance)) return HFVIS_ERR_INVALID_ARGUMENT;
    s = lk_ctx_init(&ctx, mesh, rays, opts);
    if (s != HFVIS_OK) return s;
    s = lk_cam_init(&cam, view);
    if (s != HFVIS_OK) return s;
    words = ctx.words;
    if (view->width > HFVIS_RASTER_MAX_SIZE || view->height > HFVIS_RASTER_MAX_SIZE)
        return HFVIS_ERR_LIMIT;
    npix = (size_t)view->width * (size_t)view->height;
    if (!lk_mul(npix, (size_t)words, &maskwords) || maskwords > SIZE_MAX / sizeof(uint32_t))
        return HFVIS_ERR_LIMIT;
    s = lk_gbuffer_run(mesh, view, ctx.o.gbuffer_cull, ctx.o.alloc, &ids, &bary);
    if (s != HFVIS_OK) return s;
    for (i = 0; i < npix; i++) nrec += ids[i] != HFVIS_NO_TRIANGLE;
    if (!lk_part(&bytes, npix, sizeof(int32_t)) || !lk_part(&bytes, nrec, LK_REC * sizeof(double)) ||
        !lk_part(&bytes, (size_t)words, sizeof(uint32_t)) ||
        (!masks && !lk_part(&bytes, nrec, (size_t)words * sizeof(uint32_t)))) {
        lk_free(ctx.o.alloc, ids);
        return HFVIS_ERR_LIMIT; /* only on 32-bit size_t */
    }
    block = (unsigned char *)lk_alloc(ctx.o.alloc, bytes);
    if (!block) {
        lk_free(ctx.o.alloc, ids);
        return HFVIS_ERR_OUT_OF_MEMORY;
    }
    cur = block;
    recidx = (int32_t *)lk_take(&cur, npix, sizeof(int32_t));
    rec = (double *)lk_take(&cur, nrec, LK_REC * sizeof(double));
    tmask = (uint32_t *)lk_take(&cur, (size_t)words, sizeof(uint32_t));
    acc = masks ? masks : (uint32_t *)lk_take(&cur, nrec, (size_t)words * sizeof(uint32_t));
    /* receivers (Method 1 step 1) and frames */
    nrec = 0;
    for (i = 0; i < npix; i++) {
        double n[3], *r;
        if (ids[i] == HFVIS_NO_TRIANGLE) {
            recidx[i] = -1;
            continue;
        }
        r = rec + LK_REC * nrec;
        lk_pixel_receiver(mesh, &cam, ids[i], bary + 2 * i, r, n);
        lk_frame_make(&ctx.jit, n, (uint64_t)i, r + 3);
        r[12] = lk_depth(&cam, r);
        recidx[i] = (int32_t)nrec++;
    }
    lk_free(ctx.o.alloc, ids);
    /* occlusion buffers cleared (step 2); masks[pixel] or acc[receiver] */
    memset(acc, 0, sizeof(uint32_t) * (masks ? maskwords : nrec * (size_t)words));
    memset(&st, 0, sizeof st);
    for (t = 0; t < mesh->triangle_count; t++) { /* step 3, per triangle */
        const float *f0 = lk_vertex(mesh, t, 0), *f1 = lk_vertex(mesh, t, 1), *f2 = lk_vertex(mesh, t, 2);
        double rmin, rmax, c[3], R, mabs, rr, low, Rs, nw[3], dmin, dc, vd;
        int two = lk_two_sided(&ctx, t), prism, box[4], x, y, k;
        lk_prism P;
        lk_window(&ctx, t, &rmin, &rmax);
        if (lk_world_degenerate(f0, f1, f2) || !(rmax > 0.0)) continue; /* never blocks */
        lk_tri_sphere(f0, f1, f2, c, &R);
        mabs = lk_margin(rmax, R, f0, f1, f2);
        rr = rmax + mabs;
        low = two ? rr : ctx.o.epsilon + mabs;
        Rs = R + rr;
        prism = ctx.o.volume == HFVIS_LK_VOLUME_PRISM ||
                (ctx.o.volume == HFVIS_LK_VOLUME_AUTO && R / rmax > ctx.o.alpha);
        if (prism && !lk_prism_build(f0, f1, f2, rr, low, &P)) prism = 0;
        {
            double u[3], w[3], len;
            for (k = 0; k < 3; k++) {
                u[k] = (double)f1[k] - (double)f0[k];
                w[k] = (double)f2[k] - (double)f0[k];
            }
            lk_cross(u, w, nw);
            len = sqrt(lk_dot(nw, nw));
            for (k = 0; k < 3; k++) nw[k] /= len;
        }
        if (prism) {
            st.prisms++;
            lk_screen_box(&cam, (const double(*)[3])P.vtx, P.nv, box);
        } else {
            double corners[8][3];
            st.spheres++;
            for (k = 0; k < 8; k++) {
                corners[k][0] = c[0] + ((k & 1) ? Rs : -Rs);
                corners[k][1] = c[1] + ((k & 2) ? Rs : -Rs);
                corners[k][2] = c[2] + ((k & 4) ? Rs : -Rs);
            }
            lk_screen_box(&cam, (const double(*)[3])corners, 8, box);
        }
        {
            double v[3];
            for (k = 0; k < 3; k++) v[k] = (double)f0[k];
            dmin = lk_depth(&cam, v);
            for (k = 0; k < 3; k++) v[k] = (double)f1[k];
            vd = lk_depth(&cam, v);
            if (vd < dmin) dmin = vd;
            for (k = 0; k < 3; k++) v[k] = (double)f2[k];
            vd = lk_depth(&cam, v);
            if (vd < dmin) dmin = vd;
        }
        dc = lk_depth(&cam, c);
        for (y = box[2]; y <= box[3]; y++)
            for (x = box[0]; x <= box[1]; x++) {
                int32_t ri = recidx[(size_t)y * (size_t)view->width + (size_t)x];
                const double *r, *p, *F;
                double o[3], D[3], ti, to, fdepth, dp, dx, dy, dz;
                lk_tri tri;
                uint32_t *dst;
                if (ri < 0) continue;
                r = rec + LK_REC * (size_t)ri;
                p = r;
                F = r + 3;
                dp = r[12];
                for (k = 0; k < 3; k++) {
                    if (cam.ortho) {
                        o[k] = p[k] - cam.fwd[k];
                        D[k] = cam.fwd[k];
                    } else {
                        o[k] = cam.eye[k];
                        D[k] = p[k] - cam.eye[k];
                    }
                }
                /* the fragment: the eye line meets the volume, p not behind its far side */
                if (prism) {
                    if (!lk_prism_clip(&P, o, D, &ti, &to) || to < 1.0) continue;
                    fdepth = cam.ortho ? dp + (to - 1.0) : dp * to;
                } else {
                    fdepth = dc + Rs; /* the billboard sits just behind the sphere */
                    if (dp > fdepth || !lk_ball_clip(c, Rs, o, D, &ti, &to)) continue;
                    if (!two) { /* front half: -nw.(x - v0) <= low */
                        double a0 = -(nw[0] * (o[0] - (double)f0[0]) + nw[1] * (o[1] - (double)f0[1]) +
                                      nw[2] * (o[2] - (double)f0[2])) - low;
                        double b0 = -lk_dot(nw, D);
                        if (b0 == 0.0) {
                            if (a0 > 0.0) continue;
                        } else if (b0 > 0.0) {
                            if (-a0 / b0 < to) to = -a0 / b0;
                        } else if (-a0 / b0 > ti) {
                            ti = -a0 / b0;
                        }
                        if (ti > to) continue;
                    }
                }
                st.fragments++;
                /* culling tests in the order of [LK] §4.2 */
                if ((ctx.cull & HFVIS_LK_CULL_PAPER_FAR_DEPTH) && fdepth > dp + rmax) {
                    st.culled_far_depth++;
                    continue;
                }
                if ((ctx.cull & HFVIS_LK_CULL_FAR_DEPTH) && dmin > dp + rr) {
                    st.culled_far_depth++;
                    continue;
                }
                dx = p[0] - c[0];
                dy = p[1] - c[1];
                dz = p[2] - c[2];
                if ((ctx.cull & HFVIS_LK_CULL_SPHERE) && dx * dx + dy * dy + dz * dz > Rs * Rs) {
                    st.culled_sphere++;
                    continue;
                }
                lk_tri_setup(&tri, F, p, f0, f1, f2, two, rmin, rmax, ctx.o.epsilon);
                if (tri.verdict == HFVIS_LK_TRI_DEGENERATE || tri.verdict == HFVIS_LK_TRI_SELF) {
                    st.skipped++;
                    continue;
                }
                if ((ctx.cull & HFVIS_LK_CULL_FACING) && tri.verdict == HFVIS_LK_TRI_FACING_AWAY) {
                    st.culled_facing++;
                    continue;
                }
                if ((ctx.cull & HFVIS_LK_CULL_PLANE) && tri.verdict == HFVIS_LK_TRI_TOO_FAR) {
                    st.culled_plane++;
                    continue;
                }
                if ((ctx.cull & HFVIS_LK_CULL_HORIZON) && tri.zmax <= 0.0) {
                    st.culled_horizon++;
                    continue;
                }
                dst = acc + (masks ? (size_t)y * (size_t)view->width + (size_t)x : (size_t)ri) * (size_t)words;
                lk_ctx_mask(&ctx, &tri, dst, tmask);
                st.masks++;
                for (k = 0; k < words; k++) dst[k] |= tmask[k];
            }
    }
    /* step 4: W = popcount/N */
    for (i = 0; i < npix; i++) {
        int32_t ri = recidx[i];
        const uint32_t *mk;
        int bits = 0, k;
        if (ri < 0) {
            if (obscurance) obscurance[i] = (float)NAN;
            continue;
        }
        mk = acc + (masks ? i : (size_t)ri) * (size_t)words;
        for (k = 0; k < words; k++) bits += lk_popcount(mk[k]);
        st.rays_blocked += (uint64_t)bits;
        if (obscurance) obscurance[i] = (float)((double)bits / (double)rays->count);
    }
    st.receivers = nrec;
    st.rays = (uint64_t)nrec * (uint64_t)rays->count;
    if (stats) *stats = st;
    lk_free(ctx.o.alloc, block);
    return HFVIS_OK;
}

/* ---- 5.8 Method 2: BVH traversal ([LK] §5, spec A.9) ------------------------------------- */

/* Per-triangle data of Methods 2 and the ray caster: minimal bounding sphere (c, R), R < 0 for
 * a zero-area triangle. 4 doubles per triangle. */
static void lk_tri_table(const hfvis_mesh *m, double *td)
{
    size_t t;
    for (t = 0; t < m->triangle_count; t++) {
        const float *f0 = lk_vertex(m, t, 0), *f1 = lk_vertex(m, t, 1), *f2 = lk_vertex(m, t, 2);
        double *d = td + 4 * t;
        if (lk_world_degenerate(f0, f1, f2)) {
            d[0] = d[1] = d[2] = 0.0;
            d[3] = -1.0;
        } else {
            lk_tri_sphere(f0, f1, f2, d, d + 3);
        }
    }
}

/* The BVH must belong to the mesh and be well formed: children after their parent and inside
 * the node array, leaf ranges inside tri_order, triangle indices in range, finite ordered
 * boxes, depth <= HFVIS_BVH_MAX_DEPTH (so the fixed traversal stacks suffice). depth: scratch
 * of node_count bytes. */
static hfvis_status lk_bvh_check(const hfvis_bvh *b, const hfvis_mesh *m, uint8_t *depth)
{
    size_t i, j;
    if (b->triangle_count != m->triangle_count) return HFVIS_ERR_INVALID_ARGUMENT;
    if (b->node_count == 0) return m->triangle_count == 0 ? HFVIS_OK : HFVIS_ERR_INVALID_ARGUMENT;
    if (!b->nodes || !b->tri_order || b->node_count > SIZE_MAX / 2) return HFVIS_ERR_INVALID_ARGUMENT;
    memset(depth, 0, b->node_count);
    depth[0] = 1;
    for (i = 0; i < b->node_count; i++) {
        const hfvis_bvh_node *nd = b->nodes + i;
        int a;
        if (depth[i] == 0) continue; /* never reached */
        for (a = 0; a < 3; a++)
            if (!isfinite(nd->lo[a]) || !isfinite(nd->hi[a]) || !(nd->lo[a] <= nd->hi[a]))
                return HFVIS_ERR_INVALID_ARGUMENT;
        if (nd->count == 0) {
            size_t l = nd->left_or_first;
            if (l <= i || l + 1 >= b->node_count || depth[i] >= HFVIS_BVH_MAX_DEPTH)
                return HFVIS_ERR_INVALID_ARGUMENT;
            if (depth[l] < depth[i] + 1) depth[l] = (uint8_t)(depth[i] + 1);
            if (depth[l + 1] < depth[i] + 1) depth[l + 1] = (uint8_t)(depth[i] + 1);
        } else {
            size_t f = nd->left_or_first;
            if (nd->count > HFVIS_BVH_MAX_LEAF_SIZE || f > b->triangle_count ||
                nd->count > b->triangle_count - f)
                return HFVIS_ERR_INVALID_ARGUMENT;
            for (j = f; j < f + nd->count; j++)
                if (b->tri_order[j] >= b->triangle_count) return HFVIS_ERR_INVALID_ARGUMENT;
        }
    }
    return HFVIS_OK;
}

/* Shared scratch of Method 2 and the ray caster: triangle table, BVH check, stacks. */
typedef struct lk_trav {
    unsigned char *block;
    double *td;          /* 4 per triangle */
    uint32_t *stack;     /* (HFVIS_BVH_MAX_DEPTH + 2) * (1 + words) */
    uint32_t *C, *tmask; /* words each */
} lk_trav;

#define LK_STACK (HFVIS_BVH_MAX_DEPTH + 2)

static hfvis_status lk_trav_init(lk_trav *tv, const lk_ctx *c, const hfvis_bvh *bvh)
{
    size_t bytes = 0, T = c->mesh->triangle_count;
    unsigned char *cur;
    uint8_t *depth;
    hfvis_status s;
    if (!lk_part(&bytes, T, 4 * sizeof(double)) || !lk_part(&bytes, bvh->node_count, 1) ||
        !lk_part(&bytes, LK_STACK, (1 + (size_t)c->words) * sizeof(uint32_t)) ||
        !lk_part(&bytes, 2 * (size_t)c->words, sizeof(uint32_t)))
        return HFVIS_ERR_LIMIT; /* only on 32-bit size_t */
    tv->block = (unsigned char *)lk_alloc(c->o.alloc, bytes);
    if (!tv->block) return HFVIS_ERR_OUT_OF_MEMORY;
    cur = tv->block;
    tv->td = (double *)lk_take(&cur, T, 4 * sizeof(double));
    depth = (uint8_t *)lk_take(&cur, bvh->node_count, 1);
    tv->stack = (uint32_t *)lk_take(&cur, LK_STACK, (1 + (size_t)c->words) * sizeof(uint32_t));
    tv->C = (uint32_t *)lk_take(&cur, 2 * (size_t)c->words, sizeof(uint32_t));
    tv->tmask = tv->C + c->words;
    s = lk_bvh_check(bvh, c->mesh, depth);
    if (s != HFVIS_OK) {
        lk_free(c->o.alloc, tv->block);
        return s;
    }
    lk_tri_table(c->mesh, tv->td);
    return HFVIS_OK;
}

/* Common argument checks of Method 2 and the ray caster. */
static hfvis_status lk_explicit_init(lk_ctx *c, const hfvis_mesh *mesh, const hfvis_bvh *bvh,
                                     const hfvis_lk_rays *rays, const hfvis_lk_receivers *recv,
                                     const hfvis_lk_options *opts, const uint32_t *masks,
                                     const float *obscurance)
{
    hfvis_status s;
    size_t words;
    if (!mesh || !bvh || !rays || !recv || (!masks && !obscurance)) return HFVIS_ERR_INVALID_ARGUMENT;
    s = lk_ctx_init(c, mesh, rays, opts);
    if (s != HFVIS_OK) return s;
    if (!lk_receivers_valid(recv)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (!lk_mul(recv->count, (size_t)rays->words, &words) || words > SIZE_MAX / sizeof(uint32_t))
        return HFVIS_ERR_LIMIT;
    return HFVIS_OK;
}

/* Squared distance from p to a box. */
static double lk_box_dist2(const hfvis_bvh_node *nd, const double p[3])
{
    double d2 = 0.0;
    int a;
    for (a = 0; a < 3; a++) {
        double lo = (double)nd->lo[a], hi = (double)nd->hi[a], d = 0.0;
        if (p[a] < lo) d = lo - p[a];
        else if (p[a] > hi) d = p[a] - hi;
        d2 += d * d;
    }
    return d2;
}

/* Largest local z (F row 3) over the box corners. */
static double lk_box_zmax(const hfvis_bvh_node *nd, const double F[9], const double p[3])
{
    double z = 0.0;
    int a;
    for (a = 0; a < 3; a++) {
        double zl = F[6 + a] * ((double)nd->lo[a] - p[a]), zh = F[6 + a] * ((double)nd->hi[a] - p[a]);
        z += zl > zh ? zl : zh;
    }
    return z;
}

/* Node occlusion mask (spec A.9.3) of the box's bounding sphere (centre, half-diagonal).
 * EXACT: bit i = the segment [0, s_i] (units of r) meets the sphere of radius R (1 + 1e-9) +
 * 1e-9 r; words are skipped by their cones, and rays already blocked (set in C) are not
 * computed (left 0: only M & ~C is ever used, and C only grows). SPHERE_LUT: [LK] Fig. 4 -
 * equal lengths: the cone P(c, tau/dist) if tau <= r, else the separating plane
 * P(c, (r^2 + dist^2 - R^2)/(2 r dist)); variable lengths: the cone in the direction table.
 * NONE: all ones. */
static void lk_node_mask(const lk_ctx *c, const hfvis_bvh_node *nd, const double F[9],
                         const double p[3], const uint32_t *C, uint32_t *out)
{
    const hfvis_lk_rays *R = c->R;
    double w[3], cl[3], Rn, d2, dist, ch[3], half = 0.0;
    int a, k, i;
    if (c->o.node_mask == HFVIS_LK_NODE_NONE) {
        for (k = 0; k < c->words; k++) out[k] = lk_word_bits(R->count, k);
        return;
    }
    for (a = 0; a < 3; a++) {
        double lo = (double)nd->lo[a], hi = (double)nd->hi[a];
        w[a] = 0.5 * (lo + hi) - p[a];
        half += (hi - lo) * (hi - lo);
    }
    for (a = 0; a < 3; a++) cl[a] = (F[3 * a] * w[0] + F[3 * a + 1] * w[1] + F[3 * a + 2] * w[2]) / c->r;
    Rn = 0.5 * sqrt(half) / c->r;
    Rn = Rn * (1.0 + LK_MARGIN) + LK_MARGIN;
    d2 = lk_dot(cl, cl);
    if (d2 <= Rn * Rn) {
        for (k = 0; k < c->words; k++) out[k] = lk_word_bits(R->count, k);
        return;
    }
    dist = sqrt(d2);
    for (a = 0; a < 3; a++) ch[a] = cl[a] / dist;
    if (c->o.node_mask == HFVIS_LK_NODE_SPHERE_LUT) {
        double tau = sqrt(d2 - Rn * Rn), delta;
        const uint32_t *src;
        if (!R->equal_lengths) src = lk_lut_get(c->o.lut, 1, ch, tau / dist);
        else {
            delta = tau <= 1.0 ? tau / dist : (1.0 + d2 - Rn * Rn) / (2.0 * dist);
            src = lk_lut_get(c->o.lut, 0, ch, delta);
        }
        for (k = 0; k < c->words; k++) out[k] = src[k];
        return;
    }
    {
        double sb = Rn / dist, cb = sqrt(1.0 - sb * sb);
        for (k = 0; k < c->words; k++) {
            const double *cone = R->word_cone + 7 * k;
            int i0 = 32 * k, i1 = i0 + 32 < R->count ? i0 + 32 : R->count;
            double cphi = lk_dot(ch, cone), lim = cone[3] * cb - cone[4] * sb;
            uint32_t bits = 0;
            if ((~C[k] & lk_word_bits(R->count, k)) == 0) { /* every ray already blocked */
                out[k] = 0;
                continue;
            }
            /* zero when the word's cone and the sphere's cone (half-angle beta) do not meet:
             * angle(axis, c) > theta + beta (tested when theta + beta < pi: sin > 0), or
             * the sphere lies beyond the word's longest ray */
            if ((cone[4] * cb + cone[3] * sb > 0.0 && cphi < lim - LK_MARGIN) ||
                dist - Rn > cone[6] + LK_MARGIN) {
                out[k] = 0;
                continue;
            }
            /* all ones when the word's cone lies inside the sphere's (angle(axis, c) + theta <=
             * beta: cos phi >= cos(beta - theta), beta > theta) and its shortest ray reaches
             * dist (every ray inside the cone enters the sphere before distance dist) */
            if (sb * cone[3] - cb * cone[4] > 0.0 && cphi >= cb * cone[3] + sb * cone[4] + LK_MARGIN &&
                cone[5] >= dist + LK_MARGIN) {
                out[k] = lk_word_bits(R->count, k);
                continue;
            }
            for (i = i0; i < i1; i++) {
                /* the segment [0, s] meets the sphere (c, Rn), c outside: with p = c.s, the
                 * closest point is s when p >= s.s, else t s with t = p/s.s (p <= 0: the origin,
                 * outside): |c - s|^2 <= Rn^2, or d2 - p^2/s.s <= Rn^2 (multiplied out) */
                const double *s = R->point + 3 * i;
                double ss = lk_dot(s, s), pp, q[3];
                if ((C[k] >> (i - i0)) & 1u) continue; /* already blocked: bit irrelevant */
                pp = lk_dot(cl, s);
                if (!(pp > 0.0)) continue;
                if (pp >= ss) {
                    for (a = 0; a < 3; a++) q[a] = cl[a] - s[a];
                    if (lk_dot(q, q) <= Rn * Rn) bits |= 1u << (i - i0);
                } else if ((d2 - Rn * Rn) * ss <= pp * pp) {
                    bits |= 1u << (i - i0);
                }
            }
            out[k] = bits;
        }
    }
}

/* Does mask M add a ray to C? (popcount(M & ~C)) */
static int lk_estimate(const uint32_t *M, const uint32_t *C, int words)
{
    int k, e = 0;
    for (k = 0; k < words; k++) e += lk_popcount(M[k] & ~C[k]);
    return e;
}

/* Cull tests of a node; 1 = keep. */
static int lk_node_keep(const lk_ctx *c, const hfvis_bvh_node *nd, const double F[9],
                        const double p[3], hfvis_lk_stats *st)
{
    if (lk_box_dist2(nd, p) > c->r * c->r * (1.0 + 2.0 * LK_MARGIN)) {
        st->nodes_culled_distance++;
        return 0;
    }
    if ((c->cull & HFVIS_LK_CULL_HORIZON) && lk_box_zmax(nd, F, p) <= 0.0) {
        st->nodes_culled_horizon++;
        return 0;
    }
    return 1;
}

/* One receiver of Method 2: C = OR of the masks of the triangles it reaches. */
static void lk_bvh_receiver(const lk_ctx *c, const hfvis_bvh *bvh, const lk_trav *tv,
                            const double p[3], const double F[9], uint32_t *C, hfvis_lk_stats *st)
{
    const int words = c->words;
    const size_t ent = 1 + (size_t)words;
    uint32_t *stk = tv->stack, full_last = lk_word_bits(c->R->count, words - 1);
    int sp = 0, k;
    memset(C, 0, sizeof(uint32_t) * (size_t)words);
    if (bvh->node_count == 0) return;
    if (!lk_node_keep(c, bvh->nodes, F, p, st)) return;
    stk[0] = 0;
    lk_node_mask(c, bvh->nodes, F, p, C, stk + 1);
    sp = 1;
    while (sp > 0) {
        const uint32_t *top = stk + (size_t)(sp - 1) * ent;
        const hfvis_bvh_node *nd = bvh->nodes + top[0];
        sp--;
        if (lk_estimate(top + 1, C, words) == 0) { /* stale estimate re-checked (A.13-14) */
            st->nodes_culled_mask++;
            continue;
        }
        st->nodes_visited++;
        if (nd->count > 0) {
            uint32_t j;
            for (j = nd->left_or_first; j < nd->left_or_first + nd->count; j++) {
                size_t t = bvh->tri_order[j];
                const double *td = tv->td + 4 * t;
                const float *f0, *f1, *f2;
                double rmin, rmax, dx, dy, dz, mabs;
                lk_tri tri;
                int full;
                st->fragments++;
                if (td[3] < 0.0) {
                    st->skipped++;
                    continue;
                }
                f0 = lk_vertex(c->mesh, t, 0);
                f1 = lk_vertex(c->mesh, t, 1);
                f2 = lk_vertex(c->mesh, t, 2);
                lk_window(c, t, &rmin, &rmax);
                lk_tri_setup(&tri, F, p, f0, f1, f2, lk_two_sided(c, t), rmin, rmax, c->o.epsilon);
                if (tri.verdict == HFVIS_LK_TRI_DEGENERATE || tri.verdict == HFVIS_LK_TRI_SELF) {
                    st->skipped++;
                    continue;
                }
                /* culling tests in the BVH order of [LK] §5 */
                if ((c->cull & HFVIS_LK_CULL_HORIZON) && tri.zmax <= 0.0) {
                    st->culled_horizon++;
                    continue;
                }
                if ((c->cull & HFVIS_LK_CULL_FACING) && tri.verdict == HFVIS_LK_TRI_FACING_AWAY) {
                    st->culled_facing++;
                    continue;
                }
                if ((c->cull & HFVIS_LK_CULL_PLANE) && tri.verdict == HFVIS_LK_TRI_TOO_FAR) {
                    st->culled_plane++;
                    continue;
                }
                mabs = lk_margin(rmax, td[3], f0, f1, f2);
                dx = p[0] - td[0];
                dy = p[1] - td[1];
                dz = p[2] - td[2];
                if ((c->cull & HFVIS_LK_CULL_SPHERE) &&
                    dx * dx + dy * dy + dz * dz > (td[3] + rmax + mabs) * (td[3] + rmax + mabs)) {
                    st->culled_sphere++;
                    continue;
                }
                lk_ctx_mask(c, &tri, C, tv->tmask);
                st->masks++;
                full = 1;
                for (k = 0; k < words; k++) {
                    C[k] |= tv->tmask[k];
                    if (C[k] != (k == words - 1 ? full_last : 0xFFFFFFFFu)) full = 0;
                }
                if (full) return; /* every ray blocked */
            }
        } else {
            uint32_t ch[2], *mk[2];
            int e[2], keep[2], q;
            ch[0] = nd->left_or_first;
            ch[1] = nd->left_or_first + 1;
            for (q = 0; q < 2; q++) {
                const hfvis_bvh_node *cn = bvh->nodes + ch[q];
                mk[q] = stk + (size_t)(sp + q) * ent + 1;
                keep[q] = lk_node_keep(c, cn, F, p, st);
                e[q] = 0;
                if (!keep[q]) continue;
                lk_node_mask(c, cn, F, p, C, mk[q]);
                e[q] = lk_estimate(mk[q], C, words);
                if (e[q] == 0) {
                    st->nodes_culled_mask++;
                    keep[q] = 0;
                }
            }
            /* push the smaller estimate first: the larger is visited next (ties: left first) */
            if (keep[0] && keep[1]) {
                int first = e[1] <= e[0] ? 1 : 0; /* pushed first (popped last) */
                uint32_t *a0 = stk + (size_t)sp * ent, *a1 = a0 + ent;
                if (first == 0) { /* order in place: [left, right] -> right on top */
                    a0[0] = ch[0];
                    a1[0] = ch[1];
                } else { /* swap the two entries: [right, left] */
                    for (k = 0; k < words; k++) {
                        uint32_t tmp = a0[1 + k];
                        a0[1 + k] = a1[1 + k];
                        a1[1 + k] = tmp;
                    }
                    a0[0] = ch[1];
                    a1[0] = ch[0];
                }
                sp += 2;
            } else if (keep[0] || keep[1]) {
                uint32_t *a0 = stk + (size_t)sp * ent;
                if (keep[1]) memcpy(a0 + 1, mk[1], sizeof(uint32_t) * (size_t)words);
                a0[0] = keep[0] ? ch[0] : ch[1];
                sp += 1;
            }
        }
    }
}

static void lk_write_result(const lk_ctx *c, const uint32_t *C, size_t k, uint32_t *masks,
                            float *obscurance, hfvis_lk_stats *st)
{
    int bits = 0, w;
    for (w = 0; w < c->words; w++) bits += lk_popcount(C[w]);
    if (masks) memcpy(masks + k * (size_t)c->words, C, sizeof(uint32_t) * (size_t)c->words);
    if (obscurance) obscurance[k] = (float)((double)bits / (double)c->R->count);
    st->rays_blocked += (uint64_t)bits;
}

static void lk_receiver_frame(const lk_ctx *c, const hfvis_lk_receivers *recv, size_t k,
                              double F[9])
{
    lk_frame_make(&c->jit, recv->normal + 3 * k, recv->key ? recv->key[k] : (uint64_t)k, F);
}

HFVIS_API hfvis_status hfvis_lk_bvh(const hfvis_mesh *mesh, const hfvis_bvh *bvh,
                                    const hfvis_lk_rays *rays, const hfvis_lk_receivers *recv,
                                    const hfvis_lk_options *opts, uint32_t *masks,
                                    float *obscurance, hfvis_lk_stats *stats)
{
    lk_ctx c;
    lk_trav tv;
    hfvis_lk_stats st;
    hfvis_status s;
    size_t k;
    s = lk_explicit_init(&c, mesh, bvh, rays, recv, opts, masks, obscurance);
    if (s != HFVIS_OK) return s;
    s = lk_trav_init(&tv, &c, bvh);
    if (s != HFVIS_OK) return s;
    memset(&st, 0, sizeof st);
    for (k = 0; k < recv->count; k++) {
        double F[9];
        lk_receiver_frame(&c, recv, k, F);
        lk_bvh_receiver(&c, bvh, &tv, recv->position + 3 * k, F, tv.C, &st);
        lk_write_result(&c, tv.C, k, masks, obscurance, &st);
    }
    st.receivers = recv->count;
    st.rays = (uint64_t)recv->count * (uint64_t)rays->count;
    if (stats) *stats = st;
    lk_free(c.o.alloc, tv.block);
    return HFVIS_OK;
}

/* ---- 5.9 the reference ray caster (spec A.10) ------------------------------------------- */

/* Slab test of the segment p + tD, t in [0, 1], against a padded node box, in double, widened
 * by LK_SLAB_PAD (relative) so it never rejects a box that the predicate's hit point lies in. */
static int lk_slab(const hfvis_bvh_node *nd, const double p[3], const double D[3],
                   const double inv[3])
{
    double tn = -LK_INF, tf = LK_INF;
    int a;
    for (a = 0; a < 3; a++) {
        double lo = (double)nd->lo[a], hi = (double)nd->hi[a], t0, t1;
        if (D[a] == 0.0) {
            if (p[a] < lo || p[a] > hi) return 0;
            continue;
        }
        t0 = (lo - p[a]) * inv[a];
        t1 = (hi - p[a]) * inv[a];
        if (t0 > t1) {
            double t = t0;
            t0 = t1;
            t1 = t;
        }
        if (t0 > tn) tn = t0;
        if (t1 < tf) tf = t1;
    }
    tn -= LK_SLAB_PAD * (1.0 + fabs(tn));
    tf += LK_SLAB_PAD * (1.0 + fabs(tf));
    return tn <= tf && tf >= 0.0 && tn <= 1.0;
}

/* Any-hit of ray i of one receiver with the predicate (EXACT). */
static int lk_cast_exact(const lk_ctx *c, const hfvis_bvh *bvh, const lk_trav *tv,
                         const double p[3], const double F[9], int i, hfvis_lk_stats *st)
{
    const double *s = c->R->point + 3 * i;
    double D[3], inv[3];
    uint32_t *stk = tv->stack;
    int sp = 0, a;
    if (c->R->length[i] == 0.0 || bvh->node_count == 0) return 0;
    for (a = 0; a < 3; a++) {
        D[a] = c->r * (F[a] * s[0] + F[3 + a] * s[1] + F[6 + a] * s[2]);
        inv[a] = D[a] != 0.0 ? 1.0 / D[a] : 0.0;
    }
    stk[sp++] = 0;
    while (sp > 0) {
        const hfvis_bvh_node *nd = bvh->nodes + stk[--sp];
        if (!lk_slab(nd, p, D, inv)) continue;
        st->nodes_visited++;
        if (nd->count > 0) {
            uint32_t j;
            for (j = nd->left_or_first; j < nd->left_or_first + nd->count; j++) {
                size_t t = bvh->tri_order[j];
                double rmin, rmax;
                lk_tri tri;
                if (tv->td[4 * t + 3] < 0.0) continue;
                lk_window(c, t, &rmin, &rmax);
                lk_tri_setup(&tri, F, p, lk_vertex(c->mesh, t, 0), lk_vertex(c->mesh, t, 1),
                             lk_vertex(c->mesh, t, 2), lk_two_sided(c, t), rmin, rmax, c->o.epsilon);
                st->fragments++;
                if (lk_blocks(&tri, s)) return 1;
            }
        } else {
            stk[sp++] = nd->left_or_first + 1;
            stk[sp++] = nd->left_or_first;
        }
    }
    return 0;
}

/* The WATERTIGHT test's candidate filter: the epsilon rule, one-sidedness for per-triangle
 * sides, the distance window. */
typedef struct lk_wt {
    const lk_ctx *c;
    const double *p;
    double lambda;   /* l_i / r */
} lk_wt;

static int lk_wt_filter(void *user, const hfvis_ray *ray, const hfvis_hit *cand)
{
    const lk_wt *w = (const lk_wt *)user;
    const lk_ctx *c = w->c;
    size_t t = cand->triangle;
    const float *f0 = lk_vertex(c->mesh, t, 0), *f1 = lk_vertex(c->mesh, t, 1), *f2 = lk_vertex(c->mesh, t, 2);
    double u[3], v[3], n[3], len, h, rmin, rmax, dist;
    int a;
    (void)ray;
    for (a = 0; a < 3; a++) {
        u[a] = (double)f1[a] - (double)f0[a];
        v[a] = (double)f2[a] - (double)f0[a];
    }
    lk_cross(u, v, n);
    len = sqrt(lk_dot(n, n));
    if (!(len > 0.0)) return 0;
    h = (n[0] * (w->p[0] - (double)f0[0]) + n[1] * (w->p[1] - (double)f0[1]) +
         n[2] * (w->p[2] - (double)f0[2])) / len;
    if (!(fabs(h) >= c->o.epsilon)) return 0;
    if (c->o.sides == HFVIS_LK_SIDES_PER_TRIANGLE && !c->o.two_sided[t] && !cand->front) return 0;
    lk_window(c, t, &rmin, &rmax);
    dist = (double)cand->t;
    return dist >= rmin * w->lambda && dist <= rmax * w->lambda;
}

static hfvis_status lk_cast_watertight(const lk_ctx *c, const hfvis_bvh *bvh, const double p[3],
                                       const double F[9], int i, int *blocked)
{
    const double *u = c->R->direction + 3 * i;
    hfvis_ray ray;
    hfvis_hit hit;
    lk_wt w;
    int a;
    *blocked = 0;
    if (c->R->length[i] == 0.0) return HFVIS_OK;
    memset(&ray, 0, sizeof ray);
    for (a = 0; a < 3; a++) {
        ray.origin[a] = (float)p[a];
        ray.direction[a] = (float)(F[a] * u[0] + F[3 + a] * u[1] + F[6 + a] * u[2]);
    }
    ray.t_min = FLT_MIN;
    ray.t_max = (float)(c->R->length[i] * c->r);
    ray.cull = c->o.sides == HFVIS_LK_SIDES_ONE ? HFVIS_CULL_BACK : HFVIS_CULL_NONE;
    w.c = c;
    w.p = p;
    w.lambda = c->R->length[i];
    {
        hfvis_status s = hfvis_bvh_intersect(bvh, c->mesh, &ray, HFVIS_RAY_ANY, lk_wt_filter, &w, &hit);
        if (s != HFVIS_OK) return s;
    }
    *blocked = hit.triangle != HFVIS_NO_TRIANGLE;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_lk_raycast(const hfvis_mesh *mesh, const hfvis_bvh *bvh,
                                        const hfvis_lk_rays *rays,
                                        const hfvis_lk_receivers *recv,
                                        const hfvis_lk_options *opts, uint32_t *masks,
                                        float *obscurance, hfvis_lk_stats *stats)
{
    lk_ctx c;
    lk_trav tv;
    hfvis_lk_stats st;
    hfvis_status s = HFVIS_OK;
    size_t k;
    s = lk_explicit_init(&c, mesh, bvh, rays, recv, opts, masks, obscurance);
    if (s != HFVIS_OK) return s;
    s = lk_trav_init(&tv, &c, bvh);
    if (s != HFVIS_OK) return s;
    memset(&st, 0, sizeof st);
    for (k = 0; k < recv->count && s == HFVIS_OK; k++) {
        double F[9];
        const double *p = recv->position + 3 * k;
        int i;
        lk_receiver_frame(&c, recv, k, F);
        memset(tv.C, 0, sizeof(uint32_t) * (size_t)c.words);
        for (i = 0; i < rays->count; i++) {
            int blocked;
            if (c.o.raycast_test == HFVIS_LK_RAYCAST_WATERTIGHT) {
                s = lk_cast_watertight(&c, bvh, p, F, i, &blocked);
                if (s != HFVIS_OK) break;
            } else {
                blocked = lk_cast_exact(&c, bvh, &tv, p, F, i, &st);
            }
            if (blocked) tv.C[i >> 5] |= 1u << (i & 31);
        }
        if (s == HFVIS_OK) lk_write_result(&c, tv.C, k, masks, obscurance, &st);
    }
    st.receivers = recv->count;
    st.rays = (uint64_t)recv->count * (uint64_t)rays->count;
    if (s == HFVIS_OK && stats) *stats = st;
    lk_free(c.o.alloc, tv.block);
    return s;
}

/* ---- 5.10 the image driver ------------------------------------------------------------------ */

HFVIS_API hfvis_status hfvis_lk_image(hfvis_lk_method method, const hfvis_mesh *mesh,
                                      const hfvis_bvh *bvh, const hfvis_view *view,
                                      const hfvis_lk_rays *rays, const hfvis_lk_options *opts,
                                      uint32_t *masks, float *obscurance, hfvis_lk_stats *stats)
{
    hfvis_lk_options o;
    hfvis_lk_receivers rc;
    hfvis_bvh own;
    lk_cam cam;
    hfvis_status s;
    unsigned char *block, *cur;
    double *pos, *nrm;
    uint64_t *key;
    uint32_t *rm = NULL;
    float *ro = NULL;
    size_t npix, bytes = 0, count = 0, i, words;
    if (method == HFVIS_LK_METHOD_RASTER)
        return hfvis_lk_raster(mesh, view, rays, opts, masks, obscurance, stats);
    if ((method != HFVIS_LK_METHOD_BVH && method != HFVIS_LK_METHOD_RAYCAST) || !mesh || !view ||
        !lk_rays_valid(rays) || (!masks && !obscurance))
        return HFVIS_ERR_INVALID_ARGUMENT;
    s = hfvis_lk_options_resolve(opts, rays->radius, &o);
    if (s != HFVIS_OK) return s;
    s = lk_mesh_check(mesh);
    if (s != HFVIS_OK) return s;
    s = lk_cam_init(&cam, view);
    if (s != HFVIS_OK) return s;
    if (view->width > HFVIS_RASTER_MAX_SIZE || view->height > HFVIS_RASTER_MAX_SIZE)
        return HFVIS_ERR_LIMIT;
    npix = (size_t)view->width * (size_t)view->height;
    words = (size_t)rays->words;
    if (!lk_part(&bytes, npix, 6 * sizeof(double)) || !lk_part(&bytes, npix, sizeof(uint64_t)) ||
        (masks && !lk_part(&bytes, npix, words * sizeof(uint32_t))) ||
        (obscurance && !lk_part(&bytes, npix, sizeof(float))))
        return HFVIS_ERR_LIMIT;
    block = (unsigned char *)lk_alloc(o.alloc, bytes);
    if (!block) return HFVIS_ERR_OUT_OF_MEMORY;
    cur = block;
    pos = (double *)lk_take(&cur, npix, 3 * sizeof(double));
    nrm = (double *)lk_take(&cur, npix, 3 * sizeof(double));
    key = (uint64_t *)lk_take(&cur, npix, sizeof(uint64_t));
    if (masks) rm = (uint32_t *)lk_take(&cur, npix, words * sizeof(uint32_t));
    if (obscurance) ro = (float *)lk_take(&cur, npix, sizeof(float));
    s = hfvis_lk_gbuffer_receivers(mesh, view, &o, pos, nrm, key, &count);
    if (s != HFVIS_OK) {
        lk_free(o.alloc, block);
        return s;
    }
    if (!bvh) {
        hfvis_bvh_options bo = hfvis_bvh_options_default();
        bo.alloc = o.alloc;
        s = hfvis_bvh_build(mesh, &bo, &own);
        if (s != HFVIS_OK) {
            lk_free(o.alloc, block);
            return s;
        }
    }
    rc.count = count;
    rc.position = pos;
    rc.normal = nrm;
    rc.key = key;
    if (method == HFVIS_LK_METHOD_BVH) s = hfvis_lk_bvh(mesh, bvh ? bvh : &own, rays, &rc, &o, rm, ro, stats);
    else s = hfvis_lk_raycast(mesh, bvh ? bvh : &own, rays, &rc, &o, rm, ro, stats);
    if (!bvh) hfvis_bvh_free(o.alloc, &own);
    if (s == HFVIS_OK) {
        if (masks) memset(masks, 0, sizeof(uint32_t) * npix * words);
        if (obscurance)
            for (i = 0; i < npix; i++) obscurance[i] = (float)NAN;
        for (i = 0; i < count; i++) {
            if (masks) memcpy(masks + key[i] * words, rm + i * words, sizeof(uint32_t) * words);
            if (obscurance) obscurance[key[i]] = ro[i];
        }
    }
    lk_free(o.alloc, block);
    return s;
}
