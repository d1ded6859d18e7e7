
/* ========================================================================================== */
/* ssao.c - Laine-Karras bitmask ray-cast ambient occlusion                                    */
/* ========================================================================================== */

/* S. Laine, T. Karras, "Two Methods for Fast Ray-Cast Ambient Occlusion", EGSR 2010 ([LK]);
 * spec raycast-ao-and-hf-gi.md part A. All N shadow rays of one receiver are resolved together as
 * an N-bit occlusion mask: ray i -> word i/32, bit i%32 (mask words = ceil(N/32), unused bits 0).
 * Three ways of filling the masks, which give IDENTICAL masks for identical ray sets (exact
 * mode, below):
 *   Method 1, hfvis_lk_raster   - per triangle, the receivers of a camera's G-buffer that its
 *                                 region of influence covers ([LK] §4, spec A.6-A.8);
 *   Method 2, hfvis_lk_bvh      - per receiver (any points), a BVH traversal with conservative
 *                                 node masks ([LK] §5, spec A.9);
 *   reference, hfvis_lk_raycast - every ray of every receiver cast through the same BVH with an
 *                                 any-hit query (spec A.10).
 *
 * Obscurance (DESIGN §2): W = popcount(mask)/N in [0, 1], 0 = nothing blocks ([LK] Eq. 3). The
 * directions are cosine-distributed (Malley's lifting of disc points), so W estimates
 * (1/pi) Int rho(D(p, w)) (n.w) dw ([LK] Eq. 1) with the falloff rho folded into the ray
 * lengths (l_i = r rho^-1(xi_i), spec A.2): a ray is "blocked" when a triangle crosses the
 * segment p -> p + l_i w_i. With the default constant falloff every ray has length r.
 *
 * The blocking predicate (spec A.4.1), evaluated in double and IDENTICALLY by all three methods
 * (they share one routine; this is what makes the masks equal bit for bit). For a receiver at p
 * with the orthonormal frame F (rows x', y', z'; z' = the jittered normal) and a triangle
 * v0, v1, v2 (floats): a = F (v0 - p), b = F (v1 - p), c = F (v2 - p) (each row dotted with the
 * double difference, x + y + z in that order); n = (b - a) x (c - a), nh = n/|n|; h = nh.a.
 *   - the triangle is skipped (never blocks) when its WORLD cross product (v1 - v0) x (v2 - v0),
 *     evaluated in double, is exactly 0 (zero area), when n is 0, or when |h| < epsilon (the
 *     receiver lies in the triangle's plane: its own triangle and coplanar neighbours, spec
 *     A.13-7);
 *   - one-sided triangles block only receivers on their front side: h < 0, i.e.
 *     nh.(p - v0) > 0 (the side the normal (v1 - v0) x (v2 - v0) points to);
 *   - d = |h|; with the triangle's distance window [r_min, r_max] (LOD, default [0, r]) the
 *     triangle never blocks when d > r_max;
 *   - m = sign(h) nh (so m.a = d > 0); edge planes e1 = a x b, e2 = b x c, e3 = c x a, negated
 *     when h < 0; ray i with the normalised sample point s_i = (l_i/r) u_i is blocked iff
 *       e1.s_i >= 0 and e2.s_i >= 0 and e3.s_i >= 0 and m.s_i >= d/r_max
 *       and not (r_min > 0 and d < r_min and m.s_i > d/r_min),
 *     i.e. the segment of length l_i r_max/r reaches the plane inside the triangle (edges and
 *     the far end included: the hit distance t = l_i d/(r m.s_i) satisfies
 *     r_min l_i/r <= t <= r_max l_i/r, spec A.4.3).
 * Every culling test (spec A.5) only skips work: it is applied only where it implies that the
 * predicate is false for every ray, with margins far above the rounding of the predicate, so
 * switching tests on or off never changes a mask (tested exactly). The paper's literal "far
 * depth" test is the one exception (HFVIS_LK_CULL_PAPER_FAR_DEPTH, off by default; spec A.13-1).
 *
 * LUT mode (spec A.4.2) replaces the per-ray dot products by 4 (5 with a window) look-ups in a
 * T^3 table of plane masks: faster for large N, but quantised - masks then differ from the
 * exact ones for rays within about one table node of a plane (the paper's faint systematic
 * errors), and the three-way identity holds only in exact mode.
 *
 * What is and is not guaranteed
 *   - Exact mode (the defaults: MASK_EXACT, NODE_EXACT, RAYCAST_EXACT): Methods 1 and 2 and the
 *     ray caster return the same masks for the same receivers, frames and rays, by construction:
 *     all three OR values of the one predicate routine, and every shortcut (word cones, culling
 *     tests, node masks, influence volumes, slab tests, rays already blocked) skips only work
 *     whose predicate value is 0 (or already set) with a margin of at least 1e-9 relative, far
 *     above its rounding (about 1e-15). Tested bit for bit on seeded random soups (one-, two-
 *     and per-triangle sides, LOD windows, three falloffs) and on the test meshes, and with every
 *     culling test switched off.
 *   - The predicate is the geometric answer up to double rounding: 0 disagreements with an
 *     independent Moller-Trumbore test in double on 384,000 random ray-triangle pairs, and 0 with
 *     the library's float watertight any-hit test on 292,864 AO rays (the room scene one- and
 *     two-sided, a random soup with per-triangle sides); expect
 *     differences only for rays within about 1e-15 (double) or 1e-7 (float) relative of an edge,
 *     a vertex or the segment's end.
 *   - Not guaranteed: the margins assume coordinates within about 1e6 r of the origin and
 *     triangles not thinner than about 1e-9 r; beyond that a shortcut could in principle skip a
 *     ray the predicate would set (never observed). LUT mode and the paper's far-depth test give
 *     approximations (see there).
 * Determinism: same inputs, same binary, same bits. Rays, frames and jitter come from explicit
 * seeds and the library's own PCG32 / SplitMix64; receiver k's jitter key is k (or the pixel
 * index y*width + x for G-buffer receivers). */

#define HFVIS_LK_MAX_RAYS 4096                  /* N = 1..4096 rays per receiver */
#define HFVIS_LK_LUT_MAX_BYTES ((size_t)1 << 28) /* 256 MiB: the paper's 128^3 table at N = 1024;
                                                   larger tables return HFVIS_ERR_LIMIT */
#define HFVIS_LK_LUT_MIN_RESOLUTION 2
#define HFVIS_LK_LUT_MAX_RESOLUTION 1024
#define HFVIS_LK_DEFAULT_LUT_RESOLUTION 128     /* the paper's T */
#define HFVIS_LK_DEFAULT_EPSILON 1e-5           /* plane epsilon, as a fraction of the radius r */
#define HFVIS_LK_DEFAULT_ALPHA 0.2              /* prism if R_T/r_max > alpha ([LK] §4.1) */
#define HFVIS_LK_DEFAULT_TILT 0.05              /* default normal-tilt jitter bound, radians */

/* ---- ray sets (spec A.2) ------------------------------------------------------------------ */

/* How the N disc points are placed before they are lifted to the hemisphere. */
typedef enum hfvis_lk_pattern {
    HFVIS_LK_PATTERN_DEFAULT = 0, /* = LLOYD */
    HFVIS_LK_PATTERN_LLOYD = 1,   /* [LK] §6: random points, lloyd_iterations Lloyd steps, each
                                     point replaced by a uniform random point of its Voronoi
                                     cell (rejection sampling, 64 attempts, else it stays),
                                     final_iterations more steps (cells estimated from the
                                     centres of a density_resolution^2 grid, spec A.2) */
    HFVIS_LK_PATTERN_RANDOM = 2,  /* independent uniform points of the disc (for tests) */
    HFVIS_LK_PATTERN_LLOYD_TORUS = 3 /* the same relaxation and jitter on the periodic square,
                                        mapped onto the disc by the area-preserving concentric
                                        map of Shirley & Chiu 1997. On the disc the Lloyd
                                        centroids of the rim cells lie inward, so LLOYD leaves
                                        the outermost ring of points about half a cell inside
                                        the rim and under-samples grazing directions (N = 1024:
                                        no point beyond rho = 0.995, and the AO of a plane at
                                        h = 0.3 r comes out about 0.01 low); the torus has no
                                        rim (moments within about 0.005 at N = 1024) */
} hfvis_lk_pattern;

/* The falloff rho(x) of the normalised occluder distance x = D/r, non-increasing, rho = 0 from
 * x = 1 on. The ray lengths realise it: l_i/r = sup{x in [0, 1] : rho(x) >= xi_i} with the
 * stratified xi_i = (pi(i) + 1/2)/N, pi a seeded random permutation (uncorrelated with the
 * directions), so P(l >= D) = rho(D) ([LK] Eq. 3, spec A.1). */
typedef enum hfvis_lk_falloff {
    HFVIS_LK_FALLOFF_DEFAULT = 0,   /* = CONSTANT */
    HFVIS_LK_FALLOFF_CONSTANT = 1,  /* rho = 1 on [0, 1): every l_i = r (the paper's tests) */
    HFVIS_LK_FALLOFF_LINEAR = 2,    /* rho = 1 - x: l_i/r = 1 - xi_i, uniform lengths */
    HFVIS_LK_FALLOFF_QUADRATIC = 3, /* rho = (1 - x)^2: l_i/r = 1 - sqrt(xi_i) */
    HFVIS_LK_FALLOFF_CUSTOM = 4     /* rho = falloff_fn(user, x), inverted by bisection */
} hfvis_lk_falloff;

/* A custom falloff: rho(x) for x = D/r in [0, 1], in [0, 1] and non-increasing. */
typedef double (*hfvis_lk_falloff_fn)(void *user, double x);

/* Options of hfvis_lk_rays_build. NULL or a zero struct = defaults. */
typedef struct hfvis_lk_ray_options {
    const hfvis_allocator *alloc;   /* the ray set's block and the scratch; NULL = malloc */
    hfvis_lk_pattern pattern;       /* default LLOYD */
    uint64_t seed;                  /* 0 is a valid seed and the default */
    int lloyd_iterations;           /* LLOYD*: steps before the Voronoi jitter, 1..10000;
                                       0 = 64 */
    int final_iterations;           /* LLOYD*: steps after it, 1..10000; 0 = 4 */
    int density_resolution;         /* LLOYD*: the density grid's side, 16..2048; 0 = adaptive,
                                       about 48 grid points per site and at least 64:
                                       ceil(sqrt(48 N 4/pi)) (disc), ceil(sqrt(48 N)) (torus) */
    hfvis_lk_falloff falloff;       /* default CONSTANT */
    hfvis_lk_falloff_fn falloff_fn; /* CUSTOM only */
    void *falloff_user;             /* CUSTOM only */
} hfvis_lk_ray_options;

/* The defaults: alloc NULL, LLOYD, seed 0, 64 + 4 Lloyd steps, adaptive grid, CONSTANT. */
HFVIS_API hfvis_lk_ray_options hfvis_lk_ray_options_default(void);

/* A ray set in the canonical receiver frame (z = normal), shared by every receiver ([LK] §3).
 * One block (direction is its start): free with hfvis_lk_rays_free. The rays are ordered so that
 * each 32-ray word covers a compact patch of the hemisphere (Morton order of the disc points);
 * word_cone holds, per word, the unit axis (3), cos and sin of the half-angle of the cone of its
 * directions (inflated by 1e-9 rad), the least and largest length: 7 doubles per word, used to
 * skip whole words with margins (the results are those of the plain per-ray loop). */
typedef struct hfvis_lk_rays {
    int count;             /* N, 1..HFVIS_LK_MAX_RAYS */
    int words;             /* ceil(N/32) */
    double radius;         /* r, world units: the longest possible ray */
    double *direction;     /* 3N: unit directions u_i, u_z > 0 (cosine-distributed) */
    double *length;        /* N: l_i/r in [0, 1] */
    double *point;         /* 3N: normalised sample points s_i = (l_i/r) u_i, |s_i| <= 1 */
    double *word_cone;     /* 7 per word (see above) */
    double min_elevation;  /* min_i asin(u_i,z) > 0, radians (bounds the tilt jitter) */
    int equal_lengths;     /* 1 when every l_i = r */
} hfvis_lk_rays;

/* Build a ray set of `count` rays of radius `radius` (> 0, finite): disc points (pattern), lifted
 * to the hemisphere u = (x, y, sqrt(1 - x^2 - y^2)), every point strictly inside the disc of
 * radius sqrt(1 - 2^-20) (so u_z >= 2^-10), ordered by the Morton code of the disc point, and
 * the lengths of the falloff. Deterministic (seed). Cost: LLOYD O((iterations + jitter) *
 * density_resolution^2), at the defaults 0.03 s for N = 128 and 0.22 s for N = 1024 (torus:
 * 0.05 s, 0.34 s); RANDOM O(N log N).
 * Allocations: the set's one block (8*(7N + 7 words) bytes) and, LLOYD, one scratch block.
 * Returns HFVIS_OK; HFVIS_ERR_INVALID_ARGUMENT for a NULL out, count outside
 * 1..HFVIS_LK_MAX_RAYS, a non-positive or non-finite radius, an unknown pattern or falloff, an
 * iteration count or resolution out of range, a CUSTOM falloff without fn or whose values at
 * x = j/1024 (j = 0..1024) are not finite, outside [0, 1] or increasing;
 * HFVIS_ERR_OUT_OF_MEMORY. On error *out is untouched and nothing is leaked. */
HFVIS_API hfvis_status hfvis_lk_rays_build(int count, double radius,
                                           const hfvis_lk_ray_options *opts, hfvis_lk_rays *out);

/* A ray set from given directions (3N, finite, each normalised here; u_z must stay > 0 after
 * normalisation) and normalised lengths l_i/r (N values in [0, 1]; NULL = all 1), kept in the
 * given order. One allocation. Errors as hfvis_lk_rays_build (INVALID_ARGUMENT for NULL
 * directions, a zero or non-finite direction, u_z <= 0, a length outside [0, 1]). */
HFVIS_API hfvis_status hfvis_lk_rays_custom(int count, double radius, const double *directions,
                                            const double *lengths, const hfvis_allocator *alloc,
                                            hfvis_lk_rays *out);

/* Release a ray set (the allocator it was built with; NULL = free) and zero it. NULL allowed. */
HFVIS_API void hfvis_lk_rays_free(const hfvis_allocator *alloc, hfvis_lk_rays *rays);

/* Words of one mask: (count + 31)/32; 0 for a count outside 1..HFVIS_LK_MAX_RAYS. */
HFVIS_API int hfvis_lk_mask_words(int count);

/* Obscurance of one mask: popcount(mask)/count in [0, 1] (NaN for NULL or a bad count). */
HFVIS_API double hfvis_lk_obscurance(const uint32_t *mask, int count);

/* ---- receiver frame and jitter (spec A.3) ------------------------------------------------- */

/* Jitter of the receiver frame ([LK] §3: against banding on flat areas). */
typedef enum hfvis_lk_jitter {
    HFVIS_LK_JITTER_DEFAULT = 0, /* = rotation uniform in [-pi, pi], tilt bound
                                    HFVIS_LK_DEFAULT_TILT */
    HFVIS_LK_JITTER_NONE = 1,    /* the plain frame of the normal (identity for n = +z) */
    HFVIS_LK_JITTER_CUSTOM = 2   /* rotation_max_rad in [0, pi], tilt_max_rad in [0, pi/2] */
} hfvis_lk_jitter;

/* The receiver frame F (rows x', y', z', row-major double[9], orthonormal up to rounding) of a
 * normal n (need not be unit) and a jitter key, spec A.3: (xi1, xi2, xi3) = SplitMix64 of
 * seed and key; t1, t2 = the branchless orthonormal basis of T. Duff et al. 2017 ("Building an
 * Orthonormal Basis, Revisited"); delta = min(tilt_max, 0.9 min_elevation);
 * n' = cos(delta xi1) n + sin(delta xi1)(cos(2 pi xi2) t1 + sin(2 pi xi2) t2), normalised;
 * (x0, y0) = the basis of n'; psi = rotation_max (2 xi3 - 1); x' = cos psi x0 + sin psi y0,
 * y' = -sin psi x0 + cos psi y0, z' = n'. No sample ray goes below the receiver's true tangent
 * plane (each keeps an elevation >= 0.1 min_elevation). World direction of ray i: F^T u_i.
 * JITTER_NONE: (t1, t2, n). Returns HFVIS_ERR_INVALID_ARGUMENT for NULL, an invalid ray set, a
 * zero or non-finite normal, an unknown jitter or custom bounds out of range. */
HFVIS_API hfvis_status hfvis_lk_frame(const hfvis_lk_rays *rays, const double normal[3],
                                      uint64_t seed, uint64_t key, hfvis_lk_jitter jitter,
                                      double rotation_max_rad, double tilt_max_rad,
                                      double frame[9]);

/* ---- occlusion masks and the plane look-up table (spec A.4) ------------------------------- */

/* The 3-D plane look-up table ([LK] §3.1) with the node convention of spec A.4.2: node
 * k = (kx, ky, kz) in 0..T-1 stands for q = -1 + 2k/(T - 1); s = max|q_j|; nodes with s < 1/8
 * are 0 (unused core); otherwise the plane m = q/|q|, delta = (1 - s) 8/7 (= d/r) and bit i is
 * (m.s_i > delta). Masks at masks[((kz*T + ky)*T + kx)*words]. `directions` is the same table
 * built from the unit directions u_i (the projection case of node masks for variable-length
 * rays, [LK] §5); NULL when every length is 1 (it would be identical). */
typedef struct hfvis_lk_lut {
    int resolution;        /* T */
    int count;             /* N of the ray set it was built for */
    int words;
    uint32_t *masks;       /* T^3 * words */
    uint32_t *directions;  /* T^3 * words, or NULL */
    size_t bytes;          /* total bytes of the tables */
} hfvis_lk_lut;

/* Bytes of the tables for T = resolution and `count` rays: T^3 ceil(count/32) 4 bytes per table
 * (two_tables: 2 tables). 0 for invalid arguments or on size_t overflow. */
HFVIS_API size_t hfvis_lk_lut_bytes(int resolution, int count, int two_tables);

/* Build the table(s) for a ray set (two when the lengths differ). Cost T^3 N dot products
 * (whole words decided by the word cones with margins give the same bits); about 0.3 s for the
 * paper's T = 128, N = 128. Returns HFVIS_OK; HFVIS_ERR_INVALID_ARGUMENT for NULL, an invalid
 * ray set, resolution outside HFVIS_LK_LUT_MIN..MAX_RESOLUTION; HFVIS_ERR_LIMIT when the tables
 * need more than HFVIS_LK_LUT_MAX_BYTES (e.g. N = 1024 with T > 128: use a smaller T or exact
 * mode); HFVIS_ERR_OUT_OF_MEMORY. One or two allocations; *out untouched on error. */
HFVIS_API hfvis_status hfvis_lk_lut_build(const hfvis_lk_rays *rays, int resolution,
                                          const hfvis_allocator *alloc, hfvis_lk_lut *out);

/* Release the tables (allocator they were built with) and zero *lut. NULL allowed. */
HFVIS_API void hfvis_lk_lut_free(const hfvis_allocator *alloc, hfvis_lk_lut *lut);

/* Node of a plane (m, d/r) (spec A.4.2 LUT_FETCH): delta = d_over_r clamped to [0, 1];
 * q = m (1 - 7 delta/8)/max_j |m_j|; k_j = clamp(floor((q_j + 1)(T - 1)/2 + 1/2), 0, T - 1).
 * Returns HFVIS_ERR_INVALID_ARGUMENT for NULL, a resolution out of range, m zero or not finite,
 * a non-finite d_over_r. */
HFVIS_API hfvis_status hfvis_lk_lut_index(int resolution, const double m[3], double d_over_r,
                                          int ijk[3]);

/* The mask of plane (m, d/r) in the table (directions != 0: the direction table, which is the
 * main table when all lengths are 1); NULL for the invalid arguments of hfvis_lk_lut_index. */
HFVIS_API const uint32_t *hfvis_lk_lut_fetch(const hfvis_lk_lut *lut, int directions,
                                             const double m[3], double d_over_r);

/* Exact plane mask: bit i = (m.s_i >= d_over_r), for every ray (mask holds words words).
 * Returns HFVIS_ERR_INVALID_ARGUMENT for NULL, an invalid ray set or non-finite m / d_over_r. */
HFVIS_API hfvis_status hfvis_lk_plane_mask(const hfvis_lk_rays *rays, const double m[3],
                                           double d_over_r, uint32_t *mask);

/* What the blocking predicate made of one triangle for one receiver. */
typedef enum hfvis_lk_verdict {
    HFVIS_LK_TRI_MASKED = 0,      /* the mask was computed (it may still be 0) */
    HFVIS_LK_TRI_DEGENERATE = 1,  /* zero area (world or frame cross product exactly 0) */
    HFVIS_LK_TRI_SELF = 2,        /* |h| < epsilon: the receiver lies in its plane */
    HFVIS_LK_TRI_FACING_AWAY = 3, /* one-sided and the receiver is behind it */
    HFVIS_LK_TRI_TOO_FAR = 4      /* plane distance d > r_max */
} hfvis_lk_verdict;

/* The exact occlusion mask of one triangle for one receiver (the blocking predicate above;
 * lut != NULL: the LUT form (spec A.4.2/A.4.3): edges lut(e_k/|e_k|, 0), plane lut(m, d/r_max),
 * window ~lut(m, d/r_min)). position = p (world, double), frame = F (hfvis_lk_frame); the
 * distance window [r_min, r_max] with 0 <= r_min <= r_max <= radius; epsilon > 0 (world units,
 * e.g. HFVIS_LK_DEFAULT_EPSILON * radius). mask (words words) is written in every case (all 0
 * unless the verdict is MASKED); verdict may be NULL. Returns HFVIS_ERR_INVALID_ARGUMENT for NULL
 * pointers, an invalid ray set, non-finite inputs, a bad window or epsilon, a lut built for
 * another ray count. No allocation; O(N) (LUT: O(words)). */
HFVIS_API hfvis_status hfvis_lk_triangle_mask(const hfvis_lk_rays *rays, const hfvis_lk_lut *lut,
                                              const double position[3], const double frame[9],
                                              const float v0[3], const float v1[3],
                                              const float v2[3], int two_sided, double r_min,
                                              double r_max, double epsilon, uint32_t *mask,
                                              hfvis_lk_verdict *verdict);

/* ---- the three methods ------------------------------------------------------------------ */

/* Culling tests (spec A.5), bit flags of hfvis_lk_options.cull. They only skip work (see the
 * predicate above), except PAPER_FAR_DEPTH. */
#define HFVIS_LK_CULL_FAR_DEPTH 0x01u       /* Method 1 test 1, safe form: skip when every vertex's
                                               linear view depth exceeds the receiver's by more
                                               than r_max (so is every point of the triangle) */
#define HFVIS_LK_CULL_SPHERE 0x02u          /* |p - c_T| > R_T + r_max (minimal bounding sphere) */
#define HFVIS_LK_CULL_FACING 0x04u          /* one-sided and facing away (h >= 0) */
#define HFVIS_LK_CULL_PLANE 0x08u           /* plane distance d > r_max */
#define HFVIS_LK_CULL_HORIZON 0x10u         /* every vertex below the receiver's horizon (local
                                               z <= 0); Method 2 also culls nodes by it */
#define HFVIS_LK_CULL_PAPER_FAR_DEPTH 0x20u /* Method 1 test 1 as [LK] §4.2 states it: skip when
                                               the rasterized far-side depth of the influence
                                               volume exceeds the receiver's depth + r_max. NOT
                                               conservative (spec A.13-1): behind a grazing
                                               prism or a billboard it drops real occluders */
#define HFVIS_LK_CULL_SET 0x100u            /* marks an explicit set: cull = HFVIS_LK_CULL_SET |
                                               flags; HFVIS_LK_CULL_SET alone = no test */
#define HFVIS_LK_CULL_NONE HFVIS_LK_CULL_SET
#define HFVIS_LK_CULL_ALL (HFVIS_LK_CULL_SET | 0x1Fu) /* the default: every safe test */

/* How a triangle's occlusion mask is computed. */
typedef enum hfvis_lk_mask_mode {
    HFVIS_LK_MASK_DEFAULT = 0, /* = EXACT */
    HFVIS_LK_MASK_EXACT = 1,   /* per-ray dot products (the predicate): the three methods agree */
    HFVIS_LK_MASK_LUT = 2      /* table look-ups (opts->lut required); approximate */
} hfvis_lk_mask_mode;

/* Method 2's node occlusion masks (spec A.9.3), from the node box's bounding sphere (box centre,
 * half-diagonal). */
typedef enum hfvis_lk_node_mask {
    HFVIS_LK_NODE_DEFAULT = 0,    /* = EXACT */
    HFVIS_LK_NODE_EXACT = 1,      /* bit i = segment [0, l_i u_i] meets the sphere (with a
                                     margin): conservative, so results equal Method 1's */
    HFVIS_LK_NODE_SPHERE_LUT = 2, /* the paper's circular mask by one plane look-up ([LK]
                                     Fig. 4; direction table for variable lengths). Quantised,
                                     hence NOT conservative: may lose occlusion */
    HFVIS_LK_NODE_NONE = 3        /* all ones: only the distance and horizon culls */
} hfvis_lk_node_mask;

/* One- or two-sided occluders (the paper's tests: all one-sided). */
typedef enum hfvis_lk_sides {
    HFVIS_LK_SIDES_DEFAULT = 0,     /* = ONE */
    HFVIS_LK_SIDES_ONE = 1,
    HFVIS_LK_SIDES_TWO = 2,
    HFVIS_LK_SIDES_PER_TRIANGLE = 3 /* two_sided[t] != 0 marks triangle t two-sided */
} hfvis_lk_sides;

/* Method 1's bounding volume of a triangle's region of influence ([LK] §4.1, spec A.6). */
typedef enum hfvis_lk_volume {
    HFVIS_LK_VOLUME_DEFAULT = 0, /* = AUTO */
    HFVIS_LK_VOLUME_AUTO = 1,    /* prism if R_T/r_max > alpha, else the sphere billboard */
    HFVIS_LK_VOLUME_PRISM = 2,   /* always the hexagonal prism (the sphere for slivers whose
                                    prism is ill-conditioned) */
    HFVIS_LK_VOLUME_SPHERE = 3   /* always the billboard of the sphere (c_T, R_T + r_max) */
} hfvis_lk_volume;

/* The reference ray caster's ray-triangle test. */
typedef enum hfvis_lk_raycast_test {
    HFVIS_LK_RAYCAST_DEFAULT = 0,   /* = EXACT */
    HFVIS_LK_RAYCAST_EXACT = 1,     /* the blocking predicate (double): equal to the masks of
                                       Methods 1 and 2 bit for bit */
    HFVIS_LK_RAYCAST_WATERTIGHT = 2 /* the library's float watertight test (hfvis_bvh_intersect
                                       any-hit, HFVIS_CULL_BACK for one-sided triangles, a hit
                                       filter for the epsilon and window rules), an independent
                                       check: differs only for rays within rounding of an edge,
                                       a vertex or the segment's end */
} hfvis_lk_raycast_test;

/* Options of the three methods. NULL or a zero struct = defaults. */
typedef struct hfvis_lk_options {
    const hfvis_allocator *alloc;       /* scratch; NULL = malloc/free */
    hfvis_lk_mask_mode mask_mode;       /* default EXACT */
    const hfvis_lk_lut *lut;            /* required by MASK_LUT and NODE_SPHERE_LUT */
    hfvis_lk_node_mask node_mask;       /* Method 2; default EXACT */
    unsigned cull;                      /* 0 = HFVIS_LK_CULL_ALL; else HFVIS_LK_CULL_SET | flags */
    hfvis_lk_sides sides;               /* default ONE */
    const uint8_t *two_sided;           /* SIDES_PER_TRIANGLE: one byte per triangle */
    const float *lod_range;             /* NULL or 2 per triangle: the window [r_min, r_max],
                                           0 <= r_min <= r_max <= radius ([LK] §4.3) */
    double epsilon;                     /* plane epsilon, world units, > 0;
                                           0 = HFVIS_LK_DEFAULT_EPSILON * radius */
    hfvis_lk_jitter jitter;             /* default: full rotation, tilt <= 0.05 rad */
    double rotation_max_rad;            /* JITTER_CUSTOM only */
    double tilt_max_rad;                /* JITTER_CUSTOM only */
    uint64_t seed;                      /* jitter seed; 0 is valid and the default */
    hfvis_lk_volume volume;             /* Method 1; default AUTO */
    double alpha;                       /* Method 1 prism/billboard switch, > 0; 0 = 0.2 */
    hfvis_cull_mode gbuffer_cull;       /* culling of the receivers' rasterization; default
                                           HFVIS_CULL_NONE */
    hfvis_lk_raycast_test raycast_test; /* reference; default EXACT */
} hfvis_lk_options;

/* The defaults (epsilon is left 0: it depends on the radius; see hfvis_lk_options_resolve). */
HFVIS_API hfvis_lk_options hfvis_lk_options_default(void);

/* The options a call with `in` (NULL = defaults) and a ray set of radius `radius` uses, every
 * default made explicit (cull, enums, epsilon, alpha, jitter bounds) - so a port can print the
 * exact parameters. Returns HFVIS_ERR_INVALID_ARGUMENT for NULL out, a bad radius, unknown enum
 * values or flags, a non-positive or non-finite epsilon or alpha, custom jitter bounds out of
 * range; PER_TRIANGLE without two_sided, a LUT mode without lut. */
HFVIS_API hfvis_status hfvis_lk_options_resolve(const hfvis_lk_options *in, double radius,
                                                hfvis_lk_options *out);

/* What a call did (counts, written on success). For Table 2 of [LK] compare `masks` between
 * runs with different cull sets. Method 1 counts (triangle, receiver) pairs, Method 2 triangles
 * reached in leaves per receiver, the ray caster ray-triangle tests. */
typedef struct hfvis_lk_stats {
    uint64_t receivers;            /* receivers processed */
    uint64_t rays;                 /* receivers * N */
    uint64_t rays_blocked;         /* set bits in all masks */
    uint64_t fragments;            /* M1: pairs passing the inverted depth test; M2: triangles
                                      met in leaves; ray caster: predicate evaluations (EXACT
                                      test only; 0 with WATERTIGHT) */
    uint64_t culled_far_depth;     /* M1 test 1 (safe or paper form) */
    uint64_t culled_sphere;        /* influence-sphere test */
    uint64_t culled_facing;
    uint64_t culled_plane;
    uint64_t culled_horizon;
    uint64_t skipped;              /* degenerate or |h| < epsilon (not a culling test) */
    uint64_t masks;                /* triangle masks computed */
    uint64_t prisms, spheres;      /* M1: volumes of each kind rasterized */
    uint64_t nodes_visited;        /* M2 and ray caster (EXACT): inner nodes and leaves entered */
    uint64_t nodes_culled_distance, nodes_culled_horizon, nodes_culled_mask; /* M2 */
} hfvis_lk_stats;

/* Explicit receivers: points with normals (the hemisphere side) and jitter keys. Positions and
 * normals are double: a point on a float triangle is generally not a float, and rounding it
 * would move it off the plane (against the epsilon rule). */
typedef struct hfvis_lk_receivers {
    size_t count;
    const double *position;  /* 3 per receiver, world, finite */
    const double *normal;    /* 3 per receiver, finite, non-zero (normalised internally) */
    const uint64_t *key;     /* jitter key per receiver; NULL = the index */
} hfvis_lk_receivers;

/* The receivers of a view (Method 1's G-buffer, [LK] §4 step 1): hfvis_rasterize (triangle id
 * and barycentrics, culling opts->gbuffer_cull) and, at every pixel with a triangle, in raster
 * order: p = (1 - b1 - b2) v0 + b1 v1 + b2 v2 in double, the face normal (v1 - v0) x (v2 - v0)
 * turned toward the viewer (negated when it points away from the eye, or from -forward for an
 * orthographic view), key = y*width + x. position, normal (3 doubles each) and key (may be
 * NULL) must hold width*height receivers; count gets the number written. Returns HFVIS_OK, the
 * errors of hfvis_rasterize, HFVIS_ERR_INVALID_ARGUMENT for NULL or bad options. Allocations:
 * one block of 12 bytes per pixel plus the rasterizer's scratch. */
HFVIS_API hfvis_status hfvis_lk_gbuffer_receivers(const hfvis_mesh *mesh, const hfvis_view *view,
                                                  const hfvis_lk_options *opts, double *position,
                                                  double *normal, uint64_t *key, size_t *count);

/* Method 1 (rasterization, [LK] §4, spec A.6-A.8) on the CPU. The receivers are those of
 * hfvis_lk_gbuffer_receivers (frames by hfvis_lk_frame with opts' jitter and key = pixel
 * index). Per triangle, in index order: the minimal bounding sphere (c_T, R_T); the volume
 * bounding its region of influence with radius r_max: the hexagonal prism in half-space form
 * {o_k.(x - v_k) <= r, u_k.(x - v_k) <= r, -eps <= n.(x - v0) <= r} (lower cap -r for two-sided
 * triangles) or the sphere billboard (c_T, R_T + r_max), one-sided cut to its front half; its
 * screen bounding box (whole screen when it reaches behind the eye); every receiver pixel of the
 * box whose eye line meets the volume and does not lie behind the volume's far side (the
 * inverted depth test; a billboard sits just behind its sphere) is a fragment; then the tests
 * 1-5 in the paper's order (far depth, sphere, facing, plane distance, horizon) and the mask,
 * OR-ed into the pixel's. Volumes are enlarged by a relative 1e-9 margin.
 * masks: width*height*words uint32 (pixel y*width + x), obscurance: width*height floats (NaN
 * at pixels without a receiver); either may be NULL (not both); stats may be NULL.
 * Returns HFVIS_OK; HFVIS_ERR_INVALID_ARGUMENT for NULL mesh/view/rays, both outputs NULL, an
 * invalid mesh, view or ray set, bad options or a window beyond the radius; HFVIS_ERR_LIMIT
 * for width or height > HFVIS_RASTER_MAX_SIZE (and the rasterizer's limits, or a size that
 * overflows size_t on 32-bit builds); HFVIS_ERR_OUT_OF_MEMORY. Outputs untouched on error.
 * Receivers: only pixels whose triangle the G-buffer shows (background pixels have none,
 * spec A.13-11); the receiver normal faces the viewer, so the hemisphere is on the visible
 * side (back faces seen through an open mesh receive on their visible side too).
 * Memory: 3 blocks: the G-buffer (12 bytes per pixel), the rasterizer's scratch, and one block
 * of 4 bytes per pixel plus 104 bytes per receiver (plus its masks when masks is NULL).
 * Cost O(T + covered pixels * N). */
HFVIS_API hfvis_status hfvis_lk_raster(const hfvis_mesh *mesh, const hfvis_view *view,
                                       const hfvis_lk_rays *rays, const hfvis_lk_options *opts,
                                       uint32_t *masks, float *obscurance, hfvis_lk_stats *stats);

/* Method 2 (BVH traversal, [LK] §5, spec A.9) for explicit receivers. Per receiver: cumulative
 * mask C = 0; a node (the root too) is culled when its padded box lies farther than r from p,
 * entirely below the horizon (every corner's local z <= 0), or its node mask adds no ray
 * (popcount(M & ~C) = 0); surviving children are visited larger estimate first; leaf triangles
 * pass the tests in the paper's BVH order (horizon, facing, plane distance, sphere) and
 * C |= mask; stops when every ray is blocked. With exact node masks the result is the OR of
 * all triangle masks (order-independent), i.e. equal to Method 1 and the ray caster.
 * bvh: built over mesh (hfvis_bvh_build); it is validated first (O(nodes)). masks:
 * recv->count*words, obscurance: recv->count; either may be NULL (not both).
 * Returns HFVIS_OK; HFVIS_ERR_INVALID_ARGUMENT for NULL, an invalid mesh, ray set or receiver
 * (non-finite, zero normal), a BVH that does not match the mesh or is malformed, bad options;
 * HFVIS_ERR_LIMIT when count*words or the scratch overflows size_t; HFVIS_ERR_OUT_OF_MEMORY. Outputs untouched on error. Memory: 1 block (32 bytes per
 * triangle, 1 byte per node, the traversal stack). */
HFVIS_API hfvis_status hfvis_lk_bvh(const hfvis_mesh *mesh, const hfvis_bvh *bvh,
                                    const hfvis_lk_rays *rays, const hfvis_lk_receivers *recv,
                                    const hfvis_lk_options *opts, uint32_t *masks,
                                    float *obscurance, hfvis_lk_stats *stats);

/* The reference ray caster (spec A.10): every ray i of every receiver, the segment
 * p + t r F^T s_i, t in [0, 1], cast through the BVH (slab tests in double on the padded boxes,
 * widened by 2^-40) with an any-hit query; the ray-triangle test is opts->raycast_test (EXACT:
 * the blocking predicate, so the masks equal Methods 1 and 2 bit for bit; WATERTIGHT: the
 * library's float hfvis_bvh_intersect). Arguments, outputs and errors as hfvis_lk_bvh (its
 * options mask_mode, node_mask and cull do not apply). Memory: 1 block, as hfvis_lk_bvh. Cost
 * O(rays log T). */
HFVIS_API hfvis_status hfvis_lk_raycast(const hfvis_mesh *mesh, const hfvis_bvh *bvh,
                                        const hfvis_lk_rays *rays,
                                        const hfvis_lk_receivers *recv,
                                        const hfvis_lk_options *opts, uint32_t *masks,
                                        float *obscurance, hfvis_lk_stats *stats);

/* Which method hfvis_lk_image runs. */
typedef enum hfvis_lk_method {
    HFVIS_LK_METHOD_RASTER = 1,  /* hfvis_lk_raster */
    HFVIS_LK_METHOD_BVH = 2,     /* hfvis_lk_bvh on the G-buffer receivers */
    HFVIS_LK_METHOD_RAYCAST = 3  /* hfvis_lk_raycast on the G-buffer receivers */
} hfvis_lk_method;

/* The AO image of a view by any method: the G-buffer receivers (hfvis_lk_gbuffer_receivers) and
 * the method; outputs per pixel as hfvis_lk_raster (NaN / zero masks where no receiver). bvh may
 * be NULL for the BVH methods (one is built with opts->alloc and freed). With exact masks the
 * three methods give the same masks. Errors: those of the routines called, and
 * HFVIS_ERR_INVALID_ARGUMENT for an unknown method. */
HFVIS_API hfvis_status hfvis_lk_image(hfvis_lk_method method, const hfvis_mesh *mesh,
                                      const hfvis_bvh *bvh, const hfvis_view *view,
                                      const hfvis_lk_rays *rays, const hfvis_lk_options *opts,
                                      uint32_t *masks, float *obscurance, hfvis_lk_stats *stats);

