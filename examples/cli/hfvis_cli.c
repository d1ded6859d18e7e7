/* hfvis_cli.c - the `hfvis` command-line tool (README.md, CLI): horizon maps, sky-view factor,
 * uniform-sky light, sun shadows, environment light, normals, interreflected light, the
 * visibility index and viewsheds of PGM/PFM height fields; voxelization of OBJ meshes.
 * Every file is read and written through the library's codecs (hfvis_image_load, the encoders
 * and hfvis_write_file), so the tool exercises exactly what a vendoring user gets; an interrupt
 * (SIGINT, SIGTERM, SIGHUP) removes the temporary file of a write in progress. Errors: one line
 * "hfvis: <what>: <why>" on stderr, exit 1 (2 for usage errors); exit 0 means OUT is complete. */
#define _POSIX_C_SOURCE 200809L /* isatty() under -std=c99 */
#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#if defined(__unix__) || (defined(__APPLE__) && defined(__MACH__))
#include <sys/stat.h> /* stat(): an output that is an input */
#include <unistd.h>
#define CLI_HAVE_ISATTY 1
#define CLI_HAVE_SIGACTION 1
#endif
#include <time.h>
#include "../common.h"
#include "../raster_io.h"

#define CLI_PI 3.14159265358979323846
#define CLI_FLT_MAX ((double)FLT_MAX)                 /* largest value a float flag may take */
#define CLI_MAX_DIRS 65536                        /* --dirs upper bound */
#define CLI_HORIZON_MAX_VALUES HFVIS_IMAGE_MAX_VALUES /* K*W*H limit of `horizon` (2^28 floats, 1 GiB) */
#define CLI_MAX_BOUNCES 1000                      /* --bounces upper bound (one sweep each) */
#define CLI_MAX_TARGETS 64                        /* viewshed --target points per run */
#define CLI_MAX_RELIEF 1e150 /* |height| / cell: the slopes' squares stay far below DBL_MAX */
#define CLI_EXIT_ERROR 1
#define CLI_EXIT_USAGE 2
#define CLI_RUN (-1)                              /* parse_args: go on and run the command */

enum { CMD_HORIZON, CMD_SKYVIEW, CMD_SKY, CMD_SHADOW, CMD_LIGHT, CMD_NORMALS, CMD_INDIRECT,
       CMD_VISIBILITY, CMD_VIEWSHED, CMD_VOXELIZE, CMD_GI, CMD_SSAO, CMD_VOLGI, CMD_VISFIELD, CMD_MESHAO,
       CMD_HILLSHADE, CMD_OPENNESS, CMD_SUM, CMD_COUNT };
static const char *const cli_cmd_names[CMD_COUNT] = {
    "horizon", "skyview", "sky", "shadow", "light", "normals", "indirect", "visibility",
    "viewshed", "voxelize", "gi", "ssao", "volgi", "visfield", "meshao", "hillshade", "openness",
    "sum"
};

/* voxelize --mode, --axis, --method */
enum { VOX_SURFACE, VOX_CONSERVATIVE, VOX_SOLID };
enum { AXIS_DEFAULT, AXIS_DOMINANT, AXIS_ALL, AXIS_X, AXIS_Y, AXIS_Z };
#define CLI_MAX_RES 2048 /* --res upper bound (the grid limit is 2^31 voxels) */

/* indirect --output */
enum { OUT_TOTAL, OUT_DIRECT, OUT_INDIRECT };

#define CLI_VOLGI_MAX_LIGHTS 8

#define CLI_VOLGI_HELP                                                                              \
    "usage: hfvis volgi MESH.obj|--room -o OUT.pfm|OUT.pgm [--res N] [--iterations I]\n"           \
    "         [--light SPEC]... [--eye X,Y,Z] [--target X,Y,Z] [--up X,Y,Z] [--fov DEG]\n"          \
    "         [--size WxH] [--albedo A] [--output total|direct|indirect] [--transfer cone|normalized]\n" \
    "         [--paths all|void] [--reflection mirror|diffuse] [--reflectance R|albedo]\n"          \
    "Direct and indirect light of a triangle mesh with the volume-based VPL method of Gaitatzes\n" \
    "2012, ch. 5: the mesh is voxelized along x, y and z with its direct light (shadow rays), every\n" \
    "lit voxel becomes a virtual point light (a cosine lobe in 2-band spherical harmonics), the\n"  \
    "light is propagated I steps from voxel to voxel (reflected where it meets occupied voxels)\n"  \
    "and each pixel gathers it from the occupied voxels around its surface point. OUT holds RGB\n"  \
    "radiance toward the camera (Lambertian; a .pgm stacks R, G, B as planes top to bottom).\n"     \
    "  --room            the test room instead of MESH: the unit cube open at y = 0 with a red wall\n" \
    "                    at x = 0, a green wall at x = 1, two white boxes (albedo 0.75)\n"         \
    "  --res N           voxels along the longest side, 2..2048 (default 32, the thesis'); the\n"   \
    "                    outermost planes of the mesh lie on voxel centres\n"                     \
    "  --iterations I    propagation steps, 1..1048576 (default 64: 2 bounces on 32^3)\n"          \
    "  --light SPEC      up to 8 lights (default: one point light, see below), SPEC one of\n"       \
    "                      point:X,Y,Z[:I]            radiant intensity I (W/sr)\n"                 \
    "                      spot:X,Y,Z:DX,DY,DZ:OUTER[,INNER][:I]  cone half-angles in degrees\n"    \
    "                                                  (INNER default 0.8 OUTER)\n"                \
    "                      dir:DX,DY,DZ[:E]           travelling along D, irradiance E\n"           \
    "                    I and E: one value (grey) or R,G,B; default 1 for the room; for a mesh\n" \
    "                    the default light sits above and in front of it, at about 2 sizes\n"      \
    "  --eye, --target   camera position and aim (default: in front of the open side of the room;\n" \
    "                    for a mesh: 2.2 sizes in front (-y) and a little above its centre)\n"     \
    "  --up X,Y,Z        camera up direction (default 0,0,1)\n"                                   \
    "  --fov DEG         vertical field of view, 1..179 (default 40)\n"                           \
    "  --size WxH        image size (default 512x512)\n"                                          \
    "  --albedo A        grey albedo of MESH, 0..1 (default 0.75; not with --room)\n"             \
    "  --output WHAT     total: direct + indirect (default); direct: the direct light with\n"   \
    "                    shadows (shadow rays); indirect: the propagated light only\n"           \
    "  --transfer T      cone: the thesis kernel, clamped 45-degree cone fluxes (default);\n"     \
    "                    normalized: the same proportions, nothing lost between the cones\n"       \
    "  --paths P         all: every face neighbour exchanges light (default, the reference kernel, docs/errata.md E59);\n"  \
    "                    void: no light between two occupied voxels (\"only in void space\")\n"   \
    "  --reflection R    mirror: on the dominant axis of the voxel normal (default, the thesis);\n" \
    "                    diffuse: re-emitted as a cosine lobe about the normal\n"                  \
    "  --reflectance R   reflectance of occupied voxels during the propagation, 0..1 (default\n"   \
    "                    0.5, the thesis), or 'albedo' for the voxels' own colour\n"               \
    "Prints the grid, the voxel counts and the light budget unless --quiet. Default PGM range\n"   \
    "0:the largest output value. Only -o, --range and --quiet of the shared options apply.\n"

#define CLI_VOLGI_FLAGS                                                                      \
    { "--room", 0, CLI_ONLY(CMD_VOLGI) }, { "--iterations", 1, CLI_ONLY(CMD_VOLGI) },        \
    { "--light", 1, CLI_ONLY(CMD_VOLGI) }, { "--eye", 1, CLI_ONLY(CMD_VOLGI) | CLI_ONLY(CMD_MESHAO) },              \
    { "--target", 1, CLI_ONLY(CMD_VOLGI) | CLI_ONLY(CMD_MESHAO) | CLI_ONLY(CMD_VIEWSHED) }, { "--up", 1, CLI_ONLY(CMD_VOLGI) | CLI_ONLY(CMD_MESHAO) },              \
    { "--fov", 1, CLI_ONLY(CMD_VOLGI) | CLI_ONLY(CMD_MESHAO) }, { "--size", 1, CLI_ONLY(CMD_VOLGI) | CLI_ONLY(CMD_VISFIELD) | CLI_ONLY(CMD_MESHAO) },               \
    { "--transfer", 1, CLI_ONLY(CMD_VOLGI) }, { "--paths", 1, CLI_ONLY(CMD_VOLGI) },         \
    { "--reflection", 1, CLI_ONLY(CMD_VOLGI) }, { "--reflectance", 1, CLI_ONLY(CMD_VOLGI) }


#define CLI_VF_HELP                                                                                  \
    "usage: hfvis visfield MESH.obj -o FIELD.hfvf [--positions K] [--dirs D] [--format F]\n"        \
    "                      [--mapping M]\n"                                                          \
    "       hfvis visfield --ao FIELD.hfvf -o OUT [--ground Z] [--extent E] [--size WxH] [--rays S]\n" \
    "                      [--max-distance L] [--bias B] [--reference MESH.obj]\n"                  \
    "Pre-computed 4D visibility fields ([G12] ch. 4): for K sample points on the mesh's bounding\n" \
    "sphere and D x D directions over the inward hemisphere at each, the distance to the mesh\n"    \
    "(Alg. 1). A ray that meets the sphere then finds its hit distance by one table lookup.\n"     \
    "Build mode writes the field (the .hfvf format documented in hfvis.h); K*D*D rays are cast\n"   \
    "(4226 x 32 x 32 = 4.3 M rays; about 1 us each on a 100k-triangle mesh).\n"                     \
    "  --positions K     positional samples, a count 2(2n^2+2n+1): 10, 26, 50, 82, 122, ..., 290,\n" \
    "                    1090, 4226 (default, the thesis' recommendation), 16642, ...\n"            \
    "  --dirs D          directional samples per side, 1..4096 (default 32)\n"                      \
    "  --format F        u8 (default: 1 byte per direction), f32 (float), bit (hit/miss and one\n"  \
    "                    average distance), normal (RGBA8: normal + 8-bit distance)\n"              \
    "  --mapping M       concentric (default, Shirley-Chiu + Malley), polar or rejection\n"         \
    "--ao reads FIELD and writes the ambient obscurance (0 open .. 1 blocked, cosine-weighted,\n"   \
    "[G12] Alg. 2) of the ground plane z = Z under the object, seen from above: a W x H image of\n" \
    "the rectangle of half-width E (half-height E H/W) around the sphere's centre, row 0 = +y.\n"   \
    "  --ground Z        height of the ground plane in the field's object space (default: the\n"   \
    "                    bottom of the bounding sphere, centre z - radius)\n"                       \
    "  --extent E        half-width of the rectangle, > 0 (default 1.5 x the sphere's radius)\n"    \
    "  --size WxH        image size in pixels (default 256x256)\n"                                  \
    "  --rays S          S x S concentric rays per pixel, 1..256 (default 16: 256 rays)\n"          \
    "  --max-distance L  rays blocked farther than L do not count (default: unlimited)\n"          \
    "  --bias B          inside-query bias as a fraction of the radius, >= 0 (default 0.02)\n"     \
    "  --reference M     ray-cast M (the mesh the field was built from) with the same rays instead\n" \
    "                    (the oracle: compare the two images)\n"                                    \
    "OUT is .pgm (16-bit, default range 0:1) or .pfm.\n"

#define CLI_VF_FLAGS                                                                              \
    { "--positions", 1, CLI_ONLY(CMD_VISFIELD) }, { "--format", 1, CLI_ONLY(CMD_VISFIELD) },      \
    { "--mapping", 1, CLI_ONLY(CMD_VISFIELD) }, { "--ao", 0, CLI_ONLY(CMD_VISFIELD) },            \
    { "--ground", 1, CLI_ONLY(CMD_VISFIELD) }, { "--extent", 1, CLI_ONLY(CMD_VISFIELD) },         \
    { "--rays", 1, CLI_ONLY(CMD_VISFIELD) | CLI_ONLY(CMD_MESHAO) },                                                      \
    { "--bias", 1, CLI_ONLY(CMD_VISFIELD) }, { "--reference", 1, CLI_ONLY(CMD_VISFIELD) }


#define CLI_LK_HELP                                                                                  \
    "usage: hfvis meshao MESH.obj -o OUT [--method raster|bvh|raycast] [--rays N] [--radius R]\n"  \
    "         [--pattern torus|lloyd|random] [--falloff constant|linear|quadratic] [--eye X,Y,Z] [--target X,Y,Z] [--up X,Y,Z]\n"  \
    "         [--fov DEG] [--size WxH] [--two-sided] [--lut T] [--seed S] [--no-jitter] [--stats]\n" \
    "Ray-cast ambient obscurance of a triangle mesh seen by a pinhole camera, with the bit masks of\n" \
    "Laine & Karras 2010: each visible point (pixel) casts N cosine-distributed shadow rays of\n"   \
    "length up to R; W = blocked rays / N (0 open .. 1 blocked). All N rays of a point are decided\n" \
    "together: each nearby triangle sets the bits of the rays it blocks (three edge planes and its\n" \
    "own plane). The three methods give the same image bit for bit:\n"                              \
    "  --method M        bvh (default): BVH traversal per point with node masks (Method 2);\n"      \
    "                    raster: each triangle's region of influence projected over the pixels\n"   \
    "                    (Method 1); raycast: every ray through the BVH (the reference)\n"          \
    "  --rays N          rays per point, 1..4096 (default 128)\n"                                  \
    "  --pattern P       how the N directions are placed (one set, turned per point): torus\n"     \
    "                    (default: Lloyd-relaxed points of the periodic square mapped onto the\n"  \
    "                    disc, uniform up to the horizon), lloyd (Lloyd-relaxed on the disc as in\n" \
    "                    the paper: too few grazing rays, obscurance biased low, e.g. -16 % for\n"   \
    "                    the bunny at N = 1024) or random (independent points: unbiased, noisier)\n" \
    "  --radius R        longest ray, > 0 (default 0.1 x the mesh's bounding-box diagonal)\n"      \
    "  --falloff F       constant (default: every ray has length R), linear (rho = 1 - d/R) or\n"   \
    "                    quadratic (rho = (1 - d/R)^2): ray lengths distributed by the falloff\n"   \
    "  --eye X,Y,Z       camera position (default: in front of the bounding box, from -y, above)\n" \
    "  --target X,Y,Z    point looked at (default: the bounding-box centre)\n"                     \
    "  --up X,Y,Z        up direction (default 0,0,1; 0,1,0 when looking along z)\n"              \
    "  --fov DEG         vertical field of view, 1..179 (default 45)\n"                            \
    "  --size WxH        image size in pixels, 1..32768 each, at most 2^26 pixels\n"              \
    "                    (default 512x384)\n"                                                     \
    "  --two-sided       every triangle occludes from both sides (default: only from the side its\n" \
    "                    normal, counter-clockwise winding, points to)\n"                         \
    "  --lut T           plane look-up table masks of T^3 nodes, 2..1024 (faster for many rays;\n"  \
    "                    approximate: rays within about one node of a plane may flip)\n"          \
    "  --seed S          seed of the ray pattern and the per-pixel jitter, 0..2^53 (default 0)\n"  \
    "  --no-jitter       no per-pixel rotation of the pattern (banding on flat areas)\n"          \
    "  --stats           print the counts of the run (receivers, rays, culling) to stdout, before\n"   \
    "                    OUT is written (if the print fails, OUT is left untouched)\n"       \
    "OUT is .pgm (16-bit, range 0:1; pixels without geometry 0) or .pfm (NaN there).\n"

#define CLI_HILLSHADE_HELP                                                                           \
    "usage: hfvis hillshade IN -o OUT [--sun-azimuth A] [--sun-elevation E] [--sun-radius R]\n"    \
    "         [--blend N] [--no-shadows] [options]\n"                                              \
    "Shaded relief with cast shadows: H = (1/N) sum_j max(n . l_j, 0) V_j, n the grid normal, l_j\n" \
    "the direction of sun j and V_j its visibility from the exact sweep toward it (0 in shadow,\n" \
    "1 lit; with --sun-radius the visible fraction of the sun disc: soft shadows). In [0, 1];\n"   \
    "without shadows it is the classic hillshade cos(zenith) cos(slope) + sin(zenith) sin(slope)\n" \
    "cos(azimuth - aspect) (gdaldem hillshade / 255). NaN at holes. Default PGM range 0:1.\n"     \
    "  --sun-azimuth A   azimuth of the sun in the --convention (default 315: north-west)\n"       \
    "  --sun-elevation E elevation of the sun, -90..90 (default 45)\n"                            \
    "  --sun-radius R    angular radius of the sun disc, 0..90 (default 0; the real sun 0.27)\n"  \
    "  --blend N         multi-directional: N suns at A + 360 j/N, averaged (default 1)\n"         \
    "  --no-shadows      V_j = 1: the local hillshade only\n"

#define CLI_OPENNESS_HELP                                                                            \
    "usage: hfvis openness IN -o OUT [--radius R] [--negative] [--dirs K] [--degrees] [options]\n" \
    "Topographic openness (Yokoyama, Shirasawa & Pike 2002): the mean over K directions of the\n"  \
    "zenith angle pi/2 - beta_k, beta_k the largest elevation angle of the terrain within the\n"   \
    "horizontal distance R (positive openness); --negative: the mean nadir angle pi/2 + delta_k,\n" \
    "delta_k the smallest elevation angle within R (the positive openness of -z). pi/2 on a plane,\n" \
    "larger on summits (positive) and in pits (negative). A direction that meets no terrain (the\n" \
    "open border) counts beta = -pi/2: use --border clamp to extend the edges. NaN at holes.\n"    \
    "  --radius R        search distance in height units (--cell applies), >= 0 (default 0 =\n"   \
    "                    unlimited: the exact sweep, O(K W H)); R > 0: a bilinear ray march in\n"  \
    "                    1-cell steps, O(K W H R/cell) (RVT's and SAGA's radius); hfvis_openness\n" \
    "  --negative        negative openness\n"                                                      \
    "  --dirs K          directions (default 8, the paper's)\n"                                     \
    "  --degrees         output in degrees (default radians)\n"                                     \
    "Default PGM range 0:pi (0:180 with --degrees).\n"

#define CLI_SUM_HELP                                                                                 \
    "usage: hfvis sum PART.hfvs... -o OUT [--range LO:HI] [--quiet]\n"                              \
    "Add up the partial results of one run split with --dir-range (horizon, skyview, sky, light,\n" \
    "visibility) and write the file the single run writes (PFM, or PGM with its default range).\n" \
    "A part holds the raw per-direction sums of its range in double precision (the horizon: its\n"  \
    "planes) and the command, the input's fingerprint and every parameter; the parts are added in\n" \
    "direction order and finished once (e.g. SVF = 1 - S/K). The output equals the single run's\n"   \
    "bit for bit, except that a value within about K*2^-53 of a float rounding boundary may differ\n" \
    "by one ulp. Refused, with nothing written: parts of different commands, inputs, grids or\n"   \
    "parameters, overlapping ranges, and directions that no part holds.\n"                        \
    "  -o OUT            *.pfm or *.pgm, as for the command that made the parts\n"                 \
    "  --range LO:HI     .pgm only: the values mapped to codes 1 and 65535\n"                 \
    "  --overwrite       allow OUT to be one of the parts\n"

#define CLI_LK_FLAGS                                                                          \
    { "--falloff", 1, CLI_ONLY(CMD_MESHAO) }, { "--two-sided", 0, CLI_ONLY(CMD_MESHAO) },     \
    { "--lut", 1, CLI_ONLY(CMD_MESHAO) }, { "--seed", 1, CLI_ONLY(CMD_MESHAO) },              \
    { "--no-jitter", 0, CLI_ONLY(CMD_MESHAO) }, { "--pattern", 1, CLI_ONLY(CMD_MESHAO) }

typedef struct cli_args {
    int cmd;
    int has_dir_range, dir_begin, dir_end, out_partial; /* --dir-range A:B, -o *.hfvs */
    const char *in, *out, *env, *albedo_map, *emission;
    int out_pgm, out_raster, band, has_cell; /* -o *.tif/.asc/.bil/.flt; --band N (1-based) */
    double cell, zscale, azimuth0, nodata, range_lo, range_hi;
    double sky, albedo, sun_azimuth, sun_elevation, sun_radius, sun_irradiance;
    int dirs, border, border_cells, method, bounces, output;
    int compass, degrees, quiet, math, fraction, stats;
    int has_nodata, has_range, has_sun_azimuth, has_sun_elevation, has_sun_radius;
    int has_sun_irradiance, has_sky, has_albedo, has_bounces;
    double observer_x, observer_y, observer_height, target_height, max_distance;
    int has_observer, exact;
    int res, vox_mode, vox_axis, vox_method, max_vertices, open_mesh, out_binvox;
    double padding;
    /* GIS conventions, map coordinates, hillshade, openness, safety, progress (CLI_GIS_HELP) */
    int convention, has_convention, radians, has_azimuth0, has_azimuth, split, overwrite;
    int progress_lines, observer_grid, curvature, svf, blend, negative, no_shadows, ntargets;
    int has_geotransform, has_radius, has_refraction, has_earth_radius;
    double azimuth, refraction, earth_radius, radius, targets[2 * CLI_MAX_TARGETS];
    double geotransform[6]; /* GDAL order; set by a georeferenced input (else cli_georef's default) */
    int order, subsample, has_dirs, has_specular, has_shininess;
    double specular, shininess;
    int ssao_method, ssao_depth, ssao_has_ortho, ssao_has_near, ssao_has_far, ssao_guard;
    double ssao_fov, ssao_ortho, ssao_radius, ssao_near, ssao_far;
    int room, iterations, vg_nlights, vg_has_eye, vg_has_target, vg_width, vg_height, vg_transfer,
        vg_paths, vg_reflection, vg_rho_albedo, vg_has_rho;
    double vg_eye[3], vg_target[3], vg_up[3], vg_fov, vg_rho;
    hfvis_volgi_light vg_lights[CLI_VOLGI_MAX_LIGHTS];
    int vf_positions, vf_format, vf_mapping, vf_ao, vf_rays, vf_has_size;
    int vf_has_extent, vf_has_ground, vf_has_bias;
    double vf_extent, vf_ground, vf_bias;
    const char *vf_reference;
    int lk_method, lk_rays, lk_pattern, lk_falloff, lk_width, lk_height, lk_two_sided, lk_lut, lk_no_jitter,
        lk_has_eye, lk_has_target, lk_has_up, lk_has_radius;
    double lk_radius, lk_fov, lk_seed, lk_eye[3], lk_target[3], lk_up[3];
    double max_memory; /* --max-memory bytes, 0 = no limit (default: cli_default_max_memory) */
    int has_window, win_x, win_y, win_w, win_h; /* --window X0,Y0,W,H (cells; docs/tiles.md) */
} cli_args;

/* ssao --method, --depth */
enum { SSAO_LSAO, SSAO_HBAO, SSAO_FFAO, SSAO_RAYTRACE };
enum { SSAO_DEPTH_LINEAR, SSAO_DEPTH_GL, SSAO_DEPTH_D3D, SSAO_DEPTH_REVERSED };

#define CLI_GI_HELP                                                                                  \
    "usage: hfvis gi IN -o OUT [--dirs K] [--order O] [--subsample S] [--bounces B] [--albedo A]\n"  \
    "         [--specular S --shininess N] [--sun-azimuth DEG --sun-elevation DEG [--sun-radius DEG]\n" \
    "         [--sun-irradiance E]] [--sky C | --env ENV.pfm] [--output total|direct|indirect]\n"    \
    "Direct light and interreflections with the multi-resolution method of Nowrouzezahrai &\n"     \
    "Snyder 2009: per receiver, K azimuthal slices are scanned over a height pyramid with steps\n"  \
    "growing by 2^(1/4); each slice's visibility and indirect light become Legendre vectors and\n"  \
    "order-O spherical harmonics, shaded with the pixel's own normal. An approximation of\n"        \
    "'indirect' (soft: order-4 SH), faster with --subsample 2 or 4. Lambertian radiance: an open\n" \
    "flat receiver under a sky C with albedo A returns A*C. Default: sky 1, albedo 1, one bounce.\n" \
    "  --dirs K              azimuthal slices, 1..4096 (default 32, the paper's)\n"                  \
    "  --order O             SH order 1..4 (default 4)\n"                                             \
    "  --subsample S         visibility and bounces per S x S block, 1..64 (default 1; 2 is the\n"   \
    "                        paper's recommended trade-off)\n"                                        \
    "  --bounces B           interreflection bounces, 0..1000 (default 1)\n"                          \
    "  --albedo A            diffuse albedo, >= 0 (default 1)\n"                                      \
    "  --specular S          Phong specular weight, >= 0 (default 0), seen from straight above\n"     \
    "  --shininess N         Phong exponent, > 0 (default 32; with --specular)\n"                     \
    "  --sun-azimuth DEG     the sun's azimuth: the --convention's, compass by default\n"              \
    "  --sun-elevation DEG   sun elevation above the horizontal, -90..90 (with --sun-azimuth)\n"      \
    "  --sun-radius DEG      0 (default): a directional sun, hard shadows; 0..90: a key light\n"      \
    "                        (a disc with soft SH shadows from its own restricted visibility)\n"      \
    "  --sun-irradiance E    irradiance on a surface facing the sun, >= 0 (default pi)\n"             \
    "  --sky C               uniform sky radiance, >= 0 (default 1; 0 for the sun alone)\n"           \
    "  --env ENV.pfm         lat-long environment instead of the uniform sky (see 'light')\n"         \
    "  --output WHAT         total: direct + all bounces (default); direct: no bounce (--bounces\n"   \
    "                        not allowed); indirect: the bounces only (needs B >= 1)\n"               \
    "--azimuth0 and --compass place the slices, --border applies to the slices and the pyramid.\n"  \
    "OUT has the environment's channels (1 for --sky). NaN at holes. Default PGM range 0:the\n"     \
    "largest output value.\n"

#define CLI_GI_FLAGS                                                                         \
    { "--order", 1, CLI_ONLY(CMD_GI) }, { "--subsample", 1, CLI_ONLY(CMD_GI) },              \
    { "--specular", 1, CLI_ONLY(CMD_GI) }, { "--shininess", 1, CLI_ONLY(CMD_GI) }


/* ------------------------------------------------------------------------------------------ */
/* help                                                                                       */
/* ------------------------------------------------------------------------------------------ */

static const char cli_usage[] =
    "usage: hfvis COMMAND IN [options] -o OUT\n"
    "       hfvis COMMAND --help\n"
    "\n"
    "Visibility and light on height fields with the line-sweep horizon algorithm of\n"
    "Timonen & Westerholm 2010. IN is a height field: PGM (P2/P5, 8 or 16 bit, raw values),\n"
    "grey PFM (Pf), GeoTIFF (.tif), ESRI ASCII grid (.asc) or EHdr raw grid (.bil/.flt).\n"
    "Row 0 is the north edge, x (columns) runs east, y (rows) south.\n"
    "\n"
    "commands:\n"
    "  horizon     horizon elevation angle toward K directions (K planes in one image)\n"
    "  skyview     sky-view factor 1 - (1/K) sum_k sin(max(alpha_k, 0)), in [0, 1]\n"
    "  sky         uniform-sky light, [P1] Eq. 5 (cosine-weighted and slope-aware)\n"
    "  shadow      sun visibility in [0, 1] from one exact sweep toward the sun\n"
    "  light       environment light from a lat-long PFM map\n"
    "  normals     unit surface normals (x east, y south, z up) as a 3-channel PFM\n"
    "  indirect    sun and sky light with interreflections between terrain points ([P2])\n"
    "  gi          multi-resolution GI (Nowrouzezahrai & Snyder): sky, sun, bounces, gloss\n"
    "  visibility  visibility index: the grid samples each point sees along K directions\n"
    "  viewshed    which samples an observer at one point sees (line of sight)\n"
    "  hillshade   shaded relief with cast shadows from the exact sweep, one or more suns\n"
    "  openness    positive or negative topographic openness (Yokoyama et al. 2002)\n"
    "  voxelize    voxels of an OBJ mesh: surface, conservative or solid (.binvox or .raw)\n"
    "  volgi       direct + indirect light of an OBJ mesh or the test room ([G12] ch. 5)\n"
    "  visfield    4D visibility field of an OBJ mesh (.hfvf), or AO images from one\n"
    "  meshao      ray-cast ambient obscurance of an OBJ mesh (Laine & Karras bit masks)\n"
    "  ssao        screen-space obscurance of a depth buffer: LSAO, HBAO, FFAO, ray traced\n"
    "  sum         add up the partial results of --dir-range runs into the single run's OUT\n"
    "  mosaic      assemble the pieces of --window runs into the whole run's OUT\n"
    "  info        print a raster's width, height, bands, cell, CRS and NoData\n"
    "  azimuths    print the K azimuths a run uses, in degrees, in output-plane order\n";

static const char cli_shared_help[] =
    "\n"
    "shared options (every command accepts them and ignores those it does not use):\n"
    "  -o OUT            output file, required: *.pfm writes PFM floats, *.pgm a 16-bit PGM;\n"
    "                    a PGM of a 3-channel result stacks the channels as planes, top to bottom;\n"
    "                    PGM code 0 is NoData and LO..HI map to 1..65535, recorded in the header\n"
    "                    comment \"# hfvis range LO HI nodata 0\"\n"
    "                    *.tif a GeoTIFF (tiled, DEFLATE; Float32, or the smallest integer type\n"
    "                    for viewshed and visibility counts), *.asc an ESRI ASCII grid,\n"
    "                    *.bil/*.flt raw floats + .hdr: these carry IN's georeference and NoData\n"
    "                    (planes and channels become bands)\n"
    "  --band N          IN is a multi-band raster: use band N (1-based, default 1)\n"
    "  --range LO:HI     .pgm only: the values mapped to 0 and 65535 (default per command)\n"
    "  --cell S          distance between samples, in height units (default: the cell size of a\n"
    "                    georeferenced IN (.tif, .asc, .bil/.flt), else 1 with a note)\n"
    "  --zscale Z        multiply input values by Z, non-zero (default 1)\n"
    "  --nodata V        input values equal to V are holes: no occlusion, output NaN (PGM code 0)\n"
    "  --dirs K          number of azimuth directions, 1..65536 (default 16)\n"
    "  --convention C    how azimuths are read and directions ordered (height-field commands):\n"
    "                    compass (default): bearings clockwise from north, direction k at\n"
    "                    azimuth0 + 360k/K; grass: counter-clockwise from east (r.horizon,\n"
    "                    r.sun), direction k at azimuth0 + 360k/K counter-clockwise; grid: the\n"
    "                    library's psi, from east toward south (x toward y; the old --math)\n"
    "  --azimuth0 A      azimuth of direction 0 in the convention (default: compass 0 = north;\n"
    "                    grass and grid 0 = east). Degrees (before 0.2: radians); see --radians\n"
    "  --radians         angle flags (--azimuth0, --azimuth, --sun-*) in radians, not degrees\n"
    "  --compass         the same as --convention compass (the default)\n"
    "  --degrees         angle outputs in degrees instead of radians\n";
static const char cli_shared_help2[] =
    "  --dir-range A:B   horizon, skyview, sky, light, visibility: only the directions at\n"
    "                    positions A..B-1 of the K (0 <= A < B <= K) in sweep order (with K a\n"
    "                    multiple of 4, each 4 consecutive positions are the quarter turns\n"
    "                    k, k+K/4, k+K/2, k+3K/4 that share one lattice: give A and B as\n"
    "                    multiples of 4 and each part costs its share of the run); OUT (*.hfvs)\n"
    "                    is then a partial result, and 'hfvis sum' adds the parts of a split\n"
    "                    into the single run's OUT\n"
    "  --border MODE     open (nothing outside the grid, default), clamp (edge heights extend\n"
    "                    outward) or wrap (periodic field)\n"
    "  --border-cells N  clamp/wrap: lines start N cells outside the grid, 1..1048576\n"
    "                    (default max(width, height))\n"
    "  --exact           horizon, skyview, sky, light, shadow: exact rays (beyond [P1]): every\n"
    "                    sample gets its own ray along the nearest rational direction, no\n"
    "                    interpolation between lattice lines (right at walls, roofs, cliffs;\n"
    "                    'hfvis azimuths --exact' prints the directions used). visibility,\n"
    "                    indirect and gi keep the lattice\n"
    "  --max-distance R  horizon, skyview, sky, shadow, light, visibility, indirect, hillshade:\n"
    "                    the search radius in height units (--cell applies): occluders farther\n"
    "                    than R along the ray are ignored (GRASS maxdistance, SAGA and RVT radius,\n"
    "                    WhiteboxTools max_dist); 0 = unlimited (default). visibility and\n"
    "                    indirect: visible samples farther than R are not counted or gathered.\n"
    "                    viewshed: its range\n"
    "  --window X0,Y0,W,H  with a finite R (openness: --radius R; not visibility, indirect): only\n"
    "                    the W x H cells from\n"
    "                    column X0, row Y0 (clipped to IN), reading only them and a halo of\n"
    "                    ceil(R/cell) + 1 cells (GeoTIFF strips/tiles, .bil/.flt, PFM and binary\n"
    "                    PGM rows, by seeking); OUT (.pfm .tif .bil .flt .asc) is a piece, placed\n"
    "                    and georeferenced at the window, with its sidecar OUT.tile; 'hfvis\n"
    "                    mosaic' joins the pieces into the whole run's OUT (docs/tiles.md)\n"
    "  --quiet           no progress bar (shown on stderr only when it is a terminal) and no notes\n"
    "  --progress        plain progress lines on stderr instead (percent, elapsed, ETA), for logs\n"
    "                    and job schedulers, and a summary line at the end (time, cells,\n"
    "                    directions); runs over 10 s end with the summary anyway (not --quiet)\n"
    "  --overwrite       allow OUT to be one of the inputs (refused otherwise: same file,\n"
    "                    through hard and symbolic links too)\n"
    "  --max-memory B    refuse a run whose estimated memory exceeds B bytes (suffix K, M, G or\n"
    "                    T: powers of 1024; 0 = no limit); default half of the physical memory\n"
    "                    where the system reports it (sysconf), else no limit. The estimate and\n"
    "                    the work (lattice nodes swept, rays, voxel updates) are printed on\n"
    "                    stderr with the progress bar\n"
    "  -h, --help        this help; 'hfvis COMMAND --help' describes one command\n"
    "\n"
    "Options take their value as the next argument or as --option=value; an option given twice\n"
    "takes its last value (as most Unix tools; volgi's --light adds one light each time).\n"
    "OUT is written to a temporary file beside it and renamed onto it: a symbolic link named\n"
    "OUT is replaced by the file (write to the link's target to keep the link); an interrupt\n"
    "(SIGINT, SIGTERM, SIGHUP) removes the temporary file.\n"
    "Exit status: 0 = OUT is complete, 1 = error, 2 = usage error; an error is one line\n"
    "\"hfvis: <what>: <why>\" on stderr, and OUT is then left untouched.\n";

static const char *const cli_cmd_help[CMD_COUNT] = {
    "usage: hfvis horizon IN -o OUT [options]\n"
    "The horizon elevation angle alpha in [-pi/2, pi/2] toward each direction psi_k: the largest\n"
    "elevation under which the sample sees terrain that way; -pi/2 where it sees none (open\n"
    "border). OUT holds the K planes stacked top to bottom: plane k is rows k*H .. k*H+H-1 of a\n"
    "W x (K*H) image. K*W*H may not exceed 2^28 values (1 GiB) and K*H not 1048576 rows; for\n"
    "larger inputs use skyview, sky or light, which keep no horizon map.\n"
    "  --degrees         alpha in degrees\n"
    "  --azimuth A       one direction only, toward azimuth A (the convention's, degrees unless\n"
    "                    --radians): the same as --dirs 1 --azimuth0 A\n"
    "  --split           one file per direction instead of the stack (as r.horizon writes one\n"
    "                    map per direction), named OUT's stem + \"_\" + the direction's azimuth in\n"
    "                    the convention in degrees: hor.pfm -> hor_000.pfm, hor_022_500.pfm (22.5)\n"
    "Planes follow the convention: compass clockwise from azimuth0 (north by default), grass\n"
    "counter-clockwise from azimuth0 (east by default), grid clockwise from east.\n"
    "Default PGM range -1.5707963:1.5707963 (-90:90 with --degrees).\n",

    "usage: hfvis skyview IN -o OUT [--svf zaksek|saga|visible] [options]\n"
    "The sky-view factor SVF = 1 - (1/K) sum_k sin(max(alpha_k, 0)) (Zaksek et al. 2011, as RVT\n"
    "and GRASS r.skyview): 1 on open flat ground, lower in valleys. Default PGM range 0:1.\n"
    "  --svf D           zaksek (default, above; the fused sweep); saga: SAGA's \"Sky View\n"
    "                    Factor\", the cosine-weighted sky of the tilted receiver,\n"
    "                    (1/K) sum_k [n_z cos^2 phi_k + (n_x cos psi_k + n_y sin psi_k)\n"
    "                    (pi/2 - phi_k - sin phi_k cos phi_k)], phi_k = max(alpha_k, 0), n the grid\n"
    "                    normal: 1 - (1/K) sum sin^2 phi_k on level ground; visible: SAGA's\n"
    "                    \"Visible Sky\" (1/K) sum (1 - phi_k/(pi/2)) as a fraction (SAGA: percent).\n"
    "                    saga and visible sweep one direction at a time (no --dir-range)\n",

    "usage: hfvis sky IN -o OUT [--sky C] [--albedo A] [options]\n"
    "Light reflected under a uniform sky of radiance C, [P1] Eq. 5: cosine-weighted and aware\n"
    "of the surface slope; an open flat receiver returns A*C (Lambertian, albedo A).\n"
    "  --sky C           sky radiance, >= 0 (default 1)\n"
    "  --albedo A        surface albedo, >= 0 (default 1)\n"
    "Default PGM range 0:A*C (0:1 if A*C is 0).\n",

    "usage: hfvis shadow IN --sun-azimuth DEG --sun-elevation DEG [--sun-radius DEG] -o OUT\n"
    "Sun visibility in [0, 1] from one exact sweep toward the sun: 1 lit, 0 in shadow. The\n"
    "receiver's own tangent plane is not applied; multiply by max(n.l, 0) for shading.\n"
    "  --sun-azimuth DEG     the sun's azimuth: the --convention's, compass by default (required)\n"
    "  --sun-elevation DEG   sun elevation above the horizontal, -90..90 (required)\n"
    "  --sun-radius DEG      angular radius of the sun disc, 0..90 (default 0: hard shadow);\n"
    "                        > 0 gives the visible fraction of the disc (the real sun: 0.27)\n"
    "Default PGM range 0:1.\n",

    "usage: hfvis light IN --env ENV.pfm -o OUT [--albedo A] [--method prefix|lp] [options]\n"
    "Light reflected from a lat-long environment map ([P1] §6.2), Lambertian with albedo A.\n"
    "ENV (PF colour or Pf grey; any image the codecs read) covers the whole sphere: row 0 is\n"
    "the zenith, the last row the nadir; column p is the azimuth band [2 pi p/n, 2 pi (p+1)/n)\n"
    "measured like psi, from east toward south (--compass does not change it). OUT has the\n"
    "channels of ENV (PF or Pf).\n"
    "  --env ENV.pfm     the environment map (required)\n"
    "  --albedo A        surface albedo, >= 0 (default 1)\n"
    "  --method M        prefix (exact prefix integrals, default) or lp (the paper's L_p table)\n"
    "Default PGM range 0:the largest output value.\n",

    "usage: hfvis normals IN -o OUT [options]\n"
    "Unit surface normals ([P1] §7: sum of the four quad normals around a sample), 3 channels\n"
    "(x east, y south, z up); NaN at holes. Uses --cell, --zscale and --nodata only.\n"
    "Default PGM range -1:1 (the x, y and z planes stacked top to bottom).\n",

    "usage: hfvis indirect IN -o OUT [--albedo A | --albedo-map MAP] [--bounces B]\n"
    "         [--sun-azimuth DEG --sun-elevation DEG [--sun-radius DEG] [--sun-irradiance E]]\n"
    "         [--sky C | --env ENV.pfm] [--emission EMIT] [--output total|direct|indirect]\n"
    "Light with interreflections between terrain points ([P2] §10.1). The direct light D (sun\n"
    "and uniform sky or environment, [P1]; reflected radiance for albedo 1) gives the exit\n"
    "radiance L_0 = EMIT + A*D, and each bounce gathers the light of the terrain samples every\n"
    "point sees along the K directions (hull-tree intervisibility, [P2] §5-8):\n"
    "L_(b+1) = EMIT + A*(D + I[L_b]). Lambertian radiance: an open flat receiver under a sky C\n"
    "with albedo A returns A*C. Default: no sun, sky 1, albedo 1, one bounce.\n"
    "  --albedo A            constant albedo, >= 0 (default 1)\n"
    "  --albedo-map MAP      per-sample albedo, a map of IN's size (instead of --albedo)\n"
    "  --bounces B           interreflection bounces, 0..1000 (default 1); one sweep each\n"
    "  --sun-azimuth DEG     the sun's azimuth: the --convention's, compass by default\n"
    "  --sun-elevation DEG   sun elevation above the horizontal, -90..90 (with --sun-azimuth)\n"
    "  --sun-radius DEG      angular radius of the sun disc, 0..90 (default 0: hard shadows)\n"
    "  --sun-irradiance E    irradiance on a surface facing the sun, >= 0 (default pi: a flat\n"
    "                        receiver under a zenith sun reflects E/pi = 1 with albedo 1)\n"
    "  --sky C               uniform sky radiance, >= 0 (default 1; 0 for the sun alone)\n"
    "  --env ENV.pfm         lat-long environment instead of the uniform sky (see 'light')\n"
    "  --emission EMIT       emitted radiance per sample, a map of IN's size (default 0)\n"
    "  --output WHAT         total: L_B, the exit radiance after B bounces (default);\n"
    "                        direct: L_0 = EMIT + A*D, no bounce (--bounces not allowed);\n"
    "                        indirect: L_B - L_0, the light that came from other terrain\n"
    "                        (needs B >= 1)\n"
    "Maps (MAP, EMIT) are PGM or PFM images of IN's size: PGM values are divided by the file's\n"
    "maxval (0..1), PFM values are used as stored; they must be finite and >= 0 wherever IN\n"
    "has no hole. OUT has 3 channels (PF) if ENV, MAP or EMIT has 3, else 1 (Pf); a one-channel\n"
    "input then applies to all three. NaN at holes. Default PGM range 0:the largest output value.\n",

    "usage: hfvis visibility IN -o OUT [--fraction] [--stats] [options]\n"
    "The visibility index: the number of grid samples each point sees along its K lines, from\n"
    "the hull-tree intervisibility sweep ([P2] §5-8). A sample is seen when no sample between\n"
    "it and the point rises above the sight line (grazing counts); the point itself is not\n"
    "counted, nor samples outside the grid (also with --border clamp/wrap), nor holes. On a\n"
    "flat field with --dirs 1, column x of a W-wide row sees W-1-x samples. NaN at holes.\n"
    "  --fraction   divide by the samples the point could see: the same count on a flat field\n"
    "               with IN's holes, where every sample is seen; in [0, 1], 0 where the point's\n"
    "               lines hold no sample. Runs a second sweep in which every sample is visible,\n"
    "               O(K*W*H*N): 15 s at 1024 x 1024, K = 16 on one core\n"
    "  --stats      before writing OUT, print the sweep's counters to stdout as averages per\n"
    "               receiver-direction (lattice node and direction), as [P2] Tables 1-2:\n"
    "               visible samples, horizons m_a and tree iterations t_a; with --fraction also\n"
    "               the samples tested (the naive scan's iterations) and the ratios\n"
    "Default PGM range 0:the largest count (0:1 with --fraction).\n",

    "usage: hfvis viewshed IN --observer X,Y -o OUT [--observer-height H] [--target-height T]\n"
    "         [--max-distance D] [--exact]\n"
    "The viewshed of one observer: 1 where the observer's eye sees the target above a sample,\n"
    "0 where terrain hides it, NaN at holes and beyond --max-distance (0 in PGM). The terrain\n"
    "is the bilinear surface through the samples; a sight line that grazes it counts as\n"
    "visible. Method: R2 of Franklin & Ray 1994 (rays to every border sample, running maximum\n"
    "slope), O((W + H) * max(W, H)): 2(W + H) rays of up to max(W, H) steps (a 1 x 1048576 grid\n"
    "takes hours); it differs from the exact line of sight (--exact) only at samples whose\n"
    "sight line nearly grazes the terrain: measured from 8 observers (summit, valley, slope, 5\n"
    "random) on a 512 x 512 SRTM tile and a 512 x 512 fBm, on 0.005-1.2 % of the samples (mean\n"
    "0.2-0.4 %); the most from a summit, which sees the most.\n"
    "  --observer X,Y        the observer in map coordinates (required, or --observer-grid):\n"
    "                        sample (column c, row r) is at X = c*cell, Y = r*cell (cell centres;\n"
    "                        a georeferenced input uses its geotransform); it must stand on data\n"
    "  --observer-grid C,R   the observer's column and row instead, reals in [0, W-1] x [0, H-1]\n"
    "  --target X,Y          a point of interest (map coordinates, up to 64): prints\n"
    "                        \"target X,Y (column c, row r): visible|hidden|...\" for its nearest sample\n"
    "  --curvature           Earth curvature and refraction as GRASS r.viewshed -c -r: each target\n"
    "                        is lowered by (1 - k) d^2/(2 R), d its horizontal distance (heights and\n"
    "                        --cell in metres)\n"
    "  --refraction K        refraction coefficient k, -1..1 (default 0.13; 0: curvature only)\n"
    "  --earth-radius R      R in metres (default 6371000, the mean radius)\n"
    "  --observer-height H   eye height above the surface, height units, >= 0 (default 0)\n"
    "  --target-height T     target height above each sample, >= 0 (default 0)\n"
    "  --max-distance D      horizontal range in height units (--cell applies), >= 0;\n"
    "                        0 = unlimited (default)\n"
    "  --exact               the exact line-of-sight oracle instead (half-cell march per\n"
    "                        sample): O(W*H*max(W, H)), 4 s at 1024 x 1024\n"
    "--dirs, --azimuth0, --compass, --degrees and --border do not apply. Default PGM range 0:1.\n",

    "usage: hfvis voxelize MESH.obj --res N [--mode surface|conservative|solid] [--axis A]\n"
    "         [--method pixel|slicing|clipping] [--max-vertices V] [--padding F] [--open]\n"
    "         -o OUT.binvox|OUT.raw\n"
    "Voxels of a triangle mesh (Wavefront OBJ: v and f lines, polygons fanned). The grid has\n"
    "cubic voxels, N of them along the longest side of the mesh's bounding box (enlarged by F\n"
    "times that side on every side), the other sides rounded up and centred.\n"
    "  --res N           voxels along the longest side, 1..2048 (required)\n"
    "  --mode M          surface (default): the voxels that hold a pixel-centre sample of a\n"
    "                    triangle in the sweep along its dominant axis ([G12] ch. 6, 6-separating\n"
    "                    with --axis all); conservative: every voxel a triangle touches (exact\n"
    "                    triangle-box overlap); solid: the voxels whose centre is inside the\n"
    "                    mesh, by ray parity (the mesh must be closed unless --open: the\n"     \
    "                    parity of every column along x, y and z is checked, whatever --axis)\n"
    "  --axis A          surface: dominant (default), all (three sweeps merged, [G12] Alg. 4) or\n"
    "                    x, y, z (one sweep); solid: the parity ray direction x, y or z (default z)\n"
    "  --method M        surface: pixel (the pixel-centre rule, default), slicing (geometry-shader\n"
    "                    triangle slicing, [G12] Alg. 5) or clipping (fragment clipping, Alg. 6)\n"
    "  --max-vertices V  slicing/clipping: the geometry shader's output-vertex limit; triangles\n"
    "                    spanning more slabs than it allows leave holes, as in the thesis\n"
    "                    (slicing V >= 7, clipping V >= 3; default unlimited)\n"
    "  --padding F       empty margin around the mesh, a fraction of its longest side, 0..1\n"
    "                    (default 0)\n"
    "  --open            solid: leave columns that cross an open mesh an odd number of times\n"
    "                    empty instead of failing\n"
    "OUT: *.binvox (the binvox format of viewvox/binvox: a cube of the largest side, run-length\n"
    "coded, translate and scale of the grid) or *.raw (one byte per voxel, 0 or 1, x fastest,\n"
    "then y, then z; the dimensions are printed). Prints the grid and the voxel count unless\n"
    "--quiet. Only -o and --quiet of the shared options apply.\n",

    CLI_GI_HELP,

    "usage: hfvis ssao DEPTH.pfm -o OUT [--method lsao|hbao|ffao|raytrace] [--fov-y DEG]\n"
    "         [--ortho SCALE] [--radius R] [--dirs K] [--guard PIXELS]\n"
    "         [--depth linear|gl|d3d|reversed --near N --far F]\n"
    "Screen-space ambient obscurance of a depth buffer (one-channel PFM or PGM, row 0 at the\n"
    "top). OUT is obscurance in [0, 1] (0 = open) of the inner pixels: the buffer minus the\n"
    "guard band on every side.\n"
    "  --method M        lsao: line-sweep AO ([P3]); hbao: horizon-based ray march, out to\n"
    "                    a sixteenth of the image height; ffao: far-field AO ([P4], default);\n"
    "                    raytrace: the screen-space ray-traced reference (256 rays per\n"
    "                    pixel, slow)\n"
    "  --fov-y DEG       vertical field of view of the inner image, 0..180 (default 60)\n"
    "  --ortho SCALE     orthographic camera instead, SCALE view units per pixel\n"
    "  --radius R        falloff rho = R^2/(R^2 + d^2) (view units); default none (rho = 1)\n"
    "  --dirs K          directions (default: lsao 16, hbao 16, ffao 8 x 2 segments; raytrace\n"
    "                    ignores it)\n"
    "  --guard PIXELS    guard band per side (default 10 % of the width and height)\n"
    "  --depth ENC       linear view depth (default), gl or d3d window depth, reversed Z; the\n"
    "                    hardware encodings need --near and --far\n"
    "Only -o, --dirs and --quiet of the shared options apply. Default PGM range 0:1.\n",

    CLI_VOLGI_HELP,

    CLI_VF_HELP,

    CLI_LK_HELP,

    CLI_HILLSHADE_HELP,

    CLI_OPENNESS_HELP,

    CLI_SUM_HELP
};

/* ------------------------------------------------------------------------------------------ */
/* errors and progress                                                                        */
/* ------------------------------------------------------------------------------------------ */

static int cli_bar_open; /* a progress line is on stderr without its newline yet */

/* Print the one error line "hfvis: <what>: <why>" and return code. */
static int cli_error(int code, const char *what, const char *fmt, ...)
{
    char why[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(why, sizeof why, fmt, ap);
    va_end(ap);
    if (cli_bar_open) { fputc('\n', stderr); cli_bar_open = 0; }
    ex_error(what, why);
    return code;
}

/* A failed library call; for I/O errors the C library's reason is added when there is one. */
static int cli_status(const char *what, hfvis_status s, int saved_errno)
{
    if (s == HFVIS_ERR_IO && saved_errno != 0)
        return cli_error(CLI_EXIT_ERROR, what, "%s (%s)", hfvis_status_string(s),
                         strerror(saved_errno));
    return cli_error(CLI_EXIT_ERROR, what, "%s", hfvis_status_string(s));
}

/* One progress bar over several library calls: each call reports its own done/total, the bar
 * shows base + done out of the run's total (its units are directions; 0 = each call's total). */
typedef struct cli_progress_state {
    const char *label;
    long long base;   /* units finished by the calls before the current one */
    long long total;  /* units of the whole run */
} cli_progress_state;

/* One library report (done of total) as the run's units now of all; the base moves on when a
 * call completes. */
static void cli_progress_advance(cli_progress_state *p, int done, int total, long long *now,
                                 long long *all)
{
    *all = p->total > 0 ? p->total : total;
    *now = p->total > 0 ? p->base + done : done;
    if (*now > *all) *now = *all;
    if (done >= total) p->base += total;
}

/* hfvis_progress_fn: "\r<command> [#####.....] done/total" on stderr. */
static void cli_progress(void *user, int done, int total)
{
    enum { BAR = 32 };
    cli_progress_state *p = (cli_progress_state *)user;
    long long all, now;
    char bar[BAR + 1];
    int i, fill;
    cli_progress_advance(p, done, total, &now, &all);
    fill = all > 0 ? (int)(now * BAR / all) : BAR;
    for (i = 0; i < BAR; i++) bar[i] = i < fill ? '#' : '.';
    bar[BAR] = '\0';
    fprintf(stderr, "\r%s [%s] %lld/%lld", p->label, bar, now, all);
    cli_bar_open = now < all;
    if (!cli_bar_open) fputc('\n', stderr);
    fflush(stderr);
}

/* --max-memory's default: half of the physical memory where sysconf reports it, else 0 (none). */
static double cli_default_max_memory(void)
{
#if defined(CLI_HAVE_SIGACTION) && defined(_SC_PHYS_PAGES) && defined(_SC_PAGESIZE)
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    if (pages > 0 && page > 0) return 0.5 * (double)pages * (double)page;
#endif
    return 0.0;
}

static int cli_stderr_is_terminal(void)
{
#ifdef CLI_HAVE_ISATTY
    return isatty(STDERR_FILENO);
#else
    return 0;
#endif
}

/* ------------------------------------------------------------------------------------------ */
/* argument parsing                                                                           */
/* ------------------------------------------------------------------------------------------ */

/* A finite number with nothing else in s (no leading space, no trailing characters). */
static int cli_parse_real(const char *s, double *out)
{
    char *end;
    double v;
    if (s[0] == '\0' || isspace((unsigned char)s[0])) return 0;
    errno = 0;
    v = strtod(s, &end);
    if (*end != '\0' || !isfinite(v)) return 0;
    *out = v;
    return 1;
}

/* flag's value as a real in [lo, hi] (lo excluded when lo_open); "expect" words the rule. */
static int cli_real(const char *flag, const char *s, double lo, int lo_open, double hi,
                    const char *expect, double *out)
{
    double v;
    if (!cli_parse_real(s, &v) || v < lo || (lo_open && v == lo) || v > hi)
        return cli_error(CLI_EXIT_USAGE, flag, "expected %s, got '%s'", expect, s);
    *out = v;
    return 0;
}

static int cli_int(const char *flag, const char *s, long lo, long hi, const char *expect, int *out)
{
    char *end;
    long v;
    if (s[0] == '\0' || isspace((unsigned char)s[0]))
        return cli_error(CLI_EXIT_USAGE, flag, "expected %s, got '%s'", expect, s);
    errno = 0;
    v = strtol(s, &end, 10);
    if (*end != '\0' || errno == ERANGE || v < lo || v > hi)
        return cli_error(CLI_EXIT_USAGE, flag, "expected %s, got '%s'", expect, s);
    *out = (int)v;
    return 0;
}

/* Case-insensitive "does s end in ext". */
static int cli_ends_with(const char *s, const char *ext)
{
    size_t n = strlen(s), m = strlen(ext), i;
    if (n <= m) return 0;
    for (i = 0; i < m; i++)
        if (tolower((unsigned char)s[n - m + i]) != tolower((unsigned char)ext[i])) return 0;
    return 1;
}

/* The flags only `ssao` has, and its --method; -1 if f is none of them. */
static int cli_set_ssao(cli_args *a, const char *f, const char *v)
{
    if (!strcmp(f, "--method") || !strcmp(f, "--depth")) {
        static const char *const methods[] = {"lsao", "hbao", "ffao", "raytrace"};
        static const char *const encodings[] = {"linear", "gl", "d3d", "reversed"};
        int is_method = !strcmp(f, "--method"), i;
        for (i = 0; i < 4; i++)
            if (!strcmp(v, is_method ? methods[i] : encodings[i])) {
                *(is_method ? &a->ssao_method : &a->ssao_depth) = i;
                return 0;
            }
        return cli_error(CLI_EXIT_USAGE, f, is_method ? "expected lsao, hbao, ffao or raytrace, "
                         "got '%s'" : "expected linear, gl, d3d or reversed, got '%s'", v);
    }
    if (!strcmp(f, "--fov-y")) return cli_real(f, v, 0.0, 1, 179.999, "degrees in (0, 180)", &a->ssao_fov);
    if (!strcmp(f, "--ortho")) {
        a->ssao_has_ortho = 1;
        return cli_real(f, v, 0.0, 1, CLI_FLT_MAX, "a scale > 0", &a->ssao_ortho);
    }
    if (!strcmp(f, "--radius")) return cli_real(f, v, 0.0, 1, CLI_FLT_MAX, "a radius > 0", &a->ssao_radius);
    if (!strcmp(f, "--guard")) return cli_int(f, v, 0, 65536, "an integer 0..65536", &a->ssao_guard);
    if (!strcmp(f, "--near")) {
        a->ssao_has_near = 1;
        return cli_real(f, v, -CLI_FLT_MAX, 0, CLI_FLT_MAX, "a finite distance", &a->ssao_near);
    }
    if (!strcmp(f, "--far")) {
        a->ssao_has_far = 1;
        return cli_real(f, v, -CLI_FLT_MAX, 0, CLI_FLT_MAX, "a finite distance", &a->ssao_far);
    }
    return -1;
}

/* The flags only `gi` has; -1 if f is none of them. */
static int cli_set_gi(cli_args *a, const char *f, const char *v)
{
    if (!strcmp(f, "--order")) return cli_int(f, v, 1, 4, "an integer 1..4", &a->order);
    if (!strcmp(f, "--subsample"))
        return cli_int(f, v, 1, HFVIS_NS_MAX_SUBSAMPLE, "an integer 1..64", &a->subsample);
    if (!strcmp(f, "--specular")) {
        a->has_specular = 1;
        return cli_real(f, v, 0.0, 0, CLI_FLT_MAX, "a weight >= 0", &a->specular);
    }
    if (!strcmp(f, "--shininess")) {
        a->has_shininess = 1;
        return cli_real(f, v, 0.0, 1, CLI_FLT_MAX, "an exponent > 0", &a->shininess);
    }
    return -1;
}

/* Combinations `gi` rejects; returns 0 or CLI_EXIT_USAGE (message printed). */
static int cli_check_gi(const cli_args *a)
{
    int sun = a->has_sun_azimuth || a->has_sun_elevation;
    if (a->has_sun_azimuth && !a->has_sun_elevation)
        return cli_error(CLI_EXIT_USAGE, "--sun-azimuth", "needs --sun-elevation DEG");
    if (a->has_sun_elevation && !a->has_sun_azimuth)
        return cli_error(CLI_EXIT_USAGE, "--sun-elevation", "needs --sun-azimuth DEG");
    if (!sun && (a->has_sun_radius || a->has_sun_irradiance || a->math))
        return cli_error(CLI_EXIT_USAGE, a->has_sun_radius ? "--sun-radius" :
                         a->has_sun_irradiance ? "--sun-irradiance" : "--math",
                         "needs a sun (--sun-azimuth and --sun-elevation)");
    if (a->has_shininess && !a->has_specular)
        return cli_error(CLI_EXIT_USAGE, "--shininess", "needs --specular S");
    if (a->has_sky && a->env)
        return cli_error(CLI_EXIT_USAGE, "--env", "cannot be combined with --sky");
    if (a->output == OUT_DIRECT && a->has_bounces)
        return cli_error(CLI_EXIT_USAGE, "--bounces", "has no effect with --output direct");
    if (a->output == OUT_INDIRECT && a->bounces < 1)
        return cli_error(CLI_EXIT_USAGE, "--output indirect", "needs --bounces >= 1");
    return 0;
}


/* meshao's defaults (called for every command; harmless for the others). */
static void cli_lk_defaults(cli_args *a)
{
    a->lk_method = HFVIS_LK_METHOD_BVH;
    a->lk_rays = 128;
    a->lk_falloff = HFVIS_LK_FALLOFF_CONSTANT;
    a->lk_width = 512;
    a->lk_height = 384;
    a->lk_fov = 45.0;
    a->lk_up[0] = 0.0; a->lk_up[1] = 0.0; a->lk_up[2] = 1.0;
}

/* "X,Y,Z" (--eye, --target, --up): three finite numbers; 0 or CLI_EXIT_USAGE (reported). */
static int cli_xyz(const char *f, const char *v, double out[3])
{
    char buf[256];
    const char *p = v;
    int k;
    for (k = 0; k < 3; k++) {
        const char *e = k < 2 ? strchr(p, ',') : p + strlen(p);
        size_t n = e ? (size_t)(e - p) : 0;
        if (!e || n == 0 || n >= sizeof buf) break;
        memcpy(buf, p, n);
        buf[n] = '\0';
        if (!cli_parse_real(buf, &out[k]) || fabs(out[k]) > CLI_FLT_MAX) break;
        p = e + 1;
    }
    if (k < 3) return cli_error(CLI_EXIT_USAGE, f, "expected X,Y,Z (three finite numbers), got '%s'", v);
    return 0;
}

/* "WxH" (--size): sides 1..HFVIS_RASTER_MAX_SIZE, at most 2^26 pixels; 0 or CLI_EXIT_USAGE. */
static int cli_size(const char *f, const char *v, int *width, int *height)
{
    char *end;
    long w, h;
    errno = 0;
    w = strtol(v, &end, 10);
    if (end == v || !isdigit((unsigned char)v[0]) || (*end != 'x' && *end != 'X') || w < 1
        || w > HFVIS_RASTER_MAX_SIZE)
        return cli_error(CLI_EXIT_USAGE, f, "expected WxH, sides 1..%d, got '%s'",
                         HFVIS_RASTER_MAX_SIZE, v);
    h = strtol(end + 1, &end, 10);
    if (*end != '\0' || errno == ERANGE || h < 1 || h > HFVIS_RASTER_MAX_SIZE
        || (long long)w * h > 1LL << 26)
        return cli_error(CLI_EXIT_USAGE, f, "expected WxH, sides 1..%d, at most 2^26 pixels, got "
                         "'%s'", HFVIS_RASTER_MAX_SIZE, v);
    *width = (int)w, *height = (int)h;
    return 0;
}

/* The flags of `meshao` (called only for it, before the shared ones, because it gives --method,
 * --rays, --radius and the camera flags their own meaning); -1 if f is none of them. */
static int cli_set_lk(cli_args *a, const char *f, const char *v)
{
    if (!strcmp(f, "--method")) {
        if (!strcmp(v, "raster")) a->lk_method = HFVIS_LK_METHOD_RASTER;
        else if (!strcmp(v, "bvh")) a->lk_method = HFVIS_LK_METHOD_BVH;
        else if (!strcmp(v, "raycast")) a->lk_method = HFVIS_LK_METHOD_RAYCAST;
        else return cli_error(CLI_EXIT_USAGE, f, "expected raster, bvh or raycast, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--rays"))
        return cli_int(f, v, 1, HFVIS_LK_MAX_RAYS, "an integer 1..4096", &a->lk_rays);
    if (!strcmp(f, "--pattern")) {
        if (!strcmp(v, "torus")) a->lk_pattern = HFVIS_LK_PATTERN_LLOYD_TORUS;
        else if (!strcmp(v, "lloyd")) a->lk_pattern = HFVIS_LK_PATTERN_LLOYD;
        else if (!strcmp(v, "random")) a->lk_pattern = HFVIS_LK_PATTERN_RANDOM;
        else return cli_error(CLI_EXIT_USAGE, f, "expected torus, lloyd or random, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--radius")) {
        a->lk_has_radius = 1;
        return cli_real(f, v, 0.0, 1, CLI_FLT_MAX, "a radius > 0", &a->lk_radius);
    }
    if (!strcmp(f, "--falloff")) {
        if (!strcmp(v, "constant")) a->lk_falloff = HFVIS_LK_FALLOFF_CONSTANT;
        else if (!strcmp(v, "linear")) a->lk_falloff = HFVIS_LK_FALLOFF_LINEAR;
        else if (!strcmp(v, "quadratic")) a->lk_falloff = HFVIS_LK_FALLOFF_QUADRATIC;
        else return cli_error(CLI_EXIT_USAGE, f, "expected constant, linear or quadratic, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--eye")) { a->lk_has_eye = 1; return cli_xyz(f, v, a->lk_eye); }
    if (!strcmp(f, "--target")) { a->lk_has_target = 1; return cli_xyz(f, v, a->lk_target); }
    if (!strcmp(f, "--up")) { a->lk_has_up = 1; return cli_xyz(f, v, a->lk_up); }
    if (!strcmp(f, "--fov")) return cli_real(f, v, 1.0, 0, 179.0, "degrees in 1..179", &a->lk_fov);
    if (!strcmp(f, "--size")) return cli_size(f, v, &a->lk_width, &a->lk_height);
    if (!strcmp(f, "--two-sided")) { a->lk_two_sided = 1; return 0; }
    if (!strcmp(f, "--lut"))
        return cli_int(f, v, HFVIS_LK_LUT_MIN_RESOLUTION, HFVIS_LK_LUT_MAX_RESOLUTION,
                       "a table resolution 2..1024", &a->lk_lut);
    if (!strcmp(f, "--seed"))
        return cli_real(f, v, 0.0, 0, 9007199254740992.0, "an integer 0..2^53", &a->lk_seed);
    if (!strcmp(f, "--no-jitter")) { a->lk_no_jitter = 1; return 0; }
    return -1;
}

/* Combinations `meshao` rejects; returns 0 or CLI_EXIT_USAGE (message printed). */
static int cli_check_lk(const cli_args *a)
{
    if (a->lk_seed != floor(a->lk_seed))
        return cli_error(CLI_EXIT_USAGE, "--seed", "expected an integer, got %g", a->lk_seed);
    if (a->lk_has_eye && a->lk_has_target && a->lk_eye[0] == a->lk_target[0] &&
        a->lk_eye[1] == a->lk_target[1] && a->lk_eye[2] == a->lk_target[2])
        return cli_error(CLI_EXIT_USAGE, "--eye", "the eye and the target coincide");
    if (a->lk_has_up && a->lk_up[0] == 0.0 && a->lk_up[1] == 0.0 && a->lk_up[2] == 0.0)
        return cli_error(CLI_EXIT_USAGE, "--up", "the up direction is zero");
    return 0;
}


/* -o and the flags only `visfield` has; -1 if f is none of them. */
static int cli_set_vf(cli_args *a, const char *f, const char *v)
{
    if (!strcmp(f, "-o")) { /* checked against the mode in cli_check_vf */
        a->out = v;
        a->out_pgm = cli_ends_with(v, ".pgm");
        return 0;
    }
    if (!strcmp(f, "--positions")) {
        int k, n;
        if (cli_int(f, v, 1, INT_MAX, "a count 2(2n^2+2n+1) such as 290, 1090 or 4226", &k))
            return CLI_EXIT_USAGE;
        for (n = 1; n <= HFVIS_VISFIELD_MAX_N; n++)
            if (hfvis_visfield_position_count(n) >= (size_t)k) break;
        if (n > HFVIS_VISFIELD_MAX_N || hfvis_visfield_position_count(n) != (size_t)k) {
            if (n > HFVIS_VISFIELD_MAX_N)
                return cli_error(CLI_EXIT_USAGE, f, "at most %zu positional samples, got '%s'",
                                 hfvis_visfield_position_count(HFVIS_VISFIELD_MAX_N), v);
            return cli_error(CLI_EXIT_USAGE, f, "expected a count 2(2n^2+2n+1), got '%s' (nearest: "
                             "%zu or %zu)", v, n > 1 ? hfvis_visfield_position_count(n - 1) : 0,
                             hfvis_visfield_position_count(n));
        }
        a->vf_positions = n; /* stored as the frequency n */
        return 0;
    }
    if (!strcmp(f, "--format")) {
        if (!strcmp(v, "u8")) a->vf_format = HFVIS_VISFIELD_U8;
        else if (!strcmp(v, "f32")) a->vf_format = HFVIS_VISFIELD_F32;
        else if (!strcmp(v, "bit")) a->vf_format = HFVIS_VISFIELD_BIT;
        else if (!strcmp(v, "normal")) a->vf_format = HFVIS_VISFIELD_NORMAL;
        else return cli_error(CLI_EXIT_USAGE, f, "expected u8, f32, bit or normal, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--mapping")) {
        if (!strcmp(v, "concentric")) a->vf_mapping = HFVIS_DIRMAP_CONCENTRIC;
        else if (!strcmp(v, "polar")) a->vf_mapping = HFVIS_DIRMAP_POLAR;
        else if (!strcmp(v, "rejection")) a->vf_mapping = HFVIS_DIRMAP_REJECTION;
        else return cli_error(CLI_EXIT_USAGE, f, "expected concentric, polar or rejection, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--ao")) { a->vf_ao = 1; return 0; }
    if (!strcmp(f, "--size")) { a->vf_has_size = 1; return -1; } /* WxH parsed by volgi's code */
    if (!strcmp(f, "--ground")) {
        a->vf_has_ground = 1;
        return cli_real(f, v, -CLI_FLT_MAX, 0, CLI_FLT_MAX, "a finite height", &a->vf_ground);
    }
    if (!strcmp(f, "--extent")) {
        a->vf_has_extent = 1;
        return cli_real(f, v, 0.0, 1, CLI_FLT_MAX, "a half-size > 0", &a->vf_extent);
    }
    if (!strcmp(f, "--rays"))
        return cli_int(f, v, 1, HFVIS_VISFIELD_MAX_RAYS_SQRT, "an integer 1..256", &a->vf_rays);
    if (!strcmp(f, "--bias")) {
        a->vf_has_bias = 1;
        return cli_real(f, v, 0.0, 0, 1.0, "a fraction of the radius in 0..1", &a->vf_bias);
    }
    if (!strcmp(f, "--reference")) { a->vf_reference = v; return 0; }
    return -1;
}

/* Combinations `visfield` rejects; returns 0 or CLI_EXIT_USAGE (message printed). */
static int cli_check_vf(const cli_args *a)
{
    if (a->vf_ao) {
        if (!cli_ends_with(a->out, ".pgm") && !cli_ends_with(a->out, ".pfm"))
            return cli_error(CLI_EXIT_USAGE, a->out, "unknown output type (use a .pfm or .pgm name)");
        if (a->vf_positions || a->vf_format || a->vf_mapping || a->has_dirs)
            return cli_error(CLI_EXIT_USAGE, a->vf_positions ? "--positions" : a->vf_format ? "--format"
                             : a->vf_mapping ? "--mapping" : "--dirs", "applies only to building a field");
        return 0;
    }
    if (a->has_range) return cli_error(CLI_EXIT_USAGE, "--range", "applies only to --ao images");
    if (!cli_ends_with(a->out, ".hfvf"))
        return cli_error(CLI_EXIT_USAGE, a->out, "unknown output type for a field (use a .hfvf name)");
    if (a->vf_has_ground || a->vf_has_extent || a->vf_has_size || a->vf_rays || a->vf_has_bias
        || a->vf_reference || a->max_distance > 0.0)
        return cli_error(CLI_EXIT_USAGE, a->vf_has_ground ? "--ground" : a->vf_has_extent ? "--extent"
                         : a->vf_has_size ? "--size" : a->vf_rays ? "--rays" : a->vf_has_bias ? "--bias"
                         : a->vf_reference ? "--reference" : "--max-distance", "applies only to --ao");
    if (a->has_dirs && (a->dirs < 1 || a->dirs > HFVIS_VISFIELD_MAX_DIR_RES))
        return cli_error(CLI_EXIT_USAGE, "--dirs", "a field takes 1..4096 directions per side, got %d",
                         a->dirs);
    return 0;
}


static void cli_volgi_defaults(cli_args *a)
{
    a->vg_up[0] = 0.0, a->vg_up[1] = 0.0, a->vg_up[2] = 1.0;
    a->vg_fov = 40.0;
    a->vg_width = 512, a->vg_height = 512;
    a->iterations = HFVIS_VOLGI_DEFAULT_ITERATIONS;
}

/* Parse "r1,r2,...": between min and max finite reals (s[0..len)); returns the count or -1. */
static int cli_volgi_reals(const char *s, size_t len, double *out, int min, int max)
{
    char buf[256];
    const char *p;
    int n = 0;
    if (len >= sizeof buf) return -1;
    memcpy(buf, s, len);
    buf[len] = '\0';
    p = buf;
    for (;;) {
        char *comma = strchr(p, ',');
        if (n == max) return -1;
        if (comma) *comma = '\0';
        if (!cli_parse_real(p, &out[n])) return -1;
        n++;
        if (!comma) break;
        p = comma + 1;
    }
    return n >= min ? n : -1;
}

/* --light SPEC (see CLI_VOLGI_HELP); returns 0 or CLI_EXIT_USAGE. */
static int cli_volgi_light(cli_args *a, const char *v)
{
    static const char *const kinds[3] = { "point:", "spot:", "dir:" };
    const char *bad = "expected point:X,Y,Z[:I], spot:X,Y,Z:DX,DY,DZ:OUTER[,INNER][:I] or "
                      "dir:DX,DY,DZ[:E], got '%s'";
    hfvis_volgi_light L;
    const char *p, *parts[4];
    size_t lens[4];
    double vals[3];
    int kind, np = 0, need, c, n;
    memset(&L, 0, sizeof L);
    if (a->vg_nlights == CLI_VOLGI_MAX_LIGHTS)
        return cli_error(CLI_EXIT_USAGE, "--light", "at most %d lights", CLI_VOLGI_MAX_LIGHTS);
    for (kind = 0; kind < 3 && strncmp(v, kinds[kind], strlen(kinds[kind])); kind++) {}
    if (kind == 3) return cli_error(CLI_EXIT_USAGE, "--light", bad, v);
    p = v + strlen(kinds[kind]);
    while (np < 4) { /* split at ':' */
        const char *colon = strchr(p, ':');
        parts[np] = p;
        lens[np] = colon ? (size_t)(colon - p) : strlen(p);
        np++;
        if (!colon) break;
        p = colon + 1;
        if (np == 4) return cli_error(CLI_EXIT_USAGE, "--light", bad, v);
    }
    need = kind == 1 ? 3 : 1; /* parts before the optional intensity */
    if (np != need && np != need + 1) return cli_error(CLI_EXIT_USAGE, "--light", bad, v);
    L.type = kind == 0 ? HFVIS_VOLGI_LIGHT_POINT : kind == 1 ? HFVIS_VOLGI_LIGHT_SPOT
                                                           : HFVIS_VOLGI_LIGHT_DIRECTIONAL;
    if (cli_volgi_reals(parts[0], lens[0], kind == 2 ? L.direction : L.position, 3, 3) != 3)
        return cli_error(CLI_EXIT_USAGE, "--light", bad, v);
    if (kind == 1) {
        double ang[2];
        if (cli_volgi_reals(parts[1], lens[1], L.direction, 3, 3) != 3)
            return cli_error(CLI_EXIT_USAGE, "--light", bad, v);
        n = cli_volgi_reals(parts[2], lens[2], ang, 1, 2);
        if (n < 0 || !(ang[0] > 0.0 && ang[0] <= 180.0) || (n == 2 && !(ang[1] >= 0.0 && ang[1] <= ang[0])))
            return cli_error(CLI_EXIT_USAGE, "--light", "spot angles: OUTER in (0, 180], 0 <= INNER <= "
                             "OUTER degrees, got '%s'", v);
        L.spot_outer_rad = ang[0] * (CLI_PI / 180.0);
        L.spot_inner_rad = (n == 2 ? ang[1] : 0.8 * ang[0]) * (CLI_PI / 180.0);
    }
    if ((kind == 1 || kind == 2) && L.direction[0] == 0.0 && L.direction[1] == 0.0 && L.direction[2] == 0.0)
        return cli_error(CLI_EXIT_USAGE, "--light", "the direction must not be 0,0,0, got '%s'", v);
    vals[0] = vals[1] = vals[2] = 1.0;
    if (np == need + 1) {
        n = cli_volgi_reals(parts[need], lens[need], vals, 1, 3);
        if (n == 2 || n < 0) return cli_error(CLI_EXIT_USAGE, "--light", "intensity: one value or R,G,B, got '%s'", v);
        if (n == 1) vals[1] = vals[2] = vals[0];
    }
    for (c = 0; c < 3; c++) {
        if (!(vals[c] >= 0.0 && vals[c] <= CLI_FLT_MAX))
            return cli_error(CLI_EXIT_USAGE, "--light", "intensity must be >= 0, got '%s'", v);
        L.intensity[c] = (float)vals[c];
    }
    for (c = 0; c < 3; c++)
        if (fabs(L.position[c]) > 1e30)
            return cli_error(CLI_EXIT_USAGE, "--light", "position beyond 1e30, got '%s'", v);
    a->vg_lights[a->vg_nlights++] = L;
    return 0;
}

/* The flags only `volgi` has; -1 if f is none of them. */
static int cli_set_volgi(cli_args *a, const char *f, const char *v)
{
    if (!strcmp(f, "--room")) { a->room = 1; return 0; }
    if (!strcmp(f, "--iterations"))
        return cli_int(f, v, 1, HFVIS_VOLGI_MAX_ITERATIONS, "an integer 1..1048576", &a->iterations);
    if (!strcmp(f, "--light")) return cli_volgi_light(a, v);
    if (!strcmp(f, "--eye") || !strcmp(f, "--target") || !strcmp(f, "--up")) {
        if (f[2] == 'e') a->vg_has_eye = 1;
        if (f[2] == 't') a->vg_has_target = 1;
        return cli_xyz(f, v, f[2] == 'e' ? a->vg_eye : f[2] == 't' ? a->vg_target : a->vg_up);
    }
    if (!strcmp(f, "--fov")) return cli_real(f, v, 1.0, 0, 179.0, "degrees in 1..179", &a->vg_fov);
    if (!strcmp(f, "--size")) return cli_size(f, v, &a->vg_width, &a->vg_height);
    if (!strcmp(f, "--transfer")) {
        if (!strcmp(v, "cone")) a->vg_transfer = HFVIS_VOLGI_TRANSFER_CONE;
        else if (!strcmp(v, "normalized")) a->vg_transfer = HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED;
        else return cli_error(CLI_EXIT_USAGE, f, "expected cone or normalized, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--paths")) {
        if (!strcmp(v, "all")) a->vg_paths = HFVIS_VOLGI_PATHS_ALL;
        else if (!strcmp(v, "void")) a->vg_paths = HFVIS_VOLGI_PATHS_VOID;
        else return cli_error(CLI_EXIT_USAGE, f, "expected all or void, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--reflection")) {
        if (!strcmp(v, "mirror")) a->vg_reflection = HFVIS_VOLGI_REFLECT_MIRROR;
        else if (!strcmp(v, "diffuse")) a->vg_reflection = HFVIS_VOLGI_REFLECT_DIFFUSE;
        else return cli_error(CLI_EXIT_USAGE, f, "expected mirror or diffuse, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--reflectance")) {
        a->vg_has_rho = 1;
        if (!strcmp(v, "albedo")) { a->vg_rho_albedo = 1; return 0; }
        a->vg_rho_albedo = 0;
        return cli_real(f, v, 0.0, 0, 1.0, "a reflectance in 0..1 or 'albedo'", &a->vg_rho);
    }
    return -1;
}

/* Combinations `volgi` rejects; returns 0 or CLI_EXIT_USAGE (message printed). */
static int cli_check_volgi(const cli_args *a)
{
    if (a->room && a->in) return cli_error(CLI_EXIT_USAGE, a->in, "--room renders the test room: no MESH");
    if (a->room && a->has_albedo)
        return cli_error(CLI_EXIT_USAGE, "--albedo", "applies to a MESH (the room has its own colours)");
    if (a->has_albedo && a->albedo > 1.0)
        return cli_error(CLI_EXIT_USAGE, "--albedo", "expected an albedo in 0..1, got %g", a->albedo);
    if (a->res == 1) return cli_error(CLI_EXIT_USAGE, "--res", "volgi needs at least 2 voxels");
    return 0;
}

/* ------------------------------------------------------------------------------------------ */
/* GIS conventions: angle units, azimuth conventions, map coordinates (docs/gis-conventions.md) */
/* ------------------------------------------------------------------------------------------ */

/* --convention: how an azimuth flag's value is read and in which sense directions k advance.
 * The library's psi runs from east toward south (+x toward +y, rows down): clockwise on a
 * north-up map. */
enum { CONV_COMPASS, CONV_GRASS, CONV_GRID };
static const char *const cli_conv_names[3] = { "compass", "grass", "grid" };

#define CLI_SUMMARY_SECONDS 10.0 /* runs at least this long end with a summary line on stderr */

#define CLI_GIS_FLAGS                                                                             \
    { "--convention", 1, CLI_HF }, { "--radians", 0, CLI_HF }, { "--overwrite", 0, CLI_ALL },     \
    { "--progress", 0, CLI_ALL }, { "--azimuth", 1, CLI_ONLY(CMD_HORIZON) },                      \
    { "--split", 0, CLI_ONLY(CMD_HORIZON) }, { "--observer-grid", 1, CLI_ONLY(CMD_VIEWSHED) },    \
    { "--curvature", 0, CLI_ONLY(CMD_VIEWSHED) }, { "--refraction", 1, CLI_ONLY(CMD_VIEWSHED) },  \
    { "--earth-radius", 1, CLI_ONLY(CMD_VIEWSHED) }, { "--svf", 1, CLI_ONLY(CMD_SKYVIEW) },       \
    { "--blend", 1, CLI_ONLY(CMD_HILLSHADE) }, { "--no-shadows", 0, CLI_ONLY(CMD_HILLSHADE) },    \
    { "--negative", 0, CLI_ONLY(CMD_OPENNESS) }

#define CLI_EARTH_RADIUS 6371000.0 /* mean Earth radius in metres (IUGG), --earth-radius default */
#define CLI_REFRACTION 0.13        /* the usual refraction coefficient (ArcGIS's default) */

/* An angle flag's value in degrees (it was given in radians with --radians). */
static double cli_deg(const cli_args *a, double v)
{
    return a->radians ? v * (180.0 / CLI_PI) : v;
}

/* An azimuth in degrees, read in convention conv, as the library's psi in radians. */
static double cli_psi(int conv, double deg)
{
    if (conv == CONV_COMPASS) return (deg - 90.0) * (CLI_PI / 180.0);
    if (conv == CONV_GRASS) return -deg * (CLI_PI / 180.0);
    return deg * (CLI_PI / 180.0);
}

/* psi in radians as an azimuth of convention conv, in degrees in [0, 360). */
static double cli_from_psi(int conv, double psi)
{
    double deg = psi * (180.0 / CLI_PI), v;
    v = conv == CONV_COMPASS ? deg + 90.0 : conv == CONV_GRASS ? -deg : deg;
    v = fmod(v, 360.0);
    if (v < 0.0) v += 360.0;
    if (v >= 360.0 - 1e-9 || v == 0.0) v = 0.0; /* -0.0 and rounding just under a turn */
    return v;
}

/* The library direction that is direction k of the user's convention: GRASS's directions run
 * counter-clockwise, the library's clockwise from the same psi_0. */
static int cli_lib_direction(const cli_args *a, int k)
{
    return a->convention == CONV_GRASS ? (a->dirs - k) % a->dirs : k;
}

/* "X,Y" -> two finite reals; 0 or CLI_EXIT_USAGE (reported with what). */
static int cli_pair(const char *f, const char *v, const char *what, double *x, double *y)
{
    char buf[256];
    const char *comma = strchr(v, ',');
    size_t n = comma ? (size_t)(comma - v) : 0;
    if (!comma || n >= sizeof buf) return cli_error(CLI_EXIT_USAGE, f, "expected %s, got '%s'", what, v);
    memcpy(buf, v, n);
    buf[n] = '\0';
    if (!cli_parse_real(buf, x) || !cli_parse_real(comma + 1, y) || fabs(*x) > 1e300 || fabs(*y) > 1e300)
        return cli_error(CLI_EXIT_USAGE, f, "expected %s, got '%s'", what, v);
    return 0;
}

/* The GIS flags (conventions, map coordinates, hillshade, openness, safety, progress); -1 if f
 * is none of them. */
static int cli_set_gis(cli_args *a, const char *f, const char *v)
{
    if (!strcmp(f, "--convention")) {
        int c;
        for (c = 0; c < 3; c++)
            if (!strcmp(v, cli_conv_names[c])) {
                a->convention = c;
                a->has_convention = 1;
                return 0;
            }
        if (!strcmp(v, "math"))
            return cli_error(CLI_EXIT_USAGE, f, "'math' is ambiguous: use grass (counter-clockwise "
                             "from east) or grid (from east toward south, the old --math)");
        return cli_error(CLI_EXIT_USAGE, f, "expected compass, grass or grid, got '%s'", v);
    }
    if (!strcmp(f, "--compass")) { /* the default since 0.2; kept so old command lines run */
        if (a->has_convention && a->convention != CONV_COMPASS)
            return cli_error(CLI_EXIT_USAGE, f, "contradicts --convention %s",
                             cli_conv_names[a->convention]);
        a->convention = CONV_COMPASS;
        a->has_convention = 1;
        return 0;
    }
    if (!strcmp(f, "--math"))
        return cli_error(CLI_EXIT_USAGE, f, "removed: it read --sun-azimuth from east toward south, "
                         "now '--convention grid'; GRASS's counter-clockwise from east is "
                         "'--convention grass'");
    if (!strcmp(f, "--radians")) { a->radians = 1; return 0; }
    if (!strcmp(f, "--azimuth0")) {
        a->has_azimuth0 = 1;
        return cli_real(f, v, -1e6, 0, 1e6, "a finite angle (degrees, or radians with --radians)",
                        &a->azimuth0);
    }
    if (!strcmp(f, "--azimuth")) {
        a->has_azimuth = 1;
        return cli_real(f, v, -1e6, 0, 1e6, "a finite angle (degrees, or radians with --radians)",
                        &a->azimuth);
    }
    if (!strcmp(f, "--split")) { a->split = 1; return 0; }
    if (!strcmp(f, "--overwrite")) { a->overwrite = 1; return 0; }
    if (!strcmp(f, "--progress")) { a->progress_lines = 1; return 0; }
    if (a->cmd == CMD_VIEWSHED) {
        if (!strcmp(f, "--observer") || !strcmp(f, "--observer-grid")) {
            a->observer_grid = f[10] == '-';
            a->has_observer = 1;
            return cli_pair(f, v, a->observer_grid ? "COL,ROW (grid position)" : "X,Y (map "
                            "coordinates)", &a->observer_x, &a->observer_y);
        }
        if (!strcmp(f, "--target")) {
            if (a->ntargets == CLI_MAX_TARGETS)
                return cli_error(CLI_EXIT_USAGE, f, "at most %d targets", CLI_MAX_TARGETS);
            a->ntargets++;
            return cli_pair(f, v, "X,Y (map coordinates)", &a->targets[2 * a->ntargets - 2],
                            &a->targets[2 * a->ntargets - 1]);
        }
        if (!strcmp(f, "--curvature")) { a->curvature = 1; return 0; }
        if (!strcmp(f, "--refraction")) {
            a->has_refraction = 1;
            return cli_real(f, v, -1.0, 0, 1.0, "a coefficient in -1..1", &a->refraction);
        }
        if (!strcmp(f, "--earth-radius")) {
            a->has_earth_radius = 1;
            return cli_real(f, v, 0.0, 1, 1e12, "a radius > 0 (metres)", &a->earth_radius);
        }
    }
    if (!strcmp(f, "--svf")) {
        static const char *const names[3] = { "zaksek", "saga", "visible" };
        int k;
        for (k = 0; k < 3; k++)
            if (!strcmp(v, names[k])) { a->svf = k; return 0; }
        return cli_error(CLI_EXIT_USAGE, f, "expected zaksek, saga or visible, got '%s'", v);
    }
    if (!strcmp(f, "--blend")) return cli_int(f, v, 1, 360, "a count of sun directions 1..360", &a->blend);
    if (!strcmp(f, "--no-shadows")) { a->no_shadows = 1; return 0; }
    if (!strcmp(f, "--negative")) { a->negative = 1; return 0; }
    if (a->cmd == CMD_OPENNESS && !strcmp(f, "--radius")) {
        a->has_radius = 1;
        return cli_real(f, v, 0.0, 0, DBL_MAX, "a distance >= 0 (0 = unlimited)", &a->radius);
    }
    return -1;
}

/* After parsing: read the angle flags in their unit and convention and store them as the
 * library's psi (a->azimuth0 in radians, --sun-azimuth in psi degrees with a->math set), check
 * the GIS combinations. Returns 0 or CLI_EXIT_USAGE (reported). */
static int cli_gis_finish(cli_args *a)
{
    double deg;
    if (a->cmd == CMD_HILLSHADE) { /* the cartographic default light: north-west, 45 degrees up */
        if (!a->has_sun_azimuth) a->sun_azimuth = a->radians ? 315.0 * CLI_PI / 180.0 : 315.0;
        if (!a->has_sun_elevation) a->sun_elevation = a->radians ? CLI_PI / 4.0 : 45.0;
        a->has_sun_azimuth = a->has_sun_elevation = 1;
        if (!a->blend) a->blend = 1;
    }
    if (a->has_sun_elevation) {
        a->sun_elevation = cli_deg(a, a->sun_elevation);
        if (a->sun_elevation < -90.0 || a->sun_elevation > 90.0)
            return cli_error(CLI_EXIT_USAGE, "--sun-elevation", "expected -90..90 degrees, got %g",
                             a->sun_elevation);
    }
    if (a->has_sun_radius) {
        a->sun_radius = cli_deg(a, a->sun_radius);
        if (a->sun_radius > 90.0)
            return cli_error(CLI_EXIT_USAGE, "--sun-radius", "expected 0..90 degrees, got %g",
                             a->sun_radius);
    }
    if (a->has_sun_azimuth) { /* as psi in degrees: the existing sun code reads that with math */
        a->sun_azimuth = cli_psi(a->convention, cli_deg(a, a->sun_azimuth)) * (180.0 / CLI_PI);
        a->math = 1;
    }
    if (a->has_azimuth) {
        if (a->has_dirs && a->dirs != 1)
            return cli_error(CLI_EXIT_USAGE, "--azimuth", "gives one direction: not with --dirs %d",
                             a->dirs);
        if (a->has_azimuth0)
            return cli_error(CLI_EXIT_USAGE, "--azimuth", "cannot be combined with --azimuth0");
        a->dirs = 1;
        a->azimuth0 = a->azimuth;
        a->has_azimuth0 = 1;
    }
    if (a->svf != 0 && a->has_dir_range)
        return cli_error(CLI_EXIT_USAGE, "--dir-range", "applies to --svf zaksek only");
    if (a->split && (a->out_partial || a->has_dir_range))
        return cli_error(CLI_EXIT_USAGE, "--split", "cannot be combined with --dir-range");
    if (a->convention == CONV_GRASS && a->cmd == CMD_HORIZON && a->has_dir_range)
        return cli_error(CLI_EXIT_USAGE, "--dir-range", "horizon parts keep the library's clockwise "
                         "order: use --convention compass or grid for a split horizon run");
    if ((a->has_refraction || a->has_earth_radius) && !a->curvature)
        return cli_error(CLI_EXIT_USAGE, a->has_refraction ? "--refraction" : "--earth-radius",
                         "applies with --curvature");
    if (!a->has_refraction) a->refraction = CLI_REFRACTION;
    if (!a->has_earth_radius) a->earth_radius = CLI_EARTH_RADIUS;
    if (a->cmd == CMD_OPENNESS && !a->has_dirs) a->dirs = 8; /* Yokoyama et al.'s eight */
    /* direction 0: north (compass) or east (grass, grid: r.horizon's start=0 and the old default) */
    deg = a->has_azimuth0 ? cli_deg(a, a->azimuth0) : 0.0;
    a->azimuth0 = cli_psi(a->convention, deg);
    a->compass = 0; /* a->azimuth0 is psi_0 now */
    return 0;
}

#define CLI_ALL ((1u << CMD_COUNT) - 1u)
#define CLI_ONLY(c) (1u << (c))
#define CLI_SUN (CLI_ONLY(CMD_SHADOW) | CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI) \
                 | CLI_ONLY(CMD_HILLSHADE)) /* the sun flags */
/* the sweep commands: --max-distance R is the library's search radius, --window makes a piece */
#define CLI_SWEEP (CLI_ONLY(CMD_HORIZON) | CLI_ONLY(CMD_SKYVIEW) | CLI_ONLY(CMD_SKY) | CLI_ONLY(CMD_SHADOW) \
                   | CLI_ONLY(CMD_LIGHT) | CLI_ONLY(CMD_HILLSHADE))
/* the [P2] hull-tree commands: a search radius but no windows in the library (hfvis.h, "Search
 * radius and tiles") */
#define CLI_P2 (CLI_ONLY(CMD_VISIBILITY) | CLI_ONLY(CMD_INDIRECT))
/* the height-field commands: the GIS conventions apply to them */
#define CLI_HF (CLI_ALL & ~(CLI_ONLY(CMD_VOXELIZE) | CLI_ONLY(CMD_SSAO) | CLI_ONLY(CMD_VOLGI) \
                            | CLI_ONLY(CMD_VISFIELD) | CLI_ONLY(CMD_MESHAO) | CLI_ONLY(CMD_SUM)))
typedef struct cli_flag { const char *name; int has_value; unsigned commands; } cli_flag;
static const cli_flag cli_flags[] = {
    { "-o", 1, CLI_ALL },           { "--range", 1, CLI_ALL },       { "--cell", 1, CLI_ALL },
    { "--zscale", 1, CLI_ALL },     { "--nodata", 1, CLI_ALL },      { "--dirs", 1, CLI_ALL },
    { "--azimuth0", 1, CLI_ALL },   { "--compass", 0, CLI_ALL },     { "--degrees", 0, CLI_ALL },
    { "--border", 1, CLI_ALL },     { "--border-cells", 1, CLI_ALL }, { "--quiet", 0, CLI_ALL },
    { "--band", 1, CLI_ALL },
    { "--max-memory", 1, CLI_ALL },
    { "--dir-range", 1, CLI_ONLY(CMD_HORIZON) | CLI_ONLY(CMD_SKYVIEW) | CLI_ONLY(CMD_SKY)
                        | CLI_ONLY(CMD_LIGHT) | CLI_ONLY(CMD_VISIBILITY) },
    { "--sky", 1, CLI_ONLY(CMD_SKY) | CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI) },
    { "--albedo", 1, CLI_ONLY(CMD_SKY) | CLI_ONLY(CMD_LIGHT) | CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI)
                  | CLI_ONLY(CMD_VOLGI) },
    { "--sun-azimuth", 1, CLI_SUN },              { "--sun-elevation", 1, CLI_SUN },
    { "--sun-radius", 1, CLI_SUN },               { "--math", 0, CLI_SUN },
    { "--env", 1, CLI_ONLY(CMD_LIGHT) | CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI) },
    { "--method", 1, CLI_ONLY(CMD_LIGHT) | CLI_ONLY(CMD_VOXELIZE) | CLI_ONLY(CMD_SSAO)
                     | CLI_ONLY(CMD_MESHAO) },
    { "--sun-irradiance", 1, CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI) }, { "--albedo-map", 1, CLI_ONLY(CMD_INDIRECT) },
    { "--emission", 1, CLI_ONLY(CMD_INDIRECT) },  { "--bounces", 1, CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI) },
    { "--output", 1, CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI) | CLI_ONLY(CMD_VOLGI) },
    { "--fraction", 0, CLI_ONLY(CMD_VISIBILITY) }, { "--stats", 0, CLI_ONLY(CMD_VISIBILITY) | CLI_ONLY(CMD_MESHAO) },
    { "--observer", 1, CLI_ONLY(CMD_VIEWSHED) },  { "--observer-height", 1, CLI_ONLY(CMD_VIEWSHED) },
    { "--target-height", 1, CLI_ONLY(CMD_VIEWSHED) },
    { "--max-distance", 1, CLI_ONLY(CMD_VIEWSHED) | CLI_ONLY(CMD_VISFIELD) | CLI_SWEEP | CLI_P2 },
    { "--window", 1, CLI_SWEEP | CLI_ONLY(CMD_OPENNESS) },
    { "--exact", 0, CLI_ONLY(CMD_VIEWSHED) | CLI_ONLY(CMD_HORIZON) | CLI_ONLY(CMD_SKYVIEW) | CLI_ONLY(CMD_SKY)
                    | CLI_ONLY(CMD_LIGHT) | CLI_ONLY(CMD_SHADOW) },
    { "--res", 1, CLI_ONLY(CMD_VOXELIZE) | CLI_ONLY(CMD_VOLGI) },       { "--mode", 1, CLI_ONLY(CMD_VOXELIZE) },
    { "--axis", 1, CLI_ONLY(CMD_VOXELIZE) },  
    { "--max-vertices", 1, CLI_ONLY(CMD_VOXELIZE) }, { "--padding", 1, CLI_ONLY(CMD_VOXELIZE) },
    { "--open", 0, CLI_ONLY(CMD_VOXELIZE) },
    CLI_GI_FLAGS,
    CLI_VOLGI_FLAGS,
    CLI_VF_FLAGS,
    CLI_LK_FLAGS,
    { "--fov-y", 1, CLI_ONLY(CMD_SSAO) },         { "--ortho", 1, CLI_ONLY(CMD_SSAO) },
    { "--radius", 1, CLI_ONLY(CMD_SSAO) | CLI_ONLY(CMD_MESHAO) | CLI_ONLY(CMD_OPENNESS) },        { "--guard", 1, CLI_ONLY(CMD_SSAO) },
    { "--depth", 1, CLI_ONLY(CMD_SSAO) },         { "--near", 1, CLI_ONLY(CMD_SSAO) },
    { "--far", 1, CLI_ONLY(CMD_SSAO) },
    CLI_GIS_FLAGS
};

/* Apply one recognised flag; returns 0 or CLI_EXIT_USAGE (message printed). */
static int cli_set(cli_args *a, const char *f, const char *v)
{
    {
        int r = cli_set_gis(a, f, v);
        if (r >= 0) return r;
    }
    if (a->cmd == CMD_MESHAO) {
        int r = cli_set_lk(a, f, v);
        if (r >= 0) return r;
    }
    if (!strcmp(f, "-o") && a->cmd == CMD_VISFIELD) return cli_set_vf(a, f, v);
    if (!strcmp(f, "-o") && a->cmd == CMD_VOXELIZE) {
        if (cli_ends_with(v, ".binvox")) a->out_binvox = 1;
        else if (cli_ends_with(v, ".raw")) a->out_binvox = 0;
        else return cli_error(CLI_EXIT_USAGE, v, "unknown output type (use a .binvox or .raw name)");
        a->out = v;
        return 0;
    }
    if (!strcmp(f, "-o")) {
        a->out_pgm = a->out_partial = 0;
        if (cli_ends_with(v, ".pfm")) a->out_pgm = 0;
        else if (cli_ends_with(v, ".pgm")) a->out_pgm = 1;
        else if (cli_ends_with(v, ".hfvs")) a->out_partial = 1;
        else if (ex_rio_format_of(v)) a->out_raster = 1;
        else return cli_error(CLI_EXIT_USAGE, v, "unknown output type (use a .pfm, .pgm, .tif, .asc, .bil "
                              "or .flt name)");
        a->out = v;
        return 0;
    }
    if (!strcmp(f, "--dir-range")) { /* "A:B", checked against K in cli_parse */
        char *end;
        long b, e;
        errno = 0;
        b = strtol(v, &end, 10);
        if (end == v || !isdigit((unsigned char)v[0]) || *end != ':' || !isdigit((unsigned char)end[1]))
            return cli_error(CLI_EXIT_USAGE, f, "expected A:B (directions A..B-1), got '%s'", v);
        e = strtol(end + 1, &end, 10);
        if (*end != '\0' || errno == ERANGE || b > CLI_MAX_DIRS || e > CLI_MAX_DIRS)
            return cli_error(CLI_EXIT_USAGE, f, "expected A:B (directions A..B-1), got '%s'", v);
        a->has_dir_range = 1;
        a->dir_begin = (int)b;
        a->dir_end = (int)e;
        return 0;
    }
    if (!strcmp(f, "--range")) {
        char buf[256];
        const char *colon = strchr(v, ':');
        size_t n = colon ? (size_t)(colon - v) : 0;
        if (!colon || n >= sizeof buf)
            return cli_error(CLI_EXIT_USAGE, f, "expected LO:HI, got '%s'", v);
        memcpy(buf, v, n);
        buf[n] = '\0';
        if (!cli_parse_real(buf, &a->range_lo) || !cli_parse_real(colon + 1, &a->range_hi) ||
            fabs(a->range_lo) > CLI_FLT_MAX || fabs(a->range_hi) > CLI_FLT_MAX ||
            !((float)a->range_lo < (float)a->range_hi))
            return cli_error(CLI_EXIT_USAGE, f, "expected LO:HI with finite LO < HI, got '%s'", v);
        a->has_range = 1;
        return 0;
    }
    if (!strcmp(f, "--max-memory")) { /* BYTES with an optional K, M, G or T (powers of 1024) */
        char *end;
        double m;
        errno = 0;
        m = strtod(v, &end);
        if (end != v && *end) {
            const char *u = "KMGT", *q = strchr(u, toupper((unsigned char)*end));
            if (q && end[1] == '\0') m *= pow(1024.0, (double)(q - u + 1)), end++;
        }
        if (end == v || *end != '\0' || !(m >= 0.0) || !isfinite(m) || !isdigit((unsigned char)v[0]))
            return cli_error(CLI_EXIT_USAGE, f, "expected bytes >= 0 with an optional K, M, G or T "
                             "(0 = no limit), got '%s'", v);
        a->max_memory = m;
        return 0;
    }
    if (!strcmp(f, "--cell")) {
        a->has_cell = 1;
        return cli_real(f, v, 0.0, 1, DBL_MAX, "a number > 0", &a->cell);
    }
    if (!strcmp(f, "--band")) return cli_int(f, v, 1, EX_RIO_MAX_BANDS, "a band number 1..65535", &a->band);
    if (!strcmp(f, "--zscale")) {
        if (cli_real(f, v, -CLI_FLT_MAX, 0, CLI_FLT_MAX, "a non-zero number", &a->zscale)) return CLI_EXIT_USAGE;
        if ((float)a->zscale == 0.0f)
            return cli_error(CLI_EXIT_USAGE, f, "expected a non-zero number, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--nodata")) {
        a->has_nodata = 1;
        return cli_real(f, v, -CLI_FLT_MAX, 0, CLI_FLT_MAX, "a finite number", &a->nodata);
    }
    if (!strcmp(f, "--dirs")) a->has_dirs = 1;
    if (!strcmp(f, "--dirs")) return cli_int(f, v, 1, CLI_MAX_DIRS, "an integer 1..65536", &a->dirs);
    if (!strcmp(f, "--degrees")) { a->degrees = 1; return 0; }
    if (!strcmp(f, "--quiet")) { a->quiet = 1; return 0; }
    if (!strcmp(f, "--border")) {
        if (!strcmp(v, "open")) a->border = HFVIS_BORDER_OPEN;
        else if (!strcmp(v, "clamp")) a->border = HFVIS_BORDER_CLAMP;
        else if (!strcmp(v, "wrap")) a->border = HFVIS_BORDER_WRAP;
        else return cli_error(CLI_EXIT_USAGE, f, "expected open, clamp or wrap, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--border-cells"))
        return cli_int(f, v, 1, HFVIS_IMAGE_MAX_DIM, "an integer 1..1048576", &a->border_cells);
    if (!strcmp(f, "--sky")) {
        a->has_sky = 1;
        return cli_real(f, v, 0.0, 0, CLI_FLT_MAX, "a radiance >= 0", &a->sky);
    }
    if (!strcmp(f, "--albedo")) {
        a->has_albedo = 1;
        return cli_real(f, v, 0.0, 0, CLI_FLT_MAX, "an albedo >= 0", &a->albedo);
    }
    if (!strcmp(f, "--sun-irradiance")) {
        a->has_sun_irradiance = 1;
        return cli_real(f, v, 0.0, 0, CLI_FLT_MAX, "an irradiance >= 0", &a->sun_irradiance);
    }
    if (!strcmp(f, "--albedo-map")) { a->albedo_map = v; return 0; }
    if (!strcmp(f, "--emission")) { a->emission = v; return 0; }
    if (!strcmp(f, "--bounces")) {
        a->has_bounces = 1;
        return cli_int(f, v, 0, CLI_MAX_BOUNCES, "an integer 0..1000", &a->bounces);
    }
    if (!strcmp(f, "--output")) {
        if (!strcmp(v, "total")) a->output = OUT_TOTAL;
        else if (!strcmp(v, "direct")) a->output = OUT_DIRECT;
        else if (!strcmp(v, "indirect")) a->output = OUT_INDIRECT;
        else return cli_error(CLI_EXIT_USAGE, f, "expected total, direct or indirect, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--fraction")) { a->fraction = 1; return 0; }
    if (!strcmp(f, "--stats")) { a->stats = 1; return 0; }
    if (!strcmp(f, "--sun-azimuth")) {
        a->has_sun_azimuth = 1;
        return cli_real(f, v, -DBL_MAX, 0, DBL_MAX, "a finite angle in degrees", &a->sun_azimuth);
    }
    if (!strcmp(f, "--sun-elevation")) {
        a->has_sun_elevation = 1;
        return cli_real(f, v, -90.0, 0, 90.0, "degrees in -90..90", &a->sun_elevation);
    }
    if (!strcmp(f, "--sun-radius")) {
        a->has_sun_radius = 1;
        return cli_real(f, v, 0.0, 0, 90.0, "degrees in 0..90", &a->sun_radius);
    }
    if (!strcmp(f, "--env")) { a->env = v; return 0; }
    if (!strcmp(f, "--observer-height"))
        return cli_real(f, v, 0.0, 0, DBL_MAX, "a height >= 0", &a->observer_height);
    if (!strcmp(f, "--target-height"))
        return cli_real(f, v, 0.0, 0, DBL_MAX, "a height >= 0", &a->target_height);
    if (!strcmp(f, "--max-distance"))
        return cli_real(f, v, 0.0, 0, DBL_MAX, "a distance >= 0", &a->max_distance);
    if (!strcmp(f, "--exact")) { a->exact = 1; return 0; }
    if (!strcmp(f, "--window")) { /* X0,Y0,W,H in cells; clipped to the raster when it is read */
        long n[4];
        const char *p = v;
        char *end;
        int k;
        for (k = 0; k < 4; k++, p = end + 1) {
            errno = 0;
            n[k] = strtol(p, &end, 10);
            if (end == p || errno == ERANGE || n[k] < -(long)INT_MAX / 2 || n[k] > (long)INT_MAX / 2 ||
                (k >= 2 && n[k] < 1) || *end != (k < 3 ? ',' : '\0'))
                return cli_error(CLI_EXIT_USAGE, f, "expected X0,Y0,W,H (cells: first column and row, "
                                 "width and height >= 1), got '%s'", v);
        }
        a->has_window = 1;
        a->win_x = (int)n[0], a->win_y = (int)n[1], a->win_w = (int)n[2], a->win_h = (int)n[3];
        return 0;
    }
    if (!strcmp(f, "--res")) return cli_int(f, v, 1, CLI_MAX_RES, "an integer 1..2048", &a->res);
    if (!strcmp(f, "--max-vertices"))
        return cli_int(f, v, 1, 1000000, "an integer 1..1000000", &a->max_vertices);
    if (!strcmp(f, "--padding")) return cli_real(f, v, 0.0, 0, 1.0, "a fraction in 0..1", &a->padding);
    if (!strcmp(f, "--open")) { a->open_mesh = 1; return 0; }
    if (!strcmp(f, "--mode")) {
        if (!strcmp(v, "surface")) a->vox_mode = VOX_SURFACE;
        else if (!strcmp(v, "conservative")) a->vox_mode = VOX_CONSERVATIVE;
        else if (!strcmp(v, "solid")) a->vox_mode = VOX_SOLID;
        else return cli_error(CLI_EXIT_USAGE, f, "expected surface, conservative or solid, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--axis")) {
        static const char *const names[] = {"", "dominant", "all", "x", "y", "z"};
        int k;
        for (k = AXIS_DOMINANT; k <= AXIS_Z; k++)
            if (!strcmp(v, names[k])) { a->vox_axis = k; return 0; }
        return cli_error(CLI_EXIT_USAGE, f, "expected dominant, all, x, y or z, got '%s'", v);
    }
    if (a->cmd == CMD_VISFIELD) {
        int r = cli_set_vf(a, f, v);
        if (r >= 0) return r;
    }
    {
        int r = cli_set_volgi(a, f, v);
        if (r >= 0) return r;
    }
    {
        int r = cli_set_gi(a, f, v);
        if (r >= 0) return r;
        if (a->cmd == CMD_SSAO && (r = cli_set_ssao(a, f, v)) >= 0) return r;
    }
    if (a->cmd == CMD_VOXELIZE) { /* --method of voxelize */
        if (!strcmp(v, "pixel")) a->vox_method = HFVIS_VOXELIZE_PIXEL_RULE;
        else if (!strcmp(v, "slicing")) a->vox_method = HFVIS_VOXELIZE_GS_SLICING;
        else if (!strcmp(v, "clipping")) a->vox_method = HFVIS_VOXELIZE_FRAGMENT_CLIPPING;
        else return cli_error(CLI_EXIT_USAGE, f, "expected pixel, slicing or clipping, got '%s'", v);
        return 0;
    }
    /* --method */
    if (!strcmp(v, "prefix")) a->method = HFVIS_ENV_PREFIX;
    else if (!strcmp(v, "lp")) a->method = HFVIS_ENV_LP_TABLE;
    else return cli_error(CLI_EXIT_USAGE, f, "expected prefix or lp, got '%s'", v);
    return 0;
}

/* --window: the combinations a piece cannot honour; 0 or CLI_EXIT_USAGE (reported). */
static int cli_check_window(const cli_args *a)
{
    if (a->cmd == CMD_OPENNESS ? !(a->radius > 0.0) : !(a->max_distance > 0.0))
        return cli_error(CLI_EXIT_USAGE, "--window", "needs a finite %s: without it a receiver's "
                         "horizon depends on the whole field, so no window of it can be computed "
                         "from the window and a halo", a->cmd == CMD_OPENNESS ? "--radius R" : "--max-distance R");
    if (a->has_dir_range || a->out_partial)
        return cli_error(CLI_EXIT_USAGE, "--window", "cannot be combined with --dir-range");
    if (a->split) return cli_error(CLI_EXIT_USAGE, "--window", "cannot be combined with --split");
    if (a->out_pgm)
        return cli_error(CLI_EXIT_USAGE, a->out, "a piece keeps its values exactly: write .pfm, .tif, "
                         ".bil/.flt or .asc ('hfvis mosaic' writes the .pgm)");
    if (a->border == HFVIS_BORDER_WRAP)
        return cli_error(CLI_EXIT_USAGE, "--window", "--border wrap joins opposite edges of the whole "
                         "raster: not with a window");
    if (a->albedo_map || a->emission)
        return cli_error(CLI_EXIT_USAGE, "--window", "cannot be combined with %s (a map of the whole "
                         "raster)", a->albedo_map ? "--albedo-map" : "--emission");
    return 0;
}

/* Returns CLI_RUN, or the exit status after printing help (0) or a usage error (2). */
static int cli_parse(int argc, char **argv, cli_args *a)
{
    int i, c, positional_only = 0;
    memset(a, 0, sizeof *a);
    a->cell = 1.0; a->zscale = 1.0; a->dirs = 16; a->sky = 1.0; a->albedo = 1.0;
    a->max_memory = cli_default_max_memory();
    a->border = HFVIS_BORDER_OPEN; a->method = HFVIS_ENV_PREFIX;
    a->bounces = 1; a->sun_irradiance = CLI_PI; a->output = OUT_TOTAL;
    a->order = 4; a->subsample = 1;
    a->ssao_method = SSAO_FFAO; a->ssao_depth = SSAO_DEPTH_LINEAR; a->ssao_fov = 60.0;
    a->ssao_guard = -1;
    cli_volgi_defaults(a);
    cli_lk_defaults(a);
    if (argc < 2) return cli_error(CLI_EXIT_USAGE, "usage", "missing COMMAND (try 'hfvis --help')");
    if (!strcmp(argv[1], "-h") || !strcmp(argv[1], "--help") || !strcmp(argv[1], "help")) {
        if (argc > 2 && strcmp(argv[1], "help") == 0) {
            for (c = 0; c < CMD_COUNT; c++)
                if (!strcmp(argv[2], cli_cmd_names[c])) {
                    printf("%s%s%s", cli_cmd_help[c], cli_shared_help, cli_shared_help2);
                    return 0;
                }
            return cli_error(CLI_EXIT_USAGE, argv[2], "unknown command (try 'hfvis --help')");
        }
        printf("%s%s%s", cli_usage, cli_shared_help, cli_shared_help2);
        return 0;
    }
    for (c = 0; c < CMD_COUNT && strcmp(argv[1], cli_cmd_names[c]); c++) {}
    if (c == CMD_COUNT) return cli_error(CLI_EXIT_USAGE, argv[1], "unknown command (try 'hfvis --help')");
    a->cmd = c;
    for (i = 2; i < argc; i++) {
        const char *arg = argv[i], *value = NULL, *eq;
        char name[64];
        size_t n, k;
        if (positional_only || arg[0] != '-' || arg[1] == '\0') {
            if (a->in) return cli_error(CLI_EXIT_USAGE, arg, "unexpected argument (only one IN)");
            a->in = arg;
            continue;
        }
        if (!strcmp(arg, "--")) { positional_only = 1; continue; }
        if (!strcmp(arg, "-h") || !strcmp(arg, "--help")) {
            printf("%s%s%s", cli_cmd_help[a->cmd], cli_shared_help, cli_shared_help2);
            return 0;
        }
        eq = strchr(arg, '=');
        n = eq ? (size_t)(eq - arg) : strlen(arg);
        if (n >= sizeof name) n = sizeof name - 1;
        memcpy(name, arg, n);
        name[n] = '\0';
        for (k = 0; k < sizeof cli_flags / sizeof cli_flags[0]; k++)
            if (!strcmp(name, cli_flags[k].name)) break;
        if (k == sizeof cli_flags / sizeof cli_flags[0])
            return cli_error(CLI_EXIT_USAGE, name, "unknown option (see 'hfvis %s --help')",
                             cli_cmd_names[a->cmd]);
        if ((CLI_ONLY(a->cmd) & CLI_P2) && !strcmp(name, "--window"))
            return cli_error(CLI_EXIT_USAGE, name, "'%s' sweeps whole lattice lines with the [P2] "
                             "hull tree, which honours --max-distance but computes no windows; run "
                             "it whole (or split it with --dir-range)", cli_cmd_names[a->cmd]);
        if (!(cli_flags[k].commands & CLI_ONLY(a->cmd)))
            return cli_error(CLI_EXIT_USAGE, name, "not an option of '%s' (see 'hfvis %s --help')",
                             cli_cmd_names[a->cmd], cli_cmd_names[a->cmd]);
        if (cli_flags[k].has_value) {
            if (eq) value = eq + 1;
            else if (i + 1 < argc) value = argv[++i];
            else return cli_error(CLI_EXIT_USAGE, name, "missing value");
        } else if (eq) {
            return cli_error(CLI_EXIT_USAGE, name, "takes no value");
        }
        if (cli_set(a, name, value)) return CLI_EXIT_USAGE;
    }
    if (!a->in && !(a->cmd == CMD_VOLGI && a->room))
        return cli_error(CLI_EXIT_USAGE, cli_cmd_names[a->cmd], "missing input file IN");
    if (!a->out) return cli_error(CLI_EXIT_USAGE, cli_cmd_names[a->cmd], "missing -o OUT");
    if (a->sky * a->albedo > CLI_FLT_MAX) /* the sky light's scale: outputs would be inf */
        return cli_error(CLI_EXIT_USAGE, "--sky/--albedo", "%g x %g exceeds the float range (3.4e38)",
                         a->sky, a->albedo);
    if (a->has_range && !a->out_pgm)
        return cli_error(CLI_EXIT_USAGE, "--range", a->out_partial ? "applies to 'hfvis sum', not to "
                         "a partial result" : "applies only to .pgm output");
    if (a->out_partial && !a->has_dir_range)
        return cli_error(CLI_EXIT_USAGE, a->out, "a .hfvs partial result needs --dir-range A:B");
    if (a->has_dir_range) {
        if (!a->out_partial)
            return cli_error(CLI_EXIT_USAGE, a->out, "a --dir-range run writes a partial result: use a "
                             ".hfvs name (then 'hfvis sum')");
        if (!(a->dir_begin < a->dir_end && a->dir_end <= a->dirs))
            return cli_error(CLI_EXIT_USAGE, "--dir-range", "expected A:B with 0 <= A < B <= K = %d, got "
                             "%d:%d", a->dirs, a->dir_begin, a->dir_end);
        if (a->stats)
            return cli_error(CLI_EXIT_USAGE, "--stats", "cannot be combined with --dir-range");
    }
    if (a->cmd == CMD_SHADOW && !a->has_sun_azimuth)
        return cli_error(CLI_EXIT_USAGE, "shadow", "missing --sun-azimuth DEG");
    if (a->cmd == CMD_SHADOW && !a->has_sun_elevation)
        return cli_error(CLI_EXIT_USAGE, "shadow", "missing --sun-elevation DEG");
    if (a->cmd == CMD_VIEWSHED && !a->has_observer)
        return cli_error(CLI_EXIT_USAGE, "viewshed", "missing --observer X,Y");
    if (a->cmd == CMD_VOXELIZE) {
        const char *m = a->vox_mode == VOX_SOLID ? "solid" : "conservative";
        if (!a->res) return cli_error(CLI_EXIT_USAGE, "voxelize", "missing --res N");
        if (a->vox_mode != VOX_SURFACE && (a->vox_method != HFVIS_VOXELIZE_PIXEL_RULE || a->max_vertices))
            return cli_error(CLI_EXIT_USAGE, a->max_vertices ? "--max-vertices" : "--method",
                             "applies only to --mode surface, not %s", m);
        if (a->vox_mode == VOX_CONSERVATIVE && a->vox_axis != AXIS_DEFAULT)
            return cli_error(CLI_EXIT_USAGE, "--axis", "does not apply to --mode conservative");
        if (a->vox_mode == VOX_SOLID && (a->vox_axis == AXIS_DOMINANT || a->vox_axis == AXIS_ALL))
            return cli_error(CLI_EXIT_USAGE, "--axis", "--mode solid takes x, y or z");
        if (a->open_mesh && a->vox_mode != VOX_SOLID)
            return cli_error(CLI_EXIT_USAGE, "--open", "applies only to --mode solid");
        if (a->max_vertices && a->vox_method == HFVIS_VOXELIZE_PIXEL_RULE)
            return cli_error(CLI_EXIT_USAGE, "--max-vertices", "needs --method slicing or clipping");
    }
    if (a->cmd == CMD_LIGHT && !a->env)
        return cli_error(CLI_EXIT_USAGE, "light", "missing --env ENV.pfm");
    if (a->cmd == CMD_INDIRECT) {
        int sun = a->has_sun_azimuth || a->has_sun_elevation;
        if (a->has_sun_azimuth && !a->has_sun_elevation)
            return cli_error(CLI_EXIT_USAGE, "--sun-azimuth", "needs --sun-elevation DEG");
        if (a->has_sun_elevation && !a->has_sun_azimuth)
            return cli_error(CLI_EXIT_USAGE, "--sun-elevation", "needs --sun-azimuth DEG");
        if (!sun && (a->has_sun_radius || a->has_sun_irradiance || a->math))
            return cli_error(CLI_EXIT_USAGE, a->has_sun_radius ? "--sun-radius" :
                             a->has_sun_irradiance ? "--sun-irradiance" : "--math",
                             "needs a sun (--sun-azimuth and --sun-elevation)");
        if (a->has_albedo && a->albedo_map)
            return cli_error(CLI_EXIT_USAGE, "--albedo-map", "cannot be combined with --albedo");
        if (a->has_sky && a->env)
            return cli_error(CLI_EXIT_USAGE, "--env", "cannot be combined with --sky");
        if (a->output == OUT_DIRECT && a->has_bounces)
            return cli_error(CLI_EXIT_USAGE, "--bounces", "has no effect with --output direct");
        if (a->output == OUT_INDIRECT && a->bounces < 1)
            return cli_error(CLI_EXIT_USAGE, "--output indirect", "needs --bounces >= 1");
    }
    if (a->has_window && cli_check_window(a)) return CLI_EXIT_USAGE;
    if (a->cmd == CMD_GI && cli_check_gi(a)) return CLI_EXIT_USAGE;
    if (a->cmd == CMD_VOLGI && cli_check_volgi(a)) return CLI_EXIT_USAGE;
    if (a->cmd == CMD_VISFIELD && cli_check_vf(a)) return CLI_EXIT_USAGE;
    if (a->cmd == CMD_MESHAO && cli_check_lk(a)) return CLI_EXIT_USAGE;
    return CLI_RUN;
}

/* ------------------------------------------------------------------------------------------ */
/* running a command                                                                          */
/* ------------------------------------------------------------------------------------------ */

/* The georeference of a raster IN, carried to a raster OUT (cli_save); the rows of IN, to
 * recognise stacked output planes. The CLI's one piece of global state besides the bar. */
static ex_georef cli_geo;
static int cli_in_height;
static float *cli_alloc(size_t a, size_t b, size_t c);

/* A --window run (docs/tiles.md): the window of the raster it writes, the grid it loads (the
 * window and a halo, clipped to the raster), and what its piece's sidecar records. */
#define CLI_PIECE_TAG_MAX 2048 /* a piece's run tag: the command, the input's identity, ~30 parameters */
typedef struct cli_window {
    int active;                 /* this run computes one piece */
    int halo;                   /* cells of halo (cli_halo), -1 unknown */
    int x0, y0, w, h;           /* the window, clipped to the raster */
    int gx0, gy0, gw, gh;       /* the grid loaded: window + halo, clipped */
    int ext_w, ext_h;           /* the raster */
    char in_id[64], crs[64], gt[160], nodata[80];
    char tag[CLI_PIECE_TAG_MAX];
} cli_window;
static cli_window cli_win = { 0, -1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, "", "", "", "", "" };
static int cli_window_plan(const cli_args *a, ex_rio_reader *r, const char *path, double cell);

/* Load a GeoTIFF, ASC or EHdr IN (band --band): NoData -> NaN, the georeference kept in cli_geo,
 * *cell from it (geographic CRS refused unless --cell), --cell overriding with a note. */
static int cli_load_raster(const cli_args *a, float **z, int *w, int *h, double *cell)
{
    ex_rio_reader r;
    float *px;
    double rc_cell = 0.0;
    char why[256];
    int gx = 0, gy = 0, gw, gh;
    if ((ex_rio_format_of(a->in) ? ex_rio_open(&r, a->in) : ex_rio_open_netpbm(&r, a->in)) != 0)
        return cli_error(CLI_EXIT_ERROR, a->in, "%s", r.err);
    if (r.format == EX_RIO_NETPBM && r.bands != 1) {
        ex_rio_close(&r);
        return cli_error(CLI_EXIT_ERROR, a->in, "a height field has one channel, this image has %d", 3);
    }
    if ((a->band ? a->band : 1) > r.bands) {
        cli_error(CLI_EXIT_ERROR, a->in, "--band %d: the raster has %d band%s", a->band, r.bands,
                  r.bands == 1 ? "" : "s");
        ex_rio_close(&r);
        return CLI_EXIT_ERROR;
    }
    if (!cli_win.active && (r.width > HFVIS_IMAGE_MAX_DIM || r.height > HFVIS_IMAGE_MAX_DIM ||
        (size_t)r.width * (size_t)r.height > HFVIS_IMAGE_MAX_VALUES)) {
        cli_error(CLI_EXIT_ERROR, a->in, "%s: %d x %d cells exceed the limit of 2^28 values",
                  hfvis_status_string(HFVIS_ERR_LIMIT), r.width, r.height);
        ex_rio_close(&r);
        return CLI_EXIT_ERROR;
    }
    if (r.geo.has_transform) {
        if (r.geo.crs == EX_RIO_CRS_GEOGRAPHIC && !a->has_cell) {
            char crs[32] = "";
            if (r.geo.epsg) snprintf(crs, sizeof crs, ", EPSG:%d", r.geo.epsg);
            cli_error(CLI_EXIT_ERROR, a->in, "geographic coordinates (cells in degrees%s): reproject to "
                      "metres first, e.g. gdalwarp -t_srs EPSG:32633 (your UTM zone) -r bilinear IN out.tif, "
                      "or give --cell in metres", crs);
            ex_rio_close(&r);
            return CLI_EXIT_ERROR;
        }
        if (ex_georef_cell(&r.geo, &rc_cell, why) != 0) {
            cli_error(CLI_EXIT_ERROR, a->in, "%s", why);
            ex_rio_close(&r);
            return CLI_EXIT_ERROR;
        }
        if (!a->has_cell) *cell = rc_cell;
        else if (!a->quiet && a->cell != rc_cell)
            fprintf(stderr, "hfvis: note: --cell %g overrides the cell size %.10g of %s\n", a->cell, rc_cell,
                    a->in);
    } else if (!a->has_cell && !a->quiet) {
        fprintf(stderr, "hfvis: note: %s has no georeference: cell size 1 (give --cell)\n", a->in);
    }
    gw = r.width, gh = r.height;
    if (cli_win.active) { /* the window and its halo only (estimate and refusal before allocating) */
        int rc = cli_window_plan(a, &r, a->in, *cell);
        if (rc != 0) {
            ex_rio_close(&r);
            return rc;
        }
        gx = cli_win.gx0, gy = cli_win.gy0, gw = cli_win.gw, gh = cli_win.gh;
    }
    px = cli_alloc((size_t)gw, (size_t)gh, 1);
    if (!px) {
        ex_rio_close(&r);
        return cli_status(a->in, HFVIS_ERR_OUT_OF_MEMORY, 0);
    }
    r.nodata_to_nan = 1;
    if (ex_rio_read(&r, a->band ? a->band - 1 : 0, gx, gy, gw, gh, px, gw) != 0) {
        cli_error(CLI_EXIT_ERROR, a->in, "%s", r.err);
        free(px);
        ex_rio_close(&r);
        return CLI_EXIT_ERROR;
    }
    *z = px; *w = gw; *h = gh;
    ex_georef_free(&cli_geo);
    cli_geo = r.geo; /* moved: the reader no longer owns it */
    memset(&r.geo, 0, sizeof r.geo);
    if (cli_win.active) ex_georef_shift(&cli_geo, cli_win.x0, cli_win.y0); /* the piece's origin */
    ex_rio_close(&r);
    return 0;
}

/* What a run is expected to cost before it allocates: bytes at its peak and units of work. */
typedef struct cli_cost {
    double bytes, work;
    const char *unit;
} cli_cost;

/* The estimate of a command on a w x h input (height fields, ssao) or from its flags (meshes,
 * volumes). Height fields: input, output, the sweep's lattice (about min(W^2 + H^2,
 * (W + H)^2/2) nodes of 8-byte heights, 12-byte normals and 8 bytes a channel), the grid
 * accumulator; the work is K sweeps over the lattice. A model of the allocations, not a bound
 * on them (the file buffers of the codecs come on top for a moment). */
static cli_cost cli_estimate(const cli_args *a, int w, int h, int channels)
{
    cli_cost c;
    double n = (double)w * (double)h, W = (double)w, H = (double)h, K = (double)a->dirs, lat, ch = channels;
    double diag2 = W * W + H * H, thin = (W + H) * (W + H) / 2.0;
    lat = diag2 < thin ? diag2 : thin;
    c.bytes = 0.0, c.work = 0.0, c.unit = "lattice nodes swept";
    switch (a->cmd) {
    case CMD_VOXELIZE:
        c.bytes = pow((double)a->res, 3.0), c.work = c.bytes, c.unit = "voxels";
        return c;
    case CMD_VOLGI:
        c.bytes = pow((double)a->res, 3.0) * 4.0 * 16.0 + (double)a->vg_width * (double)a->vg_height * 12.0;
        c.work = pow((double)a->res, 3.0) * (double)a->iterations, c.unit = "voxel updates";
        return c;
    case CMD_VISFIELD:
        if (a->vf_ao) {
            c.bytes = (double)a->vg_width * (double)a->vg_height * 4.0;
            c.work = c.bytes / 4.0 * (double)(a->vf_rays ? a->vf_rays : 64), c.unit = "rays";
        } else {
            double P = (double)(a->vf_positions ? a->vf_positions : 82), D = (double)(a->has_dirs ? a->dirs : 16);
            c.bytes = P * 2.0 * D * D * 4.0, c.work = P * 2.0 * D * D, c.unit = "direction texels";
        }
        return c;
    case CMD_MESHAO:
        c.bytes = (double)a->lk_width * (double)a->lk_height * 16.0;
        c.work = (double)a->lk_width * (double)a->lk_height * (double)(a->lk_rays ? a->lk_rays : 64);
        c.unit = "rays";
        return c;
    case CMD_SSAO:
        c.bytes = n * 8.0, c.work = n * (a->has_dirs ? K : 16.0) * (W > H ? W : H) / 4.0, c.unit = "depth samples";
        return c;
    case CMD_VIEWSHED:
        c.bytes = n * 8.0, c.work = (W + H) * (W > H ? W : H), c.unit = "line-of-sight steps";
        return c;
    case CMD_HORIZON: ch = 4.0; break;
    case CMD_GI: c.bytes = n * 4.0 * 64.0; break; /* the NS09 pyramids and SH planes */
    default: break;
    }
    c.bytes += n * 4.0 + n * 4.0 * (a->cmd == CMD_HORIZON ? K : (double)channels); /* in, out */
    c.bytes += lat * (8.0 + 12.0 + 8.0 * ch) + n * (12.0 + 8.0 * ch);             /* sweep */
    if (a->cmd == CMD_VISIBILITY || a->cmd == CMD_INDIRECT) c.bytes += lat * 8.0 * ch;
    c.work = K * (n + lat / 4.0);
    if (a->cmd == CMD_INDIRECT) c.work *= (double)(a->bounces + 1);
    if (a->cmd == CMD_VISIBILITY && a->fraction) c.work *= 2.0;
    return c;
}

/* The channels of a height-field command's output, for the estimate before anything is loaded:
 * light has ENV's, indirect the most of ENV, --albedo-map and --emission (PGM or PFM: their
 * headers only are read), normals 3, the rest 1. A header that cannot be read counts 1; the
 * load reports it. */
static int cli_out_channels(const cli_args *a)
{
    const char *maps[3] = {a->env, NULL, NULL};
    int channels = a->cmd == CMD_NORMALS ? 3 : 1, i;
    if (a->cmd != CMD_LIGHT && a->cmd != CMD_INDIRECT) return channels;
    if (a->cmd == CMD_INDIRECT) maps[1] = a->albedo_map, maps[2] = a->emission;
    for (i = 0; i < 3; i++) {
        ex_rio_reader r;
        if (!maps[i] || ex_rio_open_netpbm(&r, maps[i]) != 0) continue;
        if (r.bands > channels) channels = r.bands;
        ex_rio_close(&r);
    }
    return channels;
}

static int cli_window_side(const cli_args *a, int halo, int w, int h, int channels);
/* Print the estimate with the progress bar or the --progress lines, and refuse a run past
 * --max-memory (0 = none), suggesting a window size when the run can be tiled. */
static int cli_check_cost(const cli_args *a, int w, int h, int channels)
{
    const char *cmd = cli_cmd_names[a->cmd];
    cli_cost c = cli_estimate(a, w, h, channels);
    if (!a->quiet && (a->progress_lines || cli_stderr_is_terminal()))
        fprintf(stderr, "%s: estimate %.3g MiB, %.3g %s\n", cmd, c.bytes / 1048576.0, c.work, c.unit);
    if (a->max_memory > 0.0 && c.bytes > a->max_memory) {
        char hint[200] = "";
        if (cli_win.halo >= 0) { /* tiles: the largest square window whose grid (+ halo) fits */
            int ww = cli_win.active ? cli_win.ext_w : w, hh = cli_win.active ? cli_win.ext_h : h;
            int side = cli_window_side(a, cli_win.halo, ww, hh, channels);
            if (side > 0)
                snprintf(hint, sizeof hint, "; windows of %d x %d cells fit (halo %d; --window X0,Y0,%d,%d, "
                         "examples/tiles.sh)", side, side, cli_win.halo, side, side);
            else
                snprintf(hint, sizeof hint, "; not even a 1-cell window with its halo of %d cells fits: "
                         "lower --max-distance", cli_win.halo);
        } else if (a->cmd < CMD_COUNT && (CLI_ONLY(a->cmd) & CLI_SWEEP)) {
            snprintf(hint, sizeof hint, ", or tile it: --max-distance R and --window (docs/tiles.md)");
        }
        return cli_error(CLI_EXIT_ERROR, cmd, "needs about %.3g MiB (%.3g %s), over --max-memory %.3g "
                         "MiB; raise --max-memory or make the run smaller (input, --dir-range, flags)%s",
                         c.bytes / 1048576.0, c.work, c.unit, a->max_memory / 1048576.0, hint);
    }
    return 0;
}

/* The halo of a window run, in cells: every input cell a receiver of the window can depend on
 * lies within it. The sweeps use the library's rule (hfvis_tile_halo: ceil(R / cell) plus the
 * cells of the gather and the normals, by ray mode); indirect multiplies the radius by the
 * bounces + 1 (bounce b gathers light that the terrain up to b R away received); openness
 * marches --radius, plus one cell for its bilinear taps. */
static int cli_halo(const cli_args *a, double cell)
{
    const hfvis_ray_mode rays = a->exact && a->cmd != CMD_VIEWSHED ? HFVIS_RAYS_EXACT : HFVIS_RAYS_LATTICE;
    double r = a->cmd == CMD_OPENNESS ? a->radius : a->max_distance, h;
    int halo;
    if (a->cmd == CMD_OPENNESS) {
        h = ceil(r / cell) + 1.0;
        return h < (double)HFVIS_IMAGE_MAX_DIM ? (int)h : HFVIS_IMAGE_MAX_DIM;
    }
    if (a->cmd == CMD_INDIRECT) r *= (double)((a->output == OUT_DIRECT ? 0 : a->bounces) + 1);
    halo = hfvis_tile_halo(r, cell, rays);
    return halo >= 0 && halo < HFVIS_IMAGE_MAX_DIM ? halo : HFVIS_IMAGE_MAX_DIM;
}

/* The largest side S of a square window whose grid, S + 2 halo (clipped to the w x h raster) on
 * each axis, fits --max-memory by cli_estimate; 0 if none does. */
static int cli_window_side(const cli_args *a, int halo, int w, int h, int channels)
{
    int lo = 0, hi = w > h ? w : h;
    while (lo < hi) {
        int mid = lo + (hi - lo + 1) / 2;
        double gw = (double)mid + 2.0 * halo, gh = gw;
        if (gw > w) gw = w;
        if (gh > h) gh = h;
        if (cli_estimate(a, (int)gw, (int)gh, channels).bytes <= a->max_memory) lo = mid;
        else hi = mid - 1;
    }
    return lo;
}

/* A file's identity without reading it whole: its size and the CRC-32 of its first and last
 * 64 KiB (the header, the first and last rows or strips; a TIFF's directory). */
static int cli_file_id(const char *path, char *out, size_t cap)
{
    enum { BLOCK = 65536 };
    FILE *f = fopen(path, "rb");
    unsigned char *buf = (unsigned char *)malloc(BLOCK);
    uint32_t crc = 0;
    long len = -1;
    size_t n;
    int ok = f && buf && fseek(f, 0, SEEK_END) == 0 && (len = ftell(f)) >= 0 && fseek(f, 0, SEEK_SET) == 0;
    if (ok) {
        n = fread(buf, 1, BLOCK, f);
        crc = hfvis_crc32(crc, buf, n);
        if (len > BLOCK) {
            ok = fseek(f, len - BLOCK, SEEK_SET) == 0 && fread(buf, 1, BLOCK, f) == BLOCK;
            crc = hfvis_crc32(crc, buf, BLOCK);
        }
    }
    if (f) fclose(f);
    free(buf);
    snprintf(out, cap, "%lx-%08lx", (unsigned long)len, (unsigned long)crc);
    return ok ? 0 : -1;
}

/* A --window run, once the raster's header is read: clip the window, add the halo, estimate the
 * grid's memory (refused with a window size that fits) and record the input's identity. */
static int cli_window_plan(const cli_args *a, ex_rio_reader *r, const char *path, double cell)
{
    long long x0 = a->win_x, y0 = a->win_y, x1 = x0 + a->win_w, y1 = y0 + a->win_h, h;
    const ex_georef *g = &r->geo;
    uint32_t crs = 0;
    cli_window *v = &cli_win;
    if (x0 < 0) x0 = 0;
    if (y0 < 0) y0 = 0;
    if (x1 > r->width) x1 = r->width;
    if (y1 > r->height) y1 = r->height;
    if (x0 >= x1 || y0 >= y1)
        return cli_error(CLI_EXIT_ERROR, "--window", "%d,%d,%d,%d lies outside the raster (%d x %d cells)",
                         a->win_x, a->win_y, a->win_w, a->win_h, r->width, r->height);
    v->halo = cli_halo(a, cell);
    h = v->halo;
    v->x0 = (int)x0, v->y0 = (int)y0, v->w = (int)(x1 - x0), v->h = (int)(y1 - y0);
    v->ext_w = r->width, v->ext_h = r->height;
    v->gx0 = (int)(x0 - h > 0 ? x0 - h : 0), v->gy0 = (int)(y0 - h > 0 ? y0 - h : 0);
    v->gw = (int)((x1 + h < r->width ? x1 + h : r->width) - v->gx0);
    v->gh = (int)((y1 + h < r->height ? y1 + h : r->height) - v->gy0);
    if (cli_check_cost(a, v->gw, v->gh, cli_out_channels(a)) != 0) return CLI_EXIT_ERROR;
    if ((size_t)v->gw * (size_t)v->gh > HFVIS_IMAGE_MAX_VALUES || v->gw > HFVIS_IMAGE_MAX_DIM ||
        v->gh > HFVIS_IMAGE_MAX_DIM)
        return cli_error(CLI_EXIT_ERROR, "--window", "%s: the window and its halo of %d cells, %d x %d, "
                         "exceed 2^28 values or 2^20 rows or columns; use windows of at most %d x %d cells",
                         hfvis_status_string(HFVIS_ERR_LIMIT), v->halo, v->gw, v->gh,
                         16384 - 2 * v->halo > 1 ? 16384 - 2 * v->halo : 1,
                         16384 - 2 * v->halo > 1 ? 16384 - 2 * v->halo : 1);
    if (cli_file_id(path, v->in_id, sizeof v->in_id) != 0)
        return cli_error(CLI_EXIT_ERROR, path, "cannot read it to fingerprint it");
    if (g->geokeys) crs = hfvis_crc32(crs, g->geokeys, g->n_geokeys * sizeof *g->geokeys);
    if (g->geodoubles) crs = hfvis_crc32(crs, g->geodoubles, g->n_geodoubles * sizeof *g->geodoubles);
    if (g->geoascii) crs = hfvis_crc32(crs, g->geoascii, g->n_geoascii);
    if (g->prj) crs = hfvis_crc32(crs, g->prj, strlen(g->prj));
    snprintf(v->crs, sizeof v->crs, "%d:%d:%08lx", g->crs, g->epsg, (unsigned long)crs);
    if (g->has_transform)
        snprintf(v->gt, sizeof v->gt, "%a,%a,%a,%a,%a,%a", g->gt[0], g->gt[1], g->gt[2], g->gt[3],
                 g->gt[4], g->gt[5]);
    else
        strcpy(v->gt, "none");
    if (g->has_nodata) snprintf(v->nodata, sizeof v->nodata, "%s", g->nodata_text);
    else strcpy(v->nodata, "none");
    return 0;
}

/* Load IN as a one-channel height field; --nodata values become NaN, the rest are scaled.
 * *cell: --cell, else the raster's cell size, else 1 (with a note unless --quiet). */
static int cli_load_heights(const cli_args *a, float **z, int *w, int *h, double *cell)
{
    hfvis_image_info info;
    float *px = NULL, zscale = (float)a->zscale, nodata = (float)a->nodata;
    double top = 0.0; /* largest |height| */
    size_t i, n;
    hfvis_status s;
    *cell = a->cell;
    if (ex_rio_format_of(a->in) || cli_win.active) {
        int rc = cli_load_raster(a, &px, w, h, cell);
        if (rc != 0) return rc;
    } else {
        if (a->band > 1)
            return cli_error(CLI_EXIT_ERROR, a->in, "--band %d: a PFM/PGM height field has one band", a->band);
        errno = 0;
        s = hfvis_image_load(a->in, NULL, &px, &info);
        if (s != HFVIS_OK) return cli_status(a->in, s, errno);
        if (info.channels != 1) {
            hfvis_free(NULL, px);
            return cli_error(CLI_EXIT_ERROR, a->in, "a height field has one channel, this image has %d",
                             info.channels);
        }
        if (!a->has_cell && !a->quiet)
            fprintf(stderr, "hfvis: note: %s has no cell size: using 1 (give --cell)\n", a->in);
        *w = info.width; *h = info.height;
    }
    n = (size_t)*w * (size_t)*h; /* <= HFVIS_IMAGE_MAX_VALUES (decoder limit) */
    for (i = 0; i < n; i++) {
        float v = px[i];
        if (a->has_nodata && v == nodata) {
            px[i] = (float)NAN;
            continue;
        }
        px[i] = v * zscale;
        if (isfinite(v) && !isfinite(px[i])) { /* not a hole: refused, never silently one */
            hfvis_free(NULL, px);
            return cli_error(CLI_EXIT_ERROR, "--zscale", "%g times the value %g at (%lu, %lu) "
                             "exceeds the float range (3.4e38)", a->zscale, (double)v,
                             (unsigned long)(i % (size_t)*w), (unsigned long)(i / (size_t)*w));
        }
        if (fabs((double)px[i]) > top) top = fabs((double)px[i]);
    }
    /* heights in cells (z / cell, in double) and their squares must stay finite */
    if (top / *cell > CLI_MAX_RELIEF || *cell < DBL_MIN) {
        hfvis_free(NULL, px);
        return cli_error(CLI_EXIT_ERROR, "--cell", "%g is too small for heights up to %g: their ratio "
                         "must stay below %g (and the cell at least %g)", *cell, top, CLI_MAX_RELIEF,
                         DBL_MIN);
    }
    if (a->has_nodata && !cli_geo.has_nodata) { /* --nodata is the outputs' NoData too */
        cli_geo.has_nodata = 1;
        cli_geo.nodata = (double)nodata;
        snprintf(cli_geo.nodata_text, sizeof cli_geo.nodata_text, "%.9g", (double)nodata);
    }
    cli_in_height = *h;
    *z = px;
    return 0;
}

/* Allocate count floats, count = a*b*c with overflow check. */
static float *cli_alloc(size_t a, size_t b, size_t c)
{
    if (a == 0 || b == 0 || c == 0 || a > SIZE_MAX / b || a * b > SIZE_MAX / c ||
        a * b * c > SIZE_MAX / sizeof(float))
        return NULL;
    return (float *)calloc(a * b * c, sizeof(float)); /* zeros: a window run leaves cells unwritten */
}

/* Integral outputs (viewshed 0/1, visibility counts) go into the smallest integer GeoTIFF type
 * holding their values and NoData: the input's NoData when it is an integer, else (holes
 * present) one past the largest value. Returns 0 (and leaves o, g alone) to keep Float32. */
static int cli_integral_type(const cli_args *a, const float *px, size_t n, ex_georef *g,
                             ex_rio_write_options *o)
{
    static const int types[4][2] = { { EX_RIO_UINT, 8 }, { EX_RIO_UINT, 16 }, { EX_RIO_INT, 16 },
                                     { EX_RIO_INT, 32 } };
    double lo = 0.0, hi = 0.0, nd = 0.0;
    int holes = 0, want_nd, k;
    size_t i;
    if (!(a->cmd == CMD_VIEWSHED || (a->cmd == CMD_VISIBILITY && !a->fraction))) return 0;
    for (i = 0; i < n; i++) {
        double v = (double)px[i];
        if (isnan(v)) { holes = 1; continue; }
        if (v != floor(v) || fabs(v) > 2147483647.0) return 0;
        if (v < lo) lo = v;
        if (v > hi) hi = v;
    }
    want_nd = holes || g->has_nodata;
    if (g->has_nodata && isfinite(g->nodata) && g->nodata == floor(g->nodata)) nd = g->nodata;
    else if (g->has_nodata && !holes) want_nd = 0; /* a NaN or fractional NoData nobody needs */
    else if (want_nd) nd = hi + 1.0;
    for (k = 0; k < 4; k++) {
        double tlo = types[k][0] == EX_RIO_UINT ? 0.0 : -ldexp(1.0, types[k][1] - 1);
        double thi = types[k][0] == EX_RIO_UINT ? ldexp(1.0, types[k][1]) - 1.0 : ldexp(1.0, types[k][1] - 1) - 1.0;
        if (lo >= tlo && hi <= thi && (!want_nd || (nd >= tlo && nd <= thi))) break;
    }
    if (k == 4) return 0;
    o->kind = types[k][0];
    o->bits = types[k][1];
    o->predictor = 2;
    g->has_nodata = want_nd;
    if (want_nd) {
        g->nodata = nd;
        snprintf(g->nodata_text, sizeof g->nodata_text, "%.0f", nd);
    }
    return 1;
}

/* ------------------------------------------------------------------------------------------ */
/* writing: every file goes through hfvis_write_file, whose temporary name is kept here so that  */
/* SIGINT, SIGTERM and SIGHUP remove it (the handler unlinks it and re-raises the signal)        */
/* ------------------------------------------------------------------------------------------ */

#define CLI_TMP_CAP 4096 /* longest temporary name the handler can remove (PATH_MAX on Linux) */
static char cli_tmp_name[CLI_TMP_CAP];
static volatile sig_atomic_t cli_tmp_armed; /* cli_tmp_name names a file that may exist */

/* hfvis_write_options.on_temp: armed only after the name is complete, disarmed before it changes. */
static void cli_on_temp(void *user, const char *tmp)
{
    size_t n = tmp ? strlen(tmp) : 0;
    (void)user;
    cli_tmp_armed = 0;
    if (!tmp || n >= CLI_TMP_CAP) return;
    memcpy(cli_tmp_name, tmp, n + 1);
    cli_tmp_armed = 1;
}

#ifdef CLI_HAVE_SIGACTION
/* Async-signal-safe: unlink the temporary file, restore the default action and re-raise, so the
 * exit status says which signal ended the run (130 for SIGINT, 143 for SIGTERM in a shell). */
static void cli_on_signal(int sig)
{
    if (cli_tmp_armed) unlink(cli_tmp_name);
    signal(sig, SIG_DFL);
    raise(sig);
}

/* Install the handler for SIGINT, SIGTERM and SIGHUP, leaving an ignored signal ignored. */
static void cli_signals(void)
{
    static const int sigs[3] = { SIGINT, SIGTERM, SIGHUP };
    int i;
    for (i = 0; i < 3; i++) {
        struct sigaction sa, old;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = cli_on_signal;
        sigemptyset(&sa.sa_mask);
        if (sigaction(sigs[i], NULL, &old) == 0 && old.sa_handler == SIG_IGN) continue;
        sigaction(sigs[i], &sa, NULL);
    }
}
#else
static void cli_signals(void) {}
#endif

/* Write n bytes to path (hfvis_write_file with the temporary name recorded), freeing bytes. */
static hfvis_status cli_write(const char *path, unsigned char *bytes, size_t n, hfvis_status s)
{
    hfvis_write_options wo;
    wo.on_temp = cli_on_temp;
    wo.user = NULL;
    if (s == HFVIS_OK) s = hfvis_write_file(path, bytes, n, &wo);
    free(bytes);
    return s;
}

/* The library's savers, through cli_write: encode into memory (need bytes), then write. */
typedef hfvis_status (*cli_encoder)(const void *what, void *out, size_t cap, size_t *written);
static hfvis_status cli_write_encoded(const char *path, size_t need, cli_encoder encode, const void *what)
{
    unsigned char *buf = need ? (unsigned char *)malloc(need) : NULL;
    size_t written = 0;
    hfvis_status s;
    if (!buf) return need ? HFVIS_ERR_OUT_OF_MEMORY : HFVIS_ERR_INVALID_ARGUMENT;
    s = encode(what, buf, need, &written);
    return cli_write(path, buf, written, s);
}
typedef struct cli_image { /* the arguments of hfvis_pfm_encode / hfvis_pgm_range_encode */
    const float *px;
    int w, h, channels;
    ptrdiff_t stride;
    float lo, hi;
} cli_image;
typedef struct cli_voxels {
    const hfvis_volume_grid *grid;
    const uint8_t *occ;
} cli_voxels;
static hfvis_status cli_enc_pfm(const void *what, void *out, size_t cap, size_t *written)
{
    const cli_image *m = (const cli_image *)what;
    return hfvis_pfm_encode(m->px, m->w, m->h, m->channels, m->stride, out, cap, written);
}
static hfvis_status cli_enc_binvox(const void *what, void *out, size_t cap, size_t *written)
{
    const cli_voxels *v = (const cli_voxels *)what;
    return hfvis_binvox_encode(v->grid, v->occ, out, cap, written);
}
static hfvis_status cli_enc_visfield(const void *what, void *out, size_t cap, size_t *written)
{
    return hfvis_visfield_encode((const hfvis_visfield *)what, out, cap, written);
}
static hfvis_status cli_enc_partial(const void *what, void *out, size_t cap, size_t *written)
{
    return hfvis_partial_encode((const hfvis_partial *)what, out, cap, written);
}
static hfvis_status cli_pfm_save(const char *path, const float *px, int w, int h, int channels, ptrdiff_t stride)
{
    cli_image m;
    memset(&m, 0, sizeof m);
    m.px = px, m.w = w, m.h = h, m.channels = channels, m.stride = stride;
    return cli_write_encoded(path, hfvis_pfm_encode_size(w, h, channels), cli_enc_pfm, &m);
}
static hfvis_status cli_enc_pgm_range(const void *what, void *out, size_t cap, size_t *written)
{
    const cli_image *m = (const cli_image *)what;
    return hfvis_pgm_range_encode(m->px, m->w, m->h, m->stride, m->lo, m->hi, out, cap, written);
}
/* A NoData-safe 16-bit PGM with its range in the header (hfvis_pgm_range_encode). */
static hfvis_status cli_pgm_save(const char *path, const float *px, int w, int h, ptrdiff_t stride,
                                 float lo, float hi)
{
    cli_image m;
    memset(&m, 0, sizeof m);
    m.px = px, m.w = w, m.h = h, m.stride = stride, m.lo = lo, m.hi = hi;
    return cli_write_encoded(path, hfvis_pgm_range_encode_size(w, h, lo, hi), cli_enc_pgm_range, &m);
}
static hfvis_status cli_binvox_save(const char *path, const hfvis_volume_grid *grid, const uint8_t *occ)
{
    cli_voxels v;
    v.grid = grid, v.occ = occ;
    return cli_write_encoded(path, hfvis_binvox_encode_size(grid, occ), cli_enc_binvox, &v);
}
static hfvis_status cli_voxels_raw_save(const char *path, const hfvis_volume_grid *grid, const uint8_t *occ)
{
    hfvis_write_options wo;
    size_t n = (size_t)grid->dims[0] * (size_t)grid->dims[1] * (size_t)grid->dims[2];
    wo.on_temp = cli_on_temp;
    wo.user = NULL;
    return hfvis_write_file(path, occ, n, &wo);
}
static hfvis_status cli_visfield_save(const char *path, const hfvis_visfield *vf)
{
    return cli_write_encoded(path, hfvis_visfield_encode_size(vf), cli_enc_visfield, vf);
}
static hfvis_status cli_partial_save(const char *path, const hfvis_partial *p)
{
    return cli_write_encoded(path, hfvis_partial_encode_size(p), cli_enc_partial, p);
}

static int cli_save_piece(const cli_args *a, const float *px, int w, int h, int channels, double lo,
                          double hi);
/* Write OUT: PFM with its channels, or a 16-bit PGM with the channel planes stacked (NoData code 0,
 * the range in its header: hfvis_pgm_range_save). A --window run writes its piece instead. */
static int cli_save(const cli_args *a, const float *px, int w, int h, int channels, double lo,
                    double hi)
{
    hfvis_status s;
    if (cli_win.active) return cli_save_piece(a, px, w, h, channels, lo, hi);
    errno = 0;
    if (a->out_raster) {
        /* planes stacked top to bottom (horizon) or channels interleaved become bands */
        int planes = cli_in_height > 0 && h % cli_in_height == 0 ? h / cli_in_height : 1;
        ex_rio_image img;
        ex_rio_write_options o;
        ex_georef g = cli_geo; /* shallow: only the NoData fields change, on the copy */
        char why[256];
        size_t i, n = (size_t)w * (size_t)h * (size_t)channels;
        int moved = 0;
        img.data = px;
        img.width = w;
        img.height = h / planes;
        img.bands = planes * channels;
        img.pixel_step = (size_t)channels;
        img.row_step = (size_t)w * (size_t)channels;
        img.band_step = channels > 1 ? 1 : (size_t)w * (size_t)img.height;
        memset(&o, 0, sizeof o);
        o.tiled = 1;
        o.deflate = 1;
        o.predictor = 3;
        if (g.has_nodata) /* the input's NoData, unless the output has it as a real value */
            for (i = 0; i < n; i++)
                if (!isnan(px[i]) && (double)px[i] == g.nodata) {
                    moved = 1;
                    g.has_nodata = 0;
                    break;
                }
        if ((ex_rio_format_of(a->out) != EX_RIO_TIFF || !cli_integral_type(a, px, n, &g, &o)) && !g.has_nodata)
            /* NaN cells: declare NoData NaN */
            for (i = 0; i < n; i++)
                if (isnan(px[i])) {
                    g.has_nodata = 1;
                    g.nodata = (double)NAN;
                    strcpy(g.nodata_text, "nan");
                    break;
                }
        if (ex_rio_write(a->out, &img, &g, &o, why) != 0) return cli_error(CLI_EXIT_ERROR, a->out, "%s", why);
        if (moved && !a->quiet)
            fprintf(stderr, "hfvis: note: %s: the input's NoData %s is a value of this output: holes are "
                    "written as %s\n", a->out, cli_geo.nodata_text, g.has_nodata ? g.nodata_text : "NaN");
        return 0;
    }
    if (!a->out_pgm) {
        s = cli_pfm_save(a->out, px, w, h, channels, w);
    } else {
        if (a->has_range) { lo = a->range_lo; hi = a->range_hi; }
        if (channels == 1) {
            s = cli_pgm_save(a->out, px, w, h, w, (float)lo, (float)hi);
        } else {
            size_t n = (size_t)w * (size_t)h, i;
            int c;
            float *planes = cli_alloc(n, (size_t)channels, 1);
            if (!planes) return cli_status(a->out, HFVIS_ERR_OUT_OF_MEMORY, 0);
            for (c = 0; c < channels; c++)
                for (i = 0; i < n; i++) planes[(size_t)c * n + i] = px[i * (size_t)channels + (size_t)c];
            if ((long long)h * channels > INT_MAX) s = HFVIS_ERR_LIMIT;
            else s = cli_pgm_save(a->out, planes, w, h * channels, w, (float)lo, (float)hi);
            free(planes);
        }
    }
    if (s != HFVIS_OK) return cli_status(a->out, s, errno);
    return 0;
}

/* Load a lat-long environment map (any image the codecs read). */
static int cli_load_env(const char *path, float **px, hfvis_env *env)
{
    hfvis_image_info info;
    hfvis_status s;
    errno = 0;
    size_t i, n;
    s = hfvis_image_load(path, NULL, px, &info);
    if (s != HFVIS_OK) return cli_status(path, s, errno);
    env->radiance = *px; env->n_theta = info.height; env->n_phi = info.width;
    env->channels = info.channels;
    n = (size_t)info.width * (size_t)info.height * (size_t)info.channels;
    for (i = 0; i < n; i++) /* radiance: finite and >= 0 (a NaN or negative sky is no light) */
        if (!((*px)[i] >= 0.0f && (*px)[i] <= FLT_MAX)) {
            size_t pix = i / (size_t)info.channels;
            return cli_error(CLI_EXIT_ERROR, path, "radiance %g at (%lu, %lu): must be finite and >= 0",
                             (double)(*px)[i], (unsigned long)(pix % (size_t)info.width),
                             (unsigned long)(pix / (size_t)info.width));
        }
    return 0;
}

/* Load a per-sample map of the height field's size (indirect --albedo-map, --emission): PGM
 * values divided by the file's maxval, PFM values as stored; every value finite and >= 0
 * wherever the height field has no hole. */
static int cli_load_map(const char *path, const hfvis_grid *grid, float **px, int *channels)
{
    hfvis_image_info info;
    float *m = NULL;
    size_t i, n = (size_t)grid->width * (size_t)grid->height;
    int c;
    hfvis_status s;
    errno = 0;
    s = hfvis_image_load(path, NULL, &m, &info);
    if (s != HFVIS_OK) return cli_status(path, s, errno);
    if (info.width != grid->width || info.height != grid->height) {
        hfvis_free(NULL, m);
        return cli_error(CLI_EXIT_ERROR, path, "%d x %d samples, but IN has %d x %d", info.width,
                         info.height, grid->width, grid->height);
    }
    for (i = 0; i < n; i++)
        for (c = 0; c < info.channels; c++) {
            float *v = m + i * (size_t)info.channels + (size_t)c;
            if (info.format == HFVIS_FORMAT_PGM) *v = (float)((double)*v / (double)info.maxval);
            if (isfinite(grid->z[i]) && !(isfinite(*v) && *v >= 0.0f)) {
                double bad = (double)*v;
                hfvis_free(NULL, m);
                return cli_error(CLI_EXIT_ERROR, path, "value %g at column %d, row %d is not a "
                                 "finite number >= 0", bad, (int)(i % (size_t)grid->width),
                                 (int)(i / (size_t)grid->width));
            }
        }
    *px = m;
    *channels = info.channels;
    return 0;
}

/* Give a one-channel array of n samples `channels` channels (each a copy), replacing *px. */
static int cli_widen(float **px, size_t n, int channels)
{
    size_t i;
    int c;
    float *w = cli_alloc(n, (size_t)channels, 1);
    if (!w) return cli_status("indirect", HFVIS_ERR_OUT_OF_MEMORY, 0);
    for (i = 0; i < n; i++)
        for (c = 0; c < channels; c++) w[i * (size_t)channels + (size_t)c] = (*px)[i];
    hfvis_free(NULL, *px);
    *px = w;
    return 0;
}

/* Largest finite value of px[0..n), or fallback if none is > 0: the top of a default PGM range. */
static double cli_top(const float *px, size_t n, double fallback)
{
    size_t i;
    double top = 0.0;
    for (i = 0; i < n; i++)
        if (isfinite(px[i]) && (double)px[i] > top) top = (double)px[i];
    return (float)top > 0.0f ? top : fallback;
}

/* Radiance outputs scale with the inputs (sky, sun, environment, emission, albedo, specular),
 * each bounded by the float range alone, so their product can overflow: refuse a result that is
 * not finite where the height field has a sample, rather than write it with exit 0. */
static int cli_check_radiance(const char *cmd, const hfvis_grid *grid, const float *out, int channels)
{
    int x, y, c;
    for (y = 0; y < grid->height; y++)
        for (x = 0; x < grid->width; x++) {
            const size_t i = (size_t)y * (size_t)grid->width + (size_t)x;
            if (!isfinite(grid->z[(ptrdiff_t)y * grid->stride + x])) continue;
            for (c = 0; c < channels; c++)
                if (!isfinite(out[i * (size_t)channels + (size_t)c]))
                    return cli_error(CLI_EXIT_ERROR, cmd, "the result at column %d, row %d is %g: "
                                     "the light inputs (sky, sun, environment, emission, albedo, "
                                     "specular) overflow the float range (3.4e38); scale them down",
                                     x, y, (double)out[i * (size_t)channels + (size_t)c]);
        }
    return 0;
}

/* indirect: direct light (hfvis_direct_light), then hfvis_terrain_gi. */
static int cli_run_indirect(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts,
                            cli_progress_state *prog)
{
    const char *cmd = "indirect";
    const int w = grid->width, h = grid->height, K = a->dirs;
    const size_t n = (size_t)w * (size_t)h;
    const int has_sun = a->has_sun_azimuth;
    const int bounces = a->output == OUT_DIRECT ? 0 : a->bounces;
    float *env_px = NULL, *albedo = NULL, *emit = NULL, *direct = NULL, *out = NULL, *base = NULL;
    int env_ch = 1, albedo_ch = 1, emit_ch = 1, channels, direct_ch, rc = 0, c;
    hfvis_env env;
    hfvis_sun sun;
    hfvis_status s;
    size_t i;

    memset(&env, 0, sizeof env);
    memset(&sun, 0, sizeof sun);
    if (a->env) {
        if ((rc = cli_load_env(a->env, &env_px, &env)) != 0) goto done;
        env_ch = env.channels;
    }
    if (a->albedo_map && (rc = cli_load_map(a->albedo_map, grid, &albedo, &albedo_ch)) != 0) goto done;
    if (a->emission && (rc = cli_load_map(a->emission, grid, &emit, &emit_ch)) != 0) goto done;
    /* Output channels: the most of any input; one-channel inputs apply to every channel. */
    channels = env_ch > albedo_ch ? env_ch : albedo_ch;
    if (emit_ch > channels) channels = emit_ch;
    {
        const char *names[3] = { a->env, a->albedo_map, a->emission };
        const int counts[3] = { env_ch, albedo_ch, emit_ch };
        for (c = 0; c < 3; c++)
            if (names[c] && counts[c] != 1 && counts[c] != channels) {
                rc = cli_error(CLI_EXIT_ERROR, names[c], "%d channels, but another input has %d "
                               "(inputs need 1 channel or the same count)", counts[c], channels);
                goto done;
            }
    }
    if (albedo && albedo_ch < channels && (rc = cli_widen(&albedo, n, channels)) != 0) goto done;
    if (emit && emit_ch < channels && (rc = cli_widen(&emit, n, channels)) != 0) goto done;
    direct = cli_alloc(n, (size_t)channels, 1);
    out = cli_alloc(n, (size_t)channels, 1);
    if (a->output == OUT_INDIRECT) base = cli_alloc(n, (size_t)channels, 1);
    if (!direct || !out || (a->output == OUT_INDIRECT && !base)) {
        rc = cli_status(cmd, HFVIS_ERR_OUT_OF_MEMORY, 0);
        goto done;
    }
    if (has_sun) {
        double psi_deg = a->math ? a->sun_azimuth : a->sun_azimuth - 90.0;
        sun.azimuth_rad = psi_deg * (CLI_PI / 180.0);
        sun.elevation_rad = a->sun_elevation * (CLI_PI / 180.0);
        sun.radius_rad = a->sun_radius * (CLI_PI / 180.0);
        for (c = 0; c < 4; c++) sun.irradiance[c] = (float)a->sun_irradiance;
    }
    /* one bar: the sky or environment sweep (K), the sun sweep (1), K per bounce */
    prog->total = (long long)K * (1 + bounces) + (has_sun ? 1 : 0);

    /* D: the sky part has the environment's channels (1 for the uniform sky) */
    direct_ch = a->env ? env_ch : 1;
    s = hfvis_direct_light(grid, K, has_sun ? &sun : NULL, (float)a->sky, a->env ? &env : NULL,
                           direct_ch, opts, direct);
    if (s != HFVIS_OK) { rc = cli_status(cmd, s, 0); goto done; }
    if (direct_ch < channels) /* spread the one channel, back to front (in place) */
        for (i = n; i-- > 0;)
            for (c = channels - 1; c >= 0; c--) direct[i * (size_t)channels + (size_t)c] = direct[i];

    s = hfvis_terrain_gi(grid, K, direct, emit, albedo, (float)a->albedo, channels, bounces, opts,
                         NULL, out);
    if (s == HFVIS_OK && a->output == OUT_INDIRECT) { /* L_B - L_0 */
        s = hfvis_terrain_gi(grid, K, direct, emit, albedo, (float)a->albedo, channels, 0, opts,
                             NULL, base);
        for (i = 0; s == HFVIS_OK && i < n * (size_t)channels; i++)
            out[i] = (float)((double)out[i] - (double)base[i]);
    }
    if (s != HFVIS_OK) { rc = cli_status(cmd, s, 0); goto done; }
    if ((rc = cli_check_radiance(cmd, grid, out, channels)) != 0) goto done;
    rc = cli_save(a, out, w, h, channels, 0.0, cli_top(out, n * (size_t)channels, 1.0));
done:
    free(base);
    free(out);
    free(direct);
    hfvis_free(NULL, emit);
    hfvis_free(NULL, albedo);
    hfvis_free(NULL, env_px);
    return rc;
}

/* gi: hfvis_ns_gi with a uniform sky or a projected environment, and an optional sun. */
static int cli_run_gi(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts,
                  cli_progress_state *prog)
{
    const char *cmd = "gi";
    const int w = grid->width, h = grid->height;
    const size_t n = (size_t)w * (size_t)h;
    const int bounces = a->output == OUT_DIRECT ? 0 : a->bounces;
    float *env_px = NULL, *direct = NULL, *bounce = NULL, *out = NULL;
    double env_sh[4 * HFVIS_SH_COEFFS];
    int channels = 1, rc = 0, c, b;
    hfvis_env env;
    hfvis_sun sun;
    hfvis_ns_scene scene;
    hfvis_ns_gi_options o = hfvis_ns_gi_options_default();
    hfvis_ns_gi_outputs res;
    hfvis_status s;
    size_t i;

    memset(&env, 0, sizeof env);
    memset(&sun, 0, sizeof sun);
    memset(&scene, 0, sizeof scene);
    memset(&res, 0, sizeof res);
    memset(env_sh, 0, sizeof env_sh);
    if (a->env) {
        if ((rc = cli_load_env(a->env, &env_px, &env)) != 0) goto done;
        channels = env.channels;
        s = hfvis_sh_project_env(&env, env_sh); /* the environment as order-4 SH ([NS09] §7) */
        if (s != HFVIS_OK) { rc = cli_status(a->env, s, 0); goto done; }
    } else {
        env_sh[0] = 2.0 * sqrt(CLI_PI) * a->sky; /* a uniform sky c: Int c Y_00 = 2 sqrt(pi) c */
    }
    scene.channels = channels;
    scene.env_sh = env_sh;
    for (c = 0; c < 4; c++) scene.albedo[c] = (float)a->albedo;
    scene.specular = (float)a->specular;
    scene.shininess = (float)(a->has_shininess ? a->shininess : 32.0);
    if (a->has_sun_azimuth) {
        double psi_deg = a->math ? a->sun_azimuth : a->sun_azimuth - 90.0;
        sun.azimuth_rad = psi_deg * (CLI_PI / 180.0);
        sun.elevation_rad = a->sun_elevation * (CLI_PI / 180.0);
        sun.radius_rad = a->sun_radius * (CLI_PI / 180.0);
        for (c = 0; c < 4; c++) sun.irradiance[c] = (float)a->sun_irradiance;
        scene.lights = &sun;
        scene.light_count = 1;
    }
    o.directions = a->has_dirs ? a->dirs : 32;
    o.sh_order = a->order;
    o.subsample = a->subsample;
    o.border = opts->border;
    o.azimuth0_rad = opts->azimuth0_rad;
    o.key_mode = HFVIS_NS_KEY_RATIO; /* a disc sun keeps its brightness (see hfvis.h) */
    o.progress = opts->progress;
    o.progress_user = opts->progress_user;
    prog->total = 0; /* the library reports receiver rows over all passes */

    direct = cli_alloc(n, (size_t)channels, 1);
    out = cli_alloc(n, (size_t)channels, 1);
    if (bounces > 0) bounce = cli_alloc(n, (size_t)channels, (size_t)bounces);
    if (!direct || !out || (bounces > 0 && !bounce)) {
        rc = cli_status(cmd, HFVIS_ERR_OUT_OF_MEMORY, 0);
        goto done;
    }
    res.bounces = bounces;
    res.direct = direct;
    res.bounce = bounce;
    s = hfvis_ns_gi(grid, &scene, &o, &res);
    if (s != HFVIS_OK) { rc = cli_status(cmd, s, 0); goto done; }
    for (i = 0; i < n * (size_t)channels; i++) {
        double v = a->output == OUT_INDIRECT ? 0.0 : (double)direct[i];
        for (b = 0; b < bounces; b++) v += (double)bounce[(size_t)b * n * (size_t)channels + i];
        out[i] = (float)v;
    }
    if ((rc = cli_check_radiance(cmd, grid, out, channels)) != 0) goto done;
    rc = cli_save(a, out, w, h, channels, 0.0, cli_top(out, n * (size_t)channels, 1.0));
done:
    free(out);
    free(bounce);
    free(direct);
    hfvis_free(NULL, env_px);
    return rc;
}

/* visibility: hfvis_visibility_count; --fraction divides by the count on a flat field with the
 * same holes (where every sample is visible); --stats prints the counters before OUT is written
 * (a print that fails leaves OUT untouched). */
static int cli_run_visibility(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts,
                              cli_progress_state *prog)
{
    const char *cmd = "visibility";
    const int w = grid->width, h = grid->height, K = a->dirs;
    const size_t n = (size_t)w * (size_t)h;
    float *out = cli_alloc(n, 1, 1), *flat_z = NULL, *tested = NULL;
    hfvis_visibility_stats st, flat_st;
    hfvis_status s;
    size_t i;
    int rc;

    memset(&flat_st, 0, sizeof flat_st);
    if (!out) return cli_status(cmd, HFVIS_ERR_OUT_OF_MEMORY, 0);
    prog->total = (long long)K * (a->fraction ? 2 : 1);
    s = hfvis_visibility_count(grid, K, opts, NULL, out, w, &st);
    if (s == HFVIS_OK && a->fraction) {
        hfvis_grid flat = *grid;
        flat_z = cli_alloc(n, 1, 1);
        tested = cli_alloc(n, 1, 1);
        if (!flat_z || !tested) s = HFVIS_ERR_OUT_OF_MEMORY;
        else {
            for (i = 0; i < n; i++) flat_z[i] = isfinite(grid->z[i]) ? 0.0f : (float)NAN;
            flat.z = flat_z;
            s = hfvis_visibility_count(&flat, K, opts, NULL, tested, w, &flat_st);
        }
        for (i = 0; s == HFVIS_OK && i < n; i++)
            if (!isnan(out[i])) out[i] = tested[i] > 0.0f ? (float)((double)out[i] / (double)tested[i]) : 0.0f;
    }
    rc = s != HFVIS_OK ? cli_status(cmd, s, 0) : 0;
    if (rc == 0 && a->stats) { /* before OUT: a failed print must not follow a replaced OUT */
        double r = st.receivers > 0.0 ? st.receivers : 1.0; /* 0 receivers: print zeros */
        printf("receiver-directions: %.0f\n", st.receivers);
        printf("visible per receiver-direction: %.6g\n", st.visible / r);
        printf("horizons per receiver-direction (m_a): %.6g\n", st.horizons / r);
        printf("iterations per receiver-direction (t_a): %.6g\n", st.iterations / r);
        if (a->fraction) {
            double t = flat_st.visible > 0.0 ? flat_st.visible : 1.0;
            printf("tested per receiver-direction: %.6g\n", flat_st.visible / r);
            printf("visible/tested: %.6g\n", st.visible / t);
            printf("t_a/tested: %.6g\n", st.iterations / t);
        }
        if (fflush(stdout) != 0 || ferror(stdout))
            rc = cli_error(CLI_EXIT_ERROR, "stdout", "%s (OUT not written)", strerror(errno));
    }
    if (rc == 0) rc = cli_save(a, out, w, h, 1, 0.0, a->fraction ? 1.0 : cli_top(out, n, 1.0));
    free(tested);
    free(flat_z);
    free(out);
    return rc;
}

/* ssao: a depth buffer (linear, or hardware depth linearised first) -> obscurance of the inner
 * pixels by the chosen method. */
static int cli_run_ssao(const cli_args *a)
{
    float *depth = NULL, *ao = NULL;
    hfvis_image_info info;
    hfvis_camera cam;
    hfvis_falloff fo;
    hfvis_status s;
    int rc = 0, gx, gy, W, H;
    /* the methods' direction counts (hfvis.h): the flag is named, not the library's status */
    if (a->has_dirs && a->ssao_method != SSAO_RAYTRACE &&
        (a->dirs > HFVIS_SSAO_MAX_DIRECTIONS || (a->ssao_method == SSAO_FFAO && a->dirs < 3)))
        return cli_error(CLI_EXIT_USAGE, "--dirs", "ssao --method %s takes %d..%d directions, got %d",
                         a->ssao_method == SSAO_LSAO ? "lsao" : a->ssao_method == SSAO_HBAO ? "hbao" : "ffao",
                         a->ssao_method == SSAO_FFAO ? 3 : 1, HFVIS_SSAO_MAX_DIRECTIONS, a->dirs);
    errno = 0;
    s = hfvis_image_load(a->in, NULL, &depth, &info);
    if (s != HFVIS_OK) return cli_status(a->in, s, errno);
    if ((rc = cli_check_cost(a, info.width, info.height, 1)) != 0) goto done;
    if (info.channels != 1) {
        rc = cli_error(CLI_EXIT_ERROR, a->in, "expected a one-channel depth buffer");
        goto done;
    }
    gx = a->ssao_guard >= 0 ? a->ssao_guard : info.width / 10;
    gy = a->ssao_guard >= 0 ? a->ssao_guard : info.height / 10;
    if (2 * gx >= info.width || 2 * gy >= info.height) {
        rc = cli_error(CLI_EXIT_USAGE, "--guard", "leaves no inner pixel in a %dx%d buffer",
                       info.width, info.height);
        goto done;
    }
    if (a->ssao_depth != SSAO_DEPTH_LINEAR) {
        static const hfvis_depth_encoding enc[] = {HFVIS_DEPTH_GL, HFVIS_DEPTH_GL, HFVIS_DEPTH_D3D,
                                                   HFVIS_DEPTH_REVERSED_Z};
        if (!a->ssao_has_near || !a->ssao_has_far) {
            rc = cli_error(CLI_EXIT_USAGE, "--depth", "hardware depth needs --near and --far");
            goto done;
        }
        s = hfvis_depth_linearize(depth, info.width, info.height, info.width, enc[a->ssao_depth],
                                  a->ssao_has_ortho, a->ssao_near, a->ssao_far, depth, info.width);
        if (s != HFVIS_OK) { rc = cli_status("--near/--far", s, 0); goto done; }
    }
    if (a->ssao_has_ortho)
        s = hfvis_camera_orthographic(&cam, info.width, info.height, gx, gy, a->ssao_ortho);
    else
        s = hfvis_camera_perspective(&cam, info.width, info.height, gx, gy,
                                     a->ssao_fov * CLI_PI / 180.0);
    if (s != HFVIS_OK) { rc = cli_status("camera", s, 0); goto done; }
    if (a->ssao_depth != SSAO_DEPTH_LINEAR)
        cam.far_depth = a->ssao_far; /* the far plane is background */
    memset(&fo, 0, sizeof fo);
    if (a->ssao_radius > 0.0) {
        fo.kind = HFVIS_FALLOFF_INV_QUADRATIC;
        fo.param = a->ssao_radius * a->ssao_radius;
    }
    W = info.width - 2 * gx;
    H = info.height - 2 * gy;
    ao = (float *)malloc(sizeof(float) * (size_t)W * (size_t)H);
    if (!ao) { rc = cli_status("ssao", HFVIS_ERR_OUT_OF_MEMORY, 0); goto done; }
    if (a->ssao_method == SSAO_LSAO) {
        hfvis_lsao_options o = hfvis_lsao_options_default();
        o.falloff = fo;
        o.directions = a->has_dirs ? a->dirs : 0;
        s = hfvis_lsao(&cam, depth, NULL, &o, ao, W);
    } else if (a->ssao_method == SSAO_HBAO) {
        hfvis_hbao_options o = hfvis_hbao_options_default();
        o.falloff = fo;
        o.directions = a->has_dirs ? a->dirs : 0;
        s = hfvis_hbao(&cam, depth, NULL, &o, ao, W);
    } else if (a->ssao_method == SSAO_FFAO) {
        hfvis_ffao_options o = hfvis_ffao_options_default();
        o.falloff = fo;
        o.directions = a->has_dirs ? a->dirs : 0;
        s = hfvis_ffao(&cam, depth, NULL, &o, ao, W);
    } else {
        hfvis_ssao_rt_options o = hfvis_ssao_rt_options_default();
        o.falloff = fo;
        s = hfvis_ssao_reference(&cam, depth, NULL, &o, ao, W);
    }
    if (s != HFVIS_OK) { rc = cli_status("ssao", s, 0); goto done; }
    rc = cli_save(a, ao, W, H, 1, 0.0, 1.0);
done:
    free(ao);
    hfvis_free(NULL, depth);
    return rc;
}

/* voxelize: MESH.obj -> a cubic-voxel grid fitted to the mesh -> .binvox or .raw. */
static int cli_run_voxelize(const cli_args *a)
{
    hfvis_mesh mesh;
    hfvis_volume_grid grid;
    uint8_t *occ = NULL;
    size_t voxels, count = 0, i;
    hfvis_status s;
    int rc = 0;
    errno = 0;
    s = hfvis_mesh_load(a->in, NULL, &mesh);
    if (s != HFVIS_OK) return cli_status(a->in, s, errno);
    s = hfvis_volume_grid_fit(&mesh, a->res, a->padding, 1, &grid);
    if (s == HFVIS_ERR_INVALID_ARGUMENT && mesh.triangle_count == 0) {
        rc = cli_error(CLI_EXIT_ERROR, a->in, "the mesh has no triangles");
        goto done;
    }
    if (s != HFVIS_OK) { rc = cli_status("voxelize", s, 0); goto done; }
    voxels = (size_t)grid.dims[0] * (size_t)grid.dims[1] * (size_t)grid.dims[2];
    occ = (uint8_t *)malloc(voxels);
    if (!occ) { rc = cli_status("voxelize", HFVIS_ERR_OUT_OF_MEMORY, 0); goto done; }
    if (a->vox_mode == VOX_SURFACE) {
        hfvis_voxelize_options o = hfvis_voxelize_options_default();
        static const hfvis_voxelize_axes axes[] = {HFVIS_AXES_DOMINANT, HFVIS_AXES_DOMINANT,
                                                   HFVIS_AXES_ALL, HFVIS_AXES_ONLY_X,
                                                   HFVIS_AXES_ONLY_Y, HFVIS_AXES_ONLY_Z};
        o.method = (hfvis_voxelize_method)a->vox_method;
        o.axes = axes[a->vox_axis];
        o.max_output_vertices = a->max_vertices;
        if (a->max_vertices && hfvis_gs_max_slices(a->max_vertices,
                                                   o.method == HFVIS_VOXELIZE_FRAGMENT_CLIPPING) == 0) {
            rc = cli_error(CLI_EXIT_USAGE, "--max-vertices", "%d vertices hold no slab (slicing "
                           "needs >= 7, clipping >= 3)", a->max_vertices);
            goto done;
        }
        s = hfvis_voxelize_occupancy(&mesh, &grid, &o, occ);
        for (i = 0; s == HFVIS_OK && i < voxels; i++) count += occ[i];
    } else {
        hfvis_binary_voxel_options o = hfvis_binary_voxel_options_default();
        if (a->vox_mode == VOX_CONSERVATIVE) {
            s = hfvis_voxelize_conservative(&mesh, &grid, &o, occ, &count);
        } else {
            o.axis = a->vox_axis == AXIS_X ? HFVIS_PARITY_AXIS_X
                     : a->vox_axis == AXIS_Y ? HFVIS_PARITY_AXIS_Y : HFVIS_PARITY_AXIS_Z;
            o.allow_open = a->open_mesh;
            s = hfvis_voxelize_solid(&mesh, &grid, &o, occ, &count);
            if (s == HFVIS_ERR_FORMAT) {
                rc = cli_error(CLI_EXIT_ERROR, a->in, "the mesh is not closed (a parity ray "
                               "crosses it an odd number of times); use --open or --mode surface");
                goto done;
            }
        }
    }
    if (s != HFVIS_OK) { rc = cli_status("voxelize", s, 0); goto done; }
    errno = 0;
    s = a->out_binvox ? cli_binvox_save(a->out, &grid, occ) : cli_voxels_raw_save(a->out, &grid, occ);
    if (s != HFVIS_OK) { rc = cli_status(a->out, s, errno); goto done; }
    if (!a->quiet)
        printf("voxelize: %zu triangles -> %d x %d x %d voxels of %.6g (origin %.6g %.6g %.6g), "
               "%zu set\n", mesh.triangle_count, grid.dims[0], grid.dims[1], grid.dims[2],
               grid.cell[0], grid.origin[0], grid.origin[1], grid.origin[2], count);
done:
    free(occ);
    hfvis_mesh_free(NULL, &mesh);
    return rc;
}


/* meshao: MESH.obj -> camera -> hfvis_lk_image -> OUT. */
static int cli_run_meshao(const cli_args *a)
{
    const char *cmd = "meshao";
    hfvis_mesh mesh;
    hfvis_lk_rays rays;
    hfvis_lk_ray_options ro = hfvis_lk_ray_options_default();
    hfvis_lk_options o = hfvis_lk_options_default();
    hfvis_lk_lut lut;
    hfvis_lk_stats st;
    hfvis_view view;
    hfvis_status s;
    double lo[3], hi[3], c[3], eye[3], tgt[3], up[3], d[3], diag, dist, radius, nearp, farp, len;
    float *out = NULL;
    int rc = 0, k;
    memset(&rays, 0, sizeof rays);
    memset(&lut, 0, sizeof lut);
    errno = 0;
    s = hfvis_mesh_load(a->in, NULL, &mesh);
    if (s != HFVIS_OK) return cli_status(a->in, s, errno);
    if (mesh.triangle_count == 0) {
        rc = cli_error(CLI_EXIT_ERROR, a->in, "the mesh has no triangles");
        goto done;
    }
    s = hfvis_mesh_bounds(&mesh, lo, hi);
    if (s != HFVIS_OK) { rc = cli_status(cmd, s, 0); goto done; }
    for (k = 0; k < 3; k++) c[k] = 0.5 * (lo[k] + hi[k]);
    diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                (hi[2] - lo[2]) * (hi[2] - lo[2]));
    if (!(diag > 0.0)) diag = 1.0;
    radius = a->lk_has_radius ? a->lk_radius : 0.1 * diag;
    /* camera: default eye in front (-y) and above the box, framing it */
    for (k = 0; k < 3; k++) tgt[k] = a->lk_has_target ? a->lk_target[k] : c[k];
    if (a->lk_has_eye) {
        for (k = 0; k < 3; k++) eye[k] = a->lk_eye[k];
    } else {
        double back = 0.5 * diag / tan(0.5 * a->lk_fov * (CLI_PI / 180.0)) + 0.5 * diag;
        eye[0] = tgt[0] + 0.25 * back;
        eye[1] = tgt[1] - 0.9 * back;
        eye[2] = tgt[2] + 0.45 * back;
    }
    for (k = 0; k < 3; k++) {
        d[k] = tgt[k] - eye[k];
        up[k] = a->lk_up[k];
    }
    dist = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(dist > 0.0)) { rc = cli_error(CLI_EXIT_ERROR, "--eye", "the eye is at the target"); goto done; }
    len = fabs(d[0] * up[0] + d[1] * up[1] + d[2] * up[2]) /
          (dist * sqrt(up[0] * up[0] + up[1] * up[1] + up[2] * up[2]));
    if (!a->lk_has_up && len > 0.999) { up[0] = 0.0; up[1] = 1.0; up[2] = 0.0; }
    farp = dist + 2.0 * diag + 2.0 * radius;
    nearp = farp * 1e-4;
    s = hfvis_view_perspective(&view, eye, tgt, up, a->lk_fov * (CLI_PI / 180.0), a->lk_width,
                               a->lk_height, nearp, farp);
    if (s != HFVIS_OK) {
        rc = cli_error(CLI_EXIT_ERROR, cmd, "%s (is --up parallel to the viewing direction?)",
                       hfvis_status_string(s));
        goto done;
    }
    /* rays, options, optional table */
    ro.falloff = (hfvis_lk_falloff)a->lk_falloff;
    ro.pattern = (hfvis_lk_pattern)a->lk_pattern; /* 0 = the library's default */
    ro.seed = (uint64_t)a->lk_seed;
    s = hfvis_lk_rays_build(a->lk_rays, radius, &ro, &rays);
    if (s != HFVIS_OK) { rc = cli_status(cmd, s, 0); goto done; }
    o.seed = (uint64_t)a->lk_seed;
    o.sides = a->lk_two_sided ? HFVIS_LK_SIDES_TWO : HFVIS_LK_SIDES_ONE;
    if (a->lk_no_jitter) o.jitter = HFVIS_LK_JITTER_NONE;
    if (a->lk_lut) {
        s = hfvis_lk_lut_build(&rays, a->lk_lut, NULL, &lut);
        if (s == HFVIS_ERR_LIMIT) {
            rc = cli_error(CLI_EXIT_ERROR, "--lut", "%s: a %d^3 table for %d rays needs %.0f MiB (limit "
                           "%.0f MiB); use a smaller T or exact masks", hfvis_status_string(s), a->lk_lut,
                           a->lk_rays, (double)hfvis_lk_lut_bytes(a->lk_lut, a->lk_rays, !rays.equal_lengths) / 1048576.0,
                           (double)HFVIS_LK_LUT_MAX_BYTES / 1048576.0);
            goto done;
        }
        if (s != HFVIS_OK) { rc = cli_status(cmd, s, 0); goto done; }
        o.lut = &lut;
        o.mask_mode = HFVIS_LK_MASK_LUT;
    }
    out = cli_alloc((size_t)a->lk_width, (size_t)a->lk_height, 1);
    if (!out) { rc = cli_status(cmd, HFVIS_ERR_OUT_OF_MEMORY, 0); goto done; }
    s = hfvis_lk_image((hfvis_lk_method)a->lk_method, &mesh, NULL, &view, &rays, &o, NULL, out, &st);
    if (s != HFVIS_OK) { rc = cli_status(cmd, s, 0); goto done; }
    if (a->stats) { /* before OUT: a failed print must not follow a replaced OUT */
        printf("receivers: %llu\nrays: %llu\nblocked: %llu (mean obscurance %.6f)\n",
               (unsigned long long)st.receivers, (unsigned long long)st.rays,
               (unsigned long long)st.rays_blocked,
               st.rays ? (double)st.rays_blocked / (double)st.rays : 0.0);
        printf("candidates: %llu\nmasks computed: %llu\nculled: far depth %llu, sphere %llu, facing %llu, "
               "plane %llu, horizon %llu\nskipped (self plane, zero area): %llu\n",
               (unsigned long long)st.fragments, (unsigned long long)st.masks,
               (unsigned long long)st.culled_far_depth, (unsigned long long)st.culled_sphere,
               (unsigned long long)st.culled_facing, (unsigned long long)st.culled_plane,
               (unsigned long long)st.culled_horizon, (unsigned long long)st.skipped);
        if (a->lk_method == HFVIS_LK_METHOD_RASTER)
            printf("volumes: %llu prisms, %llu spheres\n", (unsigned long long)st.prisms,
                   (unsigned long long)st.spheres);
        else
            printf("nodes visited: %llu (culled: distance %llu, horizon %llu, mask %llu)\n",
                   (unsigned long long)st.nodes_visited, (unsigned long long)st.nodes_culled_distance,
                   (unsigned long long)st.nodes_culled_horizon, (unsigned long long)st.nodes_culled_mask);
        if (fflush(stdout) != 0 || ferror(stdout)) {
            rc = cli_error(CLI_EXIT_ERROR, "stdout", "%s (OUT not written)", strerror(errno));
            goto done;
        }
    }
    rc = cli_save(a, out, a->lk_width, a->lk_height, 1, 0.0, 1.0);
done:
    free(out);
    hfvis_lk_lut_free(NULL, &lut);
    hfvis_lk_rays_free(NULL, &rays);
    hfvis_mesh_free(NULL, &mesh);
    return rc;
}


/* visfield MESH.obj: build (Alg. 1) and save. */
static int cli_vf_build(const cli_args *a)
{
    static const char *const fmt_names[5] = {"u8", "u8", "f32", "bit", "normal"};
    hfvis_mesh mesh = {0};
    hfvis_visfield vf;
    hfvis_visfield_build_options bo;
    cli_progress_state prog;
    hfvis_status s;
    size_t bytes;
    int rc = 0;
    memset(&vf, 0, sizeof vf);
    memset(&bo, 0, sizeof bo);
    errno = 0;
    s = hfvis_mesh_load(a->in, NULL, &mesh);
    if (s != HFVIS_OK) return cli_status(a->in, s, errno);
    if (mesh.vertex_count == 0) {
        rc = cli_error(CLI_EXIT_ERROR, a->in, "the mesh has no vertices");
        goto done;
    }
    s = hfvis_visfield_bounding_sphere(&mesh, vf.center, &vf.radius);
    if (s != HFVIS_OK) { rc = cli_status("visfield", s, 0); goto done; }
    vf.positions_n = a->vf_positions ? a->vf_positions : 32; /* K = 4226 */
    vf.dir_res = a->has_dirs ? a->dirs : 32;
    vf.format = a->vf_format ? (hfvis_visfield_format)a->vf_format : HFVIS_VISFIELD_U8;
    vf.mapping = a->vf_mapping ? (hfvis_dirmap)a->vf_mapping : HFVIS_DIRMAP_CONCENTRIC;
    bytes = hfvis_visfield_size(vf.positions_n, vf.dir_res, vf.format);
    if (bytes == 0 || (uint64_t)bytes > HFVIS_VISFIELD_MAX_BYTES) {
        rc = cli_error(CLI_EXIT_ERROR, "visfield", "%s: %zu maps of %d x %d exceed the file limit of "
                       "4 GiB; use fewer --positions or --dirs", hfvis_status_string(HFVIS_ERR_LIMIT),
                       hfvis_visfield_position_count(vf.positions_n), vf.dir_res, vf.dir_res);
        goto done;
    }
    vf.maps = malloc(bytes);
    vf.maps_size = bytes;
    if (!vf.maps) { rc = cli_status("visfield", HFVIS_ERR_OUT_OF_MEMORY, 0); goto done; }
    prog.label = "visfield"; prog.base = 0; prog.total = 0;
    if (!a->quiet && cli_stderr_is_terminal()) {
        bo.progress = cli_progress;
        bo.progress_user = &prog;
    }
    s = hfvis_visfield_build(&mesh, &bo, &vf);
    if (s != HFVIS_OK) { rc = cli_status("visfield", s, 0); goto done; }
    errno = 0;
    s = cli_visfield_save(a->out, &vf);
    if (s != HFVIS_OK) { rc = cli_status(a->out, s, errno); goto done; }
    if (!a->quiet)
        printf("visfield: %zu triangles -> %zu maps of %d x %d (%s), sphere centre %.6g %.6g %.6g "
               "radius %.6g, %zu bytes\n", mesh.triangle_count,
               hfvis_visfield_position_count(vf.positions_n), vf.dir_res, vf.dir_res,
               fmt_names[vf.format], vf.center[0], vf.center[1], vf.center[2], vf.radius,
               hfvis_visfield_encode_size(&vf));
done:
    if (cli_bar_open) { fputc('\n', stderr); cli_bar_open = 0; }
    free(vf.maps);
    hfvis_mesh_free(NULL, &mesh);
    return rc;
}

/* visfield --ao FIELD: obscurance of a ground plane under the object (field or ray cast). */
static int cli_vf_ao(const cli_args *a)
{
    hfvis_visfield vf;
    hfvis_visfield_object ob;
    hfvis_visfield_ao_options o = hfvis_visfield_ao_options_default();
    hfvis_mesh mesh = {0};
    hfvis_bvh bvh;
    hfvis_status s;
    float *pts = NULL, *nrm = NULL, *ao = NULL;
    const int W = a->vf_has_size ? a->vg_width : 256, H = a->vf_has_size ? a->vg_height : 256;
    size_t n = (size_t)W * (size_t)H, p;
    double E, EY, Z;
    int rc = 0, x, y, i, have_bvh = 0;
    memset(&vf, 0, sizeof vf);
    memset(&bvh, 0, sizeof bvh);
    errno = 0;
    s = hfvis_visfield_load(a->in, NULL, &vf);
    if (s != HFVIS_OK) return cli_status(a->in, s, errno);
    E = a->vf_has_extent ? a->vf_extent : 1.5 * vf.radius;
    EY = E * (double)H / (double)W;
    Z = a->vf_has_ground ? a->vf_ground : vf.center[2] - vf.radius;
    pts = cli_alloc(n, 3, 1);
    nrm = cli_alloc(n, 3, 1);
    ao = cli_alloc(n, 1, 1);
    if (!pts || !nrm || !ao) { rc = cli_status("visfield", HFVIS_ERR_OUT_OF_MEMORY, 0); goto done; }
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++) { /* seen from above: x right, row 0 at +y */
            p = (size_t)y * (size_t)W + (size_t)x;
            pts[3 * p] = (float)(vf.center[0] - E + 2.0 * E * (x + 0.5) / W);
            pts[3 * p + 1] = (float)(vf.center[1] + EY - 2.0 * EY * (y + 0.5) / H);
            pts[3 * p + 2] = (float)Z;
            nrm[3 * p] = nrm[3 * p + 1] = 0.0f;
            nrm[3 * p + 2] = 1.0f;
        }
    ob.field = &vf;
    ob.mesh = NULL;
    ob.bvh = NULL;
    for (i = 0; i < 16; i++) ob.object_to_world[i] = (i % 5 == 0) ? 1.0 : 0.0;
    o.rays_sqrt = a->vf_rays ? a->vf_rays : 16;
    if (a->max_distance > 0.0) o.max_distance = a->max_distance;
    if (a->vf_has_bias) o.bias = a->vf_bias > 0.0 ? a->vf_bias : 1e-300; /* 0 means the default */
    if (a->vf_reference) {
        errno = 0;
        s = hfvis_mesh_load(a->vf_reference, NULL, &mesh);
        if (s != HFVIS_OK) { rc = cli_status(a->vf_reference, s, errno); goto done; }
        s = hfvis_bvh_build(&mesh, NULL, &bvh);
        if (s != HFVIS_OK) { rc = cli_status(a->vf_reference, s, 0); goto done; }
        have_bvh = 1;
        ob.mesh = &mesh;
        ob.bvh = &bvh;
        s = hfvis_visfield_ambient_occlusion_reference(&ob, 1, pts, nrm, n, &o, ao);
    } else {
        s = hfvis_visfield_ambient_occlusion(&ob, 1, pts, nrm, n, &o, ao);
    }
    if (s != HFVIS_OK) { rc = cli_status("visfield", s, 0); goto done; }
    rc = cli_save(a, ao, W, H, 1, 0.0, 1.0);
    if (rc == 0 && !a->quiet) {
        double mean = 0.0;
        for (p = 0; p < n; p++) mean += (double)ao[p];
        printf("visfield: %s obscurance of the plane z = %.6g over [%.6g, %.6g] x [%.6g, %.6g], "
               "%d x %d rays per pixel: mean %.4f\n", a->vf_reference ? "ray-cast" : "field", Z,
               vf.center[0] - E, vf.center[0] + E, vf.center[1] - EY, vf.center[1] + EY, o.rays_sqrt,
               o.rays_sqrt, mean / (double)n);
    }
done:
    if (have_bvh) hfvis_bvh_free(NULL, &bvh);
    hfvis_mesh_free(NULL, &mesh);
    free(pts);
    free(nrm);
    free(ao);
    hfvis_visfield_free(NULL, &vf);
    return rc;
}

static int cli_run_visfield(const cli_args *a)
{
    return a->vf_ao ? cli_vf_ao(a) : cli_vf_build(a);
}


/* volgi: MESH.obj or the room -> hfvis_volgi_render -> the chosen RGB plane as PFM or PGM. */
static int cli_run_volgi(const cli_args *a)
{
    const char *cmd = "volgi";
    const int w = a->vg_width, h = a->vg_height;
    const size_t n = (size_t)w * (size_t)h;
    hfvis_mesh mesh;
    hfvis_volgi_scene sc;
    hfvis_volgi_light def;
    hfvis_volgi_options o = hfvis_volgi_options_default();
    hfvis_volgi_outputs out;
    hfvis_volgi_render_info info;
    hfvis_view view;
    double lo[3], hi[3], c[3], e = 0.0, eye[3], target[3], d;
    float *albedo = NULL, *img = NULL;
    hfvis_status s;
    size_t t;
    int k, rc = 0;

    memset(&mesh, 0, sizeof mesh);
    errno = 0;
    s = a->room ? hfvis_mesh_room(NULL, &mesh) : hfvis_mesh_load(a->in, NULL, &mesh);
    if (s != HFVIS_OK) return cli_status(a->room ? cmd : a->in, s, errno);
    if (mesh.triangle_count == 0 || hfvis_mesh_bounds(&mesh, lo, hi) != HFVIS_OK) {
        rc = cli_error(CLI_EXIT_ERROR, a->in, "the mesh has no triangles");
        goto done;
    }
    for (k = 0; k < 3; k++) {
        c[k] = 0.5 * (lo[k] + hi[k]);
        if (hi[k] - lo[k] > e) e = hi[k] - lo[k];
    }
    if (!(e > 0.0)) { rc = cli_error(CLI_EXIT_ERROR, a->in, "the mesh has no extent"); goto done; }
    albedo = cli_alloc(mesh.triangle_count, 3, 1);
    img = cli_alloc(n, 3, 1);
    if (!albedo || !img) { rc = cli_status(cmd, HFVIS_ERR_OUT_OF_MEMORY, 0); goto done; }
    for (t = 0; t < mesh.triangle_count; t++) { /* room: walls 0-1 red (x = 0), 2-3 green (x = 1) */
        float grey = a->has_albedo ? (float)a->albedo : 0.75f;
        albedo[3 * t] = a->room && t >= 2 && t < 4 ? 0.15f : grey;
        albedo[3 * t + 1] = a->room && t < 2 ? 0.15f : grey;
        albedo[3 * t + 2] = a->room && t < 4 ? 0.15f : grey;
    }
    /* camera and default light */
    memset(&def, 0, sizeof def);
    def.type = HFVIS_VOLGI_LIGHT_POINT;
    if (a->room) {
        eye[0] = 0.5, eye[1] = -1.1, eye[2] = 0.5, target[0] = 0.5, target[1] = 0.5, target[2] = 0.45;
        def.position[0] = 0.5, def.position[1] = 0.45, def.position[2] = 0.9;
        def.intensity[0] = def.intensity[1] = def.intensity[2] = 1.0f;
    } else {
        eye[0] = c[0], eye[1] = c[1] - 2.2 * e, eye[2] = c[2] + 0.6 * e;
        target[0] = c[0], target[1] = c[1], target[2] = c[2];
        def.position[0] = c[0] + 0.6 * e, def.position[1] = c[1] - 1.2 * e, def.position[2] = c[2] + 1.5 * e;
        def.intensity[0] = def.intensity[1] = def.intensity[2] = (float)(4.0 * e * e);
    }
    for (k = 0; k < 3; k++) {
        if (a->vg_has_eye) eye[k] = a->vg_eye[k];
        if (a->vg_has_target) target[k] = a->vg_target[k];
    }
    d = sqrt((eye[0] - target[0]) * (eye[0] - target[0]) + (eye[1] - target[1]) * (eye[1] - target[1])
             + (eye[2] - target[2]) * (eye[2] - target[2]));
    s = hfvis_view_perspective(&view, eye, target, a->vg_up, a->vg_fov * (CLI_PI / 180.0), w, h,
                               1e-3 * (d + e), 100.0 * (d + e));
    if (s != HFVIS_OK) {
        rc = cli_error(CLI_EXIT_USAGE, "--eye", "camera: eye and target must differ and the view "
                       "direction must not be parallel to --up");
        goto done;
    }
    memset(&sc, 0, sizeof sc);
    sc.mesh = &mesh;
    sc.albedo = albedo;
    sc.lights = a->vg_nlights ? a->vg_lights : &def;
    sc.light_count = a->vg_nlights ? a->vg_nlights : 1;
    o.resolution = a->res ? a->res : HFVIS_VOLGI_DEFAULT_RESOLUTION;
    o.iterations = a->iterations;
    o.transfer = (hfvis_volgi_transfer)a->vg_transfer;
    o.paths = (hfvis_volgi_paths)a->vg_paths;
    o.reflection = (hfvis_volgi_reflection)a->vg_reflection;
    if (a->vg_has_rho) {
        o.reflectance_source = a->vg_rho_albedo ? HFVIS_VOLGI_REFLECTANCE_ALBEDO : HFVIS_VOLGI_REFLECTANCE_CONSTANT;
        o.reflectance = (float)a->vg_rho;
    }
    memset(&out, 0, sizeof out);
    if (a->output == OUT_DIRECT) out.direct = img;
    else if (a->output == OUT_INDIRECT) out.indirect = img;
    else out.total = img;
    s = hfvis_volgi_render(&sc, NULL, &view, &o, &out, &info);
    if (s == HFVIS_ERR_LIMIT) {
        rc = cli_error(CLI_EXIT_ERROR, "--res", "%s: the grid would exceed 2^31 voxels", hfvis_status_string(s));
        goto done;
    }
    if (s != HFVIS_OK) { rc = cli_status(cmd, s, 0); goto done; }
    rc = cli_save(a, img, w, h, 3, 0.0, cli_top(img, 3 * n, 1.0));
    if (rc == 0 && !a->quiet)
        printf("volgi: %zu triangles, %d x %d x %d voxels of %.6g, %zu occupied (%zu fragments), %d "
               "iterations; VPL flux %.6g, recorded at surfaces %.6g, still travelling %.6g (red band); "
               "%zu of %zu pixels covered\n", mesh.triangle_count, info.grid.dims[0], info.grid.dims[1],
               info.grid.dims[2], info.grid.cell[0], info.occupied, info.fragments, a->iterations,
               info.injected[0], info.deposited[0], info.remaining[0], info.covered_pixels, n);
done:
    free(img);
    free(albedo);
    hfvis_mesh_free(NULL, &mesh);
    return rc;
}

/* ------------------------------------------------------------------------------------------ */
/* split runs: --dir-range writes a partial result (HFVISSUM), `sum` adds the parts            */
/* ------------------------------------------------------------------------------------------ */

#define CLI_TAG_MAX 1024 /* our tags: the command, fingerprints and a dozen parameters */

/* FNV-1a 64 over the bytes of n floats (the loaded input, or an environment map). */
static unsigned long long cli_fingerprint(const float *v, size_t n)
{
    unsigned long long h = 14695981039346656037ull;
    size_t i;
    int b;
    for (i = 0; i < n; i++) {
        unsigned char raw[sizeof(float)];
        memcpy(raw, &v[i], sizeof raw);
        for (b = 0; b < (int)sizeof raw; b++) h = (h ^ raw[b]) * 1099511628211ull;
    }
    return h;
}

/* The tag of a partial result: "cmd=NAME" then every parameter that changes the sums or their
 * finish, as key=value (reals as exact hexadecimal floats); `sum` compares tags token by token. */
static void cli_partial_tag(const cli_args *a, const hfvis_grid *grid, const hfvis_sweep_options *o,
                            const hfvis_env *env, char *tag)
{
    int n = snprintf(tag, CLI_TAG_MAX, "cmd=%s dirs=%d in=%016llx cell=%a border=%d border-cells=%d "
                     "azimuth0=%a rays=%s max-distance=%a", cli_cmd_names[a->cmd], a->dirs,
                     cli_fingerprint(grid->z, (size_t)grid->width * (size_t)grid->height),
                     grid->cell_size, (int)o->border, o->border_cells, o->azimuth0_rad,
                     o->rays == HFVIS_RAYS_EXACT ? "exact" : "lattice", o->max_distance);
    char *t = tag + n;
    size_t left = CLI_TAG_MAX - (size_t)n;
    switch (a->cmd) {
    case CMD_HORIZON: snprintf(t, left, " degrees=%d", a->degrees); break;
    case CMD_SKY: snprintf(t, left, " sky=%a albedo=%a", a->sky, a->albedo); break;
    case CMD_LIGHT:
        snprintf(t, left, " env=%016llx env-size=%dx%dx%d albedo=%a method=%d",
                 cli_fingerprint(env->radiance, (size_t)env->n_theta * (size_t)env->n_phi *
                                 (size_t)env->channels), env->n_phi, env->n_theta, env->channels,
                 a->albedo, a->method);
        break;
    case CMD_VISIBILITY: snprintf(t, left, " fraction=%d", a->fraction); break;
    default: break; /* CMD_SKYVIEW */
    }
}

/* A --dir-range run: the raw sums of directions [A, B) (hfvis_direction_sums; the horizon: its
 * planes) as planes of doubles, saved as a partial result. */
static int cli_run_partial(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts,
                           cli_progress_state *prog, const hfvis_env *env)
{
    const char *cmd = cli_cmd_names[a->cmd];
    const size_t n = (size_t)grid->width * (size_t)grid->height;
    const int count = a->dir_end - a->dir_begin;
    int planes = 1, channels = 1, c;
    double *sums = NULL, *raw = NULL;
    float *map = NULL, *flat_z = NULL;
    char tag[CLI_TAG_MAX];
    hfvis_partial part;
    hfvis_status s = HFVIS_OK;
    size_t i;
    int rc = 0;

    opts->direction_begin = a->dir_begin;
    opts->direction_end = a->dir_end;
    opts->direction_order = HFVIS_DIRECTION_ORDER_SWEEP; /* parts of whole quarter-turn groups */
    if (a->cmd == CMD_HORIZON) {
        planes = count;
        if ((size_t)a->dirs > CLI_HORIZON_MAX_VALUES / n ||
            (long long)a->dirs * grid->height > HFVIS_IMAGE_MAX_DIM)
            return cli_error(CLI_EXIT_ERROR, cmd, "%s: the summed map, %d planes of %d x %d, would exceed "
                             "the limit of 2^28 values and %d rows; use fewer --dirs, or skyview/sky/light",
                             hfvis_status_string(HFVIS_ERR_LIMIT), a->dirs, grid->width, grid->height,
                             HFVIS_IMAGE_MAX_DIM);
    } else if (a->cmd == CMD_LIGHT) planes = channels = env->channels;
    else if (a->cmd == CMD_VISIBILITY && a->fraction) planes = 2;
    if ((unsigned long long)planes * n > HFVIS_PARTIAL_MAX_VALUES || (size_t)planes > SIZE_MAX / 8u / n)
        return cli_error(CLI_EXIT_ERROR, cmd, "%s: %d planes of %d x %d exceed the limit of 2^32 "
                         "values; use a smaller --dir-range", hfvis_status_string(HFVIS_ERR_LIMIT),
                         planes, grid->width, grid->height);
    sums = (double *)malloc(n * (size_t)planes * sizeof(double));
    if (!sums) return cli_status(cmd, HFVIS_ERR_OUT_OF_MEMORY, 0);
    prog->total = (long long)count * (a->cmd == CMD_VISIBILITY && a->fraction ? 2 : 1);
    if (a->cmd == CMD_HORIZON) {
        map = cli_alloc(n, (size_t)planes, 1);
        if (!map) s = HFVIS_ERR_OUT_OF_MEMORY;
        else s = hfvis_horizon_map(grid, a->dirs, opts, map);
        for (i = 0; s == HFVIS_OK && i < n * (size_t)planes; i++) sums[i] = (double)map[i];
    } else if (a->cmd == CMD_LIGHT) {
        hfvis_env_options eopts = hfvis_env_options_default();
        eopts.method = (hfvis_env_method)a->method;
        raw = (double *)malloc(n * (size_t)channels * sizeof(double));
        if (!raw) s = HFVIS_ERR_OUT_OF_MEMORY;
        else s = hfvis_direction_sums(grid, a->dirs, HFVIS_SUM_ENV_LIGHT, env, &eopts, opts, raw);
        for (i = 0; s == HFVIS_OK && i < n; i++) /* interleaved channels -> planes */
            for (c = 0; c < channels; c++) sums[(size_t)c * n + i] = raw[i * (size_t)channels + (size_t)c];
    } else {
        hfvis_sum_kind kind = a->cmd == CMD_SKYVIEW ? HFVIS_SUM_SKY_VIEW
                              : a->cmd == CMD_SKY ? HFVIS_SUM_SKY_LIGHT : HFVIS_SUM_VISIBILITY;
        s = hfvis_direction_sums(grid, a->dirs, kind, NULL, NULL, opts, sums);
        if (s == HFVIS_OK && planes == 2) { /* --fraction: the same sums on a flat field */
            hfvis_grid flat = *grid;
            flat_z = cli_alloc(n, 1, 1);
            if (!flat_z) s = HFVIS_ERR_OUT_OF_MEMORY;
            else {
                for (i = 0; i < n; i++) flat_z[i] = isfinite(grid->z[i]) ? 0.0f : (float)NAN;
                flat.z = flat_z;
                s = hfvis_direction_sums(&flat, a->dirs, kind, NULL, NULL, opts, sums + n);
            }
        }
    }
    if (s != HFVIS_OK) { rc = cli_status(cmd, s, 0); goto done; }
    cli_partial_tag(a, grid, opts, env, tag);
    part.width = grid->width;
    part.height = grid->height;
    part.planes = planes;
    part.directions = a->dirs;
    part.begin = a->dir_begin;
    part.end = a->dir_end;
    part.tag = tag;
    part.sums = sums;
    errno = 0;
    s = cli_partial_save(a->out, &part);
    if (s != HFVIS_OK) rc = cli_status(a->out, s, errno);
done:
    free(flat_z);
    free(raw);
    free(map);
    free(sums);
    return rc;
}

/* The value of key in a tag ("key=value" tokens), copied into out; 0 if absent. */
static int cli_tag_value(const char *tag, const char *key, char *out, size_t cap)
{
    size_t k = strlen(key);
    const char *p = tag;
    while (p && *p) {
        const char *sp = strchr(p, ' ');
        size_t len = sp ? (size_t)(sp - p) : strlen(p);
        if (len > k && !strncmp(p, key, k) && p[k] == '=') {
            if (len - k - 1 >= cap) return 0;
            memcpy(out, p + k + 1, len - k - 1);
            out[len - k - 1] = '\0';
            return 1;
        }
        p = sp ? sp + 1 : NULL;
    }
    return 0;
}

/* The first token of tag a that tag b does not have, or "" (copied into out). */
static void cli_tag_first_difference(const char *a, const char *b, char *out, size_t cap)
{
    const char *p = a;
    out[0] = '\0';
    while (p && *p) {
        const char *sp = strchr(p, ' ');
        size_t len = sp ? (size_t)(sp - p) : strlen(p);
        const char *q = b;
        int found = 0;
        while (q && *q && !found) {
            const char *sq = strchr(q, ' ');
            size_t lq = sq ? (size_t)(sq - q) : strlen(q);
            found = lq == len && !strncmp(p, q, len);
            q = sq ? sq + 1 : NULL;
        }
        if (!found) {
            if (len >= cap) len = cap - 1;
            memcpy(out, p, len);
            out[len] = '\0';
            return;
        }
        p = sp ? sp + 1 : NULL;
    }
}

/* A real parameter of a tag (written with %a). */
static int cli_tag_real(const char *tag, const char *key, double *v)
{
    char buf[64];
    return cli_tag_value(tag, key, buf, sizeof buf) && cli_parse_real(buf, v);
}

/* One part's header and a copy of its tag (pass 1 of `sum` keeps these, not the sums). */
typedef struct cli_part {
    int width, height, planes, directions, begin, end;
    char *tag;
} cli_part;

/* Load path; on success copy its header and tag into m (when m->tag is NULL) or check that they
 * still equal m's (pass 2). The caller frees *p with hfvis_partial_free. */
static int cli_sum_load(const char *path, hfvis_partial *p, cli_part *m)
{
    hfvis_status s;
    errno = 0;
    s = hfvis_partial_load(path, NULL, p);
    if (s == HFVIS_ERR_FORMAT) { /* say which: an old part, or a damaged or foreign file */
        char head[12] = { 0 };
        FILE *f = fopen(path, "rb");
        size_t got = f ? fread(head, 1, 11, f) : 0;
        if (f) fclose(f);
        if (got == 11 && !memcmp(head, "HFVISSUM 1\n", 11))
            return cli_error(CLI_EXIT_ERROR, path, "a version-1 part (no checksum; written by an "
                             "older hfvis): rerun its --dir-range with this hfvis");
        if (got == 11 && !memcmp(head, "HFVISSUM 2\n", 11))
            return cli_error(CLI_EXIT_ERROR, path, "%s: damaged part (its header, size or CRC-32 "
                             "checksum does not match): rerun its --dir-range",
                             hfvis_status_string(s));
    }
    if (s != HFVIS_OK) return cli_status(path, s, errno);
    if (!m->tag) {
        size_t len = strlen(p->tag);
        m->tag = (char *)malloc(len + 1);
        if (!m->tag) {
            hfvis_partial_free(NULL, p);
            return cli_status(path, HFVIS_ERR_OUT_OF_MEMORY, 0);
        }
        memcpy(m->tag, p->tag, len + 1);
        m->width = p->width, m->height = p->height, m->planes = p->planes;
        m->directions = p->directions, m->begin = p->begin, m->end = p->end;
    } else if (strcmp(m->tag, p->tag) || m->width != p->width || m->height != p->height ||
               m->planes != p->planes || m->directions != p->directions || m->begin != p->begin ||
               m->end != p->end) {
        hfvis_partial_free(NULL, p);
        return cli_error(CLI_EXIT_ERROR, path, "changed while being summed");
    }
    return 0;
}

/* The domain of a part's values (NaN marks a hole in every kind): horizon elevations lie in
 * [-pi/2, pi/2] (as floats); a sky-view sum of n directions in [0, n] (each term
 * sin(max(alpha, 0))); sky light terms ([P1] Eq. 5) in [0, 1] each; environment sums are finite
 * and >= 0 (radiance >= 0); visibility counts in [0, n*(W + H + 3)] (a lattice line holds at
 * most diagonal + 3 nodes). A value outside is refused rather than summed. */
static int cli_sum_check(const char *path, int cmd, const hfvis_partial *p)
{
    const size_t count = (size_t)p->width * (size_t)p->height * (size_t)p->planes;
    const double n = (double)(p->end - p->begin);
    double lo = 0.0, hi = n;
    size_t k;
    char rays[16];
    if ((cmd == CMD_SKYVIEW || cmd == CMD_SKY) && cli_tag_value(p->tag, "rays", rays, sizeof rays) &&
        !strcmp(rays, "exact")) { /* exact rays weight direction k by K w_k, its share of the circle */
        hfvis_sweep_options o = hfvis_sweep_options_default();
        double *w = (double *)malloc(sizeof(double) * (size_t)p->directions), wmax = 0.0;
        o.rays = HFVIS_RAYS_EXACT;
        if (!w || !cli_tag_real(p->tag, "azimuth0", &o.azimuth0_rad) ||
            hfvis_sweep_azimuths(p->directions, &o, NULL, w) != HFVIS_OK) {
            free(w);
            return cli_error(CLI_EXIT_ERROR, path, "cannot recompute the exact-ray weights of this part");
        }
        for (k = 0; k < (size_t)p->directions; k++) if (w[k] > wmax) wmax = w[k];
        free(w);
        hi = n * (double)p->directions * wmax;
    }
    if (cmd == CMD_HORIZON) hi = (double)(float)(CLI_PI / 2.0), lo = -hi;
    else if (cmd == CMD_LIGHT) hi = HUGE_VAL;
    else if (cmd == CMD_VISIBILITY) hi = n * ((double)p->width + (double)p->height + 3.0);
    for (k = 0; k < count; k++) {
        double v = p->sums[k];
        if (isnan(v)) continue;
        if (!(v >= lo && v <= hi && isfinite(v)))
            return cli_error(CLI_EXIT_ERROR, path, "value %.17g at index %lu lies outside the domain "
                             "[%g, %g] of a %s part: the file is damaged", v, (unsigned long)k, lo, hi,
                             cli_cmd_names[cmd]);
    }
    return 0;
}

/* `hfvis sum PART... -o OUT`: check that the parts are one run's and tile [0, K) (pass 1 reads
 * each part and keeps only its header), then add them in direction order, one part in memory at
 * a time (pass 2), finish exactly as the single run does and write OUT (atomically: the codecs
 * write a temporary file and rename it). */
static int cli_refuse_input(int overwrite, const char *out, const char *const *inputs, int n);
static int cli_sum(int argc, char **argv)
{
    enum { MAX_PARTS = 4096 };
    static cli_part meta[MAX_PARTS];
    static const char *names[MAX_PARTS];
    static int order[MAX_PARTS];
    cli_args a;
    const char *cmdname = "sum";
    char name[32], key[64], other[64];
    int nparts = 0, i, j, rc = 0, cmd, K, W, H, planes, channels = 1, out_planes = 1, deg = 0;
    double lo = 0.0, hi = 1.0, *acc = NULL;
    float *out = NULL;
    size_t n, k;

    memset(&a, 0, sizeof a);
    for (i = 2; i < argc; i++) {
        const char *arg = argv[i];
        if (!strcmp(arg, "-h") || !strcmp(arg, "--help")) {
            printf("%s", cli_cmd_help[CMD_SUM]);
            return 0;
        }
        if (!strcmp(arg, "-o") || !strncmp(arg, "-o=", 3) || !strcmp(arg, "--range") ||
            !strncmp(arg, "--range=", 8)) {
            int is_o = arg[1] == 'o';
            const char *eq = strchr(arg, '='), *v = eq ? eq + 1 : (i + 1 < argc ? argv[++i] : NULL);
            if (!v) return cli_error(CLI_EXIT_USAGE, is_o ? "-o" : "--range", "missing value");
            if (is_o) {
                if (!cli_ends_with(v, ".pfm") && !cli_ends_with(v, ".pgm"))
                    return cli_error(CLI_EXIT_USAGE, v, "unknown output type (use a .pfm or .pgm name)");
                a.out = v;
                a.out_pgm = cli_ends_with(v, ".pgm");
            } else if (cli_set(&a, "--range", v)) {
                return CLI_EXIT_USAGE;
            }
            continue;
        }
        if (!strcmp(arg, "--quiet")) continue;
        if (!strcmp(arg, "--overwrite")) { a.overwrite = 1; continue; }
        if (arg[0] == '-' && arg[1] != '\0')
            return cli_error(CLI_EXIT_USAGE, arg, "unknown option (see 'hfvis sum --help')");
        if (nparts == MAX_PARTS) return cli_error(CLI_EXIT_USAGE, arg, "more than %d parts", MAX_PARTS);
        names[nparts++] = arg;
    }
    if (nparts == 0) return cli_error(CLI_EXIT_USAGE, cmdname, "missing PART.hfvs files");
    if (!a.out) return cli_error(CLI_EXIT_USAGE, cmdname, "missing -o OUT");
    if (a.has_range && !a.out_pgm) return cli_error(CLI_EXIT_USAGE, "--range", "applies only to .pgm output");
    if ((rc = cli_refuse_input(a.overwrite, a.out, names, nparts)) != 0) return rc;

    /* pass 1: headers and tags */
    for (i = 0; i < nparts; i++) meta[i].tag = NULL;
    for (i = 0; i < nparts; i++) {
        hfvis_partial p;
        if ((rc = cli_sum_load(names[i], &p, &meta[i])) != 0) goto done;
        hfvis_partial_free(NULL, &p);
    }
    /* the first part decides the run; every other part must be the same run */
    if (!cli_tag_value(meta[0].tag, "cmd", name, sizeof name)) name[0] = '\0';
    for (cmd = 0; cmd < CMD_COUNT && strcmp(name, cli_cmd_names[cmd]); cmd++) {}
    if (cmd != CMD_HORIZON && cmd != CMD_SKYVIEW && cmd != CMD_SKY && cmd != CMD_LIGHT &&
        cmd != CMD_VISIBILITY) {
        rc = cli_error(CLI_EXIT_ERROR, names[0], "not a partial result of hfvis horizon, skyview, sky, "
                       "light or visibility");
        goto done;
    }
    K = meta[0].directions, W = meta[0].width, H = meta[0].height, planes = meta[0].planes;
    for (i = 1; i < nparts; i++) {
        const cli_part *p = &meta[i];
        if (p->width != W || p->height != H || p->directions != K ||
            (cmd != CMD_HORIZON && p->planes != planes)) {
            rc = cli_error(CLI_EXIT_ERROR, names[i], "not the same run as %s: %d x %d x %d values of "
                           "K = %d there, %d x %d x %d of K = %d here", names[0], W, H, planes, K,
                           p->width, p->height, p->planes, p->directions);
            goto done;
        }
        cli_tag_first_difference(p->tag, meta[0].tag, key, sizeof key);
        if (key[0]) {
            char *eq = strchr(key, '=');
            if (eq) *eq = '\0';
            if (!cli_tag_value(meta[0].tag, key, other, sizeof other)) strcpy(other, "(none)");
            rc = cli_error(CLI_EXIT_ERROR, names[i], "not the same run as %s: %s=%s there, %s here",
                           names[0], key, other, eq ? eq + 1 : "");
            goto done;
        }
    }
    for (i = 0; i < nparts; i++) /* horizon parts hold one plane per direction */
        if (cmd == CMD_HORIZON && meta[i].planes != meta[i].end - meta[i].begin) {
            rc = cli_error(CLI_EXIT_ERROR, names[i], "%d planes for directions %d:%d", meta[i].planes,
                           meta[i].begin, meta[i].end);
            goto done;
        }
    /* the ranges, sorted by their first direction (insertion sort), must tile [0, K) */
    for (i = 0; i < nparts; i++) {
        for (j = i; j > 0 && meta[order[j - 1]].begin > meta[i].begin; j--) order[j] = order[j - 1];
        order[j] = i;
    }
    for (i = 0; i < nparts; i++) {
        int b = meta[order[i]].begin, prev_end = i ? meta[order[i - 1]].end : 0;
        if (b < prev_end) {
            rc = cli_error(CLI_EXIT_ERROR, names[order[i]], "directions %d:%d overlap %d:%d of %s",
                           b, meta[order[i]].end, meta[order[i - 1]].begin, prev_end,
                           names[order[i - 1]]);
            goto done;
        }
        if (b > prev_end) {
            rc = cli_error(CLI_EXIT_ERROR, cmdname, "directions %d:%d of K = %d are missing (no part "
                           "holds them)", prev_end, b, K);
            goto done;
        }
    }
    if (meta[order[nparts - 1]].end != K) {
        rc = cli_error(CLI_EXIT_ERROR, cmdname, "directions %d:%d of K = %d are missing (no part holds "
                       "them)", meta[order[nparts - 1]].end, K, K);
        goto done;
    }

    /* pass 2: add in direction order and finish as the single run (cli_run) does */
    n = (size_t)W * (size_t)H;
    if (cmd == CMD_LIGHT) channels = planes;
    if (cmd == CMD_HORIZON) out_planes = K;
    if ((size_t)out_planes > CLI_HORIZON_MAX_VALUES / n || (long long)out_planes * H > HFVIS_IMAGE_MAX_DIM) {
        rc = cli_error(CLI_EXIT_ERROR, cmdname, "%s: %d planes of %d x %d exceed the limit of 2^28 "
                       "values and %d rows", hfvis_status_string(HFVIS_ERR_LIMIT), out_planes, W, H,
                       HFVIS_IMAGE_MAX_DIM);
        goto done;
    }
    out = cli_alloc(n, (size_t)out_planes, (size_t)channels);
    if (cmd != CMD_HORIZON) acc = (double *)malloc(n * (size_t)planes * sizeof(double));
    if (!out || (cmd != CMD_HORIZON && !acc)) {
        rc = cli_status(cmdname, HFVIS_ERR_OUT_OF_MEMORY, 0);
        goto done;
    }
    if (cmd == CMD_HORIZON) {
        char v[8];
        deg = cli_tag_value(meta[0].tag, "degrees", v, sizeof v) && !strcmp(v, "1");
        lo = deg ? -90.0 : -CLI_PI / 2.0;
        hi = deg ? 90.0 : CLI_PI / 2.0;
    }
    for (i = 0; i < nparts; i++) {
        hfvis_partial p;
        const size_t count = n * (size_t)meta[order[i]].planes;
        if ((rc = cli_sum_load(names[order[i]], &p, &meta[order[i]])) != 0) goto done;
        if ((rc = cli_sum_check(names[order[i]], cmd, &p)) != 0) {
            hfvis_partial_free(NULL, &p);
            goto done;
        }
        if (cmd == CMD_HORIZON) { /* plane j is the direction at sweep position begin + j */
            for (j = 0; j < p.planes; j++) {
                int pos = p.begin + j, kk = K % 4 ? pos : pos / 4 + (pos % 4) * (K / 4);
                const double *src = p.sums + (size_t)j * n;
                float *dst = out + (size_t)kk * n;
                for (k = 0; k < n; k++) dst[k] = deg ? (float)(src[k] * (180.0 / CLI_PI)) : (float)src[k];
            }
        } else if (i == 0) {
            memcpy(acc, p.sums, count * sizeof(double));
        } else {
            for (k = 0; k < count; k++) acc[k] += p.sums[k];
        }
        hfvis_partial_free(NULL, &p);
    }
    if (cmd == CMD_SKYVIEW) {
        for (k = 0; k < n; k++) out[k] = (float)(1.0 + (-1.0 / (double)K) * acc[k]);
    } else if (cmd == CMD_SKY) {
        double sky = 0.0, albedo = 0.0, scale;
        if (!cli_tag_real(meta[0].tag, "sky", &sky) || !cli_tag_real(meta[0].tag, "albedo", &albedo)) {
            rc = cli_error(CLI_EXIT_ERROR, names[0], "the part does not name its sky and albedo");
            goto done;
        }
        scale = (double)(float)sky * (double)(float)albedo; /* the floats the single run passes */
        for (k = 0; k < n; k++) out[k] = (float)(0.0 + scale * acc[k]);
        if (sky * albedo <= CLI_FLT_MAX && (float)(sky * albedo) > 0.0f) hi = sky * albedo;
    } else if (cmd == CMD_LIGHT) {
        double albedo = 0.0;
        int c;
        if (!cli_tag_real(meta[0].tag, "albedo", &albedo)) {
            rc = cli_error(CLI_EXIT_ERROR, names[0], "the part does not name its albedo");
            goto done;
        }
        for (k = 0; k < n; k++)
            for (c = 0; c < channels; c++)
                out[k * (size_t)channels + (size_t)c] =
                    (float)(0.0 + (double)(float)albedo * acc[(size_t)c * n + k]);
        hi = cli_top(out, n * (size_t)channels, 1.0);
    } else if (cmd == CMD_VISIBILITY) { /* with --fraction plane 1 holds the flat field's counts */
        for (k = 0; k < n; k++) {
            float count = (float)(0.0 + 1.0 * acc[k]);
            if (planes == 2 && !isnan(count)) {
                float tested = (float)(0.0 + 1.0 * acc[n + k]);
                count = tested > 0.0f ? (float)((double)count / (double)tested) : 0.0f;
            }
            out[k] = count;
        }
        hi = planes == 2 ? 1.0 : cli_top(out, n, 1.0);
    }
    if (cmd == CMD_SKY || cmd == CMD_LIGHT) /* finite sums scaled past the float range */
        for (k = 0; k < n * (size_t)channels; k++)
            if (!isfinite(out[k]) && isfinite(acc[(k % (size_t)channels) * n + k / (size_t)channels])) {
                rc = cli_error(CLI_EXIT_ERROR, "sum", "the result at column %d, row %d is %g: the "
                               "parts' sky, environment or albedo overflow the float range (3.4e38)",
                               (int)(k / (size_t)channels % (size_t)W),
                               (int)(k / (size_t)channels / (size_t)W), (double)out[k]);
                goto done;
            }
    rc = cli_save(&a, out, W, H * out_planes, channels, lo, hi);
done:
    free(acc);
    free(out);
    for (i = 0; i < nparts; i++) free(meta[i].tag);
    return rc;
}

/* ------------------------------------------------------------------------------------------ */
/* GIS commands and safety: same-file refusal, progress lines, map coordinates, viewshed,       */
/* hillshade, openness, SAGA's sky-view factor, horizon planes per file                         */
/* ------------------------------------------------------------------------------------------ */

static double cli_t0;             /* start of the run, cli_now() */
static double cli_run_cells;      /* grid samples of the run, for the summary line */
static int cli_run_directions;    /* directions of the run (0: none), for the summary line */
static double cli_line_last;      /* when the last --progress line was printed */
static int cli_line_pct = -1;     /* and its percentage */

/* Seconds on a monotonic clock (wall clock where there is none). */
static double cli_now(void)
{
#if defined(CLOCK_MONOTONIC) && defined(CLI_HAVE_ISATTY)
    struct timespec ts;
    if (clock_gettime(CLOCK_MONOTONIC, &ts) == 0) return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
#endif
    return (double)time(NULL);
}

/* hfvis_progress_fn of --progress: plain lines "hfvis CMD: P% (done/total), T s elapsed, ETA E s"
 * on stderr, one per 5% (or per 30 s), for logs and job schedulers. */
static void cli_progress_line(void *user, int done, int total)
{
    cli_progress_state *p = (cli_progress_state *)user;
    long long all, now;
    double t = cli_now() - cli_t0;
    int pct;
    cli_progress_advance(p, done, total, &now, &all);
    pct = all > 0 ? (int)(now * 100 / all) : 100;
    if (pct >= cli_line_pct + 5 || now == all || t - cli_line_last >= 30.0) {
        if (now >= all)
            fprintf(stderr, "hfvis %s: 100%% (%lld/%lld), %.1f s\n", p->label, now, all, t);
        else if (now > 0)
            fprintf(stderr, "hfvis %s: %d%% (%lld/%lld), %.0f s elapsed, ETA %.0f s\n", p->label, pct,
                    now, all, t, t * (double)(all - now) / (double)now);
        else
            fprintf(stderr, "hfvis %s: 0%% (0/%lld), %.0f s elapsed\n", p->label, all, t);
        fflush(stderr);
        cli_line_pct = pct;
        cli_line_last = t;
    }
}

/* Whether paths x and y name one file (same device and inode: hard links and symbolic links
 * too); 0 when either does not exist. */
static int cli_same_file(const char *x, const char *y)
{
#ifdef CLI_HAVE_ISATTY
    struct stat sx, sy;
    if (stat(x, &sx) != 0 || stat(y, &sy) != 0) return 0;
    return sx.st_dev == sy.st_dev && sx.st_ino == sy.st_ino;
#else
    return strcmp(x, y) == 0;
#endif
}

/* Refuse to write out over one of the n inputs (NULL entries skipped) unless --overwrite:
 * 0, or CLI_EXIT_ERROR after one error line. */
static int cli_refuse_input(int overwrite, const char *out, const char *const *inputs, int n)
{
    int i;
    for (i = 0; i < n && !overwrite; i++)
        if (inputs[i] && cli_same_file(out, inputs[i]))
            return cli_error(CLI_EXIT_ERROR, out, "is the input %s: refusing to replace an input "
                             "(give --overwrite to do so)", inputs[i]);
    return 0;
}

/* Every input of a command against out. */
static int cli_refuse_inputs(const cli_args *a, const char *out)
{
    const char *inputs[5];
    inputs[0] = a->in, inputs[1] = a->env, inputs[2] = a->albedo_map, inputs[3] = a->emission;
    inputs[4] = a->vf_reference;
    return cli_refuse_input(a->overwrite, out, inputs, 5);
}

/* The georeference as a GDAL geotransform: map X = gt[0] + P*gt[1] + L*gt[2],
 * Y = gt[3] + P*gt[4] + L*gt[5] for pixel-corner coordinates (P, L); the sample of column c, row
 * r is the centre of its pixel, (P, L) = (c + 0.5, r + 0.5). Without a georeferenced input
 * (PFM, PGM) the sample of column c, row r lies at X = c*cell, Y = r*cell (the library's world
 * frame: Y grows southward). */
static void cli_georef(const cli_args *a, double cell, double gt[6])
{
    int i;
    if (a->has_geotransform) {
        for (i = 0; i < 6; i++) gt[i] = a->geotransform[i];
        return;
    }
    if (cli_geo.has_transform) { /* a georeferenced input (GeoTIFF, ASC, EHdr) */
        for (i = 0; i < 6; i++) gt[i] = cli_geo.gt[i];
        return;
    }
    gt[0] = -0.5 * cell, gt[1] = cell, gt[2] = 0.0;
    gt[3] = -0.5 * cell, gt[4] = 0.0, gt[5] = cell;
}

/* Map point (X, Y) -> grid position (x, y) (column, row of sample centres); 0 if the transform
 * cannot be inverted. */
static int cli_map_to_grid(const cli_args *a, double cell, double X, double Y, double *x, double *y)
{
    double gt[6], det, dx, dy;
    cli_georef(a, cell, gt);
    det = gt[1] * gt[5] - gt[2] * gt[4];
    if (!(fabs(det) > 0.0) || !isfinite(det)) return 0;
    dx = X - gt[0], dy = Y - gt[3];
    *x = (gt[5] * dx - gt[2] * dy) / det - 0.5;
    *y = (-gt[4] * dx + gt[1] * dy) / det - 0.5;
    return isfinite(*x) && isfinite(*y);
}

/* viewshed: the observer (map coordinates, or --observer-grid) on a sample that is not NoData,
 * optional Earth curvature and refraction as in GRASS r.viewshed (each target's height lowered by
 * (1 - k) d^2 / (2 R), d its horizontal distance from the observer), R2 or the exact oracle, and
 * the verdict at each --target on stdout. */
static int cli_run_viewshed(const cli_args *a, const hfvis_grid *grid, float *out)
{
    const int w = grid->width, h = grid->height;
    const size_t n = (size_t)w * (size_t)h;
    hfvis_viewshed_options vo;
    hfvis_grid g = *grid;
    float *zc = NULL;
    double ox = a->observer_x, oy = a->observer_y;
    hfvis_status s;
    int rc = 0, t;
    memset(&vo, 0, sizeof vo);
    vo.observer_height = a->observer_height;
    vo.target_height = a->target_height;
    vo.max_distance = a->max_distance;
    if (!a->observer_grid && !cli_map_to_grid(a, grid->cell_size, a->observer_x, a->observer_y, &ox, &oy))
        return cli_error(CLI_EXIT_ERROR, "--observer", "the georeference cannot be inverted");
    if (!(ox >= 0.0 && ox <= w - 1 && oy >= 0.0 && oy <= h - 1))
        return cli_error(CLI_EXIT_ERROR, a->observer_grid ? "--observer-grid" : "--observer",
                         "%g,%g (column %g, row %g) is outside the grid [0, %d] x [0, %d]",
                         a->observer_x, a->observer_y, ox, oy, w - 1, h - 1);
    if (isnan(hfvis_grid_sample(grid, ox, oy)))
        return cli_error(CLI_EXIT_ERROR, a->observer_grid ? "--observer-grid" : "--observer",
                         "%g,%g (column %g, row %g) is on NoData: the observer needs ground",
                         a->observer_x, a->observer_y, ox, oy);
    if (a->curvature) { /* GRASS r.viewshed -c -r: z - (1 - k) d^2/(2R), d in metres */
        const double c = (1.0 - a->refraction) / (2.0 * a->earth_radius);
        size_t i;
        zc = cli_alloc(n, 1, 1);
        if (!zc) return cli_status("viewshed", HFVIS_ERR_OUT_OF_MEMORY, 0);
        for (i = 0; i < n; i++) {
            double dx = ((double)(i % (size_t)w) - ox) * grid->cell_size;
            double dy = ((double)(i / (size_t)w) - oy) * grid->cell_size;
            zc[i] = (float)((double)grid->z[i] - c * (dx * dx + dy * dy));
        }
        g.z = zc;
        g.stride = w;
    }
    if (a->exact) s = hfvis_viewshed_reference(&g, ox, oy, &vo, 0.0, out, w);
    else s = hfvis_viewshed(&g, ox, oy, &vo, out, w);
    free(zc);
    if (s != HFVIS_OK) return cli_status("viewshed", s, 0);
    for (t = 0; t < a->ntargets; t++) { /* the verdict of the sample nearest to each target */
        double X = a->targets[2 * t], Y = a->targets[2 * t + 1], x, y;
        const char *verdict = "outside the grid";
        long c = -1, r = -1;
        if (cli_map_to_grid(a, grid->cell_size, X, Y, &x, &y) && x > -0.5 && x < w - 0.5 &&
            y > -0.5 && y < h - 0.5) {
            float v;
            c = (long)floor(x + 0.5), r = (long)floor(y + 0.5);
            v = out[(size_t)r * (size_t)w + (size_t)c];
            verdict = v == 1.0f ? "visible" : v == 0.0f ? "hidden" :
                      isnan(grid->z[(size_t)r * (size_t)grid->stride + (size_t)c]) ? "no data"
                      : "beyond --max-distance";
        }
        printf("target %.10g,%.10g (column %ld, row %ld): %s\n", X, Y, c, r, verdict);
    }
    if (a->ntargets > 0 && fflush(stdout) != 0) rc = cli_error(CLI_EXIT_ERROR, "stdout", "%s", strerror(errno));
    return rc;
}

/* hillshade: H = (1/N) sum_j max(n . l_j, 0) V_j over N suns spread evenly in azimuth from
 * --sun-azimuth (N = --blend), n the grid normal, l_j the direction of sun j's centre and V_j its
 * visibility from the exact sweep (hfvis_sun_visibility: 0/1, or the visible fraction of a disc
 * of --sun-radius), V_j = 1 with --no-shadows. In [0, 1]; NaN at holes. */
static int cli_run_hillshade(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts,
                             cli_progress_state *prog, float *out)
{
    const int w = grid->width, N = a->blend;
    const size_t n = (size_t)w * (size_t)grid->height;
    const double el = a->sun_elevation * (CLI_PI / 180.0), psi0 = a->sun_azimuth * (CLI_PI / 180.0);
    float *nrm = cli_alloc(n, 3, 1), *vis = cli_alloc(n, 1, 1);
    double *acc = (double *)calloc(n, sizeof(double));
    hfvis_status s = HFVIS_OK;
    size_t i;
    int j, rc = 0;
    if (!nrm || !vis || !acc) { rc = cli_status("hillshade", HFVIS_ERR_OUT_OF_MEMORY, 0); goto done; }
    s = hfvis_normals_compute(grid, nrm);
    prog->total = N;
    for (j = 0; s == HFVIS_OK && j < N; j++) {
        const double psi = psi0 + 2.0 * CLI_PI * j / N;
        const double l[3] = { cos(el) * cos(psi), cos(el) * sin(psi), sin(el) };
        if (a->no_shadows) {
            for (i = 0; i < n; i++) vis[i] = 1.0f;
            if (opts->progress) opts->progress(opts->progress_user, 1, 1);
        } else {
            s = hfvis_sun_visibility(grid, psi, el, a->sun_radius * (CLI_PI / 180.0), opts, vis, w);
        }
        for (i = 0; s == HFVIS_OK && i < n; i++) {
            double d = (double)nrm[3 * i] * l[0] + (double)nrm[3 * i + 1] * l[1] + (double)nrm[3 * i + 2] * l[2];
            acc[i] += (d > 0.0 ? d : 0.0) * (double)vis[i];
        }
    }
    if (s != HFVIS_OK) { rc = cli_status("hillshade", s, 0); goto done; }
    for (i = 0; i < n; i++) out[i] = isfinite(grid->z[(i / (size_t)w) * (size_t)grid->stride + i % (size_t)w])
                                     ? (float)(acc[i] / N) : (float)NAN;
done:
    free(acc);
    free(vis);
    free(nrm);
    return rc;
}

/* openness: hfvis_openness (Yokoyama et al. 2002), in radians or, with --degrees, degrees. */
static int cli_run_openness(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts,
                            cli_progress_state *prog, float *out)
{
    hfvis_openness_options oo;
    hfvis_status s;
    size_t i, n = (size_t)grid->width * (size_t)grid->height;
    memset(&oo, 0, sizeof oo);
    oo.radius = a->radius;
    oo.negative = a->negative;
    prog->total = a->radius > 0.0 ? grid->height : a->dirs; /* rows of the march, or directions */
    s = hfvis_openness(grid, a->dirs, &oo, opts, out, grid->width);
    if (s != HFVIS_OK) return cli_status("openness", s, 0);
    if (a->degrees)
        for (i = 0; i < n; i++) out[i] = (float)((double)out[i] * (180.0 / CLI_PI));
    return 0;
}

/* skyview --svf saga|visible, SAGA's "Sky View Factor" tool (ta_lighting, after Hantzschel et al.
 * 2005), from the K horizon angles phi_k = max(alpha_k, 0) (SAGA never lets a horizon fall below
 * the horizontal) and the grid normal (n_x, n_y, n_z):
 *   saga:    (1/K) sum_k [n_z cos^2 phi_k + (n_x cos psi_k + n_y sin psi_k)(pi/2 - phi_k - sin phi_k cos phi_k)]
 *            (n_z = cos slope, n_x cos psi + n_y sin psi = sin slope cos(psi - aspect)): the
 *            cosine-weighted sky, 1 - (1/K) sum sin^2 phi_k on level ground;
 *   visible: (1/K) sum_k (1 - phi_k/(pi/2)), SAGA's "Visible Sky" as a fraction (SAGA: percent). */
static int cli_run_skyview_saga(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts,
                                cli_progress_state *prog, float *out)
{
    const int w = grid->width, K = a->dirs;
    const size_t n = (size_t)w * (size_t)grid->height;
    float *nrm = a->svf == 1 ? cli_alloc(n, 3, 1) : NULL, *plane = cli_alloc(n, 1, 1);
    double *acc = (double *)calloc(n, sizeof(double));
    hfvis_status s = HFVIS_OK;
    size_t i;
    int k, rc = 0;
    if ((a->svf == 1 && !nrm) || !plane || !acc) { rc = cli_status("skyview", HFVIS_ERR_OUT_OF_MEMORY, 0); goto done; }
    if (nrm) s = hfvis_normals_compute(grid, nrm);
    prog->total = K;
    for (k = 0; s == HFVIS_OK && k < K; k++) {
        const double psi = opts->azimuth0_rad + 2.0 * CLI_PI * k / K, c = cos(psi), sn = sin(psi);
        s = hfvis_horizon_direction(grid, K, k, opts, plane, w);
        for (i = 0; s == HFVIS_OK && i < n; i++) {
            double phi = (double)plane[i] > 0.0 ? (double)plane[i] : 0.0;
            if (isnan(plane[i])) { acc[i] = (double)NAN; continue; }
            if (nrm)
                acc[i] += (double)nrm[3 * i + 2] * cos(phi) * cos(phi) +
                          ((double)nrm[3 * i] * c + (double)nrm[3 * i + 1] * sn) *
                              (CLI_PI / 2.0 - phi - sin(phi) * cos(phi));
            else
                acc[i] += 1.0 - phi / (CLI_PI / 2.0);
        }
    }
    if (s != HFVIS_OK) { rc = cli_status("skyview", s, 0); goto done; }
    for (i = 0; i < n; i++) out[i] = (float)(acc[i] / K);
done:
    free(acc);
    free(plane);
    free(nrm);
    return rc;
}

/* The commands of this section: compute into out (W x H) and save it. */
static int cli_run_gis(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts,
                       cli_progress_state *prog)
{
    const int w = grid->width, h = grid->height;
    float *out = cli_alloc((size_t)w, (size_t)h, 1);
    double lo = 0.0, hi = 1.0;
    int rc;
    if (!out) return cli_status(cli_cmd_names[a->cmd], HFVIS_ERR_OUT_OF_MEMORY, 0);
    if (a->cmd == CMD_VIEWSHED) {
        rc = cli_run_viewshed(a, grid, out);
    } else if (a->cmd == CMD_HILLSHADE) {
        cli_run_directions = a->blend;
        rc = cli_run_hillshade(a, grid, opts, prog, out);
    } else if (a->cmd == CMD_OPENNESS) {
        hi = a->degrees ? 180.0 : CLI_PI; /* 0 .. 180 degrees */
        rc = cli_run_openness(a, grid, opts, prog, out);
    } else {
        rc = cli_run_skyview_saga(a, grid, opts, prog, out);
    }
    if (rc == 0) rc = cli_save(a, out, w, h, 1, lo, hi);
    free(out);
    return rc;
}

/* horizon, after the sweep: the planes in the user's convention's order (GRASS's run
 * counter-clockwise) and, with --split, one file per direction named OUT's stem + "_" + the
 * direction's azimuth in degrees in the convention (as r.horizon names its maps: "_045", or
 * "_022_500" for 22.5), else the stacked map. */
static int cli_horizon_finish(const cli_args *a, float *map, int w, int h, double lo, double hi)
{
    const size_t n = (size_t)w * (size_t)h;
    const int K = a->dirs;
    int k, rc = 0;
    if (a->convention == CONV_GRASS && K > 2) { /* plane k <- library plane (K - k) % K, in place */
        float *tmp = cli_alloc(n, 1, 1);
        if (!tmp) return cli_status("horizon", HFVIS_ERR_OUT_OF_MEMORY, 0);
        for (k = 1; k < K - k; k++) {
            memcpy(tmp, map + (size_t)k * n, n * sizeof(float));
            memcpy(map + (size_t)k * n, map + (size_t)(K - k) * n, n * sizeof(float));
            memcpy(map + (size_t)(K - k) * n, tmp, n * sizeof(float));
        }
        free(tmp);
    }
    if (!a->split) return cli_save(a, map, w, h * K, 1, lo, hi);
    for (k = 0; k < K && rc == 0; k++) {
        cli_args one = *a;
        char name[4096];
        const char *dot = strrchr(a->out, '.');
        const double psi = a->azimuth0 + 2.0 * CLI_PI * cli_lib_direction(a, k) / K;
        double deg = cli_from_psi(a->convention, psi);
        long whole = (long)floor(deg), milli = (long)floor((deg - (double)whole) * 1000.0 + 0.5);
        size_t stem = dot ? (size_t)(dot - a->out) : strlen(a->out);
        int len;
        if (milli == 1000) whole++, milli = 0;
        if (milli == 0)
            len = snprintf(name, sizeof name, "%.*s_%03ld%s", (int)stem, a->out, whole, a->out + stem);
        else
            len = snprintf(name, sizeof name, "%.*s_%03ld_%03ld%s", (int)stem, a->out, whole, milli,
                           a->out + stem);
        if (len < 0 || (size_t)len >= sizeof name) return cli_error(CLI_EXIT_ERROR, a->out, "name too long");
        if ((rc = cli_refuse_inputs(a, name)) != 0) return rc;
        one.out = name;
        rc = cli_save(&one, map + (size_t)k * n, w, h, 1, lo, hi);
    }
    return rc;
}

/* ------------------------------------------------------------------------------------------ */
/* tiles: a --window run writes a piece and its sidecar, `mosaic` assembles the pieces          */
/* (docs/tiles.md)                                                                              */
/* ------------------------------------------------------------------------------------------ */

#define CLI_PIECE_MAGIC "HFVISTILE 1\n"
#define CLI_PIECE_SIDECAR ".tile" /* appended to the piece's name */

/* The run tag of a piece: every key that must match across the pieces of one run. The order
 * matters: `mosaic` names the first key that differs, so the CRS and cell size come before
 * the input's identity (a reprojected input differs in all three). Over-inclusive on purpose:
 * every value-changing flag of every tiled command, whatever the command. */
static void cli_piece_tag(const cli_args *a, const hfvis_grid *grid, const hfvis_sweep_options *o)
{
    char env_id[64] = "none", nodata_flag[40] = "none";
    if (a->env && cli_file_id(a->env, env_id, sizeof env_id) != 0) strcpy(env_id, "unreadable");
    if (a->has_nodata) snprintf(nodata_flag, sizeof nodata_flag, "%a", (double)(float)a->nodata);
    snprintf(cli_win.tag, sizeof cli_win.tag,
             "cmd=%s crs=%s cell=%a extent=%dx%d in=%s gt=%s band=%d nodata=%s set-nodata=%s zscale=%a "
             "max-distance=%a dirs=%d border=%d border-cells=%d azimuth0=%a rays=%s convention=%d "
             "degrees=%d svf=%d sky=%a albedo=%a sun=%a,%a,%a,%a,%d blend=%d no-shadows=%d radius=%a "
             "negative=%d fraction=%d method=%d bounces=%d output=%d env=%s",
             cli_cmd_names[a->cmd], cli_win.crs, grid->cell_size, cli_win.ext_w, cli_win.ext_h,
             cli_win.in_id, cli_win.gt, a->band ? a->band : 1, cli_win.nodata, nodata_flag, a->zscale,
             o->max_distance, a->dirs, (int)o->border, o->border_cells, o->azimuth0_rad,
             o->rays == HFVIS_RAYS_EXACT ? "exact" : "lattice", a->convention, a->degrees, a->svf,
             a->sky, a->albedo, a->sun_azimuth, a->sun_elevation, a->sun_radius, a->sun_irradiance,
             a->has_sun_azimuth, a->blend, a->no_shadows, a->radius, a->negative, a->fraction,
             a->method, a->bounces, a->output, env_id);
}

/* Commands whose default PGM range tops at the largest output value (mosaic recomputes it). */
static int cli_range_is_top(int cmd, int fraction)
{
    return cmd == CMD_LIGHT || cmd == CMD_INDIRECT || (cmd == CMD_VISIBILITY && !fraction);
}

/* A --window run's output: the window cut out of each plane of the grid's result (w x h with
 * the planes stacked), written as OUT with the georeference moved to the window, then the
 * sidecar OUT.tile: the window, the planes and channels, the default range, the run tag. */
static int cli_save_piece(const cli_args *a, const float *px, int w, int h, int channels, double lo,
                          double hi)
{
    const cli_window v = cli_win;
    const int planes = h / v.gh;
    const size_t row = (size_t)v.w * (size_t)channels;
    float *cut = cli_alloc((size_t)v.w * (size_t)v.h, (size_t)planes, (size_t)channels);
    char *side = NULL, *text = NULL, range[96];
    size_t len;
    int p, y, rc;
    hfvis_status s;
    if (!cut) return cli_status(a->out, HFVIS_ERR_OUT_OF_MEMORY, 0);
    for (p = 0; p < planes; p++)
        for (y = 0; y < v.h; y++)
            memcpy(cut + ((size_t)p * (size_t)v.h + (size_t)y) * row,
                   px + (((size_t)p * (size_t)v.gh + (size_t)(v.y0 - v.gy0 + y)) * (size_t)w +
                         (size_t)(v.x0 - v.gx0)) * (size_t)channels, row * sizeof(float));
    cli_win.active = 0; /* write it as an ordinary output of v.w x v.h cells */
    cli_in_height = v.h;
    rc = cli_save(a, cut, v.w, v.h * planes, channels, lo, hi);
    free(cut);
    if (rc != 0) return rc;
    if (cli_range_is_top(a->cmd, a->fraction)) strcpy(range, "top");
    else snprintf(range, sizeof range, "%a:%a", lo, hi);
    len = strlen(a->out) + sizeof CLI_PIECE_SIDECAR;
    side = (char *)malloc(len);
    text = (char *)malloc(CLI_PIECE_TAG_MAX + 256);
    if (!side || !text) {
        free(side);
        free(text);
        return cli_status(a->out, HFVIS_ERR_OUT_OF_MEMORY, 0);
    }
    snprintf(side, len, "%s%s", a->out, CLI_PIECE_SIDECAR);
    snprintf(text, CLI_PIECE_TAG_MAX + 256, CLI_PIECE_MAGIC "window=%d,%d,%d,%d planes=%d channels=%d "
             "range=%s\n%s\n", v.x0, v.y0, v.w, v.h, planes, channels, range, v.tag);
    errno = 0;
    s = cli_write(side, (unsigned char *)text, strlen(text), HFVIS_OK); /* frees text */
    rc = s == HFVIS_OK ? 0 : cli_status(side, s, errno);
    free(side);
    return rc;
}

#define CLI_MOSAIC_HELP                                                                              \
    "usage: hfvis mosaic PIECE... -o OUT [--range LO:HI] [--overwrite] [--quiet]\n"                 \
    "Assemble the pieces of one tiled run (--max-distance R --window X0,Y0,W,H, each piece with\n"  \
    "its sidecar PIECE.tile) into the raster the whole run writes: OUT equals the whole run's\n"    \
    "output bit for bit (a GeoTIFF georeferenced as the whole run's). Refused, with nothing\n"     \
    "written, naming the problem: pieces of different inputs, CRS, cell sizes, R or other\n"       \
    "parameters, overlapping windows, and cells that no piece holds. OUT holds the whole raster\n" \
    "in memory (W x H x planes floats); beyond that, gdalbuildvrt over GeoTIFF pieces.\n"         \
    "  -o OUT            .pfm, .pgm (with the command's default range), .tif, .asc, .bil or .flt\n" \
    "  --range LO:HI     .pgm only: the values mapped to codes 1 and 65535\n"                     \
    "  --overwrite       allow OUT to be one of the pieces\n"

/* One piece's sidecar, as read back. */
typedef struct cli_piece {
    int x0, y0, w, h, planes, channels;
    char range[96];
    char tag[CLI_PIECE_TAG_MAX];
} cli_piece;

static int cli_piece_meta(const char *path, cli_piece *p)
{
    size_t n = strlen(path) + sizeof CLI_PIECE_SIDECAR, len = 0;
    char *side = (char *)malloc(n), *text = NULL, *line2, *line3, *end;
    int ok = 0;
    if (!side) return cli_status(path, HFVIS_ERR_OUT_OF_MEMORY, 0);
    snprintf(side, n, "%s%s", path, CLI_PIECE_SIDECAR);
    text = ex_rio_slurp(side, EX_RIO_MAX_HEADER, &len);
    if (!text) {
        cli_error(CLI_EXIT_ERROR, path, "no sidecar %s: not a piece of 'hfvis ... --window' (or moved "
                  "without it)", side);
        free(side);
        return CLI_EXIT_ERROR;
    }
    line2 = strchr(text, '\n');
    line3 = line2 ? strchr(line2 + 1, '\n') : NULL;
    if (!strncmp(text, CLI_PIECE_MAGIC, sizeof CLI_PIECE_MAGIC - 1) && line3) {
        *line3++ = '\0';
        end = strchr(line3, '\n');
        if (end) *end = '\0';
        ok = sscanf(line2 + 1, "window=%d,%d,%d,%d planes=%d channels=%d range=%95s", &p->x0, &p->y0,
                    &p->w, &p->h, &p->planes, &p->channels, p->range) == 7 &&
             strlen(line3) < sizeof p->tag && p->w > 0 && p->h > 0 && p->planes > 0 && p->channels > 0;
        if (ok) strcpy(p->tag, line3);
    }
    if (!ok) cli_error(CLI_EXIT_ERROR, side, "not a piece sidecar (damaged, or of another hfvis version)");
    free(text);
    free(side);
    return ok ? 0 : CLI_EXIT_ERROR;
}

/* The problem a differing tag key names. */
static const char *cli_piece_problem(const char *key)
{
    if (!strcmp(key, "crs")) return "different CRS";
    if (!strcmp(key, "cell")) return "different cell sizes";
    if (!strcmp(key, "max-distance")) return "different R (--max-distance)";
    if (!strcmp(key, "cmd")) return "different commands";
    if (!strcmp(key, "in") || !strcmp(key, "extent") || !strcmp(key, "gt") || !strcmp(key, "band"))
        return "different inputs";
    return "different parameters";
}

/* Read piece path (of sidecar m) into the mosaic out (W x H cells, planes stacked, channels
 * interleaved), checking its size and, for a raster, its CRS and cell size against ref's. */
static int cli_piece_read(const char *path, const cli_piece *m, int W, int H, float *out,
                          const ex_georef *ref, ex_georef *keep)
{
    const size_t C = (size_t)m->channels;
    int x, y, p, c;
    if (ex_rio_format_of(path)) {
        ex_rio_reader r;
        float *row;
        if (ex_rio_open(&r, path) != 0) return cli_error(CLI_EXIT_ERROR, path, "%s", r.err);
        if (r.width != m->w || r.height != m->h || r.bands != m->planes * m->channels) {
            cli_error(CLI_EXIT_ERROR, path, "%d x %d cells, %d bands: its sidecar says %d x %d, %d", r.width,
                      r.height, r.bands, m->w, m->h, m->planes * m->channels);
            ex_rio_close(&r);
            return CLI_EXIT_ERROR;
        }
        if (ref && (ref->crs != r.geo.crs || ref->epsg != r.geo.epsg)) {
            cli_error(CLI_EXIT_ERROR, path, "different CRS (EPSG:%d there, EPSG:%d here)", ref->epsg, r.geo.epsg);
            ex_rio_close(&r);
            return CLI_EXIT_ERROR;
        }
        if (ref && (ref->has_transform != r.geo.has_transform || ref->gt[1] != r.geo.gt[1] ||
                    ref->gt[5] != r.geo.gt[5])) {
            cli_error(CLI_EXIT_ERROR, path, "different cell sizes (%.10g x %.10g there, %.10g x %.10g here)",
                      ref->gt[1], ref->gt[5], r.geo.gt[1], r.geo.gt[5]);
            ex_rio_close(&r);
            return CLI_EXIT_ERROR;
        }
        row = cli_alloc((size_t)m->w, (size_t)m->h, 1); /* one band: each strip or tile decoded once */
        if (!row) {
            ex_rio_close(&r);
            return cli_status(path, HFVIS_ERR_OUT_OF_MEMORY, 0);
        }
        r.nodata_to_nan = 1;
        for (p = 0; p < m->planes; p++)
            for (c = 0; c < m->channels; c++) {
                if (ex_rio_read(&r, m->channels > 1 ? c : p, 0, 0, m->w, m->h, row, m->w) != 0) {
                    cli_error(CLI_EXIT_ERROR, path, "%s", r.err);
                    free(row);
                    ex_rio_close(&r);
                    return CLI_EXIT_ERROR;
                }
                for (y = 0; y < m->h; y++) {
                    float *dst = out + (((size_t)p * (size_t)H + (size_t)(m->y0 + y)) * (size_t)W + (size_t)m->x0) * C + (size_t)c;
                    const float *src = row + (size_t)y * (size_t)m->w;
                    for (x = 0; x < m->w; x++) dst[(size_t)x * C] = src[x];
                }
            }
        free(row);
        if (keep) { /* the georeference of the piece at (0, 0) is the whole raster's */
            ex_georef_free(keep);
            *keep = r.geo;
            memset(&r.geo, 0, sizeof r.geo);
        }
        ex_rio_close(&r);
        return 0;
    } else {
        hfvis_image_info info;
        float *px = NULL;
        hfvis_status s;
        errno = 0;
        s = hfvis_image_load(path, NULL, &px, &info);
        if (s != HFVIS_OK) return cli_status(path, s, errno);
        if (info.format != HFVIS_FORMAT_PFM || info.width != m->w || info.height != m->h * m->planes ||
            info.channels != m->channels) {
            hfvis_free(NULL, px);
            return cli_error(CLI_EXIT_ERROR, path, "%d x %d x %d values: its sidecar says a PFM of %d x %d x %d",
                             info.width, info.height, info.channels, m->w, m->h * m->planes, m->channels);
        }
        for (p = 0; p < m->planes; p++)
            for (y = 0; y < m->h; y++)
                memcpy(out + (((size_t)p * (size_t)H + (size_t)(m->y0 + y)) * (size_t)W + (size_t)m->x0) * C,
                       px + ((size_t)p * (size_t)m->h + (size_t)y) * (size_t)m->w * C,
                       (size_t)m->w * C * sizeof(float));
        hfvis_free(NULL, px);
        return 0;
    }
}

/* `hfvis mosaic PIECE... -o OUT`: the sidecars first (one run: same tag; the windows tile the
 * extent: inside it, no two overlapping, their areas summing to it), then the pieces into one
 * raster, written as the whole run writes it (cli_save with the whole raster's georeference). */
static int cli_mosaic(int argc, char **argv)
{
    enum { MAX_PIECES = 65536 };
    static const char *names[MAX_PIECES];
    cli_piece *meta = NULL;
    cli_args a;
    char key[64], other[CLI_PIECE_TAG_MAX], cmdname[32], ext[64];
    int n = 0, i, j, rc = 0, W = 0, H = 0, planes, channels, origin = -1, cmd;
    double area = 0.0, lo = 0.0, hi = 1.0;
    float *out = NULL;
    ex_georef ref;

    memset(&a, 0, sizeof a);
    memset(&ref, 0, sizeof ref);
    for (i = 2; i < argc; i++) {
        const char *arg = argv[i];
        if (!strcmp(arg, "-h") || !strcmp(arg, "--help")) {
            printf("%s", CLI_MOSAIC_HELP);
            return 0;
        }
        if (!strcmp(arg, "-o") || !strncmp(arg, "-o=", 3) || !strcmp(arg, "--range") || !strncmp(arg, "--range=", 8)) {
            int is_o = arg[1] == 'o';
            const char *eq = strchr(arg, '='), *v = eq ? eq + 1 : (i + 1 < argc ? argv[++i] : NULL);
            if (!v) return cli_error(CLI_EXIT_USAGE, is_o ? "-o" : "--range", "missing value");
            if (!is_o) {
                if (cli_set(&a, "--range", v)) return CLI_EXIT_USAGE;
                continue;
            }
            if (!cli_ends_with(v, ".pfm") && !cli_ends_with(v, ".pgm") && !ex_rio_format_of(v))
                return cli_error(CLI_EXIT_USAGE, v, "unknown output type (use a .pfm, .pgm, .tif, .asc, .bil or .flt name)");
            a.out = v;
            a.out_pgm = cli_ends_with(v, ".pgm");
            a.out_raster = ex_rio_format_of(v) != 0;
            continue;
        }
        if (!strcmp(arg, "--quiet")) { a.quiet = 1; continue; }
        if (!strcmp(arg, "--overwrite")) { a.overwrite = 1; continue; }
        if (arg[0] == '-' && arg[1] != '\0')
            return cli_error(CLI_EXIT_USAGE, arg, "unknown option (see 'hfvis mosaic --help')");
        if (n == MAX_PIECES) return cli_error(CLI_EXIT_USAGE, arg, "more than %d pieces", MAX_PIECES);
        names[n++] = arg;
    }
    if (n == 0) return cli_error(CLI_EXIT_USAGE, "mosaic", "missing PIECE files");
    if (!a.out) return cli_error(CLI_EXIT_USAGE, "mosaic", "missing -o OUT");
    if (a.has_range && !a.out_pgm) return cli_error(CLI_EXIT_USAGE, "--range", "applies only to .pgm output");
    if ((rc = cli_refuse_input(a.overwrite, a.out, names, n)) != 0) return rc;
    meta = (cli_piece *)malloc((size_t)n * sizeof *meta);
    if (!meta) return cli_status("mosaic", HFVIS_ERR_OUT_OF_MEMORY, 0);

    /* one run */
    for (i = 0; i < n; i++) {
        if ((rc = cli_piece_meta(names[i], &meta[i])) != 0) goto done;
        if (i == 0) continue;
        cli_tag_first_difference(meta[i].tag, meta[0].tag, key, sizeof key);
        if (key[0]) {
            char *eq = strchr(key, '=');
            if (eq) *eq = '\0';
            if (!cli_tag_value(meta[0].tag, key, other, sizeof other)) strcpy(other, "(none)");
            rc = cli_error(CLI_EXIT_ERROR, names[i], "not the same run as %s: %s (%s=%s there, %s here)",
                           names[0], cli_piece_problem(key), key, other, eq ? eq + 1 : "");
            goto done;
        }
        if (meta[i].planes != meta[0].planes || meta[i].channels != meta[0].channels) {
            rc = cli_error(CLI_EXIT_ERROR, names[i], "not the same run as %s: %d planes of %d channels there, "
                           "%d of %d here", names[0], meta[0].planes, meta[0].channels, meta[i].planes,
                           meta[i].channels);
            goto done;
        }
    }
    if (!cli_tag_value(meta[0].tag, "extent", ext, sizeof ext) || sscanf(ext, "%dx%d", &W, &H) != 2 ||
        W < 1 || H < 1 || !cli_tag_value(meta[0].tag, "cmd", cmdname, sizeof cmdname)) {
        rc = cli_error(CLI_EXIT_ERROR, names[0], "its sidecar names no extent or command");
        goto done;
    }
    for (cmd = 0; cmd < CMD_COUNT && strcmp(cmdname, cli_cmd_names[cmd]); cmd++) {}
    planes = meta[0].planes, channels = meta[0].channels;
    /* the windows tile the extent: inside it, pairwise disjoint, areas summing to it */
    for (i = 0; i < n; i++) {
        const cli_piece *p = &meta[i];
        if (p->x0 < 0 || p->y0 < 0 || p->w > W - p->x0 || p->h > H - p->y0) {
            rc = cli_error(CLI_EXIT_ERROR, names[i], "window %d,%d,%d,%d lies outside the extent %d x %d",
                           p->x0, p->y0, p->w, p->h, W, H);
            goto done;
        }
        if (p->x0 == 0 && p->y0 == 0) origin = i;
        area += (double)p->w * (double)p->h;
        for (j = 0; j < i; j++) {
            const cli_piece *q = &meta[j];
            if (p->x0 < q->x0 + q->w && q->x0 < p->x0 + p->w && p->y0 < q->y0 + q->h && q->y0 < p->y0 + p->h) {
                rc = cli_error(CLI_EXIT_ERROR, names[i], "overlaps %s: windows %d,%d,%d,%d and %d,%d,%d,%d "
                               "share cells", names[j], p->x0, p->y0, p->w, p->h, q->x0, q->y0, q->w, q->h);
                goto done;
            }
        }
    }
    if (area < (double)W * (double)H) {
        rc = cli_error(CLI_EXIT_ERROR, "mosaic", "missing pieces: %.0f of the %d x %d cells are in no "
                       "piece%s", (double)W * (double)H - area, W, H,
                       origin < 0 ? " (none holds cell 0,0)" : "");
        goto done;
    }
    if (planes > 1 && (long long)planes * H > HFVIS_IMAGE_MAX_DIM) {
        rc = cli_error(CLI_EXIT_ERROR, "mosaic", "%s: %d planes of %d rows", hfvis_status_string(HFVIS_ERR_LIMIT),
                       planes, H);
        goto done;
    }
    out = cli_alloc((size_t)W * (size_t)H, (size_t)planes, (size_t)channels);
    if (!out) { rc = cli_status("mosaic", HFVIS_ERR_OUT_OF_MEMORY, 0); goto done; }
    /* the piece at (0, 0) first: its georeference is the whole raster's and the reference of the others */
    if ((rc = cli_piece_read(names[origin], &meta[origin], W, H, out, NULL, &ref)) != 0) goto done;
    for (i = 0; i < n; i++)
        if (i != origin && (rc = cli_piece_read(names[i], &meta[i], W, H, out,
                                                ex_rio_format_of(names[origin]) ? &ref : NULL, NULL)) != 0)
            goto done;
    if (!ref.has_transform && cli_tag_value(meta[0].tag, "gt", other, sizeof other) && strcmp(other, "none")) {
        /* PFM pieces: the geotransform from the sidecar (their CRS is not kept: use raster pieces) */
        char *q = other;
        for (i = 0; i < 6; i++) {
            char *comma = strchr(q, ',');
            if (comma) *comma = '\0';
            if (!cli_parse_real(q, &ref.gt[i])) break;
            q = comma ? comma + 1 : q + strlen(q);
        }
        ref.has_transform = i == 6;
    }
    /* NoData as the whole run had it: the input's (the pieces may have declared NaN or moved it) */
    ref.has_nodata = 0;
    if (cli_tag_value(meta[0].tag, "nodata", other, sizeof other) && strcmp(other, "none"))
        ex_georef_set_nodata(&ref, other, strlen(other));
    if (!ref.has_nodata && cli_tag_value(meta[0].tag, "set-nodata", other, sizeof other) && strcmp(other, "none") &&
        cli_parse_real(other, &ref.nodata)) {
        ref.has_nodata = 1;
        snprintf(ref.nodata_text, sizeof ref.nodata_text, "%.9g", ref.nodata);
    }
    ex_georef_free(&cli_geo);
    cli_geo = ref;
    memset(&ref, 0, sizeof ref);
    cli_in_height = H;
    a.cmd = cmd < CMD_COUNT ? cmd : CMD_SKYVIEW;
    a.fraction = cli_tag_value(meta[0].tag, "fraction", other, sizeof other) && !strcmp(other, "1");
    if (!strcmp(meta[0].range, "top")) {
        hi = cli_top(out, (size_t)W * (size_t)H * (size_t)planes * (size_t)channels, 1.0);
    } else {
        char *colon = strchr(meta[0].range, ':');
        if (colon) *colon = '\0';
        if (!colon || !cli_parse_real(meta[0].range, &lo) || !cli_parse_real(colon + 1, &hi)) lo = 0.0, hi = 1.0;
    }
    rc = cli_save(&a, out, W, H * planes, channels, lo, hi);
done:
    ex_georef_free(&ref);
    free(out);
    free(meta);
    return rc;
}

/* `hfvis info RASTER`: the header of a raster (any the tool reads), one "key value" per line, for
 * scripts (examples/tiles.sh): only the header is read. */
static int cli_info(int argc, char **argv)
{
    ex_rio_reader r;
    double cell = 0.0;
    char why[256];
    static const char *const crs[4] = { "unknown", "projected", "geographic", "geocentric" };
    static const char *const fmt[5] = { "", "tiff", "asc", "ehdr", "netpbm" };
    if (argc != 3 || argv[2][0] == '-') {
        if (argc == 3 && (!strcmp(argv[2], "-h") || !strcmp(argv[2], "--help"))) {
            printf("usage: hfvis info RASTER\nPrints width, height, bands, cell, origin (map X and Y of "
                   "the upper-left corner), crs, nodata and format\nof RASTER (.tif .asc .bil .flt .pfm, "
                   "binary .pgm), one 'key value' per line; cell, origin\nand nodata are 'none' when the "
                   "file has none. Only the header is read.\n");
            return 0;
        }
        return cli_error(CLI_EXIT_USAGE, "info", "usage: hfvis info RASTER");
    }
    if ((ex_rio_format_of(argv[2]) ? ex_rio_open(&r, argv[2]) : ex_rio_open_netpbm(&r, argv[2])) != 0)
        return cli_error(CLI_EXIT_ERROR, argv[2], "%s", r.err);
    printf("width %d\nheight %d\nbands %d\n", r.width, r.height, r.bands);
    if (r.geo.has_transform && ex_georef_cell(&r.geo, &cell, why) == 0) printf("cell %.17g\n", cell);
    else printf("cell none\n");
    if (r.geo.has_transform) printf("origin %.17g %.17g\n", r.geo.gt[0], r.geo.gt[3]); /* upper-left corner */
    else printf("origin none\n");
    printf("crs %s", crs[r.geo.crs >= 0 && r.geo.crs < 4 ? r.geo.crs : 0]);
    if (r.geo.epsg) printf(" EPSG:%d", r.geo.epsg);
    printf("\nnodata %s\nformat %s\n", r.geo.has_nodata ? r.geo.nodata_text : "none",
           fmt[r.format >= 1 && r.format <= 4 ? r.format : 0]);
    ex_rio_close(&r);
    return fflush(stdout) == 0 && !ferror(stdout) ? 0 : cli_error(CLI_EXIT_ERROR, "info", "cannot write to stdout");
}

static int cli_run(const cli_args *a)
{
    const char *cmd = cli_cmd_names[a->cmd];
    cli_progress_state prog;
    float *z = NULL, *out = NULL, *env_px = NULL;
    int w = 0, h = 0, rc, channels = 1, planes = 1;
    double lo = 0.0, hi = 1.0;
    hfvis_grid grid;
    hfvis_sweep_options opts = hfvis_sweep_options_default();
    hfvis_env env;
    hfvis_status s = HFVIS_OK;

    if (a->cmd == CMD_VOXELIZE || a->cmd == CMD_VOLGI || a->cmd == CMD_VISFIELD || a->cmd == CMD_MESHAO)
        if ((rc = cli_check_cost(a, 0, 0, 1)) != 0) return rc;
    if (a->cmd == CMD_VOXELIZE) return cli_run_voxelize(a);
    if (a->cmd == CMD_SSAO) return cli_run_ssao(a);
    if (a->cmd == CMD_VOLGI) return cli_run_volgi(a);
    if (a->cmd == CMD_VISFIELD) return cli_run_visfield(a);
    if (a->cmd == CMD_MESHAO) return cli_run_meshao(a);
    memset(&env, 0, sizeof env);
    cli_win.active = a->has_window;
    if ((rc = cli_load_heights(a, &z, &w, &h, &grid.cell_size)) != 0) return rc;
    grid.z = z; grid.width = w; grid.height = h; grid.stride = w;
    opts.border = (hfvis_border)a->border;
    opts.border_cells = a->border_cells;
    opts.azimuth0_rad = a->compass ? a->azimuth0 - CLI_PI / 2.0 : a->azimuth0;
    if (a->exact && a->cmd != CMD_VIEWSHED) opts.rays = HFVIS_RAYS_EXACT;
    if (a->cmd != CMD_VIEWSHED) opts.max_distance = a->max_distance; /* viewshed: its own range */
    if (cli_win.active && a->cmd == CMD_OPENNESS) {
        /* openness marches --radius per receiver: the halo holds every cell a window receiver
         * reaches, and the window + halo grid's own border is the raster's wherever a march can
         * meet it, so it runs as a plain grid (the library refuses a window for it) */
        cli_piece_tag(a, &grid, &opts);
    } else if (cli_win.active) { /* the grid is window + halo of the raster; compute the window */
        opts.origin_x = cli_win.gx0, opts.origin_y = cli_win.gy0;
        opts.extent_width = cli_win.ext_w, opts.extent_height = cli_win.ext_h;
        if (a->cmd != CMD_INDIRECT) { /* indirect's bounces need every point of the grid */
            opts.receiver_x = cli_win.x0 - cli_win.gx0, opts.receiver_y = cli_win.y0 - cli_win.gy0;
            opts.receiver_width = cli_win.w, opts.receiver_height = cli_win.h;
        }
        cli_piece_tag(a, &grid, &opts);
    } else if (a->max_distance > 0.0 && a->cmd < CMD_COUNT && (CLI_ONLY(a->cmd) & CLI_SWEEP)) {
        cli_win.halo = cli_halo(a, grid.cell_size); /* for the window size a refusal suggests */
    }
    prog.label = cmd; prog.base = 0; prog.total = 0;
    cli_run_cells = (double)w * (double)h;
    cli_run_directions = a->cmd == CMD_NORMALS || a->cmd == CMD_VIEWSHED ? 0
                         : a->cmd == CMD_SHADOW ? 1 : a->dirs;
    if (a->progress_lines && !a->quiet) {
        opts.progress = cli_progress_line;
        opts.progress_user = &prog;
    } else if (!a->quiet && cli_stderr_is_terminal()) {
        opts.progress = cli_progress;
        opts.progress_user = &prog;
    }
    if (!cli_win.active && (rc = cli_check_cost(a, w, h, cli_out_channels(a))) != 0) goto done;
    if (a->has_dir_range) {
        if (a->cmd == CMD_LIGHT && (rc = cli_load_env(a->env, &env_px, &env)) != 0) goto done;
        rc = cli_run_partial(a, &grid, &opts, &prog, &env);
        goto done;
    }
    if (a->cmd == CMD_INDIRECT) { rc = cli_run_indirect(a, &grid, &opts, &prog); goto done; }
    if (a->cmd == CMD_VISIBILITY) { rc = cli_run_visibility(a, &grid, &opts, &prog); goto done; }
    if (a->cmd == CMD_GI) { rc = cli_run_gi(a, &grid, &opts, &prog); goto done; }
    if (a->cmd == CMD_VIEWSHED || a->cmd == CMD_HILLSHADE || a->cmd == CMD_OPENNESS ||
        (a->cmd == CMD_SKYVIEW && a->svf != 0)) {
        rc = cli_run_gis(a, &grid, &opts, &prog);
        goto done;
    }
    if (a->cmd == CMD_HORIZON) {
        size_t values = (size_t)w * (size_t)h; /* <= 2^28, so the product below cannot overflow */
        planes = a->dirs;
        if ((size_t)planes > CLI_HORIZON_MAX_VALUES / values ||
            (long long)planes * h > HFVIS_IMAGE_MAX_DIM) {
            rc = cli_error(CLI_EXIT_ERROR, cmd, "%s: %d planes of %d x %d exceed the limit of "
                           "2^28 values and %d rows; use fewer --dirs, or skyview/sky/light",
                           hfvis_status_string(HFVIS_ERR_LIMIT), planes, w, h, HFVIS_IMAGE_MAX_DIM);
            goto done;
        }
        lo = -CLI_PI / 2.0; hi = CLI_PI / 2.0;
    } else if (a->cmd == CMD_NORMALS) {
        channels = 3; lo = -1.0;
    } else if (a->cmd == CMD_LIGHT) {
        if ((rc = cli_load_env(a->env, &env_px, &env)) != 0) goto done;
        channels = env.channels;
    }
    out = cli_alloc((size_t)w * (size_t)h, (size_t)planes, (size_t)channels);
    if (!out) { rc = cli_status(cmd, HFVIS_ERR_OUT_OF_MEMORY, 0); goto done; }

    switch (a->cmd) {
    case CMD_HORIZON:
        s = hfvis_horizon_map(&grid, a->dirs, &opts, out);
        if (s == HFVIS_OK && a->degrees) {
            size_t i, n = (size_t)w * (size_t)h * (size_t)planes;
            for (i = 0; i < n; i++) out[i] = (float)((double)out[i] * (180.0 / CLI_PI));
            lo = -90.0; hi = 90.0;
        }
        break;
    case CMD_SKYVIEW:
        s = hfvis_sky_view_factor(&grid, a->dirs, &opts, out, w);
        break;
    case CMD_SKY:
        s = hfvis_sky_light(&grid, a->dirs, (float)a->sky, (float)a->albedo, &opts, out, w);
        if (a->sky * a->albedo <= CLI_FLT_MAX && (float)(a->sky * a->albedo) > 0.0f)
            hi = a->sky * a->albedo;
        break;
    case CMD_SHADOW: {
        double bearing_or_psi = a->math ? a->sun_azimuth : a->sun_azimuth - 90.0;
        s = hfvis_sun_visibility(&grid, bearing_or_psi * (CLI_PI / 180.0),
                                 a->sun_elevation * (CLI_PI / 180.0),
                                 a->sun_radius * (CLI_PI / 180.0), &opts, out, w);
        break;
    }
    case CMD_LIGHT: {
        hfvis_env_options eopts = hfvis_env_options_default();
        eopts.method = (hfvis_env_method)a->method;
        s = hfvis_env_light(&grid, a->dirs, &env, (float)a->albedo, &opts, &eopts, out, w);
        if (s == HFVIS_OK) hi = cli_top(out, (size_t)w * (size_t)h * (size_t)channels, 1.0);
        break;
    }
    default: /* CMD_NORMALS */
        s = hfvis_normals_compute(&grid, out);
        break;
    }
    if (s != HFVIS_OK) { rc = cli_status(cmd, s, 0); goto done; }
    if ((a->cmd == CMD_SKY || a->cmd == CMD_LIGHT) &&
        (rc = cli_check_radiance(cmd, &grid, out, channels)) != 0)
        goto done;
    if (a->cmd == CMD_HORIZON) { rc = cli_horizon_finish(a, out, w, h, lo, hi); goto done; }
    rc = cli_save(a, out, w, h * planes, channels, lo, hi);
done:
    if (cli_bar_open) { fputc('\n', stderr); cli_bar_open = 0; } /* a bar that fell short */
    free(out);
    hfvis_free(NULL, env_px);
    hfvis_free(NULL, z);
    return rc;
}

static const char cli_azimuths_help[] =
    "usage: hfvis azimuths --dirs K [--exact] [--convention compass|grass|grid] [--azimuth0 A]\n"
    "         [--radians]\n"
    "Prints the K azimuths a run with these options uses, one per line, in output-plane order\n"
    "(plane k of 'hfvis horizon'), in degrees of the convention: compass bearings (clockwise\n"
    "from north, the default; --compass says the same), GRASS's counter-clockwise from east, or\n"
    "grid (from east toward south, the library's psi). --azimuth0 is direction 0 in that\n"
    "convention, degrees unless --radians. Without --exact: direction k is azimuth0 + 360k/K\n"
    "(GRASS: counter-clockwise); with --exact: rational directions (a, b), the nearest with\n"
    "max(|a|, |b|) <= max(5, ceil(K/4)) (64 for K = 1), and for 32 < K <= 360 the cheapest\n"
    "(smallest |a| + |b|) within 0.25 degrees.\n";

/* hfvis azimuths: the directions of a run (hfvis_sweep_azimuths), one per line. */
static int cli_azimuths(int argc, char **argv)
{
    hfvis_sweep_options o = hfvis_sweep_options_default();
    double az0 = 0.0, *az;
    int i, K = 16, conv = CONV_COMPASS, radians = 0, has_dirs = 0, k, c, rc;
    for (i = 2; i < argc; i++) {
        const char *f = argv[i], *v = NULL, *eq = strchr(f, '=');
        char name[32];
        size_t n = eq ? (size_t)(eq - f) : strlen(f);
        if (!strcmp(f, "-h") || !strcmp(f, "--help")) {
            printf("%s", cli_azimuths_help);
            return 0;
        }
        if (n >= sizeof name) n = sizeof name - 1;
        memcpy(name, f, n);
        name[n] = '\0';
        if (!strcmp(name, "--exact") && !eq) { o.rays = HFVIS_RAYS_EXACT; continue; }
        if (!strcmp(name, "--compass") && !eq) { conv = CONV_COMPASS; continue; }
        if (!strcmp(name, "--radians") && !eq) { radians = 1; continue; }
        if (strcmp(name, "--dirs") && strcmp(name, "--azimuth0") && strcmp(name, "--convention"))
            return cli_error(CLI_EXIT_USAGE, f, "unknown option (see 'hfvis azimuths --help')");
        if (eq) v = eq + 1;
        else if (i + 1 < argc) v = argv[++i];
        else return cli_error(CLI_EXIT_USAGE, name, "needs a value");
        if (!strcmp(name, "--dirs")) {
            if ((rc = cli_int(name, v, 1, CLI_MAX_DIRS, "an integer 1..65536", &K)) != 0) return rc;
            has_dirs = 1;
        } else if (!strcmp(name, "--convention")) {
            for (c = 0; c < 3 && strcmp(v, cli_conv_names[c]); c++) {}
            if (c == 3) return cli_error(CLI_EXIT_USAGE, name, "expected compass, grass or grid, got '%s'", v);
            conv = c;
        } else if (!cli_parse_real(v, &az0)) {
            return cli_error(CLI_EXIT_USAGE, name, "expected a finite angle, got '%s'", v);
        }
    }
    if (!has_dirs) return cli_error(CLI_EXIT_USAGE, "azimuths", "needs --dirs K");
    o.azimuth0_rad = cli_psi(conv, radians ? az0 * (180.0 / CLI_PI) : az0);
    az = (double *)malloc((size_t)K * sizeof(double));
    if (!az) return cli_status("azimuths", HFVIS_ERR_OUT_OF_MEMORY, 0);
    if (hfvis_sweep_azimuths(K, &o, az, NULL) != HFVIS_OK) {
        free(az);
        return cli_error(CLI_EXIT_USAGE, "--azimuth0", "not a usable azimuth");
    }
    for (k = 0; k < K; k++) /* GRASS's direction k is the library's (K - k) mod K */
        printf("%.17g\n", cli_from_psi(conv, az[conv == CONV_GRASS ? (K - k) % K : k]));
    free(az);
    return 0;
}

int main(int argc, char **argv)
{
    cli_args a;
    int rc;
    cli_signals();
    ex_atomic_on_temp = cli_on_temp; /* the raster writers' temporary files too */
    if (argc >= 2 && !strcmp(argv[1], "sum")) return cli_sum(argc, argv);
    if (argc >= 2 && !strcmp(argv[1], "azimuths")) return cli_azimuths(argc, argv);
    if (argc >= 2 && !strcmp(argv[1], "mosaic")) return cli_mosaic(argc, argv);
    if (argc >= 2 && !strcmp(argv[1], "info")) return cli_info(argc, argv);
    cli_t0 = cli_now();
    rc = cli_parse(argc, argv, &a);
    if (rc != CLI_RUN) return rc;
    if ((rc = cli_gis_finish(&a)) != 0) return rc;
    if ((rc = cli_refuse_inputs(&a, a.out)) != 0) return rc;
    rc = cli_run(&a);
    ex_georef_free(&cli_geo);
    if (rc == 0 && !a.quiet && a.out && (a.progress_lines || cli_now() - cli_t0 >= CLI_SUMMARY_SECONDS)) {
        fprintf(stderr, "hfvis %s: done in %.1f s", cli_cmd_names[a.cmd], cli_now() - cli_t0);
        if (cli_run_cells > 0.0) fprintf(stderr, ": %.0f cells", cli_run_cells);
        if (cli_run_directions > 0) fprintf(stderr, ", %d direction%s", cli_run_directions,
                                            cli_run_directions == 1 ? "" : "s");
        fprintf(stderr, " -> %s\n", a.out);
    }
    return rc;
}
