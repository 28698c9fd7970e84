/* embree_raw.c - the kernel limit for bench/raytrace.sh: the same Whitted ray tree as
 * `vwalls render` (eye, shadow, mirror and refracted rays, same directions), traced by
 * a plain recursive loop of rtcIntersect1 / rtcOccluded1 on one Embree scene, with no
 * cells, no messages and no pixel packages. Prints rays, seconds and rays/s.
 *   usage: vw_bench_embree_raw SCENE.nff WxH [DEPTH]
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "raytrace/geometry.h"
#include "raytrace/raytrace.h"

typedef struct bench {
    rt_cell_geo geo;
    const rt_light *lights;
    int nlights, max_depth;
    double eps;
    long long rays;
    double sink; /* keeps the shading from being optimised away */
} bench;

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void unit3(double v[3])
{
    double l = sqrt(dot3(v, v));
    if (l > 0)
        for (int a = 0; a < 3; a++) v[a] /= l;
}

/* Where a ray leaving a surface of geometric normal n in direction d starts its search,
   as the ray tracer's shade() makes it (rt_ray_eps; the factor a float, as in the ray). */
static double start(const bench *b, const double d[3], const double n[3])
{
    return (double)rt_ray_eps(d, n) * b->eps;
}

/* One ray from org, its search from t = tn (0 for an eye ray: it leaves no surface). */
static void trace(bench *b, const double org[3], const double dir[3], double tn, int depth,
                  double wsum)
{
    rt_hit h;
    b->rays++;
    if (!rt_cell_geo_intersect(&b->geo, org, dir, tn, INFINITY, &h)) return;
    const rt_object *o = h.obj;
    const vw_material *m = &o->mat;
    double p[3], n[3];
    for (int a = 0; a < 3; a++) p[a] = org[a] + h.t * dir[a];
    if (o->kind == RT_SPHERE) {
        for (int a = 0; a < 3; a++) n[a] = p[a] - o->g.sphere.c[a];
    } else if (o->kind == RT_CONE) {
        rt_cone_normal(o, p, n);
    } else {
        double e1[3], e2[3];
        for (int a = 0; a < 3; a++) {
            e1[a] = o->g.tri.v[1][a] - o->g.tri.v[0][a];
            e2[a] = o->g.tri.v[2][a] - o->g.tri.v[0][a];
        }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    }
    unit3(n);
    int entering = dot3(dir, n) < 0;
    if (!entering)
        for (int a = 0; a < 3; a++) n[a] = -n[a];
    double dn = dot3(dir, n), refl[3];
    for (int a = 0; a < 3; a++) refl[a] = dir[a] - 2 * dn * n[a];
    unit3(refl);
    for (int i = 0; i < b->nlights; i++) {
        double l[3], dist;
        for (int a = 0; a < 3; a++) l[a] = b->lights[i].pos[a] - p[a];
        dist = sqrt(dot3(l, l));
        for (int a = 0; a < 3; a++) l[a] /= dist;
        double ndl = dot3(n, l), ts = start(b, l, n);
        if (ndl <= 0 || !(dist > ts)) continue;
        b->rays++;
        /* Short of the light by 64 eps, as shade() ends its shadow rays. */
        if (!rt_cell_geo_occluded(&b->geo, p, l, ts, dist - 64.0 * b->eps))
            b->sink += wsum * ndl * m->diffuse[0];
    }
    if (depth >= b->max_depth) return;
    /* A mirror ray where the ray tracer makes one (shade, apps/raytrace/module.c). */
    if (m->reflect[0] > 0 || m->reflect[1] > 0 || m->reflect[2] > 0)
        trace(b, p, refl, start(b, refl, n), depth + 1, wsum * m->reflect[0]);
    if (m->transmit > 0) {
        double ior = m->ior > 0 ? m->ior : 1.0, eta = entering ? 1.0 / ior : ior;
        double c1 = -dot3(dir, n), k2 = 1 - eta * eta * (1 - c1 * c1), t[3];
        if (k2 < 0) {
            memcpy(t, refl, sizeof t);
        } else {
            for (int a = 0; a < 3; a++) t[a] = eta * dir[a] + (eta * c1 - sqrt(k2)) * n[a];
            unit3(t);
        }
        trace(b, p, t, start(b, t, n), depth + 1, wsum * m->transmit);
    }
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int main(int argc, char **argv)
{
    int W = 512, H = 512, depth = argc > 3 ? atoi(argv[3]) : 5;
    if (argc < 3 || sscanf(argv[2], "%dx%d", &W, &H) != 2) {
        fprintf(stderr, "usage: vw_bench_embree_raw SCENE.nff WxH [DEPTH]\n");
        return 2;
    }
    char err[512];
    vw_scene *s;
    if (vw_scene_read_file(argv[1], &s, err, sizeof err) != VW_OK) {
        fprintf(stderr, "%s\n", err);
        return 2;
    }
    /* The same camera, lights and epsilon as `vwalls render` (through rt_job). */
    rt_params p;
    memset(&p, 0, sizeof p);
    p.width = W;
    p.height = H;
    p.depth = depth;
    rt_job *job;
    if (rt_job_create(s, &p, &job, err, sizeof err) != VW_OK) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    const rt_shared *sh = rt_job_shared(job);
    rt_object *objs;
    size_t n;
    rt_objects_from_scene(s, &objs, &n);
    void *dev = rt_device_new(1);
    bench b;
    memset(&b, 0, sizeof b);
    double t0 = now();
    if (rt_cell_geo_build(dev, objs, n, &rt_float_frame_identity, &b.geo) != VW_OK) return 1;
    double t1 = now();
    b.lights = sh->lights;
    b.nlights = sh->nlights;
    b.max_depth = sh->max_depth;
    b.eps = sh->eps;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double dir[3];
            rt_view_ray(&sh->view, x, y, dir);
            trace(&b, sh->view.eye, dir, 0, 1, 1.0);
        }
    double t2 = now();
    printf("embree_raw: %dx%d depth %d: build %.6f s, trace %.6f s, rays %lld, %.3f Mrays/s "
           "(checksum %.3g)\n",
           W, H, depth, t1 - t0, t2 - t1, b.rays, b.rays / (t2 - t1) * 1e-6, b.sink);
    rt_cell_geo_free(&b.geo);
    rt_device_free(dev);
    free(objs);
    rt_job_free(job);
    vw_scene_free(s);
    return 0;
}
