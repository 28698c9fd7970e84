/* geometry.h - a cell's ray-tracing geometry (an Embree scene over the cell's object
 * records) and the two queries on it. App-local: only the ray tracer uses it.
 */
#ifndef RT_GEOMETRY_H
#define RT_GEOMETRY_H

#include "raytrace/raytrace.h"

typedef struct rt_cell_geo {
    void *scene;                 /* RTCScene */
    rt_object *obj;              /* the cell's own copy of its records */
    size_t nobj;
    uint32_t *sph_map, *tri_map, *cone_map; /* Embree primID -> index in obj */
    int geom_kind[3];            /* Embree geomID -> rt_kind */
    vw_box bounds;               /* of the objects (world coordinates); empty (lo > hi)
                                    without any */
    double scale;                /* Embree's coordinates are the world's times this */
} rt_cell_geo;

typedef struct rt_hit {
    const rt_object *obj;
    double t;                    /* as Embree found it (a float) */
    float u, v;                  /* barycentrics of a triangle hit */
} rt_hit;

/* scale: a power of two, the same for every cell of a job (rt_embree_scale). */
vw_status rt_cell_geo_build(void *device, const rt_object *objects, size_t n, double scale,
                            rt_cell_geo *g);
void rt_cell_geo_free(rt_cell_geo *g);
/* Built cells shared within a process: the copies of a farmed or duplicated cell have
   the same records, so they read one scene (Embree's queries are thread-safe) instead
   of each worker building and keeping its own. Entries are counted references; the
   first worker to ask for some records builds them while the others wait. */
typedef struct rt_geo_cache rt_geo_cache;
rt_geo_cache *rt_geo_cache_new(double scale); /* the scale its geometries are built at */
void rt_geo_cache_free(rt_geo_cache *c); /* every entry must have been released */
/* The geometry of objects[0..n): a built one with the very same records, or built now.
   Release with rt_geo_release. */
vw_status rt_geo_acquire(rt_geo_cache *c, void *device, const rt_object *objects, size_t n,
                         const rt_cell_geo **out);
void rt_geo_release(rt_geo_cache *c, const rt_cell_geo *g);
/* Distinct geometries alive (tests). */
size_t rt_geo_cache_size(rt_geo_cache *c);

/* The first hit with t in [tnear, tfar]; 0 when none. */
int rt_cell_geo_intersect(const rt_cell_geo *g, const double org[3], const double dir[3],
                          double tnear, double tfar, rt_hit *hit);
/* Is there any hit with t in [tnear, tfar]? */
int rt_cell_geo_occluded(const rt_cell_geo *g, const double org[3], const double dir[3],
                         double tnear, double tfar);
/* The unit outward normal of a cone's side at p (inward for RT_INSIDE cones). */
void rt_cone_normal(const rt_object *o, const double p[3], double n[3]);

/* One RTCDevice per process, shared by every cell (Embree's device is thread-safe). */
/* The power of two Embree's coordinates are multiplied by, for a scene whose
   coordinates (and eye) lie at most `far` from the origin: 1 from 2^-10 to 2^20, where
   Embree's floats are at ease (so most scenes give Embree their own numbers), else the
   power that brings far into [1, 2). */
double rt_embree_scale(double far);
void *rt_device_new(void);
void rt_device_free(void *device);

#endif
