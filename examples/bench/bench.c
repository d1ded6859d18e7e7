/* bench.c - `make bench`: each fast routine beside its oracle/baseline in one run, reporting
 * ns per receiver-direction, the ratio, and peak scratch memory.
 * Usage: bench [quick] [SECTION...]   sections: horizon p2 indirect gi mesh raster ...
 * (BENCH_ARGS="quick raster" make bench); no section = all. */
#define _POSIX_C_SOURCE 200809L
#include "bench.h"
#include "hfvis.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static void die(const char *what, hfvis_status s)
{
    fprintf(stderr, "bench: %s: %s\n", what, hfvis_status_string(s));
    exit(1);
}

static void *xmalloc(size_t n)
{
    void *p = malloc(n);
    if (!p) {
        fprintf(stderr, "bench: out of memory (%zu bytes)\n", n);
        exit(1);
    }
    memset(p, 0, n); /* touch the pages so first-touch faults are not timed */
    return p;
}

/* Receivers for the oracle: a fixed pseudo-random subset (xorshift, seed 1). */
static float *sample_points(int n, int count)
{
    float *p = (float *)xmalloc(sizeof(float) * 2 * (size_t)count);
    unsigned s = 2463534242u;
    int i;
    for (i = 0; i < 2 * count; i++) {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        p[i] = (float)(s % (unsigned)n);
    }
    return p;
}

static void make_terrain(float *z, int n)
{
    hfvis_field f;
    hfvis_status s;
    memset(&f, 0, sizeof f);
    f.kind = HFVIS_FIELD_FBM;
    f.amplitude = (double)n / 8.0;
    f.wavelength = (double)n / 4.0;
    f.seed = 3;
    if ((s = hfvis_field_generate(&f, n, n, n, z)) != HFVIS_OK) die("field", s);
}

/* Other routines at 512^2 beside their oracles: per-line brute force, ray march, hemisphere. */
static void bench_others(int n)
{
    size_t cells = (size_t)n * (size_t)n;
    float *z = (float *)xmalloc(sizeof(float) * cells), *out = (float *)xmalloc(sizeof(float) * cells * 3);
    float *lat, *pts, *ref, *nrm, env_rad[64 * 128 * 3];
    hfvis_grid g;
    hfvis_lattice L;
    hfvis_env env;
    hfvis_env_options lp = hfvis_env_options_default();
    hfvis_hemisphere_options ho;
    double t0, t_fast, t_slow;
    int i, K = 16, P = 64;
    size_t nodes;
    hfvis_status s;
    make_terrain(z, n);
    g.z = z;
    g.width = n;
    g.height = n;
    g.stride = n;
    g.cell_size = 1.0;
    printf("\n%-38s%4d^2 %12s %12s %9s\n", "other routines at", n, "fast", "baseline", "ratio");
    /* P1 hull vs the per-line brute force on the same lattice (one direction, 30 deg). */
    hfvis_lattice_init(&L, n, n, 0.5235987755982988);
    nodes = hfvis_lattice_nodes(&L);
    lat = (float *)xmalloc(sizeof(float) * nodes);
    t0 = bench_now();
    if ((s = hfvis_horizon_lattice(&g, 0.5235987755982988, NULL, lat)) != HFVIS_OK) die("lattice", s);
    t_fast = (bench_now() - t0) * 1e9 / (double)cells;
    t0 = bench_now();
    if ((s = hfvis_horizon_lattice_naive(&g, 0.5235987755982988, NULL, lat)) != HFVIS_OK) die("lattice naive", s);
    t_slow = (bench_now() - t0) * 1e9 / (double)cells;
    printf("%-44s %9.2f ns %9.0f ns %8.0fx\n", "hull lattice vs per-line brute force, /node", t_fast, t_slow, t_slow / t_fast);
    pts = sample_points(n, P);
    ref = (float *)xmalloc(sizeof(float) * (size_t)P * (size_t)K);
    t0 = bench_now();
    if ((s = hfvis_horizon_reference(&g, K, NULL, NULL, pts, (size_t)P, ref)) != HFVIS_OK) die("reference", s);
    t_slow = (bench_now() - t0) * 1e9 / ((double)P * (double)K);
    t0 = bench_now();
    if ((s = hfvis_sky_view_factor(&g, K, NULL, out, n)) != HFVIS_OK) die("svf", s);
    t_fast = (bench_now() - t0) * 1e9 / ((double)cells * (double)K);
    printf("%-44s %9.2f ns %9.0f ns %8.0fx\n", "sky-view factor K=16 vs ray march, /rd", t_fast, t_slow, t_slow / t_fast);
    {   /* openness K = 8: the unlimited sweep beside the march limited to 32 cells (RVT-like) */
        hfvis_openness_options oo;
        memset(&oo, 0, sizeof oo);
        t0 = bench_now();
        if ((s = hfvis_openness(&g, 8, &oo, NULL, out, n)) != HFVIS_OK) die("openness", s);
        t_fast = (bench_now() - t0) * 1e9 / ((double)cells * 8.0);
        oo.radius = 32.0;
        t0 = bench_now();
        if ((s = hfvis_openness(&g, 8, &oo, NULL, out, n)) != HFVIS_OK) die("openness radius", s);
        t_slow = (bench_now() - t0) * 1e9 / ((double)cells * 8.0);
        printf("%-44s %9.2f ns %9.0f ns %8.1fx\n", "openness K=8 unlimited vs R=32 march, /rd", t_fast, t_slow,
               t_slow / t_fast);
    }
    t0 = bench_now();
    if ((s = hfvis_sun_visibility(&g, 0.7, 0.3, 0.0046, NULL, out, n)) != HFVIS_OK) die("sun", s);
    t_fast = (bench_now() - t0) * 1e9 / (double)cells;
    printf("%-44s %9.2f ns %9.0f ns %8.0fx\n", "sun visibility (1 sweep) vs ray march, /rcv", t_fast, t_slow, t_slow / t_fast);
    /* Environment light against the hemisphere oracle (256 azimuths x 512 zenith steps). */
    for (i = 0; i < 64 * 128 * 3; i++) env_rad[i] = 0.2f + 0.8f * (float)((i / 3) % 128) / 128.0f;
    env.radiance = env_rad;
    env.n_theta = 64;
    env.n_phi = 128;
    env.channels = 3;
    nrm = (float *)xmalloc(sizeof(float) * cells * 3);
    hfvis_normals_compute(&g, nrm);
    {
        float *pn = (float *)xmalloc(sizeof(float) * 3 * (size_t)P);
        int p;
        for (p = 0; p < P; p++) {
            size_t idx = (size_t)pts[2 * p + 1] * (size_t)n + (size_t)pts[2 * p];
            pn[3 * p] = nrm[3 * idx];
            pn[3 * p + 1] = nrm[3 * idx + 1];
            pn[3 * p + 2] = nrm[3 * idx + 2];
        }
        memset(&ho, 0, sizeof ho);
        t0 = bench_now();
        if ((s = hfvis_light_reference(&g, &env, 1.0f, NULL, NULL, &ho, pts, pn, (size_t)P, ref)) != HFVIS_OK)
            die("light reference", s);
        t_slow = (bench_now() - t0) * 1e9 / (double)P;
        free(pn);
    }
    t0 = bench_now();
    if ((s = hfvis_env_light(&g, K, &env, 1.0f, NULL, NULL, out, n)) != HFVIS_OK) die("env", s);
    t_fast = (bench_now() - t0) * 1e9 / (double)cells;
    printf("%-44s %9.0f ns %9.0f ns %8.0fx\n", "env light prefix K=16 vs hemisphere, /rcv", t_fast, t_slow, t_slow / t_fast);
    lp.method = HFVIS_ENV_LP_TABLE;
    t0 = bench_now();
    if ((s = hfvis_env_light(&g, K, &env, 1.0f, NULL, &lp, out, n)) != HFVIS_OK) die("env lp", s);
    t_fast = (bench_now() - t0) * 1e9 / (double)cells;
    printf("%-44s %9.0f ns %9.0f ns %8.0fx\n", "env light L_p K=16 vs hemisphere, /rcv", t_fast, t_slow, t_slow / t_fast);
    free(z);
    free(out);
    free(lat);
    free(pts);
    free(ref);
    free(nrm);
}

/* P2 intervisibility: the hull tree against the naive per-receiver scan on the same lattice,
 * per direction (K = 4, one lattice group), on fBm and brick fields; the paper's figures are
 * [P2] Tables 2-3 (1024^2, GTX 480). Then the scaling exponent of visible points per receiver
 * for "more extent" (fixed feature size) and "more detail" (features scale with N). */
static void make_field(float *z, int n, hfvis_field_kind kind, double wavelength, double amplitude)
{
    hfvis_field f;
    hfvis_status s;
    memset(&f, 0, sizeof f);
    f.kind = kind;
    f.amplitude = amplitude;
    f.wavelength = wavelength;
    f.seed = 3;
    if ((s = hfvis_field_generate(&f, n, n, n, z)) != HFVIS_OK) die("field", s);
}

static void bench_p2(int quick)
{
    int sizes[3] = {256, 512, 1024}, si, fi, K = 4, ns = quick ? 1 : 3;
    double vis_extent[3], vis_detail[3];
    printf("\nP2 intervisibility, per direction (K = 4): tree vs naive scan on the same lattice\n");
    printf("%-7s %-7s | %9s %9s %9s | %9s %9s | %9s %9s %8s\n", "field", "size", "visible", "m_a",
           "t_a", "naive it", "t_a/nv", "tree ms", "naive ms", "speedup");
    for (fi = 0; fi < 2; fi++)
        for (si = 0; si < ns; si++) {
            int n = sizes[si];
            size_t cells = (size_t)n * (size_t)n;
            float *z = (float *)xmalloc(sizeof(float) * cells), *out = (float *)xmalloc(sizeof(float) * cells);
            hfvis_grid g;
            hfvis_visibility_stats st, sn;
            hfvis_status s;
            double t0, tt, tn, r;
            if (fi == 0) make_field(z, n, HFVIS_FIELD_FBM, (double)n / 4.0, (double)n / 8.0);
            else make_field(z, n, HFVIS_FIELD_BRICKS, 16.0, 2.0);
            g.z = z;
            g.width = n;
            g.height = n;
            g.stride = n;
            g.cell_size = 1.0;
            t0 = bench_now();
            if ((s = hfvis_visibility_count(&g, K, NULL, NULL, out, n, &st)) != HFVIS_OK) die("visibility", s);
            tt = (bench_now() - t0) * 1e3 / (double)K;
            t0 = bench_now();
            if ((s = hfvis_visibility_count_naive(&g, K, NULL, out, n, &sn)) != HFVIS_OK) die("visibility naive", s);
            tn = (bench_now() - t0) * 1e3 / (double)K;
            r = st.receivers;
            printf("%-7s %5d^2 | %9.2f %9.2f %9.2f | %9.1f %8.2f%% | %9.1f %9.1f %7.1fx\n",
                   fi == 0 ? "fBm" : "bricks", n, st.visible / r, st.horizons / r, st.iterations / r,
                   sn.iterations / r, 100.0 * st.iterations / sn.iterations, tt, tn, tn / tt);
            fflush(stdout);
            free(z);
            free(out);
        }
    printf("paper (1024^2, K = 256): fractal terrain m_a 9.25 t_a 11.7 (2.4%% of naive 484), "
           "brick 3.06 / 4.80 (0.99%%); speed-up 2.4x / 4.2x\n");
    /* scaling of visible points per receiver-direction */
    for (si = 0; si < 3; si++) {
        int n = sizes[si];
        size_t cells = (size_t)n * (size_t)n;
        float *z = (float *)xmalloc(sizeof(float) * cells), *out = (float *)xmalloc(sizeof(float) * cells);
        hfvis_grid g;
        hfvis_visibility_stats st;
        hfvis_status s;
        g.z = z;
        g.width = n;
        g.height = n;
        g.stride = n;
        g.cell_size = 1.0;
        make_field(z, n, HFVIS_FIELD_FBM, 64.0, 8.0); /* more extent: same features, more of them */
        if ((s = hfvis_visibility_count(&g, K, NULL, NULL, out, n, &st)) != HFVIS_OK) die("visibility", s);
        vis_extent[si] = st.visible / st.receivers;
        make_field(z, n, HFVIS_FIELD_FBM, (double)n / 4.0, (double)n / 8.0); /* more detail */
        if ((s = hfvis_visibility_count(&g, K, NULL, NULL, out, n, &st)) != HFVIS_OK) die("visibility", s);
        vis_detail[si] = st.visible / st.receivers;
        free(z);
        free(out);
        if (quick) break;
    }
    if (!quick) {
        /* least-squares slope of log(visible) against log(N) over the three sizes */
        double e[2], *v[2];
        int q, i;
        v[0] = vis_extent;
        v[1] = vis_detail;
        for (q = 0; q < 2; q++) {
            double sx = 0, sy = 0, sxx = 0, sxy = 0;
            for (i = 0; i < 3; i++) {
                double x = log((double)sizes[i]), y = log(v[q][i]);
                sx += x;
                sy += y;
                sxx += x * x;
                sxy += x * y;
            }
            e[q] = (3.0 * sxy - sx * sy) / (3.0 * sxx - sx * sx);
        }
        printf("visible points per receiver-direction at 256/512/1024: extent %.2f %.2f %.2f -> N^%.2f; "
               "detail %.2f %.2f %.2f -> N^%.2f (paper: N^0.01 and N^0.65)\n",
               vis_extent[0], vis_extent[1], vis_extent[2], e[0], vis_detail[0], vis_detail[1],
               vis_detail[2], e[1]);
    }
}

/* Indirect gather cost per receiver-direction, tree vs naive visible sets. */
static void bench_indirect(int n)
{
    size_t cells = (size_t)n * (size_t)n, i;
    float *z = (float *)xmalloc(sizeof(float) * cells), *ex = (float *)xmalloc(sizeof(float) * cells),
          *out = (float *)xmalloc(sizeof(float) * cells);
    hfvis_grid g;
    hfvis_status s;
    double t0, tt, tn, rd;
    int K = 16;
    make_field(z, n, HFVIS_FIELD_FBM, (double)n / 4.0, (double)n / 8.0);
    for (i = 0; i < cells; i++) ex[i] = 0.5f;
    g.z = z;
    g.width = n;
    g.height = n;
    g.stride = n;
    g.cell_size = 1.0;
    rd = (double)cells * (double)K;
    t0 = bench_now();
    if ((s = hfvis_indirect_light(&g, K, ex, 1, 1.0f, 1.0f, NULL, NULL, out, n)) != HFVIS_OK) die("indirect", s);
    tt = (bench_now() - t0) * 1e9 / rd;
    t0 = bench_now();
    if ((s = hfvis_indirect_light_naive(&g, K, ex, 1, 1.0f, 1.0f, NULL, out, n)) != HFVIS_OK) die("indirect naive", s);
    tn = (bench_now() - t0) * 1e9 / rd;
    printf("indirect gather %d^2 K=16: tree %.1f ns/rd, naive %.1f ns/rd, %.1fx\n", n, tt, tn, tn / tt);
    free(z);
    free(ex);
    free(out);
}

/* Terrain GI (direct light + B bounces, hfvis_terrain_gi) beside the same pipeline built from
 * the naive visible sets (hfvis_indirect_light_naive per bounce); viewshed R2 beside its exact
 * line-of-sight oracle. */
static void bench_gi_viewshed(int n)
{
    size_t cells = (size_t)n * (size_t)n, i;
    float *z = (float *)xmalloc(sizeof(float) * cells), *d = (float *)xmalloc(sizeof(float) * cells),
          *l = (float *)xmalloc(sizeof(float) * cells), *g2 = (float *)xmalloc(sizeof(float) * cells),
          *tmp = (float *)xmalloc(sizeof(float) * cells);
    hfvis_grid g;
    hfvis_sun sun;
    hfvis_viewshed_options vo;
    hfvis_status s;
    double t0, t_direct, t_gi, t_naive, t_r2, t_exact, rd;
    const float rho = 0.5f;
    int K = 16, b, B = 2;
    size_t differ = 0;
    make_field(z, n, HFVIS_FIELD_FBM, (double)n / 4.0, (double)n / 8.0);
    g.z = z; g.width = n; g.height = n; g.stride = n; g.cell_size = 1.0;
    memset(&sun, 0, sizeof sun);
    sun.azimuth_rad = 0.7; sun.elevation_rad = 0.5;
    sun.irradiance[0] = 3.14159265f;
    rd = (double)cells * (double)K;
    t0 = bench_now();
    if ((s = hfvis_direct_light(&g, K, &sun, 1.0f, NULL, 1, NULL, d)) != HFVIS_OK) die("direct", s);
    t_direct = bench_now() - t0;
    t0 = bench_now();
    if ((s = hfvis_terrain_gi(&g, K, d, NULL, NULL, rho, 1, B, NULL, NULL, g2)) != HFVIS_OK) die("gi", s);
    t_gi = bench_now() - t0;
    /* naive pipeline: L_0 = rho*D, L_(b+1) = rho*(D + I_naive[L_b]) */
    t0 = bench_now();
    for (i = 0; i < cells; i++) l[i] = rho * d[i];
    for (b = 0; b < B; b++) {
        if ((s = hfvis_indirect_light_naive(&g, K, l, 1, 1.0f, 1.0f, NULL, tmp, n)) != HFVIS_OK)
            die("indirect naive", s);
        for (i = 0; i < cells; i++) l[i] = isnan(tmp[i]) ? tmp[i] : rho * (d[i] + tmp[i]);
    }
    t_naive = bench_now() - t0;
    printf("\nterrain GI %d^2 K=%d, %d bounces: direct light %.1f ns/rd; GI %.1f ns/rd per bounce, "
           "naive pipeline %.1f, %.1fx\n", n, K, B, t_direct * 1e9 / rd, t_gi * 1e9 / rd / B,
           t_naive * 1e9 / rd / B, t_naive / t_gi);
    memset(&vo, 0, sizeof vo);
    vo.observer_height = 1.7; /* an eye above the surface; the fBm's amplitude is n/8 */
    t0 = bench_now();
    if ((s = hfvis_viewshed(&g, n * 0.5, n * 0.5, &vo, d, n)) != HFVIS_OK) die("viewshed", s);
    t_r2 = bench_now() - t0;
    t0 = bench_now();
    if ((s = hfvis_viewshed_reference(&g, n * 0.5, n * 0.5, &vo, 0.0, l, n)) != HFVIS_OK) die("viewshed ref", s);
    t_exact = bench_now() - t0;
    for (i = 0; i < cells; i++) differ += d[i] != l[i] && !(isnan(d[i]) && isnan(l[i]));
    printf("viewshed %d^2 (eye 1.7 above the centre): R2 %.1f ns/cell (%.3f s), exact LOS %.0f ns/cell, %.0fx; "
           "%.2f%% cells differ\n", n, t_r2 * 1e9 / (double)cells, t_r2, t_exact * 1e9 / (double)cells,
           t_exact / t_r2, 100.0 * (double)differ / (double)cells);
    free(z); free(d); free(l); free(g2); free(tmp);
}

/* The sections of examples/bench_*.c (bench.h). */
static const struct { const char *name; void (*run)(int quick); } module_sections[] = {
    {"ns", bench_gi2}, {"mesh", bench_mesh}, {"raster", bench_raster}, {"bvh", bench_bvh}, {"vox", bench_vox}, {"cons", bench_cons}, {"iv", bench_iv}, {"vf", bench_vf}, {"volgi", bench_volgi}, {"ssao", bench_ssao}, {"ffao", bench_ssaob}, {"lk", bench_lk}, {"lkobj", bench_lk_obj}, {"dirs", bench_dirs}, {"exact", bench_exact}, {"radius", bench_radius}, {"tiles", bench_tiles}, {"threads", bench_threads}, {"solar", bench_solar}, {"solar-sites", bench_solar_sites}
};

static int wanted(int argc, char **argv, int first, const char *name)
{
    int i;
    if (first >= argc) return 1;
    for (i = first; i < argc; i++)
        if (strcmp(argv[i], name) == 0) return 1;
    return 0;
}

static void bench_horizon(int quick);

int main(int argc, char **argv)
{
    int quick = argc > 1 && strcmp(argv[1], "quick") == 0, first = quick ? 2 : 1;
    size_t m;
    if (wanted(argc, argv, first, "horizon")) bench_horizon(quick);
    if (wanted(argc, argv, first, "p2")) {
        bench_others(quick ? 256 : 512);
        bench_p2(quick);
    }
    if (wanted(argc, argv, first, "indirect")) bench_indirect(quick ? 256 : 512);
    if (wanted(argc, argv, first, "gi")) bench_gi_viewshed(quick ? 256 : 1024);
    for (m = 0; m < sizeof module_sections / sizeof module_sections[0]; m++)
        if (wanted(argc, argv, first, module_sections[m].name)) module_sections[m].run(quick);
    return 0;
}

/* The three routines of bench_horizon again with their scratch in one block that was touched
 * before (bench_arena): the time of a caller that reuses its scratch, without the first-touch page
 * faults of a fresh allocation (about 11 us per 4 KiB page on the VM docs/performance.md was
 * measured on). cap: the most bytes any of the three allocates in one call. */
static void bench_horizon_reused(const hfvis_grid *g, int K, float *map, float *light, size_t cap)
{
    bench_arena arena;
    hfvis_allocator al = {bench_arena_alloc, bench_arena_free, NULL};
    hfvis_sweep_options o = hfvis_sweep_options_default();
    double t0, t[3], rd = (double)g->width * (double)g->height * (double)K;
    hfvis_status s;
    int r;
    arena.cap = cap;
    arena.base = (unsigned char *)xmalloc(arena.cap);
    memset(arena.base, 0, arena.cap); /* the first touch, outside the timing */
    al.user = &arena;
    o.alloc = &al;
    for (r = 0; r < 3; r++) {
        arena.used = 0;
        t0 = bench_now();
        if (r == 0) s = hfvis_horizon_map(g, K, &o, map);
        else if (r == 1) s = hfvis_sky_light(g, K, 1.0f, 1.0f, &o, light, g->width);
        else s = hfvis_sky_view_factor(g, K, &o, light, g->width);
        if (s != HFVIS_OK) die("reused scratch", s);
        t[r] = (bench_now() - t0) * 1e9 / rd;
    }
    printf("%4d^2 %4d | %9.2f %8s | %9.2f %8s | %9.2f %8s | scratch reused (opts.alloc keeps one block)\n",
           g->width, K, t[0], "", t[1], "", t[2], "");
    free(arena.base);
}

/* P1, lattice mode: horizon map, fused sky light and sky-view factor beside the ray-march
 * oracle, in ns per receiver-direction (single-threaded; docs/performance.md has the profile). */
static void bench_horizon(int quick)
{
    int sizes[2] = {512, 1024}, Ks[3] = {16, 64, 256}, si, ki, nsizes = quick ? 1 : 2;
    int nk = quick ? 1 : 3;
    printf("hfvis bench (ns per receiver-direction; oracle = per-receiver ray march, unit steps,\n"
           "on a fixed random subset of receivers; scratch = peak library allocation)\n\n");
    printf("lattice mode: map = hfvis_horizon_map, sky = hfvis_sky_light, svf = hfvis_sky_view_factor\n");
    printf("%-6s %4s | %9s %8s | %9s %8s | %9s %8s | %9s %7s %7s %7s\n", "size", "K", "map ns/rd",
           "scratch", "sky ns/rd", "scratch", "svf ns/rd", "scratch", "oracle", "map x", "sky x", "svf x");
    for (si = 0; si < nsizes; si++) {
        int n = sizes[si];
        size_t cells = (size_t)n * (size_t)n;
        float *z = (float *)xmalloc(sizeof(float) * cells);
        float *light = (float *)xmalloc(sizeof(float) * cells);
        hfvis_grid g;
        make_terrain(z, n);
        g.z = z;
        g.width = n;
        g.height = n;
        g.stride = n;
        g.cell_size = 1.0;
        for (ki = 0; ki < nk; ki++) {
            int K = Ks[ki], P = quick ? 64 : 256;
            float *map = (float *)xmalloc(sizeof(float) * cells * (size_t)K);
            float *pts = sample_points(n, P), *ref = (float *)xmalloc(sizeof(float) * (size_t)P * (size_t)K);
            bench_tracker tm = {0, 0, 0, 0}, ts = {0, 0, 0, 0}, tv = {0, 0, 0, 0};
            hfvis_allocator am = {bench_track_alloc, bench_track_free, NULL}, as = am, av = am;
            hfvis_sweep_options om = hfvis_sweep_options_default(), os = om, ov = om;
            double t0, t_map, t_sky, t_svf, t_ref, rd = (double)cells * (double)K;
            hfvis_status s;
            am.user = &tm;
            as.user = &ts;
            av.user = &tv;
            om.alloc = &am;
            os.alloc = &as;
            ov.alloc = &av;
            t0 = bench_now();
            if ((s = hfvis_horizon_map(&g, K, &om, map)) != HFVIS_OK) die("horizon map", s);
            t_map = (bench_now() - t0) * 1e9 / rd;
            t0 = bench_now();
            if ((s = hfvis_sky_light(&g, K, 1.0f, 1.0f, &os, light, n)) != HFVIS_OK) die("sky", s);
            t_sky = (bench_now() - t0) * 1e9 / rd;
            t0 = bench_now();
            if ((s = hfvis_sky_view_factor(&g, K, &ov, light, n)) != HFVIS_OK) die("svf", s);
            t_svf = (bench_now() - t0) * 1e9 / rd;
            t0 = bench_now();
            if ((s = hfvis_horizon_reference(&g, K, NULL, NULL, pts, (size_t)P, ref)) != HFVIS_OK)
                die("reference", s);
            t_ref = (bench_now() - t0) * 1e9 / ((double)P * (double)K);
            printf("%4d^2 %4d | %9.2f %7.1fM | %9.2f %7.1fM | %9.2f %7.1fM | %9.1f %6.0fx %6.0fx %6.0fx\n",
                   n, K, t_map, (double)tm.peak / 1048576.0, t_sky, (double)ts.peak / 1048576.0, t_svf,
                   (double)tv.peak / 1048576.0, t_ref, t_ref / t_map, t_ref / t_sky, t_ref / t_svf);
            if (K == 64) {
                const bench_tracker *tr[3] = {&tm, &ts, &tv};
                size_t cap = 0;
                int i;
                for (i = 0; i < 3; i++) /* with room for the arena's 64-byte alignment */
                    if (tr[i]->total + 64u * tr[i]->count > cap) cap = tr[i]->total + 64u * tr[i]->count;
                bench_horizon_reused(&g, K, map, light, cap);
            }
            fflush(stdout);
            free(map);
            free(pts);
            free(ref);
        }
        free(z);
        free(light);
    }
}
