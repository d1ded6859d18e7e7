
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
 * the triangle's); the result is EXACTLY the set hfvis_voxelize_conservative_reference gives,
 * voxel for voxel, including ties (faces on voxel boundaries, vertices on voxel corners).
 * Method (Schwarz & Seidel 2010, made exact): per triangle, in the frame of its dominant axis,
 * each of the nine edge axes becomes a bound on two voxel-centre coordinates and the plane axis
 * a bound on the layers of each column; rows of columns, then the layer interval of each
 * column, follow from these bounds evaluated in double with a safety margin (2^-30 of the
 * coordinate scale, far above the rounding of either side), so a voxel decided by the margin
 * is decided as the SAT decides it, and the few voxels within a margin of a bound are decided
 * by the SAT's own expressions. Bounding boxes of at most 16 voxels use the SAT directly on
 * the voxels not set yet. Cost O(T + rows + columns + voxels written) plus O(grid volume / 64)
 * to clear and emit; the baseline is O(sum of bounding-box voxels). occ: dims[0]*dims[1]*dims[2]
 * bytes, overwritten. count (may be NULL): occupied voxels. opts: only alloc is used. Two
 * allocations: vertex_count*24 bytes (vertices in grid space) and ceil(dims/4)^3 * 8 bytes (a
 * bit per voxel in 4x4x4 bricks). Errors: see the section comment. */
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

/* Solid voxelization by parity (spec §3.9: Chen & Fang 1998; Eisemann & Decoret 2008):
 * occ[v] = 1 when the centre of voxel v lies inside the mesh, decided by the parity of the
 * crossings of the line through the voxel centres along opts->axis (default z) below the
 * centre. A crossing is a triangle covering the column's centre point (u, w) = (iu+.5, iw+.5)
 * in projection: vertices are moved to that point and the three edge functions are evaluated
 * with their EXACT sign (a double product test, falling back to Dekker's error-free products on
 * ties), and an edge passing exactly through the point counts for the triangle on one side only
 * (the point moved by an infinitesimal (eps, eps^2) must be inside: a top-left rule), so a
 * shared edge or vertex is counted once where the surface passes through and 0 or 2 times where
 * it folds. Each crossing at depth z toggles every voxel whose centre is above z (k + 0.5 > z;
 * a centre exactly on the surface counts as below it): one toggle per crossing into occ, then a
 * prefix XOR along the axis (O(grid volume)). Orientation does not matter; nested closed
 * surfaces alternate inside/outside; self-intersecting ones give their crossing parity.
 * The mesh must be closed: with exact signs every line crosses a closed surface an even number
 * of times, so a column crossed an odd number of times proves an open mesh: HFVIS_ERR_FORMAT
 * (occ untouched) unless opts->allow_open, which leaves such columns empty and fills the others
 * (a hole lets the columns through it fall out; it cannot flood the rest). Triangles with a
 * zero grid-space normal are ignored; edge-on triangles (zero projected area) never cross.
 * opts: alloc, axis (HFVIS_ERR_INVALID_ARGUMENT for an unknown value), allow_open.
 * count (may be NULL): occupied voxels. One allocation (dims[u]*dims[w] bytes of column
 * parities). Cost: O(T + covered column centres) twice (a checking pass first unless
 * allow_open) + O(grid volume). Errors: see the section comment. */
HFVIS_API hfvis_status hfvis_voxelize_solid(const hfvis_mesh *mesh, const hfvis_volume_grid *grid,
                                            const hfvis_binary_voxel_options *opts, uint8_t *occ,
                                            size_t *count);

/* Oracle of hfvis_voxelize_solid, per voxel centre c independently of any axis: the generalized
 * winding number w(c) = (1/4pi) sum over triangles of their signed solid angle at c (Van
 * Oosterom & Strackee; Jacobson et al. 2013) in double, and occ = 1 when round(|w|) is odd.
 * On a consistently oriented closed mesh this is the parity of hfvis_voxelize_solid except for
 * centres within rounding of the surface. Never fails on open meshes (no HFVIS_ERR_FORMAT).
 * opts->axis is only checked. Same other arguments and errors; allocates nothing.
 * Cost O(voxels * T) (small grids only). */
HFVIS_API hfvis_status hfvis_voxelize_solid_reference(const hfvis_mesh *mesh,
                                                      const hfvis_volume_grid *grid,
                                                      const hfvis_binary_voxel_options *opts,
                                                      uint8_t *occ, size_t *count);

/* *result = 1 when the mesh's index structure is closed and consistently oriented: every
 * directed edge a -> b (a != b) of a triangle occurs exactly once and its reverse b -> a occurs
 * exactly once too (so every undirected edge is used by exactly two triangles in opposite
 * directions); 0 otherwise (including triangles with a repeated index). An empty mesh is
 * watertight. Only indices are compared: a soup whose coincident corners are separate vertices
 * is not watertight here (hfvis_voxelize_solid works on positions and accepts it).
 * Returns HFVIS_ERR_INVALID_ARGUMENT for a NULL result or an invalid mesh,
 * HFVIS_ERR_OUT_OF_MEMORY if the edge array (24 bytes per triangle, one allocation from alloc,
 * NULL = malloc) cannot be allocated; *result untouched then. Cost O(T log T). */
HFVIS_API hfvis_status hfvis_mesh_is_watertight(const hfvis_mesh *mesh,
                                                const hfvis_allocator *alloc, int *result);

/* Words of a bitmask volume (hfvis_voxelize_bitmask): dims[0]*dims[1]*ceil(dims[2]/32);
 * 0 for a NULL or invalid grid. */
HFVIS_API size_t hfvis_bitmask_words(const hfvis_volume_grid *grid);

/* Bitmask surface voxelization (Eisemann & Decoret 2006, run from the three axis viewpoints;
 * spec §3.9, §6): for each axis a (u = a+1, w = a+2 mod 3), every non-degenerate triangle is
 * rasterized into the (u, w) pixel grid with the pixel-centre rule of hfvis_voxelize_solid (the
 * watertight top-left coverage), the depth z along a of each covered centre is interpolated
 * (barycentrics, clamped to the triangle's depth range) and the bit of slab floor(z) (a depth
 * on a boundary goes to the upper slab; slabs outside [0, dims[a]) are dropped) is ORed in; the
 * three passes are ORed. This is the voxel set of the thesis' three-axis Chen-Fang variant
 * (hfvis_voxelize_occupancy with HFVIS_AXES_ALL and the pixel rule), up to centres within
 * rounding of an edge or depths within rounding of a slab boundary, and a subset of
 * hfvis_voxelize_conservative (the triangle point of a fragment lies in its voxel).
 * Layout (the slicemap layout of Eisemann & Decoret 2008): bits packed along z, 32 per word,
 * one run of W = ceil(dims[2]/32) words per (i, j) column: voxel (i, j, k) is bit (k & 31) of
 * bits[(j*dims[0] + i)*W + (k >> 5)]; bits for k >= dims[2] are 0. bits must hold
 * hfvis_bitmask_words(grid) words (overwritten). count (may be NULL): set bits. opts: unused
 * (may be NULL). Allocates nothing. Cost O(T + covered pixels of the three projections).
 * Errors: see the section comment. */
HFVIS_API hfvis_status hfvis_voxelize_bitmask(const hfvis_mesh *mesh, const hfvis_volume_grid *grid,
                                              const hfvis_binary_voxel_options *opts, uint32_t *bits,
                                              size_t *count);

/* Unpacks a bitmask volume into uint8 occupancy (grid order, 0/1). Returns
 * HFVIS_ERR_INVALID_ARGUMENT for NULL or an invalid grid. */
HFVIS_API hfvis_status hfvis_bitmask_to_occupancy(const hfvis_volume_grid *grid,
                                                  const uint32_t *bits, uint8_t *occ);

/* .binvox (the voxel format of P. Min's binvox / viewvox; header "#binvox 1", "dim D D D",
 * "translate tx ty tz", "scale s", "data", then run-length pairs (value, count 1..255) over the
 * D^3 voxels with x slowest, then z, then y fastest: binvox index x*D*D + z*D + y is hfvis voxel
 * (i, j, k) = (x, y, z)). Voxel (x, y, z) spans translate + (scale/D)*[x, x+1] x [y, y+1] x
 * [z, z+1], so translate = origin and scale = D*cell. binvox grids are cubes with cubic voxels:
 * a grid is written padded with empty voxels to the cube of its largest side D, with
 * translate = origin and scale = D * max(cell[a]) (non-cubic cells are approximated by the
 * largest). Numbers are written locale-independently with the fewest digits that read back
 * exactly (up to 15), else 17 digits. Any nonzero occupancy byte is written as 1. */

/* Exact size in bytes of the encoding of (grid, occ) (scans occ for the runs); 0 for NULL, an
 * invalid grid, a cube of more than HFVIS_VOLUME_MAX_VOXELS voxels or a scale D*cell that
 * overflows a double. */
HFVIS_API size_t hfvis_binvox_encode_size(const hfvis_volume_grid *grid, const uint8_t *occ);

/* Encodes into out (capacity bytes); *written = bytes written. Returns HFVIS_ERR_INVALID_ARGUMENT
 * for NULL or an invalid grid, HFVIS_ERR_LIMIT when the padded cube exceeds
 * HFVIS_VOLUME_MAX_VOXELS or its scale overflows, HFVIS_ERR_BUFFER_TOO_SMALL below hfvis_binvox_encode_size. */
HFVIS_API hfvis_status hfvis_binvox_encode(const hfvis_volume_grid *grid, const uint8_t *occ,
                                           void *out, size_t capacity, size_t *written);

/* Decodes a .binvox held in memory (strict): "#binvox 1" (or 2: values 0..255) on the first
 * line; then lines "dim", "translate", "scale" in any order, each at most once ("dim"
 * required, three equal positive integers; "translate" three finite numbers, default 0;
 * "scale" one positive finite number, default 1), blanks between fields, "\n" or "\r\n" line
 * ends; then "data" and its line end; then exactly the pairs covering D^3 voxels: version 1
 * values 0 or 1, counts 1..255, no run past the end, nothing after the last pair.
 * On success *grid = D^3 voxels, origin = translate, cell = scale/D, and *occ = D^3 bytes in
 * hfvis order (the file's values), allocated with alloc (NULL = malloc; free with
 * hfvis_free(alloc, *occ)). The runs are validated before allocating (one allocation).
 * Returns HFVIS_ERR_INVALID_ARGUMENT for NULL data, grid or occ; HFVIS_ERR_FORMAT for any
 * malformation (also a non-cubic dim or a scale/D that is not a valid cell); HFVIS_ERR_LIMIT
 * when D^3 exceeds HFVIS_VOLUME_MAX_VOXELS; HFVIS_ERR_OUT_OF_MEMORY. Outputs untouched on
 * error. */
HFVIS_API hfvis_status hfvis_binvox_decode(const void *data, size_t size,
                                           const hfvis_allocator *alloc, hfvis_volume_grid *grid,
                                           uint8_t **occ);

/* File wrappers (not with HFVIS_NO_STDIO). Save writes atomically (a temporary file renamed
 * onto path: complete or untouched), allocating the encoding with malloc; errors of encode,
 * HFVIS_ERR_IO, HFVIS_ERR_OUT_OF_MEMORY. Load: errors of decode and HFVIS_ERR_IO. */
HFVIS_API hfvis_status hfvis_binvox_save(const char *path, const hfvis_volume_grid *grid,
                                         const uint8_t *occ);
HFVIS_API hfvis_status hfvis_binvox_load(const char *path, const hfvis_allocator *alloc,
                                         hfvis_volume_grid *grid, uint8_t **occ);

/* Raw occupancy: exactly dims[0]*dims[1]*dims[2] bytes of voxels, as given, in grid order
 * (x fastest, then y, then z), no header (read it with the grid's dims, e.g. a "raw volume"
 * import of 8-bit unsigned data). Errors: HFVIS_ERR_INVALID_ARGUMENT for NULL or an invalid grid,
 * HFVIS_ERR_IO, HFVIS_ERR_OUT_OF_MEMORY. */
HFVIS_API hfvis_status hfvis_voxels_raw_save(const char *path, const hfvis_volume_grid *grid,
                                             const uint8_t *voxels);
