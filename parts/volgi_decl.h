
/* ========================================================================================== */
/* voxel.c - volume-based VPL indirect illumination ([G12] ch. 5, spec voxel §2)               */
/* ========================================================================================== */

/* Gaitatzes' volume-based indirect light ([G12] ch. 5; 3IA/CGVCVIP 2010 with Mavridis and
 * Papaioannou), a Light Propagation Volume (Kaplanyan 2009) that knows the geometry:
 *   1. the scene is voxelized along all three axes with direct lighting (Alg. 4: the three
 *      per-axis volumes merged with MAX; hfvis_volgi_voxelize): per voxel an occupancy, an
 *      average normal, an albedo and the outgoing radiance of the directly lit (or emissive)
 *      surface in it;
 *   2. every lit voxel becomes a virtual point light (VPL), a cosine lobe about its normal in
 *      2-band spherical harmonics (hfvis_volgi_inject);
 *   3. the light is propagated iteratively from voxel to face neighbour (eq. 11, the reference
 *      kernel of spec §2.5; hfvis_volgi_propagate): through empty voxels unchanged, and at
 *      occupied voxels it is recorded in an accumulation volume A and reflected (T_r);
 *   4. each pixel gathers A from the occupied voxels around it and integrates it against its
 *      clamped cosine (eqs. 12-15; hfvis_volgi_gather).
 * hfvis_volgi_render runs the whole pipeline for a view.
 *
 * Conventions of this section.
 * - SH: real, orthonormal, 2 bands = 4 coefficients per colour band, DESIGN's convention:
 *   Y_0 = 1/(2 sqrt pi), Y_1 = 0.4886 y, Y_2 = 0.4886 z, Y_3 = 0.4886 x (0.4886 = sqrt(3/(4 pi))),
 *   the first 4 values of hfvis_sh_eval. An SH volume holds HFVIS_VOLGI_FLOATS = 12 floats per
 *   voxel, band-major: v[lin*12 + 4*band + k], bands R, G, B, lin = the grid's linear index.
 * - The propagation volume P and the accumulation volume A hold radiant INTENSITY (flux per
 *   steradian, W/sr in a world where radiance is W/(m^2 sr)) as a function of the direction the
 *   light TRAVELS. The flux (energy) of a band is its integral over the sphere, 2 sqrt(pi) c_0.
 * - A VPL of a voxel with outgoing radiance L (Lambertian, DESIGN §2) and unit normal n has the
 *   flux Phi = pi L s^2 of one voxel face (s^2 = the face of the grid perpendicular to n's
 *   dominant axis) and the intensity (Phi/pi) max(0, n.w) (spec §2.4 [C]).
 * - Constants (spec §2.2): the clamped cosine about n, CC(n) = (sqrt(pi)/2, sqrt(pi/3) n_y,
 *   sqrt(pi/3) n_z, sqrt(pi/3) n_x), and the cone of half-angle 45 degrees about d (the thesis'
 *   "90-degree cone"), Cone(d) = (sqrt(pi)(1 - cos 45), (sqrt(3 pi)/2) sin^2 45 d_y, ...).
 * - All transport arithmetic is double, rounded to float once per stored value. Determinism:
 *   same inputs, same binary, same bits.
 * - Choices the thesis leaves open [C] (spec §2.9), each an option where it matters: the VPL scale
 *   (the flux of one voxel face, above); the meaning of eq. 11 (hfvis_volgi_transfer: per
 *   neighbour the cone flux, re-expanded as a cosine lobe along the travel direction, negative SH
 *   ringing clamped); transfers between two occupied voxels (hfvis_volgi_paths); the mirror axis
 *   (dominant axis of the average normal, ties to the lowest axis; no normal: all three) or a
 *   diffuse re-emission (hfvis_volgi_reflection); partial occupancy as transparency (1 - alpha
 *   passes unchanged); light sent out of the grid is lost; A starts at zero (direct light is not
 *   in A; the first bounce's albedo is in the injected radiance); rho after the first bounce
 *   (hfvis_volgi_reflectance); normals and albedo averaged, radiance MAX-merged
 *   (hfvis_volgi_voxelize); the gather's renormalised trilinear weights over occupied voxels and
 *   its flux-to-irradiance scale (hfvis_volgi_gather); direct light by BVH shadow rays, one-sided.
 * - Thin (one-voxel) walls leak light through the side lobes of the kernel and a cone covers
 *   only 11.04 of the 12.57 sr of the sphere (12 % of an isotropic voxel's flux is not
 *   transported per step; 1.8 % of a cosine lobe's): the reference kernel is the thesis', not an
 *   unbiased light transport; see hfvis_volgi_transfer for the energy-conserving variant. */

#define HFVIS_VOLGI_SH 4                  /* SH coefficients per colour band */
#define HFVIS_VOLGI_FLOATS 12             /* floats per voxel of an SH volume (3 bands x 4) */
#define HFVIS_VOLGI_DEFAULT_ITERATIONS 64 /* the thesis' indoor count (room: 64 on 32^3) */
#define HFVIS_VOLGI_DEFAULT_RESOLUTION 32 /* the thesis' grid (Table 2) */
#define HFVIS_VOLGI_DEFAULT_REFLECTANCE 0.5 /* [G12] §5.6: "after the first light bounce we
                                               consider it constant and equal to 0.5" */
#define HFVIS_VOLGI_DEFAULT_GATHER_SCALE (12.0 / 7.0) /* see hfvis_volgi_gather */
#define HFVIS_VOLGI_MAX_ITERATIONS 1048576
#define HFVIS_VOLGI_MAX_RESOLUTION 2048
#define HFVIS_VOLGI_MAX_LIGHTS 65536
/* Largest |value| accepted in SH volumes and radiance inputs: keeps every sum finite in float
 * (2^31 voxels x 2^20 iterations x 1e20 < FLT_MAX). */
#define HFVIS_VOLGI_MAX_VALUE 1e20f

/* ---- 2-band SH helpers (spec §2.2) ---------------------------------------------------------- */

/* The 4 basis functions at the unit direction dir/|dir|. Returns HFVIS_OK, or
 * HFVIS_ERR_INVALID_ARGUMENT for NULL, a non-finite or zero dir (out untouched). */
HFVIS_API hfvis_status hfvis_volgi_sh_basis(const double dir[3], double out[4]);

/* SH projection of the clamped cosine max(0, n.w) about n/|n|: CC(n) above; its integral is pi
 * and CC(n).CC(n) = 7 pi/12 (the projection keeps 0.875 of the lobe's 2 pi/3 self-product).
 * Errors as hfvis_volgi_sh_basis. */
HFVIS_API hfvis_status hfvis_volgi_sh_clamped_cosine(const double normal[3], double out[4]);

/* SH projection of the indicator of the cone of half-angle half_angle_rad in (0, pi] about
 * axis/|axis|: (sqrt(pi)(1 - cos a), (sqrt(3 pi)/2) sin^2 a axis_y, ... z, ... x), so that
 * f.Cone = the integral of the SH function f over the cone. 45 degrees: (0.5191397,
 * 0.7674950 d_y, 0.7674950 d_z, 0.7674950 d_x). Errors as hfvis_volgi_sh_basis, plus a
 * half-angle outside (0, pi] or not finite. */
HFVIS_API hfvis_status hfvis_volgi_sh_cone(const double axis[3], double half_angle_rad,
                                           double out[4]);

/* ---- options ------------------------------------------------------------------------------ */

/* How the flux that leaves a voxel toward a face neighbour is computed (eq. 11, spec §2.5). */
typedef enum hfvis_volgi_transfer {
    /* Default: the reference kernel of spec §2.5 [C]. The flux through the face toward
     * neighbour i = j + o is F = max(0, P_j . Cone(o)) per band (the SH integral of P_j over the
     * 45-degree cone about o, negative values from SH ringing clamped), and it arrives at i as a
     * cosine lobe (F/pi) CC(o) travelling along o. The part of P_j's flux outside the six cones
     * is not transported (reported as `uncovered` by hfvis_volgi_energy): 1.8 % per step for a
     * cosine lobe along an axis, 12 % for isotropic light. Single VPL (Phi/pi) CC(+z) in empty
     * space: forward flux Phi (3 - sqrt 2)/4, each side Phi (2 - sqrt 2)/4, backward 0. */
    HFVIS_VOLGI_TRANSFER_CONE = 0,
    /* Energy-conserving variant [C]: the whole flux 2 sqrt(pi) c_0 of P_j is split among the six
     * directions in proportion to their clamped cone fluxes, F_o = Phi_j F_o^ref / sum F^ref, so
     * light is lost only by absorption and by leaving the grid (the same first-step proportions,
     * 0.4036 Phi forward, 0.1491 Phi per side). Voxels with Phi_j <= 0 send nothing. */
    HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED = 1
} hfvis_volgi_transfer;

/* What an occupied voxel does with the light S_in that arrives (the thesis' T_r). */
typedef enum hfvis_volgi_reflection {
    /* Default, the thesis' simplification (§5.5.2): mirror S_in on the plane perpendicular to the
     * dominant axis m of the voxel's average normal (ties: lowest axis), i.e. negate band-1
     * coefficient m (index 3 for x, 1 for y, 2 for z; T_r = 1 except -1 there [I]). Keeps c_0, so
     * the reflected flux is exactly rho times the arriving flux. A voxel whose normal is 0
     * negates all three band-1 coefficients (sends the light back) [C]. */
    HFVIS_VOLGI_REFLECT_MIRROR = 0,
    /* Alternative (b) of spec §2.5, "the new propagation direction is determined by the stored
     * average voxel normal": the arriving flux Phi = 2 sqrt(pi) c_0 is re-emitted as a cosine lobe
     * rho (Phi/pi) CC(+-n) about the normal, on the side the light came from (-n when the band-1
     * part of S_in points along +n, i.e. the light arrives from behind). Normal 0: an isotropic
     * re-emission of the same flux. Per band. */
    HFVIS_VOLGI_REFLECT_DIFFUSE = 1
} hfvis_volgi_reflection;

/* The reflectance rho of occupied voxels in the propagation (not the first bounce, whose albedo
 * is already in the injected radiance, nor the final gather, which uses the pixel's albedo). */
typedef enum hfvis_volgi_reflectance {
    HFVIS_VOLGI_REFLECTANCE_THESIS = 0,   /* default: 0.5 for every band ([G12] §5.6) */
    HFVIS_VOLGI_REFLECTANCE_CONSTANT = 1, /* options.reflectance, in [0, 1] (0: pure absorbers) */
    HFVIS_VOLGI_REFLECTANCE_ALBEDO = 2    /* the voxel's albedo (hfvis_volgi_geometry.albedo, which
                                             must then be given), per band: coloured bounces */
} hfvis_volgi_reflectance;

/* Which face-neighbour transfers carry light. */
typedef enum hfvis_volgi_paths {
    /* Default, spec §2.5's reference kernel: every voxel gathers from all six neighbours, also
     * an occupied voxel from an occupied one (spec §2.9: occupied sources emit into all six
     * directions). Side effect: the side lobes of a lit wall's VPLs land in the neighbouring
     * voxels of the same wall and are recorded there, so a lit surface receives a share of its
     * own light as "indirect" (about 4 x 0.146 of a VPL's flux per step). */
    HFVIS_VOLGI_PATHS_ALL = 0,
    /* "Energy is propagated only in void space, from one voxel boundary to the next" ([G12]
     * §5.5) read literally [C]: a transfer from voxel j to face neighbour i carries the weight
     * 1 - alpha_j alpha_i, so nothing passes between two occupied voxels (no light creeping
     * along or through surfaces). The held-back flux is reported as `blocked` (CONE) or given to
     * the open directions (CONE_NORMALIZED; all blocked: reported as blocked). */
    HFVIS_VOLGI_PATHS_VOID = 1
} hfvis_volgi_paths;

/* Options of every hfvis_volgi_* routine that has tunables. NULL or a zero struct = defaults. */
typedef struct hfvis_volgi_options {
    const hfvis_allocator *alloc;   /* scratch and internal BVH; NULL = malloc/free */
    int iterations;                 /* hfvis_volgi_render: propagation steps, 1..
                                       HFVIS_VOLGI_MAX_ITERATIONS; 0 = 64 */
    int resolution;                 /* hfvis_volgi_render without a grid: voxels along the
                                       longest side (hfvis_volgi_grid_fit), 2..2048; 0 = 32 */
    hfvis_volgi_transfer transfer;  /* default HFVIS_VOLGI_TRANSFER_CONE */
    hfvis_volgi_reflection reflection; /* default HFVIS_VOLGI_REFLECT_MIRROR */
    hfvis_volgi_reflectance reflectance_source; /* default HFVIS_VOLGI_REFLECTANCE_THESIS */
    hfvis_volgi_paths paths;        /* default HFVIS_VOLGI_PATHS_ALL */
    float reflectance;              /* with HFVIS_VOLGI_REFLECTANCE_CONSTANT: rho in [0, 1] */
    double gather_scale;            /* kappa of hfvis_volgi_gather, finite, > 0; 0 = 12/7 */
    double shadow_bias;             /* world distance a shadow ray skips at its start, finite,
                                       > 0; 0 = 1e-5 times the diagonal of the mesh's bounds */
} hfvis_volgi_options;

/* The defaults above, filled in (alloc NULL, iterations 64, resolution 32, CONE, MIRROR,
 * THESIS, ALL, reflectance 0.5, gather_scale 12/7, shadow_bias 0 = relative to the scene). */
HFVIS_API hfvis_volgi_options hfvis_volgi_options_default(void);

/* The parameters a call with opts uses (so that a port can print them): every 0 replaced by its
 * default, reflectance = the rho in use (0.5 for THESIS; unchanged for ALBEDO); shadow_bias stays
 * 0 when it is relative to the scene. opts may be NULL. Returns HFVIS_OK, or
 * HFVIS_ERR_INVALID_ARGUMENT for a NULL out or an invalid field (out untouched): an unknown enum,
 * iterations outside 0..HFVIS_VOLGI_MAX_ITERATIONS, resolution outside 0, 2..2048, a reflectance
 * outside [0, 1] with CONSTANT, a negative or non-finite gather_scale or shadow_bias. Every
 * hfvis_volgi_* routine that takes options rejects the same fields. */
HFVIS_API hfvis_status hfvis_volgi_options_resolve(const hfvis_volgi_options *opts,
                                                   hfvis_volgi_options *out);

/* ---- the geometry volume and the transport ------------------------------------------------ */

/* The read-only geometry volume (thesis: occupancy and average normal "compacted into a single
 * voxel value", plus an optional albedo), caller-owned arrays over grid's voxels, each in the
 * grid's linear order. Valid when grid is valid (hfvis_volume_grid), occupancy and normal are
 * not NULL, every occupancy is in [0, 1] (0 = empty; partial values are transparency: a fraction
 * 1 - alpha passes unchanged, [C]), every normal component is finite (any length: the mirror
 * axis and the diffuse side use its direction; 0 = no normal) and albedo is NULL or every value
 * is in [0, 1]. */
typedef struct hfvis_volgi_geometry {
    hfvis_volume_grid grid;
    const float *occupancy;  /* 1 float per voxel */
    const float *normal;     /* 3 floats per voxel (x, y, z) */
    const float *albedo;     /* 3 floats per voxel (R, G, B) or NULL */
} hfvis_volgi_geometry;

/* Energy accounting of one propagation step, per colour band, in flux units (2 sqrt(pi) c_0
 * summed over voxels, double). Exactly (up to float rounding of the stored volume):
 *   start = end + absorbed + escaped + blocked + uncovered - created.
 * created is 0 for every volume produced by hfvis_volgi_inject and the propagation (each voxel's
 * band-1 magnitude stays <= (2/sqrt 3) c_0, the bound of a cosine lobe, under which the six
 * clamped cone fluxes never exceed the voxel's flux); only arbitrary inputs (e.g. c_0 < 0) can
 * make it positive. With HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED uncovered is 0. */
typedef struct hfvis_volgi_energy {
    double start[3];      /* flux in prop_in */
    double end[3];        /* flux in prop_out */
    double absorbed[3];   /* alpha (1 - rho) Phi(S_in) at occupied voxels */
    double escaped[3];    /* fluxes sent across the grid's border (lost) */
    double blocked[3];    /* held back by the path weights (HFVIS_VOLGI_PATHS_VOID) */
    double uncovered[3];  /* sum over voxels of max(0, Phi_j - sent_j - blocked_j): outside the
                             six cones, not transported */
    double created[3];    /* sum over voxels of max(0, sent_j + blocked_j - Phi_j) */
    double deposited[3];  /* alpha Phi(S_in) added to the accumulation volume: the flux that
                             reached surfaces in this step */
} hfvis_volgi_energy;

/* VPL injection ([G12] §5.5.1, spec §2.4): prop[v] = L_v s^2 CC(n_v) per band for every voxel with
 * occupancy > 0, a non-zero normal and radiance L_v = radiance[3v..3v+2] (outgoing radiance of the
 * lit or emissive surface, >= 0), i.e. a cosine lobe carrying the flux pi L_v s^2 (s^2: the face
 * perpendicular to the normal's dominant axis); an occupied voxel without a normal gets the
 * isotropic lobe of the same flux (c_0 only); every other voxel gets 0. The whole of prop is
 * written (12 floats per voxel, see Conventions). prop must not overlap the inputs.
 * Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for NULL, an invalid geometry or a radiance that
 * is negative, not finite or above HFVIS_VOLGI_MAX_VALUE (prop untouched). Allocates nothing.
 * Cost O(voxels). */
HFVIS_API hfvis_status hfvis_volgi_inject(const hfvis_volgi_geometry *geometry,
                                          const float *radiance, float *prop);

/* One propagation step (eq. 11 with the reference kernel of spec §2.5), by gathering at each
 * voxel i from its six face neighbours j = i - o, o in the order +x, -x, +y, -y, +z, -z:
 *   S_in = sum_o (F_o(j)/pi) CC(o)     (F: see hfvis_volgi_transfer; neighbours outside the grid
 *                                       send nothing, light sent out of the grid is lost)
 *   empty voxel (alpha = 0):  prop_out[i] = S_in                        (T_r = 1)
 *   occupied:                 accum[i] += alpha S_in
 *                             prop_out[i] = (1 - alpha) S_in + alpha rho R(S_in)
 * with R the reflection of opts->reflection and rho of opts->reflectance_source. Occupied source
 * voxels emit into all six directions too (spec §2.9). accum is added to (clear it before the
 * first step: the thesis' A starts at zero, so direct light is not in A). energy may be NULL;
 * otherwise it receives the step's accounting (one extra pass over prop_in).
 * prop_in and accum must not overlap prop_out; prop_in may not overlap accum.
 * With HFVIS_VOLGI_PATHS_VOID every transfer j -> i is weighted by 1 - alpha_j alpha_i.
 * Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for NULL arrays, an invalid geometry, invalid
 * options (hfvis_volgi_options_resolve; also HFVIS_VOLGI_REFLECTANCE_ALBEDO without albedo), or a
 * prop_in or accum value that is not finite or above HFVIS_VOLGI_MAX_VALUE in magnitude;
 * HFVIS_ERR_LIMIT when an SH volume of the grid would exceed SIZE_MAX bytes (32-bit builds);
 * outputs untouched then. Allocates nothing with the default transfer; the normalised transfer
 * allocates one block of 24 bytes per voxel (HFVIS_ERR_OUT_OF_MEMORY). The inputs are checked
 * on every call (O(voxels), about a quarter of a step): use hfvis_volgi_propagate for loops.
 * Cost: O(voxels); about 6 x 3 x 4 floating-point operations and 7 voxel reads per voxel.
 * Exact: equals hfvis_volgi_propagate_step_reference bit for bit. */
HFVIS_API hfvis_status hfvis_volgi_propagate_step(const hfvis_volgi_geometry *geometry,
                                                  const hfvis_volgi_options *opts,
                                                  const float *prop_in, float *prop_out,
                                                  float *accum, hfvis_volgi_energy *energy);

/* Oracle of hfvis_volgi_propagate_step: spec §2.5's pseudo-code literally, per voxel and
 * direction with the full 4-coefficient products P_j . Cone(o) and (F/pi) CC(o) (the vectors of
 * hfvis_volgi_sh_cone and hfvis_volgi_sh_clamped_cosine along the six axes), and for the
 * normalised transfer all six cone fluxes of j recomputed for every (i, o). Same arguments,
 * results (bit for bit) and errors; allocates nothing. Cost: several times the fast step. */
HFVIS_API hfvis_status hfvis_volgi_propagate_step_reference(const hfvis_volgi_geometry *geometry,
                                                            const hfvis_volgi_options *opts,
                                                            const float *prop_in, float *prop_out,
                                                            float *accum,
                                                            hfvis_volgi_energy *energy);

/* `iterations` propagation steps (hfvis_volgi_propagate_step each, ping-pong through one scratch
 * volume): on return prop holds the light still travelling and accum has every step's arrivals
 * added (multiple bounces: light reflected at occupied voxels goes on propagating). On an N-grid
 * with walls N voxels apart k bounces need about kN steps ([G12] §5.6). energy: NULL or an array
 * of `iterations` entries, one per step. iterations 0 returns HFVIS_OK without touching anything.
 * Returns the errors of hfvis_volgi_propagate_step plus HFVIS_ERR_INVALID_ARGUMENT for
 * iterations outside 0..HFVIS_VOLGI_MAX_ITERATIONS, HFVIS_ERR_OUT_OF_MEMORY; prop, accum and
 * energy untouched on error. Memory: one block of 48 bytes per voxel (plus 24 for the normalised
 * transfer). The inputs are checked once. Cost: iterations x one step. */
HFVIS_API hfvis_status hfvis_volgi_propagate(const hfvis_volgi_geometry *geometry,
                                             const hfvis_volgi_options *opts, int iterations,
                                             float *prop, float *accum,
                                             hfvis_volgi_energy *energy);

/* Final gather ([G12] §5.5.3, eqs. 12-15, spec §2.6) at a surface point with unit normal n
 * (normalised here): with g = (p - origin)/cell - 1/2, b = floor(g), f = g - b, the trilinear
 * weights of the 8 voxels b + {0,1}^3 are applied to accum over those inside the grid with
 * occupancy > 0 only ("from the eight closest grid points only the ones corresponding to occupied
 * voxels are considered") and renormalised by their sum; then per band
 *   E = (kappa / s_n^2) max(0, L . CC(-n))
 * (A is indexed by travel direction, so light arriving at the surface travels along -n).
 * s_n^2 is the grid face perpendicular to n's dominant axis: accum holds flux, E is irradiance.
 * kappa = opts->gather_scale (default 12/7 = 1/(7/12), the SH self-product of the clamped cosine
 * over pi: a flux F arriving head on as the lobe (F/pi) CC(-n) gives exactly F/s^2). The
 * absolute scale is the library's choice: the thesis gives none. Accuracy (measured in the
 * tests): two parallel plates 9 voxels apart, emitter radiance L, absorbing receiver; the exact
 * irradiance at the receiver's centre is 0.858 pi L, this method gives 0.9 % of it with the
 * CONE transfer (each step forwards only (3 - sqrt 2)/4 of a lobe along its axis and spreads the
 * rest sideways, where the 45-degree cones lose a share), 10.5 % with CONE_NORMALIZED and 26 %
 * with CONE_NORMALIZED and HFVIS_VOLGI_PATHS_VOID: the transport is a diffusion over a few voxels,
 * good for relative, short-range effects (colour bleeding, contact light), not for absolute
 * radiometry. No occupied voxel among the 8:
 * E = 0. Outgoing indirect radiance is albedo E / pi (DESIGN §2).
 * Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for NULL, an invalid geometry (not re-checked
 * per value: O(1) call; the arrays are only read at the 8 voxels), a non-finite point, a zero or
 * non-finite normal, invalid options. Allocates nothing. */
HFVIS_API hfvis_status hfvis_volgi_gather(const hfvis_volgi_geometry *geometry,
                                          const float *accum, const hfvis_volgi_options *opts,
                                          const double point[3], const double normal[3],
                                          float irradiance[3]);

/* ---- scene, direct light, voxelization with direct light, the whole pipeline --------------- */

typedef enum hfvis_volgi_light_type {
    HFVIS_VOLGI_LIGHT_POINT = 0,       /* at position; radiant intensity I: E = I cos / d^2 */
    HFVIS_VOLGI_LIGHT_SPOT = 1,        /* a point light times the spot factor about direction */
    HFVIS_VOLGI_LIGHT_DIRECTIONAL = 2  /* travelling along direction; intensity = irradiance on a
                                          surface facing it: E = I max(0, -n.d) */
} hfvis_volgi_light_type;

/* A light. Spot factor: 1 within spot_inner_rad of the axis, 0 beyond spot_outer_rad, linear in
 * the cosine of the angle in between (a hard edge when they are equal), 0 <= inner <= outer <= pi,
 * outer > 0. */
typedef struct hfvis_volgi_light {
    hfvis_volgi_light_type type;
    double position[3];     /* point, spot: world position (finite) */
    double direction[3];    /* spot: axis; directional: the direction the light travels; finite,
                               not zero (normalised here) */
    float intensity[3];     /* RGB, finite, >= 0: W/sr (point, spot) or W/m^2 (directional) */
    double spot_inner_rad, spot_outer_rad;
} hfvis_volgi_light;

/* A lit scene: a mesh with per-triangle materials and lights. Direct light is one-sided: a
 * triangle is lit on its front side only (normal (v1 - v0) x (v2 - v0), hfvis_mesh), from lights
 * it sees; shadows by BVH shadow rays (not shadow maps: exact, no bias map). */
typedef struct hfvis_volgi_scene {
    const hfvis_mesh *mesh;
    const float *albedo;    /* 3 floats per triangle in [0, 1], or NULL = 1 (white) */
    const float *emission;  /* 3 floats per triangle, emitted radiance >= 0, or NULL = none */
    const hfvis_volgi_light *lights;
    int light_count;        /* 0..HFVIS_VOLGI_MAX_LIGHTS (lights may be NULL when 0) */
    const hfvis_bvh *bvh;   /* the mesh's BVH (hfvis_bvh_build), or NULL: the routines that need
                               one build it with opts->alloc (hfvis_volgi_direct_irradiance
                               requires it) */
} hfvis_volgi_scene;

/* Direct irradiance E (RGB, W/m^2) at a surface point with normal n (normalised here) from the
 * scene's lights, with shadows: for each light, E += I_eff max(0, n.l) (/ d^2 for point and spot
 * lights) when the shadow ray from point toward the light (BVH any-hit, both faces block, for
 * t in [bias, d - bias], bias = opts->shadow_bias or 1e-5 times the diagonal of the BVH's root
 * box) meets no triangle other than skip_triangle (the receiver's own triangle, or
 * HFVIS_NO_TRIANGLE); directional lights: t in [bias, infinity) along -direction. A receiver
 * within 2 bias of a point or spot light gets nothing from it.
 * scene->bvh must be the mesh's BVH; the mesh is not re-checked (O(lights x log T) per call).
 * Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for NULL, a NULL bvh or one whose
 * triangle_count differs from the mesh's, an invalid light, non-finite point or normal, a zero
 * normal, invalid options; irradiance untouched then. Allocates nothing. */
HFVIS_API hfvis_status hfvis_volgi_direct_irradiance(const hfvis_volgi_scene *scene,
                                                     const hfvis_volgi_options *opts,
                                                     const double point[3],
                                                     const double normal[3],
                                                     uint32_t skip_triangle, float irradiance[3]);

/* A grid for the room-like scenes of this section: cubic voxels of side ext/(resolution - 1),
 * ext = the longest side of the bounds of the vertices the triangles use, so that the two bounding
 * planes of that side pass through voxel CENTRES (a wall in the middle of its voxel layer, not on
 * a voxel boundary where rounding picks the side); the other axes get round(ext_a/s) + 1 voxels,
 * centred on the bounds. resolution = the voxels along the longest side. Returns HFVIS_OK, or
 * HFVIS_ERR_INVALID_ARGUMENT for NULL, an invalid mesh, no triangles, a zero extent, resolution
 * outside 2..HFVIS_VOLGI_MAX_RESOLUTION; HFVIS_ERR_LIMIT past HFVIS_VOLUME_MAX_VOXELS. */
HFVIS_API hfvis_status hfvis_volgi_grid_fit(const hfvis_mesh *mesh, int resolution,
                                            hfvis_volume_grid *out);

/* Voxelization with direct lighting ([G12] ch. 5 Alg. 4, spec §2.3): hfvis_voxelize_surface with
 * HFVIS_AXES_ALL (the x, y and z slicing passes, pixel-centre rule) over scene->mesh, where each
 * fragment at position p on triangle t with normal n_t writes
 *   radiance = albedo_t E_direct(p, n_t)/pi + emission_t   (hfvis_volgi_direct_irradiance)
 * merged per channel with MAX over every fragment of the voxel (the thesis' MAX blend, also the
 * MAX merge of the three per-axis volumes), and the normal and albedo AVERAGED over the voxel's
 * fragments ([C], spec §2.9; the GPU's MAX merge of normals is biased). Outputs, each over the
 * grid's voxels in linear order, caller-owned, written entirely: occupancy (1 floats per voxel:
 * 1 where a fragment landed, else 0), normal (3: unit average, 0 where the fragments' normals
 * cancel or the voxel is empty), albedo (3; may be NULL), radiance (3). fragments (may be NULL)
 * receives the number of fragments. The outputs form a hfvis_volgi_geometry for grid.
 * Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for NULL (other than albedo, fragments), an
 * invalid mesh, grid, light, material value (albedo outside [0, 1], negative or non-finite
 * emission), options, or a scene->bvh that does not match the mesh's triangle count;
 * HFVIS_ERR_LIMIT for a mesh past HFVIS_BVH_MAX_TRIANGLES; HFVIS_ERR_OUT_OF_MEMORY. Outputs
 * untouched on error. Memory: one block of 40 bytes per voxel, plus the BVH's four blocks
 * (hfvis_bvh_build) when scene->bvh is NULL. Cost: O(T + fragments x lights x shadow ray). */
HFVIS_API hfvis_status hfvis_volgi_voxelize(const hfvis_volgi_scene *scene,
                                            const hfvis_volume_grid *grid,
                                            const hfvis_volgi_options *opts, float *occupancy,
                                            float *normal, float *albedo, float *radiance,
                                            size_t *fragments);

/* Per-pixel RGB outputs of hfvis_volgi_render, each 3 floats per pixel (pixel (x, y) at
 * 3*(y*width + x), row 0 at the top, hfvis_view), or NULL when not wanted; they must not overlap.
 * Outgoing radiance toward the camera (Lambertian, DESIGN §2); empty pixels get 0. */
typedef struct hfvis_volgi_outputs {
    float *direct;    /* emission + albedo E_direct / pi (with shadow rays per pixel) */
    float *indirect;  /* albedo E_indirect / pi (hfvis_volgi_gather) */
    float *total;     /* direct + indirect */
} hfvis_volgi_outputs;

/* What hfvis_volgi_render did (may be NULL). */
typedef struct hfvis_volgi_render_info {
    hfvis_volume_grid grid;  /* the grid used */
    size_t fragments;        /* voxel fragments of Alg. 4 */
    size_t occupied;         /* occupied voxels */
    size_t covered_pixels;   /* pixels showing a triangle */
    double injected[3];      /* flux of the VPLs (per band) */
    double deposited[3];     /* flux recorded in the accumulation volume over all iterations */
    double remaining[3];     /* flux still travelling after the last iteration */
} hfvis_volgi_render_info;

/* The whole pipeline for one view: G-buffer (hfvis_rasterize: triangle id, barycentrics, world
 * normal; no culling) -> voxelization with direct light (hfvis_volgi_voxelize over grid, or, when
 * grid is NULL, over hfvis_volgi_grid_fit(mesh, opts->resolution)) -> VPL injection ->
 * opts->iterations propagation steps (hfvis_volgi_propagate with opts) -> per covered pixel, at
 * the exact surface point (from the barycentrics) with the face normal of its triangle (the lit
 * side is the front side, hfvis_volgi_scene; a back face seen by the camera is shaded as what it
 * is, the unlit side):
 *   direct = emission + albedo E_direct/pi   (shadow rays, hfvis_volgi_direct_irradiance),
 *   indirect = albedo E_indirect/pi          (hfvis_volgi_gather),
 *   total = direct + indirect                (the two floats added in double, rounded once).
 * Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT (NULL scene, view or outputs; every output NULL
 * is fine), the errors of hfvis_rasterize (invalid view: HFVIS_ERR_INVALID_ARGUMENT; width or
 * height > HFVIS_RASTER_MAX_SIZE: HFVIS_ERR_LIMIT), hfvis_volgi_grid_fit, hfvis_volgi_voxelize and
 * hfvis_volgi_propagate, HFVIS_ERR_OUT_OF_MEMORY; outputs and info untouched on error.
 * Memory (opts->alloc), in this order: a G-buffer block of 24 bytes per pixel and the
 * rasterizer's scratch; the BVH when scene->bvh is NULL (hfvis_bvh_build: four blocks, two kept
 * until return); the geometry block (40 bytes per voxel); the voxelizer's scratch (40 bytes per
 * voxel, freed before the next); the P and A volumes (96 bytes per voxel); the propagation's
 * scratch (48 bytes per voxel, + 24 normalised): 6 blocks with a scene BVH, 10 without.
 * Cost: the voxelization, iterations x voxels, and per pixel (lights shadow rays + 8 voxel reads).
 * Deterministic (bit-exact on one build). */
HFVIS_API hfvis_status hfvis_volgi_render(const hfvis_volgi_scene *scene,
                                          const hfvis_volume_grid *grid, const hfvis_view *view,
                                          const hfvis_volgi_options *opts,
                                          const hfvis_volgi_outputs *outputs,
                                          hfvis_volgi_render_info *info);
