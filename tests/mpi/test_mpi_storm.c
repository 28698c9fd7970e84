/* test_mpi_storm.c - a message storm across processes: chains of tokens hop between
 * random cells (so most hops cross a process boundary under MPI), some go to the output
 * process, some are posted before the run. What arrives is a pure function of the seed,
 * so every rank checks the global counters, per-cell figures and output against a
 * sequential reference, over two runs of the same world. Also: agreement between ranks,
 * a rank that dies in the middle of a run (for the fault tests), and a step of the
 * world's life that fails on one rank only (--fail: every rank must fail it, naming it),
 * a peer whose module differs (--agree), a peer that sends a garbled packet (--wire) and
 * a step() that calls vw_world_agree (--agree-in-step: the job must stop, naming it).
 *
 * usage: test_mpi_storm [--workers W] [--seeds N] [--agree] [--kill-rank R] [--exit-rank R]
 *                       [--hang-rank R]
 *                       [--fail STEP --fail-rank R] [--wire] [--agree-in-step]
 * Runs alone (threads engine) or under mpirun; honours VW_STRESS / VW_STRESS_SPLIT.
 */
#include <mpi.h>
#include <signal.h>
#include <string.h>
#include <unistd.h>

#include "vw_test.h"
#include "vwalls/engine.h"
#include "vwalls/vwalls.h"

enum { MSG_TOKEN, MSG_POSTED, NKINDS };
enum { CNT_RECEIVED, CNT_SUM, CNT_CORRUPT, CNT_OUTPUT, CNT_POSTED, NCOUNTERS };

typedef struct token {
    uint64_t key;
    uint32_t hops;
    uint32_t len;
    unsigned char payload[96];
} token;

typedef struct storm {
    uint64_t seed;
    int ncells, roots;
    int64_t output_sum;   /* output handler only (serialised, rank 0) */
    int kill_rank;        /* -1: nobody dies */
    int fail_build_rank;  /* cell_build fails on this rank's cells (-1: none) */
    int fail_run;         /* rank + 1 whose handler fails the run (0: none); then every
                             cell's step() sends tokens for ever, so the run can only end
                             if every rank drops its work */
    int hang_rank1;       /* rank + 1 whose handler hangs (0: none): a rank alive but stuck,
                             which only the launcher's time limit ends (MPIEXEC_TIMEOUT) */
} storm;

static void fill(token *t, uint64_t key, uint32_t hops)
{
    t->key = key;
    t->hops = hops;
    t->len = (uint32_t)(vw_test_mix(key ^ 1) % sizeof t->payload);
    for (uint32_t i = 0; i < t->len; i++) t->payload[i] = (unsigned char)vw_test_mix(key + i);
}

static int nchildren(const token *t)
{
    return t->hops ? 1 + (int)(vw_test_mix(t->key ^ 2) % 2) : 0;
}
static int dest_of(uint64_t key, int ncells)
{
    return (int)(vw_test_mix(key ^ 3) % (uint64_t)ncells);
}
static uint64_t child_key(const token *t, int c) { return vw_test_mix(t->key + 100 + (uint64_t)c); }
static int64_t low(uint64_t k) { return (int64_t)(k & 0xffffffu); }

/* The reference: deliveries per cell, key sum, output count and output key sum. */
static void expect(uint64_t key, uint32_t hops, int ncells, int64_t *per_cell, int64_t *sum,
                   int64_t *outputs, int64_t *outsum)
{
    token t;
    fill(&t, key, hops);
    per_cell[dest_of(key, ncells)]++;
    *sum += low(key);
    if ((key & 7) == 0) (*outputs)++, *outsum += low(key);
    for (int c = 0; c < nchildren(&t); c++)
        expect(child_key(&t, c), hops - 1, ncells, per_cell, sum, outputs, outsum);
}

static uint64_t root_key(const storm *st, int cell, int r)
{
    return vw_test_mix(st->seed ^ ((uint64_t)cell << 24) ^ (uint64_t)r);
}

typedef struct tcell {
    int roots_sent;
} tcell;

static vw_status build(vw_ctx *ctx, const void *objs, size_t n, void **state)
{
    (void)objs, (void)n;
    if (((storm *)vw_ctx_user(ctx))->fail_build_rank == vw_ctx_process(ctx)) return VW_E_INPUT;
    *state = calloc(1, sizeof(tcell));
    return *state ? VW_OK : VW_E_NOMEM;
}

static void cell_free(void *state, void *user)
{
    (void)user;
    free(state);
}

static int step(vw_ctx *ctx, void *state)
{
    tcell *tc = state;
    storm *st = vw_ctx_user(ctx);
    if (tc->roots_sent == st->roots && !st->fail_run) return 0;
    uint64_t key = root_key(st, vw_ctx_cell(ctx), tc->roots_sent++);
    token t;
    fill(&t, key, 2 + (uint32_t)(key % 5));
    vw_send_cell(ctx, dest_of(key, st->ncells), MSG_TOKEN, &t);
    return 1;
}

static void on_token(vw_ctx *ctx, void *state, const void *msg)
{
    (void)state;
    const token *t = msg;
    storm *st = vw_ctx_user(ctx);
    static _Atomic long handled;
    if (st->kill_rank == vw_ctx_process(ctx) && ++handled == 500) raise(SIGKILL);
    if (st->hang_rank1 == vw_ctx_process(ctx) + 1 && ++handled == 500) {
        fprintf(stderr, "test_mpi_storm: rank %d hangs on purpose\n", vw_ctx_process(ctx));
        for (;;) pause(); /* its communication thread goes on: alive, but never done */
    }
    if (st->fail_run == vw_ctx_process(ctx) + 1 && ++handled == 2000)
        vw_ctx_fail(ctx, VW_E_NOMEM, "no room for token %ld", (long)handled);
    token check;
    fill(&check, t->key, t->hops);
    if (check.len != t->len || memcmp(check.payload, t->payload, t->len) != 0 ||
        dest_of(t->key, st->ncells) != vw_ctx_cell(ctx))
        vw_count(ctx, CNT_CORRUPT, 1);
    vw_count(ctx, CNT_RECEIVED, 1);
    vw_count(ctx, CNT_SUM, low(t->key));
    if ((t->key & 7) == 0) {
        vw_send_output(ctx, MSG_TOKEN, t);
        vw_count(ctx, CNT_OUTPUT, 1);
    }
    for (int c = 0; c < nchildren(t); c++) {
        token k;
        uint64_t key = child_key(t, c);
        fill(&k, key, t->hops - 1);
        vw_send_cell(ctx, dest_of(key, st->ncells), MSG_TOKEN, &k);
    }
}

static void on_posted(vw_ctx *ctx, void *state, const void *msg)
{
    (void)state;
    const int64_t *v = msg;
    vw_count(ctx, CNT_POSTED, *v);
}

static void on_output(void *user, const void *msg)
{
    storm *st = user;
    st->output_sum += low(((const token *)msg)->key);
}

static const vw_msg_kind kinds[NKINDS] = {
    [MSG_TOKEN] = {"token", sizeof(token), on_token, on_output},
    /* Independent (any copy may count it: copies add up to their cell), so a cell can
       be duplicated (test_mismatch). */
    [MSG_POSTED] = {"posted", sizeof(int64_t), on_posted, NULL, VW_MSG_INDEPENDENT},
};
static const char *const counters[NCOUNTERS] = {"received", "sum", "corrupt", "output", "posted"};
static const vw_module storm_module = {
    .abi = VW_MODULE_ABI,
    .name = "mpi-storm",
    .kinds = kinds,
    .nkinds = NKINDS,
    .counters = counters,
    .ncounters = NCOUNTERS,
    .cell_build = build,
    .cell_free = cell_free,
    .step = step,
};

/* Every rank passes a status; rank `bad` fails. All must agree on rank bad's message. */
static void test_agree(int bad)
{
    int rank = vw_engine_rank(), size = vw_engine_size();
    char msg[256];
    snprintf(msg, sizeof msg, "%s", rank == bad ? "scene.nff:3: bad number 'x'" : "");
    vw_status st = vw_engine_agree(rank == bad ? VW_E_INPUT : VW_OK, msg, sizeof msg);
    if (bad < size) {
        CHECK_EQ_INT(st, VW_E_INPUT);
        char want[256];
        snprintf(want, sizeof want, size > 1 ? "rank %d: scene.nff:3: bad number 'x'"
                                             : "scene.nff:3: bad number 'x'", bad);
        if (strcmp(msg, want) != 0) {
            fprintf(stderr, "rank %d: agreed message '%s', expected '%s'\n", rank, msg, want);
            exit(1);
        }
    } else {
        CHECK_EQ_INT(st, VW_OK);
    }
    CHECK_EQ_INT(vw_engine_agree(VW_OK, NULL, 0), VW_OK);
}

/* vw_config_agree agrees on the communicator a configuration names, before any world:
   MPI_COMM_WORLD when it names none (as vw_engine_agree), else that one alone. Rank
   `bad` fails; with the job split into even and odd ranks, only bad's half learns it,
   from "rank R" of that half. */
static void expect_agreed(vw_status st, const char *msg, int failed, int r, int n)
{
    char want[256];
    snprintf(want, sizeof want, n > 1 ? "rank %d: no memory for the cells" : "no memory for the cells", r);
    if (!failed) {
        CHECK_EQ_INT(st, VW_OK);
    } else {
        CHECK_EQ_INT(st, VW_E_NOMEM);
        if (strcmp(msg, want) != 0) {
            fprintf(stderr, "rank %d: agreed message '%s', expected '%s'\n", vw_engine_rank(), msg, want);
            exit(1);
        }
    }
}

static void test_config_agree(int bad)
{
    int rank = vw_engine_rank(), size = vw_engine_size();
    char msg[256];
    snprintf(msg, sizeof msg, "%s", rank == bad ? "no memory for the cells" : "");
    vw_status st = vw_config_agree(NULL, rank == bad ? VW_E_NOMEM : VW_OK, msg, sizeof msg);
    expect_agreed(st, msg, bad < size, bad, size);

    MPI_Comm half;
    MPI_Comm_split(MPI_COMM_WORLD, rank % 2, rank, &half); /* rank r is r / 2 there */
    int hsize;
    MPI_Comm_size(half, &hsize);
    vw_config c;
    vw_config_init(&c);
    c.mpi_comm = &half;
    snprintf(msg, sizeof msg, "%s", rank == bad ? "no memory for the cells" : "");
    st = vw_config_agree(&c, rank == bad ? VW_E_NOMEM : VW_OK, msg, sizeof msg);
    expect_agreed(st, msg, bad < size && bad % 2 == rank % 2, bad / 2, hsize);
    MPI_Comm_free(&half);
}

static void point_bounds(const void *o, vw_box *b, void *user)
{
    (void)user;
    const double *p = o;
    for (int a = 0; a < 3; a++) b->lo[a] = b->hi[a] = p[a];
}

/* A world given differently to one process (the last) fails to commit on every process,
   with a message naming it, instead of running on and meeting packets it cannot read:
   other walls, another mapping, other copies, other worker speeds (the copies'
   shares: every process must agree on who makes which batch), or other objects (a
   scene file that differs between hosts: the answer would be wrong without a word).
   The same world commits. */
static void test_mismatch(int workers)
{
    int rank = vw_engine_rank(), size = vw_engine_size(), bad = size - 1;
    vw_box box = {{0, 0, 0}, {1, 1, 1}};
    static const char *const what_name[] = {"same", "walls", "mapping", "copies", "speeds", "objects"};
    vw_module with_objects = storm_module;
    with_objects.object_size = 3 * sizeof(double);
    with_objects.object_bounds = point_bounds;
    for (int what = 0; what < 6; what++) {
        int differs = what > 0 && rank == bad && size > 1;
        int dims[3] = {2, 2, differs && what == 1 ? 1 : 2};
        vw_decomp *d;
        CHECK_EQ_INT(vw_decomp_create_grid(&box, dims, &d), VW_OK);
        int nc = vw_decomp_cell_count(d), gw = size * workers;
        int *map = malloc(sizeof(int) * (size_t)nc);
        for (int c = 0; c < nc; c++) map[c] = c % gw;
        if (differs && what == 2) map[0] = 1 % gw, map[1] = 0;
        storm st = {1, nc, 0, 0, -1, -1};
        vw_config cfg;
        vw_config_init(&cfg);
        cfg.workers = workers;
        cfg.cell_worker = map;
        double *speeds = malloc(sizeof(double) * (size_t)gw);
        for (int g = 0; g < gw; g++) speeds[g] = differs && what == 4 && g == 0 ? 3.0 : 1.0;
        cfg.worker_speeds = speeds;
        vw_world *w;
        CHECK_EQ_INT(vw_world_create(what == 0 || what == 5 ? &with_objects : &storm_module, &st, d,
                                     &cfg, &w), VW_OK);
        free(speeds); /* the world keeps its own copy */
        if (what == 0 || what == 5) {
            double pts[3][3] = {{0.1, 0.2, 0.3}, {0.6, 0.6, 0.6}, {0.9, 0.1, 0.5}};
            if (differs) pts[2][1] = 0.15; /* one point elsewhere in the same cell */
            CHECK_EQ_INT(vw_world_add_objects(w, pts, 3), VW_OK);
        }
        /* Every process sets the copies (a collective step); the one that differs gives
           cell 0 a copy where the others give it none. */
        if (what == 3 || (what == 4 && gw > 1)) {
            int other = (map[0] + 1) % gw, n = what == 4 || differs ? 1 : 0;
            CHECK_EQ_INT(vw_world_set_replicas(w, 0, n ? &other : NULL, n), VW_OK);
        }
        vw_status got = vw_world_commit(w);
        if (what == 0 || size == 1 || gw < 2) {
            EXPECT(got == VW_OK, "%s: commit %d: %s", what_name[what], (int)got, vw_world_errmsg(w));
        } else {
            char want[64];
            snprintf(want, sizeof want, "process %d was given another world", bad);
            EXPECT(got == VW_E_STATE && strstr(vw_world_errmsg(w), want),
                   "rank %d, %s: commit %d: '%s'", rank, what_name[what], (int)got,
                   vw_world_errmsg(w));
        }
        vw_world_free(w);
        vw_decomp_free(d);
        free(map);
    }
}

/* Rank `bad` runs another build of the module: one message kind more, a kind of another
   size, another record size, another counter or another name. Packets cross MPI as raw
   bytes, so every process must refuse the world when it is created (the others' messages
   would be read wrongly), naming that process. */
static void test_module_mismatch(int workers)
{
    int rank = vw_engine_rank(), size = vw_engine_size(), bad = size - 1;
    static const char *const what_name[] = {"same", "a kind more", "a kind's size",
                                            "the record size", "a counter", "the name"};
    static const vw_msg_kind more[NKINDS + 1] = {
        [MSG_TOKEN] = {"token", sizeof(token), on_token, on_output},
        [MSG_POSTED] = {"posted", sizeof(int64_t), on_posted, NULL, 0},
        [NKINDS] = {"newer", sizeof(int64_t), on_posted, NULL, 0},
    };
    static const vw_msg_kind wider[NKINDS] = {
        [MSG_TOKEN] = {"token", sizeof(token), on_token, on_output},
        [MSG_POSTED] = {"posted", 2 * sizeof(int64_t), on_posted, NULL, 0},
    };
    static const char *const other_counters[NCOUNTERS] = {"received", "sum", "corrupt", "output",
                                                          "posted twice"};
    vw_box box = {{0, 0, 0}, {1, 1, 1}};
    int dims[3] = {2, 1, 1};
    for (int what = 0; what < 6; what++) {
        vw_module m = storm_module;
        if (what > 0 && rank == bad) {
            if (what == 1) m.kinds = more, m.nkinds = NKINDS + 1;
            if (what == 2) m.kinds = wider;
            if (what == 3) m.object_size = 3 * sizeof(double), m.object_bounds = point_bounds;
            if (what == 4) m.counters = other_counters;
            if (what == 5) m.name = "mpi-storm 2";
        }
        vw_decomp *d;
        CHECK_EQ_INT(vw_decomp_create_grid(&box, dims, &d), VW_OK);
        storm st = {1, 2, 0, 0, -1, -1};
        vw_config cfg;
        vw_config_init(&cfg);
        cfg.workers = workers;
        vw_world *w = NULL;
        vw_status got = vw_world_create(&m, &st, d, &cfg, &w);
        if (what == 0 || size == 1) {
            EXPECT(got == VW_OK, "%s: create %d: %s", what_name[what], (int)got, vw_world_errmsg(NULL));
        } else {
            char want[64];
            snprintf(want, sizeof want, "process %d runs another module than process 0", bad);
            EXPECT(got == VW_E_INVAL && !w && strstr(vw_world_errmsg(NULL), want),
                   "rank %d, %s: create %d: '%s'", rank, what_name[what], (int)got,
                   vw_world_errmsg(NULL));
        }
        vw_world_free(w);
        vw_decomp_free(d);
    }
}

/* One step of a world's life fails on rank `bad` only, the way a local failure does
   (out of memory, a cell that cannot be built): create (a bad worker speed), add (more
   objects than memory), update (an unknown object), replicas (a worker that does not
   exist), redecompose (a mapping to one), commit (cell_build fails on that rank's
   cells), run (the same, in the commit that run makes), handler (a message handler
   calls vw_ctx_fail in the run, while every cell's step() sends for ever). Every rank
   goes on like any
   program: it stops at the first step that fails, frees what it has and finishes MPI.
   The step must fail on every rank with the failing rank's message, or the others
   would wait for it in the next collective call (and it for them in MPI_Finalize). */
static int local_failure(const char *step, int bad, int workers)
{
    int rank = vw_engine_rank(), here = rank == bad;
    vw_box box = {{0, 0, 0}, {1, 1, 1}};
    int dims[3] = {2, 2, 1};
    vw_decomp *d;
    CHECK_EQ_INT(vw_decomp_create_grid(&box, dims, &d), VW_OK);
    int nc = vw_decomp_cell_count(d), gw = vw_engine_size() * workers;
    storm st = {1, nc, 1, 0, -1, here && (!strcmp(step, "commit") || !strcmp(step, "run")) ? bad : -1,
                !strcmp(step, "handler") ? bad + 1 : 0};
    vw_module mod = storm_module;
    mod.object_size = 3 * sizeof(double);
    mod.object_bounds = point_bounds;
    vw_config cfg;
    vw_config_init(&cfg);
    cfg.workers = workers;
    double *speeds = malloc(sizeof(double) * (size_t)gw);
    for (int g = 0; g < gw; g++) speeds[g] = here && !strcmp(step, "create") ? -1.0 : 1.0;
    cfg.worker_speeds = speeds;
    vw_world *w = NULL;
    const char *failed = "create";
    vw_status s = vw_world_create(&mod, &st, d, &cfg, &w);
    free(speeds);
    double pts[3][3] = {{0.1, 0.2, 0.3}, {0.6, 0.6, 0.6}, {0.9, 0.1, 0.5}};
    if (s == VW_OK) {
        failed = "add";
        /* A count whose bytes do not fit a size_t: refused as out of memory. */
        s = vw_world_add_objects(w, pts, here && !strcmp(step, "add") ? SIZE_MAX / 2 : 3);
    }
    if (s == VW_OK) {
        failed = "update";
        s = vw_world_update_object(w, here && !strcmp(step, "update") ? 99 : 1, pts[2]);
    }
    if (s == VW_OK && gw > 1) {
        failed = "replicas";
        int other = here && !strcmp(step, "replicas") ? gw + 5 : (vw_world_cell_worker(w, 0) + 1) % gw;
        s = vw_world_set_replicas(w, 0, &other, 1);
    }
    if (s == VW_OK) {
        failed = "redecompose";
        int *map = malloc(sizeof(int) * (size_t)nc);
        for (int c = 0; c < nc; c++) map[c] = here && !strcmp(step, "redecompose") ? gw + c : c % gw;
        s = vw_world_redecompose(w, d, map);
        free(map);
    }
    if (s == VW_OK && strcmp(step, "run") != 0 && strcmp(step, "handler") != 0) {
        failed = "commit";
        s = vw_world_commit(w);
    }
    if (s == VW_OK) {
        failed = !strcmp(step, "handler") ? "handler" : "run";
        s = vw_world_run(w);
    }
    char want[64];
    snprintf(want, sizeof want, "rank %d: ", bad);
    /* A build that fails names its cell: the lowest of rank bad's (both its workers
       fail, the one that fails first need not hold it). */
    int cell = 0;
    while (cell < nc && (cell % gw) / workers != bad) cell++;
    if (!strcmp(step, "commit") || !strcmp(step, "run"))
        snprintf(want, sizeof want, "rank %d: building cell %d failed: ", bad, cell);
    if (!strcmp(step, "handler")) snprintf(want, sizeof want, "rank %d: cell ", bad);
    const char *msg = vw_world_errmsg(w);
    int ok = s != VW_OK && !strcmp(failed, step) && strstr(msg, want) == msg &&
             (strcmp(step, "handler") != 0 || strstr(msg, ": no room for token 2000"));
    fprintf(stderr, "test_mpi_storm: process %d: %s failed (%s): %s%s\n", rank, failed,
            vw_status_message(s), msg, ok ? "" : " [UNEXPECTED]");
    vw_world_free(w);
    vw_decomp_free(d);
    return 1; /* as a program whose step failed */
}

/* --wire: rank 1 garbles the first packet it sends (VW_FAULT=wire-garble: its first
   message's kind becomes one past the module's last), as a bug or a corrupted buffer
   would; another build of the module is refused when the world is created
   (test_module_mismatch). Rank 0 must stop the job naming the packet's sender, not index
   its kinds past their end. */
static vw_status wire_build(vw_ctx *ctx, const void *objs, size_t n, void **state)
{
    (void)ctx, (void)objs, (void)n;
    *state = NULL;
    return VW_OK;
}

static int wire_step(vw_ctx *ctx, void *state)
{
    (void)state;
    static int sent;
    if (vw_ctx_process(ctx) != 1 || vw_ctx_cell(ctx) != 1 || sent) return 0;
    sent = 1;
    int64_t v = 7;
    vw_send_cell(ctx, 0, MSG_POSTED, &v);
    return 1;
}

/* A world of one cell per process on one worker each, running step (wire_build's
   cells), which the caller expects to stop the job: 1 when the run ended instead. */
static int run_line_world(vw_world **w, int (*step)(vw_ctx *, void *), const char *unnoticed)
{
    vw_module m = storm_module;
    m.cell_build = wire_build;
    m.cell_free = NULL;
    m.step = step;
    vw_box box = {{0, 0, 0}, {1, 1, 1}};
    int dims[3] = {vw_engine_size(), 1, 1};
    vw_decomp *d;
    CHECK_EQ_INT(vw_decomp_create_grid(&box, dims, &d), VW_OK);
    storm st = {1, dims[0], 0, 0, -1, -1};
    vw_config cfg;
    vw_config_init(&cfg);
    cfg.workers = 1;
    CHECK_EQ_INT(vw_world_create(&m, &st, d, &cfg, w), VW_OK);
    CHECK_EQ_INT(vw_world_run(*w), VW_OK);
    fprintf(stderr, "test_mpi_storm: process %d: %s\n", vw_engine_rank(), unnoticed);
    vw_world_free(*w);
    vw_decomp_free(d);
    return 1;
}

static int wire_garbled(void)
{
    if (vw_engine_rank() == 1) setenv("VW_FAULT", "wire-garble", 1); /* read by the transport */
    vw_world *w;
    return run_line_world(&w, wire_step, "the run ended without noticing the garbled packet");
}

/* --agree-in-step: every process's step() calls vw_world_agree on its own world: a
   collective made from a worker thread while the run's own collectives are under way,
   which was let through (a hang, or an agreement mixed up with the run's messages).
   Like the calls that change the world, it must stop the process, naming the call. */
static vw_world *agree_world;

static int agree_step(vw_ctx *ctx, void *state)
{
    (void)ctx, (void)state;
    static int called; /* one worker, one cell per process */
    if (called) return 0;
    called = 1;
    vw_world_agree(agree_world, VW_OK, NULL, 0);
    return 1;
}

static int agree_in_step(void)
{
    return run_line_world(&agree_world, agree_step, "vw_world_agree from step() went unnoticed");
}

int main(int argc, char **argv)
{
    int workers = 2, seeds = 3, agree = 0, kill_rank = -1, exit_rank = -1, fail_rank = 1, wire = 0;
    int hang_rank = -1, agree_step_mode = 0;
    const char *fail = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--workers") && i + 1 < argc) workers = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--seeds") && i + 1 < argc) seeds = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--agree")) agree = 1;
        else if (!strcmp(argv[i], "--kill-rank") && i + 1 < argc) kill_rank = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--exit-rank") && i + 1 < argc) exit_rank = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--hang-rank") && i + 1 < argc) hang_rank = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--fail") && i + 1 < argc) fail = argv[++i];
        else if (!strcmp(argv[i], "--wire")) wire = 1;
        else if (!strcmp(argv[i], "--agree-in-step")) agree_step_mode = 1;
        else if (!strcmp(argv[i], "--fail-rank") && i + 1 < argc) fail_rank = atoi(argv[++i]);
        else {
            fprintf(stderr, "test_mpi_storm: bad argument '%s'\n", argv[i]);
            return 2;
        }
    }
    char err[256];
    if (vw_engine_init(&argc, &argv, err, sizeof err) != VW_OK) {
        fprintf(stderr, "test_mpi_storm: %s\n", err);
        return 1;
    }
    int rank = vw_engine_rank();
    if (wire || fail || agree_step_mode) {
        int rc = wire ? wire_garbled() : agree_step_mode ? agree_in_step()
                                                         : local_failure(fail, fail_rank, workers);
        vw_engine_finish();
        return rc;
    }
    if (agree) {
        for (int bad = 0; bad <= vw_engine_size(); bad++) test_agree(bad);
        for (int bad = 0; bad <= vw_engine_size(); bad++) test_config_agree(bad);
        test_mismatch(workers);
        test_module_mismatch(workers);
        if (rank == 0) printf("agreement: %d checks, %d failed\n", vw_test_checks, vw_test_failures);
        vw_engine_finish();
        return vw_test_failures ? 1 : 0;
    }
    vw_box box = {{0, 0, 0}, {1, 1, 1}};
    const char *layouts[] = {"1", "2x2", "3x1x2", "2x2x2", "4x4x2"};
    int64_t total = 0;
    for (int seed = 1; seed <= seeds; seed++)
        for (size_t li = 0; li < sizeof layouts / sizeof layouts[0]; li++) {
            int dims[3];
            CHECK_EQ_INT(vw_layout_parse(layouts[li], dims, NULL, 0), VW_OK);
            vw_decomp *d;
            CHECK_EQ_INT(vw_decomp_create_grid(&box, dims, &d), VW_OK);
            int ncells = vw_decomp_cell_count(d);
            storm st = {(uint64_t)seed * 104729u + li, ncells, 5 + (seed * 7 + (int)li) % 30, 0, kill_rank, -1,
                        0, hang_rank + 1};
            int64_t *per_cell = calloc((size_t)ncells, sizeof *per_cell);
            int64_t sum = 0, outputs = 0, outsum = 0;
            for (int c = 0; c < ncells; c++)
                for (int r = 0; r < st.roots; r++) {
                    uint64_t key = root_key(&st, c, r);
                    expect(key, 2 + (uint32_t)(key % 5), ncells, per_cell, &sum, &outputs, &outsum);
                }
            vw_config cfg;
            vw_config_init(&cfg);
            cfg.workers = workers;
            cfg.packet_bytes = 64 + (size_t)(seed * 1499 + (int)li * 613) % 4096;
            vw_world *w;
            CHECK_EQ_INT(vw_world_create(&storm_module, &st, d, &cfg, &w), VW_OK);
            if (exit_rank == vw_world_process(w) && seed == 1 && li == 1) {
                fprintf(stderr, "test_mpi_storm: rank %d exits on purpose\n", exit_rank);
                exit(3); /* without MPI_Finalize, while the others wait for it */
            }
            /* Every rank posts every message; each is kept by its cell's process only. */
            for (int c = 0; c < ncells; c++) {
                int64_t v = c + 1;
                CHECK_EQ_INT(vw_world_post(w, c, MSG_POSTED, &v), VW_OK);
            }
            CHECK_EQ_INT(vw_world_run(w), VW_OK);
            int64_t want = 0;
            for (int c = 0; c < ncells; c++) want += per_cell[c];
            CHECK_EQ_INT(vw_world_counter(w, CNT_RECEIVED), want);
            CHECK_EQ_INT(vw_world_counter(w, CNT_SUM), sum);
            CHECK_EQ_INT(vw_world_counter(w, CNT_CORRUPT), 0);
            CHECK_EQ_INT(vw_world_counter(w, CNT_OUTPUT), outputs);
            CHECK_EQ_INT(vw_world_counter(w, CNT_POSTED), (int64_t)ncells * (ncells + 1) / 2);
            if (vw_world_is_output(w)) CHECK_EQ_INT(st.output_sum, outsum);
            for (int c = 0; c < ncells; c++) {
                vw_cell_stats cs;
                CHECK_EQ_INT(vw_world_cell_stats(w, c, &cs), VW_OK);
                CHECK_EQ_INT(cs.messages_in, per_cell[c] + 1); /* + its posted message */
                CHECK_EQ_INT(vw_world_cell_counter(w, c, CNT_POSTED), c + 1);
                CHECK(cs.busy_s >= 0);
            }
            double busy = 0;
            for (int g = 0; g < vw_world_processes(w) * vw_world_workers(w); g++)
                busy += vw_world_worker_busy(w, g);
            CHECK(busy > 0);
            CHECK(vw_world_imbalance(w) >= 1.0 - 1e-9);
            /* Second run: only new posts; counters accumulate, nothing else moves. */
            for (int c = 0; c < ncells; c++) {
                int64_t v = 1000;
                CHECK_EQ_INT(vw_world_post(w, c, MSG_POSTED, &v), VW_OK);
            }
            CHECK_EQ_INT(vw_world_run(w), VW_OK);
            CHECK_EQ_INT(vw_world_counter(w, CNT_RECEIVED), want);
            CHECK_EQ_INT(vw_world_counter(w, CNT_POSTED),
                         (int64_t)ncells * (ncells + 1) / 2 + 1000 * (int64_t)ncells);
            vw_cell_stats cs0;
            CHECK_EQ_INT(vw_world_cell_stats(w, 0, &cs0), VW_OK);
            CHECK_EQ_INT(cs0.messages_in, per_cell[0] + 2);
            if (seed == 1 && li == 3 && vw_world_is_output(w)) {
                const char *path = getenv("VW_TEST_STATS");
                if (path) CHECK_EQ_INT(vw_world_write_stats(w, path, "test-mpi-storm", NULL), VW_OK);
            }
            total += want;
            vw_world_free(w);
            vw_decomp_free(d);
            free(per_cell);
        }
    if (rank == 0) printf("%lld tokens delivered on %d process(es); %d checks passed\n",
                          (long long)total, vw_engine_size(), vw_test_checks);
    vw_engine_finish();
    return 0;
}
