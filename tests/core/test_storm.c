/* test_storm.c - a message storm through the runtime: random fan-out chains with
 * random payloads between random cells. The tree of messages is a pure function of
 * the seed (every child is derived from its parent's content), so the number of
 * deliveries and a checksum of what was delivered are known in advance whatever the
 * order; every message must arrive exactly once, intact, and the run must end.
 * Half the sparks whose cell is on the same worker are handed off inline
 * (vw_ctx_enter / vw_ctx_restore) instead of sent: they must count the same.
 * Sparks are independent messages, and in every other run a third of the cells are
 * duplicated: the copies share the sparks sent to their cell (and take the ones
 * handed off inline on their worker), and the counts must not change.
 *
 * usage: test_storm [SEEDS] [--stress]   (also honours VW_STRESS / VW_STRESS_SPLIT)
 */
#include <string.h>

#include "vw_test.h"
#include "vwalls/vwalls.h"

enum { MSG_SPARK, MSG_ECHO, NKINDS };
enum { CNT_RECEIVED, CNT_SUM, CNT_CORRUPT, CNT_OUTPUT, CNT_ECHO, NCOUNTERS };

typedef struct spark {
    uint64_t key;      /* determines hops, children, payload */
    uint32_t hops;     /* generations left */
    uint32_t len;      /* payload bytes used */
    unsigned char payload[200];
} spark;

typedef struct storm {
    uint64_t seed;
    int ncells;
    int roots_per_cell;
    long output_seen; /* touched only by the output handler (serialised) */
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

/* The sequential reference: how many sparks a root creates in all, their key sum, and
   how many echoes (a spark with 3 children also greets all neighbours of its cell). */
static void expect(const vw_decomp *d, uint64_t key, uint32_t hops, int64_t *count,
                   int64_t *sum, int64_t *echoes)
{
    spark s;
    fill(&s, key, hops);
    (*count)++;
    *sum += (int64_t)(s.key & 0xffffffffu);
    int n = children(&s);
    if (n == 3) {
        int cell = dest_of(key, vw_decomp_cell_count(d));
        for (int f = 0; f < 6; f++) *echoes += vw_decomp_neighbours(d, cell, f, NULL, 0);
    }
    for (int c = 0; c < n; c++)
        expect(d, vw_test_mix(s.key + 100 + (uint64_t)c), hops - 1, count, sum, echoes);
}

typedef struct storm_cell {
    int roots_sent;
} storm_cell;

static vw_status build(vw_ctx *ctx, const void *objs, size_t n, void **state)
{
    (void)ctx, (void)objs, (void)n;
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
    if (sc->roots_sent == st->roots_per_cell) return 0;
    spark s;
    uint64_t key =
        vw_test_mix(st->seed ^ ((uint64_t)vw_ctx_cell(ctx) << 20) ^ (uint64_t)sc->roots_sent);
    fill(&s, key, 1 + (uint32_t)(key % 6));
    vw_send_cell(ctx, dest_of(key, st->ncells), MSG_SPARK, &s);
    sc->roots_sent++;
    return 1;
}

static void on_spark(vw_ctx *ctx, void *state, const void *msg)
{
    (void)state;
    const spark *s = msg;
    storm *st = vw_ctx_user(ctx);
    spark check;
    fill(&check, s->key, s->hops);
    if (check.len != s->len || memcmp(check.payload, s->payload, s->len) != 0)
        vw_count(ctx, CNT_CORRUPT, 1);
    vw_count(ctx, CNT_RECEIVED, 1);
    vw_count(ctx, CNT_SUM, (int64_t)(s->key & 0xffffffffu));
    if ((s->key & 15) == 0) {
        vw_send_output(ctx, MSG_SPARK, s);
        vw_count(ctx, CNT_OUTPUT, 1);
    }
    int n = children(s);
    if (n == 3) vw_send_neighbours(ctx, MSG_ECHO, s); /* the other route */
    int cell = vw_ctx_cell(ctx), replica = vw_ctx_replica(ctx);
    for (int c = 0; c < n; c++) {
        spark k;
        uint64_t key = vw_test_mix(s->key + 100 + (uint64_t)c);
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

static void on_output(void *user, const void *msg)
{
    (void)msg;
    storm *st = user;
    st->output_seen++;
}

static const vw_msg_kind kinds[NKINDS] = {
    [MSG_SPARK] = {"spark", sizeof(spark), on_spark, on_output, VW_MSG_INDEPENDENT},
    [MSG_ECHO] = {"echo", 16, on_echo, NULL},
};
static const char *const counters[NCOUNTERS] = {"received", "sum", "corrupt", "output", "echo"};
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

int main(int argc, char **argv)
{
    int seeds = argc > 1 ? atoi(argv[1]) : 20;
    int stress = argc > 2 && !strcmp(argv[2], "--stress");
    vw_box world = {{0, 0, 0}, {1, 1, 1}};
    const char *layouts[] = {"1", "2", "2x2", "3x1x2", "2x2x2", "4x4x4"};
    int runs = 0, dup_runs = 0;
    int64_t total = 0;
    for (int seed = 1; seed <= seeds; seed++) {
        for (size_t li = 0; li < sizeof layouts / sizeof layouts[0]; li++) {
            int dims[3];
            CHECK_EQ_INT(vw_layout_parse(layouts[li], dims, NULL, 0), VW_OK);
            vw_decomp *d;
            CHECK_EQ_INT(vw_decomp_create_grid(&world, dims, &d), VW_OK);
            int ncells = vw_decomp_cell_count(d);
            int workers = 1 + (seed + (int)li) % 8;
            storm st = {(uint64_t)seed * 7919u, ncells, 10 + seed % 20, 0};
            int64_t want = 0, sum = 0, echoes = 0;
            for (int c = 0; c < ncells; c++)
                for (int r = 0; r < st.roots_per_cell; r++) {
                    uint64_t key = vw_test_mix(st.seed ^ ((uint64_t)c << 20) ^ (uint64_t)r);
                    expect(d, key, 1 + (uint32_t)(key % 6), &want, &sum, &echoes);
                }
            vw_config cfg;
            vw_config_init(&cfg);
            cfg.workers = workers;
            cfg.packet_bytes = 64 + (size_t)(seed * 997) % 8192; /* small packets: more flushes */
            if (stress && !cfg.stress_seed) cfg.stress_seed = (uint64_t)seed;
            /* A tiny message cap: step() is held back often, nothing may be lost. */
            if (seed % 3 == 0) cfg.cap_bytes = 256;
            vw_world *w;
            CHECK_EQ_INT(vw_world_create(&storm_module, &st, d, &cfg, &w), VW_OK);
            int ncopies = 0;
            if (workers > 1 && seed % 2 == 0)
                for (int c = 0; c < ncells; c += 3) {
                    /* Copies on up to two other workers. */
                    int m = vw_world_cell_worker(w, c), on[2], n = 0;
                    for (int k = 1; k <= 2 && k < workers; k++) on[n++] = (m + k) % workers;
                    CHECK_EQ_INT(vw_world_set_replicas(w, c, on, n), VW_OK);
                    ncopies += n;
                }
            CHECK_EQ_INT(vw_world_run(w), VW_OK);
            int64_t received = vw_world_counter(w, CNT_RECEIVED);
            CHECK_EQ_INT(received, want);
            total += received;
            CHECK_EQ_INT(vw_world_counter(w, CNT_SUM), sum);
            CHECK_EQ_INT(vw_world_counter(w, CNT_ECHO), echoes);
            CHECK_EQ_INT(vw_world_counter(w, CNT_CORRUPT), 0);
            if (vw_world_is_output(w)) CHECK_EQ_INT(st.output_seen, vw_world_counter(w, CNT_OUTPUT));
            /* Messages delivered = messages the cells counted in. */
            uint64_t in = 0;
            for (int c = 0; c < ncells; c++) {
                vw_cell_stats cs;
                CHECK_EQ_INT(vw_world_cell_stats(w, c, &cs), VW_OK);
                in += cs.messages_in;
            }
            CHECK_EQ_INT((int64_t)in, received + echoes);
            /* Run again: nothing left to do, must terminate at once with no deliveries. */
            CHECK_EQ_INT(vw_world_run(w), VW_OK);
            CHECK_EQ_INT(vw_world_counter(w, CNT_RECEIVED), received);
            vw_world_free(w);
            vw_decomp_free(d);
            runs++;
            dup_runs += ncopies > 0;
        }
    }
    printf("%d storm runs (%d with copies), %lld sparks delivered\n", runs, dup_runs,
           (long long)total);
    TEST_DONE();
}
