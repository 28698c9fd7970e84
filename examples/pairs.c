/* pairs.c - the example module: count pairs of touching spheres, distributed.
 *
 * Each sphere is owned by the cell holding its centre. A cell counts the touching
 * pairs among its own spheres, and sends each of its spheres as a *ghost* to every
 * other cell within reach (the sphere's box widened by the largest radius). A pair
 * split across cells is counted by the owner of the sphere with the smaller id when
 * the other one's ghost arrives, so every pair is counted exactly once.
 */
#include "pairs.h"

#include <stdlib.h>
#include <time.h>

#include "sphere_bins.h"

enum { MSG_GHOST, NKINDS };                 /* message kinds */
enum { CNT_PAIRS, CNT_GHOSTS, NCOUNTERS };  /* counters */

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
    const double h = 2 * ((const pairs_params *)vw_ctx_user(ctx))->rmax;
    pairs_cell *pc = calloc(1, sizeof *pc);
    if (!pc) return VW_E_NOMEM;
    if (ex_bins_build(&pc->bins, ctx, objects, n, h) != VW_OK) {
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
    vw_count(ctx, CNT_PAIRS, local);
    int *cells = malloc(sizeof(int) * (size_t)vw_decomp_cell_count(vw_ctx_decomp(ctx)));
    if (!cells) abort();
    for (size_t i = 0; i < pc->bins.n; i++) {
        const ex_sphere *s = &pc->bins.own[i];
        vw_box reach;
        for (int k = 0; k < 3; k++) {
            reach.lo[k] = s->c[k] - s->r - pp->rmax;
            reach.hi[k] = s->c[k] + s->r + pp->rmax;
        }
        int n = vw_decomp_cells_overlapping(vw_ctx_decomp(ctx), &reach, 0, cells,
                                            vw_decomp_cell_count(vw_ctx_decomp(ctx)));
        for (int k = 0; k < n; k++) {
            if (cells[k] == vw_ctx_cell(ctx)) continue;
            vw_send_cell(ctx, cells[k], MSG_GHOST, s);
            vw_count(ctx, CNT_GHOSTS, 1);
        }
    }
    free(cells);
    return 1;
}

static void on_ghost(vw_ctx *ctx, void *state, const void *msg)
{
    const pairs_cell *pc = state;
    vw_count(ctx, CNT_PAIRS, count_near(&pc->bins, msg));
}

static const vw_msg_kind kinds[NKINDS] = {
    [MSG_GHOST] = {"ghost", sizeof(ex_sphere), on_ghost, NULL},
};
static const char *const counters[NCOUNTERS] = {"pairs", "ghosts"};

static const vw_module pairs_module = {
    .abi = VW_MODULE_ABI,
    .name = "pairs",
    .object_size = sizeof(ex_sphere),
    .object_bounds = sphere_bounds,
    .kinds = kinds,
    .nkinds = NKINDS,
    .counters = counters,
    .ncounters = NCOUNTERS,
    .cell_build = cell_build,
    .cell_free = cell_free,
    .step = step,
};

vw_status ex_pairs_count(const ex_sphere *s, size_t n, double rmax, const vw_decomp *d,
                         const vw_config *cfg, int64_t *pairs, vw_world **out_world)
{
    /* The world keeps a pointer to params: a world handed back is for reading stats,
       not for running again. */
    pairs_params params = {rmax};
    vw_world *w;
    vw_status st = vw_world_create(&pairs_module, &params, d, cfg, &w);
    if (st != VW_OK) return st;
    struct timespec t[4];
    clock_gettime(CLOCK_MONOTONIC, &t[0]);
    st = vw_world_add_objects(w, s, n);          /* placement into cells */
    clock_gettime(CLOCK_MONOTONIC, &t[1]);
    if (st == VW_OK) st = vw_world_commit(w);    /* cell_build on every worker */
    clock_gettime(CLOCK_MONOTONIC, &t[2]);
    if (st == VW_OK) st = vw_world_run(w);       /* steps and ghosts until quiescence */
    clock_gettime(CLOCK_MONOTONIC, &t[3]);
    const char *phase[3] = {"place", "build", "compute"};
    for (int i = 0; i < 3; i++)
        vw_world_add_time(w, phase[i], (double)(t[i + 1].tv_sec - t[i].tv_sec) +
                                           1e-9 * (double)(t[i + 1].tv_nsec - t[i].tv_nsec));
    *pairs = vw_world_counter(w, CNT_PAIRS);
    if (out_world)
        *out_world = w;
    else
        vw_world_free(w);
    return st;
}

/* ---- the sequential side: scene and reference ---- */

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
