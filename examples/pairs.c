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

enum { MSG_GHOST, NKINDS };                 /* message kinds */
enum { CNT_PAIRS, CNT_GHOSTS, NCOUNTERS };  /* counters */

typedef struct pairs_params {
    double rmax;                            /* reach of a ghost */
} pairs_params;

typedef struct pairs_cell {
    ex_sphere *own;                         /* spheres whose centre lies in this cell */
    size_t nown;
    int ghosts_sent;
} pairs_cell;

static int touching(const ex_sphere *a, const ex_sphere *b)
{
    double d2 = 0;
    for (int k = 0; k < 3; k++) d2 += (a->c[k] - b->c[k]) * (a->c[k] - b->c[k]);
    return d2 <= (a->r + b->r) * (a->r + b->r);
}

static void sphere_bounds(const void *obj, vw_box *out, void *user)
{
    const ex_sphere *s = obj;
    (void)user;
    for (int k = 0; k < 3; k++) out->lo[k] = out->hi[k] = s->c[k]; /* placed by its centre */
}

static vw_status cell_build(vw_ctx *ctx, const void *objects, size_t n, void **state)
{
    pairs_cell *pc = calloc(1, sizeof *pc);
    if (!pc || !(pc->own = malloc(sizeof(ex_sphere) * (n ? n : 1)))) {
        free(pc);
        return VW_E_NOMEM;
    }
    const ex_sphere *s = objects;
    static const double dir[3] = {1, 1, 1};     /* a centre on a wall goes to the + side */
    for (size_t i = 0; i < n; i++)             /* near a wall, a centre lands in two cells */
        if (vw_decomp_locate(vw_ctx_decomp(ctx), s[i].c, dir) == vw_ctx_cell(ctx))
            pc->own[pc->nown++] = s[i];
    *state = pc;
    return VW_OK;
}

static void cell_free(void *state, void *user)
{
    pairs_cell *pc = state;
    (void)user;
    if (pc) free(pc->own);
    free(pc);
}

/* First step: count local pairs and send the ghosts. Afterwards there is nothing to do. */
static int step(vw_ctx *ctx, void *state)
{
    pairs_cell *pc = state;
    if (pc->ghosts_sent) return 0;
    pc->ghosts_sent = 1;
    int64_t local = 0;
    for (size_t i = 0; i < pc->nown; i++)
        for (size_t j = i + 1; j < pc->nown; j++) local += touching(&pc->own[i], &pc->own[j]);
    vw_count(ctx, CNT_PAIRS, local);
    const pairs_params *pp = vw_ctx_user(ctx);
    int *cells = malloc(sizeof(int) * (size_t)vw_decomp_cell_count(vw_ctx_decomp(ctx)));
    if (!cells) abort();
    for (size_t i = 0; i < pc->nown; i++) {
        const ex_sphere *s = &pc->own[i];
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
    const ex_sphere *g = msg;
    int64_t n = 0;
    for (size_t i = 0; i < pc->nown; i++)
        n += pc->own[i].id < g->id && touching(&pc->own[i], g);
    vw_count(ctx, CNT_PAIRS, n);
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
    st = vw_world_add_objects(w, s, n);
    if (st == VW_OK) st = vw_world_run(w);
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
        for (size_t j = i + 1; j < n; j++) c += touching(&s[i], &s[j]);
    return c;
}
