
/* ========================================================================================== */
/* 14. Nowrouzezahrai-Snyder GI: slices, pyramid, lights, bounces                             */
/* ========================================================================================== */
/* The pipeline of [NS09] D. Nowrouzezahrai, J. Snyder, "Fast Global Illumination on Dynamic
 * Height Fields", CGF 28(4), 2009, on top of the math layer of section 13: the multi-resolution
 * height pyramid and the exponential step schedule (§5.2, Eq. 14-15), the maximum blocking angle
 * as a B-spline maximum and the casting set (Eq. 16-17), the visibility and indirect-radiance
 * NLP vectors (Eq. 11-12), the per-sample form of the wedge accumulation (Eq. 20-21), key and
 * directional lights (§6-7), shading with diffuse and Phong lobes (§7), the radiance pyramids of
 * the bounces (§5.3) and sub-sampling with full-resolution normals (§7, Fig. 6-7). "spec" is
 * spec/raycast-ao-and-hf-gi.md part B; its errata and [choice]s are applied and cited.
 *
 * Contents
 *   1. Limits, small helpers, the B-spline maximum (Eq. 16) and per-sample wedge matrices
 *   2. The multi-resolution pyramid (spec B.4 CPU proposal, B.5)
 *   3. Options, scene validation and the memory plan
 *   4. The slice scan: blocking angles, omega_max, casting set (Eq. 14-17)
 *   5. Receiver records: visibility, key and directional lights (Eq. 11, §6, spec B.8)
 *   6. Receiver records: indirect radiance of a bounce (Eq. 12, §5.3, spec B.5)
 *   7. Shading (§7) and the sliding two-row upsampling of sub-sampled receivers (spec B.9)
 *   8. The driver (spec B.9 RENDER)
 *
 * Everything is computed in double; the pyramids, the glossy incident-radiance buffer and the
 * outputs are float. Comparisons of blocking angles are made on tangents (atan is monotone), and
 * the NLP projections only need sin(omega) = t / sqrt(1 + t^2), so atan is evaluated only where
 * the B-spline maximum needs angles. */

#define HF_NS_CAST_TOL 1e-12          /* spec B.4: omega_i > run + 1e-12 enters the casting set */
#define HF_NS_SNAP 1e-15              /* |cos|, |sin| below this are axis directions: exactly 0 */
#define HF_NS_MAXCH 64                /* channels of a pyramid: 16 SH x 4 colour channels */
#define HF_NS_KTAPS 7                 /* blur kernel taps (offsets -3..3) */

/* ------------------------------------------------------ 1. helpers, Eq. 16, sample matrices */

/* vbar(sigma) of Eq. 10 from s = sin(sigma) (spec B.3 closed form; same as ns_vbar). */
static void hf_ns_vbar(double s, double *v)
{
    double s2 = s * s;
    v[0] = NS_NLP0 * (s + 1.0);
    v[1] = NS_NLP1 * (s2 - 1.0) / 2.0;
    v[2] = NS_NLP2 * (s2 - 1.0) * s / 2.0;
    v[3] = NS_NLP3 * (5.0 * s2 - 1.0) * (s2 - 1.0) / 8.0;
}

/* Eq. 11: v = vbar(hi) - vbar(lo) for sines lo < hi, else 0. */
static void hf_ns_vis(double s_lo, double s_hi, double *v)
{
    double a[4], b[4];
    int q;
    if (!(s_hi > s_lo)) {
        v[0] = v[1] = v[2] = v[3] = 0.0;
        return;
    }
    hf_ns_vbar(s_hi, b);
    hf_ns_vbar(s_lo, a);
    for (q = 0; q < 4; q++) v[q] = b[q] - a[q];
}

/* Band of SH index i. */
static int hf_ns_band(int i) { return i < 1 ? 0 : i < 4 ? 1 : i < 9 ? 2 : 3; }

/* The zonal lobe Ahat rotated to axis a (unit): F_i = Ahat_l Y_i(a). */
static void hf_ns_lobe(const double *Ahat, const double *a, double *F)
{
    int i;
    ns_sh_eval_unit(a[0], a[1], a[2], F);
    for (i = 0; i < NS_SH_N; i++) F[i] *= Ahat[hf_ns_band(i)];
}

static double hf_ns_sine(double t) { return t / sqrt(1.0 + t * t); }

/* acc (16) += G (16x4, row-major) * w (4). */
static void hf_ns_acc(double *acc, const double *G, const double *w)
{
    int r;
    for (r = 0; r < NS_SH_N; r++, G += 4) acc[r] += G[0] * w[0] + G[1] * w[1] + G[2] * w[2] + G[3] * w[3];
}

static double hf_ns_dot16(const double *a, const double *b)
{
    double s = 0.0;
    int i;
    for (i = 0; i < NS_SH_N; i++) s += a[i] * b[i];
    return s;
}

/* out (16) += T (16x16, out index major) * v (16). */
static void hf_ns_matvec_add(const double *T, const double *v, double *out)
{
    int r, i;
    for (r = 0; r < NS_SH_N; r++, T += NS_SH_N) {
        double s = 0.0;
        for (i = 0; i < NS_SH_N; i++) s += T[i] * v[i];
        out[r] += s;
    }
}

static double hf_ns_bs_knot(const double *w, int n, int j)
{
    int a = j > 0 ? j - 1 : 0, b = j + 1 < n ? j + 1 : n - 1;
    return (w[a] + 4.0 * w[j] + w[b]) / 6.0;
}

static double hf_ns_bs_mid(const double *w, int n, int j)
{
    int a = j > 0 ? j - 1 : 0, d = j + 2 < n ? j + 2 : n - 1;
    return (w[a] + 23.0 * w[j] + 23.0 * w[j + 1] + w[d]) / 48.0;
}

hfvis_status hfvis_ns_bspline_max(int n, const double *omega_rad, double *out)
{
    double best;
    int j;
    if (out == NULL || n < 0 || (n > 0 && omega_rad == NULL)) return HFVIS_ERR_INVALID_ARGUMENT;
    for (j = 0; j < n; j++)
        if (!isfinite(omega_rad[j])) return HFVIS_ERR_INVALID_ARGUMENT;
    if (n == 0) {
        *out = -HF_HALF_PI;
        return HFVIS_OK;
    }
    /* Eq. 16: knots S(j) and midpoints S(j + 1/2) of the uniform cubic B-spline, ends replicated */
    best = hf_ns_bs_knot(omega_rad, n, 0);
    for (j = 0; j < n; j++) {
        double v = hf_ns_bs_knot(omega_rad, n, j);
        if (v > best) best = v;
        if (j + 1 < n) {
            v = hf_ns_bs_mid(omega_rad, n, j);
            if (v > best) best = v;
        }
    }
    *out = best;
    return HFVIS_OK;
}

/* The angle of sample i, atan(t_i), computed once (w[i] = 3 marks "not yet"). */
static double hf_ns_ang(const double *t, double *w, int i)
{
    if (w[i] > 2.0) w[i] = atan(t[i]);
    return w[i];
}

/* A cheap atan with |error| <= 1.51e-3 rad (Rajan et al. 2006 on [-1, 1], reflected outside),
 * used only to find which B-spline windows can hold the maximum. */
#define HF_NS_FATAN_ERR 1.6e-3
static inline double hf_ns_fatan(double t)
{
    double a = fabs(t), r;
    if (a <= 1.0) return 0.78539816339744831 * t - t * (a - 1.0) * (0.2447 + 0.0663 * a);
    r = 1.0 / t;
    a = fabs(r);
    return (t > 0.0 ? HF_HALF_PI : -HF_HALF_PI) - (0.78539816339744831 * r - r * (a - 1.0) * (0.2447 + 0.0663 * a));
}

/* Eq. 16 on the tangents t[0..n-1] (n >= 1): the value hfvis_ns_bspline_max gives for their
 * angles. A knot or midpoint value is a convex combination of its window's angles, so with the
 * cheap atan every window's value is known to within HF_NS_FATAN_ERR; only the windows that can
 * still hold the maximum are evaluated with atan. w: n doubles of scratch, ap: 3n. */
static double hf_ns_omax_bspline(const double *t, int n, double *w, double *ap)
{
    double amax = -HF_INF, best = -HF_INF, thr, *sk = ap + n;
    int i, j;
    for (i = 0; i < n; i++) {
        w[i] = 3.0;
        ap[i] = hf_ns_fatan(t[i]);
    }
    /* sk[2j] = approximate knot value, sk[2j+1] = approximate midpoint value (the constants'
     * rounding is far inside the bound) */
    for (j = 0; j < n; j++) {
        const double p = ap[j > 0 ? j - 1 : 0], c0 = ap[j], nx = ap[j + 1 < n ? j + 1 : n - 1];
        double v = (p + 4.0 * c0 + nx) * (1.0 / 6.0);
        sk[2 * j] = v;
        if (v > amax) amax = v;
        if (j + 1 < n) {
            v = (p + 23.0 * (c0 + nx) + ap[j + 2 < n ? j + 2 : n - 1]) * (1.0 / 48.0);
            sk[2 * j + 1] = v;
            if (v > amax) amax = v;
        }
    }
    thr = amax - 2.0 * HF_NS_FATAN_ERR - 1e-12;
    for (j = 0; j < n; j++) {
        int a = j > 0 ? j - 1 : 0, b = j + 1 < n ? j + 1 : n - 1, d = j + 2 < n ? j + 2 : n - 1;
        if (sk[2 * j] >= thr) {
            double v = (hf_ns_ang(t, w, a) + 4.0 * hf_ns_ang(t, w, j) + hf_ns_ang(t, w, b)) / 6.0;
            if (v > best) best = v;
        }
        if (j + 1 < n && sk[2 * j + 1] >= thr) {
            double v = (hf_ns_ang(t, w, a) + 23.0 * hf_ns_ang(t, w, j) + 23.0 * hf_ns_ang(t, w, b) +
                        hf_ns_ang(t, w, d)) / 48.0;
            if (v > best) best = v;
        }
    }
#ifdef HFVIS_ENABLE_ASSERTS
    {
        double full;
        for (i = 0; i < n; i++) (void)hf_ns_ang(t, w, i);
        (void)hfvis_ns_bspline_max(n, w, &full);
        HFVIS_ASSERT(full == best);
    }
#endif
    return best;
}

hfvis_status hfvis_ns_sample_matrices(const hfvis_ns_wedges *set, double *G)
{
    int cols, ns, nw, m, j, s, k, r;
    size_t i, total;
    if (set == NULL || G == NULL) return HFVIS_ERR_INVALID_ARGUMENT;
    cols = hfvis_ns_wedge_columns(set->interp);
    m = set->samples;
    if (cols == 0 || m < (set->full_circle ? 1 : 2) || !isfinite(set->phi0_rad) ||
        !isfinite(set->dphi_rad))
        return HFVIS_ERR_INVALID_ARGUMENT;
    ns = cols / 4;
    nw = set->full_circle ? m : m - 1;
    total = (size_t)m * 64u;
    for (i = 0; i < total; i++) G[i] = 0.0;
    /* Eq. 21 as Sum_j Rot_z(M [w_j; w_(j+1)], phi_j) = Sum_i (Sum_(j,s -> i) Rot_z(M_s, phi_j)) w_i:
     * the sample index of each block as in hfvis_ns_wedges_to_sh (wrapped or clamped) */
    for (j = 0; j < nw; j++) {
        double ang = set->phi0_rad + (double)j * set->dphi_rad;
        for (s = 0; s < ns; s++) {
            int idx = j + s - (ns == 4 ? 1 : 0);
            if (set->full_circle) idx = ((idx % m) + m) % m;
            else idx = idx < 0 ? 0 : (idx > m - 1 ? m - 1 : idx);
            for (k = 0; k < 4; k++) {
                double col[NS_SH_N], rot[NS_SH_N];
                for (r = 0; r < NS_SH_N; r++) col[r] = set->matrix[r * cols + s * 4 + k];
                (void)hfvis_sh_rotate_z(col, ang, rot);
                for (r = 0; r < NS_SH_N; r++) G[((size_t)idx * 16u + (size_t)r) * 4u + (size_t)k] += rot[r];
            }
        }
    }
    return HFVIS_OK;
}

/* ---------------------------------------------------------------------- 2. the pyramid */

/* One level: a float image of w x h texels x channels, sampled at grid position x as the octave
 * coordinate u = x*a + b (texel centres of octave o sit at grid positions 2^o (i + 1/2) - 1/2,
 * times the base scale of a sub-sampled base). */
typedef struct hf_ns_level {
    float *img;
    int w, h;
    double a, b;
} hf_ns_level;

static void hf_ns_oct_dims(int bw, int bh, int o, int *w, int *h)
{
    int i;
    *w = bw;
    *h = bh;
    for (i = 0; i < o; i++) {
        *w = (*w + 1) / 2;
        *h = (*h + 1) / 2;
    }
}

/* Index of filter tap i in [0, n) under the border rule, or -1 (OPEN: no texel there). */
static int hf_ns_tap(int i, int n, int border)
{
    if (i >= 0 && i < n) return i;
    if (border == HFVIS_BORDER_WRAP) return ((i % n) + n) % n;
    if (border == HFVIS_BORDER_CLAMP) return i < 0 ? 0 : n - 1;
    return -1;
}

/* dst (dw x dh) = separable filter of src (sw x sh), C channels: output texel X reads source
 * texels step*X + first + t, t = 0..nt-1, with weight w[t] per axis. Taps outside the image
 * follow the border; hole taps (channel 0 not finite) are dropped; the 2-D weights are
 * renormalised, which the two passes do exactly by carrying the weight sum beside the values.
 * row: sw*(C+1) doubles. */
static void hf_ns_filter(const float *src, int sw, int sh, float *dst, int dw, int dh, int C,
                         const double *w, int nt, int first, int step, int border, double *row)
{
    int X, Y, t, c, x;
    const int C1 = C + 1;
    for (Y = 0; Y < dh; Y++) {
        for (x = 0; x < sw * C1; x++) row[x] = 0.0;
        for (t = 0; t < nt; t++) {
            int yy = hf_ns_tap(Y * step + first + t, sh, border);
            const float *sr;
            if (yy < 0 || w[t] == 0.0) continue;
            sr = src + (size_t)yy * (size_t)sw * (size_t)C;
            for (x = 0; x < sw; x++) {
                const float *p = sr + (size_t)x * (size_t)C;
                double *r = row + (size_t)x * (size_t)C1;
                if (!isfinite(p[0])) continue;
                for (c = 0; c < C; c++) r[c] += w[t] * (double)p[c];
                r[C] += w[t];
            }
        }
        for (X = 0; X < dw; X++) {
            double acc[HF_NS_MAXCH], den = 0.0;
            float *o = dst + ((size_t)Y * (size_t)dw + (size_t)X) * (size_t)C;
            for (c = 0; c < C; c++) acc[c] = 0.0;
            for (t = 0; t < nt; t++) {
                int xx = hf_ns_tap(X * step + first + t, sw, border);
                const double *r;
                if (xx < 0 || w[t] == 0.0) continue;
                r = row + (size_t)xx * (size_t)C1;
                if (r[C] == 0.0) continue;
                for (c = 0; c < C; c++) acc[c] += w[t] * r[c];
                den += w[t] * r[C];
            }
            for (c = 0; c < C; c++) o[c] = den > 0.0 ? (float)(acc[c] / den) : (float)HF_NAN;
        }
    }
}

/* Cubic B-spline B3(u), support |u| < 2. */
static double hf_ns_b3(double u)
{
    u = fabs(u);
    if (u >= 2.0) return 0.0;
    if (u >= 1.0) return (2.0 - u) * (2.0 - u) * (2.0 - u) / 6.0;
    return (4.0 - 6.0 * u * u + 3.0 * u * u * u) / 6.0;
}

/* Variance of the sampled, normalised B3(x/s) kernel on x = -3..3 (weights into w if non-NULL). */
static double hf_ns_b3_variance(double s, double *w)
{
    double sum = 0.0, m2 = 0.0, t[HF_NS_KTAPS];
    int x;
    for (x = -3; x <= 3; x++) {
        t[x + 3] = hf_ns_b3((double)x / s);
        sum += t[x + 3];
        m2 += (double)(x * x) * t[x + 3];
    }
    if (w)
        for (x = 0; x < HF_NS_KTAPS; x++) w[x] = t[x] / sum;
    return m2 / sum;
}

/* The blur kernel of level j of an octave (spec B.4: "a normalized, sampled cubic B-spline kernel
 * of scale 2^(j/k)"): its scale is chosen (bisection) so that its variance is (4^(j/k) - 1)/4 G_o
 * texels^2: the variance of a level then grows like 4^(l/k) across the whole pyramid, G_(o+1)
 * adding the 3/4 of the [1,3,3,1]/8 decimation. j = 0 is the identity. */
static void hf_ns_blur_kernel(int k, int j, double *w)
{
    double target = (pow(4.0, (double)j / (double)k) - 1.0) / 4.0, lo = 0.5, hi = 2.0;
    int it;
    if (j == 0) {
        for (it = 0; it < HF_NS_KTAPS; it++) w[it] = it == 3 ? 1.0 : 0.0;
        return;
    }
    for (it = 0; it < 100; it++) {
        double mid = 0.5 * (lo + hi);
        if (hf_ns_b3_variance(mid, NULL) < target) lo = mid;
        else hi = mid;
    }
    (void)hf_ns_b3_variance(0.5 * (lo + hi), w);
}

/* Build levels 1..L-1 (level 0 filled by the caller). kern: k kernels of HF_NS_KTAPS taps. */
static void hf_ns_pyr_build(hf_ns_level *lv, int L, int k, int C, int border, const double *kern,
                            double *row)
{
    static const double dec[4] = {1.0 / 8.0, 3.0 / 8.0, 3.0 / 8.0, 1.0 / 8.0};
    int l;
    for (l = 1; l < L; l++) {
        int o = l / k, j = l % k;
        if (j == 0) {
            const hf_ns_level *s = &lv[k * (o - 1)];
            hf_ns_filter(s->img, s->w, s->h, lv[l].img, lv[l].w, lv[l].h, C, dec, 4, -1, 2, border, row);
        } else {
            const hf_ns_level *s = &lv[k * o];
            hf_ns_filter(s->img, s->w, s->h, lv[l].img, lv[l].w, lv[l].h, C, kern + j * HF_NS_KTAPS,
                         HF_NS_KTAPS, -3, 1, border, row);
        }
    }
}

/* Bilinear taps of coordinate u on n texels: clamped (OPEN, CLAMP) or periodic (WRAP). */
static void hf_ns_axis(double u, int n, int wrap, int *i0, int *i1, double *f)
{
    double fl;
    if (n == 1) {
        *i0 = *i1 = 0;
        *f = 0.0;
        return;
    }
    if (wrap) {
        u -= floor(u / (double)n) * (double)n;
        fl = floor(u);
        *i0 = (int)fl;
        if (*i0 >= n || *i0 < 0) {
            *i0 = 0;
            fl = 0.0;
            u = 0.0;
        }
        *i1 = *i0 + 1 == n ? 0 : *i0 + 1;
        *f = u - fl;
        return;
    }
    if (u < 0.0) u = 0.0;
    else if (u > (double)(n - 1)) u = (double)(n - 1);
    fl = floor(u);
    if (fl > (double)(n - 2)) fl = (double)(n - 2);
    *i0 = (int)fl;
    *i1 = *i0 + 1;
    *f = u - fl;
}

/* Clamped bilinear tap of coordinate u on n texels (OPEN, CLAMP): (int) truncation is floor for
 * u > 0, and u beyond the last texel gives weight 1 on it. */
static inline void hf_ns_axis_clamped(double u, int n, int *i0, double *f)
{
    int i;
    if (n == 1 || u <= 0.0) {
        *i0 = 0;
        *f = 0.0;
        return;
    }
    i = (int)u;
    if (i > n - 2) i = n - 2;
    *i0 = i;
    *f = u - (double)i;
    if (*f > 1.0) *f = 1.0;
}

/* One channel (heights): bilinear at grid position (x, y); a tap with zero weight is never read
 * (as hf_bilerp), so a hole beside an exact sample position does not leak in. NaN = hole. */
static inline double hf_ns_sample1(const hf_ns_level *L, int wrap, int holes, double x, double y)
{
    int x0, x1, y0, y1;
    double fx, fy, r0 = 0.0, r1;
    const float *p0, *p1;
    if (wrap) {
        hf_ns_axis(x * L->a + L->b, L->w, 1, &x0, &x1, &fx);
        hf_ns_axis(y * L->a + L->b, L->h, 1, &y0, &y1, &fy);
    } else {
        hf_ns_axis_clamped(x * L->a + L->b, L->w, &x0, &fx);
        hf_ns_axis_clamped(y * L->a + L->b, L->h, &y0, &fy);
        x1 = L->w > 1 ? x0 + 1 : x0;
        y1 = L->h > 1 ? y0 + 1 : y0;
    }
    p0 = L->img + (size_t)y0 * (size_t)L->w;
    p1 = L->img + (size_t)y1 * (size_t)L->w;
    if (!holes) /* every tap finite: the plain form gives the same value */
        return ((double)p0[x0] * (1.0 - fx) + (double)p0[x1] * fx) * (1.0 - fy) +
               ((double)p1[x0] * (1.0 - fx) + (double)p1[x1] * fx) * fy;
    if (fy != 1.0) {
        r0 = fx == 0.0 ? (double)p0[x0] : fx == 1.0 ? (double)p0[x1]
                                                    : (double)p0[x0] * (1.0 - fx) + (double)p0[x1] * fx;
        if (fy == 0.0) return r0;
    }
    r1 = fx == 0.0 ? (double)p1[x0] : fx == 1.0 ? (double)p1[x1]
                                                : (double)p1[x0] * (1.0 - fx) + (double)p1[x1] * fx;
    if (fy == 1.0) return r1;
    return r0 * (1.0 - fy) + r1 * fy;
}

/* C channels at grid position (x, y) into out; 0 if the sample is a hole. holes = 0 promises that
 * no texel is one (then the plain weighted sum, same value). */
static int hf_ns_sampleC(const hf_ns_level *L, int C, int wrap, int holes, double x, double y, double *out)
{
    int x0, x1, y0, y1, c, q;
    double fx, fy, wt[4];
    const float *tp[4];
    if (wrap) {
        hf_ns_axis(x * L->a + L->b, L->w, 1, &x0, &x1, &fx);
        hf_ns_axis(y * L->a + L->b, L->h, 1, &y0, &y1, &fy);
    } else {
        hf_ns_axis_clamped(x * L->a + L->b, L->w, &x0, &fx);
        hf_ns_axis_clamped(y * L->a + L->b, L->h, &y0, &fy);
        x1 = L->w > 1 ? x0 + 1 : x0;
        y1 = L->h > 1 ? y0 + 1 : y0;
    }
    wt[0] = (1.0 - fx) * (1.0 - fy);
    wt[1] = fx * (1.0 - fy);
    wt[2] = (1.0 - fx) * fy;
    wt[3] = fx * fy;
    tp[0] = L->img + ((size_t)y0 * (size_t)L->w + (size_t)x0) * (size_t)C;
    tp[1] = L->img + ((size_t)y0 * (size_t)L->w + (size_t)x1) * (size_t)C;
    tp[2] = L->img + ((size_t)y1 * (size_t)L->w + (size_t)x0) * (size_t)C;
    tp[3] = L->img + ((size_t)y1 * (size_t)L->w + (size_t)x1) * (size_t)C;
    if (!holes) { /* every texel finite */
        for (c = 0; c < C; c++)
            out[c] = wt[0] * (double)tp[0][c] + wt[1] * (double)tp[1][c] + wt[2] * (double)tp[2][c] +
                     wt[3] * (double)tp[3][c];
        return 1;
    }
    for (c = 0; c < C; c++) out[c] = 0.0;
    for (q = 0; q < 4; q++) {
        if (wt[q] == 0.0) continue;
        if (!isfinite(tp[q][0])) return 0;
        for (c = 0; c < C; c++) out[c] += wt[q] * (double)tp[q][c];
    }
    return 1;
}

/* ------------------------------------------------------- 3. options, validation, memory plan */

typedef struct hf_ns_cast {
    int i;              /* step index */
    double t;           /* tan(omega_i) */
    double x, y;        /* grid position of the step (after the border rule) */
    double dz;          /* height difference at level l_v(i), world units */
} hf_ns_cast;

typedef struct hf_ns_key {
    int full;                  /* 1: the cap holds the zenith: full circle, the environment slices */
    double sin_lmin, sin_lmax; /* elevation range [l_min, l_max] as sines */
    double *cph, *sph;         /* key_directions azimuths (partial extent) */
    double *G;                 /* 64*key_directions sample matrices (partial extent) */
    double *T;                 /* C*256: the product matrix of L_key */
    double Ls[NS_SH_N];        /* L_key per unit irradiance (RATIO) */
    double E0[4];              /* irradiance per channel (RATIO) */
    double box;                /* Ls . V_box: the unoccluded restricted visibility's (RATIO) */
} hf_ns_key;

typedef struct hf_ns_dir {
    double d[3], cph, sph, sin_e;
    double E0[4];
    double Yd[NS_SH_N];        /* Y(d), bands >= order zeroed */
} hf_ns_dir;

typedef struct hf_ns_recv {
    double x, y, n[3];
    double *hl;                /* receiver height at each level of the height pyramid */
} hf_ns_recv;

typedef struct hf_ns_ctx {
    const hfvis_grid *g;
    const hfvis_ns_scene *sc;
    hfvis_ns_gi_options o;     /* resolved */
    int W, H, C, m, mk, k, n, ov, ou, order, s, Rw, Rh, B;
    int border, wrap, open, holes;
    int Lv, Lu;                /* levels built: heights, radiance */
    int nkey, ndir;            /* separate key lights, directional lights */
    int env, env_scan;         /* an environment (T_env) exists; the m environment slices run */
    int gloss, gvec, need_normals, want_vis;
    int cwords, cfilled;       /* casting-set cache: words per slice, filled by a pass */
    int rec_d, rec_b, rec_max, Cmax;
    double cell, rho_s, S, Ad[4], Ap[4], view[3];
    /* tables (block 1) */
    double *gamma, *tau, *inv_dist, *ecos, *esin, *G_env, *T_env, *kern, *row;
    int *lv_i, *lu_i;
    hf_ns_key *keys;
    hf_ns_dir *dirs;
    hf_ns_level *hp, *dp, *ip;
    double *tv, *wc, *wa, *smax, *hl, *ub, *vb, *Iq, *rtmp, *vtmp;
    hf_ns_cast *cast;
    /* block 2: height pyramid and normals; block 3: two receiver rows; block 4: bounces */
    float *normals;
    double *win;
    float *exitbuf, *ibuf;
    uint64_t *cmask;           /* casting-set cache: Rw*Rh*m*cwords words, or NULL */
} hf_ns_ctx;

hfvis_ns_gi_options hfvis_ns_gi_options_default(void)
{
    hfvis_ns_gi_options o;
    memset(&o, 0, sizeof o);
    o.directions = 32;
    o.key_directions = 3;
    o.levels_per_octave = 4;
    o.levels = 0;
    o.level_offset_v = 2;
    o.level_offset_u = 2;
    o.sh_order = 4;
    o.subsample = 1;
    o.interp = HFVIS_NS_INTERP_LINEAR;
    o.omega_min = HFVIS_NS_OMEGA_MIN_EXACT;
    o.omega_max = HFVIS_NS_OMEGA_MAX_BSPLINE;
    o.clamp_to_tangent = 0;
    o.directional = HFVIS_NS_DIRECTIONAL_HARD;
    o.key_mode = HFVIS_NS_KEY_SEPARATE;
    o.glossy = HFVIS_NS_GLOSSY_VECTOR;
    o.cast_cache = HFVIS_NS_CACHE_ON;
    o.view_dir[0] = 0.0;
    o.view_dir[1] = 0.0;
    o.view_dir[2] = 1.0;
    o.border = HFVIS_BORDER_OPEN;
    return o;
}

static int hf_ns_range(int v, int lo, int hi) { return v >= lo && v <= hi; }

hfvis_status hfvis_ns_gi_options_resolve(const hfvis_grid *grid, const hfvis_ns_gi_options *in,
                                         hfvis_ns_gi_options *out)
{
    hfvis_ns_gi_options o, d = hfvis_ns_gi_options_default();
    double vn;
    if (!hf_grid_valid(grid) || out == NULL) return HFVIS_ERR_INVALID_ARGUMENT;
    if (in) o = *in;
    else memset(&o, 0, sizeof o);
    if (!hf_ns_range(o.directions, 0, HFVIS_NS_MAX_DIRECTIONS) ||
        !(o.key_directions == 0 || hf_ns_range(o.key_directions, 2, HFVIS_NS_MAX_KEY_DIRECTIONS)) ||
        !hf_ns_range(o.levels_per_octave, 0, HFVIS_NS_MAX_LEVELS_PER_OCTAVE) ||
        !hf_ns_range(o.levels, 0, HFVIS_NS_MAX_LEVELS) ||
        !hf_ns_range(o.level_offset_v, HFVIS_NS_NO_OFFSET, HFVIS_NS_MAX_LEVEL_OFFSET) ||
        !hf_ns_range(o.level_offset_u, HFVIS_NS_NO_OFFSET, HFVIS_NS_MAX_LEVEL_OFFSET) ||
        !hf_ns_range(o.sh_order, 0, 4) || !hf_ns_range(o.subsample, 0, HFVIS_NS_MAX_SUBSAMPLE) ||
        hfvis_ns_wedge_columns(o.interp) == 0 ||
        !hf_ns_range((int)o.omega_min, 0, 2) || !hf_ns_range((int)o.omega_max, 0, 2) ||
        !hf_ns_range(o.clamp_to_tangent, 0, 1) || !hf_ns_range((int)o.directional, 0, 3) ||
        !hf_ns_range((int)o.key_mode, 0, 3) || !hf_ns_range((int)o.glossy, 0, 2) ||
        !hf_ns_range((int)o.cast_cache, 0, 2) ||
        !isfinite(o.view_dir[0]) || !isfinite(o.view_dir[1]) || !isfinite(o.view_dir[2]) ||
        !hf_border_valid(o.border) || !isfinite(o.azimuth0_rad))
        return HFVIS_ERR_INVALID_ARGUMENT;
    vn = sqrt(o.view_dir[0] * o.view_dir[0] + o.view_dir[1] * o.view_dir[1] +
              o.view_dir[2] * o.view_dir[2]);
    if (vn == 0.0) {
        o.view_dir[0] = d.view_dir[0];
        o.view_dir[1] = d.view_dir[1];
        o.view_dir[2] = d.view_dir[2];
    } else if (!isfinite(vn)) {
        return HFVIS_ERR_INVALID_ARGUMENT;
    } else {
        o.view_dir[0] /= vn;
        o.view_dir[1] /= vn;
        o.view_dir[2] /= vn;
    }
    if (o.directions == 0) o.directions = d.directions;
    if (o.key_directions == 0) o.key_directions = d.key_directions;
    if (o.levels_per_octave == 0) o.levels_per_octave = d.levels_per_octave;
    if (o.level_offset_v == 0) o.level_offset_v = d.level_offset_v;
    if (o.level_offset_u == 0) o.level_offset_u = d.level_offset_u;
    if (o.sh_order == 0) o.sh_order = d.sh_order;
    if (o.subsample == 0) o.subsample = d.subsample;
    if (o.interp == HFVIS_NS_INTERP_DEFAULT) o.interp = d.interp;
    if (o.omega_min == HFVIS_NS_OMEGA_MIN_DEFAULT) o.omega_min = d.omega_min;
    if (o.omega_max == HFVIS_NS_OMEGA_MAX_DEFAULT) o.omega_max = d.omega_max;
    if (o.directional == HFVIS_NS_DIRECTIONAL_DEFAULT) o.directional = d.directional;
    if (o.key_mode == HFVIS_NS_KEY_DEFAULT) o.key_mode = d.key_mode;
    if (o.glossy == HFVIS_NS_GLOSSY_DEFAULT) o.glossy = d.glossy;
    if (o.cast_cache == HFVIS_NS_CACHE_DEFAULT) o.cast_cache = d.cast_cache;
    if (o.border == HFVIS_BORDER_DEFAULT) o.border = d.border;
    if (o.levels == 0) {
        /* the last step tau_(n-1) = 2^((n-1)/k) reaches the grid's diagonal (spec B.4: the natural
         * choice 1 + k log2 R, for any aspect) */
        double D = hypot((double)(grid->width - 1), (double)(grid->height - 1)), e;
        if (D < 1.0) D = 1.0;
        e = ceil((double)o.levels_per_octave * log2(D) - 1e-9);
        if (e < 0.0) e = 0.0;
        o.levels = 1 + (int)e;
        if (o.levels > HFVIS_NS_MAX_LEVELS) o.levels = HFVIS_NS_MAX_LEVELS;
    }
    *out = o;
    return HFVIS_OK;
}

static int hf_ns_offset(int v) { return v == HFVIS_NS_NO_OFFSET ? 0 : v; }

/* A non-hole sample of the grid with a non-finite map value makes the map invalid. */
static int hf_ns_map_valid(const hfvis_grid *g, const float *map, int C)
{
    int x, y, c;
    if (!map) return 1;
    for (y = 0; y < g->height; y++)
        for (x = 0; x < g->width; x++) {
            const float *p = map + ((size_t)y * (size_t)g->width + (size_t)x) * (size_t)C;
            if (!isfinite(g->z[(ptrdiff_t)y * g->stride + x])) continue;
            for (c = 0; c < C; c++)
                if (!isfinite(p[c])) return 0;
        }
    return 1;
}

/* Validate and resolve everything that decides sizes (no allocation, no tables). */
static hfvis_status hf_ns_setup(hf_ns_ctx *c, const hfvis_grid *grid, const hfvis_ns_scene *sc,
                                const hfvis_ns_gi_options *opts, int bounces, int want_vis)
{
    int i, ch;
    size_t t;
    memset(c, 0, sizeof *c);
    if (!hf_grid_valid(grid) || sc == NULL || bounces < 0) return HFVIS_ERR_INVALID_ARGUMENT;
    if (hfvis_ns_gi_options_resolve(grid, opts, &c->o) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    if (sc->channels < 1 || sc->channels > 4 || sc->light_count < 0 ||
        sc->light_count > HFVIS_NS_MAX_LIGHTS || (sc->light_count > 0 && sc->lights == NULL) ||
        !isfinite(sc->specular) || sc->specular < 0.0f ||
        (sc->specular > 0.0f && (!isfinite(sc->shininess) || !(sc->shininess > 0.0f))))
        return HFVIS_ERR_INVALID_ARGUMENT;
    c->C = sc->channels;
    for (ch = 0; ch < c->C; ch++)
        if (!isfinite(sc->albedo[ch])) return HFVIS_ERR_INVALID_ARGUMENT;
    if (sc->env_sh)
        for (i = 0; i < NS_SH_N * c->C; i++)
            if (!isfinite(sc->env_sh[i])) return HFVIS_ERR_INVALID_ARGUMENT;
    if (!hf_mul_size(hf_grid_count(grid), (size_t)c->C * 16u, &t) ||
        !hf_mul_size(t, (size_t)bounces + 1u, &t) || !hf_mul_size(t, sizeof(double), &t))
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (i = 0; i < sc->light_count; i++) {
        const hfvis_sun *L = &sc->lights[i];
        if (!isfinite(L->azimuth_rad) || !isfinite(L->elevation_rad) || !isfinite(L->radius_rad) ||
            fabs(L->elevation_rad) > HF_HALF_PI || L->radius_rad < 0.0 || L->radius_rad > HF_HALF_PI)
            return HFVIS_ERR_INVALID_ARGUMENT;
        for (ch = 0; ch < c->C; ch++)
            if (!isfinite(L->irradiance[ch])) return HFVIS_ERR_INVALID_ARGUMENT;
        if (L->radius_rad == 0.0) c->ndir++;
        else if (c->o.key_mode != HFVIS_NS_KEY_ENVIRONMENT) c->nkey++;
    }
    if (!hf_ns_map_valid(grid, sc->albedo_map, c->C) || !hf_ns_map_valid(grid, sc->emission, c->C))
        return HFVIS_ERR_INVALID_ARGUMENT;
    c->g = grid;
    c->sc = sc;
    c->W = grid->width;
    c->H = grid->height;
    c->m = c->o.directions;
    c->mk = c->o.key_directions;
    c->k = c->o.levels_per_octave;
    c->n = c->o.levels;
    c->ov = hf_ns_offset(c->o.level_offset_v);
    c->ou = hf_ns_offset(c->o.level_offset_u);
    c->order = c->o.sh_order;
    c->s = c->o.subsample;
    c->Rw = (c->W + c->s - 1) / c->s;
    c->Rh = (c->H + c->s - 1) / c->s;
    c->B = bounces;
    c->border = (int)c->o.border;
    c->wrap = c->o.border == HFVIS_BORDER_WRAP;
    c->open = c->o.border == HFVIS_BORDER_OPEN;
    c->cell = grid->cell_size;
    /* levels actually read: l_v(n-1) and l_u(n-1) */
    c->Lv = c->n - 1 - c->k * c->ov;
    c->Lv = (c->Lv < 0 ? 0 : c->Lv) + 1;
    c->Lu = c->n - 1 - c->k * c->ou;
    c->Lu = (c->Lu < 0 ? 0 : c->Lu) + 1;
    c->gloss = sc->specular > 0.0f;
    c->gvec = c->gloss && bounces > 0 && c->o.glossy == HFVIS_NS_GLOSSY_VECTOR;
    c->need_normals = c->s > 1 || c->gvec;
    c->want_vis = want_vis;
    c->env = sc->env_sh != NULL || (sc->light_count > c->ndir && c->o.key_mode == HFVIS_NS_KEY_ENVIRONMENT);
    c->env_scan = c->env || want_vis;
    for (i = 0; i < sc->light_count; i++) {
        const hfvis_sun *L = &sc->lights[i];
        if (L->radius_rad > 0.0 && c->o.key_mode != HFVIS_NS_KEY_ENVIRONMENT &&
            !(L->radius_rad < HF_HALF_PI - fabs(L->elevation_rad)))
            c->env_scan = 1; /* a cap holding the zenith uses the environment slices */
    }
    c->rec_d = NS_SH_N * (1 + c->nkey) + c->ndir;
    c->rec_b = NS_SH_N * c->C;
    c->rec_max = c->rec_d > c->rec_b ? c->rec_d : c->rec_b;
    c->Cmax = c->gvec ? NS_SH_N * c->C : c->C;
    c->cwords = bounces > 0 && c->o.cast_cache == HFVIS_NS_CACHE_ON ? (c->n + 63) / 64 : 0;
    c->rho_s = (double)sc->specular;
    c->S = (double)sc->shininess;
    return HFVIS_OK;
}

typedef struct hf_ns_arena {
    unsigned char *base;
    size_t used;
    int overflow;
} hf_ns_arena;

/* Carve count*elem bytes (16-byte aligned) from the arena; with base NULL only measures. */
static void *hf_ns_take(hf_ns_arena *a, size_t count, size_t elem)
{
    size_t bytes, start;
    if (!hf_mul_size(count, elem, &bytes) || a->used > SIZE_MAX - 15u) {
        a->overflow = 1;
        return NULL;
    }
    start = (a->used + 15u) & ~(size_t)15u;
    if (bytes > SIZE_MAX - start) {
        a->overflow = 1;
        return NULL;
    }
    a->used = start + bytes;
    return a->base ? (void *)(a->base + start) : NULL;
}

/* Carve the images of a pyramid of L levels over a bw x bh base scaled by bscale grid units. */
static void hf_ns_pyr_carve(hf_ns_arena *a, hf_ns_level *lv, int L, int k, int bw, int bh,
                            double bscale, int C)
{
    int l;
    for (l = 0; l < L; l++) {
        int w, h, o = l / k;
        float *img;
        double sc = bscale * ldexp(1.0, o);
        hf_ns_oct_dims(bw, bh, o, &w, &h);
        img = (float *)hf_ns_take(a, (size_t)w * (size_t)h, sizeof(float) * (size_t)C);
        if (lv) {
            lv[l].img = img;
            lv[l].w = w;
            lv[l].h = h;
            lv[l].a = 1.0 / sc;
            lv[l].b = sc == 1.0 ? 0.0 : 0.5 / sc - 0.5;
        }
    }
}

/* Lay out the four blocks: tables, heights, window, bounces (pointers only when bases are set). */
static void hf_ns_carve(hf_ns_ctx *c, hf_ns_arena *A)
{
    const size_t n = (size_t)c->n, m = (size_t)c->m, C = (size_t)c->C;
    size_t mw = (size_t)(c->W > c->Rw ? c->W : c->Rw);
    hf_ns_arena *t = &A[0];
    c->keys = (hf_ns_key *)hf_ns_take(t, (size_t)c->nkey, sizeof(hf_ns_key));
    c->dirs = (hf_ns_dir *)hf_ns_take(t, (size_t)c->ndir, sizeof(hf_ns_dir));
    c->hp = (hf_ns_level *)hf_ns_take(t, (size_t)c->Lv, sizeof(hf_ns_level));
    c->dp = (hf_ns_level *)hf_ns_take(t, c->B > 0 ? (size_t)c->Lu : 0u, sizeof(hf_ns_level));
    c->ip = (hf_ns_level *)hf_ns_take(t, c->gvec ? (size_t)c->Lu : 0u, sizeof(hf_ns_level));
    c->cast = (hf_ns_cast *)hf_ns_take(t, n, sizeof(hf_ns_cast));
    c->gamma = (double *)hf_ns_take(t, 4096u, sizeof(double));
    c->tau = (double *)hf_ns_take(t, n, sizeof(double));
    c->inv_dist = (double *)hf_ns_take(t, n, sizeof(double));
    c->ecos = (double *)hf_ns_take(t, m, sizeof(double));
    c->esin = (double *)hf_ns_take(t, m, sizeof(double));
    c->G_env = (double *)hf_ns_take(t, m, 64u * sizeof(double));
    c->T_env = (double *)hf_ns_take(t, C, 256u * sizeof(double));
    c->kern = (double *)hf_ns_take(t, (size_t)c->k, HF_NS_KTAPS * sizeof(double));
    c->row = (double *)hf_ns_take(t, mw, ((size_t)c->Cmax + 1u) * sizeof(double));
    c->tv = (double *)hf_ns_take(t, n, sizeof(double));
    c->wc = (double *)hf_ns_take(t, n, sizeof(double));
    c->wa = (double *)hf_ns_take(t, n, 3u * sizeof(double));
    c->smax = (double *)hf_ns_take(t, m, sizeof(double));
    c->hl = (double *)hf_ns_take(t, (size_t)c->Lv, sizeof(double));
    c->ub = (double *)hf_ns_take(t, n, C * sizeof(double));
    c->vb = (double *)hf_ns_take(t, n, 4u * sizeof(double));
    c->Iq = (double *)hf_ns_take(t, C, NS_SH_N * sizeof(double));
    c->rtmp = (double *)hf_ns_take(t, (size_t)c->rec_max, sizeof(double));
    c->vtmp = (double *)hf_ns_take(t, C, NS_SH_N * sizeof(double));
    c->lv_i = (int *)hf_ns_take(t, n, sizeof(int));
    c->lu_i = (int *)hf_ns_take(t, n, sizeof(int));
    {
        int q;
        for (q = 0; q < c->nkey; q++) {
            double *cp = (double *)hf_ns_take(t, (size_t)c->mk, sizeof(double));
            double *sp = (double *)hf_ns_take(t, (size_t)c->mk, sizeof(double));
            double *G = (double *)hf_ns_take(t, (size_t)c->mk, 64u * sizeof(double));
            double *T = (double *)hf_ns_take(t, C, 256u * sizeof(double));
            if (c->keys) {
                c->keys[q].cph = cp;
                c->keys[q].sph = sp;
                c->keys[q].G = G;
                c->keys[q].T = T;
            }
        }
    }
    /* block 2: the height pyramid (1 channel) and the normals */
    hf_ns_pyr_carve(&A[1], c->hp, c->Lv, c->k, c->W, c->H, 1.0, 1);
    c->normals = (float *)hf_ns_take(&A[1], c->need_normals ? hf_grid_count(c->g) : 0u, 3u * sizeof(float));
    /* block 3: two receiver rows */
    c->win = (double *)hf_ns_take(&A[2], 2u * (size_t)c->Rw, (size_t)c->rec_max * sizeof(double));
    /* block 4: the bounces' buffers and pyramids */
    if (c->B > 0) {
        size_t words = 0;
        if (c->cwords > 0 && (!hf_mul_size((size_t)c->Rw * (size_t)c->Rh, m, &words) ||
                              !hf_mul_size(words, (size_t)c->cwords, &words)))
            A[3].overflow = 1;
        c->cmask = c->cwords > 0 ? (uint64_t *)hf_ns_take(&A[3], words, sizeof(uint64_t)) : NULL;
        c->exitbuf = (float *)hf_ns_take(&A[3], hf_grid_count(c->g), C * sizeof(float));
        hf_ns_pyr_carve(&A[3], c->dp, c->Lu, c->k, c->W, c->H, 1.0, c->C);
        if (c->gvec) {
            c->ibuf = (float *)hf_ns_take(&A[3], (size_t)c->Rw * (size_t)c->Rh,
                                          C * NS_SH_N * sizeof(float));
            hf_ns_pyr_carve(&A[3], c->ip, c->Lu, c->k, c->Rw, c->Rh, (double)c->s, c->C * NS_SH_N);
        }
    }
}

/* Measure the four blocks. 0 if a size overflows. */
static int hf_ns_measure(hf_ns_ctx *c, size_t bytes[4])
{
    hf_ns_arena A[4];
    int q;
    memset(A, 0, sizeof A);
    hf_ns_carve(c, A);
    for (q = 0; q < 4; q++) {
        if (A[q].overflow) return 0;
        bytes[q] = A[q].used;
    }
    return 1;
}

hfvis_status hfvis_ns_gi_scratch_size(const hfvis_grid *grid, const hfvis_ns_scene *scene,
                                      const hfvis_ns_gi_options *opts, int bounces, size_t *bytes)
{
    hf_ns_ctx c;
    size_t b[4], total = 0;
    int q;
    hfvis_status s;
    if (bytes == NULL) return HFVIS_ERR_INVALID_ARGUMENT;
    if ((s = hf_ns_setup(&c, grid, scene, opts, bounces, 0)) != HFVIS_OK) return s;
    if (!hf_ns_measure(&c, b)) return HFVIS_ERR_INVALID_ARGUMENT;
    for (q = 0; q < 4; q++) {
        if (b[q] > SIZE_MAX - total) return HFVIS_ERR_INVALID_ARGUMENT;
        total += b[q];
    }
    *bytes = total;
    return HFVIS_OK;
}

/* ------------------------------------------------------------------- 4. the slice scan */

/* Apply the border rule to a grid position; 0 if it lies outside an OPEN grid. */
static int hf_ns_place(const hf_ns_ctx *c, double *x, double *y)
{
    const double W = (double)c->W, H = (double)c->H;
    if (c->wrap) {
        *x -= floor(*x / W) * W;
        *y -= floor(*y / H) * H;
        if (!(*x < W)) *x = 0.0;
        if (!(*y < H)) *y = 0.0;
        return 1;
    }
    if (*x < 0.0 || *x > W - 1.0 || *y < 0.0 || *y > H - 1.0) {
        if (c->open) return 0;
        *x = hf_clampd(*x, 0.0, W - 1.0);
        *y = hf_clampd(*y, 0.0, H - 1.0);
    }
    return 1;
}

/* [NS09] Eq. 14-15, 17 along the slice (cph, sph) from receiver r: the tangents of the valid
 * steps into tv (if not NULL; returns their count) and, if cast is not NULL, the casting set
 * seeded with tan(omega_min) = t_seed into cast (*ncast elements, strictly increasing omega), and
 * their step indices as bits into bits (zeroed by the caller) if it is not NULL. */
static int hf_ns_scan(const hf_ns_ctx *c, const hf_ns_recv *r, double cph, double sph, double t_seed,
                      double *tv, hf_ns_cast *cast, int *ncast, uint64_t *bits)
{
    const double W1 = (double)(c->W - 1), H1 = (double)(c->H - 1);
    double run = t_seed;
    int i, nv = 0, K = 0;
    for (i = 0; i < c->n; i++) {
        const int l = c->lv_i[i];
        double x = r->x + c->tau[i] * cph, y = r->y + c->tau[i] * sph, hp = r->hl[l], hq, t;
        if (x < 0.0 || x > W1 || y < 0.0 || y > H1) {
            if (!hf_ns_place(c, &x, &y)) break; /* OPEN: the ray has left the grid for good */
        }
        if (isnan(hp)) continue;
        hq = hf_ns_sample1(&c->hp[l], c->wrap, c->holes, x, y);
        if (isnan(hq)) continue; /* a hole never occludes and never casts */
        t = (hq - hp) * c->inv_dist[i];
        if (tv) tv[nv] = t;
        nv++;
        /* Eq. 17 (spec B.4): omega_i above the running maximum, which starts at omega_min */
        if (cast && t > run + HF_NS_CAST_TOL * (1.0 + run * run)) {
            cast[K].i = i;
            cast[K].t = t;
            cast[K].x = x;
            cast[K].y = y;
            cast[K].dz = hq - hp;
            K++;
            run = t;
            if (bits) bits[i >> 6] |= (uint64_t)1 << (i & 63);
        }
    }
    if (ncast) *ncast = K;
    return nv;
}

/* sin(omega_max) of a slice (Eq. 16 or the raw maximum); -1 if no step was valid. */
static double hf_ns_smax(hf_ns_ctx *c, int nv)
{
    int i;
    if (nv == 0) return -1.0;
    if (c->o.omega_max == HFVIS_NS_OMEGA_MAX_RAW) {
        double t = c->tv[0];
        for (i = 1; i < nv; i++)
            if (c->tv[i] > t) t = c->tv[i];
        return hf_ns_sine(t);
    }
    return sin(hf_ns_omax_bspline(c->tv, nv, c->wc, c->wa));
}

/* omega_min of the receiver normal N toward (cph, sph) as tangent and sine ([NS09] §3 with the
 * spec B.2 erratum; N_z > 0 for every normal the library makes). */
static void hf_ns_omega_min(const hf_ns_ctx *c, const double *N, double cph, double sph,
                            double *t_min, double *s_min)
{
    double d = N[0] * cph + N[1] * sph;
    if (c->o.omega_min == HFVIS_NS_OMEGA_MIN_PAPER) {
        if (d > 1.0) d = 1.0;
        if (d < -1.0) d = -1.0;
        *s_min = -d;                       /* sin(-asin d) */
        *t_min = fabs(d) < 1.0 ? -d / sqrt(1.0 - d * d) : (d > 0.0 ? -HF_INF : HF_INF);
    } else {
        *s_min = -d / sqrt(d * d + N[2] * N[2]); /* sin(atan2(-d, N_z)) */
        *t_min = -d / N[2];
    }
}

/* Set up receiver r at grid position (X, Y) with unit normal N: its height at every level of the
 * height pyramid. 0 if it is a hole (level 0 not finite) or N is not usable. */
static int hf_ns_recv_at(hf_ns_ctx *c, double X, double Y, const double *N, hf_ns_recv *r)
{
    int l;
    if (!isfinite(N[0]) || !isfinite(N[1]) || !(N[2] > 0.0)) return 0;
    r->x = X;
    r->y = Y;
    r->n[0] = N[0];
    r->n[1] = N[1];
    r->n[2] = N[2];
    r->hl = c->hl;
    for (l = 0; l < c->Lv; l++) r->hl[l] = hf_ns_sample1(&c->hp[l], c->wrap, c->holes, X, Y);
    return !isnan(r->hl[0]);
}

/* ------------------------------------- 5. receiver records: visibility and the direct lights */

/* Record of the direct pass at (X, Y): V_env (16), V_key (16 per separate key light), the shadow
 * factor of each directional light; rec[0] = NaN for a hole. */
static void hf_ns_direct_rec(hf_ns_ctx *c, double X, double Y, const double *N, double *rec, uint64_t *mask)
{
    hf_ns_recv r;
    double *V = rec, *Vk = rec + NS_SH_N, *dv = rec + NS_SH_N * (1 + c->nkey);
    int j, q, nv;
    for (q = 0; q < c->rec_d; q++) rec[q] = 0.0;
    if (!hf_ns_recv_at(c, X, Y, N, &r)) {
        rec[0] = HF_NAN;
        return;
    }
    if (c->env_scan)
        for (j = 0; j < c->m; j++) {
            double sm, v[4], tmin = 0.0, smin = -1.0;
            uint64_t *bits = mask ? mask + (size_t)j * (size_t)c->cwords : NULL;
            int K;
            if (bits || c->o.clamp_to_tangent) hf_ns_omega_min(c, N, c->ecos[j], c->esin[j], &tmin, &smin);
            for (q = 0; bits && q < c->cwords; q++) bits[q] = 0;
            /* the casting set for the bounces comes with the visibility scan (spec B.9 [choice]) */
            nv = hf_ns_scan(c, &r, c->ecos[j], c->esin[j], tmin, c->tv, bits ? c->cast : NULL, &K, bits);
            sm = hf_ns_smax(c, nv);
            c->smax[j] = sm;
            if (c->o.clamp_to_tangent && smin > sm) sm = smin;
            hf_ns_vis(sm, 1.0, v); /* Eq. 11: v = vbar(pi/2) - vbar(omega_max) */
            hf_ns_acc(V, c->G_env + (size_t)j * 64u, v);
        }
    for (q = 0; q < c->nkey; q++) {
        const hf_ns_key *K = &c->keys[q];
        double *VK = Vk + NS_SH_N * q;
        const int mm = K->full ? c->m : c->mk;
        for (j = 0; j < mm; j++) {
            double sm, v[4], tmin, smin, cp = K->full ? c->ecos[j] : K->cph[j];
            double sp = K->full ? c->esin[j] : K->sph[j];
            if (K->full) sm = c->smax[j];
            else {
                nv = hf_ns_scan(c, &r, cp, sp, 0.0, c->tv, NULL, NULL, NULL);
                sm = hf_ns_smax(c, nv);
            }
            /* [NS09] §6: the intersection of [omega_max, pi/2] and [l_min, l_max] */
            if (K->sin_lmin > sm) sm = K->sin_lmin;
            if (c->o.clamp_to_tangent) {
                hf_ns_omega_min(c, N, cp, sp, &tmin, &smin);
                if (smin > sm) sm = smin;
            }
            hf_ns_vis(sm, K->sin_lmax, v);
            hf_ns_acc(VK, (K->full ? c->G_env : K->G) + (size_t)j * 64u, v);
        }
    }
    for (q = 0; q < c->ndir; q++) {
        const hf_ns_dir *D = &c->dirs[q];
        double sm;
        nv = hf_ns_scan(c, &r, D->cph, D->sph, 0.0, c->tv, NULL, NULL, NULL);
        sm = hf_ns_smax(c, nv);
        if (c->o.directional == HFVIS_NS_DIRECTIONAL_SOFT) {
            /* spec B.8 soft: clamp(v(phi_L) . P^(sin omega_L), 0, 1) */
            double v[4], P[4], val;
            hf_ns_vis(sm, 1.0, v);
            (void)hfvis_nlp_eval(D->sin_e, P);
            val = v[0] * P[0] + v[1] * P[1] + v[2] * P[2] + v[3] * P[3];
            dv[q] = val < 0.0 ? 0.0 : val > 1.0 ? 1.0 : val;
        } else {
            dv[q] = D->sin_e > sm ? 1.0 : 0.0; /* [omega_L > omega_max(phi_L)] */
        }
    }
}

/* The SH incident radiance of a direct record, channel ch: L_env * V + Sum L_key * V_key, plus
 * the directional lights as SH deltas when sh_dirs (spec B.7-B.8). */
static void hf_ns_incident(const hf_ns_ctx *c, const double *rec, int ch, int sh_dirs, double *I)
{
    int q, i;
    for (i = 0; i < NS_SH_N; i++) I[i] = 0.0;
    if (c->env) hf_ns_matvec_add(c->T_env + (size_t)ch * 256u, rec, I);
    for (q = 0; q < c->nkey; q++) {
        const hf_ns_key *K = &c->keys[q];
        if (c->o.key_mode == HFVIS_NS_KEY_RATIO) {
            /* the visible share of the light's SH energy, Int L V_key / Int L V_box, times L */
            double f = K->box > 0.0 ? hf_ns_dot16(K->Ls, rec + NS_SH_N * (1 + q)) / K->box : 0.0;
            f = f < 0.0 ? 0.0 : f > 1.0 ? 1.0 : f;
            for (i = 0; i < NS_SH_N; i++) I[i] += f * K->E0[ch] * K->Ls[i];
        } else {
            hf_ns_matvec_add(K->T + (size_t)ch * 256u, rec + NS_SH_N * (1 + q), I);
        }
    }
    if (sh_dirs)
        for (q = 0; q < c->ndir; q++) {
            const double f = c->dirs[q].E0[ch] * rec[NS_SH_N * (1 + c->nkey) + q];
            for (i = 0; i < NS_SH_N; i++) I[i] += f * c->dirs[q].Yd[i];
        }
}

/* ------------------------------------------- 6. receiver records: the indirect radiance */

/* Normal at a fractional grid position: bilinear over the full-resolution normals (renormalised
 * over the finite ones), normalised. 0 if none is finite. */
static int hf_ns_normal_interp(const hf_ns_ctx *c, double x, double y, double *N)
{
    int x0, x1, y0, y1, q, i;
    double fx, fy, wt[4], len, tot = 0.0;
    const float *tp[4];
    hf_ns_axis(x, c->W, c->wrap, &x0, &x1, &fx);
    hf_ns_axis(y, c->H, c->wrap, &y0, &y1, &fy);
    wt[0] = (1.0 - fx) * (1.0 - fy);
    wt[1] = fx * (1.0 - fy);
    wt[2] = (1.0 - fx) * fy;
    wt[3] = fx * fy;
    tp[0] = c->normals + ((size_t)y0 * (size_t)c->W + (size_t)x0) * 3u;
    tp[1] = c->normals + ((size_t)y0 * (size_t)c->W + (size_t)x1) * 3u;
    tp[2] = c->normals + ((size_t)y1 * (size_t)c->W + (size_t)x0) * 3u;
    tp[3] = c->normals + ((size_t)y1 * (size_t)c->W + (size_t)x1) * 3u;
    N[0] = N[1] = N[2] = 0.0;
    for (q = 0; q < 4; q++) {
        if (wt[q] == 0.0 || !isfinite(tp[q][0])) continue;
        for (i = 0; i < 3; i++) N[i] += wt[q] * (double)tp[q][i];
        tot += wt[q];
    }
    len = sqrt(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]);
    if (!(tot > 0.0) || !(len > 0.0)) return 0;
    for (i = 0; i < 3; i++) N[i] /= len;
    return 1;
}

/* The casting set of a slice from its cached step indices: the same steps, heights and tangents as
 * hf_ns_scan found them, without scanning the others. */
static int hf_ns_cast_cached(hf_ns_ctx *c, const hf_ns_recv *r, double cph, double sph, const uint64_t *bits)
{
    int w, K = 0;
    for (w = 0; w < c->cwords; w++) {
        uint64_t b = bits[w];
        while (b) {
            int bit = 0, i, l;
            double x, y, hq;
            while (!((b >> bit) & 1u)) bit++;
            b &= b - 1u;
            i = w * 64 + bit;
            l = c->lv_i[i];
            x = r->x + c->tau[i] * cph;
            y = r->y + c->tau[i] * sph;
            if (x < 0.0 || x > (double)(c->W - 1) || y < 0.0 || y > (double)(c->H - 1))
                (void)hf_ns_place(c, &x, &y);
            hq = hf_ns_sample1(&c->hp[l], c->wrap, c->holes, x, y);
            c->cast[K].i = i;
            c->cast[K].t = (hq - r->hl[l]) * c->inv_dist[i];
            c->cast[K].x = x;
            c->cast[K].y = y;
            c->cast[K].dz = hq - r->hl[l];
            K++;
        }
    }
    return K;
}

/* Record of bounce pass at (X, Y): U (16 per channel) from the casting sets (Eq. 12) and the
 * exit radiance of the previous bounce; rec[0] = NaN for a hole. */
static void hf_ns_bounce_rec(hf_ns_ctx *c, double X, double Y, const double *N, double *rec, uint64_t *mask)
{
    hf_ns_recv r;
    const int C = c->C;
    int j, q, ch, K, i;
    for (q = 0; q < c->rec_b; q++) rec[q] = 0.0;
    if (!hf_ns_recv_at(c, X, Y, N, &r)) {
        rec[0] = HF_NAN;
        return;
    }
    for (j = 0; j < c->m; j++) {
        const double cph = c->ecos[j], sph = c->esin[j];
        double tmin, smin, vm[4];
        hf_ns_omega_min(c, N, cph, sph, &tmin, &smin);
        if (mask && c->cfilled) {
            K = hf_ns_cast_cached(c, &r, cph, sph, mask + (size_t)j * (size_t)c->cwords);
        } else {
            uint64_t *bits = mask ? mask + (size_t)j * (size_t)c->cwords : NULL;
            for (i = 0; bits && i < c->cwords; i++) bits[i] = 0;
            (void)hf_ns_scan(c, &r, cph, sph, tmin, NULL, c->cast, &K, bits);
        }
        if (K == 0) continue; /* spec B.3: an empty casting set gives u = 0 */
        for (q = 0; q < K; q++) {
            const hf_ns_cast *e = &c->cast[q];
            const int lu = c->lu_i[e->i];
            double *u = c->ub + (size_t)q * (size_t)C;
            /* [NS09] §5.3: u(tau) from the radiance pyramid at level l_u(i) (spec B.5) */
            if (!hf_ns_sampleC(&c->dp[lu], C, c->wrap, c->holes, e->x, e->y, u))
                for (ch = 0; ch < C; ch++) u[ch] = 0.0;
            if (c->gvec) {
                /* glossy: u += specular F_q(s) . I_(b-1)(q), s from q toward the receiver */
                double s3[3], Nq[3], len, ns, R[3], F[NS_SH_N];
                s3[0] = -c->tau[e->i] * c->cell * cph;
                s3[1] = -c->tau[e->i] * c->cell * sph;
                s3[2] = -e->dz;
                len = sqrt(s3[0] * s3[0] + s3[1] * s3[1] + s3[2] * s3[2]);
                if (len > 0.0 && hf_ns_normal_interp(c, e->x, e->y, Nq) &&
                    hf_ns_sampleC(&c->ip[lu], NS_SH_N * C, c->wrap, c->holes, e->x, e->y, c->Iq)) {
                    for (i = 0; i < 3; i++) s3[i] /= len;
                    ns = Nq[0] * s3[0] + Nq[1] * s3[1] + Nq[2] * s3[2];
                    if (ns > 0.0) { /* the receiver is above q's tangent plane */
                        for (i = 0; i < 3; i++) R[i] = 2.0 * ns * Nq[i] - s3[i];
                        hf_ns_lobe(c->Ap, R, F);
                        for (ch = 0; ch < C; ch++) {
                            double g = hf_ns_dot16(F, c->Iq + (size_t)ch * NS_SH_N);
                            if (g > 0.0) u[ch] += c->rho_s * g;
                        }
                    }
                }
            }
            hf_ns_vbar(hf_ns_sine(e->t), c->vb + (size_t)q * 4u);
        }
        hf_ns_vbar(smin, vm);
        /* Eq. 12 (spec B.3 errata): Sum_k (u_k - u_(k+1)) vbar(omega_k) - u_0 vbar(omega_min) */
        for (ch = 0; ch < C; ch++) {
            double w[4] = {0.0, 0.0, 0.0, 0.0};
            const double u0 = c->ub[ch];
            for (q = 0; q < K; q++) {
                const double du = c->ub[(size_t)q * (size_t)C + (size_t)ch] -
                                  (q + 1 < K ? c->ub[(size_t)(q + 1) * (size_t)C + (size_t)ch] : 0.0);
                const double *vb = c->vb + (size_t)q * 4u;
                w[0] += du * vb[0];
                w[1] += du * vb[1];
                w[2] += du * vb[2];
                w[3] += du * vb[3];
            }
            for (i = 0; i < 4; i++) w[i] -= u0 * vm[i];
            hf_ns_acc(rec + (size_t)ch * NS_SH_N, c->G_env + (size_t)j * 64u, w);
        }
    }
}

/* -------------------------------------------------- 7. shading and the upsampling window */

/* Normalised Phong lobe (S+1)/(2 pi) max(cos, 0)^S: the exact response to a directional light. */
static double hf_ns_phong(double S, double cosv)
{
    return cosv > 0.0 ? (S + 1.0) / NS_TWO_PI * pow(cosv, S) : 0.0;
}

/* Receiver (i, j): position (block centre, clamped to the grid) and normal. 0 if no normal. */
static int hf_ns_recv_pos(const hf_ns_ctx *c, int i, int j, double *X, double *Y, double *N)
{
    if (c->s == 1) {
        *X = (double)i;
        *Y = (double)j;
        hf_normal_at(c->g, i, j, N);
        return isfinite(N[0]);
    }
    *X = hf_clampd((double)(c->s * i) + 0.5 * (double)(c->s - 1), 0.0, (double)(c->W - 1));
    *Y = hf_clampd((double)(c->s * j) + 0.5 * (double)(c->s - 1), 0.0, (double)(c->H - 1));
    return hf_ns_normal_interp(c, *X, *Y, N);
}

/* Coarse rows (r0, r1) and weight f of full-resolution row or column y over R receivers. */
static void hf_ns_coarse(const hf_ns_ctx *c, int y, int R, int *r0, int *r1, double *f)
{
    double v = ((double)y - 0.5 * (double)(c->s - 1)) / (double)c->s, fl = floor(v);
    if (fl < 0.0) {
        *r0 = 0;
        *f = 0.0;
    } else if (fl >= (double)(R - 1)) {
        *r0 = R - 1;
        *f = 0.0;
    } else {
        *r0 = (int)fl;
        *f = v - fl;
    }
    *r1 = *r0 + 1 < R ? *r0 + 1 : R - 1;
}

/* The record of texel (x, y) from the two window rows: bilinear over the valid receivers
 * (renormalised), or NULL if none has weight (the caller then computes the texel itself). */
static const double *hf_ns_upsample(hf_ns_ctx *c, int x, int y, int rec, double *out)
{
    int i0, i1, j0, j1, q, r, wq;
    double fx, fy, wt[4], tot = 0.0;
    const double *rp[4];
    if (c->s == 1) {
        const double *p = c->win + ((size_t)(y & 1) * (size_t)c->Rw + (size_t)x) * (size_t)rec;
        return isnan(p[0]) ? NULL : p;
    }
    hf_ns_coarse(c, x, c->Rw, &i0, &i1, &fx);
    hf_ns_coarse(c, y, c->Rh, &j0, &j1, &fy);
    wt[0] = (1.0 - fx) * (1.0 - fy);
    wt[1] = fx * (1.0 - fy);
    wt[2] = (1.0 - fx) * fy;
    wt[3] = fx * fy;
    rp[0] = c->win + ((size_t)(j0 & 1) * (size_t)c->Rw + (size_t)i0) * (size_t)rec;
    rp[1] = c->win + ((size_t)(j0 & 1) * (size_t)c->Rw + (size_t)i1) * (size_t)rec;
    rp[2] = c->win + ((size_t)(j1 & 1) * (size_t)c->Rw + (size_t)i0) * (size_t)rec;
    rp[3] = c->win + ((size_t)(j1 & 1) * (size_t)c->Rw + (size_t)i1) * (size_t)rec;
    for (r = 0; r < rec; r++) out[r] = 0.0;
    wq = 0;
    for (q = 0; q < 4; q++) {
        if (wt[q] == 0.0 || isnan(rp[q][0])) continue;
        for (r = 0; r < rec; r++) out[r] += wt[q] * rp[q][r];
        tot += wt[q];
        wq++;
    }
    if (wq == 0) return NULL;
    if (tot != 1.0)
        for (r = 0; r < rec; r++) out[r] /= tot;
    return out;
}

/* Shade row y of pass b (0 = direct): outputs, and the exit radiance the next bounce gathers. */
static void hf_ns_shade_row(hf_ns_ctx *c, int b, int y, const hfvis_ns_gi_outputs *out)
{
    const int C = c->C, rec = b == 0 ? c->rec_d : c->rec_b;
    const hfvis_ns_scene *sc = c->sc;
    const size_t plane = hf_grid_count(c->g) * (size_t)C;
    float *bo = (b > 0 && out->bounce) ? out->bounce + (size_t)(b - 1) * plane : NULL;
    int x, ch, q;
    for (x = 0; x < c->W; x++) {
        const size_t px = (size_t)y * (size_t)c->W + (size_t)x, o0 = px * (size_t)C;
        const double *r;
        double N[3], FN[NS_SH_N], FR[NS_SH_N], R[3], nv = 0.0;
        if (!isfinite(c->g->z[(ptrdiff_t)y * c->g->stride + x])) {
            for (ch = 0; ch < C; ch++) {
                if (b == 0 && out->direct) out->direct[o0 + (size_t)ch] = (float)HF_NAN;
                if (bo) bo[o0 + (size_t)ch] = (float)HF_NAN;
                if (out->total) out->total[o0 + (size_t)ch] = (float)HF_NAN;
                if (c->exitbuf && b < c->B) c->exitbuf[o0 + (size_t)ch] = (float)HF_NAN;
            }
            continue;
        }
        hf_normal_at(c->g, x, y, N);
        r = hf_ns_upsample(c, x, y, rec, c->rtmp);
        if (r == NULL) { /* no receiver around: this texel is a receiver of its own */
            if (b == 0) hf_ns_direct_rec(c, (double)x, (double)y, N, c->rtmp, NULL);
            else hf_ns_bounce_rec(c, (double)x, (double)y, N, c->rtmp, NULL);
            r = c->rtmp;
        }
        /* [NS09] §7: F(w_o) = the lobe rotated to N (diffuse) or to R = reflect(view, N) (Phong) */
        hf_ns_lobe(c->Ad, N, FN);
        if (c->gloss) {
            nv = N[0] * c->view[0] + N[1] * c->view[1] + N[2] * c->view[2];
            for (q = 0; q < 3; q++) R[q] = 2.0 * nv * N[q] - c->view[q];
            hf_ns_lobe(c->Ap, R, FR);
        }
        for (ch = 0; ch < C; ch++) {
            const size_t oi = o0 + (size_t)ch;
            const double rho = sc->albedo_map ? (double)sc->albedo_map[oi] : (double)sc->albedo[ch];
            double E, Gl = 0.0, val, ex;
            if (isnan(r[0])) {
                val = ex = HF_NAN;
            } else if (b == 0) {
                const double emis = sc->emission ? (double)sc->emission[oi] : 0.0;
                const int sh_dirs = c->o.directional == HFVIS_NS_DIRECTIONAL_SH;
                double *I = c->vtmp;
                hf_ns_incident(c, r, ch, sh_dirs, I);
                E = hf_ns_dot16(FN, I);
                if (c->gloss) Gl = hf_ns_dot16(FR, I);
                if (!sh_dirs)
                    for (q = 0; q < c->ndir; q++) {
                        const hf_ns_dir *D = &c->dirs[q];
                        const double vis = r[NS_SH_N * (1 + c->nkey) + q];
                        const double cl = N[0] * D->d[0] + N[1] * D->d[1] + N[2] * D->d[2];
                        if (vis == 0.0) continue;
                        if (cl > 0.0) E += D->E0[ch] * cl * vis;
                        if (c->gloss)
                            Gl += D->E0[ch] * vis *
                                  hf_ns_phong(c->S, R[0] * D->d[0] + R[1] * D->d[1] + R[2] * D->d[2]);
                    }
                ex = emis + rho / HF_PI * E;
                val = ex + c->rho_s * Gl;
            } else {
                const double *U = r + (size_t)ch * NS_SH_N;
                E = hf_ns_dot16(FN, U);
                if (c->gloss) Gl = hf_ns_dot16(FR, U);
                ex = rho / HF_PI * E;
                val = ex + c->rho_s * Gl;
            }
            if (c->o.glossy == HFVIS_NS_GLOSSY_SCALAR) ex = val;
            if (b == 0) {
                if (out->direct) out->direct[oi] = (float)val;
                if (out->total) out->total[oi] = (float)val;
            } else {
                if (bo) bo[oi] = (float)val;
                if (out->total) out->total[oi] = (float)((double)out->total[oi] + val);
            }
            if (c->exitbuf && b < c->B) c->exitbuf[oi] = (float)ex;
        }
    }
}

/* One pass over the receivers (b = 0: visibility and direct light; b >= 1: bounce b), two
 * receiver rows at a time; each full-resolution row is shaded as soon as the receiver rows around
 * it exist. */
static void hf_ns_pass(hf_ns_ctx *c, int b, const hfvis_ns_gi_outputs *out, int *done, int total)
{
    const int rec = b == 0 ? c->rec_d : c->rec_b;
    int i, j, y = 0, ch, q;
    for (j = 0; j < c->Rh; j++) {
        double *row = c->win + (size_t)(j & 1) * (size_t)c->Rw * (size_t)rec;
        for (i = 0; i < c->Rw; i++) {
            double X, Y, N[3], *r = row + (size_t)i * (size_t)rec;
            const size_t ri = (size_t)j * (size_t)c->Rw + (size_t)i;
            if (hf_ns_recv_pos(c, i, j, &X, &Y, N)) {
                uint64_t *mask = c->cmask ? c->cmask + ri * (size_t)c->m * (size_t)c->cwords : NULL;
                if (b == 0) hf_ns_direct_rec(c, X, Y, N, r, c->env_scan ? mask : NULL);
                else hf_ns_bounce_rec(c, X, Y, N, r, mask);
            } else {
                for (q = 0; q < rec; q++) r[q] = 0.0;
                r[0] = HF_NAN;
            }
            if (b == 0 && c->want_vis && out->visibility)
                for (q = 0; q < NS_SH_N; q++)
                    out->visibility[ri * NS_SH_N + (size_t)q] = isnan(r[0]) ? (float)HF_NAN : (float)r[q];
            if (c->gvec && b < c->B) {
                /* the glossy pyramid's input: I_0 = L * V (+ the directional lights as SH deltas), or
                 * I_b = U_b ([NS09] §5.3) */
                float *Ib = c->ibuf + ri * (size_t)c->C * NS_SH_N;
                for (ch = 0; ch < c->C; ch++) {
                    double *I = c->vtmp;
                    if (b == 0) hf_ns_incident(c, r, ch, 1, I);
                    else
                        for (q = 0; q < NS_SH_N; q++) I[q] = r[(size_t)ch * NS_SH_N + (size_t)q];
                    for (q = 0; q < NS_SH_N; q++)
                        Ib[(size_t)ch * NS_SH_N + (size_t)q] = isnan(r[0]) ? (float)HF_NAN : (float)I[q];
                }
            }
        }
        for (; y < c->H; y++) {
            int r0, r1;
            double f;
            hf_ns_coarse(c, y, c->Rh, &r0, &r1, &f);
            if (r1 > j) break;
            hf_ns_shade_row(c, b, y, out);
        }
        ++*done;
        if (c->o.progress) c->o.progress(c->o.progress_user, *done, total);
    }
}

/* ------------------------------------------------------------------------ 8. the driver */

/* Fill the tables: steps, directions, wedge sample matrices, light products, lobes, kernels. */
static void hf_ns_tables(hf_ns_ctx *c)
{
    const hfvis_ns_scene *sc = c->sc;
    const int C = c->C, nb = c->order * c->order;
    hfvis_ns_wedges ws;
    double Lenv[4 * NS_SH_N];
    int i, j, q, ch, kk, dq = 0;
    memset(&ws, 0, sizeof ws);
    (void)hfvis_sh_product_tensor(c->gamma);
    for (i = 0; i < c->n; i++) {
        /* Eq. 14 in cell units (spec B.4): tau_i = 2^(i/k); l_v(i) = max(0, i - k o_v) */
        c->tau[i] = pow(2.0, (double)i / (double)c->k);
        c->inv_dist[i] = 1.0 / (c->tau[i] * c->cell);
        c->lv_i[i] = i - c->k * c->ov < 0 ? 0 : i - c->k * c->ov;
        c->lu_i[i] = i - c->k * c->ou < 0 ? 0 : i - c->k * c->ou;
    }
    for (j = 0; j < c->m; j++) {
        double phi = c->o.azimuth0_rad + NS_TWO_PI * (double)j / (double)c->m;
        c->ecos[j] = fabs(cos(phi)) < HF_NS_SNAP ? 0.0 : cos(phi);
        c->esin[j] = fabs(sin(phi)) < HF_NS_SNAP ? 0.0 : sin(phi);
    }
    /* full circle: m wedges with the wrap-around one (spec B.6 erratum on Eq. 21) */
    (void)hfvis_ns_wedges_full(&ws, c->o.interp, c->m, c->o.azimuth0_rad);
    (void)hfvis_ns_sample_matrices(&ws, c->G_env);
    for (j = 0; j < c->m; j++)
        for (i = nb * 4; i < 64; i++) c->G_env[(size_t)j * 64u + (size_t)i] = 0.0;
    /* lights */
    for (i = 0; i < 4 * NS_SH_N; i++) Lenv[i] = 0.0;
    if (sc->env_sh)
        for (ch = 0; ch < C; ch++)
            for (i = 0; i < nb; i++) Lenv[ch * NS_SH_N + i] = sc->env_sh[ch * NS_SH_N + i];
    kk = 0;
    for (q = 0; q < sc->light_count; q++) {
        const hfvis_sun *L = &sc->lights[q];
        const double e = L->elevation_rad, ce = cos(e), se = sin(e), psi = L->azimuth_rad;
        double a[3], cph = cos(psi), sph = sin(psi);
        cph = fabs(cph) < HF_NS_SNAP ? 0.0 : cph;
        sph = fabs(sph) < HF_NS_SNAP ? 0.0 : sph;
        a[0] = ce * cph;
        a[1] = ce * sph;
        a[2] = se;
        if (L->radius_rad == 0.0) {
            hf_ns_dir *D = &c->dirs[dq++];
            D->d[0] = a[0];
            D->d[1] = a[1];
            D->d[2] = a[2];
            D->cph = cph;
            D->sph = sph;
            D->sin_e = se;
            for (ch = 0; ch < 4; ch++) D->E0[ch] = ch < C ? (double)L->irradiance[ch] : 0.0;
            ns_sh_eval_unit(a[0], a[1], a[2], D->Yd);
            for (i = nb; i < NS_SH_N; i++) D->Yd[i] = 0.0;
        } else {
            /* spec B.8: a uniform cap of angular radius alpha about a, L0 = E0 / (pi sin^2 alpha)
             * (its irradiance on a facing surface is L0 pi sin^2 alpha), L_lm = L0 Ahat_l Y_lm(a) */
            double Ah[4], F[NS_SH_N], sa = sin(L->radius_rad);
            double *dst;
            (void)hfvis_zh_cap(L->radius_rad, Ah);
            (void)hfvis_sh_from_zh(Ah, a, F);
            if (c->o.key_mode != HFVIS_NS_KEY_ENVIRONMENT) {
                hf_ns_key *K = &c->keys[kk++];
                double vb[4], Vbox[NS_SH_N];
                double lmin = e - L->radius_rad, lmax = e + L->radius_rad, Lk[4 * NS_SH_N];
                if (lmin < -HF_HALF_PI) lmin = -HF_HALF_PI;
                if (lmax > HF_HALF_PI) lmax = HF_HALF_PI;
                K->sin_lmin = sin(lmin);
                K->sin_lmax = sin(lmax);
                K->full = !(L->radius_rad < HF_HALF_PI - fabs(e));
                if (!K->full) {
                    /* azimuth extent phi_c +- asin(sin alpha / cos e), key_directions samples */
                    double half = asin(sa / ce), pa = psi - half, pb = psi + half;
                    (void)hfvis_ns_wedges_partial(&ws, c->o.interp, c->mk, pa, pb);
                    (void)hfvis_ns_sample_matrices(&ws, K->G);
                    for (j = 0; j < c->mk; j++) {
                        double ph = pa + (double)j * ws.dphi_rad;
                        K->cph[j] = fabs(cos(ph)) < HF_NS_SNAP ? 0.0 : cos(ph);
                        K->sph[j] = fabs(sin(ph)) < HF_NS_SNAP ? 0.0 : sin(ph);
                        for (i = nb * 4; i < 64; i++) K->G[(size_t)j * 64u + (size_t)i] = 0.0;
                    }
                }
                /* RATIO: L per unit irradiance and its overlap with the unoccluded box */
                for (i = 0; i < NS_SH_N; i++) {
                    K->Ls[i] = i < nb ? F[i] / (HF_PI * sa * sa) : 0.0;
                    Vbox[i] = 0.0;
                }
                for (ch = 0; ch < 4; ch++) K->E0[ch] = ch < C ? (double)L->irradiance[ch] : 0.0;
                hf_ns_vis(K->sin_lmin, K->sin_lmax, vb);
                for (j = 0; j < (K->full ? c->m : c->mk); j++)
                    hf_ns_acc(Vbox, (K->full ? c->G_env : K->G) + (size_t)j * 64u, vb);
                K->box = hf_ns_dot16(K->Ls, Vbox);
                dst = Lk;
                for (ch = 0; ch < C; ch++)
                    for (i = 0; i < NS_SH_N; i++)
                        dst[ch * NS_SH_N + i] = i < nb ? (double)L->irradiance[ch] / (HF_PI * sa * sa) * F[i] : 0.0;
                /* T[ch][r][j] = Sum_i Gamma_ijr L_i: the SH product L * V as a matrix on V */
                for (ch = 0; ch < C; ch++)
                    for (i = 0; i < NS_SH_N; i++)
                        for (j = 0; j < NS_SH_N; j++) {
                            double s = 0.0;
                            int r2;
                            for (r2 = 0; r2 < NS_SH_N; r2++)
                                s += c->gamma[(r2 * NS_SH_N + j) * NS_SH_N + i] * Lk[ch * NS_SH_N + r2];
                            K->T[(size_t)ch * 256u + (size_t)(i * NS_SH_N + j)] = i < nb ? s : 0.0;
                        }
            } else {
                for (ch = 0; ch < C; ch++)
                    for (i = 0; i < nb; i++)
                        Lenv[ch * NS_SH_N + i] += (double)L->irradiance[ch] / (HF_PI * sa * sa) * F[i];
            }
        }
    }
    for (ch = 0; ch < C; ch++)
        for (i = 0; i < NS_SH_N; i++)
            for (j = 0; j < NS_SH_N; j++) {
                double s = 0.0;
                int r2;
                for (r2 = 0; r2 < NS_SH_N; r2++)
                    s += c->gamma[(r2 * NS_SH_N + j) * NS_SH_N + i] * Lenv[ch * NS_SH_N + r2];
                c->T_env[(size_t)ch * 256u + (size_t)(i * NS_SH_N + j)] = i < nb ? s : 0.0;
            }
    /* lobes (Ahat multipliers), bands >= order dropped */
    (void)hfvis_zh_diffuse(c->Ad);
    if (c->gloss) (void)hfvis_zh_phong(c->S, c->Ap);
    for (i = c->order; i < 4; i++) c->Ad[i] = c->Ap[i] = 0.0;
    c->view[0] = c->o.view_dir[0];
    c->view[1] = c->o.view_dir[1];
    c->view[2] = c->o.view_dir[2];
    for (j = 0; j < c->k; j++) hf_ns_blur_kernel(c->k, j, c->kern + (size_t)j * HF_NS_KTAPS);
}

hfvis_status hfvis_ns_gi(const hfvis_grid *grid, const hfvis_ns_scene *scene,
                         const hfvis_ns_gi_options *opts, const hfvis_ns_gi_outputs *out)
{
    hf_ns_ctx c;
    hf_ns_arena A[4];
    size_t bytes[4], plane, t;
    const hfvis_allocator *alloc;
    void *blk[4] = {NULL, NULL, NULL, NULL};
    int q, b, x, y, done = 0, total;
    hfvis_status s;
    if (out == NULL) return HFVIS_ERR_INVALID_ARGUMENT;
    if ((s = hf_ns_setup(&c, grid, scene, opts, out->bounces, out->visibility != NULL)) != HFVIS_OK)
        return s;
    plane = hf_grid_count(grid) * (size_t)c.C; /* checked by hf_ns_setup */
    if (!hf_mul_size(plane, (size_t)c.B, &t) ||
        !hf_mul_size((size_t)c.Rw * (size_t)c.Rh, NS_SH_N, &t) || !hf_ns_measure(&c, bytes))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (!out->direct && !out->bounce && !out->total && !out->visibility) return HFVIS_OK;
    alloc = c.o.alloc;
    for (q = 0; q < 4; q++) {
        if (bytes[q] == 0) continue;
        blk[q] = hf_alloc(alloc, bytes[q]);
        if (blk[q] == NULL) {
            while (q-- > 0) hf_free(alloc, blk[q]);
            return HFVIS_ERR_OUT_OF_MEMORY;
        }
    }
    memset(A, 0, sizeof A);
    for (q = 0; q < 4; q++) A[q].base = (unsigned char *)blk[q];
    hf_ns_carve(&c, A);
    hf_ns_tables(&c);
    /* the height pyramid (level 0 = the heights, holes as NaN) and the normals */
    for (y = 0; y < c.H; y++)
        for (x = 0; x < c.W; x++) {
            float z = grid->z[(ptrdiff_t)y * grid->stride + x];
            c.hp[0].img[(size_t)y * (size_t)c.W + (size_t)x] = isfinite(z) ? z : (float)HF_NAN;
            if (!isfinite(z)) c.holes = 1;
        }
    hf_ns_pyr_build(c.hp, c.Lv, c.k, 1, c.border, c.kern, c.row);
    if (c.need_normals) (void)hfvis_normals_compute(grid, c.normals);
    total = c.Rh * (1 + c.B);
    hf_ns_pass(&c, 0, out, &done, total);
    c.cfilled = c.env_scan; /* the direct pass scanned the casting sets with the visibility */
    for (b = 1; b <= c.B; b++) {
        /* [NS09] §5.3: the radiance pyramid of bounce b-1 (and the glossy SH pyramid) */
        memcpy(c.dp[0].img, c.exitbuf, plane * sizeof(float));
        hf_ns_pyr_build(c.dp, c.Lu, c.k, c.C, c.border, c.kern, c.row);
        if (c.gvec) {
            memcpy(c.ip[0].img, c.ibuf, (size_t)c.Rw * (size_t)c.Rh * (size_t)c.C * NS_SH_N * sizeof(float));
            hf_ns_pyr_build(c.ip, c.Lu, c.k, c.C * NS_SH_N, c.border, c.kern, c.row);
        }
        hf_ns_pass(&c, b, out, &done, total);
        c.cfilled = 1;
    }
    for (q = 3; q >= 0; q--) hf_free(alloc, blk[q]);
    return HFVIS_OK;
}
