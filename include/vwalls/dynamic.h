/* vwalls/dynamic.h - the dynamic-scene handler: objects that move between cells, the
 * collision test at a move's destination and the swept test along its path, both run
 * distributed over the cells, and the edit language that drives them.
 *
 * Invariants:
 *  - every object keeps the global id it was given (scene file order; an added object
 *    gets the next unused id; a removed id is never reused);
 *  - after every accepted edit, each object is held by exactly the cells its bounds
 *    overlap (vw_world_update_object does the leaving and joining);
 *  - a move is decided as if edits were applied one at a time, in script order, even
 *    when a batch of them is probed in one distributed run.
 */
#ifndef VWALLS_DYNAMIC_H
#define VWALLS_DYNAMIC_H

#include <stdio.h>
#include "vwalls/common.h"
#include "vwalls/decomp.h"
#include "vwalls/scene.h"
#include "vwalls/world.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- shapes and the pairwise tests -------------------------------------------------- */

typedef enum vw_shape_kind {
    VW_SHAPE_NONE = 0,     /* an empty slot: collides with nothing, lies in no cell */
    VW_SHAPE_SPHERE = 1,   /* p[0] centre, r radius */
    VW_SHAPE_TRIANGLE = 2, /* p[0], p[1], p[2] */
    VW_SHAPE_BOX = 3       /* p[0] lo, p[1] hi: how cones are tested (conservative) */
} vw_shape_kind;

/* One collision primitive. An object may be several shapes (a polygon is a fan of
   triangles); they share the object's id and never collide with each other. */
typedef struct vw_shape {
    int32_t kind;      /* vw_shape_kind */
    int32_t id;        /* the object's global id */
    double p[3][3];
    double r;
} vw_shape;

/* Bounds of a shape, or of the volume it sweeps moving by d (d may be NULL). */
VW_API void vw_shape_bounds(const vw_shape *s, const double d[3], vw_box *out);

/* Do shapes a and b interpenetrate by more than tol? With d non-NULL, a is swept along
   the translation d (t in [0,1]) and the swept volume is tested.
   Touching (penetration <= tol) is not a collision, so objects that rest on each other
   may move apart; two coplanar triangles that overlap in their plane do collide.
   Exactness:
     sphere-sphere, sphere-triangle, triangle-triangle: exact (closed-form distance;
       triangle pairs by the separating axis theorem over face normals, edge-edge
       cross products and in-plane edge normals, which is complete for convex polytopes);
     swept sphere (capsule) vs sphere/triangle, swept triangle (prism, the convex hull
       of the triangle and its translate) vs triangle, and the reverse: exact;
     boxes (cones): the cone is replaced by its bounding box, and a sphere or capsule
       tested against a box is replaced by its own bounding box: conservative (may
       reject a move that misses by less than the boxes' slack, never accepts a hit). */
VW_API int vw_shape_collide(const vw_shape *a, const double d[3], const vw_shape *b, double tol);

/* ---- the distributed collider ------------------------------------------------------- */

/* A world of shapes over a decomposition, answering batches of probes with one
   distributed run: every probe is posted to the cells its (swept) destination bounds
   overlap; each cell tests it against the shapes it holds and reports contacts to every
   process (through one mailbox cell per process), so every process decides the same.
   No separate ghost exchange is needed: a shape overlapping a wall is held by the cells
   on both sides (the placement rule), so the cells a probe reaches hold every shape
   that can touch it. With more processes than cells (mpirun -np 2 on one cell) the
   collider divides its own copy of the decomposition until every process hosts a cell;
   vw_collider_world then reports that copy. */
typedef struct vw_collider vw_collider;

/* What a probe asks. The object `start` (all of whose shapes carry id) moves to `end`.
   VW_PROBE_END: test `end` against the others. VW_PROBE_SWEEP: also test the volume
   `start` sweeps along d (end must then be start translated by d). An obstacle that
   already interpenetrates `start` does not count for the sweep (so a resting object
   can be lifted off what it rests on), only for the end test: its contact says
   VW_PROBE_START instead; where a sphere is in the pair, only when the path takes it no
   deeper than it starts (one sunk a hair in a floor cannot go through it: that pair
   says VW_PROBE_THROUGH), and never where a box (a cone) is, whose box may hold the
   mover without touching the cone. The rule is the object's: a sweep that meets one
   shape of an obstacle whose other shape `start` interpenetrates (a floor of two
   triangles, the mover sunk in one) is no sweep hit either, but a path deeper into a
   shape it starts in is one, whatever the obstacle's other shapes say (a mover sunk in
   both triangles of a floor, going through one and away from the other). The contacts
   of one tag and obstacle are merged (their bits or'ed), so a caller counts a sweep hit
   where a contact has VW_PROBE_THROUGH, or VW_PROBE_SWEEP and not VW_PROBE_START. */
enum { VW_PROBE_END = 1, VW_PROBE_SWEEP = 2, VW_PROBE_START = 4, VW_PROBE_THROUGH = 8 };
typedef struct vw_probe {
    vw_shape start, end;
    double d[3];
    int32_t flags;
    int32_t tag;       /* the caller's number, returned in contacts */
} vw_probe;

typedef struct vw_contact {
    int32_t tag;       /* the probe's tag */
    int32_t obstacle;  /* the id of the object hit */
    int32_t how;       /* VW_PROBE_END, _SWEEP, _START, _THROUGH, or'ed */
    int32_t pad;
} vw_contact;

/* c may be NULL (defaults). tol: the contact tolerance of vw_shape_collide. Collective
   under MPI; memory one process lacks fails it on all (vw_config_agree). */
VW_API vw_status vw_collider_create(const vw_decomp *d, const vw_config *c, double tol,
                                    vw_collider **out);
VW_API void vw_collider_free(vw_collider *c);
/* Shapes get slots 0, 1, ... in the order added (like vw_world_add_objects). */
VW_API vw_status vw_collider_add(vw_collider *c, const vw_shape *s, size_t n);
/* Replaces slot `slot`; it migrates to the cells its new bounds overlap. */
VW_API vw_status vw_collider_update(vw_collider *c, size_t slot, const vw_shape *s);
/* New decomposition and mapping (after the balancer moved walls). */
VW_API vw_status vw_collider_redecompose(vw_collider *c, const vw_decomp *d,
                                         const int *cell_worker);
/* One distributed run for n probes. *out (malloc'ed, free with free()) gets the contacts,
   one per (tag, obstacle), sorted by tag then obstacle, identical on every process.
   Collective under MPI: every process passes the same probes. A failure (of the posting,
   the run or the room for *out) fails it on every process, with the same
   vw_collider_errmsg ("rank R: ..." under MPI). */
VW_API vw_status vw_collider_query(vw_collider *c, const vw_probe *probes, size_t n,
                                   vw_contact **out, size_t *nout);
/* Why the last vw_collider_query failed ("no error" when it did not). */
VW_API const char *vw_collider_errmsg(const vw_collider *c);
VW_API vw_world *vw_collider_world(vw_collider *c);

/* ---- the edit language (docs/edit-language.md) -------------------------------------- */

typedef enum vw_edit_op {
    VW_EDIT_NONE = 0,  /* blank line or comment */
    VW_EDIT_MOVE,      /* move ID dx dy dz */
    VW_EDIT_MOVETO,    /* moveto ID x y z        (the object's centre goes to x y z) */
    VW_EDIT_ROTATE,    /* rotate ID ax ay az DEG (about its centre, right-handed) */
    VW_EDIT_ADD,       /* add sphere x y z r [MATERIAL] */
    VW_EDIT_REMOVE,    /* remove ID */
    VW_EDIT_CHECK,     /* check on|off */
    VW_EDIT_SWEEP,     /* sweep on|off */
    VW_EDIT_FRAME,     /* frame */
    VW_EDIT_BALANCE    /* balance */
} vw_edit_op;

/* Whether op is an object edit, one vw_dynscene_apply decides (MOVE .. REMOVE, kept
   together in the enum); the others are switches and commands of the session. */
static inline int vw_edit_is_object(vw_edit_op op)
{
    return op >= VW_EDIT_MOVE && op <= VW_EDIT_REMOVE;
}

typedef struct vw_edit {
    vw_edit_op op;
    int id;            /* MOVE, MOVETO, ROTATE, REMOVE */
    double v[4];       /* MOVE: d; MOVETO: target; ROTATE: axis, degrees; ADD: x y z r */
    int material;      /* ADD: material index, -1 = none given */
    int on;            /* CHECK, SWEEP */
    int line;          /* line number, for messages */
} vw_edit;

/* Parses one line. VW_E_INPUT with "name:line: message" in err for a malformed line
   (unknown command, wrong count, non-number, NaN or infinity, zero axis). Ids are
   only checked against the scene when the edit is applied. */
VW_API vw_status vw_edit_parse(const char *line, const char *name, int lineno, vw_edit *out,
                               char *err, size_t errlen);

/* ---- the dynamic scene -------------------------------------------------------------- */

/* A scene being edited: the vw_scene (kept as the truth, so it can be written out), the
   collision shapes of every object in a collider over the same decomposition as the
   application's world, and the per-batch decisions. Objects removed keep their id
   reserved; the scene written by vw_dynscene_write_nff leaves them out. */
typedef struct vw_dynscene vw_dynscene;

typedef struct vw_dynscene_params {
    const vw_decomp *decomp;    /* the application's decomposition (cloned) */
    const vw_config *config;    /* may be NULL */
    double tol;                 /* contact tolerance; 0: 1e-9 of the world diagonal */
    int brute_force;            /* 1: decide with an O(n^2) loop instead of the collider
                                   (the tests' reference) */
} vw_dynscene_params;

/* Takes ownership of scene s (freed by vw_dynscene_free, also on failure). Collective
   under MPI, like vw_world_create: the shapes each process makes from its own copy of
   the scene are agreed on (vw_config_agree on p->config) before the collider's world,
   so a process that fails alone (memory, a polygon its copy gives fewer than three
   vertices) fails on every process, with "rank R: ..." in err. */
VW_API vw_status vw_dynscene_create(vw_scene *s, const vw_dynscene_params *p,
                                    vw_dynscene **out, char *err, size_t errlen);
VW_API void vw_dynscene_free(vw_dynscene *ds);
VW_API const vw_scene *vw_dynscene_scene(const vw_dynscene *ds);
VW_API vw_collider *vw_dynscene_collider(vw_dynscene *ds);
/* The object with global id `id` exists (was read or added, not removed). */
VW_API int vw_dynscene_alive(const vw_dynscene *ds, int id);
/* Ids ever given out (alive or removed): 0..n-1. */
VW_API int vw_dynscene_ids(const vw_dynscene *ds);

/* What became of one edit. */
typedef enum vw_outcome {
    VW_OUT_ACCEPTED = 0,
    VW_OUT_COLLISION,   /* the destination interpenetrates obstacle */
    VW_OUT_SWEEP,       /* the path does (the destination is free) */
    VW_OUT_INVALID      /* bad input: message in vw_result.msg */
} vw_outcome;

typedef struct vw_result {
    vw_edit edit;
    vw_outcome outcome;
    int obstacle;       /* COLLISION, SWEEP: the smallest id hit */
    int id;             /* the object edited (ADD: the new id) */
    char msg[160];      /* INVALID: the message (without "file:line: ") */
} vw_result;

/* Applies a batch of object edits (MOVE, MOVETO, ROTATE, ADD, REMOVE) in order, with the
   current check/sweep switches; one distributed query decides them all. results[i]
   tells the outcome of edits[i]. Accepted edits change the scene and the collider.
   *changed (malloc'ed) lists the ids whose geometry changed, ascending, once each.
   An edit naming an object twice in one batch is allowed (decided in order).
   Collective under MPI: memory one process lacks fails the call on every process
   (agreed before each collective step), vw_dynscene_errmsg saying why ("rank R: ...");
   the edits accepted before the failing batch stay. */
/* Why the last vw_dynscene_apply failed ("" when it did not). */
VW_API const char *vw_dynscene_errmsg(const vw_dynscene *ds);
VW_API vw_status vw_dynscene_apply(vw_dynscene *ds, const vw_edit *edits, size_t n, int check,
                                   int sweep, vw_result *results, int **changed,
                                   size_t *nchanged);
/* The collision shapes of object id (slots of the collider): *first, *n. */
VW_API void vw_dynscene_slots(const vw_dynscene *ds, int id, size_t *first, size_t *n);
/* The world box the scene must stay inside (moves leaving it are invalid). */
VW_API vw_box vw_dynscene_world(const vw_dynscene *ds);
/* The live objects as a scene (removed ones left out; ids become dense again). */
VW_API vw_status vw_dynscene_write_nff(const vw_dynscene *ds, FILE *f);
/* Replace the decomposition of the collider (after balancing the application's world). */
VW_API vw_status vw_dynscene_redecompose(vw_dynscene *ds, const vw_decomp *d,
                                         const int *cell_worker);

#ifdef __cplusplus
}
#endif
#endif
