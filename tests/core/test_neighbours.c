/* test_neighbours.c - face neighbour lists against brute force: random kd-trees (divided
 * anywhere, staggered, with unequal splits and splits shared exactly between subtrees,
 * in 1, 2 and 3 dimensions), grids with uneven walls, and clones of each. Every list
 * must hold exactly the cells whose opposite face lies on the same plane and overlaps
 * it with positive area, in the depth-first order of the tree's leaves (low side
 * first: cells send to their neighbours in this order), and the largest count must match.
 */
#include <string.h>

#include "vw_test.h"
#include "vwalls/vwalls.h"

static uint64_t rng = 20261128;
static uint64_t next_u64(void)
{
    uint64_t z = vw_test_mix(rng);
    rng += 0x9e3779b97f4a7c15ull;
    return z;
}
static double urand(void) { return (double)(next_u64() >> 11) * 0x1.0p-53; }
static int irand(int n) { return (int)(next_u64() % (uint64_t)n); }

static const vw_box world = {{-1, 0, 2}, {3, 1, 2.5}};

/* A tree being grown by dividing its cells: the node array and each cell's leaf. */
typedef struct tree {
    vw_kd_node *nodes;
    int nn, ncells, *leaf;
    vw_box *box;
} tree;

static void tree_init(tree *t, int maxcells)
{
    t->nodes = malloc(sizeof *t->nodes * (size_t)(2 * maxcells));
    t->leaf = malloc(sizeof(int) * (size_t)maxcells);
    t->box = malloc(sizeof(vw_box) * (size_t)maxcells);
    CHECK(t->nodes && t->leaf && t->box);
    t->nodes[0] = (vw_kd_node){-1, 0, -1, -1, 0};
    t->nn = 1;
    t->ncells = 1;
    t->leaf[0] = 0;
    t->box[0] = world;
}

static void tree_free(tree *t)
{
    free(t->nodes);
    free(t->leaf);
    free(t->box);
}

/* A split of cell c across axis a, strictly inside it: half the time one of the planes
   k/q of the world (q in 4, 8, 16), so that walls of different subtrees coincide exactly
   and faces meet at edges or corners, or are flush; else anywhere (unequal pieces). */
static int pick_split(const tree *t, int c, int a, double *s)
{
    const vw_box *b = &t->box[c];
    if (irand(2)) {
        int q = 4 << irand(3);
        double w = world.hi[a] - world.lo[a];
        int k0 = (int)floor((b->lo[a] - world.lo[a]) / w * q) + 1;
        int k1 = (int)ceil((b->hi[a] - world.lo[a]) / w * q) - 1;
        for (int tries = 0; tries < 4 && k0 <= k1; tries++) {
            int k = k0 + irand(k1 - k0 + 1);
            double v = world.lo[a] + w * k / q;
            if (v > b->lo[a] && v < b->hi[a]) {
                *s = v;
                return 1;
            }
        }
    }
    double v = b->lo[a] + (b->hi[a] - b->lo[a]) * (0.05 + 0.9 * urand());
    if (!(v > b->lo[a] && v < b->hi[a])) return 0;
    *s = v;
    return 1;
}

static void divide(tree *t, int c, int a, double s)
{
    int leaf = t->leaf[c], n = t->nn, nc = t->ncells;
    t->nodes[n] = (vw_kd_node){-1, 0, -1, -1, c};
    t->nodes[n + 1] = (vw_kd_node){-1, 0, -1, -1, nc};
    t->nodes[leaf] = (vw_kd_node){a, s, n, n + 1, -1};
    t->leaf[c] = n;
    t->leaf[nc] = n + 1;
    t->box[nc] = t->box[c];
    t->box[c].hi[a] = s;
    t->box[nc].lo[a] = s;
    t->nn = n + 2;
    t->ncells = nc + 1;
}

/* Divides random cells across random axes of `axes` (a bit mask) until there are n. */
static void grow_random(tree *t, int n, int axes)
{
    while (t->ncells < n) {
        int c = irand(t->ncells), a;
        do a = irand(3);
        while (!(axes >> a & 1));
        double s;
        if (pick_split(t, c, a, &s)) divide(t, c, a, s);
    }
}

/* The balancer's staggered shape: slabs across the first axis of `axes`, each cut on
   its own across the second, each column on its own across the third; k pieces each. */
static void grow_staggered(tree *t, int k, int axes)
{
    int order[3], na = 0;
    for (int a = 0; a < 3; a++)
        if (axes >> a & 1) order[na++] = a;
    for (int level = 0; level < na; level++) {
        int a = order[level], before = t->ncells;
        for (int c = 0; c < before; c++) {
            int pieces = 1 + irand(k), cell = c;
            for (int p = 1; p < pieces; p++) {
                double s;
                /* Divide the last piece, so each stays a chain of one wall per step. */
                if (pick_split(t, cell, a, &s)) {
                    divide(t, cell, a, s);
                    cell = t->ncells - 1;
                }
            }
        }
    }
}

static void leaf_order(const vw_kd_node *nodes, int node, int *rank, int *k)
{
    if (nodes[node].axis < 0) {
        rank[nodes[node].cell] = (*k)++;
        return;
    }
    leaf_order(nodes, nodes[node].left, rank, k);
    leaf_order(nodes, nodes[node].right, rank, k);
}

/* Do the faces f of p and f^1 of q lie on one plane and overlap with positive area? */
static int brute_neighbours(const vw_box *p, const vw_box *q, int f)
{
    int a = VW_FACE_AXIS(f);
    double s = VW_FACE_SIGN(f) > 0 ? p->hi[a] : p->lo[a];
    double qs = VW_FACE_SIGN(f) > 0 ? q->lo[a] : q->hi[a];
    if (s != qs) return 0;
    for (int k = 0; k < 3; k++) {
        if (k == a) continue;
        double lo = p->lo[k] > q->lo[k] ? p->lo[k] : q->lo[k];
        double hi = p->hi[k] < q->hi[k] ? p->hi[k] : q->hi[k];
        if (!(hi > lo)) return 0;
    }
    return 1;
}

static long pairs_total, multi_faces;

/* d's lists are brute force's, in leaf order; returns nothing, stops at the first
   difference, naming the cell and face. */
static void check_neighbours(const vw_decomp *d, const char *what)
{
    int n = vw_decomp_cell_count(d), nnodes;
    const vw_kd_node *nodes = vw_decomp_nodes(d, &nnodes);
    int *rank = malloc(sizeof(int) * (size_t)n), *byrank = malloc(sizeof(int) * (size_t)n);
    int *want = malloc(sizeof(int) * (size_t)n), *got = malloc(sizeof(int) * (size_t)n);
    vw_box *box = malloc(sizeof(vw_box) * (size_t)n);
    CHECK(rank && byrank && want && got && box);
    int k = 0;
    leaf_order(nodes, 0, rank, &k);
    CHECK_EQ_INT(k, n);
    for (int c = 0; c < n; c++) {
        byrank[rank[c]] = c;
        box[c] = vw_decomp_cell_box(d, c);
    }
    int max_total = 0;
    for (int c = 0; c < n; c++) {
        int total = 0;
        for (int f = 0; f < 6; f++) {
            int m = 0;
            for (int r = 0; r < n; r++) {
                int q = byrank[r];
                if (q != c && brute_neighbours(&box[c], &box[q], f)) want[m++] = q;
            }
            int g = vw_decomp_neighbours(d, c, f, got, n);
            EXPECT(g == m, "%s: cell %d face %d: %d neighbours, brute force %d", what, c, f, g,
                   m);
            for (int i = 0; i < m && i < g; i++)
                EXPECT(got[i] == want[i], "%s: cell %d face %d: neighbour %d is %d, brute force %d",
                       what, c, f, i, got[i], want[i]);
            if (vw_test_failures) exit(1);
            CHECK_EQ_INT(vw_decomp_neighbours(d, c, f, NULL, 0), m);
            total += m;
            pairs_total += m;
            multi_faces += m > 1;
        }
        if (total > max_total) max_total = total;
    }
    CHECK_EQ_INT(vw_decomp_max_neighbours(d), max_total);
    /* Outside the cells and faces: none. */
    CHECK_EQ_INT(vw_decomp_neighbours(d, -1, 0, NULL, 0), 0);
    CHECK_EQ_INT(vw_decomp_neighbours(d, n, 0, NULL, 0), 0);
    CHECK_EQ_INT(vw_decomp_neighbours(d, 0, 6, NULL, 0), 0);
    free(rank);
    free(byrank);
    free(want);
    free(got);
    free(box);
}

static int collect(const vw_segment *s, void *user)
{
    vw_segment *out = user;
    int i = 0;
    while (out[i].cell >= 0) i++;
    out[i] = *s;
    out[i + 1].cell = -1;
    return 1;
}

/* A clone answers as its source: the same tree, boxes and lists, and the same carried
   walks (whose one-step crossings use the copied per-face steps). */
static void check_clone(const vw_decomp *d, const char *what)
{
    vw_decomp *e;
    CHECK_EQ_INT(vw_decomp_clone(d, &e), VW_OK);
    CHECK(vw_decomp_equal(d, e));
    CHECK_EQ_INT(vw_decomp_get_kind(e), vw_decomp_get_kind(d));
    int n = vw_decomp_cell_count(d), n1, n2;
    CHECK_EQ_INT(vw_decomp_cell_count(e), n);
    const vw_kd_node *a = vw_decomp_nodes(d, &n1), *b = vw_decomp_nodes(e, &n2);
    CHECK_EQ_INT(n1, n2);
    for (int i = 0; i < n1; i++) /* field by field: the struct has padding */
        CHECK(a[i].axis == b[i].axis && a[i].left == b[i].left && a[i].right == b[i].right &&
              a[i].cell == b[i].cell && memcmp(&a[i].split, &b[i].split, sizeof a[i].split) == 0);
    for (int c = 0; c < n; c++) {
        vw_box p = vw_decomp_cell_box(d, c), q = vw_decomp_cell_box(e, c);
        CHECK(memcmp(&p, &q, sizeof p) == 0);
    }
    for (int ax = 0; ax < 3; ax++) {
        const double *wd = vw_decomp_grid_walls(d, ax), *we = vw_decomp_grid_walls(e, ax);
        CHECK_EQ_INT(wd == NULL, we == NULL);
        int dims[3];
        vw_decomp_dims(d, dims);
        if (wd) CHECK(memcmp(wd, we, sizeof(double) * (size_t)(dims[ax] - 1)) == 0);
    }
    check_neighbours(e, what);
    vw_segment *want = malloc(sizeof(vw_segment) * (size_t)(n + 1));
    CHECK(want);
    for (int i = 0; i < 50; i++) {
        double o[3], dir[3];
        for (int ax = 0; ax < 3; ax++) {
            o[ax] = world.lo[ax] + (world.hi[ax] - world.lo[ax]) * urand();
            dir[ax] = urand() - 0.5;
        }
        want[0].cell = -1;
        int m = vw_decomp_walk(d, o, dir, 0, INFINITY, collect, want);
        vw_walk w;
        int got = vw_walk_start(e, &w, o, dir, 0, INFINITY);
        CHECK_EQ_INT(got, m > 0);
        for (int s = 0; got && s < m; s++) {
            CHECK_EQ_INT(w.seg.cell, want[s].cell);
            CHECK(memcmp(&w.seg.t1, &want[s].t1, sizeof w.seg.t1) == 0);
            CHECK_EQ_INT(vw_walk_next(e, &w), s + 1 < m);
        }
    }
    free(want);
    vw_decomp_free(e);
}

static void check_tree(tree *t, vw_decomp_kind kind, int framed, const char *what)
{
    /* A frame permuting the axes: orthonormal and exact. */
    static const double perm[9] = {0, 1, 0, 0, 0, 1, 1, 0, 0};
    vw_decomp *d;
    CHECK_EQ_INT(vw_decomp_create_kd(&world, t->nodes, t->nn, framed ? perm : NULL, kind, &d),
                 VW_OK);
    CHECK_EQ_INT(vw_decomp_cell_count(d), t->ncells);
    check_neighbours(d, what);
    check_clone(d, what);
    vw_decomp_free(d);
}

int main(void)
{
    /* Axis sets: one axis (each), two, all three. */
    static const int axis_sets[] = {1, 2, 4, 3, 5, 6, 7};
    char what[96];
    for (int round = 0; round < 140; round++) {
        int axes = axis_sets[round % 7];
        int n = 1 + irand(round < 70 ? 40 : 400);
        tree t;
        tree_init(&t, 2048);
        grow_random(&t, n, axes);
        snprintf(what, sizeof what, "random tree %d (%d cells, axes %d)", round, t.ncells, axes);
        check_tree(&t, VW_DECOMP_DIVIDED, round & 1, what);
        tree_free(&t);

        tree_init(&t, 2048);
        grow_staggered(&t, round < 70 ? 4 : 8, axes);
        snprintf(what, sizeof what, "staggered tree %d (%d cells, axes %d)", round, t.ncells,
                 axes);
        check_tree(&t, VW_DECOMP_STAGGERED, round & 2, what);
        /* Then divided further: a staggered tree with grid cuts through its cells. */
        grow_random(&t, t.ncells + 1 + irand(t.ncells), axes);
        snprintf(what, sizeof what, "staggered and divided tree %d (%d cells, axes %d)", round,
                 t.ncells, axes);
        check_tree(&t, VW_DECOMP_DIVIDED, 0, what);
        tree_free(&t);
    }
    /* One large tree, deep and shallow parts. */
    {
        tree t;
        tree_init(&t, 3000);
        grow_random(&t, 3000, 7);
        check_tree(&t, VW_DECOMP_DIVIDED, 0, "large random tree");
        tree_free(&t);
    }
    /* Grids: uniform and uneven walls, 1 to 3 dimensions, with a rotated frame. */
    for (int round = 0; round < 30; round++) {
        int dims[3], axes = axis_sets[round % 7];
        double *walls[3] = {0};
        for (int a = 0; a < 3; a++) {
            dims[a] = axes >> a & 1 ? 1 + irand(7) : 1;
            walls[a] = malloc(sizeof(double) * (size_t)dims[a]);
            CHECK(walls[a]);
            double w = world.hi[a] - world.lo[a];
            for (int i = 1; i < dims[a]; i++) /* uneven: each wall up to 0.4 of a cell off */
                walls[a][i - 1] =
                    world.lo[a] + w * (i + (round & 2 ? 0.8 * (urand() - 0.5) : 0)) / dims[a];
        }
        double c = cos(0.3), s = sin(0.3);
        double frame[9] = {c, 0, -s, 0, 1, 0, s, 0, c};
        const double *cw[3] = {walls[0], walls[1], walls[2]};
        vw_decomp *d;
        CHECK_EQ_INT(vw_decomp_create_grid_walls(&world, dims, cw, round & 4 ? frame : NULL, &d),
                     VW_OK);
        snprintf(what, sizeof what, "grid %dx%dx%d (round %d)", dims[0], dims[1], dims[2], round);
        check_neighbours(d, what);
        for (int cell = 0; cell < vw_decomp_cell_count(d); cell++)
            for (int f = 0; f < 6; f++) CHECK(vw_decomp_neighbours(d, cell, f, NULL, 0) <= 1);
        check_clone(d, what);
        vw_decomp_free(d);
        for (int a = 0; a < 3; a++) free(walls[a]);
    }
    /* The trees were not trivial: many pairs, and faces with several neighbours. */
    CHECK(pairs_total > 100000);
    CHECK(multi_faces > 1000);
    printf("%ld neighbour entries, %ld faces with several\n", pairs_total, multi_faces);
    TEST_DONE();
}
