
/* ========================================================================================== */
/* voxel.c - binary voxelizers: conservative (SAT), solid (parity), bitmask; .binvox and raw   */
/* ========================================================================================== */

/* All three voxelizers below decide in GRID SPACE: vertex p becomes g = (p - origin) / cell,
 * per axis in double (one division per coordinate, the same expression in every routine and its
 * reference), so voxel (i, j, k) is the unit cube [i, i+1] x [j, j+1] x [k, k+1] with centre
 * (i + 0.5, j + 0.5, k + 0.5). Occupancy outputs are uint8 per voxel in the grid's linear order
 * (k*dims[1] + j)*dims[0] + i, 1 = occupied, 0 = empty; the whole array is overwritten.
 * Common errors: HFVIS_ERR_INVALID_ARGUMENT for a NULL or invalid mesh (hfvis_mesh) or grid
 * (hfvis_volume_grid), a NULL output or an unknown enum in the options (outputs untouched);
 * HFVIS_ERR_LIMIT when a vertex lies more than 2^60 cells from the grid origin (the exact
 * predicates would overflow); HFVIS_ERR_OUT_OF_MEMORY when scratch cannot be allocated (nothing
 * leaked, outputs untouched). Degenerate triangles (zero grid-space normal) are skipped. */

/* The axis along which hfvis_voxelize_solid casts its parity rays. */
typedef enum hfvis_parity_axis {
    HFVIS_PARITY_AXIS_DEFAULT = 0, /* = HFVIS_PARITY_AXIS_Z */
    HFVIS_PARITY_AXIS_X = 1,
    HFVIS_PARITY_AXIS_Y = 2,
    HFVIS_PARITY_AXIS_Z = 3
} hfvis_parity_axis;

/* Options of the binary voxelizers (NULL or all-zero = defaults). */
typedef struct hfvis_binary_voxel_options {
    const hfvis_allocator *alloc; /* scratch; NULL = malloc/free */
    hfvis_parity_axis axis;       /* solid only: ray direction (default z) */
    int allow_open;               /* solid only: 0 (default) = a column crossed an odd number of
                                     times (an open mesh) fails with HFVIS_ERR_FORMAT; nonzero =
                                     such columns are left empty and the others are filled */
} hfvis_binary_voxel_options;

/* The defaults: alloc NULL, axis HFVIS_PARITY_AXIS_Z, allow_open 0. */
HFVIS_API hfvis_binary_voxel_options hfvis_binary_voxel_options_default(void);

/* Triangle / axis-aligned box overlap by the separating-axis theorem (Akenine-Moller 2001;
 * spec voxel §3.9): the box (centre, half sizes half[a] >= 0) and the triangle (v0, v1, v2)
 * overlap unless one of 13 axes separates them: the 3 box normals (bounding boxes), the 9
 * cross products e_a x f_j of the box axes with the triangle edges f0 = v1-v0, f1 = v2-v1,
 * f2 = v0-v2, and the triangle normal n = f0 x f1. Both are CLOSED sets: touching (a vertex,
 * edge or face on the box boundary) counts as overlap, so a triangle lying in the plane shared
 * by two voxels overlaps both. Zero axes (an edge parallel to a box axis, a degenerate
 * triangle) never separate, so a degenerate triangle is tested as the segment or point it is.
 * Evaluated in double with a fixed expression per axis (documented in voxel.c, 5a); exact up to
 * the rounding of those expressions, which hfvis_voxelize_conservative reproduces bit for bit.
 * Inputs must be finite (otherwise the result is unspecified, but no undefined behaviour).
 * Returns 1 when they overlap, 0 when an axis separates them. */
HFVIS_API int hfvis_triangle_box_overlap(const double center[3], const double half[3],
                                         const double v0[3], const double v1[3],
                                         const double v2[3]);

/* Conservative surface voxelization: occ[v] = 1 for every voxel whose closed cube the triangle
 * overlaps by hfvis_triangle_box_overlap (grid space: centre (i+.5, j+.5, k+.5), half 0.5), for
 * every triangle; 26-separating, a superset of the pixel-centre voxelizations (spec §3.4, §3.9).
 * Only the voxels of the triangle's bounding-box range are candidates: along each axis
 * i = max(0, ceil(min) - 1) .. min(dims-1, floor(max)) (the voxels whose closed extent meets
 * the triangle's); the result is EXACTLY the set hfvis_voxelize_conservative_reference gives.
 * Method (Schwarz & Seidel 2010): per triangle, the normal, the plane's radius and the nine
 * edge axes are set up once; per column of the dominant projection the three 2D edge axes are
 * tested once, the interval of layers inside the plane slab is found from the plane equation
 * and fixed up with the SAT's own expressions, and only the two ends of that interval are
 * tested against the six remaining axes (every axis is monotone along the column in floating
 * point, so the passing layers form an interval). Cost O(T + columns + voxels written) plus
 * clearing occ. occ: vx = dims[0]*dims[1]*dims[2] bytes, overwritten. count (may be NULL):
 * occupied voxels. opts: only alloc is used. One allocation (vertex_count*24 bytes).
 * Errors: see the section comment. */
HFVIS_API hfvis_status hfvis_voxelize_conservative(const hfvis_mesh *mesh,
                                                   const hfvis_volume_grid *grid,
                                                   const hfvis_binary_voxel_options *opts,
                                                   uint8_t *occ, size_t *count);

/* The oracle and baseline of hfvis_voxelize_conservative: for every triangle, for every voxel
 * of its bounding-box range, one call of hfvis_triangle_box_overlap (nothing precomputed).
 * Same arguments, result and errors; no allocation. Cost O(sum over triangles of bbox voxels). */
HFVIS_API hfvis_status hfvis_voxelize_conservative_reference(const hfvis_mesh *mesh,
                                                             const hfvis_volume_grid *grid,
                                                             const hfvis_binary_voxel_options *opts,
                                                             uint8_t *occ, size_t *count);
