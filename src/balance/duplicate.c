/* duplicate.c - cell duplication (the paper's fourth strategy): an overloaded cell is
 * copied, with its objects, to underloaded workers; the master shares its independent
 * messages (rays) with the copies, so each of the k copies carries load / k. The walls
 * and the neighbourhood do not change; only the duplicated cells' objects move.
 *
 * Plan: k_c copies of cell c (1: the master alone). Each round gives one more copy to
 * the cell whose copies take longest, then places all the non-master shares afresh,
 * largest first, each on the worker that holds no share of its cell yet and would be
 * done first (masters stay where they are). Placing afresh, not adding to the last
 * placement, lets a round undo an earlier round's choice. The best placement seen is
 * kept; rounds end at lambda <= 1 + tolerance or after max_extra copies.
 * A placement is judged as the runtime will run it: the copies of a cell share its work
 * in proportion to their workers' speeds (vw_config.worker_speeds, the same speeds), so
 * each copy of cell c takes L_c / S_c, S_c the sum of its copies' speeds (L_c / k_c with
 * equal speeds), and a worker's time is the sum of that over the cells it holds. The
 * placement itself sizes shares as L_c / k_c: the speeds of the copies still to place
 * are not known yet.
 * Cost: O(max_extra * (cells + S log S + S * workers)) for S shares, plus cells * workers
 * bytes.
 */
#include "balance/balance_internal.h"
#include "core/world_internal.h"

#include <stdlib.h>
#include <string.h>

typedef struct share {
    double w;
    int cell;
} share;

static int by_weight_desc(const void *a, const void *b)
{
    const share *x = a, *y = b;
    if (x->w != y->w) return x->w < y->w ? 1 : -1;
    return x->cell - y->cell; /* ties: a fixed order, so every process plans alike */
}

vw_status vw__balance_duplicate_plan(const double *load, const int *cell_worker, int ncells,
                                     int gworkers, const double *speeds, double tolerance,
                                     int max_extra, int *pair_cell, int *pair_worker, int *npairs,
                                     double *lambda)
{
    *npairs = 0;
    *lambda = 1.0;
    if (ncells < 1 || gworkers < 1) return VW_OK;
    double *t = malloc(sizeof(double) * (size_t)gworkers);
    int *k = malloc(sizeof(int) * (size_t)ncells);
    share *sh = malloc(sizeof(share) * (size_t)(max_extra > 0 ? max_extra : 1));
    int *pc = malloc(sizeof(int) * (size_t)(max_extra > 0 ? max_extra : 1));
    int *pw = malloc(sizeof(int) * (size_t)(max_extra > 0 ? max_extra : 1));
    unsigned char *holds = malloc((size_t)ncells * (size_t)gworkers);
    double *span = malloc(sizeof(double) * (size_t)ncells); /* L_c / S_c, see above */
    double *time = malloc(sizeof(double) * (size_t)gworkers);
    if (!t || !k || !sh || !pc || !pw || !holds || !span || !time) {
        free(t), free(k), free(sh), free(pc), free(pw), free(holds), free(span), free(time);
        return VW_E_NOMEM;
    }
    double top = 0; /* the fastest speed */
    for (int g = 0; speeds && g < gworkers; g++) top = speeds[g] > top ? speeds[g] : top;
    for (int c = 0; c < ncells; c++) k[c] = 1;
    double best = -1;
    int extra = 0;
    for (;;) {
        /* Masters first, then the copies' shares, largest first. Only a copied cell's
           row of holds is read (a cell alone is held by its master), so only those are
           cleared and set: a round costs cells + copies x workers, not cells x workers
           (32768 cells on 64 workers: 3.4 s for 1024 rounds, where the rows were all
           cleared and summed each round). */
        for (int g = 0; g < gworkers; g++) t[g] = 0;
        int ns = 0;
        for (int c = 0; c < ncells; c++) {
            int g = cell_worker[c];
            if (g < 0 || g >= gworkers) continue;
            t[g] += load[c] / k[c];
            if (k[c] < 2) continue;
            memset(&holds[(size_t)c * gworkers], 0, (size_t)gworkers);
            holds[(size_t)c * gworkers + g] = 1;
            for (int i = 1; i < k[c]; i++) sh[ns++] = (share){load[c] / k[c], c};
        }
        qsort(sh, (size_t)ns, sizeof *sh, by_weight_desc);
        for (int i = 0; i < ns; i++) {
            int c = sh[i].cell, gmin = -1;
            for (int g = 0; g < gworkers; g++) {
                if (holds[(size_t)c * gworkers + g]) continue;
                double x = speeds ? t[g] / speeds[g] : t[g];
                if (gmin < 0 || x < (speeds ? t[gmin] / speeds[gmin] : t[gmin])) gmin = g;
            }
            /* k[c] < gworkers always holds, so a free worker exists. */
            t[gmin] += sh[i].w;
            holds[(size_t)c * gworkers + gmin] = 1;
            pc[i] = c;
            pw[i] = gmin;
        }
        /* The placement as the runtime runs it: shares by speed. */
        for (int g = 0; g < gworkers; g++) time[g] = 0;
        for (int c = 0; c < ncells; c++) {
            int m = cell_worker[c];
            if (m < 0 || m >= gworkers) { /* no master: no share placed */
                span[c] = 0;
                continue;
            }
            if (k[c] < 2) { /* the master alone */
                span[c] = load[c] / (speeds ? speeds[m] : 1.0);
                time[m] += span[c];
                continue;
            }
            const unsigned char *h = &holds[(size_t)c * gworkers];
            double S = 0;
            for (int g = 0; g < gworkers; g++)
                if (h[g]) S += speeds ? speeds[g] : 1.0;
            span[c] = S > 0 ? load[c] / S : 0;
            for (int g = 0; g < gworkers; g++)
                if (h[g]) time[g] += span[c];
        }
        /* lambda as vw_balance_imbalance defines it: the slowest worker's time
           against a split by speed (vw__lambda, given each worker's work, its time
           times its speed as a fraction of the fastest). Max / mean of the times let
           an idle slow worker lift lambda, and the plan copied cells to it. */
        for (int g = 0; g < gworkers; g++) time[g] *= speeds ? speeds[g] / top : 1.0;
        double lam = vw__lambda(time, speeds, gworkers);
        if (best < 0 || lam < best - 1e-12) {
            best = lam;
            *npairs = ns;
            memcpy(pair_cell, pc, sizeof(int) * (size_t)ns);
            memcpy(pair_worker, pw, sizeof(int) * (size_t)ns);
        }
        if (lam <= 1.0 + tolerance || extra >= max_extra) break;
        /* One more copy for the cell whose copies take longest that can still have one. */
        int heavy = -1;
        for (int c = 0; c < ncells; c++)
            if (load[c] > 0 && k[c] < gworkers && (heavy < 0 || span[c] > span[heavy]))
                heavy = c;
        if (heavy < 0) break;
        k[heavy]++;
        extra++;
    }
    *lambda = best;
    free(t), free(k), free(sh), free(pc), free(pw), free(holds), free(span), free(time);
    return VW_OK;
}
