/* collider.c - the distributed collision test: a vwalls module whose objects are
 * collision shapes and whose messages are probes (a moving object, sent to the cells
 * its destination or swept bounds overlap) and contacts (a hit, sent to every process).
 *
 * Why contacts go to every process and not only to the output process: under MPI every
 * process must apply the same accepted edits to its copy of the placement, so every
 * process must see every contact. Each process names one of its cells as its mailbox;
 * a cell that finds a hit sends the contact to every mailbox.
 */
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include "decomp/decomp_internal.h"
#include "dynamic/dynamic_internal.h"

enum { K_PROBE = 0, K_CONTACT = 1 };
enum { C_PROBES = 0, C_TESTS, C_CONTACTS, C_NCOUNTERS };

struct vw_collider {
    vw_world *world;
    double tol;
    int *mailbox;          /* per process: the cell receiving contacts */
    int nprocs;
    pthread_mutex_t mu;    /* guards the contact list */
    vw_contact *contacts;
    size_t ncontacts, capcontacts;
    char errmsg[512];      /* why the last query failed (vw_collider_errmsg) */
    int fault_contacts;    /* VW_FAULT=collider-contacts-nomem: no room for contacts */
};

/* A cell's shapes sorted by the low x of their bounds, with the bounds kept beside
   them: a probe visits only the x-slab its box can reach (binary search on lo.x, less
   the widest shape), not every shape of a crowded cell. */
typedef struct cell {
    vw_shape *s;
    vw_box *b;
    size_t n;
    double maxw;      /* the widest shape's x extent */
    vw_collider *c;
} cell;

typedef struct keyed {
    double lo;
    size_t i;
} keyed;

static int keyed_cmp(const void *a, const void *b)
{
    const keyed *x = a, *y = b;
    if (x->lo != y->lo) return x->lo < y->lo ? -1 : 1;
    return (x->i > y->i) - (x->i < y->i);
}

static void shape_bounds(const void *object, vw_box *out, void *user)
{
    (void)user;
    vw_shape_bounds(object, NULL, out);
}

static void cell_free(void *state, void *user);

static vw_status cell_build(vw_ctx *ctx, const void *objects, size_t n, void **state)
{
    cell *c = calloc(1, sizeof *c);
    if (!c) return VW_E_NOMEM;
    c->c = vw_ctx_user(ctx);
    if (n) {
        const vw_shape *in = objects;
        c->s = malloc(n * sizeof *c->s);
        c->b = malloc(n * sizeof *c->b);
        keyed *k = malloc(n * sizeof *k);
        if (!c->s || !c->b || !k) {
            free(k);
            cell_free(c, NULL);
            return VW_E_NOMEM;
        }
        for (size_t i = 0; i < n; i++) {
            vw_box b;
            vw_shape_bounds(&in[i], NULL, &b);
            k[i].lo = b.lo[0];
            k[i].i = i;
        }
        qsort(k, n, sizeof *k, keyed_cmp);
        for (size_t i = 0; i < n; i++) {
            c->s[i] = in[k[i].i];
            vw_shape_bounds(&c->s[i], NULL, &c->b[i]);
            if (c->b[i].hi[0] - c->b[i].lo[0] > c->maxw) c->maxw = c->b[i].hi[0] - c->b[i].lo[0];
        }
        free(k);
    }
    c->n = n;
    *state = c;
    return VW_OK;
}

static void cell_free(void *state, void *user)
{
    (void)user;
    cell *c = state;
    if (!c) return;
    free(c->s);
    free(c->b);
    free(c);
}

static int boxes_overlap(const vw_box *a, const vw_box *b)
{
    for (int k = 0; k < 3; k++)
        if (a->hi[k] < b->lo[k] || b->hi[k] < a->lo[k]) return 0;
    return 1;
}

/* The test of one probe against one obstacle shape; shared with the brute-force
   reference (vw__probe_test) so both decide by the same rule. */
int vw__probe_test(const vw_probe *p, const vw_shape *o, double tol)
{
    if (o->kind == VW_SHAPE_NONE || o->id == p->start.id) return 0;
    int how = 0;
    if ((p->flags & VW_PROBE_END) && vw_shape_collide(&p->end, NULL, o, tol)) how |= VW_PROBE_END;
    /* The swept volume holds the start, so a start that interpenetrates o sweeps into
       it too: START, not SWEEP (the caller applies the rule per object). Only where the
       pair is tested exactly: a box (a cone) stands for a cone it may hold with room to
       spare, and a mover starting in that room (not touching the cone) was let through
       the cone itself, its whole path exempt; so a box's sweep hit is always SWEEP,
       which keeps the cone's test conservative (no move that hits it is accepted). And
       where a sphere is involved, only for a path that takes the mover no deeper into o
       than it starts (leaving o, or sliding along it): a sphere sunk in a floor by a
       hair more than tol (a scene written with six digits) went through the floor with
       sweep on, where one resting on it exactly was stopped. Sunk and going deeper is
       THROUGH, which no START of the obstacle's other shapes cancels: a ball sunk on
       the diagonal of a floor quad, so in both its triangles, dropped through one while
       stepping away from the other, whose START exempted the whole quad. */
    if ((p->flags & VW_PROBE_SWEEP) && vw_shape_collide(&p->start, p->d, o, tol)) {
        int exact = p->start.kind != VW_SHAPE_BOX && o->kind != VW_SHAPE_BOX;
        if (!exact || !vw_shape_collide(&p->start, NULL, o, tol))
            how |= VW_PROBE_SWEEP;
        else
            how |= vw__shape_sweep_deepens(&p->start, p->d, o, tol) ? VW_PROBE_THROUGH
                                                                    : VW_PROBE_START;
    }
    return how;
}

static void handle_probe(vw_ctx *ctx, void *state, const void *msg)
{
    cell *c = state;
    const vw_probe *p = msg;
    vw_box pb;
    vw_shape_bounds(&p->end, NULL, &pb);
    if (p->flags & VW_PROBE_SWEEP) {
        vw_box sb;
        vw_shape_bounds(&p->start, p->d, &sb);
        for (int k = 0; k < 3; k++) {
            pb.lo[k] = fmin(pb.lo[k], sb.lo[k]);
            pb.hi[k] = fmax(pb.hi[k], sb.hi[k]);
        }
    }
    for (int k = 0; k < 3; k++) {
        pb.lo[k] -= c->c->tol;
        pb.hi[k] += c->c->tol;
    }
    vw_count(ctx, C_PROBES, 1);
    int64_t tests = 0;
    /* First shape whose lo.x can reach the probe: lo.x >= pb.lo.x - maxw. */
    size_t lo = 0, hi = c->n;
    double from = pb.lo[0] - c->maxw;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (c->b[mid].lo[0] < from) lo = mid + 1;
        else hi = mid;
    }
    for (size_t i = lo; i < c->n && c->b[i].lo[0] <= pb.hi[0]; i++) {
        if (!boxes_overlap(&pb, &c->b[i])) continue;
        tests++;
        int how = vw__probe_test(p, &c->s[i], c->c->tol);
        if (!how) continue;
        vw_contact ct = {p->tag, c->s[i].id, how, 0};
        vw_count(ctx, C_CONTACTS, 1);
        for (int q = 0; q < c->c->nprocs; q++) vw_send_cell(ctx, c->c->mailbox[q], K_CONTACT, &ct);
    }
    vw_count(ctx, C_TESTS, tests);
}

static void handle_contact(vw_ctx *ctx, void *state, const void *msg)
{
    (void)state;
    vw_collider *c = vw_ctx_user(ctx);
    pthread_mutex_lock(&c->mu);
    if (c->ncontacts == c->capcontacts) {
        size_t cap = c->capcontacts ? 2 * c->capcontacts : 64;
        vw_contact *n = c->fault_contacts ? NULL : realloc(c->contacts, cap * sizeof *n);
        if (!n) { /* a lost contact would accept a colliding move: the query fails */
            pthread_mutex_unlock(&c->mu);
            vw_ctx_fail(ctx, VW_E_NOMEM, "out of memory for %zu contacts", cap);
            return;
        }
        c->contacts = n;
        c->capcontacts = cap;
    }
    c->contacts[c->ncontacts++] = *(const vw_contact *)msg;
    pthread_mutex_unlock(&c->mu);
}

static const vw_msg_kind kinds[] = {
    {"probe", sizeof(vw_probe), handle_probe, NULL},
    {"contact", sizeof(vw_contact), handle_contact, NULL},
};
static const char *const counters[C_NCOUNTERS] = {"probes", "tests", "contacts"};

static const vw_module collider_module = {
    .abi = VW_MODULE_ABI,
    .name = "collider",
    .object_size = sizeof(vw_shape),
    .object_bounds = shape_bounds,
    .kinds = kinds,
    .nkinds = 2,
    .counters = counters,
    .ncounters = C_NCOUNTERS,
    .cell_build = cell_build,
    .cell_free = cell_free,
};

/* One mailbox per process: the lowest cell it hosts. */
static vw_status find_mailboxes(vw_collider *c)
{
    int np = vw_world_processes(c->world), nw = vw_world_workers(c->world);
    int nc = vw_decomp_cell_count(vw_world_decomp(c->world));
    free(c->mailbox);
    c->mailbox = malloc(sizeof(int) * (size_t)np);
    if (!c->mailbox) return VW_E_NOMEM;
    c->nprocs = np;
    for (int p = 0; p < np; p++) c->mailbox[p] = -1;
    for (int cl = nc - 1; cl >= 0; cl--) c->mailbox[vw_world_cell_worker(c->world, cl) / nw] = cl;
    for (int p = 0; p < np; p++)
        if (c->mailbox[p] < 0) return VW_E_INVAL; /* a process without cells */
    return VW_OK;
}

/* find_mailboxes, agreed before the caller's next collective step: its allocation is
   this process's own, while "a process without cells" (VW_E_INVAL) is the same answer on
   every process (the mapping is). */
static vw_status mailboxes(vw_collider *c)
{
    vw_status st = find_mailboxes(c);
    vw_status all = vw_world_agree(c->world, st == VW_E_INVAL ? VW_OK : st, NULL, 0);
    return all != VW_OK ? all : st;
}

/* More processes than cells (mpirun -np 2 with one cell): a process without a cell has
   no mailbox, and could not learn the contacts. The collider needs no particular walls,
   only the placement rule, so it then divides its own copy of the decomposition: the
   largest cell (by volume; the lowest id on ties) is halved along its longest side, the
   low half keeping the cell and its worker, the high half a new cell on the first
   worker of a process without one, until every process hosts a cell. Every process
   computes the same division. */
static vw_status give_every_process_a_cell(vw_collider *c, const vw_decomp *d)
{
    int np = vw_world_processes(c->world), nw = vw_world_workers(c->world);
    int nc = vw_decomp_cell_count(d), nn0;
    const vw_kd_node *n0 = vw_decomp_nodes(d, &nn0);
    if (!n0 || nc + np > VW_MAX_CELLS) return VW_E_INVAL;
    vw_kd_node *nodes = malloc(sizeof *nodes * (size_t)(nn0 + 2 * np));
    int *cw = malloc(sizeof(int) * (size_t)(nc + np));
    int *hosts = calloc((size_t)np, sizeof(int));
    vw_decomp *cur = NULL;
    vw_status st = nodes && cw && hosts ? vw_decomp_clone(d, &cur) : VW_E_NOMEM;
    int nn = nn0;
    if (st == VW_OK) {
        memcpy(nodes, n0, sizeof *nodes * (size_t)nn0);
        for (int cl = 0; cl < nc; cl++) {
            cw[cl] = vw_world_cell_worker(c->world, cl);
            hosts[cw[cl] / nw]++;
        }
    }
    const double *F = vw_decomp_frame(d);
    vw_box wb = vw_decomp_world(d);
    for (int p = 0; p < np && st == VW_OK; p++) {
        if (hosts[p]) continue;
        int big = 0;
        double bigv = -1;
        for (int cl = 0; cl < nc; cl++) {
            vw_box b = vw_decomp_cell_box(cur, cl);
            double v = (b.hi[0] - b.lo[0]) * (b.hi[1] - b.lo[1]) * (b.hi[2] - b.lo[2]);
            if (v > bigv) big = cl, bigv = v;
        }
        vw_box b = vw_decomp_cell_box(cur, big);
        int axis = 0;
        for (int a = 1; a < 3; a++)
            if (b.hi[a] - b.lo[a] > b.hi[axis] - b.lo[axis]) axis = a;
        double split = 0.5 * (b.lo[axis] + b.hi[axis]);
        if (!(split > b.lo[axis] && split < b.hi[axis])) {
            st = VW_E_INVAL; /* a cell too thin to halve */
            break;
        }
        nn = vw__kd_divide(nodes, nn, big, axis, split, nc);
        cw[nc++] = p * nw;
        hosts[p]++;
        vw_decomp *nd = NULL;
        st = vw_decomp_create_kd(&wb, nodes, nn, F, VW_DECOMP_DIVIDED, &nd);
        if (st == VW_OK) {
            vw_decomp_free(cur);
            cur = nd;
        }
    }
    /* The division was computed on each process alone; the redecomposition is
       collective. */
    st = vw_world_agree(c->world, st, NULL, 0);
    if (st == VW_OK) st = vw_world_redecompose(c->world, cur, cw);
    if (st == VW_OK) st = mailboxes(c);
    vw_decomp_free(cur);
    free(nodes), free(cw), free(hosts);
    return st;
}

vw_status vw_collider_create(const vw_decomp *d, const vw_config *cfg, double tol,
                             vw_collider **out)
{
    if (!out || !d) return VW_E_INVAL;
    *out = NULL;
    vw_collider *c = calloc(1, sizeof *c);
    /* (collective: the others go on to create the world) */
    if (vw_config_agree(cfg, c ? VW_OK : VW_E_NOMEM, NULL, 0) != VW_OK) {
        free(c);
        return VW_E_NOMEM;
    }
    c->tol = tol > 0 ? tol : 0;
    c->fault_contacts = vw_test_fault("collider-contacts-nomem");
    pthread_mutex_init(&c->mu, NULL);
    vw_status st = vw_world_create(&collider_module, c, d, cfg, &c->world);
    if (st == VW_OK && (st = mailboxes(c)) == VW_E_INVAL) st = give_every_process_a_cell(c, d);
    if (st != VW_OK) {
        vw_collider_free(c);
        return st;
    }
    *out = c;
    return VW_OK;
}

void vw_collider_free(vw_collider *c)
{
    if (!c) return;
    vw_world_free(c->world);
    pthread_mutex_destroy(&c->mu);
    free(c->mailbox);
    free(c->contacts);
    free(c);
}

vw_status vw_collider_add(vw_collider *c, const vw_shape *s, size_t n)
{
    if (!c) return VW_E_INVAL;
    return vw_world_add_objects(c->world, s, n);
}

vw_status vw_collider_update(vw_collider *c, size_t slot, const vw_shape *s)
{
    if (!c) return VW_E_INVAL;
    return vw_world_update_object(c->world, slot, s);
}

vw_status vw_collider_redecompose(vw_collider *c, const vw_decomp *d, const int *cell_worker)
{
    if (!c || !d) return VW_E_INVAL;
    vw_status st = vw_world_redecompose(c->world, d, cell_worker);
    if (st == VW_OK && (st = mailboxes(c)) == VW_E_INVAL) st = give_every_process_a_cell(c, d);
    return st;
}

const char *vw_collider_errmsg(const vw_collider *c)
{
    return !c ? "no collider" : c->errmsg[0] ? c->errmsg : "no error";
}

vw_world *vw_collider_world(vw_collider *c) { return c ? c->world : NULL; }

static int contact_cmp(const void *a, const void *b)
{
    const vw_contact *x = a, *y = b;
    if (x->tag != y->tag) return x->tag < y->tag ? -1 : 1;
    if (x->obstacle != y->obstacle) return x->obstacle < y->obstacle ? -1 : 1;
    return 0;
}

vw_status vw_collider_query(vw_collider *c, const vw_probe *probes, size_t n, vw_contact **out,
                            size_t *nout)
{
    if (!c || !out || !nout || (n && !probes)) return VW_E_INVAL;
    *out = NULL;
    *nout = 0;
    c->errmsg[0] = 0;
    const vw_decomp *d = vw_world_decomp(c->world);
    int nc = vw_decomp_cell_count(d);
    int *cells = malloc(sizeof(int) * (size_t)nc);
    vw_status st = cells ? VW_OK : VW_E_NOMEM;
    for (size_t i = 0; i < n && st == VW_OK; i++) {
        const vw_probe *p = &probes[i];
        vw_box b;
        vw_shape_bounds(&p->end, NULL, &b);
        if (p->flags & VW_PROBE_SWEEP) {
            vw_box sb;
            vw_shape_bounds(&p->start, p->d, &sb);
            for (int k = 0; k < 3; k++) {
                b.lo[k] = fmin(b.lo[k], sb.lo[k]);
                b.hi[k] = fmax(b.hi[k], sb.hi[k]);
            }
        }
        /* The cells widened by tol: an obstacle held only by a cell the probe misses by
           less than tol cannot be hit deeper than tol, but the pad keeps the reached set
           a superset of the cells holding any shape the probe's box touches. */
        int k = vw_decomp_cells_overlapping(d, &b, 2 * c->tol + 1e-12, cells, nc);
        for (int j = 0; j < k && j < nc && st == VW_OK; j++)
            st = vw_world_post(c->world, cells[j], K_PROBE, p);
    }
    free(cells);
    c->ncontacts = 0;
    /* The probes were posted on each process alone; the run is collective. */
    if (st != VW_OK) snprintf(c->errmsg, sizeof c->errmsg, "posting the probes: %s", vw_status_message(st));
    st = vw_world_agree(c->world, st, c->errmsg, sizeof c->errmsg);
    if (st != VW_OK) return st;
    st = vw_world_run(c->world);
    if (st != VW_OK) {
        /* "rank R: cell C: ..." from the run, the same on every process */
        snprintf(c->errmsg, sizeof c->errmsg, "%s", vw_world_errmsg(c->world));
        return st;
    }
    if (c->ncontacts) qsort(c->contacts, c->ncontacts, sizeof *c->contacts, contact_cmp);
    /* One contact per (tag, obstacle): the same obstacle is held by every cell it
       overlaps, and a polygon is several shapes. */
    size_t m = 0;
    for (size_t i = 0; i < c->ncontacts; i++) {
        if (m && c->contacts[m - 1].tag == c->contacts[i].tag &&
            c->contacts[m - 1].obstacle == c->contacts[i].obstacle)
            c->contacts[m - 1].how |= c->contacts[i].how;
        else
            c->contacts[m++] = c->contacts[i];
    }
    vw_contact *r = malloc((m ? m : 1) * sizeof *r);
    if (!r) snprintf(c->errmsg, sizeof c->errmsg, "out of memory for %zu contacts", m);
    st = vw_world_agree(c->world, r ? VW_OK : VW_E_NOMEM, c->errmsg, sizeof c->errmsg);
    if (st != VW_OK) {
        free(r);
        return st;
    }
    if (m) memcpy(r, c->contacts, m * sizeof *r);
    *out = r;
    *nout = m;
    return VW_OK;
}
