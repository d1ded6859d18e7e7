#include "hfvis.h"
#include "test.h"
#include <stdlib.h>
TEST(smoke)
{
    enum { W = 40, H = 30 };
    static float z[W * H], d[W * H], tot[W * H], bo[2 * W * H], vis[16 * W * H];
    double env[16] = {0};
    hfvis_grid g = {z, W, H, W, 1.0};
    hfvis_ns_scene sc;
    hfvis_ns_gi_outputs o;
    int i;
    memset(&sc, 0, sizeof sc);
    for (i = 0; i < W * H; i++) z[i] = 0.0f;
    env[0] = 2.0 * sqrt(3.14159265358979323846);
    sc.channels = 1; sc.env_sh = env; sc.albedo[0] = 1.0f;
    memset(&o, 0, sizeof o);
    o.bounces = 2; o.direct = d; o.total = tot; o.bounce = bo; o.visibility = vis;
    CHECK_EQ_STATUS(hfvis_ns_gi(&g, &sc, NULL, &o), HFVIS_OK);
    printf("flat: %.9g %.9g %.9g | V %.6g %.6g %.6g %.6g\n", (double)d[15 * W + 20], (double)tot[15 * W + 20], (double)bo[15*W+20], (double)vis[(15*W+20)*16], (double)vis[(15*W+20)*16+2], (double)vis[(15*W+20)*16+6], (double)vis[(15*W+20)*16+12]);
}
int main(int argc, char **argv) { TEST_INIT(argc, argv); RUN(smoke); return TEST_DONE(); }
