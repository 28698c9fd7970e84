/* test_radiosity.c - tests of the radiosity application: delta form factors, analytic
 * form factors, a closed box, decomposition independence, the energy ledger and
 * checkpoint/resume. One executable; the first argument names the test.
 * Scenes are built in code (squares, a box) or by the generators (cornell).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include "radiosity/radiosity.h"
#include "vw_test.h"
#include "vwalls/gen.h"

/* ---- scenes in code ---- */

typedef struct quad {
    double v[4][3];
    float rho, emit;
} quad;

static vw_scene *scene_of(const quad *q, int n)
{
    vw_scene *s = calloc(1, sizeof *s);
    s->materials = calloc((size_t)n, sizeof *s->materials);
    s->polygons = calloc((size_t)n, sizeof *s->polygons);
    s->vertices = calloc((size_t)n * 4, sizeof *s->vertices);
    s->indices = calloc((size_t)n * 4, sizeof *s->indices);
    s->nmaterials = s->npolygons = (size_t)n;
    s->nvertices = s->nindices = (size_t)n * 4;
    for (int i = 0; i < n; i++) {
        for (int k = 0; k < 3; k++) {
            s->materials[i].diffuse[k] = q[i].rho;
            s->materials[i].emission[k] = q[i].emit;
        }
        s->materials[i].ior = 1;
        s->polygons[i] = (vw_polygon){.id = i, .material = i, .first = 4 * i, .count = 4};
        for (int k = 0; k < 4; k++) {
            memcpy(s->vertices[4 * i + k], q[i].v[k], sizeof(double) * 3);
            s->indices[4 * i + k] = 4 * i + k;
        }
    }
    return s;
}

/* The six inward faces of the unit cube; face 0 (the floor) emits when emit > 0. */
static vw_scene *box_scene(float rho, float emit)
{
    quad q[6] = {
        {{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, rho, emit},   /* z=0, normal +z */
        {{{0, 0, 1}, {0, 1, 1}, {1, 1, 1}, {1, 0, 1}}, rho, 0},      /* z=1, normal -z */
        {{{0, 0, 0}, {0, 1, 0}, {0, 1, 1}, {0, 0, 1}}, rho, 0},      /* x=0, normal +x */
        {{{1, 0, 0}, {1, 0, 1}, {1, 1, 1}, {1, 1, 0}}, rho, 0},      /* x=1, normal -x */
        {{{0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}}, rho, 0},      /* y=0, normal +y */
        {{{0, 1, 0}, {1, 1, 0}, {1, 1, 1}, {0, 1, 1}}, rho, 0},      /* y=1, normal -y */
    };
    return scene_of(q, 6);
}

static vw_scene *cornell(void)
{
    vw_scene *s = NULL;
    char err[256];
    vw_status st = vw_gen("cornell", NULL, &s, err, sizeof err);
    if (st != VW_OK) {
        fprintf(stderr, "cornell: %s\n", err);
        exit(1);
    }
    return s;
}

/* ---- solving ---- */

typedef struct result {
    size_t npoly;
    double *area;
    double (*B)[3], (*inc)[3];
    rad_ledger ledger;
    int64_t shots;
    double ratio;
} result;

static void result_free(result *r)
{
    free(r->area), free(r->B), free(r->inc);
}

/* A scene meshed on o's layout and solved as o says: what every solving test starts from
   (rad_options.quiet on; close with solved_close). */
typedef struct solved {
    vw_decomp *d;
    rad_mesh m;
    rad_solver *s;
    int conv;
    const rad_elem_result *e; /* the collected elements */
    size_t ne;
} solved;

/* The scene's world box cut on o's layout, and the scene meshed on it (named `name` in
   messages); what every solving and meshing test starts from. */
static void meshed(const vw_scene *sc, const char *name, const rad_options *o, vw_decomp **d,
                   rad_mesh *m)
{
    vw_box wb = rad_world_box(sc);
    CHECK(vw_decomp_create_grid(&wb, o->dims, d) == VW_OK);
    char err[512] = "";
    vw_status st = rad_mesh_build(sc, name, *d, o, m, err, sizeof err);
    if (st != VW_OK) fprintf(stderr, "%s\n", err);
    CHECK(st == VW_OK);
}

static void solved_open(const vw_scene *sc, rad_options o, solved *v)
{
    memset(v, 0, sizeof *v);
    o.quiet = 1;
    meshed(sc, "test", &o, &v->d, &v->m);
    char err[512] = "";
    vw_status st = rad_solver_create(&v->m, v->d, &o, &v->s, err, sizeof err);
    if (st != VW_OK) fprintf(stderr, "%s\n", err);
    CHECK(st == VW_OK);
    CHECK(rad_solver_run(v->s, NULL, NULL, &v->conv, err, sizeof err) == VW_OK);
    CHECK(rad_solver_collect(v->s, err, sizeof err) == VW_OK);
    v->e = rad_solver_elements(v->s, &v->ne);
}

static void solved_close(solved *v)
{
    rad_solver_free(v->s);
    rad_mesh_free(&v->m);
    vw_decomp_free(v->d);
}

/* Per polygon: area, radiosity, incident power; and the run's ledger, shots, ratio. */
static result result_of(const solved *v)
{
    result r;
    memset(&r, 0, sizeof r);
    r.npoly = v->m.npolys;
    r.area = calloc(r.npoly, sizeof *r.area);
    r.B = calloc(r.npoly, sizeof *r.B);
    r.inc = calloc(r.npoly, sizeof *r.inc);
    rad_polygon_sums(v->e, v->ne, r.npoly, r.area, r.B, r.inc);
    r.ledger = rad_solver_ledger(v->s);
    r.shots = rad_solver_shots(v->s);
    r.ratio = rad_solver_unshot_ratio(v->s);
    return r;
}

static result solve(const vw_scene *sc, rad_options o)
{
    solved v;
    solved_open(sc, o, &v);
    result r = result_of(&v);
    if (o.max_rounds == 0 && o.max_shots == 0) CHECK(v.conv);
    solved_close(&v);
    return r;
}

/* Area-weighted relative RMS difference of polygon radiosities. */
static double rel_rms(const result *a, const result *b)
{
    double num = 0, den = 0;
    for (size_t i = 0; i < a->npoly; i++)
        for (int k = 0; k < 3; k++) {
            double d = a->B[i][k] - b->B[i][k];
            num += a->area[i] * d * d;
            den += a->area[i] * b->B[i][k] * b->B[i][k];
        }
    return sqrt(num / den);
}

/* ---- tests ---- */

static int t_ffsum(void)
{
    int res[] = {8, 32, 64, 100};
    for (int i = 0; i < 4; i++) {
        rad_hemicube h;
        CHECK(rad_hemicube_init(&h, res[i]) == VW_OK);
        printf("res %3d: sum of delta form factors %.6f\n", res[i], h.raw_sum);
        if (res[i] >= 32) CHECK_NEAR(h.raw_sum, 1.0, 1e-3);
        double s = 0;
        for (int p = 0; p < h.npix; p++) s += h.dff[p];
        CHECK_NEAR(s, 1.0, 1e-12);
        rad_hemicube_free(&h);
    }
    CHECK(rad_hemicube_bitmap_bytes(RAD_MAX_RES) + 128 <= VW_MAX_MSG_BYTES);
    return 0;
}

/* F from unit square 0 (emitting, black) to square 1 (black): incident / emitted. */
static double ff(const quad *q, const char *layout, int *ok)
{
    vw_scene *sc = scene_of(q, 2);
    rad_options o;
    rad_options_init(&o);
    o.patch_size = 1.0 / 16;
    o.elem_split = 1;
    o.res = 100;
    o.sf = 1e-9;
    o.workers = 2;
    if (layout) vw_layout_parse(layout, o.dims, NULL, 0);
    result r = solve(sc, o);
    double F = r.inc[1][0] / 1.0;
    printf("F = %.5f  (%s, ledger error %.2e, escaped %.4f)\n", F, layout ? layout : "1",
           r.ledger.error, r.ledger.escaped[0]);
    *ok = r.ledger.error < 1e-9;
    result_free(&r);
    vw_scene_free(sc);
    return F;
}

static int t_parallel(void)
{
    quad q[2] = {{{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, 0, 1},
                 {{{0, 0, 1}, {0, 1, 1}, {1, 1, 1}, {1, 0, 1}}, 0, 0}};
    /* Parallel unit squares at distance 1 (Howell's catalogue, C-11). */
    double X = 1, Y = 1, x = sqrt(1 + X * X), y = sqrt(1 + Y * Y);
    double ref = 2 / (M_PI * X * Y) *
                 (0.5 * log(x * x * y * y / (x * x + y * y - 1)) + X * y * atan(X / y) + Y * x * atan(Y / x) -
                  X * atan(X) - Y * atan(Y));
    int ok;
    double F = ff(q, NULL, &ok);
    printf("analytic %.5f, relative error %.3f%%\n", ref, 100 * fabs(F - ref) / ref);
    CHECK(ok);
    CHECK_NEAR(F, ref, 0.02 * ref);
    F = ff(q, "2x2x2", &ok);
    CHECK(ok);
    CHECK_NEAR(F, ref, 0.02 * ref);
    return 0;
}

static int t_perpendicular(void)
{
    quad q[2] = {{{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, 0, 1},   /* z=0, normal +z */
                 {{{0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}}, 0, 0}};  /* y=0, normal +y */
    /* Perpendicular unit squares sharing an edge (Howell C-14, W = H = 1). */
    double W = 1, H = 1, W2 = W * W, H2 = H * H, R = W2 + H2;
    double ref = 1 / (M_PI * W) *
                 (W * atan(1 / W) + H * atan(1 / H) - sqrt(R) * atan(1 / sqrt(R)) +
                  0.25 * log((1 + W2) * (1 + H2) / (1 + R) *
                             pow(W2 * (1 + R) / ((1 + W2) * R), W2) *
                             pow(H2 * (1 + R) / ((1 + H2) * R), H2)));
    int ok;
    double F = ff(q, NULL, &ok);
    printf("analytic %.5f, relative error %.3f%%\n", ref, 100 * fabs(F - ref) / ref);
    CHECK(ok);
    CHECK_NEAR(F, ref, 0.02 * ref);
    F = ff(q, "2x2x2", &ok);
    CHECK(ok);
    CHECK_NEAR(F, ref, 0.02 * ref);
    return 0;
}

static int t_box(void)
{
    const float rho = 0.5f;
    vw_scene *sc = box_scene(rho, 1);
    rad_options o;
    rad_options_init(&o);
    o.patch_size = 0.25;
    o.sf = 1e-5;
    o.workers = 2;
    const char *layouts[] = {"1", "2x2x2"};
    for (int l = 0; l < 2; l++) {
        vw_layout_parse(layouts[l], o.dims, NULL, 0);
        result r = solve(sc, o);
        double total = 0, emitted = 1; /* the floor: area 1, Ke 1 */
        for (size_t i = 0; i < r.npoly; i++) total += r.B[i][0] * r.area[i];
        double want = emitted / (1 - rho);
        printf("%s: sum B*A = %.6f, want %.6f (rel %.2e), %lld shots, ledger %.2e, escaped %.2e\n",
               layouts[l], total, want, fabs(total - want) / want, (long long)r.shots, r.ledger.error,
               r.ledger.escaped[0]);
        CHECK_NEAR(total, want, 0.01 * want);
        CHECK(r.ledger.error < 1e-9);
        result_free(&r);
    }
    vw_scene_free(sc);
    return 0;
}

static int t_layouts(void)
{
    vw_scene *sc = cornell();
    rad_options o;
    rad_options_init(&o);
    o.sf = 2e-4;
    o.workers = 1;
    result ref = solve(sc, o);
    printf("1 cell, 1 worker: %lld shots, ledger %.2e\n", (long long)ref.shots, ref.ledger.error);
    CHECK(ref.ledger.error < 1e-9);
    struct { const char *layout; int workers; } v[] = {
        {"1", 2}, {"1", 4}, {"2x2x2", 1}, {"2x2x2", 2}, {"2x2x2", 4}, {"4x4x4", 2},
    };
    for (size_t i = 0; i < sizeof v / sizeof v[0]; i++) {
        vw_layout_parse(v[i].layout, o.dims, NULL, 0);
        o.workers = v[i].workers;
        result r = solve(sc, o);
        double e = rel_rms(&r, &ref);
        printf("%-6s %d workers: %lld shots, relative RMS vs one cell %.3f%%, ledger %.2e\n", v[i].layout,
               v[i].workers, (long long)r.shots, 100 * e, r.ledger.error);
        CHECK(e <= 0.01);
        CHECK(r.ledger.error < 1e-9);
        result_free(&r);
    }
    result_free(&ref);
    vw_scene_free(sc);
    return 0;
}

static int t_checkpoint(void)
{
    vw_scene *sc = cornell();
    rad_options o;
    rad_options_init(&o);
    o.sf = 2e-4;
    o.workers = 2;
    vw_layout_parse("2x2x2", o.dims, NULL, 0);
    result full = solve(sc, o);
    char path[] = "/tmp/vw_rad_ckXXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0);
    close(fd);
    rad_options a = o;
    a.checkpoint = path;
    a.checkpoint_every = 0;
    a.max_rounds = 3;
    result part = solve(sc, a); /* stops mid-run; the checkpoint of round 3 stays */
    printf("interrupted after %lld shots (unshot ratio %.3g)\n", (long long)part.shots, part.ratio);
    CHECK(part.ratio > o.sf);
    rad_options b = o;
    b.resume = path;
    result res = solve(sc, b);
    double e = rel_rms(&res, &full);
    printf("resumed: %lld shots in all, relative RMS vs uninterrupted %.3f%%, ledger %.2e\n",
           (long long)res.shots, 100 * e, res.ledger.error);
    CHECK(res.shots > part.shots);
    CHECK(e <= 0.01);
    CHECK(res.ledger.error < 1e-9);
    unlink(path);
    result_free(&full), result_free(&part), result_free(&res);
    vw_scene_free(sc);
    return 0;
}

/* The furnace: a closed box whose every face emits E = 1 and reflects rho = 0.5 has
   B = E / (1 - rho) = 2 everywhere. Per polygon within 0.2 % (sf 1e-6: the unshot
   power left is 4e-5 of the emitted), per element within 5 % (the hemicube's
   point-to-area form factor from a shooter's centroid misplaces light near the edges
   between faces: elements of a patch's size, 0.125, measured 1.95-2.03; at half a
   patch, --elements 2, 1.84-2.11), nothing escapes, on 1 cell and 2x2x2. */
static int t_furnace(void)
{
    vw_scene *sc = box_scene(0.5f, 1);
    for (size_t i = 0; i < sc->nmaterials; i++)
        for (int k = 0; k < 3; k++) sc->materials[i].emission[k] = 1;
    rad_options o;
    rad_options_init(&o);
    o.patch_size = 0.125;
    o.elem_split = 1;
    o.sf = 1e-6;
    o.workers = 2;
    const char *layouts[] = {"1", "2x2x2"};
    for (int l = 0; l < 2; l++) {
        vw_layout_parse(layouts[l], o.dims, NULL, 0);
        solved v;
        solved_open(sc, o, &v);
        CHECK(v.conv);
        result r = result_of(&v);
        double pmin = INFINITY, pmax = -INFINITY, emin = INFINITY, emax = -INFINITY;
        for (size_t i = 0; i < r.npoly; i++) {
            pmin = fmin(pmin, r.B[i][0]), pmax = fmax(pmax, r.B[i][0]);
            CHECK_NEAR(r.B[i][0], 2, 0.002 * 2);
        }
        for (size_t i = 0; i < v.ne; i++) {
            emin = fmin(emin, v.e[i].B[0]), emax = fmax(emax, v.e[i].B[0]);
            CHECK_NEAR(v.e[i].B[0], 2, 0.05 * 2);
        }
        printf("%s: polygons B %.5f-%.5f, elements %.4f-%.4f (want 2), escaped %.2e, ledger %.2e\n",
               layouts[l], pmin, pmax, emin, emax, r.ledger.escaped[0], r.ledger.error);
        CHECK(fabs(r.ledger.escaped[0]) < 1e-9 * r.ledger.emitted[0]);
        CHECK(r.ledger.error < 1e-9);
        result_free(&r);
        solved_close(&v);
    }
    vw_scene_free(sc);
    return 0;
}

/* A two-sided panel is two coincident polygons back to back. A light below it must light
   the side facing it, whichever polygon comes first in the scene: the hemicube's depth
   tie went to the element rasterised first, and when that was the back face it absorbed
   the light (a back face is black), so the lit side stayed dark (incident 0.0028 of the
   0.1300 the single panel gets, one cell, the top polygon first). Per
   layout: 1 cell and 3x3x3 (the pair in one cell), 2x2x2 (the pair near a wall), with
   and without subdivision. */
static int t_twosided(void)
{
    const quad light = {{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, 0, 1};        /* +z */
    const quad down = {{{.25, .25, .5}, {.25, .75, .5}, {.75, .75, .5}, {.75, .25, .5}}, .5f, 0};
    const quad up = {{{.25, .25, .5}, {.75, .25, .5}, {.75, .75, .5}, {.25, .75, .5}}, .5f, 0};
    const char *layouts[] = {"1", "3x3x3", "2x2x2"};
    rad_options o;
    rad_options_init(&o);
    o.patch_size = 1.0 / 8;
    o.sf = 1e-9;
    o.workers = 2;
    for (int sub = 0; sub < 2; sub++) {
        o.subdivide = sub ? 0.3 : 0;
        for (int l = 0; l < 3; l++) {
            vw_layout_parse(layouts[l], o.dims, NULL, 0);
            quad one[2] = {light, down};
            vw_scene *sc = scene_of(one, 2);
            result r1 = solve(sc, o);
            vw_scene_free(sc);
            double want = r1.inc[1][0];
            for (int order = 0; order < 2; order++) {
                quad two[3] = {light, order ? down : up, order ? up : down};
                sc = scene_of(two, 3);
                result r = solve(sc, o);
                int id = order ? 1 : 2, iu = order ? 2 : 1;
                printf("%s%s, %s first: lit side incident %.5f (single panel %.5f), top %.2e, "
                       "ledger %.2e\n", layouts[l], sub ? " subdivided" : "", order ? "down" : "up",
                       r.inc[id][0], want, r.inc[iu][0], r.ledger.error);
                CHECK(want > 0.1);
                CHECK_NEAR(r.inc[id][0], want, 0.01 * want);
                CHECK(r.inc[iu][0] < 1e-3 * want);
                CHECK(r.ledger.error < 1e-9);
                result_free(&r);
                vw_scene_free(sc);
            }
            result_free(&r1);
        }
    }
    return 0;
}

static float *read_pfm(const char *path, int *w, int *h);

/* The picture of a two-sided panel: from below it must show the lit side's radiosity,
   from above the top's, whichever polygon comes first (the picture's z-buffer gave a
   tie to the first: from below it showed the dark top, 0 for 0.277). */
static int t_twosided_image(void)
{
    const quad light = {{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, 0, 1};
    const quad down = {{{.25, .25, .5}, {.25, .75, .5}, {.75, .75, .5}, {.75, .25, .5}}, .5f, 0};
    const quad up = {{{.25, .25, .5}, {.75, .25, .5}, {.75, .75, .5}, {.25, .75, .5}}, .5f, 0};
    rad_options o;
    rad_options_init(&o);
    o.patch_size = 1.0 / 8;
    o.sf = 1e-9;
    o.workers = 1;
    char path[64];
    snprintf(path, sizeof path, "/tmp/vw_rad_twosided_%ld.pfm", (long)getpid());
    for (int order = 0; order < 2; order++) {
        quad q[3] = {light, order ? down : up, order ? up : down};
        vw_scene *sc = scene_of(q, 3);
        solved v;
        solved_open(sc, o, &v);
        result r = result_of(&v);
        int id = order ? 1 : 2, iu = order ? 2 : 1;
        for (int below = 0; below < 2; below++) {
            vw_camera cam;
            memset(&cam, 0, sizeof cam);
            double z0 = below ? 0.2 : 0.9, z1 = below ? 1 : 0;
            cam.from[0] = cam.at[0] = 0.5, cam.from[1] = cam.at[1] = 0.5;
            cam.from[2] = z0, cam.at[2] = z1, cam.up[1] = 1;
            cam.angle = 30, cam.width = cam.height = 16, cam.hither = 1e-3;
            const double amb[3] = {0, 0, 0};
            char err[256] = "";
            CHECK(rad_write_image(path, &cam, &v.m, v.e, v.ne, amb, err, sizeof err) == VW_OK);
            int w, h;
            float *px = read_pfm(path, &w, &h);
            CHECK(px && w == 16 && h == 16);
            /* The lit side varies over the panel (its centre is 7 % above its mean);
               the top is lit by nothing. */
            double got = px[3 * (8 * 16 + 8)], lit = r.B[id][0];
            printf("picture, %s first, from %s: centre %.5f (lit side %.5f, top %.5f)\n",
                   order ? "down" : "up", below ? "below" : "above", got, lit, r.B[iu][0]);
            CHECK(lit > 0.1);
            if (below) CHECK_NEAR(got, lit, 0.15 * lit);
            else CHECK(got < 0.01 * lit);
            free(px);
        }
        result_free(&r);
        solved_close(&v);
        vw_scene_free(sc);
    }
    unlink(path);
    return 0;
}

/* Adaptive subdivision. A leaf element of the result: polygon, centroid, size (its grid
   square's side) and mean reflected radiosity. */
typedef struct leaf {
    int32_t poly;
    double c[3], size, y;
} leaf;

/* Solves like solve() and also returns the leaves of non-emitting polygons. */
static result solve_leaves(const vw_scene *sc, rad_options o, leaf **out, size_t *nout)
{
    solved v;
    solved_open(sc, o, &v);
    CHECK(v.conv);
    result r = result_of(&v);
    const rad_elem_result *e = v.e;
    size_t ne = v.ne;
    *out = calloc(ne, sizeof **out);
    *nout = 0;
    for (size_t i = 0; i < ne; i++) {
        const rad_piece *pc = &v.m.pieces[e[i].piece];
        /* Emitters, and slivers left by clipping (few pixels, noisy in any solution). */
        double size = pc->elem / (double)(1 << e[i].level);
        if (pc->emit[0] + pc->emit[1] + pc->emit[2] > 0 || e[i].area < 0.5 * size * size) continue;
        rad_poly poly;
        leaf *l = &(*out)[(*nout)++];
        CHECK(rad_elem_polygon(pc, e[i].level, e[i].gi, e[i].gj, &poly) >= 3);
        rad_poly_area(&poly, NULL, l->c);
        l->poly = e[i].poly;
        l->size = size;
        l->y = (pc->rho[0] * e[i].incident[0] + pc->rho[1] * e[i].incident[1] + pc->rho[2] * e[i].incident[2]) /
               (3 * e[i].area);
    }
    solved_close(&v);
    return r;
}

static int cmp_dbl(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Over pairs of adjacent leaves (same polygon, centroids at most half their sizes'
   sum apart, so edge neighbours only) of polygon poly (-1: all): the 99th percentile of
   the radiosity gradient |dy| / distance relative to the polygon's mean (sharpness: a
   shadow edge resolved on small leaves is steep), and the median of |dy| relative to
   the polygon's mean (roughness: a checkerboard of aliased leaves makes it large; a
   smooth solution on smaller leaves makes it smaller). With poly -1 the mean is over
   all polygons. */
static void leaf_stats(const leaf *l, size_t n, int32_t poly, double *grad, double *rough)
{
    double *d = malloc(sizeof(double) * 64 * (n ? n : 1)), *gr = malloc(sizeof(double) * 64 * (n ? n : 1));
    size_t nd = 0;
    double ysum = 0, cnt = 0;
    for (size_t i = 0; i < n; i++)
        if (poly < 0 || l[i].poly == poly) ysum += l[i].y, cnt++;
    double ymean = cnt > 0 ? ysum / cnt : 1;
    for (size_t i = 0; i < n; i++) {
        if (poly >= 0 && l[i].poly != poly) continue;
        for (size_t j = i + 1; j < n; j++) {
            if (l[j].poly != l[i].poly) continue;
            double r[3] = {l[i].c[0] - l[j].c[0], l[i].c[1] - l[j].c[1], l[i].c[2] - l[j].c[2]};
            double dist = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
            if (dist > 0.5 * (l[i].size + l[j].size) * 1.001 || dist <= 0) continue;
            double dy = fabs(l[i].y - l[j].y);
            if (nd < 64 * n) gr[nd] = dy / dist / ymean, d[nd++] = dy / ymean;
        }
    }
    qsort(d, nd, sizeof *d, cmp_dbl);
    qsort(gr, nd, sizeof *gr, cmp_dbl);
    *rough = nd ? d[nd / 2] : 0;
    *grad = nd ? gr[(size_t)(0.99 * (double)(nd - 1))] : 0;
    free(d), free(gr);
}

/* --subdivide on the Cornell box: the energy ledger still balances; the solution (per
   polygon) matches the one without subdivision and the one-cell subdivided one within
   1 %; the floor's steepest gradient (the blocks' contact shadows) is at least twice as
   steep as without subdivision, on one cell and on 2x2x2; and neighbouring leaves differ
   less than without subdivision (0.6 x; measured 0.2 x on one cell, 0.46 x on 2x2x2):
   a checkerboard of aliased leaves fails this. */
static int t_subdivide(void)
{
    vw_scene *sc = cornell();
    rad_options o;
    rad_options_init(&o);
    o.sf = 1e-3;
    o.workers = 2;
    leaf *l0, *l1, *l2;
    size_t n0, n1, n2;
    result a = solve_leaves(sc, o, &l0, &n0);
    o.subdivide = 0.3;
    result b = solve_leaves(sc, o, &l1, &n1);
    vw_layout_parse("2x2x2", o.dims, NULL, 0);
    result c = solve_leaves(sc, o, &l2, &n2);
    /* Sharpness on polygon 0, the floor; roughness over all polygons. */
    double g0, r0, g1, r1, g2, r2, ra, rb, rc;
    leaf_stats(l0, n0, -1, &g0, &ra), leaf_stats(l0, n0, 0, &g0, &r0);
    leaf_stats(l1, n1, -1, &g1, &rb), leaf_stats(l1, n1, 0, &g1, &r1);
    leaf_stats(l2, n2, -1, &g2, &rc), leaf_stats(l2, n2, 0, &g2, &r2);
    double e_ba = rel_rms(&b, &a), e_cb = rel_rms(&c, &b);
    printf("no subdivision: %zu leaves, floor steepest gradient %.4f /mm, median neighbour contrast %.4f, ledger %.2e\n",
           n0, g0, ra, a.ledger.error);
    printf("subdivided, 1 cell: %zu leaves, floor %.4f /mm, contrast %.4f, ledger %.2e, vs unsubdivided %.3f%% RMS\n",
           n1, g1, rb, b.ledger.error, 100 * e_ba);
    printf("subdivided, 2x2x2: %zu leaves, floor %.4f /mm, contrast %.4f, ledger %.2e, vs one cell %.3f%% RMS\n", n2,
           g2, rc, c.ledger.error, 100 * e_cb);
    CHECK(a.ledger.error < 1e-9);
    CHECK(b.ledger.error < 1e-9);
    CHECK(c.ledger.error < 1e-9);
    CHECK(n1 > n0 && n2 > n0);
    CHECK(e_ba <= 0.01);
    CHECK(e_cb <= 0.01);
    CHECK(g1 >= 2 * g0);
    CHECK(g2 >= 2 * g0);
    CHECK(rb <= 0.6 * ra);
    CHECK(rc <= 0.6 * ra);
    free(l0), free(l1), free(l2);
    result_free(&a), result_free(&b), result_free(&c);
    vw_scene_free(sc);
    return 0;
}

/* The full-matrix Gauss-Seidel reference (reference.c) on one cell, as polygon sums. */
static result reference(const vw_scene *sc, rad_options o, rad_reference *ref)
{
    result r;
    memset(&r, 0, sizeof r);
    o.quiet = 1;
    o.dims[0] = o.dims[1] = o.dims[2] = 1;
    vw_box wb = rad_world_box(sc);
    vw_decomp *d;
    rad_mesh m;
    meshed(sc, "test", &o, &d, &m);
    char err[512] = "";
    vw_status st = rad_reference_solve(&m, &wb, o.res, 1e-13, 100000, ref, err, sizeof err);
    if (st != VW_OK) fprintf(stderr, "%s\n", err);
    CHECK(st == VW_OK);
    rad_elem_result *e = rad_reference_elements(&m, ref);
    CHECK(e != NULL);
    r.npoly = m.npolys;
    r.area = calloc(r.npoly, sizeof *r.area);
    r.B = calloc(r.npoly, sizeof *r.B);
    r.inc = calloc(r.npoly, sizeof *r.inc);
    rad_polygon_sums(e, ref->n, r.npoly, r.area, r.B, r.inc);
    free(e);
    rad_mesh_free(&m);
    vw_decomp_free(d);
    return r;
}

/* ---- where the world sits ---- */

/* Level-0 elements of a scene on layout dims after one round, and how many of them
   cover at most 1e-6 of their grid square. */
static size_t count_elements(const vw_scene *sc, const char *layout, size_t *slivers)
{
    rad_options o;
    rad_options_init(&o);
    o.workers = 2;
    o.max_shots = 1;
    vw_layout_parse(layout, o.dims, NULL, 0);
    solved v;
    solved_open(sc, o, &v);
    *slivers = 0;
    for (size_t i = 0; i < v.ne; i++) {
        double h = v.m.pieces[v.e[i].piece].elem / (double)(1 << v.e[i].level);
        *slivers += !(v.e[i].area > 1e-6 * h * h);
    }
    size_t ne = v.ne;
    solved_close(&v);
    return ne;
}

/* The Cornell box scaled and moved: the same elements on every layout, and no sliver.
   Piece edges on grid lines (every patch edge) are computed a few ulps off them, and the
   square beyond used to become a sliver element some 1e-13 wide, or not, as the
   rounding of the world's position fell (cornell.nff on 2x2x2: 2929 elements, 2904 at
   1/1000 the size, 3004 moved by 1e4, for 2889 real ones; this scene on one cell had
   28 slivers). A sliver's radiosity stays 0 and subdivision split its neighbours for
   it: 11598 leaves, 11945 moved. */
static int t_placement(void)
{
    vw_scene *sc = cornell();
    const double xf[][4] = {{1, 0, 0, 0},   {1e-3, 0, 0, 0}, {1e3, 0, 0, 0},
                            {1, 0.3, 1e4, -7}, {3.7, -1e3, 2, 0}, {0.01, 5, 5, 5}};
    const char *layouts[] = {"1", "2x2x2", "3x5x2"};
    double (*orig)[3] = malloc(sizeof *orig * sc->nvertices);
    memcpy(orig, sc->vertices, sizeof *orig * sc->nvertices);
    for (int l = 0; l < 3; l++) {
        size_t want = 0;
        for (size_t t = 0; t < sizeof xf / sizeof xf[0]; t++) {
            for (size_t v = 0; v < sc->nvertices; v++)
                for (int k = 0; k < 3; k++) sc->vertices[v][k] = orig[v][k] * xf[t][0] + xf[t][1 + k];
            size_t slivers, n = count_elements(sc, layouts[l], &slivers);
            printf("%-5s x %-6g + (%g, %g, %g): %zu elements, %zu slivers\n", layouts[l], xf[t][0], xf[t][1],
                   xf[t][2], xf[t][3], n, slivers);
            if (t == 0) want = n;
            CHECK_EQ_INT((long long)n, (long long)want);
            CHECK_EQ_INT((long long)slivers, 0);
        }
    }
    free(orig);
    vw_scene_free(sc);
    return 0;
}

/* ---- many cells ---- */

/* The Cornell box on 16x16x16 cells, one round: memory must follow the work, not the
   cells. Each cell with elements used to keep its own hemicube z-buffer (196 KB at res
   64; 220 MB peak here, 1.1 GB on 32x32x32); the z-buffer is now one a worker (64 MB
   here, 0.48 GB on 32x32x32). The bound is skipped under sanitizers (their shadow
   memory). */
static int t_manycells(void)
{
    vw_scene *sc = cornell();
    rad_options o;
    rad_options_init(&o);
    o.workers = 1;
    o.max_shots = 1;
    /* Since the stopping rule is about patches (module.c, patch_unshot) every piece of a
       lit patch shoots at sf 1e-3: 723 shots of a bitmap through 4096 cells, 13 s here
       and past the TSan stage's limit. The cells' memory, checked here, does not depend
       on the shots: sf 1e-2 shoots 33. */
    o.sf = 1e-2;
    vw_layout_parse("16x16x16", o.dims, NULL, 0);
    result r = solve(sc, o);
    struct rusage ru;
    CHECK(getrusage(RUSAGE_SELF, &ru) == 0);
    double mb = ru.ru_maxrss / 1024.0;
    printf("16x16x16, one round: %lld shots, ledger %.2e, peak RSS %.0f MB\n", (long long)r.shots, r.ledger.error,
           mb);
    CHECK(r.shots > 0);
    CHECK(r.ledger.error < 1e-9);
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
    printf("(sanitizer build: memory bound not checked)\n");
#else
    CHECK(mb < 128);
#endif
    result_free(&r);
    vw_scene_free(sc);
    return 0;
}

/* ---- concave polygons ---- */

/* Floor polygons (corners (x, 0, z), normal +y; counts[i] corners each, ids 0..) under a
   square emitter facing down (the last polygon). */
static vw_scene *floor_scene(const double (*xz)[2], const int *counts, int nfloor)
{
    int nv = 4;
    for (int i = 0; i < nfloor; i++) nv += counts[i];
    vw_scene *s = calloc(1, sizeof *s);
    s->materials = calloc(2, sizeof *s->materials);
    s->polygons = calloc((size_t)nfloor + 1, sizeof *s->polygons);
    s->vertices = calloc((size_t)nv, sizeof *s->vertices);
    s->indices = calloc((size_t)nv, sizeof *s->indices);
    s->nmaterials = 2;
    s->npolygons = (size_t)nfloor + 1;
    s->nvertices = s->nindices = (size_t)nv;
    for (int k = 0; k < 3; k++) {
        s->materials[0].diffuse[k] = 0.8f;
        s->materials[1].diffuse[k] = 0.5f;
        s->materials[1].emission[k] = 10;
    }
    s->materials[0].ior = s->materials[1].ior = 1;
    int at = 0;
    for (int i = 0; i < nfloor; i++) {
        s->polygons[i] = (vw_polygon){.id = i, .material = 0, .first = at, .count = counts[i]};
        for (int k = 0; k < counts[i]; k++, at++) {
            s->vertices[at][0] = xz[at][0], s->vertices[at][2] = xz[at][1];
            s->indices[at] = at;
        }
    }
    const double em[4][3] = {{0.4, 1.5, 0.4}, {1.6, 1.5, 0.4}, {1.6, 1.5, 1.6}, {0.4, 1.5, 1.6}};
    s->polygons[nfloor] = (vw_polygon){.id = nfloor, .material = 1, .first = at, .count = 4};
    for (int k = 0; k < 4; k++, at++) {
        memcpy(s->vertices[at], em[k], sizeof em[k]);
        s->indices[at] = at;
    }
    return s;
}

/* Is (x, z) inside the floor polygon xz[0..n) or within tol of its boundary? */
static int inside_floor(const double (*xz)[2], int n, double x, double z, double tol)
{
    int in = 0;
    for (int i = 0, j = n - 1; i < n; j = i++) {
        const double *a = xz[j], *b = xz[i];
        double ex = b[0] - a[0], ez = b[1] - a[1], l2 = ex * ex + ez * ez;
        double t = l2 > 0 ? ((x - a[0]) * ex + (z - a[1]) * ez) / l2 : 0;
        t = t < 0 ? 0 : t > 1 ? 1 : t;
        double dx = a[0] + t * ex - x, dz = a[1] + t * ez - z;
        if (dx * dx + dz * dz <= tol * tol) return 1;
        if ((a[1] > z) != (b[1] > z) && x < a[0] + (z - a[1]) / (b[1] - a[1]) * ex) in = !in;
    }
    return in;
}

/* Area-weighted radiosity (channel 0) of floor polygons 0..nfloor-1. */
static double floor_B(const result *r, int nfloor)
{
    double ba = 0, a = 0;
    for (int i = 0; i < nfloor; i++) ba += r->B[i][0] * r->area[i], a += r->area[i];
    return ba / a;
}

/* Concave floors: an L whose inner corner lies inside a patch (6 corners) and a gear of
   12 teeth (48 corners, more than a piece holds, so it used to be fanned in chunks).
   Every piece must be convex (the rasterisers fill a polygon by its edge functions),
   lie in the polygon and tile it; the solution must match the same floor given as
   convex polygons, agree across layouts and with the Gauss-Seidel reference, and
   balance its ledger. Before concave polygons were split into convex parts, the L's
   corner piece was concave (its element drawn as the intersection of its half planes:
   a dark spot at the corner) and the gear was meshed 3 % too large, filled in between
   its teeth. */
static int t_concave(void)
{
    enum { TEETH = 12, GN = 4 * TEETH };
    double lxz[6][2] = {{0, 0}, {0, 2}, {1.07, 2}, {1.07, 1.07}, {2, 1.07}, {2, 0}};
    double lsplit[8][2] = {{0, 0}, {0, 2}, {1.07, 2}, {1.07, 0}, {1.07, 0}, {1.07, 1.07}, {2, 1.07}, {2, 0}};
    int lsplit_n[2] = {4, 4};
    /* The L with its inner corner given twice: no three consecutive corners show its
       turn, and it was meshed as a convex polygon, its corner piece concave. */
    double l2xz[7][2] = {{0, 0}, {0, 2}, {1.07, 2}, {1.07, 1.07}, {1.07, 1.07}, {2, 1.07}, {2, 0}};
    /* The gear: tooth i spans angles (i + f) 2 pi / TEETH for f in 0 .. 0.5, radii 0.7 (root)
       and 1.0 (tip); corners in decreasing angle so the normal is +y. Split: the root
       polygon (2 TEETH corners, convex) and one quad per tooth. */
    double gxz[GN][2], gsplit[2 * TEETH + GN][2];
    int gsplit_n[1 + TEETH];
    const double rf[4][2] = {{0.7, 0}, {1.0, 0.15}, {1.0, 0.35}, {0.7, 0.5}};
    for (int i = 0; i < TEETH; i++)
        for (int k = 0; k < 4; k++) {
            double t = -2 * M_PI * (i + rf[k][1]) / TEETH;
            gxz[4 * i + k][0] = 1 + rf[k][0] * cos(t), gxz[4 * i + k][1] = 1 + rf[k][0] * sin(t);
        }
    gsplit_n[0] = 2 * TEETH;
    for (int i = 0; i < TEETH; i++) {
        memcpy(gsplit[2 * i], gxz[4 * i], sizeof gxz[0]);
        memcpy(gsplit[2 * i + 1], gxz[4 * i + 3], sizeof gxz[0]);
        memcpy(gsplit[2 * TEETH + 4 * i], gxz[4 * i], sizeof gxz[0] * 4);
        gsplit_n[1 + i] = 4;
    }
    double garea = 0;
    for (int i = 0; i < GN; i++) {
        const double *a = gxz[i], *b = gxz[(i + 1) % GN];
        garea += 0.5 * (a[1] * b[0] - a[0] * b[1]);
    }
    struct {
        const char *name;
        double (*xz)[2];
        int n;
        double area;
        double (*split)[2];
        int *split_n, nsplit;
    } sh[] = {
        {"L", lxz, 6, 2 * 2 - 0.93 * 0.93, lsplit, lsplit_n, 2},
        {"gear", gxz, GN, garea, gsplit, gsplit_n, 1 + TEETH},
        {"L2", l2xz, 7, 2 * 2 - 0.93 * 0.93, lsplit, lsplit_n, 2},
    };
    for (int si = 0; si < 3; si++) {
        vw_scene *sc = floor_scene((const double(*)[2])sh[si].xz, &sh[si].n, 1);
        vw_scene *cv = floor_scene((const double(*)[2])sh[si].split, sh[si].split_n, sh[si].nsplit);
        rad_options o;
        rad_options_init(&o);
        o.patch_size = 0.2;
        o.workers = 2;
        o.quiet = 1;
        o.sf = 1e-4;
        const char *layouts[] = {"1", "2x2x1", "3x3x1"};
        result r[3];
        for (int l = 0; l < 3; l++) {
            vw_layout_parse(layouts[l], o.dims, NULL, 0);
            /* The mesh: convex pieces inside the polygon that add up to its area. */
            vw_decomp *d;
            rad_mesh m;
            meshed(sc, "test", &o, &d, &m);
            double area = 0;
            int concave = 0, outside = 0;
            for (size_t i = 0; i < m.npieces; i++) {
                const rad_piece *pc = &m.pieces[i];
                if (pc->poly != 0) continue;
                area += pc->area;
                for (int k = 0; k < pc->nv; k++) {
                    /* The turn between the next corners elsewhere: a repeated corner
                       turns by 0 and would hide the turn at it. */
                    int kb = (k + 1) % pc->nv, kc;
                    while (kb != k && !memcmp(pc->v[kb], pc->v[k], sizeof pc->v[k])) kb = (kb + 1) % pc->nv;
                    for (kc = (kb + 1) % pc->nv; kc != k && !memcmp(pc->v[kc], pc->v[kb], sizeof pc->v[kb]);)
                        kc = (kc + 1) % pc->nv;
                    const double *a = pc->v[k], *b = pc->v[kb], *c = pc->v[kc];
                    double e1x = b[0] - a[0], e1z = b[2] - a[2], e2x = c[0] - b[0], e2z = c[2] - b[2];
                    /* +y normal: a left turn seen from above is e1 x e2 along +y. */
                    double turn = e1z * e2x - e1x * e2z;
                    concave += turn < -1e-12 * (fabs(e1x) + fabs(e1z)) * (fabs(e2x) + fabs(e2z));
                    outside += !inside_floor((const double(*)[2])sh[si].xz, sh[si].n, a[0], a[2], 1e-9);
                }
            }
            printf("%-4s %-5s: %zu pieces, area %.9f (polygon %.9f), %d concave corners, %d corners outside\n",
                   sh[si].name, layouts[l], m.npieces, area, sh[si].area, concave, outside);
            CHECK_NEAR(area, sh[si].area, 1e-9 * sh[si].area);
            CHECK(concave == 0);
            CHECK(outside == 0);
            rad_mesh_free(&m);
            vw_decomp_free(d);
            r[l] = solve(sc, o);
            CHECK(r[l].ledger.error < 1e-9);
            CHECK_NEAR(r[l].area[0], sh[si].area, 1e-9 * sh[si].area);
        }
        o.dims[0] = o.dims[1] = o.dims[2] = 1;
        result c = solve(cv, o);
        rad_reference ref;
        result g = reference(sc, o, &ref);
        double b = floor_B(&r[0], 1), bc = floor_B(&c, sh[si].nsplit), bg = floor_B(&g, 1);
        printf("%-4s floor B: 1 cell %.5f, 2x2x1 %.5f, 3x3x1 %.5f; as convex polygons %.5f; Gauss-Seidel %.5f\n",
               sh[si].name, b, floor_B(&r[1], 1), floor_B(&r[2], 1), bc, bg);
        CHECK_NEAR(floor_B(&r[1], 1), b, 0.01 * b);
        CHECK_NEAR(floor_B(&r[2], 1), b, 0.01 * b);
        CHECK_NEAR(bc, b, 0.01 * b);
        CHECK_NEAR(bg, b, 0.01 * b);
        for (int l = 0; l < 3; l++) result_free(&r[l]);
        result_free(&c), result_free(&g);
        rad_reference_free(&ref);
        vw_scene_free(sc), vw_scene_free(cv);
    }
    return 0;
}

/* Gauss-Seidel on the full matrix: the closed box gives sum B A = E / (1 - rho); on the
   Cornell box the progressive solution on one cell approaches it as sf falls (0.03 % at
   1e-5), and 2x2x2 at 1e-4 is within 1 %. */
static int t_reference(void)
{
    const float rho = 0.5f;
    vw_scene *sc = box_scene(rho, 1);
    rad_options o;
    rad_options_init(&o);
    o.patch_size = 0.25;
    o.workers = 2;
    rad_reference ref;
    result g = reference(sc, o, &ref);
    double total = 0;
    for (size_t i = 0; i < g.npoly; i++) total += g.B[i][0] * g.area[i];
    printf("box: Gauss-Seidel %d sweeps, sum B*A = %.6f (want 2)\n", ref.sweeps, total);
    CHECK_NEAR(total, 2.0, 0.01 * 2.0);
    rad_reference_free(&ref);
    result_free(&g);
    vw_scene_free(sc);

    sc = cornell();
    rad_options_init(&o);
    o.workers = 2;
    g = reference(sc, o, &ref);
    printf("cornell: %zu patches, form factors %.2f s, Gauss-Seidel %d sweeps %.3f s\n", ref.n, ref.ff_s,
           ref.sweeps, ref.solve_s);
    double last = 1;
    const double sfs[] = {1e-3, 1e-4, 1e-5};
    for (int i = 0; i < 3; i++) {
        o.sf = sfs[i];
        for (int l = 0; l < 1 + (i == 1); l++) {
            vw_layout_parse(l ? "2x2x2" : "1", o.dims, NULL, 0);
            result r = solve(sc, o);
            double e = rel_rms(&r, &g);
            printf("  progressive sf %.0e, %-5s: %lld shots, relative RMS vs Gauss-Seidel %.3f%%\n", sfs[i],
                   l ? "2x2x2" : "1", (long long)r.shots, 100 * e);
            if (l == 0) {
                CHECK(e < last);
                last = e;
            } else {
                CHECK(e <= 0.01);
            }
            result_free(&r);
        }
    }
    CHECK(last <= 0.002);
    rad_reference_free(&ref);
    result_free(&g);
    vw_scene_free(sc);
    return 0;
}

/* reference SCENE OUT.csv PATCH_SIZE RES ELEMENTS: the Gauss-Seidel reference of a scene
   file as a --csv file (the bench compares the progressive solution with it). */
static int t_reference_file(const char *path, const char *csv, double ps, int res, int elems)
{
    vw_scene *sc = NULL;
    char err[512] = "";
    if (vw_scene_read_file(path, &sc, err, sizeof err) != VW_OK) {
        fprintf(stderr, "%s\n", err);
        return 2;
    }
    rad_options o;
    rad_options_init(&o);
    o.quiet = 1;
    o.patch_size = ps;
    o.res = res;
    o.elem_split = elems;
    vw_box wb = rad_world_box(sc);
    vw_decomp *d;
    rad_mesh m;
    meshed(sc, path, &o, &d, &m);
    rad_reference ref;
    vw_status st = rad_reference_solve(&m, &wb, o.res, 1e-13, 100000, &ref, err, sizeof err);
    if (st != VW_OK) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    rad_elem_result *e = rad_reference_elements(&m, &ref);
    CHECK(e != NULL);
    CHECK(rad_write_csv(csv, &m, sc, e, ref.n, err, sizeof err) == VW_OK);
    printf("{\"patches\": %zu, \"matrix_bytes\": %zu, \"form_factors_s\": %.6f, \"gauss_seidel_s\": %.6f, "
           "\"sweeps\": %d, \"change\": %.3g}\n",
           ref.n, ref.matrix_bytes, ref.ff_s, ref.solve_s, ref.sweeps, ref.change);
    free(e);
    rad_reference_free(&ref);
    rad_mesh_free(&m);
    vw_decomp_free(d);
    vw_scene_free(sc);
    return 0;
}

/* Writes a generated scene as NFF (the CLI tests read it). */
static int t_gen(const char *name, const char *path)
{
    vw_scene *s = NULL;
    char err[256];
    CHECK(vw_gen(name, NULL, &s, err, sizeof err) == VW_OK);
    CHECK(vw_scene_write_nff_file(s, path, err, sizeof err) == VW_OK);
    vw_scene_free(s);
    return 0;
}

/* Area-weighted relative RMS between the radiosities of two --csv files. */
static int t_csvcmp(const char *a, const char *b, double tol)
{
    FILE *fa = fopen(a, "r"), *fb = fopen(b, "r");
    CHECK(fa && fb);
    char la[1024], lb[1024];
    double num = 0, den = 0;
    int rows = 0;
    CHECK(fgets(la, sizeof la, fa) && fgets(lb, sizeof lb, fb));
    while (fgets(la, sizeof la, fa)) {
        CHECK(fgets(lb, sizeof lb, fb));
        int ida, idb;
        double x[10], y[10];
        CHECK(sscanf(la, "%d,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &ida, &x[0], &x[1], &x[2], &x[3], &x[4],
                     &x[5], &x[6], &x[7], &x[8], &x[9]) == 11);
        CHECK(sscanf(lb, "%d,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &idb, &y[0], &y[1], &y[2], &y[3], &y[4],
                     &y[5], &y[6], &y[7], &y[8], &y[9]) == 11);
        CHECK_EQ_INT(ida, idb);
        for (int k = 7; k < 10; k++) {
            num += x[0] * (x[k] - y[k]) * (x[k] - y[k]);
            den += x[0] * x[k] * x[k];
        }
        rows++;
    }
    fclose(fa), fclose(fb);
    double e = sqrt(num / den);
    printf("%d polygons, relative RMS %.4f%%\n", rows, 100 * e);
    CHECK(rows > 0);
    CHECK(e <= tol);
    return 0;
}

/* The pixels of a .pfm picture (width x height x 3 floats, little endian, as
   rad_write_image writes it); NULL when it is not one. */
static float *read_pfm(const char *path, int *w, int *h)
{
    FILE *f = fopen(path, "rb");
    float *px = NULL;
    double scale;
    if (f && fscanf(f, "PF %d %d %lf", w, h, &scale) == 3 && fgetc(f) == '\n' && *w > 0 && *h > 0 &&
        (px = malloc(sizeof *px * 3 * (size_t)*w * (size_t)*h)) &&
        fread(px, sizeof *px, 3 * (size_t)*w * (size_t)*h, f) != 3 * (size_t)*w * (size_t)*h) {
        free(px);
        px = NULL;
    }
    if (f) fclose(f);
    return px;
}

/* pfmcmp A B MINLIT TOL: A has at least MINLIT of its pixels lit (some channel above 0),
   and B differs from it by at most TOL (mean absolute difference over mean value). */
static int t_pfmcmp(const char *a, const char *b, double minlit, double tol)
{
    int wa, ha, wb, hb;
    float *x = read_pfm(a, &wa, &ha), *y = read_pfm(b, &wb, &hb);
    CHECK(x && y);
    CHECK_EQ_INT(wa, wb);
    CHECK_EQ_INT(ha, hb);
    size_t n = (size_t)wa * (size_t)ha, lit = 0;
    double diff = 0, sum = 0;
    for (size_t i = 0; i < n; i++) {
        lit += x[3 * i] > 0 || x[3 * i + 1] > 0 || x[3 * i + 2] > 0;
        for (int k = 0; k < 3; k++) diff += fabs(x[3 * i + k] - y[3 * i + k]), sum += fabs(x[3 * i + k]);
    }
    double rel = sum > 0 ? diff / sum : 0;
    printf("%s: %.3f of the pixels lit; %s differs by %.4f (relative)\n", a, (double)lit / n, b, rel);
    free(x), free(y);
    CHECK((double)lit / n >= minlit);
    CHECK(rel <= tol);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_radiosity ffsum|parallel|perpendicular|box|furnace|twosided|layouts|checkpoint|subdivide|concave|placement|manycells|reference|gen NAME FILE\n");
        return 2;
    }
    const char *t = argv[1];
    if (!strcmp(t, "ffsum")) return t_ffsum();
    if (!strcmp(t, "parallel")) return t_parallel();
    if (!strcmp(t, "perpendicular")) return t_perpendicular();
    if (!strcmp(t, "box")) return t_box();
    if (!strcmp(t, "furnace")) return t_furnace();
    if (!strcmp(t, "twosided")) return t_twosided() || t_twosided_image();
    if (!strcmp(t, "layouts")) return t_layouts();
    if (!strcmp(t, "checkpoint")) return t_checkpoint();
    if (!strcmp(t, "subdivide")) return t_subdivide();
    if (!strcmp(t, "concave")) return t_concave();
    if (!strcmp(t, "placement")) return t_placement();
    if (!strcmp(t, "manycells")) return t_manycells();
    if (!strcmp(t, "reference") && argc == 2) return t_reference();
    if (!strcmp(t, "reference") && argc == 7)
        return t_reference_file(argv[2], argv[3], atof(argv[4]), atoi(argv[5]), atoi(argv[6]));
    if (!strcmp(t, "gen") && argc == 4) return t_gen(argv[2], argv[3]);
    if (!strcmp(t, "csvcmp") && argc == 5) return t_csvcmp(argv[2], argv[3], atof(argv[4]));
    if (!strcmp(t, "pfmcmp") && argc == 6) return t_pfmcmp(argv[2], argv[3], atof(argv[4]), atof(argv[5]));
    fprintf(stderr, "unknown test '%s'\n", t);
    return 2;
}
