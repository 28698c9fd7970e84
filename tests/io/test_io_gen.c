/* test_io_gen.c - the scene generators: sphereflake counts, determinism for a seed,
 * non-overlapping random spheres and the cluster fraction, the Cornell box's light,
 * and that every generated scene survives an NFF round trip bit for bit.
 */
#define _GNU_SOURCE
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "io_test_util.h"
#include "vw_test.h"
#include "vwalls/gen.h"

static vw_scene *gen(const char *name, int size, int count, uint64_t seed, double cluster)
{
    vw_gen_params p;
    vw_gen_params_init(&p);
    p.size = size;
    p.count = count;
    p.seed = seed;
    p.cluster = cluster;
    char err[256] = "";
    vw_scene *s = NULL;
    vw_status st = vw_gen(name, &p, &s, err, sizeof err);
    if (st != VW_OK)
        fprintf(stderr, "vw_gen %s: %s\n", name, err);
    CHECK_EQ_INT(st, VW_OK);
    return s;
}

static void check_no_overlap(const vw_scene *s, double rel)
{
    for (size_t i = 0; i < s->nspheres; i++)
        for (size_t j = i + 1; j < s->nspheres; j++) {
            const vw_sphere *a = &s->spheres[i], *b = &s->spheres[j];
            double d2 = 0;
            for (int k = 0; k < 3; k++)
                d2 += (a->center[k] - b->center[k]) * (a->center[k] - b->center[k]);
            double r = (a->radius + b->radius) * (1 - rel);
            if (d2 < r * r) {
                fprintf(stderr, "spheres %d and %d overlap\n", a->id, b->id);
                CHECK(0);
            }
        }
}

static int emits(const vw_scene *s, int m)
{
    const float *e = s->materials[m].emission;
    return e[0] > 0 || e[1] > 0 || e[2] > 0;
}

static void normal(const vw_scene *s, size_t poly, double n[3])
{
    const vw_polygon *p = &s->polygons[poly];
    const double *a = s->vertices[s->indices[p->first]], *b = s->vertices[s->indices[p->first + 1]],
                 *c = s->vertices[s->indices[p->first + 2]];
    double u[3], v[3];
    for (int k = 0; k < 3; k++) {
        u[k] = b[k] - a[k];
        v[k] = c[k] - a[k];
    }
    n[0] = u[1] * v[2] - u[2] * v[1];
    n[1] = u[2] * v[0] - u[0] * v[2];
    n[2] = u[0] * v[1] - u[1] * v[0];
}

static int nwarnings;

static void count_warning(const char *msg, void *user)
{
    (void)user;
    fprintf(stderr, "%s\n", msg);
    nwarnings++;
}

/* How far the polygon's corners lie off its plane (Newell's normal through their
   centroid), as a fraction of its size (the largest distance of a corner from the
   centroid): what the radiosity mesher measures, warning from 1e-3 on. */
static double off_plane(const vw_scene *s, size_t poly)
{
    const vw_polygon *p = &s->polygons[poly];
    double (*v)[3] = malloc((size_t)p->count * sizeof *v), n[3], cen[3] = {0, 0, 0};
    CHECK(v != NULL);
    for (int i = 0; i < p->count; i++)
        for (int k = 0; k < 3; k++) {
            v[i][k] = s->vertices[s->indices[p->first + i]][k];
            cen[k] += v[i][k] / p->count;
        }
    vw_polygon_normal((const double(*)[3])v, p->count, n);
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), off = 0, size = 0;
    CHECK(len > 0);
    for (int i = 0; i < p->count; i++) {
        double q[3] = {v[i][0] - cen[0], v[i][1] - cen[1], v[i][2] - cen[2]};
        off = fmax(off, fabs(q[0] * n[0] + q[1] * n[1] + q[2] * n[2]) / len);
        size = fmax(size, sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]));
    }
    free(v);
    return off / size;
}

int main(void)
{
    /* Sphereflake: 1 + 9 + ... + 9^n spheres plus the ground. */
    long expect = 0, pow9 = 1;
    for (int n = 0; n <= 4; n++) {
        expect += pow9;
        pow9 *= 9;
        vw_scene *s = gen("balls", n, 0, 1, 0);
        if (n == 0) {
            vw_scene_free(s);
            s = gen("balls", 0, 0, 1, 0);   /* size 0 means the default, 4 */
            CHECK_EQ_INT(s->nspheres, 7381);
            vw_scene_free(s);
            continue;
        }
        CHECK_EQ_INT(s->nspheres, expect);
        CHECK_EQ_INT(s->npolygons, 1);
        CHECK_EQ_INT(s->nlights, 3);
        CHECK_EQ_INT(s->camera.valid, 1);
        CHECK_EQ_INT(s->camera.width, 512);
        CHECK(s->materials[s->spheres[0].material].specular[0] > 0.3f);   /* mirror-ish */
        if (n <= 3)
            check_no_overlap(s, 1e-9);
        vw_scene_free(s);
    }

    /* The sphereflake is SPD's balls (Haines), sphere for sphere: its first lines, as
       balls.c prints them with 6 digits. The children were turned about their parent's
       axis from SPD's (the same counts and sizes, other spheres). */
    {
        static const double spd[][4] = {
            {0, 0, 0, 0.5},
            {0.272166, 0.272166, 0.544331, 0.166667},
            {0.420314, 0.420314, 0.618405, 0.0555556},
            {0.461844, 0.304709, 0.43322, 0.0555556},
            {0.304709, 0.461844, 0.43322, 0.0555556},
            {0.230635, 0.38777, 0.729516, 0.0555556},
            {0.115031, 0.4293, 0.544331, 0.0555556},
            {0.082487, 0.239622, 0.655442, 0.0555556},
            {0.38777, 0.230635, 0.729516, 0.0555556},
            {0.239622, 0.082487, 0.655442, 0.0555556},
            {0.4293, 0.115031, 0.544331, 0.0555556},
            {0.643951, 0.172546, 0, 0.166667}};
        vw_scene *s = gen("balls", 2, 0, 1, 0);
        for (size_t i = 0; i < sizeof spd / sizeof spd[0]; i++) {
            const vw_sphere *b = &s->spheres[i];
            double d = fabs(b->radius - spd[i][3]);
            for (int a = 0; a < 3; a++) d = fmax(d, fabs(b->center[a] - spd[i][a]));
            EXPECT(d < 1e-6, "sphere %zu: %g %g %g %g, SPD has %g %g %g %g", i, b->center[0],
                   b->center[1], b->center[2], b->radius, spd[i][0], spd[i][1], spd[i][2],
                   spd[i][3]);
        }
        vw_scene_free(s);
    }

    /* Every generator: deterministic, round-trips through NFF exactly, sane. */
    for (size_t g = 0; vw_gen_name(g); g++) {
        const char *name = vw_gen_name(g);
        int size = !strcmp(name, "balls") ? 2 : !strcmp(name, "tree") ? 4
                 : !strcmp(name, "rings") ? 3 : 0;
        vw_scene *a = gen(name, size, 300, 7, 0.5), *b = gen(name, size, 300, 7, 0.5);
        size_t na = 0, nb = 0;
        char *ta = nff_string(a, &na), *tb = nff_string(b, &nb);
        CHECK(na == nb && memcmp(ta, tb, na) == 0);
        vw_scene *r;
        char err[512];
        vw_status st = vw_scene_read_nff(name, ta, na, &r, err, sizeof err);
        if (st != VW_OK)
            fprintf(stderr, "%s: %s\n", name, err);
        CHECK_EQ_INT(st, VW_OK);
        CHECK(scene_equal(a, r));
        CHECK(vw_scene_count_objects(a) > 0);
        CHECK_EQ_INT(a->camera.valid, 1);
        CHECK(a->nlights >= 1);
        double lo[3], hi[3];
        vw_scene_bounds(a, lo, hi);
        for (int k = 0; k < 3; k++)
            CHECK(isfinite(lo[k]) && isfinite(hi[k]) && lo[k] <= hi[k]);
        printf("%-8s %6zu objects (%zu spheres, %zu cones, %zu polygons), %zu materials\n",
               name, vw_scene_count_objects(a), a->nspheres, a->ncones, a->npolygons,
               a->nmaterials);
        free(ta);
        free(tb);
        vw_scene_free(a);
        vw_scene_free(b);
        vw_scene_free(r);
    }

    /* Every generator with its default options writes clean geometry: each polygon
       planar to rounding (the Cornell box's red wall, as published, was 0.8 mm off, and
       the radiosity mesher warned and flattened it), and its NFF reads back without a
       warning. */
    vw_scene_set_warning_handler(count_warning, NULL);
    for (size_t g = 0; vw_gen_name(g); g++) {
        const char *name = vw_gen_name(g);
        vw_scene *a, *r;
        char err[512];
        CHECK_EQ_INT(vw_gen(name, NULL, &a, err, sizeof err), VW_OK);
        double worst = 0;
        size_t at = 0;
        for (size_t i = 0; i < a->npolygons; i++)
            if (off_plane(a, i) > worst) {
                worst = off_plane(a, i);
                at = i;
            }
        EXPECT(worst <= 1e-12, "%s: polygon (id %d) is %.3g of its size off its plane", name,
               a->polygons[at].id, worst);
        size_t n = 0;
        char *t = nff_string(a, &n);
        nwarnings = 0;
        CHECK_EQ_INT(vw_scene_read_nff(name, t, n, &r, err, sizeof err), VW_OK);
        EXPECT(nwarnings == 0, "%s: %d warnings reading its NFF back", name, nwarnings);
        free(t);
        vw_scene_free(a);
        vw_scene_free(r);
    }
    vw_scene_set_warning_handler(NULL, NULL);

    /* Random spheres: the seed matters, no overlaps, the cluster fraction holds. */
    {
        vw_scene *a = gen("spheres", 0, 500, 3, 0.5), *b = gen("spheres", 0, 500, 4, 0.5);
        CHECK_EQ_INT(a->nspheres, 500);
        CHECK(memcmp(a->spheres[0].center, b->spheres[0].center, sizeof(double[3])) != 0);
        check_no_overlap(a, 0);
        int inside = 0;
        for (size_t i = 0; i < a->nspheres; i++) {
            int in = 1;
            for (int k = 0; k < 3; k++)
                in &= a->spheres[i].center[k] >= 1.25 && a->spheres[i].center[k] <= 3.75;
            inside += in;
        }
        CHECK(inside >= 250 && inside < 500);
        vw_scene_free(a);
        vw_scene_free(b);
        a = gen("spheres", 0, 1000, 1, 1.0);
        CHECK_EQ_INT(a->nspheres, 1000);
        check_no_overlap(a, 0);
        for (size_t i = 0; i < a->nspheres; i++)
            for (int k = 0; k < 3; k++)
                CHECK(a->spheres[i].center[k] >= 1.25 && a->spheres[i].center[k] <= 3.75);
        vw_scene_free(a);
    }

    /* Cornell box: 20 polygons (the red wall is two triangles), an emitting light
       facing down, no other emitter. */
    {
        vw_scene *c = gen("cornell", 0, 0, 1, 0);
        CHECK_EQ_INT(c->npolygons, 20);
        int lamps = 0;
        for (size_t i = 0; i < c->npolygons; i++)
            if (emits(c, c->polygons[i].material)) {
                double n[3];
                normal(c, i, n);
                CHECK(n[1] < 0 && n[0] == 0 && n[2] == 0);
                lamps++;
            }
        CHECK_EQ_INT(lamps, 1);
        /* the floor faces up */
        double n[3];
        normal(c, 0, n);
        CHECK(n[1] > 0);
        vw_scene_free(c);
        vw_scene *r = gen("room", 0, 0, 1, 0);
        lamps = 0;
        for (size_t i = 0; i < r->npolygons; i++)
            lamps += emits(r, r->polygons[i].material);
        CHECK_EQ_INT(lamps, 1);
        CHECK(r->npolygons > 50);
        vw_scene_free(r);
    }

    /* Parameters. */
    vw_gen_params p;
    vw_gen_params_init(&p);
    p.width = 320;
    p.height = 200;
    vw_scene *s;
    char err[256];
    CHECK_EQ_INT(vw_gen("tree", &p, &s, err, sizeof err), VW_OK);
    CHECK(s->camera.width == 320 && s->camera.height == 200);
    vw_scene_free(s);
    CHECK_EQ_INT(vw_gen("teapot", NULL, &s, err, sizeof err), VW_E_INVAL);
    CHECK(strstr(err, "unknown generator 'teapot'") != NULL && s == NULL);
    p.size = 99;
    CHECK_EQ_INT(vw_gen("balls", &p, &s, err, sizeof err), VW_E_INVAL);
    CHECK(strstr(err, "size 99") != NULL);
    p.size = 0;
    p.cluster = 1.5;
    CHECK_EQ_INT(vw_gen("spheres", &p, &s, err, sizeof err), VW_E_INVAL);
    TEST_DONE();
}
