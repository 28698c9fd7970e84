/* test_decomp.c - the decomposition's invariants, checked against brute force:
 * cells tile the world, point location, ray walks (order, contiguity, restart),
 * neighbour symmetry, front-to-back order, object placement, layout strings.
 */
#include <string.h>

#include "vw_test.h"
#include "vwalls/vwalls.h"

static uint64_t rng = 12345;
static double urand(void)
{
    uint64_t z = vw_test_mix(rng);
    rng += 0x9e3779b97f4a7c15ull;
    return (double)(z >> 11) * 0x1.0p-53;
}

static int inside(const vw_box *b, const double q[3])
{
    for (int a = 0; a < 3; a++)
        if (q[a] < b->lo[a] || q[a] > b->hi[a]) return 0;
    return 1;
}

typedef struct segs {
    vw_segment s[VW_MAX_CELLS];
    int n;
} segs;
static segs walk_a, walk_b;

static int collect(const vw_segment *s, void *user)
{
    segs *w = user;
    w->s[w->n++] = *s;
    return 1;
}

/* vw_walk from o (and, with resume, restarted from each segment as a received ray is)
   gives exactly the segments of `want`, vw_decomp_walk's walk of the same ray. */
static void check_carried(const vw_decomp *d, const double o[3], const double dir[3],
                          const segs *want, int resume)
{
    vw_walk w;
    int got = vw_walk_start(d, &w, o, dir, 0, INFINITY);
    CHECK_EQ_INT(got, want->n > 0);
    for (int s = 0; got && s < want->n; s++) {
        CHECK_EQ_INT(w.seg.cell, want->s[s].cell);
        CHECK(memcmp(&w.seg.t0, &want->s[s].t0, sizeof w.seg.t0) == 0);
        CHECK(memcmp(&w.seg.t1, &want->s[s].t1, sizeof w.seg.t1) == 0);
        if (resume) {
            vw_walk r;
            vw_walk_resume(d, &r, o, dir, &want->s[s], w.tmax);
            w = r;
        }
        CHECK_EQ_INT(vw_walk_next(d, &w), s + 1 < want->n);
    }
}

/* Does the ray cross box b (frame coordinates) over an interval of positive length
   within [t0, t1]? Brute force slab test, with a tolerance that only admits
   grazing contacts the walk may legitimately skip. */
static int crosses(const vw_box *b, const double o[3], const double d[3], double t0, double t1,
                   double *lo, double *hi)
{
    for (int a = 0; a < 3; a++) {
        if (d[a] == 0) {
            if (o[a] < b->lo[a] || o[a] > b->hi[a]) return 0;
            continue;
        }
        double ta = (b->lo[a] - o[a]) / d[a], tb = (b->hi[a] - o[a]) / d[a];
        if (ta > tb) {
            double t = ta;
            ta = tb;
            tb = t;
        }
        if (ta > t0) t0 = ta;
        if (tb < t1) t1 = tb;
    }
    *lo = t0;
    *hi = t1;
    return t1 - t0 > 1e-9;
}

/* Frame coordinates q to world coordinates (F^T q; q itself without a frame). */
static void frame_to_world(const double *F, const double q[3], double out[3])
{
    for (int a = 0; a < 3; a++) out[a] = F ? F[a] * q[0] + F[3 + a] * q[1] + F[6 + a] * q[2] : q[a];
}

/* vw_decomp_cone_cell against the walk: an eye outside the world looks at it through
   small cones (an image tile's four corner rays); where a cone gets a cell, rays drawn
   at random inside the cone, and its generators, all start their walk in that cell.
   Most small cones get one (the answer is of use). From inside the world every cone
   gets the eye's cell, when the eye lies away from its walls, and none from a wall. */
static void check_cones(const vw_decomp *d)
{
    vw_box w = vw_decomp_world(d);
    const double *F = vw_decomp_frame(d);
    int answered = 0, asked = 0;
    for (int i = 0; i < 300; i++) {
        /* An eye on a sphere around the world (world coordinates), looking at a point
           of the world's box in frame coordinates turned to the world's. */
        double eye[3], q[3], at[3];
        double th = 2 * M_PI * urand(), z = 2 * urand() - 1, r = sqrt(1 - z * z);
        double dir0[3] = {r * cos(th), r * sin(th), z};
        for (int a = 0; a < 3; a++) {
            q[a] = w.lo[a] + (w.hi[a] - w.lo[a]) * urand();
            eye[a] = 0.5 + 3 * dir0[a];
        }
        frame_to_world(F, q, at);
        double fwd[3], u[3], v[3];
        for (int a = 0; a < 3; a++) fwd[a] = at[a] - eye[a];
        /* two directions across it */
        double t[3] = {fabs(fwd[0]) < 0.5 ? 1 : 0, fabs(fwd[0]) < 0.5 ? 0 : 1, 0};
        u[0] = fwd[1] * t[2] - fwd[2] * t[1], u[1] = fwd[2] * t[0] - fwd[0] * t[2],
        u[2] = fwd[0] * t[1] - fwd[1] * t[0];
        v[0] = fwd[1] * u[2] - fwd[2] * u[1], v[1] = fwd[2] * u[0] - fwd[0] * u[2],
        v[2] = fwd[0] * u[1] - fwd[1] * u[0];
        double lu = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
        double lv = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        double half = 0.002 + 0.05 * urand() * urand(); /* the cone's spread */
        double gen[4][3];
        for (int k = 0; k < 4; k++)
            for (int a = 0; a < 3; a++)
                gen[k][a] = fwd[a] + half * ((k & 1) ? 1 : -1) * u[a] / lu * 3 +
                            half * ((k & 2) ? 1 : -1) * v[a] / lv * 3;
        int c = vw_decomp_cone_cell(d, eye, (const double(*)[3])gen, 4);
        asked++;
        if (c < 0) continue;
        answered++;
        CHECK(c < vw_decomp_cell_count(d));
        for (int s = 0; s < 40; s++) {
            double wgt[4], sum = 0, dir[3] = {0, 0, 0};
            for (int k = 0; k < 4; k++) sum += wgt[k] = s < 4 ? (k == s) : urand();
            for (int k = 0; k < 4; k++)
                for (int a = 0; a < 3; a++) dir[a] += wgt[k] / sum * gen[k][a];
            vw_segment f;
            CHECK(vw_decomp_first_segment(d, eye, dir, 0, INFINITY, &f));
            CHECK_EQ_INT(f.cell, c);
        }
    }
    CHECK(answered > asked / 3);
    /* From inside the world: the cell that holds the eye, for any cone, when the eye
       lies away from its walls (a cell's centre); none from a point on a wall. */
    double gen[2][3] = {{1, 0.1, 0.1}, {-0.2, 1, 0.3}};
    for (int c = 0; c < vw_decomp_cell_count(d); c++) {
        vw_box b = vw_decomp_cell_box(d, c);
        double q[3], in[3];
        for (int a = 0; a < 3; a++) q[a] = 0.5 * (b.lo[a] + b.hi[a]);
        frame_to_world(F, q, in);
        CHECK_EQ_INT(vw_decomp_cone_cell(d, in, (const double(*)[3])gen, 2), c);
        for (int k = 0; k < 2; k++) {
            vw_segment f;
            CHECK(vw_decomp_first_segment(d, in, gen[k], 0, INFINITY, &f));
            CHECK_EQ_INT(f.cell, c);
        }
        CHECK_EQ_INT(vw_decomp_cone_cell(d, in, (const double(*)[3])gen, 0), -1);
        if (c == 0 && vw_decomp_cell_count(d) > 1) { /* on its wall */
            for (int a = 0; a < 3; a++) q[a] = b.hi[a] < w.hi[a] ? b.hi[a] : q[a];
            frame_to_world(F, q, in);
            CHECK_EQ_INT(vw_decomp_cone_cell(d, in, (const double(*)[3])gen, 2), -1);
        }
    }
}

static void check_decomp(const vw_decomp *d)
{
    int n = vw_decomp_cell_count(d);
    vw_box world = vw_decomp_world(d);
    double wvol = 1, vol = 0;
    for (int a = 0; a < 3; a++) wvol *= world.hi[a] - world.lo[a];
    for (int c = 0; c < n; c++) {
        vw_box b = vw_decomp_cell_box(d, c);
        double v = 1;
        for (int a = 0; a < 3; a++) {
            CHECK(b.hi[a] > b.lo[a]);
            v *= b.hi[a] - b.lo[a];
        }
        vol += v;
    }
    CHECK_NEAR(vol, wvol, 1e-9 * wvol);

    /* Random points: exactly one cell holds each (interior points), and locate finds it. */
    const double *F = vw_decomp_frame(d);
    for (int i = 0; i < 2000; i++) {
        double q[3], p[3];
        for (int a = 0; a < 3; a++) q[a] = world.lo[a] + urand() * (world.hi[a] - world.lo[a]);
        /* q is in frame coordinates; p = F^T q in world coordinates, as the library's
           inverse of vw_decomp_to_frame gives it too */
        frame_to_world(F, q, p);
        double pp[3];
        vw_decomp_from_frame(d, q, pp);
        CHECK(memcmp(p, pp, sizeof p) == 0);
        double qq[3];
        vw_decomp_to_frame(d, p, qq);
        int holders = 0, holder = -1;
        for (int c = 0; c < n; c++) {
            vw_box b = vw_decomp_cell_box(d, c);
            if (inside(&b, qq)) holders++, holder = c;
        }
        CHECK_EQ_INT(holders, 1);
        CHECK_EQ_INT(vw_decomp_locate(d, p, NULL), holder);
    }

    /* Neighbours: symmetric, and touching with positive area. */
    for (int c = 0; c < n; c++)
        for (int f = 0; f < 6; f++) {
            int nb[VW_MAX_CELLS];
            int k = vw_decomp_neighbours(d, c, f, nb, VW_MAX_CELLS);
            for (int i = 0; i < k; i++) {
                int back[VW_MAX_CELLS];
                int m = vw_decomp_neighbours(d, nb[i], f ^ 1, back, VW_MAX_CELLS);
                int found = 0;
                for (int j = 0; j < m; j++) found |= back[j] == c;
                CHECK(found);
            }
        }

    /* Ray walks against brute force, contiguity, restart, front-to-back order. */
    int *order = malloc(sizeof(int) * (size_t)n), *rank = malloc(sizeof(int) * (size_t)n);
    for (int i = 0; i < 300; i++) {
        double o[3], dir[3], qo[3], qd[3];
        for (int a = 0; a < 3; a++) {
            double ext = world.hi[a] - world.lo[a];
            o[a] = world.lo[a] - 0.5 * ext + 2 * ext * urand();
            dir[a] = urand() - 0.5;
        }
        if (i % 7 == 0) dir[i % 3] = 0; /* axis-parallel components */
        if (i % 5 == 1) {
            /* Through a corner of a cell, with dyadic directions: the ray meets two or
               three walls at the same t, ties on which the walk, its first-segment
               descent and a restart at an exit must agree. */
            vw_box cb = vw_decomp_cell_box(d, i % n);
            const double *F = vw_decomp_frame(d);
            double q[3], p[3], v[3];
            static const double steps[] = {0.5, -0.5, 0.25, -0.25, 0};
            for (int a = 0; a < 3; a++) {
                q[a] = (i >> a) & 2 ? cb.hi[a] : cb.lo[a];
                v[a] = steps[(unsigned)(i / 5 + 3 * a) % 5];
            }
            if (v[0] == 0 && v[1] == 0 && v[2] == 0) v[0] = 0.5;
            for (int a = 0; a < 3; a++) { /* frame -> world: F^T */
                p[a] = F ? F[a] * q[0] + F[3 + a] * q[1] + F[6 + a] * q[2] : q[a];
                dir[a] = F ? F[a] * v[0] + F[3 + a] * v[1] + F[6 + a] * v[2] : v[a];
            }
            for (int a = 0; a < 3; a++) o[a] = p[a] - 2 * dir[a];
        }
        walk_a.n = 0;
        vw_decomp_walk(d, o, dir, 0, INFINITY, collect, &walk_a);
        {
            vw_segment f;
            int got = vw_decomp_first_segment(d, o, dir, 0, INFINITY, &f);
            CHECK_EQ_INT(got, walk_a.n > 0);
            if (got) CHECK(f.cell == walk_a.s[0].cell && f.t0 == walk_a.s[0].t0 &&
                           f.t1 == walk_a.s[0].t1);
        }
        /* Clip once, then step from exit to exit without clipping: the same walk. */
        double c0 = 0, c1 = INFINITY;
        int clipped = vw_decomp_clip(d, o, dir, &c0, &c1);
        CHECK_EQ_INT(clipped, walk_a.n > 0);
        for (int s = 0; clipped && s <= walk_a.n; s++) {
            vw_segment f;
            int got = vw_decomp_next_segment(d, o, dir, s ? walk_a.s[s - 1].t1 : c0, c1, &f);
            CHECK_EQ_INT(got, s < walk_a.n);
            if (got)
                CHECK(f.cell == walk_a.s[s].cell && f.t0 == walk_a.s[s].t0 &&
                      f.t1 == walk_a.s[s].t1);
        }
        /* The carried walk steps through the same segments, bit for bit, from the start
           and resumed at any segment (as a ray received in a message); and from a point
           inside each segment, as a secondary ray leaves a hit. */
        check_carried(d, o, dir, &walk_a, 0);
        check_carried(d, o, dir, &walk_a, 1);
        for (int s = 0; s < walk_a.n; s++) {
            double mid = 0.5 * (walk_a.s[s].t0 + walk_a.s[s].t1), p[3];
            if (!isfinite(mid)) continue;
            for (int a = 0; a < 3; a++) p[a] = o[a] + mid * dir[a];
            walk_b.n = 0;
            vw_decomp_walk(d, p, dir, 0, INFINITY, collect, &walk_b);
            check_carried(d, p, dir, &walk_b, 0);
        }
        vw_decomp_to_frame(d, o, qo);
        vw_decomp_to_frame(d, dir, qd);
        for (int s = 0; s < walk_a.n; s++) {
            CHECK(walk_a.s[s].t0 < walk_a.s[s].t1);
            if (s) CHECK(walk_a.s[s].t0 == walk_a.s[s - 1].t1); /* the same double */
            /* Restarting at an exit gives the rest of the walk, bit for bit. */
            walk_b.n = 0;
            vw_decomp_walk(d, o, dir, walk_a.s[s].t0, INFINITY, collect, &walk_b);
            CHECK_EQ_INT(walk_b.n, walk_a.n - s);
            for (int k = 0; k < walk_b.n; k++) {
                CHECK_EQ_INT(walk_b.s[k].cell, walk_a.s[s + k].cell);
                CHECK(walk_b.s[k].t1 == walk_a.s[s + k].t1);
            }
            /* The first-segment fast path is the walk's first segment, bit for bit. */
            vw_segment f;
            CHECK(vw_decomp_first_segment(d, o, dir, walk_a.s[s].t0, INFINITY, &f));
            CHECK_EQ_INT(f.cell, walk_a.s[s].cell);
            CHECK(memcmp(&f.t0, &walk_a.s[s].t0, sizeof f.t0) == 0);
            CHECK(memcmp(&f.t1, &walk_a.s[s].t1, sizeof f.t1) == 0);
        }
        /* Every cell the ray really crosses is in the walk, and only those. */
        for (int c = 0; c < n; c++) {
            vw_box b = vw_decomp_cell_box(d, c);
            double lo = 0, hi = 0;
            int want = crosses(&b, qo, qd, 0, INFINITY, &lo, &hi);
            int got = 0;
            for (int s = 0; s < walk_a.n; s++)
                if (walk_a.s[s].cell == c) {
                    got = 1;
                    CHECK_NEAR(walk_a.s[s].t0, lo, 1e-9 * (1 + fabs(lo)));
                    CHECK_NEAR(walk_a.s[s].t1, hi, 1e-9 * (1 + fabs(hi)));
                }
            /* A ray along a wall touches the cells on both sides; the walk gives it to
               one of them: brute force cannot judge the corner rays there. */
            if (want && i % 5 != 1) CHECK(got);
        }
        /* Front-to-back from the origin (when inside): the walk respects that order. */
        if (vw_decomp_locate(d, o, dir) >= 0) {
            vw_decomp_front_to_back(d, o, order);
            for (int k = 0; k < n; k++) rank[order[k]] = k;
            for (int s = 1; s < walk_a.n; s++)
                CHECK(rank[walk_a.s[s].cell] > rank[walk_a.s[s - 1].cell]);
        }
    }
    free(order);
    free(rank);

    /* Placement: a box lands in exactly the cells it overlaps. */
    for (int i = 0; i < 300; i++) {
        vw_box b;
        for (int a = 0; a < 3; a++) {
            double ext = world.hi[a] - world.lo[a];
            double c = world.lo[a] + ext * urand(), r = 0.2 * ext * urand();
            b.lo[a] = c - r;
            b.hi[a] = c + r;
        }
        if (F) continue; /* under rotation the frame box is conservative: skip brute force */
        int cells[VW_MAX_CELLS];
        int k = vw_decomp_cells_overlapping(d, &b, 0, cells, VW_MAX_CELLS);
        int want = 0;
        for (int c = 0; c < n; c++) {
            vw_box cb = vw_decomp_cell_box(d, c);
            int ov = 1;
            for (int a = 0; a < 3; a++) ov &= b.lo[a] <= cb.hi[a] && b.hi[a] >= cb.lo[a];
            int got = 0;
            for (int j = 0; j < k; j++) got |= cells[j] == c;
            CHECK_EQ_INT(got, ov);
            want += ov;
        }
        CHECK_EQ_INT(k, want);
    }
    check_cones(d);
}

/* A staggered kd-tree: 3 x slabs, each cut in y at its own place, each column in z. */
static vw_decomp *make_staggered(const vw_box *world)
{
    vw_kd_node nodes[64];
    int nn = 0, cell = 0;
    double xs[2] = {0.3, 0.55};
    /* root: x < 0.3 | rest; rest: x < 0.55 | x >= 0.55 */
    int root = nn++, rest = nn++;
    int slab[3];
    for (int s = 0; s < 3; s++) {
        int ysplit = nn++;
        slab[s] = ysplit;
        double y = 0.2 + 0.25 * s;
        nodes[ysplit] = (vw_kd_node){1, y, -1, -1, -1};
        for (int side = 0; side < 2; side++) {
            int zs = nn++;
            nodes[zs] = (vw_kd_node){2, 0.1 + 0.3 * s + 0.2 * side, nn, nn + 1, -1};
            nodes[nn] = (vw_kd_node){-1, 0, -1, -1, cell++};
            nodes[nn + 1] = (vw_kd_node){-1, 0, -1, -1, cell++};
            nn += 2;
            if (side == 0)
                nodes[ysplit].left = zs;
            else
                nodes[ysplit].right = zs;
        }
    }
    nodes[root] = (vw_kd_node){0, xs[0], slab[0], rest, -1};
    nodes[rest] = (vw_kd_node){0, xs[1], slab[1], slab[2], -1};
    vw_decomp *d = NULL;
    CHECK_EQ_INT(vw_decomp_create_kd(world, nodes, nn, NULL, VW_DECOMP_STAGGERED, &d), VW_OK);
    return d;
}

int main(void)
{
    vw_box world = {{0, 0, 0}, {1, 1, 1}};
    const char *layouts[] = {"1", "2", "2x4", "2x2x2", "3x3x3", "4x4x4", "1x1x5", "7x3x2"};
    for (size_t i = 0; i < sizeof layouts / sizeof layouts[0]; i++) {
        int dims[3];
        CHECK_EQ_INT(vw_layout_parse(layouts[i], dims, NULL, 0), VW_OK);
        vw_decomp *d;
        CHECK_EQ_INT(vw_decomp_create_grid(&world, dims, &d), VW_OK);
        CHECK_EQ_INT(vw_decomp_cell_count(d), dims[0] * dims[1] * dims[2]);
        check_decomp(d);
        /* Grid invariant: one neighbour per face at most. */
        for (int c = 0; c < vw_decomp_cell_count(d); c++)
            for (int f = 0; f < 6; f++) CHECK(vw_decomp_neighbours(d, c, f, NULL, 0) <= 1);
        vw_decomp_free(d);
    }
    /* Uneven walls, and a rotated frame. */
    {
        int dims[3] = {3, 2, 2};
        double wx[2] = {0.1, 0.8}, wy[1] = {0.3}, wz[1] = {0.9};
        const double *walls[3] = {wx, wy, wz};
        double c = cos(0.4), s = sin(0.4);
        double frame[9] = {c, -s, 0, s, c, 0, 0, 0, 1};
        vw_decomp *d;
        CHECK_EQ_INT(vw_decomp_create_grid_walls(&world, dims, walls, NULL, &d), VW_OK);
        check_decomp(d);
        vw_decomp_free(d);
        CHECK_EQ_INT(vw_decomp_create_grid_walls(&world, dims, walls, frame, &d), VW_OK);
        CHECK(vw_decomp_frame(d) != NULL);
        check_decomp(d);
        vw_decomp *e;
        CHECK_EQ_INT(vw_decomp_clone(d, &e), VW_OK);
        check_decomp(e);
        vw_decomp_free(e);
        vw_decomp_free(d);
        double bad[1] = {1.5};
        const double *bw[3] = {wx, bad, wz};
        CHECK_EQ_INT(vw_decomp_create_grid_walls(&world, dims, bw, NULL, &d), VW_E_INVAL);
    }
    /* Staggered: several neighbours per face. */
    {
        vw_decomp *d = make_staggered(&world);
        CHECK_EQ_INT(vw_decomp_cell_count(d), 12);
        CHECK(vw_decomp_max_neighbours(d) > 6);
        check_decomp(d);
        vw_decomp_free(d);
    }
    /* Malformed trees are refused. */
    {
        vw_kd_node cyc[3] = {{0, 0.5, 1, 1, -1}, {-1, 0, -1, -1, 0}, {-1, 0, -1, -1, 1}};
        vw_decomp *d;
        CHECK_EQ_INT(vw_decomp_create_kd(&world, cyc, 3, NULL, VW_DECOMP_DIVIDED, &d), VW_E_INVAL);
        vw_kd_node outside[3] = {{0, 1.5, 1, 2, -1}, {-1, 0, -1, -1, 0}, {-1, 0, -1, -1, 1}};
        CHECK_EQ_INT(vw_decomp_create_kd(&world, outside, 3, NULL, VW_DECOMP_DIVIDED, &d), VW_E_INVAL);
        /* A frame with a NaN is no rotation: accepted, it would put every point
           outside the world (vw_decomp_locate -1). */
        vw_kd_node two[3] = {{0, 0.3, 1, 2, -1}, {-1, 0, -1, -1, 0}, {-1, 0, -1, -1, 1}};
        double nan_frame[9] = {NAN, 0, 0, 0, 1, 0, 0, 0, 1};
        CHECK_EQ_INT(vw_decomp_create_kd(&world, two, 3, nan_frame, VW_DECOMP_DIVIDED, &d), VW_E_INVAL);
        int dims[3] = {2, 1, 1};
        CHECK_EQ_INT(vw_decomp_create_grid_walls(&world, dims, NULL, nan_frame, &d), VW_E_INVAL);
        /* A tree is not a grid: it has no walls per axis, and a clone made as a grid
           would have moved the wall at 0.3 to 0.5. */
        CHECK_EQ_INT(vw_decomp_create_kd(&world, two, 3, NULL, VW_DECOMP_GRID, &d), VW_E_INVAL);
        CHECK_EQ_INT(vw_decomp_create_kd(&world, two, 3, NULL, (vw_decomp_kind)7, &d), VW_E_INVAL);
        CHECK_EQ_INT(vw_decomp_create_kd(&world, two, 3, NULL, VW_DECOMP_DIVIDED, &d), VW_OK);
        vw_decomp *e;
        CHECK_EQ_INT(vw_decomp_clone(d, &e), VW_OK);
        CHECK(vw_decomp_equal(d, e));
        CHECK_EQ_INT(vw_decomp_cell_box(e, 0).hi[0] == 0.3, 1);
        vw_decomp_free(e);
        vw_decomp_free(d);
    }
    /* Layout strings. */
    {
        int dims[3];
        char err[128];
        const char *bad[] = {"", "x", "2x", "x2", "0", "2x0", "4x0x2", "-1", "2x2x2x2", "a", "2y3",
                             "99999999", "100x100x100", "4x100000"};
        for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
            CHECK_EQ_INT(vw_layout_parse(bad[i], dims, err, sizeof err), VW_E_INPUT);
            CHECK(strstr(err, "layout") != NULL);
            CHECK(dims[0] == 1 && dims[1] == 1 && dims[2] == 1); /* not half parsed */
        }
        CHECK_EQ_INT(vw_layout_parse("2X3", dims, err, sizeof err), VW_OK);
        CHECK_EQ_INT(dims[0] * 10 + dims[1] * 100 + dims[2], 2 * 10 + 3 * 100 + 1);
    }
    TEST_DONE();
}
