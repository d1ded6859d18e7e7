/* 07_visibility_index.c - the visibility index of a generated terrain (how many samples each point sees), with the [P2] sweep statistics. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "common.h"

#define W 256
#define H 256
#define K 16 /* azimuth directions */

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "out";
    const hfvis_field terrain = { .kind = HFVIS_FIELD_FBM, .amplitude = 48.0, .wavelength = 128.0,
                                  .octaves = 6, .seed = 2010 };
    float *z = malloc(sizeof(float) * W * H), *count = malloc(sizeof(float) * W * H);
    float *naive = malloc(sizeof(float) * W * H);
    hfvis_visibility_stats st, ns;
    hfvis_grid grid;
    double top = 0.0, mean = 0.0;
    size_t i, differ = 0;
    int rc = 1;

    if (!z || !count || !naive) { ex_error("07_visibility_index", "out of memory"); goto fail; }
    EX_CHECK(hfvis_field_generate(&terrain, W, H, W, z), "hfvis_field_generate");
    grid.z = z; grid.width = W; grid.height = H; grid.stride = W; grid.cell_size = 1.0;

    /* Hull-tree sweep ([P2] Alg. 1): each point's visible samples follow from its local
     * horizons; the work is linear in the horizons, not in the samples behind the point. */
    EX_CHECK(hfvis_visibility_count(&grid, K, NULL, NULL, count, W, &st), "hfvis_visibility_count");
    /* The oracle scans every earlier sample of each line: its iterations are the naive cost. */
    EX_CHECK(hfvis_visibility_count_naive(&grid, K, NULL, naive, W, &ns), "hfvis_visibility_count_naive");
    for (i = 0; i < (size_t)W * H; i++) {
        differ += count[i] != naive[i];
        mean += (double)count[i];
        if ((double)count[i] > top) top = (double)count[i];
    }
    if (differ) { ex_error("07_visibility_index", "hull tree and naive counts differ"); goto fail; }
    mean /= (double)W * H;

    /* Per receiver-direction, as [P2] Table 1 (visible points) and Table 2 (m_a, t_a). */
    printf("07_visibility_index: %dx%d fBm, K = %d: a point sees %.1f samples on average (at most %.0f)\n",
           W, H, K, mean, top);
    printf("07_visibility_index: per receiver-direction: visible %.2f of %.1f tested (%.1f%%), "
           "horizons m_a %.2f, iterations t_a %.2f (%.1f%% of the naive scan)\n",
           st.visible / st.receivers, ns.iterations / ns.receivers, 100.0 * st.visible / ns.iterations,
           st.horizons / st.receivers, st.iterations / st.receivers,
           100.0 * st.iterations / ns.iterations);
    if (ex_save_pgm_png(dir, "07_visibility_index.pgm", count, W, H, W, 0.0f, (float)top)) goto fail;
    rc = 0;
fail:
    free(z); free(count); free(naive);
    return rc;
}
