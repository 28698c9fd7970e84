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

/* A cut of a block of cells[3] cells, ext[3] long a side, into d[0]*d[1]*d[2] parts:
   its flaws, worst first, parts left empty (more parts a side than cells) and sides
   the parts do not divide evenly; then its cost, the area of the walls it cuts (the
   neighbour traffic that leaves a part goes through them: a cut across x is a plane
   across the block, ext[1] * ext[2], whatever the cells), and the cell faces it cuts. */
typedef struct cut_score {
    int flaw; /* empty sides * 4 + uneven sides */
    double area, faces;
} cut_score;

static cut_score score_cut(const int cells[3], const double ext[3], const int d[3])
{
    cut_score s = {0, 0, 0};
    for (int x = 0; x < 3; x++) {
        int y = (x + 1) % 3, z = (x + 2) % 3;
        int cx = cells[x] > 0 ? cells[x] : 1;
        int cy = cells[y] > 0 ? cells[y] : 1, cz = cells[z] > 0 ? cells[z] : 1;
        s.flaw += d[x] > cx ? 4 : cx % d[x] != 0;
        s.area += (d[x] - 1) * ext[y] * ext[z];
        s.faces += (d[x] - 1) * (double)cy * cz;
    }
    return s;
}

/* The factorisation n = d[0]*d[1]*d[2] to cut a block of cells[3] cells, ext[3] long a
   side: of the least flawed (want 0), or of those whose largest block is want cells and
   smallest at least `least` (want > 0: evenness is then settled), the one cutting the
   least wall area; of areas within 5 % of the least, the fewest cell faces, then the
   first found. The 5 %: a world meant as a cube is its objects' bounds, a sphere's radius
   short here and there (1000 spheres in a 10-cube: 9.94 x 9.97 x 10.00), and there the
   camera, not the area, decided the traffic (4x2x1 cells on 2 workers: 1569 messages
   cut across x, 2411 cut across y, whose wall is 0.2 % smaller; the faces choose x).
   0 when no factorisation qualifies (dims untouched). */
static int pick_cut(int n, const int cells[3], const double ext[3], long want, long least,
                    int dims[3])
{
    int flaw = INT_MAX;
    double least_area = INFINITY, best_faces = INFINITY;
    for (int pass = 0; pass < 2; pass++)
        for (int a = 1; a <= n; a++) {
            if (n % a) continue;
            for (int b = 1; b <= n / a; b++) {
                if ((n / a) % b) continue;
                int d[3] = {a, b, n / a / b};
                if (want > 0 &&
                    (largest_block(cells, d) != want || smallest_block(cells, d) < least))
                    continue;
                cut_score s = score_cut(cells, ext, d);
                if (want > 0) s.flaw = 0;
                if (pass == 0) {
                    /* the least flaw, and the least area among cuts of that flaw */
                    if (s.flaw < flaw) flaw = s.flaw, least_area = INFINITY;
                    if (s.flaw == flaw && s.area < least_area) least_area = s.area;
                } else if (s.flaw == flaw && s.area <= least_area * 1.05 &&
                           s.faces < best_faces) {
                    best_faces = s.faces;
                    memcpy(dims, d, sizeof d);
                }
            }
        }
    return flaw < INT_MAX;
}

vw_status vw_map_dims(int n, const int cells[3], int dims[3])
{
    /* n < 1 gave {0, 1, 1}: a grid of no parts. */
    if (dims) dims[0] = dims[1] = dims[2] = 1;
    if (n < 1 || !cells || !dims) return VW_E_INVAL;
    /* No sizes: the cells are cubes of side 1, so the area a cut makes is the count of
       faces it cuts. */
    double ext[3];
    for (int a = 0; a < 3; a++) ext[a] = cells[a] > 0 ? cells[a] : 1;
    pick_cut(n, cells, ext, 0, 0, dims);
    return VW_OK;
}

/* The parts a side for n blocks of the cells, ext[3] long a side: of the factorisations
   whose largest block is the fewest cells n blocks can have (ceil(cells / n)) and whose
   smallest block has at least `least` cells, the one cutting the least wall area
   (vw_map_dims' choice, by the real sides, wherever that is as even). 0 when no
   factorisation is that even: a prime n over sides shorter than it, or uneven sides
   (8 cells 2x2x2 on 3 workers were 4, 4, 0; 3x3x3 on 4 were 12, 6, 6, 3); the caller
   cuts runs instead. `least` is what the next level needs: a process block with fewer
   cells than the process has workers leaves one of them without a cell (2x5x1 on 3
   processes of 3 workers were blocks of 4, 4 and 2 cells, and worker 8 had none where
   runs give every worker one or two). */
static int even_dims(int n, const int cells[3], const double ext[3], long least, int dims[3])
{
    long total = (long)cells[0] * cells[1] * cells[2];
    long want = (total + n - 1) / n;
    pick_cut(n, cells, ext, 0, 0, dims);
    if (largest_block(cells, dims) == want && smallest_block(cells, dims) >= least) return 1;
    return pick_cut(n, cells, ext, want, least, dims);
}

/* A grid's wall positions along each axis, the world's sides included: pos[a][i] is the
   lower wall of the cells of index i along a, pos[a][cells[a]] the world's upper side
   (frame coordinates, as the walls). The one allocation is returned for free(). */
static double *wall_positions(const vw_decomp *d, const int cells[3], double *pos[3])
{
    double *all = malloc(sizeof(double) * ((size_t)cells[0] + cells[1] + cells[2] + 3));
    if (!all) return NULL;
    vw_box wb = vw_decomp_world(d);
    double *p = all;
    for (int a = 0; a < 3; a++) {
        const double *w = vw_decomp_grid_walls(d, a);
        pos[a] = p;
        p[0] = wb.lo[a];
        for (int i = 1; i < cells[a]; i++) p[i] = w ? w[i - 1] : wb.lo[a];
        p[cells[a]] = wb.hi[a];
        p += cells[a] + 1;
    }
    return all;
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
    /* Cuts are scored by the wall area they cut, from the walls where they are now (a
       balancer's walls are mapped too). */
    double *pos[3], *all = wall_positions(d, cells, pos);
    if (!all) return VW_E_NOMEM;
    double ext[3];
    for (int a = 0; a < 3; a++) ext[a] = pos[a][cells[a]] - pos[a][0];
    if (!even_dims(nprocs, cells, ext, nc >= g ? wpp : 1, pd)) {
        for (int c = 0; c < nc; c++) {
            int ix[3] = {c % cells[0], (c / cells[0]) % cells[1], c / (cells[0] * cells[1])};
            cell_worker[c] = (int)(block_rank(ix, zero, cells) * g / nc);
        }
        free(all);
        return VW_OK;
    }
    /* Each process block's cut into worker blocks, found at its first cell (wd[0] 0:
       not yet; -1: none as even, runs): the cut is the same for every cell of the
       block, and was found again for each. */
    int *pwd = calloc((size_t)nprocs * 3, sizeof *pwd);
    if (!pwd) {
        free(all);
        return VW_E_NOMEM;
    }
    for (int c = 0; c < nc; c++) {
        int ix[3] = {c % cells[0], (c / cells[0]) % cells[1], c / (cells[0] * cells[1])};
        int pb[3], lo[3], hi[3], sub[3], wb[3];
        for (int a = 0; a < 3; a++) {
            /* The process block holding index ix[a], and that block's extent. */
            pb[a] = (int)((long)ix[a] * pd[a] / cells[a]);
            lo[a] = (int)(((long)pb[a] * cells[a] + pd[a] - 1) / pd[a]);
            hi[a] = (int)(((long)(pb[a] + 1) * cells[a] + pd[a] - 1) / pd[a]);
            sub[a] = hi[a] - lo[a];
            ext[a] = pos[a][hi[a]] - pos[a][lo[a]];
        }
        int proc = pb[0] + pd[0] * (pb[1] + pd[1] * pb[2]), local;
        int *wd = pwd + (size_t)proc * 3;
        if (!wd[0] && !even_dims(wpp, sub, ext, 1, wd)) wd[0] = -1;
        if (wd[0] > 0) {
            for (int a = 0; a < 3; a++)
                wb[a] = (int)((long)(ix[a] - lo[a]) * wd[a] / (sub[a] ? sub[a] : 1));
            local = wb[0] + wd[0] * (wb[1] + wd[1] * wb[2]);
        } else {
            long n = (long)sub[0] * sub[1] * sub[2];
            local = (int)(block_rank(ix, lo, sub) * wpp / n);
        }
        cell_worker[c] = proc * wpp + local;
    }
    free(pwd), free(all);
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
    /* An infinite load is a unit above every finite one: a worker's finish time is its
       count of infinite cells, then its finite load over its speed. Infinite cells (first
       in the sort) so go one to a worker before any gets a second, and finite ones to the
       workers with fewest infinite cells. As one sum, every worker's time was infinite
       once it had one, and neighbours, then the lowest id, chose: all four of a row of
       4x4 cells on worker 0 of 4. */
    int *ninf = calloc((size_t)gworkers, sizeof *ninf);
    if (!ninf) {
        free(order), free(t);
        return VW_E_NOMEM;
    }
    int nb[64];
    for (int i = 0; i < nc; i++) {
        int c = order[i].cell, inf = isinf(order[i].load);
        double l = inf ? 0.0 : order[i].load;
        int fewest = INT_MAX;
        for (int g = 0; g < gworkers; g++)
            if (ninf[g] < fewest) fewest = ninf[g];
        /* Longest processing time first: the worker that would finish this cell first. */
        double best = INFINITY;
        for (int g = 0; g < gworkers; g++) {
            double f = (t[g] + l) / (speeds ? speeds[g] / smax : 1.0);
            if (ninf[g] == fewest && f < best) best = f;
        }
        /* Among workers nearly as good, the one hosting most of the cell's neighbours. */
        int pick = -1, pick_nb = -1;
        double pick_f = INFINITY;
        for (int g = 0; g < gworkers; g++) {
            double f = (t[g] + l) / (speeds ? speeds[g] / smax : 1.0);
            if (ninf[g] != fewest || f > best * (1.0 + slack) + 1e-300) continue;
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
        ninf[pick] += inf;
    }
    free(order), free(t), free(ninf);
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
