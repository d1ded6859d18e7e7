
/* ---- P4 far-field ambient obscurance (FFAO; [P4], spec §5) --------------------------------- */

/* How the slab integral L(a, b, c, d) of [P4] Eq. 3 is evaluated (spec §5.2). */
typedef enum hfvis_ffao_estimator {
    HFVIS_FFAO_L_DEFAULT = 0,      /* CLOSED_FORM for falloff NONE, else TABLE (the options'
                                      table, or one built per call with the default sizes) */
    HFVIS_FFAO_L_QUADRATURE = 1,   /* Gauss-Legendre with quad_nodes nodes (the reference) */
    HFVIS_FFAO_L_TABLE = 2,        /* the tabulated L (the paper's 3D texture, here 4D) */
    HFVIS_FFAO_L_CLOSED_FORM = 3   /* F(t) = t sin(d)/2 - cos(2t - d)/4: falloff NONE only */
} hfvis_ffao_estimator;

/* Sector averaging of the virtual points (spec §5.6). */
typedef enum hfvis_ffao_averaging {
    HFVIS_FFAO_AVERAGE_DEFAULT = 0, /* ON for thickness 0 (continuous depth), else OFF */
    HFVIS_FFAO_AVERAGE_ON = 1,      /* mean of (m0, m1) over the lines inside the segment */
    HFVIS_FFAO_AVERAGE_OFF = 2      /* the single line through the segment's middle */
} hfvis_ffao_averaging;

/* The near field (spec §5.8): what covers the first 1-2 intervals ahead of a receiver. */
typedef enum hfvis_ffao_near {
    HFVIS_FFAO_NEAR_DEFAULT = 0,   /* = DIRECT */
    HFVIS_FFAO_NEAR_NONE = 1,      /* far field only ([P4] Fig. 1 "far field >= 15 px") */
    HFVIS_FFAO_NEAR_DIRECT = 2     /* an HBAO-style march at 1 px steps along +D from the
                                      receiver up to the first far interval, every sample a slab
                                      point of the same estimator; its horizon is handed on */
} hfvis_ffao_near;

/* A tabulated L(a, b, c, d) (spec §5.2 [R]): na x nb x nc x nd floats over a in [0, pi],
 * u = b/(b + b_ref) in [0, 1], c in [pi/2, pi], d in [-pi/2, pi/2], each on a uniform grid
 * including the ends; L(a) = Int_{max(a, d - pi/2, 0)}^{min(c, d + pi/2, pi)} rho(b/sin(c - t))
 * cos(t - d) sin t dt, accumulated from a = pi down with 8-node Gauss-Legendre per a-cell.
 * Lookups interpolate linearly in all four (the paper takes d from the nearest value). */
typedef struct hfvis_ffao_table {
    int na, nb, nc, nd;
    double b_ref;
    float *values;                 /* [((id nc + ic) nb + ib) na + ia] */
    const hfvis_allocator *alloc;  /* the allocator that owns values */
} hfvis_ffao_table;

/* Options of hfvis_ffao and hfvis_ssao_mipmap. NULL or a zero struct = the defaults in
 * brackets. */
typedef struct hfvis_ffao_options {
    const hfvis_allocator *alloc;  /* NULL = malloc/free */
    int directions;                /* K scan directions, 3..HFVIS_SSAO_MAX_DIRECTIONS [8; sparse 18] */
    int segments;                  /* S segments per sector, 1..64 [2] ("K = 8x2") */
    double azimuth0_rad;           /* direction k at azimuth0 + 2 pi k/K [0] */
    int b0;                        /* B0, base interval length in steps (px), 1..4096 [10] */
    int levels;                    /* hierarchy levels B_n = B0 2^n; 0 = all that fit, 1 = none */
    double level_gamma;            /* schedule (spec §5.5): B_n <= gamma (distance) [1] */
    double receiver_slope;         /* s of the second receiver angle, < 0 [-1] */
    hfvis_ffao_averaging averaging;/* [DEFAULT] */
    int jitter;                    /* 1: rotate every segment of a pixel by one hash in
                                      [-1/2, 1/2] segment widths (§5.9) [0] */
    uint32_t seed;                 /* jitter hash seed */
    double thickness;              /* finite depth-field thickness in view units; 0 = infinite
                                      ([P4] §11) [0] */
    hfvis_falloff falloff;         /* [NONE] */
    hfvis_ffao_estimator estimator;/* [DEFAULT] */
    const hfvis_ffao_table *table; /* for TABLE / DEFAULT, built for this falloff [NULL] */
    int quad_nodes;                /* QUADRATURE nodes 1..64 [16] */
    hfvis_ffao_near near_field;    /* [DIRECT] */
    hfvis_ssao_sampling sampling;  /* depth reads [BILINEAR for thickness 0, else NEAREST] */
    int sparse;                    /* 1: SAAO 3x3 separation (§5.9), K % 9 == 0 [0] */
    int blur;                      /* sparse only: 1 = the 5x5 bilateral blur after the gather */
    int blur_radius;               /* [2] */
    double blur_threshold;         /* relative ambient-light difference accepted [0.07] */
    int mip_directions;            /* hfvis_ssao_mipmap: K [16] */
    double mip_growth;             /* hfvis_ssao_mipmap: step growth per sample, >= 1 [1.5] */
} hfvis_ffao_options;

HFVIS_API hfvis_ffao_options hfvis_ffao_options_default(void);

/* The options with every default filled in. HFVIS_ERR_INVALID_ARGUMENT for NULL out, values
 * outside the ranges above, an unknown enum value, a non-finite number, sparse with K % 9 != 0,
 * CLOSED_FORM with a falloff other than NONE, an invalid table or falloff. in may be NULL. */
HFVIS_API hfvis_status hfvis_ffao_options_resolve(const hfvis_ffao_options *in,
                                                  hfvis_ffao_options *out);

/* The slab integral of [P4] Eq. 3 (spec §5.2 [D]) over [a, theta_hi] clipped to
 * [max(d - pi/2, 0), min(c, d + pi/2, pi)]: Int rho(b / sin(c - t)) cos(t - d) sin t dt, angles
 * in radians from the receiver's zenith (t = 0 zenith, toward the scan direction), b the
 * distance from the receiver to the slab's line (view units), c the slab's direction, d the
 * projected normal's. Gauss-Legendre with `nodes` (1..64) nodes; exact for falloff NONE up to
 * the quadrature's polynomial order. NaN for an invalid falloff or argument. Pure. */
HFVIS_API double hfvis_ffao_slab_integral(const hfvis_falloff *falloff, double a, double theta_hi,
                                          double b, double c, double d, int nodes);
/* The same for rho = 1 in closed form, F(hi) - F(lo) with F(t) = t sin(d)/2 - cos(2t - d)/4.
 * NaN for non-finite a, c, d or NaN theta_hi. Pure. */
HFVIS_API double hfvis_ffao_slab_rho1(double a, double theta_hi, double c, double d);

/* Build the table of L for a falloff (sizes 0 = defaults 64 x 48 x 16 x 33 = 6.4 MB; each 2..4096;
 * b_ref 0 = the falloff's length: sqrt(r), lambda, R, the custom support or 1). One allocation
 * with alloc, released by hfvis_ffao_table_free. HFVIS_ERR_INVALID_ARGUMENT for NULL out, an
 * invalid falloff, bad sizes or b_ref; HFVIS_ERR_LIMIT on size overflow; HFVIS_ERR_OUT_OF_MEMORY. */
HFVIS_API hfvis_status hfvis_ffao_table_build(const hfvis_falloff *falloff, int na, int nb, int nc,
                                              int nd, double b_ref, const hfvis_allocator *alloc,
                                              hfvis_ffao_table *out);
HFVIS_API void hfvis_ffao_table_free(hfvis_ffao_table *table);
/* L(a, b, c, d) from the table (inputs clamped to its ranges); NaN for an invalid table. */
HFVIS_API double hfvis_ffao_table_lookup(const hfvis_ffao_table *table, double a, double b,
                                         double c, double d);

/* The virtual point of an interval (spec §5.4): h = ((m0 - m1)/slope, m0 zscale) from
 * m0 = max y and m1 = max(y - slope x) (the corrected [P4] Alg. 1, spec §5.3). h NULL: no-op. */
HFVIS_API void hfvis_ffao_virtual_point(double m0, double m1, double slope, double zscale,
                                        double h[2]);

/* The angular width around the zenith of the screen sector [phi_lo, phi_hi] (radians, screen
 * azimuths, 0 < phi_hi - phi_lo < pi) at view point p (spec §5.2 [D]): the angle between the
 * sector's boundary line directions e1 projected onto the plane perpendicular to the view ray
 * (orthographic: the view axis). Sectors of a full circle sum to 2 pi; 2 pi/K on the axis.
 * NaN for an invalid camera or argument (perspective p not in front of the eye). Pure. */
HFVIS_API double hfvis_ffao_sector_weight(const hfvis_camera *cam, const double p[3],
                                          double phi_lo, double phi_hi);

/* One slice of the slab estimator (spec §5.2 SliceObscurance): receiver p and projected normal
 * n in the slice's 2D frame (eye at the origin, y toward the camera; orthographic 1: zenith +y),
 * points (hx[i], hy[i]) ordered outward; point i is visible iff its zenith angle a_i is below
 * every earlier one (strictly; starting from theta_start, pi = nothing yet), and then adds
 * |n| (L(a_i) - L(theta_min_before)) with the options' falloff, estimator, table, quad_nodes
 * and thickness (a finite thickness ends the slab: [P4] §11). *obscurance = the sum (not divided
 * by pi), *theta_min (may be NULL) = the final horizon. Non-finite points are skipped.
 * HFVIS_ERR_INVALID_ARGUMENT for NULL p/n/obscurance, count < 0, NULL arrays with count > 0,
 * orthographic not 0/1, non-finite p or n, p at the eye (perspective), TABLE without a table,
 * options that hfvis_ffao_options_resolve rejects. */
HFVIS_API hfvis_status hfvis_ffao_slice(const double p[2], const double n[2], const double *hx,
                                        const double *hy, int count, int orthographic,
                                        double theta_start, const hfvis_ffao_options *opts,
                                        double *obscurance, double *theta_min);

/* Screen-space far-field ambient obscurance ([P4]; spec §5.7 FfaoPixel), the COS convention
 * (spec §1.2: converges to the ray-traced reference, P4 Eq. 1). Per scan direction k (uniform
 * azimuths, dense lattice D_S = D_L = 1 px): the scan kernel stores per line and interval of B0
 * steps m0 = max Q.z and m1 = max(Q.z - s Q.e1) over the samples (background skipped), levels
 * B_n = B0 2^n take the max of two children, prefix sums over the lines (double) give sector
 * averages. Per inner non-background pixel and segment: the near field (options), then the
 * intervals from the first one starting at least B0 steps ahead, at the largest level n with
 * cur % B_n == 0 and B_n <= gamma (cur - t_pixel), each averaged over the lines between the
 * segment's boundary rays (at least the nearest line) into a virtual point, culled to rising
 * horizons and summed by the slab estimator; ao = clamp((1/pi) sum_k,g w_kg I_kg, 0, 1) with
 * w_kg the segment widths around the zenith. sparse: each pixel of a 3x3 block evaluates the far
 * field of sectors k with k % 9 = (x % 3) + 3 (y % 3) on the box-averaged depth and normal,
 * the gather adds the full-rate near field to the far field averaged over the accepted
 * neighbours (weights renormalised), then the optional bilateral blur. ao[y*ao_stride + x],
 * inner pixels; background receivers 0. normals NULL: reconstructed (hfvis_depth_normals).
 * Allocations: normals (if reconstructed), directions, lines, the interval prefix sums
 * (about 48 (W0 + H0) W0 H0 / (B0 sqrt 2 ... ) bytes: 3 doubles per line and interval and
 * level, one direction at a time), the per-pixel accumulator (8 or 32 bytes/pixel), and the L
 * table when built per call. Cost O(K W0 H0) scan + O(K S W H log(W0 + H0)) evaluation.
 * HFVIS_ERR_INVALID_ARGUMENT for an invalid camera or options, NULL depth/ao, ao_stride < inner
 * width; HFVIS_ERR_LIMIT; HFVIS_ERR_OUT_OF_MEMORY. Outputs untouched on error. */
HFVIS_API hfvis_status hfvis_ffao(const hfvis_camera *cam, const float *depth,
                                  const float *normals, const hfvis_ffao_options *opts,
                                  float *ao, ptrdiff_t ao_stride);

/* The mipmap baseline ([P4] §5, spec §5.10): a pyramid of averaged depth (thickness 0) or of
 * the nearest depth ("max mips", thickness > 0; background ignored); per pixel, mip_directions
 * directions with samples at 1 px, then steps growing by mip_growth, plus one at the buffer
 * edge, each read trilinearly at level log2(max(1, 2 s tan(pi/K))) and fed as a slab point to
 * the same estimator (falloff, estimator, table, thickness); segment widths as hfvis_ffao.
 * Allocations: normals (if reconstructed), the pyramid (4/3 W0 H0 floats), the L table when
 * built per call. Errors as hfvis_ffao. */
HFVIS_API hfvis_status hfvis_ssao_mipmap(const hfvis_camera *cam, const float *depth,
                                         const float *normals, const hfvis_ffao_options *opts,
                                         float *ao, ptrdiff_t ao_stride);

/* 5x5 (radius 2) bilateral box blur of [P4] §10 on obscurance: each pixel becomes 1 - the mean
 * ambient light 1 - ao over the neighbours within `radius` whose ambient light differs from the
 * centre's by at most threshold times it (the centre always). in and out must not be the same
 * buffer. HFVIS_ERR_INVALID_ARGUMENT for NULL, in == out, sizes < 1, strides < width, radius
 * outside 0..64, a negative or non-finite threshold. Allocates nothing. */
HFVIS_API hfvis_status hfvis_ssao_bilateral_blur(const float *in, ptrdiff_t in_stride, int width,
                                                 int height, int radius, double threshold,
                                                 float *out, ptrdiff_t out_stride);

/* Error statistics of an AO image against a reference ([P4] §8, spec §5.12). */
typedef struct hfvis_ssao_error_stats {
    double mean;     /* e_A: mean |ao - ref| (relative: / |ref| where |ref| > 1e-6) */
    double bias;     /* mean (ao - ref), absolute */
    double rms, max;
    double within;   /* e_<tol: fraction of pixels with error <= tolerance */
    size_t count;    /* pixels compared (both finite) */
} hfvis_ssao_error_stats;

/* Compare width x height images; pixels where either is non-finite are skipped. error_image
 * (may be NULL): 1 - min(error / 0.2, 1) (white = 0, black >= 20 %, as P4 Fig. 7; 1 for skipped
 * pixels). HFVIS_ERR_INVALID_ARGUMENT for NULL ao/ref/stats, sizes < 1, strides < width,
 * tolerance negative or non-finite, relative not 0/1. */
HFVIS_API hfvis_status hfvis_ssao_error(const float *ao, ptrdiff_t ao_stride, const float *ref,
                                        ptrdiff_t ref_stride, int width, int height,
                                        double tolerance, int relative,
                                        hfvis_ssao_error_stats *stats, float *error_image,
                                        ptrdiff_t error_stride);
