/* main.c - the entry point of the `hfvis` command-line tool and its one translation unit: it
 * includes every file of examples/cli/ once (so nothing is external and the build is one
 * compiler call), then dispatches: sum, azimuths, mosaic and info have their own parsers, every
 * other command goes through cli_parse and cli_run. May call: everything. */
#include "cli.h"
#include "help.c"
#include "progress.c"
#include "flags.c"
#include "gis.c"
#include "write.c"
#include "run.c"
#include "sweeps.c"
#include "p2.c"
#include "gis_products.c"
#include "screen.c"
#include "meshes.c"
#include "split.c"
#include "tiles.c"
#include "solar.c"

int main(int argc, char **argv)
{
    cli_args a;
    int rc;
    cli_signals();
    ex_atomic_on_temp = cli_on_temp; /* the raster writers' temporary files too */
    if (argc >= 2 && !strcmp(argv[1], "sum")) return cli_sum(argc, argv);
    if (argc >= 2 && !strcmp(argv[1], "azimuths")) return cli_azimuths(argc, argv);
    if (argc >= 2 && !strcmp(argv[1], "mosaic")) return cli_mosaic(argc, argv);
    if (argc >= 2 && !strcmp(argv[1], "info")) return cli_info(argc, argv);
    cli_t0 = cli_now();
    rc = cli_parse(argc, argv, &a);
    if (rc != CLI_RUN) return rc;
    if ((rc = cli_gis_finish(&a)) != 0) return rc;
    if ((rc = cli_refuse_inputs(&a, a.out)) != 0) return rc;
    rc = cli_run(&a);
    ex_georef_free(&cli_geo);
    if (rc == 0 && !a.quiet && a.out && (a.progress_lines || cli_now() - cli_t0 >= CLI_SUMMARY_SECONDS)) {
        fprintf(stderr, "hfvis %s: done in %.1f s", cli_cmd_names[a.cmd], cli_now() - cli_t0);
        if (cli_run_cells > 0.0) fprintf(stderr, ": %.0f cells", cli_run_cells);
        if (cli_run_directions > 0) fprintf(stderr, ", %d direction%s", cli_run_directions,
                                            cli_run_directions == 1 ? "" : "s");
        fprintf(stderr, " -> %s\n", a.out);
    }
    return rc;
}
