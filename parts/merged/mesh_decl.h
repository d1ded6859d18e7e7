
/* ---- meshes: limits, analytic test meshes, bounds, Wavefront OBJ -------------------------- */

/* Limits of every mesh a hfvis function creates (generators, OBJ decoder): past them the call
 * returns HFVIS_ERR_LIMIT (2^28 vertices = 3 GiB of floats, 2^28 triangles = 3 GiB of indices). */
#define HFVIS_MESH_MAX_VERTICES ((size_t)1 << 28)
#define HFVIS_MESH_MAX_TRIANGLES ((size_t)1 << 28)
#define HFVIS_MESH_ICOSPHERE_MAX_SUBDIVISIONS 10 /* 20*4^10 = 20,971,520 triangles */

/* Analytic meshes. Each allocates mesh->xyz and mesh->indices with alloc (NULL = malloc; free
 * both with hfvis_mesh_free(alloc, mesh)), with exact sizes, vertices shared between
 * triangles (indexed), every triangle counter-clockwise seen from outside: the normal
 * (v1 - v0) x (v2 - v0) points out of the enclosed volume. Coordinates are computed in double
 * and rounded to float once. The surfaces called closed are watertight: every edge is shared by
 * exactly two triangles that use it in opposite directions, so the signed volume
 * (1/6) sum v0 . (v1 x v2) is positive. Deterministic: same arguments, same bits (on one libm).
 * Every generator returns HFVIS_OK, HFVIS_ERR_INVALID_ARGUMENT for a NULL out (or point
 * argument), a non-finite parameter or one outside its stated range, or when a coordinate would
 * not be finite in float; HFVIS_ERR_LIMIT past HFVIS_MESH_MAX_VERTICES / _TRIANGLES;
 * HFVIS_ERR_OUT_OF_MEMORY if an allocation fails. On error nothing is leaked and *out is
 * untouched. */

/* Axis-aligned box [lo, hi] (lo[a] < hi[a] on every axis): 8 vertices (corner k takes hi on
 * axis a when bit a of k is set), 12 triangles (two per face, faces -x, +x, -y, +y, -z, +z),
 * closed. Two allocations. */
HFVIS_API hfvis_status hfvis_mesh_box(const hfvis_allocator *alloc, const double lo[3],
                                      const double hi[3], hfvis_mesh *out);

/* UV sphere of centre c and radius r > 0, axis z: `slices` >= 3 meridians (phi_j = 2 pi j /
 * slices from +x toward +y) and `stacks` >= 2 bands (theta_i = pi i / stacks from +z). Vertex 0
 * is the north pole (c + (0,0,r)), then rings i = 1..stacks-1 (j fastest), last the south pole:
 * (stacks-1)*slices + 2 vertices, 2*slices*(stacks-1) triangles, closed. The band quads are
 * planar isosceles trapezoids, so area and volume have closed forms (frustums of regular
 * slices-gons of radius r sin theta_i). Three allocations (one temporary). */
HFVIS_API hfvis_status hfvis_mesh_uv_sphere(const hfvis_allocator *alloc, const double c[3],
                                            double r, int slices, int stacks, hfvis_mesh *out);

/* Icosphere of centre c, radius r > 0: the icosahedron subdivided `subdivisions` times
 * (0..HFVIS_MESH_ICOSPHERE_MAX_SUBDIVISIONS), 10*4^s + 2 vertices, 20*4^s triangles, closed.
 * Construction (exactly A. Kahler's widely copied "Creating an icosphere mesh in code", 2009,
 * which the spec voxel §3.13 sphere counts were made with): base vertices, in this order,
 * (-1,t,0) (1,t,0) (-1,-t,0) (1,-t,0) (0,-1,t) (0,1,t) (0,-1,-t) (0,1,-t) (t,0,-1) (t,0,1)
 * (-t,0,-1) (-t,0,1), t = (1+sqrt 5)/2, normalised to the unit sphere; faces (0,11,5) (0,5,1)
 * (0,1,7) (0,7,10) (0,10,11) (1,5,9) (5,11,4) (11,10,2) (10,7,6) (7,1,8) (3,9,4) (3,4,2) (3,2,6)
 * (3,6,8) (3,8,9) (4,9,5) (2,4,11) (6,2,10) (8,6,7) (9,8,1). Each level visits the faces in
 * order, creating the midpoint of (v1,v2), (v2,v3), (v3,v1) on first use (appended, shared by the
 * two faces of the edge, normalised in double: m = (p+q)/|p+q|), and replaces face t by (v1,a,c),
 * (v2,b,a), (v3,c,b), (a,b,c) at positions 4t..4t+3. Finally vertex = c + r*unit, rounded to
 * float. Five allocations (three temporary: unit positions in double, 24 bytes per vertex, and
 * the edge map, <= 360*4^s bytes); s = 10 needs about 1 GiB in all. */
HFVIS_API hfvis_status hfvis_mesh_icosphere(const hfvis_allocator *alloc, const double c[3],
                                            double r, int subdivisions, hfvis_mesh *out);

/* Torus about the z axis through c: major radius R, tube radius r, 0 < r < R; `major` >= 3
 * rings at u_i = 2 pi i / major (from +x toward +y), `minor` >= 3 vertices per ring at
 * v_j = 2 pi j / minor: vertex i*minor + j = c + ((R + r cos v) cos u, (R + r cos v) sin u,
 * r sin v). major*minor vertices, 2*major*minor triangles, closed. Two allocations. */
HFVIS_API hfvis_status hfvis_mesh_torus(const hfvis_allocator *alloc, const double c[3],
                                        double R, double r, int major, int minor,
                                        hfvis_mesh *out);

/* Shape of hfvis_mesh_torus_knot, in units of `scale`. */
#define HFVIS_TORUS_KNOT_MAJOR 1.0 /* R: radius of the torus the knot winds on */
#define HFVIS_TORUS_KNOT_MINOR 0.5 /* a: radius of the winding */
#define HFVIS_TORUS_KNOT_TUBE 0.25 /* tube radius */

/* A (p, q) torus-knot tube centred on c: centre line C(t) = scale*((1 + 0.5 cos qt) cos pt,
 * (1 + 0.5 cos qt) sin pt, 0.5 sin qt), t = 2 pi i / segments; ring i has `sides` vertices at
 * C + 0.25 scale (cos v N + sin v B), v = 2 pi j / sides, N = the unit part of C(t) orthogonal to
 * the tangent T, B = N x T. p, q >= 1 coprime, segments, sides >= 3, scale > 0.
 * segments*sides vertices, 2*segments*sides triangles, closed. For (2, 3) the centre line's
 * strands stay >= 0.83 scale apart and its radius of curvature is >= 0.71 scale, so the tube
 * (radius 0.25 scale) is embedded (no self-intersection); likewise (3, 4) (strands >= 0.62).
 * The mesh lies within |x|, |y| <= 1.75 scale, |z| <= 0.75 scale. The benchmark mesh of the
 * issue is p = 2, q = 3, segments = 2500, sides = 20: 50,000 vertices, 100,000 triangles.
 * Two allocations. */
HFVIS_API hfvis_status hfvis_mesh_torus_knot(const hfvis_allocator *alloc, const double c[3],
                                             double scale, int p, int q, int segments, int sides,
                                             hfvis_mesh *out);

/* A height field as a mesh: sample (x, y) becomes vertex (x*cell_size, y*cell_size, z) (DESIGN
 * §2), and each cell with corners a = (x,y), b = (x+1,y), c = (x,y+1), d = (x+1,y+1) is split
 * along the diagonal a-d into (a, b, d) and (a, d, c), whose normals point to +z (up) for a
 * flat field. hfvis.c's surface is bilinear (hfvis_grid_sample), which no triangulation
 * reproduces: the two agree along every grid line (cell edges are linear in both) and on cells
 * whose corners are coplanar (z_a + z_d = z_b + z_c); at a cell centre the bilinear height
 * exceeds the mesh's (z_a + z_d)/2 by (z_b + z_c - z_a - z_d)/4.
 * A triangle with a non-finite corner (a hole) is left out; only the vertices some kept
 * triangle uses are stored, in row-major order (without holes vertex y*width + x is sample
 * (x, y)). Up to 2*(width-1)*(height-1) triangles; a 1-wide or 1-high grid gives an empty mesh
 * (no arrays). Returns HFVIS_ERR_INVALID_ARGUMENT for NULL, sizes < 1, stride < width, a
 * non-positive or non-finite cell size or a grid extent that overflows float; HFVIS_ERR_LIMIT
 * if width*height > HFVIS_MESH_MAX_VERTICES. Three allocations (one temporary). */
HFVIS_API hfvis_status hfvis_mesh_from_grid(const hfvis_allocator *alloc, const hfvis_grid *g,
                                            hfvis_mesh *out);

/* A Cornell-box-like room, z up, world units = the room's size: walls of the unit cube
 * [0,1]^3 facing INTO the room (floor z = 0 up, ceiling z = 1 down, back y = 1, sides x = 0 and
 * x = 1), open at the front y = 0 (look in from e.g. eye (0.5, -1.2, 0.5) toward (0.5, 0.5,
 * 0.5)); a short box 0.3 x 0.3 x 0.3 centred at (0.66, 0.33) rotated -17 degrees about z and a
 * tall box 0.3 x 0.3 x 0.6 centred at (0.34, 0.62) rotated +17 degrees, standing on the floor,
 * outward, without bottom faces (they lie on the floor). 24 vertices (8 per box: the room's,
 * the short box's, the tall box's), 30 triangles (10 each): walls 0..9 (two per wall in the
 * order x = 0, x = 1, back, floor, ceiling), short box 10..19, tall box 20..29 (faces -x, +x,
 * -y, +y, +z of the box frame). Not closed. Two allocations. */
HFVIS_API hfvis_status hfvis_mesh_room(const hfvis_allocator *alloc, hfvis_mesh *out);

/* A teapot-like test mesh (deterministic; n >= 1 sets the tessellation), z up, standing on
 * z = 0: a body of revolution about the z axis (a Catmull-Rom profile through base, belly
 * (radius 1 at z ~ 0.48), shoulder, lid and knob up to the top pole at z = 1.42, revolved into
 * 12n meridians x 8n bands, closed, vertex layout as the UV sphere) plus two open tubes in the
 * plane y = 0: the spout (quadratic Bezier centre line from (0.55, 0, 0.30) inside the body to
 * its open mouth at (1.6, 0, 1.05), radius 0.17 tapering to 0.08) and the handle (cubic Bezier
 * from (-0.70, 0, 0.88) to (-0.72, 0, 0.30), both ends inside the body, radius 0.075), each
 * 8n+1 rings of 6n vertices. Bounds about [-1.47, 1.68] x [-1, 1] x [0, 1.42].
 * NOT watertight: the four tube end rings (24n edges) are boundary edges and the tubes pierce
 * the body (no boolean union), so do not use it with solid (parity) voxelization; the body
 * alone is closed and every triangle faces outward. 192n^2 + 2 vertices, 384n^2 - 24n
 * triangles. n > 4096 returns HFVIS_ERR_LIMIT (as do counts past HFVIS_MESH_MAX_*). Three
 * allocations (one temporary). */
HFVIS_API hfvis_status hfvis_mesh_teapot(const hfvis_allocator *alloc, int n, hfvis_mesh *out);

/* Axis-aligned bounds of every vertex of a mesh (also vertices no triangle uses), as doubles
 * (exact: each is one of the floats). Returns HFVIS_ERR_INVALID_ARGUMENT for NULL, an invalid
 * mesh (hfvis_mesh) or a mesh without vertices; lo, hi untouched then. */
HFVIS_API hfvis_status hfvis_mesh_bounds(const hfvis_mesh *mesh, double lo[3], double hi[3]);

/* Decode a Wavefront OBJ held in memory into a new mesh (arrays from alloc, NULL = malloc;
 * release with hfvis_mesh_free(alloc, out)). Read: `v x y z` (further numbers on the line, a w
 * or colour values, are checked and ignored) and `f` with 3 or more vertex references `i`,
 * `i/t`, `i//n` or `i/t/n` (t and n are checked for syntax only and ignored); i >= 1 is a
 * 1-based vertex index (forward references to later `v` lines are allowed), i <= -1 refers to
 * the i-th most recent vertex before the line. A polygon v0 v1 ... vk is fanned into
 * (v0, v_{j-1}, v_j), j = 2..k, in file order. Every other statement (vt, vn, vp, o, g, s,
 * usemtl, mtllib, l, p, ...) is ignored. Lines end at LF, CR or CRLF; `#` starts a comment
 * anywhere on a line; tokens are separated by blanks or tabs; no line continuation (`\`).
 * Numbers: [+-] digits [. digits] [e [+-] digits] (also ".5", "5."), parsed without the C
 * locale (no strtod): the first 19 significant digits are exact, the value is formed in double
 * within 3 ulp and rounded once to float, so the result is the nearest float except for
 * decimals within ~4e-16 (relative) of a midpoint between two floats; every float written
 * with 9 significant digits (as hfvis_obj_encode does) reads back bit for bit. Magnitudes
 * below 1e-46 read as (signed) zero. Two passes (validate and count, then fill): exact sizes,
 * two allocations.
 * Returns HFVIS_OK (an OBJ without v or f lines gives an empty mesh with no arrays),
 * HFVIS_ERR_INVALID_ARGUMENT if out is NULL or data is NULL with size > 0, HFVIS_ERR_FORMAT for
 * a malformed number (also inf, nan, hex) or one whose magnitude exceeds FLT_MAX, fewer than 3
 * numbers on a v line, fewer than 3 references on an f line, a malformed reference, an index 0
 * or out of range; HFVIS_ERR_LIMIT past HFVIS_MESH_MAX_VERTICES / _TRIANGLES (after fanning);
 * HFVIS_ERR_OUT_OF_MEMORY. On error nothing is leaked and *out is untouched.
 * Cost O(size). */
HFVIS_API hfvis_status hfvis_obj_decode(const void *data, size_t size,
                                        const hfvis_allocator *alloc, hfvis_mesh *out);

/* Exact bytes hfvis_obj_encode writes for mesh; 0 if mesh is NULL or invalid (hfvis_mesh) or the
 * size overflows size_t. Cost O(V + T) (it formats every number). */
HFVIS_API size_t hfvis_obj_encode_size(const hfvis_mesh *mesh);

/* Encode mesh as OBJ text: a comment line "# hfvis mesh: V vertices, T triangles", one
 * "v x y z" line per vertex, one "f a b c" line per triangle (1-based indices), LF line ends.
 * Each coordinate is the shortest decimal of at most 9 significant digits that
 * hfvis_obj_decode reads back as the same float bit for bit (-0 stays -0), in plain or
 * exponent notation, whichever is shorter (ties: plain), written by the library's own code
 * (locale-independent, no printf). Decoding the output gives the same mesh bit for bit.
 * out must hold hfvis_obj_encode_size(mesh) bytes (out_capacity); *written receives the count.
 * The decoder's HFVIS_MESH_MAX_* limits are not applied. Returns HFVIS_OK,
 * HFVIS_ERR_INVALID_ARGUMENT for NULL or an invalid mesh, HFVIS_ERR_BUFFER_TOO_SMALL (out
 * untouched). Allocates nothing. */
HFVIS_API hfvis_status hfvis_obj_encode(const hfvis_mesh *mesh, void *out, size_t out_capacity,
                                        size_t *written);

/* File wrappers (absent with HFVIS_NO_STDIO). load reads the whole file with alloc and decodes
 * it (hfvis_obj_decode; three allocations, the file buffer freed before returning). save encodes
 * into a malloc'ed buffer and writes a temporary file beside path, then renames it, so path is
 * either complete or untouched. Returns the decoder's / encoder's errors, HFVIS_ERR_IO if the
 * file cannot be read or written (e.g. path is a directory), HFVIS_ERR_OUT_OF_MEMORY. */
HFVIS_API hfvis_status hfvis_mesh_load(const char *path, const hfvis_allocator *alloc,
                                       hfvis_mesh *out);
HFVIS_API hfvis_status hfvis_mesh_save(const char *path, const hfvis_mesh *mesh);
