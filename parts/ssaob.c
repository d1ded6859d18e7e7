
/* ========================================================================================== */
/* 9. P4 far-field ambient obscurance ([P4] Timonen, "Screen-Space Far-Field Ambient          */
/*    Obscurance", HPG 2013; spec screenspace-p3-p4 §5): the slab estimator L(a, b, c, d)     */
/*    ([P4] Eq. 2-3) by quadrature, table and the closed form for rho = 1, the scan kernel    */
/*    ([P4] Alg. 1 with the sign correction of spec §5.3), virtual points (§5.4), the          */
/*    resolution hierarchy (§5.5), prefix sums and sector averaging (§5.6), the obscurity     */
/*    kernel ([P4] Alg. 2, spec §5.7), the near field (§5.8), jitter, sparse 3x3 evaluation    */
/*    and the bilateral blur (§5.9); 10. the mipmap baseline ([P4] §5, spec §5.10);            */
/*    11. error metrics ([P4] §8, spec §5.12).                                                 */
/* ========================================================================================== */

#define SSB_MAX_LEVELS 24
#define SSB_MAX_NODES 64
#define SSB_TABLE_MAX 4096

/* ---- 9.1 the slab integral L (spec §5.2) ------------------------------------------------- */

/* Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n; n <= SSB_MAX_NODES). */
static void ssb_gauss(int n, double *x, double *w)
{
    int i, j, it;
    for (i = 0; i < n; i++) {
        double z = cos(SS_PI * ((double)i + 0.75) / ((double)n + 0.5)), pp = 1.0;
        for (it = 0; it < 100; it++) {
            double p1 = 1.0, p2 = 0.0, z1;
            for (j = 0; j < n; j++) {
                double p3 = p2;
                p2 = p1;
                p1 = ((2.0 * (double)j + 1.0) * z * p2 - (double)j * p3) / ((double)j + 1.0);
            }
            pp = (double)n * (z * p1 - p2) / (z * z - 1.0);
            z1 = z;
            z = z1 - p1 / pp;
            if (fabs(z - z1) < 1e-15) break;
        }
        x[i] = z;
        w[i] = 2.0 / ((1.0 - z * z) * pp * pp);
    }
}

/* The integration range of L for (c, d): [lo0, hi0] = [max(d - pi/2, 0), min(c, d + pi/2, pi)]. */
static void ssb_range(double c, double d, double *lo0, double *hi0)
{
    double lo = d - 0.5 * SS_PI, hi = d + 0.5 * SS_PI;
    if (lo < 0.0) lo = 0.0;
    if (hi > c) hi = c;
    if (hi > SS_PI) hi = SS_PI;
    *lo0 = lo;
    *hi0 = hi;
}

/* Antiderivative of sin(t) cos(t - d) (spec §5.2: F = t sin d / 2 - cos(2t - d) / 4). */
static double ssb_F(double t, double d) { return 0.5 * t * sin(d) - 0.25 * cos(2.0 * t - d); }

/* Integral of rho(b / sin(c - t)) cos(t - d) sin t over [A, B] (already clipped), by
 * Gauss-Legendre with n nodes (x, w on [-1, 1]). */
static double ssb_quad(const ss_fall *f, double A, double B, double b, double c, double d, int n,
                       const double *x, const double *w)
{
    double m = 0.5 * (A + B), h = 0.5 * (B - A), s = 0.0;
    int i;
    if (!(B > A)) return 0.0;
    for (i = 0; i < n; i++) {
        double t = m + h * x[i], sn = sin(c - t), dist, r;
        dist = sn > 0.0 ? b / sn : SS_INF;
        r = f->kind == HFVIS_FALLOFF_NONE ? 1.0 : (dist < SS_INF ? ss_rho(f, dist) : 0.0);
        if (f->kind != HFVIS_FALLOFF_NONE && b == 0.0) r = 1.0;
        s += w[i] * r * cos(t - d) * sin(t);
    }
    return s * h;
}

double hfvis_ffao_slab_rho1(double a, double theta_hi, double c, double d)
{
    double lo, hi;
    if (!ss_finite(a) || theta_hi != theta_hi || !ss_finite(c) || !ss_finite(d)) return SS_NAN;
    ssb_range(c, d, &lo, &hi);
    if (a > lo) lo = a;
    if (theta_hi < hi) hi = theta_hi;
    return hi > lo ? ssb_F(hi, d) - ssb_F(lo, d) : 0.0;
}

double hfvis_ffao_slab_integral(const hfvis_falloff *falloff, double a, double theta_hi,
                                double b, double c, double d, int nodes)
{
    ss_fall f;
    double x[SSB_MAX_NODES], w[SSB_MAX_NODES], lo, hi;
    if (ss_fall_load(falloff, &f) != HFVIS_OK || !ss_finite(a) || theta_hi != theta_hi ||
        !(b >= 0.0) || !ss_finite(c) || !ss_finite(d) || nodes < 1 || nodes > SSB_MAX_NODES)
        return SS_NAN;
    ssb_range(c, d, &lo, &hi);
    if (a > lo) lo = a;
    if (theta_hi < hi) hi = theta_hi;
    if (!(hi > lo)) return 0.0;
    ssb_gauss(nodes, x, w);
    return ssb_quad(&f, lo, hi, b, c, d, nodes, x, w);
}

/* ---- 9.2 the tabulated L (spec §5.2 Table L [R]) ------------------------------------------ */


hfvis_status hfvis_ffao_table_build(const hfvis_falloff *falloff, int na, int nb, int nc, int nd,
                                    double b_ref, const hfvis_allocator *alloc,
                                    hfvis_ffao_table *out)
{
    ss_fall f;
    size_t cells;
    float *v;
    double x[8], w[8];
    int ib, ic, id, ia;
    if (!out || ss_fall_load(falloff, &f) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    if (na == 0) na = 64;
    if (nb == 0) nb = 48;
    if (nc == 0) nc = 16;
    if (nd == 0) nd = 33;
    if (na < 2 || nb < 2 || nc < 2 || nd < 2 || na > SSB_TABLE_MAX || nb > SSB_TABLE_MAX ||
        nc > SSB_TABLE_MAX || nd > SSB_TABLE_MAX)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (b_ref == 0.0) {
        if (f.kind == HFVIS_FALLOFF_INV_QUADRATIC || f.kind == HFVIS_FALLOFF_HBAO) b_ref = sqrt(f.a);
        else if (f.kind == HFVIS_FALLOFF_NONE) b_ref = 1.0;
        else if (f.kind == HFVIS_FALLOFF_CUSTOM) b_ref = f.a > 0.0 ? f.a : 1.0;
        else b_ref = f.a;
    }
    if (!(ss_finite(b_ref) && b_ref > 0.0)) return HFVIS_ERR_INVALID_ARGUMENT;
    cells = ss_bytes3((size_t)na * (size_t)nb, (size_t)nc * (size_t)nd, sizeof(float));
    if (!cells) return HFVIS_ERR_LIMIT;
    v = (float *)ss_alloc(alloc, cells);
    if (!v) return HFVIS_ERR_OUT_OF_MEMORY;
    ssb_gauss(8, x, w);
    for (id = 0; id < nd; id++)
        for (ic = 0; ic < nc; ic++)
            for (ib = 0; ib < nb; ib++) {
                double u = (double)ib / (double)(nb - 1), b, d, c, lo0, hi0, acc = 0.0;
                float *row = v + (((size_t)id * (size_t)nc + (size_t)ic) * (size_t)nb + (size_t)ib) *
                                     (size_t)na;
                b = u < 1.0 ? b_ref * u / (1.0 - u) : SS_INF;
                c = 0.5 * SS_PI + 0.5 * SS_PI * (double)ic / (double)(nc - 1);
                d = -0.5 * SS_PI + SS_PI * (double)id / (double)(nd - 1);
                ssb_range(c, d, &lo0, &hi0);
                row[na - 1] = 0.0f;
                for (ia = na - 2; ia >= 0; ia--) {
                    double A = SS_PI * (double)ia / (double)(na - 1);
                    double B = SS_PI * (double)(ia + 1) / (double)(na - 1);
                    if (A < lo0) A = lo0;
                    if (B > hi0) B = hi0;
                    if (B > A) {
                        if (b < SS_INF) acc += ssb_quad(&f, A, B, b, c, d, 8, x, w);
                        else if (f.kind == HFVIS_FALLOFF_NONE) acc += ssb_F(B, d) - ssb_F(A, d);
                    }
                    row[ia] = (float)acc;
                }
            }
    out->na = na;
    out->nb = nb;
    out->nc = nc;
    out->nd = nd;
    out->b_ref = b_ref;
    out->values = v;
    out->alloc = alloc;
    return HFVIS_OK;
}

void hfvis_ffao_table_free(hfvis_ffao_table *t)
{
    if (!t) return;
    ss_free(t->alloc, t->values);
    memset(t, 0, sizeof *t);
}

static int ssb_table_ok(const hfvis_ffao_table *t)
{
    return t && t->values && t->na >= 2 && t->nb >= 2 && t->nc >= 2 && t->nd >= 2 &&
           t->na <= SSB_TABLE_MAX && t->nb <= SSB_TABLE_MAX && t->nc <= SSB_TABLE_MAX &&
           t->nd <= SSB_TABLE_MAX && ss_finite(t->b_ref) && t->b_ref > 0.0;
}

/* Cell index and fraction of v on a uniform axis [lo, hi] with n points. */
static void ssb_axis(double v, double lo, double hi, int n, int *i, double *fr)
{
    double p = (v - lo) / (hi - lo) * (double)(n - 1);
    int k;
    if (!(p > 0.0)) p = 0.0;
    if (p > (double)(n - 1)) p = (double)(n - 1);
    k = (int)p;
    if (k > n - 2) k = n - 2;
    *i = k;
    *fr = p - (double)k;
}

/* Quadrilinear lookup of L(a, b, c, d) (inputs clamped to the table's ranges). */
static double ssb_lookup(const hfvis_ffao_table *t, double a, double b, double c, double d)
{
    int ia, ib, ic, id, k;
    double fa, fb, fc, fd, u, s = 0.0;
    u = b > 0.0 ? b / (b + t->b_ref) : 0.0;
    ssb_axis(a, 0.0, SS_PI, t->na, &ia, &fa);
    ssb_axis(u, 0.0, 1.0, t->nb, &ib, &fb);
    ssb_axis(c, 0.5 * SS_PI, SS_PI, t->nc, &ic, &fc);
    ssb_axis(d, -0.5 * SS_PI, 0.5 * SS_PI, t->nd, &id, &fd);
    for (k = 0; k < 8; k++) {
        int kb = k & 1, kc = (k >> 1) & 1, kd = (k >> 2) & 1;
        double wgt = (kb ? fb : 1.0 - fb) * (kc ? fc : 1.0 - fc) * (kd ? fd : 1.0 - fd);
        const float *row;
        if (wgt == 0.0) continue;
        row = t->values + (((size_t)(id + kd) * (size_t)t->nc + (size_t)(ic + kc)) * (size_t)t->nb +
                           (size_t)(ib + kb)) * (size_t)t->na;
        s += wgt * ((1.0 - fa) * (double)row[ia] + fa * (double)row[ia + 1]);
    }
    return s;
}

double hfvis_ffao_table_lookup(const hfvis_ffao_table *t, double a, double b, double c, double d)
{
    if (!ssb_table_ok(t) || a != a || b != b || c != c || d != d) return SS_NAN;
    return ssb_lookup(t, a, b, c, d);
}

/* ---- 9.3 virtual points, sector weights, the slice estimator (spec §5.2, §5.4) ------------- */

void hfvis_ffao_virtual_point(double m0, double m1, double slope, double zscale, double h[2])
{
    if (!h) return;
    h[0] = (m0 - m1) / slope; /* spec §5.3: m1 = max(y - s x), so x_h = (m0 - m1)/s */
    h[1] = m0 * zscale;
}

/* e1 of screen azimuth phi (unit, z = 0). */
static void ssb_e1_phi(const ss_cam *c, double phi, double e[3])
{
    ss_plane_e1(c, cos(phi), sin(phi), e);
}

/* Angle around the zenith between boundary vectors ea, eb (spec §5.2 [D]): both projected onto
 * the plane perpendicular to v (unit view ray; orthographic +Z). */
static double ssb_wedge(const double ea[3], const double eb[3], const double v[3])
{
    double pa[3], pb[3], cr[3], da = ss_dot3(ea, v), db = ss_dot3(eb, v);
    int k;
    for (k = 0; k < 3; k++) {
        pa[k] = ea[k] - da * v[k];
        pb[k] = eb[k] - db * v[k];
    }
    ss_cross3(pa, pb, cr);
    return atan2(sqrt(ss_dot3(cr, cr)), ss_dot3(pa, pb));
}

double hfvis_ffao_sector_weight(const hfvis_camera *cam, const double p[3], double phi_lo,
                                double phi_hi)
{
    ss_cam c;
    double ea[3], eb[3], v[3] = {0.0, 0.0, 1.0};
    if (ss_cam_load(cam, &c) != HFVIS_OK || !p || !ss_finite(phi_lo) || !ss_finite(phi_hi) ||
        !(phi_hi > phi_lo) || phi_hi - phi_lo >= SS_PI)
        return SS_NAN;
    if (c.persp) {
        v[0] = p[0];
        v[1] = p[1];
        v[2] = p[2];
        if (!(p[2] < 0.0) || !ss_normalize3(v)) return SS_NAN;
    }
    ssb_e1_phi(&c, phi_lo, ea);
    ssb_e1_phi(&c, phi_hi, eb);
    return ssb_wedge(ea, eb, v);
}

/* The receiver in its slice (spec §5.7): 2D position, zenith, the x axis toward +D, the
 * projected normal's angle d and length. */
typedef struct ssb_rx {
    double px, py, ux, uy, xx, xy, d, nlen;
    int ortho;
} ssb_rx;

/* How L is evaluated. */
typedef struct ssb_est {
    ss_fall f;
    int mode;           /* 1 quadrature, 2 table, 3 closed form */
    int nodes;
    double x[SSB_MAX_NODES], w[SSB_MAX_NODES];
    const hfvis_ffao_table *table;
    double thickness;
} ssb_est;

static double ssb_theta(const ssb_rx *r, double wx, double wy)
{
    return atan2(wx * r->xx + wy * r->xy, wx * r->ux + wy * r->uy);
}

/* The slab of point h (spec §5.2 SliceObscurance): adds nothing unless h is visible
 * (a < theta_min, strict); returns the slab's integral and lowers *thmin to a. */
static double ssb_slab(const ssb_est *e, const ssb_rx *r, double hx, double hy, double *thmin)
{
    double a = ssb_theta(r, hx - r->px, hy - r->py), b, c, tl, lo, hi, s;
    if (!(a < *thmin)) return 0.0;
    if (r->ortho) {
        b = fabs(hx - r->px);
        c = SS_PI;
    } else {
        double hl = sqrt(hx * hx + hy * hy);
        b = fabs(r->px * hy - r->py * hx) / hl;
        c = ssb_theta(r, hx, hy);
        if (c < 0.0) c = -c; /* a point behind the eye's axis of the slice (degenerate) */
    }
    tl = *thmin;
    if (e->thickness > 0.0) { /* [P4] §11: the slab ends thickness below h along its view ray */
        double bx, by, tb;
        if (r->ortho) {
            bx = hx;
            by = hy - e->thickness;
        } else {
            double hl = sqrt(hx * hx + hy * hy);
            bx = hx + e->thickness * hx / hl;
            by = hy + e->thickness * hy / hl;
        }
        tb = ssb_theta(r, bx - r->px, by - r->py);
        if (tb < tl) tl = tb;
    }
    *thmin = a;
    if (e->mode == 2) {
        double dd = r->d;
        s = ssb_lookup(e->table, a, b, c, dd) - (tl < c ? ssb_lookup(e->table, tl, b, c, dd) : 0.0);
        return s > 0.0 ? r->nlen * s : 0.0;
    }
    ssb_range(c, r->d, &lo, &hi);
    if (a > lo) lo = a;
    if (tl < hi) hi = tl;
    if (!(hi > lo)) return 0.0;
    if (e->mode == 3) return r->nlen * (ssb_F(hi, r->d) - ssb_F(lo, r->d));
    return r->nlen * ssb_quad(&e->f, lo, hi, b, c, r->d, e->nodes, e->x, e->w);
}

/* Receiver setup from its 2D position and projected normal. */
static void ssb_rx_init(ssb_rx *r, int ortho, double px, double py, double nx, double ny)
{
    double l;
    r->ortho = ortho;
    r->px = px;
    r->py = py;
    if (ortho) {
        r->ux = 0.0;
        r->uy = 1.0;
    } else {
        l = sqrt(px * px + py * py);
        r->ux = -px / l;
        r->uy = -py / l;
    }
    r->xx = r->uy;
    r->xy = -r->ux;
    r->nlen = sqrt(nx * nx + ny * ny);
    r->d = ssb_theta(r, nx, ny);
}

static hfvis_status ssb_est_init(ssb_est *e, const hfvis_falloff *f, hfvis_ffao_estimator m,
                                 const hfvis_ffao_table *t, int nodes, double thickness)
{
    if (ss_fall_load(f, &e->f) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    if (nodes == 0) nodes = 16;
    if (nodes < 1 || nodes > SSB_MAX_NODES) return HFVIS_ERR_INVALID_ARGUMENT;
    e->nodes = nodes;
    ssb_gauss(nodes, e->x, e->w);
    e->table = t;
    e->thickness = thickness;
    switch (m) {
    case HFVIS_FFAO_L_DEFAULT:
        e->mode = e->f.kind == HFVIS_FALLOFF_NONE ? 3 : (t ? 2 : 1);
        break;
    case HFVIS_FFAO_L_QUADRATURE: e->mode = 1; break;
    case HFVIS_FFAO_L_TABLE: e->mode = 2; break;
    case HFVIS_FFAO_L_CLOSED_FORM:
        if (e->f.kind != HFVIS_FALLOFF_NONE) return HFVIS_ERR_INVALID_ARGUMENT;
        e->mode = 3;
        break;
    default: return HFVIS_ERR_INVALID_ARGUMENT;
    }
    if (e->mode == 2 && t && !ssb_table_ok(t)) return HFVIS_ERR_INVALID_ARGUMENT;
    return HFVIS_OK;
}

hfvis_status hfvis_ffao_slice(const double p[2], const double n[2], const double *hx,
                              const double *hy, int count, int orthographic, double theta_start,
                              const hfvis_ffao_options *opts, double *obscurance,
                              double *theta_min)
{
    hfvis_ffao_options o;
    ssb_est e;
    ssb_rx r;
    double th, acc = 0.0;
    int i;
    if (hfvis_ffao_options_resolve(opts, &o) != HFVIS_OK || !p || !n || count < 0 ||
        (count > 0 && (!hx || !hy)) || (orthographic != 0 && orthographic != 1) ||
        theta_start != theta_start || !ss_finite(p[0]) || !ss_finite(p[1]) || !ss_finite(n[0]) ||
        !ss_finite(n[1]) || !obscurance)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (!orthographic && !(p[0] * p[0] + p[1] * p[1] > 0.0)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.estimator == HFVIS_FFAO_L_TABLE && !o.table) return HFVIS_ERR_INVALID_ARGUMENT;
    if (ssb_est_init(&e, &o.falloff, o.estimator, o.table, o.quad_nodes, o.thickness) != HFVIS_OK)
        return HFVIS_ERR_INVALID_ARGUMENT;
    ssb_rx_init(&r, orthographic, p[0], p[1], n[0], n[1]);
    th = theta_start;
    for (i = 0; i < count; i++) {
        if (!ss_finite(hx[i]) || !ss_finite(hy[i])) continue;
        if (!orthographic && !(hx[i] * hx[i] + hy[i] * hy[i] > 0.0)) continue;
        acc += ssb_slab(&e, &r, hx[i], hy[i], &th);
    }
    *obscurance = acc;
    if (theta_min) *theta_min = th;
    return HFVIS_OK;
}

/* ---- 9.4 options ------------------------------------------------------------------------- */

hfvis_ffao_options hfvis_ffao_options_default(void)
{
    hfvis_ffao_options o;
    memset(&o, 0, sizeof o);
    return o;
}

hfvis_status hfvis_ffao_options_resolve(const hfvis_ffao_options *in, hfvis_ffao_options *out)
{
    hfvis_ffao_options o;
    if (!out) return HFVIS_ERR_INVALID_ARGUMENT;
    if (in) o = *in;
    else memset(&o, 0, sizeof o);
    if (o.directions == 0) o.directions = o.sparse ? 18 : 8;
    if (o.segments == 0) o.segments = 2;
    if (o.b0 == 0) o.b0 = 10;
    if (o.level_gamma == 0.0) o.level_gamma = 1.0;
    if (o.receiver_slope == 0.0) o.receiver_slope = -1.0;
    if (o.averaging == HFVIS_FFAO_AVERAGE_DEFAULT)
        o.averaging = o.thickness > 0.0 ? HFVIS_FFAO_AVERAGE_OFF : HFVIS_FFAO_AVERAGE_ON;
    if (o.sampling == HFVIS_SSAO_SAMPLING_DEFAULT)
        o.sampling = o.thickness > 0.0 ? HFVIS_SSAO_SAMPLING_NEAREST : HFVIS_SSAO_SAMPLING_BILINEAR;
    if (o.near_field == HFVIS_FFAO_NEAR_DEFAULT) o.near_field = HFVIS_FFAO_NEAR_DIRECT;
    if (o.quad_nodes == 0) o.quad_nodes = 16;
    if (o.blur_radius == 0) o.blur_radius = 2;
    if (o.blur_threshold == 0.0) o.blur_threshold = 0.07;
    if (o.mip_growth == 0.0) o.mip_growth = 1.5;
    if (o.mip_directions == 0) o.mip_directions = 16;
    if (o.directions < 3 || o.directions > HFVIS_SSAO_MAX_DIRECTIONS || o.segments < 1 ||
        o.segments > 64 || o.b0 < 1 || o.b0 > 4096 || o.levels < 0 || o.levels > SSB_MAX_LEVELS ||
        !(ss_finite(o.level_gamma) && o.level_gamma > 0.0) ||
        !(ss_finite(o.receiver_slope) && o.receiver_slope < 0.0) || !ss_finite(o.azimuth0_rad) ||
        (o.averaging != HFVIS_FFAO_AVERAGE_ON && o.averaging != HFVIS_FFAO_AVERAGE_OFF) ||
        (o.jitter != 0 && o.jitter != 1) || (o.sparse != 0 && o.sparse != 1) ||
        (o.blur != 0 && o.blur != 1) || !(ss_finite(o.thickness) && o.thickness >= 0.0) ||
        (o.sampling != HFVIS_SSAO_SAMPLING_NEAREST && o.sampling != HFVIS_SSAO_SAMPLING_BILINEAR) ||
        (o.near_field != HFVIS_FFAO_NEAR_NONE && o.near_field != HFVIS_FFAO_NEAR_DIRECT) ||
        o.quad_nodes < 1 || o.quad_nodes > SSB_MAX_NODES || o.blur_radius < 0 ||
        o.blur_radius > 64 || !(ss_finite(o.blur_threshold) && o.blur_threshold >= 0.0) ||
        !(ss_finite(o.mip_growth) && o.mip_growth >= 1.0 && o.mip_growth <= 16.0) ||
        o.mip_directions < 3 || o.mip_directions > HFVIS_SSAO_MAX_DIRECTIONS ||
        (int)o.estimator < 0 || (int)o.estimator > (int)HFVIS_FFAO_L_CLOSED_FORM ||
        (o.sparse && o.directions % 9 != 0) || hfvis_falloff_check(&o.falloff) != HFVIS_OK)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.table && !ssb_table_ok(o.table)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (o.estimator == HFVIS_FFAO_L_CLOSED_FORM && o.falloff.kind != HFVIS_FALLOFF_NONE &&
        o.falloff.kind != HFVIS_FALLOFF_DEFAULT)
        return HFVIS_ERR_INVALID_ARGUMENT;
    *out = o;
    return HFVIS_OK;
}

/* ---- 9.5 the FFAO pipeline ---------------------------------------------------------------- */

/* One scan direction's data: lattice, line ranges, and per level the prefix sums over lines of
 * (m0, m1, valid) for every interval: pre[lev][3 * (J * (nl + 1) + l)] (slot l = sum over lines
 * < l). */
typedef struct ssb_dir {
    hfvis_ssao_lattice lat;
    hfvis_ssao_line *lines;
    double e1[3], phi;
    double eb[65][3];            /* segment boundary vectors (S + 1) */
    int smax;                    /* largest step index of any line */
    int nlev, nj[SSB_MAX_LEVELS];
    double *pre[SSB_MAX_LEVELS];
} ssb_dir;

typedef struct ssb_ctx {
    ss_cam c;
    hfvis_ffao_options o;
    ssb_est e;
    const float *depth;
    int bil;
} ssb_ctx;

/* Largest step index and per-level interval counts of a direction; total doubles needed. */
static size_t ssb_dir_size(const ssb_ctx *x, ssb_dir *dd)
{
    int n, smax = 0, j;
    size_t tot = 0, nl1 = (size_t)dd->lat.line_count + 1;
    for (j = 0; j < dd->lat.line_count; j++) {
        const hfvis_ssao_line *ln = &dd->lines[j];
        if (ln->count > 0 && ln->first + ln->count - 1 > smax) smax = ln->first + ln->count - 1;
    }
    dd->smax = smax;
    dd->nlev = 0;
    for (n = 0; n < SSB_MAX_LEVELS; n++) {
        long long bn = (long long)x->o.b0 << n;
        if (n > 0 && bn > (long long)smax + 1) break;
        if (x->o.levels > 0 && n >= x->o.levels) break;
        dd->nj[n] = (int)((long long)smax / bn) + 1;
        tot += (size_t)dd->nj[n] * nl1 * 3;
        dd->nlev = n + 1;
    }
    return tot;
}

/* Scan kernel ([P4] Alg. 1, spec §5.3) + hierarchy (§5.5) + prefix sums (§5.6). */
static void ssb_scan(const ssb_ctx *x, ssb_dir *dd, double *mem)
{
    const ss_cam *c = &x->c;
    size_t nl1 = (size_t)dd->lat.line_count + 1, k;
    double s = x->o.receiver_slope;
    int n, j, J, l;
    for (n = 0; n < dd->nlev; n++) {
        dd->pre[n] = mem;
        for (k = 0; k < (size_t)dd->nj[n] * nl1; k++) {
            mem[3 * k] = -SS_INF;
            mem[3 * k + 1] = -SS_INF;
            mem[3 * k + 2] = 0.0;
        }
        mem += (size_t)dd->nj[n] * nl1 * 3;
    }
    for (j = 0; j < dd->lat.line_count; j++) {
        const hfvis_ssao_line *ln = &dd->lines[j];
        int i;
        for (i = ln->first; i < ln->first + ln->count; i++) {
            double u = ln->x0 + (double)i * dd->lat.dir.step_x, v = ln->y0 + (double)i * dd->lat.dir.step_y;
            double qu, qv, z, Q[3], xq, yq;
            double *cell;
            z = ss_sample(c, x->depth, x->bil, u, v, ss_texel(u, c->W), ss_texel(v, c->H), &qu, &qv);
            if (z != z) continue; /* background: never occludes */
            ss_unproject(c, qu, qv, z, Q);
            xq = ss_dot3(Q, dd->e1);
            yq = Q[2];
            cell = dd->pre[0] + 3 * ((size_t)(i / x->o.b0) * nl1 + (size_t)j + 1);
            if (yq > cell[0]) cell[0] = yq;                      /* m0 = max(y) */
            if (yq - s * xq > cell[1]) cell[1] = yq - s * xq;    /* m1 = max(y - s x) (§5.3 [A]) */
            cell[2] = 1.0;
        }
    }
    for (n = 1; n < dd->nlev; n++) /* B_n = 2 B_{n-1}: max over the two children */
        for (J = 0; J < dd->nj[n]; J++)
            for (l = 1; l < (int)nl1; l++) {
                double *dst = dd->pre[n] + 3 * ((size_t)J * nl1 + (size_t)l), *a, *b;
                a = dd->pre[n - 1] + 3 * ((size_t)(2 * J) * nl1 + (size_t)l);
                dst[0] = a[0];
                dst[1] = a[1];
                dst[2] = a[2];
                if (2 * J + 1 < dd->nj[n - 1]) {
                    b = a + 3 * nl1;
                    if (b[0] > dst[0]) dst[0] = b[0];
                    if (b[1] > dst[1]) dst[1] = b[1];
                    if (b[2] > dst[2]) dst[2] = b[2];
                }
            }
    for (n = 0; n < dd->nlev; n++)
        for (J = 0; J < dd->nj[n]; J++) {
            double *row = dd->pre[n] + 3 * (size_t)J * nl1, s0 = 0.0, s1 = 0.0, sc = 0.0;
            row[0] = row[1] = row[2] = 0.0;
            for (l = 1; l < (int)nl1; l++) {
                double *cl = row + 3 * l;
                if (cl[2] > 0.0) {
                    s0 += cl[0];
                    s1 += cl[1];
                    sc += 1.0;
                }
                cl[0] = s0;
                cl[1] = s1;
                cl[2] = sc;
            }
        }
}

/* Near field (spec §5.8 [R]): direct samples at 1, 2, ... px along +D from the receiver up to
 * (excluding) along-line distance `until`, through the slab estimator. */
static double ssb_near(const ssb_ctx *x, const ssb_dir *dd, const ssb_rx *r, double cu, double cv,
                       double zs, double until, double *thmin)
{
    const ss_cam *c = &x->c;
    double acc = 0.0, sdist;
    for (sdist = 1.0; sdist < until - 1e-9; sdist += 1.0) {
        double u = cu + sdist * dd->lat.dir.dx, v = cv + sdist * dd->lat.dir.dy, qu, qv, z, Q[3];
        if (u < 0.5 || v < 0.5 || u > (double)c->W - 0.5 || v > (double)c->H - 0.5) break;
        z = ss_sample(c, x->depth, x->bil, u, v, ss_texel(u, c->W), ss_texel(v, c->H), &qu, &qv);
        if (z != z) continue;
        ss_unproject(c, qu, qv, z, Q);
        acc += ssb_slab(&x->e, r, ss_dot3(Q, dd->e1), Q[2] * zs, thmin);
    }
    return acc;
}

/* One receiver, one scan direction (spec §5.7 FfaoPixel for sector k): returns in *near_sum
 * and *far_sum the w-weighted integrals (w in radians around the zenith) of the near and far
 * fields, in *wsum the sector's weight. jit in [-1, 1]: the sector rotation of §5.9. */
static void ssb_pixel_dir(const ssb_ctx *x, const ssb_dir *dd, double cu, double cv, double z,
                          const double nrm[3], double jit, int want_near, int want_far,
                          double *near_sum, double *far_sum, double *wsum)
{
    const ss_cam *c = &x->c;
    double P[3], yh[3], v[3], zs, t_pix, jx, far0, thn = SS_PI, In = 0.0, wsec = 0.0, Ifar = 0.0;
    double dphi = 2.0 * SS_PI / ((double)x->o.directions * (double)x->o.segments);
    ssb_rx r;
    int S = x->o.segments, g, J0, b0 = x->o.b0;
    ss_unproject(c, cu, cv, z, P);
    ss_plane_yhat(c, dd->e1, P, yh);
    zs = c->persp ? 1.0 / yh[2] : 1.0;
    ssb_rx_init(&r, !c->persp, ss_dot3(P, dd->e1), P[2] * zs, ss_dot3(nrm, dd->e1), ss_dot3(nrm, yh));
    if (c->persp) {
        v[0] = P[0];
        v[1] = P[1];
        v[2] = P[2];
        ss_normalize3(v);
    } else {
        v[0] = v[1] = 0.0;
        v[2] = 1.0;
    }
    t_pix = (cu * dd->lat.dir.dx + cv * dd->lat.dir.dy - dd->lat.t_min) / dd->lat.dir.step;
    jx = (cu * dd->lat.px + cv * dd->lat.py - dd->lat.s_first) / dd->lat.dir.spacing;
    J0 = (int)ceil((t_pix + (double)b0) / (double)b0 - 1e-9);
    far0 = (double)J0 * (double)b0;
    if (x->o.near_field == HFVIS_FFAO_NEAR_DIRECT) In = ssb_near(x, dd, &r, cu, cv, zs, far0 - t_pix, &thn);
    for (g = 0; g < S; g++) wsec += ssb_wedge(dd->eb[g], dd->eb[g + 1], v);
    *wsum = wsec;
    *near_sum = want_near ? wsec * In : 0.0;
    *far_sum = 0.0;
    if (!want_far) return;
    for (g = 0; g < S; g++) {
        double wg = ssb_wedge(dd->eb[g], dd->eb[g + 1], v), th = thn, Ig = 0.0;
        double alo = -SS_PI / (double)x->o.directions + dphi * (double)g + jit * 0.5 * dphi;
        double ahi = alo + dphi, tlo = tan(alo), thi = tan(ahi), amid = tan(0.5 * (alo + ahi));
        long long cur = (long long)J0 * b0;
        while (cur <= dd->smax) {
            int n = dd->nlev - 1, J, lA, lB;
            long long bn;
            double rr, olo, ohi, cnt, m0, m1, hx, hy;
            const double *row;
            size_t nl1 = (size_t)dd->lat.line_count + 1;
            for (; n > 0; n--) {
                bn = (long long)b0 << n;
                if (cur % bn == 0 && (double)bn <= x->o.level_gamma * ((double)cur - t_pix)) break;
            }
            bn = (long long)b0 << n;
            J = (int)(cur / bn);
            cur += bn;
            if (J >= dd->nj[n]) break;
            rr = ((double)J + 0.5) * (double)bn - t_pix;
            if (x->o.averaging == HFVIS_FFAO_AVERAGE_ON) {
                olo = jx + rr * tlo;
                ohi = jx + rr * thi;
                lA = (int)ceil(olo - 1e-9);
                lB = (int)floor(ohi + 1e-9);
                if (lA > lB) lA = lB = (int)floor(jx + rr * amid + 0.5);
            } else {
                lA = lB = (int)floor(jx + rr * amid + 0.5);
            }
            if (lB < 0 || lA > dd->lat.line_count - 1) continue;
            if (lA < 0) lA = 0;
            if (lB > dd->lat.line_count - 1) lB = dd->lat.line_count - 1;
            row = dd->pre[n] + 3 * (size_t)J * nl1;
            cnt = row[3 * (lB + 1) + 2] - row[3 * lA + 2];
            if (!(cnt > 0.0)) continue;
            m0 = (row[3 * (lB + 1)] - row[3 * lA]) / cnt;
            m1 = (row[3 * (lB + 1) + 1] - row[3 * lA + 1]) / cnt;
            hx = (m0 - m1) / x->o.receiver_slope; /* virtual point (spec §5.4) */
            hy = m0 * zs;
            if (!r.ortho && !(hx * hx + hy * hy > 0.0)) continue;
            Ig += ssb_slab(&x->e, &r, hx, hy, &th);
        }
        Ifar += wg * Ig;
    }
    *far_sum = Ifar;
}

/* Normal of texel (x, y) in double (the given or reconstructed buffer; the eye direction when
 * it is (0,0,0)). */
static void ssb_normal(const ss_cam *c, const float *normals, int x, int y, double z, double n[3])
{
    const float *np = normals + 3 * ((ptrdiff_t)y * c->stride + x);
    n[0] = (double)np[0];
    n[1] = (double)np[1];
    n[2] = (double)np[2];
    if (!ss_normalize3(n)) {
        if (c->persp) {
            ss_unproject(c, (double)x + 0.5, (double)y + 0.5, z, n);
            n[0] = -n[0];
            n[1] = -n[1];
            n[2] = -n[2];
            ss_normalize3(n);
        } else {
            n[0] = n[1] = 0.0;
            n[2] = 1.0;
        }
    }
}

/* Sparse mode box average (spec §5.9): mean depth and normal over the accepted 3x3 neighbours
 * (n_c . n_i > 0.5 and |z_i - z_c| < 3 % z_c); bit (dy+1)*3 + (dx+1) of *mask marks them. */
static void ssb_box(const ss_cam *c, const float *depth, const float *normals, int x, int y,
                    double *zo, double no[3], unsigned *mask)
{
    double zc = ss_tex(c, depth, x, y), nc[3], zs = 0.0, ns[3] = {0.0, 0.0, 0.0};
    int dx, dy, k = 0;
    unsigned m = 0;
    ssb_normal(c, normals, x, y, zc, nc);
    for (dy = -1; dy <= 1; dy++)
        for (dx = -1; dx <= 1; dx++) {
            int xx = x + dx, yy = y + dy;
            double zi, ni[3];
            if (xx < c->gx || yy < c->gy || xx >= c->W - c->gx || yy >= c->H - c->gy) continue;
            zi = ss_tex(c, depth, xx, yy);
            if (ss_bg(c, zi) || !(fabs(zi - zc) < 0.03 * zc)) continue;
            ssb_normal(c, normals, xx, yy, zi, ni);
            if (!(ss_dot3(ni, nc) > 0.5)) continue;
            m |= 1u << ((dy + 1) * 3 + (dx + 1));
            zs += zi;
            ns[0] += ni[0];
            ns[1] += ni[1];
            ns[2] += ni[2];
            k++;
        }
    *zo = zs / (double)k;
    if (!ss_normalize3(ns)) memcpy(ns, nc, sizeof ns);
    memcpy(no, ns, sizeof ns);
    *mask = m;
}

static void ssb_blur(const float *in, ptrdiff_t is, int w, int h, int rad, double thr, float *out,
                     ptrdiff_t os)
{
    int x, y, dx, dy;
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            double lc = 1.0 - (double)in[(ptrdiff_t)y * is + x], s = 0.0;
            int k = 0;
            for (dy = -rad; dy <= rad; dy++)
                for (dx = -rad; dx <= rad; dx++) {
                    int xx = x + dx, yy = y + dy;
                    double li;
                    if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
                    li = 1.0 - (double)in[(ptrdiff_t)yy * is + xx];
                    if (!(fabs(li - lc) <= thr * lc) && !(dx == 0 && dy == 0)) continue;
                    s += li;
                    k++;
                }
            out[(ptrdiff_t)y * os + x] = (float)(1.0 - s / (double)k);
        }
}

hfvis_status hfvis_ssao_bilateral_blur(const float *in, ptrdiff_t in_stride, int width,
                                       int height, int radius, double threshold, float *out,
                                       ptrdiff_t out_stride)
{
    if (!in || !out || width < 1 || height < 1 || in_stride < width || out_stride < width ||
        radius < 0 || radius > 64 || !(ss_finite(threshold) && threshold >= 0.0) || in == out)
        return HFVIS_ERR_INVALID_ARGUMENT;
    ssb_blur(in, in_stride, width, height, radius, threshold, out, out_stride);
    return HFVIS_OK;
}

/* Common setup of hfvis_ffao / hfvis_ssao_mipmap: camera, options, estimator (building the
 * table when needed into *own). */
static hfvis_status ssb_setup(ssb_ctx *x, const hfvis_camera *cam, const float *depth,
                              const hfvis_ffao_options *opts, float *ao, ptrdiff_t ao_stride,
                              hfvis_ffao_table *own)
{
    hfvis_status s;
    memset(x, 0, sizeof *x);
    memset(own, 0, sizeof *own);
    if (ss_cam_load(cam, &x->c) != HFVIS_OK || hfvis_ffao_options_resolve(opts, &x->o) != HFVIS_OK ||
        !depth || !ao || ao_stride < x->c.W - 2 * x->c.gx)
        return HFVIS_ERR_INVALID_ARGUMENT;
    x->depth = depth;
    x->bil = x->o.sampling == HFVIS_SSAO_SAMPLING_BILINEAR;
    s = ssb_est_init(&x->e, &x->o.falloff, x->o.estimator, x->o.table, x->o.quad_nodes, x->o.thickness);
    if (s != HFVIS_OK) return s;
    if (x->e.mode == 2 && !x->o.table) {
        s = hfvis_ffao_table_build(&x->o.falloff, 0, 0, 0, 0, 0.0, x->o.alloc, own);
        if (s != HFVIS_OK) return s;
        x->e.table = own;
    }
    return HFVIS_OK;
}

hfvis_status hfvis_ffao(const hfvis_camera *cam, const float *depth, const float *normals,
                        const hfvis_ffao_options *opts, float *ao, ptrdiff_t ao_stride)
{
    ssb_ctx x;
    hfvis_ffao_table own;
    hfvis_status s;
    const ss_cam *c;
    hfvis_ssao_direction *dirs = NULL;
    ssb_dir dd;
    float *nrm = NULL;
    double *pre = NULL, *acc = NULL;
    size_t maxpre = 0, npix, maxlines = 0, b;
    int K, k, W, H, px, py;
    const hfvis_allocator *al;
    s = ssb_setup(&x, cam, depth, opts, ao, ao_stride, &own);
    if (s != HFVIS_OK) return s;
    c = &x.c;
    al = x.o.alloc;
    K = x.o.directions;
    W = c->W - 2 * c->gx;
    H = c->H - 2 * c->gy;
    npix = (size_t)W * (size_t)H;
    memset(&dd, 0, sizeof dd);
    s = HFVIS_ERR_OUT_OF_MEMORY;
    if (!normals) {
        b = ss_bytes3((size_t)c->stride, (size_t)c->H, 3 * sizeof(float));
        if (!b || !(nrm = (float *)ss_alloc(al, b))) goto done;
        ss_normals_fill(c, depth, nrm);
        normals = nrm;
    }
    if (!(dirs = (hfvis_ssao_direction *)ss_alloc(al, (size_t)K * sizeof *dirs))) goto done;
    hfvis_ssao_directions_uniform(K, x.o.azimuth0_rad, 1.0, 1.0, dirs);
    for (k = 0; k < K; k++) { /* sizes: the largest direction */
        s = ss_lattice_init(c, &dirs[k], &dd.lat);
        if (s != HFVIS_OK) goto done;
        if ((size_t)dd.lat.line_count > maxlines) maxlines = (size_t)dd.lat.line_count;
    }
    s = HFVIS_ERR_OUT_OF_MEMORY;
    if (!(dd.lines = (hfvis_ssao_line *)ss_alloc(al, maxlines * sizeof *dd.lines))) goto done;
    for (k = 0; k < K; k++) {
        size_t t;
        ss_lattice_init(c, &dirs[k], &dd.lat);
        ss_lattice_fill(c, &dd.lat, dd.lines);
        t = ssb_dir_size(&x, &dd);
        if (t > maxpre) maxpre = t;
    }
    b = ss_bytes3(maxpre, 1, sizeof(double));
    if (!b || !(pre = (double *)ss_alloc(al, b))) goto done;
    /* per pixel: ao sum; sparse adds far sum, far weight and the box mask */
    b = ss_bytes3(npix, x.o.sparse ? 4 : 1, sizeof(double));
    if (!b || !(acc = (double *)ss_alloc(al, b))) goto done;
    memset(acc, 0, b);
    for (k = 0; k < K; k++) {
        int g;
        ss_lattice_init(c, &dirs[k], &dd.lat);
        ss_lattice_fill(c, &dd.lat, dd.lines);
        ssb_dir_size(&x, &dd);
        dd.phi = x.o.azimuth0_rad + 2.0 * SS_PI * (double)k / (double)K;
        ss_plane_e1(c, dirs[k].dx, dirs[k].dy, dd.e1);
        for (g = 0; g <= x.o.segments; g++)
            ssb_e1_phi(c, dd.phi - SS_PI / (double)K + 2.0 * SS_PI * (double)g / ((double)K * (double)x.o.segments),
                       dd.eb[g]);
        ssb_scan(&x, &dd, pre);
        for (py = 0; py < H; py++)
            for (px = 0; px < W; px++) {
                int tx = px + c->gx, ty = py + c->gy;
                double z = ss_tex(c, depth, tx, ty), nv[3], ns, fs, ws, jit = 0.0;
                size_t o = (size_t)py * (size_t)W + (size_t)px;
                if (ss_bg(c, z)) continue;
                if (x.o.jitter) jit = 2.0 * ss_hash01((uint32_t)tx, (uint32_t)ty, 7u, x.o.seed) - 1.0;
                ssb_normal(c, normals, tx, ty, z, nv);
                if (!x.o.sparse) {
                    ssb_pixel_dir(&x, &dd, (double)tx + 0.5, (double)ty + 0.5, z, nv, jit, 1, 1, &ns, &fs, &ws);
                    acc[o] += ns + fs;
                } else {
                    int cls = (px % 3) + 3 * (py % 3);
                    ssb_pixel_dir(&x, &dd, (double)tx + 0.5, (double)ty + 0.5, z, nv, jit, 1, 0, &ns, &fs, &ws);
                    acc[o] += ns;
                    if (k % 9 == cls) {
                        double za, na[3];
                        unsigned m;
                        ssb_box(c, depth, normals, tx, ty, &za, na, &m);
                        ssb_pixel_dir(&x, &dd, (double)tx + 0.5, (double)ty + 0.5, za, na, jit, 0, 1, &ns, &fs, &ws);
                        acc[npix + o] += fs;
                        acc[2 * npix + o] += ws;
                        acc[3 * npix + o] = (double)m;
                    }
                }
            }
    }
    if (!x.o.sparse) {
        for (py = 0; py < H; py++)
            for (px = 0; px < W; px++) {
                double a = acc[(size_t)py * (size_t)W + (size_t)px] / SS_PI;
                if (ss_bg(c, ss_tex(c, depth, px + c->gx, py + c->gy))) a = 0.0;
                ao[(ptrdiff_t)py * ao_stride + px] = (float)(a > 0.0 ? (a < 1.0 ? a : 1.0) : 0.0);
            }
    } else {
        /* gather (spec §5.9): near field + far field averaged over the accepted 3x3 pixels,
         * renormalised by the summed sector weights; then the optional 5x5 bilateral blur */
        float *tmp = (float *)(acc + npix); /* the far sums are consumed row by row below */
        double *res = acc;                  /* reuse: result per pixel overwrites the near sum */
        for (py = 0; py < H; py++)
            for (px = 0; px < W; px++) {
                size_t o = (size_t)py * (size_t)W + (size_t)px;
                double fsum = 0.0, wsum = 0.0, a;
                unsigned m = (unsigned)acc[3 * npix + o];
                int dx, dy;
                if (ss_bg(c, ss_tex(c, depth, px + c->gx, py + c->gy))) {
                    acc[3 * npix + o] = -1.0;
                    continue;
                }
                for (dy = -1; dy <= 1; dy++)
                    for (dx = -1; dx <= 1; dx++) {
                        size_t q;
                        if (!(m & (1u << ((dy + 1) * 3 + (dx + 1))))) continue;
                        q = (size_t)(py + dy) * (size_t)W + (size_t)(px + dx);
                        fsum += acc[npix + q];
                        wsum += acc[2 * npix + q];
                    }
                a = res[o] / SS_PI + (wsum > 0.0 ? 2.0 * fsum / wsum : 0.0); /* (1/pi) 2 pi fsum/wsum */
                acc[3 * npix + o] = a; /* staged: neighbours still need the far sums */
            }
        for (py = 0; py < H; py++)
            for (px = 0; px < W; px++) {
                size_t o = (size_t)py * (size_t)W + (size_t)px;
                double a = acc[3 * npix + o];
                a = a > 0.0 ? (a < 1.0 ? a : 1.0) : 0.0;
                tmp[o] = (float)a;
            }
        if (x.o.blur) ssb_blur(tmp, W, W, H, x.o.blur_radius, x.o.blur_threshold, (float *)acc, W);
        for (py = 0; py < H; py++)
            for (px = 0; px < W; px++) {
                size_t o = (size_t)py * (size_t)W + (size_t)px;
                float a = x.o.blur ? ((float *)acc)[o] : tmp[o];
                if (ss_bg(c, ss_tex(c, depth, px + c->gx, py + c->gy))) a = 0.0f;
                ao[(ptrdiff_t)py * ao_stride + px] = a;
            }
    }
    s = HFVIS_OK;
done:
    ss_free(al, acc);
    ss_free(al, pre);
    ss_free(al, dd.lines);
    ss_free(al, dirs);
    ss_free(al, nrm);
    if (own.values) hfvis_ffao_table_free(&own);
    return s;
}

/* ========================================================================================== */
/* 10. The mipmap baseline ([P4] §5, spec §5.10)                                               */
/* ========================================================================================== */

/* Pyramid level sizes: level l is ceil(W / 2^l) x ceil(H / 2^l); offsets into one block. */
static int ssb_mip_layout(const ss_cam *c, int *w, int *h, size_t *off, size_t *total)
{
    int l = 0;
    size_t t = 0;
    w[0] = c->W;
    h[0] = c->H;
    for (;;) {
        off[l] = t;
        t += (size_t)w[l] * (size_t)h[l];
        if ((w[l] == 1 && h[l] == 1) || l == 31) break;
        w[l + 1] = (w[l] + 1) / 2;
        h[l + 1] = (h[l] + 1) / 2;
        l++;
    }
    *total = t;
    return l + 1;
}

/* Depth of level l at continuous full-resolution position (u, v), bilinear over the level's
 * non-background texels (NaN when all taps are background). */
static double ssb_mip_tap(const float *m, int w, int h, int l, double u, double v)
{
    double s = (double)(1 << l), a = u / s - 0.5, b = v / s - 0.5, acc = 0.0, ws = 0.0, fa, fb;
    int x0, y0, k;
    if (a < 0.0) a = 0.0;
    if (b < 0.0) b = 0.0;
    if (a > (double)(w - 1)) a = (double)(w - 1);
    if (b > (double)(h - 1)) b = (double)(h - 1);
    x0 = (int)a;
    y0 = (int)b;
    if (x0 > w - 2) x0 = w > 1 ? w - 2 : 0;
    if (y0 > h - 2) y0 = h > 1 ? h - 2 : 0;
    fa = a - (double)x0;
    fb = b - (double)y0;
    for (k = 0; k < 4; k++) {
        int xx = x0 + (k & 1), yy = y0 + (k >> 1);
        double wt = ((k & 1) ? fa : 1.0 - fa) * ((k >> 1) ? fb : 1.0 - fb), z;
        if (wt <= 0.0 || xx >= w || yy >= h) continue;
        z = (double)m[(size_t)yy * (size_t)w + (size_t)xx];
        if (z != z) continue;
        acc += wt * z;
        ws += wt;
    }
    return ws > 0.0 ? acc / ws : SS_NAN;
}

hfvis_status hfvis_ssao_mipmap(const hfvis_camera *cam, const float *depth, const float *normals,
                               const hfvis_ffao_options *opts, float *ao, ptrdiff_t ao_stride)
{
    ssb_ctx x;
    hfvis_ffao_table own;
    hfvis_status s;
    const ss_cam *c;
    float *nrm = NULL, *mip = NULL;
    int lw[33], lh[33], nl, l, K, k, W, H, px, py, i, j;
    size_t off[33], tot, b;
    const hfvis_allocator *al;
    s = ssb_setup(&x, cam, depth, opts, ao, ao_stride, &own);
    if (s != HFVIS_OK) return s;
    c = &x.c;
    al = x.o.alloc;
    K = x.o.mip_directions;
    W = c->W - 2 * c->gx;
    H = c->H - 2 * c->gy;
    s = HFVIS_ERR_OUT_OF_MEMORY;
    if (!normals) {
        b = ss_bytes3((size_t)c->stride, (size_t)c->H, 3 * sizeof(float));
        if (!b || !(nrm = (float *)ss_alloc(al, b))) goto done;
        ss_normals_fill(c, depth, nrm);
        normals = nrm;
    }
    nl = ssb_mip_layout(c, lw, lh, off, &tot);
    b = ss_bytes3(tot, 1, sizeof(float));
    if (!b || !(mip = (float *)ss_alloc(al, b))) goto done;
    for (j = 0; j < c->H; j++) /* level 0: depth, NaN for background */
        for (i = 0; i < c->W; i++) {
            double z = ss_tex(c, depth, i, j);
            mip[(size_t)j * (size_t)c->W + (size_t)i] = ss_bg(c, z) ? (float)SS_NAN : (float)z;
        }
    for (l = 1; l < nl; l++) /* averaged mips (continuous) or min-depth "max" mips (thickness) */
        for (j = 0; j < lh[l]; j++)
            for (i = 0; i < lw[l]; i++) {
                double acc = 0.0, mn = SS_INF;
                int q, n = 0;
                for (q = 0; q < 4; q++) {
                    int xx = 2 * i + (q & 1), yy = 2 * j + (q >> 1);
                    double z;
                    if (xx >= lw[l - 1] || yy >= lh[l - 1]) continue;
                    z = (double)mip[off[l - 1] + (size_t)yy * (size_t)lw[l - 1] + (size_t)xx];
                    if (z != z) continue;
                    acc += z;
                    if (z < mn) mn = z;
                    n++;
                }
                mip[off[l] + (size_t)j * (size_t)lw[l] + (size_t)i] =
                    n ? (float)(x.o.thickness > 0.0 ? mn : acc / (double)n) : (float)SS_NAN;
            }
    for (py = 0; py < H; py++)
        for (px = 0; px < W; px++) {
            int tx = px + c->gx, ty = py + c->gy;
            double z = ss_tex(c, depth, tx, ty), nv[3], P[3], v[3], sum = 0.0, a;
            if (ss_bg(c, z)) {
                ao[(ptrdiff_t)py * ao_stride + px] = 0.0f;
                continue;
            }
            ssb_normal(c, normals, tx, ty, z, nv);
            ss_unproject(c, (double)tx + 0.5, (double)ty + 0.5, z, P);
            memcpy(v, P, sizeof v);
            if (c->persp) ss_normalize3(v);
            else v[0] = v[1] = 0.0, v[2] = 1.0;
            for (k = 0; k < K; k++) {
                double phi = x.o.azimuth0_rad + 2.0 * SS_PI * (double)k / (double)K;
                double D[2], e1[3], ea[3], eb[3], yh[3], zs, th = SS_PI, I = 0.0, dist, step, tmax;
                double cu = (double)tx + 0.5, cv = (double)ty + 0.5, t1;
                ssb_rx r;
                int last = 0;
                D[0] = cos(phi);
                D[1] = sin(phi);
                ss_plane_e1(c, D[0], D[1], e1);
                ssb_e1_phi(c, phi - SS_PI / (double)K, ea);
                ssb_e1_phi(c, phi + SS_PI / (double)K, eb);
                ss_plane_yhat(c, e1, P, yh);
                zs = c->persp ? 1.0 / yh[2] : 1.0;
                ssb_rx_init(&r, !c->persp, ss_dot3(P, e1), P[2] * zs, ss_dot3(nv, e1), ss_dot3(nv, yh));
                /* distance to the texel-centre rectangle's edge along D */
                tmax = SS_INF;
                for (i = 0; i < 2; i++) {
                    double pc = i ? cv : cu, hi = (double)(i ? c->H : c->W) - 0.5;
                    if (D[i] > 1e-12) t1 = (hi - pc) / D[i];
                    else if (D[i] < -1e-12) t1 = (0.5 - pc) / D[i];
                    else continue;
                    if (t1 < tmax) tmax = t1;
                }
                dist = 1.0;
                step = 1.0;
                while (!last) {
                    double u, vv, lam, lf, zq, z2, Q[3];
                    int l0;
                    if (dist >= tmax) { /* one extra sample at the buffer edge (spec §5.10) */
                        dist = tmax;
                        last = 1;
                        if (!(tmax > 0.0)) break;
                    }
                    u = cu + dist * D[0];
                    vv = cv + dist * D[1];
                    lam = 2.0 * dist * tan(SS_PI / (double)K);
                    lam = lam > 1.0 ? log(lam) / log(2.0) : 0.0;
                    if (lam > (double)(nl - 1)) lam = (double)(nl - 1);
                    l0 = (int)lam;
                    lf = lam - (double)l0;
                    zq = ssb_mip_tap(mip + off[l0], lw[l0], lh[l0], l0, u, vv);
                    if (lf > 0.0 && l0 + 1 < nl) {
                        z2 = ssb_mip_tap(mip + off[l0 + 1], lw[l0 + 1], lh[l0 + 1], l0 + 1, u, vv);
                        if (zq != zq) zq = z2;
                        else if (z2 == z2) zq = (1.0 - lf) * zq + lf * z2;
                    }
                    if (zq == zq) {
                        ss_unproject(c, u, vv, zq, Q);
                        I += ssb_slab(&x.e, &r, ss_dot3(Q, e1), Q[2] * zs, &th);
                    }
                    step *= x.o.mip_growth;
                    dist += step;
                }
                sum += ssb_wedge(ea, eb, v) * I;
            }
            a = sum / SS_PI;
            ao[(ptrdiff_t)py * ao_stride + px] = (float)(a > 0.0 ? (a < 1.0 ? a : 1.0) : 0.0);
        }
    s = HFVIS_OK;
done:
    ss_free(al, mip);
    ss_free(al, nrm);
    if (own.values) hfvis_ffao_table_free(&own);
    return s;
}

/* ========================================================================================== */
/* 11. Error metrics ([P4] §8, spec §5.12)                                                     */
/* ========================================================================================== */

hfvis_status hfvis_ssao_error(const float *ao, ptrdiff_t ao_stride, const float *ref,
                              ptrdiff_t ref_stride, int width, int height, double tolerance,
                              int relative, hfvis_ssao_error_stats *stats, float *error_image,
                              ptrdiff_t error_stride)
{
    double sum = 0.0, sq = 0.0, mx = 0.0, in = 0.0, sd = 0.0;
    size_t n = 0;
    int x, y;
    if (!ao || !ref || !stats || width < 1 || height < 1 || ao_stride < width ||
        ref_stride < width || (error_image && error_stride < width) ||
        !(ss_finite(tolerance) && tolerance >= 0.0) || (relative != 0 && relative != 1))
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (y = 0; y < height; y++)
        for (x = 0; x < width; x++) {
            double a = (double)ao[(ptrdiff_t)y * ao_stride + x];
            double r = (double)ref[(ptrdiff_t)y * ref_stride + x], e;
            if (!ss_finite(a) || !ss_finite(r)) {
                if (error_image) error_image[(ptrdiff_t)y * error_stride + x] = 1.0f;
                continue;
            }
            e = fabs(a - r);
            if (relative && fabs(r) > 1e-6) e /= fabs(r);
            sum += e;
            sd += a - r;
            sq += e * e;
            if (e > mx) mx = e;
            if (e <= tolerance) in += 1.0;
            n++;
            if (error_image) {
                double g = 1.0 - e / 0.2; /* white = 0, black >= 20 % ([P4] Fig. 7) */
                error_image[(ptrdiff_t)y * error_stride + x] = (float)(g > 0.0 ? g : 0.0);
            }
        }
    memset(stats, 0, sizeof *stats);
    stats->count = n;
    if (n) {
        stats->mean = sum / (double)n;
        stats->bias = sd / (double)n;
        stats->rms = sqrt(sq / (double)n);
        stats->max = mx;
        stats->within = in / (double)n;
    }
    return HFVIS_OK;
}
