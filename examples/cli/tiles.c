/* tiles.c - tiles (docs/tiles.md): a --window run plans its window and halo, writes a piece and
 * its sidecar (.tile) with the run tag and the checksum of its values; `mosaic` checks the pieces
 * and assembles them. Owns: the window of the run (cli_run_state.win). May call: progress.c, gis.c,
 * write.c, run.c's estimate, split.c's cli_fnv_value. */

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
    cli_window *v = &a->run->win;
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
    v->has_gt = g->has_transform;
    memcpy(v->raster_gt, g->gt, sizeof v->raster_gt);
    if (g->has_transform)
        snprintf(v->gt, sizeof v->gt, "%a,%a,%a,%a,%a,%a", g->gt[0], g->gt[1], g->gt[2], g->gt[3],
                 g->gt[4], g->gt[5]);
    else
        strcpy(v->gt, "none");
    if (g->has_nodata) snprintf(v->nodata, sizeof v->nodata, "%s", g->nodata_text);
    else strcpy(v->nodata, "none");
    return 0;
}


/* The run tag of a piece: every key that must match across the pieces of one run. The order
 * matters: `mosaic` names the first key that differs, so the CRS and cell size come before
 * the input's identity (a reprojected input differs in all three). Over-inclusive on purpose:
 * every value-changing flag of every tiled command, whatever the command. */
static void cli_piece_tag(const cli_args *a, const hfvis_grid *grid, const hfvis_sweep_options *o)
{
    char env_id[64] = "none", nodata_flag[40] = "none";
    cli_window *win = &a->run->win;
    if (a->env && cli_file_id(a->env, env_id, sizeof env_id) != 0) strcpy(env_id, "unreadable");
    if (a->has_nodata) snprintf(nodata_flag, sizeof nodata_flag, "%a", (double)(float)a->nodata);
    snprintf(win->tag, sizeof win->tag,
             "cmd=%s crs=%s cell=%a extent=%dx%d in=%s gt=%s band=%d nodata=%s set-nodata=%s zscale=%a "
             "max-distance=%a dirs=%d border=%d border-cells=%d azimuth0=%a rays=%s convention=%d "
             "degrees=%d svf=%d sky=%a albedo=%a sun=%a,%a,%a,%a,%d blend=%d no-shadows=%d radius=%a "
             "negative=%d fraction=%d method=%d bounces=%d output=%d env=%s "
             "solar=%d-%d-%d,%d-%d-%d,%d,%d,%a,%a,%d,%a,%d,%a,%d,%a,%a,%d,%d,%d,%d,%d,%a,%d,%d,%s",
             cli_commands[a->cmd].name, win->crs, grid->cell_size, win->ext_w, win->ext_h,
             win->in_id, win->gt, a->band ? a->band : 1, win->nodata, nodata_flag, a->zscale,
             o->max_distance, a->dirs, (int)o->border, o->border_cells, o->azimuth0_rad,
             o->rays == HFVIS_RAYS_EXACT ? "exact" : "lattice", a->convention, a->degrees, a->svf,
             a->sky, a->albedo, a->sun_azimuth, a->sun_elevation, a->sun_radius, a->sun_irradiance,
             a->has_sun_azimuth, a->blend, a->no_shadows, a->radius, a->negative, a->fraction,
             a->method, a->bounces, a->output, env_id, a->sol_y, a->sol_m, a->sol_d,
             a->sol_has_end ? a->sol_ey : 0, a->sol_has_end ? a->sol_em : 0, a->sol_has_end ? a->sol_ed : 0,
             a->sol_instant, a->sol_solar_time, a->sol_hour, a->sol_step, a->sol_has_lat, a->sol_lat,
             a->sol_has_lon, a->sol_lon, a->sol_has_offset, a->sol_offset, a->sol_linke,
             a->sol_has_linke_monthly, a->sol_bands, a->sol_horizons, a->sol_normals, a->has_dirs,
             a->sun_radius, a->has_sun_radius, a->has_albedo, a->sol_linke_map ? "map" : "none");
    {
        size_t len = strlen(win->tag);
        if (a->sol_has_zrange)
            snprintf(win->tag + len, sizeof win->tag - len, " height-range=%a,%a", a->sol_zmin, a->sol_zmax);
        else
            snprintf(win->tag + len, sizeof win->tag - len, " height-range=none");
    }
    if (a->cmd == CMD_SOLAR) { /* what a mosaic needs to name its bands (cli_solar_labels_of_tag) */
        size_t len = strlen(win->tag);
        snprintf(win->tag + len, sizeof win->tag - len, " solar-labels=%d-%d-%d,%d,%d", a->sol_y, a->sol_m,
                 a->sol_d, a->sol_instant, (int)a->sol_bands);
    }
    if (a->sol_has_linke_monthly) {
        int k;
        for (k = 0; k < 12; k++) {
            size_t len = strlen(win->tag);
            snprintf(win->tag + len, sizeof win->tag - len, "%s%a", k ? "," : " linke-monthly=",
                     a->sol_linke_monthly[k]);
        }
    }
    { /* the per-cell maps a window reads its share of: pieces of other maps do not join */
        const char *maps[3] = { a->albedo_map, a->emission, a->sol_linke_map };
        int k;
        for (k = 0; k < 3; k++) {
            char id[64] = "none";
            size_t len = strlen(win->tag);
            if (maps[k] && cli_file_id(maps[k], id, sizeof id) != 0) strcpy(id, "unreadable");
            snprintf(win->tag + len, sizeof win->tag - len, "%s%s", k ? "," : " maps=", id);
        }
    }
}

/* Commands whose default PGM range tops at the largest output value (mosaic recomputes it). */
static int cli_range_is_top(int cmd, int fraction)
{
    return cmd == CMD_LIGHT || cmd == CMD_INDIRECT || (cmd == CMD_VISIBILITY && !fraction);
}

/* A --window run's output: the window cut out of each plane of the grid's result (w x h with
 * the planes stacked), its sidecar OUT.tile (the window, the planes and channels, the default
 * range, the checksum of the values, the run tag), then the piece OUT with the georeference moved
 * to the window. Each is written to a temporary name and renamed; the sidecar goes first, so a
 * failure leaves OUT as it was, and one between the two renames leaves a sidecar whose checksum
 * the old piece does not match: `mosaic` refuses that pair, as it refuses an old piece beside the
 * sidecar of another run. */
static int cli_save_piece(const cli_args *a, cli_output out)
{
    const cli_window v = a->run->win;
    const float *px = out.px;
    const int w = out.w, planes = out.planes, channels = out.channels;
    const double lo = out.lo, hi = out.hi;
    const size_t row = (size_t)v.w * (size_t)channels;
    float *cut = cli_alloc((size_t)v.w * (size_t)v.h, (size_t)planes, (size_t)channels);
    const size_t n = (size_t)v.w * (size_t)v.h * (size_t)planes * (size_t)channels;
    char *side = NULL, *text = NULL, range[96];
    unsigned long long sum = CLI_FNV_OFFSET;
    size_t len, i;
    int p, y, rc;
    hfvis_status s;
    if (!cut) return cli_status(a->out, HFVIS_ERR_OUT_OF_MEMORY, 0);
    for (p = 0; p < planes; p++)
        for (y = 0; y < v.h; y++)
            memcpy(cut + ((size_t)p * (size_t)v.h + (size_t)y) * row,
                   px + (((size_t)p * (size_t)v.gh + (size_t)(v.y0 - v.gy0 + y)) * (size_t)w +
                         (size_t)(v.x0 - v.gx0)) * (size_t)channels, row * sizeof(float));
    for (i = 0; i < n; i++) sum = cli_fnv_value(sum, cut[i]);
    if (cli_range_is_top(a->cmd, a->fraction)) strcpy(range, "top");
    else snprintf(range, sizeof range, "%a:%a", lo, hi);
    len = strlen(a->out) + sizeof CLI_PIECE_SIDECAR;
    side = (char *)malloc(len);
    text = (char *)malloc(CLI_PIECE_TAG_MAX + 256);
    if (!side || !text) {
        free(side);
        free(text);
        free(cut);
        return cli_status(a->out, HFVIS_ERR_OUT_OF_MEMORY, 0);
    }
    snprintf(side, len, "%s%s", a->out, CLI_PIECE_SIDECAR);
    snprintf(text, CLI_PIECE_TAG_MAX + 256, CLI_PIECE_MAGIC "window=%d,%d,%d,%d planes=%d channels=%d "
             "range=%s values=%016llx\n%s\n", v.x0, v.y0, v.w, v.h, planes, channels, range, sum, v.tag);
    errno = 0;
    s = cli_write(side, (unsigned char *)text, strlen(text), HFVIS_OK); /* frees text */
    rc = s == HFVIS_OK ? 0 : cli_status(side, s, errno);
    free(side);
    if (rc == 0) {
        a->run->win.active = 0; /* write it as an ordinary output of v.w x v.h cells */
        cli_output piece = cli_output_of(cut, v.w, v.h, planes, channels, lo, hi);
        piece.band_names = out.band_names, piece.unit = out.unit; /* the whole run's labels */
        piece.meta = out.meta, piece.n_meta = out.n_meta;
        rc = cli_save(a, piece);
    }
    free(cut);
    return rc;
}


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
        ok = sscanf(line2 + 1, "window=%d,%d,%d,%d planes=%d channels=%d range=%95s values=%llx", &p->x0,
                    &p->y0, &p->w, &p->h, &p->planes, &p->channels, p->range, &p->values) == 8 &&
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

/* The refusal of a piece whose values are not the ones its sidecar records. */
static int cli_piece_stale(const char *path)
{
    return cli_error(CLI_EXIT_ERROR, path, "its values differ from those its sidecar %s%s records (an edited "
                     "or swapped piece, or a sidecar of another run): rerun this window", path, CLI_PIECE_SIDECAR);
}

/* The checksum of piece m's values once read into the mosaic out (cli_save_piece's order). */
static unsigned long long cli_piece_sum(const cli_piece *m, int W, int H, const float *out)
{
    const size_t C = (size_t)m->channels, row = (size_t)m->w * C;
    unsigned long long sum = CLI_FNV_OFFSET;
    size_t i;
    int p, y;
    for (p = 0; p < m->planes; p++)
        for (y = 0; y < m->h; y++) {
            const float *src = out + (((size_t)p * (size_t)H + (size_t)(m->y0 + y)) * (size_t)W + (size_t)m->x0) * C;
            for (i = 0; i < row; i++) sum = cli_fnv_value(sum, src[i]);
        }
    return sum;
}

/* Read piece path (of sidecar m) into the mosaic out (W x H cells, planes stacked, channels
 * interleaved), checking its size, its values against the sidecar's checksum and, for a raster,
 * its own origin against where whole (the whole raster's georeference, or NULL) puts m's window
 * and its CRS and cell size against ref's. */
static int cli_piece_read(const char *path, const cli_piece *m, int W, int H, float *out,
                          const ex_georef *whole, const ex_georef *ref, ex_georef *keep)
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
        if (whole && whole->has_transform && r.geo.has_transform) {
            ex_georef at = *whole; /* shallow: only the geotransform is used */
            const double cx = fabs(at.gt[1]) + fabs(at.gt[2]), cy = fabs(at.gt[4]) + fabs(at.gt[5]);
            double dx, dy;
            at.n_tiepoints = 0, at.has_matrix = 0;
            ex_georef_shift(&at, m->x0, m->y0);
            dx = r.geo.gt[0] - at.gt[0], dy = r.geo.gt[3] - at.gt[3];
            if (!(fabs(dx) <= CLI_PIECE_ORIGIN_TOLERANCE * cx && fabs(dy) <= CLI_PIECE_ORIGIN_TOLERANCE * cy)) {
                cli_error(CLI_EXIT_ERROR, path, "its own origin lies %.6g, %.6g map units from window %d,%d,%d,%d "
                          "of its sidecar %s%s (a swapped piece or sidecar)", dx, dy, m->x0, m->y0, m->w, m->h,
                          path, CLI_PIECE_SIDECAR);
                ex_rio_close(&r);
                return CLI_EXIT_ERROR;
            }
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
        if (cli_piece_sum(m, W, H, out) != m->values) {
            ex_rio_close(&r);
            return cli_piece_stale(path);
        }
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
        return cli_piece_sum(m, W, H, out) == m->values ? 0 : cli_piece_stale(path);
    }
}

/* `hfvis mosaic PIECE... -o OUT`: the sidecars first (one run: same tag; the windows tile the
 * extent: inside it, no two overlapping, their areas summing to it), then the pieces into one
 * raster, written as the whole run writes it (cli_save with the whole raster's georeference). */
static int cli_mosaic(int argc, char **argv)
{
    const char **names = (const char **)calloc((size_t)argc, sizeof *names); /* the pieces */
    int rc = names ? cli_mosaic_pieces(argc, argv, names) : cli_status("mosaic", HFVIS_ERR_OUT_OF_MEMORY, 0);
    free((void *)names);
    return rc;
}

/* cli_mosaic with the array of its pieces' names (at most argc). */
static int cli_mosaic_pieces(int argc, char **argv, const char **names)
{
    enum { MAX_PIECES = 65536 };
    cli_piece *meta = NULL;
    cli_args a;
    cli_run_state run;
    char key[64], other[CLI_PIECE_TAG_MAX], cmdname[32], ext[64];
    int n = 0, i, j, rc = 0, W = 0, H = 0, planes, channels, origin = -1, cmd;
    double area = 0.0, lo = 0.0, hi = 1.0;
    float *out = NULL;
    ex_georef ref, whole;

    memset(&a, 0, sizeof a);
    cli_run_init(&run);
    a.run = &run;
    memset(&ref, 0, sizeof ref);
    memset(&whole, 0, sizeof whole);
    for (i = 2; i < argc; i++) {
        const char *arg = argv[i];
        if (!strcmp(arg, "-h") || !strcmp(arg, "--help")) return cli_help(CMD_MOSAIC);
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
            return cli_refuse_flag(CMD_MOSAIC, arg);
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
    for (cmd = 0; cmd < CMD_COUNT && strcmp(cmdname, cli_commands[cmd].name); cmd++) {}
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
    /* the whole raster's geotransform, as the run's tag records it: where each piece belongs */
    if (cli_tag_value(meta[0].tag, "gt", other, sizeof other) && strcmp(other, "none")) {
        char *q = other;
        for (i = 0; i < 6; i++) {
            char *comma = strchr(q, ',');
            if (comma) *comma = '\0';
            if (!cli_parse_real(q, &whole.gt[i])) break;
            q = comma ? comma + 1 : q + strlen(q);
        }
        whole.has_transform = i == 6;
    }
    /* the piece at (0, 0) first: its georeference is the whole raster's and the reference of the others */
    if ((rc = cli_piece_read(names[origin], &meta[origin], W, H, out, &whole, NULL, &ref)) != 0) goto done;
    for (i = 0; i < n; i++)
        if (i != origin && (rc = cli_piece_read(names[i], &meta[i], W, H, out, &whole,
                                                ex_rio_format_of(names[origin]) ? &ref : NULL, NULL)) != 0)
            goto done;
    if (!ref.has_transform && whole.has_transform) {
        /* PFM pieces: the geotransform from the sidecar (their CRS is not kept: use raster pieces) */
        memcpy(ref.gt, whole.gt, sizeof ref.gt);
        ref.has_transform = 1;
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
    ex_georef_free(&run.geo);
    run.geo = ref;
    memset(&ref, 0, sizeof ref);
    a.cmd = cmd < CMD_COUNT ? cmd : CMD_SKYVIEW;
    a.fraction = cli_tag_value(meta[0].tag, "fraction", other, sizeof other) && !strcmp(other, "1");
    if (!strcmp(meta[0].range, "top")) {
        hi = cli_top(out, (size_t)W * (size_t)H * (size_t)planes * (size_t)channels, 1.0);
    } else {
        char *colon = strchr(meta[0].range, ':');
        if (colon) *colon = '\0';
        if (!colon || !cli_parse_real(meta[0].range, &lo) || !cli_parse_real(colon + 1, &hi)) lo = 0.0, hi = 1.0;
    }
    {
        cli_output whole_out = cli_output_of(out, W, H, planes, channels, lo, hi);
        cli_labels L;
        memset(&L, 0, sizeof L);
        char (*solar_text)[16] = NULL;
        const char **solar_names = NULL;
        if (a.cmd == CMD_HORIZON) { /* the whole run's band labels, from the run's tag */
            if ((rc = cli_horizon_labels_of_tag(meta[0].tag, planes, &L)) != 0) goto done;
            if (L.band) {
                whole_out.band_names = L.band, whole_out.unit = L.unit;
                whole_out.meta = L.meta, whole_out.n_meta = planes + 3;
            }
        } else if (a.cmd == CMD_SOLAR) { /* the whole run's descriptions and unit, from the tag */
            if (cli_solar_labels_of_tag(meta[0].tag, planes, &solar_text, &solar_names, &whole_out.unit)) {
                rc = cli_status("mosaic", HFVIS_ERR_OUT_OF_MEMORY, 0);
                goto done;
            }
            whole_out.band_names = solar_names;
        } else {
            whole_out.band_names = cli_fixed_band_names(a.cmd, planes * channels);
        }
        rc = cli_save(&a, whole_out);
        cli_labels_free(&L);
        free(solar_text);
        free(solar_names);
    }
done:
    ex_georef_free(&ref);
    ex_georef_free(&run.geo);
    free(out);
    free(meta);
    return rc;
}
