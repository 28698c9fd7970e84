/* cmd_example_pairs.c - vwalls example-pairs: the example module on random spheres,
 * printing the distributed count of touching pairs (and, with --check, the O(n^2) one).
 */
#include <stdio.h>
#include <stdlib.h>

#include "cli.h"
#include "example_opts.h"
#include "commands.h"
#include "pairs.h"

static const char *const CMD = "example-pairs";

static void help(void)
{
    printf("usage: vwalls example-pairs [--spheres N] [--radius R] [--seed S] [--cells LAYOUT]\n"
           "                            [--workers W] [--stats FILE.json] [--check] [--quiet]\n"
           "\n"
           "Counts touching pairs among N random spheres in the unit cube, distributed over\n"
           "cells: each cell owns the spheres whose centre it holds and sends ghosts of them\n"
           "to the cells within reach. Two spheres touch when their centres are at most the\n"
           "sum of their radii apart (tangent spheres touch), the same on every layout.\n"
           "  --spheres N    number of spheres (default 10000)\n"
           "  --radius R     largest radius, 1e-6 to 0.25; radii are uniform in [R/4, R]\n"
           "                 (default 0.01)\n"
           "  --seed S       random seed (default 1)\n"
           "  --cells L      layout of cells, like 4, 2x4, 2x2x2 (default 2x2x2)\n"
           "  --workers W    worker threads per process (default: the cores it may run on)\n"
           "  --stats FILE   write the stats JSON (the count as counters.pairs)\n"
           "  --check        also count by brute force (O(N^2)) and fail if the counts\n"
           "                 differ (exit status 1, no stats written)\n"
           "  --quiet        print only the count\n"
           "  --help         this text\n"
           "\nexit status: 0 success, 2 bad input or usage, 1 any other failure\n");
}

int vw_cmd_example_pairs(int argc, char **argv)
{
    vw_example_opts o = {.spheres = 10000, .seed = 1, .workers = 0, .radius = 0.01,
                         .dims = {2, 2, 2}};
    int rc0 = vw_example_opts_parse(CMD, argc, argv, &o, help);
    if (rc0 >= 0) return rc0;
    long n = o.spheres, workers = o.workers;
    double rmax = o.radius;
    int check = o.check, quiet = o.quiet;
    const char *stats = o.stats;
    double t0 = vw_cli_now();
    ex_sphere *s;
    vw_decomp *d;
    int rc = vw_example_spheres(CMD, &o, 1, &s, &d);
    if (rc != VW_EXIT_OK) return rc;
    vw_status st;
    vw_config cfg;
    vw_config_init(&cfg);
    cfg.workers = (int)workers;
    int64_t pairs = 0;
    vw_world *w = NULL;
    double t1 = vw_cli_now();
    st = ex_pairs_count(s, (size_t)n, rmax, d, &cfg, &pairs, &w);
    double t2 = vw_cli_now();
    if (st != VW_OK) {
        /* Spheres refused, a world not made, a step that failed: ex_errmsg says which. */
        vw_cli_error(CMD, "run failed: %s", ex_errmsg());
        rc = VW_EXIT_FAIL;
    }
    if (rc == VW_EXIT_OK && vw_world_is_output(w)) {
        vw_world_add_time(w, "load", t1 - t0);
        if (quiet) {
            printf("%lld\n", (long long)pairs);
        } else {
            char layout[64];
            vw_decomp_layout_string(d, layout, sizeof layout);
            printf("touching pairs: %lld\n", (long long)pairs);
            printf("spheres %ld, cells %s (%d), workers %d x %d process%s\n", n, layout,
                   vw_decomp_cell_count(d), vw_world_workers(w), vw_world_processes(w),
                   vw_world_processes(w) == 1 ? "" : "es");
            printf("ghosts sent %lld, time %.3f s, imbalance %.3f\n",
                   (long long)vw_world_counter(w, EX_PAIRS_CNT_GHOSTS), t2 - t1,
                   vw_world_imbalance(w));
            printf("phases: generate %.3f s, place %.3f s, build %.3f s, compute %.3f s\n", t1 - t0,
                   vw_world_time(w, "place"), vw_world_time(w, "build"), vw_world_time(w, "compute"));
        }
        /* The output process alone checks; every process exits with its verdict, agreed
           when the command has returned (vw_cli_job_status, tools/vwalls.c). */
        if (check) {
            int64_t ref = ex_pairs_brute(s, (size_t)n);
            /* VW_FAULT=example-mismatch (tests): the brute force taken as one pair more. */
            if (vw_cli_fault("example-mismatch")) ref++;
            if (!quiet) printf("brute force: %lld\n", (long long)ref);
            if (ref != pairs) {
                vw_cli_error(CMD, "distributed count %lld differs from brute force %lld",
                             (long long)pairs, (long long)ref);
                rc = VW_EXIT_FAIL;
            }
        }
        /* After the check: a run that fails leaves no output file. */
        if (rc == VW_EXIT_OK && stats && vw_world_write_stats(w, stats, CMD, NULL) != VW_OK) {
            vw_cli_error(CMD, "%s", vw_world_errmsg(w));
            rc = VW_EXIT_FAIL;
        }
    }
    vw_world_free(w);
    vw_decomp_free(d);
    free(s);
    return rc;
}
