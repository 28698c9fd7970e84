/* test_dynamic.c - tests of the dynamic-scene handler: the pairwise tests on hand-made
 * cases, placement after every edit (brute force over all cells), distributed batch
 * decisions against the one-at-a-time O(n^2) reference, tunnelling, and a frame after
 * edits against a render of the edited scene from scratch (bit for bit).
 * Usage: test_dynamic primitives|placement|decisions|tunnel|swept|frame [seeds] [--workers W]
 * The same binary runs under mpirun (placement, decisions, frame).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include "raytrace/anim.h"
#include "vw_test.h"
#include "vwalls/vwalls.h"

static uint64_t rng_state = 1;
static double urand(void)
{
    rng_state ^= rng_state << 13, rng_state ^= rng_state >> 7, rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) / 9007199254740992.0;
}
static double uni(double a, double b) { return a + (b - a) * urand(); }

/* ---- hand-made cases ------------------------------------------------------------------- */

static vw_shape sphere(double x, double y, double z, double r)
{
    vw_shape s;
    memset(&s, 0, sizeof s);
    s.kind = VW_SHAPE_SPHERE;
    s.p[0][0] = x, s.p[0][1] = y, s.p[0][2] = z;
    s.r = r;
    return s;
}
static vw_shape tri(const double a[3], const double b[3], const double c[3])
{
    vw_shape s;
    memset(&s, 0, sizeof s);
    s.kind = VW_SHAPE_TRIANGLE;
    memcpy(s.p[0], a, 24), memcpy(s.p[1], b, 24), memcpy(s.p[2], c, 24);
    return s;
}

static void test_primitives(void)
{
    double tol = 1e-12;
    vw_shape a = sphere(0, 0, 0, 1), b = sphere(1.5, 0, 0, 1), c = sphere(2, 0, 0, 1);
    CHECK(vw_shape_collide(&a, NULL, &b, tol));
    CHECK(!vw_shape_collide(&a, NULL, &c, tol)); /* touching is not colliding */
    /* The ground: a big triangle in z = 0. */
    const double g0[3] = {-10, -10, 0}, g1[3] = {10, -10, 0}, g2[3] = {0, 10, 0};
    vw_shape ground = tri(g0, g1, g2);
    vw_shape above = sphere(0, 0, 1, 1), into = sphere(0, 0, 0.5, 1), far = sphere(0, 0, 5, 0.1);
    CHECK(!vw_shape_collide(&above, NULL, &ground, tol));
    CHECK(vw_shape_collide(&into, NULL, &ground, tol));
    /* A small sphere jumping through the ground: endpoints free, path not. */
    double d[3] = {0, 0, -10};
    vw_shape end = sphere(0, 0, -5, 0.1);
    CHECK(!vw_shape_collide(&end, NULL, &ground, tol));
    CHECK(vw_shape_collide(&far, d, &ground, tol));
    CHECK(vw_shape_collide(&ground, (double[3]){0, 0, 10}, &far, tol)); /* relative motion */
    /* Grazing paths: passing at exactly the touching distance is free, a hair closer is
       not (the ground; a sphere passed at the sum of the radii). */
    vw_shape graze = sphere(-5, -5, 1, 1);
    CHECK(!vw_shape_collide(&graze, (double[3]){10, 10, 0}, &ground, tol));
    graze.p[0][2] = 1 - 1e-9;
    CHECK(vw_shape_collide(&graze, (double[3]){10, 10, 0}, &ground, tol));
    vw_shape pass = sphere(-5, 2, 0, 1);
    CHECK(!vw_shape_collide(&pass, (double[3]){10, 0, 0}, &a, tol));
    pass.p[0][1] = 2 - 1e-9;
    CHECK(vw_shape_collide(&pass, (double[3]){10, 0, 0}, &a, tol));
    /* Triangles: crossing, touching at an edge, coplanar overlapping, coplanar apart. */
    const double h0[3] = {0, 0, -1}, h1[3] = {0, 0, 1}, h2[3] = {1, 0, 0};
    vw_shape cross_t = tri(h0, h1, h2);
    CHECK(vw_shape_collide(&cross_t, NULL, &ground, tol));
    const double k0[3] = {0, 0, 0}, k1[3] = {0, 0, 1}, k2[3] = {1, 0, 1};
    vw_shape stand = tri(k0, k1, k2); /* touches the ground at one vertex */
    CHECK(!vw_shape_collide(&stand, NULL, &ground, tol));
    const double p0[3] = {0, 0, 0}, p1[3] = {2, 0, 0}, p2[3] = {0, 2, 0};
    const double q0[3] = {1, 1, 0}, q1[3] = {-1, 1, 0}, q2[3] = {1, -1, 0};
    vw_shape P = tri(p0, p1, p2), Q = tri(q0, q1, q2);
    CHECK(vw_shape_collide(&P, NULL, &Q, tol));
    const double r0[3] = {3, 3, 0}, r1[3] = {4, 3, 0}, r2[3] = {3, 4, 0};
    vw_shape R = tri(r0, r1, r2);
    CHECK(!vw_shape_collide(&P, NULL, &R, tol));
    /* A swept triangle (prism) through a thin wall, ends on both sides. */
    const double w0[3] = {5, -5, -5}, w1[3] = {5, 5, -5}, w2[3] = {5, 0, 5};
    vw_shape wall = tri(w0, w1, w2);
    const double m0[3] = {0, 0, 0}, m1[3] = {1, 0, 0}, m2[3] = {0, 1, 0};
    vw_shape mover = tri(m0, m1, m2);
    CHECK(!vw_shape_collide(&mover, NULL, &wall, tol));
    CHECK(vw_shape_collide(&mover, (double[3]){10, 0, 0}, &wall, tol));
    CHECK(!vw_shape_collide(&mover, (double[3]){0, 10, 0}, &wall, tol));
    /* A degenerate triangle whose first two corners coincide (a polygon with a repeated
       vertex) is the segment to its third: a sphere on it collides, at rest and swept
       through it (the distance was 0/0, a NaN, so neither was ever a hit). */
    const double s0[3] = {-2, 0, 0}, s2[3] = {2, 0, 0};
    vw_shape seg = tri(s0, s0, s2);
    vw_shape on = sphere(0, 0, 0.2, 0.5), over = sphere(0.5, 0, 3, 0.1);
    CHECK(vw_shape_collide(&on, NULL, &seg, tol));
    CHECK(vw_shape_collide(&seg, NULL, &on, tol));
    CHECK(vw_shape_collide(&over, (double[3]){0, 0, -6}, &seg, tol));
    CHECK(vw_shape_collide(&seg, (double[3]){0, 0, 6}, &over, tol));
    CHECK(!vw_shape_collide(&over, (double[3]){0, 0, -2}, &seg, tol));
    /* Boxes (cones) conservatively. */
    vw_shape box;
    memset(&box, 0, sizeof box);
    box.kind = VW_SHAPE_BOX;
    box.p[1][0] = box.p[1][1] = box.p[1][2] = 1;
    vw_shape s_in = sphere(1.2, 0.5, 0.5, 0.3), s_out = sphere(3, 0.5, 0.5, 0.3);
    CHECK(vw_shape_collide(&s_in, NULL, &box, tol));
    CHECK(!vw_shape_collide(&s_out, NULL, &box, tol));
    CHECK(vw_shape_collide(&s_out, (double[3]){-5, 0, 0}, &box, tol));
    /* The parser leaves the caller's strtok alone: a script cut into lines with strtok
       is parsed to its end (it once stopped after the first line, its words cut by
       strtok, whose state then pointed into the parser's own buffer). */
    char script[] = "move 1 1 0 0\nmoveto 2 0 0 0\n\t remove   3 # gone\n";
    const vw_edit_op want[] = {VW_EDIT_MOVE, VW_EDIT_MOVETO, VW_EDIT_REMOVE};
    int lines = 0;
    for (char *line = strtok(script, "\n"); line; line = strtok(NULL, "\n")) {
        vw_edit e;
        char err[128];
        CHECK(lines < 3);
        CHECK(vw_edit_parse(line, "s", lines + 1, &e, err, sizeof err) == VW_OK);
        CHECK_EQ_INT(e.op, want[lines]);
        CHECK_EQ_INT(e.id, lines + 1);
        lines++;
    }
    CHECK_EQ_INT(lines, 3);
}

/* ---- random scenes and scripts --------------------------------------------------------- */

/* Spheres, triangles, a quad and a cone in [0,10]^3, as NFF text. */
static vw_scene *random_scene(int n)
{
    size_t cap = (size_t)n * 200 + 4096, len = 0;
    char *t = malloc(cap);
    len += (size_t)snprintf(t + len, cap - len,
                            "v\nfrom 5 -20 8\nat 5 5 5\nup 0 0 1\nangle 40\nhither 0.01\n"
                            "resolution 48 48\nb 0.1 0.2 0.3\nl 5 -5 20\nl -5 5 15 0.5 0.5 0.5\n"
                            "f 0.8 0.5 0.3 0.7 0.3 10 0 1\n");
    for (int i = 0; i < n; i++) {
        double x = uni(0.5, 9.5), y = uni(0.5, 9.5), z = uni(0.5, 9.5);
        int k = i % 7;
        if (i == 3) {
            len += (size_t)snprintf(t + len, cap - len, "c\n%.17g %.17g %.17g 0.3\n%.17g %.17g %.17g 0.1\n",
                                    x, y, z, x + 0.2, y + 0.5, z + 0.3);
        } else if (i == 5) {
            len += (size_t)snprintf(t + len, cap - len, "f 0.3 0.8 0.3 0.5 0.5 5 0 1\n"
                                    "p 4\n%.17g %.17g %.17g\n%.17g %.17g %.17g\n%.17g %.17g %.17g\n%.17g %.17g %.17g\n",
                                    x, y, z, x + 1, y, z, x + 1, y + 1, z, x, y + 1, z);
        } else if (k == 1 || k == 4) {
            len += (size_t)snprintf(t + len, cap - len, "p 3\n");
            for (int v = 0; v < 3; v++)
                len += (size_t)snprintf(t + len, cap - len, "%.17g %.17g %.17g\n", x + uni(-0.6, 0.6),
                                        y + uni(-0.6, 0.6), z + uni(-0.6, 0.6));
        } else {
            len += (size_t)snprintf(t + len, cap - len, "s %.17g %.17g %.17g %.17g\n", x, y, z, uni(0.1, 0.5));
        }
    }
    vw_scene *s = NULL;
    char err[256];
    vw_status st = vw_scene_read_nff("random", t, len, &s, err, sizeof err);
    if (st != VW_OK) fprintf(stderr, "%s\n", err);
    CHECK(st == VW_OK);
    free(t);
    return s;
}

/* A random edit of an object that may or may not exist. */
static vw_edit random_edit(int nids, int line)
{
    vw_edit e;
    memset(&e, 0, sizeof e);
    e.line = line;
    e.material = -1;
    double u = urand();
    e.id = (int)(urand() * (nids + 2)); /* sometimes no such object */
    if (u < 0.45) {
        e.op = VW_EDIT_MOVE;
        double reach = urand() < 0.2 ? 4 : 0.8;
        for (int k = 0; k < 3; k++) e.v[k] = uni(-reach, reach);
    } else if (u < 0.6) {
        e.op = VW_EDIT_MOVETO;
        for (int k = 0; k < 3; k++) e.v[k] = uni(-1, 11); /* sometimes outside the world */
    } else if (u < 0.75) {
        e.op = VW_EDIT_ROTATE;
        for (int k = 0; k < 3; k++) e.v[k] = uni(-1, 1);
        e.v[3] = uni(-180, 180);
    } else if (u < 0.88) {
        e.op = VW_EDIT_ADD;
        for (int k = 0; k < 3; k++) e.v[k] = uni(0.5, 9.5);
        e.v[3] = uni(0.05, 0.4);
        e.material = urand() < 0.5 ? 0 : -1;
    } else {
        e.op = VW_EDIT_REMOVE;
    }
    return e;
}

static int world_of(vw_box *w)
{
    for (int k = 0; k < 3; k++) w->lo[k] = -0.5, w->hi[k] = 10.5;
    return 0;
}

/* Every slot of world w is held by exactly the cells its bounds (by bounds_fn) overlap,
   each cell box widened by the world's placement pad (1e-9 of the largest extent, the
   rule world.c states), found by brute force over all cells. */
typedef void (*bounds_fn)(const void *obj, vw_box *b, void *user);
static void check_placement(vw_world *w, size_t nslots, const void *objs, size_t osz, bounds_fn fn,
                            void *user)
{
    const vw_decomp *d = vw_world_decomp(w);
    int nc = vw_decomp_cell_count(d);
    vw_box wb = vw_decomp_world(d);
    double ext = 0;
    for (int k = 0; k < 3; k++) ext = fmax(ext, wb.hi[k] - wb.lo[k]);
    double pad = ext * 1e-9;
    int *got = malloc(sizeof(int) * (size_t)nc);
    for (size_t s = 0; s < nslots; s++) {
        vw_box b, f;
        fn((const char *)objs + s * osz, &b, user);
        vw_decomp_box_to_frame(d, &b, &f);
        int n = vw_world_cells_of_object(w, s, got, nc);
        int m = 0;
        for (int c = 0; c < nc; c++) {
            vw_box cb = vw_decomp_cell_box(d, c);
            int ov = 1;
            for (int k = 0; k < 3; k++)
                if (f.hi[k] < cb.lo[k] - pad || f.lo[k] > cb.hi[k] + pad) ov = 0;
            if (!ov) continue;
            if (m >= n || got[m] != c) {
                fprintf(stderr, "slot %zu: expected in cell %d, held by %d cells\n", s, c, n);
                CHECK(0);
            }
            m++;
        }
        CHECK_EQ_INT(m, n);
    }
    free(got);
}

static void shape_bounds_fn(const void *o, vw_box *b, void *user)
{
    (void)user;
    vw_shape_bounds(o, NULL, b);
}
static void rt_bounds_fn(const void *o, vw_box *b, void *user)
{
    rt_object_bounds(o, *(const double *)user, b);
}

/* The collider's shapes, read back slot by slot through the dynscene's own mirror: the
   scene is re-derived and compared against a fresh dynscene would be circular, so the
   shapes come from a brute-force dynscene run in lock step (same decisions). */
static void test_placement(int seeds, int workers)
{
    const char *layouts[] = {"1", "2x2x1", "3x2x2", "4x1x3"};
    for (int seed = 1; seed <= seeds; seed++) {
        rng_state = 0x9e3779b97f4a7c15ull * (uint64_t)seed + 7;
        int dims[3];
        char err[512];
        vw_layout_parse(layouts[seed % 4], dims, err, sizeof err);
        rt_anim_params p;
        memset(&p, 0, sizeof p);
        p.width = p.height = 24;
        memcpy(p.dims, dims, sizeof dims);
        p.workers = workers;
        p.margin = 0.05;
        rt_anim *a;
        CHECK(rt_anim_create(random_scene(60), &p, &a, err, sizeof err) == VW_OK);
        vw_dynscene *ds = rt_anim_dynscene(a);
        rt_job *job = rt_anim_job(a);
        double bpad = rt_job_shared(job)->bpad;
        for (int step = 0; step < 25; step++) {
            vw_edit e[6];
            vw_result r[6];
            int ne = 1 + (int)(urand() * 6);
            for (int i = 0; i < ne; i++) e[i] = random_edit(vw_dynscene_ids(ds), i + 1);
            rt_anim_stats st;
            memset(&st, 0, sizeof st);
            CHECK(rt_anim_apply(a, e, (size_t)ne, step % 3 != 0, step % 2, r, &st, err,
                                sizeof err) == VW_OK);
            if (step % 5 == 4) CHECK(rt_anim_render(a, NULL, err, sizeof err) == VW_OK);
            /* The collider world: its shapes are the dynscene's slots. */
            vw_world *cw = vw_collider_world(vw_dynscene_collider(ds));
            size_t nslots = 0;
            for (int id = 0; id < vw_dynscene_ids(ds); id++) {
                size_t f, n;
                vw_dynscene_slots(ds, id, &f, &n);
                if (f + n > nslots) nslots = f + n;
            }
            /* Rebuild the expected shapes from the scene, independently of the collider. */
            vw_shape *sh = calloc(nslots ? nslots : 1, sizeof *sh);
            rt_object *ro = calloc(nslots ? nslots : 1, sizeof *ro);
            const vw_scene *sc = vw_dynscene_scene(ds);
            for (int id = 0; id < vw_dynscene_ids(ds); id++) {
                size_t f, n;
                vw_dynscene_slots(ds, id, &f, &n);
                vw_prim_kind k;
                size_t idx;
                if (!vw_dynscene_alive(ds, id) || vw_scene_find_object(sc, id, &k, &idx) != VW_OK) {
                    for (size_t j = 0; j < n; j++) sh[f + j].kind = VW_SHAPE_NONE, rt_object_empty(&ro[f + j]);
                    continue;
                }
                CHECK_EQ_INT(rt_object_records(sc, k, idx, ro + f), n);
                for (size_t j = 0; j < n; j++) {
                    /* The collision shape's bounds: the record's bounds without pad
                       (spheres, triangles and the cone box are the same boxes). */
                    vw_box b;
                    if (ro[f + j].id < 0) {
                        sh[f + j].kind = VW_SHAPE_NONE;
                        continue;
                    }
                    rt_object_bounds(&ro[f + j], 0, &b);
                    sh[f + j].kind = VW_SHAPE_BOX;
                    memcpy(sh[f + j].p[0], b.lo, 24);
                    memcpy(sh[f + j].p[1], b.hi, 24);
                }
            }
            check_placement(cw, nslots, sh, sizeof *sh, shape_bounds_fn, NULL);
            check_placement(rt_job_world(job), nslots, ro, sizeof *ro, rt_bounds_fn, &bpad);
            free(sh);
            free(ro);
        }
        rt_anim_free(a);
    }
}

/* Distributed batches against the one-at-a-time brute-force reference. */
static void test_decisions(int seeds, int workers)
{
    const char *layouts[] = {"2x2x2", "1", "3x1x2", "4x4x1"};
    for (int seed = 1; seed <= seeds; seed++) {
        rng_state = 0x2545f4914f6cdd1dull * (uint64_t)seed + 11;
        int n = 40 + seed * 10;
        vw_scene *s1 = random_scene(n);
        uint64_t keep = rng_state;
        rng_state = 0x2545f4914f6cdd1dull * (uint64_t)seed + 11;
        vw_scene *s2 = random_scene(n);
        CHECK(keep == rng_state);
        rng_state = 0x2545f4914f6cdd1dull * (uint64_t)seed + 11;
        vw_scene *s3 = random_scene(n); /* brute force, whole batches (--brute-force) */
        CHECK(keep == rng_state);
        vw_box world;
        world_of(&world);
        int dims[3];
        char err[512];
        /* "1" under mpirun too: the collider divides its own copy of the cells until
           every process has a contact mailbox (it once refused to start). */
        vw_layout_parse(layouts[seed % 4], dims, err, sizeof err);
        vw_decomp *d;
        CHECK(vw_decomp_create_grid(&world, dims, &d) == VW_OK);
        vw_config cfg;
        vw_config_init(&cfg);
        cfg.workers = workers;
        vw_dynscene_params p = {d, &cfg, 0, 0};
        vw_dynscene *dist, *ref, *bref;
        CHECK(vw_dynscene_create(s1, &p, &dist, err, sizeof err) == VW_OK);
        p.brute_force = 1;
        CHECK(vw_dynscene_create(s2, &p, &ref, err, sizeof err) == VW_OK);
        CHECK(vw_dynscene_create(s3, &p, &bref, err, sizeof err) == VW_OK);
        size_t counts[4] = {0, 0, 0, 0};
        for (int round = 0; round < 12; round++) {
            int check = round % 4 != 3, sweep = round % 2;
            int ne = 1 + (int)(urand() * 40);
            vw_edit *e = calloc((size_t)ne, sizeof *e);
            vw_result *r1 = calloc((size_t)ne, sizeof *r1), *r2 = calloc((size_t)ne, sizeof *r2);
            vw_result *r3 = calloc((size_t)ne, sizeof *r3);
            for (int i = 0; i < ne; i++) {
                e[i] = random_edit(vw_dynscene_ids(dist), i + 1);
                /* Repeat an earlier id now and then: decided in order too. */
                if (i > 0 && urand() < 0.1 && e[i].op != VW_EDIT_ADD) e[i].id = e[i - 1].id;
            }
            int *ch;
            size_t nch;
            CHECK(vw_dynscene_apply(dist, e, (size_t)ne, check, sweep, r1, &ch, &nch) == VW_OK);
            free(ch);
            CHECK(vw_dynscene_apply(bref, e, (size_t)ne, check, sweep, r3, &ch, &nch) == VW_OK);
            free(ch);
            for (int i = 0; i < ne; i++) { /* the reference: one edit at a time */
                CHECK(vw_dynscene_apply(ref, &e[i], 1, check, sweep, &r2[i], &ch, &nch) == VW_OK);
                free(ch);
            }
            for (int i = 0; i < ne; i++) {
                if (r1[i].outcome != r2[i].outcome || r1[i].obstacle != r2[i].obstacle || r1[i].id != r2[i].id)
                    fprintf(stderr, "seed %d round %d edit %d (op %d id %d): %d/%d vs reference %d/%d\n", seed,
                            round, i, e[i].op, e[i].id, r1[i].outcome, r1[i].obstacle, r2[i].outcome,
                            r2[i].obstacle);
                CHECK_EQ_INT(r1[i].outcome, r2[i].outcome);
                CHECK_EQ_INT(r1[i].obstacle, r2[i].obstacle);
                CHECK_EQ_INT(r1[i].id, r2[i].id);
                CHECK_EQ_INT(r3[i].outcome, r2[i].outcome);
                CHECK_EQ_INT(r3[i].obstacle, r2[i].obstacle);
                counts[r1[i].outcome]++;
            }
            free(e);
            free(r1);
            free(r2);
            free(r3);
        }
        if (vw_engine_rank() == 0)
            printf("seed %d: accepted %zu, collisions %zu, sweeps %zu, invalid %zu\n", seed, counts[0],
                   counts[1], counts[2], counts[3]);
        vw_dynscene_free(dist);
        vw_dynscene_free(ref);
        vw_dynscene_free(bref);
        vw_decomp_free(d);
    }
}

/* A sphere sunk 0.1 into a floor is moved off it sideways, sweep on: the floor is an
   object it already interpenetrates at its start, so the floor does not count for the
   sweep, whether the floor is one triangle or a quad of two (the mover sunk in the
   first, its path over the second): the rule was applied per triangle, and the quad
   rejected the move ("would pass through object 0") where the triangle accepted it. */
static void test_sunk(const vw_decomp *d, const vw_config *cfg)
{
    static const char *const floors[] = {"p 4\n0 0 0\n2 0 0\n2 1 0\n0 1 0\n",
                                         "p 3\n0 0 0\n4 0 0\n0 2 0\n"};
    for (int f = 0; f < 2; f++)
        for (int brute = 0; brute < 2; brute++) {
            char nff[512], err[256];
            snprintf(nff, sizeof nff, "v\nfrom 0 -10 0\nat 0 0 0\nup 0 0 1\nangle 40\n"
                     "hither 0.01\nresolution 16 16\nb 0 0 0\nl 0 -5 5\n"
                     "f 1 1 1 1 0 0 0 1\n%ss 1.5 0.2 0.4 0.5\ns 4 4 4 0.1\n", floors[f]);
            vw_scene *s;
            CHECK(vw_scene_read_nff("sunk", nff, strlen(nff), &s, err, sizeof err) == VW_OK);
            vw_dynscene_params p = {d, cfg, 0, brute};
            vw_dynscene *ds;
            CHECK(vw_dynscene_create(s, &p, &ds, err, sizeof err) == VW_OK);
            vw_edit e;
            vw_result r;
            int *ch;
            size_t nch;
            CHECK(vw_edit_parse("move 1 -3 0.6 0", "t", 1, &e, err, sizeof err) == VW_OK);
            CHECK(vw_dynscene_apply(ds, &e, 1, 1, 1, &r, &ch, &nch) == VW_OK);
            free(ch);
            EXPECT(r.outcome == VW_OUT_ACCEPTED, "floor %s, brute %d: outcome %d (obstacle %d)",
                   f ? "triangle" : "quad", brute, (int)r.outcome, r.obstacle);
            /* Back under the floor through it, from off it: that is a sweep hit. */
            CHECK(vw_edit_parse("moveto 1 1 0.5 -1", "t", 2, &e, err, sizeof err) == VW_OK);
            CHECK(vw_dynscene_apply(ds, &e, 1, 1, 1, &r, &ch, &nch) == VW_OK);
            free(ch);
            EXPECT(r.outcome == VW_OUT_SWEEP && r.obstacle == 0, "floor %s, brute %d: outcome "
                   "%d (obstacle %d), expected a sweep hit on 0", f ? "triangle" : "quad",
                   brute, (int)r.outcome, r.obstacle);
            vw_dynscene_free(ds);
        }
}

/* The brute-force reference decides a batch of several edits as the cells do. A quad
   (two triangles) starts sunk in two spheres, each in one triangle, and slides along
   its plane, its other triangle passing under each sphere as deep as the first starts:
   both spheres are objects it interpenetrates at its start and goes no deeper into, so
   the move is accepted. A second edit of the batch has a contact too. The reference
   merged the (edit, obstacle) contacts by swapping the list's last one (the second
   edit's) into the hole, which ended the scan of the first edit's contacts: sphere 1's
   START and SWEEP stayed apart, and the move was "would pass through object 1" by
   brute force alone (vwalls animate --brute-force on the script "sweep on / move 2 3 0
   0 / move 3 0 0 0.5"). */
static void test_brute_batch(const vw_decomp *d, const vw_config *cfg)
{
    const char *nff = "v\nfrom 0 -20 0\nat 0 0 0\nup 0 0 1\nangle 40\nhither 0.01\n"
                      "resolution 8 8\nb 0 0 0\nl 0 -5 5\nf 1 1 1 1 0 0 0 1\n"
                      "s 1.2 0.8 0.25 0.3\ns 1.7 1.3 0.25 0.3\n"  /* ids 0, 1 */
                      "p 4\n0 0 0\n2 0 0\n2 2 0\n0 2 0\n"         /* id 2: the quad */
                      "s 4 4 2 0.5\ns 4 4 3.2 0.5\n";             /* ids 3, 4 */
    for (int brute = 0; brute < 2; brute++) {
        char err[256];
        vw_scene *s;
        CHECK(vw_scene_read_nff("batch", nff, strlen(nff), &s, err, sizeof err) == VW_OK);
        vw_dynscene_params p = {d, cfg, 0, brute};
        vw_dynscene *ds;
        CHECK(vw_dynscene_create(s, &p, &ds, err, sizeof err) == VW_OK);
        vw_edit e[2];
        vw_result r[2];
        int *ch;
        size_t nch;
        CHECK(vw_edit_parse("move 2 3 0 0", "t", 1, &e[0], err, sizeof err) == VW_OK);
        CHECK(vw_edit_parse("move 3 0 0 0.5", "t", 2, &e[1], err, sizeof err) == VW_OK);
        CHECK(vw_dynscene_apply(ds, e, 2, 1, 1, r, &ch, &nch) == VW_OK);
        free(ch);
        EXPECT(r[0].outcome == VW_OUT_ACCEPTED, "brute %d: the sunk quad's move: outcome %d "
               "(obstacle %d), expected accepted", brute, (int)r[0].outcome, r[0].obstacle);
        EXPECT(r[1].outcome == VW_OUT_COLLISION && r[1].obstacle == 4, "brute %d: the second "
               "move: outcome %d (obstacle %d)", brute, (int)r[1].outcome, r[1].obstacle);
        vw_dynscene_free(ds);
    }
}

/* A cone is tested as its box, conservatively: no move that hits the cone is accepted.
   A sphere starting in the box's empty corner (1.3 from the axis of a cylinder of
   radius 0.2) moves straight across the cylinder's axis, at (1, 1, 1), to a place
   outside the box. The start overlapping the box made the box an object the mover
   "already interpenetrates", exempt from the sweep: the move was accepted through the
   cylinder. Without sweep only the destination counts, and it is free. */
static void test_cone_slack(const vw_decomp *d, const vw_config *cfg)
{
    const char *nff = "v\nfrom 0 -20 0\nat 0 0 0\nup 0 0 1\nangle 40\nhither 0.01\n"
                      "resolution 8 8\nb 0 0 0\nl 0 -5 5\nf 1 1 1 1 0 0 0 1\n"
                      "c\n0 0 0 0.2\n2 2 2 0.2\n"   /* id 0: a cylinder along (1, 1, 1) */
                      "s 1.8 0.2 0.2 0.1\n";         /* id 1: in its box, off the cylinder */
    for (int brute = 0; brute < 2; brute++)
        for (int sweep = 0; sweep < 2; sweep++) {
            char err[256];
            vw_scene *s;
            CHECK(vw_scene_read_nff("cone", nff, strlen(nff), &s, err, sizeof err) == VW_OK);
            vw_dynscene_params p = {d, cfg, 0, brute};
            vw_dynscene *ds;
            CHECK(vw_dynscene_create(s, &p, &ds, err, sizeof err) == VW_OK);
            vw_edit e;
            vw_result r;
            int *ch;
            size_t nch;
            CHECK(vw_edit_parse("move 1 -2.3 2.3 2.3", "t", 1, &e, err, sizeof err) == VW_OK);
            CHECK(vw_dynscene_apply(ds, &e, 1, 1, sweep, &r, &ch, &nch) == VW_OK);
            free(ch);
            if (sweep)
                EXPECT(r.outcome == VW_OUT_SWEEP && r.obstacle == 0, "brute %d: the path through "
                       "the cylinder: outcome %d (obstacle %d), expected a sweep hit on 0", brute,
                       (int)r.outcome, r.obstacle);
            else
                EXPECT(r.outcome == VW_OUT_ACCEPTED, "brute %d, sweep off: outcome %d (obstacle %d)",
                       brute, (int)r.outcome, r.obstacle);
            vw_dynscene_free(ds);
        }
}

struct sunk_case {
    const char *edit;
    int outcome, obstacle;
};
static void sunk_cases(const vw_decomp *d, const vw_config *cfg, const char *nff,
                       const struct sunk_case *cases, size_t ncases);

/* An object a mover starts sunk in is exempt from the sweep only along a path that
   takes it no deeper: a sphere sunk in a floor by a hair more than the tolerance (1e-6,
   the rounding of a scene written with six digits) went through the floor with sweep
   on, where one resting on it exactly was stopped; a triangle sunk in a sphere went
   through the sphere's middle. Leaving stays free. */
static void test_sunk_through(const vw_decomp *d, const vw_config *cfg)
{
    const char *nff = "v\nfrom 0 -20 0\nat 0 0 0\nup 0 0 1\nangle 40\nhither 0.01\n"
                      "resolution 8 8\nb 0 0 0\nl 0 -5 5\nf 1 1 1 1 0 0 0 1\n"
                      "p 4\n-3 -3 0\n3 -3 0\n3 3 0\n-3 3 0\n"  /* id 0: the floor */
                      "s 0 0 0.499999 0.5\n"                     /* id 1: sunk 1e-6 in it */
                      "s 1 1 0.5 0.5\n"                          /* id 2: resting on it */
                      "s -2 2 2 1\n"                             /* id 3: a ball */
                      "p 3\n-2.2 2 2.5\n-1.8 2 2.5\n-2 2.2 2.5\n"; /* id 4: sunk in it */
    static const struct sunk_case cases[] = {
        {"move 1 0 0 -2", VW_OUT_SWEEP, 0},    /* through the floor: it was accepted */
        {"move 2 0 0 -2", VW_OUT_SWEEP, 0},    /* the same from resting on it */
        {"move 4 0 0 -1.5", VW_OUT_SWEEP, 3},  /* through the ball's middle: accepted */
        {"move 1 0 0 1", VW_OUT_ACCEPTED, -1}, /* off the floor */
        {"move 4 0 0 1", VW_OUT_ACCEPTED, -1}, /* out of the ball */
    };
    sunk_cases(d, cfg, nff, cases, sizeof cases / sizeof cases[0]);
    /* A small ball sunk 1e-5 on the diagonal that splits a floor quad into two
       triangles, so it is sunk in both. Dropped through the floor with a sideways step
       across the diagonal, its centre comes nearer to one triangle (the one it goes
       through) and, by less than tol, to the other (which it leaves): the second
       triangle's START once cancelled the first's sweep hit, for the whole quad, and
       the ball went through. The same with the floor lifted through the ball. */
    const char *diag = "v\nfrom 0 -10 5\nat 0 0 0\nup 0 0 1\nangle 45\nhither 0.01\n"
                       "resolution 8 8\nl 0 0 4\nf 0.8 0.8 0.8 1 0 0 0 0\n"
                       "p 4\n-4 -4 0\n4 -4 0\n4 4 0\n-4 4 0\n" /* id 0: the floor */
                       "s 1 1 0.00099 0.001\n";                  /* id 1: sunk in both halves */
    static const struct sunk_case across[] = {
        {"move 1 -0.5 0.5 -0.0021", VW_OUT_SWEEP, 0}, /* through, stepping aside: accepted */
        {"move 0 0.5 -0.5 0.0021", VW_OUT_SWEEP, 1},  /* the floor up through it: accepted */
        {"move 1 0 0 -0.0021", VW_OUT_SWEEP, 0},      /* straight through */
        {"move 1 0.5 0 0.002", VW_OUT_ACCEPTED, -1},  /* off it, stepping aside */
    };
    sunk_cases(d, cfg, diag, across, sizeof across / sizeof across[0]);
}

/* Applies each edit (sweep on) to the scene, in order, on the cells of d and by brute
   force, and checks its outcome and the obstacle named. */
static void sunk_cases(const vw_decomp *d, const vw_config *cfg, const char *nff,
                       const struct sunk_case *cases, size_t ncases)
{
    for (int brute = 0; brute < 2; brute++) {
        char err[256];
        vw_scene *s;
        CHECK(vw_scene_read_nff("through", nff, strlen(nff), &s, err, sizeof err) == VW_OK);
        vw_dynscene_params p = {d, cfg, 0, brute};
        vw_dynscene *ds;
        CHECK(vw_dynscene_create(s, &p, &ds, err, sizeof err) == VW_OK);
        for (size_t i = 0; i < ncases; i++) {
            vw_edit e;
            vw_result r;
            int *ch;
            size_t nch;
            CHECK(vw_edit_parse(cases[i].edit, "t", (int)i + 1, &e, err, sizeof err) == VW_OK);
            CHECK(vw_dynscene_apply(ds, &e, 1, 1, 1, &r, &ch, &nch) == VW_OK);
            free(ch);
            EXPECT((int)r.outcome == cases[i].outcome && r.obstacle == cases[i].obstacle,
                   "brute %d: '%s': outcome %d (obstacle %d), expected %d (obstacle %d)", brute,
                   cases[i].edit, (int)r.outcome, r.obstacle, cases[i].outcome, cases[i].obstacle);
        }
        vw_dynscene_free(ds);
    }
}

/* A small fast sphere and a thin triangle: the endpoint test accepts the jump, the
   swept test rejects it, naming the triangle. */
static void test_tunnel(int workers)
{
    const char *nff = "v\nfrom 0 -10 0\nat 0 0 0\nup 0 0 1\nangle 40\nhither 0.01\nresolution 16 16\n"
                      "b 0 0 0\nl 0 -5 5\nf 1 1 1 1 0 0 0 1\n"
                      "s 0 0 -2 0.05\n"                         /* id 0: the bullet */
                      "p 3\n-3 -3 0\n3 -3 0\n0 3 0\n"           /* id 1: the pane, z = 0 */
                      "s 4 4 4 0.1\n";                          /* id 2: far away */
    vw_box world = {{-5, -5, -5}, {5, 5, 5}};
    int dims[3] = {2, 2, 2};
    vw_decomp *d;
    CHECK(vw_decomp_create_grid(&world, dims, &d) == VW_OK);
    vw_config cfg;
    vw_config_init(&cfg);
    cfg.workers = workers;
    for (int brute = 0; brute < 2; brute++) {
        vw_scene *s;
        char err[256];
        CHECK(vw_scene_read_nff("tunnel", nff, strlen(nff), &s, err, sizeof err) == VW_OK);
        vw_dynscene_params p = {d, &cfg, 0, brute};
        vw_dynscene *ds;
        CHECK(vw_dynscene_create(s, &p, &ds, err, sizeof err) == VW_OK);
        vw_edit e;
        CHECK(vw_edit_parse("move 0 0 0 4", "t", 1, &e, err, sizeof err) == VW_OK);
        vw_result r;
        int *ch;
        size_t nch;
        CHECK(vw_dynscene_apply(ds, &e, 1, 1, 1, &r, &ch, &nch) == VW_OK); /* sweep on */
        free(ch);
        CHECK_EQ_INT(r.outcome, VW_OUT_SWEEP);
        CHECK_EQ_INT(r.obstacle, 1);
        CHECK(vw_dynscene_apply(ds, &e, 1, 1, 0, &r, &ch, &nch) == VW_OK); /* endpoint only */
        free(ch);
        CHECK_EQ_INT(r.outcome, VW_OUT_ACCEPTED);
        CHECK_EQ_INT(nch, 1);
        /* Now above the pane; a sideways move passes nothing. */
        CHECK(vw_edit_parse("move 0 1 0 0", "t", 2, &e, err, sizeof err) == VW_OK);
        CHECK(vw_dynscene_apply(ds, &e, 1, 1, 1, &r, &ch, &nch) == VW_OK);
        free(ch);
        CHECK_EQ_INT(r.outcome, VW_OUT_ACCEPTED);
        /* Landing on the pane collides at the destination. */
        CHECK(vw_edit_parse("moveto 0 1 0 0.01", "t", 3, &e, err, sizeof err) == VW_OK);
        CHECK(vw_dynscene_apply(ds, &e, 1, 1, 0, &r, &ch, &nch) == VW_OK);
        free(ch);
        CHECK_EQ_INT(r.outcome, VW_OUT_COLLISION);
        CHECK_EQ_INT(r.obstacle, 1);
        /* Edits a program made itself get the parser's checks: a sphere of radius <= 0
           is not added (the scene written would not read back), a zero axis is named. */
        const vw_edit hand[] = {{VW_EDIT_ADD, 0, {4, -4, 4, -1}, -1},
                                {VW_EDIT_ADD, 0, {-4, -4, 4, 0}, -1},
                                {VW_EDIT_MOVE, 2, {NAN, 0, 0}, -1},
                                {VW_EDIT_ROTATE, 1, {0, 0, 0, 90}, -1}};
        const char *why[] = {"radius", "radius", "not finite", "axis of object 1 is zero"};
        for (int i = 0; i < 4; i++) {
            CHECK(vw_dynscene_apply(ds, &hand[i], 1, 1, 1, &r, &ch, &nch) == VW_OK);
            free(ch);
            CHECK_EQ_INT(r.outcome, VW_OUT_INVALID);
            CHECK(strstr(r.msg, why[i]) != NULL);
        }
        CHECK_EQ_INT(vw_dynscene_ids(ds), 3);
        FILE *f = tmpfile();
        CHECK(f && vw_dynscene_write_nff(ds, f) == VW_OK);
        long len = ftell(f);
        char *text = malloc((size_t)len);
        rewind(f);
        CHECK(text && fread(text, 1, (size_t)len, f) == (size_t)len);
        fclose(f);
        vw_scene *back;
        CHECK(vw_scene_read_nff("written", text, (size_t)len, &back, err, sizeof err) == VW_OK);
        CHECK_EQ_INT(vw_scene_count_objects(back), 3);
        vw_scene_free(back);
        free(text);
        /* An edit naming an object far beyond the scene is invalid, and costs no memory
           by its number (it cost two bytes per id up to it: 4 GB here, so under a limit
           of 1 GB more address space the apply failed with VW_E_NOMEM). The sanitizers
           reserve terabytes of address space, so the limit is for plain builds. */
#if !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
        {
            FILE *statm = fopen("/proc/self/statm", "r");
            unsigned long pages = 0;
            CHECK(statm && fscanf(statm, "%lu", &pages) == 1);
            fclose(statm);
            struct rlimit old, lim;
            CHECK(getrlimit(RLIMIT_AS, &old) == 0);
            lim = old;
            lim.rlim_cur = (rlim_t)pages * (rlim_t)sysconf(_SC_PAGESIZE) + ((rlim_t)1 << 30);
            CHECK(setrlimit(RLIMIT_AS, &lim) == 0);
            CHECK(vw_edit_parse("remove 2000000000", "t", 4, &e, err, sizeof err) == VW_OK);
            vw_status st = vw_dynscene_apply(ds, &e, 1, 1, 1, &r, &ch, &nch);
            CHECK(setrlimit(RLIMIT_AS, &old) == 0);
            CHECK_EQ_INT(st, VW_OK);
            free(ch);
            CHECK_EQ_INT(r.outcome, VW_OUT_INVALID);
            CHECK(strstr(r.msg, "no object 2000000000") != NULL);
        }
#endif
        vw_dynscene_free(ds);
    }
    test_sunk(d, &cfg);
    test_brute_batch(d, &cfg);
    test_cone_slack(d, &cfg);
    test_sunk_through(d, &cfg);
    vw_decomp_free(d);
}

/* The swept tests against the static test at many points of the path: a path that
   meets the obstacle at a sampled point must be reported. Random spheres and triangles,
   tilted every way, so the point where a sphere's path crosses a triangle's plane is
   off the plane by rounding (the pierce test once asked for an exact zero distance
   there: a small sphere flew through the middle of a tilted pane, 97 % of such paths). */
static vw_shape random_shape(int kind, double size)
{
    vw_shape x;
    memset(&x, 0, sizeof x);
    x.kind = kind;
    double c[3] = {uni(-1, 1), uni(-1, 1), uni(-1, 1)};
    if (kind == VW_SHAPE_SPHERE) {
        memcpy(x.p[0], c, sizeof c);
        x.r = uni(0.05, 0.5) * size;
    } else {
        for (int v = 0; v < 3; v++)
            for (int k = 0; k < 3; k++) x.p[v][k] = c[k] + uni(-1, 1) * size;
    }
    return x;
}

static void test_swept(void)
{
    /* The hand-made case: a bullet through a tilted pane's middle (barycentric
       coordinates about 0.30, 0.34, 0.36), both ends far from it. */
    const double a[3] = {-1.3, -1.1, -0.7}, b[3] = {1.7, 0.9, -0.3}, c[3] = {0.1, 0.3, 1.9};
    vw_shape pane = tri(a, b, c), bullet = sphere(-2, -0.3, 0.2, 0.05);
    pane.id = 1;
    double d[3] = {4.1, 0.7, 0.3}, back[3] = {-4.1, -0.7, -0.3};
    CHECK(vw_shape_collide(&bullet, d, &pane, 1e-9));
    CHECK(vw_shape_collide(&pane, back, &bullet, 1e-9)); /* the same relative motion */
    const int kinds[2] = {VW_SHAPE_SPHERE, VW_SHAPE_TRIANGLE};
    rng_state = 12345;
    for (int ka = 0; ka < 2; ka++)
        for (int kb = 0; kb < 2; kb++) {
            int missed = 0, hits = 0;
            for (int it = 0; it < 3000; it++) {
                vw_shape m = random_shape(kinds[ka], 1), o = random_shape(kinds[kb], 2);
                m.id = 1, o.id = 2;
                double dd[3] = {uni(-4, 4), uni(-4, 4), uni(-4, 4)};
                for (int v = 0; v < 3; v++)
                    for (int k = 0; k < 3; k++) m.p[v][k] -= dd[k] / 2;
                int swept = vw_shape_collide(&m, dd, &o, 1e-9), sampled = 0;
                for (int i = 0; i <= 400 && !sampled; i++) {
                    vw_shape at = m;
                    for (int v = 0; v < 3; v++)
                        for (int k = 0; k < 3; k++) at.p[v][k] += dd[k] * (i / 400.0);
                    sampled = vw_shape_collide(&at, NULL, &o, 1e-9);
                }
                hits += sampled;
                missed += sampled && !swept;
            }
            EXPECT(missed == 0, "mover kind %d, obstacle kind %d: the path missed %d of %d hits",
                   kinds[ka], kinds[kb], missed, hits);
            CHECK(hits > 100);
        }
}

/* A frame after edits equals the edited scene written as NFF, read back and rendered
   from scratch (same camera, world box and scale), bit for bit. */
static void test_frame(int seeds, int workers)
{
    for (int seed = 1; seed <= seeds; seed++) {
        rng_state = 0x51ed27f1ull * (uint64_t)seed + 3;
        rt_anim_params p;
        memset(&p, 0, sizeof p);
        p.width = p.height = 48;
        p.dims[0] = 2, p.dims[1] = 1 + seed % 2, p.dims[2] = 2;
        p.workers = workers;
        rt_anim *a;
        char err[512];
        CHECK(rt_anim_create(random_scene(50), &p, &a, err, sizeof err) == VW_OK);
        vw_dynscene *ds = rt_anim_dynscene(a);
        for (int frame = 0; frame < 3; frame++) {
            vw_edit e[20];
            vw_result r[20];
            for (int i = 0; i < 20; i++) e[i] = random_edit(vw_dynscene_ids(ds), i + 1);
            rt_anim_stats st;
            memset(&st, 0, sizeof st);
            CHECK(rt_anim_apply(a, e, 20, 1, frame % 2, r, &st, err, sizeof err) == VW_OK);
            CHECK(rt_anim_render(a, &st, err, sizeof err) == VW_OK);
            /* The edited scene from scratch. */
            char *text = NULL;
            size_t len = 0;
            FILE *f = open_memstream(&text, &len);
            CHECK(vw_dynscene_write_nff(ds, f) == VW_OK);
            fclose(f);
            vw_scene *s2;
            CHECK(vw_scene_read_nff("edited", text, len, &s2, err, sizeof err) == VW_OK);
            free(text);
            rt_params rp;
            memset(&rp, 0, sizeof rp);
            rp.width = rp.height = 48;
            rp.dims[0] = rp.dims[1] = rp.dims[2] = 1 + frame % 2; /* any layout: same image */
            rp.workers = workers;
            rp.camera = rt_anim_camera(a);
            rp.world = rt_anim_world(a);
            rp.scale = rt_anim_scale(a);
            rt_job *j;
            CHECK(rt_job_create(s2, &rp, &j, err, sizeof err) == VW_OK);
            CHECK(rt_job_commit(j, err, sizeof err) == VW_OK);
            CHECK(rt_job_run(j, err, sizeof err) == VW_OK);
            if (rt_job_is_output(j)) {
                const int64_t *x = rt_job_sums(rt_anim_job(a)), *y = rt_job_sums(j);
                size_t np = (size_t)48 * 48 * 3, diff = 0;
                for (size_t i = 0; i < np; i++) diff += x[i] != y[i];
                if (diff) fprintf(stderr, "seed %d frame %d: %zu of %zu sums differ\n", seed, frame, diff, np);
                CHECK_EQ_INT(diff, 0);
            }
            rt_job_free(j);
            vw_scene_free(s2);
        }
        rt_anim_free(a);
    }
}

int main(int argc, char **argv)
{
    char msg[256];
    if (vw_engine_init(&argc, &argv, msg, sizeof msg) != VW_OK) {
        fprintf(stderr, "%s\n", msg);
        return 1;
    }
    if (argc < 2) {
        fprintf(stderr, "usage: test_dynamic primitives|placement|decisions|tunnel|frame [seeds] [--workers W]\n");
        return 2;
    }
    int seeds = 3, workers = 2;
    for (int i = 2; i < argc; i++) {
        if (!strcmp(argv[i], "--workers") && i + 1 < argc)
            workers = atoi(argv[++i]);
        else
            seeds = atoi(argv[i]);
    }
    if (!strcmp(argv[1], "primitives")) test_primitives();
    else if (!strcmp(argv[1], "placement")) test_placement(seeds, workers);
    else if (!strcmp(argv[1], "decisions")) test_decisions(seeds, workers);
    else if (!strcmp(argv[1], "tunnel")) test_tunnel(workers);
    else if (!strcmp(argv[1], "swept")) test_swept();
    else if (!strcmp(argv[1], "frame")) test_frame(seeds, workers);
    else {
        fprintf(stderr, "unknown test '%s'\n", argv[1]);
        return 2;
    }
    int rank = vw_engine_rank();
    vw_engine_finish();
    if (rank != 0) return 0;
    TEST_DONE();
}
