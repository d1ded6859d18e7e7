/* flags.c - the command line: the table of flags (name, value, the commands that take it, type,
 * range, default, unit), the parsing primitives (cli_real, cli_int, cli_set_number) and cli_parse,
 * which applies each flag and checks the combinations. Owns: cli_args' contents. May call:
 * progress.c (errors), gis.c (GIS flags), the command families' flag setters and checks (sweeps.c,
 * screen.c, meshes.c). */

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

/* What a flag's value is: the type column of `hfvis --list-flags`. */
enum {
    CLI_V_NONE,   /* a switch: no value */
    CLI_V_INT,    /* an integer */
    CLI_V_REAL,   /* a finite number */
    CLI_V_TEXT,   /* a file name or a specification read by its command */
    CLI_V_CHOICE, /* one of a few words */
    CLI_V_LIST,   /* numbers joined by ',', ':' or 'x' (pairs, points, windows, sizes) */
    CLI_V_DATE,   /* a date or a time of day */
    CLI_V_BYTES,  /* a size in bytes with an optional K, M, G or T */
    CLI_V_DURATION /* hours: a number with its unit, m (minutes) or h (hours); a bare number refused */
};
static const char *const cli_kind_names[] = {"-", "int", "real", "text", "choice", "list", "date",
                                             "bytes", "duration"};

/* The flags: name, value (its placeholder in the help; NULL: the flag takes none), the commands
 * that use it, its value's type, range, default and unit, and for the shared options their --help
 * entry (the others are described in their commands' help). A command refuses by name every flag
 * whose row does not list it; `hfvis --list-flags [CMD]` prints this table, `hfvis CMD --help`
 * its rows for CMD, test/cli_test.sh walks it. A flag whose meaning depends on the command
 * (--rays, --fov, --radius) has one row per meaning, with disjoint commands (cli_flag_for).
 * A numeric row (int, real, duration) has a field ("at"): cli_parse stores its default dv there
 * before reading the command line, and cli_set_number parses it from the row alone: the value must
 * lie in [lo, hi] (lo excluded when lo_open), else the refusal names the flag and says "expected
 * <rule>"; its "then" hook, if any, checks or converts the stored value afterwards. The other
 * rows (at 0) are parsed by their commands' setters: their syntax is not a number. */
typedef struct cli_flag {
    const char *name, *value;
    unsigned long commands; /* CLI_ONLY(CMD_...) bits */
    int kind;               /* CLI_V_... */
    double lo, hi;          /* CLI_V_INT, CLI_V_REAL, CLI_V_DURATION rows: the accepted range */
    int lo_open;            /* lo itself refused */
    const char *rule;       /* the range in words, for the refusal: "expected <rule>, got '<v>'" */
    double dv;              /* what the field holds without the flag */
    const char *def, *unit; /* the default in words where dv is a "not given" mark or reads
                               better so (NULL: dv itself), and the unit (NULL: none) */
    size_t at, has;         /* offsetof the cli_args field it sets (int or double by kind; 0: a
                               command's setter), and of its has_ field (0: none) */
    const char *word;       /* a word taken instead of a number (the field keeps dv; then sees it) */
    int (*then)(cli_args *a, const char *v); /* after the value is stored: 0 or CLI_EXIT_USAGE */
    const char *help;
} cli_flag;
#define CLI_HAS(field) offsetof(cli_args, field)
#define CLI_SWITCH CLI_V_NONE, 0.0, 0.0, 0, NULL, 0.0, "off", NULL, 0, 0, NULL, NULL
#define CLI_TYPED(kind) kind, 0.0, 0.0, 0, NULL, 0.0, NULL, NULL, 0, 0, NULL, NULL
#define CLI_WORDS(kind, def) kind, 0.0, 0.0, 0, NULL, 0.0, def, NULL, 0, 0, NULL, NULL /* its default */
#define CLI_NUMBER(kind, lo, lo_open, hi, rule, dv, def, unit, field, has, word, then) \
    kind, lo, hi, lo_open, rule, dv, def, unit, offsetof(cli_args, field), has, word, then
#define CLI_INT_AT(lo, hi, rule, dv, def, unit, field, has) \
    CLI_NUMBER(CLI_V_INT, lo, 0, hi, rule, dv, def, unit, field, has, NULL, NULL)
#define CLI_REAL_AT(lo, lo_open, hi, rule, dv, def, unit, field, has) \
    CLI_NUMBER(CLI_V_REAL, lo, lo_open, hi, rule, dv, def, unit, field, has, NULL, NULL)
static const cli_flag cli_flags[] = {
    { "-o", "OUT", CLI_OUT,
      CLI_TYPED(CLI_V_TEXT),
      "output file, required: *.pfm writes PFM floats, *.pgm a 16-bit PGM;\n"
      "                    a PGM of a 3-channel result stacks the channels as planes, top to bottom;\n"
      "                    PGM code 0 is NoData and LO..HI map to 1..65535, recorded in the header\n"
      "                    comment \"# hfvis range LO HI nodata 0\"\n"
      "                    *.tif a GeoTIFF (tiled, DEFLATE; Float32, or the smallest integer type\n"
      "                    for viewshed and whole visibility counts), *.asc an ESRI ASCII grid,\n"
      "                    *.bil/*.flt raw floats + .hdr: these carry IN's georeference and NoData\n"
      "                    (planes and channels become bands)\n" },
    { "--band", "N", CLI_HF,
      CLI_INT_AT(1, EX_RIO_MAX_BANDS, "a band number 1..65535", 0.0, "1", NULL, band, 0),
      "IN is a multi-band raster: use band N (1-based, default 1)\n" },
    { "--range", "LO:HI", CLI_PGM,
      CLI_WORDS(CLI_V_LIST, "per command"),
      ".pgm only: the values mapped to 0 and 65535 (default per command)\n" },
    { "--cell", "S", CLI_HF,
      CLI_REAL_AT(0.0, 1, DBL_MAX, "a number > 0", 1.0, "georef or 1", "height units", cell,
                  CLI_HAS(has_cell)),
      "distance between samples, in height units (default: the cell size of a\n"
      "                    georeferenced IN (.tif, .asc, .bil/.flt), else 1 with a note)\n" },
    { "--zscale", "Z", CLI_HF,
      CLI_NUMBER(CLI_V_REAL, -CLI_FLT_MAX, 0, CLI_FLT_MAX, "a non-zero number", 1.0, NULL, NULL,
                 zscale, 0, NULL, cli_then_zscale),
      "multiply input values by Z, non-zero (default 1)\n" },
    { "--nodata", "V", CLI_HF,
      CLI_REAL_AT(-CLI_FLT_MAX, 0, CLI_FLT_MAX, "a finite number", 0.0, "none", "height units",
                  nodata, CLI_HAS(has_nodata)),
      "input values equal to V are holes: no occlusion, output NaN (PGM code 0)\n" },
    { "--dirs", "K", CLI_DIRS | CLI_ONLY(CMD_SSAO) | CLI_ONLY(CMD_VISFIELD) | CLI_ONLY(CMD_SOLAR),
      CLI_INT_AT(1, CLI_MAX_DIRS, "an integer 1..65536", 16.0, "16 (openness 8, solar 64)", "directions",
                 dirs, CLI_HAS(has_dirs)),
      "number of azimuth directions, 1..65536 (default 16; openness 8, solar 64)\n" },
    { "--convention", "C", CLI_ANGLES,
      CLI_WORDS(CLI_V_CHOICE, "compass"),
      "how azimuths are read and directions ordered (height-field commands):\n"
      "                    compass (default): bearings clockwise from north, direction k at\n"
      "                    azimuth0 + 360k/K; grass: counter-clockwise from east (r.horizon,\n"
      "                    r.sun), direction k at azimuth0 + 360k/K counter-clockwise; grid: the\n"
      "                    library's psi, from east toward south (x toward y; the old --math)\n" },
    { "--azimuth0", "A", CLI_DIRS,
      CLI_REAL_AT(-1e6, 0, 1e6, "a finite angle (degrees, or radians with --radians)", 0.0,
                  "compass 0 = north; grass, grid 0 = east", "degrees (radians with --radians)",
                  azimuth0, CLI_HAS(has_azimuth0)),
      "azimuth of direction 0 in the convention (default: compass 0 = north;\n"
      "                    grass and grid 0 = east). Degrees (before 0.2: radians); see --radians\n" },
    { "--radians", NULL, CLI_ANGLES,
      CLI_SWITCH,
      "angle flags (--azimuth0, --azimuth, --sun-*) in radians, not degrees\n" },
    { "--compass", NULL, CLI_ANGLES,
      CLI_SWITCH,
      "the same as --convention compass (the default)\n" },
    { "--degrees", NULL, CLI_ONLY(CMD_HORIZON) | CLI_ONLY(CMD_OPENNESS),
      CLI_SWITCH,
      "angle outputs in degrees instead of radians\n" },
    { "--dir-range", "A:B", CLI_ONLY(CMD_HORIZON) | CLI_ONLY(CMD_SKYVIEW) | CLI_ONLY(CMD_SKY) | CLI_ONLY(CMD_LIGHT)
                      | CLI_ONLY(CMD_VISIBILITY),
      CLI_TYPED(CLI_V_LIST),
      "horizon, skyview, sky, light, visibility: only the directions at\n"
      "                    positions A..B-1 of the K (0 <= A < B <= K) in sweep order (with K a\n"
      "                    multiple of 4, each 4 consecutive positions are the quarter turns\n"
      "                    k, k+K/4, k+K/2, k+3K/4 that share one lattice: give A and B as\n"
      "                    multiples of 4 and each part costs its share of the run); OUT (*.hfvs)\n"
      "                    is then a partial result, and 'hfvis sum' adds the parts of a split\n"
      "                    into the single run's OUT\n" },
    { "--border", "MODE", CLI_BORDER | CLI_ONLY(CMD_SOLAR),
      CLI_WORDS(CLI_V_CHOICE, "open"),
      "open (nothing outside the grid, default), clamp (edge heights extend\n"
      "                    outward) or wrap (periodic field)\n" },
    { "--border-cells", "N", (CLI_BORDER & ~(CLI_ONLY(CMD_GI) | CLI_ONLY(CMD_VISIBILITY))) | CLI_ONLY(CMD_SOLAR),
      CLI_INT_AT(1, HFVIS_IMAGE_MAX_DIM, "an integer 1..1048576", 0.0, "max(W,H)", "cells",
                 border_cells, 0),
      "clamp/wrap: lines start N cells outside the grid, 1..1048576\n"
      "                    (default max(width, height))\n" },
    { "--exact", NULL, CLI_ONLY(CMD_VIEWSHED) | CLI_ONLY(CMD_HORIZON) | CLI_ONLY(CMD_SKYVIEW) | CLI_ONLY(CMD_SKY)
                      | CLI_ONLY(CMD_LIGHT) | CLI_ONLY(CMD_SHADOW) | CLI_ONLY(CMD_AZIMUTHS)
                      | CLI_ONLY(CMD_HILLSHADE),
      CLI_SWITCH,
      "horizon, skyview, sky, light, shadow: exact rays (beyond [P1]): every\n"
      "                    sample gets its own ray along the nearest rational direction, no\n"
      "                    interpolation between lattice lines (right at walls, roofs, cliffs;\n"
      "                    'hfvis azimuths --exact' prints the directions used). visibility,\n"
      "                    indirect and gi keep the lattice. --dirs K: 1..16384 with --exact\n" },
    { "--exact-near", "D", CLI_ONLY(CMD_HORIZON) | CLI_ONLY(CMD_SKYVIEW) | CLI_ONLY(CMD_SKY) | CLI_ONLY(CMD_LIGHT)
                         | CLI_ONLY(CMD_SHADOW) | CLI_ONLY(CMD_HILLSHADE),
      CLI_INT_AT(0, HFVIS_RAY_NEAR_CELLS_MAX, "an integer 0..65536", 0.0, "0 (every sample)", "cells",
                 exact_near, CLI_HAS(has_exact_near)),
      "with exact rays, without --max-distance: each receiver's own ray within\n"
      "                    D cells, beyond that a far field shared by the receivers within half\n"
      "                    a cell of it (within atan(1/(2D)) of the azimuth; D = 8: 3.6 deg), for\n"
      "                    the directions whose lines are longer than D cells between grid points\n"
      "                    (at K = 16 none); 0 = every sample of every ray (default). D = 8 is\n"
      "                    2-3x faster at K >= 64 (docs/exact-rays.md, near and far field)\n" },
    { "--max-distance", "R", CLI_ONLY(CMD_VIEWSHED) | CLI_ONLY(CMD_VISFIELD) | CLI_SWEEP | CLI_P2
                           | CLI_ONLY(CMD_SOLAR),
      CLI_REAL_AT(0.0, 0, DBL_MAX, "a distance >= 0", 0.0, "0 (unlimited)", "height units",
                  max_distance, 0),
      "horizon, skyview, sky, shadow, light, visibility, indirect, hillshade:\n"
      "                    the search radius in height units (--cell applies): occluders farther\n"
      "                    than R along the ray are ignored (GRASS maxdistance, SAGA and RVT radius,\n"
      "                    WhiteboxTools max_dist); 0 = unlimited (default). visibility and\n"
      "                    indirect: visible samples farther than R are not counted or gathered.\n"
      "                    viewshed: its range\n" },
    { "--window", "X0,Y0,W,H", CLI_SWEEP | CLI_ONLY(CMD_OPENNESS) | CLI_ONLY(CMD_SOLAR),
      CLI_TYPED(CLI_V_LIST),
      "with a finite R (openness: --radius R; not visibility, indirect; solar:\n"
      "                    each output a piece, IN's height range read by strips): only the\n"
      "                    W x H cells from\n"
      "                    column X0, row Y0 (clipped to IN), reading only them and a halo of\n"
      "                    ceil(R/cell) + 1 cells (GeoTIFF strips/tiles, .bil/.flt, PFM and binary\n"
      "                    PGM rows, by seeking); OUT (.pfm .tif .bil .flt .asc) is a piece, placed\n"
      "                    and georeferenced at the window, with its sidecar OUT.tile; 'hfvis\n"
      "                    mosaic' joins the pieces into the whole run's OUT (docs/tiles.md)\n" },
    { "--quiet", NULL, CLI_OUT,
      CLI_SWITCH,
      "no progress bar (shown on stderr only when it is a terminal) and no notes\n" },
    { "--progress", NULL, CLI_RUNS,
      CLI_SWITCH,
      "plain progress lines on stderr instead (percent, elapsed, ETA), for logs\n"
      "                    and job schedulers, and a summary line at the end (time, cells,\n"
      "                    directions); runs over 10 s end with the summary anyway (not --quiet)\n" },
    { "--overwrite", NULL, CLI_OUT,
      CLI_SWITCH,
      "allow OUT to be one of the inputs (refused otherwise: same file,\n"
      "                    through hard and symbolic links too); solar: each of its outputs.\n"
      "                    Two outputs of one run never share a file (or an ASC/EHdr .prj)\n" },
    { "--max-memory", "B", CLI_RUNS,
      CLI_WORDS(CLI_V_BYTES, "half the physical memory"),
      "refuse a run whose estimated memory exceeds B bytes (suffix K, M, G or\n"
      "                    T: powers of 1024; 0 = no limit); default half of the physical memory\n"
      "                    where the system reports it (sysconf), else no limit. The estimate and\n"
      "                    the work (lattice nodes swept, rays, voxel updates) are printed on\n"
      "                    stderr with the progress bar\n" },
    { "--threads", "N", CLI_THREADED,
      CLI_INT_AT(0, CLI_THREADS_MAX, "an integer 0..256 (0: the online cores)", 0.0,
                 "0 (the online cores)", "threads", threads, CLI_HAS(has_threads)),
      "horizon, skyview, sky, light, shadow, hillshade, openness --radius, solar:\n"
      "                    run on N threads, 0..256; default 0: the online cores, fewer where\n"
      "                    --max-memory cannot hold one run's estimate per thread. The output\n"
      "                    is the one-thread run's bit for bit (directions, bands across the sun,\n"
      "                    rows; solar: its exact horizon map by directions). Each thread adds its\n"
      "                    own lattice (--exact: a tangent plane) to the peak memory\n"
      "                    (docs/performance.md, Threads)\n" },
    { "--sky", "C", CLI_ONLY(CMD_SKY) | CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI),
      CLI_REAL_AT(0.0, 0, CLI_FLT_MAX, "a radiance >= 0", 1.0, NULL, "radiance", sky,
                  CLI_HAS(has_sky)), NULL },
    { "--albedo", "A", CLI_ONLY(CMD_SKY) | CLI_ONLY(CMD_LIGHT) | CLI_ONLY(CMD_INDIRECT)
                     | CLI_ONLY(CMD_GI) | CLI_ONLY(CMD_VOLGI) | CLI_ONLY(CMD_SOLAR),
      CLI_REAL_AT(0.0, 0, CLI_FLT_MAX, "an albedo >= 0", 1.0, "per command", NULL, albedo,
                  CLI_HAS(has_albedo)), NULL },
    { "--sun-azimuth", "DEG", CLI_SUN,
      CLI_REAL_AT(-DBL_MAX, 0, DBL_MAX, "a finite angle in degrees", 0.0, "per command", "degrees",
                  sun_azimuth, CLI_HAS(has_sun_azimuth)), NULL },
    { "--sun-elevation", "DEG", CLI_SUN,
      CLI_REAL_AT(-90.0, 0, 90.0, "degrees in -90..90", 0.0, "per command", "degrees",
                  sun_elevation, CLI_HAS(has_sun_elevation)), NULL },
    { "--sun-radius", "DEG", CLI_SUN | CLI_ONLY(CMD_SOLAR),
      CLI_REAL_AT(0.0, 0, 90.0, "degrees in 0..90", 0.0, NULL, "degrees", sun_radius,
                  CLI_HAS(has_sun_radius)), NULL },
    { "--math", NULL, CLI_SUN,
      CLI_SWITCH, NULL },
    { "--env", "ENV", CLI_ONLY(CMD_LIGHT) | CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI),
      CLI_TYPED(CLI_V_TEXT), NULL },
    { "--method", "M", CLI_ONLY(CMD_LIGHT) | CLI_ONLY(CMD_VOXELIZE) | CLI_ONLY(CMD_SSAO)
                     | CLI_ONLY(CMD_MESHAO),
      CLI_WORDS(CLI_V_CHOICE, "per command"), NULL },
    { "--sun-irradiance", "E", CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI),
      CLI_REAL_AT(0.0, 0, CLI_FLT_MAX, "an irradiance >= 0", CLI_PI, "pi", "irradiance",
                  sun_irradiance, CLI_HAS(has_sun_irradiance)), NULL },
    { "--albedo-map", "MAP", CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_SOLAR),
      CLI_TYPED(CLI_V_TEXT), NULL },
    { "--emission", "MAP", CLI_ONLY(CMD_INDIRECT),
      CLI_TYPED(CLI_V_TEXT), NULL },
    { "--bounces", "B", CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI),
      CLI_INT_AT(0, CLI_MAX_BOUNCES, "an integer 0..1000", 1.0, NULL, "bounces", bounces,
                 CLI_HAS(has_bounces)), NULL },
    { "--output", "WHAT", CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI) | CLI_ONLY(CMD_VOLGI),
      CLI_WORDS(CLI_V_CHOICE, "total"), NULL },
    { "--fraction", NULL, CLI_ONLY(CMD_VISIBILITY),
      CLI_SWITCH, NULL },
    { "--stats", NULL, CLI_ONLY(CMD_VISIBILITY) | CLI_ONLY(CMD_MESHAO),
      CLI_SWITCH, NULL },
    { "--observer", "X,Y", CLI_ONLY(CMD_VIEWSHED),
      CLI_TYPED(CLI_V_LIST), NULL },
    { "--observer-height", "H", CLI_ONLY(CMD_VIEWSHED),
      CLI_REAL_AT(0.0, 0, DBL_MAX, "a height >= 0", 0.0, NULL, "height units", observer_height, 0),
                  NULL },
    { "--target-height", "H", CLI_ONLY(CMD_VIEWSHED),
      CLI_REAL_AT(0.0, 0, DBL_MAX, "a height >= 0", 0.0, NULL, "height units", target_height, 0),
                  NULL },
    { "--res", "N", CLI_ONLY(CMD_VOXELIZE) | CLI_ONLY(CMD_VOLGI),
      CLI_INT_AT(1, CLI_MAX_RES, "an integer 1..2048", 0.0, "per command", "voxels", res, 0),
                 NULL },
    { "--mode", "M", CLI_ONLY(CMD_VOXELIZE),
      CLI_WORDS(CLI_V_CHOICE, "surface"), NULL },
    { "--axis", "A", CLI_ONLY(CMD_VOXELIZE),
      CLI_WORDS(CLI_V_CHOICE, "dominant (solid: z)"), NULL },
    { "--max-vertices", "N", CLI_ONLY(CMD_VOXELIZE),
      CLI_INT_AT(1, 1000000, "an integer 1..1000000", 0.0, "per method", "vertices", max_vertices,
                 0), NULL },
    { "--padding", "P", CLI_ONLY(CMD_VOXELIZE),
      CLI_REAL_AT(0.0, 0, 1.0, "a fraction in 0..1", 0.0, NULL, NULL, padding, 0), NULL },
    { "--open", NULL, CLI_ONLY(CMD_VOXELIZE),
      CLI_SWITCH, NULL },
    { "--order", "O", CLI_ONLY(CMD_GI),
      CLI_INT_AT(1, 4, "an integer 1..4", 4.0, NULL, "SH order", order, 0), NULL },
    { "--subsample", "S", CLI_ONLY(CMD_GI),
      CLI_INT_AT(1, HFVIS_NS_MAX_SUBSAMPLE, "an integer 1..64", 1.0, NULL, "cells per side",
                 subsample, 0), NULL },
    { "--specular", "S", CLI_ONLY(CMD_GI),
      CLI_REAL_AT(0.0, 0, CLI_FLT_MAX, "a weight >= 0", 0.0, NULL, NULL, specular,
                  CLI_HAS(has_specular)), NULL },
    { "--shininess", "N", CLI_ONLY(CMD_GI),
      CLI_REAL_AT(0.0, 1, CLI_FLT_MAX, "an exponent > 0", 32.0, NULL, NULL, shininess,
                  CLI_HAS(has_shininess)), NULL },
    { "--room", NULL, CLI_ONLY(CMD_VOLGI),
      CLI_SWITCH, NULL },
    { "--iterations", "I", CLI_ONLY(CMD_VOLGI),
      CLI_INT_AT(1, HFVIS_VOLGI_MAX_ITERATIONS, "an integer 1..1048576",
                 HFVIS_VOLGI_DEFAULT_ITERATIONS, NULL, "steps",
                 iterations, 0), NULL },
    { "--light", "SPEC", CLI_ONLY(CMD_VOLGI),
      CLI_TYPED(CLI_V_TEXT), NULL },
    { "--eye", "X,Y,Z", CLI_ONLY(CMD_VOLGI) | CLI_ONLY(CMD_MESHAO),
      CLI_TYPED(CLI_V_LIST), NULL },
    { "--target", "POINT", CLI_ONLY(CMD_VOLGI) | CLI_ONLY(CMD_MESHAO)
                     | CLI_ONLY(CMD_VIEWSHED),
      CLI_TYPED(CLI_V_LIST), NULL },
    { "--up", "X,Y,Z", CLI_ONLY(CMD_VOLGI) | CLI_ONLY(CMD_MESHAO),
      CLI_TYPED(CLI_V_LIST), NULL },
    { "--fov", "DEG", CLI_ONLY(CMD_VOLGI),
      CLI_REAL_AT(1.0, 0, 179.0, "degrees in 1..179", 40.0, NULL, "degrees", vg_fov, 0), NULL },
    { "--fov", "DEG", CLI_ONLY(CMD_MESHAO),
      CLI_REAL_AT(1.0, 0, 179.0, "degrees in 1..179", 45.0, NULL, "degrees", lk_fov, 0), NULL },
    { "--size", "WxH", CLI_ONLY(CMD_VOLGI) | CLI_ONLY(CMD_VISFIELD) | CLI_ONLY(CMD_MESHAO),
      CLI_WORDS(CLI_V_LIST, "per command"), NULL },
    { "--transfer", "T", CLI_ONLY(CMD_VOLGI),
      CLI_WORDS(CLI_V_CHOICE, "cone"), NULL },
    { "--paths", "P", CLI_ONLY(CMD_VOLGI),
      CLI_WORDS(CLI_V_CHOICE, "all"), NULL },
    { "--reflection", "R", CLI_ONLY(CMD_VOLGI),
      CLI_WORDS(CLI_V_CHOICE, "mirror"), NULL },
    { "--reflectance", "R", CLI_ONLY(CMD_VOLGI),
      CLI_NUMBER(CLI_V_REAL, 0.0, 0, 1.0, "a reflectance in 0..1 or 'albedo'", 0.0,
                 "0.5", NULL, vg_rho, CLI_HAS(vg_has_rho), "albedo",
                 cli_then_reflectance), NULL },
    { "--positions", "K", CLI_ONLY(CMD_VISFIELD),
      CLI_NUMBER(CLI_V_INT, 1, 0, INT_MAX, "a count 2(2n^2+2n+1) such as 290, 1090 or 4226",
                 0.0, "4226", "positions", vf_positions, 0, NULL, cli_then_positions), NULL },
    { "--format", "F", CLI_ONLY(CMD_VISFIELD),
      CLI_WORDS(CLI_V_CHOICE, "u8"), NULL },
    { "--mapping", "M", CLI_ONLY(CMD_VISFIELD),
      CLI_WORDS(CLI_V_CHOICE, "concentric"), NULL },
    { "--ao", NULL, CLI_ONLY(CMD_VISFIELD),
      CLI_SWITCH, NULL },
    { "--ground", "Z", CLI_ONLY(CMD_VISFIELD),
      CLI_REAL_AT(-CLI_FLT_MAX, 0, CLI_FLT_MAX, "a finite height", 0.0, "per field", "object units",
                 vf_ground, CLI_HAS(vf_has_ground)), NULL },
    { "--extent", "E", CLI_ONLY(CMD_VISFIELD),
      CLI_REAL_AT(0.0, 1, CLI_FLT_MAX, "a half-size > 0", 0.0, "1.5 radii", "object units",
                  vf_extent, CLI_HAS(vf_has_extent)), NULL },
    { "--rays", "S", CLI_ONLY(CMD_VISFIELD),
      CLI_INT_AT(1, HFVIS_VISFIELD_MAX_RAYS_SQRT, "an integer 1..256", 0.0, "16", "rays per side",
                 vf_rays, 0), NULL },
    { "--rays", "N", CLI_ONLY(CMD_MESHAO),
      CLI_INT_AT(1, HFVIS_LK_MAX_RAYS, "an integer 1..4096", 128.0, NULL, "rays", lk_rays, 0),
                 NULL },
    { "--bias", "B", CLI_ONLY(CMD_VISFIELD),
      CLI_REAL_AT(0.0, 0, 1.0, "a fraction of the radius in 0..1", 0.0, "0.02", "radii", vf_bias,
                 CLI_HAS(vf_has_bias)), NULL },
    { "--reference", "MESH", CLI_ONLY(CMD_VISFIELD),
      CLI_TYPED(CLI_V_TEXT), NULL },
    { "--falloff", "F", CLI_ONLY(CMD_MESHAO),
      CLI_WORDS(CLI_V_CHOICE, "constant"), NULL },
    { "--two-sided", NULL, CLI_ONLY(CMD_MESHAO),
      CLI_SWITCH, NULL },
    { "--lut", "T", CLI_ONLY(CMD_MESHAO),
      CLI_INT_AT(HFVIS_LK_LUT_MIN_RESOLUTION, HFVIS_LK_LUT_MAX_RESOLUTION,
                 "a table resolution 2..1024", 0.0, "none", "nodes per side", lk_lut, 0), NULL },
    { "--seed", "S", CLI_ONLY(CMD_MESHAO),
      CLI_REAL_AT(0.0, 0, 9007199254740992.0, "an integer 0..2^53", 0.0, NULL, NULL, lk_seed, 0),
                  NULL },
    { "--no-jitter", NULL, CLI_ONLY(CMD_MESHAO),
      CLI_SWITCH, NULL },
    { "--pattern", "P", CLI_ONLY(CMD_MESHAO),
      CLI_WORDS(CLI_V_CHOICE, "torus"), NULL },
    { "--fov-y", "DEG", CLI_ONLY(CMD_SSAO),
      CLI_REAL_AT(0.0, 1, 179.999, "degrees in (0, 180)", 60.0, NULL, "degrees", ssao_fov, 0),
                  NULL },
    { "--ortho", "SCALE", CLI_ONLY(CMD_SSAO),
      CLI_REAL_AT(0.0, 1, CLI_FLT_MAX, "a scale > 0", 0.0, "none (perspective)",
                  "view units per pixel", ssao_ortho, CLI_HAS(ssao_has_ortho)), NULL },
    { "--radius", "R", CLI_ONLY(CMD_SSAO),
      CLI_REAL_AT(0.0, 1, CLI_FLT_MAX, "a radius > 0", 0.0, "none (rho = 1)", "view units",
                  ssao_radius, 0), NULL },
    { "--radius", "R", CLI_ONLY(CMD_MESHAO),
      CLI_REAL_AT(0.0, 1, CLI_FLT_MAX, "a radius > 0", 0.0, "0.1 x the mesh's diagonal",
                  "mesh units",
                  lk_radius, CLI_HAS(lk_has_radius)), NULL },
    { "--radius", "R", CLI_ONLY(CMD_OPENNESS),
      CLI_REAL_AT(0.0, 0, DBL_MAX, "a distance >= 0 (0 = unlimited)", 0.0, "0 (unlimited)",
                  "height units", radius, CLI_HAS(has_radius)), NULL },
    { "--guard", "PIXELS", CLI_ONLY(CMD_SSAO),
      CLI_INT_AT(0, 65536, "an integer 0..65536", -1.0, "W/10 and H/10", "pixels", ssao_guard, 0),
                 NULL },
    { "--depth", "ENC", CLI_ONLY(CMD_SSAO),
      CLI_WORDS(CLI_V_CHOICE, "linear"), NULL },
    { "--near", "N", CLI_ONLY(CMD_SSAO),
      CLI_REAL_AT(-CLI_FLT_MAX, 0, CLI_FLT_MAX, "a finite distance", 0.0, "none", "view units",
                  ssao_near, CLI_HAS(ssao_has_near)), NULL },
    { "--far", "F", CLI_ONLY(CMD_SSAO),
      CLI_REAL_AT(-CLI_FLT_MAX, 0, CLI_FLT_MAX, "a finite distance", 0.0, "none", "view units",
                  ssao_far, CLI_HAS(ssao_has_far)), NULL },
    { "--azimuth", "A", CLI_ONLY(CMD_HORIZON),
      CLI_REAL_AT(-1e6, 0, 1e6, "a finite angle (degrees, or radians with --radians)", 0.0,
                  "none (K directions)", "degrees (radians with --radians)", azimuth,
                  CLI_HAS(has_azimuth)), NULL },
    { "--split", NULL, CLI_ONLY(CMD_HORIZON),
      CLI_SWITCH, NULL },
    { "--observer-grid", "C,R", CLI_ONLY(CMD_VIEWSHED),
      CLI_TYPED(CLI_V_LIST), NULL },
    { "--curvature", NULL, CLI_ONLY(CMD_VIEWSHED),
      CLI_SWITCH, NULL },
    { "--refraction", "K", CLI_ONLY(CMD_VIEWSHED),
      CLI_REAL_AT(-1.0, 0, 1.0, "a coefficient in -1..1", CLI_REFRACTION, NULL, NULL, refraction,
                 CLI_HAS(has_refraction)), NULL },
    { "--earth-radius", "R", CLI_ONLY(CMD_VIEWSHED),
      CLI_REAL_AT(0.0, 1, 1e12, "a radius > 0 (metres)", CLI_EARTH_RADIUS, NULL, "metres",
                  earth_radius, CLI_HAS(has_earth_radius)), NULL },
    { "--svf", "D", CLI_ONLY(CMD_SKYVIEW),
      CLI_WORDS(CLI_V_CHOICE, "zaksek"), NULL },
    { "--blend", "N", CLI_ONLY(CMD_HILLSHADE),
      CLI_INT_AT(1, 360, "a count of sun directions 1..360", 0.0, "1", "suns", blend, 0), NULL },
    { "--no-shadows", NULL, CLI_ONLY(CMD_HILLSHADE),
      CLI_SWITCH, NULL },
    { "--negative", NULL, CLI_ONLY(CMD_OPENNESS),
      CLI_SWITCH, NULL },
    { "--both", NULL, CLI_ONLY(CMD_OPENNESS),
      CLI_SWITCH, NULL },
    { "--lattice", NULL, CLI_ONLY(CMD_HILLSHADE),
      CLI_SWITCH, NULL },
    { "--day", "DATE", CLI_ONLY(CMD_SOLAR),
      CLI_TYPED(CLI_V_DATE), NULL },
    { "--start", "DATE", CLI_ONLY(CMD_SOLAR),
      CLI_TYPED(CLI_V_DATE), NULL },
    { "--end", "DATE", CLI_ONLY(CMD_SOLAR),
      CLI_TYPED(CLI_V_DATE), NULL },
    { "--time", "HH:MM", CLI_ONLY(CMD_SOLAR),
      CLI_TYPED(CLI_V_DATE), NULL },
    { "--step", "S", CLI_ONLY(CMD_SOLAR),
      CLI_NUMBER(CLI_V_DURATION, 0.0, 1, 24.0, "a step in (0, 24h] with its unit, like 15m or 0.5h", 0.0,
                 "15m", "hours (m or h required)", sol_step, 0, NULL, NULL), NULL },
    { "--linke", "L", CLI_ONLY(CMD_SOLAR),
      CLI_REAL_AT(0.0, 1, 10.0, "a Linke turbidity factor in (0, 10]", 0.0, "3", NULL, sol_linke,
                  CLI_HAS(sol_has_linke)), NULL },
    { "--linke-monthly", "L1,...,L12", CLI_ONLY(CMD_SOLAR),
      CLI_TYPED(CLI_V_LIST), NULL },
    { "--linke-map", "MAP", CLI_ONLY(CMD_SOLAR),
      CLI_TYPED(CLI_V_TEXT), NULL },
    { "--latitude", "DEG", CLI_ONLY(CMD_SOLAR),
      CLI_REAL_AT(-90.0, 0, 90.0, "a latitude in degrees, -90..90", 0.0, "IN's CRS", "degrees",
                  sol_lat, CLI_HAS(sol_has_lat)), NULL },
    { "--longitude", "DEG", CLI_ONLY(CMD_SOLAR),
      CLI_REAL_AT(-180.0, 0, 180.0, "a longitude in degrees, -180..180 (east positive)", 0.0,
                  "IN's CRS", "degrees", sol_lon, CLI_HAS(sol_has_lon)), NULL },
    { "--utc-offset", "H", CLI_ONLY(CMD_SOLAR),
      CLI_REAL_AT(-14.0, 0, 14.0, "hours east of UTC, -14..14", 0.0, NULL, "hours", sol_offset,
                  CLI_HAS(sol_has_offset)), NULL },
    { "--solar-time", NULL, CLI_ONLY(CMD_SOLAR),
      CLI_SWITCH, NULL },
    { "--bands", "day|month", CLI_ONLY(CMD_SOLAR),
      CLI_WORDS(CLI_V_CHOICE, "one (the total)"), NULL },
    { "--horizons", "exact|near-far|lattice", CLI_ONLY(CMD_SOLAR),
      CLI_WORDS(CLI_V_CHOICE, "exact"), NULL },
    { "--normals", "central|horn", CLI_ONLY(CMD_SOLAR),
      CLI_WORDS(CLI_V_CHOICE, "central"), NULL },
    { "--height-range", "LO,HI", CLI_ONLY(CMD_SOLAR),
      CLI_TYPED(CLI_V_LIST), NULL },
    { "--beam", "OUT", CLI_ONLY(CMD_SOLAR),
      CLI_TYPED(CLI_V_TEXT), NULL },
    { "--diffuse", "OUT", CLI_ONLY(CMD_SOLAR),
      CLI_TYPED(CLI_V_TEXT), NULL },
    { "--reflected", "OUT", CLI_ONLY(CMD_SOLAR),
      CLI_TYPED(CLI_V_TEXT), NULL },
    { "--sun-hours", "OUT", CLI_ONLY(CMD_SOLAR),
      CLI_TYPED(CLI_V_TEXT), NULL },
};
#define CLI_NFLAGS (sizeof cli_flags / sizeof cli_flags[0])

/* The command named name, or -1. */
static int cli_command_of(const char *name)
{
    int c;
    for (c = 0; c < CMD_COUNT; c++)
        if (!strcmp(name, cli_commands[c].name)) return c;
    return -1;
}

/* The row of flag name that command cmd uses (a flag of several meanings has one row per
 * meaning), else its first row, else CLI_NFLAGS. */
static size_t cli_flag_for(const char *name, int cmd)
{
    size_t k, first = CLI_NFLAGS;
    for (k = 0; k < CLI_NFLAGS; k++) {
        if (strcmp(name, cli_flags[k].name)) continue;
        if (cli_flags[k].commands & CLI_ONLY(cmd)) return k;
        if (first == CLI_NFLAGS) first = k;
    }
    return first;
}

/* Every numeric row's default into its field (cli_parse, before the command line). */
static void cli_flag_defaults(cli_args *a)
{
    char *base = (char *)a;
    size_t k;
    for (k = 0; k < CLI_NFLAGS; k++) {
        const cli_flag *f = &cli_flags[k];
        if (!f->at) continue;
        if (f->kind == CLI_V_INT) *(int *)(void *)(base + f->at) = (int)f->dv;
        else *(double *)(void *)(base + f->at) = f->dv;
    }
}

/* A numeric flag from its row (row->at != 0): v parsed as the row's kind (a duration: a number of
 * minutes with m or of hours with h, stored in hours; a bare number is refused, as its unit
 * would be a guess), checked against [lo, hi] (lo
 * excluded when lo_open), stored in the row's cli_args field, its has_ field set, then its hook
 * run; the row's word, if any, is taken instead of a number (the field keeps its default). Returns
 * 0 or CLI_EXIT_USAGE ("expected <rule>, got '<v>'", naming the flag). */
static int cli_set_number(cli_args *a, const cli_flag *row, const char *v)
{
    char *base = (char *)a;
    int rc;
    if (row->has) *(int *)(void *)(base + row->has) = 1;
    if (row->word && !strcmp(v, row->word)) rc = 0;
    else if (row->kind == CLI_V_INT)
        rc = cli_int(row->name, v, (long)row->lo, (long)row->hi, row->rule,
                     (int *)(void *)(base + row->at));
    else if (row->kind == CLI_V_DURATION) {
        char buf[64];
        size_t n = strlen(v);
        double x, scale = 1.0 / 60.0;
        if (n == 0 || n >= sizeof buf)
            return cli_error(CLI_EXIT_USAGE, row->name, "expected %s, got '%s'", row->rule, v);
        memcpy(buf, v, n + 1);
        if (buf[n - 1] != 'm' && buf[n - 1] != 'h') {
            if (cli_parse_real(buf, &x))
                return cli_error(CLI_EXIT_USAGE, row->name, "'%s' has no unit: give minutes or hours, like "
                                 "%sm or %sh (range (0, 24h])", v, v, v);
            return cli_error(CLI_EXIT_USAGE, row->name, "expected %s, got '%s'", row->rule, v);
        }
        if (buf[n - 1] == 'h') scale = 1.0;
        buf[n - 1] = '\0';
        if (!cli_parse_real(buf, &x))
            return cli_error(CLI_EXIT_USAGE, row->name, "expected %s, got '%s'", row->rule, v);
        x *= scale;
        if (x < row->lo || (row->lo_open && x == row->lo) || x > row->hi)
            return cli_error(CLI_EXIT_USAGE, row->name, "expected %s, got '%s'", row->rule, v);
        *(double *)(void *)(base + row->at) = x;
        rc = 0;
    } else
        rc = cli_real(row->name, v, row->lo, row->lo_open, row->hi, row->rule,
                      (double *)(void *)(base + row->at));
    if (rc) return rc;
    return row->then ? row->then(a, v) : 0;
}

/* --zscale: non-zero as a float too (the library multiplies in float). */
static int cli_then_zscale(cli_args *a, const char *v)
{
    if ((float)a->zscale == 0.0f)
        return cli_error(CLI_EXIT_USAGE, "--zscale", "expected a non-zero number, got '%s'", v);
    return 0;
}

/* --positions K: K must be a count 2(2n^2+2n+1); the field keeps the frequency n. */
static int cli_then_positions(cli_args *a, const char *v)
{
    const char *f = "--positions";
    int k = a->vf_positions, n;
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
    a->vf_positions = n;
    return 0;
}

/* --reflectance albedo: the voxels' own colour instead of the number. */
static int cli_then_reflectance(cli_args *a, const char *v)
{
    a->vg_rho_albedo = !strcmp(v, "albedo");
    return 0;
}

/* A number of a flag's row as --list-flags and the help print it: "inf" beyond the float range
 * (no limit), else the shortest of %.15g..%.17g that reads back as x. */
static void cli_flag_number(double x, char *out, size_t cap)
{
    int p;
    if (fabs(x) >= CLI_FLT_MAX) { snprintf(out, cap, "%sinf", x < 0.0 ? "-" : ""); return; }
    for (p = 15; p <= 17; p++) {
        snprintf(out, cap, "%.*g", p, x);
        if (strtod(out, NULL) == x) return;
    }
}

/* A row's RANGE and DEFAULT columns (--list-flags, the help): "[LO,HI]" or "(LO,HI]" for reals
 * and durations, "[LO..HI]" for integers, "-" for the rows a command parses; the default in words,
 * or the row's dv, or "-" for a row without one. */
static void cli_flag_columns(const cli_flag *f, char *range, char *def, size_t cap)
{
    char lo[40], hi[40];
    if (f->at) {
        cli_flag_number(f->lo, lo, sizeof lo);
        cli_flag_number(f->hi, hi, sizeof hi);
        snprintf(range, cap, "%s%s%s%s]", f->lo_open ? "(" : "[", lo, f->kind == CLI_V_INT ? ".." : ",", hi);
    } else {
        snprintf(range, cap, "-");
    }
    if (f->def) snprintf(def, cap, "%s", f->def);
    else if (f->at) cli_flag_number(f->dv, def, cap);
    else snprintf(def, cap, "-");
}

/* A flag that command cmd does not take (arg: "--name" or "--name=value"): refused by name,
 * "not used" when the table has it, else unknown. Returns CLI_EXIT_USAGE. */
static int cli_refuse_flag(int cmd, const char *arg)
{
    const char *name = cli_commands[cmd].name, *eq = strchr(arg, '=');
    char flag[64];
    size_t n = eq ? (size_t)(eq - arg) : strlen(arg);
    if (n >= sizeof flag) n = sizeof flag - 1;
    memcpy(flag, arg, n);
    flag[n] = '\0';
    if (cli_flag_for(flag, cmd) == CLI_NFLAGS)
        return cli_error(CLI_EXIT_USAGE, flag, "unknown option (see 'hfvis %s --help')", name);
    return cli_error(CLI_EXIT_USAGE, name, "%s is not used by %s (see 'hfvis %s --help')", flag, name, name);
}

/* The values section of `hfvis CMD --help`: for each flag CMD uses, from its row, one line
 * "  --flag VALUE  TYPE[ in RANGE][, default DEF][, unit UNIT]" (TYPE "switch" for a flag without
 * a value; RANGE and DEF as --list-flags prints them, so the two cannot disagree). */
static void cli_help_values(int cmd)
{
    size_t k;
    int any = 0;
    for (k = 0; k < CLI_NFLAGS; k++) {
        const cli_flag *f = &cli_flags[k];
        char label[64], range[96], def[96];
        if (!(f->commands & CLI_ONLY(cmd))) continue;
        if (!any++)
            printf("\nvalues of %s's options (type, range, default, unit; also 'hfvis --list-flags %s'):\n",
                   cli_commands[cmd].name, cli_commands[cmd].name);
        snprintf(label, sizeof label, "%s%s%s", f->name, f->value ? " " : "", f->value ? f->value : "");
        cli_flag_columns(f, range, def, sizeof range);
        printf("  %-18s  %s", label, f->kind == CLI_V_NONE ? "switch" : cli_kind_names[f->kind]);
        if (strcmp(range, "-")) printf(" in %s", range);
        if (strcmp(def, "-")) printf(", default %s", def);
        if (f->unit) printf(", unit %s", f->unit);
        printf("\n");
    }
}

/* `hfvis --help` (cmd < 0: the usage, the commands and every shared option) or `hfvis CMD
 * --help` (the command's help, the shared options it uses and the values of all its options),
 * from the tables; returns 0. */
static int cli_help(int cmd)
{
    size_t k;
    int c;
    if (cmd < 0) {
        printf("%s", cli_usage);
        for (c = 0; c < CMD_COUNT; c++) printf("  %-11s %s\n", cli_commands[c].name, cli_commands[c].summary);
        printf("\nshared options (each command's --help lists those it uses; it refuses the others):\n");
    } else if (cli_commands[cmd].main) { /* sum, mosaic, info: their help lists their options */
        printf("%s", cli_commands[cmd].help);
        cli_help_values(cmd);
        return 0;
    } else {
        printf("%s\nshared options of %s:\n", cli_commands[cmd].help, cli_commands[cmd].name);
    }
    for (k = 0; k < CLI_NFLAGS; k++) {
        const cli_flag *f = &cli_flags[k];
        char label[64];
        if (!f->help || (cmd >= 0 && !(f->commands & CLI_ONLY(cmd)))) continue;
        snprintf(label, sizeof label, "%s%s%s", f->name, f->value ? " " : "", f->value ? f->value : "");
        printf("  %-16s  %s", label, f->help);
    }
    printf("%s", cli_help_tail);
    if (cmd >= 0) cli_help_values(cmd);
    return 0;
}

/* `hfvis --list-commands`: the commands, one per line (for scripts and tests). */
static int cli_list_commands(int argc)
{
    int c;
    if (argc != 2) return cli_error(CLI_EXIT_USAGE, "--list-commands", "takes no argument");
    for (c = 0; c < CMD_COUNT; c++) printf("%s\n", cli_commands[c].name);
    return fflush(stdout) == 0 && !ferror(stdout) ? 0 : cli_error(CLI_EXIT_ERROR, "stdout", "write error");
}

/* `hfvis --list-flags [COMMAND]`: one flag per line, "NAME VALUE COMMANDS TYPE RANGE DEFAULT
 * UNIT" separated by tabs (VALUE "-" for a flag without one, COMMANDS the commands that use it,
 * comma-separated; TYPE int, real, text, choice, list, date, bytes or "-" for a switch; RANGE
 * "[LO,HI]" or "(LO,HI]" for reals, "[LO..HI]" for integers, "inf" for no limit, "-" where a
 * hand-written setter checks the value; "-" for no default or unit); with COMMAND, only the flags
 * it uses. */
static int cli_list_flags(int argc, char **argv)
{
    int cmd = -1, c;
    size_t k;
    if (argc > 3) return cli_error(CLI_EXIT_USAGE, "--list-flags", "takes at most one COMMAND");
    if (argc == 3 && (cmd = cli_command_of(argv[2])) < 0)
        return cli_error(CLI_EXIT_USAGE, argv[2], "unknown command (try 'hfvis --list-commands')");
    for (k = 0; k < CLI_NFLAGS; k++) {
        const char *sep = "";
        const cli_flag *f = &cli_flags[k];
        char range[96], def[96];
        if (cmd >= 0 && !(f->commands & CLI_ONLY(cmd))) continue;
        printf("%s\t%s\t", f->name, f->value ? f->value : "-");
        for (c = 0; c < CMD_COUNT; c++)
            if (f->commands & CLI_ONLY(c)) printf("%s%s", sep, cli_commands[c].name), sep = ",";
        cli_flag_columns(f, range, def, sizeof range);
        printf("\t%s\t%s\t%s\t%s\n", cli_kind_names[f->kind], range, def, f->unit ? f->unit : "-");
    }
    return fflush(stdout) == 0 && !ferror(stdout) ? 0 : cli_error(CLI_EXIT_ERROR, "stdout", "write error");
}

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
    if (a->cmd == CMD_SOLAR) {
        int r = cli_set_solar(a, f, v);
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
    {
        size_t k = cli_flag_for(f, a->cmd);
        const cli_flag *row = k < CLI_NFLAGS ? &cli_flags[k] : NULL;
        if (row && row->at) /* a numeric flag of the table: its row says its range and field */
            return cli_set_number(a, row, v) ? CLI_EXIT_USAGE : 0;
    }
    if (!strcmp(f, "--degrees")) { a->degrees = 1; return 0; }
    if (!strcmp(f, "--quiet")) { a->quiet = 1; return 0; }
    if (!strcmp(f, "--border")) {
        if (!strcmp(v, "open")) a->border = HFVIS_BORDER_OPEN;
        else if (!strcmp(v, "clamp")) a->border = HFVIS_BORDER_CLAMP;
        else if (!strcmp(v, "wrap")) a->border = HFVIS_BORDER_WRAP;
        else return cli_error(CLI_EXIT_USAGE, f, "expected open, clamp or wrap, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--albedo-map")) { a->albedo_map = v; return 0; }
    if (!strcmp(f, "--emission")) { a->emission = v; return 0; }
    if (!strcmp(f, "--output")) {
        if (!strcmp(v, "total")) a->output = OUT_TOTAL;
        else if (!strcmp(v, "direct")) a->output = OUT_DIRECT;
        else if (!strcmp(v, "indirect")) a->output = OUT_INDIRECT;
        else return cli_error(CLI_EXIT_USAGE, f, "expected total, direct or indirect, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--fraction")) { a->fraction = 1; return 0; }
    if (!strcmp(f, "--stats")) { a->stats = 1; return 0; }
    if (!strcmp(f, "--env")) { a->env = v; return 0; }
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
    if (a->cmd == CMD_SSAO) {
        int r = cli_set_ssao(a, f, v);
        if (r >= 0) return r;
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
    if (a->border == HFVIS_BORDER_CLAMP && a->cmd != CMD_OPENNESS) /* openness marches a plain grid */
        return cli_error(CLI_EXIT_USAGE, "--border clamp", "a sweep's clamped lines start outside the "
                         "whole raster, which a window's lines do not: not with --window (run whole, "
                         "or --border open; openness --radius windows take clamp)");
    return 0;
}

/* Returns CLI_RUN, or the exit status after printing help (0) or a usage error (2). */
static int cli_parse(int argc, char **argv, cli_args *a)
{
    int i, c, positional_only = 0;
    memset(a, 0, sizeof *a);
    cli_flag_defaults(a);
    a->max_memory = cli_default_max_memory();
    a->border = HFVIS_BORDER_OPEN; a->method = HFVIS_ENV_PREFIX;
    a->output = OUT_TOTAL;
    a->ssao_method = SSAO_FFAO; a->ssao_depth = SSAO_DEPTH_LINEAR;
    cli_volgi_defaults(a);
    cli_lk_defaults(a);
    if (argc < 2) return cli_error(CLI_EXIT_USAGE, "usage", "missing COMMAND (try 'hfvis --help')");
    if (!strcmp(argv[1], "-h") || !strcmp(argv[1], "--help") || !strcmp(argv[1], "help")) {
        if (argc > 2 && strcmp(argv[1], "help") == 0) {
            if ((c = cli_command_of(argv[2])) < 0)
                return cli_error(CLI_EXIT_USAGE, argv[2], "unknown command (try 'hfvis --help')");
            return cli_help(c);
        }
        return cli_help(-1);
    }
    if ((c = cli_command_of(argv[1])) < 0)
        return cli_error(CLI_EXIT_USAGE, argv[1], "unknown command (try 'hfvis --help')");
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
        if (!strcmp(arg, "-h") || !strcmp(arg, "--help")) return cli_help(a->cmd);
        eq = strchr(arg, '=');
        n = eq ? (size_t)(eq - arg) : strlen(arg);
        if (n >= sizeof name) n = sizeof name - 1;
        memcpy(name, arg, n);
        name[n] = '\0';
        if ((k = cli_flag_for(name, a->cmd)) == CLI_NFLAGS) return cli_refuse_flag(a->cmd, name);
        if ((CLI_ONLY(a->cmd) & CLI_P2) && !strcmp(name, "--window"))
            return cli_error(CLI_EXIT_USAGE, cli_commands[a->cmd].name, "--window is not used by %s: "
                             "it sweeps whole lattice lines with the [P2] hull tree, which honours "
                             "--max-distance but computes no windows; run it whole (or split it with "
                             "--dir-range)", cli_commands[a->cmd].name);
        if (!(cli_flags[k].commands & CLI_ONLY(a->cmd))) return cli_refuse_flag(a->cmd, name);
        if (cli_flags[k].value) {
            if (eq) value = eq + 1;
            else if (i + 1 < argc) value = argv[++i];
            else return cli_error(CLI_EXIT_USAGE, name, "missing value");
        } else if (eq) {
            return cli_error(CLI_EXIT_USAGE, name, "takes no value");
        }
        if (cli_set(a, name, value)) return CLI_EXIT_USAGE;
    }
    if (!a->in && (cli_commands[a->cmd].io & CLI_IN_NEEDED) && !(a->cmd == CMD_VOLGI && a->room))
        return cli_error(CLI_EXIT_USAGE, cli_commands[a->cmd].name, "missing input file IN");
    if (!a->out && (cli_commands[a->cmd].io & CLI_OUT_NEEDED))
        return cli_error(CLI_EXIT_USAGE, cli_commands[a->cmd].name, "missing -o OUT");
    if (a->threads == 0) { /* --threads 0, the default: the online cores, capped by cli_check_cost */
        a->threads = cli_threads_online();
        a->threads_auto = 1;
    }
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
        if (a->has_threads && a->threads > 1)
            return cli_error(CLI_EXIT_USAGE, "--threads", "a --dir-range part runs on one thread: "
                             "split the range into more parts instead");
        a->threads = 1;
    }
    if (a->border_cells > 0 && a->border == HFVIS_BORDER_OPEN) /* only clamp and wrap lines start outside */
        return cli_error(CLI_EXIT_USAGE, "--border-cells", "applies to --border clamp or wrap (an open border "
                         "has nothing outside the grid)");
    if (a->cmd == CMD_HILLSHADE) { /* a GIS product: exact shadows unless --lattice */
        if (a->lattice && a->exact)
            return cli_error(CLI_EXIT_USAGE, "--lattice", "cannot be combined with --exact");
        a->exact = !a->lattice;
    }
    if (a->exact && a->has_dirs && a->dirs > 4 * HFVIS_RAY_DENOMINATOR_MAX) /* hfvis.h "Exact rays" */
        return cli_error(CLI_EXIT_USAGE, "--dirs", "exact rays take K <= %d directions, got %d",
                         4 * HFVIS_RAY_DENOMINATOR_MAX, a->dirs);
    if (a->has_exact_near && a->exact_near > 0 && !a->exact)
        return cli_error(CLI_EXIT_USAGE, "--exact-near", "applies to exact rays: add --exact");
    if (a->has_exact_near && a->exact_near > 0 && a->max_distance > 0.0)
        return cli_error(CLI_EXIT_USAGE, "--exact-near", "applies without --max-distance (a finite "
                         "radius keeps every sample of every ray)");
    if (a->has_threads && a->threads > 1 && a->cmd == CMD_OPENNESS && !(a->radius > 0.0))
        return cli_error(CLI_EXIT_USAGE, "--threads", "openness splits over threads with --radius R "
                         "only (unlimited openness runs on one thread)");
    if (cli_commands[a->cmd].check && cli_commands[a->cmd].check(a)) return CLI_EXIT_USAGE;
    if (a->has_window && cli_check_window(a)) return CLI_EXIT_USAGE;
    return CLI_RUN;
}
