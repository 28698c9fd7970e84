/* kdtree.c - every decomposition is a kd-tree of walls over the world box.
 *
 * The tree gives point location, the cells a ray crosses (with their parameter
 * intervals), face neighbours, front-to-back order and object placement. A ray walk
 * computes the crossing parameter of a wall as (split - o[a]) / d[a] and nothing else,
 * so the exit parameter of one cell is bit-for-bit the entry parameter of the next,
 * and a walk restarted at any exit parameter splits the rest of the ray identically.
 */
#include "decomp/decomp_internal.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *vw_decomp_kind_name(vw_decomp_kind k)
{
    switch (k) {
    case VW_DECOMP_GRID: return "grid";
    case VW_DECOMP_STAGGERED: return "staggered";
    case VW_DECOMP_DIVIDED: return "divided";
    }
    return "unknown";
}

/* ---- construction -------------------------------------------------------------- */

/* Computes the cell boxes top-down and checks that the tree is a tree: every node
   reached once, splits strictly inside their node's box, cell ids a permutation. */
static int kd_check(vw_decomp *d, int node, vw_box box, int depth, unsigned char *seen)
{
    if (node < 0 || node >= d->nnodes || seen[node] || depth > 200) return 0;
    seen[node] = 1;
    const vw_kd_node *n = &d->nodes[node];
    if (n->axis < 0) {
        if (n->cell < 0 || n->cell >= d->ncells || d->cell_leaf[n->cell] >= 0) return 0;
        d->cell_leaf[n->cell] = node;
        d->cell_box[n->cell] = box;
        return 1;
    }
    if (n->axis > 2 || !isfinite(n->split)) return 0;
    if (!(n->split > box.lo[n->axis] && n->split < box.hi[n->axis])) return 0;
    vw_box l = box, r = box;
    l.hi[n->axis] = n->split;
    r.lo[n->axis] = n->split;
    return kd_check(d, n->left, l, depth + 1, seen) && kd_check(d, n->right, r, depth + 1, seen);
}

static void build_neighbours(vw_decomp *d);

/* vw_decomp_create_kd for every kind; the grid constructor adds its dims and walls. */
static vw_status kd_create(const vw_box *world, const vw_kd_node *nodes, int nnodes,
                           const double *frame, vw_decomp_kind kind, vw_decomp **out)
{
    if (!out) return VW_E_INVAL;
    *out = NULL;
    if (!world || !nodes || nnodes < 1) return VW_E_INVAL;
    for (int a = 0; a < 3; a++)
        if (!(world->lo[a] < world->hi[a]) || !isfinite(world->lo[a]) || !isfinite(world->hi[a]))
            return VW_E_INVAL;
    int ncells = 0;
    for (int i = 0; i < nnodes; i++)
        if (nodes[i].axis < 0) ncells++;
    if (ncells < 1 || ncells > VW_MAX_CELLS) return VW_E_LIMIT;

    vw_decomp *d = calloc(1, sizeof *d);
    if (!d) return VW_E_NOMEM;
    static _Atomic uint64_t drawn; /* (the last number drawn: see vw_decomp.same_as) */
    atomic_init(&d->same_as, atomic_fetch_add_explicit(&drawn, 1, memory_order_relaxed) + 1);
    d->kind = kind;
    d->world = *world;
    d->nnodes = nnodes;
    d->ncells = ncells;
    d->nodes = malloc(sizeof *d->nodes * (size_t)nnodes);
    d->cell_box = malloc(sizeof *d->cell_box * (size_t)ncells);
    d->cell_leaf = malloc(sizeof *d->cell_leaf * (size_t)ncells);
    unsigned char *seen = calloc((size_t)nnodes, 1);
    if (!d->nodes || !d->cell_box || !d->cell_leaf || !seen) {
        free(seen);
        vw_decomp_free(d);
        return VW_E_NOMEM;
    }
    memcpy(d->nodes, nodes, sizeof *d->nodes * (size_t)nnodes);
    for (int c = 0; c < ncells; c++) d->cell_leaf[c] = -1;
    int ok = kd_check(d, 0, d->world, 0, seen);
    for (int i = 0; ok && i < nnodes; i++) ok = seen[i];
    free(seen);
    if (!ok) {
        vw_decomp_free(d);
        return VW_E_INVAL;
    }
    if (frame) {
        /* Orthonormal rows, so that t is preserved: |F d| = |d|. */
        for (int i = 0; i < 3 && ok; i++)
            for (int j = 0; j < 3; j++) {
                double dot = 0;
                for (int k = 0; k < 3; k++) dot += frame[3 * i + k] * frame[3 * j + k];
                if (!(fabs(dot - (i == j)) <= 1e-9)) ok = 0; /* NaN too */
            }
        if (!ok) {
            vw_decomp_free(d);
            return VW_E_INVAL;
        }
        int identity = 1;
        for (int k = 0; k < 9; k++)
            if (frame[k] != ((k % 4) == 0 ? 1.0 : 0.0)) identity = 0;
        if (!identity) {
            d->has_frame = 1;
            memcpy(d->frame, frame, sizeof d->frame);
        }
    }
    d->dims[0] = ncells;
    d->dims[1] = d->dims[2] = 1;
    build_neighbours(d);
    if (!d->nb_start) {
        vw_decomp_free(d);
        return VW_E_NOMEM;
    }
    *out = d;
    return VW_OK;
}

vw_status vw_decomp_create_kd(const vw_box *world, const vw_kd_node *nodes, int nnodes,
                              const double *frame, vw_decomp_kind kind, vw_decomp **out)
{
    /* A grid knows its walls per axis (vw_decomp_grid_walls, the tensor balancer, the
       clone rebuilds it from them); a tree given here has none, so it cannot be one. */
    if (kind != VW_DECOMP_STAGGERED && kind != VW_DECOMP_DIVIDED) {
        if (out) *out = NULL;
        return VW_E_INVAL;
    }
    return kd_create(world, nodes, nnodes, frame, kind, out);
}

/* Appends the nodes splitting axis `axis` of grid index range [i0, i1) with boundary
   positions b; below each slab, recurses into the next axis. Returns the node index. */
static int grid_build(vw_kd_node *nodes, int *nn, const int dims[3], const double *b[3],
                      int axis, int i0, int i1, int idx[3])
{
    int me = (*nn)++;
    if (i1 - i0 > 1) {
        int mid = (i0 + i1) / 2;
        nodes[me].axis = axis;
        nodes[me].split = b[axis][mid];
        nodes[me].cell = -1;
        int l = grid_build(nodes, nn, dims, b, axis, i0, mid, idx);
        int r = grid_build(nodes, nn, dims, b, axis, mid, i1, idx);
        nodes[me].left = l;
        nodes[me].right = r;
        return me;
    }
    idx[axis] = i0;
    if (axis == 2) {
        nodes[me].axis = -1;
        nodes[me].cell = idx[0] + dims[0] * (idx[1] + dims[1] * idx[2]);
        nodes[me].left = nodes[me].right = -1;
        return me;
    }
    (*nn)--; /* this slab is not a node of its own: the next axis starts here */
    return grid_build(nodes, nn, dims, b, axis + 1, 0, dims[axis + 1], idx);
}

vw_status vw_decomp_create_grid_walls(const vw_box *world, const int dims[3],
                                      const double *const walls[3], const double *frame,
                                      vw_decomp **out)
{
    if (!out) return VW_E_INVAL;
    *out = NULL;
    if (!world || !dims) return VW_E_INVAL;
    long ncells = 1;
    for (int a = 0; a < 3; a++) {
        if (dims[a] < 1) return VW_E_INVAL;
        ncells *= dims[a];
        if (ncells > VW_MAX_CELLS) return VW_E_LIMIT;
    }
    double *b[3] = {0};
    vw_status st = VW_OK;
    for (int a = 0; a < 3 && st == VW_OK; a++) {
        b[a] = malloc(sizeof(double) * (size_t)(dims[a] + 1));
        if (!b[a]) {
            st = VW_E_NOMEM;
            break;
        }
        b[a][0] = world->lo[a];
        b[a][dims[a]] = world->hi[a];
        for (int i = 1; i < dims[a]; i++) {
            double f = (double)i / dims[a];
            b[a][i] = walls && walls[a] ? walls[a][i - 1]
                                        : world->lo[a] * (1.0 - f) + world->hi[a] * f;
        }
        for (int i = 0; i < dims[a]; i++)
            if (!(b[a][i] < b[a][i + 1])) st = VW_E_INVAL;
    }
    vw_kd_node *nodes = NULL;
    if (st == VW_OK) {
        nodes = calloc((size_t)(2 * ncells), sizeof *nodes);
        if (!nodes) st = VW_E_NOMEM;
    }
    if (st == VW_OK) {
        int nn = 0, idx[3] = {0, 0, 0};
        const double *cb[3] = {b[0], b[1], b[2]};
        grid_build(nodes, &nn, dims, cb, 0, 0, dims[0], idx);
        st = kd_create(world, nodes, nn, frame, VW_DECOMP_GRID, out);
    }
    if (st == VW_OK) {
        vw_decomp *d = *out;
        for (int a = 0; a < 3; a++) {
            d->dims[a] = dims[a];
            d->walls[a] = malloc(sizeof(double) * (size_t)(dims[a] > 1 ? dims[a] - 1 : 1));
            if (!d->walls[a]) {
                vw_decomp_free(d);
                *out = NULL;
                st = VW_E_NOMEM;
                break;
            }
            for (int i = 1; i < dims[a]; i++) d->walls[a][i - 1] = b[a][i];
        }
    }
    free(nodes);
    for (int a = 0; a < 3; a++) free(b[a]);
    return st;
}

vw_status vw_decomp_create_grid(const vw_box *world, const int dims[3], vw_decomp **out)
{
    return vw_decomp_create_grid_walls(world, dims, NULL, NULL, out);
}

/* A copy of n elements of `size` bytes (at least one, so that an empty array is not
   taken for a failed allocation). */
static void *dup_array(const void *p, size_t n, size_t size)
{
    void *q = malloc(size * (n ? n : 1));
    if (q && n) memcpy(q, p, size * n);
    return q;
}

/* A copy, not a rebuild: the same tree gives the same cell boxes, neighbour lists and
   walk steps, so they are copied too (building them again cost most of the ray tracer's
   load phase at 32x32x32 cells, for two clones a render). The clone takes d's number,
   so every later comparison of the two, or of their clones, is immediate. */
vw_status vw_decomp_clone(const vw_decomp *d, vw_decomp **out)
{
    if (!d || !out) return VW_E_INVAL;
    *out = NULL;
    vw_decomp *c = calloc(1, sizeof *c);
    if (!c) return VW_E_NOMEM;
    atomic_init(&c->same_as, atomic_load_explicit(&d->same_as, memory_order_relaxed));
    c->kind = d->kind;
    c->world = d->world;
    c->has_frame = d->has_frame;
    memcpy(c->frame, d->frame, sizeof c->frame);
    c->nnodes = d->nnodes;
    c->ncells = d->ncells;
    memcpy(c->dims, d->dims, sizeof c->dims);
    c->max_nb = d->max_nb;
    size_t n = (size_t)d->ncells;
    c->nodes = dup_array(d->nodes, (size_t)d->nnodes, sizeof *c->nodes);
    c->cell_box = dup_array(d->cell_box, n, sizeof *c->cell_box);
    c->cell_leaf = dup_array(d->cell_leaf, n, sizeof *c->cell_leaf);
    c->nb_start = dup_array(d->nb_start, 6 * n + 1, sizeof *c->nb_start);
    c->nb = dup_array(d->nb, (size_t)d->nb_start[6 * n], sizeof *c->nb);
    c->face_step = dup_array(d->face_step, 6 * n, sizeof *c->face_step);
    int ok = c->nodes && c->cell_box && c->cell_leaf && c->nb_start && c->nb && c->face_step;
    for (int a = 0; a < 3 && ok; a++)
        if (d->walls[a]) {
            c->walls[a] = dup_array(d->walls[a], (size_t)(d->dims[a] - 1), sizeof(double));
            ok = c->walls[a] != NULL;
        }
    if (!ok) {
        vw_decomp_free(c);
        return VW_E_NOMEM;
    }
    *out = c;
    return VW_OK;
}

int vw_decomp_equal(const vw_decomp *a, const vw_decomp *b)
{
    if (!a || !b) return a == b;
    uint64_t na = atomic_load_explicit(&a->same_as, memory_order_relaxed);
    uint64_t nb = atomic_load_explicit(&b->same_as, memory_order_relaxed);
    if (a == b || na == nb) return 1;
    /* Doubles compared as bits: -0.0 and 0.0 could round a walk differently. */
    if (a->nnodes != b->nnodes || a->has_frame != b->has_frame) return 0;
    if (memcmp(&a->world, &b->world, sizeof a->world) != 0) return 0;
    if (a->has_frame && memcmp(a->frame, b->frame, sizeof a->frame) != 0) return 0;
    for (int i = 0; i < a->nnodes; i++) {
        const vw_kd_node *p = &a->nodes[i], *q = &b->nodes[i];
        if (p->axis != q->axis || p->left != q->left || p->right != q->right ||
            p->cell != q->cell ||
            (p->axis >= 0 && memcmp(&p->split, &q->split, sizeof p->split) != 0))
            return 0;
    }
    /* Equal: both take the lower number, so the next comparison is immediate. The
       decompositions are the caller's const, but only this field changes, and it does
       not change what any query answers. */
    uint64_t n = na < nb ? na : nb;
    atomic_store_explicit(&((vw_decomp *)a)->same_as, n, memory_order_relaxed);
    atomic_store_explicit(&((vw_decomp *)b)->same_as, n, memory_order_relaxed);
    return 1;
}

void vw_decomp_free(vw_decomp *d)
{
    if (!d) return;
    free(d->nodes);
    free(d->cell_box);
    free(d->cell_leaf);
    free(d->nb_start);
    free(d->nb);
    free(d->face_step);
    for (int a = 0; a < 3; a++) free(d->walls[a]);
    free(d);
}

/* ---- queries -------------------------------------------------------------------- */

vw_decomp_kind vw_decomp_get_kind(const vw_decomp *d) { return d->kind; }
int vw_decomp_cell_count(const vw_decomp *d) { return d ? d->ncells : 0; }
void vw_decomp_dims(const vw_decomp *d, int dims[3]) { memcpy(dims, d->dims, sizeof d->dims); }
vw_box vw_decomp_world(const vw_decomp *d) { return d->world; }
const double *vw_decomp_frame(const vw_decomp *d) { return d->has_frame ? d->frame : NULL; }

const double *vw_decomp_grid_walls(const vw_decomp *d, int axis)
{
    if (!d || d->kind != VW_DECOMP_GRID || axis < 0 || axis > 2 || d->dims[axis] < 2) return NULL;
    return d->walls[axis];
}

const vw_kd_node *vw_decomp_nodes(const vw_decomp *d, int *nnodes)
{
    if (nnodes) *nnodes = d->nnodes;
    return d->nodes;
}

vw_box vw_decomp_cell_box(const vw_decomp *d, int cell)
{
    if (cell < 0 || cell >= d->ncells) {
        vw_box empty = {{0, 0, 0}, {0, 0, 0}};
        return empty;
    }
    return d->cell_box[cell];
}

void vw_decomp_layout_string(const vw_decomp *d, char *buf, size_t len)
{
    if (d->kind == VW_DECOMP_GRID)
        snprintf(buf, len, "%dx%dx%d", d->dims[0], d->dims[1], d->dims[2]);
    else
        snprintf(buf, len, "%d", d->ncells);
}

void vw_decomp_from_frame(const vw_decomp *d, const double q[3], double out[3])
{
    if (!d->has_frame) {
        out[0] = q[0], out[1] = q[1], out[2] = q[2];
        return;
    }
    const double *F = d->frame;
    double x = q[0], y = q[1], z = q[2];
    for (int a = 0; a < 3; a++) out[a] = F[0 * 3 + a] * x + F[1 * 3 + a] * y + F[2 * 3 + a] * z;
}

void vw_decomp_to_frame(const vw_decomp *d, const double p[3], double out[3])
{
    if (!d->has_frame) {
        out[0] = p[0], out[1] = p[1], out[2] = p[2];
        return;
    }
    const double *F = d->frame;
    double x = p[0], y = p[1], z = p[2];
    for (int i = 0; i < 3; i++) out[i] = F[3 * i] * x + F[3 * i + 1] * y + F[3 * i + 2] * z;
}

void vw_decomp_box_to_frame(const vw_decomp *d, const vw_box *b, vw_box *out)
{
    if (!d->has_frame) {
        *out = *b;
        return;
    }
    vw_box r;
    for (int a = 0; a < 3; a++) r.lo[a] = INFINITY, r.hi[a] = -INFINITY;
    for (int c = 0; c < 8; c++) {
        double p[3] = {(c & 1) ? b->hi[0] : b->lo[0], (c & 2) ? b->hi[1] : b->lo[1],
                       (c & 4) ? b->hi[2] : b->lo[2]};
        double q[3];
        vw_decomp_to_frame(d, p, q);
        for (int a = 0; a < 3; a++) {
            if (q[a] < r.lo[a]) r.lo[a] = q[a];
            if (q[a] > r.hi[a]) r.hi[a] = q[a];
        }
    }
    *out = r;
}

int vw_decomp_locate(const vw_decomp *d, const double p[3], const double dir[3])
{
    double q[3], v[3] = {0, 0, 0};
    vw_decomp_to_frame(d, p, q);
    if (dir) vw_decomp_to_frame(d, dir, v);
    for (int a = 0; a < 3; a++)
        if (!(q[a] >= d->world.lo[a] && q[a] <= d->world.hi[a])) return -1;
    int node = 0;
    while (d->nodes[node].axis >= 0) {
        const vw_kd_node *n = &d->nodes[node];
        int a = n->axis;
        int right = q[a] > n->split || (q[a] == n->split && v[a] >= 0);
        node = right ? n->right : n->left;
    }
    return d->nodes[node].cell;
}

/* ---- the ray walk ---------------------------------------------------------------- */

typedef struct walk_state {
    const vw_decomp *d;
    const double *o, *v;
    vw_segment_fn fn;
    void *user;
    int count, stop;
} walk_state;

static void walk(walk_state *w, int node, double t0, double t1)
{
    const vw_kd_node *n = &w->d->nodes[node];
    if (n->axis < 0) {
        if (t0 < t1) {
            vw_segment s = {n->cell, t0, t1};
            w->count++;
            if (!w->fn(&s, w->user)) w->stop = 1;
        }
        return;
    }
    int a = n->axis;
    if (w->v[a] == 0) {
        walk(w, w->o[a] < n->split ? n->left : n->right, t0, t1);
        return;
    }
    double ts = (n->split - w->o[a]) / w->v[a];
    int near = w->v[a] > 0 ? n->left : n->right;
    int far = w->v[a] > 0 ? n->right : n->left;
    if (t0 < ts) walk(w, near, t0, t1 < ts ? t1 : ts);
    if (!w->stop && ts < t1) walk(w, far, t0 > ts ? t0 : ts, t1);
}

/* Clips [*t0p, *t1p] to the world box (slab test), in frame coordinates; 0 when the
   ray misses it. Every walk clips with this one function, so all agree bit for bit.
   Along an axis where the origin lies inside the box, the entry parameter is <= 0, so
   it cannot raise a t0 >= 0 and is not computed: for a ray that starts inside (every
   secondary ray) that saves three of the six divisions, with the same result. */
static int clip(const vw_decomp *d, const double q[3], const double v[3], double *t0p,
                double *t1p)
{
    double t0 = *t0p, t1 = *t1p;
    for (int a = 0; a < 3; a++) {
        double lo = d->world.lo[a], hi = d->world.hi[a];
        if (v[a] == 0) {
            if (q[a] < lo || q[a] > hi) return 0;
            continue;
        }
        double near = v[a] > 0 ? lo : hi, far = v[a] > 0 ? hi : lo;
        if (!(t0 >= 0 && q[a] >= lo && q[a] <= hi)) {
            double ta = (near - q[a]) / v[a];
            if (ta > t0) t0 = ta;
        }
        double tb = (far - q[a]) / v[a];
        if (tb < t1) t1 = tb;
    }
    *t0p = t0;
    *t1p = t1;
    return t0 < t1;
}

/* The walk of the ray q + t v given in frame coordinates. */
static int walk_frame(const vw_decomp *d, const double q[3], const double v[3], double t0,
                      double t1, vw_segment_fn fn, void *user)
{
    if (!clip(d, q, v, &t0, &t1)) return 0;
    walk_state w = {d, q, v, fn, user, 0, 0};
    walk(&w, 0, t0, t1);
    return w.count;
}

int vw_decomp_walk(const vw_decomp *d, const double o[3], const double dir[3], double t0,
                   double t1, vw_segment_fn fn, void *user)
{
    double q[3], v[3];
    vw_decomp_to_frame(d, o, q);
    vw_decomp_to_frame(d, dir, v);
    return walk_frame(d, q, v, t0, t1, fn, user);
}

static int first_fn(const vw_segment *s, void *user)
{
    *(vw_segment *)user = *s;
    return 0;
}

static void ray_to_frame(const vw_decomp *d, const double o[3], const double dir[3],
                         double q[3], double v[3])
{
    if (d->has_frame) {
        vw_decomp_to_frame(d, o, q);
        vw_decomp_to_frame(d, dir, v);
    } else {
        q[0] = o[0], q[1] = o[1], q[2] = o[2];
        v[0] = dir[0], v[1] = dir[1], v[2] = dir[2];
    }
}


/* The first segment is the first leaf of the walk, and the walk reaches it by one
   descent: at a node the near child is taken whenever t0 < ts, and a subtree entered
   with t0 < t1 always yields a segment, so the recursion never backtracks. This loop
   makes that descent with the walk's own arithmetic (the same (split - o[a]) / d[a],
   the same min/max), so it returns the walk's first segment bit for bit, at a fraction
   of its cost: it runs for every wall a ray crosses. Only a NaN can make the descent
   fail (both comparisons false); the walk itself then decides. [t0, t1] is clipped.
   Inlined into its two callers: the call alone was ~1% of a 2x2x2 render's
   instructions. */
static inline __attribute__((always_inline)) int
descend(const vw_decomp *d, const double q[3], const double v[3], double t0, double t1,
        vw_segment *out, double exit[3])
{
    const double t0_in = t0, t1_in = t1;
    const vw_kd_node *nodes = d->nodes, *n = &nodes[0];
    while (n->axis >= 0) {
        int a = n->axis;
        if (v[a] == 0) {
            n = &nodes[q[a] < n->split ? n->left : n->right];
            continue;
        }
        double ts = (n->split - q[a]) / v[a];
        if (t0 < ts) {
            n = &nodes[v[a] > 0 ? n->left : n->right];
            t1 = t1 < ts ? t1 : ts;
            if (exit && ts < exit[a]) exit[a] = ts;
        } else if (ts < t1) {
            n = &nodes[v[a] > 0 ? n->right : n->left];
            t0 = t0 > ts ? t0 : ts;
        } else {
            return walk_frame(d, q, v, t0_in, t1_in, first_fn, out) > 0 ? 2 : 0;
        }
    }
    if (!(t0 < t1)) return walk_frame(d, q, v, t0_in, t1_in, first_fn, out) > 0 ? 2 : 0;
    out->cell = n->cell;
    out->t0 = t0;
    out->t1 = t1;
    return 1;
}

int vw_decomp_first_segment(const vw_decomp *d, const double o[3], const double dir[3],
                            double t0, double t1, vw_segment *out)
{
    double q[3], v[3];
    ray_to_frame(d, o, dir, q, v);
    if (!clip(d, q, v, &t0, &t1)) return 0;
    return descend(d, q, v, t0, t1, out, NULL) != 0;
}

/* From inside the world box every ray's walk starts in the cell that holds o. From
   outside, the rays of a cone all enter the world through the face of the world box that the
   first generator's ray enters by, and inside one cell's piece of that face, when each
   generator crosses the face's plane inside the face, a margin away from its edges,
   and the rectangle those crossings span lies a margin away from every wall: a central
   projection maps segments to segments, so every ray of the cone crosses the plane in
   the crossings' convex hull, inside that rectangle; and a ray from outside the box
   that crosses a face's plane inside the face enters the box there. The margin (1e-9
   of the coordinates' magnitude) is a million times the rounding of the crossings, so
   the per-ray walk agrees with the answer (a ray on a wall is no concern: no rectangle
   within the margin of one is accepted). */
int vw_decomp_cone_cell(const vw_decomp *d, const double o[3], const double (*dirs)[3], int n)
{
    if (n < 1) return -1;
    double q[3];
    vw_decomp_to_frame(d, o, q);
    const vw_box *W = &d->world;
    double mag = 0;
    for (int a = 0; a < 3; a++)
        mag = fmax(mag, fmax(fabs(q[a]), fmax(fabs(W->lo[a]), fabs(W->hi[a]))));
    double m = 1e-9 * mag;
    if (!(m > 0) || !isfinite(m)) return -1;
    int within = 1; /* o inside the world box, a margin away from its faces */
    for (int a = 0; a < 3; a++) within &= q[a] > W->lo[a] + m && q[a] < W->hi[a] - m;
    if (within) { /* every walk starts in o's cell: o's cell, when away from its walls */
        const vw_kd_node *nodes = d->nodes, *nd = &nodes[0];
        while (nd && nd->axis >= 0)
            nd = q[nd->axis] < nd->split - m   ? &nodes[nd->left]
                 : q[nd->axis] > nd->split + m ? &nodes[nd->right]
                                                 : NULL;
        return nd ? nd->cell : -1;
    }
    int fa = -1, hiside = 0; /* the face: axis and side (0 lower, 1 upper) */
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int k = 0; k < n; k++) {
        double v[3];
        vw_decomp_to_frame(d, dirs[k], v);
        int found = 0;
        /* The first generator picks the face among those the eye lies beyond; the
           others must cross the same one. */
        for (int a = k ? fa : 0; a < (k ? fa + 1 : 3) && !found; a++) {
            int up = k ? hiside : q[a] > W->hi[a];
            double face = up ? W->hi[a] : W->lo[a];
            if (up ? !(q[a] > W->hi[a] + m) : !(q[a] < W->lo[a] - m)) continue;
            if (up ? !(v[a] < 0) : !(v[a] > 0)) continue; /* not toward the face */
            double t = (face - q[a]) / v[a];
            double p[3] = {0, 0, 0};
            int inside = 1;
            for (int b = 0; b < 3; b++) {
                if (b == a) continue;
                p[b] = q[b] + t * v[b];
                inside &= p[b] > W->lo[b] + m && p[b] < W->hi[b] - m;
            }
            if (!inside) continue;
            found = 1;
            fa = a;
            hiside = up;
            for (int b = 0; b < 3; b++) {
                if (b == a) continue;
                lo[b] = fmin(lo[b], p[b]);
                hi[b] = fmax(hi[b], p[b]);
            }
        }
        if (!found) return -1;
    }
    const vw_kd_node *nodes = d->nodes, *nd = &nodes[0];
    while (nd->axis >= 0) {
        int a = nd->axis;
        if (a == fa) /* the face's side of the split, when it is not the face */
            nd = hiside ? (nd->split < W->hi[a] - m ? &nodes[nd->right] : NULL)
                        : (nd->split > W->lo[a] + m ? &nodes[nd->left] : NULL);
        else
            nd = hi[a] < nd->split - m   ? &nodes[nd->left]
                 : lo[a] > nd->split + m ? &nodes[nd->right]
                                         : NULL;
        if (!nd) return -1;
    }
    return nd->cell;
}

int vw_decomp_clip(const vw_decomp *d, const double o[3], const double dir[3], double *t0,
                   double *t1)
{
    double q[3], v[3];
    ray_to_frame(d, o, dir, q, v);
    return clip(d, q, v, t0, t1);
}

/* A clipped interval stays clipped when restarted at a segment's exit: the clip would
   raise t0 to the world entry, which every segment's t0 already exceeds, and lower t1
   to the same world exit it lowered it to before. So skipping it changes nothing. */
int vw_decomp_next_segment(const vw_decomp *d, const double o[3], const double dir[3],
                           double t0, double t1, vw_segment *out)
{
    if (!(t0 < t1)) return 0;
    if (!d->has_frame) return descend(d, o, dir, t0, t1, out, NULL) != 0; /* it runs per wall */
    double q[3], v[3];
    ray_to_frame(d, o, dir, q, v);
    return descend(d, q, v, t0, t1, out, NULL) != 0;
}

/* ---- the carried walk (vw_walk) ------------------------------------------------------ */

/* The ray's exits from `cell` along each axis: (wall - q[a]) / v[a], the walk's own
   arithmetic, on the far wall; INFINITY where that wall is the world's (the walk's end
   is clipped to it already) or the ray runs parallel to the axis. A descent's t1 is the
   least of them and the clipped end: the far walls are splits on the cell's path, taken
   on their near side, and any other split ahead on the path lies beyond. */
static void cell_exits(const vw_decomp *d, int cell, vw_walk *w)
{
    const vw_box *b = &d->cell_box[cell];
    for (int a = 0; a < 3; a++) {
        double v = w->v[a];
        double wall = v > 0 ? b->hi[a] : b->lo[a];
        int inner = v > 0 ? wall != d->world.hi[a] : v < 0 && wall != d->world.lo[a];
        w->exit[a] = inner ? (wall - w->q[a]) / v : INFINITY;
    }
}

int vw_walk_start(const vw_decomp *d, vw_walk *w, const double o[3], const double dir[3],
                  double t0, double t1)
{
    ray_to_frame(d, o, dir, w->q, w->v);
    if (!clip(d, w->q, w->v, &t0, &t1)) return 0;
    w->tmax = t1;
    /* The descent's near sides give the exits: on each axis the nearest split ahead on
       the path is the cell's far wall (a walk of the whole tree gives none). */
    w->exit[0] = w->exit[1] = w->exit[2] = INFINITY;
    switch (descend(d, w->q, w->v, t0, t1, &w->seg, w->exit)) {
    case 0: return 0;
    case 2: cell_exits(d, w->seg.cell, w);
    }
    return 1;
}

void vw_walk_resume(const vw_decomp *d, vw_walk *w, const double o[3], const double dir[3],
                    const vw_segment *seg, double tmax)
{
    ray_to_frame(d, o, dir, w->q, w->v);
    w->tmax = tmax;
    w->seg = *seg;
    cell_exits(d, seg->cell, w);
}

/* The next cell is across the one wall the ray leaves by: the face's neighbour, flush
   with the cell on the other two axes. Then the descent to it would take the same
   sides of every split as it did to this cell, except the crossed wall's, so the new
   segment is [this exit, least of its exits], only one of them new. A ray leaving by
   an edge or a corner (two exits equal), a face with other neighbours, or a NaN goes by
   the descent. Either way the new segment ends beyond te: the walk always advances. */
int vw_walk_next(const vw_decomp *d, vw_walk *w)
{
    double te = w->seg.t1;
    if (!(te < w->tmax)) return 0;
    /* te < tmax, so te is the least exit: the ray leaves by axis a. */
    double *e = w->exit;
    int a = e[0] == te ? 0 : e[1] == te ? 1 : 2;
    const vw_face_step *f = &d->face_step[6 * w->seg.cell + 2 * a + (w->v[a] > 0)];
    if (f->next >= 0) {
        double ea = f->inner ? (f->wall - w->q[a]) / w->v[a] : INFINITY, old = e[a];
        e[a] = ea;
        double t1 = w->tmax;
        t1 = e[0] < t1 ? e[0] : t1;
        t1 = e[1] < t1 ? e[1] : t1;
        t1 = e[2] < t1 ? e[2] : t1;
        if (te < t1) { /* not so when another exit equals te: an edge or corner */
            w->seg.cell = f->next;
            w->seg.t0 = te;
            w->seg.t1 = t1;
            return 1;
        }
        e[a] = old;
    }
    vw_segment s;
    double x[3] = {INFINITY, INFINITY, INFINITY};
    switch (descend(d, w->q, w->v, te, w->tmax, &s, x)) {
    case 0: return 0;
    case 1: memcpy(w->exit, x, sizeof x); break;
    case 2: cell_exits(d, s.cell, w);
    }
    w->seg = s;
    return 1;
}

/* ---- overlap queries, neighbours, front-to-back ------------------------------------ */

static int overlap(const vw_decomp *d, int node, const vw_box *b, double pad, int *out,
                   int max, int count)
{
    const vw_kd_node *n = &d->nodes[node];
    if (n->axis < 0) {
        if (count < max) out[count] = n->cell;
        return count + 1;
    }
    if (b->lo[n->axis] - pad <= n->split) count = overlap(d, n->left, b, pad, out, max, count);
    if (b->hi[n->axis] + pad >= n->split) count = overlap(d, n->right, b, pad, out, max, count);
    return count;
}

int vw_decomp_cells_overlapping(const vw_decomp *d, const vw_box *b, double pad, int *out,
                                int max)
{
    vw_box f;
    vw_decomp_box_to_frame(d, b, &f);
    for (int a = 0; a < 3; a++)
        if (f.hi[a] + pad < d->world.lo[a] || f.lo[a] - pad > d->world.hi[a]) return 0;
    return overlap(d, 0, &f, pad, out, max, 0);
}

/* Face neighbours from the tree itself. Two cells sharing a face piece of positive area
   across axis a lie on either side of the split that separates them first (their lowest
   common node), and that split is on axis a at the face's coordinate: a split on another
   axis would leave their extents along it overlapping in one point at most. So every
   pair is found once, at one node on axis a, by matching the leaves of its low subtree
   that touch the split with those of its high subtree that do (nb_match): each side's
   leaves tile the node's cross-section, and the match descends both tilings together,
   keeping only pieces that overlap with positive area. The cost is about the pairs
   found times the depth of the subtrees below the split, at most; a query of each face's
   plane from the root (as before) also visited every cell touching the face's edges and
   corners, about 300 nodes a face at 32x32x32 cells. */

typedef struct nb_pairs {
    int *v; /* (low cell, high cell, axis) per pair */
    size_t n, cap;
    int fail;
} nb_pairs;

static void nb_push(nb_pairs *P, int lo, int hi, int a)
{
    if (P->n + 3 > P->cap) {
        size_t cap = P->cap ? 2 * P->cap : 3 * 1024;
        int *v = realloc(P->v, sizeof(int) * cap);
        if (!v) {
            P->fail = 1;
            return;
        }
        P->v = v;
        P->cap = cap;
    }
    P->v[P->n++] = lo;
    P->v[P->n++] = hi;
    P->v[P->n++] = a;
}

/* Pairs the leaves of subtree l that touch the split plane across axis a from below with
   those of subtree r that touch it from above, where their pieces of the plane overlap
   with positive area. lb and rb are the subtrees' boxes, of which only the two axes
   other than a are kept; they overlap with positive area on both. */
static void nb_match(const vw_decomp *d, int l, vw_box lb, int r, vw_box rb, int a,
                     nb_pairs *P)
{
    /* A split on axis a inside a subtree: only its side toward the plane touches it. */
    while (d->nodes[l].axis == a) l = d->nodes[l].right;
    while (d->nodes[r].axis == a) r = d->nodes[r].left;
    const vw_kd_node *L = &d->nodes[l], *R = &d->nodes[r];
    if (L->axis < 0 && R->axis < 0) {
        nb_push(P, L->cell, R->cell, a);
        return;
    }
    /* Divide the larger piece (a leaf is not divided): fewer calls per pair found. */
    int b = (a + 1) % 3, c = (a + 2) % 3;
    double la = (lb.hi[b] - lb.lo[b]) * (lb.hi[c] - lb.lo[c]);
    double ra = (rb.hi[b] - rb.lo[b]) * (rb.hi[c] - rb.lo[c]);
    int left = R->axis < 0 || (L->axis >= 0 && la >= ra);
    const vw_kd_node *N = left ? L : R;
    const vw_box *other = left ? &rb : &lb;
    int k = N->axis;
    vw_box lo = left ? lb : rb, hi = lo;
    lo.hi[k] = N->split;
    hi.lo[k] = N->split;
    /* The whole overlaps `other` with positive length on axis k, so a half does iff the
       split leaves it some of other's extent: edges and corners that merely touch are no
       faces shared. */
    if (N->split > other->lo[k]) {
        if (left) nb_match(d, N->left, lo, r, rb, a, P);
        else nb_match(d, l, lb, N->left, lo, a, P);
    }
    if (N->split < other->hi[k]) {
        if (left) nb_match(d, N->right, hi, r, rb, a, P);
        else nb_match(d, l, lb, N->right, hi, a, P);
    }
}

/* Every node's pairs (nb_match). */
static void nb_walk(const vw_decomp *d, int node, vw_box box, nb_pairs *P)
{
    const vw_kd_node *n = &d->nodes[node];
    if (n->axis < 0) return;
    vw_box l = box, r = box;
    l.hi[n->axis] = n->split;
    r.lo[n->axis] = n->split;
    nb_match(d, n->left, l, n->right, r, n->axis, P);
    nb_walk(d, n->left, l, P);
    nb_walk(d, n->right, r, P);
}

/* Neighbour lists per (cell, face), each in the depth-first order of the leaves, low
   side first, as a query of the face's plane from the root listed them: the order cells
   send to their neighbours in (vw_send_neighbours), which decides the order of messages.
   The pairs come in that order: all of a cell's neighbours across one face are found by
   one nb_match (at the one split on that plane above the cell), and of its calls those
   holding the cell divide the other side low half first, each half to the end. */
static void build_neighbours(vw_decomp *d)
{
    int n = d->ncells;
    nb_pairs P = {0};
    d->nb_start = calloc((size_t)(6 * n + 1), sizeof(int));
    int *pos = malloc(sizeof(int) * (size_t)(6 * n));
    if (!d->nb_start || !pos) goto fail;
    nb_walk(d, 0, d->world, &P);
    if (P.fail || P.n / 3 > (size_t)(INT_MAX / 2)) goto fail;
    size_t npairs = P.n / 3;
    /* Counted per (cell, face), then placed in the order found. */
    for (size_t i = 0; i < P.n; i += 3) {
        d->nb_start[6 * P.v[i] + 2 * P.v[i + 2] + 1 + 1]++;
        d->nb_start[6 * P.v[i + 1] + 2 * P.v[i + 2] + 1]++;
    }
    for (int s = 0; s < 6 * n; s++) d->nb_start[s + 1] += d->nb_start[s];
    d->nb = malloc(sizeof(int) * (2 * npairs + 1));
    if (!d->nb) goto fail;
    memcpy(pos, d->nb_start, sizeof(int) * (size_t)(6 * n));
    for (size_t i = 0; i < P.n; i += 3) {
        int lo = P.v[i], hi = P.v[i + 1], a = P.v[i + 2];
        d->nb[pos[6 * lo + 2 * a + 1]++] = hi;
        d->nb[pos[6 * hi + 2 * a]++] = lo;
    }
    d->max_nb = 0;
    for (int c = 0; c < n; c++) {
        int total = d->nb_start[6 * c + 6] - d->nb_start[6 * c];
        if (total > d->max_nb) d->max_nb = total;
    }
    /* The faces a walk crosses in one step (vw_walk_next): one neighbour, flush with
       the cell on the two other axes, so the ray's exits along them stay the same. */
    d->face_step = malloc(sizeof *d->face_step * (size_t)(6 * n));
    if (!d->face_step) goto fail;
    for (int c = 0; c < n; c++)
        for (int f = 0; f < 6; f++) {
            int s = d->nb_start[6 * c + f], a = VW_FACE_AXIS(f), up = VW_FACE_SIGN(f) > 0;
            vw_face_step *st = &d->face_step[6 * c + f];
            st->next = -1;
            st->inner = 0;
            st->wall = 0;
            if (d->nb_start[6 * c + f + 1] - s != 1) continue;
            const vw_box *p = &d->cell_box[c], *q = &d->cell_box[d->nb[s]];
            int flush = 1;
            for (int k = 0; k < 3; k++)
                if (k != a && (p->lo[k] != q->lo[k] || p->hi[k] != q->hi[k])) flush = 0;
            if (!flush) continue;
            st->next = d->nb[s];
            st->wall = up ? q->hi[a] : q->lo[a];
            st->inner = st->wall != (up ? d->world.hi[a] : d->world.lo[a]);
        }
    free(P.v);
    free(pos);
    return;
fail:
    free(P.v);
    free(pos);
    free(d->nb_start);
    d->nb_start = NULL;
}

int vw_decomp_neighbours(const vw_decomp *d, int cell, int face, int *out, int max)
{
    if (cell < 0 || cell >= d->ncells || face < 0 || face > 5) return 0;
    int s = d->nb_start[6 * cell + face], e = d->nb_start[6 * cell + face + 1];
    for (int i = s; i < e && i - s < max; i++) out[i - s] = d->nb[i];
    return e - s;
}

int vw_decomp_max_neighbours(const vw_decomp *d) { return d->max_nb; }

static void ftb(const vw_decomp *d, int node, const double q[3], int *order, int *k)
{
    const vw_kd_node *n = &d->nodes[node];
    if (n->axis < 0) {
        order[(*k)++] = n->cell;
        return;
    }
    int near_left = q[n->axis] < n->split;
    ftb(d, near_left ? n->left : n->right, q, order, k);
    ftb(d, near_left ? n->right : n->left, q, order, k);
}

void vw_decomp_front_to_back(const vw_decomp *d, const double p[3], int *order)
{
    double q[3];
    vw_decomp_to_frame(d, p, q);
    int k = 0;
    ftb(d, 0, q, order, &k);
}

/* ---- layout strings --------------------------------------------------------------- */

vw_status vw_layout_parse(const char *s, int dims[3], char *err, size_t errlen)
{
    dims[0] = dims[1] = dims[2] = 1;
    const char *p = s ? s : "";
    int n = 0;
    long total = 1;
    if (!*p) goto bad;
    while (*p) {
        if (n == 3) goto bad;
        if (*p < '0' || *p > '9') goto bad;
        long v = 0;
        while (*p >= '0' && *p <= '9') {
            v = v * 10 + (*p - '0');
            if (v > VW_MAX_CELLS) break;
            p++;
        }
        if (v < 1) {
            if (err) snprintf(err, errlen, "layout '%s': every dimension must be at least 1", s);
            goto refused;
        }
        total *= v;
        if (v > VW_MAX_CELLS || total > VW_MAX_CELLS) {
            if (err)
                snprintf(err, errlen, "layout '%s': more than %d cells", s, VW_MAX_CELLS);
            goto refused;
        }
        dims[n++] = (int)v;
        if (*p == 'x' || *p == 'X') {
            p++;
            if (!*p) goto bad;
        } else if (*p) {
            goto bad;
        }
    }
    return VW_OK;
bad:
    if (err)
        snprintf(err, errlen, "layout '%s': expected 1 to 3 positive numbers joined by 'x', like 2x2x2",
                 s ? s : "");
refused: /* every refusal leaves dims at 1x1x1, not half parsed ("4x0x2" left 4x1x1) */
    dims[0] = dims[1] = dims[2] = 1;
    return VW_E_INPUT;
}

int vw__kd_divide(vw_kd_node *nodes, int n, int cell, int axis, double split, int newcell)
{
    int leaf = -1;
    for (int i = 0; i < n; i++)
        if (nodes[i].axis < 0 && nodes[i].cell == cell) leaf = i;
    if (leaf < 0) return n;
    nodes[n] = (vw_kd_node){-1, 0, -1, -1, cell};
    nodes[n + 1] = (vw_kd_node){-1, 0, -1, -1, newcell};
    nodes[leaf] = (vw_kd_node){axis, split, n, n + 1, -1};
    return n + 2;
}
