/* load.c - the load model (what one cell's load is) and the load field (where the load
 * lies): point masses made from measured cell loads and re-calibrated by later ones.
 *
 * Cost: a field of n points is located in a decomposition in O(n depth); the balancers
 * sort it a few times, so a field of ~10^5 points costs milliseconds.
 */
#include "balance/balance_internal.h"
#include "core/world_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void vw_load_spec_init(vw_load_spec *s)
{
    memset(s, 0, sizeof *s);
    s->model = VW_LOAD_BUSY;
    s->counter = -1;
    s->w_objects = s->w_pixels = s->w_messages = 1.0;
}

/* Cell c's measured busy time as work: each unit's (the master's, each copy's) busy time
   times its worker's speed, as a fraction of the fastest (a worker three times slower
   takes three times as long for the same rays; the balancers then divide by the speed
   of the worker they plan for). Without speeds, the busy time. */
static double busy_work(const vw_world *w, int c)
{
    const vw__cell *cl = &w->cells[c];
    if (!w->speeds) {
        double s = cl->busy.s;
        for (int r = 0; r < cl->nreps; r++) s += cl->reps[r].busy.s;
        return s;
    }
    double top = 0;
    for (int g = 0; g < w->gworkers; g++) top = w->speeds[g] > top ? w->speeds[g] : top;
    double s = cl->busy.s * (w->speeds[cl->worker] / top);
    for (int r = 0; r < cl->nreps; r++)
        s += cl->reps[r].busy.s * (w->speeds[cl->reps[r].worker] / top);
    return s;
}

vw_status vw_balance_cell_loads(const vw_world *w, const vw_load_spec *s, double *out)
{
    if (!w || !s || !out) return VW_E_INVAL;
    if (s->model == VW_LOAD_COUNTER && (s->counter < 0 || s->counter >= w->m->ncounters))
        return VW_E_INVAL;
    for (int c = 0; c < w->ncells; c++) {
        /* A duplicated cell's load is the sum over its master and copies. */
        vw_cell_stats cs;
        vw_world_cell_stats(w, c, &cs);
        int64_t counter = s->counter >= 0 && s->counter < w->m->ncounters
                              ? vw_world_cell_counter(w, c, s->counter)
                              : 0;
        switch (s->model) {
        case VW_LOAD_BUSY: out[c] = busy_work(w, c); break;
        case VW_LOAD_COUNTER: out[c] = (double)counter; break;
        case VW_LOAD_MODEL:
            out[c] = s->w_objects * (double)cs.objects + s->w_messages * (double)cs.messages_in +
                     s->w_pixels * (double)counter;
            break;
        default: return VW_E_INVAL;
        }
    }
    return VW_OK;
}

double vw_balance_imbalance(const double *cell_load, const int *cell_worker, int ncells,
                            int gworkers, const double *speeds)
{
    if (gworkers < 1) return 1.0;
    /* A worker of speed 0 never finishes its share: no finite lambda describes that,
       and dividing by it gave inf / inf = NaN, which every comparison a caller makes
       (lambda <= 1 + tolerance, predicted < before) takes as false. vw__lambda says
       INFINITY for it, as for a negative, NaN or infinite load. */
    double *t = calloc((size_t)gworkers, sizeof *t);
    if (!t) return 0;
    for (int c = 0; c < ncells; c++) {
        int g = cell_worker ? cell_worker[c] : c % gworkers;
        if (g >= 0 && g < gworkers) t[g] += cell_load[c];
    }
    double lam = vw__lambda(t, speeds, gworkers);
    free(t);
    return lam;
}

/* ---- the field ------------------------------------------------------------------------ */

vw_status vw_load_field_create(vw_load_field **out)
{
    if (!out) return VW_E_INVAL;
    *out = calloc(1, sizeof **out);
    return *out ? VW_OK : VW_E_NOMEM;
}

void vw_load_field_free(vw_load_field *f)
{
    if (!f) return;
    free(f->p);
    free(f->w);
    free(f);
}

vw_status vw_load_field_add_point(vw_load_field *f, const double p[3], double w)
{
    /* A point that is nowhere still counted in the balancers' totals: one NaN point of
       weight 100 beside a uniform load of 4 squeezed every tensor wall to min_width. */
    if (!f || !p || !(w >= 0) || !isfinite(w)) return VW_E_INVAL;
    if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) return VW_E_INVAL;
    if (f->n == f->cap) {
        size_t cap = f->cap ? 2 * f->cap : 1024;
        double(*np)[3] = realloc(f->p, cap * sizeof *np);
        if (!np) return VW_E_NOMEM;
        f->p = np;
        double *nw = realloc(f->w, cap * sizeof *nw);
        if (!nw) return VW_E_NOMEM;
        f->w = nw;
        f->cap = cap;
    }
    memcpy(f->p[f->n], p, sizeof f->p[0]);
    f->w[f->n++] = w;
    return VW_OK;
}

/* k^3 points of weight load/k^3 at the centres of a k-sub-grid of cell c (frame box ->
   world coordinates: vw_decomp_from_frame). */
static vw_status add_uniform(vw_load_field *f, const vw_decomp *d, int c, double load, int k)
{
    vw_box b = vw_decomp_cell_box(d, c);
    double w = load / ((double)k * k * k);
    for (int i = 0; i < k; i++)
        for (int j = 0; j < k; j++)
            for (int l = 0; l < k; l++) {
                double q[3], p[3];
                int ix[3] = {i, j, l};
                for (int a = 0; a < 3; a++)
                    q[a] = b.lo[a] + (b.hi[a] - b.lo[a]) * ((double)ix[a] + 0.5) / k;
                vw_decomp_from_frame(d, q, p);
                vw_status st = vw_load_field_add_point(f, p, w);
                if (st != VW_OK) return st;
            }
    return VW_OK;
}

vw_status vw_load_field_add_cells(vw_load_field *f, const vw_decomp *d, const double *cell_load,
                                  int k)
{
    if (!f || !d || !cell_load || k < 1 || k > 64) return VW_E_INVAL;
    for (int c = 0; c < vw_decomp_cell_count(d); c++) {
        if (!(cell_load[c] > 0)) continue;
        vw_status st = add_uniform(f, d, c, cell_load[c], k);
        if (st != VW_OK) return st;
    }
    return VW_OK;
}

/* The cell of each point (-1 outside d's world). */
static int *locate_all(const vw_load_field *f, const vw_decomp *d)
{
    int *cell = malloc((f->n ? f->n : 1) * sizeof *cell);
    if (!cell) return NULL;
    for (size_t i = 0; i < f->n; i++) cell[i] = vw_decomp_locate(d, f->p[i], NULL);
    return cell;
}

void vw_load_field_cell_loads(const vw_load_field *f, const vw_decomp *d, double *out)
{
    int nc = vw_decomp_cell_count(d);
    for (int c = 0; c < nc; c++) out[c] = 0;
    if (!f) return;
    for (size_t i = 0; i < f->n; i++) {
        int c = vw_decomp_locate(d, f->p[i], NULL);
        if (c >= 0) out[c] += f->w[i];
    }
}

vw_status vw_load_field_calibrate(vw_load_field *f, const vw_decomp *d, const double *cell_load,
                                  int k)
{
    if (!f || !d || !cell_load || k < 1 || k > 64) return VW_E_INVAL;
    int nc = vw_decomp_cell_count(d);
    /* An infinite load would scale its cell's points to infinite weights (which
       add_point refuses); checked before the field is touched. */
    for (int c = 0; c < nc; c++)
        if (cell_load[c] == INFINITY) return VW_E_INVAL;
    double *pred = calloc((size_t)nc, sizeof *pred);
    int *cell = locate_all(f, d);
    if (!pred || !cell) {
        free(pred);
        free(cell);
        return VW_E_NOMEM;
    }
    for (size_t i = 0; i < f->n; i++)
        if (cell[i] >= 0) pred[cell[i]] += f->w[i];
    /* The measurement wins where it disagrees: scale inside each cell. A cell the old
       field thought empty gets uniform points. */
    for (size_t i = 0; i < f->n; i++) {
        int c = cell[i];
        if (c >= 0 && pred[c] > 0) f->w[i] *= (cell_load[c] > 0 ? cell_load[c] : 0) / pred[c];
    }
    size_t nold = f->n;
    vw_status st = VW_OK;
    for (int c = 0; c < nc && st == VW_OK; c++)
        if (!(pred[c] > 0) && cell_load[c] > 0) st = add_uniform(f, d, c, cell_load[c], k);
    (void)nold;
    free(pred);
    free(cell);
    return st;
}

double vw_load_field_total(const vw_load_field *f)
{
    double s = 0;
    for (size_t i = 0; f && i < f->n; i++) s += f->w[i];
    return s;
}

size_t vw_load_field_points(const vw_load_field *f) { return f ? f->n : 0; }

long vw__field_points(const vw_load_field *f, const double *F, vw__lpt **out)
{
    *out = NULL;
    if (!f || f->n == 0) return 0;
    vw__lpt *pts = malloc(f->n * sizeof *pts);
    if (!pts) return -1;
    long m = 0;
    for (size_t i = 0; i < f->n; i++) {
        if (!(f->w[i] > 0)) continue;
        const double *p = f->p[i];
        for (int a = 0; a < 3; a++)
            pts[m].x[a] = F ? F[3 * a] * p[0] + F[3 * a + 1] * p[1] + F[3 * a + 2] * p[2] : p[a];
        pts[m].w = f->w[i];
        m++;
    }
    *out = pts;
    return m;
}

/* ---- the weighted-quantile cut -------------------------------------------------------- */

/* One comparator per axis, not one reading the axis from a file-static variable:
   vw_balance_decompose is public, and two threads balancing two worlds at once set
   each other's axis in the middle of a sort (a tensor balance then came out wrong in
   about one call of ten). */
#define CMP_AXIS(name, a)                                                                 \
    static int name(const void *p, const void *q)                                         \
    {                                                                                     \
        double x = ((const vw__lpt *)p)->x[a], y = ((const vw__lpt *)q)->x[a];            \
        return x < y ? -1 : x > y;                                                        \
    }
CMP_AXIS(cmp_x, 0)
CMP_AXIS(cmp_y, 1)
CMP_AXIS(cmp_z, 2)

/* Walls keep at least minw apart and from lo and hi: forward from lo, then backward from
   hi (which wins when the box is too small for both). Where minw is below the spacing of
   the doubles there (a box a few units in the last place wide: a scene far from the
   origin for its size), prev + minw rounds to prev, and walls came out equal, which no
   decomposition takes; so a wall is also at least the next double past its neighbour.
   1 when lo < walls[0] < ... < walls[parts-2] < hi. */
static int clamp_walls(double *walls, int parts, double lo, double hi, double minw)
{
    double prev = lo;
    for (int k = 0; k < parts - 1; k++) {
        if (!(walls[k] >= prev + minw)) walls[k] = prev + minw;
        if (!(walls[k] > prev)) walls[k] = nextafter(prev, INFINITY);
        prev = walls[k];
    }
    double next = hi;
    for (int k = parts - 2; k >= 0; k--) {
        if (!(walls[k] <= next - minw)) walls[k] = next - minw;
        if (!(walls[k] < next)) walls[k] = nextafter(next, -INFINITY);
        next = walls[k];
    }
    return next > lo;
}

int vw__cut(vw__lpt *pts, long n, int axis, double lo, double hi, int parts, double minw,
            double *walls)
{
    return vw__cut_shares(pts, n, axis, lo, hi, parts, NULL, minw, walls);
}

int vw__cut_shares(vw__lpt *pts, long n, int axis, double lo, double hi, int parts,
                   const double *share, double minw, double *walls)
{
    if (parts < 2) return 1;
    /* The pieces' shares of the load, as fractions of their sum (equal without them, or
       when they sum to no positive number). */
    double ssum = 0;
    for (int k = 0; share && k < parts; k++) ssum += share[k] > 0 ? share[k] : 0;
    if (!(ssum > 0) || !isfinite(ssum)) share = NULL;
    if (n > 1) qsort(pts, (size_t)n, sizeof *pts, axis == 0 ? cmp_x : axis == 1 ? cmp_y : cmp_z);
    /* Points with equal coordinates form one group (a cell's k x k sub-grid points share
       their x): each group's mass is spread evenly between the midpoints to the groups
       beside it, so the cumulative load is piecewise linear, as for uniform cells. */
    double *gx = malloc(sizeof(double) * (size_t)(n ? n : 1));
    double *gw = malloc(sizeof(double) * (size_t)(n ? n : 1));
    long ng = 0;
    double total = 0;
    for (long i = 0; gx && gw && i < n; i++) {
        if (ng && pts[i].x[axis] == gx[ng - 1]) {
            gw[ng - 1] += pts[i].w;
        } else {
            gx[ng] = pts[i].x[axis];
            gw[ng++] = pts[i].w;
        }
        total += pts[i].w;
    }
    long i = 0;
    double cum = 0, before = 0; /* before: the shares of the pieces below wall k */
    for (int k = 1; k < parts; k++) {
        before += share ? (share[k - 1] > 0 ? share[k - 1] : 0) / ssum : 1.0 / parts;
        double frac = fmin(1.0, before);
        double target = share ? total * frac : total * k / parts, x;
        if (!(total > 0) || !gx || !gw) {
            /* no load known here: widths in proportion to the shares */
            x = share ? lo + (hi - lo) * frac : lo + (hi - lo) * k / parts;
        } else {
            while (i < ng && cum + gw[i] < target) cum += gw[i++];
            if (i >= ng) i = ng - 1, cum = total - gw[i];
            double a = i > 0 ? 0.5 * (gx[i - 1] + gx[i]) : lo;
            double b = i + 1 < ng ? 0.5 * (gx[i] + gx[i + 1]) : hi;
            /* The outermost groups reach as far from their point as on the inner side. */
            if (i == 0 && i + 1 < ng) a = fmax(lo, gx[0] - (b - gx[0]));
            if (i + 1 >= ng && i > 0) b = fmin(hi, gx[i] + (gx[i] - a));
            double f = gw[i] > 0 ? (target - cum) / gw[i] : 0.5;
            x = a + fmin(1.0, fmax(0.0, f)) * (b - a);
        }
        walls[k - 1] = x;
    }
    free(gx);
    free(gw);
    /* Walls never cross and keep minw apart and from the world's faces. */
    if (minw * parts > hi - lo) minw = (hi - lo) / parts * 0.5;
    if (!(minw >= 0)) minw = 0;
    if (clamp_walls(walls, parts, lo, hi, minw)) return 1;
    /* minw, rounded at the walls' magnitude, can still ask more than the box has: one
       double apart is all a wall needs. Without minw the clamp fails only when fewer
       than parts - 1 doubles lie strictly between lo and hi. */
    return clamp_walls(walls, parts, lo, hi, 0);
}
