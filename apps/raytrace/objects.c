/* objects.c - the ray tracer's object records: a scene's spheres, cones and polygons as
 * plain records with their material copied in, so any cell can shade any hit alone.
 * Polygons are split by vw_polygon_triangulate (a fan when convex, ear clipping when
 * concave); every triangle keeps its polygon's global id.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "raytrace/raytrace.h"

static void material_of(const vw_scene *s, int m, vw_material *out)
{
    if (m >= 0 && (size_t)m < s->nmaterials) {
        *out = s->materials[m];
    } else {
        /* No material given: white diffuse, the NFF default before any 'f'. */
        memset(out, 0, sizeof *out);
        out->diffuse[0] = out->diffuse[1] = out->diffuse[2] = 1.0f;
        out->ior = 1.0f;
    }
}

static double tri_area2(const double a[3], const double b[3], const double c[3])
{
    double e1[3], e2[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = b[k] - a[k];
        e2[k] = c[k] - a[k];
    }
    double x = e1[1] * e2[2] - e1[2] * e2[1];
    double y = e1[2] * e2[0] - e1[0] * e2[2];
    double z = e1[0] * e2[1] - e1[1] * e2[0];
    return x * x + y * y + z * z;
}

/* Scratch space for one polygon's corners and triangles, grown as polygons need. */
typedef struct poly_work {
    double (*v)[3];
    int (*tri)[3];
    int cap;
} poly_work;

/* The count - 2 triangle records of polygon i into out. A triangle of zero area can
   never be hit; it is dropped (leaving it out keeps NaN normals out of the shading)
   or, with keep_empty, becomes an empty record. *made gets the number written. */
static vw_status polygon_records(const vw_scene *s, size_t i, poly_work *w, int keep_empty,
                                 rt_object *out, size_t *made)
{
    const vw_polygon *p = &s->polygons[i];
    *made = 0;
    if (p->count < 3) return VW_OK;
    if (p->count > w->cap) {
        double (*v)[3] = realloc(w->v, (size_t)p->count * sizeof *v);
        if (!v) return VW_E_NOMEM;
        w->v = v;
        int (*t)[3] = realloc(w->tri, (size_t)p->count * sizeof *t);
        if (!t) return VW_E_NOMEM;
        w->tri = t;
        w->cap = p->count;
    }
    const int *idx = &s->indices[p->first];
    for (int j = 0; j < p->count; j++) memcpy(w->v[j], s->vertices[idx[j]], sizeof w->v[j]);
    vw_status st = vw_polygon_triangulate((const double (*)[3])w->v, p->count, w->tri);
    if (st != VW_OK) return st;
    int smooth = p->has_normals && s->normals;
    size_t k = 0;
    for (int j = 0; j + 2 < p->count; j++) {
        rt_object *r = &out[k];
        memset(r, 0, sizeof *r);
        for (int c = 0; c < 3; c++) {
            memcpy(r->g.tri.v[c], w->v[w->tri[j][c]], sizeof r->g.tri.v[c]);
            if (smooth)
                memcpy(r->g.tri.n[c], s->normals[(size_t)p->first + (size_t)w->tri[j][c]],
                       sizeof r->g.tri.n[c]);
        }
        if (!(tri_area2(r->g.tri.v[0], r->g.tri.v[1], r->g.tri.v[2]) > 0)) {
            if (keep_empty) rt_object_empty(&out[k++]);
            continue;
        }
        r->kind = RT_TRIANGLE;
        r->id = p->id;
        if (smooth) r->flags |= RT_SMOOTH;
        material_of(s, p->material, &r->mat);
        k++;
    }
    *made = k;
    return VW_OK;
}

size_t rt_objects_count(const vw_scene *s) { return s->nspheres + s->ncones + s->npolygons; }

size_t rt_objects_room(const vw_scene *s, size_t *widest)
{
    size_t room = s->nspheres + s->ncones, w = 1;
    for (size_t i = 0; i < s->npolygons; i++)
        if (s->polygons[i].count >= 3) {
            size_t t = (size_t)s->polygons[i].count - 2;
            room += t;
            if (t > w) w = t;
        }
    if (widest) *widest = w;
    return room;
}

/* A fresh record (every byte set: the geometry cache compares records by their bytes)
   of this kind, scene id and material. */
static rt_object *record(const vw_scene *s, rt_object *r, int kind, int id, int material)
{
    memset(r, 0, sizeof *r);
    r->kind = kind;
    r->id = id;
    material_of(s, material, &r->mat);
    return r;
}

vw_status rt_objects_next(const vw_scene *s, size_t *next, rt_object *out, size_t room, size_t *n)
{
    size_t k = 0, i = *next, end = rt_objects_count(s);
    poly_work w = {NULL, NULL, 0};
    vw_status st = VW_OK;
    /* Objects in the scene's order: its spheres, then its cones, then its polygons. */
    for (; i < end && st == VW_OK; i++) {
        if (i < s->nspheres) {
            if (k == room) break;
            const vw_sphere *sp = &s->spheres[i];
            rt_object *r = record(s, &out[k++], RT_SPHERE, sp->id, sp->material);
            memcpy(r->g.sphere.c, sp->center, sizeof r->g.sphere.c);
            r->g.sphere.r = fabs(sp->radius);
            /* NFF: a negative radius means only the inside is visible; as for cones, both
               sides are shaded and the sign turns the normal inward. */
            if (sp->radius < 0) r->flags |= RT_INSIDE;
        } else if (i < s->nspheres + s->ncones) {
            if (k == room) break;
            const vw_cone *c = &s->cones[i - s->nspheres];
            rt_object *r = record(s, &out[k++], RT_CONE, c->id, c->material);
            memcpy(r->g.cone.base, c->base, sizeof r->g.cone.base);
            memcpy(r->g.cone.apex, c->apex, sizeof r->g.cone.apex);
            r->g.cone.r0 = fabs(c->base_radius);
            r->g.cone.r1 = fabs(c->apex_radius);
            /* NFF: negative radii mean only the inside is visible; we shade both sides,
               so the sign only turns the normal (it matters for refraction). */
            if (c->base_radius < 0 || c->apex_radius < 0) r->flags |= RT_INSIDE;
        } else {
            size_t pi = i - s->nspheres - s->ncones, made;
            int count = s->polygons[pi].count;
            if (count >= 3 && (size_t)count - 2 > room - k) {
                if (k == 0) st = VW_E_INVAL; /* room for its triangles was promised */
                break;
            }
            st = polygon_records(s, pi, &w, 0, &out[k], &made);
            k += made;
        }
    }
    free(w.v);
    free(w.tri);
    if (st != VW_OK) return st;
    *next = i;
    *n = k;
    return VW_OK;
}

vw_status rt_objects_from_scene(const vw_scene *s, rt_object **out, size_t *n)
{
    size_t room = rt_objects_room(s, NULL), next = 0;
    rt_object *o = malloc((room ? room : 1) * sizeof *o);
    if (!o) return VW_E_NOMEM;
    vw_status st = rt_objects_next(s, &next, o, room, n);
    if (st != VW_OK) {
        free(o);
        return st;
    }
    *out = o;
    return VW_OK;
}

void rt_object_bounds(const rt_object *o, double pad, vw_box *out)
{
    switch (o->kind) {
    case RT_SPHERE:
        for (int a = 0; a < 3; a++) {
            out->lo[a] = o->g.sphere.c[a] - o->g.sphere.r;
            out->hi[a] = o->g.sphere.c[a] + o->g.sphere.r;
        }
        break;
    case RT_CONE: {
        /* Each end disc lies in the plane normal to the axis w; its extent along
           coordinate axis a is r * sqrt(1 - w_a^2). */
        double w[3], len = 0;
        for (int a = 0; a < 3; a++) {
            w[a] = o->g.cone.apex[a] - o->g.cone.base[a];
            len += w[a] * w[a];
        }
        len = sqrt(len);
        for (int a = 0; a < 3; a++) {
            double wa = len > 0 ? w[a] / len : 0;
            double e = sqrt(fmax(0.0, 1.0 - wa * wa));
            double b0 = o->g.cone.base[a], b1 = o->g.cone.apex[a];
            double r0 = o->g.cone.r0 * e, r1 = o->g.cone.r1 * e;
            out->lo[a] = fmin(b0 - r0, b1 - r1);
            out->hi[a] = fmax(b0 + r0, b1 + r1);
        }
        break;
    }
    default:
        for (int a = 0; a < 3; a++) {
            out->lo[a] = fmin(o->g.tri.v[0][a], fmin(o->g.tri.v[1][a], o->g.tri.v[2][a]));
            out->hi[a] = fmax(o->g.tri.v[0][a], fmax(o->g.tri.v[1][a], o->g.tri.v[2][a]));
        }
        break;
    }
    for (int a = 0; a < 3; a++) {
        out->lo[a] -= pad;
        out->hi[a] += pad;
    }
}

void rt_object_empty(rt_object *o)
{
    /* A zero sphere far beyond any world box: vw_decomp_cells_overlapping() gives no
       cell for it, so no cell holds it and Embree never sees it. */
    memset(o, 0, sizeof *o);
    o->kind = RT_SPHERE;
    o->id = -1;
    for (int a = 0; a < 3; a++) o->g.sphere.c[a] = 1e300;
}

size_t rt_object_records(const vw_scene *s, vw_prim_kind kind, size_t index, rt_object *out)
{
    if (kind != VW_PRIM_POLYGON) {
        /* The one-object scene trick keeps a single code path for records. */
        vw_scene one = *s;
        one.nspheres = one.ncones = one.npolygons = 0;
        if (kind == VW_PRIM_SPHERE) one.spheres = &s->spheres[index], one.nspheres = 1;
        else one.cones = &s->cones[index], one.ncones = 1;
        rt_object *o;
        size_t n;
        if (rt_objects_from_scene(&one, &o, &n) != VW_OK || n != 1) {
            rt_object_empty(out);
            return 1;
        }
        *out = *o;
        free(o);
        return 1;
    }
    const vw_polygon *p = &s->polygons[index];
    size_t n = p->count >= 3 ? (size_t)p->count - 2 : 0, made = 0;
    poly_work w = {NULL, NULL, 0};
    if (polygon_records(s, index, &w, 1, out, &made) != VW_OK || made != n)
        for (size_t k = 0; k < n; k++) rt_object_empty(&out[k]);
    free(w.v);
    free(w.tri);
    return n;
}
