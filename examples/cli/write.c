/* write.c - safe writing: every file goes through hfvis_write_file, whose temporary name is kept
 * here so that SIGINT, SIGTERM and SIGHUP remove it (the handler unlinks it and re-raises the
 * signal; SIGXFSZ is ignored, so a file-size limit is a write error); the encoders of the
 * library's formats; cli_save (PFM, PGM and the GIS rasters); a replaced file's stale GDAL
 * sidecar OUT.aux.xml removed; the refusals of outputs before a run (an input, an unwritable
 * directory, two outputs of one file). Owns: the temporary-file names. May call: progress.c,
 * gis.c, tiles.c (pieces), the library's encoders and examples/raster_io.h. */

#define CLI_TMP_CAP 4096 /* longest temporary name the handler can remove (PATH_MAX on Linux) */
#define CLI_TMP_SLOTS 8  /* temporary files alive at once: a raster with its sidecars (ex_publish) */
static char cli_tmp_name[CLI_TMP_SLOTS][CLI_TMP_CAP];
static volatile sig_atomic_t cli_tmp_armed; /* cli_tmp_name[0..armed) name files that may exist */

/* hfvis_write_options.on_temp: each new temporary name takes the next slot and is armed only
 * once it is complete; NULL (the file, or the whole set, renamed or removed) disarms them all. */
static void cli_on_temp(void *user, const char *tmp)
{
    size_t n = tmp ? strlen(tmp) : 0;
    int k = cli_tmp_armed;
    (void)user;
    if (!tmp) {
        cli_tmp_armed = 0;
        return;
    }
    if (n >= CLI_TMP_CAP || k >= CLI_TMP_SLOTS) return;
    memcpy(cli_tmp_name[k], tmp, n + 1);
    cli_tmp_armed = k + 1;
}

#ifdef CLI_HAVE_SIGACTION
/* Async-signal-safe: unlink the temporary file, restore the default action and re-raise, so the
 * exit status says which signal ended the run (130 for SIGINT, 143 for SIGTERM in a shell). */
static void cli_on_signal(int sig)
{
    int k;
    for (k = 0; k < cli_tmp_armed; k++) unlink(cli_tmp_name[k]);
    signal(sig, SIG_DFL);
    raise(sig);
}

/* ex_atomic_hold: SIGINT, SIGTERM and SIGHUP wait (blocked, then delivered) while a temporary
 * file is created and reported, and while a raster's set of files is moved into place. The
 * signal mask before the outermost hold is restored after it (nested holds count). */
static sigset_t cli_hold_mask;
static int cli_hold_depth;
static void cli_hold(int hold)
{
    sigset_t s;
    if (!hold) {
        if (cli_hold_depth > 0 && --cli_hold_depth == 0) sigprocmask(SIG_SETMASK, &cli_hold_mask, NULL);
        return;
    }
    if (cli_hold_depth++ > 0) return;
    sigemptyset(&s);
    sigaddset(&s, SIGINT);
    sigaddset(&s, SIGTERM);
    sigaddset(&s, SIGHUP);
    sigprocmask(SIG_BLOCK, &s, &cli_hold_mask);
}

/* Install the handler for SIGINT, SIGTERM and SIGHUP, leaving an ignored signal ignored; ignore
 * SIGXFSZ; hold the signals where a raster writer asks (ex_atomic_hold). */
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
    ex_atomic_hold = cli_hold;
#ifdef SIGXFSZ
    { /* past a file-size limit (ulimit -f), a write fails with EFBIG and is reported, instead of
       * the signal ending the run silently and leaving the temporary file */
        struct sigaction ign;
        memset(&ign, 0, sizeof ign);
        ign.sa_handler = SIG_IGN;
        sigemptyset(&ign.sa_mask);
        sigaction(SIGXFSZ, &ign, NULL);
    }
#endif
}
#else
static void cli_signals(void) {}
#endif

/* hfvis_write_file's on_temp in cli_write_file: name the file for the handler, then let the held
 * signals through (user: 1 while they are held). */
static void cli_on_temp_release(void *user, const char *tmp)
{
    int *held = (int *)user;
    cli_on_temp(NULL, tmp);
    if (tmp && *held) {
        *held = 0;
        ex_atomic_hold(0);
    }
}

/* After path has been replaced by a new file: remove path.aux.xml, the sidecar in which GDAL
 * keeps statistics and histograms of a raster (gdalinfo -stats, QGIS), so that it does not
 * describe the old values. GDAL removes it when it recreates a file itself. Best effort: a file
 * that is not there, or that cannot be removed, is left as it is. */
static void cli_drop_aux(const char *path)
{
    static const char ext[] = ".aux.xml";
    char aux[CLI_TMP_CAP];
    size_t n = strlen(path);
    if (n + sizeof ext > sizeof aux) return;
    memcpy(aux, path, n);
    memcpy(aux + n, ext, sizeof ext);
    (void)remove(aux);
}

/* hfvis_write_file with its temporary name recorded. The signals wait (ex_atomic_hold) from
 * before the file is created until the library has named it, so that no interrupt falls between
 * the two and leaves the file behind. */
static hfvis_status cli_write_file(const char *path, const void *bytes, size_t n)
{
    hfvis_write_options wo;
    hfvis_status s;
    int held = ex_atomic_hold != NULL;
    wo.on_temp = cli_on_temp_release;
    wo.user = &held;
    if (held) ex_atomic_hold(1);
    s = hfvis_write_file(path, bytes, n, &wo);
    if (held) ex_atomic_hold(0); /* the file was never created */
    if (s == HFVIS_OK) cli_drop_aux(path);
    return s;
}

/* Write n bytes to path (cli_write_file), freeing bytes. */
static hfvis_status cli_write(const char *path, unsigned char *bytes, size_t n, hfvis_status s)
{
    if (s == HFVIS_OK) s = cli_write_file(path, bytes, n);
    free(bytes);
    return s;
}

static hfvis_status cli_write_encoded(const char *path, size_t need, cli_encoder encode, const void *what)
{
    unsigned char *buf = need ? (unsigned char *)cli_huge_malloc(need) : NULL; /* threads.c */
    size_t written = 0;
    hfvis_status s;
    if (!buf) return need ? HFVIS_ERR_OUT_OF_MEMORY : HFVIS_ERR_INVALID_ARGUMENT;
    s = encode(what, buf, need, &written);
    return cli_write(path, buf, written, s);
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
/* A PFM streamed in slices of rows, never whole in memory (a 4096^2 horizon map of 16 planes
 * is 1 GiB, whose first touch alone took seconds on this project's VMs): the header of the
 * whole image, then the rows from the bottom up as PFM stores them, in slices of at most
 * CLI_PFM_SLICE bytes, each encoded by the library (hfvis_pfm_encode of the slice's rows: its pixel bytes,
 * after the slice's own header, are the file's bytes at the slice's place) into its thread's
 * buffer and written there with pwrite, the slices over the run's threads (cli_threaded_rows,
 * while CLI_ROWS_BAND rows fit in CLI_PFM_SLICE bytes):
 * the kernel's copy of a large output into the page cache, the larger part of the write, is then
 * shared by the threads too (a 1 GiB horizon map: 2.3 s of a 17.5 s one-thread run here; docs/
 * performance.md, "Threads"). Without POSIX threads, one thread writes the slices in order
 * with fwrite. The file is the one hfvis_pfm_encode makes of the whole image, byte for byte
 * (cli_test checks the header and size, and --threads 1 against 2; the pixel bytes are the
 * library's). */
#define CLI_PFM_SLICE ((size_t)8 << 20)
typedef struct cli_pfm_slices {
    const float *px;
    int w, h, channels;
    ptrdiff_t stride;
    FILE *f;                   /* one thread: written in order with fwrite */
    int fd;                    /* threads: the file's descriptor for pwrite, -1 for fwrite */
    long long base;            /* the header's length: where the bottom row starts */
    unsigned char **buf;       /* one slice buffer per thread */
    int *err;                  /* the errno of a failed write, per thread */
} cli_pfm_slices;

static hfvis_status cli_pfm_slice(void *ctx, int y0, int y1, int thread)
{
    const cli_pfm_slices *j = (const cli_pfm_slices *)ctx;
    const size_t row = (size_t)j->w * (size_t)j->channels * 4;
    const size_t slice = hfvis_pfm_encode_size(j->w, y1 - y0, j->channels), pixels = row * (size_t)(y1 - y0);
    const unsigned char *p = j->buf[thread] + (slice - pixels);
    size_t written = 0, left = pixels;
    hfvis_status s = hfvis_pfm_encode(j->px + (ptrdiff_t)y0 * j->stride * j->channels, j->w, y1 - y0, j->channels,
                                      j->stride, j->buf[thread], slice, &written);
    if (s != HFVIS_OK) return s;
    if (written != slice) return HFVIS_ERR_INVALID_ARGUMENT; /* not the library's layout */
    if (j->fd < 0) return fwrite(p, 1, pixels, j->f) == pixels ? HFVIS_OK : HFVIS_ERR_IO;
#if CLI_HAVE_THREADS
    {
        off_t at = (off_t)(j->base + (long long)row * (long long)(j->h - y1)); /* rows [y0, y1), bottom up */
        while (left > 0) {
            ssize_t n = pwrite(j->fd, p, left, at);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) { /* a short write that makes no progress is a failure too (disk full) */
                j->err[thread] = n < 0 ? errno : ENOSPC;
                return HFVIS_ERR_IO;
            }
            p += n, at += n, left -= (size_t)n;
        }
    }
#else
    (void)left;
#endif
    return HFVIS_OK;
}

static hfvis_status cli_pfm_save(const char *path, const float *px, int w, int h, int channels, ptrdiff_t stride,
                                 int threads)
{
    const size_t need = hfvis_pfm_encode_size(w, h, channels), row = (size_t)w * (size_t)channels * 4;
    int rows = row >= CLI_PFM_SLICE ? 1 : h < (int)(CLI_PFM_SLICE / row) ? h : (int)(CLI_PFM_SLICE / row);
    char head[64];
    int len, ok, t, err[CLI_THREADS_MAX];
    unsigned char *buf[CLI_THREADS_MAX];
    char *tmp = NULL;
    cli_pfm_slices j;
    hfvis_status s = HFVIS_OK;
    if (need == 0 || stride < w) return HFVIS_ERR_INVALID_ARGUMENT;
    len = snprintf(head, sizeof head, "P%c\n%d %d\n-1.0\n", channels == 3 ? 'F' : 'f', w, h);
    if (len <= 0 || (size_t)len != need - row * (size_t)h) return HFVIS_ERR_INVALID_ARGUMENT; /* not the library's */
    if (!CLI_HAVE_THREADS || threads < 1) threads = 1;
    if (threads > CLI_THREADS_MAX) threads = CLI_THREADS_MAX;
    if (threads > (h - 1) / CLI_ROWS_BAND + 1) threads = (h - 1) / CLI_ROWS_BAND + 1;
    if (row > CLI_PFM_SLICE / CLI_ROWS_BAND) threads = 1; /* a thread's band would pass CLI_PFM_SLICE */
    if (threads > 1) rows = h < CLI_ROWS_BAND ? h : CLI_ROWS_BAND; /* cli_threaded_rows' bands */
    memset(&j, 0, sizeof j);
    for (t = 0; t < threads; t++) {
        err[t] = 0;
        buf[t] = (unsigned char *)cli_huge_malloc(hfvis_pfm_encode_size(w, rows, channels));
        if (!buf[t]) s = HFVIS_ERR_OUT_OF_MEMORY;
    }
    j.f = s == HFVIS_OK ? ex_atomic_open(path, &tmp) : NULL;
    if (!j.f) {
        for (t = 0; t < threads; t++) free(buf[t]);
        return s == HFVIS_OK ? HFVIS_ERR_IO : s;
    }
    j.px = px, j.w = w, j.h = h, j.channels = channels, j.stride = stride;
    j.fd = -1, j.base = len, j.buf = buf, j.err = err;
    ok = fwrite(head, 1, (size_t)len, j.f) == (size_t)len && fflush(j.f) == 0;
#if CLI_HAVE_THREADS
    if (threads > 1) j.fd = fileno(j.f); /* the header is flushed: the slices go after it */
#endif
    if (ok && j.fd >= 0) {
        s = cli_threaded_rows(h, threads, cli_pfm_slice, &j);
    } else if (ok) {
        int y1;
        for (y1 = h; s == HFVIS_OK && y1 > 0; y1 -= rows) /* the topmost slice last */
            s = cli_pfm_slice(&j, y1 > rows ? y1 - rows : 0, y1, 0);
    }
    ok = ok && s == HFVIS_OK;
    for (t = 0; t < threads; t++) {
        if (err[t]) errno = err[t]; /* the failed write's reason, for the caller's message */
        free(buf[t]);
    }
    if (!ex_atomic_close(j.f, tmp, path, ok) && s == HFVIS_OK) s = HFVIS_ERR_IO; /* a short write too */
    if (s == HFVIS_OK) cli_drop_aux(path);
    return s;
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
    size_t n = (size_t)grid->dims[0] * (size_t)grid->dims[1] * (size_t)grid->dims[2];
    return cli_write_file(path, occ, n);
}
static hfvis_status cli_visfield_save(const char *path, const hfvis_visfield *vf)
{
    return cli_write_encoded(path, hfvis_visfield_encode_size(vf), cli_enc_visfield, vf);
}
static hfvis_status cli_partial_save(const char *path, const hfvis_partial *p)
{
    return cli_write_encoded(path, hfvis_partial_encode_size(p), cli_enc_partial, p);
}

/* The descriptor of planes x (w x h) cells of `channels` values with default range [lo, hi]. */
static cli_output cli_output_of(const float *px, int w, int h, int planes, int channels, double lo,
                                double hi)
{
    cli_output o;
    memset(&o, 0, sizeof o);
    o.px = px, o.w = w, o.h = h, o.planes = planes, o.channels = channels, o.lo = lo, o.hi = hi;
    return o;
}

/* Write OUT: PFM with its channels, or a 16-bit PGM with the channel planes stacked (NoData code 0,
 * the range in its header: hfvis_pgm_range_save). A --window run writes its piece instead. */
static int cli_save(const cli_args *a, cli_output out)
{
    const float *px = out.px;
    const int w = out.w, h = out.h * out.planes, channels = out.channels;
    double lo = out.lo, hi = out.hi;
    hfvis_status s;
    if (a->run->win.active) return cli_save_piece(a, out);
    errno = 0;
    if (a->out_raster) {
        /* planes stacked top to bottom (horizon) or channels interleaved become bands */
        const int planes = out.planes; /* planes and channels become bands */
        ex_rio_image img;
        ex_rio_write_options o;
        ex_georef g = a->run->geo; /* shallow: only the NoData fields change, on the copy */
        char why[256];
        size_t i, n = (size_t)w * (size_t)h * (size_t)channels;
        int moved = 0, threads = cli_run_threads(a);
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
        o.parallel = cli_parallel_for; /* the tiles compressed over the run's threads */
        o.parallel_user = &threads;
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
        o.band_names = out.band_names;
        o.unit = out.unit;
        o.meta = out.meta;
        o.n_meta = out.n_meta;
        if (ex_rio_write(a->out, &img, &g, &o, why) != 0) return cli_error(CLI_EXIT_ERROR, a->out, "%s", why);
        cli_drop_aux(a->out);
        if (ex_rio_format_of(a->out) != EX_RIO_TIFF && ex_rio_crs_lost(&g) && !a->quiet)
            fprintf(stderr, "hfvis: note: %s has no .prj: the input's CRS EPSG:%d has no WKT here (write .tif "
                    "to keep it, or copy a .prj beside it)\n", a->out, g.epsg);
        if (moved && !a->quiet)
            fprintf(stderr, "hfvis: note: %s: the input's NoData %s is a value of this output: holes are "
                    "written as %s\n", a->out, a->run->geo.nodata_text, g.has_nodata ? g.nodata_text : "NaN");
        return 0;
    }
    if (!a->out_pgm) {
        s = cli_pfm_save(a->out, px, w, h, channels, w, cli_run_threads(a));
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
    for (i = 0; i < n && !overwrite && out; i++) /* out: NULL for a command that writes none */
        if (inputs[i] && cli_same_file(out, inputs[i]))
            return cli_error(CLI_EXIT_ERROR, out, "is the input %s: refusing to replace an input "
                             "(give --overwrite to do so)", inputs[i]);
    return 0;
}

/* Every input of a command against out. */
static int cli_refuse_inputs(const cli_args *a, const char *out)
{
    const char *inputs[6];
    inputs[0] = a->in, inputs[1] = a->env, inputs[2] = a->albedo_map, inputs[3] = a->emission;
    inputs[4] = a->vf_reference, inputs[5] = a->sol_linke_map;
    return cli_refuse_input(a->overwrite, out, inputs, 6);
}

#ifdef CLI_HAVE_ISATTY
/* The directory of path ("." without a '/', "/" for a name at the root) into d[cap]: 1, or 0
 * when it does not fit. */
static int cli_dir_of(const char *path, char *d, size_t cap)
{
    const char *s = strrchr(path, '/');
    size_t n = s ? (size_t)(s - path) : 0;
    if (n + 2 > cap) return 0;
    if (!s) strcpy(d, ".");
    else if (n == 0) strcpy(d, "/");
    else memcpy(d, path, n), d[n] = '\0';
    return 1;
}
#endif

/* Whether paths x and y name one file, existing or still to be written: the same string, the
 * same file (cli_same_file), or one last component in one directory (same device and inode). */
static int cli_same_path(const char *x, const char *y)
{
    if (!strcmp(x, y) || cli_same_file(x, y)) return 1;
#ifdef CLI_HAVE_ISATTY
    {
        const char *sx = strrchr(x, '/'), *sy = strrchr(y, '/');
        char dx[CLI_TMP_CAP], dy[CLI_TMP_CAP];
        struct stat tx, ty;
        if (strcmp(sx ? sx + 1 : x, sy ? sy + 1 : y) || !cli_dir_of(x, dx, sizeof dx) ||
            !cli_dir_of(y, dy, sizeof dy))
            return 0;
        return stat(dx, &tx) == 0 && stat(dy, &ty) == 0 && tx.st_dev == ty.st_dev && tx.st_ino == ty.st_ino;
    }
#else
    return 0;
#endif
}

/* An output whose directory does not exist or cannot be written to is refused before the run
 * computes anything (the write would fail after it): 0, or CLI_EXIT_ERROR after one line. */
static int cli_refuse_unwritable(const char *path)
{
#ifdef CLI_HAVE_ISATTY
    char d[CLI_TMP_CAP];
    struct stat st;
    if (!cli_dir_of(path, d, sizeof d)) return 0; /* the write reports it */
    if (stat(d, &st) != 0)
        return cli_error(CLI_EXIT_ERROR, path, "cannot be written: its directory %s: %s", d, strerror(errno));
    if (!S_ISDIR(st.st_mode))
        return cli_error(CLI_EXIT_ERROR, path, "cannot be written: %s is not a directory", d);
    if (access(d, W_OK | X_OK) != 0)
        return cli_error(CLI_EXIT_ERROR, path, "cannot be written: its directory %s: %s", d, strerror(errno));
#else
    (void)path;
#endif
    return 0;
}

/* Every output file of a run (OUT and solar's --beam, --diffuse, --reflected, --sun-hours): none
 * may be an input unless --overwrite, nor lie in a directory that does not exist or cannot be
 * written to (CLI_EXIT_ERROR); no two may name one file, nor (ASC grids, EHdr rasters) one .prj
 * or .hdr sidecar, whatever --overwrite says (CLI_EXIT_USAGE): the later would replace the
 * earlier. 0, or the exit status after one error line. */
static int cli_refuse_outputs(const cli_args *a)
{
    static const char *const flag[5] = { "-o", "--beam", "--diffuse", "--reflected", "--sun-hours" };
    const char *outs[5];
    int i, j, rc;
    outs[0] = a->out, outs[1] = a->sol_out[0], outs[2] = a->sol_out[1], outs[3] = a->sol_out[2];
    outs[4] = a->sol_out[3];
    for (i = 0; i < 5; i++)
        if (outs[i] && ((rc = cli_refuse_inputs(a, outs[i])) != 0 || (rc = cli_refuse_unwritable(outs[i])) != 0))
            return rc;
    for (i = 0; i < 5; i++)
        for (j = i + 1; outs[i] && j < 5; j++) {
            int fi, fj, same;
            char *pi, *pj;
            if (!outs[j]) continue;
            if (cli_same_path(outs[i], outs[j]))
                return cli_error(CLI_EXIT_USAGE, outs[j], "is the output of both %s and %s: give each "
                                 "output its own file", flag[i], flag[j]);
            fi = ex_rio_format_of(outs[i]), fj = ex_rio_format_of(outs[j]);
            if ((fi != EX_RIO_ASC && fi != EX_RIO_EHDR) || (fj != EX_RIO_ASC && fj != EX_RIO_EHDR)) continue;
            pi = ex_rio_sidecar(outs[i], ".prj"), pj = ex_rio_sidecar(outs[j], ".prj");
            same = pi && pj && cli_same_path(pi, pj);
            if (same)
                cli_error(CLI_EXIT_USAGE, outs[j], "shares its sidecar %s with %s (%s): give the "
                          "outputs different names before the extension", pj, outs[i], flag[i]);
            free(pi);
            free(pj);
            if (same) return CLI_EXIT_USAGE;
            if (!pi || !pj) return cli_status(outs[j], HFVIS_ERR_OUT_OF_MEMORY, 0);
        }
    return 0;
}
