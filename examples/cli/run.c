/* run.c - running a height-field or image command: the cost estimate and --max-memory check,
 * the halo and window size of tiled runs, loading the heights, and cli_run, which dispatches a
 * parsed command to its family. May call: every command family, write.c, gis.c, tiles.c, split.c,
 * progress.c. */

/* The estimates: one per command row (main.c, cli_commands' estimate column), of a run on a w x h
 * input (height fields, ssao) or from its flags (meshes, volumes: w = h = 0), with channels the
 * output's channels. A model of the allocations, not a bound on them (the file buffers of the
 * codecs come on top for a moment). */
static cli_cost cli_cost_of(double bytes, double work, const char *unit)
{
    cli_cost c;
    c.bytes = bytes, c.work = work, c.unit = unit;
    return c;
}

/* The sweep commands: input, output (planes of one channel or channels), the sweep's lattice
 * (about min(W^2 + H^2, (W + H)^2/2) nodes of 8-byte heights, 12-byte normals and 8 bytes a
 * lattice channel ch), the grid accumulator, and bytes more per cell (gi's pyramids) and per
 * lattice node (the [P2] hull tree's), 8 bytes a cell with --exact-near (the cells' twists); the
 * work is K sweeps over the lattice. */
static cli_cost cli_sweep_cost(const cli_args *a, int w, int h, double out, double ch, double cell_bytes,
                               double node_bytes)
{
    double n = (double)w * (double)h, W = (double)w, H = (double)h, K = (double)a->dirs, lat;
    double diag2 = W * W + H * H, thin = (W + H) * (W + H) / 2.0;
    cli_cost c = cli_cost_of(n * cell_bytes, 0.0, "lattice nodes swept");
    lat = diag2 < thin ? diag2 : thin;
    c.bytes += n * 4.0 + n * 4.0 * out;                                 /* in, out */
    c.bytes += lat * (8.0 + 12.0 + 8.0 * ch) + n * (12.0 + 8.0 * ch);   /* sweep */
    if (node_bytes > 0.0) c.bytes += lat * node_bytes;
    if (a->exact && a->exact_near > 0) c.bytes += n * 8.0; /* the near field's twist per cell */
    c.work = K * (n + lat / 4.0);
    return c;
}
/* every sweep command but these below: one output of the channels, a lattice of as many */
static cli_cost cli_estimate_sweep(const cli_args *a, int w, int h, int channels)
{
    return cli_sweep_cost(a, w, h, (double)channels, (double)channels, 0.0, 0.0);
}
/* horizon: K planes out, 4 lattice channels */
static cli_cost cli_estimate_horizon(const cli_args *a, int w, int h, int channels)
{
    (void)channels;
    return cli_sweep_cost(a, w, h, (double)a->dirs, 4.0, 0.0, 0.0);
}
/* gi: the NS09 pyramids and SH planes, 256 bytes a cell */
static cli_cost cli_estimate_gi(const cli_args *a, int w, int h, int channels)
{
    return cli_sweep_cost(a, w, h, (double)channels, (double)channels, 4.0 * 64.0, 0.0);
}
/* visibility: the hull tree; --fraction sweeps twice */
static cli_cost cli_estimate_visibility(const cli_args *a, int w, int h, int channels)
{
    cli_cost c = cli_sweep_cost(a, w, h, (double)channels, (double)channels, 0.0, 8.0 * (double)channels);
    if (a->fraction) c.work *= 2.0;
    return c;
}
/* indirect: the hull tree, one gather per bounce and the direct light */
static cli_cost cli_estimate_indirect(const cli_args *a, int w, int h, int channels)
{
    cli_cost c = cli_sweep_cost(a, w, h, (double)channels, (double)channels, 0.0, 8.0 * (double)channels);
    c.work *= (double)(a->bounces + 1);
    return c;
}
/* solar (hfvis.h, hfvis_solar_irradiation's "Memory"; docs/solar.md): per cell the heights, the
 * map of K directions (64 unless --dirs), its sample-major copy only where the sector sums or
 * the step loop read one (a period of --start/--end, a Linke map; a day's path reads the map as
 * made), 120 bytes of state, 4 doubles of sums per band, 4 bytes per band of each output (-o,
 * --beam, --diffuse, --reflected, --sun-hours), the per-cell sites (16 bytes) and the Linke and
 * albedo maps; per run the sector sums' steps (about 350 bytes per step: 12 MB a year)
 * and the per-cell sites' hourly table (1 KB per day); the work, the map's sweeps. */
static cli_cost cli_estimate_solar(const cli_args *a, int w, int h, int channels)
{
    double n = (double)w * (double)h, K = a->has_dirs ? (double)a->dirs : 64.0;
    double copy = a->sol_has_end || a->sol_linke_map ? 4.0 * K : 0.0;
    double bands = (double)cli_solar_band_count(a), days = (double)cli_solar_days(a), outs = 0.0, cell, run = 0.0;
    int k;
    (void)channels;
    if (bands < 1.0) bands = 1.0; /* dates the check refuses: never run */
    if (days < 1.0) days = 1.0;
    if (a->out) outs += 1.0;
    for (k = 0; k < 4; k++)
        if (a->sol_out[k]) outs += 1.0;
    cell = 4.0 + 4.0 * K + copy + 120.0 + 32.0 * bands + 4.0 * bands * outs;
    if (!a->sol_has_lat) cell += 16.0, run += 1024.0 * days;
    if (a->sol_linke_map) cell += 4.0;
    if (a->albedo_map) cell += 4.0;
    if (a->sol_has_end) run += 350.0 * days * 24.0 / (a->sol_step > 0.0 ? a->sol_step : 0.25);
    return cli_cost_of(n * cell + run, K * 16.0 * n, "ray crossings");
}
/* viewshed: the grid and its output; one line of sight per edge cell */
static cli_cost cli_estimate_viewshed(const cli_args *a, int w, int h, int channels)
{
    double n = (double)w * (double)h, W = (double)w, H = (double)h;
    (void)a, (void)channels;
    return cli_cost_of(n * 8.0, (W + H) * (W > H ? W : H), "line-of-sight steps");
}
/* ssao: depth and output; K directions march up to max(W, H) / 4 samples */
static cli_cost cli_estimate_ssao(const cli_args *a, int w, int h, int channels)
{
    double n = (double)w * (double)h, W = (double)w, H = (double)h, K = (double)a->dirs;
    (void)channels;
    return cli_cost_of(n * 8.0, n * (a->has_dirs ? K : 16.0) * (W > H ? W : H) / 4.0, "depth samples");
}
/* voxelize: one byte a voxel (of the grid grown by one layer on each axis for --mode surface) */
static cli_cost cli_estimate_voxelize(const cli_args *a, int w, int h, int channels)
{
    double v = pow((double)a->res + (a->vox_mode == VOX_SURFACE ? 1.0 : 0.0), 3.0);
    (void)w, (void)h, (void)channels;
    return cli_cost_of(v, v, "voxels");
}
/* volgi (hfvis_volgi_render's "Memory"): per voxel of the res^3 bound the geometry (40 bytes), the P
 * and A volumes (96) and the propagation's scratch (48, + 24 normalized); per pixel the G-buffer
 * (24), the image and its encoding (12 + 12); --res defaults to the library's 32 */
static cli_cost cli_estimate_volgi(const cli_args *a, int w, int h, int channels)
{
    double v = pow((double)(a->res ? a->res : HFVIS_VOLGI_DEFAULT_RESOLUTION), 3.0);
    double per_voxel = 40.0 + 96.0 + 48.0 + (a->vg_transfer == HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED ? 24.0 : 0.0);
    (void)w, (void)h, (void)channels;
    return cli_cost_of(v * per_voxel + (double)a->vg_width * (double)a->vg_height * 48.0,
                       v * (double)a->iterations, "voxel updates");
}
/* visfield: the AO image (W x H, S^2 rays a pixel), or the field's maps (hfvis_visfield_size of
 * K positions, D^2 directions; defaults 4226 and 32) twice: built, and encoded for the file */
static cli_cost cli_estimate_visfield(const cli_args *a, int w, int h, int channels)
{
    const int n = a->vf_positions ? a->vf_positions : 32, d = a->has_dirs ? a->dirs : 32; /* n: K = 2(2n^2+2n+1) */
    const double K = (double)hfvis_visfield_position_count(n), D = (double)d;
    const size_t maps = hfvis_visfield_size(n, d, (hfvis_visfield_format)a->vf_format);
    const double field = maps ? (double)maps : K * D * D * 4.0; /* 0: out of range, or past size_t */
    (void)w, (void)h, (void)channels;
    if (a->vf_ao) {
        const double W = a->vf_has_size ? (double)a->vg_width : 256.0, H = a->vf_has_size ? (double)a->vg_height : 256.0;
        const double S = (double)(a->vf_rays ? a->vf_rays : 16);
        return cli_cost_of(W * H * 4.0 * 2.0, W * H * S * S, "rays");
    }
    return cli_cost_of(field * 2.0, K * D * D, "rays");
}
/* meshao: the image's buffers, its rays */
static cli_cost cli_estimate_meshao(const cli_args *a, int w, int h, int channels)
{
    (void)w, (void)h, (void)channels;
    return cli_cost_of((double)a->lk_width * (double)a->lk_height * 16.0,
                       (double)a->lk_width * (double)a->lk_height * (double)(a->lk_rays ? a->lk_rays : 64), "rays");
}

/* The band descriptions of the outputs whose bands are fixed: normals' three axes (hfvis.h
 * "Grids") and openness --both's two planes; NULL for the others. The whole run, its pieces and
 * their mosaic name them alike. */
static const char *const *cli_fixed_band_names(int cmd, int bands)
{
    static const char *const axes[3] = { "x (east)", "y (south)", "z (up)" };
    static const char *const both[2] = { "positive openness", "negative openness" };
    if (cmd == CMD_NORMALS && bands == 3) return axes;
    if (cmd == CMD_OPENNESS && bands == 2) return both;
    return NULL;
}

/* The channels of a height-field command's output, for the estimate before anything is loaded:
 * light has ENV's, indirect the most of ENV, --albedo-map and --emission (PGM, PFM or a
 * raster's bands: their headers only are read), normals 3, the rest 1. A header that cannot be
 * read counts 1; the load reports it. */
static int cli_out_channels(const cli_args *a)
{
    const char *maps[3] = {a->env, NULL, NULL};
    int channels = a->cmd == CMD_NORMALS ? 3 : 1, i;
    if (a->cmd != CMD_LIGHT && a->cmd != CMD_INDIRECT) return channels;
    if (a->cmd == CMD_INDIRECT) maps[1] = a->albedo_map, maps[2] = a->emission;
    for (i = 0; i < 3; i++) {
        ex_rio_reader r;
        if (!maps[i] || cli_open_raster(&r, maps[i]) != 0) continue;
        if (r.bands > channels) channels = r.bands;
        ex_rio_close(&r);
    }
    return channels;
}

/* Print the estimate with the progress bar or the --progress lines, and refuse a run past
 * --max-memory (0 = none), suggesting a window size when the run can be tiled. */
static int cli_check_cost(const cli_args *a, int w, int h, int channels)
{
    const char *cmd = cli_commands[a->cmd].name;
    cli_cost c = cli_commands[a->cmd].estimate(a, w, h, channels);
    a->run->threads = a->threads;
    if (a->threads_auto && a->threads > 1 && a->max_memory > 0.0 && c.bytes > 0.0 &&
        c.bytes * a->threads > a->max_memory) /* a thread's scratch is at most one run's estimate */
        a->run->threads = c.bytes * 2.0 > a->max_memory ? 1 : (int)(a->max_memory / c.bytes);
    if (!a->quiet && (a->progress_lines || cli_stderr_is_terminal())) {
        fprintf(stderr, "%s: estimate %.3g MiB, %.3g %s", cmd, c.bytes / 1048576.0, c.work, c.unit);
        if (CLI_ONLY(a->cmd) & CLI_THREADED)
            fprintf(stderr, ", %d thread%s", a->run->threads, a->run->threads == 1 ? "" : "s");
        fputc('\n', stderr);
    }
    if (a->max_memory > 0.0 && c.bytes > a->max_memory) {
        char hint[200] = "";
        if (a->run->win.halo >= 0) { /* tiles: the largest square window whose grid (+ halo) fits */
            const cli_window *win = &a->run->win;
            int ww = win->active ? win->ext_w : w, hh = win->active ? win->ext_h : h;
            int side = cli_window_side(a, a->run->win.halo, ww, hh, channels);
            if (side > 0)
                snprintf(hint, sizeof hint, "; windows of %d x %d cells fit (halo %d; --window X0,Y0,%d,%d, "
                         "examples/tiles.sh)", side, side, a->run->win.halo, side, side);
            else
                snprintf(hint, sizeof hint, "; not even a 1-cell window with its halo of %d cells fits: "
                         "lower --max-distance", a->run->win.halo);
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
 * each axis, fits --max-memory by the command's estimate; 0 if none does. */
static int cli_window_side(const cli_args *a, int halo, int w, int h, int channels)
{
    int lo = 0, hi = w > h ? w : h;
    while (lo < hi) {
        int mid = lo + (hi - lo + 1) / 2;
        double gw = (double)mid + 2.0 * halo, gh = gw;
        if (gw > w) gw = w;
        if (gh > h) gh = h;
        if (cli_commands[a->cmd].estimate(a, (int)gw, (int)gh, channels).bytes <= a->max_memory) lo = mid;
        else hi = mid - 1;
    }
    return lo;
}

/* A binary PFM ("Pf" or "PF"): read by rows over the threads (cli_load_raster), where the
 * library's hfvis_image_load takes the file whole and then its rows. */
static int cli_is_pfm(const char *path)
{
    unsigned char m[2];
    FILE *f = fopen(path, "rb");
    int pfm = f && fread(m, 1, 2, f) == 2 && m[0] == 'P' && (m[1] == 'f' || m[1] == 'F');
    if (f) fclose(f);
    return pfm;
}

/* The heights' pass of cli_load_heights over the threads, by blocks of CLI_HEIGHTS_BLOCK values:
 * --nodata values and non-finite ones become holes (NaN), the others are scaled by --zscale. */
#define CLI_HEIGHTS_BLOCK ((size_t)1 << 18) /* values: 1 MB of floats */
typedef struct cli_heights {
    float *px;
    size_t n;
    float zscale, nodata;
    uint32_t has_nodata;
    float *top; /* per block: the largest |scaled height|, +inf if one overflows (the block left as read) */
} cli_heights;

/* 1 for a hole: a value that is not finite, or --nodata's. */
static uint32_t cli_height_hole(float v, float nodata, uint32_t has_nodata)
{
    uint32_t u;
    memcpy(&u, &v, sizeof u);
    return (uint32_t)((u & 0x7fffffffu) >= 0x7f800000u) | (has_nodata & (uint32_t)(v == nodata));
}

/* The bits of |v| (those of a non-negative float order as its value), 0 for a hole. */
static uint32_t cli_height_magnitude(float v, float nodata, uint32_t has_nodata)
{
    uint32_t u;
    memcpy(&u, &v, sizeof u);
    return u & 0x7fffffffu & (cli_height_hole(v, nodata, has_nodata) - 1u);
}

/* v * zscale, or NaN for a hole, without a branch. */
static float cli_height_scaled(float v, float nodata, uint32_t has_nodata, float zscale)
{
    float s = v * zscale;
    uint32_t hole = cli_height_hole(v, nodata, has_nodata), u;
    memcpy(&u, &s, sizeof u);
    u = (u & (hole - 1u)) | (0x7fc00000u & (0u - hole)); /* 0x7fc00000: a quiet NaN */
    memcpy(&s, &u, sizeof u);
    return s;
}

/* Loops of a fixed count of CLI_HEIGHTS_LANE values, which gcc -O2 vectorizes, and the rest one by
 * one: the block's largest magnitude, then the stores. The largest scaled magnitude is
 * fl(max |v| |zscale|), the largest of the fl(|v| |zscale|): rounding is monotone. */
#define CLI_HEIGHTS_LANE 64
static int cli_heights_block(void *ctx, size_t b)
{
    const cli_heights *j = (const cli_heights *)ctx;
    float *p = j->px + b * CLI_HEIGHTS_BLOCK, big;
    const float zs = j->zscale, nd = j->nodata;
    const size_t n = j->n - b * CLI_HEIGHTS_BLOCK < CLI_HEIGHTS_BLOCK ? j->n - b * CLI_HEIGHTS_BLOCK : CLI_HEIGHTS_BLOCK;
    const uint32_t use_nd = j->has_nodata ? 1u : 0u;
    uint32_t top = 0, m;
    size_t i, k;
    for (i = 0; i + CLI_HEIGHTS_LANE <= n; i += CLI_HEIGHTS_LANE) {
        const float *q = p + i;
        for (k = 0; k < CLI_HEIGHTS_LANE; k++) {
            m = cli_height_magnitude(q[k], nd, use_nd);
            top = m > top ? m : top;
        }
    }
    for (; i < n; i++) {
        m = cli_height_magnitude(p[i], nd, use_nd);
        top = m > top ? m : top;
    }
    memcpy(&big, &top, sizeof big);
    j->top[b] = fabsf(big * zs);
    if (!(j->top[b] <= FLT_MAX)) {
        j->top[b] = HUGE_VALF;
        return 0;
    }
    for (i = 0; i + CLI_HEIGHTS_LANE <= n; i += CLI_HEIGHTS_LANE) {
        float *q = p + i;
        for (k = 0; k < CLI_HEIGHTS_LANE; k++) q[k] = cli_height_scaled(q[k], nd, use_nd, zs);
    }
    for (; i < n; i++) p[i] = cli_height_scaled(p[i], nd, use_nd, zs);
    return 0;
}

/* Load IN as a one-channel height field; --nodata values become NaN, the rest are scaled.
 * *cell: --cell, else the raster's cell size, else 1 (with a note unless --quiet). */
static int cli_load_heights(const cli_args *a, float **z, int *w, int *h, double *cell)
{
    hfvis_image_info info;
    float *px = NULL, zscale = (float)a->zscale, nodata = (float)a->nodata;
    double top = 0.0; /* largest |height| */
    size_t i, n, blocks;
    cli_heights j;
    int threads;
    hfvis_status s;
    *cell = a->cell;
    if (ex_rio_format_of(a->in) || a->run->win.active || cli_is_pfm(a->in)) {
        int rc = cli_load_raster(a, &px, w, h, cell);
        if (rc != 0) return rc;
    } else {
        if (a->band > 1)
            return cli_error(CLI_EXIT_ERROR, a->in, "--band %d: a PFM/PGM height field has one band", a->band);
        errno = 0; /* the file's bytes and the heights on huge pages (threads.c): a 4 KiB page's
                    * first touch costs 10-15 us on this project's VMs, 0.5 s for a 4096^2 load */
        s = hfvis_image_load(a->in, &cli_huge_allocator, &px, &info);
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
    j.px = px;
    j.n = n;
    j.zscale = zscale;
    j.nodata = nodata;
    j.has_nodata = a->has_nodata ? 1u : 0u;
    blocks = (n - 1) / CLI_HEIGHTS_BLOCK + 1;
    threads = cli_run_threads(a);
    if (!(j.top = (float *)malloc(blocks * sizeof *j.top))) {
        hfvis_free(NULL, px);
        return cli_status(a->in, HFVIS_ERR_OUT_OF_MEMORY, 0);
    }
    /* the blocks never fail, and a thread that cannot start leaves its blocks to the others */
    (void)cli_parallel_for(&threads, blocks, cli_heights_block, &j);
    for (i = 0; i < blocks && !(j.top[i] > FLT_MAX); i++)
        if ((double)j.top[i] > top) top = (double)j.top[i];
    free(j.top);
    if (i < blocks) { /* not a hole: refused, never silently one (block i is as read) */
        double v;
        for (i *= CLI_HEIGHTS_BLOCK; i < n && (cli_height_hole(px[i], nodata, j.has_nodata) || isfinite(px[i] * zscale));
             i++) {}
        v = i < n ? (double)px[i] : 0.0;
        hfvis_free(NULL, px);
        return cli_error(CLI_EXIT_ERROR, "--zscale", "%g times the value %g at (%lu, %lu) "
                         "exceeds the float range (3.4e38)", a->zscale, v,
                         (unsigned long)(i % (size_t)*w), (unsigned long)(i / (size_t)*w));
    }
    /* heights in cells (z / cell, in double) and their squares must stay finite */
    if (top / *cell > CLI_MAX_RELIEF || *cell < DBL_MIN) {
        hfvis_free(NULL, px);
        if (a->has_cell)
            return cli_error(CLI_EXIT_ERROR, "--cell", "%g is too small for heights up to %g: their ratio "
                             "must stay below %g (and the cell at least %g)", *cell, top, CLI_MAX_RELIEF,
                             DBL_MIN);
        return cli_error(CLI_EXIT_ERROR, a->in, "heights up to %g over cells of %g (%s): their ratio must stay "
                         "below %g; give --cell in the heights' unit or scale them with --zscale", top, *cell,
                         ex_rio_format_of(a->in) ? "the raster's cell size" : "no cell size given: 1",
                         CLI_MAX_RELIEF);
    }
    if (a->has_nodata && !a->run->geo.has_nodata) { /* --nodata is the outputs' NoData too */
        a->run->geo.has_nodata = 1;
        a->run->geo.nodata = (double)nodata;
        snprintf(a->run->geo.nodata_text, sizeof a->run->geo.nodata_text, "%.9g", (double)nodata);
    }
    *z = px;
    return 0;
}

/* Allocate count floats, count = a*b*c with overflow check. */
static float *cli_alloc(size_t a, size_t b, size_t c)
{
    if (a == 0 || b == 0 || c == 0 || a > SIZE_MAX / b || a * b > SIZE_MAX / c ||
        a * b * c > SIZE_MAX / sizeof(float))
        return NULL;
    /* zeros (a window run leaves cells unwritten), on huge pages where offered, untouched */
    return (float *)cli_huge_calloc(a * b * c * sizeof(float));
}

/* IN's size (and cell size, 0 when unknown) from its header alone, for --max-memory before
 * the heights are loaded: 1, or 0 when the header cannot be read this way (an ASCII PGM, and an
 * ASC grid, whose text is parsed whole: the load then reports or checks it, its memory bounded
 * by the file's size). */
static int cli_peek_size(const cli_args *a, int *w, int *h, double *cell)
{
    ex_rio_reader r;
    char why[256];
    if (ex_rio_format_of(a->in) == EX_RIO_ASC) return 0;
    if (cli_open_raster(&r, a->in) != 0) {
        ex_rio_close(&r);
        return 0;
    }
    *w = r.width;
    *h = r.height;
    *cell = a->has_cell ? a->cell : 0.0;
    if (!a->has_cell && r.geo.has_transform && ex_georef_cell(&r.geo, cell, why) != 0) *cell = 0.0;
    ex_rio_close(&r);
    return 1;
}

/* The height-field commands: load IN, set up the sweep options, the window and the progress,
 * then run the command (its own function for indirect, visibility, gi and the GIS products) and
 * write OUT. */
static int cli_run_heights(const cli_args *a)
{
    const char *cmd = cli_commands[a->cmd].name;
    cli_progress_state prog;
    float *z = NULL, *out = NULL, *env_px = NULL;
    int w = 0, h = 0, rc, channels = 1, planes = 1, checked = 0;
    double lo = 0.0, hi = 1.0;
    hfvis_grid grid;
    hfvis_sweep_options opts = hfvis_sweep_options_default();
    hfvis_env env;
    hfvis_status s = HFVIS_OK;

    memset(&env, 0, sizeof env);
    a->run->win.active = a->has_window;
    if (!a->run->win.active) { /* --max-memory from the header's size, before the heights are read */
        double pcell = 0.0;
        int pw, ph;
        if (cli_peek_size(a, &pw, &ph, &pcell)) {
            if (a->max_distance > 0.0 && pcell > 0.0 && a->cmd < CMD_COUNT && (CLI_ONLY(a->cmd) & CLI_SWEEP))
                a->run->win.halo = cli_halo(a, pcell);
            if ((rc = cli_check_cost(a, pw, ph, cli_out_channels(a))) != 0) return rc;
            checked = 1;
        }
    }
    if ((rc = cli_load_heights(a, &z, &w, &h, &grid.cell_size)) != 0) return rc;
    grid.z = z; grid.width = w; grid.height = h; grid.stride = w;
    opts.border = (hfvis_border)a->border;
    opts.border_cells = a->border_cells;
    opts.azimuth0_rad = a->compass ? a->azimuth0 - CLI_PI / 2.0 : a->azimuth0;
    if (a->exact && a->cmd != CMD_VIEWSHED) opts.rays = HFVIS_RAYS_EXACT;
    if (a->exact && a->cmd != CMD_VIEWSHED) opts.ray_near_cells = a->exact_near; /* flags.c checks */
    if (a->cmd != CMD_VIEWSHED) opts.max_distance = a->max_distance; /* viewshed: its own range */
    opts.alloc = &cli_huge_allocator; /* lattices and planes on huge pages where offered (threads.c) */
    if (a->run->win.active && a->cmd == CMD_OPENNESS) {
        /* openness marches --radius per receiver: the halo holds every cell a window receiver
         * reaches, and the window + halo grid's own border is the raster's wherever a march can
         * meet it, so it runs as a plain grid (the library refuses a window for it) */
        cli_piece_tag(a, &grid, &opts);
    } else if (a->run->win.active) { /* the grid is window + halo of the raster; compute the window */
        opts.origin_x = a->run->win.gx0, opts.origin_y = a->run->win.gy0;
        opts.extent_width = a->run->win.ext_w, opts.extent_height = a->run->win.ext_h;
        if (a->cmd != CMD_INDIRECT) { /* indirect's bounces need every point of the grid */
            opts.receiver_x = a->run->win.x0 - a->run->win.gx0;
            opts.receiver_y = a->run->win.y0 - a->run->win.gy0;
            opts.receiver_width = a->run->win.w, opts.receiver_height = a->run->win.h;
        }
        cli_piece_tag(a, &grid, &opts);
    } else if (a->max_distance > 0.0 && a->cmd < CMD_COUNT && (CLI_ONLY(a->cmd) & CLI_SWEEP)) {
        a->run->win.halo = cli_halo(a, grid.cell_size); /* for the window size a refusal suggests */
    }
    prog.label = cmd; prog.base = 0; prog.total = 0; prog.run = a->run;
    a->run->cells = (double)w * (double)h;
    a->run->directions = a->cmd == CMD_NORMALS || a->cmd == CMD_VIEWSHED ? 0
                         : a->cmd == CMD_SHADOW ? 1 : a->cmd == CMD_SOLAR && !a->has_dirs ? 64 : a->dirs;
    if (a->progress_lines && !a->quiet) {
        opts.progress = cli_progress_line;
        opts.progress_user = &prog;
    } else if (!a->quiet && cli_stderr_is_terminal()) {
        opts.progress = cli_progress;
        opts.progress_user = &prog;
    }
    if (!a->run->win.active && !checked && (rc = cli_check_cost(a, w, h, cli_out_channels(a))) != 0) goto done;
    if (a->has_dir_range) {
        if (a->cmd == CMD_LIGHT && (rc = cli_load_env(a->env, &env_px, &env)) != 0) goto done;
        rc = cli_run_partial(a, &grid, &opts, &prog, &env);
        goto done;
    }
    if (a->cmd == CMD_INDIRECT) { rc = cli_run_indirect(a, &grid, &opts, &prog); goto done; }
    if (a->cmd == CMD_VISIBILITY) { rc = cli_run_visibility(a, &grid, &opts, &prog); goto done; }
    if (a->cmd == CMD_GI) { rc = cli_run_gi(a, &grid, &opts, &prog); goto done; }
    if (a->cmd == CMD_SOLAR) { rc = cli_run_solar(a, &grid, &opts); goto done; }
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
        s = cli_run_threads(a) > 1 ? cli_threaded_horizon_map(&grid, a->dirs, &opts, cli_run_threads(a), NULL, out)
                           : hfvis_horizon_map(&grid, a->dirs, &opts, out);
        if (s == HFVIS_OK && a->degrees) {
            size_t i, n = (size_t)w * (size_t)h * (size_t)planes;
            for (i = 0; i < n; i++) out[i] = (float)((double)out[i] * (180.0 / CLI_PI));
            lo = -90.0; hi = 90.0;
        }
        break;
    case CMD_SKYVIEW:
        s = cli_run_threads(a) > 1 ? cli_threaded_light(CMD_SKYVIEW, &grid, a->dirs, 0.0, NULL, NULL, &opts,
                                                cli_run_threads(a), 1, out)
                           : hfvis_sky_view_factor(&grid, a->dirs, &opts, out, w);
        break;
    case CMD_SKY:
        s = cli_run_threads(a) > 1 ? cli_threaded_light(CMD_SKY, &grid, a->dirs,
                                                (double)(float)a->sky * (double)(float)a->albedo, NULL,
                                                NULL, &opts, cli_run_threads(a), 1, out)
                           : hfvis_sky_light(&grid, a->dirs, (float)a->sky, (float)a->albedo, &opts, out, w);
        if (a->sky * a->albedo <= CLI_FLT_MAX && (float)(a->sky * a->albedo) > 0.0f)
            hi = a->sky * a->albedo;
        break;
    case CMD_SHADOW: {
        double bearing_or_psi = a->math ? a->sun_azimuth : a->sun_azimuth - 90.0;
        s = cli_threaded_sun(&grid, bearing_or_psi * (CLI_PI / 180.0), a->sun_elevation * (CLI_PI / 180.0),
                             a->sun_radius * (CLI_PI / 180.0), &opts, cli_run_threads(a), out, w);
        break;
    }
    case CMD_LIGHT: {
        hfvis_env_options eopts = hfvis_env_options_default();
        eopts.method = (hfvis_env_method)a->method;
        s = cli_run_threads(a) > 1 ? cli_threaded_light(CMD_LIGHT, &grid, a->dirs, (double)(float)a->albedo, &env,
                                                &eopts, &opts, cli_run_threads(a), channels, out)
                           : hfvis_env_light(&grid, a->dirs, &env, (float)a->albedo, &opts, &eopts, out, w);
        if (s == HFVIS_OK) hi = cli_top(out, (size_t)w * (size_t)h * (size_t)channels, 1.0);
        break;
    }
    case CMD_NORMALS:
        s = hfvis_normals_compute(&grid, out);
        break;
    default: /* a command of the table whose run is this function but has no case here */
        rc = cli_error(CLI_EXIT_ERROR, cmd, "internal error: no height-field run for this command");
        goto done;
    }
    if (s != HFVIS_OK) { rc = cli_status(cmd, s, 0); goto done; }
    if ((a->cmd == CMD_SKY || a->cmd == CMD_LIGHT) &&
        (rc = cli_check_radiance(cmd, &grid, out, channels)) != 0)
        goto done;
    if (a->cmd == CMD_HORIZON) { rc = cli_horizon_finish(a, out, w, h, lo, hi); goto done; }
    {
        cli_output o = cli_output_of(out, w, h, planes, channels, lo, hi);
        o.band_names = cli_fixed_band_names(a->cmd, planes * channels);
        rc = cli_save(a, o);
    }
done:
    cli_progress_end(a->run, rc); /* a bar that fell short */
    free(out);
    hfvis_free(NULL, env_px);
    hfvis_free(NULL, z);
    return rc;
}
