/* split.c - split runs: --dir-range writes a partial result (HFVISSUM) tagged with the command,
 * the input's fingerprint, every parameter and the input's georeference (geo=); `sum` checks
 * the parts and adds them into the single run's OUT, a raster one with that georeference.
 * May call: progress.c, flags.c's primitives, sweeps.c, write.c. */


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

/* The input's georeference in a part's tag (token "geo=", base64url without padding): a byte
 * string, least significant byte first, of
 *   u8 flags (1 transform, 2 NoData, 4 pixel-is-point, 8 flip_x, 16 flip_y, 32 ModelPixelScale,
 *      64 ModelTransformation), u8 CRS kind, u32 EPSG code,
 *   [6 f64 geotransform] [f64 NoData, u8 n, n bytes of its spelling] [3 f64 scale] [16 f64 matrix],
 *   u32 n + n f64 ModelTiepoint, u32 n + n u16 GeoKey directory, u32 n + n f64 GeoDoubleParams,
 *   u32 n + n bytes GeoAsciiParams, u32 n + n bytes of the .prj's WKT,
 * so that `sum` writes a raster OUT with the single run's georeference, bit for bit. */
static void cli_geo_put(cli_geo_bytes *o, const void *src, size_t len)
{
    if (o->n + len > o->cap) o->over = 1;
    else if (len) memcpy(o->b + o->n, src, len);
    o->n += len;
}

static void cli_geo_put_uint(cli_geo_bytes *o, unsigned long v, int bytes)
{
    unsigned char c[4];
    int i;
    for (i = 0; i < bytes; i++) c[i] = (unsigned char)(v >> (8 * i) & 0xffu);
    cli_geo_put(o, c, (size_t)bytes);
}

static void cli_geo_put_reals(cli_geo_bytes *o, const double *v, size_t n)
{
    size_t i;
    for (i = 0; i < n; i++) {
        uint64_t bits;
        unsigned char c[8];
        int b;
        memcpy(&bits, &v[i], sizeof bits);
        for (b = 0; b < 8; b++) c[b] = (unsigned char)(bits >> (8 * b) & 0xffu);
        cli_geo_put(o, c, 8);
    }
}

static void cli_geo_encode(const ex_georef *g, cli_geo_bytes *o)
{
    size_t i, prj = g->prj ? strlen(g->prj) : 0, nd = strlen(g->nodata_text);
    cli_geo_put_uint(o, (unsigned long)((g->has_transform ? 1 : 0) | (g->has_nodata ? 2 : 0) |
                                        (g->pixel_is_point ? 4 : 0) | (g->flip_x ? 8 : 0) |
                                        (g->flip_y ? 16 : 0) | (g->has_scale ? 32 : 0) |
                                        (g->has_matrix ? 64 : 0)), 1);
    cli_geo_put_uint(o, (unsigned long)g->crs, 1);
    cli_geo_put_uint(o, (unsigned long)g->epsg, 4);
    if (g->has_transform) cli_geo_put_reals(o, g->gt, 6);
    if (g->has_nodata) {
        cli_geo_put_reals(o, &g->nodata, 1);
        cli_geo_put_uint(o, (unsigned long)nd, 1);
        cli_geo_put(o, g->nodata_text, nd);
    }
    if (g->has_scale) cli_geo_put_reals(o, g->scale, 3);
    if (g->has_matrix) cli_geo_put_reals(o, g->matrix, 16);
    cli_geo_put_uint(o, (unsigned long)g->n_tiepoints, 4);
    cli_geo_put_reals(o, g->tiepoints, g->n_tiepoints);
    cli_geo_put_uint(o, (unsigned long)g->n_geokeys, 4);
    for (i = 0; i < g->n_geokeys; i++) cli_geo_put_uint(o, g->geokeys[i], 2);
    cli_geo_put_uint(o, (unsigned long)g->n_geodoubles, 4);
    cli_geo_put_reals(o, g->geodoubles, g->n_geodoubles);
    cli_geo_put_uint(o, (unsigned long)g->n_geoascii, 4);
    cli_geo_put(o, g->geoascii, g->n_geoascii);
    cli_geo_put_uint(o, (unsigned long)prj, 4);
    cli_geo_put(o, g->prj, prj);
}

static const char cli_b64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_";

/* Base64url of b[0..n) into out (4 ceil(n/3) + 1 bytes), NUL-terminated, no padding. */
static void cli_b64_encode(const unsigned char *b, size_t n, char *out)
{
    size_t i;
    for (i = 0; i < n; i += 3) {
        unsigned long v = (unsigned long)b[i] << 16 |
                          (i + 1 < n ? (unsigned long)b[i + 1] << 8 : 0) | (i + 2 < n ? b[i + 2] : 0);
        size_t k, m = n - i >= 3 ? 4 : n - i + 1;
        for (k = 0; k < m; k++) *out++ = cli_b64[v >> (18 - 6 * k) & 63u];
    }
    *out = '\0';
}

/* Decode base64url text s (no padding) into b (capacity (3 strlen(s)) / 4); the byte count, or
 * (size_t)-1 for a character outside the alphabet or a dangling one. */
static size_t cli_b64_decode(const char *s, unsigned char *b)
{
    size_t n = 0, len = strlen(s), i, k;
    if (len % 4 == 1) return (size_t)-1;
    for (i = 0; i < len; i += 4) {
        unsigned long v = 0;
        size_t m = len - i >= 4 ? 4 : len - i;
        for (k = 0; k < 4; k++) {
            const char *c = k < m ? strchr(cli_b64, s[i + k]) : cli_b64;
            if (!c || !*c) return (size_t)-1;
            v = v << 6 | (unsigned long)(c - cli_b64);
        }
        for (k = 0; k + 1 < m; k++) b[n++] = (unsigned char)(v >> (16 - 8 * k) & 0xffu);
    }
    return n;
}

/* Reading the byte string back: each getter fails (returns -1, and keeps failing) past the end. */
typedef struct {
    const unsigned char *b;
    size_t n, at;
} cli_geo_reader;

static int cli_geo_get(cli_geo_reader *r, void *dst, size_t len)
{
    if (len > r->n - r->at) return -1;
    if (len) memcpy(dst, r->b + r->at, len);
    r->at += len;
    return 0;
}

static int cli_geo_get_uint(cli_geo_reader *r, unsigned long *v, int bytes)
{
    unsigned char c[4];
    int i;
    *v = 0;
    if (cli_geo_get(r, c, (size_t)bytes)) return -1;
    for (i = bytes - 1; i >= 0; i--) *v = *v << 8 | c[i];
    return 0;
}

static int cli_geo_get_reals(cli_geo_reader *r, double *v, size_t n)
{
    size_t i;
    for (i = 0; i < n; i++) {
        unsigned char c[8];
        uint64_t bits = 0;
        int b;
        if (cli_geo_get(r, c, 8)) return -1;
        for (b = 7; b >= 0; b--) bits = bits << 8 | c[b];
        memcpy(&v[i], &bits, sizeof bits);
    }
    return 0;
}

/* An array of n elements of size each, read with its u32 count (at most EX_RIO_MAX_GEO, and no
 * more than the bytes left); *out NULL when n = 0. */
static int cli_geo_get_array(cli_geo_reader *r, size_t size, void **out, size_t *n, size_t extra)
{
    unsigned long count;
    *out = NULL;
    *n = 0;
    if (cli_geo_get_uint(r, &count, 4) || count > EX_RIO_MAX_GEO || count * size > r->n - r->at)
        return -1;
    if (count == 0) return 0;
    *out = calloc(count * size + extra, 1);
    if (!*out) return -1;
    *n = (size_t)count;
    return 0;
}

/* Decode a "geo=" token's value into g (zeroed first; the caller frees it with ex_georef_free):
 * 0, or -1 when the value is not a georeference this hfvis wrote. */
static int cli_geo_decode(const char *text, ex_georef *g)
{
    size_t len = strlen(text), i;
    unsigned char *b = (unsigned char *)malloc(len * 3 / 4 + 1);
    cli_geo_reader r;
    unsigned long flags = 0, crs = 0, epsg = 0, nd = 0;
    void *arr;
    int bad;
    memset(g, 0, sizeof *g);
    if (!b) return -1;
    r.b = b, r.at = 0, r.n = cli_b64_decode(text, b);
    bad = r.n == (size_t)-1 || cli_geo_get_uint(&r, &flags, 1) || flags > 127 ||
          cli_geo_get_uint(&r, &crs, 1) || crs > EX_RIO_CRS_GEOCENTRIC ||
          cli_geo_get_uint(&r, &epsg, 4) || epsg > 0x7fffffffUL;
    if (!bad) {
        g->has_transform = (flags & 1) != 0, g->has_nodata = (flags & 2) != 0;
        g->pixel_is_point = (flags & 4) != 0;
        g->flip_x = (flags & 8) != 0, g->flip_y = (flags & 16) != 0;
        g->has_scale = (flags & 32) != 0, g->has_matrix = (flags & 64) != 0;
        g->crs = (int)crs, g->epsg = (int)epsg;
        bad = (g->has_transform && cli_geo_get_reals(&r, g->gt, 6)) ||
              (g->has_nodata && (cli_geo_get_reals(&r, &g->nodata, 1) ||
                                 cli_geo_get_uint(&r, &nd, 1) || nd >= sizeof g->nodata_text ||
                                 cli_geo_get(&r, g->nodata_text, nd))) ||
              (g->has_scale && cli_geo_get_reals(&r, g->scale, 3)) ||
              (g->has_matrix && cli_geo_get_reals(&r, g->matrix, 16));
    }
    bad = bad || cli_geo_get_array(&r, 8, &arr, &g->n_tiepoints, 0) ||
          cli_geo_get_reals(&r, (double *)(g->tiepoints = (double *)arr), g->n_tiepoints);
    bad = bad || cli_geo_get_array(&r, 2, &arr, &g->n_geokeys, 0);
    if (!bad) {
        g->geokeys = (uint16_t *)arr;
        for (i = 0; i < g->n_geokeys; i++) {
            unsigned long v;
            cli_geo_get_uint(&r, &v, 2);
            g->geokeys[i] = (uint16_t)v;
        }
    }
    bad = bad || cli_geo_get_array(&r, 8, &arr, &g->n_geodoubles, 0) ||
          cli_geo_get_reals(&r, (double *)(g->geodoubles = (double *)arr), g->n_geodoubles);
    bad = bad || cli_geo_get_array(&r, 1, &arr, &g->n_geoascii, 1) ||
          cli_geo_get(&r, (g->geoascii = (char *)arr), g->n_geoascii);
    if (!bad) {
        size_t n_prj = 0;
        bad = cli_geo_get_array(&r, 1, &arr, &n_prj, 1) ||
              cli_geo_get(&r, (g->prj = (char *)arr), n_prj) ||
              strlen(g->prj ? g->prj : "") != n_prj || r.at != r.n;
    }
    free(b);
    if (bad) ex_georef_free(g);
    return bad ? -1 : 0;
}

/* The tag of a partial result (tag: HFVIS_PARTIAL_MAX_TAG + 1 bytes): "cmd=NAME" then every
 * parameter that changes the sums or their finish, as key=value (reals as exact hexadecimal
 * floats), then "geo=" and the input's georeference (cli_geo_encode), or "geo=long-" and its
 * FNV-1a 64 when that would pass the library's tag limit; `sum` compares tags token by token.
 * (Parts of an older hfvis have "georef=0|1" instead of "geo=" and carry no georeference.)
 * Returns 0, or -1 when memory runs out. */
static int cli_partial_tag(const cli_args *a, const hfvis_grid *grid, const hfvis_sweep_options *o,
                           const hfvis_env *env, char *tag)
{
    int n = snprintf(tag, CLI_TAG_MAX, "cmd=%s dirs=%d in=%016llx cell=%a border=%d border-cells=%d "
                     "azimuth0=%a rays=%s max-distance=%a", cli_commands[a->cmd].name, a->dirs,
                     cli_fingerprint(grid->z, (size_t)grid->width * (size_t)grid->height),
                     grid->cell_size, (int)o->border, o->border_cells, o->azimuth0_rad,
                     o->rays == HFVIS_RAYS_EXACT ? "exact" : "lattice", o->max_distance);
    char *t = tag + n;
    size_t left = CLI_TAG_MAX - (size_t)n;
    unsigned char geo[HFVIS_PARTIAL_MAX_TAG];
    cli_geo_bytes gb;
    if (o->ray_near_cells > 0 && left > 1) { /* only then: the tags of other parts stay as they were */
        n = snprintf(t, left, " exact-near=%d", o->ray_near_cells);
        t += n;
        left -= (size_t)n;
    }
    gb.b = geo, gb.n = 0, gb.cap = sizeof geo, gb.over = 0;
    cli_geo_encode(&a->run->geo, &gb);
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
    n = (int)strlen(tag);
    if (!gb.over && (size_t)n + 5 + (gb.n + 2) / 3 * 4 <= HFVIS_PARTIAL_MAX_TAG) {
        memcpy(tag + n, " geo=", 5);
        cli_b64_encode(geo, gb.n, tag + n + 5);
    } else { /* too long to carry: its fingerprint still keeps other georeferences' parts apart */
        unsigned long long h = CLI_FNV_OFFSET;
        cli_geo_bytes all;
        unsigned char *bytes;
        size_t i;
        all.b = NULL, all.n = 0, all.cap = 0, all.over = 0;
        cli_geo_encode(&a->run->geo, &all); /* counts the bytes */
        bytes = (unsigned char *)malloc(all.n);
        if (!bytes) return -1;
        all.b = bytes, all.cap = all.n, all.n = 0, all.over = 0;
        cli_geo_encode(&a->run->geo, &all);
        for (i = 0; i < all.n; i++) h = (h ^ bytes[i]) * 1099511628211ull;
        free(bytes);
        snprintf(tag + n, HFVIS_PARTIAL_MAX_TAG + 1 - (size_t)n, " geo=long-%lu-%016llx",
                 (unsigned long)all.n, h);
    }
    return 0;
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
    char tag[HFVIS_PARTIAL_MAX_TAG + 1];
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
    if (cli_partial_tag(a, grid, opts, env, tag)) {
        rc = cli_status(cmd, HFVIS_ERR_OUT_OF_MEMORY, 0);
        goto done;
    }
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

/* The value of a tag's "geo=" token (up to its end or the next space), or NULL if it has none. */
static const char *cli_tag_geo(const char *tag)
{
    const char *p = tag;
    while (p && *p) {
        if (!strncmp(p, "geo=", 4)) return p + 4;
        p = strchr(p, ' ');
        if (p) p++;
    }
    return NULL;
}

/* Decode the "geo=" value at v (ending at a space or the tag's end) into g: 0 or -1. */
static int cli_geo_decode_token(const char *v, ex_georef *g)
{
    size_t len = strcspn(v, " ");
    char *text = (char *)malloc(len + 1);
    int rc;
    memset(g, 0, sizeof *g);
    if (!text) return -1;
    memcpy(text, v, len);
    text[len] = '\0';
    rc = cli_geo_decode(text, g);
    free(text);
    return rc;
}

/* What differs between two parts' georeferences ("geo=" values a and b), in words. */
static const char *cli_geo_difference(const char *a, const char *b)
{
    ex_georef ga, gb;
    const char *what = "georeference";
    size_t i;
    if (cli_geo_decode_token(a, &ga)) return what;
    if (cli_geo_decode_token(b, &gb)) {
        ex_georef_free(&ga);
        return what;
    }
    if (ga.has_transform != gb.has_transform || memcmp(ga.gt, gb.gt, sizeof ga.gt))
        what = "georeference (geotransform: origin or cell size)";
    else if (ga.has_nodata != gb.has_nodata || strcmp(ga.nodata_text, gb.nodata_text))
        what = "georeference (NoData)";
    else if (ga.flip_x != gb.flip_x || ga.flip_y != gb.flip_y ||
             ga.pixel_is_point != gb.pixel_is_point)
        what = "georeference (orientation or raster type)";
    else if (strcmp(ga.prj ? ga.prj : "", gb.prj ? gb.prj : ""))
        what = "georeference (CRS: the .prj's WKT)";
    else if (ga.crs != gb.crs || ga.epsg != gb.epsg || ga.n_geokeys != gb.n_geokeys ||
             ga.n_geodoubles != gb.n_geodoubles || ga.n_geoascii != gb.n_geoascii)
        what = "georeference (CRS: GeoKeys)";
    else {
        for (i = 0; i < ga.n_geokeys && ga.geokeys[i] == gb.geokeys[i]; i++) {}
        if (i < ga.n_geokeys ||
            (ga.n_geoascii && memcmp(ga.geoascii, gb.geoascii, ga.n_geoascii)) ||
            (ga.n_geodoubles &&
             memcmp(ga.geodoubles, gb.geodoubles, ga.n_geodoubles * sizeof(double))))
            what = "georeference (CRS: GeoKeys)";
        else
            what = "georeference (GeoTIFF tie points, scale or transformation)";
    }
    ex_georef_free(&ga);
    ex_georef_free(&gb);
    return what;
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
        if (!strcmp(arg, "--quiet")) { a.quiet = 1; continue; }
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
    for (i = 0; i < nparts; i++) /* parts of an older hfvis: no georeference to check */
        if (!cli_tag_geo(meta[i].tag)) {
            rc = cli_error(CLI_EXIT_ERROR, names[i], "a part written by an older hfvis (its tag has "
                           "georef=, not the input's georeference geo=): rerun its --dir-range with "
                           "this hfvis");
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
        if (!strncmp(key, "geo=", 4)) {
            rc = cli_error(CLI_EXIT_ERROR, names[i], "not the same run as %s: the input's %s differs",
                           names[0], cli_geo_difference(cli_tag_geo(meta[0].tag), cli_tag_geo(p->tag)));
            goto done;
        }
        if (key[0]) {
            char *eq = strchr(key, '=');
            if (eq) *eq = '\0';
            if (!cli_tag_value(meta[0].tag, key, other, sizeof other)) strcpy(other, "(none)");
            rc = cli_error(CLI_EXIT_ERROR, names[i], "not the same run as %s: %s=%s there, %s here",
                           names[0], key, other, eq ? eq + 1 : "");
            goto done;
        }
        cli_tag_first_difference(meta[0].tag, p->tag, key, sizeof key); /* a token only there */
        if (key[0]) {
            char *eq = strchr(key, '=');
            if (eq) *eq = '\0';
            rc = cli_error(CLI_EXIT_ERROR, names[i], "not the same run as %s: %s=%s there, (none) here",
                           names[0], key, eq ? eq + 1 : "");
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

    if (a.out_raster) { /* the single run's georeference, from the (equal) tags */
        const char *geo = cli_tag_geo(meta[0].tag);
        if (!strncmp(geo, "long-", 5)) {
            rc = cli_error(CLI_EXIT_ERROR, a.out, "the input's georeference (%.*s bytes) is too long "
                           "for a part's tag (%d characters) to carry: write .pfm or .pgm, or run whole "
                           "(or in --window pieces and 'hfvis mosaic')", (int)strcspn(geo + 5, "-"),
                           geo + 5, HFVIS_PARTIAL_MAX_TAG);
            goto done;
        }
        if (cli_geo_decode_token(geo, &run.geo)) {
            rc = cli_error(CLI_EXIT_ERROR, names[0], "damaged part: its georeference (geo=) does not "
                           "decode");
            goto done;
        }
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
    ex_georef_free(&run.geo);
    for (i = 0; i < nparts; i++) free(meta[i].tag);
    return rc;
}
