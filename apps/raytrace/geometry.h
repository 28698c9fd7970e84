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
    rt_float_frame ff;           /* Embree's coordinates: (world's - ff.origin) * ff.scale */
} rt_cell_geo;

typedef struct rt_hit {
    const rt_object *obj;
    double t;                    /* as Embree found it (a float) */
    float u, v;                  /* barycentrics of a triangle hit */
} rt_hit;

vw_status rt_cell_geo_build(void *device, const rt_object *objects, size_t n,
                            const rt_float_frame *ff, rt_cell_geo *g);
void rt_cell_geo_free(rt_cell_geo *g);
/* Built cells shared within a process: the copies of a farmed or duplicated cell have
   the same records, so they read one scene (Embree's queries are thread-safe) instead
   of each worker building and keeping its own. Entries are counted references; the
   first worker to ask for some records builds them while the others wait. */
typedef struct rt_geo_cache rt_geo_cache;
rt_geo_cache *rt_geo_cache_new(const rt_float_frame *ff); /* its geometries' frame */
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

/* The power of two Embree's coordinates are multiplied by, for a scene whose
   coordinates (and eye) lie at most `far` from the origin: 1 from 2^-10 to 2^20, where
   Embree's floats are at ease (so most scenes give Embree their own numbers), else the
   power that brings far into [1, 2). */
double rt_embree_scale(double far);
/* The frame of a job whose rays start at the eye or inside the world box (world
   coordinates): the origin is the box's centre when the box lies further from (0, 0, 0)
   than four times its diagonal, else (0, 0, 0), so that most scenes give Embree their
   own numbers; the scale is rt_embree_scale of the largest coordinate of the eye and the
   box measured from that origin. */
rt_float_frame rt_float_frame_of(const double eye[3], const vw_box *world);
/* The magnitude the ray tracer's margins (rt_shared.eps, overlap, a cell's reach) are
   proportional to, for a point p where rays start: |p - ff.origin| in the 1-norm, which
   Embree's float error (2^-24) is relative to, and at least 1e-7 of |p|, which the
   doubles' own rounding (2^-53) is relative to: the margins, 1e-6 of it and more, then
   stay a thousand times above both. Without an origin it is |p|. */
double rt_float_frame_norm1(const rt_float_frame *ff, const double p[3]);
/* The frame with this origin and scale (a power of two). */
rt_float_frame rt_float_frame_make(const double origin[3], double scale);
/* The identity frame (origin 0, scale 1), for tests and tools that trace raw scenes. */
extern const rt_float_frame rt_float_frame_identity;
/* One RTCDevice per process, shared by every cell (Embree's device is thread-safe); a
   build uses up to `threads` threads (the process's workers). */
void *rt_device_new(int threads);
void rt_device_free(void *device);

#endif
