/* help.c - the help texts of the `hfvis` tool: each command's --help (CLI_<COMMAND>_HELP, named
 * by its row of cli_commands in main.c), the usage line and the text after the options. The
 * command list and the shared options are printed from the tables (cli_help, flags.c).
 * Owns: text only (no code). May call: nothing. */

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
    "0:the largest output value.\n"

#define CLI_SOLAR_HELP                                                                              \
    "usage: hfvis solar DEM --day YYYY-MM-DD | --start DATE --end DATE [--step 15m] [--time HH:MM]\n" \
    "         [--linke L | --linke-monthly L1,...,L12 | --linke-map MAP] [--albedo A |\n"           \
    "         --albedo-map MAP] -o GLOBAL [--beam B] [--diffuse D] [--reflected R]\n"               \
    "         [--sun-hours H] [--latitude DEG --longitude DEG] [--utc-offset H | --solar-time]\n"   \
    "         [--bands day|month] [--normals central|horn] [--sun-radius DEG] [--dirs K]\n"         \
    "         [--max-distance R [--window X0,Y0,W,H]] [--height-range LO,HI]\n"                     \
    "         [--horizons exact|near-far|lattice]\n"                                                \
    "Clear-sky solar irradiation (Wh/m^2) of a day or a date range, or irradiance (W/m^2) at\n"     \
    "--time, on every cell: r.sun's ESRA atmosphere (Suri & Hofierka 2004), the sun from NREL's\n"  \
    "SPA (Reda & Andreas 2004/2008), the beam shaded by exact horizons (docs/solar.md).\n"          \
    "  --day DATE        one day, YYYY-MM-DD (local civil day; --time HH:MM: that instant); years\n" \
    "                    -2000..6000 (SPA's; -YYYY before 0), Julian calendar before 1582-10-15\n"  \
    "  --start, --end    a date range, both days included (not across 1582-10-04/15); --start\n"    \
    "                    needs --end, --day takes none\n"                                           \
    "  --step S          time step with its unit, m or h: 15m (default), 0.5h, 1h; (0, 24h]\n"      \
    "  --linke L         Linke turbidity, (0, 10] (default 3); or --linke-monthly: 12 values\n"     \
    "                    from January; or --linke-map: per cell, a map of the DEM's size: GeoTIFF,\n" \
    "                    ASC, EHdr (.bil/.flt), PFM or PGM (values / maxval), one band\n"           \
    "  --albedo A        ground albedo, [0, 1] (default 0.2); or --albedo-map: per cell, a map\n"   \
    "  -o GLOBAL         global irradiation; --beam, --diffuse, --reflected, --sun-hours write\n"   \
    "                    the parts and the hours of direct sun (.pfm, .tif, .asc, .bil, .flt);\n"   \
    "                    none may be IN or a map (unless --overwrite), no two one file\n"           \
    "  --latitude, --longitude  the site in degrees (east positive); default: each cell's, by\n"    \
    "                    the inverse projection of a Transverse Mercator CRS (UTM by EPSG code,\n"  \
    "                    or its parameters in GeoTIFF keys or a WKT)\n"                            \
    "  --utc-offset H    dates and --time are UTC + H (default 0); --solar-time: local solar time\n" \
    "                    and r.sun's solar geometry and steps (r.sun's convention)\n"               \
    "  --bands day|month one band per day or per calendar month, stacked like horizon planes\n"     \
    "                    (--max-memory counts 32 bytes of sums and 4 per output a cell and band)\n" \
    "  --normals N       central (default): central differences; horn: Horn's 3x3 stencil, as\n"    \
    "                    r.slope.aspect and gdaldem (what r.sun reads)\n"                           \
    "  --sun-radius DEG  shade the sun's disc (default: its centre); --dirs K: directions of the\n" \
    "                    horizon map, 1..4096 (default 64; 16: a day 5x faster, within 0.2 %)\n"    \
    "  --horizons H      exact (default), near-far (exact within 8 cells: about 0.6x the map's\n"   \
    "                    time) or lattice ([P1]: about 4x faster, misses one-cell walls' shadow)\n" \
    "  --max-distance R  the horizons' search radius: --window X0,Y0,W,H pieces (each output\n"     \
    "                    its own) join with 'hfvis mosaic' into the whole run bit for bit\n"        \
    "                    (docs/tiles.md; IN's height range is read by strips first)\n"              \
    "  --height-range LO,HI  that height range given instead (after --zscale): every height\n"      \
    "                    read must lie in it, and the pieces of one run must share it\n"            \
    "Polar night gives 0. With --progress the site's latitude and longitude go to stderr.\n"        \
    "Refused before the run: an output that is an input or another output's file, an .asc\n"        \
    "output of more than one band, an output whose directory does not exist or cannot be\n"         \
    "written. The outputs are written after the run, -o GLOBAL last: when a write fails, OUT\n"     \
    "is then left untouched (the extra outputs written before it stay replaced).\n"

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
    "         [--blend N] [--no-shadows] [--lattice] [options]\n"                                  \
    "Shaded relief with cast shadows: H = (1/N) sum_j max(n . l_j, 0) V_j, n the grid normal, l_j\n" \
    "the direction of sun j and V_j its visibility from exact rays toward it (0 in shadow,\n" \
    "1 lit; with --sun-radius the visible fraction of the sun disc: soft shadows). In [0, 1];\n"   \
    "without shadows it is the classic hillshade cos(zenith) cos(slope) + sin(zenith) sin(slope)\n" \
    "cos(azimuth - aspect) (gdaldem hillshade / 255). NaN at holes. Default PGM range 0:1.\n"     \
    "  --sun-azimuth A   azimuth of the sun in the --convention (default 315: north-west)\n"       \
    "  --sun-elevation E elevation of the sun, -90..90 (default 45)\n"                            \
    "  --sun-radius R    angular radius of the sun disc, 0..90 (default 0; the real sun 0.27)\n"  \
    "  --blend N         multi-directional: N suns at A + 360 j/N, averaged (default 1)\n"         \
    "  --no-shadows      V_j = 1: the local hillshade only (not with --sun-radius, --lattice,\n"  \
    "                    --exact-near, nor --max-distance unless a --window needs its halo)\n"   \
    "  --lattice         shadows from the [P1] lattice sweep instead of exact rays (faster; misses\n" \
    "                    shadow cells next to walls and cliffs; --exact names the default)\n"

#define CLI_OPENNESS_HELP                                                                            \
    "usage: hfvis openness IN -o OUT [--radius R] [--negative | --both] [--dirs K] [--degrees]\n" \
    "         [options]\n"                                                                          \
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
    "  --both            positive and negative openness in one run (one march serves both):\n"    \
    "                    OUT holds two planes (bands), positive then negative\n"                   \
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
    "by one ulp. Refused, with nothing written: parts of different commands, inputs, grids,\n"    \
    "georeferences or parameters, parts of an older hfvis (no georeference), overlapping ranges,\n" \
    "and directions that no part holds.\n"                                                         \
    "  -o OUT            *.pfm or *.pgm, as for the command that made the parts, or a raster\n"    \
    "                    *.tif, *.asc, *.bil/*.flt with the input's georeference, NoData and\n"    \
    "                    CRS (.prj), which the parts carry; a horizon GeoTIFF gets the single\n"  \
    "                    run's band labels, rebuilt from the parts' tag\n"                         \
    "  --range LO:HI     .pgm only: the values mapped to codes 1 and 65535\n"                 \
    "  --overwrite       allow OUT to be one of the parts\n"

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

static const char cli_usage[] =
    "usage: hfvis COMMAND IN [options] -o OUT\n"
    "       hfvis COMMAND --help\n"
    "\n"
    "Visibility and light on height fields with the line-sweep horizon algorithm of\n"
    "Timonen & Westerholm 2010. IN is a height field: PGM (P2/P5, 8 or 16 bit, raw values),\n"
    "grey PFM (Pf), GeoTIFF (.tif), ESRI ASCII grid (.asc) or EHdr raw grid (.bil/.flt).\n"
    "Row 0 is the north edge, x (columns) runs east, y (rows) south.\n"
    "\n"
    "commands:\n";

/* After the shared options in every help. */
static const char cli_help_tail[] =
    "  -h, --help        this help; 'hfvis COMMAND --help' describes one command\n"
    "  --list-commands   the commands, one per line; --list-flags [COMMAND]: the flags (of COMMAND)\n"
    "\n"
    "Options take their value as the next argument or as --option=value; an option given twice\n"
    "takes its last value (as most Unix tools; volgi's --light adds one light each time).\n"
    "A flag that a command does not use is refused by name (exit 2).\n"
    "OUT is written to a temporary file beside it and renamed onto it: a symbolic link named\n"
    "OUT is replaced by the file (write to the link's target to keep the link); an interrupt\n"
    "(SIGINT, SIGTERM, SIGHUP) removes the temporary file; past a file-size limit (ulimit -f)\n"
    "the write fails as on a full disk. Once OUT is replaced, OUT.aux.xml (the statistics GDAL\n"
    "and QGIS keep beside a raster) is removed, as GDAL does when it recreates a file.\n"
    "Exit status: 0 = OUT is complete, 1 = error, 2 = usage error; an error is one line\n"
    "\"hfvis: <what>: <why>\" on stderr, and OUT is then left untouched.\n";

#define CLI_HORIZON_HELP \
    "usage: hfvis horizon IN -o OUT [options]\n" \
    "The horizon elevation angle alpha in [-pi/2, pi/2] toward each direction psi_k: the largest\n" \
    "elevation under which the sample sees terrain that way; -pi/2 where it sees none (open\n" \
    "border). OUT holds the K planes stacked top to bottom: plane k is rows k*H .. k*H+H-1 of a\n" \
    "W x (K*H) image. K*W*H may not exceed 2^28 values (1 GiB) and K*H not 1048576 rows; for\n" \
    "larger inputs use skyview, sky or light, which keep no horizon map.\n" \
    "  --degrees         alpha in degrees\n" \
    "  --azimuth A       one direction only, toward azimuth A (the convention's, degrees unless\n" \
    "                    --radians): the same as --dirs 1 --azimuth0 A\n" \
    "  --split           one file per direction instead of the stack (as r.horizon writes one\n" \
    "                    map per direction), named OUT's stem + \"_\" + the direction's azimuth in\n" \
    "                    the convention in degrees: hor.pfm -> hor_000.pfm, hor_022_500.pfm (22.5);\n" \
    "                    with --exact the azimuth the ray actually takes (hor_014_036 for the\n" \
    "                    nominal 15 at K = 24). A GeoTIFF names each band's azimuth (gdalinfo)\n" \
    "Planes follow the convention: compass clockwise from azimuth0 (north by default), grass\n" \
    "counter-clockwise from azimuth0 (east by default), grid clockwise from east.\n" \
    "Default PGM range -1.5707963:1.5707963 (-90:90 with --degrees).\n"

#define CLI_SKYVIEW_HELP \
    "usage: hfvis skyview IN -o OUT [--svf zaksek|saga|visible] [options]\n" \
    "The sky-view factor SVF = 1 - (1/K) sum_k sin(max(alpha_k, 0)) (Zaksek et al. 2011, as RVT\n" \
    "and GRASS r.skyview): 1 on open flat ground, lower in valleys. Default PGM range 0:1.\n" \
    "  --svf D           zaksek (default, above; the fused sweep); saga: SAGA's \"Sky View\n" \
    "                    Factor\", the cosine-weighted sky of the tilted receiver,\n" \
    "                    (1/K) sum_k [n_z cos^2 phi_k + (n_x cos psi_k + n_y sin psi_k)\n" \
    "                    (pi/2 - phi_k - sin phi_k cos phi_k)], phi_k = max(alpha_k, 0), n the grid\n" \
    "                    normal: 1 - (1/K) sum sin^2 phi_k on level ground; visible: SAGA's\n" \
    "                    \"Visible Sky\" (1/K) sum (1 - phi_k/(pi/2)) as a fraction (SAGA: percent).\n" \
    "                    saga and visible sweep one direction at a time (no --dir-range)\n"

#define CLI_SKY_HELP \
    "usage: hfvis sky IN -o OUT [--sky C] [--albedo A] [options]\n" \
    "Light reflected under a uniform sky of radiance C, [P1] Eq. 5: cosine-weighted and aware\n" \
    "of the surface slope; an open flat receiver returns A*C (Lambertian, albedo A).\n" \
    "  --sky C           sky radiance, >= 0 (default 1)\n" \
    "  --albedo A        surface albedo, >= 0 (default 1)\n" \
    "Default PGM range 0:A*C (0:1 if A*C is 0).\n"

#define CLI_SHADOW_HELP \
    "usage: hfvis shadow IN --sun-azimuth DEG --sun-elevation DEG [--sun-radius DEG] -o OUT\n" \
    "Sun visibility in [0, 1] from one exact sweep toward the sun: 1 lit, 0 in shadow. The\n" \
    "receiver's own tangent plane is not applied; multiply by max(n.l, 0) for shading.\n" \
    "  --sun-azimuth DEG     the sun's azimuth: the --convention's, compass by default (required)\n" \
    "  --sun-elevation DEG   sun elevation above the horizontal, -90..90 (required)\n" \
    "  --sun-radius DEG      angular radius of the sun disc, 0..90 (default 0: hard shadow);\n" \
    "                        > 0 gives the visible fraction of the disc (the real sun: 0.27)\n" \
    "Default PGM range 0:1.\n"

#define CLI_LIGHT_HELP \
    "usage: hfvis light IN --env ENV.pfm -o OUT [--albedo A] [--method prefix|lp] [options]\n" \
    "Light reflected from a lat-long environment map ([P1] §6.2), Lambertian with albedo A.\n" \
    "ENV (PF colour or Pf grey; any image the codecs read) covers the whole sphere: row 0 is\n" \
    "the zenith, the last row the nadir; column p is the azimuth band [2 pi p/n, 2 pi (p+1)/n)\n" \
    "measured like psi, from east toward south (--compass does not change it). OUT has the\n" \
    "channels of ENV (PF or Pf).\n" \
    "  --env ENV.pfm     the environment map (required)\n" \
    "  --albedo A        surface albedo, >= 0 (default 1)\n" \
    "  --method M        prefix (exact prefix integrals, default) or lp (the paper's L_p table)\n" \
    "Default PGM range 0:the largest output value.\n"

#define CLI_NORMALS_HELP \
    "usage: hfvis normals IN -o OUT [options]\n" \
    "Unit surface normals ([P1] §7: sum of the four quad normals around a sample), 3 channels\n" \
    "(x east, y south, z up); NaN at holes. Uses --cell, --zscale and --nodata only.\n" \
    "Default PGM range -1:1 (the x, y and z planes stacked top to bottom).\n"

#define CLI_INDIRECT_HELP \
    "usage: hfvis indirect IN -o OUT [--albedo A | --albedo-map MAP] [--bounces B]\n" \
    "         [--sun-azimuth DEG --sun-elevation DEG [--sun-radius DEG] [--sun-irradiance E]]\n" \
    "         [--sky C | --env ENV.pfm] [--emission EMIT] [--output total|direct|indirect]\n" \
    "Light with interreflections between terrain points ([P2] §10.1). The direct light D (sun\n" \
    "and uniform sky or environment, [P1]; reflected radiance for albedo 1) gives the exit\n" \
    "radiance L_0 = EMIT + A*D, and each bounce gathers the light of the terrain samples every\n" \
    "point sees along the K directions (hull-tree intervisibility, [P2] §5-8):\n" \
    "L_(b+1) = EMIT + A*(D + I[L_b]). Lambertian radiance: an open flat receiver under a sky C\n" \
    "with albedo A returns A*C. Default: no sun, sky 1, albedo 1, one bounce.\n" \
    "  --albedo A            constant albedo, >= 0 (default 1)\n" \
    "  --albedo-map MAP      per-sample albedo, a map of IN's size (instead of --albedo): GeoTIFF,\n" \
    "                        ASC, EHdr (.bil/.flt), PFM or PGM (values / maxval)\n" \
    "  --bounces B           interreflection bounces, 0..1000 (default 1); one sweep each\n" \
    "  --sun-azimuth DEG     the sun's azimuth: the --convention's, compass by default\n" \
    "  --sun-elevation DEG   sun elevation above the horizontal, -90..90 (with --sun-azimuth)\n" \
    "  --sun-radius DEG      angular radius of the sun disc, 0..90 (default 0: hard shadows)\n" \
    "  --sun-irradiance E    irradiance on a surface facing the sun, >= 0 (default pi: a flat\n" \
    "                        receiver under a zenith sun reflects E/pi = 1 with albedo 1)\n" \
    "  --sky C               uniform sky radiance, >= 0 (default 1; 0 for the sun alone)\n" \
    "  --env ENV.pfm         lat-long environment instead of the uniform sky (see 'light')\n" \
    "  --emission EMIT       emitted radiance per sample, a map of IN's size (default 0)\n" \
    "  --output WHAT         total: L_B, the exit radiance after B bounces (default);\n" \
    "                        direct: L_0 = EMIT + A*D, no bounce (--bounces not allowed);\n" \
    "                        indirect: L_B - L_0, the light that came from other terrain\n" \
    "                        (needs B >= 1)\n" \
    "Maps (MAP, EMIT) are PGM or PFM images of IN's size: PGM values are divided by the file's\n" \
    "maxval (0..1), PFM values are used as stored; they must be finite and >= 0 wherever IN\n" \
    "has no hole. OUT has 3 channels (PF) if ENV, MAP or EMIT has 3, else 1 (Pf); a one-channel\n" \
    "input then applies to all three. NaN at holes. Default PGM range 0:the largest output value.\n"

#define CLI_VISIBILITY_HELP \
    "usage: hfvis visibility IN -o OUT [--fraction] [--stats] [options]\n" \
    "The visibility index: the number of grid samples each point sees along its K lines, from\n" \
    "the hull-tree intervisibility sweep ([P2] §5-8). A sample is seen when no sample between\n" \
    "it and the point rises above the sight line (grazing counts); the point itself is not\n" \
    "counted, nor samples outside the grid (also with --border clamp/wrap), nor holes. On a\n" \
    "flat field with --dirs 1, column x of a W-wide row sees W-1-x samples. NaN at holes.\n" \
    "Off the grid axes a point takes the counts of the lattice nodes around it bilinearly, so\n" \
    "the count is not a whole number there (a GeoTIFF output is then Float32).\n"             \
    "  --fraction   divide by the samples the point could see: the same count on a flat field\n" \
    "               with IN's holes, where every sample is seen; in [0, 1], 0 where the point's\n" \
    "               lines hold no sample. Runs a second sweep in which every sample is visible,\n" \
    "               O(K*W*H*N): 15 s at 1024 x 1024, K = 16 on one core\n" \
    "  --stats      before writing OUT, print the sweep's counters to stdout as averages per\n" \
    "               receiver-direction (lattice node and direction), as [P2] Tables 1-2:\n" \
    "               visible samples, horizons m_a and tree iterations t_a; with --fraction also\n" \
    "               the samples tested (the naive scan's iterations) and the ratios\n" \
    "Default PGM range 0:the largest count (0:1 with --fraction).\n"

#define CLI_VIEWSHED_HELP \
    "usage: hfvis viewshed IN --observer X,Y -o OUT [--observer-height H] [--target-height T]\n" \
    "         [--max-distance D] [--exact]\n" \
    "The viewshed of one observer: 1 where the observer's eye sees the target above a sample,\n" \
    "0 where terrain hides it, NaN at holes and beyond --max-distance (0 in PGM). The terrain\n" \
    "is the bilinear surface through the samples; a sight line that grazes it counts as\n" \
    "visible. Method: R2 of Franklin & Ray 1994 (rays to every border sample, running maximum\n" \
    "slope), O((W + H) * max(W, H)): 2(W + H) rays of up to max(W, H) steps (a 1 x 1048576 grid\n" \
    "takes hours); it differs from the exact line of sight (--exact) only at samples whose\n" \
    "sight line nearly grazes the terrain: measured from 8 observers (summit, valley, slope, 5\n" \
    "random) on a 512 x 512 SRTM tile and a 512 x 512 fBm, on 0.005-1.2 % of the samples (mean\n" \
    "0.2-0.4 %); the most from a summit, which sees the most.\n" \
    "  --observer X,Y        the observer in map coordinates (required, or --observer-grid):\n" \
    "                        sample (column c, row r) is at X = c*cell, Y = r*cell (cell centres;\n" \
    "                        a georeferenced input uses its geotransform); it must stand on data\n" \
    "  --observer-grid C,R   the observer's column and row instead, reals in [0, W-1] x [0, H-1]\n" \
    "                        (one observer: the two together, or either twice, are refused)\n" \
    "  --target X,Y          a point of interest (map coordinates, up to 64): prints\n" \
    "                        \"target X,Y (column c, row r): visible|hidden|...\" for its nearest sample\n" \
    "  --curvature           Earth curvature and refraction as GRASS r.viewshed -c -r: each target\n" \
    "                        is lowered by (1 - k) d^2/(2 R), d its horizontal distance (heights and\n" \
    "                        --cell in metres)\n" \
    "  --refraction K        refraction coefficient k, -1..1 (default 0.13; 0: curvature only)\n" \
    "  --earth-radius R      R in metres (default 6371000, the mean radius)\n" \
    "  --observer-height H   eye height above the surface, height units, >= 0 (default 0)\n" \
    "  --target-height T     target height above each sample, >= 0 (default 0)\n" \
    "  --max-distance D      horizontal range in height units (--cell applies), >= 0;\n" \
    "                        0 = unlimited (default)\n" \
    "  --exact               the exact line-of-sight oracle instead (half-cell march per\n" \
    "                        sample): O(W*H*max(W, H)), 4 s at 1024 x 1024\n" \
    "--dirs, --azimuth0, --compass, --degrees and --border do not apply. Default PGM range 0:1.\n"

#define CLI_VOXELIZE_HELP \
    "usage: hfvis voxelize MESH.obj --res N [--mode surface|conservative|solid] [--axis A]\n" \
    "         [--method pixel|slicing|clipping] [--max-vertices V] [--padding F] [--open]\n" \
    "         -o OUT.binvox|OUT.raw\n" \
    "Voxels of a triangle mesh (Wavefront OBJ: v and f lines, polygons fanned). The grid has\n" \
    "cubic voxels, N of them along the longest side of the mesh's bounding box (enlarged by F\n" \
    "times that side on every side), the other sides rounded up and centred.\n" \
    "  --res N           voxels along the longest side, 1..2048 (required)\n" \
    "  --mode M          surface (default): the voxels that hold a pixel-centre sample of a\n" \
    "                    triangle in the sweep along its dominant axis ([G12] ch. 6, 6-separating\n" \
    "                    with --axis all; a sample on the grid's far side, as a cube's top\n" \
    "                    face, goes into the last voxel); conservative: every voxel a triangle\n" \
    "                    touches (exact triangle-box overlap); solid: the voxels whose centre\n" \
    "                    is inside the mesh, by ray parity (the mesh must be closed unless\n" \
    "                    --open: the parity of every column along x, y and z is checked,\n" \
    "                    whatever --axis)\n" \
    "  --axis A          surface: dominant (default), all (three sweeps merged, [G12] Alg. 4) or\n" \
    "                    x, y, z (one sweep); solid: the parity ray direction x, y or z (default z)\n" \
    "  --method M        surface: pixel (the pixel-centre rule, default), slicing (geometry-shader\n" \
    "                    triangle slicing, [G12] Alg. 5) or clipping (fragment clipping, Alg. 6)\n" \
    "  --max-vertices V  slicing/clipping: the geometry shader's output-vertex limit; triangles\n" \
    "                    spanning more slabs than it allows leave holes, as in the thesis\n" \
    "                    (slicing V >= 7, clipping V >= 3; default unlimited)\n" \
    "  --padding F       empty margin around the mesh, a fraction of its longest side, 0..1\n" \
    "                    (default 0)\n" \
    "  --open            solid: leave columns that cross an open mesh an odd number of times\n" \
    "                    empty instead of failing\n" \
    "OUT: *.binvox (the binvox format of viewvox/binvox: a cube of the largest side, at most\n" \
    "2^31 voxels, run-length coded, translate and scale of the grid) or *.raw (one byte per\n" \
    "voxel, 0 or 1, x fastest, then y, then z; the dimensions are printed). Prints the grid and\n" \
    "the voxel count unless --quiet.\n"

#define CLI_SSAO_HELP \
    "usage: hfvis ssao DEPTH.pfm -o OUT [--method lsao|hbao|ffao|raytrace] [--fov-y DEG]\n" \
    "         [--ortho SCALE] [--radius R] [--dirs K] [--guard PIXELS]\n" \
    "         [--depth linear|gl|d3d|reversed --near N --far F]\n" \
    "Screen-space ambient obscurance of a depth buffer (one-channel PFM or PGM, row 0 at the\n" \
    "top). OUT is obscurance in [0, 1] (0 = open) of the inner pixels: the buffer minus the\n" \
    "guard band on every side. A depth that is not finite or <= 0 (after --depth's decoding)\n" \
    "is background: it occludes nothing and gets 0.\n" \
    "  --method M        lsao: line-sweep AO ([P3]); hbao: horizon-based ray march, out to\n" \
    "                    a sixteenth of the image height; ffao: far-field AO ([P4], default);\n" \
    "                    raytrace: the screen-space ray-traced reference (256 rays per\n" \
    "                    pixel, slow)\n" \
    "  --fov-y DEG       vertical field of view of the inner image, 0..180 (default 60)\n" \
    "  --ortho SCALE     orthographic camera instead, SCALE view units per pixel\n" \
    "  --radius R        falloff rho = R^2/(R^2 + d^2) (view units); default none (rho = 1)\n" \
    "  --dirs K          directions (default: lsao 16, hbao 16, ffao 8 x 2 segments; raytrace\n" \
    "                    ignores it)\n" \
    "  --guard PIXELS    guard band per side (default 10 % of the width and height)\n" \
    "  --depth ENC       linear view depth (default), gl or d3d window depth, reversed Z; the\n" \
    "                    hardware encodings need --near and --far (0 < near < far; 0 <= near\n" \
    "                    with --ortho), which linear depth refuses\n" \
    "Default PGM range 0:1.\n"

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

#define CLI_AZIMUTHS_HELP \
    "usage: hfvis azimuths [IN] --dirs K [--exact] [--convention compass|grass|grid] [--azimuth0 A]\n" \
    "         [--radians]\n" \
    "Prints the K azimuths a run with these options uses, one per line, in output-plane order\n" \
    "(plane k of 'hfvis horizon'), in degrees of the convention: compass bearings (clockwise\n" \
    "from north, the default; --compass says the same), GRASS's counter-clockwise from east, or\n" \
    "grid (from east toward south, the library's psi). --azimuth0 is direction 0 in that\n" \
    "convention, degrees unless --radians. Without --exact: direction k is azimuth0 + 360k/K\n" \
    "(GRASS: counter-clockwise); with --exact: rational directions (a, b), the nearest with\n" \
    "max(|a|, |b|) <= max(5, ceil(K/4)) (64 for K = 1), and for K > 32 the cheapest (smallest\n" \
    "|a| + |b|) within 0.25 degrees or, for K > 360, a quarter of the sector 360/K (K <=\n" \
    "16384). IN, when given, is read as the run reads it\n" \
    "(the directions do not depend on it).\n"

#define CLI_INFO_HELP \
    "usage: hfvis info RASTER\nPrints width, height, bands, cell, origin (map X and Y of " \
    "the upper-left corner), crs, nodata and format\nof RASTER (.tif .asc .bil .flt .pfm, " \
    "binary .pgm), one 'key value' per line; cell, origin\nand nodata are 'none' when the " \
    "file has none. Only the header is read.\n"
