
/* ========================================================================================== */
/* voxel.c - incremental image-based voxelization (thesis ch. 7, spec voxel §4)                */
/* ========================================================================================== */

/* Incremental voxelization (IV, Gaitatzes 2012 ch. 7) keeps last frame's Volume Buffer and
 * updates it from depth images: a cleanup phase (Alg. 7, Listing 7.1, eq. 17) empties every
 * voxel whose centre is seen in front of the recorded depth by more than a bias b, an injection
 * phase (Listing 7.2) unprojects every depth pixel to world space and writes its attributes
 * into the voxel it falls in. Over many views the volume converges to the voxels of everything
 * ever seen; a stale voxel disappears when some view sees through it.
 *
 * Conventions of this section.
 * - Depth images are GL window depths zw in [0, 1] of a hfvis_view (row 0 at the TOP, pixel
 *   (x, y) at depth[y*width + x], as hfvis_rasterize writes them). zw = 1 is background (nothing
 *   seen up to the far plane). A value that is NaN or outside [0, 1] is no-data: that pixel
 *   neither clears, turns on nor injects anything.
 * - eq. 16 with its sign restored (hfvis_depth_to_eye_z) turns zw into the eye-space z_e of the
 *   surface; a point's eye z is p'_z = row 2 of view applied to p (negative in front).
 * - A voxel is EMPTY when all its channels are 0 (what cleanup leaves, the cleared state of a
 *   volume). An occupancy channel (default channel 0) receives 1 for every injected or
 *   turned-on voxel, so that a voxel with all-zero attributes (black albedo) is not empty.
 * - Cleanup and single pass read `prev` and write `curr` (the thesis' ping-pong); curr may be
 *   prev (in place) or its data may be a different, NON-overlapping array. The two must have
 *   equal grids (origin, cell, dims) and channel counts.
 * - All geometry is in double; the decisions are exactly those of hfvis_iv_classify_voxel (the
 *   per-voxel oracle) bit for bit. No function keeps a pointer after returning. */

/* One depth image with its view and optional per-pixel attributes (a camera G-buffer or a light's
 * reflective shadow map). attributes: width*height*attribute_count floats, interleaved per pixel
 * (attributes[(y*width + x)*attribute_count + a]), or NULL when attribute_count is 0.
 * Valid when depth is not NULL, view.width, view.height >= 1, the matrices are finite, the
 * planes are finite with 0 < near_plane < far_plane (perspective) or near_plane < far_plane
 * (orthographic), and 0 <= attribute_count <= HFVIS_VOLUME_MAX_CHANNELS. */
typedef struct hfvis_depth_image {
    hfvis_view view;
    const float *depth;
    const float *attributes;
    int attribute_count;
} hfvis_depth_image;

/* Where a voxel centre lies against one depth image (thesis Fig. 70, spec voxel §4.3). */
typedef enum hfvis_iv_class {
    HFVIS_IV_UNSEEN = 0,  /* no information: behind the camera, nearer than the near plane,
                             outside the image (|ndc x| or |ndc y| > 1) or a no-data pixel; kept */
    HFVIS_IV_CLEARED = 1, /* p'_z > z_e + b (eq. 17): in front of the surface, turned off (v1) */
    HFVIS_IV_BAND = 2,    /* z_e - b <= p'_z <= z_e + b: in the surface band, "must be updated"
                             (v2); never for a background pixel (zw = 1) */
    HFVIS_IV_KEPT = 3     /* p'_z < z_e - b (behind the surface, v3), or within b of the far
                             plane of a background pixel; kept */
} hfvis_iv_class;

/* The bias b of eq. 17. */
typedef enum hfvis_iv_bias_rule {
    HFVIS_IV_BIAS_HALF_DIAGONAL = 0, /* default: b = |cell|/2, the voxel's "radius (half
                                        diagonal)" of the text (§7.4.1); (sqrt 3/2) s for cubes */
    HFVIS_IV_BIAS_FULL_DIAGONAL = 1, /* b = |cell|: Listing 7.1 (distance between the eye-space
                                        images of p + h and p - h, h = half the voxel size) */
    HFVIS_IV_BIAS_EXPLICIT = 2       /* b = options.bias (finite, >= 0) */
} hfvis_iv_bias_rule;

/* Which depth texels decide a clear. */
typedef enum hfvis_iv_footprint {
    HFVIS_IV_FOOTPRINT_CENTER = 0,      /* default, the thesis (Listing 7.1): the one texel under
                                           the voxel centre (nearest, floor of the window
                                           coordinate, clamped to the image) */
    HFVIS_IV_FOOTPRINT_CONSERVATIVE = 1 /* clear only if the centre texel clears AND every pixel
                                           whose centre lies in the bounding box of the voxel's 8
                                           projected corners clears (corners before the near plane:
                                           never cleared). Since b >= the eye-z extent of the
                                           voxel about its centre, a voxel containing a surface
                                           point that lies on any pixel-centre ray is then never
                                           cleared (the first hit on that ray is not farther than
                                           the point). Needs b >= the half diagonal. So static
                                           geometry's voxels are not lost at silhouettes, as they
                                           are with the centre rule, and the set converges
                                           monotonically up to "slivers": a voxel whose surface
                                           part no pixel ray of a view meets can still be cleared
                                           by that view (and re-injected by another). Costs a
                                           pyramid (see hfvis_iv_cleanup) and a footprint scan per
                                           vetoed clear. */
} hfvis_iv_footprint;

#define HFVIS_IV_NO_CHANNEL (-1)

/* Options of every hfvis_iv_* routine (zero = defaults). */
typedef struct hfvis_iv_options {
    hfvis_iv_bias_rule bias_rule;     /* default HFVIS_IV_BIAS_HALF_DIAGONAL */
    double bias;                      /* world units, only with HFVIS_IV_BIAS_EXPLICIT */
    hfvis_iv_footprint footprint;     /* default HFVIS_IV_FOOTPRINT_CENTER */
    int occupancy_channel;            /* channel set to 1 by injection / turn-on (through its
                                         blend in injection); default 0; HFVIS_IV_NO_CHANNEL for
                                         none */
    const int *attribute_channels;    /* attribute a of an image goes to channel
                                         attribute_channels[a] (HFVIS_IV_NO_CHANNEL = dropped);
                                         must hold attribute_count entries for every image, no
                                         two equal, none equal to the occupancy channel. NULL:
                                         attributes fill the channels other than the occupancy
                                         channel in increasing order (default: a -> a + 1) */
    int grid_width, grid_height;      /* injection point grid (Listing 7.2); 0 = the image's
                                         width / height (one point per pixel centre) */
    const hfvis_allocator *alloc;     /* scratch; NULL = malloc/free */
} hfvis_iv_options;

HFVIS_API hfvis_iv_options hfvis_iv_options_default(void);

/* What a call did. Counts are written (not accumulated) on success; untouched on error. */
typedef struct hfvis_iv_stats {
    size_t cleared, band, kept, unseen; /* classifications performed, summed over images: cleanup
                                           classifies the voxels non-empty at that moment, single
                                           pass every voxel */
    size_t turned_off;                  /* clears of non-empty voxels (per image; with one image:
                                           the voxels non-empty before and empty after) */
    size_t turned_on;                   /* single pass: turn-ons of empty voxels (per image) */
    size_t points_injected;             /* injection points written into a voxel */
    size_t points_background;           /* points on background (zw = 1) or no-data pixels */
    size_t points_outside;              /* points whose world position lies outside the grid */
} hfvis_iv_stats;

/* Detail of one classification, for diffing a GPU port. */
typedef struct hfvis_iv_sample {
    hfvis_iv_class cls;
    int pixel_x, pixel_y;   /* the depth texel read (-1, -1 if none) */
    double eye_z;           /* p'_z of the point (or voxel centre) */
    double depth_eye_z;     /* z_e of that texel by eq. 16; NaN if none */
} hfvis_iv_sample;

/* The default bias: half the voxel diagonal, 0.5*sqrt(cx^2 + cy^2 + cz^2). NaN for a NULL or
 * invalid grid (which every routine then rejects). The Listing 7.1 bias is twice this. */
HFVIS_API double hfvis_iv_bias_half_diagonal(const hfvis_volume_grid *grid);

/* The bias b that opts selects for grid (rule as hfvis_iv_options). HFVIS_ERR_INVALID_ARGUMENT
 * for NULL grid/out, an invalid grid, an unknown rule, or an explicit bias that is negative or
 * not finite. */
HFVIS_API hfvis_status hfvis_iv_bias(const hfvis_volume_grid *grid, const hfvis_iv_options *opts,
                                     double *out);

/* Classify a world point against one depth image with bias b (spec voxel §4.3): project with
 * proj*view; UNSEEN if clip w <= 0, p'_z > -near_plane, |ndc x| > 1 or |ndc y| > 1 (ndc =
 * clip.xy * (1/clip.w)); texel (floor((ndc_x+1)/2*W), floor((1-ndc_y)/2*H)) clamped to W-1, H-1;
 * UNSEEN for a no-data texel; then CLEARED / BAND / KEPT by eq. 17 in eye space, in double,
 * exactly as the literal comparisons p'_z > z_e + b and p'_z < z_e - b decide them (for
 * perspective views a division-free test with a rounding margin settles all but near-ties,
 * which fall back to the literal form). The affine rows are evaluated as
 * ((m[12+r] + m[8+r] z) + m[4+r] y) + m[r] x, the order hfvis_iv_cleanup uses. out gets the class,
 * the texel, p'_z and the texel's z_e.
 * Returns HFVIS_ERR_INVALID_ARGUMENT for NULL, an invalid image (see hfvis_depth_image), a
 * non-finite point, or a negative or non-finite bias. No allocation. */
HFVIS_API hfvis_status hfvis_iv_classify(const hfvis_depth_image *image, const double point[3],
                                         double bias, hfvis_iv_sample *out);

/* Oracle: the decision hfvis_iv_cleanup and hfvis_iv_single_pass take for voxel (i, j, k) of grid
 * under opts (bias rule and footprint), computed directly (the conservative footprint by
 * scanning every pixel of the box). Centre = origin + cell*(index + 0.5). With the centre
 * footprint this is hfvis_iv_classify of the centre. With the conservative one a centre CLEARED
 * that some footprint pixel (or a corner before the near plane) vetoes becomes KEPT.
 * Returns HFVIS_ERR_INVALID_ARGUMENT for NULL, an invalid grid or image, a voxel outside the
 * grid, or bad options. No allocation. */
HFVIS_API hfvis_status hfvis_iv_classify_voxel(const hfvis_depth_image *image,
                                               const hfvis_volume_grid *grid, int i, int j, int k,
                                               const hfvis_iv_options *opts,
                                               hfvis_iv_sample *out);

/* Cleanup phase (Alg. 7 "Cleanup", Listing 7.1, eq. 17): for every image in order and every voxel
 * of prev non-empty at that moment, CLEARED sets all channels of curr to 0, any other class copies
 * prev's values (the decision is hfvis_iv_classify_voxel's). Empty voxels stay empty and are not
 * classified (on the GPU every voxel is; the result is the same), so the cost over a surface
 * volume is mostly one pass over memory. Sequential images are equivalent to the thesis'
 * per-image ping-pong. image_count may be 0 (a copy). stats may be NULL.
 * Errors: HFVIS_ERR_INVALID_ARGUMENT for NULL prev/curr/data, images NULL with image_count > 0,
 * an invalid image, unequal grids or channel counts, bad options; HFVIS_ERR_OUT_OF_MEMORY.
 * Allocates nothing with the centre footprint; with the conservative one 1 block of about
 * 4*W*H/3 bytes per image (a min-depth pyramid that accepts most clears without a scan).
 * Cost O(voxels*images) plus, conservative, the footprint scans of vetoed clears. */
HFVIS_API hfvis_status hfvis_iv_cleanup(const hfvis_volume *prev, hfvis_volume *curr,
                                        const hfvis_depth_image *images, size_t image_count,
                                        const hfvis_iv_options *opts, hfvis_iv_stats *stats);

/* Injection phase (Listing 7.2): for every image in order, a grid_width x grid_height grid of
 * points in raster order (top row first), point (gx, gy) at u = (gx + 0.5)/Gx, v = (gy + 0.5)/Gy
 * from the top-left corner, reads the texel (floor(u W), floor(v H)); background (zw = 1) and
 * no-data texels are skipped; otherwise the point (2u - 1, 1 - 2v, 2 zw - 1) in NDC is
 * unprojected with (proj*view)^-1 and, if it lies in the grid (voxel floor((p - origin)/cell)),
 * its attributes are written to their channels and 1 to the occupancy channel, each through the
 * channel's blend (MAX, REPLACE = last point in raster order wins, MIN, ADD: sum; ADD on the
 * occupancy channel counts the points, for an average). Other channels are untouched.
 * Errors: HFVIS_ERR_INVALID_ARGUMENT for NULL vol/data, images NULL with image_count > 0, an
 * invalid image, a singular proj*view, bad options (channel map, negative grid size). No
 * allocation. Cost O(points) (independent of the volume size). */
HFVIS_API hfvis_status hfvis_iv_inject(hfvis_volume *vol, const hfvis_depth_image *images,
                                       size_t image_count, const hfvis_iv_options *opts,
                                       hfvis_iv_stats *stats);

/* One IV frame, Algorithm 7: hfvis_iv_cleanup(prev -> curr, all images), then hfvis_iv_inject
 * (curr, all images). Statistics of both. Errors and allocation as those two; on error curr is
 * untouched (every argument is checked before anything is written). */
HFVIS_API hfvis_status hfvis_iv_update(const hfvis_volume *prev, hfvis_volume *curr,
                                       const hfvis_depth_image *images, size_t image_count,
                                       const hfvis_iv_options *opts, hfvis_iv_stats *stats);

/* Single-pass ("optimised") IV (§7.4.3, spec voxel §4.5): no injection; for every voxel and every
 * image in order: CLEARED empties it, BAND turns it on / updates it: occupancy channel = 1 and
 * the mapped channels = the attributes of the centre texel, written as they are (REPLACE, like
 * the thesis' shader output; the blends are not used), KEPT and UNSEEN keep it. A voxel cleared
 * by one image can be turned on by a later one. Samples geometry at volume resolution; several
 * voxels along one pixel ray can be in the band (2b >= one voxel). Errors and allocation as
 * hfvis_iv_cleanup. Cost O(voxels*images). */
HFVIS_API hfvis_status hfvis_iv_single_pass(const hfvis_volume *prev, hfvis_volume *curr,
                                            const hfvis_depth_image *images, size_t image_count,
                                            const hfvis_iv_options *opts, hfvis_iv_stats *stats);

/* IV for lighting (§7.5, spec voxel §4.6): after cleanup of the attribute volume, every NON-EMPTY
 * voxel of the separate injection volume (cleared every frame, VPLs injected with ADD, camera
 * samples with REPLACE) replaces the corresponding values of curr: channels[0..channel_count)
 * (NULL = every channel). Non-empty: the occupancy channel of opts is non-zero, or with
 * HFVIS_IV_NO_CHANNEL any channel is non-zero. replaced (may be NULL) gets the number of voxels.
 * Errors: HFVIS_ERR_INVALID_ARGUMENT for NULL, unequal grids or channel counts, a channel out of
 * range or listed twice, channel_count outside 1..channels with a list. No allocation. */
HFVIS_API hfvis_status hfvis_iv_replace_nonempty(hfvis_volume *curr,
                                                 const hfvis_volume *injection,
                                                 const int *channels, int channel_count,
                                                 const hfvis_iv_options *opts, size_t *replaced);

/* The voxel set of a volume as bytes (for hfvis_voxel_distance_metrics): out[v] = 1 where
 * channel `channel` of voxel v is non-zero (HFVIS_IV_NO_CHANNEL: any channel), else 0. out holds
 * dims[0]*dims[1]*dims[2] bytes. count (may be NULL) gets the number of 1s.
 * HFVIS_ERR_INVALID_ARGUMENT for NULL vol/data/out, an invalid grid or channel. */
HFVIS_API hfvis_status hfvis_iv_occupancy(const hfvis_volume *vol, int channel, uint8_t *out,
                                          size_t *count);

/* Exact Euclidean distance from p to the triangle (a, b, c), all in double (closest point by
 * Voronoi regions of the triangle, Ericson 2005 §5.1.5; a degenerate triangle is its segments).
 * NaN if a pointer is NULL. */
HFVIS_API double hfvis_point_triangle_distance(const double p[3], const double a[3],
                                               const double b[3], const double c[3]);

/* Options of the Table 9 metric. */
typedef struct hfvis_distance_options {
    size_t sample_count;            /* area-uniform samples of the mesh for d(X, Y); 0 = 100000 */
    uint64_t seed;                  /* sampling seed (0 is a valid seed and the default) */
    const hfvis_allocator *alloc;   /* scratch; NULL = malloc/free */
} hfvis_distance_options;

/* Distances between a mesh X and a voxel set Y (its voxel centres), thesis Table 9 (spec voxel
 * §4.8): Y -> X exactly (every centre's distance to the nearest triangle, point-triangle in
 * double); X -> Y over seeded area-uniform samples of X (a lower bound of the true sup).
 * Table 9 reports the "average Hausdorff distance" normalised by the mesh bounding-box diagonal,
 * in percent; the thesis leaves "average" open, hfvis reports both directed means and maxima:
 * table9_percent = 100 * max(mean Y->X, mean X->Y) / diagonal [C]. */
typedef struct hfvis_distance_metrics {
    double mean_voxel_to_mesh, max_voxel_to_mesh;  /* over voxel centres */
    double mean_mesh_to_voxel, max_mesh_to_voxel;  /* over mesh samples */
    double hausdorff;        /* max of the two maxima: d_H(X, Y) = max(d(X, Y), d(Y, X)) */
    double table9_percent;   /* 100 * max of the two means / diagonal */
    double diagonal;         /* mesh bounding-box diagonal */
    size_t voxel_count, sample_count;
} hfvis_distance_metrics;

/* Table 9 metric of the voxels v with occupancy[v] != 0 on grid (dims[0]*dims[1]*dims[2] bytes,
 * as hfvis_voxelize_occupancy or hfvis_iv_occupancy write them) against mesh. Zero-area triangles
 * are ignored (never sampled, never nearest). Accelerated by two bounding-volume hierarchies
 * (triangles, voxel centres) with exact pruning: equal bit for bit to
 * hfvis_voxel_distance_metrics_naive. Errors: HFVIS_ERR_INVALID_ARGUMENT for NULL, an invalid
 * mesh or grid, a mesh without positive-area triangles, an empty voxel set; HFVIS_ERR_LIMIT past
 * 2^31 triangles or voxels; HFVIS_ERR_OUT_OF_MEMORY. Allocates 6 blocks (O(T + voxels + sample_count)). Cost about
 * O((voxels + samples) log). */
HFVIS_API hfvis_status hfvis_voxel_distance_metrics(const hfvis_mesh *mesh,
                                                    const hfvis_volume_grid *grid,
                                                    const uint8_t *occupancy,
                                                    const hfvis_distance_options *opts,
                                                    hfvis_distance_metrics *out);

/* Oracle: the same metric by brute force (every centre against every triangle, every sample
 * against every centre) on the same samples. O(voxels*T + samples*voxels). Allocates 3 blocks. */
HFVIS_API hfvis_status hfvis_voxel_distance_metrics_naive(const hfvis_mesh *mesh,
                                                          const hfvis_volume_grid *grid,
                                                          const uint8_t *occupancy,
                                                          const hfvis_distance_options *opts,
                                                          hfvis_distance_metrics *out);
