/* cmd_bench.c - vwalls bench: how the ray tracer scales on this machine (or under mpirun,
 * on these machines), measured side by side in one run. Every configuration (a layout
 * of cells and a number of workers) renders the same scene in each round, the rounds
 * interleaving the configurations so that a shared machine's drift in speed hits them
 * alike; the table gives each one's best times, its speedup and efficiency against the
 * first configuration, the imbalance lambda of the workers' busy time (of the round whose
 * compute time it gives), and what the machine's load does not change (ray-cell visits
 * per ray, messages). Every configuration
 * must make the same image, bit for bit (the fixed-point pixel sums), by tracing the
 * same rays (which is what makes the rows' visits per ray comparable): the design's
 * promise, checked on every render; a difference is a failure (exit status 1).
 */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "commands.h"
#include "raytrace/raytrace.h"
#include "vwalls/gen.h"

static const char *const CMD = "bench";

enum { MAX_CONFIGS = 64, MAX_ROUNDS = 100 };

static void help(void)
{
    printf("usage: vwalls bench [SCENE.(nff|obj|ply)] [options]\n"
           "\n"
           "Measures how the ray tracer scales, side by side in one run: every configuration\n"
           "(a layout of cells x a number of workers) renders the same scene once a round,\n"
           "the configurations interleaved, so that a drift of the machine's speed hits\n"
           "them alike. For each it prints the best build and compute times over the\n"
           "rounds, the speedup (compute, best of rounds; and the median of the ratios\n"
           "within each round) and the efficiency against the first configuration, the\n"
           "imbalance lambda of the workers' busy time (in the round of the best compute\n"
           "time), ray-cell visits per ray and the messages. Every configuration must\n"
           "render the same image, bit for bit, and trace the same number of rays: a\n"
           "difference is reported and fails the command (exit status 1).\n"
           "  SCENE            the scene (default: the generated sphereflake, vwalls gen\n"
           "                   balls: 7381 spheres on a floor polygon, 3 lights)\n"
           "  --cells LIST     comma-separated layouts (default 1,2x2x2)\n"
           "  --workers LIST   comma-separated worker counts per process, 1 to 1024\n"
           "                   (default 1 and the cores, when there are more than one)\n"
           "  --size WxH       image size (default 256x256)\n"
           "  --depth D        maximum ray depth, 1 to 64 (default 5)\n"
           "  --repeat N       rounds, 1 to %d (default 3)\n"
           "  --world X0,Y0,Z0,X1,Y1,Z1  the world box covers at least this box, as for\n"
           "                   vwalls render (default: the scene's bounds, padded)\n"
           "  --farm F         auto (default) | all | idle | none, as vwalls render --farm:\n"
           "                   none maps the cells onto the workers, so rays cross between\n"
           "                   workers as messages (the paper's setting)\n"
           "  --csv FILE       also write the table as CSV (one row per configuration)\n"
           "  --stats FILE     the stats JSON: the table's figures and every round's times\n"
           "  -q, --quiet      the table only (no scene line, no progress)\n"
           "  --help           this text\n"
           "Configurations: every layout with every worker count, in the order given; the\n"
           "first is the reference of the speedups (by default 1 cell on 1 worker). At most\n"
           "%d. Under mpirun every process runs its workers; the first process prints.\n"
           "Timings, and lambda (a ratio of busy times), depend on what else the machine runs;\n"
           "visits, rays and messages do not.\n"
           "\nexit status: 0 success, 2 bad input or usage, 1 any other failure (also: two\n"
           "configurations rendered different images or traced different numbers of rays)\n",
           MAX_ROUNDS, MAX_CONFIGS);
}

typedef struct bench_config {
    int dims[3];
    long workers;
    /* per round */
    double build[MAX_ROUNDS], compute[MAX_ROUNDS];
    /* the imbalance of the workers' busy time: a timing too, so the table gives the one
       of the round whose compute time it gives (the best) */
    double lambda[MAX_ROUNDS];
    /* from the last round (the same every round) */
    long long rays, segments;
    unsigned long long messages;
    int cells, copies, all_workers;
} bench_config;

/* A comma-separated list of values, each given to one(); -1 (reported) when empty or when
   an item is. */
static int each_item(const char *opt, const char *list, int (*one)(const char *opt, const char *item, void *arg),
                     void *arg)
{
    char buf[512];
    if (!*list || strlen(list) >= sizeof buf) {
        vw_cli_error(CMD, "%s: bad value '%s' (expected a comma-separated list)", opt, list);
        return -1;
    }
    strcpy(buf, list);
    for (char *p = buf;;) {
        char *comma = strchr(p, ',');
        if (comma) *comma = 0;
        if (!*p) {
            vw_cli_error(CMD, "%s: bad value '%s' (an empty item)", opt, list);
            return -1;
        }
        if (one(opt, p, arg)) return -1;
        if (!comma) return 0;
        p = comma + 1;
    }
}

typedef struct lists {
    int dims[MAX_CONFIGS][3];
    int nlayouts;
    long workers[MAX_CONFIGS];
    int nworkers;
} lists;

static int one_layout(const char *opt, const char *item, void *arg)
{
    lists *l = arg;
    if (l->nlayouts == MAX_CONFIGS) {
        vw_cli_error(CMD, "%s: at most %d layouts", opt, MAX_CONFIGS);
        return -1;
    }
    return vw_cli_layout(CMD, opt, item, l->dims[l->nlayouts++]);
}

static int one_workers(const char *opt, const char *item, void *arg)
{
    lists *l = arg;
    if (l->nworkers == MAX_CONFIGS) {
        vw_cli_error(CMD, "%s: at most %d worker counts", opt, MAX_CONFIGS);
        return -1;
    }
    return vw_cli_int(CMD, opt, item, 1, 1024, &l->workers[l->nworkers++]);
}

static void layout_name(const int dims[3], char *buf, size_t len)
{
    if (dims[2] > 1) snprintf(buf, len, "%dx%dx%d", dims[0], dims[1], dims[2]);
    else if (dims[1] > 1) snprintf(buf, len, "%dx%d", dims[0], dims[1]);
    else snprintf(buf, len, "%d", dims[0]);
}

/* The round with the least v (the first of equals). */
static int best_round(const double *v, int n)
{
    int b = 0;
    for (int i = 1; i < n; i++)
        if (v[i] < v[b]) b = i;
    return b;
}

static double best(const double *v, int n) { return v[best_round(v, n)]; }

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The median of a[i] / b[i] over the rounds: each round ran every configuration at the
   machine's speed of the moment. */
static double median_ratio(const double *a, const double *b, int n)
{
    double r[MAX_ROUNDS];
    for (int i = 0; i < n; i++) r[i] = b[i] > 0 ? a[i] / b[i] : 0;
    qsort(r, (size_t)n, sizeof *r, cmp_double);
    return n % 2 ? r[n / 2] : 0.5 * (r[n / 2 - 1] + r[n / 2]);
}

/* ", \"name\": [v0, v1, ...]": every round's seconds. 0 when out of memory. */
static int rounds_json(char **buf, size_t *len, size_t *cap, const char *name, const double *v, int n)
{
    char x[32];
    int ok = vw_cli_appendf(buf, len, cap, ", \"%s\": [", name);
    for (int i = 0; i < n && ok; i++)
        ok = vw_cli_appendf(buf, len, cap, "%s%s", i ? ", " : "", vw_cli_json_number(v[i], x));
    return ok && vw_cli_appendf(buf, len, cap, "]");
}

/* One render of configuration c (base: the parameters every configuration shares; its
   times go to round `round`; last: it is the last configuration); the output process
   keeps the pixel sums of the first render in *ref (allocated here) and compares every
   later render's with them: the first pixel that differs goes to *bad_pixel. The rays of the first render go to *ref_rays (-1 before
   it); a later render that traced another number sets *bad_rays (every process alike:
   the counters are summed over the processes). */
static vw_status run_one(const vw_scene *scene, const rt_params *base, bench_config *c, int round,
                         int last, int64_t **ref, size_t *nref, long long *bad_pixel,
                         long long *ref_rays, int *bad_rays, char *err, size_t errlen)
{
    rt_params p = *base;
    memcpy(p.dims, c->dims, sizeof p.dims);
    p.workers = (int)c->workers;
    rt_job *job = NULL;
    double t0 = vw_cli_now();
    vw_status st = rt_job_create(scene, &p, &job, err, errlen);
    if (st == VW_OK) st = rt_job_commit(job, err, errlen);
    double t1 = vw_cli_now();
    if (st == VW_OK) st = rt_job_run(job, err, errlen);
    double t2 = vw_cli_now();
    if (st != VW_OK) {
        rt_job_free(job);
        return st;
    }
    c->build[round] = t1 - t0;
    c->compute[round] = t2 - t1;
    vw_world *w = rt_job_world(job);
    c->lambda[round] = vw_world_imbalance(w);
    c->rays = vw_world_counter(w, RT_C_EYE) + vw_world_counter(w, RT_C_REFLECT) +
              vw_world_counter(w, RT_C_REFRACT) + vw_world_counter(w, RT_C_SHADOW);
    /* VW_FAULT=bench-rays (tests): the last configuration taken as one ray more. */
    if (last && vw_cli_fault("bench-rays")) c->rays++;
    if (*ref_rays < 0)
        *ref_rays = c->rays;
    else if (c->rays != *ref_rays)
        *bad_rays = 1;
    c->segments = vw_world_counter(w, RT_C_SEGMENTS);
    vw_traffic tr;
    vw_world_traffic(w, &tr); /* collective */
    c->messages = tr.msgs;
    c->cells = vw_decomp_cell_count(vw_world_decomp(w));
    c->copies = rt_job_farm_copies(job);
    c->all_workers = vw_world_workers(w) * vw_world_processes(w);
    st = VW_OK;
    if (rt_job_is_output(job)) {
        const rt_shared *sh = rt_job_shared(job);
        size_t n = (size_t)sh->view.width * (size_t)sh->view.height * 3;
        const int64_t *sums = rt_job_sums(job);
        if (!*ref) {
            *ref = vw_cli_fault("bench-nomem") ? NULL : malloc(n * sizeof **ref);
            if (*ref) {
                memcpy(*ref, sums, n * sizeof **ref);
                *nref = n;
            } else {
                snprintf(err, errlen, "out of memory for the reference image");
                st = VW_E_NOMEM;
            }
        } else {
            for (size_t i = 0; i < n && i < *nref; i++)
                /* VW_FAULT=bench-mismatch (tests): the last configuration's last pixel
                   is taken as one that differs. */
                if (sums[i] != (*ref)[i] || (i == n - 1 && last && vw_cli_fault("bench-mismatch"))) {
                    *bad_pixel = (long long)(i / 3);
                    break;
                }
        }
    }
    /* The output process alone kept the image: all stop if it could not, or the others
       would wait for it in the next render. */
    st = vw_world_agree(rt_job_world(job), st, err, errlen);
    rt_job_free(job);
    return st;
}

int vw_cmd_bench(int argc, char **argv)
{
    const char *scene_path = NULL, *csv = NULL, *stats = NULL, *v;
    double t0 = vw_cli_now();
    int width = 256, height = 256, quiet = 0, farm = -1, cells_given = 0, workers_given = 0;
    int has_world = 0;
    vw_box world_min;
    long depth = 5, repeat = 3;
    lists L;
    memset(&L, 0, sizeof L);
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        int taken;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            help();
            return VW_EXIT_OK;
        } else if (!strcmp(a, "--quiet") || !strcmp(a, "-q")) {
            quiet = 1;
        } else if (!strcmp(a, "--cells")) {
            L.nlayouts = 0;
            if (!(v = vw_cli_value(CMD, argc, argv, &i)) || each_item(a, v, one_layout, &L))
                return VW_EXIT_USAGE;
            cells_given = 1;
        } else if (!strcmp(a, "--workers")) {
            L.nworkers = 0;
            if (!(v = vw_cli_value(CMD, argc, argv, &i)) || each_item(a, v, one_workers, &L))
                return VW_EXIT_USAGE;
            workers_given = 1;
        } else if ((taken = vw_cli_image_option(CMD, argc, argv, &i, &width, &height, &depth))) {
            if (taken < 0) return VW_EXIT_USAGE;
        } else if (!strcmp(a, "--repeat")) {
            if (!(v = vw_cli_value(CMD, argc, argv, &i)) ||
                vw_cli_int(CMD, a, v, 1, MAX_ROUNDS, &repeat))
                return VW_EXIT_USAGE;
        } else if (!strcmp(a, "--farm")) {
            if (!(v = vw_cli_value(CMD, argc, argv, &i)) || vw_cli_farm(CMD, v, &farm))
                return VW_EXIT_USAGE;
        } else if (!strcmp(a, "--world")) {
            if (vw_cli_box(CMD, a, vw_cli_value(CMD, argc, argv, &i), &world_min))
                return VW_EXIT_USAGE;
            has_world = 1;
        } else if (!strcmp(a, "--csv")) {
            if (!(csv = vw_cli_output(CMD, argc, argv, &i))) return VW_EXIT_USAGE;
        } else if (!strcmp(a, "--stats")) {
            if (!(stats = vw_cli_output(CMD, argc, argv, &i))) return VW_EXIT_USAGE;
        } else if (vw_cli_scene_arg(CMD, a, &scene_path)) {
            return VW_EXIT_USAGE;
        }
    }
    if (!cells_given) {
        L.nlayouts = 2;
        int d[2][3] = {{1, 1, 1}, {2, 2, 2}};
        memcpy(L.dims, d, sizeof d);
    }
    if (!workers_given) {
        /* 1 and the world's default (one per core; under MPI the fewest of any host). */
        long cores = vw_cli_job_workers(0) / vw_engine_size();
        L.nworkers = cores > 1 ? 2 : 1;
        L.workers[0] = 1;
        L.workers[1] = cores;
    }
    int nconf = L.nlayouts * L.nworkers;
    if (nconf > MAX_CONFIGS) {
        vw_cli_error(CMD, "%d configurations (layouts x worker counts): at most %d", nconf,
                     MAX_CONFIGS);
        return VW_EXIT_USAGE;
    }
    {
        const char *opts[] = {"--csv", "--stats"};
        const char *paths[] = {csv, stats};
        const char *inputs[] = {scene_path, NULL};
        int crc = vw_cli_check_files(CMD, inputs, opts, paths, 2);
        if (crc != VW_EXIT_OK) return crc;
    }

    /* The scene: every process reads (or makes) its own and all agree. */
    int rc = VW_EXIT_OK;
    char err[1024] = "";
    vw_scene *scene = NULL;
    if (scene_path) {
        if (vw_scene_read_file(scene_path, &scene, err, sizeof err) != VW_OK) rc = VW_EXIT_USAGE;
    } else {
        char why[512] = "";
        if (vw_gen("balls", NULL, &scene, why, sizeof why) != VW_OK)
            rc = vw_cli_fail(CMD, VW_EXIT_FAIL, err, sizeof err, "generating the sphereflake: %s", why);
    }
    if ((rc = vw_cli_agree(CMD, rc, err, sizeof err)) != VW_EXIT_OK) {
        vw_scene_free(scene);
        return rc;
    }
    vw_camera cam = scene->camera;
    if (!cam.valid) {
        cam.width = cam.height = 0;
        vw_scene_default_camera(scene, &cam);
    }
    if (vw_cli_same_view(CMD, width, height, depth, &cam, scene) || vw_cli_same_scene(CMD, scene)) {
        vw_scene_free(scene);
        return VW_EXIT_USAGE;
    }
    { /* no output over one of the scene's material libraries */
        const char *opts[] = {"--csv", "--stats"};
        const char *paths[] = {csv, stats};
        int crc = vw_cli_check_scene_files(CMD, scene, opts, paths, 2);
        if (crc != VW_EXIT_OK) {
            vw_scene_free(scene);
            return crc;
        }
    }

    bench_config *conf = calloc((size_t)nconf, sizeof *conf);
    if (!conf) rc = vw_cli_fail(CMD, VW_EXIT_FAIL, err, sizeof err, "out of memory for the table");
    if ((rc = vw_cli_agree(CMD, rc, err, sizeof err)) != VW_EXIT_OK) {
        vw_scene_free(scene);
        free(conf);
        return rc;
    }
    for (int l = 0, k = 0; l < L.nlayouts; l++)
        for (int wk = 0; wk < L.nworkers; wk++, k++) {
            memcpy(conf[k].dims, L.dims[l], sizeof conf[k].dims);
            conf[k].workers = L.workers[wk];
        }
    int out = vw_cli_is_output();
    if (!quiet && out) {
        printf("bench: %s: %zu objects, %dx%d, depth %ld, %d configuration%s x %ld round%s, "
               "%d process%s\n",
               scene_path ? scene_path : "the sphereflake of vwalls gen balls",
               vw_scene_count_objects(scene), width, height, depth, nconf, nconf == 1 ? "" : "s",
               repeat, repeat == 1 ? "" : "s", vw_engine_size(), vw_engine_size() == 1 ? "" : "es");
        fflush(stdout);
    }

    vw_progress bar;
    vw_progress_begin(&bar, "bench", quiet || !out ? VW_PROGRESS_OFF : VW_PROGRESS_AUTO);
    int64_t *ref = NULL;
    size_t nref = 0;
    long long bad_pixel = -1, ref_rays = -1, bad_rays_count = 0;
    int bad_conf = -1, bad_rays_conf = -1;
    /* A first render, not counted, pays what only the first render of a process pays
       (Embree's start, the first touch of the heap), which the first configuration
       would otherwise carry in round 1. */
    bench_config warm = conf[0];
    long long px0 = -1;
    int rays0 = 0;
    rt_params base;
    memset(&base, 0, sizeof base);
    base.width = width;
    base.height = height;
    base.depth = (int)depth;
    base.camera = &cam;
    base.world_min = has_world ? &world_min : NULL;
    base.farm_first = 1; /* no balancer and no new mapping: the copies come first */
    base.farm = (rt_farm)vw_cli_farm_resolve(farm, 0);
    vw_status st = run_one(scene, &base, &warm, 0, 0, &ref, &nref, &px0, &ref_rays, &rays0, err,
                           sizeof err);
    for (int r = 0; r < repeat && st == VW_OK; r++)
        for (int k = 0; k < nconf && st == VW_OK; k++) {
            long long px = -1;
            int bad_rays = 0;
            st = run_one(scene, &base, &conf[k], r, k == nconf - 1, &ref, &nref, &px, &ref_rays,
                         &bad_rays, err, sizeof err);
            if (px >= 0 && bad_conf < 0) bad_conf = k, bad_pixel = px;
            if (bad_rays && bad_rays_conf < 0) bad_rays_conf = k, bad_rays_count = conf[k].rays;
            char note[64];
            snprintf(note, sizeof note, "round %d of %ld", r + 1, repeat);
            vw_progress_update(&bar, (double)(r * nconf + k + 1) / (double)(repeat * nconf), note);
        }
    vw_progress_end(&bar);
    free(ref);
    /* The stats' head, while the scene is at hand (the table's rows follow). */
    char *js = NULL;
    size_t jl = 0, jc = 0;
    int jok = 1;
    if (st == VW_OK && stats && out) {
        long most = 1;
        for (int k = 0; k < L.nworkers; k++)
            if (L.workers[k] > most) most = L.workers[k];
        jok = vw_cli_stats_begin(&js, &jl, &jc, CMD, (int)most);
        jok = jok && vw_cli_appendf(&js, &jl, &jc, ",\n  \"scene\": {\"file\": ");
        jok = jok && vw_cli_json_string(&js, &jl, &jc, scene_path);
        if (!scene_path) jok = jok && vw_cli_appendf(&js, &jl, &jc, ", \"generator\": \"balls\"");
        jok = jok && vw_cli_appendf(&js, &jl, &jc, ", ");
        jok = jok && vw_cli_scene_json(&js, &jl, &jc, scene);
        jok = jok && vw_cli_appendf(&js, &jl, &jc,
                                    "},\n  \"image\": {\"width\": %d, \"height\": %d, \"depth\": %ld},"
                                    "\n  \"rounds\": %ld,\n  \"farm\": \"%s\",\n  \"world\": ",
                                    width, height, depth, repeat,
                                    farm < 0 ? "auto" : rt_farm_name((rt_farm)farm));
        if (has_world)
            jok = jok && vw_cli_box_json(&js, &jl, &jc, world_min.lo, world_min.hi);
        else
            jok = jok && vw_cli_appendf(&js, &jl, &jc, "null");
        jok = jok && vw_cli_appendf(&js, &jl, &jc, ",\n  \"configurations\": [");
    }
    vw_scene_free(scene);
    if (st != VW_OK) {
        vw_cli_error(CMD, "%s", err);
        free(conf);
        return st == VW_E_INVAL ? VW_EXIT_USAGE : VW_EXIT_FAIL;
    }

    if (out) {
        const bench_config *b = &conf[0];
        double bc = best(b->compute, (int)repeat);
        char *table = NULL, *csvtext = NULL;
        size_t tl = 0, tc = 0, cl = 0, cc = 0;
        int ok = vw_cli_appendf(&table, &tl, &tc,
                                "%-10s %5s %7s %6s %8s %9s %8s %7s %10s %7s %10s %9s\n", "cells",
                                "count", "workers", "copies", "build s", "compute s", "speedup",
                                "median", "efficiency", "lambda", "visits/ray", "messages");
        ok &= vw_cli_appendf(&csvtext, &cl, &cc,
                             "cells,cell_count,workers,copies,build_s,compute_s,speedup,"
                             "speedup_median,efficiency,lambda,visits_per_ray,messages\n");
        for (int k = 0; k < nconf; k++) {
            const bench_config *c = &conf[k];
            char name[64];
            layout_name(c->dims, name, sizeof name);
            double cb = best(c->compute, (int)repeat), bb = best(c->build, (int)repeat);
            double speedup = cb > 0 ? bc / cb : 0;
            double med = median_ratio(b->compute, c->compute, (int)repeat);
            double eff = c->all_workers > 0 ? speedup * b->all_workers / c->all_workers : 0;
            double visits = c->rays > 0 ? (double)c->segments / (double)c->rays : 0;
            double lambda = c->lambda[best_round(c->compute, (int)repeat)];
            ok &= vw_cli_appendf(&table, &tl, &tc,
                                 "%-10s %5d %7d %6d %8.3f %9.3f %8.2f %7.2f %10.2f %7.3f %10.2f %9llu\n",
                                 name, c->cells, c->all_workers, c->copies, bb, cb, speedup, med, eff,
                                 lambda, visits, c->messages);
            ok &= vw_cli_appendf(&csvtext, &cl, &cc, "%s,%d,%d,%d,%.6f,%.6f,%.4f,%.4f,%.4f,%.4f,%.4f,%llu\n",
                                 name, c->cells, c->all_workers, c->copies, bb, cb, speedup, med, eff,
                                 lambda, visits, c->messages);
            if (js) {
                char n[7][32];
                jok = jok && vw_cli_appendf(&js, &jl, &jc,
                    "%s\n    {\"layout\": \"%s\", \"cells\": %d, \"workers\": %d, "
                    "\"workers_per_process\": %ld, \"copies\": %d, \"build_s\": %s, \"compute_s\": %s, "
                    "\"speedup\": %s, \"speedup_median\": %s, \"efficiency\": %s, \"imbalance\": %s, "
                    "\"rays\": %lld, \"segments\": %lld, \"visits_per_ray\": %s, \"messages\": %llu",
                    k ? "," : "", name, c->cells, c->all_workers, c->workers, c->copies,
                    vw_cli_json_number(bb, n[0]), vw_cli_json_number(cb, n[1]),
                    vw_cli_json_number(speedup, n[2]), vw_cli_json_number(med, n[3]),
                    vw_cli_json_number(eff, n[4]), vw_cli_json_number(lambda, n[5]), c->rays,
                    c->segments, vw_cli_json_number(visits, n[6]), c->messages);
                jok = jok && rounds_json(&js, &jl, &jc, "build_rounds_s", c->build, (int)repeat);
                jok = jok && rounds_json(&js, &jl, &jc, "compute_rounds_s", c->compute, (int)repeat);
                jok = jok && rounds_json(&js, &jl, &jc, "imbalance_rounds", c->lambda, (int)repeat);
                jok = jok && vw_cli_appendf(&js, &jl, &jc, "}");
            }
        }
        if (js) jok = jok && vw_cli_appendf(&js, &jl, &jc, "\n  ],\n  \"images_identical\": %s",
                                            bad_conf < 0 ? "true" : "false");
        if (!ok || (stats && !jok)) {
            vw_cli_error(CMD, "out of memory for the table");
            rc = VW_EXIT_FAIL;
        } else {
            fputs(table, stdout);
            if (!quiet)
                printf("speedup: the first row's compute time over this row's (best of %ld "
                       "round%s; median: of the ratios within each round); efficiency: speedup "
                       "x the first row's workers / this row's\n",
                       repeat, repeat == 1 ? "" : "s");
            if (bad_conf >= 0) {
                char name[64];
                layout_name(conf[bad_conf].dims, name, sizeof name);
                vw_cli_error(CMD, "cells %s on %ld worker%s rendered another image than the first "
                                  "configuration: pixel (%lld, %lld) differs (every layout and worker count "
                                  "must give the same image, bit for bit)",
                             name, conf[bad_conf].workers, conf[bad_conf].workers == 1 ? "" : "s",
                             bad_pixel % width, bad_pixel / width);
                rc = VW_EXIT_FAIL;
            } else if (!quiet) {
                printf("images: identical in all %d configurations (fixed-point pixel sums)\n", nconf);
            }
            if (bad_rays_conf >= 0) {
                char name[64];
                const bench_config *c = &conf[bad_rays_conf];
                layout_name(c->dims, name, sizeof name);
                vw_cli_error(CMD, "cells %s on %ld worker%s traced %lld rays, the first configuration "
                                  "%lld (every layout and worker count must trace the same rays)",
                             name, c->workers, c->workers == 1 ? "" : "s", bad_rays_count, ref_rays);
                rc = VW_EXIT_FAIL;
            } else if (!quiet) {
                printf("rays: %lld in every configuration (eye, reflected, refracted and shadow "
                       "rays: the same rays, so visits per ray compare)\n", ref_rays);
            }
            /* A failed run leaves no output, as every command's; the CSV and the stats
               appear together or not at all. */
            if (rc == VW_EXIT_OK && (csv || stats)) {
                vw_outfile_hold();
                if (csv && vw_outfile_write(csv, csvtext, cl, err, sizeof err) != VW_OK) {
                    vw_cli_error(CMD, "%s", err);
                    rc = VW_EXIT_FAIL;
                }
                if (rc == VW_EXIT_OK && stats)
                    rc = vw_cli_stats_end(CMD, stats, &js, &jl, &jc, t0, NULL, NULL, 0);
                if (vw_outfile_release(rc == VW_EXIT_OK, err, sizeof err) != VW_OK && rc == VW_EXIT_OK) {
                    vw_cli_error(CMD, "%s", err);
                    rc = VW_EXIT_FAIL;
                }
            }
        }
        free(table);
        free(csvtext);
    }
    free(js);
    free(conf);
    return rc;
}
