/* hello_cells.c - the tutorial's driver (docs/tutorial.md): runs hello_module on random
 * points, alone on worker threads or under mpirun, checks the result against a sequential
 * count, and prints counters and stats.
 *   usage: hello_cells [--points N] [--cells LAYOUT] [--workers W] [--stats FILE.json]
 */
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hello_module.h"

/* Every process generates the same points from the same seed (splitmix64). */
static double uniform(uint64_t *x)
{
    uint64_t z = (*x += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return (double)((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
}

/* The same answer without cells' help, to check against. */
static int check(const vw_decomp *d, const ex_point *pts, size_t n, const ex_hello_result *r)
{
    int ncells = vw_decomp_cell_count(d), bad = 0, nb[64];
    int64_t *own = calloc((size_t)ncells, sizeof *own);
    static const double plus[3] = {1, 1, 1};
    if (!own) return 1;
    for (size_t i = 0; i < n; i++) own[vw_decomp_locate(d, pts[i].p, plus)]++;
    for (int c = 0; c < ncells; c++) {
        int64_t sum = 0;
        for (int face = 0; face < 6; face++) {
            int k = vw_decomp_neighbours(d, c, face, nb, 64);
            for (int j = 0; j < k && j < 64; j++) sum += own[nb[j]];
        }
        if (own[c] != r->own[c] || sum != r->neighbours[c]) {
            fprintf(stderr, "cell %d: %lld own, %lld around; expected %lld, %lld\n", c,
                    (long long)r->own[c], (long long)r->neighbours[c], (long long)own[c],
                    (long long)sum);
            bad = 1;
        }
    }
    free(own);
    return bad;
}

/* [main] */
int main(int argc, char **argv)
{
    /* 1. The engine: under mpirun this initialises MPI; alone it does nothing. */
    char msg[256];
    if (vw_engine_init(&argc, &argv, msg, sizeof msg) != VW_OK) {
        fprintf(stderr, "hello_cells: %s\n", msg);
        return 1;
    }
    long npoints = 100000;
    int workers = 0;
    const char *layout = "2x2x2", *stats = NULL;
    for (int i = 1; i < argc; i += 2) {
        const char *opt = argv[i], *val = i + 1 < argc ? argv[i + 1] : "";
        char *end;
        long v = strtol(val, &end, 10);
        int number = *val && !*end && v >= 0 && v <= INT_MAX;
        if (!strcmp(opt, "--points") && number) npoints = v;
        else if (!strcmp(opt, "--workers") && number) workers = (int)v;
        else if (!strcmp(opt, "--cells") && *val) layout = val;
        else if (!strcmp(opt, "--stats") && *val) stats = val;
        else {   /* a typo must not run the defaults silently */
            fprintf(stderr, "hello_cells: bad option '%s %s'\nusage: hello_cells [--points N] "
                    "[--cells LAYOUT] [--workers W] [--stats FILE.json]\n", opt, val);
            vw_engine_finish();
            return 2;
        }
    }

    /* 2. The decomposition: the unit cube cut by walls into a grid of cells. */
    int dims[3];
    vw_decomp *d = NULL;
    vw_box unit = {{0, 0, 0}, {1, 1, 1}};
    if (vw_layout_parse(layout, dims, msg, sizeof msg) != VW_OK ||
        vw_decomp_create_grid(&unit, dims, &d) != VW_OK) {
        fprintf(stderr, "hello_cells: --cells %s: %s\n", layout, msg);
        vw_engine_finish();
        return 2;
    }
    int ncells = vw_decomp_cell_count(d);

    /* 3. The objects: every process adds all of them; each keeps those in its cells.
          What a process prepares alone is agreed on before the world: under mpirun, one
          that gave up alone would leave the others waiting in vw_world_create. */
    size_t n = npoints > 0 ? (size_t)npoints : 0;
    ex_point *pts = malloc(sizeof *pts * (n ? n : 1));
    ex_hello_result result = {ncells, calloc((size_t)ncells, sizeof(int64_t)),
                              calloc((size_t)ncells, sizeof(int64_t)), 0};
    vw_config cfg;
    vw_config_init(&cfg);           /* defaults, then VW_STRESS from the environment */
    cfg.workers = workers;          /* 0: one per core */
    msg[0] = 0;
    vw_status st = pts && result.own && result.neighbours ? VW_OK : VW_E_NOMEM;
    st = vw_config_agree(&cfg, st, msg, sizeof msg);
    uint64_t seed = 42;
    for (size_t i = 0; st == VW_OK && i < n; i++)
        for (int k = 0; k < 3; k++) pts[i].p[k] = uniform(&seed);

    /* 4. The world: create, add, commit (cells are built), run to quiescence. */
    vw_world *w = NULL;
    if (st == VW_OK) {
        st = vw_world_create(&ex_hello_module, &result, d, &cfg, &w);
        /* With w NULL, vw_world_errmsg says why vw_world_create made no world. */
        if (st == VW_OK) st = vw_world_add_objects(w, pts, n);
        if (st == VW_OK) st = vw_world_commit(w);
        if (st == VW_OK) st = vw_world_run(w);
        if (st != VW_OK) snprintf(msg, sizeof msg, "%s", vw_world_errmsg(w));
    }
    int rc = 0;
    if (st != VW_OK) {
        fprintf(stderr, "hello_cells: %s\n", *msg ? msg : vw_status_message(st));
        rc = 1;
    }

    /* 5. Results. Counters and stats are valid on every process; what output handlers
          collected is on the output process only, so only it prints and checks. */
    if (rc == 0 && vw_world_is_output(w)) {
        printf("%d cells on %d process(es) x %d worker(s)\n", ncells, vw_world_processes(w),
               vw_world_workers(w));
        printf("points %lld, count messages %lld, imbalance %.2f\n",
               (long long)vw_world_counter(w, EX_HELLO_CNT_POINTS),
               (long long)vw_world_counter(w, EX_HELLO_CNT_MESSAGES), vw_world_imbalance(w));
        for (int c = 0; c < ncells && c < 8; c++) {
            vw_cell_stats cs;
            vw_world_cell_stats(w, c, &cs);
            printf("cell %d (worker %d): %lld points, %lld around, %llu messages in\n", c,
                   cs.worker, (long long)result.own[c], (long long)result.neighbours[c],
                   (unsigned long long)cs.messages_in);
        }
        if (result.summaries != ncells) {
            fprintf(stderr, "%lld summaries for %d cells: each cell must report once\n",
                    (long long)result.summaries, ncells);
            rc = 1;
        }
        if (vw_world_counter(w, EX_HELLO_CNT_POINTS) != (int64_t)n || check(d, pts, n, &result))
            rc = 1;
        if (stats && vw_world_write_stats(w, stats, "hello_cells", NULL) != VW_OK) {
            fprintf(stderr, "hello_cells: %s\n", vw_world_errmsg(w));
            rc = 1;
        }
        printf("%s\n", rc ? "MISMATCH" : "ok");
    }

    /* 6. Clean up; vw_engine_finish finalises MPI if vw_engine_init started it. */
    vw_world_free(w);
    vw_decomp_free(d);
    free(pts), free(result.own), free(result.neighbours);
    vw_engine_finish();
    return rc;
}
/* [main] */
