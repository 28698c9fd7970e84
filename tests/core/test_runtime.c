/* test_runtime.c - corner cases of the runtime's loop, one per subcommand:
 *
 *   step-send  a step() that sends and returns 0 (it handed over what it buffered, and
 *              has nothing more to do): the message must arrive in that run, not wait
 *              in an open packet after the run has ended;
 *   meter      a handler hands off inline (vw_ctx_enter / vw_ctx_restore) 0..70 times and
 *              then works in its own cell: that time must be charged to the cells (shared
 *              among the units noted since the last clock read, as the meter does), also
 *              when the last hand-off filled the meter's list of notes.
 *
 * usage: test_runtime step-send|meter   (also honours VW_STRESS)
 */
#include <string.h>
#include <time.h>

#include "vw_test.h"
#include "vwalls/vwalls.h"

enum { MSG_PING, MSG_WORK, NKINDS };
enum { CNT_PINGS, CNT_OUTPUTS, NCOUNTERS };

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

static vw_status build(vw_ctx *ctx, const void *objs, size_t n, void **state)
{
    (void)objs, (void)n;
    *state = vw_ctx_user(ctx);
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

static const vw_msg_kind kinds[NKINDS] = {
    [MSG_PING] = {"ping", 0, on_ping, out_ping, 0},
    [MSG_WORK] = {"work", sizeof(work), on_work, NULL, 0},
};
static const char *const counters[NCOUNTERS] = {"pings", "outputs"};

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
            EXPECT(sh.outputs == run, "%d workers, run %d: %ld outputs arrived", workers, run,
                   sh.outputs);
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

int main(int argc, char **argv)
{
    const char *what = argc > 1 ? argv[1] : "";
    if (!strcmp(what, "step-send")) return test_step_send();
    if (!strcmp(what, "meter")) return test_meter();
    fprintf(stderr, "usage: test_runtime step-send|meter\n");
    return 2;
}
