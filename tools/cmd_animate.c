/* cmd_animate.c - vwalls animate: runs an edit script (docs/edit-language.md) on a scene,
 * deciding every move with the distributed collision and sweep tests, rendering a frame
 * at every 'frame', rebalancing between frames; and the session both it and vwalls edit
 * (the same language from stdin) share.
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>

#include "cli.h"
#include "commands.h"
#include "raytrace/anim.h"

/* Object edits wait in a batch, decided together by one distributed query, until a line
   that needs the state (frame, check, sweep, balance) or the end; so a frame's thousand
   moves cost one collider run, not a thousand. */
#define MAX_BATCH 4096

typedef struct vw_anim_session vw_anim_session;

typedef struct frame_rec {
    int frame;
    size_t edits, accepted, rejected, records, cells;
    size_t invalid;              /* lines refused (not parsed, or not applicable): not edits */
    size_t objects;              /* live objects after the frame's edits (removed ones gone) */
    double apply_s, update_s, build_s, render_s, lambda, work_lambda, balance_s;
    int balanced;
} frame_rec;

struct vw_anim_session {
    const char *cmd, *name, *pattern, *strategy;
    rt_anim *anim;
    int check, sweep, keep_going, interactive, quiet;
    double threshold;            /* rebalance when lambda > 1 + threshold */
    int trigger_work;            /* that lambda is the counted work's, not busy time's */
    rt_farm farm;                /* how the workers share the cells (--farm) */
    vw_outfile *logf;            /* --log on the output process, or NULL */
    FILE *log;                   /* its stream: every edit's outcome */
    vw_edit batch[MAX_BATCH];
    size_t nbatch;
    vw_result res[MAX_BATCH];    /* the batch's outcomes: made with the session, since a
                                    process out of memory alone at a flush would leave the
                                    others waiting for it in the query */
    rt_anim_stats acc;           /* since the last frame */
    size_t total_acc, total_coll, total_sweep, total_invalid;
    int frame, failed;           /* failed: 2 bad input, 1 other */
    int bad_lines;               /* lines refused (parsed or applied): exit status 2 */
    int frame_errors;            /* vwalls edit's frames not written: exit status 1 */
    frame_rec *frames;
    size_t nframes, capframes;
    int farm_all_said;           /* FARM_ALL_NOTE printed for --balance */
    vw_progress bar;             /* animate on a terminal: the script's frames done */
    long script_frames;          /* the frames the script writes (animate) */
};

/* The progress bar shares the terminal with the frame lines and the messages: it is
   wiped (vw_progress_hide) before any of them is printed, and drawn again at the next
   frame. */

/* Under --farm all every worker holds every cell, so the workers share each cell's
   work whatever the walls, and the balancer, which sees that mapping, has nothing to
   move (it answered "lambda 1.000 -> 1.000" right after a frame line showing 1.9): on
   one process the 'balance' command and --balance say so instead of balancing. */
#define FARM_ALL_NOTE "nothing to balance with --farm all (every worker holds every cell)"

/* Is that so? Under MPI a process holds its own cells only, and the balancer moves
   the walls between the processes (2x2x1 on two processes: lambda 1.244 -> 1.192). */
static int farm_all_one_process(vw_anim_session *s)
{
    return s->farm == RT_FARM_ALL && vw_world_processes(rt_job_world(rt_anim_job(s->anim))) == 1;
}

static void say(const vw_anim_session *s, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void say(const vw_anim_session *s, const char *fmt, ...)
{
    if (!vw_cli_is_output() || s->quiet) return;
    vw_progress_hide(&s->bar);
    va_list ap;
    va_start(ap, fmt);
    vfprintf(stdout, fmt, ap);
    va_end(ap);
    if (s->bar.enabled) fflush(stdout); /* before the bar is drawn again */
}

/* An edit's answer: always for vwalls edit (its answers are its output), unless --quiet
   for animate. */
static void tell(const vw_anim_session *s, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void tell(const vw_anim_session *s, const char *fmt, ...)
{
    if (!vw_cli_is_output() || (s->quiet && !s->interactive)) return;
    vw_progress_hide(&s->bar);
    va_list ap;
    va_start(ap, fmt);
    vfprintf(stdout, fmt, ap);
    va_end(ap);
}

static const char *op_name(vw_edit_op op)
{
    static const char *const n[] = {"", "move", "moveto", "rotate", "add", "remove",
                                    "check", "sweep", "frame", "balance"};
    return op <= VW_EDIT_BALANCE ? n[op] : "?";
}

/* Decides the waiting batch and reports every outcome. */
static int flush(vw_anim_session *s)
{
    if (!s->nbatch) return 0;
    vw_result *res = s->res;
    memset(res, 0, s->nbatch * sizeof *res);
    rt_anim_stats st;
    memset(&st, 0, sizeof st);
    char err[512];
    vw_status rc = rt_anim_apply(s->anim, s->batch, s->nbatch, s->check, s->sweep, res, &st, err,
                                 sizeof err);
    if (rc != VW_OK) {
        vw_progress_hide(&s->bar);
        vw_cli_error(s->cmd, "%s", err);
        s->nbatch = 0;
        return s->failed = 1;
    }
    s->acc.accepted += st.accepted, s->acc.collisions += st.collisions;
    s->acc.sweeps += st.sweeps, s->acc.invalid += st.invalid;
    s->acc.records_updated += st.records_updated;
    s->acc.apply_s += st.apply_s, s->acc.update_s += st.update_s;
    s->total_acc += st.accepted, s->total_coll += st.collisions;
    s->total_sweep += st.sweeps, s->total_invalid += st.invalid;
    for (size_t i = 0; i < s->nbatch; i++) {
        const vw_result *r = &res[i];
        const char *op = op_name(r->edit.op);
        int out = vw_cli_is_output();
        switch (r->outcome) {
        case VW_OUT_ACCEPTED:
            if (s->interactive) tell(s, "%s %d: accepted\n", op, r->id);
            if (s->log && out) fprintf(s->log, "%s:%d: %s %d: accepted\n", s->name, r->edit.line, op, r->id);
            break;
        case VW_OUT_COLLISION:
        case VW_OUT_SWEEP: {
            const char *why = r->outcome == VW_OUT_COLLISION ? "collides at its destination with"
                                                             : "would pass through";
            tell(s, "%s:%d: %s %d rejected: %s object %d\n", s->name, r->edit.line, op, r->id, why,
                 r->obstacle);
            if (s->log && out)
                fprintf(s->log, "%s:%d: %s %d: rejected: %s object %d\n", s->name, r->edit.line, op,
                        r->id, why, r->obstacle);
            break;
        }
        default:
            vw_progress_hide(&s->bar);
            if (out) fprintf(stderr, "%s:%d: %s\n", s->name, r->edit.line, r->msg);
            if (s->log && out) fprintf(s->log, "%s:%d: %s: invalid: %s\n", s->name, r->edit.line, op, r->msg);
            s->bad_lines++;
            if (!s->interactive && !s->keep_going && !s->failed) s->failed = 2;
            break;
        }
    }
    s->nbatch = 0;
    return s->failed;
}

/* The objects alive now: the scene's and the added ones, the removed ones not (the
   render world keeps a removed object's record slots, empty). */
static size_t live_objects(vw_anim_session *s)
{
    const vw_dynscene *ds = rt_anim_dynscene(s->anim);
    size_t n = 0;
    for (int id = 0, ids = vw_dynscene_ids(ds); id < ids; id++) n += vw_dynscene_alive(ds, id) != 0;
    return n;
}

static int do_frame(vw_anim_session *s)
{
    char err[5120] = ""; /* room for a long path and the reason after it */
    rt_anim_stats st;
    memset(&st, 0, sizeof st);
    vw_status rc = rt_anim_render(s->anim, &st, err, sizeof err);
    if (rc != VW_OK) {
        vw_progress_hide(&s->bar);
        vw_cli_error(s->cmd, "frame %d: %s", s->frame, err);
        return s->failed = 1;
    }
    rt_job *job = rt_anim_job(s->anim);
    const rt_shared *sh = rt_job_shared(job);
    int w = sh->view.width, h = sh->view.height;
    /* Without -o (vwalls edit) a frame still renders; its times are reported. */
    vw_status wst = VW_OK;
    err[0] = 0;
    /* The frame's record, on every process; made room for before the agreement below,
       which all stop at if one has none. */
    if (s->nframes == s->capframes) {
        size_t cap = s->capframes ? 2 * s->capframes : 16;
        frame_rec *f = vw_cli_fault("frames-nomem") ? NULL : realloc(s->frames, cap * sizeof *f);
        if (f) {
            s->frames = f;
            s->capframes = cap;
        } else {
            snprintf(err, sizeof err, "frame %d: %s", s->frame, vw_status_message(VW_E_NOMEM));
            wst = VW_E_NOMEM;
        }
    }
    if (wst == VW_OK && vw_cli_is_output() && s->pattern) {
        char path[4096];
        uint8_t *rgb = NULL;
        /* The pattern has exactly one integer conversion (vw_cli_frame_pattern). */
        if (snprintf(path, sizeof path, s->pattern, s->frame) >= (int)sizeof path) {
            snprintf(err, sizeof err, "frame %d: the file name is longer than %zu bytes", s->frame,
                     sizeof path - 1);
            wst = VW_E_INVAL;
        } else if (!(rgb = malloc((size_t)w * h * 3))) {
            snprintf(err, sizeof err, "frame %d: %s", s->frame, vw_status_message(VW_E_NOMEM));
            wst = VW_E_NOMEM;
        } else {
            rt_job_rgb8(job, rgb);
            /* Compressed on as many threads as the process has workers (idle now). */
            wst = vw_image_write_png_threads(path, w, h, rgb, vw_world_workers(rt_job_world(job)),
                                             err, sizeof err);
            free(rgb);
        }
    }
    /* Only the output process writes; all stop when it cannot (a missing directory) or
       one has no room for the record, or the others would wait for it in the next
       edit's collective calls forever. */
    if (vw_engine_agree(wst, err, sizeof err) != VW_OK) {
        vw_progress_hide(&s->bar);
        vw_cli_error(s->cmd, "%s", err);
        /* vwalls edit goes on (every process knows, from the agreement): the session's
           edits are not lost for a frame its user can make room for (a directory removed
           since the start, a full disk); the number is not used, so the next 'frame'
           writes it, and the exit status is 1. */
        if (s->interactive) {
            s->frame_errors++;
            return 0;
        }
        return s->failed = 1;
    }
    frame_rec *f = &s->frames[s->nframes++];
    memset(f, 0, sizeof *f);
    f->frame = s->frame;
    f->accepted = s->acc.accepted;
    /* The edits applied: accepted, or rejected by the collision or sweep test. A line
       refused as invalid (it does not parse, or names no object) is no edit: counted
       apart. */
    f->rejected = s->acc.collisions + s->acc.sweeps;
    f->edits = f->accepted + f->rejected;
    f->invalid = s->acc.invalid;
    f->objects = live_objects(s);
    f->records = s->acc.records_updated;
    f->cells = st.cells_rebuilt;
    f->apply_s = s->acc.apply_s;
    f->update_s = s->acc.update_s;
    f->build_s = st.build_s;
    f->render_s = st.render_s;
    f->lambda = rt_anim_imbalance(s->anim);
    f->work_lambda = rt_anim_work_imbalance(s->anim);
    char inv[64] = "";
    if (f->invalid) snprintf(inv, sizeof inv, ", %zu invalid line%s", f->invalid, f->invalid == 1 ? "" : "s");
    say(s, "frame %d: %zu edits (%zu accepted)%s, %zu records, %zu cells rebuilt; decide %.3f s, "
           "update %.3f s, build %.3f s, render %.3f s, lambda %.3f (work %.3f)\n",
        s->frame, f->edits, f->accepted, inv, f->records, f->cells, f->apply_s,
        f->update_s, f->build_s, f->render_s, f->lambda, f->work_lambda);
    memset(&s->acc, 0, sizeof s->acc);
    s->frame++;
    /* Between frames: rebalance when the frame just rendered was uneven enough. */
    double lam = s->trigger_work ? f->work_lambda : f->lambda;
    int rebalance = s->strategy && strcmp(s->strategy, "none") && lam > 1.0 + s->threshold;
    if (rebalance && farm_all_one_process(s)) {
        /* Every worker holds every cell: the balancer sees a mapping it cannot improve
           (it said "lambda 1.000 -> 1.000" after a frame line showing 1.9); said once. */
        if (!s->farm_all_said) say(s, "  --balance %s: " FARM_ALL_NOTE ": walls unchanged\n", s->strategy);
        s->farm_all_said = 1;
    } else if (rebalance) {
        double before = 0, pred = 0, t0 = vw_cli_now();
        rc = rt_anim_balance(s->anim, s->strategy, &before, &pred, err, sizeof err);
        f->balance_s = vw_cli_now() - t0;
        if (rc != VW_OK) {
            vw_progress_hide(&s->bar);
            vw_cli_error(s->cmd, "%s", err);
            return s->failed = rc == VW_E_INVAL ? 2 : 1;
        }
        f->balanced = 1;
        say(s, "  rebalanced (%s): lambda %.3f -> %.3f predicted, %.3f s\n", s->strategy, before,
            pred, f->balance_s);
    }
    if (s->script_frames > 0) {
        char note[64];
        snprintf(note, sizeof note, "frame %zu/%ld", s->nframes, s->script_frames);
        vw_progress_update(&s->bar, (double)s->nframes / (double)s->script_frames, note);
    }
    return 0;
}

/* The command a line's first word names (the language's own spelling), or NULL when it
   names none (a blank line, an unknown word: the parser's message quotes it). For the
   log of a line that does not parse, which names its command like that of one refused
   when applied. */
static const char *line_command(const char *line, size_t len)
{
    const char *end = line + len;
    while (line < end && *line && strchr(" \t\v\f", *line)) line++; /* vw_edit_parse's blanks */
    const char *w = line;
    while (line < end && *line && !strchr(" \t\v\f\r\n#", *line)) line++;
    size_t n = (size_t)(line - w);
    for (int op = VW_EDIT_NONE + 1; op <= VW_EDIT_BALANCE; op++) {
        const char *name = op_name((vw_edit_op)op);
        if (n && strlen(name) == n && !memcmp(name, w, n)) return name;
    }
    return NULL;
}

/* Parses one line of the language (len bytes); a line that does not parse is reported
   (stderr and the log), counted as invalid, and VW_E_INPUT comes back. */
static vw_status parse_line(vw_anim_session *s, const char *line, size_t len, int lineno,
                            vw_edit *e)
{
    char err[512];
    vw_status pst;
    if (memchr(line, '\0', len)) { /* the parser would stop at it and not see the rest */
        snprintf(err, sizeof err, "%s:%d: a NUL byte in the line", s->name, lineno);
        pst = VW_E_INPUT;
    } else {
        pst = vw_edit_parse(line, s->name, lineno, e, err, sizeof err);
    }
    if (pst == VW_OK) return VW_OK;
    int out = vw_cli_is_output();
    vw_progress_hide(&s->bar);
    if (out) fprintf(stderr, "%s\n", err);
    if (s->log && out) {
        /* The message after its "name:line: ", in the log's own format. */
        char prefix[64];
        int k = snprintf(prefix, sizeof prefix, ":%d: ", lineno);
        const char *why = strstr(err, prefix);
        const char *cmd = line_command(line, len);
        fprintf(s->log, "%s:%d: %s%sinvalid: %s\n", s->name, lineno, cmd ? cmd : "", cmd ? ": " : "",
                why ? why + k : err);
    }
    s->acc.invalid++;
    s->total_invalid++;
    s->bad_lines++;
    return VW_E_INPUT;
}

/* One line of the language (len bytes, its newline included). Returns nonzero when the
   session must stop. */
static int session_line(vw_anim_session *s, const char *line, size_t len, int lineno)
{
    vw_edit e;
    char err[512];
    if (parse_line(s, line, len, lineno, &e) != VW_OK) {
        if (!s->interactive && !s->keep_going) {
            flush(s);
            return s->failed = 2;
        }
        return 0;
    }
    if (vw_edit_is_object(e.op)) {
        s->batch[s->nbatch++] = e;
        if (s->nbatch == MAX_BATCH || s->interactive) flush(s);
        return s->failed;
    }
    switch (e.op) {
    case VW_EDIT_CHECK:
        flush(s);
        s->check = e.on;
        break;
    case VW_EDIT_SWEEP:
        flush(s);
        s->sweep = e.on;
        break;
    case VW_EDIT_FRAME:
        if (!flush(s)) do_frame(s);
        break;
    case VW_EDIT_BALANCE: {
        if (flush(s)) break;
        if (farm_all_one_process(s)) { /* nothing the balancer can do (FARM_ALL_NOTE) */
            say(s, "balance: " FARM_ALL_NOTE ": walls unchanged\n");
            break;
        }
        double before = 0, pred = 0;
        vw_status rc = rt_anim_balance(s->anim, s->strategy && strcmp(s->strategy, "none") ? s->strategy : "tensor",
                                       &before, &pred, err, sizeof err);
        if (rc != VW_OK) {
            vw_progress_hide(&s->bar);
            if (vw_cli_is_output()) fprintf(stderr, "%s:%d: balance: %s\n", s->name, lineno, err);
            if (rc != VW_E_UNSUPPORTED && !s->interactive) s->failed = 1;
        } else if (before == 0) { /* the loads were reset by a rebalance: 1 -> 1 said nothing */
            say(s, "balance: no load measured on the current walls yet (render a frame "
                   "first): walls unchanged\n");
        } else {
            say(s, "balanced: lambda %.3f -> %.3f predicted\n", before, pred);
        }
        break;
    }
    default: /* VW_EDIT_NONE: a blank line or a comment */
        break;
    }
    return s->failed;
}

static void help(const char *cmd)
{
    if (!strcmp(cmd, "edit"))
        printf("usage: vwalls edit SCENE [-o 'frames/%%04d.png'] [options]\n"
               "\nReads the edit language (docs/edit-language.md) from stdin, one command per line,\n"
               "and answers every edit at once; 'frame' renders the current scene.\n");
    else
        printf("usage: vwalls animate SCENE EDITS -o 'frames/%%04d.png' [options]\n"
               "\nRuns the edit script EDITS (docs/edit-language.md) on SCENE: moves are checked\n"
               "for collisions at their destination (and along their path with 'sweep on') by\n"
               "cells of the decomposition; every 'frame' renders a PNG. Under MPI the first\n"
               "process reads EDITS and hands it to the others.\n");
    printf("  -o, --output PATTERN  frame file names: a .png name with one %%d (like %%04d)\n"
           "                   for the frame number (from 0), %%%% for a percent sign\n"
           "  --cells L        layout of cells, like 4, 2x4, 2x2x2 (default 1; at most\n"
           "                   32768 cells)\n"
           "  --workers W      worker threads per process, 1 to 1024 (default: the cores it\n"
           "                   may run on)\n"
           "  --size WxH       image size (default: the scene's, else 512x512)\n"
           "  --depth D        maximum ray depth, 1 to 64 (default 5)\n"
           "  --balance S      none|tensor|rotate|staggered|divide: rebalance between frames\n"
           "                   when lambda exceeds 1 + --threshold (default 0.1)\n"
           "  --threshold X    rebalance when lambda exceeds 1 + X (default 0.1)\n"
           "  --trigger T      busy | work: that lambda is of the workers' busy time, or of\n"
           "                   their counted work (ray segments: the same on every run when\n"
           "                   no cell has copies, as with --farm idle or none); default:\n"
           "                   busy, or work where the workers outnumber the cores (their\n"
           "                   busy time is then mostly waiting for a core)\n"
           "  --farm F         auto (default) | all | idle | none, as for render: auto is all\n"
           "                   (every worker holds every cell), or idle with --balance\n"
           "  --margin F       the world box is the scene bounds grown by F x diagonal on\n"
           "                   every side (default 0.25); objects cannot leave it\n"
           "  --world X0,Y0,Z0,X1,Y1,Z1  the world box covers this box too: the walls then\n"
           "                   divide the space the scene is meant to fill (as render's)\n");
    if (strcmp(cmd, "edit")) /* edit answers every line and goes on */
        printf("  --keep-going     report bad lines and go on instead of stopping\n"
               "                   (the exit status is still 2)\n");
    printf("  --log FILE       every edit's and invalid line's outcome, one line each\n"
           "  --stats FILE     the stats JSON, with an \"animation\" member (per frame)\n"
           "  --full-rebuild   rebuild every cell at every frame (the benchmark's baseline)\n"
           "  --brute-force    decide with the O(n^2) reference instead of the cells\n"
           "  -q, --quiet      no banner, frame lines or summary (animate: no rejections\n"
           "                   or progress bar either; edit always answers every edit)\n"
           "  --help           this text\n"
           "The outputs (the frames, --log, --stats) must be files other than each other and\n"
           "the inputs (devices like /dev/null excepted); \"-\" is not standard output.\n"
           "Exit status: 0 success, 2 bad input (any bad line; it stops animate unless\n"
           "--keep-going: lines that do not parse before the first frame, others where\n"
           "they are reached), 1 other.\n");
}

static char *frames_json(vw_anim_session *s)
{
    char *j = NULL;
    size_t n = 0, cap = 0;
    int ok = vw_cli_appendf(&j, &n, &cap,
                            "\"animation\": {\"frames\": %zu, \"accepted\": %zu, \"collisions\": %zu, "
                            "\"sweeps\": %zu, \"invalid\": %zu, \"objects\": %zu, \"farm\": \"%s\", "
                            "\"trigger\": \"%s\", \"per_frame\": [",
                            s->nframes, s->total_acc, s->total_coll, s->total_sweep, s->total_invalid,
                            live_objects(s), rt_farm_name(s->farm), s->trigger_work ? "work" : "busy");
    for (size_t i = 0; ok && i < s->nframes; i++) {
        const frame_rec *f = &s->frames[i];
        ok = vw_cli_appendf(&j, &n, &cap,
                            "%s\n    {\"frame\": %d, \"edits\": %zu, \"accepted\": %zu, \"invalid\": %zu, "
                            "\"objects\": %zu, \"records\": %zu, "
                            "\"cells_rebuilt\": %zu, \"decide_s\": %.6f, \"update_s\": %.6f, "
                            "\"build_s\": %.6f, \"render_s\": %.6f, \"lambda\": %.4f, "
                            "\"work_lambda\": %.4f, \"balanced\": %d, \"balance_s\": %.6f}",
                            i ? "," : "", f->frame, f->edits, f->accepted, f->invalid, f->objects,
                            f->records, f->cells,
                            f->apply_s, f->update_s, f->build_s, f->render_s, f->lambda,
                            f->work_lambda, f->balanced, f->balance_s);
    }
    if (ok) ok = vw_cli_appendf(&j, &n, &cap, "]}");
    if (!ok) {
        free(j);
        return NULL;
    }
    return j;
}

/* Where the edits come from. Every process must apply the same edits in the same order:
   a line bad on one host only would stop that process alone while the others wait in the
   next collective. So the output process alone reads them and hands them to the others.
   A script file is read whole and broadcast once (its length, then its bytes); standard
   input (vwalls edit) must stream, as a line is answered before the next is typed, so it
   is broadcast a line at a time (MPI launchers forward stdin to rank 0 alone anyway). */
typedef struct edits_src {
    char *text;         /* the script file's bytes, on every process; NULL for stdin */
    size_t len, pos;    /* its length and the start of the next line */
    char *line;         /* stdin: the current line, on every process */
    size_t cap;
} edits_src;

/* Reads the script at path whole on the output process, and gives every process its
   bytes. Collective; every process returns the same status, the message in err:
   VW_E_INPUT when the script cannot be opened (bad input: exit status 2), VW_E_IO or
   VW_E_NOMEM when it cannot be read or held. */
static vw_status edits_load(edits_src *e, const char *path, char *err, size_t errlen)
{
    vw_status st = VW_OK;
    int64_t len = 0;
    if (vw_cli_is_output()) {
        FILE *in = fopen(path, "r");
        struct stat sb;
        if (!in || (fstat(fileno(in), &sb) == 0 && S_ISDIR(sb.st_mode))) {
            snprintf(err, errlen, "cannot open '%s': %s", path, in ? strerror(EISDIR) : strerror(errno));
            st = VW_E_INPUT;
        } else {
            size_t cap = 0, n = 0, k;
            char *p;
            do {
                if (n == cap) {
                    cap = cap ? 2 * cap : 65536;
                    if (!(p = realloc(e->text, cap + 1))) {
                        snprintf(err, errlen, "out of memory reading '%s'", path);
                        st = VW_E_NOMEM;
                        break;
                    }
                    e->text = p;
                }
                n += k = fread(e->text + n, 1, cap - n, in);
            } while (k > 0);
            if (st == VW_OK && ferror(in)) {
                snprintf(err, errlen, "cannot read '%s': %s", path, strerror(errno ? errno : EIO));
                st = VW_E_IO;
            }
            len = (int64_t)n;
        }
        if (in) fclose(in);
    }
    if ((st = vw_engine_agree(st, err, errlen)) != VW_OK) return st;
    vw_engine_broadcast(&len, sizeof len);
    if (!vw_cli_is_output() && !(e->text = malloc((size_t)len + 1))) {
        snprintf(err, errlen, "out of memory for the %lld bytes of '%s'", (long long)len, path);
        st = VW_E_NOMEM;
    }
    if ((st = vw_engine_agree(st, err, errlen)) != VW_OK) return st;
    vw_engine_broadcast(e->text, (size_t)len);
    e->text[len] = 0;
    e->len = (size_t)len;
    return VW_OK;
}

/* The next line of the edits, with its line end (its length, <= 0 at the end;
   *read_error gets errno when reading stdin failed). Collective for stdin. */
static ssize_t next_line(edits_src *e, const char **line, int *read_error)
{
    *read_error = 0;
    if (e->text) {
        if (e->pos >= e->len) return 0;
        const char *p = e->text + e->pos, *nl = memchr(p, '\n', e->len - e->pos);
        size_t n = nl ? (size_t)(nl - p) + 1 : e->len - e->pos;
        e->pos += n;
        *line = p;
        return (ssize_t)n;
    }
    ssize_t len = 0;
    if (vw_cli_is_output()) {
        len = getline(&e->line, &e->cap, stdin);
        *read_error = len < 0 && ferror(stdin) ? errno : 0;
    }
    int64_t head[2] = {len, *read_error};
    vw_engine_broadcast(head, sizeof head);
    len = (ssize_t)head[0];
    *read_error = (int)head[1];
    if (len <= 0) return len;
    if (!vw_cli_is_output() && e->cap < (size_t)len + 1) {
        char *p = realloc(e->line, (size_t)len + 1);
        if (!p) vw_engine_abort(VW_EXIT_FAIL, "vwalls edit: out of memory for a line of stdin");
        e->line = p;
        e->cap = (size_t)len + 1;
    }
    vw_engine_broadcast(e->line, (size_t)len);
    e->line[len] = 0;
    *line = e->line;
    return len;
}

/* Where the line piece starting at p ends: at a lone CR (a line end of classic Mac OS
   files, as in the NFF and OBJ readers; CRLF is one line end) or at end. */
static const char *piece_end(const char *p, const char *end)
{
    while (p < end && !(*p == '\r' && (p + 1 == end || p[1] != '\n'))) p++;
    return p;
}

/* Calls fn(arg, piece, its length, its number) on every line piece of the whole script
   (a line, its newline included, or the part of one up to a lone CR), numbered from 1
   as the session numbers them. */
static void each_piece(const edits_src *ed, void (*fn)(void *arg, const char *p, size_t len, int lineno),
                       void *arg)
{
    int lineno = 0;
    for (size_t pos = 0; ed->text && pos < ed->len;) {
        const char *p = ed->text + pos, *nl = memchr(p, '\n', ed->len - pos);
        const char *end = nl ? nl + 1 : ed->text + ed->len;
        pos = (size_t)(end - ed->text);
        while (p < end) {
            const char *q = piece_end(p, end);
            fn(arg, p, (size_t)(q - p), ++lineno);
            p = q + 1;
        }
    }
}

typedef struct precheck_arg {
    vw_anim_session *s;
    int bad;
} precheck_arg;

static void precheck_piece(void *arg, const char *p, size_t len, int lineno)
{
    precheck_arg *a = arg;
    vw_edit e;
    a->bad += parse_line(a->s, p, len, lineno, &e) != VW_OK;
}

/* animate without --keep-going: every line of the script is parsed before the first
   edit, so a line that does not parse (a typo at the end of a long script) stops the
   run before any frame is written, and every such line is reported at once. Lines that
   parse but cannot be applied (an id already removed, a move out of the world box)
   are found only when they are reached. Returns the number of bad lines. */
static int precheck(vw_anim_session *s, const edits_src *ed)
{
    precheck_arg a = {s, 0};
    each_piece(ed, precheck_piece, &a);
    return a.bad;
}

typedef struct frames_arg {
    const char *name;
    long frames;
} frames_arg;

static void count_frame(void *arg, const char *p, size_t len, int lineno)
{
    frames_arg *a = arg;
    vw_edit e;
    char err[8];
    if (!memchr(p, '\0', len) && vw_edit_parse(p, a->name, lineno, &e, err, sizeof err) == VW_OK &&
        e.op == VW_EDIT_FRAME)
        a->frames++;
}

/* The number of 'frame' lines of the script (those that parse): the frames a run can
   write. */
static long script_frames(const vw_anim_session *s, const edits_src *ed)
{
    frames_arg a = {s->name, 0};
    each_piece(ed, count_frame, &a);
    return a.frames;
}

/* Would a frame replace one of the inputs (the scene, its material libraries, animate's
   EDITS)? That is a usage error found before the work, like an output that names an
   input (vw_cli_check_files, which sees -o as a pattern, not as its frames): with -o
   'e%d.png' the script e1.png was replaced at frame 1, and a frame name that is a link
   to the scene replaced the scene. Compared by device and inode: the frames 0 to
   nframes-1 (the script's; vwalls edit's are not known in advance), and the frame whose
   number an input's name holds (vw_cli_frame_file). VW_EXIT_OK, or VW_EXIT_USAGE on
   every process with the message printed once (inputs NULL: out of memory, VW_EXIT_FAIL).
   Collective under MPI. */
static int frames_spare_inputs(const char *cmd, const char *pattern, const char *const *inputs,
                               int nin, long nframes)
{
    char err[1024] = "";
    vw_status st = VW_OK;
    if (!inputs) { /* no room for their list */
        snprintf(err, sizeof err, "%s", vw_status_message(VW_E_NOMEM));
        st = VW_E_NOMEM;
    }
    for (int k = 0; st == VW_OK && pattern && vw_cli_is_output() && k < nin; k++) {
        int frame;
        if (inputs[k] && vw_cli_frame_file(pattern, inputs[k], nframes, &frame)) {
            snprintf(err, sizeof err, "-o %s: frame %d is the input file %s: it would be overwritten",
                     pattern, frame, inputs[k]);
            st = VW_E_INPUT;
        }
    }
    st = vw_engine_agree(st, err, sizeof err);
    if (st == VW_OK) return VW_EXIT_OK;
    vw_cli_error(cmd, "%s", err);
    return st == VW_E_INPUT ? VW_EXIT_USAGE : VW_EXIT_FAIL;
}

/* The whole command, for both animate (edits from a file) and edit (from stdin). */
int vw_anim_main(const char *cmd, int argc, char **argv)
{
    const char *scene_path = NULL, *edits_path = NULL, *stats = NULL, *log_path = NULL;
    edits_src ed = {0};
    vw_anim_session *s = calloc(1, sizeof *s);
    /* Before the options are read: this process cannot know where the others will next
       agree (a usage error returns before any collective call), so it ends the job. */
    if (!s) {
        char msg[96];
        snprintf(msg, sizeof msg, "vwalls %s: out of memory for the session", cmd);
        vw_engine_abort(VW_EXIT_FAIL, msg);
    }
    s->cmd = cmd;
    s->check = 1;
    s->threshold = 0.1;
    s->interactive = !strcmp(cmd, "edit");
    rt_anim_params p;
    vw_box world_min;
    memset(&p, 0, sizeof p);
    long workers = 0, depth = 0;
    int trigger_given = 0;
    int rc = VW_EXIT_USAGE, farm = -1; /* -1: auto, resolved once the options are read */
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v;
        int taken;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            help(cmd);
            free(s);
            return VW_EXIT_OK;
        } else if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
            if (!(s->pattern = vw_cli_value(cmd, argc, argv, &i))) goto done;
        } else if (!strcmp(a, "--cells")) {
            if (!(v = vw_cli_value(cmd, argc, argv, &i)) || vw_cli_layout(cmd, a, v, p.dims)) goto done;
        } else if (!strcmp(a, "--workers")) {
            if (!(v = vw_cli_value(cmd, argc, argv, &i)) || vw_cli_int(cmd, a, v, 1, 1024, &workers)) goto done;
        } else if ((taken = vw_cli_image_option(cmd, argc, argv, &i, &p.width, &p.height, &depth))) {
            if (taken < 0) goto done;
        } else if (!strcmp(a, "--balance")) {
            if (!(s->strategy = vw_cli_value(cmd, argc, argv, &i))) goto done;
        } else if (!strcmp(a, "--farm")) {
            if (!(v = vw_cli_value(cmd, argc, argv, &i)) || vw_cli_farm(cmd, v, &farm)) goto done;
        } else if (!strcmp(a, "--trigger")) {
            if (!(v = vw_cli_value(cmd, argc, argv, &i))) goto done;
            if (strcmp(v, "busy") && strcmp(v, "work")) {
                vw_cli_error(cmd, "--trigger: bad value '%s' (expected busy or work)", v);
                goto done;
            }
            s->trigger_work = !strcmp(v, "work");
            trigger_given = 1;
        } else if (!strcmp(a, "--threshold")) {
            if (!(v = vw_cli_value(cmd, argc, argv, &i)) || vw_cli_double(cmd, a, v, 0, 100, &s->threshold)) goto done;
        } else if (!strcmp(a, "--margin")) {
            if (!(v = vw_cli_value(cmd, argc, argv, &i)) || vw_cli_double(cmd, a, v, 1e-6, 100, &p.margin)) goto done;
        } else if (!strcmp(a, "--world")) {
            if (vw_cli_box(cmd, a, vw_cli_value(cmd, argc, argv, &i), &world_min)) goto done;
            p.world_min = &world_min;
        } else if (!strcmp(a, "--keep-going") && !s->interactive) {
            /* animate's alone: edit answers every line and goes on, so it takes the
               option no more than any other it has no use for (an unknown option). */
            s->keep_going = 1;
        } else if (!strcmp(a, "--log")) {
            if (!(log_path = vw_cli_output(cmd, argc, argv, &i))) goto done;
        } else if (!strcmp(a, "--stats")) {
            if (!(stats = vw_cli_output(cmd, argc, argv, &i))) goto done;
        } else if (!strcmp(a, "--full-rebuild")) {
            p.full_rebuild = 1;
        } else if (!strcmp(a, "--brute-force")) {
            p.brute_force = 1;
        } else if (!strcmp(a, "--quiet") || !strcmp(a, "-q")) {
            s->quiet = 1;
        } else if (a[0] == '-' && a[1]) {
            vw_cli_error(cmd, "unknown option '%s' (try --help)", a);
            goto done;
        } else if (!scene_path) {
            scene_path = a;
        } else if (!s->interactive && !edits_path) {
            edits_path = a;
        } else {
            vw_cli_error(cmd, "unexpected argument '%s' (try --help)", a);
            goto done;
        }
    }
    if (!scene_path || (!s->interactive && (!edits_path || !s->pattern))) {
        vw_cli_error(cmd, s->interactive ? "usage: vwalls edit SCENE [-o PATTERN] (try --help)"
                                          : "usage: vwalls animate SCENE EDITS -o PATTERN (try --help)");
        goto done;
    }
    if (s->pattern && vw_cli_frame_pattern(cmd, "-o", s->pattern)) goto done;
    if (s->strategy && strcmp(s->strategy, "none") && strcmp(s->strategy, "tensor") &&
        strcmp(s->strategy, "rotate") && strcmp(s->strategy, "staggered") && strcmp(s->strategy, "divide")) {
        vw_cli_error(cmd, "--balance: bad value '%s' (expected none, tensor, rotate, staggered or divide)",
                     s->strategy);
        goto done;
    }
    p.workers = (int)workers;
    p.depth = (int)depth;
    p.farm = (rt_farm)vw_cli_farm_resolve(farm, s->strategy != NULL); /* as render's */
    s->farm = p.farm;
    {
        /* The frames' directory, the stats' and the log's (opened below, once the world
           is built), before any work: a --stats into a missing directory failed after
           the last frame; a --log naming the edits replaced them. */
        const char *opts[] = {"-o", "--stats", "--log"};
        const char *paths[] = {s->pattern, stats, log_path};
        const char *inputs[] = {scene_path, edits_path, NULL};
        int crc = vw_cli_check_files(cmd, inputs, opts, paths, 3);
        /* ... and neither is one of the frames: --log f00.png with -o f%02d.png
           replaced frame 0 by the log at the end. */
        if (crc == VW_EXIT_OK) crc = vw_cli_check_frames(cmd, s->pattern, opts + 1, paths + 1, 2, 0);
        if (crc != VW_EXIT_OK) {
            rc = crc;
            goto done;
        }
    }
    double t_start = vw_cli_now();
    /* Under MPI the output process reads the edits (edits_load) and every process reads
       the scene; all stop if one cannot (a file missing on one host), and the output
       process says which and why. */
    s->name = edits_path ? edits_path : "stdin";
    char err[1024] = "";
    vw_status est = edits_path ? edits_load(&ed, edits_path, err, sizeof err) : VW_OK;
    if (est != VW_OK) {
        vw_cli_error(cmd, "%s", err);
        rc = est == VW_E_INPUT ? VW_EXIT_USAGE : VW_EXIT_FAIL;
        goto done;
    }
    vw_scene *scene = NULL;
    if (vw_engine_agree(vw_scene_read_file(scene_path, &scene, err, sizeof err), err, sizeof err) != VW_OK) {
        if (vw_cli_is_output()) fprintf(stderr, "%s\n", err);
        vw_scene_free(scene);
        goto done;
    }
    if (vw_cli_same_view(cmd, p.width, p.height, depth, &scene->camera, scene) ||
        vw_cli_same_scene(cmd, scene)) {
        vw_scene_free(scene);
        goto done;
    }
    if (vw_cli_scene_size(scene_path, &scene->camera, p.width)) { /* as render's */
        vw_scene_free(scene);
        goto done;
    }
    {
        /* The scene's material libraries are inputs too (--log x.mtl replaced x.obj's). */
        const char *opts[] = {"--stats", "--log"};
        const char *paths[] = {stats, log_path};
        int crc = vw_cli_check_scene_files(cmd, scene, opts, paths, 2);
        /* ... and no frame is one of the inputs. */
        const char **in = crc == VW_EXIT_OK ? calloc(scene->nmaterials + 3, sizeof *in) : NULL;
        if (crc == VW_EXIT_OK) {
            int nin = 0;
            if (in) in[nin++] = scene_path;
            if (in && edits_path) in[nin++] = edits_path;
            for (size_t m = 0; in && m < scene->nmaterials; m++) {
                const char *lib = scene->materials[m].file > 0 ? vw_scene_string(scene, scene->materials[m].file) : NULL;
                int seen = !lib;
                for (int k = 0; !seen && k < nin; k++) seen = !strcmp(in[k], lib);
                if (!seen) in[nin++] = lib;
            }
            long nframes = s->script_frames = script_frames(s, &ed);
            crc = frames_spare_inputs(cmd, s->pattern, in, nin, nframes);
            /* ... and neither --stats nor --log is one of the frames the script writes,
               whatever its name says (a link to frame 3 named s.json; above, only the
               number a name holds was known). */
            if (crc == VW_EXIT_OK && nframes > 0)
                crc = vw_cli_check_frames(cmd, s->pattern, opts, paths, 2, nframes);
        }
        free(in);
        if (crc != VW_EXIT_OK) {
            rc = crc;
            vw_scene_free(scene);
            goto done;
        }
    }
    vw_status st = rt_anim_create(scene, &p, &s->anim, err, sizeof err);
    if (st != VW_OK) {
        vw_cli_error(cmd, "%s", err);
        rc = st == VW_E_INVAL ? VW_EXIT_USAGE : VW_EXIT_FAIL; /* as render's */
        goto done;
    }
    /* Busy time on more workers than cores is mostly time spent waiting for a core: its
       lambda would rebalance at every frame by the scheduler's noise. The default trigger
       is then the counted work, as render's default load (the cores as render counts
       them, so every process decides alike: they must rebalance together). */
    if (!trigger_given && s->strategy && strcmp(s->strategy, "none")) {
        int workers_here = vw_world_workers(rt_job_world(rt_anim_job(s->anim)));
        double cores = vw_engine_core_share();
        int crowded = workers_here > cores;
        char cbuf[96];
        s->trigger_work = crowded;
        /* On stderr, as render's note: edit's standard output is its answers. */
        if (crowded && !s->quiet && vw_cli_is_output())
            fprintf(stderr, "vwalls %s: %s: rebalancing when the counted "
                            "work's lambda exceeds 1 + %g (--trigger work), not busy time's, "
                            "which would be mostly waiting for a core\n",
                    cmd, vw_cli_crowding(workers_here, cores, cbuf, sizeof cbuf), s->threshold);
    }
    if (log_path) { /* written by the output process; all stop when it cannot */
        vw_status lst = vw_cli_is_output() ? vw_outfile_open(log_path, &s->logf, err, sizeof err) : VW_OK;
        if (vw_engine_agree(lst, err, sizeof err) != VW_OK) {
            vw_cli_error(cmd, "%s", err);
            rc = VW_EXIT_FAIL;
            goto done;
        }
        if (s->logf) s->log = vw_outfile_stream(s->logf);
    }
    /* Whole lines, however long (the parser refuses a long command; a long comment is
       fine), so no tail of a line is ever read as a line of its own. */
    const char *line = NULL;
    ssize_t len;
    int lineno = 0;
    if (s->interactive) {
        say(s, "vwalls edit: %d objects; commands: move moveto rotate add remove check sweep frame balance\n",
            vw_dynscene_ids(rt_anim_dynscene(s->anim)));
        fflush(stdout); /* a program driving edit waits for it */
    }
    /* animate on a terminal: a bar over the script's frames (vwalls edit's are not known,
       and its answers are its output). */
    vw_progress_begin(&s->bar, cmd, s->quiet || s->interactive || s->script_frames <= 0
                                         ? VW_PROGRESS_OFF : VW_PROGRESS_AUTO);
    int read_error = 0;
    int stop = 0;
    if (ed.text && !s->keep_going && precheck(s, &ed)) stop = s->failed = 2;
    while (!stop && (len = next_line(&ed, &line, &read_error)) > 0) {
        /* A lone CR ends a line too; the parser stops at the CR, so each piece is
           handed over in place. */
        const char *p = line, *end = line + len;
        while (!stop && p < end) {
            const char *q = piece_end(p, end);
            lineno++;
            stop = session_line(s, p, (size_t)(q - p), lineno);
            p = q + 1;
        }
        if (s->interactive) fflush(stdout);
    }
    if (!s->failed) flush(s);
    vw_progress_end(&s->bar);
    s->bar.enabled = 0;
    if (read_error && !s->failed) {
        vw_cli_error(cmd, "cannot read 'stdin': %s", strerror(read_error));
        s->failed = 1;
    }
    say(s, "%s: %zu accepted, %zu rejected at the destination, %zu rejected along the path, "
           "%zu invalid; %zu frames (farm %s)\n",
        cmd, s->total_acc, s->total_coll, s->total_sweep, s->total_invalid, s->nframes,
        rt_farm_name(s->farm));
    if (stats && s->failed != 1) {
        char *extra = frames_json(s);
        vw_world *w = rt_job_world(rt_anim_job(s->anim));
        vw_world_add_time(w, "total", vw_cli_now() - t_start);
        if (!extra) {
            vw_cli_error(cmd, "out of memory for the stats");
            if (!s->failed) s->failed = 1;
        } else if (vw_world_write_stats(w, stats, cmd, extra) != VW_OK) {
            vw_cli_error(cmd, "%s", vw_world_errmsg(w));
            if (!s->failed) s->failed = 1;
        }
        free(extra);
    }
    /* The log is put in place at the end, a failed session's too: it says how far the
       edits went. */
    if (s->logf) {
        vw_status lst = vw_outfile_commit(s->logf, err, sizeof err);
        s->logf = NULL;
        s->log = NULL;
        if (lst != VW_OK) {
            vw_cli_error(cmd, "%s", err);
            if (!s->failed) s->failed = 1;
        }
    }
    /* A bad line is bad input even when the session went on past it (--keep-going, edit). */
    rc = s->failed ? s->failed : s->frame_errors ? VW_EXIT_FAIL : s->bad_lines ? VW_EXIT_USAGE : VW_EXIT_OK;
done:
    free(ed.text);
    free(ed.line);
    vw_outfile_abort(s->logf);
    rt_anim_free(s->anim);
    free(s->frames);
    free(s);
    return rc;
}

int vw_cmd_animate(int argc, char **argv) { return vw_anim_main("animate", argc, argv); }
