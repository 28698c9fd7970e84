/* cmd_example_components.c - vwalls example-components: the second example module on
 * random spheres, printing the connected components of touching spheres found by labels
 * travelling across walls (and, with --check, comparing every label with the sequential one).
 */
#include <stdio.h>
#include <stdlib.h>

#include "cli.h"
#include "example_opts.h"
#include "commands.h"
#include "components.h"

static const char *const CMD = "example-components";

static void help(void)
{
    printf("usage: vwalls example-components [--spheres N] [--radius R] [--seed S] [--cells LAYOUT]\n"
           "                                 [--workers W] [--stats FILE.json] [--check] [--quiet]\n"
           "\n"
           "Finds the connected components of touching spheres among N random spheres in the\n"
           "unit cube, distributed over cells: each cell joins its own spheres with union-find,\n"
           "then the smallest id of every component travels across walls until no label goes\n"
           "down; the runtime's quiescence ends the run. Two spheres touch when their\n"
           "centres are at most the sum of their radii apart (tangent spheres touch).\n"
           "  --spheres N    number of spheres (default 10000)\n"
           "  --radius R     largest radius, 1e-6 to 0.25; radii are uniform in [R/4, R]\n"
           "                 (default 0.035, near percolation for 10000 spheres)\n"
           "  --seed S       random seed (default 1)\n"
           "  --cells L      layout of cells, like 4, 2x4, 2x2x2 (default 2x2x2)\n"
           "  --workers W    worker threads per process (default: the cores it may run on)\n"
           "  --stats FILE   write the stats JSON (counters under \"components\")\n"
           "  --check        also label sequentially (O(N^2)) and fail if any label differs\n"
           "                 (exit status 1, no stats written)\n"
           "  --quiet        print only the number of components\n"
           "  --help         this text\n"
           "\nexit status: 0 success, 2 bad input or usage, 1 any other failure\n");
}

/* Size of the largest component, from labels (smallest id of each sphere's component). */
static int64_t largest(const int64_t *labels, size_t n)
{
    int64_t *size = calloc(n ? n : 1, sizeof *size), best = 0;
    if (!size) return -1;
    for (size_t i = 0; i < n; i++)
        if (++size[labels[i]] > best) best = size[labels[i]];
    free(size);
    return best;
}

int vw_cmd_example_components(int argc, char **argv)
{
    vw_example_opts o = {.spheres = 10000, .seed = 1, .workers = 0, .radius = 0.035,
                         .dims = {2, 2, 2}};
    int rc0 = vw_example_opts_parse(CMD, argc, argv, &o, help);
    if (rc0 >= 0) return rc0;
    long n = o.spheres, workers = o.workers;
    double rmax = o.radius;
    int check = o.check, quiet = o.quiet;
    const char *stats = o.stats;
    size_t ns = (size_t)(n ? n : 1);
    int64_t *labels = malloc(sizeof *labels * ns), *ref = check ? malloc(sizeof *ref * ns) : NULL;
    double t0 = vw_cli_now();
    ex_sphere *s;
    vw_decomp *d;
    int rc = vw_example_spheres(CMD, &o, labels && (!check || ref), &s, &d);
    if (rc != VW_EXIT_OK) {
        free(labels), free(ref);
        return rc;
    }
    vw_status st;
    vw_config cfg;
    vw_config_init(&cfg);
    cfg.workers = (int)workers;
    int64_t ncomp = 0;
    vw_world *w = NULL;
    double t1 = vw_cli_now();
    st = ex_components_label(s, (size_t)n, rmax, d, &cfg, labels, &ncomp, &w);
    double t2 = vw_cli_now();
    if (st != VW_OK) {
        /* Spheres refused, a world not made, a step that failed: ex_errmsg says which. */
        vw_cli_error(CMD, "run failed: %s", ex_errmsg());
        rc = VW_EXIT_FAIL;
    }
    if (rc == VW_EXIT_OK && vw_world_is_output(w)) {
        vw_world_add_time(w, "load", t1 - t0);
        if (quiet) {
            printf("%lld\n", (long long)ncomp);
        } else {
            char layout[64];
            vw_decomp_layout_string(d, layout, sizeof layout);
            printf("components: %lld (largest %lld spheres)\n", (long long)ncomp,
                   (long long)largest(labels, (size_t)n));
            printf("spheres %ld, cells %s (%d), workers %d x %d process%s\n", n, layout,
                   vw_decomp_cell_count(d), vw_world_workers(w), vw_world_processes(w),
                   vw_world_processes(w) == 1 ? "" : "es");
            printf("local components %lld, label messages %lld, relabels %lld\n",
                   (long long)vw_world_counter(w, EX_COMPONENTS_CNT_LOCAL),
                   (long long)vw_world_counter(w, EX_COMPONENTS_CNT_LABEL_MSGS),
                   (long long)vw_world_counter(w, EX_COMPONENTS_CNT_RELABELS));
            printf("time %.3f s, imbalance %.3f\n", t2 - t1, vw_world_imbalance(w));
            printf("phases: generate %.3f s, place %.3f s, build %.3f s, compute %.3f s, "
                   "report %.3f s\n", t1 - t0, vw_world_time(w, "place"), vw_world_time(w, "build"),
                   vw_world_time(w, "compute"), vw_world_time(w, "report"));
        }
        /* The output process alone checks; every process exits with its verdict, agreed
           when the command has returned (vw_cli_job_status, tools/vwalls.c). */
        if (check) {
            int64_t nref = ex_components_reference(s, (size_t)n, ref);
            /* VW_FAULT=example-mismatch (tests): one component more in the reference. */
            if (vw_cli_fault("example-mismatch")) nref++;
            if (!quiet) printf("sequential: %lld components\n", (long long)nref);
            size_t bad = 0, first = 0;
            for (size_t i = 0; i < (size_t)n; i++)
                if (labels[i] != ref[i] && !bad++) first = i;
            if (nref != ncomp || bad) {
                vw_cli_error(CMD, "distributed result differs from the sequential one: %lld vs %lld "
                             "components, %zu labels differ%s", (long long)ncomp, (long long)nref, bad,
                             bad ? "" : " (none)");
                if (bad)
                    vw_cli_error(CMD, "first: sphere %zu has label %lld, expected %lld", first,
                                 (long long)labels[first], (long long)ref[first]);
                rc = VW_EXIT_FAIL;
            }
        }
        /* After the check: a run that fails leaves no output file. */
        if (rc == VW_EXIT_OK && stats) {
            char extra[256];
            snprintf(extra, sizeof extra,
                     "\"components\": {\"count\": %lld, \"local\": %lld, \"label_messages\": %lld, "
                     "\"relabels\": %lld}",
                     (long long)ncomp, (long long)vw_world_counter(w, EX_COMPONENTS_CNT_LOCAL),
                     (long long)vw_world_counter(w, EX_COMPONENTS_CNT_LABEL_MSGS),
                     (long long)vw_world_counter(w, EX_COMPONENTS_CNT_RELABELS));
            if (vw_world_write_stats(w, stats, CMD, extra) != VW_OK) {
                vw_cli_error(CMD, "%s", vw_world_errmsg(w));
                rc = VW_EXIT_FAIL;
            }
        }
    }
    vw_world_free(w);
    vw_decomp_free(d);
    free(s), free(labels), free(ref);
    return rc;
}
