
/* ========================================================================================== */
/* voxel.c - BVH and ray casting: SAH bounding volume hierarchy, watertight ray-triangle test  */
/* ========================================================================================== */

/* Rays and hits (all queries below).
 *
 * A ray is the segment origin + t*direction, t in [t_min, t_max] (both ends included), in the
 * mesh's world units; direction need not be unit length (t is then in units of |direction|).
 * Valid when origin and direction are finite, direction != 0, 0 <= t_min <= t_max (t_min
 * finite, t_max may be +INFINITY) and cull is one of the hfvis_cull_mode values.
 *
 * Triangles are tested with the watertight algorithm of S. Woop, C. Benthin, I. Wald,
 * "Watertight Ray/Triangle Intersection", JCGT 2(1), 2013 (hfvis_ray_triangle): the vertices
 * are translated to the ray origin, permuted so the direction's largest component is z, and
 * sheared so the ray becomes the +z axis; the three 2D edge functions U, V, W of the sheared
 * vertices decide the hit, evaluated in float and again in double when one is exactly 0 (or
 * not finite), so their SIGNS are exact for the sheared float vertices. A point is inside when
 * U, V, W all have the same sign, zeros counting as either sign: edges and vertices belong to
 * the triangle, and a ray through an edge or vertex of a closed mesh (shared vertices, or
 * bit-identical duplicated vertices) always hits at least one of its triangles - no cracks.
 * Zero-area triangles ((v1 - v0) x (v2 - v0) exactly 0, decided exactly) never hit; neither do
 * triangles the ray meets edge-on (U + V + W = 0).
 * Hit values: t = (U Az + V Bz + W Cz)/(U + V + W) (the paper's T/det, float; double on the
 * fallback path), u = V/det, v = W/det: the hit point is (1-u-v) v0 + u v1 + v v2. front = 1
 * when the ray meets the side the normal (v1 - v0) x (v2 - v0) points to (direction.n < 0;
 * det > 0), 0 otherwise. A hit needs t in [t_min, t_max] and t finite.
 *
 * Exactness: hfvis_ray_triangle is a pure function of the ray and the three float vertices,
 * bit-identical across IEEE-754 builds that evaluate float in float (FLT_EVAL_METHOD 0: SSE2,
 * ARM) without FMA contraction. The closest hit is the candidate of smallest t; exactly equal t
 * go to the LOWEST triangle index. The BVH queries return exactly what their naive oracles
 * return (same t, triangle, u, v, front bits; for any-hit the same verdict): both apply the
 * same test and the same order, and the BVH prunes conservatively - node boxes are padded (see
 * hfvis_bvh_node) and the slab test widens the far distance and the current best distance by
 * the factor (1 + 2^-16), above the 1 + 2 gamma_3 of T. Ize, "Robust BVH Ray Traversal", JCGT
 * 2(2), 2013. What is not guaranteed: the margins cover the rounding of the slab test and of
 * the hit distance of well-conditioned hits; for a ray grazing a triangle (angle below about
 * 1e-4 rad) t is ill-conditioned and could in principle fall outside the padded box, and the
 * BVH would then lose that hit only if a competing hit at almost the same distance (or t_min /
 * t_max) prunes the box. Never observed: 0 mismatches in the tests (over 2e5 rays, incl. rays
 * through edges, vertices and face planes), in 1.9e6 more seeded rays, and in 4.8e6
 * adversarial rays grazing triangle corners at 1e-3 .. 1e-8 rad.
 * Range: every vertex - origin difference and the sheared coordinates must stay in float range
 * (|coordinates| below about 1e37); beyond that a triangle may be missed (never a crash). */

/* A ray (see above). A zero-initialised struct is invalid (direction 0); t_max = INFINITY and
 * cull = HFVIS_CULL_NONE are the usual choices. */
typedef struct hfvis_ray {
    float origin[3];
    float direction[3];   /* finite, not all zero; need not be unit length */
    float t_min;          /* >= 0, finite; hits with t >= t_min count (for the open interval
                             (0, L] of AO rays use the smallest positive float, or an offset
                             that skips the receiver's own triangle) */
    float t_max;          /* >= t_min, may be INFINITY; hits with t <= t_max count */
    hfvis_cull_mode cull; /* the rasterizer's enum: HFVIS_CULL_NONE (default, 0) both sides
                             hit; HFVIS_CULL_BACK ignores triangles seen from behind
                             (direction . n > 0, n = (v1 - v0) x (v2 - v0)), as the one-sided
                             AO rays of Laine & Karras; HFVIS_CULL_FRONT ignores those seen from
                             the front (direction . n < 0) */
} hfvis_ray;

/* A ray query's result. On a miss: t = +INFINITY, triangle = HFVIS_NO_TRIANGLE, u = v = 0,
 * front = 0. */
typedef struct hfvis_hit {
    float t;            /* ray parameter of the hit point: origin + t*direction */
    uint32_t triangle;  /* triangle index in the mesh, HFVIS_NO_TRIANGLE on a miss */
    float u, v;         /* barycentrics of v1 and v2: point = (1-u-v) v0 + u v1 + v v2 */
    int front;          /* 1: the ray meets the front (normal) side, 0: the back side */
} hfvis_hit;

/* Which hit a query returns. */
typedef enum hfvis_ray_query {
    HFVIS_RAY_CLOSEST = 0, /* smallest t in [t_min, t_max]; equal t: lowest triangle index */
    HFVIS_RAY_ANY = 1      /* stop at the first accepted hit in [t_min, t_max] (occlusion) */
} hfvis_ray_query;

/* Optional candidate filter of hfvis_bvh_intersect / hfvis_ray_intersect_naive (alpha masks,
 * self-intersection rules such as the Laine-Karras reference's "skip triangles whose plane
 * passes within eps of the receiver", per-object masks). Called with a candidate hit (t in
 * [t_min, t_max], culling passed, triangle set) that would be accepted; return nonzero to
 * accept it, 0 to ignore that triangle for this ray. It must be a pure function of its
 * arguments: the queries call it in different orders and not for every candidate (a candidate
 * that cannot beat the current best is not offered), and only then do the BVH and naive results
 * agree exactly. */
typedef int (*hfvis_hit_filter)(void *user, const hfvis_ray *ray, const hfvis_hit *candidate);

/* The watertight ray-triangle test (see "Rays and hits" above) of one triangle v0, v1, v2.
 * On a hit writes hit (triangle = 0, the only one); on a miss writes the miss values (triangle =
 * HFVIS_NO_TRIANGLE). Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for a NULL pointer, an
 * invalid ray or a non-finite vertex (hit untouched). Cost: about 40 flops, plus an exact
 * zero-area test (usually one 6-term sum) on a hit. Allocates nothing. */
HFVIS_API hfvis_status hfvis_ray_triangle(const hfvis_ray *ray, const float v0[3],
                                          const float v1[3], const float v2[3], hfvis_hit *hit);

/* ---- BVH ------------------------------------------------------------------------------------ */

#define HFVIS_BVH_MAX_LEAF_SIZE 8        /* leaves hold 1..max_leaf_size triangles */
#define HFVIS_BVH_DEFAULT_LEAF_SIZE 4
#define HFVIS_BVH_DEFAULT_BINS 16        /* SAH bins per axis */
#define HFVIS_BVH_MAX_BINS 64
#define HFVIS_BVH_SAH_DEPTH 64           /* nodes deeper than this are split at the median */
#define HFVIS_BVH_MAX_DEPTH 96           /* guaranteed bound of hfvis_bvh.depth (SAH_DEPTH + 32) */
#define HFVIS_BVH_MAX_TRIANGLES ((size_t)0x7FFFFFFF) /* 2^31 - 1: node indices fit uint32_t */

/* One node, 32 bytes. The layout is part of the API so that GPU ports can upload it as is.
 * lo, hi: an axis-aligned box (float) containing the float bounding boxes of all triangles
 * below the node, padded outward: each bound moves out by pad = 2^-18 * m, m = the largest of
 * the box's |lo[a]|, |hi[a]| and hi[a] - lo[a] (before padding, in double, then rounded to float
 * away from the box; so every child box lies inside its parent's box).
 * count == 0: inner node, children nodes[left_or_first] and nodes[left_or_first + 1] (siblings
 * are adjacent); count 1..max_leaf_size: leaf holding the triangles
 * tri_order[left_or_first .. left_or_first + count - 1]. */
typedef struct hfvis_bvh_node {
    float lo[3];
    float hi[3];
    uint32_t left_or_first;
    uint32_t count;
} hfvis_bvh_node;

/* A BVH over a mesh's triangles. nodes[0] is the root; node_count <= 2*triangle_count - 1
 * (0 nodes for a mesh without triangles: every query misses). tri_order is a permutation of
 * 0..triangle_count-1 (every triangle exactly once, degenerate ones included). depth = nodes on
 * the longest root-to-leaf path (1 for a single leaf, 0 when empty), <= HFVIS_BVH_MAX_DEPTH.
 * The BVH holds no pointer to the mesh: pass the same, unmodified mesh to every query. */
typedef struct hfvis_bvh {
    hfvis_bvh_node *nodes;
    size_t node_count;
    uint32_t *tri_order;
    size_t triangle_count;
    size_t leaf_count;
    int depth;
    int max_leaf_size;   /* the option it was built with */
} hfvis_bvh;

/* Options of hfvis_bvh_build. NULL or a zero struct = defaults. */
typedef struct hfvis_bvh_options {
    const hfvis_allocator *alloc; /* for the BVH's two arrays and the scratch; NULL = malloc */
    int max_leaf_size;            /* 1..HFVIS_BVH_MAX_LEAF_SIZE; 0 = HFVIS_BVH_DEFAULT_LEAF_SIZE */
    int bins;                     /* SAH bins per axis, 2..HFVIS_BVH_MAX_BINS; 0 = default 16 */
} hfvis_bvh_options;

/* The defaults: alloc NULL, max_leaf_size 4, bins 16. */
HFVIS_API hfvis_bvh_options hfvis_bvh_options_default(void);

/* Build a BVH over mesh's triangles: top-down, binned surface area heuristic (MacDonald &
 * Booth 1990; binning as I. Wald, "On fast construction of SAH-based bounding volume
 * hierarchies", IEEE RT 2007), the spec's A.9.2 choice: for each node, triangle centroids
 * (centres of their float bounding boxes) are put into `bins` equal bins over the centroid
 * bounds on each axis whose centroid extent is > 0; the split between bins with the least
 * C_trav + C_tri (A_L N_L + A_R N_R)/A (C_trav = C_tri = 1, A = box surface area) wins (ties:
 * lower axis, then lower bin). A node becomes a leaf when it holds one triangle, or at most
 * max_leaf_size triangles and the leaf cost N <= the best split cost; a node of more than
 * max_leaf_size triangles is always split. Nodes deeper than HFVIS_BVH_SAH_DEPTH, and nodes
 * whose centroids all coincide or whose box has zero area, are split at the median of the
 * centroids along the axis of largest centroid extent (ties by triangle index), so depth <=
 * HFVIS_BVH_MAX_DEPTH. Deterministic: same mesh and options, same arrays bit for bit.
 * O(n log n) for n triangles (O(bins) per node and O(n) per level).
 * On success *out owns two blocks from opts->alloc (nodes, tri_order); free them with
 * hfvis_bvh_free(opts->alloc, out). The build allocates four blocks in all (the two above,
 * 24 bytes per triangle of bounds and 2n-1 nodes of scratch, freed before returning).
 * Returns HFVIS_OK; HFVIS_ERR_INVALID_ARGUMENT for NULL mesh or out, max_leaf_size or bins out
 * of range, an invalid mesh (hfvis_mesh); HFVIS_ERR_LIMIT for more than HFVIS_BVH_MAX_TRIANGLES
 * triangles (checked before the mesh's arrays are read); HFVIS_ERR_OUT_OF_MEMORY. On error *out
 * is untouched and nothing is leaked. */
HFVIS_API hfvis_status hfvis_bvh_build(const hfvis_mesh *mesh, const hfvis_bvh_options *opts,
                                       hfvis_bvh *out);

/* Release a BVH's arrays with the allocator it was built with (NULL = free) and zero the
 * struct. bvh may be NULL. */
HFVIS_API void hfvis_bvh_free(const hfvis_allocator *alloc, hfvis_bvh *bvh);

/* Ray query through the BVH (see "Rays and hits"): the closest hit (query HFVIS_RAY_CLOSEST)
 * or any hit (HFVIS_RAY_ANY) in [t_min, t_max] among the triangles that pass culling and the
 * optional filter (filter may be NULL; user is passed to it). Traversal: explicit stack
 * (HFVIS_BVH_MAX_DEPTH entries), both children's slab tests at each inner node, nearer child
 * first, the farther one pushed with its entry distance and skipped on pop once the best hit is
 * closer. The slab test uses 1/direction with zero components as +-infinity (the sign of the
 * zero) and ignores the NaN of 0 * infinity, so axis-parallel rays, also rays lying in a box's
 * face plane, are handled without NaN. The closest hit equals hfvis_ray_intersect_naive's bit
 * for bit; the any-hit verdict equals the naive one (the triangle reported may differ: any
 * accepted hit, not necessarily the closest). hit receives the result, miss values on a miss.
 * Returns HFVIS_OK; HFVIS_ERR_INVALID_ARGUMENT for NULL bvh, mesh, ray or hit, an invalid ray,
 * an unknown query, a bvh whose triangle_count differs from the mesh's or whose depth exceeds
 * HFVIS_BVH_MAX_DEPTH, a visited triangle with an index >= vertex_count, or a corrupted bvh met
 * during the traversal (a child index not after its parent or past node_count, a leaf range
 * past tri_order, a stack overflow); hit is untouched then. Memory-safe for any bvh whose
 * arrays have node_count and triangle_count entries. The mesh's coordinates are not re-checked
 * (hfvis_bvh_build did). Allocates nothing; reentrant. Cost: O(log n) nodes for typical
 * scenes. */
HFVIS_API hfvis_status hfvis_bvh_intersect(const hfvis_bvh *bvh, const hfvis_mesh *mesh,
                                           const hfvis_ray *ray, hfvis_ray_query query,
                                           hfvis_hit_filter filter, void *user, hfvis_hit *hit);

/* hfvis_bvh_intersect(bvh, mesh, ray, HFVIS_RAY_CLOSEST, NULL, NULL, hit). */
HFVIS_API hfvis_status hfvis_bvh_closest_hit(const hfvis_bvh *bvh, const hfvis_mesh *mesh,
                                             const hfvis_ray *ray, hfvis_hit *hit);

/* hfvis_bvh_intersect(bvh, mesh, ray, HFVIS_RAY_ANY, NULL, NULL, hit): stops at the first
 * hit found in [t_min, t_max] (shadow / AO rays). A hit has hit->triangle != HFVIS_NO_TRIANGLE. */
HFVIS_API hfvis_status hfvis_bvh_any_hit(const hfvis_bvh *bvh, const hfvis_mesh *mesh,
                                         const hfvis_ray *ray, hfvis_hit *hit);

/* Oracle: the same query by testing every triangle in index order with hfvis_ray_triangle's
 * test. Closest: the smallest t, ties to the lowest index. Any: the lowest-index accepted hit.
 * Returns HFVIS_OK; HFVIS_ERR_INVALID_ARGUMENT for NULL mesh, ray or hit, NULL mesh arrays with
 * nonzero counts, an invalid ray, an unknown query, or an index >= vertex_count (hit
 * untouched); coordinates are not checked for finiteness. Allocates nothing. Cost: O(T). */
HFVIS_API hfvis_status hfvis_ray_intersect_naive(const hfvis_mesh *mesh, const hfvis_ray *ray,
                                                 hfvis_ray_query query, hfvis_hit_filter filter,
                                                 void *user, hfvis_hit *hit);

/* hfvis_ray_intersect_naive(mesh, ray, HFVIS_RAY_CLOSEST, NULL, NULL, hit). */
HFVIS_API hfvis_status hfvis_ray_closest_naive(const hfvis_mesh *mesh, const hfvis_ray *ray,
                                               hfvis_hit *hit);

/* hfvis_ray_intersect_naive(mesh, ray, HFVIS_RAY_ANY, NULL, NULL, hit). */
HFVIS_API hfvis_status hfvis_ray_any_naive(const hfvis_mesh *mesh, const hfvis_ray *ray,
                                           hfvis_hit *hit);
