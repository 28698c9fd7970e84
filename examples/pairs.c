/* pairs.c - the example module: count pairs of touching spheres, distributed.
 *
 * Each sphere is owned by the cell holding its centre. A cell counts the touching
 * pairs among its own spheres, and sends each of its spheres as a *ghost* to every
 * other cell within reach (the sphere's box widened by the largest radius). A pair
 * split across cells is counted by the owner of the sphere with the smaller id when
 * the other one's ghost arrives, so every pair is counted exactly once.
 */
#include "pairs.h"

#include <math.h>
#include <stdlib.h>
#include <time.h>

enum { MSG_GHOST, NKINDS };                 /* message kinds */
enum { CNT_PAIRS, CNT_GHOSTS, NCOUNTERS };  /* counters */

typedef struct pairs_params {
    double rmax;                            /* reach of a ghost */
} pairs_params;

typedef struct pairs_cell {
    ex_sphere *own;                         /* spheres whose centre lies in this cell, */
    uint64_t *key;                          /* sorted by bin key */
    size_t nown;
    int ghosts_sent;
} pairs_cell;

static int touching(const ex_sphere *a, const ex_sphere *b)
{
    double d2 = 0;
    for (int k = 0; k < 3; k++) d2 += (a->c[k] - b->c[k]) * (a->c[k] - b->c[k]);
    return d2 <= (a->r + b->r) * (a->r + b->r);
}

/* Spheres are binned on a grid of spacing h = 2*rmax (two touching spheres lie in
   adjacent bins) and sorted by bin key, z fastest: the 3 bins (x+dx, y+dy, z-1..z+1)
   are one run of the sorted array. Work per query is O(log n), whatever the layout. */
static uint64_t bin_key(const double c[3], double h, int dx, int dy, int dz)
{
    uint64_t k = 0;
    for (int a = 0; a < 3; a++) {
        int64_t i = (int64_t)floor(c[a] / h) + 1 + (a == 0 ? dx : a == 1 ? dy : dz);
        k = (k << 21) | (uint64_t)(i < 0 ? 0 : i);
    }
    return k;
}

static size_t lower_bound(const pairs_cell *pc, uint64_t key)
{
    size_t lo = 0, hi = pc->nown;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (pc->key[mid] < key) lo = mid + 1; else hi = mid;
    }
    return lo;
}

/* Own spheres with a smaller id than q that touch q. Summed over all own spheres it
   counts each local pair once; for a ghost q it counts the pairs this cell owns. */
static int64_t count_near(const pairs_cell *pc, const ex_sphere *q, double h)
{
    int64_t n = 0;
    for (int dx = -1; dx <= 1; dx++)
        for (int dy = -1; dy <= 1; dy++) {
            uint64_t last = bin_key(q->c, h, dx, dy, 1);
            for (size_t j = lower_bound(pc, bin_key(q->c, h, dx, dy, -1));
                 j < pc->nown && pc->key[j] <= last; j++)
                n += pc->own[j].id < q->id && touching(&pc->own[j], q);
        }
    return n;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
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
    uint64_t (*tmp)[2] = malloc(sizeof *tmp * (n ? n : 1)); /* (key, index) to sort */
    if (pc) pc->own = malloc(sizeof(ex_sphere) * (n ? n : 1));
    if (pc) pc->key = malloc(sizeof(uint64_t) * (n ? n : 1));
    if (!pc || !pc->own || !pc->key || !tmp) {
        if (pc) free(pc->own), free(pc->key);
        free(pc), free(tmp);
        return VW_E_NOMEM;
    }
    const ex_sphere *s = objects;
    static const double dir[3] = {1, 1, 1};     /* a centre on a wall goes to the + side */
    size_t m = 0;
    for (size_t i = 0; i < n; i++)             /* near a wall, a centre lands in two cells */
        if (vw_decomp_locate(vw_ctx_decomp(ctx), s[i].c, dir) == vw_ctx_cell(ctx))
            tmp[m][0] = bin_key(s[i].c, h, 0, 0, 0), tmp[m++][1] = i;
    qsort(tmp, m, sizeof *tmp, cmp_u64);
    for (size_t i = 0; i < m; i++) pc->key[i] = tmp[i][0], pc->own[i] = s[tmp[i][1]];
    pc->nown = m;
    free(tmp);
    *state = pc;
    return VW_OK;
}

static void cell_free(void *state, void *user)
{
    pairs_cell *pc = state;
    (void)user;
    if (pc) free(pc->own), free(pc->key);
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
    for (size_t i = 0; i < pc->nown; i++) local += count_near(pc, &pc->own[i], 2 * pp->rmax);
    vw_count(ctx, CNT_PAIRS, local);
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
    const pairs_params *pp = vw_ctx_user(ctx);
    vw_count(ctx, CNT_PAIRS, count_near(pc, g, 2 * pp->rmax));
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
        for (size_t j = i + 1; j < n; j++) c += touching(&s[i], &s[j]);
    return c;
}
