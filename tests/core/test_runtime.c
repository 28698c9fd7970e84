/* test_runtime.c - corner cases of the runtime's loop, one per subcommand:
 *
 *   step-send  a step() that sends and returns 0 (it handed over what it buffered, and
 *              has nothing more to do): the message must arrive in that run, not wait
 *              in an open packet after the run has ended;
 *   meter      a handler hands off inline (vw_ctx_enter / vw_ctx_restore) 0..70 times and
 *              then works in its own cell: that time must be charged to the cells (shared
 *              among the units noted since the last clock read, as the meter does), also
 *              when the last hand-off filled the meter's list of notes;
 *   build-enter  a cell_build that tries inline hand-offs (there is no run to hand off
 *              in, and the other cells may not be built yet): refused, and they must
 *              leave the meter alone, also across a new decomposition (the meter kept
 *              pointers to the old cells' figures and charged them the time since the
 *              clock's epoch);
 *   build-fail  a cell_build that fails (module.h: it frees what it made; what it left
 *              in *state is not the runtime's): the commit fails naming the lowest
 *              failing cell, or copy of a cell, whichever worker failed first; cell_free is never
 *              given a failed build's state, a later commit builds the failed cells (and
 *              only those) again, and every state built is freed once (run it under
 *              -DVW_ASAN=ON: LeakSanitizer and double frees);
 *   thread-fail  a run whose worker threads cannot all be started fails, and the next
 *              runs, with threads, deliver everything: a chain of hops between two
 *              workers, started by a message posted before the failed run.
 *   run-fail   a handler or a step() that calls vw_ctx_fail, and a packet the runtime
 *              cannot allocate, fail the run: it ends (though the steps would send for
 *              ever), returns the status with "cell C: message" (the first failure),
 *              calls no handler, step or output handler after it, and the next run
 *              delivers everything again.
 *
 * usage: test_runtime step-send|meter|thread-fail|build-enter|build-fail|run-fail
 * (also honours VW_STRESS; step-send also runs under mpirun)
 * (pthread_create and malloc are wrapped at link time, so thread-fail and run-fail can
 * make them fail.)
 */
#include <errno.h>
#include <pthread.h>
#include <stdatomic.h>
#include <string.h>
#include <time.h>

#include "vw_test.h"
#include "vwalls/vwalls.h"

enum { MSG_PING, MSG_WORK, MSG_HOP, MSG_FLOOD, NKINDS };
enum { CNT_PINGS, CNT_OUTPUTS, CNT_HOPS, NCOUNTERS };

/* Failing pthread_create (EAGAIN, as when threads run out): 0 never, 1 always, 2 every
   second call (the first of two threads starts, the second does not). */
static atomic_int fail_threads, thread_calls;

int __real_pthread_create(pthread_t *t, const pthread_attr_t *a, void *(*fn)(void *), void *arg);
int __wrap_pthread_create(pthread_t *t, const pthread_attr_t *a, void *(*fn)(void *), void *arg);
int __wrap_pthread_create(pthread_t *t, const pthread_attr_t *a, void *(*fn)(void *), void *arg)
{
    int mode = atomic_load(&fail_threads), call = atomic_fetch_add(&thread_calls, 1);
    if (mode == 1 || (mode == 2 && call % 2 == 1)) return EAGAIN;
    return __real_pthread_create(t, a, fn, arg);
}

typedef struct shared {
    int run;          /* the run in progress, bumped by the test between runs */
    int step_runs[8]; /* per cell: the run step() last sent in */
    long outputs;     /* output handler (serialised) */
    double spin_s;    /* meter: how long a work message works in its own cell */
} shared;

typedef struct work {
    int32_t rounds; /* hand-offs to do first */
    int32_t depth;  /* cells entered per round before restoring (1 or 2) */
} work;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int build_enters; /* build-enter: hand-offs cell_build tries */
static int build_entered; /* ... and how many were taken */

static vw_status build(vw_ctx *ctx, const void *objs, size_t n, void **state)
{
    (void)objs, (void)n;
    *state = vw_ctx_user(ctx);
    int cell = vw_ctx_cell(ctx), rep = vw_ctx_replica(ctx);
    int ncells = vw_decomp_cell_count(vw_ctx_decomp(ctx));
    for (int i = 0; i < build_enters; i++) {
        if (vw_ctx_enter(ctx, (cell + 1 + i % 2) % ncells, MSG_WORK)) build_entered++;
        vw_ctx_restore(ctx, cell, rep);
    }
    return VW_OK;
}

/* Cell 0 sends one ping to the last cell and one to the output per run, and reports no
   work: what it sent is all it had. */
static int step_ping(vw_ctx *ctx, void *state)
{
    shared *sh = state;
    int cell = vw_ctx_cell(ctx);
    if (cell != 0 || sh->step_runs[cell] == sh->run) return 0;
    sh->step_runs[cell] = sh->run;
    int last = vw_decomp_cell_count(vw_ctx_decomp(ctx)) - 1;
    vw_send_cell(ctx, last, MSG_PING, NULL);
    vw_send_output(ctx, MSG_PING, NULL);
    return 0;
}

static void on_ping(vw_ctx *ctx, void *state, const void *msg)
{
    (void)state, (void)msg;
    vw_count(ctx, CNT_PINGS, 1);
}

static void out_ping(void *user, const void *msg)
{
    (void)msg;
    ((shared *)user)->outputs++;
}

/* Hands off into the other cells `rounds` times, then spins spin_s in its own cell. */
static void on_work(vw_ctx *ctx, void *state, const void *msg)
{
    shared *sh = state;
    const work *wm = msg;
    int cell = vw_ctx_cell(ctx), rep = vw_ctx_replica(ctx);
    int ncells = vw_decomp_cell_count(vw_ctx_decomp(ctx));
    for (int r = 0; r < wm->rounds; r++) {
        for (int k = 1; k <= wm->depth; k++) {
            void *there = vw_ctx_enter(ctx, (cell + k) % ncells, MSG_WORK);
            CHECK(there != NULL);
        }
        vw_ctx_restore(ctx, cell, rep);
    }
    double until = now_s() + sh->spin_s;
    while (now_s() < until) {
    }
}

/* A hop goes on to the other cell until its count is used up. */
static void on_hop(vw_ctx *ctx, void *state, const void *msg)
{
    (void)state;
    int32_t left = *(const int32_t *)msg;
    vw_count(ctx, CNT_HOPS, 1);
    if (left > 0) {
        int32_t next = left - 1;
        vw_send_cell(ctx, 1 - vw_ctx_cell(ctx), MSG_HOP, &next);
    }
}

/* ---- run-fail ---- */

enum { FLOOD_NONE, FLOOD_HANDLER, FLOOD_STEP, FLOOD_PACKET };
static int flood;                      /* how run-fail's run fails */
static int fail_after = 3000;          /* ... after this many hops or steps */
static atomic_int flood_hops, flood_steps, fail_cell = -1, late_calls;
static atomic_int failing;             /* set by the failing call, before vw_ctx_fail */
static atomic_int fail_packets;        /* malloc fails for packets (> 30,000 bytes) */

void *__real_malloc(size_t n);
void *__wrap_malloc(size_t n);
void *__wrap_malloc(size_t n)
{
    if (n > 30000 && atomic_load(&fail_packets)) return NULL;
    return __real_malloc(n);
}

/* A hop that goes on for ever, to the next cell (not with FLOOD_STEP, whose steps run
   only when the inboxes are empty); with FLOOD_HANDLER the fail_after-th one fails the
   run. */
static void on_flood_hop(vw_ctx *ctx, void *state, const void *msg)
{
    (void)state, (void)msg;
    if (atomic_load(&failing)) atomic_fetch_add(&late_calls, 1);
    int n = atomic_fetch_add(&flood_hops, 1) + 1;
    if (flood == FLOOD_HANDLER && n == fail_after) {
        atomic_store(&fail_cell, vw_ctx_cell(ctx));
        vw_ctx_fail(ctx, VW_E_NOMEM, "no room for hop %d", n);
        vw_ctx_fail(ctx, VW_E_INPUT, "a second failure, not reported");
        atomic_store(&failing, 1);
        return;
    }
    if (flood == FLOOD_STEP) return;
    int ncells = vw_decomp_cell_count(vw_ctx_decomp(ctx));
    vw_send_cell(ctx, (vw_ctx_cell(ctx) + 1) % ncells, MSG_FLOOD, NULL);
    vw_send_output(ctx, MSG_FLOOD, NULL);
}

static void out_flood(void *user, const void *msg)
{
    (void)user, (void)msg;
    if (atomic_load(&failing)) atomic_fetch_add(&late_calls, 1);
}

/* Every cell sends a hop at every call, for ever: only a failure ends such a run. */
static int step_flood(vw_ctx *ctx, void *state)
{
    (void)state;
    if (flood == FLOOD_NONE) return 0;
    if (atomic_load(&failing)) atomic_fetch_add(&late_calls, 1);
    int n = atomic_fetch_add(&flood_steps, 1) + 1;
    if (flood == FLOOD_STEP && n == fail_after) {
        atomic_store(&fail_cell, vw_ctx_cell(ctx));
        vw_ctx_fail(ctx, VW_E_INPUT, "step %d found bad input", n);
        atomic_store(&failing, 1);
        return 1;
    }
    vw_send_cell(ctx, vw_ctx_cell(ctx), MSG_FLOOD, NULL);
    return 1;
}

static const vw_msg_kind kinds[NKINDS] = {
    [MSG_PING] = {"ping", 0, on_ping, out_ping, 0},
    [MSG_WORK] = {"work", sizeof(work), on_work, NULL, 0},
    [MSG_HOP] = {"hop", sizeof(int32_t), on_hop, NULL, 0},
    [MSG_FLOOD] = {"flood", 0, on_flood_hop, out_flood, 0},
};
static const char *const counters[NCOUNTERS] = {"pings", "outputs", "hops"};

static vw_module module = {
    .abi = VW_MODULE_ABI,
    .name = "runtime-test",
    .kinds = kinds,
    .nkinds = NKINDS,
    .counters = counters,
    .ncounters = NCOUNTERS,
    .cell_build = build,
};

static vw_world *make_world(const char *layout, int workers, shared *sh, vw_decomp **d)
{
    vw_box box = {{0, 0, 0}, {1, 1, 1}};
    int dims[3];
    CHECK_EQ_INT(vw_layout_parse(layout, dims, NULL, 0), VW_OK);
    CHECK_EQ_INT(vw_decomp_create_grid(&box, dims, d), VW_OK);
    vw_config cfg;
    vw_config_init(&cfg);
    cfg.workers = workers;
    vw_world *w;
    CHECK_EQ_INT(vw_world_create(&module, sh, *d, &cfg, &w), VW_OK);
    return w;
}

static int test_step_send(void)
{
    module.step = step_ping;
    for (int workers = 1; workers <= 3; workers++) {
        shared sh = {0};
        vw_decomp *d;
        vw_world *w = make_world("3", workers, &sh, &d);
        for (int run = 1; run <= 3; run++) {
            sh.run = run;
            CHECK_EQ_INT(vw_world_run(w), VW_OK);
            EXPECT(vw_world_counter(w, CNT_PINGS) == run,
                   "%d workers, run %d: %lld pings arrived", workers, run,
                   (long long)vw_world_counter(w, CNT_PINGS));
            if (vw_world_is_output(w))
                EXPECT(sh.outputs == run, "%d workers, run %d: %ld outputs arrived", workers,
                       run, sh.outputs);
        }
        vw_world_free(w);
        vw_decomp_free(d);
    }
    TEST_DONE();
}

static double cells_busy(const vw_world *w)
{
    double s = 0;
    for (int c = 0; c < vw_decomp_cell_count(vw_world_decomp(w)); c++) {
        vw_cell_stats cs;
        CHECK_EQ_INT(vw_world_cell_stats(w, c, &cs), VW_OK);
        s += cs.busy_s;
    }
    return s;
}

static int test_meter(void)
{
    module.step = NULL;
    shared sh = {0};
    sh.spin_s = 0.004;
    vw_decomp *d;
    /* One worker hosts all three cells, so every hand-off is taken. */
    vw_world *w = make_world("3", 1, &sh, &d);
    for (int depth = 1; depth <= 2; depth++)
        for (int rounds = 0; rounds <= 70; rounds++) {
            double before = cells_busy(w);
            work wm = {rounds, depth};
            CHECK_EQ_INT(vw_world_post(w, 0, MSG_WORK, &wm), VW_OK);
            CHECK_EQ_INT(vw_world_run(w), VW_OK);
            /* The spin is spin_s of the worker's time (wall time: a preemption only adds
               to it), and all of it is some cell's; the hand-offs take microseconds. */
            double got = cells_busy(w) - before;
            EXPECT(got >= 0.9 * sh.spin_s, "depth %d, %d rounds of hand-offs: the cells were "
                   "charged %.6f s for a %.3f s spin", depth, rounds, got, sh.spin_s);
        }
    vw_world_free(w);
    vw_decomp_free(d);
    TEST_DONE();
}

static int test_build_enter(void)
{
    module.step = NULL;
    build_enters = 100;
    shared sh = {0};
    vw_decomp *d, *d2;
    vw_world *w = make_world("3", 1, &sh, &d);
    CHECK_EQ_INT(vw_world_commit(w), VW_OK);
    EXPECT(build_entered == 0, "cell_build was let into %d cells", build_entered);
    CHECK_EQ_INT(vw_world_run(w), VW_OK);
    double busy = cells_busy(w);
    EXPECT(busy < 1.0, "the cells were charged %.3f s for a run with nothing to do", busy);
    /* New walls (the old cells freed), built and run: nothing ran, nothing is charged. */
    vw_box box = {{0, 0, 0}, {1, 1, 1}};
    int dims[3] = {2, 2, 1};
    CHECK_EQ_INT(vw_decomp_create_grid(&box, dims, &d2), VW_OK);
    CHECK_EQ_INT(vw_world_redecompose(w, d2, NULL), VW_OK);
    CHECK_EQ_INT(vw_world_run(w), VW_OK);
    CHECK_EQ_INT(vw_world_run(w), VW_OK);
    busy = cells_busy(w);
    EXPECT(busy < 1.0, "the new cells were charged %.3f s for runs with nothing to do", busy);
    vw_world_free(w);
    vw_decomp_free(d);
    vw_decomp_free(d2);
    build_enters = 0;
    TEST_DONE();
}

static int test_thread_fail(void)
{
    module.step = NULL;
    for (int fails = 1; fails <= 2; fails++) {
        shared sh = {0};
        vw_decomp *d;
        /* Two cells on two workers: every hop crosses between them. */
        vw_world *w = make_world("2", 2, &sh, &d);
        CHECK_EQ_INT(vw_world_cell_worker(w, 0), 0);
        CHECK_EQ_INT(vw_world_cell_worker(w, 1), 1);
        int32_t hops = 200;
        CHECK_EQ_INT(vw_world_post(w, 0, MSG_HOP, &hops), VW_OK);
        /* No thread, or only the first of two, starts: the cells are built without
           them, and the run fails. */
        atomic_store(&thread_calls, 0);
        atomic_store(&fail_threads, fails);
        vw_status st = vw_world_run(w);
        atomic_store(&fail_threads, 0);
        EXPECT(st == VW_E_LIMIT, "run without threads: status %d", (int)st);
        /* Then threads start: the posted chain runs whole, and so do new ones. */
        int64_t want = 0;
        for (int run = 0; run < 20; run++) {
            if (run > 0) CHECK_EQ_INT(vw_world_post(w, run % 2, MSG_HOP, &hops), VW_OK);
            CHECK_EQ_INT(vw_world_run(w), VW_OK);
            want += hops + 1;
            EXPECT(vw_world_counter(w, CNT_HOPS) == want, "after a failed run, run %d: %lld of "
                   "%lld hops", run, (long long)vw_world_counter(w, CNT_HOPS), (long long)want);
            if (vw_world_counter(w, CNT_HOPS) != want) break;
        }
        vw_world_free(w);
        vw_decomp_free(d);
    }
    TEST_DONE();
}

/* ---- build-fail ---- */

static int fail_mask;                 /* cells whose cell_build fails (their masters) */
static int fail_copy = -1;            /* ... and the copies of this cell (-1: none) */
static atomic_int built_ok, freed, built_calls;
static char stale;                    /* what a failed build leaves in *state */

static vw_status build_or_fail(vw_ctx *ctx, const void *objs, size_t n, void **state)
{
    (void)objs, (void)n;
    atomic_fetch_add(&built_calls, 1);
    int *c = malloc(sizeof *c);
    if (!c) return VW_E_NOMEM;
    *c = vw_ctx_cell(ctx);
    *state = c;
    int bad = vw_ctx_replica(ctx) ? vw_ctx_cell(ctx) == fail_copy : fail_mask >> vw_ctx_cell(ctx) & 1;
    if (bad) {
        /* The build cleans up after itself, as every module in the tree does, and leaves
           something that is no state behind: the runtime must not keep or free it. */
        free(c);
        *state = &stale;
        return VW_E_INPUT;
    }
    atomic_fetch_add(&built_ok, 1);
    return VW_OK;
}

static void free_built(void *state, void *user)
{
    (void)user;
    if (state == &stale) {
        fprintf(stderr, "test_runtime: cell_free was given a failed build's state\n");
        exit(1);
    }
    atomic_fetch_add(&freed, 1);
    free(state);
}

/* A world of module m on four cells in a row (*d, to free after the world). */
static vw_world *four_cells(const vw_module *m, shared *sh, int workers, vw_decomp **d)
{
    vw_box box = {{0, 0, 0}, {1, 1, 1}};
    int dims[3] = {4, 1, 1};
    CHECK_EQ_INT(vw_decomp_create_grid(&box, dims, d), VW_OK);
    vw_config cfg;
    vw_config_init(&cfg);
    cfg.workers = workers;
    vw_world *w;
    CHECK_EQ_INT(vw_world_create(m, sh, *d, &cfg, &w), VW_OK);
    return w;
}

static int test_build_fail(void)
{
    vw_module m = module;
    m.cell_build = build_or_fail;
    m.cell_free = free_built;
    m.step = NULL;
    for (int workers = 1; workers <= 2; workers++) {
        atomic_store(&built_ok, 0), atomic_store(&freed, 0), atomic_store(&built_calls, 0);
        shared sh = {0};
        vw_decomp *d;
        vw_world *w = four_cells(&m, &sh, workers, &d);
        fail_mask = 1 << 1 | 1 << 3;
        CHECK_EQ_INT(vw_world_commit(w), VW_E_INPUT);
        /* The message names the lowest failing cell, whichever worker failed first. */
        EXPECT(strstr(vw_world_errmsg(w), "building cell 1 failed: bad input") != NULL,
               "%d workers: commit failed with '%s'", workers, vw_world_errmsg(w));
        CHECK_EQ_INT(vw_world_run(w), VW_E_INPUT); /* run commits first: fails the same */
        fail_mask = 0;
        int calls = atomic_load(&built_calls), ok = atomic_load(&built_ok);
        CHECK_EQ_INT(vw_world_commit(w), VW_OK);
        /* Only the cells not built yet are built now (each worker stops at its first
           failure, so which those are depends on the worker count). */
        CHECK_EQ_INT(atomic_load(&built_calls) - calls, 4 - ok);
        CHECK_EQ_INT(atomic_load(&built_ok), 4);
        CHECK_EQ_INT(vw_world_run(w), VW_OK);
        CHECK_EQ_INT(atomic_load(&freed), 0);
        vw_world_free(w);
        CHECK_EQ_INT(atomic_load(&freed), 4); /* every state built, once */
        vw_decomp_free(d);
    }
    /* A copy that fails is named as the copy it is, not as its cell (whose master built):
       cells 0 and 2 get a copy each on the other worker, and cell 2's fails. The world's
       first error is kept, so each case is a world of its own. (Copies need a kind
       that any copy may handle.) */
    vw_msg_kind indep[NKINDS];
    memcpy(indep, kinds, sizeof indep);
    indep[MSG_PING].flags = VW_MSG_INDEPENDENT;
    m.kinds = indep;
    for (int failing = 0; failing <= 1; failing++) {
        shared sh = {0};
        vw_decomp *d;
        vw_world *w = four_cells(&m, &sh, 2, &d);
        for (int c = 0; c <= 2; c += 2) {
            int other = 1 - vw_world_cell_worker(w, c);
            CHECK_EQ_INT(vw_world_set_replicas(w, c, &other, 1), VW_OK);
        }
        fail_mask = failing ? 1 << 3 : 0; /* with a master failing above it too */
        fail_copy = 2;
        CHECK_EQ_INT(vw_world_commit(w), VW_E_INPUT);
        EXPECT(strstr(vw_world_errmsg(w), "building copy 1 of cell 2 failed: bad input") != NULL,
               "a copy failed (and cell 3: %d): commit failed with '%s'", failing,
               vw_world_errmsg(w));
        fail_mask = 0;
        fail_copy = -1;
        CHECK_EQ_INT(vw_world_commit(w), VW_OK);
        vw_world_free(w);
        vw_decomp_free(d);
    }
    TEST_DONE();
}

/* The run of world w (of `workers` workers) fails: with `want` (status) and errmsg
   "cell C: <text>" where C is the failing cell. Nothing of the module runs after the
   failing call but the calls the other workers had begun: one each at most. */
static void expect_failed_run(vw_world *w, int workers, vw_status want, const char *text,
                              const char *how)
{
    atomic_store(&failing, 0);
    atomic_store(&late_calls, 0);
    atomic_store(&fail_cell, -1);
    atomic_store(&flood_hops, 0);
    atomic_store(&flood_steps, 0);
    vw_status st = vw_world_run(w);
    EXPECT(st == want, "%s: the run returned %d, not %d", how, (int)st, (int)want);
    char msg[128];
    if (atomic_load(&fail_cell) >= 0)
        snprintf(msg, sizeof msg, "cell %d: %s", atomic_load(&fail_cell), text);
    else
        snprintf(msg, sizeof msg, "%s", text);
    EXPECT(strstr(vw_world_errmsg(w), msg) != NULL, "%s: errmsg '%s', not '%s'", how,
           vw_world_errmsg(w), msg);
    EXPECT(atomic_load(&late_calls) <= workers - 1, "%s: %d calls of the module after the failure",
           how, atomic_load(&late_calls));
}

static int test_run_fail(void)
{
    static const char *const hows[] = {"", "a handler fails", "a step fails",
                                       "no memory for packets"};
    static const char *const texts[] = {"", "no room for hop 3000", "step 3000 found bad input",
                                        "out of memory for a 32768-byte packet"};
    static const vw_status statuses[] = {VW_OK, VW_E_NOMEM, VW_E_INPUT, VW_E_NOMEM};
    module.step = step_flood;
    for (int workers = 1; workers <= 4; workers *= 2) {
        for (int how = FLOOD_HANDLER; how <= FLOOD_PACKET; how++) {
            shared sh = {0};
            vw_decomp *d;
            vw_world *w = make_world("2x2x2", workers, &sh, &d);
            char what[64];
            snprintf(what, sizeof what, "%d workers, %s", workers, hows[how]);
            /* The runtime's own failure: no memory for a packet (the floods' packets are
               32 KiB); the steps and hops would flood for ever without it. */
            flood = how == FLOOD_PACKET ? FLOOD_HANDLER : how;
            fail_after = how == FLOOD_PACKET ? 1 << 30 : 3000;
            atomic_store(&fail_packets, how == FLOOD_PACKET);
            expect_failed_run(w, workers, statuses[how], texts[how], what);
            atomic_store(&fail_packets, 0);
            /* A second failed run tells its own failure, not the first run's. */
            flood = FLOOD_STEP;
            fail_after = 2000;
            char again[96];
            snprintf(again, sizeof again, "%s, then a step fails", what);
            expect_failed_run(w, workers, VW_E_INPUT, "step 2000 found bad input", again);
            /* The world runs again: a chain of hops arrives whole. */
            flood = FLOOD_NONE;
            int64_t before = vw_world_counter(w, CNT_HOPS);
            int32_t hops = 300;
            CHECK_EQ_INT(vw_world_post(w, 0, MSG_HOP, &hops), VW_OK);
            EXPECT(vw_world_run(w) == VW_OK, "%s: the next run failed: %s", what, vw_world_errmsg(w));
            EXPECT(vw_world_counter(w, CNT_HOPS) - before == hops + 1, "%s: the next run had %lld "
                   "of %d hops", what, (long long)(vw_world_counter(w, CNT_HOPS) - before), hops + 1);
            vw_world_free(w);
            vw_decomp_free(d);
        }
    }
    module.step = NULL;
    flood = FLOOD_NONE;
    TEST_DONE();
}

int main(int argc, char **argv)
{
    const char *what = argc > 1 ? argv[1] : "";
    if (!strcmp(what, "step-send")) return test_step_send();
    if (!strcmp(what, "meter")) return test_meter();
    if (!strcmp(what, "thread-fail")) return test_thread_fail();
    if (!strcmp(what, "build-enter")) return test_build_enter();
    if (!strcmp(what, "build-fail")) return test_build_fail();
    if (!strcmp(what, "run-fail")) return test_run_fail();
    fprintf(stderr, "usage: test_runtime step-send|meter|thread-fail|build-enter|build-fail|run-fail\n");
    return 2;
}
