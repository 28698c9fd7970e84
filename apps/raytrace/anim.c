/* anim.c - the ray tracer over a dynamic scene: a render job and a vw_dynscene over the
 * same decomposition, kept in step edit by edit (see anim.h for the slot rule).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "raytrace/anim.h"
#if __has_include("vwalls/balance.h")
#include "vwalls/balance.h"
#define RT_HAVE_BALANCE 1
#else
#define RT_HAVE_BALANCE 0
#endif

struct rt_anim {
    rt_job *job;
    vw_dynscene *ds;
    vw_camera cam;
    vw_box world;
    double scale;
    int full_rebuild;
    rt_farm farm;
    double last_lambda, last_work_lambda;
    rt_object *rec;       /* the records as last placed in the render world, by slot */
    size_t nrec, caprec;
    /* The cells the edits since the last frame touched, each marked once (several
       batches may touch one cell), so the frame reports each rebuilt cell once;
       rebuild_all when the next commit builds every cell (first frame, rebalance). */
    unsigned char *touched;
    int ntouched_cells;   /* cells the mark array covers (the layout may change) */
    size_t ntouched;
    int rebuild_all;
};

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

rt_job *rt_anim_job(rt_anim *a) { return a->job; }
vw_dynscene *rt_anim_dynscene(rt_anim *a) { return a->ds; }
const vw_camera *rt_anim_camera(const rt_anim *a) { return &a->cam; }
const vw_box *rt_anim_world(const rt_anim *a) { return &a->world; }
double rt_anim_scale(const rt_anim *a) { return a->scale; }

void rt_anim_free(rt_anim *a)
{
    if (!a) return;
    rt_job_free(a->job);
    vw_dynscene_free(a->ds);
    free(a->rec);
    free(a->touched);
    free(a);
}

/* The records of object id (its slot run); removed objects give empty records. */
static size_t object_records(const vw_scene *s, int id, int alive, size_t nslots, rt_object *out)
{
    vw_prim_kind k;
    size_t idx;
    if (!alive || vw_scene_find_object(s, id, &k, &idx) != VW_OK) {
        for (size_t i = 0; i < nslots; i++) rt_object_empty(&out[i]);
        return nslots;
    }
    return rt_object_records(s, k, idx, out);
}

vw_status rt_anim_create(vw_scene *s, const rt_anim_params *p, rt_anim **out, char *err,
                         size_t errlen)
{
    *out = NULL;
    rt_anim *a = calloc(1, sizeof *a);
    rt_object *rec = NULL;
    size_t nrec = 0;
    vw_status st = a ? VW_OK : VW_E_NOMEM;
    if (a) {
        a->full_rebuild = p->full_rebuild;
        a->farm = p->farm;
        a->rebuild_all = 1; /* the first frame builds every cell */
        double lo[3], hi[3], diag = 0;
        vw_scene_bounds(s, lo, hi);
        for (int k = 0; k < 3; k++) diag += (hi[k] - lo[k]) * (hi[k] - lo[k]);
        diag = sqrt(diag);
        if (!(diag > 0)) diag = 1;
        a->scale = diag;
        double margin = p->margin > 0 ? p->margin : 0.25;
        for (int k = 0; k < 3; k++) {
            a->world.lo[k] = lo[k] - margin * diag;
            a->world.hi[k] = hi[k] + margin * diag;
            if (p->world_min) {
                a->world.lo[k] = fmin(a->world.lo[k], p->world_min->lo[k]);
                a->world.hi[k] = fmax(a->world.hi[k], p->world_min->hi[k]);
            }
        }
        if (s->camera.valid)
            a->cam = s->camera;
        else
            vw_scene_default_camera(s, &a->cam);

        /* Records in slot order: object by object, in id order. */
        size_t n = vw_scene_count_objects(s), cap = 0;
        for (size_t id = 0; id < n; id++) {
            vw_prim_kind k;
            size_t idx;
            if (vw_scene_find_object(s, (int)id, &k, &idx) != VW_OK) continue;
            cap += k == VW_PRIM_POLYGON ? (size_t)(s->polygons[idx].count - 2) : 1;
        }
        rec = vw_test_fault("anim-nomem") ? NULL : malloc((cap ? cap : 1) * sizeof *rec);
        if (!rec) st = VW_E_NOMEM;
        for (size_t id = 0; rec && id < n; id++) {
            vw_prim_kind k;
            size_t idx;
            if (vw_scene_find_object(s, (int)id, &k, &idx) != VW_OK) continue;
            nrec += rt_object_records(s, k, idx, rec + nrec);
        }
    }
    if (st != VW_OK) snprintf(err, errlen, "out of memory for the scene's records");
    /* Each process makes its records from its own copy of the scene: all fail, or none
       waits for one in the world's creation (rt_job_create). */
    st = vw_config_agree(p->config, st, err, errlen);
    if (st != VW_OK) {
        free(rec);
        rt_anim_free(a);
        vw_scene_free(s);
        return st;
    }
    rt_params rp;
    memset(&rp, 0, sizeof rp);
    rp.width = p->width;
    rp.height = p->height;
    rp.depth = p->depth;
    memcpy(rp.dims, p->dims, sizeof rp.dims);
    rp.workers = p->workers;
    rp.camera = &a->cam;
    rp.config = p->config;
    rp.world = &a->world;
    rp.scale = a->scale;
    rp.objects = rec;
    rp.nobjects = nrec;
    rp.farm_first = 1; /* (the first frame's rt_job_farm then adds none) */
    rp.farm = p->farm;
    st = rt_job_create(s, &rp, &a->job, err, errlen);
    a->rec = rec;
    a->nrec = a->caprec = nrec;
    if (st != VW_OK) {
        rt_anim_free(a);
        vw_scene_free(s);
        return st;
    }
    vw_dynscene_params dp;
    memset(&dp, 0, sizeof dp);
    dp.decomp = vw_world_decomp(rt_job_world(a->job));
    vw_config cfg = rt_job_config(&rp); /* the dynamic scene runs as the job does */
    dp.config = &cfg;
    dp.brute_force = p->brute_force;
    st = vw_dynscene_create(s, &dp, &a->ds, err, errlen); /* owns s from here */
    if (st != VW_OK) {
        rt_anim_free(a);
        return st;
    }
    *out = a;
    return VW_OK;
}

/* Adds the cells the record's bounds overlap to the touched set (what the world marks
   dirty: the same bounds and pad as its placement). */
static void touch(const vw_decomp *d, const rt_shared *sh, const rt_object *o, unsigned char *mark,
                  int *cells, size_t *ntouched)
{
    vw_box b;
    rt_object_bounds(o, sh->bpad, &b);
    vw_box wb = vw_decomp_world(d);
    double ext = 0;
    for (int k = 0; k < 3; k++) ext = fmax(ext, wb.hi[k] - wb.lo[k]);
    int nc = vw_decomp_cell_count(d);
    int m = vw_decomp_cells_overlapping(d, &b, ext * 1e-9, cells, nc);
    for (int i = 0; i < m && i < nc; i++)
        if (!mark[cells[i]]) {
            mark[cells[i]] = 1;
            ++*ntouched;
        }
}

vw_status rt_anim_apply(rt_anim *a, const vw_edit *edits, size_t n, int check, int sweep,
                        vw_result *results, rt_anim_stats *rs, char *err, size_t errlen)
{
    double t0 = now();
    int *changed = NULL;
    size_t nchanged = 0;
    if (errlen) err[0] = 0;
    vw_status st = vw_dynscene_apply(a->ds, edits, n, check, sweep, results, &changed, &nchanged);
    if (st != VW_OK) {
        /* Failed on every process alike (the dynscene agrees): "rank R: what" becomes
           "rank R: applying edits: what", the form of the agreement below, which would
           name this process instead. */
        vw_errmsg_wrap(err, errlen, "applying edits", vw_dynscene_errmsg(a->ds));
        rs->apply_s += now() - t0;
        return st;
    }
    double t1 = now();
    for (size_t i = 0; i < n; i++) {
        if (results[i].outcome == VW_OUT_ACCEPTED) rs->accepted++;
        else if (results[i].outcome == VW_OUT_COLLISION) rs->collisions++;
        else if (results[i].outcome == VW_OUT_SWEEP) rs->sweeps++;
        else rs->invalid++;
    }
    vw_world *w = rt_job_world(a->job);
    const vw_decomp *d = vw_world_decomp(w);
    const rt_shared *sh = rt_job_shared(a->job);
    const vw_scene *s = vw_dynscene_scene(a->ds);
    int nc = vw_decomp_cell_count(d);
    /* The bookkeeping is this process's own: the marks of the touched cells, and room
       for every changed object's records (the ids and slots are the same everywhere,
       so the room is too). All of it is made here, before the first update of the world
       (collective), and agreed on once a batch: all fail, or none waits for one in an
       update. */
    int *cells = NULL;
    if (st == VW_OK && a->ntouched_cells != nc) {
        /* A new layout (rebalanced): its first frame builds every cell anyway. */
        free(a->touched);
        a->touched = vw_test_fault("anim-apply-nomem") ? NULL : calloc((size_t)nc, 1);
        a->ntouched_cells = a->touched ? nc : 0;
        a->ntouched = 0;
    }
    if (st == VW_OK) cells = malloc(sizeof(int) * (size_t)nc);
    if (st == VW_OK && (!a->touched || !cells)) st = VW_E_NOMEM;
    size_t need = 0;
    for (size_t i = 0; st == VW_OK && i < nchanged; i++) {
        size_t first, ns;
        vw_dynscene_slots(a->ds, changed[i], &first, &ns);
        if (first + ns > need) need = first + ns;
    }
    if (st == VW_OK && need > a->caprec) {
        size_t cap = a->caprec ? a->caprec : 64;
        while (cap < need) cap *= 2;
        rt_object *r =
            vw_test_fault("anim-records-nomem") ? NULL : realloc(a->rec, cap * sizeof *r);
        if (r) {
            a->rec = r;
            a->caprec = cap;
        } else {
            st = VW_E_NOMEM;
        }
    }
    if (st != VW_OK && !err[0])
        snprintf(err, errlen, "applying edits: out of memory for the marks and records");
    st = vw_world_agree(w, st, err, errlen);
    unsigned char *mark = a->touched;
    size_t touched_before = rs->cells_touched;
    for (size_t i = 0; i < nchanged && st == VW_OK; i++) {
        int id = changed[i];
        size_t first, ns;
        vw_dynscene_slots(a->ds, id, &first, &ns);
        for (size_t k = 0; k < ns; k++) /* the cells it leaves */
            if (first + k < a->nrec) touch(d, sh, &a->rec[first + k], mark, cells, &rs->cells_touched);
        object_records(s, id, vw_dynscene_alive(a->ds, id), ns, a->rec + first);
        for (size_t k = 0; k < ns && st == VW_OK; k++) {
            size_t slot = first + k;
            touch(d, sh, &a->rec[slot], mark, cells, &rs->cells_touched); /* the cells it joins */
            /* An added object takes the next slot of the world (the dynscene hands out
               slots in the same order); others are replaced in place. */
            if (slot >= a->nrec) {
                st = vw_world_add_objects(w, &a->rec[slot], 1);
                a->nrec = slot + 1;
            } else {
                st = vw_world_update_object(w, slot, &a->rec[slot]);
            }
            if (st != VW_OK)
                snprintf(err, errlen, "updating the render world: %s", vw_world_errmsg(w));
            rs->records_updated++;
        }
    }
    a->ntouched += rs->cells_touched - touched_before;
    free(cells);
    free(changed);
    rs->apply_s += t1 - t0;
    rs->update_s += now() - t1;
    return st;
}

vw_status rt_anim_render(rt_anim *a, rt_anim_stats *rs, char *err, size_t errlen)
{
    vw_world *w = rt_job_world(a->job);
    vw_status st = VW_OK;
    if (a->full_rebuild) {
        /* The benchmark's baseline: the same decomposition and mapping again, which
           re-places every object and rebuilds every cell. */
        const vw_decomp *d = vw_world_decomp(w);
        int nc = vw_decomp_cell_count(d);
        int *cw = malloc(sizeof(int) * (size_t)nc);
        vw_decomp *copy = NULL;
        st = cw ? vw_decomp_clone(d, &copy) : VW_E_NOMEM;
        for (int c = 0; st == VW_OK && c < nc; c++) cw[c] = vw_world_cell_worker(w, c);
        /* The copies are this process's own; the redecomposition is collective. */
        st = vw_world_agree(w, st, NULL, 0);
        if (st == VW_OK) st = vw_world_redecompose(w, copy, cw);
        vw_decomp_free(copy);
        free(cw);
        if (st != VW_OK) {
            snprintf(err, errlen, "rebuilding: %s", vw_status_message(st));
            return st;
        }
    }
    int nc = vw_decomp_cell_count(vw_world_decomp(w));
    if (rs) rs->cells_rebuilt = a->full_rebuild || a->rebuild_all ? (size_t)nc : a->ntouched;
    if (a->touched) memset(a->touched, 0, (size_t)a->ntouched_cells);
    a->ntouched = 0;
    a->rebuild_all = 0;
    st = rt_job_reset(a->job); /* cells keep their state; run() restarts eye rays */
    double t0 = now();
    /* The workers share the cells as a->farm says; copies follow the objects' edits
       (they read their cell's scene, rebuilt once) and go with a new layout. */
    if (st == VW_OK) st = rt_job_farm(a->job, a->farm, NULL, err, errlen);
    if (st == VW_OK) st = rt_job_commit(a->job, err, errlen);
    double t1 = now();
    if (st == VW_OK) st = rt_job_run(a->job, err, errlen);
    double t2 = now();
    if (rs) {
        rs->build_s = t1 - t0;
        rs->render_s = t2 - t1;
    }
    a->last_lambda = vw_world_imbalance(w);
    a->last_work_lambda = rt_job_work_imbalance(a->job, NULL);
    return st;
}

double rt_anim_imbalance(rt_anim *a) { return a->last_lambda; }
double rt_anim_work_imbalance(rt_anim *a) { return a->last_work_lambda; }

vw_status rt_anim_balance(rt_anim *a, const char *strategy, double *before, double *predicted,
                          char *err, size_t errlen)
{
#if RT_HAVE_BALANCE
    vw_balance_strategy bs;
    if (vw_balance_strategy_parse(strategy, &bs) != VW_OK || bs == VW_BALANCE_DUPLICATE) {
        snprintf(err, errlen, "unknown or unsupported balance strategy '%s'", strategy);
        return VW_E_INVAL;
    }
    if (errlen) err[0] = 0;
    vw_world *w = rt_job_world(a->job);
    int nc = vw_decomp_cell_count(vw_world_decomp(w));
    double *load =
        vw_test_fault("anim-balance-nomem") ? NULL : malloc(sizeof(double) * VW_MAX_CELLS);
    int *cw = malloc(sizeof(int) * VW_MAX_CELLS);
    vw_load_field *f = NULL;
    vw_load_spec ls;
    vw_load_spec_init(&ls);
    ls.model = VW_LOAD_COUNTER;   /* ray-cell visits: deterministic, the same on every */
    ls.counter = RT_C_SEGMENTS;   /* process and every run, unlike busy time */
    vw_status st = load && cw ? vw_balance_cell_loads(w, &ls, load) : VW_E_NOMEM;
    double total = 0;
    for (int c = 0; st == VW_OK && c < nc; c++) total += load[c];
    if (st == VW_OK && total > 0) st = vw_load_field_create(&f);
    if (st == VW_OK && total > 0) st = vw_load_field_add_cells(f, vw_world_decomp(w), load, 4);
    if (st != VW_OK) snprintf(err, errlen, "balancing: the loads: %s", vw_status_message(st));
    /* The arrays and the field are this process's own: all fail, or none waits for one
       in the balance (collective). */
    st = vw_world_agree(w, st, err, errlen);
    /* New walls start with no load measured: until a frame is rendered on them there
       is nothing to balance by (the loads are the job's own, equal on every process,
       so every process returns here alike). */
    if (st == VW_OK && !(total > 0)) {
        if (before) *before = 0;
        if (predicted) *predicted = 0;
        free(load);
        free(cw);
        return VW_OK;
    }
    vw_balance_report rep;
    memset(&rep, 0, sizeof rep);
    if (st == VW_OK && bs != VW_BALANCE_NONE) {
        vw_balance_params bp;
        vw_balance_params_init(&bp);
        bp.strategy = bs;
        vw_balance_apply ap;
        memset(&ap, 0, sizeof ap);
        st = vw_balance_world(w, f, &bp, &ap, &rep);
        if (st != VW_OK) snprintf(err, errlen, "balancing: %s", vw_world_errmsg(w));
        if (st == VW_OK && rep.applied) a->rebuild_all = 1; /* new cells, all built anew */
    }
    if (st == VW_OK) {
        /* The collider follows the render world's new walls and mapping. */
        const vw_decomp *d = vw_world_decomp(w);
        nc = vw_decomp_cell_count(d);
        for (int c = 0; c < nc; c++) cw[c] = vw_world_cell_worker(w, c);
        st = vw_dynscene_redecompose(a->ds, d, cw);
    }
    if (st != VW_OK && !err[0]) snprintf(err, errlen, "balancing: %s", vw_status_message(st));
    if (before) *before = rep.imbalance_before;
    if (predicted) *predicted = rep.imbalance_predicted;
    vw_load_field_free(f);
    free(load);
    free(cw);
    return st;
#else
    (void)a, (void)strategy, (void)before, (void)predicted;
    snprintf(err, errlen, "this build has no load balancer");
    return VW_E_UNSUPPORTED;
#endif
}
