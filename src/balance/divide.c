/* divide.c - cell division: an overloaded cell is split (extra kd-tree splits below its
 * leaf) and the pieces go to underloaded workers. The walls of the rest of the
 * decomposition stay where they are, so only the divided cell's objects move.
 *
 * Loop: map the cells onto the workers longest-processing-time first; while the
 * predicted imbalance exceeds the tolerance, split the heaviest cell in two at the
 * median of its load along its longest side (or, where that side is too few doubles
 * wide to hold a wall or its cut would leave all the load on one side, the next longest
 * that is not). A cell that cannot be cut on any side (every side too few doubles wide)
 * is marked and passed over for the next heaviest: the other cells' pieces can still
 * fill the other workers. Bounded by max_extra extra cells over a run of divides, each on
 * the last one's cells, not per call (divide_limit); ends early when no cell can be
 * cut, and when an uncuttable cell alone sets lambda on a fastest worker (no cut can
 * lower lambda then: see divide_stops).
 */
#include "balance/balance_internal.h"
#include "decomp/decomp_internal.h"
#include "vwalls/map.h"

#include <stdlib.h>
#include <string.h>

/* The side on which cell `cell` of d is cut and the wall (*split), or -1 when no side of
   it can be cut (none has a double inside it). pts: the field's npts points in world
   coordinates; tmp room for them (the cell's, in the frame F, are gathered there). */
static int cut_side(const vw_decomp *d, int cell, const vw__lpt *pts, long npts, vw__lpt *tmp,
                    const double *F, const vw_box *wb, double min_width, double *split)
{
    vw_box b = vw_decomp_cell_box(d, cell);
    long m = 0;
    for (long i = 0; i < npts; i++)
        if (vw_decomp_locate(d, pts[i].x, NULL) == cell) {
            tmp[m] = pts[i];
            if (F)
                for (int a = 0; a < 3; a++)
                    tmp[m].x[a] = F[3 * a] * pts[i].x[0] + F[3 * a + 1] * pts[i].x[1] +
                                  F[3 * a + 2] * pts[i].x[2];
            m++;
        }
    /* Its sides longest first (of equal ones the lower axis). A side with no double
       inside it (a cell far from the origin for its size) cannot be cut, and the next
       longest is tried: the sphere of radius 1 at x = 1e16 has cells a few doubles
       wide on x, the longest side in world units, and normal on y and z. A cut that
       leaves all the cell's load on one side (its load lies on one coordinate there:
       a line or plane of load, or a side a few doubles wide) moves nothing; the next
       side whose cut divides the load is taken instead, and only when none does the
       longest that can be cut, as before. */
    int order[3] = {0, 1, 2};
    for (int i = 1; i < 3; i++)
        for (int j = i; j > 0; j--) {
            int u = order[j - 1], v = order[j];
            if (!(b.hi[v] - b.lo[v] > b.hi[u] - b.lo[u])) break;
            order[j - 1] = v, order[j] = u;
        }
    int axis = -1, first = -1;
    double first_split = 0;
    for (int i = 0; i < 3 && axis < 0; i++) {
        int a = order[i];
        double s;
        if (!vw__cut(tmp, m, a, b.lo[a], b.hi[a], 2, min_width * (wb->hi[a] - wb->lo[a]), &s))
            continue;
        if (first < 0) first = a, first_split = s;
        /* Some of the cell's load below the wall and some above (a point on the wall
           is above it, as vw_decomp_locate has it)? */
        int below = 0, above = 0;
        for (long k = 0; k < m && !(below && above); k++) {
            if (tmp[k].x[a] < s)
                below = 1;
            else
                above = 1;
        }
        if (below && above) axis = a, *split = s;
    }
    if (axis < 0) axis = first, *split = first_split;
    return axis;
}

/* Whether no cut can lower lambda any more: some worker's time (its load over its speed
   as a fraction of the fastest, as vw_map_greedy and vw__lambda take it) t_max, the
   largest, equals the load of a cell that cannot be cut. Wherever any mapping puts
   that cell, its worker takes at least its load over that worker's speed, so at least
   its load (speeds are at most 1 as fractions); the total load does not change with
   cuts, so neither can lambda. It is not enough that the most loaded worker holds only
   an uncuttable cell: with unequal speeds it may sit on a slower worker, and pieces of
   other cells can let the mapper give it a faster one (speeds 2 and 1, a cell 12 that
   can be cut and 10 that cannot: 12 | 10 is 20 on the slow worker, 10 + 6 | 6 is 16).
   Only cells whose load is at least t_max are candidates: t_max >= a cell's load over
   its worker's speed >= its load, with equality only for a cell alone (but for cells
   without load) on a fastest worker that sets lambda. A candidate not yet tried is
   tried (cut_side) and marked when it cannot be cut; *known / *kaxis / *ksplit hand a
   candidate found cuttable on to the caller, so the cut is not sought twice (it is the
   heaviest cell, the one cut next). A cell whose load lies on one point but whose sides
   hold doubles counts as cuttable, as in the loop: its pieces may share the load at the
   next measurement, and after a few cuts it is a few doubles wide and uncuttable. */
static int divide_stops(const vw_decomp *d, const double *load, const int *map, int nc, int gw,
                        const double *speeds, unsigned char *uncut, const vw__lpt *pts,
                        long npts, vw__lpt *tmp, const double *F, const vw_box *wb,
                        double min_width, int *known, int *kaxis, double *ksplit)
{
    double *t = calloc((size_t)gw, sizeof *t), smax = 0, tmax = 0;
    if (!t) return 0; /* the bound is an economy: without it, cut on as before */
    for (int c = 0; c < nc; c++)
        if (map[c] >= 0 && map[c] < gw && load[c] > 0) t[map[c]] += load[c];
    for (int g = 0; speeds && g < gw; g++) smax = speeds[g] > smax ? speeds[g] : smax;
    for (int g = 0; g < gw; g++) {
        double x = t[g] / (speeds ? speeds[g] / smax : 1.0);
        tmax = x > tmax ? x : tmax;
    }
    free(t);
    for (int c = 0; c < nc && tmax > 0; c++) {
        if (!(load[c] >= tmax)) continue;
        if (!uncut[c] && *known != c) {
            double s;
            int a = cut_side(d, c, pts, npts, tmp, F, wb, min_width, &s);
            if (a < 0)
                uncut[c] = 1;
            else if (*known < 0)
                *known = c, *kaxis = a, *ksplit = s;
        }
        if (uncut[c]) return 1;
    }
    return 0;
}

/* How many cells divide may leave in all, given cur's nc cells on gw workers and
   max_extra extra cells. The bound holds over a run of divides, each on the last one's
   result (the ray tracer's rounds, animate's rebalances between frames), not per call:
   divide never merges cells, and a per-call max_extra let the cells pile up round after
   round (the clustered scene at 4x4x4 on 64 workers, render's five rounds: 1026 cells
   for a budget of 256 extra). A decomposition divide has not made (a grid, a staggered
   one) is where a run starts: max_extra more. A divided one (the kind divide returns)
   may already hold extra cells, and which of them are extra the tree does not tell:
   it may grow to gworkers + max_extra cells, and one that holds that many or more
   gets none. So a run that starts from n cells never holds more than max(n, gworkers) +
   max_extra (n + max_extra where n >= gworkers, the grid of every worker a cell or
   more). VW_MAX_CELLS caps it all. */
static int divide_limit(const vw_decomp *cur, int nc, int gw, int max_extra)
{
    long long lim = (long long)nc + max_extra;
    if (vw_decomp_get_kind(cur) == VW_DECOMP_DIVIDED) {
        lim = (long long)gw + max_extra;
        if (lim < nc) lim = nc;
    }
    return lim > VW_MAX_CELLS ? (nc > VW_MAX_CELLS ? nc : VW_MAX_CELLS) : (int)lim;
}

vw_status vw__balance_divide(const vw_decomp *cur, const vw_load_field *f,
                             const vw_balance_params *p, vw_decomp **out, int *cell_worker)
{
    int nn0;
    const vw_kd_node *n0 = vw_decomp_nodes(cur, &nn0);
    int nc = vw_decomp_cell_count(cur);
    int gw = p->gworkers > 0 ? p->gworkers : nc;
    int max_extra = p->max_extra > 0 ? p->max_extra : 4 * gw;
    /* The cells there may be at the end (divide_limit): a fresh decomposition gets
       max_extra more; a divided one, as divide returns it, no more than gworkers +
       max_extra in all. */
    int limit = divide_limit(cur, nc, gw, max_extra);
    int cap_nodes = nn0 + 2 * (limit - nc), cap_cells = limit;
    vw_kd_node *nodes = malloc(sizeof *nodes * (size_t)cap_nodes);
    double *load = calloc((size_t)cap_cells, sizeof *load);
    int *map = malloc(sizeof(int) * (size_t)cap_cells);
    /* Cells found uncuttable (no side with a double inside). A cut changes only the cell
       cut (its box and points), so the mark holds for the other cells to the end. */
    unsigned char *uncut = calloc((size_t)cap_cells, 1);
    vw__lpt *pts = NULL;
    long npts = vw__field_points(f, NULL, &pts); /* world coordinates */
    vw__lpt *tmp = malloc(sizeof *tmp * (size_t)(npts > 0 ? npts : 1));
    vw_decomp *d = NULL;
    vw_status st = (!nodes || !load || !map || !uncut || npts < 0 || !tmp) ? VW_E_NOMEM : VW_OK;
    if (st == VW_OK) {
        memcpy(nodes, n0, sizeof *nodes * (size_t)nn0);
        st = vw_decomp_clone(cur, &d);
    }
    int nn = nn0;
    const double *F = vw_decomp_frame(cur);
    vw_box wb = vw_decomp_world(cur);
    while (st == VW_OK) {
        vw_load_field_cell_loads(f, d, load);
        st = vw_map_greedy(d, load, gw, p->speeds, 0.0, map);
        if (st != VW_OK) break;
        double lam = vw_balance_imbalance(load, map, nc, gw, p->speeds);
        if (lam <= 1.0 + p->tolerance || nc >= limit) break;
        /* An uncuttable cell alone on a fastest worker sets lambda: cuts would spend cells
           up to the limit for nothing (they did, lambda unchanged). */
        int known = -1, kaxis = -1;
        double ksplit = 0;
        if (divide_stops(d, load, map, nc, gw, p->speeds, uncut, pts, npts, tmp, F, &wb,
                         p->min_width, &known, &kaxis, &ksplit))
            break;
        /* The heaviest cell not marked uncuttable; one that proves uncuttable is marked
           and the next heaviest tried: stopping there left the other cells as they
           were, though their pieces could still fill the other workers. Each cell is
           marked at most once, so this costs at most one more gathering of points per
           cell. A cell without load is not cut: its pieces change no worker's share. */
        int heavy = -1, axis = -1;
        double split = 0;
        for (;;) {
            heavy = -1;
            for (int c = 0; c < nc; c++)
                if (!uncut[c] && (heavy < 0 || load[c] > load[heavy])) heavy = c;
            if (heavy >= 0 && !(load[heavy] > 0)) heavy = -1;
            if (heavy < 0) break;
            if (heavy == known)
                axis = kaxis, split = ksplit;
            else
                axis = cut_side(d, heavy, pts, npts, tmp, F, &wb, p->min_width, &split);
            if (axis >= 0) break;
            uncut[heavy] = 1;
        }
        if (heavy < 0) break; /* no loaded cell can be cut: each too thin on every side */
        /* The leaf becomes a wall with the old cell on its low side, a new cell above. */
        nn = vw__kd_divide(nodes, nn, heavy, axis, split, nc);
        nc++;
        vw_decomp *nd;
        st = vw_decomp_create_kd(&wb, nodes, nn, F, VW_DECOMP_DIVIDED, &nd);
        if (st != VW_OK) break;
        vw_decomp_free(d);
        d = nd;
    }
    if (st == VW_OK && cell_worker) memcpy(cell_worker, map, sizeof(int) * (size_t)nc);
    if (st == VW_OK)
        *out = d;
    else
        vw_decomp_free(d);
    free(nodes), free(load), free(map), free(uncut), free(pts), free(tmp);
    return st;
}
