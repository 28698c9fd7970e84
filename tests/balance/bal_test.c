/* bal_test.c - tests of the load balancers and the mappers, one executable, one test per
 * subcommand (registered in tests/balance.cmake):
 *   identical SCENE WxH   every strategy (and mapping) renders the same fixed-point sums
 *                         as one cell on one worker
 *   conserve              migration keeps every object in exactly the cells its bounds
 *                         overlap (ids, counts and checksums) through a chain of balancers;
 *                         worker speeds of 0 or less, a min_width that is no fraction
 *                         and negative dims refused, with a message naming them
 *   staggered8            staggered on 2x2x2 keeps 2 slabs x 2 columns x 2 cells round
 *                         after round, and reaches lambda <= 1.30, below tensor's, on the
 *                         counted work of a 50%-clustered 1000-sphere scene
 *   shares                tensor and staggered with unequal numbers of cells a worker
 *                         (3x1x1 on 2 workers, 2x2x1 on 3): lambda of counted work <= 1.25,
 *                         below what equal cells allow (4/3, 3/2); the sums unchanged
 *   divide16              divide (with its extra rounds) reaches lambda <= 1.06 on the
 *                         counted work of a 100%-clustered 1000-sphere scene, 16 cells
 *   rotate                the principal-axis frame of an oblique line of load is the line;
 *                         with unequal worker speeds, the frame of lowest lambda by speed
 *   map                   every cell mapped once; block keeps a hand layout's neighbour
 *                         share, and gives no worker more cells than ceil(cells / workers)
 *                         nor none where there are enough (2x2x2 on 3 workers: 3, 3, 2,
 *                         not 4, 4, 0); weighted gives speeds 1,1,2,4 proportional load; bad
 *                         speeds and speed lists refused; lambda never NaN
 *   duplicate             cell duplication: the same sums and exact counters with copies,
 *                         copies built from the cell's objects (and rebuilt when they
 *                         change), bad copy lists refused, and lambda of the counted work
 *                         of a 50%-clustered scene down to <= 1.10 on 8 cells; 64 cells
 *                         on 4 workers, the load on one worker's 16: lambda 4 -> <= 1.03
 *                         (the default cap of copies was 4 x workers: lambda 2)
 *   thin                  cells a few doubles wide (a box far from the origin for its
 *                         size): every balancer returns a decomposition round after
 *                         round, every point in a cell, and a box with too few doubles
 *                         for the cells asked keeps its walls; bad parameters are refused
 *   divide_thin           divide on a box a few doubles wide on x (its longest side) and
 *                         normal on y and z, the load along y (and in a frame turned
 *                         45 degrees, along z): it cuts the sides that can be cut and
 *                         divide the load, down to lambda <= 1.10 on 8 workers
 *   divide_hot            divide with an uncuttable cell (one double wide on every side)
 *                         holding a point of load, the heaviest: the other cells are
 *                         divided still (lambda 1.29 -> <= 1.05 on 2 workers, 1.75 ->
 *                         <= 1.15 on 8), the hot cell kept whole, no empty cell cut
 *   divide_rounds         divide round after round on its own result: the cells stay
 *                         within max(start, workers) + max_extra (the limit held per
 *                         round, and they piled up); divide_rounds_render: render's
 *                         rounds at 4x4x4 on 64 workers within 64 + 4 x 64
 */
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../vw_test.h"
#include "balance/balance_internal.h"
#include "raytrace/raytrace.h"
#include "vwalls/gen.h"
#include "vwalls/vwalls.h"


static vw_scene *load_scene(const char *spec)
{
    char err[512];
    vw_scene *s = NULL;
    if (!strncmp(spec, "spheres:", 8)) { /* spheres:CLUSTER:SEED */
        vw_gen_params p;
        vw_gen_params_init(&p);
        p.count = 1000;
        p.cluster = atof(spec + 8);
        const char *c = strchr(spec + 8, ':');
        p.seed = c ? (uint64_t)atoll(c + 1) : 1;
        if (vw_gen("spheres", &p, &s, err, sizeof err) != VW_OK) {
            fprintf(stderr, "gen %s: %s\n", spec, err);
            exit(1);
        }
    } else if (!strncmp(spec, "gen:", 4)) {
        vw_gen_params p;
        vw_gen_params_init(&p);
        p.size = 2;
        if (vw_gen(spec + 4, &p, &s, err, sizeof err) != VW_OK) {
            fprintf(stderr, "gen %s: %s\n", spec, err);
            exit(1);
        }
    } else if (vw_scene_read_file(spec, &s, err, sizeof err) != VW_OK) {
        fprintf(stderr, "%s\n", err);
        exit(1);
    }
    return s;
}

/* One render, optionally balanced; returns the sums (malloc'ed) and keeps the job. */
static int64_t *render(const vw_scene *s, int w, int h, const int dims[3], int workers,
                       const rt_balance *b, rt_job **keep)
{
    rt_params p;
    memset(&p, 0, sizeof p);
    p.width = w;
    p.height = h;
    memcpy(p.dims, dims, sizeof p.dims);
    p.workers = workers;
    char err[512] = "";
    rt_job *j;
    if (rt_job_create(s, &p, &j, err, sizeof err) != VW_OK) {
        fprintf(stderr, "create: %s\n", err);
        exit(1);
    }
    rt_balance_result res;
    if (b && rt_job_balance(j, b, &res, err, sizeof err) != VW_OK) {
        fprintf(stderr, "balance: %s\n", err);
        exit(1);
    }
    if (rt_job_commit(j, err, sizeof err) || rt_job_run(j, err, sizeof err)) {
        fprintf(stderr, "render failed: %s\n", err);
        exit(1);
    }
    size_t n = (size_t)w * h * 3;
    int64_t *sums = malloc(n * sizeof *sums);
    memcpy(sums, rt_job_sums(j), n * sizeof *sums);
    if (keep)
        *keep = j;
    else
        rt_job_free(j);
    return sums;
}

static void balance_spec(rt_balance *b, vw_balance_strategy s)
{
    memset(b, 0, sizeof *b);
    b->strategy = s;
    b->map = VW_MAP_BLOCK;
    vw_load_spec_init(&b->load);
    b->load.model = VW_LOAD_COUNTER; /* deterministic: the same walls on every run */
    b->load.counter = RT_C_SEGMENTS;
    b->rounds = 2;
    b->stride = 4;
}

/* ---- identical ----------------------------------------------------------------------- */

static int t_identical(const char *spec, const char *size)
{
    vw_scene *s = load_scene(spec);
    int w = 64, h = 64;
    if (size) sscanf(size, "%dx%d", &w, &h);
    int one[3] = {1, 1, 1};
    int64_t *ref = render(s, w, h, one, 1, NULL, NULL);
    size_t n = (size_t)w * h * 3;
    static const vw_balance_strategy strat[] = {VW_BALANCE_NONE, VW_BALANCE_TENSOR,
                                                VW_BALANCE_ROTATE, VW_BALANCE_STAGGERED,
                                                VW_BALANCE_DIVIDE, VW_BALANCE_DUPLICATE};
    static const int layouts[][3] = {{2, 2, 2}, {2, 4, 1}, {4, 4, 4}};
    static const vw_map_kind maps[] = {VW_MAP_BLOCK, VW_MAP_GREEDY, VW_MAP_WEIGHTED};
    double speeds[3] = {1, 2, 1};
    int k = 0;
    for (size_t si = 0; si < sizeof strat / sizeof *strat; si++)
        for (size_t li = 0; li < sizeof layouts / sizeof *layouts; li++) {
            int workers = 1 + (int)((si + li) % 3);
            rt_balance b;
            balance_spec(&b, strat[si]);
            b.map = maps[k++ % 3];
            if (b.map == VW_MAP_WEIGHTED) b.speeds = speeds;
            if (b.map == VW_MAP_WEIGHTED && workers != 3) b.speeds = NULL;
            b.load.model = (si + li) % 2 ? VW_LOAD_BUSY : VW_LOAD_COUNTER;
            rt_job *j;
            int64_t *got = render(s, w, h, layouts[li], workers, &b, &j);
            size_t diff = 0;
            for (size_t i = 0; i < n; i++) diff += got[i] != ref[i];
            EXPECT(diff == 0, "%s, %dx%dx%d, %d workers, map %s: %zu of %zu sums differ",
                  vw_balance_strategy_name(strat[si]), layouts[li][0], layouts[li][1],
                  layouts[li][2], workers, vw_map_kind_name(b.map), diff, n);
            vw_world *wd = rt_job_world(j);
            EXPECT(vw_world_counter(wd, RT_C_EYE) + vw_world_counter(wd, RT_C_REFLECT) +
                          vw_world_counter(wd, RT_C_REFRACT) + vw_world_counter(wd, RT_C_SHADOW) ==
                      vw_world_counter(wd, RT_C_ENDED),
                  "%s: rays created != rays ended", vw_balance_strategy_name(strat[si]));
            free(got);
            rt_job_free(j);
        }
    free(ref);
    vw_scene_free(s);
    return vw_test_failures ? 1 : 0;
}

/* ---- conserve: a module whose cells checksum the ids they were built with ------------- */

typedef struct tobj {
    int64_t id;
    double lo[3], hi[3];
} tobj;

typedef struct tcell {
    double sum; /* sum of hash(id): exact in a double (each < 2^20, < 2^30 objects) */
} tcell;

static double hash_id(int64_t id) { return (double)(((uint64_t)id * 2654435761u) & 0xfffff); }

static void tbounds(const void *o, vw_box *b, void *user)
{
    (void)user;
    const tobj *t = o;
    memcpy(b->lo, t->lo, sizeof b->lo);
    memcpy(b->hi, t->hi, sizeof b->hi);
}

static vw_status tbuild(vw_ctx *ctx, const void *objects, size_t n, void **state)
{
    (void)ctx;
    tcell *c = calloc(1, sizeof *c);
    if (!c) return VW_E_NOMEM;
    const tobj *o = objects;
    for (size_t i = 0; i < n; i++) c->sum += hash_id(o[i].id);
    *state = c;
    return VW_OK;
}

static void tfree(void *state, void *user)
{
    (void)user;
    free(state);
}

static double tload(vw_ctx *ctx, void *state)
{
    (void)ctx;
    return ((tcell *)state)->sum;
}

static const vw_module tmodule = {.abi = VW_MODULE_ABI, .name = "conserve",
                                  .object_size = sizeof(tobj), .object_bounds = tbounds,
                                  .cell_build = tbuild, .cell_free = tfree, .load = tload};

/* The same with one independent (no-op) message kind, so its cells may be duplicated. */
static void tnop(vw_ctx *ctx, void *state, const void *msg) { (void)ctx, (void)state, (void)msg; }
static const vw_msg_kind tkinds[] = {{"nop", 8, tnop, NULL, VW_MSG_INDEPENDENT}};
static const vw_module tmodule_ind = {.abi = VW_MODULE_ABI, .name = "conserve-dup",
                                      .object_size = sizeof(tobj), .object_bounds = tbounds,
                                      .kinds = tkinds, .nkinds = 1,
                                      .cell_build = tbuild, .cell_free = tfree, .load = tload};

/* Every cell holds exactly the objects whose bounds overlap it: count and checksum. */
static void check_placement(vw_world *w, const tobj *objs, size_t n, const char *what)
{
    const vw_decomp *d = vw_world_decomp(w);
    int nc = vw_decomp_cell_count(d);
    double *sum = calloc((size_t)nc, sizeof *sum);
    size_t *cnt = calloc((size_t)nc, sizeof *cnt);
    vw_box wb = vw_decomp_world(d);
    double ext = 0;
    for (int a = 0; a < 3; a++) ext = fmax(ext, wb.hi[a] - wb.lo[a]);
    int cells[VW_MAX_CELLS > 4096 ? 4096 : VW_MAX_CELLS];
    for (size_t i = 0; i < n; i++) {
        vw_box b;
        tbounds(&objs[i], &b, NULL);
        int m = vw_decomp_cells_overlapping(d, &b, ext * 1e-9, cells, 4096);
        EXPECT(m >= 1, "%s: object %zu is in no cell", what, i);
        for (int k = 0; k < m && k < 4096; k++) {
            sum[cells[k]] += hash_id(objs[i].id);
            cnt[cells[k]]++;
        }
    }
    for (int c = 0; c < nc; c++) {
        vw_cell_stats cs;
        vw_world_cell_stats(w, c, &cs);
        EXPECT(cs.objects == cnt[c], "%s: cell %d holds %zu objects, its bounds overlap %zu",
              what, c, cs.objects, cnt[c]);
        EXPECT(cs.load == sum[c], "%s: cell %d was built with the wrong objects (checksum %.0f, "
                                 "expected %.0f)", what, c, cs.load, sum[c]);
    }
    free(sum);
    free(cnt);
}

static int t_conserve(void)
{
    size_t n = 3000;
    tobj *objs = malloc(n * sizeof *objs);
    uint64_t r = 12345;
    for (size_t i = 0; i < n; i++) {
        objs[i].id = (int64_t)i;
        for (int a = 0; a < 3; a++) {
            r = r * 6364136223846793005ull + 1442695040888963407ull;
            double u = (double)(r >> 11) / 9007199254740992.0;
            /* Half the objects in a corner cluster: walls move far. */
            double x = i % 2 ? 0.8 * u * u * u : u;
            objs[i].lo[a] = x;
            objs[i].hi[a] = x + 0.01 + 0.02 * (double)(i % 3);
        }
    }
    vw_box world = {{-0.01, -0.01, -0.01}, {1.05, 1.05, 1.05}};
    int dims[3] = {2, 2, 2};
    vw_decomp *d;
    vw_decomp_create_grid(&world, dims, &d);
    vw_config cfg;
    vw_config_init(&cfg);
    cfg.workers = 3;
    vw_world *w;
    EXPECT(vw_world_create(&tmodule, NULL, d, &cfg, &w) == VW_OK, "create");
    vw_world_add_objects(w, objs, n);
    vw_world_commit(w);
    check_placement(w, objs, n, "initial");
    /* The load field: where the objects are (one point per object's centre). */
    vw_load_field *f;
    vw_load_field_create(&f);
    for (size_t i = 0; i < n; i++) {
        double p[3];
        for (int a = 0; a < 3; a++) p[a] = 0.5 * (objs[i].lo[a] + objs[i].hi[a]);
        vw_load_field_add_point(f, p, 1.0);
    }
    static const vw_balance_strategy chain[] = {VW_BALANCE_TENSOR, VW_BALANCE_STAGGERED,
                                                VW_BALANCE_ROTATE, VW_BALANCE_DIVIDE,
                                                VW_BALANCE_TENSOR};
    for (size_t k = 0; k < sizeof chain / sizeof *chain; k++) {
        vw_balance_params p;
        vw_balance_params_init(&p);
        p.strategy = chain[k];
        vw_balance_report rep;
        vw_status st = vw_balance_world(w, f, &p, NULL, &rep);
        EXPECT(st == VW_OK, "balance %s: %s", vw_balance_strategy_name(chain[k]), vw_status_name(st));
        EXPECT(rep.imbalance_predicted <= rep.imbalance_before + 1e-12,
              "%s made it worse: %.3f -> %.3f", vw_balance_strategy_name(chain[k]),
              rep.imbalance_before, rep.imbalance_predicted);
        EXPECT(rep.bytes_moved == rep.migrated_objects * sizeof(tobj), "bytes moved");
        vw_world_commit(w);
        check_placement(w, objs, n, vw_balance_strategy_name(chain[k]));
        printf("conserve: %-9s cells %3d lambda %.3f -> %.3f, %llu migrated, max neighbours %d\n",
               vw_balance_strategy_name(chain[k]), rep.cells, rep.imbalance_before,
               rep.imbalance_predicted, (unsigned long long)rep.migrated_objects,
               rep.max_neighbours);
    }
    /* A worker speed of 0, less, or NaN is refused, by the speeds of the call and of
       the apply step alike, and the world keeps its walls and placement. */
    {
        int cells = vw_decomp_cell_count(vw_world_decomp(w));
        const double bad[][3] = {{1, 0, 1}, {1, -1, 1}, {1, 1, NAN}, {INFINITY, 1, 1}};
        for (int i = 0; i < 4; i++)
            for (int via_apply = 0; via_apply < 2; via_apply++) {
                vw_balance_params p;
                vw_balance_params_init(&p);
                p.strategy = VW_BALANCE_TENSOR;
                vw_balance_apply ap;
                memset(&ap, 0, sizeof ap);
                if (via_apply) ap.speeds = bad[i];
                else p.speeds = bad[i];
                vw_balance_report rep;
                vw_status st = vw_balance_world(w, f, &p, &ap, &rep);
                EXPECT(st == VW_E_INVAL, "speeds %g,%g,%g (%s): %s", bad[i][0], bad[i][1],
                       bad[i][2], via_apply ? "apply" : "params", vw_status_name(st));
            }
        EXPECT(vw_decomp_cell_count(vw_world_decomp(w)) == cells, "the walls changed");
        EXPECT(strstr(vw_world_errmsg(w), "speeds must be positive") != NULL, "message: %s",
               vw_world_errmsg(w));
        /* So are a min_width that is no fraction and negative dims, each named in the
           message (a NaN min_width made NaN walls: "vw_balance_world: invalid argument"). */
        const struct {
            double min_width;
            int dim;
            const char *says;
        } wrong[] = {{NAN, 0, "min_width nan"}, {-0.1, 0, "min_width -0.1"},
                     {1.5, 0, "min_width 1.5"}, {1e-3, -2, "dims -2x0x0"}};
        for (int i = 0; i < 4; i++) {
            vw_balance_params p;
            vw_balance_params_init(&p);
            p.strategy = VW_BALANCE_TENSOR;
            p.min_width = wrong[i].min_width;
            p.dims[0] = wrong[i].dim;
            vw_balance_report rep;
            vw_status st = vw_balance_world(w, f, &p, NULL, &rep);
            EXPECT(st == VW_E_INVAL && strstr(vw_world_errmsg(w), wrong[i].says),
                   "%s: %s, message: %s", wrong[i].says, vw_status_name(st), vw_world_errmsg(w));
        }
        EXPECT(vw_decomp_cell_count(vw_world_decomp(w)) == cells, "the walls changed");
        vw_world_commit(w);
        check_placement(w, objs, n, "after bad speeds");
    }
    vw_load_field_free(f);
    vw_world_free(w);
    vw_decomp_free(d);
    free(objs);
    return vw_test_failures ? 1 : 0;
}

/* ---- staggered8 ------------------------------------------------------------------------ */

/* Whether the subtree at node is cut along axis a into 2 pieces, each cut along a + 1 ... */
static int halves(const vw_kd_node *nodes, int node, int a)
{
    if (a == 3) return nodes[node].axis < 0;
    const vw_kd_node *n = &nodes[node];
    return n->axis == a && halves(nodes, n->left, a + 1) && halves(nodes, n->right, a + 1);
}

static int t_staggered8(void)
{
    vw_scene *s = load_scene("spheres:0.5:1");
    int dims[3] = {2, 2, 2};
    static const vw_balance_strategy strat[3] = {VW_BALANCE_NONE, VW_BALANCE_TENSOR,
                                                 VW_BALANCE_STAGGERED};
    double lam[3];
    for (int k = 0; k < 3; k++) {
        rt_balance b;
        balance_spec(&b, strat[k]);
        b.rounds = 3;
        rt_job *j;
        int64_t *sums = render(s, 128, 128, dims, 8, k ? &b : NULL, &j);
        lam[k] = rt_job_work_imbalance(j, NULL);
        const vw_decomp *d = vw_world_decomp(rt_job_world(j));
        EXPECT(vw_decomp_cell_count(d) == 8, "8 cells");
        if (strat[k] == VW_BALANCE_STAGGERED) {
            /* Every round keeps the 2x2x2 layout: 2 slabs, 2 columns each, 2 cells each
               (later rounds made 8 slabs of it once: vw_decomp_dims of a staggered tree). */
            int nn;
            EXPECT(halves(vw_decomp_nodes(d, &nn), 0, 0), "staggered 2x2x2 kept its layout");
        }
        free(sums);
        rt_job_free(j);
    }
    printf("staggered8: work lambda none %.3f, tensor %.3f, staggered %.3f\n", lam[0], lam[1],
           lam[2]);
    /* Staggered cells have more freedom than a grid's: each slab and column is cut at its
       own quantiles. (The load field's resolution, k^3 points a cell, bounds how far a
       hot spot within one cell can be split.) */
    EXPECT(lam[2] <= 1.30, "staggered lambda %.3f > 1.30 (none: %.3f)", lam[2], lam[0]);
    EXPECT(lam[2] < lam[1], "staggered lambda %.3f not below tensor's %.3f", lam[2], lam[1]);
    vw_scene_free(s);
    return vw_test_failures ? 1 : 0;
}

/* ---- shares: cells of unequal load where the workers hold unequal numbers of cells ----- */

/* Tensor and staggered cut cells of equal load. With 3 cells on 2 workers (block: 2 and
   1) or 4 on 3 (2, 1, 1), equal cells leave lambda at 4/3 and 3/2 whatever the load; cut
   at each worker's share (its cells get half, or a third, of the load between them) they
   balance the workers. Uniform 1000 spheres, 128x128, counted work; the sums stay the
   unbalanced render's. */
static int t_shares(void)
{
    vw_scene *s = load_scene("spheres:0:1");
    static const struct {
        int dims[3], workers;
        double bound; /* lambda of equal cells on this mapping */
    } cases[] = {{{3, 1, 1}, 2, 4.0 / 3}, {{2, 2, 1}, 3, 1.5}};
    static const vw_balance_strategy strat[2] = {VW_BALANCE_TENSOR, VW_BALANCE_STAGGERED};
    for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
        const int *dims = cases[k].dims;
        int one[3] = {1, 1, 1};
        int64_t *ref = render(s, 128, 128, one, 1, NULL, NULL);
        rt_job *j0;
        int64_t *plain = render(s, 128, 128, dims, cases[k].workers, NULL, &j0);
        double lam0 = rt_job_work_imbalance(j0, NULL);
        rt_job_free(j0);
        free(plain);
        for (int si = 0; si < 2; si++) {
            rt_balance b;
            balance_spec(&b, strat[si]);
            rt_job *j;
            int64_t *sums = render(s, 128, 128, dims, cases[k].workers, &b, &j);
            double lam = rt_job_work_imbalance(j, NULL);
            printf("shares: %dx%dx%d on %d workers, %s: work lambda %.3f (none %.3f, equal "
                   "cells at best %.3f)\n", dims[0], dims[1], dims[2], cases[k].workers,
                   vw_balance_strategy_name(strat[si]), lam, lam0, cases[k].bound);
            EXPECT(lam <= 1.25, "%dx%dx%d on %d workers, %s: lambda %.3f > 1.25", dims[0],
                   dims[1], dims[2], cases[k].workers, vw_balance_strategy_name(strat[si]), lam);
            EXPECT(!memcmp(sums, ref, sizeof(int64_t) * 128 * 128 * 3), "%s: sums differ",
                   vw_balance_strategy_name(strat[si]));
            free(sums);
            rt_job_free(j);
        }
        free(ref);
    }
    vw_scene_free(s);
    return vw_test_failures ? 1 : 0;
}

#define DIVIDE16_MAX 1.06

/* ---- divide16: division with its extra rounds on a fully clustered scene ---------------- */

static int t_divide16(void)
{
    vw_scene *s = load_scene("spheres:1:1");
    int dims[3] = {4, 2, 2};
    double lam[2];
    for (int strat = 0; strat < 2; strat++) {
        rt_balance b;
        balance_spec(&b, strat ? VW_BALANCE_DIVIDE : VW_BALANCE_NONE);
        b.stride = 0; /* the automatic stride, which follows the divided layout */
        rt_job *j;
        int64_t *sums = render(s, 128, 128, dims, 16, strat ? &b : NULL, &j);
        lam[strat] = rt_job_work_imbalance(j, NULL);
        free(sums);
        rt_job_free(j);
    }
    printf("divide16: work lambda none %.3f, divide %.3f\n", lam[0], lam[1]);
    EXPECT(lam[1] <= DIVIDE16_MAX, "divide lambda %.3f > %.2f (none: %.3f)", lam[1], DIVIDE16_MAX,
          lam[0]);
    vw_scene_free(s);
    return vw_test_failures ? 1 : 0;
}

/* ---- rotate: the frame follows an oblique line of load --------------------------------- */

static int t_rotate(void)
{
    vw_load_field *f;
    vw_decomp *d, *t, *r;
    vw_balance_params p;
    vw_box world = {{0, 0, 0}, {1, 1, 1}};
    double dir[3] = {1 / sqrt(3.0), 1 / sqrt(3.0), 1 / sqrt(3.0)};
    /* 400 points, and 40,000: a field that large (many cells) has its candidate frames
       cut and scored coarsened (tensor.c, VW_ROTATE_POINTS), the winner cut again from
       the whole field; it must still find the line. */
    for (int big = 0; big < 2; big++) {
        int npts = big ? 40000 : 400;
        vw_load_field_create(&f);
        /* A line from (0.1,0.1,0.1) to (0.9,0.9,0.9), with a little spread across it. */
        double across[3] = {1 / sqrt(2.0), -1 / sqrt(2.0), 0};
        for (int i = 0; i < npts; i++) {
            double pt[3], off = 0.02 * ((i * 7919 % 101) / 100.0 - 0.5);
            for (int a = 0; a < 3; a++)
                pt[a] = 0.1 + 0.8 * (i / (npts - 1.0)) * dir[a] * sqrt(3.0) + off * across[a];
            vw_load_field_add_point(f, pt, 1.0);
        }
        int dims[3] = {2, 2, 2};
        vw_decomp_create_grid(&world, dims, &d);
        double load[8];
        vw_load_field_cell_loads(f, d, load);
        t = r = NULL;
        vw_balance_params_init(&p);
        p.strategy = VW_BALANCE_TENSOR;
        p.dims[0] = 2, p.dims[1] = 2, p.dims[2] = 1; /* tensor: the line crosses 2 of 4 cells */
        EXPECT(vw_balance_decompose(d, f, &p, &t, NULL) == VW_OK, "tensor");
        p.strategy = VW_BALANCE_ROTATE;
        EXPECT(vw_balance_decompose(d, f, &p, &r, NULL) == VW_OK, "rotate");
        const double *F = r ? vw_decomp_frame(r) : NULL;
        EXPECT(F != NULL, "rotate kept the identity frame");
        if (F) {
            double c = fabs(F[0] * dir[0] + F[1] * dir[1] + F[2] * dir[2]);
            EXPECT(c > 0.999, "frame x axis is not the line: cos %.4f", c);
        }
        /* The rotated world box holds the whole old world box. */
        if (r) {
            for (int i = 0; i < 8; i++) {
                double q[3] = {(double)(i & 1), (double)((i >> 1) & 1), (double)((i >> 2) & 1)};
                EXPECT(vw_decomp_locate(r, q, NULL) >= 0, "corner %d outside the rotated world", i);
            }
            double lt[4], lr[4];
            vw_load_field_cell_loads(f, t, lt);
            vw_load_field_cell_loads(f, r, lr);
            int ident[4] = {0, 1, 2, 3};
            double lamt = vw_balance_imbalance(lt, ident, 4, 4, NULL);
            double lamr = vw_balance_imbalance(lr, ident, 4, 4, NULL);
            printf("rotate: 2x2x1 on an oblique line of %d points: tensor %.3f, rotate %.3f\n",
                   npts, lamt, lamr);
            EXPECT(lamr <= 1.10 && lamt >= 1.5, "%d points: rotate %.3f vs tensor %.3f", npts, lamr,
                   lamt);
        }
        vw_decomp_free(t);
        vw_decomp_free(r);
        vw_decomp_free(d);
        vw_load_field_free(f);
    }

    /* Unequal workers (speeds 1 and 3, two cells): the frames are judged by lambda with
       the speeds (vw__lambda), not by max / mean of the cells. Three masses, 1, 2 and 1,
       at z = 0.5: the unrotated walls cut 1 | 3, which the fast worker's share fits
       (lambda 1); a frame along y cuts 2 | 2, max / mean 1, so rotate chose it, and
       then the fast worker takes both cells while the slow one idles (lambda 4/3). */
    vw_load_field_create(&f);
    const double masses[3][4] = {{0.2, 0.2, 0.5, 1}, {0.5, 0.8, 0.5, 2}, {0.8, 0.3, 0.5, 1}};
    for (int i = 0; i < 3; i++) vw_load_field_add_point(f, masses[i], masses[i][3]);
    int dims2[3] = {2, 1, 1};
    vw_decomp_create_grid(&world, dims2, &d);
    double speeds[2] = {1, 3};
    vw_balance_params_init(&p);
    p.gworkers = 2;
    p.speeds = speeds;
    p.strategy = VW_BALANCE_TENSOR;
    t = r = NULL;
    EXPECT(vw_balance_decompose(d, f, &p, &t, NULL) == VW_OK, "tensor with speeds");
    p.strategy = VW_BALANCE_ROTATE;
    EXPECT(vw_balance_decompose(d, f, &p, &r, NULL) == VW_OK, "rotate with speeds");
    if (t && r) {
        /* Each plan's lambda as the balancer predicts it: cells mapped by speed. */
        double lamt = 0, lamr = 0;
        for (int k = 0; k < 2; k++) {
            const vw_decomp *x = k ? r : t;
            double ld[2];
            int cw[2];
            vw_load_field_cell_loads(f, x, ld);
            CHECK_EQ_INT(vw_map_greedy(x, ld, 2, speeds, 0.0, cw), VW_OK);
            *(k ? &lamr : &lamt) = vw_balance_imbalance(ld, cw, 2, 2, speeds);
        }
        printf("rotate: speeds 1,3, masses 1, 2, 1: tensor %.3f, rotate %.3f\n", lamt, lamr);
        EXPECT(lamr <= lamt + 1e-9, "rotate %.4f predicts worse than tensor %.4f with speeds",
               lamr, lamt);
        EXPECT(fabs(lamr - 1.0) < 1e-9, "rotate with speeds 1,3: lambda %.4f, want 1", lamr);
    }
    vw_decomp_free(t);
    vw_decomp_free(r);
    vw_decomp_free(d);
    vw_load_field_free(f);
    return vw_test_failures ? 1 : 0;
}

/* ---- map --------------------------------------------------------------------------------- */

static void shares(const vw_decomp *d, const int *cw, int wpp, int *same_worker, int *same_proc,
                   int *pairs)
{
    *same_worker = *same_proc = *pairs = 0;
    int nb[64];
    for (int c = 0; c < vw_decomp_cell_count(d); c++)
        for (int f = 1; f < 6; f += 2) { /* + faces: every pair once */
            int n = vw_decomp_neighbours(d, c, f, nb, 64);
            for (int k = 0; k < n; k++) {
                (*pairs)++;
                *same_worker += cw[c] == cw[nb[k]];
                *same_proc += cw[c] / wpp == cw[nb[k]] / wpp;
            }
        }
}

static int t_map(void)
{
    vw_box world = {{0, 0, 0}, {1, 1, 1}};
    /* Every cell mapped exactly once, to a valid worker, by every mapper. */
    static const int layouts[][3] = {{2, 4, 1}, {3, 3, 3}, {8, 8, 1}, {5, 1, 1}};
    static const int pw[][2] = {{1, 1}, {2, 2}, {3, 2}, {1, 7}};
    for (size_t li = 0; li < 4; li++) {
        vw_decomp *d;
        vw_decomp_create_grid(&world, layouts[li], &d);
        int nc = vw_decomp_cell_count(d);
        double *load = malloc(sizeof(double) * (size_t)nc);
        int *cw = malloc(sizeof(int) * (size_t)nc);
        for (int c = 0; c < nc; c++) load[c] = 1.0 + (c * 7 % 5);
        for (size_t pi = 0; pi < 4; pi++)
            for (int kind = VW_MAP_BLOCK; kind <= VW_MAP_WEIGHTED; kind++) {
                int gw = pw[pi][0] * pw[pi][1];
                for (int c = 0; c < nc; c++) cw[c] = -1;
                EXPECT(vw_map_compute((vw_map_kind)kind, d, load, pw[pi][0], pw[pi][1], NULL, cw) ==
                          VW_OK,
                      "map");
                for (int c = 0; c < nc; c++)
                    EXPECT(cw[c] >= 0 && cw[c] < gw, "%s: cell %d -> worker %d of %d",
                          vw_map_kind_name((vw_map_kind)kind), c, cw[c], gw);
            }
        free(load);
        free(cw);
        vw_decomp_free(d);
    }
    /* 2x4 on 2 processes x 2 workers: block keeps at least the neighbour share of the
       hand layout (processes split y into halves, each worker one row of 2 cells):
       4 of 10 face pairs inside a worker, 8 inside a process. */
    {
        int dims[3] = {2, 4, 1};
        vw_decomp *d;
        vw_decomp_create_grid(&world, dims, &d);
        int cw[8], hand[8];
        for (int c = 0; c < 8; c++) {
            int j = c / 2;
            hand[c] = (j / 2) * 2 + (j % 2);
        }
        vw_map_block(d, 2, 2, cw);
        int sw, sp, np, hw, hp, hn;
        shares(d, cw, 2, &sw, &sp, &np);
        shares(d, hand, 2, &hw, &hp, &hn);
        printf("map: 2x4 on 2x2: block keeps %d/%d pairs in a worker, %d in a process; hand "
               "layout %d, %d\n", sw, np, sp, hw, hp);
        EXPECT(sw >= hw && sp >= hp, "block %d/%d below the hand layout %d/%d", sw, sp, hw, hp);
        int per[4] = {0};
        for (int c = 0; c < 8; c++) per[cw[c]]++;
        for (int g = 0; g < 4; g++) EXPECT(per[g] == 2, "worker %d hosts %d cells", g, per[g]);
        vw_decomp_free(d);
    }
    /* Block never leaves a worker (or a process) emptier than runs of cells would: no
       worker more than ceil(cells / workers) cells, none without a cell while there are
       enough. 2x2x2 on 3 workers was 4, 4, 0 (and a tensor balance mapped so was
       refused); on 5, 4, 0, 4, 0, 0; 3x3x3 on 4, 12, 6, 6, 3. Where the workers divide
       the grid evenly the blocks are as before (the 2x4 case above). */
    {
        static const int lay[][3] = {{2, 2, 2}, {2, 2, 2}, {2, 2, 2}, {2, 2, 2}, {3, 3, 3},
                                     {4, 4, 4}, {4, 4, 4}, {4, 4, 1}, {2, 2, 1}, {4, 2, 2}};
        static const int pw2[][2] = {{1, 3}, {1, 5}, {3, 1}, {2, 3}, {1, 4},
                                     {2, 3}, {3, 2}, {1, 5}, {1, 3}, {2, 4}};
        for (size_t i = 0; i < sizeof lay / sizeof lay[0]; i++) {
            vw_decomp *d;
            vw_decomp_create_grid(&world, lay[i], &d);
            int nc = vw_decomp_cell_count(d), gw = pw2[i][0] * pw2[i][1];
            int cw[64], per[16] = {0}, pper[16] = {0};
            EXPECT(vw_map_block(d, pw2[i][0], pw2[i][1], cw) == VW_OK, "block");
            for (int c = 0; c < nc; c++) per[cw[c]]++, pper[cw[c] / pw2[i][1]]++;
            int most = (nc + gw - 1) / gw, pmost = (nc + pw2[i][0] - 1) / pw2[i][0];
            for (int g = 0; g < gw; g++)
                EXPECT(per[g] <= most && per[g] >= 1, "block %dx%dx%d on %d x %d: worker %d "
                       "hosts %d cells (at most %d, at least 1)", lay[i][0], lay[i][1],
                       lay[i][2], pw2[i][0], pw2[i][1], g, per[g], most);
            for (int q = 0; q < pw2[i][0]; q++)
                EXPECT(pper[q] <= pmost, "block %dx%dx%d on %d x %d: process %d hosts %d cells "
                       "(at most %d)", lay[i][0], lay[i][1], lay[i][2], pw2[i][0], pw2[i][1],
                       q, pper[q], pmost);
            vw_decomp_free(d);
        }
    }
    /* Weighted: speeds 1,1,2,4 over 256 cells of uneven load -> shares 1/8,1/8,1/4,1/2. */
    {
        int dims[3] = {16, 16, 1};
        vw_decomp *d;
        vw_decomp_create_grid(&world, dims, &d);
        double load[256], sp[4] = {1, 1, 2, 4}, got[4] = {0}, total = 0;
        int cw[256];
        for (int c = 0; c < 256; c++) total += load[c] = 1.0 + (double)((c * 37) % 11);
        EXPECT(vw_map_weighted(d, load, 4, sp, cw) == VW_OK, "weighted");
        for (int c = 0; c < 256; c++) got[cw[c]] += load[c];
        /* Speeds are relative: scaled by 1e300 (or by 1e-300) they map alike. With raw
           speeds near 1e308 the finish times fell below the greedy's absolute slack,
           and two equal workers got seven cells and one. */
        double big[4], small[4];
        int cw_big[256], cw_small[256];
        for (int g = 0; g < 4; g++) big[g] = sp[g] * 1e300, small[g] = sp[g] * 1e-300;
        EXPECT(vw_map_weighted(d, load, 4, big, cw_big) == VW_OK, "weighted, speeds * 1e300");
        EXPECT(vw_map_weighted(d, load, 4, small, cw_small) == VW_OK, "weighted, speeds * 1e-300");
        EXPECT(!memcmp(cw, cw_big, sizeof cw), "speeds * 1e300 map otherwise");
        EXPECT(!memcmp(cw, cw_small, sizeof cw), "speeds * 1e-300 map otherwise");
        for (int g = 0; g < 4; g++) {
            double want = total * sp[g] / 8.0;
            printf("map: weighted worker %d speed %.0f: load %.1f, proportional share %.1f\n", g,
                   sp[g], got[g], want);
            EXPECT(fabs(got[g] - want) <= 0.10 * want, "worker %d: %.1f vs %.1f", g, got[g], want);
        }
        vw_decomp_free(d);
    }
    /* Bad speeds or slack are refused: a speed <= 0 (or a negative slack) left no
       worker near the best, and the cell went to worker -1 (a write before t[0]). */
    {
        int dims[3] = {2, 2, 2};
        vw_decomp *d;
        vw_decomp_create_grid(&world, dims, &d);
        double load[8] = {1, 2, 3, 4, 5, 6, 7, 8};
        int cw[8];
        const double bad[][4] = {{1, 1, 1, -1}, {1, 0, 1, 1}, {1, NAN, 1, 1}, {1, 1, INFINITY, 1}};
        for (int i = 0; i < 4; i++) {
            EXPECT(vw_map_greedy(d, load, 4, bad[i], 0.05, cw) == VW_E_INVAL, "speeds %d", i);
            EXPECT(vw_map_weighted(d, load, 4, bad[i], cw) == VW_E_INVAL, "speeds %d", i);
            EXPECT(vw_map_compute(VW_MAP_GREEDY, d, load, 2, 2, bad[i], cw) == VW_E_INVAL,
                   "speeds %d", i);
        }
        EXPECT(vw_map_greedy(d, load, 4, NULL, -1, cw) == VW_E_INVAL, "slack -1");
        EXPECT(vw_map_greedy(d, load, 4, NULL, NAN, cw) == VW_E_INVAL, "slack NaN");
        /* 65536 x 65536 workers are more than an int counts. */
        EXPECT(vw_map_compute(VW_MAP_GREEDY, d, load, 65536, 65536, NULL, cw) == VW_E_INVAL,
               "workers overflow");
        EXPECT(vw_map_compute(VW_MAP_BLOCK, d, load, 0, 2, NULL, cw) == VW_E_INVAL, "0 processes");
        vw_decomp_free(d);
    }
    /* lambda is never NaN: a worker of speed 0 (it used to give inf / inf, or 0 / 0
       without load), a negative or NaN speed, or a NaN, infinite or negative load give
       INFINITY; no load at all gives 1. */
    {
        double load[4] = {1, 2, 3, 4}, none[4] = {0}, nanl[4] = {1, NAN, 1, 1};
        double infl[4] = {1, INFINITY, 1, 1}, negl[4] = {1, -1, 1, 1};
        int cw[4] = {0, 1, 2, 3};
        double s1[4] = {1, 1, 1, 1}, s0[4] = {1, 0, 1, 1}, sneg[4] = {1, 1, -2, 1};
        double snan[4] = {1, 1, 1, NAN}, sinf[4] = {INFINITY, 1, 1, 1};
        double fast[4] = {0, 5, 5, 5}, s1000[4] = {1, 1000, 1000, 1000}, prop[4] = {1, 2, 3, 4};
        double s1234[4] = {1, 2, 3, 4}, slow[4] = {10, 0, 0, 0}, s7[4] = {7, 7, 7, 7};
        double sbig[4] = {1e308, 1e308, 1e308, 1e308};
        struct { const double *load, *speeds; double want; const char *what; } cases[] = {
            {load, s1, 4 / 2.5, "1,2,3,4"},       {load, NULL, 4 / 2.5, "no speeds"},
            {none, s1, 1, "no load"},             {load, s0, INFINITY, "speed 0"},
            {none, s0, INFINITY, "speed 0, no load"}, {load, sneg, INFINITY, "speed -2"},
            {load, snan, INFINITY, "speed NaN"},  {load, sinf, INFINITY, "speed inf"},
            {nanl, NULL, INFINITY, "load NaN"},   {infl, s1, INFINITY, "load inf"},
            {negl, NULL, INFINITY, "load -1"},
            /* Unequal speeds: the slowest worker's time against a split by speed. The
               load evenly on the three fast workers of 1,1000,1000,1000 is 3001/3000
               (it was 4/3: the idle slow worker pulled the mean down); a split in
               proportion to the speeds is 1; all on the slowest of 1,2,3,4 takes 10
               times the best; equal speeds of any size are max / mean. */
            {fast, s1000, 3001.0 / 3000, "even on the fast of 1,1000,1000,1000"},
            {prop, s1234, 1, "in proportion to 1,2,3,4"},
            {slow, s1234, 10, "all on the slowest of 1,2,3,4"},
            {load, s7, 4 / 2.5, "speeds 7"},      {load, sbig, 4 / 2.5, "speeds 1e308"},
        };
        for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
            double lam = vw_balance_imbalance(cases[i].load, cw, 4, 4, cases[i].speeds);
            EXPECT(lam == cases[i].want || fabs(lam - cases[i].want) <= 1e-12,
                   "imbalance, %s: %g (want %g)", cases[i].what, lam, cases[i].want);
        }
    }
    /* Speed lists: exactly n positive numbers between commas, in decimal notation with
       no white space or '+' before them. A trailing comma ("1,2," for 2 workers) used to
       pass as the two speeds before it. */
    {
        double sp[3] = {0};
        EXPECT(vw_map_parse_speeds("1,2.5", sp, 2) == VW_OK && sp[0] == 1 && sp[1] == 2.5,
               "'1,2.5': %g %g", sp[0], sp[1]);
        static const char *const bad[] = {"1,2,", "1,2,,", ",1,2", "1,,2", "1,2,3", "1", "",
                                          "1,0", "1,-2", "1,nan", "1,inf", "1;2", "1,2x", "1, ",
                                          "0x1,2", "1,0X2", "1, 0x2", "1,+0x2", "1,2e0x",
                                          /* as the command line's numbers */
                                          " 1,2", "1, 2", "+1,2", "1,+2", "1,\t2"};
        for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
            EXPECT(vw_map_parse_speeds(bad[i], sp, 2) == VW_E_INVAL, "'%s' accepted", bad[i]);
        EXPECT(vw_map_parse_speeds("1,2,", sp, 3) == VW_E_INVAL, "'1,2,' for 3 workers");
        EXPECT(vw_map_parse_speeds("1e0,2.5E-1", sp, 2) == VW_OK && sp[1] == 0.25,
               "'1e0,2.5E-1': %g %g", sp[0], sp[1]);
    }
    return vw_test_failures ? 1 : 0;
}

/* ---- duplicate ------------------------------------------------------------------------- */

/* The plan alone (vw__balance_duplicate_plan), on loads whose best plan and lambda are
   known: a copy's share of its cell follows its worker's speed, as the runtime's does. */
static void duplicate_plans(void)
{
    int pc[8], pw[8], np;
    double lam;
    /* One cell (load 4) on worker 0 of two with speeds 1 and 3: one copy on worker 1;
       the copies take 1 and 3 of the 4 and are done together (lambda 1). With equal
       shares (2 and 2) the plan would have predicted 1.5. */
    {
        double load[1] = {4}, speeds[2] = {1, 3};
        int cw[1] = {0};
        EXPECT(vw__balance_duplicate_plan(load, cw, 1, 2, speeds, 0.03, 8, pc, pw, &np, &lam) == VW_OK,
               "plan");
        EXPECT(np == 1 && pc[0] == 0 && pw[0] == 1, "speeds 1,3: %d copies", np);
        EXPECT(fabs(lam - 1.0) < 1e-12, "speeds 1,3: lambda %.6f, expected 1", lam);
    }
    /* Two cells of load 3 on the two workers (speeds 1, 3): lambda 3 / 1.5 = 2 before
       (a split by speed takes 6 / 4); the slow worker's cell gets a copy (the slowest
       worker then takes 1.75: lambda 1.75 / 1.5), then the other one (1). */
    {
        double load[2] = {3, 3}, speeds[2] = {1, 3};
        int cw[2] = {0, 1};
        EXPECT(vw__balance_duplicate_plan(load, cw, 2, 2, speeds, 0.03, 8, pc, pw, &np, &lam) == VW_OK,
               "plan");
        EXPECT(np == 2, "two cells, speeds 1,3: %d copies, expected 2", np);
        EXPECT(fabs(lam - 1.0) < 1e-12, "two cells, speeds 1,3: lambda %.6f, expected 1", lam);
        EXPECT(vw__balance_duplicate_plan(load, cw, 2, 2, speeds, 0.03, 1, pc, pw, &np, &lam) == VW_OK,
               "plan");
        EXPECT(np == 1 && pc[0] == 0 && pw[0] == 1 && fabs(lam - 1.75 / 1.5) < 1e-12,
               "one copy at most: cell %d on worker %d, lambda %.6f, expected cell 0 on 1, 7/6",
               np ? pc[0] : -1, np ? pw[0] : -1, lam);
    }
    /* lambda by the documented definition (vw_balance_imbalance): the slowest worker's
       time against a split by speed, not max / mean of the times. Load 4 on the fast
       worker of speeds 1,3 is lambda 4/3 (max / mean said 2); all of it on the fast one
       of 1,1000 is within the tolerance already, so no copy is planned (max / mean said
       2 and copied the cell to the slow worker). */
    {
        double load[1] = {4}, speeds[2] = {1, 3}, s1000[2] = {1, 1000};
        int cw[1] = {1};
        EXPECT(vw__balance_duplicate_plan(load, cw, 1, 2, speeds, 0.03, 0, pc, pw, &np, &lam) == VW_OK,
               "plan");
        double want = vw_balance_imbalance(load, cw, 1, 2, speeds);
        EXPECT(np == 0 && fabs(lam - want) < 1e-12 && fabs(want - 4.0 / 3) < 1e-12,
               "no copies, speeds 1,3: %d copies, lambda %.6f, expected %.6f", np, lam, want);
        EXPECT(vw__balance_duplicate_plan(load, cw, 1, 2, s1000, 0.03, 8, pc, pw, &np, &lam) == VW_OK,
               "plan");
        EXPECT(np == 0 && fabs(lam - 1.001) < 1e-12,
               "all on the fast of 1,1000: %d copies, lambda %.6f, expected none, 1.001", np, lam);
    }
    /* Equal speeds (NULL): loads 6 and 2 -> copies of both, lambda 1. */
    {
        double load[2] = {6, 2};
        int cw[2] = {0, 1};
        EXPECT(vw__balance_duplicate_plan(load, cw, 2, 2, NULL, 0.03, 8, pc, pw, &np, &lam) == VW_OK,
               "plan");
        EXPECT(np == 2 && fabs(lam - 1.0) < 1e-12, "loads 6,2: %d copies, lambda %.6f", np, lam);
    }
}

static int t_duplicate(void)
{
    duplicate_plans();
    /* The runtime: copies are built from the cell's objects (the load() checksum of a
       cell with n copies is (n + 1) times its objects' sum, also after an object moved),
       and bad copy lists are refused. */
    {
        vw_box world = {{0, 0, 0}, {2, 1, 1}};
        int dims[3] = {2, 1, 1};
        vw_decomp *d;
        vw_decomp_create_grid(&world, dims, &d);
        vw_config cfg;
        vw_config_init(&cfg);
        cfg.workers = 3;
        vw_world *plain, *w;
        EXPECT(vw_world_create(&tmodule, NULL, d, &cfg, &plain) == VW_OK, "create");
        EXPECT(vw_world_create(&tmodule_ind, NULL, d, &cfg, &w) == VW_OK, "create");
        tobj objs[40];
        for (int i = 0; i < 40; i++) {
            double x = 0.05 * i;
            objs[i] = (tobj){i, {x, 0.1, 0.1}, {x + 0.04, 0.2, 0.2}};
        }
        vw_world_add_objects(plain, objs, 40);
        vw_world_add_objects(w, objs, 40);
        int two[2] = {1, 2}, self[1] = {0}, twice[2] = {1, 1}, far[1] = {3};
        EXPECT(vw_world_set_replicas(plain, 0, two, 2) == VW_E_INVAL,
              "a module without independent kinds was duplicated");
        EXPECT(vw_world_set_replicas(w, 0, self, 1) == VW_E_INVAL, "copy on the master's worker");
        EXPECT(vw_world_set_replicas(w, 0, twice, 2) == VW_E_INVAL, "two copies on one worker");
        EXPECT(vw_world_set_replicas(w, 0, far, 1) == VW_E_INVAL, "copy on worker 3 of 3");
        EXPECT(vw_world_set_replicas(w, 0, two, 2) == VW_OK, "set replicas: %s", vw_world_errmsg(w));
        int got[4];
        EXPECT(vw_world_replicas(w, 0, got, 4) == 2 && got[0] == 1 && got[1] == 2, "replica list");
        EXPECT(vw_world_run(w) == VW_OK && vw_world_run(plain) == VW_OK, "run");
        for (int round = 0; round < 2; round++) {
            for (int c = 0; c < 2; c++) {
                vw_cell_stats a, b;
                vw_world_cell_stats(plain, c, &a);
                vw_world_cell_stats(w, c, &b);
                int k = c == 0 ? 3 : 1;
                EXPECT(b.replicas == k - 1 && b.load == k * a.load,
                      "round %d, cell %d: %d copies, load %.0f, expected %d x %.0f", round, c,
                      b.replicas, b.load, k, a.load);
            }
            /* Move object 3 from cell 0 into cell 1: the copies must rebuild too. */
            tobj moved = {3, {1.5, 0.5, 0.5}, {1.6, 0.6, 0.6}};
            vw_world_update_object(w, 3, &moved);
            vw_world_update_object(plain, 3, &moved);
            EXPECT(vw_world_run(w) == VW_OK && vw_world_run(plain) == VW_OK, "run");
        }
        vw_world_free(plain);
        vw_world_free(w);
        vw_decomp_free(d);
    }
    /* The ray tracer: the same sums and counters as without copies. */
    vw_scene *s = load_scene("spheres:0.5:3");
    int one[3] = {1, 1, 1};
    int64_t *ref = render(s, 64, 64, one, 1, NULL, NULL);
    static const int layouts[][4] = {{2, 2, 2, 4}, {2, 2, 2, 8}, {4, 2, 1, 3}, {2, 2, 1, 2}};
    int copies_seen = 0;
    for (size_t li = 0; li < sizeof layouts / sizeof *layouts; li++) {
        const int *L = layouts[li];
        rt_job *jn, *jd;
        int64_t *plain = render(s, 64, 64, L, L[3], NULL, &jn);
        rt_balance b;
        balance_spec(&b, VW_BALANCE_DUPLICATE);
        int64_t *dup = render(s, 64, 64, L, L[3], &b, &jd);
        size_t diff = 0, n = 64 * 64 * 3;
        for (size_t i = 0; i < n; i++) diff += dup[i] != ref[i] || plain[i] != ref[i];
        EXPECT(diff == 0, "%dx%dx%d, %d workers: %zu sums differ", L[0], L[1], L[2], L[3], diff);
        vw_world *wn = rt_job_world(jn), *wd = rt_job_world(jd);
        for (int k = 0; k < RT_NCOUNTERS; k++)
            EXPECT(vw_world_counter(wn, k) == vw_world_counter(wd, k),
                  "%dx%dx%d: counter %d: %lld with copies, %lld without", L[0], L[1], L[2], k,
                  (long long)vw_world_counter(wd, k), (long long)vw_world_counter(wn, k));
        int64_t per_worker = 0;
        for (int g = 0; g < L[3]; g++) per_worker += vw_world_worker_counter(wd, g, RT_C_SEGMENTS);
        EXPECT(per_worker == vw_world_counter(wd, RT_C_SEGMENTS), "worker counters do not add up");
        for (int c = 0; c < vw_decomp_cell_count(vw_world_decomp(wd)); c++)
            copies_seen += vw_world_replicas(wd, c, NULL, 0);
        free(plain), free(dup);
        rt_job_free(jn), rt_job_free(jd);
    }
    EXPECT(copies_seen > 0, "no cell was ever duplicated");
    free(ref);
    vw_scene_free(s);
    /* Lambda of the counted work on a clustered scene: 8 cells, one worker each. */
    s = load_scene("spheres:0.5:1");
    int dims[3] = {2, 2, 2};
    double lam[2];
    for (int strat = 0; strat < 2; strat++) {
        rt_balance b;
        balance_spec(&b, VW_BALANCE_DUPLICATE);
        rt_job *j;
        int64_t *sums = render(s, 128, 128, dims, 8, strat ? &b : NULL, &j);
        lam[strat] = rt_job_work_imbalance(j, NULL);
        free(sums);
        rt_job_free(j);
    }
    printf("duplicate: work lambda none %.3f, duplicate %.3f\n", lam[0], lam[1]);
    EXPECT(lam[1] <= 1.10 && lam[1] < lam[0], "duplicate lambda %.3f (none: %.3f)", lam[1], lam[0]);
    vw_scene_free(s);
    /* Many cells on few workers: 4x4x4 on 4 workers, all the load in the 16 cells of
       worker 3. Every one of them needs a copy on each other worker (48 copies) for
       lambda 1; the default cap of 4 x workers (16) stopped at one copy each, lambda 2. */
    {
        vw_box world = {{0, 0, 0}, {1, 1, 1}};
        int d4[3] = {4, 4, 4};
        vw_decomp *d;
        vw_decomp_create_grid(&world, d4, &d);
        vw_config cfg;
        vw_config_init(&cfg);
        cfg.workers = 4;
        vw_world *w;
        EXPECT(vw_world_create(&tmodule_ind, NULL, d, &cfg, &w) == VW_OK, "create");
        double cl[64];
        for (int c = 0; c < 64; c++) cl[c] = c >= 48 ? 1.0 + (c % 3) : 0.0;
        vw_load_field *f;
        vw_load_field_create(&f);
        vw_load_field_add_cells(f, d, cl, 4);
        vw_balance_params p;
        vw_balance_params_init(&p);
        p.strategy = VW_BALANCE_DUPLICATE;
        vw_balance_report r;
        EXPECT(vw_balance_world(w, f, &p, NULL, &r) == VW_OK, "balance: %s", vw_world_errmsg(w));
        printf("duplicate: 64 cells on 4 workers: lambda %.3f -> %.3f, %d copies\n",
               r.imbalance_before, r.imbalance_predicted, r.duplicates);
        EXPECT(r.applied && r.imbalance_before > 3.9 && r.imbalance_predicted <= 1.03,
               "64 cells on 4 workers: lambda %.3f -> %.3f with %d copies, expected <= 1.03",
               r.imbalance_before, r.imbalance_predicted, r.duplicates);
        vw_load_field_free(f);
        vw_world_free(w);
        vw_decomp_free(d);
    }
    return vw_test_failures ? 1 : 0;
}

/* ---- the load field's inputs ------------------------------------------------------------ */

/* Points and loads that are not finite are refused and leave the field as it was: one
   NaN point once squeezed every tensor wall to min_width, an infinite load made
   infinite weights. */
static int t_field(void)
{
    vw_box world = {{0, 0, 0}, {1, 1, 1}};
    int dims[3] = {4, 1, 1};
    vw_decomp *d;
    vw_decomp_create_grid(&world, dims, &d);
    double loads[4] = {1, 1, 1, 1};
    vw_load_field *f;
    vw_load_field_create(&f);
    vw_load_field_add_cells(f, d, loads, 2);
    const double bad[][3] = {{NAN, 0.5, 0.5}, {0.5, INFINITY, 0.5}, {0.5, 0.5, -INFINITY}};
    for (int i = 0; i < 3; i++)
        EXPECT(vw_load_field_add_point(f, bad[i], 100) == VW_E_INVAL, "point %d", i);
    const double inf_load[4] = {1, INFINITY, 1, 1};
    EXPECT(vw_load_field_calibrate(f, d, inf_load, 2) == VW_E_INVAL, "infinite load");
    EXPECT(vw_load_field_total(f) == 4.0, "total %g", vw_load_field_total(f));
    vw_balance_params p;
    vw_balance_params_init(&p);
    p.strategy = VW_BALANCE_TENSOR;
    vw_decomp *nd = NULL;
    EXPECT(vw_balance_decompose(d, f, &p, &nd, NULL) == VW_OK, "tensor");
    const double *walls = nd ? vw_decomp_grid_walls(nd, 0) : NULL;
    for (int i = 0; walls && i < 3; i++)
        EXPECT(fabs(walls[i] - 0.25 * (i + 1)) < 1e-12, "wall %d at %g", i, walls[i]);
    vw_decomp_free(nd);
    vw_load_field_free(f);
    vw_decomp_free(d);
    return vw_test_failures ? 1 : 0;
}

/* ---- cells a few doubles wide ------------------------------------------------------------ */

/* Every cell of d has a box of positive width on every axis; returns the cell count. */
static int cells_ok(const vw_decomp *d, const char *what)
{
    int nc = vw_decomp_cell_count(d), bad = 0;
    for (int c = 0; c < nc; c++) {
        vw_box b = vw_decomp_cell_box(d, c);
        for (int a = 0; a < 3; a++) bad += !(b.lo[a] < b.hi[a]);
    }
    EXPECT(bad == 0, "%s: %d flat cell sides", what, bad);
    return nc;
}

/* The ray tracer's world box for a sphere of radius 1 at x = 1e16 on 4x4x4 cells is 64
   doubles wide on x (they are 2 apart there), and for one of radius 1e-20 at x = 1 the
   same around 1: min_width, 1e-3 of the extent, is finer than the doubles, so a wall
   min_width past its neighbour was the neighbour itself. Staggered then failed with
   "vw_balance_world: invalid argument": its rounds after the first cut the 64 cells of
   a staggered layout into 64 x slabs (vw_decomp_dims says {64, 1, 1} for a tree that
   is no grid), 63 walls in 63 doubles. */
static int t_thin(void)
{
    static const double where[][2] = {{1e16, 64}, {1.0, 32 * DBL_EPSILON}}; /* x, half width */
    static const vw_balance_strategy strat[] = {VW_BALANCE_TENSOR, VW_BALANCE_ROTATE,
                                                VW_BALANCE_STAGGERED, VW_BALANCE_DIVIDE};
    int *map = malloc(sizeof(int) * VW_MAX_CELLS);
    double *loads = malloc(sizeof(double) * VW_MAX_CELLS);
    CHECK(map && loads);
    for (int wi = 0; wi < 2; wi++) {
        double x = where[wi][0], half = where[wi][1];
        vw_box world = {{x - half, -1, -1}, {x + half, 1, 1}};
        int dims[3] = {4, 4, 4};
        vw_decomp *d;
        CHECK(vw_decomp_create_grid(&world, dims, &d) == VW_OK);
        for (size_t si = 0; si < sizeof strat / sizeof *strat; si++) {
            const char *name = vw_balance_strategy_name(strat[si]);
            /* Uniform load, and most of it on one point: one double on x. */
            vw_load_field *f;
            vw_load_field_create(&f);
            for (int c = 0; c < 64; c++) loads[c] = 1;
            vw_load_field_add_cells(f, d, loads, 4);
            const double heavy[3] = {x, 0.1, -0.2};
            vw_load_field_add_point(f, heavy, 1000);
            vw_decomp *cur;
            CHECK(vw_decomp_clone(d, &cur) == VW_OK);
            for (int round = 0; round < 3 && cur; round++) {
                char what[96];
                snprintf(what, sizeof what, "x %g, %s, round %d", x, name, round);
                vw_balance_params p;
                vw_balance_params_init(&p);
                p.strategy = strat[si];
                p.gworkers = 8;
                vw_decomp *nd = NULL;
                vw_status st = vw_balance_decompose(cur, f, &p, &nd, map);
                EXPECT(st == VW_OK && nd, "%s: %s", what, vw_status_name(st));
                if (!nd) break;
                int nc = cells_ok(nd, what);
                EXPECT(strat[si] == VW_BALANCE_DIVIDE ? nc >= 64 : nc == 64, "%s: %d cells", what, nc);
                /* Every point of the world is in a cell: a rotated frame's box is padded
                   for the rounding of the rotation, which at 1e16 is units, not 1e-9 of
                   the extent. */
                int lost = 0;
                for (size_t i = 0; i < f->n; i++) lost += vw_decomp_locate(nd, f->p[i], NULL) < 0;
                EXPECT(lost == 0, "%s: %d of %zu points in no cell", what, lost, f->n);
                /* The next round learns from this one's cells, as the ray tracer's do. */
                vw_load_field_cell_loads(f, nd, loads);
                vw_load_field_calibrate(f, nd, loads, 4);
                vw_decomp_free(cur);
                cur = nd;
            }
            vw_decomp_free(cur);
            vw_load_field_free(f);
        }
        vw_decomp_free(d);
    }
    /* Fewer doubles than walls asked: x from 1e16 to 1e16 + 4 has one double inside, and
       4 slabs need 3. The balancers keep the walls they have (one cell), no error. */
    {
        vw_box world = {{1e16, -1, -1}, {1e16 + 4, 1, 1}};
        int one[3] = {1, 1, 1};
        vw_decomp *d;
        CHECK(vw_decomp_create_grid(&world, one, &d) == VW_OK);
        vw_load_field *f;
        vw_load_field_create(&f);
        const double pt[3] = {1e16 + 2, 0, 0};
        vw_load_field_add_point(f, pt, 1);
        for (int si = 0; si < 3; si++) {
            vw_balance_params p;
            vw_balance_params_init(&p);
            p.strategy = strat[si];
            p.dims[0] = 4;
            vw_decomp *nd = NULL;
            vw_status st = vw_balance_decompose(d, f, &p, &nd, NULL);
            EXPECT(st == VW_OK && nd && vw_decomp_cell_count(nd) == 1,
                   "4 slabs in 2 doubles, %s: %s, %d cells", vw_balance_strategy_name(strat[si]),
                   vw_status_name(st), nd ? vw_decomp_cell_count(nd) : 0);
            vw_decomp_free(nd);
        }
        /* A caller's wrong parameters are still refused. */
        vw_balance_params p;
        vw_balance_params_init(&p);
        p.strategy = VW_BALANCE_TENSOR;
        vw_decomp *nd = NULL;
        p.min_width = NAN;
        EXPECT(vw_balance_decompose(d, f, &p, &nd, NULL) == VW_E_INVAL && !nd, "min_width NaN");
        p.min_width = 1e-3;
        p.dims[0] = -4;
        EXPECT(vw_balance_decompose(d, f, &p, &nd, NULL) == VW_E_INVAL && !nd, "dims -4");
        vw_load_field_free(f);
        vw_decomp_free(d);
    }
    free(map);
    free(loads);
    printf("thin: %d failures\n", vw_test_failures);
    return vw_test_failures ? 1 : 0;
}

/* ---- divide_thin: divide cuts a side that can be cut ------------------------------------ */

/* Divides d on field f for gw workers (max_extra 0: the default), expecting success and
   every point of f in a cell of the result (what names the case). Returns the result
   (NULL on failure); *lam its lambda by the mapping divide made, *cells its count. */
static vw_decomp *divide_checked(const vw_decomp *d, vw_load_field *f, int gw,
                                 const double *speeds, int max_extra, const char *what,
                                 double *lam, int *cells)
{
    double *loads = malloc(sizeof(double) * VW_MAX_CELLS);
    int *map = malloc(sizeof(int) * VW_MAX_CELLS);
    CHECK(loads && map);
    vw_balance_params p;
    vw_balance_params_init(&p);
    p.strategy = VW_BALANCE_DIVIDE;
    p.gworkers = gw;
    p.speeds = speeds;
    p.max_extra = max_extra;
    vw_decomp *nd = NULL;
    vw_status st = vw_balance_decompose(d, f, &p, &nd, map);
    EXPECT(st == VW_OK && nd, "%s: divide: %s", what, vw_status_name(st));
    *lam = INFINITY;
    *cells = 0;
    if (nd) {
        *cells = cells_ok(nd, what);
        vw_load_field_cell_loads(f, nd, loads);
        *lam = vw_balance_imbalance(loads, map, *cells, gw, speeds);
        int lost = 0;
        for (size_t i = 0; i < f->n; i++) lost += vw_decomp_locate(nd, f->p[i], NULL) < 0;
        EXPECT(lost == 0, "%s: %d of %zu points in no cell", what, lost, f->n);
    }
    free(loads);
    free(map);
    return nd;
}

/* Divide splits the heaviest cell along its longest side in world units. Far from the
   origin for its size that side can be a few doubles wide (x below: 2 apart at 1e16)
   while y and z are normal; divide stopped at the first cell whose longest side had no
   double inside it, though a cut on y or z would have balanced the load. The load: on
   the box's middle on axis 3 - la - sa, 40 values along axis la (weight growing along
   it), 5 along sa, in frame coordinates (frame F, NULL: none); with `uniform` also one
   unit a cell of the grid, as a first measurement on it gives. 8 workers. Returns lambda
   of the divided cells by the mapping divide made; *cells their count, *cut a bit per
   axis on which some cell is narrower than the world. */
static double divide_far(const vw_box *world, const int dims[3], const double *F, int la,
                         int sa, int uniform, int *cells, int *cut)
{
    double mid[3];
    const double *walls[3];
    for (int a = 0; a < 3; a++) {
        CHECK(dims[a] == 1 || dims[a] == 2);
        mid[a] = 0.5 * (world->lo[a] + world->hi[a]);
        walls[a] = &mid[a];
    }
    vw_decomp *d;
    CHECK(vw_decomp_create_grid_walls(world, dims, walls, F, &d) == VW_OK);
    vw_load_field *f;
    CHECK(vw_load_field_create(&f) == VW_OK);
    double *loads = malloc(sizeof(double) * VW_MAX_CELLS);
    CHECK(loads);
    if (uniform) {
        for (int c = 0; c < vw_decomp_cell_count(d); c++) loads[c] = 1;
        CHECK(vw_load_field_add_cells(f, d, loads, 4) == VW_OK);
    }
    int ma = 3 - la - sa;
    for (int i = 0; i < 40; i++)
        for (int k = 0; k < 5; k++) {
            double q[3], p[3];
            q[ma] = 0.5 * (world->lo[ma] + world->hi[ma]);
            q[la] = world->lo[la] + (world->hi[la] - world->lo[la]) * (i + 0.5) / 40;
            q[sa] = world->lo[sa] + (world->hi[sa] - world->lo[sa]) * (k + 0.5) / 5;
            vw_decomp_from_frame(d, q, p);
            CHECK(vw_load_field_add_point(f, p, 1 + 0.1 * i) == VW_OK);
        }
    for (size_t i = 0; i < f->n; i++) CHECK(vw_decomp_locate(d, f->p[i], NULL) >= 0);
    double lam;
    vw_decomp *nd = divide_checked(d, f, 8, NULL, 0, "divide far from the origin", &lam, cells);
    *cut = 0;
    for (int c = 0; c < *cells; c++) {
        vw_box b = vw_decomp_cell_box(nd, c);
        for (int a = 0; a < 3; a++)
            if (b.lo[a] != world->lo[a] || b.hi[a] != world->hi[a]) *cut |= 1 << a;
    }
    vw_decomp_free(nd);
    vw_decomp_free(d);
    vw_load_field_free(f);
    free(loads);
    return lam;
}

static int t_divide_thin(void)
{
    int cells, cut;
    /* One cell, x two units (adjacent doubles: none inside) and longer than y and z:
       divide kept the one cell, lambda 8. */
    {
        vw_box world = {{1e16, -0.9, -0.5}, {1e16 + 2, 0.9, 0.5}};
        int one[3] = {1, 1, 1};
        double lam = divide_far(&world, one, NULL, 1, 2, 0, &cells, &cut);
        printf("divide_thin: x without a double inside, 1 cell: %d cells, lambda %.3f\n", cells,
               lam);
        EXPECT(cells >= 8 && lam <= 1.10, "1 cell: %d cells, lambda %.3f (want <= 1.10)", cells,
               lam);
        EXPECT(cut == 6, "1 cell: cuts on axes %d (want y and z: 6; x has no double inside)",
               cut);
    }
    /* The ray tracer's box for a sphere of radius 1 at x = 1e16 on 2x2x2 cells: x 32 units,
       16 doubles (8 a cell), y and z 2; a uniform first field. Divide cut x, the longest,
       until its pieces were one double wide, and stopped with the load in them: 9 cells,
       lambda 3.2. */
    {
        vw_box world = {{1e16 - 16, -1, -1}, {1e16 + 16, 1, 1}};
        int dims[3] = {2, 2, 2};
        double lam = divide_far(&world, dims, NULL, 1, 2, 1, &cells, &cut);
        printf("divide_thin: x 16 doubles, 2x2x2: %d cells, lambda %.3f\n", cells, lam);
        EXPECT(lam <= 1.10, "2x2x2: %d cells, lambda %.3f (want <= 1.10)", cells, lam);
    }
    /* The same far away in a frame turned 45 degrees about z: frame x and y (7e15, doubles
       1 apart) 32 doubles wide, the longest sides, and the load 5 values on frame y;
       only z, 2 units, cuts it finely. Lengths in the frame are lengths in the world (the
       frame is orthonormal), so the longest side is still the longest in world units. */
    {
        const double h = sqrt(0.5), F[9] = {h, h, 0, -h, h, 0, 0, 0, 1};
        double cx = h * 1e16, cy = -h * 1e16;
        vw_box world = {{cx - 12, cy - 12, -1}, {cx + 12, cy + 12, 1}};
        int dims[3] = {2, 2, 1};
        double lam = divide_far(&world, dims, F, 2, 1, 1, &cells, &cut);
        printf("divide_thin: rotated frame, x and y 32 doubles, 2x2x1: %d cells, lambda %.3f\n",
               cells, lam);
        EXPECT(lam <= 1.10 && (cut & 4), "rotated: %d cells, lambda %.3f (want <= 1.10), cuts %d",
               cells, lam, cut);
    }
    printf("divide_thin: %d failures\n", vw_test_failures);
    return vw_test_failures ? 1 : 0;
}

/* ---- divide_hot: an uncuttable heaviest cell does not end divide ------------------------ */

/* World [1, 2]^3 on 2x2x2 cells, each axis's wall one double past 1: the cell at the
   origin corner is one double wide on every side, no wall fits in it, and it holds a
   point of load hot_load. The other load is spread: `line` on a line along x in the cell
   one double wide on y and z (cuttable on x only), `bulk` on an 8x8x8 grid of points in
   the cell [w, 2]^3. gw workers of the given speeds (NULL: equal), at most max_extra
   extra cells (0: divide's default). Divide stopped ("break") as soon as the heaviest
   cell could not be cut, with the other cells still overloading a worker (divide_hot;
   divide_stop for when it must stop). Returns lambda of the result by divide's mapping; *cells its cell count; *hot_whole 1
   when the hot point's cell is the uncuttable corner, unchanged. */
static double divide_hot_corner(int gw, const double *speeds, int max_extra, double hot_load,
                                double line, double bulk, int *cells, int *hot_whole)
{
    const double w = nextafter(1.0, 2.0);
    vw_box world = {{1, 1, 1}, {2, 2, 2}};
    int dims[3] = {2, 2, 2};
    const double *walls[3] = {&w, &w, &w};
    vw_decomp *d;
    CHECK(vw_decomp_create_grid_walls(&world, dims, walls, NULL, &d) == VW_OK);
    vw_load_field *f;
    CHECK(vw_load_field_create(&f) == VW_OK);
    const double hot[3] = {1, 1, 1};
    CHECK(vw_load_field_add_point(f, hot, hot_load) == VW_OK);
    for (int i = 0; line > 0 && i < 16; i++) {
        const double q[3] = {1.1 + 0.05 * i, 1, 1};
        CHECK(vw_load_field_add_point(f, q, line / 16) == VW_OK);
    }
    for (int i = 0; bulk > 0 && i < 512; i++) {
        const double q[3] = {1.1 + 0.1 * (i % 8), 1.1 + 0.1 * (i / 8 % 8), 1.1 + 0.1 * (i / 64)};
        CHECK(vw_load_field_add_point(f, q, bulk / 512) == VW_OK);
    }
    CHECK(vw_decomp_locate(d, hot, NULL) >= 0);
    vw_box hb = vw_decomp_cell_box(d, vw_decomp_locate(d, hot, NULL));
    CHECK(hb.hi[0] == w && hb.hi[1] == w && hb.hi[2] == w);
    double lam;
    vw_decomp *nd = divide_checked(d, f, gw, speeds, max_extra, "divide with a hot cell", &lam,
                                   cells);
    *hot_whole = 0;
    int hc = nd ? vw_decomp_locate(nd, hot, NULL) : -1;
    if (hc >= 0) {
        vw_box b = vw_decomp_cell_box(nd, hc);
        *hot_whole = 1;
        for (int a = 0; a < 3; a++) *hot_whole &= b.lo[a] == hb.lo[a] && b.hi[a] == hb.hi[a];
    }
    vw_decomp_free(nd);
    vw_decomp_free(d);
    vw_load_field_free(f);
    return lam;
}

/* divide_hot_corner with the point's load 10, equal speeds and 32 extra cells at most. */
static double divide_hot(int gw, double line, double bulk, int *cells, int *hot_whole)
{
    return divide_hot_corner(gw, NULL, 32, 10, line, bulk, cells, hot_whole);
}

static int t_divide_hot(void)
{
    int cells, whole;
    /* 2 workers, the hot cell 10 the heaviest, the line and the bulk 9 each: the hot
       cell on one worker, 18 on the other, lambda 18 / 14 = 1.29; divide stopped at
       once, 8 cells. */
    double lam = divide_hot(2, 9, 9, &cells, &whole);
    printf("divide_hot: 2 workers, hot 10, line 9, bulk 9: %d cells, lambda %.3f\n", cells, lam);
    EXPECT(lam <= 1.05 && cells > 8 && whole,
           "2 workers: %d cells, lambda %.3f (want <= 1.05, more than 8 cells), hot cell whole %d",
           cells, lam, whole);
    /* 8 workers, the bulk 70: it is cut into pieces of 8.75, then the hot cell is the
       heaviest; divide stopped there with two pieces on one worker, lambda 17.5 / 10.
       Going on, the 32 extra cells halve the bulk into 32 pieces of 70 / 32 for the 7
       other workers: 5 on one, lambda 1.094. */
    lam = divide_hot(8, 0, 70, &cells, &whole);
    printf("divide_hot: 8 workers, hot 10, bulk 70: %d cells, lambda %.3f\n", cells, lam);
    EXPECT(lam <= 1.15 && whole,
           "8 workers: %d cells, lambda %.3f (want <= 1.15), hot cell whole %d", cells, lam,
           whole);
    /* Only the hot point: no loaded cell can be cut, and no empty one is: 8 cells, lambda
       8, as before. */
    lam = divide_hot(8, 0, 0, &cells, &whole);
    printf("divide_hot: 8 workers, hot 10 alone: %d cells, lambda %.3f\n", cells, lam);
    EXPECT(cells == 8 && whole && fabs(lam - 8) < 1e-9,
           "hot alone: %d cells (want 8: empty cells not cut), lambda %.3f", cells, lam);
    printf("divide_hot: %d failures\n", vw_test_failures);
    return vw_test_failures ? 1 : 0;
}

/* ---- two threads balancing at once ------------------------------------------------------ */

/* The mappers and balancers are plain functions of their inputs: two threads running
   them at once on different loads get what each gets alone. (Their sorts once read a
   file-static array or axis that the other thread's call overwrote.) */
typedef struct side {
    vw_decomp *d;
    double *load;
    vw_load_field *f;
    int *map;          /* vw_map_greedy alone */
    vw_decomp *walls;  /* the tensor balance alone */
    int wrong;
} side;

static void *side_run(void *arg)
{
    side *s = arg;
    int nc = vw_decomp_cell_count(s->d);
    int *cw = malloc(sizeof(int) * (size_t)nc);
    vw_balance_params p;
    vw_balance_params_init(&p);
    p.strategy = VW_BALANCE_TENSOR;
    for (int it = 0; it < 100; it++) {
        vw_map_greedy(s->d, s->load, 7, NULL, 0.05, cw);
        s->wrong += memcmp(cw, s->map, sizeof(int) * (size_t)nc) != 0;
        vw_decomp *nd = NULL;
        vw_balance_decompose(s->d, s->f, &p, &nd, NULL);
        s->wrong += !vw_decomp_equal(nd, s->walls);
        vw_decomp_free(nd);
    }
    free(cw);
    return NULL;
}

static int t_concurrent(void)
{
    vw_box world = {{0, 0, 0}, {1, 1, 1}};
    int dims[3] = {16, 16, 8};
    vw_decomp *d;
    vw_decomp_create_grid(&world, dims, &d);
    int nc = vw_decomp_cell_count(d);
    side sd[2];
    vw_balance_params p;
    vw_balance_params_init(&p);
    p.strategy = VW_BALANCE_TENSOR;
    for (int k = 0; k < 2; k++) {
        sd[k].d = d;
        sd[k].load = malloc(sizeof(double) * (size_t)nc);
        sd[k].map = malloc(sizeof(int) * (size_t)nc);
        for (int c = 0; c < nc; c++) sd[k].load[c] = k ? (double)((c * 37) % 101) : (double)(nc - c);
        CHECK(vw_map_greedy(d, sd[k].load, 7, NULL, 0.05, sd[k].map) == VW_OK);
        vw_load_field_create(&sd[k].f);
        vw_load_field_add_cells(sd[k].f, d, sd[k].load, 1);
        CHECK(vw_balance_decompose(d, sd[k].f, &p, &sd[k].walls, NULL) == VW_OK);
        sd[k].wrong = 0;
    }
    pthread_t th[2];
    for (int k = 0; k < 2; k++) CHECK(pthread_create(&th[k], NULL, side_run, &sd[k]) == 0);
    for (int k = 0; k < 2; k++) pthread_join(th[k], NULL);
    printf("concurrent: %d and %d of 200 results differ from the thread's alone\n", sd[0].wrong,
           sd[1].wrong);
    for (int k = 0; k < 2; k++) {
        EXPECT(sd[k].wrong == 0, "thread %d: %d wrong results", k, sd[k].wrong);
        free(sd[k].load);
        free(sd[k].map);
        vw_load_field_free(sd[k].f);
        vw_decomp_free(sd[k].walls);
    }
    vw_decomp_free(d);
    return vw_test_failures ? 1 : 0;
}

/* divide_hot_corner's world (as divide_hot's): the corner cell at (1, 1, 1) is one double wide on every side,
   so no wall fits in it, and it holds a point of load `hot`. `bulk` is spread on an
   8x8x8 grid of points in the cell [w, 2]^3, `line` on a line along x in the cell one
   double wide on y and z. When the hot cell alone is the work of a fastest worker and
   that worker's time is the largest, no cut can lower lambda: wherever the mapping puts
   the hot cell, its worker takes at least that long, and the total does not change.
   Divide went on cutting the bulk up to max_extra all the same (40 cells for 8, lambda
   unchanged). It must still cut where the hot cell sits on a slower worker (pieces of
   the bulk let the mapper give it the fast one) and where the hot cell's worker holds
   more than it (pieces let the mapper move the rest off). */
typedef struct stop_outcome {
    int cells;  /* cells of the result */
    double lam; /* lambda by speed of the mapping divide made */
    int whole;  /* the hot cell is the uncuttable corner, unchanged */
} stop_outcome;

static stop_outcome divide_stop_run(int gw, const double *speeds, int max_extra, double hot,
                                    double line, double bulk)
{
    stop_outcome o;
    o.lam = divide_hot_corner(gw, speeds, max_extra, hot, line, bulk, &o.cells, &o.whole);
    return o;
}

static int t_divide_stop(void)
{
    stop_outcome o;
    /* Equal speeds, 2 workers: the hot cell 10 on one, the bulk 4 on the other, lambda
       10 / 7 = 1.429 whatever is cut. Divide cut the bulk 32 times (40 cells). */
    o = divide_stop_run(2, NULL, 32, 10, 0, 4);
    printf("divide_stop: 2 workers, hot 10, bulk 4: %d cells, lambda %.4f\n", o.cells, o.lam);
    EXPECT(o.cells == 8 && fabs(o.lam - 10.0 / 7) < 1e-12 && o.whole,
           "hot alone sets lambda: %d cells (want 8), lambda %.6f (want %.6f), hot whole %d",
           o.cells, o.lam, 10.0 / 7, o.whole);
    /* The same with max_extra 0 (4 * gworkers): 16 cells before. */
    o = divide_stop_run(2, NULL, 0, 10, 0, 4);
    printf("divide_stop: 2 workers, default max_extra: %d cells, lambda %.4f\n", o.cells, o.lam);
    EXPECT(o.cells == 8 && fabs(o.lam - 10.0 / 7) < 1e-12,
           "default max_extra: %d cells (want 8), lambda %.6f", o.cells, o.lam);

    /* Speeds 1 and 2: the hot cell on the fast worker (10 / 1), the bulk on the slow one
       (4 / 0.5 = 8), lambda 10 / (14 / 1.5) = 1.071. No cut can lower it: 8 cells (40
       before). */
    static const double slow_fast[2] = {1, 2};
    o = divide_stop_run(2, slow_fast, 32, 10, 0, 4);
    printf("divide_stop: speeds 1,2, hot 10 on the fast worker, bulk 4: %d cells, lambda %.4f\n",
           o.cells, o.lam);
    EXPECT(o.cells == 8 && fabs(o.lam - 10 / (14 / 1.5)) < 1e-12 && o.whole,
           "speeds 1,2: %d cells (want 8), lambda %.6f (want %.6f)", o.cells, o.lam,
           10 / (14 / 1.5));

    /* Speeds 2 and 1, bulk 12: the bulk goes to the fast worker first, the hot cell to
       the slow one, 10 / 0.5 = 20, lambda 20 / (22 / 1.5) = 1.364: the most loaded worker
       holds only the hot cell, yet halving the bulk lets the mapper put the hot cell on
       the fast worker (10 + 6 | 6 / 0.5: 16). Divide must go on. */
    static const double fast_slow[2] = {2, 1};
    o = divide_stop_run(2, fast_slow, 32, 10, 0, 12);
    printf("divide_stop: speeds 2,1, hot 10 on the slow worker, bulk 12: %d cells, lambda %.4f\n",
           o.cells, o.lam);
    EXPECT(o.cells > 8 && o.lam <= 1.10 && o.whole,
           "speeds 2,1: %d cells, lambda %.4f (want <= 1.10, was 1.364 on 8 cells)", o.cells,
           o.lam);

    /* Equal speeds, hot 10, bulk 10, line 5: the line joins the hot cell (a tie, the lower
       worker), 15 | 10, lambda 1.2. That worker holds more than the uncuttable cell:
       pieces of the bulk and the line let the rest move off. Divide must go on. */
    o = divide_stop_run(2, NULL, 32, 10, 5, 10);
    printf("divide_stop: 2 workers, hot 10 with line 5, bulk 10: %d cells, lambda %.4f\n",
           o.cells, o.lam);
    EXPECT(o.cells > 8 && o.lam <= 1.05 && o.whole,
           "hot shares its worker: %d cells, lambda %.4f (want <= 1.05, was 1.2)", o.cells,
           o.lam);

    /* 4 workers, hot 10, bulk 24: the bulk cut into pieces until three workers hold 8
       each, lambda 10 / 8.5 = 1.176 with the hot cell alone on the fourth; then stop. */
    o = divide_stop_run(4, NULL, 32, 10, 0, 24);
    printf("divide_stop: 4 workers, hot 10, bulk 24: %d cells, lambda %.4f\n", o.cells, o.lam);
    EXPECT(o.cells > 8 && o.cells < 40 && fabs(o.lam - 10 / 8.5) < 1e-12 && o.whole,
           "4 workers: %d cells (want some, fewer than 40), lambda %.6f (want %.6f)", o.cells,
           o.lam, 10 / 8.5);
    TEST_DONE();
}

/* ---- divide_rounds: the bound on extra cells holds over rounds ---------------------------- */

/* Divides again and again, each round on the last one's result (as render's rounds and
   animate's rebalances between frames do), the load a tight cluster of points in one cell
   that max_extra cuts cannot spread over the workers, so every round would cut on. The
   cells never pass max(start, gw) + max_extra (max_extra 0: 4 x gw); divide's limit held
   per call, and the cells piled up (one cell on 8 workers, max_extra 4: 40 after ten
   rounds, up to the tolerance). Returns the cells after `rounds`. */
static int divide_rounds_run(const int dims[3], int gw, int max_extra, int rounds)
{
    vw_box world = {{0, 0, 0}, {1, 1, 1}};
    vw_decomp *d = NULL;
    vw_load_field *f = NULL;
    CHECK(vw_decomp_create_grid(&world, dims, &d) == VW_OK);
    CHECK(vw_load_field_create(&f) == VW_OK);
    /* 10^3 points in [0.1, 0.2)^3, and a thin spread everywhere. */
    for (int i = 0; i < 10; i++)
        for (int j = 0; j < 10; j++)
            for (int k = 0; k < 10; k++) {
                double q[3] = {0.1 + 0.01 * i, 0.1 + 0.01 * j, 0.1 + 0.01 * k};
                CHECK(vw_load_field_add_point(f, q, 1.0) == VW_OK);
                double r[3] = {0.05 + 0.1 * i, 0.05 + 0.1 * j, 0.05 + 0.1 * k};
                CHECK(vw_load_field_add_point(f, r, 0.01) == VW_OK);
            }
    int start = vw_decomp_cell_count(d);
    int extra = max_extra > 0 ? max_extra : 4 * gw;
    int bound = (start > gw ? start : gw) + extra, first = start + extra;
    int cells = start, prev = start;
    char what[96];
    for (int r = 0; r < rounds; r++) {
        snprintf(what, sizeof what, "%dx%dx%d on %d workers, max_extra %d, round %d", dims[0],
                 dims[1], dims[2], gw, max_extra, r + 1);
        double lam;
        vw_decomp *nd = divide_checked(d, f, gw, NULL, max_extra, what, &lam, &cells);
        if (!nd) break;
        vw_decomp_free(d);
        d = nd;
        /* The first round is as before: max_extra more than it was given. */
        EXPECT(r > 0 || cells <= first, "%s: %d cells, more than %d + %d", what, cells, start,
               extra);
        EXPECT(cells <= bound, "%s: %d cells, more than max(%d, %d) + %d = %d", what, cells,
               start, gw, extra, bound);
        EXPECT(cells >= prev, "%s: %d cells, fewer than %d", what, cells, prev);
        prev = cells;
    }
    printf("divide_rounds: %dx%dx%d on %d workers, max_extra %d: %d cells after %d rounds "
           "(bound %d)\n", dims[0], dims[1], dims[2], gw, max_extra, cells, rounds, bound);
    vw_load_field_free(f);
    vw_decomp_free(d);
    return cells;
}

static int t_divide_rounds(void)
{
    static const int d222[3] = {2, 2, 2}, d111[3] = {1, 1, 1}, d444[3] = {4, 4, 4};
    /* As many cells as workers: 8 + 4 over the run (was 15, the tolerance reached). */
    int c = divide_rounds_run(d222, 8, 4, 10);
    EXPECT(c == 12, "2x2x2 on 8 workers, max_extra 4: %d cells after 10 rounds (want 12)", c);
    /* The default max_extra, 4 x 8: 8 + 32 = 40. */
    divide_rounds_run(d222, 8, 0, 10);
    /* Fewer cells than workers: gworkers + max_extra at most (the first round 1 + 4;
       was 40). */
    divide_rounds_run(d111, 8, 4, 10);
    /* More cells than workers: 64 + 4 (was 71). */
    c = divide_rounds_run(d444, 8, 4, 10);
    EXPECT(c == 68, "4x4x4 on 8 workers, max_extra 4: %d cells after 10 rounds (want 68)", c);
    TEST_DONE();
}

/* ---- divide_rounds_render: render's rounds keep to the bound ----------------------------- */

/* Render's divide rounds (2 + 3) on a fully clustered scene at 4x4x4 on 64 workers, sampled
   every 4th row and column: each round divided anew with 4 x 64 extra cells, and the
   scene ended on 1026 cells (2000 spheres, 128x128, vwalls render --prepass 4). */
static int t_divide_rounds_render(void)
{
    char err[512];
    vw_scene *s = NULL;
    vw_gen_params gp;
    vw_gen_params_init(&gp);
    gp.count = 2000;
    gp.cluster = 1;
    gp.seed = 1;
    if (vw_gen("spheres", &gp, &s, err, sizeof err) != VW_OK) {
        fprintf(stderr, "gen spheres: %s\n", err);
        return 1;
    }
    int dims[3] = {4, 4, 4};
    rt_balance b;
    balance_spec(&b, VW_BALANCE_DIVIDE);
    b.stride = 4;
    rt_job *j;
    int64_t *sums = render(s, 128, 128, dims, 64, &b, &j);
    int cells = vw_decomp_cell_count(vw_world_decomp(rt_job_world(j)));
    printf("divide_rounds_render: 4x4x4 on 64 workers: %d cells, work lambda %.3f\n", cells,
           rt_job_work_imbalance(j, NULL));
    EXPECT(cells <= 64 + 4 * 64, "%d cells, more than 64 + 4 x 64", cells);
    free(sums);
    rt_job_free(j);
    vw_scene_free(s);
    return vw_test_failures ? 1 : 0;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: bal_test identical|conserve|staggered8|divide16|rotate|map|duplicate|field|concurrent|thin|divide_thin|divide_hot|divide_stop|divide_rounds|divide_rounds_render|shares [...]\n");
        return 2;
    }
    const char *cmd = argv[1];
    if (!strcmp(cmd, "identical")) return t_identical(argc > 2 ? argv[2] : "gen:balls", argc > 3 ? argv[3] : NULL);
    if (!strcmp(cmd, "conserve")) return t_conserve();
    if (!strcmp(cmd, "staggered8")) return t_staggered8();
    if (!strcmp(cmd, "rotate")) return t_rotate();
    if (!strcmp(cmd, "divide16")) return t_divide16();
    if (!strcmp(cmd, "shares")) return t_shares();
    if (!strcmp(cmd, "map")) return t_map();
    if (!strcmp(cmd, "duplicate")) return t_duplicate();
    if (!strcmp(cmd, "field")) return t_field();
    if (!strcmp(cmd, "concurrent")) return t_concurrent();
    if (!strcmp(cmd, "thin")) return t_thin();
    if (!strcmp(cmd, "divide_thin")) return t_divide_thin();
    if (!strcmp(cmd, "divide_hot")) return t_divide_hot();
    if (!strcmp(cmd, "divide_stop")) return t_divide_stop();
    if (!strcmp(cmd, "divide_rounds")) return t_divide_rounds();
    if (!strcmp(cmd, "divide_rounds_render")) return t_divide_rounds_render();
    fprintf(stderr, "bal_test: unknown test '%s'\n", cmd);
    return 2;
}
