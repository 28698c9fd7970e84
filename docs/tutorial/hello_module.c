/* hello_module.c - the tutorial's module (docs/tutorial.md walks through it): points in a
 * box; each cell counts the points it owns, sends the count to its face neighbours, and
 * once it has heard from all of them reports both numbers to the output process.
 */
#include "hello_module.h"

#include <stdlib.h>

/* [kinds] Message kinds and counters are indices into the tables below. */
enum { MSG_COUNT, MSG_SUMMARY, NKINDS };

typedef struct ex_count_msg {     /* cell -> face neighbour */
    int64_t points;
} ex_count_msg;

typedef struct ex_summary_msg {   /* cell -> output process */
    int cell;
    int64_t own, neighbours;
} ex_summary_msg;
/* [kinds] */

/* [state] A cell's local state: built once, touched only by the worker hosting the cell. */
typedef struct ex_cell {
    int64_t own;              /* points whose owner is this cell */
    int64_t neighbours;       /* sum of the counts heard so far */
    int expected, heard;      /* face neighbours, and how many have told us */
    int started, reported;
} ex_cell;
/* [state] */

/* [bounds] An object is placed into every cell its box overlaps. A point has a box of
   size zero, so a point lying exactly on a wall lands in the cells on both sides. */
static void point_bounds(const void *object, vw_box *out, void *user)
{
    const ex_point *pt = object;
    (void)user;
    for (int k = 0; k < 3; k++) out->lo[k] = out->hi[k] = pt->p[k];
}
/* [bounds] */

/* [build] Runs once per cell at commit. Counting must count every point once, so a cell
   keeps only the points it *owns*: vw_decomp_locate with a direction decides a point on
   a wall (here: the + side). */
static vw_status cell_build(vw_ctx *ctx, const void *objects, size_t n, void **state)
{
    ex_cell *c = calloc(1, sizeof *c);
    if (!c) return VW_E_NOMEM;
    const vw_decomp *d = vw_ctx_decomp(ctx);
    const ex_point *pts = objects;
    static const double plus[3] = {1, 1, 1};
    for (size_t i = 0; i < n; i++) c->own += vw_decomp_locate(d, pts[i].p, plus) == vw_ctx_cell(ctx);
    for (int face = 0; face < 6; face++)   /* max 0: only the number of neighbours */
        c->expected += vw_decomp_neighbours(d, vw_ctx_cell(ctx), face, NULL, 0);
    *state = c;
    return VW_OK;
}

static void cell_free(void *state, void *user)
{
    (void)user;
    free(state);
}
/* [build] */

/* [step] Local work that needs no message. Return 1 when it did something: the runtime
   calls it again until it returns 0, and again after the cell receives messages.
   Both step and on_count may find the cell complete: when all neighbours' counts
   arrive before the cell's own step runs, on_count reports, then step would again.
   The `reported` flag makes the summary go out once. */
static void report_if_complete(vw_ctx *ctx, ex_cell *c)
{
    if (c->reported || c->heard < c->expected) return;
    c->reported = 1;
    ex_summary_msg s = {vw_ctx_cell(ctx), c->own, c->neighbours};
    VW_SEND_OUTPUT(ctx, MSG_SUMMARY, s);                 /* checks sizeof s: module.h */
}

static int step(vw_ctx *ctx, void *state)
{
    ex_cell *c = state;
    if (c->started) return 0;
    c->started = 1;
    vw_count(ctx, EX_HELLO_CNT_POINTS, c->own);
    ex_count_msg m = {c->own};
    int sent = VW_SEND_NEIGHBOURS(ctx, MSG_COUNT, m);    /* copied: m may go out of scope */
    vw_count(ctx, EX_HELLO_CNT_MESSAGES, sent);
    report_if_complete(ctx, c);                          /* a cell with no neighbours */
    return 1;
}
/* [step] */

/* [handlers] A handler runs on the worker hosting the destination cell, with that
   cell's state; it may send messages itself. */
static void on_count(vw_ctx *ctx, void *state, const void *msg)
{
    ex_cell *c = state;
    const ex_count_msg *m = msg;
    c->neighbours += m->points;
    c->heard++;
    report_if_complete(ctx, c);
}

/* An output handler runs on the output process (rank 0), one call at a time, with the
   user pointer given to vw_world_create: no locking needed. */
static void on_summary(void *user, const void *msg)
{
    ex_hello_result *r = user;
    const ex_summary_msg *s = msg;
    r->own[s->cell] = s->own;
    r->neighbours[s->cell] = s->neighbours;
    r->summaries++;
}
/* [handlers] */

/* [module] The module: a table of callbacks, registered by passing it to vw_world_create. */
static const vw_msg_kind kinds[NKINDS] = {
    [MSG_COUNT] = {"count", sizeof(ex_count_msg), on_count, NULL},
    [MSG_SUMMARY] = {"summary", sizeof(ex_summary_msg), NULL, on_summary},
};
static const char *const counters[EX_HELLO_NCOUNTERS] = {
    [EX_HELLO_CNT_POINTS] = "points",
    [EX_HELLO_CNT_MESSAGES] = "count_messages",
};

const vw_module ex_hello_module = {
    .abi = VW_MODULE_ABI,
    .name = "hello",
    .object_size = sizeof(ex_point),
    .object_bounds = point_bounds,
    .kinds = kinds,
    .nkinds = NKINDS,
    .counters = counters,
    .ncounters = EX_HELLO_NCOUNTERS,
    .cell_build = cell_build,
    .cell_free = cell_free,
    .step = step,
};
/* [module] */
