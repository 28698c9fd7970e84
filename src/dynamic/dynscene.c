/* dynscene.c - the dynamic scene: a vw_scene under edits (move, moveto, rotate, add,
 * remove), the collision shapes of its objects in a distributed collider, and the
 * decisions of a batch of edits taken with one distributed query.
 *
 * Batch rule (why one query suffices): edits of distinct objects are probed together
 * against the scene as it was before the batch; then they are decided in script order,
 * dropping contacts with objects an earlier edit of the batch has already moved away
 * and testing, locally, against the new places of those objects. That is exactly the
 * one-edit-at-a-time decision. An edit naming an object a previous edit of the batch
 * touched starts a new query (its start depends on the earlier outcome).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "dynamic/dynamic_internal.h"

/* The geometry of one object, detached from the scene while an edit transforms it. */
typedef struct geom {
    vw_prim_kind kind;
    int material;
    double c[3], r;                  /* sphere */
    double base[3], apex[3], r0, r1; /* cone (signed radii, as in the scene) */
    int nv;                          /* polygon */
    double (*v)[3], (*n)[3];         /* nv each; n NULL without normals */
} geom;

typedef struct objinfo {
    int kind;          /* vw_prim_kind, or -1 removed */
    size_t index;      /* in the scene's array of that kind */
    size_t slot, nslots;
    int own_vertices;  /* polygon: its vertices are its own (copied on first edit) */
} objinfo;

struct vw_dynscene {
    vw_scene *s;
    vw_collider *col;
    vw_shape *shapes;  /* every slot's current shape (mirrors the collider) */
    size_t nslots, capslots;
    objinfo *obj;      /* by id */
    int nids, capids;
    size_t capspheres, capvertices;
    vw_box world;
    double tol;
    int brute;
    /* Test switches (VW_FAULT), read at create: a batch's bookkeeping (batch-nomem) or
       the room for its accepted edits (commit-nomem) cannot be had. */
    int fault_batch, fault_commit;
    char errmsg[256]; /* why the last vw_dynscene_apply failed */
};

/* ---- geometry ----------------------------------------------------------------------- */

static void geom_free(geom *g)
{
    free(g->v);
    free(g->n);
    g->v = g->n = NULL;
}

static vw_status geom_get(const vw_dynscene *ds, int id, geom *g)
{
    memset(g, 0, sizeof *g);
    const objinfo *o = &ds->obj[id];
    const vw_scene *s = ds->s;
    g->kind = (vw_prim_kind)o->kind;
    switch (o->kind) {
    case VW_PRIM_SPHERE:
        g->material = s->spheres[o->index].material;
        memcpy(g->c, s->spheres[o->index].center, sizeof g->c);
        g->r = s->spheres[o->index].radius;
        break;
    case VW_PRIM_CONE: {
        const vw_cone *c = &s->cones[o->index];
        g->material = c->material;
        memcpy(g->base, c->base, sizeof g->base);
        memcpy(g->apex, c->apex, sizeof g->apex);
        g->r0 = c->base_radius;
        g->r1 = c->apex_radius;
        break;
    }
    default: {
        const vw_polygon *p = &s->polygons[o->index];
        g->material = p->material;
        g->nv = p->count;
        g->v = malloc(sizeof *g->v * (size_t)p->count);
        if (!g->v) return VW_E_NOMEM;
        for (int k = 0; k < p->count; k++)
            memcpy(g->v[k], s->vertices[s->indices[p->first + k]], sizeof g->v[k]);
        if (p->has_normals && s->normals) {
            g->n = malloc(sizeof *g->n * (size_t)p->count);
            if (!g->n) return VW_E_NOMEM;
            memcpy(g->n, s->normals[p->first], sizeof *g->n * (size_t)p->count);
        }
        break;
    }
    }
    return VW_OK;
}

static size_t geom_nslots(const geom *g) { return g->kind == VW_PRIM_POLYGON ? (size_t)g->nv - 2 : 1; }

/* The collision shapes of an object: a sphere; a cone's bounding box (the ray tracer's
   tight bounds of its two end discs); a polygon's triangles, the ray tracer's
   (vw_polygon_triangulate). VW_E_NOMEM when a concave polygon's scratch cannot be had. */
static vw_status geom_shapes(const geom *g, int id, vw_shape *out)
{
    size_t n = geom_nslots(g);
    memset(out, 0, n * sizeof *out);
    for (size_t i = 0; i < n; i++) out[i].id = id;
    if (g->kind == VW_PRIM_SPHERE) {
        out->kind = VW_SHAPE_SPHERE;
        memcpy(out->p[0], g->c, sizeof out->p[0]);
        out->r = fabs(g->r);
    } else if (g->kind == VW_PRIM_CONE) {
        out->kind = VW_SHAPE_BOX;
        double w[3], len = 0;
        for (int a = 0; a < 3; a++) w[a] = g->apex[a] - g->base[a], len += w[a] * w[a];
        len = sqrt(len);
        for (int a = 0; a < 3; a++) {
            double wa = len > 0 ? w[a] / len : 0, e = sqrt(fmax(0.0, 1.0 - wa * wa));
            double r0 = fabs(g->r0) * e, r1 = fabs(g->r1) * e;
            out->p[0][a] = fmin(g->base[a] - r0, g->apex[a] - r1);
            out->p[1][a] = fmax(g->base[a] + r0, g->apex[a] + r1);
        }
    } else {
        int (*tri)[3] = malloc((size_t)g->nv * sizeof *tri);
        if (!tri) return VW_E_NOMEM;
        vw_status st = vw_polygon_triangulate((const double (*)[3])g->v, g->nv, tri);
        for (int j = 0; st == VW_OK && j + 2 < g->nv; j++) {
            vw_shape *t = &out[j];
            t->kind = VW_SHAPE_TRIANGLE;
            for (int c = 0; c < 3; c++) memcpy(t->p[c], g->v[tri[j][c]], sizeof t->p[c]);
        }
        free(tri);
        return st;
    }
    return VW_OK;
}

static void geom_bounds(const geom *g, double lo[3], double hi[3])
{
    for (int a = 0; a < 3; a++) lo[a] = INFINITY, hi[a] = -INFINITY;
    if (g->kind == VW_PRIM_SPHERE) {
        for (int a = 0; a < 3; a++) lo[a] = g->c[a] - fabs(g->r), hi[a] = g->c[a] + fabs(g->r);
    } else if (g->kind == VW_PRIM_CONE) {
        for (int a = 0; a < 3; a++) {
            lo[a] = fmin(g->base[a] - fabs(g->r0), g->apex[a] - fabs(g->r1));
            hi[a] = fmax(g->base[a] + fabs(g->r0), g->apex[a] + fabs(g->r1));
        }
    } else {
        for (int k = 0; k < g->nv; k++)
            for (int a = 0; a < 3; a++) lo[a] = fmin(lo[a], g->v[k][a]), hi[a] = fmax(hi[a], g->v[k][a]);
    }
}

/* An affine map: p -> R (p - o) + o + t (R = identity for translations). */
typedef struct xform {
    double R[3][3], o[3], t[3];
    int rot;
} xform;

static void xf_point(const xform *x, const double p[3], double out[3])
{
    if (!x->rot) {
        for (int a = 0; a < 3; a++) out[a] = p[a] + x->t[a];
        return;
    }
    double q[3] = {p[0] - x->o[0], p[1] - x->o[1], p[2] - x->o[2]};
    for (int a = 0; a < 3; a++)
        out[a] = x->R[a][0] * q[0] + x->R[a][1] * q[1] + x->R[a][2] * q[2] + x->o[a] + x->t[a];
}

static void xf_dir(const xform *x, double v[3])
{
    if (!x->rot) return;
    double q[3] = {v[0], v[1], v[2]};
    for (int a = 0; a < 3; a++) v[a] = x->R[a][0] * q[0] + x->R[a][1] * q[1] + x->R[a][2] * q[2];
}

static void geom_apply(geom *g, const xform *x)
{
    double q[3];
    if (g->kind == VW_PRIM_SPHERE) {
        xf_point(x, g->c, q);
        memcpy(g->c, q, sizeof q);
    } else if (g->kind == VW_PRIM_CONE) {
        xf_point(x, g->base, q);
        memcpy(g->base, q, sizeof q);
        xf_point(x, g->apex, q);
        memcpy(g->apex, q, sizeof q);
    } else {
        for (int k = 0; k < g->nv; k++) {
            xf_point(x, g->v[k], q);
            memcpy(g->v[k], q, sizeof q);
            if (g->n) xf_dir(x, g->n[k]);
        }
    }
}

/* Rodrigues: rotation by deg degrees about unit axis u, right-handed. */
static void rotation(const double axis[3], double deg, double R[3][3])
{
    /* Scaled by its largest component first: squares of components beyond 1e154
       overflow (the unit axis came out 0, and the "rotation" scaled by cos), and below
       1e-154 underflow. */
    double m = fmax(fabs(axis[0]), fmax(fabs(axis[1]), fabs(axis[2])));
    double a[3] = {axis[0] / m, axis[1] / m, axis[2] / m};
    double l = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    double u[3] = {a[0] / l, a[1] / l, a[2] / l};
    double th = deg * (3.14159265358979323846 / 180.0), c = cos(th), s = sin(th), C = 1 - c;
    R[0][0] = c + u[0] * u[0] * C, R[0][1] = u[0] * u[1] * C - u[2] * s, R[0][2] = u[0] * u[2] * C + u[1] * s;
    R[1][0] = u[1] * u[0] * C + u[2] * s, R[1][1] = c + u[1] * u[1] * C, R[1][2] = u[1] * u[2] * C - u[0] * s;
    R[2][0] = u[2] * u[0] * C - u[1] * s, R[2][1] = u[2] * u[1] * C + u[0] * s, R[2][2] = c + u[2] * u[2] * C;
}

/* Writes an edited geometry back into the scene. A polygon's vertices may be shared
   with other polygons (OBJ meshes): on its first edit it gets copies of its own. */
static vw_status geom_put(vw_dynscene *ds, int id, const geom *g)
{
    objinfo *o = &ds->obj[id];
    vw_scene *s = ds->s;
    if (g->kind == VW_PRIM_SPHERE) {
        memcpy(s->spheres[o->index].center, g->c, sizeof g->c);
    } else if (g->kind == VW_PRIM_CONE) {
        memcpy(s->cones[o->index].base, g->base, sizeof g->base);
        memcpy(s->cones[o->index].apex, g->apex, sizeof g->apex);
    } else {
        vw_polygon *p = &s->polygons[o->index];
        if (!o->own_vertices) {
            size_t need = s->nvertices + (size_t)p->count;
            if (need > ds->capvertices) {
                size_t cap = ds->capvertices > s->nvertices ? ds->capvertices : s->nvertices;
                while (cap < need) cap = cap ? 2 * cap : 64;
                double(*nv)[3] = realloc(s->vertices, cap * sizeof *nv);
                if (!nv) return VW_E_NOMEM;
                s->vertices = nv;
                ds->capvertices = cap;
            }
            for (int k = 0; k < p->count; k++) s->indices[p->first + k] = (int)(s->nvertices + (size_t)k);
            s->nvertices = need;
            o->own_vertices = 1;
        }
        for (int k = 0; k < p->count; k++) {
            memcpy(s->vertices[s->indices[p->first + k]], g->v[k], sizeof g->v[k]);
            if (g->n) memcpy(s->normals[p->first + k], g->n[k], sizeof g->n[k]);
        }
    }
    return VW_OK;
}

/* ---- creation ------------------------------------------------------------------------- */

static vw_status grow_ids(vw_dynscene *ds, int need)
{
    if (need <= ds->capids) return VW_OK;
    int cap = ds->capids ? ds->capids : 64;
    while (cap < need) cap *= 2;
    objinfo *o = realloc(ds->obj, sizeof *o * (size_t)cap);
    if (!o) return VW_E_NOMEM;
    ds->obj = o;
    ds->capids = cap;
    return VW_OK;
}

static vw_status grow_slots(vw_dynscene *ds, size_t need)
{
    if (need <= ds->capslots) return VW_OK;
    size_t cap = ds->capslots ? ds->capslots : 64;
    while (cap < need) cap *= 2;
    vw_shape *s = realloc(ds->shapes, sizeof *s * cap);
    if (!s) return VW_E_NOMEM;
    ds->shapes = s;
    ds->capslots = cap;
    return VW_OK;
}

vw_status vw_dynscene_create(vw_scene *s, const vw_dynscene_params *p, vw_dynscene **out,
                             char *err, size_t errlen)
{
    if (err && errlen) err[0] = 0;
    if (!out || !s || !p || !p->decomp) {
        vw_scene_free(s);
        return VW_E_INVAL;
    }
    *out = NULL;
    vw_dynscene *ds = calloc(1, sizeof *ds);
    if (!ds) {
        /* (collective: the others go on to the collider's world) */
        char msg[64] = "";
        vw_status st = vw_config_agree(p->config, VW_E_NOMEM, msg, sizeof msg);
        if (err && errlen)
            snprintf(err, errlen, "cannot set up the dynamic scene: %s", msg[0] ? msg : vw_status_message(st));
        vw_scene_free(s);
        return st;
    }
    ds->s = s;
    ds->capspheres = s->nspheres;
    ds->capvertices = s->nvertices;
    ds->world = vw_decomp_world(p->decomp);
    ds->brute = p->brute_force;
    ds->fault_batch = vw_test_fault("dynscene-batch-nomem");
    ds->fault_commit = vw_test_fault("dynscene-commit-nomem");
    double diag = 0;
    for (int a = 0; a < 3; a++) diag += pow(ds->world.hi[a] - ds->world.lo[a], 2);
    ds->tol = p->tol > 0 ? p->tol : 1e-9 * sqrt(diag);
    int n = (int)vw_scene_count_objects(s);
    vw_status st = grow_ids(ds, n);
    for (int id = 0; id < n && st == VW_OK; id++) {
        vw_prim_kind k;
        size_t idx;
        st = vw_scene_find_object(s, id, &k, &idx);
        if (st != VW_OK) break;
        objinfo *o = &ds->obj[id];
        memset(o, 0, sizeof *o);
        o->kind = (int)k;
        o->index = idx;
        o->slot = ds->nslots;
        geom g;
        st = geom_get(ds, id, &g);
        if (st == VW_OK && g.kind == VW_PRIM_POLYGON && g.nv < 3) st = VW_E_INPUT;
        if (st == VW_OK) {
            o->nslots = geom_nslots(&g);
            st = grow_slots(ds, ds->nslots + o->nslots);
        }
        if (st == VW_OK) st = geom_shapes(&g, id, ds->shapes + ds->nslots);
        if (st == VW_OK) ds->nslots += o->nslots;
        geom_free(&g);
    }
    ds->nids = n;
    /* Each process made the shapes from its own copy of the scene: all fail with the
       lowest failing rank's status, or none waits for it in the collider's world. */
    char msg[160] = "";
    if (st != VW_OK) snprintf(msg, sizeof msg, "%s", vw_status_message(st));
    st = vw_config_agree(p->config, st, msg, sizeof msg);
    if (st != VW_OK) {
        if (err && errlen) snprintf(err, errlen, "cannot set up the dynamic scene: %s", msg);
        vw_dynscene_free(ds);
        return st;
    }
    st = vw_collider_create(p->decomp, p->config, ds->tol, &ds->col);
    if (st == VW_OK) st = vw_collider_add(ds->col, ds->shapes, ds->nslots);
    if (st != VW_OK) {
        if (err && errlen)
            snprintf(err, errlen, "cannot set up the dynamic scene: %s%s", vw_status_message(st),
                     st == VW_E_INVAL ? " (every process needs at least one cell)" : "");
        vw_dynscene_free(ds);
        return st;
    }
    *out = ds;
    return VW_OK;
}

void vw_dynscene_free(vw_dynscene *ds)
{
    if (!ds) return;
    vw_collider_free(ds->col);
    vw_scene_free(ds->s);
    free(ds->shapes);
    free(ds->obj);
    free(ds);
}

const vw_scene *vw_dynscene_scene(const vw_dynscene *ds) { return ds->s; }
vw_collider *vw_dynscene_collider(vw_dynscene *ds) { return ds->col; }
int vw_dynscene_alive(const vw_dynscene *ds, int id) { return id >= 0 && id < ds->nids && ds->obj[id].kind >= 0; }
int vw_dynscene_ids(const vw_dynscene *ds) { return ds->nids; }
vw_box vw_dynscene_world(const vw_dynscene *ds) { return ds->world; }

void vw_dynscene_slots(const vw_dynscene *ds, int id, size_t *first, size_t *n)
{
    *first = *n = 0;
    if (id >= 0 && id < ds->nids) {
        *first = ds->obj[id].slot;
        *n = ds->obj[id].nslots;
    }
}

vw_status vw_dynscene_redecompose(vw_dynscene *ds, const vw_decomp *d, const int *cell_worker)
{
    return vw_collider_redecompose(ds->col, d, cell_worker);
}

/* ---- one batch ------------------------------------------------------------------------ */

/* An edit being decided: its object's new geometry and shapes. */
typedef struct pending {
    vw_box reach;               /* bounds of its end shapes and swept start (local tests) */
    vw_box endb;                /* bounds of its end shapes */
    int id, slot0, nshapes;     /* slot0: first slot; shapes in end[] at probe0 */
    size_t probe0;
    int add, remove;
    geom g;
    double d[3];
    int swept;
} pending;

static void invalid(vw_result *r, const char *fmt, int id)
{
    r->outcome = VW_OUT_INVALID;
    snprintf(r->msg, sizeof r->msg, fmt, id);
}

/* Prepares edit e: validates it and computes the new geometry. 0 when invalid. */
static int prepare(vw_dynscene *ds, const vw_edit *e, int next_id, vw_result *r, pending *pd)
{
    memset(pd, 0, sizeof *pd);
    r->edit = *e;
    r->outcome = VW_OUT_ACCEPTED;
    r->obstacle = -1;
    r->id = e->id;
    /* vw_edit_parse's checks of the numbers, for edits a program made itself: a sphere
       of radius <= 0 was added, and the scene written then failed to read back. */
    int nv = e->op == VW_EDIT_ADD || e->op == VW_EDIT_ROTATE ? 4 : e->op == VW_EDIT_REMOVE ? 0 : 3;
    for (int k = 0; k < nv; k++)
        if (!isfinite(e->v[k])) {
            invalid(r, "a number of the edit is not finite", 0);
            return 0;
        }
    if (e->op == VW_EDIT_ADD && !(e->v[3] > 0)) {
        invalid(r, "sphere radius must be > 0", 0);
        return 0;
    }
    if (e->op == VW_EDIT_ROTATE && e->v[0] == 0 && e->v[1] == 0 && e->v[2] == 0) {
        invalid(r, "rotation axis of object %d is zero", e->id);
        return 0;
    }
    if (e->op == VW_EDIT_ADD) {
        if (e->material >= 0 && (size_t)e->material >= ds->s->nmaterials) {
            invalid(r, "no material %d in the scene", e->material);
            return 0;
        }
        pd->add = 1;
        pd->id = r->id = next_id;
        pd->g.kind = VW_PRIM_SPHERE;
        pd->g.material = e->material;
        memcpy(pd->g.c, e->v, sizeof pd->g.c);
        pd->g.r = e->v[3];
    } else {
        if (!vw_dynscene_alive(ds, e->id)) {
            invalid(r, "no object %d", e->id);
            return 0;
        }
        pd->id = e->id;
        /* Memory is this process's own: the batch fails (on every process, agreed),
           where an edit taken as invalid here alone would leave the processes with
           different scenes. */
        if (geom_get(ds, e->id, &pd->g) != VW_OK) return -1;
        if (e->op == VW_EDIT_REMOVE) {
            pd->remove = 1;
            return 1;
        }
        double lo[3], hi[3];
        geom_bounds(&pd->g, lo, hi);
        xform x;
        memset(&x, 0, sizeof x);
        for (int a = 0; a < 3; a++) {
            double ctr = 0.5 * (lo[a] + hi[a]);
            if (e->op == VW_EDIT_MOVE) x.t[a] = e->v[a];
            if (e->op == VW_EDIT_MOVETO) x.t[a] = e->v[a] - ctr;
            x.o[a] = ctr;
        }
        if (e->op == VW_EDIT_ROTATE) {
            x.rot = 1;
            rotation(e->v, e->v[3], x.R);
        } else {
            memcpy(pd->d, x.t, sizeof pd->d);
            pd->swept = 1;
        }
        geom_apply(&pd->g, &x);
    }
    double lo[3], hi[3];
    geom_bounds(&pd->g, lo, hi);
    for (int a = 0; a < 3; a++)
        if (!(lo[a] >= ds->world.lo[a] && hi[a] <= ds->world.hi[a])) {
            geom_free(&pd->g);
            invalid(r, "object %d would leave the world box (which cannot grow)", pd->id);
            return 0;
        }
    return 1;
}

typedef struct batch {
    vw_probe *probes;
    size_t nprobes, cap;
} batch;

static vw_status add_probe(batch *b, const vw_probe *p)
{
    if (b->nprobes == b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 64;
        vw_probe *n = realloc(b->probes, cap * sizeof *n);
        if (!n) return VW_E_NOMEM;
        b->probes = n;
        b->cap = cap;
    }
    b->probes[b->nprobes++] = *p;
    return VW_OK;
}

static int boxes_overlap(const vw_box *a, const vw_box *b, double pad)
{
    for (int k = 0; k < 3; k++)
        if (a->hi[k] + pad < b->lo[k] || b->hi[k] + pad < a->lo[k]) return 0;
    return 1;
}

/* Whether an obstacle's merged contact bits make a sweep hit: the mover's path goes
   deeper into a shape it starts in, or meets it and the mover did not already
   interpenetrate it at its start (dynamic.h). */
static int sweep_hits(int how)
{
    return (how & VW_PROBE_THROUGH) || ((how & VW_PROBE_SWEEP) && !(how & VW_PROBE_START));
}

static int contact_cmp(const void *a, const void *b)
{
    const vw_contact *x = a, *y = b;
    if (x->tag != y->tag) return x->tag < y->tag ? -1 : 1;
    return (x->obstacle > y->obstacle) - (x->obstacle < y->obstacle);
}

/* Contacts by brute force: every probe against every slot (the reference). */
static vw_status brute_contacts(vw_dynscene *ds, const batch *b, vw_contact **out, size_t *nout)
{
    size_t n = 0, cap = 16;
    vw_contact *c = malloc(cap * sizeof *c);
    if (!c) return VW_E_NOMEM;
    for (size_t i = 0; i < b->nprobes; i++) {
        int last = -1;
        for (size_t s = 0; s < ds->nslots; s++) {
            int how = vw__probe_test(&b->probes[i], &ds->shapes[s], ds->tol);
            if (!how) continue;
            if (last >= 0 && c[last].tag == b->probes[i].tag && c[last].obstacle == ds->shapes[s].id) {
                c[last].how |= how;
                continue;
            }
            if (n == cap) {
                vw_contact *m = realloc(c, 2 * cap * sizeof *c);
                if (!m) {
                    free(c);
                    return VW_E_NOMEM;
                }
                c = m;
                cap *= 2;
            }
            c[n] = (vw_contact){b->probes[i].tag, ds->shapes[s].id, how, 0};
            last = (int)n++;
        }
    }
    /* A polygon mover is several probes of one tag, so (tag, obstacle) pairs repeat
       across them (a mover's triangle 0 meets obstacles A and B, its triangle 1 A and B
       again): sorted, then merged like the collider's, one contact per pair with its
       bits or'ed. (The merge swapped the list's last contact into the hole, which in a
       batch of several edits was another tag's: it ended the scan of this tag, and a
       START and a SWEEP of one obstacle stayed apart, a sweep hit the cells do not
       see.) */
    if (n) qsort(c, n, sizeof *c, contact_cmp);
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        if (m && c[m - 1].tag == c[i].tag && c[m - 1].obstacle == c[i].obstacle)
            c[m - 1].how |= c[i].how;
        else
            c[m++] = c[i];
    }
    *out = c;
    *nout = m;
    return VW_OK;
}

/* Commits an accepted edit: scene, shapes, collider. */
static vw_status commit_edit(vw_dynscene *ds, pending *pd, const vw_shape *end)
{
    vw_status st = VW_OK;
    if (pd->add) {
        vw_scene *s = ds->s;
        if (s->nspheres == ds->capspheres) {
            size_t cap = ds->capspheres ? 2 * ds->capspheres : 16;
            vw_sphere *n = realloc(s->spheres, cap * sizeof *n);
            if (!n) return VW_E_NOMEM;
            s->spheres = n;
            ds->capspheres = cap;
        }
        /* Ids grow, so the spheres stay sorted by id (vw_scene_find_object). */
        vw_sphere *sp = &s->spheres[s->nspheres];
        sp->id = pd->id;
        sp->material = pd->g.material;
        memcpy(sp->center, pd->g.c, sizeof sp->center);
        sp->radius = pd->g.r;
        if ((st = grow_ids(ds, pd->id + 1)) != VW_OK) return st;
        if ((st = grow_slots(ds, ds->nslots + 1)) != VW_OK) return st;
        objinfo *o = &ds->obj[pd->id];
        memset(o, 0, sizeof *o);
        o->kind = VW_PRIM_SPHERE;
        o->index = s->nspheres++;
        o->slot = ds->nslots;
        o->nslots = 1;
        ds->nids = pd->id + 1;
        ds->shapes[ds->nslots++] = end[0];
        return vw_collider_add(ds->col, end, 1);
    }
    objinfo *o = &ds->obj[pd->id];
    if (pd->remove) {
        /* The id stays reserved; its slots become empty shapes, which no cell holds. */
        for (size_t k = 0; k < o->nslots && st == VW_OK; k++) {
            vw_shape none;
            memset(&none, 0, sizeof none);
            none.id = pd->id;
            ds->shapes[o->slot + k] = none;
            st = vw_collider_update(ds->col, o->slot + k, &none);
        }
        o->kind = -1;
        return st;
    }
    if ((st = geom_put(ds, pd->id, &pd->g)) != VW_OK) return st;
    for (size_t k = 0; k < o->nslots && st == VW_OK; k++) {
        ds->shapes[o->slot + k] = end[k];
        st = vw_collider_update(ds->col, o->slot + k, &end[k]);
    }
    return st;
}

/* This process's own part of a step (its bookkeeping, allocated alone) ends in
   agreement before the next collective call: every process gets the lowest failing
   rank's status, so all stop, or none waits for one that stopped (vwalls/world.h). */
static vw_status agree(vw_dynscene *ds, vw_status st, const char *what)
{
    char msg[sizeof ds->errmsg];
    snprintf(msg, sizeof msg, "%s: %s", what, vw_status_message(st));
    st = vw_world_agree(vw_collider_world(ds->col), st, msg, sizeof msg);
    if (st != VW_OK && !ds->errmsg[0]) snprintf(ds->errmsg, sizeof ds->errmsg, "%s", msg);
    return st;
}

const char *vw_dynscene_errmsg(const vw_dynscene *ds) { return ds ? ds->errmsg : "no scene"; }

/* Room for the accepted edits of a batch, made before the first of them is committed:
   commit_edit then allocates nothing on this process alone between the collider's
   collective updates. */
static vw_status reserve_commits(vw_dynscene *ds, const pending *pd, const vw_result *res,
                                 const unsigned char *ok, size_t n)
{
    if (ds->fault_commit) return VW_E_NOMEM;
    size_t adds = 0, vertices = 0;
    int maxid = ds->nids;
    for (size_t i = 0; i < n; i++) {
        if (!ok[i] || res[i].outcome != VW_OUT_ACCEPTED) continue;
        if (pd[i].add) {
            adds++;
            if (pd[i].id + 1 > maxid) maxid = pd[i].id + 1;
            continue;
        }
        const objinfo *o = &ds->obj[pd[i].id];
        if (!pd[i].remove && o->kind == VW_PRIM_POLYGON && !o->own_vertices)
            vertices += (size_t)ds->s->polygons[o->index].count;
    }
    vw_scene *s = ds->s;
    if (s->nspheres + adds > ds->capspheres) {
        size_t cap = ds->capspheres ? ds->capspheres : 16;
        while (cap < s->nspheres + adds) cap *= 2;
        vw_sphere *sp = realloc(s->spheres, cap * sizeof *sp);
        if (!sp) return VW_E_NOMEM;
        s->spheres = sp;
        ds->capspheres = cap;
    }
    if (s->nvertices + vertices > ds->capvertices) {
        size_t cap = ds->capvertices > s->nvertices ? ds->capvertices : s->nvertices;
        while (cap < s->nvertices + vertices) cap = cap ? 2 * cap : 64;
        double(*nv)[3] = realloc(s->vertices, cap * sizeof *nv);
        if (!nv) return VW_E_NOMEM;
        s->vertices = nv;
        ds->capvertices = cap;
    }
    vw_status st = grow_ids(ds, maxid);
    if (st == VW_OK) st = grow_slots(ds, ds->nslots + adds);
    return st;
}

/* Decides and commits edits [0, n) whose ids are distinct. */
static vw_status run_batch(vw_dynscene *ds, const vw_edit *edits, size_t n, int check, int sweep,
                           vw_result *res, unsigned char *changed_bits, size_t *nbits)
{
    pending *pd = ds->fault_batch ? NULL : calloc(n ? n : 1, sizeof *pd);
    unsigned char *ok = calloc(n ? n : 1, 1);
    batch b = {0};
    vw_shape *ends = NULL;
    size_t nends = 0, capends = 0;
    vw_status st = (pd && ok) ? VW_OK : VW_E_NOMEM;
    int next_id = ds->nids;
    for (size_t i = 0; i < n && st == VW_OK; i++) {
        int ready = prepare(ds, &edits[i], next_id, &res[i], &pd[i]);
        if (ready < 0) {
            st = VW_E_NOMEM;
            break;
        }
        ok[i] = (unsigned char)ready;
        if (!ok[i]) continue;
        if (pd[i].add) next_id++;
        if (pd[i].remove) continue;
        size_t ns = geom_nslots(&pd[i].g);
        if (nends + ns > capends) {
            size_t cap = capends ? capends : 64;
            while (cap < nends + ns) cap *= 2;
            vw_shape *e = realloc(ends, cap * sizeof *e);
            if (!e) {
                st = VW_E_NOMEM;
                break;
            }
            ends = e;
            capends = cap;
        }
        pd[i].probe0 = nends;
        pd[i].nshapes = (int)ns;
        if ((st = geom_shapes(&pd[i].g, pd[i].id, ends + nends)) != VW_OK) break;
        for (int a = 0; a < 3; a++) {
            pd[i].endb.lo[a] = pd[i].reach.lo[a] = INFINITY;
            pd[i].endb.hi[a] = pd[i].reach.hi[a] = -INFINITY;
        }
        for (size_t k = 0; k < ns; k++) {
            vw_box eb, sb;
            vw_shape_bounds(&ends[nends + k], NULL, &eb);
            if (pd[i].add)
                sb = eb;
            else
                vw_shape_bounds(&ds->shapes[ds->obj[pd[i].id].slot + k], sweep && pd[i].swept ? pd[i].d : NULL, &sb);
            for (int a = 0; a < 3; a++) {
                pd[i].endb.lo[a] = fmin(pd[i].endb.lo[a], eb.lo[a]);
                pd[i].endb.hi[a] = fmax(pd[i].endb.hi[a], eb.hi[a]);
                pd[i].reach.lo[a] = fmin(pd[i].reach.lo[a], fmin(eb.lo[a], sb.lo[a]));
                pd[i].reach.hi[a] = fmax(pd[i].reach.hi[a], fmax(eb.hi[a], sb.hi[a]));
            }
        }
        nends += ns;
        if (!check) continue;
        for (size_t k = 0; k < ns && st == VW_OK; k++) {
            vw_probe p;
            memset(&p, 0, sizeof p);
            p.end = ends[pd[i].probe0 + k];
            p.tag = (int32_t)i;
            p.flags = VW_PROBE_END;
            if (pd[i].add) {
                p.start = p.end;
            } else {
                p.start = ds->shapes[ds->obj[pd[i].id].slot + k];
                if (sweep && pd[i].swept) {
                    p.flags |= VW_PROBE_SWEEP;
                    memcpy(p.d, pd[i].d, sizeof p.d);
                }
            }
            st = add_probe(&b, &p);
        }
    }
    vw_contact *ct = NULL;
    size_t nct = 0;
    /* The probes were made alone; the query is collective. */
    st = agree(ds, st, "preparing a batch of edits");
    const char *why = NULL; /* the query's own message, when it failed */
    if (st == VW_OK && check) {
        if (ds->brute)
            st = brute_contacts(ds, &b, &ct, &nct);
        else if ((st = vw_collider_query(ds->col, b.probes, b.nprobes, &ct, &nct)) != VW_OK)
            why = vw_collider_errmsg(ds->col);
        if (st == VW_OK && nct) qsort(ct, nct, sizeof *ct, contact_cmp);
    }
    /* moved[id] != 0: an earlier edit of this batch was accepted for id (its old
       place is gone). Ids in a batch are distinct, so a small map by id suffices. */
    unsigned char *moved = calloc((size_t)next_id + 1, 1);
    if (!moved && st == VW_OK) st = VW_E_NOMEM;
    size_t ci = 0;
    for (size_t i = 0; i < n && st == VW_OK; i++) {
        while (ci < nct && ct[ci].tag < (int32_t)i) ci++;
        if (!ok[i]) continue;
        int end_hit = -1, sweep_hit = -1;
        if (check && !pd[i].remove) {
            for (size_t c = ci; c < nct && ct[c].tag == (int32_t)i; c++) {
                if (moved[ct[c].obstacle]) continue; /* it has left that place */
                if ((ct[c].how & VW_PROBE_END) && end_hit < 0) end_hit = ct[c].obstacle;
                if (sweep_hits(ct[c].how) && sweep_hit < 0) sweep_hit = ct[c].obstacle;
            }
            /* The new places of the edits accepted before this one in the batch. */
            for (size_t j = 0; j < i; j++) {
                if (!ok[j] || pd[j].remove || res[j].outcome != VW_OUT_ACCEPTED) continue;
                if (!boxes_overlap(&pd[i].reach, &pd[j].endb, ds->tol)) continue;
                int how = 0; /* over every pair of their shapes: the rule is per object */
                for (size_t k = 0; k < (size_t)pd[i].nshapes; k++) {
                    vw_probe p;
                    memset(&p, 0, sizeof p);
                    p.end = ends[pd[i].probe0 + k];
                    p.flags = VW_PROBE_END;
                    p.start = pd[i].add ? p.end : ds->shapes[ds->obj[pd[i].id].slot + k];
                    if (!pd[i].add && sweep && pd[i].swept) {
                        p.flags |= VW_PROBE_SWEEP;
                        memcpy(p.d, pd[i].d, sizeof p.d);
                    }
                    vw_box pb, sb;
                    vw_shape_bounds(&p.end, NULL, &pb);
                    vw_shape_bounds(&p.start, p.d, &sb);
                    for (int a = 0; a < 3; a++) pb.lo[a] = fmin(pb.lo[a], sb.lo[a]), pb.hi[a] = fmax(pb.hi[a], sb.hi[a]);
                    for (size_t m = 0; m < (size_t)pd[j].nshapes; m++) {
                        const vw_shape *o = &ends[pd[j].probe0 + m];
                        vw_box ob;
                        vw_shape_bounds(o, NULL, &ob);
                        if (!boxes_overlap(&pb, &ob, ds->tol)) continue;
                        how |= vw__probe_test(&p, o, ds->tol);
                    }
                }
                if ((how & VW_PROBE_END) && (end_hit < 0 || pd[j].id < end_hit)) end_hit = pd[j].id;
                if (sweep_hits(how) && (sweep_hit < 0 || pd[j].id < sweep_hit)) sweep_hit = pd[j].id;
            }
        }
        if (end_hit >= 0) {
            res[i].outcome = VW_OUT_COLLISION;
            res[i].obstacle = end_hit;
        } else if (sweep_hit >= 0) {
            res[i].outcome = VW_OUT_SWEEP;
            res[i].obstacle = sweep_hit;
        } else {
            moved[pd[i].id] = 1;
        }
    }
    /* Commit the accepted edits, in order (adds take their ids in order): their room
       first, agreed, since each commit updates the collider (collective). */
    if (st == VW_OK) st = reserve_commits(ds, pd, res, ok, n);
    if (why) {
        /* The query failed on every process alike, with one message: no agreement
           (it would name the lowest rank, not the one that failed). */
        if (!ds->errmsg[0])
            vw_errmsg_wrap(ds->errmsg, sizeof ds->errmsg, "checking a batch of edits for collisions", why);
    } else {
        st = agree(ds, st, "deciding a batch of edits");
    }
    for (size_t i = 0; i < n && st == VW_OK; i++) {
        if (!ok[i] || res[i].outcome != VW_OUT_ACCEPTED) continue;
        st = commit_edit(ds, &pd[i], ends ? ends + pd[i].probe0 : NULL);
        if (st == VW_OK) {
            changed_bits[pd[i].id] = 1;
            if ((size_t)pd[i].id + 1 > *nbits) *nbits = (size_t)pd[i].id + 1;
        }
    }
    for (size_t i = 0; pd && i < n; i++) geom_free(&pd[i].g);
    free(moved);
    free(ct);
    free(ends);
    free(b.probes);
    free(ok);
    free(pd);
    return st;
}

vw_status vw_dynscene_apply(vw_dynscene *ds, const vw_edit *edits, size_t n, int check, int sweep,
                            vw_result *results, int **changed, size_t *nchanged)
{
    if (!ds || (n && (!edits || !results)) || !changed || !nchanged) return VW_E_INVAL;
    *changed = NULL;
    *nchanged = 0;
    for (size_t i = 0; i < n; i++)
        if (!vw_edit_is_object(edits[i].op)) return VW_E_INVAL;
    /* Every id the batch can create, and so every id an accepted edit can name. A larger
       id names no object (its edit is invalid, whatever else the run holds), so it needs
       no byte: sized by the ids named, "remove 2000000000" cost 4 GB. */
    size_t maxid = (size_t)ds->nids + n + 1;
    unsigned char *bits = calloc(maxid, 1), *seen = calloc(maxid, 1);
    ds->errmsg[0] = 0;
    vw_status st = agree(ds, (bits && seen) ? VW_OK : VW_E_NOMEM, "the edits' bookkeeping");
    size_t nbits = 0, i = 0;
    while (st == VW_OK && i < n) {
        /* The longest run of edits with distinct ids. An add never repeats an id, but it
           ends the run, so the ids of later adds are known when they are prepared. */
        size_t j = i;
        while (j < n) {
            const vw_edit *e = &edits[j];
            if (e->op == VW_EDIT_ADD) {
                j++;
                break;
            }
            if (e->id >= 0 && (size_t)e->id < maxid) {
                if (seen[e->id]) break;
                seen[e->id] = 1;
            }
            j++;
        }
        for (size_t k = i; k < j; k++)
            if (edits[k].op != VW_EDIT_ADD && edits[k].id >= 0 && (size_t)edits[k].id < maxid) seen[edits[k].id] = 0;
        st = run_batch(ds, edits + i, j - i, check, sweep, results + i, bits, &nbits);
        i = j;
    }
    size_t m = 0;
    for (size_t k = 0; k < nbits; k++) m += bits[k];
    int *out = malloc((m ? m : 1) * sizeof *out);
    if (!out && st == VW_OK) st = VW_E_NOMEM;
    /* The caller's next step may be collective too (a world update). */
    if (st != VW_OK && !ds->errmsg[0])
        snprintf(ds->errmsg, sizeof ds->errmsg, "committing the edits: %s", vw_status_message(st));
    st = agree(ds, st, "listing the changed objects");
    if (st == VW_OK) {
        m = 0;
        for (size_t k = 0; k < nbits; k++)
            if (bits[k]) out[m++] = (int)k;
        *changed = out;
        *nchanged = m;
    } else {
        free(out);
    }
    free(bits);
    free(seen);
    return st;
}

/* ---- writing -------------------------------------------------------------------------- */

vw_status vw_dynscene_write_nff(const vw_dynscene *ds, FILE *f)
{
    const vw_scene *s = ds->s;
    vw_scene live = *s;
    live.spheres = malloc((s->nspheres ? s->nspheres : 1) * sizeof *live.spheres);
    live.cones = malloc((s->ncones ? s->ncones : 1) * sizeof *live.cones);
    live.polygons = malloc((s->npolygons ? s->npolygons : 1) * sizeof *live.polygons);
    vw_status st = VW_E_NOMEM;
    if (live.spheres && live.cones && live.polygons) {
        live.nspheres = live.ncones = live.npolygons = 0;
        for (size_t i = 0; i < s->nspheres; i++)
            if (vw_dynscene_alive(ds, s->spheres[i].id)) live.spheres[live.nspheres++] = s->spheres[i];
        for (size_t i = 0; i < s->ncones; i++)
            if (vw_dynscene_alive(ds, s->cones[i].id)) live.cones[live.ncones++] = s->cones[i];
        for (size_t i = 0; i < s->npolygons; i++)
            if (vw_dynscene_alive(ds, s->polygons[i].id)) live.polygons[live.npolygons++] = s->polygons[i];
        st = vw_scene_write_nff(&live, f);
    }
    free(live.spheres);
    free(live.cones);
    free(live.polygons);
    return st;
}
