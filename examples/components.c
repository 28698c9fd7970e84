/* components.c - the second example module: connected components of touching spheres.
 *
 * Each sphere is owned by the cell holding its centre (as in pairs.c). A cell joins its
 * own touching spheres with union-find once, at build; those local components never
 * change again. Only their *labels* do: a label is the smallest sphere id known to be
 * connected, and it only ever goes down. A boundary sphere (one within reach of another
 * cell) is sent with its component's label to every cell in reach; a cell that finds
 * one of its spheres touching it lowers that component's label and, if it went down,
 * resends its own boundary spheres. Labels are bounded below, so the exchange stops by
 * itself, and the runtime's quiescence is the end of the algorithm: no convergence test.
 * A second run collects every sphere's label on the output process.
 */
#include "components.h"

#include <stdlib.h>
#include <time.h>

#include "sphere_bins.h"

enum { MSG_LABEL, MSG_REPORT, MSG_RESULT, NKINDS };   /* message kinds */

/* "Sphere s belongs to a component whose smallest known id is label." Carrying the whole
   sphere (not just its id) means the receiver needs no earlier ghost: messages may
   arrive in any order. */
typedef struct ex_label_msg {
    ex_sphere s;
    int64_t label;
} ex_label_msg;

typedef struct ex_result_msg {
    int64_t id, label;
} ex_result_msg;

typedef struct ex_params {
    double rmax;          /* reach of a boundary sphere beyond its own radius */
    int64_t *labels;      /* the result, written by the output handler */
    size_t n;
} ex_params;

typedef struct ex_cell {
    ex_bins bins;         /* the spheres this cell owns (sphere_bins.h) */
    size_t *parent;       /* union-find over own spheres, fully compressed after build */
    int64_t *label;       /* meaningful at roots: smallest id known to be connected */
    /* Boundary spheres grouped by root: bsph[bstart[r] .. bstart[r+1]) are the own
       spheres of root r that other cells can touch; dest[dstart[i] .. dstart[i+1]) are
       the other cells within reach of own sphere i. */
    size_t *bstart, *bsph, *dstart;
    int *dest;
    /* Roots whose label went down since their boundary spheres were last sent. Each
       root is on the stack at most once (dirty flag), so the stack needs nown slots. */
    unsigned char *dirty;
    size_t *stack, nstack;
    int started;
} ex_cell;

/* ---- union-find over the own spheres (built once) ---- */

static size_t find(size_t *parent, size_t i)
{
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
}

typedef struct ex_join {
    ex_cell *ec;
    size_t i;
} ex_join;

/* Sphere j touches sphere i: one component. */
static void join(size_t j, void *arg)
{
    const ex_join *jn = arg;
    size_t a = find(jn->ec->parent, jn->i), b = find(jn->ec->parent, j);
    if (a != b) jn->ec->parent[a > b ? a : b] = a < b ? a : b;
}

/* ---- the module ---- */

static void sphere_bounds(const void *obj, vw_box *out, void *user)
{
    const ex_sphere *s = obj;
    (void)user;
    for (int k = 0; k < 3; k++) out->lo[k] = out->hi[k] = s->c[k]; /* placed by its centre */
}

static void cell_free(void *state, void *user)
{
    ex_cell *ec = state;
    (void)user;
    if (!ec) return;
    ex_bins_free(&ec->bins);
    free(ec->parent), free(ec->label), free(ec->bstart);
    free(ec->bsph), free(ec->dstart), free(ec->dest), free(ec->dirty), free(ec->stack);
    free(ec);
}

/* Own spheres, local components, and who must hear about each boundary sphere. */
static vw_status cell_build(vw_ctx *ctx, const void *objects, size_t n, void **state)
{
    const ex_params *pp = vw_ctx_user(ctx);
    const vw_decomp *d = vw_ctx_decomp(ctx);
    const int self = vw_ctx_cell(ctx), ncells = vw_decomp_cell_count(d);
    const size_t m1 = n ? n : 1;
    ex_cell *ec = calloc(1, sizeof *ec);
    int *cells = malloc(sizeof(int) * (size_t)ncells);
    if (!ec || !cells || ex_bins_build(&ec->bins, ctx, objects, n, pp->rmax) != VW_OK) goto nomem;
    ec->parent = malloc(sizeof *ec->parent * m1);
    ec->label = malloc(sizeof *ec->label * m1);
    ec->bstart = calloc(m1 + 1, sizeof *ec->bstart);
    ec->bsph = malloc(sizeof *ec->bsph * m1);
    ec->dstart = calloc(m1 + 1, sizeof *ec->dstart);
    ec->dirty = calloc(m1, 1);
    ec->stack = malloc(sizeof *ec->stack * m1);
    if (!ec->parent || !ec->label || !ec->bstart || !ec->bsph ||
        !ec->dstart || !ec->dirty || !ec->stack)
        goto nomem;

    const ex_sphere *own = ec->bins.own;
    const size_t m = ec->bins.n;

    /* Local components. */
    for (size_t i = 0; i < m; i++) ec->parent[i] = i;
    for (size_t i = 0; i < m; i++) {
        ex_join jn = {ec, i};
        ex_bins_for_touching(&ec->bins, &own[i], join, &jn);
    }
    for (size_t i = 0; i < m; i++) ec->label[i] = INT64_MAX;
    int64_t local = 0;
    for (size_t i = 0; i < m; i++) {
        size_t r = ec->parent[i] = find(ec->parent, i);
        local += r == i;
        if (own[i].id < ec->label[r]) ec->label[r] = own[i].id;
    }
    vw_count(ctx, EX_COMPONENTS_CNT_LOCAL, local);

    /* Destinations of every own sphere: the other cells within its reach (its box
       widened by its radius and the largest radius: ex_reach_cells). Touching is
       symmetric and reach covers it, so a cell hears about every foreign sphere touching
       one of its own. */
    size_t ndest = 0, cap = 0;
    for (size_t i = 0; i < m; i++) {
        int nc = ex_reach_cells(d, &own[i], pp->rmax, cells, ncells);
        for (int k = 0; k < nc; k++) {
            if (cells[k] == self) continue;
            if (ndest == cap) {
                cap = cap ? 2 * cap : 64;
                int *grown = realloc(ec->dest, sizeof *grown * cap);
                if (!grown) goto nomem;
                ec->dest = grown;
            }
            ec->dest[ndest++] = cells[k];
        }
        ec->dstart[i + 1] = ndest;
        if (ec->dstart[i + 1] > ec->dstart[i]) ec->bstart[ec->parent[i] + 1]++;
    }
    /* Group the boundary spheres by root (a counting sort). The dirty stack is unused
       until the first step, so it holds the fill positions meanwhile. */
    for (size_t r = 0; r < m; r++) ec->bstart[r + 1] += ec->bstart[r];
    for (size_t r = 0; r < m; r++) ec->stack[r] = ec->bstart[r];
    for (size_t i = 0; i < m; i++)
        if (ec->dstart[i + 1] > ec->dstart[i]) ec->bsph[ec->stack[ec->parent[i]]++] = i;

    free(cells);
    *state = ec;
    return VW_OK;
nomem:
    free(cells);
    cell_free(ec, NULL);
    return VW_E_NOMEM;
}

static void mark_dirty(ex_cell *ec, size_t r)
{
    if (!ec->dirty[r]) ec->dirty[r] = 1, ec->stack[ec->nstack++] = r;
}

/* Sends the boundary spheres of every root whose label went down. The runtime calls step
   only when the worker's inbox is empty, so many label drops cost one resend. */
static int step(vw_ctx *ctx, void *state)
{
    ex_cell *ec = state;
    if (!ec->started) {     /* first call: every boundary sphere's initial label goes out */
        ec->started = 1;
        for (size_t r = 0; r < ec->bins.n; r++)
            if (ec->bstart[r + 1] > ec->bstart[r]) mark_dirty(ec, r);
    }
    if (!ec->nstack) return 0;
    while (ec->nstack) {
        size_t r = ec->stack[--ec->nstack];
        ec->dirty[r] = 0;
        for (size_t b = ec->bstart[r]; b < ec->bstart[r + 1]; b++) {
            size_t i = ec->bsph[b];
            ex_label_msg msg = {ec->bins.own[i], ec->label[r]};
            for (size_t k = ec->dstart[i]; k < ec->dstart[i + 1]; k++)
                VW_SEND_CELL(ctx, ec->dest[k], MSG_LABEL, msg);
            vw_count(ctx, EX_COMPONENTS_CNT_LABEL_MSGS, (int64_t)(ec->dstart[i + 1] - ec->dstart[i]));
        }
    }
    return 1;
}

typedef struct ex_lower {
    vw_ctx *ctx;
    ex_cell *ec;
    int64_t label;
} ex_lower;

static void lower(size_t j, void *arg)
{
    const ex_lower *lw = arg;
    ex_cell *ec = lw->ec;
    size_t r = ec->parent[j];
    if (lw->label < ec->label[r]) {
        ec->label[r] = lw->label;
        mark_dirty(ec, r);
        vw_count(lw->ctx, EX_COMPONENTS_CNT_RELABELS, 1);
    }
}

/* A foreign sphere and its label: every local component it touches takes the label if
   it is smaller. */
static void on_label(vw_ctx *ctx, void *state, const void *msg)
{
    const ex_label_msg *lm = msg;
    ex_lower lw = {ctx, state, lm->label};
    ex_bins_for_touching(&lw.ec->bins, &lm->s, lower, &lw);
}

/* Second run: labels are final; every cell reports its spheres to the output process. */
static void on_report(vw_ctx *ctx, void *state, const void *msg)
{
    const ex_cell *ec = state;
    (void)msg;
    for (size_t i = 0; i < ec->bins.n; i++) {
        ex_result_msg res = {ec->bins.own[i].id, ec->label[ec->parent[i]]};
        VW_SEND_OUTPUT(ctx, MSG_RESULT, res);
        if (res.label == res.id) vw_count(ctx, EX_COMPONENTS_CNT_COMPONENTS, 1);
    }
}

/* Runs on the output process, one call at a time. */
static void on_result(void *user, const void *msg)
{
    const ex_params *pp = user;
    const ex_result_msg *res = msg;
    if (pp->labels && res->id >= 0 && (size_t)res->id < pp->n) pp->labels[res->id] = res->label;
}

static const vw_msg_kind kinds[NKINDS] = {
    [MSG_LABEL] = {"label", sizeof(ex_label_msg), on_label, NULL},
    [MSG_REPORT] = {"report", sizeof(int), on_report, NULL},
    [MSG_RESULT] = {"result", sizeof(ex_result_msg), NULL, on_result},
};
static const char *const counters[EX_COMPONENTS_NCOUNTERS] = {
    [EX_COMPONENTS_CNT_COMPONENTS] = "components",
    [EX_COMPONENTS_CNT_LOCAL] = "local_components",
    [EX_COMPONENTS_CNT_LABEL_MSGS] = "label_messages",
    [EX_COMPONENTS_CNT_RELABELS] = "relabels",
};

static const vw_module components_module = {
    .abi = VW_MODULE_ABI,
    .name = "components",
    .object_size = sizeof(ex_sphere),
    .object_bounds = sphere_bounds,
    .kinds = kinds,
    .nkinds = NKINDS,
    .counters = counters,
    .ncounters = EX_COMPONENTS_NCOUNTERS,
    .cell_build = cell_build,
    .cell_free = cell_free,
    .step = step,
};

static double seconds_between(const struct timespec *a, const struct timespec *b)
{
    return (double)(b->tv_sec - a->tv_sec) + 1e-9 * (double)(b->tv_nsec - a->tv_nsec);
}

vw_status ex_components_label(const ex_sphere *s, size_t n, double rmax, const vw_decomp *d,
                              const vw_config *cfg, int64_t *labels, int64_t *ncomponents,
                              vw_world **out_world)
{
    if (out_world) *out_world = NULL;
    vw_status st = ex__spheres_agree(s, n, rmax, d, 1, cfg);
    if (st != VW_OK) return st;
    /* The world keeps a pointer to params: a world handed back is for reading stats,
       not for running again. */
    ex_params params = {rmax, labels, n};
    vw_world *w;
    st = vw_world_create(&components_module, &params, d, cfg, &w);
    if (st != VW_OK) return ex__world_failed(st, NULL);
    struct timespec t[5];
    clock_gettime(CLOCK_MONOTONIC, &t[0]);
    st = vw_world_add_objects(w, s, n);          /* placement into cells */
    clock_gettime(CLOCK_MONOTONIC, &t[1]);
    if (st == VW_OK) st = vw_world_commit(w);    /* local union-find in every cell */
    clock_gettime(CLOCK_MONOTONIC, &t[2]);
    if (st == VW_OK) st = vw_world_run(w);       /* labels travel until none goes down */
    clock_gettime(CLOCK_MONOTONIC, &t[3]);
    const int dummy = 0;
    for (int c = 0; st == VW_OK && c < vw_decomp_cell_count(d); c++)
        st = VW_WORLD_POST(w, c, MSG_REPORT, dummy);
    if (st == VW_OK) st = vw_world_run(w);       /* final labels to the output process */
    clock_gettime(CLOCK_MONOTONIC, &t[4]);
    ex__world_failed(st, w);
    const char *phase[4] = {"place", "build", "compute", "report"};
    for (int i = 0; i < 4; i++) vw_world_add_time(w, phase[i], seconds_between(&t[i], &t[i + 1]));
    *ncomponents = vw_world_counter(w, EX_COMPONENTS_CNT_COMPONENTS);
    if (out_world)
        *out_world = w;
    else
        vw_world_free(w);
    return st;
}

/* ---- the sequential reference ---- */

int64_t ex_components_reference(const ex_sphere *s, size_t n, int64_t *labels)
{
    size_t *parent = malloc(sizeof *parent * (n ? n : 1));
    if (!parent) return -1;
    for (size_t i = 0; i < n; i++) parent[i] = i;
    for (size_t i = 0; i < n; i++)
        for (size_t j = i + 1; j < n; j++)
            if (ex_touching(&s[i], &s[j])) {
                size_t a = find(parent, i), b = find(parent, j);
                if (a != b) parent[a > b ? a : b] = a < b ? a : b;
            }
    /* Linking the larger index under the smaller makes every root its component's
       smallest index, which is the smallest id when ids are indices. */
    int64_t ncomp = 0;
    for (size_t i = 0; i < n; i++) {
        size_t r = find(parent, i);
        labels[i] = s[r].id;
        ncomp += r == i;
    }
    free(parent);
    return ncomp;
}
