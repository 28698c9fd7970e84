/* test_farm.c - farmed work (vw_ctx_next_batch): the copies of a duplicated cell make
 * its batches from step(), and every batch must be made exactly once in every run,
 * whatever the interleaving. With vw_config.steal off each copy makes exactly its
 * turns (copy r of k: r, r + k, ...); with it on, a copy whose turns are used up takes
 * the turns the others have not taken, so a copy on a slowed-down worker (emulated with
 * vw_config.worker_slowdown) leaves most of its share to the fast one. With worker
 * speeds (vw_config.worker_speeds) the shares follow them.
 *
 * Under mpirun (--mpi) the copies are on every worker of every process, and a copy
 * takes the turns of copies in other processes too (a request to the process that
 * holds their counter). Each process sees only the batches its own copies made, so
 * "every batch once" is checked on the gathered counters: how many were made, and the
 * sum of a 40-bit hash of each batch's number.
 *
 * --garble-turn (under mpirun): every process's first turn request names a copy that
 * does not exist (VW_FAULT=turn-garble); the receiver must end the job saying so
 * (mpi_turn_check).
 *
 * usage: test_farm [--stress]   (also honours VW_STRESS)
 *        mpirun -np N test_farm --mpi [--stress] [--garble-turn]
 */
#include <stdatomic.h>
#include <string.h>

#include "vw_test.h"
#include "vwalls/vwalls.h"

enum { CNT_MADE, CNT_HASH, NCOUNTERS };

typedef struct farm {
    uint64_t nbatches;
    atomic_int *made; /* per cell and batch (cell * nbatches + batch): times made this run */
    int work;         /* iterations of busy work a batch */
} farm;

/* The cells keep nothing of their own: their state is the shared farm. */
static vw_status build(vw_ctx *ctx, const void *objs, size_t n, void **state)
{
    (void)objs, (void)n;
    *state = vw_ctx_user(ctx);
    return VW_OK;
}

static void cell_free(void *state, void *user) { (void)state, (void)user; }

/* A batch number's hash (splitmix64's finaliser), 40 bits: sums of a million fit. */
static int64_t batch_hash(uint64_t b)
{
    b += 0x9e3779b97f4a7c15ull;
    b = (b ^ (b >> 30)) * 0xbf58476d1ce4e5b9ull;
    b = (b ^ (b >> 27)) * 0x94d049bb133111ebull;
    return (int64_t)((b ^ (b >> 31)) >> 24);
}

/* One batch per call, with a little work in it, so the slowdown's meter has time to
   stretch. */
static int step(vw_ctx *ctx, void *state)
{
    (void)state;
    farm *f = vw_ctx_user(ctx);
    uint64_t b = vw_ctx_next_batch(ctx, f->nbatches);
    if (b >= f->nbatches) return 0;
    atomic_fetch_add(&f->made[(size_t)vw_ctx_cell(ctx) * f->nbatches + b], 1);
    vw_count(ctx, CNT_MADE, 1);
    vw_count(ctx, CNT_HASH, batch_hash(b));
    volatile double x = 1;
    for (int i = 0; i < f->work; i++) x = x * 1.0000001 + 1e-9;
    return 1;
}

static void ignore(vw_ctx *ctx, void *state, const void *msg) { (void)ctx, (void)state, (void)msg; }

static const vw_msg_kind kinds[] = {{"unused", 8, ignore, NULL, VW_MSG_INDEPENDENT}};
static const char *const counters[] = {"made", "hash"};

static const vw_module farm_module = {
    .abi = VW_MODULE_ABI,
    .name = "farm",
    .kinds = kinds,
    .nkinds = 1,
    .counters = counters,
    .ncounters = NCOUNTERS,
    .cell_build = build,
    .cell_free = cell_free,
    .step = step,
};

/* Runs `runs` times a world of one cell with a copy on every other worker (of every
   process); returns the batches worker 0 made per run on average. Every batch is made
   once in every run. `workers` is per process. */
static int64_t farm_runs_work(int workers, int steal, const double *slowdown,
                              const double *speeds, uint64_t nbatches, int runs, uint64_t stress,
                              int work)
{
    vw_box box = {{0, 0, 0}, {1, 1, 1}};
    int dims[3] = {1, 1, 1};
    vw_decomp *d;
    CHECK_EQ_INT(vw_decomp_create_grid(&box, dims, &d), VW_OK);
    farm f = {nbatches, calloc(nbatches, sizeof(atomic_int)), work};
    CHECK(f.made != NULL);
    vw_config cfg;
    vw_config_init(&cfg);
    cfg.workers = workers;
    cfg.steal = steal;
    cfg.worker_slowdown = slowdown;
    cfg.worker_speeds = speeds;
    if (stress && !cfg.stress_seed) cfg.stress_seed = stress;
    vw_world *w;
    CHECK_EQ_INT(vw_world_create(&farm_module, &f, d, &cfg, &w), VW_OK);
    int procs = vw_world_processes(w), gworkers = workers * procs;
    int on[64], n = 0;
    for (int g = 1; g < gworkers && n < 64; g++) on[n++] = g;
    CHECK_EQ_INT(vw_world_set_replicas(w, 0, on, n), VW_OK);
    int64_t hashes = 0;
    for (uint64_t b = 0; b < nbatches; b++) hashes += batch_hash(b);
    for (int r = 0; r < runs; r++) {
        for (uint64_t b = 0; b < nbatches; b++) atomic_store(&f.made[b], 0);
        CHECK_EQ_INT(vw_world_run(w), VW_OK);
        if (procs == 1) {
            uint64_t wrong = 0;
            for (uint64_t b = 0; b < nbatches; b++) wrong += atomic_load(&f.made[b]) != 1;
            EXPECT(wrong == 0, "%d workers, steal %d, run %d: %llu of %llu batches not made once",
                   workers, steal, r, (unsigned long long)wrong, (unsigned long long)nbatches);
        }
        /* The workers' counters (every process's) add up over the runs. */
        int64_t sum = 0, hash = 0;
        for (int g = 0; g < gworkers; g++) {
            sum += vw_world_worker_counter(w, g, CNT_MADE);
            hash += vw_world_worker_counter(w, g, CNT_HASH);
        }
        EXPECT(sum == (int64_t)nbatches * (r + 1) && hash == hashes * (r + 1),
               "%d processes x %d workers, steal %d, run %d: the workers made %lld batches of "
               "%llu a run, hash sum %s", procs, workers, steal, r, (long long)sum,
               (unsigned long long)nbatches, hash == hashes * (r + 1) ? "right" : "wrong");
    }
    int64_t mine = vw_world_worker_counter(w, 0, CNT_MADE);
    vw_world_free(w);
    vw_decomp_free(d);
    free(f.made);
    return runs > 0 ? mine / runs : 0;
}

static int64_t farm_runs(int workers, int steal, const double *slowdown, const double *speeds,
                         uint64_t nbatches, int runs, uint64_t stress)
{
    return farm_runs_work(workers, steal, slowdown, speeds, nbatches, runs, stress, 2000);
}

/* Cell c's copies in pattern p: on the k = (c + p) % gw workers after its master m
   (some cells have none, some a copy on every other worker). */
static int pattern_copies(int c, int m, int gw, int p, int *on)
{
    int k = (c + p) % gw;
    for (int i = 0; i < k; i++) on[i] = (m + 1 + i) % gw;
    return k;
}

/* Runs the world once and checks every cell's batches were each made once; with steal
   off and equal speeds, also that every worker made exactly the turns of the units it
   hosts (unit u of a cell with k units: batches u, u + k, ...), so each unit was on its
   worker's list exactly once. */
static void check_cells_run(vw_world *w, farm *f, int ncells, int gw, int steal, const char *when)
{
    size_t nb = f->nbatches;
    for (size_t i = 0; i < (size_t)ncells * nb; i++) atomic_store(&f->made[i], 0);
    vw_world_reset_stats(w);
    CHECK_EQ_INT(vw_world_run(w), VW_OK);
    uint64_t wrong = 0;
    for (size_t i = 0; i < (size_t)ncells * nb; i++) wrong += atomic_load(&f->made[i]) != 1;
    EXPECT(wrong == 0, "%d cells, steal %d, %s: %llu of %zu batches not made once", ncells,
           steal, when, (unsigned long long)wrong, (size_t)ncells * nb);
    if (steal) return;
    int64_t want[64] = {0};
    int on[64];
    for (int c = 0; c < ncells; c++) {
        int n = vw_world_replicas(w, c, on, 64), k = n + 1;
        for (int u = 0; u < k; u++) {
            int g = u ? on[u - 1] : vw_world_cell_worker(w, c);
            if ((size_t)u < nb) want[g] += (int64_t)((nb - (size_t)u + (size_t)k - 1) / (size_t)k);
        }
    }
    for (int g = 0; g < gw; g++) {
        int64_t made = vw_world_worker_counter(w, g, CNT_MADE);
        EXPECT(made == want[g], "%d cells, %s: worker %d made %lld batches, its units' turns "
               "are %lld", ncells, when, g, (long long)made, (long long)want[g]);
    }
}

/* Copies set on many cells, some set twice or dropped before the commit, then run:
   the workers' lists of units are made once at the commit (vw_world.units_stale), and
   must come out as if remade at every vw_world_set_replicas. Then copies changed after
   a run, and after a remap (which lists the units itself). */
static void farm_many_cells(int workers, int steal, uint64_t stress)
{
    vw_box box = {{0, 0, 0}, {1, 1, 1}};
    int dims[3] = {4, 3, 2};
    vw_decomp *d;
    CHECK_EQ_INT(vw_decomp_create_grid(&box, dims, &d), VW_OK);
    int nc = vw_decomp_cell_count(d);
    farm f = {37, calloc((size_t)nc * 37, sizeof(atomic_int)), 200};
    CHECK(f.made != NULL);
    vw_config cfg;
    vw_config_init(&cfg);
    cfg.workers = workers;
    cfg.steal = steal;
    if (stress && !cfg.stress_seed) cfg.stress_seed = stress;
    vw_world *w;
    CHECK_EQ_INT(vw_world_create(&farm_module, &f, d, &cfg, &w), VW_OK);
    int gw = workers, on[64];
    for (int c = 0; c < nc; c++) {
        int n = pattern_copies(c, vw_world_cell_worker(w, c), gw, 0, on);
        CHECK_EQ_INT(vw_world_set_replicas(w, c, on, n), VW_OK);
    }
    for (int c = 1; c < nc; c += 2) { /* again, otherwise, before any commit */
        int n = pattern_copies(c, vw_world_cell_worker(w, c), gw, 1, on);
        CHECK_EQ_INT(vw_world_set_replicas(w, c, on, n), VW_OK);
    }
    check_cells_run(w, &f, nc, gw, steal, "copies set before the first run");
    check_cells_run(w, &f, nc, gw, steal, "run again");
    for (int c = 0; c < nc; c += 3) {
        int n = pattern_copies(c, vw_world_cell_worker(w, c), gw, 2, on);
        CHECK_EQ_INT(vw_world_set_replicas(w, c, on, n), VW_OK);
    }
    CHECK_EQ_INT(vw_world_commit(w), VW_OK);
    check_cells_run(w, &f, nc, gw, steal, "copies changed after a run, then committed");
    int cw[64];
    for (int c = 0; c < nc; c++) cw[c] = (c * 7 + 1) % gw;
    CHECK_EQ_INT(vw_world_remap(w, cw), VW_OK); /* (drops the copies) */
    check_cells_run(w, &f, nc, gw, steal, "remapped");
    for (int c = 0; c < nc; c++) {
        int n = pattern_copies(c, cw[c], gw, 3, on);
        CHECK_EQ_INT(vw_world_set_replicas(w, c, on, n), VW_OK);
    }
    check_cells_run(w, &f, nc, gw, steal, "remapped, copies set again");
    vw_world_free(w);
    vw_decomp_free(d);
    free(f.made);
}

/* Under mpirun: one worker per process, the copies spread over the processes. */
static void mpi_main(uint64_t stress)
{
    int procs = vw_engine_size();
    /* Off: exactly the turns, equal shares (402 batches: the master's share is 402 / N
       rounded up for N processes of one worker). */
    int64_t mine = farm_runs(1, 0, NULL, NULL, 402, 2, stress);
    int64_t share = (402 + procs - 1) / procs;
    EXPECT(mine == share, "steal off, %d processes: worker 0 made %lld of 402 batches, not "
           "its %lld turns", procs, (long long)mine, (long long)share);
    /* On, every other process's worker 1000 times slower: worker 0 takes most of their
       turns, asking their processes for them. The emulated slowdown spins for a multiple
       of the wall time the work took, and on a loaded machine the processes get unequal
       parts of their cores, so the ratio between them is not the factor: with 8x and 32x, two busy loops beside made worker 0 miss its 300 of 400
       batches (np 2) in 5 of 6 and 3 of 8 runs (253-297); with 1000x it made 391-392
       under the same load, and the run takes no longer, as worker 0 does the rest. */
    double slow[16];
    for (int g = 0; g < 16; g++) slow[g] = g ? 1000.0 : 1.0;
    if (procs <= 16) {
        mine = farm_runs_work(1, 1, slow, NULL, 400, 2, stress, 50000);
        EXPECT(mine > 400 / procs + 400 / (2 * procs), "steal on, the other processes slowed "
               "1000x: worker 0 made only %lld of 400 batches", (long long)mine);
    }
    /* Every batch once with two workers a process, with equal and unequal speeds. */
    static const double mixed[16] = {1.0, 2.5, 0.001, 7.0, 1.0, 3.0, 1.0, 2.0,
                                     1.0, 2.5, 0.001, 7.0, 1.0, 3.0, 1.0, 2.0};
    for (int steal = 0; steal <= 1; steal++) {
        farm_runs(2, steal, NULL, NULL, 997, 3, stress);
        if (procs <= 8) farm_runs(2, steal, NULL, mixed, 997, 2, stress);
    }
    farm_runs(1, 1, NULL, NULL, 1, 2, stress); /* fewer batches than copies */
}

int main(int argc, char **argv)
{
    int mpi = 0;
    uint64_t stress = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--stress"))
            stress = 7;
        else if (!strcmp(argv[i], "--mpi"))
            mpi = 1;
        else if (!strcmp(argv[i], "--garble-turn"))
            setenv("VW_FAULT", "turn-garble", 1); /* read by the transport */
    }
    if (mpi) {
        char msg[300];
        if (vw_engine_init(&argc, &argv, msg, sizeof msg) != VW_OK) {
            fprintf(stderr, "test_farm: %s\n", msg);
            return 1;
        }
        mpi_main(stress);
        printf("farm (%d processes): %d failures\n", vw_engine_size(), vw_test_failures);
        vw_engine_finish();
        return vw_test_failures ? 1 : 0;
    }
    /* Off: exactly the turns, equal shares (101 batches: the master gets one more). */
    int64_t mine = farm_runs(2, 0, NULL, NULL, 101, 3, stress);
    EXPECT(mine == 51, "steal off: worker 0 made %lld of 101 batches a run, not its 51 turns",
           (long long)mine);
    /* On, the copy's worker 8 times slower: the master takes most of the copy's turns. */
    static const double slow[2] = {1.0, 8.0};
    mine = farm_runs(2, 1, slow, NULL, 400, 2, stress);
    EXPECT(mine > 260, "steal on, copy slowed 8x: worker 0 made only %lld of 400 batches",
           (long long)mine);
    /* Off, with worker speeds 1 and 3: the master's share is exactly a quarter (8 of
       every 32 slots), and three quarters when the speeds are swapped. */
    static const double s13[2] = {1.0, 3.0}, s31[2] = {3.0, 1.0};
    mine = farm_runs(2, 0, NULL, s13, 400, 2, stress);
    EXPECT(mine == 100, "steal off, speeds 1,3: worker 0 made %lld of 400 batches a run, not 100",
           (long long)mine);
    mine = farm_runs(2, 0, NULL, s31, 400, 2, stress);
    EXPECT(mine == 300, "steal off, speeds 3,1: worker 0 made %lld of 400 batches a run, not 300",
           (long long)mine);
    /* Many copies, every batch once, under any interleaving (more workers than cores
       too: the copies race for the turns left), with equal and with unequal speeds
       (a very slow worker still gets a slot). */
    static const double mixed[6] = {1.0, 2.5, 0.001, 7.0, 1.0, 3.0};
    for (int workers = 2; workers <= 6; workers += 2)
        for (int steal = 0; steal <= 1; steal++) {
            farm_runs(workers, steal, NULL, NULL, 997, 3, stress);
            farm_runs(workers, steal, NULL, mixed, 997, 2, stress);
        }
    /* Fewer batches than copies: most copies get none. */
    farm_runs(6, 1, NULL, NULL, 3, 2, stress);
    farm_runs(6, 0, NULL, mixed, 3, 2, stress);
    /* Copies on many cells, set in bulk before a commit. */
    for (int steal = 0; steal <= 1; steal++) farm_many_cells(5, steal, stress);
    printf("farm: %d failures\n", vw_test_failures);
    return vw_test_failures ? 1 : 0;
}
