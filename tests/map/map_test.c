/* map_test.c - the mappers' invariants over many grids and worker counts (src/map/map.c):
 * block gives every worker a cell when the grid has enough, and no worker or process
 * more than runs of cells would; greedy places by the loads it sorts, whatever they
 * are (NaN, none at all); block cuts the least wall area, vw_map_dims refuses n < 1,
 * greedy spreads cells of infinite load. Deterministic counts only; no timings.
 * usage: vw_test_map block|greedy_nan|greedy_zero|block_area|dims|greedy_inf
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

/* The wall area between cells on different workers: each pair of grid neighbours
   (i, j, k) and the next cell along an axis whose workers differ adds their common
   face. */
static double cut_area(const vw_decomp *d, const int *cw)
{
    int n[3];
    vw_decomp_dims(d, n);
    double area = 0;
    for (int c = 0; c < n[0] * n[1] * n[2]; c++) {
        int ix[3] = {c % n[0], (c / n[0]) % n[1], c / (n[0] * n[1])};
        vw_box b = vw_decomp_cell_box(d, c);
        for (int a = 0; a < 3; a++) {
            if (ix[a] + 1 >= n[a]) continue;
            int step = a == 0 ? 1 : a == 1 ? n[0] : n[0] * n[1];
            if (cw[c] == cw[c + step]) continue;
            int y = (a + 1) % 3, z = (a + 2) % 3;
            area += (b.hi[y] - b.lo[y]) * (b.hi[z] - b.lo[z]);
        }
    }
    return area;
}

/* Block cuts the least wall area, not the fewest cell faces. 2x2x2 cells of the
   sphereflake's world (24 x 24 x 1.33) went to 2 and 4 workers cut at the horizontal
   wall (576) where a vertical one is 32: twice the messages between workers (30048
   against 10427 at 96x96). And the walls where they are: 4x2x1 cells of a 10 x 1 x 1
   world with walls at x = 1, 5, 9 on 2 processes of 2 workers, the process blocks
   [0, 5] and [5, 10] were cut along y (area 5 each, the first of two cuts of 2 faces)
   where the walls at 1 and 9 are 1. */
static int t_block_area(void)
{
    vw_box flat = {{-12, -12, -0.5}, {12, 12, 0.83}};
    int dims[3] = {2, 2, 2}, cw[8];
    vw_decomp *d;
    CHECK(vw_decomp_create_grid(&flat, dims, &d) == VW_OK);
    double wall = 24 * 1.33;
    for (int w = 2; w <= 4; w += 2) {
        CHECK(vw_map_block(d, 1, w, cw) == VW_OK);
        double a = cut_area(d, cw);
        printf("2x2x2 of 24 x 24 x 1.33 on %d workers: cut area %g (%g the least)\n", w, a,
               (w / 2) * wall);
        EXPECT(fabs(a - (w / 2) * wall) < 1e-9, "%d workers: cut area %g, not %g", w, a,
               (w / 2) * wall);
    }
    vw_decomp_free(d);

    vw_box box = {{0, 0, 0}, {10, 1, 1}};
    int dims2[3] = {4, 2, 1}, cw2[8];
    static const double wx[] = {1, 5, 9}, wy[] = {0.5};
    const double *walls[3] = {wx, wy, NULL};
    CHECK(vw_decomp_create_grid_walls(&box, dims2, walls, NULL, &d) == VW_OK);
    CHECK(vw_map_block(d, 2, 2, cw2) == VW_OK);
    double a = cut_area(d, cw2);
    printf("4x2x1 walls at x = 1, 5, 9 on 2 x 2 workers: cut area %g (3 the least)\n", a);
    EXPECT(fabs(a - 3) < 1e-9, "cut area %g, not 3", a);
    vw_decomp_free(d);
    TEST_DONE();
}

/* vw_map_dims with n < 1 (or no arrays) is refused, and dims are 1x1x1: it gave
   {0, 1, 1}, a grid of no parts. */
static int t_dims(void)
{
    const int cells[3] = {4, 2, 1};
    for (int n = -2; n <= 0; n++) {
        int dims[3] = {7, 7, 7};
        vw_status st = vw_map_dims(n, cells, dims);
        printf("vw_map_dims(%d): status %d, %d %d %d\n", n, (int)st, dims[0], dims[1], dims[2]);
        EXPECT(st == VW_E_INVAL, "n %d: status %d", n, (int)st);
        EXPECT(dims[0] == 1 && dims[1] == 1 && dims[2] == 1, "n %d: %dx%dx%d", n, dims[0],
               dims[1], dims[2]);
    }
    int dims[3];
    EXPECT(vw_map_dims(2, NULL, dims) == VW_E_INVAL, "no cells");
    EXPECT(vw_map_dims(2, cells, NULL) == VW_E_INVAL, "no dims");
    /* Without sizes cells are cubes: the cut of fewest faces, across the longest side. */
    EXPECT(vw_map_dims(2, cells, dims) == VW_OK && dims[0] == 2 && dims[1] == 1 &&
               dims[2] == 1, "4x2x1 on 2: %dx%dx%d", dims[0], dims[1], dims[2]);
    TEST_DONE();
}

/* Cells of infinite load go one to a worker before any gets a second, and the finite
   ones to the workers with fewest infinite cells. A row of 4 infinite cells of 4x4 went
   all to worker 0 of 4 (every worker's time was infinite once it had one, and the
   neighbours chose). */
static int t_greedy_inf(void)
{
    vw_box world = {{0, 0, 0}, {1, 1, 1}};
    int dims[3] = {4, 4, 1}, cw[16];
    vw_decomp *d;
    CHECK(vw_decomp_create_grid(&world, dims, &d) == VW_OK);
    static const double speeds[4] = {1, 1, 2, 4};
    for (int ninf = 4; ninf <= 6; ninf += 2)
        for (int s = 0; s < 3; s++) {
            double load[16];
            for (int c = 0; c < 16; c++) load[c] = c < ninf ? INFINITY : 1 + c % 3;
            double slack = s == 1 ? 0.0 : 0.05;
            const double *sp = s == 2 ? speeds : NULL;
            CHECK(vw_map_greedy(d, load, 4, sp, slack, cw) == VW_OK);
            int inf[4] = {0}, fin[4] = {0};
            for (int c = 0; c < 16; c++) (c < ninf ? inf : fin)[cw[c]]++;
            printf("%d infinite cells, slack %g%s: infinite %d %d %d %d, finite %d %d %d %d\n",
                   ninf, slack, sp ? ", speeds 1,1,2,4" : "", inf[0], inf[1], inf[2], inf[3],
                   fin[0], fin[1], fin[2], fin[3]);
            int lo = 16, hi = 0;
            for (int g = 0; g < 4; g++) {
                if (inf[g] < lo) lo = inf[g];
                if (inf[g] > hi) hi = inf[g];
            }
            EXPECT(hi - lo <= 1, "%d infinite cells spread %d to %d a worker", ninf, lo, hi);
            for (int g = 0; g < 4; g++)
                EXPECT(!fin[g] || inf[g] == lo, "worker %d with %d infinite cells got %d finite "
                       "ones (fewest infinite: %d)", g, inf[g], fin[g], lo);
            /* the same mapping again: deterministic */
            int again[16];
            CHECK(vw_map_greedy(d, load, 4, sp, slack, again) == VW_OK);
            EXPECT(!memcmp(cw, again, sizeof cw), "a second mapping differs");
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
    if (!strcmp(t, "block_area")) return t_block_area();
    if (!strcmp(t, "dims")) return t_dims();
    if (!strcmp(t, "greedy_inf")) return t_greedy_inf();
    fprintf(stderr, "usage: vw_test_map block|greedy_nan|greedy_zero|block_area|dims|"
                    "greedy_inf\n");
    return 2;
}
