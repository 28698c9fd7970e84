/* test_mpi_traffic_agree.c - vw_world_traffic and vw_world_machines end in agreement under
 * MPI, like the steps of a world's life: given a NULL out / machine_of on some ranks only,
 * every rank returns VW_E_INVAL with "rank R: <the call's message>" (R the lowest failing
 * rank) and none is left waiting for another in the calls' collectives (the test's time
 * limit catches that); the calls then still work and give every rank the same figures.
 * Run alone, the threads engine answers as before: the plain message, no rank.
 *
 * usage: test_mpi_traffic_agree (alone or under mpirun)
 */
#include <stdatomic.h>
#include <string.h>

#include "vw_test.h"
#include "vwalls/engine.h"
#include "vwalls/vwalls.h"

enum { MAX_CELLS = 64 };

/* Every cell sends one message to the next cell in its first step (one worker per
   process, so under MPI most of them cross a process). */
static atomic_int sent[MAX_CELLS];
static int ncells;

static int step(vw_ctx *ctx, void *state)
{
    (void)state;
    int c = vw_ctx_cell(ctx);
    if (atomic_exchange(&sent[c], 1)) return 0;
    int hop = c;
    vw_send_cell(ctx, (c + 1) % ncells, 0, &hop);
    return 1;
}

static void on_hop(vw_ctx *ctx, void *state, const void *msg)
{
    (void)ctx, (void)state, (void)msg;
}

static const vw_msg_kind kinds[] = {{"hop", sizeof(int), on_hop, NULL, 0}};
static const vw_module hop_module = {
    .abi = VW_MODULE_ABI,
    .name = "traffic-agree",
    .kinds = kinds,
    .nkinds = 1,
    .step = step,
};

/* Whether this rank is one of the failing ones (bits of `bad`). */
static int failing(unsigned bad) { return (bad >> vw_engine_rank()) & 1u; }

static int lowest(unsigned bad)
{
    int r = 0;
    while (!((bad >> r) & 1u)) r++;
    return r;
}

/* The failure every rank must hold: "rank R: what" under MPI, what alone otherwise. */
static void check_message(vw_world *w, unsigned bad, const char *what)
{
    char want[256];
    if (vw_engine_size() > 1) snprintf(want, sizeof want, "rank %d: %s", lowest(bad), what);
    else snprintf(want, sizeof want, "%s", what);
    if (strcmp(vw_world_errmsg(w), want) != 0) {
        fprintf(stderr, "test_mpi_traffic_agree: rank %d holds \"%s\", not \"%s\"\n",
                vw_engine_rank(), vw_world_errmsg(w), want);
        exit(1);
    }
}

static void check_answers(vw_world *w, const vw_traffic *ref, const int *mach_ref)
{
    vw_traffic t;
    int mach[MAX_CELLS];
    CHECK_EQ_INT(vw_world_traffic(w, &t), VW_OK);
    CHECK(memcmp(&t, ref, sizeof t) == 0);
    CHECK_EQ_INT(vw_world_machines(w, mach), VW_OK);
    CHECK(memcmp(mach, mach_ref, sizeof(int) * (size_t)vw_world_processes(w)) == 0);
}

int main(int argc, char **argv)
{
    char err[256];
    if (vw_engine_init(&argc, &argv, err, sizeof err) != VW_OK) {
        fprintf(stderr, "test_mpi_traffic_agree: %s\n", err);
        return 1;
    }
    int size = vw_engine_size(), rank = vw_engine_rank();
    CHECK(size <= 8);
    vw_box box = {{0, 0, 0}, {1, 1, 1}};
    int dims[3] = {2 * size, 1, 1};
    vw_decomp *d;
    CHECK_EQ_INT(vw_decomp_create_grid(&box, dims, &d), VW_OK);
    ncells = vw_decomp_cell_count(d);
    vw_config cfg;
    vw_config_init(&cfg);
    cfg.workers = 1;
    vw_world *w;
    CHECK_EQ_INT(vw_world_create(&hop_module, NULL, d, &cfg, &w), VW_OK);
    CHECK_EQ_INT(vw_world_commit(w), VW_OK);
    CHECK_EQ_INT(vw_world_run(w), VW_OK);

    /* The figures of the run, the same on every rank. */
    vw_traffic ref;
    int mach_ref[MAX_CELLS];
    CHECK_EQ_INT(vw_world_traffic(w, &ref), VW_OK);
    CHECK_EQ_INT(ref.msgs, ncells);
    CHECK_EQ_INT(vw_world_machines(w, mach_ref), VW_OK);
    CHECK_EQ_INT(mach_ref[0], 0);
    vw_traffic rank0 = ref;
    vw_engine_broadcast(&rank0, sizeof rank0);
    CHECK(memcmp(&rank0, &ref, sizeof ref) == 0);

    /* Every non-empty set of failing ranks among the first three (alone: rank 0), rank 1
       alone first: the others, fine, used to wait for it in the calls' collectives. */
    static const unsigned sets[] = {2, 1, 3, 4, 5, 6, 7};
    int cases = 0;
    for (int i = 0; i < (int)(sizeof sets / sizeof *sets); i++) {
        unsigned bad = sets[i];
        if (bad >> (size < 3 ? size : 3)) continue;
        vw_traffic t;
        int mach[MAX_CELLS];
        CHECK_EQ_INT(vw_world_traffic(w, failing(bad) ? NULL : &t), VW_E_INVAL);
        check_message(w, bad, "vw_world_traffic: out is NULL");
        CHECK_EQ_INT(vw_world_machines(w, failing(bad) ? NULL : mach), VW_E_INVAL);
        check_message(w, bad, "vw_world_machines: machine_of is NULL");
        /* Nobody was left behind in a collective: the calls still meet and agree. */
        check_answers(w, &ref, mach_ref);
        cases++;
    }
    /* A NULL world has no processes to agree with: VW_E_INVAL on the caller alone. */
    vw_traffic t;
    int mach[1];
    CHECK_EQ_INT(vw_world_traffic(NULL, &t), VW_E_INVAL);
    CHECK_EQ_INT(vw_world_machines(NULL, mach), VW_E_INVAL);
    check_answers(w, &ref, mach_ref);

    vw_world_free(w);
    vw_decomp_free(d);
    if (rank == 0)
        printf("traffic agreement: %d processes, %d failing sets, %d checks\n", size, cases,
               vw_test_checks);
    vw_engine_finish();
    return 0;
}
