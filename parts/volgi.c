
/* ========================================================================================== */
/* Volume-based VPL indirect illumination ([G12] ch. 5, "Interactive Volume-based Indirect     */
/* Illumination of Dynamic Scenes": Alg. 4, eqs. 7, 11-15; spec voxel §2)                     */
/*   GI.1 2-band SH: basis, clamped cosine, cone (spec §2.2)                                  */
/*   GI.2 options, transport constants, validation                                           */
/*   GI.3 VPL injection ([G12] §5.5.1, spec §2.4)                                             */
/*   GI.4 one propagation step (eq. 11 with the reference kernel of spec §2.5): the fast      */
/*        gathering kernel, the literal reference, the energy accounting                     */
/*   GI.5 the propagation loop (multiple bounces, §5.5.2 / §5.6)                               */
/*   GI.6 final gather (eqs. 12-15, spec §2.6)                                                */
/*   GI.7 lights and direct irradiance with BVH shadow rays                                   */
/*   GI.8 voxelization with direct light (Alg. 4) and the room grid                           */
/*   GI.9 the whole pipeline for a view                                                       */
/* Every choice the thesis leaves open is marked [C] and listed in hfvis.h.                   */
/* ========================================================================================== */

#define VX_GI_F 12 /* HFVIS_VOLGI_FLOATS */

/* The per-voxel tail of the fast kernel is forced inline: called out of line, its vector loads
 * of the just-stored accumulators miss store-to-load forwarding (a 2x slowdown measured). */
#if defined(__GNUC__)
#define VX_GI_INLINE static inline __attribute__((always_inline))
#else
#define VX_GI_INLINE static
#endif

/* ---- GI.1 2-band SH (DESIGN: real, orthonormal, no Condon-Shortley phase, index l(l+1)+m:
 *      0 = Y00, 1 = y, 2 = z, 3 = x) ------------------------------------------------------ */

/* u = d/|d| (scaled first, so no intermediate overflows); 0 for NULL, non-finite or zero d. */
static int vx_gi_unit(const double *d, double u[3])
{
    double m, x, y, z, l;
    if (!d || !isfinite(d[0]) || !isfinite(d[1]) || !isfinite(d[2])) return 0;
    m = fabs(d[0]);
    if (fabs(d[1]) > m) m = fabs(d[1]);
    if (fabs(d[2]) > m) m = fabs(d[2]);
    if (!(m > 0.0)) return 0;
    x = d[0] / m, y = d[1] / m, z = d[2] / m;
    l = sqrt(x * x + y * y + z * z);
    u[0] = x / l, u[1] = y / l, u[2] = z / l;
    return 1;
}

/* The band-1 coefficient of axis a (x -> 3, y -> 1, z -> 2). */
static const int vx_gi_band1[3] = { 3, 1, 2 };

HFVIS_API hfvis_status hfvis_volgi_sh_basis(const double dir[3], double out[4])
{
    double u[3], k;
    if (!out || !vx_gi_unit(dir, u)) return HFVIS_ERR_INVALID_ARGUMENT;
    k = sqrt(3.0 / (4.0 * VX_PI));
    out[0] = 0.5 / sqrt(VX_PI);
    out[1] = k * u[1], out[2] = k * u[2], out[3] = k * u[0];
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_volgi_sh_clamped_cosine(const double normal[3], double out[4])
{
    double u[3], k;
    if (!out || !vx_gi_unit(normal, u)) return HFVIS_ERR_INVALID_ARGUMENT;
    /* Int max(0, n.w) Y00 = pi/(2 sqrt pi); Int max(0, n.w) 0.4886 (n.w) = 0.4886 * 2 pi/3 */
    k = sqrt(VX_PI / 3.0);
    out[0] = 0.5 * sqrt(VX_PI);
    out[1] = k * u[1], out[2] = k * u[2], out[3] = k * u[0];
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_volgi_sh_cone(const double axis[3], double half_angle_rad,
                                           double out[4])
{
    double u[3], k, s;
    if (!out || !vx_gi_unit(axis, u) || !isfinite(half_angle_rad) || !(half_angle_rad > 0.0)
        || half_angle_rad > VX_PI)
        return HFVIS_ERR_INVALID_ARGUMENT;
    /* Int_cone Y00 = 2 pi (1 - cos a)/(2 sqrt pi); Int_cone 0.4886 cos t = 0.4886 pi sin^2 a */
    s = sin(half_angle_rad);
    k = 0.5 * sqrt(3.0 * VX_PI) * (s * s);
    out[0] = sqrt(VX_PI) * (1.0 - cos(half_angle_rad));
    out[1] = k * u[1], out[2] = k * u[2], out[3] = k * u[0];
    return HFVIS_OK;
}

/* ---- GI.2 options, constants, validation ------------------------------------------------ */

HFVIS_API hfvis_volgi_options hfvis_volgi_options_default(void)
{
    hfvis_volgi_options o;
    memset(&o, 0, sizeof o);
    o.iterations = HFVIS_VOLGI_DEFAULT_ITERATIONS;
    o.resolution = HFVIS_VOLGI_DEFAULT_RESOLUTION;
    o.transfer = HFVIS_VOLGI_TRANSFER_CONE;
    o.reflection = HFVIS_VOLGI_REFLECT_MIRROR;
    o.paths = HFVIS_VOLGI_PATHS_ALL;
    o.reflectance_source = HFVIS_VOLGI_REFLECTANCE_THESIS;
    o.reflectance = (float)HFVIS_VOLGI_DEFAULT_REFLECTANCE;
    o.gather_scale = HFVIS_VOLGI_DEFAULT_GATHER_SCALE;
    o.shadow_bias = 0.0;
    return o;
}

/* Resolved options. */
typedef struct vx_gi_cfg {
    const hfvis_allocator *alloc;
    int iterations, resolution;
    hfvis_volgi_transfer transfer;
    hfvis_volgi_reflection reflection;
    hfvis_volgi_reflectance rsrc;
    hfvis_volgi_paths paths;
    double rho;           /* the constant reflectance (THESIS or CONSTANT) */
    double gather_scale;
    double shadow_bias;   /* 0: relative to the scene */
} vx_gi_cfg;

static hfvis_status vx_gi_resolve(const hfvis_volgi_options *o, vx_gi_cfg *c)
{
    hfvis_volgi_options d = hfvis_volgi_options_default();
    if (!o) o = &d;
    memset(c, 0, sizeof *c);
    c->alloc = o->alloc;
    c->iterations = o->iterations == 0 ? HFVIS_VOLGI_DEFAULT_ITERATIONS : o->iterations;
    c->resolution = o->resolution == 0 ? HFVIS_VOLGI_DEFAULT_RESOLUTION : o->resolution;
    if (c->iterations < 1 || c->iterations > HFVIS_VOLGI_MAX_ITERATIONS || c->resolution < 2
        || c->resolution > HFVIS_VOLGI_MAX_RESOLUTION)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o->transfer != HFVIS_VOLGI_TRANSFER_CONE && o->transfer != HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o->reflection != HFVIS_VOLGI_REFLECT_MIRROR && o->reflection != HFVIS_VOLGI_REFLECT_DIFFUSE)
        return HFVIS_ERR_INVALID_ARGUMENT;
    if (o->paths != HFVIS_VOLGI_PATHS_ALL && o->paths != HFVIS_VOLGI_PATHS_VOID)
        return HFVIS_ERR_INVALID_ARGUMENT;
    c->transfer = o->transfer;
    c->reflection = o->reflection;
    c->paths = o->paths;
    c->rsrc = o->reflectance_source;
    switch (o->reflectance_source) {
    case HFVIS_VOLGI_REFLECTANCE_THESIS: c->rho = HFVIS_VOLGI_DEFAULT_REFLECTANCE; break;
    case HFVIS_VOLGI_REFLECTANCE_CONSTANT:
        if (!(o->reflectance >= 0.0f && o->reflectance <= 1.0f)) return HFVIS_ERR_INVALID_ARGUMENT;
        c->rho = (double)o->reflectance;
        break;
    case HFVIS_VOLGI_REFLECTANCE_ALBEDO: c->rho = 0.0; break;
    default: return HFVIS_ERR_INVALID_ARGUMENT;
    }
    if (!isfinite(o->gather_scale) || o->gather_scale < 0.0) return HFVIS_ERR_INVALID_ARGUMENT;
    c->gather_scale = o->gather_scale == 0.0 ? HFVIS_VOLGI_DEFAULT_GATHER_SCALE : o->gather_scale;
    if (!isfinite(o->shadow_bias) || o->shadow_bias < 0.0) return HFVIS_ERR_INVALID_ARGUMENT;
    c->shadow_bias = o->shadow_bias;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_volgi_options_resolve(const hfvis_volgi_options *opts,
                                                   hfvis_volgi_options *out)
{
    vx_gi_cfg c;
    hfvis_volgi_options r;
    hfvis_status s;
    if (!out) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_gi_resolve(opts, &c);
    if (s != HFVIS_OK) return s;
    memset(&r, 0, sizeof r);
    r.alloc = c.alloc;
    r.iterations = c.iterations;
    r.resolution = c.resolution;
    r.transfer = c.transfer;
    r.reflection = c.reflection;
    r.reflectance_source = c.rsrc;
    r.paths = c.paths;
    r.reflectance = c.rsrc == HFVIS_VOLGI_REFLECTANCE_ALBEDO ? (opts ? opts->reflectance : 0.0f) : (float)c.rho;
    r.gather_scale = c.gather_scale;
    r.shadow_bias = c.shadow_bias;
    *out = r;
    return HFVIS_OK;
}

/* The transport constants, for the six travel directions o in the order +x, -x, +y, -y, +z, -z:
 * Cone45(o) and CC(o) as 4-vectors (from the public helpers, so that the fast kernel and the
 * reference use the same bits), and the sparse form the fast kernel uses. */
typedef struct vx_gi_consts {
    double cone[6][4], cc[6][4];
    double a;             /* cone[d][0], sqrt(pi)(1 - cos 45) */
    double sb[6], sc[6];  /* cone[d][band1 of d's axis], cc[d][same]: +-b, +-sqrt(pi/3) */
    double c0;            /* cc[d][0], sqrt(pi)/2 */
    double ccpi[6][4];    /* cc[d][k]/pi: S_in += F ccpi[o] is eq. 11's re-expansion (F/pi) CC(o) */
    double k0, k1[6];     /* ccpi[d][0], ccpi[d][band1 of d's axis] */
    double lobe;          /* c1/c0 of a cosine lobe: 2/sqrt 3 */
    double flux;          /* 2 sqrt(pi): flux of a band = flux * c_0 */
} vx_gi_consts;

static void vx_gi_consts_init(vx_gi_consts *k)
{
    int d;
    for (d = 0; d < 6; d++) {
        double e[3] = { 0.0, 0.0, 0.0 };
        int ax = d / 2;
        e[ax] = (d & 1) ? -1.0 : 1.0;
        (void)hfvis_volgi_sh_cone(e, 0.25 * VX_PI, k->cone[d]);
        (void)hfvis_volgi_sh_clamped_cosine(e, k->cc[d]);
        k->sb[d] = k->cone[d][vx_gi_band1[ax]];
        k->sc[d] = k->cc[d][vx_gi_band1[ax]];
    }
    for (d = 0; d < 6; d++) {
        int q;
        for (q = 0; q < 4; q++) k->ccpi[d][q] = k->cc[d][q] / VX_PI;
        k->k1[d] = k->ccpi[d][vx_gi_band1[d / 2]];
    }
    k->a = k->cone[0][0];
    k->c0 = k->cc[0][0];
    k->k0 = k->ccpi[0][0];
    k->lobe = k->cc[0][3] / k->cc[0][0];
    k->flux = 2.0 * sqrt(VX_PI);
}

/* Voxel count of a valid grid, or 0 when an SH volume of it would overflow size_t. */
static size_t vx_gi_voxels(const hfvis_volume_grid *g)
{
    size_t n = vx_grid_voxels(g), bytes;
    if (!vx_mul_size(n, (size_t)VX_GI_F * sizeof(double), &bytes)) return 0;
    return n;
}

/* Validate a geometry volume (O(voxels)); *n receives the voxel count. */
static hfvis_status vx_gi_geometry_check(const hfvis_volgi_geometry *g, size_t *n)
{
    size_t i, m;
    if (!g || !g->occupancy || !g->normal || !vx_grid_valid(&g->grid)) return HFVIS_ERR_INVALID_ARGUMENT;
    m = vx_gi_voxels(&g->grid);
    if (m == 0) return HFVIS_ERR_LIMIT;
    for (i = 0; i < m; i++) {
        float a = g->occupancy[i];
        if (!(a >= 0.0f && a <= 1.0f)) return HFVIS_ERR_INVALID_ARGUMENT;
    }
    for (i = 0; i < 3 * m; i++)
        if (!isfinite(g->normal[i])) return HFVIS_ERR_INVALID_ARGUMENT;
    if (g->albedo)
        for (i = 0; i < 3 * m; i++)
            if (!(g->albedo[i] >= 0.0f && g->albedo[i] <= 1.0f)) return HFVIS_ERR_INVALID_ARGUMENT;
    *n = m;
    return HFVIS_OK;
}

/* Every value finite with |v| <= HFVIS_VOLGI_MAX_VALUE. */
static int vx_gi_values_ok(const float *v, size_t count)
{
    size_t i;
    for (i = 0; i < count; i++)
        if (!(fabsf(v[i]) <= HFVIS_VOLGI_MAX_VALUE)) return 0;
    return 1;
}

/* ---- GI.3 VPL injection ----------------------------------------------------------------- */

/* Dominant axis of a vector (largest |component|, ties to the lower axis); -1 when it is 0. */
static int vx_gi_dominant(double x, double y, double z)
{
    double ax = fabs(x), ay = fabs(y), az = fabs(z);
    if (ax == 0.0 && ay == 0.0 && az == 0.0) return -1;
    if (ax >= ay && ax >= az) return 0;
    return ay >= az ? 1 : 2;
}

/* Area of the grid face perpendicular to axis a (s^2 for cubic voxels). */
static double vx_gi_face(const hfvis_volume_grid *g, int a)
{
    return g->cell[(a + 1) % 3] * g->cell[(a + 2) % 3];
}

HFVIS_API hfvis_status hfvis_volgi_inject(const hfvis_volgi_geometry *geometry,
                                          const float *radiance, float *prop)
{
    vx_gi_consts K;
    size_t n, v;
    hfvis_status s;
    if (!geometry || !radiance || !prop) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_gi_geometry_check(geometry, &n);
    if (s != HFVIS_OK) return s;
    for (v = 0; v < 3 * n; v++)
        if (!(radiance[v] >= 0.0f && radiance[v] <= HFVIS_VOLGI_MAX_VALUE))
            return HFVIS_ERR_INVALID_ARGUMENT;
    vx_gi_consts_init(&K);
    for (v = 0; v < n; v++) {
        float *p = prop + v * VX_GI_F;
        const float *nv = geometry->normal + 3 * v;
        double u[3], cc[4] = { 0.0, 0.0, 0.0, 0.0 }, area;
        int b, k, ax;
        for (k = 0; k < VX_GI_F; k++) p[k] = 0.0f;
        if (!(geometry->occupancy[v] > 0.0f)) continue;
        ax = vx_gi_dominant((double)nv[0], (double)nv[1], (double)nv[2]);
        if (ax >= 0) {
            double nd[3];
            nd[0] = (double)nv[0], nd[1] = (double)nv[1], nd[2] = (double)nv[2];
            (void)vx_gi_unit(nd, u);
            (void)hfvis_volgi_sh_clamped_cosine(u, cc);
            area = vx_gi_face(&geometry->grid, ax);
        } else { /* no normal: the isotropic lobe of the same flux, c_0 = CC's c_0 [C] */
            cc[0] = K.c0;
            area = pow(geometry->grid.cell[0] * geometry->grid.cell[1] * geometry->grid.cell[2],
                       2.0 / 3.0);
        }
        /* P0 = (Phi/pi) CC(n), Phi = pi L s^2 (spec §2.4 [C]) */
        for (b = 0; b < 3; b++) {
            double q = (double)radiance[3 * v + (size_t)b] * area;
            for (k = 0; k < 4; k++) p[4 * b + k] = (float)(q * cc[k]);
        }
    }
    return HFVIS_OK;
}

/* ---- GI.4 one propagation step ---------------------------------------------------------- */

typedef struct vx_gi_step {
    const hfvis_volgi_geometry *g;
    vx_gi_cfg cfg;
    vx_gi_consts K;
    const float *pin;
    float *pout, *acc;
    const double *scale;          /* normalised transfer: Phi_j / sum_o F_o(j) per voxel and band */
    hfvis_volgi_energy *en;       /* NULL: no accounting */
    int dims[3];
    size_t stride[3];             /* voxel strides along x, y, z */
} vx_gi_step;

/* The clamped cone flux of band b of the SH voxel q toward direction d (sparse form: the zero
 * coefficients of Cone(o) are left out; equal to the full 4-term product whenever it is > 0). */
static double vx_gi_cone_flux(const vx_gi_consts *K, const float *q, int d)
{
    double F = K->a * (double)q[0] + K->sb[d] * (double)q[vx_gi_band1[d / 2]];
    return F > 0.0 ? F : 0.0;
}

/* 1 when the neighbour of voxel ijk in (travel) direction d exists. */
static int vx_gi_has(const int dims[3], const int ijk[3], int d)
{
    int ax = d / 2;
    return (d & 1) ? ijk[ax] > 0 : ijk[ax] + 1 < dims[ax];
}

/* Linear index of the (existing) neighbour of voxel v in direction d. */
static size_t vx_gi_nb(const vx_gi_step *c, size_t v, int d)
{
    return (d & 1) ? v - c->stride[d / 2] : v + c->stride[d / 2];
}

/* Path weight of a transfer from voxel jl to its face neighbour il: 1 (HFVIS_VOLGI_PATHS_ALL),
 * or 1 - alpha_j alpha_i (HFVIS_VOLGI_PATHS_VOID: no light between two occupied voxels). */
static double vx_gi_path(const vx_gi_step *c, size_t jl, size_t il)
{
    if (c->cfg.paths == HFVIS_VOLGI_PATHS_ALL) return 1.0;
    return 1.0 - (double)c->g->occupancy[jl] * (double)c->g->occupancy[il];
}

/* Normalised transfer: Phi / sum_o F_o w_o for band b of voxel v at ijk (clamped cone fluxes
 * times path weights, summed in the order o = 0..5; leaving the grid has weight 1), or 0 when
 * either is <= 0. */
static double vx_gi_norm_scale(const vx_gi_step *c, size_t v, const int ijk[3], int b)
{
    const float *q = c->pin + v * VX_GI_F + 4 * b;
    double sum = 0.0, phi = c->K.flux * (double)q[0];
    int d;
    for (d = 0; d < 6; d++) {
        double F = vx_gi_cone_flux(&c->K, q, d);
        if (vx_gi_has(c->dims, ijk, d)) F *= vx_gi_path(c, v, vx_gi_nb(c, v, d));
        sum += F;
    }
    return phi > 0.0 && sum > 0.0 ? phi / sum : 0.0;
}

/* The table of vx_gi_norm_scale for every voxel and band (the fast step's normalisation); the
 * same products and sums, with the six path weights computed once per voxel. */
static void vx_gi_scale_pass(const vx_gi_step *c, double *scale)
{
    int ijk[3], b, d;
    size_t v = 0;
    for (ijk[2] = 0; ijk[2] < c->dims[2]; ijk[2]++)
        for (ijk[1] = 0; ijk[1] < c->dims[1]; ijk[1]++)
            for (ijk[0] = 0; ijk[0] < c->dims[0]; ijk[0]++, v++) {
                double w[6];
                for (d = 0; d < 6; d++)
                    w[d] = vx_gi_has(c->dims, ijk, d) ? vx_gi_path(c, v, vx_gi_nb(c, v, d)) : 1.0;
                for (b = 0; b < 3; b++) {
                    const float *q = c->pin + v * VX_GI_F + 4 * b;
                    double sum = 0.0, phi = c->K.flux * (double)q[0];
                    for (d = 0; d < 6; d++) sum += vx_gi_cone_flux(&c->K, q, d) * w[d];
                    scale[3 * v + (size_t)b] = phi > 0.0 && sum > 0.0 ? phi / sum : 0.0;
                }
            }
}

/* The source side of the energy accounting (start, escaped, blocked, uncovered, created), shared
 * by the fast step and the reference: per voxel and band what it sends, what leaves the grid and
 * what the path weights hold back. */
static void vx_gi_energy_sources(const vx_gi_step *c)
{
    hfvis_volgi_energy *e = c->en;
    const int norm = c->cfg.transfer == HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED;
    int ijk[3], b, d;
    size_t v = 0;
    for (ijk[2] = 0; ijk[2] < c->dims[2]; ijk[2]++)
        for (ijk[1] = 0; ijk[1] < c->dims[1]; ijk[1]++)
            for (ijk[0] = 0; ijk[0] < c->dims[0]; ijk[0]++, v++)
                for (b = 0; b < 3; b++) {
                    const float *q = c->pin + v * VX_GI_F + 4 * b;
                    double phi = c->K.flux * (double)q[0], sent = 0.0, esc = 0.0, blk = 0.0;
                    double sc = norm ? vx_gi_norm_scale(c, v, ijk, b) : 1.0;
                    for (d = 0; d < 6; d++) {
                        double F = vx_gi_cone_flux(&c->K, q, d) * sc, w = 1.0;
                        if (vx_gi_has(c->dims, ijk, d)) w = vx_gi_path(c, v, vx_gi_nb(c, v, d));
                        else esc += F;
                        sent += F * w;
                        blk += F * (1.0 - w);
                    }
                    if (norm && phi > 0.0) { /* exact in real arithmetic: all or nothing */
                        if (sc > 0.0) sent = phi, blk = 0.0;
                        else sent = 0.0, blk = phi, esc = 0.0;
                    }
                    e->start[b] += phi;
                    e->escaped[b] += esc;
                    e->blocked[b] += blk;
                    if (phi > sent + blk) e->uncovered[b] += phi - sent - blk;
                    else e->created[b] += sent + blk - phi;
                }
}

/* R(S_in) of one band (the thesis' T_r, or the diffuse alternative), into r. */
VX_GI_INLINE void vx_gi_reflect(const vx_gi_step *c, const float *nv, const double *s, double r[4])
{
    int k, ax = vx_gi_dominant((double)nv[0], (double)nv[1], (double)nv[2]);
    if (c->cfg.reflection == HFVIS_VOLGI_REFLECT_MIRROR) {
        for (k = 0; k < 4; k++) r[k] = s[k];
        if (ax >= 0) {
            r[vx_gi_band1[ax]] = -s[vx_gi_band1[ax]]; /* mirror on the plane perpendicular to ax */
        } else {
            r[1] = -s[1], r[2] = -s[2], r[3] = -s[3]; /* no normal: back where it came from [C] */
        }
        return;
    }
    /* diffuse: c_0 kept (the flux), the band-1 part (2/sqrt 3) c_0 along +-n [C] */
    r[0] = s[0];
    r[1] = r[2] = r[3] = 0.0;
    if (ax >= 0) {
        double nd[3], u[3], side, g;
        nd[0] = (double)nv[0], nd[1] = (double)nv[1], nd[2] = (double)nv[2];
        (void)vx_gi_unit(nd, u);
        side = s[3] * u[0] + s[1] * u[1] + s[2] * u[2]; /* > 0: travelling along +n, from behind */
        g = (side > 0.0 ? -1.0 : 1.0) * (s[0] * c->K.lobe);
        r[1] = g * u[1], r[2] = g * u[2], r[3] = g * u[0];
    }
}

/* The receiving side of voxel lin, shared by the fast step and the reference: record and
 * reflect at occupied voxels (T_r), transmit through empty ones; energy end/absorbed/deposited. */
VX_GI_INLINE void vx_gi_finish(const vx_gi_step *c, size_t lin, const double s[VX_GI_F])
{
    float *po = c->pout + lin * VX_GI_F;
    double alpha = (double)c->g->occupancy[lin];
    int b, k;
    if (alpha == 0.0) { /* void: T_r = 1 */
        for (k = 0; k < VX_GI_F; k++) po[k] = (float)s[k];
    } else {
        float *pa = c->acc + lin * VX_GI_F;
        const float *nv = c->g->normal + 3 * lin;
        for (k = 0; k < VX_GI_F; k++) pa[k] = (float)((double)pa[k] + alpha * s[k]);
        for (b = 0; b < 3; b++) {
            double r[4], rho = c->cfg.rsrc == HFVIS_VOLGI_REFLECTANCE_ALBEDO
                                   ? (double)c->g->albedo[3 * lin + (size_t)b] : c->cfg.rho;
            vx_gi_reflect(c, nv, s + 4 * b, r);
            for (k = 0; k < 4; k++)
                po[4 * b + k] = (float)((1.0 - alpha) * s[4 * b + k] + alpha * (rho * r[k]));
            if (c->en) {
                double phi = c->K.flux * s[4 * b];
                c->en->absorbed[b] += alpha * (1.0 - rho) * phi;
                c->en->deposited[b] += alpha * phi;
            }
        }
    }
    if (c->en)
        for (b = 0; b < 3; b++) c->en->end[b] += c->K.flux * (double)po[4 * b];
}

/* One neighbour of the fast kernel: direction D (travel), its band-1 coefficient M (a constant,
 * so that the accumulators stay in registers), source voxel JL. Per band: F = max(0, a c_0 +
 * (+-b) c_M) (the sparse form of P_j . Cone(o)), times the path weight and the normalisation;
 * S_in += F ccpi[o] on the two non-zero coefficients of (F/pi) CC(o). The branch-free clamp adds
 * exact zeros for F = 0, so the sums equal the reference's bit for bit. */
#define VX_GI_TAKE(D, M, JL)                                                                   \
    do {                                                                                       \
        const size_t jl_ = (JL);                                                               \
        const float *q_ = pin + jl_ * VX_GI_F;                                                 \
        const double sb_ = K->sb[D], k1_ = K->k1[D];                                           \
        double w_ = 1.0, F0_, F1_, F2_;                                                        \
        if (void_only) w_ = 1.0 - (double)occ[jl_] * ai;                                        \
        if (w_ > 0.0) {                                                                        \
            F0_ = a * (double)q_[0] + sb_ * (double)q_[M];                                     \
            F1_ = a * (double)q_[4] + sb_ * (double)q_[4 + M];                                 \
            F2_ = a * (double)q_[8] + sb_ * (double)q_[8 + M];                                 \
            F0_ = (F0_ > 0.0 ? F0_ : 0.0) * w_;                                                \
            F1_ = (F1_ > 0.0 ? F1_ : 0.0) * w_;                                                \
            F2_ = (F2_ > 0.0 ? F2_ : 0.0) * w_;                                                \
            if (scale) {                                                                       \
                F0_ *= scale[3 * jl_], F1_ *= scale[3 * jl_ + 1], F2_ *= scale[3 * jl_ + 2];   \
            }                                                                                  \
            s0 += F0_ * k0, s4 += F1_ * k0, s8 += F2_ * k0;                                    \
            s[M] += F0_ * k1_, s[4 + M] += F1_ * k1_, s[8 + M] += F2_ * k1_;                   \
        }                                                                                      \
    } while (0)

/* Fast step: gathering at every voxel from its six face neighbours ([G12] Fig. 51), in the
 * order +x, -x, +y, -y, +z, -z of the reference. */
static void vx_gi_step_fast(const vx_gi_step *c)
{
    const int nx = c->dims[0], ny = c->dims[1], nz = c->dims[2];
    const int void_only = c->cfg.paths == HFVIS_VOLGI_PATHS_VOID;
    const size_t sy = c->stride[1], sz = c->stride[2];
    const vx_gi_consts *K = &c->K;
    const double a = K->a, k0 = K->k0;
    const float *occ = c->g->occupancy, *pin = c->pin;
    const double *scale = c->scale;
    int i, j, k;
    for (k = 0; k < nz; k++)
        for (j = 0; j < ny; j++) {
            const size_t row = (size_t)k * sz + (size_t)j * sy;
            for (i = 0; i < nx; i++) {
                const size_t lin = row + (size_t)i;
                const double ai = void_only ? (double)occ[lin] : 0.0;
                double s[VX_GI_F] = { 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0 };
                double s0 = 0.0, s4 = 0.0, s8 = 0.0;
                /* o = +x comes from i - 1, o = -x from i + 1, ... (j = i - o) */
                if (i > 0) VX_GI_TAKE(0, 3, lin - 1);
                if (i + 1 < nx) VX_GI_TAKE(1, 3, lin + 1);
                if (j > 0) VX_GI_TAKE(2, 1, lin - sy);
                if (j + 1 < ny) VX_GI_TAKE(3, 1, lin + sy);
                if (k > 0) VX_GI_TAKE(4, 2, lin - sz);
                if (k + 1 < nz) VX_GI_TAKE(5, 2, lin + sz);
                s[0] = s0, s[4] = s4, s[8] = s8;
                vx_gi_finish(c, lin, s);
            }
        }
}
#undef VX_GI_TAKE

/* Linear index of voxel v of grid dims. */
static size_t vx_gi_lin(const int dims[3], const int v[3])
{
    return ((size_t)v[2] * (size_t)dims[1] + (size_t)v[1]) * (size_t)dims[0] + (size_t)v[0];
}

/* Reference step: spec §2.5's pseudo-code literally, full 4-coefficient products, every path
 * weight and normalisation recomputed per (i, o). */
static void vx_gi_step_reference(const vx_gi_step *c)
{
    const int void_only = c->cfg.paths == HFVIS_VOLGI_PATHS_VOID;
    int ijk[3], d, b, k, e;
    size_t lin = 0;
    for (ijk[2] = 0; ijk[2] < c->dims[2]; ijk[2]++)
        for (ijk[1] = 0; ijk[1] < c->dims[1]; ijk[1]++)
            for (ijk[0] = 0; ijk[0] < c->dims[0]; ijk[0]++, lin++) {
                double s[VX_GI_F];
                for (k = 0; k < VX_GI_F; k++) s[k] = 0.0;
                for (d = 0; d < 6; d++) {             /* o = travel direction j -> i */
                    int jj[3];
                    size_t jlin;
                    const float *P;
                    double w;
                    jj[0] = ijk[0], jj[1] = ijk[1], jj[2] = ijk[2];
                    jj[d / 2] += (d & 1) ? 1 : -1;    /* j = i - o */
                    if (jj[d / 2] < 0 || jj[d / 2] >= c->dims[d / 2]) continue;
                    jlin = vx_gi_lin(c->dims, jj);
                    P = c->pin + jlin * VX_GI_F;
                    w = void_only ? 1.0 - (double)c->g->occupancy[jlin] * (double)c->g->occupancy[lin] : 1.0;
                    for (b = 0; b < 3; b++) {
                        double F = 0.0;
                        for (k = 0; k < 4; k++) F += (double)P[4 * b + k] * c->K.cone[d][k];
                        F = F > 0.0 ? F : 0.0;
                        F *= w;
                        if (c->cfg.transfer == HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED) {
                            /* all six weighted cone fluxes of j, recomputed */
                            double sum = 0.0, phi = c->K.flux * (double)P[4 * b];
                            for (e = 0; e < 6; e++) {
                                double G = 0.0;
                                int nn[3];
                                for (k = 0; k < 4; k++) G += (double)P[4 * b + k] * c->K.cone[e][k];
                                G = G > 0.0 ? G : 0.0;
                                nn[0] = jj[0], nn[1] = jj[1], nn[2] = jj[2];
                                nn[e / 2] += (e & 1) ? -1 : 1; /* j + o_e */
                                if (void_only && nn[e / 2] >= 0 && nn[e / 2] < c->dims[e / 2])
                                    G *= 1.0 - (double)c->g->occupancy[jlin]
                                                   * (double)c->g->occupancy[vx_gi_lin(c->dims, nn)];
                                sum += G;
                            }
                            F *= phi > 0.0 && sum > 0.0 ? phi / sum : 0.0;
                        }
                        for (k = 0; k < 4; k++) s[4 * b + k] += F * c->K.ccpi[d][k]; /* (F/pi) CC(o) */
                    }
                }
                vx_gi_finish(c, lin, s);
            }
}

/* Set up a step context (inputs validated by the caller). */
static void vx_gi_step_init(vx_gi_step *c, const hfvis_volgi_geometry *g, const vx_gi_cfg *cfg,
                            const float *pin, float *pout, float *acc, const double *scale,
                            hfvis_volgi_energy *en)
{
    memset(c, 0, sizeof *c);
    c->g = g;
    c->cfg = *cfg;
    vx_gi_consts_init(&c->K);
    c->pin = pin, c->pout = pout, c->acc = acc, c->scale = scale, c->en = en;
    c->dims[0] = g->grid.dims[0], c->dims[1] = g->grid.dims[1], c->dims[2] = g->grid.dims[2];
    c->stride[0] = 1;
    c->stride[1] = (size_t)c->dims[0];
    c->stride[2] = (size_t)c->dims[0] * (size_t)c->dims[1];
}

/* Validation shared by the step entry points and the loop. */
static hfvis_status vx_gi_transport_check(const hfvis_volgi_geometry *g, const hfvis_volgi_options *o,
                                          const float *pin, const float *acc, vx_gi_cfg *cfg,
                                          size_t *n)
{
    hfvis_status s;
    if (!g || !pin || !acc) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_gi_resolve(o, cfg);
    if (s != HFVIS_OK) return s;
    if (cfg->rsrc == HFVIS_VOLGI_REFLECTANCE_ALBEDO && !g->albedo) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_gi_geometry_check(g, n);
    if (s != HFVIS_OK) return s;
    if (!vx_gi_values_ok(pin, *n * VX_GI_F) || !vx_gi_values_ok(acc, *n * VX_GI_F))
        return HFVIS_ERR_INVALID_ARGUMENT;
    return HFVIS_OK;
}

static hfvis_status vx_gi_step_entry(const hfvis_volgi_geometry *g, const hfvis_volgi_options *o,
                                     const float *pin, float *pout, float *acc,
                                     hfvis_volgi_energy *energy, int reference)
{
    vx_gi_cfg cfg;
    vx_gi_step c;
    hfvis_volgi_energy en;
    double *scale = NULL;
    size_t n;
    hfvis_status s;
    if (!pout) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_gi_transport_check(g, o, pin, acc, &cfg, &n);
    if (s != HFVIS_OK) return s;
    if (cfg.transfer == HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED && !reference) {
        scale = (double *)vx_alloc_array(cfg.alloc, n, 3 * sizeof(double));
        if (!scale) return HFVIS_ERR_OUT_OF_MEMORY;
    }
    memset(&en, 0, sizeof en);
    vx_gi_step_init(&c, g, &cfg, pin, pout, acc, NULL, energy ? &en : NULL);
    if (scale) {
        vx_gi_scale_pass(&c, scale);
        c.scale = scale;
    }
    if (energy) vx_gi_energy_sources(&c);
    if (reference) vx_gi_step_reference(&c);
    else vx_gi_step_fast(&c);
    vx_free(cfg.alloc, scale);
    if (energy) *energy = en;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_volgi_propagate_step(const hfvis_volgi_geometry *geometry,
                                                  const hfvis_volgi_options *opts,
                                                  const float *prop_in, float *prop_out,
                                                  float *accum, hfvis_volgi_energy *energy)
{
    return vx_gi_step_entry(geometry, opts, prop_in, prop_out, accum, energy, 0);
}

HFVIS_API hfvis_status hfvis_volgi_propagate_step_reference(const hfvis_volgi_geometry *geometry,
                                                            const hfvis_volgi_options *opts,
                                                            const float *prop_in, float *prop_out,
                                                            float *accum,
                                                            hfvis_volgi_energy *energy)
{
    return vx_gi_step_entry(geometry, opts, prop_in, prop_out, accum, energy, 1);
}

/* ---- GI.5 the propagation loop ---------------------------------------------------------- */

/* The loop on validated inputs; scratch: n*12 floats, then n*3 doubles for the normalised
 * transfer (one block). */
static void vx_gi_propagate_run(const hfvis_volgi_geometry *g, const vx_gi_cfg *cfg, int iterations,
                                float *prop, float *accum, hfvis_volgi_energy *energy, float *tmp,
                                double *scale, size_t n)
{
    float *cur = prop, *nxt = tmp;
    int t;
    for (t = 0; t < iterations; t++) {
        vx_gi_step c;
        float *sw;
        if (energy) memset(&energy[t], 0, sizeof energy[t]);
        vx_gi_step_init(&c, g, cfg, cur, nxt, accum, NULL, energy ? &energy[t] : NULL);
        if (scale) {
            vx_gi_scale_pass(&c, scale);
            c.scale = scale;
        }
        if (energy) vx_gi_energy_sources(&c);
        vx_gi_step_fast(&c);
        sw = cur, cur = nxt, nxt = sw;
    }
    if (cur != prop) memcpy(prop, cur, n * VX_GI_F * sizeof(float));
}

/* Scratch bytes of the loop: 12 floats per voxel (+ 3 doubles, normalised). 0 on overflow. */
static size_t vx_gi_loop_scratch(const vx_gi_cfg *cfg, size_t n, size_t *scale_off)
{
    size_t a, b = 0;
    if (!vx_mul_size(n, VX_GI_F * sizeof(float), &a)) return 0;
    a = (a + sizeof(double) - 1) / sizeof(double) * sizeof(double);
    *scale_off = a;
    if (cfg->transfer == HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED
        && (!vx_mul_size(n, 3 * sizeof(double), &b) || b > SIZE_MAX - a))
        return 0;
    return a + b;
}

HFVIS_API hfvis_status hfvis_volgi_propagate(const hfvis_volgi_geometry *geometry,
                                             const hfvis_volgi_options *opts, int iterations,
                                             float *prop, float *accum,
                                             hfvis_volgi_energy *energy)
{
    vx_gi_cfg cfg;
    size_t n, bytes, off;
    unsigned char *block;
    hfvis_status s;
    if (!prop || iterations < 0 || iterations > HFVIS_VOLGI_MAX_ITERATIONS)
        return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_gi_transport_check(geometry, opts, prop, accum, &cfg, &n);
    if (s != HFVIS_OK) return s;
    if (iterations == 0) return HFVIS_OK;
    bytes = vx_gi_loop_scratch(&cfg, n, &off);
    if (bytes == 0) return HFVIS_ERR_LIMIT;
    block = (unsigned char *)vx_alloc(cfg.alloc, bytes);
    if (!block) return HFVIS_ERR_OUT_OF_MEMORY;
    vx_gi_propagate_run(geometry, &cfg, iterations, prop, accum, energy, (float *)(void *)block,
                        cfg.transfer == HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED
                            ? (double *)(void *)(block + off) : NULL, n);
    vx_free(cfg.alloc, block);
    return HFVIS_OK;
}

/* ---- GI.6 final gather ------------------------------------------------------------------ */

/* Eqs. 12-15 on validated inputs (spec §2.6); n need not be unit (a zero n gives 0). */
static void vx_gi_gather_point(const hfvis_volgi_geometry *g, const float *accum, double kappa,
                               const double p[3], const double n[3], double E[3])
{
    double gg[3], f[3], L[VX_GI_F], wsum = 0.0, u[3], m[3], cc[4], area;
    int b0[3], c, a, k, b, ax;
    E[0] = E[1] = E[2] = 0.0;
    ax = vx_gi_dominant(n[0], n[1], n[2]);
    if (ax < 0 || !vx_gi_unit(n, u)) return;
    for (a = 0; a < 3; a++) {
        gg[a] = (p[a] - g->grid.origin[a]) / g->grid.cell[a] - 0.5;
        if (!(gg[a] > -2.0 && gg[a] < (double)g->grid.dims[a] + 1.0)) return; /* no voxel near */
        b0[a] = (int)floor(gg[a]);
        f[a] = gg[a] - (double)b0[a];
    }
    for (k = 0; k < VX_GI_F; k++) L[k] = 0.0;
    for (c = 0; c < 8; c++) {
        int v[3];
        double w = 1.0;
        size_t lin;
        for (a = 0; a < 3; a++) {
            int bit = (c >> a) & 1;
            v[a] = b0[a] + bit;
            w *= bit ? f[a] : 1.0 - f[a];
        }
        if (v[0] < 0 || v[1] < 0 || v[2] < 0 || v[0] >= g->grid.dims[0] || v[1] >= g->grid.dims[1]
            || v[2] >= g->grid.dims[2])
            continue;
        lin = ((size_t)v[2] * (size_t)g->grid.dims[1] + (size_t)v[1]) * (size_t)g->grid.dims[0]
              + (size_t)v[0];
        if (!(g->occupancy[lin] > 0.0f)) continue; /* only occupied voxels ([G12] §5.5.3) */
        for (k = 0; k < VX_GI_F; k++) L[k] += w * (double)accum[lin * VX_GI_F + (size_t)k];
        wsum += w;
    }
    if (!(wsum > 0.0)) return;
    /* A is indexed by travel direction: light reaching the surface travels along -n */
    m[0] = -u[0], m[1] = -u[1], m[2] = -u[2];
    (void)hfvis_volgi_sh_clamped_cosine(m, cc);
    area = vx_gi_face(&g->grid, ax);
    for (b = 0; b < 3; b++) {
        double d = 0.0;
        for (k = 0; k < 4; k++) d += (L[4 * b + k] / wsum) * cc[k]; /* eq. 7: a dot product */
        E[b] = d > 0.0 ? kappa * d / area : 0.0;
    }
}

HFVIS_API hfvis_status hfvis_volgi_gather(const hfvis_volgi_geometry *geometry,
                                          const float *accum, const hfvis_volgi_options *opts,
                                          const double point[3], const double normal[3],
                                          float irradiance[3])
{
    vx_gi_cfg cfg;
    double u[3], E[3];
    hfvis_status s;
    if (!geometry || !accum || !point || !normal || !irradiance || !geometry->occupancy
        || !geometry->normal || !vx_grid_valid(&geometry->grid) || !vx_gi_unit(normal, u)
        || !isfinite(point[0]) || !isfinite(point[1]) || !isfinite(point[2]))
        return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_gi_resolve(opts, &cfg);
    if (s != HFVIS_OK) return s;
    vx_gi_gather_point(geometry, accum, cfg.gather_scale, point, u, E);
    irradiance[0] = (float)E[0], irradiance[1] = (float)E[1], irradiance[2] = (float)E[2];
    return HFVIS_OK;
}

/* ---- GI.7 lights and direct irradiance ------------------------------------------------- */

#define VX_GI_MAX_COORD 1e30 /* light positions and receivers: far inside float range */

static int vx_gi_vec_ok(const double *v, int nonzero)
{
    int a;
    for (a = 0; a < 3; a++)
        if (!(fabs(v[a]) <= VX_GI_MAX_COORD)) return 0;
    return !nonzero || v[0] != 0.0 || v[1] != 0.0 || v[2] != 0.0;
}

static int vx_gi_light_ok(const hfvis_volgi_light *L)
{
    int b;
    for (b = 0; b < 3; b++)
        if (!(L->intensity[b] >= 0.0f && L->intensity[b] <= FLT_MAX)) return 0;
    switch (L->type) {
    case HFVIS_VOLGI_LIGHT_POINT: return vx_gi_vec_ok(L->position, 0);
    case HFVIS_VOLGI_LIGHT_SPOT:
        return vx_gi_vec_ok(L->position, 0) && vx_gi_vec_ok(L->direction, 1)
               && L->spot_inner_rad >= 0.0 && L->spot_inner_rad <= L->spot_outer_rad
               && L->spot_outer_rad > 0.0 && L->spot_outer_rad <= VX_PI;
    case HFVIS_VOLGI_LIGHT_DIRECTIONAL: return vx_gi_vec_ok(L->direction, 1);
    }
    return 0;
}

/* Shadow rays ignore the receiver's own triangle. */
static int vx_gi_skip_filter(void *user, const hfvis_ray *ray, const hfvis_hit *candidate)
{
    (void)ray;
    return candidate->triangle != *(const uint32_t *)user;
}

/* The default shadow bias: 1e-5 times the diagonal of the BVH's root box (0 without nodes). */
static double vx_gi_bias(const vx_gi_cfg *cfg, const hfvis_bvh *bvh)
{
    double d2 = 0.0;
    int a;
    if (cfg->shadow_bias > 0.0) return cfg->shadow_bias;
    if (bvh->node_count == 0) return 0.0;
    for (a = 0; a < 3; a++) {
        double e = (double)bvh->nodes[0].hi[a] - (double)bvh->nodes[0].lo[a];
        d2 += e * e;
    }
    return 1e-5 * sqrt(d2);
}

/* Direct irradiance on validated inputs (n unit). */
static void vx_gi_direct(const hfvis_volgi_scene *sc, const hfvis_bvh *bvh, double bias,
                         const double p[3], const double n[3], uint32_t skip, double E[3])
{
    int l, b;
    E[0] = E[1] = E[2] = 0.0;
    for (l = 0; l < sc->light_count; l++) {
        const hfvis_volgi_light *L = &sc->lights[l];
        double dir[3], w = 1.0, cosn;
        hfvis_ray ray;
        hfvis_hit hit;
        int a;
        if (L->type == HFVIS_VOLGI_LIGHT_DIRECTIONAL) {
            double u[3];
            (void)vx_gi_unit(L->direction, u);
            dir[0] = -u[0], dir[1] = -u[1], dir[2] = -u[2];
            cosn = n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2];
            if (!(cosn > 0.0)) continue;
            for (a = 0; a < 3; a++) ray.direction[a] = (float)dir[a];
            ray.t_min = (float)bias;
            ray.t_max = (float)INFINITY;
        } else {
            double d[3], dist;
            for (a = 0; a < 3; a++) d[a] = L->position[a] - p[a];
            dist = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            if (!(dist > 2.0 * bias) || !(dist > 0.0)) continue; /* receiver at the light */
            for (a = 0; a < 3; a++) dir[a] = d[a] / dist;
            cosn = n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2];
            if (!(cosn > 0.0)) continue;
            if (L->type == HFVIS_VOLGI_LIGHT_SPOT) {
                double u[3], ct, ci = cos(L->spot_inner_rad), co = cos(L->spot_outer_rad);
                (void)vx_gi_unit(L->direction, u);
                ct = -(dir[0] * u[0] + dir[1] * u[1] + dir[2] * u[2]); /* cos(axis, light->p) */
                if (ct >= ci) w = 1.0;
                else if (ct <= co || ci == co) w = 0.0;
                else w = (ct - co) / (ci - co);
                if (!(w > 0.0)) continue;
            }
            w /= dist * dist;
            for (a = 0; a < 3; a++) ray.direction[a] = (float)d[a];
            ray.t_min = (float)(bias / dist);
            ray.t_max = (float)(1.0 - bias / dist);
        }
        if (bvh->node_count > 0) {
            uint32_t skip_tri = skip;
            hfvis_status st;
            for (a = 0; a < 3; a++) ray.origin[a] = (float)p[a];
            ray.cull = HFVIS_CULL_NONE;
            st = hfvis_bvh_intersect(bvh, sc->mesh, &ray, HFVIS_RAY_ANY, vx_gi_skip_filter,
                                     &skip_tri, &hit);
            HFVIS_ASSERT(st == HFVIS_OK);
            if (st == HFVIS_OK && hit.triangle != HFVIS_NO_TRIANGLE) continue; /* in shadow */
        }
        for (b = 0; b < 3; b++) E[b] += (double)L->intensity[b] * w * cosn;
    }
}

/* Scene checks: mesh, materials, lights, the BVH's triangle count. */
static hfvis_status vx_gi_scene_check(const hfvis_volgi_scene *sc)
{
    size_t i, t3;
    int l;
    if (!sc || !sc->mesh) return HFVIS_ERR_INVALID_ARGUMENT;
    if (sc->mesh->triangle_count > HFVIS_BVH_MAX_TRIANGLES) return HFVIS_ERR_LIMIT;
    if (vx_mesh_check(sc->mesh) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    if (sc->light_count < 0 || sc->light_count > HFVIS_VOLGI_MAX_LIGHTS
        || (sc->light_count > 0 && !sc->lights))
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (l = 0; l < sc->light_count; l++)
        if (!vx_gi_light_ok(&sc->lights[l])) return HFVIS_ERR_INVALID_ARGUMENT;
    t3 = 3 * sc->mesh->triangle_count;
    if (sc->albedo)
        for (i = 0; i < t3; i++)
            if (!(sc->albedo[i] >= 0.0f && sc->albedo[i] <= 1.0f)) return HFVIS_ERR_INVALID_ARGUMENT;
    if (sc->emission)
        for (i = 0; i < t3; i++)
            if (!(sc->emission[i] >= 0.0f && sc->emission[i] <= HFVIS_VOLGI_MAX_VALUE))
                return HFVIS_ERR_INVALID_ARGUMENT;
    if (sc->bvh && sc->bvh->triangle_count != sc->mesh->triangle_count) return HFVIS_ERR_INVALID_ARGUMENT;
    return HFVIS_OK;
}

HFVIS_API hfvis_status hfvis_volgi_direct_irradiance(const hfvis_volgi_scene *scene,
                                                     const hfvis_volgi_options *opts,
                                                     const double point[3],
                                                     const double normal[3],
                                                     uint32_t skip_triangle, float irradiance[3])
{
    vx_gi_cfg cfg;
    double u[3], E[3];
    int l;
    hfvis_status s;
    if (!scene || !scene->mesh || !scene->bvh || !point || !normal || !irradiance
        || !vx_gi_vec_ok(point, 0) || !vx_gi_unit(normal, u)
        || scene->bvh->triangle_count != scene->mesh->triangle_count
        || (scene->bvh->node_count > 0 && !scene->bvh->nodes)
        || scene->light_count < 0 || scene->light_count > HFVIS_VOLGI_MAX_LIGHTS
        || (scene->light_count > 0 && !scene->lights))
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (l = 0; l < scene->light_count; l++)
        if (!vx_gi_light_ok(&scene->lights[l])) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_gi_resolve(opts, &cfg);
    if (s != HFVIS_OK) return s;
    vx_gi_direct(scene, scene->bvh, vx_gi_bias(&cfg, scene->bvh), point, u, skip_triangle, E);
    irradiance[0] = (float)E[0], irradiance[1] = (float)E[1], irradiance[2] = (float)E[2];
    return HFVIS_OK;
}

/* ---- GI.8 voxelization with direct light (Alg. 4) and the room grid --------------------- */

HFVIS_API hfvis_status hfvis_volgi_grid_fit(const hfvis_mesh *mesh, int resolution,
                                            hfvis_volume_grid *out)
{
    double lo[3], hi[3], ext_max = 0.0, s;
    hfvis_volume_grid g;
    size_t i, total = 1;
    int a;
    if (!out || vx_mesh_check(mesh) != HFVIS_OK || mesh->triangle_count == 0 || resolution < 2
        || resolution > HFVIS_VOLGI_MAX_RESOLUTION)
        return HFVIS_ERR_INVALID_ARGUMENT;
    for (a = 0; a < 3; a++) lo[a] = HUGE_VAL, hi[a] = -HUGE_VAL;
    for (i = 0; i < 3 * mesh->triangle_count; i++) {
        const float *p = mesh->xyz + 3 * (size_t)mesh->indices[i];
        for (a = 0; a < 3; a++) {
            if ((double)p[a] < lo[a]) lo[a] = (double)p[a];
            if ((double)p[a] > hi[a]) hi[a] = (double)p[a];
        }
    }
    for (a = 0; a < 3; a++)
        if (hi[a] - lo[a] > ext_max) ext_max = hi[a] - lo[a];
    if (!(ext_max > 0.0) || !isfinite(ext_max)) return HFVIS_ERR_INVALID_ARGUMENT;
    s = ext_max / (double)(resolution - 1);
    memset(&g, 0, sizeof g);
    for (a = 0; a < 3; a++) {
        double nn = floor((hi[a] - lo[a]) / s + 0.5) + 1.0;
        g.dims[a] = (int)nn; /* <= resolution */
        g.cell[a] = s;
        g.origin[a] = 0.5 * (lo[a] + hi[a]) - 0.5 * nn * s;
        if (!(s > 0.0) || !isfinite(g.origin[a])) return HFVIS_ERR_INVALID_ARGUMENT;
        if (!vx_mul_size(total, (size_t)g.dims[a], &total) || total > HFVIS_VOLUME_MAX_VOXELS)
            return HFVIS_ERR_LIMIT;
    }
    *out = g;
    return HFVIS_OK;
}

/* The Volume Buffer layout of the voxelization: fragment count, normal sum, albedo sum (ADD:
 * averages [C]) and radiance (MAX: [G12] Alg. 4). */
#define VX_GI_VCH 10

typedef struct vx_gi_frag_user {
    const hfvis_volgi_scene *sc;
    const hfvis_bvh *bvh;
    double bias;
} vx_gi_frag_user;

static void vx_gi_fragment(const hfvis_voxel_fragment *f, float *values, void *user)
{
    const vx_gi_frag_user *u = (const vx_gi_frag_user *)user;
    const size_t t = (size_t)f->triangle;
    double p[3], n[3], E[3];
    int b;
    values[0] = 1.0f;
    for (b = 0; b < 3; b++) {
        p[b] = (double)f->position[b];
        n[b] = (double)f->normal[b];
        values[1 + b] = f->normal[b];
        values[4 + b] = u->sc->albedo ? u->sc->albedo[3 * t + (size_t)b] : 1.0f;
    }
    /* radiosity from direct light with shadows, plus emission ([G12] §5.5.1), as radiance */
    vx_gi_direct(u->sc, u->bvh, u->bias, p, n, f->triangle, E);
    for (b = 0; b < 3; b++) {
        double L = (double)values[4 + b] * E[b] / VX_PI;
        if (u->sc->emission) L += (double)u->sc->emission[3 * t + (size_t)b];
        values[7 + b] = (float)L;
    }
}

/* Alg. 4 on validated inputs into the caller's arrays (albedo may be NULL). One block. */
static hfvis_status vx_gi_voxelize(const hfvis_volgi_scene *sc, const hfvis_bvh *bvh,
                                   const hfvis_volume_grid *grid, const vx_gi_cfg *cfg, float *occ,
                                   float *nrm, float *alb, float *rad, size_t *fragments)
{
    size_t n = vx_grid_voxels(grid), v, count = 0;
    float *block = (float *)vx_alloc_array(cfg->alloc, n, VX_GI_VCH * sizeof(float));
    hfvis_volume vol;
    hfvis_voxelize_options vo = hfvis_voxelize_options_default();
    vx_gi_frag_user fu;
    hfvis_status s;
    int b;
    if (!block) return HFVIS_ERR_OUT_OF_MEMORY;
    s = hfvis_volume_init(&vol, grid, VX_GI_VCH, block, HFVIS_BLEND_ADD);
    HFVIS_ASSERT(s == HFVIS_OK);
    for (b = 7; b < VX_GI_VCH; b++) vol.blend[b] = HFVIS_BLEND_MAX;
    fu.sc = sc, fu.bvh = bvh, fu.bias = vx_gi_bias(cfg, bvh);
    vo.axes = HFVIS_AXES_ALL;        /* the x, y and z slicing passes of Alg. 4 */
    vo.fragment = vx_gi_fragment;
    vo.user = &fu;
    s = hfvis_voxelize_surface(sc->mesh, &vol, &vo, &count);
    HFVIS_ASSERT(s == HFVIS_OK);
    for (v = 0; v < n; v++) {
        const float *q = block + v * VX_GI_VCH;
        double cnt = (double)q[0], len;
        occ[v] = cnt > 0.0 ? 1.0f : 0.0f;
        len = sqrt((double)q[1] * (double)q[1] + (double)q[2] * (double)q[2] + (double)q[3] * (double)q[3]);
        for (b = 0; b < 3; b++) {
            /* average normal; 0 when the fragments' normals cancel (a two-sided sheet) */
            nrm[3 * v + (size_t)b] = cnt > 0.0 && len > 1e-6 * cnt ? (float)((double)q[1 + b] / len) : 0.0f;
            if (alb) {
                double al = cnt > 0.0 ? (double)q[4 + b] / cnt : 0.0;
                alb[3 * v + (size_t)b] = (float)(al > 1.0 ? 1.0 : al);
            }
            rad[3 * v + (size_t)b] = q[7 + b];
        }
    }
    vx_free(cfg->alloc, block);
    if (fragments) *fragments = count;
    return s;
}

/* The scene's BVH, or one built into *own with cfg->alloc. */
static hfvis_status vx_gi_bvh(const hfvis_volgi_scene *sc, const vx_gi_cfg *cfg, hfvis_bvh *own,
                              const hfvis_bvh **bvh)
{
    hfvis_bvh_options bo = hfvis_bvh_options_default();
    hfvis_status s;
    memset(own, 0, sizeof *own);
    if (sc->bvh) {
        *bvh = sc->bvh;
        return HFVIS_OK;
    }
    bo.alloc = cfg->alloc;
    s = hfvis_bvh_build(sc->mesh, &bo, own);
    if (s == HFVIS_OK) *bvh = own;
    return s;
}

HFVIS_API hfvis_status hfvis_volgi_voxelize(const hfvis_volgi_scene *scene,
                                            const hfvis_volume_grid *grid,
                                            const hfvis_volgi_options *opts, float *occupancy,
                                            float *normal, float *albedo, float *radiance,
                                            size_t *fragments)
{
    vx_gi_cfg cfg;
    hfvis_bvh own;
    const hfvis_bvh *bvh = NULL;
    hfvis_status s;
    if (!grid || !occupancy || !normal || !radiance || !vx_grid_valid(grid))
        return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_gi_resolve(opts, &cfg);
    if (s != HFVIS_OK) return s;
    s = vx_gi_scene_check(scene);
    if (s != HFVIS_OK) return s;
    s = vx_gi_bvh(scene, &cfg, &own, &bvh);
    if (s != HFVIS_OK) return s;
    s = vx_gi_voxelize(scene, bvh, grid, &cfg, occupancy, normal, albedo, radiance, fragments);
    hfvis_bvh_free(cfg.alloc, &own);
    return s;
}

/* ---- GI.9 the whole pipeline ------------------------------------------------------------ */

/* Flux of one band summed over an SH volume. */
static void vx_gi_flux_sum(const float *sh, size_t n, double out[3])
{
    const double k = 2.0 * sqrt(VX_PI);
    size_t v;
    int b;
    out[0] = out[1] = out[2] = 0.0;
    for (v = 0; v < n; v++)
        for (b = 0; b < 3; b++) out[b] += k * (double)sh[v * VX_GI_F + 4 * (size_t)b];
}

HFVIS_API hfvis_status hfvis_volgi_render(const hfvis_volgi_scene *scene,
                                          const hfvis_volume_grid *grid, const hfvis_view *view,
                                          const hfvis_volgi_options *opts,
                                          const hfvis_volgi_outputs *outputs,
                                          hfvis_volgi_render_info *info)
{
    vx_gi_cfg cfg;
    hfvis_volume_grid G;
    hfvis_bvh own;
    const hfvis_bvh *bvh = NULL;
    hfvis_raster_options ro = hfvis_raster_options_default();
    hfvis_raster_outputs rout;
    hfvis_volgi_geometry geo;
    hfvis_volgi_render_info inf;
    hfvis_volgi_options po;
    float *gbuf = NULL, *gvol = NULL, *sh = NULL;
    uint32_t *tri;
    size_t n, pixels, px, frags = 0, v;
    hfvis_status s;
    double bias;

    memset(&own, 0, sizeof own);
    memset(&inf, 0, sizeof inf);
    if (!scene || !view || !outputs) return HFVIS_ERR_INVALID_ARGUMENT;
    s = vx_gi_resolve(opts, &cfg);
    if (s != HFVIS_OK) return s;
    s = vx_gi_scene_check(scene);
    if (s != HFVIS_OK) return s;
    if (grid) {
        if (!vx_grid_valid(grid)) return HFVIS_ERR_INVALID_ARGUMENT;
        G = *grid;
    } else {
        s = hfvis_volgi_grid_fit(scene->mesh, cfg.resolution, &G);
        if (s != HFVIS_OK) return s;
    }
    n = vx_gi_voxels(&G);
    if (n == 0) return HFVIS_ERR_LIMIT;
    if (view->width < 1 || view->height < 1) return HFVIS_ERR_INVALID_ARGUMENT;
    if (view->width > HFVIS_RASTER_MAX_SIZE || view->height > HFVIS_RASTER_MAX_SIZE)
        return HFVIS_ERR_LIMIT;
    pixels = (size_t)view->width * (size_t)view->height;

    /* G-buffer: normal (3), barycentrics (2), triangle id (1) per pixel, one block */
    gbuf = (float *)vx_alloc_array(cfg.alloc, pixels, 5 * sizeof(float) + sizeof(uint32_t));
    if (!gbuf) return HFVIS_ERR_OUT_OF_MEMORY;
    tri = (uint32_t *)(void *)(gbuf + 5 * pixels);
    memset(&rout, 0, sizeof rout);
    rout.normal = gbuf;
    rout.barycentric = gbuf + 3 * pixels;
    rout.triangle_id = tri;
    ro.alloc = cfg.alloc;
    s = hfvis_rasterize(scene->mesh, view, &ro, &rout);
    if (s != HFVIS_OK) goto done;
    s = vx_gi_bvh(scene, &cfg, &own, &bvh);
    if (s != HFVIS_OK) goto done;

    /* geometry volume: occupancy, normal, albedo, radiance (10 floats per voxel) */
    gvol = (float *)vx_alloc_array(cfg.alloc, n, 10 * sizeof(float));
    if (!gvol) { s = HFVIS_ERR_OUT_OF_MEMORY; goto done; }
    s = vx_gi_voxelize(scene, bvh, &G, &cfg, gvol, gvol + n, gvol + 4 * n, gvol + 7 * n, &frags);
    if (s != HFVIS_OK) goto done;
    geo.grid = G;
    geo.occupancy = gvol;
    geo.normal = gvol + n;
    geo.albedo = gvol + 4 * n;

    /* SH volumes: P (propagation) and A (accumulation) */
    sh = (float *)vx_alloc_array(cfg.alloc, n, 2 * VX_GI_F * sizeof(float));
    if (!sh) { s = HFVIS_ERR_OUT_OF_MEMORY; goto done; }
    s = hfvis_volgi_inject(&geo, gvol + 7 * n, sh);
    if (s != HFVIS_OK) goto done;
    vx_gi_flux_sum(sh, n, inf.injected);
    memset(sh + n * VX_GI_F, 0, n * VX_GI_F * sizeof(float));
    po = opts ? *opts : hfvis_volgi_options_default();
    s = hfvis_volgi_propagate(&geo, &po, cfg.iterations, sh, sh + n * VX_GI_F, NULL);
    if (s != HFVIS_OK) goto done;
    vx_gi_flux_sum(sh, n, inf.remaining);
    vx_gi_flux_sum(sh + n * VX_GI_F, n, inf.deposited);

    /* shading: per pixel at the exact surface point */
    bias = vx_gi_bias(&cfg, bvh);
    for (px = 0; px < pixels; px++) {
        float d[3] = { 0.0f, 0.0f, 0.0f }, id[3] = { 0.0f, 0.0f, 0.0f };
        int b;
        if (tri[px] != HFVIS_NO_TRIANGLE) {
            const size_t t = (size_t)tri[px];
            const uint32_t *ix = scene->mesh->indices + 3 * t;
            const float *v0 = scene->mesh->xyz + 3 * (size_t)ix[0];
            const float *v1 = scene->mesh->xyz + 3 * (size_t)ix[1];
            const float *v2 = scene->mesh->xyz + 3 * (size_t)ix[2];
            double b1 = (double)rout.barycentric[2 * px], b2 = (double)rout.barycentric[2 * px + 1];
            double p[3], nn[3], Ed[3], Ei[3];
            for (b = 0; b < 3; b++) {
                p[b] = (1.0 - b1 - b2) * (double)v0[b] + b1 * (double)v1[b] + b2 * (double)v2[b];
                nn[b] = (double)rout.normal[3 * px + (size_t)b];
            }
            vx_gi_direct(scene, bvh, bias, p, nn, tri[px], Ed);
            vx_gi_gather_point(&geo, sh + n * VX_GI_F, cfg.gather_scale, p, nn, Ei);
            for (b = 0; b < 3; b++) {
                double al = scene->albedo ? (double)scene->albedo[3 * t + (size_t)b] : 1.0;
                double em = scene->emission ? (double)scene->emission[3 * t + (size_t)b] : 0.0;
                d[b] = (float)(em + al * Ed[b] / VX_PI);
                id[b] = (float)(al * Ei[b] / VX_PI);
            }
            inf.covered_pixels++;
        }
        for (b = 0; b < 3; b++) {
            if (outputs->direct) outputs->direct[3 * px + (size_t)b] = d[b];
            if (outputs->indirect) outputs->indirect[3 * px + (size_t)b] = id[b];
            if (outputs->total) outputs->total[3 * px + (size_t)b] = (float)((double)d[b] + (double)id[b]);
        }
    }
    inf.grid = G;
    inf.fragments = frags;
    for (v = 0; v < n; v++) inf.occupied += gvol[v] > 0.0f;
    if (info) *info = inf;
done:
    vx_free(cfg.alloc, sh);
    vx_free(cfg.alloc, gvol);
    hfvis_bvh_free(cfg.alloc, &own);
    vx_free(cfg.alloc, gbuf);
    return s;
}
