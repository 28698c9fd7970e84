/* test_storm.c - a message storm through the runtime, on the threads engine alone or
 * across the processes of an MPI job (the same program, the same checks): random
 * fan-out chains of sparks with random payloads hop between random cells (under MPI
 * most hops cross a process boundary), some go to the output process, some greet every
 * neighbour of their cell (vw_send_neighbours), and every cell is posted a message
 * before the run. What arrives is a pure function of the seed (every child is derived
 * from its parent's content), so every process checks the global counters, every
 * cell's figures and the output against a sequential reference, whatever the order:
 * every message must arrive exactly once, intact, at its cell, and the run must end.
 * Half the sparks whose cell is on the same worker are handed off inline
 * (vw_ctx_enter / vw_ctx_restore) instead of sent: they must count the same. Sparks are
 * independent messages, and in every other run a third of the cells are duplicated: the
 * copies share the sparks sent to their cell (and take the ones handed off inline on
 * their worker), and the counts must not change. Then the same world runs twice more
 * (new posts only, then nothing at all): only the posts move.
 *
 * Beside the storm, for the MPI tests (mpi.cmake): agreement between ranks and the
 * refusal of a world or module that differs on one rank (--agree), a rank that dies,
 * exits or hangs in the middle of a storm (--kill-rank, --exit-rank, --hang-rank: the
 * fault tests), a step of the world's life that fails on one rank only (--fail: every
 * rank must fail it, naming it), a peer that sends a garbled packet (--wire) and a step()
 * that calls vw_world_agree (--agree-in-step: the job must stop, naming it).
 *
 * usage: test_storm [SEEDS] [--stress] [--seeds N] [--workers W] [--agree]
 *                   [--kill-rank R] [--exit-rank R] [--hang-rank R]
 *                   [--fail STEP --fail-rank R] [--wire] [--agree-in-step]
 * SEEDS (or --seeds N, default 20) storms over six layouts each; --stress sets the
 * stress seed when VW_STRESS does not (VW_STRESS_SPLIT is read by the runtime). Without
 * --workers each storm runs 1 to 8 workers per process, varying; with it, W.
 * Runs alone (threads engine) or under mpirun.
 */
#include <signal.h>
#include <string.h>
#include <unistd.h>

#if VW_HAVE_MPI
#include <mpi.h>
#endif

#include "vw_test.h"
#include "vwalls/engine.h"
#include "vwalls/vwalls.h"

enum { MSG_SPARK, MSG_ECHO, MSG_POSTED, NKINDS };
enum { CNT_RECEIVED, CNT_SUM, CNT_CORRUPT, CNT_OUTPUT, CNT_ECHO, CNT_POSTED, NCOUNTERS };

typedef struct spark {
    uint64_t key;      /* determines hops, children, payload, cell */
    uint32_t hops;     /* generations left */
    uint32_t len;      /* payload bytes used */
    unsigned char payload[96];
} spark;

typedef struct storm {
    uint64_t seed;
    int ncells, roots;    /* roots per cell */
    long output_seen;     /* output handler only (serialised, on the output process) */
    int64_t output_sum;   /* the same */
    int kill_rank;        /* -1: nobody dies */
    int fail_build_rank;  /* cell_build fails on this rank's cells (-1: none) */
    int fail_run;         /* rank + 1 whose handler fails the run (0: none); then every
                             cell's step() sends sparks for ever, so the run can only end
                             if every rank drops its work */
    int hang_rank1;       /* rank + 1 whose handler hangs (0: none): a rank alive but stuck,
                             which only the launcher's time limit ends (MPIEXEC_TIMEOUT) */
} storm;

static void fill(spark *s, uint64_t key, uint32_t hops)
{
    s->key = key;
    s->hops = hops;
    s->len = (uint32_t)(vw_test_mix(key ^ 1) % sizeof s->payload);
    for (uint32_t i = 0; i < s->len; i++) s->payload[i] = (unsigned char)vw_test_mix(key + i);
}

static int children(const spark *s) { return s->hops ? (int)(vw_test_mix(s->key ^ 2) % 4) : 0; }
static int dest_of(uint64_t key, int ncells)
{
    return (int)(vw_test_mix(key ^ 3) % (uint64_t)ncells);
}
static uint64_t child_key(const spark *s, int c) { return vw_test_mix(s->key + 100 + (uint64_t)c); }
static int64_t low(uint64_t k) { return (int64_t)(k & 0xffffffu); }
static int is_output(uint64_t key) { return (key & 7) == 0; }

static uint64_t root_key(const storm *st, int cell, int r)
{
    return vw_test_mix(st->seed ^ ((uint64_t)cell << 24) ^ (uint64_t)r);
}
static uint32_t root_hops(uint64_t key) { return 1 + (uint32_t)(key % 6); }

/* The sequential reference of one root's tree: the sparks and echoes every cell
   receives (a spark with 3 children also greets every neighbour of its cell), the key
   sum, the outputs and their key sum. nb: room for vw_decomp_max_neighbours ids. */
typedef struct reference {
    int64_t *sparks, *echoes; /* per cell */
    int64_t sum, outputs, outsum;
    int *nb;
} reference;

static void expect(const vw_decomp *d, uint64_t key, uint32_t hops, reference *ref)
{
    spark s;
    fill(&s, key, hops);
    int cell = dest_of(key, vw_decomp_cell_count(d)), n = children(&s);
    ref->sparks[cell]++;
    ref->sum += low(key);
    if (is_output(key)) ref->outputs++, ref->outsum += low(key);
    if (n == 3)
        for (int f = 0; f < 6; f++) {
            int k = vw_decomp_neighbours(d, cell, f, ref->nb, vw_decomp_max_neighbours(d));
            for (int i = 0; i < k; i++) ref->echoes[ref->nb[i]]++;
        }
    for (int c = 0; c < n; c++) expect(d, child_key(&s, c), hops - 1, ref);
}

typedef struct storm_cell {
    int roots_sent;
} storm_cell;

static vw_status build(vw_ctx *ctx, const void *objs, size_t n, void **state)
{
    (void)objs, (void)n;
    if (((storm *)vw_ctx_user(ctx))->fail_build_rank == vw_ctx_process(ctx)) return VW_E_INPUT;
    *state = calloc(1, sizeof(storm_cell));
    return *state ? VW_OK : VW_E_NOMEM;
}

static void cell_free(void *state, void *user)
{
    (void)user;
    free(state);
}

static int step(vw_ctx *ctx, void *state)
{
    storm_cell *sc = state;
    storm *st = vw_ctx_user(ctx);
    if (vw_ctx_replica(ctx) > 0) return 0; /* the roots are the master's */
    if (sc->roots_sent == st->roots && !st->fail_run) return 0;
    uint64_t key = root_key(st, vw_ctx_cell(ctx), sc->roots_sent++);
    spark s;
    fill(&s, key, root_hops(key));
    vw_send_cell(ctx, dest_of(key, st->ncells), MSG_SPARK, &s);
    return 1;
}

static void on_spark(vw_ctx *ctx, void *state, const void *msg)
{
    (void)state;
    const spark *s = msg;
    storm *st = vw_ctx_user(ctx);
    static _Atomic long handled;
    if (st->kill_rank == vw_ctx_process(ctx) && ++handled == 500) raise(SIGKILL);
    if (st->hang_rank1 == vw_ctx_process(ctx) + 1 && ++handled == 500) {
        fprintf(stderr, "test_storm: rank %d hangs on purpose\n", vw_ctx_process(ctx));
        for (;;) pause(); /* its communication thread goes on: alive, but never done */
    }
    if (st->fail_run == vw_ctx_process(ctx) + 1 && ++handled == 2000)
        vw_ctx_fail(ctx, VW_E_NOMEM, "no room for spark %ld", (long)handled);
    spark check;
    fill(&check, s->key, s->hops);
    if (check.len != s->len || memcmp(check.payload, s->payload, s->len) != 0 ||
        dest_of(s->key, st->ncells) != vw_ctx_cell(ctx))
        vw_count(ctx, CNT_CORRUPT, 1);
    vw_count(ctx, CNT_RECEIVED, 1);
    vw_count(ctx, CNT_SUM, low(s->key));
    if (is_output(s->key)) {
        vw_send_output(ctx, MSG_SPARK, s);
        vw_count(ctx, CNT_OUTPUT, 1);
    }
    int n = children(s);
    if (n == 3) vw_send_neighbours(ctx, MSG_ECHO, s); /* the other route */
    int cell = vw_ctx_cell(ctx), replica = vw_ctx_replica(ctx);
    for (int c = 0; c < n; c++) {
        spark k;
        uint64_t key = child_key(s, c);
        fill(&k, key, s->hops - 1);
        int dest = dest_of(key, st->ncells);
        /* Every other child is handed off inline when its cell is on this worker
           (vw_ctx_enter): it must count exactly as if it had been delivered. */
        void *there = (key >> 7) & 1 ? vw_ctx_enter(ctx, dest, MSG_SPARK) : NULL;
        if (!there) {
            vw_send_cell(ctx, dest, MSG_SPARK, &k);
            continue;
        }
        if (vw_ctx_cell(ctx) != dest) vw_count(ctx, CNT_CORRUPT, 1);
        on_spark(ctx, there, &k);
        vw_ctx_restore(ctx, cell, replica);
        if (vw_ctx_cell(ctx) != cell || vw_ctx_replica(ctx) != replica) vw_count(ctx, CNT_CORRUPT, 1);
    }
}

static void on_echo(vw_ctx *ctx, void *state, const void *msg)
{
    (void)state, (void)msg;
    vw_count(ctx, CNT_ECHO, 1);
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
    st->output_seen++;
    st->output_sum += low(((const spark *)msg)->key);
}

static const vw_msg_kind kinds[NKINDS] = {
    [MSG_SPARK] = {"spark", sizeof(spark), on_spark, on_output, VW_MSG_INDEPENDENT},
    [MSG_ECHO] = {"echo", 16, on_echo, NULL},
    /* Independent (any copy may count it: copies add up to their cell). */
    [MSG_POSTED] = {"posted", sizeof(int64_t), on_posted, NULL, VW_MSG_INDEPENDENT},
};
static const char *const counters[NCOUNTERS] = {"received", "sum", "corrupt", "output", "echo",
                                                "posted"};
static const vw_module storm_module = {
    .abi = VW_MODULE_ABI,
    .name = "storm",
    .kinds = kinds,
    .nkinds = NKINDS,
    .counters = counters,
    .ncounters = NCOUNTERS,
    .cell_build = build,
    .cell_free = cell_free,
    .step = step,
};

/* What the storm runs: seeds, workers per process (0: 1 to 8, varying), the stress
   seed, and the faults of the fault tests. */
typedef struct options {
    int seeds, workers, stress, kill_rank, exit_rank, hang_rank;
} options;

/* Every cell's figures after a run: sparks and echoes as the reference says, plus the
   posted messages (`posts` of them each, their values summing to posted(c)). */
static void check_cells(vw_world *w, const reference *ref, int ncells, int posts, int64_t base)
{
    uint64_t in = 0;
    for (int c = 0; c < ncells; c++) {
        vw_cell_stats cs;
        CHECK_EQ_INT(vw_world_cell_stats(w, c, &cs), VW_OK);
        CHECK_EQ_INT(cs.messages_in, ref->sparks[c] + ref->echoes[c] + posts);
        CHECK_EQ_INT(vw_world_cell_counter(w, c, CNT_RECEIVED), ref->sparks[c]);
        CHECK_EQ_INT(vw_world_cell_counter(w, c, CNT_ECHO), ref->echoes[c]);
        CHECK_EQ_INT(vw_world_cell_counter(w, c, CNT_POSTED), (c + 1) + base);
        CHECK(cs.busy_s >= 0);
        in += cs.messages_in;
    }
    /* Messages delivered = messages the cells counted in. */
    CHECK_EQ_INT((int64_t)in, vw_world_counter(w, CNT_RECEIVED) + vw_world_counter(w, CNT_ECHO) +
                                  (int64_t)ncells * posts);
}

/* One storm: seed on the layout, checked against the reference over three runs of the
   same world. Returns the sparks delivered; *copies: whether cells were duplicated. */
static int64_t storm_run(const options *o, int seed, int li, const char *layout, int *copies)
{
    vw_box box = {{0, 0, 0}, {1, 1, 1}};
    int dims[3];
    CHECK_EQ_INT(vw_layout_parse(layout, dims, NULL, 0), VW_OK);
    vw_decomp *d;
    CHECK_EQ_INT(vw_decomp_create_grid(&box, dims, &d), VW_OK);
    int ncells = vw_decomp_cell_count(d);
    int workers = o->workers ? o->workers : 1 + (seed + li) % 8;
    storm st = {.seed = (uint64_t)seed * 104729u + (uint64_t)li, .ncells = ncells,
                .roots = 5 + (seed * 7 + li) % 30, .kill_rank = o->kill_rank,
                .fail_build_rank = -1, .hang_rank1 = o->hang_rank + 1};
    reference ref = {calloc((size_t)ncells, sizeof(int64_t)), calloc((size_t)ncells, sizeof(int64_t)),
                     0, 0, 0, malloc(sizeof(int) * (size_t)(vw_decomp_max_neighbours(d) + 1))};
    CHECK(ref.sparks && ref.echoes && ref.nb);
    for (int c = 0; c < ncells; c++)
        for (int r = 0; r < st.roots; r++) {
            uint64_t key = root_key(&st, c, r);
            expect(d, key, root_hops(key), &ref);
        }
    int64_t want = 0, echoes = 0;
    for (int c = 0; c < ncells; c++) want += ref.sparks[c], echoes += ref.echoes[c];

    vw_config cfg;
    vw_config_init(&cfg);
    cfg.workers = workers;
    cfg.packet_bytes = 64 + (size_t)(seed * 1499 + li * 613) % 8192; /* small packets: more flushes */
    if (o->stress && !cfg.stress_seed) cfg.stress_seed = (uint64_t)seed;
    /* A tiny message cap: step() is held back often, nothing may be lost. */
    if (seed % 3 == 0) cfg.cap_bytes = 256;
    vw_world *w;
    CHECK_EQ_INT(vw_world_create(&storm_module, &st, d, &cfg, &w), VW_OK);
    if (o->exit_rank == vw_world_process(w) && seed == 1 && li == 1) {
        fprintf(stderr, "test_storm: rank %d exits on purpose\n", o->exit_rank);
        exit(3); /* without MPI_Finalize, while the others wait for it */
    }
    int gw = vw_world_processes(w) * vw_world_workers(w);
    *copies = 0;
    if (gw > 1 && seed % 2 == 0)
        for (int c = 0; c < ncells; c += 3) {
            /* Copies on up to two other workers (of any process). */
            int m = vw_world_cell_worker(w, c), on[2], n = 0;
            for (int k = 1; k <= 2 && k < gw; k++) on[n++] = (m + k) % gw;
            CHECK_EQ_INT(vw_world_set_replicas(w, c, on, n), VW_OK);
            *copies = 1;
        }
    /* Every rank posts every message; each is kept by its cell's process only. */
    for (int c = 0; c < ncells; c++) {
        int64_t v = c + 1;
        CHECK_EQ_INT(vw_world_post(w, c, MSG_POSTED, &v), VW_OK);
    }
    CHECK_EQ_INT(vw_world_run(w), VW_OK);
    CHECK_EQ_INT(vw_world_counter(w, CNT_RECEIVED), want);
    CHECK_EQ_INT(vw_world_counter(w, CNT_SUM), ref.sum);
    CHECK_EQ_INT(vw_world_counter(w, CNT_ECHO), echoes);
    CHECK_EQ_INT(vw_world_counter(w, CNT_CORRUPT), 0);
    CHECK_EQ_INT(vw_world_counter(w, CNT_OUTPUT), ref.outputs);
    CHECK_EQ_INT(vw_world_counter(w, CNT_POSTED), (int64_t)ncells * (ncells + 1) / 2);
    if (vw_world_is_output(w)) {
        CHECK_EQ_INT(st.output_seen, vw_world_counter(w, CNT_OUTPUT));
        CHECK_EQ_INT(st.output_sum, ref.outsum);
    }
    check_cells(w, &ref, ncells, 1, 0);
    double busy = 0;
    for (int g = 0; g < gw; g++) busy += vw_world_worker_busy(w, g);
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
    check_cells(w, &ref, ncells, 2, 1000);
    /* Third run: nothing left to do, it must end at once with no deliveries. */
    CHECK_EQ_INT(vw_world_run(w), VW_OK);
    CHECK_EQ_INT(vw_world_counter(w, CNT_RECEIVED), want);
    CHECK_EQ_INT(vw_world_counter(w, CNT_ECHO), echoes);
    vw_cell_stats cs0;
    CHECK_EQ_INT(vw_world_cell_stats(w, 0, &cs0), VW_OK);
    CHECK_EQ_INT(cs0.messages_in, ref.sparks[0] + ref.echoes[0] + 2);
    if (seed == 1 && !strcmp(layout, "2x2x2") && vw_world_is_output(w)) {
        const char *path = getenv("VW_TEST_STATS");
        if (path) CHECK_EQ_INT(vw_world_write_stats(w, path, "test-storm", NULL), VW_OK);
    }
    vw_world_free(w);
    vw_decomp_free(d);
    free(ref.sparks);
    free(ref.echoes);
    free(ref.nb);
    return want;
}

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
        /* Under MPI the rank follows the FILE:LINE: of bad input, which stays first. */
        snprintf(want, sizeof want, size > 1 ? "scene.nff:3: rank %d: bad number 'x'"
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
#if VW_HAVE_MPI /* a communicator of one's own needs MPI */
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
#endif
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
        storm st = {.seed = 1, .ncells = nc, .kill_rank = -1, .fail_build_rank = -1};
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
    vw_msg_kind more[NKINDS + 1], wider[NKINDS];
    memcpy(more, kinds, sizeof kinds);
    more[NKINDS] = (vw_msg_kind){"newer", sizeof(int64_t), on_posted, NULL, 0};
    memcpy(wider, kinds, sizeof kinds);
    wider[MSG_POSTED].size = 2 * sizeof(int64_t);
    const char *other_counters[NCOUNTERS];
    memcpy(other_counters, counters, sizeof counters);
    other_counters[CNT_POSTED] = "posted twice";
    vw_box box = {{0, 0, 0}, {1, 1, 1}};
    int dims[3] = {2, 1, 1};
    for (int what = 0; what < 6; what++) {
        vw_module m = storm_module;
        if (what > 0 && rank == bad) {
            if (what == 1) m.kinds = more, m.nkinds = NKINDS + 1;
            if (what == 2) m.kinds = wider;
            if (what == 3) m.object_size = 3 * sizeof(double), m.object_bounds = point_bounds;
            if (what == 4) m.counters = other_counters;
            if (what == 5) m.name = "storm 2";
        }
        vw_decomp *d;
        CHECK_EQ_INT(vw_decomp_create_grid(&box, dims, &d), VW_OK);
        storm st = {.seed = 1, .ncells = 2, .kill_rank = -1, .fail_build_rank = -1};
        vw_config cfg;
        vw_config_init(&cfg);
        cfg.workers = workers;
        vw_world *w = NULL;
        vw_status got = vw_world_create(&m, &st, d, &cfg, &w);
        if (what == 0 || size == 1) {
            EXPECT(got == VW_OK, "%s: create %d: %s", what_name[what], (int)got, vw_world_errmsg(NULL));
        } else {
            /* The message says what differs, with both processes' values. */
            char want[256];
            const char *detail[] = {
                "", "4 message kinds on process %d, 3 on process 0",
                "message kind 2 ('posted') of 16 bytes on process %d, 8 on process 0",
                "objects of 24 bytes on process %d, 0 on process 0", "other counter names",
                "another module name"};
            int n = snprintf(want, sizeof want, "process %d runs another module than process 0 "
                             "(module 'storm': ", bad);
            snprintf(want + n, sizeof want - (size_t)n, detail[what], bad);
            EXPECT(got == VW_E_INVAL && !w && strstr(vw_world_errmsg(NULL), want),
                   "rank %d, %s: create %d: '%s' (want '%s')", rank, what_name[what], (int)got,
                   vw_world_errmsg(NULL), want);
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
   goes on like any program: it stops at the first step that fails, frees what it has
   and finishes MPI. The step must fail on every rank with the failing rank's message,
   or the others would wait for it in the next collective call (and it for them in
   MPI_Finalize). */
static int local_failure(const char *step, int bad, int workers)
{
    int rank = vw_engine_rank(), here = rank == bad;
    vw_box box = {{0, 0, 0}, {1, 1, 1}};
    int dims[3] = {2, 2, 1};
    vw_decomp *d;
    CHECK_EQ_INT(vw_decomp_create_grid(&box, dims, &d), VW_OK);
    int nc = vw_decomp_cell_count(d), gw = vw_engine_size() * workers;
    storm st = {.seed = 1, .ncells = nc, .roots = 1, .kill_rank = -1,
                .fail_build_rank = here && (!strcmp(step, "commit") || !strcmp(step, "run")) ? bad : -1,
                .fail_run = !strcmp(step, "handler") ? bad + 1 : 0};
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
             (strcmp(step, "handler") != 0 || strstr(msg, ": no room for spark 2000"));
    /* tests/mpi/local_fail.sh reads these lines by this prefix. */
    fprintf(stderr, "test_storm: process %d: %s failed (%s): %s%s\n", rank, failed,
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
    storm st = {.seed = 1, .ncells = dims[0], .kill_rank = -1, .fail_build_rank = -1};
    vw_config cfg;
    vw_config_init(&cfg);
    cfg.workers = 1;
    CHECK_EQ_INT(vw_world_create(&m, &st, d, &cfg, w), VW_OK);
    CHECK_EQ_INT(vw_world_run(*w), VW_OK);
    fprintf(stderr, "test_storm: process %d: %s\n", vw_engine_rank(), unnoticed);
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
    options o = {20, 0, 0, -1, -1, -1};
    int agree = 0, fail_rank = 1, wire = 0, agree_step_mode = 0;
    const char *fail = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--workers") && i + 1 < argc) o.workers = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--seeds") && i + 1 < argc) o.seeds = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--stress")) o.stress = 1;
        else if (!strcmp(argv[i], "--agree")) agree = 1;
        else if (!strcmp(argv[i], "--kill-rank") && i + 1 < argc) o.kill_rank = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--exit-rank") && i + 1 < argc) o.exit_rank = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--hang-rank") && i + 1 < argc) o.hang_rank = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--fail") && i + 1 < argc) fail = argv[++i];
        else if (!strcmp(argv[i], "--wire")) wire = 1;
        else if (!strcmp(argv[i], "--agree-in-step")) agree_step_mode = 1;
        else if (!strcmp(argv[i], "--fail-rank") && i + 1 < argc) fail_rank = atoi(argv[++i]);
        else if (argv[i][0] >= '0' && argv[i][0] <= '9') o.seeds = atoi(argv[i]);
        else {
            fprintf(stderr, "test_storm: bad argument '%s'\n", argv[i]);
            return 2;
        }
    }
    if (o.workers < 0 || o.seeds < 0) {
        fprintf(stderr, "test_storm: bad --workers or seed count\n");
        return 2;
    }
    char err[256];
    if (vw_engine_init(&argc, &argv, err, sizeof err) != VW_OK) {
        fprintf(stderr, "test_storm: %s\n", err);
        return 1;
    }
    int rank = vw_engine_rank(), workers = o.workers ? o.workers : 2;
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
    const char *layouts[] = {"1", "2", "2x2", "3x1x2", "2x2x2", "4x4x2"};
    int runs = 0, dup_runs = 0;
    int64_t total = 0;
    for (int seed = 1; seed <= o.seeds; seed++)
        for (int li = 0; li < (int)(sizeof layouts / sizeof layouts[0]); li++) {
            int copies;
            total += storm_run(&o, seed, li, layouts[li], &copies);
            runs++;
            dup_runs += copies;
        }
    if (rank == 0)
        printf("%d storm runs (%d with copies) on %d process(es), %lld sparks delivered; "
               "%d checks passed\n", runs, dup_runs, vw_engine_size(), (long long)total,
               vw_test_checks);
    vw_engine_finish();
    return 0;
}
