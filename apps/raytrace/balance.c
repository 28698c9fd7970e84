/* balance.c - load balancing a single ray-traced image: a sparse pre-pass measures
 * where the work lies, the balancer (vwalls/balance.h) moves the walls, and the job is
 * reset for the full render. The image cannot change: the pixel sums are exact integers
 * and every ray's first hit is the same for every decomposition (raytrace.h).
 */
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
    vw_world *w = rt_job_world((rt_job *)j);
    int nc = vw_decomp_cell_count(vw_world_decomp(w));
    double *load = malloc(sizeof(double) * (size_t)nc);
    int *map = malloc(sizeof(int) * (size_t)nc);
    double lam = 0;
    if (load && map) {
        for (int c = 0; c < nc; c++) {
            load[c] = (double)vw_world_cell_counter(w, c, RT_C_SEGMENTS);
            map[c] = vw_world_cell_worker(w, c);
        }
        lam = vw_balance_imbalance(load, map, nc, vw_world_workers(w) * vw_world_processes(w),
                                   speeds);
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
    int *cw = malloc(sizeof(int) * (size_t)vw_decomp_cell_count(d));
    vw_status st = cw ? vw_map_compute(kind, d, load, vw_world_processes(w), vw_world_workers(w),
                                       speeds, cw)
                      : VW_E_NOMEM;
    if (st == VW_OK) st = vw_world_remap(w, cw);
    if (st != VW_OK) snprintf(err, errlen, "mapping the cells: %s", vw_status_message(st));
    free(cw);
    return st;
}

/* Rebuilds the cells in place (same walls, same workers: nothing migrates), for cells
   that were last built for the pre-pass's sparse pixels. */
static vw_status rebuild(vw_world *w)
{
    const vw_decomp *d = vw_world_decomp(w);
    int nc = vw_decomp_cell_count(d);
    int *cw = malloc(sizeof(int) * (size_t)nc);
    if (!cw) return VW_E_NOMEM;
    for (int c = 0; c < nc; c++) cw[c] = vw_world_cell_worker(w, c);
    vw_status st = vw_world_redecompose(w, d, cw);
    free(cw);
    return st;
}

vw_status rt_job_balance(rt_job *j, const rt_balance *b, rt_balance_result *bi, char *err,
                         size_t errlen)
{
    memset(bi, 0, sizeof *bi);
    if (errlen) err[0] = 0;
    vw_world *w = rt_job_world(j);
    vw_load_field *f = NULL;
    double *load = malloc(sizeof(double) * VW_MAX_CELLS);
    vw_status st = load ? vw_load_field_create(&f) : VW_E_NOMEM;
    int stale = 0; /* cells are built for the sparse pre-pass */
    rt_job_set_sample(j, b->stride);
    int rounds = b->rounds > 0 ? b->rounds : 1;
    for (int r = 0; st == VW_OK && r < rounds; r++) {
        double t0 = now();
        st = rt_job_reset(j);
        /* Cells built before the sample was set (the caller's commit) must be rebuilt. */
        if (st == VW_OK && r == 0) st = rebuild(w);
        if (st == VW_OK) st = rt_job_commit(j, err, errlen);
        if (st == VW_OK) st = rt_job_run(j, err, errlen);
        if (st != VW_OK) break;
        stale = 1;
        bi->prepass_s += now() - t0;
        const vw_decomp *d = vw_world_decomp(w);
        st = vw_balance_cell_loads(w, &b->load, load);
        if (st == VW_OK)
            st = r == 0 ? vw_load_field_add_cells(f, d, load, 4)
                        : vw_load_field_calibrate(f, d, load, 4);
        if (st != VW_OK) {
            snprintf(err, errlen, "the load field: %s", vw_status_message(st));
            break;
        }
        if (b->strategy == VW_BALANCE_NONE) {
            /* Mapping only: greedy / weighted by the measured loads. */
            st = rt_job_map(j, b->map, load, b->speeds, err, errlen);
            stale = 0;
            bi->rounds++;
            break;
        }
        vw_balance_params bp;
        vw_balance_params_init(&bp);
        bp.strategy = b->strategy;
        bp.speeds = b->speeds;
        vw_balance_apply ap = {(int)b->map, b->speeds, 0, 0};
        vw_balance_report rep;
        st = vw_balance_world(w, f, &bp, &ap, &rep);
        if (st != VW_OK) {
            snprintf(err, errlen, "balancing: %s", vw_status_message(st));
            break;
        }
        double before = r == 0 ? rep.imbalance_before : bi->rep.imbalance_before;
        bi->rep = rep;
        bi->rep.imbalance_before = before;
        bi->migrated += rep.migrated_objects;
        bi->bytes += rep.bytes_moved;
        bi->rounds++;
        if (rep.applied) stale = 0;
    }
    rt_job_set_sample(j, 1);
    if (st == VW_OK && stale) st = rebuild(w);
    if (st == VW_OK) st = rt_job_reset(j);
    if (st != VW_OK && !err[0]) snprintf(err, errlen, "balancing: %s", vw_status_message(st));
    vw_load_field_free(f);
    free(load);
    return st;
}
