
/* ========================================================================================== */
/* voxel.c - 4D visibility fields ([G12] ch. 4, Alg. 1-3; spec voxel §1)                      */
/* ========================================================================================== */

/* A visibility field (Gaitatzes et al., WSCG 2008/2010; [G12] ch. 4) replaces the ray-object
 * intersection of secondary rays (ambient-occlusion, shadow and glossy-reflection rays) against
 * one RIGID object by a table lookup. For K positional samples u_k on the object's bounding
 * sphere (centre c, radius R) and, at each, a D x D map of directions over the hemisphere
 * around the INWARD normal w_k = -u_k, it stores the distance from p_k = c + R u_k along the
 * direction to the first surface of the object (or a miss). A query ray meets the sphere
 * analytically and reads the rest of its distance from the map of the nearest sample, at the
 * texel of its direction. Everything is in OBJECT space; instances with rigid transforms (and a
 * uniform scale) share one field.
 *
 * Conventions of this section.
 * - Positional samples (spec §1.3, the octahedral construction that reproduces the thesis'
 *   counts; [G12] cites Slater's triangle subdivision): with frequency n, the upper hemisphere
 *   holds the points (a, b, n - |a| - |b|)/|.| for integer |a| + |b| <= n (H = 2n^2 + 2n + 1
 *   of them), the lower one their mirror images (a, b, -(n - |a| - |b|))/|.|, so
 *   K = 2(2n^2 + 2n + 1): n = 4, 8, 16, 32, 64 give 82, 290, 1090, 4226, 16642 (the thesis'
 *   80 is taken as a misprint of 82). Index k = h*H + r, h = 0 upper (z >= 0), 1 lower; within
 *   a hemisphere rows b = -n..n in increasing order, each with a = -(n-|b|)..(n-|b|) in
 *   increasing order. The equator (|a| + |b| = n) exists in both hemispheres (same point, same
 *   map content); the nearest-sample lookup returns the upper copy.
 * - Frame: the hemisphere of sample k is expressed in the tangent frame (t, b, w) of
 *   hfvis_visfield_frame(w), w = -u_k; a local direction l = (lx, ly, lz), lz >= 0, is the
 *   object direction lx t + ly b + lz w.
 * - Maps (spec §1.4): texel (i, j), 0 <= i, j < D, has square coordinates A = 2(i + 0.5)/D - 1
 *   (column i), B = 2(j + 0.5)/D - 1 (row j); see hfvis_dirmap. Storage is maps[k][j][i].
 * - Distances are stored normalised by the sphere's diameter 2R, so they lie in [0, 1]: a chord
 *   is at most 2R long. A MISS means the ray from p_k leaves the sphere without meeting the
 *   object (the thesis records it as 2R).
 * - The mesh must lie inside the sphere. Geometry is double; the rays of the build are
 *   hfvis_ray (float) cast with hfvis_bvh_closest_hit, so the build equals its oracle
 *   (hfvis_visfield_build_reference, the naive caster) bit for bit.
 * - Objects in a scene (hfvis_visfield_object) carry an object -> world matrix
 *   M = [s Q | T] (column-major as hfvis_view, Q orthogonal, s > 0 a uniform scale): a world
 *   ray (o, d) becomes o' = Q^T (o - T)/s, d' = Q^T d, and object distances are multiplied by s
 *   ([G12] §4.4.2 "q' = M^-1 q"). Non-uniform scale is refused (the sphere would be an ellipsoid).
 * - Every query is an approximation: the stored ray starts at the snapped sample p_k and runs
 *   along the snapped texel direction, so hit distances carry a positional error of about
 *   R * (covering angle, ~79 deg / n) and the 8-bit step R/127; the tests report hit/miss
 *   disagreement and mean distance error against ray casting (the oracle) per (K, D). Measured
 *   (teapot in the thesis' corner, 256 AO rays per receiver, 8-bit scale): AO RMS about 9, 4.4,
 *   3.0, 2.6 for K = 82, 290, 1090, 4226 at D = 32 (the thesis' Fig. 35 trend: K matters, D
 *   hardly). Receivers on the object itself (intra-object AO) need the bias above the snapping
 *   offset: a convex sphere occludes itself by 10 % at K = 1090 with the default bias (0 with
 *   0.1 R) and by 0.4 % at K = 4226. */

#define HFVIS_VISFIELD_MAX_N 1024          /* positions_n: 1..1024 (K <= 4,198,402 maps) */
#define HFVIS_VISFIELD_MAX_DIR_RES 4096    /* dir_res D: 1..4096 */
#define HFVIS_VISFIELD_U8_SCALE 254        /* 8-bit distance code q = round(254 th/(2R)), 0..254 */
#define HFVIS_VISFIELD_U8_MISS 255         /* 8-bit miss code */
#define HFVIS_VISFIELD_DEFAULT_BIAS 0.02   /* inside-query bias, a fraction of the radius R */
#define HFVIS_VISFIELD_NONE ((size_t)-1)   /* "no map" / "no object" in results */
#define HFVIS_VISFIELD_MAX_RAYS_SQRT 256   /* AO rays per point: at most 256 x 256 */
#define HFVIS_VISFIELD_MAX_SAMPLES 65536   /* shadow / reflection rays per point */
/* Largest payload (map bytes) the file decoder accepts: 4 GiB. Larger fields can be built in
 * memory (hfvis_visfield_size) but not loaded. */
#define HFVIS_VISFIELD_MAX_BYTES ((uint64_t)1 << 32)
#define HFVIS_VISFIELD_FILE_HEADER 80      /* bytes before the payload in a field file */

/* How the hemisphere of directions maps onto the D x D texels ([G12] §4.4.4, spec §1.4). */
typedef enum hfvis_dirmap {
    HFVIS_DIRMAP_DEFAULT = 0,    /* = HFVIS_DIRMAP_CONCENTRIC */
    /* Polar ("uniform") mapping: column i is the polar angle theta = (i + 0.5)/D * pi/2 from the
     * inward normal, row j the azimuth phi = (j + 0.5)/D * 2 pi from t toward b;
     * l = (sin theta cos phi, sin theta sin phi, cos theta). Directions crowd at the pole. */
    HFVIS_DIRMAP_POLAR = 1,
    /* Rejection sampling + Malley: l = (A, B, sqrt(1 - A^2 - B^2)); texels whose centre lies
     * outside the unit disk (A^2 + B^2 > 1, about 21.5 %) are unused and hold the miss code, so
     * a query direction that falls into one (near the rim) is a miss. */
    HFVIS_DIRMAP_REJECTION = 2,
    /* Shirley-Chiu concentric map + Malley (the thesis' choice): (A, B) -> disk point (x, y) by
     * hfvis_concentric_square_to_disk, l = (x, y, sqrt(1 - x^2 - y^2)); cosine-distributed,
     * area preserving. sin(angle to the normal) = max(|A|, |B|). */
    HFVIS_DIRMAP_CONCENTRIC = 3
} hfvis_dirmap;

/* What a texel stores ([G12] §4.6.1, spec §1.2, §1.5-1.6). */
typedef enum hfvis_visfield_format {
    HFVIS_VISFIELD_DEFAULT = 0,  /* = HFVIS_VISFIELD_U8 */
    /* 1 byte per texel: a hit at distance th stores q = min(254, floor(254 th/(2R) + 0.5)),
     * decoded as q * 2R/254 (error <= R/254); a miss stores 255. The thesis' default. */
    HFVIS_VISFIELD_U8 = 1,
    /* 4 bytes per texel (native-endian float in memory, little-endian in files): th/(2R) for a
     * hit, clamped to [0, 1 - 2^-24] (the largest float below 1), and exactly 1.0 for a miss
     * (the thesis' "2R"). */
    HFVIS_VISFIELD_F32 = 2,
    /* 1 bit per texel (hit = 1), bit index (k*D + j)*D + i, byte index >> 3, bit index & 7
     * (least significant first); (K*D*D + 7)/8 bytes, unused bits of the last byte are 0. A hit
     * reads the field's avg_distance ([G12] §4.6.1.3, "the average distance of the sample
     * points towards the object in the direction of the normal"). */
    HFVIS_VISFIELD_BIT = 3,
    /* 4 bytes per texel for reflections ([G12] §4.5.2: distances plus normal maps): bytes 0..2
     * the object-space unit normal n of the hit triangle ((v1 - v0) x (v2 - v0), the mesh's
     * winding) as floor(127.5 n + 128) clamped to 0..255, decoded (b - 127.5)/127.5 and
     * renormalised; byte 3 the 8-bit distance code of HFVIS_VISFIELD_U8. A miss is 0, 0, 0, 255. */
    HFVIS_VISFIELD_NORMAL = 4
} hfvis_visfield_format;

/* A visibility field: its parameters and the caller's storage. Set the parameters and maps /
 * maps_size (hfvis_visfield_size bytes, any alignment) before hfvis_visfield_build; the decoder
 * fills everything and allocates maps. Valid when center and radius are finite, radius > 0,
 * positions_n in 1..HFVIS_VISFIELD_MAX_N, dir_res in 1..HFVIS_VISFIELD_MAX_DIR_RES, mapping and
 * format are known values, avg_distance is in [0, 1], maps is not NULL and maps_size >=
 * hfvis_visfield_size(positions_n, dir_res, format). */
typedef struct hfvis_visfield {
    double center[3];              /* object-space bounding sphere centre c */
    double radius;                 /* its radius R > 0; the mesh must lie inside */
    int positions_n;               /* octahedral frequency n; K = 2(2n^2 + 2n + 1) maps */
    int dir_res;                   /* D: each map holds D x D texels */
    hfvis_dirmap mapping;          /* direction map; 0 = concentric */
    hfvis_visfield_format format;  /* texel format; 0 = 8-bit distance */
    double avg_distance;           /* written by the build (every format): the mean over the
                                      samples whose central ray (along w_k) hits of th/(2R),
                                      0.5 if none hits; what a set bit means (BIT format) */
    void *maps;                    /* the K maps, maps[k][j][i] in the format's layout */
    size_t maps_size;              /* bytes available at maps */
} hfvis_visfield;

/* Result of one visibility-field query. */
typedef enum hfvis_visfield_result {
    HFVIS_VISFIELD_MISS = 0,     /* nothing found (also: the ray misses the sphere) */
    HFVIS_VISFIELD_HIT = 1,      /* origin outside the sphere: the first surface, at distance */
    HFVIS_VISFIELD_OCCLUDED = 2  /* origin inside the sphere ([G12] Fig. 31): some surface lies
                                    between the origin (beyond the bias) and the sphere exit;
                                    distance is that of the crossing nearest the exit */
} hfvis_visfield_result;

typedef struct hfvis_visfield_hit {
    hfvis_visfield_result result;
    double distance;     /* along the UNIT ray direction, object units; INFINITY on a miss */
    double normal[3];    /* hits of a HFVIS_VISFIELD_NORMAL field (and every reference hit): the
                            unit object-space normal of the surface (mesh winding); else 0 */
    double sphere_t;     /* d1: distance to the sphere entry (outside) or exit (inside);
                            INFINITY when the ray does not meet the sphere */
    size_t position;     /* map k read, HFVIS_VISFIELD_NONE if none (and in reference results) */
    int texel_i, texel_j;/* texel read, -1 if none */
} hfvis_visfield_hit;

/* ---- samples, frames and direction maps ------------------------------------------------- */

/* Number of positional samples K = 2(2n^2 + 2n + 1); 0 if n is outside 1..HFVIS_VISFIELD_MAX_N. */
HFVIS_API size_t hfvis_visfield_position_count(int positions_n);

/* Unit direction u_k of positional sample k (see Conventions): (a, b, +-c)/sqrt(a^2+b^2+c^2),
 * c = n - |a| - |b|, in double (the squared length is an exact integer). Constant time.
 * Returns HFVIS_ERR_INVALID_ARGUMENT for n out of range, k >= K or NULL dir (dir untouched). */
HFVIS_API hfvis_status hfvis_visfield_position(int positions_n, size_t k, double dir[3]);

/* Nearest positional sample to direction q (any length > 0), in constant time (spec §1.3; a CPU
 * replacement of Slater's colour-index buffer). Samples are ranked by the key d |d| / L, d = the
 * dot product of q with the lattice point (a, b, +-c), L = a^2 + b^2 + c^2 (exact): a monotone
 * function of the cosine, so the largest key is the nearest sample (no square root). Equal keys
 * go to the lowest index (an equator point therefore gives its upper copy). q is first divided by
 * its largest |component| when that lies outside [1e-100, 1e100] (no overflow). The search
 * projects q radially onto the octahedron |x| + |y| + |z| = 1 of its hemisphere (h = q.z < 0)
 * and compares the 3 x 3 lattice points around (round(n x), round(n y)) with |a| + |b| <= n.
 * Equals hfvis_visfield_nearest_position_naive bit for bit (the same keys, the same tie rule):
 * the tests check 4 x 10^5 random and adversarial directions (Voronoi edges between samples,
 * the equator, coordinate planes, scales 1e+-250). Returns HFVIS_ERR_INVALID_ARGUMENT for n out
 * of range, NULL, a non-finite or zero q (k untouched). */
HFVIS_API hfvis_status hfvis_visfield_nearest_position(int positions_n, const double q[3],
                                                       size_t *k);

/* Oracle: the same key over all K samples in index order (strictly greater wins). O(K). */
HFVIS_API hfvis_status hfvis_visfield_nearest_position_naive(int positions_n, const double q[3],
                                                             size_t *k);

/* The fixed tangent frame of a unit vector w (Duff et al., "Building an orthonormal basis,
 * revisited", JCGT 6(1), 2017): s = -1 if w.z < 0 else 1 (also for -0), a = -1/(s + w.z),
 * e = w.x w.y a,
 * t = (1 + s w.x^2 a, s e, -s w.x), b = (e, s + w.y^2 a, -w.y); (t, b, w) is orthonormal and
 * right-handed (t x b = w) to rounding. Used for the maps (w = -u_k) and the AO ray sets
 * (w = the receiver normal). w must be unit length and the pointers valid (not checked). */
HFVIS_API void hfvis_visfield_frame(const double w[3], double t[3], double b[3]);

/* Shirley & Chiu's concentric map, "A low distortion map between disk and square", JGT 2(3),
 * 1997 (spec §1.4 formulas): square [-1, 1]^2 -> unit disk, area preserving; the disk radius is
 * max(|a|, |b|). And its inverse (the origin maps to (0, 0)). Outputs must not be NULL. */
HFVIS_API void hfvis_concentric_square_to_disk(double a, double b, double *x, double *y);
HFVIS_API void hfvis_concentric_disk_to_square(double x, double y, double *a, double *b);

/* Local direction of texel (i, j) under mapping with D x D texels (see hfvis_dirmap): unit,
 * lz >= 0. *used = 0 for an unused rejection-sampling texel (l then holds its unprojected
 * (A, B, 0)), else 1. Returns HFVIS_ERR_INVALID_ARGUMENT for an unknown mapping, D out of
 * 1..HFVIS_VISFIELD_MAX_DIR_RES, i or j outside 0..D-1, NULL (outputs untouched). */
HFVIS_API hfvis_status hfvis_dirmap_to_local(hfvis_dirmap mapping, int dir_res, int i, int j,
                                             double l[3], int *used);

/* Texel of local direction l (finite, lz >= 0, any length > 0; normalised first): polar
 * i = min(D-1, floor(theta/(pi/2) D)), j = min(D-1, floor(phi/(2 pi) D)), phi = atan2 in
 * [0, 2 pi); rejection (A, B) = (lx, ly); concentric (A, B) = hfvis_concentric_disk_to_square
 * (lx, ly); then i = clamp(floor((A + 1)/2 D), 0, D-1) and likewise j from B. *used as
 * hfvis_dirmap_to_local for that texel (used may be NULL). The inverse of hfvis_dirmap_to_local
 * on every texel centre (tested for all texels up to D = 512). Returns
 * HFVIS_ERR_INVALID_ARGUMENT for an unknown mapping, D out of range, NULL i or j, l NULL,
 * non-finite, zero or with lz < 0 (outputs untouched). */
HFVIS_API hfvis_status hfvis_dirmap_from_local(hfvis_dirmap mapping, int dir_res,
                                               const double l[3], int *i, int *j, int *used);

/* ---- build --------------------------------------------------------------------------------- */

/* Bytes of the maps of a field: K*D*D (U8), 4*K*D*D (F32, NORMAL), (K*D*D + 7)/8 (BIT); e.g.
 * n = 32 (K = 4226), D = 64, U8: 17,309,696 bytes, the thesis' "16.5 MB". 0 for parameters out
 * of range, an unknown format, or a size that overflows size_t. */
HFVIS_API size_t hfvis_visfield_size(int positions_n, int dir_res, hfvis_visfield_format format);

/* A bounding sphere for a field (spec §1.1 proposal): centre = the centre of the mesh's
 * axis-aligned bounds, radius = (1 + 1e-4) * the largest vertex distance from it (and at least
 * 1e-30, for a mesh of one point). Returns HFVIS_ERR_INVALID_ARGUMENT for NULL, an invalid mesh
 * or one without vertices (outputs untouched). */
HFVIS_API hfvis_status hfvis_visfield_bounding_sphere(const hfvis_mesh *mesh, double center[3],
                                                      double *radius);

/* Options of hfvis_visfield_build. NULL or a zero struct = defaults. */
typedef struct hfvis_visfield_build_options {
    const hfvis_allocator *alloc;  /* for the BVH built internally; NULL = malloc/free */
    const hfvis_bvh *bvh;          /* a BVH of the same mesh to use (none is built then); NULL =
                                      build one (hfvis_bvh_build defaults) */
    hfvis_progress_fn progress;    /* called after each map with (done, K); NULL = none */
    void *progress_user;
} hfvis_visfield_build_options;

/* Build a visibility field ([G12] Alg. 1, spec §1.5): for every sample k, p_k = c + R u_k,
 * w = -u_k, and every texel (i, j) of the mapping (unused rejection texels get the miss code),
 * the ray hfvis_ray{origin = (float)p_k, direction = (float)(lx t + ly b + lz w), t_min = 0,
 * t_max = INFINITY, cull none} is cast with hfvis_bvh_closest_hit; a hit at t stores
 * th = t * |direction| (ray starts ON the sphere, a hit at 0 is kept), normalised by 2R, in
 * vf->format; its triangle's normal for the NORMAL format. avg_distance from the K central rays
 * (direction (float)w) likewise. Reads vf's parameters, writes vf->maps (whole) and
 * vf->avg_distance. opts may be NULL.
 * Returns HFVIS_OK; HFVIS_ERR_INVALID_ARGUMENT for NULL mesh or vf, an invalid mesh
 * (hfvis_mesh), invalid parameters (see hfvis_visfield, maps NULL), a vertex farther than
 * radius * (1 + 1e-6) from the centre, a supplied bvh whose triangle_count differs;
 * HFVIS_ERR_BUFFER_TOO_SMALL if maps_size < hfvis_visfield_size; the BVH build's errors
 * (HFVIS_ERR_LIMIT, HFVIS_ERR_OUT_OF_MEMORY). On error vf is untouched.
 * Memory: the BVH build's four blocks (two freed before it returns, two at the end); none with
 * opts->bvh. Cost O(K D^2 log T) rays (thesis: 4226 x 32^2 = 4.3 M rays). Deterministic. A
 * corrupt caller BVH is detected by the ray queries (HFVIS_ERR_INVALID_ARGUMENT) only once the
 * traversal meets it, possibly after maps were written. */
HFVIS_API hfvis_status hfvis_visfield_build(const hfvis_mesh *mesh,
                                            const hfvis_visfield_build_options *opts,
                                            hfvis_visfield *vf);

/* Oracle of hfvis_visfield_build: the same rays cast with hfvis_ray_closest_naive (every
 * triangle per ray). Same arguments (opts->bvh and alloc are ignored) and errors; equal maps
 * and avg_distance bit for bit. Allocates nothing. Cost O(K D^2 T). */
HFVIS_API hfvis_status hfvis_visfield_build_reference(const hfvis_mesh *mesh,
                                                      const hfvis_visfield_build_options *opts,
                                                      hfvis_visfield *vf);

/* Decode texel (i, j) of map k: *hit = 1 and *distance = th/(2R) as stored (U8: q/254, F32:
 * the float, BIT: avg_distance, NORMAL: byte 3 / 254), or *hit = 0 and *distance = 1 for a miss;
 * normal (may be NULL) receives the decoded unit normal of a NORMAL hit, else 0.
 * Returns HFVIS_ERR_INVALID_ARGUMENT for an invalid vf, k >= K, i or j out of range, NULL hit or
 * distance (outputs untouched). */
HFVIS_API hfvis_status hfvis_visfield_texel(const hfvis_visfield *vf, size_t k, int i, int j,
                                            int *hit, double *distance, double normal[3]);

/* ---- queries (Algorithms 2 and 3, spec §1.7) ------------------------------------------------ */

/* One ray against one field, in object space: origin o, direction d (any length > 0; t counts
 * along d/|d|). With oc = o - c, beta = oc.d, gamma = oc.oc - R^2, Delta = beta^2 - gamma:
 *  - gamma >= 0 (origin outside or on the sphere, Fig. 29): MISS if Delta <= 0 or the exit
 *    t1 = -beta + sqrt(Delta) <= 0; else the entry t0 = max(0, -beta - sqrt(Delta)), k = the
 *    nearest sample to the entry point, l = (d.t, d.b, d.w) in its frame; MISS if lz <= 0 or the
 *    texel is unused or stores a miss; else HIT at distance t0 + v 2R (v = the stored fraction).
 *  - gamma < 0 (inside, Fig. 31): the exit p1 at t1; k = nearest sample to p1; the REVERSED ray
 *    -d in k's frame; unoccluded (MISS) if lz <= 0, unused or a miss; else d2 = v 2R and the
 *    result is OCCLUDED at distance t1 - d2 when d2 < t1 - bias, MISS otherwise. The bias
 *    (object units, >= 0) is the thesis' missing tolerance (spec §1.7(b)): a receiver on the
 *    object's own surface sees its own surface at d2 ~ t1; use >= the 8-bit step 2R/254 plus the
 *    snapping error (HFVIS_VISFIELD_DEFAULT_BIAS * R is a reasonable start).
 * Exactly one map texel is read. out receives the result (see hfvis_visfield_hit).
 * Returns HFVIS_ERR_INVALID_ARGUMENT for an invalid vf, NULL or non-finite o or d, d = 0, bias
 * negative or not finite (out untouched). Allocates nothing. Cost O(1): one sphere test, 9
 * candidate samples, one inverse map, one load. */
HFVIS_API hfvis_status hfvis_visfield_query(const hfvis_visfield *vf, const double origin[3],
                                            const double direction[3], double bias,
                                            hfvis_visfield_hit *out);

/* Oracle: the same query with the map lookup replaced by exact ray casting against the mesh
 * (bvh, or hfvis_ray_closest_naive when bvh is NULL): outside, the ray from the entry point
 * along d (HIT at t0 + t); inside, the reversed ray from the exit point along -d (OCCLUDED at
 * t1 - t when t < t1 - bias). Rays are hfvis_ray in float (t_min 0, t_max INFINITY, no culling),
 * t converted to the unit direction as in the build; normal = the hit triangle's unit normal.
 * (With the mesh inside the sphere the outside answer is the exact first hit from the origin;
 * the inside one is exact for the decision, and its distance is that of the last crossing
 * before the exit, as the field's.) Only vf's sphere is used (maps may be NULL).
 * Returns the errors of hfvis_visfield_query (vf's parameters without maps), plus NULL mesh,
 * and the errors of the ray query (a bvh not of this mesh). */
HFVIS_API hfvis_status hfvis_visfield_query_reference(const hfvis_visfield *vf,
                                                      const hfvis_mesh *mesh,
                                                      const hfvis_bvh *bvh,
                                                      const double origin[3],
                                                      const double direction[3], double bias,
                                                      hfvis_visfield_hit *out);

/* One object of a scene: a field placed by a rigid transform (with uniform scale). The fast
 * routines read field; the reference routines read field's sphere and cast rays against mesh
 * (through bvh if not NULL, else naively). */
typedef struct hfvis_visfield_object {
    const hfvis_visfield *field;
    const hfvis_mesh *mesh;        /* object-space mesh the field was built from (reference) */
    const hfvis_bvh *bvh;          /* its BVH or NULL (reference) */
    double object_to_world[16];    /* column-major; [s Q | T] with Q orthogonal (rows and columns
                                      orthonormal within 1e-6 relative), s > 0, last row
                                      (0, 0, 0, 1) exactly */
} hfvis_visfield_object;

/* How several objects combine in ambient occlusion. */
typedef enum hfvis_visfield_combine {
    HFVIS_VISFIELD_COMBINE_DEFAULT = 0,     /* = ANY */
    HFVIS_VISFIELD_COMBINE_ANY = 1,         /* a ray is blocked when any object blocks it (the
                                               physically consistent rule; spec §1.7(c) [C]) */
    HFVIS_VISFIELD_COMBINE_SUBTRACTIVE = 2  /* the thesis' GPU passes with reverse-subtract
                                               blending: obscurance = min(1, sum over objects),
                                               a ray blocked twice counts twice */
} hfvis_visfield_combine;

/* What a blocking distance contributes to obscurance ([G12] leaves V(distance) open). */
typedef enum hfvis_visfield_falloff {
    HFVIS_VISFIELD_FALLOFF_DEFAULT = 0,     /* = BINARY */
    HFVIS_VISFIELD_FALLOFF_BINARY = 1,      /* 1 if blocked within max_distance */
    HFVIS_VISFIELD_FALLOFF_LINEAR = 2       /* 1 - distance/max_distance (needs max_distance) */
} hfvis_visfield_falloff;

/* Options of the ambient-occlusion routines. NULL or a zero struct = defaults. */
typedef struct hfvis_visfield_ao_options {
    int rays_sqrt;                  /* S: S x S rays per point; 0 = 16 (256 rays, the thesis' CPU
                                       count); 1..HFVIS_VISFIELD_MAX_RAYS_SQRT */
    double max_distance;            /* world units; 0 or +INFINITY = unlimited (default) */
    hfvis_visfield_falloff falloff; /* default binary */
    hfvis_visfield_combine combine; /* default ANY */
    double bias;                    /* inside-query bias as a fraction of each object's radius
                                       (scaled to world by s); 0 = HFVIS_VISFIELD_DEFAULT_BIAS */
    double offset;                  /* ray origins x + offset n, world units >= 0; default 0 */
    const hfvis_allocator *alloc;   /* scratch; NULL = malloc/free */
} hfvis_visfield_ao_options;

HFVIS_API hfvis_visfield_ao_options hfvis_visfield_ao_options_default(void);

/* Ambient obscurance of receiver points from visibility fields ([G12] Alg. 2/3, spec §1.7(c)):
 * per point x with unit normal n (renormalised here), the S x S rays l = concentric((2i+1)/S - 1,
 * (2j+1)/S - 1) lifted by Malley (cosine distributed, as the thesis' pre-generated ray set) in
 * the frame hfvis_visfield_frame(n), direction lx t + ly b + lz n, from x + offset n; each object
 * answers hfvis_visfield_query in its object space with bias = opts->bias * R. A HIT or
 * OCCLUDED at world distance s*distance <= max_distance blocks the ray with weight 1 (binary)
 * or 1 - distance/max_distance (linear); ANY takes the largest weight over the objects (the
 * nearest blocker), SUBTRACTIVE their sum. out[p] = min(1, (1/S^2) sum over rays) is the
 * obscurance (DESIGN: 0 = open, 1 = fully blocked; the thesis prints 1 - this). Because the rays
 * are cosine distributed this estimates (1/pi) Int (1 - V) cos.
 * points, normals: 3 floats per point; out: point_count floats (must not overlap them).
 * Returns HFVIS_ERR_INVALID_ARGUMENT for NULL objects with object_count > 0, an invalid field
 * or transform, NULL points/normals/out with point_count > 0, a non-finite point or normal, a
 * zero normal, bad options (S out of range, negative or NaN max_distance, bias or offset, linear
 * falloff without a finite max_distance, unknown enums); HFVIS_ERR_OUT_OF_MEMORY (out
 * untouched). Memory: 2 scratch blocks (the ray set, 24 S^2 bytes, and the object transforms).
 * Cost O(points S^2 objects). */
HFVIS_API hfvis_status hfvis_visfield_ambient_occlusion(const hfvis_visfield_object *objects,
                                                        size_t object_count, const float *points,
                                                        const float *normals, size_t point_count,
                                                        const hfvis_visfield_ao_options *opts,
                                                        float *out);

/* Oracle: the same rays and rules with hfvis_visfield_query_reference (exact ray casting
 * against each object's mesh) instead of the maps. Errors as above plus a NULL mesh, a bvh
 * whose triangle_count differs, an invalid mesh. Memory: 3 scratch blocks (out is written
 * only on success). */
HFVIS_API hfvis_status hfvis_visfield_ambient_occlusion_reference(
    const hfvis_visfield_object *objects, size_t object_count, const float *points,
    const float *normals, size_t point_count, const hfvis_visfield_ao_options *opts, float *out);

/* Options of the soft-shadow routines. NULL or a zero struct = defaults. */
typedef struct hfvis_visfield_shadow_options {
    int samples;                    /* light samples per point, 1..HFVIS_VISFIELD_MAX_SAMPLES;
                                       0 = 20 (the thesis' shadow rays per pixel) */
    double bias;                    /* as hfvis_visfield_ao_options.bias */
    const hfvis_allocator *alloc;   /* scratch; NULL = malloc/free */
} hfvis_visfield_shadow_options;

/* Visibility of a spherical light (centre, radius >= 0; 0 = a point light, hard shadows) from
 * points ([G12] §4.5.2, spec §1.7(d)): per point x, `samples` points y_i on the disc of the light
 * facing x (centre + radius (dx e1 + dy e2), (dx, dy) = the concentric map of the Hammersley
 * point ((i + 0.5)/N, radical inverse of i in base 2), (e1, e2) = the frame of the unit vector
 * from x to the centre); the shadow ray x -> y_i of length L is blocked when some object
 * returns HIT or OCCLUDED at world distance < L. out[p] = fraction of unblocked rays, in [0, 1]
 * (1 = fully lit; multiply by the cosine term yourself). A point inside the light's disc
 * distance (L = 0) counts as lit.
 * Returns HFVIS_ERR_INVALID_ARGUMENT as the AO routine (light NULL/non-finite, radius < 0 or
 * not finite, samples out of range); HFVIS_ERR_OUT_OF_MEMORY. Memory: 2 scratch blocks. */
HFVIS_API hfvis_status hfvis_visfield_soft_shadow(const hfvis_visfield_object *objects,
                                                  size_t object_count, const float *points,
                                                  size_t point_count,
                                                  const double light_center[3],
                                                  double light_radius,
                                                  const hfvis_visfield_shadow_options *opts,
                                                  float *out);

/* Oracle of hfvis_visfield_soft_shadow: the same rays against the meshes (reference queries).
 * Memory: 3 scratch blocks (out written only on success). */
HFVIS_API hfvis_status hfvis_visfield_soft_shadow_reference(
    const hfvis_visfield_object *objects, size_t object_count, const float *points,
    size_t point_count, const double light_center[3], double light_radius,
    const hfvis_visfield_shadow_options *opts, float *out);

/* The nearest object a world ray meets, through the fields (secondary rays of [G12] §4.5.2). */
typedef struct hfvis_visfield_trace_hit {
    size_t object;                  /* index into objects; HFVIS_VISFIELD_NONE on a miss */
    hfvis_visfield_result result;   /* HIT or OCCLUDED (origin inside that object's sphere) */
    double distance;                /* world distance along the unit direction; INFINITY on a
                                       miss */
    double point[3];                /* world hit point origin + distance * direction */
    double normal[3];               /* world unit normal from a NORMAL field (or the reference),
                                       else 0 */
} hfvis_visfield_trace_hit;

/* Trace one world ray: every object is queried (bias = bias_fraction * R, 0 = the default
 * fraction) and the smallest world distance wins (ties: lowest object index). Returns
 * HFVIS_ERR_INVALID_ARGUMENT for invalid objects, NULL, non-finite or zero direction, a negative
 * or non-finite bias_fraction (hit untouched). Allocates nothing. */
HFVIS_API hfvis_status hfvis_visfield_trace(const hfvis_visfield_object *objects,
                                            size_t object_count, const double origin[3],
                                            const double direction[3], double bias_fraction,
                                            hfvis_visfield_trace_hit *hit);

/* Oracle of hfvis_visfield_trace (reference queries against the meshes). */
HFVIS_API hfvis_status hfvis_visfield_trace_reference(const hfvis_visfield_object *objects,
                                                      size_t object_count,
                                                      const double origin[3],
                                                      const double direction[3],
                                                      double bias_fraction,
                                                      hfvis_visfield_trace_hit *hit);

/* Options of the reflection routines. NULL or a zero struct = defaults. */
typedef struct hfvis_visfield_reflect_options {
    int rays;             /* rays per point, 1..HFVIS_VISFIELD_MAX_SAMPLES; 0 = 4 (the thesis'
                             rays per reflective pixel) */
    double shininess;     /* Phong exponent of the glossy lobe about the mirror direction, > 0;
                             0 (default) = a perfect mirror (every ray the mirror direction) */
    double bias;          /* as hfvis_visfield_ao_options.bias */
    double offset;        /* ray origin x + offset n, world units >= 0 */
} hfvis_visfield_reflect_options;

/* Reflection rays of one receiver ([G12] §4.5.2 "polished" stochastic reflections): mirror
 * direction r = v - 2 (v.n) n of the incoming direction v (toward the surface) about the unit
 * normal n; ray i has cos(angle to r) = u_i^(1/(shininess+1)) and azimuth 2 pi v_i about r in
 * the frame of r, (u_i, v_i) = the Hammersley point ((i + 0.5)/N, radical inverse of i) (the
 * mirror direction itself without shininess); each is traced (hfvis_visfield_trace). A ray
 * below the surface (direction . n <= 0) is not traced and gets a miss. hits: opts->rays entries.
 * Returns HFVIS_ERR_INVALID_ARGUMENT for invalid objects, NULL or non-finite vectors, zero n or
 * v, bad options (hits untouched). Allocates nothing. */
HFVIS_API hfvis_status hfvis_visfield_reflect(const hfvis_visfield_object *objects,
                                              size_t object_count, const double point[3],
                                              const double normal[3], const double incoming[3],
                                              const hfvis_visfield_reflect_options *opts,
                                              hfvis_visfield_trace_hit *hits);

/* Oracle of hfvis_visfield_reflect: the same rays, hfvis_visfield_trace_reference. */
HFVIS_API hfvis_status hfvis_visfield_reflect_reference(const hfvis_visfield_object *objects,
                                                        size_t object_count,
                                                        const double point[3],
                                                        const double normal[3],
                                                        const double incoming[3],
                                                        const hfvis_visfield_reflect_options *opts,
                                                        hfvis_visfield_trace_hit *hits);

/* ---- the field file (.hfvf) --------------------------------------------------------------- */

/* A field file is a header of HFVIS_VISFIELD_FILE_HEADER = 80 bytes followed by the maps,
 * every number little-endian:
 *    offset  bytes  field
 *      0      8     magic "HFVFIELD"
 *      8      4     version, uint32 = 1
 *     12      4     format, uint32: 1 U8, 2 F32, 3 BIT, 4 NORMAL (hfvis_visfield_format)
 *     16      4     mapping, uint32: 1 polar, 2 rejection, 3 concentric (hfvis_dirmap)
 *     20      4     positions_n, uint32, 1..HFVIS_VISFIELD_MAX_N
 *     24      4     dir_res, uint32, 1..HFVIS_VISFIELD_MAX_DIR_RES
 *     28      4     reserved, uint32 = 0
 *     32     24     center, 3 x IEEE-754 binary64
 *     56      8     radius, binary64, finite > 0
 *     64      8     avg_distance, binary64 in [0, 1]
 *     72      8     payload bytes, uint64 = hfvis_visfield_size(n, D, format)
 *     80      -     the maps as in memory (F32 texels as little-endian binary32)
 * and nothing after the payload. */

/* Exact bytes hfvis_visfield_encode writes (80 + the maps); 0 for an invalid vf or overflow. */
HFVIS_API size_t hfvis_visfield_encode_size(const hfvis_visfield *vf);

/* Encode vf (the default enums written as their explicit values). out must hold
 * hfvis_visfield_encode_size bytes (out_capacity); *written receives the count (may be NULL).
 * Returns HFVIS_ERR_INVALID_ARGUMENT for NULL or an invalid vf, HFVIS_ERR_BUFFER_TOO_SMALL (out
 * untouched). Allocates nothing. */
HFVIS_API hfvis_status hfvis_visfield_encode(const hfvis_visfield *vf, void *out,
                                             size_t out_capacity, size_t *written);

/* Decode a field file held in memory into *out, its maps in one block from alloc (NULL =
 * malloc; release with hfvis_visfield_free(alloc, out)). Strict: HFVIS_ERR_FORMAT for a size
 * below 80, a wrong magic, version, reserved word or enum value, n or D of 0, a payload size
 * that differs from the computed one or from the bytes present (truncated or trailing data), a
 * non-finite centre, a radius not finite and > 0, avg_distance outside [0, 1], and payload
 * contents a build cannot produce: F32 values other than [0, 1) or exactly 1, unused rejection
 * texels without the miss code, NORMAL misses whose normal bytes are not 0, set padding bits;
 * HFVIS_ERR_LIMIT for n > HFVIS_VISFIELD_MAX_N, D > HFVIS_VISFIELD_MAX_DIR_RES or a payload above
 * HFVIS_VISFIELD_MAX_BYTES or SIZE_MAX (decided from the header, before the data size is
 * compared); HFVIS_ERR_INVALID_ARGUMENT for NULL out or NULL data with size > 0;
 * HFVIS_ERR_OUT_OF_MEMORY. Every size is overflow-checked. On error *out is untouched.
 * One allocation. Cost O(size). */
HFVIS_API hfvis_status hfvis_visfield_decode(const void *data, size_t size,
                                             const hfvis_allocator *alloc, hfvis_visfield *out);

/* Release the maps of a decoded / loaded field with the allocator it was decoded with and zero
 * the struct. vf may be NULL. (Never call it on a field whose maps the caller owns.) */
HFVIS_API void hfvis_visfield_free(const hfvis_allocator *alloc, hfvis_visfield *vf);

/* File wrappers (absent with HFVIS_NO_STDIO): save encodes into a malloc'ed buffer and writes it
 * atomically (temporary file renamed onto path); load reads the whole file with alloc and
 * decodes it (two allocations, the file buffer freed before returning). Errors of the codec,
 * HFVIS_ERR_IO, HFVIS_ERR_OUT_OF_MEMORY. */
HFVIS_API hfvis_status hfvis_visfield_save(const char *path, const hfvis_visfield *vf);
HFVIS_API hfvis_status hfvis_visfield_load(const char *path, const hfvis_allocator *alloc,
                                           hfvis_visfield *out);
