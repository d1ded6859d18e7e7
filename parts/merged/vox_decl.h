
/* ---- surface voxelization into the Volume Buffer ([G12] ch. 6 Alg. 5 and 6, ch. 5 Alg. 4;
 *      spec voxel §3.4-3.8, §3.13) ------------------------------------------------------- */

/* One voxel fragment: a sample point of a triangle written into one voxel. The sample point is
 * the centre of the pass's pixel (voxel[u] + 0.5, voxel[w] + 0.5) in grid space, u = (axis+1)
 * mod 3, w = (axis+2) mod 3, lifted onto the triangle's plane along `axis`. */
typedef struct hfvis_voxel_fragment {
    int voxel[3];          /* (i, j, k) of the voxel written, inside the grid */
    int axis;              /* sweep axis of the pass (0 x, 1 y, 2 z); voxel[axis] is the slab */
    uint32_t triangle;     /* index of the triangle in the mesh */
    float barycentric[3];  /* of the sample point w.r.t. the triangle's vertices 0, 1, 2; they
                              sum to 1 and lie in [0, 1] up to rounding (orthographic sweep: no
                              perspective correction, spec voxel §3.8) */
    float position[3];     /* world position of the sample point, sum_i barycentric_i v_i */
    float normal[3];       /* unit world-space geometric normal, (v1 - v0) x (v2 - v0) normalised */
} hfvis_voxel_fragment;

/* Attribute callback of the Volume Buffer ("pixel shader", [G12] §6.5): fill values[c] for the
 * channels c = 0 .. vol->channels-1 of fragment f. values holds HFVIS_VOLUME_MAX_CHANNELS floats,
 * all 0 on entry (writes past vol->channels are ignored, never out of bounds); after the call
 * each channel c is blended into the voxel with vol->blend[c] (hfvis_volume_write's equation).
 * The callback must not modify the volume being written. */
typedef void (*hfvis_voxel_fragment_fn)(const hfvis_voxel_fragment *f, float *values, void *user);

/* How a triangle is cut into the slabs of its sweep (spec voxel §3.4-3.6). Without an output
 * vertex limit all three give the voxel set of the pixel-centre rule; they differ in cost and,
 * with a limit, in the holes they leave. */
typedef enum hfvis_voxelize_method {
    /* Default. The common CPU rule (spec §3.4): each pass pixel (pu, pw) whose centre lies in the
     * projected triangle gets the voxel of slab floor(z), z = the triangle plane's depth at the
     * centre. One fragment per covered pixel. No vertex limit (max_output_vertices must be 0). */
    HFVIS_VOXELIZE_PIXEL_RULE = 0,
    /* Geometry-shader triangle slicing ([G12] Alg. 5, spec §3.5): the triangle is clipped
     * (Sutherland-Hodgman against both planes of a slab) into one convex piece per slab it
     * spans, lowest slab first, and each piece is rasterised (pixel centres, top-left rule on the
     * piece's own edges) into its slab. Equals the pixel rule except where a pixel centre lies
     * within rounding (about 1e-12 voxels) of a slab plane or a triangle edge. */
    HFVIS_VOXELIZE_GS_SLICING = 1,
    /* Pixel-shader fragment clipping ([G12] Alg. 6, spec §3.6): the whole triangle is rasterised
     * once per slab it spans, lowest first, and a fragment is kept only in the slab that holds its
     * depth, [k, k+1) (the half-open form of the thesis' open interval). Without a limit this is
     * the pixel rule exactly; the cost grows with the slabs spanned (n passes over the
     * triangle's rows; the discarded fragments are rejected per row range, not one by one). */
    HFVIS_VOXELIZE_FRAGMENT_CLIPPING = 2
} hfvis_voxelize_method;

/* Which sweep passes see a triangle. */
typedef enum hfvis_voxelize_axes {
    /* Default ([G12] §6.4): each triangle only in the pass of its dominant axis, the largest
     * |component| of its GRID-space normal (ties -> lowest axis index). */
    HFVIS_AXES_DOMINANT = 0,
    /* [G12] ch. 5 Alg. 4 (Chen-Fang slicing without XOR): the passes x, y, z, in that order,
     * each over every triangle not edge-on to it, all blended into the volume; with
     * HFVIS_BLEND_MAX this is exactly the thesis' three per-axis volumes merged with MAX
     * (hfvis_volume_merge of the three HFVIS_AXES_ONLY_* results). */
    HFVIS_AXES_ALL = 1,
    /* One pass only (one of Alg. 4's per-axis volumes; also the thesis' "one axis per frame"
     * amortisation, spec §2.3). */
    HFVIS_AXES_ONLY_X = 2,
    HFVIS_AXES_ONLY_Y = 3,
    HFVIS_AXES_ONLY_Z = 4
} hfvis_voxelize_axes;

/* Options of the surface voxelizers. Zero-initialised or NULL = defaults: pixel rule, dominant
 * axis, no vertex limit, occupancy only. */
typedef struct hfvis_voxelize_options {
    hfvis_voxelize_method method;   /* default HFVIS_VOXELIZE_PIXEL_RULE */
    hfvis_voxelize_axes axes;       /* default HFVIS_AXES_DOMINANT */
    int max_output_vertices;        /* the geometry shader's declared vertex limit V ([G12] §6.6,
                                       spec §3.7); 0 = unlimited (default). With V > 0 a triangle
                                       keeps only its hfvis_gs_max_slices(V, method ==
                                       FRAGMENT_CLIPPING) lowest slabs, counted from the slab of
                                       its lowest vertex (slabs outside the grid count too):
                                       the thesis' holes. GS slicing needs V >= 7, fragment
                                       clipping V >= 3; the pixel rule takes no limit. */
    hfvis_voxel_fragment_fn fragment; /* attribute callback; NULL: channel 0 is blended with 1
                                         (occupancy) and the other channels are not touched */
    void *user;                     /* passed to fragment */
    const hfvis_allocator *alloc;   /* unused: the surface voxelizers allocate nothing */
} hfvis_voxelize_options;

HFVIS_API hfvis_voxelize_options hfvis_voxelize_options_default(void);

/* Slabs a triangle keeps under a geometry-shader output limit of V vertices (spec §3.7):
 * GS slicing emits 3 + 4n vertices for n slabs, so floor((V - 3)/4) (V = 7, 11, 15, 19 ->
 * 1, 2, 3, 4); fragment clipping (pixel_clipping != 0) emits 3n, so floor(V/3) (V = 3, 6, 9 ->
 * 1, 2, 3). 0 when V is too small for one slab (and for V <= 0). */
HFVIS_API int hfvis_gs_max_slices(int max_output_vertices, int pixel_clipping);

/* Surface voxelization of a triangle soup into a Volume Buffer ([G12] ch. 6; ch. 5 Alg. 4 with
 * HFVIS_AXES_ALL). Grid space is g = (p - origin)/cell per axis, so a voxel is a unit cube; a
 * pass along axis a (u = a+1, w = a+2 mod 3) projects onto the (u, w) plane, whose pixel
 * (pu, pw) has its centre at (pu + 0.5, pw + 0.5), and cuts along a into slabs [k, k+1).
 * Rules, exactly (spec §3.4, §3.12):
 *   - The grid-space normal n = (g1 - g0) x (g2 - g0) in double; n == 0: the triangle is
 *     degenerate and skipped; in a pass with n_a == 0 it is edge-on and skipped. A triangle with
 *     a grid coordinate beyond 1e150 voxels is skipped; a pass whose depth slope |n_u/n_a| or
 *     |n_w/n_a| exceeds 1e100 is skipped (edge-on to precision).
 *   - Coverage: a pixel centre is inside when every edge function (2D cross product, evaluated
 *     from the edge's lexicographically smaller endpoint, so that the two triangles of a shared
 *     edge see exactly opposite values) is > 0, or == 0 on a top-left edge (in the (u, w) plane,
 *     w up, counter-clockwise: an edge going down, or horizontal going left). A closed mesh
 *     covers each pixel centre of one pass once.
 *   - Depth: z = (Z0 + dz/dw (w - W0)) + dz/du (u - U0) from vertex 0, clamped to the
 *     triangle's depth range; slab floor(z) (a depth exactly on a boundary goes to the upper
 *     slab); slabs outside [0, dims[a]) are discarded, as are pixels outside the grid.
 *   - GS slicing clips with the slab planes; each crossing point is computed from the original
 *     edge with its lower-depth endpoint first, so neighbouring pieces and neighbouring triangles
 *     share it exactly; degenerate (zero-area) pieces are skipped.
 * Every fragment written (a covered pixel landing in a grid voxel) calls opts->fragment and
 * blends its values with the per-channel blends of vol (see hfvis_voxel_fragment_fn). With
 * HFVIS_AXES_DOMINANT each (triangle, pixel) gives at most one fragment; within one triangle
 * and pass no voxel is written twice. Order: triangle by triangle in index order (with
 * HFVIS_AXES_ALL: pass x over all triangles, then y, then z); within one triangle and pass the
 * order is unspecified. vol must have been set up by hfvis_volume_init (any channels and
 * blends); it is not cleared first, so several meshes or calls accumulate.
 * fragments_written (may be NULL) receives the number of fragments blended.
 * opts may be NULL. The mesh arrays must not overlap vol->data.
 * Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for a NULL or invalid mesh (hfvis_mesh), a
 * NULL vol or vol->data, an invalid vol->grid, channels outside 1..32, an unknown blend in a
 * used channel, an unknown method or axes, max_output_vertices < 0, > 0 with the pixel rule,
 * or too small for one slab (hfvis_gs_max_slices == 0); vol and *fragments_written are
 * untouched then. Allocates nothing. Cost: O(T + rows + fragments) per pass, never
 * O(grid volume): per pixel row the covered span is found from the edge functions (each is
 * monotone along the row, so about two evaluations per edge settle its end; rows narrower than
 * 4 pixels are simply tested pixel by pixel) and the slab changes along it likewise (or per
 * pixel when the depth slope exceeds 1/4), then the row's fragments are written without being
 * tested again. Fragment clipping re-rasterises the rows once per slab spanned (Alg. 6's cost);
 * GS slicing rasterises each slab piece over its own rows (Alg. 5's).
 * Exact: equals hfvis_voxelize_surface_reference bit for bit (same voxels, values, count),
 * given IEEE double arithmetic without excess precision (FLT_EVAL_METHOD 0, as on SSE2 and
 * AArch64) and without FMA contraction (-ffp-contract=off). */
HFVIS_API hfvis_status hfvis_voxelize_surface(const hfvis_mesh *mesh, hfvis_volume *vol,
                                              const hfvis_voxelize_options *opts,
                                              size_t *fragments_written);

/* Oracle of hfvis_voxelize_surface, by definition per voxel: for every triangle and pass (same
 * order), every slab k the method allows and every pixel of the triangle's (for GS slicing: the
 * slab piece's) pixel bounding box inside the grid, test the voxel directly in double:
 *   pixel rule:        the centre is inside the projected triangle and k <= z < k+1;
 *   fragment clipping: the same, for each slab of the capped range [kmin, kmin + S - 1] (Alg. 6
 *                      literally: the whole triangle per slab, fragments outside discarded);
 *   GS slicing:        the centre is inside the slab-k piece (the same Sutherland-Hodgman
 *                      clip) under its own edges' top-left rule (Alg. 5).
 * Same arguments, errors and outputs as hfvis_voxelize_surface. Cost: O(sum over triangles of
 * the voxels of their bounding boxes). */
HFVIS_API hfvis_status hfvis_voxelize_surface_reference(const hfvis_mesh *mesh, hfvis_volume *vol,
                                                        const hfvis_voxelize_options *opts,
                                                        size_t *fragments_written);

/* Binary surface voxelization: occ[(k*dims[1] + j)*dims[0] + i] = 1 for every voxel that
 * hfvis_voxelize_surface would write with the same options, 0 elsewhere (the whole array is
 * written). opts->fragment is ignored. occ must hold dims[0]*dims[1]*dims[2] bytes and must
 * not overlap the mesh. Errors as hfvis_voxelize_surface (a NULL or invalid grid, NULL occ);
 * occ untouched then. Allocates nothing. */
HFVIS_API hfvis_status hfvis_voxelize_occupancy(const hfvis_mesh *mesh,
                                                const hfvis_volume_grid *grid,
                                                const hfvis_voxelize_options *opts, uint8_t *occ);

/* Ready-made attribute callbacks (hfvis_voxel_fragment_fn), the thesis' Volume Buffer channels
 * ([G12] §6.5, spec §3.8). */

/* values[0] = 1 (occupancy). user unused. */
HFVIS_API void hfvis_voxel_fragment_occupancy(const hfvis_voxel_fragment *f, float *values,
                                              void *user);
/* values[0] = 1, values[1..3] = the unit world normal (a volume of 4 channels; with MAX blend
 * a voxel keeps the component-wise maximum, the thesis' GPU behaviour; use ADD with an ADD
 * occupancy channel to average). user unused. */
HFVIS_API void hfvis_voxel_fragment_normal_occupancy(const hfvis_voxel_fragment *f, float *values,
                                                     void *user);

/* Direct irradiance E (RGB, with shadows if the caller tests them) arriving at a surface point
 * with unit normal n; used by hfvis_voxel_fragment_attributes for the radiance channels. */
typedef void (*hfvis_voxel_irradiance_fn)(const float position[3], const float normal[3],
                                          float rgb[3], void *user);

/* Attribute selection for hfvis_voxel_fragment_attributes: the selected attributes are packed
 * in this order into consecutive channels from 0 (hfvis_voxel_attribute_channel). */
#define HFVIS_VOXEL_ATTR_OCCUPANCY 1u /* 1 channel: 1 */
#define HFVIS_VOXEL_ATTR_NORMAL 2u    /* 3 channels: unit world normal (x, y, z) */
#define HFVIS_VOXEL_ATTR_ALBEDO 4u    /* 3 channels: RGB albedo */
#define HFVIS_VOXEL_ATTR_RADIANCE 8u  /* 3 channels: RGB outgoing radiance, Lambertian
                                         (DESIGN §2): albedo * E / pi + emission */

/* user of hfvis_voxel_fragment_attributes. Zero-initialised = occupancy only. */
typedef struct hfvis_voxel_attributes {
    unsigned flags;                  /* HFVIS_VOXEL_ATTR_* bits; 0 = OCCUPANCY; unknown bits
                                        are ignored */
    const float *albedo;             /* 3 floats per triangle, or NULL = albedo 1 (white) */
    const float *emission;           /* 3 floats per triangle: emitted radiance, NULL = none */
    hfvis_voxel_irradiance_fn irradiance; /* direct irradiance; NULL = 0 (radiance = emission) */
    void *irradiance_user;
} hfvis_voxel_attributes;

/* First channel of `attribute` (one HFVIS_VOXEL_ATTR_* bit) in the packing of `flags`
 * (0 = occupancy only), or -1 if flags does not select it. The channel count of a layout is
 * hfvis_voxel_attribute_channel(flags, 0): 1 per occupancy, 3 per other attribute. */
HFVIS_API int hfvis_voxel_attribute_channel(unsigned flags, unsigned attribute);

/* The general attribute callback: writes the attributes selected by
 * ((const hfvis_voxel_attributes *)user)->flags, packed from channel 0 (see
 * hfvis_voxel_attribute_channel): occupancy 1, the unit normal, the triangle's albedo, and
 * radiance = albedo * E(position, normal) / pi + emission (the thesis' "direct lighting with
 * shadows and emission", [G12] §6.5, ch. 5 §5.5.1). user NULL = occupancy only. The
 * per-triangle arrays must hold 3 floats for every triangle of the mesh voxelized. */
HFVIS_API void hfvis_voxel_fragment_attributes(const hfvis_voxel_fragment *f, float *values,
                                               void *user);
