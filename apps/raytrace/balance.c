/* balance.c - load balancing a single ray-traced image: a sparse pre-pass measures
 * where the work lies, the balancer (vwalls/balance.h) moves the walls, and the job is
 * reset for the full render. The image cannot change: the pixel sums are exact integers
 * and every ray's first hit is the same for every decomposition (raytrace.h).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "raytrace/raytrace.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

double rt_job_work_imbalance(const rt_job *j, const double *speeds)
{
    /* Per worker, so the copies of duplicated cells count where they ran. */
    vw_world *w = rt_job_world((rt_job *)j);
    int gw = vw_world_workers(w) * vw_world_processes(w);
    double *load = malloc(sizeof(double) * (size_t)gw);
    int *map = malloc(sizeof(int) * (size_t)gw);
    double lam = 0;
    if (load && map) {
        for (int g = 0; g < gw; g++) {
            load[g] = (double)vw_world_worker_counter(w, g, RT_C_SEGMENTS);
            map[g] = g;
        }
        lam = vw_balance_imbalance(load, map, gw, gw, speeds);
    }
    free(load);
    free(map);
    return lam;
}

vw_status rt_job_map(rt_job *j, vw_map_kind kind, const double *load, const double *speeds,
                     char *err, size_t errlen)
{
    vw_world *w = rt_job_world(j);
    const vw_decomp *d = vw_world_decomp(w);
    int *cw = vw_test_fault("map-nomem") ? NULL : malloc(sizeof(int) * (size_t)vw_decomp_cell_count(d));
    vw_status st = cw ? vw_map_compute(kind, d, load, vw_world_processes(w), vw_world_workers(w),
                                       speeds, cw)
                      : VW_E_NOMEM;
    if (st != VW_OK) snprintf(err, errlen, "mapping the cells: %s", vw_status_message(st));
    /* The mapping is computed by each process: all fail, or none waits in the remap. */
    st = vw_world_agree(w, st, err, errlen);
    if (st == VW_OK && (st = vw_world_remap(w, cw)) != VW_OK)
        snprintf(err, errlen, "mapping the cells: %s", vw_world_errmsg(w));
    free(cw);
    return st;
}

int rt_farm_parse(const char *s)
{
    static const char *const names[] = {"idle", "all", "none"};
    for (int f = 0; f < 3; f++)
        if (!strcmp(s, names[f])) return f;
    return -1;
}

const char *rt_farm_name(rt_farm f)
{
    return f == RT_FARM_ALL ? "all" : f == RT_FARM_NONE ? "none" : "idle";
}

vw_status rt_job_farm(rt_job *j, rt_farm f, int *copies, char *err, size_t errlen)
{
    vw_world *w = rt_job_world(j);
    int nc = vw_decomp_cell_count(vw_world_decomp(w));
    int W = vw_world_workers(w), gw = W * vw_world_processes(w);
    if (copies) *copies = 0;
    if (f == RT_FARM_NONE || gw < 2) return VW_OK;
    /* Which workers and processes host something (a master or a copy) now. */
    int np = vw_world_processes(w);
    unsigned char *hosts = vw_test_fault("farm-nomem") ? NULL : calloc((size_t)gw, 1);
    unsigned char *proc_hosts = calloc((size_t)np, 1);
    int *on = malloc(sizeof(int) * (size_t)gw), *have = malloc(sizeof(int) * (size_t)gw);
    vw_status st = hosts && proc_hosts && on && have ? VW_OK : VW_E_NOMEM;
    if (st != VW_OK) snprintf(err, errlen, "farming the cells: %s", vw_status_message(st));
    /* Memory is each process's own: all fail, or none waits in vw_world_set_replicas
       for one that returned. What follows fails alike everywhere (the same mapping, and
       set_replicas agrees). */
    st = vw_world_agree(w, st, err, errlen);
    if (st != VW_OK) {
        free(hosts), free(proc_hosts), free(on), free(have);
        return st;
    }
    for (int c = 0; st == VW_OK && c < nc; c++) {
        int m = vw_world_cell_worker(w, c); /* -1 only for a cell outside 0..nc-1 */
        if (m < 0 || m >= gw) {
            st = VW_E_INVAL;
            break;
        }
        hosts[m] = 1;
        int n = vw_world_replicas(w, c, have, gw);
        for (int i = 0; i < n; i++) hosts[have[i]] = 1;
    }
    for (int g = 0; st == VW_OK && g < gw; g++) proc_hosts[g / W] |= hosts[g];
    for (int c = 0; st == VW_OK && c < nc; c++) {
        int m = vw_world_cell_worker(w, c);
        int n = vw_world_replicas(w, c, on, gw), before = n;
        for (int g = 0; g < gw; g++) {
            /* A worker farms its own process's cells; a process that hosts none (more
               processes than cells) farms them all. */
            if (g == m || (g / W != m / W && proc_hosts[g / W])) continue;
            if (f == RT_FARM_IDLE && hosts[g]) continue;
            int dup = 0;
            for (int i = 0; i < n; i++) dup |= on[i] == g;
            if (!dup) on[n++] = g;
        }
        if (n > before) st = vw_world_set_replicas(w, c, on, n);
        if (copies) *copies += n - before;
    }
    if (st != VW_OK) snprintf(err, errlen, "farming the cells: %s", vw_status_message(st));
    free(hosts), free(proc_hosts), free(on), free(have);
    return st;
}

/* Rebuilds the cells in place (same walls, same workers, same copies of duplicated
   cells: nothing migrates), for cells that were last built for the pre-pass's sparse
   pixels. Its arrays are each process's own: all fail, or none waits for one in the
   redecomposition (one agreement a rebuild). */
static vw_status rebuild(vw_world *w, char *err, size_t errlen)
{
    const vw_decomp *d = vw_world_decomp(w);
    int nc = vw_decomp_cell_count(d), gw = vw_world_workers(w) * vw_world_processes(w);
    int *cw = vw_test_fault("balance-rebuild-nomem") ? NULL : malloc(sizeof(int) * (size_t)nc);
    int *nrep = calloc((size_t)nc, sizeof *nrep);
    int *reps = malloc(sizeof(int) * (size_t)nc * (size_t)gw);
    vw_status st = cw && nrep && reps ? VW_OK : VW_E_NOMEM;
    if (st != VW_OK) snprintf(err, errlen, "rebuilding the cells: out of memory");
    if ((st = vw_world_agree(w, st, err, errlen)) != VW_OK) {
        free(cw), free(nrep), free(reps);
        return st;
    }
    for (int c = 0; c < nc; c++) {
        cw[c] = vw_world_cell_worker(w, c);
        nrep[c] = vw_world_replicas(w, c, reps + (size_t)c * gw, gw);
    }
    st = vw_world_redecompose(w, d, cw); /* (drops the copies) */
    for (int c = 0; c < nc && st == VW_OK; c++)
        if (nrep[c]) st = vw_world_set_replicas(w, c, reps + (size_t)c * gw, nrep[c]);
    if (st != VW_OK) snprintf(err, errlen, "rebuilding the cells: %s", vw_world_errmsg(w));
    free(cw), free(nrep), free(reps);
    return st;
}

/* A layout to come back to: walls, mapping and copies of duplicated cells. */
typedef struct layout {
    vw_decomp *d;
    int *cw, *nrep, *reps;
    int gw;
} layout;

static void layout_free(layout *l)
{
    vw_decomp_free(l->d);
    free(l->cw), free(l->nrep), free(l->reps);
    memset(l, 0, sizeof *l);
}

static vw_status layout_save(vw_world *w, layout *l)
{
    layout_free(l);
    int nc = vw_decomp_cell_count(vw_world_decomp(w));
    l->gw = vw_world_workers(w) * vw_world_processes(w);
    l->cw = vw_test_fault("balance-layout-nomem") ? NULL : malloc(sizeof(int) * (size_t)nc);
    l->nrep = malloc(sizeof(int) * (size_t)nc);
    l->reps = malloc(sizeof(int) * (size_t)nc * (size_t)l->gw);
    if (!l->cw || !l->nrep || !l->reps) return VW_E_NOMEM;
    for (int c = 0; c < nc; c++) {
        l->cw[c] = vw_world_cell_worker(w, c);
        l->nrep[c] = vw_world_replicas(w, c, l->reps + (size_t)c * l->gw, l->gw);
    }
    return vw_decomp_clone(vw_world_decomp(w), &l->d);
}

static vw_status layout_restore(vw_world *w, const layout *l)
{
    vw_status st = vw_world_redecompose(w, l->d, l->cw);
    int nc = vw_decomp_cell_count(l->d);
    for (int c = 0; c < nc && st == VW_OK; c++)
        if (l->nrep[c]) st = vw_world_set_replicas(w, c, l->reps + (size_t)c * l->gw, l->nrep[c]);
    return st;
}

/* Back to the best layout the rounds measured; err names the step when it fails. */
static vw_status restore_best(vw_world *w, const layout *best, char *err, size_t errlen)
{
    vw_status st = layout_restore(w, best);
    if (st != VW_OK)
        snprintf(err, errlen, "restoring the best layout: %s", vw_status_message(st));
    return st;
}

/* What the last run (a pre-pass) measured of the layout: lambda of its loads per
   worker (copies of duplicated cells where they ran) into *lam, and its cost: the
   slowest worker's load (its busy time, or its counted or modelled load over its
   speed) per pixel sampled. The cost compares layouts; lambda compares a layout with
   itself. A balance that adds work can lower lambda and raise the slowest worker's load
   all the same: a rotated frame's larger world box lets more eye rays in, and divided
   cells' walls are crossed by more rays (docs/balancing.md, "lambda is not the time").
   VW_E_NOMEM on this process alone. */
static vw_status measured(vw_world *w, const vw_load_spec *ls, const double *cell_load,
                          const double *speeds, double pixels, double *lam, double *cost)
{
    int gw = vw_world_workers(w) * vw_world_processes(w);
    int nc = vw_decomp_cell_count(vw_world_decomp(w));
    double *t = calloc((size_t)gw, sizeof *t);
    int *id = malloc(sizeof(int) * (size_t)gw);
    *lam = 0;
    *cost = 0;
    if (t && id) {
        for (int g = 0; g < gw; g++) id[g] = g;
        if (ls->model == VW_LOAD_COUNTER)
            for (int g = 0; g < gw; g++) t[g] = (double)vw_world_worker_counter(w, g, ls->counter);
        else if (ls->model == VW_LOAD_BUSY)
            for (int g = 0; g < gw; g++) t[g] = vw_world_worker_busy(w, g);
        else
            for (int c = 0; c < nc; c++) t[vw_world_cell_worker(w, c)] += cell_load[c];
        /* Busy times are times already: the world's lambda weighs them by speed. */
        *lam = ls->model == VW_LOAD_BUSY ? vw_world_imbalance(w)
                                         : vw_balance_imbalance(t, id, gw, gw, speeds);
        double slowest = 0;
        for (int g = 0; g < gw; g++) {
            double x = ls->model != VW_LOAD_BUSY && speeds ? t[g] / speeds[g] : t[g];
            if (x > slowest) slowest = x;
        }
        *cost = pixels > 0 ? slowest / pixels : slowest;
    }
    vw_status st = t && id ? VW_OK : VW_E_NOMEM;
    free(t), free(id);
    return st;
}

/* The pixels a pre-pass of this stride samples: every stride-th row and column. */
static double sampled_pixels(const rt_shared *sh, int stride)
{
    double s = stride > 1 ? stride : 1;
    return ceil(sh->view.width / s) * ceil(sh->view.height / s);
}

/* Extra pre-pass / balance rounds for divide and rotate (see rt_job_balance). */
#define RT_BALANCE_EXTRA 3

int rt_prepass_stride(int width, int height, int cells)
{
    /* At least RT_PREPASS_RAYS eye rays per cell on average: a cell's measured load is a
       sum over its sampled rays, so its relative error falls like 1/sqrt(rays); with a
       fixed stride, 64 cells of a 256x256 image would see 16 rays each. */
    double want = (double)RT_PREPASS_RAYS * (cells > 0 ? cells : 1);
    int s = (int)floor(sqrt((double)width * height / want));
    return s < 1 ? 1 : s > 8 ? 8 : s;
}

/* Maps the cells by their loads (load: one figure per cell of the walls in use) with
   the balance's mapping, greedy or weighted, and reports what it moved and the
   imbalance it predicts. The cells were built for the pre-pass, so what the remap
   moves counts (the world's count, which the stats JSON's "balance" member shows). */
static vw_status map_measured(rt_job *j, const rt_balance *b, const double *load,
                              rt_balance_result *bi, char *err, size_t errlen)
{
    vw_world *w = rt_job_world(j);
    uint64_t moved = vw_world_migrated(w);
    vw_status st = rt_job_map(j, b->map, load, b->speeds, err, errlen);
    if (st != VW_OK) return st;
    moved = vw_world_migrated(w) - moved;
    bi->migrated += moved;
    bi->bytes += moved * sizeof(rt_object);
    /* (the remap replaced the decomposition; the walls are the same, so load still has a
       figure per cell) */
    int nc = vw_decomp_cell_count(vw_world_decomp(w));
    int *cw = malloc(sizeof(int) * (size_t)nc);
    for (int c = 0; cw && c < nc; c++) cw[c] = vw_world_cell_worker(w, c);
    int gw = vw_world_workers(w) * vw_world_processes(w);
    bi->rep.imbalance_predicted = cw ? vw_balance_imbalance(load, cw, nc, gw, b->speeds) : 0;
    free(cw);
    return VW_OK;
}

/* One balance of the rounds: its report becomes the result's, but for the imbalance
   the rounds started from (the first balance's own), and its migrations add up. */
static vw_status balance_once(vw_world *w, vw_load_field *f, const vw_balance_params *bp,
                              vw_balance_apply *ap, vw_balance_report *rep, int first,
                              rt_balance_result *bi, char *err, size_t errlen)
{
    vw_status st = vw_balance_world(w, f, bp, ap, rep);
    if (st != VW_OK) {
        snprintf(err, errlen, "balancing: %s", vw_world_errmsg(w));
        return st;
    }
    double before = first ? rep->imbalance_before : bi->rep.imbalance_before;
    bi->rep = *rep;
    bi->rep.imbalance_before = before;
    bi->migrated += rep->migrated_objects;
    bi->bytes += rep->bytes_moved;
    return VW_OK;
}

vw_status rt_job_balance(rt_job *j, const rt_balance *b, rt_balance_result *bi, char *err,
                         size_t errlen)
{
    memset(bi, 0, sizeof *bi);
    if (errlen) err[0] = 0;
    vw_world *w = rt_job_world(j);
    vw_load_field *f = NULL;
    double *load = vw_test_fault("balance-nomem") ? NULL : malloc(sizeof(double) * VW_MAX_CELLS);
    vw_status st = load ? vw_load_field_create(&f) : VW_E_NOMEM;
    if (st != VW_OK) snprintf(err, errlen, "balancing: the loads: %s", vw_status_message(st));
    /* Each process's own memory: all fail, or none waits for one in the pre-pass. */
    st = vw_world_agree(w, st, err, errlen);
    int stale = 0; /* cells are built for the sparse pre-pass */
    const rt_shared *sh = rt_job_shared(j);
    int stride = b->stride > 0 ? b->stride
                               : rt_prepass_stride(sh->view.width, sh->view.height,
                                                   vw_decomp_cell_count(vw_world_decomp(w)));
    rt_job_set_sample(j, stride);
    bi->stride = stride;
    int rounds = b->rounds > 0 ? b->rounds : 1;
    /* Divide and rotate get RT_BALANCE_EXTRA more rounds: their first balance is
       predicted from a field measured on the old cells (uniform inside each), so a
       divided piece or a rotated frame is cut from a coarse picture; the rounds after
       it cut again from measurements on the new cells. They end early once a balance
       predicts no gain. */
    if (b->strategy == VW_BALANCE_DIVIDE || b->strategy == VW_BALANCE_ROTATE)
        rounds += RT_BALANCE_EXTRA;
    /* Every balance is checked by the next pre-pass: the best measured layout so far is
       kept and restored at the end, so a balance the measurement refutes (its slowest
       worker's load per sampled pixel no lower than the best's: measured()) is undone.
       So with R rounds there are R + 1 pre-passes. */
    layout best = {0};
    double best_cost = 0;
    /* The prediction made for the layout applied last, and for the best layout measured
       (the original's is what its pre-pass measured): where the rounds end on the best
       layout restored, the result reports its prediction, not the prediction of the
       layout just undone, so a run that kept its original layout says "predicted" =
       "before" instead of a gain it never got. */
    double pred_applied = 0, best_pred = 0;
    int best_round = 0;
    int turned_refuted = 0; /* rotated frames refuted in a row (below) */
    /* Greedy or weighted: the first layout is mapped by its loads before round 0. */
    int remap_first = b->strategy != VW_BALANCE_NONE && b->map != VW_MAP_BLOCK, remapped = 0;
    vw_balance_strategy strategy = b->strategy; /* rotate may fall back to tensor, below */
    for (int r = 0; st == VW_OK && r <= rounds; r++) {
        double t0 = now();
        if (b->stride <= 0 && r > 0) {
            /* About RT_PREPASS_RAYS eye rays for every cell of the layout measured now:
               divide makes more (and smaller) cells, duplication shares cells between
               workers; a stride chosen for the first layout would sample them coarsely. */
            const vw_decomp *dn = vw_world_decomp(w);
            int units = 0, nc = vw_decomp_cell_count(dn);
            for (int c = 0; c < nc; c++) units += 1 + vw_world_replicas(w, c, NULL, 0);
            int s2 = rt_prepass_stride(sh->view.width, sh->view.height, units);
            if (s2 < stride) {
                stride = s2;
                rt_job_set_sample(j, stride);
                bi->stride = stride;
                if (st == VW_OK) st = rebuild(w, err, errlen);
            }
        }
        if (st != VW_OK) break;
        st = rt_job_reset(j);
        /* Cells built before the sample was set (the caller's commit) must be rebuilt. */
        if (st == VW_OK && r == 0) st = rebuild(w, err, errlen);
        if (st == VW_OK) st = rt_job_commit(j, err, errlen);
        if (st == VW_OK) st = rt_job_run(j, err, errlen);
        if (st != VW_OK) break;
        stale = 1;
        bi->prepass_s += now() - t0;
        const vw_decomp *d = vw_world_decomp(w);
        /* From here to the round's next collective step (restoring the best layout, the
           mapping, the balance) each process works alone: the loads (global figures,
           the same everywhere) and their lambda, the saved layout, the field. Its memory
           is its own, so the round agrees once on all of it, before that step. */
        double lam = 0, cost = 0;
        st = vw_balance_cell_loads(w, &b->load, load);
        if (st != VW_OK)
            snprintf(err, errlen, "the load field: %s", vw_status_message(st));
        else if ((st = measured(w, &b->load, load, b->speeds, sampled_pixels(sh, stride), &lam,
                                &cost)) != VW_OK)
            snprintf(err, errlen, "the measured imbalance: %s", vw_status_message(st));
        if (remap_first && st == VW_OK) {
            /* The first layout mapped by its measured loads, as --balance none maps it,
               is what a balance must beat: the first pre-pass is run again on it, and
               that is round 0. Kept as it was mapped before any load was known, a
               balance measured better than it was kept though worse than none: balls,
               128x128, 4x4x1 cells, 3 workers, --map greedy, --balance-load segments,
               --farm none: tensor's work lambda 1.903 against none's 1.213. */
            remap_first = 0;
            if ((st = vw_world_agree(w, st, err, errlen)) != VW_OK) break;
            if ((st = map_measured(j, b, load, bi, err, errlen)) != VW_OK) break;
            /* "before" is the layout as it came, as the mapping alone reports it */
            bi->rep.imbalance_before = lam;
            remapped = 1;
            r--;
            continue;
        }
        /* Refuted (its cost no lower than the best measured): the field still learns
           from this measurement and the next round balances on from here; the best
           layout measured is restored when the rounds end. */
        int refuted = r > 0 && b->strategy != VW_BALANCE_NONE && !(cost < best_cost);
        int last = r == rounds;
        if (st == VW_OK && !refuted && b->strategy != VW_BALANCE_NONE) {
            best_cost = cost;
            bi->measured = lam;
            best_pred = r == 0 ? lam : pred_applied;
            best_round = r;
            if ((st = layout_save(w, &best)) != VW_OK)
                snprintf(err, errlen, "saving the layout: %s", vw_status_message(st));
        }
        if (st == VW_OK && !last) {
            st = r == 0 ? vw_load_field_add_cells(f, d, load, 4)
                        : vw_load_field_calibrate(f, d, load, 4);
            if (st != VW_OK) snprintf(err, errlen, "the load field: %s", vw_status_message(st));
        }
        if ((st = vw_world_agree(w, st, err, errlen)) != VW_OK) break;
        if (refuted && last) {
            /* Back to the best layout measured (its cells are built for the pre-pass as
               the others, so stale stays). */
            st = restore_best(w, &best, err, errlen);
            bi->reverted = 1;
            break;
        }
        if (last) break;
        if (b->strategy == VW_BALANCE_NONE) {
            /* Mapping only: greedy / weighted by the measured loads. */
            st = map_measured(j, b, load, bi, err, errlen);
            bi->rep.imbalance_before = lam;
            stale = 0;
            bi->rounds++;
            break;
        }
        vw_balance_params bp;
        vw_balance_params_init(&bp);
        bp.speeds = b->speeds;
        vw_balance_apply ap = {(int)b->map, b->speeds, 0, 0};
        vw_balance_report rep;
        /* A rotated frame refuted against an unrotated best layout gets one more round
           in its frame: its walls are cut again there from the field its measurement
           re-calibrated (the fully clustered 1000 spheres, 512x512, 2x4 cells, one
           worker a cell, --balance-load segments: the first frame measured 0.2 % worse
           than the grid, the next one in it gave work lambda 1.087, tensor's walls after
           it 1.197). Refuted again, rotation is given up: every rotated candidate is
           predicted from a field that cannot see the work a turned world box adds (more
           eye rays enter it), so rotate would pick one round after round, and the
           rounds ended on the grid, unbalanced (1000 uniform spheres in their cube,
           160x160, 2x2x2: five rotated layouts refuted, work lambda 1.568 where
           tensor's walls give 1.272). Back to the best layout, and on with rotate's
           unrotated candidate, tensor's walls. */
        int turned = vw_decomp_frame(d) != NULL;
        int at_best = 0; /* the world holds the best layout again (restored this round) */
        if (!refuted) {
            turned_refuted = 0;
        } else if (strategy == VW_BALANCE_ROTATE && turned && !vw_decomp_frame(best.d) &&
                   ++turned_refuted >= 2) {
            if ((st = restore_best(w, &best, err, errlen)) != VW_OK) break;
            at_best = 1;
            strategy = VW_BALANCE_TENSOR;
        }
        bp.strategy = strategy;
        if ((st = balance_once(w, f, &bp, &ap, &rep, r == 0 && !remapped, bi, err, errlen)) != VW_OK)
            break;
        bi->rounds++;
        if (!rep.applied && refuted && !at_best && r + 1 < rounds) {
            /* The layout measured worse than the best, and no balance on from it predicts a
               gain: go back to the best layout and balance again from there, on the field
               as this measurement re-calibrated it. Stopping here kept the best layout
               unbalanced: rotate's first frame on the fully clustered 1000 spheres (512x512,
               2x4 cells, 8 workers, --balance-load segments) was predicted at lambda 1.000
               from the field of the grid's uniform cells, measured 1.361 with more work,
               could not be re-cut in its frame, and the grid came back with its work lambda
               1.514, where the unrotated frame's walls give 1.15. A rotated frame that
               cannot be re-cut is given up at once, as above. */
            if ((st = restore_best(w, &best, err, errlen)) != VW_OK) break;
            if (strategy == VW_BALANCE_ROTATE && turned && !vw_decomp_frame(vw_world_decomp(w)))
                bp.strategy = strategy = VW_BALANCE_TENSOR;
            if ((st = balance_once(w, f, &bp, &ap, &rep, 0, bi, err, errlen)) != VW_OK) break;
            if (!rep.applied) { /* the best layout stays, balanced no further */
                bi->reverted = 1;
                break;
            }
        } else if (!rep.applied) { /* nothing changed: measuring again would tell nothing */
            if (refuted && !at_best) st = restore_best(w, &best, err, errlen);
            bi->reverted = refuted;
            break;
        }
        pred_applied = rep.imbalance_predicted;
    }
    if (bi->reverted) {
        /* The layout in use is the best one measured: its prediction, and whether it is
           a balanced one at all (best_round 0: the layout the rounds started from). */
        bi->rep.imbalance_predicted = best_pred;
        bi->rep.applied = best_round > 0;
    }
    layout_free(&best);
    rt_job_set_sample(j, 1);
    if (st == VW_OK && stale) st = rebuild(w, err, errlen);
    if (st == VW_OK) st = rt_job_reset(j);
    if (st != VW_OK && !err[0]) snprintf(err, errlen, "balancing: %s", vw_status_message(st));
    vw_load_field_free(f);
    free(load);
    return st;
}
