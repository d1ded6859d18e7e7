
/* ---- reference rasterizer: triangles -> depth, normal, triangle id, barycentrics ----------- */

/* Largest image side the rasterizer accepts (width, height <= 32768; past it HFVIS_ERR_LIMIT).
 * With 8 sub-pixel bits and the guard band below every edge function fits in 60 bits. */
#define HFVIS_RASTER_MAX_SIZE 32768
/* Vertices are snapped to 1/256 pixel (the D3D11 / GL 8-bit sub-pixel precision). */
#define HFVIS_RASTER_SUBPIXEL_BITS 8
/* Guard band: geometry is clipped in clip space only where it leaves the window coordinate
 * range [-2^19, 2^19] pixels about the image centre (x/w and y/w beyond +-2^20/width and
 * +-2^20/height in NDC); inside that range triangles are rasterized unclipped (x/y). */
#define HFVIS_RASTER_GUARD_PIXELS 524288.0

/* Which faces are discarded. Front-facing = the vertices v0, v1, v2 appear counter-clockwise on
 * screen (y up), i.e. the face normal (v1 - v0) x (v2 - v0) points toward the viewer (the
 * hfvis_mesh convention and GL's default glFrontFace(GL_CCW)). */
typedef enum hfvis_cull_mode {
    HFVIS_CULL_NONE = 0,  /* default: both sides rasterized */
    HFVIS_CULL_BACK = 1,  /* faces pointing away from the viewer discarded */
    HFVIS_CULL_FRONT = 2  /* faces pointing toward the viewer discarded */
} hfvis_cull_mode;

/* Coordinate frame of the normal output plane. */
typedef enum hfvis_normal_space {
    HFVIS_NORMAL_WORLD = 0, /* default: the mesh's frame */
    HFVIS_NORMAL_EYE = 1    /* rotated by the view matrix (eye space: x right, y up, +z toward
                               the viewer), as the screen-space AO routines expect */
} hfvis_normal_space;

/* Options of hfvis_rasterize and hfvis_rasterize_reference. NULL or a zero struct = defaults. */
typedef struct hfvis_raster_options {
    const hfvis_allocator *alloc;     /* scratch; NULL = malloc/free */
    hfvis_cull_mode cull;             /* default HFVIS_CULL_NONE */
    hfvis_normal_space normal_space;  /* default HFVIS_NORMAL_WORLD */
    int normal_toward_viewer;         /* 0 (default): the face normal as the winding gives it;
                                         1: negated on back faces, so it always faces the
                                         viewer (two-sided lighting). Other values invalid. */
} hfvis_raster_options;

HFVIS_API hfvis_raster_options hfvis_raster_options_default(void);

/* The output planes of a rasterization, each width*height pixels (per-pixel components
 * interleaved), pixel (x, y) at index y*width + x, row 0 at the TOP (hfvis_view). Any pointer may
 * be NULL (plane not wanted); the planes must not overlap each other. Every requested plane is
 * written at every pixel; "empty" pixels (no fragment) get the values in brackets. */
typedef struct hfvis_raster_outputs {
    float *linear_depth;      /* positive linear view depth -z_eye of the visible surface, world
                                 units (perspective: along the view axis, not the ray length;
                                 orthographic with near <= 0: may be <= 0) [+INFINITY] */
    float *window_depth;      /* GL window depth zw = (z_ndc + 1)/2 in [0, 1]; the depth test
                                 runs on it in double [1] */
    float *normal;            /* 3 floats per pixel: the unit geometric face normal
                                 normalize((v1 - v0) x (v2 - v0)) of the visible triangle, frame
                                 and sign per the options [0, 0, 0] */
    uint32_t *triangle_id;    /* index of the visible triangle in the mesh [HFVIS_NO_TRIANGLE] */
    float *barycentric;       /* 2 floats per pixel: (b1, b2), the perspective-correct
                                 barycentric coordinates of the visible point with respect to v1
                                 and v2 of its triangle (point = (1-b1-b2) v0 + b1 v1 + b2 v2,
                                 as ray-tracing u, v); exact at the pixel centre, so at a
                                 centre within the 1/256-pixel snapping of an edge they may lie
                                 outside [0, 1] by that much [0, 0] */
    uint32_t *coverage_count; /* fragments per pixel: how many non-culled triangles cover the
                                 pixel within the depth range, before the depth test (the depth
                                 complexity; watertightness checks) [0] */
} hfvis_raster_outputs;

/* Rasterize a triangle mesh seen through a view: the visible triangle at every pixel centre and
 * its depth, normal and barycentrics, as OpenGL/D3D hardware does it (the scenes of the
 * incremental voxelizer and the screen-space issues are rendered with it).
 * Pipeline (spec voxel §0 conventions): vertices go to clip space c = proj*view*v in double;
 * triangles entirely outside one frustum plane are skipped; the rest are clipped in homogeneous
 * clip space against the near plane z = -w (Sutherland-Hodgman; crossing triangles are cut,
 * never dropped) and, only where they leave the guard band, against the guard-band planes
 * (HFVIS_RASTER_GUARD_PIXELS), then fan-triangulated. Vertices snap to 1/256 pixel (round half
 * up) in window coordinates (x right, y DOWN, pixel (x, y) centred at (x + 1/2, y + 1/2)), and
 * coverage is decided by exact 64-bit integer edge functions at pixel centres with the D3D
 * TOP-LEFT fill rule (a centre exactly on an edge belongs to the triangle only if the edge is a
 * top edge, horizontal with the triangle below it, or a left edge): triangles that share an edge
 * never both cover a pixel and never leave a crack, so over a closed mesh every pixel is covered
 * exactly (depth complexity) times. Clip-generated vertices depend only on the shared edge, so
 * this holds across clipped triangles too. Zero-area triangles (world space, or edge-on: zero
 * homogeneous determinant) are never rasterized; culling uses the sign of the determinant of the
 * clip-space (x, y, w) rows (the facing as seen from the eye).
 * Per fragment, the perspective-correct barycentrics of the ORIGINAL triangle at the exact pixel
 * centre (NDC per hfvis_view) come from its homogeneous 2D edge functions (Olano & Greer 1997)
 * in double - independent of snapping and clipping - and give zw = (z_ndc + 1)/2 and the linear
 * depth -z_eye = -(sum b_i z_eye_i). Fragments with zw outside [0, 1] are dropped (far plane:
 * beyond it; near: rounding at the clip line). Depth test LESS on zw in double; triangles are
 * drawn in index order, so on equal zw the lower triangle id wins.
 * The view must be a GL perspective or orthographic view as hfvis_view describes (after near
 * clipping every w must be positive).
 * opts may be NULL. out's planes: see hfvis_raster_outputs (all NULL: nothing to do, HFVIS_OK).
 * Returns HFVIS_OK; HFVIS_ERR_INVALID_ARGUMENT for a NULL mesh/view/outputs, an invalid mesh
 * (hfvis_mesh), width or height < 1, non-finite matrices, non-finite or unordered near/far
 * (near >= far; near <= 0 for a perspective view), an unknown cull mode or normal space, or
 * normal_toward_viewer not 0/1; HFVIS_ERR_LIMIT if width or height > HFVIS_RASTER_MAX_SIZE or
 * triangle_count >= HFVIS_NO_TRIANGLE; HFVIS_ERR_OUT_OF_MEMORY if the scratch allocation fails.
 * On error the outputs are untouched.
 * Memory: one scratch block of 8*(width*height + width + height + 7*vertex_count) bytes (the
 * double depth buffer and the clip-space and snapped vertices), none when every plane is NULL.
 * Cost: O(V + T + covered bounding-box pixels). Deterministic (bit-exact on one build). */
HFVIS_API hfvis_status hfvis_rasterize(const hfvis_mesh *mesh, const hfvis_view *view,
                                       const hfvis_raster_options *opts,
                                       const hfvis_raster_outputs *out);

/* The rasterizer's oracle: one ray per pixel centre against every triangle. The ray runs
 * through the pixel centre's near- and far-plane points (inverse of proj*view, NDC per
 * hfvis_view); a triangle is hit when the three scalar triple products d.((v_i - o) x
 * (v_i+1 - o)) (double, world space) have one sign (zeros included: edges and vertices count),
 * and their normalised values are the perspective-correct barycentrics. Facing: front when
 * d . n < 0 (n = (v1 - v0) x (v2 - v0)); culling as in hfvis_rasterize. zw and the linear depth
 * follow from the barycentrics and the clip/eye coordinates of the vertices exactly as in
 * hfvis_rasterize; hits with clip w <= 0 or zw outside [0, 1] are ignored; the closest zw wins,
 * ties to the lower triangle id. coverage_count counts the hits (inclusive edges: a ray through
 * a shared edge counts both triangles). Same arguments, outputs and errors as hfvis_rasterize
 * (plus HFVIS_ERR_INVALID_ARGUMENT when proj*view is singular); allocates nothing.
 * Agreement: equal triangle ids at every pixel whose centre is farther than about 1/256 pixel
 * from the projected edges (snapping), depth within rounding (1e-12 relative in double).
 * Cost: O(width*height*T). */
HFVIS_API hfvis_status hfvis_rasterize_reference(const hfvis_mesh *mesh, const hfvis_view *view,
                                                 const hfvis_raster_options *opts,
                                                 const hfvis_raster_outputs *out);
