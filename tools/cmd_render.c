/* cmd_render.c - vwalls render: the distributed ray tracer on an NFF, OBJ or PLY scene,
 * writing a PNG or PFM (atomically, by the output process only), and optionally the
 * stats JSON and a picture of the walls tinted by each cell's measured load.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>

#include "cli.h"
#include "commands.h"
#include "raytrace/raytrace.h"
#include "vwalls/image.h"

enum { MAX_LIGHTS = 64 }; /* --light */

static const char *const CMD = "render";

static void help(void)
{
    printf("usage: vwalls render SCENE.(nff|obj|ply) -o OUT.(png|pfm) [options]\n"
           "\n"
           "Ray traces the scene (Whitted: Phong lights with shadow rays, mirror reflection,\n"
           "refraction) with rays travelling as messages between the cells of a grid of\n"
           "virtual walls. The image is bit-identical for every layout and worker count.\n"
           "  -o, --output FILE  output image, .png (8-bit) or .pfm (float, unclamped)\n"
           "  --cells L        layout of cells, like 4, 2x4, 2x2x2 (default 1; at most\n"
           "                   32768 cells)\n"
           "  --workers W      worker threads per process, 1 to 1024 (default: the cores\n"
           "                   it may run on, as nproc counts, or a cgroup CPU quota's\n"
           "                   rounded up; under MPI, its share of its host's, the fewest\n"
           "                   of any process)\n"
           "  --size WxH       image size (default: the scene's, else 512x512)\n"
           "  --depth D        maximum ray depth, 1 to 64; eye rays are depth 1 (default 5)\n"
           "  --from X,Y,Z --at X,Y,Z --up X,Y,Z --angle DEG\n"
           "                   override the camera (angle: full vertical field of view,\n"
           "                   above 0 and below 180 degrees, as in an NFF file)\n"
           "  --light X,Y,Z[,R,G,B]  replace the scene's lights: each --light adds one point\n"
           "                   light (up to 64); without a colour, 1/sqrt(lights) each,\n"
           "                   as NFF gives a light without one; a colour is taken as an\n"
           "                   NFF 'l' takes it (negative darkens)\n"
           "  --world X0,Y0,Z0,X1,Y1,Z1  the world box covers at least this box (default:\n"
           "                   the scene's bounds, padded, which it always covers): the\n"
           "                   walls then divide the space the scene is meant to fill, as\n"
           "                   the paper's grids do, not only where its objects lie\n"
           "  --stats FILE     write the stats JSON\n"
           "  --overlay FILE   write a PNG of the image with the walls drawn and each pixel\n"
           "                   tinted by the measured load of the cell where its eye ray\n"
           "                   hit (green light .. red heavy; no tint where it hit nothing)\n"
           "  --balance S      none|tensor|rotate|staggered|divide|duplicate: a sparse pre-pass\n"
           "                   measures where the work lies, the balancer moves the walls (or,\n"
           "                   duplicate, copies overloaded cells to idle workers, which share\n"
           "                   their rays), then the full render (the image does not change)\n"
           "  --balance-load M busy (measured time) | searches (counted ray-cell visits that\n"
           "                   search the cell's objects) | segments (all counted ray-cell\n"
           "                   visits, also those passing through empty space) | model\n"
           "                   (objects + pixels + messages); the counts are deterministic;\n"
           "                   default: busy, or segments where the workers outnumber the\n"
           "                   cores (busy time is then mostly waiting for a core)\n"
           "  --balance-iters N  pre-pass / balance rounds, 1 to 20 (default 2; divide and\n"
           "                     rotate take up to 3 more, stopping when no gain is\n"
           "                     predicted)\n"
           "  --prepass N      pre-pass traces every N-th row and column, N from 1 to 256\n"
           "                   (default: about 256 eye rays per cell, N between 1 and 8)\n"
           "  --farm F         auto (default) | all | idle | none: the workers of a process\n"
           "                   share its cells by holding copies; all: every worker gets one\n"
           "                   of every cell (rays cross only to other processes; the copies\n"
           "                   read one built scene); idle: only workers that host no cell get\n"
           "                   copies (of all the process's cells); none: the mapping alone;\n"
           "                   auto: all, or idle when --balance or --map is given (even\n"
           "                   none or block: their plan decides which worker runs which\n"
           "                   cell); a process hosting no cell farms them all\n"
           "                   (but with none, it idles)\n"
           "  --map K          block (default) | greedy (by load) | weighted (by --speeds)\n"
           "  --speeds LIST    relative speed of every worker, like 1,1,2,4: --map weighted\n"
           "                   maps by them, and copies of cells take shares of the work\n"
           "                   in proportion (--slow W:K gives worker W the speed 1/K);\n"
           "                   one per worker of the job: processes x --workers (default:\n"
           "                   the fewest cores of any process, see --workers)\n"
           "  --slow W:K[,..]  worker W does its work K times slower, K from 1 to 1000\n"
           "                   (emulates a slow machine); each worker at most once\n"
           "  --steal S        auto (default) | on | off: a copy that is done takes the\n"
           "                   turns other copies of its cell (on any process) have not\n"
           "                   taken; off: every copy makes exactly its share; auto: on\n"
           "                   when a process has no more workers than cores\n"
           "  --overlay-by B   load (default): each pixel by the load of the cell its eye\n"
           "                   ray hit in; entry: by the load of the cell where its eye ray\n"
           "                   entered the world (the cells' primary pixels: the viewport's\n"
           "                   projection onto the cells); worker: by the worker that made\n"
           "                   its eye ray (farmed cells show their copies' turns)\n"
           "  --progress       the progress bar even when stderr is no terminal (mpirun)\n"
           "  -q, --quiet      no progress bar and no summary\n"
           "  --help           this text\n"
           "The outputs (-o, --stats, --overlay) must be files other than each other and the\n"
           "scene (devices like /dev/null excepted); \"-\" is not standard output.\n"
           "Runs under mpirun too; only the first process writes files.\n"
           "\nexit status: 0 success, 2 bad input or usage, 1 any other failure\n");
}


/* The progress bar: a small thread polls the output handler's atomic counter, so the
   workers never wait for the terminal. It sleeps on a condition, so that the end of the
   render wakes it at once instead of after its tenth of a second. */
typedef struct progress_ctx {
    rt_job *job;
    vw_progress bar;
    pthread_mutex_t lock;
    pthread_cond_t wake;
    int stop; /* under lock */
    double t0;
} progress_ctx;

static void *progress_main(void *arg)
{
    progress_ctx *p = arg;
    int64_t total = rt_job_primary_pixels(p->job);
    for (;;) {
        struct timespec until;
        clock_gettime(CLOCK_REALTIME, &until);
        until.tv_nsec += 100 * 1000 * 1000;
        if (until.tv_nsec >= 1000000000L) until.tv_sec++, until.tv_nsec -= 1000000000L;
        pthread_mutex_lock(&p->lock);
        while (!p->stop && pthread_cond_timedwait(&p->wake, &p->lock, &until) == 0) {
        }
        int stop = p->stop;
        pthread_mutex_unlock(&p->lock);
        int64_t done, rays; /* and at the end the final state, 100 % */
        rt_job_progress(p->job, &done, &rays);
        double el = vw_cli_now() - p->t0;
        char note[64];
        snprintf(note, sizeof note, "%.2f Mrays/s", el > 0 ? rays / el * 1e-6 : 0.0);
        vw_progress_update(&p->bar, total > 0 ? (double)done / (double)total : 1.0, note);
        if (stop) return NULL;
    }
}

/* ---- balancing: a sparse pre-pass, the balancer, then the full render ----------------- */

/* JSON has no NaN nor infinity, and one "inf" makes the whole file unreadable: every
   double of balance_detail goes through num(), as every double of the core's stats does
   (src/core/stats.c; 0 stands for "not measured"). A lambda is infinite where a worker
   is next to infinitely slower than another (--speeds 1e308,1). */
static double num(double x) { return isfinite(x) ? x : 0.0; }

/* The copies of cells the balancer made (--balance duplicate) in the world as it
   renders: all its copies less the farm's (made after balancing, counted apart in
   farm_copies). What the last balancing round added said 0 when that round kept the
   copies it found, or when the best layout, copies and all, was restored. */
static int world_duplicates(vw_world *w, int farm_copies)
{
    int n = 0, nc = vw_decomp_cell_count(vw_world_decomp(w));
    for (int c = 0; c < nc; c++) n += vw_world_replicas(w, c, NULL, 0);
    return n - farm_copies;
}

/* The stats JSON member "balance_detail" appended to the ray tracer's members. */
static char *with_balance_json(char *rt, rt_job *job, vw_world *w, const vw_traffic *tr,
                               const rt_balance_result *bi,
                               vw_balance_strategy s, vw_map_kind map, const vw_load_spec *ls,
                               const double *speeds, rt_farm farm, int farm_copies)
{
    if (!rt) return NULL;
    /* A counted load is named by its counter ("segments", "searches"). */
    static const char *const models[] = {"busy", "counter", "model"};
    const char *model = ls->model == VW_LOAD_COUNTER && ls->counter >= 0 &&
                                ls->counter < rt_module.ncounters
                            ? rt_module.counters[ls->counter]
                            : models[ls->model <= VW_LOAD_MODEL ? ls->model : 0];
    size_t n = strlen(rt) + 1024;
    char *out = malloc(n);
    if (!out) return rt;
    snprintf(out, n,
             "%s,\n  \"balance_detail\": {\"strategy\": \"%s\", \"map\": \"%s\", "
             "\"load_model\": \"%s\", \"rounds\": %d, \"imbalance_before\": %.6g, "
             "\"imbalance_predicted\": %.6g, \"imbalance_after\": %.6g, "
             "\"imbalance_work\": %.6g, \"migrated_objects\": %llu, \"bytes_moved\": %llu, "
             "\"max_neighbours\": %d, \"prepass_s\": %.6f, \"balance_s\": %.6f, "
             "\"prepass_stride\": %d, \"reverted\": %d, \"imbalance_measured\": %.6g, "
             "\"duplicates\": %d, \"farm\": \"%s\", \"farm_copies\": %d},\n"
             "  \"traffic\": {\"messages\": %llu, \"bytes\": %llu, \"worker_messages\": %llu, "
             "\"worker_bytes\": %llu, \"process_messages\": %llu, \"process_bytes\": %llu, "
             "\"machine_messages\": %llu, \"machine_bytes\": %llu, \"share_worker\": %.6g, "
             "\"share_process\": %.6g, \"share_machine\": %.6g}",
             rt, vw_balance_strategy_name(s), vw_map_kind_name(map),
             model, bi->rounds,
             num(bi->rep.imbalance_before), num(bi->rep.imbalance_predicted),
             num(vw_world_imbalance(w)), num(rt_job_work_imbalance(job, speeds)),
             (unsigned long long)bi->migrated,
             (unsigned long long)bi->bytes, vw_decomp_max_neighbours(vw_world_decomp(w)),
             bi->prepass_s, vw_world_time(w, "balance"), bi->stride, bi->reverted, num(bi->measured),
             world_duplicates(w, farm_copies), rt_farm_name(farm), farm_copies, (unsigned long long)tr->msgs,
             (unsigned long long)tr->bytes, (unsigned long long)tr->msgs_worker,
             (unsigned long long)tr->bytes_worker, (unsigned long long)tr->msgs_process,
             (unsigned long long)tr->bytes_process, (unsigned long long)tr->msgs_machine,
             (unsigned long long)tr->bytes_machine,
             tr->msgs ? (double)tr->msgs_worker / (double)tr->msgs : 1.0,
             tr->msgs ? (double)tr->msgs_process / (double)tr->msgs : 1.0,
             tr->msgs ? (double)tr->msgs_machine / (double)tr->msgs : 1.0);
    free(rt);
    return out;
}

int vw_cli_farm(const char *cmd, const char *v, int *farm)
{
    if (!strcmp(v, "auto")) {
        *farm = -1;
        return 0;
    }
    if ((*farm = rt_farm_parse(v)) < 0) {
        vw_cli_error(cmd, "--farm: bad value '%s' (expected auto, all, idle or none)", v);
        return 1;
    }
    return 0;
}

/* auto: every worker holds every cell of its process, the fastest on one machine (a ray
   stays on its worker: no messages, no waiting for another worker), unless a balancer
   or a mapping was asked for: then their plan runs as planned. */
int vw_cli_farm_resolve(int farm, int planned)
{
    if (farm >= 0) return farm;
    return planned ? RT_FARM_IDLE : RT_FARM_ALL;
}

int vw_cmd_render(int argc, char **argv)
{
    const char *scene_path = NULL, *out = NULL, *stats = NULL, *overlay = NULL;
    int dims[3] = {1, 1, 1}, width = 0, height = 0, quiet = 0, progress = 0;
    long workers = 0, depth = 5;
    double from[3], at[3], up[3], angle = 0;
    int has_from = 0, has_at = 0, has_up = 0, has_angle = 0, has_world = 0;
    vw_box world_min;
    vw_light lights[MAX_LIGHTS];
    int light_color[MAX_LIGHTS]; /* was the colour given? */
    int nlights = 0;
    const char *speeds_s = NULL, *slow_s = NULL;
    vw_balance_strategy strategy = VW_BALANCE_NONE;
    int farm = -1, farm_copies = 0; /* -1: auto, resolved once the options are read */
    int steal = -1;                 /* vw_config.steal: -1 auto, 1 on, 0 off */
    vw_map_kind map = VW_MAP_BLOCK;
    int map_given = 0, balance_given = 0, by_worker = 0, by_entry = 0, by_given = 0;
    const char *tuning = NULL; /* a pre-pass option given: it needs --balance or --map */
    long iters = 2, prepass = 0; /* 0: rt_prepass_stride() */
    vw_load_spec lspec;
    vw_load_spec_init(&lspec);
    int load_given = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v;
        int taken;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            help();
            return VW_EXIT_OK;
        } else if (!strcmp(a, "--quiet") || !strcmp(a, "-q")) {
            quiet = 1;
        } else if (!strcmp(a, "--progress")) {
            progress = 1;
        } else if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
            if (!(out = vw_cli_output(CMD, argc, argv, &i))) return VW_EXIT_USAGE;
        } else if (!strcmp(a, "--cells")) {
            if (!(v = vw_cli_value(CMD, argc, argv, &i)) || vw_cli_layout(CMD, a, v, dims))
                return VW_EXIT_USAGE;
        } else if (!strcmp(a, "--workers")) {
            if (!(v = vw_cli_value(CMD, argc, argv, &i)) || vw_cli_int(CMD, a, v, 1, 1024, &workers))
                return VW_EXIT_USAGE;
        } else if ((taken = vw_cli_image_option(CMD, argc, argv, &i, &width, &height, &depth))) {
            if (taken < 0) return VW_EXIT_USAGE;
        } else if (!strcmp(a, "--stats")) {
            if (!(stats = vw_cli_output(CMD, argc, argv, &i))) return VW_EXIT_USAGE;
        } else if (!strcmp(a, "--overlay")) {
            if (!(overlay = vw_cli_output(CMD, argc, argv, &i))) return VW_EXIT_USAGE;
        } else if (!strcmp(a, "--balance")) {
            if (!(v = vw_cli_value(CMD, argc, argv, &i))) return VW_EXIT_USAGE;
            if (vw_balance_strategy_parse(v, &strategy) != VW_OK) {
                vw_cli_error(CMD, "--balance: bad value '%s' (expected none, tensor, rotate, "
                                  "staggered, divide or duplicate)", v);
                return VW_EXIT_USAGE;
            }
            balance_given = 1;
        } else if (!strcmp(a, "--balance-load")) {
            tuning = a;
            load_given = 1;
            if (!(v = vw_cli_value(CMD, argc, argv, &i))) return VW_EXIT_USAGE;
            if (!strcmp(v, "busy")) {
                lspec.model = VW_LOAD_BUSY;
            } else if (!strcmp(v, "segments")) {
                lspec.model = VW_LOAD_COUNTER;
                lspec.counter = RT_C_SEGMENTS;
            } else if (!strcmp(v, "searches")) {
                lspec.model = VW_LOAD_COUNTER;
                lspec.counter = RT_C_SEARCHES;
            } else if (!strcmp(v, "model")) {
                lspec.model = VW_LOAD_MODEL;
                lspec.counter = RT_C_PIXELS;
            } else {
                vw_cli_error(CMD, "--balance-load: bad value '%s' (expected busy, searches, segments "
                                  "or model)", v);
                return VW_EXIT_USAGE;
            }
        } else if (!strcmp(a, "--balance-iters")) {
            tuning = a;
            if (!(v = vw_cli_value(CMD, argc, argv, &i)) || vw_cli_int(CMD, a, v, 1, 20, &iters))
                return VW_EXIT_USAGE;
        } else if (!strcmp(a, "--prepass")) {
            tuning = a;
            if (!(v = vw_cli_value(CMD, argc, argv, &i)) || vw_cli_int(CMD, a, v, 1, 256, &prepass))
                return VW_EXIT_USAGE;
        } else if (!strcmp(a, "--map")) {
            if (!(v = vw_cli_value(CMD, argc, argv, &i))) return VW_EXIT_USAGE;
            if (vw_map_kind_parse(v, &map) != VW_OK) {
                vw_cli_error(CMD, "--map: bad value '%s' (expected block, greedy or weighted)", v);
                return VW_EXIT_USAGE;
            }
            map_given = 1;
        } else if (!strcmp(a, "--farm")) {
            if (!(v = vw_cli_value(CMD, argc, argv, &i)) || vw_cli_farm(CMD, v, &farm))
                return VW_EXIT_USAGE;
        } else if (!strcmp(a, "--steal")) {
            if (!(v = vw_cli_value(CMD, argc, argv, &i))) return VW_EXIT_USAGE;
            if (!strcmp(v, "auto") || !strcmp(v, "on") || !strcmp(v, "off")) {
                steal = !strcmp(v, "auto") ? -1 : !strcmp(v, "on");
            } else {
                vw_cli_error(CMD, "--steal: bad value '%s' (expected auto, on or off)", v);
                return VW_EXIT_USAGE;
            }
        } else if (!strcmp(a, "--speeds")) {
            if (!(speeds_s = vw_cli_value(CMD, argc, argv, &i))) return VW_EXIT_USAGE;
        } else if (!strcmp(a, "--slow")) {
            if (!(slow_s = vw_cli_value(CMD, argc, argv, &i))) return VW_EXIT_USAGE;
            if (!*slow_s) { /* the parse below reads no worker from it, and slowed none */
                vw_cli_error(CMD, "--slow: bad value '' (expected W:K,... with K from 1 to 1000)");
                return VW_EXIT_USAGE;
            }
        } else if (!strcmp(a, "--overlay-by")) {
            if (!(v = vw_cli_value(CMD, argc, argv, &i))) return VW_EXIT_USAGE;
            if (strcmp(v, "load") && strcmp(v, "entry") && strcmp(v, "worker")) {
                vw_cli_error(CMD, "--overlay-by: bad value '%s' (expected load, entry or worker)", v);
                return VW_EXIT_USAGE;
            }
            by_worker = !strcmp(v, "worker");
            by_entry = !strcmp(v, "entry");
            by_given = 1;
        } else if (!strcmp(a, "--world")) {
            if (vw_cli_box(CMD, a, vw_cli_value(CMD, argc, argv, &i), &world_min))
                return VW_EXIT_USAGE;
            has_world = 1;
        } else if (!strcmp(a, "--from")) {
            if (vw_cli_numbers(CMD, a, vw_cli_value(CMD, argc, argv, &i), "X,Y,Z", from, 3, 3,
                               NULL))
                return VW_EXIT_USAGE;
            has_from = 1;
        } else if (!strcmp(a, "--at")) {
            if (vw_cli_numbers(CMD, a, vw_cli_value(CMD, argc, argv, &i), "X,Y,Z", at, 3, 3,
                               NULL))
                return VW_EXIT_USAGE;
            has_at = 1;
        } else if (!strcmp(a, "--up")) {
            if (vw_cli_numbers(CMD, a, vw_cli_value(CMD, argc, argv, &i), "X,Y,Z", up, 3, 3,
                               NULL))
                return VW_EXIT_USAGE;
            has_up = 1;
        } else if (!strcmp(a, "--light")) {
            double l[6];
            int n = 0;
            if (nlights == MAX_LIGHTS) {
                vw_cli_error(CMD, "--light: at most %d lights", MAX_LIGHTS);
                return VW_EXIT_USAGE;
            }
            if (vw_cli_numbers(CMD, a, v = vw_cli_value(CMD, argc, argv, &i), "X,Y,Z or X,Y,Z,R,G,B",
                               l, 3, 6, &n))
                return VW_EXIT_USAGE;
            /* The colour as an NFF 'l' line takes it (nff.c): any number that fits a
               float, which vw_cli_numbers checks, negative too (a negative light
               darkens, as in POV-Ray; the pixel sums are signed). */
            if (n != 3 && n != 6) {
                vw_cli_error(CMD, "--light: bad value '%s' (expected X,Y,Z or X,Y,Z,R,G,B)", v);
                return VW_EXIT_USAGE;
            }
            light_color[nlights] = n == 6;
            vw_light *L = &lights[nlights++];
            for (int k = 0; k < 3; k++) {
                L->pos[k] = l[k];
                L->color[k] = n == 6 ? (float)l[3 + k] : 0.0f;
            }
        } else if (!strcmp(a, "--angle")) {
            /* Any angle an NFF file may give, which the ray tracer takes as given. */
            if (!(v = vw_cli_value(CMD, argc, argv, &i)) || vw_cli_angle(CMD, a, v, &angle))
                return VW_EXIT_USAGE;
            has_angle = 1;
        } else if (vw_cli_scene_arg(CMD, a, &scene_path)) {
            return VW_EXIT_USAGE;
        }
    }
    if (!scene_path || !out) {
        vw_cli_error(CMD, "need a scene and -o OUT.png (try --help)");
        return VW_EXIT_USAGE;
    }
    if (vw_cli_named(CMD, "-o", out) || (overlay && vw_cli_named(CMD, "--overlay", overlay)))
        return VW_EXIT_USAGE;
    vw_image_format format = vw_image_format_of(out);
    int pfm = format == VW_IMAGE_PFM;
    if (format == VW_IMAGE_NONE) {
        vw_cli_error(CMD, "-o %s: the output must end in .png or .pfm", out);
        return VW_EXIT_USAGE;
    }
    if (overlay && vw_image_format_of(overlay) != VW_IMAGE_PNG) {
        vw_cli_error(CMD, "--overlay %s: the overlay must end in .png", overlay);
        return VW_EXIT_USAGE;
    }

    {
        /* A --stats into a missing directory failed after the image was written; a
           --stats naming the image or the scene replaced it. */
        const char *opts[] = {"-o", "--overlay", "--stats"};
        const char *paths[] = {out, overlay, stats};
        const char *inputs[] = {scene_path, NULL};
        int crc = vw_cli_check_files(CMD, inputs, opts, paths, 3);
        if (crc != VW_EXIT_OK) return crc;
    }

    /* Workers of the whole job, for --speeds and --slow (the world's own default when
       --workers is not given: one per core, under MPI each process's share of its
       host's cores, the fewest of any, so every host expects as many speeds). */
    int gw = vw_cli_job_workers(workers);
    /* Up to the world's creation, each process checks what it has itself (its memory,
       its scene file: every process reads its own copy) and all agree at the end of
       each phase: one that stopped alone would leave the others waiting in the next
       collective call. */
    int rc = VW_EXIT_OK;
    char err[1024] = "";
    double *speeds = NULL, *slowdown = NULL;
    if (speeds_s) {
        speeds = vw_cli_fault("speeds-nomem") ? NULL : malloc(sizeof(double) * (size_t)gw);
        if (!speeds)
            rc = vw_cli_fail(CMD, VW_EXIT_FAIL, err, sizeof err, "out of memory for --speeds");
        else if (vw_map_parse_speeds(speeds_s, speeds, gw) != VW_OK)
            rc = vw_cli_fail(CMD, VW_EXIT_USAGE, err, sizeof err, "--speeds: bad value '%s' "
                             "(expected %d positive number%s, one per worker: %d process%s x %d "
                             "worker%s%s)", speeds_s, gw, gw == 1 ? "" : "s", vw_engine_size(),
                             vw_engine_size() == 1 ? "" : "es", gw / vw_engine_size(),
                             gw / vw_engine_size() == 1 ? "" : "s",
                             workers > 0 ? "" : vw_engine_size() == 1 ? ", one per core; --workers sets them"
                                                                      : ", the fewest cores of any "
                                                                        "process; --workers sets them");
    }
    if (rc == VW_EXIT_OK && slow_s) {
        slowdown = malloc(sizeof(double) * (size_t)gw);
        if (!slowdown) rc = vw_cli_fail(CMD, VW_EXIT_FAIL, err, sizeof err, "out of memory for --slow");
        /* 0 until a worker is given: one given twice ("1:3,1:4") is a mistake, not
           the last one winning. */
        for (int g = 0; slowdown && g < gw; g++) slowdown[g] = 0;
        for (const char *q = slow_s; slowdown && *q;) {
            char *end;
            long wk = strtol(q, &end, 10);
            double k = 0;
            if (end != q && *end == ':') k = vw_cli_strtod(end + 1, &end);
            if (!(*q >= '0' && *q <= '9') || wk >= gw || !(k >= 1) || k > 1000 ||
                (*end && *end != ',') ||
                (*end == ',' && !end[1])) {
                rc = vw_cli_fail(CMD, VW_EXIT_USAGE, err, sizeof err, "--slow: bad value '%s' "
                                 "(expected W:K,... with worker W < %d and K from 1 to 1000)",
                                 slow_s, gw);
                break;
            }
            if (slowdown[wk] != 0) {
                rc = vw_cli_fail(CMD, VW_EXIT_USAGE, err, sizeof err, "--slow: bad value '%s' "
                                 "(worker %ld given twice)", slow_s, wk);
                break;
            }
            slowdown[wk] = k;
            q = *end ? end + 1 : end;
        }
        for (int g = 0; slowdown && g < gw; g++)
            if (slowdown[g] == 0) slowdown[g] = 1.0;
        /* A known slow-down is the calibration: its speed is 1/K. */
        if (rc == VW_EXIT_OK && !speeds) {
            speeds = malloc(sizeof(double) * (size_t)gw);
            if (!speeds) rc = vw_cli_fail(CMD, VW_EXIT_FAIL, err, sizeof err, "out of memory for --slow");
            for (int g = 0; speeds && g < gw; g++) speeds[g] = 1.0 / slowdown[g];
        }
    }

    double t_load0 = vw_cli_now();
    vw_scene *scene = NULL;
    /* Under MPI every process reads the scene; all stop if one cannot (a file missing on
       one host), and the output process says which and why (the parser's
       "file:line: message", under MPI with "rank R: " after its "file:line: "). */
    if (rc == VW_EXIT_OK && vw_scene_read_file(scene_path, &scene, err, sizeof err) != VW_OK)
        rc = VW_EXIT_USAGE;
    if ((rc = vw_cli_agree(CMD, rc, err, sizeof err)) != VW_EXIT_OK) {
        vw_scene_free(scene);
        free(speeds), free(slowdown);
        return rc;
    }
    if (nlights) { /* --light: these lights instead of the scene's */
        vw_light *L = malloc(sizeof *L * (size_t)nlights);
        if (L) {
            /* The NFF reader's rule (nff.c) for lights without a colour. */
            float dflt = (float)(1.0 / sqrt((double)nlights));
            for (int k = 0; k < nlights; k++) {
                L[k] = lights[k];
                if (!light_color[k]) L[k].color[0] = L[k].color[1] = L[k].color[2] = dflt;
            }
            free(scene->lights);
            scene->lights = L;
            scene->nlights = (size_t)nlights;
        } else {
            rc = vw_cli_fail(CMD, VW_EXIT_FAIL, err, sizeof err, "out of memory for the lights");
        }
    }
    vw_camera cam = scene->camera;
    if (!cam.valid) {
        cam.width = cam.height = 0;
        vw_scene_default_camera(scene, &cam);
    }
    if (has_from) memcpy(cam.from, from, sizeof from);
    if (has_at) memcpy(cam.at, at, sizeof at);
    if (has_up) memcpy(cam.up, up, sizeof up);
    if (has_angle) cam.angle = angle;
    /* A file's own camera was checked by its parser; the options are checked against it
       here, on every process's own copy of the file (--at at the scene's eye on one
       host only). */
    const char *camera_problem = vw_camera_problem(&cam);
    if (camera_problem && rc == VW_EXIT_OK)
        rc = vw_cli_fail(CMD, VW_EXIT_USAGE, err, sizeof err, "--from/--at/--up: %s", camera_problem);
    if ((rc = vw_cli_agree(CMD, rc, err, sizeof err)) != VW_EXIT_OK ||
        vw_cli_same_view(CMD, width, height, depth, &cam, scene) || vw_cli_same_scene(CMD, scene)) {
        vw_scene_free(scene);
        free(speeds), free(slowdown);
        return rc != VW_EXIT_OK ? rc : VW_EXIT_USAGE;
    }
    /* The file's resolution, too large, was refused by the ray tracer without its line;
       the same on every process (vw_cli_same_view compared it). */
    if (vw_cli_scene_size(scene_path, &cam, width)) {
        vw_scene_free(scene);
        free(speeds), free(slowdown);
        return VW_EXIT_USAGE;
    }
    {
        /* The material libraries the scene named are inputs too: a --stats x.mtl
           replaced the library of x.obj. Known only now that the scene is read. */
        const char *opts[] = {"-o", "--overlay", "--stats"};
        const char *paths[] = {out, overlay, stats};
        int crc = vw_cli_check_scene_files(CMD, scene, opts, paths, 3);
        if (crc != VW_EXIT_OK) {
            vw_scene_free(scene);
            free(speeds), free(slowdown);
            return crc;
        }
    }

    rt_params p;
    memset(&p, 0, sizeof p);
    p.width = width;
    p.height = height;
    p.depth = (int)depth;
    memcpy(p.dims, dims, sizeof dims);
    p.workers = (int)workers;
    p.camera = &cam;
    p.world_min = has_world ? &world_min : NULL;
    vw_config cfg;
    vw_config_init(&cfg);
    cfg.worker_slowdown = slowdown;
    cfg.worker_speeds = speeds; /* the shares of farmed and duplicated cells' copies */
    cfg.steal = steal;
    p.config = &cfg;
    farm = vw_cli_farm_resolve(farm, balance_given || map_given);
    /* The initial mapping is the one rendered (no balancer, no new mapping): its copies
       are made before the objects come, so under MPI each process keeps the records its
       copies need as they come, and none is fetched at the commit. */
    int balancing = strategy != VW_BALANCE_NONE || map != VW_MAP_BLOCK;
    p.farm_first = !balancing && !map_given && !speeds;
    p.farm = (rt_farm)farm;
    rt_job *job = NULL;
    vw_status st = rt_job_create(scene, &p, &job, err, sizeof err);
    size_t nobjects = vw_scene_count_objects(scene);
    vw_scene_free(scene);
    if (st != VW_OK) {
        vw_cli_error(CMD, "%s", err);
        free(speeds), free(slowdown);
        return st == VW_E_INVAL ? VW_EXIT_USAGE : VW_EXIT_FAIL;
    }
    vw_world *w = rt_job_world(job);
    /* The mapping of the initial cells (greedy and weighted refine it by load after the
       pre-pass, when there is one). */
    if (tuning && !balancing && vw_cli_is_output())
        fprintf(stderr, "vwalls render: warning: %s has no effect without a pre-pass (--balance "
                        "other than none, or --map greedy or weighted)\n", tuning);
    if (by_given && !overlay && vw_cli_is_output())
        fprintf(stderr, "vwalls render: warning: --overlay-by has no effect without --overlay\n");
    /* Busy time on more workers than cores is mostly time spent waiting for a core: the
       balancer would move walls by the scheduler's noise (docs/balancing.md). So the
       default load is then the counted visits (segments: searches alone hand the empty
       cells to one worker, and measured slower, docs/balancing.md); asked for, busy time
       is warned of. The cores are each process's share of its host's (processes that may
       run on the same cores split them), the fewest of any process, so every process
       decides alike: they must balance by the same load (collective under MPI: counted
       only when balancing, which every process is or none). */
    double cores = balancing ? vw_engine_core_share() : 0;
    int crowded = balancing && vw_world_workers(w) > cores;
    char cbuf[96];
    if (balancing && !load_given && crowded) {
        lspec.model = VW_LOAD_COUNTER;
        lspec.counter = RT_C_SEGMENTS;
        if (!quiet && vw_cli_is_output())
            fprintf(stderr, "vwalls render: %s: balancing on the counted "
                            "ray-cell visits (--balance-load segments), not on "
                            "busy time, which would be mostly waiting for a core\n",
                    vw_cli_crowding(vw_world_workers(w), cores, cbuf, sizeof cbuf));
    } else if (balancing && lspec.model == VW_LOAD_BUSY && crowded && vw_cli_is_output()) {
        fprintf(stderr, "vwalls render: warning: %s: their busy time is "
                        "mostly waiting for a core, a poor load to balance by (--balance-load "
                        "segments counts the work)\n",
                vw_cli_crowding(vw_world_workers(w), cores, cbuf, sizeof cbuf));
    }
    rt_balance_result bi;
    memset(&bi, 0, sizeof bi);
    if ((map_given || speeds) && rt_job_map(job, map, NULL, speeds, err, sizeof err) != VW_OK) {
        vw_cli_error(CMD, "%s", err);
        rt_job_free(job);
        free(speeds), free(slowdown);
        return VW_EXIT_FAIL;
    }
    double t_loaded = vw_cli_now(); /* the balance phase (pre-pass) is timed apart */
    if (balancing) {
        double tb0 = t_loaded;
        rt_balance rb = {strategy, map, speeds, lspec, (int)iters, (int)prepass};
        st = rt_job_balance(job, &rb, &bi, err, sizeof err);
        if (st != VW_OK) {
            vw_cli_error(CMD, "%s", err);
            rt_job_free(job);
            free(speeds), free(slowdown);
            return VW_EXIT_FAIL;
        }
        /* The balancer recorded its own computing time; add the pre-pass's. */
        vw_world_add_time(w, "balance", vw_cli_now() - tb0 - vw_world_time(w, "balance"));
    }
    double t_build0 = vw_cli_now();
    /* The worker and cell maps are the output process's alone: all stop if it has no
       room for one, or the others would wait for it in the farming and the commit. */
    if (overlay && by_worker &&
        (vw_cli_fault("eye-workers-nomem") && rt_job_is_output(job) ? VW_E_NOMEM
                                                                     : rt_job_record_eye_workers(job)) != VW_OK)
        rc = vw_cli_fail(CMD, VW_EXIT_FAIL, err, sizeof err, "out of memory for the overlay's worker map");
    if (overlay && !by_worker && !by_entry &&
        (vw_cli_fault("hit-cells-nomem") && rt_job_is_output(job) ? VW_E_NOMEM
                                                                   : rt_job_record_hit_cells(job)) != VW_OK)
        rc = vw_cli_fail(CMD, VW_EXIT_FAIL, err, sizeof err, "out of memory for the overlay's cell map");
    if ((rc = vw_cli_agree(CMD, rc, err, sizeof err)) != VW_EXIT_OK) {
        rt_job_free(job);
        free(speeds), free(slowdown);
        return rc;
    }
    if (p.farm_first)
        farm_copies = rt_job_farm_copies(job);
    if ((!p.farm_first && rt_job_farm(job, (rt_farm)farm, &farm_copies, err, sizeof err) != VW_OK) ||
        rt_job_commit(job, err, sizeof err) != VW_OK) {
        vw_cli_error(CMD, "%s", err);
        rt_job_free(job);
        free(speeds), free(slowdown);
        return VW_EXIT_FAIL;
    }
    double t_run0 = vw_cli_now();

    progress_ctx pc;
    memset(&pc, 0, sizeof pc);
    pc.job = job;
    pc.t0 = t_run0;
    pthread_mutex_init(&pc.lock, NULL);
    pthread_cond_init(&pc.wake, NULL);
    vw_progress_begin(&pc.bar, "render",
                      quiet || !rt_job_is_output(job) ? VW_PROGRESS_OFF
                      : progress                      ? VW_PROGRESS_ON
                                                      : VW_PROGRESS_AUTO);
    pthread_t th;
    int have_thread = pc.bar.enabled && pthread_create(&th, NULL, progress_main, &pc) == 0;
    st = rt_job_run(job, err, sizeof err);
    if (have_thread) {
        pthread_mutex_lock(&pc.lock);
        pc.stop = 1;
        pthread_cond_signal(&pc.wake);
        pthread_mutex_unlock(&pc.lock);
        pthread_join(th, NULL);
    }
    pthread_cond_destroy(&pc.wake);
    pthread_mutex_destroy(&pc.lock);
    vw_progress_end(&pc.bar);
    double t_run1 = vw_cli_now();
    if (st != VW_OK) {
        vw_cli_error(CMD, "%s", err);
        rt_job_free(job);
        free(speeds), free(slowdown);
        return VW_EXIT_FAIL;
    }
    /* Collective: every process calls it, only the output process writes it. */
    vw_traffic traffic;
    vw_world_traffic(w, &traffic);
    if (balancing)
        /* Before: measured by the pre-pass on the layout and mapping the balancer (or, with
           --map alone, the remap) started from; a mapping alone records no balance
           itself, and "before" showed the full render's lambda, as "after" does. After:
           measured on the full render (busy time over workers), not predicted. */
        vw_world_set_balance_info(w, vw_balance_strategy_name(strategy), bi.rep.imbalance_before,
                                  vw_world_imbalance(w), bi.migrated);
    vw_world_add_time(w, "load", t_loaded - t_load0);
    vw_world_add_time(w, "build", t_run0 - t_build0);
    vw_world_add_time(w, "compute", t_run1 - t_run0);

    if (rt_job_is_output(job)) {
        /* The image, the overlay and the stats appear together or not at all (a full
           disk at the stats leaves no image): released below. */
        vw_outfile_hold();
        const rt_shared *sh = rt_job_shared(job);
        int W = sh->view.width, H = sh->view.height;
        size_t n = (size_t)W * H * 3;
        if (pfm) {
            float *img = malloc(n * sizeof *img);
            if (!img) {
                vw_cli_error(CMD, "out of memory for a %dx%d image", W, H);
                rc = VW_EXIT_FAIL;
            } else {
                rt_job_rgbf(job, img);
                if (vw_image_write_pfm(out, W, H, img, err, sizeof err) != VW_OK) {
                    vw_cli_error(CMD, "%s", err);
                    rc = VW_EXIT_FAIL;
                }
                free(img);
            }
        } else {
            uint8_t *img = malloc(n);
            if (!img) {
                vw_cli_error(CMD, "out of memory for a %dx%d image", W, H);
                rc = VW_EXIT_FAIL;
            } else {
                rt_job_rgb8(job, img);
                if (vw_image_write_png_threads(out, W, H, img, vw_world_workers(w), err, sizeof err) != VW_OK) {
                    vw_cli_error(CMD, "%s", err);
                    rc = VW_EXIT_FAIL;
                }
                free(img);
            }
        }
        if (overlay && rc == VW_EXIT_OK) {
            uint8_t *img = malloc(n);
            if (img) {
                if (by_worker)
                    rt_job_overlay_workers(job, img);
                else
                    rt_job_overlay(job, img);
                if (vw_image_write_png_threads(overlay, W, H, img, vw_world_workers(w), err, sizeof err) != VW_OK) {
                    vw_cli_error(CMD, "%s", err);
                    rc = VW_EXIT_FAIL;
                }
                free(img);
            }
        }
        double t_end = vw_cli_now();
        vw_world_add_time(w, "write", t_end - t_run1);
        if (stats && rc == VW_EXIT_OK) {
            char *extra = with_balance_json(rt_job_stats_json(job), job, w, &traffic, &bi, strategy, map, &lspec,
                                            speeds, (rt_farm)farm, farm_copies);
            if (vw_world_write_stats(w, stats, CMD, extra) != VW_OK) {
                vw_cli_error(CMD, "%s", vw_world_errmsg(w));
                rc = VW_EXIT_FAIL;
            }
            free(extra);
        }
        if (vw_outfile_release(rc == VW_EXIT_OK, err, sizeof err) != VW_OK && rc == VW_EXIT_OK) {
            vw_cli_error(CMD, "%s", err);
            rc = VW_EXIT_FAIL;
        }
        if (!quiet && rc == VW_EXIT_OK) {
            long long eye = vw_world_counter(w, RT_C_EYE), refl = vw_world_counter(w, RT_C_REFLECT);
            long long refr = vw_world_counter(w, RT_C_REFRACT), shad = vw_world_counter(w, RT_C_SHADOW);
            long long total = eye + refl + refr + shad;
            double comp = t_run1 - t_run0;
            char layout[64];
            vw_decomp_layout_string(vw_world_decomp(w), layout, sizeof layout);
            printf("render %s -> %s: %dx%d, depth %d, %zu objects\n", scene_path, out, W, H,
                   sh->max_depth, nobjects);
            printf("cells %s (%d), workers %d x %d process%s, farm %s (%d cop%s), imbalance "
                   "lambda %.3f\n", layout, vw_decomp_cell_count(vw_world_decomp(w)),
                   vw_world_workers(w), vw_world_processes(w),
                   vw_world_processes(w) == 1 ? "" : "es", rt_farm_name((rt_farm)farm), farm_copies,
                   farm_copies == 1 ? "y" : "ies", vw_world_imbalance(w));
            if (balancing)
                printf("balance %s, map %s: lambda before %.3f, predicted %.3f, after %.3f "
                       "(work lambda %.3f); %llu objects migrated, %.3f s\n",
                       vw_balance_strategy_name(strategy), vw_map_kind_name(map),
                       bi.rep.imbalance_before, bi.rep.imbalance_predicted, vw_world_imbalance(w),
                       rt_job_work_imbalance(job, speeds), (unsigned long long)bi.migrated,
                       vw_world_time(w, "balance"));
            if (balancing && bi.reverted && !bi.rep.applied)
                printf("balance: every layout the balancer made measured worse than the first "
                       "in its pre-pass: the first kept\n");
            printf("time: load %.3f s, balance %.3f s, build %.3f s, compute %.3f s, write %.3f s, "
                   "total %.3f s\n", t_loaded - t_load0, t_build0 - t_loaded, t_run0 - t_build0, comp,
                   t_end - t_run1, t_end - t_load0);
            printf("rays: eye %lld, reflect %lld, refract %lld, shadow %lld; %lld in all, "
                   "%.3f Mrays/s\n",
                   eye, refl, refr, shad, total, comp > 0 ? total / comp * 1e-6 : 0.0);
        }
    }
    rt_job_free(job);
    free(speeds), free(slowdown);
    return rc;
}
