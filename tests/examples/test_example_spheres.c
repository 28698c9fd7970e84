/* test_example_spheres.c - the two example modules (examples/pairs.c, components.c) on
 * sphere sets made to stress them, against this file's own O(n^2) reference: uniform and
 * clustered spheres, spheres exactly touching across a wall (the distance of the centres
 * equal to the sum of the radii in floating point, centres on a wall or an ulp off it:
 * "walls", "chains"), spheres larger than a cell, duplicates, zero radii, all radii zero
 * (rmax 0), a world below the origin, centres on the world's faces. Every case runs on
 * every layout and worker count asked for; the pair count must equal the brute force's,
 * the components' labels the smallest id of each component, and the number and sizes of
 * the components a union-find's over the brute-force pairs. Case "invalid": sphere sets
 * the modules cannot count are refused with VW_E_INVAL, not counted wrong, and
 * ex_errmsg says why in ex_spheres_check's words.
 *
 * "Touching" is pairs.h's definition: |c1 - c2|^2 <= (r1 + r2)^2, evaluated in double as
 * written there. It is written out here again on purpose, so that the reference does not
 * share the module's code.
 *   usage: test_example_spheres [--cells L[,L...]] [--workers W[,W...]] [--case NAME]
 * Under mpirun every process runs every case; the output process checks the labels.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "components.h"
#include "pairs.h"

/* ---- the reference ---- */

static int touch(const ex_sphere *a, const ex_sphere *b)
{
    double d2 = 0;
    for (int k = 0; k < 3; k++) d2 += (a->c[k] - b->c[k]) * (a->c[k] - b->c[k]);
    return d2 <= (a->r + b->r) * (a->r + b->r);
}

static size_t uf_find(size_t *p, size_t i)
{
    while (p[i] != i) i = p[i] = p[p[i]];
    return i;
}

typedef struct reference {
    int64_t pairs, ncomp;
    int64_t *label; /* smallest id of the component */
    int64_t *sizes; /* sizes of the components, sorted */
} reference;

static int cmp_i64(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

/* Component sizes from labels (ids are 0..n-1), sorted; returns their number. */
static int64_t sizes_of(const int64_t *label, size_t n, int64_t *sizes)
{
    int64_t *count = calloc(n ? n : 1, sizeof *count), m = 0;
    if (!count) abort();
    for (size_t i = 0; i < n; i++)
        if (label[i] >= 0 && (size_t)label[i] < n) count[label[i]]++;
    for (size_t i = 0; i < n; i++)
        if (count[i]) sizes[m++] = count[i];
    qsort(sizes, (size_t)m, sizeof *sizes, cmp_i64);
    free(count);
    return m;
}

static void reference_make(const ex_sphere *s, size_t n, reference *ref)
{
    size_t *p = malloc(sizeof *p * (n ? n : 1));
    ref->label = malloc(sizeof *ref->label * (n ? n : 1));
    ref->sizes = malloc(sizeof *ref->sizes * (n ? n : 1));
    if (!p || !ref->label || !ref->sizes) abort();
    ref->pairs = 0;
    for (size_t i = 0; i < n; i++) p[i] = i;
    for (size_t i = 0; i < n; i++)
        for (size_t j = i + 1; j < n; j++)
            if (touch(&s[i], &s[j])) {
                ref->pairs++;
                size_t a = uf_find(p, i), b = uf_find(p, j);
                if (a != b) p[a > b ? a : b] = a < b ? a : b;
            }
    for (size_t i = 0; i < n; i++) ref->label[i] = (int64_t)uf_find(p, i);
    ref->ncomp = sizes_of(ref->label, n, ref->sizes);
    free(p);
}

/* ---- the sphere sets (the same on every process: a fixed seed) ---- */

static uint64_t rng_state;
static double uniform(void)
{
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return (double)((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
}

typedef struct set {
    ex_sphere *s;
    size_t n, cap;
    vw_box world; /* the unit cube unless the case says otherwise */
} set;

static void add(set *S, double x, double y, double z, double r)
{
    double p[3] = {x, y, z};
    for (int k = 0; k < 3; k++)
        if (!(p[k] >= S->world.lo[k] && p[k] <= S->world.hi[k])) return; /* centres in the world */
    if (S->n == S->cap) {
        S->cap = S->cap ? 2 * S->cap : 256;
        S->s = realloc(S->s, sizeof *S->s * S->cap);
        if (!S->s) abort();
    }
    ex_sphere *e = &S->s[S->n];
    e->id = (int64_t)S->n;
    e->c[0] = x, e->c[1] = y, e->c[2] = z, e->r = r;
    S->n++;
}

static double clamp01(double v) { return v < 0 ? 0 : v > 1 ? 1 : v; }

static double step_ulps(double v, int u)
{
    for (; u > 0; u--) v = nextafter(v, 2);
    for (; u < 0; u++) v = nextafter(v, -1);
    return v;
}

static void make_uniform(set *S)
{
    for (int i = 0; i < 1500; i++) add(S, uniform(), uniform(), uniform(), 0.04 * (0.25 + 0.75 * uniform()));
}

static void make_clustered(set *S)
{
    for (int c = 0; c < 8; c++) {
        double m[3] = {uniform(), uniform(), uniform()};
        if (c < 3) m[c] = 0.5; /* some clusters sit on the middle walls */
        for (int i = 0; i < 150; i++) {
            double p[3];
            for (int k = 0; k < 3; k++)
                p[k] = clamp01(m[k] + 0.03 * (uniform() + uniform() + uniform() - 1.5));
            add(S, p[0], p[1], p[2], 0.005 + 0.007 * uniform());
        }
    }
}

/* One pair exactly touching across wall W on axis `axis`: the larger sphere (radius
   rmax) with its centre on the wall or an ulp off it, the other sphere at the farthest
   position where the two still touch in floating point, on side sg of it (diagonally
   across an edge of cells when diag). Returns 0 when the two do not touch after all. */
static int wall_pair(int axis, double W, double sg, int diag, double rmax, ex_sphere *a,
                     ex_sphere *b)
{
    double pr = rmax, qr = rmax * uniform();
    a->r = pr, b->r = qr;
    for (int k = 0; k < 3; k++) a->c[k] = uniform();
    a->c[axis] = step_ulps(W, (int)(uniform() * 3) - 1);
    double dir[3] = {0, 0, 0};
    dir[axis] = sg;
    if (diag) dir[axis] = dir[(axis + 1) % 3] = sg / sqrt(2);
    for (int k = 0; k < 3; k++) b->c[k] = a->c[k] + dir[k] * (pr + qr);
    for (int u = 0; u < 8; u++) {
        ex_sphere c = *b;
        c.c[axis] = step_ulps(b->c[axis], sg > 0 ? 1 : -1);
        if (!touch(a, &c)) break;
        *b = c;
    }
    return touch(a, b);
}

/* Pairs exactly touching across the walls of the layouts tested (see wall_pair). Most
   are random; on every wall, axis and side, some are the pairs where the smaller
   sphere's reach (its centre +- (its radius + rmax), rounded as written) stops short of
   the larger one's centre by rounding alone: a ghost sent only as far as that reach
   never meets the sphere it touches. Whether such pairs exist on a wall depends on how
   the sums round: with rmax 0.04 they do on the walls 3/8 and 1/2 (and so on every
   layout tested but 1). */
static void make_walls(set *S)
{
    static const double walls[] = {0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875};
    const double rmax = 0.04;
    ex_sphere a, b;
    for (int i = 0; i < 300; i++)
        if (wall_pair(i % 3, walls[(i / 3) % 7], i % 8 < 4 ? -1 : 1, i % 7 == 3, rmax, &a, &b)) {
            add(S, a.c[0], a.c[1], a.c[2], a.r);
            add(S, b.c[0], b.c[1], b.c[2], b.r);
        }
    for (int axis = 0; axis < 3; axis++)
        for (int w = 0; w < 7; w++)
            for (int sg = -1; sg <= 1; sg += 2)
                for (int found = 0, tries = 0; found < 3 && tries < 20000; tries++) {
                    if (!wall_pair(axis, walls[w], sg, 0, rmax, &a, &b)) continue;
                    /* The larger sphere's centre owned across the wall from the
                       smaller's (a centre on the wall goes to the + side), and the
                       smaller's reach ending before the wall. */
                    double end = sg < 0 ? b.c[axis] + b.r + rmax : b.c[axis] - b.r - rmax;
                    if (sg < 0 ? !(a.c[axis] >= walls[w] && end < walls[w])
                               : !(a.c[axis] < walls[w] && end > walls[w]))
                        continue;
                    add(S, a.c[0], a.c[1], a.c[2], a.r);
                    add(S, b.c[0], b.c[1], b.c[2], b.r);
                    found++;
                }
}

/* Chains along each axis, each sphere exactly touching the next (dyadic: radius 1/16,
   centres 1/8 apart), centres on the walls of 1x1x8 and 4x4x4, then between them. */
static void make_chains(set *S)
{
    for (int axis = 0; axis < 3; axis++)
        for (int off = 0; off < 2; off++)
            for (int k = 0; k <= 8; k++) {
                double p[3] = {0.3 + 0.1 * axis, 0.9 - 0.2 * off, 0.15 + 0.3 * off};
                p[axis] = k / 8.0 + off / 16.0;
                add(S, p[0], p[1], p[2], 0.0625);
            }
}

static void make_large(set *S)
{
    for (int i = 0; i < 300; i++) add(S, uniform(), uniform(), uniform(), 0.3 * (0.25 + 0.75 * uniform()));
}

static void make_duplicates(set *S)
{
    for (int i = 0; i < 400; i++) {
        double x = uniform(), y = uniform(), z = uniform(), r = 0.03 * (0.25 + 0.75 * uniform());
        if (i % 10 == 0) x = 0.5;   /* duplicates on a wall */
        int copies = 1 + (int)(uniform() * 3);
        for (int c = 0; c < copies; c++) add(S, x, y, z, r);
    }
}

/* Zero radii: points that touch only by coinciding, or by lying on a sphere's surface. */
static void make_zero(set *S)
{
    for (int i = 0; i < 300; i++) {
        double x = uniform(), y = uniform(), z = uniform();
        if (i % 7 == 0) y = 0.25;
        add(S, x, y, z, i % 2 ? 0 : 0.02 * uniform());
        if (i % 3 == 0) add(S, x, y, z, 0); /* a point on a point, or at a centre */
    }
    /* Points on the surface of a sphere of radius 1/8 centred on the corner of 8 cells. */
    add(S, 0.5, 0.5, 0.5, 0.125);
    for (int k = 0; k < 3; k++)
        for (int sg = -1; sg <= 1; sg += 2) {
            double p[3] = {0.5, 0.5, 0.5};
            p[k] += sg * 0.125;
            add(S, p[0], p[1], p[2], 0);
        }
}

/* Every radius zero (the largest radius is 0): points touch when they coincide. */
static void make_allzero(set *S)
{
    for (int i = 0; i < 400; i++) {
        double x = (double)(int)(uniform() * 8) / 8, y = (double)(int)(uniform() * 8) / 8,
               z = (double)(int)(uniform() * 4) / 4;
        add(S, x, y, z, 0);
    }
}

/* A world on both sides of the origin, [-1, 1]^3: grid bins of negative coordinates. */
static void make_negative(set *S)
{
    for (int k = 0; k < 3; k++) S->world.lo[k] = -1;
    for (int i = 0; i < 1500; i++)
        add(S, 2 * uniform() - 1, 2 * uniform() - 1, 2 * uniform() - 1, 0.06 * (0.25 + 0.75 * uniform()));
}

/* Centres on the world's faces, edges and corners (the world box is closed: they belong
   to the last cell along the axis), touching each other and across the walls. */
static void make_faces(set *S)
{
    for (int i = 0; i < 27; i++) {
        double p[3] = {(i % 3) / 2.0, (i / 3 % 3) / 2.0, (i / 9) / 2.0};
        add(S, p[0], p[1], p[2], 0.25);          /* 1/2 apart: neighbours touch */
        add(S, p[0], p[1], p[2], 0);             /* and a point at every centre */
    }
    for (int i = 0; i < 300; i++) {
        double p[3] = {uniform(), uniform(), uniform()};
        p[i % 3] = i % 2 ? 1 : 0;
        add(S, p[0], p[1], p[2], 0.02 * uniform());
    }
}

typedef struct test_case {
    const char *name;
    void (*make)(set *);
} test_case;

static const test_case cases[] = {
    {"uniform", make_uniform},   {"clustered", make_clustered},   {"walls", make_walls},
    {"chains", make_chains},
    {"large", make_large},       {"duplicates", make_duplicates}, {"zero", make_zero},
    {"allzero", make_allzero},   {"negative", make_negative},     {"faces", make_faces},
};

/* After a call of one of the modules that returned st: a refusal gives ex_errmsg in
   ex_spheres_check's own words (under MPI after "rank R: ", every process refusing
   alike), a success "no error". Returns 1 (and says so) when it does not. */
static int errmsg_is_why(vw_status st, const ex_sphere *s, size_t n, double rmax,
                         const vw_decomp *d, int ids_are_indices, const char *module,
                         const char *what, int workers)
{
    char why[256] = "";
    ex_spheres_check(s, n, rmax, d, ids_are_indices, why, sizeof why);
    const char *got = ex_errmsg();
    size_t lg = strlen(got), lw = strlen(why);
    int ok = st == VW_OK ? !strcmp(got, "no error")
                         : lw && lg >= lw && !strcmp(got + lg - lw, why) &&
                               (lg == lw || (vw_engine_size() > 1 && !strncmp(got, "rank 0: ", 8) &&
                                             lg == lw + 8));
    if (!ok)
        fprintf(stderr, "invalid w%d: %s, %s: %s, ex_errmsg \"%s\", expected \"%s%s\"\n", workers,
                module, what, vw_status_message(st), got,
                st == VW_OK ? "no error" : vw_engine_size() > 1 ? "rank 0: " : "",
                st == VW_OK ? "" : why);
    return !ok;
}

/* Sphere sets the modules cannot count right are refused (VW_E_INVAL, no world), not
   counted wrong: a radius above the rmax given (its ghosts would not reach far enough), a
   negative radius, a centre outside the world box (in no cell) or not a number, rmax not
   a finite number >= 0, two spheres with one id (a pair across a wall is counted by the
   smaller id), and for components an id outside 0..n-1. */
static int run_invalid(int workers)
{
    enum { N = 40 };
    vw_decomp *d = NULL;
    vw_box unit = {{0, 0, 0}, {1, 1, 1}};
    int dims[3] = {2, 2, 2}, bad = 0;
    if (vw_decomp_create_grid(&unit, dims, &d) != VW_OK) return 1;
    vw_config cfg;
    vw_config_init(&cfg);
    cfg.workers = workers;
    const char *what[] = {"radius above rmax", "negative radius", "centre outside the world",
                          "centre not a number", "rmax not finite", "rmax negative", "an id twice",
                          "an id out of 0..n-1 (components only)", "valid"};
    enum { NWHAT = sizeof what / sizeof *what };
    for (int k = 0; k < NWHAT; k++) {
        ex_sphere s[N];
        double rmax = 0.1;
        rng_state = 99;
        for (int i = 0; i < N; i++) {
            s[i].id = i;
            for (int a = 0; a < 3; a++) s[i].c[a] = uniform();
            s[i].r = 0.1 * uniform();
        }
        switch (k) {
        case 0: s[7].r = 0.15; break;
        case 1: s[7].r = -0.01; break;
        case 2: s[7].c[0] = 1.05; break;
        case 3: s[7].c[1] = nan(""); break;
        case 4: rmax = INFINITY; break;
        case 5: rmax = -0.1; break;
        case 6: s[7].id = 3; break;
        case 7: s[7].id = N; break;
        default: break;
        }
        int64_t pairs = -1, ncomp = -1, labels[N];
        vw_world *w = (vw_world *)&pairs; /* not NULL: a refusal must set it NULL */
        vw_status st = ex_pairs_count(s, N, rmax, d, &cfg, &pairs, &w);
        vw_status want = k == NWHAT - 1 || k == 7 ? VW_OK : VW_E_INVAL;
        if (st != want || (st != VW_OK && w)) {
            fprintf(stderr, "invalid w%d: pairs, %s: %s, expected %s%s\n", workers, what[k],
                    vw_status_message(st), vw_status_message(want),
                    st != VW_OK && w ? " (and a world handed back)" : "");
            bad = 1;
        }
        bad |= errmsg_is_why(st, s, N, rmax, d, 0, "pairs", what[k], workers);
        if (st == VW_OK) vw_world_free(w);
        want = k == NWHAT - 1 ? VW_OK : VW_E_INVAL;
        st = ex_components_label(s, N, rmax, d, &cfg, labels, &ncomp, NULL);
        if (st != want) {
            fprintf(stderr, "invalid w%d: components, %s: %s, expected %s\n", workers, what[k],
                    vw_status_message(st), vw_status_message(want));
            bad = 1;
        }
        bad |= errmsg_is_why(st, s, N, rmax, d, 1, "components", what[k], workers);
        char why[256] = "";
        if (k < NWHAT - 1 && ex_spheres_check(s, N, rmax, d, 1, why, sizeof why) == VW_OK) {
            fprintf(stderr, "invalid w%d: ex_spheres_check passes %s\n", workers, what[k]);
            bad = 1;
        }
        if (vw_engine_rank() == 0 && k < NWHAT - 1)
            printf("invalid w%d: %s: %s\n", workers, what[k], ex_errmsg());
    }
    /* Valid spheres and a world vw_world_create refuses: its reason, kept by ex_errmsg
       (the world is gone). */
    ex_sphere one = {0, {0.5, 0.5, 0.5}, 0.1};
    vw_config many = cfg;
    many.workers = 5000;
    int64_t pairs = -1, ncomp = -1, label;
    for (int m = 0; m < 2; m++) {
        vw_status st = m ? ex_components_label(&one, 1, 0.1, d, &many, &label, &ncomp, NULL)
                         : ex_pairs_count(&one, 1, 0.1, d, &many, &pairs, NULL);
        if (st == VW_OK || !strstr(ex_errmsg(), "5000 workers (at most 1024)")) {
            fprintf(stderr, "invalid w%d: %s, 5000 workers: %s, ex_errmsg \"%s\"\n", workers,
                    m ? "components" : "pairs", vw_status_message(st), ex_errmsg());
            bad = 1;
        }
    }
    vw_decomp_free(d);
    return bad;
}

/* ---- the runs ---- */

static int split_list(char *list, char **items, int max)
{
    int n = 0;
    for (char *p = strtok(list, ","); p && n < max; p = strtok(NULL, ",")) items[n++] = p;
    return n;
}

static int run(const test_case *tc, const char *layout, int workers)
{
    char msg[256];
    set S = {NULL, 0, 0, {{0, 0, 0}, {1, 1, 1}}};
    rng_state = 12345;
    tc->make(&S);
    double rmax = 0;
    for (size_t i = 0; i < S.n; i++)
        if (S.s[i].r > rmax) rmax = S.s[i].r;
    int dims[3];
    vw_decomp *d = NULL;
    if (vw_layout_parse(layout, dims, msg, sizeof msg) != VW_OK ||
        vw_decomp_create_grid(&S.world, dims, &d) != VW_OK) {
        fprintf(stderr, "bad layout %s\n", layout);
        exit(2);
    }
    vw_config cfg;
    vw_config_init(&cfg);
    cfg.workers = workers;

    reference ref;
    reference_make(S.s, S.n, &ref);
    int bad = 0;
    int64_t pairs = -1, ncomp = -1;
    vw_status st = ex_pairs_count(S.s, S.n, rmax, d, &cfg, &pairs, NULL);
    int64_t *labels = malloc(sizeof *labels * (S.n ? S.n : 1));
    if (!labels) abort();
    for (size_t i = 0; i < S.n; i++) labels[i] = -1;
    vw_status st2 = ex_components_label(S.s, S.n, rmax, d, &cfg, labels, &ncomp, NULL);
    int out = vw_engine_rank() == 0;
    if (st != VW_OK || st2 != VW_OK) {
        fprintf(stderr, "%s %s w%d: run failed: %s / %s\n", tc->name, layout, workers,
                vw_status_message(st), vw_status_message(st2));
        bad = 1;
    }
    if (st == VW_OK && pairs != ref.pairs) {
        fprintf(stderr, "%s %s w%d: %lld pairs, brute force %lld\n", tc->name, layout, workers,
                (long long)pairs, (long long)ref.pairs);
        bad = 1;
    }
    if (st2 == VW_OK && ncomp != ref.ncomp) {
        fprintf(stderr, "%s %s w%d: %lld components, union-find %lld\n", tc->name, layout, workers,
                (long long)ncomp, (long long)ref.ncomp);
        bad = 1;
    }
    if (st2 == VW_OK && out) { /* the labels are collected on the output process only */
        size_t nbad = 0, first = 0;
        for (size_t i = 0; i < S.n; i++)
            if (labels[i] != ref.label[i] && !nbad++) first = i;
        int64_t *sizes = malloc(sizeof *sizes * (S.n ? S.n : 1));
        if (!sizes) abort();
        int64_t m = sizes_of(labels, S.n, sizes);
        int same_sizes = m == ref.ncomp && !memcmp(sizes, ref.sizes, sizeof *sizes * (size_t)m);
        if (nbad || !same_sizes) {
            fprintf(stderr, "%s %s w%d: %zu labels differ (first: sphere %zu, %lld, expected %lld), "
                    "component sizes %s\n", tc->name, layout, workers, nbad, first,
                    (long long)labels[first], (long long)ref.label[first],
                    same_sizes ? "equal" : "differ");
            bad = 1;
        }
        free(sizes);
    }
    if (out)
        printf("%-10s %-6s w%d: %5zu spheres, rmax %.4g, %6lld pairs, %5lld components%s\n", tc->name,
               layout, workers, S.n, rmax, (long long)ref.pairs, (long long)ref.ncomp,
               bad ? "  FAIL" : "");
    free(labels), free(ref.label), free(ref.sizes), free(S.s);
    vw_decomp_free(d);
    return bad;
}

int main(int argc, char **argv)
{
    char msg[256];
    if (vw_engine_init(&argc, &argv, msg, sizeof msg) != VW_OK) {
        fprintf(stderr, "test_example_spheres: %s\n", msg);
        return 1;
    }
    char cells_buf[256] = "1,2,2x2x2,4x4x4,1x1x8", workers_buf[64] = "1,2,4";
    const char *only = NULL;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--cells")) snprintf(cells_buf, sizeof cells_buf, "%s", argv[i + 1]);
        else if (!strcmp(argv[i], "--workers")) snprintf(workers_buf, sizeof workers_buf, "%s", argv[i + 1]);
        else if (!strcmp(argv[i], "--case")) only = argv[i + 1];
        else {
            fprintf(stderr, "usage: test_example_spheres [--cells L,...] [--workers W,...] [--case NAME]\n");
            return 2;
        }
    }
    char *layouts[16], *wlist[16];
    int nl = split_list(cells_buf, layouts, 16), nw = split_list(workers_buf, wlist, 16);
    int bad = 0, ran = 0;
    if (only && !strcmp(only, "invalid")) {
        for (int w = 0; w < nw; w++) bad |= run_invalid(atoi(wlist[w]));
        ran = 1;
    }
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
        if (only && strcmp(only, cases[c].name)) continue;
        for (int l = 0; l < nl; l++)
            for (int w = 0; w < nw; w++) {
                bad |= run(&cases[c], layouts[l], atoi(wlist[w]));
                ran++;
            }
    }
    if (!ran) {
        fprintf(stderr, "no case named %s\n", only ? only : "");
        bad = 1;
    }
    vw_engine_finish();
    return bad;
}
