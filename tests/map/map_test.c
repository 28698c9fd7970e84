/* map_test.c - the mappers' invariants over many grids and worker counts (src/map/map.c):
 * block gives every worker a cell when the grid has enough, and no worker or process
 * more than runs of cells would; greedy places by the loads it sorts, whatever they
 * are (NaN, none at all). Deterministic counts only; no timings.
 * usage: vw_test_map block|greedy_nan|greedy_zero
 */
#include "vw_test.h"
#include "vwalls/map.h"

#include <string.h>

/* Block, on every grid up to 6x6x6 and up to 8 processes of up to 6 workers: each cell
   on a worker that exists, no worker over ceil(cells / workers) cells nor a process over
   ceil(cells / processes), and none without a cell while there are as many cells as
   workers. 2x5x1 on 3 processes of 3 workers were process blocks of 4, 4 and 2 cells,
   and worker 8 had none (15 such cases, all with a process block smaller than its
   workers). */
static int t_block(void)
{
    vw_box world = {{0, 0, 0}, {1, 1, 1}};
    int cases = 0;
    for (int x = 1; x <= 6; x++)
        for (int y = 1; y <= 6; y++)
            for (int z = 1; z <= 6; z++) {
                int dims[3] = {x, y, z}, cw[216];
                vw_decomp *d;
                CHECK(vw_decomp_create_grid(&world, dims, &d) == VW_OK);
                int nc = vw_decomp_cell_count(d);
                for (int np = 1; np <= 8; np++)
                    for (int wpp = 1; wpp <= 6; wpp++) {
                        int g = np * wpp, per[48] = {0}, pper[8] = {0}, ok = 1;
                        for (int c = 0; c < nc; c++) cw[c] = -1;
                        EXPECT(vw_map_block(d, np, wpp, cw) == VW_OK, "%dx%dx%d", x, y, z);
                        for (int c = 0; c < nc && ok; c++) {
                            ok = cw[c] >= 0 && cw[c] < g;
                            EXPECT(ok, "%dx%dx%d on %d x %d: cell %d on worker %d", x, y, z, np,
                                   wpp, c, cw[c]);
                            if (ok) per[cw[c]]++, pper[cw[c] / wpp]++;
                        }
                        if (!ok) continue;
                        int most = (nc + g - 1) / g, pmost = (nc + np - 1) / np;
                        for (int k = 0; k < g; k++)
                            EXPECT(per[k] <= most && (nc < g || per[k] >= 1),
                                   "%dx%dx%d on %d processes x %d workers: worker %d hosts %d "
                                   "cells (at most %d, at least 1)", x, y, z, np, wpp, k, per[k],
                                   most);
                        for (int p = 0; p < np; p++)
                            EXPECT(pper[p] <= pmost, "%dx%dx%d on %d x %d: process %d hosts %d "
                                   "cells (at most %d)", x, y, z, np, wpp, p, pper[p], pmost);
                        cases++;
                    }
                vw_decomp_free(d);
            }
    printf("block: %d grids and worker counts\n", cases);
    TEST_DONE();
}

/* 8x8 cells of uneven loads on 4 workers. */
static void loads(double *load)
{
    for (int c = 0; c < 64; c++) load[c] = 1 + (c * 37) % 11;
}

/* A load that is no positive number is none, in the sort as in the placement: NaN for
   13 loads maps as 0 for them. Sorted with the NaNs, longest first was lost (48 cells
   elsewhere, up to 78 on a worker where 76 is the most with the zeros). */
static int t_greedy_nan(void)
{
    vw_box world = {{0, 0, 0}, {1, 1, 1}};
    int dims[3] = {8, 8, 1}, cn[64], cz[64];
    vw_decomp *d;
    CHECK(vw_decomp_create_grid(&world, dims, &d) == VW_OK);
    double ln[64], lz[64];
    loads(ln);
    loads(lz);
    for (int c = 2; c < 64; c += 5) ln[c] = NAN, lz[c] = 0;
    static const double neg = -3;
    for (int s = 0; s < 2; s++) {
        double slack = s ? 0.0 : 0.05;
        CHECK(vw_map_greedy(d, ln, 4, NULL, slack, cn) == VW_OK);
        CHECK(vw_map_greedy(d, lz, 4, NULL, slack, cz) == VW_OK);
        int differ = 0;
        double tn[4] = {0}, tz[4] = {0};
        for (int c = 0; c < 64; c++) {
            differ += cn[c] != cz[c];
            tn[cn[c]] += lz[c], tz[cz[c]] += lz[c];
        }
        printf("greedy, slack %g: NaN loads map %g %g %g %g, zero loads %g %g %g %g\n", slack,
               tn[0], tn[1], tn[2], tn[3], tz[0], tz[1], tz[2], tz[3]);
        EXPECT(differ == 0, "slack %g: %d cells mapped otherwise with NaN loads than with 0",
               slack, differ);
        /* and a negative load is none too */
        for (int c = 2; c < 64; c += 5) ln[c] = neg;
        CHECK(vw_map_greedy(d, ln, 4, NULL, slack, cn) == VW_OK);
        EXPECT(!memcmp(cn, cz, sizeof cn), "slack %g: negative loads map otherwise than 0",
               slack);
        for (int c = 2; c < 64; c += 5) ln[c] = NAN;
    }
    vw_decomp_free(d);
    TEST_DONE();
}

/* No load at all (a pre-pass that counted nothing) maps as no loads given (NULL): every
   cell counts alike. All 64 went to worker 0 of 4, by greedy and by weighted. */
static int t_greedy_zero(void)
{
    vw_box world = {{0, 0, 0}, {1, 1, 1}};
    int dims[3] = {8, 8, 1}, cz[64], c1[64];
    vw_decomp *d;
    CHECK(vw_decomp_create_grid(&world, dims, &d) == VW_OK);
    double zero[64] = {0};
    static const double speeds[4] = {1, 1, 2, 4};
    for (int kind = VW_MAP_GREEDY; kind <= VW_MAP_WEIGHTED; kind++)
        for (int s = 0; s < 2; s++) {
            const double *sp = s ? speeds : NULL;
            CHECK(vw_map_compute((vw_map_kind)kind, d, zero, 2, 2, sp, cz) == VW_OK);
            CHECK(vw_map_compute((vw_map_kind)kind, d, NULL, 2, 2, sp, c1) == VW_OK);
            int per[4] = {0};
            for (int c = 0; c < 64; c++) per[cz[c]]++;
            printf("%s%s, no load: %d %d %d %d cells\n", vw_map_kind_name((vw_map_kind)kind),
                   s ? " with speeds 1,1,2,4" : "", per[0], per[1], per[2], per[3]);
            EXPECT(!memcmp(cz, c1, sizeof cz), "%s: zero loads map otherwise than none given",
                   vw_map_kind_name((vw_map_kind)kind));
            for (int g = 0; g < 4; g++)
                EXPECT(per[g] >= (s ? 8 * (int)speeds[g] - 2 : 16) &&
                       per[g] <= (s ? 8 * (int)speeds[g] + 2 : 16),
                       "%s%s: worker %d hosts %d of 64 cells",
                       vw_map_kind_name((vw_map_kind)kind), s ? " with speeds" : "", g, per[g]);
        }
    vw_decomp_free(d);
    TEST_DONE();
}

int main(int argc, char **argv)
{
    const char *t = argc > 1 ? argv[1] : "";
    if (!strcmp(t, "block")) return t_block();
    if (!strcmp(t, "greedy_nan")) return t_greedy_nan();
    if (!strcmp(t, "greedy_zero")) return t_greedy_zero();
    fprintf(stderr, "usage: vw_test_map block|greedy_nan|greedy_zero\n");
    return 2;
}
