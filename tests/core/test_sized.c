/* test_sized.c - the sized sends (module.h: vw_send_cell_sized and the others, the
 * VW_SEND_* macros) check the record they are given against its kind's size:
 *   ok       every cell of a 2x2 grid on two workers sends a 32-byte record through
 *            each of the five macros, a record through a pointer (*p), and a signal
 *            (size 0, no buffer); every message arrives whole, as many as the plain
 *            sends deliver, and a point outside the world is dropped as by
 *            vw_send_point; before the run, VW_WORLD_POST posts a record of the kind's
 *            size and vw_world_post_sized a signal, and refuses (VW_E_INVAL, a message
 *            naming both sizes, nothing posted) a record short or long
 *   cell-small | cell-large | pointer | point | point-outside | face | face-wall |
 *   neighbours | output | signal
 *            a record whose size is not the kind's (smaller: every message was cut
 *            short; larger: the send read past it; a pointer given for the record; a
 *            send that reaches no cell; a buffer for a signal) stops the process
 *            (abort) with a message on stderr naming the call, the kind, the size given
 *            and the kind's size: run in a child, whose end and stderr are checked. The
 *            plain sends, given the same records, let them through silently.
 * Usage: test_sized MODE [EXPECTED-MESSAGE]
 */
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include "vw_test.h"
#include "vwalls/vwalls.h"
#include "core/run_child.h"

typedef struct obj {
    double p[3];
} obj;

enum { MSG_REC, MSG_OUT, MSG_SIGNAL, NKINDS };

/* 32 bytes: what the kinds MSG_REC and MSG_OUT carry. */
typedef struct rec {
    double v[3];
    int32_t from, tag;
} rec;
typedef struct rec_short { /* 24 bytes: the record one field short */
    double v[3];
} rec_short;
typedef struct rec_long { /* 40 bytes: the record one field long */
    rec r;
    double extra;
} rec_long;

enum { TAG_CELL, TAG_POINT, TAG_FACE, TAG_NEIGHBOURS, TAG_POINTER, TAG_POST, NTAGS };

static const char *mode;
static int got[NTAGS], got_bad, got_signals, got_out, out_bad;

static rec make(int from, int tag)
{
    rec r = {{from + 0.25, from * 2.0 + tag, -1.0 - from}, from, tag};
    return r;
}

static int whole(const rec *r)
{
    rec want = make(r->from, r->tag);
    return r->tag >= 0 && r->tag < NTAGS && !memcmp(r, &want, sizeof want);
}

static void bounds(const void *o, vw_box *b, void *user)
{
    (void)user;
    const obj *x = o;
    for (int a = 0; a < 3; a++) b->lo[a] = b->hi[a] = x->p[a];
}

static void on_rec(vw_ctx *ctx, void *state, const void *msg)
{
    (void)ctx, (void)state;
    const rec *r = msg;
    if (whole(r))
        __atomic_add_fetch(&got[r->tag], 1, __ATOMIC_RELAXED);
    else
        __atomic_add_fetch(&got_bad, 1, __ATOMIC_RELAXED);
}

static void on_signal(vw_ctx *ctx, void *state, const void *msg)
{
    (void)ctx, (void)state, (void)msg;
    __atomic_add_fetch(&got_signals, 1, __ATOMIC_RELAXED);
}

static void on_out(void *user, const void *msg)
{
    (void)user;
    got_out++;
    if (!whole(msg)) out_bad++;
}

static int started[4];
/* What each cell's sends returned, checked by main after the run (a check on a worker
   thread would race on the test's counters). */
static int point_in[4], point_out[4], neighbours[4], alloc_failed[4];

/* The centre of cell 0 of the 2x2 grid over the unit cube, and a point outside. */
static const double centre0[3] = {0.25, 0.25, 0.5}, outside[3] = {2, 2, 2};

static int step(vw_ctx *ctx, void *state)
{
    (void)state;
    int c = vw_ctx_cell(ctx);
    if (started[c]) return 0;
    started[c] = 1;
    if (!strcmp(mode, "ok")) {
        rec r = make(c, TAG_CELL);
        VW_SEND_CELL(ctx, (c + 1) % 4, MSG_REC, r);
        r = make(c, TAG_POINT);
        point_in[c] = VW_SEND_POINT(ctx, centre0, NULL, MSG_REC, r);
        point_out[c] = VW_SEND_POINT(ctx, outside, NULL, MSG_REC, r); /* dropped: -1 */
        r = make(c, TAG_FACE);
        VW_SEND_FACE(ctx, 1, MSG_REC, r); /* +x: cells 0 and 2 have a neighbour there */
        r = make(c, TAG_NEIGHBOURS);
        neighbours[c] = VW_SEND_NEIGHBOURS(ctx, MSG_REC, r);
        rec *p = malloc(sizeof *p);
        if (!p) {
            alloc_failed[c] = 1;
            return 1;
        }
        *p = make(c, TAG_POINTER);
        VW_SEND_CELL(ctx, c, MSG_REC, *p);
        free(p);
        r = make(c, 0);
        VW_SEND_OUTPUT(ctx, MSG_OUT, r);
        vw_send_cell_sized(ctx, c, MSG_SIGNAL, NULL, 0);
        return 1;
    }
    /* The mistake, once, from cell 0. */
    if (c != 0) return 0;
    rec_short s = {{1, 2, 3}};
    rec_long l = {make(0, TAG_CELL), 4};
    rec *p = &l.r;
    if (!strcmp(mode, "cell-small")) VW_SEND_CELL(ctx, 1, MSG_REC, s);
    if (!strcmp(mode, "cell-large")) VW_SEND_CELL(ctx, 1, MSG_REC, l);
    if (!strcmp(mode, "pointer")) VW_SEND_CELL(ctx, 1, MSG_REC, p); /* meant *p */
    if (!strcmp(mode, "point")) VW_SEND_POINT(ctx, centre0, NULL, MSG_REC, s);
    if (!strcmp(mode, "point-outside")) VW_SEND_POINT(ctx, outside, NULL, MSG_REC, l);
    if (!strcmp(mode, "face")) VW_SEND_FACE(ctx, 1, MSG_REC, s);
    if (!strcmp(mode, "face-wall")) VW_SEND_FACE(ctx, 0, MSG_REC, s); /* -x: the world's wall */
    if (!strcmp(mode, "neighbours")) VW_SEND_NEIGHBOURS(ctx, MSG_REC, l);
    if (!strcmp(mode, "output")) VW_SEND_OUTPUT(ctx, MSG_OUT, s);
    if (!strcmp(mode, "signal")) VW_SEND_CELL(ctx, 1, MSG_SIGNAL, s);
    return 1;
}

static vw_status build(vw_ctx *ctx, const void *objects, size_t n, void **state)
{
    (void)ctx, (void)objects, (void)n;
    *state = NULL;
    return VW_OK;
}

static const vw_msg_kind kinds[NKINDS] = {
    [MSG_REC] = {.name = "rec", .size = sizeof(rec), .handle = on_rec},
    [MSG_OUT] = {.name = "out", .size = sizeof(rec), .output = on_out},
    [MSG_SIGNAL] = {.name = "signal", .size = 0, .handle = on_signal},
};
static const char *const counters[] = {"none"};

int main(int argc, char **argv)
{
    mode = argc > 1 ? argv[1] : "ok";
    vw_box world = {{0, 0, 0}, {1, 1, 1}};
    int dims[3] = {2, 2, 1};
    vw_decomp *d;
    CHECK(vw_decomp_create_grid(&world, dims, &d) == VW_OK);
    CHECK_EQ_INT(vw_decomp_cell_count(d), 4);
    vw_module m = {.abi = VW_MODULE_ABI, .name = "sized", .object_size = sizeof(obj),
                   .object_bounds = bounds, .kinds = kinds, .nkinds = NKINDS,
                   .counters = counters, .ncounters = 1, .cell_build = build, .step = step};
    vw_config cfg;
    vw_config_init(&cfg);
    cfg.workers = 2;
    vw_world *w = NULL;
    CHECK(vw_world_create(&m, NULL, d, &cfg, &w) == VW_OK);
    obj o = {{0.5, 0.5, 0.5}};
    CHECK(vw_world_add_objects(w, &o, 1) == VW_OK);
    if (!strcmp(mode, "ok")) {
        /* Posts: the record of the kind's size and a signal go; one short or long is
           refused with a message, nothing posted. */
        rec r = make(9, TAG_POST);
        rec_short rs = {{1, 2, 3}};
        rec_long rl = {make(9, TAG_POST), 4};
        CHECK_EQ_INT(VW_WORLD_POST(w, 3, MSG_REC, r), VW_OK);
        CHECK_EQ_INT(VW_WORLD_POST(w, 3, MSG_REC, rs), VW_E_INVAL);
        printf("post: %s\n", vw_world_errmsg(w));
        CHECK(strstr(vw_world_errmsg(w), "posted a record of 24 bytes for message kind 0 ('rec'), "
                                         "whose size is 32 bytes") != NULL);
        CHECK_EQ_INT(VW_WORLD_POST(w, 2, MSG_REC, rl), VW_E_INVAL);
        CHECK(strstr(vw_world_errmsg(w), "posted a record of 40 bytes") != NULL);
        CHECK_EQ_INT(vw_world_post_sized(w, 1, MSG_SIGNAL, NULL, 0), VW_OK);
        CHECK_EQ_INT(vw_world_post_sized(w, 1, MSG_SIGNAL, &r, sizeof r), VW_E_INVAL);
        CHECK_EQ_INT(vw_world_run(w), VW_OK);
        CHECK_EQ_INT(got[TAG_POST], 1);
        for (int c = 0; c < 4; c++) {
            CHECK_EQ_INT(point_in[c], 0);
            CHECK_EQ_INT(point_out[c], -1);
            CHECK_EQ_INT(neighbours[c], 2);
            CHECK_EQ_INT(alloc_failed[c], 0);
        }
        CHECK_EQ_INT(got_bad, 0);
        CHECK_EQ_INT(got[TAG_CELL], 4);
        CHECK_EQ_INT(got[TAG_POINT], 4);
        CHECK_EQ_INT(got[TAG_FACE], 2);
        CHECK_EQ_INT(got[TAG_NEIGHBOURS], 8);
        CHECK_EQ_INT(got[TAG_POINTER], 4);
        CHECK_EQ_INT(got_signals, 5); /* four sent, one posted */
        CHECK_EQ_INT(got_out, 4);
        CHECK_EQ_INT(out_bad, 0);
    } else {
        /* The child makes the mistake with its stderr into a pipe. */
        char err[1024];
        int status = run_in_child(w, err, sizeof err);
        printf("%s: %s", mode, err);
        CHECK(WIFSIGNALED(status) && WTERMSIG(status) == SIGABRT);
        CHECK(argc > 2 && strstr(err, argv[2]) != NULL);
        /* One whole line: "vwalls: module 'sized' WHAT (worker W, in cell 0)\n". */
        const char *at = strstr(err, "vwalls: module 'sized' gave vw_send_");
        CHECK(at && strstr(at, " (worker ") && strstr(at, ", in cell 0)\n"));
    }
    vw_world_free(w);
    vw_decomp_free(d);
    printf("sized %s ok\n", mode);
    return vw_test_failures ? 1 : 0;
}
