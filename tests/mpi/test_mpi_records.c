/* test_mpi_records.c - a world's object records under MPI: every process keeps only its
 * share (the records of the objects its cells and copies hold, and of the objects no
 * cell holds whose home it is), and every cell, wherever it is built, gets its objects'
 * records whole and in the order added, through every change of a world's life:
 * objects added (some outside the world box), new mappings (cells move to other
 * processes), new decompositions (a larger world box places the outside objects too),
 * copies of cells on other processes, and objects moved by vw_world_update_object
 * (into another cell, out of the world, back in).
 *
 * After every commit each process checks, for each unit (cell or copy) built then:
 * the records' contents (each carries a check word of its id and position), their ids
 * against the world's placement (vw_world_cells_of_object), and their order. And it
 * checks that the records it keeps are exactly its share (the world's internals).
 * Alone (no mpirun) every record is kept, and the same builds are checked.
 *
 * usage: test_mpi_records [--objects N] [--workers W]
 */
#include <stdatomic.h>
#include <string.h>

#include "core/world_internal.h"
#include "vw_test.h"
#include "vwalls/engine.h"
#include "vwalls/vwalls.h"

typedef struct rec {
    uint64_t id;
    double c[3], r;
    uint64_t check; /* of id and c: a record garbled or swapped on the way shows */
} rec;

static uint64_t rec_check(const rec *o)
{
    uint64_t h = vw_test_mix(o->id);
    for (int a = 0; a < 3; a++) {
        uint64_t b;
        memcpy(&b, &o->c[a], sizeof b);
        h = vw_test_mix(h ^ b);
    }
    return h;
}

static void rec_bounds(const void *object, vw_box *out, void *user)
{
    (void)user;
    const rec *o = object;
    for (int a = 0; a < 3; a++) {
        out->lo[a] = o->c[a] - o->r;
        out->hi[a] = o->c[a] + o->r;
    }
}

enum { MAX_CELLS = 64, MAX_UNITS = 8 };

/* What each unit (cell, copy) built in the current commit received: the ids in order. */
typedef struct built {
    atomic_int done;
    size_t n;
    uint64_t *ids;
} built;
static built units[MAX_CELLS][MAX_UNITS];
static atomic_int bad_records;

static vw_status build(vw_ctx *ctx, const void *objects, size_t n, void **state)
{
    built *b = &units[vw_ctx_cell(ctx)][vw_ctx_replica(ctx)];
    free(b->ids);
    b->ids = malloc(sizeof *b->ids * (n ? n : 1));
    if (!b->ids) return VW_E_NOMEM;
    const rec *o = objects;
    for (size_t i = 0; i < n; i++) {
        if (o[i].check != rec_check(&o[i])) atomic_fetch_add(&bad_records, 1);
        b->ids[i] = o[i].id;
    }
    b->n = n;
    atomic_store(&b->done, 1);
    *state = NULL;
    return VW_OK;
}

static void on_msg(vw_ctx *ctx, void *state, const void *msg) { (void)ctx, (void)state, (void)msg; }

static const vw_msg_kind kinds[] = {{"nothing", sizeof(int), on_msg, NULL, VW_MSG_INDEPENDENT}};
static const vw_module rec_module = {
    .abi = VW_MODULE_ABI,
    .name = "records",
    .object_size = sizeof(rec),
    .object_bounds = rec_bounds,
    .kinds = kinds,
    .nkinds = 1,
    .cell_build = build,
};

static size_t nobj;
static rec *objs; /* the scene as every process has it (updates applied) */

static void forget_builds(void)
{
    for (int c = 0; c < MAX_CELLS; c++)
        for (int u = 0; u < MAX_UNITS; u++) atomic_store(&units[c][u].done, 0);
}

/* Whether this process hosts unit u (0: the master) of cell c. */
static int hosts(const vw_world *w, int c, int u)
{
    int g = vw_world_cell_worker(w, c);
    if (u > 0) {
        int reps[MAX_UNITS];
        int n = vw_world_replicas(w, c, reps, MAX_UNITS);
        if (u > n) return 0;
        g = reps[u - 1];
    }
    return g / vw_world_workers(w) == vw_world_process(w);
}

static int moved; /* objects were moved (vw_world_update_object) */

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* Checks every unit built since forget_builds() against the world's placement (its
   objects' ids, ascending: the order added), that at least `want_built` were, and that
   this process keeps exactly its share of the records. */
static void check_commit(vw_world *w, int want_built, const char *what)
{
    CHECK_EQ_INT(atomic_load(&bad_records), 0);
    int ncells = vw_decomp_cell_count(vw_world_decomp(w)), nbuilt = 0;
    CHECK(ncells <= MAX_CELLS);
    /* The ids each cell holds, from the placement. */
    uint64_t *ids[MAX_CELLS];
    size_t count[MAX_CELLS] = {0};
    for (int c = 0; c < ncells; c++) CHECK((ids[c] = malloc(sizeof(uint64_t) * nobj)) != NULL);
    unsigned char *share = calloc(nobj, 1);
    CHECK(share);
    for (size_t id = 0; id < nobj; id++) {
        int cells[MAX_CELLS];
        int k = vw_world_cells_of_object(w, id, cells, MAX_CELLS);
        if (k == 0 && (int)(id % (size_t)vw_world_processes(w)) == vw_world_process(w)) share[id] = 1;
        for (int i = 0; i < k; i++) {
            int c = cells[i];
            ids[c][count[c]++] = id;
            for (int u = 0; u < MAX_UNITS; u++)
                if (hosts(w, c, u)) share[id] = 1;
        }
    }
    for (int c = 0; c < ncells; c++)
        for (int u = 0; u < MAX_UNITS; u++) {
            const built *b = &units[c][u];
            if (!atomic_load(&b->done)) continue;
            CHECK(hosts(w, c, u));
            CHECK_EQ_INT(b->n, count[c]);
            /* In the order added until objects move: vw_world_update_object appends a
               moved object to its new cells' lists. So compared as sets, and in order
               while nothing moved. */
            if (!moved) CHECK(memcmp(b->ids, ids[c], sizeof(uint64_t) * count[c]) == 0);
            qsort(b->ids, b->n, sizeof *b->ids, cmp_u64);
            CHECK(memcmp(b->ids, ids[c], sizeof(uint64_t) * count[c]) == 0);
            nbuilt++;
        }
    if (nbuilt < want_built) {
        fprintf(stderr, "test_mpi_records: %s: rank %d built %d units, expected at least %d\n",
                what, vw_world_process(w), nbuilt, want_built);
        exit(1);
    }
    /* The records kept: exactly the share (every one alone), each the object's
       current record. */
    size_t nshare = 0;
    int single = vw_world_processes(w) == 1;
    for (size_t id = 0; id < nobj; id++) {
        const unsigned char *r = vw__world_record(w, id);
        nshare += share[id];
        if ((single && !r) || (!single && share[id] != (r != NULL))) {
            fprintf(stderr, "test_mpi_records: %s: rank %d %s object %zu's record\n", what,
                    vw_world_process(w), r ? "keeps" : "lacks", id);
            exit(1);
        }
        if (r) CHECK(memcmp(r, &objs[id], sizeof(rec)) == 0);
    }
    if (!single) CHECK_EQ_INT(w->nslots, nshare);
    if (vw_world_process(w) == 0)
        printf("%s: rank 0 keeps %zu of %zu records, built %d units\n", what, w->nslots, nobj, nbuilt);
    for (int c = 0; c < ncells; c++) free(ids[c]);
    free(share);
    forget_builds();
}

static void commit(vw_world *w, int want_built, const char *what)
{
    vw_status st = vw_world_commit(w);
    if (st != VW_OK) {
        fprintf(stderr, "test_mpi_records: %s: commit: %s\n", what, vw_world_errmsg(w));
        exit(1);
    }
    check_commit(w, want_built, what);
}

int main(int argc, char **argv)
{
    char msg[256];
    if (vw_engine_init(&argc, &argv, msg, sizeof msg) != VW_OK) {
        fprintf(stderr, "test_mpi_records: %s\n", msg);
        return 1;
    }
    int workers = 1;
    nobj = 3000;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--objects")) nobj = (size_t)atol(argv[i + 1]);
        if (!strcmp(argv[i], "--workers")) workers = atoi(argv[i + 1]);
    }
    /* Spheres in [0, 1]^3, a tenth of them outside the world box [0, 0.8]^3 at first. */
    objs = calloc(nobj, sizeof *objs);
    CHECK(objs);
    for (size_t i = 0; i < nobj; i++) {
        rec *o = &objs[i];
        o->id = i;
        for (int a = 0; a < 3; a++) o->c[a] = (double)(vw_test_mix(i * 3 + (uint64_t)a) >> 11) / 9007199254740992.0;
        if (i % 10 == 0) o->c[0] = 0.9;
        o->r = 0.01;
        o->check = rec_check(o);
    }
    vw_box small = {{0, 0, 0}, {0.8, 0.8, 0.8}}, large = {{0, 0, 0}, {1, 1, 1}};
    vw_decomp *d1, *d2;
    CHECK_EQ_INT(vw_decomp_create_grid(&small, (int[3]){2, 2, 2}, &d1), VW_OK);
    CHECK_EQ_INT(vw_decomp_create_grid(&large, (int[3]){3, 2, 1}, &d2), VW_OK);
    vw_config cfg;
    vw_config_init(&cfg);
    cfg.workers = workers;
    vw_world *w;
    if (vw_world_create(&rec_module, NULL, d1, &cfg, &w) != VW_OK) {
        fprintf(stderr, "test_mpi_records: create: %s\n", vw_world_errmsg(NULL));
        return 1;
    }
    int P = vw_world_processes(w), G = P * vw_world_workers(w);
    /* Added in three parts: kept or not as they come. */
    size_t part = nobj / 3;
    CHECK_EQ_INT(vw_world_add_objects(w, objs, part), VW_OK);
    CHECK_EQ_INT(vw_world_add_objects(w, objs + part, nobj - 2 * part), VW_OK);
    CHECK_EQ_INT(vw_world_add_objects(w, objs + nobj - part, part), VW_OK);
    commit(w, 1, "first commit");
    /* Kept as they were added: nothing to fetch at the first commit. */
    CHECK_EQ_INT(w->fetched, 0);

    /* Every cell to another worker (and so, for most, another process). */
    int map[MAX_CELLS];
    for (int c = 0; c < 8; c++) map[c] = (vw_world_cell_worker(w, c) + 1 + c) % G;
    CHECK_EQ_INT(vw_world_remap(w, map), VW_OK);
    commit(w, 1, "remap");
    if (P > 1) CHECK(w->fetched > 0); /* every cell moved, most to another process */

    /* A larger world box: the objects outside the old one join cells. */
    int map2[MAX_CELLS];
    for (int c = 0; c < 6; c++) map2[c] = (c * 5) % G;
    CHECK_EQ_INT(vw_world_redecompose(w, d2, map2), VW_OK);
    commit(w, 1, "redecompose");

    /* Copies of cells 0 and 3 on every other worker: those processes build them. */
    for (int c = 0; c < 6; c += 3) {
        int reps[MAX_UNITS], n = 0;
        for (int g = 0; g < G && n < MAX_UNITS - 1; g++)
            if (g != vw_world_cell_worker(w, c)) reps[n++] = g;
        CHECK_EQ_INT(vw_world_set_replicas(w, c, reps, n), VW_OK);
    }
    CHECK_EQ_INT(vw_world_commit(w), VW_OK);
    /* Every copy is new: each process built those it hosts. */
    for (int c = 0; c < 6; c += 3)
        for (int u = 1; u < MAX_UNITS; u++)
            if (hosts(w, c, u)) CHECK(atomic_load(&units[c][u].done));
    check_commit(w, 0, "copies");

    /* Moves: into another cell, out of the world, and (one moved out before) back in. */
    for (size_t i = 1; i < nobj; i += 7) {
        rec *o = &objs[i];
        if (i % 3 == 0)
            o->c[2] = 5.0; /* out of the world box: held by no cell, kept by its home */
        else
            o->c[0] = 1.0 - o->c[0];
        o->check = rec_check(o);
        CHECK_EQ_INT(vw_world_update_object(w, i, o), VW_OK);
    }
    moved = 1;
    commit(w, 1, "moves");
    for (size_t i = 1; i < nobj; i += 7)
        if (i % 3 == 0) {
            objs[i].c[2] = 0.5;
            objs[i].check = rec_check(&objs[i]);
        }
    /* Back in by a new decomposition alone would need the records of objects held by
       no cell: their homes have them. Here by update, then a redecomposition. */
    for (size_t i = 1; i < nobj; i += 7)
        if (i % 3 == 0) CHECK_EQ_INT(vw_world_update_object(w, i, &objs[i]), VW_OK);
    CHECK_EQ_INT(vw_world_redecompose(w, d1, NULL), VW_OK);
    commit(w, 1, "back to the first layout");
    CHECK_EQ_INT(vw_world_run(w), VW_OK);

    vw_world_free(w);
    vw_decomp_free(d1);
    vw_decomp_free(d2);
    free(objs);
    for (int c = 0; c < MAX_CELLS; c++)
        for (int u = 0; u < MAX_UNITS; u++) free(units[c][u].ids);
    if (vw_engine_rank() == 0) printf("test_mpi_records: %d processes, %d checks passed\n", P, vw_test_checks);
    vw_engine_finish();
    return 0;
}
