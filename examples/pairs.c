/* pairs.c - the example module: count pairs of touching spheres, distributed.
 *
 * Each sphere is owned by the cell holding its centre. A cell counts the touching
 * pairs among its own spheres, and sends each of its spheres as a *ghost* to every
 * other cell within reach (the sphere's box widened by the largest radius). A pair
 * split across cells is counted by the owner of the sphere with the smaller id when
 * the other one's ghost arrives, so every pair is counted exactly once.
 */
#include "pairs.h"

#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "sphere_bins.h"

enum { MSG_GHOST, NKINDS };                 /* message kinds; counters: pairs.h */

typedef struct pairs_params {
    double rmax;                            /* reach of a ghost */
} pairs_params;

typedef struct pairs_cell {
    ex_bins bins;                           /* the spheres this cell owns */
    int ghosts_sent;
} pairs_cell;

typedef struct near_count {
    const ex_bins *bins;
    const ex_sphere *q;
    int64_t n;
} near_count;

static void count_one(size_t j, void *arg)
{
    near_count *nc = arg;
    nc->n += nc->bins->own[j].id < nc->q->id;
}

/* Own spheres with a smaller id than q that touch q. Summed over all own spheres it
   counts each local pair once; for a ghost q it counts the pairs this cell owns. */
static int64_t count_near(const ex_bins *bins, const ex_sphere *q)
{
    near_count nc = {bins, q, 0};
    ex_bins_for_touching(bins, q, count_one, &nc);
    return nc.n;
}

static void sphere_bounds(const void *obj, vw_box *out, void *user)
{
    const ex_sphere *s = obj;
    (void)user;
    for (int k = 0; k < 3; k++) out->lo[k] = out->hi[k] = s->c[k]; /* placed by its centre */
}

static vw_status cell_build(vw_ctx *ctx, const void *objects, size_t n, void **state)
{
    const double rmax = ((const pairs_params *)vw_ctx_user(ctx))->rmax;
    pairs_cell *pc = calloc(1, sizeof *pc);
    if (!pc) return VW_E_NOMEM;
    if (ex_bins_build(&pc->bins, ctx, objects, n, rmax) != VW_OK) {
        free(pc);
        return VW_E_NOMEM;
    }
    *state = pc;
    return VW_OK;
}

static void cell_free(void *state, void *user)
{
    pairs_cell *pc = state;
    (void)user;
    if (pc) ex_bins_free(&pc->bins);
    free(pc);
}

/* First step: count local pairs and send the ghosts. Afterwards there is nothing to do. */
static int step(vw_ctx *ctx, void *state)
{
    pairs_cell *pc = state;
    if (pc->ghosts_sent) return 0;
    pc->ghosts_sent = 1;
    const pairs_params *pp = vw_ctx_user(ctx);
    int64_t local = 0;
    for (size_t i = 0; i < pc->bins.n; i++) local += count_near(&pc->bins, &pc->bins.own[i]);
    vw_count(ctx, EX_PAIRS_CNT_PAIRS, local);
    int *cells = malloc(sizeof(int) * (size_t)vw_decomp_cell_count(vw_ctx_decomp(ctx)));
    if (!cells) { /* fails the run: vw_world_run returns VW_E_NOMEM with this message */
        vw_ctx_fail(ctx, VW_E_NOMEM, "no memory for the cells a ghost reaches");
        return 0;
    }
    for (size_t i = 0; i < pc->bins.n; i++) {
        const ex_sphere *s = &pc->bins.own[i];
        int n = ex_reach_cells(vw_ctx_decomp(ctx), s, pp->rmax, cells,
                               vw_decomp_cell_count(vw_ctx_decomp(ctx)));
        for (int k = 0; k < n; k++) {
            if (cells[k] == vw_ctx_cell(ctx)) continue;
            VW_SEND_CELL(ctx, cells[k], MSG_GHOST, *s);
            vw_count(ctx, EX_PAIRS_CNT_GHOSTS, 1);
        }
    }
    free(cells);
    return 1;
}

static void on_ghost(vw_ctx *ctx, void *state, const void *msg)
{
    const pairs_cell *pc = state;
    vw_count(ctx, EX_PAIRS_CNT_PAIRS, count_near(&pc->bins, msg));
}

static const vw_msg_kind kinds[NKINDS] = {
    [MSG_GHOST] = {"ghost", sizeof(ex_sphere), on_ghost, NULL},
};
static const char *const counters[EX_PAIRS_NCOUNTERS] = {
    [EX_PAIRS_CNT_PAIRS] = "pairs",
    [EX_PAIRS_CNT_GHOSTS] = "ghosts",
};

static const vw_module pairs_module = {
    .abi = VW_MODULE_ABI,
    .name = "pairs",
    .object_size = sizeof(ex_sphere),
    .object_bounds = sphere_bounds,
    .kinds = kinds,
    .nkinds = NKINDS,
    .counters = counters,
    .ncounters = EX_PAIRS_NCOUNTERS,
    .cell_build = cell_build,
    .cell_free = cell_free,
    .step = step,
};

vw_status ex_pairs_count(const ex_sphere *s, size_t n, double rmax, const vw_decomp *d,
                         const vw_config *cfg, int64_t *pairs, vw_world **out_world)
{
    if (out_world) *out_world = NULL;
    vw_status st = ex__spheres_agree(s, n, rmax, d, 0, cfg);
    if (st != VW_OK) return st;
    /* The world keeps a pointer to params: a world handed back is for reading stats,
       not for running again. */
    pairs_params params = {rmax};
    vw_world *w;
    st = vw_world_create(&pairs_module, &params, d, cfg, &w);
    if (st != VW_OK) return ex__world_failed(st, NULL);
    struct timespec t[4];
    clock_gettime(CLOCK_MONOTONIC, &t[0]);
    st = vw_world_add_objects(w, s, n);          /* placement into cells */
    clock_gettime(CLOCK_MONOTONIC, &t[1]);
    if (st == VW_OK) st = vw_world_commit(w);    /* cell_build on every worker */
    clock_gettime(CLOCK_MONOTONIC, &t[2]);
    if (st == VW_OK) st = vw_world_run(w);       /* steps and ghosts until quiescence */
    clock_gettime(CLOCK_MONOTONIC, &t[3]);
    ex__world_failed(st, w);
    const char *phase[3] = {"place", "build", "compute"};
    for (int i = 0; i < 3; i++)
        vw_world_add_time(w, phase[i], (double)(t[i + 1].tv_sec - t[i].tv_sec) +
                                           1e-9 * (double)(t[i + 1].tv_nsec - t[i].tv_nsec));
    *pairs = vw_world_counter(w, EX_PAIRS_CNT_PAIRS);
    if (out_world)
        *out_world = w;
    else
        vw_world_free(w);
    return st;
}

/* ---- the sequential side: checks, scene and reference ---- */

/* ex_errmsg's message: one a thread, as the calls it explains may run in several. */
static _Thread_local char errmsg[512];

const char *ex_errmsg(void) { return errmsg[0] ? errmsg : "no error"; }

/* Agreed: a process out of memory for the check alone would leave the others waiting
   for it in vw_world_create. The reason is ex_spheres_check's, written straight into
   ex_errmsg's message: one text, wherever it is read. */
vw_status ex__spheres_agree(const ex_sphere *s, size_t n, double rmax, const vw_decomp *d,
                            int ids_are_indices, const vw_config *cfg)
{
    errmsg[0] = 0;
    vw_status st = ex_spheres_check(s, n, rmax, d, ids_are_indices, errmsg, sizeof errmsg);
    st = vw_config_agree(cfg, st, errmsg, sizeof errmsg);
    if (st == VW_OK) errmsg[0] = 0;
    return st;
}

vw_status ex__world_failed(vw_status st, const vw_world *w)
{
    if (st != VW_OK) snprintf(errmsg, sizeof errmsg, "%s", vw_world_errmsg(w));
    return st;
}

static int cmp_id(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

/* The smallest id that appears twice in s[0..n), in *dup; -1 when out of memory. A
   sorted copy of the ids: right for every id (a bitmap would need ids in 0..n-1), in
   8n bytes whatever they are. */
static int id_twice(const ex_sphere *s, size_t n, int64_t *dup)
{
    int64_t *ids = malloc(sizeof *ids * (n ? n : 1));
    if (!ids) return -1;
    for (size_t i = 0; i < n; i++) ids[i] = s[i].id;
    qsort(ids, n, sizeof *ids, cmp_id);
    int found = 0;
    for (size_t i = 1; i < n && !found; i++)
        if (ids[i] == ids[i - 1]) *dup = ids[i], found = 1;
    free(ids);
    return found;
}

vw_status ex_spheres_check(const ex_sphere *s, size_t n, double rmax, const vw_decomp *d,
                           int ids_are_indices, char *why, size_t len)
{
    char msg[256] = "";
    int64_t dup = 0;
    int twice = 0;
    if (!(rmax >= 0 && rmax <= DBL_MAX))
        snprintf(msg, sizeof msg, "largest radius %g: not a finite number >= 0", rmax);
    for (size_t i = 0; !*msg && i < n; i++) {
        const ex_sphere *e = &s[i];
        if (!(e->r >= 0 && e->r <= rmax))
            snprintf(msg, sizeof msg, "sphere %zu (id %lld): radius %g is not from 0 to the largest "
                     "radius %g", i, (long long)e->id, e->r, rmax);
        else if (vw_decomp_locate(d, e->c, NULL) < 0)
            snprintf(msg, sizeof msg, "sphere %zu (id %lld): centre (%g, %g, %g) is not in the world box",
                     i, (long long)e->id, e->c[0], e->c[1], e->c[2]);
        else if (ids_are_indices && !(e->id >= 0 && (uint64_t)e->id < n))
            snprintf(msg, sizeof msg, "sphere %zu: id %lld is not from 0 to %zu", i, (long long)e->id,
                     n - 1);
    }
    if (!*msg && n > 1 && (twice = id_twice(s, n, &dup)) < 0) {
        if (why && len) snprintf(why, len, "out of memory checking the ids of %zu spheres", n);
        return VW_E_NOMEM;
    }
    if (twice) snprintf(msg, sizeof msg, "id %lld is given to two spheres", (long long)dup);
    if (why && len) snprintf(why, len, "%s", msg);
    return *msg ? VW_E_INVAL : VW_OK;
}

static double uniform(uint64_t *x)
{
    uint64_t z = (*x += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return (double)((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
}

void ex_pairs_generate(ex_sphere *s, size_t n, double rmax, uint64_t seed)
{
    for (size_t i = 0; i < n; i++) {
        s[i].id = (int64_t)i;
        for (int k = 0; k < 3; k++) s[i].c[k] = uniform(&seed);
        s[i].r = rmax * (0.25 + 0.75 * uniform(&seed));
    }
}

int64_t ex_pairs_brute(const ex_sphere *s, size_t n)
{
    int64_t c = 0;
    for (size_t i = 0; i < n; i++)
        for (size_t j = i + 1; j < n; j++) c += ex_touching(&s[i], &s[j]);
    return c;
}
