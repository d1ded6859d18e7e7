/* ========================================================================================== */
/* Incremental image-based multi-valued voxelization ([G12] ch. 7; spec voxel §4)             */
/*   IV.1 depth images, options, channel maps                                                 */
/*   IV.2 classification of a voxel centre: eq. 16 (sign restored), eq. 17 with the bias b,   */
/*        Fig. 70's three zones; the conservative footprint and its min-depth pyramid         */
/*   IV.3 cleanup (Alg. 7 "Cleanup", Listing 7.1) and single-pass IV (§7.4.3)                 */
/*   IV.4 injection (Listing 7.2), Alg. 7 as one frame, the lighting variant (§7.5)           */
/*   IV.5 Table 9 distance metric: exact point-triangle distance, two BVHs, seeded sampling   */
/* ========================================================================================== */

/* ---- IV.1 depth images, options, channel maps ------------------------------------------- */

#define VX_IV_STACK 256 /* BVH traversal stack (median splits: depth <= 33 for 2^32 items) */

/* Everything a pass needs of one image: the rows of view and proj*view that the classification
 * evaluates, as ((r[3] + r[2] z) + r[1] y) + r[0] x (the order the hoisted loops use). */
typedef struct vx_iv_img {
    double ez[4];             /* row 2 of view: eye-space z */
    double cx[4], cy[4], cw[4]; /* rows 0, 1, 3 of proj*view: clip x, y, w */
    double n, f;
    int ortho, w, h;
    const float *depth;
    const float *attr;
    int nattr;
    const float *pyr;         /* conservative footprint: min-depth pyramid levels 1.. or NULL */
    int levels;
    size_t lev_off[40];
    int lev_w[40], lev_h[40];
} vx_iv_img;

/* Resolved options. */
typedef struct vx_iv_opt {
    double bias;
    int conservative;
    int occ;                  /* occupancy channel or -1 */
    int gw, gh;
    const int *map;           /* explicit attribute map or NULL */
    const hfvis_allocator *alloc;
} vx_iv_opt;

HFVIS_API hfvis_iv_options hfvis_iv_options_default(void)
{
    hfvis_iv_options o;
    memset(&o, 0, sizeof o);
    o.bias_rule = HFVIS_IV_BIAS_HALF_DIAGONAL;
    o.bias = 0.0;
    o.footprint = HFVIS_IV_FOOTPRINT_CENTER;
    o.occupancy_channel = 0;
    o.attribute_channels = NULL;
    o.grid_width = 0;
    o.grid_height = 0;
    o.alloc = NULL;
    return o;
}

HFVIS_API double hfvis_iv_bias_half_diagonal(const hfvis_volume_grid *grid)
{
    if (!vx_grid_valid(grid)) return (double)NAN;
    return 0.5 * sqrt(grid->cell[0] * grid->cell[0] + grid->cell[1] * grid->cell[1]
                      + grid->cell[2] * grid->cell[2]);
}

HFVIS_API hfvis_status hfvis_iv_bias(const hfvis_volume_grid *grid, const hfvis_iv_options *opts,
                                     double *out)
{
    double b;
    hfvis_iv_bias_rule rule = opts ? opts->bias_rule : HFVIS_IV_BIAS_HALF_DIAGONAL;
    if (!out || !vx_grid_valid(grid)) return HFVIS_ERR_INVALID_ARGUMENT;
    switch (rule) {
    case HFVIS_IV_BIAS_HALF_DIAGONAL: b = hfvis_iv_bias_half_diagonal(grid); break;
    case HFVIS_IV_BIAS_FULL_DIAGONAL: b = 2.0 * hfvis_iv_bias_half_diagonal(grid); break;
    case HFVIS_IV_BIAS_EXPLICIT:
        b = opts->bias;
        if (!isfinite(b) || !(b >= 0.0)) return HFVIS_ERR_INVALID_ARGUMENT;
        break;
    default: return HFVIS_ERR_INVALID_ARGUMENT;
    }
    if (!isfinite(b)) return HFVIS_ERR_INVALID_ARGUMENT;
    *out = b;
    return HFVIS_OK;
}

/* 1 when vol is a usable Volume Buffer. */
static int vx_iv_volume_ok(const hfvis_volume *vol)
{
    return vol && vol->data && vol->channels >= 1 && vol->channels <= HFVIS_VOLUME_MAX_CHANNELS
           && hfvis_volume_size(&vol->grid, vol->channels) != 0;
}

static int vx_iv_same_grid(const hfvis_volume_grid *a, const hfvis_volume_grid *b)
{
    int i;
    for (i = 0; i < 3; i++)
        if (a->dims[i] != b->dims[i] || a->origin[i] != b->origin[i] || a->cell[i] != b->cell[i])
            return 0;
    return 1;
}

/* Options against a volume of `channels` channels (channels 0: no volume, e.g. classify); the
 * bias is resolved for grid. */
static hfvis_status vx_iv_resolve(const hfvis_iv_options *opts, const hfvis_volume_grid *grid,
                                  int channels, vx_iv_opt *o)
{
    hfvis_iv_options d = hfvis_iv_options_default();
    hfvis_status s;
    if (!opts) opts = &d;
    if (opts->footprint != HFVIS_IV_FOOTPRINT_CENTER
        && opts->footprint != HFVIS_IV_FOOTPRINT_CONSERVATIVE)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (opts->grid_width < 0 || opts->grid_height < 0) return HFVIS_ERR_INVALID_ARGUMENT;
    if (opts->occupancy_channel < HFVIS_IV_NO_CHANNEL
        || (channels > 0 && opts->occupancy_channel >= channels))
        return HFVIS_ERR_INVALID_ARGUMENT;
    s = hfvis_iv_bias(grid, opts, &o->bias);
    if (s != HFVIS_OK) return s;
    o->conservative = opts->footprint == HFVIS_IV_FOOTPRINT_CONSERVATIVE;
    o->occ = opts->occupancy_channel;
    o->gw = opts->grid_width;
    o->gh = opts->grid_height;
    o->map = opts->attribute_channels;
    o->alloc = opts->alloc;
    return HFVIS_OK;
}

/* Channel of attribute a (< nattr) for a volume of `channels` channels, written to map[a]
 * (-1 = dropped). HFVIS_ERR_INVALID_ARGUMENT when the map is bad (see hfvis_iv_options). */
static hfvis_status vx_iv_channel_map(const vx_iv_opt *o, int nattr, int channels, int *map)
{
    int a, b, c = 0;
    for (a = 0; a < nattr; a++) {
        if (o->map) {
            map[a] = o->map[a];
            if (map[a] < HFVIS_IV_NO_CHANNEL || map[a] >= channels
                || (map[a] >= 0 && map[a] == o->occ))
                return HFVIS_ERR_INVALID_ARGUMENT;
            for (b = 0; b < a; b++)
                if (map[a] >= 0 && map[b] == map[a]) return HFVIS_ERR_INVALID_ARGUMENT;
        } else {
            if (c == o->occ) c++;
            if (c >= channels) return HFVIS_ERR_INVALID_ARGUMENT;
            map[a] = c++;
        }
    }
    return HFVIS_OK;
}

/* Validate one depth image and fill the per-image rows. */
static hfvis_status vx_iv_image(const hfvis_depth_image *im, vx_iv_img *out)
{
    const hfvis_view *v;
    double m[16];
    size_t px, na;
    int r;
    if (!im || !im->depth) return HFVIS_ERR_INVALID_ARGUMENT;
    v = &im->view;
    if (v->width < 1 || v->height < 1 || !vx_all_finite(v->view, 16) || !vx_all_finite(v->proj, 16)
        || !isfinite(v->near_plane) || !isfinite(v->far_plane)
        || !(v->near_plane < v->far_plane) || (!v->orthographic && !(v->near_plane > 0.0)))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (im->attribute_count < 0 || im->attribute_count > HFVIS_VOLUME_MAX_CHANNELS
        || (im->attribute_count > 0 && !im->attributes))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (!vx_mul_size((size_t)v->width, (size_t)v->height, &px)
        || !vx_mul_size(px, (size_t)(im->attribute_count > 0 ? im->attribute_count : 1), &na))
        return HFVIS_ERR_INVALID_ARGUMENT;
    hfvis_mat4_multiply(v->proj, v->view, m);
    if (!vx_all_finite(m, 16)) return HFVIS_ERR_INVALID_ARGUMENT;
    memset(out, 0, sizeof *out);
    for (r = 0; r < 4; r++) {
        out->ez[r] = VX_M(v->view, 2, r);
        out->cx[r] = VX_M(m, 0, r);
        out->cy[r] = VX_M(m, 1, r);
        out->cw[r] = VX_M(m, 3, r);
    }
    out->n = v->near_plane;
    out->f = v->far_plane;
    out->ortho = v->orthographic ? 1 : 0;
    out->w = v->width;
    out->h = v->height;
    out->depth = im->depth;
    out->attr = im->attribute_count > 0 ? im->attributes : NULL;
    out->nattr = im->attribute_count;
    return HFVIS_OK;
}

/* The affine row in the fixed evaluation order ((r3 + r2 z) + r1 y) + r0 x. */
static double vx_iv_row(const double r[4], double x, double y, double z)
{
    return ((r[3] + r[2] * z) + r[1] * y) + r[0] * x;
}

/* ---- IV.2 classification ---------------------------------------------------------------- */

/* A depth texel usable as information: zw in [0, 1] (NaN and out-of-range values are no-data). */
static int vx_iv_texel_ok(float zw)
{
    return zw >= 0.0f && zw <= 1.0f;
}

/* Eq. 17 against one valid texel zw, for a point of eye z ez: CLEARED if ez > z_e + b, else
 * KEPT for a background texel (zw = 1) or ez < z_e - b, else BAND; z_e by eq. 16 (sign restored,
 * hfvis_depth_to_eye_z) in double. The decision is that literal comparison; for perspective views
 * it is usually reached without the division of eq. 16: with D = f - zw (f - n) > 0,
 * ez - b - z_e = ((ez - b) D + n f) / D, so the sign of P = (ez - b) D + n f decides unless |P| is
 * within t = 1e-12 ((|ez| + b) D + 2 n f) - about 10^4 times the rounding of both forms - and
 * likewise Q = (ez + b) D + n f for the band; inside t the literal form is evaluated. */
static hfvis_iv_class vx_iv_zone(const vx_iv_img *im, double b, double ez, float zw)
{
    double ze;
    if (!im->ortho) {
        double D = im->f - (double)zw * (im->f - im->n), nf = im->n * im->f;
        double P = (ez - b) * D + nf, Q = (ez + b) * D + nf;
        double t = 1e-12 * ((fabs(ez) + b) * D + 2.0 * nf);
        if (P > t) return HFVIS_IV_CLEARED;
        if (P < -t) {
            if (zw == 1.0f || Q < -t) return HFVIS_IV_KEPT;
            if (Q > t) return HFVIS_IV_BAND;
        }
    }
    ze = hfvis_depth_to_eye_z((double)zw, im->n, im->f, im->ortho); /* eq. 16, sign restored */
    if (ez > ze + b) return HFVIS_IV_CLEARED; /* eq. 17: in front of the recorded surface (v1) */
    if (zw == 1.0f) return HFVIS_IV_KEPT;     /* background: nothing to update */
    if (ez < ze - b) return HFVIS_IV_KEPT;    /* behind the surface (v3) */
    return HFVIS_IV_BAND;                     /* surface band (v2) */
}

/* The classification of a point with eye z `ez` and clip (X, Y, W) (spec voxel §4.3): UNSEEN
 * without information, else the zone of its texel. Writes the texel read (or -1, -1). */
static hfvis_iv_class vx_iv_decide(const vx_iv_img *im, double b, double ez, double X, double Y,
                                   double W, int *opx, int *opy)
{
    double inv, nx, ny, sx, sy;
    int px, py;
    float zw;
    *opx = -1;
    *opy = -1;
    /* behind the camera, or nearer than the near plane (NDC z < -1; no information) [C] */
    if (!(W > 0.0) || !(ez <= -im->n)) return HFVIS_IV_UNSEEN;
    inv = 1.0 / W;
    nx = X * inv;
    ny = Y * inv;
    if (!(nx >= -1.0 && nx <= 1.0 && ny >= -1.0 && ny <= 1.0)) return HFVIS_IV_UNSEEN;
    /* nearest texel, row 0 at the top: (floor((ndc_x+1)/2 W), floor((1-ndc_y)/2 H)), clamped */
    sx = (nx + 1.0) * 0.5 * (double)im->w;
    sy = (1.0 - ny) * 0.5 * (double)im->h;
    px = (int)sx; /* sx >= 0: truncation is floor */
    py = (int)sy;
    if (px > im->w - 1) px = im->w - 1;
    if (py > im->h - 1) py = im->h - 1;
    *opx = px;
    *opy = py;
    zw = im->depth[(size_t)py * (size_t)im->w + (size_t)px];
    if (!vx_iv_texel_ok(zw)) return HFVIS_IV_UNSEEN;
    return vx_iv_zone(im, b, ez, zw);
}

/* Offsets of the 8 corners of a voxel about its centre in one row: +-(r[0] hx), ... */
typedef struct vx_iv_corner_rows {
    double a[4][3]; /* [row: ez, X, Y, W][axis] = r[axis] * half_cell[axis] */
} vx_iv_corner_rows;

static void vx_iv_corner_setup(const vx_iv_img *im, const hfvis_volume_grid *g,
                               vx_iv_corner_rows *cr)
{
    int a;
    for (a = 0; a < 3; a++) {
        double h = 0.5 * g->cell[a];
        cr->a[0][a] = im->ez[a] * h;
        cr->a[1][a] = im->cx[a] * h;
        cr->a[2][a] = im->cy[a] * h;
        cr->a[3][a] = im->cw[a] * h;
    }
}

/* Minimum over a clipped pixel rectangle of the min-depth pyramid (sentinel -1 = no-data). */
static float vx_iv_pyr_min(const vx_iv_img *im, int x0, int x1, int y0, int y1)
{
    int L = 1, x, y;
    float m = 2.0f;
    while (L < im->levels && (((x1 >> L) - (x0 >> L)) > 1 || ((y1 >> L) - (y0 >> L)) > 1)) L++;
    HFVIS_ASSERT(L < im->levels); /* the top level is 1 x 1 */
    {
        const float *lev = im->pyr + im->lev_off[L];
        int lw = im->lev_w[L];
        for (y = y0 >> L; y <= (y1 >> L); y++)
            for (x = x0 >> L; x <= (x1 >> L); x++) {
                float v = lev[(size_t)y * (size_t)lw + (size_t)x];
                if (v < m) m = v;
            }
    }
    return m;
}

/* Conservative footprint (spec voxel §4.3 [C]): 1 if the clear of a voxel whose centre test
 * cleared is vetoed: a corner before the near plane or behind the camera, or a pixel whose
 * centre lies in the bounding box of the projected corners that is no-data or does not clear
 * (p'_z > z_e + b fails). With a pyramid, a rectangle whose minimum depth clears is accepted
 * without a scan: z_e(zw) falls as zw grows (every step of eq. 16 is monotone), so the minimum
 * clearing implies every texel clears (vx_iv_zone decides exactly as the literal form, whose
 * every step is monotone in zw), and the answer is the scan's bit for bit. */
static int vx_iv_veto(const vx_iv_img *im, const vx_iv_corner_rows *cr, double b, double ez,
                      double X, double Y, double W)
{
    double nx0 = HUGE_VAL, nx1 = -HUGE_VAL, ny0 = HUGE_VAL, ny1 = -HUGE_VAL;
    double fx0, fx1, fy0, fy1;
    int c, x0, x1, y0, y1, x, y;
    for (c = 0; c < 8; c++) {
        double sx = (c & 1) ? 1.0 : -1.0, sy = (c & 2) ? 1.0 : -1.0, sz = (c & 4) ? 1.0 : -1.0;
        double cez = ((ez + sx * cr->a[0][0]) + sy * cr->a[0][1]) + sz * cr->a[0][2];
        double cX = ((X + sx * cr->a[1][0]) + sy * cr->a[1][1]) + sz * cr->a[1][2];
        double cY = ((Y + sx * cr->a[2][0]) + sy * cr->a[2][1]) + sz * cr->a[2][2];
        double cW = ((W + sx * cr->a[3][0]) + sy * cr->a[3][1]) + sz * cr->a[3][2];
        double nx, ny;
        if (!(cW > 0.0) || !(cez <= -im->n)) return 1;
        nx = cX / cW;
        ny = cY / cW;
        if (nx < nx0) nx0 = nx;
        if (nx > nx1) nx1 = nx;
        if (ny < ny0) ny0 = ny;
        if (ny > ny1) ny1 = ny;
    }
    /* pixel x has its centre at window x + 0.5: centres in [sx0, sx1] are ceil(sx0 - 0.5) ..
     * floor(sx1 - 0.5); rows count from the top */
    fx0 = ceil((nx0 + 1.0) * 0.5 * (double)im->w - 0.5);
    fx1 = floor((nx1 + 1.0) * 0.5 * (double)im->w - 0.5);
    fy0 = ceil((1.0 - ny1) * 0.5 * (double)im->h - 0.5);
    fy1 = floor((1.0 - ny0) * 0.5 * (double)im->h - 0.5);
    if (!(fx0 >= 0.0)) fx0 = 0.0;
    if (!(fy0 >= 0.0)) fy0 = 0.0;
    if (!(fx1 <= (double)(im->w - 1))) fx1 = (double)(im->w - 1);
    if (!(fy1 <= (double)(im->h - 1))) fy1 = (double)(im->h - 1);
    if (fx0 > fx1 || fy0 > fy1) return 0; /* no pixel centre inside: the centre texel decided */
    x0 = (int)fx0;
    x1 = (int)fx1;
    y0 = (int)fy0;
    y1 = (int)fy1;
    if (im->pyr && (x1 - x0 > 1 || y1 - y0 > 1)) {
        float m = vx_iv_pyr_min(im, x0, x1, y0, y1);
        if (m >= 0.0f && vx_iv_zone(im, b, ez, m) == HFVIS_IV_CLEARED) return 0;
    }
    for (y = y0; y <= y1; y++) {
        const float *row = im->depth + (size_t)y * (size_t)im->w;
        for (x = x0; x <= x1; x++) {
            float zw = row[x];
            if (!vx_iv_texel_ok(zw)) return 1;
            if (vx_iv_zone(im, b, ez, zw) != HFVIS_IV_CLEARED) return 1;
        }
    }
    return 0;
}

/* Pyramid sizes of a w x h image (levels 1.. until 1 x 1); returns the float count, 0 on
 * overflow (never for valid images). */
static size_t vx_iv_pyr_layout(vx_iv_img *im)
{
    size_t total = 0, n;
    int L = 0, w = im->w, h = im->h;
    im->lev_w[0] = w;
    im->lev_h[0] = h;
    im->lev_off[0] = 0;
    while (w > 1 || h > 1) {
        w = (w + 1) / 2;
        h = (h + 1) / 2;
        L++;
        im->lev_w[L] = w;
        im->lev_h[L] = h;
        im->lev_off[L] = total;
        if (!vx_mul_size((size_t)w, (size_t)h, &n) || total > SIZE_MAX - n) return 0;
        total += n;
    }
    im->levels = L + 1;
    return total;
}

/* Fill the pyramid (min of each 2 x 2 block; level 0 is the image, no-data -> -1). */
static void vx_iv_pyr_build(vx_iv_img *im, float *store)
{
    int L, x, y;
    im->pyr = store;
    for (L = 1; L < im->levels; L++) {
        int pw = im->lev_w[L - 1], ph = im->lev_h[L - 1], w = im->lev_w[L], h = im->lev_h[L];
        const float *src = L == 1 ? im->depth : store + im->lev_off[L - 1];
        float *dst = store + im->lev_off[L];
        for (y = 0; y < h; y++)
            for (x = 0; x < w; x++) {
                float m = 2.0f;
                int dx, dy;
                for (dy = 0; dy < 2; dy++)
                    for (dx = 0; dx < 2; dx++) {
                        int sx = 2 * x + dx, sy = 2 * y + dy;
                        float v;
                        if (sx >= pw || sy >= ph) continue;
                        v = src[(size_t)sy * (size_t)pw + (size_t)sx];
                        if (L == 1 && !vx_iv_texel_ok(v)) v = -1.0f;
                        if (v < m) m = v;
                    }
                dst[(size_t)y * (size_t)w + (size_t)x] = m;
            }
    }
}

static void vx_iv_sample_set(const vx_iv_img *im, hfvis_iv_sample *out, hfvis_iv_class cls, int px,
                             int py, double ez)
{
    double ze = (double)NAN;
    if (px >= 0) {
        float zw = im->depth[(size_t)py * (size_t)im->w + (size_t)px];
        if (vx_iv_texel_ok(zw)) ze = hfvis_depth_to_eye_z((double)zw, im->n, im->f, im->ortho);
    }
    out->cls = cls;
    out->pixel_x = px;
    out->pixel_y = py;
    out->eye_z = ez;
    out->depth_eye_z = ze;
}

HFVIS_API hfvis_status hfvis_iv_classify(const hfvis_depth_image *image, const double point[3],
                                         double bias, hfvis_iv_sample *out)
{
    vx_iv_img im;
    double ez, X, Y, W;
    int px, py;
    hfvis_iv_class cls;
    if (!out || !point || !vx_all_finite(point, 3) || !isfinite(bias) || !(bias >= 0.0))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (vx_iv_image(image, &im) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    ez = vx_iv_row(im.ez, point[0], point[1], point[2]);
    X = vx_iv_row(im.cx, point[0], point[1], point[2]);
    Y = vx_iv_row(im.cy, point[0], point[1], point[2]);
    W = vx_iv_row(im.cw, point[0], point[1], point[2]);
    cls = vx_iv_decide(&im, bias, ez, X, Y, W, &px, &py);
    vx_iv_sample_set(&im, out, cls, px, py, ez);
    return HFVIS_OK;
}

/* Voxel centre coordinate along axis a (the one expression every path uses). */
static double vx_iv_centre(const hfvis_volume_grid *g, int a, int idx)
{
    return g->origin[a] + g->cell[a] * ((double)idx + 0.5);
}

HFVIS_API hfvis_status hfvis_iv_classify_voxel(const hfvis_depth_image *image,
                                               const hfvis_volume_grid *grid, int i, int j, int k,
                                               const hfvis_iv_options *opts,
                                               hfvis_iv_sample *out)
{
    vx_iv_img im;
    vx_iv_opt o;
    double x, y, z, ez, X, Y, W;
    int px, py;
    hfvis_iv_class cls;
    if (!out || !vx_grid_valid(grid) || i < 0 || j < 0 || k < 0 || i >= grid->dims[0]
        || j >= grid->dims[1] || k >= grid->dims[2])
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (vx_iv_resolve(opts, grid, 0, &o) != HFVIS_OK || vx_iv_image(image, &im) != HFVIS_OK)
        return HFVIS_ERR_INVALID_ARGUMENT;
    x = vx_iv_centre(grid, 0, i);
    y = vx_iv_centre(grid, 1, j);
    z = vx_iv_centre(grid, 2, k);
    ez = vx_iv_row(im.ez, x, y, z);
    X = vx_iv_row(im.cx, x, y, z);
    Y = vx_iv_row(im.cy, x, y, z);
    W = vx_iv_row(im.cw, x, y, z);
    cls = vx_iv_decide(&im, o.bias, ez, X, Y, W, &px, &py);
    if (cls == HFVIS_IV_CLEARED && o.conservative) {
        vx_iv_corner_rows cr;
        vx_iv_corner_setup(&im, grid, &cr);
        if (vx_iv_veto(&im, &cr, o.bias, ez, X, Y, W)) cls = HFVIS_IV_KEPT;
    }
    vx_iv_sample_set(&im, out, cls, px, py, ez);
    return HFVIS_OK;
}

/* ---- IV.3 cleanup and single pass --------------------------------------------------------- */

static int vx_iv_empty(const float *v, int channels)
{
    int c;
    for (c = 0; c < channels; c++)
        if (v[c] != 0.0f) return 0;
    return 1;
}

/* First index in [i, n) of a non-empty voxel of the row (C channels per voxel), or n: the first
 * non-zero float from voxel i on, tested in branch-free blocks of 8 floats (a cleanup pass over a
 * surface volume spends most of its time here). */
static int vx_iv_next_nonempty(const float *row, int i, int n, int C)
{
    size_t f = (size_t)i * (size_t)C, end = (size_t)n * (size_t)C;
    while (f + 8 <= end) {
        const float *v = row + f;
        int z = (v[0] == 0.0f) & (v[1] == 0.0f) & (v[2] == 0.0f) & (v[3] == 0.0f)
                & (v[4] == 0.0f) & (v[5] == 0.0f) & (v[6] == 0.0f) & (v[7] == 0.0f);
        if (!z) break;
        f += 8;
    }
    while (f < end && row[f] == 0.0f) f++;
    return (int)(f / (size_t)C);
}

/* Per-call counters. */
typedef struct vx_iv_count {
    size_t cls[4];
    size_t off, on, inj, bg, outside;
} vx_iv_count;

/* One image over the whole volume: src -> dst (src == dst in place). single: turn on the band
 * (§7.4.3), else cleanup only (Alg. 7 Cleanup). map: attribute -> channel for the band. Row by
 * row: the row is copied once (ping-pong), then only voxels that can change are visited (cleanup:
 * the non-empty ones; an empty voxel stays empty). The affine rows are hoisted per slab and row in
 * the order of vx_iv_row, so every voxel sees exactly hfvis_iv_classify_voxel's numbers. */
static void vx_iv_pass(const float *src, float *dst, const hfvis_volume_grid *g, int C,
                       const vx_iv_img *im, const vx_iv_opt *o, int single, const int *map,
                       vx_iv_count *cnt)
{
    const int nx = g->dims[0], ny = g->dims[1], nz = g->dims[2];
    const size_t cs = (size_t)C, row = (size_t)nx * cs;
    vx_iv_corner_rows cr;
    int i, j, k, c;
    size_t lin = 0;
    vx_iv_corner_setup(im, g, &cr);
    for (k = 0; k < nz; k++) {
        double z = vx_iv_centre(g, 2, k);
        double kez = im->ez[3] + im->ez[2] * z, kX = im->cx[3] + im->cx[2] * z;
        double kY = im->cy[3] + im->cy[2] * z, kW = im->cw[3] + im->cw[2] * z;
        for (j = 0; j < ny; j++, lin += (size_t)nx) {
            double y = vx_iv_centre(g, 1, j);
            double jez = kez + im->ez[1] * y, jX = kX + im->cx[1] * y;
            double jY = kY + im->cy[1] * y, jW = kW + im->cw[1] * y;
            const float *srow = src + lin * cs;
            float *drow = dst + lin * cs;
            if (drow != srow) memcpy(drow, srow, row * sizeof(float));
            for (i = 0; i < nx; i++) {
                float *d;
                double x, ez, X, Y, W;
                int px, py, empty;
                hfvis_iv_class cls;
                if (!single) { /* cleanup: an empty voxel stays empty */
                    i = vx_iv_next_nonempty(drow, i, nx, C);
                    if (i >= nx) break;
                }
                d = drow + (size_t)i * cs; /* holds the source values now */
                empty = single ? vx_iv_empty(d, C) : 0;
                x = vx_iv_centre(g, 0, i);
                ez = jez + im->ez[0] * x;
                X = jX + im->cx[0] * x;
                Y = jY + im->cy[0] * x;
                W = jW + im->cw[0] * x;
                cls = vx_iv_decide(im, o->bias, ez, X, Y, W, &px, &py);
                if (cls == HFVIS_IV_CLEARED && o->conservative
                    && vx_iv_veto(im, &cr, o->bias, ez, X, Y, W))
                    cls = HFVIS_IV_KEPT;
                cnt->cls[cls]++;
                if (cls == HFVIS_IV_CLEARED) {
                    if (!empty) {
                        for (c = 0; c < C; c++) d[c] = 0.0f;
                        cnt->off++;
                    }
                } else if (cls == HFVIS_IV_BAND && single) {
                    /* turn on / update with the centre texel's attributes (replace) */
                    int t;
                    if (im->nattr > 0) {
                        const float *a = im->attr + ((size_t)py * (size_t)im->w + (size_t)px)
                                                        * (size_t)im->nattr;
                        for (t = 0; t < im->nattr; t++)
                            if (map[t] >= 0) d[map[t]] = a[t];
                    }
                    if (o->occ >= 0) d[o->occ] = 1.0f;
                    if (empty && !vx_iv_empty(d, C)) cnt->on++;
                }
            }
        }
    }
}

/* Validates the arguments of cleanup / single pass and resolves everything. */
static hfvis_status vx_iv_pass_args(const hfvis_volume *prev, const hfvis_volume *curr,
                                    const hfvis_depth_image *images, size_t count,
                                    const hfvis_iv_options *opts, vx_iv_opt *o, int single)
{
    size_t t;
    if (!vx_iv_volume_ok(prev) || !vx_iv_volume_ok(curr) || (count > 0 && !images))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (prev->channels != curr->channels || !vx_iv_same_grid(&prev->grid, &curr->grid))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (vx_iv_resolve(opts, &prev->grid, prev->channels, o) != HFVIS_OK)
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (t = 0; t < count; t++) {
        vx_iv_img im;
        int map[HFVIS_VOLUME_MAX_CHANNELS];
        if (vx_iv_image(&images[t], &im) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
        if (single && vx_iv_channel_map(o, im.nattr, prev->channels, map) != HFVIS_OK)
            return HFVIS_ERR_INVALID_ARGUMENT;
    }
    return HFVIS_OK;
}

static void vx_iv_stats_out(const vx_iv_count *c, hfvis_iv_stats *stats)
{
    if (!stats) return;
    memset(stats, 0, sizeof *stats);
    stats->unseen = c->cls[HFVIS_IV_UNSEEN];
    stats->cleared = c->cls[HFVIS_IV_CLEARED];
    stats->band = c->cls[HFVIS_IV_BAND];
    stats->kept = c->cls[HFVIS_IV_KEPT];
    stats->turned_off = c->off;
    stats->turned_on = c->on;
    stats->points_injected = c->inj;
    stats->points_background = c->bg;
    stats->points_outside = c->outside;
}

/* Cleanup or single pass after validation: the pyramids (one block for all images), then the
 * images in order, the first reading prev and the others curr in place. */
static hfvis_status vx_iv_run(const hfvis_volume *prev, hfvis_volume *curr,
                              const hfvis_depth_image *images, size_t count, const vx_iv_opt *o,
                              int single, vx_iv_count *cnt)
{
    float *pyr = NULL;
    size_t t, total = 0, n = hfvis_volume_size(&prev->grid, prev->channels);
    if (o->conservative && count > 0) {
        for (t = 0; t < count; t++) {
            vx_iv_img im;
            size_t s;
            (void)vx_iv_image(&images[t], &im);
            s = vx_iv_pyr_layout(&im);
            if (s == 0 && (im.w > 1 || im.h > 1)) return HFVIS_ERR_INVALID_ARGUMENT;
            if (total > SIZE_MAX - s) return HFVIS_ERR_INVALID_ARGUMENT;
            total += s;
        }
        if (total > 0) {
            pyr = (float *)vx_alloc_array(o->alloc, total, sizeof(float));
            if (!pyr) return HFVIS_ERR_OUT_OF_MEMORY;
        }
    }
    if (count == 0 && curr->data != prev->data)
        for (t = 0; t < n; t++) curr->data[t] = prev->data[t];
    total = 0;
    for (t = 0; t < count; t++) {
        vx_iv_img im;
        int map[HFVIS_VOLUME_MAX_CHANNELS] = {0};
        (void)vx_iv_image(&images[t], &im);
        if (single) (void)vx_iv_channel_map(o, im.nattr, prev->channels, map);
        if (pyr) {
            size_t s = vx_iv_pyr_layout(&im);
            vx_iv_pyr_build(&im, pyr + total);
            total += s;
        }
        vx_iv_pass(t == 0 ? prev->data : curr->data, curr->data, &prev->grid, prev->channels, &im,
                   o, single, map, cnt);
    }
    vx_free(o->alloc, pyr);
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_iv_cleanup(const hfvis_volume *prev, hfvis_volume *curr,
                                        const hfvis_depth_image *images, size_t image_count,
                                        const hfvis_iv_options *opts, hfvis_iv_stats *stats)
{
    vx_iv_opt o;
    vx_iv_count cnt;
    hfvis_status s = vx_iv_pass_args(prev, curr, images, image_count, opts, &o, 0);
    if (s != HFVIS_OK) return s;
    memset(&cnt, 0, sizeof cnt);
    s = vx_iv_run(prev, curr, images, image_count, &o, 0, &cnt);
    if (s != HFVIS_OK) return s;
    vx_iv_stats_out(&cnt, stats);
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_iv_single_pass(const hfvis_volume *prev, hfvis_volume *curr,
                                            const hfvis_depth_image *images, size_t image_count,
                                            const hfvis_iv_options *opts, hfvis_iv_stats *stats)
{
    vx_iv_opt o;
    vx_iv_count cnt;
    hfvis_status s = vx_iv_pass_args(prev, curr, images, image_count, opts, &o, 1);
    if (s != HFVIS_OK) return s;
    memset(&cnt, 0, sizeof cnt);
    s = vx_iv_run(prev, curr, images, image_count, &o, 1, &cnt);
    if (s != HFVIS_OK) return s;
    vx_iv_stats_out(&cnt, stats);
    return HFVIS_OK;
}

/* ---- IV.4 injection, one frame, lighting ---------------------------------------------------- */

/* Validate the injection arguments (everything that can fail). */
static hfvis_status vx_iv_inject_args(const hfvis_volume *vol, const hfvis_depth_image *images,
                                      size_t count, const vx_iv_opt *o)
{
    size_t t;
    int c, map[HFVIS_VOLUME_MAX_CHANNELS];
    if (!vx_iv_volume_ok(vol) || (count > 0 && !images)) return HFVIS_ERR_INVALID_ARGUMENT;
    for (c = 0; c < vol->channels; c++)
        if (!vx_blend_valid(vol->blend[c])) return HFVIS_ERR_INVALID_ARGUMENT;
    for (t = 0; t < count; t++) {
        vx_iv_img im;
        double m[16], inv[16];
        if (vx_iv_image(&images[t], &im) != HFVIS_OK
            || vx_iv_channel_map(o, im.nattr, vol->channels, map) != HFVIS_OK)
            return HFVIS_ERR_INVALID_ARGUMENT;
        hfvis_mat4_multiply(images[t].view.proj, images[t].view.view, m);
        if (hfvis_mat4_invert(m, inv) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    }
    return HFVIS_OK;
}

/* Listing 7.2 for validated arguments. */
static void vx_iv_inject_run(hfvis_volume *vol, const hfvis_depth_image *images, size_t count,
                             const vx_iv_opt *o, vx_iv_count *cnt)
{
    const hfvis_volume_grid *g = &vol->grid;
    const size_t cs = (size_t)vol->channels;
    size_t t;
    for (t = 0; t < count; t++) {
        vx_iv_img im;
        double m[16], inv[16];
        int map[HFVIS_VOLUME_MAX_CHANNELS], gx, gy, gw, gh;
        (void)vx_iv_image(&images[t], &im);
        (void)vx_iv_channel_map(o, im.nattr, vol->channels, map);
        hfvis_mat4_multiply(images[t].view.proj, images[t].view.view, m);
        (void)hfvis_mat4_invert(m, inv);
        gw = o->gw > 0 ? o->gw : im.w;
        gh = o->gh > 0 ? o->gh : im.h;
        for (gy = 0; gy < gh; gy++) {
            double v = ((double)gy + 0.5) / (double)gh;
            int py = (int)(v * (double)im.h);
            if (py > im.h - 1) py = im.h - 1;
            for (gx = 0; gx < gw; gx++) {
                double u = ((double)gx + 0.5) / (double)gw, ndc[4], hp[4], p[3];
                int px = (int)(u * (double)im.w), idx[3], a, ok = 1;
                size_t pix;
                float zw, *d;
                if (px > im.w - 1) px = im.w - 1;
                pix = (size_t)py * (size_t)im.w + (size_t)px;
                zw = im.depth[pix];
                if (!(zw >= 0.0f && zw < 1.0f)) { /* background or no-data: no sample */
                    cnt->bg++;
                    continue;
                }
                /* canonical screen space -> world (PointCSS2WCS: inverse view-projection) */
                ndc[0] = 2.0 * u - 1.0;
                ndc[1] = 1.0 - 2.0 * v;
                ndc[2] = 2.0 * (double)zw - 1.0;
                ndc[3] = 1.0;
                vx_mat4_apply(inv, ndc, hp);
                if (!(hp[3] != 0.0)) {
                    cnt->outside++;
                    continue;
                }
                for (a = 0; a < 3; a++) {
                    double q;
                    p[a] = hp[a] / hp[3];
                    q = (p[a] - g->origin[a]) / g->cell[a];
                    if (!(q >= 0.0 && q < (double)g->dims[a])) {
                        ok = 0;
                        break;
                    }
                    idx[a] = (int)q;
                    if (idx[a] > g->dims[a] - 1) idx[a] = g->dims[a] - 1;
                }
                if (!ok) {
                    cnt->outside++;
                    continue;
                }
                d = vol->data + (((size_t)idx[2] * (size_t)g->dims[1] + (size_t)idx[1])
                                     * (size_t)g->dims[0]
                                 + (size_t)idx[0])
                                    * cs;
                if (im.nattr > 0) {
                    const float *at = im.attr + pix * (size_t)im.nattr;
                    for (a = 0; a < im.nattr; a++)
                        if (map[a] >= 0) d[map[a]] = vx_blend_apply(vol->blend[map[a]], d[map[a]], at[a]);
                }
                if (o->occ >= 0) d[o->occ] = vx_blend_apply(vol->blend[o->occ], d[o->occ], 1.0f);
                cnt->inj++;
            }
        }
    }
}

HFVIS_API hfvis_status hfvis_iv_inject(hfvis_volume *vol, const hfvis_depth_image *images,
                                       size_t image_count, const hfvis_iv_options *opts,
                                       hfvis_iv_stats *stats)
{
    vx_iv_opt o;
    vx_iv_count cnt;
    if (!vx_iv_volume_ok(vol) || vx_iv_resolve(opts, &vol->grid, vol->channels, &o) != HFVIS_OK
        || vx_iv_inject_args(vol, images, image_count, &o) != HFVIS_OK)
        return HFVIS_ERR_INVALID_ARGUMENT;
    memset(&cnt, 0, sizeof cnt);
    vx_iv_inject_run(vol, images, image_count, &o, &cnt);
    vx_iv_stats_out(&cnt, stats);
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_iv_update(const hfvis_volume *prev, hfvis_volume *curr,
                                       const hfvis_depth_image *images, size_t image_count,
                                       const hfvis_iv_options *opts, hfvis_iv_stats *stats)
{
    vx_iv_opt o;
    vx_iv_count cnt;
    hfvis_status s = vx_iv_pass_args(prev, curr, images, image_count, opts, &o, 0);
    if (s != HFVIS_OK) return s;
    if (vx_iv_inject_args(curr, images, image_count, &o) != HFVIS_OK)
        return HFVIS_ERR_INVALID_ARGUMENT;
    memset(&cnt, 0, sizeof cnt);
    s = vx_iv_run(prev, curr, images, image_count, &o, 0, &cnt); /* all cleanups (Alg. 7) */
    if (s != HFVIS_OK) return s;
    vx_iv_inject_run(curr, images, image_count, &o, &cnt);       /* then all injections */
    vx_iv_stats_out(&cnt, stats);
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_iv_replace_nonempty(hfvis_volume *curr,
                                                 const hfvis_volume *injection,
                                                 const int *channels, int channel_count,
                                                 const hfvis_iv_options *opts, size_t *replaced)
{
    int list[HFVIS_VOLUME_MAX_CHANNELS], n, a, b, occ, C;
    size_t v, nv, count = 0;
    if (!vx_iv_volume_ok(curr) || !vx_iv_volume_ok(injection)
        || curr->channels != injection->channels || !vx_iv_same_grid(&curr->grid, &injection->grid))
        return HFVIS_ERR_INVALID_ARGUMENT;
    C = curr->channels;
    occ = opts ? opts->occupancy_channel : 0;
    if (occ < HFVIS_IV_NO_CHANNEL || occ >= C) return HFVIS_ERR_INVALID_ARGUMENT;
    if (channels) {
        if (channel_count < 1 || channel_count > C) return HFVIS_ERR_INVALID_ARGUMENT;
        for (a = 0; a < channel_count; a++) {
            if (channels[a] < 0 || channels[a] >= C) return HFVIS_ERR_INVALID_ARGUMENT;
            for (b = 0; b < a; b++)
                if (channels[b] == channels[a]) return HFVIS_ERR_INVALID_ARGUMENT;
            list[a] = channels[a];
        }
        n = channel_count;
    } else {
        for (a = 0; a < C; a++) list[a] = a;
        n = C;
    }
    nv = vx_grid_voxels(&curr->grid);
    for (v = 0; v < nv; v++) {
        const float *s = injection->data + v * (size_t)C;
        float *d = curr->data + v * (size_t)C;
        if (occ >= 0 ? s[occ] == 0.0f : vx_iv_empty(s, C)) continue;
        for (a = 0; a < n; a++) d[list[a]] = s[list[a]];
        count++;
    }
    if (replaced) *replaced = count;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_iv_occupancy(const hfvis_volume *vol, int channel, uint8_t *out,
                                          size_t *count)
{
    size_t v, nv, n = 0;
    if (!vx_iv_volume_ok(vol) || !out || channel < HFVIS_IV_NO_CHANNEL || channel >= vol->channels)
        return HFVIS_ERR_INVALID_ARGUMENT;
    nv = vx_grid_voxels(&vol->grid);
    for (v = 0; v < nv; v++) {
        const float *s = vol->data + v * (size_t)vol->channels;
        int on = channel >= 0 ? s[channel] != 0.0f : !vx_iv_empty(s, vol->channels);
        out[v] = (uint8_t)(on ? 1 : 0);
        n += (size_t)on;
    }
    if (count) *count = n;
    return HFVIS_OK;
}

/* ---- IV.5 Table 9 distance metric --------------------------------------------------------- */

/* Squared distance from p to triangle (a, b, c): the closest point by Voronoi regions
 * (Ericson, Real-Time Collision Detection §5.1.5), in double. A degenerate triangle (zero
 * cross product) is the union of its edges. */
static double vx_iv_seg_d2(const double p[3], const double a[3], const double b[3])
{
    double ab[3], ap[3], t, l2, q, d2 = 0.0;
    int i;
    for (i = 0; i < 3; i++) ab[i] = b[i] - a[i], ap[i] = p[i] - a[i];
    l2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
    t = l2 > 0.0 ? (ab[0] * ap[0] + ab[1] * ap[1] + ab[2] * ap[2]) / l2 : 0.0;
    if (!(t > 0.0)) t = 0.0;
    if (t > 1.0) t = 1.0;
    for (i = 0; i < 3; i++) {
        q = p[i] - (a[i] + t * ab[i]);
        d2 += q * q;
    }
    return d2;
}

static double vx_iv_tri_d2(const double p[3], const double a[3], const double b[3],
                           const double c[3])
{
    double ab[3], ac[3], ap[3], bp[3], cp[3], q[3], n[3];
    double d1, d2, d3, d4, d5, d6, va, vb, vc, v, w, den, r = 0.0;
    int i;
    for (i = 0; i < 3; i++) {
        ab[i] = b[i] - a[i];
        ac[i] = c[i] - a[i];
        ap[i] = p[i] - a[i];
        bp[i] = p[i] - b[i];
        cp[i] = p[i] - c[i];
    }
    n[0] = ab[1] * ac[2] - ab[2] * ac[1];
    n[1] = ab[2] * ac[0] - ab[0] * ac[2];
    n[2] = ab[0] * ac[1] - ab[1] * ac[0];
    if (n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0) {
        double s0 = vx_iv_seg_d2(p, a, b), s1 = vx_iv_seg_d2(p, b, c), s2 = vx_iv_seg_d2(p, c, a);
        if (s1 < s0) s0 = s1;
        return s2 < s0 ? s2 : s0;
    }
    d1 = ab[0] * ap[0] + ab[1] * ap[1] + ab[2] * ap[2];
    d2 = ac[0] * ap[0] + ac[1] * ap[1] + ac[2] * ap[2];
    d3 = ab[0] * bp[0] + ab[1] * bp[1] + ab[2] * bp[2];
    d4 = ac[0] * bp[0] + ac[1] * bp[1] + ac[2] * bp[2];
    d5 = ab[0] * cp[0] + ab[1] * cp[1] + ab[2] * cp[2];
    d6 = ac[0] * cp[0] + ac[1] * cp[1] + ac[2] * cp[2];
    vc = d1 * d4 - d3 * d2;
    vb = d5 * d2 - d1 * d6;
    va = d3 * d6 - d5 * d4;
    if (d1 <= 0.0 && d2 <= 0.0) { /* vertex region a */
        for (i = 0; i < 3; i++) q[i] = a[i];
    } else if (d3 >= 0.0 && d4 <= d3) { /* vertex region b */
        for (i = 0; i < 3; i++) q[i] = b[i];
    } else if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) { /* edge ab */
        v = d1 / (d1 - d3);
        for (i = 0; i < 3; i++) q[i] = a[i] + v * ab[i];
    } else if (d6 >= 0.0 && d5 <= d6) { /* vertex region c */
        for (i = 0; i < 3; i++) q[i] = c[i];
    } else if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) { /* edge ac */
        w = d2 / (d2 - d6);
        for (i = 0; i < 3; i++) q[i] = a[i] + w * ac[i];
    } else if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) { /* edge bc */
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        for (i = 0; i < 3; i++) q[i] = b[i] + w * (c[i] - b[i]);
    } else { /* face: barycentric (1 - v - w, v, w) */
        den = va + vb + vc;
        if (!(den > 0.0)) { /* rounding on a sliver: fall back to the edges */
            double s0 = vx_iv_seg_d2(p, a, b), s1 = vx_iv_seg_d2(p, b, c), s2 = vx_iv_seg_d2(p, c, a);
            if (s1 < s0) s0 = s1;
            return s2 < s0 ? s2 : s0;
        }
        v = vb / den;
        w = vc / den;
        for (i = 0; i < 3; i++) q[i] = a[i] + ab[i] * v + ac[i] * w;
    }
    for (i = 0; i < 3; i++) r += (p[i] - q[i]) * (p[i] - q[i]);
    return r;
}

HFVIS_API double hfvis_point_triangle_distance(const double p[3], const double a[3],
                                               const double b[3], const double c[3])
{
    if (!p || !a || !b || !c) return (double)NAN;
    return sqrt(vx_iv_tri_d2(p, a, b, c));
}

/* PCG32 (O'Neill 2014), the library's own small PRNG. */
typedef struct vx_iv_rng {
    uint64_t state, inc;
} vx_iv_rng;

static uint32_t vx_iv_rng_next(vx_iv_rng *r)
{
    uint64_t old = r->state;
    uint32_t xs, rot;
    r->state = old * 6364136223846793005ull + r->inc;
    xs = (uint32_t)(((old >> 18) ^ old) >> 27);
    rot = (uint32_t)(old >> 59);
    return (xs >> rot) | (xs << ((32u - rot) & 31u));
}

static void vx_iv_rng_seed(vx_iv_rng *r, uint64_t seed)
{
    r->state = 0u;
    r->inc = (0xda3e39cb94b95bdbull << 1u) | 1u;
    (void)vx_iv_rng_next(r);
    r->state += seed ^ 0x853c49e6748fea9bull;
    (void)vx_iv_rng_next(r);
}

/* Uniform double in [0, 1) with 53 random bits. */
static double vx_iv_rng_unit(vx_iv_rng *r)
{
    uint32_t a = vx_iv_rng_next(r) >> 5, b = vx_iv_rng_next(r) >> 6;
    return ((double)a * 67108864.0 + (double)b) * (1.0 / 9007199254740992.0);
}

/* Shared set-up of the metric: the positive-area triangles, their area prefix sums, the voxel
 * centres, the bounding-box diagonal and a coordinate scale for the pruning margin. */
typedef struct vx_iv_metric {
    const hfvis_mesh *mesh;
    uint32_t *tris;  /* ids of positive-area triangles */
    double *cdf;     /* inclusive prefix sums of their areas */
    size_t nt;
    double *pts;     /* voxel centres, 3 per point */
    size_t np;
    double diag, scale2;
    size_t samples;
    uint64_t seed;
    const hfvis_allocator *alloc;
} vx_iv_metric;

static void vx_iv_tri_vertices(const hfvis_mesh *m, size_t t, double v[3][3])
{
    int c, a;
    for (c = 0; c < 3; c++) {
        const float *p = m->xyz + 3 * (size_t)m->indices[3 * t + (size_t)c];
        for (a = 0; a < 3; a++) v[c][a] = (double)p[a];
    }
}

static void vx_iv_metric_free(vx_iv_metric *M)
{
    vx_free(M->alloc, M->pts);
    vx_free(M->alloc, M->cdf);
    vx_free(M->alloc, M->tris);
    M->pts = NULL;
    M->cdf = NULL;
    M->tris = NULL;
}

/* Validates and builds the set-up (3 blocks: triangle ids, prefix sums, centres). */
static hfvis_status vx_iv_metric_init(vx_iv_metric *M, const hfvis_mesh *mesh,
                                      const hfvis_volume_grid *grid, const uint8_t *occ,
                                      const hfvis_distance_options *opts)
{
    size_t t, nv, v, nt = 0, np = 0;
    double lo[3], hi[3], sum = 0.0, s = 0.0, e[3];
    int a;
    memset(M, 0, sizeof *M);
    if (!occ || !vx_grid_valid(grid) || vx_mesh_check(mesh) != HFVIS_OK)
        return HFVIS_ERR_INVALID_ARGUMENT;
    M->mesh = mesh;
    M->samples = opts && opts->sample_count ? opts->sample_count : 100000;
    M->seed = opts ? opts->seed : 0u;
    M->alloc = opts ? opts->alloc : NULL;
    if (mesh->triangle_count > (size_t)UINT32_MAX / 2) return HFVIS_ERR_LIMIT;
    for (a = 0; a < 3; a++) lo[a] = HUGE_VAL, hi[a] = -HUGE_VAL;
    for (t = 0; t < mesh->triangle_count; t++) {
        double p[3][3], u[3], w[3], n[3];
        int c;
        vx_iv_tri_vertices(mesh, t, p);
        for (c = 0; c < 3; c++)
            for (a = 0; a < 3; a++) {
                if (p[c][a] < lo[a]) lo[a] = p[c][a];
                if (p[c][a] > hi[a]) hi[a] = p[c][a];
            }
        for (a = 0; a < 3; a++) u[a] = p[1][a] - p[0][a], w[a] = p[2][a] - p[0][a];
        n[0] = u[1] * w[2] - u[2] * w[1];
        n[1] = u[2] * w[0] - u[0] * w[2];
        n[2] = u[0] * w[1] - u[1] * w[0];
        if (n[0] != 0.0 || n[1] != 0.0 || n[2] != 0.0) nt++;
    }
    nv = vx_grid_voxels(grid);
    for (v = 0; v < nv; v++) np += occ[v] != 0;
    if (nt == 0 || np == 0) return HFVIS_ERR_INVALID_ARGUMENT;
    if (np > (size_t)UINT32_MAX / 2 || np > SIZE_MAX / 6 || nt > SIZE_MAX / 6) return HFVIS_ERR_LIMIT;
    for (a = 0; a < 3; a++) {
        double m1 = fabs(lo[a]) > fabs(hi[a]) ? fabs(lo[a]) : fabs(hi[a]);
        double g0 = fabs(grid->origin[a]), g1 = fabs(grid->origin[a] + grid->cell[a] * (double)grid->dims[a]);
        if (g0 > m1) m1 = g0;
        if (g1 > m1) m1 = g1;
        s += m1 * m1;
        e[a] = hi[a] - lo[a];
    }
    M->diag = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
    M->scale2 = s;
    M->tris = (uint32_t *)vx_alloc_array(M->alloc, nt, sizeof(uint32_t));
    if (!M->tris) return HFVIS_ERR_OUT_OF_MEMORY;
    M->cdf = (double *)vx_alloc_array(M->alloc, nt, sizeof(double));
    M->pts = (double *)vx_alloc_array(M->alloc, 3 * np, sizeof(double));
    if (!M->cdf || !M->pts) {
        vx_iv_metric_free(M);
        return HFVIS_ERR_OUT_OF_MEMORY;
    }
    M->nt = 0;
    for (t = 0; t < mesh->triangle_count; t++) {
        double p[3][3], u[3], w[3], n[3], area;
        vx_iv_tri_vertices(mesh, t, p);
        for (a = 0; a < 3; a++) u[a] = p[1][a] - p[0][a], w[a] = p[2][a] - p[0][a];
        n[0] = u[1] * w[2] - u[2] * w[1];
        n[1] = u[2] * w[0] - u[0] * w[2];
        n[2] = u[0] * w[1] - u[1] * w[0];
        if (n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0) continue;
        area = 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        sum += area;
        M->tris[M->nt] = (uint32_t)t;
        M->cdf[M->nt] = sum;
        M->nt++;
    }
    if (!(sum > 0.0) || !isfinite(sum)) {
        vx_iv_metric_free(M);
        return HFVIS_ERR_INVALID_ARGUMENT;
    }
    M->np = 0;
    {
        int i, j, k;
        size_t lin = 0;
        for (k = 0; k < grid->dims[2]; k++)
            for (j = 0; j < grid->dims[1]; j++)
                for (i = 0; i < grid->dims[0]; i++, lin++) {
                    if (!occ[lin]) continue;
                    M->pts[3 * M->np + 0] = vx_iv_centre(grid, 0, i);
                    M->pts[3 * M->np + 1] = vx_iv_centre(grid, 1, j);
                    M->pts[3 * M->np + 2] = vx_iv_centre(grid, 2, k);
                    M->np++;
                }
    }
    return HFVIS_OK;
}

/* Sample s of the mesh (the same sequence for the fast path and the oracle). */
static void vx_iv_metric_sample(const vx_iv_metric *M, vx_iv_rng *r, double out[3])
{
    double u = vx_iv_rng_unit(r) * M->cdf[M->nt - 1], r2 = vx_iv_rng_unit(r), r3 = vx_iv_rng_unit(r);
    double v[3][3], su = sqrt(r2), w0 = 1.0 - su, w1 = su * (1.0 - r3), w2 = su * r3;
    size_t lo = 0, hi = M->nt - 1;
    int a;
    while (lo < hi) { /* first prefix sum > u */
        size_t mid = lo + (hi - lo) / 2;
        if (M->cdf[mid] > u) hi = mid;
        else lo = mid + 1;
    }
    vx_iv_tri_vertices(M->mesh, (size_t)M->tris[lo], v);
    for (a = 0; a < 3; a++) out[a] = (w0 * v[0][a] + w1 * v[1][a]) + w2 * v[2][a];
}

static double vx_iv_pt_d2(const double p[3], const double q[3])
{
    double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
    return (dx * dx + dy * dy) + dz * dz;
}

/* A bounding-volume hierarchy over items with boxes (median split of the centroids along the
 * longest axis, up to 4 items per leaf). Inner node: count 0, children first and first + 1. */
typedef struct vx_iv_node {
    double lo[3], hi[3];
    uint32_t first, count;
} vx_iv_node;

typedef struct vx_iv_bvh {
    vx_iv_node *nodes;
    uint32_t *items;
    void *block;
} vx_iv_bvh;

/* Reorders items[first..first+count) so that position first+mid holds the element of rank mid by
 * key (lo + hi on axis a), smaller before, larger after (Hoare quickselect, median of three). */
static void vx_iv_select(uint32_t *it, size_t first, size_t count, size_t mid, const double *lo,
                         const double *hi, int a)
{
    size_t l = first, r = first + count - 1, want = first + mid;
    while (r > l) {
        size_t i = l, j = r, m = l + (r - l) / 2;
        double k0 = lo[3 * (size_t)it[l] + (size_t)a] + hi[3 * (size_t)it[l] + (size_t)a];
        double k1 = lo[3 * (size_t)it[m] + (size_t)a] + hi[3 * (size_t)it[m] + (size_t)a];
        double k2 = lo[3 * (size_t)it[r] + (size_t)a] + hi[3 * (size_t)it[r] + (size_t)a];
        double piv = k0 < k1 ? (k1 < k2 ? k1 : (k0 < k2 ? k2 : k0)) : (k0 < k2 ? k0 : (k1 < k2 ? k2 : k1));
        for (;;) {
            uint32_t tmp;
            while (lo[3 * (size_t)it[i] + (size_t)a] + hi[3 * (size_t)it[i] + (size_t)a] < piv) i++;
            while (lo[3 * (size_t)it[j] + (size_t)a] + hi[3 * (size_t)it[j] + (size_t)a] > piv) j--;
            if (i >= j) break;
            tmp = it[i];
            it[i] = it[j];
            it[j] = tmp;
            i++;
            j--;
        }
        /* now [l, j] <= piv <= [j+1, r] */
        if (want <= j) r = j;
        else l = j + 1;
    }
}

/* Builds over n >= 1 items with boxes lo/hi (3 doubles each). One block. */
static hfvis_status vx_iv_bvh_build(vx_iv_bvh *b, size_t n, const double *lo, const double *hi,
                                    const hfvis_allocator *alloc)
{
    size_t nn = 2 * n, bytes_nodes, bytes_items, used = 1, sp = 0, i;
    uint32_t stack[VX_IV_STACK];
    memset(b, 0, sizeof *b);
    if (n > (size_t)UINT32_MAX / 2) return HFVIS_ERR_LIMIT;
    if (!vx_mul_size(nn, sizeof(vx_iv_node), &bytes_nodes)
        || !vx_mul_size(n, sizeof(uint32_t), &bytes_items) || bytes_nodes > SIZE_MAX - bytes_items)
        return HFVIS_ERR_LIMIT;
    b->block = vx_alloc(alloc, bytes_nodes + bytes_items);
    if (!b->block) return HFVIS_ERR_OUT_OF_MEMORY;
    b->nodes = (vx_iv_node *)b->block;
    b->items = (uint32_t *)(void *)((unsigned char *)b->block + bytes_nodes);
    for (i = 0; i < n; i++) b->items[i] = (uint32_t)i;
    b->nodes[0].first = 0;
    b->nodes[0].count = (uint32_t)n;
    stack[sp++] = 0;
    while (sp > 0) {
        vx_iv_node *nd = &b->nodes[stack[--sp]];
        size_t first = nd->first, count = nd->count, mid;
        double clo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, chi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
        int a, axis = 0;
        for (a = 0; a < 3; a++) nd->lo[a] = HUGE_VAL, nd->hi[a] = -HUGE_VAL;
        for (i = first; i < first + count; i++) {
            size_t it = (size_t)b->items[i];
            for (a = 0; a < 3; a++) {
                double c = lo[3 * it + (size_t)a] + hi[3 * it + (size_t)a];
                if (lo[3 * it + (size_t)a] < nd->lo[a]) nd->lo[a] = lo[3 * it + (size_t)a];
                if (hi[3 * it + (size_t)a] > nd->hi[a]) nd->hi[a] = hi[3 * it + (size_t)a];
                if (c < clo[a]) clo[a] = c;
                if (c > chi[a]) chi[a] = c;
            }
        }
        if (count <= 4) continue; /* leaf */
        for (a = 1; a < 3; a++)
            if (chi[a] - clo[a] > chi[axis] - clo[axis]) axis = a;
        mid = count / 2;
        vx_iv_select(b->items, first, count, mid, lo, hi, axis);
        HFVIS_ASSERT(used + 2 <= nn && sp + 2 <= VX_IV_STACK);
        nd->first = (uint32_t)used;
        nd->count = 0;
        b->nodes[used].first = (uint32_t)first;
        b->nodes[used].count = (uint32_t)mid;
        b->nodes[used + 1].first = (uint32_t)(first + mid);
        b->nodes[used + 1].count = (uint32_t)(count - mid);
        stack[sp++] = (uint32_t)used;
        stack[sp++] = (uint32_t)(used + 1);
        used += 2;
    }
    return HFVIS_OK;
}

static double vx_iv_box_d2(const vx_iv_node *nd, const double p[3])
{
    double d2 = 0.0;
    int a;
    for (a = 0; a < 3; a++) {
        double g = 0.0;
        if (p[a] < nd->lo[a]) g = nd->lo[a] - p[a];
        else if (p[a] > nd->hi[a]) g = p[a] - nd->hi[a];
        d2 += g * g;
    }
    return d2;
}

/* Smallest squared distance from p to an item (tri: triangles of M, else voxel centres). A node
 * is skipped only when its box is farther than the best so far plus a margin far above the
 * rounding of the distances (1e-9 of best + coordinate scale^2), so the minimum is exactly the
 * brute-force minimum of the same per-item values. */
static double vx_iv_bvh_nearest(const vx_iv_bvh *b, const vx_iv_metric *M, int tri,
                                const double p[3])
{
    uint32_t stack[VX_IV_STACK];
    size_t sp = 0;
    double best = HUGE_VAL;
    stack[sp++] = 0;
    while (sp > 0) {
        const vx_iv_node *nd = &b->nodes[stack[--sp]];
        if (vx_iv_box_d2(nd, p) > best + 1e-9 * (best + M->scale2)) continue;
        if (nd->count > 0) {
            uint32_t i;
            for (i = nd->first; i < nd->first + nd->count; i++) {
                size_t it = (size_t)b->items[i];
                double d2;
                if (tri) {
                    double v[3][3];
                    vx_iv_tri_vertices(M->mesh, (size_t)M->tris[it], v);
                    d2 = vx_iv_tri_d2(p, v[0], v[1], v[2]);
                } else {
                    d2 = vx_iv_pt_d2(p, M->pts + 3 * it);
                }
                if (d2 < best) best = d2;
            }
        } else {
            double d0 = vx_iv_box_d2(&b->nodes[nd->first], p);
            double d1 = vx_iv_box_d2(&b->nodes[nd->first + 1], p);
            HFVIS_ASSERT(sp + 2 <= VX_IV_STACK);
            if (d0 <= d1) { /* nearer child popped first */
                stack[sp++] = nd->first + 1;
                stack[sp++] = nd->first;
            } else {
                stack[sp++] = nd->first;
                stack[sp++] = nd->first + 1;
            }
        }
    }
    return best;
}

static void vx_iv_metric_out(const vx_iv_metric *M, double sum_p, double max_p, double sum_s,
                             double max_s, hfvis_distance_metrics *out)
{
    hfvis_distance_metrics r;
    double mp = sum_p / (double)M->np, ms = sum_s / (double)M->samples;
    memset(&r, 0, sizeof r);
    r.mean_voxel_to_mesh = mp;
    r.max_voxel_to_mesh = max_p;
    r.mean_mesh_to_voxel = ms;
    r.max_mesh_to_voxel = max_s;
    r.hausdorff = max_p > max_s ? max_p : max_s;
    r.diagonal = M->diag;
    r.table9_percent = M->diag > 0.0 ? 100.0 * (mp > ms ? mp : ms) / M->diag : (double)NAN;
    r.voxel_count = M->np;
    r.sample_count = M->samples;
    *out = r;
}

HFVIS_API hfvis_status hfvis_voxel_distance_metrics(const hfvis_mesh *mesh,
                                                    const hfvis_volume_grid *grid,
                                                    const uint8_t *occupancy,
                                                    const hfvis_distance_options *opts,
                                                    hfvis_distance_metrics *out)
{
    vx_iv_metric M;
    vx_iv_bvh tb, pb;
    vx_iv_rng rng;
    double *box = NULL, sum_p = 0.0, max_p = 0.0, sum_s = 0.0, max_s = 0.0;
    size_t t, s;
    hfvis_status st;
    if (!out) return HFVIS_ERR_INVALID_ARGUMENT;
    st = vx_iv_metric_init(&M, mesh, grid, occupancy, opts);
    if (st != HFVIS_OK) return st;
    /* triangle boxes (lo: first 3 nt doubles, hi: next 3 nt) */
    box = (double *)vx_alloc_array(M.alloc, 6 * M.nt, sizeof(double));
    if (!box) {
        vx_iv_metric_free(&M);
        return HFVIS_ERR_OUT_OF_MEMORY;
    }
    for (t = 0; t < M.nt; t++) {
        double v[3][3];
        int a, c;
        vx_iv_tri_vertices(mesh, (size_t)M.tris[t], v);
        for (a = 0; a < 3; a++) {
            double l = v[0][a], h = v[0][a];
            for (c = 1; c < 3; c++) {
                if (v[c][a] < l) l = v[c][a];
                if (v[c][a] > h) h = v[c][a];
            }
            box[3 * t + (size_t)a] = l;
            box[3 * M.nt + 3 * t + (size_t)a] = h;
        }
    }
    st = vx_iv_bvh_build(&tb, M.nt, box, box + 3 * M.nt, M.alloc);
    if (st != HFVIS_OK) {
        vx_free(M.alloc, box);
        vx_iv_metric_free(&M);
        return st;
    }
    st = vx_iv_bvh_build(&pb, M.np, M.pts, M.pts, M.alloc);
    if (st != HFVIS_OK) {
        vx_free(M.alloc, tb.block);
        vx_free(M.alloc, box);
        vx_iv_metric_free(&M);
        return st;
    }
    /* Y -> X: every voxel centre to the mesh, exactly */
    for (s = 0; s < M.np; s++) {
        double d = sqrt(vx_iv_bvh_nearest(&tb, &M, 1, M.pts + 3 * s));
        sum_p += d;
        if (d > max_p) max_p = d;
    }
    /* X -> Y: area-uniform samples of the mesh to the nearest voxel centre */
    vx_iv_rng_seed(&rng, M.seed);
    for (s = 0; s < M.samples; s++) {
        double q[3], d;
        vx_iv_metric_sample(&M, &rng, q);
        d = sqrt(vx_iv_bvh_nearest(&pb, &M, 0, q));
        sum_s += d;
        if (d > max_s) max_s = d;
    }
    vx_iv_metric_out(&M, sum_p, max_p, sum_s, max_s, out);
    vx_free(M.alloc, pb.block);
    vx_free(M.alloc, tb.block);
    vx_free(M.alloc, box);
    vx_iv_metric_free(&M);
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_voxel_distance_metrics_naive(const hfvis_mesh *mesh,
                                                          const hfvis_volume_grid *grid,
                                                          const uint8_t *occupancy,
                                                          const hfvis_distance_options *opts,
                                                          hfvis_distance_metrics *out)
{
    vx_iv_metric M;
    vx_iv_rng rng;
    double sum_p = 0.0, max_p = 0.0, sum_s = 0.0, max_s = 0.0;
    size_t t, s;
    hfvis_status st;
    if (!out) return HFVIS_ERR_INVALID_ARGUMENT;
    st = vx_iv_metric_init(&M, mesh, grid, occupancy, opts);
    if (st != HFVIS_OK) return st;
    for (s = 0; s < M.np; s++) {
        double best = HUGE_VAL, d;
        for (t = 0; t < M.nt; t++) {
            double v[3][3], d2;
            vx_iv_tri_vertices(mesh, (size_t)M.tris[t], v);
            d2 = vx_iv_tri_d2(M.pts + 3 * s, v[0], v[1], v[2]);
            if (d2 < best) best = d2;
        }
        d = sqrt(best);
        sum_p += d;
        if (d > max_p) max_p = d;
    }
    vx_iv_rng_seed(&rng, M.seed);
    for (s = 0; s < M.samples; s++) {
        double q[3], best = HUGE_VAL, d;
        size_t p;
        vx_iv_metric_sample(&M, &rng, q);
        for (p = 0; p < M.np; p++) {
            double d2 = vx_iv_pt_d2(q, M.pts + 3 * p);
            if (d2 < best) best = d2;
        }
        d = sqrt(best);
        sum_s += d;
        if (d > max_s) max_s = d;
    }
    vx_iv_metric_out(&M, sum_p, max_p, sum_s, max_s, out);
    vx_iv_metric_free(&M);
    return HFVIS_OK;
}
