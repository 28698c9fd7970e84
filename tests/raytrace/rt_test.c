/* rt_test.c - tests of the distributed ray tracer, one executable, one test per
 * subcommand (registered in tests/raytrace.cmake):
 *   identical SCENE WxH   the same fixed-point sums for every layout and worker count,
 *                         and every ray created is ended (SCENE: a file or gen:NAME:SIZE)
 *   analytic [OFFSET]     one diffuse sphere and one light against the formula, 1/255
 *                         (the scene moved by OFFSET on every axis: float error)
 *   cone                  the cone/cylinder intersection against sampled points
 *   scale                 a sphere, a triangle and a cone give the same hits, bit for bit,
 *                         at every power-of-two scale Embree is handed (rt_embree_scale);
 *                         the float frame a job picks (rt_float_frame_of)
 *   watertight            rays aimed at a mesh's shared edges and vertices hit it
 *   concave SCENE         each polygon's triangle records cover it and nothing else
 *   lighton               a light exactly on a surface lights what faces it
 *   hitcells              the overlay's map of the cells where eye rays hit
 *   view                  the eye rays span the angle an NFF 'v' block gives, all of
 *                         the range the reader accepts (0..180 degrees)
 *   illum SCENE.obj       MTL illum decides the mirror ray: tests/data/good/illum.obj's
 *                         strips reflect the glowing wall by Ks with illum 3 or no
 *                         illum, not with illum 2
 *   write SCENE WxH LAYOUT WORKERS OUT.png   (a helper for looking at pictures)
 *   nff SCENE             the scene as NFF on stdout (gen:balls:4 for the benchmark)
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../vw_test.h"
#include "raytrace/geometry.h"
#include "raytrace/raytrace.h"
#include "vwalls/gen.h"
#include "vwalls/image.h"


static vw_scene *load(const char *spec)
{
    char err[512];
    vw_scene *s = NULL;
    if (!strncmp(spec, "gen:", 4)) {
        char name[64];
        int size = 0;
        const char *colon = strchr(spec + 4, ':');
        size_t n = colon ? (size_t)(colon - spec - 4) : strlen(spec + 4);
        if (n >= sizeof name) n = sizeof name - 1;
        memcpy(name, spec + 4, n);
        name[n] = 0;
        if (colon) size = atoi(colon + 1);
        vw_gen_params p;
        vw_gen_params_init(&p);
        p.size = size;
        if (vw_gen(name, &p, &s, err, sizeof err) != VW_OK) {
            fprintf(stderr, "gen %s: %s\n", spec, err);
            exit(1);
        }
    } else if (vw_scene_read_file(spec, &s, err, sizeof err) != VW_OK) {
        fprintf(stderr, "%s\n", err);
        exit(1);
    }
    return s;
}

/* Is (x, y) inside polygon p (corners q[0..n) projected on axes ax, ay)? Even-odd. */
static int inside2(const double (*q)[3], int n, int ax, int ay, double x, double y)
{
    int in = 0;
    for (int i = 0, j = n - 1; i < n; j = i++) {
        double xi = q[i][ax], yi = q[i][ay], xj = q[j][ax], yj = q[j][ay];
        if ((yi > y) != (yj > y) && x < xj + (y - yj) * (xi - xj) / (yi - yj)) in = !in;
    }
    return in;
}

/* Every polygon of SCENE (planar, simple, concave or not) against its triangle records
   (rt_objects_from_scene, and rt_object_records one polygon at a time): the triangles'
   areas add up to the polygon's, each lies inside the polygon (its centroid and points
   near each corner), and each faces the way the polygon does. A fan from the first
   corner of a concave polygon fails all three. */
static int test_concave(const char *spec)
{
    vw_scene *s = load(spec);
    rt_object *o;
    size_t no;
    CHECK(rt_objects_from_scene(s, &o, &no) == VW_OK);
    size_t at = 0;
    for (size_t i = 0; i < s->npolygons; i++) {
        const vw_polygon *p = &s->polygons[i];
        double (*q)[3] = malloc((size_t)p->count * sizeof *q), nw[3] = {0, 0, 0};
        CHECK(q != NULL);
        for (int k = 0; k < p->count; k++)
            memcpy(q[k], s->vertices[s->indices[p->first + k]], sizeof q[k]);
        for (int k = 0; k < p->count; k++) {
            const double *a = q[k], *b = q[(k + 1) % p->count];
            nw[0] += (a[1] - b[1]) * (a[2] + b[2]);
            nw[1] += (a[2] - b[2]) * (a[0] + b[0]);
            nw[2] += (a[0] - b[0]) * (a[1] + b[1]);
        }
        double area = 0.5 * sqrt(nw[0] * nw[0] + nw[1] * nw[1] + nw[2] * nw[2]), sum = 0;
        int drop = fabs(nw[0]) > fabs(nw[1]) ? 0 : 1;
        if (fabs(nw[2]) > fabs(nw[drop])) drop = 2;
        int ax = (drop + 1) % 3, ay = (drop + 2) % 3;
        rt_object *rec = calloc((size_t)p->count, sizeof *rec);
        CHECK(rec != NULL);
        size_t nrec = rt_object_records(s, VW_PRIM_POLYGON, i, rec), got = 0;
        CHECK_EQ_INT(nrec, p->count - 2);
        for (size_t r = 0; r < nrec; r++) {
            if (rec[r].id < 0) continue; /* a triangle of no area */
            const rt_object *t = &rec[r];
            CHECK(at < no);
            CHECK(!memcmp(&o[at++], t, sizeof *t)); /* the same records, in the same order */
            got++;
            CHECK_EQ_INT(t->id, p->id);
            double e1[3], e2[3], x[3];
            for (int a = 0; a < 3; a++) {
                e1[a] = t->g.tri.v[1][a] - t->g.tri.v[0][a];
                e2[a] = t->g.tri.v[2][a] - t->g.tri.v[0][a];
            }
            x[0] = e1[1] * e2[2] - e1[2] * e2[1];
            x[1] = e1[2] * e2[0] - e1[0] * e2[2];
            x[2] = e1[0] * e2[1] - e1[1] * e2[0];
            sum += 0.5 * sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
            EXPECT(x[0] * nw[0] + x[1] * nw[1] + x[2] * nw[2] > 0, "polygon %d: triangle %zu faces away",
                   p->id, r);
            /* The centroid, and points a tenth of the way from each corner to it. */
            double c[3];
            for (int a = 0; a < 3; a++)
                c[a] = (t->g.tri.v[0][a] + t->g.tri.v[1][a] + t->g.tri.v[2][a]) / 3;
            EXPECT(inside2((const double (*)[3])q, p->count, ax, ay, c[ax], c[ay]),
                   "polygon %d: triangle %zu lies outside it", p->id, r);
            for (int k = 0; k < 3; k++) {
                double px = 0.9 * t->g.tri.v[k][ax] + 0.1 * c[ax];
                double py = 0.9 * t->g.tri.v[k][ay] + 0.1 * c[ay];
                EXPECT(inside2((const double (*)[3])q, p->count, ax, ay, px, py),
                       "polygon %d: triangle %zu reaches outside it near corner %d", p->id, r, k);
            }
        }
        EXPECT(fabs(sum - area) <= 1e-9 * area, "polygon %d: triangles cover %.17g, polygon %.17g",
               p->id, sum, area);
        CHECK(got > 0);
        free(rec);
        free(q);
    }
    CHECK(s->npolygons > 0);
    free(o);
    vw_scene_free(s);
    TEST_DONE();
}

/* Renders; returns the malloc'ed fixed-point sums (w*h*3) and the ray counters. */
static int64_t *render_farm(const vw_scene *s, int w, int h, const int dims[3], int workers,
                            rt_farm farm, int64_t counters[RT_NCOUNTERS], rt_job **keep)
{
    rt_params p;
    memset(&p, 0, sizeof p);
    p.width = w;
    p.height = h;
    memcpy(p.dims, dims, sizeof p.dims);
    p.workers = workers;
    char err[512];
    rt_job *j;
    if (rt_job_create(s, &p, &j, err, sizeof err) != VW_OK || rt_job_record_eye_workers(j) ||
        rt_job_farm(j, farm, NULL, err, sizeof err) || rt_job_commit(j, err, sizeof err) ||
        rt_job_run(j, err, sizeof err)) {
        fprintf(stderr, "render failed: %s\n", err);
        exit(1);
    }
    size_t n = (size_t)w * h * 3;
    int64_t *sums = malloc(n * sizeof *sums);
    memcpy(sums, rt_job_sums(j), n * sizeof *sums);
    /* The copies of a cell in this process read one built scene: never more scenes
       alive than cells. */
    vw_world *world = rt_job_world(j);
    int ncells = vw_decomp_cell_count(vw_world_decomp(world));
    size_t scenes = rt_geo_cache_size(rt_job_shared(j)->geo_cache);
    EXPECT(scenes <= (size_t)ncells, "%d cells, %d workers, farm %d: %zu scenes built", ncells,
           workers, (int)farm, scenes);
    /* The overlay's account of who made each eye ray must be what each worker made. */
    int gw = vw_world_workers(world) * vw_world_processes(world);
    int *eye = malloc((size_t)w * h * sizeof *eye);
    int64_t *per = calloc((size_t)gw, sizeof *per);
    EXPECT(eye && per && rt_job_eye_workers(j, eye), "eye workers");
    for (size_t i = 0; eye && per && i < (size_t)w * h; i++)
        if (eye[i] >= 0 && eye[i] < gw) per[eye[i]]++;
    for (int g = 0; per && g < gw; g++)
        EXPECT(per[g] == vw_world_worker_counter(world, g, RT_C_PIXELS),
               "%d workers, farm %d: worker %d made %lld eye rays, the map says %lld", workers,
               (int)farm, g, (long long)vw_world_worker_counter(world, g, RT_C_PIXELS),
               (long long)per[g]);
    free(eye);
    free(per);
    /* Each cell made the eye rays of the pixels whose walk starts in it: the map made
       by tiles (job.c) against a walk per pixel. */
    const vw_decomp *d = vw_world_decomp(world);
    const rt_view *view = &rt_job_shared(j)->view;
    int64_t *mine = calloc((size_t)ncells, sizeof *mine);
    for (int y = 0; mine && y < h; y++)
        for (int x = 0; x < w; x++) {
            double dir[3];
            vw_segment seg;
            rt_view_ray(view, x, y, dir);
            if (vw_decomp_first_segment(d, view->eye, dir, 0.0, INFINITY, &seg)) mine[seg.cell]++;
        }
    for (int c = 0; mine && c < ncells; c++)
        EXPECT(mine[c] == vw_world_cell_counter(world, c, RT_C_PIXELS),
               "%d cells: cell %d made %lld eye rays, its pixels' walks start there %lld times",
               ncells, c, (long long)vw_world_cell_counter(world, c, RT_C_PIXELS),
               (long long)mine[c]);
    EXPECT(mine != NULL, "out of memory");
    free(mine);
    for (int k = 0; k < RT_NCOUNTERS; k++) counters[k] = vw_world_counter(rt_job_world(j), k);
    if (keep)
        *keep = j;
    else
        rt_job_free(j);
    return sums;
}

static int64_t *render(const vw_scene *s, int w, int h, const int dims[3], int workers,
                       int64_t counters[RT_NCOUNTERS], rt_job **keep)
{
    return render_farm(s, w, h, dims, workers, RT_FARM_NONE, counters, keep);
}

static int test_identical(const char *spec, const char *size)
{
    int w = 96, h = 96;
    if (size && sscanf(size, "%dx%d", &w, &h) != 2) return 2;
    vw_scene *s = load(spec);
    static const int layouts[][3] = {{1, 1, 1}, {2, 1, 1}, {2, 4, 1}, {2, 2, 2}, {4, 4, 4}};
    static const int workers[] = {1, 2, 4};
    int64_t c0[RT_NCOUNTERS];
    int64_t *ref = render(s, w, h, layouts[0], 1, c0, NULL);
    size_t n = (size_t)w * h * 3;
    int64_t rays = c0[RT_C_EYE] + c0[RT_C_REFLECT] + c0[RT_C_REFRACT] + c0[RT_C_SHADOW];
    printf("%s %dx%d: eye %lld reflect %lld refract %lld shadow %lld\n", spec, w, h,
           (long long)c0[RT_C_EYE], (long long)c0[RT_C_REFLECT], (long long)c0[RT_C_REFRACT],
           (long long)c0[RT_C_SHADOW]);
    EXPECT(rays == c0[RT_C_ENDED], "created %lld, ended %lld", (long long)rays,
          (long long)c0[RT_C_ENDED]);
    EXPECT(c0[RT_C_EYE] == c0[RT_C_PIXELS], "eye %lld, pixels %lld", (long long)c0[RT_C_EYE],
          (long long)c0[RT_C_PIXELS]);
    EXPECT(c0[RT_C_EYE] > 0, "no eye rays");
    /* Each layout and worker count without copies, then (more than one worker) with
       the workers farming the cells: copies of every cell (all), or only on the
       workers that host no cell (idle). */
    static const char *const farm_names[] = {"idle", "all", "none"};
    for (int farm = RT_FARM_NONE; farm >= 0; farm--)
    for (size_t li = 0; li < sizeof layouts / sizeof layouts[0]; li++)
        for (size_t wi = 0; wi < sizeof workers / sizeof workers[0]; wi++) {
            if (li == 0 && wi == 0) continue;
            if (farm != RT_FARM_NONE && workers[wi] == 1) continue;
            /* idle changes nothing where every worker hosts a cell */
            if (farm == RT_FARM_IDLE &&
                layouts[li][0] * layouts[li][1] * layouts[li][2] >= workers[wi])
                continue;
            int64_t c[RT_NCOUNTERS];
            int64_t *img = render_farm(s, w, h, layouts[li], workers[wi], (rt_farm)farm, c, NULL);
            size_t diff = 0, first = n;
            for (size_t i = 0; i < n; i++)
                if (img[i] != ref[i]) {
                    if (!diff) first = i;
                    diff++;
                }
            EXPECT(diff == 0, "layout %dx%dx%d workers %d farm %s: %zu sums differ (first: pixel "
                   "%zu)", layouts[li][0], layouts[li][1], layouts[li][2], workers[wi],
                   farm_names[farm], diff, first / 3);
            int64_t r = c[RT_C_EYE] + c[RT_C_REFLECT] + c[RT_C_REFRACT] + c[RT_C_SHADOW];
            EXPECT(r == c[RT_C_ENDED], "layout %dx%dx%d workers %d farm %s: created %lld, ended "
                   "%lld", layouts[li][0], layouts[li][1], layouts[li][2], workers[wi],
                   farm_names[farm], (long long)r, (long long)c[RT_C_ENDED]);
            /* The same rays, whatever the walls. */
            for (int k = RT_C_EYE; k <= RT_C_PIXELS; k++)
                EXPECT(c[k] == c0[k], "layout %dx%dx%d workers %d farm %s: counter %d is %lld, "
                       "not %lld", layouts[li][0], layouts[li][1], layouts[li][2], workers[wi],
                       farm_names[farm], k, (long long)c[k], (long long)c0[k]);
            free(img);
        }
    free(ref);
    vw_scene_free(s);
    return vw_test_failures ? 1 : 0;
}

/* One diffuse sphere lit by one light, no specular, no ambient: every pixel is either
   the background or Kd * colour * max(0, N.L) * light, by the formula alone. The whole
   scene (eye, light, sphere) can be moved by `off` on every axis: far from the origin
   Embree's float error grows with the coordinates, and a shadow ray must still start
   clear of its own surface (the acne of a too small eps shows as dark pixels). */
static int test_analytic(double off)
{
    char nff[512];
    int len = snprintf(nff, sizeof nff,
                       "v\nfrom %.17g %.17g %.17g\nat %.17g %.17g %.17g\nup 0 1 0\nangle 30\n"
                       "hither 1\nresolution 64 48\n"
                       "b 0.1 0.2 0.3\n"
                       "l %.17g %.17g %.17g\n"
                       "f 1 0.5 0.25 0.8 0 0 0 1\n"
                       "s %.17g %.17g %.17g 1\n",
                       0.3 + off, 0.2 + off, 5 + off, off, off, off, 3 + off, 4 + off, 5 + off,
                       off, off, off);
    char err[256];
    vw_scene *s;
    if (vw_scene_read_nff("analytic.nff", nff, (size_t)len, &s, err, sizeof err) != VW_OK) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    int W = 64, H = 48;
    int dims[3] = {2, 2, 1};
    int64_t c[RT_NCOUNTERS];
    int64_t *sums = render(s, W, H, dims, 2, c, NULL);
    const double eye[3] = {0.3, 0.2, 5}, L[3] = {3, 4, 5}, col[3] = {0.8, 0.4, 0.2},
                 bg[3] = {0.1, 0.2, 0.3};
    /* The camera frame, written out independently of view.c. */
    double f[3] = {-0.3, -0.2, -5}, lf = sqrt(0.09 + 0.04 + 25);
    for (int a = 0; a < 3; a++) f[a] /= lf;
    double r[3] = {f[1] * 0 - f[2] * 1, f[2] * 0 - f[0] * 0, f[0] * 1 - f[1] * 0};
    double lr = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    for (int a = 0; a < 3; a++) r[a] /= lr;
    double u[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]};
    double th = tan(15.0 * 3.14159265358979323846 / 180.0), aspect = (double)W / H;
    int checked = 0, worst = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double sx = ((x + 0.5) / W * 2 - 1) * th * aspect, sy = (1 - (y + 0.5) / H * 2) * th;
            double d[3], ld = 0;
            for (int a = 0; a < 3; a++) {
                d[a] = f[a] + sx * r[a] + sy * u[a];
                ld += d[a] * d[a];
            }
            ld = sqrt(ld);
            for (int a = 0; a < 3; a++) d[a] /= ld;
            /* |e + t d| = 1 */
            double b = eye[0] * d[0] + eye[1] * d[1] + eye[2] * d[2];
            double cc = eye[0] * eye[0] + eye[1] * eye[1] + eye[2] * eye[2] - 1;
            double disc = b * b - cc;
            if (fabs(disc) < 1e-3) continue; /* grazing: float hit tests may go either way */
            double expect[3];
            if (disc < 0) {
                memcpy(expect, bg, sizeof expect);
            } else {
                double t = -b - sqrt(disc), p[3], l[3], ll = 0;
                for (int a = 0; a < 3; a++) {
                    p[a] = eye[a] + t * d[a];
                    l[a] = L[a] - p[a];
                    ll += l[a] * l[a];
                }
                ll = sqrt(ll);
                double ndl = (p[0] * l[0] + p[1] * l[1] + p[2] * l[2]) / ll;
                for (int a = 0; a < 3; a++) expect[a] = ndl > 0 ? col[a] * ndl : 0;
            }
            for (int a = 0; a < 3; a++) {
                int got = rt_fix_to_u8(sums[((size_t)y * W + x) * 3 + a]);
                int want = (int)lround(fmin(1, fmax(0, expect[a])) * 255);
                int e = abs(got - want);
                if (e > worst) worst = e;
                EXPECT(e <= 1, "pixel (%d,%d) channel %d: got %d, expected %d", x, y, a, got, want);
            }
            checked++;
        }
    printf("analytic: %d pixels checked, worst difference %d/255\n", checked, worst);
    EXPECT(checked > W * H / 2, "only %d pixels checked", checked);
    int64_t rays = c[RT_C_EYE] + c[RT_C_REFLECT] + c[RT_C_REFRACT] + c[RT_C_SHADOW];
    EXPECT(rays == c[RT_C_ENDED], "created %lld, ended %lld", (long long)rays, (long long)c[RT_C_ENDED]);
    free(sums);
    vw_scene_free(s);
    return vw_test_failures ? 1 : 0;
}

/* A ball 0.2 across resting on a floor 2000 wide, the light straight above: the floor
   just beside the point of contact lies in the ball's shadow, and the floor farther out
   is lit by the formula; and the floor seen from 0.01 above. The least t of a shadow
   ray was 1e-4 of the scene's diagonal (0.28 here), so the ray from the floor passed the
   ball unseen and the ball cast no shadow at all (job.c, the eps). */
static int test_contact(void)
{
    static const double at[2] = {0.05, 0.3}; /* in the shadow (radius 0.1), lit */
    for (int k = 0; k < 2; k++) {
        char nff[512];
        int len = snprintf(nff, sizeof nff,
                           "v\nfrom 1 0.2 0.3\nat %g 0 0\nup 0 0 1\nangle 20\nresolution 9 9\n"
                           "b 0.1 0.2 0.3\nl 0 0 10\nf 1 1 1 0.8 0 0 0 1\n"
                           "p 4 -1000 -1000 0 1000 -1000 0 1000 1000 0 -1000 1000 0\n"
                           "f 1 0 0 0.8 0 0 0 1\ns 0 0 0.1 0.1\n", at[k]);
        char err[256];
        vw_scene *s;
        if (vw_scene_read_nff("contact.nff", nff, (size_t)len, &s, err, sizeof err) != VW_OK) {
            fprintf(stderr, "%s\n", err);
            return 1;
        }
        int dims[3] = {2, 2, 1};
        int64_t c[RT_NCOUNTERS];
        int64_t *sums = render(s, 9, 9, dims, 2, c, NULL);
        /* The centre pixel's ray goes through `at`, on the floor (z = 0). */
        double ndl = 10 / sqrt(at[k] * at[k] + 100), want = k ? 0.8 * ndl : 0;
        for (int a = 0; a < 3; a++) {
            double got = (double)sums[(4 * 9 + 4) * 3 + a] / RT_FIX_ONE;
            EXPECT(fabs(got - want) < 1e-6, "floor at (%g, 0, 0), channel %d: %.9g, expected "
                   "%.9g (%s)", at[k], a, got, want, k ? "lit" : "in the ball's shadow");
        }
        free(sums);
        vw_scene_free(s);
    }
    /* The eye 0.01 above that floor, looking down: an eye ray leaves no surface and
       starts at the eye (it started at the eps, and the floor was not there). */
    const char *low = "v\nfrom 5 0 0.01\nat 5 0 0\nup 0 1 0\nangle 20\nresolution 9 9\n"
                      "b 0.1 0.2 0.3\nl 5 0 10\nf 1 1 1 0.8 0 0 0 1\n"
                      "p 4 -1000 -1000 0 1000 -1000 0 1000 1000 0 -1000 1000 0\n";
    char err[256];
    vw_scene *s;
    if (vw_scene_read_nff("low.nff", low, strlen(low), &s, err, sizeof err) != VW_OK) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    int dims[3] = {1, 1, 1};
    int64_t c[RT_NCOUNTERS];
    int64_t *sums = render(s, 9, 9, dims, 1, c, NULL);
    double got = (double)sums[(4 * 9 + 4) * 3] / RT_FIX_ONE;
    EXPECT(fabs(got - 0.8) < 1e-6, "floor 0.01 below the eye: %.9g, expected 0.8", got);
    free(sums);
    vw_scene_free(s);
    return vw_test_failures ? 1 : 0;
}

/* A light exactly on a surface lights what lies in front of that surface: a light on a
   floor lights a ball above it, and a light on a ball's surface another ball. The
   shadow ray ended at the light's distance, where it found the surface the light lies
   on (Embree's tests take their far end), so both balls were black. */
static int test_lighton(void)
{
    static const char *const scenes[2] = {
        /* Ball point (0, -0.5, 1), normal -y; light (2, -2, 0) on the floor z = 0. */
        "v\nfrom 0 -10 1\nat 0 0 1\nup 0 0 1\nangle 30\nresolution 9 9\nb 0 0 0\n"
        "l 2 -2 0\nf 1 1 1 1 0 0 0 1\ns 0 0 1 0.5\n"
        "p 4 -5 -5 0 5 -5 0 5 5 0 -5 5 0\n",
        /* Ball point (-0.5, 0, 1), normal -x; light (-3, -2.5, 1) on the other ball,
           where its normal points back at that point. */
        "v\nfrom -10 0 1\nat 0 0 1\nup 0 0 1\nangle 30\nresolution 9 9\nb 0 0 0\n"
        "l -3 -2.5 1\nf 1 1 1 0.8 0 0 0 1\ns 0 0 1 0.5\n"
        "s -4 -3.5 1 1.4142135623730951\n"};
    const double want[2] = {1.5 / sqrt(7.25), 0.8 * sqrt(0.5)};
    for (int k = 0; k < 2; k++) {
        char err[256];
        vw_scene *s;
        if (vw_scene_read_nff("lighton.nff", scenes[k], strlen(scenes[k]), &s, err, sizeof err) !=
            VW_OK) {
            fprintf(stderr, "%s\n", err);
            return 1;
        }
        for (int layout = 0; layout < 2; layout++) {
            int dims[3] = {layout ? 2 : 1, layout ? 2 : 1, 1};
            int64_t c[RT_NCOUNTERS];
            int64_t *sums = render(s, 9, 9, dims, 2, c, NULL);
            for (int a = 0; a < 3; a++) {
                double got = (double)sums[(4 * 9 + 4) * 3 + a] / RT_FIX_ONE;
                EXPECT(fabs(got - want[k]) < 1e-5, "scene %d on %dx%dx1 cells, channel %d: "
                       "%.9g, expected %.9g (the light on a surface)", k, dims[0], dims[1], a,
                       got, want[k]);
            }
            free(sums);
        }
        vw_scene_free(s);
    }
    return vw_test_failures ? 1 : 0;
}

/* The field of view is the angle the file gives, for every angle the NFF reader
   accepts: angles from 179 on were once replaced by 45 degrees without a word. */
static int test_view(void)
{
    static const double angles[] = {0.5, 30, 45, 90, 170, 178.9, 179, 179.5, 179.99};
    for (size_t i = 0; i < sizeof angles / sizeof angles[0]; i++) {
        char nff[256], err[256];
        int len = snprintf(nff, sizeof nff, "v from 0 0 10 at 0 0 0 up 0 1 0 angle %.17g\n",
                           angles[i]);
        vw_scene *s;
        CHECK(vw_scene_read_nff("view.nff", nff, (size_t)len, &s, err, sizeof err) == VW_OK);
        rt_view v;
        rt_view_init(&v, &s->camera, 2, 2);
        double th = tan(angles[i] * 0.5 * 3.14159265358979323846 / 180.0);
        EXPECT(fabs(v.tan_half - th) <= 1e-12 * th, "angle %g: tan_half %.17g, expected %.17g",
               angles[i], v.tan_half, th);
        /* The ray through the centre of the top left pixel of a 2x2 image lies half the
           way to the edges: at (-th/2, th/2) on the screen one unit ahead. */
        double d[3];
        rt_view_ray(&v, 0, 0, d);
        EXPECT(fabs(-d[1] / d[2] - 0.5 * th) <= 1e-9 * th && fabs(d[0] / d[2] - 0.5 * th) <= 1e-9 * th,
               "angle %g: ray %g %g %g", angles[i], d[0], d[1], d[2]);
        vw_scene_free(s);
    }
    printf("view: %zu angles\n", sizeof angles / sizeof angles[0]);
    return vw_test_failures ? 1 : 0;
}

/* The overlay's cells (rt_job_record_hit_cells): two spheres, one each side of the
   wall of a 2x1x1 layout, seen from outside the world box and from inside it. A pixel
   through a sphere's centre is tinted by that sphere's cell, a corner pixel that sees
   nothing by none (-1), and the map is the same on 1 worker and on 2 (farmed or
   mapped). With the eye inside the box the cells where eye rays enter (rt_job's owner
   map) are one cell for every pixel, and the hits still show both. */
static int test_hitcells(void)
{
    /* From outside; and from inside the cell x < 0, near the box's -y face, with a
       wide view that takes in both spheres. */
    static const char *const eyes[] = {"0 -6 0 at 0 0 0 up 0 0 1 angle 60",
                                       "-0.2 -0.45 0 at -0.2 1 0 up 0 0 1 angle 150"};
    for (int e = 0; e < 2; e++) {
        char nff[512], err[256];
        int len = snprintf(nff, sizeof nff,
                           "v from %s hither 0.01 resolution 64 64\n"
                           "l 0 -10 10\nf 1 1 1 1 0 0 0 1\ns -1 0 0 0.5\ns 1 0 0 0.5\n",
                           eyes[e]);
        vw_scene *s;
        CHECK(vw_scene_read_nff("hit.nff", nff, (size_t)len, &s, err, sizeof err) == VW_OK);
        int *first = NULL;
        for (int run = 0; run < 3; run++) {
            static const int workers[] = {1, 2, 2};
            static const rt_farm farms[] = {RT_FARM_NONE, RT_FARM_NONE, RT_FARM_ALL};
            rt_params p;
            memset(&p, 0, sizeof p);
            p.width = p.height = 64;
            p.dims[0] = 2, p.dims[1] = p.dims[2] = 1;
            p.workers = workers[run];
            rt_job *j;
            CHECK(rt_job_create(s, &p, &j, err, sizeof err) == VW_OK);
            CHECK(rt_job_record_hit_cells(j) == VW_OK && rt_job_farm(j, farms[run], NULL, err, sizeof err) == VW_OK &&
                  rt_job_commit(j, err, sizeof err) == VW_OK && rt_job_run(j, err, sizeof err) == VW_OK);
            const rt_shared *sh = rt_job_shared(j);
            const vw_decomp *d = vw_world_decomp(rt_job_world(j));
            CHECK(sh->hit_cell != NULL);
            /* The pixels through the spheres' centres, and a corner. */
            for (int k = 0; k < 2; k++) {
                double c[3] = {k ? 1.0 : -1.0, 0, 0}, x, y;
                CHECK(rt_view_project(&sh->view, c, &x, &y));
                int px = (int)y * 64 + (int)x, want = vw_decomp_locate(d, c, NULL);
                EXPECT(sh->hit_cell[px] == want, "eye %s, run %d: sphere %d's pixel tinted by cell %d, "
                       "expected %d", eyes[e], run, k, sh->hit_cell[px], want);
            }
            EXPECT(sh->hit_cell[0] == -1, "eye %s: a corner that sees nothing tinted by cell %d",
                   eyes[e], sh->hit_cell[0]);
            if (!first) {
                first = malloc(64 * 64 * sizeof *first);
                CHECK(first != NULL);
                memcpy(first, sh->hit_cell, 64 * 64 * sizeof *first);
            } else {
                EXPECT(!memcmp(first, sh->hit_cell, 64 * 64 * sizeof *first),
                       "eye %s: another map of hit cells on %d workers, farm %d", eyes[e],
                       workers[run], (int)farms[run]);
            }
            if (e == 1) { /* inside: one cell makes every eye ray */
                int cells_entered = 0, seen[2] = {0, 0};
                for (int i = 0; i < 64 * 64; i++)
                    if (sh->owner[i] >= 0 && sh->owner[i] < 2 && !seen[sh->owner[i]]) {
                        seen[sh->owner[i]] = 1;
                        cells_entered++;
                    }
                EXPECT(cells_entered == 1, "eye inside: eye rays start in %d cells", cells_entered);
            }
            rt_job_free(j);
        }
        free(first);
        vw_scene_free(s);
    }
    printf("hitcells: 2 eyes x 3 runs\n");
    return vw_test_failures ? 1 : 0;
}

/* tests/data/good/illum.obj: strips on the floor y = 0 (x in [-3,-1]: illum 2, [-1,1]:
   illum 3, [1,3]: no illum; each Kd 0, Ks 0.5) before a wall at z = -5 that glows 1 and
   reflects nothing. A floor pixel whose mirror ray meets the wall shows 0.5 where the
   strip reflects, 0 where it does not (the highlight of the one default light, behind
   the mirror rays, adds nothing there). Exported materials (Blender: illum 2, Ks 0.5)
   once rendered as half mirrors. */
static int test_illum(const char *path)
{
    vw_scene *s = load(path);
    vw_camera *cam = &s->camera;
    const double from[3] = {0, 3, 8};
    memcpy(cam->from, from, sizeof cam->from);
    cam->at[0] = cam->at[1] = cam->at[2] = 0;
    cam->up[0] = cam->up[2] = 0;
    cam->up[1] = 1;
    cam->angle = 50;
    cam->hither = 0;
    cam->valid = 1;
    int W = 96, H = 72, dims[3] = {2, 1, 2};
    int64_t c[RT_NCOUNTERS];
    int64_t *sums = render(s, W, H, dims, 2, c, NULL);
    rt_view v;
    rt_view_init(&v, cam, W, H);
    int seen[3] = {0, 0, 0}, bad[3] = {0, 0, 0}, first[3][3];
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double d[3];
            rt_view_ray(&v, x, y, d);
            if (d[1] >= 0) continue;
            double t = -from[1] / d[1], p[3];
            for (int a = 0; a < 3; a++) p[a] = from[a] + t * d[a];
            /* Well inside a strip, and its mirror ray well inside the wall. */
            double fx = p[0] + 3, cell = floor(fx / 2);
            if (cell < 0 || cell > 2 || fabs(fx - 2 * cell - 1) > 0.8 || fabs(p[2]) > 2.3) continue;
            if (d[2] >= 0) continue;
            double t2 = (-5 - p[2]) / d[2], wx = p[0] + t2 * d[0], wy = p[1] - t2 * d[1];
            if (fabs(wx) > 19 || wy < 0.5 || wy > 19) continue;
            int strip = (int)cell;
            int want = strip == 0 ? 0 : 128;   /* 0.5 of 255, rounded */
            int got = rt_fix_to_u8(sums[((size_t)y * W + x) * 3]);
            for (int k = 1; k < 3; k++)
                if (abs(rt_fix_to_u8(sums[((size_t)y * W + x) * 3 + k]) - want) > abs(got - want))
                    got = rt_fix_to_u8(sums[((size_t)y * W + x) * 3 + k]);
            if (abs(got - want) > 1 && !bad[strip]++) {
                first[strip][0] = x;
                first[strip][1] = y;
                first[strip][2] = got;
            }
            seen[strip]++;
        }
    static const char *const name[] = {"illum 2", "illum 3", "no illum"};
    for (int k = 0; k < 3; k++)
        EXPECT(!bad[k], "%s strip: %d of %d pixels wrong, first (%d,%d): %d, expected %d",
               name[k], bad[k], seen[k], first[k][0], first[k][1], first[k][2], k ? 128 : 0);
    printf("illum: %d, %d and %d pixels checked on the illum 2, illum 3 and no-illum strips\n",
           seen[0], seen[1], seen[2]);
    EXPECT(seen[0] > 50 && seen[1] > 50 && seen[2] > 50, "too few pixels checked");
    EXPECT(c[RT_C_REFLECT] > 0, "no mirror rays");
    free(sums);
    vw_scene_free(s);
    return vw_test_failures ? 1 : 0;
}

/* Rays aimed at points sampled on a cone's side must hit it there, from outside. */
static int test_cone(void)
{
    rt_object o;
    memset(&o, 0, sizeof o);
    o.kind = RT_CONE;
    double base[3] = {0.2, -1, 0.1}, apex[3] = {-0.1, 1.5, 0.3};
    memcpy(o.g.cone.base, base, sizeof base);
    memcpy(o.g.cone.apex, apex, sizeof apex);
    o.g.cone.r0 = 0.8;
    o.g.cone.r1 = 0.3;
    void *dev = rt_device_new(1);
    rt_cell_geo g;
    EXPECT(rt_cell_geo_build(dev, &o, 1, &rt_float_frame_identity, &g) == VW_OK, "build");
    int hits = 0, n = 0;
    for (int i = 0; i < 200; i++) {
        double s = (i % 20 + 0.5) / 20.0, phi = (i / 20) * 0.6283 + 0.1;
        double w[3], hgt = 0;
        for (int a = 0; a < 3; a++) {
            w[a] = apex[a] - base[a];
            hgt += w[a] * w[a];
        }
        hgt = sqrt(hgt);
        for (int a = 0; a < 3; a++) w[a] /= hgt;
        double e1[3] = {w[1], -w[0], 0}, l1 = sqrt(w[0] * w[0] + w[1] * w[1]);
        for (int a = 0; a < 3; a++) e1[a] /= l1;
        double e2[3] = {w[1] * e1[2] - w[2] * e1[1], w[2] * e1[0] - w[0] * e1[2],
                        w[0] * e1[1] - w[1] * e1[0]};
        double rad = 0.8 + (0.3 - 0.8) * s, p[3], radial[3];
        for (int a = 0; a < 3; a++) {
            radial[a] = cos(phi) * e1[a] + sin(phi) * e2[a];
            p[a] = base[a] + s * hgt * w[a] + rad * radial[a];
        }
        double org[3], dir[3];
        for (int a = 0; a < 3; a++) {
            org[a] = p[a] + 3 * radial[a];
            dir[a] = -radial[a];
        }
        rt_hit h;
        n++;
        if (rt_cell_geo_intersect(&g, org, dir, 0, 100, &h)) {
            double q[3], err = 0;
            for (int a = 0; a < 3; a++) {
                q[a] = org[a] + h.t * dir[a];
                err += (q[a] - p[a]) * (q[a] - p[a]);
            }
            /* A ray along the outward radial of a cone whose sides slope: it meets the side
               at p, exactly (float t). */
            EXPECT(sqrt(err) < 1e-5, "ray %d: hit %g away from the sampled point", i, sqrt(err));
            double nn[3];
            rt_cone_normal(&o, q, nn);
            EXPECT(nn[0] * radial[0] + nn[1] * radial[1] + nn[2] * radial[2] > 0.8,
                  "ray %d: normal does not point outward", i);
            hits++;
        }
        /* Shadow query agrees. */
        EXPECT(rt_cell_geo_occluded(&g, org, dir, 0, 100) == 1, "ray %d: not occluded", i);
        EXPECT(rt_cell_geo_occluded(&g, org, dir, 0, 2.9) == 0, "ray %d: occluded too early", i);
    }
    EXPECT(hits == n, "%d of %d rays hit", hits, n);
    rt_cell_geo_free(&g);

    /* Rays at 1e-7 rad to a cylinder 7e6 long (a fuzzer's scene): the quadratic term of
       the side's equation is ~1e-14 and was dropped as if zero, which made a hit out of
       a ray passing 1.35 or more from the axis (a cell holding the cylinder alone then
       found its shadow ray occluded, and the image differed from one cell's), and put
       the exit of a ray starting inside 0.67e6 too far. */
    rt_object cyl;
    memset(&cyl, 0, sizeof cyl);
    cyl.kind = RT_CONE;
    const double cb[3] = {-1.8, 7000000.8, 0}, ca[3] = {-0.8, 0.8, 1.8};
    memcpy(cyl.g.cone.base, cb, sizeof cb);
    memcpy(cyl.g.cone.apex, ca, sizeof ca);
    cyl.g.cone.r0 = cyl.g.cone.r1 = 0.5;
    EXPECT(rt_cell_geo_build(dev, &cyl, 1, &rt_float_frame_identity, &g) == VW_OK, "build");
    for (int i = 0; i < 5; i++) {
        double org[3] = {-3.17 + 0.1 * i, 3.9, 2e-7}, dir[3] = {2.7e-9, 1, 2.67e-9};
        double l = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
        for (int a = 0; a < 3; a++) dir[a] /= l;
        rt_hit h;
        EXPECT(!rt_cell_geo_intersect(&g, org, dir, 0, 1e7, &h), "parallel ray %d: a hit at t %g", i,
               h.t);
        EXPECT(!rt_cell_geo_occluded(&g, org, dir, 0, 1e7), "parallel ray %d: occluded", i);
        EXPECT(!rt_cell_geo_occluded(&g, org, dir, 3.5e6, 1e7), "parallel ray %d: occluded past 3.5e6", i);
    }
    rt_cell_geo_free(&g);
    /* A cylinder along y, r 0.5; a ray inside it, 0.3 off the axis, drifting out at 1e-7
       rad: it meets the side where x = 0.5, at t = 0.2 / sin(1e-7) = 2e6. */
    const double yb[3] = {0, 0, 0}, ya[3] = {0, 7e6, 0};
    memcpy(cyl.g.cone.base, yb, sizeof yb);
    memcpy(cyl.g.cone.apex, ya, sizeof ya);
    EXPECT(rt_cell_geo_build(dev, &cyl, 1, &rt_float_frame_identity, &g) == VW_OK, "build");
    {
        double org[3] = {0.3, 1, 0}, dir[3] = {sin(1e-7), cos(1e-7), 0};
        rt_hit h;
        int hit = rt_cell_geo_intersect(&g, org, dir, 0, 1e7, &h);
        EXPECT(hit && fabs(h.t - 0.2 / sin(1e-7)) < 1.0, "drifting ray: %s t %.9g, want %.9g",
               hit ? "hit at" : "no hit,", hit ? h.t : 0.0, 0.2 / sin(1e-7));
    }
    rt_cell_geo_free(&g);
    rt_device_free(dev);
    printf("cone: %d of %d sampled points hit\n", hits, n);
    return vw_test_failures ? 1 : 0;
}

/* The same objects (a sphere, a triangle, a cone) and rays give the same answers, bit
   for bit, whatever power of two the geometry is handed to Embree at: the object, t,
   u, v of the first hit, and the shadow query over the same intervals. Also the
   scale's contract: 1 where Embree's floats are at ease, else the power of two that
   brings `far` into [1, 2). */
static int test_scale(void)
{
    EXPECT(rt_embree_scale(1.0) == 1.0 && rt_embree_scale(0x1p20) == 1.0 &&
               rt_embree_scale(0x1p-10) == 1.0,
           "unit-sized scenes are handed over as they are");
    EXPECT(rt_embree_scale(0) == 1.0 && rt_embree_scale(INFINITY) == 1.0 &&
               rt_embree_scale(NAN) == 1.0,
           "no scale from a far of 0, infinity or NaN");
    static const double fars[] = {3e12, 0x1p21, 1e-15, 0x1p-11, 5e35, 1e-60};
    for (size_t i = 0; i < sizeof fars / sizeof fars[0]; i++) {
        double sc = rt_embree_scale(fars[i]), m;
        int e;
        m = frexp(sc, &e);
        EXPECT(m == 0.5 && fars[i] * sc >= 1 && fars[i] * sc < 2,
               "far %g: scale %a is not the power of two that brings it into [1, 2)", fars[i], sc);
    }
    /* The frame of a job: the identity near the origin, the box's centre far from it. */
    const double eye[3] = {3, 3, 3}, far_eye[3] = {1e9 + 3, 3, 3};
    const vw_box near_box = {{-2, -1, -1}, {2, 1, 1}}, far_box = {{1e9 - 2, -1, -1}, {1e9 + 2, 1, 1}};
    rt_float_frame f0 = rt_float_frame_of(eye, &near_box), f1 = rt_float_frame_of(far_eye, &far_box);
    EXPECT(!f0.moved && f0.scale == 1 && f0.origin[0] == 0, "near the origin: not the identity");
    EXPECT(f1.moved && f1.scale == 1 && f1.origin[0] == 1e9 && f1.origin[1] == 0 &&
               f1.inv_scale == 1,
           "far from it: origin %g %g %g scale %g", f1.origin[0], f1.origin[1], f1.origin[2],
           f1.scale);
    /* The margins' magnitude: 6 from the frame's origin, but the doubles' rounding at 1e9
       (1e-7 of the coordinates' sum) is larger there. */
    EXPECT(rt_float_frame_norm1(&f0, eye) == 9 &&
               rt_float_frame_norm1(&f1, far_eye) == 1e-7 * ((1e9 + 3) + 3 + 3),
           "magnitudes %g and %g", rt_float_frame_norm1(&f0, eye), rt_float_frame_norm1(&f1, far_eye));
    rt_object o[3];
    memset(o, 0, sizeof o);
    o[0].kind = RT_SPHERE;
    o[0].g.sphere.c[0] = 0.3, o[0].g.sphere.c[1] = -0.2, o[0].g.sphere.c[2] = 0.1;
    o[0].g.sphere.r = 0.7;
    o[1].kind = RT_TRIANGLE;
    static const double tv[3][3] = {{-2, -2, -0.9}, {2.5, -1.5, -0.8}, {0.2, 2.5, -1.1}};
    memcpy(o[1].g.tri.v, tv, sizeof tv);
    o[2].kind = RT_CONE;
    static const double cb[3] = {1.2, 0.4, -0.9}, ca[3] = {1.0, 0.9, 0.8};
    memcpy(o[2].g.cone.base, cb, sizeof cb);
    memcpy(o[2].g.cone.apex, ca, sizeof ca);
    o[2].g.cone.r0 = 0.5;
    o[2].g.cone.r1 = 0.2;
    static const double scales[] = {1.0, 0x1p-30, 0x1p30};
    void *dev = rt_device_new(1);
    rt_cell_geo g[3];
    for (int k = 0; k < 3; k++) {
        static const double zero[3] = {0, 0, 0};
        rt_float_frame ff = rt_float_frame_make(zero, scales[k]);
        EXPECT(rt_cell_geo_build(dev, o, 3, &ff, &g[k]) == VW_OK, "build");
    }
    uint64_t rng = 12345;
    int hits[3] = {0, 0, 0}, nrays = 3000;
    for (int i = 0; i < nrays; i++) {
        double org[3], dir[3], len = 0;
        for (int a = 0; a < 3; a++) {
            rng = rng * 6364136223846793005ull + 1442695040888963407ull;
            org[a] = 4.0 * ((double)(rng >> 11) / 9007199254740992.0) - 2.0 + (a == 2 ? 3.0 : 0.0);
            rng = rng * 6364136223846793005ull + 1442695040888963407ull;
            dir[a] = (double)(rng >> 11) / 9007199254740992.0 - 0.5 - (a == 2 ? 0.8 : 0.0);
            len += dir[a] * dir[a];
        }
        for (int a = 0; a < 3; a++) dir[a] /= sqrt(len);
        double tn = 0.01 * (i % 7), tf = i % 5 ? INFINITY : 2.0 + (i % 11);
        rt_hit h[3];
        int got[3], occ[3];
        for (int k = 0; k < 3; k++) {
            got[k] = rt_cell_geo_intersect(&g[k], org, dir, tn, tf, &h[k]);
            occ[k] = rt_cell_geo_occluded(&g[k], org, dir, tn, tf);
        }
        for (int k = 1; k < 3; k++) {
            EXPECT(got[k] == got[0] && occ[k] == occ[0], "ray %d, scale %a: hit %d occluded %d, "
                   "at scale 1 %d %d", i, scales[k], got[k], occ[k], got[0], occ[0]);
            if (got[k] && got[0])
                EXPECT(h[k].obj - g[k].obj == h[0].obj - g[0].obj && h[k].t == h[0].t &&
                           h[k].u == h[0].u && h[k].v == h[0].v,
                       "ray %d, scale %a: object %d t %.17g, at scale 1 object %d t %.17g", i,
                       scales[k], (int)(h[k].obj - g[k].obj), h[k].t, (int)(h[0].obj - g[0].obj),
                       h[0].t);
        }
        if (got[0]) hits[h[0].obj - g[0].obj]++;
    }
    /* Every kind was hit often enough for the comparison to mean something. */
    EXPECT(hits[0] > 100 && hits[1] > 100 && hits[2] > 20, "hits: sphere %d, triangle %d, cone %d",
           hits[0], hits[1], hits[2]);
    for (int k = 0; k < 3; k++) rt_cell_geo_free(&g[k]);
    rt_device_free(dev);
    printf("scale: %d rays; hits: sphere %d, triangle %d, cone %d, the same at 2^-30 and 2^30\n",
           nrays, hits[0], hits[1], hits[2]);
    return vw_test_failures ? 1 : 0;
}

/* Rays aimed at the shared edges and vertices of a mesh (a bumpy heightfield of
   2 x 40 x 40 triangles, each with its own copy of the shared vertices, as
   rt_cell_geo_build makes them) must hit it, and the shadow query must agree: a ray
   that slips between two triangles shows the background through the surface. Embree's
   robust mode is not exactly watertight either: of these rays it lets 9 in 150,000
   through at edges and 213 in 50,000 at vertices (its default mode: 9,802 and 9,586),
   so the test bounds the rates at 1e-3 and 2e-2. */
static int test_watertight(void)
{
    enum { N = 40 };
    static double z[N + 1][N + 1];
    for (int j = 0; j <= N; j++)
        for (int i = 0; i <= N; i++)
            z[j][i] = 0.07 * sin(11.0 * i / N) * cos(9.0 * j / N) + 0.013 * ((i * 7 + j * 3) % 5);
    rt_object *tri = calloc(2 * N * N, sizeof *tri);
    EXPECT(tri != NULL, "memory");
    if (!tri) return 1;
    size_t nt = 0;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            int c[4][2] = {{i, j}, {i + 1, j}, {i + 1, j + 1}, {i, j + 1}};
            static const int fan[2][3] = {{0, 1, 2}, {0, 2, 3}};
            for (int f = 0; f < 2; f++, nt++) {
                tri[nt].kind = RT_TRIANGLE;
                tri[nt].id = (int32_t)nt;
                for (int k = 0; k < 3; k++) {
                    const int *v = c[fan[f][k]];
                    tri[nt].g.tri.v[k][0] = (double)v[0] / N;
                    tri[nt].g.tri.v[k][1] = (double)v[1] / N;
                    tri[nt].g.tri.v[k][2] = z[v[1]][v[0]];
                }
            }
        }
    void *dev = rt_device_new(1);
    rt_cell_geo g;
    EXPECT(rt_cell_geo_build(dev, tri, nt, &rt_float_frame_identity, &g) == VW_OK, "build");
    /* The target points: on the mesh's inner edges (in float, as Embree holds the
       vertices), at their ends (the vertices) and at random places along them. */
    uint64_t seed = 99;
    int misses = 0, n = 0, at_vertex = 0, vertex_misses = 0;
    for (int r = 0; r < 200000; r++) {
        seed = seed * 6364136223846793005ull + 1442695040888963407ull;
        int i = 1 + (int)((seed >> 33) % (N - 1)), j = 1 + (int)((seed >> 45) % (N - 1));
        int kind = (int)((seed >> 20) % 3); /* 0: along x, 1: along y, 2: the diagonal */
        int i2 = kind == 1 ? i : i + 1, j2 = kind == 0 ? j : j + 1;
        double s = (r % 4 == 0) ? 0.0 : (double)((seed >> 11) & 0xffff) / 65536.0;
        double a[3] = {(float)((double)i / N), (float)((double)j / N), (float)z[j][i]};
        double b[3] = {(float)((double)i2 / N), (float)((double)j2 / N), (float)z[j2][i2]};
        double p[3], org[3], dir[3], len = 0;
        /* from above, in a direction that varies with the ray */
        double d0 = ((double)((seed >> 5) & 1023) / 1023.0 - 0.5) * 0.8;
        double d1 = ((double)((seed >> 15) & 1023) / 1023.0 - 0.5) * 0.8;
        for (int k = 0; k < 3; k++) p[k] = a[k] + s * (b[k] - a[k]);
        dir[0] = d0, dir[1] = d1, dir[2] = -1;
        for (int k = 0; k < 3; k++) len += dir[k] * dir[k];
        len = sqrt(len);
        for (int k = 0; k < 3; k++) {
            dir[k] /= len;
            org[k] = p[k] - 2.0 * dir[k];
        }
        rt_hit h;
        n++;
        int hit = rt_cell_geo_intersect(&g, org, dir, 0, 10, &h);
        int occ = rt_cell_geo_occluded(&g, org, dir, 0, 10);
        at_vertex += s == 0;
        if (!hit || !occ) {
            if (misses < 5)
                printf("watertight: ray %d at (%.9g %.9g %.9g) slips through (%s)\n", r, p[0], p[1],
                       p[2], hit ? "occluded query" : "first hit");
            misses++;
            vertex_misses += s == 0;
        }
    }
    int edge_misses = misses - vertex_misses, at_edge = n - at_vertex;
    EXPECT(edge_misses <= at_edge / 1000, "%d of %d rays aimed at shared edges missed the mesh",
           edge_misses, at_edge);
    EXPECT(vertex_misses <= at_vertex / 50, "%d of %d rays aimed at shared vertices missed the mesh",
           vertex_misses, at_vertex);
    rt_cell_geo_free(&g);
    rt_device_free(dev);
    free(tri);
    printf("watertight: %d of %d rays at shared edges hit, %d of %d at shared vertices\n",
           at_edge - edge_misses, at_edge, at_vertex - vertex_misses, at_vertex);
    return vw_test_failures ? 1 : 0;
}

static int write_png(int argc, char **argv)
{
    if (argc < 7) return 2;
    vw_scene *s = load(argv[2]);
    int w, h, dims[3];
    char err[256];
    if (sscanf(argv[3], "%dx%d", &w, &h) != 2 || vw_layout_parse(argv[4], dims, err, sizeof err))
        return 2;
    rt_params p;
    memset(&p, 0, sizeof p);
    p.width = w;
    p.height = h;
    memcpy(p.dims, dims, sizeof dims);
    p.workers = atoi(argv[5]);
    rt_job *j;
    if (rt_job_create(s, &p, &j, err, sizeof err) || rt_job_commit(j, err, sizeof err) ||
        rt_job_run(j, err, sizeof err)) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    uint8_t *img = malloc((size_t)w * h * 3);
    rt_job_rgb8(j, img);
    vw_status st = vw_image_write_png(argv[6], w, h, img, err, sizeof err);
    free(img);
    rt_job_free(j);
    vw_scene_free(s);
    return st == VW_OK ? 0 : 1;
}

/* The NFF text of a scene spec (for the benchmark, which needs a file). */
static int write_nff(const char *spec)
{
    vw_scene *s = load(spec);
    vw_status st = vw_scene_write_nff(s, stdout);
    vw_scene_free(s);
    return st == VW_OK ? 0 : 1;
}

/* The scene's records a part at a time (rt_objects_next, as rt_job_create adds them to
   the world) are the whole conversion's (rt_objects_from_scene), byte for byte and in
   order, for every room from the widest polygon's triangles up to all of them: parts
   that end inside the spheres, at a cone, before a polygon that does not fit. A room
   smaller than the widest polygon is refused, not overrun. */
static int test_parts(const char *spec)
{
    vw_scene *s = load(spec);
    rt_object *all;
    size_t nall, widest;
    CHECK(rt_objects_from_scene(s, &all, &nall) == VW_OK);
    size_t room = rt_objects_room(s, &widest), count = rt_objects_count(s);
    CHECK(nall <= room);
    rt_object *part = malloc((room + 1) * sizeof *part);
    CHECK(part != NULL);
    size_t rooms = 0;
    for (size_t r = widest; r <= room + 1; r++, rooms++) {
        size_t next = 0, at = 0, parts = 0;
        while (next < count) {
            size_t n = 99, before = next;
            CHECK(rt_objects_next(s, &next, part, r, &n) == VW_OK);
            CHECK(next > before); /* every part advances */
            CHECK(n <= r && at + n <= nall);
            CHECK(n == 0 || !memcmp(part, &all[at], n * sizeof *part));
            at += n;
            parts++;
        }
        CHECK_EQ_INT(at, nall);
        CHECK(r < room || parts == 1); /* room for all: one part */
    }
    if (widest > 1) {
        /* The widest polygon alone in a part with less room than its triangles. */
        size_t next = 0, n;
        int refused = 0;
        while (next < count && !refused) {
            vw_status st = rt_objects_next(s, &next, part, widest - 1, &n);
            refused = st != VW_OK;
        }
        CHECK(refused);
    }
    printf("parts: %zu records of %zu objects (widest polygon %zu triangles) equal in %zu room sizes\n",
           nall, count, widest, rooms);
    free(part);
    free(all);
    vw_scene_free(s);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc >= 3 && !strcmp(argv[1], "nff")) return write_nff(argv[2]);
    if (argc >= 3 && !strcmp(argv[1], "identical")) return test_identical(argv[2], argc > 3 ? argv[3] : NULL);
    if (argc >= 2 && !strcmp(argv[1], "analytic")) return test_analytic(argc > 2 ? atof(argv[2]) : 0);
    if (argc >= 2 && !strcmp(argv[1], "contact")) return test_contact();
    if (argc >= 2 && !strcmp(argv[1], "lighton")) return test_lighton();
    if (argc >= 2 && !strcmp(argv[1], "cone")) return test_cone();
    if (argc >= 2 && !strcmp(argv[1], "scale")) return test_scale();
    if (argc >= 2 && !strcmp(argv[1], "view")) return test_view();
    if (argc >= 2 && !strcmp(argv[1], "hitcells")) return test_hitcells();
    if (argc >= 3 && !strcmp(argv[1], "illum")) return test_illum(argv[2]);
    if (argc >= 2 && !strcmp(argv[1], "watertight")) return test_watertight();
    if (argc >= 3 && !strcmp(argv[1], "concave")) return test_concave(argv[2]);
    if (argc >= 3 && !strcmp(argv[1], "parts")) return test_parts(argv[2]);
    if (argc >= 2 && !strcmp(argv[1], "write")) return write_png(argc, argv);
    fprintf(stderr, "usage: rt_test identical SCENE [WxH] | analytic | cone | write ...\n");
    return 2;
}
