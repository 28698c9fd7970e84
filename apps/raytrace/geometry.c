/* geometry.c - a cell's Embree scene over its object records, and the queries the
 * shading needs: the first hit in a t-interval and "is anything in this interval".
 * Spheres are Embree points (RTC_GEOMETRY_TYPE_SPHERE_POINT), triangles triangle
 * geometry, NFF cones user geometry with the exact intersection below.
 *
 * Invariant for bit-identical images: the hit found for a ray and an interval depends
 * only on the ray and the primitives, never on which other primitives share the cell.
 * Every primitive test is a pure function of (ray, primitive). The intervals of a ray's
 * segments do not tile its whole interval exactly in Embree's float tests (its box
 * tests round, and a flat box on a wall can be missed from both sides), so a cell's
 * interval runs past its far wall by an overlap (walk_ray, rt_shared.overlap). Exactly
 * coincident primitives tie, and which one Embree reports depends on its tree: such
 * z-fighting is outside the invariant (docs/known-issues.md).
 *
 * Embree sees the scene in a float frame (rt_float_frame): measured from an origin
 * inside it when it lies far from (0, 0, 0) for its size, so its floats keep their bits
 * for the scene's detail, and multiplied by a power of two: Embree's tests multiply
 * three or four coordinates, which overflow for a scene 1e12 across and vanish for one
 * 1e-15 across, so such a scene is brought near unit size. The product with a power of
 * two is exact, so the tests find the same hits, at t * scale; t does not change with
 * the origin.
 */
#include <embree3/rtcore.h>
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include "raytrace/geometry.h"

/* The intersect context carries the ray in double precision to the cone callbacks. */
typedef struct rt_isect_ctx {
    struct RTCIntersectContext base; /* first: Embree hands back a pointer to it */
    const double *org, *dir;
} rt_isect_ctx;

/* ---- cones -------------------------------------------------------------------------- */

/* The smallest t with t * scale in [tn, tf] (compared as floats, like Embree's own tests)
   where the ray meets the cone's side between its end discs; 0 when there is none.
   The side is |P - (P.w)w|^2 = (r0 + k P.w)^2 for 0 <= P.w <= h, with P = o + t d - base,
   w the unit axis, h its length and k = (r1 - r0) / h. */
static int cone_hit(const rt_object *o, const double org[3], const double dir[3], float tn,
                    float tf, double scale, double *tout)
{
    double w[3], D[3], h = 0;
    for (int a = 0; a < 3; a++) {
        w[a] = o->g.cone.apex[a] - o->g.cone.base[a];
        D[a] = org[a] - o->g.cone.base[a];
        h += w[a] * w[a];
    }
    h = sqrt(h);
    if (!(h > 0)) return 0;
    for (int a = 0; a < 3; a++) w[a] /= h;
    double r0 = o->g.cone.r0, k = (o->g.cone.r1 - o->g.cone.r0) / h;
    double dw = dir[0] * w[0] + dir[1] * w[1] + dir[2] * w[2];
    double Dw = D[0] * w[0] + D[1] * w[1] + D[2] * w[2];
    /* The coefficients from the parts of d and D across the axis, not as dd - dw^2 and
       DD - Dw^2: those differences cancel for a ray nearly along the axis (A ~ 1e-14
       from two numbers near 1, with an error of a per cent) and for an origin far along
       it (DD ~ 1e13), and a ray 1e-7 rad off a cylinder's axis then met its side
       0.02 % off; the parts across are small numbers computed as such. */
    double dp[3], Dp[3];
    for (int a = 0; a < 3; a++) {
        dp[a] = dir[a] - dw * w[a];
        Dp[a] = D[a] - Dw * w[a];
    }
    double rD = r0 + k * Dw;
    double A = dp[0] * dp[0] + dp[1] * dp[1] + dp[2] * dp[2] - k * k * dw * dw;
    double B = 2.0 * (Dp[0] * dp[0] + Dp[1] * dp[1] + Dp[2] * dp[2] - rD * k * dw);
    double C = Dp[0] * Dp[0] + Dp[1] * Dp[1] + Dp[2] * Dp[2] - rD * rD;
    double ts[2];
    int nt = 0;
    /* Linear only where the quadratic term is exactly gone (a ray parallel to a
       cylinder's axis, or to a cone's side). A small A is no licence to drop it: a ray
       at 1e-7 rad to a cylinder 7e6 long has A ~ 1e-13, and A t^2 ~ 1 at t ~ 3e6,
       where the linear root made a hit out of a miss. The stable pair below keeps the
       near root accurate for a small A, and puts the far one far away. */
    if (A == 0) {
        if (B != 0) ts[nt++] = -C / B;
    } else {
        double disc = B * B - 4 * A * C;
        if (disc < 0) return 0;
        double s = sqrt(disc);
        /* The numerically stable pair of roots. */
        double q = B < 0 ? -0.5 * (B - s) : -0.5 * (B + s);
        double x0 = q / A, x1 = q != 0 ? C / q : x0;
        ts[nt++] = fmin(x0, x1);
        ts[nt++] = fmax(x0, x1);
    }
    for (int i = 0; i < nt; i++) {
        double t = ts[i];
        float tf32 = (float)(t * scale);
        if (!(tf32 >= tn && tf32 <= tf)) continue;
        double z = Dw + t * dw;
        /* Only the nappe whose radius is the (non-negative) interpolated radius. */
        if (z < 0 || z > h || r0 + k * z < 0) continue;
        *tout = t;
        return 1;
    }
    return 0;
}

void rt_cone_normal(const rt_object *o, const double p[3], double n[3])
{
    double w[3], P[3], h = 0;
    for (int a = 0; a < 3; a++) {
        w[a] = o->g.cone.apex[a] - o->g.cone.base[a];
        P[a] = p[a] - o->g.cone.base[a];
        h += w[a] * w[a];
    }
    h = sqrt(h);
    for (int a = 0; a < 3; a++) w[a] /= h;
    double k = (o->g.cone.r1 - o->g.cone.r0) / h;
    double z = P[0] * w[0] + P[1] * w[1] + P[2] * w[2];
    double r = o->g.cone.r0 + k * z;
    /* Gradient of |P - zw|^2 - (r0 + kz)^2, halved. */
    double l = 0;
    for (int a = 0; a < 3; a++) {
        n[a] = P[a] - z * w[a] - k * r * w[a];
        l += n[a] * n[a];
    }
    l = sqrt(l);
    double s = (o->flags & RT_INSIDE) ? -1.0 : 1.0;
    for (int a = 0; a < 3; a++) n[a] = l > 0 ? s * n[a] / l : 0;
}

static void cone_bounds(const struct RTCBoundsFunctionArguments *args)
{
    const rt_cell_geo *g = args->geometryUserPtr;
    const rt_object *o = &g->obj[g->cone_map[args->primID]];
    vw_box b;
    rt_object_bounds(o, 0, &b);
    for (int a = 0; a < 3; a++) { /* into the float frame, widened by the subtraction's rounding */
        const double *o0 = g->ff.origin;
        double elo = 0x1p-51 * (fabs(b.lo[a]) + fabs(o0[a]));
        double ehi = 0x1p-51 * (fabs(b.hi[a]) + fabs(o0[a]));
        b.lo[a] = (b.lo[a] - o0[a] - elo) * g->ff.scale;
        b.hi[a] = (b.hi[a] - o0[a] + ehi) * g->ff.scale;
    }
    /* Round outward so the float box contains the double one. */
    args->bounds_o->lower_x = nextafterf((float)b.lo[0], -INFINITY);
    args->bounds_o->lower_y = nextafterf((float)b.lo[1], -INFINITY);
    args->bounds_o->lower_z = nextafterf((float)b.lo[2], -INFINITY);
    args->bounds_o->upper_x = nextafterf((float)b.hi[0], INFINITY);
    args->bounds_o->upper_y = nextafterf((float)b.hi[1], INFINITY);
    args->bounds_o->upper_z = nextafterf((float)b.hi[2], INFINITY);
}

static void cone_intersect(const struct RTCIntersectFunctionNArguments *args)
{
    if (!args->valid[0]) return;
    const rt_cell_geo *g = args->geometryUserPtr;
    const rt_isect_ctx *c = (const rt_isect_ctx *)args->context;
    struct RTCRayHit *rh = (struct RTCRayHit *)args->rayhit; /* N == 1: rtcIntersect1 */
    double t;
    if (!cone_hit(&g->obj[g->cone_map[args->primID]], c->org, c->dir, rh->ray.tnear,
                  rh->ray.tfar, g->ff.scale, &t))
        return;
    rh->ray.tfar = (float)(t * g->ff.scale);
    rh->hit.u = rh->hit.v = 0;
    rh->hit.Ng_x = rh->hit.Ng_y = rh->hit.Ng_z = 0;
    rh->hit.primID = args->primID;
    rh->hit.geomID = args->geomID;
    rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

static void cone_occluded(const struct RTCOccludedFunctionNArguments *args)
{
    if (!args->valid[0]) return;
    const rt_cell_geo *g = args->geometryUserPtr;
    const rt_isect_ctx *c = (const rt_isect_ctx *)args->context;
    struct RTCRay *r = (struct RTCRay *)args->ray;
    double t;
    if (cone_hit(&g->obj[g->cone_map[args->primID]], c->org, c->dir, r->tnear, r->tfar,
                 g->ff.scale, &t))
        r->tfar = -INFINITY;
}

/* ---- the cell's scene ------------------------------------------------------------ */

static vw_status attach(rt_cell_geo *g, RTCGeometry geom, int kind)
{
    rtcCommitGeometry(geom);
    unsigned id = rtcAttachGeometry((RTCScene)g->scene, geom);
    rtcReleaseGeometry(geom);
    if (id >= 3) return VW_E_STATE;
    g->geom_kind[id] = kind;
    return VW_OK;
}

vw_status rt_cell_geo_build(void *device, const rt_object *objects, size_t n,
                            const rt_float_frame *ff, rt_cell_geo *g)
{
    memset(g, 0, sizeof *g);
    g->ff = *ff;
    const double *o0 = ff->origin, scale = ff->scale;
    g->geom_kind[0] = g->geom_kind[1] = g->geom_kind[2] = -1;
    g->obj = malloc((n ? n : 1) * sizeof *g->obj);
    g->sph_map = malloc((n ? n : 1) * sizeof *g->sph_map);
    g->tri_map = malloc((n ? n : 1) * sizeof *g->tri_map);
    g->cone_map = malloc((n ? n : 1) * sizeof *g->cone_map);
    if (!g->obj || !g->sph_map || !g->tri_map || !g->cone_map) return VW_E_NOMEM;
    if (n) memcpy(g->obj, objects, n * sizeof *g->obj);
    g->nobj = n;
    for (int a = 0; a < 3; a++) {
        g->bounds.lo[a] = INFINITY;
        g->bounds.hi[a] = -INFINITY;
    }
    size_t ns = 0, nt = 0, nc = 0;
    for (size_t i = 0; i < n; i++) {
        vw_box b;
        rt_object_bounds(&g->obj[i], 0, &b);
        for (int a = 0; a < 3; a++) {
            if (b.lo[a] < g->bounds.lo[a]) g->bounds.lo[a] = b.lo[a];
            if (b.hi[a] > g->bounds.hi[a]) g->bounds.hi[a] = b.hi[a];
        }
        switch (g->obj[i].kind) {
        case RT_SPHERE: g->sph_map[ns++] = (uint32_t)i; break;
        case RT_TRIANGLE: g->tri_map[nt++] = (uint32_t)i; break;
        case RT_CONE: g->cone_map[nc++] = (uint32_t)i; break;
        default: break;
        }
    }
    RTCDevice dev = (RTCDevice)device;
    RTCScene sc = rtcNewScene(dev);
    if (!sc) return VW_E_NOMEM;
    g->scene = sc;
    rtcSetSceneBuildQuality(sc, RTC_BUILD_QUALITY_MEDIUM);
    /* Robust mode: without it, rays aimed at the edges two triangles share slip between
       them 7% of the time, and at shared vertices 19% (test raytrace_watertight), which
       shows the background through a mesh as single bright or dark pixels. It costs
       2-6% on the sphereflake. Every cell alike, so a hit never depends on the layout. */
    rtcSetSceneFlags(sc, RTC_SCENE_FLAG_ROBUST);
    vw_status st = VW_OK;
    if (ns) {
        RTCGeometry geom = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_SPHERE_POINT);
        float *v = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                           4 * sizeof(float), ns);
        if (!v) return VW_E_NOMEM;
        for (size_t i = 0; i < ns; i++) {
            const rt_object *o = &g->obj[g->sph_map[i]];
            for (int a = 0; a < 3; a++) v[4 * i + a] = (float)((o->g.sphere.c[a] - o0[a]) * scale);
            v[4 * i + 3] = (float)(o->g.sphere.r * scale);
        }
        if ((st = attach(g, geom, RT_SPHERE)) != VW_OK) return st;
    }
    if (nt) {
        RTCGeometry geom = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
        float *v = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                           3 * sizeof(float), 3 * nt);
        unsigned *ix = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0,
                                               RTC_FORMAT_UINT3, 3 * sizeof(unsigned), nt);
        if (!v || !ix) return VW_E_NOMEM;
        /* Three vertices of its own per triangle: a triangle's float data (and so its
           hits) must not depend on which other triangles share the cell. */
        for (size_t i = 0; i < nt; i++) {
            const rt_object *o = &g->obj[g->tri_map[i]];
            for (int c = 0; c < 3; c++) {
                for (int a = 0; a < 3; a++)
                    v[9 * i + 3 * c + a] = (float)((o->g.tri.v[c][a] - o0[a]) * scale);
                ix[3 * i + c] = (unsigned)(3 * i + c);
            }
        }
        if ((st = attach(g, geom, RT_TRIANGLE)) != VW_OK) return st;
    }
    if (nc) {
        RTCGeometry geom = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_USER);
        rtcSetGeometryUserPrimitiveCount(geom, (unsigned)nc);
        rtcSetGeometryUserData(geom, g);
        rtcSetGeometryBoundsFunction(geom, cone_bounds, NULL);
        rtcSetGeometryIntersectFunction(geom, cone_intersect);
        rtcSetGeometryOccludedFunction(geom, cone_occluded);
        if ((st = attach(g, geom, RT_CONE)) != VW_OK) return st;
    }
    rtcCommitScene(sc);
    if (rtcGetDeviceError(dev) != RTC_ERROR_NONE) return VW_E_STATE;
    return VW_OK;
}

void rt_cell_geo_free(rt_cell_geo *g)
{
    if (!g) return;
    if (g->scene) rtcReleaseScene((RTCScene)g->scene);
    free(g->obj);
    free(g->sph_map);
    free(g->tri_map);
    free(g->cone_map);
    memset(g, 0, sizeof *g);
}

/* The ray as Embree sees it: its origin in the float frame, t scaled, the direction as
   it is. The identity frame (most scenes) skips the arithmetic, a few per cent of a
   call. */
static void make_ray(struct RTCRay *r, const double org[3], const double dir[3], double tn,
                     double tf, const rt_float_frame *ff)
{
    if (ff->moved) {
        double scale = ff->scale;
        r->org_x = (float)((org[0] - ff->origin[0]) * scale);
        r->org_y = (float)((org[1] - ff->origin[1]) * scale);
        r->org_z = (float)((org[2] - ff->origin[2]) * scale);
        r->tnear = (float)(tn * scale);
        r->tfar = (float)(tf * scale);
    } else {
        r->org_x = (float)org[0];
        r->org_y = (float)org[1];
        r->org_z = (float)org[2];
        r->tnear = (float)tn;
        r->tfar = (float)tf;
    }
    r->dir_x = (float)dir[0];
    r->dir_y = (float)dir[1];
    r->dir_z = (float)dir[2];
    r->time = 0;
    r->mask = 0xFFFFFFFFu;
    r->id = 0;
    r->flags = 0;
}

int rt_cell_geo_intersect(const rt_cell_geo *g, const double org[3], const double dir[3],
                          double tnear, double tfar, rt_hit *hit)
{
    if (!g->scene || !(tnear <= tfar)) return 0;
    rt_isect_ctx c;
    rtcInitIntersectContext(&c.base);
    c.org = org;
    c.dir = dir;
    struct RTCRayHit rh;
    make_ray(&rh.ray, org, dir, tnear, tfar, &g->ff);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1((RTCScene)g->scene, &c.base, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID || rh.hit.geomID >= 3) return 0;
    int kind = g->geom_kind[rh.hit.geomID];
    const uint32_t *map = kind == RT_SPHERE ? g->sph_map
                          : kind == RT_TRIANGLE ? g->tri_map : g->cone_map;
    hit->obj = &g->obj[map[rh.hit.primID]];
    hit->t = g->ff.moved ? rh.ray.tfar * g->ff.inv_scale : rh.ray.tfar; /* exact */
    hit->u = rh.hit.u;
    hit->v = rh.hit.v;
    return 1;
}

int rt_cell_geo_occluded(const rt_cell_geo *g, const double org[3], const double dir[3],
                         double tnear, double tfar)
{
    if (!g->scene || !(tnear <= tfar)) return 0;
    rt_isect_ctx c;
    rtcInitIntersectContext(&c.base);
    c.org = org;
    c.dir = dir;
    struct RTCRay r;
    make_ray(&r, org, dir, tnear, tfar, &g->ff);
    rtcOccluded1((RTCScene)g->scene, &c.base, &r);
    return r.tfar == -INFINITY;
}

double rt_embree_scale(double far)
{
    if (!(far > 0) || !isfinite(far) || (far >= 0x1p-10 && far <= 0x1p20)) return 1.0;
    return ldexp(1.0, -ilogb(far));
}

const rt_float_frame rt_float_frame_identity = {{0, 0, 0}, 1.0, 1.0, 0};

rt_float_frame rt_float_frame_make(const double origin[3], double scale)
{
    rt_float_frame ff = {{origin[0], origin[1], origin[2]}, scale, 1.0 / scale, 0};
    ff.moved = origin[0] != 0 || origin[1] != 0 || origin[2] != 0 || scale != 1.0;
    return ff;
}

rt_float_frame rt_float_frame_of(const double eye[3], const vw_box *world)
{
    double origin[3] = {0, 0, 0}, diag2 = 0, dist2 = 0, c[3];
    for (int a = 0; a < 3; a++) {
        c[a] = 0.5 * (world->lo[a] + world->hi[a]);
        diag2 += (world->hi[a] - world->lo[a]) * (world->hi[a] - world->lo[a]);
        dist2 += c[a] * c[a];
    }
    if (dist2 > 16 * diag2) memcpy(origin, c, sizeof c); /* |c| > 4 diagonals */
    double far = 0;
    for (int a = 0; a < 3; a++) {
        far = fmax(far, fabs(eye[a] - origin[a]));
        far = fmax(far, fmax(fabs(world->lo[a] - origin[a]), fabs(world->hi[a] - origin[a])));
    }
    return rt_float_frame_make(origin, rt_embree_scale(far));
}

double rt_float_frame_norm1(const rt_float_frame *ff, const double p[3])
{
    const double *o = ff->origin;
    double rel = fabs(p[0] - o[0]) + fabs(p[1] - o[1]) + fabs(p[2] - o[2]);
    return fmax(rel, 1e-7 * (fabs(p[0]) + fabs(p[1]) + fabs(p[2])));
}

void *rt_device_new(int threads)
{
    /* A cell's build runs on the worker that hosts it, and Embree may share it among as
       many threads as the process has workers: the builds of different cells then
       overlap as they did, and a cell that farmed copies share (one build, which the
       other copies wait for) is built by them all. One thread did that build alone
       while the others idled: 4.4 -> 3.4 ms for the level-4 sphereflake on two workers,
       35 -> 25 ms for the size-5 one (median of 25 and 5 renders). */
#if defined(__SANITIZE_THREAD__)
    /* ThreadSanitizer: TBB's worker threads synchronise in code it does not see, and it
       takes what they reach through its interceptors for races (libstdc++ comparing
       Embree's strings, a delete at exit: CI, twentieth session). The TSan build runs
       Embree's builds on the calling worker alone, as every build did before; it checks
       the runtime's threads, not Embree's (tests/raytrace/tsan.supp). */
    threads = 1;
#endif
    char cfg[64];
    snprintf(cfg, sizeof cfg, "threads=%d,set_affinity=0,verbose=0", threads > 1 ? threads : 1);
    return rtcNewDevice(cfg);
}

void rt_device_free(void *device)
{
    if (device) rtcReleaseDevice((RTCDevice)device);
}

/* ---- built cells shared within a process ------------------------------------------- */

typedef struct rt_geo_entry {
    struct rt_geo_entry *next;
    /* The records it is built from, compared under the lock: the builder's own while
       it is being built, then geo.obj. The geometry is built in place (Embree keeps its
       address for the cones' callbacks), outside the lock, and read only once ready. */
    const rt_object *key;
    size_t nkey;
    rt_cell_geo geo;
    int refs;
    int state;         /* 0 building, 1 ready, -1 failed (waiters give up) */
    vw_status status;
} rt_geo_entry;

struct rt_geo_cache {
    rt_float_frame ff; /* every geometry's */
    pthread_mutex_t mu;
    pthread_cond_t cv; /* an entry left the building state */
    rt_geo_entry *head;
};

rt_geo_cache *rt_geo_cache_new(const rt_float_frame *ff)
{
    rt_geo_cache *c = calloc(1, sizeof *c);
    if (!c) return NULL;
    c->ff = *ff;
    pthread_mutex_init(&c->mu, NULL);
    pthread_cond_init(&c->cv, NULL);
    return c;
}

void rt_geo_cache_free(rt_geo_cache *c)
{
    if (!c) return;
    while (c->head) { /* only after a leak elsewhere: free what is left */
        rt_geo_entry *e = c->head;
        c->head = e->next;
        rt_cell_geo_free(&e->geo);
        free(e);
    }
    pthread_cond_destroy(&c->cv);
    pthread_mutex_destroy(&c->mu);
    free(c);
}

size_t rt_geo_cache_size(rt_geo_cache *c)
{
    size_t n = 0;
    pthread_mutex_lock(&c->mu);
    for (rt_geo_entry *e = c->head; e; e = e->next) n++;
    pthread_mutex_unlock(&c->mu);
    return n;
}

/* An entry with these very records (its records are set before it is listed). */
static rt_geo_entry *find(rt_geo_cache *c, const rt_object *objects, size_t n)
{
    for (rt_geo_entry *e = c->head; e; e = e->next)
        if (e->state >= 0 && e->nkey == n &&
            (n == 0 || memcmp(e->key, objects, n * sizeof *objects) == 0))
            return e;
    return NULL;
}

/* Drops one reference, the lock held; the last one unlinks and frees the entry. */
static void unref(rt_geo_cache *c, rt_geo_entry *e)
{
    if (--e->refs > 0) return;
    rt_geo_entry **pp = &c->head;
    while (*pp != e) pp = &(*pp)->next;
    *pp = e->next;
    rt_cell_geo_free(&e->geo);
    free(e);
}

vw_status rt_geo_acquire(rt_geo_cache *c, void *device, const rt_object *objects, size_t n,
                         const rt_cell_geo **out)
{
    *out = NULL;
    pthread_mutex_lock(&c->mu);
    rt_geo_entry *e = find(c, objects, n);
    if (e) {
        e->refs++;
        while (e->state == 0) pthread_cond_wait(&c->cv, &c->mu);
        vw_status st = e->state > 0 ? VW_OK : e->status;
        if (st == VW_OK)
            *out = &e->geo;
        else
            unref(c, e); /* the builder failed */
        pthread_mutex_unlock(&c->mu);
        return st;
    }
    /* Build it here, listed as building so that others asking for it wait. While it is
       built, the key is the caller's own records, which stay as they are until this
       call returns, and that is after the key has become geo.obj (under the lock). */
    e = calloc(1, sizeof *e);
    if (!e) {
        pthread_mutex_unlock(&c->mu);
        return VW_E_NOMEM;
    }
    e->key = objects;
    e->nkey = n;
    e->refs = 1;
    e->next = c->head;
    c->head = e;
    pthread_mutex_unlock(&c->mu);

    vw_status st = rt_cell_geo_build(device, objects, n, &c->ff, &e->geo);

    pthread_mutex_lock(&c->mu);
    e->key = st == VW_OK ? e->geo.obj : NULL; /* (a failed entry is never compared) */
    e->state = st == VW_OK ? 1 : -1;
    e->status = st;
    pthread_cond_broadcast(&c->cv);
    if (st == VW_OK)
        *out = &e->geo;
    else
        unref(c, e);
    pthread_mutex_unlock(&c->mu);
    return st;
}

void rt_geo_release(rt_geo_cache *c, const rt_cell_geo *g)
{
    if (!c || !g) return;
    pthread_mutex_lock(&c->mu);
    for (rt_geo_entry *e = c->head; e; e = e->next)
        if (&e->geo == g) {
            unref(c, e);
            break;
        }
    pthread_mutex_unlock(&c->mu);
}
