/* ========================================================================================== */
/* 4D visibility fields ([G12] ch. 4: Alg. 1 build, Alg. 2/3 queries, Figs. 29/31; spec voxel */
/* §1; A. Gaitatzes et al., "Presampled visibility for ambient occlusion", WSCG 2008, and     */
/* "Fast approximate visibility on the GPU using pre-computed 4D visibility fields", WSCG 2010) */
/* ========================================================================================== */
/* Contents
 *   vf-a. positional samples on the bounding sphere (octahedral subdivision, spec §1.3) and
 *         the constant-time nearest-sample lookup
 *   vf-b. tangent frame (Duff et al. 2017) and the three hemisphere direction maps (§1.4)
 *   vf-c. sizes, validation, texel encoding (§1.2, §1.5-1.6)
 *   vf-d. build (Alg. 1) with the BVH, and its naive-caster oracle
 *   vf-e. queries from outside (Fig. 29) and inside (Fig. 31), and the ray-cast oracle (§1.7)
 *   vf-f. scenes of rigid instances: ambient occlusion (Alg. 2/3), soft shadows, tracing and
 *         reflections (§1.7(c)-(d)), each with its ray-cast oracle
 *   vf-g. the field file: encoder, strict decoder, file wrappers */

#define VX_VF_RIGID_TOL 1e-6          /* |Q^T Q - I| tolerance of an object transform */
#define VX_VF_INSIDE_TOL 1e-6         /* vertices may exceed the radius by this fraction */
#define VX_VF_DEFAULT_RAYS_SQRT 16    /* AO: 16 x 16 = 256 rays (the thesis' CPU count) */
#define VX_VF_DEFAULT_SHADOW_SAMPLES 20 /* thesis: 20 shadow rays per pixel */
#define VX_VF_DEFAULT_REFLECT_RAYS 4  /* thesis: 4 rays per reflective pixel */
#define VX_VF_F32_MAX_HIT 0.99999994f /* 1 - 2^-24: the largest float below 1 */

/* ---- vf-a. positional samples ------------------------------------------------------------ */

/* Samples per hemisphere, H = 2n^2 + 2n + 1 = n^2 + (n+1)^2. */
static size_t vx_vf_hemi(int n)
{
    return 2u * (size_t)n * (size_t)n + 2u * (size_t)n + 1u;
}

static int vx_vf_n_valid(int n) { return n >= 1 && n <= HFVIS_VISFIELD_MAX_N; }
static int vx_vf_d_valid(int d) { return d >= 1 && d <= HFVIS_VISFIELD_MAX_DIR_RES; }

/* Largest s with s*s <= r (r < 2^42 here, so the double estimate is off by at most one). */
static size_t vx_vf_isqrt(size_t r)
{
    size_t s = (size_t)sqrt((double)r);
    while (s > 0 && s * s > r) s--;
    while ((s + 1) * (s + 1) <= r) s++;
    return s;
}

/* Unit direction of lattice point (a, b) of hemisphere h: (a, b, +-c)/sqrt(a^2 + b^2 + c^2),
 * c = n - |a| - |b| (the octahedron point (a/n, b/n, c/n) projected radially; the squared
 * length is an exact integer in double). */
static void vx_vf_oct_dir(int n, int a, int b, int h, double out[3])
{
    int c = n - abs(a) - abs(b);
    double len2 = (double)((long long)a * a + (long long)b * b + (long long)c * c);
    double inv = 1.0 / sqrt(len2);
    out[0] = (double)a * inv;
    out[1] = (double)b * inv;
    out[2] = (h ? -(double)c : (double)c) * inv;
}

/* (h, a, b) of sample k < K. Rows m = b + n: row m <= n holds 2m + 1 points and starts at m^2;
 * the rows above n are counted from the end (the last (2n - m + 1)^2 points are rows m..2n). */
static void vx_vf_decode_index(int n, size_t k, int *h, int *a, int *b)
{
    size_t H = vx_vf_hemi(n), r = k % H;
    *h = (int)(k / H);
    if (r < (size_t)(n + 1) * (size_t)(n + 1)) {
        size_t m = vx_vf_isqrt(r);
        *b = (int)m - n;
        *a = (int)(r - m * m) - (int)m;       /* w = n - |b| = m points each side */
    } else {
        size_t rr = H - 1 - r, mp = vx_vf_isqrt(rr); /* mp = 2n - m = the row's half width */
        *b = n - (int)mp;
        *a = (int)mp - (int)(rr - mp * mp);
    }
}

/* Index of (h, a, b), |a| + |b| <= n. */
static size_t vx_vf_encode_index(int n, int h, int a, int b)
{
    size_t H = vx_vf_hemi(n), m = (size_t)(b + n), off;
    int w = n - abs(b);
    if (m <= (size_t)n) off = m * m;
    else off = H - (2u * (size_t)n - m + 1u) * (2u * (size_t)n - m + 1u);
    return (size_t)h * H + off + (size_t)(a + w);
}

HFVIS_API size_t hfvis_visfield_position_count(int positions_n)
{
    if (!vx_vf_n_valid(positions_n)) return 0;
    return 2u * vx_vf_hemi(positions_n);
}

HFVIS_API hfvis_status hfvis_visfield_position(int positions_n, size_t k, double dir[3])
{
    int h, a, b;
    if (!vx_vf_n_valid(positions_n) || !dir || k >= 2u * vx_vf_hemi(positions_n))
        return HFVIS_ERR_INVALID_ARGUMENT;
    vx_vf_decode_index(positions_n, k, &h, &a, &b);
    vx_vf_oct_dir(positions_n, a, b, h, dir);
    return HFVIS_OK;
}

/* The key every nearest-sample search ranks lattice point (a, b, cs) by, cs = +-(n - |a| - |b|)
 * (the sign of its hemisphere): with d = q . (a, b, cs) and L = a^2 + b^2 + cs^2 (exact), the key
 * d |d| / L = |q|^2 cos|cos| is monotone in the cosine of the angle between q and the sample, so
 * its maximum is the nearest sample, and it needs no square root. One expression for the fast
 * search and the oracle, so that they agree bit for bit. */
static double vx_vf_key(const double q[3], int a, int b, int cs)
{
    double L = (double)((long long)a * a + (long long)b * b + (long long)cs * cs);
    double d = q[0] * (double)a + q[1] * (double)b + q[2] * (double)cs;
    return d * fabs(d) / L;
}

/* q itself, or q divided by its largest |component| when that lies outside [1e-100, 1e100], so
 * that the keys neither overflow nor underflow. Applied by the fast search and the oracle alike. */
static void vx_vf_safe_q(const double q[3], double out[3])
{
    double m = fabs(q[0]);
    if (fabs(q[1]) > m) m = fabs(q[1]);
    if (fabs(q[2]) > m) m = fabs(q[2]);
    if (m >= 1e-100 && m <= 1e100) {
        out[0] = q[0];
        out[1] = q[1];
        out[2] = q[2];
    } else {
        out[0] = q[0] / m;
        out[1] = q[1] / m;
        out[2] = q[2] / m;
    }
}

/* Nearest sample to q (finite, not zero): radial projection onto the octahedron face of q's
 * hemisphere, the (up to) 9 lattice points of the 3 x 3 window around it, ranked by vx_vf_key;
 * equal keys go to the lower index, where an equator point counts with its upper copy's index
 * (same point, same key, lower index): the oracle's rule exactly. Returns the index and the
 * winner's lattice point (*h, *a, *b), the equator in the upper hemisphere. */
static size_t vx_vf_nearest_abh(int n, const double q0[3], int *ph, int *pa, int *pb)
{
    double q[3];
    int h = q0[2] < 0.0, ra, rb, a, b, m = 0, i, best = 0;
    int ca[9], cb[9], cc[9];
    double key[9], qz, s, fx, fy;
    size_t best_k = 0;
    vx_vf_safe_q(q0, q);
    qz = fabs(q[2]);
    s = fabs(q[0]) + fabs(q[1]) + qz;
    fx = floor(q[0] / s * (double)n + 0.5);
    fy = floor(q[1] / s * (double)n + 0.5);
    ra = fx >= -(double)n && fx <= (double)n ? (int)fx : 0;
    rb = fy >= -(double)n && fy <= (double)n ? (int)fy : 0;
    for (b = rb - 1; b <= rb + 1; b++)
        for (a = ra - 1; a <= ra + 1; a++) {
            int c = n - abs(a) - abs(b);
            if (b < -n || b > n || c < 0) continue;
            ca[m] = a;
            cb[m] = b;
            cc[m] = h ? -c : c;
            m++;
        }
    HFVIS_ASSERT(m > 0);
    for (i = 0; i < m; i++) key[i] = vx_vf_key(q, ca[i], cb[i], cc[i]); /* independent: pipelined */
    for (i = 1; i < m; i++) {
        if (key[i] < key[best]) continue;
        if (key[i] == key[best]) { /* a tie: the lower index wins */
            size_t ki = vx_vf_encode_index(n, cc[i] == 0 ? 0 : h, ca[i], cb[i]);
            best_k = vx_vf_encode_index(n, cc[best] == 0 ? 0 : h, ca[best], cb[best]);
            if (ki >= best_k) continue;
        }
        best = i;
    }
    *ph = cc[best] == 0 ? 0 : h;
    *pa = ca[best];
    *pb = cb[best];
    best_k = vx_vf_encode_index(n, *ph, *pa, *pb);
    return best_k;
}

static size_t vx_vf_nearest(int n, const double q[3])
{
    int h, a, b;
    return vx_vf_nearest_abh(n, q, &h, &a, &b);
}

static int vx_vf_vec_ok(const double v[3])
{
    return v && isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2])
           && (v[0] != 0.0 || v[1] != 0.0 || v[2] != 0.0);
}

HFVIS_API hfvis_status hfvis_visfield_nearest_position(int positions_n, const double q[3],
                                                       size_t *k)
{
    if (!vx_vf_n_valid(positions_n) || !vx_vf_vec_ok(q) || !k) return HFVIS_ERR_INVALID_ARGUMENT;
    *k = vx_vf_nearest(positions_n, q);
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_visfield_nearest_position_naive(int positions_n, const double q0[3],
                                                             size_t *k)
{
    size_t K, i, best_i = 0;
    double best = -HUGE_VAL, q[3];
    if (!vx_vf_n_valid(positions_n) || !vx_vf_vec_ok(q0) || !k) return HFVIS_ERR_INVALID_ARGUMENT;
    K = 2u * vx_vf_hemi(positions_n);
    vx_vf_safe_q(q0, q);
    for (i = 0; i < K; i++) {
        double dd;
        int h, a, b, c;
        vx_vf_decode_index(positions_n, i, &h, &a, &b);
        c = positions_n - abs(a) - abs(b);
        dd = vx_vf_key(q, a, b, h ? -c : c);
        if (i == 0 || dd > best) {
            best = dd;
            best_i = i;
        }
    }
    *k = best_i;
    return HFVIS_OK;
}

/* ---- vf-b. frame and direction maps ------------------------------------------------------ */

HFVIS_API void hfvis_visfield_frame(const double w[3], double t[3], double b[3])
{
    double s = w[2] < 0.0 ? -1.0 : 1.0; /* copysign(1, w.z) without C99 copysign's -0 case */
    double a = -1.0 / (s + w[2]), e = w[0] * w[1] * a;
    t[0] = 1.0 + s * w[0] * w[0] * a;
    t[1] = s * e;
    t[2] = -s * w[0];
    b[0] = e;
    b[1] = s + w[1] * w[1] * a;
    b[2] = -w[1];
}

#define VX_VF_QPI (VX_PI / 4.0)

HFVIS_API void hfvis_concentric_square_to_disk(double a, double b, double *x, double *y)
{
    double r, phi;
    if (a == 0.0 && b == 0.0) {
        *x = 0.0;
        *y = 0.0;
        return;
    }
    if (a > -b) {
        if (a > b) { r = a; phi = VX_VF_QPI * (b / a); }
        else { r = b; phi = VX_VF_QPI * (2.0 - a / b); }
    } else {
        if (a < b) { r = -a; phi = VX_VF_QPI * (4.0 + b / a); }
        else { r = -b; phi = b != 0.0 ? VX_VF_QPI * (6.0 - a / b) : 0.0; }
    }
    *x = r * cos(phi);
    *y = r * sin(phi);
}

HFVIS_API void hfvis_concentric_disk_to_square(double x, double y, double *a, double *b)
{
    double r = sqrt(x * x + y * y), phi;
    if (r == 0.0) {
        *a = 0.0;
        *b = 0.0;
        return;
    }
    phi = atan2(y, x);
    if (phi < -VX_VF_QPI) phi += 2.0 * VX_PI;
    if (phi < VX_VF_QPI) { *a = r; *b = r * (phi / VX_VF_QPI); }
    else if (phi < 3.0 * VX_VF_QPI) { *b = r; *a = r * (2.0 - phi / VX_VF_QPI); }
    else if (phi < 5.0 * VX_VF_QPI) { *a = -r; *b = -r * (phi / VX_VF_QPI - 4.0); }
    else { *b = -r; *a = -r * (6.0 - phi / VX_VF_QPI); }
}

static hfvis_dirmap vx_vf_mapping(hfvis_dirmap m)
{
    return m == HFVIS_DIRMAP_DEFAULT ? HFVIS_DIRMAP_CONCENTRIC : m;
}

static int vx_vf_mapping_valid(hfvis_dirmap m)
{
    return m == HFVIS_DIRMAP_DEFAULT || m == HFVIS_DIRMAP_POLAR || m == HFVIS_DIRMAP_REJECTION
           || m == HFVIS_DIRMAP_CONCENTRIC;
}

/* Square coordinate of texel index i (centre). */
static double vx_vf_sq(int i, int D)
{
    return 2.0 * ((double)i + 0.5) / (double)D - 1.0;
}

/* Texel index of square coordinate A, clamped to 0..D-1. */
static int vx_vf_texel_of(double A, int D)
{
    double f = floor((A + 1.0) * 0.5 * (double)D);
    if (!(f >= 0.0)) return 0;
    if (f > (double)(D - 1)) return D - 1;
    return (int)f;
}

/* Local direction of texel (i, j); returns 0 for an unused rejection texel. m resolved. */
static int vx_vf_to_local(hfvis_dirmap m, int D, int i, int j, double l[3])
{
    if (m == HFVIS_DIRMAP_POLAR) {
        double th = ((double)i + 0.5) / (double)D * (VX_PI / 2.0);
        double ph = ((double)j + 0.5) / (double)D * (2.0 * VX_PI);
        l[0] = sin(th) * cos(ph);
        l[1] = sin(th) * sin(ph);
        l[2] = cos(th);
        return 1;
    } else {
        double A = vx_vf_sq(i, D), B = vx_vf_sq(j, D), x, y, r2;
        if (m == HFVIS_DIRMAP_REJECTION) {
            x = A;
            y = B;
            r2 = x * x + y * y;
            if (r2 > 1.0) {
                l[0] = x;
                l[1] = y;
                l[2] = 0.0;
                return 0;
            }
        } else {
            hfvis_concentric_square_to_disk(A, B, &x, &y);
            r2 = x * x + y * y;
        }
        l[0] = x;
        l[1] = y;
        l[2] = sqrt(r2 < 1.0 ? 1.0 - r2 : 0.0);
        return 1;
    }
}

/* Texel of a unit local direction l (lz >= 0); returns whether it is used. m resolved. */
static int vx_vf_from_local(hfvis_dirmap m, int D, const double l[3], int *i, int *j)
{
    if (m == HFVIS_DIRMAP_POLAR) {
        double lz = l[2] > 1.0 ? 1.0 : l[2], th = acos(lz), ph = atan2(l[1], l[0]);
        double fi, fj;
        if (ph < 0.0) ph += 2.0 * VX_PI;
        fi = floor(th / (VX_PI / 2.0) * (double)D);
        fj = floor(ph / (2.0 * VX_PI) * (double)D);
        *i = fi >= (double)D ? D - 1 : (fi < 0.0 ? 0 : (int)fi);
        *j = fj >= (double)D ? D - 1 : (fj < 0.0 ? 0 : (int)fj);
        return 1;
    } else if (m == HFVIS_DIRMAP_REJECTION) {
        double A, B;
        *i = vx_vf_texel_of(l[0], D);
        *j = vx_vf_texel_of(l[1], D);
        A = vx_vf_sq(*i, D);
        B = vx_vf_sq(*j, D);
        return A * A + B * B <= 1.0;
    } else {
        double A, B;
        hfvis_concentric_disk_to_square(l[0], l[1], &A, &B);
        *i = vx_vf_texel_of(A, D);
        *j = vx_vf_texel_of(B, D);
        return 1;
    }
}

HFVIS_API hfvis_status hfvis_dirmap_to_local(hfvis_dirmap mapping, int dir_res, int i, int j,
                                             double l[3], int *used)
{
    double tmp[3];
    int u;
    if (!vx_vf_mapping_valid(mapping) || !vx_vf_d_valid(dir_res) || i < 0 || j < 0
        || i >= dir_res || j >= dir_res || !l || !used)
        return HFVIS_ERR_INVALID_ARGUMENT;
    u = vx_vf_to_local(vx_vf_mapping(mapping), dir_res, i, j, tmp);
    l[0] = tmp[0];
    l[1] = tmp[1];
    l[2] = tmp[2];
    *used = u;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_dirmap_from_local(hfvis_dirmap mapping, int dir_res,
                                               const double l[3], int *i, int *j, int *used)
{
    double len, u[3];
    int ii, jj, us;
    if (!vx_vf_mapping_valid(mapping) || !vx_vf_d_valid(dir_res) || !vx_vf_vec_ok(l) || !i || !j
        || l[2] < 0.0)
        return HFVIS_ERR_INVALID_ARGUMENT;
    len = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
    if (!(len > 0.0) || !isfinite(len)) return HFVIS_ERR_INVALID_ARGUMENT;
    u[0] = l[0] / len;
    u[1] = l[1] / len;
    u[2] = l[2] / len;
    us = vx_vf_from_local(vx_vf_mapping(mapping), dir_res, u, &ii, &jj);
    *i = ii;
    *j = jj;
    if (used) *used = us;
    return HFVIS_OK;
}

/* ---- vf-c. sizes, validation, texel encoding --------------------------------------------- */

static hfvis_visfield_format vx_vf_format(hfvis_visfield_format f)
{
    return f == HFVIS_VISFIELD_DEFAULT ? HFVIS_VISFIELD_U8 : f;
}

static int vx_vf_format_valid(hfvis_visfield_format f)
{
    return f == HFVIS_VISFIELD_DEFAULT || f == HFVIS_VISFIELD_U8 || f == HFVIS_VISFIELD_F32
           || f == HFVIS_VISFIELD_BIT || f == HFVIS_VISFIELD_NORMAL;
}

/* Maps bytes in 64 bits (never overflows for valid n, D: K*D^2*4 < 2^49). */
static uint64_t vx_vf_size64(int n, int D, hfvis_visfield_format f)
{
    uint64_t texels = (uint64_t)(2u * vx_vf_hemi(n)) * (uint64_t)D * (uint64_t)D;
    switch (vx_vf_format(f)) {
    case HFVIS_VISFIELD_F32:
    case HFVIS_VISFIELD_NORMAL: return texels * 4u;
    case HFVIS_VISFIELD_BIT: return (texels + 7u) / 8u;
    default: return texels;
    }
}

HFVIS_API size_t hfvis_visfield_size(int positions_n, int dir_res, hfvis_visfield_format format)
{
    uint64_t s;
    if (!vx_vf_n_valid(positions_n) || !vx_vf_d_valid(dir_res) || !vx_vf_format_valid(format))
        return 0;
    s = vx_vf_size64(positions_n, dir_res, format);
    if (s > (uint64_t)SIZE_MAX) return 0;
    return (size_t)s;
}

/* Parameters valid (maps not looked at). */
static int vx_vf_params_ok(const hfvis_visfield *vf)
{
    return vf && isfinite(vf->center[0]) && isfinite(vf->center[1]) && isfinite(vf->center[2])
           && isfinite(vf->radius) && vf->radius > 0.0 && vx_vf_n_valid(vf->positions_n)
           && vx_vf_d_valid(vf->dir_res) && vx_vf_mapping_valid(vf->mapping)
           && vx_vf_format_valid(vf->format) && isfinite(vf->avg_distance)
           && vf->avg_distance >= 0.0 && vf->avg_distance <= 1.0;
}

/* Parameters valid and maps present with enough bytes. */
static int vx_vf_valid(const hfvis_visfield *vf)
{
    size_t need;
    if (!vx_vf_params_ok(vf) || !vf->maps) return 0;
    need = hfvis_visfield_size(vf->positions_n, vf->dir_res, vf->format);
    return need != 0 && vf->maps_size >= need;
}

/* 8-bit distance code of a normalised hit distance v in [0, 1] (spec §1.5 [C]). */
static unsigned char vx_vf_code8(double v)
{
    double q = floor((double)HFVIS_VISFIELD_U8_SCALE * v + 0.5);
    if (!(q >= 0.0)) q = 0.0;
    if (q > (double)HFVIS_VISFIELD_U8_SCALE) q = (double)HFVIS_VISFIELD_U8_SCALE;
    return (unsigned char)q;
}

static unsigned char vx_vf_code_normal(double c)
{
    double q = floor(127.5 * c + 128.0);
    if (!(q >= 0.0)) q = 0.0;
    if (q > 255.0) q = 255.0;
    return (unsigned char)q;
}

/* Write texel t (linear index over all maps) of format f: hit (v = th/(2R)) or miss. */
static void vx_vf_store(unsigned char *maps, hfvis_visfield_format f, size_t t, int hit, double v,
                        const double nrm[3])
{
    switch (f) {
    case HFVIS_VISFIELD_F32: {
        float x = 1.0f;
        if (hit) {
            x = (float)v;
            if (!(x >= 0.0f)) x = 0.0f;
            if (x > VX_VF_F32_MAX_HIT) x = VX_VF_F32_MAX_HIT;
        }
        memcpy(maps + 4 * t, &x, 4);
        break;
    }
    case HFVIS_VISFIELD_BIT:
        if (hit) maps[t >> 3] = (unsigned char)(maps[t >> 3] | (1u << (t & 7u)));
        else maps[t >> 3] = (unsigned char)(maps[t >> 3] & ~(1u << (t & 7u)));
        break;
    case HFVIS_VISFIELD_NORMAL:
        if (hit) {
            maps[4 * t] = vx_vf_code_normal(nrm[0]);
            maps[4 * t + 1] = vx_vf_code_normal(nrm[1]);
            maps[4 * t + 2] = vx_vf_code_normal(nrm[2]);
            maps[4 * t + 3] = vx_vf_code8(v);
        } else {
            maps[4 * t] = maps[4 * t + 1] = maps[4 * t + 2] = 0;
            maps[4 * t + 3] = HFVIS_VISFIELD_U8_MISS;
        }
        break;
    default:
        maps[t] = hit ? vx_vf_code8(v) : (unsigned char)HFVIS_VISFIELD_U8_MISS;
        break;
    }
}

/* Read texel t: returns 1 for a hit with *v = th/(2R) (and the normal for NORMAL), 0 for a miss. */
static int vx_vf_load(const hfvis_visfield *vf, hfvis_visfield_format f, size_t t, double *v,
                      double nrm[3])
{
    const unsigned char *maps = (const unsigned char *)vf->maps;
    switch (f) {
    case HFVIS_VISFIELD_F32: {
        float x;
        memcpy(&x, maps + 4 * t, 4);
        if (!(x < 1.0f)) return 0;
        *v = (double)x;
        return 1;
    }
    case HFVIS_VISFIELD_BIT:
        if (!((maps[t >> 3] >> (t & 7u)) & 1u)) return 0;
        *v = vf->avg_distance;
        return 1;
    case HFVIS_VISFIELD_NORMAL: {
        const unsigned char *p = maps + 4 * t;
        if (p[3] == HFVIS_VISFIELD_U8_MISS) return 0;
        *v = (double)p[3] / (double)HFVIS_VISFIELD_U8_SCALE;
        if (nrm) {
            double x = ((double)p[0] - 127.5) / 127.5, y = ((double)p[1] - 127.5) / 127.5;
            double z = ((double)p[2] - 127.5) / 127.5, len = sqrt(x * x + y * y + z * z);
            nrm[0] = x / len;
            nrm[1] = y / len;
            nrm[2] = z / len;
        }
        return 1;
    }
    default:
        if (maps[t] == HFVIS_VISFIELD_U8_MISS) return 0;
        *v = (double)maps[t] / (double)HFVIS_VISFIELD_U8_SCALE;
        return 1;
    }
}

HFVIS_API hfvis_status hfvis_visfield_texel(const hfvis_visfield *vf, size_t k, int i, int j,
                                            int *hit, double *distance, double normal[3])
{
    double v = 1.0, nrm[3] = {0.0, 0.0, 0.0};
    size_t D;
    hfvis_visfield_format f;
    int h;
    if (!vx_vf_valid(vf) || !hit || !distance || k >= 2u * vx_vf_hemi(vf->positions_n) || i < 0
        || j < 0 || i >= vf->dir_res || j >= vf->dir_res)
        return HFVIS_ERR_INVALID_ARGUMENT;
    D = (size_t)vf->dir_res;
    f = vx_vf_format(vf->format);
    h = vx_vf_load(vf, f, (k * D + (size_t)j) * D + (size_t)i, &v, nrm);
    if (!h) v = 1.0;
    if (!h || f != HFVIS_VISFIELD_NORMAL) nrm[0] = nrm[1] = nrm[2] = 0.0;
    *hit = h;
    *distance = v;
    if (normal) {
        normal[0] = nrm[0];
        normal[1] = nrm[1];
        normal[2] = nrm[2];
    }
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_visfield_bounding_sphere(const hfvis_mesh *mesh, double center[3],
                                                      double *radius)
{
    double lo[3], hi[3], c[3], r2 = 0.0, r;
    size_t v;
    int a;
    if (!mesh || !center || !radius || vx_mesh_check(mesh) != HFVIS_OK || mesh->vertex_count == 0)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (hfvis_mesh_bounds(mesh, lo, hi) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    for (a = 0; a < 3; a++) c[a] = 0.5 * lo[a] + 0.5 * hi[a];
    for (v = 0; v < mesh->vertex_count; v++) {
        const float *p = mesh->xyz + 3 * v;
        double dx = (double)p[0] - c[0], dy = (double)p[1] - c[1], dz = (double)p[2] - c[2];
        double d2 = dx * dx + dy * dy + dz * dz;
        if (d2 > r2) r2 = d2;
    }
    r = sqrt(r2) * (1.0 + 1e-4);
    if (r < 1e-30) r = 1e-30;
    for (a = 0; a < 3; a++) center[a] = c[a];
    *radius = r;
    return HFVIS_OK;
}

/* ---- vf-d. build (Algorithm 1) ----------------------------------------------------------- */

/* Unit geometric normal (v1 - v0) x (v2 - v0) of triangle tri, in double. */
static void vx_vf_tri_normal(const hfvis_mesh *m, uint32_t tri, double n[3])
{
    const uint32_t *ix = m->indices + 3 * (size_t)tri;
    const float *p0 = m->xyz + 3 * (size_t)ix[0], *p1 = m->xyz + 3 * (size_t)ix[1];
    const float *p2 = m->xyz + 3 * (size_t)ix[2];
    double e1[3], e2[3], len;
    int a;
    for (a = 0; a < 3; a++) {
        e1[a] = (double)p1[a] - (double)p0[a];
        e2[a] = (double)p2[a] - (double)p0[a];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (len > 0.0) {
        n[0] /= len;
        n[1] /= len;
        n[2] /= len;
    }
}

/* Closest hit of a float ray from o along d (t_min = 0, t_max = +inf), through bvh or naively
 * (bvh NULL). *th = t * |direction| (distance along the unit direction); *tri the triangle. */
static hfvis_status vx_vf_cast(const hfvis_mesh *mesh, const hfvis_bvh *bvh, const double o[3],
                               const double d[3], int *hit, double *th, uint32_t *tri)
{
    hfvis_ray ray;
    hfvis_hit h;
    hfvis_status s;
    double len;
    int a;
    for (a = 0; a < 3; a++) {
        ray.origin[a] = (float)o[a];
        ray.direction[a] = (float)d[a];
    }
    ray.t_min = 0.0f;
    ray.t_max = INFINITY;
    ray.cull = HFVIS_CULL_NONE;
    s = bvh ? hfvis_bvh_closest_hit(bvh, mesh, &ray, &h) : hfvis_ray_closest_naive(mesh, &ray, &h);
    if (s != HFVIS_OK) return s;
    *hit = h.triangle != HFVIS_NO_TRIANGLE;
    if (*hit) {
        len = sqrt((double)ray.direction[0] * (double)ray.direction[0]
                   + (double)ray.direction[1] * (double)ray.direction[1]
                   + (double)ray.direction[2] * (double)ray.direction[2]);
        *th = (double)h.t * len;
        *tri = h.triangle;
    }
    return HFVIS_OK;
}

/* Arguments of both builds: a valid mesh inside the sphere, valid parameters and storage. */
static hfvis_status vx_vf_build_check(const hfvis_mesh *mesh, const hfvis_visfield *vf)
{
    size_t need, v;
    double lim;
    if (!mesh || !vf || vx_mesh_check(mesh) != HFVIS_OK || !vf->maps)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (!isfinite(vf->center[0]) || !isfinite(vf->center[1]) || !isfinite(vf->center[2])
        || !isfinite(vf->radius) || !(vf->radius > 0.0) || !vx_vf_n_valid(vf->positions_n)
        || !vx_vf_d_valid(vf->dir_res) || !vx_vf_mapping_valid(vf->mapping)
        || !vx_vf_format_valid(vf->format))
        return HFVIS_ERR_INVALID_ARGUMENT;
    need = hfvis_visfield_size(vf->positions_n, vf->dir_res, vf->format);
    if (need == 0) return HFVIS_ERR_LIMIT; /* does not fit size_t (32-bit hosts) */
    lim = vf->radius * (1.0 + VX_VF_INSIDE_TOL);
    lim *= lim;
    for (v = 0; v < mesh->vertex_count; v++) {
        const float *p = mesh->xyz + 3 * v;
        double dx = (double)p[0] - vf->center[0], dy = (double)p[1] - vf->center[1];
        double dz = (double)p[2] - vf->center[2];
        if (!(dx * dx + dy * dy + dz * dz <= lim)) return HFVIS_ERR_INVALID_ARGUMENT;
    }
    if (vf->maps_size < need) return HFVIS_ERR_BUFFER_TOO_SMALL;
    return HFVIS_OK;
}

/* Algorithm 1 over all samples and texels; bvh NULL = the naive caster. */
static hfvis_status vx_vf_build_run(const hfvis_mesh *mesh, const hfvis_bvh *bvh,
                                    const hfvis_visfield_build_options *opts, hfvis_visfield *vf)
{
    const int n = vf->positions_n, D = vf->dir_res;
    const size_t K = 2u * vx_vf_hemi(n), DD = (size_t)D * (size_t)D;
    const hfvis_dirmap m = vx_vf_mapping(vf->mapping);
    const hfvis_visfield_format f = vx_vf_format(vf->format);
    const double R = vf->radius, inv2R = 1.0 / (2.0 * R);
    unsigned char *maps = (unsigned char *)vf->maps;
    double sum = 0.0, nrm[3] = {0.0, 0.0, 0.0};
    size_t k, central = 0;
    hfvis_status s;

    if (f == HFVIS_VISFIELD_BIT) memset(maps, 0, (size_t)vx_vf_size64(n, D, f));
    for (k = 0; k < K; k++) {
        double u[3], w[3], t[3], b[3], p[3], th = 0.0;
        uint32_t tri = 0;
        int i, j, hit = 0, a;
        s = hfvis_visfield_position(n, k, u);
        HFVIS_ASSERT(s == HFVIS_OK);
        for (a = 0; a < 3; a++) {
            w[a] = -u[a];
            p[a] = vf->center[a] + R * u[a];
        }
        hfvis_visfield_frame(w, t, b);
        /* the central ray (along the inward normal) for avg_distance ([G12] §4.6.1.3) */
        s = vx_vf_cast(mesh, bvh, p, w, &hit, &th, &tri);
        if (s != HFVIS_OK) return s;
        if (hit) {
            sum += th * inv2R;
            central++;
        }
        for (j = 0; j < D; j++)
            for (i = 0; i < D; i++) {
                double l[3], d[3];
                size_t texel = k * DD + (size_t)j * (size_t)D + (size_t)i;
                hit = 0;
                if (vx_vf_to_local(m, D, i, j, l)) {
                    for (a = 0; a < 3; a++) d[a] = l[0] * t[a] + l[1] * b[a] + l[2] * w[a];
                    s = vx_vf_cast(mesh, bvh, p, d, &hit, &th, &tri);
                    if (s != HFVIS_OK) return s;
                }
                if (hit && f == HFVIS_VISFIELD_NORMAL) vx_vf_tri_normal(mesh, tri, nrm);
                vx_vf_store(maps, f, texel, hit, hit ? th * inv2R : 1.0, nrm);
            }
        if (opts && opts->progress) opts->progress(opts->progress_user, (int)(k + 1), (int)K);
    }
    vf->avg_distance = central ? sum / (double)central : 0.5;
    if (vf->avg_distance > 1.0) vf->avg_distance = 1.0;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_visfield_build(const hfvis_mesh *mesh,
                                            const hfvis_visfield_build_options *opts,
                                            hfvis_visfield *vf)
{
    hfvis_bvh own;
    const hfvis_bvh *bvh;
    hfvis_status s = vx_vf_build_check(mesh, vf);
    if (s != HFVIS_OK) return s;
    if (opts && opts->bvh) {
        if (opts->bvh->triangle_count != mesh->triangle_count) return HFVIS_ERR_INVALID_ARGUMENT;
        return vx_vf_build_run(mesh, opts->bvh, opts, vf);
    }
    {
        hfvis_bvh_options bo = hfvis_bvh_options_default();
        bo.alloc = opts ? opts->alloc : NULL;
        s = hfvis_bvh_build(mesh, &bo, &own);
        if (s != HFVIS_OK) return s;
    }
    bvh = &own;
    s = vx_vf_build_run(mesh, bvh, opts, vf);
    hfvis_bvh_free(opts ? opts->alloc : NULL, &own);
    return s;
}

HFVIS_API hfvis_status hfvis_visfield_build_reference(const hfvis_mesh *mesh,
                                                      const hfvis_visfield_build_options *opts,
                                                      hfvis_visfield *vf)
{
    hfvis_status s = vx_vf_build_check(mesh, vf);
    if (s != HFVIS_OK) return s;
    return vx_vf_build_run(mesh, NULL, opts, vf);
}

/* ---- vf-e. queries ----------------------------------------------------------------------- */

static void vx_vf_hit_miss(hfvis_visfield_hit *h)
{
    h->result = HFVIS_VISFIELD_MISS;
    h->distance = INFINITY;
    h->normal[0] = h->normal[1] = h->normal[2] = 0.0;
    h->sphere_t = INFINITY;
    h->position = HFVIS_VISFIELD_NONE;
    h->texel_i = h->texel_j = -1;
}

/* The sphere part of both queries: returns 0 (miss: the ray does not meet the sphere), 1
 * (outside: *t = entry t0, rel = entry - c) or 2 (inside: *t = exit t1, rel = exit - c). */
static int vx_vf_sphere(const hfvis_visfield *vf, const double o[3], const double d[3], double *t,
                        double rel[3])
{
    double oc[3], beta, gamma, delta, sq, t0, t1, R = vf->radius;
    int a;
    for (a = 0; a < 3; a++) oc[a] = o[a] - vf->center[a];
    beta = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
    gamma = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - R * R;
    delta = beta * beta - gamma;
    /* fields or rays so far out that the squares overflow: no answer rather than a NaN index */
    if (!isfinite(beta) || !isfinite(gamma) || !isfinite(delta)) return 0;
    if (gamma >= 0.0) {
        if (!(delta > 0.0)) return 0;
        sq = sqrt(delta);
        t1 = -beta + sq;
        if (!(t1 > 0.0)) return 0;
        t0 = -beta - sq;
        if (t0 < 0.0) t0 = 0.0;
        *t = t0;
        for (a = 0; a < 3; a++) rel[a] = oc[a] + t0 * d[a];
        if (rel[0] == 0.0 && rel[1] == 0.0 && rel[2] == 0.0) /* underflow: a central ray */
            for (a = 0; a < 3; a++) rel[a] = -d[a];
        return isfinite(t0) && isfinite(rel[0]) && isfinite(rel[1]) && isfinite(rel[2]) ? 1 : 0;
    }
    sq = sqrt(delta);
    t1 = -beta + sq;
    *t = t1;
    for (a = 0; a < 3; a++) rel[a] = oc[a] + t1 * d[a];
    if (rel[0] == 0.0 && rel[1] == 0.0 && rel[2] == 0.0)
        for (a = 0; a < 3; a++) rel[a] = d[a];
    return isfinite(t1) && isfinite(rel[0]) && isfinite(rel[1]) && isfinite(rel[2]) ? 2 : 0;
}

/* The map lookup of both cases: direction e (unit) toward the object at the sample nearest rel.
 * Returns 1 with *v (and nrm) on a stored hit. */
static int vx_vf_lookup(const hfvis_visfield *vf, const double rel[3], const double e[3],
                        hfvis_visfield_hit *out, double *v, double nrm[3])
{
    const int n = vf->positions_n, D = vf->dir_res;
    const hfvis_visfield_format f = vx_vf_format(vf->format);
    double u[3], w[3], t[3], b[3], l[3];
    int h, aa, bb, i, j;
    size_t k = vx_vf_nearest_abh(n, rel, &h, &aa, &bb);
    vx_vf_oct_dir(n, aa, bb, h, u);
    w[0] = -u[0];
    w[1] = -u[1];
    w[2] = -u[2];
    hfvis_visfield_frame(w, t, b);
    out->position = k;
    l[0] = e[0] * t[0] + e[1] * t[1] + e[2] * t[2];
    l[1] = e[0] * b[0] + e[1] * b[1] + e[2] * b[2];
    l[2] = e[0] * w[0] + e[1] * w[1] + e[2] * w[2];
    if (!(l[2] > 0.0)) return 0; /* grazing: outside the sample's hemisphere (spec §1.7 [C]) */
    if (!vx_vf_from_local(vx_vf_mapping(vf->mapping), D, l, &i, &j)) {
        out->texel_i = i;
        out->texel_j = j;
        return 0; /* unused rejection texel */
    }
    out->texel_i = i;
    out->texel_j = j;
    return vx_vf_load(vf, f, (k * (size_t)D + (size_t)j) * (size_t)D + (size_t)i, v,
                      f == HFVIS_VISFIELD_NORMAL ? nrm : NULL);
}

/* Algorithms 2/3 for one ray, d unit, object space. */
static void vx_vf_query_core(const hfvis_visfield *vf, const double o[3], const double d[3],
                             double bias, hfvis_visfield_hit *out)
{
    double t, rel[3], v = 0.0, nrm[3] = {0.0, 0.0, 0.0}, e[3], twoR = 2.0 * vf->radius;
    int c;
    vx_vf_hit_miss(out);
    c = vx_vf_sphere(vf, o, d, &t, rel);
    if (c == 0) return;
    out->sphere_t = t;
    if (c == 1) {
        if (!vx_vf_lookup(vf, rel, d, out, &v, nrm)) return;
        out->result = HFVIS_VISFIELD_HIT;
        out->distance = t + v * twoR;
    } else {
        double d2;
        e[0] = -d[0];
        e[1] = -d[1];
        e[2] = -d[2];
        if (!vx_vf_lookup(vf, rel, e, out, &v, nrm)) return;
        d2 = v * twoR;
        if (!(d2 < t - bias)) return;
        out->result = HFVIS_VISFIELD_OCCLUDED;
        out->distance = t - d2;
    }
    out->normal[0] = nrm[0];
    out->normal[1] = nrm[1];
    out->normal[2] = nrm[2];
}

/* The same with exact ray casting from the entry / exit point. */
static hfvis_status vx_vf_query_ref_core(const hfvis_visfield *vf, const hfvis_mesh *mesh,
                                         const hfvis_bvh *bvh, const double o[3],
                                         const double d[3], double bias, hfvis_visfield_hit *out)
{
    double t, rel[3], p[3], e[3], th = 0.0;
    uint32_t tri = 0;
    hfvis_status s;
    int c, a, hit = 0;
    vx_vf_hit_miss(out);
    c = vx_vf_sphere(vf, o, d, &t, rel);
    if (c == 0) return HFVIS_OK;
    out->sphere_t = t;
    for (a = 0; a < 3; a++) {
        p[a] = o[a] + t * d[a];
        e[a] = c == 1 ? d[a] : -d[a];
    }
    s = vx_vf_cast(mesh, bvh, p, e, &hit, &th, &tri);
    if (s != HFVIS_OK) return s;
    if (!hit) return HFVIS_OK;
    if (c == 1) {
        out->result = HFVIS_VISFIELD_HIT;
        out->distance = t + th;
    } else {
        if (!(th < t - bias)) return HFVIS_OK;
        out->result = HFVIS_VISFIELD_OCCLUDED;
        out->distance = t - th;
    }
    vx_vf_tri_normal(mesh, tri, out->normal);
    return HFVIS_OK;
}

/* Unit copy of a valid direction. */
static int vx_vf_unit(const double d[3], double u[3])
{
    double len;
    if (!vx_vf_vec_ok(d)) return 0;
    len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(len > 0.0) || !isfinite(len)) { /* over/underflow: rescale first */
        double m = fabs(d[0]);
        if (fabs(d[1]) > m) m = fabs(d[1]);
        if (fabs(d[2]) > m) m = fabs(d[2]);
        u[0] = d[0] / m;
        u[1] = d[1] / m;
        u[2] = d[2] / m;
        len = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
        u[0] /= len;
        u[1] /= len;
        u[2] /= len;
        return 1;
    }
    u[0] = d[0] / len;
    u[1] = d[1] / len;
    u[2] = d[2] / len;
    return 1;
}

static int vx_vf_point_ok(const double p[3])
{
    return p && isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]);
}

HFVIS_API hfvis_status hfvis_visfield_query(const hfvis_visfield *vf, const double origin[3],
                                            const double direction[3], double bias,
                                            hfvis_visfield_hit *out)
{
    double d[3];
    hfvis_visfield_hit h;
    if (!vx_vf_valid(vf) || !vx_vf_point_ok(origin) || !vx_vf_unit(direction, d) || !out
        || !isfinite(bias) || bias < 0.0)
        return HFVIS_ERR_INVALID_ARGUMENT;
    vx_vf_query_core(vf, origin, d, bias, &h);
    *out = h;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_visfield_query_reference(const hfvis_visfield *vf,
                                                      const hfvis_mesh *mesh,
                                                      const hfvis_bvh *bvh,
                                                      const double origin[3],
                                                      const double direction[3], double bias,
                                                      hfvis_visfield_hit *out)
{
    double d[3];
    hfvis_visfield_hit h;
    hfvis_status s;
    if (!vx_vf_params_ok(vf) || !mesh || !vx_vf_point_ok(origin) || !vx_vf_unit(direction, d)
        || !out || !isfinite(bias) || bias < 0.0)
        return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_vf_query_ref_core(vf, mesh, bvh, origin, d, bias, &h);
    if (s != HFVIS_OK) return s;
    *out = h;
    return HFVIS_OK;
}

/* ---- vf-f. scenes: AO, soft shadows, tracing, reflections -------------------------------- */

/* One object prepared for queries: object -> world M = [s Q | T]. */
typedef struct vx_vf_inst {
    const hfvis_visfield *vf;
    const hfvis_mesh *mesh;
    const hfvis_bvh *bvh;
    double q[9];     /* columns of Q: q[3c + r] */
    double T[3];
    double s, inv_s;
    double bias;     /* object units */
} vx_vf_inst;

/* Rigid-with-uniform-scale check of a column-major matrix; fills inst's transform. */
static int vx_vf_transform(const double m[16], vx_vf_inst *in)
{
    double s2;
    int a, b, r;
    for (a = 0; a < 16; a++)
        if (!isfinite(m[a])) return 0;
    if (m[3] != 0.0 || m[7] != 0.0 || m[11] != 0.0 || m[15] != 1.0) return 0;
    s2 = m[0] * m[0] + m[1] * m[1] + m[2] * m[2];
    if (!(s2 > 0.0) || !isfinite(s2)) return 0;
    for (a = 0; a < 3; a++)
        for (b = a; b < 3; b++) {
            double dd = m[4 * a] * m[4 * b] + m[4 * a + 1] * m[4 * b + 1]
                        + m[4 * a + 2] * m[4 * b + 2];
            if (!(fabs(dd - (a == b ? s2 : 0.0)) <= VX_VF_RIGID_TOL * s2)) return 0;
        }
    in->s = sqrt(s2);
    in->inv_s = 1.0 / in->s;
    for (a = 0; a < 3; a++) {
        for (r = 0; r < 3; r++) in->q[3 * a + r] = m[4 * a + r] * in->inv_s;
        in->T[a] = m[12 + a];
    }
    return 1;
}

/* Validate the objects of a scene (reference: also meshes and BVHs, O(V + T) each). */
static hfvis_status vx_vf_objects_check(const hfvis_visfield_object *objects, size_t count,
                                        int reference)
{
    size_t i;
    vx_vf_inst tmp;
    if (count && !objects) return HFVIS_ERR_INVALID_ARGUMENT;
    for (i = 0; i < count; i++) {
        const hfvis_visfield_object *o = objects + i;
        if (!vx_vf_transform(o->object_to_world, &tmp)) return HFVIS_ERR_INVALID_ARGUMENT;
        if (reference) {
            if (!vx_vf_params_ok(o->field) || vx_mesh_check(o->mesh) != HFVIS_OK)
                return HFVIS_ERR_INVALID_ARGUMENT;
            if (o->bvh && o->bvh->triangle_count != o->mesh->triangle_count)
                return HFVIS_ERR_INVALID_ARGUMENT;
        } else if (!vx_vf_valid(o->field)) {
            return HFVIS_ERR_INVALID_ARGUMENT;
        }
    }
    return HFVIS_OK;
}

/* Prepare a validated object; bias_frac * R is its object-space bias. */
static void vx_vf_inst_make(const hfvis_visfield_object *o, double bias_frac, vx_vf_inst *in)
{
    int ok = vx_vf_transform(o->object_to_world, in);
    HFVIS_ASSERT(ok);
    (void)ok;
    in->vf = o->field;
    in->mesh = o->mesh;
    in->bvh = o->bvh;
    in->bias = bias_frac * o->field->radius;
}

/* World ray (o, d unit) -> object space (o2, d2 unit). */
static void vx_vf_to_object(const vx_vf_inst *in, const double o[3], const double d[3],
                            double o2[3], double d2[3])
{
    double r[3];
    int c;
    for (c = 0; c < 3; c++) r[c] = o[c] - in->T[c];
    for (c = 0; c < 3; c++) {
        const double *qc = in->q + 3 * c;
        o2[c] = (qc[0] * r[0] + qc[1] * r[1] + qc[2] * r[2]) * in->inv_s;
        d2[c] = qc[0] * d[0] + qc[1] * d[1] + qc[2] * d[2];
    }
}

/* Query one object with a world ray; world distance in *dist. Returns the result. */
static hfvis_status vx_vf_inst_query(const vx_vf_inst *in, int reference, const double o[3],
                                     const double d[3], hfvis_visfield_hit *h)
{
    double o2[3], d2[3];
    vx_vf_to_object(in, o, d, o2, d2);
    if (reference) return vx_vf_query_ref_core(in->vf, in->mesh, in->bvh, o2, d2, in->bias, h);
    vx_vf_query_core(in->vf, o2, d2, in->bias, h);
    return HFVIS_OK;
}

HFVIS_API hfvis_visfield_ao_options hfvis_visfield_ao_options_default(void)
{
    hfvis_visfield_ao_options o;
    memset(&o, 0, sizeof o);
    o.rays_sqrt = VX_VF_DEFAULT_RAYS_SQRT;
    o.max_distance = INFINITY;
    o.falloff = HFVIS_VISFIELD_FALLOFF_BINARY;
    o.combine = HFVIS_VISFIELD_COMBINE_ANY;
    o.bias = HFVIS_VISFIELD_DEFAULT_BIAS;
    o.offset = 0.0;
    o.alloc = NULL;
    return o;
}

/* Bias fraction of the options (0 = default); -1 if invalid. */
static double vx_vf_bias_frac(double b)
{
    if (!isfinite(b) || b < 0.0) return -1.0;
    return b == 0.0 ? HFVIS_VISFIELD_DEFAULT_BIAS : b;
}

/* Points (and normals) finite, normals not zero. */
static int vx_vf_points_ok(const float *pts, const float *nrm, size_t count)
{
    size_t i;
    if (count > SIZE_MAX / 3) return 0;
    for (i = 0; i < 3 * count; i++)
        if (!isfinite(pts[i]) || (nrm && !isfinite(nrm[i]))) return 0;
    if (nrm)
        for (i = 0; i < count; i++)
            if (nrm[3 * i] == 0.0f && nrm[3 * i + 1] == 0.0f && nrm[3 * i + 2] == 0.0f) return 0;
    return 1;
}

/* The instances of a validated scene in one block (NULL and OK for count 0). */
static hfvis_status vx_vf_insts(const hfvis_visfield_object *objects, size_t count,
                                double bias_frac, const hfvis_allocator *alloc, vx_vf_inst **out)
{
    size_t i;
    vx_vf_inst *in;
    *out = NULL;
    if (count == 0) return HFVIS_OK;
    in = (vx_vf_inst *)vx_alloc_array(alloc, count, sizeof *in);
    if (!in) return HFVIS_ERR_OUT_OF_MEMORY;
    for (i = 0; i < count; i++) vx_vf_inst_make(objects + i, bias_frac, in + i);
    *out = in;
    return HFVIS_OK;
}

/* Ambient occlusion driver (fast or reference). */
static hfvis_status vx_vf_ao_run(const hfvis_visfield_object *objects, size_t count,
                                 const float *points, const float *normals, size_t pc,
                                 const hfvis_visfield_ao_options *opts, float *out, int reference)
{
    hfvis_visfield_ao_options o = hfvis_visfield_ao_options_default();
    const hfvis_allocator *alloc;
    vx_vf_inst *in = NULL;
    double *rays = NULL, maxd, bias_frac;
    float *res = NULL;
    size_t S, nr, p, r, m;
    hfvis_status s;
    int i, j;

    if (opts) {
        o = *opts;
        if (o.rays_sqrt == 0) o.rays_sqrt = VX_VF_DEFAULT_RAYS_SQRT;
        if (o.max_distance == 0.0) o.max_distance = INFINITY;
        if (o.falloff == HFVIS_VISFIELD_FALLOFF_DEFAULT) o.falloff = HFVIS_VISFIELD_FALLOFF_BINARY;
        if (o.combine == HFVIS_VISFIELD_COMBINE_DEFAULT) o.combine = HFVIS_VISFIELD_COMBINE_ANY;
    }
    bias_frac = vx_vf_bias_frac(o.bias);
    maxd = o.max_distance;
    if (o.rays_sqrt < 1 || o.rays_sqrt > HFVIS_VISFIELD_MAX_RAYS_SQRT || !(maxd > 0.0)
        || bias_frac < 0.0 || !isfinite(o.offset) || o.offset < 0.0
        || (o.falloff != HFVIS_VISFIELD_FALLOFF_BINARY
            && o.falloff != HFVIS_VISFIELD_FALLOFF_LINEAR)
        || (o.combine != HFVIS_VISFIELD_COMBINE_ANY
            && o.combine != HFVIS_VISFIELD_COMBINE_SUBTRACTIVE)
        || (o.falloff == HFVIS_VISFIELD_FALLOFF_LINEAR && !isfinite(maxd)))
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (pc && (!points || !normals || !out)) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_vf_objects_check(objects, count, reference);
    if (s != HFVIS_OK) return s;
    if (pc && !vx_vf_points_ok(points, normals, pc)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (pc == 0) return HFVIS_OK;
    alloc = o.alloc;
    S = (size_t)o.rays_sqrt;
    nr = S * S;
    /* the pre-generated hemisphere ray set ([G12] §4.5.1): concentric grid + Malley */
    rays = (double *)vx_alloc_array(alloc, nr, 3 * sizeof(double));
    if (!rays) return HFVIS_ERR_OUT_OF_MEMORY;
    for (j = 0; j < o.rays_sqrt; j++)
        for (i = 0; i < o.rays_sqrt; i++) {
            double x, y, r2, *l = rays + 3 * ((size_t)j * S + (size_t)i);
            hfvis_concentric_square_to_disk(vx_vf_sq(i, o.rays_sqrt), vx_vf_sq(j, o.rays_sqrt),
                                            &x, &y);
            r2 = x * x + y * y;
            l[0] = x;
            l[1] = y;
            l[2] = sqrt(r2 < 1.0 ? 1.0 - r2 : 0.0);
        }
    s = vx_vf_insts(objects, count, bias_frac, alloc, &in);
    if (s != HFVIS_OK) goto done;
    if (reference) {
        res = (float *)vx_alloc_array(alloc, pc, sizeof(float));
        if (!res) { s = HFVIS_ERR_OUT_OF_MEMORY; goto done; }
    }
    for (p = 0; p < pc; p++) {
        double x[3], nn[3], n0[3], t[3], b[3], total = 0.0;
        int a;
        for (a = 0; a < 3; a++) n0[a] = (double)normals[3 * p + a];
        vx_vf_unit(n0, nn);
        hfvis_visfield_frame(nn, t, b);
        for (a = 0; a < 3; a++) x[a] = (double)points[3 * p + a] + o.offset * nn[a];
        for (r = 0; r < nr && count; r++) {
            const double *l = rays + 3 * r;
            double d[3], occ = 0.0;
            for (a = 0; a < 3; a++) d[a] = l[0] * t[a] + l[1] * b[a] + l[2] * nn[a];
            for (m = 0; m < count; m++) {
                hfvis_visfield_hit h;
                double dw, wgt;
                s = vx_vf_inst_query(in + m, reference, x, d, &h);
                if (s != HFVIS_OK) goto done;
                if (h.result == HFVIS_VISFIELD_MISS) continue;
                dw = in[m].s * h.distance;
                if (!(dw <= maxd)) continue;
                wgt = o.falloff == HFVIS_VISFIELD_FALLOFF_BINARY ? 1.0 : 1.0 - dw / maxd;
                if (wgt < 0.0) wgt = 0.0;
                if (o.combine == HFVIS_VISFIELD_COMBINE_SUBTRACTIVE) {
                    occ += wgt;
                } else if (wgt > occ) {
                    occ = wgt;
                    if (occ >= 1.0) break; /* any object blocks fully */
                }
            }
            total += occ;
        }
        total /= (double)nr;
        if (total > 1.0) total = 1.0;
        if (reference) res[p] = (float)total;
        else out[p] = (float)total;
    }
    if (reference) memcpy(out, res, pc * sizeof(float));
    s = HFVIS_OK;
done:
    vx_free(alloc, res);
    vx_free(alloc, in);
    vx_free(alloc, rays);
    return s;
}

HFVIS_API hfvis_status hfvis_visfield_ambient_occlusion(const hfvis_visfield_object *objects,
                                                        size_t object_count, const float *points,
                                                        const float *normals, size_t point_count,
                                                        const hfvis_visfield_ao_options *opts,
                                                        float *out)
{
    return vx_vf_ao_run(objects, object_count, points, normals, point_count, opts, out, 0);
}

HFVIS_API hfvis_status hfvis_visfield_ambient_occlusion_reference(
    const hfvis_visfield_object *objects, size_t object_count, const float *points,
    const float *normals, size_t point_count, const hfvis_visfield_ao_options *opts, float *out)
{
    return vx_vf_ao_run(objects, object_count, points, normals, point_count, opts, out, 1);
}

/* Van der Corput radical inverse of i in base 2, in [0, 1). */
static double vx_vf_radical2(uint32_t i)
{
    i = (i << 16) | (i >> 16);
    i = ((i & 0x00ff00ffu) << 8) | ((i & 0xff00ff00u) >> 8);
    i = ((i & 0x0f0f0f0fu) << 4) | ((i & 0xf0f0f0f0u) >> 4);
    i = ((i & 0x33333333u) << 2) | ((i & 0xccccccccu) >> 2);
    i = ((i & 0x55555555u) << 1) | ((i & 0xaaaaaaaau) >> 1);
    return (double)i * (1.0 / 4294967296.0);
}

/* Soft-shadow driver (fast or reference). */
static hfvis_status vx_vf_shadow_run(const hfvis_visfield_object *objects, size_t count,
                                     const float *points, size_t pc, const double lc[3],
                                     double lr, const hfvis_visfield_shadow_options *opts,
                                     float *out, int reference)
{
    const hfvis_allocator *alloc = opts ? opts->alloc : NULL;
    int N = opts && opts->samples ? opts->samples : VX_VF_DEFAULT_SHADOW_SAMPLES;
    double bias_frac = vx_vf_bias_frac(opts ? opts->bias : 0.0), *disk = NULL;
    vx_vf_inst *in = NULL;
    float *res = NULL;
    size_t p, m;
    hfvis_status s;
    int i;

    if (N < 1 || N > HFVIS_VISFIELD_MAX_SAMPLES || bias_frac < 0.0 || !vx_vf_point_ok(lc)
        || !isfinite(lr) || lr < 0.0)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (pc && (!points || !out)) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_vf_objects_check(objects, count, reference);
    if (s != HFVIS_OK) return s;
    if (pc && !vx_vf_points_ok(points, NULL, pc)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (pc == 0) return HFVIS_OK;
    disk = (double *)vx_alloc_array(alloc, (size_t)N, 2 * sizeof(double));
    if (!disk) return HFVIS_ERR_OUT_OF_MEMORY;
    for (i = 0; i < N; i++) /* Hammersley points on the light's disc */
        hfvis_concentric_square_to_disk(2.0 * (((double)i + 0.5) / (double)N) - 1.0,
                                        2.0 * vx_vf_radical2((uint32_t)i) - 1.0, disk + 2 * i,
                                        disk + 2 * i + 1);
    s = vx_vf_insts(objects, count, bias_frac, alloc, &in);
    if (s != HFVIS_OK) goto done;
    if (reference) {
        res = (float *)vx_alloc_array(alloc, pc, sizeof(float));
        if (!res) { s = HFVIS_ERR_OUT_OF_MEMORY; goto done; }
    }
    for (p = 0; p < pc; p++) {
        double x[3], v[3], w[3] = {0.0, 0.0, 1.0}, e1[3], e2[3], len;
        int a, lit = 0;
        for (a = 0; a < 3; a++) {
            x[a] = (double)points[3 * p + a];
            v[a] = lc[a] - x[a];
        }
        len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (len > 0.0 && isfinite(len))
            for (a = 0; a < 3; a++) w[a] = v[a] / len;
        hfvis_visfield_frame(w, e1, e2);
        for (i = 0; i < N; i++) {
            double y[3], d[3], L;
            int blocked = 0;
            for (a = 0; a < 3; a++)
                y[a] = lc[a] + lr * (disk[2 * i] * e1[a] + disk[2 * i + 1] * e2[a]);
            for (a = 0; a < 3; a++) d[a] = y[a] - x[a];
            L = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            if (!(L > 0.0) || !isfinite(L)) {
                lit++;
                continue;
            }
            for (a = 0; a < 3; a++) d[a] /= L;
            for (m = 0; m < count && !blocked; m++) {
                hfvis_visfield_hit h;
                s = vx_vf_inst_query(in + m, reference, x, d, &h);
                if (s != HFVIS_OK) goto done;
                blocked = h.result != HFVIS_VISFIELD_MISS && in[m].s * h.distance < L;
            }
            lit += !blocked;
        }
        if (reference) res[p] = (float)((double)lit / (double)N);
        else out[p] = (float)((double)lit / (double)N);
    }
    if (reference) memcpy(out, res, pc * sizeof(float));
    s = HFVIS_OK;
done:
    vx_free(alloc, res);
    vx_free(alloc, in);
    vx_free(alloc, disk);
    return s;
}

HFVIS_API hfvis_status hfvis_visfield_soft_shadow(const hfvis_visfield_object *objects,
                                                  size_t object_count, const float *points,
                                                  size_t point_count,
                                                  const double light_center[3],
                                                  double light_radius,
                                                  const hfvis_visfield_shadow_options *opts,
                                                  float *out)
{
    return vx_vf_shadow_run(objects, object_count, points, point_count, light_center,
                            light_radius, opts, out, 0);
}

HFVIS_API hfvis_status hfvis_visfield_soft_shadow_reference(
    const hfvis_visfield_object *objects, size_t object_count, const float *points,
    size_t point_count, const double light_center[3], double light_radius,
    const hfvis_visfield_shadow_options *opts, float *out)
{
    return vx_vf_shadow_run(objects, object_count, points, point_count, light_center,
                            light_radius, opts, out, 1);
}

/* Nearest object along a world ray (o, d unit) of a validated scene. */
static hfvis_status vx_vf_trace_core(const hfvis_visfield_object *objects, size_t count,
                                     const double o[3], const double d[3], double bias_frac,
                                     int reference, hfvis_visfield_trace_hit *out)
{
    size_t m;
    int a;
    out->object = HFVIS_VISFIELD_NONE;
    out->result = HFVIS_VISFIELD_MISS;
    out->distance = INFINITY;
    for (a = 0; a < 3; a++) out->point[a] = out->normal[a] = 0.0;
    for (m = 0; m < count; m++) {
        vx_vf_inst in;
        hfvis_visfield_hit h;
        double dw;
        hfvis_status s;
        vx_vf_inst_make(objects + m, bias_frac, &in);
        s = vx_vf_inst_query(&in, reference, o, d, &h);
        if (s != HFVIS_OK) return s;
        if (h.result == HFVIS_VISFIELD_MISS) continue;
        dw = in.s * h.distance;
        if (!(dw < out->distance)) continue;
        out->object = m;
        out->result = h.result;
        out->distance = dw;
        for (a = 0; a < 3; a++) {
            out->point[a] = o[a] + dw * d[a];
            out->normal[a] = in.q[a] * h.normal[0] + in.q[3 + a] * h.normal[1]
                             + in.q[6 + a] * h.normal[2];
        }
    }
    return HFVIS_OK;
}

static hfvis_status vx_vf_trace_run(const hfvis_visfield_object *objects, size_t count,
                                    const double origin[3], const double direction[3],
                                    double bias_fraction, hfvis_visfield_trace_hit *hit,
                                    int reference)
{
    double d[3], bf = vx_vf_bias_frac(bias_fraction);
    hfvis_visfield_trace_hit h;
    hfvis_status s;
    if (!vx_vf_point_ok(origin) || !vx_vf_unit(direction, d) || !hit || bf < 0.0)
        return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_vf_objects_check(objects, count, reference);
    if (s != HFVIS_OK) return s;
    s = vx_vf_trace_core(objects, count, origin, d, bf, reference, &h);
    if (s != HFVIS_OK) return s;
    *hit = h;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_visfield_trace(const hfvis_visfield_object *objects,
                                            size_t object_count, const double origin[3],
                                            const double direction[3], double bias_fraction,
                                            hfvis_visfield_trace_hit *hit)
{
    return vx_vf_trace_run(objects, object_count, origin, direction, bias_fraction, hit, 0);
}

HFVIS_API hfvis_status hfvis_visfield_trace_reference(const hfvis_visfield_object *objects,
                                                      size_t object_count,
                                                      const double origin[3],
                                                      const double direction[3],
                                                      double bias_fraction,
                                                      hfvis_visfield_trace_hit *hit)
{
    return vx_vf_trace_run(objects, object_count, origin, direction, bias_fraction, hit, 1);
}

/* Direction of reflection ray i of N about the mirror direction r (frame t, b). */
static void vx_vf_lobe_dir(int i, int N, double shin, const double r[3], const double t[3],
                           const double b[3], double d[3])
{
    int a;
    if (shin > 0.0) {
        double c = pow(((double)i + 0.5) / (double)N, 1.0 / (shin + 1.0));
        double sn = sqrt(c < 1.0 ? 1.0 - c * c : 0.0);
        double ph = 2.0 * VX_PI * vx_vf_radical2((uint32_t)i);
        for (a = 0; a < 3; a++) d[a] = sn * cos(ph) * t[a] + sn * sin(ph) * b[a] + c * r[a];
    } else {
        for (a = 0; a < 3; a++) d[a] = r[a];
    }
}

static hfvis_status vx_vf_reflect_run(const hfvis_visfield_object *objects, size_t count,
                                      const double point[3], const double normal[3],
                                      const double incoming[3],
                                      const hfvis_visfield_reflect_options *opts,
                                      hfvis_visfield_trace_hit *hits, int reference)
{
    int N = opts && opts->rays ? opts->rays : VX_VF_DEFAULT_REFLECT_RAYS, i, a, pass;
    double shin = opts ? opts->shininess : 0.0, off = opts ? opts->offset : 0.0;
    double bf = vx_vf_bias_frac(opts ? opts->bias : 0.0), n[3], v[3], r[3], t[3], b[3], x[3], vn;
    hfvis_status s;
    if (N < 1 || N > HFVIS_VISFIELD_MAX_SAMPLES || !isfinite(shin) || shin < 0.0 || bf < 0.0
        || !isfinite(off) || off < 0.0 || !vx_vf_point_ok(point) || !vx_vf_unit(normal, n)
        || !vx_vf_unit(incoming, v) || !hits)
        return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_vf_objects_check(objects, count, reference);
    if (s != HFVIS_OK) return s;
    vn = v[0] * n[0] + v[1] * n[1] + v[2] * n[2];
    for (a = 0; a < 3; a++) {
        r[a] = v[a] - 2.0 * vn * n[a];
        x[a] = point[a] + off * n[a];
    }
    if (!vx_vf_unit(r, r)) return HFVIS_ERR_INVALID_ARGUMENT;
    hfvis_visfield_frame(r, t, b);
    /* The reference's ray queries can fail (a corrupt bvh): it traces every ray once before
     * writing anything, so that hits stay untouched on error. */
    for (pass = reference ? 0 : 1; pass < 2; pass++)
        for (i = 0; i < N; i++) {
            double d[3];
            hfvis_visfield_trace_hit h;
            vx_vf_lobe_dir(i, N, shin, r, t, b, d);
            if (!(d[0] * n[0] + d[1] * n[1] + d[2] * n[2] > 0.0)) { /* below the surface */
                h.object = HFVIS_VISFIELD_NONE;
                h.result = HFVIS_VISFIELD_MISS;
                h.distance = INFINITY;
                for (a = 0; a < 3; a++) h.point[a] = h.normal[a] = 0.0;
            } else {
                s = vx_vf_trace_core(objects, count, x, d, bf, reference, &h);
                if (s != HFVIS_OK) return s;
            }
            if (pass == 1) hits[i] = h;
        }
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_visfield_reflect(const hfvis_visfield_object *objects,
                                              size_t object_count, const double point[3],
                                              const double normal[3], const double incoming[3],
                                              const hfvis_visfield_reflect_options *opts,
                                              hfvis_visfield_trace_hit *hits)
{
    return vx_vf_reflect_run(objects, object_count, point, normal, incoming, opts, hits, 0);
}

HFVIS_API hfvis_status hfvis_visfield_reflect_reference(const hfvis_visfield_object *objects,
                                                        size_t object_count,
                                                        const double point[3],
                                                        const double normal[3],
                                                        const double incoming[3],
                                                        const hfvis_visfield_reflect_options *opts,
                                                        hfvis_visfield_trace_hit *hits)
{
    return vx_vf_reflect_run(objects, object_count, point, normal, incoming, opts, hits, 1);
}

/* ---- vf-g. the field file ---------------------------------------------------------------- */

static const unsigned char vx_vf_magic[8] = {'H', 'F', 'V', 'F', 'I', 'E', 'L', 'D'};

static void vx_vf_put32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)(v & 0xffu);
    p[1] = (unsigned char)((v >> 8) & 0xffu);
    p[2] = (unsigned char)((v >> 16) & 0xffu);
    p[3] = (unsigned char)((v >> 24) & 0xffu);
}

static void vx_vf_put64(unsigned char *p, uint64_t v)
{
    vx_vf_put32(p, (uint32_t)(v & 0xffffffffu));
    vx_vf_put32(p + 4, (uint32_t)(v >> 32));
}

static void vx_vf_putf64(unsigned char *p, double d)
{
    uint64_t v;
    memcpy(&v, &d, 8);
    vx_vf_put64(p, v);
}

static uint32_t vx_vf_get32(const unsigned char *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

static uint64_t vx_vf_get64(const unsigned char *p)
{
    return (uint64_t)vx_vf_get32(p) | ((uint64_t)vx_vf_get32(p + 4) << 32);
}

static double vx_vf_getf64(const unsigned char *p)
{
    uint64_t v = vx_vf_get64(p);
    double d;
    memcpy(&d, &v, 8);
    return d;
}

HFVIS_API size_t hfvis_visfield_encode_size(const hfvis_visfield *vf)
{
    size_t need;
    if (!vx_vf_valid(vf)) return 0;
    need = hfvis_visfield_size(vf->positions_n, vf->dir_res, vf->format);
    if (need > SIZE_MAX - HFVIS_VISFIELD_FILE_HEADER) return 0;
    return need + HFVIS_VISFIELD_FILE_HEADER;
}

HFVIS_API hfvis_status hfvis_visfield_encode(const hfvis_visfield *vf, void *out,
                                             size_t out_capacity, size_t *written)
{
    unsigned char *p = (unsigned char *)out;
    const unsigned char *src;
    size_t total = hfvis_visfield_encode_size(vf), payload, i;
    hfvis_visfield_format f;
    if (!vf || !out || total == 0) return HFVIS_ERR_INVALID_ARGUMENT;
    if (out_capacity < total) return HFVIS_ERR_BUFFER_TOO_SMALL;
    payload = total - HFVIS_VISFIELD_FILE_HEADER;
    f = vx_vf_format(vf->format);
    memcpy(p, vx_vf_magic, 8);
    vx_vf_put32(p + 8, 1u);
    vx_vf_put32(p + 12, (uint32_t)f);
    vx_vf_put32(p + 16, (uint32_t)vx_vf_mapping(vf->mapping));
    vx_vf_put32(p + 20, (uint32_t)vf->positions_n);
    vx_vf_put32(p + 24, (uint32_t)vf->dir_res);
    vx_vf_put32(p + 28, 0u);
    vx_vf_putf64(p + 32, vf->center[0]);
    vx_vf_putf64(p + 40, vf->center[1]);
    vx_vf_putf64(p + 48, vf->center[2]);
    vx_vf_putf64(p + 56, vf->radius);
    vx_vf_putf64(p + 64, vf->avg_distance);
    vx_vf_put64(p + 72, (uint64_t)payload);
    p += HFVIS_VISFIELD_FILE_HEADER;
    src = (const unsigned char *)vf->maps;
    if (f == HFVIS_VISFIELD_F32) {
        for (i = 0; i < payload; i += 4) {
            uint32_t v;
            memcpy(&v, src + i, 4);
            vx_vf_put32(p + i, v);
        }
    } else {
        memcpy(p, src, payload);
    }
    if (written) *written = total;
    return HFVIS_OK;
}

/* Payload contents a build can produce (file byte order for F32). */
static int vx_vf_payload_ok(const unsigned char *pl, hfvis_visfield_format f, hfvis_dirmap m,
                            int n, int D, size_t bytes)
{
    const size_t K = 2u * vx_vf_hemi(n), DD = (size_t)D * (size_t)D, texels = K * DD;
    size_t t, k;
    int i, j;
    if (f == HFVIS_VISFIELD_F32) {
        for (t = 0; t < texels; t++) {
            uint32_t v = vx_vf_get32(pl + 4 * t);
            float x;
            memcpy(&x, &v, 4);
            if (!(x >= 0.0f && x <= 1.0f)) return 0; /* NaN, negative, > 1 */
        }
    } else if (f == HFVIS_VISFIELD_NORMAL) {
        for (t = 0; t < texels; t++) {
            const unsigned char *q = pl + 4 * t;
            if (q[3] == HFVIS_VISFIELD_U8_MISS && (q[0] | q[1] | q[2]) != 0) return 0;
        }
    } else if (f == HFVIS_VISFIELD_BIT && (texels & 7u) != 0) {
        if (pl[bytes - 1] >> (texels & 7u)) return 0; /* padding bits */
    }
    if (m != HFVIS_DIRMAP_REJECTION) return 1;
    for (j = 0; j < D; j++)
        for (i = 0; i < D; i++) {
            double A = vx_vf_sq(i, D), B = vx_vf_sq(j, D);
            if (A * A + B * B <= 1.0) continue;
            for (k = 0; k < K; k++) {
                size_t tt = k * DD + (size_t)j * (size_t)D + (size_t)i;
                int miss;
                switch (f) {
                case HFVIS_VISFIELD_F32: miss = vx_vf_get32(pl + 4 * tt) == 0x3f800000u; break;
                case HFVIS_VISFIELD_BIT: miss = !((pl[tt >> 3] >> (tt & 7u)) & 1u); break;
                case HFVIS_VISFIELD_NORMAL: miss = pl[4 * tt + 3] == HFVIS_VISFIELD_U8_MISS; break;
                default: miss = pl[tt] == HFVIS_VISFIELD_U8_MISS; break;
                }
                if (!miss) return 0;
            }
        }
    return 1;
}

HFVIS_API hfvis_status hfvis_visfield_decode(const void *data, size_t size,
                                             const hfvis_allocator *alloc, hfvis_visfield *out)
{
    const unsigned char *p = (const unsigned char *)data;
    uint32_t version, fmt, map, n, D;
    uint64_t payload, want;
    hfvis_visfield vf;
    unsigned char *maps;
    size_t i;
    if (!out || (!data && size > 0)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (size < HFVIS_VISFIELD_FILE_HEADER || memcmp(p, vx_vf_magic, 8) != 0)
        return HFVIS_ERR_FORMAT;
    version = vx_vf_get32(p + 8);
    fmt = vx_vf_get32(p + 12);
    map = vx_vf_get32(p + 16);
    n = vx_vf_get32(p + 20);
    D = vx_vf_get32(p + 24);
    if (version != 1u || vx_vf_get32(p + 28) != 0u || fmt < 1u || fmt > 4u || map < 1u || map > 3u
        || n == 0u || D == 0u)
        return HFVIS_ERR_FORMAT;
    if (n > (uint32_t)HFVIS_VISFIELD_MAX_N || D > (uint32_t)HFVIS_VISFIELD_MAX_DIR_RES)
        return HFVIS_ERR_LIMIT;
    want = vx_vf_size64((int)n, (int)D, (hfvis_visfield_format)fmt);
    if (want > HFVIS_VISFIELD_MAX_BYTES || want > (uint64_t)SIZE_MAX - HFVIS_VISFIELD_FILE_HEADER)
        return HFVIS_ERR_LIMIT;
    payload = vx_vf_get64(p + 72);
    if (payload != want || (uint64_t)(size - HFVIS_VISFIELD_FILE_HEADER) != want)
        return HFVIS_ERR_FORMAT;
    memset(&vf, 0, sizeof vf);
    vf.center[0] = vx_vf_getf64(p + 32);
    vf.center[1] = vx_vf_getf64(p + 40);
    vf.center[2] = vx_vf_getf64(p + 48);
    vf.radius = vx_vf_getf64(p + 56);
    vf.avg_distance = vx_vf_getf64(p + 64);
    vf.positions_n = (int)n;
    vf.dir_res = (int)D;
    vf.format = (hfvis_visfield_format)fmt;
    vf.mapping = (hfvis_dirmap)map;
    if (!vx_vf_params_ok(&vf)) return HFVIS_ERR_FORMAT;
    p += HFVIS_VISFIELD_FILE_HEADER;
    if (!vx_vf_payload_ok(p, vf.format, vf.mapping, vf.positions_n, vf.dir_res, (size_t)want))
        return HFVIS_ERR_FORMAT;
    maps = (unsigned char *)vx_alloc(alloc, (size_t)want);
    if (!maps) return HFVIS_ERR_OUT_OF_MEMORY;
    if (vf.format == HFVIS_VISFIELD_F32) {
        for (i = 0; i < (size_t)want; i += 4) {
            uint32_t v = vx_vf_get32(p + i);
            memcpy(maps + i, &v, 4);
        }
    } else {
        memcpy(maps, p, (size_t)want);
    }
    vf.maps = maps;
    vf.maps_size = (size_t)want;
    *out = vf;
    return HFVIS_OK;
}

HFVIS_API void hfvis_visfield_free(const hfvis_allocator *alloc, hfvis_visfield *vf)
{
    if (!vf) return;
    vx_free(alloc, vf->maps);
    memset(vf, 0, sizeof *vf);
}

#ifndef HFVIS_NO_STDIO
HFVIS_API hfvis_status hfvis_visfield_save(const char *path, const hfvis_visfield *vf)
{
    size_t need = hfvis_visfield_encode_size(vf), written = 0;
    unsigned char *buf;
    hfvis_status s;
    if (!path || need == 0) return HFVIS_ERR_INVALID_ARGUMENT;
    buf = (unsigned char *)malloc(need);
    if (!buf) return HFVIS_ERR_OUT_OF_MEMORY;
    s = hfvis_visfield_encode(vf, buf, need, &written);
    if (s == HFVIS_OK) s = hfvis__write_file(path, buf, written);
    free(buf);
    return s;
}

HFVIS_API hfvis_status hfvis_visfield_load(const char *path, const hfvis_allocator *alloc,
                                           hfvis_visfield *out)
{
    unsigned char *data = NULL;
    size_t size = 0;
    hfvis_status s;
    if (!path || !out) return HFVIS_ERR_INVALID_ARGUMENT;
    s = hfvis__read_file(path, alloc, &data, &size);
    if (s != HFVIS_OK) return s;
    s = hfvis_visfield_decode(data, size, alloc, out);
    vx_free(alloc, data);
    return s;
}
#endif
