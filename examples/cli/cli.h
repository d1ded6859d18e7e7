/* cli.h - the `hfvis` command-line tool's shared declarations (README.md, CLI): limits, the
 * commands, the parsed arguments (cli_args), the types several files share, the run's state
 * (cli_run_state, reached through cli_args.run) and the prototypes of every function. The tool
 * is one translation unit (main.c includes every file once), so everything here is static. Files by concern:
 *   main.c          the entry point        help.c          the help texts
 *   flags.c         flag table and parser  progress.c      errors, progress bar and lines
 *   gis.c           conventions, rasters   run.c           estimate, loading, cli_run
 *   write.c         safe writing, signals  sweeps.c        sweep helpers, gi, horizon planes
 *   p2.c            indirect, visibility   gis_products.c  viewshed, hillshade, openness
 *   screen.c        ssao                   meshes.c        meshao, visfield, volgi, voxelize
 *   split.c         --dir-range and sum    tiles.c         --window pieces and mosaic
 *   solar.c         solar: dates, site, irradiation
 * Every file is read and written through the library's codecs (hfvis_image_load, the encoders
 * and hfvis_write_file) or examples/raster_io.h (GeoTIFF, ASC, EHdr), so the tool exercises what
 * a vendoring user gets; an interrupt (SIGINT, SIGTERM, SIGHUP) removes the temporary file of a
 * write in progress. Errors: one line "hfvis: <what>: <why>" on stderr, exit 1 (2 for usage
 * errors); exit 0 means OUT is complete. */
#ifndef HFVIS_CLI_H
#define HFVIS_CLI_H
#define _POSIX_C_SOURCE 200809L /* isatty() under -std=c99 */
#define _DEFAULT_SOURCE /* glibc: madvise's MADV_HUGEPAGE beside it (threads.c, cli_huge_alloc) */
#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#if defined(__unix__) || (defined(__APPLE__) && defined(__MACH__))
#include <sys/stat.h> /* stat(): an output that is an input */
#include <sys/mman.h> /* madvise(): large blocks on huge pages (threads.c) */
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

/* The commands, in the order of `hfvis --help`; each is one row of cli_commands (main.c). */
enum { CMD_HORIZON, CMD_SKYVIEW, CMD_SKY, CMD_SHADOW, CMD_LIGHT, CMD_NORMALS, CMD_INDIRECT,
       CMD_GI, CMD_VISIBILITY, CMD_VIEWSHED, CMD_HILLSHADE, CMD_OPENNESS, CMD_SOLAR, CMD_VOXELIZE,
       CMD_VOLGI, CMD_VISFIELD, CMD_MESHAO, CMD_SSAO, CMD_SUM, CMD_MOSAIC, CMD_INFO, CMD_AZIMUTHS,
       CMD_COUNT };

/* voxelize --mode, --axis, --method */
enum { VOX_SURFACE, VOX_CONSERVATIVE, VOX_SOLID };
enum { AXIS_DEFAULT, AXIS_DOMINANT, AXIS_ALL, AXIS_X, AXIS_Y, AXIS_Z };
#define CLI_MAX_RES 2048 /* --res upper bound (the grid limit is 2^31 voxels) */

/* indirect --output */
enum { OUT_TOTAL, OUT_DIRECT, OUT_INDIRECT };

#define CLI_VOLGI_MAX_LIGHTS 8

/* A --window run (docs/tiles.md): the window of the raster it writes, the grid it loads (the
 * window and a halo, clipped to the raster), and what its piece's sidecar records. */
#define CLI_PIECE_TAG_MAX 2048 /* a piece's run tag: the command, the input's identity, ~30 parameters */
typedef struct cli_window {
    int active;                 /* this run computes one piece */
    int halo;                   /* cells of halo (cli_halo), -1 unknown */
    int x0, y0, w, h;           /* the window, clipped to the raster */
    int gx0, gy0, gw, gh;       /* the grid loaded: window + halo, clipped */
    int ext_w, ext_h;           /* the raster */
    int has_gt;                 /* the raster's own georeference (before the piece's shift): */
    double raster_gt[6];        /* solar places every raster cell by it */
    char in_id[64], crs[64], gt[160], nodata[80];
    char tag[CLI_PIECE_TAG_MAX];
} cli_window;
/* The state of one run: the georeference of a raster IN carried to a raster OUT, the --window
 * piece, the clock, the last --progress line or the progress bar, and the summary line's figures. main (and sum,
 * mosaic) own one per run, set up by cli_run_init; commands reach it through cli_args.run, the
 * progress callbacks through cli_progress_state.run. */
typedef struct cli_run_state {
    ex_georef geo;    /* the georeference of a raster IN, carried to a raster OUT (cli_save) */
    cli_window win;   /* a --window run's piece */
    double t0;        /* start of the run, cli_now() */
    double cells;     /* grid samples of the run, for the summary line */
    int directions;   /* directions of the run (0: none), for the summary line */
    double line_last; /* when the last --progress line was printed */
    int line_pct;     /* and its percentage (-1: none yet) */
    int bar_open;     /* the progress bar's line is on stderr without its newline (cli_progress) */
    int threads;      /* the threads the run uses (cli_check_cost; 0: cli_args.threads) */
} cli_run_state;

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
    int threads, has_threads; /* --threads N (threads.c); default the online cores */
    int threads_auto;         /* --threads 0 or none: cli_check_cost caps them by --max-memory */
    int lattice;              /* hillshade --lattice: lattice-mode shadows (default exact rays) */
    int exact_near, has_exact_near; /* --exact-near D: hfvis_sweep_options.ray_near_cells */
    /* solar (solar.c): dates, times, atmosphere, site, extra outputs (beam, diffuse, reflected,
     * sun hours) */
    int sol_y, sol_m, sol_d, sol_ey, sol_em, sol_ed, sol_has_start, sol_has_end;
    int sol_has_day, sol_has_range_start; /* which of --day and --start set sol_y/m/d (sol_has_start) */
    int sol_instant, sol_solar_time, sol_has_lat, sol_has_lon, sol_has_offset, sol_has_linke;
    int sol_has_linke_monthly, sol_bands, sol_horizons, sol_normals, sol_has_zrange;
    double sol_hour, sol_step, sol_lat, sol_lon, sol_offset, sol_linke, sol_linke_monthly[12];
    double sol_zmin, sol_zmax; /* --height-range LO,HI */
    const char *sol_linke_map, *sol_out[4];
    cli_run_state *run; /* the run's state (cli_run_init) */
} cli_args;

/* ssao --method, --depth */
enum { SSAO_LSAO, SSAO_HBAO, SSAO_FFAO, SSAO_RAYTRACE };
enum { SSAO_DEPTH_LINEAR, SSAO_DEPTH_GL, SSAO_DEPTH_D3D, SSAO_DEPTH_REVERSED };

/* --convention: how an azimuth flag's value is read and in which sense directions k advance.
 * The library's psi runs from east toward south (+x toward +y, rows down): clockwise on a
 * north-up map. */
enum { CONV_COMPASS, CONV_GRASS, CONV_GRID };
static const char *const cli_conv_names[3] = { "compass", "grass", "grid" };

#define CLI_SUMMARY_SECONDS 10.0 /* runs at least this long end with a summary line on stderr */

#define CLI_EARTH_RADIUS 6371000.0 /* mean Earth radius in metres (IUGG), --earth-radius default */
#define CLI_REFRACTION 0.13        /* the usual refraction coefficient (ArcGIS's default) */

/* Sets of commands, for the flag table (flags.c): bit CLI_ONLY(c) is command c. */
#define CLI_ONLY(c) (1ul << (c))
#define CLI_ALL ((1ul << CMD_COUNT) - 1ul)
/* the height-field commands: IN is a raster of heights (--cell, --zscale, --nodata, --band) */
#define CLI_HF (CLI_ONLY(CMD_HORIZON) | CLI_ONLY(CMD_SKYVIEW) | CLI_ONLY(CMD_SKY) | CLI_ONLY(CMD_SHADOW) \
                | CLI_ONLY(CMD_LIGHT) | CLI_ONLY(CMD_NORMALS) | CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI) \
                | CLI_ONLY(CMD_VISIBILITY) | CLI_ONLY(CMD_VIEWSHED) | CLI_ONLY(CMD_HILLSHADE) \
                | CLI_ONLY(CMD_OPENNESS) | CLI_ONLY(CMD_SOLAR))
/* the commands that parse with cli_parse and write OUT (--progress, --max-memory) */
#define CLI_RUNS (CLI_HF | CLI_ONLY(CMD_VOXELIZE) | CLI_ONLY(CMD_VOLGI) | CLI_ONLY(CMD_VISFIELD) \
                  | CLI_ONLY(CMD_MESHAO) | CLI_ONLY(CMD_SSAO))
/* every command that writes OUT (-o, --quiet, --overwrite); those that can write a PGM (--range) */
#define CLI_OUT (CLI_RUNS | CLI_ONLY(CMD_SUM) | CLI_ONLY(CMD_MOSAIC))
#define CLI_PGM (CLI_OUT & ~(CLI_ONLY(CMD_VOXELIZE) | CLI_ONLY(CMD_SOLAR)))
/* the commands of K azimuth directions (--dirs K, --azimuth0) */
#define CLI_DIRS (CLI_ONLY(CMD_HORIZON) | CLI_ONLY(CMD_SKYVIEW) | CLI_ONLY(CMD_SKY) | CLI_ONLY(CMD_LIGHT) \
                  | CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI) | CLI_ONLY(CMD_VISIBILITY) \
                  | CLI_ONLY(CMD_OPENNESS) | CLI_ONLY(CMD_AZIMUTHS))
#define CLI_SUN (CLI_ONLY(CMD_SHADOW) | CLI_ONLY(CMD_INDIRECT) | CLI_ONLY(CMD_GI) \
                 | CLI_ONLY(CMD_HILLSHADE)) /* the sun flags */
/* the commands with azimuth flags (--convention, --radians, --compass) */
#define CLI_ANGLES (CLI_DIRS | CLI_SUN)
/* the commands that sweep lines over the grid, which start outside it (--border) */
#define CLI_BORDER (CLI_ANGLES & ~CLI_ONLY(CMD_AZIMUTHS))
/* the sweep commands: --max-distance R is the library's search radius, --window makes a piece */
#define CLI_SWEEP (CLI_ONLY(CMD_HORIZON) | CLI_ONLY(CMD_SKYVIEW) | CLI_ONLY(CMD_SKY) | CLI_ONLY(CMD_SHADOW) \
                   | CLI_ONLY(CMD_LIGHT) | CLI_ONLY(CMD_HILLSHADE))
/* the commands whose work splits over threads bit for bit (--threads, threads.c) */
#define CLI_THREADED (CLI_ONLY(CMD_HORIZON) | CLI_ONLY(CMD_SKYVIEW) | CLI_ONLY(CMD_SKY) | CLI_ONLY(CMD_LIGHT) \
                      | CLI_ONLY(CMD_SHADOW) | CLI_ONLY(CMD_HILLSHADE) | CLI_ONLY(CMD_OPENNESS) \
                      | CLI_ONLY(CMD_SOLAR))
/* the [P2] hull-tree commands: a search radius but no windows in the library (hfvis.h, "Search
 * radius and tiles") */
#define CLI_P2 (CLI_ONLY(CMD_VISIBILITY) | CLI_ONLY(CMD_INDIRECT))

/* A command (main.c, cli_commands): its name and one-line summary for `hfvis --help`, its --help
 * text, whether it needs IN and OUT and is estimated before it runs (cli_check_cost), the check
 * of its flags' combinations (NULL: none), its memory and work estimate (run.c; set exactly for
 * the commands that take --max-memory), and how it runs: run takes the parsed arguments
 * (cli_parse); main, for the commands with lists of inputs (sum, mosaic, info), takes the
 * command line. Exactly one of run and main is set; main.c checks the table before running. */
typedef struct cli_cost cli_cost;
enum { CLI_IN_NEEDED = 1, CLI_OUT_NEEDED = 2, CLI_COST_FIRST = 4 };
typedef struct cli_command {
    const char *name, *summary, *help;
    int io; /* CLI_IN_NEEDED, CLI_OUT_NEEDED; CLI_COST_FIRST: estimated from the flags, before run */
    int (*check)(const cli_args *a);
    cli_cost (*estimate)(const cli_args *a, int w, int h, int channels);
    int (*run)(const cli_args *a);
    int (*main)(int argc, char **argv);
} cli_command;
static const cli_command cli_commands[CMD_COUNT]; /* defined in main.c */

/* One progress bar over several library calls: each call reports its own done/total, the bar
 * shows base + done out of the run's total (its units are directions; 0 = each call's total). */
typedef struct cli_progress_state {
    const char *label;
    long long base;   /* units finished by the calls before the current one */
    long long total;  /* units of the whole run */
    cli_run_state *run; /* the clock and the last line of --progress */
} cli_progress_state;


/* What a command writes, handed to cli_save: `planes` planes of w x h cells stacked top to bottom
 * (horizon: one per direction), each cell `channels` interleaved values (light: the
 * environment's), and the default PGM range [lo, hi]. A raster OUT gets planes x channels bands. */
typedef struct cli_output {
    const float *px;
    int w, h, planes, channels;
    double lo, hi;
    /* GeoTIFF: each band's description (NULL or planes*channels names), the bands' unit and
     * metadata items (GDAL_METADATA, shown by gdalinfo); NULL/0 = none */
    const char *const *band_names;
    const char *unit;
    const ex_rio_meta *meta;
    int n_meta;
} cli_output;

/* A horizon map's labels for a GeoTIFF: each band's description ("azimuth 14.036 deg compass")
 * and AZIMUTH, and the dataset's CONVENTION, UNIT and RAYS (GDAL_METADATA, shown by gdalinfo). */
typedef struct cli_labels {
    char (*names)[64], (*values)[32];
    const char **band;
    ex_rio_meta *meta; /* 3 dataset items, then one AZIMUTH per band */
    double *used;      /* exact rays: the azimuths the run used (hfvis_sweep_azimuths) */
    const char *unit;
} cli_labels;
static void cli_labels_free(cli_labels *L);
static int cli_horizon_labels(const cli_args *a, cli_labels *L);
static int cli_horizon_labels_of_tag(const char *tag, int planes, cli_labels *L);

/* What a run is expected to cost before it allocates: bytes at its peak and units of work. */
struct cli_cost {
    double bytes, work;
    const char *unit;
};

/* The library's savers, through cli_write: encode into memory (need bytes), then write. */
typedef hfvis_status (*cli_encoder)(const void *what, void *out, size_t cap, size_t *written);

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

#define CLI_TAG_MAX 1024 /* our tags: the command, fingerprints and a dozen parameters */

/* A part's georeference being encoded into b[0..cap) (split.c, cli_geo_encode): n counts every
 * byte, and over is set when they do not fit. */
typedef struct cli_geo_bytes {
    unsigned char *b;
    size_t n, cap;
    int over;
} cli_geo_bytes;

/* One part's header and a copy of its tag (pass 1 of `sum` keeps these, not the sums). */
typedef struct cli_part {
    int width, height, planes, directions, begin, end;
    char *tag;
} cli_part;

#define CLI_PIECE_MAGIC "HFVISTILE 2\n" /* 2: the values= checksum; a version-1 sidecar is refused */
#define CLI_PIECE_SIDECAR ".tile" /* appended to the piece's name */
/* How far (in cells) a piece's own origin may lie from where its sidecar's window puts it: the
 * text formats carry the origin in 17 digits, a misplaced piece is off by whole cells. */
#define CLI_PIECE_ORIGIN_TOLERANCE 1e-3

/* One piece's sidecar, as read back. */
typedef struct cli_piece {
    int x0, y0, w, h, planes, channels;
    unsigned long long values; /* the checksum of its values (cli_fnv_value) */
    char range[96];
    char tag[CLI_PIECE_TAG_MAX];
} cli_piece;

/* prototypes, by file */
/* progress.c */
static int cli_error(int code, const char *what, const char *fmt, ...);
static int cli_status(const char *what, hfvis_status s, int saved_errno);
static void cli_progress_advance(cli_progress_state *p, int done, int total, long long *now,
                                 long long *all);
static void cli_progress(void *user, int done, int total);
static void cli_progress_end(cli_run_state *run, int rc);
static double cli_default_max_memory(void);
static int cli_stderr_is_terminal(void);
static double cli_now(void);
static void cli_progress_line(void *user, int done, int total);
/* flags.c */
static int cli_parse_real(const char *s, double *out);
static int cli_real(const char *flag, const char *s, double lo, int lo_open, double hi,
                    const char *expect, double *out);
static int cli_int(const char *flag, const char *s, long lo, long hi, const char *expect, int *out);
static int cli_ends_with(const char *s, const char *ext);
static int cli_command_of(const char *name);
static size_t cli_flag_for(const char *name, int cmd);
static void cli_flag_defaults(cli_args *a);
static int cli_then_zscale(cli_args *a, const char *v);
static int cli_then_positions(cli_args *a, const char *v);
static int cli_then_reflectance(cli_args *a, const char *v);
static void cli_flag_number(double x, char *out, size_t cap);
static void cli_help_values(int cmd);
static int cli_refuse_flag(int cmd, const char *arg);
static int cli_help(int cmd);
static int cli_list_commands(int argc);
static int cli_list_flags(int argc, char **argv);
static int cli_set(cli_args *a, const char *f, const char *v);
static int cli_check_window(const cli_args *a);
static int cli_parse(int argc, char **argv, cli_args *a);
/* gis.c */
static int cli_open_raster(ex_rio_reader *r, const char *path);
static double cli_deg(const cli_args *a, double v);
static double cli_psi(int conv, double deg);
static double cli_from_psi(int conv, double psi);
static int cli_lib_direction(const cli_args *a, int k);
static int cli_pair(const char *f, const char *v, const char *what, double *x, double *y);
static int cli_set_gis(cli_args *a, const char *f, const char *v);
static int cli_gis_finish(cli_args *a);
static int cli_load_raster(const cli_args *a, float **z, int *w, int *h, double *cell);
static int cli_integral_type(const cli_args *a, const float *px, size_t n, ex_georef *g,
                             ex_rio_write_options *o);
static void cli_georef(const cli_args *a, double cell, double gt[6]);
static int cli_map_to_grid(const cli_args *a, double cell, double X, double Y, double *x, double *y);
static int cli_info(int argc, char **argv);
static int cli_check_azimuths(const cli_args *a);
static int cli_run_azimuths(const cli_args *a);
/* write.c */
static void cli_on_temp(void *user, const char *tmp);
static void cli_on_signal(int sig);
static void cli_signals(void);
static void cli_drop_aux(const char *path);
static hfvis_status cli_write(const char *path, unsigned char *bytes, size_t n, hfvis_status s);
static hfvis_status cli_write_encoded(const char *path, size_t need, cli_encoder encode, const void *what);
static hfvis_status cli_enc_binvox(const void *what, void *out, size_t cap, size_t *written);
static hfvis_status cli_enc_visfield(const void *what, void *out, size_t cap, size_t *written);
static hfvis_status cli_enc_partial(const void *what, void *out, size_t cap, size_t *written);
static hfvis_status cli_pfm_save(const char *path, const float *px, int w, int h, int channels, ptrdiff_t stride,
                                 int threads);
static hfvis_status cli_enc_pgm_range(const void *what, void *out, size_t cap, size_t *written);
static hfvis_status cli_pgm_save(const char *path, const float *px, int w, int h, ptrdiff_t stride,
                                 float lo, float hi);
static hfvis_status cli_binvox_save(const char *path, const hfvis_volume_grid *grid, const uint8_t *occ);
static hfvis_status cli_voxels_raw_save(const char *path, const hfvis_volume_grid *grid, const uint8_t *occ);
static hfvis_status cli_visfield_save(const char *path, const hfvis_visfield *vf);
static hfvis_status cli_partial_save(const char *path, const hfvis_partial *p);
static cli_output cli_output_of(const float *px, int w, int h, int planes, int channels, double lo,
                                double hi);
static int cli_save(const cli_args *a, cli_output out);
static int cli_same_file(const char *x, const char *y);
static int cli_refuse_input(int overwrite, const char *out, const char *const *inputs, int n);
static int cli_refuse_inputs(const cli_args *a, const char *out);
static int cli_same_path(const char *x, const char *y);
static int cli_refuse_unwritable(const char *path);
static int cli_refuse_outputs(const cli_args *a);
/* run.c */
static const char *const *cli_fixed_band_names(int cmd, int bands);
static cli_cost cli_cost_of(double bytes, double work, const char *unit);
static cli_cost cli_sweep_cost(const cli_args *a, int w, int h, double out, double ch, double cell_bytes,
                               double node_bytes);
static cli_cost cli_estimate_sweep(const cli_args *a, int w, int h, int channels);
static cli_cost cli_estimate_horizon(const cli_args *a, int w, int h, int channels);
static cli_cost cli_estimate_gi(const cli_args *a, int w, int h, int channels);
static cli_cost cli_estimate_visibility(const cli_args *a, int w, int h, int channels);
static cli_cost cli_estimate_indirect(const cli_args *a, int w, int h, int channels);
static cli_cost cli_estimate_solar(const cli_args *a, int w, int h, int channels);
static cli_cost cli_estimate_viewshed(const cli_args *a, int w, int h, int channels);
static cli_cost cli_estimate_ssao(const cli_args *a, int w, int h, int channels);
static cli_cost cli_estimate_voxelize(const cli_args *a, int w, int h, int channels);
static cli_cost cli_estimate_volgi(const cli_args *a, int w, int h, int channels);
static cli_cost cli_estimate_visfield(const cli_args *a, int w, int h, int channels);
static cli_cost cli_estimate_meshao(const cli_args *a, int w, int h, int channels);
static int cli_out_channels(const cli_args *a);
static int cli_check_cost(const cli_args *a, int w, int h, int channels);
static int cli_halo(const cli_args *a, double cell);
static int cli_window_side(const cli_args *a, int halo, int w, int h, int channels);
static int cli_load_heights(const cli_args *a, float **z, int *w, int *h, double *cell);
static float *cli_alloc(size_t a, size_t b, size_t c);
static int cli_run_heights(const cli_args *a);
/* sweeps.c */
static int cli_check_light_flags(const cli_args *a);
static int cli_check_gi(const cli_args *a);
static int cli_load_env(const char *path, float **px, hfvis_env *env);
static int cli_load_map(const char *path, const cli_window *win, const hfvis_grid *grid, float **px,
                        int *channels);
static int cli_widen(float **px, size_t n, int channels);
static double cli_top(const float *px, size_t n, double fallback);
static int cli_check_radiance(const char *cmd, const hfvis_grid *grid, const float *out, int channels);
static int cli_run_gi(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts,
                  cli_progress_state *prog);
static int cli_horizon_finish(const cli_args *a, float *map, int w, int h, double lo, double hi);
static int cli_check_shadow(const cli_args *a);
static int cli_check_light(const cli_args *a);
/* p2.c */
static int cli_check_indirect(const cli_args *a);
static int cli_run_indirect(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts,
                            cli_progress_state *prog);
static int cli_run_visibility(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts,
                              cli_progress_state *prog);
/* gis_products.c */
static int cli_run_viewshed(const cli_args *a, const hfvis_grid *grid, float *out);
static int cli_run_hillshade(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts,
                             cli_progress_state *prog, float *out);
static int cli_run_openness(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts,
                            cli_progress_state *prog, float *out);
static int cli_run_skyview_saga(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts,
                                cli_progress_state *prog, float *out);
static int cli_run_gis(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts,
                       cli_progress_state *prog);
static int cli_check_hillshade(const cli_args *a);
static int cli_check_viewshed(const cli_args *a);
/* screen.c */
static int cli_set_ssao(cli_args *a, const char *f, const char *v);
static int cli_check_ssao(const cli_args *a);
static int cli_run_ssao(const cli_args *a);
/* meshes.c */
static void cli_lk_defaults(cli_args *a);
static int cli_xyz(const char *f, const char *v, double out[3]);
static int cli_size(const char *f, const char *v, int *width, int *height);
static int cli_set_lk(cli_args *a, const char *f, const char *v);
static int cli_check_lk(const cli_args *a);
static int cli_set_vf(cli_args *a, const char *f, const char *v);
static int cli_check_vf(const cli_args *a);
static void cli_volgi_defaults(cli_args *a);
static int cli_volgi_reals(const char *s, size_t len, double *out, int min, int max);
static int cli_volgi_light(cli_args *a, const char *v);
static int cli_set_volgi(cli_args *a, const char *f, const char *v);
static int cli_check_volgi(const cli_args *a);
static int cli_check_voxelize(const cli_args *a);
static int cli_run_voxelize(const cli_args *a);
static int cli_run_meshao(const cli_args *a);
static int cli_vf_build(const cli_args *a);
static int cli_vf_ao(const cli_args *a);
static int cli_run_visfield(const cli_args *a);
static int cli_run_volgi(const cli_args *a);
/* split.c */
static unsigned long long cli_fingerprint(const float *v, size_t n);
static int cli_partial_tag(const cli_args *a, const hfvis_grid *grid, const hfvis_sweep_options *o,
                           const hfvis_env *env, char *tag);
static int cli_run_partial(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts,
                           cli_progress_state *prog, const hfvis_env *env);
static int cli_tag_value(const char *tag, const char *key, char *out, size_t cap);
static void cli_tag_first_difference(const char *a, const char *b, char *out, size_t cap);
static int cli_tag_real(const char *tag, const char *key, double *v);
static void cli_geo_encode(const ex_georef *g, cli_geo_bytes *o);
static int cli_geo_decode(const char *text, ex_georef *g);
static const char *cli_tag_geo(const char *tag);
static int cli_geo_decode_token(const char *v, ex_georef *g);
static const char *cli_geo_difference(const char *a, const char *b);
static int cli_sum_load(const char *path, hfvis_partial *p, cli_part *m);
static int cli_sum_check(const char *path, int cmd, const hfvis_partial *p);
static int cli_sum(int argc, char **argv);
static int cli_sum_parts(int argc, char **argv, const char **names, cli_part *meta, int *order);
/* tiles.c */
static int cli_file_id(const char *path, char *out, size_t cap);
static int cli_window_plan(const cli_args *a, ex_rio_reader *r, const char *path, double cell);
static void cli_piece_tag(const cli_args *a, const hfvis_grid *grid, const hfvis_sweep_options *o);
static int cli_range_is_top(int cmd, int fraction);
static int cli_save_piece(const cli_args *a, cli_output out);
static int cli_piece_meta(const char *path, cli_piece *p);
static const char *cli_piece_problem(const char *key);
static int cli_piece_read(const char *path, const cli_piece *m, int W, int H, float *out,
                          const ex_georef *whole, const ex_georef *ref, ex_georef *keep);
static int cli_mosaic(int argc, char **argv);
static int cli_mosaic_pieces(int argc, char **argv, const char **names);
/* solar.c */
static int cli_solar_date(const char *f, const char *v, int *y, int *m, int *d);
static long cli_solar_civil_days(int y, int m, int d, int gregorian);
static long cli_solar_day_number(int y, int m, int d);
static int cli_set_solar(cli_args *a, const char *f, const char *v);
static int cli_solar_days(const cli_args *a);
static int cli_solar_band_count(const cli_args *a);
static int cli_solar_labels_of_tag(const char *tag, int bands, char (**names)[16], const char ***ptrs,
                                   const char **unit);
static int cli_check_solar(const cli_args *a);
static int cli_run_solar(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts);
/* main.c */
static int cli_commands_complete(void);

#endif /* HFVIS_CLI_H */
