
/* ========================================================================================== */
/* hfvis.c - Nowrouzezahrai-Snyder GI pipeline ([NS09] §5-9; spec GI B.2, B.4-B.9, B.12)     */
/* ========================================================================================== */
/* The approximate, fast counterpart of the exact P1/P2 pipeline (hfvis_direct_light,
 * hfvis_terrain_gi): per receiver, m azimuthal slices are scanned with exponentially growing
 * steps over a multi-resolution height pyramid ([NS09] §5.2, Eq. 14-17); each slice's visibility
 * and indirect radiance become order-4 normalized Legendre (NLP) vectors (Eq. 10-12), which the
 * Appendix-A wedge matrices turn into order-4 SH (Eq. 18-21); shading is an SH dot product with a
 * diffuse or Phong zonal lobe (§7); each bounce gathers the previous bounce's exit radiance from a
 * radiance pyramid (§5.3). Conventions are those of the math layer above (SH without the
 * Condon-Shortley phase, Ahat multipliers, NLP in z = sin(omega)) and of the whole API
 * (DESIGN radiance: an open flat receiver under a uniform sky c with albedo 1 returns c).
 *
 * Slices (spec GI B.2, B.4). A receiver at grid position (x, y) looking toward
 * phi_j = azimuth0_rad + 2 pi j/m (phi measured like psi, from +x toward +y) takes steps
 * tau_i = 2^(i/k) cells, i = 0..n-1 (Eq. 14 in cell units); step i reads level
 * l_v(i) = max(0, i - k*o_v) of the height pyramid at the receiver and at the step point (Eq. 15:
 * both heights from the same level; the level offset makes the level finer by o_v octaves, the
 * spec GI B.4 erratum) and gives the blocking angle omega_i = atan(dz / (tau_i cell_size)).
 * omega_max is the maximum of the uniform cubic B-spline through the omega_i at its knots and
 * midpoints (Eq. 16, end points replicated) or the raw maximum; the casting set holds the steps
 * whose omega_i exceeds every earlier one and the tangent-plane angle omega_min (Eq. 17; admitted
 * when larger by more than 1e-12 rad). Steps outside the grid (HFVIS_BORDER_OPEN: the ray ends
 * there) and steps whose height is a hole are skipped: they neither occlude nor cast.
 *
 * The pyramid (spec GI B.4, CPU proposal). Octave images G_0 = the heights, G_(o+1) = G_o
 * filtered with the separable [1,3,3,1]/8 kernel and decimated by 2 (texel i of G_(o+1) is centred
 * between texels 2i and 2i+1 of G_o); level l = k*o + j (0 <= j < k) is G_o convolved with a
 * separable, sampled, normalised cubic B-spline kernel whose variance is (4^(j/k) - 1)/4 G_o
 * texels^2, so the blur grows smoothly and reaches 3/4 (the decimation's) as j -> k; level 0 is the
 * heights exactly. Levels are sampled bilinearly in octave coordinates. Filter taps outside the
 * image follow the border (OPEN: dropped, CLAMP: edge texel, WRAP: periodic) and hole taps are
 * dropped, the weights renormalised (a level texel with no finite tap is a hole). The same pyramid
 * holds the exit radiance of a bounce (spec GI B.5) with levels l_u(i) = max(0, i - k*o_u).
 * Memory: about (4/3) k W H floats per channel, not the paper's stack of n full-size textures.
 *
 * Outputs are radiance toward the viewer (view_dir): direct = emission + (albedo/pi) E_direct +
 * specular * glossy_direct; bounce b = (albedo/pi) E_b + specular * glossy_b, E_b the irradiance
 * from the SH incident radiance U_b gathered from the exit radiance of bounce b-1; total = direct +
 * the bounces. For a diffuse surface this is, bounce by bounce, the recursion
 * L_B = emission + albedo (D + I[L_(B-1)]) of hfvis_terrain_gi. How close it comes to the exact
 * pipeline is measured in test_gi2.c against hfvis_sky_light and hfvis_indirect_light (P1/P2)
 * and printed by the bench. */

/* How omega_max is taken from a slice's blocking angles. */
typedef enum hfvis_ns_omega_max {
    HFVIS_NS_OMEGA_MAX_DEFAULT = 0,  /* = BSPLINE */
    HFVIS_NS_OMEGA_MAX_BSPLINE = 1,  /* [NS09] Eq. 16 (smooths: lowers isolated spikes) */
    HFVIS_NS_OMEGA_MAX_RAW = 2       /* max_i omega_i (spec GI B.4 [choice]; with it the closure
                                        identity of B.13-9 is exact) */
} hfvis_ns_omega_max;

/* Directional lights (hfvis_sun with radius_rad == 0), spec GI B.8 [choice]. */
typedef enum hfvis_ns_directional {
    HFVIS_NS_DIRECTIONAL_DEFAULT = 0,  /* = HARD */
    HFVIS_NS_DIRECTIONAL_HARD = 1,     /* E0 max(N.d, 0) [omega_L > omega_max(phi_L)], from one more
                                          slice scan toward the light */
    HFVIS_NS_DIRECTIONAL_SOFT = 2,     /* the indicator replaced by clamp(v(phi_L) . P^(sin omega_L),
                                          0, 1): the NLP-smoothed step of the slice toward the light.
                                          The order-4 NLP rings near the zenith: an open flat
                                          receiver gets 13/16 = 0.8125 of a zenith light */
    HFVIS_NS_DIRECTIONAL_SH = 3        /* the SH delta E0 Y(d) times the HARD indicator, shaded
                                          through SH like the environment; rings:
                                          E = E0 (1/4 + cos(g)/2 + (5/16) P_2(cos g)), 17/16 E0 at
                                          g = 0 (spec GI B.13-8) */
} hfvis_ns_directional;

/* Key lights (hfvis_sun with radius_rad > 0): uniform circular caps ([NS09] §6-7, spec GI B.8). */
typedef enum hfvis_ns_key_mode {
    HFVIS_NS_KEY_DEFAULT = 0,      /* = SEPARATE */
    HFVIS_NS_KEY_SEPARATE = 1,     /* own visibility V_key over the cap's azimuth extent
                                      (key_directions samples, key_directions - 1 wedges; the full
                                      circle with the environment's slices when the cap holds the
                                      zenith) and elevation range [l_min, l_max] (§6); the incident
                                      radiance gains the SH product L_key * V_key (spec B.8). Note:
                                      order-4 SH cannot hold the narrow box V_key, and the product
                                      loses most of a small light's energy even where nothing
                                      occludes it (a cap of radius 0.3 rad at 40 deg elevation
                                      delivers 29% of its irradiance to open flat ground) */
    HFVIS_NS_KEY_ENVIRONMENT = 2,  /* folded into the environment: L_key * V (faster, softer) */
    HFVIS_NS_KEY_RATIO = 3         /* [choice, not in [NS09]] V_key as in SEPARATE, used only as a
                                      shadow factor: f = clamp(Int L V_key / Int L V_box, 0, 1),
                                      V_box the unoccluded restricted visibility (dot products of
                                      the SH vectors), and the incident radiance gains f L_key: open
                                      ground gets the light's full SH irradiance */
} hfvis_ns_key_mode;

/* Glossy interreflection (spec GI B.5). */
typedef enum hfvis_ns_glossy {
    HFVIS_NS_GLOSSY_DEFAULT = 0,   /* = VECTOR */
    HFVIS_NS_GLOSSY_VECTOR = 1,    /* two pyramids: the diffuse exit radiance, and the incident
                                      SH I_(b-1) (16 per channel, at the receiver resolution); a
                                      remote point q sends specular * max(F_q(s) . I_(b-1)(q), 0)
                                      toward the receiver on top of its diffuse exit radiance,
                                      F_q the Phong lobe about the reflection of s = normalize(p - q)
                                      in q's full-resolution normal ([NS09] §5.3 "non-diffuse") */
    HFVIS_NS_GLOSSY_SCALAR = 2     /* one scalar pyramid of the shade toward the viewer (diffuse +
                                      glossy): [NS09] §5.3's "mixture" approximation */
} hfvis_ns_glossy;

/* Keeping the casting sets between passes (spec B.9 [choice] "cache cast sets for bounces"). */
typedef enum hfvis_ns_cache {
    HFVIS_NS_CACHE_DEFAULT = 0,    /* = ON */
    HFVIS_NS_CACHE_ON = 1,         /* the first scan of each slice (the visibility scan of the direct
                                      pass, or the first bounce) records its casting set as a bit
                                      mask of steps; later bounces re-read only those steps: same
                                      result, bit for bit, at ceil(n/64)*8 bytes per receiver and
                                      slice (1024^2, m = 32, n <= 64: 256 MiB; 2x2: 64 MiB) */
    HFVIS_NS_CACHE_OFF = 2         /* every bounce scans every slice again */
} hfvis_ns_cache;

/* level_offset_v / level_offset_u value for "no offset" (0 octaves; 0 itself means the default). */
#define HFVIS_NS_NO_OFFSET (-1)

/* Limits of the options (larger values are HFVIS_ERR_INVALID_ARGUMENT). */
#define HFVIS_NS_MAX_DIRECTIONS 4096
#define HFVIS_NS_MAX_KEY_DIRECTIONS 256
#define HFVIS_NS_MAX_LEVELS_PER_OCTAVE 32
#define HFVIS_NS_MAX_LEVELS 1024
#define HFVIS_NS_MAX_LEVEL_OFFSET 64
#define HFVIS_NS_MAX_SUBSAMPLE 64
#define HFVIS_NS_MAX_LIGHTS 64

/* Options of hfvis_ns_gi. NULL or a zeroed struct means every default. */
typedef struct hfvis_ns_gi_options {
    int directions;          /* m: azimuthal slices over the full circle (environment and
                                indirect light), 1..4096; 0 = 32 ([NS09] §9) */
    int key_directions;      /* azimuthal samples over a key light's partial extent, 2..256;
                                0 = 3 ([NS09] §9) */
    int levels_per_octave;   /* k = k_v = k_u (Eq. 14), 1..32; 0 = 4 */
    int levels;              /* n = n_v = n_u: steps per slice, 1..1024; 0 = auto:
                                1 + ceil(k log2(max(1, hypot(width-1, height-1)))), so the last
                                step reaches the grid's diagonal (spec GI B.4's 1 + k log2 R, plus
                                at most k/2 + 1 steps) */
    int level_offset_v;      /* o_v, octaves, 1..64; 0 = 2 ([NS09] §5.2); HFVIS_NS_NO_OFFSET = 0 */
    int level_offset_u;      /* o_u, likewise, for the radiance pyramid; 0 = 2 */
    int sh_order;            /* SH order o, 1..4 (bands l < o kept in V, U, the lights and the
                                lobes); 0 = 4. The NLP vectors stay order 4. */
    int subsample;           /* s: V, U computed for one receiver per s x s block (at the block
                                centre, clamped to the grid) and bilinearly upsampled; shading
                                uses full-resolution normals ([NS09] §7), 1..64; 0 = 1 */
    hfvis_ns_interp interp;           /* azimuthal interpolation; default LINEAR */
    hfvis_ns_omega_min omega_min;     /* tangent-plane angle; default EXACT (atan2 form) */
    hfvis_ns_omega_max omega_max;     /* default BSPLINE (Eq. 16) */
    int clamp_to_tangent;    /* 1: slice visibility starts at max(omega_max, omega_min) (spec GI
                                B.3 [choice]); 0 = off, as [NS09] (the lobe's clamped cosine
                                removes the light from below the tangent plane, approximately) */
    hfvis_ns_directional directional; /* default HARD */
    hfvis_ns_key_mode key_mode;       /* default SEPARATE */
    hfvis_ns_glossy glossy;           /* default VECTOR */
    hfvis_ns_cache cast_cache;        /* default ON (only used with bounces) */
    double view_dir[3];      /* unit vector from the surface toward the viewer (distant
                                viewer; normalised here); 0,0,0 = (0, 0, 1), looking straight down.
                                Only the glossy terms depend on it. */
    hfvis_border border;     /* default OPEN */
    double azimuth0_rad;     /* phi_0 of slice 0 */
    const hfvis_allocator *alloc;    /* scratch; NULL = malloc/free */
    hfvis_progress_fn progress;      /* optional: called after each receiver row of each pass,
                                        total = receiver rows * (1 + bounces) */
    void *progress_user;
} hfvis_ns_gi_options;

/* The defaults, filled in (levels stays 0 = auto: it depends on the grid). */
HFVIS_API hfvis_ns_gi_options hfvis_ns_gi_options_default(void);

/* The options hfvis_ns_gi uses for this grid: every default resolved (levels computed, enums
 * made explicit, view_dir normalised; level offsets of "none" stay HFVIS_NS_NO_OFFSET), so a
 * port can print the exact parameters. in may be NULL. Returns HFVIS_OK, or
 * HFVIS_ERR_INVALID_ARGUMENT for an invalid grid, a NULL out or an invalid option. */
HFVIS_API hfvis_status hfvis_ns_gi_options_resolve(const hfvis_grid *grid,
                                                   const hfvis_ns_gi_options *in,
                                                   hfvis_ns_gi_options *out);

/* What is lit, and how it reflects. */
typedef struct hfvis_ns_scene {
    int channels;                /* C, 1..4 */
    const double *env_sh;        /* environment radiance as SH, env_sh[c*16 + i] (e.g. from
                                    hfvis_sh_project_env; a uniform sky c is 2 sqrt(pi) c at
                                    i = 0), or NULL for none */
    const hfvis_sun *lights;     /* light_count lights (azimuth = look direction toward the light,
                                    elevation in [-pi/2, pi/2], irradiance[c] on a surface facing
                                    it): radius_rad == 0 is a directional light, 0 < radius_rad
                                    <= pi/2 a key light (a uniform cap of radiance
                                    irradiance / (pi sin^2 radius)). NULL if light_count is 0. */
    int light_count;             /* 0..64 */
    float albedo[4];             /* diffuse albedo per channel (first C used) */
    const float *albedo_map;     /* or per sample: albedo_map[(y*width + x)*C + c]; NULL = albedo */
    const float *emission;       /* emitted radiance per sample, same layout, or NULL */
    float specular;              /* Phong specular weight, >= 0 (0 = diffuse only) */
    float shininess;             /* Phong exponent S > 0 (used when specular > 0): the lobe
                                    ((S+1)/(2 pi)) cos^S about the reflection vector, in SH its
                                    multipliers exp(-l^2/(2S)) (hfvis_zh_phong) */
} hfvis_ns_scene;

/* Where the results go (each pointer may be NULL). Layout [(y*width + x)*C + c], width stride;
 * bounce plane b-1 (b = 1..bounces) at bounce + (b-1)*width*height*C; visibility[(j*rw + i)*16 + r]
 * for receiver (i, j) of the rw x rh receiver grid, rw = ceil(width/s), rh = ceil(height/s). */
typedef struct hfvis_ns_gi_outputs {
    int bounces;                 /* B >= 0 indirect bounces */
    float *direct;               /* width*height*C: emission + direct light */
    float *bounce;               /* bounces*width*height*C: the radiance each bounce adds */
    float *total;                /* width*height*C: direct + every bounce */
    float *visibility;           /* 16*rw*rh: the environment visibility SH V (Eq. 21) per
                                    receiver, for diffing a port; NaN at receivers on holes */
} hfvis_ns_gi_outputs;

/* Multi-resolution height-field global illumination ([NS09]; spec GI B.9 RENDER).
 * Per receiver (one per s x s block): m slices (Eq. 15-17) give V = Sum_j G_j v_j with
 * v_j = vbar(pi/2) - vbar(omega_max,j) (Eq. 11), G_j the wedge matrices rotated into place
 * (hfvis_ns_sample_matrices; m wedges with the wrap-around one); key lights add their restricted
 * V_key; the incident radiance is I_0 = L_env * V + Sum L_key * V_key (SH products), plus the
 * directional lights. Per bounce b the casting sets are scanned again and the exit radiance of
 * bounce b-1 read from the radiance pyramid at level l_u(i) (Eq. 12) gives U_b. Every texel is
 * shaded with its own full-resolution normal (hfvis_normals_compute) from V, V_key, U_b
 * bilinearly upsampled over the receivers (renormalised over receivers that are not holes; a texel
 * with none around is computed as a receiver of its own): diffuse E = (Ahat_diffuse Y(N)) . I,
 * glossy (Ahat_phong Y(R)) . I with R = reflect(view_dir, N).
 * Exact cases (tested): an open flat field under a uniform sky c returns albedo*c for any m,
 * interp, k, n, offsets and s (bands 0 and 1 of the hemisphere are exact, spec GI B.13-7); a
 * V-shaped valley's bottom reproduces the order-4 trench values of B.13-9; emission 1 with a black
 * sky and raw omega_max closes the furnace: direct(sky 1) + bounce(emission 1) = 1.
 * Holes: a non-finite height never occludes, is never in a casting set, and gets NaN in every
 * output. Lighting below the tangent plane and SH ringing are not clamped (spec GI B.12-8): outputs
 * can be slightly negative.
 * grid: valid (hfvis_grid). scene: see hfvis_ns_scene. opts may be NULL. out: non-NULL; outputs
 * must not overlap each other or the inputs.
 * Returns HFVIS_OK, HFVIS_ERR_INVALID_ARGUMENT for NULL grid/scene/out, an invalid grid, a bad
 * option, channels outside 1..4, a non-finite env_sh value, a light with a non-finite field, an
 * elevation outside [-pi/2, pi/2] or a radius outside [0, pi/2], more than 64 lights, a non-finite
 * albedo, specular < 0 or non-finite, shininess <= 0 or non-finite with specular > 0, a
 * non-finite albedo_map / emission value at a sample that is not a hole, bounces < 0, or sizes that
 * overflow size_t; HFVIS_ERR_OUT_OF_MEMORY (nothing written, nothing leaked).
 * Allocates at most 4 blocks (hfvis_ns_gi_scratch_size bytes): tables, height pyramid and
 * normals, two receiver rows, and (with bounces) the casting-set cache and radiance pyramids.
 * Cost: O(rw rh (m + key samples + directional lights) n) for the direct pass (about 20 ns per
 * step on one 2020s core) and O(rw rh m K C) per bounce with the cache (K the casting-set size;
 * x16 with VECTOR glossy), plus O(W H C 256) shading. Deterministic.
 * Accuracy (measured, test_gi2.c and the bench, fBm terrains): with the defaults, the direct light
 * of a uniform sky is within 1.4-2.3% RMS of P1's (hfvis_sky_light), of which about 1.8% is the
 * order-4 SH truncation itself (the SH projection of the exact horizons is that far from P1); one
 * bounce is within 0.016 (unit sky) RMS of P2's hfvis_indirect_light; hard sun shadows differ from
 * hfvis_sun_visibility at 3-4% of the pixels (exponential steps miss thin ridges; P1 itself differs
 * from a fine ray march at 4.7%). Full-frame RMS against the exact pipeline: 5-7% of the mean. */
HFVIS_API hfvis_status hfvis_ns_gi(const hfvis_grid *grid, const hfvis_ns_scene *scene,
                                   const hfvis_ns_gi_options *opts,
                                   const hfvis_ns_gi_outputs *out);

/* Bytes of scratch hfvis_ns_gi allocates for these arguments (the sum of its blocks, all live at
 * once: its peak), the "memory" of [NS09] Table 1 without the caller's outputs. bounces >= 0.
 * Same validation as hfvis_ns_gi (outputs are not needed). */
HFVIS_API hfvis_status hfvis_ns_gi_scratch_size(const hfvis_grid *grid, const hfvis_ns_scene *scene,
                                                const hfvis_ns_gi_options *opts, int bounces,
                                                size_t *bytes);

/* [NS09] Eq. 16: the maximum of the uniform cubic B-spline with control points omega[0..n-1]
 * (radians), evaluated at the knots S(j) = (w_(j-1) + 4 w_j + w_(j+1))/6 and the midpoints
 * S(j+1/2) = (w_(j-1) + 23 w_j + 23 w_(j+1) + w_(j+2))/48, end points replicated
 * (w_(-1) = w_0, w_n = w_(n-1); spec GI B.4 [choice]). n = 0 gives -pi/2 (nothing blocks).
 * Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT for a NULL out, n < 0, NULL omega with n > 0 or
 * a non-finite omega. Cost O(n). */
HFVIS_API hfvis_status hfvis_ns_bspline_max(int n, const double *omega_rad, double *out);

/* The per-sample form of [NS09] Eq. 20-21: G[(j*16 + r)*4 + k] such that
 * hfvis_ns_wedges_to_sh(set, w) = Sum_j G_j w_j (G_j a 16x4 matrix, r the SH index, k the NLP
 * index): each wedge matrix block is rotated into place once, Rot_z(M_s, phi_wedge), and added to
 * the sample it reads, so a slice costs 64 multiply-adds and no rotation. Equal to
 * hfvis_ns_wedges_to_sh up to rounding. G must hold 64*set->samples doubles.
 * Returns HFVIS_OK, or HFVIS_ERR_INVALID_ARGUMENT as hfvis_ns_wedges_to_sh. */
HFVIS_API hfvis_status hfvis_ns_sample_matrices(const hfvis_ns_wedges *set, double *G);
