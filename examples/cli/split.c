/* split.c - split runs: --dir-range writes a partial result (HFVISSUM) tagged with the command,
 * the input's fingerprint and every parameter; `sum` checks the parts and adds them into the
 * single run's OUT. May call: progress.c, flags.c's primitives, sweeps.c, write.c. */


/* FNV-1a 64 of one value, folded into h (start: CLI_FNV_OFFSET): the value's IEEE bits, least
 * significant byte first (the same on every byte order), every NaN as one quiet NaN and -0 as +0,
 * so that a piece's values hash the same in every format that holds them exactly. */
#define CLI_FNV_OFFSET 14695981039346656037ull
static unsigned long long cli_fnv_value(unsigned long long h, float v)
{
    uint32_t bits = 0x7fc00000u;
    int b;
    if (v == 0.0f) bits = 0;
    else if (!isnan(v)) memcpy(&bits, &v, sizeof bits);
    for (b = 0; b < 4; b++) h = (h ^ ((bits >> (8 * b)) & 0xffu)) * 1099511628211ull;
    return h;
}

/* FNV-1a 64 over n floats (the loaded input, or an environment map). */
static unsigned long long cli_fingerprint(const float *v, size_t n)
{
    unsigned long long h = CLI_FNV_OFFSET;
    size_t i;
    for (i = 0; i < n; i++) h = cli_fnv_value(h, v[i]);
    return h;
}

/* The tag of a partial result: "cmd=NAME" then every parameter that changes the sums or their
 * finish, as key=value (reals as exact hexadecimal floats); `sum` compares tags token by token. */
static void cli_partial_tag(const cli_args *a, const hfvis_grid *grid, const hfvis_sweep_options *o,
                            const hfvis_env *env, char *tag)
{
    const ex_georef *g = &a->run->geo;
    int n = snprintf(tag, CLI_TAG_MAX, "cmd=%s dirs=%d in=%016llx cell=%a border=%d border-cells=%d "
                     "azimuth0=%a rays=%s max-distance=%a georef=%d", cli_commands[a->cmd].name, a->dirs,
                     cli_fingerprint(grid->z, (size_t)grid->width * (size_t)grid->height),
                     grid->cell_size, (int)o->border, o->border_cells, o->azimuth0_rad,
                     o->rays == HFVIS_RAYS_EXACT ? "exact" : "lattice", o->max_distance,
                     g->has_transform || g->crs || g->epsg || g->has_nodata || g->prj || g->n_geokeys);
    char *t = tag + n;
    size_t left = CLI_TAG_MAX - (size_t)n;
    switch (a->cmd) {
    case CMD_HORIZON: /* and the convention, from which `sum` rebuilds the band labels */
        snprintf(t, left, " degrees=%d convention=%d", a->degrees, a->convention);
        break;
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
    const char *cmd = cli_commands[a->cmd].name;
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
                             cli_commands[cmd].name);
    }
    return 0;
}

/* `hfvis sum PART... -o OUT`: check that the parts are one run's and tile [0, K) (pass 1 reads
 * each part and keeps only its header), then add them in direction order, one part in memory at
 * a time (pass 2), finish exactly as the single run does and write OUT (atomically: the codecs
 * write a temporary file and rename it). */

static int cli_sum(int argc, char **argv)
{
    /* per part (at most argc): its name, header and tag, and its place in direction order */
    const char **names = (const char **)calloc((size_t)argc, sizeof *names);
    cli_part *meta = (cli_part *)calloc((size_t)argc, sizeof *meta);
    int *order = (int *)calloc((size_t)argc, sizeof *order), rc;
    if (!names || !meta || !order) rc = cli_status("sum", HFVIS_ERR_OUT_OF_MEMORY, 0);
    else rc = cli_sum_parts(argc, argv, names, meta, order);
    free(order);
    free(meta);
    free((void *)names);
    return rc;
}

/* cli_sum with its per-part arrays. */
static int cli_sum_parts(int argc, char **argv, const char **names, cli_part *meta, int *order)
{
    enum { MAX_PARTS = 4096 };
    cli_args a;
    cli_run_state run;
    const char *cmdname = "sum";
    char name[32], key[64], other[64];
    int nparts = 0, i, j, rc = 0, cmd, K, W, H, planes, channels = 1, out_planes = 1, deg = 0;
    double lo = 0.0, hi = 1.0, *acc = NULL;
    float *out = NULL;
    size_t n, k;

    memset(&a, 0, sizeof a);
    cli_run_init(&run);
    a.run = &run;
    for (i = 2; i < argc; i++) {
        const char *arg = argv[i];
        if (!strcmp(arg, "-h") || !strcmp(arg, "--help")) return cli_help(CMD_SUM);
        if (!strcmp(arg, "-o") || !strncmp(arg, "-o=", 3) || !strcmp(arg, "--range") ||
            !strncmp(arg, "--range=", 8)) {
            int is_o = arg[1] == 'o';
            const char *eq = strchr(arg, '='), *v = eq ? eq + 1 : (i + 1 < argc ? argv[++i] : NULL);
            if (!v) return cli_error(CLI_EXIT_USAGE, is_o ? "-o" : "--range", "missing value");
            if (is_o) {
                if (!cli_ends_with(v, ".pfm") && !cli_ends_with(v, ".pgm") && !ex_rio_format_of(v))
                    return cli_error(CLI_EXIT_USAGE, v, "unknown output type (use a .pfm, .pgm, .tif, "
                                     ".asc, .bil or .flt name)");
                a.out = v;
                a.out_pgm = cli_ends_with(v, ".pgm");
                a.out_raster = !a.out_pgm && !cli_ends_with(v, ".pfm");
            } else if (cli_set(&a, "--range", v)) {
                return CLI_EXIT_USAGE;
            }
            continue;
        }
        if (!strcmp(arg, "--quiet")) continue;
        if (!strcmp(arg, "--overwrite")) { a.overwrite = 1; continue; }
        if (arg[0] == '-' && arg[1] != '\0')
            return cli_refuse_flag(CMD_SUM, arg);
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
    for (cmd = 0; cmd < CMD_COUNT && strcmp(name, cli_commands[cmd].name); cmd++) {}
    if (cmd != CMD_HORIZON && cmd != CMD_SKYVIEW && cmd != CMD_SKY && cmd != CMD_LIGHT &&
        cmd != CMD_VISIBILITY) {
        rc = cli_error(CLI_EXIT_ERROR, names[0], "not a partial result of hfvis horizon, skyview, sky, "
                       "light or visibility");
        goto done;
    }
    K = meta[0].directions, W = meta[0].width, H = meta[0].height, planes = meta[0].planes;
    if (a.out_raster && cli_tag_value(meta[0].tag, "georef", name, sizeof name) && strcmp(name, "0")) {
        rc = cli_error(CLI_EXIT_ERROR, a.out, "the parts come from a georeferenced raster, whose "
                       "georeference a partial result does not carry: write .pfm or .pgm, or run "
                       "whole (or in --window pieces and 'hfvis mosaic')");
        goto done;
    }
    a.cmd = cmd; /* the single run's command and flags, for cli_save (visibility's integer counts) */
    a.fraction = cmd == CMD_VISIBILITY && planes == 2;
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
                float *dst = out + (size_t)kk * n; /* (a split horizon is compass or grid) */
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
        for (k = 0; k < n; k++) out[k] = cli_sum_finish(CMD_SKYVIEW, K, 0.0, acc[k]);
    } else if (cmd == CMD_SKY) {
        double sky = 0.0, albedo = 0.0, scale;
        if (!cli_tag_real(meta[0].tag, "sky", &sky) || !cli_tag_real(meta[0].tag, "albedo", &albedo)) {
            rc = cli_error(CLI_EXIT_ERROR, names[0], "the part does not name its sky and albedo");
            goto done;
        }
        scale = (double)(float)sky * (double)(float)albedo; /* the floats the single run passes */
        for (k = 0; k < n; k++) out[k] = cli_sum_finish(CMD_SKY, K, scale, acc[k]);
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
                    cli_sum_finish(CMD_LIGHT, K, (double)(float)albedo, acc[(size_t)c * n + k]);
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
    {
        cli_output whole = cli_output_of(out, W, H, out_planes, channels, lo, hi);
        cli_labels L;
        memset(&L, 0, sizeof L);
        if (cmd == CMD_HORIZON && (rc = cli_horizon_labels_of_tag(meta[0].tag, K, &L)) != 0) goto done;
        if (L.band) whole.band_names = L.band, whole.unit = L.unit, whole.meta = L.meta, whole.n_meta = K + 3;
        rc = cli_save(&a, whole);
        cli_labels_free(&L);
    }
done:
    free(acc);
    free(out);
    for (i = 0; i < nparts; i++) free(meta[i].tag);
    return rc;
}
