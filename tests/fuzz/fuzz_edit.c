/* fuzz_edit.c - libFuzzer target for the edit language (src/dynamic/edit.c) and the
 * dynamic-scene handler behind it. The input is an edit script, one command per line.
 * Besides "never crash", it checks:
 *  - the parser's contract: a line is accepted, or refused with "fuzz.edits:LINE: why";
 *    an accepted edit has finite numbers, a positive radius, a non-zero rotation axis;
 *  - the collider's decisions: the script's batches (cut where `vwalls animate` cuts
 *    them: check, sweep, frame, balance) are decided by cells of a 2x2x1 world on two
 *    workers, and one edit at a time by the O(n^2) brute-force reference; every outcome,
 *    obstacle, id and message must agree, and the two scenes must be the same NFF after
 *    every batch;
 *  - moves and rotations are rigid: an object they were accepted for keeps its sizes
 *    (radii, a cone's length, a polygon's sides) to 1e-9 of the world.
 */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vwalls/vwalls.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

enum { MAX_LINES = 256, MAX_BATCH = 64 };

/* Spheres near each other and on the walls x = 5 and y = 5, a triangle, a quad and a
   cone: every kind of collision shape, objects held by several cells. */
static const char scene_nff[] =
    "v\nfrom 5 -20 8\nat 5 5 5\nup 0 0 1\nangle 40\nhither 0.01\nresolution 8 8\n"
    "b 0 0 0\nl 5 -5 20\nf 0.8 0.5 0.3 0.7 0.3 10 0 1\n"
    "s 2 2 2 0.5\n"
    "s 3.1 2 2 0.5\n"
    "s 5 5 5 0.3\n"
    "s 7 7 7 1\n"
    "s 5 2 8 0.25\n"
    "p 3\n1 6 1\n3 6 1\n2 8 2\n"
    "p 4\n6 1 4\n8 1 4\n8 3 4\n6 3 4\n"
    "c\n8 8 1 0.4\n8 8 3 0.1\n";

static void die(const char *what, int line, const char *detail)
{
    fprintf(stderr, "fuzz_edit: line %d: %s%s%s\n", line, what, detail ? ": " : "",
            detail ? detail : "");
    abort();
}

/* The scene as NFF text (malloc'ed). */
static char *nff_text(const vw_dynscene *ds)
{
    char *text = NULL;
    size_t n = 0;
    FILE *f = open_memstream(&text, &n);
    if (!f) abort();
    if (vw_dynscene_write_nff(ds, f) != VW_OK) die("writing the scene failed", 0, NULL);
    fclose(f);
    return text;
}

/* One parsed line against the parser's contract. */
static void check_parsed(vw_status st, const vw_edit *e, const char *err, int lineno)
{
    if (st != VW_OK) {
        char prefix[64];
        int k = snprintf(prefix, sizeof prefix, "fuzz.edits:%d: ", lineno);
        if (st != VW_E_INPUT) die("status is neither OK nor INPUT", lineno, err);
        if (strncmp(err, prefix, (size_t)k) || !err[k]) die("message without file:line: why", lineno, err);
        return;
    }
    if (e->line != lineno) die("edit has the wrong line", lineno, NULL);
    switch (e->op) {
    case VW_EDIT_ROTATE:
        if (!(e->v[0] != 0 || e->v[1] != 0 || e->v[2] != 0))
            die("rotation with a zero axis accepted", lineno, NULL);
        /* fall through */
    case VW_EDIT_MOVE:
    case VW_EDIT_MOVETO:
    case VW_EDIT_ADD:
        for (int k = 0; k < 4; k++)
            if (!(e->v[k] - e->v[k] == 0)) die("non-finite number accepted", lineno, NULL);
        if (e->op == VW_EDIT_ADD && !(e->v[3] > 0)) die("radius <= 0 accepted", lineno, NULL);
        if (e->op != VW_EDIT_ADD && e->id < 0) die("negative id accepted", lineno, NULL);
        break;
    case VW_EDIT_NONE:
    case VW_EDIT_REMOVE:
    case VW_EDIT_CHECK:
    case VW_EDIT_SWEEP:
    case VW_EDIT_FRAME:
    case VW_EDIT_BALANCE:
        break;
    default:
        die("unknown op", lineno, NULL);
    }
}

/* The sizes a rigid motion keeps: a sphere's radius; a cone's radii and length; a
   polygon's sides (at most 6 numbers). Returns how many, 0 for no such object. */
static int sizes(const vw_scene *s, int id, double out[6])
{
    vw_prim_kind kind;
    size_t i;
    if (vw_scene_find_object(s, id, &kind, &i) != VW_OK) return 0;
    if (kind == VW_PRIM_SPHERE) {
        out[0] = s->spheres[i].radius;
        return 1;
    }
    if (kind == VW_PRIM_CONE) {
        const vw_cone *c = &s->cones[i];
        double l = 0;
        for (int k = 0; k < 3; k++) l += (c->apex[k] - c->base[k]) * (c->apex[k] - c->base[k]);
        out[0] = c->base_radius, out[1] = c->apex_radius, out[2] = sqrt(l);
        return 3;
    }
    const vw_polygon *p = &s->polygons[i];
    int n = p->count < 6 ? p->count : 6;
    for (int j = 0; j < n; j++) {
        const double *a = s->vertices[s->indices[p->first + j]];
        const double *b = s->vertices[s->indices[p->first + (j + 1) % p->count]];
        double l = 0;
        for (int k = 0; k < 3; k++) l += (b[k] - a[k]) * (b[k] - a[k]);
        out[j] = sqrt(l);
    }
    return n;
}

/* Decides a batch both ways and compares. */
static void decide(vw_dynscene *dist, vw_dynscene *ref, const vw_edit *e, size_t n, int check,
                   int sweep)
{
    if (!n) return;
    vw_result r1[MAX_BATCH], r2[MAX_BATCH];
    int *ch;
    size_t nch;
    /* The sizes before the batch of every object it moves or turns (an object edited
       twice in the batch is checked against the first). */
    double before[MAX_BATCH][6];
    int nbefore[MAX_BATCH];
    for (size_t i = 0; i < n; i++) {
        int rigid = e[i].op == VW_EDIT_MOVE || e[i].op == VW_EDIT_MOVETO || e[i].op == VW_EDIT_ROTATE;
        nbefore[i] = rigid ? sizes(vw_dynscene_scene(dist), e[i].id, before[i]) : 0;
    }
    if (vw_dynscene_apply(dist, e, n, check, sweep, r1, &ch, &nch) != VW_OK)
        die("the collider's batch failed", e[0].line, NULL);
    free(ch);
    for (size_t i = 0; i < n; i++) {
        if (vw_dynscene_apply(ref, &e[i], 1, check, sweep, &r2[i], &ch, &nch) != VW_OK)
            die("the reference failed", e[i].line, NULL);
        free(ch);
    }
    for (size_t i = 0; i < n; i++) {
        if (r1[i].outcome != r2[i].outcome || r1[i].obstacle != r2[i].obstacle ||
            r1[i].id != r2[i].id ||
            (r1[i].outcome == VW_OUT_INVALID && strcmp(r1[i].msg, r2[i].msg))) {
            fprintf(stderr, "collider: outcome %d obstacle %d id %d '%s'; reference: %d %d %d '%s'\n",
                    r1[i].outcome, r1[i].obstacle, r1[i].id, r1[i].msg, r2[i].outcome,
                    r2[i].obstacle, r2[i].id, r2[i].msg);
            die("the collider and the reference disagree", e[i].line, NULL);
        }
    }
    for (size_t i = 0; i < n; i++) {
        double after[6];
        if (!nbefore[i] || r1[i].outcome != VW_OUT_ACCEPTED) continue;
        int na = sizes(vw_dynscene_scene(dist), e[i].id, after);
        if (!na) continue; /* removed later in the batch */
        if (na != nbefore[i]) die("an object changed kind", e[i].line, NULL);
        for (int k = 0; k < nbefore[i]; k++)
            if (!(fabs(after[k] - before[i][k]) <= 1e-8)) { /* 1e-9 of the 11-unit world */
                fprintf(stderr, "size %d: %.17g before, %.17g after\n", k, before[i][k], after[k]);
                die("a move or rotation changed the object's size", e[i].line, NULL);
            }
    }
    char *a = nff_text(dist), *b = nff_text(ref);
    if (strcmp(a, b)) die("the scenes differ after the batch", e[n - 1].line, NULL);
    free(a);
    free(b);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    if (!text) return 0;
    memcpy(text, data, size);
    text[size] = 0;

    char err[512];
    vw_scene *s1 = NULL, *s2 = NULL;
    if (vw_scene_read_nff("scene", scene_nff, sizeof scene_nff - 1, &s1, err, sizeof err) != VW_OK ||
        vw_scene_read_nff("scene", scene_nff, sizeof scene_nff - 1, &s2, err, sizeof err) != VW_OK)
        die("the fixed scene does not read", 0, err);
    vw_box world = {{-0.5, -0.5, -0.5}, {10.5, 10.5, 10.5}};
    int dims[3] = {2, 2, 1};
    vw_decomp *d = NULL;
    if (vw_decomp_create_grid(&world, dims, &d) != VW_OK) abort();
    vw_config cfg;
    vw_config_init(&cfg);
    cfg.workers = 2;
    vw_dynscene_params p = {d, &cfg, 0, 0};
    vw_dynscene *dist = NULL, *ref = NULL;
    if (vw_dynscene_create(s1, &p, &dist, err, sizeof err) != VW_OK) die("create", 0, err);
    p.brute_force = 1;
    if (vw_dynscene_create(s2, &p, &ref, err, sizeof err) != VW_OK) die("create (reference)", 0, err);

    vw_edit batch[MAX_BATCH];
    size_t nbatch = 0;
    int check = 1, sweep = 0, lineno = 0;
    char *line = text;
    while (line && lineno < MAX_LINES) {
        char *next = strchr(line, '\n');
        if (next) *next++ = 0;
        lineno++;
        vw_edit e;
        err[0] = 0;
        vw_status st = vw_edit_parse(line, "fuzz.edits", lineno, &e, err, sizeof err);
        check_parsed(st, &e, err, lineno);
        line = next;
        if (st != VW_OK) continue; /* as --keep-going does */
        if (e.op == VW_EDIT_NONE) continue;
        if (vw_edit_is_object(e.op)) {
            batch[nbatch++] = e;
            if (nbatch < MAX_BATCH) continue;
        }
        decide(dist, ref, batch, nbatch, check, sweep);
        nbatch = 0;
        if (e.op == VW_EDIT_CHECK) check = e.on;
        if (e.op == VW_EDIT_SWEEP) sweep = e.on;
    }
    decide(dist, ref, batch, nbatch, check, sweep);
    vw_dynscene_free(dist);
    vw_dynscene_free(ref);
    vw_decomp_free(d);
    free(text);
    return 0;
}
