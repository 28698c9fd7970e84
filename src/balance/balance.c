/* balance.c - the balancer's front: strategy names, dispatch to the tensor, rotation,
 * staggered and division balancers, and applying a new decomposition and mapping to a
 * world between runs (with the "does it pay" test and the stats it records).
 */
#include "balance/balance_internal.h"
#include "core/world_internal.h"
#include "vwalls/map.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const names[] = {"none", "tensor", "rotate", "staggered", "divide", "duplicate"};

const char *vw_balance_strategy_name(vw_balance_strategy s)
{
    return (unsigned)s < sizeof names / sizeof *names ? names[s] : "unknown";
}

vw_status vw_balance_strategy_parse(const char *s, vw_balance_strategy *out)
{
    if (!s || !out) return VW_E_INVAL;
    for (unsigned i = 0; i < sizeof names / sizeof *names; i++)
        if (!strcmp(s, names[i])) {
            *out = (vw_balance_strategy)i;
            return VW_OK;
        }
    return VW_E_INVAL;
}

void vw_balance_params_init(vw_balance_params *p)
{
    memset(p, 0, sizeof *p);
    p->min_width = 1e-3;
    p->tolerance = 0.03;
}

/* What is wrong with p, as a message, or NULL. The caller's mistakes, told apart from a
   balancer that cannot move walls (cells a few doubles wide: it keeps them, no error). */
static const char *params_problem(const vw_balance_params *p, char *buf, size_t len)
{
    if ((unsigned)p->strategy >= sizeof names / sizeof *names)
        snprintf(buf, len, "unknown strategy %d", (int)p->strategy);
    else if (!(p->min_width >= 0 && p->min_width < 1))
        snprintf(buf, len, "min_width %g: must be a fraction of the world extent, from 0 to "
                 "below 1", p->min_width);
    else if (p->dims[0] < 0 || p->dims[1] < 0 || p->dims[2] < 0)
        snprintf(buf, len, "dims %dx%dx%d: must be positive (or all 0: the current layout's)",
                 p->dims[0], p->dims[1], p->dims[2]);
    else
        return NULL;
    return buf;
}

/* The pieces of the subtree at `node` cut along `axis`: the subtrees below its splits on
   that axis. */
static int pieces_along(const vw_kd_node *nodes, int node, int axis)
{
    if (nodes[node].axis != axis) return 1;
    return pieces_along(nodes, nodes[node].left, axis) +
           pieces_along(nodes, nodes[node].right, axis);
}

/* A staggered decomposition's slabs, columns a slab and cells a column, read back from its
   tree (the first slab's and column's: staggered.c cuts them all alike). vw_decomp_dims
   gives any kd-tree but a grid as {cells, 1, 1}, and the next round of a 4x4x4 staggered
   balance made 64 slabs of it. */
static void staggered_dims(const vw_decomp *d, int dims[3])
{
    int nn, node = 0;
    const vw_kd_node *nodes = vw_decomp_nodes(d, &nn);
    for (int a = 0; a < 3; a++) {
        dims[a] = pieces_along(nodes, node, a);
        while (nodes[node].axis == a) node = nodes[node].left;
    }
}

vw_status vw_balance_decompose(const vw_decomp *current, const vw_load_field *f,
                               const vw_balance_params *p, vw_decomp **out, int *cell_worker)
{
    if (!out) return VW_E_INVAL;
    *out = NULL;
    char why[160];
    if (!current || !f || !p || params_problem(p, why, sizeof why)) return VW_E_INVAL;
    int dims[3];
    if (p->dims[0] > 0 || p->dims[1] > 0 || p->dims[2] > 0)
        for (int a = 0; a < 3; a++) dims[a] = p->dims[a] > 0 ? p->dims[a] : 1;
    else if (vw_decomp_get_kind(current) == VW_DECOMP_STAGGERED)
        staggered_dims(current, dims);
    else
        vw_decomp_dims(current, dims);
    switch (p->strategy) {
    case VW_BALANCE_NONE:
    case VW_BALANCE_DUPLICATE: /* duplication keeps the walls (see vw_balance_world) */
        return vw_decomp_clone(current, out);
    case VW_BALANCE_TENSOR: return vw__balance_tensor(current, f, p, dims, out);
    case VW_BALANCE_ROTATE: return vw__balance_rotate(current, f, p, dims, out);
    case VW_BALANCE_STAGGERED: return vw__balance_staggered(current, f, p, dims, out);
    case VW_BALANCE_DIVIDE: return vw__balance_divide(current, f, p, out, cell_worker);
    }
    return VW_E_INVAL;
}

/* lambda of per-cell loads on the world's current mapping, each duplicated cell's load
   shared by its master and copies as the runtime shares its work (equally, or by the
   world's worker speeds). */
static double units_lambda(const vw_world *w, const double *load, const double *speeds)
{
    double *t = calloc((size_t)w->gworkers, sizeof *t);
    if (!t) return 0;
    for (int c = 0; c < w->ncells; c++) {
        const vw__cell *cl = &w->cells[c];
        t[cl->worker] += load[c] * vw__unit_share(cl, 0);
        for (int r = 0; r < cl->nreps; r++) t[cl->reps[r].worker] += load[c] * vw__unit_share(cl, r + 1);
    }
    /* The one definition (vw__lambda): max / mean of load / speed read an idle slow
       worker's 0 into the mean, so 'before' was 2 where vw_balance_imbalance, and so
       every 'predicted' compared with it, said 1.001 (speeds 1,1000). */
    double lam = vw__lambda(t, speeds, w->gworkers);
    free(t);
    return lam;
}

/* Duplication: the walls stay, overloaded cells get copies on underloaded workers (the
   plan replaces any copies from an earlier round). Objects that move are the
   duplicated cells' objects a receiving worker did not hold yet. */
static vw_status balance_duplicate(vw_world *w, const double *load, const vw_balance_params *p,
                                   const vw_balance_apply *a, vw_balance_report *r)
{
    /* Copies are the only lever here (the walls and the masters stay), and many cells
       on few workers need about one a cell: 64 cells of a sphere's load on 4 workers,
       block-mapped, need 34 copies for lambda 1.03, and 4 * gworkers (16) stopped at
       1.50. So at least one a cell, up to 1024 (a round of the planner costs cells +
       copies x workers: 0.3 s for 1024 copies of 32768 cells on 64 workers). */
    int max_extra = p->max_extra > 0 ? p->max_extra : 4 * w->gworkers;
    int per_cell = w->ncells < 1024 ? w->ncells : 1024;
    if (p->max_extra <= 0 && max_extra < per_cell) max_extra = per_cell;
    size_t nextra = sizeof(int) * (size_t)max_extra;
    int *pc = vw_test_fault("balance-copies-nomem") ? NULL : malloc(nextra), *pw = malloc(nextra);
    int *list = malloc(sizeof(int) * (size_t)w->gworkers);
    int np = 0;
    vw_status st = pc && pw && list ? VW_OK : VW_E_NOMEM;
    int independent = 0;
    for (int k = 0; k < w->m->nkinds; k++) independent |= (w->m->kinds[k].flags & VW_MSG_INDEPENDENT) != 0;
    r->imbalance_before = units_lambda(w, load, p->speeds);
    r->imbalance_predicted = r->imbalance_before;
    r->cells = w->ncells;
    r->max_neighbours = vw_decomp_max_neighbours(w->decomp);
    if (st == VW_OK && independent)
        st = vw__balance_duplicate_plan(load, w->cell_worker, w->ncells, w->gworkers, p->speeds,
                                        p->tolerance, max_extra, pc, pw, &np,
                                        &r->imbalance_predicted);
    int pays = st == VW_OK && independent && r->imbalance_predicted < r->imbalance_before;
    if (pays && a && a->last_compute_s > 0)
        pays = (1.0 - r->imbalance_predicted / r->imbalance_before) * a->last_compute_s > a->rebuild_s;
    if (!pays) r->imbalance_predicted = r->imbalance_before;
    /* (object, worker) pairs held before, to count what the copies move. */
    size_t gw = (size_t)w->gworkers;
    unsigned char *held = pays ? calloc(w->nobjects ? w->nobjects * gw : 1, 1) : NULL;
    if (pays && !held) st = VW_E_NOMEM;
    /* The plan is each process's own (from the same loads: only memory can differ), and
       the copies are collective: all fail, or none waits for one in them. */
    st = vw__world_step_agreed(w, st, "vw_balance_world");
    for (int c = 0; pays && st == VW_OK && c < w->ncells; c++) {
        const vw__cell *cl = &w->cells[c];
        for (int u = 0; u <= cl->nreps; u++) {
            size_t g = (size_t)(u ? cl->reps[u - 1].worker : cl->worker);
            for (size_t i = 0; i < cl->nobjs; i++) held[cl->objs[i] * gw + g] = 1;
        }
    }
    for (int c = 0; pays && st == VW_OK && c < w->ncells; c++) {
        int n = 0;
        for (int i = 0; i < np; i++)
            if (pc[i] == c) list[n++] = pw[i];
        if (n == 0 && w->cells[c].nreps == 0) continue;
        st = vw_world_set_replicas(w, c, list, n);
        const vw__cell *cl = &w->cells[c];
        for (int k = 0; st == VW_OK && k < n; k++)
            for (size_t i = 0; i < cl->nobjs; i++) {
                unsigned char *h = &held[cl->objs[i] * gw + (size_t)list[k]];
                if (!*h) r->migrated_objects++;
                *h = 1;
            }
        r->duplicates += n;
    }
    free(held);
    r->bytes_moved = r->migrated_objects * (uint64_t)w->m->object_size;
    r->applied = pays && st == VW_OK;
    free(pc), free(pw), free(list);
    return st;
}

/* Tensor, rotate and staggered cut cells of equal load, which balances the workers only
   when each gets as many cells (at equal speeds). Where the mapping *nd got (map) puts
   unequal numbers on them (3 cells on 2 workers: 2 and 1; 4 on 3; a block mapping of 8
   on 6), or their speeds differ, lambda stayed at the busiest worker's cells over the
   mean (4/3 for 3 cells on 2 workers, 3/2 for 4 on 3) whatever the load. So the layout is
   also cut with each cell's share of the load its worker's (its speed, by the number of
   cells it holds) and mapped the same way; it replaces *nd (with its loads, mapping and
   *lam) when its predicted lambda is lower. In a rotated frame the walls are cut again
   in that frame. Kinds other than a grid or a staggered tree (tensor keeping a layout it
   cannot cut) are left as they are. */
static vw_status shaped(vw_world *w, const vw_load_field *f, const vw_balance_params *p,
                        vw_map_kind mk, const double *speeds, vw_decomp **nd, double *load,
                        int *map, double *lam)
{
    vw_decomp_kind kind = vw_decomp_get_kind(*nd);
    int want = p->strategy == VW_BALANCE_STAGGERED ? VW_DECOMP_STAGGERED : VW_DECOMP_GRID;
    if ((int)kind != want) return VW_OK;
    int dims[3];
    if (kind == VW_DECOMP_STAGGERED)
        staggered_dims(*nd, dims);
    else
        vw_decomp_dims(*nd, dims);
    int nc = vw_decomp_cell_count(*nd), gw = w->gworkers;
    if ((long)dims[0] * dims[1] * dims[2] != nc || nc < 2) return VW_OK;
    int *held = calloc((size_t)gw, sizeof *held);
    double *share = malloc(sizeof(double) * (size_t)nc);
    double *load2 = malloc(sizeof(double) * VW_MAX_CELLS);
    int *map2 = malloc(sizeof(int) * VW_MAX_CELLS);
    vw_decomp *d2 = NULL;
    vw_status st = held && share && load2 && map2 ? VW_OK : VW_E_NOMEM;
    int equal = 1;
    for (int c = 0; st == VW_OK && c < nc; c++)
        if (map[c] >= 0 && map[c] < gw) held[map[c]]++;
    for (int c = 0; st == VW_OK && c < nc; c++) {
        int g = map[c] >= 0 && map[c] < gw ? map[c] : 0;
        share[c] = (speeds ? speeds[g] : 1.0) / (held[g] > 0 ? held[g] : 1);
        equal &= share[c] == share[0];
    }
    if (st == VW_OK && !equal) st = vw__balance_shaped(*nd, f, p, dims, kind, share, &d2);
    if (st == VW_OK && d2) {
        vw_load_field_cell_loads(f, d2, load2);
        st = vw_map_compute(mk, d2, load2, w->nprocs, w->nworkers, speeds, map2);
        double lam2 = st == VW_OK ? vw_balance_imbalance(load2, map2, nc, gw, speeds) : 0;
        if (st == VW_OK && lam2 < *lam - 1e-9) {
            vw_decomp_free(*nd);
            *nd = d2;
            d2 = NULL;
            memcpy(load, load2, sizeof(double) * (size_t)nc);
            memcpy(map, map2, sizeof(int) * (size_t)nc);
            *lam = lam2;
        }
    }
    vw_decomp_free(d2);
    free(held), free(share), free(load2), free(map2);
    return st;
}

vw_status vw_balance_world(vw_world *w, const vw_load_field *f, const vw_balance_params *p,
                           const vw_balance_apply *a, vw_balance_report *rep)
{
    if (!w) return VW_E_INVAL;
    vw__world_begin_step(w);
    /* The caller's mistakes are refused on every process alike (they all pass the same
       arguments), before anything is planned. */
    char why[160];
    if (rep) memset(rep, 0, sizeof *rep);
    if (!f || !p)
        return vw__world_error(w, VW_E_INVAL, "vw_balance_world: no %s (NULL)",
                               !f ? "load field" : "parameters");
    if (params_problem(p, why, sizeof why))
        return vw__world_error(w, VW_E_INVAL, "vw_balance_world: %s", why);
    double t0 = vw__now();
    vw_balance_report r;
    memset(&r, 0, sizeof r);
    r.strategy = p->strategy;
    vw_balance_params pp = *p;
    if (pp.gworkers <= 0) pp.gworkers = w->gworkers;
    const double *speeds = a && a->speeds ? a->speeds : p->speeds;
    pp.speeds = speeds;
    /* A worker of speed 0 (or less, or NaN) would get no load, or all of it; its lambda
       is no number to decide by. Refused, as the world refuses such worker_speeds. */
    for (int g = 0; speeds && g < w->gworkers; g++)
        if (!(speeds[g] > 0) || !isfinite(speeds[g])) {
            if (rep) *rep = r;
            return vw__world_error(w, VW_E_INVAL, "vw_balance_world: worker %d has speed %g: "
                                   "speeds must be positive and finite", g, speeds[g]);
        }

    /* Before: the field's loads on the current layout and mapping (the field was made
       from, or calibrated by, the last measurement, so these are the measured loads). */
    double *load =
        vw_test_fault("balance-plan-nomem") ? NULL : malloc(sizeof(double) * VW_MAX_CELLS);
    int *map = malloc(sizeof(int) * VW_MAX_CELLS);
    vw_decomp *nd = NULL;
    vw_status st = load && map ? VW_OK : VW_E_NOMEM;
    if (st == VW_OK) {
        vw_load_field_cell_loads(f, w->decomp, load);
        /* With duplicated cells, their copies carry their share (units_lambda). */
        r.imbalance_before = units_lambda(w, load, speeds);
    }
    if (p->strategy == VW_BALANCE_DUPLICATE) {
        /* One agreement on every process: balance_duplicate's, or, without memory for
           the loads, this one. */
        st = st == VW_OK ? balance_duplicate(w, load, &pp, a, &r)
                         : vw__world_step_agreed(w, st, "vw_balance_world");
        goto done;
    }
    if (st == VW_OK) st = vw_balance_decompose(w->decomp, f, &pp, &nd, map);
    int nc = nd ? vw_decomp_cell_count(nd) : 0, pays = 0;
    if (st == VW_OK) {
        vw_load_field_cell_loads(f, nd, load);
        if (p->strategy != VW_BALANCE_DIVIDE) {
            vw_map_kind mk = a ? (vw_map_kind)a->map : VW_MAP_BLOCK;
            st = vw_map_compute(mk, nd, load, w->nprocs, w->nworkers, speeds, map);
        }
    }
    double lam = st == VW_OK ? vw_balance_imbalance(load, map, nc, w->gworkers, speeds) : 0;
    if (st == VW_OK && p->strategy != VW_BALANCE_DIVIDE) {
        vw_map_kind mk = a ? (vw_map_kind)a->map : VW_MAP_BLOCK;
        st = shaped(w, f, &pp, mk, speeds, &nd, load, map, &lam);
    }
    if (st == VW_OK) {
        r.imbalance_predicted = lam;
        r.cells = nc;
        r.max_neighbours = vw_decomp_max_neighbours(nd);
        /* Does it pay? The expected gain is the part of the last compute time the
           better balance saves; the cost is what re-placing and rebuilding took. */
        pays = r.imbalance_predicted < r.imbalance_before;
        if (pays && a && a->last_compute_s > 0) {
            double gain = (1.0 - r.imbalance_predicted / r.imbalance_before) * a->last_compute_s;
            pays = gain > a->rebuild_s;
        }
        if (!pays) r.imbalance_predicted = r.imbalance_before;
    }
    /* Each process plans alone, from the same field, so only memory can make the plans
       differ: all fail, or none waits for one in the redecomposition. */
    st = vw__world_step_agreed(w, st, "vw_balance_world");
    if (st == VW_OK && pays) {
        uint64_t before = w->migrated;
        st = vw_world_redecompose(w, nd, map);
        r.migrated_objects = w->migrated - before;
        r.bytes_moved = r.migrated_objects * (uint64_t)w->m->object_size;
        r.applied = st == VW_OK;
    }
done:
    vw_decomp_free(nd);
    free(load);
    free(map);
    r.seconds = vw__now() - t0;
    if (st == VW_OK) {
        vw_world_set_balance_info(w, vw_balance_strategy_name(p->strategy), r.imbalance_before,
                                  r.imbalance_predicted, r.migrated_objects);
        vw_world_add_time(w, "balance", r.seconds);
    }
    if (rep) *rep = r;
    return st;
}
