/* divide_stop.c - divide stops when an uncuttable cell alone sets lambda (registered in
 * tests/balance.cmake as balance_divide_stop).
 *
 * World [1, 2]^3 on 2x2x2 cells with each axis's wall one double past 1 (as in
 * bal_test's divide_hot): the corner cell at (1, 1, 1) is one double wide on every side,
 * so no wall fits in it, and it holds a point of load `hot`. `bulk` is spread on an
 * 8x8x8 grid of points in the cell [w, 2]^3, `line` on a line along x in the cell one
 * double wide on y and z. When the hot cell alone is the work of a fastest worker and
 * that worker's time is the largest, no cut can lower lambda: wherever the mapping puts
 * the hot cell, its worker takes at least that long, and the total does not change.
 * Divide went on cutting the bulk up to max_extra all the same (40 cells for 8, lambda
 * unchanged). It must still cut where the hot cell sits on a slower worker (pieces of
 * the bulk let the mapper give it the fast one) and where the hot cell's worker holds
 * more than it (pieces let the mapper move the rest off).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../vw_test.h"
#include "vwalls/vwalls.h"

typedef struct outcome {
    int cells;    /* cells of the result */
    double lam;   /* lambda by speed of the mapping divide made */
    int whole;    /* the hot cell is the uncuttable corner, unchanged */
} outcome;

static outcome divide_run(int gw, const double *speeds, int max_extra, double hot, double line,
                          double bulk)
{
    const double w = nextafter(1.0, 2.0);
    vw_box world = {{1, 1, 1}, {2, 2, 2}};
    int dims[3] = {2, 2, 2};
    const double *walls[3] = {&w, &w, &w};
    vw_decomp *d;
    CHECK(vw_decomp_create_grid_walls(&world, dims, walls, NULL, &d) == VW_OK);
    vw_load_field *f;
    CHECK(vw_load_field_create(&f) == VW_OK);
    /* The points (kept to check that each is in a cell of the result). */
    static double pt[1 + 16 + 512][3];
    int n = 0;
    const double hp[3] = {1, 1, 1};
    CHECK(vw_load_field_add_point(f, hp, hot) == VW_OK);
    memcpy(pt[n++], hp, sizeof hp);
    for (int i = 0; line > 0 && i < 16; i++) {
        const double q[3] = {1.1 + 0.05 * i, 1, 1};
        CHECK(vw_load_field_add_point(f, q, line / 16) == VW_OK);
        memcpy(pt[n++], q, sizeof q);
    }
    for (int i = 0; bulk > 0 && i < 512; i++) {
        const double q[3] = {1.1 + 0.1 * (i % 8), 1.1 + 0.1 * (i / 8 % 8), 1.1 + 0.1 * (i / 64)};
        CHECK(vw_load_field_add_point(f, q, bulk / 512) == VW_OK);
        memcpy(pt[n++], q, sizeof q);
    }
    int hc0 = vw_decomp_locate(d, hp, NULL);
    CHECK(hc0 >= 0);
    vw_box hb = vw_decomp_cell_box(d, hc0);
    CHECK(hb.hi[0] == w && hb.hi[1] == w && hb.hi[2] == w);

    double *loads = malloc(sizeof(double) * VW_MAX_CELLS);
    int *map = malloc(sizeof(int) * VW_MAX_CELLS);
    CHECK(loads && map);
    vw_balance_params p;
    vw_balance_params_init(&p);
    p.strategy = VW_BALANCE_DIVIDE;
    p.gworkers = gw;
    p.speeds = speeds;
    p.max_extra = max_extra;
    vw_decomp *nd = NULL;
    CHECK(vw_balance_decompose(d, f, &p, &nd, map) == VW_OK && nd);
    outcome o = {vw_decomp_cell_count(nd), 0, 1};
    vw_load_field_cell_loads(f, nd, loads);
    o.lam = vw_balance_imbalance(loads, map, o.cells, gw, speeds);
    int hc = vw_decomp_locate(nd, hp, NULL);
    CHECK(hc >= 0);
    vw_box b = vw_decomp_cell_box(nd, hc);
    for (int a = 0; a < 3; a++) o.whole &= b.lo[a] == hb.lo[a] && b.hi[a] == hb.hi[a];
    int lost = 0;
    for (int i = 0; i < n; i++) lost += vw_decomp_locate(nd, pt[i], NULL) < 0;
    CHECK(lost == 0);
    vw_decomp_free(nd);
    vw_decomp_free(d);
    vw_load_field_free(f);
    free(loads);
    free(map);
    return o;
}

int main(void)
{
    outcome o;
    /* Equal speeds, 2 workers: the hot cell 10 on one, the bulk 4 on the other, lambda
       10 / 7 = 1.429 whatever is cut. Divide cut the bulk 32 times (40 cells). */
    o = divide_run(2, NULL, 32, 10, 0, 4);
    printf("divide_stop: 2 workers, hot 10, bulk 4: %d cells, lambda %.4f\n", o.cells, o.lam);
    EXPECT(o.cells == 8 && fabs(o.lam - 10.0 / 7) < 1e-12 && o.whole,
           "hot alone sets lambda: %d cells (want 8), lambda %.6f (want %.6f), hot whole %d",
           o.cells, o.lam, 10.0 / 7, o.whole);
    /* The same with max_extra 0 (4 * gworkers): 16 cells before. */
    o = divide_run(2, NULL, 0, 10, 0, 4);
    printf("divide_stop: 2 workers, default max_extra: %d cells, lambda %.4f\n", o.cells, o.lam);
    EXPECT(o.cells == 8 && fabs(o.lam - 10.0 / 7) < 1e-12,
           "default max_extra: %d cells (want 8), lambda %.6f", o.cells, o.lam);

    /* Speeds 1 and 2: the hot cell on the fast worker (10 / 1), the bulk on the slow one
       (4 / 0.5 = 8), lambda 10 / (14 / 1.5) = 1.071. No cut can lower it: 8 cells (40
       before). */
    static const double slow_fast[2] = {1, 2};
    o = divide_run(2, slow_fast, 32, 10, 0, 4);
    printf("divide_stop: speeds 1,2, hot 10 on the fast worker, bulk 4: %d cells, lambda %.4f\n",
           o.cells, o.lam);
    EXPECT(o.cells == 8 && fabs(o.lam - 10 / (14 / 1.5)) < 1e-12 && o.whole,
           "speeds 1,2: %d cells (want 8), lambda %.6f (want %.6f)", o.cells, o.lam,
           10 / (14 / 1.5));

    /* Speeds 2 and 1, bulk 12: the bulk goes to the fast worker first, the hot cell to
       the slow one, 10 / 0.5 = 20, lambda 20 / (22 / 1.5) = 1.364: the most loaded worker
       holds only the hot cell, yet halving the bulk lets the mapper put the hot cell on
       the fast worker (10 + 6 | 6 / 0.5: 16). Divide must go on. */
    static const double fast_slow[2] = {2, 1};
    o = divide_run(2, fast_slow, 32, 10, 0, 12);
    printf("divide_stop: speeds 2,1, hot 10 on the slow worker, bulk 12: %d cells, lambda %.4f\n",
           o.cells, o.lam);
    EXPECT(o.cells > 8 && o.lam <= 1.10 && o.whole,
           "speeds 2,1: %d cells, lambda %.4f (want <= 1.10, was 1.364 on 8 cells)", o.cells,
           o.lam);

    /* Equal speeds, hot 10, bulk 10, line 5: the line joins the hot cell (a tie, the lower
       worker), 15 | 10, lambda 1.2. That worker holds more than the uncuttable cell:
       pieces of the bulk and the line let the rest move off. Divide must go on. */
    o = divide_run(2, NULL, 32, 10, 5, 10);
    printf("divide_stop: 2 workers, hot 10 with line 5, bulk 10: %d cells, lambda %.4f\n",
           o.cells, o.lam);
    EXPECT(o.cells > 8 && o.lam <= 1.05 && o.whole,
           "hot shares its worker: %d cells, lambda %.4f (want <= 1.05, was 1.2)", o.cells,
           o.lam);

    /* 4 workers, hot 10, bulk 24: the bulk cut into pieces until three workers hold 8
       each, lambda 10 / 8.5 = 1.176 with the hot cell alone on the fourth; then stop. */
    o = divide_run(4, NULL, 32, 10, 0, 24);
    printf("divide_stop: 4 workers, hot 10, bulk 24: %d cells, lambda %.4f\n", o.cells, o.lam);
    EXPECT(o.cells > 8 && o.cells < 40 && fabs(o.lam - 10 / 8.5) < 1e-12 && o.whole,
           "4 workers: %d cells (want some, fewer than 40), lambda %.6f (want %.6f)", o.cells,
           o.lam, 10 / 8.5);
    TEST_DONE();
}
