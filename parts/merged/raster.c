
/* ========================================================================================== */
/* Reference rasterizer (issue 4 "mesh infrastructure"; spec voxel §0 view conventions)       */
/* ========================================================================================== */
/* The fixed-function GPU pipeline on the CPU, as the thesis' ch. 7 camera and light views render
 * their depth and G-buffer images ([G12] §7.4.1-7.4.2; Listings 7.1-7.2 read them):
 *   vertex stage   c = proj * view * v (double), eye z kept for the linear depth;
 *   clipping       homogeneous Sutherland-Hodgman (Sutherland & Hodgman 1974) against the near
 *                  plane z = -w, and against guard-band planes only where needed;
 *   setup          snap to 1/256 pixel; orientation by the signed area;
 *   coverage       integer edge functions (Pineda 1988) at pixel centres, D3D top-left rule;
 *   interpolation  homogeneous 2D barycentrics of the unclipped triangle (Olano & Greer 1997,
 *                  "Triangle scan conversion using 2D homogeneous coordinates"):
 *                  for clip-space columns c_j = (x_j, y_j, w_j), r_j = c_{j+1} x c_{j+2},
 *                  a_j(p) = r_j . p / det with p = (x_ndc, y_ndc, 1) and det = r_0 . c_0;
 *                  b_j = a_j / sum a (perspective-correct), z_ndc = sum a_j z_j (affine in
 *                  screen space);
 *   depth test     LESS on zw = (z_ndc + 1)/2 in double, triangles in index order.
 * The oracle (hfvis_rasterize_reference) shoots a ray per pixel centre instead. */

#define VX_RASTER_SUB 256      /* 1 << HFVIS_RASTER_SUBPIXEL_BITS */
#define VX_RASTER_MAX_POLY 9   /* 3 vertices + at most one per clip plane (5 planes) */

/* Per-triangle interpolation setup shared by every fragment of the triangle. */
typedef struct vx_raster_tri {
    double r[9];        /* r_j = rows 3j..3j+2: a_j = (r_j . (px, py, 1)) / det */
    double zp[3];       /* z_ndc = zp . (px, py, 1) */
    double ze[3];       /* eye-space z of the three vertices */
    float normal[3];    /* normal output of this triangle */
    uint32_t id;
} vx_raster_tri;

/* Everything a fragment writes to. */
typedef struct vx_raster_ctx {
    const hfvis_raster_outputs *out;
    double *zbuf;         /* width*height, +INF = empty */
    const double *ndc_x;  /* NDC x of the pixel centres of each column */
    const double *ndc_y;  /* NDC y of each row */
    int width, height;
    int want_attr;        /* linear depth, normal or barycentrics requested */
} vx_raster_ctx;

/* NDC of pixel centres (hfvis_view): x_ndc = 2(x + 0.5)/width - 1, y_ndc = 1 - 2(y + 0.5)/height.
 * Shared by the rasterizer and its oracle. */
static double vx_raster_ndc_x(int x, int width)
{
    return 2.0 * ((double)x + 0.5) / (double)width - 1.0;
}
static double vx_raster_ndc_y(int y, int height)
{
    return 1.0 - 2.0 * ((double)y + 0.5) / (double)height;
}

HFVIS_API hfvis_raster_options hfvis_raster_options_default(void)
{
    hfvis_raster_options o;
    memset(&o, 0, sizeof o);
    o.alloc = NULL;
    o.cull = HFVIS_CULL_NONE;
    o.normal_space = HFVIS_NORMAL_WORLD;
    o.normal_toward_viewer = 0;
    return o;
}

/* Argument checks common to both rasterizers; *opt receives the resolved options. */
static hfvis_status vx_raster_check(const hfvis_mesh *mesh, const hfvis_view *view,
                                    const hfvis_raster_options *opts,
                                    const hfvis_raster_outputs *out, hfvis_raster_options *opt)
{
    size_t pixels;
    if (!mesh || !view || !out) return HFVIS_ERR_INVALID_ARGUMENT;
    if (mesh->triangle_count >= (size_t)HFVIS_NO_TRIANGLE) return HFVIS_ERR_LIMIT; /* ids */
    if (vx_mesh_check(mesh) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    *opt = opts ? *opts : hfvis_raster_options_default();
    if (opt->cull != HFVIS_CULL_NONE && opt->cull != HFVIS_CULL_BACK
        && opt->cull != HFVIS_CULL_FRONT)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (opt->normal_space != HFVIS_NORMAL_WORLD && opt->normal_space != HFVIS_NORMAL_EYE)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (opt->normal_toward_viewer != 0 && opt->normal_toward_viewer != 1)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (view->width < 1 || view->height < 1) return HFVIS_ERR_INVALID_ARGUMENT;
    if (!vx_all_finite(view->view, 16) || !vx_all_finite(view->proj, 16))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (!isfinite(view->near_plane) || !isfinite(view->far_plane)
        || !(view->near_plane < view->far_plane)
        || (!view->orthographic && !(view->near_plane > 0.0)))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (view->width > HFVIS_RASTER_MAX_SIZE || view->height > HFVIS_RASTER_MAX_SIZE)
        return HFVIS_ERR_LIMIT;
    if (!vx_mul_size((size_t)view->width, (size_t)view->height, &pixels))
        return HFVIS_ERR_LIMIT; /* cannot happen with the size limit; kept for the invariant */
    return HFVIS_OK;
}

/* Fill every requested plane with the empty values. */
static void vx_raster_clear(const hfvis_raster_outputs *out, size_t pixels)
{
    size_t i;
    if (out->linear_depth)
        for (i = 0; i < pixels; i++) out->linear_depth[i] = (float)HUGE_VAL;
    if (out->window_depth)
        for (i = 0; i < pixels; i++) out->window_depth[i] = 1.0f;
    if (out->triangle_id)
        for (i = 0; i < pixels; i++) out->triangle_id[i] = HFVIS_NO_TRIANGLE;
    if (out->coverage_count) memset(out->coverage_count, 0, pixels * sizeof(uint32_t));
    if (out->normal) memset(out->normal, 0, 3 * pixels * sizeof(float));
    if (out->barycentric) memset(out->barycentric, 0, 2 * pixels * sizeof(float));
}

/* The normal output of triangle (a, b, c) (world coordinates): normalize((b-a) x (c-a)) in the
 * requested frame, negated when flip. Returns 0 for a zero-area triangle. Shared by both
 * rasterizers, so their normals are bit-identical. */
static int vx_raster_normal(const float *a, const float *b, const float *c, const double view[16],
                            hfvis_normal_space space, int flip, float out[3])
{
    double e1[3], e2[3], n[3], len;
    int i;
    for (i = 0; i < 3; i++) {
        e1[i] = (double)b[i] - (double)a[i];
        e2[i] = (double)c[i] - (double)a[i];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    if (n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0) return 0;
    if (space == HFVIS_NORMAL_EYE) {
        double m[3];
        for (i = 0; i < 3; i++)
            m[i] = VX_M(view, i, 0) * n[0] + VX_M(view, i, 1) * n[1] + VX_M(view, i, 2) * n[2];
        n[0] = m[0], n[1] = m[1], n[2] = m[2];
    }
    len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0.0) || !isfinite(len)) { /* overflow of huge coordinates: rescale */
        double s = fmax(fabs(n[0]), fmax(fabs(n[1]), fabs(n[2])));
        if (!(s > 0.0) || !isfinite(s)) return 0;
        for (i = 0; i < 3; i++) n[i] /= s;
        len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    }
    if (flip) len = -len;
    for (i = 0; i < 3; i++) out[i] = (float)(n[i] / len);
    return 1;
}

/* 1 when triangle (a, b, c) has zero area in world space ((b-a) x (c-a) == 0 exactly, as
 * vx_raster_normal decides it). */
static int vx_raster_degenerate(const float *a, const float *b, const float *c)
{
    double e1[3], e2[3];
    int i;
    for (i = 0; i < 3; i++) {
        e1[i] = (double)b[i] - (double)a[i];
        e2[i] = (double)c[i] - (double)a[i];
    }
    return e1[1] * e2[2] - e1[2] * e2[1] == 0.0 && e1[2] * e2[0] - e1[0] * e2[2] == 0.0
           && e1[0] * e2[1] - e1[1] * e2[0] == 0.0;
}

/* ---- fragments ---------------------------------------------------------------------------- */

/* One covered pixel centre (x, y) of triangle t: depth range, coverage count, depth test LESS,
 * writes. */
static void vx_raster_fragment(const vx_raster_ctx *ctx, const vx_raster_tri *t, int x, int y,
                               double zrow)
{
    const hfvis_raster_outputs *o = ctx->out;
    size_t i = (size_t)y * (size_t)ctx->width + (size_t)x;
    double px = ctx->ndc_x[x];
    double zw = 0.5 * (t->zp[0] * px + zrow) + 0.5; /* zrow = zp[1] * py + zp[2] */
    if (!(zw >= 0.0 && zw <= 1.0)) return; /* beyond the far plane, or before the near plane */
    if (o->coverage_count) o->coverage_count[i]++;
    if (!(zw < ctx->zbuf[i])) return;
    ctx->zbuf[i] = zw;
    if (o->window_depth) o->window_depth[i] = (float)zw;
    if (o->triangle_id) o->triangle_id[i] = t->id;
    if (ctx->want_attr) {
        double py = ctx->ndc_y[y];
        double a0 = t->r[0] * px + t->r[1] * py + t->r[2];
        double a1 = t->r[3] * px + t->r[4] * py + t->r[5];
        double a2 = t->r[6] * px + t->r[7] * py + t->r[8];
        double s = 1.0 / (a0 + a1 + a2), b0 = a0 * s, b1 = a1 * s, b2 = a2 * s;
        if (o->linear_depth)
            o->linear_depth[i] = (float)-(b0 * t->ze[0] + b1 * t->ze[1] + b2 * t->ze[2]);
        if (o->barycentric) {
            o->barycentric[2 * i] = (float)b1;
            o->barycentric[2 * i + 1] = (float)b2;
        }
        if (o->normal) {
            o->normal[3 * i] = t->normal[0];
            o->normal[3 * i + 1] = t->normal[1];
            o->normal[3 * i + 2] = t->normal[2];
        }
    }
}

/* ---- setup and edge walking --------------------------------------------------------------- */

/* floor(a / b) for b > 0. */
static int64_t vx_raster_floordiv(int64_t a, int64_t b)
{
    int64_t q = a / b;
    if ((a % b) != 0 && (a < 0)) q--;
    return q;
}

/* Rasterize the snapped triangle (X[k], Y[k]) (fixed point, 1/256 pixel, y down) for the
 * interpolation setup t. Exact: all edge functions are int64 (|coordinates| < 2^28). */
static void vx_raster_subtriangle(const vx_raster_ctx *ctx, const vx_raster_tri *t,
                                  const int64_t X[3], const int64_t Y[3])
{
    int64_t x0 = X[0], y0 = Y[0], x1 = X[1], y1 = Y[1], x2 = X[2], y2 = Y[2];
    int64_t area = (x1 - x0) * (y2 - y0) - (y1 - y0) * (x2 - x0);
    int64_t ax[3], ay[3], dx[3], dy[3], F[3], Frow[3], minx, maxx, miny, maxy, cx, cy;
    int64_t xs, xe, ys, ye, xx, yy;
    int k;
    if (area == 0) return;
    if (area < 0) { /* orient so the interior has E > 0: swap v1, v2 */
        int64_t tx = x1, ty = y1;
        x1 = x2, y1 = y2, x2 = tx, y2 = ty;
    }
    /* edge k runs from vertex k+1 to vertex k+2 (opposite vertex k) */
    ax[0] = x1, ay[0] = y1, dx[0] = x2 - x1, dy[0] = y2 - y1;
    ax[1] = x2, ay[1] = y2, dx[1] = x0 - x2, dy[1] = y0 - y2;
    ax[2] = x0, ay[2] = y0, dx[2] = x1 - x0, dy[2] = y1 - y0;
    minx = x0 < x1 ? (x0 < x2 ? x0 : x2) : (x1 < x2 ? x1 : x2);
    maxx = x0 > x1 ? (x0 > x2 ? x0 : x2) : (x1 > x2 ? x1 : x2);
    miny = y0 < y1 ? (y0 < y2 ? y0 : y2) : (y1 < y2 ? y1 : y2);
    maxy = y0 > y1 ? (y0 > y2 ? y0 : y2) : (y1 > y2 ? y1 : y2);
    /* pixel columns whose centre 256 x + 128 lies in [minx, maxx], clamped to the image */
    xs = -vx_raster_floordiv(-(minx - VX_RASTER_SUB / 2), VX_RASTER_SUB);
    xe = vx_raster_floordiv(maxx - VX_RASTER_SUB / 2, VX_RASTER_SUB);
    ys = -vx_raster_floordiv(-(miny - VX_RASTER_SUB / 2), VX_RASTER_SUB);
    ye = vx_raster_floordiv(maxy - VX_RASTER_SUB / 2, VX_RASTER_SUB);
    if (xs < 0) xs = 0;
    if (ys < 0) ys = 0;
    if (xe > ctx->width - 1) xe = ctx->width - 1;
    if (ye > ctx->height - 1) ye = ctx->height - 1;
    if (xs > xe || ys > ye) return;
    cx = xs * VX_RASTER_SUB + VX_RASTER_SUB / 2;
    cy = ys * VX_RASTER_SUB + VX_RASTER_SUB / 2;
    for (k = 0; k < 3; k++) {
        /* E_k(p) = dx (py - ay) - dy (px - ax) > 0 inside. Top-left rule (y down): a centre on
         * edge k is inside iff the edge is left (dy < 0) or top (dy == 0, dx > 0). F = E - 1
         * + topleft, so covered <=> F >= 0 for all three edges. */
        int64_t e = dx[k] * (cy - ay[k]) - dy[k] * (cx - ax[k]);
        int topleft = dy[k] < 0 || (dy[k] == 0 && dx[k] > 0);
        Frow[k] = e - 1 + (topleft ? 1 : 0);
        dx[k] *= VX_RASTER_SUB; /* per-pixel steps */
        dy[k] *= VX_RASTER_SUB;
    }
    for (yy = ys; yy <= ye; yy++) {
        double zrow = t->zp[1] * ctx->ndc_y[yy] + t->zp[2];
        F[0] = Frow[0], F[1] = Frow[1], F[2] = Frow[2];
        for (xx = xs; xx <= xe; xx++) {
            if ((F[0] | F[1] | F[2]) >= 0) vx_raster_fragment(ctx, t, (int)xx, (int)yy, zrow);
            F[0] -= dy[0], F[1] -= dy[1], F[2] -= dy[2];
        }
        Frow[0] += dx[0], Frow[1] += dx[1], Frow[2] += dx[2];
    }
}

/* Signed distance of clip-space point c (x, y, z, w) to clip plane `plane`: >= 0 inside.
 * 0: near z >= -w; 1..4: guard band x <= gx w, x >= -gx w, y <= gy w, y >= -gy w. */
static double vx_raster_plane(const double c[4], int plane, double gx, double gy)
{
    switch (plane) {
    case 0: return c[2] + c[3];
    case 1: return gx * c[3] - c[0];
    case 2: return gx * c[3] + c[0];
    case 3: return gy * c[3] - c[1];
    default: return gy * c[3] + c[1];
    }
}

/* Clip polygon poly[0..n) against one plane (Sutherland-Hodgman) into out; returns the new
 * count. The intersection point of an edge is computed from its inside end toward its outside
 * end, so two triangles sharing the edge get bit-identical points (watertight after clipping). */
static int vx_raster_clip(double (*poly)[4], int n, int plane, double gx, double gy,
                          double (*out)[4])
{
    int i, m = 0, k;
    for (i = 0; i < n; i++) {
        const double *p = poly[i], *q = poly[(i + 1) % n];
        double dp = vx_raster_plane(p, plane, gx, gy), dq = vx_raster_plane(q, plane, gx, gy);
        if (dp >= 0.0) {
            for (k = 0; k < 4; k++) out[m][k] = p[k];
            m++;
        }
        if ((dp >= 0.0) != (dq >= 0.0)) {
            const double *in = dp >= 0.0 ? p : q, *ou = dp >= 0.0 ? q : p;
            double din = dp >= 0.0 ? dp : dq, dout = dp >= 0.0 ? dq : dp;
            double s = din / (din - dout);
            for (k = 0; k < 4; k++) out[m][k] = in[k] + s * (ou[k] - in[k]);
            m++;
        }
    }
    return m;
}

/* Snap a clip-space point to fixed-point window coordinates; 0 if w <= 0 or not finite. */
static int vx_raster_snap(const double c[4], int width, int height, int64_t *X, int64_t *Y)
{
    double fx, fy;
    if (!(c[3] > 0.0)) return 0;
    fx = (c[0] / c[3] + 1.0) * (0.5 * (double)width) * (double)VX_RASTER_SUB;
    fy = (1.0 - c[1] / c[3]) * (0.5 * (double)height) * (double)VX_RASTER_SUB;
    if (!(fabs(fx) < 4.0e8 && fabs(fy) < 4.0e8)) return 0; /* guard band keeps |.| < 2^28 */
    *X = (int64_t)floor(fx + 0.5);
    *Y = (int64_t)floor(fy + 0.5);
    return 1;
}

/* Per-vertex cache: clip x y z w, eye z, and (inside the near plane and the guard band only)
 * the snapped window coordinates as exact doubles, else NaN. */
#define VX_RASTER_VSTRIDE 7

/* One mesh triangle: trivial reject, facing and cull, interpolation setup, clipping, scan. */
static void vx_raster_triangle(const vx_raster_ctx *ctx, const hfvis_mesh *mesh,
                               const hfvis_view *view, const hfvis_raster_options *opt,
                               const double *vcache, uint32_t tid, double gx, double gy)
{
    const uint32_t *ix = mesh->indices + 3 * (size_t)tid;
    const double *c[3];
    double poly[2][VX_RASTER_MAX_POLY][4], det;
    vx_raster_tri t;
    int64_t X[VX_RASTER_MAX_POLY], Y[VX_RASTER_MAX_POLY];
    int j, k, n, cur, plane, outside = 0, facing_front, snapped = 1;
    unsigned codes_and = 0x3F;
    for (j = 0; j < 3; j++) {
        unsigned code = 0;
        c[j] = vcache + VX_RASTER_VSTRIDE * (size_t)ix[j];
        if (c[j][0] > c[j][3]) code |= 1;
        if (c[j][0] < -c[j][3]) code |= 2;
        if (c[j][1] > c[j][3]) code |= 4;
        if (c[j][1] < -c[j][3]) code |= 8;
        if (c[j][2] > c[j][3]) code |= 16;
        if (c[j][2] < -c[j][3]) code |= 32;
        codes_and &= code;
        if (!vx_all_finite(c[j], 5)) return;
        if (!(c[j][5] == c[j][5])) snapped = 0; /* NaN: needs clipping */
    }
    if (codes_and) return; /* all three outside one frustum plane */
    /* homogeneous edge vectors r_j = c_{j+1} x c_{j+2} over (x, y, w) */
    for (j = 0; j < 3; j++) {
        const double *p = c[(j + 1) % 3], *q = c[(j + 2) % 3];
        t.r[3 * j] = p[1] * q[3] - p[3] * q[1];
        t.r[3 * j + 1] = p[3] * q[0] - p[0] * q[3];
        t.r[3 * j + 2] = p[0] * q[1] - p[1] * q[0];
    }
    det = t.r[0] * c[0][0] + t.r[1] * c[0][1] + t.r[2] * c[0][3];
    if (det == 0.0 || !isfinite(det)) return; /* edge-on, or degenerate */
    facing_front = det > 0.0;
    if ((opt->cull == HFVIS_CULL_BACK && !facing_front)
        || (opt->cull == HFVIS_CULL_FRONT && facing_front))
        return;
    {
        const float *v0 = mesh->xyz + 3 * (size_t)ix[0], *v1 = mesh->xyz + 3 * (size_t)ix[1],
                    *v2 = mesh->xyz + 3 * (size_t)ix[2];
        if (ctx->out->normal) {
            if (!vx_raster_normal(v0, v1, v2, view->view, opt->normal_space,
                                  opt->normal_toward_viewer && !facing_front, t.normal))
                return; /* zero area in world space */
        } else if (vx_raster_degenerate(v0, v1, v2)) {
            return;
        }
    }
    for (k = 0; k < 3; k++) {
        t.zp[k] = (t.r[k] * c[0][2] + t.r[3 + k] * c[1][2] + t.r[6 + k] * c[2][2]) / det;
        t.ze[k] = c[k][4];
    }
    t.id = tid;
    if (snapped) { /* fast path: every vertex in front of the near plane, inside the guard band */
        for (j = 0; j < 3; j++) X[j] = (int64_t)c[j][5], Y[j] = (int64_t)c[j][6];
        vx_raster_subtriangle(ctx, &t, X, Y);
        return;
    }
    /* clipping: near plane always checked, guard-band planes only where a vertex leaves them */
    for (j = 0; j < 3; j++)
        for (k = 0; k < 4; k++) poly[0][j][k] = c[j][k];
    n = 3;
    cur = 0;
    for (plane = 0; plane < 5 && n >= 3; plane++) {
        int need = 0;
        for (j = 0; j < n; j++)
            if (!(vx_raster_plane(poly[cur][j], plane, gx, gy) >= 0.0)) need = 1;
        if (!need) continue;
        n = vx_raster_clip(poly[cur], n, plane, gx, gy, poly[1 - cur]);
        cur = 1 - cur;
    }
    if (n < 3) return;
    for (j = 0; j < n; j++)
        if (!vx_raster_snap(poly[cur][j], ctx->width, ctx->height, &X[j], &Y[j])) outside = 1;
    if (outside) return; /* w <= 0 after near clipping: not a GL view (documented) */
    for (j = 1; j + 1 < n; j++) { /* fan (0, j, j+1): inner diagonals are shared exactly */
        int64_t TX[3], TY[3];
        TX[0] = X[0], TY[0] = Y[0], TX[1] = X[j], TY[1] = Y[j], TX[2] = X[j + 1], TY[2] = Y[j + 1];
        vx_raster_subtriangle(ctx, &t, TX, TY);
    }
}

HFVIS_API hfvis_status hfvis_rasterize(const hfvis_mesh *mesh, const hfvis_view *view,
                                       const hfvis_raster_options *opts,
                                       const hfvis_raster_outputs *out)
{
    hfvis_raster_options opt;
    hfvis_status s = vx_raster_check(mesh, view, opts, out, &opt);
    size_t pixels, n_doubles, vcount, i;
    double *block, *vcache, *ndc_x, *ndc_y, gx, gy;
    vx_raster_ctx ctx;
    uint32_t tid;
    if (s != HFVIS_OK) return s;
    if (!out->linear_depth && !out->window_depth && !out->normal && !out->triangle_id
        && !out->barycentric && !out->coverage_count)
        return HFVIS_OK;
    pixels = (size_t)view->width * (size_t)view->height;
    vcount = mesh->vertex_count;
    /* one block: depth buffer, column and row NDC, the vertex cache */
    if (!vx_mul_size(vcount, VX_RASTER_VSTRIDE, &n_doubles) || n_doubles > SIZE_MAX - pixels
        || n_doubles + pixels > SIZE_MAX - (size_t)view->width - (size_t)view->height)
        return HFVIS_ERR_OUT_OF_MEMORY;
    n_doubles += pixels + (size_t)view->width + (size_t)view->height;
    block = (double *)vx_alloc_array(opt.alloc, n_doubles, sizeof(double));
    if (!block) return HFVIS_ERR_OUT_OF_MEMORY;
    ndc_x = block + pixels;
    ndc_y = ndc_x + view->width;
    vcache = ndc_y + view->height;
    /* guard band in NDC: window coordinates within HFVIS_RASTER_GUARD_PIXELS of the centre */
    gx = 2.0 * HFVIS_RASTER_GUARD_PIXELS / (double)view->width;
    gy = 2.0 * HFVIS_RASTER_GUARD_PIXELS / (double)view->height;
    for (i = 0; i < pixels; i++) block[i] = HUGE_VAL;
    for (i = 0; i < (size_t)view->width; i++) ndc_x[i] = vx_raster_ndc_x((int)i, view->width);
    for (i = 0; i < (size_t)view->height; i++) ndc_y[i] = vx_raster_ndc_y((int)i, view->height);
    for (i = 0; i < vcount; i++) {
        double p[4], e[4], *vc = vcache + VX_RASTER_VSTRIDE * i;
        int64_t X, Y;
        int plane, inside = 1;
        p[0] = (double)mesh->xyz[3 * i];
        p[1] = (double)mesh->xyz[3 * i + 1];
        p[2] = (double)mesh->xyz[3 * i + 2];
        p[3] = 1.0;
        vx_mat4_apply(view->view, p, e);
        vx_mat4_apply(view->proj, e, vc);
        vc[4] = e[2];
        for (plane = 0; plane < 5; plane++)
            if (!(vx_raster_plane(vc, plane, gx, gy) >= 0.0)) inside = 0;
        if (inside && vx_raster_snap(vc, view->width, view->height, &X, &Y)) {
            vc[5] = (double)X; /* |X|, |Y| < 2^29: exact */
            vc[6] = (double)Y;
        } else {
            vc[5] = vc[6] = (double)NAN;
        }
    }
    vx_raster_clear(out, pixels);
    ctx.out = out;
    ctx.zbuf = block;
    ctx.ndc_x = ndc_x;
    ctx.ndc_y = ndc_y;
    ctx.width = view->width;
    ctx.height = view->height;
    ctx.want_attr = out->linear_depth || out->normal || out->barycentric;
    for (tid = 0; (size_t)tid < mesh->triangle_count; tid++)
        vx_raster_triangle(&ctx, mesh, view, &opt, vcache, tid, gx, gy);
    vx_free(opt.alloc, block);
    return HFVIS_OK;
}

/* ---- the oracle: one ray per pixel centre ------------------------------------------------- */

HFVIS_API hfvis_status hfvis_rasterize_reference(const hfvis_mesh *mesh, const hfvis_view *view,
                                                 const hfvis_raster_options *opts,
                                                 const hfvis_raster_outputs *out)
{
    hfvis_raster_options opt;
    hfvis_status s = vx_raster_check(mesh, view, opts, out, &opt);
    double pv[16], inv[16];
    size_t pixels, t;
    int x, y;
    if (s != HFVIS_OK) return s;
    hfvis_mat4_multiply(view->proj, view->view, pv);
    if (hfvis_mat4_invert(pv, inv) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    pixels = (size_t)view->width * (size_t)view->height;
    vx_raster_clear(out, pixels);
    for (y = 0; y < view->height; y++) {
        for (x = 0; x < view->width; x++) {
            size_t i = (size_t)y * (size_t)view->width + (size_t)x;
            double ndc[4], hn[4], hf[4], o[3], d[3], best = HUGE_VAL, bb[3] = {0.0, 0.0, 0.0};
            double best_ze = 0.0;
            size_t best_t = (size_t)HFVIS_NO_TRIANGLE;
            int best_front = 1, k;
            uint32_t count = 0;
            ndc[0] = vx_raster_ndc_x(x, view->width);
            ndc[1] = vx_raster_ndc_y(y, view->height);
            ndc[3] = 1.0;
            ndc[2] = -1.0;
            vx_mat4_apply(inv, ndc, hn);
            ndc[2] = 1.0;
            vx_mat4_apply(inv, ndc, hf);
            if (hn[3] == 0.0 || hf[3] == 0.0) continue;
            for (k = 0; k < 3; k++) {
                o[k] = hn[k] / hn[3];
                d[k] = hf[k] / hf[3] - o[k];
            }
            if (!vx_all_finite(o, 3) || !vx_all_finite(d, 3)) continue;
            for (t = 0; t < mesh->triangle_count; t++) {
                const uint32_t *ix = mesh->indices + 3 * t;
                double e[3][3], sv[3], sum, b[3], cc[3][4], zc = 0.0, wc = 0.0, zw, ze = 0.0;
                int j, front;
                for (j = 0; j < 3; j++)
                    for (k = 0; k < 3; k++)
                        e[j][k] = (double)mesh->xyz[3 * (size_t)ix[j] + (size_t)k] - o[k];
                /* sv[j] = d . (e_{j+1} x e_{j+2}): the signed volume opposite vertex j */
                for (j = 0; j < 3; j++) {
                    const double *p = e[(j + 1) % 3], *q = e[(j + 2) % 3];
                    sv[j] = d[0] * (p[1] * q[2] - p[2] * q[1]) + d[1] * (p[2] * q[0] - p[0] * q[2])
                            + d[2] * (p[0] * q[1] - p[1] * q[0]);
                    if (j == 1 && ((sv[0] > 0.0 && sv[1] < 0.0) || (sv[0] < 0.0 && sv[1] > 0.0)))
                        break;
                }
                if (j < 3) continue;
                if (!((sv[0] >= 0.0 && sv[1] >= 0.0 && sv[2] >= 0.0)
                      || (sv[0] <= 0.0 && sv[1] <= 0.0 && sv[2] <= 0.0)))
                    continue;
                sum = sv[0] + sv[1] + sv[2]; /* = d . ((v1 - v0) x (v2 - v0)) */
                if (sum == 0.0 || !isfinite(sum)) continue; /* parallel ray or degenerate */
                front = sum < 0.0;
                if ((opt.cull == HFVIS_CULL_BACK && !front)
                    || (opt.cull == HFVIS_CULL_FRONT && front))
                    continue;
                for (j = 0; j < 3; j++) {
                    double p[4], ev[4];
                    b[j] = sv[j] / sum;
                    for (k = 0; k < 3; k++) p[k] = (double)mesh->xyz[3 * (size_t)ix[j] + (size_t)k];
                    p[3] = 1.0;
                    vx_mat4_apply(view->view, p, ev);
                    vx_mat4_apply(view->proj, ev, cc[j]);
                    zc += b[j] * cc[j][2];
                    wc += b[j] * cc[j][3];
                    ze += b[j] * ev[2];
                }
                if (!(wc > 0.0)) continue;
                zw = 0.5 * (zc / wc) + 0.5;
                if (!(zw >= 0.0 && zw <= 1.0)) continue;
                if (vx_raster_degenerate(mesh->xyz + 3 * (size_t)ix[0],
                                         mesh->xyz + 3 * (size_t)ix[1],
                                         mesh->xyz + 3 * (size_t)ix[2]))
                    continue; /* zero area in world space */
                count++;
                if (zw < best) {
                    best = zw;
                    best_t = t;
                    best_front = front;
                    best_ze = ze;
                    bb[0] = b[0], bb[1] = b[1], bb[2] = b[2];
                }
            }
            if (out->coverage_count) out->coverage_count[i] = count;
            if (best_t == (size_t)HFVIS_NO_TRIANGLE) continue;
            if (out->window_depth) out->window_depth[i] = (float)best;
            if (out->triangle_id) out->triangle_id[i] = (uint32_t)best_t;
            if (out->linear_depth) out->linear_depth[i] = (float)-best_ze;
            if (out->barycentric) {
                out->barycentric[2 * i] = (float)bb[1];
                out->barycentric[2 * i + 1] = (float)bb[2];
            }
            if (out->normal) {
                const uint32_t *ix = mesh->indices + 3 * best_t;
                vx_raster_normal(mesh->xyz + 3 * (size_t)ix[0], mesh->xyz + 3 * (size_t)ix[1],
                                 mesh->xyz + 3 * (size_t)ix[2], view->view, opt.normal_space,
                                 opt.normal_toward_viewer && !best_front, out->normal + 3 * i);
            }
        }
    }
    return HFVIS_OK;
}
