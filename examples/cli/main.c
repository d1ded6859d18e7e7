/* main.c - the entry point of the `hfvis` command-line tool and its one translation unit: it
 * includes every file of examples/cli/ once (so nothing is external and the build is one
 * compiler call), and the table of commands; main checks the table, then runs a command: sum,
 * mosaic and info with their own lists of inputs, every other one through cli_parse, its check
 * and its run function. May call: everything. */
#include "cli.h"
#include "help.c"
#include "progress.c"
#include "threads.c"
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

/* The commands: one row each (the order of `hfvis --help`). Adding a command: its CMD_ value in
 * cli.h's enum, its --help text (help.c), its flags' rows (flags.c: add the command's bit to
 * the rows of the flags it uses), and this row with its check, estimate (run.c) and run
 * functions. */
#define CLI_HF_IO (CLI_IN_NEEDED | CLI_OUT_NEEDED)
#define CLI_MESH_IO (CLI_IN_NEEDED | CLI_OUT_NEEDED | CLI_COST_FIRST)
static const cli_command cli_commands[CMD_COUNT] = {
    { "horizon", "horizon elevation angle toward K directions (K planes in one image)",
      CLI_HORIZON_HELP, CLI_HF_IO, NULL, cli_estimate_horizon, cli_run_heights, NULL },
    { "skyview", "sky-view factor 1 - (1/K) sum_k sin(max(alpha_k, 0)), in [0, 1]",
      CLI_SKYVIEW_HELP, CLI_HF_IO, NULL, cli_estimate_sweep, cli_run_heights, NULL },
    { "sky", "uniform-sky light, [P1] Eq. 5 (cosine-weighted and slope-aware)",
      CLI_SKY_HELP, CLI_HF_IO, NULL, cli_estimate_sweep, cli_run_heights, NULL },
    { "shadow", "sun visibility in [0, 1] from one exact sweep toward the sun",
      CLI_SHADOW_HELP, CLI_HF_IO, cli_check_shadow, cli_estimate_sweep, cli_run_heights, NULL },
    { "light", "environment light from a lat-long PFM map",
      CLI_LIGHT_HELP, CLI_HF_IO, cli_check_light, cli_estimate_sweep, cli_run_heights, NULL },
    { "normals", "unit surface normals (x east, y south, z up) as a 3-channel PFM",
      CLI_NORMALS_HELP, CLI_HF_IO, NULL, cli_estimate_sweep, cli_run_heights, NULL },
    { "indirect", "sun and sky light with interreflections between terrain points ([P2])",
      CLI_INDIRECT_HELP, CLI_HF_IO, cli_check_indirect, cli_estimate_indirect, cli_run_heights, NULL },
    { "gi", "multi-resolution GI (Nowrouzezahrai & Snyder): sky, sun, bounces, gloss",
      CLI_GI_HELP, CLI_HF_IO, cli_check_gi, cli_estimate_gi, cli_run_heights, NULL },
    { "visibility", "visibility index: the grid samples each point sees along K directions",
      CLI_VISIBILITY_HELP, CLI_HF_IO, NULL, cli_estimate_visibility, cli_run_heights, NULL },
    { "viewshed", "which samples an observer at one point sees (line of sight)",
      CLI_VIEWSHED_HELP, CLI_HF_IO, cli_check_viewshed, cli_estimate_viewshed, cli_run_heights, NULL },
    { "hillshade", "shaded relief with cast shadows from the exact sweep, one or more suns",
      CLI_HILLSHADE_HELP, CLI_HF_IO, cli_check_hillshade, cli_estimate_sweep, cli_run_heights, NULL },
    { "openness", "positive or negative topographic openness (Yokoyama et al. 2002)",
      CLI_OPENNESS_HELP, CLI_HF_IO, NULL, cli_estimate_sweep, cli_run_heights, NULL },
    { "solar", "clear-sky solar irradiation of a day or a date range over exact horizons",
      CLI_SOLAR_HELP, CLI_HF_IO, cli_check_solar, cli_estimate_solar, cli_run_heights, NULL },
    { "voxelize", "voxels of an OBJ mesh: surface, conservative or solid (.binvox or .raw)",
      CLI_VOXELIZE_HELP, CLI_MESH_IO, cli_check_voxelize, cli_estimate_voxelize, cli_run_voxelize, NULL },
    { "volgi", "direct + indirect light of an OBJ mesh or the test room ([G12] ch. 5)",
      CLI_VOLGI_HELP, CLI_MESH_IO, cli_check_volgi, cli_estimate_volgi, cli_run_volgi, NULL },
    { "visfield", "4D visibility field of an OBJ mesh (.hfvf), or AO images from one",
      CLI_VF_HELP, CLI_MESH_IO, cli_check_vf, cli_estimate_visfield, cli_run_visfield, NULL },
    { "meshao", "ray-cast ambient obscurance of an OBJ mesh (Laine & Karras bit masks)",
      CLI_LK_HELP, CLI_MESH_IO, cli_check_lk, cli_estimate_meshao, cli_run_meshao, NULL },
    { "ssao", "screen-space obscurance of a depth buffer: LSAO, HBAO, FFAO, ray traced",
      CLI_SSAO_HELP, CLI_HF_IO, cli_check_ssao, cli_estimate_ssao, cli_run_ssao, NULL },
    { "sum", "add up the partial results of --dir-range runs into the single run's OUT",
      CLI_SUM_HELP, 0, NULL, NULL, NULL, cli_sum },
    { "mosaic", "assemble the pieces of --window runs into the whole run's OUT",
      CLI_MOSAIC_HELP, 0, NULL, NULL, NULL, cli_mosaic },
    { "info", "print a raster's width, height, bands, cell, CRS and NoData",
      CLI_INFO_HELP, 0, NULL, NULL, NULL, cli_info },
    { "azimuths", "print the K azimuths a run uses, in degrees, in output-plane order",
      CLI_AZIMUTHS_HELP, 0, cli_check_azimuths, NULL, cli_run_azimuths, NULL },
};

/* A table without a way to run one of its commands, or without the estimate of a command that
 * takes --max-memory (or with one nothing calls), is an error before anything runs. */
static int cli_commands_complete(void)
{
    unsigned long limited = cli_flags[cli_flag_for("--max-memory", CMD_HORIZON)].commands;
    int c;
    for (c = 0; c < CMD_COUNT; c++) {
        if (!cli_commands[c].name || !cli_commands[c].help || !cli_commands[c].run == !cli_commands[c].main)
            return cli_error(CLI_EXIT_ERROR, cli_commands[c].name ? cli_commands[c].name : "hfvis",
                             "internal error: command %d has no name, help or single run function", c);
        if (!cli_commands[c].estimate != !(limited & CLI_ONLY(c)))
            return cli_error(CLI_EXIT_ERROR, cli_commands[c].name, "internal error: %s",
                             cli_commands[c].estimate ? "an estimate, but no --max-memory"
                                                      : "--max-memory, but no estimate");
    }
    return 0;
}

int main(int argc, char **argv)
{
    cli_args a;
    cli_run_state run;
    int rc;
    if ((rc = cli_commands_complete()) != 0) return rc;
    cli_signals();
    ex_atomic_on_temp = cli_on_temp; /* the raster writers' temporary files too */
    if (argc >= 2 && !strcmp(argv[1], "--list-commands")) return cli_list_commands(argc);
    if (argc >= 2 && !strcmp(argv[1], "--list-flags")) return cli_list_flags(argc, argv);
    if (argc >= 2 && (rc = cli_command_of(argv[1])) >= 0 && cli_commands[rc].main)
        return cli_commands[rc].main(argc, argv);
    cli_run_init(&run);
    rc = cli_parse(argc, argv, &a);
    if (rc != CLI_RUN) return rc;
    a.run = &run;
    if ((rc = cli_gis_finish(&a)) != 0) return rc;
    if ((rc = cli_refuse_outputs(&a)) != 0) return rc;
    if ((cli_commands[a.cmd].io & CLI_COST_FIRST) && (rc = cli_check_cost(&a, 0, 0, 1)) != 0) return rc;
    rc = cli_commands[a.cmd].run(&a);
    ex_georef_free(&run.geo);
    if (rc == 0 && !a.quiet && a.out && (a.progress_lines || cli_now() - run.t0 >= CLI_SUMMARY_SECONDS)) {
        fprintf(stderr, "hfvis %s: done in %.1f s", cli_commands[a.cmd].name, cli_now() - run.t0);
        if (run.cells > 0.0) fprintf(stderr, ": %.0f cells", run.cells);
        if (run.directions > 0) fprintf(stderr, ", %d direction%s", run.directions,
                                        run.directions == 1 ? "" : "s");
        fprintf(stderr, " -> %s\n", a.out);
    }
    return rc;
}
