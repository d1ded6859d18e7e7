/* hfvis_cli.c - the `hfvis` command-line tool (DESIGN.md §4): horizon maps, sky-view factor,
 * uniform-sky light, sun shadows, environment light and normals of PGM/PFM height fields.
 * Every file is read and written through the library's codecs (hfvis_image_load, hfvis_*_save),
 * so the tool exercises exactly what a vendoring user gets. Errors: one line
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
#if defined(__unix__) || (defined(__APPLE__) && defined(__MACH__))
#include <unistd.h>
#define CLI_HAVE_ISATTY 1
#endif
#include "common.h"

#define CLI_PI 3.14159265358979323846
#define CLI_FLT_MAX ((double)FLT_MAX)                 /* largest value a float flag may take */
#define CLI_MAX_DIRS 65536                        /* --dirs upper bound */
#define CLI_HORIZON_MAX_VALUES HFVIS_IMAGE_MAX_VALUES /* K*W*H limit of `horizon` (2^28 floats, 1 GiB) */
#define CLI_EXIT_ERROR 1
#define CLI_EXIT_USAGE 2
#define CLI_RUN (-1)                              /* parse_args: go on and run the command */

enum { CMD_HORIZON, CMD_SKYVIEW, CMD_SKY, CMD_SHADOW, CMD_LIGHT, CMD_NORMALS, CMD_COUNT };
static const char *const cli_cmd_names[CMD_COUNT] = {
    "horizon", "skyview", "sky", "shadow", "light", "normals"
};

typedef struct cli_args {
    int cmd;
    const char *in, *out, *env;
    int out_pgm;
    double cell, zscale, azimuth0, nodata, range_lo, range_hi;
    double sky, albedo, sun_azimuth, sun_elevation, sun_radius;
    int dirs, border, border_cells, method;
    int compass, degrees, quiet, math;
    int has_nodata, has_range, has_sun_azimuth, has_sun_elevation;
} cli_args;

/* ------------------------------------------------------------------------------------------ */
/* help                                                                                       */
/* ------------------------------------------------------------------------------------------ */

static const char cli_usage[] =
    "usage: hfvis COMMAND IN [options] -o OUT\n"
    "       hfvis COMMAND --help\n"
    "\n"
    "Visibility and light on height fields with the line-sweep horizon algorithm of\n"
    "Timonen & Westerholm 2010. IN is a height field: PGM (P2/P5, 8 or 16 bit, raw values)\n"
    "or grey PFM (Pf). Row 0 is the north edge, x (columns) runs east, y (rows) south.\n"
    "\n"
    "commands:\n"
    "  horizon   horizon elevation angle toward K directions (K planes in one image)\n"
    "  skyview   sky-view factor 1 - (1/K) sum_k sin(max(alpha_k, 0)), in [0, 1]\n"
    "  sky       uniform-sky light, [P1] Eq. 5 (cosine-weighted and slope-aware)\n"
    "  shadow    sun visibility in [0, 1] from one exact sweep toward the sun\n"
    "  light     environment light from a lat-long PFM map\n"
    "  normals   unit surface normals (x east, y south, z up) as a 3-channel PFM\n";

static const char cli_shared_help[] =
    "\n"
    "shared options (every command accepts them and ignores those it does not use):\n"
    "  -o OUT            output file, required: *.pfm writes PFM floats, *.pgm a 16-bit PGM;\n"
    "                    a PGM of a 3-channel result stacks the channels as planes, top to bottom\n"
    "  --range LO:HI     .pgm only: the values mapped to 0 and 65535 (default per command)\n"
    "  --cell S          distance between samples, in height units (default 1)\n"
    "  --zscale Z        multiply input values by Z, non-zero (default 1)\n"
    "  --nodata V        input values equal to V are holes: no occlusion, output NaN (0 in PGM)\n"
    "  --dirs K          number of azimuth directions, 1..65536 (default 16)\n"
    "  --azimuth0 RAD    azimuth of direction 0 in radians, from east toward south (default 0);\n"
    "                    direction k is psi_k = azimuth0 + 2 pi k/K\n"
    "  --compass         direction k looks toward the compass bearing 360k/K degrees, clockwise\n"
    "                    from north (psi_k = 2 pi k/K - pi/2); --azimuth0 is then the bearing of\n"
    "                    direction 0 in radians (psi_0 = azimuth0 - pi/2)\n"
    "  --degrees         angle outputs in degrees instead of radians\n"
    "  --border MODE     open (nothing outside the grid, default), clamp (edge heights extend\n"
    "                    outward) or wrap (periodic field)\n"
    "  --border-cells N  clamp/wrap: lines start N cells outside the grid, 1..1048576\n"
    "                    (default max(width, height))\n"
    "  --quiet           no progress bar (shown on stderr only when it is a terminal)\n"
    "  -h, --help        this help; 'hfvis COMMAND --help' describes one command\n"
    "\n"
    "Options take their value as the next argument or as --option=value.\n"
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
    "Default PGM range -1.5707963:1.5707963 (-90:90 with --degrees).\n",

    "usage: hfvis skyview IN -o OUT [options]\n"
    "The sky-view factor SVF = 1 - (1/K) sum_k sin(max(alpha_k, 0)) (Zaksek et al. 2011, as RVT\n"
    "and GRASS r.skyview): 1 on open flat ground, lower in valleys. Default PGM range 0:1.\n",

    "usage: hfvis sky IN -o OUT [--sky C] [--albedo A] [options]\n"
    "Light reflected under a uniform sky of radiance C, [P1] Eq. 5: cosine-weighted and aware\n"
    "of the surface slope; an open flat receiver returns A*C (Lambertian, albedo A).\n"
    "  --sky C           sky radiance, >= 0 (default 1)\n"
    "  --albedo A        surface albedo, >= 0 (default 1)\n"
    "Default PGM range 0:A*C (0:1 if A*C is 0).\n",

    "usage: hfvis shadow IN --sun-azimuth DEG --sun-elevation DEG [--sun-radius DEG] -o OUT\n"
    "Sun visibility in [0, 1] from one exact sweep toward the sun: 1 lit, 0 in shadow. The\n"
    "receiver's own tangent plane is not applied; multiply by max(n.l, 0) for shading.\n"
    "  --sun-azimuth DEG     compass bearing of the sun, degrees clockwise from north (required)\n"
    "  --math                --sun-azimuth is psi instead: degrees from east toward south\n"
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
    "Default PGM range -1:1 (the x, y and z planes stacked top to bottom).\n"
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

/* hfvis_progress_fn: "\r<command> [#####.....] done/total" on stderr. */
static void cli_progress(void *user, int done, int total)
{
    enum { BAR = 32 };
    char bar[BAR + 1];
    int i, fill = total > 0 ? (int)((long long)done * BAR / total) : BAR;
    for (i = 0; i < BAR; i++) bar[i] = i < fill ? '#' : '.';
    bar[BAR] = '\0';
    fprintf(stderr, "\r%s [%s] %d/%d", (const char *)user, bar, done, total);
    cli_bar_open = done < total;
    if (!cli_bar_open) fputc('\n', stderr);
    fflush(stderr);
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

#define CLI_ALL ((1u << CMD_COUNT) - 1u)
#define CLI_ONLY(c) (1u << (c))
typedef struct cli_flag { const char *name; int has_value; unsigned commands; } cli_flag;
static const cli_flag cli_flags[] = {
    { "-o", 1, CLI_ALL },           { "--range", 1, CLI_ALL },       { "--cell", 1, CLI_ALL },
    { "--zscale", 1, CLI_ALL },     { "--nodata", 1, CLI_ALL },      { "--dirs", 1, CLI_ALL },
    { "--azimuth0", 1, CLI_ALL },   { "--compass", 0, CLI_ALL },     { "--degrees", 0, CLI_ALL },
    { "--border", 1, CLI_ALL },     { "--border-cells", 1, CLI_ALL }, { "--quiet", 0, CLI_ALL },
    { "--sky", 1, CLI_ONLY(CMD_SKY) },
    { "--albedo", 1, CLI_ONLY(CMD_SKY) | CLI_ONLY(CMD_LIGHT) },
    { "--sun-azimuth", 1, CLI_ONLY(CMD_SHADOW) }, { "--sun-elevation", 1, CLI_ONLY(CMD_SHADOW) },
    { "--sun-radius", 1, CLI_ONLY(CMD_SHADOW) },  { "--math", 0, CLI_ONLY(CMD_SHADOW) },
    { "--env", 1, CLI_ONLY(CMD_LIGHT) },          { "--method", 1, CLI_ONLY(CMD_LIGHT) }
};

/* Apply one recognised flag; returns 0 or CLI_EXIT_USAGE (message printed). */
static int cli_set(cli_args *a, const char *f, const char *v)
{
    if (!strcmp(f, "-o")) {
        if (cli_ends_with(v, ".pfm")) a->out_pgm = 0;
        else if (cli_ends_with(v, ".pgm")) a->out_pgm = 1;
        else return cli_error(CLI_EXIT_USAGE, v, "unknown output type (use a .pfm or .pgm name)");
        a->out = v;
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
    if (!strcmp(f, "--cell")) return cli_real(f, v, 0.0, 1, DBL_MAX, "a number > 0", &a->cell);
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
    if (!strcmp(f, "--dirs")) return cli_int(f, v, 1, CLI_MAX_DIRS, "an integer 1..65536", &a->dirs);
    if (!strcmp(f, "--azimuth0"))
        return cli_real(f, v, -DBL_MAX, 0, DBL_MAX, "a finite angle in radians", &a->azimuth0);
    if (!strcmp(f, "--compass")) { a->compass = 1; return 0; }
    if (!strcmp(f, "--degrees")) { a->degrees = 1; return 0; }
    if (!strcmp(f, "--quiet")) { a->quiet = 1; return 0; }
    if (!strcmp(f, "--math")) { a->math = 1; return 0; }
    if (!strcmp(f, "--border")) {
        if (!strcmp(v, "open")) a->border = HFVIS_BORDER_OPEN;
        else if (!strcmp(v, "clamp")) a->border = HFVIS_BORDER_CLAMP;
        else if (!strcmp(v, "wrap")) a->border = HFVIS_BORDER_WRAP;
        else return cli_error(CLI_EXIT_USAGE, f, "expected open, clamp or wrap, got '%s'", v);
        return 0;
    }
    if (!strcmp(f, "--border-cells"))
        return cli_int(f, v, 1, HFVIS_IMAGE_MAX_DIM, "an integer 1..1048576", &a->border_cells);
    if (!strcmp(f, "--sky")) return cli_real(f, v, 0.0, 0, CLI_FLT_MAX, "a radiance >= 0", &a->sky);
    if (!strcmp(f, "--albedo")) return cli_real(f, v, 0.0, 0, CLI_FLT_MAX, "an albedo >= 0", &a->albedo);
    if (!strcmp(f, "--sun-azimuth")) {
        a->has_sun_azimuth = 1;
        return cli_real(f, v, -DBL_MAX, 0, DBL_MAX, "a finite angle in degrees", &a->sun_azimuth);
    }
    if (!strcmp(f, "--sun-elevation")) {
        a->has_sun_elevation = 1;
        return cli_real(f, v, -90.0, 0, 90.0, "degrees in -90..90", &a->sun_elevation);
    }
    if (!strcmp(f, "--sun-radius"))
        return cli_real(f, v, 0.0, 0, 90.0, "degrees in 0..90", &a->sun_radius);
    if (!strcmp(f, "--env")) { a->env = v; return 0; }
    /* --method */
    if (!strcmp(v, "prefix")) a->method = HFVIS_ENV_PREFIX;
    else if (!strcmp(v, "lp")) a->method = HFVIS_ENV_LP_TABLE;
    else return cli_error(CLI_EXIT_USAGE, f, "expected prefix or lp, got '%s'", v);
    return 0;
}

/* Returns CLI_RUN, or the exit status after printing help (0) or a usage error (2). */
static int cli_parse(int argc, char **argv, cli_args *a)
{
    int i, c, positional_only = 0;
    memset(a, 0, sizeof *a);
    a->cell = 1.0; a->zscale = 1.0; a->dirs = 16; a->sky = 1.0; a->albedo = 1.0;
    a->border = HFVIS_BORDER_OPEN; a->method = HFVIS_ENV_PREFIX;
    if (argc < 2) return cli_error(CLI_EXIT_USAGE, "usage", "missing COMMAND (try 'hfvis --help')");
    if (!strcmp(argv[1], "-h") || !strcmp(argv[1], "--help") || !strcmp(argv[1], "help")) {
        if (argc > 2 && strcmp(argv[1], "help") == 0) {
            for (c = 0; c < CMD_COUNT; c++)
                if (!strcmp(argv[2], cli_cmd_names[c])) {
                    printf("%s%s", cli_cmd_help[c], cli_shared_help);
                    return 0;
                }
            return cli_error(CLI_EXIT_USAGE, argv[2], "unknown command (try 'hfvis --help')");
        }
        printf("%s%s", cli_usage, cli_shared_help);
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
            printf("%s%s", cli_cmd_help[a->cmd], cli_shared_help);
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
    if (!a->in) return cli_error(CLI_EXIT_USAGE, cli_cmd_names[a->cmd], "missing input file IN");
    if (!a->out) return cli_error(CLI_EXIT_USAGE, cli_cmd_names[a->cmd], "missing -o OUT");
    if (a->has_range && !a->out_pgm)
        return cli_error(CLI_EXIT_USAGE, "--range", "applies only to .pgm output");
    if (a->cmd == CMD_SHADOW && !a->has_sun_azimuth)
        return cli_error(CLI_EXIT_USAGE, "shadow", "missing --sun-azimuth DEG");
    if (a->cmd == CMD_SHADOW && !a->has_sun_elevation)
        return cli_error(CLI_EXIT_USAGE, "shadow", "missing --sun-elevation DEG");
    if (a->cmd == CMD_LIGHT && !a->env)
        return cli_error(CLI_EXIT_USAGE, "light", "missing --env ENV.pfm");
    return CLI_RUN;
}

/* ------------------------------------------------------------------------------------------ */
/* running a command                                                                          */
/* ------------------------------------------------------------------------------------------ */

/* Load IN as a one-channel height field; --nodata values become NaN, the rest are scaled. */
static int cli_load_heights(const cli_args *a, float **z, int *w, int *h)
{
    hfvis_image_info info;
    float *px = NULL, zscale = (float)a->zscale, nodata = (float)a->nodata;
    size_t i, n;
    hfvis_status s;
    errno = 0;
    s = hfvis_image_load(a->in, NULL, &px, &info);
    if (s != HFVIS_OK) return cli_status(a->in, s, errno);
    if (info.channels != 1) {
        hfvis_free(NULL, px);
        return cli_error(CLI_EXIT_ERROR, a->in, "a height field has one channel, this image has %d",
                         info.channels);
    }
    n = (size_t)info.width * (size_t)info.height; /* <= HFVIS_IMAGE_MAX_VALUES (decoder limit) */
    for (i = 0; i < n; i++) {
        if (a->has_nodata && px[i] == nodata) px[i] = (float)NAN;
        else px[i] *= zscale;
    }
    *z = px; *w = info.width; *h = info.height;
    return 0;
}

/* Allocate count floats, count = a*b*c with overflow check. */
static float *cli_alloc(size_t a, size_t b, size_t c)
{
    if (a == 0 || b == 0 || c == 0 || a > SIZE_MAX / b || a * b > SIZE_MAX / c ||
        a * b * c > SIZE_MAX / sizeof(float))
        return NULL;
    return (float *)malloc(a * b * c * sizeof(float));
}

/* Write OUT: PFM with its channels, or a 16-bit PGM with the channel planes stacked. */
static int cli_save(const cli_args *a, const float *px, int w, int h, int channels, double lo,
                    double hi)
{
    hfvis_status s;
    errno = 0;
    if (!a->out_pgm) {
        s = hfvis_pfm_save(a->out, px, w, h, channels, w);
    } else {
        if (a->has_range) { lo = a->range_lo; hi = a->range_hi; }
        if (channels == 1) {
            s = hfvis_pgm_save(a->out, px, w, h, w, (float)lo, (float)hi, 65535);
        } else {
            size_t n = (size_t)w * (size_t)h, i;
            int c;
            float *planes = cli_alloc(n, (size_t)channels, 1);
            if (!planes) return cli_status(a->out, HFVIS_ERR_OUT_OF_MEMORY, 0);
            for (c = 0; c < channels; c++)
                for (i = 0; i < n; i++) planes[(size_t)c * n + i] = px[i * (size_t)channels + (size_t)c];
            if ((long long)h * channels > INT_MAX) s = HFVIS_ERR_LIMIT;
            else s = hfvis_pgm_save(a->out, planes, w, h * channels, w, (float)lo, (float)hi, 65535);
            free(planes);
        }
    }
    if (s != HFVIS_OK) return cli_status(a->out, s, errno);
    return 0;
}

static int cli_run(const cli_args *a)
{
    const char *cmd = cli_cmd_names[a->cmd];
    char label[16];
    float *z = NULL, *out = NULL, *env_px = NULL;
    int w = 0, h = 0, rc, channels = 1, planes = 1;
    double lo = 0.0, hi = 1.0;
    hfvis_grid grid;
    hfvis_sweep_options opts = hfvis_sweep_options_default();
    hfvis_env env;
    hfvis_status s = HFVIS_OK;

    memset(&env, 0, sizeof env);
    if ((rc = cli_load_heights(a, &z, &w, &h)) != 0) return rc;
    grid.z = z; grid.width = w; grid.height = h; grid.stride = w; grid.cell_size = a->cell;
    opts.border = (hfvis_border)a->border;
    opts.border_cells = a->border_cells;
    opts.azimuth0_rad = a->compass ? a->azimuth0 - CLI_PI / 2.0 : a->azimuth0;
    if (!a->quiet && cli_stderr_is_terminal()) {
        strcpy(label, cmd); /* a mutable copy: progress_user is void * */
        opts.progress = cli_progress;
        opts.progress_user = label;
    }
    rc = 0;
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
        hfvis_image_info info;
        errno = 0;
        s = hfvis_image_load(a->env, NULL, &env_px, &info);
        if (s != HFVIS_OK) { rc = cli_status(a->env, s, errno); goto done; }
        env.radiance = env_px; env.n_theta = info.height; env.n_phi = info.width;
        env.channels = info.channels;
        channels = info.channels;
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
        if (s == HFVIS_OK) {
            size_t i, n = (size_t)w * (size_t)h * (size_t)channels;
            double top = 0.0;
            for (i = 0; i < n; i++)
                if (isfinite(out[i]) && (double)out[i] > top) top = (double)out[i];
            if ((float)top > 0.0f) hi = top;
        }
        break;
    }
    default: /* CMD_NORMALS */
        s = hfvis_normals_compute(&grid, out);
        break;
    }
    if (s != HFVIS_OK) { rc = cli_status(cmd, s, 0); goto done; }
    rc = cli_save(a, out, w, h * planes, channels, lo, hi);
done:
    free(out);
    hfvis_free(NULL, env_px);
    hfvis_free(NULL, z);
    return rc;
}

int main(int argc, char **argv)
{
    cli_args a;
    int rc = cli_parse(argc, argv, &a);
    if (rc != CLI_RUN) return rc;
    return cli_run(&a);
}
