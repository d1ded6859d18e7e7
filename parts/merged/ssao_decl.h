
/* ------------------------------------------------------------------------------------------
 * Screen space conventions (spec screenspace-p3-p4 §2.1; [P3] = Timonen, "Line-Sweep Ambient
 * Obscurance", EGSR 2013; [P4] = Timonen, "Screen-Space Far-Field Ambient Obscurance", HPG 2013)
 *
 * Buffers. A depth buffer is width x height floats (the FULL buffer W0 x H0, guard band
 *   included), texel (x, y) at depth[y*stride + x], row 0 at the top. Values are positive
 *   linear view-space depth: the distance along the camera's forward axis (not the ray length,
 *   not NDC). A texel is BACKGROUND when its depth is not finite, <= 0, or >= the camera's
 *   far_depth: background never occludes (like a height-field hole) and receives obscurance 0.
 *   Normal buffers hold 3 floats per texel, normals[3*(y*stride + x) + c], view space, unit,
 *   facing the camera; (0, 0, 0) marks "no normal".
 * Pixels. Texel (x, y) covers [x, x+1) x [y, y+1); its centre is (x + 0.5, y + 0.5). Screen
 *   positions (u, v) are continuous in these units over the whole buffer.
 * View space. Right-handed, eye at the origin looking down -Z, +X right, +Y up:
 *   perspective   P(u, v, z) = ((u - cx) z / fx, -(v - cy) z / fy, -z)
 *   orthographic  P(u, v, z) = ((u - cx) sx, -(v - cy) sy, -z)   (zenith = +Z everywhere)
 * Guard band. guard_x / guard_y pixels per side are occluders only: AO outputs cover the inner
 *   (width - 2 guard_x) x (height - 2 guard_y) pixels, ao[y*ao_stride + x] for inner pixel
 *   (x, y) = buffer texel (x + guard_x, y + guard_y). P3's "1280(+256) x 720(+144), 20 % guard
 *   band" is guard_x = 128, guard_y = 72.
 * Directions. A screen direction D = (dx, dy) is in pixels, +x right, +y DOWN; its azimuth is
 *   atan2(dy, dx) (DESIGN §2: from +x toward +y).
 * Obscurance. Every AO output is obscurance in [0, 1], 0 = nothing blocks. Two integrands exist
 *   (spec §1.2): HBAO and LSAO weight by solid angle per azimuthal slice ("SA", the zenith is
 *   the direction to the eye, not the normal), the ray-traced reference is cosine-weighted
 *   around the normal (P4 Eq. 1, "COS"). They give different numbers for the same scene.
 * ------------------------------------------------------------------------------------------ */

struct hfvis_view; /* declared with the views below (voxel.c) */

/* Largest width or height of a screen-space buffer, and the largest direction count. */
#define HFVIS_SSAO_MAX_SIZE 65536
#define HFVIS_SSAO_MAX_DIRECTIONS 4096

/* ---- camera ------------------------------------------------------------------------------ */

typedef enum hfvis_camera_projection {
    HFVIS_CAMERA_PERSPECTIVE = 1,
    HFVIS_CAMERA_ORTHOGRAPHIC = 2   /* test mode (spec §6): camera at infinity, zenith +Z */
} hfvis_camera_projection;

/* A screen-space camera. Not an options struct: projection 0 is invalid. */
typedef struct hfvis_camera {
    int width, height;          /* full buffer W0 x H0 (guard band included), 1..HFVIS_SSAO_MAX_SIZE */
    ptrdiff_t stride;           /* elements between depth rows; 0 = width (normals: 3*stride) */
    int guard_x, guard_y;       /* guard band per side, >= 0, 2*guard < width (height) */
    hfvis_camera_projection projection;
    double fx, fy;              /* perspective: focal lengths in pixels, > 0 */
    double cx, cy;              /* principal point in continuous pixel coordinates of the full
                                   buffer (both projections; symmetric: width/2, height/2) */
    double scale_x, scale_y;    /* orthographic: view units per pixel, > 0 */
    double far_depth;           /* depth >= far_depth is background; 0 = no far limit */
} hfvis_camera;

/* HFVIS_OK if the camera is valid; HFVIS_ERR_INVALID_ARGUMENT for NULL, sizes < 1, a negative
 * stride or 0 < stride < width, guard bands < 0 or leaving no inner pixel, an unknown
 * projection, non-finite or non-positive focal lengths / scales (only those of the chosen
 * projection are read), a non-finite principal point, far_depth < 0 or NaN; HFVIS_ERR_LIMIT
 * when width or height exceeds HFVIS_SSAO_MAX_SIZE or 3*stride*height overflows. */
HFVIS_API hfvis_status hfvis_camera_check(const hfvis_camera *cam);

/* A symmetric perspective camera: the VISIBLE (inner) image of (width - 2 guard_x) x (height -
 * 2 guard_y) pixels spans the vertical field of view fov_y_rad in (0, pi), square pixels
 * (fx = fy = inner_height / (2 tan(fov_y/2))), principal point at the buffer centre, no far
 * limit, stride 0. The guard band keeps the focal length of the visible image (spec §1.3).
 * Returns the errors of hfvis_camera_check, or HFVIS_ERR_INVALID_ARGUMENT for a bad fov. */
HFVIS_API hfvis_status hfvis_camera_perspective(hfvis_camera *cam, int width, int height,
                                                int guard_x, int guard_y, double fov_y_rad);

/* An orthographic camera with square pixels of pixel_size view units, principal point at the
 * buffer centre. Errors as hfvis_camera_perspective (pixel_size must be finite, > 0). */
HFVIS_API hfvis_status hfvis_camera_orthographic(hfvis_camera *cam, int width, int height,
                                                 int guard_x, int guard_y, double pixel_size);

/* The camera of a hfvis_view (the rasterizer's, voxel.c): width/height are the view's (the
 * full guard-banded buffer), focal lengths, principal point or scales follow from the GL
 * projection matrix (perspective: fx = P00 W/2, fy = P11 H/2, cx = W/2 (1 - P02),
 * cy = H/2 (1 + P12); orthographic: sx = 2/(W P00), sy = 2/(H P11), cx = W/2 (1 + P03),
 * cy = H/2 (1 - P13)), far_depth = the view's far plane (GL clears depth to it). The linear
 * depth output of hfvis_rasterize is then this camera's depth buffer (empty pixels +INFINITY
 * are background). HFVIS_ERR_INVALID_ARGUMENT for NULL, a projection matrix that is not of
 * the GL perspective / orthographic form, or the errors of hfvis_camera_check. */
HFVIS_API hfvis_status hfvis_camera_from_view(hfvis_camera *cam, const struct hfvis_view *view,
                                              int guard_x, int guard_y);

/* View-space point of screen position (u, v) at linear depth (see the conventions).
 * HFVIS_ERR_INVALID_ARGUMENT for an invalid camera, NULL out or non-finite input. */
HFVIS_API hfvis_status hfvis_camera_unproject(const hfvis_camera *cam, double u, double v,
                                              double depth, double out[3]);

/* Screen position and linear depth of view-space point p (inverse of unproject).
 * HFVIS_ERR_INVALID_ARGUMENT for an invalid camera, NULL pointers, non-finite p or (perspective)
 * a point not in front of the eye (p[2] >= 0). */
HFVIS_API hfvis_status hfvis_camera_project(const hfvis_camera *cam, const double p[3],
                                            double *u, double *v, double *depth);

/* ---- hardware depth ---------------------------------------------------------------------- */

typedef enum hfvis_depth_encoding {
    HFVIS_DEPTH_GL = 1,                /* GL window depth d in [0, 1] (glDepthRange(0, 1)); a GL
                                          projection gives the same d as D3D: z = n f/(f - d(f - n)) */
    HFVIS_DEPTH_GL_NDC = 2,            /* GL NDC depth in [-1, 1]: d_window = (d + 1)/2 */
    HFVIS_DEPTH_D3D = 3,               /* D3D depth in [0, 1]: d = f (z - n)/(z (f - n)) */
    HFVIS_DEPTH_REVERSED_Z = 4,        /* reversed Z in [0, 1] (1 at near): z = n f/(n + d(f - n)) */
    HFVIS_DEPTH_INFINITE_FAR = 5,      /* far plane at infinity, d = 1 - n/z in [0, 1) */
    HFVIS_DEPTH_REVERSED_INFINITE = 6  /* reversed Z with infinite far, d = n/z in (0, 1] */
} hfvis_depth_encoding;

/* Linear view depth of one hardware depth value. Orthographic projections are linear:
 * z = n + d (f - n) (GL, GL_NDC after mapping, D3D), z = f - d (f - n) (REVERSED_Z); the
 * infinite-far encodings have no orthographic form. Returns +INFINITY (background) for d
 * outside the encoding's range, non-finite d, or d on the infinite far plane; the far plane
 * itself (d = 1 in GL/D3D) gives far_plane, which a camera with far_depth = far_plane treats
 * as background. Returns NaN for an unknown encoding, orthographic not 0/1, an orthographic
 * infinite-far encoding, or planes not 0 < near < far (near > 0 finite for infinite far; the
 * orthographic forms accept 0 <= near). Pure; computed in double. */
HFVIS_API double hfvis_depth_linear(double d, hfvis_depth_encoding encoding, int orthographic,
                                    double near_plane, double far_plane);

/* Inverse of hfvis_depth_linear: the hardware depth of linear depth z (z in [near, far]; other
 * z give values outside the range). NaN for invalid parameters or z <= 0 in perspective. */
HFVIS_API double hfvis_depth_hardware(double z, hfvis_depth_encoding encoding, int orthographic,
                                      double near_plane, double far_plane);

/* hfvis_depth_linear over a width x height buffer: out[y*out_stride + x] from
 * in[y*in_stride + x], rounded to float. out may equal in (same stride); other overlaps are
 * not allowed. HFVIS_ERR_INVALID_ARGUMENT for NULL buffers, sizes < 1, strides < width, or the
 * parameters hfvis_depth_linear rejects (outputs untouched). Allocates nothing. */
HFVIS_API hfvis_status hfvis_depth_linearize(const float *in, int width, int height,
                                             ptrdiff_t in_stride, hfvis_depth_encoding encoding,
                                             int orthographic, double near_plane,
                                             double far_plane, float *out, ptrdiff_t out_stride);

/* Normals from depth (spec §2.1 [R]): for each texel, the view-space points of the left/right
 * and upper/lower neighbours; on each axis the side whose depth differs less from the centre
 * (ties: right, lower; only one side if the other is background or outside the buffer) gives a
 * one-sided difference, and the normal is the normalised cross product of the two, turned to
 * face the eye (n . -P > 0; orthographic n.z > 0). With no usable neighbour on an axis the
 * normal is the direction to the eye (-P/|P|; orthographic +Z). Background texels get (0,0,0).
 * normals: 3 floats per texel in the camera's layout (3*stride per row; entries between rows
 * are not written). Exact for planes (up to rounding). HFVIS_ERR_INVALID_ARGUMENT for an
 * invalid camera or NULL buffers. Allocates nothing. Cost O(width*height). */
HFVIS_API hfvis_status hfvis_depth_normals(const hfvis_camera *cam, const float *depth,
                                           float *normals);

/* The azimuthal plane of a screen line (spec §2.2): the plane through the eye and the screen
 * line through reference view point ref with screen direction (du, dv). e1 is the unit 3D
 * direction of the line at constant depth, normalize(du/fx, -dv/fy, 0) (orthographic:
 * normalize(du sx, -dv sy, 0)); yhat is the unit vector in the plane perpendicular to e1 on the
 * camera side (yhat.z > 0; orthographic (0, 0, 1)). (Q.e1, Q.yhat) is an isometry of the plane
 * with the eye at the origin and Q.yhat = Q.z / yhat.z. HFVIS_ERR_INVALID_ARGUMENT for an
 * invalid camera, NULL pointers, non-finite values, a zero direction or (perspective) ref not
 * in front of the eye. */
HFVIS_API hfvis_status hfvis_camera_line_plane(const hfvis_camera *cam, const double ref[3],
                                               double du, double dv, double e1[3],
                                               double yhat[3]);

/* ---- falloff ----------------------------------------------------------------------------- */

typedef enum hfvis_falloff_kind {
    HFVIS_FALLOFF_DEFAULT = 0,        /* = NONE */
    HFVIS_FALLOFF_NONE = 1,           /* rho = 1: pure obscurance over the whole buffer */
    HFVIS_FALLOFF_INV_QUADRATIC = 2,  /* rho = r/(r + d^2), r = param (length^2) [P3 Eq. 2] */
    HFVIS_FALLOFF_HBAO = 3,           /* rho = max(0, r(1 + C)/(r + d^2) - C), r = param,
                                         C = hbao_c (0 = 0.3); zero from sqrt(r/C) [P3 Eq. 3] */
    HFVIS_FALLOFF_EXPONENTIAL = 4,    /* rho = exp(-d/lambda), lambda = param */
    HFVIS_FALLOFF_STEP = 5,           /* rho = 1 for d < R, else 0, R = param (pure AO) */
    HFVIS_FALLOFF_CUSTOM = 6          /* rho = fn(user, d) clamped to [0, 1] (NaN -> 0); param =
                                         its support (rho = 0 from there on, fn not called;
                                         0 = unbounded) */
} hfvis_falloff_kind;

typedef double (*hfvis_falloff_fn)(void *user, double distance);

/* A falloff rho(d) of the view-space distance d to the occluder: monotonically decreasing by
 * intent, rho(0) = 1 (spec §1.1). A zero struct is NONE. */
typedef struct hfvis_falloff {
    hfvis_falloff_kind kind;
    double param;                 /* r, lambda, R or the custom support (see the kinds) */
    double hbao_c;                /* HBAO's C, > 0; 0 = 0.3 */
    hfvis_falloff_fn fn;          /* CUSTOM only */
    void *user;                   /* CUSTOM only */
} hfvis_falloff;

/* HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for NULL, an unknown kind, a param that is not finite
 * and > 0 where the kind needs one (INV_QUADRATIC, HBAO, EXPONENTIAL, STEP), hbao_c < 0 or not
 * finite, a CUSTOM falloff without fn or with a negative / non-finite param. */
HFVIS_API hfvis_status hfvis_falloff_check(const hfvis_falloff *f);
/* rho(distance) in double (distance >= 0; NULL f = NONE). NaN for an invalid falloff. Pure
 * (CUSTOM calls fn). */
HFVIS_API double hfvis_falloff_eval(const hfvis_falloff *f, double distance);
/* The distance from which rho is 0: sqrt(r/C) for HBAO, R for STEP, the custom param, and
 * +INFINITY for unbounded falloffs; NaN for an invalid falloff. */
HFVIS_API double hfvis_falloff_support(const hfvis_falloff *f);

/* ---- directions and the line lattice ([P3] §5.1-5.2, [P4] §6; spec §2.3, §3.5) ------------ */

/* One azimuthal direction of a line sweep. */
typedef struct hfvis_ssao_direction {
    double dx, dy;            /* unit screen direction D (pixels; +y down) */
    double step_x, step_y;    /* step vector along a line, pixels: step*(dx, dy); exact
                                 integers for box patterns, so snapped samples keep one
                                 pattern for every receiver ([P3] §5.2) */
    double step;              /* D_S = |step vector|, pixels */
    double spacing;           /* D_L, distance between adjacent lines, pixels */
    double weight;            /* azimuthal coverage / 2 pi; a direction set sums to 1 */
} hfvis_ssao_direction;

/* K uniform directions psi_k = azimuth0 + 2 pi k/K, D = (cos psi, sin psi) (components within
 * 1e-15 of 0 or +-1 snapped to them, so axis directions are exact), step vector step*D,
 * weights 1/K. HFVIS_ERR_INVALID_ARGUMENT for NULL out, K outside 1..HFVIS_SSAO_MAX_DIRECTIONS,
 * a non-finite azimuth, step or spacing not finite in [1/64, HFVIS_SSAO_MAX_SIZE]. */
HFVIS_API hfvis_status hfvis_ssao_directions_uniform(int K, double azimuth0_rad, double step,
                                                     double spacing, hfvis_ssao_direction *out);

/* The K = 8n box-pattern directions of [P3] §5.2, Fig. 10: the vectors from the centre of a
 * (2n+1) x (2n+1) texel template to the centres of its outer ring, times the integer scale m,
 * ordered by azimuth from +x (direction 0 = +x). The four axis directions use the mean length
 * of the others rounded to an integer (the paper's "average of the rest", kept integral so the
 * snapped pattern stays the same for every receiver: n = 1..4 give axis steps 1, 2, 4, 5 at
 * m = 1). Weights are the azimuthal coverages w_k = (phi_{k+1} - phi_{k-1})/(4 pi) ([P3] §5.2;
 * n = 2: 26.57 deg axes, 22.5 deg (2,1)-type, 18.43 deg diagonals). out must hold 8n entries.
 * HFVIS_ERR_INVALID_ARGUMENT for NULL out, n < 1, m < 1, 8n > HFVIS_SSAO_MAX_DIRECTIONS,
 * n*m > 4096 or spacing not finite in [1/64, HFVIS_SSAO_MAX_SIZE]. */
HFVIS_API hfvis_status hfvis_ssao_directions_box(int n, int scale, double spacing,
                                                 hfvis_ssao_direction *out);

/* The line lattice of one direction over the full buffer (spec §2.3 BuildLattice): lines
 * parallel to D, spacing D_L apart along P = (-dy, dx) and centred in the texel-centre rectangle
 * [0.5, W0 - 0.5] x [0.5, H0 - 0.5] (the leftover split evenly at both sides); all lines share
 * the along-line origin t_min, so step i of every line lies at along-line coordinate
 * t_min + i*D_S (P4's interval alignment). Line j passes through s_j = s_first + j*D_L;
 * its samples are the steps i = first .. first + count - 1 inside the rectangle (tolerance
 * 1e-7 px), at (x0 + i*step_x, y0 + i*step_y). Samples are stored line after line: sample i of
 * line j has index lines[j].offset + i - lines[j].first in every lattice buffer. */
typedef struct hfvis_ssao_lattice {
    hfvis_ssao_direction dir;
    double px, py;            /* P = (-dy, dx) */
    double s_first;           /* perpendicular coordinate c.P of line 0 */
    double t_min;             /* along-line coordinate c.D of step 0 */
    int line_count;
    int max_line_samples;     /* longest line */
    size_t sample_count;      /* all samples of all lines */
} hfvis_ssao_lattice;

typedef struct hfvis_ssao_line {
    double x0, y0;            /* screen position of step i = 0 (may lie outside the buffer) */
    int first, count;         /* steps first .. first + count - 1; count may be 0 */
    size_t offset;            /* lattice-buffer index of step `first` */
} hfvis_ssao_line;

/* Set up the lattice of direction dir over the camera's buffer (counts only; O(lines)).
 * HFVIS_ERR_INVALID_ARGUMENT for an invalid camera or direction (NULL, non-unit or non-finite
 * D, step or spacing outside [1/64, HFVIS_SSAO_MAX_SIZE], step vector not step*D within 1e-9);
 * HFVIS_ERR_LIMIT if a direction would have more than 2^31 - 1 samples. */
HFVIS_API hfvis_status hfvis_ssao_lattice_init(const hfvis_camera *cam,
                                               const hfvis_ssao_direction *dir,
                                               hfvis_ssao_lattice *lat);

/* Fill lines[0 .. lat->line_count - 1] for a lattice from hfvis_ssao_lattice_init with the same
 * camera. HFVIS_ERR_INVALID_ARGUMENT for NULL pointers or an invalid camera. */
HFVIS_API hfvis_status hfvis_ssao_lattice_lines(const hfvis_camera *cam,
                                                const hfvis_ssao_lattice *lat,
                                                hfvis_ssao_line *lines);

/* The lattice sample nearest to screen position (u, v) in lattice coordinates (spec §2.3):
 * line j = round((c.P - s_first)/D_L) clamped to the lines, step i = round((c.D - t_min)/D_S)
 * clamped to that line's steps; an empty line is replaced by the nearest non-empty one.
 * Returns 1 and writes *line, *step, or 0 when the lattice has no sample or an argument is
 * NULL / non-finite. Within sqrt((D_S/2)^2 + (D_L/2)^2) of (u, v) away from the borders. */
HFVIS_API int hfvis_ssao_lattice_nearest(const hfvis_ssao_lattice *lat,
                                         const hfvis_ssao_line *lines, double u, double v,
                                         int *line, int *step);

/* ---- P3 line-sweep ambient obscurance (LSAO) ---------------------------------------------- */

typedef enum hfvis_ssao_pattern {
    HFVIS_SSAO_PATTERN_DEFAULT = 0,  /* = BOX */
    HFVIS_SSAO_PATTERN_BOX = 1,      /* hfvis_ssao_directions_box(K/8, box_scale, spacing) */
    HFVIS_SSAO_PATTERN_UNIFORM = 2,  /* hfvis_ssao_directions_uniform(K, azimuth0, step, spacing) */
    HFVIS_SSAO_PATTERN_CUSTOM = 3    /* the caller's K directions (custom_directions) */
} hfvis_ssao_pattern;

/* The tangent plane of Eq. 1, used to decide what the hull culls and to evaluate the result
 * ([P3] §4.1, Fig. 7; spec §3.4). */
typedef enum hfvis_ssao_tangent {
    HFVIS_SSAO_TANGENT_DEFAULT = 0,            /* LSAO: FIXED; HBAO: REAL */
    HFVIS_SSAO_TANGENT_FIXED = 1,              /* sin t = fixed_sin_t everywhere (P3's choice) */
    HFVIS_SSAO_TANGENT_REAL = 2,               /* the receiver's tangent for both (strategy 1) */
    HFVIS_SSAO_TANGENT_FIXED_HULL_REAL_EVAL = 3 /* fixed for the hull, real for the value (2) */
} hfvis_ssao_tangent;

/* How depth is read along a line ([P3] §5.2, spec §2.4). */
typedef enum hfvis_ssao_sampling {
    HFVIS_SSAO_SAMPLING_DEFAULT = 0,   /* LSAO, HBAO: NEAREST; ray tracer: see its options */
    HFVIS_SSAO_SAMPLING_NEAREST = 1,   /* snap to the texel centre, deproject there (as HBAO) */
    HFVIS_SSAO_SAMPLING_BILINEAR = 2   /* bilinear depth (continuous height-field assumption),
                                          deprojected at the continuous position; a tap with
                                          non-zero weight on background makes a hole */
} hfvis_ssao_sampling;

/* The 2D coordinates of a line's azimuthal plane (spec §2.2). */
typedef enum hfvis_ssao_plane {
    HFVIS_SSAO_PLANE_DEFAULT = 0,  /* LSAO: PAPER; HBAO: EXACT */
    HFVIS_SSAO_PLANE_PAPER = 1,    /* (Q.e1, Q.z) as [P3] Alg. 1 l.4 (with e1 normalised and
                                      screen y flipped); exact only for lines through the
                                      principal point */
    HFVIS_SSAO_PLANE_EXACT = 2     /* (Q.e1, Q.yhat): an isometry of the line's plane */
} hfvis_ssao_plane;

/* The hull's pop test ([P3] Alg. 1 l.12; spec §3.3 tie rule). */
typedef enum hfvis_lsao_pop {
    HFVIS_LSAO_POP_DEFAULT = 0,  /* = TIES */
    HFVIS_LSAO_POP_TIES = 1,     /* pop when occ(top) <= occ(second) and the second is higher */
    HFVIS_LSAO_POP_STRICT = 2    /* the paper's literal occ(top) < occ(second): sticks on deep
                                    points behind depth steps (spec §3.3: 5x the error) */
} hfvis_lsao_pop;

/* How a pixel reads a direction's lattice values ([P3] §5.1, spec §3.6). */
typedef enum hfvis_ssao_gather {
    HFVIS_SSAO_GATHER_DEFAULT = 0,   /* = NEAREST */
    HFVIS_SSAO_GATHER_NEAREST = 1,   /* the nearest lattice sample (the paper) */
    HFVIS_SSAO_GATHER_BILINEAR = 2   /* the 2 x 2 lattice neighbours (lines j, j+1, steps i, i+1)
                                        weighted bilinearly, rejected ones dropped and the rest
                                        renormalised (P1/P2's rotate-and-blend) */
} hfvis_ssao_gather;

/* Options of the LSAO routines. NULL or a zero struct = the defaults in brackets. */
typedef struct hfvis_lsao_options {
    const hfvis_allocator *alloc;        /* scratch; NULL = malloc/free */
    int directions;                      /* K [16]; BOX needs K % 8 == 0 */
    hfvis_ssao_pattern pattern;          /* [BOX] */
    int box_scale;                       /* BOX: integer scale m [1] */
    double step;                         /* UNIFORM: D_S in pixels [1] */
    double spacing;                      /* D_L in pixels [K / (4 D_S)]: 4 evaluations per pixel as
                                            P3 Table 2 (D_S = the mean non-axis step for BOX,
                                            so K = 8, 16, 24, 32 give 1.41, 1.64, 1.69, 1.70) */
    double azimuth0_rad;                 /* UNIFORM: psi_0 [0] */
    const hfvis_ssao_direction *custom_directions; /* CUSTOM: K directions; weights are
                                            normalised to sum 1 (finite, >= 0, positive sum) */
    hfvis_falloff falloff;               /* [NONE] */
    hfvis_ssao_tangent tangent;          /* [FIXED] */
    double fixed_sin_t;                  /* sin t of the fixed tangent, in [-1, 1] [-0.85]; 0
                                            cannot be chosen exactly (use 1e-300) */
    hfvis_ssao_sampling sampling;        /* [NEAREST] */
    hfvis_ssao_plane plane;              /* [PAPER] */
    hfvis_lsao_pop pop;                  /* [TIES] */
    hfvis_ssao_gather gather;            /* [NEAREST] */
    double reject_depth;                 /* gather: reject a sample whose depth differs from the
                                            receiver's by more than this fraction of it [0.03];
                                            negative = no depth test */
    double reject_normal;                /* gather, only with caller-supplied normals: reject a
                                            sample whose texel normal has dot < this with the
                                            receiver's [0.5]; -1 = accept all */
} hfvis_lsao_options;

HFVIS_API hfvis_lsao_options hfvis_lsao_options_default(void);

/* The options with every default filled in (directions, spacing, enums, thresholds), so a GPU
 * port can print the exact parameters. HFVIS_ERR_INVALID_ARGUMENT for NULL out, K outside
 * 1..HFVIS_SSAO_MAX_DIRECTIONS, BOX with K % 8 != 0, box_scale < 0, step/spacing not finite or
 * (when given) outside [1/64, HFVIS_SSAO_MAX_SIZE], a non-finite azimuth, CUSTOM without
 * directions or with an invalid one or bad weights, an unknown enum value, fixed_sin_t outside
 * [-1, 1], a NaN threshold, reject_normal > 1, an invalid falloff. in may be NULL. */
HFVIS_API hfvis_status hfvis_lsao_options_resolve(const hfvis_lsao_options *in,
                                                  hfvis_lsao_options *out);

/* The K directions LSAO uses (out must hold opts->directions, or 16 for NULL/0), with the
 * resolved spacing and the weights normalised. Errors of hfvis_lsao_options_resolve. */
HFVIS_API hfvis_status hfvis_lsao_directions(const hfvis_lsao_options *opts,
                                             hfvis_ssao_direction *out);

/* The obscurity hull along one line in 2D line space ([P3] §4.2, Alg. 1; spec §3.3):
 * points (x[i], y[i]) in sweep order (y grows toward the camera; the eye at the origin in
 * perspective; orthographic 1: the zenith is +y everywhere). For each receiver i the zenith is
 * u = -p/|p| (orthographic (0, 1)) and, with Sin(h) = h.u/|h| and
 *     Occ(h, st) = st + max(0, Sin(h) - st) * rho(|h|)                      (Alg. 1 l.25-29)
 * the stack of earlier points is popped while Occ(top - p, st_cull) <= Occ(second - p, st_cull)
 * (POP_STRICT: <) and Sin(top - p) < Sin(second - p); then
 *     out[i] = st_eval (empty stack) or Occ(top - p, st_eval)
 * and p is pushed (unless it coincides with the top: |h| <= 1e-12 |p|; a coincident point has
 * no elevation and never occludes). st_cull = sin_t_cull[i], st_eval = sin_t_eval[i], either
 * array NULL = opts' fixed_sin_t. A non-finite x or y (or the eye itself in perspective) is a
 * hole: never pushed, out NaN. Uses opts' falloff, pop rule and fixed_sin_t (NULL = defaults).
 * The result is the per-direction term of [P3] Eq. 1 (not clamped; may be negative). stack
 * must hold n ints. Cost: at most 2n pop tests. HFVIS_ERR_INVALID_ARGUMENT for n < 0, NULL
 * arrays with n > 0, orthographic not 0/1, or options hfvis_lsao_options_resolve rejects. */
HFVIS_API hfvis_status hfvis_lsao_line(const double *x, const double *y, const double *sin_t_cull,
                                       const double *sin_t_eval, int n, int orthographic,
                                       const hfvis_lsao_options *opts, int *stack, double *out);

/* Oracle of hfvis_lsao_line (spec §4.2; the [P3] Fig. 7 reference): for each receiver, walk
 * back over the earlier points; point j is visible iff Sin(p_j - p_i) exceeds every Sin seen
 * nearer to i; among the visible points take the largest Occ(., st_cull) (ties: the higher,
 * i.e. farther visible point) and return its Occ(., st_eval) (st_eval if none). Same contract,
 * no scratch, cost O(n^2). Exact mode: with HFVIS_FALLOFF_NONE, Occ is monotonic in Sin, the
 * obscurity hull is the P1 convex hull and hfvis_lsao_line equals this oracle (bit for bit on
 * generic input); with a falloff the hull can miss the largest occluder in degenerate cases
 * ([P3] §4.1: 0.02-0.3 % average error in the final AO). */
HFVIS_API hfvis_status hfvis_lsao_line_naive(const double *x, const double *y,
                                             const double *sin_t_cull, const double *sin_t_eval,
                                             int n, int orthographic,
                                             const hfvis_lsao_options *opts, double *out);

/* Raw per-direction LSAO output for GPU-port diffing: sweeps every line of lattice lat (from
 * hfvis_ssao_lattice_init / _lines with the same camera and a direction of these options) in
 * increasing step order - so the values describe occluders in azimuth -D - and writes the
 * Eq. 1 term of every sample to values[lattice index] (float, unclamped; NaN at holes: a
 * background sample, or under BILINEAR a tap on background) and, if sample_depth is not NULL,
 * the depth read at the sample (NaN at holes). Per sample: the depth at the snapped texel
 * centre (NEAREST; box-pattern steps are integer texel offsets from the line's first texel) or
 * bilinear at the sample (BILINEAR), deprojected, projected into the line's plane (PAPER: e1 of
 * the direction, y = Q.z; EXACT: e1, yhat through the line's middle sample ray), then
 * hfvis_lsao_line. Real tangents: the normal of the sample's texel projected into the plane,
 * t = (-n.y, n.x) (toward the occluders), sin t = t.u/|t| (fixed_sin_t where the normal is
 * (0,0,0) or perpendicular to the plane); normals NULL: reconstructed with
 * hfvis_depth_normals. Allocates 1 block of 36*max_line_samples bytes (+ 12*stride*height
 * for reconstructed normals). HFVIS_ERR_INVALID_ARGUMENT for invalid camera/options, NULL
 * depth/lat/lines/values, a lattice whose direction is invalid or whose lines do not match its
 * counts (stored back to back, each within max_line_samples, all within sample_count);
 * HFVIS_ERR_OUT_OF_MEMORY. */
HFVIS_API hfvis_status hfvis_lsao_direction(const hfvis_camera *cam, const float *depth,
                                            const float *normals, const hfvis_lsao_options *opts,
                                            const hfvis_ssao_lattice *lat,
                                            const hfvis_ssao_line *lines, float *values,
                                            float *sample_depth);

/* Oracle of hfvis_lsao_direction: the same samples through hfvis_lsao_line_naive. Equal to the
 * sweep in exact mode (falloff NONE); cost O(sum of squared line lengths). Same contract. */
HFVIS_API hfvis_status hfvis_lsao_direction_naive(const hfvis_camera *cam, const float *depth,
                                                  const float *normals,
                                                  const hfvis_lsao_options *opts,
                                                  const hfvis_ssao_lattice *lat,
                                                  const hfvis_ssao_line *lines, float *values,
                                                  float *sample_depth);

/* Gather one direction's lattice values into per-pixel accumulators ([P3] §5.1, spec §3.6):
 * for every non-background inner pixel c (buffer texel (x + guard_x, y + guard_y), centre
 * + 0.5), the nearest lattice sample (GATHER_NEAREST) or the 2 x 2 neighbours (BILINEAR) are
 * accepted when their value is not NaN, |sample_depth - z_c| <= reject_depth * z_c and (normals
 * given) n_sample . n_c >= reject_normal. When none is accepted, the nearest accepted sample
 * within 2 sqrt((D_S/2)^2 + (D_L/2)^2) is used instead; when there is none the direction is
 * dropped for that pixel. An accepted value v adds w*v to sum[y*W + x] and w to weight[y*W + x]
 * (W = inner width, w = lat->dir.weight). The final AO is clamp(sum/weight, 0, 1) (0 where
 * weight is 0), as hfvis_lsao computes it. HFVIS_ERR_INVALID_ARGUMENT for NULL pointers
 * (normals may be NULL) or invalid camera/options. Allocates nothing. */
HFVIS_API hfvis_status hfvis_lsao_gather(const hfvis_camera *cam, const float *depth,
                                         const float *normals, const hfvis_lsao_options *opts,
                                         const hfvis_ssao_lattice *lat,
                                         const hfvis_ssao_line *lines, const float *values,
                                         const float *sample_depth, double *sum, double *weight);

/* P3 line-sweep ambient obscurance ([P3] Eq. 1, Alg. 1, §5): per direction, the lattice, the
 * sweep (hfvis_lsao_direction) and the gather (hfvis_lsao_gather), then
 *   ao = clamp( sum_k w_k v_k / sum_k w_k , 0, 1 )
 * over the directions accepted at the pixel (background receivers 0). ao[y*ao_stride + x] for
 * the inner (width - 2 guard_x) x (height - 2 guard_y) pixels, obscurance (SA convention,
 * spec §1.2), the falloff over view-space distance. Work is O(K W0 H0 / (D_S D_L)) for the
 * sweeps and O(K W H) for the gathers, independent of the falloff radius; memory O(W0 H0)
 * whatever K is (one direction at a time). Allocates 5 blocks (directions, lines, the lattice
 * buffers 8 bytes/sample, the line scratch, the 16-byte/pixel accumulators) plus 1 for
 * reconstructed normals (real tangents without normals). HFVIS_ERR_INVALID_ARGUMENT for an
 * invalid camera or options, NULL depth/ao, ao_stride < inner width; HFVIS_ERR_LIMIT for a
 * lattice over 2^31 samples; HFVIS_ERR_OUT_OF_MEMORY. Outputs untouched on error. */
HFVIS_API hfvis_status hfvis_lsao(const hfvis_camera *cam, const float *depth,
                                  const float *normals, const hfvis_lsao_options *opts,
                                  float *ao, ptrdiff_t ao_stride);

/* ---- HBAO (Bavoil, Sainz, Dimitrov 2008, as the thesis describes it; spec §4.1) ----------- */

typedef enum hfvis_hbao_variant {
    HFVIS_HBAO_DEFAULT = 0,           /* = INCREMENTAL */
    HFVIS_HBAO_INCREMENTAL = 1,       /* P4's description: each sample rising above the running
                                         horizon adds rho(|h|) (sin h - max) - the SA integral
                                         with "geometry between visible samples at the higher
                                         one's distance" */
    HFVIS_HBAO_SINGLE_HORIZON = 2,    /* the thesis summary: rho(dist of the highest sample) *
                                         (sin h - sin t) */
    HFVIS_HBAO_LARGEST_OCCLUDER = 3   /* [P3] Eq. 1 by brute force over the visible samples: the
                                         largest Occ(h, sin t) (the P3 Fig. 7 reference) */
} hfvis_hbao_variant;

typedef enum hfvis_hbao_jitter {
    HFVIS_HBAO_JITTER_DEFAULT = 0,    /* = NONE */
    HFVIS_HBAO_JITTER_NONE = 1,
    HFVIS_HBAO_JITTER_ROTATION = 2,   /* the K directions rotated per pixel by xi 2 pi/K (P4's
                                         setup: "randomly rotated per pixel") */
    HFVIS_HBAO_JITTER_ROTATION_STEP = 3 /* and the march offset by a per-pixel fraction of a step */
} hfvis_hbao_jitter;

/* Options of hfvis_hbao. NULL or a zero struct = the defaults in brackets. */
typedef struct hfvis_hbao_options {
    const hfvis_allocator *alloc;     /* reconstructed normals only; NULL = malloc/free */
    int directions;                   /* K [8] (uniform azimuths azimuth0 + 2 pi k/K) */
    double azimuth0_rad;              /* [0] */
    const hfvis_ssao_direction *custom_directions; /* K directions to march instead (weights
                                         normalised), stepping by their step vectors: integer
                                         box steps visit texels at the same offsets for every
                                         receiver, as LSAO's box patterns [NULL] */
    hfvis_hbao_variant variant;       /* [INCREMENTAL] */
    int steps;                        /* N samples per direction; 0 = ceil(R_px / step_px)
                                         (custom directions: ceil(R_px / |step vector|)) [0] */
    double step_px;                   /* the auto step length in pixels [1] */
    double radius;                    /* march radius R in view units; the screen radius is
                                         R_px = R / (z |(dx/fx, dy/fy)|) (orthographic
                                         R / |(dx sx, dy sy)|) [the falloff's support; the whole
                                         buffer for unbounded falloffs] */
    double max_radius_px;             /* cap on R_px [the buffer diagonal] */
    hfvis_falloff falloff;            /* [NONE] */
    hfvis_ssao_tangent tangent;       /* REAL or FIXED [REAL] */
    double fixed_sin_t;               /* [-0.85], as hfvis_lsao_options */
    hfvis_ssao_sampling sampling;     /* [NEAREST]: snapped texels (BSD08) */
    hfvis_ssao_plane plane;           /* [EXACT] */
    hfvis_hbao_jitter jitter;         /* [NONE]; custom directions allow only NONE */
    uint32_t seed;                    /* jitter seed */
} hfvis_hbao_options;

HFVIS_API hfvis_hbao_options hfvis_hbao_options_default(void);

/* The options with every default filled in (radius and max_radius_px stay 0 = per buffer).
 * HFVIS_ERR_INVALID_ARGUMENT for NULL out, K outside 1..HFVIS_SSAO_MAX_DIRECTIONS, invalid
 * custom directions or weights, steps < 0, step_px / radius / max_radius_px negative or not
 * finite (step_px in [1/64, HFVIS_SSAO_MAX_SIZE] when given), an unknown enum value,
 * FIXED_HULL_REAL_EVAL (not an HBAO strategy), fixed_sin_t outside [-1, 1], jitter with custom
 * directions, an invalid falloff. in may be NULL. */
HFVIS_API hfvis_status hfvis_hbao_options_resolve(const hfvis_hbao_options *in,
                                                  hfvis_hbao_options *out);

/* Horizon-based ambient obscurance by ray marching (spec §4.1 HbaoPixel): for every inner
 * non-background pixel c with view point P and each direction D_k (looking TOWARD +D, so the
 * direction set should be symmetric to compare with LSAO), the samples
 *   uniform: c + (s - 1 + xi) (R_px/N) D, s = 1..N (xi = 1 without step jitter)
 *   custom:  c + s (step_x, step_y)
 * until one leaves the buffer, read as in LSAO (NEAREST: the snapped texel centre), deprojected
 * and put in the plane of P and D (EXACT: (Q.e1, Q.yhat) with yhat through P; PAPER: (Q.e1,
 * Q.z)); h = q - p, zenith u = -p/|p| (orthographic +y), Sin(h) = h.u/|h|; background samples
 * and samples coincident with P are skipped. The tangent: REAL = the receiver's normal in the
 * plane, t = (n2.y, -n2.x) (ahead), sin t = t.u/|t|; FIXED = fixed_sin_t. Per direction the
 * variant's value (INCREMENTAL sum, SINGLE_HORIZON, LARGEST_OCCLUDER, see the enum; the
 * running horizon starts at sin t), then
 *   ao = clamp( sum_k w_k value_k / sum_k w_k , 0, 1 ),   w_k = 1/K or the custom weights.
 * INCREMENTAL with falloff NONE and the real tangent is the SA obscurance of spec §1.2.
 * ao[y*ao_stride + x], inner pixels; background receivers 0. normals NULL: reconstructed with
 * hfvis_depth_normals when the tangent is REAL (1 block of 12*stride*height bytes; nothing is
 * allocated otherwise). Cost O(K N W H). Deterministic for a seed.
 * HFVIS_ERR_INVALID_ARGUMENT for invalid camera/options, NULL depth/ao, ao_stride < inner
 * width; HFVIS_ERR_OUT_OF_MEMORY. Outputs untouched on error. */
HFVIS_API hfvis_status hfvis_hbao(const hfvis_camera *cam, const float *depth,
                                  const float *normals, const hfvis_hbao_options *opts,
                                  float *ao, ptrdiff_t ao_stride);

/* ---- the screen-space ray-traced reference ([P4] §8; spec §5.11) --------------------------- */

/* Options of hfvis_ssao_raytrace. NULL or a zero struct = the defaults in brackets. */
typedef struct hfvis_ssao_rt_options {
    const hfvis_allocator *alloc;     /* reconstructed normals only; NULL = malloc/free */
    int rays;                         /* rays per pixel [256] */
    double thickness;                 /* depth-field thickness in view units; 0 = infinite (the
                                         continuous depth field of [P4] up to §11) [0] */
    hfvis_falloff falloff;            /* rho of the hit distance [NONE] */
    hfvis_ssao_sampling sampling;     /* the depth field [BILINEAR when thickness is 0,
                                         NEAREST otherwise: a finite-thickness field is not
                                         interpolated, [P4] §11] */
    int refine_iterations;            /* bisection steps on a BILINEAR hit [20] */
    double bias;                      /* ray origin P + bias z n, as a fraction of the receiver
                                         depth (covers float depth rounding) [1e-5] */
    double max_distance;              /* view units; rays go no farther (a miss) [the falloff's
                                         support; unbounded: until they leave the buffer] */
    uint32_t seed;                    /* the per-pixel Cranley-Patterson shift */
} hfvis_ssao_rt_options;

HFVIS_API hfvis_ssao_rt_options hfvis_ssao_rt_options_default(void);

/* The options with the defaults filled in (sampling resolved from thickness).
 * HFVIS_ERR_INVALID_ARGUMENT for NULL out, rays < 0, refine_iterations < 0 or > 64, thickness,
 * bias or max_distance negative or not finite, an unknown sampling, an invalid falloff. in may
 * be NULL. */
HFVIS_API hfvis_status hfvis_ssao_rt_options_resolve(const hfvis_ssao_rt_options *in,
                                                     hfvis_ssao_rt_options *out);

/* Screen-space ray-traced obscurance, the yardstick of [P4] §8 ("the best any method can do
 * with the screen-space data"): for every inner non-background pixel, R cosine-weighted rays
 * about the normal n (directions from the Hammersley set (r/R, radical inverse of r) shifted
 * per pixel by a hash of (x, y, seed), mod 1; disk radius sqrt(u1), azimuth 2 pi u2), from
 * O = P + bias z n. A ray is inside the depth field at X when its depth -X.z exceeds the field's
 * depth at its projection (and is less than it plus the thickness, if finite); background never
 * blocks. Instead of fixed-size march steps (which cut corners: about 2 % too little
 * obscurance at a cliff at 0.5 px steps), each ray is traversed exactly cell by cell in screen
 * space, the cell boundaries solved in closed form for the ray parameter: under NEAREST the
 * cells are texels, the field is constant and the ray depth linear in each, and the first
 * inside point is exact; under BILINEAR the cells lie between texel centres (the field is
 * known only there), each is tested at its entry, middle and exit, and a hit is refined by
 * bisection. The ray adds rho(distance from O to the first inside point). A ray that leaves
 * the buffer, passes behind the eye, rises above every depth, sinks below every depth plus the
 * thickness (finite thickness) or exceeds max_distance is a miss (unknown geometry counts as
 * empty). ao = (1/R) sum rho: a quasi-Monte-Carlo estimate of [P4] Eq. 1,
 * (1/pi) Int rho(d) max(0, n.w) dw - the COS convention (spec §1.2) - converging as R grows.
 * ao[y*ao_stride + x], inner pixels; background receivers 0. normals NULL: reconstructed with
 * hfvis_depth_normals (1 block of 12*stride*height bytes; nothing is allocated otherwise).
 * Deterministic for a seed. Cost O(W H R (W0 + H0)) at worst (cells per ray).
 * HFVIS_ERR_INVALID_ARGUMENT for invalid camera/options, NULL depth/ao, ao_stride < inner
 * width; HFVIS_ERR_OUT_OF_MEMORY. Outputs untouched on error. */
HFVIS_API hfvis_status hfvis_ssao_raytrace(const hfvis_camera *cam, const float *depth,
                                           const float *normals,
                                           const hfvis_ssao_rt_options *opts, float *ao,
                                           ptrdiff_t ao_stride);

/* ---- analytic depth buffers (spec §6 T1-T7) ---------------------------------------------- */

/* Height fields H(x, y) over the view-space plane z = -base_depth (x, y in view units, H toward
 * the camera), for the closed-form tests of spec §6. The orthographic camera sees them as true
 * height fields (zenith +Z); a perspective camera looking down -Z sees them in perspective
 * (vertical faces included). */
typedef enum hfvis_ssao_scene_kind {
    HFVIS_SSAO_SCENE_PLANE = 1,   /* T1: H = slope_x x + slope_y y */
    HFVIS_SSAO_SCENE_STEP = 2,    /* T4/T5: H = 0 for x < x0, height for x >= x0 (a cliff; with
                                     a large height, the wall of T4); the face at x = x0 */
    HFVIS_SSAO_SCENE_VGROOVE = 3, /* T6: H = |x - x0| tan(angle), apex line x = x0 */
    HFVIS_SSAO_SCENE_PIT = 4      /* T7: H = -sqrt(radius^2 - r^2) within radius of (x0, y0),
                                     else 0: a hemispherical pit, bottom at depth base + radius */
} hfvis_ssao_scene_kind;

typedef struct hfvis_ssao_scene {
    hfvis_ssao_scene_kind kind;
    double base_depth;        /* linear depth of the H = 0 plane, > 0 */
    double slope_x, slope_y;  /* PLANE */
    double x0, y0;            /* STEP / VGROOVE: the edge / apex x; PIT: the centre */
    double height;            /* STEP: the plateau height, base_depth - height > 0 */
    double angle;             /* VGROOVE: wall angle beta in (0, pi/2) */
    double radius;            /* PIT: > 0 */
} hfvis_ssao_scene;

/* Render a scene into a depth buffer (linear depth of the first surface along each pixel-centre
 * ray, exact in double, rounded to float; +INFINITY where a ray misses, e.g. a plane seen edge-on)
 * and, if normals is not NULL, its analytic unit normals facing the camera: PLANE
 * (-sx, -sy, 1)/|.|, STEP floor and plateau (0, 0, 1), face (-sign(height), 0, 0), VGROOVE
 * (-+tan, 0, 1)/|.| ((0, 0, 1) exactly on the apex), PIT (C - X)/radius inside (C the centre at
 * depth base_depth). Layout as the camera says (guard band included). Points on the step's
 * edge x = x0 belong to the plateau. HFVIS_ERR_INVALID_ARGUMENT for an invalid camera, NULL
 * scene or depth, an unknown kind, a non-finite parameter or one outside its range. */
HFVIS_API hfvis_status hfvis_ssao_scene_render(const hfvis_camera *cam,
                                               const hfvis_ssao_scene *scene, float *depth,
                                               float *normals);
