/* map.c - the mapping of cells onto workers and processes: block (compact blocks of the
 * cell grid, so neighbour traffic stays inside a worker, then a process), greedy (over-
 * decomposition: longest processing time first, neighbours kept together where the
 * loads allow) and weighted (unequal workers get load in proportion to their speed).
 *
 * Every mapper maps each cell exactly once, to a worker in [0, gworkers); a global
 * worker is process * workers_per_process + local worker, as in vw_config.cell_worker.
 */
#include "core/world_internal.h"
#include "vwalls/map.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *vw_map_kind_name(vw_map_kind k)
{
    switch (k) {
    case VW_MAP_BLOCK: return "block";
    case VW_MAP_GREEDY: return "greedy";
    case VW_MAP_WEIGHTED: return "weighted";
    }
    return "unknown";
}

vw_status vw_map_kind_parse(const char *s, vw_map_kind *out)
{
    if (!s || !out) return VW_E_INVAL;
    for (int k = VW_MAP_BLOCK; k <= VW_MAP_WEIGHTED; k++)
        if (!strcmp(s, vw_map_kind_name((vw_map_kind)k))) {
            *out = (vw_map_kind)k;
            return VW_OK;
        }
    return VW_E_INVAL;
}

vw_status vw_map_parse_speeds(const char *s, double *speeds, int n)
{
    if (!s || !speeds || n < 1) return VW_E_INVAL;
    int k = 0;
    const char *q = s;
    while (*q) {
        /* Decimal notation only (strtod also read "0x2" as a speed of 2), and no white
           space or '+', as the command line's numbers. */
        char *end;
        double v = vw_strtod_decimal(q, &end, 0);
        if (end == q || !(v > 0) || !isfinite(v) || k >= n) return VW_E_INVAL;
        speeds[k++] = v;
        /* A comma must be followed by a number: "1,2," is a list cut short, not two
           speeds. */
        if (*end == ',' && end[1]) end++;
        else if (*end) return VW_E_INVAL;
        q = end;
    }
    return k == n ? VW_OK : VW_E_INVAL;
}

/* ---- block ------------------------------------------------------------------------------ */

void vw_map_dims(int n, const int cells[3], int dims[3])
{
    /* Every factorisation n = a*b*c is scored: parts larger than the cell count leave
       blocks empty (never, if avoidable), uneven blocks cost balance, and every cut
       costs the faces it crosses (the neighbour traffic that leaves a block). */
    double best = INFINITY;
    dims[0] = n, dims[1] = dims[2] = 1;
    for (int a = 1; a <= n; a++) {
        if (n % a) continue;
        for (int b = 1; b <= n / a; b++) {
            if ((n / a) % b) continue;
            int c = n / a / b, d[3] = {a, b, c};
            double score = 0;
            for (int x = 0; x < 3; x++) {
                int cx = cells[x] > 0 ? cells[x] : 1;
                if (d[x] > cx) score += 1e12;
                else if (cx % d[x]) score += 1e6;
                double faces = 1;
                for (int y = 0; y < 3; y++)
                    if (y != x) faces *= cells[y] > 0 ? cells[y] : 1;
                score += (d[x] - 1) * faces;
            }
            if (score < best) {
                best = score;
                memcpy(dims, d, sizeof d);
            }
        }
    }
}

/* Leaves of the kd-tree in depth-first order: neighbours in space are near in it. */
static void leaf_order(const vw_kd_node *nodes, int node, int *order, int *k)
{
    if (nodes[node].axis < 0) {
        order[(*k)++] = nodes[node].cell;
        return;
    }
    leaf_order(nodes, nodes[node].left, order, k);
    leaf_order(nodes, nodes[node].right, order, k);
}

/* The largest block when cells are cut into d[a] parts a side (the parts of a side differ
   by one cell at most), 0 when a side has more parts than cells (an empty block). */
static long largest_block(const int cells[3], const int d[3])
{
    long m = 1;
    for (int a = 0; a < 3; a++) {
        if (d[a] > cells[a]) return 0;
        m *= (cells[a] + d[a] - 1) / d[a];
    }
    return m;
}

/* The smallest block of the same cut (0 as above). */
static long smallest_block(const int cells[3], const int d[3])
{
    long m = 1;
    for (int a = 0; a < 3; a++) {
        if (d[a] > cells[a]) return 0;
        m *= cells[a] / d[a];
    }
    return m;
}

/* The parts a side for n blocks of the cells: of the factorisations whose largest block is
   the fewest cells n blocks can have (ceil(cells / n)) and whose smallest block has at
   least `least` cells, the one cutting fewest faces (vw_map_dims' choice wherever n
   divides the cells evenly). 0 when no factorisation is that even: a prime n over sides
   shorter than it, or uneven sides (8 cells 2x2x2 on 3 workers were 4, 4, 0; 3x3x3 on 4
   were 12, 6, 6, 3); the caller cuts runs instead. `least` is what the next level
   needs: a process block with fewer cells than the process has workers leaves one of
   them without a cell (2x5x1 on 3 processes of 3 workers were blocks of 4, 4 and 2
   cells, and worker 8 had none where runs give every worker one or two). */
static int even_dims(int n, const int cells[3], long least, int dims[3])
{
    long total = (long)cells[0] * cells[1] * cells[2];
    long want = (total + n - 1) / n;
    vw_map_dims(n, cells, dims);
    if (largest_block(cells, dims) == want && smallest_block(cells, dims) >= least) return 1;
    double best = INFINITY;
    for (int a = 1; a <= n; a++) {
        if (n % a) continue;
        for (int b = 1; b <= n / a; b++) {
            if ((n / a) % b) continue;
            int d[3] = {a, b, n / a / b};
            if (largest_block(cells, d) != want || smallest_block(cells, d) < least) continue;
            double score = 0;
            for (int x = 0; x < 3; x++)
                score += (d[x] - 1) * (double)cells[(x + 1) % 3] * cells[(x + 2) % 3];
            if (score < best) {
                best = score;
                memcpy(dims, d, sizeof d);
            }
        }
    }
    return best < INFINITY;
}

/* A cell's place in the leaf order of a grid's kd-tree (x slabs, in each y rows, in each
   z cells: vw_decomp_create_grid) inside the block [lo, lo + size) of the grid. */
static long block_rank(const int ix[3], const int lo[3], const int size[3])
{
    return ((long)(ix[0] - lo[0]) * size[1] + (ix[1] - lo[1])) * size[2] + (ix[2] - lo[2]);
}

vw_status vw_map_block(const vw_decomp *d, int nprocs, int wpp, int *cell_worker)
{
    if (!d || nprocs < 1 || wpp < 1 || !cell_worker) return VW_E_INVAL;
    int nc = vw_decomp_cell_count(d);
    long g = (long)nprocs * wpp;
    if (vw_decomp_get_kind(d) != VW_DECOMP_GRID) {
        int nn, k = 0;
        const vw_kd_node *nodes = vw_decomp_nodes(d, &nn);
        int *order = malloc(sizeof(int) * (size_t)nc);
        if (!order) return VW_E_NOMEM;
        leaf_order(nodes, 0, order, &k);
        for (int i = 0; i < nc; i++) cell_worker[order[i]] = (int)((long)i * g / nc);
        free(order);
        return VW_OK;
    }
    int cells[3], pd[3];
    vw_decomp_dims(d, cells);
    /* Blocks as even as runs would be, or runs: a block mapping that left workers empty
       and others with twice the mean was worse than the plain one, and a balancer whose
       walls it mapped was refused for it (tensor on 2x2x2 and 3 workers). Every process
       block holds a cell for each of its workers when the grid has enough. The runs are
       of the grid's leaf order, so each is a slab or part of one. */
    int zero[3] = {0, 0, 0};
    if (!even_dims(nprocs, cells, nc >= g ? wpp : 1, pd)) {
        for (int c = 0; c < nc; c++) {
            int ix[3] = {c % cells[0], (c / cells[0]) % cells[1], c / (cells[0] * cells[1])};
            cell_worker[c] = (int)(block_rank(ix, zero, cells) * g / nc);
        }
        return VW_OK;
    }
    for (int c = 0; c < nc; c++) {
        int ix[3] = {c % cells[0], (c / cells[0]) % cells[1], c / (cells[0] * cells[1])};
        int pb[3], lo[3], hi[3], sub[3], wd[3], wb[3];
        for (int a = 0; a < 3; a++) {
            /* The process block holding index ix[a], and that block's extent. */
            pb[a] = (int)((long)ix[a] * pd[a] / cells[a]);
            lo[a] = (int)(((long)pb[a] * cells[a] + pd[a] - 1) / pd[a]);
            hi[a] = (int)(((long)(pb[a] + 1) * cells[a] + pd[a] - 1) / pd[a]);
            sub[a] = hi[a] - lo[a];
        }
        int proc = pb[0] + pd[0] * (pb[1] + pd[1] * pb[2]), local;
        if (even_dims(wpp, sub, 1, wd)) {
            for (int a = 0; a < 3; a++)
                wb[a] = (int)((long)(ix[a] - lo[a]) * wd[a] / (sub[a] ? sub[a] : 1));
            local = wb[0] + wd[0] * (wb[1] + wd[1] * wb[2]);
        } else {
            long n = (long)sub[0] * sub[1] * sub[2];
            local = (int)(block_rank(ix, lo, sub) * wpp / n);
        }
        cell_worker[c] = proc * wpp + local;
    }
    return VW_OK;
}

/* ---- greedy and weighted ----------------------------------------------------------------- */

/* A cell and its load, sorted together: the comparator reads no file-static array,
   which two threads mapping at once overwrote in each other's sort (a wrong mapping in
   about one call of ten). */
typedef struct ranked_cell {
    double load;
    int cell;
} ranked_cell;

static int cmp_load_desc(const void *a, const void *b)
{
    const ranked_cell *x = a, *y = b;
    if (x->load != y->load) return x->load > y->load ? -1 : 1;
    return x->cell - y->cell; /* ties by id: every process computes the same mapping */
}

vw_status vw_map_greedy(const vw_decomp *d, const double *cell_load, int gworkers,
                        const double *speeds, double slack, int *cell_worker)
{
    if (!d || gworkers < 1 || !cell_worker || !(slack >= 0)) return VW_E_INVAL;
    /* A speed that is not positive (or a negative slack) left no worker within the
       slack of the best, and the cell went to worker -1, past the start of t. */
    /* Speeds are relative: taken as fractions of the fastest, the finish times below are
       of the loads' own size. Raw speeds of 1e308 made them about 1e-306, under the
       absolute slack 1e-300, so every worker was "near the best" and the neighbours
       alone placed the cells: seven of eight on one worker of two equal ones. */
    double smax = 0;
    for (int g = 0; speeds && g < gworkers; g++) {
        if (!(speeds[g] > 0) || !isfinite(speeds[g])) return VW_E_INVAL;
        smax = fmax(smax, speeds[g]);
    }
    int nc = vw_decomp_cell_count(d);
    ranked_cell *order = malloc(sizeof *order * (size_t)nc);
    double *t = calloc((size_t)gworkers, sizeof *t);
    if (!order || !t) {
        free(order), free(t);
        return VW_E_NOMEM;
    }
    /* Cells are placed and sorted by the same load: a load that is not a positive number
       (0, negative, NaN) counts as none. Sorted by the given loads, a NaN compared
       unordered with every other, qsort's order was no longer by load, and longest
       first was lost: 8x8 cells on 4 workers, with NaN for the loads of 13 cells, got
       up to 78 where the same loads with 0 for them get at most 76. And where no cell
       has a load (a pre-pass that counted nothing) the cells count alike, as with no
       loads (NULL): with no load to go by, every worker was as good as any and the
       neighbours alone placed the cells, all 64 on one worker of 4. */
    int loaded = 0;
    for (int c = 0; c < nc; c++) {
        double l = !cell_load ? 1.0 : cell_load[c] > 0 ? cell_load[c] : 0.0;
        order[c] = (ranked_cell){l, c};
        loaded |= l > 0;
        cell_worker[c] = -1;
    }
    for (int c = 0; !loaded && c < nc; c++) order[c].load = 1.0;
    qsort(order, (size_t)nc, sizeof *order, cmp_load_desc);
    int nb[64];
    for (int i = 0; i < nc; i++) {
        int c = order[i].cell;
        double l = order[i].load;
        /* Longest processing time first: the worker that would finish this cell first. */
        double best = INFINITY;
        for (int g = 0; g < gworkers; g++) {
            double f = (t[g] + l) / (speeds ? speeds[g] / smax : 1.0);
            if (f < best) best = f;
        }
        /* Among workers nearly as good, the one hosting most of the cell's neighbours. */
        int pick = -1, pick_nb = -1;
        double pick_f = INFINITY;
        for (int g = 0; g < gworkers; g++) {
            double f = (t[g] + l) / (speeds ? speeds[g] / smax : 1.0);
            if (f > best * (1.0 + slack) + 1e-300) continue;
            int cnt = 0;
            if (slack > 0)
                for (int face = 0; face < 6; face++) {
                    int n = vw_decomp_neighbours(d, c, face, nb, 64);
                    for (int k = 0; k < n && k < 64; k++) cnt += cell_worker[nb[k]] == g;
                }
            if (cnt > pick_nb || (cnt == pick_nb && f < pick_f)) {
                pick = g;
                pick_nb = cnt;
                pick_f = f;
            }
        }
        cell_worker[c] = pick;
        t[pick] += l;
    }
    free(order), free(t);
    return VW_OK;
}

vw_status vw_map_weighted(const vw_decomp *d, const double *cell_load, int gworkers,
                          const double *speeds, int *cell_worker)
{
    return vw_map_greedy(d, cell_load, gworkers, speeds, 0.02, cell_worker);
}

vw_status vw_map_compute(vw_map_kind kind, const vw_decomp *d, const double *cell_load,
                         int nprocs, int wpp, const double *speeds, int *cell_worker)
{
    /* nprocs * wpp is the worker count: it must be an int (a signed overflow before). */
    if (nprocs < 1 || wpp < 1 || nprocs > INT_MAX / wpp) return VW_E_INVAL;
    switch (kind) {
    case VW_MAP_BLOCK: return vw_map_block(d, nprocs, wpp, cell_worker);
    case VW_MAP_GREEDY: return vw_map_greedy(d, cell_load, nprocs * wpp, speeds, 0.05, cell_worker);
    case VW_MAP_WEIGHTED: return vw_map_weighted(d, cell_load, nprocs * wpp, speeds, cell_worker);
    }
    return VW_E_INVAL;
}

/* ---- applying a mapping --------------------------------------------------------------- */

vw_status vw_world_remap(vw_world *w, const int *cell_worker)
{
    if (!w) return VW_E_INVAL;
    vw__world_begin_step(w);
    /* Agreed like any step: a process given no mapping alone would otherwise leave the
       others waiting in their redecomposition's agreement. */
    if (!cell_worker)
        return vw__world_step_agreed(w, vw__world_error(w, VW_E_INVAL, "vw_world_remap: no "
                                                         "mapping (cell_worker is NULL)"),
                                     "vw_world_remap");
    int built = 0;
    for (int c = 0; c < w->ncells; c++) built |= w->cells[c].built;
    uint64_t before = w->migrated;
    vw_status st = vw_world_redecompose(w, w->decomp, cell_worker);
    /* Before anything was built no object has really been anywhere yet. */
    if (!built) w->migrated = before;
    return st;
}
