/* module.c - the radiosity module: a cell's patches and receiver elements, shooting,
 * and the front-to-back relay of hemicube coverage bitmaps between cells.
 *
 * Front-to-back rule. For a shot from point p with normal n, the cell across face f of
 * cell C is "upstream" when p lies on its side of the wall (ties decided exactly as
 * vw_decomp_locate decides them, with n as direction). Two face neighbours are split
 * by their lowest common kd-tree split, which is that wall, so "upstream" follows the
 * kd-tree front-to-back order from p: it has no cycle, and a ray from p meets every
 * upstream cell before C. A cell takes part in a shot when its box meets the open half
 * space in front of the shooter (and the neighbourhood cube, if any); every such cell
 * except the source has at least one such upstream neighbour (walk back along a segment
 * from a point of the cell to p), so counting only participating upstream neighbours
 * makes every wait finite and exact: a cell rasterises a shot once it holds as many
 * bitmaps as it has participating upstream neighbours, and every cell on a segment
 * from p to one of its points is upstream of it, transitively. Visibility is then the
 * one-cell hemicube's.
 */
#include "radiosity/solver_internal.h"
#include "radiosity/vec.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *const rad_counter_names[RAD_NCOUNTERS] = {
    "shots", "shot_messages", "shot_bytes", "full_messages", "rasterised_elements",
    "element_splits", "back_face_hits",
};

enum { RAD_PX_CLEAR = -1, RAD_PX_UPSTREAM = -2 };

typedef struct rad_patch {
    rad_piece pc;
    double unshot[3];
    int64_t nshots;
    double scale;        /* pc.patch_area / pc.area: 1 for a patch no wall cuts */
} rad_patch;

/* The unshot power (r+g+b) of the whole patch piece pt is part of, as far as this cell
   can tell: the piece's unshot power per area times the patch's area. The stopping
   rule and the choice of shooter use it, so that they are about patches, as the
   design says, whatever the walls cut: compared piece by piece, a patch cut into k
   pieces held 1/k of its power in each, fell below --sf sooner, and the Cornell box
   stopped with 23 % of the emitted power unshot on one cell but 32 % on 6x6x6. Why it
   is safe: the patch's unshot power is the sum over its pieces of density times area,
   which is at most the largest piece density times the patch area, so when no piece's
   estimate is above the threshold no patch is. It is exact for an uncut patch (scale
   1), so a one-cell run is what it was. */
static double patch_unshot(const rad_patch *pt)
{
    return rad_sum3(pt->unshot) * pt->scale;
}

typedef struct rad_elem {
    int patch;
    int32_t level, gi, gj;
    int vfirst, nv;
    int alive;
    int root;            /* the level-0 element it descends from (itself at level 0) */
    double area;
    double B[3], incident[3];
    double won;          /* delta form factor won in the current shot */
} rad_elem;

typedef struct rad_pend {
    uint64_t id;
    int expected, received, full;
    uint64_t ready;      /* 0: waiting for bitmaps; else the order in which it became ready */
    rad_shot_hdr h;
    uint8_t *bits;
} rad_pend;

typedef struct rad_cell {
    rad_solver *S;
    int cell;
    int nnb[6];
    int *nb[6];
    vw_box *nbbox[6];
    rad_patch *patches;
    int npatches;
    rad_elem *el;
    int nel, capel;
    double (*vp)[3];
    int nvp, capvp;
    int *ht;             /* open addressing on (poly, level, gi, gj): element index or -1 */
    int htcap, htused;
    rad_pend *pend;
    int npend, cappend;
    uint8_t *mask;       /* the bitmap of this cell's own shot */
    int *touched;
    char *pvis;          /* per patch: some vertex in front of the current shooter */
    double (*hv)[3];
    /* Receiver detail (with --subdivide): every level-0 element e (they are el[0..nroot),
       built before any split) owns nsub = 4^fine cells of the deepest level, at
       [e*nsub, (e+1)*nsub), local index a*side + b for frame offsets (a, b). Each keeps
       its centroid, area, the incident power it received and the live leaf element
       that covers it. */
    int fine, side, nsub, nroot;
    double (*scc)[3], *sca, (*sci)[3], *scw;
    int *scl;
    /* Groups: runs of level-0 elements of one polygon, [gfirst[g], gfirst[g + 1]); a
       shot's power per group (gpow) and the groups it touched (glist). */
    int ngrp, *gfirst, *gpatch, *rgrp, *glist, nglist;
    int32_t *gpoly;      /* each group's polygon */
    vw_box box;          /* this cell's box (decomposition frame) */
    int *pcls;           /* per pixel in the current shot: group, RAD_PX_UPSTREAM or _CLEAR
                            (the worker's scratch, lent for the shot) */
    char *gtouched;
    double (*gpow)[3];
    int round, budget;
    int nready;          /* pending shots holding all their bitmaps */
    uint64_t readyseq;
    double thr;
    uint64_t seq;
    int64_t nshots;
    double absorbed[3], shot[3], won[3];
} rad_cell;

/* Memory the solve takes while a run is under way (cell_build takes most of a cell's,
   and fails the commit when it cannot). When it cannot be had the run fails
   (vw_ctx_fail: every process drops its work, and vw_world_run returns VW_E_NOMEM), and
   the caller drops what it was doing: NULL, and p is left as it was. */
static void *grow(vw_ctx *ctx, void *p, size_t n)
{
    const rad_solver *S = vw_ctx_user(ctx);
    void *q = S->fault_solve_nomem ? NULL : realloc(p, n ? n : 1);
    if (!q) vw_ctx_fail(ctx, VW_E_NOMEM, "out of memory (%zu bytes) in the solve", n);
    return q;
}

/* ---- elements and their hash ---- */

static uint64_t hkey(int32_t poly, int32_t level, int32_t gi, int32_t gj)
{
    uint64_t h = (uint64_t)(uint32_t)poly * 0x9e3779b97f4a7c15ull;
    h ^= (uint64_t)(uint32_t)level * 0xc2b2ae3d27d4eb4full + (h << 6);
    h ^= (uint64_t)(uint32_t)gi * 0x165667b19e3779f9ull + (h >> 3);
    h ^= (uint64_t)(uint32_t)gj * 0x27d4eb2f165667c5ull;
    return h ^ (h >> 29);
}

/* Room for the hash of elements [0, n): the table doubles, and its elements are
   re-inserted, when n would fill more than half of it. -1 when out of memory (the old
   table is kept). */
static int ht_reserve(rad_cell *c, int n)
{
    if (2 * n <= c->htcap) return 0;
    int cap = c->htcap ? 2 * c->htcap : 64;
    while (2 * n > cap) cap *= 2;
    int *ht = malloc(sizeof(int) * (size_t)cap);
    if (!ht) return -1;
    free(c->ht);
    c->ht = ht;
    c->htcap = cap;
    for (int i = 0; i < cap; i++) c->ht[i] = -1;
    c->htused = 0;
    for (int e = 0; e < c->nel; e++) {
        const rad_elem *x = &c->el[e];
        size_t i = hkey(c->patches[x->patch].pc.poly, x->level, x->gi, x->gj) & (size_t)(cap - 1);
        while (c->ht[i] >= 0) i = (i + 1) & (size_t)(cap - 1);
        c->ht[i] = e;
        c->htused++;
    }
    return 0;
}

/* Enters element e, the last one (the table has room: ht_reserve). */
static void ht_insert(rad_cell *c, int e)
{
    const rad_elem *x = &c->el[e];
    size_t i = hkey(c->patches[x->patch].pc.poly, x->level, x->gi, x->gj) & (size_t)(c->htcap - 1);
    while (c->ht[i] >= 0) i = (i + 1) & (size_t)(c->htcap - 1);
    c->ht[i] = e;
    c->htused++;
}

/* An element of polygon poly at (level, gi, gj); with piece >= 0 only that piece's.
   alive_only: skip split parents. -1 when none. */
static int ht_find(const rad_cell *c, int32_t poly, int64_t piece, int32_t level, int32_t gi,
                   int32_t gj, int alive_only)
{
    if (!c->htcap) return -1;
    size_t i = hkey(poly, level, gi, gj) & (size_t)(c->htcap - 1);
    for (; c->ht[i] >= 0; i = (i + 1) & (size_t)(c->htcap - 1)) {
        const rad_elem *x = &c->el[c->ht[i]];
        const rad_piece *pc = &c->patches[x->patch].pc;
        if (pc->poly == poly && x->level == level && x->gi == gi && x->gj == gj &&
            (piece < 0 || pc->id == piece) && (!alive_only || x->alive))
            return c->ht[i];
    }
    return -1;
}

/* Adds the element of patch at (level, gi, gj): its index, -1 when the square holds
   no element (no area), -2 when out of memory (nothing is changed then). */
static int add_elem(rad_cell *c, int patch, int level, int gi, int gj, const double B[3])
{
    rad_poly poly;
    const rad_piece *pc = &c->patches[patch].pc;
    if (rad_elem_polygon(pc, level, gi, gj, &poly) < 3) return -1;
    double area = rad_poly_area(&poly, NULL, NULL);
    if (!(area > 1e-14 * pc->area)) return -1;
    if (c->nel == c->capel) {
        int cap = c->capel ? 2 * c->capel : 64;
        rad_elem *el = realloc(c->el, sizeof *c->el * (size_t)cap);
        if (!el) return -2;
        c->el = el;
        c->capel = cap;
    }
    if (c->nvp + poly.n > c->capvp) {
        int cap = c->capvp ? c->capvp : 256;
        while (c->nvp + poly.n > cap) cap *= 2;
        double(*vp)[3] = realloc(c->vp, sizeof *c->vp * (size_t)cap);
        if (!vp) return -2;
        c->vp = vp;
        c->capvp = cap;
    }
    if (ht_reserve(c, c->nel + 1) < 0) return -2;
    rad_elem *e = &c->el[c->nel];
    memset(e, 0, sizeof *e);
    e->patch = patch, e->level = level, e->gi = gi, e->gj = gj;
    e->vfirst = c->nvp, e->nv = poly.n, e->alive = 1, e->area = area;
    e->root = c->nel; /* a child's is set by split_elem */
    memcpy(e->B, B, sizeof e->B);
    memcpy(c->vp + c->nvp, poly.v, sizeof(double) * 3 * (size_t)poly.n);
    c->nvp += poly.n;
    c->nel++;
    ht_insert(c, c->nel - 1);
    return c->nel - 1;
}

/* The deepest-level cells of element x: rows [*a0, *a0 + *w) and columns [*b0, *b0 + *w)
   of its root's block. */
static void fine_range(const rad_cell *c, const rad_elem *x, int *a0, int *b0, int *w)
{
    const rad_elem *r = &c->el[x->root];
    int sh = c->fine - x->level;
    /* Grid indices may be negative: multiply, do not shift. */
    *a0 = (x->gi - r->gi * (1 << x->level)) * (1 << sh);
    *b0 = (x->gj - r->gj * (1 << x->level)) * (1 << sh);
    *w = 1 << sh;
}

/* Sums the incident power of element x's fine cells (and their area, if area). */
static void fine_sum(const rad_cell *c, const rad_elem *x, double inc[3], double *area)
{
    int a0, b0, w;
    fine_range(c, x, &a0, &b0, &w);
    size_t base = (size_t)x->root * (size_t)c->nsub;
    inc[0] = inc[1] = inc[2] = 0;
    double A = 0;
    for (int a = a0; a < a0 + w; a++)
        for (int b = b0; b < b0 + w; b++) {
            size_t s = base + (size_t)(a * c->side + b);
            for (int k = 0; k < 3; k++) inc[k] += c->sci[s][k];
            A += c->sca[s];
        }
    if (area) *area = A;
}

/* Splits element e into its four children. With fine cells (--subdivide) each child
   takes exactly the incident power its fine cells received since the first shot: the
   re-gather is free, and the children's powers sum to the parent's (up to rounding).
   Without them (a checkpoint restored into a run without --subdivide) the children
   inherit the parent's radiosity and share its incident power by area. Either way the
   energy ledger is untouched: it counts power per patch and per cell, never per
   element. */
static int split_elem(vw_ctx *ctx, rad_cell *c, int e)
{
    rad_elem par = c->el[e];
    c->el[e].alive = 0;
    const rad_piece *pc = &c->patches[par.patch].pc;
    for (int a = 0; a < 2; a++)
        for (int b = 0; b < 2; b++) {
            int k = add_elem(c, par.patch, par.level + 1, 2 * par.gi + a, 2 * par.gj + b, par.B);
            if (k == -2) {
                vw_ctx_fail(ctx, VW_E_NOMEM, "out of memory splitting an element of %d", c->nel);
                return -1;
            }
            if (k < 0) continue;
            rad_elem *x = &c->el[k];
            x->root = par.root;
            if (!c->fine) {
                for (int ch = 0; ch < 3; ch++) x->incident[ch] = par.incident[ch] * x->area / par.area;
                continue;
            }
            fine_sum(c, x, x->incident, NULL);
            for (int ch = 0; ch < 3; ch++) x->B[ch] = pc->emit[ch] + pc->rho[ch] * x->incident[ch] / x->area;
            int a0, b0, w;
            fine_range(c, x, &a0, &b0, &w);
            for (int i = a0; i < a0 + w; i++)
                for (int j = b0; j < b0 + w; j++) c->scl[(size_t)x->root * (size_t)c->nsub + (size_t)(i * c->side + j)] = k;
        }
    return 0;
}

/* Luminance of the reflected radiosity of x's quadrant (qa, qb) from its fine cells;
   *area gets the quadrant's area. */
static double quadrant_y(const rad_cell *c, const rad_elem *x, int qa, int qb, double *area)
{
    int a0, b0, w;
    fine_range(c, x, &a0, &b0, &w);
    const rad_piece *pc = &c->patches[x->patch].pc;
    size_t base = (size_t)x->root * (size_t)c->nsub;
    double inc[3] = {0, 0, 0}, A = 0;
    w /= 2;
    for (int a = a0 + qa * w; a < a0 + (qa + 1) * w; a++)
        for (int b = b0 + qb * w; b < b0 + (qb + 1) * w; b++) {
            size_t s = base + (size_t)(a * c->side + b);
            for (int k = 0; k < 3; k++) inc[k] += c->sci[s][k];
            A += c->sca[s];
        }
    *area = A;
    return A > 0 ? (pc->rho[0] * inc[0] + pc->rho[1] * inc[1] + pc->rho[2] * inc[2]) / (3 * A) : 0;
}

/* Adaptive subdivision, decided for all elements first, then split. A live element is
   split (never an emitter, never below the fine level) when
    - its own four quadrants, known exactly from its fine cells, differ by more than
      rel times its mean and more than floor: there is detail inside it (a shadow edge);
      this is not fooled by hemicube aliasing, since the fine cells only share out the
      power the element's pixels won, by point form factors and visibility;
    - or it differs by as much from a neighbour (same polygon, same or coarser level, in
      this cell, across pieces too): an edge on the element boundary. The level-0
      values carry the hemicube's noise, so this test asks twice the contrast.
   Splitting adds no noise: the children's values are exact sums of fine cells. */
static void subdivide(vw_ctx *ctx, rad_cell *c, double rel, double floor_, int max_level)
{
    int n = c->nel, nsplit = 0;
    if (max_level > c->fine) max_level = c->fine;
    if (max_level <= 0) return;
    char *mark = grow(ctx, NULL, (size_t)(n ? n : 1));
    if (!mark) return;
    memset(mark, 0, (size_t)(n ? n : 1));
    static const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
    for (int e = 0; e < n; e++) {
        rad_elem *x = &c->el[e];
        const rad_piece *pc = &c->patches[x->patch].pc;
        if (!x->alive || x->level >= max_level || rad_sum3(pc->emit) > 0) continue;
        double lo = INFINITY, hi = -INFINITY, sy = 0, sa = 0;
        for (int q = 0; q < 4; q++) {
            double A, y = quadrant_y(c, x, q >> 1, q & 1, &A);
            if (!(A > 0.05 * x->area / 4)) continue; /* a sliver left by clipping */
            lo = fmin(lo, y), hi = fmax(hi, y);
            sy += y * A, sa += A;
        }
        double mean = sa > 0 ? sy / sa : 0;
        if (hi - lo > rel * mean && hi - lo > floor_) {
            mark[e] = 1;
            continue;
        }
        double Ya = rad_sum3(x->B) / 3;
        for (int k = 0; k < 4 && !mark[e]; k++) {
            int o = -1;
            for (int l = x->level; l >= 0 && o < 0; l--) {
                int sh = x->level - l;
                int gi = (x->gi + dx[k]) >> sh, gj = (x->gj + dy[k]) >> sh;
                o = ht_find(c, pc->poly, -1, l, gi, gj, 0);
                if (o >= 0 && !c->el[o].alive) o = -2; /* finer ones compare with x */
            }
            if (o < 0) continue;
            double Yb = rad_sum3(c->el[o].B) / 3, diff = fabs(Ya - Yb);
            if (diff > 2 * rel * 0.5 * (Ya + Yb) && diff > floor_) mark[e] = 1;
        }
    }
    for (int e = 0; e < n; e++) {
        if (!mark[e]) continue;
        if (split_elem(ctx, c, e) < 0) break;
        nsplit++;
    }
    free(mark);
    vw_count(ctx, RAD_C_SPLITS, nsplit);
}

/* ---- the wall rule ---- */

/* Is frame point q on the + side of the wall at w on one axis? Exactly the test of
   vw_decomp_locate, with the shooter normal as direction. */
static int plus_side(double q, double v, double w) { return q > w || (q == w && v >= 0); }

/* Is the cell across face f upstream (p on its side)? */
static int upstream(const vw_box *b, int f, const double q[3], const double v[3])
{
    int a = VW_FACE_AXIS(f);
    if (VW_FACE_SIGN(f) > 0) return plus_side(q[a], v[a], b->hi[a]);
    return !plus_side(q[a], v[a], b->lo[a]);
}

/* Does box b meet the open half space in front of the shooter (within the
   neighbourhood cube, if D > 0)? Computed from the message and the decomposition
   alone, so the sender and the receiver of a bitmap agree on it. */
static int in_range(const vw_box *b, const double q[3], const double v[3], double D)
{
    double s = 0;
    for (int a = 0; a < 3; a++) {
        double lo = b->lo[a], hi = b->hi[a];
        if (D > 0) {
            lo = fmax(lo, q[a] - D);
            hi = fmin(hi, q[a] + D);
            if (lo > hi) return 0;
        }
        s += v[a] > 0 ? v[a] * (hi - q[a]) : v[a] * (lo - q[a]);
    }
    return s > 0;
}

/* ---- building ---- */

static void cell_free(void *state, void *user);

static vw_status cell_build(vw_ctx *ctx, const void *objects, size_t n, void **state)
{
    rad_solver *S = vw_ctx_user(ctx);
    const vw_decomp *d = vw_ctx_decomp(ctx);
    /* Whole cache lines: the rasteriser reads this state per pixel while the other
       worker writes its own cells' states, so two cells must never share a line. */
    size_t bytes = (sizeof(rad_cell) + 63) / 64 * 64;
    rad_cell *c = aligned_alloc(64, bytes);
    if (!c) return VW_E_NOMEM;
    memset(c, 0, bytes);
    c->S = S;
    c->cell = vw_ctx_cell(ctx);
    c->box = vw_ctx_cell_box(ctx);
    const rad_piece *pcs = objects;
    if (!(c->patches = malloc(sizeof *c->patches * (n ? n : 1)))) goto nomem;
    for (size_t i = 0; i < n; i++) {
        /* The runtime hands a piece to every cell its box touches; its owner keeps it. */
        if (vw_decomp_locate(d, pcs[i].centroid, pcs[i].normal) != c->cell) continue;
        rad_patch *pt = &c->patches[c->npatches++];
        memset(pt, 0, sizeof *pt);
        pt->pc = pcs[i];
        pt->scale = pcs[i].patch_area > pcs[i].area ? pcs[i].patch_area / pcs[i].area : 1;
        for (int k = 0; k < 3; k++) pt->unshot[k] = pcs[i].emit[k] * pcs[i].area;
    }
    for (int p = 0; p < c->npatches; p++) {
        int lo[2], hi[2];
        rad_piece_grid(&c->patches[p].pc, lo, hi);
        for (int i = lo[0]; i <= hi[0]; i++)
            for (int j = lo[1]; j <= hi[1]; j++)
                if (add_elem(c, p, 0, i, j, c->patches[p].pc.emit) == -2) goto nomem;
    }
    if (S->opt.subdivide > 0 && S->opt.max_level > 0) {
        c->fine = S->opt.max_level < RAD_MAX_LEVEL ? S->opt.max_level : RAD_MAX_LEVEL;
        c->side = 1 << c->fine;
        c->nsub = c->side * c->side;
        c->nroot = c->nel;
        size_t nf = (size_t)c->nroot * (size_t)c->nsub;
        if (!(c->scc = malloc(sizeof *c->scc * (nf ? nf : 1)))) goto nomem;
        if (!(c->sca = malloc(sizeof *c->sca * (nf ? nf : 1)))) goto nomem;
        c->sci = calloc(nf ? nf : 1, sizeof *c->sci);
        if (!(c->scl = malloc(sizeof *c->scl * (nf ? nf : 1)))) goto nomem;
        if (!c->sci) goto nomem;
        /* Roots of one polygon are consecutive (patches come in mesh order, polygon by
           polygon); a polygon seen twice would only make two groups. */
        if (!(c->gfirst = malloc(sizeof(int) * (size_t)(c->nroot + 1)))) goto nomem;
        if (!(c->rgrp = malloc(sizeof(int) * (size_t)(c->nroot ? c->nroot : 1)))) goto nomem;
        size_t maxg = 1;
        for (int e = 0; e < c->nroot; e++) {
            if (!e || c->patches[c->el[e].patch].pc.poly != c->patches[c->el[e - 1].patch].pc.poly)
                c->gfirst[c->ngrp++] = e;
            c->rgrp[e] = c->ngrp - 1;
        }
        c->gfirst[c->ngrp] = c->nroot;
        /* Their patches: [gpatch[g], gpatch[g + 1]). */
        if (!(c->gpatch = malloc(sizeof(int) * (size_t)(c->ngrp + 1)))) goto nomem;
        for (int g = 0; g < c->ngrp; g++) c->gpatch[g] = c->el[c->gfirst[g]].patch;
        c->gpatch[c->ngrp] = c->npatches;
        if (!(c->gpoly = malloc(sizeof(int32_t) * (size_t)(c->ngrp ? c->ngrp : 1)))) goto nomem;
        for (int g = 0; g < c->ngrp; g++) c->gpoly[g] = c->patches[c->gpatch[g]].pc.poly;
        for (int g = 0; g < c->ngrp; g++)
            if ((size_t)(c->gfirst[g + 1] - c->gfirst[g]) > maxg) maxg = (size_t)(c->gfirst[g + 1] - c->gfirst[g]);
        if (!(c->scw = malloc(sizeof *c->scw * 2 * maxg * (size_t)c->nsub))) goto nomem;
        if (!(c->glist = malloc(sizeof(int) * (size_t)(c->ngrp ? c->ngrp : 1)))) goto nomem;
        c->gtouched = calloc((size_t)(c->ngrp ? c->ngrp : 1), 1);
        c->gpow = calloc((size_t)(c->ngrp ? c->ngrp : 1), sizeof *c->gpow);
        if (!c->gtouched || !c->gpow) goto nomem;
        for (int e = 0; e < c->nroot; e++) {
            const rad_elem *x = &c->el[e];
            for (int a = 0; a < c->side; a++)
                for (int b = 0; b < c->side; b++) {
                    size_t k = (size_t)e * (size_t)c->nsub + (size_t)(a * c->side + b);
                    rad_poly poly;
                    c->sca[k] = 0;
                    c->scl[k] = e;
                    memset(c->scc[k], 0, sizeof c->scc[k]);
                    if (rad_elem_polygon(&c->patches[x->patch].pc, c->fine, x->gi * c->side + a,
                                         x->gj * c->side + b, &poly) >= 3)
                        c->sca[k] = rad_poly_area(&poly, NULL, c->scc[k]);
                }
        }
    }
    int maxnb = vw_decomp_max_neighbours(d);
    for (int f = 0; f < 6; f++) {
        int *ids = malloc(sizeof(int) * (size_t)(maxnb > 0 ? maxnb : 1));
        if (!ids) goto nomem;
        int k = vw_decomp_neighbours(d, c->cell, f, ids, maxnb);
        c->nnb[f] = k < maxnb ? k : maxnb;
        c->nb[f] = ids;
        if (!(c->nbbox[f] = malloc(sizeof(vw_box) * (size_t)(c->nnb[f] ? c->nnb[f] : 1)))) goto nomem;
        for (int i = 0; i < c->nnb[f]; i++) c->nbbox[f][i] = vw_decomp_cell_box(d, ids[i]);
    }
    if (!(c->pvis = malloc((size_t)(c->npatches ? c->npatches : 1)))) goto nomem;
    *state = c;
    return VW_OK;
nomem: /* the build frees what it made (the runtime calls no cell_free for it) */
    cell_free(c, S);
    return VW_E_NOMEM;
}

static void cell_free(void *state, void *user)
{
    rad_cell *c = state;
    (void)user;
    if (!c) return;
    for (int f = 0; f < 6; f++) free(c->nb[f]), free(c->nbbox[f]);
    for (int i = 0; i < c->cappend; i++) free(c->pend[i].bits); /* spare buffers too */
    free(c->pend);
    free(c->patches), free(c->el), free(c->vp), free(c->ht);
    free(c->mask), free(c->touched);
    free(c->pvis), free(c->hv);
    free(c->scc), free(c->sca), free(c->sci), free(c->scl), free(c->scw);
    free(c->gfirst), free(c->gpatch), free(c->gpoly), free(c->rgrp), free(c->glist), free(c->gtouched), free(c->gpow);
    free(c);
}

static double cell_load(vw_ctx *ctx, void *state)
{
    rad_cell *c = state;
    (void)ctx;
    return (double)c->nel;
}

/* ---- reporting ---- */

static void report(vw_ctx *ctx, rad_cell *c, int round)
{
    rad_report_msg r;
    memset(&r, 0, sizeof r);
    r.round = round;
    r.cell = c->cell;
    r.nshots = c->nshots;
    for (int p = 0; p < c->npatches; p++) {
        double u = patch_unshot(&c->patches[p]);
        if (u > r.max_unshot) r.max_unshot = u;
        for (int k = 0; k < 3; k++) r.unshot[k] += c->patches[p].unshot[k];
    }
    memcpy(r.absorbed, c->absorbed, sizeof r.absorbed);
    memcpy(r.shot, c->shot, sizeof r.shot);
    memcpy(r.won, c->won, sizeof r.won);
    vw_send_output(ctx, RAD_K_REPORT, &r);
}

/* The first message of a new round reports the state the previous round left: every
   shot of that round had ended when it did (run() returns at quiescence). */
static void enter_round(vw_ctx *ctx, rad_cell *c, int round)
{
    if (round > c->round) {
        report(ctx, c, round);
        c->round = round;
    }
}

/* ---- shots ---- */

/* Keeps the cell's flag in S->stepwork: whether step() may find work (a shot ready, or
   budget left and a patch to shoot). Called wherever nready or budget changes. A cell
   without patches keeps its budget all round long while its worker has shots ready (so
   step() does not clear it), and most cells of a fine layout have none. */
static void note_work(rad_cell *c)
{
    c->S->stepwork[c->cell] = c->nready > 0 || (c->budget > 0 && c->npatches > 0);
}

/* The number of the lowest set bit of x (x != 0). */
static int ctz64(uint64_t x)
{
#if defined(__GNUC__)
    return __builtin_ctzll(x);
#else
    int n = 0;
    for (; !(x & 1); x >>= 1) n++;
    return n;
#endif
}

/* The calling worker's scratch for rasterising a shot (see rad_worker_slot), or NULL
   when it cannot be had (the run has failed). */
static rad_worker_slot *scratch(vw_ctx *ctx, const rad_cell *c)
{
    rad_worker_slot *sl = &c->S->slots[vw_ctx_worker(ctx)];
    size_t np = (size_t)c->S->hc.npix;
    if (!sl->z.depth) {
        /* All four or none: the z-buffer is known to be there by its depth. */
        double *depth = grow(ctx, NULL, sizeof(double) * np);
        int32_t *owner = depth ? grow(ctx, NULL, sizeof(int32_t) * np) : NULL;
        uint32_t *stamp = owner ? grow(ctx, NULL, sizeof(uint32_t) * np) : NULL;
        uint64_t *written = stamp ? grow(ctx, NULL, sizeof(uint64_t) * ((np + 63) / 64)) : NULL;
        if (!written) {
            free(depth), free(owner), free(stamp);
            return NULL;
        }
        memset(stamp, 0, sizeof(uint32_t) * np);
        memset(written, 0, sizeof(uint64_t) * ((np + 63) / 64));
        sl->z.depth = depth, sl->z.owner = owner, sl->z.stamp = stamp, sl->z.written = written;
        sl->z.cur = 0;
    }
    if (c->fine && !sl->pcls && !(sl->pcls = grow(ctx, NULL, sizeof(int) * np))) return NULL;
    return sl;
}

/* Forwards the shot across every face whose neighbours are downstream and take part. */
static void forward(vw_ctx *ctx, rad_cell *c, const rad_shot_hdr *h, const double q[3],
                    const double v[3], const uint8_t *bits, int full)
{
    rad_solver *S = c->S;
    vw_box own = vw_ctx_cell_box(ctx);
    unsigned char *buf = NULL;
    if (!full) {
        if (!(buf = grow(ctx, NULL, sizeof *h + S->bitmap_bytes))) return;
        memcpy(buf, h, sizeof *h);
        memcpy(buf + sizeof *h, bits, S->bitmap_bytes);
    }
    for (int f = 0; f < 6; f++) {
        if (!c->nnb[f] || upstream(&own, f, q, v)) continue;
        for (int i = 0; i < c->nnb[f]; i++) {
            if (!in_range(&c->nbbox[f][i], q, v, S->opt.neighbourhood)) continue;
            if (full) {
                vw_send_cell(ctx, c->nb[f][i], RAD_K_FULL, h);
                vw_count(ctx, RAD_C_FULL_MSGS, 1);
            } else {
                vw_send_cell(ctx, c->nb[f][i], RAD_K_SHOT, buf);
                vw_count(ctx, RAD_C_SHOT_MSGS, 1);
                vw_count(ctx, RAD_C_SHOT_BYTES, (int64_t)(sizeof *h + S->bitmap_bytes));
            }
        }
    }
    free(buf);
}

/* Does segment p + t r, 0 < t < 1, pass through piece pc? */
static int seg_hits(const rad_piece *pc, const double p[3], const double r[3])
{
    double dn = rad_dot(r, pc->normal), v0[3];
    if (dn == 0) return 0;
    rad_sub(pc->v[0], p, v0);
    double t = rad_dot(v0, pc->normal) / dn;
    if (!(t > 1e-9 && t < 1 - 1e-9)) return 0;
    double x[3];
    for (int k = 0; k < 3; k++) x[k] = p[k] + t * r[k];
    for (int i = 0; i < pc->nv; i++) {
        double e[3], d[3], cx[3];
        rad_sub(pc->v[(i + 1) % pc->nv], pc->v[i], e);
        rad_sub(x, pc->v[i], d);
        rad_cross(e, d, cx);
        if (rad_dot(cx, pc->normal) < 0) return 0;
    }
    return 1;
}

/* How visible the point p + r (hemicube coordinates hv) of group g is from the shooter
   at p in the current shot, in [0, 1]. Occluders of this cell are tested exactly: every
   other polygon owning the point's pixel or one of its 8 neighbours on that face is
   intersected piece by piece (its pieces in this cell), so this visibility is per point,
   not per pixel. Occluders of other cells are known only as the bits set upstream: they
   are filtered bilinearly between pixel centres, so their edges become a ramp one pixel
   wide rather than a step on the pixel grid that shows as blotches on grazing faces. */
static double visible(rad_cell *c, const double p[3], const double r[3], const double hv[3],
                      const double (*ax)[3], int g)
{
    const rad_hemicube *hc = &c->S->hc;
    const int R = hc->res;
    double fxy[2];
    int px = rad_hemicube_pixel(hc, hv, fxy);
    if (px < 0) return 1;
    int base, rows;
    if (px < R * R) base = 0, rows = R;
    else base = R * R + (px - R * R) / (R * R / 2) * (R * R / 2), rows = R / 2;
    int pi = (px - base) % R, pj = (px - base) / R;
    int seen[9], nseen = 0;
    for (int dj = -1; dj <= 1; dj++)
        for (int di = -1; di <= 1; di++) {
            int i = pi + di, j = pj + dj;
            if (i < 0 || i >= R || j < 0 || j >= rows) continue;
            int o = c->pcls[base + j * R + i];
            if (o < 0 || o == g || c->gpoly[o] == c->gpoly[g]) continue;
            int k;
            for (k = 0; k < nseen && seen[k] != o; k++) {}
            if (k < nseen) continue;
            seen[nseen++] = o;
            for (int pt = c->gpatch[o]; pt < c->gpatch[o + 1]; pt++)
                if (seg_hits(&c->patches[pt].pc, p, r)) return 0;
        }
    double cx = fxy[0] - 0.5, cy = fxy[1] - 0.5, blocked = 0, known = 0;
    int i0 = (int)floor(cx), j0 = (int)floor(cy);
    double fx = cx - i0, fy = cy - j0;
    const rad_piece *own = &c->patches[c->gpatch[g]].pc;
    for (int k = 0; k < 4; k++) {
        int i = i0 + (k & 1), j = j0 + (k >> 1);
        i = i < 0 ? 0 : i > R - 1 ? R - 1 : i;
        j = j < 0 ? 0 : j > rows - 1 ? rows - 1 : j;
        double wk = (k & 1 ? fx : 1 - fx) * (k >> 1 ? fy : 1 - fy);
        if (c->pcls[base + j * R + i] != RAD_PX_UPSTREAM) {
            known += wk;
            continue;
        }
        /* A pixel set upstream hides this polygon only if its ray meets the polygon's
           plane inside this cell: beyond the cell it may be the polygon's own
           continuation, set by the cell that holds it, which hides nothing. */
        double d[3], dw[3], v0[3], x[3], fr[3];
        rad_hemicube_pixel_dir(hc, base + j * R + i, d);
        for (int a = 0; a < 3; a++) dw[a] = d[0] * ax[0][a] + d[1] * ax[1][a] + d[2] * ax[2][a];
        double dn = rad_dot(dw, own->normal);
        rad_sub(own->v[0], p, v0);
        double t = dn != 0 ? rad_dot(v0, own->normal) / dn : -1;
        if (!(t > 0)) continue;
        for (int a = 0; a < 3; a++) x[a] = p[a] + t * dw[a];
        vw_decomp_to_frame(c->S->d, x, fr);
        if (fr[0] < c->box.lo[0] || fr[0] > c->box.hi[0] || fr[1] < c->box.lo[1] || fr[1] > c->box.hi[1] ||
            fr[2] < c->box.lo[2] || fr[2] > c->box.hi[2])
            continue;
        known += wk, blocked += wk;
    }
    return known > 0 ? 1 - blocked / known : 1;
}

/* Is level-0 element e wholly clear of occluders in the current shot? True when its
   vertices project onto one face and every pixel of their bounding box, widened by
   visible()'s one-pixel reach, holds its own polygon or nothing: then visible() would
   return 1 for each of its fine cells, and is skipped (most elements, most shots). */
static int unobstructed(rad_cell *c, int e, const double p[3], const double (*ax)[3], int g)
{
    const rad_hemicube *hc = &c->S->hc;
    const int R = hc->res;
    const rad_elem *x = &c->el[e];
    int face = -1, i0 = R, i1 = -1, j0 = R, j1 = -1;
    for (int v = 0; v < x->nv; v++) {
        double r[3], hv[3], fxy[2];
        rad_sub(c->vp[x->vfirst + v], p, r);
        for (int k = 0; k < 3; k++) hv[k] = rad_dot(r, ax[k]);
        int px = rad_hemicube_pixel(hc, hv, fxy);
        if (px < 0) return 0;
        int f = px < R * R ? 0 : 1 + (px - R * R) / (R * R / 2);
        if (face >= 0 && f != face) return 0;
        face = f;
        int i = (int)floor(fxy[0]), j = (int)floor(fxy[1]);
        i0 = i < i0 ? i : i0, i1 = i > i1 ? i : i1, j0 = j < j0 ? j : j0, j1 = j > j1 ? j : j1;
    }
    int rows = face == 0 ? R : R / 2, base = face == 0 ? 0 : R * R + (face - 1) * (R * R / 2);
    i0 = i0 - 1 < 0 ? 0 : i0 - 1, j0 = j0 - 1 < 0 ? 0 : j0 - 1;
    i1 = i1 + 1 > R - 1 ? R - 1 : i1 + 1, j1 = j1 + 1 > rows - 1 ? rows - 1 : j1 + 1;
    if ((i1 - i0 + 1) * (j1 - j0 + 1) > 1024) return 0;
    for (int j = j0; j <= j1; j++)
        for (int i = i0; i <= i1; i++) {
            int o = c->pcls[base + j * R + i];
            if (o == RAD_PX_UPSTREAM || (o >= 0 && o != g && c->gpoly[o] != c->gpoly[g])) return 0;
        }
    return 1;
}

/* Shares the power gpow[g] that the level-0 elements of group g (one polygon's, in this
   cell) won in this shot among all the group's fine cells, in proportion to area x
   point form factor (cos cos / r^2 at the cell's centroid) x visibility, and adds each
   share to the fine cell, the live leaf over it and its patch's unshot power.
   Visibility of a centroid: the pixel its direction falls in is clear (visible), set
   upstream (another cell's occluder: hidden), or won here by a piece whose plane the
   segment from the shooter crosses before the centroid (hidden; an element of the same
   polygon cannot hide it). If no centroid is visible the shares follow form factors
   alone, then area.
   Why a whole polygon: the pixels a small element wins alias (a grazing face gets 0, 1
   or 2 pixels from shot to shot), the pixels a polygon wins do not; the point form
   factors then place the power smoothly, and the point visibility sharply.
   The ledger stays exact: the shares sum to what the pixels won (normalised weights;
   rounding only), each share goes to absorbed and unshot as rho and 1 - rho, and the
   hemicube decides, as without subdivision, how much the polygon receives. */
static void distribute(rad_cell *c, int g, const rad_shot_hdr *h, const double (*ax)[3])
{
    int r0 = c->gfirst[g], r1 = c->gfirst[g + 1];
    size_t base = (size_t)r0 * (size_t)c->nsub, n = (size_t)(r1 - r0) * (size_t)c->nsub;
    double W = 0, Wff = 0, Wa = 0;
    double *w = c->scw, *wf = c->scw + n;
    for (int e = r0; e < r1; e++) {
        const rad_elem *x = &c->el[e];
        const rad_piece *pc = &c->patches[x->patch].pc;
        int pure = c->pvis[x->patch] && unobstructed(c, e, h->p, ax, g);
        for (int s = 0; s < c->nsub; s++) {
            size_t k = (size_t)e * (size_t)c->nsub + (size_t)s, l = k - base;
            w[l] = wf[l] = 0;
            double A = c->sca[k];
            if (!(A > 0)) continue;
            Wa += A;
            if (!c->pvis[x->patch]) continue;
            double r[3], hv[3];
            rad_sub(c->scc[k], h->p, r);
            for (int i = 0; i < 3; i++) hv[i] = rad_dot(r, ax[i]);
            double d2 = rad_dot(r, r), cr = -rad_dot(r, pc->normal);
            if (!(hv[2] > 0) || !(cr > 0) || !(d2 > 0)) continue;
            double ff = A * hv[2] * cr / (d2 * d2);
            wf[l] = ff, Wff += ff;
            double vis = pure ? 1 : visible(c, h->p, r, hv, ax, g);
            if (vis > 0) w[l] = ff * vis, W += ff * vis;
        }
    }
    const double *wt = W > 0 ? w : Wff > 0 ? wf : NULL;
    double tot = W > 0 ? W : Wff > 0 ? Wff : Wa;
    const double *P = c->gpow[g];
    if (!(tot > 0)) {
        /* Nothing to share by (no area at all): the power is absorbed. */
        for (int ch = 0; ch < 3; ch++) c->absorbed[ch] += P[ch];
        memset(c->gpow[g], 0, sizeof c->gpow[g]);
        return;
    }
    for (int e = r0; e < r1; e++) {
        const rad_elem *x = &c->el[e];
        rad_patch *pt = &c->patches[x->patch];
        const rad_piece *pc = &pt->pc;
        for (int s = 0; s < c->nsub; s++) {
            size_t k = (size_t)e * (size_t)c->nsub + (size_t)s;
            double f = (wt ? wt[k - base] : c->sca[k]) / tot;
            if (!(f > 0)) continue;
            rad_elem *leaf = &c->el[c->scl[k]];
            for (int ch = 0; ch < 3; ch++) {
                double inc = f * P[ch], refl = pc->rho[ch] * inc;
                c->sci[k][ch] += inc;
                leaf->incident[ch] += inc;
                leaf->B[ch] += refl / leaf->area;
                pt->unshot[ch] += refl;
                c->absorbed[ch] += inc - refl;
            }
        }
    }
    memset(c->gpow[g], 0, sizeof c->gpow[g]);
}

/* Projects this cell's elements onto the pixels still clear in mask (which it updates),
   deposits the power of the pixels won, and forwards the merged bitmap. */
static void process_shot(vw_ctx *ctx, rad_cell *c, const rad_shot_hdr *h, uint8_t *mask, int full)
{
    rad_solver *S = c->S;
    const vw_decomp *d = vw_ctx_decomp(ctx);
    double q[3], v[3];
    vw_decomp_to_frame(d, h->p, q);
    vw_decomp_to_frame(d, h->n, v);
    const rad_hemicube *hc = &S->hc;
    if (!full && c->nel > 0) {
        rad_worker_slot *sl = scratch(ctx, c);
        if (!sl) return;
        rad_zbuf *z = &sl->z;
        c->pcls = sl->pcls;
        if (++z->cur == 0) {
            memset(z->stamp, 0, sizeof(uint32_t) * (size_t)hc->npix);
            z->cur = 1;
        }
        double ax[3][3], vv[3];
        memcpy(ax[0], h->u, sizeof vv);
        rad_cross(h->n, h->u, ax[1]);
        memcpy(ax[2], h->n, sizeof vv);
        const double eps = S->near_eps;
        /* Patches wholly behind (or in) the shooter plane cannot be seen. */
        for (int p = 0; p < c->npatches; p++) {
            const rad_piece *pc = &c->patches[p].pc;
            c->pvis[p] = 0;
            if (pc->id == h->piece) continue;
            for (int i = 0; i < pc->nv && !c->pvis[p]; i++) {
                double r[3];
                rad_sub(pc->v[i], h->p, r);
                c->pvis[p] = rad_dot(r, h->n) > eps;
            }
        }
        if (!c->hv && !(c->hv = grow(ctx, NULL, sizeof(double) * 3 * RAD_MAXV))) return;
        int64_t nr = 0;
        /* With fine cells only the level-0 elements are rasterised, split or not: every
           shot then wins the same pixels as without subdivision (no receiver smaller
           than a pixel), and distribute() shares them out. */
        int nrast = c->fine ? c->nroot : c->nel;
        for (int e = 0; e < nrast; e++) {
            const rad_elem *x = &c->el[e];
            if ((!c->fine && !x->alive) || !c->pvis[x->patch]) continue;
            int front = 0;
            for (int i = 0; i < x->nv; i++) {
                double r[3];
                rad_sub(c->vp[x->vfirst + i], h->p, r);
                for (int k = 0; k < 3; k++) c->hv[i][k] = rad_dot(r, ax[k]);
                front |= c->hv[i][2] > eps;
            }
            if (!front) continue;
            rad_hemicube_raster(hc, (const double(*)[3])c->hv, x->nv, mask, z, e, eps);
            nr++;
        }
        vw_count(ctx, RAD_C_RASTER, nr);
        /* Deposit: every pixel won goes to its nearest element. The pixels written are
           visited in increasing order, as a scan of all npix would (the same sums), but
           a cell that sees a few elements no longer pays for the whole hemicube: with
           many cells that scan was a third of the solve. */
        if (!c->touched) c->touched = NULL;
        int ntouched = 0, captouched = 0;
        for (int wd = 0; wd < (hc->npix + 63) / 64; wd++) {
            for (uint64_t bits = z->written[wd]; bits; bits &= bits - 1) {
                int px = wd * 64 + ctz64(bits);
                rad_elem *x = &c->el[z->owner[px]];
                if (x->won == 0) {
                    if (ntouched == captouched) {
                        captouched = captouched ? 2 * captouched : 256;
                        int *t = grow(ctx, c->touched, sizeof(int) * (size_t)captouched);
                        if (!t) return;
                        c->touched = t;
                    }
                    c->touched[ntouched++] = z->owner[px];
                }
                x->won += hc->dff[px];
                mask[px >> 3] |= (uint8_t)(1u << (px & 7));
            }
            z->written[wd] = 0;
        }
        int64_t back = 0;
        for (int t = 0; t < ntouched; t++) {
            rad_elem *x = &c->el[c->touched[t]];
            rad_patch *pt = &c->patches[x->patch];
            double r[3];
            rad_sub(h->p, c->vp[x->vfirst], r);
            int facing = rad_dot(r, pt->pc.normal) > 0;
            int g = c->fine && facing ? c->rgrp[c->touched[t]] : -1;
            if (g >= 0 && !c->gtouched[g]) c->gtouched[g] = 1, c->glist[c->nglist++] = g;
            for (int k = 0; k < 3; k++) {
                double P = x->won * h->power[k];
                c->won[k] += P;
                if (g >= 0) {
                    c->gpow[g][k] += P; /* shared out by distribute() below */
                } else if (facing) {
                    double refl = pt->pc.rho[k] * P;
                    x->B[k] += refl / x->area;
                    x->incident[k] += P;
                    pt->unshot[k] += refl;
                    c->absorbed[k] += P - refl;
                } else {
                    /* The back of a one-sided polygon is black: it absorbs. */
                    c->absorbed[k] += P;
                }
            }
            back += !facing;
            x->won = 0;
        }
        if (c->nglist) {
            /* Who holds each pixel, for visible(): a group of this cell, upstream, clear. */
            for (int px = 0; px < hc->npix; px++)
                c->pcls[px] = z->stamp[px] == z->cur ? c->rgrp[c->el[z->owner[px]].root]
                              : mask[px >> 3] >> (px & 7) & 1 ? RAD_PX_UPSTREAM : RAD_PX_CLEAR;
        }
        for (int i = 0; i < c->nglist; i++) {
            int g = c->glist[i];
            distribute(c, g, h, (const double(*)[3])ax);
            c->gtouched[g] = 0;
        }
        c->nglist = 0;
        if (back) vw_count(ctx, RAD_C_BACK_HITS, back);
        full = 1;
        for (size_t b = 0; b < S->bitmap_bytes && full; b++) {
            uint8_t want = 0xff;
            if (b == S->bitmap_bytes - 1 && (hc->npix & 7)) want = (uint8_t)((1u << (hc->npix & 7)) - 1);
            full = (mask[b] & want) == want;
        }
    }
    forward(ctx, c, h, q, v, mask, full);
}

/* A bitmap (or a "full" notice) from an upstream neighbour. */
static void on_shot_common(vw_ctx *ctx, rad_cell *c, const rad_shot_hdr *h, const uint8_t *bits)
{
    rad_solver *S = c->S;
    enter_round(ctx, c, h->round);
    int k;
    for (k = 0; k < c->npend; k++)
        if (c->pend[k].id == h->id) break;
    if (k == c->npend) {
        if (c->npend == c->cappend) {
            int cap = c->cappend ? 2 * c->cappend : 8;
            rad_pend *pend = grow(ctx, c->pend, sizeof *c->pend * (size_t)cap);
            if (!pend) return;
            c->pend = pend;
            for (int i = c->cappend; i < cap; i++) c->pend[i].bits = NULL;
            c->cappend = cap;
        }
        if (!c->pend[c->npend].bits && !(c->pend[c->npend].bits = grow(ctx, NULL, S->bitmap_bytes)))
            return;
        rad_pend *pd = &c->pend[c->npend++];
        pd->id = h->id;
        pd->h = *h;
        pd->received = 0;
        pd->full = 0;
        pd->ready = 0;
        memset(pd->bits, 0, S->bitmap_bytes);
        /* How many bitmaps to wait for: the participating upstream neighbours. */
        const vw_decomp *d = vw_ctx_decomp(ctx);
        double q[3], v[3];
        vw_decomp_to_frame(d, h->p, q);
        vw_decomp_to_frame(d, h->n, v);
        vw_box own = vw_ctx_cell_box(ctx);
        int expected = 0;
        for (int f = 0; f < 6; f++) {
            if (!c->nnb[f] || !upstream(&own, f, q, v)) continue;
            for (int i = 0; i < c->nnb[f]; i++)
                expected += c->nb[f][i] == h->src_cell ||
                            in_range(&c->nbbox[f][i], q, v, S->opt.neighbourhood);
        }
        pd->expected = expected > 0 ? expected : 1;
    }
    rad_pend *pd = &c->pend[k];
    if (bits) {
        /* By 64-bit words: byte by byte (the compiler cannot tell the two buffers apart)
           this merge was 15 % of a solve on 16x16x16 cells. */
        uint8_t *dst = pd->bits;
        const size_t nb = S->bitmap_bytes;
        size_t b = 0;
        for (; b + 8 <= nb; b += 8) {
            uint64_t x, y;
            memcpy(&x, dst + b, 8);
            memcpy(&y, bits + b, 8);
            x |= y;
            memcpy(dst + b, &x, 8);
        }
        for (; b < nb; b++) dst[b] |= bits[b];
    } else {
        pd->full = 1;
    }
    if (++pd->received < pd->expected) return;
    /* Ready: rasterised by step(), not here (see run_ready). */
    pd->ready = ++c->readyseq;
    c->nready++;
    note_work(c);
    S->slots[vw_ctx_worker(ctx)].ready++;
}

/* Rasterises the pending shot that became ready first, and forwards it.
   Why from step() and not from the handler of the last bitmap: the runtime flushes a
   worker's outgoing packets only when its inbox is empty (or a packet is full), and
   step() runs only then. A worker rasterising shot after shot straight from a long inbox
   held the bitmaps it made for the other worker for many rasterisations, while that
   worker idled waiting for them: on the room (2x2x2, 2 workers) 0.8-1.1 s of each
   worker's 2.1 s of idle time was such a bitmap, made but not yet sent (0.05 s now).
   Handlers now only merge bitmaps, and every rasterisation is followed by a flush. */
static void run_ready(vw_ctx *ctx, rad_cell *c)
{
    int k = -1;
    for (int i = 0; i < c->npend; i++)
        if (c->pend[i].ready && (k < 0 || c->pend[i].ready < c->pend[k].ready)) k = i;
    rad_pend *pd = &c->pend[k];
    c->nready--;
    note_work(c);
    c->S->slots[vw_ctx_worker(ctx)].ready--;
    process_shot(ctx, c, &pd->h, pd->bits, pd->full);
    /* Swap-remove, keeping the bitmap buffers for reuse. */
    uint8_t *keep = pd->bits;
    *pd = c->pend[--c->npend];
    c->pend[c->npend].bits = keep;
}

static void on_shot(vw_ctx *ctx, void *state, const void *msg)
{
    const rad_shot_hdr *h = msg;
    on_shot_common(ctx, state, h, (const uint8_t *)msg + sizeof *h);
}

static void on_full(vw_ctx *ctx, void *state, const void *msg)
{
    on_shot_common(ctx, state, msg, NULL);
}

/* Rasterises a shot that holds all its bitmaps, if this cell has one; else shoots this
   cell's patch of largest unshot power, while the round's budget lasts and no other cell
   of this worker has a shot ready (shots in flight first: the runtime asks every cell of
   the worker in turn, so that cell is asked before the worker could go idle). */
static int step(vw_ctx *ctx, void *state)
{
    /* The flag first, not the cell: the runtime asks every cell of the worker whenever
       its inbox runs dry, and most have nothing to do. */
    const rad_solver *S = vw_ctx_user(ctx);
    if (!S->stepwork[vw_ctx_cell(ctx)]) return 0;
    rad_cell *c = state;
    if (c->nready > 0) {
        run_ready(ctx, c);
        return 1;
    }
    if (c->budget <= 0 || c->S->slots[vw_ctx_worker(ctx)].ready > 0) return 0;
    int best = -1;
    double bu = c->thr;
    for (int p = 0; p < c->npatches; p++) {
        double u = patch_unshot(&c->patches[p]);
        if (u > bu) bu = u, best = p;
    }
    if (best < 0) {
        c->budget = 0;
        note_work(c);
        return 0;
    }
    rad_patch *pt = &c->patches[best];
    rad_shot_hdr h;
    memset(&h, 0, sizeof h);
    memcpy(h.p, pt->pc.centroid, sizeof h.p);
    memcpy(h.n, pt->pc.normal, sizeof h.n);
    memcpy(h.power, pt->unshot, sizeof h.power);
    h.id = ((uint64_t)c->cell << 40) | c->seq++;
    h.piece = pt->pc.id;
    h.src_cell = c->cell;
    h.round = c->round;
    rad_hemicube_orientation(h.n, rad_shot_seed(pt->pc.id, pt->nshots), h.u);
    for (int k = 0; k < 3; k++) {
        c->shot[k] += pt->unshot[k];
        pt->unshot[k] = 0;
    }
    pt->nshots++;
    c->nshots++;
    c->budget--;
    note_work(c);
    vw_count(ctx, RAD_C_SHOTS, 1);
    if (!c->mask && !(c->mask = grow(ctx, NULL, c->S->bitmap_bytes))) return 0;
    memset(c->mask, 0, c->S->bitmap_bytes);
    process_shot(ctx, c, &h, c->mask, 0);
    return 1;
}

/* ---- control messages ---- */

static void on_go(vw_ctx *ctx, void *state, const void *msg)
{
    rad_cell *c = state;
    const rad_go_msg *g = msg;
    enter_round(ctx, c, g->round);
    if (g->sub_rel > 0) subdivide(ctx, c, g->sub_rel, g->sub_floor, g->max_level);
    c->budget = g->budget;
    c->thr = g->thr;
    note_work(c);
}

static void on_collect(vw_ctx *ctx, void *state, const void *msg)
{
    rad_cell *c = state;
    (void)msg;
    report(ctx, c, c->round);
    for (int p = 0; p < c->npatches; p++) {
        rad_patch_result r;
        memset(&r, 0, sizeof r);
        r.piece = c->patches[p].pc.id;
        r.nshots = c->patches[p].nshots;
        memcpy(r.unshot, c->patches[p].unshot, sizeof r.unshot);
        vw_send_output(ctx, RAD_K_PATCH_OUT, &r);
    }
    for (int e = 0; e < c->nel; e++) {
        const rad_elem *x = &c->el[e];
        if (!x->alive) continue;
        rad_elem_result r;
        memset(&r, 0, sizeof r);
        r.piece = c->patches[x->patch].pc.id;
        r.poly = c->patches[x->patch].pc.poly;
        r.level = x->level, r.gi = x->gi, r.gj = x->gj;
        r.area = x->area;
        memcpy(r.B, x->B, sizeof r.B);
        memcpy(r.incident, x->incident, sizeof r.incident);
        vw_send_output(ctx, RAD_K_ELEM_OUT, &r);
    }
}

static int find_patch(const rad_cell *c, int64_t piece)
{
    int lo = 0, hi = c->npatches - 1; /* patches are in mesh order, so sorted by id */
    while (lo <= hi) {
        int mid = (lo + hi) / 2;
        if (c->patches[mid].pc.id == piece) return mid;
        if (c->patches[mid].pc.id < piece) lo = mid + 1;
        else hi = mid - 1;
    }
    return -1;
}

static void on_restore_patch(vw_ctx *ctx, void *state, const void *msg)
{
    rad_cell *c = state;
    const rad_patch_result *r = msg;
    (void)ctx;
    int p = find_patch(c, r->piece);
    if (p < 0) return;
    memcpy(c->patches[p].unshot, r->unshot, sizeof r->unshot);
    c->patches[p].nshots = r->nshots;
}

static void on_restore_elem(vw_ctx *ctx, void *state, const void *msg)
{
    rad_cell *c = state;
    const rad_elem_result *r = msg;
    (void)ctx;
    if (find_patch(c, r->piece) < 0) return;
    for (;;) {
        int e = ht_find(c, r->poly, r->piece, r->level, r->gi, r->gj, 1);
        if (e >= 0) {
            rad_elem *x = &c->el[e];
            memcpy(x->B, r->B, sizeof r->B);
            memcpy(x->incident, r->incident, sizeof r->incident);
            if (c->fine) {
                /* A checkpoint holds leaves only: their power is spread over their fine
                   cells by area (the detail inside a leaf is not saved). */
                int a0, b0, w;
                double A;
                fine_range(c, x, &a0, &b0, &w);
                fine_sum(c, x, (double[3]){0, 0, 0}, &A);
                for (int a = a0; a < a0 + w; a++)
                    for (int b = b0; b < b0 + w; b++) {
                        size_t k = (size_t)x->root * (size_t)c->nsub + (size_t)(a * c->side + b);
                        for (int ch = 0; ch < 3; ch++) c->sci[k][ch] = A > 0 ? r->incident[ch] * c->sca[k] / A : 0;
                    }
            }
            return;
        }
        /* Not there yet: split the finest live ancestor, then look again. */
        int a = -1;
        for (int l = r->level - 1; l >= 0 && a < 0; l--)
            a = ht_find(c, r->poly, r->piece, l, r->gi >> (r->level - l), r->gj >> (r->level - l), 1);
        if (a < 0 || split_elem(ctx, c, a) < 0) return;
    }
}

/* ---- output handlers (output process) ---- */

static void out_report(void *user, const void *msg)
{
    rad_solver *S = user;
    const rad_report_msg *r = msg;
    S->nreports++;
    S->rep.nshots += r->nshots;
    if (r->max_unshot > S->rep.max_unshot) S->rep.max_unshot = r->max_unshot;
    for (int k = 0; k < 3; k++) {
        S->rep.unshot[k] += r->unshot[k];
        S->rep.absorbed[k] += r->absorbed[k];
        S->rep.shot[k] += r->shot[k];
        S->rep.won[k] += r->won[k];
    }
}

/* Appends a record of `size` bytes to the collect's array a (*n of *cap used) and
   returns the array, moved or not. An output handler has no context to fail the run
   with, so a record that finds no room is counted in S->collect_nomem, and
   rad_solver_collect fails. */
static void *collect_into(rad_solver *S, void *a, size_t *n, size_t *cap, size_t size,
                          const void *msg)
{
    if (S->collect_nomem) return a;
    if (*n == *cap) {
        size_t ncap = *cap ? 2 * *cap : 1024;
        void *q = S->fault_collect_nomem ? NULL : realloc(a, ncap * size);
        if (!q) {
            S->collect_nomem = ncap * size;
            return a;
        }
        a = q;
        *cap = ncap;
    }
    memcpy((unsigned char *)a + (*n)++ * size, msg, size);
    return a;
}

static void out_patch(void *user, const void *msg)
{
    rad_solver *S = user;
    S->patches = collect_into(S, S->patches, &S->npatches, &S->cappatches, sizeof *S->patches, msg);
}

static void out_elem(void *user, const void *msg)
{
    rad_solver *S = user;
    S->elems = collect_into(S, S->elems, &S->nelems, &S->capelems, sizeof *S->elems, msg);
}

void rad_module_setup(rad_solver *s)
{
    vw_msg_kind *k = s->kinds;
    memset(k, 0, sizeof s->kinds);
    k[RAD_K_GO] = (vw_msg_kind){"go", sizeof(rad_go_msg), on_go, NULL};
    k[RAD_K_SHOT] = (vw_msg_kind){"shot", sizeof(rad_shot_hdr) + s->bitmap_bytes, on_shot, NULL};
    k[RAD_K_FULL] = (vw_msg_kind){"shot_full", sizeof(rad_shot_hdr), on_full, NULL};
    k[RAD_K_COLLECT] = (vw_msg_kind){"collect", sizeof(rad_collect_msg), on_collect, NULL};
    k[RAD_K_RESTORE_PATCH] = (vw_msg_kind){"restore_patch", sizeof(rad_patch_result), on_restore_patch, NULL};
    k[RAD_K_RESTORE_ELEM] = (vw_msg_kind){"restore_elem", sizeof(rad_elem_result), on_restore_elem, NULL};
    k[RAD_K_REPORT] = (vw_msg_kind){"report", sizeof(rad_report_msg), NULL, out_report};
    k[RAD_K_PATCH_OUT] = (vw_msg_kind){"patch_out", sizeof(rad_patch_result), NULL, out_patch};
    k[RAD_K_ELEM_OUT] = (vw_msg_kind){"elem_out", sizeof(rad_elem_result), NULL, out_elem};
    vw_module *m = &s->mod;
    memset(m, 0, sizeof *m);
    m->abi = VW_MODULE_ABI;
    m->name = "radiosity";
    m->object_size = sizeof(rad_piece);
    m->object_bounds = NULL; /* set by solve.c */
    m->kinds = s->kinds;
    m->nkinds = RAD_NKINDS;
    m->counters = rad_counter_names;
    m->ncounters = RAD_NCOUNTERS;
    m->cell_build = cell_build;
    m->cell_free = cell_free;
    m->step = step;
    m->load = cell_load;
}
