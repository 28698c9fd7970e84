/* test_misuse.c - a module's mistakes get a message, never silence:
 *   create   a world that cannot be created says why through vw_world_errmsg(NULL)
 *   post     posting a kind without handle is VW_E_INVAL with a message
 *   redecompose   a bad mapping is refused and leaves the world as it was; messages
 *            posted before new walls or a new mapping reach their cell
 *   limits   counts whose bytes overflow a size_t are refused, not wrapped
 *   stats    phase names of any length and number, escaped in the stats JSON
 *   slowdown vw_config.worker_slowdown is copied at create, like the speeds
 *   signal   kinds of size 0 are sent and posted with no buffer
 *   errmsg   every failed post, query or stats write says its own why (it said "no
 *            error" or an older call's message)
 *   null     the queries answer a NULL world as world.h says (they read address 0)
 *   workers  a negative worker count is refused at create (it meant one per core), and
 *            vw_engine_workers answers -1 for the counts create refuses (it took a
 *            negative one as one per core)
 *   maperr   the calls of map.h that take a world say why they failed (vw_world_remap
 *            without a mapping, vw_world_traffic and vw_world_machines without room for
 *            their answer returned VW_E_INVAL and left "no error" or an older message)
 *   done     vw_world_done asks every cell's done(), and refuses what it cannot answer
 *   send | output | count | build-send | send-null | point-null | bad-kind | bad-cell
 *            a module's bad send (also one from cell_build, one without its message, to
 *            a kind or a cell that does not exist) or count stops the
 *            process (abort) with a message on stderr: run in a child, whose end and
 *            stderr are checked
 *   reenter-run | reenter-post | reenter-add | reenter-free | reenter-commit   a call
 *            that changes the world made from a callback (step; cell_build for commit)
 *            stops the process naming it, the same way (run hung in pool_wait, post
 *            changed the world mid-run)
 *   reenter-agree | build-agree | reenter-traffic   so do vw_world_agree from step() or
 *            cell_build, and vw_world_traffic from step(): collectives under MPI, made
 *            from a worker thread in the middle of a run or a commit (they were let
 *            through: a hang or a mixed-up agreement under MPI)
 *   count-all   every cell of eight, each on its own worker, counts into a counter that
 *            does not exist at once: one whole line is printed, by one worker (the
 *            workers' pieces were interleaved and cut short by the first abort)
 *   norestore-step | norestore-handle   a step() or a handler that hands off inline
 *            (vw_ctx_enter) and returns without vw_ctx_restore stops the process, as
 *            module.h requires the restore (it went unnoticed)
 *   enter-output | build-enter   a hand-off (vw_ctx_enter) with a kind that has no handle
 *            stops the process as vw_send_cell does, from step() to a cell of its own
 *            worker and from cell_build alike (it returned the cell's state, or NULL)
 * Usage: test_misuse MODE [EXPECTED-MESSAGE]
 */
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include "vw_test.h"
#include "vwalls/vwalls.h"
#include "core/run_child.h"

typedef struct obj {
    double p[3];
} obj;

static void bounds(const void *o, vw_box *b, void *user)
{
    (void)user;
    const obj *x = o;
    for (int a = 0; a < 3; a++) b->lo[a] = b->hi[a] = x->p[a];
}

static const char *mode;

/* norestore-handle: the message to cell 0 hands off to cell 1 and returns there. */
static void handle(vw_ctx *ctx, void *state, const void *msg)
{
    (void)state, (void)msg;
    if (!strcmp(mode, "norestore-handle") && vw_ctx_cell(ctx) == 0) vw_ctx_enter(ctx, 1, 0);
}

static void output(void *user, const void *msg)
{
    (void)user, (void)msg;
}

static vw_world *the_world; /* for the callbacks that call back into it */

/* The mistake of the mode, once, from cell 0. */
static int step(vw_ctx *ctx, void *state)
{
    int *done = state;
    /* count-all: every cell makes the mistake at once, on its own worker. */
    if (*done || (vw_ctx_cell(ctx) != 0 && strcmp(mode, "count-all"))) return 0;
    *done = 1;
    int x = 0;
    obj o = {{0.5, 0.5, 0.5}};
    if (!strcmp(mode, "send-null")) vw_send_cell(ctx, 1, 0, NULL);   /* kind 0: an int */
    if (!strcmp(mode, "point-null")) vw_send_point(ctx, (double[3]){2, 2, 2}, NULL, 0, NULL);
    if (!strcmp(mode, "reenter-run")) vw_world_run(the_world);
    if (!strcmp(mode, "reenter-post")) vw_world_post(the_world, 1, 0, &x);
    if (!strcmp(mode, "reenter-add")) vw_world_add_objects(the_world, &o, 1);
    if (!strcmp(mode, "reenter-free")) vw_world_free(the_world);
    if (!strcmp(mode, "reenter-agree")) vw_world_agree(the_world, VW_OK, NULL, 0);
    vw_traffic t;
    if (!strcmp(mode, "reenter-traffic")) vw_world_traffic(the_world, &t);
    if (!strcmp(mode, "send")) vw_send_cell(ctx, 0, 1, &x);   /* kind 1: output only */
    if (!strcmp(mode, "output")) vw_send_output(ctx, 0, &x);  /* kind 0: no output */
    if (!strcmp(mode, "count") || !strcmp(mode, "count-all")) vw_count(ctx, 5, 1); /* one counter */
    if (!strcmp(mode, "face")) vw_send_face(ctx, 6, 0, &x);   /* faces 0..5 */
    if (!strcmp(mode, "bad-kind")) vw_send_cell(ctx, 0, 7, &x);
    if (!strcmp(mode, "bad-cell")) vw_send_cell(ctx, 99, 0, &x);
    /* Both cells on one worker (see main): the hand-off succeeds, no restore follows. */
    if (!strcmp(mode, "norestore-step")) vw_ctx_enter(ctx, 1, 0);
    if (!strcmp(mode, "norestore-handle")) vw_send_cell(ctx, 0, 0, &x);
    /* Both cells on one worker: a kind with a handle would be entered. */
    if (!strcmp(mode, "enter-output") && vw_ctx_enter(ctx, 1, 1)) vw_ctx_restore(ctx, 0, 0);
    return 1;
}

static vw_status build(vw_ctx *ctx, const void *objects, size_t n, void **state)
{
    (void)objects, (void)n;
    static int done[64];
    *state = &done[vw_ctx_cell(ctx)];
    int x = 0;
    if (!strcmp(mode, "build-send") && vw_ctx_cell(ctx) == 0) vw_send_cell(ctx, 0, 0, &x);
    if (!strcmp(mode, "build-enter") && vw_ctx_cell(ctx) == 0) vw_ctx_enter(ctx, 0, 1);
    if (!strcmp(mode, "reenter-commit") && vw_ctx_cell(ctx) == 0) vw_world_commit(the_world);
    if (!strcmp(mode, "build-agree") && vw_ctx_cell(ctx) == 0) vw_world_agree(the_world, VW_OK, NULL, 0);
    return VW_OK;
}

static const vw_msg_kind kinds[] = {
    {.name = "to_cell", .size = sizeof(int), .handle = handle},
    {.name = "to_output", .size = sizeof(int), .output = output},
};
static const char *const counters[] = {"one"};

/* Signals: kinds of size 0, sent and posted with no buffer (memcpy got NULL, and the
   post was refused). */
static int signals_in, signals_out;
static void on_signal(vw_ctx *ctx, void *state, const void *msg)
{
    (void)ctx, (void)state, (void)msg;
    __atomic_add_fetch(&signals_in, 1, __ATOMIC_RELAXED);
}
static void on_signal_out(void *user, const void *msg)
{
    (void)user, (void)msg;
    signals_out++;
}
static int signal_step(vw_ctx *ctx, void *state)
{
    int *done = state;
    if (*done) return 0;
    *done = 1;
    vw_send_neighbours(ctx, 0, NULL);
    vw_send_output(ctx, 1, NULL);
    return 1;
}
static const vw_msg_kind signal_kinds[] = {
    {.name = "signal", .size = 0, .handle = on_signal},
    {.name = "signal_out", .size = 0, .output = on_signal_out},
};

/* done(): what each cell says, and how often it was asked. */
static int done_says[2], done_asked[2];
static int cell_done(vw_ctx *ctx, void *state)
{
    (void)state;
    done_asked[vw_ctx_cell(ctx)]++;
    return done_says[vw_ctx_cell(ctx)];
}

static vw_module module(void)
{
    vw_module m = {.abi = VW_MODULE_ABI, .name = "misuse", .object_size = sizeof(obj),
                   .object_bounds = bounds, .kinds = kinds, .nkinds = 2, .counters = counters,
                   .ncounters = 1, .cell_build = build, .step = step};
    return m;
}

int main(int argc, char **argv)
{
    mode = argc > 1 ? argv[1] : "create";
    vw_box world = {{0, 0, 0}, {1, 1, 1}};
    int dims[3] = {2, 1, 1};
    int all = !strcmp(mode, "count-all"); /* eight cells on eight workers */
    if (all) dims[0] = 8;
    vw_decomp *d;
    CHECK(vw_decomp_create_grid(&world, dims, &d) == VW_OK);
    vw_module m = module();
    vw_config cfg;
    vw_config_init(&cfg);
    cfg.workers = all ? 8 : 2;
    vw_world *w = NULL;
    if (!strcmp(mode, "create")) {
        /* No world to agree on: the same answer with and without the MPI engine. */
        CHECK_EQ_INT(vw_world_agree(NULL, VW_OK, NULL, 0), VW_E_INVAL);
        vw_module bad = m;
        bad.abi = VW_MODULE_ABI + 1;
        CHECK(vw_world_create(&bad, NULL, d, &cfg, &w) == VW_E_INVAL && !w);
        printf("abi: %s\n", vw_world_errmsg(NULL));
        CHECK(strstr(vw_world_errmsg(NULL), "abi") != NULL);
        cfg.workers = 5000;
        CHECK(vw_world_create(&m, NULL, d, &cfg, &w) == VW_E_LIMIT && !w);
        printf("workers: %s\n", vw_world_errmsg(NULL));
        CHECK(strstr(vw_world_errmsg(NULL), "5000 workers") != NULL);
        cfg.workers = 2;
        /* Counts without their tables: the first send or the stats JSON read NULL. */
        bad = m;
        bad.kinds = NULL;
        CHECK(vw_world_create(&bad, NULL, d, &cfg, &w) == VW_E_INVAL && !w);
        printf("kinds: %s\n", vw_world_errmsg(NULL));
        CHECK(strstr(vw_world_errmsg(NULL), "no table of kinds") != NULL);
        bad = m;
        bad.counters = NULL;
        CHECK(vw_world_create(&bad, NULL, d, &cfg, &w) == VW_E_INVAL && !w);
        CHECK(strstr(vw_world_errmsg(NULL), "no table of counter names") != NULL);
        static const char *const unnamed[] = {NULL};
        bad.counters = unnamed;
        CHECK(vw_world_create(&bad, NULL, d, &cfg, &w) == VW_E_INVAL && !w);
        CHECK(strstr(vw_world_errmsg(NULL), "counter 0 has no name") != NULL);
        /* Every message about a module names it: printf was given NULL for %s. */
        bad = m;
        bad.name = NULL;
        CHECK(vw_world_create(&bad, NULL, d, &cfg, &w) == VW_E_INVAL && !w);
        CHECK(strstr(vw_world_errmsg(NULL), "the module has no name") != NULL);
        bad.name = "";
        CHECK(vw_world_create(&bad, NULL, d, &cfg, &w) == VW_E_INVAL && !w);
        /* A kind the table's initialiser left out (all zeros), one that no handler
           takes, flags the runtime does not know: refused here, not at the first send. */
        vw_msg_kind k3[3] = {kinds[0], kinds[1]};
        bad = m;
        bad.kinds = k3;
        bad.nkinds = 3;
        CHECK(vw_world_create(&bad, NULL, d, &cfg, &w) == VW_E_INVAL && !w);
        printf("kind: %s\n", vw_world_errmsg(NULL));
        CHECK(strstr(vw_world_errmsg(NULL), "message kind 2 has no name (missing from the kinds "
                                            "table? nkinds is 3)") != NULL);
        k3[2] = (vw_msg_kind){.name = "idle", .size = 4};
        CHECK(vw_world_create(&bad, NULL, d, &cfg, &w) == VW_E_INVAL && !w);
        CHECK(strstr(vw_world_errmsg(NULL), "message kind 2 ('idle') has neither a handle") != NULL);
        k3[2] = (vw_msg_kind){.name = "odd", .size = 4, .handle = handle, .flags = 0x81};
        CHECK(vw_world_create(&bad, NULL, d, &cfg, &w) == VW_E_INVAL && !w);
        CHECK(strstr(vw_world_errmsg(NULL), "message kind 2 ('odd') has unknown flags 0x80") != NULL);
        k3[2].flags = VW_MSG_INDEPENDENT;
        CHECK(vw_world_create(&bad, NULL, d, &cfg, &w) == VW_OK && w);
        vw_world_free(w);
        w = NULL;
        CHECK(vw_world_create(&m, NULL, d, &cfg, &w) == VW_OK);
        CHECK(!strcmp(vw_world_errmsg(NULL), "no world")); /* a success clears it */
    } else if (!strcmp(mode, "null")) {
        CHECK_EQ_INT(vw_world_counter(NULL, 0), 0);
        CHECK_EQ_INT(vw_world_cell_counter(NULL, 0, 0), 0);
        CHECK_EQ_INT(vw_world_worker_counter(NULL, 0, 0), 0);
        CHECK_EQ_INT(vw_world_is_output(NULL), 0);
        CHECK_EQ_INT(vw_world_workers(NULL), 0);
        CHECK_EQ_INT(vw_world_processes(NULL), 0);
        CHECK_EQ_INT(vw_world_process(NULL), -1);
        CHECK_EQ_INT(vw_world_cell_worker(NULL, 0), -1);
        CHECK(vw_world_decomp(NULL) == NULL);
        CHECK(vw_world_imbalance(NULL) == 0);
        CHECK(vw_world_worker_busy(NULL, 0) == 0);
        vw_cell_stats cs;
        CHECK_EQ_INT(vw_world_cell_stats(NULL, 0, &cs), VW_E_INVAL);
        int yes = 1;
        CHECK_EQ_INT(vw_world_done(NULL, &yes), VW_E_INVAL);
        vw_world_reset_stats(NULL);
        vw_world_set_balance_info(NULL, "none", 1, 1, 0);
    } else if (!strcmp(mode, "workers")) {
        cfg.workers = -3;
        CHECK(vw_world_create(&m, NULL, d, &cfg, &w) == VW_E_INVAL && !w);
        printf("workers: %s\n", vw_world_errmsg(NULL));
        CHECK(strstr(vw_world_errmsg(NULL), "-3 workers") != NULL);
        /* What a world made with the count would run: none, where create refuses it. */
        CHECK_EQ_INT(vw_engine_workers(-3), -1);
        CHECK_EQ_INT(vw_engine_workers(5000), -1);
        CHECK_EQ_INT(vw_engine_workers(3), 3);
        CHECK_EQ_INT(vw_engine_workers(0), vw_host_cores());
    } else {
        if (!strncmp(mode, "norestore", 9) || !strcmp(mode, "enter-output"))
            cfg.workers = 1; /* a hand-off needs both cells */
        CHECK(vw_world_create(&m, NULL, d, &cfg, &w) == VW_OK);
        the_world = w;
        obj o[2] = {{{0.25, 0.5, 0.5}}, {{0.75, 0.5, 0.5}}};
        CHECK(vw_world_add_objects(w, o, 2) == VW_OK);
        if (!strcmp(mode, "redecompose")) {
            CHECK(vw_world_run(w) == VW_OK);
            vw_box world2 = {{0, 0, 0}, {1, 1, 1}};
            int dims2[3] = {4, 1, 1};
            vw_decomp *d2;
            CHECK(vw_decomp_create_grid(&world2, dims2, &d2) == VW_OK);
            int map[4] = {0, 1, 0, 7}; /* two workers: 7 is none of them */
            CHECK(vw_world_redecompose(w, d2, map) == VW_E_INVAL);
            printf("redecompose: %s\n", vw_world_errmsg(w));
            CHECK(strstr(vw_world_errmsg(w), "cell 3 to worker 7") != NULL);
            int remap[2] = {1, -1};
            CHECK(vw_world_remap(w, remap) == VW_E_INVAL);
            /* The world is the one before: its walls, its objects in their cells. */
            CHECK(vw_decomp_equal(vw_world_decomp(w), d));
            int cell = -1;
            CHECK(vw_world_cells_of_object(w, 0, &cell, 1) == 1 && cell == 0);
            CHECK(vw_world_cells_of_object(w, 1, &cell, 1) == 1 && cell == 1);
            int x = 0;
            CHECK(vw_world_post(w, 1, 0, &x) == VW_OK);
            CHECK(vw_world_run(w) == VW_OK);
            vw_cell_stats cs;
            CHECK(vw_world_cell_stats(w, 1, &cs) == VW_OK && cs.messages_in == 1 && cs.objects == 1);
            map[3] = 1;
            CHECK(vw_world_redecompose(w, d2, map) == VW_OK);
            CHECK(vw_world_run(w) == VW_OK);
            /* A message posted before a remap goes to its cell's new worker (it went to
               the old one, which aborted: "received a message for cell 1, which it does
               not host"). */
            int swap[4] = {1, 0, 1, 0};
            CHECK(vw_world_post(w, 1, 0, &x) == VW_OK);
            CHECK(vw_world_remap(w, swap) == VW_OK);
            CHECK(vw_world_run(w) == VW_OK);
            CHECK(vw_world_cell_stats(w, 1, &cs) == VW_OK && cs.messages_in == 1);
            /* New walls without the cell a posted message waits for are refused (the
               message was handed to cell 3 of a world of 2 cells: a read past them). */
            CHECK(vw_world_post(w, 3, 0, &x) == VW_OK);
            CHECK(vw_world_redecompose(w, d, NULL) == VW_E_STATE);
            CHECK(vw_decomp_equal(vw_world_decomp(w), d2));
            CHECK(vw_world_run(w) == VW_OK);
            CHECK(vw_world_cell_stats(w, 3, &cs) == VW_OK && cs.messages_in == 1);
            CHECK(vw_world_redecompose(w, d, NULL) == VW_OK);
            CHECK(vw_world_run(w) == VW_OK);
            vw_decomp_free(d2);
        } else if (!strcmp(mode, "limits")) {
            /* n records of 24 bytes are more bytes than a size_t holds. */
            CHECK(vw_world_add_objects(w, o, SIZE_MAX / 2) == VW_E_NOMEM);
            CHECK(vw_world_add_objects(w, o, SIZE_MAX / sizeof(obj)) == VW_E_NOMEM);
            CHECK(vw_world_cells_of_object(w, 2, NULL, 0) == 0);
            CHECK(vw_world_run(w) == VW_OK);
            vw_world *w2 = NULL;
            cfg.packet_bytes = SIZE_MAX;
            CHECK(vw_world_create(&m, NULL, d, &cfg, &w2) == VW_E_LIMIT && !w2);
            printf("packets: %s\n", vw_world_errmsg(NULL));
            CHECK(strstr(vw_world_errmsg(NULL), "packets of") != NULL);
        } else if (!strcmp(mode, "slowdown")) {
            /* The factors are the world's copy: what the caller's array holds after
               create (here a slow-down that would spin for days) does not matter. */
            vw_world *w2 = NULL;
            double *slow = malloc(2 * sizeof *slow);
            CHECK(slow != NULL);
            slow[0] = slow[1] = 1.0;
            cfg.worker_slowdown = slow;
            CHECK(vw_world_create(&m, NULL, d, &cfg, &w2) == VW_OK);
            slow[0] = slow[1] = 1e12;
            CHECK(vw_world_add_objects(w2, o, 2) == VW_OK);
            int x = 0;
            CHECK(vw_world_post(w2, 0, 0, &x) == VW_OK);
            CHECK(vw_world_run(w2) == VW_OK);
            free(slow);
            CHECK(vw_world_post(w2, 1, 0, &x) == VW_OK);
            CHECK(vw_world_run(w2) == VW_OK);
            vw_world_free(w2);
        } else if (!strcmp(mode, "signal")) {
            vw_module sm = m;
            sm.kinds = signal_kinds;
            sm.step = signal_step;
            vw_world *w2 = NULL;
            CHECK(vw_world_create(&sm, NULL, d, &cfg, &w2) == VW_OK);
            CHECK(vw_world_post(w2, 1, 0, NULL) == VW_OK);
            CHECK(vw_world_post(w, 1, 0, NULL) == VW_E_INVAL); /* a kind of 4 bytes */
            CHECK(vw_world_run(w2) == VW_OK);
            CHECK_EQ_INT(signals_in, 3);  /* one posted, one from each of the 2 cells */
            CHECK_EQ_INT(signals_out, 2);
            vw_world_free(w2);
        } else if (!strcmp(mode, "stats")) {
            const char *lng = "a phase whose name is longer than sixteen bytes";
            vw_world_add_time(w, lng, 1.5);
            vw_world_add_time(w, lng, 1.0);
            CHECK_NEAR(vw_world_time(w, lng), 2.5, 0);
            char name[16];
            for (int i = 0; i < 20; i++) {
                snprintf(name, sizeof name, "p%d", i);
                vw_world_add_time(w, name, i);
            }
            CHECK_NEAR(vw_world_time(w, "p19"), 19, 0);
            vw_world_add_time(w, "say \"hi\"\\", 3);
            vw_world_set_balance_info(w, "my \"own\"", 1, 1, 0);
            CHECK(vw_world_run(w) == VW_OK);
            const char *path = "misuse_stats.json";
            CHECK(vw_world_write_stats(w, path, "misuse", NULL) == VW_OK);
            FILE *f = fopen(path, "r");
            CHECK(f != NULL);
            static char json[65536];
            size_t n = fread(json, 1, sizeof json - 1, f);
            json[n] = 0;
            fclose(f);
            remove(path);
            CHECK(strstr(json, "\"a phase whose name is longer than sixteen bytes\": 2.5") != NULL);
            CHECK(strstr(json, "\"p19\": 19.0") != NULL);
            CHECK(strstr(json, "\"say \\\"hi\\\"\\\\\": 3.0") != NULL);
            CHECK(strstr(json, "\"strategy\": \"my \\\"own\\\"\"") != NULL);
        } else if (!strcmp(mode, "errmsg")) {
            /* Each failure after the first must replace its message with its own. */
            int x = 0;
            CHECK(vw_world_post(w, 1, 1, &x) == VW_E_INVAL);
            CHECK(strstr(vw_world_errmsg(w), "has no handle") != NULL);
            CHECK(vw_world_post(w, 5, 0, &x) == VW_E_INVAL);
            printf("post to cell 5: %s\n", vw_world_errmsg(w));
            CHECK(strstr(vw_world_errmsg(w), "cell 5, which does not exist (2 cells)") != NULL);
            CHECK(vw_world_post(w, 0, 9, &x) == VW_E_INVAL);
            CHECK(strstr(vw_world_errmsg(w), "kind 9") != NULL);
            CHECK(vw_world_post(w, 0, 0, NULL) == VW_E_INVAL);
            CHECK(strstr(vw_world_errmsg(w), "no message (NULL)") != NULL);
            vw_cell_stats cs;
            CHECK(vw_world_cell_stats(w, 9, &cs) == VW_E_INVAL);
            CHECK(strstr(vw_world_errmsg(w), "cell 9 of 2") != NULL);
            CHECK(vw_world_write_stats(w, NULL, "misuse", NULL) == VW_E_INVAL);
            CHECK(strstr(vw_world_errmsg(w), "path is NULL") != NULL);
            CHECK(vw_world_post(w, 0, 0, &x) == VW_OK);
            CHECK(!strcmp(vw_world_errmsg(w), "no error"));
        } else if (!strcmp(mode, "done")) {
            int yes = 7;
            CHECK_EQ_INT(vw_world_done(w, &yes), VW_E_INVAL); /* the module has no done() */
            CHECK(yes == 0 && strstr(vw_world_errmsg(w), "has no done()") != NULL);
            vw_module dm = m;
            dm.done = cell_done;
            vw_world *w2 = NULL;
            CHECK(vw_world_create(&dm, NULL, d, &cfg, &w2) == VW_OK);
            CHECK_EQ_INT(vw_world_done(w2, &yes), VW_E_STATE); /* nothing built yet */
            printf("done: %s\n", vw_world_errmsg(w2));
            CHECK(vw_world_add_objects(w2, o, 2) == VW_OK);
            CHECK(vw_world_run(w2) == VW_OK);
            done_says[0] = 1;
            CHECK_EQ_INT(vw_world_done(w2, &yes), VW_OK);
            CHECK_EQ_INT(yes, 0);
            done_says[1] = 1;
            CHECK_EQ_INT(vw_world_done(w2, &yes), VW_OK);
            CHECK_EQ_INT(yes, 1);
            CHECK(done_asked[0] == 2 && done_asked[1] == 2); /* every cell, every time */
            CHECK_EQ_INT(vw_world_done(w2, NULL), VW_E_INVAL);
            vw_world_free(w2);
        } else if (!strcmp(mode, "maperr")) {
            /* Each failure says its own why, after an older failure too. */
            int x = 0;
            CHECK(vw_world_post(w, 5, 0, &x) == VW_E_INVAL);
            CHECK_EQ_INT(vw_world_remap(w, NULL), VW_E_INVAL);
            printf("remap: %s\n", vw_world_errmsg(w));
            CHECK(strstr(vw_world_errmsg(w), "vw_world_remap: no mapping") != NULL);
            CHECK(vw_world_post(w, 5, 0, &x) == VW_E_INVAL);
            CHECK_EQ_INT(vw_world_traffic(w, NULL), VW_E_INVAL);
            printf("traffic: %s\n", vw_world_errmsg(w));
            CHECK(strstr(vw_world_errmsg(w), "vw_world_traffic: out is NULL") != NULL);
            CHECK(vw_world_post(w, 5, 0, &x) == VW_E_INVAL);
            CHECK_EQ_INT(vw_world_machines(w, NULL), VW_E_INVAL);
            printf("machines: %s\n", vw_world_errmsg(w));
            CHECK(strstr(vw_world_errmsg(w), "vw_world_machines: machine_of is NULL") != NULL);
            /* A NULL world has no message to set; the answers are statuses alike. */
            vw_traffic t;
            int mach[1];
            CHECK_EQ_INT(vw_world_traffic(NULL, &t), VW_E_INVAL);
            CHECK_EQ_INT(vw_world_machines(NULL, mach), VW_E_INVAL);
            CHECK_EQ_INT(vw_world_remap(NULL, mach), VW_E_INVAL);
            /* And the calls still work. */
            int swap[2] = {1, 0};
            CHECK_EQ_INT(vw_world_remap(w, swap), VW_OK);
            CHECK(!strcmp(vw_world_errmsg(w), "no error"));
            CHECK_EQ_INT(vw_world_post(w, 0, 0, &x), VW_OK);
            CHECK_EQ_INT(vw_world_run(w), VW_OK);
            CHECK_EQ_INT(vw_world_traffic(w, &t), VW_OK);
            CHECK_EQ_INT(vw_world_machines(w, mach), VW_OK);
            CHECK_EQ_INT(mach[0], 0);
        } else if (!strcmp(mode, "post")) {
            int x = 0;
            CHECK(vw_world_post(w, 1, 1, &x) == VW_E_INVAL);
            printf("post: %s\n", vw_world_errmsg(w));
            CHECK(strstr(vw_world_errmsg(w), "posted message kind 1 ('to_output') to cell 1, but the "
                                             "kind has no handle (an output kind") != NULL);
            /* Said as a send to no such cell says it (it read "posted to cell 2 of 2"). */
            CHECK(vw_world_post(w, 2, 0, &x) == VW_E_INVAL);
            printf("post: %s\n", vw_world_errmsg(w));
            CHECK(strstr(vw_world_errmsg(w), "posted to cell 2, which does not exist (2 cells)") != NULL);
        } else {
            /* The child makes the mistake with its stderr into a pipe. count-all: every
               worker makes it at once, twenty times over; the report must be one whole
               line, from one worker (the lines of several were interleaved and cut). */
            int tries = !strcmp(mode, "count-all") ? 20 : 1;
            for (int t = 0; t < tries; t++) {
            char err[1024];
            int status = run_in_child(w, err, sizeof err);
            printf("%s: %s", mode, err);
            CHECK(WIFSIGNALED(status) && WTERMSIG(status) == SIGABRT);
            CHECK(argc > 2 && strstr(err, argv[2]) != NULL);
            /* One line, whole: "vwalls: module 'misuse' WHAT (worker W, in cell C)\n". */
            const char *at = strstr(err, "vwalls: module 'misuse' ");
            if (all)
                CHECK(at && !strstr(at + 1, "vwalls: module") && strstr(at, ", in cell ") &&
                      strchr(at, '\n') && !strchr(at, '\n')[1] && strchr(at, '\n')[-1] == ')');
            }
        }
    }
    vw_world_free(w);
    vw_decomp_free(d);
    printf("misuse %s ok\n", mode);
    return vw_test_failures ? 1 : 0;
}
