/* cmd_radiosity.c - vwalls radiosity: the distributed progressive radiosity solver on an
 * OBJ+MTL or NFF scene, writing a vertex-coloured PLY, a per-polygon CSV, a PNG, stats
 * and checkpoints (apps/radiosity does the work; this file is options and files).
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"
#include "commands.h"
#include "radiosity/radiosity.h"

static const char *const CMD = "radiosity";

static void help(void)
{
    printf("usage: vwalls radiosity SCENE.(obj|nff) -o OUT.ply [options]\n"
           "\n"
           "Progressive refinement radiosity, distributed over cells: every cell shoots its\n"
           "patch of largest unshot power; a shot travels from cell to cell as a hemicube\n"
           "coverage bitmap, front to back from the shooter, never as geometry.\n"
           "Emission comes from MTL 'Ke' (NFF: '#vw Ke r g b' after an 'f'), reflectance\n"
           "from 'Kd' (NFF: colour * Kd). PLY has no emission, so a PLY scene has no light:\n"
           "convert it to OBJ+MTL or NFF and give it one. Spheres and cones are meshed as\n"
           "fixed facets (a sphere 16 x 8, a cone 16 around). At least one output: -o,\n"
           "--csv, --image, --stats, --trace or --checkpoint.\n"
           "  -o, --output FILE    vertex-coloured mesh of the solution (.ply)\n"
           "  --cells L            layout of cells, like 2x2x2 (default: 1 on one worker, else\n"
           "                       at least 4 cells a worker: 2x2x2 for 2 workers)\n"
           "  --workers W          worker threads per process (default: the cores it may run\n"
           "                       on)\n"
           "  --sf X               stop when the largest unshot power of a patch / emitted\n"
           "                       < X (default 1e-3), whatever the walls cut the patches into\n"
           "  --hemicube RES       hemicube resolution, even, <= %d (default 64)\n"
           "  --patch-size S       largest patch side (default: scene extent / 10); a side\n"
           "                       above a polygon's size makes it one patch and one element\n"
           "  --elements K         receiver elements per patch side (default 2), about 300\n"
           "                       bytes each: a solve that needs more memory than the\n"
           "                       host has left is refused before it starts\n"
           "  --per-round K        shots per cell between convergence checks (default 16)\n"
           "  --neighbourhood D    a shot reaches only cells within D of the shooter\n"
           "  --subdivide T        split elements whose radiosity varies inside them (or differs\n"
           "                       from a neighbour's by 2T) by more than T relative to the mean\n"
           "  --max-level N        deepest subdivision, 0-4 (default 3; with --subdivide each\n"
           "                       element keeps 4^N fine cells, about 60 bytes each)\n"
           "  --max-shots N        stop after the round that reaches N shots (not\n"
           "                       converged; a round makes up to --per-round per cell)\n"
           "  --stall-shots N      stop, stalled, when the last N shots absorbed or let escape\n"
           "                       less than sf of the emitted power (checked every N shots;\n"
           "                       default %d): a closed scene that reflects everything in a\n"
           "                       channel (Kd 1) spends nothing and would run for ever\n"
           "  --csv FILE           per polygon: id, area, reflectance, emission, radiosity (the\n"
           "                       values used: reflectance clamped to [0, 1], with a warning;\n"
           "                       a reflectance of 1 warns that the solve may stall)\n"
           "  --image FILE         picture from the scene's camera (or --view): .png (tone\n"
           "                       mapped) or .pfm (float: radiosity, not tone mapped)\n"
           "  --view F,A[,FOV]     camera: from x,y,z, at x,y,z, vertical angle (degrees,\n"
           "                       above 0 and below 180, default 45); +y up (+z for a\n"
           "                       view within 1 degree of vertical); near plane 1e-3 of the\n"
           "                       distance or of the scene's size, the smaller\n"
           "  --size WxH           picture size (default: the camera's, or 512x512)\n"
           "  --snapshot-every N   rewrite the outputs every N shots while solving\n"
           "  --stats FILE.json    stats JSON (radiosity: shots, unshot_ratio, energy_error)\n"
           "  --trace FILE         per round, the state at one moment: seconds, shots made,\n"
           "                       unshot ratio; the last line is the final state (for plots)\n"
           "  --checkpoint FILE    write checkpoints here (atomically)\n"
           "  --checkpoint-every S seconds between checkpoints (default 60; 0: every round;\n"
           "                       under MPI the output process's clock decides for all)\n"
           "  --resume FILE        continue from a checkpoint: the same scene, --cells,\n"
           "                       --patch-size, --elements, --hemicube, --subdivide, --max-level\n"
           "                       and --neighbourhood as the run that wrote it (--sf may change);\n"
           "                       under MPI the first process alone reads it, as it wrote it\n"
           "  --max-rounds N       stop after N rounds as if killed: only --checkpoint is\n"
           "                       written (tests)\n"
           "  --progress           the progress bar even when stderr is no terminal (mpirun)\n"
           "  -q, --quiet          no progress bar and no summary\n"
           "  --help               this text\n"
           "\nexit status: 0 success, 2 bad input or usage, 1 any other failure\n",
           RAD_MAX_RES, RAD_STALL_SHOTS);
}

typedef struct run_ctx {
    const char *out, *csv, *image, *stats;
    const vw_scene *scene;
    const rad_mesh *mesh;
    vw_camera cam;
    int64_t snapshot_every, last_snapshot;
    vw_progress bar;
    double sf, t_start;
    char *trace;          /* --trace: "seconds shots unshot_ratio" per round */
    size_t ntrace, captrace;
    double t_state;       /* when the last round ended: the moment the next report holds */
    int64_t traced_shots; /* the shots of the last trace line (-1: none yet) */
    int failed;
} run_ctx;

/* A trace line: the state at one moment (seconds since the solve began, shots made by
   then, unshot ratio then). Out of memory, the line is left out. */
static void trace_line(run_ctx *r, double t, int64_t shots, double ratio)
{
    vw_cli_appendf(&r->trace, &r->ntrace, &r->captrace, "%.6f %lld %.9g\n", t - r->t_start,
                   (long long)shots, ratio);
    r->traced_shots = shots;
}

/* After each round, with the state its start reported: the one the round before left,
   at the time that round ended. */
static void on_progress(void *user, double ratio, int64_t shots)
{
    run_ctx *r = user;
    char note[96];
    snprintf(note, sizeof note, "unshot %.2e / sf %.0e, %lld shots", ratio, r->sf, (long long)shots);
    trace_line(r, r->t_state, shots, ratio);
    r->t_state = vw_cli_now();
    double frac = ratio <= r->sf ? 1 : ratio >= 1 ? 0 : log(ratio) / log(r->sf);
    vw_progress_update(&r->bar, frac, note);
}

static int write_outputs(run_ctx *r, rad_solver *s)
{
    char err[512];
    size_t ne, np;
    const rad_elem_result *e = rad_solver_elements(s, &ne);
    const rad_patch_result *p = rad_solver_patches(s, &np);
    double amb[3];
    rad_ambient(r->mesh, p, np, amb);
    vw_status st = VW_OK;
    if (r->out) st = rad_write_ply(r->out, r->mesh, e, ne, amb, err, sizeof err);
    if (st == VW_OK && r->csv) st = rad_write_csv(r->csv, r->mesh, r->scene, e, ne, err, sizeof err);
    if (st == VW_OK && r->image) st = rad_write_image(r->image, &r->cam, r->mesh, e, ne, amb, err, sizeof err);
    if (st != VW_OK) {
        vw_cli_error(CMD, "%s", st == VW_E_NOMEM ? "out of memory writing the outputs" : err);
        return -1;
    }
    return 0;
}

static void on_round(void *user, rad_solver *s, int round)
{
    run_ctx *r = user;
    (void)round;
    if (r->snapshot_every <= 0 || r->failed) return;
    if (rad_solver_shots(s) - r->last_snapshot < r->snapshot_every) return;
    r->last_snapshot = rad_solver_shots(s);
    char err[512];
    if (rad_solver_collect(s, err, sizeof err) != VW_OK) {
        vw_cli_error(CMD, "%s", err);
        r->failed = 1;
        return;
    }
    /* Only the output process writes; every process learns whether it could, and all
       stop snapshotting together, or the others would wait for it in the next collect. */
    vw_world *w = rad_solver_world(s);
    vw_status wst = vw_world_is_output(w) && write_outputs(r, s) ? VW_E_IO : VW_OK;
    if (vw_world_agree(w, wst, err, sizeof err) != VW_OK) r->failed = 1;
}

/* --view fx,fy,fz,ax,ay,az[,fov]: the camera, +y up (+z when the view is within a
   degree of vertical); -1 after the message when it gives no view. Its near plane is
   set once the scene is read (view_hither). */
static int parse_view(const char *v, vw_camera *cam)
{
    double x[7];
    int n;
    if (vw_cli_numbers(CMD, "--view", v, "fx,fy,fz,ax,ay,az[,fov]", x, 6, 7, &n)) return -1;
    for (int k = 0; k < 3; k++) cam->from[k] = x[k], cam->at[k] = x[3 + k];
    cam->angle = n == 7 ? x[6] : 45;
    if (!vw_cli_fov_ok(cam->angle)) { /* the range of render --angle and of an NFF file */
        vw_cli_error(CMD, "--view: field of view %g out of range (above 0 and below 180 "
                     "degrees)", cam->angle);
        return -1;
    }
    /* Not only an exactly vertical view: +y up for a view some 1e-10 radians off
       vertical made the picture's right +z or -x as the tilt fell, a quarter turn
       from the exactly vertical view's for a change in the last digits of 'at'. Within
       a degree the picture turns with the tilt no more (any one up must flip
       somewhere; a degree off vertical is where a user tilts on purpose). */
    double d[3] = {cam->at[0] - cam->from[0], cam->at[1] - cam->from[1], cam->at[2] - cam->from[2]};
    double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    int vertical = len > 0 && fabs(d[1]) >= 0.99984769515639124 * len; /* cos 1 degree */
    cam->up[0] = 0, cam->up[1] = vertical ? 0 : 1, cam->up[2] = vertical ? 1 : 0;
    const char *problem = vw_camera_problem(cam);
    if (problem) {
        vw_cli_error(CMD, "--view: %s", problem);
        return -1;
    }
    return 0;
}

/* The near plane of a --view: a thousandth of the distance looked across or of the
   scene's size, whichever is less, as the default camera's (vw_scene_default_camera).
   It was 1e-3 absolute, and a scene 5.6e-5 across lay wholly in front of it, black. */
static double view_hither(const vw_camera *cam, const vw_scene *sc)
{
    double lo[3], hi[3], size = 0, dist = 0;
    vw_scene_bounds(sc, lo, hi);
    for (int k = 0; k < 3; k++) {
        size += (hi[k] - lo[k]) * (hi[k] - lo[k]);
        dist += (cam->at[k] - cam->from[k]) * (cam->at[k] - cam->from[k]);
    }
    size = sqrt(size), dist = sqrt(dist);
    return 1e-3 * (size > 0 && size < dist ? size : dist);
}

/* The elements' memory, known once the scene is meshed, against what this host has
   left: a solve that cannot fit is refused now, not part-way (or by the kernel's
   out-of-memory killer, under overcommit). The processes share the elements (the
   cells are mapped by element count), and the host's memory is shared by the job's
   processes on it. */
static int check_memory(const rad_mesh *m, const rad_options *o, char *err, size_t len)
{
    double elements = 0, need = rad_mesh_solve_bytes(m, o, &elements) / vw_engine_size();
    double avail = (double)vw_host_memory() / vw_cli_local_processes();
    if (!(avail > 0) || need <= avail) return VW_EXIT_OK;
    int fine = o->subdivide > 0 && o->max_level > 0;
    char a[32], b[32];
    return vw_cli_fail(CMD, VW_EXIT_USAGE, err, len,
                       "the solve needs about %s a process (%.0f elements of about %.0f "
                       "bytes%s), more than the %s this host has left for it: give a "
                       "smaller --elements%s, a larger --patch-size, or more processes",
                       vw_cli_bytes(need, a, sizeof a), elements, RAD_ELEM_BYTES,
                       fine ? ", each with the 4^--max-level fine cells of --subdivide, about "
                              "60 bytes each" : "",
                       vw_cli_bytes(avail, b, sizeof b), fine ? " or --max-level" : "");
}

int vw_cmd_radiosity(int argc, char **argv)
{
    rad_options o;
    rad_options_init(&o);
    int progress = 0; /* --progress */
    run_ctx r;
    memset(&r, 0, sizeof r);
    const char *scene_path = NULL, *view = NULL, *trace = NULL;
    int W = 0, H = 0, cells_given = 0;
    /* Options given that only another one uses (warned about below, as render does). */
    int level_given = 0, ck_every_given = 0, snapshot_given = 0;
    long lv;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v;
#define VALUE() if (!(v = vw_cli_value(CMD, argc, argv, &i))) return VW_EXIT_USAGE
#define OUTPUT() if (!(v = vw_cli_output(CMD, argc, argv, &i))) return VW_EXIT_USAGE
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            help();
            return VW_EXIT_OK;
        } else if (!strcmp(a, "--quiet") || !strcmp(a, "-q")) {
            o.quiet = 1;
        } else if (!strcmp(a, "--progress")) {
            progress = 1;
        } else if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
            OUTPUT();
            r.out = v;
        } else if (!strcmp(a, "--cells")) {
            VALUE();
            if (vw_cli_layout(CMD, a, v, o.dims)) return VW_EXIT_USAGE;
            cells_given = 1;
        } else if (!strcmp(a, "--workers")) {
            VALUE();
            if (vw_cli_int(CMD, a, v, 1, 1024, &lv)) return VW_EXIT_USAGE;
            o.workers = (int)lv;
        } else if (!strcmp(a, "--sf")) {
            VALUE();
            if (vw_cli_double(CMD, a, v, 1e-12, 1, &o.sf)) return VW_EXIT_USAGE;
        } else if (!strcmp(a, "--hemicube")) {
            VALUE();
            if (vw_cli_int(CMD, a, v, 2, RAD_MAX_RES, &lv)) return VW_EXIT_USAGE;
            if (lv & 1) {
                vw_cli_error(CMD, "--hemicube: bad value '%s' (expected an even number)", v);
                return VW_EXIT_USAGE;
            }
            o.res = (int)lv;
        } else if (!strcmp(a, "--patch-size")) {
            VALUE();
            if (vw_cli_double(CMD, a, v, 1e-9, 1e30, &o.patch_size)) return VW_EXIT_USAGE;
        } else if (!strcmp(a, "--elements")) {
            VALUE();
            if (vw_cli_int(CMD, a, v, 1, 64, &lv)) return VW_EXIT_USAGE;
            o.elem_split = (int)lv;
        } else if (!strcmp(a, "--per-round")) {
            VALUE();
            if (vw_cli_int(CMD, a, v, 1, 1000000, &lv)) return VW_EXIT_USAGE;
            o.per_round = (int)lv;
        } else if (!strcmp(a, "--neighbourhood")) {
            VALUE();
            if (vw_cli_double(CMD, a, v, 1e-12, 1e30, &o.neighbourhood)) return VW_EXIT_USAGE;
        } else if (!strcmp(a, "--subdivide")) {
            VALUE();
            if (vw_cli_double(CMD, a, v, 1e-6, 100, &o.subdivide)) return VW_EXIT_USAGE;
        } else if (!strcmp(a, "--max-level")) {
            VALUE();
            if (vw_cli_int(CMD, a, v, 0, RAD_MAX_LEVEL, &lv)) return VW_EXIT_USAGE;
            o.max_level = (int)lv;
            level_given = 1;
        } else if (!strcmp(a, "--max-shots")) {
            VALUE();
            if (vw_cli_int(CMD, a, v, 1, 0x7fffffffL, &lv)) return VW_EXIT_USAGE;
            o.max_shots = lv;
        } else if (!strcmp(a, "--stall-shots")) {
            VALUE();
            if (vw_cli_int(CMD, a, v, 1, 0x7fffffffL, &lv)) return VW_EXIT_USAGE;
            o.stall_shots = lv;
        } else if (!strcmp(a, "--max-rounds")) {
            VALUE();
            if (vw_cli_int(CMD, a, v, 1, 0x7fffffffL, &lv)) return VW_EXIT_USAGE;
            o.max_rounds = (int)lv;
        } else if (!strcmp(a, "--csv")) {
            OUTPUT();
            r.csv = v;
        } else if (!strcmp(a, "--image")) {
            OUTPUT();
            r.image = v;
        } else if (!strcmp(a, "--view")) {
            VALUE();
            view = v;
        } else if (!strcmp(a, "--size")) {
            VALUE();
            if (vw_cli_size(CMD, a, v, &W, &H)) return VW_EXIT_USAGE;
        } else if (!strcmp(a, "--snapshot-every")) {
            VALUE();
            if (vw_cli_int(CMD, a, v, 1, 0x7fffffffL, &lv)) return VW_EXIT_USAGE;
            r.snapshot_every = lv;
            snapshot_given = 1;
        } else if (!strcmp(a, "--stats")) {
            OUTPUT();
            r.stats = v;
        } else if (!strcmp(a, "--trace")) {
            OUTPUT();
            trace = v;
        } else if (!strcmp(a, "--checkpoint")) {
            OUTPUT();
            o.checkpoint = v;
        } else if (!strcmp(a, "--checkpoint-every")) {
            VALUE();
            if (vw_cli_double(CMD, a, v, 0, 1e9, &o.checkpoint_every)) return VW_EXIT_USAGE;
            ck_every_given = 1;
        } else if (!strcmp(a, "--resume")) {
            VALUE();
            o.resume = v;
        } else if (vw_cli_scene_arg(CMD, a, &scene_path)) {
            return VW_EXIT_USAGE;
        }
#undef VALUE
#undef OUTPUT
    }
    if (!scene_path) {
        vw_cli_error(CMD, "no scene given (try --help)");
        return VW_EXIT_USAGE;
    }
    /* Every file the user can ask for is an output, and the message names them all. */
    if (!r.out && !r.csv && !r.image && !r.stats && !trace && !o.checkpoint) {
        vw_cli_error(CMD, "no output: give -o OUT.ply, --csv F, --image F, --stats F, --trace F "
                     "or --checkpoint F");
        return VW_EXIT_USAGE;
    }
    /* Before the solve: a picture that cannot be written would be found only after it,
       and a mesh named x.obj would be written as PLY and read back as OBJ. */
    if (r.out && vw_cli_scene_output(CMD, "-o", r.out, ".ply", "PLY")) return VW_EXIT_USAGE;
    if (r.image && vw_image_format_of(r.image) == VW_IMAGE_NONE) {
        vw_cli_error(CMD, "--image %s: the picture must end in .png or .pfm", r.image);
        return VW_EXIT_USAGE;
    }
    vw_camera cam_view;
    memset(&cam_view, 0, sizeof cam_view);
    if (view && parse_view(view, &cam_view)) return VW_EXIT_USAGE;
    {
        /* Under MPI every process must solve the same problem: the world's commit
           compares only the cells and the objects' bounds, and another --sf or
           --hemicube on one rank made it shoot and rasterise by other rules (a wrong
           solution, or a wait for a shot that never comes). The picture's options
           (--view, --size) and the outputs are the output process's alone. */
        static const char *const names[] = {"--cells", "--cells", "--cells", "--sf", "--hemicube",
                                            "--patch-size", "--elements", "--per-round",
                                            "--neighbourhood", "--subdivide", "--max-level",
                                            "--max-shots", "--max-rounds", "--stall-shots"};
        const double v[] = {o.dims[0], o.dims[1], o.dims[2], o.sf, o.res, o.patch_size,
                            o.elem_split, o.per_round, o.neighbourhood, o.subdivide,
                            o.max_level, (double)o.max_shots, o.max_rounds, (double)o.stall_shots};
        _Static_assert(sizeof v / sizeof v[0] == sizeof names / sizeof names[0], "one name a value");
        if (vw_cli_same_options(CMD, names, v, sizeof v / sizeof v[0])) return VW_EXIT_USAGE;
    }
    {
        const char *opts[] = {"-o", "--csv", "--image", "--stats", "--trace", "--checkpoint"};
        const char *paths[] = {r.out, r.csv, r.image, r.stats, trace, o.checkpoint};
        const char *const inputs[] = {scene_path, NULL};
        int crc = vw_cli_check_files(CMD, inputs, opts, paths, 6);
        /* The checkpoint resumed from is an input of every output but --checkpoint,
           which may name it (the run goes on where it left off, replacing it
           atomically): --stats CK replaced it, and a failed run could not resume. */
        const char *const resumed[] = {o.resume, NULL};
        if (crc == VW_EXIT_OK && o.resume) crc = vw_cli_check_files(CMD, resumed, opts, paths, 5);
        if (crc != VW_EXIT_OK) return crc;
    }
    /* An option whose only user is absent changes nothing: a warning, as render gives
       for --overlay-by without --overlay (not an error: the run is what was asked,
       less a detail), so that "--size 64x64" without --image does not pass for a
       picture asked for. --max-level is kept (and compared by --resume) only with
       --subdivide. */
    if (vw_cli_is_output()) {
        const struct { int given, used; const char *opt, *without; } unused[] = {
            {W > 0, r.image != NULL, "--size", "--image"},
            {view != NULL, r.image != NULL, "--view", "--image"},
            {ck_every_given, o.checkpoint != NULL, "--checkpoint-every", "--checkpoint"},
            {level_given, o.subdivide > 0, "--max-level", "--subdivide"},
            {snapshot_given, r.out || r.csv || r.image, "--snapshot-every",
             "-o, --csv or --image (the outputs it rewrites)"},
        };
        for (size_t k = 0; k < sizeof unused / sizeof unused[0]; k++)
            if (unused[k].given && !unused[k].used)
                fprintf(stderr, "vwalls radiosity: warning: %s has no effect without %s\n",
                        unused[k].opt, unused[k].without);
    }

    /* A radiosity cell cannot be shared by workers (a shot's bitmaps depend on the order
       of the cells, so its messages are not independent): a worker without a cell has
       nothing to do. Without --cells, one worker keeps the single cell (the solution of
       reference); more get at least 4 cells each, so the mapping by element count can
       even them out (room, 2x2x2 on 2 workers: lambda 1.01). */
    int gw = vw_cli_job_workers(o.workers);
    if (!cells_given)
        for (int a = 0; gw > 1 && o.dims[0] * o.dims[1] * o.dims[2] < 4 * gw; a = (a + 1) % 3)
            o.dims[a] *= 2;
    else if (o.dims[0] * o.dims[1] * o.dims[2] < gw && vw_cli_is_output()) {
        int nc = o.dims[0] * o.dims[1] * o.dims[2];
        fprintf(stderr, "vwalls radiosity: warning: %d cell%s for %d workers: %d of them will "
                "idle (a radiosity cell cannot be shared); give --cells with at least %d cells\n",
                nc, nc == 1 ? "" : "s", gw, gw - nc, gw);
    }

    double t0 = vw_cli_now();
    char err[1024] = "";
    vw_scene *sc = NULL;
    /* Under MPI every process reads the scene; all stop if one cannot (a file missing on
       one host), and only the output process says why. */
    vw_status rst = vw_engine_agree(vw_scene_read_file(scene_path, &sc, err, sizeof err), err, sizeof err);
    if (rst != VW_OK) {
        if (vw_cli_is_output()) fprintf(stderr, "%s\n", err);
        vw_scene_free(sc);
        return rst == VW_E_NOMEM ? VW_EXIT_FAIL : VW_EXIT_USAGE;
    }
    /* A reflectance or an emission that differs on one host solved wrongly. */
    if (vw_cli_same_scene(CMD, sc)) {
        vw_scene_free(sc);
        return VW_EXIT_USAGE;
    }
    {
        /* The scene's material libraries are inputs too (--csv x.mtl replaced x.obj's). */
        const char *opts[] = {"-o", "--csv", "--image", "--stats", "--trace", "--checkpoint"};
        const char *paths[] = {r.out, r.csv, r.image, r.stats, trace, o.checkpoint};
        int crc = vw_cli_check_scene_files(CMD, sc, opts, paths, 6);
        if (crc != VW_EXIT_OK) {
            vw_scene_free(sc);
            return crc;
        }
    }
    /* Every process makes its own cells and mesh from its own copy of the scene, and
       checks the picture's size against that copy's camera: all agree before the
       solver's world is made, or one that stopped alone would leave the others waiting
       for it there. */
    int rc = VW_EXIT_OK;
    vw_box world = rad_world_box(sc);
    vw_decomp *d = NULL;
    rad_mesh mesh;
    memset(&mesh, 0, sizeof mesh);
    vw_status st = vw_decomp_create_grid(&world, o.dims, &d);
    if (st != VW_OK)
        rc = vw_cli_fail(CMD, VW_EXIT_FAIL, err, sizeof err, "cannot make the decomposition: %s",
                         vw_status_message(st));
    double t1 = vw_cli_now();
    /* Every process meshes the whole scene; only the output process warns, --quiet
       or not (it silences the progress bar and the summary, never a warning). */
    rad_options mo = o;
    mo.quiet = !vw_cli_is_output();
    if (rc == VW_EXIT_OK && (st = rad_mesh_build(sc, scene_path, d, &mo, &mesh, err, sizeof err)) != VW_OK)
        rc = st == VW_E_INPUT || st == VW_E_LIMIT ? VW_EXIT_USAGE : VW_EXIT_FAIL;
    if (rc == VW_EXIT_OK) rc = check_memory(&mesh, &o, err, sizeof err);
    r.scene = sc;
    r.mesh = &mesh;
    r.sf = o.sf;
    if (view) {
        r.cam = cam_view;
        r.cam.hither = view_hither(&cam_view, sc);
    } else if (sc->camera.valid)
        r.cam = sc->camera;
    else
        vw_scene_default_camera(sc, &r.cam);
    if (W > 0) r.cam.width = W, r.cam.height = H;
    if (r.cam.width <= 0) r.cam.width = 512, r.cam.height = 512;
    /* A scene file's own resolution may be larger than --size allows: refused here, as
       render refuses it, not found out by an allocation after the whole solve. */
    if (rc == VW_EXIT_OK && r.image && (r.cam.width > 16384 || r.cam.height > 16384))
        rc = vw_cli_fail(CMD, VW_EXIT_USAGE, err, sizeof err, "--image: picture size %dx%d too "
                         "large (at most 16384 on a side; give --size)", r.cam.width, r.cam.height);
    if ((rc = vw_cli_agree(CMD, rc, err, sizeof err)) != VW_EXIT_OK) {
        rad_mesh_free(&mesh);
        vw_decomp_free(d);
        vw_scene_free(sc);
        return rc;
    }

    rad_solver *s = NULL;
    double t2 = vw_cli_now();
    st = rad_solver_create(&mesh, d, &o, &s, err, sizeof err);
    if (st != VW_OK) {
        vw_cli_error(CMD, "%s", err);
        rc = st == VW_E_INPUT || st == VW_E_INVAL || st == VW_E_IO ? VW_EXIT_USAGE : VW_EXIT_FAIL;
        goto done;
    }
    double t3 = vw_cli_now();
    r.t_start = r.t_state = t3;
    r.traced_shots = -1;
    rad_solver_on_round(s, on_round, &r);
    vw_progress_begin(&r.bar, "radiosity",
                      o.quiet || !vw_world_is_output(rad_solver_world(s)) ? VW_PROGRESS_OFF
                      : progress ? VW_PROGRESS_ON
                                 : VW_PROGRESS_AUTO);
    int converged = 0;
    st = rad_solver_run(s, on_progress, &r, &converged, err, sizeof err);
    vw_progress_end(&r.bar);
    int64_t stall_span = 0;
    double stall_lost = 0;
    int stalled = st == VW_OK && rad_solver_stalled(s, &stall_span, &stall_lost);
    if (st != VW_OK || r.failed) {
        if (st != VW_OK) vw_cli_error(CMD, "%s", err);
        rc = VW_EXIT_FAIL;
        goto done;
    }
    if (o.max_rounds > 0 && !converged && !stalled) {
        /* Stopped on purpose, as if killed: the checkpoint is the only output. */
        if (o.checkpoint && rad_solver_checkpoint(s, o.checkpoint, err, sizeof err) != VW_OK) {
            vw_cli_error(CMD, "%s", err);
            rc = VW_EXIT_FAIL;
        }
        goto done;
    }
    if (rad_solver_collect(s, err, sizeof err) != VW_OK) {
        vw_cli_error(CMD, "%s", err);
        rc = VW_EXIT_FAIL;
        goto done;
    }
    double t4 = vw_cli_now();
    vw_world *w = rad_solver_world(s);
    /* Only the output process checks the ledger and writes the outputs; every process
       exits with its status, agreed when the command has returned (vw_cli_job_status). */
    if (vw_world_is_output(w)) {
        /* The final outputs (mesh, CSV, image, checkpoint, trace, stats) appear together
           or not at all: released at done. */
        vw_outfile_hold();
        rad_ledger L = rad_solver_ledger(s);
        if (vw_cli_fault("ledger")) L.error = INFINITY; /* tests: a run that fails the check */
        /* Checked before any file is written: a run whose energy does not add up is a
           failed run, and a failed run leaves no output (a snapshot or a checkpoint
           written while solving stays: they were right when written). */
        if (!(L.error <= 1e-6)) { /* NaN too */
            vw_cli_error(CMD, "energy ledger off by %.3g (relative): no output written", L.error);
            rc = VW_EXIT_FAIL;
            goto done;
        }
        if (write_outputs(&r, s)) {
            rc = VW_EXIT_FAIL;
            goto done;
        }
        /* Just collected: write, do not collect again (a collect is a run every process
           joins, and the others are past it). */
        if (o.checkpoint && rad_solver_write_checkpoint(s, o.checkpoint, err, sizeof err) != VW_OK) {
            vw_cli_error(CMD, "%s", err);
            rc = VW_EXIT_FAIL;
            goto done;
        }
        int64_t sm, sb, fm;
        rad_solver_traffic(s, &sm, &sb, &fm);
        size_t ne;
        rad_solver_elements(s, &ne);
        /* The final state, collected after the last round (unless that round shot
           nothing, and its report said so already). */
        if (rad_solver_shots(s) != r.traced_shots)
            trace_line(&r, r.t_state, rad_solver_shots(s), rad_solver_unshot_ratio(s));
        if (trace && vw_outfile_write(trace, r.trace ? r.trace : "", r.ntrace, err, sizeof err) != VW_OK) {
            vw_cli_error(CMD, "%s", err);
            rc = VW_EXIT_FAIL;
            goto done;
        }
        if (r.stats) {
            char extra[768], n[7][32];
            snprintf(extra, sizeof extra,
                     "\"radiosity\": {\"shots\": %lld, \"unshot_ratio\": %s, \"energy_error\": %s, "
                     "\"converged\": %s, \"stalled\": %s, \"sf\": %s, \"hemicube\": %d, \"pieces\": %zu, "
                     "\"elements\": %zu, "
                     "\"emitted\": %s, \"absorbed\": %s, \"unshot\": %s, \"escaped\": %s, "
                     "\"shot_messages\": %lld, \"shot_bytes\": %lld, \"full_messages\": %lld}",
                     (long long)rad_solver_shots(s), vw_cli_json_number(rad_solver_unshot_ratio(s), n[0]),
                     vw_cli_json_number(L.error, n[1]), converged ? "true" : "false", stalled ? "true" : "false",
                     vw_cli_json_number(o.sf, n[2]),
                     o.res, mesh.npieces, ne, vw_cli_json_number(L.emitted[0] + L.emitted[1] + L.emitted[2], n[3]),
                     vw_cli_json_number(L.absorbed[0] + L.absorbed[1] + L.absorbed[2], n[4]),
                     vw_cli_json_number(L.unshot[0] + L.unshot[1] + L.unshot[2], n[5]),
                     vw_cli_json_number(L.escaped[0] + L.escaped[1] + L.escaped[2], n[6]),
                     (long long)sm, (long long)sb, (long long)fm);
            vw_world_add_time(w, "load", t1 - t0);
            vw_world_add_time(w, "build", (t2 - t1) + (t3 - t2));
            vw_world_add_time(w, "compute", t4 - t3);
            if (vw_world_write_stats(w, r.stats, CMD, extra) != VW_OK) {
                vw_cli_error(CMD, "%s", vw_world_errmsg(w));
                rc = VW_EXIT_FAIL;
                goto done;
            }
        }
        if (!o.quiet) {
            char layout[64];
            vw_decomp_layout_string(d, layout, sizeof layout);
            printf("radiosity: %s, %zu pieces, %zu elements, cells %s, %d worker%s x %d process%s\n",
                   converged ? "converged" : stalled ? "stalled" : "stopped", mesh.npieces, ne, layout,
                   vw_world_workers(w),
                   vw_world_workers(w) == 1 ? "" : "s", vw_world_processes(w),
                   vw_world_processes(w) == 1 ? "" : "es");
            printf("shots %lld, unshot ratio %.3g (sf %.3g), energy error %.2e, time %.3f s\n",
                   (long long)rad_solver_shots(s), rad_solver_unshot_ratio(s), o.sf, L.error, t4 - t3);
            printf("shot messages %lld (%lld bytes), full notices %lld\n", (long long)sm, (long long)sb,
                   (long long)fm);
        }
        /* A warning (--quiet keeps it): the run ends with exit 0 and its outputs (the
           solution so far, the unshot power in the display's ambient term), as after
           --max-shots. */
        if (stalled) {
            double spent = stall_lost > 0 ? stall_lost : 0; /* not rounding's -1e-12 */
            double unshot = (L.unshot[0] + L.unshot[1] + L.unshot[2]) /
                            (L.emitted[0] + L.emitted[1] + L.emitted[2]);
            fprintf(stderr, "vwalls radiosity: warning: stalled after %lld shots: the last %lld "
                            "absorbed or let escape %.3g of the emitted power, less than --sf %g, "
                            "so the unshot power (%.3g %% of the emitted) is only spread and the "
                            "largest patch's share (unshot ratio %.3g) may never fall below --sf "
                            "(a closed scene of reflectance 1?); the outputs hold the solution so "
                            "far. Give a reflectance below 1, a larger --sf, or a larger "
                            "--stall-shots than %lld\n",
                    (long long)rad_solver_shots(s), (long long)stall_span, spent, o.sf, 100 * unshot,
                    rad_solver_unshot_ratio(s),
                    (long long)(o.stall_shots > 0 ? o.stall_shots : RAD_STALL_SHOTS));
        }
        /* sf bounds the largest patch's share of the emitted power: emitters meshed
           into more than 1/sf patches start below it, and nothing is lit. A warning, so
           --quiet (no progress bar, no summary) keeps it. */
        if (converged && rad_solver_shots(s) == 0)
            fprintf(stderr, "vwalls radiosity: warning: converged before the first shot: no "
                            "patch holds sf = %g of the emitted power (the emitters are meshed "
                            "finer); give a smaller --sf or a larger --patch-size\n", o.sf);
    }
done:
    if (vw_outfile_release(rc == VW_EXIT_OK, err, sizeof err) != VW_OK && rc == VW_EXIT_OK) {
        vw_cli_error(CMD, "%s", err);
        rc = VW_EXIT_FAIL;
    }
    free(r.trace);
    rad_solver_free(s);
    rad_mesh_free(&mesh);
    vw_decomp_free(d);
    vw_scene_free(sc);
    return rc;
}
