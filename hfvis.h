/* hfvis.h - height-field and screen-space visibility: the authoritative CPU reference.
 * Version 0.2.0. MIT licence (see LICENSE).
 *
 * hfvis is a pure C99, single-threaded, dependency-free library: copy this header and the
 * .c files you need (hfvis.c for height fields, ssao.c for screen space, voxel.c for meshes and
 * volumes; ssao.c and voxel.c need hfvis.c) into a project and compile them with
 * `cc -std=c99 -c`. It computes, on the CPU and as the papers define them:
 *   - horizon maps, sky light, sky-view factor, sun shadows and environment light on height
 *     fields by line sweeps with convex hulls [P1]; intervisibility, visibility index and
 *     indirect light with hull trees [P2]; viewsheds [R2]; multi-resolution height-field
 *     global illumination [NS09];
 *   - screen-space obscurance: line-sweep AO [P3], far-field AO [P4], HBAO [BSD08] and a
 *     screen-space ray-traced reference; bitmask ray-cast AO on meshes [LK];
 *   - meshes, BVH ray casting, surface / conservative / solid voxelization, incremental
 *     image-based voxelization, 4D visibility fields and volume-based VPL indirect light [G12].
 * Beside every fast routine stands its oracle, a slow public function from first principles, so
 * a GPU port can be checked against hfvis, and hfvis against the definition.
 *
 * Oracles and production routines. A production routine is the fast algorithm of a paper. Its
 * oracle is documented beside it ("Oracle of ...") and computes the same quantity by brute
 * force: *_naive over exactly the samples the fast routine uses (held to it bit for bit, or
 * within the tolerance its documentation names), *_reference from first principles with its
 * own sampling (a ray march, a hemisphere integral, a ray caster, a per-voxel test). Every
 * oracle's name ends in one of the two (0.2.0 renamed the two that did not: see "Deprecated
 * names" at the end of this header).
 * Production routines never call oracles; oracles cost what their comments state (often
 * quadratic) and are meant for tests and validation, not for production sizes.
 *
 * Contents (main entry points per task; every section below documents its building blocks)
 *   Files        hfvis_image_load, hfvis_pfm_save, hfvis_pgm_save; the in-memory codecs
 *                hfvis_image_decode, hfvis_pfm_encode, hfvis_pgm_encode; atomic writes
 *                hfvis_write_file, hfvis_write_begin / hfvis_write_end
 *   Terrain      hfvis_horizon_map, hfvis_horizon_direction (oracles hfvis_horizon_reference,
 *                hfvis_horizon_lattice_naive); hfvis_sky_view_factor, hfvis_sky_light,
 *                hfvis_sun_visibility, hfvis_env_light (oracle hfvis_light_reference);
 *                hfvis_intervisibility, hfvis_visibility_count, hfvis_indirect_light,
 *                hfvis_terrain_gi (oracles *_naive); hfvis_viewshed (hfvis_viewshed_reference);
 *                solar radiation: hfvis_spa, hfvis_rsun_sun_position, hfvis_esra_clear_sky,
 *                hfvis_solar_irradiation (oracle hfvis_solar_irradiation_reference);
 *                split runs: hfvis_direction_sums and the partial-sum file hfvis_partial_*;
 *                exact per-receiver rays (hfvis_sweep_options.rays, hfvis_sweep_azimuths;
 *                oracle hfvis_horizon_exact_naive); a search radius and tiles
 *                (hfvis_sweep_options.max_distance, origin, extent, receiver rectangle;
 *                hfvis_tile_halo)
 *   Terrain GI   hfvis_ns_gi ([NS09]); the SH, ZH and NLP helpers hfvis_sh_*, hfvis_zh_*,
 *                hfvis_nlp_*
 *   Screen space hfvis_camera_perspective, hfvis_camera_from_matrix, hfvis_depth_linearize;
 *                hfvis_lsao (oracle route hfvis_lsao_direction_naive), hfvis_hbao, hfvis_ffao,
 *                hfvis_ssao_reference (the reference), hfvis_ssao_mipmap, hfvis_ssao_error
 *   Meshes       hfvis_mesh_load, hfvis_rasterize, hfvis_bvh_build, hfvis_bvh_closest_hit,
 *                hfvis_lk_image ([LK]; oracle hfvis_lk_reference)
 *   Voxels       hfvis_voxelize_surface, hfvis_voxelize_conservative, hfvis_voxelize_solid,
 *                hfvis_voxelize_bitmask, hfvis_iv_update (each with its *_reference),
 *                hfvis_binvox_save
 *   Visibility fields  hfvis_visfield_build, hfvis_visfield_query,
 *                hfvis_visfield_ambient_occlusion (each with its *_reference)
 *   Volume GI    hfvis_volgi_render and its stages hfvis_volgi_inject, _propagate, _gather
 *
 * References
 *   [P1]   V. Timonen, J. Westerholm, "Scalable Height Field Self-Shadowing", Computer Graphics
 *          Forum 29(2) (Eurographics 2010).
 *   [P2]   V. Timonen, "Low-Complexity Intervisibility in Height Fields", Computer Graphics
 *          Forum 31(8), 2012.
 *   [P3]   V. Timonen, "Line-Sweep Ambient Obscurance", Computer Graphics Forum 32(4)
 *          (EGSR 2013).
 *   [P4]   V. Timonen, "Screen-Space Far-Field Ambient Obscurance", HPG 2013.
 *   [T14]  V. Timonen, "Scalable Algorithms for Height Field Illumination", TUCS Dissertations
 *          173, Abo Akademi University, 2014: collects [P1]-[P4], with appendices A.1 and A.2
 *          that correct [P1] and [P2].
 *   [LK]   S. Laine, T. Karras, "Two Methods for Fast Ray-Cast Ambient Occlusion", Computer
 *          Graphics Forum 29(4) (EGSR 2010).
 *   [NS09] D. Nowrouzezahrai, J. Snyder, "Fast Global Illumination on Dynamic Height Fields",
 *          Computer Graphics Forum 28(4) (EGSR 2009).
 *   [G12]  A. Gaitatzes, "Interactive Diffuse Global Illumination Discretization Methods for
 *          Dynamic Environments", PhD thesis, University of Cyprus, 2012.
 *   [R2]   W. R. Franklin, C. K. Ray, "Higher isn't necessarily better: visibility algorithms
 *          and experiments", 6th Int. Symposium on Spatial Data Handling, 1994 (algorithm R2).
 *   [BSD08] L. Bavoil, M. Sainz, R. Dimitrov, "Image-Space Horizon-Based Ambient Occlusion",
 *          SIGGRAPH 2008 Talks.
 *   [Z11]  K. Zaksek, K. Ostir, Z. Kokalj, "Sky-View Factor as a Relief Visualization
 *          Technique", Remote Sensing 3(2), 2011 (the sky-view factor of terrain tools).
 *
 * History (one line per milestone)
 *   P1 engine     PGM/PFM codecs, analytic fields, sweep lattice, P1 hull horizons, uniform sky,
 *                 sky-view factor, sun visibility, environment light (prefix and L_p table).
 *   P2            hull trees, intervisibility, visibility index, indirect light and bounces.
 *   Screen space  camera and depth, P3 line-sweep AO, P4 far-field AO, HBAO, the ray-traced
 *                 reference, the mipmap baseline, error metrics.
 *   Meshes        meshes and OBJ, rasterizer, BVH, surface / conservative / solid voxelization,
 *                 binvox, incremental voxelization.
 *   [LK]          bitmask ray-cast AO: ray sets, masks, look-up tables, raster and BVH methods.
 *   [G12]         4D visibility fields and volume-based VPL indirect light.
 *   [NS09]        multi-resolution height-field GI.
 *   Release       the hfvis CLI, split runs and the partial-sum file, install and pkg-config,
 *                 viewsheds, the gallery.
 *   Ports         cameras from projection matrices, bottom-up rows, LSAO's step-falloff
 *                 refusal, HBAO defaults aligned with LSAO's.
 *   Exact rays    every receiver its own ray along the nearest rational direction, the
 *                 directions weighted by their share of the circle (beyond [P1]).
 *   0.2.0         one API grammar: oracle suffixes, *_options_default() for every options
 *                 struct, *_DEFAULT = 0 in every option enum, unit-named size queries (renames
 *                 kept as deprecated aliases); one internal Common layer (hfvis__*); a search
 *                 radius with tiles that equal the whole run bit for bit; streaming atomic
 *                 writes.
 *
 * ------------------------------------------------------------------------------------------
 * QUICK START
 *
 *     float *z; hfvis_image_info info;
 *     if (hfvis_image_load("dem.pfm", NULL, &z, &info) != HFVIS_OK) return 1;
 *     hfvis_grid g = { z, info.width, info.height, info.width, 30.0 };   // 30 m cells
 *     float *svf = malloc(sizeof(float) * (size_t)info.width * (size_t)info.height);
 *     hfvis_status s = hfvis_sky_view_factor(&g, 32, NULL, svf, info.width);
 *     if (s != HFVIS_OK) fprintf(stderr, "%s\n", hfvis_status_string(s));
 *     hfvis_pfm_save("svf.pfm", svf, info.width, info.height, 1, info.width);
 *     hfvis_free(NULL, z); free(svf);
 *
 * ------------------------------------------------------------------------------------------
 * CONVENTIONS (the whole API)
 *
 * Grids. A height field is hfvis_grid: sample (x, y) is z[y*stride + x], x = column (fastest),
 *   y = row, stride counted in elements (stride >= width). Sample (x, y) lies at world position
 *   (x*cell_size, y*cell_size, z): samples sit at integer grid positions, row 0 is the top of an
 *   image and the north edge of a map. Heights and cell_size share one world unit. Between the
 *   samples the surface is bilinear (the GPU implementations of [P1] sample it so).
 * Angles are radians. Azimuth psi is measured in the grid plane from +x (increasing column,
 *   east) toward +y (increasing row, south): psi = 0 east, pi/2 south. GIS compass bearings
 *   (0 = north, clockwise) convert as psi = bearing - pi/2. With K directions,
 *   psi_k = azimuth0 + 2*pi*k/K. "The horizon toward psi" is what a receiver sees when it looks
 *   toward psi.
 * Horizon values are elevation angles alpha in [-pi/2, pi/2] above the horizontal plane: the
 *   largest elevation under which the receiver sees terrain toward psi. A receiver that sees no
 *   terrain in that direction (open border) gets alpha = -pi/2. Internally the sweep keeps the
 *   tangent t = tan(alpha) in double. Which definition each mode computes: the lattice mode
 *   keeps [P1] as published (the maximum over the nodes of the lattice lines, gathered; [P1]
 *   §4-§7); exact rays (see "Exact rays") approach the supremum over t > 0 of
 *   atan((h(p + t d) - h(p)) / t) over the bilinear surface along the ray, next to the receiver
 *   included, and their oracle hfvis_horizon_exact_naive computes that supremum.
 * Borders. HFVIS_BORDER_OPEN (default, as in the papers): nothing exists outside the grid.
 *   HFVIS_BORDER_CLAMP: edge heights extend outward. HFVIS_BORDER_WRAP: the field is periodic
 *   with period width x height (tileable fields).
 * No-data. A non-finite height (NaN, +-Inf) marks a hole. A hole never occludes, receives no
 *   value (output NaN) and a bilinear sample touching a hole with non-zero weight is a hole.
 *   Every receiver with a finite height gets a value: one stranded between holes, where the
 *   lattice holds no finite node near it, takes the per-receiver march of the oracle
 *   (hfvis_horizon_reference) toward each direction instead of the gathered lattice (horizon
 *   maps and every lattice product built on them or on the fused sums; for
 *   hfvis_indirect_light and hfvis_visibility_count the march's samples form the receiver's
 *   line: out of the grid, then border_cells pre-roll steps). Grid normals are one-sided beside
 *   holes.
 * Obscurance and light. Obscurance outputs lie in [0, 1] (0 = nothing blocks). Lighting outputs
 *   are radiance with the Lambertian convention L_o = albedo/pi * Int L_i V (n.w) dw, so an
 *   unoccluded flat receiver under a uniform sky of radiance c with albedo 1 returns c.
 *   Sky-view factor (Zaksek et al. 2011, as RVT and GRASS r.skyview):
 *   SVF = 1 - (1/K) sum_k sin(max(alpha_k, 0)).
 * Numbers. Public arrays are float; hull tests, slopes and integrals are double, rounded to
 *   float once at the output.
 * Errors. Every fallible function returns hfvis_status (HFVIS_OK == 0) and writes results
 *   through out-pointers. On any error the outputs are left untouched. A buffer described by
 *   a size and a stride (rows*stride elements) that cannot be addressed, i.e. whose byte size
 *   overflows PTRDIFF_MAX, is HFVIS_ERR_INVALID_ARGUMENT like any other bad size. The library never
 *   prints, never exits, never aborts on input, and has no global mutable state: every
 *   function is reentrant and may run concurrently on different outputs.
 * Threads. The library starts none. Inputs (grids, environments, tables, options, meshes) are
 *   only read, so any number of calls may share them while no call writes them; an allocator
 *   shared by concurrent calls must itself be thread-safe (give each thread its own). Outputs
 *   must not overlap, with one exception: bands (sweep options part_index/part_count) write
 *   disjoint cells, so the part_count calls of one sun (hfvis_sun_visibility), or of one
 *   direction of exact-mode sums (hfvis_direction_sums), may write one out concurrently; so may
 *   hfvis_solar_irradiation calls on disjoint row ranges (hfvis_solar_options.row_begin/end),
 *   and hfvis_exact_grid_rows calls on disjoint row ranges.
 *   Splitting a run over threads without changing a bit: the lattice sums by quarter-turn group
 *   (hfvis_direction_sums, one group per part, added in order), the exact sums by bands of one
 *   direction at a time (added in place), the horizon map by plane range, one sun by bands,
 *   solar irradiation by row ranges over one caller-made horizon map,
 *   and any receiver-local result by windows ("Search radius and tiles"); what every call would
 *   derive from the grid alone can be made once and shared (sweep options normals, exact_grid).
 *   The hfvis tool's
 *   --threads does exactly that; test/thread_test.c runs these calls concurrently on shared
 *   inputs under ThreadSanitizer (make sanitize).
 * Memory. The caller owns every output and sizes it with the documented formula or a *_size()
 *   query. Scratch comes from the optional allocator in the options (NULL = malloc/free);
 *   test/test_args.c's allocator sweep lists every function that allocates and fails each of
 *   its allocations in turn. The library keeps no pointer after a call, except the objects it
 *   hands back for later release: a hfvis_ffao_table keeps its allocator (which must outlive
 *   the table) so that hfvis_ffao_table_free can return its values. An allocator whose alloc
 *   is NULL means HFVIS_MALLOC for every block, which then go back to HFVIS_FREE whatever its
 *   free says.
 *   The *_save writers, which take no allocator, and every NULL allocator use HFVIS_MALLOC(size)
 *   and HFVIS_FREE(ptr), malloc and free unless both are defined when the library's .c files
 *   are compiled (as stb's STBI_MALLOC; test/test_oom.c fails them on purpose).
 * Options. NULL and a zero-initialised options struct both mean the documented defaults; zero is
 *   never a valid non-default value. Every options struct has hfvis_*_options_default(), which
 *   returns the defaults filled in (bit-identical results to a zero struct); the few that also
 *   have *_options_resolve() use it to validate and fill in a caller's struct. Every option
 *   enum names its zero *_DEFAULT; where the documented default is itself a named choice that
 *   has always been 0 (HFVIS_RAYS_LATTICE, HFVIS_BLEND_MAX, ...), both names stand for 0.
 * Sizes. A *_size() query (and *_encode_size(), *_scratch_size()) counts bytes; a query that
 *   counts elements names them: hfvis_lattice_nodes, hfvis_env_table_floats,
 *   hfvis_volume_floats. Angles are radians everywhere (see "Angles" above; a _rad suffix only
 *   repeats it, and no parameter takes degrees); a distance ending in _cells counts grid cells.
 *
 * What is and is not guaranteed
 *   - Same input and same binary: bit-identical output (build with -ffp-contract=off; FMA
 *     contraction changes the last bits; never build with -ffast-math).
 *   - Exact: the hull sweep equals the per-line brute force on the same lattice samples
 *     (hfvis_horizon_lattice_naive) bit for bit; axis directions reproduce the grid's tangents
 *     exactly.
 *   - Within tolerance: gathered (non-axis) directions against the per-receiver ray march
 *     (bilinear resampling of the lattice, docs/errata.md E7); libm differences across C
 *     libraries (sin, cos, atan) at the 1e-15 relative level; the sky and environment light
 *     terms and the lattice's horizon angles (and radius-limited openness) take atan from a
 *     polynomial within 6e-9 rad of libm's (at most a float ulp of the output; the oracles and
 *     the exact rays' angles use libm).
 *   - Not guaranteed: agreement with GPU implementations that use fp16 heights or 8-bit angles
 *     ([P1] §7); expect differences of about 1e-3 rad there.
 */
#ifndef HFVIS_H
#define HFVIS_H

#define HFVIS_VERSION_MAJOR 0
#define HFVIS_VERSION_MINOR 2
#define HFVIS_VERSION_PATCH 0
#define HFVIS_VERSION (HFVIS_VERSION_MAJOR * 10000 + HFVIS_VERSION_MINOR * 100 + HFVIS_VERSION_PATCH)

/* Configuration macros (all #ifndef-guarded):
 *   HFVIS_API           decoration for every public function (default empty).
 *   HFVIS_EXPERIMENTAL  decoration of the building blocks a port diffs against whose signatures
 *                       may still change before 1.0 (default empty): the SH, ZH and normalized
 *                       Legendre helpers and the wedge matrices of [NS09], the [LK] frame, plane
 *                       masks and look-up-table indexing, the [P2] hull tree, the 2-band SH of
 *                       the volume GI. Define it (e.g. as a deprecation attribute) to find uses.
 *   HFVIS_NO_STDIO      define when compiling the .c files to remove the file wrappers
 *                       (hfvis_*_load / hfvis_*_save); the in-memory codecs remain.
 *   HFVIS_NO_DEPRECATED define before including hfvis.h to drop the renamed functions' old
 *                       names (the "Deprecated names" block at the end).
 *   HFVIS_ENABLE_ASSERTS / HFVIS_ASSERT(x)  internal invariant checks in the .c files only. */
#ifndef HFVIS_API
#define HFVIS_API
#endif
#ifndef HFVIS_EXPERIMENTAL
#define HFVIS_EXPERIMENTAL
#endif

#include <stddef.h>
#include <stdint.h>
#ifndef HFVIS_NO_STDIO
#include <stdio.h> /* FILE, for hfvis_write_begin and hfvis_write_end */
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ========================================================================================== */
/* Status codes                                                                               */
/* ========================================================================================== */

typedef enum hfvis_status {
    HFVIS_OK = 0,                    /* success */
    HFVIS_ERR_INVALID_ARGUMENT = 1,  /* NULL where not allowed, bad size, non-finite parameter,
                                        unknown enum value; outputs untouched */
    HFVIS_ERR_OUT_OF_MEMORY = 2,     /* an allocation failed; nothing leaked, outputs untouched */
    HFVIS_ERR_FORMAT = 3,            /* malformed file or buffer contents */
    HFVIS_ERR_LIMIT = 4,             /* a size exceeds a documented limit */
    HFVIS_ERR_BUFFER_TOO_SMALL = 5,  /* the caller's output buffer is too small */
    HFVIS_ERR_IO = 6                 /* a file could not be opened, read or written */
} hfvis_status;

/* Name of a status code ("HFVIS_OK", ...) followed by a short explanation; never NULL. */
HFVIS_API const char *hfvis_status_string(hfvis_status status);

/* ========================================================================================== */
/* Allocator and shared types                                                                 */
/* ========================================================================================== */

/* Per-call allocator. alloc returns NULL on failure; free accepts NULL. */
typedef struct hfvis_allocator {
    void *(*alloc)(void *user, size_t size);
    void (*free)(void *user, void *ptr);
    void *user;
} hfvis_allocator;

/* Release memory that a hfvis function allocated for the caller (hfvis_image_load) with the
 * same allocator (NULL = free). ptr may be NULL. */
HFVIS_API void hfvis_free(const hfvis_allocator *alloc, void *ptr);

/* CRC-32 (ISO-HDLC: the polynomial of PNG, zlib and gzip) of n bytes continuing crc (start from
 * 0): hfvis_crc32(0, "123456789", 9) = 0xCBF43926. data may be NULL when n is 0. Pure helper;
 * the partial-sum files carry one, the PNG writer of the examples uses it for its chunks. */
HFVIS_API uint32_t hfvis_crc32(uint32_t crc, const void *data, size_t n);

/* A height field. See CONVENTIONS. */
typedef struct hfvis_grid {
    const float *z;        /* heights, z[y*stride + x]; non-finite = hole */
    int width;             /* samples per row, >= 1 */
    int height;            /* rows, >= 1 */
    ptrdiff_t stride;      /* elements between rows, >= width */
    double cell_size;      /* world distance between adjacent samples, > 0, same unit as z;
                              outputs keep their documented ranges while max|z| / cell_size
                              <= 1e150 (heights in cells, in double; test/fuzz/fuzz_heightfield) */
} hfvis_grid;

/* What lies outside the grid. 0 is the default (OPEN). */
typedef enum hfvis_border {
    HFVIS_BORDER_DEFAULT = 0,
    HFVIS_BORDER_OPEN = 1,   /* nothing outside (the papers) */
    HFVIS_BORDER_CLAMP = 2,  /* edge heights extend outward */
    HFVIS_BORDER_WRAP = 3    /* periodic field, period width x height */
} hfvis_border;

/* Progress callback: called after each unit of work (a direction) with done in 1..total. */
typedef void (*hfvis_progress_fn)(void *user, int done, int total);

/* An analytic height surface for oracles: height at grid position (x, y) (grid units, may lie
 * outside [0, width-1] x [0, height-1]), in world units. Return NaN for a hole. */
typedef double (*hfvis_height_fn)(void *user, double x, double y);

/* ========================================================================================== */
/* hfvis.c - codecs                                                                           */
/* ========================================================================================== */

/* Largest width or height a decoder accepts, and the largest width*height*channels. */
#define HFVIS_IMAGE_MAX_DIM 1048576
#define HFVIS_IMAGE_MAX_VALUES ((size_t)1 << 28)

typedef enum hfvis_image_format {
    HFVIS_FORMAT_UNKNOWN = 0,
    HFVIS_FORMAT_PGM = 1,      /* P2 (ASCII) or P5 (binary), maxval 1..65535 */
    HFVIS_FORMAT_PFM = 2       /* Pf (grey) or PF (RGB), either byte order */
} hfvis_image_format;

typedef struct hfvis_image_info {
    hfvis_image_format format;
    int width, height;
    int channels;              /* 1, or 3 for PF */
    int maxval;                /* PGM only: 1..65535 */
    int big_endian;            /* PFM only: 1 if the file's scale was positive */
} hfvis_image_info;

/* Read the header of a PGM or PFM held in memory (format detected from the magic number).
 * Returns HFVIS_OK, HFVIS_ERR_INVALID_ARGUMENT if data or info is NULL, HFVIS_ERR_FORMAT on a
 * bad magic, non-numeric or truncated header or truncated pixel data, HFVIS_ERR_LIMIT if a
 * dimension exceeds HFVIS_IMAGE_MAX_DIM or the value count HFVIS_IMAGE_MAX_VALUES. */
HFVIS_API hfvis_status hfvis_image_info_read(const void *data, size_t size, hfvis_image_info *info);

/* Decode a PGM or PFM from memory into floats, row 0 = top, channels interleaved.
 * PGM values are returned as the integers 0..maxval (no scaling); PFM values as stored (the
 * file's scale magnitude is not applied, as netpbm). PFM rows are stored bottom-to-top on disk
 * and flipped here. out must hold width*height*channels floats (out_count); info may be NULL.
 * Returns the errors of hfvis_image_info_read, or HFVIS_ERR_BUFFER_TOO_SMALL. */
HFVIS_API hfvis_status hfvis_image_decode(const void *data, size_t size, float *out,
                                          size_t out_count, hfvis_image_info *info);

/* Bytes needed to encode a width x height image: PFM (channels 1 or 3) or binary PGM (8-bit
 * samples for maxval <= 255, else 16-bit). Returns 0 for invalid sizes. The encoders do not
 * apply the decoders' HFVIS_IMAGE_MAX_* limits. */
HFVIS_API size_t hfvis_pfm_encode_size(int width, int height, int channels);
HFVIS_API size_t hfvis_pgm_encode_size(int width, int height, int maxval);

/* Encode a little-endian PFM (scale -1). pixels[y*stride*channels ... ] with stride in pixels.
 * out must hold hfvis_pfm_encode_size() bytes (out_capacity); *written receives the count.
 * Returns HFVIS_ERR_INVALID_ARGUMENT or HFVIS_ERR_BUFFER_TOO_SMALL on error. */
HFVIS_API hfvis_status hfvis_pfm_encode(const float *pixels, int width, int height, int channels,
                                        ptrdiff_t stride, void *out, size_t out_capacity,
                                        size_t *written);

/* Encode a binary PGM (P5; 8-bit if maxval <= 255, else 16-bit big-endian). Each value v maps
 * to round((v - lo) / (hi - lo) * maxval), clamped to [0, maxval]; non-finite values map to 0.
 * Requires lo < hi, both finite, and 1 <= maxval <= 65535. */
HFVIS_API hfvis_status hfvis_pgm_encode(const float *pixels, int width, int height,
                                        ptrdiff_t stride, float lo, float hi, int maxval,
                                        void *out, size_t out_capacity, size_t *written);

/* File wrappers (absent with HFVIS_NO_STDIO). load reads PGM or PFM, allocates *pixels with
 * alloc (NULL = malloc; release with hfvis_free) and fills info. Every *_load of the library
 * reads the header first (the first 64 KiB at most; a header longer than that is refused) and
 * refuses a bad one before reading further; then exactly the bytes the header announces and one
 * more (P5/PFM samples: trailing data is ignored, as by the decoders; partial-sum and field
 * files: trailing data is refused); a file shorter than announced is HFVIS_ERR_FORMAT, a regular
 * file without allocating for it. P2 (ASCII) and binvox bodies have no announced size and are
 * read whole after the header check; OBJ (hfvis_mesh_load) has no header and is read whole. save writes to a temporary
 * file beside path and renames it, so path is either complete or untouched.
 * Returns the decoder's errors, HFVIS_ERR_IO if the file cannot be read or written, or
 * HFVIS_ERR_OUT_OF_MEMORY. */
/* How hfvis_write_file reports its temporary file (opts may be NULL). */
typedef struct hfvis_write_options {
    /* Called with the temporary name just before the file is created, and with NULL once it is
     * renamed onto path or removed: a program that may be interrupted keeps a copy of the name
     * (the hfvis tool unlinks it from its SIGINT/SIGTERM/SIGHUP handler). May be NULL. */
    void (*on_temp)(void *user, const char *temp_path);
    void *user;
} hfvis_write_options;

/* The defaults: no callback. */
HFVIS_API hfvis_write_options hfvis_write_options_default(void);

/* Write n bytes to path atomically, as every saver of the library does: the bytes go to a
 * temporary file beside path ("<path>.tmp<8 hex digits>"; when that name's last component would
 * exceed 255 bytes, the component is cut so the name fits), which is then renamed onto path.
 * path is either complete or untouched; on failure the temporary file is removed. bytes may be
 * NULL when n is 0. A symbolic link at path is replaced by the file, not written through.
 * Returns HFVIS_OK only when path holds all n bytes; HFVIS_ERR_IO when the file cannot be
 * created, or on any short fwrite (disk full, file-size limit), failed fflush or fclose (a
 * delayed write error) or failed rename, each of which leaves path untouched and no temporary
 * file; HFVIS_ERR_INVALID_ARGUMENT (NULL or empty path, NULL bytes with n > 0) or
 * HFVIS_ERR_OUT_OF_MEMORY (the name). Every saver of the library (hfvis_pfm_save,
 * hfvis_pgm_save, hfvis_pgm_range_save, hfvis_mesh_save, hfvis_binvox_save, ...) returns this
 * status unchanged.
 * Test hooks: the write path calls HFVIS_FWRITE, HFVIS_FFLUSH, HFVIS_FCLOSE and HFVIS_RENAME,
 * which are fwrite, fflush, fclose and rename unless defined (same signatures) when the
 * library's .c files are compiled; test/test_wfault.c fails each call of every writer in turn. */
HFVIS_API hfvis_status hfvis_write_file(const char *path, const void *bytes, size_t n,
                                        const hfvis_write_options *opts);

/* The same atomic write for a file produced piece by piece (the examples' GeoTIFF writer seeks
 * back to patch offsets): hfvis_write_begin creates the temporary file (named and announced as
 * above) and returns it in *file, open for binary writing, and its name in *temp_path (owned
 * by the library); write with stdio, then call hfvis_write_end exactly once with both. With
 * commit nonzero it flushes, closes and renames the file onto path; with commit 0, or when any
 * of that fails (including an earlier write error, ferror), it removes the file and path is
 * untouched. Either way it closes the file and frees temp_path.
 * hfvis_write_begin returns HFVIS_OK, HFVIS_ERR_INVALID_ARGUMENT (a NULL or empty path, NULL
 * file or temp_path), HFVIS_ERR_IO or HFVIS_ERR_OUT_OF_MEMORY (the name), and sets *file and
 * *temp_path to NULL on failure. hfvis_write_end returns HFVIS_OK when path holds the new file
 * (or, with commit 0, when the file was discarded), HFVIS_ERR_IO when it could not be written
 * (a write error seen by ferror, a failed fflush, fclose or rename: path is untouched),
 * HFVIS_ERR_INVALID_ARGUMENT for a NULL file, temp_path or path (it still releases the others).
 * Declared only where <stdio.h> is available (not with HFVIS_NO_STDIO). */
#ifndef HFVIS_NO_STDIO
/* The write path's stdio calls (see hfvis_write_file, "Test hooks"; examples/zio.h uses them too). */
#ifndef HFVIS_FWRITE
#define HFVIS_FWRITE(ptr, size, n, file) fwrite(ptr, size, n, file)
#endif
#ifndef HFVIS_FFLUSH
#define HFVIS_FFLUSH(file) fflush(file)
#endif
#ifndef HFVIS_FCLOSE
#define HFVIS_FCLOSE(file) fclose(file)
#endif
#ifndef HFVIS_RENAME
#define HFVIS_RENAME(from, to) rename(from, to)
#endif
HFVIS_API hfvis_status hfvis_write_begin(const char *path, const hfvis_write_options *opts,
                                         FILE **file, char **temp_path);
HFVIS_API hfvis_status hfvis_write_end(const char *path, FILE *file, char *temp_path, int commit,
                                       const hfvis_write_options *opts);
#endif

HFVIS_API hfvis_status hfvis_image_load(const char *path, const hfvis_allocator *alloc,
                                        float **pixels, hfvis_image_info *info);
HFVIS_API hfvis_status hfvis_pfm_save(const char *path, const float *pixels, int width,
                                      int height, int channels, ptrdiff_t stride);
HFVIS_API hfvis_status hfvis_pgm_save(const char *path, const float *pixels, int width,
                                      int height, ptrdiff_t stride, float lo, float hi,
                                      int maxval);

/* NoData-safe PGM with its value range (the hfvis tool writes its PGM outputs so): a 16-bit binary
 * PGM whose code HFVIS_PGM_NODATA_CODE (0) marks NoData (every non-finite value) and whose codes
 * 1..65535 map [lo, hi] linearly, code = 1 + round((v - lo)/(hi - lo) * 65534) clamped to
 * [1, 65535]. The header carries the comment "# hfvis range LO HI nodata 0" right after "P5"
 * (LO, HI with 9 significant digits: the floats given, exactly), so any pgm(5) reader reads the
 * file and hfvis_pgm_range_decode maps the codes back, v = lo + (code - 1)(hi - lo)/65534 (within
 * (hi - lo)/131068 of the value written), NaN for code 0. Requires finite lo < hi.
 * encode_size: the bytes of such a file (0 for invalid sizes or range). */
#define HFVIS_PGM_NODATA_CODE 0
#define HFVIS_PGM_RANGE_CODES 65534 /* codes 1..65535 span [lo, hi] */
HFVIS_API size_t hfvis_pgm_range_encode_size(int width, int height, float lo, float hi);
HFVIS_API hfvis_status hfvis_pgm_range_encode(const float *pixels, int width, int height,
                                              ptrdiff_t stride, float lo, float hi, void *out,
                                              size_t out_capacity, size_t *written);
HFVIS_API hfvis_status hfvis_pgm_range_save(const char *path, const float *pixels, int width,
                                            int height, ptrdiff_t stride, float lo, float hi);
/* The range of a PGM in memory from its "# hfvis range" comment. Returns the decoder's errors, or
 * HFVIS_ERR_FORMAT for a PFM or a PGM without the comment (a plain PGM, or one the hfvis tool wrote
 * before 0.2: codes 0..65535 spanned the range and NoData was 0). */
HFVIS_API hfvis_status hfvis_pgm_range_read(const void *data, size_t size, float *lo, float *hi);
/* Decode such a PGM to values (as above; NaN for NoData): out holds width*height floats
 * (out_count); info may be NULL. Errors as hfvis_pgm_range_read and hfvis_image_decode. */
HFVIS_API hfvis_status hfvis_pgm_range_decode(const void *data, size_t size, float *out,
                                              size_t out_count, hfvis_image_info *info);

/* ========================================================================================== */
/* hfvis.c - analytic test fields                                                             */
/* ========================================================================================== */

typedef enum hfvis_field_kind {
    HFVIS_FIELD_PLANE = 1,        /* z = height                                                */
    HFVIS_FIELD_TILTED_PLANE = 2, /* z = height + slope_x*(x-x0) + slope_y*(y-y0)              */
    HFVIS_FIELD_V_VALLEY = 3,     /* z = height + slope*|x-x0|   (valley along y)               */
    HFVIS_FIELD_L1_PIT = 4,       /* z = height + slope*(|x-x0| + |y-y0|)  (pyramid pit)        */
    HFVIS_FIELD_LINF_PIT = 5,     /* z = height + slope*max(|x-x0|, |y-y0|)                     */
    HFVIS_FIELD_CONE = 6,         /* z = height + slope*r,  r = |(x,y)-(x0,y0)|  (cone pit)     */
    HFVIS_FIELD_HEMISPHERE = 7,   /* z = height + amplitude*sqrt(1 - (r/radius)^2) for r < radius,
                                     else height; amplitude = radius*cell_size is a true
                                     hemisphere                                                */
    HFVIS_FIELD_STEP = 8,         /* z = height for x < x0, height + amplitude for x >= x0 (a
                                     wall facing -x; sampled on the grid the rise is the bilinear
                                     ramp over [x0-1, x0])                                      */
    HFVIS_FIELD_SINUSOID = 9,     /* z = height + amplitude*sin(2pi x/wavelength)*sin(2pi y/wavelength) */
    HFVIS_FIELD_FBM = 10,         /* seeded fractional Brownian motion: octaves of value noise,
                                     base wavelength 'wavelength' cells, gain 'persistence',
                                     lacunarity 2, scaled by amplitude                          */
    HFVIS_FIELD_BRICKS = 11       /* a brick wall seen from above ([P2] Fig. 7 "brick surface"):
                                     bricks of wavelength x wavelength/2 cells in running bond,
                                     top at height, mortar joints `radius` cells wide and
                                     `amplitude` deep, brick tops jittered by seed (+-5% of
                                     amplitude)                                                 */
} hfvis_field_kind;

/* Parameters of an analytic field. Positions, radius and wavelength are in grid units (cells);
 * heights, slopes (rise per cell) and amplitude are in world units (per cell). */
typedef struct hfvis_field {
    hfvis_field_kind kind;
    double x0, y0;          /* centre / kink / wall position */
    double height;          /* base height */
    double slope;           /* V_VALLEY, L1_PIT, LINF_PIT, CONE */
    double slope_x, slope_y;/* TILTED_PLANE */
    double radius;          /* HEMISPHERE (> 0); BRICKS: mortar width in cells (0 = 1) */
    double amplitude;       /* HEMISPHERE, STEP, SINUSOID, FBM */
    double wavelength;      /* SINUSOID, FBM (> 0) */
    double persistence;     /* FBM: amplitude ratio between octaves, 0 = 0.5 */
    int octaves;            /* FBM: 0 = 8 */
    uint64_t seed;          /* FBM */
} hfvis_field;

/* Height of the field at grid position (x, y), in world units; NaN for an invalid field.
 * Matches hfvis_height_fn, so it can drive the analytic oracles with user = (void *)field. */
HFVIS_API double hfvis_field_height(void *field, double x, double y);

/* Sample the field at the integer grid positions into out[y*stride + x].
 * Returns HFVIS_ERR_INVALID_ARGUMENT for NULL, sizes < 1, stride < width, an unknown kind or
 * non-finite parameters. Cost O(width*height*octaves). */
HFVIS_API hfvis_status hfvis_field_generate(const hfvis_field *field, int width, int height,
                                           ptrdiff_t stride, float *out);

/* ========================================================================================== */
/* hfvis.c - sampling, normals and the sweep lattice ([P1] §4, Fig. 2, §7; docs/errata.md E5, E7, E8, E10) */
/* ========================================================================================== */

/* Bilinear height at grid position (x, y), clamped to the grid, in world units; NaN if a tap
 * with non-zero weight is a hole or the grid is invalid. Pure helper. */
HFVIS_API double hfvis_grid_sample(const hfvis_grid *grid, double x, double y);

/* Unit normals, 3 floats per sample (x, y, z with z up), out[(y*width + x)*3 + c].
 * [P1] §7: the sum of the unnormalised normals of the four quads around a sample, which equals
 * the central difference N ~ (h(x-1)-h(x+1), h(y-1)-h(y+1), 2*cell_size)/norm; one-sided at the
 * border and beside holes; NaN at holes. out must hold 3*width*height floats.
 * Returns HFVIS_OK or HFVIS_ERR_INVALID_ARGUMENT. Cost O(width*height). */
HFVIS_API hfvis_status hfvis_normals_compute(const hfvis_grid *grid, float *out);

/* The data exact rays derive from a grid before they trace (hfvis.h "Exact rays"), for a run
 * split into several calls over one grid (hfvis.h "Threads") to compute once and pass to each
 * call in hfvis_sweep_options.exact_grid (every call otherwise computes it in its scratch):
 * width*height + 1 doubles, out[y*width + x] the twist z(x, y) - z(x+1, y) - z(x, y+1) +
 * z(x+1, y+1) of cell (x, y) of the bilinear surface (the cross term that makes a cell bulge
 * between its edges; 0 in the last row and column), out[width*height] the class of the heights
 * (0 all finite, 1 holes and no infinite height, 2 an infinite height). Returns HFVIS_OK or
 * HFVIS_ERR_INVALID_ARGUMENT. Cost O(width*height).
 * Which parts a call reads: the class always; the twists only with the near and far field
 * (ray_near_cells) or on a grid of at most HFVIS_EXACT_TWIST_PLANE_CELLS samples. The sweep of
 * a larger grid computes each twist from its cell's four heights (the same doubles): there a
 * plane of 8 bytes a sample, read along the rays' lines, costs more in cache misses than it
 * saves (SVF K = 16 on fBm, this project's machine: 2048^2 7-10 % faster from the heights,
 * 4096^2 about 35 %, 1024^2 the same, 512^2 about 10 % slower). Such a caller needs only
 * out[width*height] written (hfvis_exact_grid_rows with out NULL gives the class alone). */
#define HFVIS_EXACT_TWIST_PLANE_CELLS 2097152 /* 2^21 samples: a 16 MB plane of twists */
HFVIS_API hfvis_status hfvis_exact_grid_compute(const hfvis_grid *grid, double *out);

/* hfvis_exact_grid_compute by row ranges, for a caller that makes the data over threads: the
 * twists of rows [row_begin, row_end) into out (laid out as above; its other elements
 * untouched; out NULL: none written) and in *height_class the class of those rows' heights (0,
 * 1 or 2 as above). Calls on disjoint row ranges may write one out concurrently (hfvis.h
 * "Threads"); when the ranges cover the grid, the largest of their classes stored in
 * out[width*height] completes what hfvis_exact_grid_compute writes, bit for bit. Returns
 * HFVIS_OK or HFVIS_ERR_INVALID_ARGUMENT (a bad grid, a NULL grid or height_class, a range
 * outside 0 <= row_begin < row_end <= height). Cost O(width*(row_end - row_begin)). */
HFVIS_API hfvis_status hfvis_exact_grid_rows(const hfvis_grid *grid, int row_begin, int row_end, double *out,
                                             int *height_class);

/* The parallel-line lattice of one look direction (docs/errata.md E5). Sweep direction
 * u = -(cos psi, sin psi), line offset v = (-u.y, u.x); node (i, j) lies at grid position
 * i*u + j*v; line j is traversed in increasing i. Lattice buffers are row-major with
 * rows j - j_min and columns i - i_min: rows = j_max-j_min+1, cols = i_max-i_min+1. */
typedef struct hfvis_lattice {
    double azimuth_rad;         /* look direction psi */
    double ux, uy, vx, vy;      /* unit vectors, snapped to exact 0/+-1 on the axes */
    int i_min, i_max, j_min, j_max;
    int width, height;          /* of the grid */
    double origin_x, origin_y;  /* tiles: node (i, j) lies at raster position i*u + j*v, grid
                                   position that minus this (the sweep options' origin_x/y);
                                   0, 0 from hfvis_lattice_init */
} hfvis_lattice;

/* Set up the lattice of look direction azimuth_rad over a width x height grid. The domain is
 * [0, width-1] x [0, height-1] (nodes within 1e-9 cell of its border inside), except that an axis
 * of one sample spans [-0.5, 0.5]: a grid one sample wide or tall is a strip one cell wide with
 * heights constant across it, so that every line crossing it holds a node and every grid point
 * has nodes to gather from (a line of zero width would hold a node only by chance).
 * Returns HFVIS_ERR_INVALID_ARGUMENT for NULL, sizes < 1 or a non-finite azimuth, and
 * HFVIS_ERR_LIMIT if the lattice would exceed 2^31 nodes. */
HFVIS_API hfvis_status hfvis_lattice_init(hfvis_lattice *lattice, int width, int height,
                                          double azimuth_rad);

/* Number of nodes of the lattice buffer, rows*cols; 0 for NULL or an empty lattice. */
HFVIS_API size_t hfvis_lattice_nodes(const hfvis_lattice *lattice);

/* The in-domain node range [*i_first, *i_last] of line j; returns the count (0 if empty, if j is
 * outside j_min..j_max or lattice is NULL: outputs not written then). */
HFVIS_API int hfvis_lattice_line(const hfvis_lattice *lattice, int j, int *i_first, int *i_last);

/* ========================================================================================== */
/* hfvis.c - P1 horizons ([P1] §5 Alg. 1, App. A.1)                */
/* ========================================================================================== */

/* How hfvis_sweep_options.direction_begin/end count the K directions. */
typedef enum hfvis_direction_order {
    HFVIS_DIRECTION_ORDER_DEFAULT = 0, /* = INDEX */
    HFVIS_DIRECTION_ORDER_INDEX = 1,   /* position p is direction k = p */
    HFVIS_DIRECTION_ORDER_SWEEP = 2    /* the order the sweep visits them: when K % 4 == 0,
                                          position p is k = p/4 + (p%4)*K/4, so the four quarter
                                          turns that share one sampled lattice ([P1] §7) are
                                          consecutive; else k = p. A range of whole quarter-turn
                                          groups (begin, end multiples of 4) samples only its own
                                          lattices: P such parts cost about 1/P of the run each */
} hfvis_direction_order;

/* How a sweep gives each receiver its horizon (see "Exact rays" below). 0 is the default. */
typedef enum hfvis_ray_mode {
    HFVIS_RAYS_DEFAULT = 0,   /* = LATTICE */
    HFVIS_RAYS_LATTICE = 0,   /* [P1]: lattice lines, gathered bilinearly (the GPU reference) */
    HFVIS_RAYS_EXACT = 1      /* every grid point its own ray, rational directions (beyond [P1]) */
} hfvis_ray_mode;

/* Largest accepted hfvis_sweep_options.ray_denominator. */
#define HFVIS_RAY_DENOMINATOR_MAX 4096
/* Largest accepted hfvis_sweep_options.ray_near_cells. */
#define HFVIS_RAY_NEAR_CELLS_MAX 65536

/* Options shared by every sweep (horizons, sky light, sky-view factor, shadows, environment). */
typedef struct hfvis_sweep_options {
    hfvis_border border;            /* default HFVIS_BORDER_OPEN */
    int border_cells;               /* CLAMP/WRAP: lines start this many cells outside the grid;
                                       0 = max(width, height) */
    double azimuth0_rad;            /* psi_0 of direction 0 */
    const hfvis_allocator *alloc;   /* scratch; NULL = malloc/free */
    int direction_begin;            /* process only the directions at positions [begin, end) of */
    int direction_end;              /* the K (direction_order), 0 <= begin < end <= K (else
                                       HFVIS_ERR_INVALID_ARGUMENT); 0, 0 = all K.
                                       Honoured by the per-direction sums (sky light, sky-view
                                       factor, environment light, visibility index, intervisibility,
                                       one indirect gather, hfvis_direction_sums: each returns its
                                       range's share of the sum) and by hfvis_horizon_map (the
                                       range's planes only); ignored by single-direction calls
                                       (hfvis_horizon_direction, hfvis_sun_visibility, lattices) */
    hfvis_progress_fn progress;     /* optional, called once per direction */
    void *progress_user;
    hfvis_direction_order direction_order; /* how direction_begin/end count; default INDEX */
    hfvis_ray_mode rays;            /* default HFVIS_RAYS_LATTICE; EXACT: see "Exact rays" */
    int ray_denominator;            /* EXACT: bound N on the direction's integer components,
                                       1..HFVIS_RAY_DENOMINATOR_MAX (the nearest direction);
                                       0 = the default rule of "Exact rays": max(5, ceil(K/4))
                                       for K <= 32, the cheapest within 0.25 deg (or a quarter
                                       of the sector 360/K deg for K > 360) for K > 32, and 64
                                       for a single direction (K = 1, hfvis_sun_visibility) */
    double max_distance;            /* R, world units: occluders farther than R from the receiver,
                                       measured horizontally along the ray, are ignored; 0 =
                                       unlimited (default), +INFINITY the same (today's sweep bit
                                       for bit); < 0 or NaN is HFVIS_ERR_INVALID_ARGUMENT. See
                                       "Search radius and tiles" */
    int origin_x, origin_y;         /* tiles: this grid is a window of a larger raster whose cell
                                       (origin_x, origin_y) is this grid's (0, 0); default 0, 0
                                       (must be 0, 0 when extent is 0, 0) */
    int extent_width, extent_height;/* that raster's size in cells (origin + grid size must fit
                                       in it); 0, 0 = this grid is the whole raster (default). A
                                       proper window needs a finite max_distance and the open
                                       border, else HFVIS_ERR_INVALID_ARGUMENT */
    int receiver_x, receiver_y;     /* compute only the receivers in this rectangle of the grid
                                       (inside it, else HFVIS_ERR_INVALID_ARGUMENT); */
    int receiver_width, receiver_height; /* 0, 0 = every receiver (default); outputs outside it
                                       are left unwritten; the work shrinks with it */
    int part_index, part_count;     /* hfvis_sun_visibility (both ray modes) and, in exact mode,
                                       hfvis_direction_sums: compute only the receivers of band
                                       part_index of part_count bands across each direction (each
                                       receiver belongs to the band of its distance across the
                                       sweep lines), so that threads can share one call's lines:
                                       every receiver is in exactly one band, its output equals
                                       the whole call's bit for bit, cells of the other bands are
                                       left alone (the calls may then write one out concurrently,
                                       see "Threads"; hfvis_direction_sums adds to its sums then).
                                       0, 0 = every receiver (default); else 0 <= part_index <
                                       part_count <= 65536 (HFVIS_ERR_INVALID_ARGUMENT otherwise,
                                       and from every other routine and mode for part_count > 1) */
    const float *normals;           /* NULL (default), or this grid's normals exactly as
                                       hfvis_normals_compute writes them (width*height*3 floats),
                                       only read: the sweeps that light the terrain (sky light,
                                       environment light and their hfvis_direction_sums in both
                                       ray modes, the [P2] indirect gather) read them instead of
                                       computing them in their scratch,
                                       so that the calls of a split run (hfvis.h, "Threads")
                                       compute them once and share them. Other values change the
                                       results (they are not checked) */
    int ray_near_cells;             /* EXACT: D, 0 = every sample of every ray (default); D > 0:
                                       each receiver's own ray within D cells, a far field shared
                                       by the receivers within half a cell of it beyond (hfvis.h
                                       "Exact rays", "Near and far field"), for the directions
                                       whose lines are longer than D between grid points and
                                       without a radius; 0..HFVIS_RAY_NEAR_CELLS_MAX */
    const double *exact_grid;       /* NULL (default), or this grid's data exactly as
                                       hfvis_exact_grid_compute writes it (width*height + 1
                                       doubles; which parts are read: there), only read:
                                       exact rays read it instead of computing it (up to 8
                                       bytes a sample of scratch and a pass over
                                       the grid per call), so that the calls of a split run
                                       compute it once. Other values change the results (not
                                       checked) */
} hfvis_sweep_options;

HFVIS_API hfvis_sweep_options hfvis_sweep_options_default(void);

/* The halo, in cells, that a tile of a run with search radius max_distance (world units, finite
 * and > 0), cell size cell_size and ray mode rays must carry on every side of its receiver
 * window for its outputs to equal the whole run's bit for bit (hfvis.h, "Search radius and
 * tiles"): ceil(max_distance / cell_size) + HFVIS_TILE_HALO_LATTICE (lattice mode) or
 * + HFVIS_TILE_HALO_EXACT (exact rays). Clip the window plus halo to the raster. Returns -1 for
 * an unlimited or invalid radius or cell size, or a halo beyond INT_MAX. */
#define HFVIS_TILE_HALO_LATTICE 5 /* gather nodes within 3 cells, their taps and normals 2 more */
#define HFVIS_TILE_HALO_EXACT 2   /* a crossing's or piece's second tap 1 more, normals 1 */
HFVIS_API int hfvis_tile_halo(double max_distance, double cell_size, hfvis_ray_mode rays);

/* The P1 hull stack along one line (Alg. 1 with the A.1 erratum fixed; ties pop).
 * For samples (distance[i], height[i]) with strictly increasing distance, writes
 * tan_out[i] = max_{j<i} (height[j]-height[i])/(distance[i]-distance[j]) (-INFINITY for i = 0)
 * and caster_out[i] = the maximising j (-1 for i = 0). Non-finite heights are holes: they
 * never occlude and get tan NaN, caster -1. caster_out may be NULL. stack must hold n ints.
 * Returns HFVIS_ERR_INVALID_ARGUMENT on NULL, n < 0 or non-increasing distances.
 * Cost: at most 2n comparisons. Exactly equal to hfvis_line_horizons_naive on generic input. */
HFVIS_API hfvis_status hfvis_line_horizons(const double *distance, const double *height, int n,
                                           double *tan_out, int *caster_out, int *stack);

/* Oracle: the O(n^2) brute-force maximum of the same slopes. Same contract, no scratch. */
HFVIS_API hfvis_status hfvis_line_horizons_naive(const double *distance, const double *height,
                                                 int n, double *tan_out, int *caster_out);

/* Raw lattice output of one direction, for GPU-port diffing: the horizon elevation angle at
 * every lattice node of hfvis_lattice_init(width, height, azimuth_rad); NaN at nodes outside the
 * grid and at holes. out must hold hfvis_lattice_nodes() floats.
 * Allocates 1 block of about 8*min(W^2+H^2, (W+H)^2/2) bytes (the sampled lattice: the largest
 * buffer over all directions, half the diagonal's square for a thin grid). Cost O(width*height). */
HFVIS_API hfvis_status hfvis_horizon_lattice(const hfvis_grid *grid, double azimuth_rad,
                                             const hfvis_sweep_options *opts, float *out);

/* Oracle for hfvis_horizon_lattice: every node scans all earlier samples of its line
 * (docs/errata.md E5). Bit-identical to the sweep. Cost O(width*height*N). */
HFVIS_API hfvis_status hfvis_horizon_lattice_naive(const hfvis_grid *grid, double azimuth_rad,
                                                   const hfvis_sweep_options *opts, float *out);

/* Horizon elevation toward direction k of K (psi_k = azimuth0 + 2 pi k/K) at every grid point:
 * the lattice gathered back with renormalised bilinear weights (docs/errata.md E7; exact for
 * axis directions). When K % 4 == 0, direction k is computed on the lattice of direction
 * k mod K/4 turned by whole quarter turns ([P1] §7), exactly as hfvis_horizon_map does, so
 * plane k of the map equals this output bit for bit; use it to split directions across threads
 * or machines. out[y*out_stride + x], out_stride >= width. Cost O(width*height). */
HFVIS_API hfvis_status hfvis_horizon_direction(const hfvis_grid *grid, int K, int k,
                                               const hfvis_sweep_options *opts, float *out,
                                               ptrdiff_t out_stride);

/* The full horizon map: K planes, plane k = out[k*width*height + y*width + x], the elevation
 * toward psi_k. out must hold K*width*height floats (check the product for overflow; it is
 * large: K = 64 at 1024^2 is 256 MiB; prefer the fused lighting calls). When K % 4 == 0 the
 * four directions psi, psi+pi/2, psi+pi, psi+3pi/2 share one sampled lattice ([P1] §7).
 * With opts->direction_begin/end = [b, e) only those planes are made: out then holds
 * (e-b)*width*height floats, in position order (opts->direction_order): the direction at
 * position p is out[(p-b)*width*height ...], bit-identical to its plane of the full map (split a
 * map across processes and stack the parts).
 * Returns HFVIS_ERR_INVALID_ARGUMENT for K < 1 or a bad range. Cost O(K*width*height). */
HFVIS_API hfvis_status hfvis_horizon_map(const hfvis_grid *grid, int K,
                                         const hfvis_sweep_options *opts, float *out);

/* Options of the per-receiver ray-march oracle. */
typedef struct hfvis_march_options {
    double step_cells;      /* march step along the ray in cells; 0 = 1 (the papers' naive
                               method takes unit steps, [P2] §1) */
    double max_distance_cells; /* stop after this distance; 0 = until the ray leaves the grid
                               (or border_cells beyond it for CLAMP/WRAP) */
} hfvis_march_options;

/* The defaults: step_cells 1, max_distance_cells 0 (to the grid's end). */
HFVIS_API hfvis_march_options hfvis_march_options_default(void);

/* Oracle: per-receiver bilinear ray march on the grid. For every receiver point (x_i, y_i)
 * (grid units; points[2*i], points[2*i+1]) and each of the K directions, samples the surface at
 * p + s*step*(cos psi_k, sin psi_k), s = 1, 2, ... and keeps the largest elevation.
 * out[i*K + k] = elevation angle. Border as in opts; with opts->rays = HFVIS_RAYS_EXACT the rays
 * follow the exact mode's actual directions (hfvis_sweep_azimuths). Use it for all grid points,
 * or for a subset of receivers (the bench does). Cost O(count*K*N). No allocation. */
HFVIS_API hfvis_status hfvis_horizon_reference(const hfvis_grid *grid, int K,
                                               const hfvis_sweep_options *opts,
                                               const hfvis_march_options *march,
                                               const float *points, size_t count, float *out);

/* Same oracle on an analytic surface: heights come from
 * fn(user, x, y) in world units, the domain is [0, width-1] x [0, height-1] in grid units and
 * one cell is cell_size world units. Only HFVIS_BORDER_OPEN is meaningful here. */
HFVIS_API hfvis_status hfvis_horizon_reference_fn(hfvis_height_fn fn, void *user, int width,
                                                  int height, double cell_size, int K,
                                                  const hfvis_sweep_options *opts,
                                                  const hfvis_march_options *march,
                                                  const float *points, size_t count,
                                                  float *out);

/* Topographic openness (Yokoyama, Shirasawa & Pike 2002, "Visualizing topography by openness",
 * PE&RS 68(3)). Positive openness: the mean over the K directions psi_k of the zenith angle
 * pi/2 - beta_k, beta_k the largest elevation angle of the terrain seen from the sample toward
 * psi_k within the horizontal distance radius. Negative openness: the mean nadir angle
 * pi/2 + delta_k, delta_k the smallest elevation angle within radius, computed as the positive
 * openness of -z (bit for bit). Radians in [0, pi]: pi/2 on a plane, more on summits (positive)
 * and in pits (negative). A direction that meets no terrain (the open border) counts
 * beta = -pi/2 (use HFVIS_BORDER_CLAMP to extend the edges). NaN at holes. */
typedef struct hfvis_openness_options {
    double radius;      /* search distance in world units, >= 0; 0 = unlimited */
    int negative;       /* 0: positive openness; 1: negative; 2: both, positive in out's first
                           height rows and negative in the next height rows (out must hold
                           2*height rows of out_stride); each plane equals its own run's bit
                           for bit, and with radius > 0 one march serves both signs */
    double step_cells;  /* radius > 0: march step in cells, >= 0; 0 = 1 */
} hfvis_openness_options;

/* The defaults: radius 0 (unlimited), positive openness, step_cells 1. */
HFVIS_API hfvis_openness_options hfvis_openness_options_default(void);

/* Openness at every grid point, out[y*out_stride + x]. opts: border, border_cells, azimuth0_rad,
 * alloc and progress, and with radius > 0 the receiver rectangle (its cells only are written, each
 * equal to the whole call's bit for bit: threads split one call by row bands); the direction
 * range is not honoured (all K); a search radius (max_distance), a window, or a rectangle
 * without a radius is HFVIS_ERR_INVALID_ARGUMENT.
 * radius > 0: the per-receiver march of hfvis_horizon_reference out to the radius, at step_cells
 *   (so the same bilinear samples as the oracle with max_distance_cells = radius/cell_size),
 *   O(K*W*H*radius/(cell_size*step_cells)); no allocation; progress once per row. Both signs
 *   (negative = 2) walk each ray once.
 * radius = 0: the exact sweep, hfvis_horizon_direction per direction, O(K*W*H); allocates
 *   W*H floats and W*H doubles (and W*H floats for negative; negative = 2 holds the positive
 *   plane in W*H floats more until the negative one is made) plus each sweep's scratch;
 *   progress once per direction (both signs: the positive run, then the negative one, each
 *   counting its K directions). Both ways each angle is rounded to float (as the horizon
 *   outputs hold it) and the K of a sample are summed in double, so with axis directions
 *   (K = 4, azimuth0 0) the sweep equals the march with a radius beyond the grid bit for bit;
 *   otherwise they differ by the gather tolerance of hfvis_horizon_direction.
 * Returns HFVIS_ERR_INVALID_ARGUMENT (bad grid, options, K < 1, out NULL, out_stride < width,
 * negative or non-finite radius or step, negative not 0, 1 or 2), HFVIS_ERR_OUT_OF_MEMORY or
 * HFVIS_ERR_LIMIT (the sweep's). */
HFVIS_API hfvis_status hfvis_openness(const hfvis_grid *grid, int K, const hfvis_openness_options *oo,
                                      const hfvis_sweep_options *opts, float *out,
                                      ptrdiff_t out_stride);

/* ========================================================================================== */
/* hfvis.c - exact rays (beyond [P1])                                                         */
/* ========================================================================================== */
/* The lattice mode gathers each receiver's horizon from the two lattice lines beside it ([P1]
 * §4, §7). Where the horizon field jumps (next to a wall, a roof edge, a cliff) that blend is
 * wrong by tens of degrees, and no lattice density cures it. With opts->rays = HFVIS_RAYS_EXACT
 * every grid point gets its own ray instead:
 *   - Directions are rational: look vector (a, b), integers with gcd 1 and max(|a|, |b|) <= N
 *     (opts->ray_denominator). The line through grid point g then passes through g + (a, b), so
 *     all grid points of a line share it. Between two of them the line crosses |a| - 1 columns
 *     and |b| - 1 rows; at a crossing the bilinear surface is the linear interpolation along that
 *     grid line, an exact point of the surface.
 *   - Between two crossings the ray stays in one cell, where the bilinear surface along it is a
 *     quadratic. Where that piece bulges above its chord (a saddle: box corners, the corners of
 *     stair-stepped cliffs) the tangent from a receiver can touch between the crossings, so such
 *     a piece also gets m - 1 evenly spaced interior samples, m the power of two up to 16 that
 *     brings the bulge below 1/16 cell of height (power-of-two spacing keeps every distance
 *     exact in double). Pieces out of reach (outside the grid, or for CLAMP/WRAP beyond
 *     border_cells) or touching a hole are not split.
 *   - Each line is swept from its far end with the hull stack of [P1] §5 (Alg. 1) over all its
 *     samples; each grid point reads the hull's tangent at its turn: the maximum elevation over
 *     every sample of its own ray. Along an axis the crossings are the grid points only (the
 *     surface is linear along a grid line).
 *   - Near field: next to the receiver the supremum is often no sample at all but the limit
 *     t -> 0+ (a receiver on a convex edge looking down: the slope of the cell the ray leaves
 *     by, at its corner, toward psi). Each receiver also takes that limit, (dz/dx |a| +
 *     dz/dy |b|) / (|(a, b)| cell) from the corner's two edge differences, and under a search
 *     radius the surface point exactly at the window's end (between two samples).
 *   - Definition and bound (HFVIS_EXACT_SUP_*_DEG): hfvis_horizon_exact_naive computes, receiver
 *     by receiver, the supremum over t > 0 of the elevation along the ray over the bilinear
 *     surface (within R under a radius): every crossing, every piece's stationary points in
 *     closed form, the t -> 0+ limit and the window's end. The sweep is never above it (every
 *     sample lies on the surface) and below it only where a piece's tangent point falls between
 *     its samples (pieces beyond the first are sampled, not maximized): on urban boxes, terraces
 *     with one-cell cliffs and fBm, all pairs, negative horizons and the near field included,
 *     mean <= 0.02 deg and p99 <= 0.52 deg measured (the roughest: white noise on fBm, 22 x 16
 *     cells); the stated bound, held by test_exact.c on hold-out fields, is
 *     HFVIS_EXACT_SUP_MEAN_DEG / HFVIS_EXACT_SUP_P99_DEG (docs/exact-rays.md).
 *   - Rule: with opts->ray_denominator = N > 0, direction k is the representable direction
 *     nearest to psi_k = azimuth0 + 2 pi k/K (ties: the smaller |a| + |b|). The default (0):
 *     K = 1: N = 64; K <= 32: N = max(5, ceil(K/4)), nearest; 32 < K <= 16384: the cheapest
 *     direction (smallest |a| + |b|, ties: the nearer; max(|a|, |b|) <= 256 for K <= 360, else
 *     <= min(4096, ceil(2K/pi) + 1)) within tau_K = min(0.25 deg, 90/K deg) of psi_k: a quarter
 *     sector or less, so the azimuths keep their order (from K = 6433 on the bound is capped at
 *     4096 and may hold no direction that near: then the nearest with max(|a|, |b|) <= 4096).
 *     K > 16384 is HFVIS_ERR_INVALID_ARGUMENT in exact mode.
 *     hfvis_sweep_azimuths returns the K azimuths actually used and their quadrature weights.
 *     Largest deviation from psi_k with the default and azimuth0 = 0: K = 4, 8: 0; K = 16, 32:
 *     0.70 deg; K = 64: 0.18; K = 128: 0.20; K = 256: 0.23; K = 360: 0.245; K = 7: 1.18
 *     (K = 1: <= 0.45).
 *   - Cost: a direction costs |a| + |b| - 1 crossings per receiver (1 on the axes and diagonals)
 *     where the lattice costs about one node, so closer directions cost longer sweeps: K = 16
 *     takes directions (1,0), (5,2), (1,1), (2,5): 3.5 crossings per receiver-direction on
 *     average, plus the interior samples below. The mean |a| + |b| of the default directions:
 *     K = 16: 4.2, K = 64: 11.7, K = 256: 15.5, K = 360: 20.5, K = 720: 27.8, K = 1024: 33.1,
 *     K = 4096: 75.6 (the nearest with N = ceil(K/4) would take 12.1, 51.5, 73, 166, 222, 897). Measured (make bench, section exact, 512^2 and 1024^2,
 *     K = 16, a quiet run 2026-12-07): the horizon map 0.53-0.57x the lattice map's time on
 *     urban DSMs (no gather), 1.05-1.45x on fBm rough at the cell scale; the fused sky-view
 *     factor 1.12-1.36x and 1.81-3.08x (earlier runs: up to 2.1x and 4.1x);
 *     at K = 64, 256, 360 on fBm 512^2 8.9x, 8.5x, 14.5x (docs/exact-rays.md, "Cost at large K").
 *     Instructions (callgrind, sky-view factor of the bench's fBm at 256^2): about 250 per
 *     receiver-direction at K = 16 and 650 at K = 64, the lattice about 104 (docs/exact-rays.md,
 *     "Fifth pass at K = 16").
 *   - Quadrature: every direction integral uses the actual azimuths phi_k. Direction k owns the
 *     sector between the midpoints to its neighbours (edges rounded to multiples of 2^-40 turn,
 *     so the shares w_k are exact and add up to exactly 1): the sky-view factor is
 *     1 - sum_k w_k sin(max(alpha_k, 0)), the uniform sky and the environment integrate [P1]
 *     Eq. 5-6 over each direction's own sector (the tangent-plane clamp taken along phi_k).
 *     A flat field gives SVF 1 and sky light albedo*sky exactly. For hfvis_direction_sums the
 *     sky-view term is K w_k sin(max(alpha_k, 0)), so every finish is the lattice mode's.
 *   - Holes never occlude and get NaN; borders as in the lattice mode: OPEN samples crossings
 *     inside the grid, CLAMP and WRAP also those up to border_cells cells outside it.
 *   - Where it applies: hfvis_horizon_map, hfvis_horizon_direction, hfvis_sky_light,
 *     hfvis_sky_view_factor, hfvis_env_light, hfvis_sun_visibility, hfvis_direct_light,
 *     hfvis_direction_sums (sky view, sky light, environment) and the ray-march oracles
 *     (hfvis_horizon_reference marches along the actual azimuths). The P2 sweeps
 *     (hfvis_intervisibility, hfvis_visibility_count, hfvis_indirect_light, hfvis_terrain_gi and
 *     their oracles, the visibility sums) keep their lattices: they return
 *     HFVIS_ERR_INVALID_ARGUMENT for HFVIS_RAYS_EXACT. hfvis_horizon_lattice and the *_from_map
 *     routines (uniform azimuths) ignore the field.
 *   - Outputs are written at grid points directly (no gather). Scratch: one block of about
 *     16*width*height bytes (the tangents and the cells' twists, 8 without the twists: with
 *     opts->exact_grid, or on a grid above HFVIS_EXACT_TWIST_PLANE_CELLS without the near
 *     field; plus 12 for normals and
 *     8*channels for the lighting sums) and a line's samples and hull stack,
 *     32*(16*(W + H + 2) + 4*border_cells) bytes.
 *   - Near and far field (opts->ray_near_cells = D > 0; 0, the default, is the sweep above bit
 *     for bit). A direction whose line is longer than D cells between grid points (|(a, b)| > D)
 *     costs |a| + |b| - 1 crossings per receiver in the sweep; instead each receiver takes the
 *     samples of its own ray nearer than D cells (every crossing, the split samples of the
 *     pieces that bulge, as the sweep takes them, the t -> 0+ limit: a stencil over the
 *     receivers of a row) and a far
 *     field shared by the receivers of M = floor(|(a, b)|) neighbouring lines: one line of
 *     direction (a, b), sampled like an exact line, within half a cell across of each of them
 *     (lines anchored at multiples of M of the raster's line index x b - y a), its upper hull
 *     kept as a tree so that every receiver finds the tangent from its own point to the hull of
 *     the samples D cells or more ahead. Every far sample lies within atan(1/(2D)) of the
 *     receiver's azimuth (D = 8: 3.6 deg); near the grid's edge, where the far line and the
 *     receivers' own rays end at different distances, the far line stops where the first of
 *     them ends and each line that runs on takes its own samples beyond (its tail).
 *     Directions with |(a, b)| <= D (K = 16: all) and runs with a finite radius keep the sweep.
 *     Accuracy: no longer never above the supremum; on a plane within |grad z across| / (2 D)
 *     in tangent; on urban boxes, terraces with one-cell cliffs and fBm (D = 8, K = 64 and 256)
 *     0.10-0.37 deg mean and 1.7-10.2 deg p99 from the supremum, all pairs (walls and cliffs seen
 *     or missed half a cell across), held to HFVIS_EXACT_FAR_MEAN_DEG / _P99_DEG. Receiver
 *     rectangles and sun bands equal the whole run bit for bit (a receiver's value depends on
 *     its own position only). Scratch: 12 bytes more per sample of a line and 8*width bytes.
 *     Cost (callgrind, sky-view factor of rough fBm 256^2, D = 8): about 640 instructions per
 *     receiver-direction at K = 256 and 580 at K = 64 (the lattice: about 100; the sweep:
 *     1150-1560 at 128^2), about 200 of them the near stencil; 4.1-4.6x the lattice's time at
 *     K = 64-360 on fBm 512^2 (make bench, quiet machine). Figures: docs/exact-rays.md, "Near
 *     and far field".
 *   - Accuracy: against the supremum over the bilinear surface (every pair) the exact mode is
 *     within 0.01 deg mean and 0.25 deg p99 on urban boxes, terraces with one-cell cliffs and
 *     fBm (the lattice: 2-6 deg mean, 23-70 deg p99); docs/exact-rays.md. */

/* ========================================================================================== */
/* hfvis.c - search radius and tiles                                                          */
/* ========================================================================================== */
/* A maximum search distance R (hfvis_sweep_options.max_distance, world units) and tiled runs:
 * a raster too large for one run is cut into windows, each run on its window plus a halo, and
 * the pieces equal the whole run bit for bit (the GIS tools' radius: GRASS r.horizon
 * maxdistance, SAGA and RVT radius, WhiteboxTools max_dist).
 *   - What R means. Exact rays: every sample (crossing or piece sample) whose horizontal
 *     distance from the receiver along its ray is at most R occludes, no other; distances are
 *     compared in 1/16 sub-steps of hfvis.h "Exact rays", exactly (floor(16 R L/(|(a, b)| cell))
 *     with L the sub-steps per step). Lattice mode: every lattice node sees the nodes of its line
 *     at most floor(R / cell_size) node steps behind it (the lattice spacing is one cell); the
 *     receiver's value is the usual gather of its nodes (docs/errata.md E7), so its own cut-off
 *     is R blended over the nodes within 1.5 cells. R below one cell: the lattice sees nothing
 *     (-pi/2 everywhere but holes), exact rays still see the crossings nearer than R, the first
 *     cell's t -> 0+ limit and the point at R ("Exact rays", near field). R beyond
 *     the field equals the unlimited run to the hull's rounding. With CLAMP/WRAP the border
 *     samples count like any other within R.
 *   - How ([P1] §5, Alg. 1 needs more: its hull answers "the highest over everything behind").
 *     Every line is cut into blocks of length R anchored at multiples of R of the raster's line
 *     coordinate (so a tile and the whole raster cut at the same places). A receiver in block b
 *     sees (i) the samples of block b before it: the Alg. 1 hull stack restarted at each block
 *     start, and (ii) the suffix of block b - 1 within R: the upper hull of block b - 1, built
 *     once right to left with an undo log (insertion: its stack height and the slot it
 *     overwrote) and undone one insertion at a time as the window start advances, queried by
 *     binary search for the vertex of greatest slope. The answer is the larger of the two; the
 *     query is skipped when the suffix's highest sample cannot beat (i) (an exact bound).
 *   - Cost: O(1) amortised per sample plus O(log h) per query (h the suffix hull's size), so it
 *     does not grow with R beyond that log; about 3 hull operations per sample where the
 *     unlimited sweep does 1. Measured (make bench, section radius; fBm, K = 16, sky-view factor,
 *     2-core machine under load): lattice 1024^2 1.3-1.7x the unlimited sweep's time at R = 16 to
 *     1024 cells, exact rays 512^2 1.4-2.3x (1.65-1.8x at R = 256). R = 0 or +INFINITY is the
 *     unlimited sweep's code path, bit for bit.
 *   - Memory: one line's window scratch, 100 bytes per sample of the longest line (lattice:
 *     about the grid diagonal; exact rays: the hull stack's length, plus 4 bytes per sample).
 *   - Tiles. Set origin_x/y to the grid's place in the raster, extent_width/height to the
 *     raster's size and receiver_* to the window inside the grid. Everything that depends on
 *     position is computed in raster coordinates: lattice nodes lie at raster positions
 *     i*u + j*v (hfvis_lattice.origin_x/y; the quarter turns of [P1] §7 likewise), the gathers
 *     and the open-border test read raster coordinates, exact-ray lines are numbered by the
 *     raster's grid points, and block boundaries are raster positions. A window needs a finite R
 *     (without R every receiver may see the whole raster: HFVIS_ERR_INVALID_ARGUMENT) and the
 *     open border (the border of a window is not the raster's).
 *   - Halo rule: read the window plus hfvis_tile_halo(R, cell_size, rays) cells on every side,
 *     clipped to the raster: ceil(R/cell) + 5 in lattice mode (the gather reads nodes within
 *     3 cells, their bilinear taps and normals 2 more), ceil(R/cell) + 2 with exact rays (a
 *     sample's second tap and the receiver's normal). The receivers of the window then equal the
 *     whole run's bit for bit (test/test_tiles.c checks sky-view factor, sky light, horizon map
 *     and sun visibility, both modes, on uneven windows down to one cell wide).
 *   - The receiver rectangle on its own works with any R and border: only its receivers are
 *     computed (lattice lines are cut to the nodes within 4 cells of it, exact-ray lines stop at
 *     their last receiver in it) and the rest of the output is left as it was.
 *   - Where it applies: hfvis_horizon_map, hfvis_horizon_direction, hfvis_sky_light,
 *     hfvis_sky_view_factor, hfvis_env_light, hfvis_sun_visibility, hfvis_direct_light,
 *     hfvis_direction_sums (sky view, sky light, environment), both modes, and
 *     hfvis_solar_irradiation (its map, sky and sums; not with TERRAIN reflection, and a window
 *     needs the site function rather than the maps: hfvis_solar_options.sweep). R also applies to hfvis_horizon_lattice(_naive)
 *     (no window: its nodes are those of hfvis_lattice_init; the rectangle is ignored) and to
 *     the oracles. Refused with HFVIS_ERR_INVALID_ARGUMENT (R, a window or a rectangle):
 *     hfvis_openness (it has its own radius).
 *   - The P2 hull-tree routines (hfvis_intervisibility, hfvis_visibility_count,
 *     hfvis_indirect_light, hfvis_terrain_gi, their oracles, the visibility sums; lattice mode
 *     only) honour R and refuse a window or a rectangle (HFVIS_ERR_INVALID_ARGUMENT). Rule: a
 *     sample counts for a receiver when it is visible (as without R: only nearer samples decide
 *     that) and at most floor(R / cell_size) node steps behind it, the lattice sweep's window.
 *     So a visible set with R is the unlimited one cut at R, the horizons listed to the callback
 *     are the minimal horizons within R, and indirect light gives the sky the band above the
 *     farthest visible sample within R (its sky part is hfvis_sky_light with the same R). The
 *     tree itself is unchanged (every sample is pushed: visibility within R needs all nearer
 *     samples, and a tree node's descendants are all farther than it, [P2] Eq. 2); the visible
 *     enumeration skips the horizon runs that end beyond R and lists no sample beyond it, so
 *     the listing and the consumers' work shrink with R, the tree's does not. The naive oracles
 *     stop their outward walk at R; they agree with the tree with R as they do without it
 *     (test/test_hfvis.c, p2t_radius_*).
 *   - Oracles, same cut-off: hfvis_horizon_lattice_naive (every node scans the nodes within R
 *     behind it), held to the sweep bit for bit on the test fields (tolerance 1e-12 rad for
 *     last-bit ties of the hull's cross products), and hfvis_horizon_exact_naive (the supremum
 *     within R: the sweep never above it, within HFVIS_EXACT_SUP_MEAN_DEG on average);
 *     hfvis_horizon_reference marches out to min(R, max_distance_cells).
 *     The oracles compute every receiver (the rectangle and origin do not change their values).
 *   - Design notes and figures: docs/search-radius.md. */

/* The K azimuths actually used by a run with these options (radians; azimuths[k] is plane k of
 * hfvis_horizon_map, index order) and their quadrature weights (each direction's share of the
 * circle, adding up to 1). Lattice mode: psi_k = azimuth0 + 2 pi k/K and 1/K. Exact mode: the
 * nearest rational directions, azimuths unwrapped to within pi of psi_k. Either array may be
 * NULL (not both). Allocates one block (K records) when weights are asked for in exact mode.
 * Returns HFVIS_OK, HFVIS_ERR_INVALID_ARGUMENT (K < 1, both NULL, bad options) or
 * HFVIS_ERR_OUT_OF_MEMORY. Cost O(K*N). */
HFVIS_API hfvis_status hfvis_sweep_azimuths(int K, const hfvis_sweep_options *opts,
                                            double *azimuths, double *weights);

/* The exact mode's horizons below the supremum of hfvis_horizon_exact_naive, over all receivers
 * and directions of a field ("Exact rays", "Definition and bound"): mean and 99th percentile. */
#define HFVIS_EXACT_SUP_MEAN_DEG 0.15
#define HFVIS_EXACT_SUP_P99_DEG 1.5
/* The same with the near and far field (ray_near_cells = 8, "Near and far field"): |horizon -
 * supremum| over all receivers and directions at K = 64 and 256, where far samples half a cell
 * across the ray decide (walls and cliffs seen or missed across, up to atan(1/(2D)) in azimuth). */
#define HFVIS_EXACT_FAR_MEAN_DEG 0.5
#define HFVIS_EXACT_FAR_P99_DEG 12.0

/* Oracle for the exact mode: for every grid point and direction, the supremum over t > 0 of the
 * elevation along its own ray over the bilinear surface (within R under a radius), receiver by
 * receiver: every grid-line crossing (the sweep's heights), every piece's stationary points in
 * closed form, the first piece's t -> 0+ limit and the window's end ("Exact rays"). Pieces count
 * where their cell is in reach (CLAMP/WRAP: border_cells beyond the grid) with four finite taps.
 * Always exact rays, whatever opts->rays says; otherwise the layout, range, border and hole rules
 * of hfvis_horizon_map. hfvis_horizon_map in exact mode is never above it and within the bound
 * stated in "Exact rays".
 * Allocates 1 block (2N crossings). Cost O(K*width*height*(max(W, H) + border_cells)). */
HFVIS_API hfvis_status hfvis_horizon_exact_naive(const hfvis_grid *grid, int K,
                                                 const hfvis_sweep_options *opts, float *out);

/* ========================================================================================== */
/* hfvis.c - P1 light ([P1] §6-7, Eq. 3-7)                                            */
/* ========================================================================================== */

/* [P1] Eq. 5 per sector: S_k(theta) = (Nz/K) sin^2 theta + (sin(pi/K)/pi) a (theta - sin 2theta / 2),
 * where a = Nx cos psi_k + Ny sin psi_k and theta the (tangent-clamped) horizon zenith angle.
 * Pure helper; the uniform-sky radiance is c * sum_k S_k. NaN for K < 1; non-finite inputs give
 * non-finite results. */
HFVIS_API double hfvis_sector_weight(int K, double nz, double a, double theta);

/* Uniform sky, fused into the sweep ([P1] §6.1 Eq. 4-5 with the clamp correction of docs/errata.md E3):
 * out = albedo * sky * sum_k S_k(theta_k) at every grid point, computed in lattice space with
 * bilinearly sampled normals and gathered (the paper's pipeline, [P1] §7). No horizon map is
 * stored: one block of about 48*(W^2+H^2) bytes, O(width*height). NaN at holes.
 * opts->direction_begin/end select a partial sum of the K directions. Cost O(K*width*height). */
HFVIS_API hfvis_status hfvis_sky_light(const hfvis_grid *grid, int K, float sky, float albedo,
                                       const hfvis_sweep_options *opts, float *out,
                                       ptrdiff_t out_stride);

/* The same from a stored horizon map (hfvis_horizon_map layout), evaluated at grid points with
 * grid normals. map_azimuth0_rad is the psi_0 the map was made with. Allocates 1 block (2K
 * doubles). */
HFVIS_API hfvis_status hfvis_sky_light_from_map(const hfvis_grid *grid, int K,
                                                double map_azimuth0_rad, const float *map,
                                                float sky, float albedo,
                                                const hfvis_allocator *alloc, float *out,
                                                ptrdiff_t out_stride);

/* Sky-view factor SVF = 1 - (1/K) sum_k sin(max(alpha_k, 0)), fused into the sweep (the term is
 * accumulated on the lattice and gathered), memory O(width*height). NaN at holes.
 * A direction range [b, e) returns its share (e-b)/K - (1/K) sum_{b<=k<e} ..., so the shares of
 * ranges that tile [0, K) add up to SVF (up to float rounding; hfvis_direction_sums keeps the
 * sums in double). */
HFVIS_API hfvis_status hfvis_sky_view_factor(const hfvis_grid *grid, int K,
                                             const hfvis_sweep_options *opts, float *out,
                                             ptrdiff_t out_stride);

/* Sky-view factor from a stored horizon map (K planes). */
HFVIS_API hfvis_status hfvis_sky_view_factor_from_map(const hfvis_grid *grid, int K,
                                                      const float *map, float *out,
                                                      ptrdiff_t out_stride);

/* Sun visibility in [0, 1] from one exact sweep toward the sun's azimuth (look direction
 * sun_azimuth_rad, hfvis.h convention) and its elevation. sun_radius_rad = 0 gives a hard shadow
 * (1 if the sun centre is above the horizon, else 0); > 0 gives the visible fraction of a sun
 * disc of that angular radius above the horizon line, 1 - (acos(d) - d sqrt(1-d^2))/pi with
 * d = clamp((elevation - alpha)/radius, -1, 1). Self-shadowing by the receiver's own tangent
 * plane is not included (multiply by max(n.l, 0) for lighting). NaN at holes.
 * Allocates 1 block (the sampled lattice). Cost O(width*height). */
HFVIS_API hfvis_status hfvis_sun_visibility(const hfvis_grid *grid, double sun_azimuth_rad,
                                            double sun_elevation_rad, double sun_radius_rad,
                                            const hfvis_sweep_options *opts, float *out,
                                            ptrdiff_t out_stride);

/* A lat-long environment ("PF map"): radiance[(t*n_phi + p)*channels + c]. Row t is the band
 * theta in [t*pi/n_theta, (t+1)*pi/n_theta) measured from the zenith (+z), so row 0 is the
 * zenith and the last row the nadir: the whole sphere, since horizons can lie below the
 * horizontal ([P1] §6.2). Column p is the azimuth band phi in [2pi p/n_phi, 2pi (p+1)/n_phi),
 * phi measured like psi (from +x toward +y). Radiance is constant within a texel. */
typedef struct hfvis_env {
    const float *radiance;
    int n_theta, n_phi;      /* >= 1 */
    int channels;            /* 1..4; n_theta*n_phi*channels floats must be addressable (a
                                count that overflows is HFVIS_ERR_INVALID_ARGUMENT) */
} hfvis_env;

typedef enum hfvis_env_method {
    HFVIS_ENV_DEFAULT = 0,
    HFVIS_ENV_PREFIX = 1,    /* exact prefix integrals A_k, B_k, C_k ([P1] Eq. 6-7; docs/errata.md E9) */
    HFVIS_ENV_LP_TABLE = 2   /* the paper's L_p table, [P1] Eq. 6-7, bilinear in (theta_n, theta_h) */
} hfvis_env_method;

typedef struct hfvis_env_options {
    hfvis_env_method method;  /* default HFVIS_ENV_PREFIX */
    int lp_normal_res;        /* L_p table theta_n samples, odd and >= 3; 0 = 15 ([P1] §6.2:
                                 16 is "safe"; odd so that theta_n = 0 is a sample) */
    int lp_horizon_res;       /* L_p table theta_h samples, >= 2; 0 = 257 ([P1]'s theta_N = 256
                                 intervals; odd so that theta_h = pi/2 is a sample and a flat
                                 receiver is exact, docs/errata.md E9) */
} hfvis_env_options;

HFVIS_API hfvis_env_options hfvis_env_options_default(void);

/* Floats of the per-direction environment tables for method and K (0 on invalid input). */
HFVIS_API size_t hfvis_env_table_floats(const hfvis_env *env, int K, const hfvis_env_options *eopts);

/* Build the per-direction tables (prefix integrals or the L_p table) for directions psi_k =
 * azimuth0_rad + 2 pi k / K. table must hold hfvis_env_table_floats() floats.
 * Prefix layout: 6*K*(n_theta+1)*channels floats, table[((k*(n_theta+1) + b)*6 + q)*C + c]:
 * q = 0..2 are A_k, B_k, C_k at the band edge b*pi/n_theta; q = 3..5 band b's sector
 * phi-integrals of L, L cos(phi - psi_k), L sin(phi - psi_k) (for partial bands).
 * L_p layout: K*M*T*channels floats, table[((k*M + i)*T + j)*C + c] = L_p^k(theta_n_i, theta_h_j)
 * with theta_n_i = pi (i/(M-1) - 1/2), theta_h_j = pi j/(T-1), 1/pi included.
 * Cost: O(K*(n_theta*(n_phi/K + 2) + M*T)*channels). */
HFVIS_API hfvis_status hfvis_env_table_build(const hfvis_env *env, int K, double azimuth0_rad,
                                             const hfvis_env_options *eopts, float *table);

/* Environment light, fused into the sweep: out[(y*out_stride + x)*channels + c] =
 * albedo/pi * sum_k [Nz A_k + a_k B_k + b_k C_k](theta_k) (prefix) or
 * albedo * sum_k |N_p| L_p^k(theta_n, theta_h) ([P1] Eq. 6), in lattice space, gathered.
 * out_stride in pixels. Allocates 2 blocks: the tables (hfvis_env_table_floats floats) and the
 * lattice scratch of hfvis_sky_light (plus channels-1 doubles per node).
 * opts->direction_begin/end select a partial sum of the K directions. */
HFVIS_API hfvis_status hfvis_env_light(const hfvis_grid *grid, int K, const hfvis_env *env,
                                       float albedo, const hfvis_sweep_options *opts,
                                       const hfvis_env_options *eopts, float *out,
                                       ptrdiff_t out_stride);

/* Environment light from a stored horizon map at grid points with grid normals.
 * Allocates 2 blocks (normals, tables). NaN at holes and where a map value is NaN. */
HFVIS_API hfvis_status hfvis_env_light_from_map(const hfvis_grid *grid, int K,
                                                double map_azimuth0_rad, const float *map,
                                                const hfvis_env *env, float albedo,
                                                const hfvis_env_options *eopts,
                                                const hfvis_allocator *alloc, float *out,
                                                ptrdiff_t out_stride);

/* Options of the hemisphere-integration oracle. */
typedef struct hfvis_hemisphere_options {
    int azimuth_samples;      /* azimuths integrated (midpoint rule); 0 = 256 */
    int zenith_samples;       /* zenith steps over [0, pi] (midpoint rule); 0 = 512 */
} hfvis_hemisphere_options;

/* The defaults: 256 azimuths, 512 zenith steps. */
HFVIS_API hfvis_hemisphere_options hfvis_hemisphere_options_default(void);

/* Oracle for all light paths: at receiver points[2i], points[2i+1] (grid units), numerically
 * integrates L_o = albedo/pi * Int L_i(w) V(w) max(n.w, 0) dw over the sphere, with V from the
 * exact horizon of the per-receiver ray march (hfvis_horizon_reference with the march options)
 * at every integration azimuth, and n the normal given in normals[3i..3i+2] (unit, z up).
 * env NULL means a uniform sky of radiance 1 (one channel). out[i*channels + c]. Integration
 * azimuths are absolute (phi_m = 2 pi (m + 1/2)/A): opts->azimuth0_rad and progress are not
 * used. NaN where the receiver, its normal or its horizon is not finite.
 * Cost O(count*(azimuth_samples*(N + zenith_samples))). No allocation. */
HFVIS_API hfvis_status hfvis_light_reference(const hfvis_grid *grid, const hfvis_env *env,
                                             float albedo, const hfvis_sweep_options *opts,
                                             const hfvis_march_options *march,
                                             const hfvis_hemisphere_options *hopts,
                                             const float *points, const float *normals,
                                             size_t count, float *out);

/* ========================================================================================== */
/* hfvis.c - P2 intervisibility ([P2] §4-8, Alg. 1-3, App. A.2)                               */
/* ========================================================================================== */

/* The convex-hull tree along one line ([P2] §5): samples are pushed in order of increasing
 * distance; after each push the tree's root children are the local visibility horizons of the
 * newest sample (the receiver), from which its visible samples follow. RecConvexity ([P2]
 * Alg. 1) runs iteratively on arrays indexed by sample (docs/errata.md E16) with the errata of
 * docs/errata.md E12-E13 fixed (the segment-start leaf is marked before the step's horizons are read; the
 * convexity test is Eq. 1's, strict). Lives in caller memory: no allocation. */
typedef struct hfvis_hull_tree hfvis_hull_tree;

typedef enum hfvis_tree_order {
    HFVIS_TREE_DEFAULT = 0,
    HFVIS_TREE_DEPTH_FIRST = 1,   /* pending tests on a LIFO stack ("step deeper" first) */
    HFVIS_TREE_BREADTH_FIRST = 2  /* FIFO: all siblings of a level first, the order of [P2]
                                     Alg. 2 (OptimizedConvexity); same output */
} hfvis_tree_order;

typedef struct hfvis_tree_options {
    hfvis_tree_order order;   /* default HFVIS_TREE_DEPTH_FIRST */
    int safe_zone;            /* 1 = SafeZoneUpdate shortcut ([P2] Alg. 3): when the new sample
                                 only replaces the root, skip the tests; same output; 0 = off */
    int safe_zone_steps;      /* window length b2 - b1 in samples; 0 = 4 ([P2] Alg. 3; docs/errata.md E15) */
} hfvis_tree_options;

/* The defaults: HFVIS_TREE_DEPTH_FIRST, SafeZoneUpdate off, safe_zone_steps 4. */
HFVIS_API hfvis_tree_options hfvis_tree_options_default(void);

/* Bytes of caller memory for a tree of up to max_samples samples (0 if max_samples < 1 or the
 * size overflows). The memory must be aligned for double (malloc'd memory is). */
HFVIS_API HFVIS_EXPERIMENTAL size_t hfvis_hull_tree_size(int max_samples);

/* Set up a tree in mem (mem_size >= hfvis_hull_tree_size(max_samples)); opts may be NULL.
 * *tree points into mem; nothing is allocated; no cleanup is needed.
 * Returns HFVIS_ERR_INVALID_ARGUMENT (NULL, bad options) or HFVIS_ERR_BUFFER_TOO_SMALL. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_hull_tree_init(void *mem, size_t mem_size, int max_samples,
                                                              const hfvis_tree_options *opts, hfvis_hull_tree **tree);

/* Empty the tree for a new line (keeps capacity and options; the iteration count restarts).
 * tree may be NULL (no-op). */
HFVIS_API HFVIS_EXPERIMENTAL void hfvis_hull_tree_reset(hfvis_hull_tree *tree);

/* Push the next sample (distance strictly greater than the previous one, finite height) and
 * update the tree ([P2] Alg. 1). *horizon_count (may be NULL) receives the number of root
 * children. Returns HFVIS_ERR_INVALID_ARGUMENT for a non-finite value or a non-increasing
 * distance, HFVIS_ERR_LIMIT when max_samples samples are already in the tree.
 * Cost: amortised O(m) for m horizons; t <= 2m + n tests over a line ([P2] §6). */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_hull_tree_push(hfvis_hull_tree *tree, double distance, double height,
                                                              int *horizon_count);

/* The horizons of the newest sample, farthest first, as sample indices (push order) into out
 * (capacity cap). minimal = 0 gives the root children as the tree holds them, which are a
 * superset of the local horizons (docs/errata.md E14); minimal = 1 keeps only true local horizons
 * (sample 0, or a sample whose predecessor is hidden). Returns the count (which may exceed cap:
 * then only cap are written), or -1 on NULL. */
HFVIS_API HFVIS_EXPERIMENTAL int hfvis_hull_tree_horizons(const hfvis_hull_tree *tree, int minimal, int *out, int cap);

/* Number of samples pushed, and RecConvexity tests made since the last reset (the paper's
 * iteration count t; t <= 2m + n). Both 0 for NULL. */
HFVIS_API HFVIS_EXPERIMENTAL int hfvis_hull_tree_count(const hfvis_hull_tree *tree);
HFVIS_API int64_t hfvis_hull_tree_iterations(const hfvis_hull_tree *tree);

/* Visible samples of receiver index `receiver` on a line (distance increasing), enumerated
 * from its horizon list (farthest first) as [P2] §10.1: out receives the sample indices farthest
 * first (elevation seen from the receiver non-increasing). A sample is visible when its
 * elevation is >= that of every sample between it and the receiver (grazing counts). Holes
 * (non-finite heights) are never visible and never occlude. Returns the count (written up to
 * cap), or -1 on invalid input. Cost O(visible). */
HFVIS_API int hfvis_line_visible_from_horizons(const double *distance, const double *height,
                                               int receiver, const int *horizons, int m,
                                               int *out, int cap);

/* Oracles: the naive visible set (walk from the receiver outward keeping the running maximum,
 * [P2] §10.1), farthest first, and the naive local horizons (visible samples whose predecessor is
 * not visible), farthest first. Same return convention. Cost O(receiver). */
HFVIS_API int hfvis_line_visible_naive(const double *distance, const double *height, int receiver,
                                       int *out, int cap);
HFVIS_API int hfvis_line_local_horizons_naive(const double *distance, const double *height,
                                              int receiver, int *out, int cap);

/* One receiver-direction of a field sweep, handed to a visibility callback. The line arrays
 * hold the samples from the line's start (negative distances: the CLAMP/WRAP pre-roll) up to
 * and including the receiver; distances and heights in world units. */
typedef struct hfvis_visibility_event {
    int k;                     /* direction index; the receiver looks toward psi_k */
    double x, y;               /* receiver position, grid units (a lattice node) */
    const double *distance;
    const double *height;
    int receiver;              /* index of the receiver in the line arrays */
    const int *horizons;       /* local horizons, farthest first (minimal set) */
    int horizon_count;
    const int *visible;        /* visible samples, farthest first */
    int visible_count;
} hfvis_visibility_event;

typedef void (*hfvis_visibility_fn)(void *user, const hfvis_visibility_event *event);

/* Counters of a field sweep ([P2] Tables 1-2: visible points, horizons m_a, iterations t_a). */
typedef struct hfvis_visibility_stats {
    double receivers;          /* receiver-directions visited */
    double visible;            /* visible samples, summed */
    double horizons;           /* tree root children (the paper's m), summed */
    double iterations;         /* RecConvexity tests (tree) or samples scanned (naive), summed */
} hfvis_visibility_stats;

/* Intervisibility over the whole field: for each of the K directions, every lattice line is
 * swept with the hull tree and the callback receives each receiver's horizons and visible
 * samples as they are found (nothing is stored: the output can be O(N) per receiver). Border
 * and hole rules as for the horizon sweeps. opts->alloc serves the scratch (one block).
 * stats may be NULL. Cost O(K * (W*H + total horizons + total visible)). */
HFVIS_API hfvis_status hfvis_intervisibility(const hfvis_grid *grid, int K,
                                             const hfvis_sweep_options *opts,
                                             const hfvis_tree_options *tree_opts,
                                             hfvis_visibility_fn fn, void *user,
                                             hfvis_visibility_stats *stats);

/* Visibility index ("total viewshed"): the number of samples each grid point sees along the K
 * directions, sum over k of the visible samples of its line (gathered from the lattice like the
 * light paths). Pre-roll samples outside the grid are not counted. NaN at holes.
 * opts->direction_begin/end select a partial count ([P2] §10.1: a sum over the K
 * lines); the counts are gathered bilinearly from the lattices, so they are not integers off the
 * axis directions, and the parts of a split add up to the full count up to float rounding. */
HFVIS_API hfvis_status hfvis_visibility_count(const hfvis_grid *grid, int K,
                                              const hfvis_sweep_options *opts,
                                              const hfvis_tree_options *tree_opts, float *out,
                                              ptrdiff_t out_stride, hfvis_visibility_stats *stats);

/* Oracle: the same counts from the naive visible sets ([P2] §1 on the same lattice).
 * Equal to hfvis_visibility_count exactly, except on samples collinear with the receiver up to
 * the last bit (bilinear ramps off a box edge, e.g.), where the tree's cross products and these
 * quotients may break the tie differently (a zero-width band: indirect light agrees).
 * Cost O(K*W*H*N). */
HFVIS_API hfvis_status hfvis_visibility_count_naive(const hfvis_grid *grid, int K,
                                                    const hfvis_sweep_options *opts, float *out,
                                                    ptrdiff_t out_stride,
                                                    hfvis_visibility_stats *stats);

/* Indirect light from visible terrain ([P2] §10.1 with the band rule of docs/errata.md E17): for each
 * receiver and direction, the visible samples s_1..s_M (far to near) each own the band of
 * zenith angles between themselves and the next nearer visible sample; the receiver reflects
 * out = albedo * [ sky * S^(theta(s_1)) + sum_j L_exit(s_j) (S^(theta(s_{j+1})) - S^(theta(s_j))) ]
 * summed over k, with S^ the tangent-clamped sector integral of [P1] Eq. 5, 1/pi included,
 * and theta(s_{M+1}) the tangent plane (so the sky part is
 * exactly the uniform-sky light of hfvis_sky_light, and uniform exit radiance c with sky c gives
 * c * sum_k S_k: the furnace identity, docs/errata.md E17). exit_radiance[(y*width + x)*channels + c]
 * is the surface's exit radiance (bilinear between samples, border rule outside), channels 1..4;
 * sky is the uniform sky radiance above the horizon (0 for terrain light only).
 * out[(y*out_stride + x)*channels + c]; NaN at holes. One block of scratch. */
HFVIS_API hfvis_status hfvis_indirect_light(const hfvis_grid *grid, int K,
                                            const float *exit_radiance, int channels, float sky,
                                            float albedo, const hfvis_sweep_options *opts,
                                            const hfvis_tree_options *tree_opts, float *out,
                                            ptrdiff_t out_stride);

/* Oracle: the same gather from the naive visible sets; equal to hfvis_indirect_light up to float
 * rounding (the same bands are summed in the same order). */
HFVIS_API hfvis_status hfvis_indirect_light_naive(const hfvis_grid *grid, int K,
                                                  const float *exit_radiance, int channels,
                                                  float sky, float albedo,
                                                  const hfvis_sweep_options *opts, float *out,
                                                  ptrdiff_t out_stride);

/* Direct + indirect light with bounces ([P2] §10.1; docs/errata.md E17):
 *   L_0 = emission + albedo * direct,  L_{b+1} = emission + albedo * (direct + I[L_b]),
 * where I[L] is hfvis_indirect_light of exit radiance L with sky 0 and albedo 1, and direct is
 * the caller's direct light as reflected radiance for albedo 1 (e.g. hfvis_sky_light plus sun
 * E_sun/pi * max(n.l, 0) * visibility). out = L_B, the exit radiance after `bounces` bounces
 * (0 = direct light and emission only). albedo is per sample (albedo_map, channels values per
 * sample) or constant (albedo_map NULL: albedo_value). emission may be NULL.
 * direct, emission, albedo_map: [(y*width + x)*channels + c]. out likewise (width stride).
 * Allocates the bounce buffers (2 blocks) and each sweep's scratch. */
HFVIS_API hfvis_status hfvis_terrain_gi(const hfvis_grid *grid, int K, const float *direct,
                                        const float *emission, const float *albedo_map,
                                        float albedo_value, int channels, int bounces,
                                        const hfvis_sweep_options *opts,
                                        const hfvis_tree_options *tree_opts, float *out);

/* A sun: a disc of angular radius radius_rad at (azimuth_rad, elevation_rad) (look direction,
 * hfvis.h convention) giving irradiance[c] on a surface facing it. */
typedef struct hfvis_sun {
    double azimuth_rad, elevation_rad, radius_rad;
    float irradiance[4];
} hfvis_sun;

/* Direct light ([P1]) as reflected radiance for albedo 1, the `direct` input of
 * hfvis_terrain_gi: sun part E/pi * max(n.l, 0) * V_sun (hfvis_sun_visibility; l the sun
 * centre's direction) plus sky part: env NULL gives sky * sum_k S_k (hfvis_sky_light, every
 * channel), else the environment light (hfvis_env_light, env->channels must equal channels).
 * sun may be NULL. out[(y*width + x)*channels + c]. Allocates the scratch of the calls it makes
 * plus one plane. */
HFVIS_API hfvis_status hfvis_direct_light(const hfvis_grid *grid, int K, const hfvis_sun *sun,
                                          float sky, const hfvis_env *env, int channels,
                                          const hfvis_sweep_options *opts, float *out);

/* ========================================================================================== */
/* hfvis.c - solar radiation (NREL SPA; r.sun's ESRA clear sky over exact horizons)           */
/* ========================================================================================== */
/* Sun position, clear-sky irradiance and its time integral over a height field, shaded by the
 * exact-ray horizons (hfvis.h "Exact rays"). The atmosphere is the one GRASS r.sun computes
 * (Suri & Hofierka 2004, "A New GIS-based Solar Radiation Model", Transactions in GIS 8(2); the
 * ESRA model, Rigollier, Bauer & Wald 2000, Solar Energy 68(1)), so r.sun's numbers can be
 * reproduced; the sun comes from NREL's Solar Position Algorithm (Reda & Andreas 2004, Solar
 * Energy 76(5), revised 2008, NREL/TP-560-34302; +-0.0003 deg from -2000 to 6000) or from
 * r.sun's own declination and solar time. docs/solar.md has the equations, the errata and the
 * measured accuracy and speed. Units: W/m^2 for an instant, Wh/m^2 for a period, hours for
 * sunshine duration; angles in radians like the rest of the API. */

/* Input of hfvis_spa: one instant (UTC calendar date and time) at one place. */
typedef struct hfvis_spa_input {
    int year, month, day;     /* Gregorian from 1582-10-15, Julian before; year -2000..6000 */
    int hour, minute;         /* UTC, 0..24 (24:00:00 = next day's 00:00), 0..59 */
    double second;            /* [0, 60] */
    double delta_ut1;         /* UT1 - UTC in seconds, (-1, 1) (IERS bulletins; 0 is fine) */
    double delta_t;           /* TT - UT1 in seconds, |delta_t| <= 8000 (about 69 s in 2020-2030) */
    double latitude_rad;      /* geodetic, [-pi/2, pi/2] */
    double longitude_rad;     /* east positive, [-pi, pi] */
    double elevation_m;       /* above the ellipsoid, >= -6500000 */
    double pressure_mbar;     /* refraction only: annual mean local pressure, (0, 5000] */
    double temperature_c;     /* refraction only: annual mean temperature, (-273, 6000] */
    double atmos_refract_rad; /* refraction only: the refraction at sunrise and sunset (SPA's
                                 0.5667 deg); the correction applies while the true elevation
                                 is >= -(sun radius 0.26667 deg + this), [0, 0.1] */
    int refraction;           /* 1: apparent (refracted) elevation, SPA Eq. 41-43; 0: true */
} hfvis_spa_input;

/* hfvis_spa's results: the intermediate values of the paper's example table, then the answer.
 * Angles in radians; longitudes and right ascensions in [0, 2 pi). */
typedef struct hfvis_spa_result {
    double jd, jde;              /* Julian day (UT) and Julian ephemeris day */
    double helio_longitude;      /* L, Earth heliocentric (SPA Eq. 9-10) */
    double helio_latitude;       /* B */
    double radius_au;            /* R, Earth-Sun distance in AU */
    double nutation_longitude;   /* delta psi (Eq. 22) */
    double nutation_obliquity;   /* delta epsilon (Eq. 23) */
    double obliquity;            /* epsilon, true obliquity of the ecliptic (Eq. 25) */
    double apparent_longitude;   /* lambda, apparent sun longitude (Eq. 27) */
    double sidereal_time;        /* nu, apparent sidereal time at Greenwich (Eq. 29) */
    double right_ascension;      /* alpha, geocentric (Eq. 30) */
    double declination;          /* delta, geocentric (Eq. 31) */
    double hour_angle;           /* H, observer local (Eq. 32) */
    double topo_declination;     /* delta', topocentric (Eq. 38) */
    double topo_hour_angle;      /* H', topocentric (Eq. 39) */
    double elevation;            /* e, topocentric; refracted when in->refraction (Eq. 43) */
    double zenith;               /* theta = pi/2 - e (Eq. 44) */
    double azimuth;              /* Phi, from north toward east (Eq. 46); the hfvis look
                                    azimuth of the sun is Phi - pi/2 */
} hfvis_spa_result;

/* NREL's Solar Position Algorithm (Reda & Andreas 2004/2008): the tables of periodic terms of
 * VSOP87 (Table A4.2) and the nutation series (Table A4.3), aberration, topocentric parallax and
 * optionally the refraction correction. Accuracy +-0.0003 deg (the paper); test/test_solar.c
 * holds it to the paper's example (Table A5.1) within 1e-6 deg and to an independent
 * low-precision algorithm (Meeus 1998 ch. 25, +-0.01 deg) over a grid of instants and places.
 * Returns HFVIS_ERR_INVALID_ARGUMENT for NULL or a field out of its range (a date that does not
 * exist: February 30, month 13, ...). No allocation; about 250 sines and cosines. */
HFVIS_API hfvis_status hfvis_spa(const hfvis_spa_input *in, hfvis_spa_result *out);

/* r.sun's solar geometry, for reproducing r.sun: the declination of day of year `day`
 * (1..366) delta = asin(0.3978 sin(d - 1.4 + 0.0355 sin(d - 0.0489))), d = 2 pi day / 365.25
 * (r.sun's com_declin, sign flipped back to the usual convention), the hour angle
 * omega = (solar_hour - 12) * pi/12 of local solar time, the true elevation and the azimuth Phi
 * (from north toward east) at latitude_rad, the day's sunrise and sunset in solar hours
 * (0 and 24 under the midnight sun, 12 and 12 in the polar night) and r.sun's extraterrestrial
 * irradiance 1367 (1 + 0.03344 cos(d - 0.048869)) W/m^2. Returns HFVIS_ERR_INVALID_ARGUMENT for
 * NULL, a day outside 1..366, a non-finite hour or a latitude outside [-pi/2, pi/2]. */
typedef struct hfvis_rsun_sun {
    double declination, hour_angle, elevation, azimuth;
    double sunrise_hour, sunset_hour;
    double extraterrestrial;     /* W/m^2 on a surface facing the sun, top of the atmosphere */
} hfvis_rsun_sun;
HFVIS_API hfvis_status hfvis_rsun_sun_position(int day, double solar_hour, double latitude_rad,
                                               hfvis_rsun_sun *out);

/* The ESRA clear sky as r.sun computes it, for a sun of true elevation elevation_rad > 0 over a
 * point height_m above sea level, Linke turbidity linke in (0, 10] and extraterrestrial normal
 * irradiance g0 (W/m^2): out[0] = beam normal irradiance, out[1] = beam on the horizontal,
 * out[2] = diffuse on the horizontal (W/m^2). Relative optical air mass: Kasten & Young 1989
 * with ESRA's refraction of the elevation and the elevation correction exp(-height/8434.5);
 * Rayleigh optical thickness (Kasten 1996 as ESRA fits it); diffuse transmission and angular
 * function of ESRA (Rigollier et al. 2000, Eq. 10-14). Elevation <= 0 gives 0, 0, 0.
 * HFVIS_ERR_INVALID_ARGUMENT for NULL or a non-finite or out-of-range argument. */
HFVIS_API hfvis_status hfvis_esra_clear_sky(double g0, double elevation_rad, double height_m,
                                            double linke, double out[3]);

/* Which sun: 0 is the default (SPA). */
typedef enum hfvis_sun_model {
    HFVIS_SUN_MODEL_DEFAULT = 0, /* = SPA */
    HFVIS_SUN_SPA = 1,           /* hfvis_spa at civil times UTC + utc_offset_hours; the
                                    extraterrestrial irradiance is 1367/R^2 */
    HFVIS_SUN_RSUN = 2           /* hfvis_rsun_sun_position: times are local solar time, the
                                    days are days of the year, and each day is stepped as
                                    r.sun steps it (the first step half a step or one and a half
                                    after sunrise, then every step while before sunset) */
} hfvis_sun_model;

/* The sky diffuse term on a receiver. 0 is the default (r.sun's). */
typedef enum hfvis_solar_diffuse {
    HFVIS_SOLAR_DIFFUSE_DEFAULT = 0,
    HFVIS_SOLAR_DIFFUSE_RSUN = 0,    /* Muneer's model on the local slope only, as r.sun */
    HFVIS_SOLAR_DIFFUSE_HORIZON = 1  /* beyond r.sun: the isotropic part of Muneer's model over
                                        the sky the receiver actually sees (scaled by V/r_sky,
                                        V the cosine-weighted visible sky of the exact horizon,
                                        hfvis_sky_light with sky 1; with HORN normals [P1]
                                        Eq. 5 over the map's K horizons above Horn's tangent
                                        plane; r_sky = (1 + cos slope)/2),
                                        the circumsolar part shaded with the beam */
} hfvis_solar_diffuse;

/* The ground-reflected term. 0 is the default (r.sun's). */
typedef enum hfvis_solar_reflected {
    HFVIS_SOLAR_REFLECTED_DEFAULT = 0,
    HFVIS_SOLAR_REFLECTED_RSUN = 0,   /* albedo * (beam + diffuse on the horizontal) *
                                         (1 - cos slope)/2: an infinite flat ground */
    HFVIS_SOLAR_REFLECTED_TERRAIN = 1 /* beyond r.sun: the light reflected by the terrain the
                                         receiver actually sees ([P2] hfvis_indirect_light of
                                         exit irradiance albedo * (beam + diffuse) of each
                                         sample, lattice mode, reflected_directions directions);
                                         one bounce */
} hfvis_solar_reflected;

/* Bands of the outputs. 0 is the default (one band: the whole period). */
typedef enum hfvis_solar_bands {
    HFVIS_SOLAR_BANDS_DEFAULT = 0,
    HFVIS_SOLAR_BANDS_TOTAL = 0,  /* one band */
    HFVIS_SOLAR_BANDS_DAY = 1,    /* one band per day of the period */
    HFVIS_SOLAR_BANDS_MONTH = 2   /* one band per calendar month the period touches */
} hfvis_solar_bands;

/* The horizons that shade the beam (and bound HORIZON's visible sky) in the fast routine. The
 * oracle always takes each receiver's own exact ray. Errors against it (mean over receivers of
 * |fast - oracle| / oracle of the daily global, beam in brackets; one day, K = 64) and the cost
 * of the map on the Colorado tile (512^2, 90 m): docs/solar.md "Horizon modes". */
typedef enum hfvis_solar_horizons {
    HFVIS_SOLAR_HORIZONS_DEFAULT = 0,  /* = EXACT */
    HFVIS_SOLAR_HORIZONS_EXACT = 1,    /* exact rays, every sample of every ray (the sweep's
                                          ray_near_cells as given, 0 by default) */
    HFVIS_SOLAR_HORIZONS_NEAR_FAR = 2, /* exact rays within HFVIS_SOLAR_NEAR_CELLS cells, the
                                          shared far field beyond (hfvis_sweep_options.
                                          ray_near_cells; about 0.6x the exact map's cost at K = 64
                                          on the Colorado tile) */
    HFVIS_SOLAR_HORIZONS_LATTICE = 3   /* [P1] lattice horizons (HFVIS_RAYS_LATTICE; about 3x
                                          cheaper than the exact map at K = 64 on the Colorado
                                          tile; misses shadow next to one-cell walls and
                                          cliffs) */
} hfvis_solar_horizons;
#define HFVIS_SOLAR_NEAR_CELLS 8

/* The surface normal of a receiver: its incidence angle, its tangent plane (the shading's lower
 * bound), r_sky = (1 + cos slope)/2, Muneer's F_g and the HORIZON visible sky. 0 is the default
 * (hfvis's own, hfvis.h "Grids"). */
typedef enum hfvis_solar_normals {
    HFVIS_SOLAR_NORMALS_DEFAULT = 0,
    HFVIS_SOLAR_NORMALS_CENTRAL = 0, /* the central differences of the four neighbours (one-sided
                                        at the border and next to holes), as hfvis_normals_compute */
    HFVIS_SOLAR_NORMALS_HORN = 1     /* Horn 1981 ("Hill shading and the reflectance map",
                                        Proc. IEEE 69(1), its 3x3 gradient estimate): each
                                        partial derivative the (1, 2, 1)-weighted
                                        mean of the three central differences across the window,
                                        as GRASS r.slope.aspect and gdaldem slope/aspect compute
                                        slope and aspect (what r.sun reads); where a neighbour
                                        of the 3x3 window is outside the grid or a hole, the
                                        central difference (CENTRAL). r.slope.aspect leaves those
                                        cells NULL (without -e) and gdaldem nodata (without
                                        -compute_edges). The TERRAIN reflected term's [P2]
                                        gather keeps its own (central) normals */
} hfvis_solar_normals;

/* What to compute: the site, the period and the surface. hfvis_solar_input_default() fills in
 * linke 3, albedo 0.2, days 1, 2026-06-21; latitude and longitude are the caller's to set. */
typedef struct hfvis_solar_input {
    double latitude_rad;      /* the site when the maps below are NULL: the sun is computed at */
    double longitude_rad;     /* this one place for the whole grid (east positive; SPA needs
                                 the longitude, RSUN ignores it) */
    const double *latitude_map;  /* per sample [y*width + x] (holes too), radians (geodetic
                                    latitude in [-pi/2, pi/2], longitude east positive in
                                    [-pi, pi]), both or */
    const double *longitude_map; /* neither: each sample's own site, e.g. the inverse projection
                                    of its CRS. The grid's up direction (-y) is then taken at the
                                    true azimuth the maps give it (the meridian convergence, from
                                    their differences along y, along x on a one-row grid), and the
                                    sun is computed per block of samples whose local frames are
                                    within opts->site_tolerance_rad of the block centre's */
    void (*site)(void *user, int x, int y, double *latitude_rad, double *longitude_rad);
                              /* or, in place of the maps (both NULL), each sample's site by
                                 this function: it stores the latitude and longitude (radians,
                                 ranges as the maps') of raster cell (x, y), where the grid's
                                 (0, 0) is raster cell (opts->sweep's origin_x, origin_y) and
                                 0 <= x < extent_width, 0 <= y < extent_height (the grid's size
                                 without a window). It is called for cells of the whole raster,
                                 outside the grid too: the blocks sharing a sun are cut from the
                                 raster's extent, and the convergence takes the neighbours
                                 clamped at the raster's edges, so a window's samples get the
                                 whole raster's suns (tiles, hfvis.h "Search radius and
                                 tiles"). It must give the same values for the same cell on
                                 every call; a value out of range is HFVIS_ERR_INVALID_ARGUMENT.
                                 The maps need the grid to be the raster (no window) */
    void *site_user;          /* passed to site */
    double height_m;          /* SPA's observer height; the air mass uses each sample's z */
    int year, month, day;     /* first day; RSUN steps day of the year from it */
    int days;                 /* >= 1 days from the first (ignored for an instant) */
    int instant;              /* 1: one instant at `hour` of the first day: W/m^2 outputs */
    double hour;              /* instant: [0, 24], UTC + utc_offset_hours (solar time in RSUN) */
    double utc_offset_hours;  /* SPA: the days and the instant are local civil time UTC +
                                 this, [-14, 14] */
    double linke;             /* Linke turbidity (0, 10] */
    double albedo;            /* ground albedo [0, 1] */
} hfvis_solar_input;

HFVIS_API hfvis_solar_input hfvis_solar_input_default(void);

/* Options of hfvis_solar_irradiation; NULL or zero = the defaults. */
typedef struct hfvis_solar_options {
    hfvis_sun_model model;       /* default SPA */
    double step_hours;           /* integration step, (0, 24]; 0 = 0.25 (15 minutes) */
    int directions;              /* K of the exact horizon map read per time step, 0..4096; 0 = 64.
                                    A day on a 512^2 DEM: 16 is about 5x faster than 64, its
                                    daily global within 0.05-0.2 % (mean) of the oracle against
                                    0.01-0.03 % (docs/solar.md, "Directions") */
    int no_shading;              /* 1: no terrain shading (r.sun without -s) */
    double sun_radius_rad;       /* 0: hard shadows (the sun's centre); > 0: the visible fraction
                                    of a disc of this angular radius (hfvis_sun_visibility's
                                    formula) scales the beam and the circumsolar diffuse */
    int refraction;              /* SPA: 1 = apparent sun direction for shading and incidence */
    double delta_t;              /* SPA: TT - UT1 in s; 0 = 69 */
    const float *linke_monthly;  /* 12 values (January first) replacing input->linke, or NULL */
    const float *linke_map;      /* per sample [y*width + x], replacing both, or NULL */
    const float *albedo_map;     /* per sample, replacing input->albedo, or NULL */
    const float *coeff_bh;       /* r.sun's real-sky beam coefficient per sample, or NULL (1) */
    const float *coeff_dh;       /* r.sun's real-sky diffuse coefficient per sample, or NULL (1) */
    hfvis_solar_diffuse diffuse;
    hfvis_solar_reflected reflected;
    int reflected_directions;    /* TERRAIN: K of the [P2] gather; 0 = 16 */
    hfvis_solar_bands bands;
    double site_tolerance_rad;   /* with input->latitude_map: the largest rotation between a
                                    sample's local frame (east, north, up turned by the
                                    convergence) and its block centre's, (0, 0.1]; 0 = 0.05 deg.
                                    Every sun direction of a sample is within it of its own */
    const hfvis_sweep_options *sweep; /* border, search radius, allocator, progress, window; its
                                    rays field is ignored (horizons below sets the ray mode).
                                    Its receiver rectangle: only those outputs are computed and
                                    written (the others untouched); its window (origin, extent:
                                    a finite radius, the open border): the grid is a window plus
                                    halo of a raster, and the rectangle's outputs equal the whole
                                    raster's run bit for bit when the sites come from input->site
                                    or one site and height_min/max are set alike in both runs.
                                    TERRAIN refuses a window or a rectangle, the maps a window.
                                    The oracle computes every receiver */
    const float *horizon_map;    /* NULL: the fast routine makes its horizon map itself (only
                                    the directions its steps read); else the caller's,
                                    directions*width*height floats exactly as hfvis_horizon_map
                                    writes them for these K directions with the sweep options
                                    hfvis_solar_map_options returns: e.g. made on several threads
                                    (the results are then bit for bit those of NULL); only the
                                    planes hfvis_solar_map_directions names are read. The oracle
                                    ignores it */
    hfvis_solar_horizons horizons; /* the fast routine's horizons; default EXACT */
    int row_begin, row_end;      /* 0, 0: every row; else the fast routine computes and writes
                                    only rows [row_begin, row_end) of the outputs (0 <= begin <
                                    end <= height; the other rows untouched), each bit for bit
                                    the whole call's: calls on disjoint ranges split a run over
                                    threads (give them one horizon_map). With a receiver
                                    rectangle, the rows of both. Not with TERRAIN. The
                                    oracle ignores it */
    hfvis_solar_normals normals; /* default CENTRAL; HORN to match r.sun fed by r.slope.aspect */
    double height_min, height_max; /* the heights the pressure nodes of the sector sums and the
                                    day path span, in place of each block's own finite heights
                                    (the air mass's p(z) is interpolated between them); both 0 =
                                    the block's (default). Else finite, height_min <= height_max:
                                    give the whole raster's range in every run that must agree
                                    with its windows (the nodes then do not depend on the grid
                                    handed in; the sector sums then take 5 nodes, not 3). The
                                    interpolation error grows with the span: within 6.4e-5 of
                                    the step loop over 6.8 km of relief (docs/solar.md
                                    "Windows") */
} hfvis_solar_options;

HFVIS_API hfvis_solar_options hfvis_solar_options_default(void);

/* The sweep options with which hfvis_solar_irradiation makes its horizon map (and HORIZON's
 * visible sky) for these options (NULL: the defaults): opts->sweep's border, radius, allocator,
 * progress, window and receiver rectangle, the ray mode and near-field cells of opts->horizons, azimuth0 0, every
 * direction. Pass them to hfvis_horizon_map to make opts->horizon_map yourself. */
HFVIS_API hfvis_sweep_options hfvis_solar_map_options(const hfvis_solar_options *opts);

/* The horizon-map directions hfvis_solar_irradiation(g, in, opts, ...) reads: need[k] = 1 for
 * each of the K = opts->directions (default 64) directions of its map that its steps read (the
 * two around each step's sun azimuth and the two around each sector bin's centre, over every
 * block of per-sample sites; every direction beyond 366 blocks x days, or with HORIZON diffuse
 * over HORN normals, which reads the whole map), else 0 (all 0 with no_shading unless HORIZON
 * over HORN). need holds K bytes. A caller's opts->horizon_map need hold only these planes (the
 * others are never read): e.g. made on several threads with hfvis_solar_map_options, one
 * direction_begin/end per needed direction. The fast routine makes exactly these itself.
 * HFVIS_ERR_INVALID_ARGUMENT as hfvis_solar_irradiation (and need NULL); out of memory. */
HFVIS_API hfvis_status hfvis_solar_map_directions(const hfvis_grid *g, const hfvis_solar_input *in,
                                                  const hfvis_solar_options *opts, unsigned char *need);

/* The outputs: each NULL or bands*width*height floats, band b at [b*width*height + y*width + x]:
 * beam, diffuse and reflected on the receiver's own surface (normal from the grid, hfvis.h
 * "Grids", or Horn's with opts->normals), their sum, and the hours of direct sun (beam > 0;
 * weighted by the visible disc fraction). NaN at holes. At least one must be set. */
typedef struct hfvis_solar_output {
    float *beam, *diffuse, *reflected, *global, *sun_hours;
} hfvis_solar_output;

/* The number of bands the outputs hold for this input and options (1, days, or the months
 * touched), or -1 for an invalid input. */
HFVIS_API int hfvis_solar_band_count(const hfvis_solar_input *input,
                                     const hfvis_solar_options *opts);

/* Irradiance (input->instant) or irradiation over a period on every grid point. Per time step:
 * the sun at the site (with input->latitude_map: at the centre of each block of samples whose
 * local frames lie within opts->site_tolerance_rad of the centre's, quadtree halving from the
 * whole raster (opts->sweep's extent; the grid without a window); the steps, sunrise and sunset are then each block's own, SPA's instant part taken
 * once per hour of the period and interpolated, within 2e-6 deg); the beam is shaded by the horizon toward the sun, read from one
 * horizon map of K directions made once (hfvis_horizon_map with hfvis_solar_map_options: exact
 * rays by default, opts->horizons; only the directions the steps read, bit-identical to the
 * whole map's planes) and interpolated linearly in azimuth between its two nearest directions;
 * then r.sun's ESRA
 * atmosphere per sample (its height for the air mass, its Linke factor, albedo and
 * coefficients). Steps (SPA): the day's civil hours cut at step_hours, each evaluated at its
 * middle; the step holding sunrise or sunset is evaluated at the middle of its sunlit part
 * (found by bisection of the true elevation) and weighted by that part's length. RSUN: r.sun's
 * steps. The sun counts while its true elevation is above 0.
 * Long periods (more than 16 sunlit steps per map direction and band) with one Linke factor per
 * step (a value or monthly values), no coefficient rasters and a hard sun take the sector sums
 * instead of the step loop: the steps binned by azimuth (4 bins per map direction), sorted by
 * elevation and summed from the top (every term is linear in per-sample constants once a step
 * is lit or not; the air mass's height enters by interpolation over 1-3 pressure nodes, 1, 2 or
 * 5 over opts->height_min..height_max when set), so a
 * sample costs O(bins * log steps) instead of O(steps); its lit test is taken at the bin's
 * centre (within 0.7 deg of the step's azimuth at K = 64).
 * Shorter periods with one Linke factor per step and no coefficient rasters (a hard sun or the
 * disc) take the day path: per step w B0c at 5 pressure nodes over the block's heights, per
 * sample the lit test as the step loop's and eight sums in a vectorized loop (within 3e-6 of
 * the step loop on the Colorado tile, 1.5e-5 over 6 km of relief; docs/solar.md "The day path").
 * Memory: K*4 bytes per sample for the map (K = 64: 256 bytes), K*4 more for its sample-major
 * copy with the sector sums or the step loop, 120 bytes per sample of state and 32 per sample
 * and band of sums, plus the outputs;
 * HORIZON adds 4 bytes per sample, TERRAIN the [P2] sweep's scratch; the sector sums about
 * 350 bytes per sunlit step (570 with height_min/max); per-sample sites 1 KB per day of the period (the hourly table)
 * and 56 bytes per block.
 * Cost: the map (hfvis.h "Exact rays") plus O(steps*width*height), or with the sector sums
 * O(steps log steps + bands*K*width*height*log steps), the steps' part once per block.
 * Accuracy against hfvis_solar_irradiation_reference: docs/solar.md and test/test_solar.c.
 * Returns HFVIS_ERR_INVALID_ARGUMENT (NULL, no output, bad input or option: a date that does
 * not exist, linke outside (0, 10], albedo outside [0, 1], a latitude outside [-pi/2, pi/2]),
 * HFVIS_ERR_OUT_OF_MEMORY or HFVIS_ERR_LIMIT (sizes). Polar night gives 0 (not an error). */
HFVIS_API hfvis_status hfvis_solar_irradiation(const hfvis_grid *grid,
                                               const hfvis_solar_input *input,
                                               const hfvis_solar_options *opts,
                                               const hfvis_solar_output *out);

/* Oracle: the same steps (with input->latitude_map: each sample's own steps at its own site, the
 * full SPA at every instant) and the same atmosphere per step and grid point, with the horizon
 * toward the sun's own azimuth from first principles at every step: each receiver's own exact
 * ray (hfvis_horizon_exact_naive, K = 1, ray_denominator 1024: within 0.002 deg of the sun's
 * azimuth); the visible sky of HORIZON integrated over 4K directions of the same rays ([P1]
 * Eq. 5 per sector); TERRAIN gathered by hfvis_indirect_light_naive; summed naively in double.
 * (The bilinear ray march hfvis_horizon_reference is not used: its samples within the first
 * cell measure the bilinear patch's own directional slope, which the solar model counts as the
 * receiver's incidence angle instead; docs/solar.md.) Cost O(steps*width*height*max(W, H)),
 * with the maps O(steps*width*height*(SPA + ray_denominator)). */
HFVIS_API hfvis_status hfvis_solar_irradiation_reference(const hfvis_grid *grid,
                                                         const hfvis_solar_input *input,
                                                         const hfvis_solar_options *opts,
                                                         const hfvis_solar_output *out);

/* ========================================================================================== */
/* hfvis.c - viewshed of one observer (Franklin & Ray 1994, R2)                               */
/* ========================================================================================== */

/* Options of hfvis_viewshed and its oracle. NULL or a zero struct: eye and targets on the
 * surface, unlimited range. */
typedef struct hfvis_viewshed_options {
    double observer_height;   /* eye height above the surface at the observer, world units, >= 0 */
    double target_height;     /* height above the surface of each target, world units, >= 0 */
    double max_distance;      /* horizontal range in world units, >= 0; 0 = unlimited */
    const hfvis_allocator *alloc; /* reserved: neither viewshed function allocates */
} hfvis_viewshed_options;

/* The defaults: all zero (eye and targets on the surface, unlimited range). */
HFVIS_API hfvis_viewshed_options hfvis_viewshed_options_default(void);

/* Viewshed of one observer: which grid points an eye at (observer_x, observer_y) sees.
 * The eye is at surface(observer) + observer_height, the target of grid point (x, y) at
 * z(x, y) + target_height, the terrain is the bilinear surface (CONVENTIONS; holes never
 * occlude) and grazing counts as visible, to within rounding (every occluder is lowered by
 * 32*DBL_EPSILON times the largest height involved, so an eye on a plane sees all of it).
 * out[y*out_stride + x] = 1 where the target is visible,
 * 0 where it is hidden, NaN at holes, beyond max_distance (horizontal distance from the observer,
 * world units), and everywhere if the surface under the observer is a hole. A grid point the
 * observer stands on exactly is visible. Visibility does not depend on cell_size (it scales all
 * slopes alike); cell_size only converts max_distance to cells.
 * Method: R2 of Franklin & Ray 1994 ("Higher isn't necessarily better: visibility algorithms
 * and experiments"), the standard fast approximation used by GIS viewshed tools. One ray goes to
 * every grid point on the border of the grid (of its intersection with the bounding square of
 * the max_distance circle when the range is limited); each ray is walked one cell at a time along
 * its major axis, sampling the surface where it crosses each grid column (row), and keeps the
 * running maximum of the terrain slopes (h - h_eye)/d; the target above a sample is visible iff
 * its slope is >= the maximum over the earlier samples of that ray. Each grid point takes the
 * decision of the sample nearest to it on its column (row) among the rays crossing within half
 * a cell (ties: the earlier ray, in the order of the top and bottom border rows, then the left
 * and right columns); a grid point that no sample decides (beside holes, whose samples decide
 * nothing) is decided by the exact line of sight of hfvis_viewshed_reference (step 0.5).
 * How it differs from exact LOS: R2 decides a grid point with a ray that passes up to half a cell
 * beside it, tests the target above that crossing point (interpolated height) rather than above
 * the grid point, and sees the terrain only at one crossing per cell. The decisions agree with
 * hfvis_viewshed_reference except at grid points whose sight line nearly grazes the terrain, i.e.
 * along the boundaries of the visible regions (R2 mostly errs towards visible: a ridge between
 * two crossings is missed), so the fraction grows with how much the observer sees. Measured
 * against the oracle at step 0.5 (`hfvis viewshed --exact`), 8 observers per terrain (the
 * summit, a valley floor, a point on the slope between them, 5 random cells), eye 0 and 1.7
 * above the surface: a 512^2 SRTM tile around Longs Peak, Colorado (90 m cells): 0.005-1.21%
 * of the grid points, mean 0.21%; a 512^2 fBm: 0.03-1.21%, mean 0.35-0.44%; three 256^2 fBm
 * (relatively more boundary): 0.13-3.13%, mean 0.81-1.33% (eye 1.7). The summit is the worst
 * case on every terrain (it sees the most: 11-41% of the grid). On rough 128^2 fBm 0.4-1.9% (97-100% of the disagreements next to a
 * visibility boundary); none on a wall seen along the rays' major axis.
 * out must hold (height-1)*out_stride + width floats, out_stride >= width, and must not overlap
 * grid->z. opts may be NULL (defaults). out is used as scratch during the call.
 * Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT if grid is NULL or invalid, out is NULL,
 * out_stride < width, the observer is non-finite or outside [0, width-1] x [0, height-1], or an
 * option is negative or non-finite (outputs untouched). No allocation.
 * Cost: O((W+H) * max(W, H)) = O(W*H) for a square grid (about 2(W+H) rays of at most max(W, H)
 * samples), plus O(max(W, H)) per grid point left to the exact fallback (beside holes).
 * Determinism: bit-exact on one build; see CONVENTIONS. */
HFVIS_API hfvis_status hfvis_viewshed(const hfvis_grid *grid, double observer_x, double observer_y,
                                      const hfvis_viewshed_options *opts, float *out,
                                      ptrdiff_t out_stride);

/* Oracle: the exact line of sight from the eye to every target. For the grid point (x, y) at
 * horizontal distance D (cells) from the observer, the bilinear surface is sampled along the
 * straight horizontal path to it at distances d = k*step_cells, k = 1, 2, ..., d < D, and the
 * target is hidden iff some sample's slope (h - h_eye)/d exceeds the target's slope
 * (z(x, y) + target_height - h_eye)/D (holes skipped). Same output, options, NaN rules and
 * errors as hfvis_viewshed, plus HFVIS_ERR_INVALID_ARGUMENT for a negative or non-finite
 * step_cells. step_cells = 0 means 0.5. The march is exact up to features narrower than the step
 * (a ridge crossed between two samples is seen at the lower of them).
 * Cost O(W*H*N/step_cells), N = max(W, H). No allocation. */
HFVIS_API hfvis_status hfvis_viewshed_reference(const hfvis_grid *grid, double observer_x,
                                                double observer_y,
                                                const hfvis_viewshed_options *opts,
                                                double step_cells, float *out,
                                                ptrdiff_t out_stride);

/* ========================================================================================== */
/* hfvis.c - Nowrouzezahrai-Snyder GI, math layer ([NS09] §3-7, App. A) */
/* ========================================================================================== */
/* [NS09] D. Nowrouzezahrai, J. Snyder, "Fast Global Illumination on Dynamic Height Fields",
 * CGF 28(4), 2009. Errata: docs/errata.md E47-E53.
 *
 * Spherical harmonics (SH). Order 4: 16 real, orthonormal coefficients, index l(l+1)+m
 *   (l = 0..3, m = -l..l), NO Condon-Shortley phase: Y_1,-1 = +0.4886 y, Y_1,0 = +0.4886 z,
 *   Y_1,1 = +0.4886 x. Directions are in the grid's world frame (x east = increasing column,
 *   y = increasing row, z up); the azimuth phi is measured like psi (from +x toward +y) and theta
 *   from +z. Separable form: Y_lm = K_l^|m| Pt_l^|m|(cos theta) Phi_m(phi) with
 *   Pt_l^mu = (1-z^2)^(mu/2) d^mu P_l/dz^mu, Phi_m = sqrt2 cos(m phi) (m > 0), 1 (m = 0),
 *   sqrt2 sin(|m| phi) (m < 0). Tables printed with the phase (A, M_lin, M_bspl, Cartesian constants) use the
 *   Condon-Shortley phase: their entries with odd |m| have the opposite sign here.
 * Zonal lobes are stored as convolution multipliers Ahat_l = sqrt(4 pi/(2l+1)) z_l (z_l the raw
 *   ZH coefficients Int g Y_l0), for every lobe (docs/errata.md E52 on the Phong vector).
 * Normalized Legendre polynomials (NLP): P^_l(z) = sqrt((2l+1)/2) P_l(z), orthonormal on
 *   [-1, 1], l = 0..3, with the corrected constants of [NS09] §4, Eq. 9-13; docs/errata.md E48, E49 (sqrt10/4 and sqrt14/4, not the
 *   5 sqrt2/4 and 7 sqrt2/4 printed in [NS09] §4). Along a slice the variable is
 *   z = cos theta = sin omega, omega the elevation (blocking angle) above the horizontal plane.
 * Precision. Everything here is double: these are the building blocks of the GI pipeline and of
 *   the checks a port makes against it. All functions are pure (no allocation, no state) and
 *   return HFVIS_ERR_INVALID_ARGUMENT, with the outputs untouched, for a NULL pointer or a
 *   non-finite or out-of-range parameter. */

#define HFVIS_SH_COEFFS 16   /* order-4 SH vector length */
#define HFVIS_NLP_COEFFS 4   /* order-4 NLP vector length */

/* Evaluate the 16 SH basis functions at a direction.
 * dir need not be unit length (it is normalised); Y receives Y_i(dir), i = l(l+1)+m.
 * Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for NULL, a non-finite or zero dir.
 * Cost: about 40 flops. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_sh_eval(const double dir[3], double Y[16]);

/* Rotate an SH vector about +z by angle_rad (active, counter-clockwise seen from +z, i.e. from
 * +x toward +y): the result f' satisfies f'(R_z(a) d) = f(d), i.e. f'(theta, phi) =
 * f(theta, phi - a). Each pair (l, +m), (l, -m) turns by m*a ([NS09] §6, App. A; docs/errata.md E51):
 *   c'_(+m) = c_(+m) cos(ma) - c_(-m) sin(ma),  c'_(-m) = c_(+m) sin(ma) + c_(-m) cos(ma);
 * m = 0 coefficients are unchanged. [NS09] Eq. 21 uses it to place each wedge.
 * out may equal in. Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for NULL or a non-finite
 * angle. Cost: 6 trigonometric calls and 24 multiply-adds. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_sh_rotate_z(const double in[16], double angle_rad, double out[16]);

/* *out = Sum_i a_i b_i, the integral over the sphere of the product of the two functions
 * ([NS09] §7 "double product integral"). Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for NULL. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_sh_dot(const double a[16], const double b[16], double *out);

/* Fill the SH triple-product tensor gamma[(i*16 + j)*16 + k] = Int Y_i Y_j Y_k dw ([NS09] §7),
 * HFVIS_SH_COEFFS^3 = 4096 doubles. Computed exactly (up to rounding) with an 8-point
 * Gauss-Legendre rule in z and a 16-point uniform rule in phi; entries below 1e-12 in magnitude
 * are set to exactly 0 (the true non-zeros are >= 0.058), which leaves 353 non-zeros.
 * Build it once and pass it to hfvis_sh_product. Returns HFVIS_OK, or
 * HFVIS_ERR_INVALID_ARGUMENT if gamma is NULL. Cost: about 0.5 M multiply-adds, no allocation. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_sh_product_tensor(double *gamma);

/* SH product truncated to order 4: out_k = Sum_ij gamma_ijk a_i b_j, the projection of the
 * pointwise product of the two functions ([NS09] §7: incident radiance = L * V). gamma comes
 * from hfvis_sh_product_tensor. out may equal a or b. Returns HFVIS_OK, or
 * HFVIS_ERR_INVALID_ARGUMENT for NULL. Cost: at most 4096 multiply-adds (zeros skipped). */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_sh_product(const double *gamma, const double a[16],
                                                           const double b[16], double out[16]);

/* Convolve an SH vector with a zonal lobe given by its multipliers Ahat (Funk-Hecke):
 * out_lm = Ahat_l in_lm. With the diffuse Ahat, evaluating out at N gives the irradiance
 * E(N) = Int L(w) max(N.w, 0) dw. out may equal in. Returns HFVIS_OK, or
 * HFVIS_ERR_INVALID_ARGUMENT for NULL or a non-finite Ahat. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_sh_convolve_zh(const double in[16], const double Ahat[4],
                                                               double out[16]);

/* Rotate a zonal lobe to an axis: out_lm = Ahat_l Y_lm(axis) = sqrt(4 pi/(2l+1)) z_l Y_lm(axis)
 * ([NS09] §7 F(w_o)). axis need not be unit length. Then Sum out_i I_i is the lobe
 * applied to the incident radiance I. Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for NULL, a
 * non-finite Ahat or a non-finite or zero axis. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_sh_from_zh(const double Ahat[4], const double axis[3],
                                                           double out[16]);

/* Shade: *out = Sum_lm Ahat_l Y_lm(axis) I_lm ([NS09] §7: F(w_o) . I). With the diffuse Ahat and
 * axis = N this is the irradiance E(N); the library's exit radiance is (albedo/pi) E (docs/errata.md
 * E52: [NS09] omits albedo/pi). With the Phong Ahat and axis = reflect(view, N) it is
 * the reflected radiance of a lobe with unit specular albedo. Errors as hfvis_sh_from_zh. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_sh_shade_zh(const double Ahat[4], const double axis[3],
                                                            const double I[16], double *out);

/* The clamped-cosine (diffuse) lobe: Ahat = (pi, 2pi/3, pi/4, 0), from the raw ZH
 * (sqrt(pi)/2, sqrt(pi/3), sqrt(5 pi)/8, 0) = (0.886227, 1.02333, 0.495416, 0) of [NS09] §7.
 * Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT if Ahat is NULL. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_zh_diffuse(double Ahat[4]);

/* The Phong lobe of exponent S ([NS09] §7 citing Ramamoorthi-Hanrahan 2002):
 * Ahat_l = exp(-l^2/(2S)). These are the multipliers of the normalised lobe
 * ((S+1)/(2 pi)) cos^S about the reflection vector (docs/errata.md E52; Ahat_0 = 1, so a uniform
 * unit environment reflects 1), in the Gaussian approximation of [RH02], accurate for large S.
 * S > 0 and finite. Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for NULL or a bad S. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_zh_phong(double S, double Ahat[4]);

/* The indicator of a circular cap of angular radius half_angle_rad in [0, pi] about +z
 * ([NS09] §6 key lights): Ahat_l = 2 pi Int_c^1 P_l(z) dz, c = cos(half_angle); Ahat_0 is the
 * cap's solid angle 2 pi (1 - c). A uniform cap of radiance L0 about axis a is L0 times
 * hfvis_sh_from_zh(Ahat, a). Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for NULL or a
 * half-angle outside [0, pi] or non-finite. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_zh_cap(double half_angle_rad, double Ahat[4]);

/* Project a lat-long environment (hfvis_env: row t = theta in [pi t/T, pi (t+1)/T) from the
 * zenith, column p = phi in [2 pi p/P, 2 pi (p+1)/P)) onto the SH basis:
 * out[c*16 + i] = Sum_texels L_c Int_texel Y_i dw, channel c in 0..channels-1 (16*channels
 * doubles). Radiance is constant within a texel (the hfvis_env convention), and each texel's
 * integral is exact: Int Phi_m dphi in closed form, and Int Pt_l^mu(cos t) sin t dt as a
 * polynomial antiderivative in z = cos t (even mu) or through Int cos^k t sin^2 t dt (odd mu) -
 * no quadrature, so a constant map L gives out_0 = 2 sqrt(pi) L and 0 elsewhere up to rounding
 * ([NS09] §6 suggests sin(theta) dtheta dphi texel weights instead; those are only
 * approximate). Non-finite radiance propagates into the output.
 * Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for NULL (env, env->radiance, out), n_theta or
 * n_phi < 1, channels outside 1..4, or a texel count that overflows size_t.
 * Cost: O(n_theta*n_phi*channels*7) multiply-adds, 6 trigonometric calls per column and 4 per
 * row and block of 64 columns. No allocation. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_sh_project_env(const hfvis_env *env, double *out);

/* Evaluate the 4 NLPs at z in [-1, 1]: P = (1/sqrt2, sqrt(3/2) z, (sqrt10/4)(3z^2 - 1),
 * (sqrt14/4)(5z^3 - 3z)) ([NS09] §4 with the docs/errata.md E48, E49). Returns HFVIS_OK, or
 * HFVIS_ERR_INVALID_ARGUMENT for NULL or z non-finite or outside [-1, 1]. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_nlp_eval(double z, double P[4]);

/* Occlusion vector vbar(sigma) = Int_{-1}^{sin sigma} P^(z) dz ([NS09] Eq. 10, limits as in
 * docs/errata.md E49): the NLP projection of the step that is 1 for elevations omega <= sigma. Closed form
 * with s = sin sigma: ((s+1)/sqrt2, sqrt(3/2)(s^2-1)/2, sqrt(5/2)(s^3-s)/2,
 * sqrt(7/2)(5s^4-6s^2+1)/8). sigma_rad is clamped to [-pi/2, pi/2] (vbar(-pi/2) = 0,
 * vbar(pi/2) = (sqrt2, 0, 0, 0)). Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for NULL or a
 * non-finite sigma. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_nlp_occlusion(double sigma_rad, double out[4]);

/* Visibility vector of the elevation interval (omega_lo, omega_hi], both clamped to
 * [-pi/2, pi/2]: vbar(hi) - vbar(lo) if hi > lo, else 0.
 *   [NS09] Eq. 11 (environment): lo = omega_max, hi = pi/2.
 *   [NS09] §6 (key light with elevation range [l_min, l_max]): lo = max(omega_max, l_min),
 *   hi = l_max. Clamping below the tangent plane is the caller's choice: lo = max(omega_max,
 *   omega_min) (docs/errata.md E53).
 * Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for NULL or a non-finite angle. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_nlp_visibility(double omega_lo_rad, double omega_hi_rad,
                                                               double out[4]);

/* NLP vector of the indirect radiance along one slice ([NS09] Eq. 8 and 12 with the limits of
 * §4, Eq. 9-13, docs/errata.md E48, E49: the integral covers z in [-1, 1], u(t_(i+1)) = 0 once
 * i+1 >= |T|):
 *   u(omega) = u[k] for omega_rad[k-1] <= omega < omega_rad[k] (omega_rad[-1] := omega_min_rad),
 *   0 below omega_min and above omega_rad[K-1];
 *   out = Sum_k (u[k] - u[k+1]) vbar(omega_rad[k]) - u[0] vbar(omega_min), u[K] := 0.
 * K is the casting-set size (>= 0; K = 0 gives 0 and the arrays may be NULL); omega_rad holds its
 * blocking angles in increasing t, which must be non-decreasing and >= omega_min_rad; u holds one
 * channel of exit radiance per element (call once per channel). Angles are clamped to
 * [-pi/2, pi/2] as in hfvis_nlp_occlusion. Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for NULL,
 * K < 0, a non-finite value or a decreasing angle sequence. Cost: O(K). */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_nlp_radiance(int K, const double *omega_rad, const double *u,
                                                             double omega_min_rad, double out[4]);

/* Reconstruct an elevation function from its NLP vector: *out = c . P^(sin omega)
 * ([NS09] Eq. 13). The order-4 truncation rings ([NS09] §4, Eq. 9-13; docs/errata.md E48, E49: values < 0 or > 1 occur).
 * Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for NULL or a non-finite omega. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_nlp_reconstruct(const double c[4], double omega_rad, double *out);

/* Azimuthal interpolation of the NLP vectors across a wedge ([NS09] §6, App. A). */
typedef enum hfvis_ns_interp {
    HFVIS_NS_INTERP_DEFAULT = 0,  /* = LINEAR */
    HFVIS_NS_INTERP_LINEAR = 1,   /* (1-a) w_j + a w_(j+1): M_lin is 16x8 ([NS09] Eq. 20, 24) */
    HFVIS_NS_INTERP_BSPLINE = 2   /* uniform cubic B-spline on w_(j-1)..w_(j+2): M_bspl is 16x16
                                     (docs/errata.md E51: not the 16x32 of [NS09] §1) */
} hfvis_ns_interp;

/* Largest wedge matrix, in doubles (16x16). */
#define HFVIS_NS_WEDGE_MATRIX_MAX 256

/* Columns of the wedge matrix: 8 (linear, default) or 16 (B-spline); 0 for an unknown value. */
HFVIS_API HFVIS_EXPERIMENTAL int hfvis_ns_wedge_columns(hfvis_ns_interp interp);

/* The Appendix-A wedge matrix for a wedge of width dphi_rad in (0, 2 pi], row-major,
 * M[r*cols + s*4 + k], r = SH index, s = sample of the wedge (0..1 linear: w_j, w_(j+1);
 * 0..3 B-spline: w_(j-1), w_j, w_(j+1), w_(j+2)), k = NLP index. The wedge is canonical,
 * phi in [0, dphi], alpha = phi/dphi (docs/errata.md E51 on Eq. 18), so
 *   M[(l,m); (s,k)] = Int_0^dphi Int_0^pi beta_s(alpha) P^_k(cos t) Y_lm(t, phi) sin t dt dphi.
 * Derivation ([NS09] §6, App. A; docs/errata.md E51 separable form, computed at run time, no table):
 * M = K_l^|m| A_(l,|m|,k) B_(m,s)(dphi) with A = Int_{-1}^{1} Pt_l^|m| P^_k dz from exact
 * polynomial / Int cos^k sin^2 antiderivatives, and B = Int_0^dphi beta_s(phi/dphi) Phi_m(phi)
 * dphi from the moments Int_0^1 a^p cos(c a) da, Int_0^1 a^p sin(c a) da (power series for
 * c <= 2, integration by parts above). Each m = 0 row (l, 0) of M_lin is dphi/(2 sqrt(2 pi)) at
 * the columns (s, k = l) and 0 elsewhere.
 * M must hold 16*hfvis_ns_wedge_columns(interp) doubles. Returns HFVIS_OK, or
 * HFVIS_ERR_INVALID_ARGUMENT for NULL, an unknown interp, or dphi non-finite or outside (0, 2 pi].
 * Cost: about 2000 flops and 12 trigonometric calls. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_ns_wedge_matrix(hfvis_ns_interp interp, double dphi_rad, double *M);

/* A set of m azimuthal samples phi_j = phi0_rad + j*dphi_rad and its wedge matrix. Fill it with
 * hfvis_ns_wedges_full or hfvis_ns_wedges_partial; it holds no pointers and may be copied. */
typedef struct hfvis_ns_wedges {
    hfvis_ns_interp interp;    /* LINEAR or BSPLINE (DEFAULT is resolved to LINEAR) */
    int samples;               /* m */
    int full_circle;           /* 1: m wedges, the last one from phi_(m-1) back to phi_0 */
    double phi0_rad;           /* azimuth of sample 0 */
    double dphi_rad;           /* wedge width */
    double matrix[HFVIS_NS_WEDGE_MATRIX_MAX];  /* hfvis_ns_wedge_matrix(interp, dphi_rad) */
} hfvis_ns_wedges;

/* Full circle (environment visibility, indirect radiance): m >= 1 samples, dphi = 2 pi/m,
 * m wedges including the wrap-around wedge (docs/errata.md E51: [NS09] Eq. 21's sum to m-1 is
 * the partial case). B-spline indices wrap modulo m. Returns HFVIS_OK, or
 * HFVIS_ERR_INVALID_ARGUMENT for NULL, m < 1, an unknown interp or a non-finite phi0. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_ns_wedges_full(hfvis_ns_wedges *set, hfvis_ns_interp interp, int m,
                                                               double phi0_rad);

/* Partial extent [phi_a, phi_b] (key lights, [NS09] §6): m >= 2 samples, dphi =
 * (phi_b - phi_a)/(m-1), m-1 wedges; B-spline indices are clamped to the end samples ([NS09] App. A;
 * the library's choice). phi_b > phi_a and phi_b - phi_a <= 2 pi (an extent crossing 0 is given as, e.g.,
 * [-0.3, 0.2]). Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for NULL, m < 2, an unknown interp
 * or a bad extent. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_ns_wedges_partial(hfvis_ns_wedges *set, hfvis_ns_interp interp,
                                                                  int m, double phi_a_rad, double phi_b_rad);

/* From slices to SH ([NS09] §6, Eq. 20-21, App. A; docs/errata.md E51 SLICES_TO_SH): w[j*4 + k] is the NLP vector
 * of sample j (j = 0..m-1, from hfvis_nlp_visibility or hfvis_nlp_radiance at azimuth phi_j);
 * out = Sum_wedges Rot_z(M x_j, phi_j). One channel per call. Returns HFVIS_OK, or
 * HFVIS_ERR_INVALID_ARGUMENT for NULL or a set whose interp or sample count is invalid.
 * Cost: per wedge 128 (linear) or 256 (B-spline) multiply-adds plus one hfvis_sh_rotate_z. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_ns_wedges_to_sh(const hfvis_ns_wedges *set, const double *w,
                                                                double out[16]);

/* Which formula gives the tangent plane's minimum blocking angle. */
typedef enum hfvis_ns_omega_min {
    HFVIS_NS_OMEGA_MIN_DEFAULT = 0,  /* = EXACT */
    HFVIS_NS_OMEGA_MIN_EXACT = 1,    /* atan2(-(N_x cos phi + N_y sin phi), N_z) ([NS09] §3) */
    HFVIS_NS_OMEGA_MIN_PAPER = 2     /* -asin(N_x cos phi + N_y sin phi) ([NS09] §3), exact only
                                        when N lies in the slice's vertical plane */
} hfvis_ns_omega_min;

/* The elevation of the receiver's tangent plane in azimuth phi_rad, in [-pi/2, pi/2] for an
 * upward normal: the minimum blocking angle omega_min of [NS09] §3 (it seeds the casting set).
 * Example: N = (1,1,1)/sqrt3, phi = 0 gives -45 deg (exact) and -35.26 deg (paper); with the
 * paper's form a tilted plane admits its own surface into the casting set.
 * normal need not be unit length. Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for NULL, a
 * zero or non-finite normal, a non-finite phi or an unknown form. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_ns_min_blocking_angle(const double normal[3], double phi_rad,
                                                                      hfvis_ns_omega_min form, double *out);

/* ========================================================================================== */
/* hfvis.c - Nowrouzezahrai-Snyder GI pipeline ([NS09] §3-9)           */
/* ========================================================================================== */
/* The approximate, fast counterpart of the exact P1/P2 pipeline (hfvis_direct_light,
 * hfvis_terrain_gi): per receiver, m azimuthal slices are scanned with exponentially growing
 * steps over a multi-resolution height pyramid ([NS09] §5.2, Eq. 14-17); each slice's visibility
 * and indirect radiance become order-4 normalized Legendre (NLP) vectors (Eq. 10-12), which the
 * Appendix-A wedge matrices turn into order-4 SH (Eq. 18-21); shading is an SH dot product with a
 * diffuse or Phong zonal lobe (§7); each bounce gathers the previous bounce's exit radiance from a
 * radiance pyramid (§5.3). Conventions are those of the math layer above (SH without the
 * Condon-Shortley phase, Ahat multipliers, NLP in z = sin(omega)) and of the whole API
 * (hfvis.h, Conventions: an open flat receiver under a uniform sky c with albedo 1 returns c).
 *
 * Slices ([NS09] §3, §5.2, Eq. 14-17). A receiver at grid position (x, y) looking toward
 * phi_j = azimuth0_rad + 2 pi j/m (phi measured like psi, from +x toward +y) takes steps
 * tau_i = 2^(i/k) cells, i = 0..n-1 (Eq. 14 in cell units); step i reads level
 * l_v(i) = max(0, i - k*o_v) of the height pyramid at the receiver and at the step point (Eq. 15:
 * both heights from the same level; the level offset makes the level finer by o_v octaves, the
 * docs/errata.md E50) and gives the blocking angle omega_i = atan(dz / (tau_i cell_size)).
 * omega_max is the maximum of the uniform cubic B-spline through the omega_i at its knots and
 * midpoints (Eq. 16, end points replicated) or the raw maximum; the casting set holds the steps
 * whose omega_i exceeds every earlier one and the tangent-plane angle omega_min (Eq. 17; admitted
 * when larger by more than 1e-12 rad). Steps outside the grid (HFVIS_BORDER_OPEN: the ray ends
 * there) and steps whose height is a hole are skipped: they neither occlude nor cast.
 *
 * The pyramid ([NS09] §5.2, Eq. 14-17, CPU proposal). Octave images G_0 = the heights, G_(o+1) = G_o
 * filtered with the separable [1,3,3,1]/8 kernel and decimated by 2 (texel i of G_(o+1) is centred
 * between texels 2i and 2i+1 of G_o); level l = k*o + j (0 <= j < k) is G_o convolved with a
 * separable, sampled, normalised cubic B-spline kernel whose variance is (4^(j/k) - 1)/4 G_o
 * texels^2, so the blur grows smoothly and reaches 3/4 (the decimation's) as j -> k; level 0 is the
 * heights exactly. Levels are sampled bilinearly in octave coordinates. Filter taps outside the
 * image follow the border (OPEN: dropped, CLAMP: edge texel, WRAP: periodic) and hole taps are
 * dropped, the weights renormalised (a level texel with no finite tap is a hole). The same pyramid
 * holds the exit radiance of a bounce ([NS09] §5.3) with levels l_u(i) = max(0, i - k*o_u).
 * Memory: about (4/3) k W H floats per channel, not the paper's stack of n full-size textures.
 *
 * Outputs are radiance toward the viewer (view_dir): direct = emission + (albedo/pi) E_direct +
 * specular * glossy_direct; bounce b = (albedo/pi) E_b + specular * glossy_b, E_b the irradiance
 * from the SH incident radiance U_b gathered from the exit radiance of bounce b-1; total = direct +
 * the bounces. For a diffuse surface this is, bounce by bounce, the recursion
 * L_B = emission + albedo (D + I[L_(B-1)]) of hfvis_terrain_gi. How close it comes to the exact
 * pipeline is measured in test_ns_gi.c against hfvis_sky_light and hfvis_indirect_light (P1/P2)
 * and printed by the bench. */

/* How omega_max is taken from a slice's blocking angles. */
typedef enum hfvis_ns_omega_max {
    HFVIS_NS_OMEGA_MAX_DEFAULT = 0,  /* = BSPLINE */
    HFVIS_NS_OMEGA_MAX_BSPLINE = 1,  /* [NS09] Eq. 16 (smooths: lowers isolated spikes) */
    HFVIS_NS_OMEGA_MAX_RAW = 2       /* max_i omega_i (docs/errata.md E53; with it the closure
                                        identity of B.13-9 is exact) */
} hfvis_ns_omega_max;

/* Directional lights (hfvis_sun with radius_rad == 0), [NS09] §6. */
typedef enum hfvis_ns_directional {
    HFVIS_NS_DIRECTIONAL_DEFAULT = 0,  /* = HARD */
    HFVIS_NS_DIRECTIONAL_HARD = 1,     /* E0 max(N.d, 0) [omega_L > omega_max(phi_L)], from one more
                                          slice scan toward the light */
    HFVIS_NS_DIRECTIONAL_SOFT = 2,     /* the indicator replaced by clamp(v(phi_L) . P^(sin omega_L),
                                          0, 1): the NLP-smoothed step of the slice toward the light.
                                          The order-4 NLP rings near the zenith: an open flat
                                          receiver gets 13/16 = 0.8125 of a zenith light */
    HFVIS_NS_DIRECTIONAL_SH = 3        /* the SH delta E0 Y(d) times the HARD indicator, shaded
                                          through SH like the environment; rings:
                                          E = E0 (1/4 + cos(g)/2 + (5/16) P_2(cos g)), 17/16 E0 at
                                          g = 0 */
} hfvis_ns_directional;

/* Key lights (hfvis_sun with radius_rad > 0): uniform circular caps ([NS09] §6-7). */
typedef enum hfvis_ns_key_mode {
    HFVIS_NS_KEY_DEFAULT = 0,      /* = SEPARATE */
    HFVIS_NS_KEY_SEPARATE = 1,     /* own visibility V_key over the cap's azimuth extent
                                      (key_directions samples, key_directions - 1 wedges; the full
                                      circle with the environment's slices when the cap holds the
                                      zenith) and elevation range [l_min, l_max] (§6); the incident
                                      radiance gains the SH product L_key * V_key ([NS09] §6). Note:
                                      order-4 SH cannot hold the narrow box V_key, and the product
                                      loses most of a small light's energy even where nothing
                                      occludes it (a cap of radius 0.3 rad at 40 deg elevation
                                      delivers 29% of its irradiance to open flat ground) */
    HFVIS_NS_KEY_ENVIRONMENT = 2,  /* folded into the environment: L_key * V (faster, softer) */
    HFVIS_NS_KEY_RATIO = 3         /* [choice, not in [NS09]] V_key as in SEPARATE, used only as a
                                      shadow factor: f = clamp(Int L V_key / Int L V_box, 0, 1),
                                      V_box the unoccluded restricted visibility (dot products of
                                      the SH vectors), and the incident radiance gains f L_key: open
                                      ground gets the light's full SH irradiance */
} hfvis_ns_key_mode;

/* Glossy interreflection ([NS09] §5.3). */
typedef enum hfvis_ns_glossy {
    HFVIS_NS_GLOSSY_DEFAULT = 0,   /* = VECTOR */
    HFVIS_NS_GLOSSY_VECTOR = 1,    /* two pyramids: the diffuse exit radiance, and the incident
                                      SH I_(b-1) (16 per channel, at the receiver resolution); a
                                      remote point q sends specular * max(F_q(s) . I_(b-1)(q), 0)
                                      toward the receiver on top of its diffuse exit radiance,
                                      F_q the Phong lobe about the reflection of s = normalize(p - q)
                                      in q's full-resolution normal ([NS09] §5.3 "non-diffuse") */
    HFVIS_NS_GLOSSY_SCALAR = 2     /* one scalar pyramid of the shade toward the viewer (diffuse +
                                      glossy): [NS09] §5.3's "mixture" approximation */
} hfvis_ns_glossy;

/* Keeping the casting sets between passes ([NS09] §9 "cache cast sets for bounces"). */
typedef enum hfvis_ns_cache {
    HFVIS_NS_CACHE_DEFAULT = 0,    /* = ON */
    HFVIS_NS_CACHE_ON = 1,         /* the first scan of each slice (the visibility scan of the direct
                                      pass, or the first bounce) records its casting set as a bit
                                      mask of steps; later bounces re-read only those steps: same
                                      result, bit for bit, at ceil(n/64)*8 bytes per receiver and
                                      slice (1024^2, m = 32, n <= 64: 256 MiB; 2x2: 64 MiB) */
    HFVIS_NS_CACHE_OFF = 2         /* every bounce scans every slice again */
} hfvis_ns_cache;

/* level_offset_v / level_offset_u value for "no offset" (0 octaves; 0 itself means the default). */
#define HFVIS_NS_NO_OFFSET (-1)

/* Limits of the options (larger values are HFVIS_ERR_INVALID_ARGUMENT). */
#define HFVIS_NS_MAX_DIRECTIONS 4096
#define HFVIS_NS_MAX_KEY_DIRECTIONS 256
#define HFVIS_NS_MAX_LEVELS_PER_OCTAVE 32
#define HFVIS_NS_MAX_LEVELS 1024
#define HFVIS_NS_MAX_LEVEL_OFFSET 64
#define HFVIS_NS_MAX_SUBSAMPLE 64
#define HFVIS_NS_MAX_LIGHTS 64

/* Options of hfvis_ns_gi. NULL or a zeroed struct means every default. */
typedef struct hfvis_ns_gi_options {
    int directions;          /* m: azimuthal slices over the full circle (environment and
                                indirect light), 1..4096; 0 = 32 ([NS09] §9) */
    int key_directions;      /* azimuthal samples over a key light's partial extent, 2..256;
                                0 = 3 ([NS09] §9) */
    int levels_per_octave;   /* k = k_v = k_u (Eq. 14), 1..32; 0 = 4 */
    int levels;              /* n = n_v = n_u: steps per slice, 1..1024; 0 = auto:
                                1 + ceil(k log2(max(1, hypot(width-1, height-1)))), so the last
                                step reaches the grid's diagonal (1 + k log2 R levels, [NS09] §5.2, plus
                                at most k/2 + 1 steps) */
    int level_offset_v;      /* o_v, octaves, 1..64; 0 = 2 ([NS09] §5.2); HFVIS_NS_NO_OFFSET = 0 */
    int level_offset_u;      /* o_u, likewise, for the radiance pyramid; 0 = 2 */
    int sh_order;            /* SH order o, 1..4 (bands l < o kept in V, U, the lights and the
                                lobes); 0 = 4. The NLP vectors stay order 4. */
    int subsample;           /* s: V, U computed for one receiver per s x s block (at the block
                                centre, clamped to the grid) and bilinearly upsampled; shading
                                uses full-resolution normals ([NS09] §7), 1..64; 0 = 1 */
    hfvis_ns_interp interp;           /* azimuthal interpolation; default LINEAR */
    hfvis_ns_omega_min omega_min;     /* tangent-plane angle; default EXACT (atan2 form) */
    hfvis_ns_omega_max omega_max;     /* default BSPLINE (Eq. 16) */
    int clamp_to_tangent;    /* 1: slice visibility starts at max(omega_max, omega_min) (docs/errata.md
                                E53); 0 = off, as [NS09] (the lobe's clamped cosine
                                removes the light from below the tangent plane, approximately) */
    hfvis_ns_directional directional; /* default HARD */
    hfvis_ns_key_mode key_mode;       /* default SEPARATE */
    hfvis_ns_glossy glossy;           /* default VECTOR */
    hfvis_ns_cache cast_cache;        /* default ON (only used with bounces) */
    double view_dir[3];      /* unit vector from the surface toward the viewer (distant
                                viewer; normalised here); 0,0,0 = (0, 0, 1), looking straight down.
                                Only the glossy terms depend on it. */
    hfvis_border border;     /* default OPEN */
    double azimuth0_rad;     /* phi_0 of slice 0 */
    const hfvis_allocator *alloc;    /* scratch; NULL = malloc/free */
    hfvis_progress_fn progress;      /* optional: called after each receiver row of each pass,
                                        total = receiver rows * (1 + bounces) */
    void *progress_user;
} hfvis_ns_gi_options;

/* The defaults, filled in (levels stays 0 = auto: it depends on the grid). */
HFVIS_API hfvis_ns_gi_options hfvis_ns_gi_options_default(void);

/* The options hfvis_ns_gi uses for this grid: every default resolved (levels computed, enums
 * made explicit, view_dir normalised; level offsets of "none" stay HFVIS_NS_NO_OFFSET), so a
 * port can print the exact parameters. in may be NULL. Returns HFVIS_OK, or
 * HFVIS_ERR_INVALID_ARGUMENT for an invalid grid, a NULL out or an invalid option. */
HFVIS_API hfvis_status hfvis_ns_gi_options_resolve(const hfvis_grid *grid,
                                                   const hfvis_ns_gi_options *in,
                                                   hfvis_ns_gi_options *out);

/* What is lit, and how it reflects. */
typedef struct hfvis_ns_scene {
    int channels;                /* C, 1..4 */
    const double *env_sh;        /* environment radiance as SH, env_sh[c*16 + i] (e.g. from
                                    hfvis_sh_project_env; a uniform sky c is 2 sqrt(pi) c at
                                    i = 0), or NULL for none */
    const hfvis_sun *lights;     /* light_count lights (azimuth = look direction toward the light,
                                    elevation in [-pi/2, pi/2], irradiance[c] on a surface facing
                                    it): radius_rad == 0 is a directional light, 0 < radius_rad
                                    <= pi/2 a key light (a uniform cap of radiance
                                    irradiance / (pi sin^2 radius)). NULL if light_count is 0. */
    int light_count;             /* 0..64 */
    float albedo[4];             /* diffuse albedo per channel (first C used) */
    const float *albedo_map;     /* or per sample: albedo_map[(y*width + x)*C + c]; NULL = albedo */
    const float *emission;       /* emitted radiance per sample, same layout, or NULL */
    float specular;              /* Phong specular weight, >= 0 (0 = diffuse only) */
    float shininess;             /* Phong exponent S > 0 (used when specular > 0): the lobe
                                    ((S+1)/(2 pi)) cos^S about the reflection vector, in SH its
                                    multipliers exp(-l^2/(2S)) (hfvis_zh_phong) */
} hfvis_ns_scene;

/* Where the results go (each pointer may be NULL). Layout [(y*width + x)*C + c], width stride;
 * bounce plane b-1 (b = 1..bounces) at bounce + (b-1)*width*height*C; visibility[(j*rw + i)*16 + r]
 * for receiver (i, j) of the rw x rh receiver grid, rw = ceil(width/s), rh = ceil(height/s). */
typedef struct hfvis_ns_gi_outputs {
    int bounces;                 /* B >= 0 indirect bounces */
    float *direct;               /* width*height*C: emission + direct light */
    float *bounce;               /* bounces*width*height*C: the radiance each bounce adds */
    float *total;                /* width*height*C: direct + every bounce */
    float *visibility;           /* 16*rw*rh: the environment visibility SH V (Eq. 21) per
                                    receiver, for diffing a port; NaN at receivers on holes */
} hfvis_ns_gi_outputs;

/* Multi-resolution height-field global illumination ([NS09] §9, Fig. 6 RENDER).
 * Per receiver (one per s x s block): m slices (Eq. 15-17) give V = Sum_j G_j v_j with
 * v_j = vbar(pi/2) - vbar(omega_max,j) (Eq. 11), G_j the wedge matrices rotated into place
 * (hfvis_ns_sample_matrices; m wedges with the wrap-around one); key lights add their restricted
 * V_key; the incident radiance is I_0 = L_env * V + Sum L_key * V_key (SH products), plus the
 * directional lights. Per bounce b the casting sets are scanned again and the exit radiance of
 * bounce b-1 read from the radiance pyramid at level l_u(i) (Eq. 12) gives U_b. Every texel is
 * shaded with its own full-resolution normal (hfvis_normals_compute) from V, V_key, U_b
 * bilinearly upsampled over the receivers (renormalised over receivers that are not holes; a texel
 * with none around is computed as a receiver of its own): diffuse E = (Ahat_diffuse Y(N)) . I,
 * glossy (Ahat_phong Y(R)) . I with R = reflect(view_dir, N).
 * Exact cases (tested): an open flat field under a uniform sky c returns albedo*c for any m,
 * interp, k, n, offsets and s (bands 0 and 1 of the hemisphere are exact); a
 * V-shaped valley's bottom reproduces the order-4 trench values of B.13-9; emission 1 with a black
 * sky and raw omega_max closes the furnace: direct(sky 1) + bounce(emission 1) = 1.
 * Holes: a non-finite height never occludes, is never in a casting set, and gets NaN in every
 * output. Lighting below the tangent plane and SH ringing are not clamped ([NS09] §4): outputs
 * can be slightly negative.
 * grid: valid (hfvis_grid). scene: see hfvis_ns_scene. opts may be NULL. out: non-NULL; outputs
 * must not overlap each other or the inputs.
 * Returns HFVIS_OK, HFVIS_ERR_INVALID_ARGUMENT for NULL grid/scene/out, an invalid grid, a bad
 * option, channels outside 1..4, a non-finite env_sh value, a light with a non-finite field, an
 * elevation outside [-pi/2, pi/2] or a radius outside [0, pi/2], more than 64 lights, a non-finite
 * albedo, specular < 0 or non-finite, shininess <= 0 or non-finite with specular > 0, a
 * non-finite albedo_map / emission value at a sample that is not a hole, bounces < 0, or sizes that
 * overflow size_t; HFVIS_ERR_OUT_OF_MEMORY (nothing written, nothing leaked).
 * Allocates at most 4 blocks (hfvis_ns_gi_scratch_size bytes): tables, height pyramid and
 * normals, two receiver rows, and (with bounces) the casting-set cache and radiance pyramids.
 * Cost: O(rw rh (m + key samples + directional lights) n) for the direct pass (about 20 ns per
 * step on one 2020s core) and O(rw rh m K C) per bounce with the cache (K the casting-set size;
 * x16 with VECTOR glossy), plus O(W H C 256) shading. Deterministic.
 * Accuracy (measured, test_ns_gi.c and the bench, fBm terrains): with the defaults, the direct light
 * of a uniform sky is within 1.4-2.3% RMS of P1's (hfvis_sky_light), of which about 1.8% is the
 * order-4 SH truncation itself (the SH projection of the exact horizons is that far from P1); one
 * bounce is within 0.016 (unit sky) RMS of P2's hfvis_indirect_light; hard sun shadows differ from
 * hfvis_sun_visibility at 3-4% of the pixels (exponential steps miss thin ridges; P1 itself differs
 * from a fine ray march at 4.7%). Full-frame RMS against the exact pipeline: 5-7% of the mean. */
HFVIS_API hfvis_status hfvis_ns_gi(const hfvis_grid *grid, const hfvis_ns_scene *scene,
                                   const hfvis_ns_gi_options *opts,
                                   const hfvis_ns_gi_outputs *out);

/* Bytes of scratch hfvis_ns_gi allocates for these arguments (the sum of its blocks, all live at
 * once: its peak), the "memory" of [NS09] Table 1 without the caller's outputs. bounces >= 0.
 * Same validation as hfvis_ns_gi (outputs are not needed). */
HFVIS_API hfvis_status hfvis_ns_gi_scratch_size(const hfvis_grid *grid, const hfvis_ns_scene *scene,
                                                const hfvis_ns_gi_options *opts, int bounces,
                                                size_t *bytes);

/* [NS09] Eq. 16: the maximum of the uniform cubic B-spline with control points omega[0..n-1]
 * (radians), evaluated at the knots S(j) = (w_(j-1) + 4 w_j + w_(j+1))/6 and the midpoints
 * S(j+1/2) = (w_(j-1) + 23 w_j + 23 w_(j+1) + w_(j+2))/48, end points replicated
 * (w_(-1) = w_0, w_n = w_(n-1); docs/errata.md E53). n = 0 gives -pi/2 (nothing blocks).
 * Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for a NULL out, n < 0, NULL omega with n > 0 or
 * a non-finite omega. Cost O(n). */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_ns_bspline_max(int n, const double *omega_rad, double *out);

/* The per-sample form of [NS09] Eq. 20-21: G[(j*16 + r)*4 + k] such that
 * hfvis_ns_wedges_to_sh(set, w) = Sum_j G_j w_j (G_j a 16x4 matrix, r the SH index, k the NLP
 * index): each wedge matrix block is rotated into place once, Rot_z(M_s, phi_wedge), and added to
 * the sample it reads, so a slice costs 64 multiply-adds and no rotation. Equal to
 * hfvis_ns_wedges_to_sh up to rounding. G must hold 64*set->samples doubles.
 * Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT as hfvis_ns_wedges_to_sh. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_ns_sample_matrices(const hfvis_ns_wedges *set, double *G);


/* ========================================================================================== */
/* hfvis.c - split runs: raw direction sums and the partial-sum file                          */
/* ========================================================================================== */
/* Every fused output above is a finish f(S) of a per-receiver sum over the K directions,
 * S = sum_k T_k: the sky-view factor 1 - S/K with T_k = sin(max(alpha_k, 0)) (Zaksek et al.
 * 2011), the uniform sky albedo*sky*S with T_k = [P1] Eq. 5's sector integral S_k, the
 * environment albedo*S with T_k = [P1] Eq. 6's sector term, the visibility index S with T_k the
 * samples seen along line k ([P2] §10.1), each gathered from its lattice to the grid
 * points. A run over a direction range [b, e) (sweep options) returns the partial sum of its
 * range; the partial sums of ranges that tile [0, K) add up to S. hfvis_direction_sums returns S
 * (or a partial S) in double, before the finish, so that split runs lose nothing to float
 * rounding: the terms are non-negative, so adding the parts in range order gives the single
 * run's S up to K * 2^-52 * S (two orders of at most K additions, far below a float ulp), and
 * the finish in float then equals the single run's output except where S lies that close to a
 * float rounding boundary (at most 1 ulp apart then). With HFVIS_DIRECTION_ORDER_SWEEP and parts
 * of exactly one quarter-turn group each (K % 4 == 0, ranges [4g, 4g+4)), added in position
 * order, the additions are the single run's own, one gathered group at a time: bit-exact. */

typedef enum hfvis_sum_kind {
    HFVIS_SUM_SKY_VIEW = 1,   /* T_k = sin(max(alpha_k, 0)); hfvis_sky_view_factor = (float)(1 - S/K) */
    HFVIS_SUM_SKY_LIGHT = 2,  /* T_k = [P1] Eq. 5 S_k; hfvis_sky_light = (float)(sky*albedo * S) */
    HFVIS_SUM_ENV_LIGHT = 3,  /* [P1] Eq. 6 per channel; hfvis_env_light = (float)(albedo * S) */
    HFVIS_SUM_VISIBILITY = 4  /* samples seen ([P2] §10.1); hfvis_visibility_count = (float)S */
} hfvis_sum_kind;

/* Raw per-receiver sums S of the directions opts->direction_begin/end (all K when 0, 0) for
 * kind, before the finish (see the enum; the finishes are computed in double as written, e.g.
 * SVF = (float)(1.0 + (-1.0/K) * S), sky light (float)(((double)sky*(double)albedo) * S)).
 * sums[(y*width + x)*channels + c]: channels = env->channels for HFVIS_SUM_ENV_LIGHT, else 1;
 * NaN at holes. env and eopts are used by HFVIS_SUM_ENV_LIGHT only (env required there, else
 * may be NULL). Scratch: that of the matching routine (hfvis_sky_light etc.).
 * Bands (exact rays, sky view / sky light / environment, opts->part_count > 1): the call ADDS
 * each direction's terms, direction by direction in index order, to sums at the receivers on
 * its band's lines of that direction (NaN at their holes) and leaves every other value alone;
 * sums then holds a running S. Calling the part_count bands of direction k, then those of
 * k + 1, ..., on sums zeroed once adds each receiver's terms in the whole call's order, so S is
 * its bits; the bands of one direction write disjoint cells (the hfvis tool runs them
 * concurrently, one direction at a time). Scratch then: one tangent plane (8 bytes a cell) and
 * line buffers, no accumulator.
 * Returns HFVIS_OK, HFVIS_ERR_INVALID_ARGUMENT (NULL grid or sums, K < 1, bad range, unknown
 * kind, missing env, bands in lattice mode or for the visibility index), HFVIS_ERR_LIMIT or
 * HFVIS_ERR_OUT_OF_MEMORY. Cost O((e-b)*width*height), a band its share. */
HFVIS_API hfvis_status hfvis_direction_sums(const hfvis_grid *grid, int K, hfvis_sum_kind kind,
                                            const hfvis_env *env, const hfvis_env_options *eopts,
                                            const hfvis_sweep_options *opts, double *sums);

/* The partial-sum file ("HFVISSUM"): the sums (or horizon planes) of one direction range of one
 * run, with what is needed to check that parts belong together. Layout, byte for byte:
 *   "HFVISSUM 2\n"
 *   "<width> <height> <planes> <directions> <begin> <end>\n"   decimal, single spaces
 *   "<tag>\n"                                                  1..HFVIS_PARTIAL_MAX_TAG bytes
 *   planes*height*width little-endian IEEE-754 doubles, sums[(p*height + y)*width + x]
 *   4 bytes: hfvis_crc32 of every byte before them, little-endian
 * and nothing after. A file whose checksum does not match is HFVIS_ERR_FORMAT, as is a version-1
 * file ("HFVISSUM 1\n", no checksum: written by hfvis 0.1.0 before the checksum; rerun it). The tag is printable ASCII (32..126) chosen by the producer; the hfvis
 * tool stores its command and every parameter that changes the result there. */
#define HFVIS_PARTIAL_MAX_TAG 4096
#define HFVIS_PARTIAL_MAX_PLANES 65536
#define HFVIS_PARTIAL_MAX_VALUES ((unsigned long long)1 << 32) /* planes*width*height (32 GiB) */

typedef struct hfvis_partial {
    int width, height;        /* of the grid, 1..HFVIS_IMAGE_MAX_DIM */
    int planes;               /* values per sample, 1..HFVIS_PARTIAL_MAX_PLANES; planes*width*height
                                 <= HFVIS_PARTIAL_MAX_VALUES (and its bytes must fit a size_t) */
    int directions;           /* K of the whole run, >= 1 */
    int begin, end;           /* the directions [begin, end) this part holds, 0 <= begin < end <= K */
    const char *tag;          /* NUL-terminated, 1..HFVIS_PARTIAL_MAX_TAG printable ASCII chars */
    double *sums;             /* planes*height*width values */
} hfvis_partial;

/* Bytes of the encoded file, or 0 if p is invalid (NULL fields, out-of-range numbers or tag). */
HFVIS_API size_t hfvis_partial_encode_size(const hfvis_partial *p);

/* Encode p into out (out_capacity bytes; *written receives the count). Returns HFVIS_OK,
 * HFVIS_ERR_INVALID_ARGUMENT or HFVIS_ERR_BUFFER_TOO_SMALL. */
HFVIS_API hfvis_status hfvis_partial_encode(const hfvis_partial *p, void *out,
                                            size_t out_capacity, size_t *written);

/* Decode a partial-sum file from memory. Allocates one block with alloc (NULL = malloc) that
 * holds the sums and the tag: release it with hfvis_partial_free. p is untouched on error.
 * Returns HFVIS_OK, HFVIS_ERR_INVALID_ARGUMENT (NULL data or p), HFVIS_ERR_FORMAT (bad magic or
 * version, malformed numbers, a range or tag out of bounds, wrong data length), HFVIS_ERR_LIMIT
 * (planes*width*height over HFVIS_PARTIAL_MAX_VALUES or SIZE_MAX/8, or a side over
 * HFVIS_IMAGE_MAX_DIM) or
 * HFVIS_ERR_OUT_OF_MEMORY. Cost O(size). */
HFVIS_API hfvis_status hfvis_partial_decode(const void *data, size_t size,
                                            const hfvis_allocator *alloc, hfvis_partial *p);

/* Release what hfvis_partial_decode/load allocated (same alloc); p may be NULL or zeroed. */
HFVIS_API void hfvis_partial_free(const hfvis_allocator *alloc, hfvis_partial *p);

/* File wrappers (absent with HFVIS_NO_STDIO): save writes through a temporary file and a rename,
 * as hfvis_pfm_save; load reads and decodes. Errors as encode/decode plus HFVIS_ERR_IO. */
HFVIS_API hfvis_status hfvis_partial_save(const char *path, const hfvis_partial *p);
HFVIS_API hfvis_status hfvis_partial_load(const char *path, const hfvis_allocator *alloc,
                                          hfvis_partial *p);

/* ========================================================================================== */
/* ssao.c - screen space: camera and depth, line lattice, P3 line-sweep AO, HBAO, references  */
/* ========================================================================================== */

/* ------------------------------------------------------------------------------------------
 * Screen space conventions ([P4] §3; docs/errata.md C7; [P3] = Timonen, "Line-Sweep Ambient
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
 *   atan2(dy, dx) (hfvis.h, Conventions: from +x toward +y).
 * Obscurance. Every AO output is obscurance in [0, 1], 0 = nothing blocks. Two integrands exist
 *   (docs/errata.md C4): HBAO and LSAO weight by solid angle per azimuthal slice ("SA", the zenith is
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
    HFVIS_CAMERA_ORTHOGRAPHIC = 2   /* test mode: camera at infinity, zenith +Z */
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
    int rows_bottom_up;         /* 0: memory row 0 is the top of the image; 1: the bottom, as
                                   glReadPixels returns it (depth and normals are read in place;
                                   AO outputs stay top-down) */
} hfvis_camera;

/* HFVIS_OK if the camera is valid; HFVIS_ERR_INVALID_ARGUMENT for NULL, sizes < 1, a negative
 * stride or 0 < stride < width, guard bands < 0 or leaving no inner pixel, an unknown
 * projection, non-finite or non-positive focal lengths / scales (only those of the chosen
 * projection are read), a non-finite principal point, far_depth < 0 or NaN; HFVIS_ERR_LIMIT
 * when width or height exceeds HFVIS_SSAO_MAX_SIZE or 3*stride*height overflows. Every other
 * routine that takes a camera returns HFVIS_ERR_INVALID_ARGUMENT for any camera this rejects
 * (HFVIS_ERR_LIMIT included), except the constructors below, which return this status. */
HFVIS_API hfvis_status hfvis_camera_check(const hfvis_camera *cam);

/* A symmetric perspective camera: the VISIBLE (inner) image of (width - 2 guard_x) x (height -
 * 2 guard_y) pixels spans the vertical field of view fov_y_rad in (0, pi), square pixels
 * (fx = fy = inner_height / (2 tan(fov_y/2))), principal point at the buffer centre, no far
 * limit, stride 0. The guard band keeps the focal length of the visible image ([T14] §2.4, [P4] §3; docs/errata.md E26).
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

/* The clip-space depth range a projection matrix was built for. */
typedef enum hfvis_clip_depth {
    HFVIS_CLIP_DEPTH_GL = 1,           /* z_ndc in [-1, 1], window depth (z_ndc + 1)/2: OpenGL */
    HFVIS_CLIP_DEPTH_ZERO_TO_ONE = 2   /* z_ndc in [0, 1]: Direct3D, Vulkan, Metal, and OpenGL
                                          with glClipControl(..., GL_ZERO_TO_ONE) */
} hfvis_clip_depth;

/* What a projection matrix says about its depth buffer, ready for hfvis_depth_linearize. */
typedef struct hfvis_projection_depth {
    hfvis_depth_encoding encoding;     /* D3D (= GL window depth: standard), REVERSED_Z,
                                          INFINITE_FAR or REVERSED_INFINITE */
    int orthographic;
    double near_plane, far_plane;      /* far_plane +INFINITY for the infinite-far encodings */
} hfvis_projection_depth;

/* The camera of a projection matrix as a port already has it. m holds the 16 elements in the
 * order glUniformMatrix4fv(..., GL_FALSE, m) takes them, which is also the memory order of a
 * row-major Direct3D / DirectXMath matrix: m[4*col + row] = A[row][col] with clip = A (x, y,
 * z, 1). Right-handed (GL, w = -z) and left-handed (D3D, w = +z) matrices, standard, reversed
 * and infinite-far depth are recognised from the matrix itself: perspective
 *   fx = W A00/(2|A32|), fy = H A11/(2|A32|), cx = W/2 (1 + s A02/|A32|),
 *   cy = H/2 (1 - s A12/|A32|), s = sign(A32);
 * orthographic (A32 = 0) sx = 2 A33/(W A00), sy = 2 A33/(H A11), cx = W/2 (1 + A03/A33),
 * cy = H/2 (1 - A13/A33). The window depth is then alpha + beta/z (orthographic alpha + beta z)
 * and the encoding and planes follow from it: an infinite far plane needs the exact form
 * (alpha exactly 1 or 0: A22 = -1, A23 = -2n for GL), an epsilon-adjusted one is refused. The
 * camera's far_depth is the far plane as a float buffer stores it (a cleared pixel is
 * background); 0 for an infinite far plane. width, height: the full buffer (guard band
 * included), row 0 at the top (set rows_bottom_up afterwards for glReadPixels order).
 * depth may be NULL. HFVIS_ERR_INVALID_ARGUMENT for NULL cam/m, an unknown clip, a non-finite
 * element, a matrix with x-y shear, a w row that is neither (0, 0, +-a, 0) nor (0, 0, 0, a),
 * non-positive scales, planes not 0 < near < far (orthographic 0 <= near), or the errors of
 * hfvis_camera_check. */
HFVIS_API hfvis_status hfvis_camera_from_matrix(hfvis_camera *cam, const double m[16],
                                                hfvis_clip_depth clip, int width, int height,
                                                int guard_x, int guard_y,
                                                hfvis_projection_depth *depth);

/* Normals from depth (docs/errata.md E28): for each texel, the view-space points of the left/right
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

/* The azimuthal plane of a screen line (docs/errata.md E20, E21): the plane through the eye and the screen
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
 * intent, rho(0) = 1 (docs/errata.md C4). A zero struct is NONE. */
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

/* ---- directions and the line lattice ([P3] §5.1-5.2, [P4] §6; docs/errata.md E24) ------------ */

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

/* The line lattice of one direction over the full buffer ([P3] §5.1, [P4] §6): lines
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

/* The lattice sample nearest to screen position (u, v) in lattice coordinates ([P3] §5.1, [P4] §6):
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
 * ([P3] §4.1, Fig. 7). */
typedef enum hfvis_ssao_tangent {
    HFVIS_SSAO_TANGENT_DEFAULT = 0,            /* LSAO: FIXED; HBAO: REAL */
    HFVIS_SSAO_TANGENT_FIXED = 1,              /* sin t = fixed_sin_t everywhere (P3's choice) */
    HFVIS_SSAO_TANGENT_REAL = 2,               /* the receiver's tangent for both (strategy 1) */
    HFVIS_SSAO_TANGENT_FIXED_HULL_REAL_EVAL = 3 /* fixed for the hull, real for the value (2) */
} hfvis_ssao_tangent;

/* How depth is read along a line ([P3] §5.2). */
typedef enum hfvis_ssao_sampling {
    HFVIS_SSAO_SAMPLING_DEFAULT = 0,   /* LSAO, HBAO: NEAREST; ray tracer: see its options */
    HFVIS_SSAO_SAMPLING_NEAREST = 1,   /* snap to the texel centre, deproject there (as HBAO) */
    HFVIS_SSAO_SAMPLING_BILINEAR = 2   /* bilinear depth (continuous height-field assumption),
                                          deprojected at the continuous position; a tap with
                                          non-zero weight on background makes a hole */
} hfvis_ssao_sampling;

/* The 2D coordinates of a line's azimuthal plane (docs/errata.md E20, E21). */
typedef enum hfvis_ssao_plane {
    HFVIS_SSAO_PLANE_DEFAULT = 0,  /* LSAO: PAPER; HBAO: EXACT */
    HFVIS_SSAO_PLANE_PAPER = 1,    /* (Q.e1, Q.z) as [P3] Alg. 1 l.4 (with e1 normalised and
                                      screen y flipped); exact only for lines through the
                                      principal point */
    HFVIS_SSAO_PLANE_EXACT = 2     /* (Q.e1, Q.yhat): an isometry of the line's plane */
} hfvis_ssao_plane;

/* The hull's pop test ([P3] Alg. 1 l.12; docs/errata.md E19). */
typedef enum hfvis_lsao_pop {
    HFVIS_LSAO_POP_DEFAULT = 0,  /* = TIES */
    HFVIS_LSAO_POP_TIES = 1,     /* pop when occ(top) <= occ(second) and the second is higher */
    HFVIS_LSAO_POP_STRICT = 2    /* the paper's literal occ(top) < occ(second): sticks on deep
                                    points behind depth steps (docs/errata.md E19: 5x the error) */
} hfvis_lsao_pop;

/* How a pixel reads a direction's lattice values ([P3] §5.1, Fig. 8; docs/errata.md E23). */
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
    hfvis_falloff falloff;               /* [NONE]; STEP is refused (see hfvis_lsao) */
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

/* The obscurity hull along one line in 2D line space ([P3] §4.2, Alg. 1):
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
 * must hold n ints. Cost: at most 2n pop tests, with neither square root nor division in them:
 * Sin is ordered by cross-multiplied (h.w)|h.w| |h'|^2 (w = -p unnormalised), Occ by
 * cross-multiplied numerators and denominators of rho's rational form, and each receiver takes
 * one root and one division for its output, inside the falloff's support only (coordinates
 * scaled by a power of two per line, which is exact, against overflow of the products). HFVIS_ERR_INVALID_ARGUMENT for n < 0, NULL
 * arrays with n > 0, orthographic not 0/1, or options hfvis_lsao_options_resolve rejects. */
HFVIS_API hfvis_status hfvis_lsao_line(const double *x, const double *y, const double *sin_t_cull,
                                       const double *sin_t_eval, int n, int orthographic,
                                       const hfvis_lsao_options *opts, int *stack, double *out);

/* Oracle of hfvis_lsao_line (the reference of [P3] Fig. 7): for each receiver, walk
 * back over the earlier points; point j is visible iff Sin(p_j - p_i) exceeds every Sin seen
 * nearer to i; among the visible points take the largest Occ(., st_cull) (ties: the higher,
 * i.e. farther visible point) and return its Occ(., st_eval) (st_eval if none). Same contract,
 * no scratch, cost O(n^2). Exact mode: with HFVIS_FALLOFF_NONE, Occ is monotonic in Sin, the
 * obscurity hull is the P1 convex hull and hfvis_lsao_line equals this oracle within rounding
 * (the oracle divides as written above, the hull cross-multiplies: at most 1e-13 apart, 5.6e-16
 * measured on test_ssao's random profiles); with a falloff the hull can miss the largest occluder in degenerate cases
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
 * centre (NEAREST; box-pattern steps are integer texel offsets from the line's first texel;
 * with the EXACT plane and non-integer steps that depth is deprojected at the point of the
 * line nearest the texel centre, so every point lies in the line's plane instead of jittering
 * across it) or
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
 * sweep in exact mode (falloff NONE) within rounding (the float values measured equal);
 * cost O(sum of squared line lengths). Same contract. */
HFVIS_API hfvis_status hfvis_lsao_direction_naive(const hfvis_camera *cam, const float *depth,
                                                  const float *normals,
                                                  const hfvis_lsao_options *opts,
                                                  const hfvis_ssao_lattice *lat,
                                                  const hfvis_ssao_line *lines, float *values,
                                                  float *sample_depth);

/* Gather one direction's lattice values into per-pixel accumulators ([P3] §5.1, Fig. 8; docs/errata.md E23):
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
 * docs/errata.md C4), the falloff over view-space distance. Work is at most O(K W0 H0 / (D_S D_L))
 * for the sweeps and O(K W H) for the gathers, otherwise independent of the falloff radius: a
 * line with nearest texels of an integer step (the box pattern's NEAREST sampling, fixed
 * tangent) is swept only over the samples the gather can read (within a few pixels of the
 * inner image) and the steps before them within the falloff's support (its other lattice
 * values are never formed), so with a guard band and a short support the sweeps do less; the
 * result equals the composition with whole lines (above) up to the hull's rounding. Memory
 * O(W0 H0) whatever K is (up to four directions at a time: four are swept, then gathered in one
 * pass).
 * Allocates 5 blocks (directions, lines of four directions, their lattice buffers 8
 * bytes/sample each, the line scratch, the 16-byte/pixel accumulators) plus 1 for
 * reconstructed normals (real tangents without normals). HFVIS_ERR_INVALID_ARGUMENT for an
 * invalid camera or options, NULL depth/ao, ao_stride < inner width; HFVIS_ERR_LIMIT for a
 * lattice over 2^31 samples; HFVIS_ERR_OUT_OF_MEMORY. Outputs untouched on error.
 *
 * Falloffs. With HFVIS_FALLOFF_NONE the obscurity hull is exact (equal to the oracle within
 * rounding, see hfvis_lsao_line_naive). With a
 * continuous falloff it is [P3] §4.1's approximation: a point popped because a farther, higher
 * point beat it for one receiver is gone for the later receivers, where the farther point's
 * weight has fallen further. Measured on a seeded box scene (320 x 240, 60 deg, K = 16) for
 * INV_QUADRATIC, HBAO and EXPONENTIAL at radius 1 and every tangent x plane: the final AO differs
 * from the oracle route (hfvis_lsao_direction_naive + hfvis_lsao_gather) by at most 0.043 and
 * by 3e-4 on average. A STEP falloff drops a point's weight from 1 to 0 at the radius, so the
 * hull discards exactly the points that become the answer (per-sample errors up to 1.4, and a
 * 1e-6 depth change flips outputs by more than 0.05): hfvis_lsao_options_resolve refuses it
 * (use HBAO with a STEP falloff, or a smooth falloff here). A CUSTOM falloff should be
 * continuous for the same reason.
 *
 * A plane facing the camera. Obscurance measures elevation from the receiver's view ray, so a
 * plane perpendicular to the optical axis rises toward the principal point by s/sqrt(f^2 + s^2)
 * along a direction (s the screen offset from the principal point, f the focal length in
 * pixels); opposite directions cancel only when both read the receiver itself. The NEAREST
 * gather ([P3] §5.1) reads each direction's sample up to D_S/2 along the line away, so such a
 * plane gets |ao| <= sum_k w_k D_S,k / (2 f) (a 154-pixel-high 60 deg image with D_S = 1:
 * 0.0037); the BILINEAR gather brings it below 1e-3; an orthographic camera gives exactly 0. */
HFVIS_API hfvis_status hfvis_lsao(const hfvis_camera *cam, const float *depth,
                                  const float *normals, const hfvis_lsao_options *opts,
                                  float *ao, ptrdiff_t ao_stride);

/* ---- HBAO (Bavoil, Sainz, Dimitrov 2008, as the thesis describes it; [T14] §4.1, [P4] §8; docs/errata.md E25) ----------- */
/* LSAO and HBAO defaults side by side (each differs only where its paper says so):
 *                 LSAO                                 HBAO
 *   directions    16 (box pattern, [P3] §5.2)           16 uniform
 *   tangent       FIXED, sin t = -0.85 ([P3] §4.1)     REAL: the receiver's normal (BSD08)
 *   plane         PAPER (Q.e1, Q.z), [P3] Alg. 1 l.4   EXACT (Q.e1, Q.yhat): BSD08 works on
 *                                                      view-space positions
 *   sampling      NEAREST (snapped texels)             NEAREST (BSD08's snapped texels)
 *   radius        the whole buffer (cost does not      the falloff's support, capped at a
 *                 depend on it, [P3] §6)               sixteenth of the inner height (O(K N))
 *   falloff       NONE                                 NONE
 */

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
    double max_radius_px;             /* cap on R_px [a sixteenth of the inner image's height,
                                         at least 8: 45 pixels at 720p, where a 1280x720 frame
                                         (+10 % guard) takes 14 s of one core at K = 16 and
                                         the whole-buffer march took 72 s at K = 8; give the
                                         buffer diagonal for the unbounded march; larger
                                         values act as the diagonal] */
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

/* Horizon-based ambient obscurance by ray marching ([T14] §4.1, [P4] §8; docs/errata.md E25): for every inner
 * non-background pixel c with view point P and each direction D_k (looking TOWARD +D, so the
 * direction set should be symmetric to compare with LSAO), the samples
 *   uniform: c + (s - 1 + xi) (R_px/N) D, s = 1..N (xi = 1 without step jitter)
 *   custom:  c + s (step_x, step_y)
 * until one leaves the buffer, read as in LSAO (NEAREST: the snapped texel's depth, at the
 * texel centre, or with the EXACT plane at the point of the march's line nearest it, so a
 * plane facing the camera stays at 0 from every direction), deprojected and put in the plane
 * of P and D (EXACT: (Q.e1, Q.yhat) with yhat through P; PAPER: (Q.e1, Q.z)); h = q - p, zenith u = -p/|p| (orthographic +y), Sin(h) = h.u/|h|; background samples
 * and samples coincident with P are skipped. The tangent: REAL = the receiver's normal in the
 * plane, t = (n2.y, -n2.x) (ahead), sin t = t.u/|t|; FIXED = fixed_sin_t. Per direction the
 * variant's value (INCREMENTAL sum, SINGLE_HORIZON, LARGEST_OCCLUDER, see the enum; the
 * running horizon starts at sin t), then
 *   ao = clamp( sum_k w_k value_k / sum_k w_k , 0, 1 ),   w_k = 1/K or the custom weights.
 * INCREMENTAL with falloff NONE and the real tangent is the SA obscurance of docs/errata.md C4.
 * ao[y*ao_stride + x], inner pixels; background receivers 0. normals NULL: reconstructed with
 * hfvis_depth_normals when the tangent is REAL (1 block of 12*stride*height bytes; nothing is
 * allocated otherwise). Cost O(K N W H). Deterministic for a seed.
 * HFVIS_ERR_INVALID_ARGUMENT for invalid camera/options, NULL depth/ao, ao_stride < inner
 * width; HFVIS_ERR_OUT_OF_MEMORY. Outputs untouched on error. */
HFVIS_API hfvis_status hfvis_hbao(const hfvis_camera *cam, const float *depth,
                                  const float *normals, const hfvis_hbao_options *opts,
                                  float *ao, ptrdiff_t ao_stride);

/* ---- the screen-space ray-traced reference ([P4] §8; docs/errata.md E36) --------------------------- */

/* Options of hfvis_ssao_reference. NULL or a zero struct = the defaults in brackets. */
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
 * (1/pi) Int rho(d) max(0, n.w) dw - the COS convention (docs/errata.md C4) - converging as R grows.
 * ao[y*ao_stride + x], inner pixels; background receivers 0. normals NULL: reconstructed with
 * hfvis_depth_normals (1 block of 12*stride*height bytes; nothing is allocated otherwise).
 * Deterministic for a seed. Cost O(W H R (W0 + H0)) at worst (cells per ray).
 * HFVIS_ERR_INVALID_ARGUMENT for invalid camera/options, NULL depth/ao, ao_stride < inner
 * width; HFVIS_ERR_OUT_OF_MEMORY. Outputs untouched on error. */
HFVIS_API hfvis_status hfvis_ssao_reference(const hfvis_camera *cam, const float *depth,
                                           const float *normals,
                                           const hfvis_ssao_rt_options *opts, float *ao,
                                           ptrdiff_t ao_stride);

/* ---- analytic depth buffers ---------------------------------------------- */

/* Height fields H(x, y) over the view-space plane z = -base_depth (x, y in view units, H toward
 * the camera), for the closed-form tests. The orthographic camera sees them as true
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



/* ---- P4 far-field ambient obscurance (FFAO; [P4]) --------------------------------- */

/* How the slab integral L(a, b, c, d) of [P4] Eq. 3 is evaluated ([P4] §4, Eq. 2-3). */
typedef enum hfvis_ffao_estimator {
    HFVIS_FFAO_L_DEFAULT = 0,      /* CLOSED_FORM for falloff NONE, else TABLE (the options'
                                      table, or one built per call with the default sizes) */
    HFVIS_FFAO_L_QUADRATURE = 1,   /* Gauss-Legendre with quad_nodes nodes (the reference) */
    HFVIS_FFAO_L_TABLE = 2,        /* the tabulated L (the paper's 3D texture, here 4D) */
    HFVIS_FFAO_L_CLOSED_FORM = 3   /* F(t) = t sin(d)/2 - cos(2t - d)/4: falloff NONE only */
} hfvis_ffao_estimator;

/* Sector averaging of the virtual points ([P4] §7; docs/errata.md E35). */
typedef enum hfvis_ffao_averaging {
    HFVIS_FFAO_AVERAGE_DEFAULT = 0, /* ON for thickness 0 (continuous depth), else OFF */
    HFVIS_FFAO_AVERAGE_ON = 1,      /* mean of (m0, m1) over the lines inside the segment */
    HFVIS_FFAO_AVERAGE_OFF = 2      /* the single line through the segment's middle */
} hfvis_ffao_averaging;

/* The near field ([P4] §9; docs/errata.md E37): what covers the first 1-2 intervals ahead of a receiver. */
typedef enum hfvis_ffao_near {
    HFVIS_FFAO_NEAR_DEFAULT = 0,   /* = DIRECT */
    HFVIS_FFAO_NEAR_NONE = 1,      /* far field only ([P4] Fig. 1 "far field >= 15 px") */
    HFVIS_FFAO_NEAR_DIRECT = 2     /* an HBAO-style march at 1 px steps along +D from the
                                      receiver up to the first far interval, every sample a slab
                                      point of the same estimator; its horizon is handed on */
} hfvis_ffao_near;

/* A tabulated L(a, b, c, d) ([P4] Eq. 3; docs/errata.md E31, E33): na x nb x nc x nd floats over a in [0, pi],
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
    double level_gamma;            /* schedule ([P4] §6; docs/errata.md E34): B_n <= gamma (distance) [1] */
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

/* The slab integral of [P4] Eq. 3 ([P4] §4, Eq. 2-3; docs/errata.md E32) over [a, theta_hi] clipped to
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
/* Release a table's values with the allocator it was built with and zero it; table may be
 * NULL (no-op). */
HFVIS_API void hfvis_ffao_table_free(hfvis_ffao_table *table);
/* L(a, b, c, d) from the table (inputs clamped to its ranges); NaN for an invalid table. */
HFVIS_API double hfvis_ffao_table_lookup(const hfvis_ffao_table *table, double a, double b,
                                         double c, double d);

/* The virtual point of an interval ([P4] §6): h = ((m0 - m1)/slope, m0 zscale) from
 * m0 = max y and m1 = max(y - slope x) (the corrected [P4] Alg. 1, docs/errata.md E29, E30). h NULL: no-op. */
HFVIS_API void hfvis_ffao_virtual_point(double m0, double m1, double slope, double zscale,
                                        double h[2]);

/* The angular width around the zenith of the screen sector [phi_lo, phi_hi] (radians, screen
 * azimuths, 0 < phi_hi - phi_lo < pi) at view point p ([P4] §4, Eq. 2-3; docs/errata.md E32): the angle between the
 * sector's boundary line directions e1 projected onto the plane perpendicular to the view ray
 * (orthographic: the view axis). Sectors of a full circle sum to 2 pi; 2 pi/K on the axis.
 * NaN for an invalid camera or argument (perspective p not in front of the eye). Pure. */
HFVIS_API double hfvis_ffao_sector_weight(const hfvis_camera *cam, const double p[3],
                                          double phi_lo, double phi_hi);

/* One slice of the slab estimator ([P4] Alg. 2; docs/errata.md E31): receiver p and projected normal
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

/* Screen-space far-field ambient obscurance ([P4] Alg. 2), the COS convention
 * (docs/errata.md C4: converges to the ray-traced reference, P4 Eq. 1). Per scan direction k (uniform
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

/* The mipmap baseline ([P4] §5): a pyramid of averaged depth (thickness 0) or of
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

/* Error statistics of an AO image against a reference ([P4] §8, docs/errata.md E36). */
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

/* ========================================================================================== */
/* voxel.c - meshes: type, OBJ codec, analytic meshes                                          */
/* ========================================================================================== */

/* A triangle mesh (hfvis.h, Conventions): vertex v is (xyz[3v], xyz[3v+1], xyz[3v+2]); triangle t has the
 * vertices indices[3t..3t+2], counter-clockwise seen from the side its normal points to
 * (n = (v1 - v0) x (v2 - v0)). A triangle soup is allowed (shared vertices not required, no
 * watertightness assumed) except by hfvis_voxelize_solid, which says so. Valid when every index
 * is < vertex_count and every coordinate is finite; functions that take a mesh check this
 * (O(V + T)) and return HFVIS_ERR_INVALID_ARGUMENT otherwise, except the per-ray queries that
 * take the mesh with its BVH (hfvis_bvh_intersect and its kin, the volume-GI light queries):
 * hfvis_bvh_build checked it, and they say so. Degenerate (zero-area) triangles
 * are allowed and never hit, rasterized or voxelized. */
typedef struct hfvis_mesh {
    const float *xyz;
    size_t vertex_count;
    const uint32_t *indices;
    size_t triangle_count;
} hfvis_mesh;

/* "No triangle" in triangle-id outputs (rasterizer, ray queries). */
#define HFVIS_NO_TRIANGLE 0xFFFFFFFFu

/* Release the arrays of a mesh that a hfvis function allocated (decoders, generators) with the
 * same allocator (NULL = free), and zero the struct. mesh may be NULL. */
HFVIS_API void hfvis_mesh_free(const hfvis_allocator *alloc, hfvis_mesh *mesh);

/* ========================================================================================== */
/* voxel.c - views: GL-convention matrices, shared by the rasterizer and incremental voxelizer */
/* ========================================================================================== */

/* A view of the world (docs/errata.md C7): 4x4 matrices in double, column-major as OpenGL
 * (element (row r, column c) is m[c*4 + r]), world -> eye (view, rigid) and eye -> clip (proj).
 * Eye space looks down -z; NDC z in [-1, 1]; window depth zw = (z_ndc + 1)/2 in [0, 1].
 * Images are width x height pixels, row 0 at the TOP (as image files): pixel (x, y) has its
 * centre at NDC (2(x + 0.5)/width - 1, 1 - 2(y + 0.5)/height). Perspective views come from
 * hfvis_mat4_perspective (glm/gluPerspective), orthographic ones from hfvis_mat4_ortho (glOrtho);
 * `orthographic` tells which (it selects the depth linearisation). near/far are the positive
 * distances of the clip planes used to build proj. */
typedef struct hfvis_view {
    double view[16];
    double proj[16];
    int width, height;
    double near_plane, far_plane;
    int orthographic;
} hfvis_view;

/* Matrices (column-major double[16], OpenGL conventions; see hfvis_view). */

/* out = a * b (apply b first). out may alias a or b. Cannot fail; the pointers must be valid
 * (not checked) and non-finite entries propagate. */
HFVIS_API void hfvis_mat4_multiply(const double a[16], const double b[16], double out[16]);
/* out = inverse of m (Gauss-Jordan, partial pivoting). HFVIS_ERR_INVALID_ARGUMENT if m is singular
 * (a pivot below 1e-300) or not finite; out untouched then. out may alias m. */
HFVIS_API hfvis_status hfvis_mat4_invert(const double m[16], double out[16]);
/* World -> eye of a camera at eye looking at target, up the approximate up direction
 * (gluLookAt). HFVIS_ERR_INVALID_ARGUMENT if eye == target, up is parallel to the view
 * direction, or a value is not finite. */
HFVIS_API hfvis_status hfvis_mat4_look_at(const double eye[3], const double target[3],
                                          const double up[3], double out[16]);
/* Perspective projection (gluPerspective): vertical field of view fov_y_rad in (0, pi), aspect =
 * width/height > 0, 0 < near_plane < far_plane. HFVIS_ERR_INVALID_ARGUMENT otherwise. */
HFVIS_API hfvis_status hfvis_mat4_perspective(double fov_y_rad, double aspect, double near_plane,
                                              double far_plane, double out[16]);
/* Orthographic projection (glOrtho): left < right, bottom < top, near_plane < far_plane.
 * HFVIS_ERR_INVALID_ARGUMENT otherwise. */
HFVIS_API hfvis_status hfvis_mat4_ortho(double left, double right, double bottom, double top,
                                        double near_plane, double far_plane, double out[16]);
/* A perspective hfvis_view in one call: look_at(eye, target, up) and
 * perspective(fov_y_rad, width/height, near_plane, far_plane). Errors as those, plus width or
 * height < 1. */
HFVIS_API hfvis_status hfvis_view_perspective(hfvis_view *view, const double eye[3],
                                              const double target[3], const double up[3],
                                              double fov_y_rad, int width, int height,
                                              double near_plane, double far_plane);
/* An orthographic hfvis_view: look_at(eye, target, up) and ortho(-half_height*aspect,
 * half_height*aspect, -half_height, half_height, near_plane, far_plane), aspect = width/height,
 * half_height > 0. */
HFVIS_API hfvis_status hfvis_view_orthographic(hfvis_view *view, const double eye[3],
                                               const double target[3], const double up[3],
                                               double half_height, int width, int height,
                                               double near_plane, double far_plane);
/* Eye-space z of a window depth zw in [0, 1] (thesis eq. 16 with its sign restored, docs/errata.md
 * E54): perspective z_e = -n f / (f - zw (f - n)), orthographic z_e = -(n + zw (f - n));
 * zw = 0 gives -n, zw = 1 gives -f. The linear view depth is -z_e. Pure: no argument is
 * checked (this one and the inverse below); NaN in gives NaN out. */
HFVIS_API double hfvis_depth_to_eye_z(double zw, double near_plane, double far_plane,
                                      int orthographic);
/* Inverse of hfvis_depth_to_eye_z: the window depth of eye-space z (z < 0 in front). */
HFVIS_API double hfvis_eye_z_to_depth(double z_eye, double near_plane, double far_plane,
                                      int orthographic);

/* ========================================================================================== */
/* voxel.c - volumes and the Volume Buffer                                                     */
/* ========================================================================================== */

/* A voxel grid (docs/errata.md C7): voxel (i, j, k) covers [origin + cell*(i, j, k),
 * origin + cell*(i+1, j+1, k+1)) (half-open), linear index (k*dims[1] + j)*dims[0] + i
 * (x fastest). Valid when every dims[a] >= 1, every cell[a] > 0 and finite, origin finite, and
 * dims[0]*dims[1]*dims[2] <= HFVIS_VOLUME_MAX_VOXELS. */
typedef struct hfvis_volume_grid {
    double origin[3];
    double cell[3];
    int dims[3];
} hfvis_volume_grid;

#define HFVIS_VOLUME_MAX_VOXELS ((size_t)1 << 31) /* 2^31 voxels (2048^3 / 4) */
#define HFVIS_VOLUME_MAX_CHANNELS 32              /* 32 floats = 1024 bits, the thesis' maximum */

/* How a written value combines with the stored one (the Volume Buffer's blend equation, thesis
 * §6.3; GL_MAX for every attachment on the GPU). */
typedef enum hfvis_blend {
    HFVIS_BLEND_DEFAULT = 0,  /* = MAX */
    HFVIS_BLEND_MAX = 0,      /* default (the thesis' GPU behaviour) */
    HFVIS_BLEND_REPLACE = 1,
    HFVIS_BLEND_MIN = 2,
    HFVIS_BLEND_ADD = 3
} hfvis_blend;

/* The Volume Buffer (thesis ch. 6, [G12] ch. 6): `channels` floats per voxel, interleaved,
 * data[lin*channels + c], caller-owned (hfvis_volume_floats floats), each channel with its blend. */
typedef struct hfvis_volume {
    hfvis_volume_grid grid;
    int channels;                                /* 1..HFVIS_VOLUME_MAX_CHANNELS */
    float *data;
    hfvis_blend blend[HFVIS_VOLUME_MAX_CHANNELS];
} hfvis_volume;

/* Fit a grid around a mesh ([G12] ch. 6; docs/errata.md E61): the longest axis of the mesh's bounding box,
 * enlarged by `padding` (a fraction of the longest extent, >= 0, on every side), gets
 * `resolution` voxels. cubic = 0: N_a = max(1, round(resolution*ext_a/ext_max)) and
 * cell_a = ext_a/N_a (near-cubic voxels covering the box exactly; the thesis' Table 3 sizes);
 * cubic != 0: cell = ext_max/resolution on every axis, N_a = max(1, ceil(ext_a/cell)), the box
 * centred in the grid. A zero extent (flat mesh) gets the cell of the longest axis and one voxel.
 * Returns HFVIS_ERR_INVALID_ARGUMENT for a NULL or invalid mesh, no triangles, resolution < 1,
 * negative or non-finite padding or an all-zero extent; HFVIS_ERR_LIMIT past
 * HFVIS_VOLUME_MAX_VOXELS. */
HFVIS_API hfvis_status hfvis_volume_grid_fit(const hfvis_mesh *mesh, int resolution,
                                             double padding, int cubic, hfvis_volume_grid *out);

/* Floats a volume of `channels` channels needs: dims[0]*dims[1]*dims[2]*channels; 0 if grid is
 * NULL or invalid or channels is outside 1..HFVIS_VOLUME_MAX_CHANNELS. */
HFVIS_API size_t hfvis_volume_floats(const hfvis_volume_grid *grid, int channels);

/* Set up vol over caller storage of hfvis_volume_floats(grid, channels) floats, every channel
 * blending with `blend`, every value 0. Returns HFVIS_ERR_INVALID_ARGUMENT for NULL, an invalid
 * grid, channels outside 1..32 or an unknown blend. */
HFVIS_API hfvis_status hfvis_volume_init(hfvis_volume *vol, const hfvis_volume_grid *grid,
                                         int channels, float *storage, hfvis_blend blend);

/* Set every value of every channel to `value`. vol must have been set up by hfvis_volume_init;
 * a NULL vol or vol->data is a no-op. */
HFVIS_API void hfvis_volume_clear(hfvis_volume *vol, float value);

/* Blend values[0..channels) into voxel (i, j, k): data = op_c(data, values[c]) per channel.
 * Returns HFVIS_ERR_INVALID_ARGUMENT for NULL, an invalid grid or channel count, an unknown
 * blend in vol->blend[0..channels) or a voxel outside the grid (nothing written). */
HFVIS_API hfvis_status hfvis_volume_write(hfvis_volume *vol, int i, int j, int k,
                                          const float *values);

/* Merge src into dst voxel by voxel with dst's per-channel blend (the thesis' MAX merge of the
 * three axis passes, ch. 5 Alg. 4). The grids' dims and the channel counts must be equal.
 * Returns HFVIS_ERR_INVALID_ARGUMENT otherwise, for NULL, or for an unknown blend of dst
 * (nothing written). */
HFVIS_API hfvis_status hfvis_volume_merge(hfvis_volume *dst, const hfvis_volume *src);


/* ========================================================================================== */
/* voxel.c - analytic test meshes and the Wavefront OBJ codec                                 */
/* ========================================================================================== */

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
 * which the sphere counts were made with): base vertices, in this order,
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

/* A height field as a mesh: sample (x, y) becomes vertex (x*cell_size, y*cell_size, z) (hfvis.h,
 * Conventions), and each cell with corners a = (x,y), b = (x+1,y), c = (x,y+1), d = (x+1,y+1) is split
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
 * it (hfvis_obj_decode; three allocations, the file buffer freed before returning); a NUL byte
 * in the first 64 KiB (no OBJ has one: /dev/zero, a binary file) is HFVIS_ERR_FORMAT before
 * anything more is read. save encodes
 * into an HFVIS_MALLOC buffer and writes a temporary file beside path, then renames it, so path is
 * either complete or untouched. Returns the decoder's / encoder's errors, HFVIS_ERR_IO if the
 * file cannot be read or written (e.g. path is a directory), HFVIS_ERR_OUT_OF_MEMORY. */
HFVIS_API hfvis_status hfvis_mesh_load(const char *path, const hfvis_allocator *alloc,
                                       hfvis_mesh *out);
HFVIS_API hfvis_status hfvis_mesh_save(const char *path, const hfvis_mesh *mesh);


/* ========================================================================================== */
/* voxel.c - reference rasterizer                                                             */
/* ========================================================================================== */

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
    HFVIS_CULL_DEFAULT = 0, /* = NONE */
    HFVIS_CULL_NONE = 0,  /* default: both sides rasterized */
    HFVIS_CULL_BACK = 1,  /* faces pointing away from the viewer discarded */
    HFVIS_CULL_FRONT = 2  /* faces pointing toward the viewer discarded */
} hfvis_cull_mode;

/* Coordinate frame of the normal output plane. */
typedef enum hfvis_normal_space {
    HFVIS_NORMAL_DEFAULT = 0, /* = WORLD */
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
 * Pipeline (docs/errata.md C7 conventions): vertices go to clip space c = proj*view*v in double;
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
 * hierarchies", IEEE RT 2007), a binned form of the greedy SAH build of [LK] §6: for each node, triangle centroids
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

/* hfvis_bvh_intersect(bvh, mesh, ray, HFVIS_RAY_CLOSEST, NULL, NULL, hit). Kept beside the
 * general query (as Embree keeps rtcIntersect and rtcOccluded): the two queries nearly every
 * caller makes, without a filter. */
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


/* ========================================================================================== */
/* voxel.c - surface voxelization and the Volume Buffer attributes ([G12] ch. 5-6)            */
/* ========================================================================================== */

/* ---- surface voxelization into the Volume Buffer ([G12] ch. 6 Alg. 5 and 6, ch. 5 Alg. 4;
 *      [G12] ch. 6, Alg. 5-6) ------------------------------------------------------- */

/* One voxel fragment: a sample point of a triangle written into one voxel. The sample point is
 * the centre of the pass's pixel (voxel[u] + 0.5, voxel[w] + 0.5) in grid space, u = (axis+1)
 * mod 3, w = (axis+2) mod 3, lifted onto the triangle's plane along `axis`. */
typedef struct hfvis_voxel_fragment {
    int voxel[3];          /* (i, j, k) of the voxel written, inside the grid */
    int axis;              /* sweep axis of the pass (0 x, 1 y, 2 z); voxel[axis] is the slab */
    uint32_t triangle;     /* index of the triangle in the mesh */
    float barycentric[3];  /* of the sample point w.r.t. the triangle's vertices 0, 1, 2; they
                              sum to 1 and lie in [0, 1] up to rounding (orthographic sweep: no
                              perspective correction, [G12] ch. 6) */
    float position[3];     /* world position of the sample point, sum_i barycentric_i v_i */
    float normal[3];       /* unit world-space geometric normal, (v1 - v0) x (v2 - v0) normalised */
} hfvis_voxel_fragment;

/* Attribute callback of the Volume Buffer ("pixel shader", [G12] §6.5): fill values[c] for the
 * channels c = 0 .. vol->channels-1 of fragment f. values holds HFVIS_VOLUME_MAX_CHANNELS floats,
 * all 0 on entry (writes past vol->channels are ignored, never out of bounds); after the call
 * each channel c is blended into the voxel with vol->blend[c] (hfvis_volume_write's equation).
 * The callback must not modify the volume being written. */
typedef void (*hfvis_voxel_fragment_fn)(const hfvis_voxel_fragment *f, float *values, void *user);

/* How a triangle is cut into the slabs of its sweep ([G12] ch. 6, Alg. 5-6). Without an output
 * vertex limit all three give the voxel set of the pixel-centre rule; they differ in cost and,
 * with a limit, in the holes they leave. */
typedef enum hfvis_voxelize_method {
    HFVIS_VOXELIZE_DEFAULT = 0, /* = PIXEL_RULE */
    /* Default. The common CPU rule ([G12] ch. 6): each pass pixel (pu, pw) whose centre lies in the
     * projected triangle gets the voxel of slab floor(z), z = the triangle plane's depth at the
     * centre. One fragment per covered pixel. No vertex limit (max_output_vertices must be 0). */
    HFVIS_VOXELIZE_PIXEL_RULE = 0,
    /* Geometry-shader triangle slicing ([G12] ch. 6, Alg. 5; docs/errata.md E58): the triangle is clipped
     * (Sutherland-Hodgman against both planes of a slab) into one convex piece per slab it
     * spans, lowest slab first, and each piece is rasterised (pixel centres, top-left rule on the
     * piece's own edges) into its slab. Equals the pixel rule except where a pixel centre lies
     * within rounding (about 1e-12 voxels) of a slab plane or a triangle edge. */
    HFVIS_VOXELIZE_GS_SLICING = 1,
    /* Pixel-shader fragment clipping ([G12] ch. 6, Alg. 6; docs/errata.md E57): the whole triangle is rasterised
     * once per slab it spans, lowest first, and a fragment is kept only in the slab that holds its
     * depth, [k, k+1) (the half-open form of the thesis' open interval). Without a limit this is
     * the pixel rule exactly; the cost grows with the slabs spanned (n passes over the
     * triangle's rows; the discarded fragments are rejected per row range, not one by one). */
    HFVIS_VOXELIZE_FRAGMENT_CLIPPING = 2
} hfvis_voxelize_method;

/* Which sweep passes see a triangle. */
typedef enum hfvis_voxelize_axes {
    HFVIS_AXES_DEFAULT = 0, /* = DOMINANT */
    /* Default ([G12] §6.4): each triangle only in the pass of its dominant axis, the largest
     * |component| of its GRID-space normal (ties -> lowest axis index). */
    HFVIS_AXES_DOMINANT = 0,
    /* [G12] ch. 5 Alg. 4 (Chen-Fang slicing without XOR): the passes x, y, z, in that order,
     * each over every triangle not edge-on to it, all blended into the volume; with
     * HFVIS_BLEND_MAX this is exactly the thesis' three per-axis volumes merged with MAX
     * (hfvis_volume_merge of the three HFVIS_AXES_ONLY_* results). */
    HFVIS_AXES_ALL = 1,
    /* One pass only (one of Alg. 4's per-axis volumes; also the thesis' "one axis per frame"
     * amortisation, [G12] ch. 5, Alg. 4). */
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
                                       [G12] ch. 6; docs/errata.md E58); 0 = unlimited (default). With V > 0 a triangle
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

/* Slabs a triangle keeps under a geometry-shader output limit of V vertices ([G12] ch. 6; docs/errata.md E58):
 * GS slicing emits 3 + 4n vertices for n slabs, so floor((V - 3)/4) (V = 7, 11, 15, 19 ->
 * 1, 2, 3, 4); fragment clipping (pixel_clipping != 0) emits 3n, so floor(V/3) (V = 3, 6, 9 ->
 * 1, 2, 3). 0 when V is too small for one slab (and for V <= 0). */
HFVIS_API int hfvis_gs_max_slices(int max_output_vertices, int pixel_clipping);

/* Surface voxelization of a triangle soup into a Volume Buffer ([G12] ch. 6; ch. 5 Alg. 4 with
 * HFVIS_AXES_ALL). Grid space is g = (p - origin)/cell per axis, so a voxel is a unit cube; a
 * pass along axis a (u = a+1, w = a+2 mod 3) projects onto the (u, w) plane, whose pixel
 * (pu, pw) has its centre at (pu + 0.5, pw + 0.5), and cuts along a into slabs [k, k+1).
 * Rules, exactly ([G12] ch. 6):
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
 * ([G12] §6.5). */

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
                                         (hfvis.h, Conventions): albedo * E / pi + emission */

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
    int allow_open;               /* solid only: 0 (default) = a column of any of the three
                                     axes crossed an odd number of times (an open mesh) fails
                                     with HFVIS_ERR_FORMAT; nonzero = such columns of `axis` are
                                     left empty and the others are filled */
} hfvis_binary_voxel_options;

/* The defaults: alloc NULL, axis HFVIS_PARITY_AXIS_Z, allow_open 0. */
HFVIS_API hfvis_binary_voxel_options hfvis_binary_voxel_options_default(void);

/* Triangle / axis-aligned box overlap by the separating-axis theorem (Akenine-Moller 2001;
 * [G12] ch. 6): the box (centre, half sizes half[a] >= 0) and the triangle (v0, v1, v2)
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
 * every triangle; 26-separating, a superset of the pixel-centre voxelizations ([G12] ch. 6).
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
 * the voxels not set yet. Cost O(V + T + rows + columns + voxels written) plus O(grid volume /
 * 64) for the bit scratch and a memset of the byte output (O(grid volume) bytes, at memory
 * bandwidth); the baseline is O(sum of bounding-box voxels). occ: dims[0]*dims[1]*dims[2]
 * bytes, overwritten. count (may be NULL): occupied voxels. opts: only alloc is used. Two
 * allocations: vertex_count*56 bytes (each vertex in grid space with its magnitude and voxel
 * ranges, computed once for the about six triangles sharing it) and ceil(dims/4)^3 * 8 bytes (a
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

/* Solid voxelization by parity ([G12] ch. 6: Chen & Fang 1998; Eisemann & Decoret 2008):
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
 * of times, so a column crossed an odd number of times proves an open mesh. Unless
 * opts->allow_open, the columns of ALL THREE axes are checked first, whatever opts->axis, so the
 * status does not depend on the axis: one odd column on any axis gives HFVIS_ERR_FORMAT (occ
 * untouched). (A hole in a face parallel to the parity axis is crossed by no column of that
 * axis; checking one axis only would fill such a mesh as if it were closed, e.g. the open Utah
 * teapot along z.) An open mesh passes only if no column centre of any axis sees its boundary
 * an odd number of times (holes smaller than a voxel between the column lines); then the fill is
 * the crossing parity along opts->axis. allow_open skips the check, leaves the columns of
 * opts->axis that are crossed an odd number of times empty and fills the others (a hole lets
 * the columns through it fall out; it cannot flood the rest); the result then depends on the
 * axis. Triangles with a zero grid-space normal are ignored; edge-on triangles (zero projected
 * area) never cross. opts: alloc, axis (HFVIS_ERR_INVALID_ARGUMENT for an unknown value),
 * allow_open. count (may be NULL): occupied voxels. One allocation (the largest of
 * dims[0]*dims[1], dims[1]*dims[2], dims[0]*dims[2] bytes of column parities). Cost:
 * O(T + covered column centres) four times (three checking passes unless allow_open) +
 * O(grid volume). Errors: see the section comment. */
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
 * [G12] ch. 6): for each axis a (u = a+1, w = a+2 mod 3), every non-degenerate triangle is
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
 * onto path: complete or untouched), allocating the encoding with HFVIS_MALLOC; errors of encode,
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

/* ========================================================================================== */
/* voxel.c - incremental image-based voxelization (thesis ch. 7, [G12] ch. 7)                  */
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

/* Where a voxel centre lies against one depth image (thesis Fig. 70, [G12] ch. 7, Alg. 7, eq. 17; docs/errata.md E55). */
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
    HFVIS_IV_BIAS_DEFAULT = 0, /* = HALF_DIAGONAL */
    HFVIS_IV_BIAS_HALF_DIAGONAL = 0, /* default: b = |cell|/2, the voxel's "radius (half
                                        diagonal)" of the text (§7.4.1); (sqrt 3/2) s for cubes */
    HFVIS_IV_BIAS_FULL_DIAGONAL = 1, /* b = |cell|: Listing 7.1 (distance between the eye-space
                                        images of p + h and p - h, h = half the voxel size) */
    HFVIS_IV_BIAS_EXPLICIT = 2       /* b = options.bias (finite, >= 0) */
} hfvis_iv_bias_rule;

/* Which depth texels decide a clear. */
typedef enum hfvis_iv_footprint {
    HFVIS_IV_FOOTPRINT_DEFAULT = 0, /* = CENTER */
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

/* Classify a world point against one depth image with bias b ([G12] ch. 7, Alg. 7, eq. 17; docs/errata.md E55): project with
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

/* Single-pass ("optimised") IV (§7.4.3, [G12] ch. 7): no injection; for every voxel and every
 * image in order: CLEARED empties it, BAND turns it on / updates it: occupancy channel = 1 and
 * the mapped channels = the attributes of the centre texel, written as they are (REPLACE, like
 * the thesis' shader output; the blends are not used), KEPT and UNSEEN keep it. A voxel cleared
 * by one image can be turned on by a later one. Samples geometry at volume resolution; several
 * voxels along one pixel ray can be in the band (2b >= one voxel). Errors and allocation as
 * hfvis_iv_cleanup. Cost O(voxels*images). */
HFVIS_API hfvis_status hfvis_iv_single_pass(const hfvis_volume *prev, hfvis_volume *curr,
                                            const hfvis_depth_image *images, size_t image_count,
                                            const hfvis_iv_options *opts, hfvis_iv_stats *stats);

/* IV for lighting (§7.5, [G12] ch. 7): after cleanup of the attribute volume, every NON-EMPTY
 * voxel of the separate injection volume (cleared every frame, VPLs injected with ADD, camera
 * samples with REPLACE) replaces the corresponding values of curr: channels[0..channel_count)
 * (NULL = every channel). Non-empty: the occupancy channel of opts is non-zero, or with
 * HFVIS_IV_NO_CHANNEL any channel is non-zero. replaced (may be NULL) gets the number of voxels.
 * Errors: HFVIS_ERR_INVALID_ARGUMENT for NULL, unequal grids or channel counts, a channel out of
 * range or listed twice, channel_count outside 1..channels with a list, an occupancy channel
 * out of range. Of opts only occupancy_channel is read (may be NULL). No allocation. */
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

/* The defaults: 100000 samples, seed 0, malloc/free. */
HFVIS_API hfvis_distance_options hfvis_distance_options_default(void);

/* Distances between a mesh X and a voxel set Y (its voxel centres), thesis Table 9 ([G12] ch. 7;
 * docs/errata.md E62): Y -> X exactly (every centre's distance to the nearest triangle, point-triangle in
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




/* ========================================================================================== */
/* voxel.c - 4D visibility fields ([G12] ch. 4, Alg. 1-3)                                     */
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
 * - Positional samples ([G12] ch. 4; docs/errata.md E56, the octahedral construction that reproduces the thesis'
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
 * - Maps ([G12] ch. 4, Fig. 30-34): texel (i, j), 0 <= i, j < D, has square coordinates A = 2(i + 0.5)/D - 1
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

/* How the hemisphere of directions maps onto the D x D texels ([G12] §4.4.4, Fig. 30-34). */
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

/* What a texel stores ([G12] §4.6.1, Fig. 42, ch. 4 Alg. 1). */
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

/* Nearest positional sample to direction q (any length > 0), in constant time ([G12] ch. 4; docs/errata.md E56; a CPU
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
 * 1997 ([G12] ch. 4, Fig. 30-34 formulas): square [-1, 1]^2 -> unit disk, area preserving; the disk radius is
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

/* A bounding sphere for a field ([G12] ch. 4 proposal): centre = the centre of the mesh's
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

/* The defaults: malloc/free, a BVH built inside, no progress callback. */
HFVIS_API hfvis_visfield_build_options hfvis_visfield_build_options_default(void);

/* Build a visibility field ([G12] ch. 4, Alg. 1): for every sample k, p_k = c + R u_k,
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

/* ---- queries (Algorithms 2 and 3, [G12] ch. 4, Alg. 2-3) ------------------------------------------------ */

/* One ray against one field, in object space: origin o, direction d (any length > 0; t counts
 * along d/|d|). With oc = o - c, beta = oc.d, gamma = oc.oc - R^2, Delta = beta^2 - gamma:
 *  - gamma >= 0 (origin outside or on the sphere, Fig. 29): MISS if Delta <= 0 or the exit
 *    t1 = -beta + sqrt(Delta) <= 0; else the entry t0 = max(0, -beta - sqrt(Delta)), k = the
 *    nearest sample to the entry point, l = (d.t, d.b, d.w) in its frame; MISS if lz <= 0 or the
 *    texel is unused or stores a miss; else HIT at distance t0 + v 2R (v = the stored fraction).
 *  - gamma < 0 (inside, Fig. 31): the exit p1 at t1; k = nearest sample to p1; the REVERSED ray
 *    -d in k's frame; unoccluded (MISS) if lz <= 0, unused or a miss; else d2 = v 2R and the
 *    result is OCCLUDED at distance t1 - d2 when d2 < t1 - bias, MISS otherwise. The bias
 *    (object units, >= 0) is the thesis' missing tolerance ([G12] ch. 4, Fig. 31): a receiver on the
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
                                               physically consistent rule; docs/errata.md E64) */
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

/* Ambient obscurance of receiver points from visibility fields ([G12] ch. 4, Alg. 2-3; docs/errata.md E64):
 * per point x with unit normal n (renormalised here), the S x S rays l = concentric((2i+1)/S - 1,
 * (2j+1)/S - 1) lifted by Malley (cosine distributed, as the thesis' pre-generated ray set) in
 * the frame hfvis_visfield_frame(n), direction lx t + ly b + lz n, from x + offset n; each object
 * answers hfvis_visfield_query in its object space with bias = opts->bias * R. A HIT or
 * OCCLUDED at world distance s*distance <= max_distance blocks the ray with weight 1 (binary)
 * or 1 - distance/max_distance (linear); ANY takes the largest weight over the objects (the
 * nearest blocker), SUBTRACTIVE their sum. out[p] = min(1, (1/S^2) sum over rays) is the
 * obscurance (hfvis.h conventions: 0 = open, 1 = fully blocked; the thesis prints 1 - this). Because the rays
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

/* The defaults: 20 samples, bias HFVIS_VISFIELD_DEFAULT_BIAS, malloc/free. */
HFVIS_API hfvis_visfield_shadow_options hfvis_visfield_shadow_options_default(void);

/* Visibility of a spherical light (centre, radius >= 0; 0 = a point light, hard shadows) from
 * points ([G12] §4.5.2): per point x, `samples` points y_i on the disc of the light
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

/* The defaults: 4 rays, a perfect mirror (shininess 0), bias HFVIS_VISFIELD_DEFAULT_BIAS,
 * offset 0. */
HFVIS_API hfvis_visfield_reflect_options hfvis_visfield_reflect_options_default(void);

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

/* File wrappers (absent with HFVIS_NO_STDIO): save encodes into an HFVIS_MALLOC buffer and
 * writes it atomically (temporary file renamed onto path); load reads the whole file with alloc and
 * decodes it (two allocations, the file buffer freed before returning). Errors of the codec,
 * HFVIS_ERR_IO, HFVIS_ERR_OUT_OF_MEMORY. */
HFVIS_API hfvis_status hfvis_visfield_save(const char *path, const hfvis_visfield *vf);
HFVIS_API hfvis_status hfvis_visfield_load(const char *path, const hfvis_allocator *alloc,
                                           hfvis_visfield *out);

/* ========================================================================================== */
/* voxel.c - volume-based VPL indirect illumination ([G12] ch. 5)                              */
/* ========================================================================================== */

/* Gaitatzes' volume-based indirect light ([G12] ch. 5; 3IA/CGVCVIP 2010 with Mavridis and
 * Papaioannou), a Light Propagation Volume (Kaplanyan 2009) that knows the geometry:
 *   1. the scene is voxelized along all three axes with direct lighting (Alg. 4: the three
 *      per-axis volumes merged with MAX; hfvis_volgi_voxelize): per voxel an occupancy, an
 *      average normal, an albedo and the outgoing radiance of the directly lit (or emissive)
 *      surface in it;
 *   2. every lit voxel becomes a virtual point light (VPL), a cosine lobe about its normal in
 *      2-band spherical harmonics (hfvis_volgi_inject);
 *   3. the light is propagated iteratively from voxel to face neighbour (eq. 11, the reference
 *      kernel of [G12] ch. 5, eq. 11; docs/errata.md E59; hfvis_volgi_propagate): through empty voxels unchanged, and at
 *      occupied voxels it is recorded in an accumulation volume A and reflected (T_r);
 *   4. each pixel gathers A from the occupied voxels around it and integrates it against its
 *      clamped cosine (eqs. 12-15; hfvis_volgi_gather).
 * hfvis_volgi_render runs the whole pipeline for a view.
 *
 * Conventions of this section.
 * - SH: real, orthonormal, 2 bands = 4 coefficients per colour band, the hfvis.h convention:
 *   Y_0 = 1/(2 sqrt pi), Y_1 = 0.4886 y, Y_2 = 0.4886 z, Y_3 = 0.4886 x (0.4886 = sqrt(3/(4 pi))),
 *   the first 4 values of hfvis_sh_eval. An SH volume holds HFVIS_VOLGI_FLOATS = 12 floats per
 *   voxel, band-major: v[lin*12 + 4*band + k], bands R, G, B, lin = the grid's linear index.
 * - The propagation volume P and the accumulation volume A hold radiant INTENSITY (flux per
 *   steradian, W/sr in a world where radiance is W/(m^2 sr)) as a function of the direction the
 *   light TRAVELS. The flux (energy) of a band is its integral over the sphere, 2 sqrt(pi) c_0.
 * - A VPL of a voxel with outgoing radiance L (Lambertian, hfvis.h, Conventions) and unit normal n has the
 *   flux Phi = pi L s^2 of one voxel face (s^2 = the face of the grid perpendicular to n's
 *   dominant axis) and the intensity (Phi/pi) max(0, n.w) ([G12] ch. 5; docs/errata.md E60).
 * - Constants ([G12] ch. 5): the clamped cosine about n, CC(n) = (sqrt(pi)/2, sqrt(pi/3) n_y,
 *   sqrt(pi/3) n_z, sqrt(pi/3) n_x), and the cone of half-angle 45 degrees about d (the thesis'
 *   "90-degree cone"), Cone(d) = (sqrt(pi)(1 - cos 45), (sqrt(3 pi)/2) sin^2 45 d_y, ...).
 * - All transport arithmetic is double, rounded to float once per stored value. Determinism:
 *   same inputs, same binary, same bits.
 * - Choices the thesis leaves open [C] (docs/errata.md E59), each an option where it matters: the VPL scale
 *   (the flux of one voxel face, above); the meaning of eq. 11 (hfvis_volgi_transfer: per
 *   neighbour the cone flux, re-expanded as a cosine lobe along the travel direction, negative SH
 *   ringing clamped); transfers between two occupied voxels (hfvis_volgi_paths); the mirror axis
 *   (dominant axis of the average normal, ties to the lowest axis; no normal: all three) or a
 *   diffuse re-emission (hfvis_volgi_reflection); partial occupancy as transparency (1 - alpha
 *   passes unchanged); light sent out of the grid is lost; A starts at zero (direct light is not
 *   in A; the first bounce's albedo is in the injected radiance); rho after the first bounce
 *   (hfvis_volgi_reflectance); normals and albedo averaged, radiance MAX-merged
 *   (hfvis_volgi_voxelize); the gather's renormalised trilinear weights over occupied voxels and
 *   its flux-to-irradiance scale (hfvis_volgi_gather); direct light by BVH shadow rays, one-sided.
 * - Thin (one-voxel) walls leak light through the side lobes of the kernel and a cone covers
 *   only 11.04 of the 12.57 sr of the sphere (12 % of an isotropic voxel's flux is not
 *   transported per step; 1.8 % of a cosine lobe's): the reference kernel is the thesis', not an
 *   unbiased light transport; see hfvis_volgi_transfer for the energy-conserving variant. */

#define HFVIS_VOLGI_SH 4                  /* SH coefficients per colour band */
#define HFVIS_VOLGI_FLOATS 12             /* floats per voxel of an SH volume (3 bands x 4) */
#define HFVIS_VOLGI_DEFAULT_ITERATIONS 64 /* the thesis' indoor count (room: 64 on 32^3) */
#define HFVIS_VOLGI_DEFAULT_RESOLUTION 32 /* the thesis' grid (Table 2) */
#define HFVIS_VOLGI_DEFAULT_REFLECTANCE 0.5 /* [G12] §5.6: "after the first light bounce we
                                               consider it constant and equal to 0.5" */
#define HFVIS_VOLGI_DEFAULT_GATHER_SCALE (12.0 / 7.0) /* see hfvis_volgi_gather */
#define HFVIS_VOLGI_MAX_ITERATIONS 1048576
#define HFVIS_VOLGI_MAX_RESOLUTION 2048
#define HFVIS_VOLGI_MAX_LIGHTS 65536
/* Largest |value| accepted in SH volumes and radiance inputs: keeps every sum finite in float
 * (2^31 voxels x 2^20 iterations x 1e20 < FLT_MAX). */
#define HFVIS_VOLGI_MAX_VALUE 1e20f

/* ---- 2-band SH helpers ([G12] ch. 5) ---------------------------------------------------------- */
/* These are bands 0-1 of the order-4 SH API (same basis, index and phase): hfvis_volgi_sh_basis
 * = the first 4 coefficients of hfvis_sh_eval, _clamped_cosine of hfvis_sh_from_zh with
 * hfvis_zh_diffuse, _cone of hfvis_sh_from_zh with hfvis_zh_cap (test_volgi holds them equal).
 * They stay as the volume GI's 4-coefficient kernels: its propagation evaluates them per voxel
 * and face, where computing 16 coefficients to keep 4 would cost four times as much. */

/* The 4 basis functions at the unit direction dir/|dir|. Returns HFVIS_OK, or
 * HFVIS_ERR_INVALID_ARGUMENT for NULL, a non-finite or zero dir (out untouched). */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_volgi_sh_basis(const double dir[3], double out[4]);

/* SH projection of the clamped cosine max(0, n.w) about n/|n|: CC(n) above; its integral is pi
 * and CC(n).CC(n) = 7 pi/12 (the projection keeps 0.875 of the lobe's 2 pi/3 self-product).
 * Errors as hfvis_volgi_sh_basis. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_volgi_sh_clamped_cosine(const double normal[3], double out[4]);

/* SH projection of the indicator of the cone of half-angle half_angle_rad in (0, pi] about
 * axis/|axis|: (sqrt(pi)(1 - cos a), (sqrt(3 pi)/2) sin^2 a axis_y, ... z, ... x), so that
 * f.Cone = the integral of the SH function f over the cone. 45 degrees: (0.5191397,
 * 0.7674950 d_y, 0.7674950 d_z, 0.7674950 d_x). Errors as hfvis_volgi_sh_basis, plus a
 * half-angle outside (0, pi] or not finite. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_volgi_sh_cone(const double axis[3], double half_angle_rad,
                                                              double out[4]);

/* ---- options ------------------------------------------------------------------------------ */

/* How the flux that leaves a voxel toward a face neighbour is computed ([G12] ch. 5, eq. 11; docs/errata.md E59). */
typedef enum hfvis_volgi_transfer {
    HFVIS_VOLGI_TRANSFER_DEFAULT = 0, /* = CONE */
    /* Default: the reference kernel of docs/errata.md E59. The flux through the face toward
     * neighbour i = j + o is F = max(0, P_j . Cone(o)) per band (the SH integral of P_j over the
     * 45-degree cone about o, negative values from SH ringing clamped), and it arrives at i as a
     * cosine lobe (F/pi) CC(o) travelling along o. The part of P_j's flux outside the six cones
     * is not transported (reported as `uncovered` by hfvis_volgi_energy): 1.8 % per step for a
     * cosine lobe along an axis, 12 % for isotropic light. Single VPL (Phi/pi) CC(+z) in empty
     * space: forward flux Phi (3 - sqrt 2)/4, each side Phi (2 - sqrt 2)/4, backward 0. */
    HFVIS_VOLGI_TRANSFER_CONE = 0,
    /* Energy-conserving variant [C]: the whole flux 2 sqrt(pi) c_0 of P_j is split among the six
     * directions in proportion to their clamped cone fluxes, F_o = Phi_j F_o^ref / sum F^ref, so
     * light is lost only by absorption and by leaving the grid (the same first-step proportions,
     * 0.4036 Phi forward, 0.1491 Phi per side). Voxels with Phi_j <= 0 send nothing. */
    HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED = 1
} hfvis_volgi_transfer;

/* What an occupied voxel does with the light S_in that arrives (the thesis' T_r). */
typedef enum hfvis_volgi_reflection {
    HFVIS_VOLGI_REFLECT_DEFAULT = 0, /* = MIRROR */
    /* Default, the thesis' simplification (§5.5.2): mirror S_in on the plane perpendicular to the
     * dominant axis m of the voxel's average normal (ties: lowest axis), i.e. negate band-1
     * coefficient m (index 3 for x, 1 for y, 2 for z; T_r = 1 except -1 there [I]). Keeps c_0, so
     * the reflected flux is exactly rho times the arriving flux. A voxel whose normal is 0
     * negates all three band-1 coefficients (sends the light back) [C]. */
    HFVIS_VOLGI_REFLECT_MIRROR = 0,
    /* Alternative (b) of [G12] ch. 5, eq. 11; docs/errata.md E59, "the new propagation direction is determined by the stored
     * average voxel normal": the arriving flux Phi = 2 sqrt(pi) c_0 is re-emitted as a cosine lobe
     * rho (Phi/pi) CC(+-n) about the normal, on the side the light came from (-n when the band-1
     * part of S_in points along +n, i.e. the light arrives from behind). Normal 0: an isotropic
     * re-emission of the same flux. Per band. */
    HFVIS_VOLGI_REFLECT_DIFFUSE = 1
} hfvis_volgi_reflection;

/* The reflectance rho of occupied voxels in the propagation (not the first bounce, whose albedo
 * is already in the injected radiance, nor the final gather, which uses the pixel's albedo). */
typedef enum hfvis_volgi_reflectance {
    HFVIS_VOLGI_REFLECTANCE_DEFAULT = 0, /* = THESIS */
    HFVIS_VOLGI_REFLECTANCE_THESIS = 0,   /* default: 0.5 for every band ([G12] §5.6) */
    HFVIS_VOLGI_REFLECTANCE_CONSTANT = 1, /* options.reflectance, in [0, 1] (0: pure absorbers) */
    HFVIS_VOLGI_REFLECTANCE_ALBEDO = 2    /* the voxel's albedo (hfvis_volgi_geometry.albedo, which
                                             must then be given), per band: coloured bounces */
} hfvis_volgi_reflectance;

/* Which face-neighbour transfers carry light. */
typedef enum hfvis_volgi_paths {
    HFVIS_VOLGI_PATHS_DEFAULT = 0, /* = ALL */
    /* Default, the reference kernel of docs/errata.md E59: every voxel gathers from all six neighbours, also
     * an occupied voxel from an occupied one (docs/errata.md E59: occupied sources emit into all six
     * directions). Side effect: the side lobes of a lit wall's VPLs land in the neighbouring
     * voxels of the same wall and are recorded there, so a lit surface receives a share of its
     * own light as "indirect" (about 4 x 0.146 of a VPL's flux per step). */
    HFVIS_VOLGI_PATHS_ALL = 0,
    /* "Energy is propagated only in void space, from one voxel boundary to the next" ([G12]
     * §5.5) read literally [C]: a transfer from voxel j to face neighbour i carries the weight
     * 1 - alpha_j alpha_i, so nothing passes between two occupied voxels (no light creeping
     * along or through surfaces). The held-back flux is reported as `blocked` (CONE) or given to
     * the open directions (CONE_NORMALIZED; all blocked: reported as blocked). */
    HFVIS_VOLGI_PATHS_VOID = 1
} hfvis_volgi_paths;

/* Options of every hfvis_volgi_* routine that has tunables. NULL or a zero struct = defaults. */
typedef struct hfvis_volgi_options {
    const hfvis_allocator *alloc;   /* scratch and internal BVH; NULL = malloc/free */
    int iterations;                 /* hfvis_volgi_render: propagation steps, 1..
                                       HFVIS_VOLGI_MAX_ITERATIONS; 0 = 64 */
    int resolution;                 /* hfvis_volgi_render without a grid: voxels along the
                                       longest side (hfvis_volgi_grid_fit), 2..2048; 0 = 32 */
    hfvis_volgi_transfer transfer;  /* default HFVIS_VOLGI_TRANSFER_CONE */
    hfvis_volgi_reflection reflection; /* default HFVIS_VOLGI_REFLECT_MIRROR */
    hfvis_volgi_reflectance reflectance_source; /* default HFVIS_VOLGI_REFLECTANCE_THESIS */
    hfvis_volgi_paths paths;        /* default HFVIS_VOLGI_PATHS_ALL */
    float reflectance;              /* with HFVIS_VOLGI_REFLECTANCE_CONSTANT: rho in [0, 1] */
    double gather_scale;            /* kappa of hfvis_volgi_gather, finite, > 0; 0 = 12/7 */
    double shadow_bias;             /* world distance a shadow ray skips at its start, finite,
                                       > 0; 0 = 1e-5 times the diagonal of the mesh's bounds */
} hfvis_volgi_options;

/* The defaults above, filled in (alloc NULL, iterations 64, resolution 32, CONE, MIRROR,
 * THESIS, ALL, reflectance 0.5, gather_scale 12/7, shadow_bias 0 = relative to the scene). */
HFVIS_API hfvis_volgi_options hfvis_volgi_options_default(void);

/* The parameters a call with opts uses (so that a port can print them): every 0 replaced by its
 * default, reflectance = the rho in use (0.5 for THESIS; unchanged for ALBEDO); shadow_bias stays
 * 0 when it is relative to the scene. opts may be NULL. Returns HFVIS_OK, or
 * HFVIS_ERR_INVALID_ARGUMENT for a NULL out or an invalid field (out untouched): an unknown enum,
 * iterations outside 0..HFVIS_VOLGI_MAX_ITERATIONS, resolution outside 0, 2..2048, a reflectance
 * outside [0, 1] with CONSTANT, a negative or non-finite gather_scale or shadow_bias. Every
 * hfvis_volgi_* routine that takes options rejects the same fields. */
HFVIS_API hfvis_status hfvis_volgi_options_resolve(const hfvis_volgi_options *opts,
                                                   hfvis_volgi_options *out);

/* ---- the geometry volume and the transport ------------------------------------------------ */

/* The read-only geometry volume (thesis: occupancy and average normal "compacted into a single
 * voxel value", plus an optional albedo), caller-owned arrays over grid's voxels, each in the
 * grid's linear order. Valid when grid is valid (hfvis_volume_grid), occupancy and normal are
 * not NULL, every occupancy is in [0, 1] (0 = empty; partial values are transparency: a fraction
 * 1 - alpha passes unchanged, [C]), every normal component is finite (any length: the mirror
 * axis and the diffuse side use its direction; 0 = no normal) and albedo is NULL or every value
 * is in [0, 1]. */
typedef struct hfvis_volgi_geometry {
    hfvis_volume_grid grid;
    const float *occupancy;  /* 1 float per voxel */
    const float *normal;     /* 3 floats per voxel (x, y, z) */
    const float *albedo;     /* 3 floats per voxel (R, G, B) or NULL */
} hfvis_volgi_geometry;

/* Energy accounting of one propagation step, per colour band, in flux units (2 sqrt(pi) c_0
 * summed over voxels, double). Exactly (up to float rounding of the stored volume):
 *   start = end + absorbed + escaped + blocked + uncovered - created.
 * created is 0 for every volume produced by hfvis_volgi_inject and the propagation (each voxel's
 * band-1 magnitude stays <= (2/sqrt 3) c_0, the bound of a cosine lobe, under which the six
 * clamped cone fluxes never exceed the voxel's flux); only arbitrary inputs (e.g. c_0 < 0) can
 * make it positive. With HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED uncovered is 0. */
typedef struct hfvis_volgi_energy {
    double start[3];      /* flux in prop_in */
    double end[3];        /* flux in prop_out */
    double absorbed[3];   /* alpha (1 - rho) Phi(S_in) at occupied voxels */
    double escaped[3];    /* fluxes sent across the grid's border (lost) */
    double blocked[3];    /* held back by the path weights (HFVIS_VOLGI_PATHS_VOID) */
    double uncovered[3];  /* sum over voxels of max(0, Phi_j - sent_j - blocked_j): outside the
                             six cones, not transported */
    double created[3];    /* sum over voxels of max(0, sent_j + blocked_j - Phi_j) */
    double deposited[3];  /* alpha Phi(S_in) added to the accumulation volume: the flux that
                             reached surfaces in this step */
} hfvis_volgi_energy;

/* VPL injection ([G12] §5.5.1): prop[v] = L_v s^2 CC(n_v) per band for every voxel with
 * occupancy > 0, a non-zero normal and radiance L_v = radiance[3v..3v+2] (outgoing radiance of the
 * lit or emissive surface, >= 0), i.e. a cosine lobe carrying the flux pi L_v s^2 (s^2: the face
 * perpendicular to the normal's dominant axis); an occupied voxel without a normal gets the
 * isotropic lobe of the same flux (c_0 only); every other voxel gets 0. The whole of prop is
 * written (12 floats per voxel, see Conventions). prop must not overlap the inputs.
 * Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for NULL, an invalid geometry or a radiance that
 * is negative, not finite or above HFVIS_VOLGI_MAX_VALUE (prop untouched). Allocates nothing.
 * Cost O(voxels). */
HFVIS_API hfvis_status hfvis_volgi_inject(const hfvis_volgi_geometry *geometry,
                                          const float *radiance, float *prop);

/* One propagation step (eq. 11 with the reference kernel of [G12] ch. 5, eq. 11; docs/errata.md E59), by gathering at each
 * voxel i from its six face neighbours j = i - o, o in the order +x, -x, +y, -y, +z, -z:
 *   S_in = sum_o (F_o(j)/pi) CC(o)     (F: see hfvis_volgi_transfer; neighbours outside the grid
 *                                       send nothing, light sent out of the grid is lost)
 *   empty voxel (alpha = 0):  prop_out[i] = S_in                        (T_r = 1)
 *   occupied:                 accum[i] += alpha S_in
 *                             prop_out[i] = (1 - alpha) S_in + alpha rho R(S_in)
 * with R the reflection of opts->reflection and rho of opts->reflectance_source. Occupied source
 * voxels emit into all six directions too (docs/errata.md E59). accum is added to (clear it before the
 * first step: the thesis' A starts at zero, so direct light is not in A). energy may be NULL;
 * otherwise it receives the step's accounting (one extra pass over prop_in).
 * prop_in and accum must not overlap prop_out; prop_in may not overlap accum.
 * With HFVIS_VOLGI_PATHS_VOID every transfer j -> i is weighted by 1 - alpha_j alpha_i.
 * Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for NULL arrays, an invalid geometry, invalid
 * options (hfvis_volgi_options_resolve; also HFVIS_VOLGI_REFLECTANCE_ALBEDO without albedo), or a
 * prop_in or accum value that is not finite or above HFVIS_VOLGI_MAX_VALUE in magnitude;
 * HFVIS_ERR_LIMIT when an SH volume of the grid would exceed SIZE_MAX bytes (32-bit builds);
 * outputs untouched then. Allocates nothing with the default transfer; the normalised transfer
 * allocates one block of 24 bytes per voxel (HFVIS_ERR_OUT_OF_MEMORY). The inputs are checked
 * on every call (O(voxels), about a quarter of a step): use hfvis_volgi_propagate for loops.
 * Cost: O(voxels); about 6 x 3 x 4 floating-point operations and 7 voxel reads per voxel.
 * Exact: equals hfvis_volgi_propagate_step_reference bit for bit. */
HFVIS_API hfvis_status hfvis_volgi_propagate_step(const hfvis_volgi_geometry *geometry,
                                                  const hfvis_volgi_options *opts,
                                                  const float *prop_in, float *prop_out,
                                                  float *accum, hfvis_volgi_energy *energy);

/* Oracle of hfvis_volgi_propagate_step: the kernel of docs/errata.md E59 literally, per voxel and
 * direction with the full 4-coefficient products P_j . Cone(o) and (F/pi) CC(o) (the vectors of
 * hfvis_volgi_sh_cone and hfvis_volgi_sh_clamped_cosine along the six axes), and for the
 * normalised transfer all six cone fluxes of j recomputed for every (i, o). Same arguments,
 * results (bit for bit) and errors; allocates nothing. Cost: several times the fast step. */
HFVIS_API hfvis_status hfvis_volgi_propagate_step_reference(const hfvis_volgi_geometry *geometry,
                                                            const hfvis_volgi_options *opts,
                                                            const float *prop_in, float *prop_out,
                                                            float *accum,
                                                            hfvis_volgi_energy *energy);

/* `iterations` propagation steps (hfvis_volgi_propagate_step each, ping-pong through one scratch
 * volume): on return prop holds the light still travelling and accum has every step's arrivals
 * added (multiple bounces: light reflected at occupied voxels goes on propagating). On an N-grid
 * with walls N voxels apart k bounces need about kN steps ([G12] §5.6). energy: NULL or an array
 * of `iterations` entries, one per step. iterations 0 returns HFVIS_OK without touching anything.
 * Returns the errors of hfvis_volgi_propagate_step plus HFVIS_ERR_INVALID_ARGUMENT for
 * iterations outside 0..HFVIS_VOLGI_MAX_ITERATIONS, HFVIS_ERR_OUT_OF_MEMORY; prop, accum and
 * energy untouched on error. Memory: one block of 48 bytes per voxel (plus 24 for the normalised
 * transfer). The inputs are checked once. Cost: iterations x one step. */
HFVIS_API hfvis_status hfvis_volgi_propagate(const hfvis_volgi_geometry *geometry,
                                             const hfvis_volgi_options *opts, int iterations,
                                             float *prop, float *accum,
                                             hfvis_volgi_energy *energy);

/* Final gather ([G12] §5.5.3, eqs. 12-15; docs/errata.md E60) at a surface point with unit normal n
 * (normalised here): with g = (p - origin)/cell - 1/2, b = floor(g), f = g - b, the trilinear
 * weights of the 8 voxels b + {0,1}^3 are applied to accum over those inside the grid with
 * occupancy > 0 only ("from the eight closest grid points only the ones corresponding to occupied
 * voxels are considered") and renormalised by their sum; then per band
 *   E = (kappa / s_n^2) max(0, L . CC(-n))
 * (A is indexed by travel direction, so light arriving at the surface travels along -n).
 * s_n^2 is the grid face perpendicular to n's dominant axis: accum holds flux, E is irradiance.
 * kappa = opts->gather_scale (default 12/7 = 1/(7/12), the SH self-product of the clamped cosine
 * over pi: a flux F arriving head on as the lobe (F/pi) CC(-n) gives exactly F/s^2). The
 * absolute scale is the library's choice: the thesis gives none. Accuracy (measured in the
 * tests): two parallel plates 9 voxels apart, emitter radiance L, absorbing receiver; the exact
 * irradiance at the receiver's centre is 0.858 pi L, this method gives 0.9 % of it with the
 * CONE transfer (each step forwards only (3 - sqrt 2)/4 of a lobe along its axis and spreads the
 * rest sideways, where the 45-degree cones lose a share), 10.5 % with CONE_NORMALIZED and 26 %
 * with CONE_NORMALIZED and HFVIS_VOLGI_PATHS_VOID: the transport is a diffusion over a few voxels,
 * good for relative, short-range effects (colour bleeding, contact light), not for absolute
 * radiometry. No occupied voxel among the 8:
 * E = 0. Outgoing indirect radiance is albedo E / pi (hfvis.h, Conventions).
 * Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for NULL, an invalid geometry (not re-checked
 * per value: O(1) call; the arrays are only read at the 8 voxels), a non-finite point, a zero or
 * non-finite normal, invalid options. Allocates nothing. */
HFVIS_API hfvis_status hfvis_volgi_gather(const hfvis_volgi_geometry *geometry,
                                          const float *accum, const hfvis_volgi_options *opts,
                                          const double point[3], const double normal[3],
                                          float irradiance[3]);

/* ---- scene, direct light, voxelization with direct light, the whole pipeline --------------- */

typedef enum hfvis_volgi_light_type {
    HFVIS_VOLGI_LIGHT_POINT = 0,       /* at position; radiant intensity I: E = I cos / d^2 */
    HFVIS_VOLGI_LIGHT_SPOT = 1,        /* a point light times the spot factor about direction */
    HFVIS_VOLGI_LIGHT_DIRECTIONAL = 2  /* travelling along direction; intensity = irradiance on a
                                          surface facing it: E = I max(0, -n.d) */
} hfvis_volgi_light_type;

/* A light. Spot factor: 1 within spot_inner_rad of the axis, 0 beyond spot_outer_rad, linear in
 * the cosine of the angle in between (a hard edge when they are equal), 0 <= inner <= outer <= pi,
 * outer > 0. */
typedef struct hfvis_volgi_light {
    hfvis_volgi_light_type type;
    double position[3];     /* point, spot: world position (finite) */
    double direction[3];    /* spot: axis; directional: the direction the light travels; finite,
                               not zero (normalised here) */
    float intensity[3];     /* RGB, finite, >= 0: W/sr (point, spot) or W/m^2 (directional) */
    double spot_inner_rad, spot_outer_rad;
} hfvis_volgi_light;

/* A lit scene: a mesh with per-triangle materials and lights. Direct light is one-sided: a
 * triangle is lit on its front side only (normal (v1 - v0) x (v2 - v0), hfvis_mesh), from lights
 * it sees; shadows by BVH shadow rays (not shadow maps: exact, no bias map). */
typedef struct hfvis_volgi_scene {
    const hfvis_mesh *mesh;
    const float *albedo;    /* 3 floats per triangle in [0, 1], or NULL = 1 (white) */
    const float *emission;  /* 3 floats per triangle, emitted radiance >= 0, or NULL = none */
    const hfvis_volgi_light *lights;
    int light_count;        /* 0..HFVIS_VOLGI_MAX_LIGHTS (lights may be NULL when 0) */
    const hfvis_bvh *bvh;   /* the mesh's BVH (hfvis_bvh_build), or NULL: the routines that need
                               one build it with opts->alloc (hfvis_volgi_direct_irradiance
                               requires it) */
} hfvis_volgi_scene;

/* Direct irradiance E (RGB, W/m^2) at a surface point with normal n (normalised here) from the
 * scene's lights, with shadows: for each light, E += I_eff max(0, n.l) (/ d^2 for point and spot
 * lights) when the shadow ray from point toward the light (BVH any-hit, both faces block, for
 * t in [bias, d - bias], bias = opts->shadow_bias or 1e-5 times the diagonal of the BVH's root
 * box) meets no triangle other than skip_triangle (the receiver's own triangle, or
 * HFVIS_NO_TRIANGLE); directional lights: t in [bias, infinity) along -direction. A receiver
 * within 2 bias of a point or spot light gets nothing from it.
 * scene->bvh must be the mesh's BVH; the mesh is not re-checked (O(lights x log T) per call).
 * Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for NULL, a NULL bvh or one whose
 * triangle_count differs from the mesh's, an invalid light, non-finite point or normal, a zero
 * normal, invalid options; irradiance untouched then. Allocates nothing. */
HFVIS_API hfvis_status hfvis_volgi_direct_irradiance(const hfvis_volgi_scene *scene,
                                                     const hfvis_volgi_options *opts,
                                                     const double point[3],
                                                     const double normal[3],
                                                     uint32_t skip_triangle, float irradiance[3]);

/* A grid for the room-like scenes of this section: cubic voxels of side ext/(resolution - 1),
 * ext = the longest side of the bounds of the vertices the triangles use, so that the two bounding
 * planes of that side pass through voxel CENTRES (a wall in the middle of its voxel layer, not on
 * a voxel boundary where rounding picks the side); the other axes get round(ext_a/s) + 1 voxels,
 * centred on the bounds. resolution = the voxels along the longest side. Returns HFVIS_OK, or
 * HFVIS_ERR_INVALID_ARGUMENT for NULL, an invalid mesh, no triangles, a zero extent, resolution
 * outside 2..HFVIS_VOLGI_MAX_RESOLUTION; HFVIS_ERR_LIMIT past HFVIS_VOLUME_MAX_VOXELS. */
HFVIS_API hfvis_status hfvis_volgi_grid_fit(const hfvis_mesh *mesh, int resolution,
                                            hfvis_volume_grid *out);

/* Voxelization with direct lighting ([G12] ch. 5, Alg. 4): hfvis_voxelize_surface with
 * HFVIS_AXES_ALL (the x, y and z slicing passes, pixel-centre rule) over scene->mesh, where each
 * fragment at position p on triangle t with normal n_t writes
 *   radiance = albedo_t E_direct(p, n_t)/pi + emission_t   (hfvis_volgi_direct_irradiance)
 * merged per channel with MAX over every fragment of the voxel (the thesis' MAX blend, also the
 * MAX merge of the three per-axis volumes), and the normal and albedo AVERAGED over the voxel's
 * fragments ([C], docs/errata.md E59; the GPU's MAX merge of normals is biased). Outputs, each over the
 * grid's voxels in linear order, caller-owned, written entirely: occupancy (1 floats per voxel:
 * 1 where a fragment landed, else 0), normal (3: unit average, 0 where the fragments' normals
 * cancel or the voxel is empty), albedo (3; may be NULL), radiance (3). fragments (may be NULL)
 * receives the number of fragments. The outputs form a hfvis_volgi_geometry for grid.
 * Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for NULL (other than albedo, fragments), an
 * invalid mesh, grid, light, material value (albedo outside [0, 1], negative or non-finite
 * emission), options, or a scene->bvh that does not match the mesh's triangle count;
 * HFVIS_ERR_LIMIT for a mesh past HFVIS_BVH_MAX_TRIANGLES; HFVIS_ERR_OUT_OF_MEMORY. Outputs
 * untouched on error. Memory: one block of 40 bytes per voxel, plus the BVH's four blocks
 * (hfvis_bvh_build) when scene->bvh is NULL. Cost: O(T + fragments x lights x shadow ray). */
HFVIS_API hfvis_status hfvis_volgi_voxelize(const hfvis_volgi_scene *scene,
                                            const hfvis_volume_grid *grid,
                                            const hfvis_volgi_options *opts, float *occupancy,
                                            float *normal, float *albedo, float *radiance,
                                            size_t *fragments);

/* Per-pixel RGB outputs of hfvis_volgi_render, each 3 floats per pixel (pixel (x, y) at
 * 3*(y*width + x), row 0 at the top, hfvis_view), or NULL when not wanted; they must not overlap.
 * Outgoing radiance toward the camera (Lambertian, hfvis.h, Conventions); empty pixels get 0. */
typedef struct hfvis_volgi_outputs {
    float *direct;    /* emission + albedo E_direct / pi (with shadow rays per pixel) */
    float *indirect;  /* albedo E_indirect / pi (hfvis_volgi_gather) */
    float *total;     /* direct + indirect */
} hfvis_volgi_outputs;

/* What hfvis_volgi_render did (may be NULL). */
typedef struct hfvis_volgi_render_info {
    hfvis_volume_grid grid;  /* the grid used */
    size_t fragments;        /* voxel fragments of Alg. 4 */
    size_t occupied;         /* occupied voxels */
    size_t covered_pixels;   /* pixels showing a triangle */
    double injected[3];      /* flux of the VPLs (per band) */
    double deposited[3];     /* flux recorded in the accumulation volume over all iterations */
    double remaining[3];     /* flux still travelling after the last iteration */
} hfvis_volgi_render_info;

/* The whole pipeline for one view: G-buffer (hfvis_rasterize: triangle id, barycentrics, world
 * normal; no culling) -> voxelization with direct light (hfvis_volgi_voxelize over grid, or, when
 * grid is NULL, over hfvis_volgi_grid_fit(mesh, opts->resolution)) -> VPL injection ->
 * opts->iterations propagation steps (hfvis_volgi_propagate with opts) -> per covered pixel, at
 * the exact surface point (from the barycentrics) with the face normal of its triangle (the lit
 * side is the front side, hfvis_volgi_scene; a back face seen by the camera is shaded as what it
 * is, the unlit side):
 *   direct = emission + albedo E_direct/pi   (shadow rays, hfvis_volgi_direct_irradiance),
 *   indirect = albedo E_indirect/pi          (hfvis_volgi_gather),
 *   total = direct + indirect                (the two floats added in double, rounded once).
 * Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT (NULL scene, view or outputs; every output NULL
 * is fine), the errors of hfvis_rasterize (invalid view: HFVIS_ERR_INVALID_ARGUMENT; width or
 * height > HFVIS_RASTER_MAX_SIZE: HFVIS_ERR_LIMIT), hfvis_volgi_grid_fit, hfvis_volgi_voxelize and
 * hfvis_volgi_propagate, HFVIS_ERR_OUT_OF_MEMORY; outputs and info untouched on error.
 * Memory (opts->alloc), in this order: a G-buffer block of 24 bytes per pixel and the
 * rasterizer's scratch; the BVH when scene->bvh is NULL (hfvis_bvh_build: four blocks, two kept
 * until return); the geometry block (40 bytes per voxel); the voxelizer's scratch (40 bytes per
 * voxel, freed before the next); the P and A volumes (96 bytes per voxel); the propagation's
 * scratch (48 bytes per voxel, + 24 normalised): 6 blocks with a scene BVH, 10 without.
 * Cost: the voxelization, iterations x voxels, and per pixel (lights shadow rays + 8 voxel reads).
 * Deterministic (bit-exact on one build). */
HFVIS_API hfvis_status hfvis_volgi_render(const hfvis_volgi_scene *scene,
                                          const hfvis_volume_grid *grid, const hfvis_view *view,
                                          const hfvis_volgi_options *opts,
                                          const hfvis_volgi_outputs *outputs,
                                          hfvis_volgi_render_info *info);

/* ========================================================================================== */
/* ssao.c - Laine-Karras bitmask ray-cast AO (declared here: it uses the meshes, views, BVH)    */
/* ========================================================================================== */

/* S. Laine, T. Karras, "Two Methods for Fast Ray-Cast Ambient Occlusion", EGSR 2010 ([LK]); errata:
 * docs/errata.md E39-E46. All N shadow rays of one receiver are resolved together as
 * an N-bit occlusion mask: ray i -> word i/32, bit i%32 (mask words = ceil(N/32), unused bits 0).
 * Three ways of filling the masks, which give IDENTICAL masks for identical ray sets (exact
 * mode, below):
 *   Method 1, hfvis_lk_raster   - per triangle, the receivers of a camera's G-buffer that its
 *                                 region of influence covers ([LK] §4);
 *   Method 2, hfvis_lk_bvh      - per receiver (any points), a BVH traversal with conservative
 *                                 node masks ([LK] §5);
 *   reference, hfvis_lk_reference - every ray of every receiver cast through the same BVH with an
 *                                 any-hit query ([LK] §6).
 *
 * Obscurance (hfvis.h, Conventions): W = popcount(mask)/N in [0, 1], 0 = nothing blocks ([LK] Eq. 3). The
 * directions are cosine-distributed (Malley's lifting of disc points), so W estimates
 * (1/pi) Int rho(D(p, w)) (n.w) dw ([LK] Eq. 1) with the falloff rho folded into the ray
 * lengths (l_i = r rho^-1(xi_i), [LK] §3; docs/errata.md E44): a ray is "blocked" when a triangle crosses the
 * segment p -> p + l_i w_i. With the default constant falloff every ray has length r.
 *
 * The blocking predicate ([LK] §3.1, Fig. 1), evaluated in double and IDENTICALLY by all three methods
 * (they share one routine; this is what makes the masks equal bit for bit). For a receiver at p
 * with the orthonormal frame F (rows x', y', z'; z' = the jittered normal) and a triangle
 * v0, v1, v2 (floats): a = F (v0 - p), b = F (v1 - p), c = F (v2 - p) (each row dotted with the
 * double difference, x + y + z in that order); n = (b - a) x (c - a), nh = n/|n|; h = nh.a.
 *   - the triangle is skipped (never blocks) when its WORLD cross product (v1 - v0) x (v2 - v0),
 *     evaluated in double, is exactly 0 (zero area), when n is 0, or when |h| < epsilon (the
 *     receiver lies in the triangle's plane: its own triangle and coplanar neighbours, [LK] §4.2);
 *   - one-sided triangles block only receivers on their front side: h < 0, i.e.
 *     nh.(p - v0) > 0 (the side the normal (v1 - v0) x (v2 - v0) points to);
 *   - d = |h|; with the triangle's distance window [r_min, r_max] (LOD, default [0, r]) the
 *     triangle never blocks when d > r_max;
 *   - m = sign(h) nh (so m.a = d > 0); edge planes e1 = a x b, e2 = b x c, e3 = c x a, negated
 *     when h < 0; ray i with the normalised sample point s_i = (l_i/r) u_i is blocked iff
 *       e1.s_i >= 0 and e2.s_i >= 0 and e3.s_i >= 0 and m.s_i >= d/r_max
 *       and not (r_min > 0 and d < r_min and m.s_i > d/r_min),
 *     i.e. the segment of length l_i r_max/r reaches the plane inside the triangle (edges and
 *     the far end included: the hit distance t = l_i d/(r m.s_i) satisfies
 *     r_min l_i/r <= t <= r_max l_i/r, [LK] §4.3; docs/errata.md E42).
 * Every culling test ([LK] §4.2, §5) only skips work: it is applied only where it implies that the
 * predicate is false for every ray, with margins far above the rounding of the predicate, so
 * switching tests on or off never changes a mask (tested exactly). The paper's literal "far
 * depth" test is the one exception (HFVIS_LK_CULL_PAPER_FAR_DEPTH, off by default; docs/errata.md E39).
 *
 * LUT mode ([LK] §3.1; docs/errata.md E40) replaces the per-ray dot products by 4 (5 with a window) look-ups in a
 * T^3 table of plane masks: faster for large N, but quantised - masks then differ from the
 * exact ones for rays within about one table node of a plane (the paper's faint systematic
 * errors), and the three-way identity holds only in exact mode.
 *
 * What is and is not guaranteed
 *   - Exact mode (the defaults: MASK_EXACT, NODE_EXACT, RAYCAST_EXACT): Methods 1 and 2 and the
 *     ray caster return the same masks for the same receivers, frames and rays, by construction:
 *     all three OR values of the one predicate routine, and every shortcut (word cones, culling
 *     tests, node masks, influence volumes, slab tests, rays already blocked) skips only work
 *     whose predicate value is 0 (or already set) with a margin of at least 1e-9 relative, far
 *     above its rounding (about 1e-15). Tested bit for bit on seeded random soups (one-, two-
 *     and per-triangle sides, LOD windows, three falloffs) and on the test meshes, and with every
 *     culling test switched off.
 *   - The predicate is the geometric answer up to double rounding: 0 disagreements with an
 *     independent Moller-Trumbore test in double on 384,000 random ray-triangle pairs, and 0 with
 *     the library's float watertight any-hit test on 292,864 AO rays (the room scene one- and
 *     two-sided, a random soup with per-triangle sides); expect
 *     differences only for rays within about 1e-15 (double) or 1e-7 (float) relative of an edge,
 *     a vertex or the segment's end.
 *   - Not guaranteed: the margins assume coordinates within about 1e6 r of the origin and
 *     triangles not thinner than about 1e-9 r; beyond that a shortcut could in principle skip a
 *     ray the predicate would set (never observed). LUT mode and the paper's far-depth test give
 *     approximations (see there).
 * Determinism: same inputs, same binary, same bits. Rays, frames and jitter come from explicit
 * seeds and the library's own PCG32 / SplitMix64; receiver k's jitter key is k (or the pixel
 * index y*width + x for G-buffer receivers). */

#define HFVIS_LK_MAX_RAYS 4096                  /* N = 1..4096 rays per receiver */
#define HFVIS_LK_LUT_MAX_BYTES ((size_t)1 << 28) /* 256 MiB: the paper's 128^3 table at N = 1024;
                                                   larger tables return HFVIS_ERR_LIMIT */
#define HFVIS_LK_LUT_MIN_RESOLUTION 2
#define HFVIS_LK_LUT_MAX_RESOLUTION 1024
#define HFVIS_LK_DEFAULT_LUT_RESOLUTION 128     /* the paper's T */
#define HFVIS_LK_DEFAULT_EPSILON 1e-5           /* plane epsilon, as a fraction of the radius r */
#define HFVIS_LK_DEFAULT_ALPHA 0.2              /* prism if R_T/r_max > alpha ([LK] §4.1) */
#define HFVIS_LK_DEFAULT_TILT 0.05              /* default normal-tilt jitter bound, radians */

/* ---- ray sets ([LK] §3; docs/errata.md E44) ------------------------------------------------------------------ */

/* How the N disc points are placed before they are lifted to the hemisphere. The default is
 * the torus pattern: the disc pattern of [LK] §6 under-samples grazing directions, which biases
 * the obscurance of curved meshes low (mean obscurance of hfvis meshao's bunny view against an
 * independent cosine-sampled estimate, docs/mesh-ao.md: LLOYD -40 % at N = 128 and -16 % at
 * N = 1024; LLOYD_TORUS, mean of 4 seeds, +1.2 % and +2.2 %, within the estimate's error of
 * 1.4-1.9 %). The torus pattern is unbiased over seeds up to its density grid's step (random
 * starting points on the periodic square, relaxed by rules that commute with translations by
 * that step, so each point is uniform on the disc at that scale); one seed still has
 * a realization error where the blocked directions form a thin band at the horizon (a few
 * percent at N = 1024; another seed gives another realization). */
typedef enum hfvis_lk_pattern {
    HFVIS_LK_PATTERN_DEFAULT = 0, /* = LLOYD_TORUS (LLOYD in 0.1.0) */
    HFVIS_LK_PATTERN_LLOYD = 1,   /* [LK] §6: random points, lloyd_iterations Lloyd steps, each
                                     point replaced by a uniform random point of its Voronoi
                                     cell (rejection sampling, 64 attempts, else it stays),
                                     final_iterations more steps (cells estimated from the
                                     centres of a density_resolution^2 grid, [LK] §3; docs/errata.md E44). On the
                                     disc the Lloyd centroids of the rim cells lie inward, so
                                     the outermost ring of points stays about half a cell inside
                                     the rim and grazing directions are under-sampled (N = 1024:
                                     no point beyond rho = 0.995): biased low wherever grazing
                                     rays are blocked (see above); kept for the paper's setup */
    HFVIS_LK_PATTERN_RANDOM = 2,  /* independent uniform points of the disc: unbiased, noisier */
    HFVIS_LK_PATTERN_LLOYD_TORUS = 3 /* the same relaxation and jitter on the periodic square,
                                        mapped onto the disc by the area-preserving concentric
                                        map of Shirley & Chiu 1997: the torus has no rim, so the
                                        points stay uniform up to the disc's edge (moments
                                        within about 0.005 at N = 1024) */
} hfvis_lk_pattern;

/* The falloff rho(x) of the normalised occluder distance x = D/r, non-increasing, rho = 0 from
 * x = 1 on. The ray lengths realise it: l_i/r = sup{x in [0, 1] : rho(x) >= xi_i} with the
 * stratified xi_i = (pi(i) + 1/2)/N, pi a seeded random permutation (uncorrelated with the
 * directions), so P(l >= D) = rho(D) ([LK] §3, Eq. 1-3). */
typedef enum hfvis_lk_falloff {
    HFVIS_LK_FALLOFF_DEFAULT = 0,   /* = CONSTANT */
    HFVIS_LK_FALLOFF_CONSTANT = 1,  /* rho = 1 on [0, 1): every l_i = r (the paper's tests) */
    HFVIS_LK_FALLOFF_LINEAR = 2,    /* rho = 1 - x: l_i/r = 1 - xi_i, uniform lengths */
    HFVIS_LK_FALLOFF_QUADRATIC = 3, /* rho = (1 - x)^2: l_i/r = 1 - sqrt(xi_i) */
    HFVIS_LK_FALLOFF_CUSTOM = 4     /* rho = falloff_fn(user, x), inverted by bisection */
} hfvis_lk_falloff;

/* A custom falloff: rho(x) for x = D/r in [0, 1], in [0, 1] and non-increasing. */
typedef double (*hfvis_lk_falloff_fn)(void *user, double x);

/* Options of hfvis_lk_rays_build. NULL or a zero struct = defaults. */
typedef struct hfvis_lk_ray_options {
    const hfvis_allocator *alloc;   /* the ray set's block and the scratch; NULL = malloc */
    hfvis_lk_pattern pattern;       /* default LLOYD_TORUS */
    uint64_t seed;                  /* 0 is a valid seed and the default */
    int lloyd_iterations;           /* LLOYD*: steps before the Voronoi jitter, 1..10000;
                                       0 = 64 */
    int final_iterations;           /* LLOYD*: steps after it, 1..10000; 0 = 4 */
    int density_resolution;         /* LLOYD*: the density grid's side, 16..2048; 0 = adaptive,
                                       about 48 grid points per site and at least 64:
                                       ceil(sqrt(48 N 4/pi)) (disc), ceil(sqrt(48 N)) (torus) */
    hfvis_lk_falloff falloff;       /* default CONSTANT */
    hfvis_lk_falloff_fn falloff_fn; /* CUSTOM only */
    void *falloff_user;             /* CUSTOM only */
} hfvis_lk_ray_options;

/* The defaults: alloc NULL, LLOYD_TORUS, seed 0, 64 + 4 Lloyd steps, adaptive grid, CONSTANT. */
HFVIS_API hfvis_lk_ray_options hfvis_lk_ray_options_default(void);

/* A ray set in the canonical receiver frame (z = normal), shared by every receiver ([LK] §3).
 * One block (direction is its start): free with hfvis_lk_rays_free. The rays are ordered so that
 * each 32-ray word covers a compact patch of the hemisphere (Morton order of the disc points);
 * word_cone holds, per word, the unit axis (3), cos and sin of the half-angle of the cone of its
 * directions (inflated by 1e-9 rad), the least and largest length: 7 doubles per word, used to
 * skip whole words with margins (the results are those of the plain per-ray loop). */
typedef struct hfvis_lk_rays {
    int count;             /* N, 1..HFVIS_LK_MAX_RAYS */
    int words;             /* ceil(N/32) */
    double radius;         /* r, world units: the longest possible ray */
    double *direction;     /* 3N: unit directions u_i, u_z > 0 (cosine-distributed) */
    double *length;        /* N: l_i/r in [0, 1] */
    double *point;         /* 3N: normalised sample points s_i = (l_i/r) u_i, |s_i| <= 1 */
    double *word_cone;     /* 7 per word (see above) */
    double min_elevation;  /* min_i asin(u_i,z) > 0, radians (bounds the tilt jitter) */
    int equal_lengths;     /* 1 when every l_i = r */
} hfvis_lk_rays;

/* Build a ray set of `count` rays of radius `radius` (> 0, finite): disc points (pattern), lifted
 * to the hemisphere u = (x, y, sqrt(1 - x^2 - y^2)), every point strictly inside the disc of
 * radius sqrt(1 - 2^-20) (so u_z >= 2^-10), ordered by the Morton code of the disc point, and
 * the lengths of the falloff. Deterministic (seed). Cost: LLOYD* O((iterations + jitter) *
 * density_resolution^2), at the defaults (LLOYD_TORUS) 0.05 s for N = 128 and 0.34 s for
 * N = 1024 (LLOYD: 0.03 s, 0.22 s); RANDOM O(N log N).
 * Allocations: the set's one block (8*(7N + 7 words) bytes) and, LLOYD, one scratch block.
 * Returns HFVIS_OK; HFVIS_ERR_INVALID_ARGUMENT for a NULL out, count outside
 * 1..HFVIS_LK_MAX_RAYS, a non-positive or non-finite radius, an unknown pattern or falloff, an
 * iteration count or resolution out of range, a CUSTOM falloff without fn or whose values at
 * x = j/1024 (j = 0..1024) are not finite, outside [0, 1] or increasing;
 * HFVIS_ERR_OUT_OF_MEMORY. On error *out is untouched and nothing is leaked. */
HFVIS_API hfvis_status hfvis_lk_rays_build(int count, double radius,
                                           const hfvis_lk_ray_options *opts, hfvis_lk_rays *out);

/* A ray set from given directions (3N, finite, each normalised here; u_z must stay > 0 after
 * normalisation) and normalised lengths l_i/r (N values in [0, 1]; NULL = all 1), kept in the
 * given order. One allocation. Errors as hfvis_lk_rays_build (INVALID_ARGUMENT for NULL
 * directions, a zero or non-finite direction, u_z <= 0, a length outside [0, 1]). */
HFVIS_API hfvis_status hfvis_lk_rays_custom(int count, double radius, const double *directions,
                                            const double *lengths, const hfvis_allocator *alloc,
                                            hfvis_lk_rays *out);

/* Release a ray set (the allocator it was built with; NULL = free) and zero it. NULL allowed. */
HFVIS_API void hfvis_lk_rays_free(const hfvis_allocator *alloc, hfvis_lk_rays *rays);

/* Words of one mask: (count + 31)/32; 0 for a count outside 1..HFVIS_LK_MAX_RAYS. */
HFVIS_API int hfvis_lk_mask_words(int count);

/* Obscurance of one mask: popcount(mask)/count in [0, 1] (NaN for NULL or a bad count). */
HFVIS_API double hfvis_lk_obscurance(const uint32_t *mask, int count);

/* ---- receiver frame and jitter ([LK] §3; docs/errata.md E45) ------------------------------------------------- */

/* Jitter of the receiver frame ([LK] §3: against banding on flat areas). */
typedef enum hfvis_lk_jitter {
    HFVIS_LK_JITTER_DEFAULT = 0, /* = rotation uniform in [-pi, pi], tilt bound
                                    HFVIS_LK_DEFAULT_TILT */
    HFVIS_LK_JITTER_NONE = 1,    /* the plain frame of the normal (identity for n = +z) */
    HFVIS_LK_JITTER_CUSTOM = 2   /* rotation_max_rad in [0, pi], tilt_max_rad in [0, pi/2] */
} hfvis_lk_jitter;

/* The receiver frame F (rows x', y', z', row-major double[9], orthonormal up to rounding) of a
 * normal n (need not be unit) and a jitter key, [LK] §3; docs/errata.md E45: (xi1, xi2, xi3) = SplitMix64 of
 * seed and key; t1, t2 = the branchless orthonormal basis of T. Duff et al. 2017 ("Building an
 * Orthonormal Basis, Revisited"); delta = min(tilt_max, 0.9 min_elevation);
 * n' = cos(delta xi1) n + sin(delta xi1)(cos(2 pi xi2) t1 + sin(2 pi xi2) t2), normalised;
 * (x0, y0) = the basis of n'; psi = rotation_max (2 xi3 - 1); x' = cos psi x0 + sin psi y0,
 * y' = -sin psi x0 + cos psi y0, z' = n'. No sample ray goes below the receiver's true tangent
 * plane (each keeps an elevation >= 0.1 min_elevation). World direction of ray i: F^T u_i.
 * JITTER_NONE: (t1, t2, n). Returns HFVIS_ERR_INVALID_ARGUMENT for NULL, an invalid ray set, a
 * zero or non-finite normal, an unknown jitter or custom bounds out of range. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_lk_frame(const hfvis_lk_rays *rays, const double normal[3],
                                                         uint64_t seed, uint64_t key, hfvis_lk_jitter jitter,
                                                         double rotation_max_rad, double tilt_max_rad,
                                                         double frame[9]);

/* ---- occlusion masks and the plane look-up table ([LK] §3.1, Fig. 1) ------------------------------- */

/* The 3-D plane look-up table ([LK] §3.1) with the node convention of docs/errata.md E40: node
 * k = (kx, ky, kz) in 0..T-1 stands for q = -1 + 2k/(T - 1); s = max|q_j|; nodes with s < 1/8
 * are 0 (unused core); otherwise the plane m = q/|q|, delta = (1 - s) 8/7 (= d/r) and bit i is
 * (m.s_i > delta). Masks at masks[((kz*T + ky)*T + kx)*words]. `directions` is the same table
 * built from the unit directions u_i (the projection case of node masks for variable-length
 * rays, [LK] §5); NULL when every length is 1 (it would be identical). */
typedef struct hfvis_lk_lut {
    int resolution;        /* T */
    int count;             /* N of the ray set it was built for */
    int words;
    uint32_t *masks;       /* T^3 * words */
    uint32_t *directions;  /* T^3 * words, or NULL */
    size_t bytes;          /* total bytes of the tables */
} hfvis_lk_lut;

/* Bytes of the tables for T = resolution and `count` rays: T^3 ceil(count/32) 4 bytes per table
 * (two_tables: 2 tables). 0 for invalid arguments or on size_t overflow. */
HFVIS_API size_t hfvis_lk_lut_bytes(int resolution, int count, int two_tables);

/* Build the table(s) for a ray set (two when the lengths differ). Cost T^3 N dot products
 * (whole words decided by the word cones with margins give the same bits); about 0.3 s for the
 * paper's T = 128, N = 128. Returns HFVIS_OK; HFVIS_ERR_INVALID_ARGUMENT for NULL, an invalid
 * ray set, resolution outside HFVIS_LK_LUT_MIN..MAX_RESOLUTION; HFVIS_ERR_LIMIT when the tables
 * need more than HFVIS_LK_LUT_MAX_BYTES (e.g. N = 1024 with T > 128: use a smaller T or exact
 * mode); HFVIS_ERR_OUT_OF_MEMORY. One or two allocations; *out untouched on error. */
HFVIS_API hfvis_status hfvis_lk_lut_build(const hfvis_lk_rays *rays, int resolution,
                                          const hfvis_allocator *alloc, hfvis_lk_lut *out);

/* Release the tables (allocator they were built with) and zero *lut. NULL allowed. */
HFVIS_API void hfvis_lk_lut_free(const hfvis_allocator *alloc, hfvis_lk_lut *lut);

/* Node of a plane (m, d/r) ([LK] §3.1; docs/errata.md E40 LUT_FETCH): delta = d_over_r clamped to [0, 1];
 * q = m (1 - 7 delta/8)/max_j |m_j|; k_j = clamp(floor((q_j + 1)(T - 1)/2 + 1/2), 0, T - 1).
 * Returns HFVIS_ERR_INVALID_ARGUMENT for NULL, a resolution out of range, m zero or not finite,
 * a non-finite d_over_r. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_lk_lut_index(int resolution, const double m[3], double d_over_r,
                                                             int ijk[3]);

/* The mask of plane (m, d/r) in the table (directions != 0: the direction table, which is the
 * main table when all lengths are 1); NULL for the invalid arguments of hfvis_lk_lut_index. */
HFVIS_API const uint32_t *hfvis_lk_lut_fetch(const hfvis_lk_lut *lut, int directions,
                                             const double m[3], double d_over_r);

/* Exact plane mask: bit i = (m.s_i >= d_over_r), for every ray (mask holds words words).
 * Returns HFVIS_ERR_INVALID_ARGUMENT for NULL, an invalid ray set or non-finite m / d_over_r. */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_lk_plane_mask(const hfvis_lk_rays *rays, const double m[3],
                                                              double d_over_r, uint32_t *mask);

/* What the blocking predicate made of one triangle for one receiver. */
typedef enum hfvis_lk_verdict {
    HFVIS_LK_TRI_MASKED = 0,      /* the mask was computed (it may still be 0) */
    HFVIS_LK_TRI_DEGENERATE = 1,  /* zero area (world or frame cross product exactly 0) */
    HFVIS_LK_TRI_SELF = 2,        /* |h| < epsilon: the receiver lies in its plane */
    HFVIS_LK_TRI_FACING_AWAY = 3, /* one-sided and the receiver is behind it */
    HFVIS_LK_TRI_TOO_FAR = 4      /* plane distance d > r_max */
} hfvis_lk_verdict;

/* The exact occlusion mask of one triangle for one receiver (the blocking predicate above;
 * lut != NULL: the LUT form ([LK] §3.1, §4.3): edges lut(e_k/|e_k|, 0), plane lut(m, d/r_max),
 * window ~lut(m, d/r_min)). position = p (world, double), frame = F (hfvis_lk_frame); the
 * distance window [r_min, r_max] with 0 <= r_min <= r_max <= radius; epsilon > 0 (world units,
 * e.g. HFVIS_LK_DEFAULT_EPSILON * radius). mask (words words) is written in every case (all 0
 * unless the verdict is MASKED); verdict may be NULL. Returns HFVIS_ERR_INVALID_ARGUMENT for NULL
 * pointers, an invalid ray set, non-finite inputs, a bad window or epsilon, a lut built for
 * another ray count. No allocation; O(N) (LUT: O(words)). */
HFVIS_API HFVIS_EXPERIMENTAL hfvis_status hfvis_lk_triangle_mask(const hfvis_lk_rays *rays, const hfvis_lk_lut *lut,
                                                                 const double position[3], const double frame[9],
                                                                 const float v0[3], const float v1[3],
                                                                 const float v2[3], int two_sided, double r_min,
                                                                 double r_max, double epsilon, uint32_t *mask,
                                                                 hfvis_lk_verdict *verdict);

/* ---- the three methods ------------------------------------------------------------------ */

/* Culling tests ([LK] §4.2, §5), bit flags of hfvis_lk_options.cull. They only skip work (see the
 * predicate above), except PAPER_FAR_DEPTH. */
#define HFVIS_LK_CULL_FAR_DEPTH 0x01u       /* Method 1 test 1, safe form: skip when every vertex's
                                               linear view depth exceeds the receiver's by more
                                               than r_max (so is every point of the triangle) */
#define HFVIS_LK_CULL_SPHERE 0x02u          /* |p - c_T| > R_T + r_max (minimal bounding sphere) */
#define HFVIS_LK_CULL_FACING 0x04u          /* one-sided and facing away (h >= 0) */
#define HFVIS_LK_CULL_PLANE 0x08u           /* plane distance d > r_max */
#define HFVIS_LK_CULL_HORIZON 0x10u         /* every vertex below the receiver's horizon (local
                                               z <= 0); Method 2 also culls nodes by it */
#define HFVIS_LK_CULL_PAPER_FAR_DEPTH 0x20u /* Method 1 test 1 as [LK] §4.2 states it: skip when
                                               the rasterized far-side depth of the influence
                                               volume exceeds the receiver's depth + r_max. NOT
                                               conservative (docs/errata.md E39): behind a grazing
                                               prism or a billboard it drops real occluders */
#define HFVIS_LK_CULL_SET 0x100u            /* marks an explicit set: cull = HFVIS_LK_CULL_SET |
                                               flags; HFVIS_LK_CULL_SET alone = no test */
#define HFVIS_LK_CULL_NONE HFVIS_LK_CULL_SET
#define HFVIS_LK_CULL_ALL (HFVIS_LK_CULL_SET | 0x1Fu) /* the default: every safe test */

/* How a triangle's occlusion mask is computed. */
typedef enum hfvis_lk_mask_mode {
    HFVIS_LK_MASK_DEFAULT = 0, /* = EXACT */
    HFVIS_LK_MASK_EXACT = 1,   /* per-ray dot products (the predicate): the three methods agree */
    HFVIS_LK_MASK_LUT = 2      /* table look-ups (opts->lut required); approximate */
} hfvis_lk_mask_mode;

/* Method 2's node occlusion masks ([LK] §5, Fig. 4; docs/errata.md E41), from the node box's bounding sphere (box centre,
 * half-diagonal). */
typedef enum hfvis_lk_node_mask {
    HFVIS_LK_NODE_DEFAULT = 0,    /* = EXACT */
    HFVIS_LK_NODE_EXACT = 1,      /* bit i = segment [0, l_i u_i] meets the sphere (with a
                                     margin): conservative, so results equal Method 1's */
    HFVIS_LK_NODE_SPHERE_LUT = 2, /* the paper's circular mask by one plane look-up ([LK]
                                     Fig. 4; direction table for variable lengths). Quantised,
                                     hence NOT conservative: may lose occlusion */
    HFVIS_LK_NODE_NONE = 3        /* all ones: only the distance and horizon culls */
} hfvis_lk_node_mask;

/* One- or two-sided occluders (the paper's tests: all one-sided). */
typedef enum hfvis_lk_sides {
    HFVIS_LK_SIDES_DEFAULT = 0,     /* = ONE */
    HFVIS_LK_SIDES_ONE = 1,
    HFVIS_LK_SIDES_TWO = 2,
    HFVIS_LK_SIDES_PER_TRIANGLE = 3 /* two_sided[t] != 0 marks triangle t two-sided */
} hfvis_lk_sides;

/* Method 1's bounding volume of a triangle's region of influence ([LK] §4.1, Fig. 2-3). */
typedef enum hfvis_lk_volume {
    HFVIS_LK_VOLUME_DEFAULT = 0, /* = AUTO */
    HFVIS_LK_VOLUME_AUTO = 1,    /* prism if R_T/r_max > alpha, else the sphere billboard */
    HFVIS_LK_VOLUME_PRISM = 2,   /* always the hexagonal prism (the sphere for slivers whose
                                    prism is ill-conditioned) */
    HFVIS_LK_VOLUME_SPHERE = 3   /* always the billboard of the sphere (c_T, R_T + r_max) */
} hfvis_lk_volume;

/* The reference ray caster's ray-triangle test. */
typedef enum hfvis_lk_raycast_test {
    HFVIS_LK_RAYCAST_DEFAULT = 0,   /* = EXACT */
    HFVIS_LK_RAYCAST_EXACT = 1,     /* the blocking predicate (double): equal to the masks of
                                       Methods 1 and 2 bit for bit */
    HFVIS_LK_RAYCAST_WATERTIGHT = 2 /* the library's float watertight test (hfvis_bvh_intersect
                                       any-hit, HFVIS_CULL_BACK for one-sided triangles, a hit
                                       filter for the epsilon and window rules), an independent
                                       check: differs only for rays within rounding of an edge,
                                       a vertex or the segment's end */
} hfvis_lk_raycast_test;

/* Options of the three methods. NULL or a zero struct = defaults. */
typedef struct hfvis_lk_options {
    const hfvis_allocator *alloc;       /* scratch; NULL = malloc/free */
    hfvis_lk_mask_mode mask_mode;       /* default EXACT */
    const hfvis_lk_lut *lut;            /* required by MASK_LUT and NODE_SPHERE_LUT */
    hfvis_lk_node_mask node_mask;       /* Method 2; default EXACT */
    unsigned cull;                      /* 0 = HFVIS_LK_CULL_ALL; else HFVIS_LK_CULL_SET | flags */
    hfvis_lk_sides sides;               /* default ONE */
    const uint8_t *two_sided;           /* SIDES_PER_TRIANGLE: one byte per triangle */
    const float *lod_range;             /* NULL or 2 per triangle: the window [r_min, r_max],
                                           0 <= r_min <= r_max <= radius ([LK] §4.3) */
    double epsilon;                     /* plane epsilon, world units, > 0;
                                           0 = HFVIS_LK_DEFAULT_EPSILON * radius */
    hfvis_lk_jitter jitter;             /* default: full rotation, tilt <= 0.05 rad */
    double rotation_max_rad;            /* JITTER_CUSTOM only */
    double tilt_max_rad;                /* JITTER_CUSTOM only */
    uint64_t seed;                      /* jitter seed; 0 is valid and the default */
    hfvis_lk_volume volume;             /* Method 1; default AUTO */
    double alpha;                       /* Method 1 prism/billboard switch, > 0; 0 = 0.2 */
    hfvis_cull_mode gbuffer_cull;       /* culling of the receivers' rasterization; default
                                           HFVIS_CULL_NONE */
    hfvis_lk_raycast_test raycast_test; /* reference; default EXACT */
} hfvis_lk_options;

/* The defaults (epsilon is left 0: it depends on the radius; see hfvis_lk_options_resolve). */
HFVIS_API hfvis_lk_options hfvis_lk_options_default(void);

/* The options a call with `in` (NULL = defaults) and a ray set of radius `radius` uses, every
 * default made explicit (cull, enums, epsilon, alpha, jitter bounds) - so a port can print the
 * exact parameters. Returns HFVIS_ERR_INVALID_ARGUMENT for NULL out, a bad radius, unknown enum
 * values or flags, a non-positive or non-finite epsilon or alpha, custom jitter bounds out of
 * range; PER_TRIANGLE without two_sided, a LUT mode without lut. */
HFVIS_API hfvis_status hfvis_lk_options_resolve(const hfvis_lk_options *in, double radius,
                                                hfvis_lk_options *out);

/* What a call did (counts, written on success). For Table 2 of [LK] compare `masks` between
 * runs with different cull sets. Method 1 counts (triangle, receiver) pairs, Method 2 triangles
 * reached in leaves per receiver, the ray caster ray-triangle tests. */
typedef struct hfvis_lk_stats {
    uint64_t receivers;            /* receivers processed */
    uint64_t rays;                 /* receivers * N */
    uint64_t rays_blocked;         /* set bits in all masks */
    uint64_t fragments;            /* M1: pairs passing the inverted depth test; M2: triangles
                                      met in leaves; ray caster: predicate evaluations (EXACT
                                      test only; 0 with WATERTIGHT) */
    uint64_t culled_far_depth;     /* M1 test 1 (safe or paper form) */
    uint64_t culled_sphere;        /* influence-sphere test */
    uint64_t culled_facing;
    uint64_t culled_plane;
    uint64_t culled_horizon;
    uint64_t skipped;              /* degenerate or |h| < epsilon (not a culling test) */
    uint64_t masks;                /* triangle masks computed */
    uint64_t prisms, spheres;      /* M1: volumes of each kind rasterized */
    uint64_t nodes_visited;        /* M2 and ray caster (EXACT): inner nodes and leaves entered */
    uint64_t nodes_culled_distance, nodes_culled_horizon, nodes_culled_mask; /* M2 */
} hfvis_lk_stats;

/* Explicit receivers: points with normals (the hemisphere side) and jitter keys. Positions and
 * normals are double: a point on a float triangle is generally not a float, and rounding it
 * would move it off the plane (against the epsilon rule). */
typedef struct hfvis_lk_receivers {
    size_t count;
    const double *position;  /* 3 per receiver, world, finite */
    const double *normal;    /* 3 per receiver, finite, non-zero (normalised internally) */
    const uint64_t *key;     /* jitter key per receiver; NULL = the index */
} hfvis_lk_receivers;

/* The receivers of a view (Method 1's G-buffer, [LK] §4 step 1): hfvis_rasterize (triangle id
 * and barycentrics, culling opts->gbuffer_cull) and, at every pixel with a triangle, in raster
 * order: p = (1 - b1 - b2) v0 + b1 v1 + b2 v2 in double, the face normal (v1 - v0) x (v2 - v0)
 * turned toward the viewer (negated when it points away from the eye, or from -forward for an
 * orthographic view), key = y*width + x. position, normal (3 doubles each) and key (may be
 * NULL) must hold width*height receivers; count gets the number written. Returns HFVIS_OK, the
 * errors of hfvis_rasterize, HFVIS_ERR_INVALID_ARGUMENT for NULL or bad options. Allocations:
 * one block of 12 bytes per pixel plus the rasterizer's scratch. */
HFVIS_API hfvis_status hfvis_lk_gbuffer_receivers(const hfvis_mesh *mesh, const hfvis_view *view,
                                                  const hfvis_lk_options *opts, double *position,
                                                  double *normal, uint64_t *key, size_t *count);

/* Method 1 (rasterization, [LK] §4) on the CPU. The receivers are those of
 * hfvis_lk_gbuffer_receivers (frames by hfvis_lk_frame with opts' jitter and key = pixel
 * index). Per triangle, in index order: the minimal bounding sphere (c_T, R_T); the volume
 * bounding its region of influence with radius r_max: the hexagonal prism in half-space form
 * {o_k.(x - v_k) <= r, u_k.(x - v_k) <= r, -eps <= n.(x - v0) <= r} (lower cap -r for two-sided
 * triangles) or the sphere billboard (c_T, R_T + r_max), one-sided cut to its front half; its
 * screen bounding box (whole screen when it reaches behind the eye); every receiver pixel of the
 * box whose eye line meets the volume and does not lie behind the volume's far side (the
 * inverted depth test; a billboard sits just behind its sphere) is a fragment; then the tests
 * 1-5 in the paper's order (far depth, sphere, facing, plane distance, horizon) and the mask,
 * OR-ed into the pixel's. Volumes are enlarged by a relative 1e-9 margin.
 * masks: width*height*words uint32 (pixel y*width + x), obscurance: width*height floats (NaN
 * at pixels without a receiver); either may be NULL (not both); stats may be NULL.
 * Returns HFVIS_OK; HFVIS_ERR_INVALID_ARGUMENT for NULL mesh/view/rays, both outputs NULL, an
 * invalid mesh, view or ray set, bad options or a window beyond the radius; HFVIS_ERR_LIMIT
 * for width or height > HFVIS_RASTER_MAX_SIZE (and the rasterizer's limits, or a size that
 * overflows size_t on 32-bit builds); HFVIS_ERR_OUT_OF_MEMORY. Outputs untouched on error.
 * Receivers: only pixels whose triangle the G-buffer shows (background pixels have none,
 * [LK] §4); the receiver normal faces the viewer, so the hemisphere is on the visible
 * side (back faces seen through an open mesh receive on their visible side too).
 * Memory: 3 blocks: the G-buffer (12 bytes per pixel), the rasterizer's scratch, and one block
 * of 4 bytes per pixel plus 104 bytes per receiver (plus its masks when masks is NULL).
 * Cost O(T + covered pixels * N). */
HFVIS_API hfvis_status hfvis_lk_raster(const hfvis_mesh *mesh, const hfvis_view *view,
                                       const hfvis_lk_rays *rays, const hfvis_lk_options *opts,
                                       uint32_t *masks, float *obscurance, hfvis_lk_stats *stats);

/* Method 2 (BVH traversal, [LK] §5) for explicit receivers. Per receiver: cumulative
 * mask C = 0; a node (the root too) is culled when its padded box lies farther than r from p,
 * entirely below the horizon (every corner's local z <= 0), or its node mask adds no ray
 * (popcount(M & ~C) = 0); surviving children are visited larger estimate first; leaf triangles
 * pass the tests in the paper's BVH order (horizon, facing, plane distance, sphere) and
 * C |= mask; stops when every ray is blocked. With exact node masks the result is the OR of
 * all triangle masks (order-independent), i.e. equal to Method 1 and the ray caster.
 * bvh: built over mesh (hfvis_bvh_build); it is validated first (O(nodes)). masks:
 * recv->count*words, obscurance: recv->count; either may be NULL (not both).
 * Returns HFVIS_OK; HFVIS_ERR_INVALID_ARGUMENT for NULL, an invalid mesh, ray set or receiver
 * (non-finite, zero normal, a count whose 3*count doubles overflow), a BVH that does not match
 * the mesh or is malformed, bad options;
 * HFVIS_ERR_LIMIT when count*words or the scratch overflows size_t; HFVIS_ERR_OUT_OF_MEMORY. Outputs untouched on error. Memory: 1 block (32 bytes per
 * triangle, 1 byte per node, the traversal stack). */
HFVIS_API hfvis_status hfvis_lk_bvh(const hfvis_mesh *mesh, const hfvis_bvh *bvh,
                                    const hfvis_lk_rays *rays, const hfvis_lk_receivers *recv,
                                    const hfvis_lk_options *opts, uint32_t *masks,
                                    float *obscurance, hfvis_lk_stats *stats);

/* The reference ray caster ([LK] §6): every ray i of every receiver, the segment
 * p + t r F^T s_i, t in [0, 1], cast through the BVH (slab tests in double on the padded boxes,
 * widened by 2^-40) with an any-hit query; the ray-triangle test is opts->raycast_test (EXACT:
 * the blocking predicate, so the masks equal Methods 1 and 2 bit for bit; WATERTIGHT: the
 * library's float hfvis_bvh_intersect). Arguments, outputs and errors as hfvis_lk_bvh (its
 * options mask_mode, node_mask and cull do not apply). Memory: 1 block, as hfvis_lk_bvh. Cost
 * O(rays log T). */
HFVIS_API hfvis_status hfvis_lk_reference(const hfvis_mesh *mesh, const hfvis_bvh *bvh,
                                        const hfvis_lk_rays *rays,
                                        const hfvis_lk_receivers *recv,
                                        const hfvis_lk_options *opts, uint32_t *masks,
                                        float *obscurance, hfvis_lk_stats *stats);

/* Which method hfvis_lk_image runs. */
typedef enum hfvis_lk_method {
    HFVIS_LK_METHOD_RASTER = 1,  /* hfvis_lk_raster */
    HFVIS_LK_METHOD_BVH = 2,     /* hfvis_lk_bvh on the G-buffer receivers */
    HFVIS_LK_METHOD_RAYCAST = 3  /* hfvis_lk_reference on the G-buffer receivers */
} hfvis_lk_method;

/* The AO image of a view by any method: the G-buffer receivers (hfvis_lk_gbuffer_receivers) and
 * the method; outputs per pixel as hfvis_lk_raster (NaN / zero masks where no receiver). bvh may
 * be NULL for the BVH methods (one is built with opts->alloc and freed). With exact masks the
 * three methods give the same masks. Errors: those of the routines called, and
 * HFVIS_ERR_INVALID_ARGUMENT for an unknown method. */
HFVIS_API hfvis_status hfvis_lk_image(hfvis_lk_method method, const hfvis_mesh *mesh,
                                      const hfvis_bvh *bvh, const hfvis_view *view,
                                      const hfvis_lk_rays *rays, const hfvis_lk_options *opts,
                                      uint32_t *masks, float *obscurance, hfvis_lk_stats *stats);

/* ========================================================================================== */
/* Deprecated names (removed in the next minor version)                                       */
/* ========================================================================================== */
/* 0.2.0 renamed these (README, "Migrating from 0.1.x"); the old names still compile. Define
 * HFVIS_NO_DEPRECATED to find their uses. */
#ifndef HFVIS_NO_DEPRECATED
#define hfvis_ssao_raytrace hfvis_ssao_reference
#define hfvis_lk_raycast hfvis_lk_reference
#define hfvis_lattice_size hfvis_lattice_nodes
#define hfvis_env_table_size hfvis_env_table_floats
#define hfvis_volume_size hfvis_volume_floats
#endif

/* ========================================================================================== */
/* Internal (not API): shared by hfvis.c, ssao.c and voxel.c                                  */
/* ========================================================================================== */
/* Seen only by the library's own .c files, which define HFVIS__INTERNAL before including this
 * header; user code never sees it and must not rely on it. Everything is defined once, in
 * hfvis.c section 1 (Common) and section 2 (file reading), except the mesh check (voxel.c
 * section 1), so ssao.c and voxel.c need hfvis.c, as the vendoring note at the top says. */
#ifdef HFVIS__INTERNAL
#ifndef HFVIS__INTERNAL_H
#define HFVIS__INTERNAL_H
#include <math.h>

#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#endif

#ifndef HFVIS_ASSERT
#ifdef HFVIS_ENABLE_ASSERTS
#include <assert.h>
#define HFVIS_ASSERT(x) assert(x)
#else
#define HFVIS_ASSERT(x) ((void)0)
#endif
#endif

/* An inner-loop helper forced inline (GCC, Clang), else left to the compiler: the hot loops
 * that pass a constant to one (hf_walk_line's kind) or reload stored values (voxel.c) rely on it.
 * HFVIS__NOINLINE keeps a rare path out of a hot loop (hf_gather_point), whose registers it
 * would otherwise take. */
#if defined(__GNUC__)
#define HFVIS__ALWAYS_INLINE inline __attribute__((always_inline))
#define HFVIS__NOINLINE __attribute__((noinline))
#else
#define HFVIS__ALWAYS_INLINE inline
#define HFVIS__NOINLINE
#endif

#define HFVIS__PI 3.14159265358979323846
#define HFVIS__HALF_PI 1.57079632679489661923
#define HFVIS__NAN ((double)NAN)
#define HFVIS__INF ((double)INFINITY)

/* Allocation (hfvis.h "Memory"): bytes from a->alloc, or from HFVIS_MALLOC when a is NULL or has
 * no alloc; NULL for 0 bytes or on failure. hfvis__free returns p to where hfvis__alloc took it
 * from: a->free when a->alloc is set (nothing when that free is NULL), else HFVIS_FREE, whatever
 * a->free says (memory from an allocator without alloc came from HFVIS_MALLOC). */
void *hfvis__alloc(const hfvis_allocator *a, size_t bytes);
void hfvis__free(const hfvis_allocator *a, void *p);
/* *out = a*b; 0 (and *out untouched) on overflow (stb's mul2sizes_valid). */
int hfvis__mul_size(size_t a, size_t b, size_t *out);
/* count*elem bytes from hfvis__alloc; NULL on overflow, failure or a zero size. */
void *hfvis__alloc_array(const hfvis_allocator *a, size_t count, size_t elem);
/* 1 if a caller plane of `height` rows `stride` pixels apart (stride >= 1), floats_per_pixel
 * floats a pixel, is addressable: every (y*stride + x)*floats_per_pixel stays below PTRDIFF_MAX
 * bytes. */
int hfvis__plane_fits(ptrdiff_t stride, int height, int floats_per_pixel);
/* 1 if v[0..n) are all finite. */
int hfvis__all_finite(const double *v, int n);
/* HFVIS_OK when the mesh is usable (hfvis_mesh: arrays present, indices < vertex_count, finite
 * coordinates), else HFVIS_ERR_INVALID_ARGUMENT; O(V + T). Defined in voxel.c section 1. */
hfvis_status hfvis__mesh_check(const hfvis_mesh *m);

/* The library's PRNGs: stateless SplitMix64 (Steele, Lea, Flood 2014) hashing, its stateful
 * stream, and PCG32 (O'Neill 2014, XSH-RR). No global state; every stream is seeded. */
uint64_t hfvis__mix64(uint64_t x);           /* the SplitMix64 output of state x */
uint64_t hfvis__splitmix64(uint64_t *state); /* hfvis__mix64(*state), then one step */
typedef struct hfvis__pcg32 {
    uint64_t state, inc;
} hfvis__pcg32;
void hfvis__pcg32_seed(hfvis__pcg32 *g, uint64_t seed, uint64_t stream);
uint32_t hfvis__pcg32_next(hfvis__pcg32 *g);
double hfvis__pcg32_unit(hfvis__pcg32 *g);               /* [0, 1), 53 bits from two draws */
uint32_t hfvis__pcg32_below(hfvis__pcg32 *g, uint32_t n); /* [0, n), n >= 1, unbiased */

#ifndef HFVIS_NO_STDIO
/* Whole-file reading (hfvis.c section 2). A sizer looks at the first bytes of a file (at most
 * HFVIS__READ_HEAD, fewer if the file is shorter) and sets *total to the exact size its header
 * announces or HFVIS__READ_ALL (a text format: read to the end), or returns the decoder's error
 * for the header (refused before anything more is read). */
#define HFVIS__READ_HEAD ((size_t)1 << 16)
#define HFVIS__READ_ALL ((size_t)-1)
typedef hfvis_status (*hfvis__sizer)(const unsigned char *head, size_t n, size_t *total);
hfvis_status hfvis__read_file(const char *path, const hfvis_allocator *alloc, hfvis__sizer sizer,
                             unsigned char **data, size_t *size);
#endif
#endif /* HFVIS__INTERNAL_H */
#endif /* HFVIS__INTERNAL */

#ifdef __cplusplus
}
#endif
#endif /* HFVIS_H */
